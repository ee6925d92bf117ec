/* test_real_dems.c -- greedy insertion on real DEMs read through GDAL,
 * checked by an independent oracle (tt_eval_triangles rasterises the TIN
 * with its own code): the requested bound holds at every valid sample,
 * every valid sample is covered, no sample is covered twice, and the
 * reported statistics agree with the oracle's.
 *  - testdata/jacksboro_fault_dem.{tif,asc,dem} (always present): the three
 *    formats give the same TIN where their heights are the same;
 *  - ../shared/testdata (skipped when absent): Crater Lake against the
 *    average errors published in the 2004 criteria study (SPEC section 6),
 *    and a handful of DEMs with nodata, feet, NaN and odd CRSs. */
#include "terratin/terratin_gdal.h"
#include "tt_test.h"
#include "tt_tin_oracle.h"

#include <cpl_conv.h>

static tt_context *ctx;

static tt_grid *read_dem(const char *path, tt_raster_info **out_info)
{
  GDALDatasetH ds = GDALOpenEx(path, GDAL_OF_RASTER | GDAL_OF_READONLY, NULL,
                               NULL, NULL);
  if (!ds) {
    TT_FAIL_("cannot open %s", path);
    return NULL;
  }
  tt_grid *g = NULL;
  tt_raster_info *info = NULL;
  CHECK_OK(ctx, tt_gdal_read_grid(ctx, GDALGetRasterBand(ds, 1), NULL, NULL,
                                  NULL, &g, &info));
  GDALClose(ds);
  if (out_info)
    *out_info = info;
  else
    tt_raster_info_destroy(info);
  return g;
}

/* The oracle: every triangle of the TIN handed to tt_eval_triangles. */
static void check_against_eval(const tt_grid *g, const tt_tin *tin,
                               double bound, const char *what)
{
  size_t nt = tt_tin_triangle_count(tin);
  double *xyz = tt_oracle_pixel_triangles(tin);
  tt_eval_result ev;
  CHECK_OK(ctx, tt_eval_triangles(ctx, g, nt, xyz, &ev));
  free(xyz);
  tt_tin_summary s;
  tt_tin_get_summary(tin, &s);
  /* only samples that no valid cell part holds stay outside the TIN */
  if (ev.uncovered != s.errors.samples - s.errors.covered)
    TT_FAIL_("%s: %zu valid samples outside the TIN, the summary says %zu",
             what, ev.uncovered, s.errors.samples - s.errors.covered);
  if (ev.uncovered != tt_oracle_uncarriable(g))
    TT_FAIL_("%s: %zu valid samples outside the TIN, %zu cannot be carried",
             what, ev.uncovered, tt_oracle_uncarriable(g));
  if (tt_oracle_nodata_inside(g, tin))
    TT_FAIL_("%s: nodata samples strictly inside triangles", what);
  if (ev.overlapped != 0)
    TT_FAIL_("%s: %zu samples inside two triangles", what, ev.overlapped);
  if (bound >= 0 && !(ev.errors.max_error <= bound + 1e-9 * (1 + bound)))
    TT_FAIL_("%s: oracle max error %.17g above the bound %g", what,
             ev.errors.max_error, bound);
  CHECK_INT_EQ(ev.errors.samples, s.valid_samples);
  CHECK_INT_EQ(ev.errors.covered, s.errors.covered);
  CHECK_DBL_NEAR(ev.errors.max_error, s.errors.max_error, 1e-9);
  CHECK_DBL_NEAR(ev.errors.rmse, s.errors.rmse,
                 1e-9 * (1 + s.errors.rmse));
  CHECK_DBL_NEAR(ev.errors.mean_abs, s.errors.mean_abs,
                 1e-9 * (1 + s.errors.mean_abs));
}

static tt_tin *refine_with(const tt_grid *g, double max_error, double percent,
                          tt_criterion criterion)
{
  tt_refine_options opt;
  tt_refine_options_init(&opt);
  opt.max_error = max_error;
  opt.percent = percent;
  opt.criterion = criterion;
  tt_tin *tin = NULL;
  CHECK_OK(ctx, tt_refine_run(ctx, g, &opt, &tin));
  return tin;
}

static tt_tin *refine(const tt_grid *g, double max_error, double percent)
{
  return refine_with(g, max_error, percent, TT_CRITERION_DELAUNAY);
}

static bool same_tin(const tt_tin *a, const tt_tin *b)
{
  if (tt_tin_vertex_count(a) != tt_tin_vertex_count(b) ||
      tt_tin_triangle_count(a) != tt_tin_triangle_count(b))
    return false;
  for (size_t t = 0; t < tt_tin_triangle_count(a); t++) {
    tt_triangle_info x, y;
    tt_tin_triangle(a, t, &x);
    tt_tin_triangle(b, t, &y);
    if (memcmp(x.v, y.v, sizeof x.v) != 0)
      return false;
  }
  return true;
}

static void test_jacksboro(void)
{
  const char *dir = getenv("TT_TESTDATA");
  char path[4096];
  snprintf(path, sizeof path, "%s/jacksboro_fault_dem.tif", dir);
  tt_grid *tif = read_dem(path, NULL);
  snprintf(path, sizeof path, "%s/jacksboro_fault_dem.asc", dir);
  tt_grid *asc = read_dem(path, NULL);
  snprintf(path, sizeof path, "%s/jacksboro_fault_dem.dem", dir);
  tt_grid *dem = read_dem(path, NULL);
  if (!tif || !asc || !dem)
    goto out;
  const double bounds[] = {50, 10, 2.5};
  for (size_t i = 0; i < sizeof bounds / sizeof bounds[0]; i++) {
    tt_tin *a = refine(tif, bounds[i], 0);
    tt_tin *b = refine(asc, bounds[i], 0);
    tt_tin *again = refine(tif, bounds[i], 0);
    char what[64];
    snprintf(what, sizeof what, "jacksboro.tif at %g m", bounds[i]);
    if (a)
      check_against_eval(tif, a, bounds[i], what);
    /* same heights, same grid: the AAIGrid copy gives the same TIN in
     * the affine frame. Its origin differs in the tenth decimal of a
     * degree (ASCII), which moves the ground points (issue 18) by 1e-5 m:
     * enough to decide some of the grid's near-co-circular quads the
     * other way, so with ground points only the sizes agree closely. */
    if (a && b) {
      size_t na = tt_tin_vertex_count(a), nb = tt_tin_vertex_count(b);
      printf("jacksboro at %g m: %zu vertices (.tif), %zu (.asc)\n",
             bounds[i], na, nb);
      CHECK(na <= nb + nb / 100 && nb <= na + na / 100);
    }
    if (a && again)
      CHECK(same_tin(a, again));
    tt_tin_destroy(a);
    tt_tin_destroy(b);
    tt_tin_destroy(again);
    tt_tin *d = refine(dem, bounds[i], 0);
    snprintf(what, sizeof what, "jacksboro.dem at %g m", bounds[i]);
    if (d)
      check_against_eval(dem, d, bounds[i], what);
    tt_tin_destroy(d);
  }
  /* the affine frame (ground points dropped): the same TIN exactly */
  tt_grid_drop_ground_points(tif);
  tt_grid_drop_ground_points(asc);
  for (size_t i = 0; i < sizeof bounds / sizeof bounds[0]; i++) {
    tt_tin *a = refine(tif, bounds[i], 0);
    tt_tin *b = refine(asc, bounds[i], 0);
    if (a && b)
      CHECK(same_tin(a, b));
    tt_tin_destroy(a);
    tt_tin_destroy(b);
  }
out:
  tt_grid_destroy(tif);
  tt_grid_destroy(asc);
  tt_grid_destroy(dem);
}

/* SPEC section 6: average error of greedy Delaunay insertion on Crater
 * Lake, by percentage of the 154,224 samples inserted. Ties among equal
 * errors may be broken differently from the 2004 implementation, so the
 * averages are compared within 2 %; the point counts are exact. The same
 * for the L2 criterion with its default repair. */
typedef struct crater_row {
  double percent;
  size_t points;
  double mean_abs;
} crater_row;

static void check_crater_lake(const tt_grid *g, tt_criterion criterion,
                              const crater_row *rows, size_t nrows)
{
  for (size_t i = 0; i < nrows; i++) {
    tt_tin *tin = refine_with(g, -1, rows[i].percent, criterion);
    if (!tin)
      continue;
    tt_tin_summary s;
    tt_tin_get_summary(tin, &s);
    CHECK_INT_EQ(s.valid_samples, 154224);
    CHECK_INT_EQ(s.vertices, rows[i].points);
    double rel = fabs(s.errors.mean_abs - rows[i].mean_abs) / rows[i].mean_abs;
    printf("crater lake %s %g%%: %zu points, mean |error| %.6g (published "
           "%.6g, %+.2f%%)\n", tt_criterion_name(criterion),
           rows[i].percent, s.vertices,
           s.errors.mean_abs, rows[i].mean_abs,
           100 * (s.errors.mean_abs - rows[i].mean_abs) / rows[i].mean_abs);
    if (rel > 0.02)
      TT_FAIL_("crater lake %s %g%%: mean error %.6g, published %.6g",
               tt_criterion_name(criterion), rows[i].percent,
               s.errors.mean_abs, rows[i].mean_abs);
    char what[64];
    snprintf(what, sizeof what, "crater lake %s %g%%",
             tt_criterion_name(criterion), rows[i].percent);
    check_against_eval(g, tin, -1, what);
    tt_tin_destroy(tin);
  }
}

static void test_crater_lake(const char *shared)
{
  char path[4096];
  snprintf(path, sizeof path,
           "%s/garland_heckbert_terra_scape/crater.stm.vrt", shared);
  tt_grid *g = read_dem(path, NULL);
  if (!g)
    return;
  static const crater_row delaunay[] = {{1, 1542, 5.26211},
                                        {10, 15422, 0.809917},
                                        {25, 38556, 0.315733},
                                        {50, 77112, 0.0864432}};
  check_crater_lake(g, TT_CRITERION_DELAUNAY, delaunay, 4);
  /* L2 with its defaults (Delaunay insertion, then the L2 local swap of the
   * final pass): the study's L2 column, the best of all criteria */
  static const crater_row l2[] = {{1, 1542, 4.24232},
                                  {10, 15422, 0.671814},
                                  {25, 38556, 0.262467},
                                  {50, 77112, 0.0570321}};
  check_crater_lake(g, TT_CRITERION_L2, l2, 4);
  tt_grid_destroy(g);
}

/* Real DEMs with nodata, feet, NaN, Web Mercator, geographic lidar: the
 * bound holds at every valid sample and every valid sample is covered. */
static void test_shared_dems(const char *shared)
{
  const struct {
    const char *file;
    double bound;
  } dems[] = {
      {"gdal_autotest/n43.dt0", 5},
      {"gdal_autotest/warp_52_dem.tif", 10},
      {"usgs_dem_san_francisco/sanfranciscos.dem", 10},
      {"gdalraster/storml_elev_orig.tif", 3},
      {"rspatial_terra/elev.tif", 5},
      {"landlab/west_bijou_gully.asc", 0.2},
      {"Rsagacmd/srtm.tif", 20},
      {"spatial.tools_tahoe_lidar/tahoe_lidar_bareearth.tif", 0.25},
      {"tin-terrain/valid_raster.tif", 0.1},
      /* non-square pixels (89.98 x 90.02), no CRS */
      {"whitebox-tools_testdata/DEM.tif", 5},
      {"whitebox-tools_testdata/DEM.rst", 5},
  };
  for (size_t i = 0; i < sizeof dems / sizeof dems[0]; i++) {
    char path[4096];
    snprintf(path, sizeof path, "%s/%s", shared, dems[i].file);
    tt_grid *g = read_dem(path, NULL);
    if (!g)
      continue;
    tt_tin *tin = refine(g, dems[i].bound, 0);
    if (tin)
      check_against_eval(g, tin, dems[i].bound, dems[i].file);
    tt_tin_destroy(tin);
    tt_grid_destroy(g);
  }
}

int main(void)
{
  GDALAllRegister();
  CPLSetConfigOption("CPL_LOG", "/dev/null");
  ctx = tt_context_create();
  TT_RUN(test_jacksboro());
  const char *shared = getenv("TT_SHARED_TESTDATA");
  char probe[4096];
  snprintf(probe, sizeof probe, "%s/CATALOG.md", shared ? shared : "");
  FILE *f = shared ? fopen(probe, "r") : NULL;
  if (f) {
    fclose(f);
    test_crater_lake(shared);
    test_shared_dems(shared);
  }
  tt_context_destroy(ctx);
  if (!f && !tt_test_failures)
    TT_SKIP("../shared/testdata is absent: Crater Lake and the shared DEMs "
            "were not tested (the bundled Jacksboro DEM passed)");
  TT_TEST_DONE();
}
