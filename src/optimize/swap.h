/*
 * swap.h -- edge swapping under a criterion (SPEC section 3.2).
 *
 * tt__swap_repair restores the criterion around a newly inserted vertex:
 * starting from the edges opposite it, every edge with a positive swap
 * value that is flippable is flipped, and the two edges the flip puts
 * opposite the new vertex are examined next. For Delaunay this is the
 * classic outward legalisation and yields the Delaunay triangulation.
 * tt__swap_all runs Lawson's flip loop over every edge (used to make a
 * starting triangulation satisfy the criterion).
 *
 * Part of src/optimize/, the optimisers: swaps under a criterion, look-ahead,
 * annealing, edge insertion, the dynamic programs.
 */
#ifndef TT_SWAP_H
#define TT_SWAP_H

#include "criteria/criterion.h"
#include "mesh/mesh.h"

typedef struct tt__edge_stack {
  int32_t *e;
  size_t n, cap;
} tt__edge_stack;

TT_HIDDEN void tt__edge_stack_free(tt__edge_stack *s);

/* opposite: n half-edges opposite the new vertex (entries < 0 ignored).
 * Returns the number of flips, or -1 when out of memory (the mesh is valid
 * but the criterion may not hold everywhere). */
TT_HIDDEN long tt__swap_repair(tt__mesh *m, const tt__criterion_vt *crit,
                               const tt__crit_env *env,
                               const int32_t *opposite, int n,
                               tt__edge_stack *stack);
TT_HIDDEN long tt__swap_all(tt__mesh *m, const tt__criterion_vt *crit,
                            const tt__crit_env *env, tt__edge_stack *stack);

#endif /* TT_SWAP_H */
