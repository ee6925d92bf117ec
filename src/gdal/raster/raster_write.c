/*
 * src/gdal/raster/ -- the rasters: a band read into a grid, a grid written
 * as a GeoTIFF.
 *
 * raster_write.c -- writing a grid as a GeoTIFF (synthetic terrains,
 * residual or reconstructed grids).
 *
 * Single band, Float32 (Float64 for a grid of doubles, so no height is
 * rounded), tiled and DEFLATE-compressed (BIGTIFF when it may
 * be needed), the grid's geotransform, the given CRS, and nodata = NaN only
 * when the grid holds NaN. The file is made under a temporary name beside
 * the final one (tt_output) and renamed when GDAL has closed it without
 * error, so a failed write leaves nothing and an existing file is replaced
 * only with overwrite.
 *
 * tt_gdal_write_raster writes any array of doubles on a DEM's grid (the
 * TIN rasterized, TIN - DEM) with any GDAL raster driver, into a file the
 * caller named (the temporary name of its tt_output): Create and strips of
 * rows, polling the progress callback between strips so an interrupt
 * stops a slow write, or, for drivers that only copy (AAIGrid, XYZ), an
 * in-memory dataset handed to CreateCopy with the same callback.
 *
 * Workload: one pass over the heights to look for NaN, one RasterIO (or
 * one per strip of rows); GDAL's block cache holds dirty tiles up to its
 * limit.
 */
#include "base/internal.h"
#include "terratin/terratin_gdal.h"

#include <cpl_error.h>
#include <cpl_string.h>

#include <math.h>
#include <stdio.h>
#include <string.h>

static int has_nan(const tt_grid *grid)
{
  const size_t n = tt_grid_width(grid) * tt_grid_height(grid);
  for (size_t i = 0; i < n; i++)
    if (isnan(tt__grid_z(grid, i)))
      return 1;
  return 0;
}

static const char *gdal_msg(void)
{
  const char *m = CPLGetLastErrorMsg();
  return m && *m ? m : "no details from GDAL";
}

tt_status tt_gdal_write_grid(tt_context *ctx, const tt_grid *grid,
                             const char *path, const char *srs_wkt,
                             int overwrite)
{
  if (!grid || !path)
    return tt__error(ctx, TT_ERR_ARG, "grid and path must not be NULL");
  GDALDriverH drv = GDALGetDriverByName("GTiff");
  if (!drv)
    return tt__error(ctx, TT_ERR_FORMAT, "the GTiff driver is not "
                     "registered (call GDALAllRegister() first)");
  const size_t nx = tt_grid_width(grid), ny = tt_grid_height(grid);
  const int f64 = tt_grid_precision(grid) == TT_PRECISION_FLOAT64;
  const GDALDataType type = f64 ? GDT_Float64 : GDT_Float32;
  const size_t elem = f64 ? sizeof(double) : sizeof(float);
  const void *heights = f64 ? (const void *)tt_grid_heights_f64_const(grid)
                            : (const void *)tt_grid_heights_const(grid);

  tt_output *out = NULL;
  tt_status s = tt_output_begin(ctx, path, "GTiff", overwrite, &out);
  if (s != TT_OK)
    return s;

  const char *const create_options[] = {"TILED=YES", "COMPRESS=DEFLATE",
                                        "BIGTIFF=IF_SAFER", NULL};
  CPLErrorReset();
  GDALDatasetH ds = GDALCreate(drv, tt_output_temp_path(out), (int)nx,
                               (int)ny, 1, type,
                               (char **)create_options);
  if (!ds) {
    s = tt__error(ctx, TT_ERR_IO, "cannot create %s: %s", path, gdal_msg());
    goto done;
  }
  double gt[6];
  tt_grid_get_geotransform(grid, gt);
  GDALSetGeoTransform(ds, gt);
  if (srs_wkt && *srs_wkt && GDALSetProjection(ds, srs_wkt) != CE_None)
    s = tt__error(ctx, TT_ERR_ARG, "%s: the CRS could not be set: %s", path,
                  gdal_msg());
  GDALRasterBandH band = GDALGetRasterBand(ds, 1);
  if (s == TT_OK && has_nan(grid))
    GDALSetRasterNoDataValue(band, NAN);
  /* GF_Write only reads the buffer: the cast drops const for GDAL's
   * signature, nothing is modified. */
  if (s == TT_OK &&
      GDALRasterIOEx(band, GF_Write, 0, 0, (int)nx, (int)ny,
                     (void *)heights, (int)nx, (int)ny, type,
                     (GSpacing)elem, (GSpacing)(nx * elem), NULL) != CE_None)
    s = tt__error(ctx, TT_ERR_IO, "cannot write %s: %s", path, gdal_msg());
  CPLErrorReset();
  GDALClose(ds); /* flushes the tiles: errors show up here */
  if (s == TT_OK && CPLGetLastErrorType() >= CE_Failure)
    s = tt__error(ctx, TT_ERR_IO, "cannot write %s: %s", path, gdal_msg());
  if (s == TT_OK)
    s = tt_output_commit(ctx, out);

done:
  tt_output_destroy(out); /* removes the temporary file unless committed */
  return s;
}

/* The app's progress callback as GDAL's (CreateCopy). */
typedef struct write_progress {
  tt_progress_fn fn;
  void *arg;
} write_progress;

static int CPL_STDCALL gdal_progress(double complete, const char *message,
                                     void *arg)
{
  const write_progress *p = arg;
  (void)message;
  return p->fn ? p->fn(complete, NULL, p->arg) : 1;
}

tt_status tt_gdal_write_raster(tt_context *ctx, GDALDriverH drv,
                               const char *path, const char *name,
                               size_t nx, size_t ny, const double *values,
                               GDALDataType type, const double gt[6],
                               const char *srs_wkt,
                               CSLConstList create_options,
                               tt_progress_fn progress, void *progress_arg)
{
  if (!drv || !path || !values || !gt || nx == 0 || ny == 0)
    return tt__error(ctx, TT_ERR_ARG, "driver, path, values and "
                     "geotransform must be given");
  if (!name)
    name = path;
  if (nx > INT32_MAX || ny > INT32_MAX)
    return tt__error(ctx, TT_ERR_LIMIT, "%s: %zu x %zu samples are more "
                     "than GDAL's 2^31 - 1 a side", name, nx, ny);
  if (type != GDT_Float32 && type != GDT_Float64)
    return tt__error(ctx, TT_ERR_ARG, "%s: the band type must be Float32 "
                     "or Float64", name);
  const int can_create =
      GDALGetMetadataItem(drv, GDAL_DCAP_CREATE, NULL) != NULL;
  write_progress wp = {progress, progress_arg};
  tt_status s = TT_OK;
  GDALDatasetH ds = NULL, out = NULL;
  CPLErrorReset();
  if (can_create)
    ds = GDALCreate(drv, path, (int)nx, (int)ny, 1, type,
                    (char **)create_options);
  else
    ds = GDALCreate(GDALGetDriverByName("MEM"), "", (int)nx, (int)ny, 1,
                    type, NULL);
  if (!ds)
    return tt__error(ctx, TT_ERR_IO, "cannot create %s: %s", name,
                     gdal_msg());
  GDALSetGeoTransform(ds, (double *)gt); /* only read: GDAL's signature */
  if (srs_wkt && *srs_wkt && GDALSetProjection(ds, srs_wkt) != CE_None) {
    s = tt__error(ctx, TT_ERR_ARG, "%s: the CRS could not be set: %s", name,
                  gdal_msg());
    goto done;
  }
  GDALRasterBandH band = GDALGetRasterBand(ds, 1);
  GDALSetRasterNoDataValue(band, NAN);
  /* Strips of rows: a whole number of the driver's blocks, at least 64
   * rows and 1 M samples, so that each strip writes whole tiles. */
  int bx = 0, by = 0;
  GDALGetBlockSize(band, &bx, &by);
  size_t strip = by > 0 ? (size_t)by : 1;
  while (strip < 64 || strip * nx < ((size_t)1 << 20))
    strip *= 2;
  for (size_t r0 = 0; r0 < ny; r0 += strip) {
    size_t rows = ny - r0 < strip ? ny - r0 : strip;
    if (can_create && progress &&
        !progress((double)r0 / (double)ny, NULL, progress_arg)) {
      s = tt__error(ctx, TT_ERR_INTERRUPTED, "%s: interrupted", name);
      goto done;
    }
    /* GF_Write only reads the buffer (GDAL's signature drops const). */
    if (GDALRasterIOEx(band, GF_Write, 0, (int)r0, (int)nx, (int)rows,
                       (void *)(values + r0 * nx), (int)nx, (int)rows,
                       GDT_Float64, (GSpacing)sizeof(double),
                       (GSpacing)(nx * sizeof(double)), NULL) != CE_None) {
      s = tt__error(ctx, TT_ERR_IO, "cannot write %s: %s", name, gdal_msg());
      goto done;
    }
  }
  if (!can_create) {
    CPLErrorReset();
    out = GDALCreateCopy(drv, path, ds, FALSE, (char **)create_options,
                         gdal_progress, &wp);
    if (!out) {
      s = CPLGetLastErrorNo() == CPLE_UserInterrupt
              ? tt__error(ctx, TT_ERR_INTERRUPTED, "%s: interrupted", name)
              : tt__error(ctx, TT_ERR_IO, "cannot write %s: %s", name,
                          gdal_msg());
      goto done;
    }
  }

done:
  CPLErrorReset();
  if (out)
    GDALClose(out);
  GDALClose(ds); /* flushes the tiles: errors show up here */
  if (s == TT_OK && CPLGetLastErrorType() >= CE_Failure)
    s = tt__error(ctx, TT_ERR_IO, "cannot write %s: %s", name, gdal_msg());
  if (s == TT_OK && progress && !progress(1.0, NULL, progress_arg))
    s = tt__error(ctx, TT_ERR_INTERRUPTED, "%s: interrupted", name);
  return s;
}
