/*
 * src/gdal/gpkg/ -- the GeoPackage fast path: a TIN's rows, SQLite database
 * pages, R-trees and a tiled run's streamed write, straight into the file
 * rather than through OGR.
 *
 * rtree_pack.c -- the R-tree packing of the GeoPackage index writers
 * (rtree_pack.h): no database, only boxes.
 *
 * Sort-Tile-Recursive, level by level: a level of k items makes
 * ceil(k / capacity) nodes whose sizes differ by at most one (so every node
 * but a lone root is at least half full), cut from ceil(sqrt(nodes))
 * vertical slices sorted by x centre, each slice sorted by y centre (for a
 * streamed block, as many slices as make the nodes about square over the
 * block's extent). Ties break on the id: the same boxes give the same
 * tree. The SQL loader (gpkg_rtree.c) and the page writers
 * (gpkg_rtree_pages.c) write what this packs, with the node blobs made
 * here.
 *
 * Workload: O(n log n) per level, a merge sort with the comparison
 * inlined; memory: the items, as much again of sorting scratch, and the
 * upper levels (1/50 of the items each).
 */
#include "gdal/gpkg/rtree_pack.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

/* One cell: a feature (leaves) or a child node (inner levels). */
typedef tt__rtree_box rt_item;

/* a before b along axis (0: x, 1: y): by the box's centre (the sum of its
 * two floats, exact in a double), ties by id. */
static inline int item_before(const rt_item *a, const rt_item *b, int axis)
{
  double ca = (double)a->box[2 * axis] + (double)a->box[2 * axis + 1];
  double cb = (double)b->box[2 * axis] + (double)b->box[2 * axis + 1];
  return ca < cb || (ca == cb && a->id < b->id);
}

/* Sorts items along axis: a merge sort with the comparison inlined (qsort's
 * callback per comparison cost the loader more than its SQL), runs of 16
 * by insertion first. tmp holds n items. The order is total (ids are
 * unique), so any correct sort gives the same result. */
static void sort_items(rt_item *items, size_t n, int axis, rt_item *tmp)
{
  enum { RUN = 16 };
  for (size_t r0 = 0; r0 < n; r0 += RUN) {
    size_t r1 = r0 + RUN < n ? r0 + RUN : n;
    for (size_t i = r0 + 1; i < r1; i++) {
      rt_item x = items[i];
      size_t j = i;
      for (; j > r0 && item_before(&x, &items[j - 1], axis); j--)
        items[j] = items[j - 1];
      items[j] = x;
    }
  }
  rt_item *src = items, *dst = tmp;
  for (size_t width = RUN; width < n; width *= 2) {
    for (size_t lo = 0; lo < n; lo += 2 * width) {
      size_t mid = lo + width < n ? lo + width : n;
      size_t hi = lo + 2 * width < n ? lo + 2 * width : n;
      size_t i = lo, j = mid, k = lo;
      while (i < mid && j < hi)
        dst[k++] = item_before(&src[j], &src[i], axis) ? src[j++] : src[i++];
      while (i < mid)
        dst[k++] = src[i++];
      while (j < hi)
        dst[k++] = src[j++];
    }
    rt_item *t = src;
    src = dst;
    dst = t;
  }
  if (src != items)
    memcpy(items, src, n * sizeof *items);
}

void tt__rtree_str_order(rt_item *items, size_t n, size_t ngroups,
                         rt_item *tmp, int fit)
{
  double ratio = 1.0;
  if (fit && n) {
    double lo[2], hi[2];
    for (int a = 0; a < 2; a++)
      lo[a] = hi[a] = (double)items[0].box[2 * a] +
                      (double)items[0].box[2 * a + 1];
    for (size_t i = 1; i < n; i++)
      for (int a = 0; a < 2; a++) {
        double c = (double)items[i].box[2 * a] +
                   (double)items[i].box[2 * a + 1];
        if (c < lo[a]) lo[a] = c;
        if (c > hi[a]) hi[a] = c;
      }
    double w = hi[0] - lo[0], h = hi[1] - lo[1];
    if (w > 0 && h > 0)
      ratio = w / h;
    else if (w > 0)
      ratio = (double)ngroups; /* a row: every group its own slice */
    else if (h > 0)
      ratio = 1.0 / (double)ngroups;
  }
  double want = ceil(sqrt((double)ngroups * ratio));
  size_t nslices = want < 1 ? 1 : want > (double)ngroups ? ngroups
                                                          : (size_t)want;
  sort_items(items, n, 0, tmp);
  for (size_t sl = 0; sl < nslices; sl++) {
    size_t g0 = sl * ngroups / nslices, g1 = (sl + 1) * ngroups / nslices;
    size_t e0 = tt__rtree_group_start(g0, n, ngroups);
    size_t e1 = tt__rtree_group_start(g1, n, ngroups);
    if (e1 > e0)
      sort_items(items + e0, e1 - e0, 1, tmp);
  }
}

void tt__rtree_packed_free(tt__rtree_packed *pk)
{
  if (!pk)
    return;
  for (int d = 1; d < pk->nlevels; d++)
    free(pk->level[d]);
  free(pk->items);
  free(pk);
}

tt_status tt__rtree_pack_items(tt_context *ctx, const char *what,
                               rt_item *items, size_t n, size_t node_cap,
                               int64_t next_nodeno, tt__rtree_packed **out)
{
  *out = NULL;
  tt__rtree_packed *pk = calloc(1, sizeof *pk);
  rt_item *tmp = n > node_cap ? malloc(n * sizeof *tmp) : NULL;
  if (!pk || (n > node_cap && !tmp)) {
    free(pk);
    free(tmp);
    return tt__error(ctx, TT_ERR_NOMEM, "%s: out of memory for the spatial "
                     "index", what);
  }
  pk->items = items;
  pk->nitems = n;
  pk->node_cap = node_cap;
  pk->level[0] = items;
  pk->n[0] = n;
  pk->nlevels = 1;
  pk->nodes_total = 1;
  tt_status s = TT_OK;
  for (int depth = 0; n > node_cap; depth++) {
    if (depth >= TT__RTREE_MAX_DEPTH) {
      s = tt__error(ctx, TT_ERR_INTERNAL, "%s: index deeper than %d "
                    "levels", what, TT__RTREE_MAX_DEPTH);
      break;
    }
    rt_item *level = pk->level[depth];
    size_t ngroups = (n + node_cap - 1) / node_cap;
    tt__rtree_str_order(level, n, ngroups, tmp, 0);
    rt_item *next = malloc(ngroups * sizeof *next);
    if (!next) {
      s = tt__error(ctx, TT_ERR_NOMEM, "%s: out of memory for the spatial "
                    "index", what);
      break;
    }
    pk->base[depth] = next_nodeno;
    for (size_t g = 0; g < ngroups; g++) {
      size_t e0 = tt__rtree_group_start(g, n, ngroups);
      size_t e1 = tt__rtree_group_start(g + 1, n, ngroups);
      rt_item *up = &next[g];
      up->id = next_nodeno++;
      memcpy(up->box, level[e0].box, sizeof up->box);
      for (size_t i = e0 + 1; i < e1; i++) {
        const float *bx = level[i].box;
        if (bx[0] < up->box[0]) up->box[0] = bx[0];
        if (bx[1] > up->box[1]) up->box[1] = bx[1];
        if (bx[2] < up->box[2]) up->box[2] = bx[2];
        if (bx[3] > up->box[3]) up->box[3] = bx[3];
      }
    }
    pk->nodes_total += ngroups;
    pk->level[depth + 1] = next;
    pk->n[depth + 1] = ngroups;
    pk->nlevels = depth + 2;
    n = ngroups;
  }
  free(tmp);
  if (s != TT_OK) {
    pk->items = NULL; /* the caller's again */
    tt__rtree_packed_free(pk);
    return s;
  }
  *out = pk;
  return TT_OK;
}

tt_status tt__rtree_pack(tt_context *ctx, const char *what,
                         tt__rtree_box *boxes, size_t n, size_t node_cap,
                         tt__rtree_packed **out)
{
  *out = NULL;
  if (node_cap < 2)
    return tt__error(ctx, TT_ERR_INTERNAL, "%s: R-tree nodes of %zu cells",
                     what, node_cap);
  return tt__rtree_pack_items(ctx, what, boxes, n, node_cap, 2, out);
}

/* v's n low bytes, big-endian. */
static void put_be(unsigned char *p, uint64_t v, int n)
{
  for (int i = 0; i < n; i++)
    p[i] = (unsigned char)(v >> (8 * (n - 1 - i)));
}

void tt__rtree_node_blob(unsigned char *blob, size_t node_size,
                         const rt_item *items, size_t n, unsigned depth)
{
  put_be(blob, depth, 2);
  put_be(blob + 2, n, 2);
  for (size_t i = 0; i < n; i++) {
    unsigned char *c = blob + 4 + i * TT__RTREE_CELL_BYTES;
    put_be(c, (uint64_t)items[i].id, 8);
    for (int k = 0; k < 4; k++) {
      uint32_t u;
      memcpy(&u, &items[i].box[k], sizeof u);
      put_be(c + 8 + 4 * k, u, 4);
    }
  }
  size_t used = 4 + n * TT__RTREE_CELL_BYTES;
  memset(blob + used, 0, node_size - used);
}
