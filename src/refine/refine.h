/*
 * refine.h -- what the other stages take from refinement (internal), beside
 * the public tt_refine_run and tile.h's tt__refine_tile.
 *
 * Part of src/refine/, the greedy insertion method (tt_refine_run).
 */
#ifndef TERRATIN_REFINE_H
#define TERRATIN_REFINE_H

#include "base/internal.h"

/* The vertices of the starting triangulation insertion builds on grid
 * (the four corners, or the valid samples' hull and the vertices the
 * nodata outline forces), counted as the TIN counts them (those in a
 * triangle): the fewest any TIN of grid that follows its outline can have,
 * and so the smallest point budget either method takes. Costs the start
 * only (no scan of the samples). */
TT_HIDDEN tt_status tt__refine_start_size(tt_context *ctx,
                                          const tt_grid *grid,
                                          size_t *out_vertices);

#endif
