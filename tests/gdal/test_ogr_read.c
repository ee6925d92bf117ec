/*
 * test_ogr_read.c -- tt_ogr_read_triangles(): every accepted geometry type
 * (POLYGON Z, TRIANGLE Z, and those inside MULTIPOLYGON Z, TIN Z,
 * GEOMETRYCOLLECTION Z) converted exactly to pixel-centre space under a
 * north-up and a rotated geotransform, every rejected one counted (quads,
 * 2D polygons, holes, open rings, points, missing geometries), a singular
 * geotransform refused; and the full loop: a TIN written by
 * tt_ogr_write_tin() to GPKG and Shapefile, read back and evaluated with
 * tt_eval_triangles(), covers every valid sample once with the TIN's own
 * maximum error.
 */
#include "terratin/terratin_gdal.h"
#include "tt_test.h"

#include <cpl_string.h>
#include <cpl_vsi.h>

#include <stdlib.h>
#include <sys/stat.h>

static char tmpdir[256];

/* Map coordinates of sample (c, r) under gt (pixel centres). */
static void map_xy(const double gt[6], double c, double r, double *x,
                   double *y)
{
  *x = gt[0] + (c + 0.5) * gt[1] + (r + 0.5) * gt[2];
  *y = gt[3] + (c + 0.5) * gt[4] + (r + 0.5) * gt[5];
}

/* "x y z" of sample (c, r) with height z, for WKT. */
static const char *pt(const double gt[6], double c, double r, double z)
{
  static char buf[8][80];
  static int k = 0;
  double x, y;
  map_xy(gt, c, r, &x, &y);
  k = (k + 1) % 8;
  snprintf(buf[k], sizeof buf[k], "%.17g %.17g %.17g", x, y, z);
  return buf[k];
}

static void add_wkt(OGRLayerH l, const char *wkt)
{
  OGRFeatureH f = OGR_F_Create(OGR_L_GetLayerDefn(l));
  if (wkt) {
    OGRGeometryH g = NULL;
    char *p = (char *)wkt;
    if (OGR_G_CreateFromWkt(&p, NULL, &g) != OGRERR_NONE)
      TT_FAIL_("bad test WKT: %s", wkt);
    OGR_F_SetGeometryDirectly(f, g);
  }
  CHECK(OGR_L_CreateFeature(l, f) == OGRERR_NONE);
  OGR_F_Destroy(f);
}

static void test_geometry_types(tt_context *ctx, const double gt[6])
{
  GDALDatasetH ds = GDALCreate(GDALGetDriverByName("Memory"), "mem", 0, 0, 0,
                               GDT_Unknown, NULL);
  OGRLayerH l = GDALDatasetCreateLayer(ds, "soup", NULL, wkbUnknown, NULL);
  char wkt[2048];
  /* Accepted: 7 triangles. */
  snprintf(wkt, sizeof wkt, "POLYGON Z ((%s, %s, %s, %s))", pt(gt, 0, 0, 5),
           pt(gt, 3, 0, 6), pt(gt, 0, 2, 7), pt(gt, 0, 0, 5));
  add_wkt(l, wkt);
  snprintf(wkt, sizeof wkt, "TRIANGLE Z ((%s, %s, %s, %s))",
           pt(gt, 1, 1, 1), pt(gt, 2, 1, 2), pt(gt, 1, 2, 3),
           pt(gt, 1, 1, 1));
  add_wkt(l, wkt);
  snprintf(wkt, sizeof wkt,
           "MULTIPOLYGON Z (((%s, %s, %s, %s)), ((%s, %s, %s, %s)))",
           pt(gt, 4, 4, 10), pt(gt, 5, 4, 11), pt(gt, 4, 5, 12),
           pt(gt, 4, 4, 10), pt(gt, 5, 4, 11), pt(gt, 5, 5, 13),
           pt(gt, 4, 5, 12), pt(gt, 5, 4, 11));
  add_wkt(l, wkt);
  snprintf(wkt, sizeof wkt,
           "TIN Z (((%s, %s, %s, %s)), ((%s, %s, %s, %s)))",
           pt(gt, 6, 6, 20), pt(gt, 7, 6, 21), pt(gt, 6, 7, 22),
           pt(gt, 6, 6, 20), pt(gt, 7, 6, 21), pt(gt, 7, 7, 23),
           pt(gt, 6, 7, 22), pt(gt, 7, 6, 21));
  add_wkt(l, wkt);
  snprintf(wkt, sizeof wkt,
           "GEOMETRYCOLLECTION Z (POLYGON Z ((%s, %s, %s, %s)), POINT Z (%s))",
           pt(gt, 8, 8, 30), pt(gt, 9, 8, 31), pt(gt, 8, 9, 32),
           pt(gt, 8, 8, 30), pt(gt, 9, 9, 33));
  add_wkt(l, wkt);
  /* Rejected: 7 (the POINT above is one). */
  snprintf(wkt, sizeof wkt, "POLYGON Z ((%s, %s, %s, %s, %s))",
           pt(gt, 0, 0, 1), pt(gt, 1, 0, 1), pt(gt, 1, 1, 1),
           pt(gt, 0, 1, 1), pt(gt, 0, 0, 1));
  add_wkt(l, wkt); /* a quad */
  double x0, y0, x1, y1, x2, y2;
  map_xy(gt, 0, 0, &x0, &y0);
  map_xy(gt, 3, 0, &x1, &y1);
  map_xy(gt, 0, 3, &x2, &y2);
  snprintf(wkt, sizeof wkt,
           "POLYGON ((%.17g %.17g, %.17g %.17g, %.17g %.17g, %.17g %.17g))",
           x0, y0, x1, y1, x2, y2, x0, y0);
  add_wkt(l, wkt); /* no Z */
  snprintf(wkt, sizeof wkt,
           "POLYGON Z ((%s, %s, %s, %s), (%s, %s, %s, %s))",
           pt(gt, 0, 0, 1), pt(gt, 9, 0, 1), pt(gt, 0, 9, 1),
           pt(gt, 0, 0, 1), pt(gt, 1, 1, 1), pt(gt, 2, 1, 1),
           pt(gt, 1, 2, 1), pt(gt, 1, 1, 1));
  add_wkt(l, wkt); /* a hole */
  snprintf(wkt, sizeof wkt, "POLYGON Z ((%s, %s, %s, %s))", pt(gt, 0, 0, 1),
           pt(gt, 1, 0, 1), pt(gt, 0, 1, 1), pt(gt, 0, 0, 2));
  add_wkt(l, wkt); /* open in z */
  snprintf(wkt, sizeof wkt, "POINT Z (%s)", pt(gt, 0, 0, 1));
  add_wkt(l, wkt);
  add_wkt(l, NULL); /* no geometry */

  double *xyz = NULL;
  size_t n = 0, rejected = 0;
  CHECK_OK(ctx, tt_ogr_read_triangles(ctx, l, gt, &xyz, &n, &rejected));
  CHECK_INT_EQ(n, 7);
  CHECK_INT_EQ(rejected, 7);
  const double want[7][9] = {
      {0, 0, 5, 3, 0, 6, 0, 2, 7},       {1, 1, 1, 2, 1, 2, 1, 2, 3},
      {4, 4, 10, 5, 4, 11, 4, 5, 12},    {5, 4, 11, 5, 5, 13, 4, 5, 12},
      {6, 6, 20, 7, 6, 21, 6, 7, 22},    {7, 6, 21, 7, 7, 23, 6, 7, 22},
      {8, 8, 30, 9, 8, 31, 8, 9, 32}};
  for (size_t t = 0; t < n && t < 7; t++)
    for (int k = 0; k < 9; k++)
      CHECK_DBL_NEAR(xyz[9 * t + k], want[t][k], 1e-9);
  free(xyz);

  /* A singular geotransform is refused. */
  const double flat[6] = {0, 1, 2, 0, 2, 4};
  xyz = NULL;
  CHECK_INT_EQ(tt_ogr_read_triangles(ctx, l, flat, &xyz, &n, &rejected),
               TT_ERR_ARG);
  CHECK(xyz == NULL);
  GDALClose(ds);
}

/* A grid with a bump, a nodata corner, and a TIN of it. */
static tt_grid *make_grid(tt_context *ctx, const double gt[6])
{
  const size_t nx = 33, ny = 27;
  float *z = malloc(nx * ny * sizeof *z);
  for (size_t r = 0; r < ny; r++)
    for (size_t c = 0; c < nx; c++) {
      double dx = (double)c - 15, dy = (double)r - 11;
      z[r * nx + c] = (c + r < 6) ? NAN
                                   : (float)(0.5 * (double)c +
                                             20 * exp(-(dx * dx + dy * dy) /
                                                      30));
    }
  tt_grid *g = NULL;
  CHECK_OK(ctx, tt_grid_create_from_floats(ctx, nx, ny, z, &g));
  free(z);
  CHECK_OK(ctx, tt_grid_set_geotransform(ctx, g, gt));
  return g;
}

static void test_round_trip(tt_context *ctx, const char *format)
{
  const int shp = strcmp(format, "ESRI Shapefile") == 0;
  const double gt[6] = {300000, 5, 0, 4000000, 0, -5};
  tt_grid *grid = make_grid(ctx, gt);
  tt_refine_options opt;
  tt_refine_options_init(&opt);
  opt.max_error = 0.5;
  tt_tin *tin = NULL;
  CHECK_OK(ctx, tt_refine_run(ctx, grid, &opt, &tin));
  if (!tin) {
    tt_grid_destroy(grid);
    return;
  }
  char path[400];
  snprintf(path, sizeof path, "%s/rt.%s", tmpdir, shp ? "shp" : "gpkg");
  tt_output *out = NULL;
  CHECK_OK(ctx, tt_output_begin(ctx, path, format, 0, &out));
  GDALDatasetH ds = GDALCreate(GDALGetDriverByName(format),
                               tt_output_temp_path(out), 0, 0, 0,
                               GDT_Unknown, NULL);
  char **opts = CSLSetNameValue(NULL, "NLN_PREFIX",
                                tt_output_layer_prefix(out));
  CHECK_OK(ctx, tt_ogr_write_tin(ctx, ds, tin, NULL, NULL, 0, opts, NULL,
                                 NULL));
  CSLDestroy(opts);
  GDALClose(ds);
  CHECK_OK(ctx, tt_output_commit(ctx, out));
  tt_output_destroy(out);

  char layer_path[400];
  snprintf(layer_path, sizeof layer_path, "%s/%s", tmpdir,
           shp ? "rt_triangles.shp" : "rt.gpkg");
  ds = GDALOpenEx(layer_path, GDAL_OF_VECTOR, NULL, NULL, NULL);
  CHECK(ds != NULL);
  if (ds) {
    OGRLayerH l = GDALDatasetGetLayerByName(ds, shp ? "rt_triangles"
                                                    : "triangles");
    double *xyz = NULL;
    size_t n = 0, rejected = 0;
    CHECK_OK(ctx, tt_ogr_read_triangles(ctx, l, gt, &xyz, &n, &rejected));
    CHECK_INT_EQ(n, tt_tin_triangle_count(tin));
    CHECK_INT_EQ(rejected, 0);
    /* The corners are the vertices' own samples. */
    for (size_t t = 0; t < n; t++) {
      tt_triangle_info ti;
      tt_tin_triangle(tin, t, &ti);
      for (int k = 0; k < 3; k++) {
        double c = xyz[9 * t + 3 * k], r = xyz[9 * t + 3 * k + 1];
        CHECK_DBL_NEAR(c, floor(c + 0.5), 1e-9);
        CHECK_DBL_NEAR(r, floor(r + 0.5), 1e-9);
      }
    }
    tt_eval_result ev;
    CHECK_OK(ctx, tt_eval_triangles(ctx, grid, n, xyz, &ev));
    tt_tin_summary sum;
    tt_tin_get_summary(tin, &sum);
    CHECK_INT_EQ(ev.triangles, n);
    CHECK_INT_EQ(ev.degenerate, 0);
    CHECK_INT_EQ(ev.uncovered, 0);
    CHECK_INT_EQ(ev.overlapped, 0);
    CHECK_INT_EQ(ev.errors.samples, sum.valid_samples);
    CHECK_INT_EQ(ev.errors.covered, sum.valid_samples);
    CHECK_DBL_NEAR(ev.errors.max_error, sum.errors.max_error, 1e-6);
    CHECK_DBL_LE(ev.errors.max_error, 0.5);
    free(xyz);
    GDALClose(ds);
  }
  tt_tin_destroy(tin);
  tt_grid_destroy(grid);
}

int main(void)
{
  GDALAllRegister();
  snprintf(tmpdir, sizeof tmpdir, "/tmp/tt_ogr_read_XXXXXX");
  if (!mkdtemp(tmpdir)) {
    perror("mkdtemp");
    return 1;
  }
  tt_context *ctx = tt_context_create();
  const double north_up[6] = {1000, 10, 0, 2000, 0, -10};
  const double rotated[6] = {500, 2, 0.5, 800, 0.3, -2};
  TT_RUN(test_geometry_types(ctx, north_up));
  TT_RUN(test_geometry_types(ctx, rotated));
  TT_RUN(test_round_trip(ctx, "GPKG"));
  TT_RUN(test_round_trip(ctx, "ESRI Shapefile"));
  tt_context_destroy(ctx);
  VSIRmdirRecursive(tmpdir);
  TT_TEST_DONE();
}
