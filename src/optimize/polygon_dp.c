/*
 * polygon_dp.c -- O(n^3) dynamic programming over a simple polygon (see
 * polygon_dp.h for the rules and the recurrence). Workload: holes of a few
 * to a few dozen vertices (the star of a vertex), so the n^2 diagonal
 * tests, each O(n), cost about as much as the recurrence itself.
 *
 * Part of src/optimize/, the optimisers: swaps under a criterion, look-ahead,
 * annealing, edge insertion, the dynamic programs.
 */
#include "optimize/polygon_dp.h"

#include "base/predicates.h"

#include <math.h>
#include <stdlib.h>

typedef struct poly {
  int n;
  const int64_t *x, *y;
  int s;
} poly;

static int orient(const poly *p, int a, int b, int c)
{
  return p->s * tt__orient_i(p->x[a], p->y[a], p->x[b], p->y[b], p->x[c],
                             p->y[c]);
}

/* c on the closed segment a-b, given a, b, c collinear */
static bool between(const poly *p, int a, int b, int c)
{
  int64_t lo, hi;
  if (p->x[a] != p->x[b]) {
    lo = p->x[a] < p->x[b] ? p->x[a] : p->x[b];
    hi = p->x[a] < p->x[b] ? p->x[b] : p->x[a];
    return p->x[c] >= lo && p->x[c] <= hi;
  }
  lo = p->y[a] < p->y[b] ? p->y[a] : p->y[b];
  hi = p->y[a] < p->y[b] ? p->y[b] : p->y[a];
  return p->y[c] >= lo && p->y[c] <= hi;
}

/* Whether the closed segments a-b and c-d meet. */
static bool meet(const poly *p, int a, int b, int c, int d)
{
  int o1 = orient(p, a, b, c), o2 = orient(p, a, b, d);
  int o3 = orient(p, c, d, a), o4 = orient(p, c, d, b);
  if (o1 * o2 < 0 && o3 * o4 < 0)
    return true;
  return (o1 == 0 && between(p, a, b, c)) || (o2 == 0 && between(p, a, b, d)) ||
         (o3 == 0 && between(p, c, d, a)) || (o4 == 0 && between(p, c, d, b));
}

/* Whether b leaves vertex a into the polygon's interior, strictly. */
static bool in_cone(const poly *p, int a, int b)
{
  int a0 = (a + p->n - 1) % p->n, a1 = (a + 1) % p->n;
  if (orient(p, a0, a, a1) > 0) /* convex corner */
    return orient(p, a, b, a0) > 0 && orient(p, b, a, a1) > 0;
  /* reflex (or flat) corner: b is not in the outer cone */
  return !(orient(p, a, b, a1) >= 0 && orient(p, b, a, a0) >= 0);
}

static bool diagonal_ok(const poly *p, int i, int j)
{
  int n = p->n;
  if (i == j || (i + 1) % n == j || (j + 1) % n == i)
    return false;
  if (!in_cone(p, i, j) || !in_cone(p, j, i))
    return false;
  for (int k = 0; k < n; k++) {
    int k1 = (k + 1) % n;
    if (k == i || k == j || k1 == i || k1 == j)
      continue;
    if (meet(p, i, j, k, k1))
      return false;
  }
  return true;
}

bool tt__polygon_diagonal_ok(int n, const int64_t *x, const int64_t *y,
                             int orient_sign, int i, int j)
{
  poly p = {n, x, y, orient_sign};
  return diagonal_ok(&p, i, j);
}

bool tt__polygon_dp(int n, const int64_t *x, const int64_t *y, int orient_sign,
                    tt__dp_combine combine, tt__dp_measure measure, void *arg,
                    int32_t *out_tris, double *out_value)
{
  if (n < 3 || n > TT__DP_MAX_N)
    return false;
  poly p = {n, x, y, orient_sign};
  size_t nn = (size_t)n * (size_t)n;
  double *q = malloc(nn * sizeof *q);
  int32_t *best = malloc(nn * sizeof *best);
  uint8_t *ok = malloc(nn);
  int32_t *stack = malloc(2 * (size_t)n * sizeof *stack);
  bool done = false;
  if (!q || !best || !ok || !stack)
    goto out;
  /* ok[i][j], i < j: a side, or a diagonal inside the polygon */
  for (int i = 0; i < n; i++)
    for (int j = i + 1; j < n; j++)
      ok[(size_t)i * n + j] =
          (j == i + 1 || (i == 0 && j == n - 1)) ? 1 : diagonal_ok(&p, i, j);
  const double none = INFINITY;
  const double empty = combine == TT__DP_SUM ? 0.0 : -INFINITY;
  for (int i = 0; i + 1 < n; i++)
    q[(size_t)i * n + i + 1] = empty;
  for (int len = 2; len < n; len++)
    for (int i = 0; i + len < n; i++) {
      int j = i + len;
      double b = none;
      int32_t bk = -1;
      if (ok[(size_t)i * n + j])
        for (int k = i + 1; k < j; k++) {
          double qa = q[(size_t)i * n + k], qb = q[(size_t)k * n + j];
          if (qa == none || qb == none || !ok[(size_t)i * n + k] ||
              !ok[(size_t)k * n + j] || orient(&p, i, k, j) <= 0)
            continue;
          double t = measure(arg, i, k, j);
          double v = combine == TT__DP_SUM ? qa + qb + t
                                           : fmax(fmax(qa, qb), t);
          if (v < b) {
            b = v;
            bk = k;
          }
        }
      q[(size_t)i * n + j] = b;
      best[(size_t)i * n + j] = bk;
    }
  if (q[n - 1] == none)
    goto out;
  if (out_value)
    *out_value = q[n - 1];
  if (out_tris) {
    int sp = 0, nt = 0;
    stack[sp++] = 0;
    stack[sp++] = n - 1;
    while (sp > 0) {
      int j = stack[--sp], i = stack[--sp];
      if (j - i < 2)
        continue;
      int k = best[(size_t)i * n + j];
      out_tris[3 * nt] = i;
      out_tris[3 * nt + 1] = k;
      out_tris[3 * nt + 2] = j;
      nt++;
      stack[sp++] = i;
      stack[sp++] = k;
      stack[sp++] = k;
      stack[sp++] = j;
    }
  }
  done = true;
out:
  free(q);
  free(best);
  free(ok);
  free(stack);
  return done;
}
