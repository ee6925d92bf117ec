/*
 * dem_view.c -- apps/core/: the command's core, what every command's
 * folder shares. This file: GDAL's input options on a DEM -- -srcwin,
 * -projwin with -projwin_srs, -a_srs (and -s_srs), -a_ullr -- as one
 * in-memory VRT over the opened raster (gdal_translate -of VRT to no
 * file, through GDALTranslate), so that every reader (a whole DEM, a
 * tiled run's windows, a tile of `tiles run`) sees the window as a
 * raster of its own: no temporary file, and the window's geotransform
 * keeps the DEM's map coordinates.
 *
 * The window is checked as gdal_translate checks it, then clipped: a
 * window partly outside the raster is read as its part inside (with a
 * warning that says which samples), one wholly outside is refused naming
 * the option. -projwin becomes a window of samples by gdal_translate's
 * rounding; with -projwin_srs its box is reprojected (PROJ, through OGR's
 * transformation of bounds, densified edges) to the DEM's CRS first.
 *
 * Invariant: the arguments are computed once (tt__app_view_args, on the
 * thread that opened the DEM, with the messages); opening a view from
 * them (tt__app_view_open) is safe on any thread with its own dataset.
 */
#include "app.h"

#include <cpl_conv.h>
#include <cpl_string.h>
#include <gdal_utils.h>
#include <ogr_srs_api.h>

#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

int tt__app_view_wanted(const tt_app_settings *s)
{
  return s->srcwin.set || s->projwin.set || s->a_ullr.set ||
         (s->srs && s->command != TT_APP_GENERATE);
}

/* The option that gave the DEM's CRS (both go to the same setting). */
static const char *srs_option(const tt_app_settings *s)
{
  return s->srs_is_s_srs ? "-s_srs" : "-a_srs";
}

/* A CRS from a user's text, axes in GIS order; NULL when GDAL cannot read
 * it. The caller frees it with OSRDestroySpatialReference(). */
static OGRSpatialReferenceH srs_from(const char *text)
{
  OGRSpatialReferenceH srs = OSRNewSpatialReference(NULL);
  if (!srs)
    return NULL;
  CPLPushErrorHandler(CPLQuietErrorHandler);
  OGRErr e = OSRSetFromUserInput(srs, text);
  CPLPopErrorHandler();
  if (e != OGRERR_NONE) {
    OSRDestroySpatialReference(srs);
    return NULL;
  }
  OSRSetAxisMappingStrategy(srs, OAMS_TRADITIONAL_GIS_ORDER);
  return srs;
}

/* -projwin in the DEM's CRS: the box as given, or, with -projwin_srs, the
 * box that holds its reprojection (21 points an edge). 0 with the reason
 * in why. */
static int projwin_in_dem_crs(const tt_app_settings *s, GDALDatasetH src,
                              double box[4], char *why, size_t size,
                              int *out_usage)
{
  memcpy(box, s->projwin.v, 4 * sizeof box[0]);
  if (!s->projwin_srs)
    return 1;
  OGRSpatialReferenceH from = srs_from(s->projwin_srs), to = NULL;
  OGRCoordinateTransformationH ct = NULL;
  int ok = 0;
  *out_usage = 1;
  if (!from) {
    snprintf(why, size, "-projwin_srs '%s': not a CRS GDAL can read",
             s->projwin_srs);
    goto done;
  }
  if (s->srs) {
    to = srs_from(s->srs);
  } else {
    OGRSpatialReferenceH own = GDALGetSpatialRef(src);
    if (own) {
      to = OSRClone(own);
      OSRSetAxisMappingStrategy(to, OAMS_TRADITIONAL_GIS_ORDER);
    }
  }
  if (!to) {
    snprintf(why, size, "-projwin_srs %s: the DEM has no CRS to reproject "
             "the window to; give it one with -a_srs SRS", s->projwin_srs);
    goto done;
  }
  if (OSRIsSame(from, to)) {
    ok = 1;
    goto done;
  }
  CPLPushErrorHandler(CPLQuietErrorHandler);
  ct = OCTNewCoordinateTransformation(from, to);
  double x0 = 0, y0 = 0, x1 = 0, y1 = 0;
  int done_ok = ct && OCTTransformBounds(ct, box[0], box[3], box[2], box[1],
                                         &x0, &y0, &x1, &y1, 21);
  CPLPopErrorHandler();
  if (!done_ok || !isfinite(x0) || !isfinite(y0) || !isfinite(x1) ||
      !isfinite(y1)) {
    *out_usage = 0;
    snprintf(why, size, "-projwin %.17g %.17g %.17g %.17g: cannot be "
             "reprojected from -projwin_srs %s to the DEM's CRS", box[0],
             box[1], box[2], box[3], s->projwin_srs);
    goto done;
  }
  box[0] = x0;
  box[1] = y1;
  box[2] = x1;
  box[3] = y0;
  ok = 1;
done:
  if (ct)
    OCTDestroyCoordinateTransformation(ct);
  OSRDestroySpatialReference(from);
  OSRDestroySpatialReference(to);
  return ok;
}

/* -projwin as a window of samples, rounded as gdal_translate rounds it
 * (offsets floored, sizes to the nearest sample). 0 with the reason. */
static int projwin_to_srcwin(const tt_app_settings *s, GDALDatasetH src,
                             double win[4], char *why, size_t size,
                             int *out_usage)
{
  double gt[6], box[4];
  if (GDALGetGeoTransform(src, gt) != CE_None) {
    *out_usage = 1;
    snprintf(why, size, "-projwin: the DEM has no geotransform to place "
             "the window in (give it one with -a_ullr and use -srcwin)");
    return 0;
  }
  if (gt[2] != 0.0 || gt[4] != 0.0) {
    *out_usage = 1;
    snprintf(why, size, "-projwin: the DEM's geotransform is rotated; "
             "give the window with -srcwin");
    return 0;
  }
  if (!projwin_in_dem_crs(s, src, box, why, size, out_usage))
    return 0;
  win[0] = floor((box[0] - gt[0]) / gt[1] + 0.001);
  win[1] = floor((box[1] - gt[3]) / gt[5] + 0.001);
  win[2] = floor((box[2] - box[0]) / gt[1] + 0.5);
  win[3] = floor((box[3] - box[1]) / gt[5] + 0.5);
  return 1;
}

static void add_number(char ***args, double x)
{
  char num[40];
  tt__app_format_double(num, sizeof num, x);
  *args = CSLAddString(*args, num);
}

/* The window (given or computed) checked against the raster, clipped;
 * 0 with the reason when none of it is inside or what is left is too
 * small for a triangle. */
static int clip_window(const char *opt, const char *given, double win[4],
                       int W, int H, char *why, size_t size, char *warn,
                       size_t warn_size)
{
  double c0 = fmax(win[0], 0.0), r0 = fmax(win[1], 0.0);
  double c1 = fmin(win[0] + win[2], (double)W);
  double r1 = fmin(win[1] + win[3], (double)H);
  if (win[2] <= 0 || win[3] <= 0) {
    snprintf(why, size, "%s %s: the window (-srcwin %.0f %.0f %.0f %.0f) "
             "has no width or height", opt, given, win[0], win[1], win[2],
             win[3]);
    return 0;
  }
  if (c1 <= c0 || r1 <= r0) {
    snprintf(why, size, "%s %s: falls completely outside the raster (%d x "
             "%d samples)%s", opt, given, W, H,
             strcmp(opt, "-srcwin") ? " as -srcwin" : "");
    if (strcmp(opt, "-srcwin") != 0) {
      size_t n = strlen(why);
      snprintf(why + n, size - n, " %.0f %.0f %.0f %.0f", win[0], win[1],
               win[2], win[3]);
    }
    return 0;
  }
  if (c0 != win[0] || r0 != win[1] || c1 - c0 != win[2] ||
      r1 - r0 != win[3])
    snprintf(warn, warn_size, "%s %s falls partly outside the raster (%d x "
             "%d samples): read as -srcwin %.0f %.0f %.0f %.0f, its part "
             "inside", opt, given, W, H, c0, r0, c1 - c0, r1 - r0);
  win[0] = c0;
  win[1] = r0;
  win[2] = c1 - c0;
  win[3] = r1 - r0;
  if (win[2] < 2 || win[3] < 2) {
    snprintf(why, size, "%s %s: the window inside the raster is %.0f x "
             "%.0f samples; at least 2 x 2 are needed", opt, given, win[2],
             win[3]);
    return 0;
  }
  return 1;
}

char **tt__app_view_args(const tt_app_settings *s, GDALDatasetH src,
                         int *out_usage, char *why, size_t size, char *warn,
                         size_t warn_size)
{
  char **args = CSLAddString(NULL, "-of");
  args = CSLAddString(args, "VRT");
  *out_usage = 0;
  why[0] = warn[0] = '\0';
  if (s->srs && s->command != TT_APP_GENERATE) {
    OGRSpatialReferenceH srs = srs_from(s->srs);
    if (!srs) {
      *out_usage = 1;
      snprintf(why, size, "%s '%s': not a CRS GDAL can read (EPSG:n, WKT, "
               "PROJ string, ...)", srs_option(s), s->srs);
      goto fail;
    }
    OSRDestroySpatialReference(srs);
  }
  if (s->srcwin.set || s->projwin.set) {
    double win[4];
    char given[160];
    const tt_app_box *b = s->srcwin.set ? &s->srcwin : &s->projwin;
    const char *opt = s->srcwin.set ? "-srcwin" : "-projwin";
    snprintf(given, sizeof given, "%.17g %.17g %.17g %.17g", b->v[0],
             b->v[1], b->v[2], b->v[3]);
    if (s->srcwin.set)
      memcpy(win, s->srcwin.v, sizeof win);
    else if (!projwin_to_srcwin(s, src, win, why, size, out_usage))
      goto fail;
    *out_usage = 1;
    if (!clip_window(opt, given, win, GDALGetRasterXSize(src),
                     GDALGetRasterYSize(src), why, size, warn, warn_size))
      goto fail;
    *out_usage = 0;
    args = CSLAddString(args, "-srcwin");
    for (int i = 0; i < 4; i++)
      add_number(&args, win[i]);
  }
  if (s->srs && s->command != TT_APP_GENERATE) {
    args = CSLAddString(args, "-a_srs");
    args = CSLAddString(args, s->srs);
  }
  if (s->a_ullr.set) {
    args = CSLAddString(args, "-a_ullr");
    for (int i = 0; i < 4; i++)
      add_number(&args, s->a_ullr.v[i]);
  }
  return args;
fail:
  CSLDestroy(args);
  return NULL;
}

GDALDatasetH tt__app_view_open(GDALDatasetH src, char **args, char *why,
                               size_t size)
{
  GDALTranslateOptions *opts = GDALTranslateOptionsNew(args, NULL);
  if (!opts) {
    snprintf(why, size, "the input options cannot be applied: %s",
             CPLGetLastErrorMsg());
    return NULL;
  }
  int usage = 0;
  CPLErrorReset();
  GDALDatasetH view = GDALTranslate("", src, opts, &usage);
  GDALTranslateOptionsFree(opts);
  if (!view) {
    snprintf(why, size, "the input options cannot be applied: %s",
             CPLGetLastErrorMsg()[0] ? CPLGetLastErrorMsg() : "GDAL failed");
    return NULL;
  }
  /* gdal_translate leaves the bands' units behind, which say the heights'
   * unit (-z_unit, the summary): the view keeps them. A VRT of no file
   * writes nothing when changed. */
  for (int b = 1; b <= GDALGetRasterCount(view); b++) {
    const char *unit = GDALGetRasterUnitType(GDALGetRasterBand(src, b));
    GDALRasterBandH vb = GDALGetRasterBand(view, b);
    if (unit && *unit && !*GDALGetRasterUnitType(vb))
      GDALSetRasterUnitType(vb, unit);
  }
  return view;
}
