/*
 * src/gdal/georef/ -- the georeferencing: where a grid's samples stand on
 * the ground, with PROJ, and where another tool's TIN lies on the DEM.
 *
 * tin_frame.c -- a TIN read from a file (tt_mesh_read, or an OGR layer
 * flattened by tt_ogr_read_triangles_map) put on the DEM's pixel-centre
 * grid for tt_eval_triangles: an explicit affine per axis first (what a
 * tool's file leaves out: hmm's STL has heights less the DEM's minimum),
 * then either the DEM's pixel frame (x the column, y the row counted up
 * from the last row, as hmm writes STL) or map coordinates, reprojected
 * from the TIN's CRS to the DEM's when the two differ and then put
 * through the inverse geotransform. Heights are never reprojected: a
 * TIN's z is compared with the DEM's as it is.
 *
 * Workload: one pass over the corners; the reprojection transforms them
 * in blocks of 4096 points with one PROJ transformation.
 */
#include "base/internal.h"
#include "terratin/terratin_gdal.h"

#include <cpl_conv.h>
#include <ogr_srs_api.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

static const char *const same_opts[] = {
    "IGNORE_DATA_AXIS_TO_SRS_AXIS_MAPPING=YES",
    "CRITERION=EQUIVALENT_EXCEPT_AXIS_ORDER_GEOGCRS", NULL};

static OGRSpatialReferenceH srs_from(const char *text)
{
  if (!text || !*text)
    return NULL;
  OGRSpatialReferenceH srs = OSRNewSpatialReference(NULL);
  if (OSRSetFromUserInput(srs, text) != OGRERR_NONE) {
    OSRDestroySpatialReference(srs);
    return NULL;
  }
  OSRSetAxisMappingStrategy(srs, OAMS_TRADITIONAL_GIS_ORDER);
  return srs;
}

/* Every corner's x, y from src to dst, in blocks. */
static tt_status reproject(tt_context *ctx, double *xyz, size_t ntri,
                           OGRSpatialReferenceH src,
                           OGRSpatialReferenceH dst)
{
  enum { BLOCK = 4096 };
  OGRCoordinateTransformationH ct = OCTNewCoordinateTransformation(src, dst);
  if (!ct)
    return tt__error(ctx, TT_ERR_ARG, "no transformation from the TIN's "
                     "CRS to the DEM's: %s", CPLGetLastErrorMsg());
  double x[BLOCK], y[BLOCK];
  int ok[BLOCK];
  const size_t npts = 3 * ntri;
  tt_status st = TT_OK;
  for (size_t p0 = 0; st == TT_OK && p0 < npts; p0 += BLOCK) {
    size_t m = npts - p0 < BLOCK ? npts - p0 : BLOCK;
    for (size_t i = 0; i < m; i++) {
      x[i] = xyz[3 * (p0 + i)];
      y[i] = xyz[3 * (p0 + i) + 1];
    }
    OCTTransformEx(ct, (int)m, x, y, NULL, ok);
    for (size_t i = 0; i < m; i++) {
      if (!ok[i]) {
        st = tt__error(ctx, TT_ERR_DATA, "corner (%.10g, %.10g) of "
                       "triangle %zu cannot be put in the DEM's CRS",
                       xyz[3 * (p0 + i)], xyz[3 * (p0 + i) + 1],
                       (p0 + i) / 3 + 1);
        break;
      }
      xyz[3 * (p0 + i)] = x[i];
      xyz[3 * (p0 + i) + 1] = y[i];
    }
  }
  OCTDestroyCoordinateTransformation(ct);
  return st;
}

/* Whether the TIN's CRS differs from the DEM's: 1 when the corners must
 * be reprojected (then *out_src, *out_dst are set), 0 otherwise. */
static int needs_reprojection(const char *tin_crs, const char *dem_crs,
                              OGRSpatialReferenceH *out_src,
                              OGRSpatialReferenceH *out_dst)
{
  OGRSpatialReferenceH src = srs_from(tin_crs), dst = srs_from(dem_crs);
  if (src && dst && !OSRIsSameEx(src, dst, (const char *const *)same_opts)) {
    *out_src = src;
    *out_dst = dst;
    return 1;
  }
  if (src)
    OSRDestroySpatialReference(src);
  if (dst)
    OSRDestroySpatialReference(dst);
  return 0;
}

tt_status tt_tin_to_pixels(tt_context *ctx, double *xyz, size_t ntriangles,
                           tt_tin_frame frame, const double transform[6],
                           size_t dem_height, const char *tin_crs,
                           const char *dem_crs, const double gt[6],
                           int *out_reprojected)
{
  if (out_reprojected)
    *out_reprojected = 0;
  if ((!xyz && ntriangles) || !gt)
    return tt__error(ctx, TT_ERR_ARG, "xyz and gt must not be NULL");
  const size_t npts = 3 * ntriangles;
  if (transform)
    for (size_t i = 0; i < npts; i++)
      for (int a = 0; a < 3; a++)
        xyz[3 * i + a] = transform[a] * xyz[3 * i + a] + transform[3 + a];
  if (frame == TT_TIN_FRAME_PIXEL) {
    for (size_t i = 0; i < npts; i++)
      xyz[3 * i + 1] = (double)dem_height - 1.0 - xyz[3 * i + 1];
    return TT_OK;
  }
  OGRSpatialReferenceH src = NULL, dst = NULL;
  if (needs_reprojection(tin_crs, dem_crs, &src, &dst)) {
    tt_status st = reproject(ctx, xyz, ntriangles, src, dst);
    OSRDestroySpatialReference(src);
    OSRDestroySpatialReference(dst);
    if (st != TT_OK)
      return st;
    if (out_reprojected)
      *out_reprojected = 1;
  }
  double inv[6], g[6];
  memcpy(g, gt, sizeof g);
  if (!GDALInvGeoTransform(g, inv))
    return tt__error(ctx, TT_ERR_ARG, "geotransform (%g, %g, %g, %g, %g, "
                     "%g) cannot be inverted", gt[0], gt[1], gt[2], gt[3],
                     gt[4], gt[5]);
  for (size_t i = 0; i < npts; i++) {
    double x = xyz[3 * i], y = xyz[3 * i + 1];
    xyz[3 * i] = inv[0] + x * inv[1] + y * inv[2] - 0.5;
    xyz[3 * i + 1] = inv[3] + x * inv[4] + y * inv[5] - 0.5;
  }
  return TT_OK;
}
