/*
 * io_gpkg_rows.c -- the rows of a TIN's triangles and vertices layers
 * written straight into a closed GeoPackage with the sqlite3 C API.
 *
 * tt_ogr_write_tin(ROWS=DEFERRED) makes the layers through OGR (tables,
 * fields, gpkg_contents, gpkg_geometry_columns, the feature-count triggers
 * and gpkg_ogr_contents: the metadata GDAL knows how to get right) and the
 * run_parameters row; this file then fills the two big tables with
 * prepared INSERTs of 64 rows each, as OGR would have filled them feature
 * by feature but without a feature object, a geometry object and a
 * statement per row. The content is the same: the same fids (1..n in TIN
 * order, given by SQLite's append path in a table that never had rows),
 * the same columns and values (NaN as NULL), the same geometry
 * blobs, which are the GeoPackage binary header ("GP", version 0, flags,
 * srs_id, envelope) followed by ISO WKB, byte for byte as GDAL 3.6 writes
 * them:
 *   triangles: flags 0x05 (little endian, XYZ envelope: minx maxx miny maxy
 *              minz maxz), WKB Polygon Z (1003), one ring of 4 points, the
 *              first repeated last;
 *   vertices:  flags 0x01 (little endian, no envelope, as GDAL writes
 *              points), WKB Point Z (1001).
 * Afterwards gpkg_contents gets the layers' extents and gpkg_ogr_contents
 * their feature counts, which GDAL would have set at close. The
 * feature-count triggers would update gpkg_ogr_contents once per row: they
 * are dropped for the inserts and re-created from their own SQL, as GDAL
 * itself does around bulk writes.
 *
 * The R-trees of both layers are then packed from the boxes just written
 * (gpkg_rtree.h), unless LCO=SPATIAL_INDEX=NO. Everything happens in one
 * IMMEDIATE transaction: a failure (disk full, an interruption through
 * progress) rolls back and leaves the file with its empty layers, as it
 * was. tests/gdal/test_gpkg_rows.c compares every row, blob and index
 * table with the OGR writer's.
 *
 * Workload: O(triangles + vertices) inserts of fixed-size rows (a 165-byte
 * and a 37-byte blob); memory 40 bytes a feature for the boxes, SQLite's
 * page cache and, with T_SRS, 16 bytes a vertex.
 */
#include "gdal/gpkg_rtree.h"
#include "gdal/tin_records.h"

#include <cpl_conv.h>
#include <cpl_string.h>

#include <sqlite3.h>

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

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

/* Little-endian stores, whatever the host's order. */
static unsigned char *put_u32(unsigned char *p, uint32_t v)
{
  for (int k = 0; k < 4; k++)
    *p++ = (unsigned char)(v >> (8 * k));
  return p;
}

static unsigned char *put_f64(unsigned char *p, double d)
{
  uint64_t v;
  memcpy(&v, &d, sizeof v);
  for (int k = 0; k < 8; k++)
    *p++ = (unsigned char)(v >> (8 * k));
  return p;
}

static unsigned char *put_header(unsigned char *p, unsigned flags,
                                 int32_t srs_id)
{
  *p++ = 'G';
  *p++ = 'P';
  *p++ = 0; /* version 1 of the blob format */
  *p++ = (unsigned char)flags;
  return put_u32(p, (uint32_t)srs_id);
}

static void extend(layer_table *t, double x, double y)
{
  if (x < t->ext[0]) t->ext[0] = x;
  if (y < t->ext[1]) t->ext[1] = y;
  if (x > t->ext[2]) t->ext[2] = x;
  if (y > t->ext[3]) t->ext[3] = y;
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

static void bind_real(sqlite3_stmt *st, int col, double v)
{
  if (isfinite(v))
    sqlite3_bind_double(st, col, v);
  else
    sqlite3_bind_null(st, col);
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

/* INSERT INTO t (fid, geom, field...) VALUES (?, ?, ?...), (...) with
 * nrows rows of values: one statement per batch of rows, since each
 * statement also ends by updating sqlite_sequence (the tables are
 * AUTOINCREMENT) and that costs as much as a row. */
static tt_status prepare_insert(rows_state *w, const layer_table *t,
                                const tt__field_spec *fields, int nfields,
                                int nrows, sqlite3_stmt **out_st)
{
  char *sql = sqlite3_mprintf("INSERT INTO \"%w\" (\"%w\"", t->name,
                              t->geom);
  for (int i = 0; sql && i < nfields; i++) {
    char *more = sqlite3_mprintf("%s, \"%w\"", sql, fields[i].name);
    sqlite3_free(sql);
    sql = more;
  }
  for (int r = 0; sql && r < nrows; r++)
    for (int i = 0; sql && i < nfields + 2; i++) {
      const char *part = i == nfields + 1 ? ")"
                         : i == 0         ? (r ? ", (?" : ") VALUES (?")
                                          : ", ?";
      char *more = sqlite3_mprintf("%s%s", sql, part);
      sqlite3_free(sql);
      sql = more;
    }
  if (!sql)
    return tt__error(w->ctx, TT_ERR_NOMEM, "out of memory");
  int rc = sqlite3_prepare_v2(w->db, sql, -1, out_st, NULL);
  sqlite3_free(sql);
  if (rc != SQLITE_OK)
    return db_error(w, "cannot prepare the inserts");
  return TT_OK;
}

/* Rows go in batches of BATCH_ROWS per statement; the last batch gets a
 * statement of its own size. */
#define BATCH_ROWS 64

typedef struct batch {
  rows_state *w;
  const layer_table *t;
  const tt__field_spec *fields;
  int nfields, ncols;
  sqlite3_stmt *full, *tail;
} batch;

/* The statement for the rows [first, first + n) and n itself. */
static tt_status batch_statement(batch *b, size_t first, size_t count,
                                 sqlite3_stmt **out_st, int *out_n)
{
  size_t n = count - first < BATCH_ROWS ? count - first : BATCH_ROWS;
  *out_n = (int)n;
  if (n == BATCH_ROWS) {
    if (!b->full) {
      tt_status s = prepare_insert(b->w, b->t, b->fields, b->nfields,
                                   BATCH_ROWS, &b->full);
      if (s != TT_OK)
        return s;
    }
    *out_st = b->full;
    return TT_OK;
  }
  sqlite3_finalize(b->tail);
  b->tail = NULL;
  tt_status s = prepare_insert(b->w, b->t, b->fields, b->nfields, (int)n,
                               &b->tail);
  *out_st = b->tail;
  return s;
}

static tt_status batch_step(batch *b, sqlite3_stmt *st, size_t first, int n)
{
  int rc = sqlite3_step(st);
  sqlite3_reset(st);
  if (rc != SQLITE_DONE)
    return tt__error(b->w->ctx, TT_ERR_IO, "%s: cannot write features %zu "
                     "to %zu of layer %s: %s", b->w->path, first,
                     first + (size_t)n - 1, b->t->name,
                     sqlite3_errmsg(b->w->db));
  for (int k = 0; k < n; k++) {
    tt_status s = report(b->w);
    if (s != TT_OK)
      return s;
  }
  return TT_OK;
}

static void batch_free(batch *b)
{
  sqlite3_finalize(b->full);
  sqlite3_finalize(b->tail);
}

static tt_status write_triangles(rows_state *w, const tt__records *rec,
                                 layer_table *t)
{
  batch b = {w, t, tt__triangle_fields, TT__TF_COUNT, TT__TF_COUNT + 1,
             NULL, NULL};
  unsigned char blobs[BATCH_ROWS][TRI_BLOB_BYTES];
  tt_status s = TT_OK;
  const size_t nt = tt_tin_triangle_count(rec->tin);
  for (size_t first = 0; s == TT_OK && first < nt; first += BATCH_ROWS) {
    sqlite3_stmt *st = NULL;
    int n = 0;
    s = batch_statement(&b, first, nt, &st, &n);
    for (int r = 0; s == TT_OK && r < n; r++) {
      size_t i = first + (size_t)r;
      tt_triangle_info tr;
      tt_vertex_info v[3];
      double px[3], py[3];
      s = tt__records_triangle(rec, w->ctx, i, &tr, v, px, py);
      if (s != TT_OK)
        break;
      double lo[3] = {px[0], py[0], v[0].z}, hi[3] = {px[0], py[0], v[0].z};
      for (int k = 1; k < 3; k++) {
        double c[3] = {px[k], py[k], v[k].z};
        for (int d = 0; d < 3; d++) {
          if (c[d] < lo[d]) lo[d] = c[d];
          if (c[d] > hi[d]) hi[d] = c[d];
        }
      }
      unsigned char *blob = blobs[r];
      unsigned char *p = put_header(blob, 0x05, t->srs_id);
      for (int d = 0; d < 3; d++) {
        p = put_f64(p, lo[d]);
        p = put_f64(p, hi[d]);
      }
      *p++ = 1; /* WKB little endian */
      p = put_u32(p, 1003);
      p = put_u32(p, 1);
      p = put_u32(p, 4);
      for (int k = 0; k < 4; k++) {
        p = put_f64(p, px[k % 3]);
        p = put_f64(p, py[k % 3]);
        p = put_f64(p, v[k % 3].z);
      }
      extend(t, lo[0], lo[1]);
      extend(t, hi[0], hi[1]);
      if (t->boxes)
        t->boxes[i] = (tt__rtree_box){(int64_t)i + 1, lo[0], hi[0], lo[1],
                                      hi[1]};
      int c = r * b.ncols + 1;
      sqlite3_bind_blob(st, c, blob, (int)(p - blob), SQLITE_STATIC);
      c += 1;
      sqlite3_bind_int64(st, c + TT__TF_V0, tr.v[0]);
      sqlite3_bind_int64(st, c + TT__TF_V1, tr.v[1]);
      sqlite3_bind_int64(st, c + TT__TF_V2, tr.v[2]);
      bind_real(st, c + TT__TF_MAX_ERR, tr.max_error);
      bind_real(st, c + TT__TF_RMSE, tr.rmse);
      sqlite3_bind_int64(st, c + TT__TF_N_SAMPLES,
                         (sqlite3_int64)tr.samples);
      bind_real(st, c + TT__TF_AREA_2D, tr.area_2d);
      bind_real(st, c + TT__TF_AREA_3D, tr.area_3d);
      bind_real(st, c + TT__TF_SLOPE, tr.slope_deg);
      bind_real(st, c + TT__TF_ASPECT, tr.aspect_deg);
      bind_real(st, c + TT__TF_MIN_ANGLE, tr.min_angle_deg);
      bind_real(st, c + TT__TF_MAX_ANGLE, tr.max_angle_deg);
    }
    if (s == TT_OK)
      s = batch_step(&b, st, first, n);
  }
  t->last_fid = sqlite3_last_insert_rowid(w->db);
  batch_free(&b);
  return s;
}

static tt_status write_vertices(rows_state *w, const tt__records *rec,
                                layer_table *t)
{
  const int nf = tt__records_vertex_fields(rec->tin);
  const int decimated = tt__records_decimated(rec->tin);
  batch b = {w, t, tt__vertex_fields, nf, nf + 1, NULL, NULL};
  unsigned char blobs[BATCH_ROWS][PT_BLOB_BYTES];
  tt_status s = TT_OK;
  const size_t nv = tt_tin_vertex_count(rec->tin);
  for (size_t first = 0; s == TT_OK && first < nv; first += BATCH_ROWS) {
    sqlite3_stmt *st = NULL;
    int n = 0;
    s = batch_statement(&b, first, nv, &st, &n);
    for (int r = 0; s == TT_OK && r < n; r++) {
      size_t i = first + (size_t)r;
      tt_vertex_info v;
      double x, y;
      s = tt__records_vertex(rec, w->ctx, i, &v, &x, &y);
      if (s != TT_OK)
        break;
      unsigned char *blob = blobs[r];
      unsigned char *p = put_header(blob, 0x01, t->srs_id);
      *p++ = 1;
      p = put_u32(p, 1001);
      p = put_f64(p, x);
      p = put_f64(p, y);
      p = put_f64(p, v.z);
      extend(t, x, y);
      if (t->boxes)
        t->boxes[i] = (tt__rtree_box){(int64_t)i + 1, x, x, y, y};
      int c = r * b.ncols + 1;
      sqlite3_bind_blob(st, c, blob, (int)(p - blob), SQLITE_STATIC);
      c += 1;
      sqlite3_bind_int64(st, c + TT__VF_ID, (sqlite3_int64)i);
      sqlite3_bind_int64(st, c + TT__VF_COL, v.col);
      sqlite3_bind_int64(st, c + TT__VF_ROW, v.row);
      bind_real(st, c + TT__VF_INS_ERR, v.insert_error);
      if (decimated)
        sqlite3_bind_null(st, c + TT__VF_INS_RANK);
      else
        sqlite3_bind_int64(st, c + TT__VF_INS_RANK, (sqlite3_int64)v.rank);
      bind_real(st, c + TT__VF_STAR_MAX, v.star_max_error);
      bind_real(st, c + TT__VF_STAR_RMSE, v.star_rmse);
      sqlite3_bind_int64(st, c + TT__VF_STAR_N,
                         (sqlite3_int64)v.star_samples);
      if (decimated)
        bind_real(st, c + TT__VF_IMPORTANCE, v.importance);
    }
    if (s == TT_OK)
      s = batch_step(&b, st, first, n);
  }
  t->last_fid = sqlite3_last_insert_rowid(w->db);
  batch_free(&b);
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
  int in_transaction = 0, rtree = 1, rtree_check = 0;
  unsigned layers = TT__LAYERS_ALL;
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
    else if (strcasecmp(key, "ROWS") != 0 && strcasecmp(key, "RTREE") != 0 &&
             strcasecmp(key, "STYLE") != 0 &&
             strcasecmp(key, "OVERWRITE") != 0)
      s = tt__error(ctx, TT_ERR_ARG, "unknown write option \"%s\" (known: "
                    "NLN_PREFIX, LAYERS, LCO, OVERWRITE, ROWS, RTREE, "
                    "RTREE_CHECK, STYLE, T_SRS)", key);
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
  if (s == TT_OK && do_tri)
    s = triggers_drop(&w, &tri);
  if (s == TT_OK && do_vtx)
    s = triggers_drop(&w, &vtx);
  if (s == TT_OK && do_tri)
    s = write_triangles(&w, &rec, &tri);
  if (s == TT_OK && do_vtx)
    s = write_vertices(&w, &rec, &vtx);
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
                                  tri.boxes, nt, rtree_check, rtree_progress,
                                  &w);
  w.lo = 0.93;
  w.hi = 0.99;
  if (s == TT_OK && rtree && do_vtx)
    s = tt__gpkg_rtree_from_boxes(ctx, w.db, gpkg_path, vtx.name, vtx.geom,
                                  vtx.boxes, nv, rtree_check, rtree_progress,
                                  &w);
  if (s == TT_OK) {
    s = exec(&w, "COMMIT", "cannot commit the TIN");
    if (s == TT_OK)
      in_transaction = 0;
  }
  if (s == TT_OK && progress)
    progress(1.0, "writing", progress_arg); /* done: too late to stop */
done:
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
