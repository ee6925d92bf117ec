/*
 * io_gpkg_rows.c -- the rows of a TIN's triangles and vertices layers
 * written straight into a closed GeoPackage: as SQLite database pages
 * (PAGES=YES, the command's way) or through the sqlite3 C API.
 *
 * tt_ogr_write_tin(ROWS=DEFERRED) makes the layers through OGR (tables,
 * fields, gpkg_contents, gpkg_geometry_columns, the feature-count triggers
 * and gpkg_ogr_contents: the metadata GDAL knows how to get right) and the
 * run_parameters row; this file then fills the two big tables and their
 * R-trees, as OGR would have filled them feature by feature. A second
 * thread makes the rows (values, geometry blobs, R-tree boxes, extents)
 * while the first writes them, then packs the R-trees. The content is the
 * same as OGR's: the same fids (1..n in TIN order, in tables that never
 * had rows), the same columns and values (NaN as NULL), the same geometry
 * blobs, which are the GeoPackage binary header ("GP", version 0, flags,
 * srs_id, envelope) followed by ISO WKB, byte for byte as GDAL 3.6 writes
 * them:
 *   triangles: flags 0x05 (little endian, XYZ envelope: minx maxx miny maxy
 *              minz maxz), WKB Polygon Z (1003), one ring of 4 points, the
 *              first repeated last;
 *   vertices:  flags 0x01 (little endian, no envelope, as GDAL writes
 *              points), WKB Point Z (1001).
 * Afterwards gpkg_contents gets the layers' extents and gpkg_ogr_contents
 * their feature counts, which GDAL would have set at close, and the
 * R-trees of both layers are written from the boxes of the rows
 * (gpkg_rtree.h), unless LCO=SPATIAL_INDEX=NO. tests/gdal/test_gpkg_rows.c
 * compares every row, blob and index table with the OGR writer's, both
 * ways.
 *
 * As pages (PAGES=YES; "the rows as database pages" below): the tables'
 * B-trees are built bottom-up, in rowid order, and written into the file
 * with SQLite closed (sqlite_pages.c, from SQLite's documented file
 * format), SQLite only making the R-trees' schema before and setting
 * sqlite_sequence, the extents and counts after: a fifth of the
 * instructions of the inserts (docs/speed.md). Nothing journals the page
 * writes: a failure or an interruption before the last few writes still
 * leaves the layers empty and unindexed (the pages are cut off, the
 * R-trees' schema dropped), but a crash during the write can leave the
 * file unsound. That
 * is acceptable for the command, which writes into a temporary file that
 * no one else opens, removed on failure and renamed to the output only
 * when the write completed; a library caller writing in place leaves
 * PAGES off (the default) and gets the SQLite path, whose one transaction
 * is crash-safe. A file the pages cannot be written into (WAL, auto-vacuum,
 * an index on a table, ...) also gets the SQLite path.
 *
 * Through SQLite (the default): one INSERT ... SELECT a layer from a
 * virtual table whose cursor hands SQLite the rows (see "the rows as a
 * virtual table" below), without a feature object, a geometry object and
 * a statement per row. The feature-count triggers would update
 * gpkg_ogr_contents once per row: they are dropped for the inserts and
 * re-created from their own SQL, as GDAL itself does around bulk writes.
 * Everything happens in one IMMEDIATE transaction: a failure (disk full,
 * an interruption through progress) rolls back and leaves the file with
 * its empty layers, as it was. JOURNAL=MEMORY (the command's temporary
 * files) keeps SQLite's rollback journal in memory: the roll-back still
 * works, only a crash in the middle of the write could leave the file
 * unsound, and that file is never renamed. Otherwise the journal is
 * SQLite's default, on disk.
 *
 * Workload: O(triangles + vertices) rows of fixed size (a 165-byte and a
 * 37-byte blob). As pages, on Crater Lake (108 k triangles, 54 k vertices)
 * 242 M instructions on the writing thread (records, pages, one R-tree's
 * packing and both trees' pages) and 246 M on the row maker (the rows'
 * values and blobs, the other packing); through SQLite about 5,000 a
 * triangle row in SQLite itself, the floor of that path. Memory: the
 * boxes, 24 bytes a feature, which become the packed trees' leaves, and
 * 24 more a feature of the tree being packed; 2 MB of rows in flight; a
 * few pages per table (or SQLite's page cache); with T_SRS, 16 bytes a
 * vertex.
 */
#include "gdal/gpkg_rtree.h"
#include "gdal/gpkg_stream.h"
#include "gdal/sqlite_pages.h"
#include "gdal/tin_records.h"

#include <cpl_conv.h>
#include <cpl_string.h>

#include <sqlite3.h>

#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <unistd.h>

#define TRI_BLOB_BYTES (8 + 48 + 1 + 4 + 4 + 4 + 4 * 24) /* 165 */
#define PT_BLOB_BYTES (8 + 1 + 4 + 24)                   /* 37 */
#define MAX_TRIGGERS 16

typedef struct rows_state {
  tt_context *ctx;
  sqlite3 *db;
  const char *path;
  tt_progress_fn progress;
  void *progress_arg;
  size_t done, total, next_report, step;
  double lo, hi;    /* the share of progress the present phase takes */
  struct rows_pipe *pipe; /* the rows tt__rows gives */
  tt_status status;       /* why the rows stopped */
} rows_state;

/* One saved trigger, re-created after the inserts. */
typedef struct saved_trigger {
  char *sql;
} saved_trigger;

/* A layer's table as OGR made it. */
typedef struct layer_table {
  char *name;       /* as in gpkg_contents */
  char *fid;        /* the INTEGER PRIMARY KEY column */
  char *geom;       /* the geometry column */
  int32_t srs_id;
  saved_trigger triggers[MAX_TRIGGERS];
  int ntriggers;
  double ext[4];    /* minx, miny, maxx, maxy of what was written */
  tt__rtree_box *boxes; /* one per row, for the R-tree (NULL: no index) */
  sqlite3_int64 last_fid; /* the fid of the last row written */
} layer_table;

static tt_status db_error(rows_state *w, const char *what)
{
  return tt__error(w->ctx, TT_ERR_IO, "%s: %s: %s", w->path, what,
                   sqlite3_errmsg(w->db));
}

static tt_status exec(rows_state *w, const char *sql, const char *what)
{
  char *err = NULL;
  if (sqlite3_exec(w->db, sql, NULL, NULL, &err) == SQLITE_OK)
    return TT_OK;
  tt_status s = tt__error(w->ctx, TT_ERR_IO, "%s: %s: %s", w->path, what,
                          err ? err : sqlite3_errmsg(w->db));
  sqlite3_free(err);
  return s;
}

static tt_status report(rows_state *w)
{
  w->done++;
  if (!w->progress || w->done < w->next_report)
    return TT_OK;
  w->next_report = w->done + w->step;
  double f = (double)w->done / (double)w->total;
  if (!w->progress(w->lo + (w->hi - w->lo) * f, "writing", w->progress_arg))
    return tt__error(w->ctx, TT_ERR_INTERRUPTED, "writing the TIN was "
                     "interrupted after %zu of %zu features", w->done,
                     w->total);
  return TT_OK;
}

/* The R-tree loader's progress, mapped onto [lo, hi]. */
static int rtree_progress(double complete, const char *message, void *arg)
{
  rows_state *w = arg;
  if (!w->progress)
    return 1;
  return w->progress(w->lo + (w->hi - w->lo) * complete, message,
                     w->progress_arg);
}

static void layer_free(layer_table *t)
{
  sqlite3_free(t->name);
  sqlite3_free(t->fid);
  sqlite3_free(t->geom);
  for (int k = 0; k < t->ntriggers; k++)
    sqlite3_free(t->triggers[k].sql);
  free(t->boxes);
  memset(t, 0, sizeof *t);
}

/* Finds the table OGR made for layer name: its geometry column and srs_id,
 * its primary key; checks that it is empty. */
static tt_status layer_find(rows_state *w, const char *name, layer_table *t)
{
  sqlite3_stmt *st = NULL;
  tt_status s = TT_OK;
  memset(t, 0, sizeof *t);
  t->ext[0] = t->ext[1] = INFINITY;
  t->ext[2] = t->ext[3] = -INFINITY;
  if (sqlite3_prepare_v2(w->db,
                         "SELECT table_name, column_name, srs_id FROM "
                         "gpkg_geometry_columns WHERE lower(table_name) = "
                         "lower(?)",
                         -1, &st, NULL) != SQLITE_OK)
    return db_error(w, "cannot read gpkg_geometry_columns");
  sqlite3_bind_text(st, 1, name, -1, SQLITE_TRANSIENT);
  if (sqlite3_step(st) != SQLITE_ROW) {
    s = tt__error(w->ctx, TT_ERR_FORMAT, "%s: no feature table %s in "
                  "gpkg_geometry_columns", w->path, name);
    goto done;
  }
  t->name = sqlite3_mprintf("%s", (const char *)sqlite3_column_text(st, 0));
  t->geom = sqlite3_mprintf("%s", (const char *)sqlite3_column_text(st, 1));
  t->srs_id = (int32_t)sqlite3_column_int(st, 2);
  sqlite3_finalize(st);
  st = NULL;
  if (!t->name || !t->geom) {
    s = tt__error(w->ctx, TT_ERR_NOMEM, "out of memory");
    goto done;
  }

  char *sql = sqlite3_mprintf("PRAGMA table_info(\"%w\")", t->name);
  int rc = sql ? sqlite3_prepare_v2(w->db, sql, -1, &st, NULL) : SQLITE_NOMEM;
  sqlite3_free(sql);
  if (rc != SQLITE_OK) {
    s = db_error(w, "cannot read the table's columns");
    goto done;
  }
  while (sqlite3_step(st) == SQLITE_ROW)
    if (sqlite3_column_int(st, 5) == 1 && !t->fid)
      t->fid = sqlite3_mprintf("%s",
                               (const char *)sqlite3_column_text(st, 1));
  sqlite3_finalize(st);
  st = NULL;
  if (!t->fid) {
    s = tt__error(w->ctx, TT_ERR_FORMAT, "%s: table %s has no primary key",
                  w->path, t->name);
    goto done;
  }

  sql = sqlite3_mprintf("SELECT 1 FROM \"%w\" LIMIT 1", t->name);
  rc = sql ? sqlite3_prepare_v2(w->db, sql, -1, &st, NULL) : SQLITE_NOMEM;
  sqlite3_free(sql);
  if (rc != SQLITE_OK) {
    s = db_error(w, "cannot read the table");
    goto done;
  }
  rc = sqlite3_step(st);
  if (rc == SQLITE_ROW)
    s = tt__error(w->ctx, TT_ERR_ARG, "%s: table %s already has rows",
                  w->path, t->name);
  else if (rc != SQLITE_DONE)
    s = db_error(w, "cannot read the table");
  sqlite3_finalize(st);
  st = NULL;
  /* The inserts leave the fid to SQLite (its append path, cheaper than a
   * seek per row): in an empty AUTOINCREMENT table that never had rows the
   * fids are then 1..n, as OGR gives them. */
  if (s == TT_OK &&
      sqlite3_prepare_v2(w->db,
                         "SELECT seq FROM sqlite_sequence WHERE "
                         "lower(name) = lower(?)",
                         -1, &st, NULL) == SQLITE_OK) {
    sqlite3_bind_text(st, 1, t->name, -1, SQLITE_TRANSIENT);
    if (sqlite3_step(st) == SQLITE_ROW && sqlite3_column_int64(st, 0) != 0)
      s = tt__error(w->ctx, TT_ERR_ARG, "%s: table %s had rows before",
                    w->path, t->name);
  }
done:
  sqlite3_finalize(st);
  return s;
}

/* Drops the table's triggers (the feature-count ones: nothing else is
 * there before the R-tree), keeping their SQL to re-create them. */
static tt_status triggers_drop(rows_state *w, layer_table *t)
{
  sqlite3_stmt *st = NULL;
  tt_status s = TT_OK;
  if (sqlite3_prepare_v2(w->db,
                         "SELECT name, sql FROM sqlite_master WHERE type = "
                         "'trigger' AND lower(tbl_name) = lower(?) ORDER BY "
                         "name",
                         -1, &st, NULL) != SQLITE_OK)
    return db_error(w, "cannot read the triggers");
  sqlite3_bind_text(st, 1, t->name, -1, SQLITE_TRANSIENT);
  char *drops = sqlite3_mprintf("%s", "");
  while (s == TT_OK && sqlite3_step(st) == SQLITE_ROW) {
    const char *name = (const char *)sqlite3_column_text(st, 0);
    const char *sql = (const char *)sqlite3_column_text(st, 1);
    if (!name || !sql)
      continue;
    if (t->ntriggers == MAX_TRIGGERS) {
      s = tt__error(w->ctx, TT_ERR_FORMAT, "%s: table %s has more than %d "
                    "triggers", w->path, t->name, MAX_TRIGGERS);
      break;
    }
    t->triggers[t->ntriggers].sql = sqlite3_mprintf("%s", sql);
    char *more = sqlite3_mprintf("%sDROP TRIGGER \"%w\";", drops, name);
    sqlite3_free(drops);
    drops = more;
    if (!t->triggers[t->ntriggers].sql || !drops)
      s = tt__error(w->ctx, TT_ERR_NOMEM, "out of memory");
    t->ntriggers++;
  }
  sqlite3_finalize(st);
  if (s == TT_OK && drops && *drops)
    s = exec(w, drops, "cannot drop the feature-count triggers");
  sqlite3_free(drops);
  return s;
}

static tt_status triggers_restore(rows_state *w, layer_table *t)
{
  for (int k = 0; k < t->ntriggers; k++) {
    tt_status s = exec(w, t->triggers[k].sql,
                       "cannot re-create the feature-count triggers");
    if (s != TT_OK)
      return s;
  }
  return TT_OK;
}

/* --- the rows as a virtual table ------------------------------------------
 * One INSERT INTO t (geom, fields...) SELECT c0, c1... FROM tt__rows writes
 * a whole layer: tt__rows is an eponymous virtual table of this connection
 * whose cursor hands SQLite the rows of the layer being written, so SQLite
 * reads the values straight from here, with no bound parameters to copy,
 * and updates sqlite_sequence once per layer. (Batches of 64 rows of bound
 * parameters, the earlier way, took 5,500 instructions a triangle in
 * SQLite's bind and VDBE code.)
 *
 * The rows are made (tt__records_*, the geometry blobs, the R-tree boxes,
 * the extents) by a second thread, a chunk of CHUNK_ROWS rows at a time,
 * through a ring of NCHUNKS chunks, while SQLite inserts the previous ones:
 * the triangles' rows, then the vertices'. With one thread (THREADS=1, or
 * no second CPU) the cursor makes each chunk itself when it needs it. Only
 * the SQLite thread reports progress; a failure on either side (an
 * interruption, a row the TIN cannot give) stops the other and ends the
 * statement with an error, kept in rows_pipe.status. */

#define MAX_COLS (1 + TT__TF_COUNT) /* the geometry and the fields */
#define ROWS_MODULE "tt__rows"
#define CHUNK_ROWS 1024
#define NCHUNKS 4

enum { V_NULL, V_INT, V_REAL };

typedef struct row_value {
  int type;
  sqlite3_int64 i;
  double d;
} row_value;

static void set_int(row_value *v, sqlite3_int64 i)
{
  v->type = V_INT;
  v->i = i;
}

static void set_real(row_value *v, double d)
{
  v->type = isfinite(d) ? V_REAL : V_NULL; /* NaN as NULL */
  v->d = d;
}

enum { CH_EMPTY, CH_MAKING, CH_FULL };

typedef struct chunk {
  int layer;         /* 0: triangles, 1: vertices */
  size_t first, n;   /* rows [first, first + n) of the layer */
  int state;         /* CH_*: CH_FULL made, not yet written */
  double ext[4];     /* the extent of its rows */
  row_value v[CHUNK_ROWS][MAX_COLS];
  unsigned char blob[CHUNK_ROWS][TRI_BLOB_BYTES];
  int blob_len[CHUNK_ROWS];
} chunk;

typedef struct rows_pipe {
  const tt__records *rec;
  layer_table *layer[2];
  size_t count[2];
  int ncols[2];
  int decimated;
  chunk *ring;       /* NCHUNKS */
  /* the rows not yet given to a chunk: from row m_first of layer m_layer;
   * chunk number claim is the next to be given them (shared) */
  int m_layer;
  size_t m_first;
  size_t claim;
  size_t made[2];    /* rows made, of each layer (shared) */
  tt_context *m_ctx; /* the maker thread's own messages */
  /* the writing side */
  int layer_now;     /* the layer being inserted */
  size_t c_slot;     /* the chunk being read, when c_held */
  int c_held;
  size_t row;        /* the row being read */
  const row_value *vals;
  const unsigned char *blob;
  int blob_len;
  /* shared */
  int threaded;
  pthread_t thread;
  pthread_mutex_t lock;
  pthread_cond_t cond;
  int stop;          /* the SQLite side gave up */
  int failed;        /* the maker failed: message in m_ctx */
  /* the R-trees, packed by the maker once the rows are made (0 cells: not
   * here; the SQLite thread packs what is not packed) */
  size_t node_cap;
  tt__rtree_packed *packed[2];
  int claimed[2];    /* the tree is (being) packed by one of the threads */
} rows_pipe;

static tt_status fill_triangle(const rows_pipe *p, tt_context *ctx,
                               size_t i, row_value *vals,
                               unsigned char *blob, int *blob_len,
                               double *ext)
{
  layer_table *t = p->layer[0];
  tt_triangle_info tr;
  double px[3], py[3], pz[3];
  tt_status s = tt__records_triangle(p->rec, ctx, i, &tr, px, py, pz);
  if (s != TT_OK)
    return s;
  double lo[3] = {px[0], py[0], pz[0]}, hi[3] = {px[0], py[0], pz[0]};
  for (int k = 1; k < 3; k++) {
    double c[3] = {px[k], py[k], pz[k]};
    for (int d = 0; d < 3; d++) {
      if (c[d] < lo[d]) lo[d] = c[d];
      if (c[d] > hi[d]) hi[d] = c[d];
    }
  }
  unsigned char *q = put_header(blob, 0x05, t->srs_id);
  for (int d = 0; d < 3; d++) {
    q = put_f64(q, lo[d]);
    q = put_f64(q, hi[d]);
  }
  *q++ = 1; /* WKB little endian */
  q = put_u32(q, 1003);
  q = put_u32(q, 1);
  q = put_u32(q, 4);
  for (int k = 0; k < 4; k++) {
    q = put_f64(q, px[k % 3]);
    q = put_f64(q, py[k % 3]);
    q = put_f64(q, pz[k % 3]);
  }
  *blob_len = (int)(q - blob);
  extend(ext, lo[0], lo[1]);
  extend(ext, hi[0], hi[1]);
  if (t->boxes)
    tt__rtree_box_set(&t->boxes[i], (int64_t)i + 1, lo[0], hi[0], lo[1],
                      hi[1]);
  row_value *f = vals + 1;
  set_int(&f[TT__TF_V0], tr.v[0]);
  set_int(&f[TT__TF_V1], tr.v[1]);
  set_int(&f[TT__TF_V2], tr.v[2]);
  set_real(&f[TT__TF_MAX_ERR], tr.max_error);
  set_real(&f[TT__TF_RMSE], tr.rmse);
  set_int(&f[TT__TF_N_SAMPLES], (sqlite3_int64)tr.samples);
  set_real(&f[TT__TF_AREA_2D], tr.area_2d);
  set_real(&f[TT__TF_AREA_3D], tr.area_3d);
  set_real(&f[TT__TF_SLOPE], tr.slope_deg);
  set_real(&f[TT__TF_ASPECT], tr.aspect_deg);
  set_real(&f[TT__TF_MIN_ANGLE], tr.min_angle_deg);
  set_real(&f[TT__TF_MAX_ANGLE], tr.max_angle_deg);
  return TT_OK;
}

static tt_status fill_vertex(const rows_pipe *p, tt_context *ctx, size_t i,
                             row_value *vals, unsigned char *blob,
                             int *blob_len, double *ext)
{
  layer_table *t = p->layer[1];
  tt_vertex_info v;
  double x, y;
  tt_status s = tt__records_vertex(p->rec, ctx, i, &v, &x, &y);
  if (s != TT_OK)
    return s;
  unsigned char *q = put_header(blob, 0x01, t->srs_id);
  *q++ = 1;
  q = put_u32(q, 1001);
  q = put_f64(q, x);
  q = put_f64(q, y);
  q = put_f64(q, v.z);
  *blob_len = (int)(q - blob);
  extend(ext, x, y);
  if (t->boxes)
    tt__rtree_box_set(&t->boxes[i], (int64_t)i + 1, x, x, y, y);
  row_value *f = vals + 1;
  set_int(&f[TT__VF_ID], (sqlite3_int64)i);
  set_int(&f[TT__VF_COL], v.col);
  set_int(&f[TT__VF_ROW], v.row);
  set_real(&f[TT__VF_INS_ERR], v.insert_error);
  if (p->decimated)
    f[TT__VF_INS_RANK].type = V_NULL;
  else
    set_int(&f[TT__VF_INS_RANK], (sqlite3_int64)v.rank);
  set_real(&f[TT__VF_STAR_MAX], v.star_max_error);
  set_real(&f[TT__VF_STAR_RMSE], v.star_rmse);
  set_int(&f[TT__VF_STAR_N], (sqlite3_int64)v.star_samples);
  if (p->decimated)
    set_real(&f[TT__VF_IMPORTANCE], v.importance);
  return TT_OK;
}

/* The rows of chunk number p->claim given to ch (p->claim then the next
 * one); 0 when every row has been given. Called with the lock held. */
static int claim_rows(rows_pipe *p, chunk *ch)
{
  while (p->m_layer < 2 && p->m_first >= p->count[p->m_layer]) {
    p->m_layer++;
    p->m_first = 0;
  }
  if (p->m_layer >= 2)
    return 0;
  size_t left = p->count[p->m_layer] - p->m_first;
  ch->layer = p->m_layer;
  ch->first = p->m_first;
  ch->n = left < CHUNK_ROWS ? left : CHUNK_ROWS;
  ch->state = CH_MAKING;
  p->m_first += ch->n;
  p->claim++;
  return 1;
}

/* Makes the rows given to ch (either thread, without the lock: the rows,
 * boxes and extent are the chunk's own). Errors go to ctx. */
static tt_status fill_chunk(rows_pipe *p, chunk *ch, tt_context *ctx)
{
  tt_status s = TT_OK;
  ch->ext[0] = ch->ext[1] = INFINITY;
  ch->ext[2] = ch->ext[3] = -INFINITY;
  for (size_t r = 0; r < ch->n && s == TT_OK; r++)
    s = (ch->layer == 0 ? fill_triangle : fill_vertex)(
        p, ctx, ch->first + r, ch->v[r], ch->blob[r], &ch->blob_len[r],
        ch->ext);
  return s;
}

static void pipe_lock(rows_pipe *p)
{
  if (p->threaded)
    pthread_mutex_lock(&p->lock);
}

static void pipe_unlock(rows_pipe *p)
{
  if (p->threaded)
    pthread_mutex_unlock(&p->lock);
}

/* ch made (lock held): its rows count, the other side may go on. */
static void chunk_made(rows_pipe *p, chunk *ch)
{
  ch->state = CH_FULL;
  p->made[ch->layer] += ch->n;
  if (p->threaded)
    pthread_cond_broadcast(&p->cond);
}

/* The maker: takes the next chunk of rows when its slot of the ring is
 * free and makes it, until every row is given (the writing side makes the
 * chunks it finds not yet taken: neither waits for the other but for a
 * chunk being made); then packs the R-trees. */
static void *maker_main(void *arg)
{
  rows_pipe *p = arg;
  for (;;) {
    pthread_mutex_lock(&p->lock);
    chunk *ch = &p->ring[p->claim % NCHUNKS];
    while (!p->stop && ch->state != CH_EMPTY) {
      pthread_cond_wait(&p->cond, &p->lock);
      ch = &p->ring[p->claim % NCHUNKS];
    }
    int more = !p->stop && claim_rows(p, ch);
    pthread_mutex_unlock(&p->lock);
    if (!more)
      break;
    tt_status s = fill_chunk(p, ch, p->m_ctx);
    pthread_mutex_lock(&p->lock);
    if (s != TT_OK)
      p->failed = 1;
    else
      chunk_made(p, ch);
    pthread_cond_broadcast(&p->cond);
    pthread_mutex_unlock(&p->lock);
    if (s != TT_OK)
      break;
  }
  /* Every row given: the R-trees' packing (sorts) goes on here while the
   * writing side writes the last rows, each tree once all its rows are
   * made (the writing side may make the last ones). The boxes become the
   * packed trees' leaves. */
  for (int k = 0; k < 2 && p->node_cap; k++) {
    pthread_mutex_lock(&p->lock);
    while (!p->stop && !p->failed && p->made[k] < p->count[k])
      pthread_cond_wait(&p->cond, &p->lock);
    int stop = p->stop || p->failed, claimed = p->claimed[k];
    p->claimed[k] = 1;
    pthread_mutex_unlock(&p->lock);
    layer_table *t = p->layer[k];
    if (stop)
      break;
    if (claimed)
      continue; /* the other thread packs it */
    if (!t->boxes || p->count[k] == 0)
      continue; /* a layer left out by LAYERS */
    if (tt__rtree_pack(p->m_ctx, t->name, t->boxes, p->count[k],
                       p->node_cap, &p->packed[k]) != TT_OK)
      break; /* the writing side packs from the boxes */
    t->boxes = NULL; /* the packed tree's */
  }
  return NULL;
}

/* The writing side: points p at row i of layer p->layer_now, taking the
 * next chunk when row i is past the one held: made by the maker, or made
 * here when the maker has not taken it yet. */
static tt_status pipe_row(rows_pipe *p, rows_state *w, size_t i)
{
  chunk *ch = p->c_held ? &p->ring[p->c_slot % NCHUNKS] : NULL;
  if (!ch || ch->layer != p->layer_now || i < ch->first ||
      i >= ch->first + ch->n) {
    pipe_lock(p);
    if (ch) { /* done with it */
      ch->state = CH_EMPTY;
      p->c_slot++;
      p->c_held = 0;
      if (p->threaded)
        pthread_cond_broadcast(&p->cond);
    }
    ch = &p->ring[p->c_slot % NCHUNKS];
    tt_status s = TT_OK;
    while (ch->state != CH_FULL) {
      if (ch->state == CH_EMPTY && p->claim == p->c_slot) {
        /* not taken: made here */
        if (!claim_rows(p, ch)) {
          s = tt__error(w->ctx, TT_ERR_INTERNAL, "%s: row %zu of layer %s "
                        "asked for past its end", w->path, i,
                        p->layer[p->layer_now]->name);
          break;
        }
        pipe_unlock(p);
        s = fill_chunk(p, ch, w->ctx);
        pipe_lock(p);
        if (s != TT_OK)
          break;
        chunk_made(p, ch);
        break;
      }
      if (p->failed || !p->threaded) {
        s = tt__error(w->ctx, TT_ERR_INTERNAL, "%s", p->failed
                      ? tt_context_errmsg(p->m_ctx) : "rows out of order");
        break;
      }
      pthread_cond_wait(&p->cond, &p->lock); /* the maker's, being made */
    }
    pipe_unlock(p);
    if (s != TT_OK)
      return s;
    p->c_held = 1;
    if (ch->layer != p->layer_now || i != ch->first)
      return tt__error(w->ctx, TT_ERR_INTERNAL, "%s: rows of layer %s out "
                       "of order (%zu)", w->path,
                       p->layer[p->layer_now]->name, i);
    /* the chunks' extents, merged in order on this side */
    double *ext = p->layer[ch->layer]->ext;
    extend(ext, ch->ext[0], ch->ext[1]);
    extend(ext, ch->ext[2], ch->ext[3]);
  }
  size_t r = i - ch->first;
  p->vals = ch->v[r];
  p->blob = ch->blob[r];
  p->blob_len = ch->blob_len[r];
  p->row = i;
  return report(w);
}

/* The writing thread, its rows all written, packs the R-trees the maker
 * has not begun (the vertices' first: the maker begins with the
 * triangles'), so that the two share the sorts. Returns the trees it
 * packed (bit k: layer k). */
static unsigned pipe_pack_too(rows_pipe *p, size_t node_cap)
{
  unsigned mine = 0;
  if (!p->threaded || !node_cap)
    return 0;
  for (int k = 1; k >= 0; k--) {
    pthread_mutex_lock(&p->lock);
    int claimed = p->claimed[k], failed = p->failed;
    p->claimed[k] = 1;
    pthread_mutex_unlock(&p->lock);
    layer_table *t = p->layer[k];
    if (claimed || failed || !t->boxes || p->count[k] == 0)
      continue;
    /* a failure (out of memory) leaves the boxes for the page writer */
    if (tt__rtree_pack(NULL, t->name, t->boxes, p->count[k], node_cap,
                       &p->packed[k]) == TT_OK)
      t->boxes = NULL; /* the packed tree's */
    mine |= 1u << k;
  }
  return mine;
}

/* Joins the maker: after its packing when the rows went in (ok), else
 * stopping it first. */
static void pipe_join(rows_pipe *p, int ok)
{
  if (p->threaded) {
    pthread_mutex_lock(&p->lock);
    p->stop = !ok;
    pthread_cond_broadcast(&p->cond);
    pthread_mutex_unlock(&p->lock);
    pthread_join(p->thread, NULL);
    pthread_cond_destroy(&p->cond);
    pthread_mutex_destroy(&p->lock);
    p->threaded = 0;
  }
  free(p->ring);
  p->ring = NULL;
}

static void pipe_free(rows_pipe *p)
{
  pipe_join(p, 0);
  for (int k = 0; k < 2; k++)
    tt__rtree_packed_free(p->packed[k]);
  if (p->m_ctx)
    tt_context_destroy(p->m_ctx);
  memset(p, 0, sizeof *p);
}

/* Sets up the rows of both layers (nt triangles, nv vertices: 0 for a layer
 * left out by LAYERS); a maker thread when threads allow. */
static tt_status pipe_begin(rows_pipe *p, rows_state *w,
                            const tt__records *rec, layer_table *tri,
                            layer_table *vtx, size_t nt, size_t nv,
                            int threads, size_t node_cap)
{
  memset(p, 0, sizeof *p);
  p->rec = rec;
  p->layer[0] = tri;
  p->layer[1] = vtx;
  p->count[0] = nt;
  p->count[1] = nv;
  p->ncols[0] = 1 + TT__TF_COUNT;
  p->ncols[1] = 1 + tt__records_vertex_fields(rec->tin);
  p->decimated = tt__records_decimated(rec->tin);
  p->ring = calloc(NCHUNKS, sizeof *p->ring);
  if (!p->ring)
    return tt__error(w->ctx, TT_ERR_NOMEM, "out of memory");
  if (threads == 1 || p->count[0] + p->count[1] <= CHUNK_ROWS ||
      (threads <= 0 && sysconf(_SC_NPROCESSORS_ONLN) < 2))
    return TT_OK;
  p->m_ctx = tt_context_create();
  if (!p->m_ctx)
    return TT_OK;
  if (pthread_mutex_init(&p->lock, NULL) != 0)
    return TT_OK;
  if (pthread_cond_init(&p->cond, NULL) != 0) {
    pthread_mutex_destroy(&p->lock);
    return TT_OK;
  }
  p->node_cap = node_cap; /* read by the maker */
  if (pthread_create(&p->thread, NULL, maker_main, p) != 0) {
    p->node_cap = 0;
    pthread_cond_destroy(&p->cond);
    pthread_mutex_destroy(&p->lock);
    return TT_OK; /* the SQLite thread makes the rows itself */
  }
  p->threaded = 1;
  return TT_OK;
}

typedef struct rows_vtab {
  sqlite3_vtab base;
  rows_state *w;
} rows_vtab;

typedef struct rows_cursor {
  sqlite3_vtab_cursor base;
  size_t row;
} rows_cursor;

static int vt_connect(sqlite3 *db, void *aux, int argc,
                      const char *const *argv, sqlite3_vtab **out,
                      char **err)
{
  (void)argc;
  (void)argv;
  (void)err;
  char decl[16 + 5 * MAX_COLS] = "CREATE TABLE x(";
  for (int k = 0; k < MAX_COLS; k++)
    snprintf(decl + strlen(decl), sizeof decl - strlen(decl), "%sc%d",
             k ? "," : "", k);
  strcat(decl, ")");
  int rc = sqlite3_declare_vtab(db, decl);
  if (rc != SQLITE_OK)
    return rc;
  rows_vtab *vt = sqlite3_malloc(sizeof *vt);
  if (!vt)
    return SQLITE_NOMEM;
  memset(vt, 0, sizeof *vt);
  vt->w = aux;
  *out = &vt->base;
  return SQLITE_OK;
}

static int vt_disconnect(sqlite3_vtab *vt)
{
  sqlite3_free(vt);
  return SQLITE_OK;
}

static size_t vt_count(const rows_state *w)
{
  return w->pipe ? w->pipe->count[w->pipe->layer_now] : 0;
}

static int vt_best_index(sqlite3_vtab *vt, sqlite3_index_info *info)
{
  info->estimatedCost = 1e6;
  info->estimatedRows = (sqlite3_int64)vt_count(((rows_vtab *)vt)->w);
  return SQLITE_OK;
}

static int vt_open(sqlite3_vtab *vt, sqlite3_vtab_cursor **out)
{
  (void)vt;
  rows_cursor *c = sqlite3_malloc(sizeof *c);
  if (!c)
    return SQLITE_NOMEM;
  memset(c, 0, sizeof *c);
  *out = &c->base;
  return SQLITE_OK;
}

static int vt_close(sqlite3_vtab_cursor *cur)
{
  sqlite3_free(cur);
  return SQLITE_OK;
}

/* Takes row c->row, or ends the statement on failure. */
static int vt_fill(rows_cursor *c)
{
  rows_vtab *vt = (rows_vtab *)c->base.pVtab;
  rows_state *w = vt->w;
  if (c->row >= vt_count(w))
    return SQLITE_OK;
  w->status = pipe_row(w->pipe, w, c->row);
  if (w->status == TT_OK)
    return SQLITE_OK;
  sqlite3_free(vt->base.zErrMsg);
  vt->base.zErrMsg = sqlite3_mprintf("%s", tt_context_errmsg(w->ctx));
  return SQLITE_ERROR;
}

static int vt_filter(sqlite3_vtab_cursor *cur, int idx, const char *idxstr,
                     int argc, sqlite3_value **argv)
{
  (void)idx;
  (void)idxstr;
  (void)argc;
  (void)argv;
  rows_cursor *c = (rows_cursor *)cur;
  c->row = 0;
  return vt_fill(c);
}

static int vt_next(sqlite3_vtab_cursor *cur)
{
  rows_cursor *c = (rows_cursor *)cur;
  c->row++;
  return vt_fill(c);
}

static int vt_eof(sqlite3_vtab_cursor *cur)
{
  return ((rows_cursor *)cur)->row >= vt_count(((rows_vtab *)cur->pVtab)->w);
}

static int vt_column(sqlite3_vtab_cursor *cur, sqlite3_context *ctx, int col)
{
  const rows_pipe *p = ((rows_vtab *)cur->pVtab)->w->pipe;
  if (col == 0) {
    /* SQLite copies it into the record before the cursor moves on */
    sqlite3_result_blob(ctx, p->blob, p->blob_len, SQLITE_STATIC);
    return SQLITE_OK;
  }
  const row_value *v = col < p->ncols[p->layer_now] ? &p->vals[col] : NULL;
  if (!v || v->type == V_NULL)
    sqlite3_result_null(ctx);
  else if (v->type == V_INT)
    sqlite3_result_int64(ctx, v->i);
  else
    sqlite3_result_double(ctx, v->d);
  return SQLITE_OK;
}

static int vt_rowid(sqlite3_vtab_cursor *cur, sqlite3_int64 *out)
{
  *out = (sqlite3_int64)((rows_cursor *)cur)->row + 1;
  return SQLITE_OK;
}

static const sqlite3_module rows_module = {
    .iVersion = 0,
    .xCreate = NULL, /* eponymous only: nothing in the file's schema */
    .xConnect = vt_connect,
    .xBestIndex = vt_best_index,
    .xDisconnect = vt_disconnect,
    .xDestroy = vt_disconnect,
    .xOpen = vt_open,
    .xClose = vt_close,
    .xFilter = vt_filter,
    .xNext = vt_next,
    .xEof = vt_eof,
    .xColumn = vt_column,
    .xRowid = vt_rowid,
};

/* Writes the rows of layer (0: triangles, 1: vertices): INSERT ... SELECT
 * from tt__rows. */
static tt_status insert_rows(rows_state *w, int layer,
                             const tt__field_spec *fields)
{
  rows_pipe *p = w->pipe;
  layer_table *t = p->layer[layer];
  const int ncols = p->ncols[layer];
  char *sql = sqlite3_mprintf("INSERT INTO \"%w\" (\"%w\"", t->name,
                              t->geom);
  for (int i = 0; sql && i + 1 < ncols; i++) {
    char *more = sqlite3_mprintf("%s, \"%w\"", sql, fields[i].name);
    sqlite3_free(sql);
    sql = more;
  }
  for (int i = 0; sql && i < ncols; i++) {
    char *more = sqlite3_mprintf("%s%sc%d", sql, i ? ", " : ") SELECT ", i);
    sqlite3_free(sql);
    sql = more;
  }
  char *more = sql ? sqlite3_mprintf("%s FROM " ROWS_MODULE, sql) : NULL;
  sqlite3_free(sql);
  sql = more;
  if (!sql)
    return tt__error(w->ctx, TT_ERR_NOMEM, "out of memory");
  sqlite3_stmt *st = NULL;
  int rc = sqlite3_prepare_v2(w->db, sql, -1, &st, NULL);
  sqlite3_free(sql);
  if (rc != SQLITE_OK)
    return db_error(w, "cannot prepare the inserts");
  p->layer_now = layer;
  w->status = TT_OK;
  rc = p->count[layer] ? sqlite3_step(st) : SQLITE_DONE;
  tt_status s = TT_OK;
  if (w->status != TT_OK)
    s = w->status;
  else if (rc != SQLITE_DONE)
    s = tt__error(w->ctx, TT_ERR_IO, "%s: cannot write the %zu features of "
                  "layer %s: %s", w->path, p->count[layer], t->name,
                  sqlite3_errmsg(w->db));
  sqlite3_finalize(st);
  t->last_fid = sqlite3_last_insert_rowid(w->db);
  return s;
}

/* gpkg_contents' extent and gpkg_ogr_contents' count, as GDAL sets them at
 * close. */
static tt_status finish_layer(rows_state *w, const layer_table *t,
                              size_t count)
{
  sqlite3_stmt *st = NULL;
  tt_status s = TT_OK;
  if (count && t->last_fid != (sqlite3_int64)count)
    return tt__error(w->ctx, TT_ERR_INTERNAL, "%s: table %s: the last of "
                     "%zu features got fid %lld", w->path, t->name, count,
                     (long long)t->last_fid);
  if (sqlite3_prepare_v2(w->db,
                         "UPDATE gpkg_contents SET min_x = ?, min_y = ?, "
                         "max_x = ?, max_y = ?, last_change = "
                         "strftime('%Y-%m-%dT%H:%M:%fZ', 'now') WHERE "
                         "lower(table_name) = lower(?)",
                         -1, &st, NULL) != SQLITE_OK)
    return db_error(w, "cannot update gpkg_contents");
  for (int k = 0; k < 4; k++)
    if (count)
      sqlite3_bind_double(st, k + 1, t->ext[k]);
    else
      sqlite3_bind_null(st, k + 1);
  sqlite3_bind_text(st, 5, t->name, -1, SQLITE_TRANSIENT);
  if (sqlite3_step(st) != SQLITE_DONE)
    s = db_error(w, "cannot update gpkg_contents");
  sqlite3_finalize(st);
  st = NULL;
  if (s != TT_OK)
    return s;
  /* gpkg_ogr_contents is GDAL's own table: absent when the file was made
   * with ADD_GPKG_OGR_CONTENTS=NO. */
  int rc = sqlite3_prepare_v2(w->db,
                              "UPDATE gpkg_ogr_contents SET feature_count = "
                              "? WHERE lower(table_name) = lower(?)",
                              -1, &st, NULL);
  if (rc != SQLITE_OK) {
    sqlite3_finalize(st);
    return TT_OK;
  }
  sqlite3_bind_int64(st, 1, (sqlite3_int64)count);
  sqlite3_bind_text(st, 2, t->name, -1, SQLITE_TRANSIENT);
  if (sqlite3_step(st) != SQLITE_DONE)
    s = db_error(w, "cannot update gpkg_ogr_contents");
  sqlite3_finalize(st);
  return s;
}

/* --- the rows as database pages -------------------------------------------
 * PAGES=YES: the tables' B-trees are written as pages (sqlite_pages.h)
 * instead of inserted. In three steps:
 *   1. in SQLite, in the one transaction that also checked the layers: the
 *      R-trees' virtual tables, triggers and gpkg_extensions rows, their
 *      shadow tables left empty; commit, close;
 *   2. with SQLite closed: the rows of both layers and the R-trees' shadow
 *      tables appended as pages to the file, then their root pages and the
 *      database header (sqlite_pages.c);
 *   3. in SQLite again: sqlite_sequence (the AUTOINCREMENT fids), the
 *      extents and feature counts, rtreecheck() on request; commit (which
 *      syncs the file).
 * A failure or an interruption in step 2 cuts the file back to its size
 * after step 1, then the R-trees of step 1 are dropped: the layers are left
 * empty and unindexed, as the SQL path leaves them. A crash, or a failure
 * in writing the last pages of step 2 (the roots and the header), can
 * leave the file unsound: hence PAGES=YES only for a file that is thrown
 * away unless the write completes (the command's temporary output), and
 * nothing else may have it open. Otherwise, and when the file does not
 * allow pages (WAL, auto-vacuum, an index on a table, a text or defaulted
 * column, rows too large for a page), the SQL path below runs. */

enum { SRC_NULL = -2, SRC_GEOM = -1 };

/* How a layer's rows map onto its table's columns. */
typedef struct page_layout {
  char *table;    /* the name in sqlite_schema */
  uint32_t root;
  int autoinc;    /* AUTOINCREMENT: sqlite_sequence gets the last fid */
  int ncols;
  int *src;       /* per column: SRC_NULL, SRC_GEOM or a field's index */
  int *aff;       /* per column: tt__sqlite_affinity() */
} page_layout;

static void layout_free(page_layout *l)
{
  sqlite3_free(l->table);
  free(l->src);
  free(l->aff);
  memset(l, 0, sizeof *l);
}

/* The columns of t for rows of the nfields fields and a geometry blob of at
 * most blob_bytes. TT_OK with *why NULL: pages can take them; *why set: a
 * reason they cannot (the SQL path writes them). */
static tt_status layout_find(rows_state *w, const layer_table *t,
                             const tt__field_spec *fields, int nfields,
                             size_t blob_bytes, size_t max_payload,
                             page_layout *out, const char **why)
{
  memset(out, 0, sizeof *out);
  *why = NULL;
  sqlite3_stmt *st = NULL;
  tt_status s = TT_OK;
  if (sqlite3_prepare_v2(w->db,
                         "SELECT name, rootpage, sql FROM sqlite_master "
                         "WHERE type = 'table' AND lower(name) = lower(?)",
                         -1, &st, NULL) != SQLITE_OK)
    return db_error(w, "cannot read the schema");
  sqlite3_bind_text(st, 1, t->name, -1, SQLITE_TRANSIENT);
  if (sqlite3_step(st) == SQLITE_ROW) {
    out->table = sqlite3_mprintf("%s", sqlite3_column_text(st, 0));
    sqlite3_int64 root = sqlite3_column_int64(st, 1);
    out->root = root > 1 && root < 0xffffffff ? (uint32_t)root : 0;
    const char *sql = (const char *)sqlite3_column_text(st, 2);
    out->autoinc = sql && sqlite3_strlike("%AUTOINCREMENT%", sql, 0) == 0;
  }
  sqlite3_finalize(st);
  st = NULL;
  if (!out->table || !out->root) {
    *why = "its table is not in sqlite_schema";
    return TT_OK;
  }
  if (sqlite3_prepare_v2(w->db,
                         "SELECT count(*) FROM sqlite_master WHERE type = "
                         "'index' AND lower(tbl_name) = lower(?)",
                         -1, &st, NULL) != SQLITE_OK)
    return db_error(w, "cannot read the schema");
  sqlite3_bind_text(st, 1, out->table, -1, SQLITE_TRANSIENT);
  if (sqlite3_step(st) == SQLITE_ROW && sqlite3_column_int(st, 0) > 0)
    *why = "the table has an index";
  sqlite3_finalize(st);
  st = NULL;
  if (*why)
    return TT_OK;

  char *sql = sqlite3_mprintf("PRAGMA table_info(\"%w\")", out->table);
  int rc = sql ? sqlite3_prepare_v2(w->db, sql, -1, &st, NULL) : SQLITE_NOMEM;
  sqlite3_free(sql);
  if (rc != SQLITE_OK)
    return db_error(w, "cannot read the table's columns");
  int cap = 0, npk = 0, geom = 0, mapped = 0;
  while (s == TT_OK && !*why && sqlite3_step(st) == SQLITE_ROW) {
    if (out->ncols == cap) {
      cap = cap ? 2 * cap : 32;
      int *a = realloc(out->src, (size_t)cap * sizeof *a);
      if (a)
        out->src = a;
      int *b = a ? realloc(out->aff, (size_t)cap * sizeof *b) : NULL;
      if (b)
        out->aff = b;
      if (!a || !b) {
        s = tt__error(w->ctx, TT_ERR_NOMEM, "out of memory");
        break;
      }
    }
    const char *name = (const char *)sqlite3_column_text(st, 1);
    const char *type = (const char *)sqlite3_column_text(st, 2);
    int has_default = sqlite3_column_type(st, 4) != SQLITE_NULL;
    int pk = sqlite3_column_int(st, 5);
    int src = SRC_NULL;
    if (pk) {
      npk++;
      if (!type || sqlite3_stricmp(type, "INTEGER") != 0 ||
          sqlite3_stricmp(name, t->fid) != 0)
        *why = "the table's primary key is not its INTEGER fid";
    } else if (name && sqlite3_stricmp(name, t->geom) == 0) {
      src = SRC_GEOM;
      geom++;
    } else {
      for (int k = 0; name && k < nfields; k++)
        if (sqlite3_stricmp(name, fields[k].name) == 0)
          src = k;
      if (src >= 0)
        mapped++;
      else if (has_default)
        *why = "a column the rows leave out has a default";
    }
    out->src[out->ncols] = src;
    out->aff[out->ncols] = tt__sqlite_affinity(type);
    if (src >= 0 && out->aff[out->ncols] == TT__AFF_TEXT)
      *why = "a field's column has text affinity";
    out->ncols++;
  }
  sqlite3_finalize(st);
  if (s != TT_OK || *why)
    return s;
  if (npk != 1 || geom != 1 || mapped != nfields)
    *why = "the table's columns are not the layer's";
  /* header and body of the largest row: 9 bytes a serial type and 8 a
   * value, the blob */
  else if (9 + 17 * (size_t)out->ncols + blob_bytes > max_payload)
    *why = "rows too large for a page";
  return TT_OK;
}

/* Whether PAGES=YES can be followed for the layers made (lay[0]:
 * triangles, lay[1]: vertices, when written); why not in *why. */
static tt_status pages_possible(rows_state *w, const layer_table *tri,
                                const layer_table *vtx, int do_tri,
                                int do_vtx, int rtree, int nvfields,
                                page_layout lay[2], const char **why)
{
  *why = NULL;
  sqlite3_stmt *st = NULL;
  char mode[16] = "";
  int autovac = 0, page = 0;
  if (sqlite3_prepare_v2(w->db, "PRAGMA journal_mode", -1, &st, NULL) ==
          SQLITE_OK &&
      sqlite3_step(st) == SQLITE_ROW && sqlite3_column_text(st, 0))
    snprintf(mode, sizeof mode, "%s", sqlite3_column_text(st, 0));
  sqlite3_finalize(st);
  if (sqlite3_prepare_v2(w->db, "PRAGMA auto_vacuum", -1, &st, NULL) ==
          SQLITE_OK &&
      sqlite3_step(st) == SQLITE_ROW)
    autovac = sqlite3_column_int(st, 0);
  sqlite3_finalize(st);
  if (sqlite3_prepare_v2(w->db, "PRAGMA page_size", -1, &st, NULL) ==
          SQLITE_OK &&
      sqlite3_step(st) == SQLITE_ROW)
    page = sqlite3_column_int(st, 0);
  sqlite3_finalize(st);
  int reserve = -1; /* asks, changes nothing */
  if (sqlite3_file_control(w->db, "main", SQLITE_FCNTL_RESERVE_BYTES,
                           &reserve) != SQLITE_OK)
    reserve = -1;
  if (strcasecmp(mode, "wal") == 0)
    *why = "the database is in WAL mode";
  else if (autovac)
    *why = "the database has auto-vacuum";
  else if (page < 512 || reserve < 0 || page - reserve < 480)
    *why = "unknown page size";
  if (*why)
    return TT_OK;
  const size_t max_payload = tt__sqlite_max_payload((size_t)(page - reserve));
  /* R-tree nodes: the page size less 64 (whatever the reserved bytes), at
   * most 51 cells of 24 bytes (tt__gpkg_rtree_node_cap()), a blob in a
   * record of a NULL and the blob: a header of 4 bytes */
  size_t node = (size_t)page - 64 < 4 + 51 * 24 ? (size_t)page - 64
                                                : 4 + 51 * 24;
  if (rtree && node + 4 > max_payload) {
    *why = "R-tree nodes too large for a page";
    return TT_OK;
  }
  tt_status s = TT_OK;
  if (do_tri)
    s = layout_find(w, tri, tt__triangle_fields, TT__TF_COUNT,
                    TRI_BLOB_BYTES, max_payload, &lay[0], why);
  if (s == TT_OK && !*why && do_vtx)
    s = layout_find(w, vtx, tt__vertex_fields, nvfields, PT_BLOB_BYTES,
                    max_payload, &lay[1], why);
  return s;
}

/* Appends the rows of layer (0: triangles, 1: vertices) to t: the values
 * the maker made, as records of the table's columns. */
static tt_status append_layer(rows_state *w, rows_pipe *p, int layer,
                              const page_layout *lay, tt__sqlite_table *t,
                              int format)
{
  if (lay->ncols > TT__SQLITE_REC_COLS)
    return tt__error(w->ctx, TT_ERR_FORMAT, "%s: table %s has more than %d "
                     "columns", w->path, lay->table, TT__SQLITE_REC_COLS);
  unsigned char body[8 * TT__SQLITE_REC_COLS + TRI_BLOB_BYTES + 8];
  tt__sqlite_rec r;
  tt_status s = TT_OK;
  p->layer_now = layer;
  for (size_t i = 0; i < p->count[layer] && s == TT_OK; i++) {
    s = pipe_row(p, w, i);
    if (s != TT_OK)
      break;
    tt__sqlite_rec_begin(&r, body, format);
    for (int c = 0; c < lay->ncols; c++) {
      int src = lay->src[c];
      if (src == SRC_GEOM) {
        tt__sqlite_rec_bytes(&r, p->blob, (size_t)p->blob_len, 0);
        continue;
      }
      const row_value *rv = src >= 0 ? &p->vals[1 + src] : NULL;
      if (!rv || rv->type == V_NULL) {
        tt__sqlite_rec_null(&r);
        continue;
      }
      tt__sqlite_value x;
      x.type = rv->type == V_INT ? TT__SQV_INT : TT__SQV_REAL;
      x.i = rv->i;
      x.d = rv->d;
      tt__sqlite_apply_affinity(&x, lay->aff[c]);
      if (x.type == TT__SQV_INT)
        tt__sqlite_rec_int(&r, x.i);
      else
        tt__sqlite_rec_real(&r, x.d);
    }
    const unsigned char *head;
    size_t nh = tt__sqlite_rec_head(&r, &head);
    s = tt__sqlite_table_append2(t, (int64_t)i + 1, head, nh, body, r.nb);
  }
  return s;
}

/* sqlite_sequence's row of an AUTOINCREMENT table: seq, the last fid, as
 * SQLite's inserts would have left it. */
static tt_status set_sequence(rows_state *w, const page_layout *lay,
                              size_t count)
{
  if (!count || !lay->autoinc)
    return TT_OK;
  sqlite3_stmt *st = NULL;
  tt_status s = TT_OK;
  if (sqlite3_prepare_v2(w->db,
                         "UPDATE sqlite_sequence SET seq = ?1 WHERE name = "
                         "?2",
                         -1, &st, NULL) != SQLITE_OK)
    return db_error(w, "cannot update sqlite_sequence");
  sqlite3_bind_int64(st, 1, (sqlite3_int64)count);
  sqlite3_bind_text(st, 2, lay->table, -1, SQLITE_TRANSIENT);
  if (sqlite3_step(st) != SQLITE_DONE)
    s = db_error(w, "cannot update sqlite_sequence");
  sqlite3_finalize(st);
  if (s != TT_OK || sqlite3_changes(w->db) > 0)
    return s;
  if (sqlite3_prepare_v2(w->db,
                         "INSERT INTO sqlite_sequence (name, seq) VALUES "
                         "(?2, ?1)",
                         -1, &st, NULL) != SQLITE_OK)
    return db_error(w, "cannot update sqlite_sequence");
  sqlite3_bind_int64(st, 1, (sqlite3_int64)count);
  sqlite3_bind_text(st, 2, lay->table, -1, SQLITE_TRANSIENT);
  if (sqlite3_step(st) != SQLITE_DONE)
    s = db_error(w, "cannot update sqlite_sequence");
  sqlite3_finalize(st);
  return s;
}

/* What the page path works with. */
typedef struct pages_job {
  rows_state *w;
  rows_pipe *pipe;
  const tt__records *rec;
  layer_table *layer[2];
  page_layout lay[2];
  size_t count[2];
  int todo[2];
  int rtree, rtree_check, threads, journal_memory;
  int had_extensions;    /* gpkg_extensions was there before step 1 */
  tt__rtree_shadow sh[2];
} pages_job;

/* Step 2: the rows and the R-trees as pages. */
static tt_status pages_write(pages_job *j)
{
  rows_state *w = j->w;
  tt__sqlite_file *f = NULL;
  tt__sqlite_table *t[2] = {NULL, NULL};
  tt_status s = tt__sqlite_file_open(w->ctx, w->path, &f);
  const int format = s == TT_OK ? tt__sqlite_file_format(f) : 4;
  for (int k = 0; k < 2 && s == TT_OK; k++)
    if (j->todo[k])
      s = tt__sqlite_table_begin(f, j->lay[k].table, j->lay[k].root, &t[k]);
  if (s == TT_OK)
    s = pipe_begin(j->pipe, w, j->rec, j->layer[0], j->layer[1],
                   j->count[0], j->count[1], j->threads,
                   j->rtree ? j->sh[j->todo[0] ? 0 : 1].node_cap : 0);
  w->pipe = j->pipe;
  w->lo = 0.0;
  w->hi = 0.9;
  for (int k = 0; k < 2 && s == TT_OK; k++)
    if (j->todo[k])
      s = append_layer(w, j->pipe, k, &j->lay[k], t[k], format);
  unsigned mine = 0;
  if (s == TT_OK && j->rtree)
    mine = pipe_pack_too(j->pipe, j->pipe->node_cap);
  /* The tables, and the R-trees this thread packed, while the maker packs
   * the others; then those. */
  for (int k = 0; k < 2; k++)
    if (t[k] && s == TT_OK) {
      s = tt__sqlite_table_finish(t[k]);
      t[k] = NULL;
      j->layer[k]->last_fid = (sqlite3_int64)j->count[k];
    }
  int written = 0; /* trees written: progress 0.9 to 0.95 to 0.99 */
  for (int pass = 0; pass < 2; pass++) {
    if (pass == 1) {
      pipe_join(j->pipe, s == TT_OK); /* the boxes, extents, trees done */
      w->pipe = NULL;
    }
    for (int k = 1; k >= 0 && s == TT_OK; k--) {
      if (!j->rtree || !j->todo[k] || ((mine >> k) & 1) != (pass == 0))
        continue;
      w->lo = written ? 0.95 : 0.9;
      w->hi = written++ ? 0.99 : 0.95;
      s = tt__rtree_write_pages(w->ctx, j->layer[k]->name,
                                j->layer[k]->boxes, j->count[k],
                                j->pipe->packed[k], &j->sh[k], f,
                                rtree_progress, w);
    }
  }
  if (s == TT_OK)
    s = tt__sqlite_file_commit(f);
  /* without the commit the file is cut back to its size after step 1 */
  tt_status c = tt__sqlite_file_close(f);
  return s != TT_OK ? s : c;
}

/* Undoes step 1 after a failure in step 2 (w->db idle). */
static void pages_undo(pages_job *j)
{
  rows_state *w = j->w;
  if (!j->rtree)
    return;
  tt_context *quiet = tt_context_create(); /* keeps the first message */
  tt_context *ctx = quiet ? quiet : w->ctx;
  if (sqlite3_exec(w->db, "BEGIN IMMEDIATE", NULL, NULL, NULL) != SQLITE_OK)
    goto done;
  tt_status s = TT_OK;
  for (int k = 0; k < 2 && s == TT_OK; k++)
    if (j->todo[k])
      s = tt__gpkg_rtree_drop(ctx, w->db, w->path, j->layer[k]->name,
                              j->layer[k]->geom);
  if (s == TT_OK && !j->had_extensions &&
      sqlite3_exec(w->db, "DROP TABLE IF EXISTS gpkg_extensions", NULL,
                   NULL, NULL) != SQLITE_OK)
    s = TT_ERR_IO;
  sqlite3_exec(w->db, s == TT_OK ? "COMMIT" : "ROLLBACK", NULL, NULL, NULL);
done:
  if (quiet)
    tt_context_destroy(quiet);
}

/* Steps 1 (from the open transaction of w->db, which it ends) to 3. Between
 * steps 1 and 3 the connection stays open but idle: in rollback-journal
 * mode it then holds no lock (which the page writer's own descriptor,
 * closed after step 2, would cancel) and no page it trusts: the change
 * counter the page writer raises makes SQLite drop its cache at the next
 * transaction, and the schema is unchanged. */
static tt_status pages_run(pages_job *j)
{
  rows_state *w = j->w;
  tt_status s = TT_OK;
  j->had_extensions =
      sqlite3_table_column_metadata(w->db, NULL, "gpkg_extensions",
                                    "extension_name", NULL, NULL, NULL, NULL,
                                    NULL) == SQLITE_OK;
  /* Step 1 needs no sync: a crash before step 3 ends loses the file. The
   * transaction so far only read; the setting needs none open. */
  int sync = 2;
  sqlite3_stmt *st = NULL;
  if (sqlite3_prepare_v2(w->db, "PRAGMA synchronous", -1, &st, NULL) ==
          SQLITE_OK &&
      sqlite3_step(st) == SQLITE_ROW)
    sync = sqlite3_column_int(st, 0);
  sqlite3_finalize(st);
  s = exec(w, "COMMIT; PRAGMA synchronous = OFF; BEGIN IMMEDIATE",
           "cannot start a transaction");
  for (int k = 0; k < 2 && s == TT_OK && j->rtree; k++)
    if (j->todo[k])
      s = tt__gpkg_rtree_create_empty(w->ctx, w->db, w->path,
                                      j->layer[k]->name, j->layer[k]->geom,
                                      &j->sh[k]);
  if (s == TT_OK)
    s = exec(w, "COMMIT", "cannot commit the spatial indexes");
  if (s != TT_OK) {
    sqlite3_exec(w->db, "ROLLBACK", NULL, NULL, NULL);
    return s;
  }
  char pragma[48];
  snprintf(pragma, sizeof pragma, "PRAGMA synchronous = %d", sync);
  s = exec(w, pragma, "cannot set synchronous");

  if (s == TT_OK)
    s = pages_write(j);
  if (s != TT_OK) {
    pages_undo(j);
    return s;
  }

  s = exec(w, "BEGIN IMMEDIATE", "cannot start a transaction");
  for (int k = 0; k < 2 && s == TT_OK; k++)
    if (j->todo[k]) {
      s = set_sequence(w, &j->lay[k], j->count[k]);
      if (s == TT_OK)
        s = finish_layer(w, j->layer[k], j->count[k]);
    }
  for (int k = 0; k < 2 && s == TT_OK && j->rtree_check && j->rtree; k++) {
    if (!j->todo[k])
      continue;
    char *sql = sqlite3_mprintf("SELECT rtreecheck(%Q)", j->sh[k].rtree);
    int rc = sql ? sqlite3_prepare_v2(w->db, sql, -1, &st, NULL)
                 : SQLITE_NOMEM;
    sqlite3_free(sql);
    const char *msg = rc == SQLITE_OK && sqlite3_step(st) == SQLITE_ROW
                          ? (const char *)sqlite3_column_text(st, 0) : NULL;
    if (!msg || strcmp(msg, "ok") != 0)
      s = tt__error(w->ctx, TT_ERR_INTERNAL, "%s: the R-tree %s fails "
                    "rtreecheck(): %.300s", w->path, j->sh[k].rtree,
                    msg ? msg : sqlite3_errmsg(w->db));
    sqlite3_finalize(st);
    st = NULL;
  }
  if (s == TT_OK)
    s = exec(w, "COMMIT", "cannot commit the TIN");
  else
    sqlite3_exec(w->db, "ROLLBACK", NULL, NULL, NULL);
  return s;
}

tt_status tt_gpkg_write_rows(tt_context *ctx, const char *gpkg_path,
                             const tt_tin *tin, OGRSpatialReferenceH srs,
                             char **options, tt_progress_fn progress,
                             void *progress_arg)
{
  if (!gpkg_path || !tin)
    return tt__error(ctx, TT_ERR_ARG, "path and TIN must not be NULL");
  rows_state w;
  tt__records rec;
  layer_table tri, vtx;
  memset(&w, 0, sizeof w);
  memset(&rec, 0, sizeof rec);
  memset(&tri, 0, sizeof tri);
  memset(&vtx, 0, sizeof vtx);
  w.ctx = ctx;
  w.path = gpkg_path;
  w.progress = progress;
  w.progress_arg = progress_arg;
  const char *prefix = "", *t_srs = NULL;
  int in_transaction = 0, rtree = 1, rtree_check = 0, threads = 0;
  int journal_memory = 0, pages = 0;
  unsigned layers = TT__LAYERS_ALL;
  rows_pipe pipe;
  memset(&pipe, 0, sizeof pipe);
  pages_job job; /* PAGES=YES */
  memset(&job, 0, sizeof job);
  char *tri_name = NULL, *vtx_name = NULL;
  tt_status s = TT_OK;

  for (char **o = options; o && *o; o++) {
    char *key = NULL;
    const char *value = CPLParseNameValue(*o, &key);
    if (!key || !value)
      s = tt__error(ctx, TT_ERR_ARG, "write option \"%s\" is not "
                    "NAME=VALUE", *o);
    else if (strcasecmp(key, "NLN_PREFIX") == 0)
      prefix = value;
    else if (strcasecmp(key, "T_SRS") == 0)
      t_srs = value;
    else if (strcasecmp(key, "LCO") == 0) {
      char *lkey = NULL;
      const char *lvalue = CPLParseNameValue(value, &lkey);
      if (lkey && lvalue && strcasecmp(lkey, "SPATIAL_INDEX") == 0)
        rtree = CPLTestBool(lvalue);
      CPLFree(lkey);
    } else if (strcasecmp(key, "RTREE_CHECK") == 0)
      rtree_check = CPLTestBool(value);
    else if (strcasecmp(key, "LAYERS") == 0)
      s = tt__records_parse_layers(ctx, value, &layers);
    else if (strcasecmp(key, "THREADS") == 0)
      threads = atoi(value);
    else if (strcasecmp(key, "JOURNAL") == 0)
      journal_memory = strcasecmp(value, "MEMORY") == 0;
    else if (strcasecmp(key, "PAGES") == 0)
      pages = CPLTestBool(value);
    else if (strcasecmp(key, "ROWS") != 0 && strcasecmp(key, "RTREE") != 0 &&
             strcasecmp(key, "STYLE") != 0 &&
             strcasecmp(key, "OVERWRITE") != 0)
      s = tt__error(ctx, TT_ERR_ARG, "unknown write option \"%s\" (known: "
                    "JOURNAL, NLN_PREFIX, LAYERS, LCO, OVERWRITE, PAGES, "
                    "ROWS, RTREE, RTREE_CHECK, STYLE, T_SRS, THREADS)", key);
    CPLFree(key);
    if (s != TT_OK)
      return s;
  }
  /* Only the layers asked for (LAYERS) were made: the others count as
   * empty here. */
  const int do_tri = (layers & TT__LAYER_TRIANGLES) != 0;
  const int do_vtx = (layers & TT__LAYER_VERTICES) != 0;
  const size_t nv = do_vtx ? tt_tin_vertex_count(tin) : 0;
  const size_t nt = do_tri ? tt_tin_triangle_count(tin) : 0;
  w.total = nv + nt;
  w.step = (w.total + 99) / 100;
  w.next_report = w.step;
  w.lo = 0.0;
  w.hi = 0.7; /* the rows; the R-trees take the rest */
  if (progress && !progress(0.0, "writing", progress_arg))
    return tt__error(ctx, TT_ERR_INTERRUPTED, "writing the TIN was "
                     "interrupted before the first feature");
  s = tt__records_init(&rec, ctx, tin, srs, t_srs);
  if (s != TT_OK)
    goto done;
  tri_name = CPLStrdup(CPLSPrintf("%striangles", prefix));
  vtx_name = CPLStrdup(CPLSPrintf("%svertices", prefix));

  if (sqlite3_open_v2(gpkg_path, &w.db,
                      SQLITE_OPEN_READWRITE | SQLITE_OPEN_NOMUTEX, NULL) !=
      SQLITE_OK) {
    s = tt__error(ctx, TT_ERR_IO, "%s: cannot open the GeoPackage: %s",
                  gpkg_path, w.db ? sqlite3_errmsg(w.db) : "out of memory");
    goto done;
  }
  sqlite3_extended_result_codes(w.db, 1);
  if (sqlite3_create_module_v2(w.db, ROWS_MODULE, &rows_module, &w, NULL) !=
      SQLITE_OK) {
    s = db_error(&w, "cannot register the row source");
    goto done;
  }
  if (journal_memory) {
    s = exec(&w, "PRAGMA journal_mode = MEMORY", "cannot set the journal");
    if (s != TT_OK)
      goto done;
  }
  s = exec(&w, "BEGIN IMMEDIATE", "cannot start a transaction");
  if (s != TT_OK)
    goto done;
  in_transaction = 1;
  if (do_tri)
    s = layer_find(&w, tri_name, &tri);
  if (s == TT_OK && do_vtx)
    s = layer_find(&w, vtx_name, &vtx);
  if (s == TT_OK && rtree) {
    tri.boxes = malloc((nt ? nt : 1) * sizeof *tri.boxes);
    vtx.boxes = malloc((nv ? nv : 1) * sizeof *vtx.boxes);
    if (!tri.boxes || !vtx.boxes)
      s = tt__error(ctx, TT_ERR_NOMEM, "%s: out of memory for the spatial "
                    "index of %zu features", gpkg_path, nt + nv);
  }
  const char *why = NULL;
  if (s == TT_OK && pages)
    s = pages_possible(&w, &tri, &vtx, do_tri, do_vtx, rtree,
                       tt__records_vertex_fields(tin), job.lay, &why);
  if (s == TT_OK && pages && why)
    CPLDebug("terratin", "%s: the rows go through SQLite, not as pages: %s",
             gpkg_path, why);
  if (s == TT_OK && pages && !why) {
    job.w = &w;
    job.pipe = &pipe;
    job.rec = &rec;
    job.layer[0] = &tri;
    job.layer[1] = &vtx;
    job.count[0] = nt;
    job.count[1] = nv;
    job.todo[0] = do_tri;
    job.todo[1] = do_vtx;
    job.rtree = rtree;
    job.rtree_check = rtree_check;
    job.threads = threads;
    job.journal_memory = journal_memory;
    in_transaction = 0; /* pages_run ends it */
    s = pages_run(&job);
    if (s == TT_OK && progress)
      progress(1.0, "writing", progress_arg); /* done: too late to stop */
    goto done;
  }
  if (s == TT_OK && do_tri)
    s = triggers_drop(&w, &tri);
  if (s == TT_OK && do_vtx)
    s = triggers_drop(&w, &vtx);
  if (s == TT_OK) {
    s = pipe_begin(&pipe, &w, &rec, &tri, &vtx, nt, nv, threads,
                   rtree ? tt__gpkg_rtree_node_cap(w.db) : 0);
    w.pipe = &pipe;
  }
  if (s == TT_OK && do_tri)
    s = insert_rows(&w, 0, tt__triangle_fields);
  if (s == TT_OK && do_vtx)
    s = insert_rows(&w, 1, tt__vertex_fields);
  pipe_join(&pipe, s == TT_OK); /* the boxes and extents are complete */
  w.pipe = NULL;
  if (s == TT_OK && do_tri)
    s = triggers_restore(&w, &tri);
  if (s == TT_OK && do_vtx)
    s = triggers_restore(&w, &vtx);
  if (s == TT_OK && do_tri)
    s = finish_layer(&w, &tri, nt);
  if (s == TT_OK && do_vtx)
    s = finish_layer(&w, &vtx, nv);
  /* The R-trees from the boxes just written, in the same transaction. */
  w.lo = 0.7;
  w.hi = 0.93;
  if (s == TT_OK && rtree && do_tri)
    s = tt__gpkg_rtree_from_boxes(ctx, w.db, gpkg_path, tri.name, tri.geom,
                                  tri.boxes, nt, pipe.packed[0], rtree_check,
                                  rtree_progress,
                                  &w);
  w.lo = 0.93;
  w.hi = 0.99;
  if (s == TT_OK && rtree && do_vtx)
    s = tt__gpkg_rtree_from_boxes(ctx, w.db, gpkg_path, vtx.name, vtx.geom,
                                  vtx.boxes, nv, pipe.packed[1], rtree_check,
                                  rtree_progress,
                                  &w);
  if (s == TT_OK) {
    s = exec(&w, "COMMIT", "cannot commit the TIN");
    if (s == TT_OK)
      in_transaction = 0;
  }
  if (s == TT_OK && progress)
    progress(1.0, "writing", progress_arg); /* done: too late to stop */
done:
  pipe_free(&pipe); /* before the tables the maker fills */
  for (int k = 0; k < 2; k++) {
    layout_free(&job.lay[k]);
    tt__rtree_shadow_free(&job.sh[k]);
  }
  if (in_transaction)
    sqlite3_exec(w.db, "ROLLBACK", NULL, NULL, NULL);
  if (w.db && sqlite3_close(w.db) != SQLITE_OK && s == TT_OK)
    s = tt__error(ctx, TT_ERR_IO, "%s: cannot close the GeoPackage",
                  gpkg_path);
  layer_free(&tri);
  layer_free(&vtx);
  CPLFree(tri_name);
  CPLFree(vtx_name);
  tt__records_free(&rec);
  return s;
}

/* --- the pages row by row, for a streamed write (gpkg_stream.h) -----------
 * pages_run()'s steps 1 to 3 split so that a tiled run
 * (io_gpkg_stream.c) can append rows as its tiles finish instead of from a
 * whole TIN: open makes step 1 and begins the tables, each row is
 * encoded as append_layer() encodes it and its box handed to its layer's
 * R-tree, which writes its leaves block by block (tt__rtree_stream), a
 * block ending at a cut the caller marks; finish ends step 2 (the last
 * blocks, the trees' upper levels and roots) and makes step 3. Nothing
 * above changes.
 *
 * The block: 65,536 boxes. On the 8193² fractal (2.0 M features, tiles of
 * 1,024) blocks of 16,384, 65,536 and 262,144 gave trees whose 1,000
 * random windows of 0.1, 1 and 5 % of the extent's side visit as many
 * nodes as the whole-layer STR tree's (within 1 %); a block a batch gave
 * up to 4 times as many for the vertices, whose batches split tiles.
 * 65,536 boxes cost about 5 MB a layer with their scratch. */

/* The boxes an R-tree block gathers at least before its leaves are
 * packed and written (RTREE_BLOCK; docs/scale.md has the measurements). */
#define STREAM_RTREE_BLOCK 65536

struct tt__gpkg_pages {
  rows_state w;
  layer_table layer[2];
  pages_job job;
  tt__sqlite_file *f;
  tt__sqlite_table *t[2];
  tt__rtree_stream *rs[2]; /* the R-trees, leaves packed as rows come */
  int format;
  int finished;
  char *names[2];
};

tt_status tt__gpkg_pages_open(tt_context *ctx, const char *path,
                              char **options, int nvfields,
                              tt__gpkg_pages **out)
{
  *out = NULL;
  tt__gpkg_pages *p = calloc(1, sizeof *p);
  if (!p)
    return tt__error(ctx, TT_ERR_NOMEM, "out of memory");
  rows_state *w = &p->w;
  pages_job *j = &p->job;
  w->ctx = ctx;
  w->path = path;
  j->w = w;
  j->layer[0] = &p->layer[0];
  j->layer[1] = &p->layer[1];
  j->rtree = 1;
  const char *prefix = "";
  unsigned layers = TT__LAYERS_ALL;
  int journal_memory = 0;
  size_t block = STREAM_RTREE_BLOCK;
  tt_status s = TT_OK;
  for (char **o = options; o && *o && s == TT_OK; o++) {
    char *key = NULL;
    const char *value = CPLParseNameValue(*o, &key);
    if (!key || !value)
      s = tt__error(ctx, TT_ERR_ARG, "write option \"%s\" is not "
                    "NAME=VALUE", *o);
    else if (strcasecmp(key, "NLN_PREFIX") == 0)
      prefix = value;
    else if (strcasecmp(key, "LCO") == 0) {
      char *lkey = NULL;
      const char *lvalue = CPLParseNameValue(value, &lkey);
      if (lkey && lvalue && strcasecmp(lkey, "SPATIAL_INDEX") == 0)
        j->rtree = CPLTestBool(lvalue);
      CPLFree(lkey);
    } else if (strcasecmp(key, "RTREE_CHECK") == 0)
      j->rtree_check = CPLTestBool(value);
    else if (strcasecmp(key, "LAYERS") == 0)
      s = tt__records_parse_layers(ctx, value, &layers);
    else if (strcasecmp(key, "JOURNAL") == 0)
      journal_memory = strcasecmp(value, "MEMORY") == 0;
    else if (strcasecmp(key, "RTREE_BLOCK") == 0) {
      char *end = NULL;
      long long v = strtoll(value, &end, 10);
      if (!end || *end || v < 1)
        s = tt__error(ctx, TT_ERR_ARG, "RTREE_BLOCK must be a count of "
                      "features, got \"%s\"", value);
      else
        block = (size_t)v;
    }
    CPLFree(key);
  }
  j->todo[0] = (layers & TT__LAYER_TRIANGLES) != 0;
  j->todo[1] = (layers & TT__LAYER_VERTICES) != 0;
  p->names[0] = CPLStrdup(CPLSPrintf("%striangles", prefix));
  p->names[1] = CPLStrdup(CPLSPrintf("%svertices", prefix));
  *out = p;
  if (s != TT_OK)
    return s;
  if (sqlite3_open_v2(path, &w->db,
                      SQLITE_OPEN_READWRITE | SQLITE_OPEN_NOMUTEX, NULL) !=
      SQLITE_OK)
    return tt__error(ctx, TT_ERR_IO, "%s: cannot open the GeoPackage: %s",
                     path, w->db ? sqlite3_errmsg(w->db) : "out of memory");
  sqlite3_extended_result_codes(w->db, 1);
  if (journal_memory)
    s = exec(w, "PRAGMA journal_mode = MEMORY", "cannot set the journal");
  if (s == TT_OK)
    s = exec(w, "BEGIN IMMEDIATE", "cannot start a transaction");
  for (int k = 0; k < 2 && s == TT_OK; k++)
    if (j->todo[k])
      s = layer_find(w, p->names[k], &p->layer[k]);
  const char *why = NULL;
  if (s == TT_OK)
    s = pages_possible(w, &p->layer[0], &p->layer[1], j->todo[0],
                       j->todo[1], j->rtree, nvfields, j->lay, &why);
  if (s == TT_OK && why)
    s = tt__error(ctx, TT_ERR_FORMAT, "%s: the rows cannot be written as "
                  "pages: %s", path, why);
  if (s != TT_OK) {
    sqlite3_exec(w->db, "ROLLBACK", NULL, NULL, NULL);
    return s;
  }
  /* step 1, as pages_run() makes it */
  j->had_extensions =
      sqlite3_table_column_metadata(w->db, NULL, "gpkg_extensions",
                                    "extension_name", NULL, NULL, NULL, NULL,
                                    NULL) == SQLITE_OK;
  int sync = 2;
  sqlite3_stmt *st = NULL;
  if (sqlite3_prepare_v2(w->db, "PRAGMA synchronous", -1, &st, NULL) ==
          SQLITE_OK &&
      sqlite3_step(st) == SQLITE_ROW)
    sync = sqlite3_column_int(st, 0);
  sqlite3_finalize(st);
  s = exec(w, "COMMIT; PRAGMA synchronous = OFF; BEGIN IMMEDIATE",
           "cannot start a transaction");
  for (int k = 0; k < 2 && s == TT_OK && j->rtree; k++)
    if (j->todo[k])
      s = tt__gpkg_rtree_create_empty(ctx, w->db, path, p->layer[k].name,
                                      p->layer[k].geom, &j->sh[k]);
  if (s == TT_OK)
    s = exec(w, "COMMIT", "cannot commit the spatial indexes");
  if (s != TT_OK) {
    sqlite3_exec(w->db, "ROLLBACK", NULL, NULL, NULL);
    memset(j->sh, 0, sizeof j->sh); /* rolled back: nothing to undo */
    j->rtree = 0;
    return s;
  }
  char pragma[48];
  snprintf(pragma, sizeof pragma, "PRAGMA synchronous = %d", sync);
  s = exec(w, pragma, "cannot set synchronous");
  /* step 2 begins */
  if (s == TT_OK)
    s = tt__sqlite_file_open(ctx, path, &p->f);
  p->format = s == TT_OK ? tt__sqlite_file_format(p->f) : 4;
  for (int k = 0; k < 2 && s == TT_OK; k++)
    if (j->todo[k]) {
      if (j->lay[k].ncols > TT__SQLITE_REC_COLS)
        s = tt__error(ctx, TT_ERR_FORMAT, "%s: table %s has more than %d "
                      "columns", path, j->lay[k].table, TT__SQLITE_REC_COLS);
      else
        s = tt__sqlite_table_begin(p->f, j->lay[k].table, j->lay[k].root,
                                   &p->t[k]);
      if (s == TT_OK && j->rtree)
        s = tt__rtree_stream_create(ctx, p->layer[k].name, &j->sh[k], p->f,
                                    block, &p->rs[k]);
    }
  return s;
}

int tt__gpkg_pages_has(const tt__gpkg_pages *p, int layer)
{
  return p->job.todo[layer];
}

int32_t tt__gpkg_pages_srs_id(const tt__gpkg_pages *p, int layer)
{
  return p->layer[layer].srs_id;
}

int tt__gpkg_pages_rtree(const tt__gpkg_pages *p)
{
  return p->job.rtree;
}

tt_status tt__gpkg_pages_row(tt__gpkg_pages *p, int layer, int64_t fid,
                             const tt__gpkg_value *fields,
                             const unsigned char *blob, size_t blob_len,
                             const tt__rtree_box *box)
{
  const page_layout *lay = &p->job.lay[layer];
  unsigned char body[8 * TT__SQLITE_REC_COLS + TRI_BLOB_BYTES + 8];
  tt__sqlite_rec r;
  tt__sqlite_rec_begin(&r, body, p->format);
  for (int c = 0; c < lay->ncols; c++) {
    int src = lay->src[c];
    if (src == SRC_GEOM) {
      tt__sqlite_rec_bytes(&r, blob, blob_len, 0);
      continue;
    }
    const tt__gpkg_value *v = src >= 0 ? &fields[src] : NULL;
    if (!v || v->type == TT__GV_NULL) {
      tt__sqlite_rec_null(&r);
      continue;
    }
    tt__sqlite_value x;
    x.type = v->type == TT__GV_INT ? TT__SQV_INT : TT__SQV_REAL;
    x.i = v->i;
    x.d = v->d;
    tt__sqlite_apply_affinity(&x, lay->aff[c]);
    if (x.type == TT__SQV_INT)
      tt__sqlite_rec_int(&r, x.i);
    else
      tt__sqlite_rec_real(&r, x.d);
  }
  const unsigned char *head;
  size_t nh = tt__sqlite_rec_head(&r, &head);
  tt_status s = tt__sqlite_table_append2(p->t[layer], fid, head, nh, body,
                                         r.nb);
  if (s == TT_OK && p->rs[layer])
    s = box ? tt__rtree_stream_add(p->rs[layer], box)
            : tt__error(p->w.ctx, TT_ERR_INTERNAL, "%s: a row without its "
                        "box for the R-tree", p->w.path);
  return s;
}

tt_status tt__gpkg_pages_cut(tt__gpkg_pages *p, int layer)
{
  return p->rs[layer] ? tt__rtree_stream_cut(p->rs[layer]) : TT_OK;
}

size_t tt__gpkg_pages_bytes(const tt__gpkg_pages *p)
{
  return p ? tt__rtree_stream_bytes(p->rs[0]) +
                 tt__rtree_stream_bytes(p->rs[1])
           : 0;
}

tt_status tt__gpkg_pages_finish(tt__gpkg_pages *p, const size_t count[2],
                                const double ext[2][4],
                                tt_progress_fn progress, void *progress_arg)
{
  rows_state *w = &p->w;
  pages_job *j = &p->job;
  tt_status s = TT_OK;
  w->progress = progress;
  w->progress_arg = progress_arg;
  for (int k = 0; k < 2; k++) {
    j->count[k] = j->todo[k] ? count[k] : 0;
    memcpy(p->layer[k].ext, ext[k], sizeof p->layer[k].ext);
    if (p->t[k] && s == TT_OK) {
      s = tt__sqlite_table_finish(p->t[k]);
      p->t[k] = NULL;
      p->layer[k].last_fid = (sqlite3_int64)j->count[k];
    }
  }
  /* the vertices' index first: what it holds is freed before the
   * triangles' (twice as many) is finished */
  for (int k = 1; k >= 0 && s == TT_OK; k--) {
    if (!p->rs[k])
      continue;
    w->lo = k ? 0.0 : 0.3;
    w->hi = k ? 0.3 : 0.9;
    s = tt__rtree_stream_finish(p->rs[k], rtree_progress, w);
    tt__rtree_stream_free(p->rs[k]);
    p->rs[k] = NULL;
  }
  if (s == TT_OK)
    s = tt__sqlite_file_commit(p->f);
  tt_status c = tt__sqlite_file_close(p->f);
  p->f = NULL;
  if (s == TT_OK)
    s = c;
  if (s != TT_OK)
    return s; /* close() undoes step 1 */
  p->finished = 1; /* the pages are in: step 3 */
  s = exec(w, "BEGIN IMMEDIATE", "cannot start a transaction");
  for (int k = 0; k < 2 && s == TT_OK; k++)
    if (j->todo[k]) {
      s = set_sequence(w, &j->lay[k], j->count[k]);
      if (s == TT_OK)
        s = finish_layer(w, &p->layer[k], j->count[k]);
    }
  for (int k = 0; k < 2 && s == TT_OK && j->rtree_check && j->rtree; k++) {
    if (!j->todo[k])
      continue;
    sqlite3_stmt *st = NULL;
    char *sql = sqlite3_mprintf("SELECT rtreecheck(%Q)", j->sh[k].rtree);
    int rc = sql ? sqlite3_prepare_v2(w->db, sql, -1, &st, NULL)
                 : SQLITE_NOMEM;
    sqlite3_free(sql);
    const char *msg = rc == SQLITE_OK && sqlite3_step(st) == SQLITE_ROW
                          ? (const char *)sqlite3_column_text(st, 0) : NULL;
    if (!msg || strcmp(msg, "ok") != 0)
      s = tt__error(w->ctx, TT_ERR_INTERNAL, "%s: the R-tree %s fails "
                    "rtreecheck(): %.300s", w->path, j->sh[k].rtree,
                    msg ? msg : sqlite3_errmsg(w->db));
    sqlite3_finalize(st);
  }
  if (s == TT_OK)
    s = exec(w, "COMMIT", "cannot commit the TIN");
  else
    sqlite3_exec(w->db, "ROLLBACK", NULL, NULL, NULL);
  if (s == TT_OK && progress)
    progress(1.0, "writing", progress_arg);
  return s;
}

void tt__gpkg_pages_close(tt__gpkg_pages *p)
{
  if (!p)
    return;
  tt__rtree_stream_free(p->rs[0]);
  tt__rtree_stream_free(p->rs[1]);
  if (p->f) /* not committed: the file is cut back to step 1's size */
    tt__sqlite_file_close(p->f);
  if (!p->finished && p->w.db && p->job.rtree)
    pages_undo(&p->job);
  if (p->w.db)
    sqlite3_close(p->w.db);
  for (int k = 0; k < 2; k++) {
    layout_free(&p->job.lay[k]);
    tt__rtree_shadow_free(&p->job.sh[k]);
    layer_free(&p->layer[k]);
    CPLFree(p->names[k]);
  }
  free(p);
}
