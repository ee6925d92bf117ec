/*
 * test_predicates.c -- the exact predicates against an exact oracle.
 *
 * The oracle scales every double of a call by one power of two to an
 * integer (a double is m * 2^e with an integer m, so dividing by the lowest
 * such 2^e over the inputs gives integers) and evaluates the full 3x3 or 4x4
 * determinant by Laplace expansion in arbitrary-precision integers written
 * here, independent of predicates.c. A positive scale does not change the
 * sign.
 *
 * Checked: known signs; exact zeros on grids (collinear rows, columns and
 * diagonals; corners of cells and larger rectangles, in pixel space and under
 * square, rectangular and sheared metrics); configurations a few ulps off
 * collinear and co-circular; sign rules under argument permutations; random
 * seeded inputs of every magnitude from subnormal to 1e300; the metric
 * incircle against tt__incircle on exactly mapped ground points, and against
 * the oracle for random double metrics; integer coordinates near 2^28.
 * Set TT_SEED to replay another seed; a failing property prints its seed.
 */
#include "base/predicates.h"
#include "tt_test.h"

/* ------------------------------------------------------------------------ */
/* Oracle: sign-magnitude integers in base 2^32. */

#define OB_LIMBS 300

typedef struct ob {
  int neg;
  int len;
  uint32_t w[OB_LIMBS];
} ob;

static void ob_norm(ob *r)
{
  while (r->len && !r->w[r->len - 1])
    r->len--;
  if (!r->len)
    r->neg = 0;
}

static void ob_small(ob *r, int64_t v)
{
  uint64_t m = v < 0 ? 0 - (uint64_t)v : (uint64_t)v;
  r->neg = v < 0;
  r->w[0] = (uint32_t)(m & 0xffffffffu);
  r->w[1] = (uint32_t)(m >> 32);
  r->len = 2;
  ob_norm(r);
}

/* r = (integer m) * 2^shift with sign. */
static void ob_shifted(ob *r, uint64_t m, int shift, int neg)
{
  int q = shift / 32, s = shift % 32;
  CHECK(q + 3 <= OB_LIMBS);
  for (int i = 0; i < q + 3; i++)
    r->w[i] = 0;
  /* m < 2^53: three limbs after a shift below 32 */
  r->w[q] = (uint32_t)((m << s) & 0xffffffffu);
  r->w[q + 1] = (uint32_t)((m >> (32 - s)) & 0xffffffffu);
  if (s == 0)
    r->w[q + 1] = (uint32_t)(m >> 32);
  r->w[q + 2] = s == 0 ? 0 : (uint32_t)(m >> (64 - s));
  r->len = q + 3;
  r->neg = neg;
  ob_norm(r);
}

/* The exponent e with x = (integer) * 2^e, as low as x's format allows. */
static int ob_low_exp(double x)
{
  return ilogb(x) - 52;
}

static void ob_from_double(ob *r, double x, int e)
{
  if (x == 0) {
    r->len = 0;
    r->neg = 0;
    return;
  }
  int lx = ob_low_exp(x);
  double mant = scalbn(fabs(x), -lx); /* an integer in [2^52, 2^53) */
  ob_shifted(r, (uint64_t)mant, lx - e, x < 0);
}

static int ob_cmpmag(const ob *a, const ob *b)
{
  if (a->len != b->len)
    return a->len > b->len ? 1 : -1;
  for (int i = a->len; i-- > 0;)
    if (a->w[i] != b->w[i])
      return a->w[i] > b->w[i] ? 1 : -1;
  return 0;
}

/* r = a + b; r distinct from a and b. */
static void ob_add(ob *r, const ob *a, const ob *b)
{
  if (a->neg == b->neg) {
    int n = a->len > b->len ? a->len : b->len;
    uint64_t c = 0;
    for (int i = 0; i < n; i++) {
      c += (uint64_t)(i < a->len ? a->w[i] : 0) + (i < b->len ? b->w[i] : 0);
      r->w[i] = (uint32_t)c;
      c >>= 32;
    }
    r->w[n] = (uint32_t)c;
    r->len = n + 1;
    r->neg = a->neg;
  } else {
    const ob *big = a, *sm = b;
    if (ob_cmpmag(a, b) < 0) {
      big = b;
      sm = a;
    }
    uint64_t br = 0;
    for (int i = 0; i < big->len; i++) {
      uint64_t x = big->w[i];
      uint64_t y = (uint64_t)(i < sm->len ? sm->w[i] : 0) + br;
      br = x < y;
      r->w[i] = (uint32_t)(x - y);
    }
    r->len = big->len;
    r->neg = big->neg;
  }
  ob_norm(r);
}

static void ob_mul(ob *r, const ob *a, const ob *b)
{
  int n = a->len + b->len;
  CHECK(n <= OB_LIMBS);
  for (int i = 0; i < n; i++)
    r->w[i] = 0;
  for (int i = 0; i < a->len; i++) {
    uint64_t c = 0;
    for (int j = 0; j < b->len; j++) {
      c += (uint64_t)a->w[i] * b->w[j] + r->w[i + j];
      r->w[i + j] = (uint32_t)c;
      c >>= 32;
    }
    r->w[i + b->len] = (uint32_t)c;
  }
  r->len = n;
  r->neg = a->neg != b->neg;
  ob_norm(r);
}

static int ob_sign(const ob *a)
{
  return a->len == 0 ? 0 : (a->neg ? -1 : 1);
}

/* Determinant of rows row..n-1 over the columns in colmask, by Laplace
 * expansion along the first of those rows. */
static void ob_det(int n, ob (*mat)[4], int row, unsigned colmask, ob *out)
{
  if (row == n - 1) {
    for (int c = 0; c < n; c++)
      if (colmask & (1u << c))
        *out = mat[row][c];
    return;
  }
  ob acc, sub, t, sum;
  acc.len = 0;
  acc.neg = 0;
  int alt = 0;
  for (int c = 0; c < n; c++) {
    if (!(colmask & (1u << c)))
      continue;
    ob_det(n, mat, row + 1, colmask & ~(1u << c), &sub);
    ob_mul(&t, &mat[row][c], &sub);
    if (alt && t.len)
      t.neg = !t.neg;
    ob_add(&sum, &acc, &t);
    acc = sum;
    alt = !alt;
  }
  *out = acc;
}

static int low_exp_of(int n, const double *v)
{
  int e = 0, any = 0;
  for (int i = 0; i < n; i++)
    if (v[i] != 0 && (!any || ob_low_exp(v[i]) < e)) {
      e = ob_low_exp(v[i]);
      any = 1;
    }
  return e;
}

static int oracle_orient(const double a[2], const double b[2],
                         const double c[2])
{
  const double *p[3] = {a, b, c};
  double v[6] = {a[0], a[1], b[0], b[1], c[0], c[1]};
  int e = low_exp_of(6, v);
  static ob mat[4][4];
  for (int i = 0; i < 3; i++) {
    ob_from_double(&mat[i][0], p[i][0], e);
    ob_from_double(&mat[i][1], p[i][1], e);
    ob_small(&mat[i][2], 1);
  }
  ob det;
  ob_det(3, mat, 0, 7u, &det);
  return ob_sign(&det);
}

static int oracle_incircle(const double a[2], const double b[2],
                           const double c[2], const double d[2])
{
  const double *p[4] = {a, b, c, d};
  double v[8] = {a[0], a[1], b[0], b[1], c[0], c[1], d[0], d[1]};
  int e = low_exp_of(8, v);
  static ob mat[4][4];
  for (int i = 0; i < 4; i++) {
    ob xx, yy;
    ob_from_double(&mat[i][0], p[i][0], e);
    ob_from_double(&mat[i][1], p[i][1], e);
    ob_mul(&xx, &mat[i][0], &mat[i][0]);
    ob_mul(&yy, &mat[i][1], &mat[i][1]);
    ob_add(&mat[i][2], &xx, &yy);
    ob_small(&mat[i][3], 1);
  }
  ob det;
  ob_det(4, mat, 0, 15u, &det);
  return ob_sign(&det);
}

/* det_sign * sign det[[x, y, m11 x^2 + 2 m12 x y + m22 y^2, 1], ...] with
 * the metric scaled to integers. */
static int oracle_metric(const tt__metric *m, int64_t p[4][2])
{
  double mv[3] = {m->m11, 2 * m->m12, m->m22};
  int e = low_exp_of(3, mv);
  ob mk[3];
  for (int k = 0; k < 3; k++)
    ob_from_double(&mk[k], mv[k], e);
  static ob mat[4][4];
  for (int i = 0; i < 4; i++) {
    ob q[3], t, s1, s2;
    ob_small(&mat[i][0], p[i][0]);
    ob_small(&mat[i][1], p[i][1]);
    ob_mul(&t, &mat[i][0], &mat[i][0]);
    ob_mul(&q[0], &mk[0], &t);
    ob_mul(&t, &mat[i][0], &mat[i][1]);
    ob_mul(&q[1], &mk[1], &t);
    ob_mul(&t, &mat[i][1], &mat[i][1]);
    ob_mul(&q[2], &mk[2], &t);
    ob_add(&s1, &q[0], &q[1]);
    ob_add(&s2, &s1, &q[2]);
    mat[i][2] = s2;
    ob_small(&mat[i][3], 1);
  }
  ob det;
  ob_det(4, mat, 0, 15u, &det);
  return (m->det_sign < 0 ? -1 : 1) * ob_sign(&det);
}

/* ------------------------------------------------------------------------ */
/* Helpers */

static uint64_t g_seed = 12345;

/* Prints the seed when a block of checks added failures. */
#define SEED_GUARD_BEGIN int seed_fail0_ = tt_test_failures
#define SEED_GUARD_END(name)                                                 \
  do {                                                                       \
    if (tt_test_failures != seed_fail0_)                                     \
      fprintf(stderr, "%s: failed with TT_SEED=%" PRIu64 "\n", name,         \
              g_seed);                                                       \
  } while (0)

/* x moved by k ulps (nextafter |k| times). */
static double ulps(double x, int k)
{
  for (; k > 0; k--)
    x = nextafter(x, INFINITY);
  for (; k < 0; k++)
    x = nextafter(x, -INFINITY);
  return x;
}

static const int perm3[6][3] = {{0, 1, 2}, {1, 2, 0}, {2, 0, 1},
                                {1, 0, 2}, {0, 2, 1}, {2, 1, 0}};
static const int perm3_sign[6] = {1, 1, 1, -1, -1, -1};

static int perm_parity(const int *p, int n)
{
  int s = 1;
  for (int i = 0; i < n; i++)
    for (int j = i + 1; j < n; j++)
      if (p[i] > p[j])
        s = -s;
  return s;
}

/* All 24 permutations of 0..3, with their parity. */
static int perm4[24][4], perm4_sign[24];

static void init_perm4(void)
{
  int n = 0;
  for (int a = 0; a < 4; a++)
    for (int b = 0; b < 4; b++)
      for (int c = 0; c < 4; c++)
        for (int d = 0; d < 4; d++)
          if (a != b && a != c && a != d && b != c && b != d && c != d) {
            int *p = perm4[n];
            p[0] = a;
            p[1] = b;
            p[2] = c;
            p[3] = d;
            perm4_sign[n++] = perm_parity(p, 4);
          }
}

/* Checks orient2d against the oracle and under all permutations. */
static int check_orient(double p[3][2])
{
  int want = oracle_orient(p[0], p[1], p[2]);
  for (int i = 0; i < 6; i++) {
    const int *q = perm3[i];
    int got = tt__orient2d(p[q[0]], p[q[1]], p[q[2]]);
    if (got != perm3_sign[i] * want) {
      TT_FAIL_("orient2d((%.17g,%.17g),(%.17g,%.17g),(%.17g,%.17g)) perm %d"
               " = %d, oracle %d",
               p[q[0]][0], p[q[0]][1], p[q[1]][0], p[q[1]][1], p[q[2]][0],
               p[q[2]][1], i, got, perm3_sign[i] * want);
      break;
    }
  }
  return want;
}

/* Checks incircle against the oracle (or want when not 2) and under all
 * permutations: any transposition of the four arguments flips the sign. */
static int check_incircle(double p[4][2], int want)
{
  int oracle = oracle_incircle(p[0], p[1], p[2], p[3]);
  if (want != 2 && want != oracle)
    TT_FAIL_("oracle disagrees with the expected sign: %d vs %d", oracle,
             want);
  for (int i = 0; i < 24; i++) {
    const int *q = perm4[i];
    int got = tt__incircle(p[q[0]], p[q[1]], p[q[2]], p[q[3]]);
    if (got != perm4_sign[i] * oracle) {
      TT_FAIL_("incircle((%.17g,%.17g),(%.17g,%.17g),(%.17g,%.17g),"
               "(%.17g,%.17g)) = %d, oracle %d",
               p[q[0]][0], p[q[0]][1], p[q[1]][0], p[q[1]][1], p[q[2]][0],
               p[q[2]][1], p[q[3]][0], p[q[3]][1], got,
               perm4_sign[i] * oracle);
      break;
    }
  }
  return oracle;
}

static int metric_call(const tt__metric *m, int64_t p[4][2],
                       const int *q)
{
  return tt__incircle_metric(m, p[q[0]][0], p[q[0]][1], p[q[1]][0],
                             p[q[1]][1], p[q[2]][0], p[q[2]][1], p[q[3]][0],
                             p[q[3]][1]);
}

/* Checks the metric incircle against want (the oracle when want is 2) under
 * all permutations. */
static void check_metric(const tt__metric *m, int64_t p[4][2], int want)
{
  if (want == 2)
    want = oracle_metric(m, p);
  for (int i = 0; i < 24; i++) {
    int got = metric_call(m, p, perm4[i]);
    if (got != perm4_sign[i] * want) {
      const int *q = perm4[i];
      TT_FAIL_("incircle_metric(m=%.17g,%.17g,%.17g,%d; (%" PRId64
               ",%" PRId64 "),(%" PRId64 ",%" PRId64 "),(%" PRId64
               ",%" PRId64 "),(%" PRId64 ",%" PRId64 ")) = %d, want %d",
               m->m11, m->m12, m->m22, m->det_sign, p[q[0]][0], p[q[0]][1],
               p[q[1]][0], p[q[1]][1], p[q[2]][0], p[q[2]][1], p[q[3]][0],
               p[q[3]][1], got, perm4_sign[i] * want);
      break;
    }
  }
}

/* ------------------------------------------------------------------------ */
/* Tests */

static void test_known_signs(void)
{
  double o[2] = {0, 0}, ex[2] = {1, 0}, ey[2] = {0, 1}, mid[2] = {0.5, 0.5};
  CHECK_INT_EQ(tt__orient2d(o, ex, ey), 1);
  CHECK_INT_EQ(tt__orient2d(o, ey, ex), -1);
  CHECK_INT_EQ(tt__orient2d(o, ex, ex), 0);
  CHECK_INT_EQ(tt__orient2d(o, mid, (double[2]){2, 2}), 0);
  CHECK_INT_EQ(tt__orient_i(0, 0, 1, 0, 0, 1), 1);
  CHECK_INT_EQ(tt__orient_i(0, 0, 0, 1, 1, 0), -1);
  CHECK_INT_EQ(tt__orient_i(0, 0, 3, 3, -5, -5), 0);

  /* Unit circle, counter-clockwise: the center is inside. */
  double a[2] = {1, 0}, b[2] = {0, 1}, c[2] = {-1, 0};
  double far[2] = {3, 3}, on[2] = {0, -1}, in[2] = {0.1, -0.2};
  CHECK_INT_EQ(tt__incircle(a, b, c, o), 1);
  CHECK_INT_EQ(tt__incircle(a, b, c, in), 1);
  CHECK_INT_EQ(tt__incircle(a, b, c, far), -1);
  CHECK_INT_EQ(tt__incircle(a, b, c, on), 0);
  CHECK_INT_EQ(tt__incircle(b, a, c, o), -1);

  /* The metric version with the identity frame agrees; a mirror frame
   * (det_sign -1, as for north-up rasters) flips the sign. */
  tt__metric id = {1, 0, 1, 1}, mir = {1, 0, 1, -1};
  CHECK_INT_EQ(tt__incircle_metric(&id, 1, 0, 0, 1, -1, 0, 0, 0), 1);
  CHECK_INT_EQ(tt__incircle_metric(&id, 1, 0, 0, 1, -1, 0, 3, 3), -1);
  CHECK_INT_EQ(tt__incircle_metric(&id, 1, 0, 0, 1, -1, 0, 0, -1), 0);
  CHECK_INT_EQ(tt__incircle_metric(&mir, 1, 0, 0, 1, -1, 0, 0, 0), -1);
  /* A stretched frame, x scaled by 10: the ground points (10,0), (0,1),
   * (-10,0) lie on the circle centered at (0,-49.5) with radius 50.5, whose
   * lowest point is (0,-100). */
  tt__metric st = {100, 0, 1, 1};
  CHECK_INT_EQ(tt__incircle_metric(&st, 1, 0, 0, 1, -1, 0, 0, -1), 1);
  CHECK_INT_EQ(tt__incircle_metric(&st, 1, 0, 0, 1, -1, 0, 0, -99), 1);
  CHECK_INT_EQ(tt__incircle_metric(&st, 1, 0, 0, 1, -1, 0, 0, -100), 0);
  CHECK_INT_EQ(tt__incircle_metric(&st, 1, 0, 0, 1, -1, 0, 0, -101), -1);
}

/* Collinear rows, columns and diagonals, and co-circular rectangle corners,
 * on grids of doubles (any values: equal coordinates make them exact). */
static void test_grid_degenerate(void)
{
  static const double xs[] = {-1e6 - 0.1, -3.3, -0.1, 0, 0.1, 0.7, 1.0 / 3,
                              2.5, 1e-7, 123456.789, 4.2e8};
  int nx = (int)(sizeof xs / sizeof xs[0]);
  for (int r = 0; r < nx; r++) {
    for (int i = 0; i < nx; i++)
      for (int j = 0; j < nx; j++)
        for (int k = 0; k < nx; k++) {
          double row[3][2] = {{xs[i], xs[r]}, {xs[j], xs[r]}, {xs[k], xs[r]}};
          double col[3][2] = {{xs[r], xs[i]}, {xs[r], xs[j]}, {xs[r], xs[k]}};
          double dia[3][2] = {{xs[i], xs[i]}, {xs[j], xs[j]}, {xs[k], xs[k]}};
          CHECK_INT_EQ(tt__orient2d(row[0], row[1], row[2]), 0);
          CHECK_INT_EQ(tt__orient2d(col[0], col[1], col[2]), 0);
          CHECK_INT_EQ(tt__orient2d(dia[0], dia[1], dia[2]), 0);
        }
  }
  /* Rectangles: all 24 orders of the four corners are co-circular. */
  for (int i = 0; i < nx; i++)
    for (int j = 0; j < nx; j++)
      for (int k = 0; k < nx; k++)
        for (int l = 0; l < nx; l++) {
          if (i >= j || k >= l) /* the permutations cover other orders */
            continue;
          double p[4][2] = {{xs[i], xs[k]}, {xs[j], xs[k]}, {xs[j], xs[l]},
                            {xs[i], xs[l]}};
          for (int q = 0; q < 24; q++) {
            const int *s = perm4[q];
            int got = tt__incircle(p[s[0]], p[s[1]], p[s[2]], p[s[3]]);
            if (got != 0) {
              TT_FAIL_("rectangle x %.17g,%.17g y %.17g,%.17g perm %d: %d",
                       xs[i], xs[j], xs[k], xs[l], q, got);
              break;
            }
          }
        }

  /* Integer grids: rows, columns and lines of slope 3/7 near 2^28. */
  const int64_t big = ((int64_t)1 << 28) - 1;
  static const int64_t ts[] = {-5, 0, 1, 2, 7, 1000};
  for (int i = 0; i < 6; i++)
    for (int j = 0; j < 6; j++)
      for (int k = 0; k < 6; k++) {
        int64_t a = ts[i], b = ts[j], c = ts[k];
        CHECK_INT_EQ(tt__orient_i(a, 4, b, 4, c, 4), 0);
        CHECK_INT_EQ(tt__orient_i(-big, a, -big, b, -big, c), 0);
        CHECK_INT_EQ(tt__orient_i(big - 7 * 1000 + 7 * a, -big + 3 * a,
                                  big - 7 * 1000 + 7 * b, -big + 3 * b,
                                  big - 7 * 1000 + 7 * c, -big + 3 * c),
                     0);
      }
  int64_t lp[3][2] = {{-big, -big}, {0, 0}, {big, big}};
  int64_t lq[3][2] = {{-big, -big + 1}, {0, 0}, {big, big}};
  for (int i = 0; i < 6; i++) {
    const int *q = perm3[i];
    CHECK_INT_EQ(tt__orient_i(lp[q[0]][0], lp[q[0]][1], lp[q[1]][0],
                              lp[q[1]][1], lp[q[2]][0], lp[q[2]][1]),
                 0);
    /* (-big, -big + 1) lies left of the diagonal, going up. */
    CHECK_INT_EQ(tt__orient_i(lq[q[0]][0], lq[q[0]][1], lq[q[1]][0],
                              lq[q[1]][1], lq[q[2]][0], lq[q[2]][1]),
                 perm3_sign[i]);
  }

  /* Pixel rectangles under square, rectangular and mirrored metrics: the
   * corners of cells and of larger rectangles stay co-circular. */
  const tt__metric ms[] = {{1, 0, 1, 1},     {900, 0, 900, -1},
                           {4, 0, 9, 1},     {1e-10, 0, 3.7e-10, -1},
                           {0.3, 0, 0.7, 1}, {1, 0, 1e6, 1}};
  static const int64_t cs[] = {-big, -1000, -1, 0, 1, 2, 5, 999, big};
  for (size_t mi = 0; mi < sizeof ms / sizeof ms[0]; mi++)
    for (int i = 0; i < 9; i++)
      for (int j = i + 1; j < 9; j++)
        for (int k = 0; k < 9; k++)
          for (int l = k + 1; l < 9; l++) {
            int64_t p[4][2] = {{cs[i], cs[k]}, {cs[j], cs[k]}, {cs[j], cs[l]},
                               {cs[i], cs[l]}};
            check_metric(&ms[mi], p, 0);
          }

  /* Sheared frame A = [[1,1],[0,1]] (and scaled by 30, mirrored): pixel
   * points whose ground images are rectangle corners, p = A^-1 g. */
  const double frames[3][4] = {{1, 1, 0, 1}, {30, 30, 0, 30}, {30, 30, 0, -30}};
  for (int f = 0; f < 3; f++) {
    tt__metric m;
    tt__metric_from_frame(frames[f], &m);
    CHECK(m.m12 != 0);
    for (int i = 0; i < 9; i++)
      for (int j = i + 1; j < 9; j++)
        for (int k = 0; k < 9; k++)
          for (int l = k + 1; l < 9; l++) {
            int64_t gx[2] = {cs[i] / 2, cs[j] / 2}, gy[2] = {cs[k] / 2,
                                                             cs[l] / 2};
            if (gx[0] == gx[1] || gy[0] == gy[1])
              continue;
            int64_t p[4][2];
            for (int c = 0; c < 4; c++) {
              int64_t x = gx[(c == 1 || c == 2)], y = gy[c >= 2];
              /* Ground (x, y) up to the scale: row = +-y, col = x - row. */
              int64_t row = frames[f][3] < 0 ? -y : y;
              p[c][0] = x - row;
              p[c][1] = row;
            }
            check_metric(&m, p, 0);
          }
  }
}

/* Collinear and co-circular configurations, exact in doubles, then moved by
 * a few ulps per coordinate; at several scales including subnormal and huge
 * ones where the scaling by a power of two is exact. */
static void test_ulp_perturbations(void)
{
  SEED_GUARD_BEGIN;
  uint64_t st = g_seed ^ 0x51ed;

  /* Shewchuk's classic: (0.5 + i ulp, 0.5 + j ulp), (12, 12), (24, 24). */
  for (int i = -12; i <= 12; i++)
    for (int j = -12; j <= 12; j++) {
      double p[3][2] = {{ulps(0.5, i), ulps(0.5, j)}, {12, 12}, {24, 24}};
      check_orient(p);
    }

  /* Grids of ulps around a point near (not on) a random line bc, so that
   * the rounded filter value would often get the sign wrong. */
  for (int line = 0; line < 24; line++) {
    double b[2] = {tt_test_uniform(&st), tt_test_uniform(&st)};
    double c[2] = {b[0] + 30 * tt_test_uniform(&st),
                   b[1] + 30 * tt_test_uniform(&st)};
    double t = tt_test_uniform(&st);
    if (line % 2) /* beyond the segment too */
      t = 1 + 2 * t;
    double a0[2] = {b[0] + t * (c[0] - b[0]), b[1] + t * (c[1] - b[1])};
    for (int i = -8; i <= 8; i++)
      for (int j = -8; j <= 8; j++) {
        double p[3][2] = {{ulps(a0[0], i), ulps(a0[1], j)},
                          {b[0], b[1]},
                          {c[0], c[1]}};
        check_orient(p);
      }
  }

  /* Integer points on the circle x^2 + y^2 = 25^2. */
  static const int circ[12][2] = {{25, 0},  {24, 7},   {20, 15}, {15, 20},
                                  {7, 24},  {0, 25},   {-7, 24}, {-20, 15},
                                  {-24, -7}, {-15, -20}, {0, -25}, {20, -15}};
  static const double scales[] = {1.0, 0x1p-30, 0x1p+20, 0x1p-1000,
                                  0x1p+900, 0x1p-1060};
  static const double offsets[] = {0, 1024, -0.5, 1e6};
  int zeros = 0, signs = 0;
  for (int it = 0; it < 4000; it++) {
    double s = scales[tt_test_rand(&st) % 6];
    double off = offsets[tt_test_rand(&st) % 4] * (s < 1e-200 ? 0 : s);
    int pick[4];
    for (int k = 0; k < 4; k++) {
      int ok;
      do {
        pick[k] = (int)(tt_test_rand(&st) % 12);
        ok = 1;
        for (int q = 0; q < k; q++)
          ok &= pick[q] != pick[k];
      } while (!ok);
    }
    double p[4][2];
    for (int k = 0; k < 4; k++) {
      p[k][0] = circ[pick[k]][0] * s + off;
      p[k][1] = circ[pick[k]][1] * s - off;
    }
    int nbump = (int)(tt_test_rand(&st) % 3);
    for (int k = 0; k < nbump; k++) {
      int pt = (int)(tt_test_rand(&st) % 4), ax = (int)(tt_test_rand(&st) % 2);
      p[pt][ax] = ulps(p[pt][ax], (int)(tt_test_rand(&st) % 7) - 3);
    }
    int r = check_incircle(p, nbump == 0 && s > 0x1p-1050 ? 0 : 2);
    zeros += r == 0;
    signs += r != 0;

    /* Three of them collinear-ish: points on a line through offsets. */
    double dx = (double)(int)(tt_test_rand(&st) % 41) - 20;
    double dy = (double)(int)(tt_test_rand(&st) % 41) - 20;
    double t[3][2];
    for (int k = 0; k < 3; k++) {
      double u = (double)(int)(tt_test_rand(&st) % 9) - 4;
      t[k][0] = (0.375 + u * dx) * s + off;
      t[k][1] = (-1.25 + u * dy) * s + off;
    }
    if (tt_test_rand(&st) % 2) {
      int pt = (int)(tt_test_rand(&st) % 3), ax = (int)(tt_test_rand(&st) % 2);
      t[pt][ax] = ulps(t[pt][ax], (int)(tt_test_rand(&st) % 7) - 3);
    }
    check_orient(t);
  }
  CHECK(zeros > 100);
  CHECK(signs > 100);
  SEED_GUARD_END("test_ulp_perturbations");
}

/* A random double: mode 0 uniform in [-1, 1], 1 any exponent, 2 around
 * 1e-300, 3 around 1e300, 4 small integers, 5 a mix of 1e300 and 1e-300. */
static double random_double(uint64_t *st, int mode)
{
  double u = 2 * tt_test_uniform(st) - 1;
  switch (mode) {
  case 0:
    return u;
  case 1: {
    int e = (int)(tt_test_rand(st) % 2090) - 1070;
    return ldexp(u, e);
  }
  case 2:
    return u * 1e-300;
  case 3:
    return u * 1e300;
  case 4:
    return (double)((int)(tt_test_rand(st) % 7) - 3);
  default:
    return tt_test_rand(st) % 2 ? u * 1e300 : u * 1e-300;
  }
}

static void test_random_doubles(void)
{
  SEED_GUARD_BEGIN;
  uint64_t st = g_seed;
  for (int it = 0; it < 6000; it++) {
    int mode = it % 6;
    double p[4][2];
    for (int k = 0; k < 4; k++) {
      p[k][0] = random_double(&st, mode);
      p[k][1] = random_double(&st, mode);
    }
    /* Sometimes start from a degenerate set: copy a point, or put d on a
     * line or at a scaled copy. */
    if (it % 5 == 0)
      p[3][0] = p[0][0], p[3][1] = p[1][1];
    if (it % 7 == 0)
      p[2][0] = p[0][0], p[2][1] = p[1][1];
    check_orient(p);
    check_incircle(p, 2);

    /* A power-of-two scaling that stays exact keeps the sign. */
    if (mode == 0) {
      double q[4][2], r[4][2];
      for (int k = 0; k < 4; k++)
        for (int a = 0; a < 2; a++) {
          q[k][a] = ldexp(p[k][a], -960);
          r[k][a] = ldexp(p[k][a], 1000);
        }
      int w = tt__incircle(p[0], p[1], p[2], p[3]);
      CHECK_INT_EQ(tt__incircle(r[0], r[1], r[2], r[3]), w);
      CHECK_INT_EQ(tt__orient2d(r[0], r[1], r[2]),
                   tt__orient2d(p[0], p[1], p[2]));
      check_incircle(q, 2);
      check_orient(q);
    }
  }
  /* Subnormals and the largest doubles. */
  double tiny = 0x1p-1074, big = 0x1.fffffffffffffp+1023;
  double sp[3][2] = {{0, 0}, {tiny, 0}, {0, tiny}};
  CHECK_INT_EQ(check_orient(sp), 1);
  double hp[3][2] = {{-big, -big}, {big, -big}, {big, big}};
  CHECK_INT_EQ(check_orient(hp), 1);
  double mp[3][2] = {{0, 0}, {big, 0}, {1, tiny}};
  CHECK_INT_EQ(check_orient(mp), 1);
  double hc[4][2] = {{big, 0}, {0, big}, {-big, 0}, {0, -big}};
  check_incircle(hc, 0);
  double sc[4][2] = {{tiny, 0}, {0, tiny}, {-tiny, 0}, {0, 0}};
  check_incircle(sc, 1);
  SEED_GUARD_END("test_random_doubles");
}

/* Integer frames map pixels to exact ground points: the metric incircle
 * must agree with tt__incircle on the ground points. */
static void test_metric_vs_ground(void)
{
  SEED_GUARD_BEGIN;
  uint64_t st = g_seed ^ 0xfeed;
  const double frames[][4] = {
      {1, 0, 0, 1},   {2, 0, 0, 3},    {30, 0, 0, -30},  {-30, 0, 0, 30},
      {60, 0, 0, -90}, {1, 1, 0, 1},    {30, 30, 0, 30}, {30, 30, 0, -30},
      {-30, -30, 0, 30}, {3, -4, 4, 3}, {3, 4, 4, -3},    {2, 1, -1, 3},
      {0, 30, -30, 0}};
  int nf = (int)(sizeof frames / sizeof frames[0]);
  const int64_t lim = ((int64_t)1 << 28) - 1;
  for (int f = 0; f < nf; f++) {
    const double *a = frames[f];
    tt__metric m;
    tt__metric_from_frame(a, &m);
    for (int it = 0; it < 3000; it++) {
      int64_t p[4][2];
      double g[4][2];
      /* Small boxes give many degenerate sets; large ones reach 2^28. */
      int64_t box = it % 3 == 0 ? 3 : (it % 3 == 1 ? 40 : lim);
      for (int k = 0; k < 4; k++) {
        p[k][0] = (int64_t)(tt_test_rand(&st) % (uint64_t)(2 * box + 1)) - box;
        p[k][1] = (int64_t)(tt_test_rand(&st) % (uint64_t)(2 * box + 1)) - box;
      }
      if (box == lim && it % 2) /* a near-degenerate big set */
        for (int k = 1; k < 4; k++) {
          p[k][0] = p[0][0] / 2 + (int64_t)(tt_test_rand(&st) % 5) - 2;
          p[k][1] = -p[0][1] + (int64_t)(tt_test_rand(&st) % 5) - 2;
          if (k == 2)
            p[k][0] = -p[k][0], p[k][1] = p[0][1];
        }
      for (int k = 0; k < 4; k++) {
        g[k][0] = a[0] * (double)p[k][0] + a[1] * (double)p[k][1];
        g[k][1] = a[2] * (double)p[k][0] + a[3] * (double)p[k][1];
      }
      int want = tt__incircle(g[0], g[1], g[2], g[3]);
      int got = metric_call(&m, p, perm4[0]);
      if (got != want) {
        TT_FAIL_("frame %d: incircle_metric (%" PRId64 ",%" PRId64
                 ") (%" PRId64 ",%" PRId64 ") (%" PRId64 ",%" PRId64
                 ") (%" PRId64 ",%" PRId64 ") = %d, ground %d",
                 f, p[0][0], p[0][1], p[1][0], p[1][1], p[2][0], p[2][1],
                 p[3][0], p[3][1], got, want);
        break;
      }
      if (it % 10 == 0)
        check_metric(&m, p, want);
    }
  }
  SEED_GUARD_END("test_metric_vs_ground");
}

/* Random double metrics, including near-cancelling ones that defeat the
 * filter and extreme ones, against the oracle. */
static void test_metric_vs_oracle(void)
{
  SEED_GUARD_BEGIN;
  uint64_t st = g_seed ^ 0xabcdef;
  const int64_t lim = ((int64_t)1 << 28) - 1;
  for (int it = 0; it < 20000; it++) {
    tt__metric m;
    int kind = it % 5;
    if (kind == 0) { /* a random rotated, anisotropic frame */
      double th = 6.283185307179586 * tt_test_uniform(&st);
      double sx = ldexp(1 + tt_test_uniform(&st), (int)(tt_test_rand(&st) % 40) - 20);
      double sy = sx * (0.5 + tt_test_uniform(&st));
      double a[4] = {sx * cos(th), -sy * sin(th), sx * sin(th), sy * cos(th)};
      if (tt_test_rand(&st) % 2)
        a[1] = -a[1], a[3] = -a[3];
      tt__metric_from_frame(a, &m);
    } else if (kind == 1 || kind == 2) { /* near integer coefficients */
      m.m11 = ulps((double)(1 + tt_test_rand(&st) % 4), (int)(tt_test_rand(&st) % 5) - 2);
      m.m12 = ulps((double)((int)(tt_test_rand(&st) % 5) - 2) * 0.5,
                   (int)(tt_test_rand(&st) % 5) - 2);
      m.m22 = ulps((double)(1 + tt_test_rand(&st) % 4), (int)(tt_test_rand(&st) % 5) - 2);
      m.det_sign = tt_test_rand(&st) % 2 ? 1 : -1;
    } else if (kind == 3) { /* square and rectangular pixels */
      m.m11 = (double)(1 + tt_test_rand(&st) % 3);
      m.m12 = 0;
      m.m22 = tt_test_rand(&st) % 2 ? m.m11 : ulps(m.m11, 1);
      m.det_sign = tt_test_rand(&st) % 2 ? 1 : -1;
    } else { /* extreme magnitudes (no real frame): the big-integer path */
      m.m11 = ldexp(1 + tt_test_uniform(&st), (int)(tt_test_rand(&st) % 2000) - 1000);
      m.m12 = ldexp(tt_test_uniform(&st) - 0.5, (int)(tt_test_rand(&st) % 2000) - 1000);
      m.m22 = tt_test_rand(&st) % 2 ? m.m11 : ldexp(1 + tt_test_uniform(&st), -1070);
      m.det_sign = 1;
    }
    int64_t box = it % 2 ? 3 : (it % 4 == 0 ? 1000 : lim);
    int64_t p[4][2];
    for (int k = 0; k < 4; k++) {
      p[k][0] = (int64_t)(tt_test_rand(&st) % (uint64_t)(2 * box + 1)) - box;
      p[k][1] = (int64_t)(tt_test_rand(&st) % (uint64_t)(2 * box + 1)) - box;
    }
    int want = oracle_metric(&m, p);
    int got = metric_call(&m, p, perm4[0]);
    if (got != want) {
      TT_FAIL_("incircle_metric(m=%a,%a,%a,%d; (%" PRId64 ",%" PRId64
               "),(%" PRId64 ",%" PRId64 "),(%" PRId64 ",%" PRId64
               "),(%" PRId64 ",%" PRId64 ")) = %d, oracle %d",
               m.m11, m.m12, m.m22, m.det_sign, p[0][0], p[0][1], p[1][0],
               p[1][1], p[2][0], p[2][1], p[3][0], p[3][1], got, want);
      break;
    }
    if (it % 50 == 0)
      check_metric(&m, p, want);
  }

  /* Ground rectangles with big pixel coordinates under integer metrics M0:
   * corners p0, p0 + s u, p0 + s u + t v, p0 + t v with u^T M0 v = 0. The
   * integer part of m11 D1 + 2 m12 D2 + m22 D3 cancels, so with coefficients
   * a few ulps off M0 the sign comes from the exact stage, with large
   * determinants. */
  static const int m0s[4][3] = {{1, 1, 2}, {5, -1, 10}, {2, 0, 3}, {1, 0, 1}};
  for (int it = 0; it < 8000; it++) {
    const int *m0 = m0s[it % 4];
    int64_t u[2], v[2];
    do {
      u[0] = (int64_t)(tt_test_rand(&st) % 7) - 3;
      u[1] = (int64_t)(tt_test_rand(&st) % 7) - 3;
    } while (u[0] == 0 && u[1] == 0);
    v[0] = m0[1] * u[0] + m0[2] * u[1];
    v[1] = -(m0[0] * u[0] + m0[1] * u[1]);
    int64_t sc = (int64_t)(tt_test_rand(&st) % (1u << 22)) + 1;
    int64_t tc = (int64_t)(tt_test_rand(&st) % (1u << 20)) + 1;
    int64_t p[4][2];
    for (int k = 0; k < 2; k++) {
      p[0][k] = (int64_t)(tt_test_rand(&st) % (1u << 26)) - (1 << 25);
      p[1][k] = p[0][k] + sc * u[k];
      p[2][k] = p[1][k] + tc * v[k];
      p[3][k] = p[0][k] + tc * v[k];
    }
    int det_sign = tt_test_rand(&st) % 2 ? 1 : -1;
    tt__metric exact = {m0[0], m0[1], m0[2], det_sign};
    CHECK_INT_EQ(metric_call(&exact, p, perm4[0]), 0);
    if (it % 5 == 0) /* and a point off by one pixel */
      p[3][0] += 1;
    tt__metric m = {ulps(m0[0], (int)(tt_test_rand(&st) % 5) - 2),
                    ulps(m0[1], (int)(tt_test_rand(&st) % 5) - 2),
                    ulps(m0[2], (int)(tt_test_rand(&st) % 5) - 2), det_sign};
    int want = oracle_metric(&m, p);
    int got = metric_call(&m, p, perm4[0]);
    if (got != want) {
      TT_FAIL_("rectangle under M0 = (%d,%d,%d), m=%a,%a,%a: %d, oracle %d",
               m0[0], m0[1], m0[2], m.m11, m.m12, m.m22, got, want);
      break;
    }
    if (it % 40 == 0)
      check_metric(&m, p, want);
  }
  SEED_GUARD_END("test_metric_vs_oracle");
}

/* Integer orientation near 2^28 against the oracle. */
static void test_orient_i_big(void)
{
  SEED_GUARD_BEGIN;
  uint64_t st = g_seed ^ 0x77;
  const int64_t lim = ((int64_t)1 << 28) - 1;
  for (int it = 0; it < 20000; it++) {
    int64_t p[3][2];
    for (int k = 0; k < 3; k++) {
      p[k][0] = (int64_t)(tt_test_rand(&st) % (uint64_t)(2 * lim + 1)) - lim;
      p[k][1] = (int64_t)(tt_test_rand(&st) % (uint64_t)(2 * lim + 1)) - lim;
    }
    if (it % 2) { /* c near the line through a and the midpoint */
      int64_t mx = (p[0][0] + p[1][0]) / 2, my = (p[0][1] + p[1][1]) / 2;
      p[2][0] = 2 * mx - p[0][0] + (int64_t)(tt_test_rand(&st) % 3) - 1;
      p[2][1] = 2 * my - p[0][1] + (int64_t)(tt_test_rand(&st) % 3) - 1;
      if (p[2][0] > lim || p[2][0] < -lim || p[2][1] > lim || p[2][1] < -lim)
        continue;
    }
    double d[3][2];
    for (int k = 0; k < 3; k++)
      d[k][0] = (double)p[k][0], d[k][1] = (double)p[k][1];
    int want = check_orient(d);
    for (int i = 0; i < 6; i++) {
      const int *q = perm3[i];
      int got = tt__orient_i(p[q[0]][0], p[q[0]][1], p[q[1]][0], p[q[1]][1],
                             p[q[2]][0], p[q[2]][1]);
      if (got != perm3_sign[i] * want) {
        TT_FAIL_("orient_i perm %d = %d, oracle %d", i, got,
                 perm3_sign[i] * want);
        break;
      }
    }
  }
  SEED_GUARD_END("test_orient_i_big");
}

int main(void)
{
  const char *s = getenv("TT_SEED");
  if (s && *s)
    g_seed = strtoull(s, NULL, 10);
  init_perm4();
  TT_RUN(test_known_signs());
  TT_RUN(test_grid_degenerate());
  TT_RUN(test_ulp_perturbations());
  TT_RUN(test_random_doubles());
  TT_RUN(test_metric_vs_ground());
  TT_RUN(test_metric_vs_oracle());
  TT_RUN(test_orient_i_big());
  TT_TEST_DONE();
}
