/*
 * georef.h -- the glue's private interface to georef_proj.c: the ground
 * frame of a georeferenced grid, chosen with PROJ (see georef_proj.c).
 * Glue only: it includes GDAL's OGR SRS API.
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

#endif /* TT_GEOREF_H */
