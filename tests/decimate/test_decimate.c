/* test_decimate.c -- vertex decimation runs, checked by independent
 * oracles:
 *  - the mesh is valid (tt__mesh_validate) after every removal of
 *    randomised runs, for every importance, selection and criterion;
 *  - the exact bound: a brute-force scan of every valid sample against
 *    every triangle (tt_eval_triangles, its own rasteriser) finds no error
 *    above -max_error, with every importance and selection, on terrains
 *    with and without nodata; no nodata sample lies inside a triangle and
 *    every valid sample a triangle can carry is covered;
 *  - the count stops are exact; grid corners stay;
 *  - same input, same bytes, whatever the thread count;
 *  - a grid of doubles keeps the bound and the exact heights;
 *  - progress goes forward and a callback returning 0 interrupts;
 *  - options are checked. */
#include "decimate/decimate.h"
#include "terratin/terratin.h"
#include "tt_test.h"
#include "tt_tin_oracle.h"

#include <stdbool.h>

static tt_context *ctx;

/* Sines plus hashed noise; with holes > 0 a few round nodata holes and a
 * nodata corner. */
static tt_grid *terrain(size_t nx, size_t ny, uint64_t seed, double noise,
                        int holes)
{
  tt_grid *g = NULL;
  if (tt_grid_create(ctx, nx, ny, &g) != TT_OK)
    return NULL;
  float *z = tt_grid_heights(g);
  uint64_t rng = seed;
  for (size_t r = 0; r < ny; r++)
    for (size_t c = 0; c < nx; c++)
      z[r * nx + c] = (float)(50 * sin(0.11 * (double)c) *
                                  cos(0.07 * (double)r) +
                              20 * sin(0.031 * (double)(c + 2 * r)) +
                              noise * tt_test_uniform(&rng));
  for (int h = 0; h < holes; h++) {
    double cx = tt_test_uniform(&rng) * (double)nx;
    double cy = tt_test_uniform(&rng) * (double)ny;
    double rad = 2 + 4 * tt_test_uniform(&rng);
    for (size_t r = 0; r < ny; r++)
      for (size_t c = 0; c < nx; c++)
        if (hypot((double)c - cx, (double)r - cy) < rad)
          z[r * nx + c] = NAN;
  }
  if (holes)
    for (size_t r = 0; r < ny / 4; r++)
      for (size_t c = 0; c + r < nx / 4; c++)
        z[r * nx + c] = NAN;
  return g;
}

typedef struct checker {
  size_t calls, bad;
  uint64_t seed;
  bool count_only; /* count the removals, validate none */
} checker;

static void check_mesh(void *arg, const tt__mesh *m, int32_t v)
{
  checker *k = arg;
  char why[256];
  k->calls++;
  if (k->count_only)
    return;
  if (m->v[v].edge != -1 || !tt__mesh_validate(m, why, sizeof why)) {
    if (k->bad++ < 3)
      TT_FAIL_("seed %llu: invalid mesh after removing %d: %s",
               (unsigned long long)k->seed, (int)v,
               m->v[v].edge != -1 ? "vertex still linked" : why);
  }
}

/* Max error of the TIN by the brute-force oracle; also the coverage. */
static double oracle_max(const tt_grid *g, const tt_tin *tin,
                         size_t *out_uncovered)
{
  double *tri = tt_oracle_pixel_triangles(tin);
  tt_eval_result er;
  CHECK_OK(ctx, tt_eval_triangles(ctx, g, tt_tin_triangle_count(tin), tri,
                                  &er));
  free(tri);
  CHECK_INT_EQ(er.overlapped, 0);
  CHECK_INT_EQ(er.degenerate, 0);
  CHECK_INT_EQ(tt_oracle_nodata_inside(g, tin), 0);
  *out_uncovered = er.uncovered;
  return er.errors.max_error;
}

static bool same_tin(const tt_tin *a, const tt_tin *b)
{
  if (tt_tin_vertex_count(a) != tt_tin_vertex_count(b) ||
      tt_tin_triangle_count(a) != tt_tin_triangle_count(b))
    return false;
  for (size_t i = 0; i < tt_tin_vertex_count(a); i++) {
    tt_vertex_info x, y;
    tt_tin_vertex(a, i, &x);
    tt_tin_vertex(b, i, &y);
    if (x.col != y.col || x.row != y.row ||
        memcmp(&x.importance, &y.importance, sizeof(double)) != 0)
      return false;
  }
  for (size_t i = 0; i < tt_tin_triangle_count(a); i++) {
    tt_triangle_info x, y;
    tt_tin_triangle(a, i, &x);
    tt_tin_triangle(b, i, &y);
    if (memcmp(x.v, y.v, sizeof x.v) != 0)
      return false;
  }
  return true;
}

static const tt_importance IMPORTANCES[] = {
    TT_IMPORTANCE_DEGREE, TT_IMPORTANCE_HDH,  TT_IMPORTANCE_ABH,
    TT_IMPORTANCE_VOLUME, TT_IMPORTANCE_DROP, TT_IMPORTANCE_ERROR};

/* Every importance x selection (x onepass), on terrain with and without
 * nodata, from every start: the bound holds by the oracle, the mesh stays
 * valid after each removal. 108 runs on each of two terrains: 19 x 17
 * samples validating the whole mesh after every removal (quadratic in the
 * size), 27 x 25 counting the removals only; all of it on 41 x 37 took
 * 38 s of the test's 39 in Release and 4 minutes under ASan. */
static void test_exact_bound(void)
{
  for (int run = 0; run < 4; run++) {
    int holes = run % 2, big = run / 2;
    tt_grid *g = big ? terrain(27, 25, 7 + (uint64_t)holes, 3.0, holes ? 3 : 0)
                     : terrain(19, 17, 7 + (uint64_t)holes, 3.0, holes ? 2 : 0);
    size_t valid = 0;
    tt_grid_check(ctx, g, &valid);
    size_t uncarriable = tt_oracle_uncarriable(g);
    for (size_t ii = 0; ii < sizeof IMPORTANCES / sizeof *IMPORTANCES; ii++)
      for (int sel = 0; sel < 3; sel++)
        for (int st = 0; st < 3; st++) {
          tt_decimate_options o;
          tt_decimate_options_init(&o);
          o.max_error = 2.5;
          o.importance = IMPORTANCES[ii];
          o.selection = sel == 2 ? TT_SELECTION_SEQUENTIAL
                                 : TT_SELECTION_INDEPENDENT;
          o.onepass = sel == 1;
          o.start = (tt_decimate_start)st;
          o.start_points = big ? 270 : 130; /* 40 % of the samples */
          checker k = {0, 0, (uint64_t)(ii * 100 + (size_t)sel * 10 +
                                        (size_t)st), big};
          tt_tin *tin = NULL;
          CHECK_OK(ctx, tt__decimate_run_checked(ctx, g, &o, check_mesh, &k,
                                                 &tin));
          if (!tin)
            continue;
          size_t unc = 0;
          double mx = oracle_max(g, tin, &unc);
          tt_tin_summary s;
          tt_tin_get_summary(tin, &s);
          if (st != TT_DSTART_GREEDY_N)
            CHECK_DBL_LE(mx, 2.5 + 1e-9);
          CHECK_INT_EQ(unc, uncarriable);
          CHECK_INT_EQ(s.stop_reason, TT_STOP_MAX_ERROR);
          CHECK_INT_EQ(s.removed_vertices, k.calls);
          CHECK_INT_EQ(s.start_vertices - s.removed_vertices, s.vertices);
          CHECK(s.vertices < valid / 3);
          if (tt_test_failures)
            fprintf(stderr, "  (%s, holes %d importance %s selection %d "
                    "start %d: %zu vertices, max %g)\n",
                    big ? "27 x 25" : "19 x 17", holes,
                    tt_importance_name(o.importance), sel, st, s.vertices,
                    mx);
          tt_tin_destroy(tin);
        }
    tt_grid_destroy(g);
  }
}

/* Randomised terrains and criteria, validate() after every removal, the
 * count stops exact. */
static void test_random_runs(void)
{
  static const tt_criterion crits[] = {
      TT_CRITERION_DELAUNAY,   TT_CRITERION_MINMAX_ANGLE,
      TT_CRITERION_MIN_AREA,   TT_CRITERION_MEAN_CURVATURE,
      TT_CRITERION_GAUSSIAN_CURVATURE, TT_CRITERION_ABN,
      TT_CRITERION_L2};
  for (uint64_t seed = 1; seed <= 14; seed++) {
    uint64_t rng = seed * 7919;
    size_t nx = 12 + (size_t)(tt_test_uniform(&rng) * 30);
    size_t ny = 12 + (size_t)(tt_test_uniform(&rng) * 30);
    tt_grid *g = terrain(nx, ny, seed, 10.0 * tt_test_uniform(&rng),
                         (int)(seed % 3));
    size_t valid = 0;
    tt_grid_check(ctx, g, &valid);
    tt_decimate_options o;
    tt_decimate_options_init(&o);
    o.criterion = crits[seed % 7];
    o.importance = IMPORTANCES[seed % 6];
    o.selection = seed % 2 ? TT_SELECTION_SEQUENTIAL
                           : TT_SELECTION_INDEPENDENT;
    o.hole = (tt_hole)(1 + seed % 2);
    o.repair = (tt_repair)(seed % 5);
    if (seed % 4 == 0)
      o.max_triangles = valid / 5;
    else
      o.max_points = valid / 10 + 4;
    checker k = {0, 0, seed, false};
    tt_tin *tin = NULL;
    tt_status st = tt__decimate_run_checked(ctx, g, &o, check_mesh, &k, &tin);
    if (st == TT_ERR_LIMIT && o.max_points) {
      /* a budget below what the nodata outline forces is refused before
       * the run, with the count to ask for: exactly that count works */
      const char *at = strstr(tt_context_errmsg(ctx), "ask for at least ");
      CHECK(at != NULL);
      size_t need = at ? (size_t)strtoul(at + 17, NULL, 10) : 0;
      CHECK(need > o.max_points);
      o.max_points = need;
      k = (checker){0, 0, seed, false};
      st = tt__decimate_run_checked(ctx, g, &o, check_mesh, &k, &tin);
      if (st == TT_OK) {
        tt_tin_summary s;
        tt_tin_get_summary(tin, &s);
        CHECK(s.vertices == need);
      }
    }
    CHECK_OK(ctx, st);
    if (tin) {
      tt_tin_summary s;
      tt_tin_get_summary(tin, &s);
      if (s.stop_reason == TT_STOP_EXHAUSTED) {
        /* only vertices that may not go are left (outline corners) */
        for (size_t i = 0; i < s.vertices; i++) {
          tt_vertex_info vi;
          tt_tin_vertex(tin, i, &vi);
          CHECK(isnan(vi.importance));
        }
        CHECK(s.vertices > o.max_points);
      } else if (o.max_points)
        CHECK_INT_EQ(s.vertices, o.max_points);
      else
        CHECK(s.triangles <= o.max_triangles &&
              s.triangles + 2 >= o.max_triangles);
      CHECK(k.calls > 0);
      if (seed % 3 == 0) {
        /* the four grid corners stay */
        int corners = 0;
        for (size_t i = 0; i < s.vertices; i++) {
          tt_vertex_info vi;
          tt_tin_vertex(tin, i, &vi);
          corners += (vi.col == 0 || (size_t)vi.col == nx - 1) &&
                     (vi.row == 0 || (size_t)vi.row == ny - 1);
          if (((vi.col == 0 || (size_t)vi.col == nx - 1) &&
               (vi.row == 0 || (size_t)vi.row == ny - 1)))
            CHECK(isnan(vi.importance));
          CHECK(isnan(vi.insert_error));
        }
        CHECK_INT_EQ(corners, 4);
      }
      size_t unc;
      (void)oracle_max(g, tin, &unc);
      CHECK_INT_EQ(unc, tt_oracle_uncarriable(g));
      tt_tin_destroy(tin);
    }
    if (tt_test_failures)
      fprintf(stderr, "  (seed %llu)\n", (unsigned long long)seed);
    tt_grid_destroy(g);
  }
}

/* The error importance at the stop is the error the removal would cause:
 * every remaining removable vertex would break the bound. */
static void test_final_importance(void)
{
  tt_grid *g = terrain(33, 33, 3, 2.0, 0);
  tt_decimate_options o;
  tt_decimate_options_init(&o);
  o.max_error = 1.5;
  o.selection = TT_SELECTION_SEQUENTIAL;
  o.optimize = TT_OPTIMIZE_NONE;
  tt_tin *tin = NULL;
  CHECK_OK(ctx, tt_decimate_run(ctx, g, &o, &tin));
  size_t removable = 0;
  for (size_t i = 0; tin && i < tt_tin_vertex_count(tin); i++) {
    tt_vertex_info vi;
    tt_tin_vertex(tin, i, &vi);
    if (!isnan(vi.importance)) {
      removable++;
      CHECK(vi.importance > 1.5);
    }
  }
  CHECK(removable > 0);
  tt_tin_destroy(tin);
  tt_grid_destroy(g);
}

/* Same bytes whatever the thread count, for each selection. */
static void test_determinism(void)
{
  tt_grid *g = terrain(90, 70, 11, 4.0, 2);
  for (int sel = 0; sel < 2; sel++)
    for (int st = 0; st < 2; st++) {
      tt_tin *t[3] = {NULL, NULL, NULL};
      for (int i = 0; i < 3; i++) {
        tt_decimate_options o;
        tt_decimate_options_init(&o);
        o.max_error = 1.0;
        o.selection = (tt_selection)sel;
        o.start = (tt_decimate_start)st;
        o.threads = i == 0 ? 1 : 2 * i;
        CHECK_OK(ctx, tt_decimate_run(ctx, g, &o, &t[i]));
      }
      if (t[0] && t[1] && t[2]) {
        CHECK(same_tin(t[0], t[1]));
        CHECK(same_tin(t[0], t[2]));
      }
      for (int i = 0; i < 3; i++)
        tt_tin_destroy(t[i]);
    }
  tt_grid_destroy(g);
}

/* Independent sets and percent: the last round is cut so the count is
 * exact; the first round removes a large share (maximal sets). */
static void test_stops(void)
{
  tt_grid *g = terrain(50, 50, 5, 1.0, 0);
  tt_decimate_options o;
  tt_decimate_options_init(&o);
  o.percent = 7.0;
  o.importance = TT_IMPORTANCE_HDH;
  tt_tin *tin = NULL;
  CHECK_OK(ctx, tt_decimate_run(ctx, g, &o, &tin));
  tt_tin_summary s;
  if (tin) {
    tt_tin_get_summary(tin, &s);
    CHECK_INT_EQ(s.vertices, 175);
    CHECK_INT_EQ(s.stop_reason, TT_STOP_MAX_POINTS);
    CHECK(s.rounds >= 2);
  }
  tt_tin_destroy(tin);
  /* one round of a 2500-vertex grid: about a quarter goes */
  o.percent = 0;
  o.max_points = 2500 - 1;
  CHECK_OK(ctx, tt_decimate_run(ctx, g, &o, &tin));
  tt_tin_destroy(tin);
  o.max_points = 0;
  o.max_error = 0.25;
  o.max_triangles = 900;
  CHECK_OK(ctx, tt_decimate_run(ctx, g, &o, &tin));
  if (tin) {
    tt_tin_get_summary(tin, &s);
    CHECK(s.stop_reason == TT_STOP_MAX_ERROR ||
          (s.stop_reason == TT_STOP_MAX_TRIANGLES && s.triangles <= 900));
  }
  tt_tin_destroy(tin);
  tt_grid_destroy(g);
}

/* A grid of doubles (heights no float holds, about 10^6 + cm): the bound
 * still holds at every sample by the oracle, and the vertices keep their
 * exact heights. */
static void test_double_heights(void)
{
  tt_grid *g = terrain(40, 30, 21, 0.3, 0);
  CHECK(tt__grid_widen(g));
  for (size_t i = 0; i < 40 * 30; i++)
    g->zd[i] = 1e6 + g->zd[i] * 0.01 + 1e-4 * (double)(i % 7);
  for (int sel = 0; sel < 2; sel++) {
    tt_decimate_options o;
    tt_decimate_options_init(&o);
    o.max_error = 0.05;
    o.selection = (tt_selection)sel;
    tt_tin *tin = NULL;
    CHECK_OK(ctx, tt_decimate_run(ctx, g, &o, &tin));
    if (!tin)
      continue;
    size_t unc;
    CHECK_DBL_LE(oracle_max(g, tin, &unc), 0.05 + 1e-9);
    CHECK(tt_tin_vertex_count(tin) < 40 * 30 / 2);
    for (size_t i = 0; i < tt_tin_vertex_count(tin); i++) {
      tt_vertex_info vi;
      tt_tin_vertex(tin, i, &vi);
      CHECK(vi.z == g->zd[(size_t)vi.row * 40 + (size_t)vi.col]);
    }
    tt_tin_destroy(tin);
  }
  tt_grid_destroy(g);
}

typedef struct stopper {
  int calls, stop_at;
  double last;
  bool backwards;
} stopper;

static int stop_progress(double complete, const char *message, void *arg)
{
  (void)message;
  stopper *st = arg;
  st->backwards |= complete < st->last;
  st->last = complete;
  return ++st->calls < st->stop_at;
}

/* The progress callback sees fractions that never go back; returning 0
 * stops the run with TT_ERR_INTERRUPTED and no TIN. */
static void test_interrupt(void)
{
  tt_grid *g = terrain(80, 80, 9, 1.0, 0);
  tt_decimate_options o;
  tt_decimate_options_init(&o);
  o.percent = 5;
  o.importance = TT_IMPORTANCE_HDH;
  stopper st = {0, 1 << 30, 0, false};
  o.progress = stop_progress;
  o.progress_arg = &st;
  tt_tin *tin = NULL;
  CHECK_OK(ctx, tt_decimate_run(ctx, g, &o, &tin));
  CHECK(tin != NULL);
  CHECK(st.calls >= 3);
  CHECK(!st.backwards);
  CHECK_DBL_NEAR(st.last, 1.0, 0);
  tt_tin_destroy(tin);
  for (int at = 1; at <= 3; at++) {
    stopper s2 = {0, at, 0, false};
    o.progress_arg = &s2;
    tin = NULL;
    CHECK_INT_EQ(tt_decimate_run(ctx, g, &o, &tin), TT_ERR_INTERRUPTED);
    CHECK(tin == NULL);
  }
  tt_grid_destroy(g);
}

static void test_options(void)
{
  tt_grid *g = terrain(10, 10, 1, 0, 0);
  tt_decimate_options o;
  tt_tin *tin = NULL;
  tt_decimate_options_init(&o);
  CHECK_INT_EQ(tt_decimate_run(ctx, g, &o, &tin), TT_ERR_ARG); /* no stop */
  o.max_error = 1;
  o.hole = TT_HOLE_DP;
  o.criterion = TT_CRITERION_L2;
  CHECK_INT_EQ(tt_decimate_run(ctx, g, &o, &tin), TT_ERR_ARG);
  o.criterion = TT_CRITERION_MIN_AREA;
  CHECK_OK(ctx, tt_decimate_run(ctx, g, &o, &tin));
  tt_tin_destroy(tin);
  o.onepass = 1;
  o.selection = TT_SELECTION_SEQUENTIAL;
  CHECK_INT_EQ(tt_decimate_run(ctx, g, &o, &tin), TT_ERR_ARG);
  tt_decimate_start st;
  size_t n = 0;
  CHECK_OK(ctx, tt_decimate_start_parse(ctx, "greedy:100000", &st, &n));
  CHECK_INT_EQ(st, TT_DSTART_GREEDY_N);
  CHECK_INT_EQ(n, 100000);
  CHECK_INT_EQ(tt_decimate_start_parse(ctx, "greedy:x", &st, &n), TT_ERR_ARG);
  CHECK_INT_EQ(tt_decimate_start_parse(ctx, "greedy:", &st, &n), TT_ERR_ARG);
  tt_importance imp;
  CHECK_OK(ctx, tt_importance_parse(ctx, "drop", &imp));
  CHECK_INT_EQ(imp, TT_IMPORTANCE_DROP);
  CHECK_STR_EQ(tt_importance_name(TT_IMPORTANCE_ABH), "abh");
  CHECK_STR_EQ(tt_hole_name(TT_HOLE_CIRCUMRADIUS), "circumradius");
  CHECK_STR_EQ(tt_selection_name(TT_SELECTION_SEQUENTIAL), "sequential");
  CHECK(tt_importance_name((tt_importance)99) == NULL);
  tt_grid_destroy(g);
}

int main(void)
{
  ctx = tt_context_create();
  TT_RUN(test_options());
  TT_RUN(test_stops());
  TT_RUN(test_random_runs());
  TT_RUN(test_exact_bound());
  TT_RUN(test_final_importance());
  TT_RUN(test_determinism());
  TT_RUN(test_double_heights());
  TT_RUN(test_interrupt());
  tt_context_destroy(ctx);
  TT_TEST_DONE();
}
