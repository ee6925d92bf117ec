/*
 * tt_test_geom.h -- exact integer plane geometry for the tests' brute-force
 * oracles (polygon DP, hole DP): orientation, points on segments, closed
 * segments meeting, and a chord's midpoint strictly inside a polygon. Kept
 * apart from src/ on purpose: an oracle must not share the code it checks.
 */
#ifndef TT_TEST_GEOM_H
#define TT_TEST_GEOM_H

#include <stdbool.h>
#include <stdint.h>

/* (b - a) x (c - a): > 0 when a, b, c turn counter-clockwise (x right,
 * y up), exact for coordinates below 2^31. */
static inline int64_t tt_test_cross(int64_t ax, int64_t ay, int64_t bx,
                                    int64_t by, int64_t cx, int64_t cy)
{
  return (bx - ax) * (cy - ay) - (by - ay) * (cx - ax);
}

static inline int tt_test_sgn(int64_t v) { return (v > 0) - (v < 0); }

/* p on the closed segment a-b. */
static inline bool tt_test_on_segment(int64_t ax, int64_t ay, int64_t bx,
                                      int64_t by, int64_t px, int64_t py)
{
  return tt_test_cross(ax, ay, bx, by, px, py) == 0 &&
         px >= (ax < bx ? ax : bx) && px <= (ax < bx ? bx : ax) &&
         py >= (ay < by ? ay : by) && py <= (ay < by ? by : ay);
}

/* The closed segments a-b and c-d of points x[], y[] meet. */
static inline bool tt_test_segments_meet(const int64_t *x, const int64_t *y,
                                         int a, int b, int c, int d)
{
  int o1 = tt_test_sgn(tt_test_cross(x[a], y[a], x[b], y[b], x[c], y[c]));
  int o2 = tt_test_sgn(tt_test_cross(x[a], y[a], x[b], y[b], x[d], y[d]));
  int o3 = tt_test_sgn(tt_test_cross(x[c], y[c], x[d], y[d], x[a], y[a]));
  int o4 = tt_test_sgn(tt_test_cross(x[c], y[c], x[d], y[d], x[b], y[b]));
  if (o1 * o2 < 0 && o3 * o4 < 0)
    return true;
  return tt_test_on_segment(x[a], y[a], x[b], y[b], x[c], y[c]) ||
         tt_test_on_segment(x[a], y[a], x[b], y[b], x[d], y[d]) ||
         tt_test_on_segment(x[c], y[c], x[d], y[d], x[a], y[a]) ||
         tt_test_on_segment(x[c], y[c], x[d], y[d], x[b], y[b]);
}

/* The midpoint of points i and j strictly inside the polygon of the first
 * n points (in order): even-odd ray count in doubled coordinates, the ray
 * going in +x, crossings counted by the half-open rule on y; a midpoint on
 * a side is not inside. */
static inline bool tt_test_midpoint_inside(int n, const int64_t *x,
                                           const int64_t *y, int i, int j)
{
  int64_t mx = x[i] + x[j], my = y[i] + y[j];
  bool in = false;
  for (int k = 0; k < n; k++) {
    int k1 = (k + 1) % n;
    int64_t ax = 2 * x[k], ay = 2 * y[k], bx = 2 * x[k1], by = 2 * y[k1];
    if (tt_test_on_segment(ax, ay, bx, by, mx, my))
      return false;
    if ((ay > my) != (by > my)) {
      /* the crossing's x beyond mx? */
      int64_t c = tt_test_cross(ax, ay, bx, by, mx, my);
      if ((by > ay) ? c > 0 : c < 0)
        in = !in;
    }
  }
  return in;
}

#endif /* TT_TEST_GEOM_H */
