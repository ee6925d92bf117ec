/*
 * src/gdal/gpkg/ -- the GeoPackage fast path: a TIN's rows, SQLite database
 * pages, R-trees and a tiled run's streamed write, straight into the file
 * rather than through OGR.
 *
 * gpkg_rows_pages.c -- the GeoPackage row writer's page path
 * (gpkg_rows.h): PAGES=YES for a whole TIN (tt_gpkg_write_rows), and the
 * same pages row by row for a streamed tiled run (tt__gpkg_pages_*,
 * gpkg_stream.h).
 *
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
 * column, rows too large for a page), the SQL path of gpkg_rows.c runs.
 */

#include "gdal/gpkg/gpkg_rows.h"

#include <cpl_conv.h>
#include <cpl_string.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

void tt__rows_layout_free(page_layout *l)
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

/* Why the file of db cannot take pages (WAL mode, auto-vacuum, a page
 * layout not known), else NULL; its page size and reserved bytes. */
static const char *file_why_not(sqlite3 *db, int *out_page, int *out_reserve)
{
  sqlite3_stmt *st = NULL;
  char mode[16] = "";
  int autovac = 0, page = 0;
  if (sqlite3_prepare_v2(db, "PRAGMA journal_mode", -1, &st, NULL) ==
          SQLITE_OK &&
      sqlite3_step(st) == SQLITE_ROW && sqlite3_column_text(st, 0))
    snprintf(mode, sizeof mode, "%s", sqlite3_column_text(st, 0));
  sqlite3_finalize(st);
  if (sqlite3_prepare_v2(db, "PRAGMA auto_vacuum", -1, &st, NULL) ==
          SQLITE_OK &&
      sqlite3_step(st) == SQLITE_ROW)
    autovac = sqlite3_column_int(st, 0);
  sqlite3_finalize(st);
  if (sqlite3_prepare_v2(db, "PRAGMA page_size", -1, &st, NULL) ==
          SQLITE_OK &&
      sqlite3_step(st) == SQLITE_ROW)
    page = sqlite3_column_int(st, 0);
  sqlite3_finalize(st);
  int reserve = -1; /* asks, changes nothing */
  if (sqlite3_file_control(db, "main", SQLITE_FCNTL_RESERVE_BYTES,
                           &reserve) != SQLITE_OK)
    reserve = -1;
  *out_page = page;
  *out_reserve = reserve;
  if (strcasecmp(mode, "wal") == 0)
    return "the database is in WAL mode";
  if (autovac)
    return "the database has auto-vacuum";
  if (page < 512 || reserve < 0 || page - reserve < 480)
    return "unknown page size";
  return NULL;
}

tt_status tt__gpkg_pages_check(tt_context *ctx, const char *path)
{
  sqlite3 *db = NULL;
  if (sqlite3_open_v2(path, &db, SQLITE_OPEN_READONLY | SQLITE_OPEN_NOMUTEX,
                      NULL) != SQLITE_OK) {
    tt_status s = tt__error(ctx, TT_ERR_IO, "%s: cannot open the "
                            "GeoPackage: %s", path,
                            db ? sqlite3_errmsg(db) : "out of memory");
    sqlite3_close(db);
    return s;
  }
  int page, reserve;
  const char *why = file_why_not(db, &page, &reserve);
  sqlite3_close(db);
  if (why)
    return tt__error(ctx, TT_ERR_FORMAT, "%s: the rows cannot be written "
                     "as pages: %s", path, why);
  return TT_OK;
}

/* Whether PAGES=YES can be followed for the layers made (lay[0]:
 * triangles, lay[1]: vertices, when written); why not in *why. */
tt_status tt__rows_pages_possible(rows_state *w, const layer_table *tri,
                                const layer_table *vtx, int do_tri,
                                int do_vtx, int rtree, int ntfields,
                                int nvfields,
                                page_layout lay[2], const char **why)
{
  int page, reserve;
  *why = file_why_not(w->db, &page, &reserve);
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
    s = layout_find(w, tri, tt__triangle_fields, ntfields,
                    TRI_BLOB_BYTES, max_payload, &lay[0], why);
  if (s == TT_OK && !*why && do_vtx)
    s = layout_find(w, vtx, tt__vertex_fields, nvfields, PT_BLOB_BYTES,
                    max_payload, &lay[1], why);
  return s;
}

/* Appends the rows of layer (0: triangles, 1: vertices) to t: the values
 * the maker made, as records of the table's columns. */
/* Appends the row fid of lay's table to t: the record of its columns from
 * the layer's fields (tin_records.h's order) and the geometry blob, with
 * the columns' affinities applied as an INSERT would. Both page paths
 * encode their rows here. lay->ncols is at most TT__SQLITE_REC_COLS. */
static tt_status append_row(tt__sqlite_table *t, const page_layout *lay,
                            int format, int64_t fid,
                            const tt__gpkg_value *fields,
                            const unsigned char *blob, size_t blob_len)
{
  unsigned char body[8 * TT__SQLITE_REC_COLS + TRI_BLOB_BYTES + 8];
  tt__sqlite_rec r;
  tt__sqlite_rec_begin(&r, body, format);
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
  return tt__sqlite_table_append2(t, fid, head, nh, body, r.nb);
}

static tt_status check_columns(rows_state *w, const page_layout *lay)
{
  if (lay->ncols <= TT__SQLITE_REC_COLS)
    return TT_OK;
  return tt__error(w->ctx, TT_ERR_FORMAT, "%s: table %s has more than %d "
                   "columns", w->path, lay->table, TT__SQLITE_REC_COLS);
}

static tt_status append_layer(rows_state *w, rows_pipe *p, int layer,
                              const page_layout *lay, tt__sqlite_table *t,
                              int format)
{
  tt_status s = check_columns(w, lay);
  p->layer_now = layer;
  for (size_t i = 0; i < p->count[layer] && s == TT_OK; i++) {
    s = tt__rows_pipe_row(p, w, i);
    if (s == TT_OK)
      s = append_row(t, lay, format, (int64_t)i + 1, p->vals + 1, p->blob,
                     (size_t)p->blob_len);
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


/* The R-trees of the layers in which (bit k: layer k), the vertices'
 * first, as pages of f; *written counts the trees written (progress 0.9
 * to 0.95 to 0.99). pages_write() calls it for the trees this thread
 * packed before the row maker is joined, and for the maker's after the
 * join: a tree's packed nodes are read only once its packer is known to
 * be done, and `which` is this thread's own value, never read from what
 * the maker writes. */
static tt_status write_trees(pages_job *j, tt__sqlite_file *f,
                             unsigned which, int *written)
{
  rows_state *w = j->w;
  tt_status s = TT_OK;
  for (int k = 1; k >= 0 && s == TT_OK; k--) {
    if (!j->rtree || !j->todo[k] || !(which & (1u << k)))
      continue;
    w->lo = *written ? 0.95 : 0.9;
    w->hi = (*written)++ ? 0.99 : 0.95;
    s = tt__rtree_write_pages(w->ctx, j->layer[k]->name,
                              j->layer[k]->boxes, j->count[k],
                              j->pipe->packed[k], &j->sh[k], f,
                              rtree_progress, w);
  }
  return s;
}

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
    s = tt__rows_pipe_begin(j->pipe, w, j->rec, j->layer[0], j->layer[1],
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
    mine = tt__rows_pipe_pack_too(j->pipe, j->pipe->node_cap);
  /* The tables, and the R-trees this thread packed, while the maker packs
   * the others; then those. */
  for (int k = 0; k < 2; k++)
    if (t[k] && s == TT_OK) {
      s = tt__sqlite_table_finish(t[k]);
      t[k] = NULL;
      j->layer[k]->last_fid = (sqlite3_int64)j->count[k];
    }
  int written = 0; /* trees written: progress 0.9 to 0.95 to 0.99 */
  if (s == TT_OK)
    s = write_trees(j, f, mine, &written);
  tt__rows_pipe_join(j->pipe, s == TT_OK); /* the boxes, extents, trees */
  w->pipe = NULL;
  if (s == TT_OK)
    s = write_trees(j, f, ~mine & 3u, &written);
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

/* Step 1, from the open transaction of j->w->db, which it ends: the
 * R-trees' virtual tables, triggers and gpkg_extensions rows, their shadow
 * tables empty (j->sh), committed without a sync (a crash before step 3
 * ends loses the file anyway; the transaction so far only read, and the
 * setting needs none open). On failure it is rolled back: nothing to
 * undo (j->rtree 0). */
static tt_status pages_step1(pages_job *j)
{
  rows_state *w = j->w;
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
  tt_status s = exec(w, "COMMIT; PRAGMA synchronous = OFF; BEGIN IMMEDIATE",
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
    for (int k = 0; k < 2; k++)
      tt__rtree_shadow_free(&j->sh[k]);
    j->rtree = 0;
    return s;
  }
  char pragma[48];
  snprintf(pragma, sizeof pragma, "PRAGMA synchronous = %d", sync);
  return exec(w, pragma, "cannot set synchronous");
}

/* Step 3, in SQLite again: sqlite_sequence, the extents and counts,
 * rtreecheck() on request; committed (which syncs the file), else rolled
 * back. */
static tt_status pages_step3(pages_job *j)
{
  rows_state *w = j->w;
  tt_status s = exec(w, "BEGIN IMMEDIATE", "cannot start a transaction");
  for (int k = 0; k < 2 && s == TT_OK; k++)
    if (j->todo[k]) {
      s = set_sequence(w, &j->lay[k], j->count[k]);
      if (s == TT_OK)
        s = tt__rows_finish_layer(w, j->layer[k], j->count[k]);
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
  return s;
}

/* Steps 1 (from the open transaction of w->db, which it ends) to 3. Between
 * steps 1 and 3 the connection stays open but idle: in rollback-journal
 * mode it then holds no lock (which the page writer's own descriptor,
 * closed after step 2, would cancel) and no page it trusts: the change
 * counter the page writer raises makes SQLite drop its cache at the next
 * transaction, and the schema is unchanged. */
tt_status tt__rows_pages_run(pages_job *j)
{
  tt_status s = pages_step1(j);
  if (s == TT_OK)
    s = pages_write(j);
  if (s != TT_OK) {
    pages_undo(j);
    return s;
  }
  return pages_step3(j);
}

/* --- the pages row by row, for a streamed write (gpkg_stream.h) -----------
 * The steps of tt__rows_pages_run() split so that a tiled run
 * (gpkg_stream.c) can append rows as its tiles finish instead of from a
 * whole TIN: open makes step 1 (pages_step1) and begins the tables, each
 * row is encoded by append_row() as the whole TIN's are and its box handed
 * to its layer's R-tree, which writes its leaves block by block
 * (tt__rtree_stream), a block ending at a cut the caller marks; finish
 * ends step 2 (the last blocks, the trees' upper levels and roots) and
 * makes step 3 (pages_step3).
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
      s = tt__rows_layer_find(w, p->names[k], &p->layer[k]);
  const char *why = NULL;
  if (s == TT_OK)
    s = tt__rows_pages_possible(w, &p->layer[0], &p->layer[1], j->todo[0],
                       j->todo[1], j->rtree, TT__TF_COUNT - 1, nvfields,
                       j->lay, &why);
  if (s == TT_OK && why)
    s = tt__error(ctx, TT_ERR_FORMAT, "%s: the rows cannot be written as "
                  "pages: %s", path, why);
  if (s != TT_OK) {
    sqlite3_exec(w->db, "ROLLBACK", NULL, NULL, NULL);
    return s;
  }
  s = pages_step1(j);
  /* step 2 begins */
  if (s == TT_OK)
    s = tt__sqlite_file_open(ctx, path, &p->f);
  p->format = s == TT_OK ? tt__sqlite_file_format(p->f) : 4;
  for (int k = 0; k < 2 && s == TT_OK; k++)
    if (j->todo[k]) {
      s = check_columns(w, &j->lay[k]);
      if (s == TT_OK)
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
  tt_status s = append_row(p->t[layer], &p->job.lay[layer], p->format, fid,
                           fields, blob, blob_len);
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
  s = pages_step3(j);
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
    tt__rows_layout_free(&p->job.lay[k]);
    tt__rtree_shadow_free(&p->job.sh[k]);
    tt__rows_layer_free(&p->layer[k]);
    CPLFree(p->names[k]);
  }
  free(p);
}
