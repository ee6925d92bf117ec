/*
 * test_rtree_stream.c -- the R-tree written as the rows stream in
 * (tt__rtree_stream, gpkg_rtree_pages.c) against SQLite's R*Tree module, no
 * mocks. Boxes are made in the order a tiled run gives them (pieces of
 * nearby features, tile after tile; large, fractional map coordinates so
 * the float rounding matters), fed with a cut after each piece into the
 * empty shadow tables of a GeoPackage-like file (tt__gpkg_rtree_create_empty)
 * as pages, with pages of 4,096, 1,024 and 512 bytes (51, 39 and 18 cells a
 * node); then:
 *   - rtreecheck() and PRAGMA integrity_check say ok;
 *   - every id 1..n is there once with its box, as floats;
 *   - a window query with each feature's own box finds it, and random
 *     windows give what a brute-force box test gives (the seed printed;
 *     TT_SEED=<n> replays);
 *   - the node count and the root's depth are those the blocks imply:
 *     no feature, one, exactly one leaf, one more, blocks that end on a
 *     piece and exactly on the block size, a last block of one box,
 *     no cuts (blocks of 16 times the size), a tree of four levels;
 *   - the root (node 1, a placeholder patched at the end) is right wherever
 *     its page is at the patch: still the kept root page, in the write
 *     queue, or written to the file;
 *   - a layer of one block at most gets the nodes tt__rtree_write_pages()
 *     writes, byte for byte;
 *   - SQLite can then insert, move and delete entries (node splits and
 *     merges through the %_parent and %_rowid rows written here) and the
 *     checks still hold;
 *   - an interruption of the finish and a box out of order are refused,
 *     and closing without a commit leaves the file byte for byte as it was;
 *   - the memory held is the block and the leaves' boxes, not the
 *     features'.
 */
#include "gdal/gpkg/gpkg_rtree.h"
#include "gdal/gpkg/sqlite_pages.h"
#include "terratin/terratin.h"
#include "tt_test.h"
#include "tt_test_sqlite.h"

#include <sqlite3.h>

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

static char tmpdir[256];
static uint64_t rng_state;
static tt_context *ctx;

static double rng_unit(void)
{
  return tt_test_uniform(&rng_state);
}

static const char *tmp_path(const char *name)
{
  static char buf[8][512];
  static int k;
  k = (k + 1) % 8;
  snprintf(buf[k], sizeof buf[k], "%s/%s", tmpdir, name);
  return buf[k];
}

/* --- the boxes ----------------------------------------------------------- */

/* n boxes in pieces of `piece` features, piece p in tile (p % 8, p / 8)
 * of 1,000 x 800 map units (rows of 8 tiles, as a tiled run hands them
 * out), each a small box at a random place in its tile; ids 1..n. */
static tt__rtree_box *make_boxes(size_t n, size_t piece)
{
  tt__rtree_box *b = malloc((n ? n : 1) * sizeof *b);
  for (size_t i = 0; i < n; i++) {
    size_t p = piece ? i / piece : 0;
    double x0 = 412345.678 + 1000.0 * (double)(p % 8);
    double y0 = 5123456.789 - 800.0 * (double)(p / 8);
    double x = x0 + 1000.0 * rng_unit(), y = y0 - 800.0 * rng_unit();
    double w = 3.7 * rng_unit(), h = 2.9 * rng_unit();
    if (i % 5 == 0)
      w = h = 0; /* a point, as the vertices' */
    tt__rtree_box_set(&b[i], (int64_t)i + 1, x, x + w, y - h, y);
  }
  return b;
}

/* --- building ------------------------------------------------------------ */

/* A new file at path with pages of `page` bytes: table t (fid, geom) in
 * gpkg_geometry_columns, its R-tree made empty; *sh its shadow tables. */
static int make_file(const char *path, int page, tt__rtree_shadow *sh)
{
  unlink(path);
  sqlite3 *db = NULL;
  if (sqlite3_open(path, &db) != SQLITE_OK) {
    TT_FAIL_("cannot create %s", path);
    sqlite3_close(db);
    return 0;
  }
  char sql[128];
  snprintf(sql, sizeof sql, "PRAGMA page_size = %d", page);
  sql_exec(db, sql);
  sql_exec(db, "CREATE TABLE gpkg_geometry_columns (table_name TEXT NOT "
               "NULL, column_name TEXT NOT NULL); INSERT INTO "
               "gpkg_geometry_columns VALUES ('t', 'geom'); CREATE TABLE t "
               "(fid INTEGER PRIMARY KEY AUTOINCREMENT, geom BLOB)");
  sql_exec(db, "BEGIN");
  tt_status s = tt__gpkg_rtree_create_empty(ctx, db, path, "t", "geom", sh);
  CHECK_INT_EQ(s, TT_OK);
  if (s != TT_OK)
    printf("%s\n", tt_context_errmsg(ctx));
  sql_exec(db, "COMMIT");
  sqlite3_close(db);
  return s == TT_OK;
}

static int stop_at_calls;
static int stop_progress(double complete, const char *msg, void *arg)
{
  (void)complete;
  (void)msg;
  (void)arg;
  return --stop_at_calls > 0;
}

/* Streams the n boxes into sh's tables of path, a cut after each piece
 * (none when piece is 0), blocks of `block`; commits unless stop (the
 * finish interrupted then). *peak: the most bytes the stream held. */
static tt_status stream_boxes(const char *path, const tt__rtree_shadow *sh,
                              const tt__rtree_box *boxes, size_t n,
                              size_t block, size_t piece, int stop,
                              size_t *peak)
{
  tt__sqlite_file *f = NULL;
  tt__rtree_stream *rs = NULL;
  tt_status s = tt__sqlite_file_open(ctx, path, &f);
  if (s == TT_OK)
    s = tt__rtree_stream_create(ctx, "t", sh, f, block, &rs);
  size_t most = 0;
  for (size_t i = 0; i < n && s == TT_OK; i++) {
    s = tt__rtree_stream_add(rs, &boxes[i]);
    if (s == TT_OK && piece && (i + 1) % piece == 0)
      s = tt__rtree_stream_cut(rs);
    size_t now = tt__rtree_stream_bytes(rs);
    most = now > most ? now : most;
  }
  if (s == TT_OK && piece)
    s = tt__rtree_stream_cut(rs);
  stop_at_calls = 2;
  if (s == TT_OK)
    s = tt__rtree_stream_finish(rs, stop ? stop_progress : NULL, NULL);
  if (s == TT_OK)
    s = tt__sqlite_file_commit(f);
  tt__rtree_stream_free(rs);
  tt_status c = tt__sqlite_file_close(f);
  if (peak)
    *peak = most;
  return s != TT_OK ? s : c;
}

/* The stream's blocks replayed (gpkg_rtree_pages.c, tt__rtree_stream_cut):
 * at a cut the boxes since the last one join the block, and when they lie
 * apart from it (a row of tiles wrapped) the block may end before them; a
 * full block ends there if it can, else at the cut; 16 times the block
 * size ends it anywhere. */
typedef struct replay {
  const tt__rtree_box *boxes;
  size_t cap, block, b0, mark, split, leaves;
  float so_far[4];
  int streamed;
} replay;

static void bounds_of(const tt__rtree_box *b, size_t n, float out[4])
{
  memcpy(out, b[0].box, sizeof b[0].box);
  for (size_t i = 1; i < n; i++) {
    out[0] = fminf(out[0], b[i].box[0]);
    out[1] = fmaxf(out[1], b[i].box[1]);
    out[2] = fminf(out[2], b[i].box[2]);
    out[3] = fmaxf(out[3], b[i].box[3]);
  }
}

static void replay_pack(replay *r, size_t k, size_t end)
{
  r->leaves += (k + r->cap - 1) / r->cap;
  r->b0 += k;
  r->streamed = 1;
  r->mark = r->split = 0;
  if (end > r->b0) {
    bounds_of(r->boxes + r->b0, end - r->b0, r->so_far);
    r->mark = end - r->b0;
  }
}

static void replay_cut(replay *r, size_t end)
{
  size_t n = end - r->b0, m = r->mark;
  if (n == m)
    return;
  float bb[4];
  bounds_of(r->boxes + r->b0 + m, n - m, bb);
  if (m == 0) {
    memcpy(r->so_far, bb, sizeof bb);
  } else {
    float *sf = r->so_far;
    if (bb[0] > sf[1] || bb[1] < sf[0] || bb[2] > sf[3] || bb[3] < sf[2])
      r->split = m;
    sf[0] = fminf(sf[0], bb[0]);
    sf[1] = fmaxf(sf[1], bb[1]);
    sf[2] = fminf(sf[2], bb[2]);
    sf[3] = fmaxf(sf[3], bb[3]);
  }
  r->mark = n;
  if (n < r->block)
    return;
  replay_pack(r, r->split ? r->split : n, end);
  if (end - r->b0 >= r->block)
    replay_pack(r, end - r->b0, end);
}

/* The nodes the stream makes of boxes[0..n): leaves block by block, then
 * the levels above; a layer never packed in blocks is the whole-layer STR
 * tree. *depth: the root's. */
static size_t expected_nodes(const tt__rtree_box *boxes, size_t n,
                             size_t block, size_t piece, size_t cap,
                             int *depth)
{
  replay r;
  memset(&r, 0, sizeof r);
  r.boxes = boxes;
  r.cap = cap;
  r.block = block <= cap ? cap + 1 : block;
  for (size_t i = 0; i < n; i++) {
    if (i + 1 - r.b0 >= 16 * r.block)
      replay_pack(&r, i + 1 - r.b0, i + 1);
    if (piece && (i + 1) % piece == 0)
      replay_cut(&r, i + 1);
  }
  if (piece)
    replay_cut(&r, n);
  size_t level, nodes;
  if (!r.streamed) { /* the features are the bottom level */
    level = n;
    nodes = 0;
    *depth = 0;
  } else {
    level = r.leaves + (n - r.b0 + cap - 1) / cap;
    nodes = level;
    *depth = 1;
  }
  while (level > cap) {
    level = (level + cap - 1) / cap;
    nodes += level;
    (*depth)++;
  }
  return nodes + 1; /* the root */
}

/* The widest leaf of path (its x extent). */
static double widest_leaf(const char *path)
{
  sqlite3 *db = db_open(path);
  if (!db)
    return -1;
  sqlite3_stmt *st = NULL;
  sqlite3_prepare_v2(db, "SELECT data FROM rtree_t_geom_node WHERE nodeno "
                     "IN (SELECT nodeno FROM rtree_t_geom_rowid)", -1, &st,
                     NULL);
  double most = 0;
  while (sqlite3_step(st) == SQLITE_ROW) {
    const unsigned char *d = sqlite3_column_blob(st, 0);
    int nc = d[2] << 8 | d[3];
    double lo = INFINITY, hi = -INFINITY;
    for (int i = 0; i < nc; i++) {
      const unsigned char *c = d + 4 + 24 * i + 8; /* minx, maxx */
      for (int k = 0; k < 2; k++) {
        uint32_t u = (uint32_t)c[4 * k] << 24 | (uint32_t)c[4 * k + 1] << 16 |
                     (uint32_t)c[4 * k + 2] << 8 | c[4 * k + 3];
        float f;
        memcpy(&f, &u, sizeof f);
        lo = fmin(lo, f);
        hi = fmax(hi, f);
      }
    }
    if (nc && hi - lo > most)
      most = hi - lo;
  }
  sqlite3_finalize(st);
  sqlite3_close(db);
  return most;
}

/* --- checks -------------------------------------------------------------- */

static int cmp_i64(const void *pa, const void *pb)
{
  int64_t a = *(const int64_t *)pa, b = *(const int64_t *)pb;
  return (a > b) - (a < b);
}

/* The index of path against want[0..n) (id i + 1 at want[i]; absent ones
 * have id 0): SQLite's checks, every entry, own-box windows for every
 * feature (or a sample of 3,000), nwin random windows against brute
 * force. */
static void check_tree(const char *path, const tt__rtree_box *want, size_t n,
                       int nwin)
{
  sqlite3 *db = db_open(path);
  if (!db)
    return;
  char *t = sql_text(db, "SELECT rtreecheck('rtree_t_geom')");
  CHECK_STR_EQ(t, "ok");
  free(t);
  t = sql_text(db, "PRAGMA integrity_check");
  CHECK_STR_EQ(t, "ok");
  free(t);
  size_t live = 0;
  for (size_t i = 0; i < n; i++)
    live += want[i].id != 0;
  CHECK_INT_EQ(sql_int(db, "SELECT count(*) FROM rtree_t_geom"),
               (long long)live);
  sqlite3_stmt *st = NULL;
  sqlite3_prepare_v2(db, "SELECT id, minx, maxx, miny, maxy FROM "
                     "rtree_t_geom ORDER BY id", -1, &st, NULL);
  size_t i = 0, bad = 0;
  while (sqlite3_step(st) == SQLITE_ROW) {
    int64_t id = sqlite3_column_int64(st, 0);
    while (i < n && want[i].id == 0)
      i++;
    if (i >= n || id != want[i].id) {
      bad++;
      break;
    }
    for (int k = 0; k < 4; k++)
      if (sqlite3_column_double(st, 1 + k) != (double)want[i].box[k])
        bad++;
    i++;
  }
  sqlite3_finalize(st);
  if (bad)
    TT_FAIL_("%s: %zu entries differ from the boxes given (at %zu)", path,
             bad, i);

  sqlite3_prepare_v2(db, "SELECT id FROM rtree_t_geom WHERE minx <= ?1 AND "
                     "maxx >= ?2 AND miny <= ?3 AND maxy >= ?4", -1, &st,
                     NULL);
  size_t step = live > 3000 ? n / 3000 + 1 : 1, missed = 0;
  for (size_t j = 0; j < n; j += step) {
    if (!want[j].id)
      continue;
    const float *b = want[j].box;
    sqlite3_bind_double(st, 1, b[1]);
    sqlite3_bind_double(st, 2, b[0]);
    sqlite3_bind_double(st, 3, b[3]);
    sqlite3_bind_double(st, 4, b[2]);
    int found = 0;
    while (sqlite3_step(st) == SQLITE_ROW)
      found |= sqlite3_column_int64(st, 0) == want[j].id;
    sqlite3_reset(st);
    missed += !found;
  }
  if (missed)
    TT_FAIL_("%s: %zu features not found by a window of their own box",
             path, missed);

  double ext[4] = {INFINITY, -INFINITY, INFINITY, -INFINITY};
  for (size_t j = 0; j < n; j++) {
    ext[0] = fmin(ext[0], want[j].box[0]);
    ext[1] = fmax(ext[1], want[j].box[1]);
    ext[2] = fmin(ext[2], want[j].box[2]);
    ext[3] = fmax(ext[3], want[j].box[3]);
  }
  int64_t *got = malloc((n + 1) * sizeof *got);
  int64_t *exp = malloc((n + 1) * sizeof *exp);
  double w = n ? ext[1] - ext[0] + 1 : 1, h = n ? ext[3] - ext[2] + 1 : 1;
  for (int q = 0; q < nwin && n; q++) {
    double sw = w * pow(10, -3 * rng_unit()), sh = h * pow(10, -3 *
                                                             rng_unit());
    double x0 = ext[0] - 0.1 * w + 1.2 * w * rng_unit() - sw / 2;
    double y0 = ext[2] - 0.1 * h + 1.2 * h * rng_unit() - sh / 2;
    double x1 = x0 + sw, y1 = y0 + sh;
    size_t ng = 0, ne = 0;
    sqlite3_bind_double(st, 1, x1);
    sqlite3_bind_double(st, 2, x0);
    sqlite3_bind_double(st, 3, y1);
    sqlite3_bind_double(st, 4, y0);
    while (sqlite3_step(st) == SQLITE_ROW && ng <= n)
      got[ng++] = sqlite3_column_int64(st, 0);
    sqlite3_reset(st);
    for (size_t j = 0; j < n; j++) {
      const float *b = want[j].box;
      if (want[j].id && b[0] <= x1 && b[1] >= x0 && b[2] <= y1 && b[3] >= y0)
        exp[ne++] = want[j].id;
    }
    qsort(got, ng, sizeof *got, cmp_i64);
    if (ng != ne || memcmp(got, exp, ng * sizeof *got) != 0) {
      TT_FAIL_("%s: window %d [%.17g %.17g] x [%.17g %.17g]: the index "
               "gives %zu, brute force %zu", path, q, x0, x1, y0, y1, ng,
               ne);
      break;
    }
  }
  free(got);
  free(exp);
  sqlite3_finalize(st);
  sqlite3_close(db);
}

static int root_depth(const char *path)
{
  sqlite3 *db = db_open(path);
  if (!db)
    return -1;
  char *t = sql_text(db, "SELECT hex(substr(data, 1, 2)) FROM "
                         "rtree_t_geom_node WHERE nodeno = 1");
  int d = t ? (int)strtol(t, NULL, 16) : -1;
  free(t);
  sqlite3_close(db);
  return d;
}

static long long node_count(const char *path)
{
  sqlite3 *db = db_open(path);
  if (!db)
    return -1;
  long long c = sql_int(db, "SELECT count(*) FROM rtree_t_geom_node");
  sqlite3_close(db);
  return c;
}

/* One case: n boxes in pieces, streamed in blocks, checked. */
static void one_case(const char *name, int page, size_t n, size_t block,
                     size_t piece, int rows_apart)
{
  tt__rtree_box *boxes = make_boxes(n, piece ? piece : 1000);
  const char *path = tmp_path(name);
  tt__rtree_shadow sh;
  if (!make_file(path, page, &sh)) {
    free(boxes);
    return;
  }
  size_t peak = 0;
  tt_status s = stream_boxes(path, &sh, boxes, n, block, piece, 0, &peak);
  CHECK_INT_EQ(s, TT_OK);
  if (s != TT_OK)
    printf("%s: %s\n", name, tt_context_errmsg(ctx));
  int depth = 0;
  size_t nodes = expected_nodes(boxes, n, block, piece, sh.node_cap, &depth);
  printf("%s: %zu boxes, pages of %d (%zu cells a node), blocks of %zu, "
         "pieces of %zu: %lld nodes (expected %zu), depth %d, at most %zu "
         "bytes held\n", name, n, page, sh.node_cap, block, piece,
         node_count(path), nodes, root_depth(path), peak);
  CHECK_INT_EQ(node_count(path), (long long)nodes);
  CHECK_INT_EQ(root_depth(path), depth);
  /* a piece a tile, blocks of fewer than a row of 8 tiles of 1,000
   * units: a block ends where a row wraps, so no leaf holds both the end
   * of a row and the start of the next (it would be some 6,000 wide) */
  if (rows_apart) {
    double most = widest_leaf(path);
    printf("%s: the widest leaf spans %.0f units\n", name, most);
    CHECK_DBL_LE(most, 2000.0);
  }
  check_tree(path, boxes, n, 150);
  tt__rtree_shadow_free(&sh);
  free(boxes);
}

/* The stream of a layer of one block at most gives the nodes
 * tt__rtree_write_pages() gives. */
static void test_one_block_same(size_t n)
{
  tt__rtree_box *boxes = make_boxes(n, 700);
  tt__rtree_shadow sa, sb;
  const char *a = tmp_path("same_a.gpkg"), *b = tmp_path("same_b.gpkg");
  char pa[512], pb[512];
  snprintf(pa, sizeof pa, "%s", a);
  snprintf(pb, sizeof pb, "%s", b);
  if (!make_file(pa, 4096, &sa) || !make_file(pb, 4096, &sb)) {
    free(boxes);
    return;
  }
  CHECK_INT_EQ(stream_boxes(pa, &sa, boxes, n, n + 1, 700, 0, NULL), TT_OK);
  tt__sqlite_file *f = NULL;
  CHECK_OK(ctx, tt__sqlite_file_open(ctx, pb, &f));
  CHECK_OK(ctx, tt__rtree_write_pages(ctx, "t", boxes, n, NULL, &sb, f, NULL,
                                      NULL));
  CHECK_OK(ctx, tt__sqlite_file_commit(f));
  CHECK_OK(ctx, tt__sqlite_file_close(f));
  sqlite3 *db = db_open(pa);
  if (db) {
    char sql[600];
    snprintf(sql, sizeof sql, "ATTACH '%s' AS b", pb);
    sql_exec(db, sql);
    static const char *const q[] = {
        "SELECT count(*) FROM (SELECT * FROM main.rtree_t_geom_node EXCEPT "
        "SELECT * FROM b.rtree_t_geom_node)",
        "SELECT count(*) FROM (SELECT * FROM main.rtree_t_geom_parent "
        "EXCEPT SELECT * FROM b.rtree_t_geom_parent)",
        "SELECT count(*) FROM (SELECT * FROM main.rtree_t_geom_rowid EXCEPT "
        "SELECT * FROM b.rtree_t_geom_rowid)",
        "SELECT (SELECT count(*) FROM main.rtree_t_geom_node) - (SELECT "
        "count(*) FROM b.rtree_t_geom_node)"};
    for (size_t k = 0; k < sizeof q / sizeof q[0]; k++)
      CHECK_INT_EQ(sql_int(db, q[k]), 0);
    sqlite3_close(db);
  }
  size_t na = 0, nb = 0;
  unsigned char *ba = slurp(pa, &na), *bb = slurp(pb, &nb);
  CHECK(ba && bb && na == nb && memcmp(ba, bb, na) == 0);
  free(ba);
  free(bb);
  tt__rtree_shadow_free(&sa);
  tt__rtree_shadow_free(&sb);
  free(boxes);
}

/* SQLite changes the streamed tree: inserts (splits), moves, deletes
 * (merges, re-inserts); the checks still hold. */
static void test_changes(void)
{
  const size_t n = 30000, more = 3000;
  tt__rtree_box *boxes = make_boxes(n + more, 900);
  const char *path = tmp_path("changes.gpkg");
  tt__rtree_shadow sh;
  if (!make_file(path, 1024, &sh)) {
    free(boxes);
    return;
  }
  CHECK_INT_EQ(stream_boxes(path, &sh, boxes, n, 2000, 900, 0, NULL), TT_OK);
  sqlite3 *db = db_open(path);
  if (!db)
    goto done;
  sqlite3_stmt *ins = NULL, *upd = NULL, *del = NULL;
  sqlite3_prepare_v2(db, "INSERT INTO rtree_t_geom VALUES (?, ?, ?, ?, ?)",
                     -1, &ins, NULL);
  sqlite3_prepare_v2(db, "UPDATE rtree_t_geom SET minx = ?2, maxx = ?3, "
                     "miny = ?4, maxy = ?5 WHERE id = ?1", -1, &upd, NULL);
  sqlite3_prepare_v2(db, "DELETE FROM rtree_t_geom WHERE id = ?", -1, &del,
                     NULL);
  sql_exec(db, "BEGIN");
  for (size_t i = n; i < n + more; i++) { /* new features, anywhere */
    sqlite3_bind_int64(ins, 1, boxes[i].id);
    for (int k = 0; k < 4; k++)
      sqlite3_bind_double(ins, 2 + k, boxes[i].box[k]);
    if (sqlite3_step(ins) != SQLITE_DONE)
      TT_FAIL_("insert %lld: %s", (long long)boxes[i].id,
               sqlite3_errmsg(db));
    sqlite3_reset(ins);
  }
  for (size_t i = 3; i < n; i += 11) { /* moved to another feature's box */
    tt__rtree_box *b = &boxes[i];
    memcpy(b->box, boxes[(i * 7919) % n].box, sizeof b->box);
    sqlite3_bind_int64(upd, 1, b->id);
    for (int k = 0; k < 4; k++)
      sqlite3_bind_double(upd, 2 + k, b->box[k]);
    if (sqlite3_step(upd) != SQLITE_DONE)
      TT_FAIL_("update %lld: %s", (long long)b->id, sqlite3_errmsg(db));
    sqlite3_reset(upd);
  }
  for (size_t i = 0; i < n; i += 3) { /* a third of them gone */
    if (i % 11 == 3)
      continue;
    sqlite3_bind_int64(del, 1, boxes[i].id);
    if (sqlite3_step(del) != SQLITE_DONE)
      TT_FAIL_("delete %lld: %s", (long long)boxes[i].id,
               sqlite3_errmsg(db));
    sqlite3_reset(del);
    boxes[i].id = 0;
  }
  sql_exec(db, "COMMIT");
  sqlite3_finalize(ins);
  sqlite3_finalize(upd);
  sqlite3_finalize(del);
  sqlite3_close(db);
  check_tree(path, boxes, n + more, 150);
done:
  tt__rtree_shadow_free(&sh);
  free(boxes);
}

/* Refusals leave the file as it was: the finish interrupted, a box out of
 * order. */
static void test_refusals(void)
{
  const size_t n = 20000;
  tt__rtree_box *boxes = make_boxes(n, 500);
  const char *path = tmp_path("refused.gpkg");
  tt__rtree_shadow sh;
  if (!make_file(path, 4096, &sh)) {
    free(boxes);
    return;
  }
  size_t n0 = 0, n1 = 0;
  unsigned char *before = slurp(path, &n0);
  tt_status s = stream_boxes(path, &sh, boxes, n, 1000, 500, 1, NULL);
  CHECK_INT_EQ(s, TT_ERR_INTERRUPTED);
  unsigned char *after = slurp(path, &n1);
  CHECK(before && after && n0 == n1 && memcmp(before, after, n0) == 0);
  free(after);
  boxes[12345].id = 99999; /* out of order */
  s = stream_boxes(path, &sh, boxes, n, 1000, 500, 0, NULL);
  CHECK_INT_EQ(s, TT_ERR_INTERNAL);
  after = slurp(path, &n1);
  CHECK(after && n0 == n1 && memcmp(before, after, n0) == 0);
  free(after);
  free(before);
  tt__rtree_shadow_free(&sh);
  free(boxes);
}

int main(void)
{
  const char *seed_env = getenv("TT_SEED");
  uint64_t seed = seed_env ? strtoull(seed_env, NULL, 10)
                           : (uint64_t)time(NULL) * 2654435761u;
  rng_state = seed;
  printf("seed %llu (TT_SEED=%llu replays)\n", (unsigned long long)seed,
         (unsigned long long)seed);
  snprintf(tmpdir, sizeof tmpdir, "/tmp/tt_rtree_stream_XXXXXX");
  if (!mkdtemp(tmpdir))
    TT_SKIP("cannot make a temporary folder");
  ctx = tt_context_create();

  /* small counts: never a block (the whole-layer tree) */
  one_case("empty.gpkg", 4096, 0, 100, 10, 0);
  one_case("one.gpkg", 4096, 1, 100, 10, 0);
  one_case("one_leaf.gpkg", 4096, 51, 100, 51, 0);
  /* one box more than a leaf, in one block of 52: two leaves under a root
   * in the %_node table's root page (the patch in the page kept for the
   * commit) */
  one_case("two_leaves.gpkg", 4096, 52, 1, 52, 0);
  /* blocks at the pieces' ends; exactly on the block size; a last block
   * of one box; no cuts at all */
  one_case("pieces.gpkg", 4096, 20000, 2000, 777, 0);
  /* rows of 8 tiles of 1,000 boxes, blocks of 2,500 to 7,000: every block
   * that fills after a row's end ends there */
  one_case("rows.gpkg", 4096, 40000, 2500, 1000, 1);
  one_case("rows_7.gpkg", 4096, 40000, 7000, 1000, 1);
  one_case("exact.gpkg", 4096, 3 * 2040, 2040, 2040, 0);
  one_case("last_one.gpkg", 4096, 3 * 2040 + 1, 2040, 2040, 0);
  one_case("no_cuts.gpkg", 4096, 40000, 1000, 0, 0);
  /* node 1's page in the write queue, then written before the patch */
  one_case("queued.gpkg", 4096, 5000, 1000, 500, 0);
  one_case("one_node_a_page.gpkg", 1024, 30000, 3000, 1500, 0);
  one_case("written.gpkg", 4096, 200000, 4096, 3000, 0);
  /* four levels with nodes of 18 cells */
  one_case("deep.gpkg", 512, 25000, 500, 333, 0);
  TT_RUN(test_one_block_same(5000));
  TT_RUN(test_changes());
  TT_RUN(test_refusals());

  /* memory: the block and the leaves, not the features */
  {
    const size_t n = 300000, block = 8192, piece = 4000;
    tt__rtree_box *boxes = make_boxes(n, piece);
    const char *path = tmp_path("memory.gpkg");
    tt__rtree_shadow sh;
    if (make_file(path, 4096, &sh)) {
      size_t peak = 0;
      CHECK_OK(ctx, stream_boxes(path, &sh, boxes, n, block, piece, 0,
                                 &peak));
      /* the block (up to block + piece boxes, grown by half), its scratch
       * (24 + 4 bytes a box), 24 bytes a leaf */
      size_t bound = 2 * (block + piece) * (24 + 24 + 4) +
                     (n / 40) * 24 * 2 + 8192;
      printf("memory: %zu features, at most %zu bytes held (bound %zu; "
             "all the boxes: %zu)\n", n, peak, bound, n * 24);
      CHECK(peak <= bound);
      tt__rtree_shadow_free(&sh);
    }
    free(boxes);
  }

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
