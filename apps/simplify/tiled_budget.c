/*
 * tiled_budget.c -- apps/simplify/, the simplify command: -max_points,
 * -max_triangles and -percent in tiles (docs/scale.md): a budget of the
 * whole DEM turned into the one bound E every tile is refined to.
 *
 * A first pass records each tile's error-against-count curve
 * (tt_tile_curve: the tile refined without its border vertices, the
 * largest error of its candidates before each insertion). A run to a
 * bound E stops at the first point of the curve whose error is <= E, so
 * only the points where the error reaches a new low matter; of those a
 * curve keeps one every 2 % of vertices more (and the last), about 600
 * points of 12 bytes at most for a tile of a million vertices. A skipped
 * low is followed by a kept one with more vertices and a lower error, so
 * the count a thinned curve gives at E is never below the unthinned one's.
 * The bound is the smallest error of any curve at which the counts summed
 * over the tiles meet the target; the passes (tt__app_budget_passes) run
 * the tiles at it (tiled.c) and correct the target by what the real count
 * says, until a pass is kept. A pass not kept is dropped by the caller's
 * drop(): its merged TIN freed, or, streamed, the rows it wrote removed
 * (the caller writes each pass as if it were kept, and drops the rows of
 * one whose counts pass the budget as soon as they do).
 */
#include "simplify.h"

#include <math.h>
#include <stdlib.h>

static bool push(app_curve *c, size_t vertices, double err)
{
  if (c->n == c->cap) {
    size_t cap = c->cap ? 2 * c->cap : 16;
    uint32_t *p = realloc(c->pts, cap * sizeof *p);
    if (!p)
      return false;
    c->pts = p;
    double *e = realloc(c->err, cap * sizeof *e);
    if (!e)
      return false;
    c->err = e;
    c->cap = cap;
  }
  c->pts[c->n] = (uint32_t)vertices;
  c->err[c->n] = err;
  c->n++;
  c->has_pending = false;
  return true;
}

bool tt__app_curve_add(app_curve *c, size_t vertices, double err)
{
  if (c->n == 0 && !c->has_pending)
    c->low = INFINITY;
  if (!(err < c->low))
    return true;
  c->low = err;
  size_t last = c->n ? c->pts[c->n - 1] : 0;
  if (c->n && vertices < last + (last / 50 > 1 ? last / 50 : 1)) {
    c->pending_pts = vertices;
    c->pending_err = err;
    c->has_pending = true;
    return true;
  }
  return push(c, vertices, err);
}

bool tt__app_curve_end(app_curve *c)
{
  return !c->has_pending || push(c, c->pending_pts, c->pending_err);
}

void tt__app_curve_free(app_curve *c)
{
  free(c->pts);
  free(c->err);
  c->pts = NULL;
  c->err = NULL;
  c->n = c->cap = 0;
}

/* The vertices a tile has when refined to e: its first point at or below
 * e; past its end (a curve cut at its insertions), its last. */
size_t tt__app_curve_count_at(const app_curve *c, double e)
{
  if (c->n == 0)
    return 0;
  size_t lo = 0, hi = c->n; /* errors decrease along the curve */
  while (lo < hi) {
    size_t mid = (lo + hi) / 2;
    if (c->err[mid] <= e)
      hi = mid;
    else
      lo = mid + 1;
  }
  return c->pts[lo < c->n ? lo : c->n - 1];
}

static size_t sum_at(const app_curve *c, size_t n, double e)
{
  size_t s = 0;
  for (size_t k = 0; k < n; k++)
    s += tt__app_curve_count_at(&c[k], e);
  return s;
}

static int cmp_double(const void *a, const void *b)
{
  double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

bool tt__app_curves_bound(const app_curve *c, size_t n, size_t target,
                          double above, double below, double *out_bound,
                          size_t *out_estimate)
{
  size_t m = 1;
  for (size_t k = 0; k < n; k++)
    m += c[k].n;
  double *e = malloc(m * sizeof *e);
  if (!e)
    return false;
  size_t ne = 0;
  if (above < 0)
    e[ne++] = 0;
  for (size_t k = 0; k < n; k++)
    for (size_t i = 0; i < c[k].n; i++)
      if (c[k].err[i] > above && c[k].err[i] < below)
        e[ne++] = c[k].err[i];
  if (ne == 0) {
    free(e);
    *out_bound = NAN; /* no bound in between */
    *out_estimate = 0;
    return true;
  }
  qsort(e, ne, sizeof *e, cmp_double);
  /* the counts fall as the bound grows: the first bound that meets the
   * target, by bisection over the curves' errors */
  size_t lo = 0, hi = ne - 1;
  if (sum_at(c, n, e[hi]) > target) {
    lo = hi; /* none meets it: the largest, the fewest vertices */
  } else {
    while (lo < hi) {
      size_t mid = (lo + hi) / 2;
      if (sum_at(c, n, e[mid]) <= target)
        hi = mid;
      else
        lo = mid + 1;
    }
  }
  *out_bound = e[lo];
  *out_estimate = sum_at(c, n, e[lo]);
  free(e);
  return true;
}

/* At most this many passes at a bound. */
#define BUDGET_PASSES 8

tt_status tt__app_budget_passes(app_run *r, const char *path,
                                const app_curve *curves, size_t ntiles,
                                size_t valid, const tt_refine_options *ro,
                                const app_budget_pass *p, double *out_bound,
                                int *out_passes)
{
  size_t max_v = ro->max_points ? ro->max_points : SIZE_MAX;
  if (ro->percent > 0) {
    size_t pc = (size_t)floor(ro->percent / 100.0 * (double)valid);
    max_v = pc < max_v ? (pc ? pc : 1) : max_v;
  }
  size_t max_t = ro->max_triangles ? ro->max_triangles : SIZE_MAX;
  size_t target = max_v < max_t / 2 ? max_v : max_t / 2;
  const double floor_e = ro->max_error; /* < 0: none */
  /* A first bound from the curves; while the TIN passes the budget, a
   * larger one aimed lower by the excess; once it fits but keeps less
   * than 98 % of the budget, one smaller bound aimed higher by the
   * shortfall, and if that passes the budget, the fitting bound again
   * (the same TIN: runs are deterministic). */
  double above = -1, below = INFINITY, e = 0, good = NAN;
  bool calibrated = false;
  size_t nv = 0, nt = 0;
  int overs = 0;      /* passes over the budget in a row */
  bool stuck = false; /* the last of them made no fewer than the one before */
  size_t over_nv = 0, over_nt = 0; /* the counts of the one before */
  for (int pass = 1;; pass++) {
    size_t estimate;
    double next;
    if (!tt__app_curves_bound(curves, ntiles, target, above, below, &next,
                              &estimate))
      return tt__app_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_NOMEM, NULL,
                          "out of memory for the curves");
    if (isnan(next) && !isnan(good))
      next = good; /* nothing between: back to the fitting bound */
    else if (isnan(next) && above > 0 && !stuck)
      /* over the budget, and the curves see no larger bound that makes
       * fewer vertices: their borders are only the corners, while a
       * pass's are simplified to the bound and thin out as it grows, so
       * try larger bounds, 2 %, 4 %, 8 % ... above, while they make
       * fewer */
      next = above * (1.0 + 0.01 * (double)(1u << (overs < 16 ? overs : 16)));
    if (!isnan(next) && pass > BUDGET_PASSES)
      return tt__app_fail(r, TT_APP_EXIT_USAGE, TT_ERR_LIMIT, path,
                          "no bound found in %d passes over the tiles that "
                          "keeps the TIN within the budget of %zu %s (the "
                          "last pass, at the bound %g, made %zu vertices and "
                          "%zu triangles); ask for a little more, or use "
                          "a larger -tile_size",
                          BUDGET_PASSES, nv > max_v ? max_v : max_t,
                          nv > max_v ? "vertices" : "triangles", e, nv, nt);
    if (isnan(next))
      return tt__app_fail(r, TT_APP_EXIT_USAGE, TT_ERR_LIMIT, path,
                          "the budget of %zu %s is below what %zu tiles make "
                          "at the bound %g (%zu vertices, %zu triangles: "
                          "their corners and borders); ask for more, or use "
                          "a larger -tile_size", nv > max_v ? max_v : max_t,
                          nv > max_v ? "vertices" : "triangles", ntiles, e,
                          nv, nt);
    e = next;
    if (floor_e >= 0 && e < floor_e)
      e = floor_e;
    tt_status st = p->run(p->arg, e, max_v, max_t, &nv, &nt);
    if (st != TT_OK)
      return st;
    *out_passes = pass;
    bool fits = nv <= max_v && nt <= max_t;
    double f = fmin(max_v < SIZE_MAX ? (double)max_v / (double)nv : INFINITY,
                    max_t < SIZE_MAX ? (double)max_t / (double)nt : INFINITY);
    if (fits && (calibrated || f <= 1 / 0.98 || e == good ||
                 (floor_e >= 0 && e == floor_e)))
      break;
    p->drop(p->arg);
    size_t aim = (size_t)floor((double)target * f * (fits ? 0.995 : 1.0));
    if (fits) {
      /* short of the budget: once, a smaller bound */
      calibrated = true;
      good = e;
      below = e;
      above = -1;
      target = aim > target ? aim : target + 1;
      overs = 0;
    } else {
      /* over: a larger bound (below the fitting one, if any), aimed lower
       * by the excess, and by twice as much more each time a pass is over
       * again: the curves' counts (borders simplified to no bound) can
       * stay a few vertices below a real pass's, whatever the bound */
      above = e;
      stuck = overs > 0 && nv >= over_nv && nt >= over_nt;
      over_nv = nv;
      over_nt = nt;
      size_t excess = nv > max_v ? nv - max_v : (nt - max_t + 1) / 2;
      size_t step = (excess ? excess : 1) << (overs < 16 ? overs : 16);
      overs++;
      size_t lower = target > step ? target - step : 1;
      target = aim < lower ? aim : lower;
    }
  }
  *out_bound = e;
  return TT_OK;
}
