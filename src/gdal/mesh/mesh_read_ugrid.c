/*
 * src/gdal/mesh/ -- the mesh formats: a TIN as SMS 2DM, PLY, OBJ, LandXML
 * or UGRID netCDF, without OGR.
 *
 * mesh_read_ugrid.c -- a UGRID 1.0 mesh of a netCDF file, through
 * libnetcdf, as a triangle soup: the first variable with cf_role =
 * "mesh_topology" and topology_dimension = 2 names its node_coordinates
 * (x and y) and face_node_connectivity; the heights are the node variable
 * whose standard_name is "altitude" (terratin's and MDAL's
 * mesh_node_z), else a third node coordinate. Faces follow the
 * connectivity's start_index (0 if absent); entries equal to its
 * _FillValue end a face, so faces of other than 3 nodes (quads of mixed
 * meshes) are counted as rejected. The CRS is the crs_wkt (or
 * spatial_ref, or wkt) of the variable the mesh's grid_mapping names,
 * else of a variable named "crs".
 */
#include "gdal/mesh/mesh_read.h"

#include <netcdf.h>

#include <stdlib.h>
#include <string.h>

/* Text attribute att of variable var, malloc'd; NULL when absent. */
static char *text_att(int nc, int var, const char *att)
{
  size_t len = 0;
  nc_type t;
  if (nc_inq_att(nc, var, att, &t, &len) != NC_NOERR || t != NC_CHAR)
    return NULL;
  char *s = malloc(len + 1);
  if (!s)
    return NULL;
  if (nc_get_att_text(nc, var, att, s) != NC_NOERR) {
    free(s);
    return NULL;
  }
  s[len] = '\0';
  return s;
}

static int find_mesh(int nc)
{
  int nvars = 0;
  nc_inq_nvars(nc, &nvars);
  for (int v = 0; v < nvars; v++) {
    char *role = text_att(nc, v, "cf_role");
    int hit = role && strcmp(role, "mesh_topology") == 0;
    free(role);
    int dim = 0;
    if (hit && nc_get_att_int(nc, v, "topology_dimension", &dim) ==
                   NC_NOERR && dim == 2)
      return v;
  }
  return -1;
}

int tt__mesh_is_ugrid(const char *path)
{
  int nc;
  if (nc_open(path, NC_NOWRITE, &nc) != NC_NOERR)
    return 0;
  int mesh = find_mesh(nc);
  nc_close(nc);
  return mesh >= 0;
}

/* A node variable read whole as doubles (malloc'd), its length checked. */
static tt_status read_nodes(tt__soup *s, int nc, const char *name,
                            size_t *nn, double **out)
{
  int var, ndims, dim;
  size_t len;
  if (nc_inq_varid(nc, name, &var) != NC_NOERR ||
      nc_inq_varndims(nc, var, &ndims) != NC_NOERR || ndims != 1 ||
      nc_inq_vardimid(nc, var, &dim) != NC_NOERR ||
      nc_inq_dimlen(nc, dim, &len) != NC_NOERR)
    return tt__error(s->ctx, TT_ERR_FORMAT, "%s: no node variable '%s' of "
                     "one dimension", s->path, name);
  if (*nn && len != *nn)
    return tt__error(s->ctx, TT_ERR_FORMAT, "%s: '%s' holds %zu nodes, "
                     "not %zu", s->path, name, len, *nn);
  *nn = len;
  if (!(*out = malloc((len ? len : 1) * sizeof **out)))
    return tt__error(s->ctx, TT_ERR_NOMEM, "%s: out of memory for %zu "
                     "nodes", s->path, len);
  if (nc_get_var_double(nc, var, *out) != NC_NOERR)
    return tt__error(s->ctx, TT_ERR_IO, "%s: cannot read '%s'", s->path,
                     name);
  return TT_OK;
}

/* The heights: the altitude variable on the nodes, else the third
 * node coordinate. */
static int z_variable(int nc, const char *coord3, char *out, size_t n)
{
  int nvars = 0;
  nc_inq_nvars(nc, &nvars);
  for (int v = 0; v < nvars; v++) {
    char *sn = text_att(nc, v, "standard_name");
    char *loc = text_att(nc, v, "location");
    int hit = sn && strcmp(sn, "altitude") == 0 &&
              (!loc || strcmp(loc, "node") == 0);
    free(sn);
    free(loc);
    if (hit)
      return nc_inq_varname(nc, v, out) == NC_NOERR;
  }
  if (coord3) {
    snprintf(out, n, "%s", coord3);
    return 1;
  }
  return 0;
}

static void read_crs(tt__soup *s, int nc, int mesh)
{
  char *gm = text_att(nc, mesh, "grid_mapping");
  int var;
  if (nc_inq_varid(nc, gm ? gm : "crs", &var) == NC_NOERR) {
    static const char *const names[] = {"crs_wkt", "spatial_ref", "wkt"};
    for (int k = 0; k < 3 && !s->crs_wkt; k++) {
      char *w = text_att(nc, var, names[k]);
      if (w && *w)
        tt__soup_set_crs(s, w, strlen(w));
      free(w);
    }
  }
  free(gm);
}

static tt_status read_faces(tt__soup *s, int nc, const char *name)
{
  int var, ndims, dims[2], start = 0, fill = NC_FILL_INT;
  size_t nf, per;
  if (nc_inq_varid(nc, name, &var) != NC_NOERR ||
      nc_inq_varndims(nc, var, &ndims) != NC_NOERR || ndims != 2 ||
      nc_inq_vardimid(nc, var, dims) != NC_NOERR ||
      nc_inq_dimlen(nc, dims[0], &nf) != NC_NOERR ||
      nc_inq_dimlen(nc, dims[1], &per) != NC_NOERR || per > 64)
    return tt__error(s->ctx, TT_ERR_FORMAT, "%s: no face connectivity "
                     "'%s' of (faces, nodes per face)", s->path, name);
  nc_get_att_int(nc, var, "start_index", &start);
  nc_get_att_int(nc, var, "_FillValue", &fill);
  enum { BLOCK = 65536 };
  int *buf = malloc(BLOCK * per * sizeof *buf);
  if (!buf)
    return tt__error(s->ctx, TT_ERR_NOMEM, "%s: out of memory", s->path);
  tt_status st = TT_OK;
  for (size_t f0 = 0; st == TT_OK && f0 < nf; f0 += BLOCK) {
    size_t m = nf - f0 < BLOCK ? nf - f0 : BLOCK;
    size_t at[2] = {f0, 0}, cnt[2] = {m, per};
    if (nc_get_vara_int(nc, var, at, cnt, buf) != NC_NOERR) {
      st = tt__error(s->ctx, TT_ERR_IO, "%s: cannot read '%s'", s->path,
                     name);
      break;
    }
    for (size_t i = 0; st == TT_OK && i < m; i++) {
      long long idx[64];
      int n = 0;
      while ((size_t)n < per && buf[i * per + n] != fill && buf[i * per + n] >= start)
        idx[n] = (long long)buf[i * per + n] - start, n++;
      st = tt__soup_face(s, idx, n, f0 + i + 1);
    }
  }
  free(buf);
  return st;
}

tt_status tt__mesh_read_ugrid(tt__soup *s, const char *path)
{
  int nc;
  if (nc_open(path, NC_NOWRITE, &nc) != NC_NOERR)
    return tt__error(s->ctx, TT_ERR_IO, "%s: cannot open as netCDF", path);
  double *c[3] = {NULL, NULL, NULL};
  char *coords = NULL, *conn = NULL, zname[NC_MAX_NAME + 1];
  char *w[4];
  size_t nn = 0;
  tt_status st = TT_OK;
  int mesh = find_mesh(nc);
  coords = mesh >= 0 ? text_att(nc, mesh, "node_coordinates") : NULL;
  conn = mesh >= 0 ? text_att(nc, mesh, "face_node_connectivity") : NULL;
  int ncoord = coords ? tt__mesh_words(coords, w, 4) : 0;
  if (mesh < 0 || ncoord < 2 || !conn) {
    st = tt__error(s->ctx, TT_ERR_FORMAT, "%s: no 2-D UGRID mesh with "
                   "node_coordinates and face_node_connectivity", path);
    goto done;
  }
  if (!z_variable(nc, ncoord > 2 ? w[2] : NULL, zname, sizeof zname)) {
    st = tt__error(s->ctx, TT_ERR_FORMAT, "%s: the mesh's nodes have no "
                   "heights (no altitude variable)", path);
    goto done;
  }
  if ((st = read_nodes(s, nc, w[0], &nn, &c[0])) != TT_OK ||
      (st = read_nodes(s, nc, w[1], &nn, &c[1])) != TT_OK ||
      (st = read_nodes(s, nc, zname, &nn, &c[2])) != TT_OK)
    goto done;
  for (size_t i = 0; st == TT_OK && i < nn; i++)
    st = tt__soup_vertex(s, c[0][i], c[1][i], c[2][i]);
  if (st == TT_OK)
    st = read_faces(s, nc, conn);
  if (st == TT_OK)
    read_crs(s, nc, mesh);
done:
  for (int k = 0; k < 3; k++)
    free(c[k]);
  free(coords);
  free(conn);
  nc_close(nc);
  return st;
}
