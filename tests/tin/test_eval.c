/*
 * test_eval.c -- tt_eval_triangles (src/tin/eval.c): planes reproduced exactly,
 * hand-computed errors, coverage, overlap and degenerate counts, the 1e-9
 * pixel tolerance, nodata, refusals, and random soups on random grids
 * against a brute-force oracle that tests every sample against every
 * triangle. Set TT_TEST_SEED to replay a random case; the seed is printed.
 * Grids of doubles are read at their own precision: a plane of heights
 * 2^30 + c + 2 r and 10^6 + (c + 2 r) / 1000 is reproduced exactly, and a
 * spike of one unit on it is measured as one.
 */
#include "tt_test.h"

#include "terratin/terratin.h"

#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

/* Appends triangle (c0,r0,z0, c1,r1,z1, c2,r2,z2) to a soup. */
typedef struct soup {
  double *v;
  size_t n, cap;
} soup;

static void soup_add(soup *s, double c0, double r0, double z0, double c1,
                     double r1, double z1, double c2, double r2, double z2)
{
  if (s->n == s->cap) {
    s->cap = s->cap ? 2 * s->cap : 16;
    double *nv = realloc(s->v, s->cap * 9 * sizeof(double));
    if (!nv) {
      fprintf(stderr, "out of memory\n");
      exit(1);
    }
    s->v = nv;
  }
  double *p = s->v + 9 * s->n++;
  p[0] = c0, p[1] = r0, p[2] = z0;
  p[3] = c1, p[4] = r1, p[5] = z1;
  p[6] = c2, p[7] = r2, p[8] = z2;
}

static tt_grid *grid_of(tt_context *ctx, size_t nx, size_t ny,
                        double (*f)(double c, double r))
{
  tt_grid *g = NULL;
  CHECK_OK(ctx, tt_grid_create(ctx, nx, ny, &g));
  if (!g)
    exit(1);
  float *z = tt_grid_heights(g);
  for (size_t r = 0; r < ny; r++)
    for (size_t c = 0; c < nx; c++)
      z[r * nx + c] = (float)f((double)c, (double)r);
  return g;
}

static double plane(double c, double r) { return 3 + 2 * c - r; }
static double zero(double c, double r) { (void)c, (void)r; return 0; }
static double pyramid(double c, double r)
{
  return 10 - fmax(fabs(c - 5), fabs(r - 5));
}

/* The whole grid as two triangles, corner heights from f. */
static void two_triangles(soup *s, size_t nx, size_t ny, int flip,
                          double (*f)(double c, double r))
{
  double X = (double)(nx - 1), Y = (double)(ny - 1);
  if (!flip) {
    soup_add(s, 0, 0, f(0, 0), X, 0, f(X, 0), X, Y, f(X, Y));
    soup_add(s, 0, 0, f(0, 0), X, Y, f(X, Y), 0, Y, f(0, Y));
  } else {
    soup_add(s, 0, 0, f(0, 0), X, Y, f(X, Y), X, 0, f(X, 0));
    soup_add(s, 0, Y, f(0, Y), X, Y, f(X, Y), 0, 0, f(0, 0));
  }
}

static void test_plane(tt_context *ctx)
{
  for (int flip = 0; flip < 2; flip++) {
    tt_grid *g = grid_of(ctx, 50, 40, plane);
    soup s = {0};
    two_triangles(&s, 50, 40, flip, plane);
    tt_eval_result res;
    CHECK_OK(ctx, tt_eval_triangles(ctx, g, s.n, s.v, &res));
    CHECK_INT_EQ(res.triangles, 2);
    CHECK_INT_EQ(res.degenerate, 0);
    CHECK_INT_EQ(res.errors.samples, 2000);
    CHECK_INT_EQ(res.errors.covered, 2000);
    CHECK_INT_EQ(res.uncovered, 0);
    CHECK_INT_EQ(res.overlapped, 0);
    CHECK_DBL_LE(res.errors.max_error, 1e-9);
    CHECK_DBL_LE(res.errors.total_abs, 1e-6);
    CHECK_DBL_LE(res.errors.rmse, 1e-9);
    tt_grid_destroy(g);
    free(s.v);
  }

  /* A pyramid is piecewise linear over the 4 triangles around its top. */
  tt_grid *g = grid_of(ctx, 11, 11, pyramid);
  soup s = {0};
  const double cs[5][2] = {{0, 0}, {10, 0}, {10, 10}, {0, 10}, {0, 0}};
  for (int i = 0; i < 4; i++)
    soup_add(&s, 5, 5, 10, cs[i][0], cs[i][1], 5, cs[i + 1][0],
             cs[i + 1][1], 5);
  tt_eval_result res;
  CHECK_OK(ctx, tt_eval_triangles(ctx, g, s.n, s.v, &res));
  CHECK_INT_EQ(res.errors.covered, 121);
  CHECK_INT_EQ(res.overlapped, 0);
  CHECK_DBL_LE(res.errors.max_error, 1e-12);
  tt_grid_destroy(g);
  free(s.v);
}

/* A spike of 10 on a flat 11x11 grid, measured by a flat TIN: every error
 * measure by hand. */
static void test_spike(tt_context *ctx)
{
  tt_grid *g = grid_of(ctx, 11, 11, zero);
  tt_grid_heights(g)[3 * 11 + 7] = 10;
  soup s = {0};
  two_triangles(&s, 11, 11, 0, zero);
  tt_eval_result res;
  CHECK_OK(ctx, tt_eval_triangles(ctx, g, s.n, s.v, &res));
  CHECK_DBL_NEAR(res.errors.max_error, 10, 1e-12);
  CHECK_INT_EQ(res.errors.max_col, 7);
  CHECK_INT_EQ(res.errors.max_row, 3);
  CHECK_DBL_NEAR(res.errors.total_abs, 10, 1e-12);
  CHECK_DBL_NEAR(res.errors.mean_abs, 10.0 / 121, 1e-12);
  CHECK_DBL_NEAR(res.errors.l2, 10, 1e-12);
  CHECK_DBL_NEAR(res.errors.rmse, 10.0 / 11, 1e-12);
  tt_grid_destroy(g);
  free(s.v);
}

static double bump(double c, double r)
{
  double x = c / 19 - 0.5, y = r / 29 - 0.5;
  return exp(-81.0 / 4.0 * (x * x + y * y));
}

/* The study's bump (20x30 samples on [0,1]^2) against the two triangles
 * through its corners: the corners are all exp(-81/8), so the TIN is flat
 * and the largest error is at the samples nearest the centre. */
static void test_bump(tt_context *ctx)
{
  tt_grid *g = grid_of(ctx, 20, 30, bump);
  soup s = {0};
  two_triangles(&s, 20, 30, 0, bump);
  tt_eval_result res;
  CHECK_OK(ctx, tt_eval_triangles(ctx, g, s.n, s.v, &res));
  double dx = 0.5 / 19, dy = 0.5 / 29;
  double want = exp(-81.0 / 4.0 * (dx * dx + dy * dy)) - exp(-81.0 / 8.0);
  CHECK_DBL_NEAR(res.errors.max_error, want, 1e-6);
  CHECK(res.errors.max_col == 9 || res.errors.max_col == 10);
  CHECK(res.errors.max_row == 14 || res.errors.max_row == 15);
  CHECK_INT_EQ(res.errors.covered, 600);
  tt_grid_destroy(g);
  free(s.v);
}

static void test_coverage(tt_context *ctx)
{
  tt_grid *g = grid_of(ctx, 10, 10, zero);
  tt_eval_result res;
  soup s = {0};

  /* Half the grid (c + r <= 9, the diagonal included): 55 samples. */
  soup_add(&s, 0, 0, 0, 9, 0, 0, 0, 9, 0);
  CHECK_OK(ctx, tt_eval_triangles(ctx, g, s.n, s.v, &res));
  CHECK_INT_EQ(res.errors.samples, 100);
  CHECK_INT_EQ(res.errors.covered, 55);
  CHECK_INT_EQ(res.uncovered, 45);
  CHECK_INT_EQ(res.overlapped, 0);

  /* The same triangle again: its 28 interior samples (c, r >= 1,
   * c + r <= 8) are overlapped; the 27 on its edges are not. A third copy
   * changes nothing: each sample is counted once. */
  soup_add(&s, 0, 9, 0, 9, 0, 0, 0, 0, 0);
  CHECK_OK(ctx, tt_eval_triangles(ctx, g, s.n, s.v, &res));
  CHECK_INT_EQ(res.errors.covered, 55);
  CHECK_INT_EQ(res.overlapped, 28);
  soup_add(&s, 9, 0, 0, 0, 0, 0, 0, 9, 0);
  CHECK_OK(ctx, tt_eval_triangles(ctx, g, s.n, s.v, &res));
  CHECK_INT_EQ(res.overlapped, 28);
  CHECK_INT_EQ(res.triangles, 3);

  /* The other half: full cover, the shared diagonal is no overlap. */
  s.n = 0;
  soup_add(&s, 0, 0, 0, 9, 0, 0, 0, 9, 0);
  soup_add(&s, 9, 9, 0, 9, 0, 0, 0, 9, 0);
  CHECK_OK(ctx, tt_eval_triangles(ctx, g, s.n, s.v, &res));
  CHECK_INT_EQ(res.errors.covered, 100);
  CHECK_INT_EQ(res.overlapped, 0);

  /* Two triangles crossing: the second's samples inside the first. Only
   * samples (c, r) with r <= 4: first triangle c + r <= 9; second is the
   * rectangle-half c >= 5, r <= 4, r >= c - 5... brute force below. */
  s.n = 0;
  soup_add(&s, 0, 0, 0, 9, 0, 0, 0, 9, 0);
  soup_add(&s, 2, 2, 0, 9, 2, 0, 9, 9, 0);
  CHECK_OK(ctx, tt_eval_triangles(ctx, g, s.n, s.v, &res));
  /* Second triangle: r >= 2, c <= 9, r <= 2 + (c - 2) * 1 (edge from
   * (2,2) to (9,9) is r = c), so samples 2 <= r <= c <= 9. It shares with
   * the first (c + r <= 9) the samples 2 <= r <= c, c + r <= 9: r = 2:
   * c = 2..7 (6), r = 3: c = 3..6 (4), r = 4: c = 4, 5 (2): 12. Of those,
   * overlapped = inside one strictly: r = 2 is on the second's edge and
   * inside the first strictly for c = 3..6 (c + r < 9, c >= 1, r >= 1);
   * (2,2) is the second's corner and inside the first: 5 so far; r = 3:
   * (3,3) on edge r = c of the second, inside the first: yes; (4,3),
   * (5,3) inside both; (6,3) on the first's hypotenuse, strictly inside
   * the second: yes: 4; r = 4: (4,4) inside first, (5,4) on first's
   * hypotenuse, inside second: 2. (7,2): on both edges: no. Total 11. */
  CHECK_INT_EQ(res.overlapped, 11);
  size_t second = 0;
  for (int r = 2; r <= 9; r++)
    second += (size_t)(10 - r);
  CHECK_INT_EQ(res.errors.covered, 55 + second - 12);

  /* A triangle much larger than the grid covers it all; one outside covers
   * nothing; one across the border covers its part. */
  s.n = 0;
  soup_add(&s, -1e6, -1e6, 0, 1e6, -1e6, 0, 0, 1e6, 0);
  CHECK_OK(ctx, tt_eval_triangles(ctx, g, s.n, s.v, &res));
  CHECK_INT_EQ(res.errors.covered, 100);
  s.n = 0;
  soup_add(&s, 20, 20, 0, 30, 20, 0, 20, 30, 0);
  soup_add(&s, -5, -5, 0, -0.5, -5, 0, -5, 100, 0);
  CHECK_OK(ctx, tt_eval_triangles(ctx, g, s.n, s.v, &res));
  CHECK_INT_EQ(res.errors.covered, 0);
  CHECK_INT_EQ(res.uncovered, 100);
  CHECK_INT_EQ(res.errors.max_col, -1);
  CHECK_DBL_NEAR(res.errors.max_error, 0, 0);
  s.n = 0;
  soup_add(&s, -5, -5, 0, 4.5, -5, 0, 4.5, 100, 0); /* columns 0..4 */
  CHECK_OK(ctx, tt_eval_triangles(ctx, g, s.n, s.v, &res));
  CHECK_INT_EQ(res.errors.covered, 50);

  /* No triangles at all. */
  CHECK_OK(ctx, tt_eval_triangles(ctx, g, 0, NULL, &res));
  CHECK_INT_EQ(res.errors.covered, 0);
  CHECK_INT_EQ(res.uncovered, 100);
  CHECK_INT_EQ(res.triangles, 0);

  tt_grid_destroy(g);
  free(s.v);
}

/* The 1e-9 pixel tolerance, also along an almost horizontal edge where
 * the tolerant span reaches past the edge's crossing of the row. */
static void test_tolerance(tt_context *ctx)
{
  tt_grid *g = grid_of(ctx, 5, 5, zero);
  tt_eval_result res;
  soup s = {0};
  /* Bottom edge 5e-10 above row 2: row 2 is in; 2e-9 above: out. */
  soup_add(&s, -0.5, 2 - 5e-10, 0, 10, 2 - 5e-10, 0, -0.5, -10, 0);
  CHECK_OK(ctx, tt_eval_triangles(ctx, g, s.n, s.v, &res));
  CHECK_INT_EQ(res.errors.covered, 15);
  s.n = 0;
  soup_add(&s, -0.5, 2 - 2e-9, 0, 10, 2 - 2e-9, 0, -0.5, -10, 0);
  CHECK_OK(ctx, tt_eval_triangles(ctx, g, s.n, s.v, &res));
  CHECK_INT_EQ(res.errors.covered, 10);
  /* A corner 5e-10 from sample (2, 2) (diagonally): in. */
  s.n = 0;
  double e = 5e-10 / sqrt(2.0);
  soup_add(&s, 2 + e, 2 + e, 0, 4.5, 2.5, 0, 2.5, 4.5, 0);
  CHECK_OK(ctx, tt_eval_triangles(ctx, g, s.n, s.v, &res));
  size_t with_corner = res.errors.covered;
  s.n = 0;
  e = 2e-9 / sqrt(2.0);
  soup_add(&s, 2 + e, 2 + e, 0, 4.5, 2.5, 0, 2.5, 4.5, 0);
  CHECK_OK(ctx, tt_eval_triangles(ctx, g, s.n, s.v, &res));
  CHECK_INT_EQ(with_corner, res.errors.covered + 1);
  tt_grid_destroy(g);

  /* Edge y = 2 - 2.15e-9 + (x + 0.5) 2e-10: within 1e-9 of row 2 from
   * column 6 on, crossing it after column 10. Rows 0 and 1 fully in. */
  g = grid_of(ctx, 20, 5, zero);
  s.n = 0;
  double y0 = 2 - 2.15e-9, slope = 2e-10;
  soup_add(&s, -0.5, y0, 0, 30, y0 + 30.5 * slope, 0, -0.5, -100, 0);
  CHECK_OK(ctx, tt_eval_triangles(ctx, g, s.n, s.v, &res));
  CHECK_INT_EQ(res.errors.covered, 40 + 14);
  tt_grid_destroy(g);
  free(s.v);
}

static void test_degenerate(tt_context *ctx)
{
  tt_grid *g = grid_of(ctx, 10, 10, zero);
  tt_eval_result res;
  soup s = {0};
  soup_add(&s, 0, 0, 0, 5, 5, 0, 9, 9, 0);          /* collinear */
  soup_add(&s, 1, 1, 0, 1, 1, 0, 7, 2, 0);          /* repeated corner */
  soup_add(&s, 3, 3, 0, 3, 3, 0, 3, 3, 0);          /* a point */
  soup_add(&s, 0.1, 0.1, 0, 0.2, 0.2, 0, 0.3, 0.3, 0); /* collinear, inexact */
  soup_add(&s, 0, 0, 0, 9, 0, 0, 0, 9, 0);          /* a real one */
  CHECK_OK(ctx, tt_eval_triangles(ctx, g, s.n, s.v, &res));
  CHECK_INT_EQ(res.triangles, 5);
  CHECK_INT_EQ(res.degenerate, 4);
  CHECK_INT_EQ(res.errors.covered, 55);
  CHECK_INT_EQ(res.overlapped, 0);
  tt_grid_destroy(g);
  free(s.v);
}

static void test_nodata(tt_context *ctx)
{
  tt_grid *g = grid_of(ctx, 10, 10, zero);
  float *z = tt_grid_heights(g);
  z[0] = NAN;          /* a corner, on both triangles */
  z[5 * 10 + 5] = NAN; /* inside the overlap */
  z[9 * 10 + 9] = NAN; /* outside the first triangle */
  z[2 * 10 + 3] = 50;  /* a large error that counts */
  tt_eval_result res;
  soup s = {0};
  soup_add(&s, 0, 0, 0, 9, 0, 0, 0, 9, 0);
  soup_add(&s, 0, 0, 0, 9, 9, 0, 0, 9, 0);
  CHECK_OK(ctx, tt_eval_triangles(ctx, g, s.n, s.v, &res));
  CHECK_INT_EQ(res.errors.samples, 97);
  /* Covered: c + r <= 9 or r >= c: 55 + 45 - 5 (the overlap's diagonal
   * part r >= c, c + r <= 9 ... counted by the oracle loop below). */
  size_t covered = 0, overlapped = 0;
  for (int r = 0; r < 10; r++)
    for (int c = 0; c < 10; c++) {
      if (isnan(z[r * 10 + c]))
        continue;
      int in1 = c + r <= 9, in2 = r >= c;
      int strict1 = c > 0 && r > 0 && c + r < 9;
      int strict2 = c > 0 && r < 9 && r > c;
      covered += in1 || in2;
      overlapped += in1 && in2 && (strict1 || strict2);
    }
  CHECK_INT_EQ(res.errors.covered, covered);
  CHECK_INT_EQ(res.overlapped, overlapped);
  CHECK_INT_EQ(res.uncovered, 97 - covered);
  CHECK_DBL_NEAR(res.errors.max_error, 50, 0);
  CHECK_DBL_NEAR(res.errors.total_abs, 50, 0);
  CHECK_INT_EQ(res.errors.max_col, 3);
  CHECK_INT_EQ(res.errors.max_row, 2);
  tt_grid_destroy(g);
  free(s.v);
}

static void test_refusals(tt_context *ctx)
{
  tt_grid *g = grid_of(ctx, 4, 4, zero);
  tt_eval_result res;
  double tri[9] = {0, 0, 0, 3, 0, 0, 0, 3, 0};
  CHECK_INT_EQ(tt_eval_triangles(ctx, NULL, 1, tri, &res), TT_ERR_ARG);
  CHECK_INT_EQ(tt_eval_triangles(ctx, g, 1, tri, NULL), TT_ERR_ARG);
  CHECK_INT_EQ(tt_eval_triangles(ctx, g, 1, NULL, &res), TT_ERR_ARG);
  tri[4] = NAN;
  CHECK_INT_EQ(tt_eval_triangles(ctx, g, 1, tri, &res), TT_ERR_DATA);
  CHECK(strstr(tt_context_errmsg(ctx), "triangle 0, corner 1: row") != NULL);
  tri[4] = 0;
  tri[8] = INFINITY;
  CHECK_INT_EQ(tt_eval_triangles(ctx, g, 1, tri, &res), TT_ERR_DATA);
  tri[8] = 0;
  tri[6] = 1e20;
  CHECK_INT_EQ(tt_eval_triangles(ctx, g, 1, tri, &res), TT_ERR_LIMIT);
  tri[6] = 0;
  tt_grid_heights(g)[5] = INFINITY;
  CHECK_INT_EQ(tt_eval_triangles(ctx, g, 1, tri, &res), TT_ERR_DATA);
  CHECK_INT_EQ(tt_eval_triangles(NULL, g, 1, tri, &res), TT_ERR_DATA);
  tt_grid_destroy(g);
}

/* ---------------------------------------------------------------------------
 * Random soups against the brute-force oracle.
 * ------------------------------------------------------------------------- */

/* The oracle's view of one triangle at one sample: -1 out, 0 on the
 * boundary, 1 strictly inside; *hp the plane's height. Barycentric
 * numerators computed directly; the test data are multiples of 1/8, so
 * they are exact and a sample off the boundary is far beyond 1e-9. */
static int oracle_in(const double *t, double c, double r, double *hp)
{
  double x0 = t[0], y0 = t[1], x1 = t[3], y1 = t[4], x2 = t[6], y2 = t[7];
  double a = (x1 - x0) * (y2 - y0) - (y1 - y0) * (x2 - x0);
  double l0 = (x1 - c) * (y2 - r) - (y1 - r) * (x2 - c);
  double l1 = (x2 - c) * (y0 - r) - (y2 - r) * (x0 - c);
  double l2 = (x0 - c) * (y1 - r) - (y0 - r) * (x1 - c);
  if (a < 0) {
    a = -a, l0 = -l0, l1 = -l1, l2 = -l2;
  }
  if (l0 < 0 || l1 < 0 || l2 < 0)
    return -1;
  *hp = (l0 * t[2] + l1 * t[5] + l2 * t[8]) / a;
  return l0 > 0 && l1 > 0 && l2 > 0 ? 1 : 0;
}

static int random_case(tt_context *ctx, uint64_t *rng, int verbose)
{
  int before = tt_test_failures;
  size_t nx = 2 + tt_test_rand(rng) % 40, ny = 2 + tt_test_rand(rng) % 40;
  tt_grid *g = NULL;
  CHECK_OK(ctx, tt_grid_create(ctx, nx, ny, &g));
  if (!g)
    return 1;
  float *z = tt_grid_heights(g);
  double nodata = tt_test_uniform(rng) * 0.3;
  for (size_t i = 0; i < nx * ny; i++)
    z[i] = tt_test_uniform(rng) < nodata
               ? NAN
               : (float)(100 * tt_test_uniform(rng) - 50);

  soup s = {0};
  /* A cell triangulation of a random block with random diagonals, cells
   * of a random size: a proper TIN over part of the grid. */
  size_t b = 1 + tt_test_rand(rng) % 3;
  size_t c0 = tt_test_rand(rng) % nx, r0 = tt_test_rand(rng) % ny;
  for (size_t r = r0; r < ny; r += b)
    for (size_t c = c0; c < nx; c += b) {
      double x0 = (double)c, y0 = (double)r, x1 = x0 + (double)b,
             y1 = y0 + (double)b;
      double za = tt_test_uniform(rng) * 100 - 50, zb = za + 1,
             zc = za - 2, zd = za + 3;
      if (tt_test_rand(rng) & 1) {
        soup_add(&s, x0, y0, za, x1, y0, zb, x1, y1, zc);
        soup_add(&s, x0, y0, za, x1, y1, zc, x0, y1, zd);
      } else {
        soup_add(&s, x0, y0, za, x1, y0, zb, x0, y1, zd);
        soup_add(&s, x1, y0, zb, x1, y1, zc, x0, y1, zd);
      }
    }
  /* Random triangles on a 1/8 lattice around the grid, some degenerate. */
  size_t extra = tt_test_rand(rng) % 30;
  for (size_t k = 0; k < extra; k++) {
    double p[9];
    for (int i = 0; i < 3; i++) {
      p[3 * i] = (double)((int64_t)(tt_test_rand(rng) % ((nx + 8) * 8)) -
                          32) / 8.0;
      p[3 * i + 1] = (double)((int64_t)(tt_test_rand(rng) % ((ny + 8) * 8)) -
                              32) / 8.0;
      p[3 * i + 2] = tt_test_uniform(rng) * 100 - 50;
    }
    switch (tt_test_rand(rng) % 8) {
    case 0: /* repeated corner */
      p[3] = p[0], p[4] = p[1];
      break;
    case 1: /* collinear */
      p[6] = 2 * p[3] - p[0], p[7] = 2 * p[4] - p[1];
      break;
    default:
      break;
    }
    soup_add(&s, p[0], p[1], p[2], p[3], p[4], p[5], p[6], p[7], p[8]);
  }
  /* Shuffle, so the proper and the random triangles interleave. */
  for (size_t i = s.n; i > 1; i--) {
    size_t j = tt_test_rand(rng) % i;
    double tmp[9];
    memcpy(tmp, s.v + 9 * (i - 1), sizeof tmp);
    memcpy(s.v + 9 * (i - 1), s.v + 9 * j, sizeof tmp);
    memcpy(s.v + 9 * j, tmp, sizeof tmp);
  }

  tt_eval_result res;
  CHECK_OK(ctx, tt_eval_triangles(ctx, g, s.n, s.v, &res));

  /* The oracle. */
  size_t valid = 0, covered = 0, overlapped = 0, degenerate = 0;
  double sum_abs = 0, sum_sq = 0, max_abs = 0;
  double *err = calloc(nx * ny, sizeof(double));
  for (size_t k = 0; k < s.n; k++) {
    const double *t = s.v + 9 * k;
    double a = (t[3] - t[0]) * (t[7] - t[1]) - (t[4] - t[1]) * (t[6] - t[0]);
    degenerate += a == 0;
  }
  for (size_t r = 0; r < ny; r++)
    for (size_t c = 0; c < nx; c++) {
      double h = z[r * nx + c];
      if (isnan(h))
        continue;
      valid++;
      int hits = 0, strict = 0;
      double first = 0;
      for (size_t k = 0; k < s.n; k++) {
        const double *t = s.v + 9 * k;
        double a = (t[3] - t[0]) * (t[7] - t[1]) -
                   (t[4] - t[1]) * (t[6] - t[0]);
        double hp;
        if (a == 0)
          continue;
        int in = oracle_in(t, (double)c, (double)r, &hp);
        if (in < 0)
          continue;
        if (hits++ == 0)
          first = hp;
        strict |= in > 0;
      }
      if (!hits)
        continue;
      covered++;
      overlapped += hits >= 2 && strict;
      double d = fabs(h - first);
      err[r * nx + c] = d;
      sum_abs += d;
      sum_sq += d * d;
      max_abs = d > max_abs ? d : max_abs;
    }

  CHECK_INT_EQ(res.triangles, s.n);
  CHECK_INT_EQ(res.degenerate, degenerate);
  CHECK_INT_EQ(res.errors.samples, valid);
  CHECK_INT_EQ(res.errors.covered, covered);
  CHECK_INT_EQ(res.uncovered, valid - covered);
  CHECK_INT_EQ(res.overlapped, overlapped);
  CHECK_DBL_NEAR(res.errors.total_abs, sum_abs, 1e-9 * (1 + sum_abs));
  CHECK_DBL_NEAR(res.errors.l2, sqrt(sum_sq), 1e-9 * (1 + sqrt(sum_sq)));
  CHECK_DBL_NEAR(res.errors.max_error, max_abs, 1e-9 * (1 + max_abs));
  if (covered) {
    CHECK_DBL_NEAR(res.errors.mean_abs, sum_abs / (double)covered, 1e-9);
    CHECK_DBL_NEAR(res.errors.rmse, sqrt(sum_sq / (double)covered), 1e-9);
    CHECK(res.errors.max_col >= 0 && res.errors.max_row >= 0);
    if (res.errors.max_col >= 0 && res.errors.max_row >= 0)
      CHECK_DBL_NEAR(err[(size_t)res.errors.max_row * nx +
                         (size_t)res.errors.max_col],
                     max_abs, 1e-9 * (1 + max_abs));
  } else {
    CHECK_INT_EQ(res.errors.max_col, -1);
  }
  if (verbose)
    printf("  %zux%zu, %zu triangles: covered %zu of %zu, overlapped %zu, "
           "degenerate %zu\n", nx, ny, s.n, covered, valid, overlapped,
           degenerate);
  free(err);
  free(s.v);
  tt_grid_destroy(g);
  return tt_test_failures != before;
}

static void test_random(tt_context *ctx)
{
  uint64_t seed = 20261122;
  const char *env = getenv("TT_TEST_SEED");
  if (env)
    seed = strtoull(env, NULL, 0);
  printf("test_eval: random cases from seed %llu (TT_TEST_SEED)\n",
         (unsigned long long)seed);
  uint64_t rng = seed;
  for (int i = 0; i < 300; i++) {
    uint64_t case_seed = tt_test_rand(&rng);
    uint64_t st = case_seed;
    if (random_case(ctx, &st, i < 3)) {
      fprintf(stderr, "random case %d failed (seed %llu, case state "
              "%llu)\n", i, (unsigned long long)seed,
              (unsigned long long)case_seed);
      break;
    }
  }
}

/* A big grid: two triangles over 2049^2 samples, the bitmaps at scale. */
static void test_large(tt_context *ctx)
{
  tt_grid *g = grid_of(ctx, 2049, 2049, plane);
  soup s = {0};
  two_triangles(&s, 2049, 2049, 0, plane);
  tt_eval_result res;
  CHECK_OK(ctx, tt_eval_triangles(ctx, g, s.n, s.v, &res));
  CHECK_INT_EQ(res.errors.covered, (size_t)2049 * 2049);
  CHECK_INT_EQ(res.overlapped, 0);
  CHECK_DBL_LE(res.errors.max_error, 1e-6);
  tt_grid_destroy(g);
  free(s.v);
}

/* Heights no float holds (2^30 + integers, 10^6 + thousandths): a plane
 * through them measures 0 everywhere, one sample raised by one unit
 * measures exactly one unit (floats would give errors of up to 64 and
 * 0.03 everywhere). */
static void test_doubles(tt_context *ctx)
{
  const size_t nx = 41, ny = 33;
  const double base[2] = {1073741824.0, 1e6}, unit[2] = {1, 0.001};
  for (int k = 0; k < 2; k++) {
    tt_grid *g = NULL;
    CHECK_OK(ctx, tt_grid_create_f64(ctx, nx, ny, &g));
    if (!g)
      return;
    CHECK(tt_grid_heights(g) == NULL);
    double *z = tt_grid_heights_f64(g);
    for (size_t r = 0; r < ny; r++)
      for (size_t c = 0; c < nx; c++)
        z[r * nx + c] = base[k] + unit[k] * (double)(c + 2 * r);
    soup s = {0};
    double X = (double)(nx - 1), Y = (double)(ny - 1);
    double z00 = z[0], zx0 = z[nx - 1], zxy = z[nx * ny - 1],
           z0y = z[(ny - 1) * nx];
    soup_add(&s, 0, 0, z00, X, 0, zx0, X, Y, zxy);
    soup_add(&s, 0, 0, z00, X, Y, zxy, 0, Y, z0y);
    tt_eval_result res;
    CHECK_OK(ctx, tt_eval_triangles(ctx, g, s.n, s.v, &res));
    CHECK_INT_EQ(res.errors.covered, nx * ny);
    CHECK_DBL_LE(res.errors.max_error, 64 * DBL_EPSILON * base[k]);
    z[5 * nx + 9] += unit[k];
    CHECK_OK(ctx, tt_eval_triangles(ctx, g, s.n, s.v, &res));
    CHECK_DBL_NEAR(res.errors.max_error, unit[k], 64 * DBL_EPSILON * base[k]);
    CHECK_INT_EQ(res.errors.max_col, 9);
    CHECK_INT_EQ(res.errors.max_row, 5);
    tt_grid_destroy(g);
    free(s.v);
  }
}

int main(void)
{
  tt_context *ctx = tt_context_create();
  CHECK(ctx != NULL);
  if (!ctx)
    return 1;
  TT_RUN(test_plane(ctx));
  TT_RUN(test_spike(ctx));
  TT_RUN(test_bump(ctx));
  TT_RUN(test_coverage(ctx));
  TT_RUN(test_tolerance(ctx));
  TT_RUN(test_degenerate(ctx));
  TT_RUN(test_nodata(ctx));
  TT_RUN(test_refusals(ctx));
  TT_RUN(test_doubles(ctx));
  TT_RUN(test_random(ctx));
  TT_RUN(test_large(ctx));
  tt_context_destroy(ctx);
  TT_TEST_DONE();
}
