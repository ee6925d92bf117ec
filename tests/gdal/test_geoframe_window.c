/* test_geoframe_window.c -- a window of a geographic or Web Mercator DEM
 * (tt_gdal_read_grid's WINDOW, what a tile reads; issue 19) is measured in
 * the whole raster's ground frame: its ground points are the whole grid's
 * at the same samples bit for bit, its frame and frame name are the whole
 * grid's, and the scale factor and convergence at a sample with its
 * neighbours in the window are the whole grid's bit for bit. Also: the
 * range of k the reader reports (over the raster's outline and centre) is
 * the range over every sample. Three DEMs: 10 x 6 degrees at 70-76 N
 * (oblique stereographic, scaled), 1 x 0.6 degree at 45 N (UTM) and a Web
 * Mercator grid at 58-61 N. And issue19_nodata_corners: a TIN's ground
 * points belong to its own vertices when the mesh dropped some. */
#include "terratin/terratin_gdal.h"
#include "terratin_lib.h"
#include "tt_test.h"

#include <cpl_conv.h>
#include <cpl_string.h>
#include <gdal.h>
#include <ogr_srs_api.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

static tt_context *ctx;

/* A Float32 MEM dataset of nx x ny heights in CRS epsg, geotransform gt. */
static GDALDatasetH make_ds(size_t nx, size_t ny, const double gt[6],
                            int epsg)
{
  GDALDriverH mem = GDALGetDriverByName("MEM");
  GDALDatasetH ds = mem ? GDALCreate(mem, "", (int)nx, (int)ny, 1,
                                     GDT_Float32, NULL)
                        : NULL;
  if (!ds)
    return NULL;
  GDALSetGeoTransform(ds, (double *)gt);
  OGRSpatialReferenceH srs = OSRNewSpatialReference(NULL);
  OSRImportFromEPSG(srs, epsg);
  GDALSetSpatialRef(ds, srs);
  OSRDestroySpatialReference(srs);
  float *z = malloc(nx * ny * sizeof *z);
  for (size_t i = 0; z && i < nx * ny; i++)
    z[i] = (float)(100 * sin(0.07 * (double)(i % nx)) *
                   cos(0.05 * (double)(i / nx)));
  CHECK(z && GDALRasterIO(GDALGetRasterBand(ds, 1), GF_Write, 0, 0, (int)nx,
                          (int)ny, z, (int)nx, (int)ny, GDT_Float32, 0,
                          0) == CE_None);
  free(z);
  return ds;
}

static tt_grid *read_window(GDALDatasetH ds, size_t c0, size_t r0,
                            size_t w, size_t h, tt_raster_info **info)
{
  char **opts = CSLSetNameValue(NULL, "WINDOW", CPLSPrintf("%zu,%zu,%zu,%zu",
                                                           c0, r0, w, h));
  tt_grid *g = NULL;
  CHECK_OK(ctx, tt_gdal_read_grid(ctx, GDALGetRasterBand(ds, 1), opts, NULL,
                                  NULL, &g, info));
  CSLDestroy(opts);
  return g;
}

static void check_dem(const char *name, size_t nx, size_t ny,
                      const double gt[6], int epsg, const char *frame)
{
  printf("%s: %zu x %zu, EPSG:%d\n", name, nx, ny, epsg);
  GDALDatasetH ds = make_ds(nx, ny, gt, epsg);
  CHECK(ds != NULL);
  if (!ds)
    return;
  tt_raster_info *fi = NULL;
  tt_grid *full = NULL;
  CHECK_OK(ctx, tt_gdal_read_grid(ctx, GDALGetRasterBand(ds, 1), NULL, NULL,
                                  NULL, &full, &fi));
  if (!full) {
    GDALClose(ds);
    return;
  }
  printf("  frame %s\n", fi->frame_name);
  CHECK(strstr(fi->frame_name, frame) != NULL);
  const double *fxy = tt_grid_ground_xy(full);
  CHECK(fxy != NULL);

  /* the range of k over every sample, scaled as the frame is: the
   * reported largest |k - 1| (outline and centre) is the same */
  double kmin = HUGE_VAL, kmax = -HUGE_VAL;
  for (size_t r = 0; r < ny; r++)
    for (size_t c = 0; c < nx; c++) {
      double k, conv;
      CHECK_INT_EQ(tt_grid_ground_scale_at(full, c, r, &k, &conv), TT_OK);
      kmin = fmin(kmin, k);
      kmax = fmax(kmax, k);
    }
  double err = fmax(fabs(kmax - 1), fabs(kmin - 1));
  printf("  k over every sample %.9f to %.9f: largest |k - 1| %.6g, "
         "reported %.6g\n", kmin, kmax, err, fi->frame_scale_error);
  CHECK_DBL_LE(fabs(err - fi->frame_scale_error), 1e-9 + 1e-6 * err);

  /* windows: inside, at each corner, two samples wide, the whole raster */
  const size_t win[][4] = {{13, 7, 30, 21},   {0, 0, 17, 11},
                           {nx - 19, 0, 19, 9}, {0, ny - 12, 25, 12},
                           {nx - 23, ny - 14, 23, 14}, {5, 3, 2, 9},
                           {7, 9, 11, 2},     {0, 0, nx, ny}};
  for (size_t i = 0; i < sizeof win / sizeof win[0]; i++) {
    size_t c0 = win[i][0], r0 = win[i][1], w = win[i][2], h = win[i][3];
    tt_raster_info *wi = NULL;
    tt_grid *g = read_window(ds, c0, r0, w, h, &wi);
    if (!g) {
      tt_raster_info_destroy(wi);
      continue;
    }
    CHECK(strcmp(wi->frame_name, fi->frame_name) == 0);
    double fa[4], wa[4];
    tt_grid_get_ground_frame(full, fa);
    tt_grid_get_ground_frame(g, wa);
    CHECK(memcmp(fa, wa, sizeof fa) == 0);
    const double *wxy = tt_grid_ground_xy(g);
    CHECK(wxy != NULL);
    size_t differ = 0, kdiffer = 0, kcount = 0;
    for (size_t r = 0; wxy && r < h; r++)
      for (size_t c = 0; c < w; c++) {
        const double *p = wxy + 2 * (r * w + c);
        const double *q = fxy + 2 * ((r0 + r) * nx + c0 + c);
        differ += memcmp(p, q, 2 * sizeof *p) != 0;
        /* the finite differences see the same neighbours where the
         * window's edge is the raster's, or one sample away */
        int cin = (c > 0 || c0 == 0) && (c + 1 < w || c0 + w == nx) &&
                  (w > 2 || nx == 2);
        int rin = (r > 0 || r0 == 0) && (r + 1 < h || r0 + h == ny) &&
                  (h > 2 || ny == 2);
        if (!cin || !rin)
          continue;
        double k1, v1, k2, v2;
        CHECK_INT_EQ(tt_grid_ground_scale_at(g, c, r, &k1, &v1), TT_OK);
        CHECK_INT_EQ(tt_grid_ground_scale_at(full, c0 + c, r0 + r, &k2,
                                             &v2), TT_OK);
        kdiffer += k1 != k2 || v1 != v2;
        kcount++;
      }
    printf("  window %zu x %zu at (%zu, %zu): %zu of %zu ground points "
           "differ, %zu of %zu scale factors\n", w, h, c0, r0, differ, w * h,
           kdiffer, kcount);
    CHECK_INT_EQ(differ, 0);
    CHECK_INT_EQ(kdiffer, 0);
    CHECK(kcount > 0 || w == 2 || h == 2);
    tt_grid_destroy(g);
    tt_raster_info_destroy(wi);
  }
  tt_grid_destroy(full);
  tt_raster_info_destroy(fi);
  GDALClose(ds);
}

/* Interior angles (degrees) of the triangle a, b, c: the smallest. */
static double min_angle(const double *a, const double *b, const double *c)
{
  const double *p[3] = {a, b, c};
  double m = 180;
  for (int i = 0; i < 3; i++) {
    const double *o = p[i], *u = p[(i + 1) % 3], *v = p[(i + 2) % 3];
    double ux = u[0] - o[0], uy = u[1] - o[1];
    double vx = v[0] - o[0], vy = v[1] - o[1];
    double ang = atan2(fabs(ux * vy - uy * vx), ux * vx + uy * vy);
    m = fmin(m, ang * 180 / 3.14159265358979323846);
  }
  return m;
}

/* issue19_nodata_corners: a geographic DEM whose corners and blobs are
 * nodata (vertices outside the valid domain or in no triangle are dropped
 * from the TIN): every triangle's angles are those of its
 * corners' ground points. The TIN's ground points were indexed by the
 * mesh's vertex ids, not the TIN's, and so belonged to other vertices
 * (Luxembourg's slopes up to 75 times off). */
static void test_nodata_corners(void)
{
  const size_t nx = 60, ny = 50;
  const double gt[6] = {6, 1.0 / 120, 0, 50, 0, -1.0 / 120};
  GDALDatasetH ds = make_ds(nx, ny, gt, 4326);
  CHECK(ds != NULL);
  if (!ds)
    return;
  GDALRasterBandH band = GDALGetRasterBand(ds, 1);
  GDALSetRasterNoDataValue(band, -9999);
  /* nodata: the corners, blobs where the heights are low, and single
   * valid samples inside them (in no triangle) */
  float *z = malloc(nx * ny * sizeof *z);
  CHECK(z && GDALRasterIO(band, GF_Read, 0, 0, (int)nx, (int)ny, z, (int)nx,
                          (int)ny, GDT_Float32, 0, 0) == CE_None);
  for (size_t r = 0; z && r < ny; r++)
    for (size_t c = 0; c < nx; c++) {
      int corner = (c < 5 || c + 5 >= nx) && (r < 5 || r + 5 >= ny);
      if (corner || (z[r * nx + c] < -40 && (c + r) % 7 != 0))
        z[r * nx + c] = -9999;
    }
  CHECK(z && GDALRasterIO(band, GF_Write, 0, 0, (int)nx, (int)ny, z,
                          (int)nx, (int)ny, GDT_Float32, 0, 0) == CE_None);
  free(z);
  tt_grid *g = NULL;
  tt_raster_info *info = NULL;
  CHECK_OK(ctx, tt_gdal_read_grid(ctx, band, NULL, NULL, NULL, &g, &info));
  tt_tin *tin = NULL;
  tt_refine_options ro;
  tt_refine_options_init(&ro);
  ro.max_error = 1;
  if (g)
    CHECK_OK(ctx, tt_refine_run(ctx, g, &ro, &tin));
  const double *xy = g ? tt_grid_ground_xy(g) : NULL;
  CHECK(xy != NULL);
  double worst = 0;
  size_t n = tin ? tt_tin_triangle_count(tin) : 0;
  for (size_t t = 0; xy && t < n; t++) {
    tt_triangle_info ti;
    CHECK_INT_EQ(tt_tin_triangle(tin, t, &ti), TT_OK);
    const double *p[3];
    for (int j = 0; j < 3; j++) {
      tt_vertex_info vi;
      tt_tin_vertex(tin, (size_t)ti.v[j], &vi);
      p[j] = xy + 2 * ((size_t)vi.row * nx + (size_t)vi.col);
    }
    worst = fmax(worst, fabs(ti.min_angle_deg - min_angle(p[0], p[1], p[2])));
  }
  printf("nodata corners: %zu triangles, smallest angles within %.3g degree "
         "of their ground points'\n", n, worst);
  CHECK(n > 100);
  CHECK_DBL_LE(worst, 1e-6);
  tt_tin_destroy(tin);
  tt_grid_destroy(g);
  tt_raster_info_destroy(info);
  GDALClose(ds);
}

int main(void)
{
  GDALAllRegister();
  ctx = tt_context_create();
  const double stereo[6] = {10, 10.0 / 96, 0, 76, 0, -6.0 / 80};
  check_dem("10 x 6 degrees at 70-76 N", 97, 81, stereo, 4326,
            "oblique stereographic");
  const double utm[6] = {7.2, 1.0 / 120, 0, 45.6, 0, -1.0 / 120};
  check_dem("1 x 0.6 degree at 45 N", 121, 73, utm, 4326, "UTM zone 32N");
  const double webmerc[6] = {1000000, 2500, 0, 8600000, 0, -5000};
  check_dem("Web Mercator at 58-61 N", 120, 120, webmerc, 3857,
            "per vertex");
  TT_RUN(test_nodata_corners());
  tt_context_destroy(ctx);
  TT_TEST_DONE();
}
