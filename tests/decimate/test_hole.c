/* test_hole.c -- the hole of one removed vertex, on hand-made stars:
 *  - no removal is ever skipped on stars made to be hard: reflex-heavy
 *    stars, collinear runs in the link, slivers of area 1/2 pixel over
 *    thousands of pixels; every hole rule fills them, the removal leaves
 *    a valid mesh with two triangles fewer, and re-inserting the vertex
 *    leaves a valid mesh again;
 *  - dp holes are optimal: compared with the best of every triangulation
 *    of small random star-shaped polygons, enumerated, for each measure
 *    (max-min angle, min-max angle, least 3-D area); again on ground
 *    points (the frame bent by a conformal map, as a geographic DEM's),
 *    measured on them;
 *  - each importance against a direct computation by hand;
 *  - a vertex on a straight border run may go, a corner may not. */
#include "decimate/decimate.h"
#include "terratin/terratin.h"
#include "tt_test.h"

#include <stdbool.h>

#define SIDE 2049
#define MID 1024

static tt_context *ctx;
static tt_grid *grid; /* SIDE x SIDE, heights given per test */

/* A decimation state over a star: centre vertex 0 at (MID, MID) and the
 * link ring[0..n) around it, counter-clockwise in the ground frame (north
 * up: ground y = -row; the caller gives the ring in increasing ground
 * angle). */
static void star_init(tt__dec *d, tt_decimate_options *o, const int64_t *x,
                      const int64_t *y, int n, bool closed)
{
  memset(d, 0, sizeof *d);
  d->ctx = ctx;
  d->g = grid;
  d->opt = o;
  d->crit = tt__criterion_get(o->criterion);
  d->importance = o->importance;
  d->hole = o->hole;
  d->max_error = -1;
  tt__metric metric;
  tt__metric_from_frame(grid->frame, &metric);
  tt__mesh_init(&d->m, &metric);
  if (tt_grid_ground_xy(grid))
    tt__mesh_use_ground_points(&d->m, tt_grid_ground_xy(grid), SIDE);
  d->env.mesh = &d->m;
  d->env.grid = grid;
  tt__dhole_init(&d->h);
  float *z = grid->z;
  tt__mesh_add_vertex(&d->m, MID, MID, z[(size_t)MID * SIDE + MID]);
  for (int i = 0; i < n; i++)
    tt__mesh_add_vertex(&d->m, (int32_t)x[i], (int32_t)y[i],
                        z[(size_t)y[i] * SIDE + (size_t)x[i]]);
  for (int i = 0; i + 1 < n || (closed && i < n); i++) {
    int32_t a = 1 + i, b = 1 + (i + 1) % n;
    CHECK(tt__mesh_orient(&d->m, 0, a, b) > 0);
    tt__mesh_add_triangle(&d->m, 0, a, b);
  }
  tt__mesh_link_all(&d->m);
  d->vflag = calloc((size_t)n + 1, 1);
  char why[200];
  CHECK(tt__mesh_validate(&d->m, why, sizeof why));
}

static void star_free(tt__dec *d)
{
  tt__mesh_free(&d->m);
  tt__dhole_free(&d->h);
  free(d->vflag);
}

/* Points at increasing ground angle around the centre. */
static int by_angle(const void *a, const void *b)
{
  const int64_t *p = a, *q = b;
  double u = atan2(-(double)(p[1] - MID), (double)(p[0] - MID));
  double v = atan2(-(double)(q[1] - MID), (double)(q[0] - MID));
  return (u > v) - (u < v);
}

/* Fills, removes the centre, validates, puts it back (a fan over the
 * same ring), validates again. */
static void remove_and_back(const int64_t *x, const int64_t *y, int n,
                            const char *what)
{
  static const tt_hole rules[] = {TT_HOLE_MINANGLE, TT_HOLE_CIRCUMRADIUS,
                                  TT_HOLE_DP};
  for (int ri = 0; ri < 3; ri++) {
    tt_decimate_options o;
    tt_decimate_options_init(&o);
    o.importance = TT_IMPORTANCE_ERROR;
    o.hole = rules[ri];
    o.criterion = ri == 2 ? TT_CRITERION_MINMAX_ANGLE : TT_CRITERION_DELAUNAY;
    tt__dec d;
    star_init(&d, &o, x, y, n, true);
    double imp, err;
    int ok = tt__dec_evaluate(&d, 0, TT__DEC_CHECK, &imp, &err);
    if (ok != 1) {
      TT_FAIL_("%s (%d vertices), hole %s: removal refused", what, n,
               tt_hole_name(rules[ri]));
      star_free(&d);
      continue;
    }
    CHECK_INT_EQ(d.h.ntri, n - 2);
    size_t before = d.m.nlive;
    CHECK(tt__mesh_remove_vertex(&d.m, 0, (const int32_t(*)[3])d.h.tri,
                                 d.h.ntri));
    char why[200];
    if (!tt__mesh_validate(&d.m, why, sizeof why))
      TT_FAIL_("%s, hole %s: %s", what, tt_hole_name(rules[ri]), why);
    CHECK_INT_EQ(d.m.nlive + 2, before);
    CHECK_INT_EQ(d.m.v[0].edge, -1);
    /* and back: locate the centre in the fill, split, flip to Delaunay */
    int32_t on = 0;
    int32_t t = tt__mesh_locate(&d.m, -1, MID, MID, &on);
    CHECK(t >= 0);
    if (t >= 0) {
      int32_t opp[4];
      bool split = on == -1 ? tt__mesh_split_triangle(&d.m, t, 0, opp)
                            : tt__mesh_split_edge(&d.m, on, 0, opp);
      CHECK(split);
      if (!tt__mesh_validate(&d.m, why, sizeof why))
        TT_FAIL_("%s, re-inserted: %s", what, why);
    }
    star_free(&d);
  }
}

static void test_hard_stars(void)
{
  uint64_t rng = 12345;
  int64_t p[512][2], x[512], y[512];
  int tested[4] = {0, 0, 0, 0};
  for (int trial = 0; trial < 300; trial++) {
    int n = 3 + (int)(tt_test_uniform(&rng) * (trial < 200 ? 14 : 120));
    int kind = trial % 4; /* 0 random, 1 reflex-heavy, 2 collinear, 3 sliver */
    int m = 0;
    for (int tries = 0; m < n && tries < 100000; tries++) {
      double ang = 2 * 3.14159265358979 * (double)m / n +
                   (tt_test_uniform(&rng) - 0.5) * (3.0 / n);
      double rad = kind == 1 ? (m % 2 ? 1000.0 : 2.0 + 6 * tt_test_uniform(&rng))
                             : 20 + 1000 * tt_test_uniform(&rng);
      p[m][0] = MID + (int64_t)llround(rad * cos(ang));
      p[m][1] = MID - (int64_t)llround(rad * sin(ang));
      if (p[m][0] == MID && p[m][1] == MID)
        continue;
      bool dup = false;
      for (int k = 0; k < m; k++)
        dup |= p[k][0] == p[m][0] && p[k][1] == p[m][1];
      if (!dup)
        m++;
    }
    if (kind == 2) {
      /* a collinear run: the link's right side is the column MID + 300 */
      int k = 0;
      for (int j = 0; j < m; j++)
        if (p[j][0] - MID <= llabs(p[j][1] - MID) ||
            p[j][0] - MID < 300) {
          p[k][0] = p[j][0];
          p[k][1] = p[j][1];
          if (p[k][0] - MID < 300 || p[k][0] - MID <= llabs(p[k][1] - MID))
            k++;
        }
      for (int t = -6; t <= 6; t++, k++) {
        p[k][0] = MID + 300;
        p[k][1] = MID + 40 * t;
      }
      m = k;
    }
    if (kind == 3 && m >= 4) {
      /* slivers: two link vertices a pixel apart far out, another nearly
       * collinear with them */
      p[0][0] = MID + 1000; p[0][1] = MID;
      p[1][0] = MID + 1000; p[1][1] = MID - 1;
      p[2][0] = MID + 999;  p[2][1] = MID - 3;
      p[3][0] = MID - 1000; p[3][1] = MID + 1;
    }
    qsort(p, (size_t)m, sizeof p[0], by_angle);
    int w = 0;
    for (int k = 0; k < m; k++)
      if (w == 0 || p[k][0] != x[w - 1] || p[k][1] != y[w - 1]) {
        x[w] = p[k][0];
        y[w] = p[k][1];
        w++;
      }
    /* keep the star valid: every fan triangle strictly turning */
    bool fan = w >= 3;
    for (int k = 0; k < w && fan; k++) {
      int k1 = (k + 1) % w;
      double cr = (double)(x[k] - MID) * (double)(-(y[k1] - MID)) -
                  (double)(-(y[k] - MID)) * (double)(x[k1] - MID);
      fan = cr > 0;
      for (int j = 0; j < k && fan; j++)
        fan = !(x[j] == x[k] && y[j] == y[k]);
    }
    if (!fan)
      continue;
    char what[64];
    snprintf(what, sizeof what, "star %d (kind %d)", trial, kind);
    remove_and_back(x, y, w, what);
    tested[kind]++;
  }
  for (int k = 0; k < 4; k++)
    if (tested[k] < 40)
      TT_FAIL_("only %d stars of kind %d", tested[k], k);
}

/* The measure of triangle (a, b, c) of mesh vertices, computed here from
 * scratch: mode 0 its smallest angle, 1 its largest, 2 its 3-D area (the
 * ground frame is (c, -r): angles and areas as in pixel space). */
/* Plan coordinates of mesh vertex v: its ground point when the mesh has
 * them, else (c, r) (mirrored, which changes no angle or area). */
static void plan_xy(const tt__mesh *m, int32_t v, double *x, double *y)
{
  *x = m->v[v].c;
  *y = m->v[v].r;
  if (m->gxy) {
    const double *q = m->gxy + 2 * ((size_t)m->v[v].r * m->gnx +
                                    (size_t)m->v[v].c);
    *x = q[0];
    *y = q[1];
  }
}

static double tri_measure(const tt__mesh *m, const int32_t c[3], int mode)
{
  double px[3], py[3];
  for (int k = 0; k < 3; k++)
    plan_xy(m, c[k], &px[k], &py[k]);
  if (mode == 2) {
    double ux = px[1] - px[0], uy = py[1] - py[0];
    double vx = px[2] - px[0], vy = py[2] - py[0];
    double uz = (double)m->v[c[1]].z - m->v[c[0]].z;
    double vz = (double)m->v[c[2]].z - m->v[c[0]].z;
    double nx = uy * vz - uz * vy, ny = uz * vx - ux * vz,
           nz = ux * vy - uy * vx;
    return 0.5 * sqrt(nx * nx + ny * ny + nz * nz);
  }
  double a[3];
  for (int e = 0; e < 3; e++) {
    int p = e, q = (e + 1) % 3, r = (e + 2) % 3;
    double ux = px[q] - px[p], uy = py[q] - py[p], vx = px[r] - px[p],
           vy = py[r] - py[p];
    a[e] = atan2(fabs(ux * vy - uy * vx), ux * vx + uy * vy);
  }
  return mode == 0 ? fmin(a[0], fmin(a[1], a[2]))
                   : fmax(a[0], fmax(a[1], a[2]));
}

/* Combines a value with a part's: mode 0 keeps the smallest (maximised
 * overall), 1 the largest (minimised), 2 sums (minimised). */
static double combine(int mode, double x, double y)
{
  return mode == 0 ? fmin(x, y) : mode == 1 ? fmax(x, y) : x + y;
}

static bool better(int mode, double x, double y)
{
  return mode == 0 ? x > y : x < y;
}

/* The best value over every triangulation of polygon[i..j] closed by
 * (i, j), by enumeration of the apex of (i, j) and recursion. */
static double enum_best(const tt__dhole *h, const tt__mesh *m, int i, int j,
                        int mode)
{
  double none = mode == 0 ? INFINITY : mode == 1 ? -INFINITY : 0;
  if (j - i < 2)
    return none;
  double best = mode == 0 ? -INFINITY : INFINITY;
  for (int k = i + 1; k < j; k++) {
    if (tt__mesh_orient(m, h->p[i], h->p[k], h->p[j]) <= 0)
      continue;
    /* the triangle must be inside: no other vertex in it */
    bool inside = true;
    for (int q = 0; q < h->n && inside; q++) {
      if (q == i || q == j || q == k)
        continue;
      inside = !(tt__mesh_orient(m, h->p[i], h->p[k], h->p[q]) >= 0 &&
                 tt__mesh_orient(m, h->p[k], h->p[j], h->p[q]) >= 0 &&
                 tt__mesh_orient(m, h->p[j], h->p[i], h->p[q]) >= 0);
    }
    if (!inside)
      continue;
    int32_t c[3] = {h->p[i], h->p[k], h->p[j]};
    double l = enum_best(h, m, i, k, mode), r = enum_best(h, m, k, j, mode);
    if (isinf(l) && l == (mode == 0 ? -INFINITY : INFINITY))
      continue; /* that side has no triangulation */
    if (isinf(r) && r == (mode == 0 ? -INFINITY : INFINITY))
      continue;
    double v = combine(mode, tri_measure(m, c, mode), combine(mode, l, r));
    if (better(mode, v, best))
      best = v;
  }
  return best;
}

static double fill_value(const tt__dec *d, int mode)
{
  double v = mode == 0 ? INFINITY : mode == 1 ? -INFINITY : 0;
  for (int t = 0; t < d->h.ntri; t++)
    v = combine(mode, v, tri_measure(&d->m, d->h.tri[t], mode));
  return v;
}

static void test_dp_optimal(void)
{
  uint64_t rng = 99;
  int checked = 0;
  for (int trial = 0; trial < 400; trial++) {
    int n = 4 + (int)(tt_test_uniform(&rng) * 6); /* 4..9 */
    int64_t p[16][2], x[16], y[16];
    for (int k = 0; k < n; k++) {
      double ang = 2 * 3.14159265358979 * (k + 0.8 * tt_test_uniform(&rng)) / n;
      double rad = 5 + 60 * tt_test_uniform(&rng);
      p[k][0] = MID + (int64_t)llround(rad * cos(ang));
      p[k][1] = MID - (int64_t)llround(rad * sin(ang));
    }
    qsort(p, (size_t)n, sizeof p[0], by_angle);
    bool fan = true;
    for (int k = 0; k < n; k++) {
      x[k] = p[k][0];
      y[k] = p[k][1];
    }
    for (int k = 0; k < n && fan; k++) {
      int k1 = (k + 1) % n;
      double cr = (double)(x[k] - MID) * (double)(-(y[k1] - MID)) -
                  (double)(-(y[k] - MID)) * (double)(x[k1] - MID);
      fan = cr > 0;
    }
    if (!fan)
      continue;
    static const tt_criterion crits[3] = {TT_CRITERION_DELAUNAY,
                                          TT_CRITERION_MINMAX_ANGLE,
                                          TT_CRITERION_MIN_AREA};
    for (int mode = 0; mode < 3; mode++) {
      tt_decimate_options o;
      tt_decimate_options_init(&o);
      o.hole = TT_HOLE_DP;
      o.criterion = crits[mode];
      o.importance = TT_IMPORTANCE_DROP;
      tt__dec d;
      star_init(&d, &o, x, y, n, true);
      double imp;
      if (tt__dec_evaluate(&d, 0, TT__DEC_FILL, &imp, NULL) != 1) {
        TT_FAIL_("dp trial %d (%s): no fill", trial,
                 tt_criterion_name(crits[mode]));
        star_free(&d);
        continue;
      }
      double got = fill_value(&d, mode);
      double best = enum_best(&d.h, &d.m, 0, n - 1, mode);
      CHECK_DBL_NEAR(got, best, 1e-9 * (1 + fabs(best)));
      /* ear cutting never beats the optimum */
      d.hole = TT_HOLE_MINANGLE;
      (void)tt__dec_evaluate(&d, 0, TT__DEC_FILL, &imp, NULL);
      double ear = fill_value(&d, mode);
      CHECK(!better(mode, ear, best + (mode == 0 ? 1e-12 : -1e-12) *
                                          (1 + fabs(best))));
      star_free(&d);
    }
    checked++;
  }
  CHECK(checked > 100);
}

/* A square star: centre (MID, MID) at height 10, four neighbours at
 * distance 10 on the axes with heights 1, 2, 3, 14; samples between hold
 * the plane of each fan triangle, so each importance has a value by hand. */
static void test_importances(void)
{
  float *z = grid->z;
  int64_t x[4] = {MID + 10, MID, MID - 10, MID};
  int64_t y[4] = {MID, MID - 10, MID, MID + 10};
  double hz[4] = {1, 2, 3, 14}, zc = 10;
  /* the star surface: fan triangles (centre, p_i, p_i+1) */
  for (int64_t r = MID - 10; r <= MID + 10; r++)
    for (int64_t c = MID - 10; c <= MID + 10; c++) {
      double u = (double)(c - MID) / 10, v = -(double)(r - MID) / 10;
      if (fabs(u) + fabs(v) > 1)
        continue;
      /* quadrant: u >= 0, v >= 0 -> p0, p1; etc. */
      int q = u >= 0 ? (v >= 0 ? 0 : 3) : (v >= 0 ? 1 : 2);
      double a = fabs(u), b = fabs(v);
      double za = hz[q], zb = hz[(q + 1) % 4];
      if (q == 1 || q == 3) {
        /* p1 is on +v, p2 on -u: the first of the pair is on v */
        double t = a;
        a = b;
        b = t;
      }
      z[r * SIDE + c] = (float)(zc + a * (za - zc) + b * (zb - zc));
    }
  static const tt_importance imps[] = {
      TT_IMPORTANCE_DEGREE, TT_IMPORTANCE_HDH,  TT_IMPORTANCE_ABH,
      TT_IMPORTANCE_VOLUME, TT_IMPORTANCE_DROP, TT_IMPORTANCE_ERROR};
  for (int k = 0; k < 6; k++) {
    tt_decimate_options o;
    tt_decimate_options_init(&o);
    o.importance = imps[k];
    o.hole = TT_HOLE_MINANGLE;
    tt__dec d;
    star_init(&d, &o, x, y, 4, true);
    double imp, err;
    CHECK_INT_EQ(tt__dec_evaluate(&d, 0, TT__DEC_SCORE, &imp, &err), 1);
    /* the fill of a square: one diagonal, p1-p3 (the v axis; mesh
     * vertices 2 and 4) or p0-p2 (the u axis); the expected values below
     * follow the one taken */
    bool vdiag = false;
    if (imps[k] >= TT_IMPORTANCE_VOLUME)
      for (int t = 0; t < d.h.ntri; t++) {
        int has = 0;
        for (int e = 0; e < 3; e++)
          has += d.h.tri[t][e] == 2 || d.h.tri[t][e] == 4;
        vdiag |= has == 2;
      }
    /* the diagonal's ends (a, b) and the two other corners (c one side,
     * e the other), heights */
    double da = vdiag ? hz[1] : hz[0], db = vdiag ? hz[3] : hz[2];
    double expect = 0;
    switch (imps[k]) {
    case TT_IMPORTANCE_DEGREE:
      expect = 4;
      break;
    case TT_IMPORTANCE_HDH:
      expect = fabs(4 * zc - (1 + 2 + 3 + 14));
      break;
    case TT_IMPORTANCE_ABH:
      expect = 2; /* three below, one above */
      break;
    case TT_IMPORTANCE_VOLUME: {
      /* star: 4 triangles of area 50; hole: 2 of area 100 */
      double star = 50 * ((zc + 1 + 2) + (zc + 2 + 3) + (zc + 3 + 14) +
                          (zc + 14 + 1)) / 3;
      double hole = 100 * ((da + db + (vdiag ? hz[0] : hz[1])) +
                           (da + db + (vdiag ? hz[2] : hz[3]))) / 3.0;
      expect = fabs(star - hole);
      break;
    }
    case TT_IMPORTANCE_DROP:
      expect = fabs(zc - (da + db) / 2.0);
      break;
    default: {
      /* brute force over the samples of the square against the fill */
      double mx = 0;
      for (int64_t r = MID - 10; r <= MID + 10; r++)
        for (int64_t c = MID - 10; c <= MID + 10; c++) {
          double u = (double)(c - MID) / 10, v = -(double)(r - MID) / 10;
          if (fabs(u) + fabs(v) > 1)
            continue;
          /* the fill: the plane of the half the sample is in */
          double zf;
          if (vdiag) /* p1 (0,1), p3 (0,-1); p0 (1,0) right, p2 left */
            zf = (da + db) / 2 + fabs(u) * ((u >= 0 ? hz[0] : hz[2]) -
                                            (da + db) / 2) +
                 v * (da - db) / 2;
          else       /* p0 (1,0), p2 (-1,0); p1 (0,1) up, p3 down */
            zf = (da + db) / 2 + fabs(v) * ((v >= 0 ? hz[1] : hz[3]) -
                                            (da + db) / 2) +
                 u * (da - db) / 2;
          mx = fmax(mx, fabs(z[r * SIDE + c] - zf));
        }
      expect = mx;
    }
    }
    CHECK_DBL_NEAR(imp, expect, 1e-4 * (1 + expect));
    star_free(&d);
  }
}

/* Boundary: a vertex in the middle of the border's straight run may go,
 * and after it the border is still straight; a corner never. */
static void test_boundary(void)
{
  tt_decimate_options o;
  tt_decimate_options_init(&o);
  o.importance = TT_IMPORTANCE_DROP;
  o.hole = TT_HOLE_MINANGLE;
  /* open star around (MID, MID) on a straight run along row MID: ring
   * from (MID+50, MID) over the half-plane above (ground y up) to
   * (MID-50, MID) */
  int64_t x[5] = {MID + 50, MID + 30, MID, MID - 30, MID - 50};
  int64_t y[5] = {MID, MID - 40, MID - 45, MID - 40, MID};
  tt__dec d;
  star_init(&d, &o, x, y, 5, false);
  double imp;
  CHECK_INT_EQ(tt__dec_evaluate(&d, 0, TT__DEC_FILL, &imp, NULL), 1);
  CHECK_INT_EQ(d.h.ntri, 3);
  CHECK(tt__mesh_remove_vertex(&d.m, 0, (const int32_t(*)[3])d.h.tri,
                               d.h.ntri));
  char why[200];
  CHECK(tt__mesh_validate(&d.m, why, sizeof why));
  CHECK_INT_EQ(d.m.nlive, 3);
  star_free(&d);
  /* bent: the centre is a corner of the outline */
  y[0] = MID + 1;
  star_init(&d, &o, x, y, 5, false);
  CHECK_INT_EQ(tt__dec_evaluate(&d, 0, TT__DEC_FILL, &imp, NULL), 0);
  star_free(&d);
}

int main(void)
{
  ctx = tt_context_create();
  CHECK_OK(ctx, tt_grid_create(ctx, SIDE, SIDE, &grid));
  /* north up: ground y = -row, the frame's orientation mirrored */
  const double gt[6] = {0, 1, 0, 0, 0, -1};
  CHECK_OK(ctx, tt_grid_set_geotransform(ctx, grid, gt));
  float *z = tt_grid_heights(grid);
  uint64_t rng = 5;
  for (size_t i = 0; i < (size_t)SIDE * SIDE; i++)
    z[i] = (float)(100 * tt_test_uniform(&rng));
  TT_RUN(test_hard_stars());
  TT_RUN(test_dp_optimal());
  /* again on ground points: (c - MID, MID - r) through p + alpha p^2
   * (complex), 0.6 % of bend over a star's 65 pixels */
  CHECK_OK(ctx, tt_grid_alloc_ground_points(ctx, grid));
  double *xy = tt_grid_ground_xy(grid);
  for (size_t r = 0; xy && r < SIDE; r++)
    for (size_t c = 0; c < SIDE; c++) {
      double x = (double)c - MID, y = (double)MID - (double)r, al = 0.003 / 65;
      xy[2 * (r * SIDE + c)] = x + al * (x * x - y * y);
      xy[2 * (r * SIDE + c) + 1] = y + al * 2 * x * y;
    }
  if (xy)
    test_dp_optimal();
  tt_grid_drop_ground_points(grid);
  TT_RUN(test_boundary());
  TT_RUN(test_importances());
  tt_grid_destroy(grid);
  tt_context_destroy(ctx);
  TT_TEST_DONE();
}
