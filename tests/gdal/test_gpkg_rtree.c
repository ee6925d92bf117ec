/*
 * test_gpkg_rtree.c -- tt_gpkg_build_rtree() against SQLite and GDAL, no
 * mocks. TINs from tt_refine_run() on synthetic grids (large, fractional
 * map coordinates so the float rounding matters) are written with
 * tt_ogr_write_tin() without an index; copies are cut to 0, 1, one full
 * node, one more, a full two-level tree and one more features, some
 * geometries set NULL or empty; then, after the build:
 *   - SQLite: rtreecheck() and PRAGMA integrity_check say ok; the root's
 *     depth is what the count implies;
 *   - every indexed fid is there once, with a box holding the geometry's
 *     true bounds (read by OGR) within two float steps; NULL and empty
 *     geometries are absent;
 *   - window queries through the R-tree return exactly the rows a
 *     brute-force box test over the stored rows finds (random windows, the
 *     seed printed; TT_SEED=<n> replays);
 *   - GDAL reopens it: OLCFastSpatialFilter, and spatial filters count what
 *     GDAL counts on the unindexed file (and, for points, an exact test);
 *   - the rows equal those GDAL's CreateSpatialIndex() writes;
 *   - the seven triggers follow inserts, updates (geometry moved, set NULL,
 *     set again, fid changed) and deletes made through OGR and SQL;
 *   - refusals (already indexed, no such table or file, malformed blob,
 *     interruption) leave the file byte for byte as it was;
 *   - the terratin command's GPKG output carries valid R-trees (with -nln),
 *     and none with -lco SPATIAL_INDEX=NO.
 */
#include "terratin/terratin_gdal.h"
#include "tt_test.h"
#include "tt_test_sqlite.h"

#include <cpl_conv.h>
#include <cpl_string.h>
#include <sqlite3.h>

#include <stdint.h>
#include <stdlib.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

static char tmpdir[256];
static uint64_t rng_state;

static uint64_t rng_next(void)
{
  return tt_test_rand(&rng_state);
}

static double rng_unit(void)
{
  return tt_test_uniform(&rng_state);
}

/* A path in the test folder; valid for the next 63 calls (callers that keep
 * one longer copy it). */
static const char *tmp_path(const char *name)
{
  static char buf[64][512];
  static int k;
  k = (k + 1) % 64;
  snprintf(buf[k], sizeof buf[k], "%s/%s", tmpdir, name);
  return buf[k];
}

/* --- files -------------------------------------------------------------- */

static void copy_file(const char *src, const char *dst)
{
  size_t n = 0;
  unsigned char *p = slurp(src, &n);
  CHECK(p != NULL);
  FILE *f = fopen(dst, "wb");
  CHECK(f != NULL);
  if (f && p)
    CHECK(fwrite(p, 1, n, f) == n);
  if (f)
    fclose(f);
  free(p);
}

static int same_file(const char *path, const unsigned char *p, size_t n)
{
  size_t m = 0;
  unsigned char *q = slurp(path, &m);
  int same = q && m == n && memcmp(p, q, n) == 0;
  free(q);
  return same;
}

/* --- TINs --------------------------------------------------------------- */

static tt_tin *make_tin(tt_context *ctx, size_t nx, size_t ny,
                        double max_error)
{
  float *z = malloc(nx * ny * sizeof *z);
  for (size_t r = 0; r < ny; r++)
    for (size_t c = 0; c < nx; c++) {
      double x = (double)c / 7.0, y = (double)r / 5.0;
      z[r * nx + c] = (float)(20 * sin(x) * cos(y) + 3 * sin(3.1 * x + y) +
                              0.05 * (double)(c * r % 17));
    }
  tt_grid *g = NULL;
  CHECK_OK(ctx, tt_grid_create_from_floats(ctx, nx, ny, z, &g));
  free(z);
  /* UTM-like origin, pixels of no binary fraction: floats must round. */
  const double gt[6] = {412345.678, 0.37, 0, 5123456.789, 0, -0.41};
  CHECK_OK(ctx, tt_grid_set_geotransform(ctx, g, gt));
  tt_refine_options opt;
  tt_refine_options_init(&opt);
  opt.max_error = max_error;
  tt_tin *tin = NULL;
  CHECK_OK(ctx, tt_refine_run(ctx, g, &opt, &tin));
  tt_grid_destroy(g);
  return tin;
}

/* Writes tin as a new GPKG at path; extra write options (e.g. no index). */
static void write_gpkg(tt_context *ctx, const tt_tin *tin, const char *path,
                       const char *opt1, const char *opt2)
{
  unlink(path);
  GDALDatasetH ds = GDALCreate(GDALGetDriverByName("GPKG"), path, 0, 0, 0,
                               GDT_Unknown, NULL);
  CHECK(ds != NULL);
  if (!ds)
    return;
  OGRSpatialReferenceH srs = OSRNewSpatialReference(NULL);
  OSRImportFromEPSG(srs, 32633);
  const tt_run_field f[] = {{"note", TT_FIELD_STRING, "rtree test", 0, 0}};
  char **opts = NULL;
  if (opt1)
    opts = CSLAddString(opts, opt1);
  if (opt2)
    opts = CSLAddString(opts, opt2);
  CHECK_OK(ctx, tt_ogr_write_tin(ctx, ds, tin, srs, f, 1, opts, NULL, NULL));
  CSLDestroy(opts);
  OSRDestroySpatialReference(srs);
  GDALClose(ds);
}

static void write_unindexed(tt_context *ctx, const tt_tin *tin,
                            const char *path)
{
  write_gpkg(ctx, tin, path, "LCO=SPATIAL_INDEX=NO", NULL);
}

/* --- what the index must hold ------------------------------------------- */

typedef struct row {
  int64_t id;
  double b[4]; /* minx maxx miny maxy */
} row;

static int cmp_row(const void *pa, const void *pb)
{
  const row *a = pa, *b = pb;
  return (a->id > b->id) - (a->id < b->id);
}

static int cmp_i64(const void *pa, const void *pb)
{
  int64_t a = *(const int64_t *)pa, b = *(const int64_t *)pb;
  return (a > b) - (a < b);
}

/* The true bounds of every non-NULL, non-empty geometry, read by OGR. */
static row *ogr_bounds(const char *path, const char *layer, size_t *out_n)
{
  GDALDatasetH ds = GDALOpenEx(path, GDAL_OF_VECTOR, NULL, NULL, NULL);
  CHECK(ds != NULL);
  *out_n = 0;
  if (!ds)
    return NULL;
  OGRLayerH l = GDALDatasetGetLayerByName(ds, layer);
  CHECK(l != NULL);
  size_t n = 0, cap = 1024;
  row *rows = malloc(cap * sizeof *rows);
  OGRFeatureH f;
  OGR_L_ResetReading(l);
  while (l && (f = OGR_L_GetNextFeature(l)) != NULL) {
    OGRGeometryH g = OGR_F_GetGeometryRef(f);
    if (g && !OGR_G_IsEmpty(g)) {
      OGREnvelope e;
      OGR_G_GetEnvelope(g, &e);
      if (n == cap)
        rows = realloc(rows, (cap *= 2) * sizeof *rows);
      rows[n].id = OGR_F_GetFID(f);
      rows[n].b[0] = e.MinX;
      rows[n].b[1] = e.MaxX;
      rows[n].b[2] = e.MinY;
      rows[n].b[3] = e.MaxY;
      n++;
    }
    OGR_F_Destroy(f);
  }
  GDALClose(ds);
  qsort(rows, n, sizeof *rows, cmp_row);
  *out_n = n;
  return rows;
}

/* The rows of rtree_<layer>_geom, by id. */
static row *rtree_rows(sqlite3 *db, const char *layer, size_t *out_n)
{
  char sql[256];
  snprintf(sql, sizeof sql, "SELECT id, minx, maxx, miny, maxy FROM "
           "\"rtree_%s_geom\" ORDER BY id", layer);
  sqlite3_stmt *st = NULL;
  *out_n = 0;
  if (sqlite3_prepare_v2(db, sql, -1, &st, NULL) != SQLITE_OK) {
    TT_FAIL_("%s: %s", sql, sqlite3_errmsg(db));
    return NULL;
  }
  size_t n = 0, cap = 1024;
  row *rows = malloc(cap * sizeof *rows);
  while (sqlite3_step(st) == SQLITE_ROW) {
    if (n == cap)
      rows = realloc(rows, (cap *= 2) * sizeof *rows);
    rows[n].id = sqlite3_column_int64(st, 0);
    for (int k = 0; k < 4; k++)
      rows[n].b[k] = sqlite3_column_double(st, 1 + k);
    n++;
  }
  sqlite3_finalize(st);
  *out_n = n;
  return rows;
}

/* Two float steps at v: the most outward rounding may move a bound. */
static double two_float_steps(double v)
{
  double a = fabs(v);
  return a < 1e-30 ? 1e-37 : 2 * ldexp(1.0, ilogb(a) - 23);
}

/* Window queries through the index against a brute-force box test. */
static void check_windows(sqlite3 *db, const char *layer, const row *rows,
                          size_t n, int nwin)
{
  if (n == 0)
    return;
  double ext[4] = {rows[0].b[0], rows[0].b[1], rows[0].b[2], rows[0].b[3]};
  for (size_t i = 1; i < n; i++) {
    ext[0] = fmin(ext[0], rows[i].b[0]);
    ext[1] = fmax(ext[1], rows[i].b[1]);
    ext[2] = fmin(ext[2], rows[i].b[2]);
    ext[3] = fmax(ext[3], rows[i].b[3]);
  }
  char sql[256];
  snprintf(sql, sizeof sql, "SELECT id FROM \"rtree_%s_geom\" WHERE minx "
           "<= ?1 AND maxx >= ?2 AND miny <= ?3 AND maxy >= ?4", layer);
  sqlite3_stmt *st = NULL;
  if (sqlite3_prepare_v2(db, sql, -1, &st, NULL) != SQLITE_OK) {
    TT_FAIL_("%s: %s", sql, sqlite3_errmsg(db));
    return;
  }
  int64_t *got = malloc((n + 1) * sizeof *got);
  int64_t *want = malloc((n + 1) * sizeof *want);
  double w = ext[1] - ext[0] + 1, h = ext[3] - ext[2] + 1;
  for (int q = 0; q < nwin; q++) {
    double x0, x1, y0, y1;
    if (q % 10 == 9) { /* a window that is one stored corner */
      const row *r = &rows[rng_next() % n];
      x0 = x1 = r->b[0];
      y0 = y1 = r->b[3];
    } else {
      double sw = w * pow(10, -3.5 * rng_unit()), sh = h *
                  pow(10, -3.5 * rng_unit());
      x0 = ext[0] - 0.1 * w + 1.2 * w * rng_unit() - sw / 2;
      y0 = ext[2] - 0.1 * h + 1.2 * h * rng_unit() - sh / 2;
      x1 = x0 + sw;
      y1 = y0 + sh;
    }
    size_t ng = 0, nw = 0;
    sqlite3_bind_double(st, 1, x1);
    sqlite3_bind_double(st, 2, x0);
    sqlite3_bind_double(st, 3, y1);
    sqlite3_bind_double(st, 4, y0);
    while (sqlite3_step(st) == SQLITE_ROW && ng <= n)
      got[ng++] = sqlite3_column_int64(st, 0);
    sqlite3_reset(st);
    for (size_t i = 0; i < n; i++)
      if (rows[i].b[0] <= x1 && rows[i].b[1] >= x0 && rows[i].b[2] <= y1 &&
          rows[i].b[3] >= y0)
        want[nw++] = rows[i].id;
    qsort(got, ng, sizeof *got, cmp_i64);
    int same = ng == nw && memcmp(got, want, ng * sizeof *got) == 0;
    if (!same)
      TT_FAIL_("%s window %d [%.17g %.17g] x [%.17g %.17g]: index gives "
               "%zu rows, brute force %zu", layer, q, x0, x1, y0, y1, ng, nw);
  }
  free(got);
  free(want);
  sqlite3_finalize(st);
}

static int root_depth(sqlite3 *db, const char *layer)
{
  char sql[256];
  snprintf(sql, sizeof sql, "SELECT hex(substr(data, 1, 2)) FROM "
           "\"rtree_%s_geom_node\" WHERE nodeno = 1", layer);
  char *t = sql_text(db, sql);
  int d = t ? (int)strtol(t, NULL, 16) : -1;
  free(t);
  return d;
}

/* The SQLite-side checks of one indexed layer; returns the index depth. */
static int check_index(const char *path, const char *layer, int nwin)
{
  sqlite3 *db = db_open(path);
  if (!db)
    return -1;
  char sql[256];
  snprintf(sql, sizeof sql, "SELECT rtreecheck('rtree_%s_geom')", layer);
  char *t = sql_text(db, sql);
  CHECK_STR_EQ(t, "ok");
  free(t);
  t = sql_text(db, "PRAGMA integrity_check");
  CHECK_STR_EQ(t, "ok");
  free(t);
  /* The trigger set of the file's GeoPackage version. */
  int v14 = sql_int(db, "PRAGMA user_version") >= 10400;
  static const char *const names14[] = {"insert", "update2", "update4",
      "update5", "update6", "update7", "delete"};
  static const char *const names13[] = {"insert", "update1", "update2",
      "update3", "update4", "delete"};
  int nnames = v14 ? 7 : 6;
  snprintf(sql, sizeof sql, "SELECT count(*) FROM sqlite_master WHERE type "
           "= 'trigger' AND tbl_name = '%s' AND name LIKE 'rtree%%'", layer);
  CHECK_INT_EQ(sql_int(db, sql), nnames);
  for (int k = 0; k < nnames; k++) {
    snprintf(sql, sizeof sql, "SELECT count(*) FROM sqlite_master WHERE "
             "type = 'trigger' AND name = 'rtree_%s_geom_%s'", layer,
             v14 ? names14[k] : names13[k]);
    CHECK_INT_EQ(sql_int(db, sql), 1);
  }
  snprintf(sql, sizeof sql, "SELECT count(*) FROM gpkg_extensions WHERE "
           "table_name = '%s' AND column_name = 'geom' AND extension_name = "
           "'gpkg_rtree_index' AND scope = 'write-only'", layer);
  CHECK_INT_EQ(sql_int(db, sql), 1);

  size_t nt = 0, nr = 0;
  row *truth = ogr_bounds(path, layer, &nt);
  row *rows = rtree_rows(db, layer, &nr);
  CHECK_INT_EQ(nr, nt);
  for (size_t i = 0; i < nr && i < nt; i++) {
    if (rows[i].id != truth[i].id) {
      TT_FAIL_("%s: index row %zu has id %lld, the table %lld", layer, i,
               (long long)rows[i].id, (long long)truth[i].id);
      break;
    }
    const double *b = rows[i].b, *e = truth[i].b;
    int holds = b[0] <= e[0] && b[1] >= e[1] && b[2] <= e[2] && b[3] >= e[3];
    int tight = e[0] - b[0] <= two_float_steps(e[0]) &&
                b[1] - e[1] <= two_float_steps(e[1]) &&
                e[2] - b[2] <= two_float_steps(e[2]) &&
                b[3] - e[3] <= two_float_steps(e[3]);
    if (!holds || !tight) {
      TT_FAIL_("%s fid %lld: box [%.17g %.17g %.17g %.17g] vs bounds "
               "[%.17g %.17g %.17g %.17g]", layer, (long long)rows[i].id,
               b[0], b[1], b[2], b[3], e[0], e[1], e[2], e[3]);
      break;
    }
  }
  check_windows(db, layer, rows, nr, nwin);
  int depth = root_depth(db, layer);
  free(truth);
  free(rows);
  sqlite3_close(db);
  return depth;
}

/* GDAL's view: fast spatial filter, and filtered counts equal to those on
 * the unindexed file (GDAL scanning) and, for points, an exact test. */
static void check_gdal_filter(const char *indexed, const char *plain,
                              const char *layer, int nwin)
{
  GDALDatasetH a = GDALOpenEx(indexed, GDAL_OF_VECTOR, NULL, NULL, NULL);
  GDALDatasetH b = GDALOpenEx(plain, GDAL_OF_VECTOR, NULL, NULL, NULL);
  CHECK(a && b);
  if (!a || !b)
    goto done;
  OGRLayerH la = GDALDatasetGetLayerByName(a, layer);
  OGRLayerH lb = GDALDatasetGetLayerByName(b, layer);
  CHECK(la && lb);
  if (!la || !lb)
    goto done;
  CHECK(OGR_L_TestCapability(la, OLCFastSpatialFilter));
  CHECK(!OGR_L_TestCapability(lb, OLCFastSpatialFilter));
  OGREnvelope ext;
  if (OGR_L_GetExtent(lb, &ext, TRUE) != OGRERR_NONE)
    goto done; /* empty layer */
  double w = ext.MaxX - ext.MinX + 1, h = ext.MaxY - ext.MinY + 1;
  for (int q = 0; q < nwin; q++) {
    double sw = w * pow(10, -2.5 * rng_unit()), sh = h *
                pow(10, -2.5 * rng_unit());
    double x0 = ext.MinX + w * rng_unit() - sw / 2;
    double y0 = ext.MinY + h * rng_unit() - sh / 2;
    long long ca = 0, cb = 0, exact = 0;
    OGR_L_SetSpatialFilterRect(la, x0, y0, x0 + sw, y0 + sh);
    OGR_L_SetSpatialFilterRect(lb, x0, y0, x0 + sw, y0 + sh);
    OGRFeatureH f;
    OGR_L_ResetReading(la);
    while ((f = OGR_L_GetNextFeature(la)) != NULL) {
      ca++;
      OGR_F_Destroy(f);
    }
    OGR_L_ResetReading(lb);
    while ((f = OGR_L_GetNextFeature(lb)) != NULL) {
      OGRGeometryH g = OGR_F_GetGeometryRef(f);
      if (g && wkbFlatten(OGR_G_GetGeometryType(g)) == wkbPoint) {
        double x = OGR_G_GetX(g, 0), y = OGR_G_GetY(g, 0);
        exact += x >= x0 && x <= x0 + sw && y >= y0 && y <= y0 + sh;
      }
      cb++;
      OGR_F_Destroy(f);
    }
    if (ca != cb)
      TT_FAIL_("%s: GDAL filter window %d: %lld features with the index, "
               "%lld without", layer, q, ca, cb);
    if (strstr(layer, "vertices") && exact != cb)
      TT_FAIL_("%s: window %d: %lld points inside, GDAL gives %lld", layer,
               q, exact, cb);
  }
done:
  if (a)
    GDALClose(a);
  if (b)
    GDALClose(b);
}

/* The (id, box) rows equal those GDAL's CreateSpatialIndex() writes. */
static void check_same_as_gdal(const char *ours, const char *plain,
                               const char *layer)
{
  const char *theirs = tmp_path("gdal_index.gpkg");
  copy_file(plain, theirs);
  GDALDatasetH ds = GDALOpenEx(theirs, GDAL_OF_VECTOR | GDAL_OF_UPDATE, NULL,
                               NULL, NULL);
  CHECK(ds != NULL);
  if (!ds)
    return;
  char sql[256];
  snprintf(sql, sizeof sql, "SELECT CreateSpatialIndex('%s', 'geom')", layer);
  OGRLayerH rs = GDALDatasetExecuteSQL(ds, sql, NULL, NULL);
  if (rs)
    GDALDatasetReleaseResultSet(ds, rs);
  GDALClose(ds);
  sqlite3 *da = db_open(ours), *db = db_open(theirs);
  size_t na = 0, nb = 0;
  row *ra = da ? rtree_rows(da, layer, &na) : NULL;
  row *rb = db ? rtree_rows(db, layer, &nb) : NULL;
  CHECK_INT_EQ(na, nb);
  for (size_t i = 0; i < na && i < nb; i++)
    if (ra[i].id != rb[i].id || memcmp(ra[i].b, rb[i].b, sizeof ra[i].b)) {
      TT_FAIL_("%s: row %zu differs from GDAL's: id %lld [%.9g %.9g %.9g "
               "%.9g] vs id %lld [%.9g %.9g %.9g %.9g]", layer, i,
               (long long)ra[i].id, ra[i].b[0], ra[i].b[1], ra[i].b[2],
               ra[i].b[3], (long long)rb[i].id, rb[i].b[0], rb[i].b[1],
               rb[i].b[2], rb[i].b[3]);
      break;
    }
  free(ra);
  free(rb);
  sqlite3_close(da);
  sqlite3_close(db);
  unlink(theirs);
}

/* --- the cases ---------------------------------------------------------- */

static int stop_after_calls;
static int stop_progress(double complete, const char *msg, void *arg)
{
  (void)complete;
  (void)msg;
  int *calls = arg;
  return ++*calls < stop_after_calls;
}

/* Builds both layers of path; checks them; returns the triangles' depth. */
static int build_and_check(tt_context *ctx, const char *path,
                           const char *plain, int nwin, int gdal_windows)
{
  CHECK_OK(ctx, tt_gpkg_build_rtree(ctx, path, "triangles", "geom", NULL,
                                    NULL));
  CHECK_OK(ctx, tt_gpkg_build_rtree(ctx, path, "vertices", "geom", NULL,
                                    NULL));
  int depth = check_index(path, "triangles", nwin);
  check_index(path, "vertices", nwin);
  check_same_as_gdal(path, plain, "triangles");
  check_same_as_gdal(path, plain, "vertices");
  if (gdal_windows) {
    check_gdal_filter(path, plain, "triangles", gdal_windows);
    check_gdal_filter(path, plain, "vertices", gdal_windows);
  }
  return depth;
}

/* Feature counts around node boundaries, cut from one unindexed TIN. */
static void test_counts(tt_context *ctx, const char *big_plain, int cap)
{
  const long long counts[] = {0, 1, cap, cap + 1, (long long)cap * cap,
                              (long long)cap * cap + 1};
  const int depths[] = {0, 0, 0, 1, 1, 2};
  for (size_t k = 0; k < sizeof counts / sizeof counts[0]; k++) {
    const char *plain = tmp_path("cut_plain.gpkg");
    const char *path = tmp_path("cut.gpkg");
    copy_file(big_plain, plain);
    sqlite3 *db = db_open(plain);
    char sql[256];
    snprintf(sql, sizeof sql, "DELETE FROM triangles WHERE fid > %lld; "
             "DELETE FROM vertices WHERE fid > %lld", counts[k], counts[k]);
    sql_exec(db, sql);
    long long nt = sql_int(db, "SELECT count(*) FROM triangles");
    sqlite3_close(db);
    CHECK_INT_EQ(nt, counts[k]);
    copy_file(plain, path);
    int depth = build_and_check(ctx, path, plain, 40, k < 4 ? 5 : 0);
    if (depth != depths[k])
      TT_FAIL_("%lld features: depth %d, expected %d", counts[k], depth,
               depths[k]);
  }
}

/* NULL and empty geometries are skipped, as the triggers would. */
static void test_null_and_empty(tt_context *ctx, const char *small_plain)
{
  const char *plain = tmp_path("holes_plain.gpkg");
  const char *path = tmp_path("holes.gpkg");
  copy_file(small_plain, plain);
  sqlite3 *db = db_open(plain);
  /* An empty point: flags 0x11 (little-endian, empty), no envelope, then
   * POINT(NaN NaN) in little-endian WKB. */
  sql_exec(db, "UPDATE triangles SET geom = NULL WHERE fid % 7 = 0");
  sql_exec(db, "UPDATE vertices SET geom = X'4750001100000000"
               "0101000000000000000000F87F000000000000F87F' "
               "WHERE fid % 5 = 0");
  long long nonnull =
      sql_int(db, "SELECT count(*) FROM triangles WHERE geom NOT NULL");
  long long nonempty =
      sql_int(db, "SELECT count(*) FROM vertices WHERE fid % 5 != 0");
  sqlite3_close(db);
  copy_file(plain, path);
  build_and_check(ctx, path, plain, 30, 3);
  db = db_open(path);
  CHECK_INT_EQ(sql_int(db, "SELECT count(*) FROM rtree_triangles_geom"),
               nonnull);
  CHECK_INT_EQ(sql_int(db, "SELECT count(*) FROM rtree_vertices_geom"),
               nonempty);
  sqlite3_close(db);
}

static OGRGeometryH make_triangle(double x, double y)
{
  OGRGeometryH poly = OGR_G_CreateGeometry(wkbPolygon25D);
  OGRGeometryH ring = OGR_G_CreateGeometry(wkbLinearRing);
  OGR_G_AddPoint(ring, x, y, 1);
  OGR_G_AddPoint(ring, x + 3.3, y, 1);
  OGR_G_AddPoint(ring, x, y + 2.2, 1);
  OGR_G_AddPoint(ring, x, y, 1);
  OGR_G_AddGeometryDirectly(poly, ring);
  return poly;
}

static int64_t add_triangle(OGRLayerH l, double x, double y)
{
  OGRFeatureH f = OGR_F_Create(OGR_L_GetLayerDefn(l));
  OGR_F_SetGeometryDirectly(f, make_triangle(x, y));
  CHECK(OGR_L_CreateFeature(l, f) == OGRERR_NONE);
  int64_t fid = OGR_F_GetFID(f);
  OGR_F_Destroy(f);
  return fid;
}

static void set_geometry(OGRLayerH l, int64_t fid, OGRGeometryH g)
{
  OGRFeatureH f = OGR_L_GetFeature(l, fid);
  CHECK(f != NULL);
  if (!f)
    return;
  OGR_F_SetGeometry(f, g);
  CHECK(OGR_L_SetFeature(l, f) == OGRERR_NONE);
  OGR_F_Destroy(f);
}

static void exec_gdal_sql(GDALDatasetH ds, const char *sql)
{
  OGRLayerH rs = GDALDatasetExecuteSQL(ds, sql, NULL, NULL);
  if (rs)
    GDALDatasetReleaseResultSet(ds, rs);
}

/* Edits through OGR and SQL after the build keep the index right. */
static void test_triggers(tt_context *ctx, const char *small_plain,
                          int version)
{
  const char *path = tmp_path("edit.gpkg");
  copy_file(small_plain, path);
  sqlite3 *vdb = db_open(path);
  char vsql[64];
  snprintf(vsql, sizeof vsql, "PRAGMA user_version = %d", version);
  sql_exec(vdb, vsql);
  sqlite3_close(vdb);
  CHECK_OK(ctx, tt_gpkg_build_rtree(ctx, path, "triangles", "geom", NULL,
                                    NULL));
  CHECK_OK(ctx, tt_gpkg_build_rtree(ctx, path, "vertices", "geom", NULL,
                                    NULL));
  GDALDatasetH ds = GDALOpenEx(path, GDAL_OF_VECTOR | GDAL_OF_UPDATE, NULL,
                               NULL, NULL);
  CHECK(ds != NULL);
  if (!ds)
    return;
  OGRLayerH l = GDALDatasetGetLayerByName(ds, "triangles");
  int64_t added = add_triangle(l, 412000.5, 5123000.25);      /* insert */
  OGRGeometryH tri = make_triangle(412100.125, 5123100.0625);
  set_geometry(l, 3, tri);                                    /* update6 */
  set_geometry(l, 4, NULL);                                   /* update2 */
  set_geometry(l, 5, NULL);
  set_geometry(l, 5, tri);                                    /* update7 */
  CHECK(OGR_L_DeleteFeature(l, 6) == OGRERR_NONE);            /* delete */
  exec_gdal_sql(ds, "UPDATE triangles SET fid = 1000000 WHERE fid = 7");
  exec_gdal_sql(ds, "UPDATE triangles SET fid = 1000001, geom = NULL "
                    "WHERE fid = 8");                         /* update4 */
  OGR_G_DestroyGeometry(tri);
  GDALClose(ds);

  check_index(path, "triangles", 40); /* every row against OGR's bounds */
  sqlite3 *db = db_open(path);
  char sql[256];
  snprintf(sql, sizeof sql, "SELECT count(*) FROM rtree_triangles_geom "
           "WHERE id = %lld AND minx <= 412000.5 AND maxx >= 412003.8",
           (long long)added);
  CHECK_INT_EQ(sql_int(db, sql), 1);
  CHECK_INT_EQ(sql_int(db, "SELECT count(*) FROM rtree_triangles_geom "
                           "WHERE id IN (4, 6, 7, 8, 1000001)"), 0);
  CHECK_INT_EQ(sql_int(db, "SELECT count(*) FROM rtree_triangles_geom "
                           "WHERE id IN (3, 5) AND minx <= 412100.125 AND "
                           "maxx >= 412103.425 AND maxx < 412104"), 2);
  CHECK_INT_EQ(sql_int(db, "SELECT count(*) FROM rtree_triangles_geom "
                           "WHERE id = 1000000 AND minx > 412300"), 1);
  sqlite3_close(db);

  /* GDAL renames the layer with its index and triggers, edits still follow;
   * disabling the index leaves no trigger behind. */
  ds = GDALOpenEx(path, GDAL_OF_VECTOR | GDAL_OF_UPDATE, NULL, NULL, NULL);
  if (version < 10400) { /* GDAL 3.6 knows only the older trigger names */
    exec_gdal_sql(ds, "ALTER TABLE triangles RENAME TO tri2");
    l = GDALDatasetGetLayerByName(ds, "tri2");
    CHECK(l != NULL);
    if (l)
      add_triangle(l, 412200.5, 5123200.25);
    GDALClose(ds);
    check_index(path, "tri2", 20);
    ds = GDALOpenEx(path, GDAL_OF_VECTOR | GDAL_OF_UPDATE, NULL, NULL, NULL);
    exec_gdal_sql(ds, "SELECT DisableSpatialIndex('tri2', 'geom')");
    GDALClose(ds);
    db = db_open(path);
    CHECK_INT_EQ(sql_int(db, "SELECT count(*) FROM sqlite_master WHERE "
                             "name LIKE 'rtree_tri2%'"), 0);
    sqlite3_close(db);
  } else {
    GDALClose(ds);
  }
}

/* Refusals leave the file as it was. */
static void test_refusals(tt_context *ctx, const char *small_plain)
{
  const char *path = tmp_path("refuse.gpkg");
  copy_file(small_plain, path);
  size_t n = 0;
  unsigned char *before = slurp(path, &n);

  /* No such table, column, file. */
  CHECK_INT_EQ(tt_gpkg_build_rtree(ctx, path, "nope", "geom", NULL, NULL),
               TT_ERR_ARG);
  CHECK(strstr(tt_context_errmsg(ctx), path) != NULL);
  CHECK(strstr(tt_context_errmsg(ctx), "nope") != NULL);
  CHECK(strchr(tt_context_errmsg(ctx), '\n') == NULL);
  CHECK_INT_EQ(tt_gpkg_build_rtree(ctx, path, "triangles", "shape", NULL,
                                   NULL), TT_ERR_ARG);
  CHECK_INT_EQ(tt_gpkg_build_rtree(ctx, path, "run_parameters", "geom",
                                   NULL, NULL), TT_ERR_ARG);
  const char *missing = tmp_path("missing.gpkg");
  CHECK(tt_gpkg_build_rtree(ctx, missing, "triangles", "geom", NULL, NULL) ==
        TT_ERR_IO);
  CHECK(access(missing, F_OK) != 0);
  CHECK(strstr(tt_context_errmsg(ctx), missing) != NULL);
  CHECK(same_file(path, before, n));

  /* Interrupted at each of its first reports: rolled back. */
  for (int stop = 1; stop <= 4; stop++) {
    int calls = 0;
    stop_after_calls = stop;
    CHECK_INT_EQ(tt_gpkg_build_rtree(ctx, path, "triangles", "geom",
                                     stop_progress, &calls),
                 TT_ERR_INTERRUPTED);
    CHECK(same_file(path, before, n));
  }
  CHECK(access(tmp_path("refuse.gpkg-journal"), F_OK) != 0);

  /* A malformed geometry blob: refused, naming the feature. */
  const char *bad = tmp_path("bad.gpkg");
  copy_file(small_plain, bad);
  sqlite3 *db = db_open(bad);
  sql_exec(db, "UPDATE triangles SET geom = X'47500001E61000000103' "
               "WHERE fid = 2");
  sqlite3_close(db);
  size_t nb = 0;
  unsigned char *bad_before = slurp(bad, &nb);
  CHECK_INT_EQ(tt_gpkg_build_rtree(ctx, bad, "triangles", "geom", NULL,
                                   NULL), TT_ERR_FORMAT);
  CHECK(strstr(tt_context_errmsg(ctx), "feature 2") != NULL);
  CHECK(same_file(bad, bad_before, nb));
  free(bad_before);

  /* Once built, a second build is refused and changes nothing. */
  CHECK_OK(ctx, tt_gpkg_build_rtree(ctx, path, "triangles", "geom", NULL,
                                    NULL));
  free(before);
  before = slurp(path, &n);
  CHECK_INT_EQ(tt_gpkg_build_rtree(ctx, path, "triangles", "geom", NULL,
                                   NULL), TT_ERR_EXISTS);
  CHECK_INT_EQ(tt_gpkg_build_rtree(ctx, path, "TRIANGLES", "GEOM", NULL,
                                   NULL), TT_ERR_EXISTS);
  CHECK(same_file(path, before, n));
  free(before);

  /* The write option: RTREE=DEFERRED leaves GPKG layers unindexed. */
  tt_tin *tin = make_tin(ctx, 12, 9, 0.5);
  const char *def = tmp_path("deferred.gpkg");
  write_gpkg(ctx, tin, def, "RTREE=DEFERRED", NULL);
  db = db_open(def);
  CHECK_INT_EQ(sql_int(db, "SELECT count(*) FROM sqlite_master WHERE name "
                           "LIKE 'rtree%'"), 0);
  sqlite3_close(db);
  GDALDatasetH ds = GDALCreate(GDALGetDriverByName("GPKG"),
                               tmp_path("bogus.gpkg"), 0, 0, 0, GDT_Unknown,
                               NULL);
  char **opts = CSLAddString(NULL, "RTREE=LATER");
  CHECK_INT_EQ(tt_ogr_write_tin(ctx, ds, tin, NULL, NULL, 0, opts, NULL,
                                NULL), TT_ERR_ARG);
  CSLDestroy(opts);
  GDALClose(ds);
  tt_tin_destroy(tin);
}

/* The terratin command writes valid R-trees into GPKG outputs. */
static void test_cli(void)
{
  const char *exe = getenv("TT_TERRATIN");
  if (!exe || !*exe) {
    printf("TT_TERRATIN not set: CLI check skipped\n");
    return;
  }
  const char *dem = tmp_path("cli_dem.tif");
  const char *out = tmp_path("cli.gpkg");
  const char *out2 = tmp_path("cli_noidx.gpkg");
  char cmd[2048];
  snprintf(cmd, sizeof cmd, "'%s' generate diamond_square '%s' -size 129 "
           "-q -overwrite && '%s' simplify '%s' '%s' -max_error 1 -nln pre_ "
           "-q -overwrite && '%s' simplify '%s' '%s' -max_error 1 -q "
           "-overwrite -lco SPATIAL_INDEX=NO", exe, dem, exe, dem, out, exe,
           dem, out2);
  CHECK_INT_EQ(system(cmd), 0);
  check_index(out, "pre_triangles", 30);
  check_index(out, "pre_vertices", 30);
  sqlite3 *db = db_open(out2);
  if (db) {
    CHECK_INT_EQ(sql_int(db, "SELECT count(*) FROM sqlite_master WHERE name "
                             "LIKE 'rtree%'"), 0);
    sqlite3_close(db);
  }
}

int main(void)
{
  GDALAllRegister();
  CPLSetConfigOption("OGR_SQLITE_SYNCHRONOUS", "OFF");
  const char *seed_env = getenv("TT_SEED");
  uint64_t seed = seed_env ? strtoull(seed_env, NULL, 10)
                           : (uint64_t)time(NULL) * 2654435761u;
  rng_state = seed;
  printf("seed %llu (TT_SEED=%llu replays)\n", (unsigned long long)seed,
         (unsigned long long)seed);
  snprintf(tmpdir, sizeof tmpdir, "/tmp/tt_rtree_XXXXXX");
  if (!mkdtemp(tmpdir))
    TT_SKIP("cannot make a temporary folder");
  tt_context *ctx = tt_context_create();

  /* The node capacity SQLite picks for this page size. */
  sqlite3 *mem = NULL;
  sqlite3_open(":memory:", &mem);
  sql_exec(mem, "PRAGMA page_size = 4096; CREATE VIRTUAL TABLE r USING "
                "rtree(id, a, b, c, d)");
  int cap = (int)((sql_int(mem, "SELECT length(data) FROM r_node") - 4) / 24);
  sqlite3_close(mem);
  printf("node capacity %d\n", cap);
  CHECK_INT_EQ(cap, 51);

  /* A small TIN and one big enough for a three-level tree. */
  tt_tin *small = make_tin(ctx, 40, 30, 0.2);
  tt_tin *big = make_tin(ctx, 200, 160, 0.05);
  printf("small TIN: %zu triangles, big TIN: %zu triangles\n",
         tt_tin_triangle_count(small), tt_tin_triangle_count(big));
  CHECK((long long)tt_tin_triangle_count(big) > (long long)cap * cap + 1);
  char small_plain[512], big_plain[512];
  snprintf(small_plain, sizeof small_plain, "%s", tmp_path("small_plain.gpkg"));
  snprintf(big_plain, sizeof big_plain, "%s", tmp_path("big_plain.gpkg"));
  write_unindexed(ctx, small, small_plain);
  write_unindexed(ctx, big, big_plain);

  const char *path = tmp_path("small.gpkg");
  copy_file(small_plain, path);
  build_and_check(ctx, path, small_plain, 200, 20);
  path = tmp_path("big.gpkg");
  copy_file(big_plain, path);
  int depth = build_and_check(ctx, path, big_plain, 300, 8);
  CHECK(depth >= 2);
  printf("big TIN index depth %d\n", depth);

  TT_RUN(test_counts(ctx, big_plain, cap));
  TT_RUN(test_null_and_empty(ctx, small_plain));
  test_triggers(ctx, small_plain, 10200); /* what GDAL 3.6 writes */
  test_triggers(ctx, small_plain, 10400); /* GeoPackage 1.4 */
  TT_RUN(test_refusals(ctx, small_plain));
  TT_RUN(test_cli());

  tt_tin_destroy(small);
  tt_tin_destroy(big);
  tt_context_destroy(ctx);
  char cmd[600];
  snprintf(cmd, sizeof cmd, "rm -rf '%s'", tmpdir);
  if (tt_test_failures == 0 && system(cmd) != 0)
    printf("could not remove %s\n", tmpdir);
  if (tt_test_failures)
    printf("FAILED (%d); files kept in %s; seed %llu\n", tt_test_failures,
           tmpdir, (unsigned long long)seed);
  return tt_test_failures ? 1 : 0;
}
