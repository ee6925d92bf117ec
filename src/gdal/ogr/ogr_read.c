/*
 * src/gdal/ogr/ -- the OGR layers: a TIN written into an OGR dataset and
 * triangles read from one, the features' records, QGIS's default style,
 * safe output paths and the protection of the input's files.
 *
 * ogr_read.c -- reading another tool's (or our own) triangles from an OGR
 * layer for tt_eval_triangles(): the layer flattened to triangles in its
 * map coordinates (ogr_flatten.c, which says what is accepted), then each
 * corner's map x,y through the inverse geotransform to pixel-edge
 * coordinates and by -0.5 to pixel-centre space, where sample (c, r)
 * stands at (c, r); z is taken from the geometry.
 */
#include "base/internal.h"
#include "terratin/terratin_gdal.h"

#include <cpl_error.h>

#include <stdlib.h>
#include <string.h>

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
  double inv[6], gt_copy[6];
  memcpy(gt_copy, gt, sizeof gt_copy);
  if (!GDALInvGeoTransform(gt_copy, inv))
    return tt__error(ctx, TT_ERR_ARG, "geotransform (%g, %g, %g, %g, %g, %g) "
                     "cannot be inverted", gt[0], gt[1], gt[2], gt[3], gt[4],
                     gt[5]);
  double *xyz = NULL;
  size_t n = 0;
  tt_status s = tt_ogr_read_triangles_map(ctx, layer, &xyz, &n,
                                          out_rejected);
  if (s != TT_OK)
    return s;
  for (size_t i = 0; i < 3 * n; i++) {
    double x = xyz[3 * i], y = xyz[3 * i + 1];
    xyz[3 * i] = inv[0] + x * inv[1] + y * inv[2] - 0.5;
    xyz[3 * i + 1] = inv[3] + x * inv[4] + y * inv[5] - 0.5;
  }
  *out_xyz = xyz;
  *out_ntriangles = n;
  return TT_OK;
}
