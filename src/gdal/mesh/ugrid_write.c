/*
 * src/gdal/mesh/ -- the mesh formats: a TIN as SMS 2DM, PLY, OBJ, LandXML
 * or UGRID netCDF, without OGR.
 *
 * ugrid_write.c -- a TIN as a UGRID 1.0 mesh in a netCDF file (-of
 * UGRID), through libnetcdf, laid out as QGIS's MDAL reads it. The file is
 * netCDF classic with 64-bit offsets (CDF-2), which every netCDF reader
 * takes (faster to write than netCDF-4, see docs/cli.md); each variable
 * but the last may hold 4 GiB (about 358 million triangles), more fails
 * cleanly (NC_EVARSIZE).
 *
 *   int mesh            cf_role = "mesh_topology", topology_dimension = 2,
 *                       node_coordinates = "mesh_node_x mesh_node_y",
 *                       face_node_connectivity = "mesh_face_nodes",
 *                       face_dimension = "nmesh_face"
 *   double mesh_node_x(nmesh_node), mesh_node_y(nmesh_node)
 *   double mesh_node_z(nmesh_node)   standard_name = "altitude" (MDAL's
 *                       "Bed Elevation" dataset)
 *   int mesh_face_nodes(nmesh_face, max_nmesh_face_nodes)  start_index = 0,
 *                       each triangle counter-clockwise
 *   double ins_err, star_max, star_rmse (nmesh_node)  location = "node"
 *   double max_err, rmse (nmesh_face), int n_samples (nmesh_face)
 *                       location = "face"
 *   int crs             crs_wkt and spatial_ref (CF, GDAL), wkt (MDAL),
 *                       epsg and EPSG_code when the CRS has an EPSG code,
 *                       grid_mapping_name for a geographic CRS
 *
 * Node i is the TIN's vertex i, face i its triangle i (the OGR layers'
 * vertex_id and fid - 1). The data variables have no time dimension
 * (MDAL reads them as one static dataset each) and their long_name is the
 * OGR field name, which MDAL shows as the dataset's name. NaN is written
 * as is. Values go out in blocks of 64 Ki entries, so memory stays small
 * and progress can stop the write between blocks.
 */
#include "gdal/mesh/mesh_ugrid.h"

#include <cpl_conv.h>
#include <ogr_srs_api.h>

#include <netcdf.h>

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

enum { BLOCK = 65536 };

/* The node and face data variables, in the order written. */
enum { NV_X, NV_Y, NV_Z, NV_INS_ERR, NV_STAR_MAX, NV_STAR_RMSE, N_NODE_VARS };
enum { FV_MAX_ERR, FV_RMSE, N_FACE_DOUBLES };

static const char *const node_attr_names[N_NODE_VARS] = {
    NULL, NULL, NULL, "ins_err", "star_max", "star_rmse"};
static const char *const node_attr_desc[N_NODE_VARS] = {
    NULL, NULL, NULL,
    "|H - H'| at the vertex's sample just before it was inserted (NaN: "
    "a starting vertex, or a decimated TIN)",
    "max |H - H'| over the samples of the triangles around the vertex",
    "RMS of |H - H'| over the same samples"};
static const char *const face_names[N_FACE_DOUBLES + 1] = {
    "max_err", "rmse", "n_samples"};
static const char *const face_desc[N_FACE_DOUBLES + 1] = {
    "max |H - H'| over the samples the triangle owns",
    "RMS of |H - H'| over the samples the triangle owns",
    "the samples the triangle owns"};

typedef struct ugrid {
  tt_context *ctx;
  const char *path;
  int nc;
  int st;          /* the first netCDF error */
  /* the file's dimensions and variables */
  int d_node, d_face, d_three;
  int v_mesh, v_crs, v_node[N_NODE_VARS], v_fn, v_face[N_FACE_DOUBLES + 1];
} ugrid;

/* Records the first netCDF failure; 1 while there is none. */
static int ok(ugrid *u, int e)
{
  if (e != NC_NOERR && u->st == NC_NOERR)
    u->st = e;
  return u->st == NC_NOERR;
}

static void put_text(ugrid *u, int var, const char *att, const char *text)
{
  if (text)
    ok(u, nc_put_att_text(u->nc, var, att, strlen(text), text));
}

static void put_int(ugrid *u, int var, const char *att, int value)
{
  ok(u, nc_put_att_int(u->nc, var, att, NC_INT, 1, &value));
}

/* The crs variable's attributes from the output CRS. */
static void put_crs(ugrid *u, int var, OGRSpatialReferenceH srs)
{
  char *wkt = NULL;
  if (OSRExportToWkt(srs, &wkt) == OGRERR_NONE && wkt) {
    put_text(u, var, "crs_wkt", wkt);
    put_text(u, var, "spatial_ref", wkt);
    put_text(u, var, "wkt", wkt);
  }
  CPLFree(wkt);
  const char *auth = OSRGetAuthorityName(srs, NULL);
  const char *code = OSRGetAuthorityCode(srs, NULL);
  if (auth && code && strcasecmp(auth, "EPSG") == 0) {
    char *end = NULL;
    long n = strtol(code, &end, 10);
    if (end && *end == '\0' && n > 0 && n < INT32_MAX)
      put_int(u, var, "epsg", (int)n);
    char buf[64];
    snprintf(buf, sizeof buf, "EPSG:%s", code);
    put_text(u, var, "EPSG_code", buf);
  }
  /* CF names every projection by its own grid_mapping_name; only the
   * geographic one is certain here (the WKT says the rest). */
  if (OSRIsGeographic(srs))
    put_text(u, var, "grid_mapping_name", "latitude_longitude");
}

/* Calls progress: 0 when it asks to stop. */
static int keep_going(tt_progress_fn progress, void *arg, size_t done,
                      size_t total)
{
  return !progress ||
         progress(total ? (double)done / (double)total : 1.0, NULL, arg);
}


/* The dimensions: nv nodes, nt faces, 3 nodes a face. */
static void define_dims(ugrid *u, size_t nv, size_t nt)
{
  ok(u, nc_def_dim(u->nc, "nmesh_node", nv, &u->d_node));
  ok(u, nc_def_dim(u->nc, "nmesh_face", nt, &u->d_face));
  ok(u, nc_def_dim(u->nc, "max_nmesh_face_nodes", 3, &u->d_three));
}

/* The global attributes and the mesh topology variable (and the crs
 * variable when there is a CRS). */
static void define_mesh(ugrid *u, const char *name, OGRSpatialReferenceH srs)
{
  put_text(u, NC_GLOBAL, "Conventions", "CF-1.8 UGRID-1.0");
  put_text(u, NC_GLOBAL, "title", name);
  char source[96];
  snprintf(source, sizeof source, "terratin %s", tt_version());
  put_text(u, NC_GLOBAL, "source", source);

  ok(u, nc_def_var(u->nc, "mesh", NC_INT, 0, NULL, &u->v_mesh));
  put_text(u, u->v_mesh, "cf_role", "mesh_topology");
  put_text(u, u->v_mesh, "long_name", name);
  put_int(u, u->v_mesh, "topology_dimension", 2);
  put_text(u, u->v_mesh, "node_coordinates", "mesh_node_x mesh_node_y");
  put_text(u, u->v_mesh, "face_node_connectivity", "mesh_face_nodes");
  put_text(u, u->v_mesh, "face_dimension", "nmesh_face");
  if (srs) {
    ok(u, nc_def_var(u->nc, "crs", NC_INT, 0, NULL, &u->v_crs));
    put_crs(u, u->v_crs, srs);
  }
}

/* The node variables: coordinates (named for the CRS), height and the
 * vertices' attributes. */
static void define_node_vars(ugrid *u, OGRSpatialReferenceH srs)
{
  static const char *const node_var_names[N_NODE_VARS] = {
      "mesh_node_x", "mesh_node_y", "mesh_node_z",
      "ins_err",     "star_max",    "star_rmse"};
  const int geographic = srs && OSRIsGeographic(srs);
  for (int k = 0; k < N_NODE_VARS; k++) {
    int v;
    ok(u, nc_def_var(u->nc, node_var_names[k], NC_DOUBLE, 1, &u->d_node, &v));
    u->v_node[k] = v;
    if (k != NV_X && k != NV_Y) {
      put_text(u, v, "mesh", "mesh");
      put_text(u, v, "location", "node");
    }
    if (k == NV_X || k == NV_Y) {
      put_text(u, v, "standard_name",
               geographic ? (k == NV_X ? "longitude" : "latitude")
                          : (k == NV_X ? "projection_x_coordinate"
                                       : "projection_y_coordinate"));
      put_text(u, v, "long_name", k == NV_X ? "x of the mesh nodes"
                                            : "y of the mesh nodes");
      if (geographic)
        put_text(u, v, "units", k == NV_X ? "degrees_east"
                                          : "degrees_north");
      else if (srs) {
        /* UDUNITS names of the common linear units; none for others */
        double m = OSRGetLinearUnits(srs, NULL);
        put_text(u, v, "units", m == 1.0            ? "m"
                                : m == 0.3048        ? "ft"
                                : fabs(m - 1200.0 / 3937.0) < 1e-12
                                    ? "US_survey_foot"
                                    : NULL);
      }
    } else {
      put_text(u, v, "coordinates", "mesh_node_x mesh_node_y");
      if (k == NV_Z) {
        put_text(u, v, "standard_name", "altitude");
        put_text(u, v, "long_name", "height of the mesh nodes (the DEM's "
                                    "samples)");
      } else {
        put_text(u, v, "long_name", node_attr_names[k]);
        put_text(u, v, "comment", node_attr_desc[k]);
      }
    }
    if (srs)
      put_text(u, v, "grid_mapping", "crs");
  }
}

/* The face variables: the connectivity and the triangles' attributes. */
static void define_face_vars(ugrid *u, OGRSpatialReferenceH srs)
{
  int fdims[2] = {u->d_face, u->d_three};
  ok(u, nc_def_var(u->nc, "mesh_face_nodes", NC_INT, 2, fdims, &u->v_fn));
  put_text(u, u->v_fn, "cf_role", "face_node_connectivity");
  put_text(u, u->v_fn, "long_name", "the vertices of each triangle, "
                                    "counter-clockwise");
  put_int(u, u->v_fn, "start_index", 0);
  for (int k = 0; k <= N_FACE_DOUBLES; k++) {
    int v;
    ok(u, nc_def_var(u->nc, face_names[k],
                     k < N_FACE_DOUBLES ? NC_DOUBLE : NC_INT, 1, &u->d_face,
                     &v));
    u->v_face[k] = v;
    put_text(u, v, "mesh", "mesh");
    put_text(u, v, "location", "face");
    put_text(u, v, "long_name", face_names[k]);
    put_text(u, v, "comment", face_desc[k]);
    if (srs)
      put_text(u, v, "grid_mapping", "crs");
  }
}

/* The nodes' values, a block at a time: column k of the block at
 * dbuf + k * BLOCK (BLOCK x N_NODE_VARS doubles). Stops at the first
 * netCDF failure (in u->st) or interruption. */
static tt_status write_nodes(ugrid *u, const tt__records *rec, double *dbuf,
                             tt_progress_fn progress, void *progress_arg,
                             size_t total)
{
  const size_t nv = tt_tin_vertex_count(rec->tin);
  for (size_t i0 = 0; i0 < nv; i0 += BLOCK) {
    size_t n = nv - i0 < BLOCK ? nv - i0 : BLOCK;
    for (size_t j = 0; j < n; j++) {
      tt_vertex_info v;
      double x, y;
      tt_status st = tt__records_vertex(rec, u->ctx, i0 + j, &v, &x, &y);
      if (st != TT_OK)
        return st;
      const double d[N_NODE_VARS] = {x,
                                     y,
                                     v.z,
                                     v.insert_error,
                                     v.star_max_error,
                                     v.star_rmse};
      for (int k = 0; k < N_NODE_VARS; k++)
        dbuf[(size_t)k * BLOCK + j] = d[k];
    }
    for (int k = 0; k < N_NODE_VARS; k++)
      ok(u, nc_put_vara_double(u->nc, u->v_node[k], &i0, &n,
                               dbuf + (size_t)k * BLOCK));
    if (!ok(u, NC_NOERR))
      return TT_OK;
    if (!keep_going(progress, progress_arg, i0 + n, total))
      return tt__error(u->ctx, TT_ERR_INTERRUPTED, "interrupted");
  }
  return TT_OK;
}

/* The faces' values, a block at a time: connectivity (3 ints), the
 * doubles, the sample counts (ibuf: BLOCK x 4 ints, dbuf: BLOCK x 2
 * doubles). Stops as write_nodes does; progress goes on from nv. */
static tt_status write_faces(ugrid *u, const tt__records *rec, double *dbuf,
                             int *ibuf, tt_progress_fn progress,
                             void *progress_arg, size_t total)
{
  const size_t nv = tt_tin_vertex_count(rec->tin);
  const size_t nt = tt_tin_triangle_count(rec->tin);
  for (size_t i0 = 0; i0 < nt; i0 += BLOCK) {
    size_t n = nt - i0 < BLOCK ? nt - i0 : BLOCK;
    int *conn = ibuf, *count = ibuf + 3 * (size_t)BLOCK;
    for (size_t j = 0; j < n; j++) {
      tt_triangle_info t;
      tt_status st = tt__records_face(rec, u->ctx, i0 + j, &t);
      if (st != TT_OK)
        return st;
      for (int k = 0; k < 3; k++)
        conn[3 * j + (size_t)k] = t.v[k];
      dbuf[j] = t.max_error;
      dbuf[(size_t)BLOCK + j] = t.rmse;
      count[j] = t.samples > INT32_MAX ? INT32_MAX : (int)t.samples;
    }
    const size_t start[2] = {i0, 0}, cnt[2] = {n, 3};
    ok(u, nc_put_vara_int(u->nc, u->v_fn, start, cnt, conn));
    ok(u, nc_put_vara_double(u->nc, u->v_face[FV_MAX_ERR], &i0, &n, dbuf));
    ok(u, nc_put_vara_double(u->nc, u->v_face[FV_RMSE], &i0, &n,
                             dbuf + BLOCK));
    ok(u, nc_put_vara_int(u->nc, u->v_face[N_FACE_DOUBLES], &i0, &n, count));
    if (!ok(u, NC_NOERR))
      return TT_OK;
    if (!keep_going(progress, progress_arg, nv + i0 + n, total))
      return tt__error(u->ctx, TT_ERR_INTERRUPTED, "interrupted");
  }
  return TT_OK;
}

tt_status tt__ugrid_write(tt_context *ctx, const char *path,
                          const char *name, const tt__records *rec,
                          tt_progress_fn progress, void *progress_arg)
{
  ugrid u;
  memset(&u, 0, sizeof u);
  u.ctx = ctx;
  u.path = path;
  u.nc = -1;
  u.st = NC_NOERR;
  u.v_crs = -1;
  tt_status st = TT_OK;
  double *dbuf = NULL;
  int *ibuf = NULL;
  const tt_tin *tin = rec->tin;
  const size_t nv = tt_tin_vertex_count(tin), nt = tt_tin_triangle_count(tin);
  const size_t total = nv + nt;
  const OGRSpatialReferenceH srs = rec->out_srs;

  /* netCDF dimensions may not be 0: an empty TIN has nothing to map. */
  if (nv == 0 || nt == 0)
    return tt__error(ctx, TT_ERR_DATA, "%s: UGRID: the TIN has no "
                     "triangles", path);
  if (!ok(&u, nc_create(path, NC_CLOBBER | NC_64BIT_OFFSET, &u.nc)))
    goto done;
  define_dims(&u, nv, nt);
  if (!ok(&u, NC_NOERR))
    goto done;
  define_mesh(&u, name, srs);
  define_node_vars(&u, srs);
  define_face_vars(&u, srs);
  if (!ok(&u, nc_enddef(u.nc)))
    goto done;

  dbuf = malloc((size_t)BLOCK * N_NODE_VARS * sizeof *dbuf);
  ibuf = malloc((size_t)BLOCK * 4 * sizeof *ibuf);
  if (!dbuf || !ibuf) {
    st = tt__error(ctx, TT_ERR_NOMEM, "out of memory");
    goto done;
  }
  st = write_nodes(&u, rec, dbuf, progress, progress_arg, total);
  if (st != TT_OK || !ok(&u, NC_NOERR))
    goto done;
  st = write_faces(&u, rec, dbuf, ibuf, progress, progress_arg, total);
  if (st != TT_OK || !ok(&u, NC_NOERR))
    goto done;
  int nc = u.nc;
  u.nc = -1;
  ok(&u, nc_close(nc));

done:
  if (u.nc >= 0)
    nc_close(u.nc);
  free(dbuf);
  free(ibuf);
  if (st == TT_OK && u.st != NC_NOERR)
    st = tt__error(ctx, TT_ERR_IO, "%s: netCDF: %s", path,
                   nc_strerror(u.st));
  return st;
}
