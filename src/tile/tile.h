/*
 * tile.h -- what the tiling stage's files share (internal): the border
 * vertices of a tile, made by border.c and forced into refinement by
 * refine.c (tt__refine_tile), and the flags that mark tile borders in the
 * mesh.
 *
 * A tile's sides are numbered 0 left (column 0 of the tile), 1 top (row
 * 0), 2 right (last column), 3 bottom (last row). A side is shared when a
 * neighbouring tile lies beyond it (not at the DEM's edge).
 *
 * Part of src/tile/, tiled runs: the tiles, their shared borders, one tile's
 * run, the merge.
 */
#ifndef TT_TILE_H
#define TT_TILE_H

#include "base/internal.h"

/* What refinement needs to know of a tile's borders, in the tile grid's
 * pixel coordinates. */
typedef struct tt__tile_borders {
  unsigned shared;      /* bit s: side s is shared */
  /* the border vertices (valid samples on shared sides that both tiles
   * keep), in a fixed order: side by side, along each side */
  int32_t *col, *row;
  size_t n, cap;
  /* per shared side, per unit segment k (samples k and k+1 along it): 1
   * when the neighbour's grid cell on that segment has three valid corners
   * or more, so the neighbour's TIN covers the segment too */
  uint8_t *cover[4];
  /* per shared side, per sample along it: 1 when it is a border vertex
   * (decimation removes the side's other samples, decimate.c) */
  uint8_t *kept[4];
  /* tt_tile_curve: called by refinement before each insertion and when
   * it stops, with the vertices and the largest error of the tile's
   * candidates (its shared sides' samples left out); NULL otherwise */
  tt_tile_curve_fn curve;
  void *curve_arg;
} tt__tile_borders;

TT_HIDDEN void tt__tile_borders_free(tt__tile_borders *b);

/* Flags every boundary edge of m on a shared side of the nx x ny tile grid
 * TT__EDGE_BORDER, and TT__EDGE_BORDER_SHARED when the neighbour's TIN has
 * it too (mesh.h): refinement after inserting the border vertices, and
 * decimation's start and result (decimate.c). */
struct tt__mesh;
TT_HIDDEN void tt__tile_flag_edges(struct tt__mesh *m, size_t nx, size_t ny,
                                   const tt__tile_borders *b);

/* Whether sample (col, row) of the nx x ny tile grid lies on a shared
 * side: 1 and *out_kept (whether it is a border vertex) when it does, else
 * 0. */
TT_HIDDEN int tt__tile_on_border(const tt__tile_borders *b, size_t nx,
                                 size_t ny, int32_t col, int32_t row,
                                 bool *out_kept);

/* Simplifies one border line of n samples z (NaN: nodata) to max_error:
 * sets keep[i] for the samples that become vertices. brk[i] marks the
 * samples that must end a polyline (the line's ends and every sample next
 * to nodata on the line or on the lines either side of it); each run
 * between two consecutive breaks is then simplified top-down (the worst
 * sample under the chord first, the first of equal ones), until every
 * sample of the run is within max_error of its chord, less a margin of a
 * few ulps of the heights (border.c). False when out of memory. */
TT_HIDDEN bool tt__border_simplify(const double *z, const uint8_t *brk,
                                   size_t n, double max_error,
                                   uint8_t *keep);

/* Greedy insertion of a tile grid with its border vertices forced and its
 * shared sides kept (refine.c): the options' stop conditions must be a
 * max error, or a max_points counting only the vertices inserted after
 * the start (its corners, nodata outline and border vertices: decimation's
 * greedy:N start in tiles). The TIN records, per vertex, the triangle its own sample
 * is counted in (tt_tin.v_home), for the merge. */
TT_HIDDEN tt_status tt__refine_tile(tt_context *ctx, const tt_grid *grid,
                                    const tt_refine_options *opt,
                                    const tt__tile_borders *borders,
                                    tt_tin **out_tin);

/* Vertex decimation of a tile grid (decimate.c): the start's samples on
 * shared sides that are not border vertices are removed first, the border
 * vertices are never removed, and border edges are flagged as refinement
 * does; opt's stop conditions must be a max error only. With start
 * greedy:N, N counts the vertices inserted after the tile's start. v_home
 * is filled as by tt__refine_tile. */
TT_HIDDEN tt_status tt__decimate_tile(tt_context *ctx, const tt_grid *grid,
                                      const tt_decimate_options *opt,
                                      const tt__tile_borders *borders,
                                      tt_tin **out_tin);

/* --- the streamed merge (stream.c) ----------------------------------------
 * The pieces of a tiled run joined in tile order, as tt_tin_merger joins
 * them, but handed out as batches of rows instead of kept: each add gives
 * the piece's triangles (tri: the piece's vertex arrays, its triangles
 * with the merged sample counts and rmse; map: its vertex indices to the
 * global ids; tri_first: the global index of its first triangle; tri NULL
 * when the piece has none) and the vertices that became final (vtx: their
 * values with the star statistics of every tile touching them, in id
 * order from vtx_first; its rank is the index plus vtx_first; with their
 * importances when decimated, NaN otherwise). A geographic or Web
 * Mercator DEM's triangles come with their piece's ground points and the
 * area function. The batch is valid until the next add; the writer makes
 * the rows tt_tin_merger_finish()'s TIN would give. */
typedef struct tt__tin_stream tt__tin_stream;
typedef struct tt__stream_batch {
  const tt_tin *tri;
  const int32_t *map;
  size_t tri_first;
  const tt_tin *vtx;
  size_t vtx_first;
} tt__stream_batch;

/* The caller frees *out with tt__tin_stream_destroy(). */
TT_HIDDEN tt_status tt__tin_stream_create(tt_context *ctx, size_t dem_width,
                                          size_t dem_height, size_t tile_size,
                                          const double gt[6],
                                          tt__tin_stream **out);
TT_HIDDEN void tt__tin_stream_destroy(tt__tin_stream *s);
/* Adds tile k's piece (k: the tile order index, every tile once, in
 * order). */
TT_HIDDEN tt_status tt__tin_stream_add(tt_context *ctx, tt__tin_stream *s,
                                       const tt_tin *piece,
                                       const tt_tile *tile, size_t k,
                                       tt__stream_batch *out);
/* The area function of a geographic DEM's triangles, from tile 0's window
 * (set before tile 0 is added; else the first piece that has one gives
 * it), as tt_tin_merger_set_ground() does. */
TT_HIDDEN void tt__tin_stream_set_ground(tt__tin_stream *s,
                                         const tt_grid *window);
/* Vertices merged but not yet handed out (the reorder buffer). */
TT_HIDDEN size_t tt__tin_stream_pending(const tt__tin_stream *s);
/* The vertices and triangles numbered so far (the TIN's counts once every
 * tile is added; they only grow). */
TT_HIDDEN void tt__tin_stream_counts(const tt__tin_stream *s,
                                     size_t *out_vertices,
                                     size_t *out_triangles);
/* The bytes the stream holds (its arrays' capacities); 0 for NULL. */
TT_HIDDEN size_t tt__tin_stream_bytes(const tt__tin_stream *s);
/* The whole TIN's summary as tt_tin_merger_finish() sets it, and the range
 * of the vertices' heights. */
TT_HIDDEN void tt__tin_stream_summary(const tt__tin_stream *s,
                                      tt_tin_summary *out, double *out_zmin,
                                      double *out_zmax);

#endif /* TT_TILE_H */
