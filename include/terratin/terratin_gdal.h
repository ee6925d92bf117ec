/*
 * terratin_gdal.h -- the GDAL/OGR/PROJ glue of terratin.
 *
 * Functions take GDAL types in GDAL's argument order (band or layer, then
 * NAME=VALUE options, then a GDALProgressFunc-shaped callback and its
 * argument), like GDALContourGenerateEx. The engine header terratin.h stays
 * free of GDAL; only this header includes it.
 *
 * Ownership sentences are fixed: "The caller owns *out_X and frees it with
 * tt_X_destroy()."
 *
 * Part of include/terratin/, the public C API.
 */
#ifndef TERRATIN_GDAL_H
#define TERRATIN_GDAL_H

#include "terratin/terratin.h"

#include <gdal.h>
#include <ogr_api.h>
#include <ogr_srs_api.h>

#ifdef __cplusplus
extern "C" {
#endif

/* What a read learned about the raster, for summaries and run_parameters. */
typedef struct tt_raster_info {
  char *path;             /* as given */
  char *driver;           /* GDAL short name, e.g. "GTiff" */
  int band;               /* 1-based */
  size_t width, height;
  size_t valid_samples;   /* samples with data */
  size_t nodata_samples;
  double gt[6];
  int has_geotransform;   /* 0: the default (0,1,0,0,0,1) was used */
  char *crs_wkt;          /* "" when the raster has no CRS */
  char *crs_name;         /* short human name, "" when none */
  int crs_is_geographic;
  char *z_unit;           /* unit of the grid's heights: "m", "ft" or
                             "us-ft" when known (after Z_UNIT=m: "m"),
                             else the declared name, "" when unknown */
  double scale, offset;   /* applied to the raw values */
  double z_factor;        /* applied last, after scale/offset and
                             z_unit_factor */
  char *area_or_point;    /* "Area", "Point" or "" as declared */
  char *datatype;         /* GDAL data type name of the band */
  double frame[4];        /* ground frame set on the grid */
  char *frame_name;       /* "geotransform", "UTM zone 17N (EPSG:32617),
                             affine at the centre (...)", ... */
  double frame_scale_error; /* largest |k - 1| of the frame's scale factor
                             k over the samples for a frame of ground
                             points (geographic CRS), else NaN */
  char *z_unit_declared;  /* the height unit as the file declares it, ""
                             when it does not */
  char *z_unit_source;    /* "band unit", "vertical CRS" or "" */
  double z_unit_factor;   /* Z_UNIT=m's factor (0.3048 for ft, 1200/3937
                             for us-ft), else 1 */
  const char *z_unit_why; /* why the heights were converted to metres:
                             "asked" (Z_UNIT=m), "the CRS is in metres" or
                             "the CRS is geographic" (Z_UNIT=auto); "" when
                             they were not (a static string) */
} tt_raster_info;

void tt_raster_info_destroy(tt_raster_info *info);

/* Reads a band into a new grid, block by block, scale/offset and Z_FACTOR
 * applied, masked samples (GDAL mask band: nodata value, NaN, alpha, .msk)
 * stored as NaN. Valid samples that are NaN or infinite are refused (naming
 * row and column), so are rasters under 2 x 2, rasters with no valid
 * sample, and rasters georeferenced by GCPs only; a raster without a
 * geotransform gets (0,1,0,0,0,1) and has_geotransform 0. A geographic CRS,
 * or a projected one whose map units are not ground metres (Web Mercator,
 * feet), gives the grid a local metric ground frame chosen with PROJ: the
 * Jacobian at the grid's centre of pixel -> UTM zone of the centre (or
 * WORK_SRS) coordinates; metric projected CRSs keep the geotransform's
 * frame unless WORK_SRS is given (src/gdal/georef/georef_proj.c; info->frame_name says
 * which frame). Heights are never changed by the frame. Unless the user set
 * GDAL_CACHEMAX, GDAL's block cache limit (process-wide) is lowered to a
 * few MiB during the read and restored after.
 * No height is rounded: the grid holds floats when every valid height is
 * exactly a float (always for Byte, Int8, Int16, UInt16 and Float32 bands
 * without scale, offset or factor), else doubles (tt_grid_precision; the
 * heights computed as above in doubles); Int64 and UInt64 values beyond
 * +-2^53, which doubles cannot all hold, and heights beyond TT_MAX_HEIGHT
 * are refused.
 * Options: Z_FACTOR=<f> (default 1), SRCNODATA=<v> or SRCNODATA=nan
 * (replaces the mask; compared with the raw values), MAX_MEMORY=<bytes>
 * (refuse grids whose samples need more; default 3/4 of physical memory),
 * SRC_Z_UNIT=m|ft|us-ft (the unit the heights are in, over the band's
 * unit type and the vertical CRS, which say it otherwise: z_unit_source
 * "given"), Z_UNIT=m (heights in ft or us-ft -- SRC_Z_UNIT, else the band
 * unit type, else the vertical CRS -- are converted to metres: height =
 * (raw * scale + offset) * (unit factor * Z_FACTOR), in doubles in that
 * order; an unknown unit is refused unless Z_FACTOR is given, which then
 * does the whole conversion), Z_UNIT=auto (converted so when the CRS is
 * projected in metres or geographic, kept when it is in feet or absent;
 * an unknown unit is kept, never refused), WORK_SRS=<CRS> (any OSRSetFromUserInput form, projected:
 * the working frame), WINDOW=col,row,width,height (read those samples
 * only, for a tile: the grid's geotransform is that of its first sample,
 * its ground frame the whole raster's, a geographic or Web Mercator
 * raster's ground points those of the whole raster's samples, bit for bit,
 * a window of nodata only is no error, GDAL's cache is left alone),
 * SOURCE_NAME=<name> and SOURCE_DRIVER=<driver> (the raster's name in
 * messages and info->path, its driver in info->driver, for a band of a
 * view over a file, such as an in-memory VRT, which has neither).
 * The caller owns *out_grid and frees it with tt_grid_destroy(); the caller
 * owns *out_info (may be NULL) and frees it with tt_raster_info_destroy(). */
tt_status tt_gdal_read_grid(tt_context *ctx, GDALRasterBandH band,
                            char **options, tt_progress_fn progress,
                            void *progress_arg, tt_grid **out_grid,
                            tt_raster_info **out_info);

/* One column of the run_parameters table. */
typedef enum tt_field_type {
  TT_FIELD_STRING = 0, TT_FIELD_INTEGER, TT_FIELD_REAL
} tt_field_type;

typedef struct tt_run_field {
  const char *name;       /* <= 10 characters when Shapefile may be used */
  tt_field_type type;
  const char *s;
  int64_t i;
  double r;
} tt_run_field;

/* Writes the TIN into an open vector dataset: layers <prefix>triangles
 * (POLYGON Z; fields v0 v1 v2 max_err rmse n_samples area_2d area_3d slope
 * aspect min_angle max_angle; ring v0 v1 v2 v0, counter-clockwise in map
 * space) and <prefix>vertices (POINT Z; fields vertex_id col row ins_err
 * ins_rank star_max star_rmse star_n; a decimated TIN adds importance and
 * leaves ins_err and ins_rank NULL), and a one-row table
 * <prefix>run_parameters from fields (names of at most 10 characters for a
 * shapefile). NaN reals are written as NULL. The rows go in one transaction
 * when the driver has them; on any failure or interruption nothing is
 * committed and the layers made are deleted again. srs (the CRS of the
 * TIN's map coordinates, the input raster's) may be NULL. The layers get
 * srs, or T_SRS: then every vertex is transformed to it with OGR/PROJ
 * (traditional GIS axis order), triangles unchanged. When the layers' CRS
 * is geographic, area_2d is the geodesic area on its ellipsoid
 * (GeographicLib's geod_polygonarea) and area_3d = area_2d / cos(slope);
 * otherwise both are ground-frame areas (see ogr_write.c).
 * Options: NLN_PREFIX=<p>, LCO=<NAME=VALUE> (repeat for each layer creation
 * option), RTREE=NOW|DEFERRED, T_SRS=<CRS> (any OSRSetFromUserInput form). GPKG gets its R-trees built once after the
 * inserts (LCO=SPATIAL_INDEX=NO: none): with RTREE=NOW (the default) by
 * GDAL before the commit; with RTREE=DEFERRED not at all, and the caller
 * builds them with tt_gpkg_build_rtree() on the closed file (layers
 * <prefix>triangles and <prefix>vertices, geometry column "geom" unless
 * LCO=GEOMETRY_NAME says otherwise); shapefiles default to LCO
 * ENCODING=UTF-8 and SPATIAL_INDEX=YES (.qix). LAYERS=<list>: the layers
 * to write, a comma-separated subset of triangles,vertices,run_parameters
 * (default all). A driver without transactions gets each layer complete
 * before the next is made (KML); a database (a driver with transactions
 * other than GPKG and SQLite: PostgreSQL) gets its tables made inside the
 * transaction, so that a rollback or a lost connection leaves none;
 * OVERWRITE=YES drops the dataset's layers of those names first (inside
 * that transaction; LCO=SCHEMA=<s> looks for s.<name>). STYLE=YES:
 * QGIS's default graduated style for each geometry layer, as rows of the
 * layer_styles table (GPKG; PostgreSQL, the table made when missing) or a
 * .qml file beside each layer's file (Shapefile, FlatGeobuf, GeoJSON: the
 * caller's tt_output registers a single file's OUTPUT.qml as a sidecar).
 * A GPKG gets every field's title and description in gpkg_data_columns
 * (the schema extension), the errors' unit Z_UNIT=<unit> ("z units" when
 * absent). Integer64 fields become Integer for drivers without them
 * (MapInfo); a layer that cannot create fields (DXF) is written without
 * attributes, with one warning. */
tt_status tt_ogr_write_tin(tt_context *ctx, GDALDatasetH dst,
                           const tt_tin *tin, OGRSpatialReferenceH srs,
                           const tt_run_field *fields, size_t nfields,
                           char **options, tt_progress_fn progress,
                           void *progress_arg);

/* Writes the rows of the <prefix>triangles and <prefix>vertices layers of
 * tin straight into the closed GeoPackage gpkg_path, whose two layers
 * tt_ogr_write_tin() made with ROWS=DEFERRED (empty, with their fields),
 * in one SQLite transaction: the same features, values and geometry blobs
 * as tt_ogr_write_tin() without ROWS=DEFERRED writes through OGR, and the
 * layers' extents and feature counts. srs and the options NLN_PREFIX and
 * T_SRS must be those given to tt_ogr_write_tin() (LCO, ROWS and RTREE are
 * accepted and ignored, so the same list can be passed). THREADS=1 makes
 * the rows on the calling thread only; otherwise a second thread makes
 * them while SQLite inserts (tt_ogr_write_tin() accepts and ignores
 * THREADS too). JOURNAL=MEMORY keeps SQLite's rollback journal in memory
 * (for a file that is deleted unless the write completes). PAGES=YES
 * writes the two tables and their R-trees as SQLite database pages with
 * SQLite closed, several times faster; it is for a file nothing else has
 * open and that is deleted unless the write completes (a crash in the
 * middle can leave it unsound; the command's temporary output); when the
 * file does not allow it (WAL mode, auto-vacuum, an index on a table) the
 * rows go through SQLite. Any failure or an interruption (progress returns
 * 0: TT_ERR_INTERRUPTED) leaves the layers empty, without an index (with
 * PAGES=YES too, but for an I/O error in its last few writes). */
tt_status tt_gpkg_write_rows(tt_context *ctx, const char *gpkg_path,
                             const tt_tin *tin, OGRSpatialReferenceH srs,
                             char **options, tt_progress_fn progress,
                             void *progress_arg);

/* Builds the GeoPackage R-tree spatial index (extension gpkg_rtree_index)
 * of geom_column in table, on a closed GeoPackage file whose table has no
 * index yet, in one SQLite transaction: the boxes are read from the
 * geometry blobs (NULL and empty geometries are not indexed), packed into a
 * full tree and written into the shadow tables of
 * rtree_<table>_<geom_column>; the triggers of the standard (the seven of
 * GeoPackage 1.4 when the file declares 1.4, else the six of 1.2.1-1.3 that
 * GDAL before 3.7 knows) and the gpkg_extensions row are added, and
 * SQLite's rtreecheck() must find the tree consistent before the commit. Several times faster than GDAL 3.6's
 * CreateSpatialIndex(), with the same index rows. Any failure or an
 * interruption (progress returns 0: TT_ERR_INTERRUPTED) leaves the file
 * unchanged; TT_ERR_EXISTS when the table is already indexed. */
tt_status tt_gpkg_build_rtree(tt_context *ctx, const char *gpkg_path,
                              const char *table, const char *geom_column,
                              tt_progress_fn progress, void *progress_arg);

/* Reads the triangles of a POLYGON Z (or TRIANGLE Z, MULTIPOLYGON Z, TIN Z,
 * POLYHEDRALSURFACE Z, GEOMETRYCOLLECTION Z) layer into pixel-centre
 * (col,row,z) triples for tt_eval_triangles(): 9 doubles per triangle, map
 * x,y put through the inverse of gt and shifted by -0.5 (sample (c,r) at
 * (c,r)), z from the geometry. Counted in *out_rejected (may be NULL), one
 * per polygon or per feature: polygons that are not triangles (a closed
 * ring of 4 points, no holes), polygons without Z, other geometry types and
 * features without geometry. The layer's filters apply. *out_xyz is NULL
 * when no triangle was found. The caller owns *out_xyz and frees it with
 * free(). */
tt_status tt_ogr_read_triangles(tt_context *ctx, OGRLayerH layer,
                                const double gt[6], double **out_xyz,
                                size_t *out_ntriangles, size_t *out_rejected);

/* The triangles of an OGR layer in the layer's own coordinates (x, y, z
 * of each corner, 9 doubles per triangle), every geometry flattened to
 * the triangles it holds: what tt_ogr_read_triangles accepts, from a
 * layer of any declared type ("Unknown" included: CSV WKT, DXF 3DFACE,
 * MULTIPATCH); a ring of more than 4 points counts once its consecutive
 * repeats are dropped (a 3DFACE's fourth corner repeating its third).
 * Rejected geometries are counted as there. The caller owns *out_xyz and
 * frees it with free(). */
tt_status tt_ogr_read_triangles_map(tt_context *ctx, OGRLayerH layer,
                                    double **out_xyz,
                                    size_t *out_ntriangles,
                                    size_t *out_rejected);

/* The frame of a TIN file's coordinates (tt_tin_to_pixels). */
typedef enum tt_tin_frame {
  TT_TIN_FRAME_MAP = 0, /* map coordinates, in the TIN's CRS */
  TT_TIN_FRAME_PIXEL    /* the DEM's samples: x the column, y the row
                           counted up from the last row (hmm's STL) */
} tt_tin_frame;

/* Puts ntriangles triangles (9 doubles each, as read) on a DEM's
 * pixel-centre grid, in place, for tt_eval_triangles(): each corner's
 * x, y, z first becomes transform[a] * v + transform[3 + a] (transform:
 * sx sy sz ox oy oz; NULL: none); then in TT_TIN_FRAME_PIXEL the row is
 * dem_height - 1 - y; in TT_TIN_FRAME_MAP x, y are reprojected from
 * tin_crs to dem_crs (WKT or anything OSRSetFromUserInput takes, e.g.
 * "EPSG:32610"; NULL or "" for either: none) when the two differ, in
 * the traditional GIS axis order, heights untouched, and then put through
 * the inverse of gt, less 0.5 (sample (c, r) at (c, r)).
 * *out_reprojected (may be NULL) says whether they were reprojected. */
tt_status tt_tin_to_pixels(tt_context *ctx, double *xyz, size_t ntriangles,
                           tt_tin_frame frame, const double transform[6],
                           size_t dem_height, const char *tin_crs,
                           const char *dem_crs, const double gt[6],
                           int *out_reprojected);

/* Writes a grid as a single-band Float32 GeoTIFF (Float64 for a grid of
 * doubles; TILED=YES, COMPRESS=DEFLATE; nodata NaN only when the grid has
 * NaN), with the grid's geotransform and srs_wkt ("" or NULL for none).
 * Written to a temporary name beside path and renamed on success (see
 * tt_output); an existing path is refused with TT_ERR_EXISTS unless
 * overwrite. Needs the GTiff driver registered. */
tt_status tt_gdal_write_grid(tt_context *ctx, const tt_grid *grid,
                             const char *path, const char *srs_wkt,
                             int overwrite);

/* Writes nx x ny doubles (row by row, NaN: nodata, declared as the band's
 * nodata value) as one band of type GDT_Float32 or GDT_Float64 to path
 * with the raster driver drv (Create, or CreateCopy of an in-memory copy
 * for drivers that only copy), the geotransform gt, srs_wkt ("" or NULL:
 * none) and the creation options. path is created as given: pass the
 * temporary name of a tt_output and commit it on success. name names the
 * file in messages (NULL: path). progress may stop the write
 * (TT_ERR_INTERRUPTED); on failure the caller's tt_output removes what
 * was made. */
tt_status tt_gdal_write_raster(tt_context *ctx, GDALDriverH drv,
                               const char *path, const char *name,
                               size_t nx, size_t ny, const double *values,
                               GDALDataType type, const double gt[6],
                               const char *srs_wkt,
                               CSLConstList create_options,
                               tt_progress_fn progress, void *progress_arg);

/* ---------------------------------------------------------------------------
 * Mesh and survey files (not OGR drivers): SMS 2DM, binary little-endian
 * PLY, Wavefront OBJ, a LandXML 1.2 TIN surface and UGRID netCDF.
 * ------------------------------------------------------------------------- */
typedef enum tt_mesh_format {
  TT_MESH_NONE = 0,
  TT_MESH_2DM,     /* MESH2D, ND id x y z, E3T id n1 n2 n3 1 (1-based) */
  TT_MESH_PLY,     /* vertex x y z ins_err star_max star_rmse (double);
                      face vertex_indices (uchar, int) max_err rmse
                      (double) n_samples (int); NaN kept */
  TT_MESH_OBJ,     /* v x y z, f a b c (1-based) */
  TT_MESH_LANDXML, /* Surface/Definition surfType="TIN": Pnts P id=
                      "northing easting elevation", Faces F "a b c" */
  TT_MESH_UGRID,   /* netCDF (CDF-2), UGRID 1.0: mesh_node_x/y/z, mesh_face_nodes
                      (start_index 0), node and face data variables */
  TT_MESH_DXF      /* AutoCAD DXF R12: one 3DFACE per triangle (its corners'
                      x y z, the fourth = the first) on layer "triangles" */
} tt_mesh_format;

/* The format of an -of name ("2DM", "PLY", "OBJ", "LandXML", "UGRID",
 * "DXF", any case), or of a path's extension (.2dm, .ply, .obj, .xml,
 * .dxf, any case; .nc is left to OGR's netCDF driver);
 * TT_MESH_NONE for anything else. */
tt_mesh_format tt_mesh_format_from_name(const char *name);
tt_mesh_format tt_mesh_format_from_path(const char *path);
/* "2DM", "PLY", "OBJ", "LandXML", "UGRID", "DXF"; NULL for TT_MESH_NONE. */
const char *tt_mesh_format_name(tt_mesh_format fmt);
/* The files a format writes beside OUTPUT, as suffixes that replace its
 * extension (2DM: "_ins_err.dat", ..., "_n_samples_els.dat", its datasets,
 * and ".prj", its CRS when it has one; the others: none),
 * NULL-terminated; static storage. */
const char *const *tt_mesh_format_sidecars(tt_mesh_format fmt);

/* Writes tin to the file path (create or truncate: give it the temporary
 * name of a tt_output and commit that) in fmt. Every vertex is written, in
 * TIN order; triangles are counter-clockwise in the output coordinates,
 * which are those of srs, or t_srs (as tt_ogr_write_tin's T_SRS; NULL or
 * "": none) with every vertex transformed. Doubles are written exactly
 * (%.17g, or binary in PLY). name labels the mesh (2DM MESHNAME, LandXML
 * Surface name, OBJ object; NULL: "TIN"). local (OBJ only): vertices
 * relative to the centre of the extent rounded to whole units, which a
 * comment line `# origin X Y` gives. 2DM's datasets are written beside
 * path under the names tt_mesh_format_sidecars() gives, and its CRS (when
 * there is one) as PATH's stem + ".prj" in ESRI's WKT1; PLY's header names
 * the CRS ("comment crs:WKT"). progress may stop the write
 * (TT_ERR_INTERRUPTED). On any failure the files written are removed. */
tt_status tt_mesh_write(tt_context *ctx, const char *path,
                        tt_mesh_format fmt, const char *name,
                        const tt_tin *tin, OGRSpatialReferenceH srs,
                        const char *t_srs, int local,
                        tt_progress_fn progress, void *progress_arg);

/* The format of a TIN file that eval reads without OGR, from its first
 * bytes (and the extension .stl or .obj, whose content says little):
 * "STL" (binary or ASCII), "PLY" (ascii or binary), "OBJ", "2DM",
 * "LandXML" or "UGRID" (a netCDF file with a 2-D mesh_topology); NULL for
 * anything else (an OGR dataset, or no file). Static storage. */
const char *tt_mesh_read_format(const char *path);

/* Reads the TIN file path (a format tt_mesh_read_format names) as
 * *out_ntriangles triangles of 9 doubles (x, y, z of each corner) in the
 * file's coordinates: OBJ's "# origin X Y" added back, LandXML's
 * northing, easting swapped to x, y. Faces of other than 3 corners (and
 * LandXML's invisible ones) are counted in *out_rejected (may be NULL).
 * *out_crs_wkt (may be NULL) is the CRS the file declares (PLY's "comment
 * crs:", LandXML's CoordinateSystem, UGRID's crs_wkt), or NULL. TT_ERR_IO
 * when the file cannot be read, TT_ERR_FORMAT with the line or face when
 * it is damaged. The caller owns *out_xyz and *out_crs_wkt and frees them
 * with free(). */
tt_status tt_mesh_read(tt_context *ctx, const char *path,
                       double **out_xyz, size_t *out_ntriangles,
                       size_t *out_rejected, char **out_crs_wkt);

/* ---------------------------------------------------------------------------
 * Safe output: never overwrite without permission, never leave a half-written
 * file. A tt_output names the final files and the temporary ones beside them.
 * ------------------------------------------------------------------------- */
typedef struct tt_output tt_output;

/* Plans output to `path` in `format` ("GPKG", "ESRI Shapefile", ...).
 * Refuses (TT_ERR_EXISTS) when a final file exists and overwrite is 0, or
 * when it is anything overwrite never replaces: a FIFO, device, socket or
 * symbolic link, a folder other than an earlier output of a driver that
 * writes folders (only regular `*triangles.*`, `*vertices.*`,
 * `*run_parameters.*` files in it); (TT_ERR_IO) when the folder is not
 * writable. GPKG and SQLite: the sidecars PATH-journal, PATH-wal, PATH-shm
 * count as final files, and TT_ERR_IO refuses an old file that another
 * process holds open (SQLite's POSIX locks); stale sidecars are removed at
 * commit, before the new file takes the name. Temporary names are
 * `.ttXXXXXXXX` (+ the extension) in path's folder, owned by the lock file
 * `.ttXXXXXXXX.lock` that the output holds with flock() while it lives;
 * the temporaries of killed runs there (their lock no longer held) are
 * removed first, each said as a warning (tt_output_remove_stale). The
 * caller owns
 * *out_output and frees it with tt_output_destroy(), which removes the
 * temporary files (folders included) unless tt_output_commit() succeeded. */
tt_status tt_output_begin(tt_context *ctx, const char *path,
                          const char *format, int overwrite,
                          tt_output **out_output);
/* Removes, in the folder of path (an output path), the temporaries of
 * runs that were killed (SIGKILL, a crash): those whose `.ttXXXXXXXX.lock`
 * no process holds. A run in progress (its lock held, in any process) and
 * temporaries without a lock file are never touched, nor what a killed
 * commit had moved aside (the user's old files). note (may be NULL) gets
 * "removed stale temporary PATH (left by a killed run)" for each. Returns
 * how many were removed. Thread-safe. */
size_t tt_output_remove_stale(const char *path, tt_log_fn note, void *user);
/* The name to create the dataset under (temporary). */
const char *tt_output_temp_path(const tt_output *out);
/* A file written beside a single-file output: the final stem (path without
 * its extension) + suffix, written as the temporary stem + suffix, checked
 * now and at commit as the output is (an existing one only replaced with
 * overwrite), renamed into place with it at commit and removed with it on
 * failure. */
tt_status tt_output_add_sidecar(tt_context *ctx, tt_output *out,
                                const char *suffix);
/* The path as given to tt_output_begin(), for messages. */
const char *tt_output_final_path(const tt_output *out);
/* The layer-name prefix to give tt_ogr_write_tin() as NLN_PREFIX: "<name>_"
 * for a shapefile output (OUTPUT `name` or `name.shp` makes the files
 * `name_triangles.shp`, `name_vertices.shp`, `name_run_parameters.dbf`),
 * "" for any other format. */
const char *tt_output_layer_prefix(const tt_output *out);
/* Registers a file the output must never replace or remove (a file the
 * input is read from), compared by device and inode, and by resolved path
 * (for names that do not exist, and for files inside a folder output).
 * Refuses at once (TT_ERR_ARG, naming both) when a planned final name is
 * that file; commit checks every name it writes again. */
tt_status tt_output_protect(tt_context *ctx, tt_output *out,
                            const char *path);
/* Registers with tt_output_protect() every local file GDAL reads for the
 * open dataset src opened as `name`: GDALGetFileList() (sidecars, VRT
 * sources, recursively through nested VRTs), and the containers named in
 * those paths and in `name` (the archive of /vsizip/, /vsitar/, /vsigzip/
 * paths, the file of a `GPKG:file:table`-style name). */
tt_status tt_output_protect_dataset(tt_context *ctx, tt_output *out,
                                    GDALDatasetH src, const char *name);
/* Renames the temporary files to their final names (for a shapefile, moves
 * each file of the temporary folder into place; the old files of those
 * names are put back if a move fails). TT_ERR_INTERRUPTED after
 * tt_output_abandon_all(). */
tt_status tt_output_commit(tt_context *ctx, tt_output *out);
/* Removes the temporary files written so far (the dataset and its
 * sidecars), so that the dataset can be created again under the same
 * temporary name: for a writer that drops what it wrote and starts over
 * (a tiled run's budget pass that is not kept). Nothing after commit or
 * tt_output_abandon_all(). Thread-safe. */
void tt_output_clear(tt_output *out);
void tt_output_destroy(tt_output *out);
/* Removes the temporary files of every live tt_output of the process that
 * is not committed, and makes their commit fail: for a watchdog thread
 * ending a process whose main thread is stuck in a driver. Returns 1 when
 * no live output was committed, 0 when one was (its run is finishing and
 * should be let finish). Thread-safe; not async-signal-safe. */
int tt_output_abandon_all(void);
/* Copies text (a driver's message) into buf (size bytes, truncated) with
 * the temporary names of every live tt_output replaced by their final
 * names, so that messages name the user's output: the temporary path (or
 * its bare file name) reads as the final path, a file inside a temporary
 * folder as that file in the final folder. Returns 1 when a name was
 * replaced. Thread-safe. */
int tt_output_rename_in_text(const char *text, char *buf, size_t size);

#ifdef __cplusplus
}
#endif
#endif /* TERRATIN_GDAL_H */
