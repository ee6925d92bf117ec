/*
 * predicates.c -- exact orientation and incircle tests (sign convention in
 * predicates.h).
 *
 * Double-precision predicates follow the plan of Shewchuk, "Adaptive
 * Precision Floating-Point Arithmetic and Fast Robust Geometric Predicates"
 * (1997): a floating-point evaluation whose rounding error is bounded a
 * priori (his ccwerrboundA / iccerrboundA, valid for exactly the evaluation
 * order used below) decides almost every call; when it cannot, an exact
 * evaluation in expansion arithmetic (a value held as a sum of
 * non-overlapping doubles) gives the sign. There are no intermediate stages
 * B/C: the exact stage is a plain, full evaluation.
 *
 * Expansion arithmetic is exact only when no intermediate value overflows or
 * underflows. The double predicates therefore check that every coordinate is
 * zero or within a range (stated at each predicate) where neither can
 * happen. Outside it (coordinates beyond about 1e-50 or 1e+70) the inputs
 * are first scaled by a power of two, which changes no sign; when they span
 * too many binades for that, a small arbitrary-precision integer evaluation
 * gives the sign. That path is exact for every finite double but slow; no
 * real terrain reaches it.
 *
 * Grid predicates work on integer pixel coordinates (|c|, |r| < 2^28) with
 * 128-bit integer intermediates; the metric incircle adds three double
 * coefficients (derivation above tt__incircle_metric).
 *
 * Workload: tt__incircle_metric runs for every flip test of Delaunay
 * refinement; its square-pixel case is a handful of integer multiplications.
 * Nothing here allocates or keeps state; all functions are reentrant.
 *
 * Part of src/base/, the base stage: the context and its errors, grids, exact
 * predicates, the heap, threads, memory limits.
 */
#include "base/predicates.h"

#include <assert.h>
#include <float.h>
#include <math.h>
#include <string.h>

#if defined(FLT_EVAL_METHOD) && FLT_EVAL_METHOD != 0
#error "predicates.c needs double arithmetic evaluated in double (SSE2, not x87)"
#endif

__extension__ typedef __int128 tt__i128;
__extension__ typedef unsigned __int128 tt__u128;

#if defined(__GNUC__)
#define TT_NOINLINE __attribute__((noinline))
#else
#define TT_NOINLINE
#endif

/* ------------------------------------------------------------------------ */
/* Expansion arithmetic (Shewchuk 1997, section 2). An expansion is an array
 * of doubles, ordered by increasing magnitude, non-overlapping, with zero
 * components removed (length 0 means the value 0); its sign is the sign of
 * its last component. Every routine below assumes round-to-nearest-even
 * double arithmetic with no overflow and no underflow. */

#define TT_EPS 1.1102230246251565e-16  /* 2^-53: half an ulp of 1 */
#define TT_SPLITTER 134217729.0        /* 2^27 + 1 */

/* x + y = a + b exactly, x = fl(a + b); needs |a| >= |b| or a == 0. */
static inline void fast_two_sum(double a, double b, double *x, double *y)
{
  double s = a + b;
  double bv = s - a;
  *x = s;
  *y = b - bv;
}

/* x + y = a + b exactly, x = fl(a + b) (Knuth's branch-free two-sum). */
static inline void two_sum(double a, double b, double *x, double *y)
{
  double s = a + b;
  double bv = s - a;
  double av = s - bv;
  *x = s;
  *y = (a - av) + (b - bv);
}

/* Dekker's split: a = hi + lo, each half fits in 26 bits (+ sign). */
static inline void split(double a, double *hi, double *lo)
{
  double c = TT_SPLITTER * a;
  double abig = c - a;
  *hi = c - abig;
  *lo = a - *hi;
}

/* x + y = a * b exactly, x = fl(a * b), with b already split. No FMA: the
 * build uses -ffp-contract=off so these products stay rounded one by one. */
static inline void two_product_presplit(double a, double b, double bhi,
                                        double blo, double *x, double *y)
{
  double p = a * b;
  double ahi, alo;
  split(a, &ahi, &alo);
  double err1 = p - ahi * bhi;
  double err2 = err1 - alo * bhi;
  double err3 = err2 - ahi * blo;
  *x = p;
  *y = alo * blo - err3;
}

static inline void two_product(double a, double b, double *x, double *y)
{
  double bhi, blo;
  split(b, &bhi, &blo);
  two_product_presplit(a, b, bhi, blo, x, y);
}

static inline int expansion_sign(int n, const double *e)
{
  return n == 0 ? 0 : (e[n - 1] > 0 ? 1 : -1);
}

/* h = e + b (Grow-Expansion, Theorem 10: e non-overlapping is enough). h may
 * be e itself: component i is read before h[<= i] is written. Returns the
 * length of h, at most elen + 1. */
static int grow_expansion(int elen, const double *e, double b, double *h)
{
  double q = b, hh;
  int hn = 0;
  for (int i = 0; i < elen; i++) {
    double ei = e[i];
    two_sum(q, ei, &q, &hh);
    if (hh != 0.0)
      h[hn++] = hh;
  }
  if (q != 0.0)
    h[hn++] = q;
  return hn;
}

/* h = e * b (Scale-Expansion, Theorem 19: strongly non-overlapping in, out).
 * h must not overlap e. Returns the length of h, at most 2 * elen. */
static int scale_expansion(int elen, const double *e, double b, double *h)
{
  if (elen == 0 || b == 0.0)
    return 0;
  double bhi, blo, q, hh, p1, p0, sum;
  int hn = 0;
  split(b, &bhi, &blo);
  two_product_presplit(e[0], b, bhi, blo, &q, &hh);
  if (hh != 0.0)
    h[hn++] = hh;
  for (int i = 1; i < elen; i++) {
    two_product_presplit(e[i], b, bhi, blo, &p1, &p0);
    two_sum(q, p0, &sum, &hh);
    if (hh != 0.0)
      h[hn++] = hh;
    fast_two_sum(p1, sum, &q, &hh);
    if (hh != 0.0)
      h[hn++] = hh;
  }
  if (q != 0.0)
    h[hn++] = q;
  return hn;
}

/* h = e + f (Fast-Expansion-Sum with zero elimination, Theorem 13: strongly
 * non-overlapping in and out, round-to-even). Merges the components by
 * increasing magnitude and carries a running sum through them. h must not
 * overlap e or f. Returns the length of h, at most elen + flen. */
static int expansion_sum(int elen, const double *e, int flen, const double *f,
                         double *h)
{
  int ei = 0, fi = 0, hn = 0;
  double q, hh;
  if (elen == 0 || flen == 0) {
    const double *src = elen == 0 ? f : e;
    int n = elen == 0 ? flen : elen;
    memcpy(h, src, (size_t)n * sizeof *h);
    return n;
  }
  /* Smallest component first. */
  if (fabs(e[0]) <= fabs(f[0]))
    q = e[ei++];
  else
    q = f[fi++];
  /* The second smallest is at least as large as q: fast_two_sum applies. */
  if (ei < elen && fi < flen) {
    if (fabs(e[ei]) <= fabs(f[fi]))
      fast_two_sum(e[ei++], q, &q, &hh);
    else
      fast_two_sum(f[fi++], q, &q, &hh);
    if (hh != 0.0)
      h[hn++] = hh;
    while (ei < elen && fi < flen) {
      if (fabs(e[ei]) <= fabs(f[fi]))
        two_sum(q, e[ei++], &q, &hh);
      else
        two_sum(q, f[fi++], &q, &hh);
      if (hh != 0.0)
        h[hn++] = hh;
    }
  }
  while (ei < elen) {
    two_sum(q, e[ei++], &q, &hh);
    if (hh != 0.0)
      h[hn++] = hh;
  }
  while (fi < flen) {
    two_sum(q, f[fi++], &q, &hh);
    if (hh != 0.0)
      h[hn++] = hh;
  }
  if (q != 0.0)
    h[hn++] = q;
  return hn;
}

/* h = a*d - b*c exactly: a 2x2 determinant of doubles, at most 4 components. */
static int det2_expansion(double a, double b, double c, double d, double *h)
{
  double p[2], q[2];
  two_product(a, d, &p[1], &p[0]);
  two_product(b, c, &q[1], &q[0]);
  q[0] = -q[0];
  q[1] = -q[1];
  /* Drop zero components so both inputs are proper expansions. */
  int pn = 0, qn = 0;
  double pz[2], qz[2];
  for (int i = 0; i < 2; i++) {
    if (p[i] != 0.0)
      pz[pn++] = p[i];
    if (q[i] != 0.0)
      qz[qn++] = q[i];
  }
  return expansion_sum(pn, pz, qn, qz, h);
}

/* ------------------------------------------------------------------------ */
/* Arbitrary-precision integers, only for double inputs whose magnitudes
 * leave the expansion-safe range. Sign and magnitude, 32-bit limbs, fixed
 * capacity: coordinates are scaled to integers by 2^-e0, e0 >= -1126 (the
 * lowest bit of a subnormal, as frexp reports it), so each is below 2^2150
 * and the degree-4 incircle determinant below 2^8610, i.e. 270 limbs. */

#define BIG_LIMBS 280

typedef struct big {
  int neg;                /* 1 when negative (never for zero) */
  int n;                  /* limbs in use, d[n-1] != 0 */
  uint32_t d[BIG_LIMBS];  /* magnitude, least significant limb first */
} big;

static void big_trim(big *r)
{
  while (r->n > 0 && r->d[r->n - 1] == 0)
    r->n--;
  if (r->n == 0)
    r->neg = 0;
}

/* r = x * 2^-e0, exact: e0 is at most the weight of x's lowest bit. */
static void big_from_double(big *r, double x, int e0)
{
  r->n = 0;
  r->neg = 0;
  if (x == 0.0)
    return;
  int ex;
  double f = frexp(fabs(x), &ex);
  uint64_t mant = (uint64_t)ldexp(f, 53); /* x = mant * 2^(ex - 53) */
  int sh = ex - 53 - e0;
  assert(sh >= 0 && sh / 32 + 3 <= BIG_LIMBS);
  int limb = sh / 32;
  tt__u128 v = (tt__u128)mant << (sh % 32);
  memset(r->d, 0, (size_t)limb * sizeof r->d[0]);
  r->d[limb] = (uint32_t)v;
  r->d[limb + 1] = (uint32_t)(v >> 32);
  r->d[limb + 2] = (uint32_t)(v >> 64);
  r->n = limb + 3;
  r->neg = x < 0;
  big_trim(r);
}

static void big_from_i128(big *r, tt__i128 x)
{
  tt__u128 m = x < 0 ? -(tt__u128)x : (tt__u128)x;
  for (int i = 0; i < 4; i++)
    r->d[i] = (uint32_t)(m >> (32 * i));
  r->n = 4;
  r->neg = x < 0;
  big_trim(r);
}

static int big_cmp_mag(const big *a, const big *b)
{
  if (a->n != b->n)
    return a->n < b->n ? -1 : 1;
  for (int i = a->n - 1; i >= 0; i--)
    if (a->d[i] != b->d[i])
      return a->d[i] < b->d[i] ? -1 : 1;
  return 0;
}

/* r = a + (negate_b ? -b : b). r may be a or b. */
static void big_add(big *r, const big *a, const big *b, int negate_b)
{
  int an = a->n, bn = b->n, aneg = a->neg, bneg = b->neg ^ negate_b;
  if (bn == 0) {
    if (r != a)
      *r = *a;
    return;
  }
  if (an == 0 || aneg == bneg) {
    int n = an > bn ? an : bn;
    uint64_t carry = 0;
    for (int i = 0; i < n; i++) {
      uint64_t s = carry + (i < an ? a->d[i] : 0) + (i < bn ? b->d[i] : 0);
      r->d[i] = (uint32_t)s;
      carry = s >> 32;
    }
    assert(n < BIG_LIMBS || carry == 0);
    if (carry)
      r->d[n++] = (uint32_t)carry;
    r->n = n;
    r->neg = an == 0 ? bneg : aneg;
    return;
  }
  /* Opposite signs: subtract the smaller magnitude from the larger. */
  const big *x = a, *y = b;
  int xneg = aneg;
  if (big_cmp_mag(a, b) < 0) {
    x = b;
    y = a;
    xneg = bneg;
  }
  int xn = x->n, yn = y->n;
  int64_t borrow = 0;
  for (int i = 0; i < xn; i++) {
    int64_t s = (int64_t)x->d[i] - (i < yn ? (int64_t)y->d[i] : 0) - borrow;
    borrow = s < 0;
    r->d[i] = (uint32_t)(s + (borrow << 32));
  }
  r->n = xn;
  r->neg = xneg;
  big_trim(r);
}

/* r = a * b; r must be neither a nor b. */
static void big_mul(big *r, const big *a, const big *b)
{
  int n = a->n + b->n;
  if (a->n == 0 || b->n == 0) {
    r->n = 0;
    r->neg = 0;
    return;
  }
  assert(n <= BIG_LIMBS);
  memset(r->d, 0, (size_t)n * sizeof r->d[0]);
  for (int i = 0; i < a->n; i++) {
    uint64_t carry = 0, ai = a->d[i];
    if (ai == 0) /* scaled doubles are sparse: most limbs are zero */
      continue;
    for (int j = 0; j < b->n; j++) {
      uint64_t t = r->d[i + j] + ai * b->d[j] + carry;
      r->d[i + j] = (uint32_t)t;
      carry = t >> 32;
    }
    r->d[i + b->n] = (uint32_t)carry;
  }
  r->n = n;
  r->neg = a->neg ^ b->neg;
  big_trim(r);
}

static int big_sign(const big *a)
{
  return a->n == 0 ? 0 : (a->neg ? -1 : 1);
}

/* The common scale 2^e0 of n doubles: the weight of the lowest possible bit
 * over the nonzero ones. Returns 0 when some value is not finite, sets
 * *all_zero when every value is zero. */
static int common_scale(int n, const double *v, int *out_e0, int *out_all_zero)
{
  int e0 = 0, any = 0;
  for (int i = 0; i < n; i++) {
    if (!isfinite(v[i]))
      return 0;
    if (v[i] == 0.0)
      continue;
    int ex;
    frexp(v[i], &ex);
    if (!any || ex - 53 < e0)
      e0 = ex - 53;
    any = 1;
  }
  *out_e0 = e0;
  *out_all_zero = !any;
  return 1;
}

static TT_NOINLINE int orient2d_big(const double a[2], const double b[2],
                                   const double c[2])
{
  double v[6] = {a[0], a[1], b[0], b[1], c[0], c[1]};
  int e0, zero;
  if (!common_scale(6, v, &e0, &zero) || zero)
    return 0;
  big p[6], acx, acy, bcx, bcy, l, r;
  for (int i = 0; i < 6; i++)
    big_from_double(&p[i], v[i], e0);
  big_add(&acx, &p[0], &p[4], 1);
  big_add(&acy, &p[1], &p[5], 1);
  big_add(&bcx, &p[2], &p[4], 1);
  big_add(&bcy, &p[3], &p[5], 1);
  big_mul(&l, &acx, &bcy);
  big_mul(&r, &acy, &bcx);
  big_add(&l, &l, &r, 1);
  return big_sign(&l);
}

static TT_NOINLINE int incircle_big(const double a[2], const double b[2],
                                    const double c[2], const double d[2])
{
  double v[8] = {a[0], a[1], b[0], b[1], c[0], c[1], d[0], d[1]};
  int e0, zero;
  if (!common_scale(8, v, &e0, &zero) || zero)
    return 0;
  big p[8], t[6], lift, minor, u, w, acc;
  for (int i = 0; i < 8; i++)
    big_from_double(&p[i], v[i], e0);
  for (int i = 0; i < 6; i++) /* adx, ady, bdx, bdy, cdx, cdy */
    big_add(&t[i], &p[i], &p[6 + (i & 1)], 1);
  acc.n = 0;
  acc.neg = 0;
  /* Row r's lift times the minor of the two other rows, taken cyclically:
   * alift (bdx cdy - bdy cdx) + blift (cdx ady - cdy adx) + ... */
  for (int r = 0; r < 3; r++) {
    const big *x0 = &t[2 * r], *y0 = &t[2 * r + 1];
    const big *x1 = &t[2 * ((r + 1) % 3)], *y1 = &t[2 * ((r + 1) % 3) + 1];
    const big *x2 = &t[2 * ((r + 2) % 3)], *y2 = &t[2 * ((r + 2) % 3) + 1];
    big_mul(&u, x0, x0);
    big_mul(&w, y0, y0);
    big_add(&lift, &u, &w, 0);
    big_mul(&u, x1, y2);
    big_mul(&w, y1, x2);
    big_add(&minor, &u, &w, 1);
    big_mul(&u, &lift, &minor);
    big_add(&acc, &acc, &u, 0);
  }
  return big_sign(&acc);
}

/* ------------------------------------------------------------------------ */
/* orient2d */

/* Ranges where every value of the filter and of the exact stage is a
 * multiple of 2^-1010 or more (so never subnormal) and below 2^1000:
 * orient2d has degree 2, incircle degree 4 in the coordinates. A nonzero
 * coordinate |x| >= 2^-k has its lowest bit at 2^(-k-52) or above. */
#define ORIENT_LO 0x1p-440
#define ORIENT_HI 0x1p+480
#define INCIRCLE_LO 0x1p-170
#define INCIRCLE_HI 0x1p+230

/* Whether x is neither zero nor in [lo, hi], or NaN; without branches (a
 * short-circuit chain costs as much as the filter itself). */
static inline int out_of_range(double x, double lo, double hi)
{
  double ax = fabs(x);
  return (ax > hi) | (ax != ax) | ((ax < lo) & (ax != 0.0));
}

/* Exact orient2d from the raw coordinates: the sum of the six products
 * ax by - ay bx + bx cy - by cx + cx ay - cy ax, each split exactly in two. */
static TT_NOINLINE int orient2d_exact(const double a[2], const double b[2],
                                      const double c[2])
{
  double t1[4], t2[4], t3[4], s12[8], s[12];
  int n1 = det2_expansion(a[0], a[1], b[0], b[1], t1);
  int n2 = det2_expansion(b[0], b[1], c[0], c[1], t2);
  int n3 = det2_expansion(c[0], c[1], a[0], a[1], t3);
  int n12 = expansion_sum(n1, t1, n2, t2, s12);
  int n = expansion_sum(n12, s12, n3, t3, s);
  return expansion_sign(n, s);
}

/* Shewchuk's ccwerrboundA: bounds the error of det below relative to
 * |detleft| + |detright| for this exact evaluation order. */
#define CCW_ERRBOUND_A ((3.0 + 16.0 * TT_EPS) * TT_EPS)

static int orient2d_far(const double a[2], const double b[2],
                        const double c[2]);

int tt__orient2d(const double a[2], const double b[2], const double c[2])
{
  if (out_of_range(a[0], ORIENT_LO, ORIENT_HI) |
      out_of_range(a[1], ORIENT_LO, ORIENT_HI) |
      out_of_range(b[0], ORIENT_LO, ORIENT_HI) |
      out_of_range(b[1], ORIENT_LO, ORIENT_HI) |
      out_of_range(c[0], ORIENT_LO, ORIENT_HI) |
      out_of_range(c[1], ORIENT_LO, ORIENT_HI))
    return orient2d_far(a, b, c);

  double detleft = (a[0] - c[0]) * (b[1] - c[1]);
  double detright = (a[1] - c[1]) * (b[0] - c[0]);
  double det = detleft - detright;
  double detsum;
  /* In range, rounding keeps the sign (and zeroness) of each product, so
   * when the two have opposite signs or one is zero the sign is exact. */
  if (detleft > 0.0) {
    if (detright <= 0.0)
      return det > 0.0 ? 1 : (det < 0.0 ? -1 : 0);
    detsum = detleft + detright;
  } else if (detleft < 0.0) {
    if (detright >= 0.0)
      return det > 0.0 ? 1 : (det < 0.0 ? -1 : 0);
    detsum = -detleft - detright;
  } else {
    return detright < 0.0 ? 1 : (detright > 0.0 ? -1 : 0);
  }
  double errbound = CCW_ERRBOUND_A * detsum;
  if (det > errbound)
    return 1;
  if (-det > errbound)
    return -1;
  return orient2d_exact(a, b, c);
}

/* ------------------------------------------------------------------------ */
/* incircle */

/* Exact incircle as the 4x4 determinant of rows (x, y, x^2 + y^2, 1) of a,
 * b, c, d (equal to the translated 3x3 form: subtract row d, expand along
 * the last column, then remove 2 dx col1 + 2 dy col2 from the lift column).
 * Expanding along the lift column:
 *   det = la T(b,c,d) - lb T(a,c,d) + lc T(a,b,d) - ld T(a,b,c)
 * with T(i,j,k) = det[[xi yi 1][xj yj 1][xk yk 1]] = ij + jk + ki where
 * ij = xi yj - xj yi, and l T = x (x T) + y (y T) with exact scaling. */
static int lift_times(const double p[2], int tn, const double *t, double *h)
{
  double tx[24], txx[48], ty[24], tyy[48];
  int nx = scale_expansion(tn, t, p[0], tx);
  int nxx = scale_expansion(nx, tx, p[0], txx);
  int ny = scale_expansion(tn, t, p[1], ty);
  int nyy = scale_expansion(ny, ty, p[1], tyy);
  return expansion_sum(nxx, txx, nyy, tyy, h);
}

static int sum3(int n1, const double *e1, int n2, const double *e2, int n3,
                const double *e3, double *h)
{
  double tmp[8];
  int n = expansion_sum(n1, e1, n2, e2, tmp);
  return expansion_sum(n, tmp, n3, e3, h);
}

static TT_NOINLINE int incircle_exact(const double a[2], const double b[2],
                                      const double c[2], const double d[2])
{
  double ab[4], bc[4], cd[4], da[4], ac[4], bd[4];
  int nab = det2_expansion(a[0], a[1], b[0], b[1], ab);
  int nbc = det2_expansion(b[0], b[1], c[0], c[1], bc);
  int ncd = det2_expansion(c[0], c[1], d[0], d[1], cd);
  int nda = det2_expansion(d[0], d[1], a[0], a[1], da);
  int nac = det2_expansion(a[0], a[1], c[0], c[1], ac);
  int nbd = det2_expansion(b[0], b[1], d[0], d[1], bd);
  double ca[4], db[4];
  for (int i = 0; i < nac; i++)
    ca[i] = -ac[i];
  for (int i = 0; i < nbd; i++)
    db[i] = -bd[i];
  int nca = nac, ndb = nbd;

  double tbcd[12], tacd[12], tabd[12], tabc[12];
  int nbcd = sum3(nbc, bc, ncd, cd, ndb, db, tbcd); /* T(b,c,d) */
  int nacd = sum3(nac, ac, ncd, cd, nda, da, tacd); /* T(a,c,d) */
  int nabd = sum3(nab, ab, nbd, bd, nda, da, tabd); /* T(a,b,d) */
  int nabc = sum3(nab, ab, nbc, bc, nca, ca, tabc); /* T(a,b,c) */
  for (int i = 0; i < nacd; i++)
    tacd[i] = -tacd[i];
  for (int i = 0; i < nabc; i++)
    tabc[i] = -tabc[i];

  double la[96], lb[96], lc[96], ld[96], s1[192], s2[192], s[384];
  int na = lift_times(a, nbcd, tbcd, la);
  int nb = lift_times(b, nacd, tacd, lb);
  int nc = lift_times(c, nabd, tabd, lc);
  int nd = lift_times(d, nabc, tabc, ld);
  int n1 = expansion_sum(na, la, nb, lb, s1);
  int n2 = expansion_sum(nc, lc, nd, ld, s2);
  int n = expansion_sum(n1, s1, n2, s2, s);
  return expansion_sign(n, s);
}

/* Scales n doubles by one power of two so the largest is in [0.5, 1) and
 * returns 1 when every scaled value is zero or in [lo, hi] (then normal, so
 * the scaling was exact): the signs of both predicates are unchanged by it. */
static int rescale(int n, const double *v, double *out, double lo, double hi)
{
  double vmax = 0;
  for (int i = 0; i < n; i++) {
    if (!isfinite(v[i]))
      return 0;
    if (fabs(v[i]) > vmax)
      vmax = fabs(v[i]);
  }
  int ex;
  frexp(vmax, &ex);
  for (int i = 0; i < n; i++) {
    out[i] = ldexp(v[i], -ex);
    if (out_of_range(out[i], lo, hi) || (v[i] != 0.0 && out[i] == 0.0))
      return 0;
  }
  return 1;
}

/* Coordinates outside the safe range: all tiny or all huge ones are scaled
 * into it; otherwise (a spread of more than ~900 binades) big integers. */
static TT_NOINLINE int orient2d_far(const double a[2], const double b[2],
                                    const double c[2])
{
  double v[6] = {a[0], a[1], b[0], b[1], c[0], c[1]}, w[6];
  if (rescale(6, v, w, ORIENT_LO, ORIENT_HI))
    return tt__orient2d(w, w + 2, w + 4);
  return orient2d_big(a, b, c);
}

static TT_NOINLINE int incircle_far(const double a[2], const double b[2],
                                    const double c[2], const double d[2])
{
  double v[8] = {a[0], a[1], b[0], b[1], c[0], c[1], d[0], d[1]}, w[8];
  if (rescale(8, v, w, INCIRCLE_LO, INCIRCLE_HI))
    return tt__incircle(w, w + 2, w + 4, w + 6);
  return incircle_big(a, b, c, d);
}

/* Shewchuk's iccerrboundA, for the evaluation order below. */
#define ICC_ERRBOUND_A ((10.0 + 96.0 * TT_EPS) * TT_EPS)

int tt__incircle(const double a[2], const double b[2], const double c[2],
                 const double d[2])
{
  if (out_of_range(a[0], INCIRCLE_LO, INCIRCLE_HI) |
      out_of_range(a[1], INCIRCLE_LO, INCIRCLE_HI) |
      out_of_range(b[0], INCIRCLE_LO, INCIRCLE_HI) |
      out_of_range(b[1], INCIRCLE_LO, INCIRCLE_HI) |
      out_of_range(c[0], INCIRCLE_LO, INCIRCLE_HI) |
      out_of_range(c[1], INCIRCLE_LO, INCIRCLE_HI) |
      out_of_range(d[0], INCIRCLE_LO, INCIRCLE_HI) |
      out_of_range(d[1], INCIRCLE_LO, INCIRCLE_HI))
    return incircle_far(a, b, c, d);

  double adx = a[0] - d[0], ady = a[1] - d[1];
  double bdx = b[0] - d[0], bdy = b[1] - d[1];
  double cdx = c[0] - d[0], cdy = c[1] - d[1];

  double bdxcdy = bdx * cdy, cdxbdy = cdx * bdy;
  double alift = adx * adx + ady * ady;
  double cdxady = cdx * ady, adxcdy = adx * cdy;
  double blift = bdx * bdx + bdy * bdy;
  double adxbdy = adx * bdy, bdxady = bdx * ady;
  double clift = cdx * cdx + cdy * cdy;

  double det = alift * (bdxcdy - cdxbdy) + blift * (cdxady - adxcdy) +
               clift * (adxbdy - bdxady);
  double permanent = (fabs(bdxcdy) + fabs(cdxbdy)) * alift +
                     (fabs(cdxady) + fabs(adxcdy)) * blift +
                     (fabs(adxbdy) + fabs(bdxady)) * clift;
  double errbound = ICC_ERRBOUND_A * permanent;
  if (det > errbound)
    return 1;
  if (-det > errbound)
    return -1;
  return incircle_exact(a, b, c, d);
}

/* ------------------------------------------------------------------------ */
/* Grid predicates */

int tt__orient_i(int64_t ax, int64_t ay, int64_t bx, int64_t by, int64_t cx,
                 int64_t cy)
{
  /* Differences below 2^29, products below 2^58: int64 would do for the
   * documented 2^28 bound; 128-bit products keep it exact up to 2^61. */
  tt__i128 det = (tt__i128)(ax - cx) * (by - cy) -
                 (tt__i128)(ay - cy) * (bx - cx);
  return det > 0 ? 1 : (det < 0 ? -1 : 0);
}

/*
 * The incircle test in a ground frame, from pixel coordinates.
 *
 * Ground points are p' = A p with M = A^T A = [[m11 m12][m12 m22]]. The
 * incircle determinant with rows (x', y', |p'|^2, 1) has first two columns
 * P A^T (P: the pixel coordinates) and lift column p^T M p, so
 *   incircle(a',b',c',d') = det(A) * det[[ax, ay, a^T M a, 1], ...].
 * Translate every point by -d (in pixel space; A is linear so the ground
 * points move by -A d): the first two columns change by multiples of the
 * ones column, and the lift q(p) = p^T M p becomes q(p - d) + 2 d^T M p -
 * q(d), i.e. it changes by a combination of the x, y and ones columns. The
 * determinant is unchanged; expanding along the ones column of row d (now
 * (0, 0, 0, 1)) leaves the 3x3 determinant of the translated rows
 * (x, y, m11 x^2 + 2 m12 x y + m22 y^2), linear in its third column:
 *   sign = det_sign * sign(m11 D1 + 2 m12 D2 + m22 D3),
 *   Dk = det[[ax ay qk(a)][bx by qk(b)][cx cy qk(c)]], q1 = x^2, q2 = x y,
 *   q3 = y^2 (translated coordinates),
 * and expanding Dk along its third column,
 *   Dk = qk(a) (bx cy - by cx) + qk(b) (cx ay - cy ax) + qk(c) (ax by - ay bx).
 *
 * Bounds, for |coordinate| < 2^28: translated coordinates are below 2^29,
 * the three 2x2 minors below 2^59 and each qk below 2^58 (int64), each
 * product below 2^117, so |Dk| < 3 * 2^117 < 2^119 and |2 D2|, |D1 + D3| <
 * 2^120: exact in __int128.
 *
 * The square-pixel case (m12 == 0, m11 == m22) is sign(m11) sign(D1 + D3),
 * all integer. Otherwise a floating-point filter decides: with dk the
 * rounded Dk (relative error <= 2^-52 even if the conversion were only
 * faithful), each tk = mk dk is within (3 eps + 2 eps^2)|mk Dk| of the true
 * product (eps = 2^-53), and the two additions add at most (2 eps + eps^2)
 * sum |tk|, so the total error is below 6 eps sum |tk| while no value
 * underflows, which the range check on the mk guarantees (|Dk| >= 1 when
 * nonzero). The filter uses 8 eps. When it cannot decide, each Dk is split
 * exactly into three doubles of 40 bits (|Dk| < 2^120), multiplied exactly
 * by mk with two-product, and the 18 terms summed in an expansion.
 * Coefficients outside [2^-500, 2^500] (no real frame) go to big integers.
 */
#define METRIC_LO 0x1p-500
#define METRIC_HI 0x1p+500
#define METRIC_ERRBOUND (8.0 * TT_EPS)

static inline int sign_i128(tt__i128 v)
{
  return v > 0 ? 1 : (v < 0 ? -1 : 0);
}

#ifndef NDEBUG
/* The documented input bound |coordinate| < 2^28 (int64 minors overflow
 * somewhat above it). */
static int coord_ok(int64_t v)
{
  return v > -((int64_t)1 << 28) && v < ((int64_t)1 << 28);
}
#endif

/* Adds mk * dk exactly to the expansion h of length n; returns the length. */
static int add_product(int n, double *h, double mk, tt__i128 dk)
{
  if (mk == 0.0 || dk == 0)
    return n;
  tt__u128 mag = dk < 0 ? -(tt__u128)dk : (tt__u128)dk;
  double sgn = dk < 0 ? -mk : mk;
  const tt__u128 mask = ((tt__u128)1 << 40) - 1;
  for (int j = 0; j < 3; j++) {
    /* Piece j, times 2^(40 j): an integer below 2^40, exact as a double. */
    double piece = (double)(uint64_t)((mag >> (40 * j)) & mask);
    if (piece == 0.0)
      continue;
    piece *= j == 0 ? 1.0 : (j == 1 ? 0x1p40 : 0x1p80);
    double x, y;
    two_product(sgn, piece, &x, &y);
    n = grow_expansion(n, h, y, h);
    n = grow_expansion(n, h, x, h);
  }
  return n;
}

static TT_NOINLINE int metric_big(const double mk[3], const tt__i128 dk[3])
{
  int e0, zero;
  if (!common_scale(3, mk, &e0, &zero) || zero)
    return 0;
  big acc, m, d, p;
  acc.n = 0;
  acc.neg = 0;
  for (int k = 0; k < 3; k++) {
    big_from_double(&m, mk[k], e0);
    big_from_i128(&d, dk[k]);
    big_mul(&p, &m, &d);
    big_add(&acc, &acc, &p, 0);
  }
  return big_sign(&acc);
}

static TT_NOINLINE int metric_general(const tt__metric *m, tt__i128 d1,
                                      tt__i128 d2x2, tt__i128 d3)
{
  double mk[3] = {m->m11, m->m12, m->m22};
  tt__i128 dk[3] = {d1, d2x2, d3};
  if (out_of_range(mk[0], METRIC_LO, METRIC_HI) |
      out_of_range(mk[1], METRIC_LO, METRIC_HI) |
      out_of_range(mk[2], METRIC_LO, METRIC_HI))
    return metric_big(mk, dk);

  double t1 = mk[0] * (double)d1;
  double t2 = mk[1] * (double)d2x2;
  double t3 = mk[2] * (double)d3;
  double s = t1 + t2 + t3;
  double errbound = METRIC_ERRBOUND * (fabs(t1) + fabs(t2) + fabs(t3));
  if (s > errbound)
    return 1;
  if (-s > errbound)
    return -1;

  double h[20];
  int n = 0;
  for (int k = 0; k < 3; k++)
    n = add_product(n, h, mk[k], dk[k]);
  return expansion_sign(n, h);
}

int tt__incircle_metric(const tt__metric *m, int64_t ax, int64_t ay,
                        int64_t bx, int64_t by, int64_t cx, int64_t cy,
                        int64_t dx, int64_t dy)
{
  assert(coord_ok(ax) && coord_ok(ay) && coord_ok(bx) && coord_ok(by) &&
         coord_ok(cx) && coord_ok(cy) && coord_ok(dx) && coord_ok(dy));
  int64_t adx = ax - dx, ady = ay - dy;
  int64_t bdx = bx - dx, bdy = by - dy;
  int64_t cdx = cx - dx, cdy = cy - dy;
  int64_t ma = bdx * cdy - bdy * cdx;
  int64_t mb = cdx * ady - cdy * adx;
  int64_t mc = adx * bdy - ady * bdx;
  int det_sign = m->det_sign < 0 ? -1 : 1;

  if (m->m12 == 0.0 && m->m11 == m->m22) {
    tt__i128 s = (tt__i128)(adx * adx + ady * ady) * ma +
                 (tt__i128)(bdx * bdx + bdy * bdy) * mb +
                 (tt__i128)(cdx * cdx + cdy * cdy) * mc;
    int sm = m->m11 > 0.0 ? 1 : (m->m11 < 0.0 ? -1 : 0);
    return det_sign * sm * sign_i128(s);
  }

  tt__i128 d1 = (tt__i128)(adx * adx) * ma + (tt__i128)(bdx * bdx) * mb +
                (tt__i128)(cdx * cdx) * mc;
  tt__i128 d3 = (tt__i128)(ady * ady) * ma + (tt__i128)(bdy * bdy) * mb +
                (tt__i128)(cdy * cdy) * mc;
  tt__i128 d2x2 = 0;
  if (m->m12 != 0.0)
    d2x2 = 2 * ((tt__i128)(adx * ady) * ma + (tt__i128)(bdx * bdy) * mb +
                (tt__i128)(cdx * cdy) * mc);
  return det_sign * metric_general(m, d1, d2x2, d3);
}

void tt__metric_from_frame(const double a[4], tt__metric *out)
{
  /* Columns of A are the ground images of a column step and a row step.
   * The orientation is the exact sign of det(A) = orient2d(0, A e1, A e2),
   * so a nearly singular frame cannot get the wrong one. */
  const double o[2] = {0, 0}, c1[2] = {a[0], a[2]}, c2[2] = {a[1], a[3]};
  out->m11 = a[0] * a[0] + a[2] * a[2];
  out->m12 = a[0] * a[1] + a[2] * a[3];
  out->m22 = a[1] * a[1] + a[3] * a[3];
  out->det_sign = tt__orient2d(o, c1, c2) < 0 ? -1 : 1;
}
