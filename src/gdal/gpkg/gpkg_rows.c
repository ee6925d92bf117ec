/*
 * src/gdal/gpkg/ -- the GeoPackage fast path: a TIN's rows, SQLite database
 * pages, R-trees and a tiled run's streamed write, straight into the file
 * rather than through OGR.
 *
 * gpkg_rows.c -- the rows of a TIN's triangles and vertices layers
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
 * The files: here tt_gpkg_write_rows(), the layers' tables found and
 * finished, and the SQL path; gpkg_rows_pipe.c makes the rows (a second
 * thread); gpkg_rows_pages.c writes them as pages, for a whole TIN and
 * row by row for a streamed tiled run; gpkg_rows.h is what they share.
 *
 * As pages (PAGES=YES; gpkg_rows_pages.c): the tables'
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
#include "gdal/gpkg/gpkg_rows.h"

#include <cpl_conv.h>
#include <cpl_string.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

void tt__rows_layer_free(layer_table *t)
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
tt_status tt__rows_layer_find(rows_state *w, const char *name, layer_table *t)
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

/* gpkg_contents' extent and gpkg_ogr_contents' count, as GDAL sets them at
 * close. */
tt_status tt__rows_finish_layer(rows_state *w, const layer_table *t,
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

/* --- the rows as a virtual table ------------------------------------------
 * One INSERT INTO t (geom, fields...) SELECT c0, c1... FROM tt__rows writes
 * a whole layer: tt__rows is an eponymous virtual table of this connection
 * whose cursor hands SQLite the rows of the layer being written, so SQLite
 * reads the values straight from here, with no bound parameters to copy,
 * and updates sqlite_sequence once per layer. (Batches of 64 rows of bound
 * parameters, the earlier way, took 5,500 instructions a triangle in
 * SQLite's bind and VDBE code.)
 * The rows come from gpkg_rows_pipe.c. */

#define ROWS_MODULE "tt__rows"

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
  w->status = tt__rows_pipe_row(w->pipe, w, c->row);
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

/* The write options (those of tt_ogr_write_tin that concern only it are
 * accepted and ignored). */
typedef struct rows_options {
  const char *prefix, *t_srs;   /* NLN_PREFIX, T_SRS: point into options */
  int rtree, rtree_check;       /* LCO=SPATIAL_INDEX, RTREE_CHECK */
  int threads, journal_memory, pages; /* THREADS, JOURNAL=MEMORY, PAGES */
  unsigned layers;              /* LAYERS: TT__LAYER_* bits */
} rows_options;

/* One write of the rows, from the open to the close. */
typedef struct rows_write {
  rows_state w;        /* the connection (the row source's aux: stays put) */
  rows_options o;
  tt__records rec;
  layer_table tri, vtx;
  rows_pipe pipe;
  pages_job job;       /* PAGES=YES */
  int do_tri, do_vtx;  /* the layers LAYERS made; the others count as empty */
  size_t nt, nv;
  int in_transaction;
  char *tri_name, *vtx_name;
} rows_write;

static tt_status parse_rows_options(tt_context *ctx, char **options,
                                    rows_options *o)
{
  o->prefix = "";
  o->t_srs = NULL;
  o->rtree = 1;
  o->rtree_check = 0;
  o->threads = 0;
  o->journal_memory = 0;
  o->pages = 0;
  o->layers = TT__LAYERS_ALL;
  tt_status s = TT_OK;
  for (char **opt = options; opt && *opt; opt++) {
    char *key = NULL;
    const char *value = CPLParseNameValue(*opt, &key);
    if (!key || !value)
      s = tt__error(ctx, TT_ERR_ARG, "write option \"%s\" is not "
                    "NAME=VALUE", *opt);
    else if (strcasecmp(key, "NLN_PREFIX") == 0)
      o->prefix = value;
    else if (strcasecmp(key, "T_SRS") == 0)
      o->t_srs = value;
    else if (strcasecmp(key, "LCO") == 0) {
      char *lkey = NULL;
      const char *lvalue = CPLParseNameValue(value, &lkey);
      if (lkey && lvalue && strcasecmp(lkey, "SPATIAL_INDEX") == 0)
        o->rtree = CPLTestBool(lvalue);
      CPLFree(lkey);
    } else if (strcasecmp(key, "RTREE_CHECK") == 0)
      o->rtree_check = CPLTestBool(value);
    else if (strcasecmp(key, "LAYERS") == 0)
      s = tt__records_parse_layers(ctx, value, &o->layers);
    else if (strcasecmp(key, "THREADS") == 0)
      o->threads = atoi(value);
    else if (strcasecmp(key, "JOURNAL") == 0)
      o->journal_memory = strcasecmp(value, "MEMORY") == 0;
    else if (strcasecmp(key, "PAGES") == 0)
      o->pages = CPLTestBool(value);
    else if (strcasecmp(key, "ROWS") != 0 && strcasecmp(key, "RTREE") != 0 &&
             strcasecmp(key, "STYLE") != 0 &&
             strcasecmp(key, "Z_UNIT") != 0 &&
             strcasecmp(key, "OVERWRITE") != 0)
      s = tt__error(ctx, TT_ERR_ARG, "unknown write option \"%s\" (known: "
                    "JOURNAL, NLN_PREFIX, LAYERS, LCO, OVERWRITE, PAGES, "
                    "ROWS, RTREE, RTREE_CHECK, STYLE, T_SRS, THREADS, Z_UNIT)",
                    key);
    CPLFree(key);
    if (s != TT_OK)
      return s;
  }
  return TT_OK;
}

/* The GeoPackage opened, the row source registered, the journal set, and
 * the one IMMEDIATE transaction begun. */
static tt_status open_gpkg(rows_write *rw)
{
  rows_state *w = &rw->w;
  if (sqlite3_open_v2(w->path, &w->db,
                      SQLITE_OPEN_READWRITE | SQLITE_OPEN_NOMUTEX, NULL) !=
      SQLITE_OK)
    return tt__error(w->ctx, TT_ERR_IO, "%s: cannot open the GeoPackage: %s",
                     w->path,
                     w->db ? sqlite3_errmsg(w->db) : "out of memory");
  sqlite3_extended_result_codes(w->db, 1);
  if (sqlite3_create_module_v2(w->db, ROWS_MODULE, &rows_module, w, NULL) !=
      SQLITE_OK)
    return db_error(w, "cannot register the row source");
  if (rw->o.journal_memory) {
    tt_status s = exec(w, "PRAGMA journal_mode = MEMORY",
                       "cannot set the journal");
    if (s != TT_OK)
      return s;
  }
  tt_status s = exec(w, "BEGIN IMMEDIATE", "cannot start a transaction");
  if (s != TT_OK)
    return s;
  rw->in_transaction = 1;
  return TT_OK;
}

/* The layers' tables found, and the boxes of their R-trees allocated. */
static tt_status find_layers(rows_write *rw)
{
  tt_status s = TT_OK;
  if (rw->do_tri)
    s = tt__rows_layer_find(&rw->w, rw->tri_name, &rw->tri);
  if (s == TT_OK && rw->do_vtx)
    s = tt__rows_layer_find(&rw->w, rw->vtx_name, &rw->vtx);
  if (s == TT_OK && rw->o.rtree) {
    rw->tri.boxes = malloc((rw->nt ? rw->nt : 1) * sizeof *rw->tri.boxes);
    rw->vtx.boxes = malloc((rw->nv ? rw->nv : 1) * sizeof *rw->vtx.boxes);
    if (!rw->tri.boxes || !rw->vtx.boxes)
      s = tt__error(rw->w.ctx, TT_ERR_NOMEM, "%s: out of memory for the "
                    "spatial index of %zu features", rw->w.path,
                    rw->nt + rw->nv);
  }
  return s;
}

/* PAGES=YES, the file allowing it: the page path (gpkg_rows_pages.c),
 * which ends the transaction. */
static tt_status write_as_pages(rows_write *rw)
{
  pages_job *job = &rw->job;
  job->w = &rw->w;
  job->pipe = &rw->pipe;
  job->rec = &rw->rec;
  job->layer[0] = &rw->tri;
  job->layer[1] = &rw->vtx;
  job->count[0] = rw->nt;
  job->count[1] = rw->nv;
  job->todo[0] = rw->do_tri;
  job->todo[1] = rw->do_vtx;
  job->rtree = rw->o.rtree;
  job->rtree_check = rw->o.rtree_check;
  job->threads = rw->o.threads;
  job->journal_memory = rw->o.journal_memory;
  rw->in_transaction = 0; /* pages_run ends it */
  tt_status s = tt__rows_pages_run(job);
  if (s == TT_OK && rw->w.progress)
    rw->w.progress(1.0, "writing", rw->w.progress_arg); /* done: too late
                                                          to stop */
  return s;
}

/* The SQL path: the feature-count triggers dropped, each layer inserted
 * from the row source (the rows made on the pipe), the triggers back, the
 * extents and counts, the R-trees from the boxes just written, all in the
 * one transaction, then the commit. */
static tt_status write_through_sql(rows_write *rw)
{
  rows_state *w = &rw->w;
  layer_table *tri = &rw->tri, *vtx = &rw->vtx;
  const int do_tri = rw->do_tri, do_vtx = rw->do_vtx;
  tt_status s = TT_OK;
  if (do_tri)
    s = triggers_drop(w, tri);
  if (s == TT_OK && do_vtx)
    s = triggers_drop(w, vtx);
  if (s == TT_OK) {
    s = tt__rows_pipe_begin(&rw->pipe, w, &rw->rec, tri, vtx, rw->nt, rw->nv,
                            rw->o.threads,
                            rw->o.rtree ? tt__gpkg_rtree_node_cap(w->db) : 0);
    w->pipe = &rw->pipe;
  }
  if (s == TT_OK && do_tri)
    s = insert_rows(w, 0, tt__triangle_fields);
  if (s == TT_OK && do_vtx)
    s = insert_rows(w, 1, tt__vertex_fields);
  tt__rows_pipe_join(&rw->pipe, s == TT_OK); /* the boxes and extents done */
  w->pipe = NULL;
  if (s == TT_OK && do_tri)
    s = triggers_restore(w, tri);
  if (s == TT_OK && do_vtx)
    s = triggers_restore(w, vtx);
  if (s == TT_OK && do_tri)
    s = tt__rows_finish_layer(w, tri, rw->nt);
  if (s == TT_OK && do_vtx)
    s = tt__rows_finish_layer(w, vtx, rw->nv);
  /* The R-trees from the boxes just written, in the same transaction. */
  w->lo = 0.7;
  w->hi = 0.93;
  if (s == TT_OK && rw->o.rtree && do_tri)
    s = tt__gpkg_rtree_from_boxes(w->ctx, w->db, w->path, tri->name,
                                  tri->geom, tri->boxes, rw->nt,
                                  rw->pipe.packed[0], rw->o.rtree_check,
                                  rtree_progress, w);
  w->lo = 0.93;
  w->hi = 0.99;
  if (s == TT_OK && rw->o.rtree && do_vtx)
    s = tt__gpkg_rtree_from_boxes(w->ctx, w->db, w->path, vtx->name,
                                  vtx->geom, vtx->boxes, rw->nv,
                                  rw->pipe.packed[1], rw->o.rtree_check,
                                  rtree_progress, w);
  if (s == TT_OK) {
    s = exec(w, "COMMIT", "cannot commit the TIN");
    if (s == TT_OK)
      rw->in_transaction = 0;
  }
  if (s == TT_OK && w->progress)
    w->progress(1.0, "writing", w->progress_arg); /* done: too late to stop */
  return s;
}

/* Everything freed, a transaction still open rolled back, the file
 * closed; s, or the close's failure. */
static tt_status end_rows_write(rows_write *rw, tt_status s)
{
  rows_state *w = &rw->w;
  tt__rows_pipe_free(&rw->pipe); /* before the tables the maker fills */
  for (int k = 0; k < 2; k++) {
    tt__rows_layout_free(&rw->job.lay[k]);
    tt__rtree_shadow_free(&rw->job.sh[k]);
  }
  if (rw->in_transaction)
    sqlite3_exec(w->db, "ROLLBACK", NULL, NULL, NULL);
  if (w->db && sqlite3_close(w->db) != SQLITE_OK && s == TT_OK)
    s = tt__error(w->ctx, TT_ERR_IO, "%s: cannot close the GeoPackage",
                  w->path);
  tt__rows_layer_free(&rw->tri);
  tt__rows_layer_free(&rw->vtx);
  CPLFree(rw->tri_name);
  CPLFree(rw->vtx_name);
  tt__records_free(&rw->rec);
  return s;
}

tt_status tt_gpkg_write_rows(tt_context *ctx, const char *gpkg_path,
                             const tt_tin *tin, OGRSpatialReferenceH srs,
                             char **options, tt_progress_fn progress,
                             void *progress_arg)
{
  if (!gpkg_path || !tin)
    return tt__error(ctx, TT_ERR_ARG, "path and TIN must not be NULL");
  rows_write rw;
  memset(&rw, 0, sizeof rw);
  rows_state *w = &rw.w;
  w->ctx = ctx;
  w->path = gpkg_path;
  w->progress = progress;
  w->progress_arg = progress_arg;
  tt_status s = parse_rows_options(ctx, options, &rw.o);
  if (s != TT_OK)
    return s;
  /* Only the layers asked for (LAYERS) were made: the others count as
   * empty here. */
  rw.do_tri = (rw.o.layers & TT__LAYER_TRIANGLES) != 0;
  rw.do_vtx = (rw.o.layers & TT__LAYER_VERTICES) != 0;
  rw.nv = rw.do_vtx ? tt_tin_vertex_count(tin) : 0;
  rw.nt = rw.do_tri ? tt_tin_triangle_count(tin) : 0;
  w->total = rw.nv + rw.nt;
  w->step = (w->total + 99) / 100;
  w->next_report = w->step;
  w->lo = 0.0;
  w->hi = 0.7; /* the rows; the R-trees take the rest */
  if (progress && !progress(0.0, "writing", progress_arg))
    return tt__error(ctx, TT_ERR_INTERRUPTED, "writing the TIN was "
                     "interrupted before the first feature");
  s = tt__records_init(&rw.rec, ctx, tin, srs, rw.o.t_srs);
  if (s != TT_OK)
    goto done;
  rw.tri_name = CPLStrdup(CPLSPrintf("%striangles", rw.o.prefix));
  rw.vtx_name = CPLStrdup(CPLSPrintf("%svertices", rw.o.prefix));

  s = open_gpkg(&rw);
  if (s == TT_OK)
    s = find_layers(&rw);
  const char *why = NULL;
  if (s == TT_OK && rw.o.pages)
    s = tt__rows_pages_possible(w, &rw.tri, &rw.vtx, rw.do_tri, rw.do_vtx,
                                rw.o.rtree, tt__records_triangle_fields(tin),
                                tt__records_vertex_fields(tin),
                                rw.job.lay, &why);
  if (s == TT_OK && rw.o.pages && why)
    CPLDebug("terratin", "%s: the rows go through SQLite, not as pages: %s",
             gpkg_path, why);
  if (s == TT_OK && rw.o.pages && !why)
    s = write_as_pages(&rw);
  else if (s == TT_OK)
    s = write_through_sql(&rw);
done:
  return end_rows_write(&rw, s);
}
