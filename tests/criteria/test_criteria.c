/* test_criteria.c -- the criteria of SPEC section 2 beside Delaunay.
 *
 *  - hand-built quads whose better diagonal is known, with the swap value's
 *    sign and size against formulas worked out here;
 *  - random meshes over grids with random heights in several ground frames:
 *    the swap value of every flippable edge equals the change of the whole
 *    triangulation's quality, scored from scratch by code in this file
 *    (areas, sum |e| alpha, sorted alpha vector, sum |K| with a brute-force
 *    convex hull, L2 over all samples, sorted angle vector);
 *  - the swap back has exactly the opposite value;
 *  - the affected-edges hook covers every edge whose swap value changed
 *    after a flip;
 *  - Gaussian curvature: the vertex classes on hand-made stars, and on a
 *    paraboloid the Delaunay (convex) triangulation is tight;
 *  - names round-trip through the registry; per-criterion timings printed.
 * Seeded; the seed is printed on failure. */
#include "criteria/geometry.h"
#include "mesh/mesh.h"
#include "base/predicates.h"
#include "mesh/raster_scan.h"
#include "optimize/swap.h"
#include "tt_test.h"

#define PI 3.14159265358979323846

static const tt_criterion ALL[] = {
    TT_CRITERION_MINMAX_ANGLE, TT_CRITERION_MINMAX_ANGLE_LEX,
    TT_CRITERION_MIN_AREA,     TT_CRITERION_MEAN_CURVATURE,
    TT_CRITERION_GAUSSIAN_CURVATURE, TT_CRITERION_ABN,
    TT_CRITERION_ABN_SUM,      TT_CRITERION_ABN_SUMSQ,
    TT_CRITERION_L2};
#define NALL (sizeof ALL / sizeof ALL[0])

/* ---------------------------------------------------------------------
 * Independent ground-frame geometry (not geometry.h's).
 * ------------------------------------------------------------------- */
typedef struct P3 {
  double x, y, z;
} P3;

/* A vertex on the ground: through the frame, or at its ground point when
 * the mesh has them (mesh.h). */
static P3 gp(const tt__mesh *m, const double a[4], int32_t v)
{
  double c = m->v[v].c, r = m->v[v].r;
  P3 p = {a[0] * c + a[1] * r, a[2] * c + a[3] * r, (double)m->v[v].z};
  if (m->gxy) {
    const double *q = m->gxy + 2 * ((size_t)m->v[v].r * m->gnx +
                                    (size_t)m->v[v].c);
    p.x = q[0];
    p.y = q[1];
  }
  return p;
}
static P3 sub(P3 p, P3 q)
{
  P3 d = {p.x - q.x, p.y - q.y, p.z - q.z};
  return d;
}
static P3 cross(P3 u, P3 v)
{
  P3 w = {u.y * v.z - u.z * v.y, u.z * v.x - u.x * v.z,
          u.x * v.y - u.y * v.x};
  return w;
}
static double dot(P3 u, P3 v) { return u.x * v.x + u.y * v.y + u.z * v.z; }
static double len(P3 u) { return sqrt(dot(u, u)); }
static double ang3(P3 u, P3 v) { return atan2(len(cross(u, v)), dot(u, v)); }
static double ang2(P3 u, P3 v)
{
  double c = (u.x * v.x + u.y * v.y) / (hypot(u.x, u.y) * hypot(v.x, v.y));
  return acos(c > 1 ? 1 : c < -1 ? -1 : c);
}

static int cmp_desc(const void *pa, const void *pb)
{
  double a = *(const double *)pa, b = *(const double *)pb;
  return a < b ? 1 : a > b ? -1 : 0;
}

/* first difference (before - after) beyond tol of two decreasing vectors */
static double lex_first(const double *b, const double *a, size_t n,
                        double tol)
{
  for (size_t i = 0; i < n; i++)
    if (fabs(b[i] - a[i]) > tol)
      return b[i] - a[i];
  return 0;
}

/* ---------------------------------------------------------------------
 * Whole-mesh scores from scratch.
 * ------------------------------------------------------------------- */
typedef struct scores {
  double area, meancurv, abn_sum, abn_sumsq, gauss, l2, maxang;
  double *angles;   /* all triangle angles, decreasing */
  size_t nang;
  double *alphas;   /* alpha of every interior edge, decreasing */
  size_t nalpha;
} scores;

static void scores_free(scores *s)
{
  free(s->angles);
  free(s->alphas);
}

/* |K(v)| from scratch: the star ordered by chaining its triangles, plain
 * double triple products, the hull cone by trying every ordered pair. */
static double oracle_gauss(const tt__mesh *m, const double a[4], int32_t v,
                           int *out_class)
{
  int32_t xs[512], ys[512];
  int nt = 0;
  for (size_t t = 0; t < m->nslots; t++) {
    if (!tt__mesh_live(m, (int32_t)t))
      continue;
    for (int k = 0; k < 3; k++)
      if (m->hv[3 * t + k] == v && nt < 512) {
        xs[nt] = m->hv[3 * t + (k + 1) % 3];
        ys[nt] = m->hv[3 * t + (k + 2) % 3];
        nt++;
      }
  }
  *out_class = -1;
  if (nt == 0)
    return 0;
  /* a start: a triangle whose x is nobody's y (boundary), else the first */
  int s0 = 0;
  bool boundary = false;
  for (int i = 0; i < nt && !boundary; i++) {
    bool found = false;
    for (int j = 0; j < nt; j++)
      found |= ys[j] == xs[i];
    if (!found) {
      s0 = i;
      boundary = true;
    }
  }
  int32_t ray[513];
  int n = 0, cur = s0;
  for (int step = 0; step < nt; step++) {
    ray[n++] = xs[cur];
    int nxt = -1;
    for (int j = 0; j < nt; j++)
      if (xs[j] == ys[cur])
        nxt = j;
    if (nxt < 0) {
      ray[n++] = ys[cur];
      break;
    }
    cur = nxt;
  }
  P3 pv = gp(m, a, v), e[513];
  for (int i = 0; i < n; i++)
    e[i] = sub(gp(m, a, ray[i]), pv);
  double sum = 0;
  for (int i = 0; i < (boundary ? n - 1 : n); i++)
    sum += ang3(e[i], e[(i + 1) % n]);
  if (boundary) {
    *out_class = TT__VERTEX_BOUNDARY;
    return fabs(PI - sum);
  }
  int support = 0, sgn = 0;
  for (int i = 0; i < n; i++) {
    P3 nn = cross(e[i], e[(i + 1) % n]);
    int pos = 0, neg = 0;
    for (int k = 0; k < n; k++) {
      if (k == i || k == (i + 1) % n)
        continue;
      double d = dot(nn, e[k]);
      pos |= d > 0;
      neg |= d < 0;
    }
    if (!(pos && neg)) {
      support++;
      if (!sgn)
        sgn = pos ? 1 : neg ? -1 : 0;
    }
  }
  if (support == n) {
    *out_class = TT__VERTEX_CONVEX;
    return 2 * PI - sum;
  }
  if (support == 0) {
    *out_class = TT__VERTEX_SADDLE;
    return sum - 2 * PI;
  }
  *out_class = TT__VERTEX_MIXED;
  double hull = 0;
  for (int p = 0; p < n; p++)
    for (int q = 0; q < n; q++) {
      if (p == q)
        continue;
      P3 nn = cross(e[p], e[q]);
      bool ok = true;
      for (int r = 0; r < n && ok; r++)
        if (r != p && r != q)
          ok = sgn * dot(nn, e[r]) > 0;
      if (ok)
        hull += ang3(e[p], e[q]);
    }
  return 2 * PI - 2 * hull + sum;
}

static void score(const tt__mesh *m, const tt_grid *g, const double a[4],
                  scores *s)
{
  memset(s, 0, sizeof *s);
  s->angles = malloc(3 * m->nslots * sizeof(double) + 8);
  s->alphas = malloc(3 * m->nslots * sizeof(double) + 8);
  for (size_t t = 0; t < m->nslots; t++) {
    if (!tt__mesh_live(m, (int32_t)t))
      continue;
    P3 p[3];
    for (int k = 0; k < 3; k++)
      p[k] = gp(m, a, m->hv[3 * t + k]);
    s->area += 0.5 * len(cross(sub(p[1], p[0]), sub(p[2], p[0])));
    for (int k = 0; k < 3; k++) {
      double an = ang2(sub(p[(k + 1) % 3], p[k]), sub(p[(k + 2) % 3], p[k]));
      s->angles[s->nang++] = an;
      if (an > s->maxang)
        s->maxang = an;
    }
    tt__scan_tri st;
    tt__scan_stats ss;
    tt__scan_tri_from_mesh(m, (int32_t)t, &st);
    tt__scan_stats_run(g, &st, &ss);
    s->l2 += ss.sum_sq;
  }
  for (size_t e = 0; e < 3 * m->nslots; e++) {
    if (!tt__mesh_live(m, (int32_t)(e / 3)) || m->twin[e] < (int32_t)e)
      continue;
    int32_t f = m->twin[e];
    P3 n[2];
    int32_t hs[2] = {(int32_t)e, f};
    for (int i = 0; i < 2; i++) {
      int32_t t0 = hs[i] - hs[i] % 3;
      P3 p0 = gp(m, a, m->hv[t0]), p1 = gp(m, a, m->hv[t0 + 1]),
         p2 = gp(m, a, m->hv[t0 + 2]);
      n[i] = cross(sub(p1, p0), sub(p2, p0));
    }
    double al = ang3(n[0], n[1]);
    double l = len(sub(gp(m, a, m->hv[f]), gp(m, a, m->hv[e])));
    s->meancurv += l * al;
    s->abn_sum += al;
    s->abn_sumsq += al * al;
    s->alphas[s->nalpha++] = al;
  }
  for (size_t v = 0; v < m->nv; v++) {
    int cls;
    s->gauss += oracle_gauss(m, a, (int32_t)v, &cls);
  }
  qsort(s->angles, s->nang, sizeof(double), cmp_desc);
  qsort(s->alphas, s->nalpha, sizeof(double), cmp_desc);
}

/* ---------------------------------------------------------------------
 * Meshes.
 * ------------------------------------------------------------------- */
static void add_tri_ccw(tt__mesh *m, int32_t a, int32_t b, int32_t c)
{
  if (tt__mesh_orient(m, a, b, c) > 0)
    tt__mesh_add_triangle(m, a, b, c);
  else
    tt__mesh_add_triangle(m, a, c, b);
}

static tt_grid *make_grid(tt_context *ctx, int nx, int ny, const double a[4])
{
  tt_grid *g = NULL;
  CHECK_OK(ctx, tt_grid_create(ctx, (size_t)nx, (size_t)ny, &g));
  if (!g)
    return NULL;
  double gt[6] = {0, a[0], a[1], 0, a[2], a[3]};
  CHECK_OK(ctx, tt_grid_set_geotransform(ctx, g, gt));
  return g;
}

static float gz(const tt_grid *g, int c, int r)
{
  return tt_grid_heights_const(g)[(size_t)r * g->nx + (size_t)c];
}

/* A random mesh over grid g: its corners, npts random samples inserted by
 * splits, some Delaunay repairs and random flips. */
static bool random_mesh(tt__mesh *m, const tt_grid *g, uint64_t *rng,
                        int npts)
{
  tt__metric metric;
  tt__metric_from_frame(g->frame, &metric);
  tt__mesh_init(m, &metric);
  if (g->gxy)
    tt__mesh_use_ground_points(m, g->gxy, g->nx);
  int W = (int)g->nx - 1, H = (int)g->ny - 1;
  int32_t v0 = tt__mesh_add_vertex(m, 0, 0, gz(g, 0, 0));
  int32_t v1 = tt__mesh_add_vertex(m, W, 0, gz(g, W, 0));
  int32_t v2 = tt__mesh_add_vertex(m, W, H, gz(g, W, H));
  int32_t v3 = tt__mesh_add_vertex(m, 0, H, gz(g, 0, H));
  add_tri_ccw(m, v0, v1, v2);
  add_tri_ccw(m, v0, v2, v3);
  tt__mesh_link_all(m);
  unsigned char *used = calloc((size_t)(W + 1) * (size_t)(H + 1), 1);
  used[0] = used[W] = used[(size_t)H * (W + 1)] =
      used[(size_t)H * (W + 1) + W] = 1;
  tt__edge_stack stack = {0};
  tt__crit_env env = {m, g, NULL};
  for (int i = 0; i < npts * 4 && (int)m->nv < npts + 4; i++) {
    int c = (int)(tt_test_rand(rng) % (uint64_t)(W + 1));
    int r = (int)(tt_test_rand(rng) % (uint64_t)(H + 1));
    if (used[(size_t)r * (W + 1) + c])
      continue;
    int32_t on, opp[4];
    int32_t t = tt__mesh_locate(m, -1, c, r, &on);
    if (t < 0 || on <= -2)
      continue;
    used[(size_t)r * (W + 1) + c] = 1;
    int32_t v = tt__mesh_add_vertex(m, c, r, gz(g, c, r));
    int nopp = 3;
    if (on < 0)
      tt__mesh_split_triangle(m, t, v, opp);
    else {
      tt__mesh_split_edge(m, on, v, opp);
      nopp = 4;
    }
    if (tt_test_rand(rng) % 2)
      tt__swap_repair(m, &tt__criterion_delaunay, &env, opp, nopp, &stack);
  }
  for (int i = 0; i < 30; i++) {
    int32_t e = (int32_t)(tt_test_rand(rng) % (3 * m->nslots));
    if (tt__mesh_live(m, e / 3) && tt__mesh_flippable(m, e))
      tt__mesh_flip(m, e);
  }
  tt__edge_stack_free(&stack);
  free(used);
  char why[256];
  if (!tt__mesh_validate(m, why, sizeof why)) {
    TT_FAIL_("random mesh invalid: %s", why);
    return false;
  }
  return true;
}

/* Interior edges as vertex pairs (u < w). */
static size_t edge_pairs(const tt__mesh *m, int32_t *u, int32_t *w)
{
  size_t n = 0;
  for (size_t e = 0; e < 3 * m->nslots; e++) {
    if (!tt__mesh_live(m, (int32_t)(e / 3)) || m->twin[e] < 0)
      continue;
    int32_t a = m->hv[e], b = m->hv[m->twin[e]];
    if (a < b) {
      u[n] = a;
      w[n] = b;
      n++;
    }
  }
  return n;
}

/* ---------------------------------------------------------------------
 * Swap value vs. whole-mesh scores; the affected hook.
 * ------------------------------------------------------------------- */
static double global_change(tt_criterion id, const scores *b, const scores *a,
                            bool *exact)
{
  *exact = true;
  switch (id) {
  case TT_CRITERION_MIN_AREA: return b->area - a->area;
  case TT_CRITERION_MEAN_CURVATURE: return b->meancurv - a->meancurv;
  case TT_CRITERION_GAUSSIAN_CURVATURE: return b->gauss - a->gauss;
  case TT_CRITERION_ABN_SUM: return b->abn_sum - a->abn_sum;
  case TT_CRITERION_ABN_SUMSQ: return b->abn_sumsq - a->abn_sumsq;
  case TT_CRITERION_L2: return b->l2 - a->l2;
  case TT_CRITERION_ABN:
    *exact = false;
    return lex_first(b->alphas, a->alphas, b->nalpha, 1e-13);
  case TT_CRITERION_MINMAX_ANGLE_LEX:
    *exact = false;
    return lex_first(b->angles, a->angles, b->nang, 1e-13);
  default:
    *exact = false;
    return b->maxang - a->maxang;
  }
}

static double scale_of(tt_criterion id, const scores *s)
{
  switch (id) {
  case TT_CRITERION_MIN_AREA: return s->area;
  case TT_CRITERION_MEAN_CURVATURE: return s->meancurv;
  case TT_CRITERION_GAUSSIAN_CURVATURE: return s->gauss + 10;
  case TT_CRITERION_ABN_SUM: return s->abn_sum;
  case TT_CRITERION_ABN_SUMSQ: return s->abn_sumsq;
  case TT_CRITERION_L2: return s->l2 + 1;
  default: return 1;
  }
}

/* The six angles (or the largest) of the quad's two triangles, from the
 * mesh as it is: the local size of the Min-Max angle values. */
static void quad_angles(const tt__mesh *m, const double a[4], int32_t e,
                        double out[6])
{
  int32_t ts[2] = {e - e % 3, m->twin[e] - m->twin[e] % 3};
  for (int i = 0; i < 2; i++) {
    P3 p[3];
    for (int k = 0; k < 3; k++)
      p[k] = gp(m, a, m->hv[ts[i] + k]);
    for (int k = 0; k < 3; k++)
      out[3 * i + k] =
          ang2(sub(p[(k + 1) % 3], p[k]), sub(p[(k + 2) % 3], p[k]));
  }
  qsort(out, 6, sizeof(double), cmp_desc);
}

static void check_values(tt__mesh *m, const tt_grid *g, uint64_t seed)
{
  const double *a = g->frame;
  tt__crit_env env = {m, g, NULL};
  size_t cap = 3 * m->nslots;
  int32_t *u = malloc(cap * sizeof *u), *w = malloc(cap * sizeof *w);
  size_t ne = edge_pairs(m, u, w);
  scores s0;
  score(m, g, a, &s0);
  for (size_t ci = 0; ci < NALL; ci++) {
    const tt__criterion_vt *vt = tt__criterion_get(ALL[ci]);
    for (size_t i = 0; i < ne; i++) {
      int32_t e = tt__mesh_find_edge(m, u[i], w[i]);
      double val = vt->swap_value(&env, e);
      CHECK(isfinite(val));
      if (!tt__mesh_flippable(m, e)) {
        if (val != 0)
          TT_FAIL_("seed %#llx %s: non-convex quad scored %g",
                   (unsigned long long)seed, vt->name, val);
        continue;
      }
      double loc_b[6], loc_a[6];
      quad_angles(m, a, e, loc_b);
      int32_t h = tt__mesh_flip(m, e);
      scores s1;
      score(m, g, a, &s1);
      quad_angles(m, a, h, loc_a);
      double back = vt->swap_value(&env, h);
      bool exact;
      double dg = global_change(ALL[ci], &s0, &s1, &exact);
      double tol = 1e-9 * (scale_of(ALL[ci], &s0) + fabs(val));
      if (exact) {
        if (!(fabs(val - dg) <= tol))
          TT_FAIL_("seed %#llx %s edge %d-%d: swap value %.17g, whole mesh "
                   "%.17g", (unsigned long long)seed, vt->name, u[i], w[i],
                   val, dg);
      } else if (ALL[ci] == TT_CRITERION_MINMAX_ANGLE) {
        double loc = loc_b[0] - loc_a[0];
        if (!(fabs(val - loc) <= 1e-9))
          TT_FAIL_("seed %#llx minmax edge %d-%d: %.17g vs local %.17g",
                   (unsigned long long)seed, u[i], w[i], val, loc);
        if (val > 1e-9 && s1.maxang > s0.maxang + 1e-12)
          TT_FAIL_("seed %#llx minmax: a positive swap raised the max",
                   (unsigned long long)seed);
      } else {
        /* lexicographic: sign of the whole comparison */
        if ((fabs(val) > 1e-9 && (val > 0) != (dg > 0)) ||
            (val == 0 && fabs(dg) > 1e-9))
          TT_FAIL_("seed %#llx %s edge %d-%d: swap value %.17g, whole-mesh "
                   "lexicographic difference %.17g", (unsigned long long)seed,
                   vt->name, u[i], w[i], val, dg);
        if (ALL[ci] == TT_CRITERION_MINMAX_ANGLE_LEX) {
          double loc = lex_first(loc_b, loc_a, 6, 1e-12);
          if (!(fabs(val - loc) <= 1e-9))
            TT_FAIL_("seed %#llx minmax_lex edge %d-%d: %.17g vs local "
                     "%.17g", (unsigned long long)seed, u[i], w[i], val, loc);
        }
      }
      /* swapping back is the opposite move, exactly (geometry.h's
       * canonical quad), so an optimiser cannot cycle on rounding */
      if (back != -val)
        TT_FAIL_("seed %#llx %s edge %d-%d: value %.17g, back %.17g",
                 (unsigned long long)seed, vt->name, u[i], w[i], val, back);
      scores_free(&s1);
      tt__mesh_flip(m, h);
    }
  }
  scores_free(&s0);
  free(u);
  free(w);
}

/* Values of every interior edge, in the order of the pairs. */
static void all_values(const tt__mesh *m, const tt__criterion_vt *vt,
                       const tt__crit_env *env, const int32_t *u,
                       const int32_t *w, size_t n, double *out)
{
  for (size_t i = 0; i < n; i++) {
    int32_t e = tt__mesh_find_edge(m, u[i], w[i]);
    out[i] = e < 0 ? NAN : vt->swap_value(env, e);
  }
}

static void check_affected(tt__mesh *m, const tt_grid *g, uint64_t seed,
                           uint64_t *rng)
{
  tt__crit_env env = {m, g, NULL};
  size_t cap = 3 * m->nslots;
  int32_t *u = malloc(cap * sizeof *u), *w = malloc(cap * sizeof *w);
  double *vb = malloc(cap * sizeof *vb), *va = malloc(cap * sizeof *va);
  size_t ne = edge_pairs(m, u, w);
  for (size_t ci = 0; ci < NALL; ci++) {
    const tt__criterion_vt *vt = tt__criterion_get(ALL[ci]);
    for (int trial = 0; trial < 12; trial++) {
      size_t i = (size_t)(tt_test_rand(rng) % ne);
      int32_t e = tt__mesh_find_edge(m, u[i], w[i]);
      if (!tt__mesh_flippable(m, e))
        continue;
      all_values(m, vt, &env, u, w, ne, vb);
      int32_t h = tt__mesh_flip(m, e);
      int32_t out[1024];
      int nout;
      if (vt->affected) {
        nout = vt->affected(&env, h, out, 1024);
        CHECK(nout <= 1024);
      } else {
        int32_t gg = m->twin[h];
        out[0] = tt__next(h);
        out[1] = tt__prev(h);
        out[2] = tt__next(gg);
        out[3] = tt__prev(gg);
        nout = 4;
      }
      all_values(m, vt, &env, u, w, ne, va);
      for (size_t k = 0; k < ne; k++) {
        if (k == i || isnan(va[k]))
          continue;
        if (fabs(va[k] - vb[k]) <= 1e-10 * (1 + fabs(vb[k])))
          continue;
        bool listed = false;
        for (int j = 0; j < nout && !listed; j++) {
          int32_t p = m->hv[out[j]], q = m->hv[tt__next(out[j])];
          listed = (p == u[k] && q == w[k]) || (p == w[k] && q == u[k]);
        }
        if (!listed)
          TT_FAIL_("seed %#llx %s: after flipping %d-%d, edge %d-%d changed "
                   "(%.17g -> %.17g) but the hook missed it",
                   (unsigned long long)seed, vt->name, u[i], w[i], u[k],
                   w[k], vb[k], va[k]);
      }
      tt__mesh_flip(m, h);
    }
  }
  free(u);
  free(w);
  free(vb);
  free(va);
}

static void random_tests(tt_context *ctx)
{
  const double frames[][4] = {
      {1, 0, 0, 1},
      {30, 0, 0, -30},
      {89.98, 0, 0, -90.02},
      {2, 1, 0, 3},
      {0.7, -0.2, 0.3, -1.1},
  };
  for (size_t fi = 0; fi < sizeof frames / sizeof frames[0]; fi++)
    for (uint64_t k = 0; k < 3; k++) {
      uint64_t seed = 0xc417e000u + 16 * fi + k, rng = seed;
      int nx = 17 + (int)(tt_test_rand(&rng) % 8);
      int ny = 13 + (int)(tt_test_rand(&rng) % 8);
      tt_grid *g = make_grid(ctx, nx, ny, frames[fi]);
      if (!g)
        return;
      float *z = tt_grid_heights(g);
      double zscale = fabs(frames[fi][0]) * (1 + (double)k);
      for (int i = 0; i < nx * ny; i++)
        z[i] = (float)(zscale * 3 * tt_test_uniform(&rng));
      tt__mesh m;
      if (random_mesh(&m, g, &rng, 28 + 6 * (int)k)) {
        check_values(&m, g, seed);
        check_affected(&m, g, seed, &rng);
      }
      tt__mesh_free(&m);
      tt_grid_destroy(g);
    }
  /* The same on ground points, as a geographic DEM has them: the frame
   * bent by the conformal map p + alpha p^2 (complex, p from the grid's
   * centre; 0.5 % across the grid), every criterion's swap value against
   * the whole-mesh scores on the ground points. */
  for (size_t fi = 0; fi < sizeof frames / sizeof frames[0]; fi++)
    for (uint64_t k = 0; k < 3; k++) {
      uint64_t seed = 0x9e0d000u + 16 * fi + k, rng = seed;
      int nx = 17 + (int)(tt_test_rand(&rng) % 8);
      int ny = 13 + (int)(tt_test_rand(&rng) % 8);
      const double *f = frames[fi];
      tt_grid *g = make_grid(ctx, nx, ny, f);
      if (!g)
        return;
      CHECK_OK(ctx, tt_grid_alloc_ground_points(ctx, g));
      double *xy = tt_grid_ground_xy(g);
      double half = 0.5 * (nx > ny ? nx : ny) *
                    sqrt(fabs(f[0] * f[3] - f[1] * f[2]));
      double alpha = 0.0025 / half;
      for (int r = 0; xy && r < ny; r++)
        for (int c = 0; c < nx; c++) {
          double dc = c - 0.5 * nx, dr = r - 0.5 * ny;
          double x = f[0] * dc + f[1] * dr, y = f[2] * dc + f[3] * dr;
          xy[2 * (r * nx + c)] = x + alpha * (x * x - y * y);
          xy[2 * (r * nx + c) + 1] = y + alpha * 2 * x * y;
        }
      float *z = tt_grid_heights(g);
      double zscale = fabs(f[0]) * (1 + (double)k);
      for (int i = 0; i < nx * ny; i++)
        z[i] = (float)(zscale * 3 * tt_test_uniform(&rng));
      tt__mesh m;
      if (xy && random_mesh(&m, g, &rng, 28 + 6 * (int)k)) {
        check_values(&m, g, seed);
        check_affected(&m, g, seed, &rng);
      }
      tt__mesh_free(&m);
      tt_grid_destroy(g);
    }
}

/* ---------------------------------------------------------------------
 * Hand-built quads.
 * ------------------------------------------------------------------- */
typedef struct qpt {
  int c, r;
  double z;
} qpt;

/* One quad a, b, c, d over a grid (heights of the vertices set in it);
 * returns the half-edge a->b. */
static int32_t quad_mesh(tt__mesh *m, tt_grid *g, const qpt p[4])
{
  tt__metric metric;
  tt__metric_from_frame(g->frame, &metric);
  tt__mesh_init(m, &metric);
  float *z = tt_grid_heights(g);
  int32_t v[4];
  for (int i = 0; i < 4; i++) {
    z[(size_t)p[i].r * g->nx + (size_t)p[i].c] = (float)p[i].z;
    v[i] = tt__mesh_add_vertex(m, p[i].c, p[i].r, (float)p[i].z);
  }
  CHECK(tt__mesh_orient(m, v[0], v[1], v[2]) > 0);
  CHECK(tt__mesh_orient(m, v[1], v[0], v[3]) > 0);
  tt__mesh_add_triangle(m, v[0], v[1], v[2]);
  tt__mesh_add_triangle(m, v[1], v[0], v[3]);
  tt__mesh_link_all(m);
  return tt__mesh_find_edge(m, v[0], v[1]);
}

static double value_of(tt__mesh *m, tt_grid *g, tt_criterion id, int32_t e)
{
  tt__crit_env env = {m, g, NULL};
  return tt__criterion_get(id)->swap_value(&env, e);
}

static void hand_quads(tt_context *ctx)
{
  const double id[4] = {1, 0, 0, 1};
  tt_grid *g = make_grid(ctx, 8, 8, id);
  if (!g)
    return;
  float *z = tt_grid_heights(g);
  for (int i = 0; i < 64; i++)
    z[i] = 0;
  tt__mesh m;

  /* Min-Max angle: the kite a(1,3) b(5,3) c(3,4) d(3,2) (identity frame).
   * The diagonal a-b leaves the angle 2 atan 2 at c (and at d); c-d leaves
   * 2 atan 0.5 at a and b and (pi - 2 atan 0.5) / 2 at c and d. */
  {
    qpt p[4] = {{1, 3, 0}, {5, 3, 0}, {3, 4, 0}, {3, 2, 0}};
    int32_t e = quad_mesh(&m, g, p);
    double before = 2 * atan(2.0);
    double after = fmax(2 * atan(0.5), (PI - 2 * atan(0.5)) / 2);
    CHECK_DBL_NEAR(value_of(&m, g, TT_CRITERION_MINMAX_ANGLE, e),
                   before - after, 1e-12);
    CHECK_DBL_NEAR(value_of(&m, g, TT_CRITERION_MINMAX_ANGLE_LEX, e),
                   before - after, 1e-12);
    int32_t h = tt__mesh_flip(&m, e);
    CHECK(value_of(&m, g, TT_CRITERION_MINMAX_ANGLE, h) < 0);
    CHECK(value_of(&m, g, TT_CRITERION_MINMAX_ANGLE_LEX, h) < 0);
    tt__mesh_free(&m);
  }
  /* A square a(0,0) b(2,2) c(0,2) d(2,0) with d raised to 3: the
   * diagonal a-b avoids the raised corner and keeps one flat triangle. */
  {
    qpt p[4] = {{0, 0, 0}, {2, 2, 0}, {0, 2, 0}, {2, 0, 3}};
    int32_t e = quad_mesh(&m, g, p);
    double area_b = 2 + sqrt(88.0) / 2, area_a = sqrt(52.0);
    CHECK_DBL_NEAR(value_of(&m, g, TT_CRITERION_MIN_AREA, e), area_b - area_a,
                   1e-12);
    double al_b = acos(16 / (4 * sqrt(88.0))), al_a = acos(16.0 / 52.0);
    CHECK_DBL_NEAR(value_of(&m, g, TT_CRITERION_MEAN_CURVATURE, e),
                   sqrt(8.0) * al_b - sqrt(17.0) * al_a, 1e-12);
    CHECK_DBL_NEAR(value_of(&m, g, TT_CRITERION_ABN, e), al_b - al_a, 1e-12);
    CHECK_DBL_NEAR(value_of(&m, g, TT_CRITERION_ABN_SUM, e), al_b - al_a,
                   1e-12);
    CHECK_DBL_NEAR(value_of(&m, g, TT_CRITERION_ABN_SUMSQ, e),
                   al_b * al_b - al_a * al_a, 1e-12);
    CHECK(value_of(&m, g, TT_CRITERION_MIN_AREA, e) < 0);
    CHECK(value_of(&m, g, TT_CRITERION_MEAN_CURVATURE, e) < 0);
    CHECK(value_of(&m, g, TT_CRITERION_ABN, e) < 0);
    /* four boundary vertices of a two-triangle (developable) patch:
     * sum |pi - theta| is the same either way */
    CHECK_DBL_NEAR(value_of(&m, g, TT_CRITERION_GAUSSIAN_CURVATURE, e), 0,
                   1e-12);
    tt__mesh_free(&m);
  }
  /* L2: z = (c - r)^2 over a 5x5 block is constant along the direction
   * (1, 1): the diagonal a(0,0)-b(4,4) follows it. Expected sums of
   * squared residuals by brute force over the block's samples. */
  {
    for (int r = 0; r < 8; r++)
      for (int c = 0; c < 8; c++)
        z[r * 8 + c] = (float)((c - r) * (c - r));
    qpt p[4] = {{0, 0, 0}, {4, 4, 0}, {0, 4, 16}, {4, 0, 16}};
    int32_t e = quad_mesh(&m, g, p);
    double sse[2] = {0, 0};
    for (int r = 0; r <= 4; r++)
      for (int c = 0; c <= 4; c++) {
        double h = (c - r) * (c - r);
        /* diagonal a-b: plane through (0,0,0),(4,4,0),(0,4,16) where
         * r >= c, through (4,0,16) where c > r: 4 |c - r| */
        double hab = 4.0 * abs(c - r);
        /* diagonal c-d (c + r = 4): plane through a, c, d where
         * c + r <= 4: 4c + 4r; through b, c, d beyond: 32 - 4c - 4r */
        double hcd = c + r <= 4 ? 4.0 * (c + r) : 32.0 - 4.0 * (c + r);
        sse[0] += (h - hab) * (h - hab);
        sse[1] += (h - hcd) * (h - hcd);
      }
    double v = value_of(&m, g, TT_CRITERION_L2, e);
    CHECK_DBL_NEAR(v, sse[0] - sse[1], 1e-9);
    CHECK(v < 0);
    tt__mesh_free(&m);
  }
  tt_grid_destroy(g);
}

/* ---------------------------------------------------------------------
 * Gaussian curvature: vertex classes, and the paraboloid.
 * ------------------------------------------------------------------- */
static void star_case(const char *what, const double *zn, int n,
                      bool boundary, double zc, int want_class)
{
  const double id[4] = {1, 0, 0, 1};
  const int off[6][2] = {{2, 0}, {1, 2}, {-1, 2}, {-2, 0}, {-1, -2}, {1, -2}};
  tt__metric metric;
  tt__metric_from_frame(id, &metric);
  tt__mesh m;
  tt__mesh_init(&m, &metric);
  int32_t c = tt__mesh_add_vertex(&m, 10, 10, (float)zc);
  int32_t v[6];
  for (int i = 0; i < n; i++)
    v[i] = tt__mesh_add_vertex(&m, 10 + off[i][0], 10 + off[i][1],
                               (float)zn[i]);
  for (int i = 0; i < (boundary ? n - 1 : n); i++)
    tt__mesh_add_triangle(&m, c, v[i], v[(i + 1) % n]);
  tt__mesh_link_all(&m);
  char why[256];
  CHECK(tt__mesh_validate(&m, why, sizeof why));
  tt__crit_env env = {&m, NULL, NULL};
  int cls, ocls;
  double k = tt__gaussian_vertex(&env, c, &cls);
  double ko = oracle_gauss(&m, id, c, &ocls);
  /* the formula by hand */
  P3 e[6];
  for (int i = 0; i < n; i++) {
    P3 d = {off[i][0], off[i][1], zn[i] - zc};
    e[i] = d;
  }
  double sum = 0;
  for (int i = 0; i < (boundary ? n - 1 : n); i++)
    sum += ang3(e[i], e[(i + 1) % n]);
  double want;
  switch (want_class) {
  case TT__VERTEX_CONVEX: want = 2 * PI - sum; break;
  case TT__VERTEX_SADDLE: want = sum - 2 * PI; break;
  case TT__VERTEX_BOUNDARY: want = fabs(PI - sum); break;
  default: {
    /* the dented pit below: ray 0 is inside the hull of rays 1..5 */
    double hull = 0;
    for (int i = 1; i < n; i++)
      hull += ang3(e[i], e[i + 1 < n ? i + 1 : 1]);
    want = 2 * PI - 2 * hull + sum;
  }
  }
  if (cls != want_class || ocls != want_class)
    TT_FAIL_("%s: class %d (oracle %d), want %d", what, cls, ocls,
             want_class);
  if (!(fabs(k - want) <= 1e-12 && fabs(ko - want) <= 1e-12))
    TT_FAIL_("%s: |K| %.17g (oracle %.17g), want %.17g", what, k, ko, want);
  if (want_class != TT__VERTEX_BOUNDARY)
    CHECK(k >= -1e-12);
  tt__mesh_free(&m);
}

static void gaussian_stars(void)
{
  const double ring1[6] = {1, 1, 1, 1, 1, 1};
  const double zero[6] = {0, 0, 0, 0, 0, 0};
  const double alt[6] = {1, -1, 1, -1, 1, -1};
  const double dent[6] = {5, 1, 1, 1, 1, 1};
  star_case("pit", ring1, 6, false, 0, TT__VERTEX_CONVEX);
  star_case("peak", zero, 6, false, 1, TT__VERTEX_CONVEX);
  star_case("flat", zero, 6, false, 0, TT__VERTEX_CONVEX);
  star_case("monkey saddle", alt, 6, false, 0, TT__VERTEX_SADDLE);
  star_case("dented pit", dent, 6, false, 0, TT__VERTEX_MIXED);
  star_case("boundary", ring1, 4, true, 0, TT__VERTEX_BOUNDARY);
  /* a sliver-thin star: the neighbours nearly coplanar with v, where
   * rounded triple products have no sign; the exact ones do */
  const double thin[6] = {1e-7, 1e-7, 1e-7, 1e-7, 1e-7, 3e-7};
  star_case("nearly flat dented pit", thin, 6, false, 0, TT__VERTEX_MIXED);
}

/* The supporting-plane sign against 128-bit integers, on rays made nearly
 * coplanar: the third height is the float nearest the coplanar one, moved
 * by a few ulps, so signs -1, 0 and +1 all occur and the rounded
 * determinant cannot be trusted. Heights are floats in [8, 2^26], hence
 * multiples of 2^-20: 2^20 z is an exact integer. */
static void gaussian_exact_orient(uint64_t seed)
{
  uint64_t rng = seed;
  int seen[3] = {0, 0, 0};
  for (int it = 0; it < 20000; it++) {
    int64_t dc[3], dr[3];
    for (int i = 0; i < 3; i++) {
      dc[i] = (int64_t)(tt_test_rand(&rng) % 201) - 100;
      dr[i] = (int64_t)(tt_test_rand(&rng) % 201) - 100;
    }
    if (it % 3 == 0) { /* rays in one vertical plane, or sharing a line */
      dc[2] = 2 * dc[0] - dc[1];
      dr[2] = 2 * dr[0] - dr[1];
    }
    float z[3], zv = (float)(8 + tt_test_uniform(&rng) * 6.7e7);
    for (int i = 0; i < 2; i++)
      z[i] = (float)(8 + tt_test_uniform(&rng) * 6.7e7);
    bool fib = it % 2 == 1;
    if (fib) {
      /* e0, e1 = consecutive Fibonacci pairs near 2^26 (their 2x2 minor
       * is +-1), e2 parallel to e1 - e0 on the map, z0 = z1: the two big
       * products (~2^80) cancel exactly and the sign is that of
       * (z2 - zv), far below their rounding */
      int64_t f[40] = {0, 1};
      for (int i = 2; i < 40; i++)
        f[i] = f[i - 1] + f[i - 2];
      int n = 20 + (int)(tt_test_rand(&rng) % 19);
      int64_t sc = 1 + (int64_t)(tt_test_rand(&rng) % 3);
      dc[0] = f[n + 1];
      dr[0] = f[n];
      dc[1] = f[n];
      dr[1] = f[n - 1];
      dc[2] = sc * (dc[1] - dc[0]);
      dr[2] = sc * (dr[1] - dr[0]);
      z[1] = z[0];
    }
    int64_t mi = dc[1] * dr[2] - dr[1] * dc[2];
    int64_t mj = dc[2] * dr[0] - dr[2] * dc[0];
    int64_t mk = dc[0] * dr[1] - dr[0] * dc[1];
    double zk = 8 + tt_test_uniform(&rng) * 6.7e7;
    if (fib)
      zk = zv;
    else if (mk != 0)
      zk = zv - ((z[0] - (double)zv) * mi + (z[1] - (double)zv) * mj) /
                    (double)mk;
    if (!(zk >= 8 && zk <= 6.7e7))
      continue;
    z[2] = (float)zk;
    int steps = (int)(tt_test_rand(&rng) % 7) - 3;
    for (; steps > 0; steps--)
      z[2] = nextafterf(z[2], INFINITY);
    for (; steps < 0; steps++)
      z[2] = nextafterf(z[2], -INFINITY);
    if (!(z[2] >= 8))
      continue;
    __int128 det = 0;
    int64_t m[3] = {mi, mj, mk};
    for (int i = 0; i < 3; i++)
      det += (__int128)(int64_t)ldexp(z[i] - (double)zv, 20) * m[i];
    int want = det > 0 ? 1 : det < 0 ? -1 : 0;
    const double zd[3] = {z[0], z[1], z[2]};
    int got = tt__gaussian_orient(dc, dr, zd, zv);
    seen[want + 1]++;
    if (got != want) {
      TT_FAIL_("seed %#llx case %d: sign %d, exact %d",
               (unsigned long long)seed, it, got, want);
      return;
    }
  }
  CHECK(seen[0] > 100 && seen[1] > 100 && seen[2] > 100);
}

/* The same for heights of a grid of doubles (53 significant bits, which
 * the exact sum splits into two halves): heights in [8, 2^23), multiples
 * of 2^-49, so that 2^49 z is an exact integer. Every other case has its
 * third ray in the plane of the first two exactly (e2 = a e0 + b e1 in
 * all three coordinates, heights multiples of 2^-30 so that no step
 * rounds), then moved by a few ulps: signs -1, 0 and +1 all occur. */
static void gaussian_exact_orient_f64(uint64_t seed)
{
  uint64_t rng = seed;
  int seen[3] = {0, 0, 0};
  for (int it = 0; it < 20000; it++) {
    int64_t dc[3], dr[3];
    for (int i = 0; i < 2; i++) {
      dc[i] = (int64_t)(tt_test_rand(&rng) % 201) - 100;
      dr[i] = (int64_t)(tt_test_rand(&rng) % 201) - 100;
    }
    double z[3], zv = 8 + ldexp(floor(tt_test_uniform(&rng) * 0x1p49), -30);
    for (int i = 0; i < 2; i++)
      z[i] = 8 + ldexp(floor(tt_test_uniform(&rng) * 0x1p49), -30);
    if (it % 2 == 0) {
      int64_t a = (int64_t)(tt_test_rand(&rng) % 7) - 3;
      int64_t b = (int64_t)(tt_test_rand(&rng) % 7) - 3;
      dc[2] = a * dc[0] + b * dc[1];
      dr[2] = a * dr[0] + b * dr[1];
      z[2] = zv + (double)a * (z[0] - zv) + (double)b * (z[1] - zv);
    } else {
      dc[2] = (int64_t)(tt_test_rand(&rng) % 201) - 100;
      dr[2] = (int64_t)(tt_test_rand(&rng) % 201) - 100;
      z[2] = 8 + tt_test_uniform(&rng) * 0x1p20;
    }
    int steps = (int)(tt_test_rand(&rng) % 7) - 3;
    for (; steps > 0; steps--)
      z[2] = nextafter(z[2], INFINITY);
    for (; steps < 0; steps++)
      z[2] = nextafter(z[2], -INFINITY);
    if (!(z[2] >= 8 && z[2] < 0x1p23))
      continue;
    int64_t mi = dc[1] * dr[2] - dr[1] * dc[2];
    int64_t mj = dc[2] * dr[0] - dr[2] * dc[0];
    int64_t mk = dc[0] * dr[1] - dr[0] * dc[1];
    __int128 det = 0, zvi = (__int128)ldexp(zv, 49);
    int64_t m[3] = {mi, mj, mk};
    for (int i = 0; i < 3; i++)
      det += ((__int128)ldexp(z[i], 49) - zvi) * m[i];
    int want = det > 0 ? 1 : det < 0 ? -1 : 0;
    int got = tt__gaussian_orient(dc, dr, z, zv);
    seen[want + 1]++;
    if (got != want) {
      TT_FAIL_("doubles, seed %#llx case %d: sign %d, exact %d",
               (unsigned long long)seed, it, got, want);
      return;
    }
  }
  CHECK(seen[0] > 100 && seen[1] > 100 && seen[2] > 100);
}

/* On z = k (x^2 + y^2) (ground x, y) the Delaunay triangulation is the
 * lower convex hull: every interior vertex convex, and swapping any edge
 * away from the boundary makes a reflex edge and raises sum |K|. */
static void gaussian_paraboloid(tt_context *ctx)
{
  const double frame[4] = {2, 1, 0, 3};
  const int N = 9;
  tt_grid *g = make_grid(ctx, N, N, frame);
  if (!g)
    return;
  float *z = tt_grid_heights(g);
  for (int r = 0; r < N; r++)
    for (int c = 0; c < N; c++) {
      double x = 2.0 * c + r - 12, y = 3.0 * r - 12;
      z[r * N + c] = (float)(0.05 * (x * x + y * y));
    }
  tt__metric metric;
  tt__metric_from_frame(g->frame, &metric);
  tt__mesh m;
  tt__mesh_init(&m, &metric);
  for (int r = 0; r < N; r++)
    for (int c = 0; c < N; c++)
      tt__mesh_add_vertex(&m, c, r, z[r * N + c]);
  for (int r = 0; r + 1 < N; r++)
    for (int c = 0; c + 1 < N; c++) {
      int32_t v00 = r * N + c, v10 = v00 + 1, v01 = v00 + N, v11 = v01 + 1;
      add_tri_ccw(&m, v00, v10, v11);
      add_tri_ccw(&m, v00, v11, v01);
    }
  tt__mesh_link_all(&m);
  tt__crit_env env = {&m, g, NULL};
  tt__edge_stack stack = {0};
  tt__swap_all(&m, &tt__criterion_delaunay, &env, &stack);
  tt__edge_stack_free(&stack);
  for (int r = 1; r + 1 < N; r++)
    for (int c = 1; c + 1 < N; c++) {
      int cls;
      tt__gaussian_vertex(&env, r * N + c, &cls);
      if (cls != TT__VERTEX_CONVEX)
        TT_FAIL_("paraboloid vertex (%d,%d) class %d", c, r, cls);
    }
  const tt__criterion_vt *vt =
      tt__criterion_get(TT_CRITERION_GAUSSIAN_CURVATURE);
  int tested = 0;
  for (size_t e = 0; e < 3 * m.nslots; e++) {
    if (!tt__mesh_live(&m, (int32_t)(e / 3)) || m.twin[e] < (int32_t)e ||
        !tt__mesh_flippable(&m, (int32_t)e))
      continue;
    int32_t f = m.twin[e];
    int32_t q[4] = {m.hv[e], m.hv[f], tt__mesh_apex(&m, (int32_t)e),
                    tt__mesh_apex(&m, f)};
    bool inner = true;
    for (int k = 0; k < 4; k++) {
      int c = m.v[q[k]].c, r = m.v[q[k]].r;
      inner &= c > 1 && r > 1 && c + 2 < N && r + 2 < N;
    }
    if (!inner)
      continue;
    double v = vt->swap_value(&env, (int32_t)e);
    if (!(v < -1e-6))
      TT_FAIL_("paraboloid: Delaunay edge %zu has Gaussian swap value %g",
               e, v);
    tested++;
  }
  CHECK(tested > 20);
  tt__mesh_free(&m);
  tt_grid_destroy(g);
}

/* Gaussian curvature's per-run cache (cache_new) never changes a value:
 * random insertions (Lawson flips under the criterion, through the cached
 * environment, so the cache grows and follows the stars as they change)
 * and random swaps, swaps back and swaps kept; at every step the cached
 * and the uncached swap value are identical (==, not close), and a swap
 * and its swap back have exactly opposite values both ways. Heights:
 * integers (the exact-in-doubles sign path), terraces (flats: coplanar
 * rays), floats, and integers past that path's 2^16 limit. Half the
 * meshes track star versions, flips are mostly reported to the cache
 * (flipped) and some are tried and reverted. A cache made for one mesh and
 * handed another is not used. */
static void gaussian_cache(tt_context *ctx, uint64_t seed)
{
  const tt__criterion_vt *vt =
      tt__criterion_get(TT_CRITERION_GAUSSIAN_CURVATURE);
  CHECK(vt->cache_new != NULL && vt->cache_free != NULL);
  if (!vt->cache_new || !vt->cache_free)
    return;
  const double frames[][4] = {{1, 0, 0, 1}, {30, 0, 0, -30},
                              {2, 1, 0, 3}, {0.7, -0.2, 0.3, -1.1}};
  long compared = 0, kept = 0;
  for (int mode = 0; mode < 4; mode++)
    for (int fi = 0; fi < 4; fi++) {
      uint64_t s0 = seed + 16 * (uint64_t)mode + (uint64_t)fi, rng = s0;
      int nx = 40 + (int)(tt_test_rand(&rng) % 20);
      int ny = 40 + (int)(tt_test_rand(&rng) % 20);
      tt_grid *g = make_grid(ctx, nx, ny, frames[fi]);
      if (!g)
        return;
      float *z = tt_grid_heights(g);
      for (int r = 0; r < ny; r++)
        for (int c = 0; c < nx; c++) {
          double h = 150 * sin(c * 0.13) * cos(r * 0.11) + 20 * sin(0.4 * c);
          double u = tt_test_uniform(&rng);
          z[r * nx + c] =
              (float)(mode == 0   ? floor(1500 + h + 3 * u)
                      : mode == 1 ? 25 * floor((1500 + h) / 25)
                      : mode == 2 ? 1500 + h + u
                                  : floor(70000 + h / 10 + 3 * u));
        }
      tt__mesh m;
      if (!random_mesh(&m, g, &rng, 12)) {
        tt__mesh_free(&m);
        tt_grid_destroy(g);
        continue;
      }
      /* half the meshes track star versions (what refinement does), so
       * the cache takes stars from its entries and keeps the other
       * configuration after reported flips; the rest prove every star */
      if (fi % 2 == 0)
        CHECK(tt__mesh_track_stars(&m));
      tt__crit_env plain = {&m, g, NULL}, cached = {&m, g, NULL};
      cached.cache = vt->cache_new(&cached);
      CHECK(cached.cache != NULL);
      tt__edge_stack stack = {0};
      for (int it = 0; it < 3000; it++) {
        if (tt_test_rand(&rng) % 16 == 1) {
          /* a value, then a flip elsewhere that may change one of its
           * stars (unreported), then that edge flipped and reported */
          int32_t e = (int32_t)(tt_test_rand(&rng) % (3 * m.nslots));
          if (!tt__mesh_live(&m, e / 3) || !tt__mesh_flippable(&m, e))
            continue;
          int32_t quad[4] = {m.hv[e], m.hv[m.twin[e]], tt__mesh_apex(&m, e),
                             tt__mesh_apex(&m, m.twin[e])};
          /* f: mostly the far side of a triangle around a quad corner,
           * whose flip gives that corner a new neighbour */
          int32_t f = (int32_t)(tt_test_rand(&rng) % (3 * m.nslots));
          if (tt_test_rand(&rng) % 4 != 0) {
            int32_t y = m.v[quad[tt_test_rand(&rng) % 4]].edge;
            for (int k = (int)(tt_test_rand(&rng) % 8); k > 0 && y >= 0; k--)
              y = m.twin[tt__prev(y)] >= 0 ? m.twin[tt__prev(y)] : y;
            f = y >= 0 ? tt__next(y) : f;
          }
          if (!tt__mesh_live(&m, f / 3) || !tt__mesh_flippable(&m, f) ||
              f / 3 == e / 3 || f / 3 == m.twin[e] / 3)
            continue;
          (void)vt->swap_value(&cached, e);
          CHECK(tt__mesh_flip(&m, f) >= 0);
          int32_t x = tt__mesh_find_edge(&m, quad[0], quad[1]);
          if (x < 0 || m.twin[x] < 0 || tt__mesh_apex(&m, x) != quad[2] ||
              tt__mesh_apex(&m, m.twin[x]) != quad[3] ||
              !tt__mesh_flippable(&m, x))
            continue;
          int32_t hx = tt__mesh_flip(&m, x);
          CHECK(hx >= 0);
          if (hx < 0)
            break;
          vt->flipped(&cached, hx);
          for (int k = 0; k < 4; k++) {
            int32_t y = m.v[quad[k]].edge;
            if (y >= 0 && m.twin[y] >= 0 &&
                vt->swap_value(&cached, y) != vt->swap_value(&plain, y))
              TT_FAIL_("seed %#llx: a flip after another: cached value of "
                       "%d differs", (unsigned long long)s0, y);
            y = y >= 0 ? tt__prev(y) : -1;
            if (y >= 0 && m.twin[y] >= 0 &&
                vt->swap_value(&cached, y) != vt->swap_value(&plain, y))
              TT_FAIL_("seed %#llx: a flip after another: cached value of "
                       "%d differs", (unsigned long long)s0, y);
          }
          continue;
        }
        if (tt_test_rand(&rng) % 16 == 0) {
          /* a tried and reverted flip (the look-ahead optimiser's) */
          int32_t e = (int32_t)(tt_test_rand(&rng) % (3 * m.nslots));
          if (!tt__mesh_live(&m, e / 3) || !tt__mesh_flippable(&m, e))
            continue;
          (void)vt->swap_value(&cached, e);
          tt__mesh_flip_undo u;
          int32_t h = tt__mesh_flip_undoable(&m, e, &u);
          CHECK(h >= 0);
          if (h < 0)
            break;
          double a = vt->swap_value(&cached, h);
          if (a != vt->swap_value(&plain, h))
            TT_FAIL_("seed %#llx: tried edge %d: cached %.17g differs",
                     (unsigned long long)s0, h, a);
          tt__mesh_flip_revert(&m, &u);
          continue;
        }
        if (tt_test_rand(&rng) % 8 == 0) {
          int c = (int)(tt_test_rand(&rng) % (uint64_t)nx);
          int r = (int)(tt_test_rand(&rng) % (uint64_t)ny);
          int32_t on, opp[4];
          int32_t t = tt__mesh_locate(&m, -1, c, r, &on);
          if (t < 0 || on <= -2)
            continue;
          int32_t v = tt__mesh_add_vertex(&m, c, r, z[r * nx + c]);
          int nopp = 3;
          if (on < 0)
            tt__mesh_split_triangle(&m, t, v, opp);
          else {
            tt__mesh_split_edge(&m, on, v, opp);
            nopp = 4;
          }
          CHECK(tt__swap_repair(&m, vt, &cached, opp, nopp, &stack) >= 0);
          continue;
        }
        int32_t e = (int32_t)(tt_test_rand(&rng) % (3 * m.nslots));
        if (!tt__mesh_live(&m, e / 3) || m.twin[e] < 0)
          continue;
        double a = vt->swap_value(&plain, e), b = vt->swap_value(&cached, e);
        compared++;
        if (a != b)
          TT_FAIL_("seed %#llx: edge %d uncached %.17g, cached %.17g",
                   (unsigned long long)s0, e, a, b);
        if (!tt__mesh_flippable(&m, e) ||
            !(a > 0 || tt_test_rand(&rng) % 3 == 0))
          continue;
        int32_t h = tt__mesh_flip(&m, e);
        if (vt->flipped && tt_test_rand(&rng) % 4 != 0)
          vt->flipped(&cached, h); /* as a flip loop reports it, mostly */
        double bc = vt->swap_value(&cached, h), bp = vt->swap_value(&plain, h);
        if (bc != -a || bp != -a)
          TT_FAIL_("seed %#llx: edge %d value %.17g, back %.17g (cached) "
                   "%.17g (uncached)", (unsigned long long)s0, e, a, bc, bp);
        if (tt_test_rand(&rng) % 2) {
          int32_t h2 = tt__mesh_flip(&m, h);
          if (vt->flipped && tt_test_rand(&rng) % 2)
            vt->flipped(&cached, h2);
          double again = vt->swap_value(&cached, h2);
          if (again != a)
            TT_FAIL_("seed %#llx: edge %d value %.17g, after swap and "
                     "swap back %.17g", (unsigned long long)s0, e, a, again);
        } else {
          kept++;
        }
      }
      char why[256];
      if (!tt__mesh_validate(&m, why, sizeof why))
        TT_FAIL_("seed %#llx: mesh invalid: %s", (unsigned long long)s0, why);
      /* the cache handed a different mesh is bypassed, not trusted */
      tt__mesh other;
      if (random_mesh(&other, g, &rng, 40)) {
        tt__crit_env wrong = {&other, g, cached.cache}, right = {&other, g,
                                                                 NULL};
        for (size_t e = 0; e < 3 * other.nslots; e++)
          if (tt__mesh_live(&other, (int32_t)(e / 3)) && other.twin[e] >= 0 &&
              vt->swap_value(&wrong, (int32_t)e) !=
                  vt->swap_value(&right, (int32_t)e))
            TT_FAIL_("seed %#llx: a cache of another mesh changed edge %zu",
                     (unsigned long long)s0, e);
      }
      tt__mesh_free(&other);
      vt->cache_free(cached.cache);
      tt__edge_stack_free(&stack);
      tt__mesh_free(&m);
      tt_grid_destroy(g);
    }
  CHECK(compared > 10000 && kept > 1000);
}

/* ---------------------------------------------------------------------
 * Names and timings.
 * ------------------------------------------------------------------- */
static void names(tt_context *ctx)
{
  const char *want[] = {"delaunay",        "minmax_angle",
                        "minmax_angle_lex", "min_area",
                        "mean_curvature",  "gaussian_curvature",
                        "abn",             "abn_sum",
                        "abn_sumsq",       "l2"};
  for (int i = 0; i < 10; i++) {
    CHECK_STR_EQ(tt_criterion_name((tt_criterion)i), want[i]);
    tt_criterion c = TT_CRITERION_DELAUNAY;
    CHECK_OK(ctx, tt_criterion_parse(ctx, want[i], &c));
    CHECK_INT_EQ(c, i);
  }
  CHECK(tt_criterion_name((tt_criterion)10) == NULL);
}

static void timings(tt_context *ctx)
{
  const double frame[4] = {30, 0, 0, -30};
  tt_grid *g = make_grid(ctx, 257, 257, frame);
  if (!g)
    return;
  uint64_t rng = 0x7117e;
  float *z = tt_grid_heights(g);
  for (int r = 0; r < 257; r++)
    for (int c = 0; c < 257; c++)
      z[r * 257 + c] = (float)(100 * sin(c * 0.05) * cos(r * 0.04) +
                               tt_test_uniform(&rng));
  tt__mesh m;
  if (random_mesh(&m, g, &rng, 600)) {
    tt__crit_env env = {&m, g, NULL};
    printf("swap value cost on a %zu-vertex mesh (ns per call):\n", m.nv);
    for (int ci = 0; ci < 10; ci++) {
      const tt__criterion_vt *vt = tt__criterion_get((tt_criterion)ci);
      double sink = 0, best = INFINITY;
      for (int rep = 0; rep < 5; rep++) { /* the fastest of 5 passes */
        long calls = 0;
        double t0 = tt__now();
        for (size_t e = 0; e < 3 * m.nslots; e++)
          if (tt__mesh_live(&m, (int32_t)(e / 3)) && m.twin[e] >= 0) {
            sink += vt->swap_value(&env, (int32_t)e);
            calls++;
          }
        double dt = (tt__now() - t0) / (double)calls;
        best = dt < best ? dt : best;
      }
      printf("  %-20s %8.0f%s\n", vt->name, 1e9 * best,
             isfinite(sink) ? "" : " (non-finite!)");
      CHECK(isfinite(sink));
    }
  }
  tt__mesh_free(&m);
  tt_grid_destroy(g);
}

int main(void)
{
  tt_context *ctx = tt_context_create();
  if (getenv("TT_CRITERIA_TIMINGS_ONLY")) { /* for profiling */
    timings(ctx);
    tt_context_destroy(ctx);
    TT_TEST_DONE();
  }
  names(ctx);
  hand_quads(ctx);
  gaussian_stars();
  gaussian_exact_orient(0x5eed0001u);
  gaussian_exact_orient_f64(0x5eed0002u);
  gaussian_paraboloid(ctx);
  gaussian_cache(ctx, 0xcac4e000u);
  random_tests(ctx);
  timings(ctx);
  tt_context_destroy(ctx);
  TT_TEST_DONE();
}
