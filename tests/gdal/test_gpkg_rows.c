/*
 * test_gpkg_rows.c -- tt_gpkg_write_rows(), the direct GeoPackage row
 * writer, against the OGR writer it replaces for GPKG: the same TIN written
 * both ways (rows through OGR plus tt_gpkg_build_rtree() on the closed file,
 * and ROWS=DEFERRED plus tt_gpkg_write_rows()) must give the same files row
 * for row: every column of the triangles and vertices tables (geometry
 * blobs byte for byte), gpkg_contents (extents; not last_change),
 * gpkg_ogr_contents, gpkg_geometry_columns, gpkg_extensions, the R-tree's
 * virtual and shadow tables, and the schema (tables, triggers, their SQL).
 * Cases: a projected CRS; T_SRS to a geographic CRS (geodesic areas); a
 * layer prefix with a renamed fid and geometry column; no spatial index;
 * the rows made on the SQLite thread (THREADS=1) or by a second thread,
 * for a TIN of one chunk of rows and one of several.
 * Then: PRAGMA integrity_check and rtreecheck() pass, GDAL opens the file
 * with the counts and extent; an interruption at any point rolls back to
 * empty layers in a sound file; a second write and a non-GPKG dataset are
 * refused.
 */
#include "terratin/terratin_gdal.h"
#include "tt_test.h"

#include <cpl_string.h>
#include <ogr_srs_api.h>

#include <sqlite3.h>

#include <stdlib.h>
#include <unistd.h>

static char tmpdir[256];

/* A 60 x 45 grid in UTM 33N, 10 m pixels: a plane, a bump, a flat shelf
 * (flat triangles have no aspect: NULL) and a nodata corner. */
static tt_tin *make_tin(tt_context *ctx, double max_error)
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
  tt_refine_options opt;
  tt_refine_options_init(&opt);
  opt.max_error = max_error;
  tt_tin *tin = NULL;
  CHECK_OK(ctx, tt_refine_run(ctx, g, &opt, &tin));
  tt_grid_destroy(g);
  return tin;
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
    for (int k = 0; k < 2; k++) {
      char layer[64];
      snprintf(layer, sizeof layer, "%s%s", prefix,
               k ? "vertices" : "triangles");
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
                          const char *fid, const char *geom, int rtree)
{
  sqlite3 *a = db_open(pa), *b = db_open(pb);
  if (!a || !b)
    goto done;
  char q[512];
  for (int k = 0; k < 2; k++) {
    const char *layer = k ? "vertices" : "triangles";
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
  for (int k = 0; k < 4; k++) {
    static const char *const col[] = {"min_x", "min_y", "max_x", "max_y"};
    snprintf(q, sizeof q, "SELECT %s FROM gpkg_contents WHERE table_name = "
             "'%striangles'", col[k], prefix);
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
  if (rtree) {
    snprintf(q, sizeof q, "SELECT rtreecheck('rtree_%striangles_%s')", prefix,
             geom);
    text_is(b, q, "ok");
  }
done:
  sqlite3_close(a);
  sqlite3_close(b);
}

static void one_case(tt_context *ctx, const tt_tin *tin,
                     OGRSpatialReferenceH srs, char **opts,
                     const char *prefix, const char *fid, const char *geom,
                     int rtree)
{
  char pa[320], pb[320];
  snprintf(pa, sizeof pa, "%s/ogr.gpkg", tmpdir);
  snprintf(pb, sizeof pb, "%s/direct.gpkg", tmpdir);
  stopper never = {0, 0};
  write_gpkg(ctx, tin, pa, srs, opts, 0, rtree, NULL);
  CHECK_OK(ctx, write_gpkg(ctx, tin, pb, srs, opts, 1, rtree, &never));
  CHECK(never.calls > 2);
  compare_files(pa, pb, prefix, fid, geom, rtree);

  /* GDAL reads the result as it reads its own. */
  GDALDatasetH ds = GDALOpenEx(pb, GDAL_OF_VECTOR, NULL, NULL, NULL);
  CHECK(ds != NULL);
  char name[64];
  snprintf(name, sizeof name, "%striangles", prefix);
  OGRLayerH l = ds ? GDALDatasetGetLayerByName(ds, name) : NULL;
  CHECK(l != NULL);
  if (l) {
    CHECK_INT_EQ(OGR_L_GetFeatureCount(l, TRUE),
                 (long long)tt_tin_triangle_count(tin));
    OGREnvelope env;
    CHECK(OGR_L_GetExtent(l, &env, FALSE) == OGRERR_NONE);
    CHECK(env.MinX < env.MaxX && env.MinY < env.MaxY);
  }
  if (ds)
    GDALClose(ds);
}

int main(void)
{
  GDALAllRegister();
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

  /* Interrupted at the first, a middle and a late progress call: rolled
   * back, a sound file with empty layers and no index. */
  char path[320];
  snprintf(path, sizeof path, "%s/stop.gpkg", tmpdir);
  stopper count = {0, 0};
  CHECK_OK(ctx, write_gpkg(ctx, tin, path, srs, NULL, 1, 1, &count));
  const int stops[] = {1, count.calls / 2, count.calls - 1};
  for (int k = 0; k < 3; k++) {
    stopper st = {0, stops[k]};
    CHECK_INT_EQ(write_gpkg(ctx, tin, path, srs, NULL, 1, 1, &st),
                 TT_ERR_INTERRUPTED);
    sqlite3 *db = db_open(path);
    text_is(db, "PRAGMA integrity_check", "ok");
    CHECK_INT_EQ(scalar(db, "SELECT count(*) FROM triangles"), 0);
    CHECK_INT_EQ(scalar(db, "SELECT count(*) FROM vertices"), 0);
    CHECK_INT_EQ(scalar(db, "SELECT count(*) FROM sqlite_master WHERE name "
                            "LIKE 'rtree%'"),
                 0);
    /* the feature-count triggers are back */
    CHECK_INT_EQ(scalar(db, "SELECT count(*) FROM sqlite_master WHERE type "
                            "= 'trigger' AND name LIKE '%feature_count%'"),
                 6);
    sqlite3_close(db);
  }

  /* The fine TIN stopped in its rows while the second thread makes them
   * (and with THREADS=1, and with the journal in memory): the same
   * roll-back. */
  stopper fcount = {0, 0};
  CHECK_OK(ctx, write_gpkg(ctx, fine, path, srs, NULL, 1, 1, &fcount));
  for (int k = 0; k < 3; k++) {
    char **to = k == 1   ? CSLSetNameValue(NULL, "THREADS", "1")
                : k == 2 ? CSLSetNameValue(NULL, "JOURNAL", "MEMORY")
                         : NULL;
    stopper st = {0, fcount.calls / 3};
    CHECK_INT_EQ(write_gpkg(ctx, fine, path, srs, to, 1, 1, &st),
                 TT_ERR_INTERRUPTED);
    CSLDestroy(to);
    sqlite3 *db = db_open(path);
    text_is(db, "PRAGMA integrity_check", "ok");
    CHECK_INT_EQ(scalar(db, "SELECT count(*) FROM triangles"), 0);
    CHECK_INT_EQ(scalar(db, "SELECT count(*) FROM vertices"), 0);
    sqlite3_close(db);
  }
  tt_tin_destroy(fine);

  /* Rows already there: refused, nothing changed. */
  CHECK_OK(ctx, write_gpkg(ctx, tin, path, srs, NULL, 1, 1, NULL));
  CHECK_INT_EQ(tt_gpkg_write_rows(ctx, path, tin, srs, NULL, NULL, NULL),
               TT_ERR_ARG);
  CHECK(strstr(tt_context_errmsg(ctx), "already has rows") != NULL);
  sqlite3 *db = db_open(path);
  CHECK_INT_EQ(scalar(db, "SELECT count(*) FROM triangles"),
               (long long)tt_tin_triangle_count(tin));
  sqlite3_close(db);

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
