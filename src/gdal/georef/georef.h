/*
 * src/gdal/georef/ -- the georeferencing: where a grid's samples stand on
 * the ground, with PROJ (the affine ground frame, and the conformal ground
 * points of a geographic or Web Mercator grid).
 *
 * georef.h -- the glue's private interface to georef_proj.c (the ground
 * frame of a georeferenced grid, chosen with PROJ) and georef_conformal.c
 * (the ground points of a geographic or Web Mercator grid), used by the
 * band reader (raster_georef.c). Glue only: it includes GDAL's OGR SRS
 * API.
 */
#ifndef TT_GEOREF_H
#define TT_GEOREF_H

#include "base/internal.h"

#include <ogr_srs_api.h>

/* The local equirectangular frame from the CRS's ellipsoid at the grid's
 * centre latitude (the fallback when PROJ cannot help). */
TT_HIDDEN tt_status tt__georef_geographic_frame(tt_context *ctx,
                                                OGRSpatialReferenceH srs,
                                                const double gt[6],
                                                size_t nx, size_t ny,
                                                double out_frame[4],
                                                char *out_name,
                                                size_t name_size);
/* The ground frame: the Jacobian of pixel -> working CRS (work_srs, or the
 * UTM zone of the centre) at the grid's centre, for geographic and
 * non-metric projected CRSs; the geotransform otherwise. */
TT_HIDDEN tt_status tt__georef_ground_frame(tt_context *ctx,
                                            OGRSpatialReferenceH srs,
                                            const char *work_srs,
                                            const double gt[6], size_t nx,
                                            size_t ny, double out_frame[4],
                                            char *out_name,
                                            size_t name_size);

/* The UTM zone (UPS beyond 84 N / 80 S, WGS 84 only) of a point at
 * (lon, lat) degrees on srs's datum; out_name gets e.g. "UTM zone 17N
 * (EPSG:32617)". NULL when none fits. The caller destroys it. */
TT_HIDDEN OGRSpatialReferenceH tt__georef_utm_of(OGRSpatialReferenceH srs,
                                                 double lon, double lat,
                                                 char *out_name,
                                                 size_t name_size);

/* Whether srs is Web Mercator (a spherical Mercator on geodetic
 * longitudes and latitudes, EPSG:3857 and its aliases), whose grids get
 * ground points as geographic ones do (georef_conformal.c). */
TT_HIDDEN int tt__georef_is_web_mercator(OGRSpatialReferenceH srs);

/* Ground points for a grid in a geographic or Web Mercator CRS
 * (georef_conformal.c): the grid is the window at (col0, row0) of a raster
 * of raster_nx x raster_ny samples with geotransform raster_gt (the whole
 * raster: 0, 0 and the grid's own size). Chooses a conformal working
 * projection for the raster's extent (or work_srs), projects every sample
 * of the grid from the raster's column and row, fills the grid's ground
 * points (tt_grid_alloc_ground_points), its ground metric and origin and
 * its area function, and sets its ground frame to the projection's
 * Jacobian at the raster's centre. The frame, its constant scale and
 * everything measured depend on the raster only: a window's ground points
 * are the whole raster's, bit for bit. out_name describes the frame;
 * out_scale_error gets the largest |k - 1| over the raster's outline and
 * centre. progress (may be NULL) is told the share of rows projected;
 * its 0 stops with TT_ERR_INTERRUPTED. TT_ERR_ARG for an unusable
 * work_srs; other failures leave the grid as it was and return the
 * status. */
TT_HIDDEN tt_status tt__georef_ground_points(tt_context *ctx,
                                             OGRSpatialReferenceH srs,
                                             const char *work_srs,
                                             const double raster_gt[6],
                                             size_t raster_nx,
                                             size_t raster_ny, size_t col0,
                                             size_t row0, tt_grid *grid,
                                             tt_progress_fn progress,
                                             void *progress_arg,
                                             char *out_name,
                                             size_t name_size,
                                             double *out_scale_error);

#endif /* TT_GEOREF_H */
