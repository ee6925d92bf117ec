/*
 * test_mesh_write.c -- tt_mesh_write() (mesh_write.c): a small TIN in
 * UTM 33N written as 2DM, PLY, OBJ (map and local coordinates) and LandXML
 * and parsed back: the vertex and face counts, every coordinate equal to
 * the double the OGR layers get (tin_records.h), every face the same three
 * vertices in the same counter-clockwise order, PLY's attributes equal to
 * the TIN's (NaN kept), LandXML read with libxml2 (when the test was built
 * with it) in the northing, easting, elevation order, the mesh's name
 * escaped in LandXML and made plain in 2DM. 2DM's six .dat datasets
 * (SMS's ASCII dataset cards, one value a vertex or a face, NaN kept) and
 * the UGRID netCDF read back with libnetcdf (dimensions, coordinates,
 * start_index and connectivity, the data variables, the CRS). Also:
 * -t_srs's transformed coordinates, the format names and extensions, and
 * an interruption through progress, which leaves no file (nor dataset).
 */
#include "gdal/ogr/tin_records.h"
#include "terratin/terratin_gdal.h"
#include "tt_test.h"

#include <cpl_vsi.h>
#include <gdal.h>
#include <netcdf.h>
#include <ogr_srs_api.h>

#include <stdint.h>
#include <stdlib.h>
#include <sys/stat.h>
#include <unistd.h>

#ifdef TT_HAVE_LIBXML2
#include <libxml/parser.h>
#include <libxml/tree.h>
#endif

static char tmpdir[256];

/* A 30 x 20 grid in UTM 33N, 10 m pixels: a plane with a bump and a nodata
 * corner. */
static tt_tin *make_tin(tt_context *ctx)
{
  const size_t nx = 30, ny = 20;
  float *z = malloc(nx * ny * sizeof *z);
  for (size_t r = 0; r < ny; r++)
    for (size_t c = 0; c < nx; c++) {
      double dx = (double)c - 15, dy = (double)r - 8;
      double h = 0.8 * (double)c + 0.3 * (double)r +
                 30 * exp(-(dx * dx + dy * dy) / 30);
      z[r * nx + c] = (c + r > 42) ? NAN : (float)h;
    }
  tt_grid *g = NULL;
  CHECK_OK(ctx, tt_grid_create_from_floats(ctx, nx, ny, z, &g));
  free(z);
  const double gt[6] = {400000.5, 10, 0, 5000000.25, 0, -10};
  CHECK_OK(ctx, tt_grid_set_geotransform(ctx, g, gt));
  tt_refine_options opt;
  tt_refine_options_init(&opt);
  opt.max_error = 0.5;
  tt_tin *tin = NULL;
  CHECK_OK(ctx, tt_refine_run(ctx, g, &opt, &tin));
  tt_grid_destroy(g);
  return tin;
}

/* What the file must hold: the output x, y, z of each vertex and the
 * counter-clockwise vertices of each triangle, from tin_records.h. */
typedef struct expected {
  size_t nv, nt;
  double *xyz;   /* 3 per vertex */
  int32_t *tri;  /* 3 per triangle */
  tt_vertex_info *v;
  tt_triangle_info *t;
} expected;

static void expected_init(expected *e, tt_context *ctx, const tt_tin *tin,
                          OGRSpatialReferenceH srs, const char *t_srs)
{
  tt__records rec;
  CHECK_OK(ctx, tt__records_init(&rec, ctx, tin, srs, t_srs));
  e->nv = tt_tin_vertex_count(tin);
  e->nt = tt_tin_triangle_count(tin);
  e->xyz = malloc(3 * e->nv * sizeof *e->xyz);
  e->tri = malloc(3 * e->nt * sizeof *e->tri);
  e->v = malloc(e->nv * sizeof *e->v);
  e->t = malloc(e->nt * sizeof *e->t);
  for (size_t i = 0; i < e->nv; i++) {
    CHECK_OK(ctx, tt__records_vertex(&rec, ctx, i, &e->v[i], &e->xyz[3 * i],
                                     &e->xyz[3 * i + 1]));
    e->xyz[3 * i + 2] = e->v[i].z;
  }
  for (size_t i = 0; i < e->nt; i++) {
    double tx[3], ty[3], tz[3];
    CHECK_OK(ctx, tt__records_triangle(&rec, ctx, i, &e->t[i], tx, ty, tz));
    memcpy(&e->tri[3 * i], e->t[i].v, sizeof e->t[i].v);
    /* counter-clockwise in the output coordinates */
    CHECK((tx[1] - tx[0]) * (ty[2] - ty[0]) -
              (ty[1] - ty[0]) * (tx[2] - tx[0]) > 0);
  }
  tt__records_free(&rec);
}

static void expected_free(expected *e)
{
  free(e->xyz);
  free(e->tri);
  free(e->v);
  free(e->t);
}

/* Counts of parsed items and mismatches, checked at the end of a file. */
typedef struct tally {
  size_t nv, nt, bad_v, bad_f;
} tally;

static void see_vertex(tally *k, const expected *e, size_t id1, double x,
                       double y, double z)
{
  size_t i = id1 - 1;
  if (id1 == 0 || i >= e->nv || x != e->xyz[3 * i] ||
      y != e->xyz[3 * i + 1] || z != e->xyz[3 * i + 2])
    k->bad_v++;
  k->nv++;
}

static void see_face(tally *k, const expected *e, size_t i, long a, long b,
                     long c)
{
  if (i >= e->nt || a - 1 != e->tri[3 * i] || b - 1 != e->tri[3 * i + 1] ||
      c - 1 != e->tri[3 * i + 2])
    k->bad_f++;
  k->nt++;
}

static void check_tally(const tally *k, const expected *e, const char *what)
{
  if (k->nv != e->nv || k->nt != e->nt || k->bad_v || k->bad_f)
    fprintf(stderr, "%s: %zu/%zu vertices (%zu differ), %zu/%zu faces "
            "(%zu differ)\n", what, k->nv, e->nv, k->bad_v, k->nt, e->nt,
            k->bad_f);
  CHECK(k->nv == e->nv);
  CHECK(k->nt == e->nt);
  CHECK(k->bad_v == 0);
  CHECK(k->bad_f == 0);
}

static void write_file(tt_context *ctx, const tt_tin *tin, const char *path,
                       tt_mesh_format fmt, OGRSpatialReferenceH srs,
                       const char *t_srs, int local)
{
  CHECK_OK(ctx, tt_mesh_write(ctx, path, fmt, "small \"tin\" <&>", tin, srs,
                              t_srs, local, NULL, NULL));
}

static void read_2dm(const char *path, const expected *e)
{
  FILE *f = fopen(path, "r");
  CHECK(f != NULL);
  if (!f)
    return;
  char line[512];
  tally k = {0, 0, 0, 0};
  int header = 0;
  while (fgets(line, sizeof line, f)) {
    size_t id;
    double x, y, z;
    long a, b, c, mat;
    if (strcmp(line, "MESH2D\n") == 0)
      header = 1;
    else if (strncmp(line, "MESHNAME", 8) == 0) /* quotes made plain */
      CHECK_STR_EQ(line, "MESHNAME \"small _tin_ <&>\"\n");
    else if (sscanf(line, "ND %zu %lf %lf %lf", &id, &x, &y, &z) == 4)
      see_vertex(&k, e, id, x, y, z);
    else if (sscanf(line, "E3T %zu %ld %ld %ld %ld", &id, &a, &b, &c,
                    &mat) == 5) {
      CHECK(id == k.nt + 1);
      CHECK(mat == 1);
      see_face(&k, e, id - 1, a, b, c);
    }
  }
  fclose(f);
  CHECK(header);
  check_tally(&k, e, path);
}

static void read_obj(const char *path, const expected *e, int local)
{
  FILE *f = fopen(path, "r");
  CHECK(f != NULL);
  if (!f)
    return;
  char line[512];
  tally k = {0, 0, 0, 0};
  double ox = 0, oy = 0, maxabs = 0;
  int origin = 0;
  while (fgets(line, sizeof line, f)) {
    double x, y, z;
    long a, b, c;
    if (sscanf(line, "# origin %lf %lf", &ox, &oy) == 2)
      origin = 1;
    else if (sscanf(line, "v %lf %lf %lf", &x, &y, &z) == 3) {
      maxabs = fmax(maxabs, fmax(fabs(x), fabs(y)));
      see_vertex(&k, e, k.nv + 1, x + ox, y + oy, z);
    } else if (sscanf(line, "f %ld %ld %ld", &a, &b, &c) == 3)
      see_face(&k, e, k.nt, a, b, c);
  }
  fclose(f);
  CHECK(origin == local);
  if (local) /* around the centre: within half the 300 x 200 m extent */
    CHECK_DBL_LE(maxabs, 151.0);
  check_tally(&k, e, path);
}

static void read_ply(const char *path, const expected *e)
{
  FILE *f = fopen(path, "rb");
  CHECK(f != NULL);
  if (!f)
    return;
  char line[4096];
  size_t nv = 0, nt = 0;
  int props = 0, binary = 0, crs = 0;
  while (fgets(line, sizeof line, f) && strcmp(line, "end_header\n")) {
    sscanf(line, "element vertex %zu", &nv);
    sscanf(line, "element face %zu", &nt);
    if (strncmp(line, "property", 8) == 0)
      props++;
    if (strcmp(line, "format binary_little_endian 1.0\n") == 0)
      binary = 1;
    if (strncmp(line, "comment crs:PROJCS[\"", 19) == 0)
      crs = 1;
  }
  CHECK(binary);
  CHECK(crs); /* MDAL's "comment crs:" line, the WKT on one line */
  CHECK_INT_EQ(props, 10);
  CHECK(nv == e->nv && nt == e->nt);
  const uint16_t one = 1;
  unsigned char lo;
  memcpy(&lo, &one, 1);
  CHECK(lo == 1); /* the test reads the body as the host's doubles */
  tally k = {0, 0, 0, 0};
  size_t bad_attr = 0, nan_ins = 0;
  for (size_t i = 0; i < nv; i++) {
    double d[6];
    if (fread(d, sizeof d[0], 6, f) != 6)
      break;
    see_vertex(&k, e, i + 1, d[0], d[1], d[2]);
    const tt_vertex_info *v = &e->v[i < e->nv ? i : 0];
    const double want[3] = {v->insert_error, v->star_max_error,
                            v->star_rmse};
    for (int j = 0; j < 3; j++)
      if (!(d[3 + j] == want[j] || (isnan(d[3 + j]) && isnan(want[j]))))
        bad_attr++;
    nan_ins += isnan(d[3]);
  }
  for (size_t i = 0; i < nt; i++) {
    unsigned char n3;
    int32_t vi[3], ns;
    double d[2];
    if (fread(&n3, 1, 1, f) != 1 || fread(vi, sizeof vi[0], 3, f) != 3 ||
        fread(d, sizeof d[0], 2, f) != 2 || fread(&ns, sizeof ns, 1, f) != 1)
      break;
    CHECK_INT_EQ(n3, 3);
    see_face(&k, e, i, (long)vi[0] + 1, (long)vi[1] + 1, (long)vi[2] + 1);
    const tt_triangle_info *t = &e->t[i < e->nt ? i : 0];
    if (d[0] != t->max_error || d[1] != t->rmse ||
        (size_t)ns != t->samples)
      bad_attr++;
  }
  CHECK(fgetc(f) == EOF); /* nothing after the faces */
  fclose(f);
  CHECK(bad_attr == 0);
  CHECK(nan_ins > 0); /* the starting vertices: NaN kept as NaN */
  check_tally(&k, e, path);
}

/* 2DM's datasets beside stem.2dm: SMS ASCII dataset files, each the
 * cards MDAL reads and one value a vertex (or a face, "_els" files). */
static void read_dat(const char *stem, const expected *e)
{
  static const char *const names[6] = {"ins_err", "star_max", "star_rmse",
                                       "max_err", "rmse", "n_samples"};
  for (int k = 0; k < 6; k++) {
    char p[600], line[256], want[64];
    snprintf(p, sizeof p, "%s_%s%s.dat", stem, names[k], k < 3 ? "" : "_els");
    FILE *f = fopen(p, "r");
    CHECK(f != NULL);
    if (!f)
      continue;
    const char *head[7] = {"DATASET\n", "OBJTYPE \"mesh2d\"\n", "BEGSCL\n",
                           NULL, NULL, NULL, "TS 0 0\n"};
    char nd[32], nc[32];
    snprintf(nd, sizeof nd, "ND %zu\n", e->nv);
    snprintf(nc, sizeof nc, "NC %zu\n", e->nt);
    snprintf(want, sizeof want, "NAME \"%s\"\n", names[k]);
    head[3] = nd;
    head[4] = nc;
    head[5] = want;
    for (int h = 0; h < 7; h++)
      CHECK_STR_EQ(fgets(line, sizeof line, f) ? line : "", head[h]);
    size_t n = k < 3 ? e->nv : e->nt, got = 0, bad = 0;
    while (got < n && fgets(line, sizeof line, f)) {
      double v = strtod(line, NULL);
      double w = k == 0   ? e->v[got].insert_error
                 : k == 1 ? e->v[got].star_max_error
                 : k == 2 ? e->v[got].star_rmse
                 : k == 3 ? e->t[got].max_error
                 : k == 4 ? e->t[got].rmse
                          : (double)e->t[got].samples;
      bad += !(v == w || (isnan(v) && isnan(w)));
      got++;
    }
    CHECK(got == n);
    CHECK(bad == 0);
    CHECK_STR_EQ(fgets(line, sizeof line, f) ? line : "", "ENDDS\n");
    CHECK(fgetc(f) == EOF);
    fclose(f);
  }
}

/* Whether any of 2DM's dataset files exists beside stem.2dm. */
static int any_dat(const char *stem)
{
  static const char *const sfx[6] = {"_ins_err", "_star_max", "_star_rmse",
                                     "_max_err_els", "_rmse_els",
                                     "_n_samples_els"};
  int n = 0;
  for (int k = 0; k < 6; k++) {
    char p[600];
    struct stat sb;
    snprintf(p, sizeof p, "%s%s.dat", stem, sfx[k]);
    n += stat(p, &sb) == 0;
  }
  return n;
}

/* 2DM's CRS beside stem.2dm: stem.prj in ESRI's WKT1 (PROJCS, ESRI's
 * names), the same CRS as want; want NULL: no .prj at all. */
static void check_prj(const char *stem, OGRSpatialReferenceH want)
{
  char p[600], wkt[4096];
  snprintf(p, sizeof p, "%s.prj", stem);
  FILE *f = fopen(p, "rb");
  if (!want) {
    CHECK(f == NULL);
    if (f)
      fclose(f);
    return;
  }
  CHECK(f != NULL);
  if (!f)
    return;
  size_t n = fread(wkt, 1, sizeof wkt - 1, f);
  fclose(f);
  wkt[n] = '\0';
  /* ESRI's dialect: one line, the projection named as ESRI names it */
  static const char head[] = "PROJCS[\"WGS_1984_UTM_Zone_33N\",";
  CHECK(strncmp(wkt, head, sizeof head - 1) == 0);
  CHECK(strchr(wkt, '\n') == NULL);
  OGRSpatialReferenceH got = OSRNewSpatialReference(NULL);
  char *w = wkt;
  CHECK(OSRImportFromESRI(got, (char **)(char *[]){w, NULL}) ==
        OGRERR_NONE);
  CHECK(OSRIsSame(got, want));
  OSRDestroySpatialReference(got);
}

/* A text attribute of a netCDF variable, or "" (static buffer). */
static const char *nc_text(int nc, int var, const char *att)
{
  static char buf[4096];
  size_t len = 0;
  buf[0] = '\0';
  if (nc_inq_attlen(nc, var, att, &len) == NC_NOERR && len < sizeof buf &&
      nc_get_att_text(nc, var, att, buf) == NC_NOERR)
    buf[len] = '\0';
  return buf;
}

/* The UGRID file through libnetcdf: what MDAL reads, equal to the TIN. */
static void read_ugrid(const char *path, const expected *e, int epsg)
{
  int nc, dn, df, d3, var;
  size_t nv = 0, nt = 0, three = 0;
  CHECK_INT_EQ(nc_open(path, NC_NOWRITE, &nc), NC_NOERR);
  CHECK_INT_EQ(nc_inq_dimid(nc, "nmesh_node", &dn), NC_NOERR);
  CHECK_INT_EQ(nc_inq_dimid(nc, "nmesh_face", &df), NC_NOERR);
  CHECK_INT_EQ(nc_inq_dimid(nc, "max_nmesh_face_nodes", &d3), NC_NOERR);
  nc_inq_dimlen(nc, dn, &nv);
  nc_inq_dimlen(nc, df, &nt);
  nc_inq_dimlen(nc, d3, &three);
  CHECK(nv == e->nv && nt == e->nt && three == 3);
  if (nv != e->nv || nt != e->nt) {
    nc_close(nc);
    return;
  }
  CHECK_STR_EQ(nc_text(nc, NC_GLOBAL, "Conventions"), "CF-1.8 UGRID-1.0");
  CHECK_INT_EQ(nc_inq_varid(nc, "mesh", &var), NC_NOERR);
  CHECK_STR_EQ(nc_text(nc, var, "cf_role"), "mesh_topology");
  CHECK_STR_EQ(nc_text(nc, var, "node_coordinates"),
               "mesh_node_x mesh_node_y");
  CHECK_STR_EQ(nc_text(nc, var, "face_node_connectivity"), "mesh_face_nodes");
  int dim = 0;
  CHECK(nc_get_att_int(nc, var, "topology_dimension", &dim) == NC_NOERR &&
        dim == 2);

  double *d = malloc(nv * sizeof *d);
  size_t bad = 0;
  static const char *const coords[3] = {"mesh_node_x", "mesh_node_y",
                                        "mesh_node_z"};
  for (int c = 0; c < 3; c++) {
    CHECK_INT_EQ(nc_inq_varid(nc, coords[c], &var), NC_NOERR);
    CHECK_INT_EQ(nc_get_var_double(nc, var, d), NC_NOERR);
    for (size_t i = 0; i < nv; i++)
      bad += d[i] != e->xyz[3 * i + (size_t)c];
  }
  CHECK_STR_EQ(nc_text(nc, var, "standard_name"), "altitude");
  CHECK(bad == 0);
  static const char *const vnames[3] = {"ins_err", "star_max", "star_rmse"};
  for (int k = 0; k < 3; k++) {
    CHECK_INT_EQ(nc_inq_varid(nc, vnames[k], &var), NC_NOERR);
    CHECK_STR_EQ(nc_text(nc, var, "location"), "node");
    CHECK_STR_EQ(nc_text(nc, var, "mesh"), "mesh");
    CHECK_INT_EQ(nc_get_var_double(nc, var, d), NC_NOERR);
    bad = 0;
    for (size_t i = 0; i < nv; i++) {
      double w = k == 0 ? e->v[i].insert_error
                 : k == 1 ? e->v[i].star_max_error : e->v[i].star_rmse;
      bad += !(d[i] == w || (isnan(d[i]) && isnan(w)));
    }
    CHECK(bad == 0);
  }
  free(d);

  int *conn = malloc(3 * nt * sizeof *conn);
  d = malloc(nt * sizeof *d);
  CHECK_INT_EQ(nc_inq_varid(nc, "mesh_face_nodes", &var), NC_NOERR);
  CHECK_STR_EQ(nc_text(nc, var, "cf_role"), "face_node_connectivity");
  int start = -1;
  CHECK(nc_get_att_int(nc, var, "start_index", &start) == NC_NOERR &&
        start == 0);
  CHECK_INT_EQ(nc_get_var_int(nc, var, conn), NC_NOERR);
  bad = 0;
  for (size_t i = 0; i < 3 * nt; i++)
    bad += conn[i] != e->tri[i];
  CHECK(bad == 0);
  static const char *const fnames[3] = {"max_err", "rmse", "n_samples"};
  for (int k = 0; k < 3; k++) {
    CHECK_INT_EQ(nc_inq_varid(nc, fnames[k], &var), NC_NOERR);
    CHECK_STR_EQ(nc_text(nc, var, "location"), "face");
    CHECK_INT_EQ(nc_get_var_double(nc, var, d), NC_NOERR);
    bad = 0;
    for (size_t i = 0; i < nt; i++) {
      double w = k == 0 ? e->t[i].max_error
                 : k == 1 ? e->t[i].rmse : (double)e->t[i].samples;
      bad += d[i] != w;
    }
    CHECK(bad == 0);
  }
  free(d);
  free(conn);

  CHECK_INT_EQ(nc_inq_varid(nc, "mesh_node_x", &var), NC_NOERR);
  CHECK_STR_EQ(nc_text(nc, var, "grid_mapping"), "crs");
  CHECK_INT_EQ(nc_inq_varid(nc, "crs", &var), NC_NOERR);
  int code = 0;
  CHECK(nc_get_att_int(nc, var, "epsg", &code) == NC_NOERR && code == epsg);
  char wkt[4096];
  snprintf(wkt, sizeof wkt, "%s", nc_text(nc, var, "wkt"));
  CHECK(strncmp(wkt, "PROJCS[", 7) == 0);
  CHECK_STR_EQ(nc_text(nc, var, "crs_wkt"), wkt);
  nc_close(nc);
}

#ifdef TT_HAVE_LIBXML2
/* The text of node's first child, as numbers. */
static int node_numbers(xmlNodePtr node, double *out, int n)
{
  xmlChar *s = xmlNodeGetContent(node);
  char *p = (char *)s, *end;
  int got = 0;
  while (p && got < n) {
    double v = strtod(p, &end);
    if (end == p)
      break;
    out[got++] = v;
    p = end;
  }
  xmlFree(s);
  return got;
}

static void walk_landxml(xmlNodePtr node, tally *k, const expected *e,
                         int *surface)
{
  for (xmlNodePtr n = node; n; n = n->next) {
    if (n->type != XML_ELEMENT_NODE)
      continue;
    const char *name = (const char *)n->name;
    if (strcmp(name, "Surface") == 0) { /* escaped, read back whole */
      xmlChar *sn = xmlGetProp(n, (const xmlChar *)"name");
      CHECK(sn && strcmp((char *)sn, "small \"tin\" <&>") == 0);
      xmlFree(sn);
    } else if (strcmp(name, "Definition") == 0) {
      xmlChar *st = xmlGetProp(n, (const xmlChar *)"surfType");
      *surface += st && strcmp((char *)st, "TIN") == 0;
      xmlFree(st);
    } else if (strcmp(name, "P") == 0) {
      double nez[3];
      xmlChar *id = xmlGetProp(n, (const xmlChar *)"id");
      size_t i1 = id ? (size_t)strtoul((char *)id, NULL, 10) : 0;
      xmlFree(id);
      if (node_numbers(n, nez, 3) == 3) /* northing easting elevation */
        see_vertex(k, e, i1, nez[1], nez[0], nez[2]);
      else
        k->bad_v++;
    } else if (strcmp(name, "F") == 0) {
      double abc[3];
      if (node_numbers(n, abc, 3) == 3)
        see_face(k, e, k->nt, (long)abc[0], (long)abc[1], (long)abc[2]);
      else
        k->bad_f++;
    }
    walk_landxml(n->children, k, e, surface);
  }
}
#endif

static void read_landxml(const char *path, const expected *e)
{
#ifdef TT_HAVE_LIBXML2
  xmlDocPtr doc = xmlReadFile(path, NULL, XML_PARSE_NONET);
  CHECK(doc != NULL);
  if (!doc)
    return;
  xmlNodePtr root = xmlDocGetRootElement(doc);
  CHECK(root && strcmp((const char *)root->name, "LandXML") == 0);
  CHECK(root && root->ns &&
        strcmp((const char *)root->ns->href,
               "http://www.landxml.org/schema/LandXML-1.2") == 0);
  tally k = {0, 0, 0, 0};
  int surface = 0;
  walk_landxml(root, &k, e, &surface);
  CHECK_INT_EQ(surface, 1);
  xmlNodePtr n = root ? root->children : NULL;
  int units = 0, crs = 0;
  for (; n; n = n->next)
    if (n->type == XML_ELEMENT_NODE) {
      units += strcmp((const char *)n->name, "Units") == 0;
      if (strcmp((const char *)n->name, "CoordinateSystem") == 0) {
        xmlChar *code = xmlGetProp(n, (const xmlChar *)"epsgCode");
        crs += code && strcmp((char *)code, "32633") == 0;
        xmlFree(code);
      }
    }
  CHECK_INT_EQ(units, 1);
  CHECK_INT_EQ(crs, 1);
  xmlFreeDoc(doc);
  check_tally(&k, e, path);
#else
  (void)e;
  printf("SKIP: %s not read back: built without libxml2\n", path);
#endif
}

static int stop_at_half(double complete, const char *msg, void *arg)
{
  (void)msg;
  (void)arg;
  return complete < 0.5;
}

int main(void)
{
  GDALAllRegister();
  snprintf(tmpdir, sizeof tmpdir, "/tmp/tt_mesh_write_XXXXXX");
  if (!mkdtemp(tmpdir)) {
    perror("mkdtemp");
    return 1;
  }
  CHECK(tt_mesh_format_from_name("2dm") == TT_MESH_2DM);
  CHECK(tt_mesh_format_from_name("ply") == TT_MESH_PLY);
  CHECK(tt_mesh_format_from_name("Obj") == TT_MESH_OBJ);
  CHECK(tt_mesh_format_from_name("LANDXML") == TT_MESH_LANDXML);
  CHECK(tt_mesh_format_from_name("GPKG") == TT_MESH_NONE);
  CHECK(tt_mesh_format_from_path("a.b/x.2DM") == TT_MESH_2DM);
  CHECK(tt_mesh_format_from_path("x.xml") == TT_MESH_LANDXML);
  CHECK(tt_mesh_format_from_path("x.ply.gpkg") == TT_MESH_NONE);
  CHECK(tt_mesh_format_from_path("dir.obj/x") == TT_MESH_NONE);
  CHECK_STR_EQ(tt_mesh_format_name(TT_MESH_LANDXML), "LandXML");
  CHECK(tt_mesh_format_from_name("ugrid") == TT_MESH_UGRID);
  CHECK(tt_mesh_format_from_path("x.nc") == TT_MESH_NONE); /* OGR's */
  CHECK_STR_EQ(tt_mesh_format_sidecars(TT_MESH_2DM)[5],
               "_n_samples_els.dat");
  CHECK_STR_EQ(tt_mesh_format_sidecars(TT_MESH_2DM)[6], ".prj");
  CHECK(tt_mesh_format_sidecars(TT_MESH_2DM)[7] == NULL);
  CHECK(tt_mesh_format_sidecars(TT_MESH_PLY)[0] == NULL);

  tt_context *ctx = tt_context_create();
  tt_tin *tin = make_tin(ctx);
  OGRSpatialReferenceH srs = OSRNewSpatialReference(NULL);
  OSRImportFromEPSG(srs, 32633);
  OSRSetAxisMappingStrategy(srs, OAMS_TRADITIONAL_GIS_ORDER);
  char p[512];
  if (tin) {
    CHECK(tt_tin_triangle_count(tin) > 20);
    expected e, eg;
    expected_init(&e, ctx, tin, srs, NULL);
    snprintf(p, sizeof p, "%s/t.2dm", tmpdir);
    write_file(ctx, tin, p, TT_MESH_2DM, srs, NULL, 0);
    read_2dm(p, &e);
    snprintf(p, sizeof p, "%s/t", tmpdir);
    read_dat(p, &e);
    check_prj(p, srs);
    /* no CRS: no .prj */
    snprintf(p, sizeof p, "%s/nocrs.2dm", tmpdir);
    write_file(ctx, tin, p, TT_MESH_2DM, NULL, NULL, 0);
    snprintf(p, sizeof p, "%s/nocrs", tmpdir);
    check_prj(p, NULL);
    snprintf(p, sizeof p, "%s/t.nc", tmpdir);
    write_file(ctx, tin, p, TT_MESH_UGRID, srs, NULL, 0);
    read_ugrid(p, &e, 32633);
    snprintf(p, sizeof p, "%s/t.ply", tmpdir);
    write_file(ctx, tin, p, TT_MESH_PLY, srs, NULL, 0);
    read_ply(p, &e);
    snprintf(p, sizeof p, "%s/t.obj", tmpdir);
    write_file(ctx, tin, p, TT_MESH_OBJ, srs, NULL, 0);
    read_obj(p, &e, 0);
    snprintf(p, sizeof p, "%s/local.obj", tmpdir);
    write_file(ctx, tin, p, TT_MESH_OBJ, srs, NULL, 1);
    read_obj(p, &e, 1);
    snprintf(p, sizeof p, "%s/t.xml", tmpdir);
    write_file(ctx, tin, p, TT_MESH_LANDXML, srs, NULL, 0);
    read_landxml(p, &e);

    /* -t_srs: the transformed coordinates, faces still counter-clockwise
     * (expected_init checks them in the output coordinates). */
    expected_init(&eg, ctx, tin, srs, "EPSG:3857");
    CHECK(eg.xyz[0] != e.xyz[0]);
    snprintf(p, sizeof p, "%s/merc.2dm", tmpdir);
    write_file(ctx, tin, p, TT_MESH_2DM, srs, "EPSG:3857", 0);
    read_2dm(p, &eg);
    snprintf(p, sizeof p, "%s/merc.ply", tmpdir);
    write_file(ctx, tin, p, TT_MESH_PLY, srs, "EPSG:3857", 0);
    read_ply(p, &eg);
    snprintf(p, sizeof p, "%s/merc", tmpdir);
    read_dat(p, &eg);
    snprintf(p, sizeof p, "%s/merc.nc", tmpdir);
    write_file(ctx, tin, p, TT_MESH_UGRID, srs, "EPSG:3857", 0);
    read_ugrid(p, &eg, 3857);

    /* An interruption halfway removes the partial file. */
    for (int f = TT_MESH_2DM; f <= TT_MESH_UGRID; f++) {
      struct stat sb;
      snprintf(p, sizeof p, "%s/stopped.%d", tmpdir, f);
      CHECK(tt_mesh_write(ctx, p, (tt_mesh_format)f, NULL, tin, srs, NULL, 0,
                          stop_at_half, NULL) == TT_ERR_INTERRUPTED);
      CHECK(stat(p, &sb) != 0);
    }
    snprintf(p, sizeof p, "%s/stopped", tmpdir);
    CHECK_INT_EQ(any_dat(p), 0);
    check_prj(p, NULL);
    /* A folder that does not exist: TT_ERR_IO, nothing made. */
    snprintf(p, sizeof p, "%s/no/such.2dm", tmpdir);
    CHECK(tt_mesh_write(ctx, p, TT_MESH_2DM, NULL, tin, srs, NULL, 0, NULL,
                        NULL) == TT_ERR_IO);
    CHECK(tt_mesh_write(ctx, p, TT_MESH_NONE, NULL, tin, srs, NULL, 0, NULL,
                        NULL) == TT_ERR_ARG);
    expected_free(&e);
    expected_free(&eg);
  }
  OSRDestroySpatialReference(srs);
  tt_tin_destroy(tin);
  tt_context_destroy(ctx);
  VSIRmdirRecursive(tmpdir);
  TT_TEST_DONE();
}
