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
 * triangle is degenerate. Angles are kept as points (cos, sin) scaled,
 * compared by a cross product, and only their difference goes through
 * atan2: one call per value (usually one for the lexicographic form too).
 * The quad is read in geometry.h's canonical form, so a swap and the swap
 * back have exactly opposite values.
 *
 * Part of src/criteria/, the criteria: one file per triangulation criterion
 * behind one vtable.
 */
#include "criteria/geometry.h"

/* An angle in [0, pi] as the point (d, c) = (u . v, |u x v|) of the upper
 * half-plane (2-D, heights ignored): its argument. Comparing two angles
 * or taking their difference needs no atan2 per angle. */
typedef struct angle {
  double d, c;
} angle;

static inline angle angle_of(tt__gvec u, tt__gvec v)
{
  angle a = {u.x * v.x + u.y * v.y, fabs(u.x * v.y - u.y * v.x)};
  return a;
}

/* > 0 when p is the larger angle, < 0 when q is, 0 on a tie. */
static inline double angle_cmp(angle p, angle q)
{
  return p.c * q.d - p.d * q.c;
}

/* p - q in radians: the argument of p / q. */
static inline double angle_diff(angle p, angle q)
{
  return atan2(p.c * q.d - p.d * q.c, p.d * q.d + p.c * q.c);
}

/* The largest angle of triangle (p, q, r): the one opposite its longest
 * side. */
static angle max_angle(tt__gvec p, tt__gvec q, tt__gvec r)
{
  tt__gvec pq = tt__gsub(q, p), qr = tt__gsub(r, q), rp = tt__gsub(p, r);
  double lpq = pq.x * pq.x + pq.y * pq.y;
  double lqr = qr.x * qr.x + qr.y * qr.y;
  double lrp = rp.x * rp.x + rp.y * rp.y;
  if (lpq >= lqr && lpq >= lrp)
    return angle_of(tt__gsub(p, r), tt__gsub(q, r));
  if (lqr >= lrp)
    return angle_of(tt__gsub(q, p), tt__gsub(r, p));
  return angle_of(tt__gsub(p, q), tt__gsub(r, q));
}

static double minmax_swap_value(const tt__crit_env *env, int32_t e)
{
  double fr[4];
  tt__quad q;
  tt__geo_frame(env, fr);
  if (!tt__quad_load(env, e, fr, &q))
    return 0.0;
  angle b1 = max_angle(q.pa, q.pb, q.pc), b2 = max_angle(q.pb, q.pa, q.pd);
  angle a1 = max_angle(q.pc, q.pa, q.pd), a2 = max_angle(q.pd, q.pb, q.pc);
  angle before = angle_cmp(b1, b2) >= 0 ? b1 : b2;
  angle after = angle_cmp(a1, a2) >= 0 ? a1 : a2;
  double d = angle_diff(before, after);
  return fabs(d) <= 1e-12 ? 0.0 : q.sign * d;
}

/* The three angles of triangle (p, q, r) into out[0..2]. */
static void angles(tt__gvec p, tt__gvec q, tt__gvec r, angle *out)
{
  out[0] = angle_of(tt__gsub(q, p), tt__gsub(r, p));
  out[1] = angle_of(tt__gsub(r, q), tt__gsub(p, q));
  out[2] = angle_of(tt__gsub(p, r), tt__gsub(q, r));
}

static void sort_desc(angle *x)
{
  for (int i = 1; i < 6; i++) {
    angle v = x[i];
    int j = i;
    for (; j > 0 && angle_cmp(x[j - 1], v) < 0; j--)
      x[j] = x[j - 1];
    x[j] = v;
  }
}

static double minmax_lex_swap_value(const tt__crit_env *env, int32_t e)
{
  double fr[4];
  tt__quad q;
  tt__geo_frame(env, fr);
  if (!tt__quad_load(env, e, fr, &q))
    return 0.0;
  angle before[6], after[6];
  angles(q.pa, q.pb, q.pc, before);
  angles(q.pb, q.pa, q.pd, before + 3);
  angles(q.pc, q.pa, q.pd, after);
  angles(q.pd, q.pb, q.pc, after + 3);
  sort_desc(before);
  sort_desc(after);
  for (int i = 0; i < 6; i++) {
    double d = angle_diff(before[i], after[i]);
    if (fabs(d) > 1e-12)
      return q.sign * d;
  }
  return 0.0;
}

const tt__criterion_vt tt__criterion_minmax_angle = {
    TT_CRITERION_MINMAX_ANGLE, "minmax_angle", false, minmax_swap_value,
    NULL, NULL, NULL, NULL, false};

const tt__criterion_vt tt__criterion_minmax_angle_lex = {
    TT_CRITERION_MINMAX_ANGLE_LEX, "minmax_angle_lex", false,
    minmax_lex_swap_value, NULL, NULL, NULL, NULL, false};
