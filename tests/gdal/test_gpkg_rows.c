/*
 * test_gpkg_rows.c -- tt_gpkg_write_rows(), the direct GeoPackage row
 * writer, against the OGR writer it replaces for GPKG: the same TIN written
 * both ways (rows through OGR plus tt_gpkg_build_rtree() on the closed file,
 * and ROWS=DEFERRED plus tt_gpkg_write_rows()) must give the same files row
 * for row: every column of the triangles and vertices tables (geometry
 * blobs byte for byte), gpkg_contents (extents; not last_change),
 * gpkg_ogr_contents, gpkg_geometry_columns, gpkg_extensions, the R-tree's
 * virtual and shadow tables, sqlite_sequence, and the schema (tables,
 * triggers, their SQL). Each case runs both of the writer's paths: rows
 * inserted through SQLite, and PAGES=YES, the tables' B-trees written as
 * pages (sqlite_pages.c), which must also give records of the same bytes
 * (dbstat's payload sums) and must really be taken (no "not as pages"
 * debug message).
 * Cases: a projected CRS; T_SRS to a geographic CRS (geodesic areas); a
 * layer prefix with a renamed fid and geometry column; no spatial index;
 * LAYERS subsets; a decimated TIN (the importance field, NULL ins_err and
 * ins_rank); the rows made on the SQLite thread (THREADS=1) or by a second
 * thread, for a TIN of one chunk of rows and one of several; pages of
 * 512 and 1,024 bytes (with reserved bytes) where the B-trees have two and
 * three interior levels, against the SQL path on the same pages.
 * Then: PRAGMA integrity_check and rtreecheck() pass; GDAL opens the file
 * with the counts and extent, its spatial filters return the features a
 * brute-force test of every feature against the box returns, and it can
 * add and delete features afterwards (integrity_check and rtreecheck()
 * again, fids going on after the last); an interruption at any point
 * leaves empty layers without an index in a sound file; a second write and
 * a non-GPKG dataset are refused.
 */
#include "terratin/terratin_gdal.h"
#include "tt_test.h"

#include <cpl_conv.h>
#include <cpl_error.h>
#include <cpl_string.h>
#include <ogr_srs_api.h>

#include <sqlite3.h>

#include <stdlib.h>
#include <unistd.h>

static char tmpdir[256];

/* A 60 x 45 grid in UTM 33N, 10 m pixels: a plane, a bump, a flat shelf
 * (flat triangles have no aspect: NULL) and a nodata corner. */
static tt_grid *make_grid(tt_context *ctx)
{
  const size_t nx = 60, ny = 45;
  float *z = malloc(nx * ny * sizeof *z);
  for (size_t r = 0; r < ny; r++)
    for (size_t c = 0; c < nx; c++) {
      double dx = (double)c - 35, dy = (double)r - 20;
      double h = 0.8 * (double)c + 0.3 * (double)r +
                 30 * exp(-(dx * dx + dy * dy) / 60);
      if (c < 15 && r < 12)
        h = 50;
      z[r * nx + c] = (c + r > 90) ? NAN : (float)h;
    }
  tt_grid *g = NULL;
  CHECK_OK(ctx, tt_grid_create_from_floats(ctx, nx, ny, z, &g));
  free(z);
  const double gt[6] = {400000, 10, 0, 5000000, 0, -10};
  CHECK_OK(ctx, tt_grid_set_geotransform(ctx, g, gt));
  return g;
}

static tt_tin *make_tin(tt_context *ctx, double max_error)
{
  tt_grid *g = make_grid(ctx);
  tt_refine_options opt;
  tt_refine_options_init(&opt);
  opt.max_error = max_error;
  tt_tin *tin = NULL;
  CHECK_OK(ctx, tt_refine_run(ctx, g, &opt, &tin));
  tt_grid_destroy(g);
  return tin;
}

/* The same grid decimated: the importance field, NULL ins_err and
 * ins_rank. */
static tt_tin *make_dtin(tt_context *ctx, double max_error)
{
  tt_grid *g = make_grid(ctx);
  tt_decimate_options o;
  tt_decimate_options_init(&o);
  o.max_error = max_error;
  tt_tin *d = NULL;
  CHECK_OK(ctx, tt_decimate_run(ctx, g, &o, &d));
  tt_grid_destroy(g);
  return d;
}

static const tt_run_field run_fields[] = {
    {"input", TT_FIELD_STRING, "synthetic", 0, 0},
    {"max_error", TT_FIELD_REAL, NULL, 0, 0.2}};

typedef struct stopper {
  int calls, stop_at; /* stop_at 0: never */
} stopper;

static int stop_fn(double complete, const char *msg, void *arg)
{
  (void)complete;
  (void)msg;
  stopper *p = arg;
  if (!p)
    return 1;
  p->calls++;
  return p->stop_at == 0 || p->calls < p->stop_at;
}

/* Creates path with the TIN's layers; direct: ROWS=DEFERRED and the row
 * writer (its progress through stop), else rows through OGR and the R-trees
 * by tt_gpkg_build_rtree(). Returns the row writer's status (TT_OK for the
 * OGR path). */
/* Pages of page bytes, reserve of them reserved, for the file at path
 * (VACUUM). */
static int page_size = 0, page_reserve = 0;

static void repage(const char *path)
{
  sqlite3 *db = NULL;
  CHECK(sqlite3_open(path, &db) == SQLITE_OK);
  char sql[64];
  snprintf(sql, sizeof sql, "PRAGMA page_size = %d", page_size);
  CHECK(sqlite3_exec(db, sql, NULL, NULL, NULL) == SQLITE_OK);
  int r = page_reserve;
  CHECK(sqlite3_file_control(db, "main", SQLITE_FCNTL_RESERVE_BYTES, &r) ==
        SQLITE_OK);
  CHECK(sqlite3_exec(db, "VACUUM", NULL, NULL, NULL) == SQLITE_OK);
  sqlite3_close(db);
}

static tt_status write_gpkg(tt_context *ctx, const tt_tin *tin,
                            const char *path, OGRSpatialReferenceH srs,
                            char **opts, int direct, int rtree,
                            stopper *stop)
{
  unlink(path);
  GDALDatasetH ds = GDALCreate(GDALGetDriverByName("GPKG"), path, 0, 0, 0,
                               GDT_Unknown, NULL);
  CHECK(ds != NULL);
  char **o = CSLDuplicate(opts);
  o = CSLSetNameValue(o, direct ? "ROWS" : "RTREE", "DEFERRED");
  CHECK_OK(ctx, tt_ogr_write_tin(ctx, ds, tin, srs, run_fields, 2, o, NULL,
                                 NULL));
  GDALClose(ds);
  if (direct && page_size)
    repage(path);
  tt_status s = TT_OK;
  if (direct) {
    char **ro = CSLSetNameValue(CSLDuplicate(o), "RTREE_CHECK", "YES");
    s = tt_gpkg_write_rows(ctx, path, tin, srs, ro, stop_fn, stop);
    CSLDestroy(ro);
  } else if (rtree) {
    const char *prefix = CSLFetchNameValueDef(o, "NLN_PREFIX", "");
    const char *geom = "geom";
    for (char **p = o; p && *p; p++)
      if (strncmp(*p, "LCO=GEOMETRY_NAME=", 18) == 0)
        geom = *p + 18;
    const char *lv = CSLFetchNameValue(o, "LAYERS");
    for (int k = 0; k < 2; k++) {
      char layer[64];
      snprintf(layer, sizeof layer, "%s%s", prefix,
               k ? "vertices" : "triangles");
      if (lv && !strstr(lv, k ? "vertices" : "triangles"))
        continue;
      CHECK_OK(ctx, tt_gpkg_build_rtree(ctx, path, layer, geom, NULL, NULL));
    }
  }
  CSLDestroy(o);
  return s;
}

static sqlite3 *db_open(const char *path)
{
  sqlite3 *db = NULL;
  if (sqlite3_open_v2(path, &db, SQLITE_OPEN_READONLY, NULL) != SQLITE_OK)
    TT_FAIL_("cannot open %s", path);
  return db;
}

/* Every row of query in both files, column by column. */
static void same_rows(sqlite3 *a, sqlite3 *b, const char *query,
                      const char *what)
{
  sqlite3_stmt *sa = NULL, *sb = NULL;
  if (sqlite3_prepare_v2(a, query, -1, &sa, NULL) != SQLITE_OK ||
      sqlite3_prepare_v2(b, query, -1, &sb, NULL) != SQLITE_OK) {
    TT_FAIL_("%s: cannot run %s: %s / %s", what, query, sqlite3_errmsg(a),
             sqlite3_errmsg(b));
    goto done;
  }
  long rows = 0;
  for (;; rows++) {
    int ra = sqlite3_step(sa), rb = sqlite3_step(sb);
    if (ra != rb) {
      TT_FAIL_("%s: row %ld exists in one file only", what, rows);
      break;
    }
    if (ra != SQLITE_ROW)
      break;
    int n = sqlite3_column_count(sa);
    CHECK_INT_EQ(n, sqlite3_column_count(sb));
    for (int c = 0; c < n; c++) {
      int ta = sqlite3_column_type(sa, c), tb = sqlite3_column_type(sb, c);
      int na = sqlite3_column_bytes(sa, c), nb = sqlite3_column_bytes(sb, c);
      int same = ta == tb && na == nb;
      if (same && ta == SQLITE_FLOAT)
        same = sqlite3_column_double(sa, c) == sqlite3_column_double(sb, c);
      else if (same && ta == SQLITE_INTEGER)
        same = sqlite3_column_int64(sa, c) == sqlite3_column_int64(sb, c);
      else if (same && ta == SQLITE_BLOB)
        same = memcmp(sqlite3_column_blob(sa, c),
                      sqlite3_column_blob(sb, c), (size_t)na) == 0;
      else if (same && ta == SQLITE_TEXT)
        same = strcmp((const char *)sqlite3_column_text(sa, c),
                      (const char *)sqlite3_column_text(sb, c)) == 0;
      if (!same) {
        TT_FAIL_("%s: row %ld column %s differs", what, rows,
                 sqlite3_column_name(sa, c));
        goto done;
      }
    }
  }
  CHECK(rows > 0);
done:
  sqlite3_finalize(sa);
  sqlite3_finalize(sb);
}

static long long scalar(sqlite3 *db, const char *query)
{
  sqlite3_stmt *st = NULL;
  long long v = -1;
  if (sqlite3_prepare_v2(db, query, -1, &st, NULL) == SQLITE_OK &&
      sqlite3_step(st) == SQLITE_ROW)
    v = sqlite3_column_int64(st, 0);
  sqlite3_finalize(st);
  return v;
}

static void text_is(sqlite3 *db, const char *query, const char *want)
{
  sqlite3_stmt *st = NULL;
  if (sqlite3_prepare_v2(db, query, -1, &st, NULL) == SQLITE_OK &&
      sqlite3_step(st) == SQLITE_ROW)
    CHECK_STR_EQ((const char *)sqlite3_column_text(st, 0), want);
  else
    TT_FAIL_("%s: %s", query, sqlite3_errmsg(db));
  sqlite3_finalize(st);
}

static void compare_files(const char *pa, const char *pb, const char *prefix,
                          const char *fid, const char *geom, int rtree,
                          unsigned layers)
{
  sqlite3 *a = db_open(pa), *b = db_open(pb);
  if (!a || !b)
    goto done;
  char q[512];
  for (int k = 0; k < 2; k++) {
    const char *layer = k ? "vertices" : "triangles";
    if (!(layers & (1u << k)))
      continue;
    snprintf(q, sizeof q, "SELECT * FROM \"%s%s\" ORDER BY \"%s\"", prefix,
             layer, fid);
    same_rows(a, b, q, layer);
    if (rtree) {
      static const char *const parts[] = {"", "_node", "_parent", "_rowid"};
      for (int p = 0; p < 4; p++) {
        snprintf(q, sizeof q, "SELECT * FROM \"rtree_%s%s_%s%s\" ORDER BY 1",
                 prefix, layer, geom, parts[p]);
        same_rows(a, b, q, q);
      }
    }
  }
  same_rows(a, b,
            "SELECT table_name, data_type, identifier, srs_id FROM "
            "gpkg_contents ORDER BY table_name",
            "gpkg_contents");
  /* The extents: ours is the exact box of the coordinates written; GDAL's
   * can differ in the last bits (36.44666666666665 for a least latitude of
   * 36.446666666666665 written). */
  for (int k = 0; k < 8; k++) {
    static const char *const col[] = {"min_x", "min_y", "max_x", "max_y"};
    if (!(layers & (1u << (k / 4))))
      continue;
    snprintf(q, sizeof q, "SELECT %s FROM gpkg_contents WHERE table_name = "
             "'%s%s'", col[k % 4], prefix, k < 4 ? "triangles" : "vertices");
    sqlite3_stmt *sa = NULL, *sb = NULL;
    if (sqlite3_prepare_v2(a, q, -1, &sa, NULL) == SQLITE_OK &&
        sqlite3_prepare_v2(b, q, -1, &sb, NULL) == SQLITE_OK &&
        sqlite3_step(sa) == SQLITE_ROW && sqlite3_step(sb) == SQLITE_ROW) {
      double va = sqlite3_column_double(sa, 0);
      double vb = sqlite3_column_double(sb, 0);
      CHECK_DBL_NEAR(va, vb, 1e-12 * (fabs(va) + 1));
    } else {
      TT_FAIL_("%s", q);
    }
    sqlite3_finalize(sa);
    sqlite3_finalize(sb);
  }
  same_rows(a, b, "SELECT * FROM gpkg_ogr_contents ORDER BY table_name",
            "gpkg_ogr_contents");
  same_rows(a, b, "SELECT * FROM sqlite_sequence ORDER BY name",
            "sqlite_sequence");
  same_rows(a, b, "SELECT * FROM gpkg_geometry_columns ORDER BY table_name",
            "gpkg_geometry_columns");
  same_rows(a, b,
            "SELECT type, name, tbl_name, sql FROM sqlite_master ORDER BY "
            "type, name",
            "schema");
  if (rtree)
    same_rows(a, b, "SELECT * FROM gpkg_extensions ORDER BY table_name",
              "gpkg_extensions");
  else
    CHECK_INT_EQ(scalar(b, "SELECT count(*) FROM sqlite_master WHERE name "
                           "LIKE 'rtree%'"),
                 0);
  text_is(b, "PRAGMA integrity_check", "ok");
  for (int k = 0; k < 2 && rtree; k++) {
    if (!(layers & (1u << k)))
      continue;
    snprintf(q, sizeof q, "SELECT rtreecheck('rtree_%s%s_%s')", prefix,
             k ? "vertices" : "triangles", geom);
    text_is(b, q, "ok");
  }
  /* The records byte for byte as long (with the same values: the same
   * encoding); the R-tree's only when the pages are alike. */
  for (int k = 0; k < 8; k++) {
    static const char *const parts[] = {"", "_node", "_parent", "_rowid"};
    if (!(layers & (1u << (k / 4))) || (k % 4 && !rtree))
      continue;
    if (k % 4 && scalar(a, "PRAGMA page_size") != scalar(b, "PRAGMA "
                                                          "page_size"))
      continue;
    const char *layer = k < 4 ? "triangles" : "vertices";
    if (k % 4)
      snprintf(q, sizeof q, "SELECT sum(payload) FROM dbstat WHERE name = "
               "'rtree_%s%s_%s%s'", prefix, layer, geom, parts[k % 4]);
    else
      snprintf(q, sizeof q, "SELECT sum(payload) FROM dbstat WHERE name = "
               "'%s%s'", prefix, layer);
    CHECK_INT_EQ(scalar(a, q), scalar(b, q));
  }
done:
  sqlite3_close(a);
  sqlite3_close(b);
}

/* Debug messages of the writer saying it did not write pages. */
static int not_pages = 0;

static void CPL_STDCALL on_message(CPLErr cls, CPLErrorNum num,
                                   const char *msg)
{
  (void)num;
  if (cls == CE_Debug && msg && strstr(msg, "not as pages"))
    not_pages++;
  else if (cls != CE_Debug)
    fprintf(stderr, "GDAL: %s\n", msg ? msg : "");
}

static int cmp_fid(const void *a, const void *b)
{
  long long x = *(const long long *)a, y = *(const long long *)b;
  return (x > y) - (x < y);
}

/* The fids of the features of l in the box, sorted: through the layer's
 * spatial filter (the R-tree: which = 0), or brute, from every feature's
 * envelope: those it meets (which = 1, edges included), those strictly
 * inside the box (which = 2). */
static long long *features_in(OGRLayerH l, const double box[4], int which,
                              size_t *n)
{
  if (which == 0)
    OGR_L_SetSpatialFilterRect(l, box[0], box[1], box[2], box[3]);
  else
    OGR_L_SetSpatialFilter(l, NULL);
  OGR_L_ResetReading(l);
  size_t cap = 64;
  long long *out = malloc(cap * sizeof *out);
  *n = 0;
  OGRFeatureH f;
  while ((f = OGR_L_GetNextFeature(l)) != NULL) {
    OGRGeometryH g = OGR_F_GetGeometryRef(f);
    int in = which == 0;
    if (which && g) {
      OGREnvelope e;
      OGR_G_GetEnvelope(g, &e);
      in = which == 1 ? e.MaxX >= box[0] && e.MinX <= box[2] &&
                            e.MaxY >= box[1] && e.MinY <= box[3]
                      : e.MinX > box[0] && e.MaxX < box[2] &&
                            e.MinY > box[1] && e.MaxY < box[3];
    }
    if (in) {
      if (*n == cap)
        out = realloc(out, (cap *= 2) * sizeof *out);
      out[(*n)++] = OGR_F_GetFID(f);
    }
    OGR_F_Destroy(f);
  }
  OGR_L_SetSpatialFilter(l, NULL);
  qsort(out, *n, sizeof *out, cmp_fid);
  return out;
}

/* Whether sorted a[0..na) lies in sorted b[0..nb). */
static int subset(const long long *a, size_t na, const long long *b,
                  size_t nb)
{
  size_t j = 0;
  for (size_t i = 0; i < na; i++) {
    while (j < nb && b[j] < a[i])
      j++;
    if (j == nb || b[j] != a[i])
      return 0;
  }
  return 1;
}

/* GDAL on the file written (path, the layers of the TIN in layers):
 * counts, extents, spatial filters against brute force and against the
 * reference file ref_path; then GDAL adds and deletes features, and SQLite
 * checks the file and the R-trees. */
static void gdal_checks(const char *path, const char *ref_path,
                        const tt_tin *tin, const char *prefix,
                        const char *geom, int rtree, unsigned layers)
{
  GDALDatasetH ds = GDALOpenEx(path, GDAL_OF_VECTOR, NULL, NULL, NULL);
  GDALDatasetH ref = GDALOpenEx(ref_path, GDAL_OF_VECTOR, NULL, NULL, NULL);
  CHECK(ds != NULL && ref != NULL);
  if (!ds)
    return;
  for (int k = 0; k < 2; k++) {
    if (!(layers & (1u << k)))
      continue;
    char name[64];
    snprintf(name, sizeof name, "%s%s", prefix, k ? "vertices" : "triangles");
    OGRLayerH l = GDALDatasetGetLayerByName(ds, name);
    CHECK(l != NULL);
    if (!l)
      continue;
    long long n = (long long)(k ? tt_tin_vertex_count(tin)
                                : tt_tin_triangle_count(tin));
    CHECK_INT_EQ(OGR_L_GetFeatureCount(l, TRUE), n);
    OGREnvelope env;
    CHECK(OGR_L_GetExtent(l, &env, FALSE) == OGRERR_NONE);
    CHECK(env.MinX < env.MaxX && env.MinY < env.MaxY);
    CHECK_INT_EQ(OGR_L_TestCapability(l, OLCFastSpatialFilter) != 0, rtree);
    /* boxes: one on the left edge, the middle, a thin strip, a tiny one,
     * and the
     * whole extent; what the filter returns lies between the features
     * inside the box and those whose envelope meets it, and is what it
     * returns on the reference file */
    const double w = env.MaxX - env.MinX, h = env.MaxY - env.MinY;
    const double boxes[5][4] = {
        {env.MinX, env.MinY + 0.4 * h, env.MinX + 0.3 * w,
         env.MinY + 0.7 * h},
        {env.MinX + 0.4 * w, env.MinY + 0.35 * h, env.MinX + 0.6 * w,
         env.MinY + 0.55 * h},
        {env.MinX + 0.5 * w, env.MinY, env.MinX + 0.5001 * w, env.MaxY},
        {env.MinX + 0.3 * w, env.MinY + 0.7 * h, env.MinX + 0.301 * w,
         env.MinY + 0.701 * h},
        {env.MinX - 1, env.MinY - 1, env.MaxX + 1, env.MaxY + 1}};
    OGRLayerH rl = ref ? GDALDatasetGetLayerByName(ref, name) : NULL;
    for (int b = 0; b < 5; b++) {
      size_t nf = 0, nm = 0, ni = 0, nr = 0;
      long long *ff = features_in(l, boxes[b], 0, &nf);
      long long *fm = features_in(l, boxes[b], 1, &nm);
      long long *fi = features_in(l, boxes[b], 2, &ni);
      CHECK(subset(fi, ni, ff, nf));
      CHECK(subset(ff, nf, fm, nm));
      if (b < 2 && !(nf > 0 && (b == 0 || ni > 0) && (long long)nm < n))
        TT_FAIL_("%s box %d: %zu inside, %zu filtered, %zu meet, of %lld",
                 name, b, ni, nf, nm, n);
      if (b == 4)
        CHECK_INT_EQ(nf, n);
      if (rl) {
        long long *fr = features_in(rl, boxes[b], 0, &nr);
        CHECK(nr == nf && (nf == 0 || memcmp(ff, fr, nf * sizeof *ff) == 0));
        free(fr);
      }
      free(ff);
      free(fm);
      free(fi);
    }
  }
  if (ref)
    GDALClose(ref);
  GDALClose(ds);

  /* GDAL adds and deletes features: SQLite's triggers keep the counts and
   * the R-trees, the fids go on after the last one written. */
  ds = GDALOpenEx(path, GDAL_OF_VECTOR | GDAL_OF_UPDATE, NULL, NULL, NULL);
  CHECK(ds != NULL);
  if (!ds)
    return;
  long long count[2] = {0, 0};
  for (int k = 0; k < 2; k++) {
    if (!(layers & (1u << k)))
      continue;
    char name[64];
    snprintf(name, sizeof name, "%s%s", prefix, k ? "vertices" : "triangles");
    OGRLayerH l = GDALDatasetGetLayerByName(ds, name);
    if (!l)
      continue;
    long long n = OGR_L_GetFeatureCount(l, TRUE);
    for (int i = 1; i <= 3; i++) {
      OGRFeatureH f = OGR_L_GetFeature(l, i);
      CHECK(f != NULL);
      if (!f)
        continue;
      OGR_F_SetFID(f, OGRNullFID);
      CHECK(OGR_L_CreateFeature(l, f) == OGRERR_NONE);
      CHECK_INT_EQ(OGR_F_GetFID(f), n + i);
      OGR_F_Destroy(f);
    }
    CHECK(OGR_L_DeleteFeature(l, 2) == OGRERR_NONE);
    CHECK(OGR_L_DeleteFeature(l, n / 2) == OGRERR_NONE);
    count[k] = n + 1;
  }
  GDALClose(ds);
  sqlite3 *db = db_open(path);
  text_is(db, "PRAGMA integrity_check", "ok");
  char q[256];
  for (int k = 0; k < 2; k++) {
    if (!(layers & (1u << k)))
      continue;
    const char *layer = k ? "vertices" : "triangles";
    snprintf(q, sizeof q, "SELECT count(*) FROM \"%s%s\"", prefix, layer);
    CHECK_INT_EQ(scalar(db, q), count[k]);
    snprintf(q, sizeof q, "SELECT feature_count FROM gpkg_ogr_contents WHERE "
             "table_name = '%s%s'", prefix, layer);
    CHECK_INT_EQ(scalar(db, q), count[k]);
    if (rtree) {
      snprintf(q, sizeof q, "SELECT rtreecheck('rtree_%s%s_%s')", prefix,
               layer, geom);
      text_is(db, q, "ok");
      snprintf(q, sizeof q, "SELECT count(*) FROM \"rtree_%s%s_%s\"", prefix,
               layer, geom);
      CHECK_INT_EQ(scalar(db, q), count[k]);
    }
  }
  sqlite3_close(db);
}

/* The TIN written by OGR (or, with small pages, by the SQL path) and by
 * the row writer through SQLite and as pages: the same files. */
static void one_case(tt_context *ctx, const tt_tin *tin,
                     OGRSpatialReferenceH srs, char **opts,
                     const char *prefix, const char *fid, const char *geom,
                     int rtree)
{
  unsigned layers = 3;
  const char *lv = CSLFetchNameValue(opts, "LAYERS");
  if (lv && !strstr(lv, "vertices"))
    layers = 1;
  else if (lv && !strstr(lv, "triangles"))
    layers = 2;
  char pa[320], pb[320], pc[320];
  snprintf(pa, sizeof pa, "%s/ogr.gpkg", tmpdir);
  snprintf(pb, sizeof pb, "%s/direct.gpkg", tmpdir);
  snprintf(pc, sizeof pc, "%s/pages.gpkg", tmpdir);
  stopper never = {0, 0}, never2 = {0, 0};
  if (page_size) /* the reference: the SQL path on the same pages */
    CHECK_OK(ctx, write_gpkg(ctx, tin, pa, srs, opts, 1, rtree, NULL));
  else
    write_gpkg(ctx, tin, pa, srs, opts, 0, rtree, NULL);
  if (!page_size) {
    CHECK_OK(ctx, write_gpkg(ctx, tin, pb, srs, opts, 1, rtree, &never));
    CHECK(never.calls > 2);
    compare_files(pa, pb, prefix, fid, geom, rtree, layers);
  }
  char **po = CSLSetNameValue(CSLDuplicate(opts), "PAGES", "YES");
  int before = not_pages;
  CHECK_OK(ctx, write_gpkg(ctx, tin, pc, srs, po, 1, rtree, &never2));
  CSLDestroy(po);
  CHECK_INT_EQ(not_pages, before); /* the pages were written */
  CHECK(never2.calls > 2);
  compare_files(pa, pc, prefix, fid, geom, rtree, layers);
  gdal_checks(pc, pa, tin, prefix, geom, rtree, layers);
}

/* Interrupted at the first, a middle and a late progress call of a write
 * with opts: a sound file with empty layers and no index. */
static void stops(tt_context *ctx, const tt_tin *tin,
                  OGRSpatialReferenceH srs, char **opts)
{
  char path[320];
  snprintf(path, sizeof path, "%s/stop.gpkg", tmpdir);
  stopper count = {0, 0};
  CHECK_OK(ctx, write_gpkg(ctx, tin, path, srs, opts, 1, 1, &count));
  const int at[] = {1, 2, count.calls / 3, count.calls / 2, count.calls - 1};
  for (int k = 0; k < 5; k++) {
    stopper st = {0, at[k]};
    CHECK_INT_EQ(write_gpkg(ctx, tin, path, srs, opts, 1, 1, &st),
                 TT_ERR_INTERRUPTED);
    sqlite3 *db = db_open(path);
    text_is(db, "PRAGMA integrity_check", "ok");
    CHECK_INT_EQ(scalar(db, "SELECT count(*) FROM triangles"), 0);
    CHECK_INT_EQ(scalar(db, "SELECT count(*) FROM vertices"), 0);
    CHECK_INT_EQ(scalar(db, "SELECT count(*) FROM sqlite_master WHERE name "
                            "LIKE 'rtree%'"), 0);
    /* no R-tree registered (the fields' descriptions are, by OGR's write) */
    CHECK_INT_EQ(scalar(db, "SELECT count(*) FROM gpkg_extensions WHERE "
                            "extension_name = 'gpkg_rtree_index'"), 0);
    /* the feature-count triggers are there */
    CHECK_INT_EQ(scalar(db, "SELECT count(*) FROM sqlite_master WHERE type "
                            "= 'trigger' AND name LIKE '%feature_count%'"),
                 6);
    sqlite3_close(db);
    /* and it can still be written */
    if (k == 2)
      CHECK_OK(ctx, tt_gpkg_write_rows(ctx, path, tin, srs, opts, NULL,
                                       NULL));
  }
}

int main(void)
{
  GDALAllRegister();
  CPLSetErrorHandler(on_message);
  CPLSetConfigOption("CPL_DEBUG", "ON");
  snprintf(tmpdir, sizeof tmpdir, "%s/tt_gpkg_rows_XXXXXX",
           getenv("TMPDIR") ? getenv("TMPDIR") : "/tmp");
  if (!mkdtemp(tmpdir)) {
    fprintf(stderr, "cannot make a temporary folder\n");
    return 1;
  }
  tt_context *ctx = tt_context_create();
  tt_tin *tin = make_tin(ctx, 0.2);
  CHECK(tin && tt_tin_triangle_count(tin) > 500);
  OGRSpatialReferenceH srs = OSRNewSpatialReference(NULL);
  OSRImportFromEPSG(srs, 32633);
  OSRSetAxisMappingStrategy(srs, OAMS_TRADITIONAL_GIS_ORDER);

  /* A projected CRS, defaults. */
  one_case(ctx, tin, srs, NULL, "", "fid", "geom", 1);
  /* T_SRS geographic: transformed vertices, geodesic areas. */
  char **o = CSLSetNameValue(NULL, "T_SRS", "EPSG:4326");
  one_case(ctx, tin, srs, o, "", "fid", "geom", 1);
  CSLDestroy(o);
  /* A prefix, another fid and geometry column; and no index at all. */
  o = CSLSetNameValue(NULL, "NLN_PREFIX", "x_");
  o = CSLAddNameValue(o, "LCO", "FID=id");
  o = CSLAddNameValue(o, "LCO", "GEOMETRY_NAME=shape");
  one_case(ctx, tin, srs, o, "x_", "id", "shape", 1);
  o = CSLAddNameValue(o, "LCO", "SPATIAL_INDEX=NO");
  one_case(ctx, tin, NULL, o, "x_", "id", "shape", 0);
  CSLDestroy(o);
  /* One layer only. */
  o = CSLSetNameValue(NULL, "LAYERS", "triangles,run_parameters");
  one_case(ctx, tin, srs, o, "", "fid", "geom", 1);
  CSLDestroy(o);
  o = CSLSetNameValue(NULL, "LAYERS", "vertices");
  one_case(ctx, tin, srs, o, "", "fid", "geom", 1);
  CSLDestroy(o);
  /* A decimated TIN: importance, ins_err and ins_rank NULL. */
  tt_tin *dtin = make_dtin(ctx, 0.5);
  CHECK(dtin && tt_tin_triangle_count(dtin) > 200);
  one_case(ctx, dtin, srs, NULL, "", "fid", "geom", 1);
  o = CSLSetNameValue(NULL, "T_SRS", "EPSG:3857");
  one_case(ctx, dtin, srs, o, "", "fid", "geom", 1);
  CSLDestroy(o);
  tt_tin_destroy(dtin);
  /* The rows made on the SQLite thread (THREADS=1) and, for a TIN of many
   * chunks of rows, by the second thread. */
  o = CSLSetNameValue(NULL, "THREADS", "1");
  one_case(ctx, tin, srs, o, "", "fid", "geom", 1);
  CSLDestroy(o);
  tt_tin *fine = make_tin(ctx, 0.0);
  CHECK(fine && tt_tin_triangle_count(fine) > 4000);
  one_case(ctx, fine, srs, NULL, "", "fid", "geom", 1);
  o = CSLSetNameValue(NULL, "THREADS", "1");
  one_case(ctx, fine, srs, o, "", "fid", "geom", 1);
  CSLDestroy(o);
  o = CSLSetNameValue(NULL, "JOURNAL", "MEMORY");
  one_case(ctx, fine, srs, o, "", "fid", "geom", 1);
  CSLDestroy(o);
  /* Small pages: the triangles' B-tree of three levels at 512 bytes, two
   * tables of two interior levels at 1,024 with 24 reserved bytes. */
  page_size = 512;
  one_case(ctx, fine, srs, NULL, "", "fid", "geom", 1);
  page_size = 1024;
  page_reserve = 24;
  o = CSLSetNameValue(NULL, "T_SRS", "EPSG:4326");
  one_case(ctx, fine, srs, o, "", "fid", "geom", 1);
  CSLDestroy(o);
  {
    char p[320];
    snprintf(p, sizeof p, "%s/pages.gpkg", tmpdir);
    sqlite3 *db = db_open(p);
    CHECK_INT_EQ(scalar(db, "SELECT max(length(path) - length(replace(path, "
                            "'/', ''))) FROM dbstat WHERE name = "
                            "'triangles'"),
                 3);
    sqlite3_close(db);
  }
  page_size = page_reserve = 0;

  /* Interrupted at the first, a middle and a late progress call: rolled
   * back, a sound file with empty layers and no index; through SQLite and
   * as pages, with the rows made by a second thread or not, the journal in
   * memory or not. */
  for (int k = 0; k < 6; k++) {
    char **so = k >= 3 ? CSLSetNameValue(NULL, "PAGES", "YES") : NULL;
    if (k % 3 == 1)
      so = CSLSetNameValue(so, "THREADS", "1");
    if (k % 3 == 2)
      so = CSLSetNameValue(so, "JOURNAL", "MEMORY");
    stops(ctx, k % 3 == 0 ? tin : fine, srs, so);
    CSLDestroy(so);
  }
  tt_tin_destroy(fine);

  /* Rows already there: refused, nothing changed. */
  char path[320];
  snprintf(path, sizeof path, "%s/stop.gpkg", tmpdir);
  CHECK_OK(ctx, write_gpkg(ctx, tin, path, srs, NULL, 1, 1, NULL));
  for (int k = 0; k < 2; k++) {
    char **ro = k ? CSLSetNameValue(NULL, "PAGES", "YES") : NULL;
    CHECK_INT_EQ(tt_gpkg_write_rows(ctx, path, tin, srs, ro, NULL, NULL),
                 TT_ERR_ARG);
    CSLDestroy(ro);
    CHECK(strstr(tt_context_errmsg(ctx), "already has rows") != NULL);
  }
  sqlite3 *db = db_open(path);
  CHECK_INT_EQ(scalar(db, "SELECT count(*) FROM triangles"),
               (long long)tt_tin_triangle_count(tin));
  text_is(db, "PRAGMA integrity_check", "ok");
  sqlite3_close(db);

  /* A database PAGES=YES cannot take (WAL): the rows through SQLite, the
   * same file. */
  {
    char pa[320], pb[320];
    snprintf(pa, sizeof pa, "%s/ogr.gpkg", tmpdir);
    snprintf(pb, sizeof pb, "%s/wal.gpkg", tmpdir);
    write_gpkg(ctx, tin, pa, srs, NULL, 0, 1, NULL);
    unlink(pb);
    GDALDatasetH ds = GDALCreate(GDALGetDriverByName("GPKG"), pb, 0, 0, 0,
                                 GDT_Unknown, NULL);
    char **wo = CSLSetNameValue(NULL, "ROWS", "DEFERRED");
    CHECK_OK(ctx, tt_ogr_write_tin(ctx, ds, tin, srs, run_fields, 2, wo,
                                   NULL, NULL));
    GDALClose(ds);
    db = NULL;
    CHECK(sqlite3_open(pb, &db) == SQLITE_OK);
    text_is(db, "PRAGMA journal_mode = WAL", "wal");
    sqlite3_close(db);
    wo = CSLSetNameValue(wo, "PAGES", "YES");
    int before = not_pages;
    CHECK_OK(ctx, tt_gpkg_write_rows(ctx, pb, tin, srs, wo, NULL, NULL));
    CHECK_INT_EQ(not_pages, before + 1);
    CSLDestroy(wo);
    compare_files(pa, pb, "", "fid", "geom", 1, 3);
  }

  /* ROWS=DEFERRED is for GeoPackages only. */
  snprintf(path, sizeof path, "%s/shp", tmpdir);
  GDALDatasetH ds = GDALCreate(GDALGetDriverByName("ESRI Shapefile"), path,
                               0, 0, 0, GDT_Unknown, NULL);
  char **ro = CSLSetNameValue(NULL, "ROWS", "DEFERRED");
  CHECK_INT_EQ(tt_ogr_write_tin(ctx, ds, tin, srs, run_fields, 2, ro, NULL,
                                NULL),
               TT_ERR_ARG);
  CSLDestroy(ro);
  GDALClose(ds);

  OSRDestroySpatialReference(srs);
  tt_tin_destroy(tin);
  tt_context_destroy(ctx);
  char cmd[300];
  snprintf(cmd, sizeof cmd, "rm -rf '%s'", tmpdir);
  if (system(cmd) != 0)
    fprintf(stderr, "could not remove %s\n", tmpdir);
  TT_TEST_DONE();
}
