/*
 * hole_dp.h -- exact minimum 3-D area re-triangulation of the hole around a
 * newly inserted vertex (SPEC section 2 item 3 and section 3.5); the hole
 * is defined in docs/min_area_hole.md.
 *
 * The hole of v: the triangles of v's star, plus, across each link edge
 * (the edge of a star triangle opposite v), the neighbouring triangle when
 * that edge has one, is not constrained, and the neighbour's apex is
 * neither a vertex of the star nor the apex of another such neighbour.
 * Its outline is a simple polygon of up to 6 vertices after a triangle
 * split and 8 after an edge split, with v strictly inside (or on the
 * outline when v lies on the mesh's boundary). Every triangulation of the
 * hole that keeps v as a vertex is a fan of triangles at v plus pockets
 * between the fan and the outline; the dynamic programme runs over both
 * (pockets as in polygon_dp.c, the fan as a shortest path around v), so
 * its minimum is exact. Constrained spokes at v (v inserted on a
 * constrained edge) and the outline are never crossed.
 *
 * Part of src/optimize/, the optimisers: swaps under a criterion, look-ahead,
 * annealing, edge insertion, the dynamic programs.
 */
#ifndef TT_HOLE_DP_H
#define TT_HOLE_DP_H

#include "criteria/criterion.h"
#include "mesh/mesh.h"

/* The largest hole outline handled (vertices); a star of more than
 * TT__HOLE_MAX_N / 2 triangles is not grown by its neighbours, a star of
 * more than TT__HOLE_MAX_N is left as it is. v's new star has at most
 * TT__HOLE_MAX_N triangles, so opposite[] with that many entries always
 * receives every link edge. */
#define TT__HOLE_MAX_N 24

/* After vertex v was inserted (its star is the 3 or 4 triangles of a split,
 * or 2 at the mesh's boundary), re-triangulates the hole around v to the
 * exact minimum of the total 3-D area (env's ground frame, heights from the
 * mesh vertices) with v as a vertex. The mesh changes only when that
 * minimum is below the hole's current area by more than 1e-12 of the sum
 * of both (ties keep the current triangles); a hole with no triangulation
 * under the exact rules (cannot happen in a valid mesh) is left as it is.
 * Writes the half-edges opposite v in v's (new) star -- its link edges,
 * each with v as the apex of its triangle, counter-clockwise around v --
 * to opposite[], at most max of them, and returns how many it wrote; 0
 * when v is in no triangle; -1 when out of memory (mesh valid and
 * unchanged). env->mesh must be m. Changed triangles are logged as
 * touched. */
TT_HIDDEN int tt__hole_min_area(tt__mesh *m, const tt__crit_env *env,
                                int32_t v, int32_t *opposite, int max);

#endif /* TT_HOLE_DP_H */
