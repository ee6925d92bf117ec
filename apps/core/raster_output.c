/*
 * raster_output.c -- apps/core/: the command's core, what every command's
 * folder shares. This file: the raster writer of rasterize and of eval
 * -error_raster: the driver (-of, else the path's extension, else GTiff) that
 * can write a float band, the band type (Float64 for a grid of doubles, else
 * Float32), the creation options (GTiff: tiled, DEFLATE, unless -co says
 * otherwise), the DEM's geotransform and CRS, and the commit of the temporary
 * name.
 */
#include "app.h"

#include <cpl_conv.h>
#include <cpl_string.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

/* A raster driver that can write a float band. */
static int can_write_floats(GDALDriverH drv)
{
  const char *types =
      GDALGetMetadataItem(drv, GDAL_DMD_CREATIONDATATYPES, NULL);
  return GDALGetMetadataItem(drv, GDAL_DCAP_RASTER, NULL) &&
         (GDALGetMetadataItem(drv, GDAL_DCAP_CREATE, NULL) ||
          GDALGetMetadataItem(drv, GDAL_DCAP_CREATECOPY, NULL)) &&
         (!types || strstr(types, "Float32") || strstr(types, "Float64"));
}

/* Whether the space-separated list holds ext (any case). */
static int has_ext(const char *list, const char *ext)
{
  size_t n = strlen(ext);
  for (const char *p = list; p && *p;) {
    while (*p == ' ')
      p++;
    const char *e = strchr(p, ' ');
    size_t len = e ? (size_t)(e - p) : strlen(p);
    if (len == n && n && strncasecmp(p, ext, n) == 0)
      return 1;
    p = e;
  }
  return 0;
}

/* No -of: GTiff for .tif, .tiff or no extension, else the first driver
 * that claims the extension and writes floats (as GDAL's utilities guess);
 * an extension only drivers without floats claim (.png) is theirs, refused
 * by the caller; an extension no driver claims gets GTiff and a warning. */
static const char *guess_driver(app_run *r, const char *path)
{
  const char *claimed = NULL;
  const char *base = strrchr(path, '/');
  const char *dot = strrchr(base ? base + 1 : path, '.');
  if (!dot || !dot[1] || strcasecmp(dot, ".tif") == 0 ||
      strcasecmp(dot, ".tiff") == 0)
    return "GTiff";
  for (int i = 0; i < GDALGetDriverCount(); i++) {
    GDALDriverH d = GDALGetDriver(i);
    const char *exts = GDALGetMetadataItem(d, GDAL_DMD_EXTENSIONS, NULL);
    if (!exts)
      exts = GDALGetMetadataItem(d, GDAL_DMD_EXTENSION, NULL);
    if (!exts || !has_ext(exts, dot + 1) ||
        !GDALGetMetadataItem(d, GDAL_DCAP_RASTER, NULL) ||
        strcmp(GDALGetDriverShortName(d), "MEM") == 0)
      continue;
    if (can_write_floats(d))
      return GDALGetDriverShortName(d);
    if (!claimed)
      claimed = GDALGetDriverShortName(d);
  }
  if (claimed)
    return claimed;
  tt__app_warn(&r->msg, "%s: no raster driver that writes floats claims "
               "the extension '%s'; writing a GeoTIFF (use -of to choose)",
               path, dot);
  return "GTiff";
}

GDALDriverH tt__app_raster_driver(app_run *r, const char *of,
                                  const char *path)
{
  char what[300]; /* "-of 'X'", or the output whose extension chose X */
  const char *cmd = tt__app_command_name(r->s->command);
  if (of || !path) {
    of = of ? of : "GTiff";
    snprintf(what, sizeof what, "-of '%s'", of);
  } else {
    of = guess_driver(r, path);
    snprintf(what, sizeof what, "%.200s (by its extension: %s)", path, of);
  }
  GDALDriverH drv = GDALGetDriverByName(of);
  if (!drv) {
    tt__app_fail(r, TT_APP_EXIT_USAGE, TT_ERR_ARG, NULL,
                 "%s: %s: no such GDAL driver (see 'gdalinfo --formats')",
                 cmd, what);
    return NULL;
  }
  if (!GDALGetMetadataItem(drv, GDAL_DCAP_RASTER, NULL) ||
      (!GDALGetMetadataItem(drv, GDAL_DCAP_CREATE, NULL) &&
       !GDALGetMetadataItem(drv, GDAL_DCAP_CREATECOPY, NULL))) {
    tt__app_fail(r, TT_APP_EXIT_USAGE, TT_ERR_ARG, NULL,
                 "%s: %s: the driver cannot write rasters", cmd, what);
    return NULL;
  }
  /* A driver that lists its band types must take floats. */
  const char *types =
      GDALGetMetadataItem(drv, GDAL_DMD_CREATIONDATATYPES, NULL);
  if (types && !strstr(types, "Float32") && !strstr(types, "Float64")) {
    tt__app_fail(r, TT_APP_EXIT_USAGE, TT_ERR_ARG, NULL,
                 "%s: %s: the driver cannot write Float32 or Float64 bands "
                 "(it takes %s); choose another with -of", cmd, what, types);
    return NULL;
  }
  return drv;
}

tt_status tt__app_write_raster(app_run *r, tt_output *out, GDALDriverH drv,
                               const tt_grid *grid,
                               const tt_raster_info *info,
                               const double *values)
{
  const char *path = tt_output_final_path(out);
  const char *name = GDALGetDriverShortName(drv);
  GDALDataType type = tt_grid_precision(grid) == TT_PRECISION_FLOAT64
                          ? GDT_Float64
                          : GDT_Float32;
  /* Doubles only where a float cannot hold every height of the DEM. */
  const char *types =
      GDALGetMetadataItem(drv, GDAL_DMD_CREATIONDATATYPES, NULL);
  if (types && type == GDT_Float64 && !strstr(types, "Float64"))
    type = GDT_Float32;
  if (types && type == GDT_Float32 && !strstr(types, "Float32"))
    type = GDT_Float64;
  char **co = NULL;
  if (strcmp(name, "GTiff") == 0) {
    co = CSLSetNameValue(co, "TILED", "YES");
    co = CSLSetNameValue(co, "COMPRESS", "DEFLATE");
    co = CSLSetNameValue(co, "PREDICTOR", "3"); /* floating point */
    co = CSLSetNameValue(co, "BIGTIFF", "IF_SAFER");
  }
  for (size_t i = 0; r->s->co[i]; i++) {
    char *key = NULL;
    const char *value = CPLParseNameValue(r->s->co[i], &key);
    if (key && value)
      co = CSLSetNameValue(co, key, value);
    CPLFree(key);
  }
  r->msg.last[0] = '\0';
  unsigned failures = r->msg.failures;
  tt_status st = tt_gdal_write_raster(
      r->ctx, drv, tt_output_temp_path(out), path, tt_grid_width(grid),
      tt_grid_height(grid), values, type, info->gt, info->crs_wkt,
      (CSLConstList)co, tt__app_phase_fn, &r->prog);
  CSLDestroy(co);
  if (st != TT_OK)
    return tt__app_fail_write(r, st, path, tt_output_temp_path(out), NULL);
  if (r->msg.failures != failures) /* a driver's failure it survived */
    return tt__app_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_IO, path, "%s",
                        r->msg.last);
  st = tt_output_commit(r->ctx, out);
  if (st == TT_ERR_EXISTS)
    return tt__app_fail_exists(r, path);
  if (st != TT_OK)
    return tt__app_fail_tt(r, st, path);
  return TT_OK;
}

