/*
 * tin_read.c -- apps/core/: the command's core, what every command's
 * folder shares. This file: eval's TIN read from whatever file holds it
 * and put on the DEM: a mesh file (STL, PLY, OBJ, 2DM, LandXML, UGRID;
 * tt_mesh_read) or an OGR layer of any geometry type (tin_input.c picks
 * it, tt_ogr_read_triangles_map flattens it), then -tin_transform, the
 * frame (-tin_frame, or by itself: an STL whose corners miss the DEM's
 * map extent but fit its grid is in the pixel frame, as hmm writes it)
 * and a reprojection from the TIN's CRS to the DEM's (tt_tin_to_pixels).
 *
 * An STL says nothing of its frame. When its corners fit only one of the
 * DEM's map extent and its grid, that one is taken; when they fit both
 * (a DEM whose map coordinates are its sample indices, as generate
 * writes), the frame whose corners land on samples of the very heights
 * wins (a simplifier's vertices are samples), tried on the first 256
 * triangles; when neither wins, the run stops and asks for -stl_frame.
 *
 * The TIN's CRS is the layer's, or the one the mesh file declares; none
 * means the DEM's. A TIN with a CRS on a DEM without one is measured as
 * it is, with a warning.
 */
#include "app.h"

#include <cpl_conv.h>
#include <ogr_api.h>
#include <ogr_srs_api.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* The triangles of an OGR layer, in its coordinates, and its CRS. */
static tt_status read_layer(app_run *r, tt_output *outp, app_tin *t)
{
  const tt_app_settings *s = r->s;
  tt_status st;
  if (!(t->ds = tt__app_open_vector(r, s->tin)))
    return r->res->status;
  if (outp && (st = tt_output_protect_dataset(r->ctx, outp, t->ds,
                                              s->tin)) != TT_OK)
    return tt__app_fail_tt(r, st, s->error_raster);
  OGRLayerH layer = tt__app_tin_layer(r, t->ds);
  if (!layer)
    return r->res->status;
  t->layer = OGR_L_GetName(layer);
  t->format = GDALGetDriverShortName(GDALGetDatasetDriver(t->ds));
  OGRSpatialReferenceH srs = OGR_L_GetSpatialRef(layer);
  char *wkt = NULL;
  if (srs && OSRExportToWkt(srs, &wkt) == OGRERR_NONE && wkt)
    t->crs_wkt = strdup(wkt);
  CPLFree(wkt);
  r->msg.last[0] = '\0';
  st = tt_ogr_read_triangles_map(r->ctx, layer, &t->xyz, &t->ntri,
                                 &t->rejected);
  if (st != TT_OK)
    return tt__app_fail_tt(r, st, s->tin);
  return TT_OK;
}

/* Of the corners of the first triangles put in frame, how many land on a
 * sample (within 1e-6 pixel) of their very height (within 1e-5
 * relative: float32 STL heights on a Float64 DEM). */
static size_t corners_on_samples(app_run *r, const app_tin *t,
                                 const tt_raster_info *info,
                                 const tt_grid *grid, tt_tin_frame frame)
{
  enum { TRY = 256 };
  double xyz[9 * TRY];
  size_t n = t->ntri < TRY ? t->ntri : TRY, hits = 0;
  const float *hf = tt_grid_heights_const(grid);
  const double *hd = tt_grid_heights_f64_const(grid);
  memcpy(xyz, t->xyz, n * 9 * sizeof(double));
  if (tt_tin_to_pixels(r->ctx, xyz, n, frame,
                       r->s->tin_transform_set ? r->s->tin_transform : NULL,
                       info->height, NULL, NULL, info->gt, NULL) != TT_OK)
    return 0;
  for (size_t i = 0; i < 3 * n; i++) {
    double c = floor(xyz[3 * i] + 0.5), rr = floor(xyz[3 * i + 1] + 0.5);
    if (fabs(xyz[3 * i] - c) > 1e-6 || fabs(xyz[3 * i + 1] - rr) > 1e-6 ||
        c < 0 || rr < 0 || c >= (double)info->width ||
        rr >= (double)info->height)
      continue;
    size_t k = (size_t)rr * info->width + (size_t)c;
    double h = hd ? hd[k] : hf ? (double)hf[k] : NAN;
    if (fabs(xyz[3 * i + 2] - h) <= 1e-5 * fmax(1.0, fabs(h)))
      hits++;
  }
  return hits;
}

/* The frame of an STL (see the top): 1 pixel, 0 map, -1 undecided
 * (recorded). */
static int stl_in_pixel_frame(app_run *r, const app_tin *t,
                              const tt_raster_info *info,
                              const tt_grid *grid)
{
  const double *tf = r->s->tin_transform_set ? r->s->tin_transform : NULL;
  double x0 = INFINITY, x1 = -INFINITY, y0 = INFINITY, y1 = -INFINITY;
  for (size_t i = 0; i < 3 * t->ntri; i++) {
    double x = t->xyz[3 * i], y = t->xyz[3 * i + 1];
    if (tf) {
      x = tf[0] * x + tf[3];
      y = tf[1] * y + tf[4];
    }
    x0 = fmin(x0, x), x1 = fmax(x1, x), y0 = fmin(y0, y), y1 = fmax(y1, y);
  }
  const double *gt = info->gt;
  double mx0 = INFINITY, mx1 = -INFINITY, my0 = INFINITY, my1 = -INFINITY;
  for (int k = 0; k < 4; k++) {
    double c = (k & 1) ? (double)info->width : 0.0;
    double rr = (k & 2) ? (double)info->height : 0.0;
    double x = gt[0] + c * gt[1] + rr * gt[2];
    double y = gt[3] + c * gt[4] + rr * gt[5];
    mx0 = fmin(mx0, x), mx1 = fmax(mx1, x), my0 = fmin(my0, y),
    my1 = fmax(my1, y);
  }
  int on_map = !(x1 < mx0 || x0 > mx1 || y1 < my0 || y0 > my1);
  int fits_grid = x0 >= -0.5 && y0 >= -0.5 &&
                  x1 <= (double)info->width - 0.5 &&
                  y1 <= (double)info->height - 0.5;
  if (on_map != fits_grid)
    return fits_grid;
  if (!on_map)
    return 0; /* neither: measured as map, which then says so */
  size_t pix = corners_on_samples(r, t, info, grid, TT_TIN_FRAME_PIXEL);
  size_t map = corners_on_samples(r, t, info, grid, TT_TIN_FRAME_MAP);
  if (pix != map)
    return pix > map;
  tt__app_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_DATA, r->s->tin,
               "the STL's corners fit both the DEM's map extent and its "
               "pixel grid; say which with -stl_frame map or -stl_frame "
               "pixel");
  return -1;
}

tt_status tt__app_read_tin(app_run *r, const tt_raster_info *info,
                           const tt_grid *grid, tt_output *outp, app_tin *t)
{
  const tt_app_settings *s = r->s;
  tt_status st;
  memset(t, 0, sizeof *t);
  t->format = tt_mesh_read_format(s->tin);
  if (t->format && s->layer)
    return tt__app_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_ARG, s->tin,
                        "is a %s file, which has no layers (-layer %s)",
                        t->format, s->layer);
  if (t->format) {
    r->msg.last[0] = '\0';
    st = tt_mesh_read(r->ctx, s->tin, &t->xyz, &t->ntri, &t->rejected,
                      &t->crs_wkt);
    if (st != TT_OK)
      return tt__app_fail_tt(r, st, s->tin);
  } else if ((st = read_layer(r, outp, t)) != TT_OK) {
    return st;
  }
  t->pixel = s->tin_frame == 2;
  if (s->tin_frame == 0 && t->format && strcmp(t->format, "STL") == 0) {
    int pixel = stl_in_pixel_frame(r, t, info, grid);
    if (pixel < 0)
      return r->res->status;
    t->pixel = pixel;
  }
  int dem_has_crs = info->crs_wkt && *info->crs_wkt;
  t->other_crs = !t->pixel && t->crs_wkt && !dem_has_crs;
  st = tt_tin_to_pixels(r->ctx, t->xyz, t->ntri,
                        t->pixel ? TT_TIN_FRAME_PIXEL : TT_TIN_FRAME_MAP,
                        s->tin_transform_set ? s->tin_transform : NULL,
                        info->height, t->crs_wkt,
                        dem_has_crs ? info->crs_wkt : NULL, info->gt,
                        &t->reprojected);
  if (st != TT_OK)
    return tt__app_fail_tt(r, st, s->tin);
  if (t->reprojected && t->crs_wkt) {
    OGRSpatialReferenceH srs = OSRNewSpatialReference(NULL);
    if (OSRSetFromUserInput(srs, t->crs_wkt) == OGRERR_NONE) {
      const char *name = OSRGetName(srs);
      snprintf(t->crs_name, sizeof t->crs_name, "%s", name ? name : "?");
    }
    OSRDestroySpatialReference(srs);
  }
  return TT_OK;
}

void tt__app_tin_free(app_tin *t)
{
  if (t->ds)
    GDALClose(t->ds);
  free(t->xyz);
  free(t->crs_wkt);
  memset(t, 0, sizeof *t);
}
