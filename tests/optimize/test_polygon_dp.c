/* test_polygon_dp.c -- the polygon DP (polygon_dp.c) against exhaustive
 * enumeration of every triangulation, for random convex and star-shaped
 * integer polygons of up to 9 vertices, for total 3-D area (sum) and the
 * largest angle (max). The enumeration is independent of the DP: it picks
 * every set of n - 3 pairwise non-crossing chords, each chord checked to
 * lie inside the polygon by its own exact test (no side crossed or
 * touched, midpoint inside by an even-odd count in doubled integer
 * coordinates), and reads the triangles off the chord set. Seeded; the
 * seed is printed (TT_SEED=<n> replays a run). */
#include "optimize/polygon_dp.h"
#include "tt_test.h"
#include "tt_test_geom.h"

#include <stdbool.h>

#define MAXN 9

typedef struct poly {
  int n;
  int64_t x[MAXN], y[MAXN];
  double z[MAXN];
  int s; /* +1: counter-clockwise in (x, y) */
} poly;

static int64_t cross(int64_t ax, int64_t ay, int64_t bx, int64_t by,
                     int64_t cx, int64_t cy)
{
  return tt_test_cross(ax, ay, bx, by, cx, cy);
}

/* closed segments meet */
static bool seg_meet(const poly *p, int a, int b, int c, int d)
{
  return tt_test_segments_meet(p->x, p->y, a, b, c, d);
}

static bool simple(const poly *p)
{
  for (int i = 0; i < p->n; i++)
    for (int j = i + 1; j < p->n; j++) {
      int i1 = (i + 1) % p->n, j1 = (j + 1) % p->n;
      if (p->x[i] == p->x[j] && p->y[i] == p->y[j])
        return false;
      if (i1 == j || j1 == i) {
        /* neighbours: only the shared corner, no fold back */
        int a = i1 == j ? i : j, m = i1 == j ? j : i, b = i1 == j ? j1 : i1;
        if (cross(p->x[a], p->y[a], p->x[m], p->y[m], p->x[b], p->y[b]) == 0 &&
            ((p->x[b] - p->x[m]) * (p->x[a] - p->x[m]) +
             (p->y[b] - p->y[m]) * (p->y[a] - p->y[m])) > 0)
          return false;
        continue;
      }
      if (seg_meet(p, i, i1, j, j1))
        return false;
    }
  return true;
}

/* midpoint of chord (i, j) strictly inside: even-odd ray count in doubled
 * coordinates, the ray going in +x with a tiny upward tilt handled by the
 * half-open rule on y */
static bool midpoint_inside(const poly *p, int i, int j)
{
  return tt_test_midpoint_inside(p->n, p->x, p->y, i, j);
}

static bool chord_inside(const poly *p, int i, int j)
{
  for (int k = 0; k < p->n; k++) {
    int k1 = (k + 1) % p->n;
    if (k == i || k == j || k1 == i || k1 == j)
      continue;
    if (seg_meet(p, i, j, k, k1))
      return false;
  }
  /* no other vertex on the chord */
  for (int k = 0; k < p->n; k++)
    if (k != i && k != j &&
        tt_test_on_segment(p->x[i], p->y[i], p->x[j], p->y[j], p->x[k],
                           p->y[k]))
      return false;
  return midpoint_inside(p, i, j);
}

/* --- measures ------------------------------------------------------------- */

static double area3(const poly *p, int a, int b, int c)
{
  double u[3] = {(double)(p->x[b] - p->x[a]), (double)(p->y[b] - p->y[a]),
                 p->z[b] - p->z[a]};
  double w[3] = {(double)(p->x[c] - p->x[a]), (double)(p->y[c] - p->y[a]),
                 p->z[c] - p->z[a]};
  double cx = u[1] * w[2] - u[2] * w[1], cy = u[2] * w[0] - u[0] * w[2],
         cz = u[0] * w[1] - u[1] * w[0];
  return 0.5 * sqrt(cx * cx + cy * cy + cz * cz);
}

static double angle_at(const poly *p, int a, int b, int c)
{
  double ux = (double)(p->x[b] - p->x[a]), uy = (double)(p->y[b] - p->y[a]);
  double wx = (double)(p->x[c] - p->x[a]), wy = (double)(p->y[c] - p->y[a]);
  return atan2(fabs(ux * wy - uy * wx), ux * wx + uy * wy);
}

static double max_angle(const poly *p, int a, int b, int c)
{
  return fmax(fmax(angle_at(p, a, b, c), angle_at(p, b, c, a)),
              angle_at(p, c, a, b));
}

static double m_area(void *arg, int i, int j, int k)
{
  return area3(arg, i, j, k);
}

static double m_angle(void *arg, int i, int j, int k)
{
  return max_angle(arg, i, j, k);
}

/* --- exhaustive enumeration -------------------------------------------- */

typedef struct enum_state {
  const poly *p;
  int chords[64][2];
  int nchords;
  int pick[MAXN];
  int npick;
  bool sum;
  double best;
  long count;
} enum_state;

static bool edge_present(const enum_state *s, int a, int b)
{
  int n = s->p->n;
  if ((a + 1) % n == b || (b + 1) % n == a)
    return true;
  for (int i = 0; i < s->npick; i++) {
    int c = s->chords[s->pick[i]][0], d = s->chords[s->pick[i]][1];
    if ((c == a && d == b) || (c == b && d == a))
      return true;
  }
  return false;
}

static void evaluate(enum_state *s)
{
  const poly *p = s->p;
  int n = p->n, nt = 0;
  double v = s->sum ? 0 : -INFINITY;
  for (int a = 0; a < n; a++)
    for (int b = a + 1; b < n; b++)
      for (int c = b + 1; c < n; c++)
        if (edge_present(s, a, b) && edge_present(s, b, c) &&
            edge_present(s, a, c)) {
          if (cross(p->x[a], p->y[a], p->x[b], p->y[b], p->x[c], p->y[c]) ==
              0)
            return; /* a zero-area triangle: not allowed */
          double t = s->sum ? area3(p, a, b, c) : max_angle(p, a, b, c);
          v = s->sum ? v + t : fmax(v, t);
          nt++;
        }
  if (nt != n - 2)
    return;
  s->count++;
  if (v < s->best)
    s->best = v;
}

static bool crossing(const enum_state *s, int u, int w)
{
  int a = s->chords[u][0], b = s->chords[u][1];
  int c = s->chords[w][0], d = s->chords[w][1];
  if (a == c || a == d || b == c || b == d)
    return false;
  return seg_meet(s->p, a, b, c, d);
}

static void choose(enum_state *s, int from)
{
  if (s->npick == s->p->n - 3) {
    evaluate(s);
    return;
  }
  for (int u = from; u < s->nchords; u++) {
    bool ok = true;
    for (int i = 0; i < s->npick && ok; i++)
      ok = !crossing(s, s->pick[i], u);
    if (!ok)
      continue;
    s->pick[s->npick++] = u;
    choose(s, u + 1);
    s->npick--;
  }
}

static double exhaustive(const poly *p, bool sum, long *out_count)
{
  enum_state s;
  memset(&s, 0, sizeof s);
  s.p = p;
  s.sum = sum;
  s.best = INFINITY;
  for (int i = 0; i < p->n; i++)
    for (int j = i + 2; j < p->n; j++)
      if (!(i == 0 && j == p->n - 1) && chord_inside(p, i, j)) {
        s.chords[s.nchords][0] = i;
        s.chords[s.nchords][1] = j;
        s.nchords++;
      }
  choose(&s, 0);
  *out_count = s.count;
  return s.best;
}

/* --- polygons ------------------------------------------------------------- */

static void set_orientation(poly *p)
{
  int64_t a = 0;
  for (int i = 0; i < p->n; i++) {
    int j = (i + 1) % p->n;
    a += p->x[i] * p->y[j] - p->x[j] * p->y[i];
  }
  p->s = a > 0 ? 1 : -1;
}

/* n points at sorted random angles around the origin, radii in
 * [rmin, 30]; rmin = 30 gives (nearly) convex polygons. */
static bool star_polygon(uint64_t *rng, int n, double rmin, poly *p)
{
  double ang[MAXN];
  for (int i = 0; i < n; i++)
    ang[i] = 6.283185307179586 * tt_test_uniform(rng);
  for (int i = 1; i < n; i++)
    for (int j = i; j > 0 && ang[j - 1] > ang[j]; j--) {
      double t = ang[j];
      ang[j] = ang[j - 1];
      ang[j - 1] = t;
    }
  p->n = n;
  for (int i = 0; i < n; i++) {
    double r = rmin + (30 - rmin) * tt_test_uniform(rng);
    p->x[i] = (int64_t)llround(r * cos(ang[i]));
    p->y[i] = (int64_t)llround(r * sin(ang[i]));
    p->z[i] = 20 * tt_test_uniform(rng);
  }
  if (tt_test_rand(rng) & 1) /* both turning directions */
    for (int i = 0; i < n / 2; i++) {
      int j = n - 1 - i;
      int64_t tx = p->x[i], ty = p->y[i];
      double tz = p->z[i];
      p->x[i] = p->x[j];
      p->y[i] = p->y[j];
      p->z[i] = p->z[j];
      p->x[j] = tx;
      p->y[j] = ty;
      p->z[j] = tz;
    }
  set_orientation(p);
  return simple(p);
}

static void check_case(const poly *p, bool sum, uint64_t seed, int round)
{
  long count;
  double want = exhaustive(p, sum, &count);
  int32_t tris[3 * MAXN];
  double got = NAN;
  bool ok = tt__polygon_dp(p->n, p->x, p->y, p->s,
                           sum ? TT__DP_SUM : TT__DP_MAX,
                           sum ? m_area : m_angle, (void *)p, tris, &got);
  if (count == 0) {
    if (ok)
      TT_FAIL_("seed %" PRIu64 " round %d: DP found a triangulation, the "
               "enumeration none", seed, round);
    return;
  }
  if (!ok) {
    TT_FAIL_("seed %" PRIu64 " round %d (n %d): DP failed, %ld "
             "triangulations exist", seed, round, p->n, count);
    return;
  }
  if (!(fabs(got - want) <= 1e-9 * (1 + fabs(want))))
    TT_FAIL_("seed %" PRIu64 " round %d (n %d, %s): DP %.17g, best of %ld "
             "triangulations %.17g", seed, round, p->n, sum ? "area" : "angle",
             got, count, want);
  /* the triangles returned have that value and are inside the polygon */
  double v = sum ? 0 : -INFINITY;
  for (int t = 0; t < p->n - 2; t++) {
    int a = tris[3 * t], b = tris[3 * t + 1], c = tris[3 * t + 2];
    CHECK(a < b && b < c);
    CHECK(p->s * tt_test_sgn(cross(p->x[a], p->y[a], p->x[b], p->y[b],
                                   p->x[c], p->y[c])) > 0);
    double m = sum ? area3(p, a, b, c) : max_angle(p, a, b, c);
    v = sum ? v + m : fmax(v, m);
    int e[3][2] = {{a, b}, {b, c}, {a, c}};
    for (int k = 0; k < 3; k++) {
      int i = e[k][0], j = e[k][1];
      bool side = j == i + 1 || (i == 0 && j == p->n - 1);
      CHECK(side || chord_inside(p, i, j));
    }
  }
  CHECK_DBL_NEAR(v, got, 1e-9 * (1 + fabs(got)));
}

int main(void)
{
  uint64_t seed = 4242;
  const char *env = getenv("TT_SEED");
  if (env)
    seed = strtoull(env, NULL, 10);
  printf("seed %" PRIu64 " (TT_SEED=%" PRIu64 " replays it)\n", seed, seed);
  uint64_t rng = seed;
  int cases = 0;
  for (int round = 0; cases < 600 && round < 5000; round++) {
    poly p;
    int n = 3 + (int)(tt_test_rand(&rng) % (MAXN - 2));
    double rmin = (round % 3 == 0) ? 30 : 4;
    if (!star_polygon(&rng, n, rmin, &p))
      continue;
    check_case(&p, true, seed, round);
    check_case(&p, false, seed, round);
    cases++;
  }
  printf("%d polygons checked\n", cases);
  CHECK(cases >= 600);

  /* the agreement of the diagonal rule with the independent one */
  rng = seed ^ 0x77;
  for (int round = 0; round < 300; round++) {
    poly p;
    if (!star_polygon(&rng, MAXN, 3, &p))
      continue;
    for (int i = 0; i < p.n; i++)
      for (int j = i + 2; j < p.n; j++) {
        if (i == 0 && j == p.n - 1)
          continue;
        bool a = tt__polygon_diagonal_ok(p.n, p.x, p.y, p.s, i, j);
        bool b = chord_inside(&p, i, j);
        if (a != b)
          TT_FAIL_("seed %" PRIu64 " round %d: diagonal (%d, %d): DP says "
                   "%d, the oracle %d", seed, round, i, j, a, b);
      }
  }
  TT_TEST_DONE();
}
