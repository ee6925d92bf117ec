/*
 * optimize.h -- local swap and look-ahead swap optimisation of a criterion
 * (SPEC section 3.2), over the whole mesh or a region grown from seed edges.
 *
 * Local swap ("maximal reduction"): the swap value of every swappable edge
 * in scope sits in an indexed max-heap; the edge with the largest positive
 * value is swapped and the edges whose values it may change are re-scored
 * (the criterion's affected-edges hook; by default the quad's four outer
 * edges), until no value above the threshold is left. Edges are identified
 * by their vertex pair, which a flip does not renumber (half-edge indices
 * it does); heap items are small ids handed out in the order edges are
 * met, so ties break the same way on every run.
 *
 * Look-ahead (Dyn, Hormann, Kim, Levin): first the local swap above runs to
 * its local optimum; then edges with SwapValue(e) <= 0 are keyed by
 * SwapValue+(e) = SwapValue(e) + max over the 4 quad edges of their value
 * after swapping e (tried with an exact undo, mesh.h), and a move swaps e
 * and then the best follow-up, taking both back if the pair does not
 * improve. Each edge starts at most one pair in a run, which bounds the
 * phase. For a criterion whose swap values are differences of an additive
 * total (min area, the curvatures, ABN sum and sum of squares, L2) every
 * move improves that total, so look-ahead never ends worse than plain
 * local swap from the same start. For the max-type criteria (min-max
 * angle and its lexicographic form, lexicographic ABN) v + w is only a
 * heuristic score of a pair: a pair is kept only when the sorted vector of
 * its three triangles (their angles, or the angles between normals across
 * their edges) gets better, so no move makes the global value worse.
 * Delaunay skips the look-ahead phase: its swap values are incircle signs,
 * not quality differences, and its local optimum is the global one.
 *
 * Cycles from floating-point noise: a single swap with value v is taken
 * only when v > tol, tol = TT__OPT_REL_EPS times the largest |swap value|
 * met in the run, and when the swap back then scores r < 0 with
 * v > |v + r| (the improvement exceeds the asymmetry of the two
 * evaluations, a measure of their rounding); otherwise it is taken back and
 * the edge rests until a swap beside it changes its neighbourhood. A pair
 * must improve by more than TT__OPT_PAIR_EPS times that largest value. As a
 * last resort a run stops after 32 moves per edge in scope (+1024) and
 * says so in its statistics.
 *
 * Constrained and boundary edges are never swapped; non-convex quads
 * neither (tt__mesh_flippable).
 *
 * Part of src/optimize/, the optimisers: swaps under a criterion, look-ahead,
 * annealing, edge insertion, the dynamic programs.
 */
#ifndef TT_OPTIMIZE_H
#define TT_OPTIMIZE_H

#include "criteria/criterion.h"
#include "mesh/mesh.h"
#include "optimize/swap.h"

#define TT__OPT_REL_EPS 1e-12
#define TT__OPT_PAIR_EPS 1e-9

/* Called after a move, before it is kept: slots are the triangle slots
 * the move wrote. Returning false takes the move back. */
typedef bool (*tt__opt_accept_fn)(void *arg, const tt__mesh *m,
                                  const int32_t *slots, int nslots);

typedef struct tt__opt_params {
  const tt__criterion_vt *crit;
  const tt__crit_env *env;
  bool lookahead;
  tt__opt_accept_fn accept;  /* NULL: every improving move is kept */
  void *accept_arg;
} tt__opt_params;

typedef struct tt__opt_stats {
  long swaps;       /* single swaps kept */
  long pairs;       /* look-ahead pairs kept */
  long refused;     /* moves the accept callback refused */
  long noisy;       /* moves taken back: a swap whose swap back scored
                       >= 0 too, or a max-type pair that did not better
                       the vector of its three triangles */
  double tol;       /* at the end every swappable edge in scope that is
                       not resting has a swap value <= tol */
  bool budget_hit;  /* stopped by the move budget */
} tt__opt_stats;

/* Optimises the edges of the nseeds half-edges of seeds (entries < 0
 * ignored) and every edge a swap reaches from them; seeds NULL: every edge
 * of the mesh. The mesh stays valid. False when out of memory (the mesh is
 * valid, the criterion may not hold everywhere). */
TT_HIDDEN bool tt__optimize_run(tt__mesh *m, const tt__opt_params *p,
                                const int32_t *seeds, size_t nseeds,
                                tt__opt_stats *out_stats);

/* Restores the criterion after vertex v was inserted (refine.c), as
 * repair says (resolved, not TT_REPAIR_AUTO): the exact incircle repair
 * for Delaunay and for TT_REPAIR_DELAUNAY (swap.c); TT_REPAIR_FLIP, the
 * Lawson flips outward from v under the criterion (each flip gives v one
 * more spoke, so they end after fewer flips than v can have neighbours);
 * TT_REPAIR_LOCAL / LOOKAHEAD, the local swap (with look-ahead) seeded
 * with the spokes and the link of v's star (and, for criteria with an
 * affected-edges hook, every edge around the link's vertices). For
 * min_area, those swaps start from the exact least-area triangulation of
 * the hole around v (hole_dp.h).
 * opposite: the n half-edges opposite v (entries < 0 ignored). Returns the
 * number of swaps, or -1 when out of memory. */
TT_HIDDEN long tt__optimize_insert(tt__mesh *m, const tt__criterion_vt *crit,
                                   const tt__crit_env *env, tt_repair repair,
                                   int32_t v, const int32_t *opposite, int n,
                                   tt__edge_stack *stack);

/* The final whole-mesh pass of refinement: mode as in tt_refine_options,
 * TT_OPTIMIZE_AUTO resolved here for the criterion and repair
 * (tt_optimize_resolve). A move is refused when one of the triangles it
 * makes has an owned sample with |H - H'| > bound, so the run's error
 * bound survives the pass. anneal: the schedule of TT_OPTIMIZE_ANNEAL
 * (anneal.h; NULL: the defaults); TT_OPTIMIZE_EDGE_INSERTION is
 * edge_insert.h's, whatever crit (the caller checks it is minmax_angle).
 * Only the swaps (insertions) and refusals of out_stats are set for
 * those two. False when out of memory. */
TT_HIDDEN bool tt__optimize_final(tt__mesh *m, const tt__criterion_vt *crit,
                                  const tt__crit_env *env, tt_optimize mode,
                                  tt_repair repair, double bound,
                                  const tt_anneal_options *anneal,
                                  tt__opt_stats *out_stats);

#endif /* TT_OPTIMIZE_H */
