/* test_gaussian_speed.c -- the Gaussian criterion's fast vertex
 * classification (gaussian.c) against the definition, bit for bit.
 *
 * gaussian.c classifies a star in O(d) (signs of consecutive triples, the
 * full supporting-plane test only for candidate pairs) and builds the hull
 * of a mixed star by Graham's scan with an O(d) proof, falling back to
 * gift wrapping. This test includes gaussian.c itself to reach its static
 * functions, and checks on random stars (degree 3 to 24, integer heights
 * full of coplanar rays, float heights, heights exactly on planes, ground
 * frames of either orientation) that
 *  - star_curvature gives the same class and the same bits of |K| as the
 *    reference below: every consecutive pair tested against every ray
 *    (SPEC section 2.5), the hull by gift wrapping from the first
 *    supporting pair -- the implementation gaussian.c had before;
 *  - whenever hull_graham proves a hull, it is gift wrapping's, ray for
 *    ray, and both outcomes (proved, refused) occur.
 * Seeded; the seed is printed on failure. */
#include "criteria/gaussian.c"

#include "tt_test.h"

#include <stdio.h>

static uint64_t rng_state;

static uint64_t rng(void) { return tt_test_rand(&rng_state); }

static int rng_int(int lo, int hi) /* [lo, hi] */
{
  return lo + (int)(rng() % (uint64_t)(hi - lo + 1));
}

/* The classification as the SPEC words it: every consecutive pair against
 * every other ray, the hull by gift wrapping from the first pair that
 * supports. Returns |K|; *out_start, *out_sgn: the hull's start and side
 * (mixed stars). */
static double ref_curvature(const tt__mesh *m, const double fr[4], int32_t v,
                            const star *s, rays *r, int *out_class,
                            int *out_start, int *out_sgn)
{
  int n = s->n;
  rays_load(m, fr, v, s, r);
  turn tsum = {1, 0, 0, true};
  for (int i = 0; i < n; i++) {
    double c, d;
    ground_cd(r, i, wrap(i + 1, n), &c, &d);
    turn_step(&tsum, c, d);
  }
  double sum = turn_angle(&tsum);
  unsigned char sides[TT__STAR_MAX + 1];
  int nsupport = 0, start = -1, sgn = 0;
  for (int i = 0; i < n; i++) {
    int j = wrap(i + 1, n), fp = 0, fn = 0;
    pair p;
    pair_make(r, i, j, &p);
    for (int t = 2; t < n; t++) {
      int sd = side(r, &p, i, j, wrap(i + t, n));
      fp |= sd > 0;
      fn |= sd < 0;
    }
    sides[i] = (unsigned char)(fp | fn << 1);
  }
  for (int i = 0; i < n; i++) {
    if (sides[i] == 3)
      continue;
    nsupport++;
    if (start < 0 && sides[i] != 0) {
      start = i;
      sgn = sides[i] == 1 ? 1 : -1;
    }
  }
  *out_start = start;
  *out_sgn = sgn;
  if (nsupport == n) {
    *out_class = TT__VERTEX_CONVEX;
    return 2 * TT__PI - sum;
  }
  if (nsupport == 0 || start < 0) {
    *out_class = TT__VERTEX_SADDLE;
    return sum - 2 * TT__PI;
  }
  *out_class = TT__VERTEX_MIXED;
  turn thull = {1, 0, 0, true};
  int tp = 0;
  unsigned char wrong = sgn > 0 ? 2 : 1;
  while (tp < n) {
    int p = wrap(start + tp, n);
    int tq = tp + 1, q = wrap(start + tq, n);
    double c, d;
    if (!(sides[p] & wrong)) {
      ground_cd(r, p, q, &c, &d);
      turn_step(&thull, c, d);
      tp = tq;
      continue;
    }
    pair pq;
    pair_make(r, p, q, &pq);
    for (int tr = tp + 2; tr <= n; tr++) {
      int x = wrap(start + tr, n);
      if (x == p)
        continue;
      if (sgn * side(r, &pq, p, q, x) < 0) {
        tq = tr;
        q = x;
        pair_make(r, p, q, &pq);
      }
    }
    ground_cd(r, p, q, &c, &d);
    turn_step(&thull, c, d);
    tp = tq;
  }
  return 2 * TT__PI - 2 * turn_angle(&thull) + sum;
}

/* A random proper fan around vertex 0 at pixel (1000, 1000): n directions
 * in increasing plan angle, every gap below pi. */
static bool make_fan(tt__mesh_vertex *vx, int n, int radius, star *s)
{
  double ang[TT__STAR_MAX];
  for (int i = 0; i < n; i++) {
    int dc, dr;
    do {
      dc = rng_int(-radius, radius);
      dr = rng_int(-radius, radius);
    } while (dc == 0 && dr == 0);
    vx[i + 1].c = 1000 + dc;
    vx[i + 1].r = 1000 + dr;
    ang[i] = atan2((double)dr, (double)dc);
  }
  /* sort by angle (insertion sort, small n) */
  for (int i = 1; i < n; i++)
    for (int j = i; j > 0 && ang[j - 1] > ang[j]; j--) {
      double a = ang[j];
      ang[j] = ang[j - 1];
      ang[j - 1] = a;
      tt__mesh_vertex t = vx[j + 1];
      vx[j + 1] = vx[j];
      vx[j] = t;
    }
  for (int i = 0; i < n; i++) {
    const tt__mesh_vertex *a = &vx[i + 1], *b = &vx[(i + 1) % n + 1];
    int64_t cr = (int64_t)(a->c - 1000) * (b->r - 1000) -
                 (int64_t)(a->r - 1000) * (b->c - 1000);
    if (cr <= 0)
      return false; /* a gap of pi or more, or two rays on one line */
  }
  s->n = n;
  s->boundary = false;
  for (int i = 0; i < n; i++)
    s->nb[i] = i + 1;
  return true;
}

static void set_heights(tt__mesh_vertex *vx, int n, int mode)
{
  double a = rng_int(-4, 4) * 0.25, b = rng_int(-4, 4) * 0.25;
  for (int i = 0; i <= n; i++) {
    double dc = vx[i].c - 1000, dr = vx[i].r - 1000;
    switch (mode) {
    case 0: /* small integers: flats and coplanar rays everywhere */
      vx[i].z = (float)rng_int(-2, 2);
      break;
    case 1: /* an integer plane, some samples off it by one */
      vx[i].z = (float)(a * 4 * dc + b * 4 * dr + 100 +
                        (rng() % 3 == 0 ? rng_int(-1, 1) : 0));
      break;
    case 2: /* floats */
      vx[i].z = (float)(1500 + (double)(rng() % 1000000) * 1e-4);
      break;
    default: /* a plane in non-integer floats, exact: the exact sums */
      vx[i].z = (float)(a * dc + b * dr + 0.125 +
                        (rng() % 4 == 0 ? rng_int(-1, 1) * 0.375 : 0));
      break;
    }
  }
}

static void random_stars(uint64_t seed)
{
  static const double frames[4][4] = {{1, 0, 0, 1},
                                      {30, 0, 0, -30},
                                      {0.7, 0.2, -0.1, 0.9},
                                      {-2.5, 0.5, 0.25, 3.0}};
  tt__mesh_vertex vx[TT__STAR_MAX + 1];
  tt__mesh m;
  memset(&m, 0, sizeof m);
  m.v = vx;
  static rays r1, r2;
  long classes[4] = {0}, proved = 0, refused = 0, stars = 0;
  rng_state = seed;
  for (int iter = 0; iter < 200000; iter++) {
    int n = rng_int(3, iter % 10 == 0 ? 24 : 9);
    int radius = rng_int(1, 3) == 1 ? 2 : 40;
    star s;
    vx[0].c = 1000;
    vx[0].r = 1000;
    if (!make_fan(vx, n, radius, &s))
      continue;
    int mode = (int)(rng() % 4);
    set_heights(vx, n, mode);
    const double *fr = frames[rng() % 4];
    int c1, c2, start, sgn;
    double k1 = star_curvature(&m, fr, 0, &s, &r1, &c1);
    double k2 = ref_curvature(&m, fr, 0, &s, &r2, &c2, &start, &sgn);
    stars++;
    classes[c1]++;
    if (c1 != c2 || memcmp(&k1, &k2, sizeof k1) != 0) {
      fprintf(stderr, "seed %#llx iter %d: n %d mode %d: class %d |K| %.17g,"
              " reference class %d |K| %.17g\n", (unsigned long long)seed,
              iter, n, mode, c1, k1, c2, k2);
      CHECK(false);
      return;
    }
    if (c2 != TT__VERTEX_MIXED)
      continue;
    int hg[TT__STAR_MAX + 1], hw[TT__STAR_MAX + 1];
    for (int i = 0; i < n; i++) { /* the consecutive pairs hull_wrap reads */
      pair p;
      pair_make(&r2, i, i + 1, &p);
      r2.nx[i] = p.nx;
      r2.ny[i] = p.ny;
      r2.nz[i] = p.nz;
      r2.nb[i] = p.bound;
    }
    int ng = hull_graham(&r2, n, start, sgn, hg);
    int nw = hull_wrap(&r2, n, start, sgn, hw);
    if (ng == 0) {
      refused++;
      continue;
    }
    proved++;
    bool same = ng == nw;
    for (int i = 0; i < ng && same; i++)
      same = hg[i] == hw[i];
    if (!same) {
      fprintf(stderr, "seed %#llx iter %d: n %d mode %d: Graham's hull of %d"
              " rays is not gift wrapping's (%d)\n", (unsigned long long)seed,
              iter, n, mode, ng, nw);
      CHECK(false);
      return;
    }
  }
  printf("stars %ld: convex %ld saddle %ld mixed %ld (hull proved %ld, "
         "wrapped %ld)\n", stars, classes[0], classes[1], classes[2], proved,
         refused);
  CHECK(classes[0] > 1000 && classes[1] > 1000 && classes[2] > 1000);
  CHECK(proved > 1000 && refused > 100);
}

int main(void)
{
  random_stars(0x9a55ull);
  random_stars(0x5eed2024ull);
  TT_TEST_DONE();
}
