/*
 * edge_insert.h -- edge insertion for the Min-Max angle (Bern, Edelsbrunner,
 * Eppstein, Mitchell, Tan; SPEC section 3.4).
 *
 * Repeat: take the worst triangle T (largest 2-D angle mu, an indexed
 * heap over the triangle slots) and its anchor p, the vertex of that
 * angle. Try edges p-q for the vertices q that p sees through the edge of
 * T opposite p, nearest first (by the number of edges p-q crosses): remove
 * the triangles p-q crosses, triangulate the two polygons on either side of
 * p-q optimally for the largest angle (polygon_dp.h), and keep the first
 * whose new triangles all have angles below mu - 1e-12. Stop when no edge
 * from the anchor improves: by the theorem of Bern et al. the largest
 * angle is then the least any triangulation of those vertices (with those
 * constrained edges) can have. Past that point the run goes on with the
 * next worst triangle, the stuck ones set aside: each insertion still
 * replaces a triangle of angle mu and makes none of mu or more, so the
 * vector of the triangles' largest angles, sorted in decreasing order,
 * gets lexicographically smaller every time, and the triangles below the
 * forced largest angle improve too (a TIN's largest angle is often forced
 * by its outline); that phase tries edges crossing at most
 * TT__EI_MORE_DEPTH edges. The run ends when every triangle is set
 * aside.
 *
 * Exact: which vertex p sees, which edges p-q crosses and whether a
 * polygon's diagonal lies inside it are integer orientation tests
 * (tt__mesh_orient, polygon_dp.c); a vertex on p-q blocks it. Constrained
 * and boundary edges are never crossed; the outline and every constrained
 * edge stay.
 *
 * Cost: every triangle is the worst once or more; the search of one
 * anchor visits the visible triangles within TT__EI_MAX_DEPTH crossed
 * edges (the depth bound keeps a failed search local on a mesh of 100k
 * vertices; the optimum is exact when every improving edge crosses fewer,
 * as on every test set). The touched log is emptied along the way.
 *
 * Part of src/optimize/, the optimisers: swaps under a criterion, look-ahead,
 * annealing, edge insertion, the dynamic programs.
 */
#ifndef TT_EDGE_INSERT_H
#define TT_EDGE_INSERT_H

#include "criteria/criterion.h"
#include "mesh/mesh.h"
#include "optimize/optimize.h"

#define TT__EI_MAX_DEPTH 32
#define TT__EI_MORE_DEPTH 8

typedef struct tt__edge_insert_stats {
  long insertions;   /* edges inserted */
  long candidates;   /* edges p-q tried */
  long refused;      /* improving insertions the accept callback refused */
  double start_max;  /* the largest angle before and after, radians */
  double end_max;
  bool optimum_reached; /* a worst triangle was stuck with no refusal: */
  double optimum_max;   /* its angle, the least largest angle there is */
} tt__edge_insert_stats;

/* Runs edge insertion over the whole mesh (2-D angles in env's ground
 * frame). accept as in optimize.h (slots: the new triangles). The mesh
 * stays valid. False when out of memory (the mesh is valid and its
 * largest angle no larger than at the start). */
TT_HIDDEN bool tt__edge_insert_run(tt__mesh *m, const tt__crit_env *env,
                                   tt__opt_accept_fn accept,
                                   void *accept_arg,
                                   tt__edge_insert_stats *out_stats);

/* The largest 2-D angle (radians) of live triangle t in env's frame, as
 * the run measures it. */
TT_HIDDEN double tt__edge_insert_tri_angle(const tt__mesh *m,
                                           const tt__crit_env *env,
                                           int32_t t);

#endif /* TT_EDGE_INSERT_H */
