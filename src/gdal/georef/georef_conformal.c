/*
 * src/gdal/georef/ -- the georeferencing: where a grid's samples stand on
 * the ground, with PROJ (the affine ground frame, and the conformal ground
 * points of a geographic or Web Mercator grid).
 *
 * georef_conformal.c -- the ground points of a longitude/latitude grid, or
 * of a Web Mercator one: every sample projected once into a conformal
 * working projection, with the projection's scale factor and meridian
 * convergence there (see tt_grid_alloc_ground_points in terratin.h).
 *
 * Web Mercator (EPSG:3857 and its aliases: a spherical Mercator of radius
 * R on the geodetic longitudes and latitudes of an ellipsoid) is conformal
 * on its sphere but not on the ellipsoid, and its scale grows as sec(lat):
 * 1.31 at 40 N, so its map units are no ground metres and one affine frame
 * cannot fix a DEM of any north-south extent. Its samples are treated as
 * the longitudes and latitudes they stand for (lon = lon0 + x / R,
 * lat = gd(y / R), checked against PROJ at the grid's corners) and get the
 * ground points, frames and geodesic areas of a geographic grid.
 *
 * The projection suits the extent of the sample centres:
 *  - beyond 84 N or 80 S: polar stereographic on the pole, centred on the
 *    DEM's middle longitude;
 *  - every longitude within 4 degrees of the central meridian of the
 *    centre's UTM zone: that UTM zone (the working CRS of today's affine
 *    frame, georef_proj.c), unchanged;
 *  - wider than tall on the ground (longitude span times the cosine of the
 *    centre latitude at least the latitude span): a Lambert conformal conic
 *    with standard parallels at 1/6 and 5/6 of the latitude range (true
 *    scale there, the smallest largest error of a conic), or Mercator when
 *    the range straddles the equator so much that the parallels' signs
 *    differ;
 *  - otherwise: an oblique stereographic centred on the DEM.
 *  - -work_srs names any projected CRS instead (it should be conformal:
 *    the scale factor below assumes it).
 * Polar stereographic, Mercator and oblique stereographic are scaled by the
 * constant that balances their largest and smallest scale over the DEM (a
 * constant factor keeps a projection conformal); the frame's name says so.
 *
 * Everything is a function of the whole raster, never of the part read: a
 * window (a tile, tiled runs of issue 19) gets the frame of the raster's
 * extent, the range of k over the raster's outline and centre
 * (raster_scale_range), and its samples projected from their column and
 * row in the raster, so that a window's ground points, k and convergence
 * are the whole grid's bit for bit.
 *
 * Scale factor and convergence come from the projected grid itself
 * (tt_grid_ground_scale_at, engine, with ellipsoid_metric below; for the
 * TIN's vertices only, nothing stored per sample): the
 * Jacobian J of pixel -> projection by finite differences over the grid
 * (central inside, second-order one-sided at the edges) against the
 * ground Jacobian G of pixel -> local east/north metres on the ellipsoid
 * (prime-vertical and meridional radii at the sample's latitude):
 * k = sqrt(|det J / det G|) (conformal: areas scale by k^2), and the
 * convergence is the angle of J G^-1 (0, 1), true north, from +y. The
 * truncation error is of the order of (pixel / earth radius)^2.
 *
 * Invariants: on success every sample has finite x, y and k > 0, and the
 * grid's ground frame is J at the raster's centre sample (so its
 * orientation, and the pixel-space orientation the mesh keeps, are the
 * projection's).
 *
 * Workload: one batched PROJ transformation per row (nx points), 16 bytes
 * of ground points per sample kept on the grid, O(1) per sample after;
 * for the range of k, at most 1,033 samples of the outline and centre,
 * each with its 3 x 3 neighbours projected (under 10,000 points, whatever
 * the size of the raster or the window).
 */
#include "gdal/georef/georef.h"
#include "base/internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cpl_conv.h>
#include <cpl_error.h>
#include <geodesic.h>
#include <ogr_srs_api.h>

#define TT_PI 3.14159265358979323846
/* UTM serves while every longitude is this close to the zone's meridian
 * (scale error at 57 N: under 0.1%; at the equator: 0.2%). */
#define TT_UTM_HALF_WIDTH_DEG 4.0

typedef enum frame_kind { FRAME_USER, FRAME_UTM, FRAME_POLAR, FRAME_LCC,
                          FRAME_MERCATOR, FRAME_STEREO } frame_kind;

/* Where the grid's map coordinates stand on the ellipsoid: a geographic
 * CRS (x, y are longitude and latitude in units of u radians) or Web
 * Mercator (radius R, central meridian lon0 radians, no false origin). */
typedef struct source {
  int webmerc;
  double u;           /* geographic: radians per unit */
  double R, lon0;     /* Web Mercator */
} source;

/* Longitude and latitude (radians) of map point (x, y). */
static void to_lonlat(const source *src, double x, double y, double *lam,
                      double *phi)
{
  if (!src->webmerc) {
    *lam = x * src->u;
    *phi = y * src->u;
    return;
  }
  *lam = src->lon0 + x / src->R;
  *phi = atan(sinh(y / src->R));
}

/* Web Mercator: the parameters of a spherical Mercator on no false origin
 * from srs's PROJ string ("+proj=merc +a=R +b=R", lat_ts 0 or k 1),
 * 1 when srs is one. */
static int web_mercator_of(OGRSpatialReferenceH srs, source *out)
{
  char *p4 = NULL;
  int ok = 0;
  if (!srs || !OSRIsProjected(srs))
    return 0;
  CPLPushErrorHandler(CPLQuietErrorHandler);
  CPLSetCurrentErrorHandlerCatchDebug(FALSE); /* debug: the handler below */
  OGRErr e = OSRExportToProj4(srs, &p4);
  CPLPopErrorHandler();
  if (e != OGRERR_NONE || !p4)
    goto done;
  double a = NAN, b = NAN, x0 = 0, y0 = 0, k = 1, lat_ts = 0, lon0 = 0,
         to_m = 1;
  int merc = 0, other = 0;
  char *save = NULL;
  for (char *t = strtok_r(p4, " ", &save); t; t = strtok_r(NULL, " ", &save)) {
    if (strcmp(t, "+proj=merc") == 0)
      merc = 1;
    else if (strncmp(t, "+a=", 3) == 0)
      a = CPLAtof(t + 3);
    else if (strncmp(t, "+b=", 3) == 0)
      b = CPLAtof(t + 3);
    else if (strncmp(t, "+x_0=", 5) == 0)
      x0 = CPLAtof(t + 5);
    else if (strncmp(t, "+y_0=", 5) == 0)
      y0 = CPLAtof(t + 5);
    else if (strncmp(t, "+k=", 3) == 0 || strncmp(t, "+k_0=", 5) == 0)
      k = CPLAtof(strchr(t, '=') + 1);
    else if (strncmp(t, "+lat_ts=", 8) == 0)
      lat_ts = CPLAtof(t + 8);
    else if (strncmp(t, "+lon_0=", 7) == 0)
      lon0 = CPLAtof(t + 7);
    else if (strncmp(t, "+to_meter=", 10) == 0)
      to_m = CPLAtof(t + 10);
    else if (strncmp(t, "+units=", 7) == 0)
      other |= strcmp(t, "+units=m") != 0;
    else if (strncmp(t, "+ellps=", 7) == 0 || strncmp(t, "+datum=", 7) == 0)
      other = 1; /* an ellipsoidal Mercator: conformal itself */
  }
  ok = merc && !other && a > 0 && a == b && x0 == 0 && y0 == 0 && k == 1 &&
       lat_ts == 0 && to_m == 1 && isfinite(lon0);
  if (ok) {
    out->webmerc = 1;
    out->u = 0;
    out->R = a;
    out->lon0 = lon0 * TT_PI / 180;
  }
done:
  CPLFree(p4);
  return ok;
}

int tt__georef_is_web_mercator(OGRSpatialReferenceH srs)
{
  source src;
  return web_mercator_of(srs, &src);
}

/* The working CRS on srs's geographic CRS for the extent, or NULL. */
static OGRSpatialReferenceH choose(OGRSpatialReferenceH srs, double lon0,
                                   double lat0, double lon_min,
                                   double lon_max, double lat_min,
                                   double lat_max, frame_kind *kind,
                                   char *name, size_t name_size)
{
  OGRSpatialReferenceH geog = OSRCloneGeogCS(srs);
  OGRSpatialReferenceH work = NULL;
  OGRErr e = OGRERR_FAILURE;
  if (!geog)
    goto done;
  const char *datum = OSRGetAttrValue(geog, "DATUM", 0);
  if (!datum)
    datum = "its datum";
  int zone = (int)floor(fmod(lon0 + 180.0 + 3600.0, 360.0) / 6.0) + 1;
  if (zone > 60)
    zone = 60;
  double cm = -183.0 + 6.0 * zone;
  if (lat_max <= 84.0 && lat_min >= -80.0 &&
      fabs(lon_min - cm) <= TT_UTM_HALF_WIDTH_DEG &&
      fabs(lon_max - cm) <= TT_UTM_HALF_WIDTH_DEG) {
    work = tt__georef_utm_of(srs, lon0, lat0, name, name_size);
    *kind = FRAME_UTM;
    e = work ? OGRERR_NONE : OGRERR_FAILURE;
    goto done;
  }
  work = OSRNewSpatialReference(NULL);
  if (!work || OSRCopyGeogCSFrom(work, geog) != OGRERR_NONE)
    goto done;
  double lat_span = lat_max - lat_min;
  double p1 = lat_min + lat_span / 6, p2 = lat_max - lat_span / 6;
  if (lat_max > 84.0 || lat_min < -80.0) {
    int north = lat0 >= 0;
    *kind = FRAME_POLAR;
    e = OSRSetProjCS(work, "terratin polar stereographic");
    if (e == OGRERR_NONE)
      e = OSRSetPS(work, north ? 90.0 : -90.0, lon0, 1.0, 0, 0);
    snprintf(name, name_size, "polar stereographic (%s pole, longitude "
             "%.6f) on %s", north ? "north" : "south", lon0, datum);
  } else if ((lon_max - lon_min) * cos(lat0 * TT_PI / 180) >= lat_span) {
    if (p1 * p2 > 0 && fabs(p1 + p2) > 1.0) {
      *kind = FRAME_LCC;
      e = OSRSetProjCS(work, "terratin Lambert conformal conic");
      if (e == OGRERR_NONE)
        e = OSRSetLCC(work, p1, p2, lat0, lon0, 0, 0);
      snprintf(name, name_size, "Lambert conformal conic (standard "
               "parallels %.6f and %.6f, centre %.6f, %.6f) on %s", p1, p2,
               lon0, lat0, datum);
    } else {
      *kind = FRAME_MERCATOR;
      e = OSRSetProjCS(work, "terratin Mercator");
      if (e == OGRERR_NONE)
        e = OSRSetMercator(work, 0.0, lon0, 1.0, 0, 0);
      snprintf(name, name_size, "Mercator (central meridian %.6f) on %s",
               lon0, datum);
    }
  } else {
    *kind = FRAME_STEREO;
    e = OSRSetProjCS(work, "terratin oblique stereographic");
    if (e == OGRERR_NONE)
      e = OSRSetOS(work, lat0, lon0, 1.0, 0, 0);
    snprintf(name, name_size, "oblique stereographic centred on (%.6f, "
             "%.6f) on %s", lon0, lat0, datum);
  }
done:
  OSRDestroySpatialReference(geog);
  if (e != OGRERR_NONE) {
    OSRDestroySpatialReference(work);
    return NULL;
  }
  return work;
}

/* Metres on the ellipsoid (a, e2) per map unit east and north at map
 * point (x, y): longitude/latitude in units of params[2] radians, or Web
 * Mercator of radius -params[2] (tt_ground_metric_fn). The prime-vertical
 * and meridional radii times the radians per unit. */
static void ellipsoid_metric(const double params[4], double x, double y,
                             double out[2])
{
  double a = params[0], e2 = params[1], u = params[2];
  double lat = y * u, ue = u, un = u;
  if (u < 0) { /* Web Mercator: d lat / dy = 1 / (R cosh(y / R)) */
    double R = -u;
    lat = atan(sinh(y / R));
    ue = 1.0 / R;
    un = cos(lat) / R;
  }
  (void)x;
  double sn = sin(lat), w2 = 1.0 - e2 * sn * sn;
  out[0] = a / sqrt(w2) * cos(lat) * ue;          /* m per unit E */
  out[1] = a * (1.0 - e2) / (w2 * sqrt(w2)) * un; /* m per unit N */
}

/* Geodesic area of a triangle of longitudes x and latitudes y (in the
 * CRS's angular unit) on the ellipsoid of params (a, f, degrees per
 * unit), or of Web Mercator x, y (params a, f, -1 / R, central meridian in
 * degrees): GeographicLib's geod_polygonarea. */
static double geodesic_area(const double params[4], const double x[3],
                            const double y[3])
{
  /* geod_init's series coefficients, kept per thread for the last
   * ellipsoid (the writer asks for every triangle's area) */
  static _Thread_local struct geod_geodesic g;
  static _Thread_local double ga = 0, gf = -1;
  if (ga != params[0] || gf != params[1]) {
    geod_init(&g, params[0], params[1]);
    ga = params[0];
    gf = params[1];
  }
  double lat[3], lon[3], area = 0, perimeter = 0;
  for (int k = 0; k < 3; k++) {
    if (params[2] > 0) {
      lon[k] = x[k] * params[2];
      lat[k] = y[k] * params[2];
    } else { /* Web Mercator */
      lon[k] = params[3] - x[k] * params[2] * (180 / TT_PI);
      lat[k] = atan(sinh(-y[k] * params[2])) * (180 / TT_PI);
    }
  }
  geod_polygonarea(&g, lat, lon, 3, &area, &perimeter);
  return fabs(area);
}

/* Web Mercator's inverse (to_lonlat) against PROJ's at the grid's corners
 * and centre: within 1e-9 degree, or TT_ERR_DATA (then the affine frame
 * stays). src is the CRS in GIS axis order. */
static tt_status check_web_mercator(tt_context *ctx,
                                    OGRSpatialReferenceH src,
                                    const source *sk, const double gt[6],
                                    size_t nx, size_t ny)
{
  OGRSpatialReferenceH geog = src ? OSRCloneGeogCS(src) : NULL;
  OGRCoordinateTransformationH ct = NULL;
  int ok = 0;
  if (geog) {
    OSRSetAxisMappingStrategy(geog, OAMS_TRADITIONAL_GIS_ORDER);
    CPLPushErrorHandler(CPLQuietErrorHandler);
    CPLSetCurrentErrorHandlerCatchDebug(FALSE); /* debug: the handler below */
    ct = OCTNewCoordinateTransformation(src, geog);
    CPLPopErrorHandler();
  }
  double deg = OSRGetAngularUnits(geog ? geog : src, NULL) * 180 / TT_PI;
  if (ct) {
    double x[5], y[5], mx[5], my[5];
    int good[5];
    for (int k = 0; k < 5; k++) {
      double px = k == 4 ? 0.5 * nx : (k & 1) ? (double)nx - 0.5 : 0.5;
      double py = k == 4 ? 0.5 * ny : (k & 2) ? (double)ny - 0.5 : 0.5;
      mx[k] = x[k] = gt[0] + px * gt[1] + py * gt[2];
      my[k] = y[k] = gt[3] + px * gt[4] + py * gt[5];
    }
    CPLPushErrorHandler(CPLQuietErrorHandler);
    CPLSetCurrentErrorHandlerCatchDebug(FALSE); /* debug: the handler below */
    ok = OCTTransformEx(ct, 5, x, y, NULL, good);
    CPLPopErrorHandler();
    for (int k = 0; ok && k < 5; k++) {
      double lam, phi;
      to_lonlat(sk, mx[k], my[k], &lam, &phi);
      ok = good[k] && fabs(x[k] * deg - lam * 180 / TT_PI) <= 1e-9 &&
           fabs(y[k] * deg - phi * 180 / TT_PI) <= 1e-9;
    }
    OCTDestroyCoordinateTransformation(ct);
  }
  OSRDestroySpatialReference(geog);
  if (!ok)
    return tt__error(ctx, TT_ERR_DATA, "PROJ does not take this CRS as Web "
                     "Mercator (spherical Mercator on geodetic latitudes)");
  return TT_OK;
}

/* The scale factor k, convergence and Jacobian J of raster sample (c, r)
 * exactly as tt_grid_ground_scale_at gives them on the whole raster's
 * ground points: a grid of the sample's neighbours (three a side, the
 * raster's edge where it has one, so the finite differences are the same)
 * projected from the raster's own columns and rows. */
static tt_status raster_scale_at(tt_context *ctx,
                                 OGRCoordinateTransformationH ct,
                                 const double gt[6], size_t nx, size_t ny,
                                 size_t c, size_t r,
                                 const double metric_par[4], double *out_k,
                                 double *out_conv, double out_j[4])
{
  size_t c0 = c > 0 ? c - 1 : 0, c1 = c + 1 < nx ? c + 1 : nx - 1;
  size_t r0 = r > 0 ? r - 1 : 0, r1 = r + 1 < ny ? r + 1 : ny - 1;
  if (c == 0)
    c1 = nx > 2 ? 2 : nx - 1;
  if (c == nx - 1)
    c0 = nx > 2 ? nx - 3 : 0;
  if (r == 0)
    r1 = ny > 2 ? 2 : ny - 1;
  if (r == ny - 1)
    r0 = ny > 2 ? ny - 3 : 0;
  size_t w = c1 - c0 + 1, h = r1 - r0 + 1;
  double x[9], y[9];
  int ok[9];
  for (size_t j = 0; j < h; j++)
    for (size_t i = 0; i < w; i++) {
      double px = (double)(c0 + i) + 0.5, py = (double)(r0 + j) + 0.5;
      x[j * w + i] = gt[0] + px * gt[1] + py * gt[2];
      y[j * w + i] = gt[3] + px * gt[4] + py * gt[5];
    }
  CPLPushErrorHandler(CPLQuietErrorHandler);
  CPLSetCurrentErrorHandlerCatchDebug(FALSE); /* debug: the handler below */
  int all = OCTTransformEx(ct, (int)(w * h), x, y, NULL, ok);
  CPLPopErrorHandler();
  tt_grid *g = NULL;
  tt_status s = tt_grid_create(ctx, w, h, &g);
  if (s == TT_OK)
    s = tt_grid_set_geotransform(ctx, g, gt);
  if (s == TT_OK)
    s = tt_grid_alloc_ground_points(ctx, g);
  if (s != TT_OK)
    goto done;
  double *xy = tt_grid_ground_xy(g);
  for (size_t i = 0; i < w * h; i++) {
    if (!all || !ok[i] || !isfinite(x[i]) || !isfinite(y[i])) {
      s = tt__error(ctx, TT_ERR_DATA, "PROJ cannot project sample (col %zu, "
                    "row %zu)", c0 + i % w, r0 + i / w);
      goto done;
    }
    xy[2 * i] = x[i];
    xy[2 * i + 1] = y[i];
  }
  tt_grid_set_ground_metric_fn(g, ellipsoid_metric, metric_par);
  tt__grid_set_ground_origin(g, c0, r0, gt);
  if (tt_grid_ground_scale_at(g, c - c0, r - r0, out_k, out_conv) != TT_OK) {
    s = tt__error(ctx, TT_ERR_DATA, "no scale factor at sample (col %zu, "
                  "row %zu) (a pole?)", c, r);
    goto done;
  }
  tt__grid_ground_jacobian(g, c - c0, r - r0, out_j);
done:
  tt_grid_destroy(g);
  return s;
}

/* Samples a side of the raster's outline is measured at for the range of
 * k: its two ends and up to this many steps between. */
#define TT_OUTLINE_STEPS 256

/* The range of k over the raster (before any constant scale), and J at its
 * centre sample (nx / 2, ny / 2): k at the samples of the outline (every
 * sample of a side up to TT_OUTLINE_STEPS + 1 of them, evenly spaced
 * otherwise) and at the two to four samples around the centre. For the
 * frames chosen here k is a function of the distance from the centre
 * (stereographic), of the latitude (polar stereographic, Mercator,
 * Lambert's conic) or of the distance from the central meridian (UTM),
 * each of which takes its extremes over a longitude/latitude rectangle on
 * its outline or at its centre; the sampling of a long side misses at most
 * the second-order bump of k between two measured samples. It depends on
 * the raster only, never on a window: every tile and an untiled run get
 * the same range, scale and frame. */
static tt_status raster_scale_range(tt_context *ctx,
                                    OGRCoordinateTransformationH ct,
                                    const double gt[6], size_t nx,
                                    size_t ny, const double metric_par[4],
                                    double *out_kmin, double *out_kmax,
                                    double out_centre_j[4])
{
  double kmin = HUGE_VAL, kmax = -HUGE_VAL, k, conv, j[4];
  tt_status s = raster_scale_at(ctx, ct, gt, nx, ny, nx / 2, ny / 2,
                                metric_par, &k, &conv, out_centre_j);
  if (s != TT_OK)
    return s;
  for (int side = 0; side < 4; side++) {
    size_t n = side < 2 ? nx : ny; /* 0, 1: top, bottom rows; 2, 3: columns */
    size_t steps = n - 1 < TT_OUTLINE_STEPS ? n - 1 : TT_OUTLINE_STEPS;
    for (size_t i = 0; i <= steps; i++) {
      size_t at = (size_t)((double)i * (double)(n - 1) / (double)steps + 0.5);
      size_t c = side < 2 ? at : side == 2 ? 0 : nx - 1;
      size_t r = side < 2 ? (side == 0 ? 0 : ny - 1) : at;
      s = raster_scale_at(ctx, ct, gt, nx, ny, c, r, metric_par, &k, &conv,
                          j);
      if (s != TT_OK)
        return s;
      kmin = fmin(kmin, k);
      kmax = fmax(kmax, k);
    }
  }
  for (int q = 0; q < 4; q++) {
    size_t c = (q & 1) ? nx / 2 : (nx - 1) / 2;
    size_t r = (q & 2) ? ny / 2 : (ny - 1) / 2;
    s = raster_scale_at(ctx, ct, gt, nx, ny, c, r, metric_par, &k, &conv, j);
    if (s != TT_OK)
      return s;
    kmin = fmin(kmin, k);
    kmax = fmax(kmax, k);
  }
  *out_kmin = kmin;
  *out_kmax = kmax;
  return TT_OK;
}

/* A ground-point job: where the map coordinates stand on the ellipsoid,
 * the raster's extent, the working projection and PROJ's transformation
 * into it. */
typedef struct conformal {
  tt_context *ctx;
  source sk;
  double a, f, e2;    /* the ellipsoid: semi-major axis, flattening, e^2 */
  double u, deg;      /* radians and degrees per unit (1: Web Mercator) */
  double lon_min, lon_max, lat_min, lat_max; /* the raster's, degrees */
  double lon0, lat0;  /* its centre */
  OGRSpatialReferenceH work, src; /* src: srs in GIS axis order */
  OGRCoordinateTransformationH ct;
  char work_name[384];
  frame_kind kind;
} conformal;

/* The ellipsoid and angular unit of srs (geographic or Web Mercator), and
 * whether the window (nx x ny at col0, row0) lies in the raster's rnx x rny
 * samples. */
static tt_status read_source(conformal *cf, OGRSpatialReferenceH srs,
                             size_t rnx, size_t rny, size_t col0,
                             size_t row0, size_t nx, size_t ny)
{
  OGRErr err = OGRERR_NONE;
  source *sk = &cf->sk;
  if (!OSRIsGeographic(srs) && !web_mercator_of(srs, sk))
    return tt__error(cf->ctx, TT_ERR_DATA, "ground points need a "
                     "geographic or Web Mercator CRS");
  double a = OSRGetSemiMajor(srs, &err);
  double invf = err == OGRERR_NONE ? OSRGetInvFlattening(srs, &err) : 0;
  double u = sk->webmerc ? 1.0 : OSRGetAngularUnits(srs, NULL); /* radians
                                                                   per unit */
  sk->u = u;
  if (err != OGRERR_NONE || !(a > 0) || !isfinite(invf) || invf < 0 ||
      !(u > 0) || rnx < 2 || rny < 2 || col0 + nx > rnx || row0 + ny > rny)
    return tt__error(cf->ctx, TT_ERR_DATA, "no ellipsoid or angular unit "
                     "for ground points");
  cf->a = a;
  cf->u = u;
  cf->f = invf > 0 ? 1.0 / invf : 0.0;
  cf->e2 = cf->f * (2.0 - cf->f);
  cf->deg = u * 180.0 / TT_PI;
  return TT_OK;
}

/* Extent of the whole raster's sample centres (a geotransform is affine,
 * longitude and latitude monotonic in x and y: the corners): a window gets
 * the frame of the raster it is cut from. */
static tt_status raster_extent(conformal *cf, const double gt[6],
                               size_t rnx, size_t rny)
{
  const double deg = cf->deg;
  double lon_min = HUGE_VAL, lon_max = -HUGE_VAL, lat_min = HUGE_VAL,
         lat_max = -HUGE_VAL;
  for (int k = 0; k < 4; k++) {
    double px = (k & 1) ? (double)rnx - 0.5 : 0.5;
    double py = (k & 2) ? (double)rny - 0.5 : 0.5;
    double lon = (gt[0] + px * gt[1] + py * gt[2]) * deg;
    double lat = (gt[3] + px * gt[4] + py * gt[5]) * deg;
    if (cf->sk.webmerc) {
      to_lonlat(&cf->sk, gt[0] + px * gt[1] + py * gt[2],
                gt[3] + px * gt[4] + py * gt[5], &lon, &lat);
      lon *= 180 / TT_PI;
      lat *= 180 / TT_PI;
    }
    lon_min = fmin(lon_min, lon);
    lon_max = fmax(lon_max, lon);
    lat_min = fmin(lat_min, lat);
    lat_max = fmax(lat_max, lat);
  }
  if (!(lat_min >= -90.0 && lat_max <= 90.0 && lon_max - lon_min <= 360.0))
    return tt__error(cf->ctx, TT_ERR_DATA, "the grid's extent is not "
                     "geographic");
  cf->lon_min = lon_min;
  cf->lon_max = lon_max;
  cf->lat_min = lat_min;
  cf->lat_max = lat_max;
  cf->lon0 = 0.5 * (lon_min + lon_max);
  cf->lat0 = 0.5 * (lat_min + lat_max);
  return TT_OK;
}

/* The working projection: work_srs when given (projected, else
 * TT_ERR_ARG), else the one chosen for the extent (choose()). */
static tt_status working_crs(conformal *cf, OGRSpatialReferenceH srs,
                             const char *work_srs)
{
  if (work_srs && *work_srs) {
    cf->work = OSRNewSpatialReference(NULL);
    CPLPushErrorHandler(CPLQuietErrorHandler);
    CPLSetCurrentErrorHandlerCatchDebug(FALSE); /* debug: the handler below */
    if (!cf->work || OSRSetFromUserInput(cf->work, work_srs) != OGRERR_NONE ||
        !OSRIsProjected(cf->work)) {
      CPLPopErrorHandler();
      return tt__error(cf->ctx, TT_ERR_ARG, "-work_srs '%s' is not a "
                       "projected CRS GDAL understands", work_srs);
    }
    CPLPopErrorHandler();
    const char *nm = OSRGetName(cf->work);
    snprintf(cf->work_name, sizeof cf->work_name, "%s (%s)",
             nm ? nm : "unnamed", work_srs);
    return TT_OK;
  }
  cf->work = choose(srs, cf->lon0, cf->lat0, cf->lon_min, cf->lon_max,
                    cf->lat_min, cf->lat_max, &cf->kind, cf->work_name,
                    sizeof cf->work_name);
  if (!cf->work)
    return tt__error(cf->ctx, TT_ERR_DATA, "GDAL cannot build a conformal "
                     "working projection on this CRS's datum");
  return TT_OK;
}

/* PROJ's transformation from srs (GIS axis order) to the working
 * projection, Web Mercator's inverse checked against PROJ first. */
static tt_status open_transform(conformal *cf, OGRSpatialReferenceH srs,
                                const char *work_srs, const double gt[6],
                                size_t rnx, size_t rny)
{
  cf->src = OSRClone(srs);
  if (cf->src)
    OSRSetAxisMappingStrategy(cf->src, OAMS_TRADITIONAL_GIS_ORDER);
  if (cf->sk.webmerc) {
    tt_status s = check_web_mercator(cf->ctx, cf->src, &cf->sk, gt, rnx, rny);
    if (s != TT_OK)
      return s;
  }
  OSRSetAxisMappingStrategy(cf->work, OAMS_TRADITIONAL_GIS_ORDER);
  CPLPushErrorHandler(CPLQuietErrorHandler);
  CPLSetCurrentErrorHandlerCatchDebug(FALSE); /* debug: the handler below */
  cf->ct = cf->src ? OCTNewCoordinateTransformation(cf->src, cf->work) : NULL;
  CPLPopErrorHandler();
  if (!cf->ct)
    return tt__error(cf->ctx,
                     work_srs && *work_srs ? TT_ERR_ARG : TT_ERR_DATA,
                     "PROJ cannot transform the raster's CRS to %s",
                     cf->work_name);
  return TT_OK;
}

/* Every sample of the grid projected, times scale, into its ground points
 * (allocated here), a row at a time: from the raster's own column and row
 * (not the window's geotransform), so that two tiles sharing a sample
 * compute the same bits for it, and an untiled run too. */
static tt_status project_samples(conformal *cf, tt_grid *grid,
                                 const double gt[6], size_t col0,
                                 size_t row0, double scale,
                                 tt_progress_fn progress, void *progress_arg)
{
  const size_t nx = grid->nx, ny = grid->ny;
  double *lx = malloc(nx * sizeof *lx);
  double *ly = malloc(nx * sizeof *ly);
  int *ok = malloc(nx * sizeof *ok);
  tt_status s = TT_OK;
  if (!lx || !ly || !ok) {
    s = tt__error(cf->ctx, TT_ERR_NOMEM, "out of memory for ground points");
    goto done;
  }
  s = tt_grid_alloc_ground_points(cf->ctx, grid);
  if (s != TT_OK)
    goto done;
  double *xy = tt_grid_ground_xy(grid);
  for (size_t r = 0; r < ny; r++) {
    for (size_t c = 0; c < nx; c++) {
      double px = (double)(col0 + c) + 0.5, py = (double)(row0 + r) + 0.5;
      lx[c] = gt[0] + px * gt[1] + py * gt[2];
      ly[c] = gt[3] + px * gt[4] + py * gt[5];
    }
    CPLPushErrorHandler(CPLQuietErrorHandler);
    CPLSetCurrentErrorHandlerCatchDebug(FALSE); /* debug: the handler below */
    int all = OCTTransformEx(cf->ct, (int)nx, lx, ly, NULL, ok);
    CPLPopErrorHandler();
    for (size_t c = 0; c < nx; c++) {
      if (!all || !ok[c] || !isfinite(lx[c]) || !isfinite(ly[c])) {
        s = tt__error(cf->ctx, TT_ERR_DATA, "PROJ cannot project sample "
                      "(col %zu, row %zu) into %s", col0 + c, row0 + r,
                      cf->work_name);
        goto done;
      }
      xy[2 * (r * nx + c)] = lx[c] * scale;
      xy[2 * (r * nx + c) + 1] = ly[c] * scale;
    }
    /* every 16 rows: some 0.1 s of a 12000-sample-wide DEM */
    if (progress && (r % 16 == 15 || r + 1 == ny) &&
        !progress((double)(r + 1) / (double)ny, "projecting",
                  progress_arg)) {
      s = tt__error(cf->ctx, TT_ERR_INTERRUPTED, "interrupted while "
                    "projecting row %zu of %zu", row0 + r, ny);
      goto done;
    }
  }
done:
  free(lx);
  free(ly);
  free(ok);
  return s;
}

tt_status tt__georef_ground_points(tt_context *ctx, OGRSpatialReferenceH srs,
                                   const char *work_srs,
                                   const double raster_gt[6],
                                   size_t raster_nx, size_t raster_ny,
                                   size_t col0, size_t row0, tt_grid *grid,
                                   tt_progress_fn progress,
                                   void *progress_arg, char *out_name,
                                   size_t name_size,
                                   double *out_scale_error)
{
  const size_t rnx = raster_nx, rny = raster_ny;
  const double *gt = raster_gt;
  conformal cf;
  memset(&cf, 0, sizeof cf);
  cf.ctx = ctx;
  cf.kind = FRAME_USER;
  tt_status s = read_source(&cf, srs, rnx, rny, col0, row0, grid->nx,
                            grid->ny);
  if (s == TT_OK)
    s = raster_extent(&cf, gt, rnx, rny);
  if (s != TT_OK)
    return s; /* nothing made yet */
  s = working_crs(&cf, srs, work_srs);
  if (s != TT_OK)
    goto done;
  s = open_transform(&cf, srs, work_srs, gt, rnx, rny);
  if (s != TT_OK)
    goto done;

  /* The range of k and the frame at the centre, of the whole raster. */
  const source *sk = &cf.sk;
  const double metric_par[4] = {cf.a, cf.e2, sk->webmerc ? -sk->R : cf.u, 0};
  double kmin, kmax, centre_frame[4];
  s = raster_scale_range(ctx, cf.ct, gt, rnx, rny, metric_par, &kmin, &kmax,
                         centre_frame);
  if (s != TT_OK)
    goto done;
  double scale = 1.0;
  if (cf.kind == FRAME_POLAR || cf.kind == FRAME_MERCATOR ||
      cf.kind == FRAME_STEREO)
    scale = 2.0 / (kmin + kmax);
  s = project_samples(&cf, grid, gt, col0, row0, scale, progress,
                      progress_arg);
  if (s != TT_OK)
    goto done;

  /* k and the convergence at the TIN's vertices (tt_grid_ground_scale_at,
   * against the ellipsoid's metric, at the raster's map coordinates) */
  tt_grid_set_ground_metric_fn(grid, ellipsoid_metric, metric_par);
  tt__grid_set_ground_origin(grid, col0, row0, raster_gt);
  if (scale != 1.0) {
    for (int k = 0; k < 4; k++)
      centre_frame[k] *= scale;
    kmin *= scale;
    kmax *= scale;
    size_t len = strlen(cf.work_name);
    snprintf(cf.work_name + len, sizeof cf.work_name - len,
             ", scaled by %.9f", scale);
  }
  s = tt_grid_set_ground_frame(ctx, grid, centre_frame);
  if (s != TT_OK)
    goto done;
  const double area_par[4] = {cf.a, cf.f, sk->webmerc ? -1.0 / sk->R : cf.deg,
                              sk->lon0 * 180 / TT_PI};
  tt_grid_set_area_fn(grid, geodesic_area, area_par);
  double err_max = fmax(fabs(kmax - 1.0), fabs(kmin - 1.0));
  *out_scale_error = err_max;
  snprintf(out_name, name_size, "%s, per vertex; scale %.6f to %.6f "
           "(%.2g%% off over the whole DEM)", cf.work_name, kmin, kmax,
           100 * err_max);
done:
  if (s != TT_OK) {
    tt_grid_drop_ground_points(grid);
    tt_grid_set_area_fn(grid, NULL, NULL);
    tt_grid_set_ground_metric_fn(grid, NULL, NULL);
  }
  if (cf.ct)
    OCTDestroyCoordinateTransformation(cf.ct);
  OSRDestroySpatialReference(cf.src);
  OSRDestroySpatialReference(cf.work);
  return s;
}
