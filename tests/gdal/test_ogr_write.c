/*
 * test_ogr_write.c -- round trips of tt_ogr_write_tin() through GPKG and
 * ESRI Shapefile with tt_output's safe paths, read back with OGR: layer
 * names and geometry types, field names and types, feature counts, every
 * attribute against the tt_tin accessors (NULL where NaN), the SRS, every
 * triangle ring closed with 4 points and counter-clockwise (GPKG; the
 * Shapefile driver stores outer rings clockwise, as its format demands, so
 * there the same corners must come back in reverse), the GPKG R-tree filled,
 * layer creation options passed through, run_parameters typed, option and
 * field-name refusals, interruption leaving nothing behind, and no file in
 * the folder but the final ones.
 */
#include "terratin/terratin_gdal.h"
#include "tt_test.h"

#include <cpl_string.h>
#include <cpl_vsi.h>

#include <dirent.h>
#include <stdlib.h>
#include <sys/stat.h>
#include <unistd.h>

static char tmpdir[256];

static int cmp_str(const void *a, const void *b)
{
  return strcmp(*(char *const *)a, *(char *const *)b);
}

static void list_dir(const char *dir, char *buf, size_t size)
{
  char *names[256];
  int n = 0;
  DIR *d = opendir(dir);
  struct dirent *e;
  buf[0] = '\0';
  if (!d)
    return;
  while ((e = readdir(d)) != NULL && n < 256)
    if (strcmp(e->d_name, ".") && strcmp(e->d_name, ".."))
      names[n++] = strdup(e->d_name);
  closedir(d);
  qsort(names, (size_t)n, sizeof *names, cmp_str);
  size_t used = 0;
  for (int i = 0; i < n; i++) {
    int w = snprintf(buf + used, size - used, "%s%s", i ? " " : "",
                     names[i]);
    if (w > 0 && (size_t)w < size - used)
      used += (size_t)w;
    free(names[i]);
  }
}

/* A 40 x 30 grid in UTM 33N, 10 m pixels: a tilted plane with a bump and
 * a flat shelf (flat triangles have no aspect), and a nodata corner. */
static tt_tin *make_tin(tt_context *ctx)
{
  const size_t nx = 40, ny = 30;
  float *z = malloc(nx * ny * sizeof *z);
  for (size_t r = 0; r < ny; r++)
    for (size_t c = 0; c < nx; c++) {
      double dx = (double)c - 25, dy = (double)r - 12;
      double h = 0.8 * (double)c + 0.3 * (double)r +
                 30 * exp(-(dx * dx + dy * dy) / 40);
      if (c < 12 && r < 10)
        h = 50; /* flat shelf */
      z[r * nx + c] = (c + r > 60) ? NAN : (float)h;
    }
  tt_grid *g = NULL;
  CHECK_OK(ctx, tt_grid_create_from_floats(ctx, nx, ny, z, &g));
  free(z);
  const double gt[6] = {400000, 10, 0, 5000000, 0, -10};
  CHECK_OK(ctx, tt_grid_set_geotransform(ctx, g, gt));
  tt_refine_options opt;
  tt_refine_options_init(&opt);
  opt.max_error = 0.25;
  tt_tin *tin = NULL;
  CHECK_OK(ctx, tt_refine_run(ctx, g, &opt, &tin));
  tt_grid_destroy(g);
  return tin;
}

static const tt_run_field run_fields[] = {
    {"input", TT_FIELD_STRING, "synthetic \xc3\xa9t\xc3\xa9", 0, 0},
    {"max_points", TT_FIELD_INTEGER, NULL, 5000000000LL, 0},
    {"max_error", TT_FIELD_REAL, NULL, 0, 0.25},
    {"criterion", TT_FIELD_STRING, "delaunay", 0, 0}};
#define N_RUN_FIELDS 4

typedef struct progress_log {
  int calls;
  double last;
  int monotone;
  int stop_after; /* 0: never stop */
} progress_log;

static int log_progress(double complete, const char *msg, void *arg)
{
  (void)msg;
  progress_log *p = arg;
  if (complete < p->last)
    p->monotone = 0;
  p->last = complete;
  p->calls++;
  return p->stop_after == 0 || p->calls < p->stop_after;
}

/* Writes tin to path in format through tt_output; returns the status of
 * the write (the output is committed only on success). */
static tt_status write_tin(tt_context *ctx, const tt_tin *tin,
                           const char *path, const char *format,
                           OGRSpatialReferenceH srs, char **extra,
                           progress_log *plog)
{
  tt_output *out = NULL;
  tt_status s = tt_output_begin(ctx, path, format, 1, &out);
  if (s != TT_OK)
    return s;
  GDALDatasetH ds = GDALCreate(GDALGetDriverByName(format),
                               tt_output_temp_path(out), 0, 0, 0,
                               GDT_Unknown, NULL);
  CHECK(ds != NULL);
  char **opts = CSLDuplicate(extra);
  opts = CSLSetNameValue(opts, "NLN_PREFIX", tt_output_layer_prefix(out));
  s = tt_ogr_write_tin(ctx, ds, tin, srs, run_fields, N_RUN_FIELDS, opts,
                       plog ? log_progress : NULL, plog);
  CSLDestroy(opts);
  GDALClose(ds);
  if (s == TT_OK)
    s = tt_output_commit(ctx, out);
  tt_output_destroy(out);
  return s;
}

static int has_field(OGRFeatureDefnH fd, const char *name, OGRFieldType t)
{
  int i = OGR_FD_GetFieldIndex(fd, name);
  if (i < 0) {
    TT_FAIL_("field %s missing", name);
    return -1;
  }
  OGRFieldType got = OGR_Fld_GetType(OGR_FD_GetFieldDefn(fd, i));
  if (got != t)
    TT_FAIL_("field %s has type %s, want %s", name,
             OGR_GetFieldTypeName(got), OGR_GetFieldTypeName(t));
  return i;
}

/* NULL when want is NaN, else the value. */
static void check_real(OGRFeatureH f, int idx, double want, const char *what,
                       size_t i)
{
  if (idx < 0)
    return;
  int is_null = OGR_F_IsFieldNull(f, idx) || !OGR_F_IsFieldSet(f, idx);
  if (isnan(want)) {
    if (!is_null)
      TT_FAIL_("%s of feature %zu: want NULL, got %.17g", what, i,
               OGR_F_GetFieldAsDouble(f, idx));
    return;
  }
  double got = OGR_F_GetFieldAsDouble(f, idx);
  if (is_null || !(fabs(got - want) <= 1e-9 * (1 + fabs(want))))
    TT_FAIL_("%s of feature %zu: got %.17g, want %.17g", what, i, got,
             want);
}

static void check_triangles(const tt_tin *tin, OGRLayerH l, int shapefile)
{
  CHECK_INT_EQ(wkbFlatten(OGR_L_GetGeomType(l)), wkbPolygon);
  CHECK(wkbHasZ(OGR_L_GetGeomType(l)));
  CHECK_INT_EQ(OGR_L_GetFeatureCount(l, TRUE), tt_tin_triangle_count(tin));
  OGRFeatureDefnH fd = OGR_L_GetLayerDefn(l);
  CHECK_INT_EQ(OGR_FD_GetFieldCount(fd), 12);
  int iv[3] = {has_field(fd, "v0", OFTInteger), has_field(fd, "v1", OFTInteger),
               has_field(fd, "v2", OFTInteger)};
  int imax = has_field(fd, "max_err", OFTReal);
  int irmse = has_field(fd, "rmse", OFTReal);
  int in = has_field(fd, "n_samples", OFTInteger64);
  int ia2 = has_field(fd, "area_2d", OFTReal);
  int ia3 = has_field(fd, "area_3d", OFTReal);
  int isl = has_field(fd, "slope", OFTReal);
  int iasp = has_field(fd, "aspect", OFTReal);
  int imin = has_field(fd, "min_angle", OFTReal);
  int imaxa = has_field(fd, "max_angle", OFTReal);
  OGR_L_ResetReading(l);
  OGRFeatureH f;
  size_t i = 0, bad_ring = 0, flat = 0;
  while ((f = OGR_L_GetNextFeature(l)) != NULL) {
    tt_triangle_info t;
    if (tt_tin_triangle(tin, i, &t) != TT_OK) {
      TT_FAIL_("more features than triangles");
      OGR_F_Destroy(f);
      break;
    }
    for (int k = 0; k < 3; k++)
      if (iv[k] >= 0)
        CHECK_INT_EQ(OGR_F_GetFieldAsInteger(f, iv[k]), t.v[k]);
    check_real(f, imax, t.max_error, "max_err", i);
    check_real(f, irmse, t.rmse, "rmse", i);
    if (in >= 0)
      CHECK_INT_EQ(OGR_F_GetFieldAsInteger64(f, in), t.samples);
    check_real(f, ia2, t.area_2d, "area_2d", i);
    check_real(f, ia3, t.area_3d, "area_3d", i);
    check_real(f, isl, t.slope_deg, "slope", i);
    check_real(f, iasp, t.aspect_deg, "aspect", i);
    check_real(f, imin, t.min_angle_deg, "min_angle", i);
    check_real(f, imaxa, t.max_angle_deg, "max_angle", i);
    flat += isnan(t.aspect_deg);

    /* The ring: closed, 4 points, the corners v0 v1 v2 counter-clockwise
     * (GPKG) or their clockwise rewinding (Shapefile). */
    OGRGeometryH g = OGR_F_GetGeometryRef(f);
    OGRGeometryH ring = g ? OGR_G_GetGeometryRef(g, 0) : NULL;
    int ok = g && wkbFlatten(OGR_G_GetGeometryType(g)) == wkbPolygon &&
             OGR_G_GetGeometryCount(g) == 1 && ring &&
             OGR_G_GetPointCount(ring) == 4 && OGR_G_Is3D(g);
    if (ok) {
      double p[4][3];
      for (int k = 0; k < 4; k++)
        OGR_G_GetPoint(ring, k, &p[k][0], &p[k][1], &p[k][2]);
      ok = p[0][0] == p[3][0] && p[0][1] == p[3][1] && p[0][2] == p[3][2];
      double area2 = 0;
      for (int k = 0; k < 3; k++)
        area2 += p[k][0] * p[k + 1][1] - p[k + 1][0] * p[k][1];
      ok = ok && (shapefile ? area2 < 0 : area2 > 0);
      for (int k = 0; k < 3 && ok; k++) {
        tt_vertex_info v;
        int pos = shapefile ? (3 - k) % 3 : k; /* v0 v2 v1 when rewound */
        tt_tin_vertex(tin, (size_t)t.v[k], &v);
        ok = p[pos][0] == v.x && p[pos][1] == v.y && p[pos][2] == v.z;
      }
    }
    if (!ok && bad_ring++ < 3)
      TT_FAIL_("triangle %zu: ring is not v0 v1 v2 v0 %s", i,
               shapefile ? "rewound clockwise" : "counter-clockwise");
    OGR_F_Destroy(f);
    i++;
  }
  CHECK_INT_EQ(i, tt_tin_triangle_count(tin));
  CHECK(flat > 0); /* the shelf made some NULL aspects */
}

static void check_vertices(const tt_tin *tin, OGRLayerH l)
{
  CHECK_INT_EQ(OGR_L_GetGeomType(l), wkbPoint25D);
  CHECK_INT_EQ(OGR_L_GetFeatureCount(l, TRUE), tt_tin_vertex_count(tin));
  OGRFeatureDefnH fd = OGR_L_GetLayerDefn(l);
  CHECK_INT_EQ(OGR_FD_GetFieldCount(fd), 8);
  int iid = has_field(fd, "vertex_id", OFTInteger);
  int ic = has_field(fd, "col", OFTInteger);
  int ir = has_field(fd, "row", OFTInteger);
  int ie = has_field(fd, "ins_err", OFTReal);
  int irk = has_field(fd, "ins_rank", OFTInteger64);
  int ism = has_field(fd, "star_max", OFTReal);
  int isr = has_field(fd, "star_rmse", OFTReal);
  int isn = has_field(fd, "star_n", OFTInteger64);
  OGR_L_ResetReading(l);
  OGRFeatureH f;
  size_t i = 0, nulls = 0;
  while ((f = OGR_L_GetNextFeature(l)) != NULL) {
    tt_vertex_info v;
    if (tt_tin_vertex(tin, i, &v) != TT_OK) {
      TT_FAIL_("more features than vertices");
      OGR_F_Destroy(f);
      break;
    }
    if (iid >= 0)
      CHECK_INT_EQ(OGR_F_GetFieldAsInteger(f, iid), i);
    if (ic >= 0)
      CHECK_INT_EQ(OGR_F_GetFieldAsInteger(f, ic), v.col);
    if (ir >= 0)
      CHECK_INT_EQ(OGR_F_GetFieldAsInteger(f, ir), v.row);
    check_real(f, ie, v.insert_error, "ins_err", i);
    nulls += isnan(v.insert_error);
    if (irk >= 0)
      CHECK_INT_EQ(OGR_F_GetFieldAsInteger64(f, irk), v.rank);
    check_real(f, ism, v.star_max_error, "star_max", i);
    check_real(f, isr, v.star_rmse, "star_rmse", i);
    if (isn >= 0)
      CHECK_INT_EQ(OGR_F_GetFieldAsInteger64(f, isn), v.star_samples);
    OGRGeometryH g = OGR_F_GetGeometryRef(f);
    CHECK(g != NULL);
    if (g) {
      CHECK_DBL_NEAR(OGR_G_GetX(g, 0), v.x, 0);
      CHECK_DBL_NEAR(OGR_G_GetY(g, 0), v.y, 0);
      CHECK_DBL_NEAR(OGR_G_GetZ(g, 0), v.z, 0);
    }
    OGR_F_Destroy(f);
    i++;
  }
  CHECK_INT_EQ(i, tt_tin_vertex_count(tin));
  CHECK(nulls > 0); /* the starting vertices have no insertion error */
}

static void check_run_parameters(OGRLayerH l, int shapefile)
{
  CHECK_INT_EQ(OGR_L_GetGeomType(l), wkbNone);
  CHECK_INT_EQ(OGR_L_GetFeatureCount(l, TRUE), 1);
  OGRFeatureDefnH fd = OGR_L_GetLayerDefn(l);
  CHECK_INT_EQ(OGR_FD_GetFieldCount(fd), N_RUN_FIELDS);
  int is = has_field(fd, "input", OFTString);
  /* DBF has no 64-bit integer type of its own: OGR reads 20 digits back
   * as Integer64. */
  int ii = has_field(fd, "max_points", OFTInteger64);
  int ir = has_field(fd, "max_error", OFTReal);
  int ic = has_field(fd, "criterion", OFTString);
  OGR_L_ResetReading(l);
  OGRFeatureH f = OGR_L_GetNextFeature(l);
  CHECK(f != NULL);
  if (!f)
    return;
  if (is >= 0)
    CHECK_STR_EQ(OGR_F_GetFieldAsString(f, is), run_fields[0].s);
  if (ii >= 0)
    CHECK_INT_EQ(OGR_F_GetFieldAsInteger64(f, ii), 5000000000LL);
  if (ir >= 0)
    CHECK_DBL_NEAR(OGR_F_GetFieldAsDouble(f, ir), 0.25, 0);
  if (ic >= 0)
    CHECK_STR_EQ(OGR_F_GetFieldAsString(f, ic), "delaunay");
  (void)shapefile;
  OGR_F_Destroy(f);
}

static void check_srs(OGRLayerH l, OGRSpatialReferenceH want)
{
  OGRSpatialReferenceH got = OGR_L_GetSpatialRef(l);
  CHECK(got != NULL);
  if (!got)
    return;
  const char *const crit[] = {"IGNORE_DATA_AXIS_TO_SRS_AXIS_MAPPING=YES",
                              NULL};
  if (!OSRIsSameEx(got, want, crit)) {
    /* A .prj holds ESRI WKT: compare what it identifies as. */
    OGRSpatialReferenceH c = OSRClone(got);
    OSRAutoIdentifyEPSG(c);
    const char *code = OSRGetAuthorityCode(c, NULL);
    CHECK_STR_EQ(code, "32633");
    OSRDestroySpatialReference(c);
  }
}

static void test_round_trip(tt_context *ctx, const tt_tin *tin,
                            const char *format)
{
  const int shp = strcmp(format, "ESRI Shapefile") == 0;
  char dir[300], path[400], listing[4096];
  snprintf(dir, sizeof dir, "%s/%s", tmpdir, shp ? "shp" : "gpkg");
  mkdir(dir, 0777);
  snprintf(path, sizeof path, "%s/%s", dir, shp ? "tin.shp" : "tin.gpkg");
  OGRSpatialReferenceH srs = OSRNewSpatialReference(NULL);
  OSRImportFromEPSG(srs, 32633);
  OSRSetAxisMappingStrategy(srs, OAMS_TRADITIONAL_GIS_ORDER);

  char **extra = NULL;
  if (!shp)
    extra = CSLAddString(extra, "LCO=GEOMETRY_NAME=geom");
  progress_log plog = {0, 0, 1, 0};
  CHECK_OK(ctx, write_tin(ctx, tin, path, format, srs, extra, &plog));
  CSLDestroy(extra);
  CHECK(plog.monotone);
  CHECK_DBL_NEAR(plog.last, 1.0, 0);
  /* Asked after every feature (a stop is seen after one feature, issue 11
   * item 6), plus the start and the end. */
  CHECK_INT_LE((long long)(tt_tin_vertex_count(tin) +
                           tt_tin_triangle_count(tin) + 1),
               plog.calls);

  list_dir(dir, listing, sizeof listing);
  if (shp)
    CHECK_STR_EQ(listing,
                 "tin_run_parameters.cpg tin_run_parameters.dbf "
                 "tin_triangles.cpg tin_triangles.dbf tin_triangles.prj "
                 "tin_triangles.qix tin_triangles.shp tin_triangles.shx "
                 "tin_vertices.cpg tin_vertices.dbf tin_vertices.prj "
                 "tin_vertices.qix tin_vertices.shp tin_vertices.shx");
  else
    CHECK_STR_EQ(listing, "tin.gpkg");

  GDALDatasetH ds = GDALOpenEx(shp ? dir : path, GDAL_OF_VECTOR, NULL, NULL,
                               NULL);
  CHECK(ds != NULL);
  if (ds) {
    const char *names[3] = {"triangles", "vertices", "run_parameters"};
    OGRLayerH layers[3];
    CHECK_INT_EQ(GDALDatasetGetLayerCount(ds), 3);
    for (int k = 0; k < 3; k++) {
      char name[64];
      snprintf(name, sizeof name, "%s%s", shp ? "tin_" : "", names[k]);
      layers[k] = GDALDatasetGetLayerByName(ds, name);
      if (!layers[k])
        TT_FAIL_("layer %s missing", name);
    }
    if (layers[0]) {
      check_triangles(tin, layers[0], shp);
      check_srs(layers[0], srs);
      if (!shp) {
        CHECK_STR_EQ(OGR_L_GetGeometryColumn(layers[0]), "geom");
        CHECK(OGR_L_TestCapability(layers[0], OLCFastSpatialFilter));
      }
    }
    if (layers[1]) {
      check_vertices(tin, layers[1]);
      check_srs(layers[1], srs);
    }
    if (layers[2])
      check_run_parameters(layers[2], shp);
    if (!shp) {
      /* The R-tree exists and holds every triangle. */
      OGRLayerH rs = GDALDatasetExecuteSQL(
          ds, "SELECT COUNT(*) FROM rtree_triangles_geom", NULL, NULL);
      CHECK(rs != NULL);
      if (rs) {
        OGRFeatureH f = OGR_L_GetNextFeature(rs);
        CHECK_INT_EQ(f ? OGR_F_GetFieldAsInteger64(f, 0) : -1,
                     tt_tin_triangle_count(tin));
        OGR_F_Destroy(f);
        GDALDatasetReleaseResultSet(ds, rs);
      }
    }
    GDALClose(ds);
  }

  /* Interrupted half-way: an error, nothing committed, nothing left. */
  snprintf(path, sizeof path, "%s/%s", dir, shp ? "stop.shp" : "stop.gpkg");
  progress_log stop = {0, 0, 1, 40};
  CHECK_INT_EQ(write_tin(ctx, tin, path, format, srs, NULL, &stop),
               TT_ERR_INTERRUPTED);
  CHECK_INT_EQ(stop.calls, 40);
  list_dir(dir, listing, sizeof listing);
  CHECK(strstr(listing, "stop") == NULL);

  /* Same into an open GPKG written directly: the rollback leaves no layer
   * behind (no transaction in Shapefile: the layers are deleted). */
  char direct[400];
  snprintf(direct, sizeof direct, "%s/%s", dir,
           shp ? "direct_dir" : "direct.gpkg");
  GDALDatasetH dd = GDALCreate(GDALGetDriverByName(format), direct, 0, 0, 0,
                               GDT_Unknown, NULL);
  CHECK(dd != NULL);
  progress_log stop2 = {0, 0, 1, 5};
  CHECK_INT_EQ(tt_ogr_write_tin(ctx, dd, tin, srs, run_fields, N_RUN_FIELDS,
                                NULL, log_progress, &stop2),
               TT_ERR_INTERRUPTED);
  CHECK_INT_EQ(GDALDatasetGetLayerCount(dd), 0);
  /* Refusals before anything is written. */
  const char *bad_opt[] = {"PREFIX=x", NULL};
  CHECK_INT_EQ(tt_ogr_write_tin(ctx, dd, tin, srs, run_fields, N_RUN_FIELDS,
                                (char **)bad_opt, NULL, NULL),
               TT_ERR_ARG);
  const char *bad_lco[] = {"LCO=NOEQUALS", NULL};
  CHECK_INT_EQ(tt_ogr_write_tin(ctx, dd, tin, srs, run_fields, N_RUN_FIELDS,
                                (char **)bad_lco, NULL, NULL),
               TT_ERR_ARG);
  const tt_run_field long_name[] = {
      {"a_long_field_name", TT_FIELD_INTEGER, NULL, 1, 0}};
  const char *no_index[] = {"LCO=SPATIAL_INDEX=NO", NULL};
  tt_status s = tt_ogr_write_tin(ctx, dd, tin, NULL, long_name, 1,
                                 (char **)no_index, NULL, NULL);
  if (shp) {
    CHECK_INT_EQ(s, TT_ERR_ARG);
    CHECK(strstr(tt_context_errmsg(ctx), "a_long_field_name") != NULL);
    CHECK_INT_EQ(GDALDatasetGetLayerCount(dd), 0);
  } else {
    /* GPKG takes long names; no SRS is fine too: "Undefined Cartesian
     * SRS" (srs_id -1), not GDAL's default of "Undefined geographic". */
    CHECK_OK(ctx, s);
    OGRLayerH l = GDALDatasetGetLayerByName(dd, "triangles");
    OGRSpatialReferenceH ls = l ? OGR_L_GetSpatialRef(l) : NULL;
    CHECK(ls != NULL && !OSRIsGeographic(ls) && OSRGetName(ls) &&
          strstr(OSRGetName(ls), "ndefined") != NULL);
    CHECK(l != NULL && !OGR_L_TestCapability(l, OLCFastSpatialFilter));
  }
  /* After the rolled-back attempts the dataset closes without errors. */
  CPLErrorReset();
  GDALClose(dd);
  CHECK_INT_EQ(CPLGetLastErrorType(), CE_None);
  if (!shp) {
    dd = GDALOpenEx(direct, GDAL_OF_VECTOR, NULL, NULL, NULL);
    CHECK(dd != NULL);
    if (dd) {
      CHECK_INT_EQ(GDALDatasetGetLayerCount(dd), 3);
      OGRLayerH l = GDALDatasetGetLayerByName(dd, "triangles");
      CHECK(l != NULL &&
            OGR_L_GetFeatureCount(l, TRUE) == (GIntBig)tt_tin_triangle_count(tin));
      GDALClose(dd);
    }
  }
  OSRDestroySpatialReference(srs);
}

int main(void)
{
  GDALAllRegister();
  snprintf(tmpdir, sizeof tmpdir, "/tmp/tt_ogr_write_XXXXXX");
  if (!mkdtemp(tmpdir)) {
    perror("mkdtemp");
    return 1;
  }
  tt_context *ctx = tt_context_create();
  tt_tin *tin = make_tin(ctx);
  if (tin) {
    CHECK(tt_tin_triangle_count(tin) > 20);
    test_round_trip(ctx, tin, "GPKG");
    test_round_trip(ctx, tin, "ESRI Shapefile");
  }
  tt_tin_destroy(tin);
  tt_context_destroy(ctx);
  VSIRmdirRecursive(tmpdir);
  TT_TEST_DONE();
}
