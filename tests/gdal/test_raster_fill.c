/*
 * test_raster_fill.c -- tt_gdal_read_grid's FILL_NODATA=K on an in-memory
 * Float32 DEM of 90 x 70 samples (a smooth surface, nodata -9999) with
 * small voids (a sample, a 3 x 2 block, an L of 5, a 10-sample bar), a
 * lake of 113 samples and a void on the raster's edge: the small voids
 * are filled, each sample within its void's neighbours' range, with the
 * values GDAL's GDALFillNodata gives the whole raster for that void's
 * search distance (gdal_fillnodata -md D); the lake, the edge void and the
 * voids above K stay nodata; every window (tiles of 16 and 23, a window
 * cutting a void) fills its samples bit for bit as the whole read, a
 * window of floats too as a whole read of doubles; the counts,
 * FILL_OWNED's and the bad values.
 */
#include "terratin/terratin_gdal.h"
#include "tt_test.h"

#include <cpl_string.h>
#include <gdal_alg.h>

#define NX 90
#define NY 70
#define NODATA -9999.0f

static tt_context *ctx;
static float dem[NX * NY];

static float surface(int c, int r)
{
  return (float)(100.0 + 20.0 * sin(c / 9.0) + 15.0 * cos(r / 7.0) +
                 0.01 * c * r);
}

typedef struct box { int c0, r0, w, h; } box;
/* the voids of at most 10 samples, then the lake's box */
static const box small[] = {{10, 10, 1, 1}, {30, 20, 3, 2}, {60, 40, 5, 2}};
static const int ell[5][2] = {{50, 55}, {51, 55}, {52, 55}, {52, 56},
                              {52, 57}};

static int in_lake(int c, int r)
{
  return (c - 70) * (c - 70) + (r - 20) * (r - 20) <= 36;
}

static void make_dem(void)
{
  for (int r = 0; r < NY; r++)
    for (int c = 0; c < NX; c++)
      dem[r * NX + c] = in_lake(c, r) ? NODATA : surface(c, r);
  for (size_t k = 0; k < sizeof small / sizeof small[0]; k++)
    for (int r = small[k].r0; r < small[k].r0 + small[k].h; r++)
      for (int c = small[k].c0; c < small[k].c0 + small[k].w; c++)
        dem[r * NX + c] = NODATA;
  for (int k = 0; k < 5; k++)
    dem[ell[k][1] * NX + ell[k][0]] = NODATA;
  dem[30 * NX + 0] = dem[31 * NX + 0] = NODATA; /* on the edge */
}

static GDALDatasetH open_dem(const float *z)
{
  GDALDatasetH ds = GDALCreate(GDALGetDriverByName("MEM"), "fill", NX, NY,
                               1, GDT_Float32, NULL);
  GDALRasterBandH b = GDALGetRasterBand(ds, 1);
  GDALSetRasterNoDataValue(b, NODATA);
  CHECK(GDALRasterIO(b, GF_Write, 0, 0, NX, NY, (void *)z, NX, NY,
                     GDT_Float32, 0, 0) == CE_None);
  return ds;
}

static tt_grid *read_grid(GDALDatasetH ds, char **opts,
                          tt_raster_info **out_info)
{
  tt_grid *g = NULL;
  tt_status s = tt_gdal_read_grid(ctx, GDALGetRasterBand(ds, 1), opts, NULL,
                                  NULL, &g, out_info);
  if (s != TT_OK)
    fprintf(stderr, "read: %s\n", tt_context_errmsg(ctx));
  CHECK(s == TT_OK);
  return g;
}

static int is_void(int c, int r) { return dem[r * NX + c] == NODATA; }

/* The whole raster, K = 10: 1 + 6 + 5 + 10 samples in 4 voids filled. */
static void test_whole(GDALDatasetH ds, tt_grid **out_g)
{
  char **o = CSLSetNameValue(NULL, "FILL_NODATA", "10");
  tt_raster_info *info = NULL;
  tt_grid *g = read_grid(ds, o, &info);
  CSLDestroy(o);
  if (!g)
    return;
  CHECK_INT_EQ(info->filled_samples, 22);
  CHECK_INT_EQ(info->filled_voids, 4);
  CHECK_INT_EQ(info->fill_max, 10);
  size_t lake = 0, nodata = 0;
  for (int r = 0; r < NY; r++)
    for (int c = 0; c < NX; c++) {
      double z = tt_grid_sample(g, (size_t)c, (size_t)r);
      lake += in_lake(c, r);
      nodata += isnan(z);
      if (in_lake(c, r) || (c == 0 && (r == 30 || r == 31)))
        CHECK(isnan(z));
      else if (is_void(c, r)) {
        /* within the range of the surface around the void */
        double lo = INFINITY, hi = -INFINITY;
        for (int y = r - 6; y <= r + 6; y++)
          for (int x = c - 6; x <= c + 6; x++)
            if (x >= 0 && y >= 0 && x < NX && y < NY && !is_void(x, y)) {
              lo = fmin(lo, dem[y * NX + x]);
              hi = fmax(hi, dem[y * NX + x]);
            }
        CHECK(z >= lo && z <= hi);
        /* and near the smooth surface it was cut from */
        CHECK(fabs(z - surface(c, r)) < 3.0);
      }
    }
  CHECK_INT_EQ(nodata, lake + 2);
  CHECK_INT_EQ(info->valid_samples, NX * NY - lake - 2);
  CHECK_INT_EQ(info->nodata_samples, lake + 2);
  tt_raster_info_destroy(info);
  *out_g = g;

  /* K = 5: the bar of 10 and the 6-sample block stay holes */
  o = CSLSetNameValue(NULL, "FILL_NODATA", "5");
  g = read_grid(ds, o, &info);
  CSLDestroy(o);
  CHECK_INT_EQ(info->filled_samples, 6);
  CHECK_INT_EQ(info->filled_voids, 2);
  CHECK(isnan(tt_grid_sample(g, 31, 20)));
  CHECK(isnan(tt_grid_sample(g, 62, 41)));
  CHECK(!isnan(tt_grid_sample(g, 52, 57)));
  tt_grid_destroy(g);
  tt_raster_info_destroy(info);
}

/* Each void's values are those of GDALFillNodata on the whole raster
 * with the void's search distance (its larger side + 1), as
 * gdal_fillnodata -md D would give them. */
static void test_as_gdal(const tt_grid *g)
{
  const int md[] = {2, 4, 6}; /* the blocks: 1 x 1, 3 x 2, 5 x 2 */
  for (int k = 0; k < 4; k++) {
    GDALDatasetH ds = open_dem(dem);
    GDALRasterBandH b = GDALGetRasterBand(ds, 1);
    char **fo = CSLSetNameValue(NULL, "TEMP_FILE_DRIVER", "MEM");
    CHECK(GDALFillNodata(b, GDALGetMaskBand(b), k < 3 ? md[k] : 4, 0, 0,
                         fo, NULL, NULL) == CE_None);
    CSLDestroy(fo);
    float z[NX * NY];
    CHECK(GDALRasterIO(b, GF_Read, 0, 0, NX, NY, z, NX, NY, GDT_Float32, 0,
                       0) == CE_None);
    if (k < 3) {
      for (int r = small[k].r0; r < small[k].r0 + small[k].h; r++)
        for (int c = small[k].c0; c < small[k].c0 + small[k].w; c++)
          CHECK_DBL_NEAR(tt_grid_sample(g, c, r), z[r * NX + c], 0);
    } else {
      for (int i = 0; i < 5; i++)
        CHECK_DBL_NEAR(tt_grid_sample(g, ell[i][0], ell[i][1]),
                       z[ell[i][1] * NX + ell[i][0]], 0);
    }
    GDALClose(ds);
  }
}

/* A window reads the same filled samples as the whole raster, and the
 * owned parts' counts add up. */
static void test_windows(GDALDatasetH ds, const tt_grid *whole, int side)
{
  size_t filled = 0, voids = 0;
  for (int r0 = 0; r0 < NY - 1; r0 += side)
    for (int c0 = 0; c0 < NX - 1; c0 += side) {
      int w = c0 + side + 1 <= NX ? side + 1 : NX - c0;
      int h = r0 + side + 1 <= NY ? side + 1 : NY - r0;
      int ow = c0 + w == NX ? w : w - 1, oh = r0 + h == NY ? h : h - 1;
      char **o = CSLSetNameValue(NULL, "FILL_NODATA", "10");
      o = CSLSetNameValue(o, "WINDOW",
                          CPLSPrintf("%d,%d,%d,%d", c0, r0, w, h));
      o = CSLSetNameValue(o, "FILL_OWNED",
                          CPLSPrintf("%d,%d,%d,%d", c0, r0, ow, oh));
      tt_raster_info *info = NULL;
      tt_grid *g = read_grid(ds, o, &info);
      CSLDestroy(o);
      if (!g)
        continue;
      filled += info->filled_samples;
      voids += info->filled_voids;
      int same = 1;
      for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
          double a = tt_grid_sample(g, x, y);
          double b = tt_grid_sample(whole, c0 + x, r0 + y);
          same &= (isnan(a) && isnan(b)) || a == b;
        }
      if (!same)
        fprintf(stderr, "window %d,%d of %d differs\n", c0, r0, side);
      CHECK(same);
      tt_grid_destroy(g);
      tt_raster_info_destroy(info);
    }
  CHECK_INT_EQ(filled, 22);
  CHECK_INT_EQ(voids, 4);
}

/* A Float64 band with a height that is no float: the whole read holds
 * doubles, a window without that height floats; the filled samples agree
 * (rounded to floats in both). */
static void test_precision(void)
{
  static double zd[NX * NY];
  for (int i = 0; i < NX * NY; i++)
    zd[i] = dem[i];
  zd[65 * NX + 85] = 100.1;
  GDALDatasetH ds = GDALCreate(GDALGetDriverByName("MEM"), "f64", NX, NY,
                               1, GDT_Float64, NULL);
  GDALRasterBandH b = GDALGetRasterBand(ds, 1);
  GDALSetRasterNoDataValue(b, NODATA);
  CHECK(GDALRasterIO(b, GF_Write, 0, 0, NX, NY, zd, NX, NY, GDT_Float64, 0,
                     0) == CE_None);
  char **o = CSLSetNameValue(NULL, "FILL_NODATA", "10");
  tt_grid *whole = read_grid(ds, o, NULL);
  o = CSLSetNameValue(o, "WINDOW", "20,10,45,40");
  tt_grid *win = read_grid(ds, o, NULL);
  CSLDestroy(o);
  if (whole && win) {
    CHECK(tt_grid_precision(whole) == TT_PRECISION_FLOAT64);
    CHECK(tt_grid_precision(win) == TT_PRECISION_FLOAT32);
    size_t filled = 0;
    for (int r = 10; r < 50; r++)
      for (int c = 20; c < 65; c++)
        if (is_void(c, r) && !in_lake(c, r)) {
          CHECK(tt_grid_sample(win, c - 20, r - 10) ==
                tt_grid_sample(whole, c, r));
          filled++;
        }
    CHECK_INT_EQ(filled, 6 + 10);
  }
  tt_grid_destroy(whole);
  tt_grid_destroy(win);
  GDALClose(ds);
}

static void test_bad_values(GDALDatasetH ds)
{
  const char *bad[] = {"0", "-3", "x", "2.5", "99999999999"};
  for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
    char **o = CSLSetNameValue(NULL, "FILL_NODATA", bad[i]);
    tt_grid *g = NULL;
    tt_status s = tt_gdal_read_grid(ctx, GDALGetRasterBand(ds, 1), o, NULL,
                                    NULL, &g, NULL);
    CSLDestroy(o);
    CHECK(s == TT_ERR_ARG);
    CHECK(strstr(tt_context_errmsg(ctx), "FILL_NODATA must be") != NULL);
    CHECK(g == NULL);
  }
}

int main(void)
{
  GDALAllRegister();
  ctx = tt_context_create();
  make_dem();
  GDALDatasetH ds = open_dem(dem);
  tt_grid *whole = NULL;
  TT_RUN(test_whole(ds, &whole));
  if (whole) {
    TT_RUN(test_as_gdal(whole));
    TT_RUN(test_windows(ds, whole, 16));
    TT_RUN(test_windows(ds, whole, 23));
    TT_RUN(test_windows(ds, whole, 61));
  }
  TT_RUN(test_precision());
  TT_RUN(test_bad_values(ds));
  tt_grid_destroy(whole);
  GDALClose(ds);
  tt_context_destroy(ctx);
  TT_TEST_DONE();
}
