/*
 * delaunay.c -- the Delaunay (Max-Min angle) criterion, SPEC section 2.1.
 *
 * An edge a->b of triangle (a, b, c) with opposite vertex d across it is
 * illegal when d lies strictly inside the ground-frame circumcircle of
 * (a, b, c). The test is exact (predicates.c): grid cells are co-circular,
 * so ties are the normal case, and a tie is legal: the edge stays. Flipping
 * illegal edges reaches the global Delaunay triangulation.
 *
 * Part of src/criteria/, the criteria: one file per triangulation criterion
 * behind one vtable.
 */
#include "criteria/criterion.h"

static double delaunay_swap_value(const tt__crit_env *env, int32_t e)
{
  const tt__mesh *m = env->mesh;
  int32_t f = m->twin[e];
  int32_t a = m->hv[e], b = m->hv[f];
  int32_t c = tt__mesh_apex(m, e), d = tt__mesh_apex(m, f);
  return (double)tt__mesh_incircle(m, a, b, c, d);
}

const tt__criterion_vt tt__criterion_delaunay = {
    TT_CRITERION_DELAUNAY, "delaunay", false, delaunay_swap_value, NULL, NULL,
    NULL, NULL, false};
