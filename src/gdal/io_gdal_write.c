/*
 * io_gdal_write.c -- writing a grid as a GeoTIFF (synthetic terrains,
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
 * Workload: one pass over the heights to look for NaN, one RasterIO; GDAL's
 * block cache holds dirty tiles up to its limit.
 */
#include "base/internal.h"
#include "terratin/terratin_gdal.h"

#include <cpl_error.h>

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
