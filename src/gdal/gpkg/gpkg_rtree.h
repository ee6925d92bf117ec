/*
 * src/gdal/gpkg/ -- the GeoPackage fast path: a TIN's rows, SQLite database
 * pages, R-trees and a tiled run's streamed write, straight into the file
 * rather than through OGR.
 *
 * gpkg_rtree.h -- the R-tree bulk loader of gpkg_rtree.c as the row
 * writer (gpkg_rows.c) uses it: inside the writer's own transaction,
 * fed with the boxes it has just written, so nothing is read back.
 */
#ifndef TERRATIN_GPKG_RTREE_H
#define TERRATIN_GPKG_RTREE_H

#include "base/internal.h"
#include "terratin/terratin_gdal.h"

#include <sqlite3.h>

typedef struct tt__sqlite_file tt__sqlite_file;

/* A feature's id (its fid) and the 2-D box of its geometry (minx, maxx,
 * miny, maxy) in floats, rounded outward as SQLite's R*Tree module rounds
 * the doubles it is given (tt__rtree_box_set): a cell of the index as it
 * is packed, 24 bytes a feature. */
typedef struct tt__rtree_box {
  int64_t id;
  float box[4];
} tt__rtree_box;

/* The module's rounding of a double to the float it stores: a min never
 * above the value, a max never below it (SQLite's rtreeValueDown/Up rule:
 * when the nearest float lies on the wrong side, scale by 1 -/+ 2^-23). */
static inline float tt__rtree_down(double d)
{
  float f = (float)d;
  if ((double)f > d)
    f = (float)(d * (d < 0 ? 1.0 + 1.0 / 8388608.0 : 1.0 - 1.0 / 8388608.0));
  return f;
}

static inline float tt__rtree_up(double d)
{
  float f = (float)d;
  if ((double)f < d)
    f = (float)(d * (d < 0 ? 1.0 - 1.0 / 8388608.0 : 1.0 + 1.0 / 8388608.0));
  return f;
}

static inline void tt__rtree_box_set(tt__rtree_box *b, int64_t id,
                                     double minx, double maxx, double miny,
                                     double maxy)
{
  b->id = id;
  b->box[0] = tt__rtree_down(minx);
  b->box[1] = tt__rtree_up(maxx);
  b->box[2] = tt__rtree_down(miny);
  b->box[3] = tt__rtree_up(maxy);
}

/* A tree packed beforehand (Sort-Tile-Recursive, see rtree_pack.c),
 * without a database: the row writer packs on its second thread while
 * SQLite inserts rows. */
typedef struct tt__rtree_packed tt__rtree_packed;

/* Packs the n boxes into nodes of node_cap cells, taking the array over:
 * on success it belongs to *out (reordered, freed with it), on failure it
 * stays the caller's. what names the index in messages. */
TT_HIDDEN tt_status tt__rtree_pack(tt_context *ctx, const char *what,
                                   tt__rtree_box *boxes, size_t n,
                                   size_t node_cap,
                                   tt__rtree_packed **out);
TT_HIDDEN void tt__rtree_packed_free(tt__rtree_packed *pk);

/* The cells a node of an R-tree created now in db will hold, from the page
 * size as SQLite's R*Tree module sizes its nodes (the loader checks it
 * against the root it creates, and packs again if it differs). */
TT_HIDDEN size_t tt__gpkg_rtree_node_cap(sqlite3 *db);

/* Builds the gpkg_rtree_index of table.geom_column in db, whose caller
 * holds an open write transaction, from the n boxes (every feature with a
 * non-empty geometry, each once; or packed, the same boxes packed by
 * tt__rtree_pack(), boxes then unused), exactly as tt_gpkg_build_rtree() would
 * from the table: the virtual table, its nodes, the standard's triggers and
 * the gpkg_extensions row. check: run SQLite's rtreecheck() on the result
 * too (about a fifth of the build's time; the tests do). gpkg_path names
 * the file in messages. The caller commits or rolls back. */
TT_HIDDEN tt_status tt__gpkg_rtree_from_boxes(
    tt_context *ctx, sqlite3 *db, const char *gpkg_path, const char *table,
    const char *geom_column, const tt__rtree_box *boxes, size_t n,
    const tt__rtree_packed *packed, int check, tt_progress_fn progress,
    void *progress_arg);

/* --- the index written as pages (sqlite_pages.h) --------------------------
 * What the page writer needs of an index made empty by
 * tt__gpkg_rtree_create_empty(): its name, the node size the module chose,
 * and the root pages of its shadow tables. */
typedef struct tt__rtree_shadow {
  char *rtree;        /* rtree_<t>_<c> as stored (sqlite3_malloc) */
  size_t node_size, node_cap;
  uint32_t root[3];   /* %_node, %_parent, %_rowid */
} tt__rtree_shadow;

/* Makes the gpkg_rtree_index of table.geom_column in db (whose caller holds
 * an open write transaction) as tt__gpkg_rtree_from_boxes() does, the
 * virtual table, its triggers and the gpkg_extensions row, but with its
 * shadow tables left empty (not even the root node), for
 * tt__rtree_write_pages() to fill with SQLite closed. TT_ERR_FORMAT when a
 * shadow table is not the plain two-column table it should be. */
TT_HIDDEN tt_status tt__gpkg_rtree_create_empty(tt_context *ctx, sqlite3 *db,
                                                const char *gpkg_path,
                                                const char *table,
                                                const char *geom_column,
                                                tt__rtree_shadow *out);
TT_HIDDEN void tt__rtree_shadow_free(tt__rtree_shadow *sh);

/* Writes the nodes, parents and rowid map of the n boxes (or of packed,
 * the same boxes packed by tt__rtree_pack(), packed again when its node
 * capacity is not the index's) into the empty shadow tables of sh, as pages
 * of f (not committed): the same rows tt__gpkg_rtree_from_boxes() would
 * insert. progress gets [0, 1]. */
TT_HIDDEN tt_status tt__rtree_write_pages(
    tt_context *ctx, const char *what, const tt__rtree_box *boxes, size_t n,
    const tt__rtree_packed *packed, const tt__rtree_shadow *sh,
    tt__sqlite_file *f, tt_progress_fn progress, void *progress_arg);

/* --- the index written as the rows stream in -------------------------------
 * For a layer whose rows are appended as pages one by one, in id order
 * (the streamed tiled run, gpkg_stream.c): its leaves are packed and
 * written block by block as the boxes come, only the leaves' boxes are
 * kept, and the upper levels, the root (node 1, a placeholder patched at
 * the end) and %_parent are written by the finish (gpkg_rtree_pages.c, "the
 * index written as the rows stream in", has the design). A layer of at
 * most one block gets the tree tt__rtree_write_pages() writes.
 *
 * tt__rtree_stream_create() for the empty shadow tables of sh (kept by the
 * caller until the finish), with pages appended to f; block: the boxes a
 * block gathers at least before it is packed at a cut (raised to one more
 * than a node holds). what names the index in messages (kept by the
 * caller). The caller frees *out with tt__rtree_stream_free(); tables it
 * left unfinished go with f, never committed. */
typedef struct tt__rtree_stream tt__rtree_stream;
TT_HIDDEN tt_status tt__rtree_stream_create(tt_context *ctx, const char *what,
                                            const tt__rtree_shadow *sh,
                                            tt__sqlite_file *f, size_t block,
                                            tt__rtree_stream **out);
/* The next feature's box: ids 1, 2, 3, ... in turn, each once. */
TT_HIDDEN tt_status tt__rtree_stream_add(tt__rtree_stream *rs,
                                         const tt__rtree_box *box);
/* A place where a block may end (the boxes so far make whole pieces of
 * the layer, close together): the block is packed when it holds at least
 * `block` boxes. Without cuts a block is packed at 16 times that. */
TT_HIDDEN tt_status tt__rtree_stream_cut(tt__rtree_stream *rs);
/* After the last box: the last block, the upper levels, the root and
 * %_parent, as pages of f (not committed). progress gets [0, 1]. */
TT_HIDDEN tt_status tt__rtree_stream_finish(tt__rtree_stream *rs,
                                            tt_progress_fn progress,
                                            void *progress_arg);
/* The bytes it holds: the block, its scratch, the leaves' boxes. */
TT_HIDDEN size_t tt__rtree_stream_bytes(const tt__rtree_stream *rs);
TT_HIDDEN void tt__rtree_stream_free(tt__rtree_stream *rs);

/* Removes the gpkg_rtree_index of table.geom_column from db (in its
 * caller's write transaction): the virtual table and its shadow tables,
 * the triggers, the gpkg_extensions row. What is not there is skipped. */
TT_HIDDEN tt_status tt__gpkg_rtree_drop(tt_context *ctx, sqlite3 *db,
                                        const char *gpkg_path,
                                        const char *table,
                                        const char *geom_column);

#endif /* TERRATIN_GPKG_RTREE_H */
