/*
 * src/gdal/gpkg/ -- the GeoPackage fast path: a TIN's rows, SQLite database
 * pages, R-trees and a tiled run's streamed write, straight into the file
 * rather than through OGR.
 *
 * gpkg_rtree_pages.c -- a GeoPackage R-tree's shadow tables written as
 * database pages while SQLite is closed (gpkg_rtree.h), for the page
 * writer of gpkg_rows.c: into the empty tables
 * tt__gpkg_rtree_create_empty() made, with the table appender of
 * sqlite_pages.c; the rows those gpkg_rtree.c's loader inserts.
 *
 * Whole (tt__rtree_write_pages): the boxes of every feature packed
 * (rtree_pack.c), then %_node (the root, node 1, first, then each level's
 * nodes in node number order), %_parent and %_rowid. Streamed
 * (tt__rtree_stream, the second section): the leaves block by block as
 * the rows come, the upper levels and the root at the end.
 *
 * Workload: one blob a node and one row a node and a feature, appended;
 * memory: whole, the packing and 4 bytes a feature and a node; streamed,
 * the block and 24 bytes a leaf.
 */
#include "gdal/gpkg/gpkg_rtree.h"
#include "gdal/gpkg/rtree_pack.h"
#include "gdal/gpkg/sqlite_pages.h"

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

/* One cell: a feature (leaves) or a child node (inner levels). */
typedef tt__rtree_box rt_item;

/* --- the whole tree ------------------------------------------------------ */

/* Appends the %_node row (nodeno, blob): the record of NULL (the INTEGER
 * PRIMARY KEY) and the blob, which is its body as it is (no copy). */
static tt_status node_row(tt__sqlite_table *t, int64_t nodeno,
                          const unsigned char *blob, size_t size, int format)
{
  unsigned char body[16];
  tt__sqlite_rec r;
  tt__sqlite_rec_begin(&r, body, format);
  tt__sqlite_rec_null(&r);
  tt__sqlite_rec_bytes_type(&r, size, 0);
  const unsigned char *head;
  size_t nh = tt__sqlite_rec_head(&r, &head);
  return tt__sqlite_table_append2(t, nodeno, head, nh, blob, size);
}

tt_status tt__rtree_write_pages(tt_context *ctx, const char *what,
                                const tt__rtree_box *boxes, size_t n,
                                const tt__rtree_packed *packed,
                                const tt__rtree_shadow *sh,
                                tt__sqlite_file *f, tt_progress_fn progress,
                                void *progress_arg)
{
  tt__rtree_packed *own = NULL;
  tt_status s = TT_OK;
  if (!packed || packed->node_cap != sh->node_cap) {
    /* packed for nodes of another size (or not at all): again, from its
     * leaves (the order is total: the same tree as from the boxes) */
    size_t m = packed ? packed->nitems : n;
    rt_item *items = malloc((m ? m : 1) * sizeof *items);
    if (!items)
      return tt__error(ctx, TT_ERR_NOMEM, "%s: out of memory for the "
                       "spatial index", what);
    if (m) /* no boxes: boxes may be NULL */
      memcpy(items, packed ? packed->items : boxes, m * sizeof *items);
    s = tt__rtree_pack_items(ctx, what, items, m, sh->node_cap, 2, &own);
    if (s != TT_OK) {
      free(items);
      return s;
    }
    packed = own;
  }
  const tt__rtree_packed *pk = packed;
  const int format = tt__sqlite_file_format(f);
  unsigned char *blob = malloc(sh->node_size);
  uint32_t *node_of = calloc(pk->nitems ? pk->nitems : 1, sizeof *node_of);
  uint32_t *parent = malloc((pk->nodes_total + 1) * sizeof *parent);
  tt__sqlite_table *t = NULL;
  char *name = NULL;
  if (!blob || !node_of || !parent) {
    s = tt__error(ctx, TT_ERR_NOMEM, "%s: out of memory for the spatial "
                  "index", what);
    goto done;
  }
  const int top = pk->nlevels - 1;
  const size_t total = pk->nodes_total * 2 + pk->nitems;
  size_t done_rows = 0;

  /* Where each node and each feature hangs: level e's groups are nodes
   * base[e] + g (the top level's one group is the root, node 1), the items
   * of level e + 1 are level e's nodes. */
  for (size_t i = 0; i <= pk->nodes_total; i++)
    parent[i] = 0;
  for (int e = 0; e <= top; e++) {
    size_t ngroups = e == top ? 1 : pk->n[e + 1];
    for (size_t g = 0; g < ngroups; g++) {
      size_t e0 = e == top ? 0 : tt__rtree_group_start(g, pk->n[e], ngroups);
      size_t e1 = e == top ? pk->n[e]
                           : tt__rtree_group_start(g + 1, pk->n[e], ngroups);
      uint32_t node = e == top ? 1u : (uint32_t)(pk->base[e] + (int64_t)g);
      for (size_t i = e0; i < e1; i++) {
        int64_t id = pk->level[e][i].id;
        if (e > 0) {
          parent[id] = node;
        } else if (id < 1 || (uint64_t)id > pk->nitems ||
                   node_of[id - 1] != 0) {
          s = tt__error(ctx, TT_ERR_INTERNAL, "%s: the features' ids are "
                        "not 1..%zu", what, pk->nitems);
          goto done;
        } else {
          node_of[id - 1] = node;
        }
      }
    }
  }

  /* %_node: the root, then every level's nodes, in node number order */
  name = sqlite3_mprintf("%s_node", sh->rtree);
  s = name ? tt__sqlite_table_begin(f, name, sh->root[0], &t)
           : tt__error(ctx, TT_ERR_NOMEM, "out of memory");
  if (s == TT_OK) {
    tt__rtree_node_blob(blob, sh->node_size, pk->level[top], pk->n[top],
                        (unsigned)top);
    s = node_row(t, 1, blob, sh->node_size, format);
  }
  for (int d = 0; d < top && s == TT_OK; d++) {
    size_t ngroups = pk->n[d + 1];
    for (size_t g = 0; g < ngroups && s == TT_OK; g++) {
      size_t e0 = tt__rtree_group_start(g, pk->n[d], ngroups);
      size_t e1 = tt__rtree_group_start(g + 1, pk->n[d], ngroups);
      tt__rtree_node_blob(blob, sh->node_size, pk->level[d] + e0, e1 - e0,
                          0);
      s = node_row(t, pk->base[d] + (int64_t)g, blob, sh->node_size,
                   format);
    }
  }
  done_rows += pk->nodes_total;
  if (s == TT_OK) {
    s = tt__sqlite_table_finish(t);
    t = NULL;
  }
  if (s == TT_OK && progress &&
      !progress((double)done_rows / (double)total, "indexing", progress_arg))
    s = tt__error(ctx, TT_ERR_INTERRUPTED, "%s: building the spatial index "
                  "was interrupted", what);

  /* %_parent: every node but the root */
  sqlite3_free(name);
  name = s == TT_OK ? sqlite3_mprintf("%s_parent", sh->rtree) : NULL;
  if (s == TT_OK)
    s = name ? tt__sqlite_table_begin(f, name, sh->root[1], &t)
             : tt__error(ctx, TT_ERR_NOMEM, "out of memory");
  for (size_t m = 2; m <= pk->nodes_total && s == TT_OK; m++)
    s = tt__sqlite_table_append_int(t, (int64_t)m, parent[m]);
  done_rows += pk->nodes_total;
  if (s == TT_OK) {
    s = tt__sqlite_table_finish(t);
    t = NULL;
  }

  /* %_rowid: every feature, by id */
  sqlite3_free(name);
  name = s == TT_OK ? sqlite3_mprintf("%s_rowid", sh->rtree) : NULL;
  if (s == TT_OK)
    s = name ? tt__sqlite_table_begin(f, name, sh->root[2], &t)
             : tt__error(ctx, TT_ERR_NOMEM, "out of memory");
  for (size_t i = 0; i < pk->nitems && s == TT_OK; i++) {
    s = tt__sqlite_table_append_int(t, (int64_t)i + 1, node_of[i]);
    if (s == TT_OK && progress && (i & 0xffff) == 0xffff &&
        !progress((double)(done_rows + i) / (double)total, "indexing",
                  progress_arg))
      s = tt__error(ctx, TT_ERR_INTERRUPTED, "%s: building the spatial "
                    "index was interrupted", what);
  }
  if (s == TT_OK) {
    s = tt__sqlite_table_finish(t);
    t = NULL;
  }
  if (s == TT_OK && progress &&
      !progress(1.0, "indexing", progress_arg))
    s = tt__error(ctx, TT_ERR_INTERRUPTED, "%s: building the spatial index "
                  "was interrupted", what);
done:
  /* a table not finished (t) is freed with the file, never committed */
  sqlite3_free(name);
  free(blob);
  free(node_of);
  free(parent);
  tt__rtree_packed_free(own);
  return s;
}

/* --- the index written as the rows stream in ------------------------------
 * tt__rtree_stream (gpkg_rtree.h): the boxes of a layer whose rows are
 * appended in id order (1, 2, ...) are gathered into a block; at a cut
 * (the end of a batch of a tiled run) once the block holds at least
 * `block` boxes, it is STR-ordered into leaves (tt__rtree_str_order with
 * the slices fitted to the block's extent: a block is a strip of a few
 * tiles) whose node blobs go to %_node and whose features' (rowid, leaf)
 * pairs go to %_rowid at once, both in rowid order; only each leaf's
 * number and box is kept. A block ends early, before the last batch, when
 * that batch lies apart from the rest (a row of tiles wrapped): a block of
 * the end of one row and the start of the next made a few leaves spanning
 * the DEM's width (tt__rtree_stream_cut). After the last row the leaves
 * are packed like any level (tt__rtree_pack_items, STR over the whole
 * layer) into the upper levels, written after them, then %_parent.
 *
 * Node numbers: the root is node 1, which SQLite's module reads first (its
 * depth, and the node size as the length of its blob), and %_node rows
 * must go in rowid order; but the root is known last. So before the first
 * leaf, node 1 is appended with a placeholder blob of the node size (all
 * zero) and its place kept (tt__sqlite_table_append2_spot); at the end
 * the root's blob is written over it (tt__sqlite_file_patch, same length,
 * so the page's cells and pointers stand). Leaves are nodes 2..L+1 in the
 * order written, the upper levels L+2 on, level by level.
 *
 * A layer that never fills a block (up to `block` features) is packed at
 * the end from its boxes, all of them, by tt__rtree_write_pages(): the
 * same tree as the merged path's, byte for byte.
 *
 * Measured on the 8193² and 16385² fractals in tiles of 1,024 (2.0 M and
 * 8.0 M features, blocks of 65,536: docs/scale.md): as many nodes visited
 * by random windows as the whole-layer STR tree's, within 2 %. Tried and
 * not kept, on the 16385²'s vertices (the leaves' area over the extent,
 * and nodes visited by windows of 0.1 % of the side; the whole-layer tree
 * 0.94 and 5.0): no early end at a row's wrap (1.09, 6.2), and halving
 * the block's groups along the wider spread of their centres instead of
 * STR (1.69, 7.4).
 *
 * Memory: the block (24 bytes a box, and 24 + 4 of scratch for the
 * sorting and the rowid pairs), 24 bytes a leaf (about one per 50
 * features) until the end, then the upper levels' packing (24 + 4 bytes a
 * leaf). */

/* Blocks bigger than this many times `block` are packed without waiting
 * for a cut: memory stays bounded for a caller that gives no cuts. */
#define RT_STREAM_HARD 16

struct tt__rtree_stream {
  tt_context *ctx;
  const char *what;
  const tt__rtree_shadow *sh;
  tt__sqlite_file *f;
  int format;
  size_t block;
  rt_item *buf, *tmp; /* the block's boxes in id order; sorting scratch */
  size_t nbuf, cap_buf, cap_tmp;
  uint32_t *node_of; /* the block's features' leaves, in id order */
  size_t cap_node_of;
  int64_t first_id;  /* the id of buf[0] */
  size_t mark;       /* buf[0..mark): the boxes before the last cut */
  float so_far[4];   /* their bounds */
  size_t split;      /* where the block may end short (0: nowhere) */
  rt_item *leaves;   /* every leaf written: node number, box */
  size_t nleaves, cap_leaves;
  unsigned char *blob;
  tt__sqlite_table *node_t, *rowid_t; /* open while streaming */
  tt__sqlite_spot root_spot;          /* node 1's payload */
  size_t root_head;                   /* its record header's bytes */
  int streaming;                      /* a block was written */
};

tt_status tt__rtree_stream_create(tt_context *ctx, const char *what,
                                  const tt__rtree_shadow *sh,
                                  tt__sqlite_file *f, size_t block,
                                  tt__rtree_stream **out)
{
  *out = NULL;
  if (sh->node_cap < 2 ||
      sh->node_size < 4 + sh->node_cap * TT__RTREE_CELL_BYTES)
    return tt__error(ctx, TT_ERR_INTERNAL, "%s: R-tree nodes of %zu cells "
                     "in %zu bytes", what, sh->node_cap, sh->node_size);
  tt__rtree_stream *rs = calloc(1, sizeof *rs);
  unsigned char *blob = malloc(sh->node_size);
  if (!rs || !blob) {
    free(rs);
    free(blob);
    return tt__error(ctx, TT_ERR_NOMEM, "out of memory");
  }
  rs->ctx = ctx;
  rs->what = what;
  rs->sh = sh;
  rs->f = f;
  rs->format = tt__sqlite_file_format(f);
  /* more than a node: a block packed makes two leaves at least, so the
   * root (node 1) is never a leaf itself */
  rs->block = block > sh->node_cap ? block : sh->node_cap + 1;
  rs->first_id = 1;
  rs->blob = blob;
  *out = rs;
  return TT_OK;
}

size_t tt__rtree_stream_bytes(const tt__rtree_stream *rs)
{
  if (!rs)
    return 0;
  return (rs->cap_buf + rs->cap_tmp + rs->cap_leaves) * sizeof(rt_item) +
         rs->cap_node_of * sizeof(uint32_t) + rs->sh->node_size;
}

void tt__rtree_stream_free(tt__rtree_stream *rs)
{
  if (!rs)
    return;
  /* tables not finished belong to the file, which frees them */
  free(rs->buf);
  free(rs->tmp);
  free(rs->node_of);
  free(rs->leaves);
  free(rs->blob);
  free(rs);
}

/* %_node and %_rowid begun, node 1's placeholder appended. */
static tt_status stream_begin(tt__rtree_stream *rs)
{
  const tt__rtree_shadow *sh = rs->sh;
  char *name = sqlite3_mprintf("%s_node", sh->rtree);
  tt_status s = name ? tt__sqlite_table_begin(rs->f, name, sh->root[0],
                                              &rs->node_t)
                     : tt__error(rs->ctx, TT_ERR_NOMEM, "out of memory");
  sqlite3_free(name);
  name = s == TT_OK ? sqlite3_mprintf("%s_rowid", sh->rtree) : NULL;
  if (s == TT_OK)
    s = name ? tt__sqlite_table_begin(rs->f, name, sh->root[2], &rs->rowid_t)
             : tt__error(rs->ctx, TT_ERR_NOMEM, "out of memory");
  sqlite3_free(name);
  if (s != TT_OK)
    return s;
  /* the record of (NULL, blob of node_size bytes): its header, then the
   * blob, zero until the root is known */
  unsigned char body[16];
  tt__sqlite_rec r;
  tt__sqlite_rec_begin(&r, body, rs->format);
  tt__sqlite_rec_null(&r);
  tt__sqlite_rec_bytes_type(&r, sh->node_size, 0);
  const unsigned char *head;
  rs->root_head = tt__sqlite_rec_head(&r, &head);
  memset(rs->blob, 0, sh->node_size);
  s = tt__sqlite_table_append2_spot(rs->node_t, 1, head, rs->root_head,
                                    rs->blob, sh->node_size, &rs->root_spot);
  rs->streaming = 1;
  return s;
}

/* The bounds of items[0..n), n > 0. */
static void items_bounds(const rt_item *items, size_t n, float out[4])
{
  memcpy(out, items[0].box, 4 * sizeof *out);
  for (size_t i = 1; i < n; i++) {
    const float *bx = items[i].box;
    if (bx[0] < out[0]) out[0] = bx[0];
    if (bx[1] > out[1]) out[1] = bx[1];
    if (bx[2] < out[2]) out[2] = bx[2];
    if (bx[3] > out[3]) out[3] = bx[3];
  }
}

/* The block's first n boxes, buf[0..n), as leaves: nodes, rowid pairs,
 * leaf boxes; the boxes after them move to the front. */
static tt_status stream_pack(tt__rtree_stream *rs, size_t n)
{
  const size_t cap = rs->sh->node_cap;
  if (n == 0)
    return TT_OK;
  tt_status s = rs->streaming ? TT_OK : stream_begin(rs);
  if (s != TT_OK)
    return s;
  const size_t ngroups = (n + cap - 1) / cap;
  if (!tt__grow((void **)&rs->tmp, &rs->cap_tmp, n, sizeof *rs->tmp) ||
      !tt__grow((void **)&rs->node_of, &rs->cap_node_of, n,
                sizeof *rs->node_of) ||
      !tt__grow((void **)&rs->leaves, &rs->cap_leaves,
                rs->nleaves + ngroups, sizeof *rs->leaves))
    return tt__error(rs->ctx, TT_ERR_NOMEM, "%s: out of memory for the "
                     "spatial index", rs->what);
  if ((uint64_t)rs->nleaves + ngroups + 1 > 0xffffffffu)
    return tt__error(rs->ctx, TT_ERR_INTERNAL, "%s: more than 2^32 R-tree "
                     "leaves", rs->what);
  tt__rtree_str_order(rs->buf, n, ngroups, rs->tmp, 1);
  for (size_t g = 0; g < ngroups && s == TT_OK; g++) {
    size_t e0 = tt__rtree_group_start(g, n, ngroups);
    size_t e1 = tt__rtree_group_start(g + 1, n, ngroups);
    rt_item *leaf = &rs->leaves[rs->nleaves];
    leaf->id = (int64_t)rs->nleaves + 2;
    memcpy(leaf->box, rs->buf[e0].box, sizeof leaf->box);
    for (size_t i = e0; i < e1; i++) {
      const float *bx = rs->buf[i].box;
      if (bx[0] < leaf->box[0]) leaf->box[0] = bx[0];
      if (bx[1] > leaf->box[1]) leaf->box[1] = bx[1];
      if (bx[2] < leaf->box[2]) leaf->box[2] = bx[2];
      if (bx[3] > leaf->box[3]) leaf->box[3] = bx[3];
      rs->node_of[rs->buf[i].id - rs->first_id] = (uint32_t)leaf->id;
    }
    tt__rtree_node_blob(rs->blob, rs->sh->node_size, rs->buf + e0, e1 - e0,
                        0);
    s = node_row(rs->node_t, leaf->id, rs->blob, rs->sh->node_size,
                 rs->format);
    rs->nleaves++;
  }
  for (size_t i = 0; i < n && s == TT_OK; i++)
    s = tt__sqlite_table_append_int(rs->rowid_t, rs->first_id + (int64_t)i,
                                    rs->node_of[i]);
  rs->first_id += (int64_t)n;
  rs->nbuf -= n;
  memmove(rs->buf, rs->buf + n, rs->nbuf * sizeof *rs->buf);
  rs->mark = rs->split = 0;
  if (rs->nbuf) { /* what is left is before no cut, or after the last */
    items_bounds(rs->buf, rs->nbuf, rs->so_far);
    rs->mark = rs->nbuf;
  }
  return s;
}

tt_status tt__rtree_stream_add(tt__rtree_stream *rs, const tt__rtree_box *b)
{
  if (b->id != rs->first_id + (int64_t)rs->nbuf)
    return tt__error(rs->ctx, TT_ERR_INTERNAL, "%s: R-tree box of id %lld "
                     "where %lld was due", rs->what, (long long)b->id,
                     (long long)(rs->first_id + (int64_t)rs->nbuf));
  if (!tt__grow((void **)&rs->buf, &rs->cap_buf, rs->nbuf + 1,
                sizeof *rs->buf))
    return tt__error(rs->ctx, TT_ERR_NOMEM, "%s: out of memory for the "
                     "spatial index", rs->what);
  rs->buf[rs->nbuf++] = *b;
  if (rs->nbuf >= RT_STREAM_HARD * rs->block)
    return stream_pack(rs, rs->nbuf);
  return TT_OK;
}

/* A cut: the boxes since the last one (a batch) join the block. When they
 * lie apart from the block so far (no overlap, not even touching: the
 * pieces jumped, a row of tiles ended and the next began at the other
 * side), the block may end before them, so that a block does not hold two
 * far clusters (whose STR slices made leaves spanning the gap: on the
 * 16385² fractal a sixth more leaf area for the vertices). A full block
 * ends there if it can, else here. */
tt_status tt__rtree_stream_cut(tt__rtree_stream *rs)
{
  const size_t n = rs->nbuf, m = rs->mark;
  if (n == m)
    return TT_OK;
  float bb[4];
  items_bounds(rs->buf + m, n - m, bb);
  if (m == 0) {
    memcpy(rs->so_far, bb, sizeof bb);
  } else {
    float *sf = rs->so_far;
    if (bb[0] > sf[1] || bb[1] < sf[0] || bb[2] > sf[3] || bb[3] < sf[2])
      rs->split = m;
    if (bb[0] < sf[0]) sf[0] = bb[0];
    if (bb[1] > sf[1]) sf[1] = bb[1];
    if (bb[2] < sf[2]) sf[2] = bb[2];
    if (bb[3] > sf[3]) sf[3] = bb[3];
  }
  rs->mark = n;
  if (n < rs->block)
    return TT_OK;
  tt_status s = stream_pack(rs, rs->split ? rs->split : n);
  if (s == TT_OK && rs->nbuf >= rs->block)
    s = stream_pack(rs, rs->nbuf);
  return s;
}

tt_status tt__rtree_stream_finish(tt__rtree_stream *rs,
                                  tt_progress_fn progress,
                                  void *progress_arg)
{
  if (!rs->streaming) /* one block at most: the whole layer's STR */
    return tt__rtree_write_pages(rs->ctx, rs->what, rs->buf, rs->nbuf,
                                 NULL, rs->sh, rs->f, progress,
                                 progress_arg);
  const tt__rtree_shadow *sh = rs->sh;
  tt__rtree_packed *pk = NULL;
  uint32_t *parent = NULL;
  char *name = NULL;
  tt__sqlite_table *t = NULL;
  tt_status s = stream_pack(rs, rs->nbuf);
  if (s == TT_OK && progress && !progress(0.5, "indexing", progress_arg))
    s = tt__error(rs->ctx, TT_ERR_INTERRUPTED, "%s: building the spatial "
                  "index was interrupted", rs->what);
  /* the upper levels: the leaves packed as any level is, numbered on */
  const size_t L = rs->nleaves;
  if (s == TT_OK) {
    s = tt__rtree_pack_items(rs->ctx, rs->what, rs->leaves, L, sh->node_cap,
                             (int64_t)L + 2, &pk);
    if (s == TT_OK) { /* the leaves are pk's now */
      rs->leaves = NULL;
      rs->cap_leaves = 0;
    }
  }
  const int top = pk ? pk->nlevels - 1 : 0;
  for (int d = 0; d < top && s == TT_OK; d++) {
    size_t ngroups = pk->n[d + 1];
    for (size_t g = 0; g < ngroups && s == TT_OK; g++) {
      size_t e0 = tt__rtree_group_start(g, pk->n[d], ngroups);
      size_t e1 = tt__rtree_group_start(g + 1, pk->n[d], ngroups);
      tt__rtree_node_blob(rs->blob, sh->node_size, pk->level[d] + e0,
                          e1 - e0, 0);
      s = node_row(rs->node_t, pk->base[d] + (int64_t)g, rs->blob,
                   sh->node_size, rs->format);
    }
  }
  if (s == TT_OK) {
    s = tt__sqlite_table_finish(rs->node_t);
    rs->node_t = NULL;
  }
  if (s == TT_OK) { /* node 1: the root, a level above the top's cells */
    tt__rtree_node_blob(rs->blob, sh->node_size, pk->level[top], pk->n[top],
                        (unsigned)top + 1);
    s = tt__sqlite_file_patch(rs->f, &rs->root_spot, rs->root_head,
                              rs->blob, sh->node_size);
  }
  if (s == TT_OK) {
    s = tt__sqlite_table_finish(rs->rowid_t);
    rs->rowid_t = NULL;
  }
  /* %_parent: every node but the root, leaves 2..L+1 then the levels
   * above */
  const size_t last = pk ? L + pk->nodes_total : 0;
  if (s == TT_OK) {
    parent = calloc(last + 1, sizeof *parent);
    if (!parent)
      s = tt__error(rs->ctx, TT_ERR_NOMEM, "%s: out of memory for the "
                    "spatial index", rs->what);
  }
  for (int e = 0; e <= top && s == TT_OK; e++) {
    size_t ngroups = e == top ? 1 : pk->n[e + 1];
    for (size_t g = 0; g < ngroups; g++) {
      size_t e0 = e == top ? 0 : tt__rtree_group_start(g, pk->n[e], ngroups);
      size_t e1 = e == top ? pk->n[e]
                           : tt__rtree_group_start(g + 1, pk->n[e], ngroups);
      uint32_t node = e == top ? 1u : (uint32_t)(pk->base[e] + (int64_t)g);
      for (size_t i = e0; i < e1; i++)
        parent[pk->level[e][i].id] = node;
    }
  }
  name = s == TT_OK ? sqlite3_mprintf("%s_parent", sh->rtree) : NULL;
  if (s == TT_OK)
    s = name ? tt__sqlite_table_begin(rs->f, name, sh->root[1], &t)
             : tt__error(rs->ctx, TT_ERR_NOMEM, "out of memory");
  for (size_t m = 2; m <= last && s == TT_OK; m++)
    s = tt__sqlite_table_append_int(t, (int64_t)m, parent[m]);
  if (s == TT_OK) {
    s = tt__sqlite_table_finish(t);
    t = NULL;
  }
  if (s == TT_OK && progress && !progress(1.0, "indexing", progress_arg))
    s = tt__error(rs->ctx, TT_ERR_INTERRUPTED, "%s: building the spatial "
                  "index was interrupted", rs->what);
  sqlite3_free(name);
  free(parent);
  tt__rtree_packed_free(pk);
  return s;
}
