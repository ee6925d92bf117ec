/*
 * criterion.h -- the small interface every triangulation criterion
 * implements (SPEC section 2), one file per criterion in src/criteria/.
 *
 * A criterion scores a triangulation; what the optimisers need is local:
 * swap_value(e) = Quality(after swapping e) - Quality(before), positive when
 * the swap improves the triangulation, computed from e's neighbourhood only.
 * The caller guarantees e has a twin; the criterion may assume nothing about
 * convexity (flippability is checked by the mesh). Delaunay answers with the
 * exact incircle sign (+1, 0, -1), so ties never flip and flipping
 * terminates.
 */
#ifndef TT_CRITERION_H
#define TT_CRITERION_H

#include "base/internal.h"
#include "mesh/mesh.h"

typedef struct tt__crit_env {
  const tt__mesh *mesh;
  const tt_grid *grid;   /* heights, for data-dependent criteria; the
                            ground frame is grid->frame: a pixel step
                            (dc, dr) is (a0 dc + a1 dr, a2 dc + a3 dr) on
                            the ground, and heights are in ground units */
  void *cache;           /* the criterion's own per-run state (cache_new),
                            or NULL: every criterion works without it */
} tt__crit_env;

typedef struct tt__criterion_vt {
  tt_criterion id;
  const char *name;
  bool data_dependent;   /* uses heights, not only x,y */
  /* Quality(after swapping e) - Quality(before), > 0 when the swap
   * improves; e has a twin (convexity is the caller's business). */
  double (*swap_value)(const tt__crit_env *env, int32_t e);
  /* After a swap made half-edge h (the new diagonal, mesh.h), writes the
   * half-edges whose swap values may have changed into out (at most max)
   * and returns their count. NULL: the four outer edges of the quad (enough
   * for every criterion whose swap value depends on the two triangles of
   * an edge only; Gaussian curvature needs the edges around the quad's
   * vertices). */
  int (*affected)(const tt__crit_env *env, int32_t h, int32_t *out, int max);
  /* Optional per-run state (a cache of values that only depend on the
   * mesh around a vertex, say): cache_new returns it for env->cache, NULL
   * when out of memory (the run then goes on without); cache_free frees
   * it. The state must never change a swap value, only its cost. Both
   * NULL: no state. */
  void *(*cache_new)(const tt__crit_env *env);
  void (*cache_free)(void *cache);
  /* Optional (NULL: nothing to do): told by a flip loop right after it
   * flipped an edge, h the new diagonal as tt__mesh_flip returned it, so
   * that a cache can keep what it computed for the configuration just
   * taken. Not every flip is reported; like the cache itself it may never
   * change a swap value. */
  void (*flipped)(const tt__crit_env *env, int32_t h);
  /* The cache reads star versions (mesh.h): a refinement run then tracks
   * them (a cost on every mesh operation, so only then). */
  bool star_versions;
} tt__criterion_vt;

/* The criterion of an id, or NULL for an unknown id. */
TT_HIDDEN const tt__criterion_vt *tt__criterion_get(tt_criterion id);

TT_HIDDEN extern const tt__criterion_vt tt__criterion_delaunay;

#endif /* TT_CRITERION_H */
