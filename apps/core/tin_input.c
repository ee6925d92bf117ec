/*
 * tin_input.c -- apps/core/: the command's core, what every command's folder
 * shares. This file: a TIN to read: the vector dataset opened (explaining in
 * one line why not) and its triangle layer picked, as eval, optimize and
 * rasterize read it (tt__app_read_dem_and_tin in dem.c, and eval).
 *
 * The layer is -layer, else "triangles" or "*_triangles" (a terratin
 * output, a Shapefile prefix), else the first polygon layer, else the
 * first layer of mixed geometries (DXF's "entities").
 */
#include "app.h"

#include <cpl_conv.h>
#include <cpl_string.h>
#include <cpl_vsi.h>
#include <ogr_api.h>
#include <ogr_srs_api.h>

#include <string.h>
#include <strings.h>

static int is_polygon_layer(OGRLayerH layer)
{
  OGRwkbGeometryType t = wkbFlatten(OGR_L_GetGeomType(layer));
  return t == wkbPolygon || t == wkbMultiPolygon || t == wkbTIN ||
         t == wkbTriangle || t == wkbPolyhedralSurface;
}

static int ends_with(const char *s, const char *suffix)
{
  size_t n = strlen(s), m = strlen(suffix);
  return n >= m && strcasecmp(s + n - m, suffix) == 0;
}

/* -layer, else "triangles" or "*_triangles", else the first polygon layer
 * (eval, optimize). */
OGRLayerH tt__app_tin_layer(app_run *r, GDALDatasetH ds)
{
  const char *path = r->s->tin;
  int n = GDALDatasetGetLayerCount(ds);
  if (r->s->layer) {
    OGRLayerH l = GDALDatasetGetLayerByName(ds, r->s->layer);
    if (!l) {
      tt__app_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_ARG, path,
               "no layer named '%s'", r->s->layer);
      return NULL;
    }
    /* A layer of points or lines is no TIN: say what it holds. */
    OGRwkbGeometryType t = OGR_L_GetGeomType(l);
    if (t != wkbUnknown && !is_polygon_layer(l)) {
      tt__app_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_DATA, path,
                   "layer '%s' holds %s geometries, not triangles (polygons "
                   "or TINs)", r->s->layer,
                   t == wkbNone ? "no" : OGRGeometryTypeToName(t));
      return NULL;
    }
    return l;
  }
  for (int pass = 0; pass < 3; pass++) {
    for (int i = 0; i < n; i++) {
      OGRLayerH l = GDALDatasetGetLayer(ds, i);
      const char *name = OGR_L_GetName(l);
      if (pass == 0 && name &&
          (strcasecmp(name, "triangles") == 0 ||
           ends_with(name, "_triangles")))
        return l;
      if (pass == 1 && is_polygon_layer(l))
        return l;
      if (pass == 2 && OGR_L_GetGeomType(l) == wkbUnknown)
        return l;
    }
  }
  tt__app_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_FORMAT, path,
           "no triangles layer and no polygon layer (%d layer%s)", n,
           n == 1 ? "" : "s");
  return NULL;
}

int tt__app_layer_in_other_crs(OGRLayerH layer, const tt_raster_info *info)
{
  static const char *const same_opts[] = {
      "IGNORE_DATA_AXIS_TO_SRS_AXIS_MAPPING=YES",
      "CRITERION=EQUIVALENT_EXCEPT_AXIS_ORDER_GEOGCRS", NULL};
  OGRSpatialReferenceH lsrs = OGR_L_GetSpatialRef(layer);
  if (!lsrs || !info->crs_wkt || !*info->crs_wkt)
    return 0;
  OGRSpatialReferenceH rsrs = OSRNewSpatialReference(info->crs_wkt);
  int other =
      rsrs && !OSRIsSameEx(rsrs, lsrs, (const char *const *)same_opts);
  if (rsrs)
    OSRDestroySpatialReference(rsrs);
  return other;
}

GDALDatasetH tt__app_open_vector(app_run *r, const char *path)
{
  VSIStatBufL sb;
  r->msg.last[0] = '\0';
  GDALDatasetH ds = GDALOpenEx(path, GDAL_OF_VECTOR | GDAL_OF_READONLY |
                                         GDAL_OF_VERBOSE_ERROR,
                               NULL, NULL, NULL);
  if (ds)
    return ds;
  if (VSIStatL(path, &sb) != 0 && !strchr(path, ':') &&
      strncmp(path, "/vsi", 4) != 0) {
    tt__app_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_IO, path,
             "no such file or directory");
    return NULL;
  }
  tt__app_quiet_push(&r->msg);
  GDALDatasetH ras = GDALOpenEx(path, GDAL_OF_RASTER | GDAL_OF_READONLY,
                                NULL, NULL, NULL);
  CPLPopErrorHandler();
  if (ras) {
    GDALClose(ras);
    int k = tt__app_arg_number(r, path);
    if (k)
      tt__app_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_FORMAT, NULL,
                   "%s: %s (argument %d) is a raster; the TIN (a vector "
                   "dataset of triangles) comes after the DEM",
                   tt__app_command_name(r->s->command),
                   tt__app_shown(r, path), k);
    else
      tt__app_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_FORMAT, path,
                   "is a raster, not a vector dataset of triangles");
    return NULL;
  }
  if (r->msg.last[0] && !strstr(r->msg.last, "not recognized"))
    tt__app_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_FORMAT, path,
             "cannot be opened as a vector dataset: %s", r->msg.last);
  else
    tt__app_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_FORMAT, path,
             "not a vector format GDAL can read");
  return NULL;
}

