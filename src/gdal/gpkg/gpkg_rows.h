/*
 * src/gdal/gpkg/ -- the GeoPackage fast path: a TIN's rows, SQLite database
 * pages, R-trees and a tiled run's streamed write, straight into the file
 * rather than through OGR.
 *
 * gpkg_rows.h -- what the files of the GeoPackage row writer share, private
 * to them: gpkg_rows.c (tt_gpkg_write_rows; the layers' tables found and
 * finished; the SQL path, a virtual table SQLite inserts from),
 * gpkg_rows_pipe.c (the rows made, on a second thread while the first
 * writes) and gpkg_rows_pages.c (the page path, whole or row by row for
 * a streamed tiled run). gpkg_rows.c's opening comment describes the
 * writer.
 */
#ifndef TERRATIN_GPKG_ROWS_H
#define TERRATIN_GPKG_ROWS_H

#include "base/internal.h"
#include "gdal/gpkg/gpkg_rtree.h"
#include "gdal/gpkg/gpkg_stream.h"
#include "gdal/gpkg/sqlite_pages.h"
#include "gdal/ogr/tin_records.h"

#include <sqlite3.h>

#include <pthread.h>
#include <stdint.h>

#define TRI_BLOB_BYTES TT__TRI_BLOB_BYTES
#define PT_BLOB_BYTES TT__PT_BLOB_BYTES
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

/* An SQLite failure of w's connection, as the status it returns. */
static inline tt_status db_error(rows_state *w, const char *what)
{
  return tt__error(w->ctx, TT_ERR_IO, "%s: %s: %s", w->path, what,
                   sqlite3_errmsg(w->db));
}

/* Runs sql on w's connection. */
static inline tt_status exec(rows_state *w, const char *sql,
                             const char *what)
{
  char *err = NULL;
  if (sqlite3_exec(w->db, sql, NULL, NULL, &err) == SQLITE_OK)
    return TT_OK;
  tt_status s = tt__error(w->ctx, TT_ERR_IO, "%s: %s: %s", w->path, what,
                          err ? err : sqlite3_errmsg(w->db));
  sqlite3_free(err);
  return s;
}

/* One more feature written: progress, and an interruption through it. */
static inline tt_status report(rows_state *w)
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
static inline int rtree_progress(double complete, const char *message,
                                 void *arg)
{
  rows_state *w = arg;
  if (!w->progress)
    return 1;
  return w->progress(w->lo + (w->hi - w->lo) * complete, message,
                     w->progress_arg);
}

/* --- the layers' tables (gpkg_rows.c) ----------------------------------
 * tt__rows_layer_find: the table OGR made for layer name, its geometry
 * column, srs_id and primary key; checks it is empty (no row, never had
 * one). tt__rows_finish_layer: its extent and feature count (count rows)
 * set in gpkg_contents and gpkg_ogr_contents, as GDAL sets them at close.
 * tt__rows_layer_free frees what layer_find set. */
TT_HIDDEN tt_status tt__rows_layer_find(rows_state *w, const char *name,
                                        layer_table *t);
TT_HIDDEN tt_status tt__rows_finish_layer(rows_state *w,
                                          const layer_table *t,
                                          size_t count);
TT_HIDDEN void tt__rows_layer_free(layer_table *t);

/* --- the rows made (gpkg_rows_pipe.c) ------------------------------------- */

#define MAX_COLS (1 + TT__TF_COUNT) /* the geometry and the fields */
#define CHUNK_ROWS 1024
#define NCHUNKS 4

/* A value of a row: the row writer's own (gpkg_stream.h), so that the
 * page path encodes the rows of both writers with one function. */
enum { V_NULL = TT__GV_NULL, V_INT = TT__GV_INT, V_REAL = TT__GV_REAL };
typedef tt__gpkg_value row_value;

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

/* Sets up the rows of both layers (nt triangles, nv vertices: 0 for a layer
 * left out by LAYERS), with a maker thread when threads allow (threads:
 * THREADS, 0 for the CPUs'); node_cap: the maker packs the R-trees of the
 * boxes once their rows are made (0: it does not). */
TT_HIDDEN tt_status tt__rows_pipe_begin(rows_pipe *p, rows_state *w,
                                        const tt__records *rec,
                                        layer_table *tri, layer_table *vtx,
                                        size_t nt, size_t nv, int threads,
                                        size_t node_cap);
/* The writing side: points p (vals, blob, blob_len) at row i of layer
 * p->layer_now, rows taken in order; reports progress. */
TT_HIDDEN tt_status tt__rows_pipe_row(rows_pipe *p, rows_state *w, size_t i);
/* The writing side, its rows written, packs the R-trees the maker has not
 * begun; returns those it packed (bit k: layer k). */
TT_HIDDEN unsigned tt__rows_pipe_pack_too(rows_pipe *p, size_t node_cap);
/* Joins the maker (after its packing when ok, else stopping it first). */
TT_HIDDEN void tt__rows_pipe_join(rows_pipe *p, int ok);
TT_HIDDEN void tt__rows_pipe_free(rows_pipe *p);

/* --- the rows as database pages (gpkg_rows_pages.c) -------------------- */

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

TT_HIDDEN void tt__rows_layout_free(page_layout *l);
/* Whether PAGES=YES can be followed for the layers made (tri, vtx, when
 * do_tri, do_vtx); the layouts of their tables into lay[2]; why not in
 * *why (TT_OK then too). */
TT_HIDDEN tt_status tt__rows_pages_possible(rows_state *w,
                                            const layer_table *tri,
                                            const layer_table *vtx,
                                            int do_tri, int do_vtx,
                                            int rtree, int ntfields,
                                            int nvfields,
                                            page_layout lay[2],
                                            const char **why);
/* Steps 1 (from the open transaction of j->w->db, which it ends) to 3 of
 * the page path for a whole TIN. */
TT_HIDDEN tt_status tt__rows_pages_run(pages_job *j);

#endif /* TERRATIN_GPKG_ROWS_H */
