/*
 * anneal.h -- simulated annealing of a criterion over the whole mesh
 * (Schumaker; SPEC section 3.3).
 *
 * Stages k = 1..K run at temperature t_k = r^k t0. A stage draws random
 * swappable edges (uniform over the half-edges of the live triangles,
 * redrawn until swappable) and, for each, with d its swap value: swaps an
 * improving one (d > tol), a neutral one (|d| <= tol), and a worsening one
 * with probability exp(d / t_k). It ends after S tries or G improving
 * swaps; a stage that swaps nothing ends the run. The generator is a
 * xoshiro256** of the run's own, seeded from the options through
 * splitmix64: the same seed and mesh give the same TIN byte for byte.
 *
 * The best triangulation seen is the one left in the mesh, never a worse
 * one than the start. Quality is tracked as the sum of the swap values
 * taken (exact, up to rounding, for the additive criteria: min area, mean
 * curvature, Gaussian, abn_sum, abn_sumsq, L2) and, for the max-type
 * criteria, first by the true global value: the largest triangle angle
 * for minmax_angle and minmax_angle_lex, the largest angle between
 * normals for abn, kept in an indexed heap; then by that sum (a
 * surrogate for the rest of their sorted vectors). For the two
 * lexicographic ones (minmax_angle_lex, abn) the start is also saved, and
 * when the sorted vector of the best is lexicographically worse than the
 * start's, the start is what the run returns. Delaunay is not
 * annealed: its flips reach the global optimum, so the run is the local
 * swap (optimize.h).
 *
 * Every swap since the best is kept in an undo log; when the log is full
 * the run goes back to the best, saves it whole (tt__mesh_snapshot), and
 * replays the log, so memory stays bounded by the log's size. The touched
 * log of the mesh is emptied along the way (a run writes nearly every
 * slot: callers treat the whole mesh as changed).
 *
 * Constrained and boundary edges are never swapped, non-convex quads
 * neither. The accept callback (optimize.h), when given, may refuse a
 * swap after it was made; it is then taken back.
 *
 * Part of src/optimize/, the optimisers: swaps under a criterion, look-ahead,
 * annealing, edge insertion, the dynamic programs.
 */
#ifndef TT_ANNEAL_H
#define TT_ANNEAL_H

#include "criteria/criterion.h"
#include "mesh/mesh.h"
#include "optimize/optimize.h"

typedef struct tt__anneal_stats {
  long stages;     /* stages run */
  long tries;      /* random swappable edges tried */
  long swaps;      /* swaps made (improving, neutral and worsening) */
  long worse;      /* worsening swaps made */
  long refused;    /* swaps the accept callback refused */
  long saves;      /* snapshots of the best taken */
  long edges;      /* E: the swappable edges at the start */
  double t0;       /* the start temperature used */
  double gain;     /* the sum of the swap values from the start to the
                      triangulation returned (>= 0 for the additive
                      criteria; for the max-type ones the global value
                      decides first, and the sum may be below 0) */
} tt__anneal_stats;

/* Anneals the whole mesh under crit (not Delaunay: see above) with the
 * schedule of opt (zero fields: the defaults of terratin.h). The mesh
 * stays valid. False when out of memory (the mesh is then valid and no
 * worse than at the start). */
TT_HIDDEN bool tt__anneal_run(tt__mesh *m, const tt__criterion_vt *crit,
                              const tt__crit_env *env,
                              const tt_anneal_options *opt,
                              tt__opt_accept_fn accept, void *accept_arg,
                              tt__anneal_stats *out_stats);

/* The same with an undo log of log_records records (0: the default, the
 * slot count within [65536, 2^20]); the result does not depend on it
 * (test_optimum checks a log of 8 against the default). */
TT_HIDDEN bool tt__anneal_run_log(tt__mesh *m, const tt__criterion_vt *crit,
                                  const tt__crit_env *env,
                                  const tt_anneal_options *opt,
                                  tt__opt_accept_fn accept, void *accept_arg,
                                  size_t log_records,
                                  tt__anneal_stats *out_stats);

#endif /* TT_ANNEAL_H */
