/*
 * test_mesh_write.c -- tt_mesh_write() (io_mesh_write.c): a small TIN in
 * UTM 33N written as 2DM, PLY, OBJ (map and local coordinates) and LandXML
 * and parsed back: the vertex and face counts, every coordinate equal to
 * the double the OGR layers get (tin_records.h), every face the same three
 * vertices in the same counter-clockwise order, PLY's attributes equal to
 * the TIN's (NaN kept), LandXML read with libxml2 (when the test was built
 * with it) in the northing, easting, elevation order, the mesh's name
 * escaped in LandXML and made plain in 2DM. Also: -t_srs's
 * transformed coordinates, the format names and extensions, and an
 * interruption through progress, which leaves no file.
 */
#include "gdal/tin_records.h"
#include "terratin/terratin_gdal.h"
#include "tt_test.h"

#include <cpl_vsi.h>
#include <gdal.h>
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
    tt_vertex_info tv[3];
    double tx[3], ty[3];
    CHECK_OK(ctx, tt__records_triangle(&rec, ctx, i, &e->t[i], tv, tx, ty));
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
  char line[256];
  size_t nv = 0, nt = 0;
  int props = 0, binary = 0;
  while (fgets(line, sizeof line, f) && strcmp(line, "end_header\n")) {
    sscanf(line, "element vertex %zu", &nv);
    sscanf(line, "element face %zu", &nt);
    if (strncmp(line, "property", 8) == 0)
      props++;
    if (strcmp(line, "format binary_little_endian 1.0\n") == 0)
      binary = 1;
  }
  CHECK(binary);
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

    /* An interruption halfway removes the partial file. */
    for (int f = TT_MESH_2DM; f <= TT_MESH_LANDXML; f++) {
      struct stat sb;
      snprintf(p, sizeof p, "%s/stopped.%d", tmpdir, f);
      CHECK(tt_mesh_write(ctx, p, (tt_mesh_format)f, NULL, tin, srs, NULL, 0,
                          stop_at_half, NULL) == TT_ERR_INTERRUPTED);
      CHECK(stat(p, &sb) != 0);
    }
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
