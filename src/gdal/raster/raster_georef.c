/*
 * src/gdal/raster/ -- the rasters: a band read into a grid, a grid written
 * as a GeoTIFF.
 *
 * raster_georef.c -- where the band read by tt_gdal_read_grid stands
 * (raster_read.h): its geotransform (the default (0,1,0,0,0,1) when there
 * is none, refused when ground control points are all there is), its CRS
 * as the info names it, the band's scale and offset, the unit of its
 * heights (the band's unit type, else the vertical CRS's) and Z_UNIT=m's
 * conversion; then, with the grid made, its ground frame: the affine
 * frame of georef_proj.c, or for a longitude/latitude or Web Mercator
 * raster every sample's ground point (georef_conformal.c), the affine
 * frame staying, with a warning, when that fails or would pass
 * MAX_MEMORY. A CRS that says geographic over coordinates that cannot be
 * is measured in the geotransform's units, with a warning.
 *
 * Workload: a few PROJ calls, and for ground points one batched
 * transformation a row (16 bytes a sample kept on the grid).
 */
#include "gdal/georef/georef.h"
#include "gdal/raster/raster_read.h"

#include <cpl_conv.h>
#include <cpl_error.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

/* Fills the CRS fields of info from srs (may be NULL). */
static tt_status describe_crs(tt_context *ctx, OGRSpatialReferenceH srs,
                              tt_raster_info *info)
{
  char *wkt = NULL;
  char name[512] = "";
  if (srs) {
    const char *const wkt_options[] = {"FORMAT=WKT2_2019", NULL};
    if (OSRExportToWktEx(srs, &wkt, wkt_options) != OGRERR_NONE) {
      CPLFree(wkt);
      wkt = NULL;
      OSRExportToWkt(srs, &wkt);
    }
    const char *crs = OSRGetName(srs);
    const char *auth = OSRGetAuthorityName(srs, NULL);
    const char *code = OSRGetAuthorityCode(srs, NULL);
    if (auth && code) {
      snprintf(name, sizeof name, "%s (%s:%s)", crs ? crs : "unnamed", auth,
               code);
    } else {
      /* No code of its own (USGS DEM, .prj files): say what it looks like,
       * which helps more than "unnamed". Only the name is affected. */
      OGRSpatialReferenceH guess = OSRClone(srs);
      CPLPushErrorHandler(CPLQuietErrorHandler);
      CPLSetCurrentErrorHandlerCatchDebug(FALSE); /* debug: the handler below */
      int found = guess && OSRAutoIdentifyEPSG(guess) == OGRERR_NONE;
      CPLPopErrorHandler();
      const char *gcode = found ? OSRGetAuthorityCode(guess, NULL) : NULL;
      if (gcode)
        snprintf(name, sizeof name, "%s (like EPSG:%s)",
                 crs ? crs : "unnamed", gcode);
      else
        snprintf(name, sizeof name, "%s", crs ? crs : "unnamed");
      OSRDestroySpatialReference(guess);
    }
    info->crs_is_geographic = OSRIsGeographic(srs) ? 1 : 0;
  }
  info->crs_wkt = tt__raster_dup_str(wkt);
  info->crs_name = tt__raster_dup_str(name);
  CPLFree(wkt);
  if (!info->crs_wkt || !info->crs_name)
    return tt__error(ctx, TT_ERR_NOMEM, "out of memory");
  return TT_OK;
}

/* The short name of a height unit: "m", "ft" (international foot) or
 * "us-ft" (US survey foot); NULL for anything else. */
static const char *unit_short_name(const char *u)
{
  static const char *const m[] = {"m", "metre", "meter", "metres", "meters",
                                  NULL};
  static const char *const ft[] = {"ft", "foot", "feet", "international "
                                   "foot", "foot (international)", "intl ft",
                                   NULL};
  static const char *const usft[] = {"us-ft", "us_ft", "ftus", "us-foot",
                                     "us survey foot", "foot_us",
                                     "us foot", "survey foot",
                                     "foot (us survey)", NULL};
  if (!u)
    return NULL;
  for (int i = 0; m[i]; i++)
    if (strcasecmp(u, m[i]) == 0)
      return "m";
  for (int i = 0; ft[i]; i++)
    if (strcasecmp(u, ft[i]) == 0)
      return "ft";
  for (int i = 0; usft[i]; i++)
    if (strcasecmp(u, usft[i]) == 0)
      return "us-ft";
  return NULL;
}

/* Metres per unit of a short unit name (unit_short_name). */
static double unit_metres(const char *short_name)
{
  if (strcmp(short_name, "ft") == 0)
    return 0.3048;
  if (strcmp(short_name, "us-ft") == 0)
    return 1200.0 / 3937.0;
  return 1.0;
}

/* The unit the heights are declared in: the band's unit type, else the
 * linear unit of the vertical part of a compound CRS (or of a vertical
 * CRS). Writes the name as declared to buf ("" when nothing says) and
 * returns where it came from. */
static const char *declared_z_unit(GDALRasterBandH band,
                                   OGRSpatialReferenceH srs, char *buf,
                                   size_t size)
{
  const char *u = GDALGetRasterUnitType(band);
  buf[0] = '\0';
  if (u && *u) {
    snprintf(buf, size, "%s", u);
    return "band unit";
  }
  if (srs && (OSRIsCompound(srs) || OSRIsVertical(srs))) {
    char *name = NULL;
    double to_m = OSRGetTargetLinearUnits(srs, "VERT_CS", &name);
    if (to_m > 0 && name && *name) {
      const char *sn = unit_short_name(name);
      /* A unit PROJ names oddly but whose size is known still counts. */
      if (!sn && fabs(to_m - 1.0) < 1e-12)
        sn = "m";
      else if (!sn && fabs(to_m - 0.3048) < 1e-12)
        sn = "ft";
      else if (!sn && fabs(to_m - 1200.0 / 3937.0) < 1e-12)
        sn = "us-ft";
      snprintf(buf, size, "%s", sn ? sn : name);
      return "vertical CRS";
    }
  }
  return "";
}

/* The whole raster's geotransform; (0,1,0,0,0,1) without one, which a
 * raster georeferenced by ground control points only may not have. */
static tt_status read_geotransform(raster_read *r)
{
  const double unit_gt[6] = {0, 1, 0, 0, 0, 1};
  memcpy(r->gt, unit_gt, sizeof r->gt);
  r->has_gt = 0;
  if (!r->ds)
    return TT_OK;
  CPLPushErrorHandler(CPLQuietErrorHandler);
  CPLSetCurrentErrorHandlerCatchDebug(FALSE); /* debug: the handler below */
  r->has_gt = GDALGetGeoTransform(r->ds, r->gt) == CE_None;
  CPLPopErrorHandler();
  if (r->has_gt)
    return TT_OK;
  memcpy(r->gt, unit_gt, sizeof r->gt);
  if (GDALGetGCPCount(r->ds) > 0)
    return tt__error(r->ctx, TT_ERR_FORMAT, "%s: georeferenced by %d ground "
                     "control points only, not by a geotransform: warp it "
                     "first (gdalwarp)", r->path, GDALGetGCPCount(r->ds));
  return TT_OK;
}

/* The band's scale and offset (1 and 0 when not given), which must be
 * usable. */
static tt_status read_scale_offset(raster_read *r)
{
  int has_scale = 0, has_offset = 0;
  r->scale = GDALGetRasterScale(r->band, &has_scale);
  r->offset = GDALGetRasterOffset(r->band, &has_offset);
  if (!has_scale)
    r->scale = 1.0;
  if (!has_offset)
    r->offset = 0.0;
  if (!isfinite(r->scale) || r->scale == 0 || !isfinite(r->offset))
    return tt__error(r->ctx, TT_ERR_FORMAT, "%s: band %d has an unusable "
                     "scale %g or offset %g", r->path,
                     GDALGetBandNumber(r->band), r->scale, r->offset);
  return TT_OK;
}

/* Why Z_UNIT=auto converts heights to metres: the CRS's horizontal unit
 * is the metre, or degrees (whose ground is measured in metres); NULL
 * when it keeps them (a CRS in feet, none). */
static const char *auto_reason(OGRSpatialReferenceH srs)
{
  if (!srs)
    return NULL;
  if (OSRIsGeographic(srs))
    return "the CRS is geographic";
  if (OSRIsProjected(srs) && fabs(OSRGetLinearUnits(srs, NULL) - 1.0) < 1e-12)
    return "the CRS is in metres";
  return NULL;
}

/* The height unit, and Z_UNIT=m's or auto's conversion (before Z_FACTOR):
 * r->conv is the options with Z_FACTOR times the unit's factor. */
static tt_status read_z_unit(raster_read *r)
{
  const read_options *opt = &r->opt;
  if (opt->src_z_unit) {
    snprintf(r->unit_declared, sizeof r->unit_declared, "%s",
             opt->src_z_unit);
    r->unit_source = "given";
  } else {
    r->unit_source = declared_z_unit(r->band, r->srs, r->unit_declared,
                                     sizeof r->unit_declared);
  }
  const char *unit_declared = r->unit_declared;
  const char *unit_short = unit_short_name(unit_declared);
  r->unit_factor = 1.0;
  r->unit_why = "";
  r->unit_out = unit_short ? unit_short : unit_declared;
  const char *why = opt->z_unit_m ? "asked"
                    : opt->z_unit_auto && unit_short &&
                            strcmp(unit_short, "m") != 0
                        ? auto_reason(r->srs)
                        : NULL;
  if (why) {
    if (unit_short) {
      r->unit_factor = unit_metres(unit_short);
    } else if (!opt->has_z_factor) {
      return tt__error(r->ctx, TT_ERR_DATA, "%s: heights cannot be "
                       "converted to metres (asked by Z_UNIT=m, -z_to m): "
                       "the height unit is %s%s%s; declare it as SRC_Z_UNIT "
                       "(-z_unit ft|us-ft|m) or give the factor to metres "
                       "as Z_FACTOR (-z_factor)", r->path,
                       unit_declared[0] ? "\"" : "unknown (no band unit, no "
                       "vertical CRS)", unit_declared,
                       unit_declared[0] ? "\", which is not m, ft or us-ft"
                                        : "");
    }
    r->unit_why = r->unit_factor != 1.0 ? why : "";
    r->unit_out = "m";
  }
  r->conv = *opt; /* what the scan multiplies by */
  r->conv.z_factor = opt->z_factor * r->unit_factor;
  return TT_OK;
}

tt_status tt__raster_georef(raster_read *r)
{
  /* before the big allocation: a GCP-only raster fails here */
  tt_status s = read_geotransform(r);
  if (s != TT_OK)
    return s;
  r->info = calloc(1, sizeof *r->info);
  if (!r->info)
    return tt__error(r->ctx, TT_ERR_NOMEM, "out of memory");
  r->srs = r->ds ? GDALGetSpatialRef(r->ds) : NULL;
  s = describe_crs(r->ctx, r->srs, r->info);
  if (s == TT_OK)
    s = read_scale_offset(r);
  if (s == TT_OK)
    s = read_z_unit(r);
  return s;
}

/* The ground points' progress, onto the read's. */
static int ground_progress(double complete, const char *message, void *arg)
{
  return tt__raster_progress(arg, complete, message);
}

/* Longitude/latitude and Web Mercator: every sample projected into a
 * conformal frame (georef_conformal.c) over the affine frame just set,
 * which stays only when that fails (with a warning) or when the ground
 * points, 16 bytes a sample beside the heights' 4, would pass MAX_MEMORY
 * (with a warning too). TT_ERR_ARG (an unusable WORK_SRS) is the one
 * failure returned. */
static tt_status set_ground_points(raster_read *r)
{
  tt_context *ctx = r->ctx;
  const read_options *opt = &r->opt;
  const size_t nx = r->nx, ny = r->ny;
  size_t n = nx * ny, with_points = n <= SIZE_MAX / 20 ? n * 20 : SIZE_MAX;
  if (with_points > opt->max_memory) {
    char need_s[32], max_s[32];
    tt__warn(ctx, "%s: the heights and ground points of %zu x %zu "
             "samples would need %s, more than %s (%s): keeping the "
             "affine frame %s", r->path, nx, ny,
             tt__format_bytes(need_s, sizeof need_s, with_points),
             opt->max_memory_default ? opt->max_memory_source
                                     : "MAX_MEMORY",
             tt__format_bytes(max_s, sizeof max_s, opt->max_memory),
             r->frame_name);
    return TT_OK;
  }
  char conformal_name[512];
  /* a window (a tile) gets the whole raster's frame and the ground points
   * of its samples as the whole raster has them; projecting them takes
   * some ten times the scan (0.35 against 0.035 us a sample, a 12000^2
   * VRT): 0 - 0.8 of the read's progress */
  r->prog_lo = 0.0;
  r->prog_hi = 0.8;
  tt_status s = tt__georef_ground_points(ctx, r->srs, opt->work_srs, r->gt,
                                         (size_t)r->xsize, (size_t)r->ysize,
                                         r->wx, r->wy, r->grid,
                                         r->progress ? ground_progress : NULL,
                                         r, conformal_name,
                                         sizeof conformal_name,
                                         &r->frame_scale_error);
  r->prog_lo = 0.8;
  r->prog_hi = 1.0;
  if (s == TT_ERR_INTERRUPTED)
    return tt__error(ctx, s, "%s: read interrupted", r->path);
  if (s == TT_OK) {
    snprintf(r->frame_name, sizeof r->frame_name, "%s", conformal_name);
  } else if (s != TT_ERR_ARG) {
    tt__warn(ctx, "%s: %s; keeping the affine frame %s", r->path,
             ctx ? ctx->errmsg : "", r->frame_name);
    tt_context_clear_error(ctx);
    s = TT_OK;
  }
  return s;
}

/* A map in feet is measured in metres (georef_proj.c): heights of no
 * declared unit are taken as metres then, which they rarely are on such a
 * map. Say so once; the TIN is the same either way. */
static void warn_feet_map(raster_read *r)
{
  OGRSpatialReferenceH srs = r->srs;
  char *lin_name = NULL;
  double lin = srs && OSRIsProjected(srs) ? OSRGetLinearUnits(srs, &lin_name)
                                          : 1.0;
  if (lin > 0 && fabs(lin - 1.0) > 1e-9 && !r->unit_declared[0] &&
      !r->opt.has_z_factor)
    tt__warn(r->ctx, "%s: the map unit is %s and the heights declare no "
             "unit: slopes and 3-D areas take them as metres (give "
             "-z_factor %.10g if they are in that unit too)", r->path,
             lin_name && *lin_name ? lin_name : "not the metre", lin);
}

/* Whether a geotransform without a CRS looks like longitude/latitude
 * degrees: every corner within +-180 by +-90, pixels under a tenth of a
 * unit (an SRTM grid without its .prj, a netCDF bathymetry in arc
 * minutes), and heights whose range is more than ten times the smaller
 * extent -- relief that no terrain has if the coordinates were in the
 * heights' unit (SRTM: 700 m over 0.1 degree). A grid in pixel units
 * (pixel 1), in metres, or a synthetic terrain on the unit square never
 * does. */
static int looks_like_degrees(const raster_read *r, double ext[4])
{
  const double *gt = r->gt;
  double px = hypot(gt[1], gt[4]), py = hypot(gt[2], gt[5]);
  if (!(px > 0 && px < 0.1 && py > 0 && py < 0.1))
    return 0;
  ext[0] = ext[2] = INFINITY;
  ext[1] = ext[3] = -INFINITY;
  for (int k = 0; k < 4; k++) {
    double c = (k & 1) ? (double)r->xsize : 0;
    double l = (k & 2) ? (double)r->ysize : 0;
    double x = gt[0] + c * gt[1] + l * gt[2];
    double y = gt[3] + c * gt[4] + l * gt[5];
    ext[0] = fmin(ext[0], x);
    ext[1] = fmax(ext[1], x);
    ext[2] = fmin(ext[2], y);
    ext[3] = fmax(ext[3], y);
  }
  if (!(ext[0] >= -180.0001 && ext[1] <= 360.0001 && ext[2] >= -90.0001 &&
        ext[3] <= 90.0001))
    return 0;
  double lo = INFINITY, hi = -INFINITY;
  const size_t w = tt_grid_width(r->grid), h = tt_grid_height(r->grid);
  for (size_t y = 0; y < h; y++)
    for (size_t x = 0; x < w; x++) {
      double z = tt_grid_sample(r->grid, x, y);
      if (!isnan(z)) {
        lo = fmin(lo, z);
        hi = fmax(hi, z);
      }
    }
  return hi - lo > 10.0 * fmin(ext[1] - ext[0], ext[3] - ext[2]);
}

tt_status tt__raster_check_degrees(raster_read *r)
{
  tt_context *ctx = r->ctx;
  double ext[4];
  if (!r->srs && !r->opt.work_srs && looks_like_degrees(r, ext)) {
    /* Measured in its own units, degrees would pass for metres: slopes
     * near 90 degrees, areas in square degrees. Said loudly, with the
     * way out; the frame's name says it too. */
    tt__warn(ctx, "%s: has no CRS, but its geotransform looks like "
             "longitude/latitude degrees (x %.6g to %.6g, y %.6g to %.6g, "
             "pixels of %.3g): slopes, angles and areas are measured as if "
             "those were the heights' units, which is wrong on the ground; "
             "give it its CRS: terratin's -a_srs EPSG:4326, or "
             "gdal_translate -of VRT -a_srs EPSG:4326 %s dem.vrt", r->path,
             ext[0],
             ext[1], ext[2], ext[3], hypot(r->gt[1], r->gt[4]), r->path);
    snprintf(r->frame_name, sizeof r->frame_name, "geotransform (no CRS; "
             "its coordinates look like degrees, measured as map units)");
  }
  return TT_OK;
}

tt_status tt__raster_frame(raster_read *r)
{
  tt_context *ctx = r->ctx;
  OGRSpatialReferenceH srs = r->srs;
  snprintf(r->frame_name, sizeof r->frame_name, "geotransform");
  r->frame_scale_error = NAN;
  if (!srs && !r->opt.work_srs)
    return TT_OK;
  double frame[4];
  tt_status s = tt__georef_ground_frame(ctx, srs, r->opt.work_srs, r->gt,
                                        (size_t)r->xsize, (size_t)r->ysize,
                                        frame, r->frame_name,
                                        sizeof r->frame_name);
  if (s == TT_ERR_DATA) {
    /* A CRS that says geographic over coordinates that cannot be (a
     * mislabelled projected grid) or a grid centred on a pole: measure in
     * the geotransform's units rather than refuse the DEM. */
    tt__warn(ctx, "%s: %s; angles and areas are measured in the "
             "geotransform's units instead", r->path, ctx ? ctx->errmsg : "");
    tt_context_clear_error(ctx);
    snprintf(r->frame_name, sizeof r->frame_name, "geotransform (the CRS "
             "is geographic but no local frame fits)");
    s = TT_OK;
  } else if (s == TT_OK) {
    s = tt_grid_set_ground_frame(ctx, r->grid, frame);
    if (s == TT_OK && srs &&
        (OSRIsGeographic(srs) || tt__georef_is_web_mercator(srs)))
      s = set_ground_points(r);
  }
  if (s != TT_OK)
    return tt__raster_with_path(ctx, s, r->path);
  warn_feet_map(r);
  return TT_OK;
}
