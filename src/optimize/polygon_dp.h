/*
 * polygon_dp.h -- optimal triangulation of a simple polygon by dynamic
 * programming (SPEC section 3.5), behind a measure callback so that
 * refinement (min area over the hole around an inserted vertex) and, later,
 * decimation (re-triangulating the hole of a removed vertex) share it.
 *
 * The polygon's n vertices are integer pixel points given in order around
 * it; orient is the sign (+1 or -1) that tt__orient_i gives for three of
 * its corners turning the way the polygon runs (the mesh's det_sign for a
 * counter-clockwise polygon in the ground frame). A diagonal is allowed
 * when it lies inside the polygon: it crosses no side, touches no vertex
 * but its ends, and leaves each end into the polygon's interior (exact
 * integer orientation tests); a triangle is allowed when its corners turn
 * strictly the polygon's way (no zero-area triangle from collinear sides).
 *
 * Decomposable measures: the value of a triangulation is G over its
 * triangles, G the sum (total 3-D area) or the maximum (largest angle,
 * largest edge), minimised. Q(i, j) is the best value of sub-polygon
 * v_i..v_j closed by the diagonal (i, j); Q(i, j) = best over apexes k of
 * G(Q(i, k), Q(k, j), measure(i, k, j)); ties go to the smallest k, so the
 * result is reproducible. O(n^3) time, O(n^2) space.
 *
 * Part of src/optimize/, the optimisers: swaps under a criterion, look-ahead,
 * annealing, edge insertion, the dynamic programs.
 */
#ifndef TT_POLYGON_DP_H
#define TT_POLYGON_DP_H

#include "base/internal.h"

typedef enum tt__dp_combine {
  TT__DP_SUM = 0,   /* minimise the sum of the measures */
  TT__DP_MAX        /* minimise the largest measure */
} tt__dp_combine;

/* The measure of triangle (v_i, v_j, v_k) of the polygon, i < j < k, the
 * corners in the polygon's turning order. Must not be NaN. */
typedef double (*tt__dp_measure)(void *arg, int i, int j, int k);

/* Triangulates the polygon (3 <= n <= TT__DP_MAX_N): writes n - 2 triangles
 * as index triples (i < j < k, polygon order) into out_tris and the best
 * value into *out_value (either may be NULL). Returns false when the
 * polygon has no triangulation under the rules above (not simple, or
 * degenerate) or when out of memory. */
#define TT__DP_MAX_N 4096
TT_HIDDEN bool tt__polygon_dp(int n, const int64_t *x, const int64_t *y,
                              int orient, tt__dp_combine combine,
                              tt__dp_measure measure, void *arg,
                              int32_t *out_tris, double *out_value);

/* Whether the diagonal (i, j) of the polygon lies inside it (the rule
 * above); exposed for tests. */
TT_HIDDEN bool tt__polygon_diagonal_ok(int n, const int64_t *x,
                                       const int64_t *y, int orient, int i,
                                       int j);

#endif /* TT_POLYGON_DP_H */
