/*
 * ogr_readback.c -- apps/simplify/, the simplify command: whether an OGR
 * format keeps the TIN it is given. The dry run (ogr_output.c) writes a
 * TIN of two triangles under /vsimem/; this reads that dataset back with
 * the same driver and compares every x, y and z read with the vertices
 * written, in the TIN's CRS (a driver that writes in a CRS of its own,
 * as KML does, is read back through it). A format that drops the heights
 * (MapInfo), flattens a triangle to one height (DXF's hatches), rounds the
 * coordinates or writes map units as longitude/latitude (GPX) is found
 * here, before the DEM is read.
 *
 * Tolerances: x and y within a millionth of the DEM's pixel, z within
 * 1e-9 of its magnitude (at least 1e-9): a format that writes doubles
 * with 15 or more significant digits passes, one that rounds to
 * centimetres or to single precision does not.
 */
#include "simplify.h"

#include <cpl_conv.h>
#include <cpl_string.h>
#include <ogr_api.h>
#include <ogr_srs_api.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct readback {
  size_t nv;
  double *x, *y, *z;   /* the vertices written, in the TIN's CRS */
  int *seen;
  double tol_xy;
  OGRCoordinateTransformationH ct; /* read CRS -> the TIN's, or NULL */
  const char *read_crs;            /* its name, for messages */
  char *why;
  size_t n;
  int bad;
} readback;

static double z_tolerance(double z)
{
  return 1e-9 * fmax(1.0, fabs(z));
}

static int check_point(readback *rb, double x, double y, double z)
{
  if (rb->ct && !OCTTransform(rb->ct, 1, &x, &y, &z)) {
    if (!rb->bad)
      snprintf(rb->why, rb->n, "a vertex read back at (%.10g, %.10g) in "
               "%s does not map back to the TIN's CRS: the format wrote "
               "the TIN's coordinates as %s ones", x, y, rb->read_crs,
               rb->read_crs);
    rb->bad = 1;
    return 0;
  }
  size_t best = 0;
  double bestd = INFINITY;
  for (size_t i = 0; i < rb->nv; i++) {
    double d = hypot(x - rb->x[i], y - rb->y[i]);
    if (d < bestd) {
      bestd = d;
      best = i;
    }
  }
  if (fabs(x - rb->x[best]) > rb->tol_xy ||
      fabs(y - rb->y[best]) > rb->tol_xy) {
    snprintf(rb->why, rb->n, "a vertex written at (%.12g, %.12g) reads "
             "back at (%.12g, %.12g)", rb->x[best], rb->y[best], x, y);
    rb->bad = 1;
    return 0;
  }
  if (!(fabs(z - rb->z[best]) <= z_tolerance(rb->z[best]))) {
    snprintf(rb->why, rb->n, "a vertex written at height %.9g reads back "
             "at %.9g", rb->z[best], z);
    rb->bad = 1;
    return 0;
  }
  rb->seen[best] = 1;
  return 1;
}

/* Every point of g (rings, parts, triangles of a TIN). */
static int check_geometry(readback *rb, OGRGeometryH g)
{
  int parts = OGR_G_GetGeometryCount(g);
  if (parts > 0) {
    for (int i = 0; i < parts; i++)
      if (!check_geometry(rb, OGR_G_GetGeometryRef(g, i)))
        return 0;
    return 1;
  }
  int np = OGR_G_GetPointCount(g);
  for (int i = 0; i < np; i++)
    if (!check_point(rb, OGR_G_GetX(g, i), OGR_G_GetY(g, i),
                     OGR_G_GetZ(g, i)))
      return 0;
  return 1;
}

/* A polygon of one closed ring of three corners (POLYGON, TRIANGLE), or a
 * collection of one (MULTIPOLYGON, TIN, POLYHEDRALSURFACE). */
static int is_triangle(OGRGeometryH g)
{
  OGRwkbGeometryType t = wkbFlatten(OGR_G_GetGeometryType(g));
  if (t == wkbMultiPolygon || t == wkbTIN || t == wkbPolyhedralSurface)
    return OGR_G_GetGeometryCount(g) == 1 &&
           is_triangle(OGR_G_GetGeometryRef(g, 0));
  if (t != wkbPolygon && t != wkbTriangle)
    return 0;
  if (OGR_G_GetGeometryCount(g) != 1)
    return 0;
  OGRGeometryH ring = OGR_G_GetGeometryRef(g, 0);
  int np = OGR_G_GetPointCount(ring);
  if (np == 3)
    return 1;
  return np == 4 && OGR_G_GetX(ring, 0) == OGR_G_GetX(ring, 3) &&
         OGR_G_GetY(ring, 0) == OGR_G_GetY(ring, 3);
}

/* The CRS the coordinates are compared in: the layer's read back, else
 * what was written (t_srs, else the TIN's). */
static int set_transform(readback *rb, OGRLayerH layer,
                         OGRSpatialReferenceH tin_srs,
                         OGRSpatialReferenceH written,
                         OGRSpatialReferenceH *imposed)
{
  OGRSpatialReferenceH read = OGR_L_GetSpatialRef(layer);
  OGRSpatialReferenceH from = read ? read : written;
  if (rb->ct)
    OCTDestroyCoordinateTransformation(rb->ct);
  rb->ct = NULL;
  rb->read_crs = from ? OSRGetName(from) : "no CRS";
  if (!rb->read_crs)
    rb->read_crs = "its CRS";
  if (read && written && !OSRIsSame(read, written) &&
      OSRIsGeographic(read) && !*imposed)
    *imposed = OSRClone(read);
  if (!from || !tin_srs || OSRIsSame(from, tin_srs))
    return 1;
  OGRSpatialReferenceH f = OSRClone(from);
  OSRSetAxisMappingStrategy(f, OAMS_TRADITIONAL_GIS_ORDER);
  rb->ct = OCTNewCoordinateTransformation(f, tin_srs);
  OSRDestroySpatialReference(f);
  if (!rb->ct) {
    snprintf(rb->why, rb->n, "its coordinates, read back in %s, cannot be "
             "mapped to the TIN's CRS", rb->read_crs);
    rb->bad = 1;
    return 0;
  }
  return 1;
}

/* The dataset name opened with drv alone; GPX keeps a point's height in
 * <ele>, which GDAL 3.6's reader gives as Z only when asked
 * (GPX_ELE_AS_25D). */
static GDALDatasetH open_back(GDALDriverH drv, const char *name)
{
  const char *allowed[] = {GDALGetDriverShortName(drv), NULL};
  int gpx = strcmp(allowed[0], "GPX") == 0;
  char *old = NULL;
  if (gpx) {
    const char *o = CPLGetThreadLocalConfigOption("GPX_ELE_AS_25D", NULL);
    old = o ? CPLStrdup(o) : NULL;
    CPLSetThreadLocalConfigOption("GPX_ELE_AS_25D", "YES");
  }
  GDALDatasetH ds = GDALOpenEx(name, GDAL_OF_VECTOR | GDAL_OF_READONLY,
                               allowed, NULL, NULL);
  if (gpx) {
    CPLSetThreadLocalConfigOption("GPX_ELE_AS_25D", old);
    CPLFree(old);
  }
  return ds;
}

/* One feature's geometry g of layer: a point or a triangle, with Z, every
 * point one written; counted. */
static void check_feature(readback *rb, OGRLayerH layer, OGRGeometryH g,
                          size_t *points, size_t *polygons)
{
  if (OGR_G_IsEmpty(g)) {
    snprintf(rb->why, rb->n, "a feature of layer %s reads back with an "
             "empty geometry", OGR_L_GetName(layer));
    rb->bad = 1;
    return;
  }
  OGRwkbGeometryType t = wkbFlatten(OGR_G_GetGeometryType(g));
  if (t == wkbPoint) {
    (*points)++;
  } else if (is_triangle(g)) {
    (*polygons)++;
  } else {
    snprintf(rb->why, rb->n, "a triangle reads back as a %s",
             OGR_G_GetGeometryName(g));
    rb->bad = 1;
    return;
  }
  if (!OGR_G_Is3D(g)) {
    snprintf(rb->why, rb->n, "it drops the heights: the %s read back has "
             "no Z", OGR_G_GetGeometryName(g));
    rb->bad = 1;
    return;
  }
  check_geometry(rb, g);
}

int tt__app_read_back(GDALDriverH drv, const char *name, unsigned layers,
                      const tt_tin *tin,
                      OGRSpatialReferenceH tin_srs, const char *t_srs,
                      double tol_xy, char *why, size_t n, char **imposed)
{
  *imposed = NULL;
  readback rb;
  memset(&rb, 0, sizeof rb);
  rb.why = why;
  rb.n = n;
  rb.tol_xy = tol_xy;
  rb.nv = tt_tin_vertex_count(tin);
  rb.x = calloc(rb.nv ? rb.nv : 1, sizeof *rb.x);
  rb.y = calloc(rb.nv ? rb.nv : 1, sizeof *rb.y);
  rb.z = calloc(rb.nv ? rb.nv : 1, sizeof *rb.z);
  rb.seen = calloc(rb.nv ? rb.nv : 1, sizeof *rb.seen);
  OGRSpatialReferenceH written = NULL, geo = NULL;
  GDALDatasetH ds = NULL;
  int ok = 0;
  if (!rb.x || !rb.y || !rb.z || !rb.seen) {
    snprintf(why, n, "out of memory");
    goto done;
  }
  for (size_t i = 0; i < rb.nv; i++) {
    tt_vertex_info v;
    tt_tin_vertex(tin, i, &v);
    rb.x[i] = v.x;
    rb.y[i] = v.y;
    rb.z[i] = v.z;
  }
  if (t_srs) {
    written = OSRNewSpatialReference(NULL);
    if (OSRSetFromUserInput(written, t_srs) != OGRERR_NONE) {
      OSRDestroySpatialReference(written);
      written = NULL;
    } else {
      OSRSetAxisMappingStrategy(written, OAMS_TRADITIONAL_GIS_ORDER);
    }
  } else if (tin_srs) {
    written = OSRClone(tin_srs);
  }
  ds = open_back(drv, name);
  if (!ds) {
    snprintf(why, n, "what it wrote cannot be read back to check it");
    goto done;
  }
  size_t polygons = 0, points = 0;
  for (int l = 0; l < GDALDatasetGetLayerCount(ds) && !rb.bad; l++) {
    OGRLayerH layer = GDALDatasetGetLayer(ds, l);
    int transform_set = 0;
    OGR_L_ResetReading(layer);
    OGRFeatureH f;
    while (!rb.bad && (f = OGR_L_GetNextFeature(layer)) != NULL) {
      OGRGeometryH g = OGR_F_GetGeometryRef(f);
      if (g && !OGR_G_IsEmpty(g) && !transform_set &&
          !set_transform(&rb, layer, tin_srs, written, &geo)) {
        OGR_F_Destroy(f);
        break;
      }
      transform_set = transform_set || (g && !OGR_G_IsEmpty(g));
      if (g)
        check_feature(&rb, layer, g, &points, &polygons);
      OGR_F_Destroy(f);
    }
  }
  size_t nt = tt_tin_triangle_count(tin);
  if (!rb.bad && (layers & 1u) && polygons != nt) {
    snprintf(why, n, "%zu of the %zu triangles written read back",
             polygons, nt);
    rb.bad = 1;
  }
  if (!rb.bad && (layers & 2u) && points != rb.nv) {
    snprintf(why, n, "%zu of the %zu vertices written read back", points,
             rb.nv);
    rb.bad = 1;
  }
  for (size_t i = 0; i < rb.nv && !rb.bad; i++)
    if (!rb.seen[i]) {
      snprintf(why, n, "the vertex written at (%.12g, %.12g) does not "
               "read back", rb.x[i], rb.y[i]);
      rb.bad = 1;
    }
  ok = !rb.bad;
  if (!ok && geo && !t_srs) {
    /* the driver writes in a geographic CRS of its own (GPX): give the
     * caller the CRS to write in */
    const char *auth = OSRGetAuthorityName(geo, NULL);
    const char *code = OSRGetAuthorityCode(geo, NULL);
    if (auth && code) {
      *imposed = CPLStrdup(CPLSPrintf("%s:%s", auth, code));
    } else {
      char *wkt = NULL;
      if (OSRExportToWkt(geo, &wkt) == OGRERR_NONE)
        *imposed = CPLStrdup(wkt);
      CPLFree(wkt);
    }
  }

done:
  if (ds)
    GDALClose(ds);
  if (rb.ct)
    OCTDestroyCoordinateTransformation(rb.ct);
  if (written)
    OSRDestroySpatialReference(written);
  if (geo)
    OSRDestroySpatialReference(geo);
  free(rb.x);
  free(rb.y);
  free(rb.z);
  free(rb.seen);
  return ok;
}
