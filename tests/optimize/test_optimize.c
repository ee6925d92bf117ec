/* test_optimize.c -- local swap and look-ahead swap (optimize.c), seeded
 * (the seed is printed; TT_SEED=<n> replays a run):
 *  - undoable flips restore the mesh word for word;
 *  - after local swap no swappable edge has a swap value above the run's
 *    threshold, whole-mesh and after each insertion (region repair);
 *  - look-ahead never ends worse than plain local swap from the same start;
 *  - exhaustive search over all triangulations of small point sets (flip
 *    graph walk, qualities summed from exact swap values): a local optimum
 *    is never above the global one, and Gaussian curvature on the sphere
 *    reaches it (once that criterion is registered);
 *  - the L2 optimiser from Delaunay never ends with a larger squared error;
 *    Gaussian and L2 beat Delaunay on a ruled surface (once registered);
 *  - refinement keeps its error bound for every criterion and optimisation,
 *    checked by the independent oracle tt_eval_triangles;
 *  - the final pass refuses moves that would raise the error past its
 *    bound.
 * Until the study's criteria land, the optimiser runs under a test
 * criterion defined here: total 3-D area, computed with the corners of each
 * triangle in sorted order so that a swap and its reverse are exact
 * negatives. */
#include "criteria/criterion.h"
#include "mesh/mesh.h"
#include "optimize/hole_dp.h"
#include "optimize/optimize.h"
#include "mesh/raster_scan.h"
#include "optimize/swap.h"
#include "terratin/terratin.h"
#include "tt_test.h"
#include "tt_tin_oracle.h"

#include <stdbool.h>
#include <time.h>

static tt_context *ctx;

/* --- the test criterion: minimum total 3-D area (pixel x, y; height z) -- */

static double tri_area3(const tt__mesh *m, int32_t a, int32_t b, int32_t c)
{
  /* sorted corners: the same triangle gives the same bits */
  int32_t v[3] = {a, b, c};
  for (int i = 0; i < 2; i++)
    for (int j = 0; j < 2 - i; j++)
      if (v[j] > v[j + 1]) {
        int32_t t = v[j];
        v[j] = v[j + 1];
        v[j + 1] = t;
      }
  double p[3][3];
  for (int k = 0; k < 3; k++) {
    p[k][0] = m->v[v[k]].c;
    p[k][1] = m->v[v[k]].r;
    p[k][2] = m->v[v[k]].z;
  }
  double u[3], w[3];
  for (int k = 0; k < 3; k++) {
    u[k] = p[1][k] - p[0][k];
    w[k] = p[2][k] - p[0][k];
  }
  double x = u[1] * w[2] - u[2] * w[1], y = u[2] * w[0] - u[0] * w[2],
         z = u[0] * w[1] - u[1] * w[0];
  return 0.5 * sqrt(x * x + y * y + z * z);
}

static double area_swap_value(const tt__crit_env *env, int32_t e)
{
  const tt__mesh *m = env->mesh;
  int32_t f = m->twin[e];
  int32_t a = m->hv[e], b = m->hv[f];
  int32_t c = tt__mesh_apex(m, e), d = tt__mesh_apex(m, f);
  double before = tri_area3(m, a, b, c) + tri_area3(m, b, a, d);
  double after = tri_area3(m, c, a, d) + tri_area3(m, d, b, c);
  return before - after;
}

static const tt__criterion_vt area_crit = {
    (tt_criterion)1000, "test_area", true, area_swap_value, NULL, NULL, NULL,
    NULL, false};

static double total_area(const tt__mesh *m)
{
  double s = 0;
  for (size_t t = 0; t < m->nslots; t++)
    if (tt__mesh_live(m, (int32_t)t))
      s += tri_area3(m, m->hv[3 * t], m->hv[3 * t + 1], m->hv[3 * t + 2]);
  return s;
}

/* --- meshes from point sets -------------------------------------------- */

static void check_valid(const tt__mesh *m, const char *what)
{
  char why[256];
  if (!tt__mesh_validate(m, why, sizeof why))
    TT_FAIL_("%s: invalid mesh: %s", what, why);
}

/* How insert_point repairs with a criterion (test_flip_repair changes it),
 * and the swaps of its last repair. */
static tt_repair insert_repair = TT_REPAIR_LOCAL;
static long last_flips;

/* Inserts (c, r) into the mesh (brute-force location), repaired by
 * Delaunay flips, or by the criterion's repair (insert_repair) when crit is
 * given. */
static bool insert_point(tt__mesh *m, const tt_grid *g, int32_t c, int32_t r,
                         const tt__criterion_vt *crit, tt__edge_stack *stack)
{
  const float *z = tt_grid_heights_const(g);
  int32_t v = tt__mesh_add_vertex(m, c, r, z[(size_t)r * tt_grid_width(g) + c]);
  tt__crit_env env = {m, g, NULL};
  for (size_t t = 0; t < m->nslots; t++) {
    if (!tt__mesh_live(m, (int32_t)t))
      continue;
    int32_t on = -1, out = 0;
    for (int k = 0; k < 3; k++) {
      int32_t a = m->hv[3 * t + k], b = m->hv[3 * t + (k + 1) % 3];
      int o = tt__mesh_orient(m, a, b, v);
      if (o < 0)
        out = 1;
      else if (o == 0)
        on = (int32_t)(3 * t) + k;
    }
    if (out)
      continue;
    int32_t opp[4];
    int n;
    bool ok;
    if (on < 0) {
      ok = tt__mesh_split_triangle(m, (int32_t)t, v, opp);
      n = 3;
    } else {
      ok = tt__mesh_split_edge(m, on, v, opp);
      n = 4;
    }
    if (!ok)
      return false;
    long flips = crit ? tt__optimize_insert(m, crit, &env, insert_repair, v,
                                            opp, n, stack)
                      : tt__swap_repair(m, &tt__criterion_delaunay, &env, opp,
                                        n, stack);
    tt__mesh_clear_touched(m);
    last_flips = flips;
    return flips >= 0;
  }
  return false;
}

/* The Delaunay triangulation (or the region-repaired one) of the grid's
 * corners and the given distinct inner points. */
static bool build_box(tt__mesh *m, const tt_grid *g, const int32_t box[4],
                      const int32_t *pts, size_t n,
                      const tt__criterion_vt *crit);

static bool build(tt__mesh *m, const tt_grid *g, const int32_t *pts, size_t n,
                  const tt__criterion_vt *crit)
{
  int32_t box[4] = {0, 0, (int32_t)tt_grid_width(g) - 1,
                    (int32_t)tt_grid_height(g) - 1};
  return build_box(m, g, box, pts, n, crit);
}

/* The same with the corners of box = (c0, r0, c1, r1) as the outline; the
 * points must lie strictly inside it. */
static bool build_box(tt__mesh *m, const tt_grid *g, const int32_t box[4],
                      const int32_t *pts, size_t n,
                      const tt__criterion_vt *crit)
{
  double fr[4];
  tt_grid_get_ground_frame(g, fr);
  tt__metric metric;
  tt__metric_from_frame(fr, &metric);
  tt__mesh_init(m, &metric);
  const float *z = tt_grid_heights_const(g);
  size_t nx = tt_grid_width(g);
  int32_t cc[4][2] = {{box[0], box[1]}, {box[2], box[1]}, {box[2], box[3]},
                      {box[0], box[3]}};
  for (int k = 0; k < 4; k++)
    tt__mesh_add_vertex(m, cc[k][0], cc[k][1],
                        z[(size_t)cc[k][1] * nx + (size_t)cc[k][0]]);
  if (tt__mesh_orient(m, 0, 1, 2) > 0) {
    tt__mesh_add_triangle(m, 0, 1, 2);
    tt__mesh_add_triangle(m, 0, 2, 3);
  } else {
    tt__mesh_add_triangle(m, 0, 2, 1);
    tt__mesh_add_triangle(m, 0, 3, 2);
  }
  tt__mesh_link_all(m);
  tt__mesh_clear_touched(m);
  tt__edge_stack stack = {NULL, 0, 0};
  bool ok = true;
  for (size_t i = 0; i < n && ok; i++)
    ok = insert_point(m, g, pts[2 * i], pts[2 * i + 1], crit, &stack);
  tt__edge_stack_free(&stack);
  return ok;
}

/* n distinct inner points of a w x h grid (not on its border). */
static void random_points(uint64_t *rng, size_t nx, size_t ny, int32_t *pts,
                          size_t n)
{
  for (size_t i = 0; i < n; i++) {
    bool dup;
    do {
      pts[2 * i] = 1 + (int32_t)(tt_test_rand(rng) % (nx - 2));
      pts[2 * i + 1] = 1 + (int32_t)(tt_test_rand(rng) % (ny - 2));
      dup = false;
      for (size_t j = 0; j < i; j++)
        dup |= pts[2 * j] == pts[2 * i] && pts[2 * j + 1] == pts[2 * i + 1];
    } while (dup);
  }
}

static tt_grid *bumpy(size_t nx, size_t ny, uint64_t seed)
{
  tt_grid *g = NULL;
  if (tt_grid_create(ctx, nx, ny, &g) != TT_OK)
    return NULL;
  float *z = tt_grid_heights(g);
  uint64_t rng = seed;
  for (size_t r = 0; r < ny; r++)
    for (size_t c = 0; c < nx; c++)
      z[r * nx + c] = (float)(20 * sin(0.3 * (double)c) * cos(0.2 * (double)r) +
                              5 * tt_test_uniform(&rng));
  return g;
}

/* The largest swap value of a swappable edge (-INFINITY when none). */
static double max_swap_value(const tt__mesh *m, const tt__criterion_vt *crit,
                             const tt_grid *g)
{
  tt__crit_env env = {m, g, NULL};
  double best = -INFINITY;
  for (size_t e = 0; e < 3 * m->nslots; e++)
    if (tt__mesh_live(m, (int32_t)(e / 3)) && m->twin[e] > (int32_t)e &&
        tt__mesh_flippable(m, (int32_t)e)) {
      double v = crit->swap_value(&env, (int32_t)e);
      if (v > best)
        best = v;
    }
  return best;
}

/* --- undo --------------------------------------------------------------- */

static void test_undo(uint64_t seed)
{
  uint64_t rng = seed;
  tt_grid *g = bumpy(30, 20, seed);
  int32_t pts[2 * 25];
  random_points(&rng, 30, 20, pts, 25);
  tt__mesh m;
  CHECK(build(&m, g, pts, 25, NULL));
  check_valid(&m, "undo: start");
  size_t n3 = 3 * m.nslots;
  int32_t *hv = malloc(n3 * sizeof *hv), *tw = malloc(n3 * sizeof *tw);
  tt__mesh_vertex *vv = malloc(m.nv * sizeof *vv);
  memcpy(hv, m.hv, n3 * sizeof *hv);
  memcpy(tw, m.twin, n3 * sizeof *tw);
  memcpy(vv, m.v, m.nv * sizeof *vv);
  int tried = 0;
  for (size_t e = 0; e < n3; e++) {
    if (!tt__mesh_flippable(&m, (int32_t)e))
      continue;
    tt__mesh_flip_undo u1, u2;
    int32_t h = tt__mesh_flip_undoable(&m, (int32_t)e, &u1);
    CHECK(h >= 0);
    check_valid(&m, "undo: after a flip");
    /* a second, neighbouring flip, reverted first */
    int32_t q = tt__next(h);
    bool two = tt__mesh_flippable(&m, q);
    if (two) {
      CHECK(tt__mesh_flip_undoable(&m, q, &u2) >= 0);
      check_valid(&m, "undo: after two flips");
      tt__mesh_flip_revert(&m, &u2);
    }
    tt__mesh_flip_revert(&m, &u1);
    tried++;
    CHECK(memcmp(hv, m.hv, n3 * sizeof *hv) == 0);
    CHECK(memcmp(tw, m.twin, n3 * sizeof *tw) == 0);
    CHECK(memcmp(vv, m.v, m.nv * sizeof *vv) == 0);
    CHECK_INT_EQ(m.ntouched, 0);
  }
  CHECK(tried > 10);
  check_valid(&m, "undo: end");
  free(hv);
  free(tw);
  free(vv);
  tt__mesh_free(&m);
  tt_grid_destroy(g);
}

/* --- local swap and look-ahead ------------------------------------------ */

static void test_local_and_lookahead(uint64_t seed)
{
  int better = 0;
  for (int round = 0; round < 8; round++) {
    uint64_t rng = seed + (uint64_t)round * 7919;
    size_t nx = 40, ny = 33, n = 60;
    tt_grid *g = bumpy(nx, ny, rng);
    int32_t pts[2 * 60];
    random_points(&rng, nx, ny, pts, n);
    tt__mesh a, b;
    CHECK(build(&a, g, pts, n, NULL));
    CHECK(build(&b, g, pts, n, NULL));
    double q0 = total_area(&a);
    tt__crit_env ea = {&a, g, NULL}, eb = {&b, g, NULL};
    tt__opt_params pa = {&area_crit, &ea, false, NULL, NULL};
    tt__opt_params pb = {&area_crit, &eb, true, NULL, NULL};
    tt__opt_stats sa, sb;
    CHECK(tt__optimize_run(&a, &pa, NULL, 0, &sa));
    CHECK(tt__optimize_run(&b, &pb, NULL, 0, &sb));
    check_valid(&a, "local swap");
    check_valid(&b, "look-ahead");
    CHECK(!sa.budget_hit && !sb.budget_hit);
    CHECK_INT_EQ(sa.noisy, 0);
    double va = max_swap_value(&a, &area_crit, g);
    double vb = max_swap_value(&b, &area_crit, g);
    if (!(va <= sa.tol) || !(vb <= sb.tol))
      TT_FAIL_("seed %" PRIu64 " round %d: a positive swap value is left "
               "(local %g, tol %g; look-ahead %g, tol %g)", seed, round, va,
               sa.tol, vb, sb.tol);
    double qa = total_area(&a), qb = total_area(&b);
    CHECK_DBL_LE(qa, q0 + 1e-9 * q0);
    if (!(qb <= qa + 1e-9 * qa))
      TT_FAIL_("seed %" PRIu64 " round %d: look-ahead %.17g worse than "
               "local %.17g", seed, round, qb, qa);
    better += qb < qa - 1e-9 * qa;
    printf("round %d: area Delaunay %.6f local %.6f (%ld swaps) look-ahead "
           "%.6f (%ld swaps, %ld pairs)\n", round, q0, qa, sa.swaps, qb,
           sb.swaps, sb.pairs);
    tt__mesh_free(&a);
    tt__mesh_free(&b);
    tt_grid_destroy(g);
  }
  printf("look-ahead strictly better in %d of 8 rounds\n", better);
}

/* Region repair after every insertion keeps the whole mesh at a local
 * optimum of a criterion whose swap value depends on two triangles. */
static void test_region_repair(uint64_t seed)
{
  uint64_t rng = seed ^ 0x5151;
  tt_grid *g = bumpy(50, 40, rng);
  int32_t pts[2 * 120];
  random_points(&rng, 50, 40, pts, 120);
  tt__mesh m;
  CHECK(build(&m, g, pts, 120, &area_crit));
  check_valid(&m, "region repair");
  double v = max_swap_value(&m, &area_crit, g);
  if (!(v <= 1e-9))
    TT_FAIL_("seed %" PRIu64 ": after region repairs an edge has swap value "
             "%g", seed, v);
  tt__mesh_free(&m);
  tt_grid_destroy(g);
}

/* --- exhaustive search over triangulations ------------------------------ */

#define MAXT 16
typedef struct tri_key {
  uint8_t t[MAXT][3];
  int n;
} tri_key;

static int cmp_tri(const void *x, const void *y)
{
  return memcmp(x, y, 3);
}

static void key_of_mesh(const tt__mesh *m, tri_key *k)
{
  k->n = 0;
  memset(k->t, 0, sizeof k->t);
  for (size_t t = 0; t < m->nslots; t++) {
    if (!tt__mesh_live(m, (int32_t)t))
      continue;
    uint8_t v[3] = {(uint8_t)m->hv[3 * t], (uint8_t)m->hv[3 * t + 1],
                    (uint8_t)m->hv[3 * t + 2]};
    for (int i = 0; i < 2; i++)
      for (int j = 0; j < 2 - i; j++)
        if (v[j] > v[j + 1]) {
          uint8_t s = v[j];
          v[j] = v[j + 1];
          v[j + 1] = s;
        }
    memcpy(k->t[k->n++], v, 3);
  }
  qsort(k->t, (size_t)k->n, 3, cmp_tri);
}

/* Rebuilds a mesh with the vertices of src and the triangles of k. */
static void mesh_of_key(const tt__mesh *src, const tri_key *k, tt__mesh *m)
{
  tt__mesh_init(m, &src->metric);
  for (size_t v = 0; v < src->nv; v++)
    tt__mesh_add_vertex(m, src->v[v].c, src->v[v].r, src->v[v].z);
  for (int i = 0; i < k->n; i++) {
    int32_t a = k->t[i][0], b = k->t[i][1], c = k->t[i][2];
    if (tt__mesh_orient(m, a, b, c) > 0)
      tt__mesh_add_triangle(m, a, b, c);
    else
      tt__mesh_add_triangle(m, a, c, b);
  }
  tt__mesh_link_all(m);
  tt__mesh_clear_touched(m);
}

/* Walks the flip graph from mesh start (it is connected for a planar point
 * set), giving each triangulation the quality of start plus the swap
 * values along the walk. Returns the best relative quality; *out_local
 * gets the relative quality of triangulation `find`. */
static double exhaustive(const tt__mesh *start, const tt__criterion_vt *crit,
                         const tt_grid *g, const tt__mesh *find,
                         double *out_local, size_t *out_count)
{
  size_t cap = 1 << 14, n = 0;
  tri_key *keys = malloc(cap * sizeof *keys);
  double *q = malloc(cap * sizeof *q);
  key_of_mesh(start, &keys[0]);
  q[0] = 0;
  n = 1;
  for (size_t i = 0; i < n; i++) {
    tt__mesh m;
    mesh_of_key(start, &keys[i], &m);
    tt__crit_env env = {&m, g, NULL};
    for (size_t e = 0; e < 3 * m.nslots; e++) {
      if (m.twin[e] < (int32_t)e || !tt__mesh_flippable(&m, (int32_t)e))
        continue;
      double v = crit->swap_value(&env, (int32_t)e);
      tt__mesh_flip_undo u;
      tt__mesh_flip_undoable(&m, (int32_t)e, &u);
      tri_key k;
      key_of_mesh(&m, &k);
      tt__mesh_flip_revert(&m, &u);
      size_t j = 0;
      while (j < n && memcmp(&keys[j], &k, sizeof k) != 0)
        j++;
      if (j == n && n < cap) {
        keys[n] = k;
        q[n++] = q[i] + v;
      }
    }
    tt__mesh_free(&m);
  }
  tri_key kf;
  key_of_mesh(find, &kf);
  double best = -INFINITY;
  *out_local = NAN;
  for (size_t i = 0; i < n; i++) {
    if (q[i] > best)
      best = q[i];
    if (memcmp(&keys[i], &kf, sizeof kf) == 0)
      *out_local = q[i];
  }
  *out_count = n;
  free(keys);
  free(q);
  return best;
}

static void exhaustive_case(const tt__criterion_vt *crit, const tt_grid *g,
                            const int32_t box[4], uint64_t seed, int round,
                            bool must_be_global)
{
  uint64_t rng = seed + 104729u * (uint64_t)round;
  size_t nin = 2 + (size_t)(tt_test_rand(&rng) % 3); /* 6..8 points */
  int32_t pts[8];
  random_points(&rng, (size_t)(box[2] - box[0] + 1),
                (size_t)(box[3] - box[1] + 1), pts, nin);
  for (size_t i = 0; i < nin; i++) {
    pts[2 * i] += box[0];
    pts[2 * i + 1] += box[1];
  }
  tt__mesh start, opt;
  CHECK(build_box(&start, g, box, pts, nin, NULL));
  CHECK(build_box(&opt, g, box, pts, nin, NULL));
  tt__crit_env env = {&opt, g, NULL};
  tt__opt_params p = {crit, &env, false, NULL, NULL};
  tt__opt_stats st;
  CHECK(tt__optimize_run(&opt, &p, NULL, 0, &st));
  check_valid(&opt, "exhaustive");
  double local, count;
  size_t nt;
  double best = exhaustive(&start, crit, g, &opt, &local, &nt);
  count = (double)nt;
  double tol = 1e-9 * (1 + fabs(best));
  if (isnan(local) || local > best + tol)
    TT_FAIL_("%s seed %" PRIu64 " round %d: local optimum %.17g not among "
             "the %g triangulations or above their best %.17g", crit->name,
             seed, round, local, count, best);
  if (must_be_global && !(local >= best - tol))
    TT_FAIL_("%s seed %" PRIu64 " round %d: local swap reached %.17g, the "
             "best of %g triangulations is %.17g", crit->name, seed, round,
             local, count, best);
  tt__mesh_free(&start);
  tt__mesh_free(&opt);
}

static void test_exhaustive(uint64_t seed)
{
  tt_grid *g = bumpy(24, 20, seed);
  const int32_t whole[4] = {0, 0, 23, 19};
  for (int round = 0; round < 12; round++)
    exhaustive_case(&area_crit, g, whole, seed, round, false);
  tt_grid_destroy(g);

  tt_criterion gid;
  tt_context_clear_error(ctx);
  if (tt_criterion_parse(ctx, "gaussian_curvature", &gid) != TT_OK) {
    printf("gaussian_curvature not registered yet: sphere optimum check "
           "skipped\n");
    tt_context_clear_error(ctx);
    return;
  }
  tt_synth_options so;
  tt_synth_options_init(&so, TT_SYNTH_SPHERE);
  tt_grid *sphere = NULL;
  CHECK_OK(ctx, tt_synth_generate(ctx, &so, &sphere));
  if (!sphere)
    return;
  /* a square inside the dome's disc (centre (20, 20), radius 20 samples):
   * the surface over it is a spherical cap, so every point set on it is in
   * convex position */
  const int32_t cap[4] = {8, 8, 32, 32};
  for (int round = 0; round < 12; round++)
    exhaustive_case(tt__criterion_get(gid), sphere, cap, seed, round, true);
  tt_grid_destroy(sphere);
}

/* --- L2 ------------------------------------------------------------------ */

static double total_sq(const tt__mesh *m, const tt_grid *g)
{
  double s = 0;
  for (size_t t = 0; t < m->nslots; t++)
    if (tt__mesh_live(m, (int32_t)t)) {
      tt__scan_tri st;
      tt__scan_stats ss;
      tt__scan_tri_from_mesh(m, (int32_t)t, &st);
      tt__scan_stats_run(g, &st, &ss);
      s += ss.sum_sq;
    }
  return s;
}

static void test_l2_from_delaunay(uint64_t seed)
{
  tt_criterion id;
  tt_context_clear_error(ctx);
  if (tt_criterion_parse(ctx, "l2", &id) != TT_OK) {
    printf("l2 not registered yet: L2-from-Delaunay check skipped\n");
    tt_context_clear_error(ctx);
    return;
  }
  const tt__criterion_vt *l2 = tt__criterion_get(id);
  for (int round = 0; round < 6; round++) {
    uint64_t rng = seed + 31u * (uint64_t)round;
    tt_grid *g = bumpy(48, 40, rng);
    int32_t pts[2 * 80];
    random_points(&rng, 48, 40, pts, 80);
    for (int look = 0; look < 2; look++) {
      tt__mesh m;
      CHECK(build(&m, g, pts, 80, NULL));
      double d = total_sq(&m, g);
      tt__crit_env env = {&m, g, NULL};
      tt__opt_params p = {l2, &env, look == 1, NULL, NULL};
      CHECK(tt__optimize_run(&m, &p, NULL, 0, NULL));
      check_valid(&m, "l2");
      double o = total_sq(&m, g);
      if (!(o <= d * (1 + 1e-9) + 1e-12))
        TT_FAIL_("seed %" PRIu64 " round %d: L2 %s ends at %.17g, Delaunay "
                 "had %.17g", seed, round, look ? "look-ahead" : "local", o,
                 d);
      tt__mesh_free(&m);
    }
    tt_grid_destroy(g);
  }
}

/* Ruled surface z = f(x) + a y: Gaussian and L2 beat Delaunay. */
static void test_ruled(void)
{
  const char *names[] = {"gaussian_curvature", "l2"};
  size_t nx = 65, ny = 65;
  tt_grid *g = NULL;
  CHECK_OK(ctx, tt_grid_create(ctx, nx, ny, &g));
  float *z = tt_grid_heights(g);
  for (size_t r = 0; r < ny; r++)
    for (size_t c = 0; c < nx; c++)
      z[r * nx + c] = (float)(12 * sin(0.21 * (double)c) +
                              0.004 * (double)(c * c) + 0.7 * (double)r);
  tt_refine_options o;
  tt_refine_options_init(&o);
  o.max_error = -1;
  o.max_points = 120;
  o.threads = 1;
  tt_tin *tin = NULL;
  CHECK_OK(ctx, tt_refine_run(ctx, g, &o, &tin));
  tt_tin_summary sd;
  tt_tin_get_summary(tin, &sd);
  tt_tin_destroy(tin);
  for (size_t i = 0; i < 2; i++) {
    tt_criterion id;
    tt_context_clear_error(ctx);
    if (tt_criterion_parse(ctx, names[i], &id) != TT_OK) {
      printf("%s not registered yet: ruled-surface check skipped\n",
             names[i]);
      tt_context_clear_error(ctx);
      continue;
    }
    o.criterion = id;
    CHECK_OK(ctx, tt_refine_run(ctx, g, &o, &tin));
    tt_tin_summary s;
    tt_tin_get_summary(tin, &s);
    CHECK_INT_EQ(s.vertices, sd.vertices);
    printf("ruled surface, %zu vertices: L2 error Delaunay %.6f, %s %.6f\n",
           s.vertices, sd.errors.l2, names[i], s.errors.l2);
    if (!(s.errors.l2 < sd.errors.l2))
      TT_FAIL_("ruled surface: %s L2 %.17g is not below Delaunay's %.17g",
               names[i], s.errors.l2, sd.errors.l2);
    tt_tin_destroy(tin);
  }
  tt_grid_destroy(g);
}

/* --- refinement keeps its bound (independent oracle) --------------------- */

static void test_bound(uint64_t seed)
{
  tt_grid *grids[2] = {bumpy(52, 41, seed), NULL};
  /* the second with nodata: a round lake and a missing corner */
  grids[1] = bumpy(48, 40, seed + 1);
  float *z = tt_grid_heights(grids[1]);
  for (size_t r = 0; r < 40; r++)
    for (size_t c = 0; c < 48; c++)
      if ((double)((c - 24) * (c - 24) + (r - 20) * (r - 20)) < 50 ||
          c + r < 8)
        z[r * 48 + c] = NAN;
  const double bounds[2] = {2.0, 0.5};
  for (int k = 0; k < 64; k++) {
    const char *name = tt_criterion_name((tt_criterion)k);
    if (!name)
      break;
    /* every repair with no final pass (the slow region repairs at the
     * looser bound only), then every final pass after the default repair */
    for (int gi = 0; gi < 2; gi++)
      for (int run = 0; run < 7; run++)
        for (int bi = 0; bi < (run >= 1 && run <= 3 ? 1 : 2); bi++) {
          tt_refine_options o;
          tt_refine_options_init(&o);
          o.criterion = (tt_criterion)k;
          if (run < 4) {
            o.repair = (tt_repair)(TT_REPAIR_FLIP + run);
            o.optimize = TT_OPTIMIZE_NONE;
          } else {
            o.optimize = (tt_optimize)(TT_OPTIMIZE_NONE + run - 4);
          }
          o.max_error = bounds[bi];
          o.threads = 1;
          tt_tin *tin = NULL;
          clock_t c0 = clock();
          CHECK_OK(ctx, tt_refine_run(ctx, grids[gi], &o, &tin));
          if (!tin)
            continue;
          if (getenv("TT_VERBOSE"))
            printf("  %s grid %d %s/%s bound %g: %zu vertices, %.3f s\n",
                   name, gi, tt_repair_name(o.repair),
                   tt_optimize_name(o.optimize), o.max_error,
                   tt_tin_vertex_count(tin),
                   (double)(clock() - c0) / CLOCKS_PER_SEC);
          double *xyz = tt_oracle_pixel_triangles(tin);
          tt_eval_result ev;
          CHECK_OK(ctx, tt_eval_triangles(ctx, grids[gi],
                                          tt_tin_triangle_count(tin), xyz,
                                          &ev));
          if (!(ev.errors.max_error <= o.max_error + 1e-9))
            TT_FAIL_("criterion %s, repair %s, optimize %s, grid %d: max "
                     "error %.17g above the bound %g", name,
                     tt_repair_name(o.repair), tt_optimize_name(o.optimize),
                     gi, ev.errors.max_error, o.max_error);
          CHECK_INT_EQ(ev.overlapped, 0);
          free(xyz);
          tt_tin_destroy(tin);
        }
  }
  tt_grid_destroy(grids[0]);
  tt_grid_destroy(grids[1]);
}

/* The final pass refuses moves that would raise the error past its bound:
 * with the bound at the mesh's present worst error, it never grows. */
static double worst_error(const tt__mesh *m, const tt_grid *g)
{
  double w = 0;
  for (size_t t = 0; t < m->nslots; t++)
    if (tt__mesh_live(m, (int32_t)t)) {
      tt__scan_tri st;
      double err;
      int64_t index;
      tt__scan_tri_from_mesh(m, (int32_t)t, &st);
      tt__scan_candidate(g, &st, &err, &index);
      w = err > w ? err : w;
    }
  return w;
}

/* The flip repair (Lawson outward from the new vertex): after each
 * insertion no edge opposite the new vertex has a positive swap value, the
 * mesh is valid and the criterion acted (it flipped; its total area is
 * printed beside Delaunay's: a flip repair only ever looks at the new
 * vertex's link, so it need not beat Delaunay). The look-ahead repair: a valid mesh at a local optimum
 * (its first phase is the local swap). */
static void test_flip_repair(uint64_t seed)
{
  uint64_t rng = seed ^ 0xf11f;
  tt_grid *g = bumpy(50, 40, rng);
  int32_t pts[2 * 120];
  random_points(&rng, 50, 40, pts, 120);
  tt__mesh m, d;
  tt__edge_stack stack = {NULL, 0, 0};
  insert_repair = TT_REPAIR_FLIP;
  CHECK(build(&m, g, pts, 0, &area_crit));
  tt__crit_env env = {&m, g, NULL};
  long bad = 0, flips = 0;
  for (int i = 0; i < 120; i++) {
    CHECK(insert_point(&m, g, pts[2 * i], pts[2 * i + 1], &area_crit,
                       &stack));
    flips += last_flips;
    int32_t v = (int32_t)m.nv - 1;
    for (size_t t = 0; t < m.nslots; t++)
      for (int k = 0; k < 3 && tt__mesh_live(&m, (int32_t)t); k++) {
        int32_t e = (int32_t)(3 * t) + k;
        if (tt__mesh_apex(&m, e) != v || m.twin[e] < 0 ||
            !tt__mesh_flippable(&m, e))
          continue;
        if (area_crit.swap_value(&env, e) > 1e-9)
          bad++;
      }
  }
  check_valid(&m, "flip repair");
  CHECK_INT_EQ(bad, 0);
  CHECK(build(&d, g, pts, 120, NULL));
  double a_flip = total_area(&m), a_del = total_area(&d);
  printf("flip repair: %ld flips, total area %.6f, Delaunay %.6f\n", flips,
         a_flip, a_del);
  CHECK(flips > 0);
  tt__mesh_free(&m);
  tt__mesh_free(&d);
  insert_repair = TT_REPAIR_LOOKAHEAD;
  CHECK(build(&m, g, pts, 120, &area_crit));
  check_valid(&m, "look-ahead repair");
  double v = max_swap_value(&m, &area_crit, g);
  if (!(v <= 1e-9))
    TT_FAIL_("seed %" PRIu64 ": after look-ahead repairs an edge has swap "
             "value %g", seed, v);
  tt__mesh_free(&m);
  insert_repair = TT_REPAIR_LOCAL;
  tt__edge_stack_free(&stack);
  tt_grid_destroy(g);
}

/* min_area's repair is the exact hole re-triangulation (hole_dp.h) and
 * then the flips from the hole's link: the same mesh as doing those two
 * steps by hand, insertion after insertion. */
static void test_min_area_hole_repair(uint64_t seed)
{
  uint64_t rng = seed ^ 0xa4ea;
  tt_grid *g = bumpy(50, 40, rng);
  int32_t pts[2 * 100];
  random_points(&rng, 50, 40, pts, 100);
  const tt__criterion_vt *ma = tt__criterion_get(TT_CRITERION_MIN_AREA);
  tt__mesh a, b;
  tt__edge_stack stack = {NULL, 0, 0};
  CHECK(build(&a, g, pts, 0, NULL));
  CHECK(build(&b, g, pts, 0, NULL));
  const float *z = tt_grid_heights_const(g);
  long replaced = 0;
  for (int i = 0; i < 100; i++) {
    int32_t c = pts[2 * i], r = pts[2 * i + 1];
    float zz = z[(size_t)r * 50 + (size_t)c];
    tt__mesh *ms[2] = {&a, &b};
    for (int w = 0; w < 2; w++) {
      tt__mesh *m = ms[w];
      int32_t v = tt__mesh_add_vertex(m, c, r, zz);
      int32_t on;
      int32_t t = tt__mesh_locate(m, -1, c, r, &on);
      CHECK(t >= 0 && on >= -1);
      int32_t opp[4];
      int n = on < 0 ? 3 : 4;
      CHECK(on < 0 ? tt__mesh_split_triangle(m, t, v, opp)
                   : tt__mesh_split_edge(m, on, v, opp));
      tt__crit_env env = {m, g, NULL};
      if (w == 0) {
        CHECK(tt__optimize_insert(m, ma, &env, TT_REPAIR_FLIP, v, opp, n,
                                  &stack) >= 0);
      } else {
        int32_t link[TT__HOLE_MAX_N];
        size_t before = m->ntouched;
        int k = tt__hole_min_area(m, &env, v, link, TT__HOLE_MAX_N);
        CHECK(k >= 3);
        replaced += m->ntouched > before + (size_t)n;
        CHECK(tt__swap_repair(m, ma, &env, link, k, &stack) >= 0);
      }
      tt__mesh_clear_touched(m);
    }
  }
  check_valid(&a, "min-area repair");
  CHECK_INT_EQ(a.nslots, b.nslots);
  CHECK(memcmp(a.hv, b.hv, 3 * a.nslots * sizeof *a.hv) == 0);
  CHECK(memcmp(a.twin, b.twin, 3 * a.nslots * sizeof *a.twin) == 0);
  printf("min-area repair: %ld of 100 holes re-triangulated\n", replaced);
  CHECK(replaced > 0);
  tt__edge_stack_free(&stack);
  tt__mesh_free(&a);
  tt__mesh_free(&b);
  tt_grid_destroy(g);
}

/* A criterion's per-run cache (cache_new) never changes a swap value: on a
 * mesh that random flips keep changing, every edge's value with the cache
 * (cold and warm) is the very value without it, and a swap and the swap
 * back stay exact opposites. */
static void test_caches(uint64_t seed)
{
  uint64_t rng = seed ^ 0xcace;
  tt_grid *g = bumpy(48, 36, rng);
  int32_t pts[2 * 80];
  random_points(&rng, 48, 36, pts, 80);
  int tested = 0;
  for (int id = 0; id < 64; id++) {
    const tt__criterion_vt *crit = tt__criterion_get((tt_criterion)id);
    if (!crit || !crit->cache_new)
      continue;
    tt__mesh m;
    CHECK(build(&m, g, pts, 80, NULL));
    tt__crit_env plain = {&m, g, NULL}, cached = {&m, g, NULL};
    cached.cache = crit->cache_new(&cached);
    CHECK(cached.cache != NULL);
    long differ = 0, asym = 0, flips = 0;
    for (int round = 0; round < 40; round++) {
      for (int pass = 0; pass < 2; pass++) /* cold, then warm */
        for (size_t e = 0; e < 3 * m.nslots; e++)
          if (tt__mesh_live(&m, (int32_t)(e / 3)) && m.twin[e] >= 0) {
            double a = crit->swap_value(&plain, (int32_t)e);
            double b = crit->swap_value(&cached, (int32_t)e);
            if (memcmp(&a, &b, sizeof a) != 0)
              differ++;
          }
      /* a random flippable edge: flip, compare the swap back, maybe keep */
      for (int tries = 0; tries < 100; tries++) {
        int32_t e = (int32_t)(tt_test_rand(&rng) % (3 * m.nslots));
        if (!tt__mesh_live(&m, e / 3) || m.twin[e] < 0 ||
            (m.eflag[e] & TT__EDGE_CONSTRAINED) || !tt__mesh_flippable(&m, e))
          continue;
        double v = crit->swap_value(&cached, e);
        int32_t h = tt__mesh_flip(&m, e);
        CHECK(h >= 0);
        double r = crit->swap_value(&cached, h);
        if (v != -r)
          asym++;
        flips++;
        break;
      }
    }
    check_valid(&m, "cache test");
    printf("%s cache: %ld flips, %ld differing values, %ld asymmetric\n",
           crit->name, flips, differ, asym);
    CHECK_INT_EQ(differ, 0);
    CHECK_INT_EQ(asym, 0);
    CHECK(flips > 20);
    crit->cache_free(cached.cache);
    tt__mesh_free(&m);
    tested++;
  }
  CHECK(tested >= 1);
  tt_grid_destroy(g);
}

static void test_final_veto(uint64_t seed)
{
  uint64_t rng = seed ^ 0xfeed;
  tt_grid *g = bumpy(60, 45, rng);
  int32_t pts[2 * 90];
  random_points(&rng, 60, 45, pts, 90);
  for (int mode = TT_OPTIMIZE_LOCAL; mode <= TT_OPTIMIZE_LOOKAHEAD; mode++) {
    tt__mesh m;
    CHECK(build(&m, g, pts, 90, NULL));
    double before = worst_error(&m, g);
    tt__crit_env env = {&m, g, NULL};
    tt__opt_stats st;
    double bound = 0.8 * before; /* already passed: nothing may rise */
    CHECK(tt__optimize_final(&m, &area_crit, &env, (tt_optimize)mode,
                             TT_REPAIR_FLIP, bound, NULL, &st));
    check_valid(&m, "final pass");
    double after = worst_error(&m, g);
    CHECK_DBL_LE(after, before);
    printf("final pass %s: %ld swaps, %ld pairs, %ld refused; worst error "
           "%.4f -> %.4f\n", tt_optimize_name((tt_optimize)mode), st.swaps,
           st.pairs, st.refused, before, after);
    CHECK(st.refused > 0);
    tt__mesh_free(&m);
  }
  tt_grid_destroy(g);
}

static void test_names(void)
{
  CHECK_STR_EQ(tt_optimize_name(TT_OPTIMIZE_AUTO), "auto");
  CHECK_STR_EQ(tt_optimize_name(TT_OPTIMIZE_LOOKAHEAD), "lookahead");
  CHECK(tt_optimize_name((tt_optimize)17) == NULL);
  tt_optimize o = TT_OPTIMIZE_AUTO;
  CHECK_OK(ctx, tt_optimize_parse(ctx, "local", &o));
  CHECK_INT_EQ(o, TT_OPTIMIZE_LOCAL);
  CHECK_INT_EQ(tt_optimize_parse(ctx, "global", &o), TT_ERR_ARG);
  CHECK(strstr(tt_context_errmsg(ctx), "global") != NULL);
  tt_refine_options ro;
  tt_refine_options_init(&ro);
  CHECK_INT_EQ(ro.optimize, TT_OPTIMIZE_AUTO);
  CHECK_INT_EQ(ro.repair, TT_REPAIR_AUTO);
  /* repair names and what auto means */
  CHECK_STR_EQ(tt_repair_name(TT_REPAIR_FLIP), "flip");
  CHECK_STR_EQ(tt_repair_name(TT_REPAIR_DELAUNAY), "delaunay");
  CHECK(tt_repair_name((tt_repair)9) == NULL);
  tt_repair rp = TT_REPAIR_AUTO;
  CHECK_OK(ctx, tt_repair_parse(ctx, "lookahead", &rp));
  CHECK_INT_EQ(rp, TT_REPAIR_LOOKAHEAD);
  CHECK_INT_EQ(tt_repair_parse(ctx, "lawson", &rp), TT_ERR_ARG);
  CHECK(strstr(tt_context_errmsg(ctx), "lawson") != NULL);
  CHECK_INT_EQ(tt_repair_resolve(TT_REPAIR_AUTO, TT_CRITERION_L2),
               TT_REPAIR_DELAUNAY);
  CHECK_INT_EQ(tt_repair_resolve(TT_REPAIR_AUTO, TT_CRITERION_ABN),
               TT_REPAIR_FLIP);
  CHECK_INT_EQ(tt_repair_resolve(TT_REPAIR_LOCAL, TT_CRITERION_L2),
               TT_REPAIR_LOCAL);
  CHECK_INT_EQ(tt_optimize_resolve(TT_OPTIMIZE_AUTO, TT_CRITERION_L2,
                                   TT_REPAIR_AUTO), TT_OPTIMIZE_LOCAL);
  CHECK_INT_EQ(tt_optimize_resolve(TT_OPTIMIZE_AUTO, TT_CRITERION_L2,
                                   TT_REPAIR_FLIP), TT_OPTIMIZE_NONE);
  CHECK_INT_EQ(tt_optimize_resolve(TT_OPTIMIZE_AUTO, TT_CRITERION_DELAUNAY,
                                   TT_REPAIR_DELAUNAY), TT_OPTIMIZE_NONE);
  CHECK_INT_EQ(tt_optimize_resolve(TT_OPTIMIZE_AUTO, TT_CRITERION_GAUSSIAN_CURVATURE,
                                   TT_REPAIR_DELAUNAY), TT_OPTIMIZE_LOCAL);
  CHECK_INT_EQ(tt_optimize_resolve(TT_OPTIMIZE_LOOKAHEAD, TT_CRITERION_L2,
                                   TT_REPAIR_FLIP), TT_OPTIMIZE_LOOKAHEAD);
}

int main(void)
{
  setvbuf(stdout, NULL, _IOLBF, 0);
  ctx = tt_context_create();
  uint64_t seed = 20260421;
  const char *env = getenv("TT_SEED");
  if (env)
    seed = strtoull(env, NULL, 10);
  printf("seed %" PRIu64 " (TT_SEED=%" PRIu64 " replays it)\n", seed, seed);
  clock_t c0 = clock();
#define RUN(call)                                                            \
  do {                                                                       \
    call;                                                                    \
    printf("%-32s %.2f s\n", #call,                                         \
           (double)(clock() - c0) / CLOCKS_PER_SEC);                         \
    c0 = clock();                                                            \
  } while (0)
  RUN(test_names());
  RUN(test_undo(seed));
  RUN(test_local_and_lookahead(seed));
  RUN(test_region_repair(seed));
  RUN(test_flip_repair(seed));
  RUN(test_caches(seed));
  RUN(test_min_area_hole_repair(seed));
  RUN(test_exhaustive(seed));
  RUN(test_l2_from_delaunay(seed));
  RUN(test_ruled());
  RUN(test_final_veto(seed));
  RUN(test_bound(seed));
  tt_context_destroy(ctx);
  TT_TEST_DONE();
}
