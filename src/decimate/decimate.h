/*
 * decimate.h -- what the files of vertex decimation share (SPEC section
 * 3.6): the run's state, the evaluation of one vertex's removal
 * (importance.c), the starting TIN (start.c), the names and options
 * (options.c). decimate.c holds the loop.
 *
 * Vertices keep their mesh index for the whole run (removal frees
 * triangle slots, never vertex records), so per-vertex arrays are indexed
 * by it. A vertex is alive while m.v[v].edge >= 0.
 *
 * Part of src/decimate/, the vertex decimation method (tt_decimate_run).
 */
#ifndef TT_DECIMATE_H
#define TT_DECIMATE_H

#include "base/internal.h"
#include "criteria/criterion.h"
#include "decimate/hole.h"
#include "mesh/mesh.h"
#include "mesh/raster_scan.h"
#include "optimize/swap.h"
#include "tile/tile.h"

/* per-vertex flags */
#define TT__DV_PINNED 1u  /* may never go: several fans, or an inner
                             constrained edge */
#define TT__DV_DIRTY 2u   /* its star changed since it was scored */
#define TT__DV_BLOCKED 4u /* its removal would break the bound; until its
                             star changes */

typedef struct tt__dec {
  tt_context *ctx;
  const tt_grid *g;
  const tt_decimate_options *opt;
  const tt__criterion_vt *crit;
  tt__crit_env env;
  tt__mesh m;
  tt_importance importance;   /* resolved */
  tt_hole hole;               /* resolved */
  tt_repair repair;           /* resolved */
  double max_error;           /* < 0: none */
  tt__scan_tiles tiles;
  tt__edge_stack stack;
  tt__dhole h;                /* the hole being evaluated */
  uint8_t *vflag;             /* per vertex */
  double *vimp;               /* per vertex: importance (NaN: may not go) */
  size_t nvert;               /* vertices alive */
  const tt__tile_borders *borders; /* tile runs (tile.h), else NULL */
} tt__dec;

/* TT_OK when every field of o is in range and the set is coherent (a
 * stop condition, onepass with independent sets only, hole dp with a
 * decomposable criterion, the optimiser's own options), else TT_ERR_ARG
 * with the reason (options.c). */
TT_HIDDEN tt_status tt__decimate_check_options(tt_context *ctx,
                                               const tt_decimate_options *o);

/* What tt__dec_evaluate computes. */
typedef enum tt__dec_eval {
  TT__DEC_SCORE = 0, /* the importance (a fill when the measure needs it) */
  TT__DEC_FILL,      /* only the boundary rule and the fill */
  TT__DEC_CHECK      /* the fill and the error it would leave */
} tt__dec_eval;

/* The evaluation of removing vertex v from the current mesh: whether it
 * may go (the boundary rule), the hole's triangulation (left in d->h) and,
 * as `what` asks, the importance (*out_importance, NaN otherwise) or the
 * largest |H - H'| over the valid samples under the filled hole
 * (*out_error, may be NULL; with importance error both are that value).
 * Returns 1 when v may go, 0 when it may not (a corner, a pinned vertex;
 * or no fill, which tests show never happens), -1 when out of memory. */
TT_HIDDEN int tt__dec_evaluate(tt__dec *d, int32_t v, tt__dec_eval what,
                               double *out_importance, double *out_error);
/* The same with the hole in h (not d->h): it only reads d and the mesh,
 * so scores of several vertices may be computed at once in threads, each
 * with its own h. */
TT_HIDDEN int tt__dec_evaluate_in(const tt__dec *d, tt__dhole *h, int32_t v,
                                  tt__dec_eval what, double *out_importance,
                                  double *out_error);

/* The largest |H - H'| over the valid samples of the closed triangle
 * (a, b, c) of mesh vertices; 0 when none. */
TT_HIDDEN double tt__dec_triangle_error(const tt__dec *d, int32_t a,
                                        int32_t b, int32_t c);

/* Builds the starting TIN into d->m as opt->start says; d->m is
 * initialised by the caller. */
TT_HIDDEN tt_status tt__dec_start(tt__dec *d, size_t valid);

/* tt_decimate_run with a check called after every removal and its
 * repair (tests: mesh invariants after each step); check may be NULL. */
typedef void (*tt__dec_check_fn)(void *arg, const tt__mesh *m, int32_t v);
TT_HIDDEN tt_status tt__decimate_run_checked(tt_context *ctx,
                                             const tt_grid *grid,
                                             const tt_decimate_options *opt,
                                             tt__dec_check_fn check,
                                             void *check_arg,
                                             tt_tin **out_tin);

#endif /* TT_DECIMATE_H */
