/*
 * minmax_angle.c -- the Min-Max angle criterion, SPEC section 2.2, in two
 * forms.
 *
 * Definition: minimise the largest 2-D (map) angle of the triangulation,
 * angles measured in the ground frame. Swap value (minmax_angle): the
 * largest of the six angles of the quad's two triangles before the swap
 * minus the largest after, in radians; positive when the swap lowers it.
 * The lexicographic form (minmax_angle_lex) compares the six angles sorted
 * in decreasing order: the swap value is the first difference (before -
 * after) larger than 1e-12 rad, so its sign is the lexicographic
 * comparison and its size the first differing difference; adding the same
 * unchanged angles of the rest of the mesh to both vectors keeps that
 * sign, so a positive value always improves the whole sorted vector.
 * Needs: the quad's four vertices only (no heights, no grid). A quad that
 * is not strictly convex scores 0 (geometry.h), so no hypothetical
 * triangle is degenerate. Cost: 4 atan2 (12 for the lexicographic form).
 */
#include "geometry.h"

/* The largest angle of triangle (p, q, r): the one opposite its longest
 * side. */
static double max_angle(tt__gvec p, tt__gvec q, tt__gvec r)
{
  tt__gvec pq = tt__gsub(q, p), qr = tt__gsub(r, q), rp = tt__gsub(p, r);
  double lpq = pq.x * pq.x + pq.y * pq.y;
  double lqr = qr.x * qr.x + qr.y * qr.y;
  double lrp = rp.x * rp.x + rp.y * rp.y;
  tt__gvec u, v; /* the two sides at the vertex opposite the longest */
  if (lpq >= lqr && lpq >= lrp) {
    u = tt__gsub(p, r);
    v = tt__gsub(q, r);
  } else if (lqr >= lrp) {
    u = tt__gsub(q, p);
    v = tt__gsub(r, p);
  } else {
    u = tt__gsub(p, q);
    v = tt__gsub(r, q);
  }
  return tt__gangle2(u, v);
}

static double minmax_swap_value(const tt__crit_env *env, int32_t e)
{
  double fr[4];
  tt__quad q;
  tt__geo_frame(env, fr);
  if (!tt__quad_load(env, e, fr, &q))
    return 0.0;
  double b1 = max_angle(q.pa, q.pb, q.pc), b2 = max_angle(q.pb, q.pa, q.pd);
  double a1 = max_angle(q.pc, q.pa, q.pd), a2 = max_angle(q.pd, q.pb, q.pc);
  double before = b1 > b2 ? b1 : b2, after = a1 > a2 ? a1 : a2;
  double d = before - after;
  return fabs(d) <= 1e-12 ? 0.0 : d;
}

/* The three angles of triangle (p, q, r) into out[0..2]. */
static void angles(tt__gvec p, tt__gvec q, tt__gvec r, double *out)
{
  out[0] = tt__gangle2(tt__gsub(q, p), tt__gsub(r, p));
  out[1] = tt__gangle2(tt__gsub(r, q), tt__gsub(p, q));
  out[2] = tt__gangle2(tt__gsub(p, r), tt__gsub(q, r));
}

static double minmax_lex_swap_value(const tt__crit_env *env, int32_t e)
{
  double fr[4];
  tt__quad q;
  tt__geo_frame(env, fr);
  if (!tt__quad_load(env, e, fr, &q))
    return 0.0;
  double before[6], after[6];
  angles(q.pa, q.pb, q.pc, before);
  angles(q.pb, q.pa, q.pd, before + 3);
  angles(q.pc, q.pa, q.pd, after);
  angles(q.pd, q.pb, q.pc, after + 3);
  tt__sort_desc(before, 6);
  tt__sort_desc(after, 6);
  return tt__lex_diff(before, after, 6);
}

const tt__criterion_vt tt__criterion_minmax_angle = {
    TT_CRITERION_MINMAX_ANGLE, "minmax_angle", false, minmax_swap_value,
    NULL};

const tt__criterion_vt tt__criterion_minmax_angle_lex = {
    TT_CRITERION_MINMAX_ANGLE_LEX, "minmax_angle_lex", false,
    minmax_lex_swap_value, NULL};
