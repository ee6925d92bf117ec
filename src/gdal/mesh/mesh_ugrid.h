/*
 * src/gdal/mesh/ -- the mesh formats: a TIN as SMS 2DM, PLY, OBJ, LandXML
 * or UGRID netCDF, without OGR.
 *
 * mesh_ugrid.h -- the UGRID netCDF writer (ugrid_write.c), called by
 * tt_mesh_write() for -of UGRID with the records it set up.
 */
#ifndef TERRATIN_MESH_UGRID_H
#define TERRATIN_MESH_UGRID_H

#include "gdal/ogr/tin_records.h"

/* Writes the TIN of rec to the netCDF file path (created or truncated) as
 * a UGRID 1.0 mesh named "mesh" (long_name: name). progress may stop it
 * (TT_ERR_INTERRUPTED). The caller removes path on failure. */
TT_HIDDEN tt_status tt__ugrid_write(tt_context *ctx, const char *path,
                                    const char *name, const tt__records *rec,
                                    tt_progress_fn progress,
                                    void *progress_arg);

#endif /* TERRATIN_MESH_UGRID_H */
