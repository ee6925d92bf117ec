/*
 * georef_proj.c -- where a grid's pixels stand on the ground.
 *
 * This file will hold the PROJ side of the glue: transforming a geographic
 * or otherwise non-metric grid into a proper local projected frame, vertical
 * unit conversion, and datum checks (a later issue). For now it holds one
 * function, the ground frame of a geographic grid: a local equirectangular
 * approximation at the grid's centre latitude, in metres, computed from the
 * CRS's own ellipsoid (meridional and prime-vertical radii of curvature).
 * It is exact at the centre latitude for distances along a parallel or a
 * meridian and drifts by about (1 - cos(dlat)) away from it, which is ample
 * for the angle and area measures of a TIN over a single DEM tile.
 *
 * Workload: a handful of floating-point operations per grid read.
 */
#include "internal.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include <ogr_srs_api.h>

/* M_PI is not in strict C11. */
#define TT_PI 3.14159265358979323846

/* Declared again in io_gdal_read.c, its only caller (the glue has no private
 * header of its own yet); keep the two in step. */
TT_HIDDEN tt_status tt__georef_geographic_frame(tt_context *ctx,
                                                OGRSpatialReferenceH srs,
                                                const double gt[6],
                                                size_t nx, size_t ny,
                                                double out_frame[4],
                                                char *out_name,
                                                size_t name_size);

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
