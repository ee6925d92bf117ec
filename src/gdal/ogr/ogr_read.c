/*
 * src/gdal/ogr/ -- the OGR layers: a TIN written into an OGR dataset and
 * triangles read from one, the features' records, QGIS's default style,
 * safe output paths and the protection of the input's files.
 *
 * ogr_read.c -- reading another tool's (or our own) triangles from an OGR
 * layer for tt_eval_triangles().
 *
 * Accepted: POLYGON Z and TRIANGLE Z whose single ring is closed and has 4
 * points, and those found inside MULTIPOLYGON Z, TIN Z, POLYHEDRALSURFACE Z
 * and GEOMETRYCOLLECTION Z. Each corner's map x,y goes through the inverse
 * geotransform to pixel-edge coordinates and then by -0.5 to pixel-centre
 * space, where sample (c, r) stands at (c, r); z is taken from the geometry.
 * Everything else is counted as rejected, one per polygon (or per feature
 * for a missing or non-polygonal geometry): rings of other lengths,
 * polygons with holes, open rings, curves, and polygons without Z (the
 * heights would be unknown). Ring orientation is not checked.
 *
 * Workload: one pass over the layer (its attribute and spatial filters
 * apply); memory 72 bytes per triangle, grown by 1.5x steps.
 */
#include "base/internal.h"
#include "terratin/terratin_gdal.h"

#include <cpl_error.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

typedef struct tri_reader {
  tt_context *ctx;
  double inv[6];         /* map -> pixel-edge coordinates */
  double *xyz;
  size_t n, cap;         /* triangles held, capacity in triangles */
  size_t rejected;
} tri_reader;

static tt_status add_polygon(tri_reader *rd, OGRGeometryH g)
{
  OGRGeometryH ring = OGR_G_GetGeometryCount(g) == 1
                          ? OGR_G_GetGeometryRef(g, 0)
                          : NULL;
  if (!OGR_G_Is3D(g) || !ring || OGR_G_GetPointCount(ring) != 4) {
    rd->rejected++;
    return TT_OK;
  }
  double p[4][3];
  for (int k = 0; k < 4; k++)
    OGR_G_GetPoint(ring, k, &p[k][0], &p[k][1], &p[k][2]);
  if (p[0][0] != p[3][0] || p[0][1] != p[3][1] || p[0][2] != p[3][2]) {
    rd->rejected++;
    return TT_OK;
  }
  if (!tt__grow((void **)&rd->xyz, &rd->cap, rd->n + 1, 9 * sizeof(double)))
    return tt__error(rd->ctx, TT_ERR_NOMEM, "out of memory after %zu "
                     "triangles", rd->n);
  double *o = rd->xyz + 9 * rd->n;
  const double *a = rd->inv;
  for (int k = 0; k < 3; k++) {
    double x = p[k][0], y = p[k][1];
    o[3 * k + 0] = a[0] + x * a[1] + y * a[2] - 0.5;
    o[3 * k + 1] = a[3] + x * a[4] + y * a[5] - 0.5;
    o[3 * k + 2] = p[k][2];
  }
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

tt_status tt_ogr_read_triangles(tt_context *ctx, OGRLayerH layer,
                                const double gt[6], double **out_xyz,
                                size_t *out_ntriangles, size_t *out_rejected)
{
  if (!out_xyz || !out_ntriangles)
    return tt__error(ctx, TT_ERR_ARG, "out_xyz and out_ntriangles must not "
                     "be NULL");
  *out_xyz = NULL;
  *out_ntriangles = 0;
  if (out_rejected)
    *out_rejected = 0;
  if (!layer || !gt)
    return tt__error(ctx, TT_ERR_ARG, "layer and geotransform must not be "
                     "NULL");

  tri_reader rd;
  memset(&rd, 0, sizeof rd);
  rd.ctx = ctx;
  double gt_copy[6];
  memcpy(gt_copy, gt, sizeof gt_copy);
  if (!GDALInvGeoTransform(gt_copy, rd.inv))
    return tt__error(ctx, TT_ERR_ARG, "geotransform (%g, %g, %g, %g, %g, %g) "
                     "cannot be inverted", gt[0], gt[1], gt[2], gt[3], gt[4],
                     gt[5]);

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
