/*
 * src/gdal/ogr/ -- the OGR layers: a TIN written into an OGR dataset and
 * triangles read from one, the features' records, QGIS's default style,
 * safe output paths and the protection of the input's files.
 *
 * ogr_flatten.c -- the triangles of an OGR layer in its own map
 * coordinates: every geometry flattened to the triangles it holds,
 * whatever the layer declares (POLYGON Z, MULTIPOLYGON Z, TIN Z,
 * POLYHEDRALSURFACE Z, or "Unknown": CSV with WKT, DXF's 3DFACE
 * entities, a MULTIPATCH Shapefile's TINs and polygons).
 *
 * Accepted: POLYGON Z and TRIANGLE Z whose single ring is closed and
 * has 3 distinct corners once repeated consecutive points are dropped
 * (a DXF 3DFACE of a triangle repeats its third corner as the fourth),
 * and those found inside MULTIPOLYGON Z, TIN Z, POLYHEDRALSURFACE Z and
 * GEOMETRYCOLLECTION Z, nested up to 8 levels. Everything else is counted
 * as rejected, one per polygon (or per feature for a missing or
 * non-polygonal geometry): rings of other lengths, polygons with holes,
 * open rings, curves, and polygons without Z (the heights would be
 * unknown). Ring orientation is not checked.
 *
 * Workload: one pass over the layer (its attribute and spatial filters
 * apply); memory 72 bytes per triangle, grown by 1.5x steps.
 */
#include "base/internal.h"
#include "terratin/terratin_gdal.h"

#include <cpl_error.h>

#include <stdlib.h>
#include <string.h>

typedef struct tri_reader {
  tt_context *ctx;
  double *xyz;
  size_t n, cap;         /* triangles held, capacity in triangles */
  size_t rejected;
} tri_reader;

/* The ring's corners without the closing point and, past 4 points,
 * without consecutive repeats (a ring of 4 points is taken as it is, so a
 * degenerate triangle is measured as one); their count, or -1 for an
 * open ring or more than 3. */
static int ring_corners(OGRGeometryH ring, double c[3][3])
{
  const int np = OGR_G_GetPointCount(ring);
  double first[3], last[3];
  if (np < 4 || np > 16)
    return -1;
  OGR_G_GetPoint(ring, 0, &first[0], &first[1], &first[2]);
  OGR_G_GetPoint(ring, np - 1, &last[0], &last[1], &last[2]);
  if (memcmp(first, last, sizeof first) != 0)
    return -1;
  int n = 0;
  for (int k = 0; k < np - 1; k++) {
    double p[3];
    OGR_G_GetPoint(ring, k, &p[0], &p[1], &p[2]);
    if (np > 4 && n > 0 && memcmp(p, c[n - 1], sizeof p) == 0)
      continue;
    if (n == 3)
      return -1;
    memcpy(c[n++], p, sizeof p);
  }
  /* The last kept corner repeating the first closes the ring early. */
  if (np > 4 && n == 3 && memcmp(c[2], c[0], sizeof c[0]) == 0)
    n = 2;
  return n;
}

static tt_status add_polygon(tri_reader *rd, OGRGeometryH g)
{
  OGRGeometryH ring = OGR_G_GetGeometryCount(g) == 1
                          ? OGR_G_GetGeometryRef(g, 0)
                          : NULL;
  double c[3][3];
  if (!OGR_G_Is3D(g) || !ring || ring_corners(ring, c) != 3) {
    rd->rejected++;
    return TT_OK;
  }
  if (!tt__grow((void **)&rd->xyz, &rd->cap, rd->n + 1, 9 * sizeof(double)))
    return tt__error(rd->ctx, TT_ERR_NOMEM, "out of memory after %zu "
                     "triangles", rd->n);
  memcpy(rd->xyz + 9 * rd->n, c, sizeof c);
  rd->n++;
  return TT_OK;
}

/* Polygons directly, collections of them recursively (depth-limited: OGR
 * geometries nest only a few levels in practice). */
static tt_status add_geometry(tri_reader *rd, OGRGeometryH g, int depth)
{
  if (!g || OGR_G_IsEmpty(g)) {
    rd->rejected++;
    return TT_OK;
  }
  switch (wkbFlatten(OGR_G_GetGeometryType(g))) {
  case wkbPolygon:
  case wkbTriangle:
    return add_polygon(rd, g);
  case wkbMultiPolygon:
  case wkbTIN:
  case wkbPolyhedralSurface:
  case wkbGeometryCollection:
    if (depth < 8) {
      const int n = OGR_G_GetGeometryCount(g);
      for (int i = 0; i < n; i++) {
        tt_status s = add_geometry(rd, OGR_G_GetGeometryRef(g, i),
                                   depth + 1);
        if (s != TT_OK)
          return s;
      }
      return TT_OK;
    }
    rd->rejected++;
    return TT_OK;
  default:
    rd->rejected++;
    return TT_OK;
  }
}

tt_status tt_ogr_read_triangles_map(tt_context *ctx, OGRLayerH layer,
                                    double **out_xyz,
                                    size_t *out_ntriangles,
                                    size_t *out_rejected)
{
  if (!out_xyz || !out_ntriangles)
    return tt__error(ctx, TT_ERR_ARG, "out_xyz and out_ntriangles must not "
                     "be NULL");
  *out_xyz = NULL;
  *out_ntriangles = 0;
  if (out_rejected)
    *out_rejected = 0;
  if (!layer)
    return tt__error(ctx, TT_ERR_ARG, "layer must not be NULL");

  tri_reader rd;
  memset(&rd, 0, sizeof rd);
  rd.ctx = ctx;
  tt_status s = TT_OK;
  OGR_L_ResetReading(layer);
  CPLErrorReset();
  OGRFeatureH f;
  while (s == TT_OK && (f = OGR_L_GetNextFeature(layer)) != NULL) {
    s = add_geometry(&rd, OGR_F_GetGeometryRef(f), 0);
    OGR_F_Destroy(f);
  }
  if (s == TT_OK && CPLGetLastErrorType() >= CE_Failure)
    s = tt__error(ctx, TT_ERR_IO, "reading layer %s failed after %zu "
                  "triangles: %s", OGR_L_GetName(layer), rd.n,
                  CPLGetLastErrorMsg());
  if (s != TT_OK) {
    free(rd.xyz);
    return s;
  }
  *out_xyz = rd.xyz;
  *out_ntriangles = rd.n;
  if (out_rejected)
    *out_rejected = rd.rejected;
  return TT_OK;
}
