/*
 * src/gdal/georef/ -- the georeferencing: where a grid's samples stand on
 * the ground, with PROJ (the affine ground frame, and the conformal ground
 * points of a geographic or Web Mercator grid).
 *
 * georef_proj.c -- where a grid's pixels stand on the ground.
 *
 * The engine measures angles, areas and the Delaunay test in a *ground
 * frame*: an affine map from a pixel step to metres (tt_grid_set_ground_
 * frame). It must stay affine, because the incircle test is exact only for
 * a constant metric tensor. This file chooses that frame.
 *
 *  - A projected CRS in metres whose scale is within TT_METRIC_TOLERANCE of
 *    the local UTM zone's (UTM itself, national grids, conformal conics):
 *    the geotransform's linear part, unchanged.
 *  - A projected CRS in another linear unit (feet, US survey feet) that is
 *    metric in that sense once the unit is converted: the geotransform's
 *    linear part times the unit (metres per map unit).
 *  - A geographic CRS, or a projected CRS whose map units are not ground
 *    metres (Web Mercator, a sheared sinusoidal), or any CRS when the
 *    caller names a working CRS (-work_srs): the Jacobian of
 *    pixel -> working-CRS coordinates at the grid's centre, by central
 *    differences over TT_JACOBIAN_STEP pixels through PROJ (OGR coordinate
 *    transformations, traditional GIS axis order on both sides). That is
 *    the Jacobian of map -> working frame times the geotransform's linear
 *    part. The working CRS is the UTM zone of the centre on the CRS's own
 *    datum (WGS 84: EPSG:326zz / 327zz; other datums: the same projection
 *    built on their geographic CRS, named by EPSG when GDAL can identify
 *    it), or UPS beyond 84 N / 80 S on WGS 84.
 *  - When PROJ cannot transform (no datum, no grid, a CRS it rejects): for
 *    a geographic CRS, the old local equirectangular frame from the CRS's
 *    ellipsoid (meridional and prime-vertical radii at the centre latitude),
 *    with a warning; for a projected CRS, the geotransform scaled by the
 *    CRS's linear unit, with a warning.
 *
 * An affine frame is exact at the centre only. On a longitude/latitude grid
 * the metres per degree of longitude change by tan(lat) * dlat between the
 * centre row and the others (the grid is a trapezoid on the ground), which
 * no affine map removes: 0.19% at the edges of the 0.29-degree Jacksboro
 * DEM, 0.84% for a 1-degree DTED tile (tests/gdal/test_georef.c measures
 * it against PROJ's own coordinates). The frame's name says how far it
 * strays at the grid's corners, and beyond 1% a warning says so.
 * Geographic and Web Mercator grids then get ground points instead
 * (georef_conformal.c); the affine frame is their fallback.
 *
 * Heights are never touched here.
 *
 * Workload: five coordinate transformations and the creation of one PROJ
 * pipeline per grid read.
 */
#include "gdal/georef/georef.h"
#include "base/internal.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include <cpl_conv.h>
#include <cpl_error.h>
#include <ogr_srs_api.h>

/* M_PI is not in strict C11. */
#define TT_PI 3.14159265358979323846

/* Half-width, in pixels, of the central differences of the Jacobian. */
#define TT_JACOBIAN_STEP 2.0
/* A metric projected CRS keeps its geotransform frame when the lengths of
 * a column step, a row step and the angle between them agree with UTM's to
 * this relative tolerance (UTM's own scale varies by 0.1% across a zone). */
#define TT_METRIC_TOLERANCE 0.01

/* Sets out_frame to the geotransform's linear part scaled to metres at the
 * centre latitude of an nx x ny grid: column and row steps in the CRS's
 * angular unit become (m per unit of longitude, m per unit of latitude)
 * steps. Assumes the GIS axis order (x = longitude, y = latitude), as GDAL
 * datasets report. out_name receives a short description for summaries. */
tt_status tt__georef_geographic_frame(tt_context *ctx,
                                      OGRSpatialReferenceH srs,
                                      const double gt[6], size_t nx,
                                      size_t ny, double out_frame[4],
                                      char *out_name, size_t name_size)
{
  OGRErr err = OGRERR_NONE;
  double a = OSRGetSemiMajor(srs, &err);
  if (err != OGRERR_NONE || !(a > 0) || !isfinite(a))
    return tt__error(ctx, TT_ERR_FORMAT, "geographic CRS has no usable "
                     "ellipsoid (semi-major axis)");
  double invf = OSRGetInvFlattening(srs, &err);
  if (err != OGRERR_NONE || !isfinite(invf) || invf < 0)
    return tt__error(ctx, TT_ERR_FORMAT, "geographic CRS has no usable "
                     "ellipsoid (inverse flattening)");
  /* Radians per angular unit (0.0174532925... for degrees). */
  char *unit_name = NULL;
  double rad_per_unit = OSRGetAngularUnits(srs, &unit_name);
  if (!(rad_per_unit > 0) || !isfinite(rad_per_unit))
    return tt__error(ctx, TT_ERR_FORMAT, "geographic CRS has no usable "
                     "angular unit");

  /* Latitude of the grid's centre, in the CRS's angular unit. */
  double cx = 0.5 * (double)nx, cy = 0.5 * (double)ny;
  double lat_units = gt[3] + cx * gt[4] + cy * gt[5];
  double lat = lat_units * rad_per_unit;
  if (!isfinite(lat) || fabs(lat) > 0.5 * TT_PI + 1e-9)
    return tt__error(ctx, TT_ERR_DATA, "grid centre latitude %g is outside "
                     "[-90, 90] degrees: the geotransform does not look "
                     "geographic", lat / TT_PI * 180.0);

  /* e^2 = f (2 - f); invf == 0 means a sphere. */
  double f = invf > 0 ? 1.0 / invf : 0.0;
  double e2 = f * (2.0 - f);
  double s = sin(lat);
  double w2 = 1.0 - e2 * s * s;
  double n_radius = a / sqrt(w2);                  /* prime vertical */
  double m_radius = a * (1.0 - e2) / (w2 * sqrt(w2)); /* meridional */
  double kx = n_radius * cos(lat) * rad_per_unit;  /* m per unit of lon */
  double ky = m_radius * rad_per_unit;             /* m per unit of lat */
  if (!(kx > 0)) /* at a pole the parallels shrink to a point */
    return tt__error(ctx, TT_ERR_DATA, "grid centre is at a pole: a local "
                     "equirectangular frame does not exist there");

  out_frame[0] = kx * gt[1];
  out_frame[1] = kx * gt[2];
  out_frame[2] = ky * gt[4];
  out_frame[3] = ky * gt[5];
  if (out_name && name_size)
    snprintf(out_name, name_size,
             "local equirectangular at latitude %.6f (%.3f m per %s of "
             "longitude, %.3f m per %s of latitude)",
             lat / TT_PI * 180.0, kx, unit_name ? unit_name : "unit", ky,
             unit_name ? unit_name : "unit");
  return TT_OK;
}

/* A copy of srs that takes and gives (x = easting or longitude, y =
 * northing or latitude), whatever the CRS's own axis order. */
static OGRSpatialReferenceH gis_order_clone(OGRSpatialReferenceH srs)
{
  OGRSpatialReferenceH c = OSRClone(srs);
  if (c)
    OSRSetAxisMappingStrategy(c, OAMS_TRADITIONAL_GIS_ORDER);
  return c;
}

/* Map coordinates of pixel-edge position (px, py). */
static void pixel_to_map(const double gt[6], double px, double py,
                         double *x, double *y)
{
  *x = gt[0] + px * gt[1] + py * gt[2];
  *y = gt[3] + px * gt[4] + py * gt[5];
}

/* Longitude and latitude (degrees) of the grid's centre on srs's own
 * geographic CRS. 0 when PROJ cannot say. */
static int centre_lonlat(OGRSpatialReferenceH srs, const double gt[6],
                         size_t nx, size_t ny, double *out_lon,
                         double *out_lat)
{
  int ok = 0;
  OGRSpatialReferenceH geog = OSRCloneGeogCS(srs);
  OGRSpatialReferenceH src = gis_order_clone(srs);
  OGRCoordinateTransformationH ct = NULL;
  if (!geog || !src)
    goto done;
  OSRSetAxisMappingStrategy(geog, OAMS_TRADITIONAL_GIS_ORDER);
  double x, y, z = 0;
  pixel_to_map(gt, 0.5 * (double)nx, 0.5 * (double)ny, &x, &y);
  if (OSRIsGeographic(srs)) {
    ok = 1;
  } else {
    ct = OCTNewCoordinateTransformation(src, geog);
    ok = ct && OCTTransform(ct, 1, &x, &y, &z);
  }
  if (ok) {
    double deg = OSRGetAngularUnits(geog, NULL) * 180.0 / TT_PI;
    *out_lon = x * deg;
    *out_lat = y * deg;
    ok = isfinite(*out_lon) && isfinite(*out_lat) && fabs(*out_lat) <= 90;
  }
done:
  if (ct)
    OCTDestroyCoordinateTransformation(ct);
  OSRDestroySpatialReference(src);
  OSRDestroySpatialReference(geog);
  return ok;
}

/* "EPSG:32617" when srs carries or can be identified by an EPSG code,
 * else "". */
static void epsg_of(OGRSpatialReferenceH srs, char *buf, size_t size)
{
  buf[0] = '\0';
  const char *auth = OSRGetAuthorityName(srs, NULL);
  const char *code = OSRGetAuthorityCode(srs, NULL);
  if (auth && code) {
    snprintf(buf, size, "%s:%s", auth, code);
    return;
  }
  OGRSpatialReferenceH guess = OSRClone(srs);
  if (!guess)
    return;
  if (OSRAutoIdentifyEPSG(guess) == OGRERR_NONE) {
    code = OSRGetAuthorityCode(guess, NULL);
    if (code)
      snprintf(buf, size, "like EPSG:%s", code);
  }
  OSRDestroySpatialReference(guess);
}

/* The UTM (or UPS) working CRS of a centre at (lon, lat) on srs's datum.
 * out_name gets e.g. "UTM zone 17N (EPSG:32617)". NULL when none fits. */
OGRSpatialReferenceH tt__georef_utm_of(OGRSpatialReferenceH srs,
                                       double lon, double lat,
                                       char *out_name, size_t name_size)
{
  OGRSpatialReferenceH geog = OSRCloneGeogCS(srs);
  OGRSpatialReferenceH wgs84 = OSRNewSpatialReference(NULL);
  OGRSpatialReferenceH work = OSRNewSpatialReference(NULL);
  int is_wgs84 = 0, ok = 0;
  if (!geog || !wgs84 || !work)
    goto done;
  is_wgs84 = OSRImportFromEPSG(wgs84, 4326) == OGRERR_NONE &&
             OSRIsSameGeogCS(geog, wgs84);
  lon = fmod(lon + 180.0, 360.0);
  if (lon < 0)
    lon += 360.0;
  int zone = (int)floor(lon / 6.0) + 1;
  if (zone > 60)
    zone = 60;
  int north = lat >= 0;
  char code[64];
  if (lat > 84.0 || lat < -80.0) {
    /* Beyond UTM's range: Universal Polar Stereographic, WGS 84 only. */
    if (!is_wgs84)
      goto done;
    int epsg = north ? 32661 : 32761;
    ok = OSRImportFromEPSG(work, epsg) == OGRERR_NONE;
    snprintf(out_name, name_size, "UPS %s (EPSG:%d)",
             north ? "North" : "South", epsg);
  } else if (is_wgs84) {
    int epsg = (north ? 32600 : 32700) + zone;
    ok = OSRImportFromEPSG(work, epsg) == OGRERR_NONE;
    snprintf(out_name, name_size, "UTM zone %d%c (EPSG:%d)", zone,
             north ? 'N' : 'S', epsg);
  } else {
    ok = OSRCopyGeogCSFrom(work, geog) == OGRERR_NONE &&
         OSRSetProjCS(work, "UTM") == OGRERR_NONE &&
         OSRSetUTM(work, zone, north) == OGRERR_NONE;
    if (ok) {
      const char *datum = OSRGetAttrValue(geog, "DATUM", 0);
      epsg_of(work, code, sizeof code);
      snprintf(out_name, name_size, "UTM zone %d%c on %s (%s)", zone,
               north ? 'N' : 'S', datum ? datum : "its datum",
               code[0] ? code : "no EPSG code");
    }
  }
done:
  OSRDestroySpatialReference(geog);
  OSRDestroySpatialReference(wgs84);
  if (!ok) {
    OSRDestroySpatialReference(work);
    return NULL;
  }
  return work;
}

/* The Jacobian of pixel -> work coordinates at the grid's centre, by
 * central differences over TT_JACOBIAN_STEP pixels, and how far the affine
 * frame strays from the working CRS at the grid's four corners: the
 * largest |frame offset - true offset| / |true offset| from the centre.
 * 0 on failure. */
static int jacobian(OGRSpatialReferenceH srs, OGRSpatialReferenceH work,
                    const double gt[6], size_t nx, size_t ny,
                    double out_frame[4], double *out_corner_error)
{
  OGRSpatialReferenceH src = gis_order_clone(srs);
  OGRSpatialReferenceH dst = gis_order_clone(work);
  OGRCoordinateTransformationH ct =
      src && dst ? OCTNewCoordinateTransformation(src, dst) : NULL;
  int ok = 0;
  if (ct) {
    const double h = TT_JACOBIAN_STEP;
    const double cx = 0.5 * (double)nx, cy = 0.5 * (double)ny;
    /* +col, -col, +row, -row, the centre, the four corners */
    const double ex = 0.5 * (double)nx, ey = 0.5 * (double)ny;
    const double dpx[9] = {h, -h, 0, 0, 0, -ex, ex, -ex, ex};
    const double dpy[9] = {0, 0, h, -h, 0, -ey, -ey, ey, ey};
    double x[9], y[9], z[9] = {0};
    for (int k = 0; k < 9; k++)
      pixel_to_map(gt, cx + dpx[k], cy + dpy[k], &x[k], &y[k]);
    int success[9] = {0};
    ok = OCTTransformEx(ct, 9, x, y, z, success);
    for (int k = 0; k < 5; k++)
      ok = ok && success[k];
    if (ok) {
      out_frame[0] = (x[0] - x[1]) / (2 * h);
      out_frame[2] = (y[0] - y[1]) / (2 * h);
      out_frame[1] = (x[2] - x[3]) / (2 * h);
      out_frame[3] = (y[2] - y[3]) / (2 * h);
      for (int k = 0; k < 4; k++)
        ok = ok && isfinite(out_frame[k]);
    }
    *out_corner_error = NAN;
    for (int k = 5; ok && k < 9; k++) {
      if (!success[k])
        continue;
      double fx = out_frame[0] * dpx[k] + out_frame[1] * dpy[k];
      double fy = out_frame[2] * dpx[k] + out_frame[3] * dpy[k];
      double tx = x[k] - x[4], ty = y[k] - y[4];
      double e = hypot(fx - tx, fy - ty) / hypot(tx, ty);
      if (isfinite(e) && !(e <= *out_corner_error))
        *out_corner_error = e;
    }
    OCTDestroyCoordinateTransformation(ct);
  }
  OSRDestroySpatialReference(src);
  OSRDestroySpatialReference(dst);
  return ok;
}

/* Whether frame a and the geotransform's linear part agree as metrics:
 * column and row step lengths and the angle between them within tol. */
static int same_metric(const double a[4], const double gt[6], double tol)
{
  double ac = hypot(a[0], a[2]), ar = hypot(a[1], a[3]);
  double gc = hypot(gt[1], gt[4]), gr = hypot(gt[2], gt[5]);
  double acos_ = (a[0] * a[1] + a[2] * a[3]) / (ac * ar);
  double gcos = (gt[1] * gt[2] + gt[4] * gt[5]) / (gc * gr);
  return fabs(ac / gc - 1) <= tol && fabs(ar / gr - 1) <= tol &&
         fabs(acos_ - gcos) <= tol;
}

static int orientation_ok(const double a[4], const double gt[6])
{
  double det = a[0] * a[3] - a[1] * a[2];
  double gdet = gt[1] * gt[5] - gt[2] * gt[4];
  return det != 0 && (det < 0) == (gdet < 0);
}

/* Chooses the ground frame of an nx x ny grid with geotransform gt in CRS
 * srs (may be NULL: the geotransform) as the file comment says. work_srs:
 * NULL or a CRS in any form OSRSetFromUserInput() takes (it must be
 * projected). out_name gets the frame's description; warnings go to the
 * context. TT_ERR_ARG for an unusable work_srs. */
tt_status tt__georef_ground_frame(tt_context *ctx, OGRSpatialReferenceH srs,
                                  const char *work_srs, const double gt[6],
                                  size_t nx, size_t ny, double out_frame[4],
                                  char *out_name, size_t name_size)
{
  tt_status s = TT_OK;
  OGRSpatialReferenceH work = NULL;
  char work_name[256] = "";
  out_frame[0] = gt[1];
  out_frame[1] = gt[2];
  out_frame[2] = gt[4];
  out_frame[3] = gt[5];
  snprintf(out_name, name_size, "geotransform");

  if (work_srs && *work_srs) {
    if (!srs)
      return tt__error(ctx, TT_ERR_ARG, "-work_srs %s: the raster has no "
                       "CRS to transform from", work_srs);
    work = OSRNewSpatialReference(NULL);
    CPLPushErrorHandler(CPLQuietErrorHandler);
    CPLSetCurrentErrorHandlerCatchDebug(FALSE); /* debug: the handler below */
    OGRErr e = work ? OSRSetFromUserInput(work, work_srs) : OGRERR_FAILURE;
    CPLPopErrorHandler();
    if (e != OGRERR_NONE) {
      s = tt__error(ctx, TT_ERR_ARG, "-work_srs '%s' is not a CRS GDAL "
                    "understands", work_srs);
      goto done;
    }
    if (!OSRIsProjected(work)) {
      s = tt__error(ctx, TT_ERR_ARG, "-work_srs '%s' is not a projected "
                    "CRS: the working frame must be in linear units",
                    work_srs);
      goto done;
    }
    const char *nm = OSRGetName(work);
    char code[64];
    epsg_of(work, code, sizeof code);
    snprintf(work_name, sizeof work_name, "%s (%s)", nm ? nm : "unnamed",
             code[0] ? code : "no EPSG code");
  }
  if (!srs)
    goto done;

  const int geographic = OSRIsGeographic(srs);
  const int projected = OSRIsProjected(srs);
  if (!work && !geographic && !projected)
    goto done; /* local or engineering CRS: its units are all we have */

  double lon = 0, lat = 0;
  int have_centre = centre_lonlat(srs, gt, nx, ny, &lon, &lat);
  if (!work && have_centre)
    work = tt__georef_utm_of(srs, lon, lat, work_name, sizeof work_name);

  double frame[4], corner_error = NAN;
  int ok = work && jacobian(srs, work, gt, nx, ny, frame, &corner_error) &&
           orientation_ok(frame, gt);
  if (work && !ok && work_srs && *work_srs) {
    s = tt__error(ctx, TT_ERR_ARG, "-work_srs '%s': PROJ cannot transform "
                  "the raster's CRS to it", work_srs);
    goto done;
  }
  if (ok) {
    double m_per_unit = projected ? OSRGetLinearUnits(srs, NULL) : 0;
    if (!(work_srs && *work_srs) && projected && m_per_unit == 1.0 &&
        same_metric(frame, gt, TT_METRIC_TOLERANCE)) {
      snprintf(out_name, name_size, "geotransform (map units are metres "
               "within %g%% of %s)", 100 * TT_METRIC_TOLERANCE, work_name);
      goto done;
    }
    /* Feet (or any linear unit) on a projection that is metric once the
     * unit is converted (a state plane in US survey feet): the
     * geotransform times the unit, the exact path of a metric DEM; its
     * TIN is the one of the same samples in metres. */
    char *unit = NULL;
    m_per_unit = projected ? OSRGetLinearUnits(srs, &unit) : 0;
    double gts[6] = {0, gt[1] * m_per_unit, gt[2] * m_per_unit, 0,
                     gt[4] * m_per_unit, gt[5] * m_per_unit};
    if (!(work_srs && *work_srs) && projected && m_per_unit > 0 &&
        isfinite(m_per_unit) && m_per_unit != 1.0 &&
        !tt__georef_is_web_mercator(srs) &&
        same_metric(frame, gts, TT_METRIC_TOLERANCE)) {
      out_frame[0] = gts[1];
      out_frame[1] = gts[2];
      out_frame[2] = gts[4];
      out_frame[3] = gts[5];
      snprintf(out_name, name_size, "geotransform x %.10g m per %s (map "
               "units are metres within %g%% of %s once converted)",
               m_per_unit, unit && *unit ? unit : "map unit",
               100 * TT_METRIC_TOLERANCE, work_name);
      goto done;
    }
    memcpy(out_frame, frame, sizeof frame);
    char centre[64] = "", corners[96] = "";
    if (have_centre)
      snprintf(centre, sizeof centre, " (%.6f, %.6f)", lon, lat);
    if (isfinite(corner_error))
      snprintf(corners, sizeof corners, "; %.2g%% off at the corners",
               100 * corner_error);
    snprintf(out_name, name_size, "%s, affine at the centre%s%s", work_name,
             centre, corners);
    /* An affine frame cannot follow a grid much larger than a UTM zone:
     * say so rather than measure angles that mean little. A geographic
     * grid gets ground points instead (georef_conformal.c), which warns
     * itself if it cannot. */
    if (isfinite(corner_error) && corner_error > 0.01 && !geographic &&
        !tt__georef_is_web_mercator(srs))
      tt__warn(ctx, "the grid is large for one affine frame: the ground "
               "frame strays %.2g%% from %s at the grid's corners; angles, "
               "areas and the Delaunay test are approximate there (tile "
               "the DEM into pieces of a few degrees)", 100 * corner_error,
               work_name);
    goto done;
  }

  /* PROJ failed: the fallbacks. */
  if (geographic) {
    s = tt__georef_geographic_frame(ctx, srs, gt, nx, ny, frame, out_name,
                                    name_size);
    if (s == TT_OK) {
      memcpy(out_frame, frame, sizeof frame);
      tt__warn(ctx, "PROJ found no local projected frame for this "
               "geographic CRS; using the %s", out_name);
    }
    goto done;
  }
  double m_per_unit = OSRGetLinearUnits(srs, NULL);
  if (m_per_unit > 0 && isfinite(m_per_unit) && m_per_unit != 1.0) {
    for (int k = 0; k < 4; k++)
      out_frame[k] = gt[k < 2 ? k + 1 : k + 2] * m_per_unit;
    snprintf(out_name, name_size, "geotransform x %.10g m per map unit "
             "(PROJ found no UTM frame)", m_per_unit);
    tt__warn(ctx, "PROJ found no local projected frame for this CRS; "
             "angles and areas use its map units converted to metres, "
             "without correcting its scale");
  }
done:
  OSRDestroySpatialReference(work);
  return s;
}
