/*
 * min_area.c -- the Min area criterion (MAT), SPEC section 2.3.
 *
 * Definition: minimise the total 3-D surface area of the TIN, sum of
 * area(T), in ground units (square metres when the frame and heights are
 * metres). Swap value: area(a, b, c) + area(b, a, d) before minus
 * area(c, a, d) + area(d, b, c) after; positive when the swap lowers the
 * area. Differences below 1e-12 of the four areas' sum are rounding noise
 * and read 0 (a flat quad has the same area either way). Needs: the quad's
 * four vertices and their heights. A quad that is not strictly convex
 * scores 0 (geometry.h); a zero-area triangle has area 0, never NaN. The
 * quad is read in geometry.h's canonical form, so a swap and the swap back
 * have exactly opposite values.
 * Cost: four cross products and four square roots.
 *
 * Part of src/criteria/, the criteria: one file per triangulation criterion
 * behind one vtable.
 */
#include "criteria/geometry.h"

static double min_area_swap_value(const tt__crit_env *env, int32_t e)
{
  double fr[4];
  tt__quad q;
  tt__geo_frame(env, fr);
  if (!tt__quad_load(env, e, fr, &q))
    return 0.0;
  double b = tt__garea(q.pa, q.pb, q.pc) + tt__garea(q.pb, q.pa, q.pd);
  double a = tt__garea(q.pc, q.pa, q.pd) + tt__garea(q.pd, q.pb, q.pc);
  return q.sign * tt__snap(b - a, b + a);
}

const tt__criterion_vt tt__criterion_min_area = {
    TT_CRITERION_MIN_AREA, "min_area", true, min_area_swap_value, NULL, NULL,
    NULL, NULL, false};
