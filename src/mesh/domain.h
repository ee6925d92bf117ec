/*
 * domain.h -- the valid domain of a grid with nodata as the constrained
 * outline of the starting triangulation (see domain.c).
 *
 * Part of src/mesh/, the mesh stage: the half-edge mesh, the samples a
 * triangle owns, the nodata domain.
 */
#ifndef TT_DOMAIN_H
#define TT_DOMAIN_H

#include "criteria/criterion.h"
#include "mesh/mesh.h"
#include "optimize/swap.h"

/* Adds a vertex for sample (col, row) to the caller's bookkeeping and the
 * mesh; false when out of memory. */
typedef bool (*tt__domain_add_vertex)(void *arg, int32_t col, int32_t row,
                                      int32_t *out_v);

/* m holds a triangulation of the valid samples' convex hull. Inserts the
 * vertices of the domain's lean outline (a polygon holding the valid
 * domain and no nodata sample, see domain.c), recovers its segments as
 * constrained edges, restores the criterion elsewhere, and deletes the
 * triangles outside it. */
TT_HIDDEN tt_status tt__domain_build(tt_context *ctx, tt__mesh *m,
                                     const tt_grid *g,
                                     const tt__criterion_vt *crit,
                                     const tt__crit_env *env,
                                     tt__edge_stack *stack,
                                     tt__domain_add_vertex add_vertex,
                                     void *add_arg);

/* Recovers the segment between vertices a and b of m as constrained
 * edges by flips (split at the vertices that lie on it, as the outline's
 * runs are). False when out of memory; *out_ok is set false when the mesh
 * defeats the recovery (a constrained edge crosses the segment). */
TT_HIDDEN bool tt__domain_recover_segment(tt__mesh *m, int32_t a, int32_t b,
                                          bool *out_ok);

#endif /* TT_DOMAIN_H */
