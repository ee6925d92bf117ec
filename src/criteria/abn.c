/*
 * abn.c -- the ABN (angle between normals) criterion, SPEC section 2.6,
 * in three forms.
 *
 * Definition: alpha(e) is the angle (radians) between the unit normals of
 * the two triangles sharing edge e (0 on the boundary). abn minimises the
 * vector of alpha over all edges sorted in decreasing order,
 * lexicographically; abn_sum minimises the sum of alpha, abn_sumsq the
 * sum of squares. A swap changes alpha on the quad's five edges only (the
 * diagonal and the 4 outer edges against the triangles across them).
 * Swap value: abn -- the five alphas before and after, each sorted in
 * decreasing order, compared lexicographically: the first difference
 * (before - after) larger than 1e-12, so the sign is the comparison and
 * the size the first differing difference (unchanged edges of the rest of
 * the mesh do not change the sign of the whole comparison); abn_sum and
 * abn_sumsq -- the sum (of squares) before minus after, differences below
 * 1e-12 of the total read 0. Positive: the swap improves.
 * Needs: the quad and the apexes across its outer edges, so the affected
 * hook is mean curvature's (the quad edges and the edges of the triangles
 * across them). Quads that are not strictly convex score 0 (geometry.h).
 * The quad is read in geometry.h's canonical form, so a swap and the swap
 * back have exactly opposite values. Cost: 8 cross products and 10 atan2.
 *
 * Part of src/criteria/, the criteria: one file per triangulation criterion
 * behind one vtable.
 */
#include "criteria/geometry.h"

/* The five alphas before and after in the quad's canonical form; *sign
 * as in tt__quad. */
static bool abn_load(const tt__crit_env *env, int32_t e, double before[5],
                     double after[5], double *sign)
{
  double fr[4], len[5], len_cd;
  tt__quad q;
  tt__geo_frame(env, fr);
  if (!tt__quad_load(env, e, fr, &q))
    return false;
  tt__quad_alphas(env, fr, &q, before, after, len, &len_cd);
  *sign = q.sign;
  return true;
}

static double abn_swap_value(const tt__crit_env *env, int32_t e)
{
  double b[5], a[5], sign;
  if (!abn_load(env, e, b, a, &sign))
    return 0.0;
  tt__sort_desc(b, 5);
  tt__sort_desc(a, 5);
  return sign * tt__lex_diff(b, a, 5);
}

static double abn_sum_swap_value(const tt__crit_env *env, int32_t e)
{
  double b[5], a[5], sign;
  if (!abn_load(env, e, b, a, &sign))
    return 0.0;
  double sb = 0, sa = 0;
  for (int k = 0; k < 5; k++) {
    sb += b[k];
    sa += a[k];
  }
  return sign * tt__snap(sb - sa, sb + sa);
}

static double abn_sumsq_swap_value(const tt__crit_env *env, int32_t e)
{
  double b[5], a[5], sign;
  if (!abn_load(env, e, b, a, &sign))
    return 0.0;
  double sb = 0, sa = 0;
  for (int k = 0; k < 5; k++) {
    sb += b[k] * b[k];
    sa += a[k] * a[k];
  }
  return sign * tt__snap(sb - sa, sb + sa);
}

const tt__criterion_vt tt__criterion_abn = {
    TT_CRITERION_ABN, "abn", true, abn_swap_value, tt__affected_quad_ring,
    NULL, NULL, NULL, false};
const tt__criterion_vt tt__criterion_abn_sum = {
    TT_CRITERION_ABN_SUM, "abn_sum", true, abn_sum_swap_value,
    tt__affected_quad_ring, NULL, NULL, NULL, false};
const tt__criterion_vt tt__criterion_abn_sumsq = {
    TT_CRITERION_ABN_SUMSQ, "abn_sumsq", true, abn_sumsq_swap_value,
    tt__affected_quad_ring, NULL, NULL, NULL, false};
