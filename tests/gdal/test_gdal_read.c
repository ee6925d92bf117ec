/*
 * test_gdal_read.c -- tt_gdal_read_grid() against rasters made here with
 * GDAL (GeoTIFF Int16/Float32, tiled and striped, nodata, NaN nodata,
 * scale/offset, AAIGrid, USGS DEM, /vsizip/) compared sample by sample with
 * the values written, the refusals (NaN not marked nodata, all nodata, 1 x N,
 * MAX_MEMORY, GCP-only), the geographic ground frame against an independent
 * series, GDAL's block cache held small during the read, and the shared real
 * DEMs when TT_SHARED_TESTDATA is present (skipped otherwise). Also
 * tt_gdal_write_grid(): written, refused, overwritten and read back.
 * Band types (issue 11): every GDAL type up to UInt64, with values chosen
 * to break float rounding where the type allows, read exactly (floats kept
 * where every height is one, doubles otherwise, widened in mid-read),
 * 64-bit integers beyond 2^53 refused, SRCNODATA and masks on the buffered
 * path, scales that floats hold and that they do not, MAX_MEMORY counted
 * at the widening; then refined at a limit and at 0 and checked by a brute
 * force in long double against the values written, and by
 * tt_eval_triangles.
 */
#include "terratin/terratin_gdal.h"
#include "tt_test.h"

#include <cpl_conv.h>
#include <cpl_string.h>
#include <cpl_vsi.h>
#include <gdal_utils.h>

#include <float.h>
#include <stdlib.h>
#include <sys/stat.h>
#include <unistd.h>

static char tmpdir[256];

static const char *tmp_path(const char *name)
{
  static char buf[512];
  snprintf(buf, sizeof buf, "%s/%s", tmpdir, name);
  return buf;
}

/* The test terrain: integer heights with some texture. */
static double terrain(int c, int r)
{
  return 100 + 3 * c - 2 * r + ((c * 7 + r * 13) % 11);
}

typedef struct raster_spec {
  GDALDataType type;
  int nx, ny;
  const char *const *create_options;
  int has_nodata;
  double nodata;
  int has_scale;
  double scale, offset;
  int epsg;               /* 0: no CRS */
  const double *gt;       /* NULL: none */
  const double *values;   /* nx*ny, row-major */
  const char *unit;
  const char *area_or_point;
} raster_spec;

static void make_raster(const char *path, const raster_spec *sp)
{
  GDALDriverH drv = GDALGetDriverByName("GTiff");
  GDALDatasetH ds = GDALCreate(drv, path, sp->nx, sp->ny, 1, sp->type,
                               (char **)sp->create_options);
  if (!ds) {
    fprintf(stderr, "cannot create %s\n", path);
    exit(1);
  }
  if (sp->gt)
    GDALSetGeoTransform(ds, (double *)sp->gt);
  if (sp->epsg) {
    OGRSpatialReferenceH srs = OSRNewSpatialReference(NULL);
    OSRImportFromEPSG(srs, sp->epsg);
    GDALSetSpatialRef(ds, srs);
    OSRDestroySpatialReference(srs);
  }
  if (sp->area_or_point)
    GDALSetMetadataItem(ds, GDALMD_AREA_OR_POINT, sp->area_or_point, NULL);
  GDALRasterBandH b = GDALGetRasterBand(ds, 1);
  if (sp->has_nodata)
    GDALSetRasterNoDataValue(b, sp->nodata);
  if (sp->has_scale) {
    GDALSetRasterScale(b, sp->scale);
    GDALSetRasterOffset(b, sp->offset);
  }
  if (sp->unit)
    GDALSetRasterUnitType(b, sp->unit);
  CHECK(GDALRasterIO(b, GF_Write, 0, 0, sp->nx, sp->ny, (void *)sp->values,
                     sp->nx, sp->ny, GDT_Float64, 0, 0) == CE_None);
  GDALClose(ds);
}

static tt_status read_path(tt_context *ctx, const char *path,
                           const char *const *options, tt_grid **grid,
                           tt_raster_info **info)
{
  GDALDatasetH ds = GDALOpen(path, GA_ReadOnly);
  if (!ds) {
    fprintf(stderr, "cannot open %s\n", path);
    tt_test_failures++;
    *grid = NULL;
    if (info)
      *info = NULL;
    return TT_ERR_IO;
  }
  tt_status s = tt_gdal_read_grid(ctx, GDALGetRasterBand(ds, 1),
                                  (char **)options, NULL, NULL, grid, info);
  GDALClose(ds);
  return s;
}

/* Every sample of grid equals expect(c,r) exactly (NaN where expected
 * NaN), whichever precision the grid holds. */
static int compare_grid(const tt_grid *g, const double *expect, int nx,
                        int ny)
{
  int bad = 0;
  CHECK_INT_EQ(tt_grid_width(g), nx);
  CHECK_INT_EQ(tt_grid_height(g), ny);
  for (int r = 0; r < ny; r++)
    for (int c = 0; c < nx; c++) {
      double e = expect[(size_t)r * nx + c];
      double v = tt_grid_sample(g, (size_t)c, (size_t)r);
      int same = isnan(e) ? isnan(v) : e == v;
      if (!same && bad++ < 5)
        TT_FAIL_("sample (%d,%d): got %.17g, want %.17g", c, r, v, e);
    }
  return bad;
}

static double *terrain_values(int nx, int ny)
{
  double *v = malloc(sizeof(double) * (size_t)nx * ny);
  for (int r = 0; r < ny; r++)
    for (int c = 0; c < nx; c++)
      v[(size_t)r * nx + c] = terrain(c, r);
  return v;
}

static void test_int16_nodata_tiled_and_striped(tt_context *ctx)
{
  const int nx = 37, ny = 29;
  double *v = terrain_values(nx, ny);
  double *want = terrain_values(nx, ny);
  for (int i = 0; i < nx * ny; i += 17) {
    v[i] = -32767;
    want[i] = NAN;
  }
  const double gt[6] = {500000, 30, 0, 4100000, 0, -30};
  const char *tiled[] = {"TILED=YES", "BLOCKXSIZE=16", "BLOCKYSIZE=16",
                         NULL};
  const char *striped[] = {"BLOCKYSIZE=3", "COMPRESS=DEFLATE", NULL};
  const char *const *opts[2] = {tiled, striped};
  for (int k = 0; k < 2; k++) {
    raster_spec sp = {GDT_Int16, nx, ny, opts[k], 1, -32767, 0, 1, 0,
                      32610, gt, v, "m", NULL};
    make_raster(tmp_path("int16.tif"), &sp);
    tt_grid *g = NULL;
    tt_raster_info *info = NULL;
    CHECK_OK(ctx, read_path(ctx, tmp_path("int16.tif"), NULL, &g, &info));
    if (!g)
      continue;
    compare_grid(g, want, nx, ny);
    size_t nodata = (size_t)(nx * ny + 16) / 17;
    CHECK_INT_EQ(info->nodata_samples, nodata);
    CHECK_INT_EQ(info->valid_samples, (size_t)nx * ny - nodata);
    CHECK_INT_EQ(info->width, nx);
    CHECK_INT_EQ(info->height, ny);
    CHECK_INT_EQ(info->band, 1);
    CHECK_STR_EQ(info->driver, "GTiff");
    CHECK_STR_EQ(info->datatype, "Int16");
    CHECK_STR_EQ(info->z_unit, "m");
    CHECK_STR_EQ(info->area_or_point, "Area");
    /* metric projected: the geotransform's frame is kept */
    CHECK(strncmp(info->frame_name, "geotransform", 12) == 0);
    CHECK(strstr(info->crs_name, "EPSG:32610") != NULL);
    CHECK(strstr(info->crs_wkt, "UTM zone 10N") != NULL);
    CHECK_INT_EQ(info->crs_is_geographic, 0);
    CHECK_INT_EQ(info->has_geotransform, 1);
    for (int i = 0; i < 6; i++)
      CHECK_DBL_NEAR(info->gt[i], gt[i], 0);
    double a[4], ggt[6];
    tt_grid_get_ground_frame(g, a);
    tt_grid_get_geotransform(g, ggt);
    CHECK_DBL_NEAR(a[0], 30, 0);
    CHECK_DBL_NEAR(a[3], -30, 0);
    CHECK_DBL_NEAR(ggt[3], 4100000, 0);
    CHECK_DBL_NEAR(info->frame[0], 30, 0);
    tt_grid_destroy(g);
    tt_raster_info_destroy(info);
  }

  /* SRCNODATA overrides the mask: -32767 becomes a height, 0 nodata. */
  raster_spec sp = {GDT_Int16, nx, ny, NULL, 1, -32767, 0, 1, 0, 0, NULL, v,
                    NULL, NULL};
  v[5] = 0;
  make_raster(tmp_path("int16b.tif"), &sp);
  const char *o[] = {"SRCNODATA=0", NULL};
  tt_grid *g = NULL;
  CHECK_OK(ctx, read_path(ctx, tmp_path("int16b.tif"), o, &g, NULL));
  if (g) {
    for (int i = 0; i < nx * ny; i++)
      want[i] = i == 5 ? NAN : v[i];
    compare_grid(g, want, nx, ny);
    tt_grid_destroy(g);
  }
  free(v);
  free(want);
}

static void test_float32_nan_nodata(tt_context *ctx)
{
  const int nx = 20, ny = 23;
  double *v = terrain_values(nx, ny);
  for (int i = 0; i < nx * ny; i++)
    v[i] += 0.25 * (i % 4);
  v[0] = v[41] = v[nx * ny - 1] = NAN;
  const double gt[6] = {0, 2, 0, 100, 0, -2};
  raster_spec sp = {GDT_Float32, nx, ny, NULL, 1, NAN, 0, 1, 0, 0, gt, v,
                    NULL, NULL};
  make_raster(tmp_path("f32.tif"), &sp);
  tt_grid *g = NULL;
  tt_raster_info *info = NULL;
  CHECK_OK(ctx, read_path(ctx, tmp_path("f32.tif"), NULL, &g, &info));
  if (g) {
    compare_grid(g, v, nx, ny);
    CHECK_INT_EQ(info->valid_samples, nx * ny - 3);
    CHECK_STR_EQ(info->datatype, "Float32");
    CHECK_STR_EQ(info->crs_wkt, "");
    CHECK_STR_EQ(info->crs_name, "");
  }
  tt_grid_destroy(g);
  tt_raster_info_destroy(info);

  /* The same NaNs without a nodata declaration: refused, then accepted with
   * SRCNODATA=nan. */
  sp.has_nodata = 0;
  make_raster(tmp_path("f32nan.tif"), &sp);
  g = NULL;
  CHECK_INT_EQ(read_path(ctx, tmp_path("f32nan.tif"), NULL, &g, NULL),
               TT_ERR_DATA);
  CHECK(g == NULL);
  CHECK(strstr(tt_context_errmsg(ctx), "f32nan.tif: height at row 0, "
               "column 0 is NaN but not marked nodata (use -srcnodata nan)")
        != NULL);
  const char *o[] = {"SRCNODATA=nan", NULL};
  CHECK_OK(ctx, read_path(ctx, tmp_path("f32nan.tif"), o, &g, NULL));
  if (g)
    compare_grid(g, v, nx, ny);
  tt_grid_destroy(g);

  /* An infinite height is refused too, naming row and column. */
  v[0] = 1;
  v[nx * 2 + 3] = INFINITY;
  make_raster(tmp_path("f32inf.tif"), &sp);
  CHECK_INT_EQ(read_path(ctx, tmp_path("f32inf.tif"), o, &g, NULL),
               TT_ERR_DATA);
  CHECK(strstr(tt_context_errmsg(ctx), "row 2, column 3 is infinite") !=
        NULL);

  /* A NaN that a numeric SRCNODATA does not cover; a height that Z_FACTOR
   * pushes past the float range. */
  v[nx * 2 + 3] = 3e38;
  v[nx + 1] = NAN;
  make_raster(tmp_path("f32big.tif"), &sp);
  const char *o2[] = {"SRCNODATA=-9999", NULL};
  CHECK_INT_EQ(read_path(ctx, tmp_path("f32big.tif"), o2, &g, NULL),
               TT_ERR_DATA);
  CHECK(strstr(tt_context_errmsg(ctx), "row 1, column 1 is NaN, which "
               "SRCNODATA -9999 does not cover") != NULL);
  const char *o3[] = {"SRCNODATA=nan", "Z_FACTOR=10", NULL};
  CHECK_INT_EQ(read_path(ctx, tmp_path("f32big.tif"), o3, &g, NULL),
               TT_ERR_DATA);
  CHECK(strstr(tt_context_errmsg(ctx), "row 2, column 3 is 3e+39 after "
               "scale 1, offset 0 and Z_FACTOR 10: beyond the +-3.40282e+38 "
               "terratin measures") != NULL);
  free(v);
}

static void test_scale_offset_z_factor(tt_context *ctx)
{
  const int nx = 10, ny = 12;
  double *v = terrain_values(nx, ny);
  double *want = malloc(sizeof(double) * nx * ny);
  v[7] = -9999;
  raster_spec sp = {GDT_Int16, nx, ny, NULL, 1, -9999, 1, 0.5, -20, 0, NULL,
                    v, "ft", "Point"};
  make_raster(tmp_path("scaled.tif"), &sp);
  const char *o[] = {"Z_FACTOR=0.3048", NULL};
  tt_grid *g = NULL;
  tt_raster_info *info = NULL;
  CHECK_OK(ctx, read_path(ctx, tmp_path("scaled.tif"), o, &g, &info));
  for (int i = 0; i < nx * ny; i++)
    want[i] = i == 7 ? NAN : (v[i] * 0.5 - 20) * 0.3048;
  if (g) {
    /* computed in doubles and kept so, not rounded to floats */
    CHECK_INT_EQ(tt_grid_precision(g), TT_PRECISION_FLOAT64);
    compare_grid(g, want, nx, ny);
    CHECK_DBL_NEAR(info->scale, 0.5, 0);
    CHECK_DBL_NEAR(info->offset, -20, 0);
    CHECK_DBL_NEAR(info->z_factor, 0.3048, 0);
    CHECK_STR_EQ(info->z_unit, "ft");
    CHECK_STR_EQ(info->area_or_point, "Point");
    /* No geotransform: the default one, flagged. */
    CHECK_INT_EQ(info->has_geotransform, 0);
    CHECK_DBL_NEAR(info->gt[1], 1, 0);
    CHECK_DBL_NEAR(info->gt[5], 1, 0);
  }
  tt_grid_destroy(g);
  tt_raster_info_destroy(info);

  const char *bad[] = {"Z_FACTOR=abc", NULL};
  CHECK_INT_EQ(read_path(ctx, tmp_path("scaled.tif"), bad, &g, NULL),
               TT_ERR_ARG);
  const char *unknown[] = {"ZFACTOR=2", NULL};
  CHECK_INT_EQ(read_path(ctx, tmp_path("scaled.tif"), unknown, &g, NULL),
               TT_ERR_ARG);
  free(v);
  free(want);
}

static void test_other_formats(tt_context *ctx)
{
  /* 1 arc-second grid on whole arc-seconds: USGS DEM keeps it exactly. */
  const int nx = 31, ny = 25;
  double *v = terrain_values(nx, ny);
  const double gt[6] = {-122.0 - 0.5 / 3600, 1.0 / 3600, 0,
                        38.0 + 0.5 / 3600, 0, -1.0 / 3600};
  raster_spec sp = {GDT_Int16, nx, ny, NULL, 0, 0, 0, 1, 0, 4267, gt, v,
                    NULL, NULL};
  make_raster(tmp_path("src.tif"), &sp);
  GDALDatasetH src = GDALOpen(tmp_path("src.tif"), GA_ReadOnly);
  CHECK(src != NULL);

  GDALDatasetH asc = GDALCreateCopy(GDALGetDriverByName("AAIGrid"),
                                    tmp_path("dem.asc"), src, FALSE, NULL,
                                    NULL, NULL);
  CHECK(asc != NULL);
  GDALClose(asc);
  /* The ASCII grid again, inside a zip. */
  char zpath[600];
  snprintf(zpath, sizeof zpath, "/vsizip/%s/dem.asc", tmp_path("dem.zip"));
  GDALDatasetH z = GDALCreateCopy(GDALGetDriverByName("AAIGrid"), zpath, src,
                                  FALSE, NULL, NULL, NULL);
  CHECK(z != NULL);
  GDALClose(z);

  const char *targv[] = {"-of", "USGSDEM", NULL};
  GDALTranslateOptions *topt = GDALTranslateOptionsNew((char **)targv, NULL);
  int usage_error = 0;
  GDALDatasetH dem = GDALTranslate(tmp_path("dem.dem"), src, topt,
                                   &usage_error);
  GDALTranslateOptionsFree(topt);
  CHECK(dem != NULL);
  GDALClose(dem);
  GDALClose(src);

  char copies[3][600];
  snprintf(copies[0], sizeof copies[0], "%s", tmp_path("dem.asc"));
  snprintf(copies[1], sizeof copies[1], "%s", zpath);
  snprintf(copies[2], sizeof copies[2], "%s", tmp_path("dem.dem"));
  const char *drivers[3] = {"AAIGrid", "AAIGrid", "USGSDEM"};
  for (int k = 0; k < 3; k++) {
    tt_grid *g = NULL;
    tt_raster_info *info = NULL;
    CHECK_OK(ctx, read_path(ctx, copies[k], NULL, &g, &info));
    if (!g)
      continue;
    if (compare_grid(g, v, nx, ny))
      fprintf(stderr, "  in %s\n", copies[k]);
    CHECK_STR_EQ(info->driver, drivers[k]);
    CHECK_INT_EQ(info->crs_is_geographic, 1);
    CHECK(strncmp(info->frame_name, "UTM zone", 8) == 0);
    tt_grid_destroy(g);
    tt_raster_info_destroy(info);
  }
  free(v);
}

/* Metres per degree from the classical series (independent of the reader's
 * radii-of-curvature formula), WGS 84. */
static double series_lon(double phi)
{
  return 111412.84 * cos(phi) - 93.5 * cos(3 * phi) + 0.118 * cos(5 * phi);
}

static double series_lat(double phi)
{
  return 111132.92 - 559.82 * cos(2 * phi) + 1.175 * cos(4 * phi) -
         0.0023 * cos(6 * phi);
}

static void test_geographic_frame(tt_context *ctx)
{
  const int nx = 40, ny = 30;
  double *v = terrain_values(nx, ny);
  const double lats[3] = {45.0, 0.0, -63.5};
  for (int k = 0; k < 3; k++) {
    /* Centre at (10 E, lats[k]), 0.001 degree pixels; also rotated. */
    const double d = 0.001;
    for (int rot = 0; rot < 2; rot++) {
      double gt[6] = {10 - nx / 2 * d, d, 0, lats[k] + ny / 2 * d, 0, -d};
      if (rot) {
        gt[2] = 0.0002;
        gt[4] = 0.0003;
        gt[3] = lats[k] - 0.5 * nx * gt[4] + ny / 2 * d;
        gt[0] = 10 - nx / 2 * d - 0.5 * ny * gt[2];
      }
      raster_spec sp = {GDT_Int16, nx, ny, NULL, 0, 0, 0, 1, 0, 4326, gt, v,
                        NULL, NULL};
      make_raster(tmp_path("geo.tif"), &sp);
      tt_grid *g = NULL;
      tt_raster_info *info = NULL;
      CHECK_OK(ctx, read_path(ctx, tmp_path("geo.tif"), NULL, &g, &info));
      if (!g)
        continue;
      double phi = lats[k] * 3.14159265358979323846 / 180;
      double a[4];
      tt_grid_get_ground_frame(g, a);
      CHECK_INT_EQ(info->crs_is_geographic, 1);
      /* The frame is UTM zone 32's Jacobian (src/gdal/georef/georef_proj.c): rotated
       * by the meridian convergence and scaled by UTM's k (0.9996 to
       * 1.0000 here), so the step lengths match the ellipsoid's to 1e-3;
       * tests/gdal/test_georef.c checks it against PROJ's coordinates. */
      double col_len = hypot(a[0], a[2]), row_len = hypot(a[1], a[3]);
      double want_col = hypot(series_lon(phi) * gt[1],
                              series_lat(phi) * gt[4]);
      double want_row = hypot(series_lon(phi) * gt[2],
                              series_lat(phi) * gt[5]);
      CHECK_DBL_NEAR(col_len / want_col, 1.0, 1e-3);
      CHECK_DBL_NEAR(row_len / want_row, 1.0, 1e-3);
      for (int i = 0; i < 4; i++)
        CHECK_DBL_NEAR(info->frame[i], a[i], 0);
      CHECK(strstr(info->frame_name, "UTM zone 32") != NULL);
      if (k == 0 && !rot) {
        /* The number: 78.85 km per degree of longitude at 45 N. */
        CHECK_DBL_NEAR(col_len / gt[1], 78846.8, 78846.8 * 1e-3);
        CHECK(strstr(info->crs_name, "WGS 84") != NULL);
      }
      tt_grid_destroy(g);
      tt_raster_info_destroy(info);
    }
  }

  /* A projected grid mislabelled as WGS 84: a warning, and the
   * geotransform as ground frame. */
  const double utm[6] = {500000, 30, 0, 4100000, 0, -30};
  raster_spec sp = {GDT_Int16, nx, ny, NULL, 0, 0, 0, 1, 0, 4326, utm, v,
                    NULL, NULL};
  make_raster(tmp_path("mislabelled.tif"), &sp);
  size_t warnings = tt_context_warning_count(ctx);
  tt_grid *g = NULL;
  tt_raster_info *info = NULL;
  CHECK_OK(ctx, read_path(ctx, tmp_path("mislabelled.tif"), NULL, &g,
                          &info));
  CHECK_INT_EQ(tt_context_warning_count(ctx), warnings + 1);
  CHECK_INT_EQ(tt_context_errno(ctx), TT_OK);
  if (g) {
    double a[4];
    tt_grid_get_ground_frame(g, a);
    CHECK_DBL_NEAR(a[0], 30, 0);
    CHECK_DBL_NEAR(a[3], -30, 0);
    CHECK(strncmp(info->frame_name, "geotransform", 12) == 0);
  }
  tt_grid_destroy(g);
  tt_raster_info_destroy(info);
  free(v);
}

static void test_refusals(tt_context *ctx)
{
  tt_grid *g = NULL;
  /* 1 x N */
  double v1[9] = {1, 2, 3, 4, 5, 6, 7, 8, 9};
  raster_spec sp = {GDT_Float32, 1, 9, NULL, 0, 0, 0, 1, 0, 0, NULL, v1,
                    NULL, NULL};
  make_raster(tmp_path("narrow.tif"), &sp);
  CHECK_INT_EQ(read_path(ctx, tmp_path("narrow.tif"), NULL, &g, NULL),
               TT_ERR_DATA);
  CHECK(strstr(tt_context_errmsg(ctx), "1 x 9") != NULL);
  sp.nx = 9;
  sp.ny = 1;
  make_raster(tmp_path("flat.tif"), &sp);
  CHECK_INT_EQ(read_path(ctx, tmp_path("flat.tif"), NULL, &g, NULL),
               TT_ERR_DATA);

  /* All nodata. */
  double v2[12];
  for (int i = 0; i < 12; i++)
    v2[i] = -1;
  raster_spec sp2 = {GDT_Int16, 4, 3, NULL, 1, -1, 0, 1, 0, 0, NULL, v2,
                     NULL, NULL};
  make_raster(tmp_path("empty.tif"), &sp2);
  CHECK_INT_EQ(read_path(ctx, tmp_path("empty.tif"), NULL, &g, NULL),
               TT_ERR_DATA);
  CHECK(strstr(tt_context_errmsg(ctx), "all nodata") != NULL);
  CHECK(g == NULL);

  /* MAX_MEMORY: 100 x 80 floats need 32000 bytes. */
  double *v3 = terrain_values(100, 80);
  raster_spec sp3 = {GDT_Int16, 100, 80, NULL, 0, 0, 0, 1, 0, 0, NULL, v3,
                     NULL, NULL};
  make_raster(tmp_path("mem.tif"), &sp3);
  const char *o1[] = {"MAX_MEMORY=31999", NULL};
  CHECK_INT_EQ(read_path(ctx, tmp_path("mem.tif"), o1, &g, NULL),
               TT_ERR_LIMIT);
  CHECK(strstr(tt_context_errmsg(ctx), "mem.tif: the 100 x 80 heights "
               "need 31.2 KiB, more than MAX_MEMORY (31.2 KiB)") != NULL);
  const char *o2[] = {"MAX_MEMORY=32000", NULL};
  CHECK_OK(ctx, read_path(ctx, tmp_path("mem.tif"), o2, &g, NULL));
  tt_grid_destroy(g);
  g = NULL;
  free(v3);

  /* GCPs only. */
  double v4[16] = {0};
  raster_spec sp4 = {GDT_Int16, 4, 4, NULL, 0, 0, 0, 1, 0, 0, NULL, v4, NULL,
                     NULL};
  make_raster(tmp_path("gcp.tif"), &sp4);
  GDALDatasetH ds = GDALOpen(tmp_path("gcp.tif"), GA_Update);
  GDAL_GCP gcps[3];
  GDALInitGCPs(3, gcps);
  const double px[3][4] = {{0, 0, 5, 40}, {4, 0, 6, 40}, {0, 4, 5, 39}};
  for (int i = 0; i < 3; i++) {
    gcps[i].dfGCPPixel = px[i][0];
    gcps[i].dfGCPLine = px[i][1];
    gcps[i].dfGCPX = px[i][2];
    gcps[i].dfGCPY = px[i][3];
  }
  GDALSetGCPs(ds, 3, gcps, SRS_WKT_WGS84_LAT_LONG);
  GDALDeinitGCPs(3, gcps);
  GDALClose(ds);
  CHECK_INT_EQ(read_path(ctx, tmp_path("gcp.tif"), NULL, &g, NULL),
               TT_ERR_FORMAT);
  CHECK(strstr(tt_context_errmsg(ctx), "ground control points") != NULL);
}

/* --- band types -------------------------------------------------------- */

/* A GeoTIFF of one band of type `type` holding raw[] (nx*ny values of the
 * C type of `type`, written as themselves, not through doubles). */
static void make_typed(const char *path, GDALDataType type, int nx, int ny,
                       const void *raw, const char *const *options,
                       int has_nodata, double nodata)
{
  GDALDatasetH ds = GDALCreate(GDALGetDriverByName("GTiff"), path, nx, ny, 1,
                               type, (char **)options);
  if (!ds) {
    fprintf(stderr, "cannot create %s\n", path);
    exit(1);
  }
  GDALRasterBandH b = GDALGetRasterBand(ds, 1);
  if (has_nodata && type == GDT_Int64)
    GDALSetRasterNoDataValueAsInt64(b, (int64_t)nodata);
  else if (has_nodata)
    GDALSetRasterNoDataValue(b, nodata);
  CHECK(GDALRasterIO(b, GF_Write, 0, 0, nx, ny, (void *)raw, nx, ny, type, 0,
                     0) == CE_None);
  GDALClose(ds);
}

/* The brute force: every sample in or on every triangle of the TIN (exact
 * integer edge tests), its error from the plane in long double against
 * truth[] (NaN: nodata, must not be inside). Returns the largest error. */
static long double oracle_max_error(const tt_tin *tin, const double *truth,
                                    int nx, size_t *out_bad)
{
  long double worst = 0;
  *out_bad = 0;
  for (size_t t = 0; t < tt_tin_triangle_count(tin); t++) {
    tt_triangle_info ti;
    tt_tin_triangle(tin, t, &ti);
    long long x[3], y[3];
    long double z[3];
    for (int k = 0; k < 3; k++) {
      tt_vertex_info vi;
      tt_tin_vertex(tin, (size_t)ti.v[k], &vi);
      x[k] = vi.col;
      y[k] = vi.row;
      z[k] = vi.z;
      if (vi.z != truth[(size_t)vi.row * nx + vi.col])
        (*out_bad)++;
    }
    long long det =
        (x[1] - x[0]) * (y[2] - y[0]) - (x[2] - x[0]) * (y[1] - y[0]);
    long long xa = x[0], xb = x[0], ya = y[0], yb = y[0];
    for (int k = 1; k < 3; k++) {
      xa = x[k] < xa ? x[k] : xa;
      xb = x[k] > xb ? x[k] : xb;
      ya = y[k] < ya ? y[k] : ya;
      yb = y[k] > yb ? y[k] : yb;
    }
    for (long long r = ya; r <= yb; r++)
      for (long long c = xa; c <= xb; c++) {
        long long w1 = (c - x[0]) * (y[2] - y[0]) - (x[2] - x[0]) * (r - y[0]);
        long long w2 = (x[1] - x[0]) * (r - y[0]) - (c - x[0]) * (y[1] - y[0]);
        long long w0 = det - w1 - w2;
        if (det < 0)
          w0 = -w0, w1 = -w1, w2 = -w2;
        if (w0 < 0 || w1 < 0 || w2 < 0)
          continue;
        double h = truth[(size_t)r * nx + (size_t)c];
        if (isnan(h)) {
          (*out_bad)++;
          continue;
        }
        long double p = ((long double)w0 * z[0] + (long double)w1 * z[1] +
                         (long double)w2 * z[2]) / (long double)llabs(det);
        long double e = fabsl((long double)h - p);
        worst = e > worst ? e : worst;
      }
  }
  return worst;
}

/* Refines g at `limit` and at 0 and checks the TINs against truth. */
static void check_refined(tt_context *ctx, const char *what, const tt_grid *g,
                          const double *truth, int nx, double limit)
{
  double zmax = 0;
  for (size_t i = 0; i < tt_grid_width(g) * tt_grid_height(g); i++)
    if (!isnan(truth[i]))
      zmax = fmax(zmax, fabs(truth[i]));
  const double tol = 64 * DBL_EPSILON * zmax;
  for (int pass = 0; pass < 2; pass++) {
    tt_refine_options opt;
    tt_refine_options_init(&opt);
    opt.max_error = pass ? 0 : limit;
    tt_tin *tin = NULL;
    CHECK_OK(ctx, tt_refine_run(ctx, g, &opt, &tin));
    if (!tin)
      return;
    size_t bad = 0;
    double worst = (double)oracle_max_error(tin, truth, nx, &bad);
    if (bad || !(worst <= opt.max_error + tol))
      TT_FAIL_("%s, -max_error %g: the TIN is %.17g off the values written "
               "(%zu vertices off their sample or nodata inside)", what,
               opt.max_error, worst, bad);
    tt_tin_summary s;
    tt_tin_get_summary(tin, &s);
    if (!(fabs(s.errors.max_error - worst) <= tol))
      TT_FAIL_("%s: the run reports max error %.17g, the oracle %.17g", what,
               s.errors.max_error, worst);
    size_t nt = tt_tin_triangle_count(tin);
    double *xyz = malloc((nt ? nt : 1) * 9 * sizeof *xyz);
    for (size_t t = 0; t < nt; t++) {
      tt_triangle_info ti;
      tt_tin_triangle(tin, t, &ti);
      for (int k = 0; k < 3; k++) {
        tt_vertex_info vi;
        tt_tin_vertex(tin, (size_t)ti.v[k], &vi);
        xyz[9 * t + 3 * k] = vi.col;
        xyz[9 * t + 3 * k + 1] = vi.row;
        xyz[9 * t + 3 * k + 2] = vi.z;
      }
    }
    tt_eval_result ev;
    CHECK_OK(ctx, tt_eval_triangles(ctx, g, nt, xyz, &ev));
    if (!(fabs(ev.errors.max_error - worst) <= tol))
      TT_FAIL_("%s: eval reports max error %.17g, the oracle %.17g", what,
               ev.errors.max_error, worst);
    free(xyz);
    tt_tin_destroy(tin);
  }
}

enum { BT_NX = 37, BT_NY = 29 };

/* A smooth terrain in [0, 1] with noise, for sample i. */
static double bt_shape(int i, uint64_t *rng)
{
  int c = i % BT_NX, r = i / BT_NX;
  return 0.45 + 0.45 * sin(0.23 * c) * cos(0.19 * r) +
         0.1 * tt_test_uniform(rng);
}

static void test_band_types(tt_context *ctx)
{
  const int n = BT_NX * BT_NY;
  double *truth = malloc(n * sizeof *truth);
  void *raw = malloc(n * 8);
  const char *striped[] = {"BLOCKYSIZE=2", NULL};
  /* type, kind of values, precision expected, -max_error */
  static const struct {
    GDALDataType type;
    const char *what;
    tt_precision want;
    double limit;
  } cases[] = {
      {GDT_Byte, "Byte 0..255", TT_PRECISION_FLOAT32, 3},
      {GDT_Int16, "Int16 -32768..32767", TT_PRECISION_FLOAT32, 50},
      {GDT_UInt16, "UInt16 0..65535", TT_PRECISION_FLOAT32, 50},
      {GDT_Int32, "Int32 below 2^24", TT_PRECISION_FLOAT32, 10},
      {GDT_Int32, "Int32 2^30 + [0, 1000)", TT_PRECISION_FLOAT64, 10},
      {GDT_Int32, "Int32 floats, then 2^30 + ...", TT_PRECISION_FLOAT64, 10},
      {GDT_UInt32, "UInt32 3 2^30 + [0, 1000)", TT_PRECISION_FLOAT64, 10},
      {GDT_Float32, "Float32 of 24 bits", TT_PRECISION_FLOAT32, 0.5},
      {GDT_Float64, "Float64 that are floats", TT_PRECISION_FLOAT32, 0.5},
      {GDT_Float64, "Float64 1e6 + k / 1000", TT_PRECISION_FLOAT64, 0.01},
      {GDT_Int64, "Int64 -2^40 - [0, 1000)", TT_PRECISION_FLOAT64, 10},
      {GDT_UInt64, "UInt64 2^53 - [0, 1000)", TT_PRECISION_FLOAT64, 10},
  };
  for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
    uint64_t rng = 1000 + k;
    for (int i = 0; i < n; i++) {
      double s = bt_shape(i, &rng), v = 0;
      switch (k) {
      case 0: v = floor(255 * s); ((uint8_t *)raw)[i] = (uint8_t)v; break;
      case 1: v = floor(65535 * s) - 32768; ((int16_t *)raw)[i] = (int16_t)v;
        break;
      case 2: v = floor(65535 * s); ((uint16_t *)raw)[i] = (uint16_t)v;
        break;
      case 3: v = 12345678 + floor(1000 * s); ((int32_t *)raw)[i] =
                                                  (int32_t)v;
        break;
      case 4: v = 1073741824.0 + floor(1000 * s);
        ((int32_t *)raw)[i] = (int32_t)v;
        break;
      case 5: /* the first rows are floats: the grid widens in mid-read */
        v = (i < n / 2 ? 0 : 1073741824.0) + floor(1000 * s);
        ((int32_t *)raw)[i] = (int32_t)v;
        break;
      case 6: v = 3221225472.0 + floor(1000 * s);
        ((uint32_t *)raw)[i] = (uint32_t)v;
        break;
      case 7: v = (float)(8848 + 40 * s); ((float *)raw)[i] = (float)v;
        break;
      case 8: v = 0.25 * floor(4000 * s); ((double *)raw)[i] = v; break;
      case 9: v = 1e6 + 0.001 * floor(1000 * s); ((double *)raw)[i] = v;
        break;
      case 10: {
        int64_t iv = -((int64_t)1 << 40) - (int64_t)floor(1000 * s);
        ((int64_t *)raw)[i] = iv;
        v = (double)iv;
        break;
      }
      default: {
        uint64_t uv = ((uint64_t)1 << 53) - (uint64_t)floor(1000 * s);
        ((uint64_t *)raw)[i] = uv;
        v = (double)uv;
        break;
      }
      }
      truth[i] = v;
    }
    make_typed(tmp_path("bt.tif"), cases[k].type, BT_NX, BT_NY, raw,
               k == 5 ? striped : NULL, 0, 0);
    tt_grid *g = NULL;
    CHECK_OK(ctx, read_path(ctx, tmp_path("bt.tif"), NULL, &g, NULL));
    if (!g)
      continue;
    if (tt_grid_precision(g) != cases[k].want)
      TT_FAIL_("%s: precision %d, want %d", cases[k].what,
               (int)tt_grid_precision(g), (int)cases[k].want);
    if (compare_grid(g, truth, BT_NX, BT_NY))
      TT_FAIL_("%s: heights not read exactly", cases[k].what);
    check_refined(ctx, cases[k].what, g, truth, BT_NX, cases[k].limit);
    tt_grid_destroy(g);
  }

  /* beyond 2^53: refused, naming the sample; 2^53 itself and -2^53 are
   * doubles */
  int64_t *i64 = raw;
  for (int i = 0; i < n; i++)
    i64[i] = i % 2 ? -((int64_t)1 << 53) : ((int64_t)1 << 53);
  make_typed(tmp_path("i64.tif"), GDT_Int64, BT_NX, BT_NY, raw, NULL, 0, 0);
  tt_grid *g = NULL;
  CHECK_OK(ctx, read_path(ctx, tmp_path("i64.tif"), NULL, &g, NULL));
  if (g)
    CHECK(tt_grid_sample(g, 1, 0) == -9007199254740992.0);
  tt_grid_destroy(g);
  i64[BT_NX * 3 + 5] = ((int64_t)1 << 53) + 1;
  make_typed(tmp_path("i64.tif"), GDT_Int64, BT_NX, BT_NY, raw, NULL, 0, 0);
  CHECK_INT_EQ(read_path(ctx, tmp_path("i64.tif"), NULL, &g, NULL),
               TT_ERR_DATA);
  CHECK(strstr(tt_context_errmsg(ctx), "height at row 3, column 5 is "
               "9007199254740993, beyond 2^53") != NULL);
  i64[BT_NX * 3 + 5] = INT64_MIN; /* declared nodata: not a height */
  make_typed(tmp_path("i64.tif"), GDT_Int64, BT_NX, BT_NY, raw, NULL, 1,
             -9223372036854775808.0);
  CHECK_OK(ctx, read_path(ctx, tmp_path("i64.tif"), NULL, &g, NULL));
  if (g)
    CHECK(isnan(tt_grid_sample(g, 5, 3)));
  tt_grid_destroy(g);
  uint64_t *u64 = raw;
  for (int i = 0; i < n; i++)
    u64[i] = i == 7 ? UINT64_MAX : 5;
  make_typed(tmp_path("u64.tif"), GDT_UInt64, BT_NX, BT_NY, raw, NULL, 0, 0);
  CHECK_INT_EQ(read_path(ctx, tmp_path("u64.tif"), NULL, &g, NULL),
               TT_ERR_DATA);
  CHECK(strstr(tt_context_errmsg(ctx), "column 7 is 18446744073709551615, "
               "beyond 2^53") != NULL);
  const char *o_nd[] = {"SRCNODATA=18446744073709551615", NULL};
  CHECK_OK(ctx, read_path(ctx, tmp_path("u64.tif"), o_nd, &g, NULL));
  if (g) {
    CHECK(isnan(tt_grid_sample(g, 7, 0)));
    CHECK(tt_grid_sample(g, 8, 0) == 5);
    CHECK_INT_EQ(tt_grid_precision(g), TT_PRECISION_FLOAT32);
  }
  tt_grid_destroy(g);

  /* Int32 nodata through the mask, and SRCNODATA compared exactly with
   * Float64 raw values (10^6 + 0.001 is not 10^6 + 0.002, as floats would
   * have it) */
  int32_t *i32 = raw;
  for (int i = 0; i < n; i++)
    i32[i] = i % 13 == 0 ? INT32_MIN : 1073741824 + i;
  make_typed(tmp_path("i32nd.tif"), GDT_Int32, BT_NX, BT_NY, raw, NULL, 1,
             (double)INT32_MIN);
  CHECK_OK(ctx, read_path(ctx, tmp_path("i32nd.tif"), NULL, &g, NULL));
  if (g) {
    CHECK(isnan(tt_grid_sample(g, 0, 0)) && isnan(tt_grid_sample(g, 13, 0)));
    CHECK(tt_grid_sample(g, 1, 0) == 1073741825.0);
    CHECK_INT_EQ(tt_grid_precision(g), TT_PRECISION_FLOAT64);
  }
  tt_grid_destroy(g);
  double *f64 = raw;
  for (int i = 0; i < n; i++)
    f64[i] = 1e6 + 0.001 * (i % 3);
  make_typed(tmp_path("f64nd.tif"), GDT_Float64, BT_NX, BT_NY, raw, NULL, 0,
             0);
  const char *o_f[] = {"SRCNODATA=1000000.001", NULL};
  CHECK_OK(ctx, read_path(ctx, tmp_path("f64nd.tif"), o_f, &g, NULL));
  if (g) {
    CHECK(tt_grid_sample(g, 0, 0) == 1e6);
    CHECK(isnan(tt_grid_sample(g, 1, 0)));
    CHECK(tt_grid_sample(g, 2, 0) == 1e6 + 0.002);
  }
  tt_grid_destroy(g);

  /* Scales: 0.5 and an offset of 100 keep Int16 heights floats; 0.1 does
   * not, and the heights are raw * 0.1 + offset computed in doubles */
  int16_t *i16 = raw;
  for (int i = 0; i < n; i++)
    i16[i] = (int16_t)(i * 37 % 20000 - 10000);
  const double scales[2][2] = {{0.5, 100}, {0.1, -3.7}};
  for (int k = 0; k < 2; k++) {
    make_typed(tmp_path("i16s.tif"), GDT_Int16, BT_NX, BT_NY, raw, NULL, 0,
               0);
    GDALDatasetH ds = GDALOpen(tmp_path("i16s.tif"), GA_Update);
    GDALSetRasterScale(GDALGetRasterBand(ds, 1), scales[k][0]);
    GDALSetRasterOffset(GDALGetRasterBand(ds, 1), scales[k][1]);
    GDALClose(ds);
    for (int i = 0; i < n; i++)
      truth[i] = ((double)i16[i] * scales[k][0] + scales[k][1]) * 1.0;
    CHECK_OK(ctx, read_path(ctx, tmp_path("i16s.tif"), NULL, &g, NULL));
    if (g) {
      CHECK_INT_EQ(tt_grid_precision(g), k == 0 ? TT_PRECISION_FLOAT32
                                                : TT_PRECISION_FLOAT64);
      CHECK_INT_EQ(compare_grid(g, truth, BT_NX, BT_NY), 0);
    }
    tt_grid_destroy(g);
  }

  /* MAX_MEMORY: floats fit, the widening to doubles (12 bytes a sample
   * for a moment) does not */
  for (int i = 0; i < n; i++)
    i32[i] = 1073741824 + i;
  make_typed(tmp_path("i32m.tif"), GDT_Int32, BT_NX, BT_NY, raw, NULL, 0, 0);
  char mm[64];
  snprintf(mm, sizeof mm, "MAX_MEMORY=%d", n * 12 - 1);
  const char *o_m[] = {mm, NULL};
  CHECK_INT_EQ(read_path(ctx, tmp_path("i32m.tif"), o_m, &g, NULL),
               TT_ERR_LIMIT);
  CHECK(strstr(tt_context_errmsg(ctx), "row 0, column 1 (1073741825) is not "
               "exactly a float, so the 37 x 29 heights are kept as doubles")
        != NULL);
  snprintf(mm, sizeof mm, "MAX_MEMORY=%d", n * 12);
  CHECK_OK(ctx, read_path(ctx, tmp_path("i32m.tif"), o_m, &g, NULL));
  tt_grid_destroy(g);
  free(raw);
  free(truth);
}

typedef struct cache_watch {
  GIntBig max_used;
  int calls;
  int stop_at;
} cache_watch;

static int watch_cache(double complete, const char *msg, void *arg)
{
  (void)complete;
  (void)msg;
  cache_watch *w = arg;
  GIntBig used = GDALGetCacheUsed64();
  if (used > w->max_used)
    w->max_used = used;
  w->calls++;
  return w->stop_at == 0 || w->calls < w->stop_at;
}

static void test_cache_and_progress(tt_context *ctx)
{
  /* 4000 x 3000 Int16 in 256 x 256 tiles: 24 MB of raw blocks (and 12 MB of
   * nodata-mask blocks), 48 MB of heights. The block cache must stay near
   * its 2 MiB read limit however large the user's default is. */
  const int nx = 4000, ny = 3000;
  const char *tiled[] = {"TILED=YES", NULL};
  GDALDatasetH cds = GDALCreate(GDALGetDriverByName("GTiff"),
                                tmp_path("big.tif"), nx, ny, 1, GDT_Int16,
                                (char **)tiled);
  GDALRasterBandH cb = GDALGetRasterBand(cds, 1);
  GDALSetRasterNoDataValue(cb, -5);
  GDALFillRaster(cb, 7, 0);
  int16_t last = 1234;
  CHECK(GDALRasterIO(cb, GF_Write, nx - 1, ny - 1, 1, 1, &last, 1, 1,
                     GDT_Int16, 0, 0) == CE_None);
  GDALClose(cds);
  GDALSetCacheMax64((GIntBig)512 << 20);
  GDALDatasetH ds = GDALOpen(tmp_path("big.tif"), GA_ReadOnly);
  cache_watch w = {0, 0, 0};
  tt_grid *g = NULL;
  CHECK_OK(ctx, tt_gdal_read_grid(ctx, GDALGetRasterBand(ds, 1), NULL,
                                  watch_cache, &w, &g, NULL));
  CHECK_INT_LE(w.max_used, (GIntBig)3 << 20);
  CHECK(w.calls >= ny / 256);
  CHECK_INT_EQ(GDALGetCacheMax64(), (GIntBig)512 << 20);
  if (g) {
    const float *z = tt_grid_heights_const(g);
    CHECK_DBL_NEAR(z[0], 7, 0);
    CHECK_DBL_NEAR(z[(size_t)nx * ny - 1], 1234, 0);
  }
  tt_grid_destroy(g);

  /* The callback's 0 stops the read. */
  cache_watch stop = {0, 0, 3};
  g = NULL;
  CHECK_INT_EQ(tt_gdal_read_grid(ctx, GDALGetRasterBand(ds, 1), NULL,
                                 watch_cache, &stop, &g, NULL),
               TT_ERR_INTERRUPTED);
  CHECK(g == NULL);
  CHECK_INT_EQ(stop.calls, 3);
  GDALClose(ds);
}

/* Progress through a geographic read: the ground points' projection
 * reports as it goes (issue 27: a 12000^2 VRT sat at 0 for 30 s), on
 * 0 - 0.8, then the scan on 0.8 - 1; never backwards; a 0 during the
 * projection stops the read. */
typedef struct progress_log {
  double at[4096];
  int projecting[4096];
  int n, stop_at;
} progress_log;

static int log_progress(double complete, const char *msg, void *arg)
{
  progress_log *l = arg;
  if (l->n < 4096) {
    l->at[l->n] = complete;
    l->projecting[l->n] = msg && strcmp(msg, "projecting") == 0;
    l->n++;
  }
  return l->stop_at == 0 || l->n < l->stop_at;
}

static void test_ground_points_progress(tt_context *ctx)
{
  const int nx = 300, ny = 256;
  double *v = terrain_values(nx, ny);
  const double d = 0.0005;
  double gt[6] = {10 - nx / 2 * d, d, 0, 45 + ny / 2 * d, 0, -d};
  raster_spec sp = {GDT_Int16, nx, ny, NULL, 0, 0, 0, 1, 0, 4326, gt, v,
                    NULL, NULL};
  make_raster(tmp_path("geo_progress.tif"), &sp);
  free(v);
  GDALDatasetH ds = GDALOpen(tmp_path("geo_progress.tif"), GA_ReadOnly);
  static progress_log l;
  memset(&l, 0, sizeof l);
  tt_grid *g = NULL;
  CHECK_OK(ctx, tt_gdal_read_grid(ctx, GDALGetRasterBand(ds, 1), NULL,
                                  log_progress, &l, &g, NULL));
  CHECK(g && tt_grid_ground_xy(g) != NULL);
  int proj = 0, mid = 0, scan = 0, backwards = 0, scan_first = -1;
  for (int i = 0; i < l.n; i++) {
    if (i && l.at[i] < l.at[i - 1])
      backwards++;
    if (l.projecting[i]) {
      proj++;
      mid += l.at[i] > 0.0 && l.at[i] < 0.8;
      CHECK(l.at[i] <= 0.8);
      CHECK(scan_first < 0); /* every projection step before the scan */
    } else {
      scan++;
      if (scan_first < 0)
        scan_first = i;
      CHECK(l.at[i] >= 0.8);
    }
  }
  CHECK_INT_EQ(backwards, 0);
  CHECK_INT_EQ(proj, ny / 16);   /* one every 16 rows */
  CHECK(mid >= ny / 16 - 1);     /* values between, not just the ends */
  CHECK(scan >= 2);
  CHECK_DBL_NEAR(l.at[l.n - 1], 1.0, 0);
  tt_grid_destroy(g);

  /* a 0 while projecting stops the read */
  memset(&l, 0, sizeof l);
  l.stop_at = 3;
  g = NULL;
  CHECK_INT_EQ(tt_gdal_read_grid(ctx, GDALGetRasterBand(ds, 1), NULL,
                                 log_progress, &l, &g, NULL),
               TT_ERR_INTERRUPTED);
  CHECK(g == NULL);
  CHECK_INT_EQ(l.n, 3);
  CHECK(l.projecting[2]);
  GDALClose(ds);
}

/* tt_gdal_write_grid: Float32, tiled, DEFLATE, NaN nodata only when
 * needed, CRS, temporary name, refusal without overwrite; read back. */
static void test_write_grid(tt_context *ctx)
{
  const size_t nx = 300, ny = 270; /* more than one 256 x 256 tile */
  float *z = malloc(nx * ny * sizeof *z);
  for (size_t i = 0; i < nx * ny; i++)
    z[i] = (float)(0.125 * (double)(i % 977)) - 40.0f;
  z[17] = z[nx * ny - 1] = NAN;
  tt_grid *g = NULL;
  CHECK_OK(ctx, tt_grid_create_from_floats(ctx, nx, ny, z, &g));
  const double gt[6] = {600000, 25, 0, 5100000, 0, -25};
  CHECK_OK(ctx, tt_grid_set_geotransform(ctx, g, gt));
  OGRSpatialReferenceH srs = OSRNewSpatialReference(NULL);
  OSRImportFromEPSG(srs, 32633);
  char *wkt = NULL;
  OSRExportToWkt(srs, &wkt);
  OSRDestroySpatialReference(srs);

  char dir[300], path[400];
  snprintf(dir, sizeof dir, "%s/wg", tmpdir);
  mkdir(dir, 0777);
  snprintf(path, sizeof path, "%s/grid.tif", dir);
  CHECK_OK(ctx, tt_gdal_write_grid(ctx, g, path, wkt, 0));
  CHECK_INT_EQ(tt_gdal_write_grid(ctx, g, path, wkt, 0), TT_ERR_EXISTS);
  CHECK(strstr(tt_context_errmsg(ctx), path) != NULL);

  GDALDatasetH ds = GDALOpen(path, GA_ReadOnly);
  CHECK(ds != NULL);
  if (ds) {
    GDALRasterBandH b = GDALGetRasterBand(ds, 1);
    CHECK_INT_EQ(GDALGetRasterDataType(b), GDT_Float32);
    int bw = 0, bh = 0, has_nd = 0;
    GDALGetBlockSize(b, &bw, &bh);
    CHECK_INT_EQ(bw, 256);
    CHECK_INT_EQ(bh, 256);
    CHECK_STR_EQ(GDALGetMetadataItem(ds, "COMPRESSION", "IMAGE_STRUCTURE"),
                 "DEFLATE");
    CHECK(isnan(GDALGetRasterNoDataValue(b, &has_nd)));
    CHECK(has_nd);
    tt_grid *back = NULL;
    tt_raster_info *info = NULL;
    CHECK_OK(ctx, tt_gdal_read_grid(ctx, b, NULL, NULL, NULL, &back,
                                    &info));
    if (back) {
      double want_gt[6];
      tt_grid_get_geotransform(back, want_gt);
      for (int i = 0; i < 6; i++)
        CHECK_DBL_NEAR(want_gt[i], gt[i], 0);
      const float *zb = tt_grid_heights_const(back);
      size_t bad = 0;
      for (size_t i = 0; i < nx * ny; i++)
        bad += !(zb[i] == z[i] || (isnan(zb[i]) && isnan(z[i])));
      CHECK_INT_EQ(bad, 0);
      CHECK_INT_EQ(info->valid_samples, nx * ny - 2);
      CHECK(strstr(info->crs_name, "32633") != NULL);
    }
    tt_grid_destroy(back);
    tt_raster_info_destroy(info);
    GDALClose(ds);
  }

  /* Overwrite with a grid without NaN: no nodata declared; no CRS. */
  for (size_t i = 0; i < nx * ny; i++)
    if (isnan(tt_grid_heights(g)[i]))
      tt_grid_heights(g)[i] = 1;
  CHECK_OK(ctx, tt_gdal_write_grid(ctx, g, path, "", 1));
  ds = GDALOpen(path, GA_ReadOnly);
  if (ds) {
    int has_nd = 1;
    GDALGetRasterNoDataValue(GDALGetRasterBand(ds, 1), &has_nd);
    CHECK(!has_nd);
    CHECK(GDALGetSpatialRef(ds) == NULL);
    GDALClose(ds);
  }
  /* Nothing but the final file in the folder; a bad CRS leaves nothing. */
  snprintf(path, sizeof path, "%s/bad.tif", dir);
  CPLPushErrorHandler(CPLQuietErrorHandler);
  CHECK_INT_EQ(tt_gdal_write_grid(ctx, g, path, "not a crs", 0), TT_ERR_ARG);
  CPLPopErrorHandler();
  char **files = VSIReadDir(dir);
  int nfiles = 0;
  for (int i = 0; files && files[i]; i++) {
    if (strcmp(files[i], ".") == 0 || strcmp(files[i], "..") == 0)
      continue;
    nfiles++;
    CHECK_STR_EQ(files[i], "grid.tif");
  }
  CHECK_INT_EQ(nfiles, 1);
  CSLDestroy(files);
  CPLFree(wkt);
  free(z);
  tt_grid_destroy(g);
}

static int test_shared_data(tt_context *ctx)
{
  const char *root = getenv("TT_SHARED_TESTDATA");
  char p[1024];
  struct stat st;
  if (!root || stat(root, &st) != 0)
    return 0;

  /* DTED and GeoTIFF of the same tile give the same grid. */
  tt_grid *a = NULL, *b = NULL;
  tt_raster_info *ia = NULL, *ib = NULL;
  snprintf(p, sizeof p, "%s/gdal_autotest/n43.dt0", root);
  CHECK_OK(ctx, read_path(ctx, p, NULL, &a, &ia));
  snprintf(p, sizeof p, "%s/gdal_autotest/n43.tif", root);
  CHECK_OK(ctx, read_path(ctx, p, NULL, &b, &ib));
  if (a && b) {
    CHECK_INT_EQ(tt_grid_width(a), 121);
    CHECK_INT_EQ(tt_grid_height(a), 121);
    CHECK(memcmp(tt_grid_heights_const(a), tt_grid_heights_const(b),
                 121 * 121 * sizeof(float)) == 0);
    CHECK_STR_EQ(ia->driver, "DTED");
    CHECK_INT_EQ(ia->crs_is_geographic, 1);
    CHECK_INT_EQ(ia->valid_samples, 121 * 121);
    for (int i = 0; i < 4; i++)
      CHECK_DBL_NEAR(ia->frame[i], ib->frame[i], 1e-6);
    /* About 43.5 N: ~80.8 km per degree of longitude. */
    CHECK_DBL_NEAR(hypot(ia->frame[0], ia->frame[2]) / ia->gt[1] /
                       series_lon(43.5 * 3.14159265358979323846 / 180),
                   1.0, 1e-3);
  }
  tt_grid_destroy(a);
  tt_grid_destroy(b);
  tt_raster_info_destroy(ia);
  tt_raster_info_destroy(ib);

  /* USGS DEM in feet, with a nodata collar. */
  snprintf(p, sizeof p, "%s/usgs_dem_san_francisco/sanfranciscos.dem", root);
  CHECK_OK(ctx, read_path(ctx, p, NULL, &a, &ia));
  if (a) {
    CHECK_STR_EQ(ia->z_unit, "ft");
    CHECK_INT_EQ(ia->width, 371);
    CHECK_INT_EQ(ia->height, 466);
    CHECK(ia->nodata_samples > 0);
    CHECK(ia->valid_samples > 371 * 466 * 9 / 10);
    CHECK(strncmp(ia->frame_name, "geotransform", 12) == 0);
    CHECK(strstr(ia->crs_name, "EPSG:26710") != NULL);
  }
  tt_grid_destroy(a);
  tt_raster_info_destroy(ia);

  /* Float32 with NaN declared as nodata, 100% valid. */
  snprintf(p, sizeof p, "%s/Rsagacmd/srtm.tif", root);
  CHECK_OK(ctx, read_path(ctx, p, NULL, &a, &ia));
  if (a) {
    CHECK_INT_EQ(ia->valid_samples, 400 * 400);
    CHECK(strstr(ia->crs_name, "3402") != NULL);
  }
  tt_grid_destroy(a);
  tt_raster_info_destroy(ia);

  /* Single-profile USGS DEM: refused as too narrow. */
  snprintf(p, sizeof p,
           "%s/gdal_autotest/usgsdem_edge_cases/022gdeme_truncated", root);
  CHECK_INT_EQ(read_path(ctx, p, NULL, &a, NULL), TT_ERR_DATA);
  return 1;
}

int main(void)
{
  /* The cache check needs the reader's own limit, which a user's
   * GDAL_CACHEMAX turns off. */
  unsetenv("GDAL_CACHEMAX");
  GDALAllRegister();
  snprintf(tmpdir, sizeof tmpdir, "/tmp/tt_gdal_read_XXXXXX");
  if (!mkdtemp(tmpdir)) {
    perror("mkdtemp");
    return 1;
  }
  tt_context *ctx = tt_context_create();
  TT_RUN(test_int16_nodata_tiled_and_striped(ctx));
  TT_RUN(test_float32_nan_nodata(ctx));
  TT_RUN(test_scale_offset_z_factor(ctx));
  TT_RUN(test_other_formats(ctx));
  TT_RUN(test_geographic_frame(ctx));
  TT_RUN(test_refusals(ctx));
  TT_RUN(test_band_types(ctx));
  TT_RUN(test_cache_and_progress(ctx));
  TT_RUN(test_ground_points_progress(ctx));
  TT_RUN(test_write_grid(ctx));
  int shared = test_shared_data(ctx);
  tt_context_destroy(ctx);
  VSIRmdirRecursive(tmpdir);
  if (!shared && !tt_test_failures)
    TT_SKIP("synthetic checks passed; TT_SHARED_TESTDATA absent, real DEMs "
            "not read");
  TT_TEST_DONE();
}
