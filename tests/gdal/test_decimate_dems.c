/* test_decimate_dems.c -- vertex decimation on real DEMs read through
 * GDAL (../shared/testdata; skipped when absent), checked by the
 * independent oracle tt_eval_triangles: with every importance and every
 * selection the -max_error bound holds at every valid sample, every
 * carriable valid sample is covered once, no nodata sample lies inside a
 * triangle, and the summary agrees with the oracle.
 *  - Crater Lake (no nodata), from greedy:20000;
 *  - Mt Hood (LANDFIRE, nodata around the data), from greedy:20000, with
 *    a bound above the 22.2 m that start leaves. */
#include "terratin/terratin_gdal.h"
#include "tt_test.h"
#include "tt_tin_oracle.h"

#include <cpl_conv.h>

#include <stdbool.h>
#include <stdio.h>

static tt_context *ctx;

static tt_grid *read_dem(const char *path)
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
  tt_raster_info_destroy(info);
  return g;
}

static void check(const tt_grid *g, const tt_tin *tin, double bound,
                  const char *what)
{
  double *xyz = tt_oracle_pixel_triangles(tin);
  tt_eval_result ev;
  CHECK_OK(ctx, tt_eval_triangles(ctx, g, tt_tin_triangle_count(tin), xyz,
                                  &ev));
  free(xyz);
  tt_tin_summary s;
  tt_tin_get_summary(tin, &s);
  if (ev.uncovered != tt_oracle_uncarriable(g))
    TT_FAIL_("%s: %zu valid samples outside the TIN, %zu cannot be carried",
             what, ev.uncovered, tt_oracle_uncarriable(g));
  if (tt_oracle_nodata_inside(g, tin))
    TT_FAIL_("%s: nodata samples strictly inside triangles", what);
  if (ev.overlapped != 0)
    TT_FAIL_("%s: %zu samples inside two triangles", what, ev.overlapped);
  if (!(ev.errors.max_error <= bound + 1e-9 * (1 + bound)))
    TT_FAIL_("%s: oracle max error %.17g above the bound %g", what,
             ev.errors.max_error, bound);
  CHECK_DBL_NEAR(ev.errors.max_error, s.errors.max_error, 1e-9);
  CHECK_DBL_NEAR(ev.errors.mean_abs, s.errors.mean_abs,
                 1e-9 * (1 + s.errors.mean_abs));
  CHECK(s.removed_vertices > 0);
  CHECK_INT_EQ(s.stop_reason, TT_STOP_MAX_ERROR);
}

static void run_all(const char *path, double bound, int every)
{
  tt_grid *g = read_dem(path);
  if (!g)
    return;
  static const tt_importance imps[] = {
      TT_IMPORTANCE_DEGREE, TT_IMPORTANCE_HDH,  TT_IMPORTANCE_ABH,
      TT_IMPORTANCE_VOLUME, TT_IMPORTANCE_DROP, TT_IMPORTANCE_ERROR};
  for (int i = 0; i < 6; i++)
    for (int sel = 0; sel < 3; sel++) {
      if (!every && imps[i] != TT_IMPORTANCE_ERROR)
        continue;
      tt_decimate_options o;
      tt_decimate_options_init(&o);
      o.max_error = bound;
      o.start = TT_DSTART_GREEDY_N;
      o.start_points = 20000;
      o.importance = imps[i];
      o.selection = sel == 2 ? TT_SELECTION_SEQUENTIAL
                             : TT_SELECTION_INDEPENDENT;
      o.onepass = sel == 1;
      o.criterion = i % 2 ? TT_CRITERION_L2 : TT_CRITERION_DELAUNAY;
      tt_tin *tin = NULL;
      CHECK_OK(ctx, tt_decimate_run(ctx, g, &o, &tin));
      if (!tin)
        continue;
      char what[256];
      snprintf(what, sizeof what, "%s, %s, selection %d", path,
               tt_importance_name(imps[i]), sel);
      check(g, tin, bound, what);
      tt_tin_destroy(tin);
    }
  tt_grid_destroy(g);
}

int main(void)
{
  const char *shared = getenv("TT_SHARED_TESTDATA");
  char crater[1024], hood[1024];
  snprintf(crater, sizeof crater,
           "%s/garland_heckbert_terra_scape/crater.stm.vrt",
           shared ? shared : "");
  snprintf(hood, sizeof hood, "%s/gdalraster/lf_elev_220_mt_hood_utm.tif",
           shared ? shared : "");
  FILE *f1 = shared && *shared ? fopen(crater, "rb") : NULL;
  FILE *f2 = shared && *shared ? fopen(hood, "rb") : NULL;
  bool there = f1 && f2;
  if (f1)
    fclose(f1);
  if (f2)
    fclose(f2);
  if (!there)
    TT_SKIP("the shared test DEMs are not there (TT_SHARED_TESTDATA=%s)",
            shared ? shared : "");
  GDALAllRegister();
  ctx = tt_context_create();
  run_all(crater, 4.0, 1);
  run_all(hood, 30.0, 0); /* greedy:20000 leaves 22.2 m: above it */
  tt_context_destroy(ctx);
  TT_TEST_DONE();
}
