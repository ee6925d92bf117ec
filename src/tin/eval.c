/*
 * eval.c -- measures any triangle soup against a grid (tt_eval_triangles):
 * ours, another tool's, overlapping, with holes, in either winding. Each
 * triangle is rasterised by rows over its bounding box clipped to the grid;
 * every valid sample within EVAL_TOL pixel of it is compared with the
 * triangle's plane at that sample, and the error measures of SPEC section 6
 * are summed.
 *
 * Invariants. A sample is measured once, by the first triangle (in input
 * order) that covers it; the max, mean and RMS errors are over the covered
 * samples (errors.covered), while errors.samples counts every valid sample
 * and uncovered the difference. A per-sample 2-bit state (two bitmaps of one
 * bit per sample) records: uncovered / covered by boundary hits only /
 * covered once, strictly inside / counted as overlapped. A sample is
 * *overlapped* when two or more triangles cover it and it lies strictly
 * inside (farther than EVAL_TOL from the boundary) at least one of them: so
 * the samples on the shared edges and vertices of a proper TIN are not
 * overlaps, while a sample inside a triangle that another triangle also
 * covers is, counted once however many triangles cover it. Triangles whose
 * area is zero within rounding (the orientation determinant is below its
 * floating-point error bound) are counted as degenerate and skipped.
 *
 * Rasterisation. For each row, the column span is cut from the three edges'
 * half-planes pushed outward by the tolerance (plus a rounding slack), and
 * only the span ends are then tested exactly: a sample counts when its
 * distance to the triangle is <= EVAL_TOL (inside, or within EVAL_TOL of an
 * edge segment). The ends move inward past samples that fail and outward
 * past neighbours that pass; by convexity every sample between the two ends
 * is covered. Heights are read at the grid's own precision (floats, or
 * doubles: tt_precision), and every error is computed in doubles.
 * tt_eval_triangles_raster also writes the TIN's height at every sample a
 * triangle covers (the first triangle's, as the error is measured), which
 * `terratin rasterize` and `eval -error_raster` write as rasters. Workload:
 * O(triangles + rows of the clipped bounding boxes + covered samples)
 * time; memory 2 bits per sample.
 *
 * Part of src/tin/, the finished TIN: its records and error statistics, eval,
 * synthetic terrains.
 */
#include "base/internal.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* A sample within this distance (pixels) of a triangle is in it. */
#define EVAL_TOL 1e-9
/* Coordinates beyond this (pixels) are refused: the squared distances
 * and determinants of the tests must stay far from overflow. */
#define EVAL_MAX_COORD 1e15
/* Relative error bound of the 2x2 orientation determinant (Shewchuk's
 * ccwerrboundA, (3 + 16 eps) eps). */
#define EVAL_ORIENT_ERRBOUND 3.3306690738754716e-16

typedef struct eval_tri {
  double x[3], y[3], z[3];   /* counter-clockwise (a2 > 0) */
  double ex[3], ey[3];       /* edge i runs from corner i to corner i+1 */
  double len[3];             /* edge lengths */
  double a2;                 /* twice the area */
} eval_tri;

/* f_i(p): twice the signed area of (corner i, corner i+1, p); >= 0 on the
 * triangle's side of edge i, and the barycentric weight of the corner
 * opposite edge i, times a2. */
static double eval_edge(const eval_tri *t, int i, double px, double py)
{
  return t->ex[i] * (py - t->y[i]) - t->ey[i] * (px - t->x[i]);
}

/* Is (px, py) within EVAL_TOL of the triangle (inside or near its
 * boundary)? */
static bool eval_near(const eval_tri *t, double px, double py)
{
  double f[3];
  bool inside = true;
  for (int i = 0; i < 3; i++) {
    f[i] = eval_edge(t, i, px, py);
    /* Farther than the tolerance outside an edge's line: out. */
    if (f[i] < -EVAL_TOL * t->len[i])
      return false;
    if (f[i] < 0)
      inside = false;
  }
  if (inside)
    return true;
  /* Outside but close to some edge line: the distance to the triangle is
   * the distance to the nearest of its three edge segments. */
  for (int i = 0; i < 3; i++) {
    double dx = px - t->x[i], dy = py - t->y[i];
    double s = (dx * t->ex[i] + dy * t->ey[i]) /
               (t->len[i] * t->len[i]);
    if (s < 0)
      s = 0;
    else if (s > 1)
      s = 1;
    double qx = dx - s * t->ex[i], qy = dy - s * t->ey[i];
    if (qx * qx + qy * qy <= EVAL_TOL * EVAL_TOL)
      return true;
  }
  return false;
}

/* Sets up t from 9 doubles; returns false for a zero-area triangle. */
static bool eval_tri_init(eval_tri *t, const double *p)
{
  for (int i = 0; i < 3; i++) {
    t->x[i] = p[3 * i];
    t->y[i] = p[3 * i + 1];
    t->z[i] = p[3 * i + 2];
  }
  double l = (t->x[1] - t->x[0]) * (t->y[2] - t->y[0]);
  double r = (t->y[1] - t->y[0]) * (t->x[2] - t->x[0]);
  double a2 = l - r;
  if (!(fabs(a2) > EVAL_ORIENT_ERRBOUND * (fabs(l) + fabs(r))))
    return false;
  if (a2 < 0) {
    /* Make it counter-clockwise: swap corners 1 and 2. */
    double tx = t->x[1], ty = t->y[1], tz = t->z[1];
    t->x[1] = t->x[2];
    t->y[1] = t->y[2];
    t->z[1] = t->z[2];
    t->x[2] = tx;
    t->y[2] = ty;
    t->z[2] = tz;
    a2 = -a2;
  }
  t->a2 = a2;
  for (int i = 0; i < 3; i++) {
    int j = (i + 1) % 3;
    t->ex[i] = t->x[j] - t->x[i];
    t->ey[i] = t->y[j] - t->y[i];
    t->len[i] = hypot(t->ex[i], t->ey[i]);
  }
  return true;
}

/* The running sums of one evaluation. */
typedef struct eval_acc {
  const tt_grid *g;
  size_t nx;
  uint64_t *cov, *mark;   /* the 2-bit sample states, see the header */
  double *zout;           /* the TIN's heights (tt_eval_triangles_raster) */
  size_t covered, overlapped;
  double sum_abs, sum_sq, max_abs;
  int64_t max_col, max_row;
} eval_acc;

/* One sample (c, r) inside or on triangle t. */
static void eval_visit(eval_acc *acc, const eval_tri *t, size_t c, size_t r)
{
  const size_t idx = r * acc->nx + c;
  /* The TIN on the grid: the first triangle over the sample gives its
   * height (at nodata samples too), with the formula of hp below, so the
   * error raster holds exactly the differences measured here. */
  if (acc->zout && isnan(acc->zout[idx])) {
    const double px = (double)c, py = (double)r;
    acc->zout[idx] = (eval_edge(t, 1, px, py) * t->z[0] +
                      eval_edge(t, 2, px, py) * t->z[1] +
                      eval_edge(t, 0, px, py) * t->z[2]) / t->a2;
  }
  const double h = tt__grid_z(acc->g, idx);
  if (isnan(h))
    return;
  const size_t w = idx >> 6;
  const uint64_t bit = (uint64_t)1 << (idx & 63);
  const bool cov = (acc->cov[w] & bit) != 0;
  const bool mark = (acc->mark[w] & bit) != 0;
  if (!cov && mark)
    return; /* already counted as overlapped */

  const double px = (double)c, py = (double)r;
  const double f0 = eval_edge(t, 0, px, py), f1 = eval_edge(t, 1, px, py),
               f2 = eval_edge(t, 2, px, py);
  const bool interior = f0 > EVAL_TOL * t->len[0] &&
                        f1 > EVAL_TOL * t->len[1] &&
                        f2 > EVAL_TOL * t->len[2];
  if (cov) {
    /* Covered before: an overlap when this hit or the earlier one (then the
     * only one) is interior. */
    if (mark || interior) {
      acc->cov[w] &= ~bit;
      acc->mark[w] |= bit;
      acc->overlapped++;
    }
    return;
  }

  /* First cover: measure. */
  acc->cov[w] |= bit;
  if (interior)
    acc->mark[w] |= bit;
  acc->covered++;
  const double hp = (f1 * t->z[0] + f2 * t->z[1] + f0 * t->z[2]) / t->a2;
  const double d = h - hp;
  const double ad = fabs(d);
  acc->sum_abs += ad;
  acc->sum_sq += d * d;
  if (ad > acc->max_abs || acc->max_col < 0) {
    acc->max_abs = ad;
    acc->max_col = (int64_t)c;
    acc->max_row = (int64_t)r;
  }
}

/* Rasterises one (non-degenerate) triangle over an nx x ny grid. */
static void eval_raster(eval_acc *acc, const eval_tri *t, size_t nx,
                        size_t ny)
{
  double xmin = t->x[0], xmax = t->x[0], ymin = t->y[0], ymax = t->y[0];
  double mag = (double)(nx > ny ? nx : ny);
  for (int i = 0; i < 3; i++) {
    xmin = fmin(xmin, t->x[i]);
    xmax = fmax(xmax, t->x[i]);
    ymin = fmin(ymin, t->y[i]);
    ymax = fmax(ymax, t->y[i]);
    mag = fmax(mag, fmax(fabs(t->x[i]), fabs(t->y[i])));
  }
  /* The candidate spans use a wider tolerance, so that rounding in their
   * computation never cuts a covered sample off; the exact test at the span
   * ends decides. */
  const double tolc = EVAL_TOL + 1e-9 + 64 * DBL_EPSILON * mag;
  const double last_col = (double)(nx - 1), last_row = (double)(ny - 1);

  double rlo = ceil(ymin - tolc), rhi = floor(ymax + tolc);
  if (rlo < 0)
    rlo = 0;
  if (rhi > last_row)
    rhi = last_row;
  if (!(rlo <= rhi))
    return;
  const size_t r0 = (size_t)rlo, r1 = (size_t)rhi;

  for (size_t r = r0; r <= r1; r++) {
    const double py = (double)r;
    double xa = xmin - tolc, xb = xmax + tolc;
    bool empty = false;
    for (int i = 0; i < 3; i++) {
      /* f_i >= -tolc len_i  <=>  ey (px - x_i) <= ex (py - y_i) + tolc len */
      const double n = t->ex[i] * (py - t->y[i]) + tolc * t->len[i];
      const double ey = t->ey[i];
      if (ey > 0) {
        double q = t->x[i] + n / ey;
        if (q < xb)
          xb = q;
      } else if (ey < 0) {
        double q = t->x[i] + n / ey;
        if (q > xa)
          xa = q;
      } else if (n < 0) {
        empty = true;
      }
    }
    if (empty)
      continue;
    if (xa < 0)
      xa = 0;
    if (xb > last_col)
      xb = last_col;
    if (!(xa <= xb))
      continue;
    size_t cl = (size_t)ceil(xa), cr = (size_t)floor(xb);
    if (cl > cr)
      continue;
    /* The span ends, exactly: inward past the samples that fail ... */
    while (cl <= cr && !eval_near(t, (double)cl, py))
      cl++;
    if (cl > cr)
      continue;
    while (cr > cl && !eval_near(t, (double)cr, py))
      cr--;
    /* ... and outward past neighbours that pass (the candidate is only an
     * estimate). */
    while (cl > 0 && eval_near(t, (double)(cl - 1), py))
      cl--;
    while (cr < nx - 1 && eval_near(t, (double)(cr + 1), py))
      cr++;
    for (size_t c = cl; c <= cr; c++)
      eval_visit(acc, t, c, r);
  }
}

tt_status tt_eval_triangles(tt_context *ctx, const tt_grid *grid,
                            size_t ntriangles, const double *pix_xyz,
                            tt_eval_result *out_result)
{
  return tt_eval_triangles_raster(ctx, grid, ntriangles, pix_xyz,
                                  out_result, NULL);
}

tt_status tt_eval_triangles_raster(tt_context *ctx, const tt_grid *grid,
                                   size_t ntriangles, const double *pix_xyz,
                                   tt_eval_result *out_result,
                                   double *out_heights)
{
  tt_status status = TT_OK;
  eval_acc acc;
  memset(&acc, 0, sizeof acc);

  if (!grid || !out_result)
    return tt__error(ctx, TT_ERR_ARG, "grid and out_result must not be "
                     "NULL");
  if (ntriangles > 0 && !pix_xyz)
    return tt__error(ctx, TT_ERR_ARG, "%zu triangles given but no "
                     "coordinates", ntriangles);
  if (ntriangles > SIZE_MAX / 9)
    return tt__error(ctx, TT_ERR_LIMIT, "%zu triangles are too many for "
                     "this machine's address space", ntriangles);
  for (size_t k = 0; k < 9 * ntriangles; k++) {
    double v = pix_xyz[k];
    if (!isfinite(v))
      return tt__error(ctx, TT_ERR_DATA, "triangle %zu, corner %zu: %s is "
                       "not finite", k / 9, k % 9 / 3,
                       k % 3 == 0 ? "column" : k % 3 == 1 ? "row" : "z");
    if (k % 3 != 2 && fabs(v) > EVAL_MAX_COORD)
      return tt__error(ctx, TT_ERR_LIMIT, "triangle %zu, corner %zu: %s "
                       "%g is farther than %g pixels from the grid", k / 9,
                       k % 9 / 3, k % 3 == 0 ? "column" : "row", v,
                       EVAL_MAX_COORD);
  }
  size_t valid = 0;
  status = tt_grid_check(ctx, grid, &valid);
  if (status != TT_OK)
    goto done;

  const size_t nx = grid->nx, ny = grid->ny;
  const size_t words = nx * ny / 64 + 1;
  acc.g = grid;
  acc.nx = nx;
  acc.cov = calloc(words, sizeof(uint64_t));
  acc.mark = calloc(words, sizeof(uint64_t));
  if (!acc.cov || !acc.mark) {
    status = tt__error(ctx, TT_ERR_NOMEM, "out of memory for the coverage "
                       "bitmaps of a %zu x %zu grid", nx, ny);
    goto done;
  }
  acc.max_col = acc.max_row = -1;
  if (out_heights) {
    for (size_t i = 0; i < nx * ny; i++)
      out_heights[i] = NAN;
    acc.zout = out_heights;
  }

  size_t degenerate = 0;
  for (size_t k = 0; k < ntriangles; k++) {
    eval_tri t;
    if (!eval_tri_init(&t, pix_xyz + 9 * k)) {
      degenerate++;
      continue;
    }
    eval_raster(&acc, &t, nx, ny);
  }

  tt_eval_result res;
  memset(&res, 0, sizeof res);
  res.triangles = ntriangles;
  res.degenerate = degenerate;
  res.overlapped = acc.overlapped;
  res.uncovered = valid - acc.covered;
  res.errors.samples = valid;
  res.errors.covered = acc.covered;
  res.errors.total_abs = acc.sum_abs;
  res.errors.l2 = sqrt(acc.sum_sq);
  res.errors.max_col = acc.max_col;
  res.errors.max_row = acc.max_row;
  if (acc.covered > 0) {
    /* Averages over the covered samples (none covered: all zero). */
    res.errors.max_error = acc.max_abs;
    res.errors.mean_abs = acc.sum_abs / (double)acc.covered;
    res.errors.rmse = sqrt(acc.sum_sq / (double)acc.covered);
  }
  *out_result = res;

done:
  free(acc.cov);
  free(acc.mark);
  return status;
}
