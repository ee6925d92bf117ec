/*
 * src/gdal/gpkg/ -- the GeoPackage fast path: a TIN's rows, SQLite database
 * pages, R-trees and a tiled run's streamed write, straight into the file
 * rather than through OGR.
 *
 * rtree_pack.h -- the R-tree packing shared by the GeoPackage index writers
 * (rtree_pack.c): Sort-Tile-Recursive order, the packed tree level by
 * level, and a node's blob as SQLite's R*Tree module stores it. Used by
 * the SQL loader (gpkg_rtree.c) and the page writers
 * (gpkg_rtree_pages.c); private to them.
 */
#ifndef TERRATIN_RTREE_PACK_H
#define TERRATIN_RTREE_PACK_H

#include "gdal/gpkg/gpkg_rtree.h"

#include <stddef.h>
#include <stdint.h>

#define TT__RTREE_CELL_BYTES 24 /* 8-byte id + 4 floats */
#define TT__RTREE_MAX_DEPTH 40  /* far beyond any table SQLite can hold */

/* The packed tree: every level's items in node order, the leaves first
 * (the boxes given, reordered), each level's groups the items of the one
 * above; the last level fits in the root. Computing needs no database. */
struct tt__rtree_packed {
  tt__rtree_box *items; /* the leaves' cells (level 0), owned */
  size_t nitems;
  size_t node_cap;
  int nlevels;
  tt__rtree_box *level[TT__RTREE_MAX_DEPTH + 1]; /* level[0] == items;
                                                    others owned */
  size_t n[TT__RTREE_MAX_DEPTH + 1];
  int64_t base[TT__RTREE_MAX_DEPTH + 1]; /* node of level d's group g:
                                            base[d] + g (the upper levels
                                            get reordered) */
  size_t nodes_total;
};

/* First item of group g when n items make ngroups groups of near-equal
 * size (sizes differ by at most one). */
static inline size_t tt__rtree_group_start(size_t g, size_t n, size_t ngroups)
{
  return (size_t)((uint64_t)g * n / ngroups);
}

/* Orders items for ngroups consecutive groups (group g from
 * tt__rtree_group_start(g) on): STR slices by x centre, each sorted by y
 * centre; ties by id. tmp holds n items. fit: as many slices as make the
 * groups about square over the extent of the items' centres (a streamed
 * block, a strip of a few tiles), else ceil(sqrt(ngroups)) as STR has it
 * (a whole layer). */
TT_HIDDEN void tt__rtree_str_order(tt__rtree_box *items, size_t n,
                                   size_t ngroups, tt__rtree_box *tmp,
                                   int fit);

/* Packs items (n) into nodes of node_cap cells, the nodes above items
 * numbered from next_nodeno on (the root is 1): on success items belong
 * to *out, on failure they stay the caller's. what names the index in
 * messages. */
TT_HIDDEN tt_status tt__rtree_pack_items(tt_context *ctx, const char *what,
                                         tt__rtree_box *items, size_t n,
                                         size_t node_cap,
                                         int64_t next_nodeno,
                                         tt__rtree_packed **out);

/* The blob of a node holding items[0..n) (depth: the root's tree depth, 0
 * for any other node) into blob, node_size bytes: big-endian, 2 bytes of
 * depth, 2 of cell count, then each cell's 8-byte id (a rowid in a leaf,
 * a child's node number above) and minx maxx miny maxy as floats; zeros
 * after. */
TT_HIDDEN void tt__rtree_node_blob(unsigned char *blob, size_t node_size,
                                   const tt__rtree_box *items, size_t n,
                                   unsigned depth);

#endif /* TERRATIN_RTREE_PACK_H */
