/*
 * breaklines.h -- the caller's breaklines made constrained edges of the
 * starting triangulation (see breaklines.c).
 *
 * Part of src/mesh/, the mesh stage: the half-edge mesh, the samples a
 * triangle owns, the nodata domain.
 */
#ifndef TT_BREAKLINES_H
#define TT_BREAKLINES_H

#include "mesh/domain.h"

/* m holds the starting triangulation of the valid domain (the outline
 * recovered, the triangles outside deleted). Inserts the ends of every
 * segment of bl as vertices (add_vertex, as tt__domain_build), recovers
 * every segment as constrained edges and restores the criterion
 * elsewhere. TT_ERR_DATA naming the segment when an end is not a valid
 * sample in the domain or a segment cannot be recovered (it crosses
 * another one or the outline). */
TT_HIDDEN tt_status tt__breaklines_insert(tt_context *ctx, tt__mesh *m,
                                          const tt_grid *g,
                                          const tt_breaklines *bl,
                                          const tt__criterion_vt *crit,
                                          const tt__crit_env *env,
                                          tt__edge_stack *stack,
                                          tt__domain_add_vertex add_vertex,
                                          void *add_arg);

/* Flags the edge between vertices a and b (either direction; none: false)
 * as a constrained edge on a breakline, both half-edges. */
TT_HIDDEN bool tt__breaklines_flag(tt__mesh *m, int32_t a, int32_t b);

#endif /* TT_BREAKLINES_H */
