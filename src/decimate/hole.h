/*
 * hole.h -- re-triangulating the hole a removed vertex leaves (SPEC
 * sections 3.5 and 3.6): ear cutting under a rule, or the exact optimum
 * of a decomposable measure through polygon_dp.c.
 *
 * The hole is the link of the vertex: p_0..p_{n-1} counter-clockwise in
 * the ground frame, closed (interior vertex) or closed by the edge
 * p_{n-1} -> p_0 through the vertex (a vertex on a straight run of the
 * boundary). Both are simple polygons; the first is star-shaped from the
 * vertex, the second from a point just inside it. Such a polygon always
 * has a triangulation into strictly counter-clockwise triangles, so the
 * fill never fails for want of one: ear cutting with exact orientation
 * tests finds an ear at every step (docs/decimation.md gives the
 * argument), collinear runs and slivers included.
 *
 * Part of src/decimate/, the vertex decimation method (tt_decimate_run).
 */
#ifndef TT_DECIMATE_HOLE_H
#define TT_DECIMATE_HOLE_H

#include "base/internal.h"
#include "mesh/mesh.h"

typedef struct tt__dhole {
  int n;                /* polygon vertices */
  int32_t *p;           /* mesh vertices, counter-clockwise */
  int ntri;             /* n - 2 after a fill */
  int32_t (*tri)[3];    /* mesh vertex triples, counter-clockwise */
  /* scratch of the ear cutting and the DP */
  int *prev, *next;
  bool *ear;
  bool *convex;         /* corner turns strictly (ear cutting) */
  double *score;
  double *gx, *gy;      /* ground coordinates relative to p_0 */
  int64_t *px, *py;     /* pixel coordinates */
  int32_t *idx;         /* DP output */
  size_t cap;
} tt__dhole;

TT_HIDDEN void tt__dhole_init(tt__dhole *h);
TT_HIDDEN void tt__dhole_free(tt__dhole *h);
/* Room for polygons of n vertices; false when out of memory. */
TT_HIDDEN bool tt__dhole_reserve(tt__dhole *h, int n);

/* Triangulates h->p[0..h->n) (set by the caller, room reserved) into
 * h->tri: rule TT_HOLE_MINANGLE, TT_HOLE_CIRCUMRADIUS or TT_HOLE_DP (the
 * criterion's decomposable measure: max-min angle for delaunay, min-max
 * angle for minmax_angle and minmax_angle_lex, total 3-D area for
 * min_area). frame: the grid's ground frame. False when no triangulation
 * was found (never for a simple polygon, which tests check) or, for dp,
 * when out of memory. */
TT_HIDDEN bool tt__dhole_fill(tt__dhole *h, const tt__mesh *m,
                              const double frame[4], tt_hole rule,
                              tt_criterion crit);

/* Whether the criterion has a decomposable measure for TT_HOLE_DP. */
TT_HIDDEN bool tt__dhole_dp_supported(tt_criterion crit);

#endif /* TT_DECIMATE_HOLE_H */
