/* test_curves.c -- the per-step error measures of a recorded run (issue 15,
 * tt_refine_options.step, tt_decimate_options.step), against full passes:
 *  - at chosen point counts, the step's measures equal those of a single
 *    run stopped there (tt_tin_summary.errors, one pass over every sample)
 *    and of tt_eval_triangles on that TIN (an independent barycentric
 *    scan), to 1e-12 relative (the max exactly), on several terrains, with
 *    nodata, floats and doubles, under criteria with and without a final
 *    pass (those steps are measured on an optimised copy);
 *  - recording changes no TIN; the last step is the TIN returned;
 *  - the running totals do not drift: a run to zero error ends at zero;
 *  - the callback stops a run; step_at without step_until; the same
 *    sums with and without threads;
 *  - decimation reports every round (every removal, sequential), its last
 *    step is the TIN returned. */
#include "terratin/terratin.h"
#include "tt_test.h"

#include <stdbool.h>
#include <stdint.h>

static tt_context *ctx;

/* Sines and hashed noise, with an optional ring of nodata. */
static tt_grid *terrain(size_t nx, size_t ny, uint64_t seed, double noise,
                        bool holes, bool f64)
{
  double *z = malloc(nx * ny * sizeof *z);
  uint64_t rng = seed;
  for (size_t r = 0; r < ny; r++)
    for (size_t c = 0; c < nx; c++) {
      double v = 50 * sin(0.11 * (double)c) * cos(0.07 * (double)r) +
                 20 * sin(0.031 * (double)(c + 2 * r)) +
                 noise * tt_test_uniform(&rng);
      /* doubles that no float holds, floats otherwise */
      z[r * nx + c] = f64 ? v + 1e-7 * (double)(c % 7) : (double)(float)v;
      double dc = (double)c - 0.3 * (double)nx, dr = (double)r - 0.6 * (double)ny;
      if (holes && dc * dc + dr * dr < 30)
        z[r * nx + c] = NAN;
      if (holes && c == nx - 1 && r < 5)
        z[r * nx + c] = NAN;
    }
  tt_grid *g = NULL;
  if (f64) {
    CHECK_OK(ctx, tt_grid_create_from_doubles(ctx, nx, ny, z, &g));
  } else {
    float *zf = malloc(nx * ny * sizeof *zf);
    for (size_t i = 0; i < nx * ny; i++)
      zf[i] = (float)z[i];
    CHECK_OK(ctx, tt_grid_create_from_floats(ctx, nx, ny, zf, &g));
    free(zf);
  }
  free(z);
  return g;
}

/* Steps as the callback saw them. */
typedef struct log_t {
  tt_step_info s[4096];
  size_t n;
  size_t stop_after; /* 0: never stop */
} log_t;

static int record(const tt_step_info *s, void *arg)
{
  log_t *l = arg;
  if (l->n < sizeof l->s / sizeof l->s[0])
    l->s[l->n++] = *s;
  return !(l->stop_after && l->n >= l->stop_after);
}

static bool near_rel(double a, double b, double rel)
{
  return fabs(a - b) <= rel * fmax(fabs(a), fabs(b)) || (a == 0 && b == 0);
}

static void check_errors(const char *what, size_t points,
                         const tt_error_stats *a, const tt_error_stats *b,
                         double rel, bool exact_max)
{
  if (a->samples != b->samples || a->covered != b->covered ||
      (exact_max ? a->max_error != b->max_error
                 : !near_rel(a->max_error, b->max_error, rel)) ||
      !near_rel(a->total_abs, b->total_abs, rel) ||
      !near_rel(a->mean_abs, b->mean_abs, rel) ||
      !near_rel(a->l2, b->l2, rel) || !near_rel(a->rmse, b->rmse, rel))
    TT_FAIL_("%s at %zu points: step samples %zu covered %zu max %.17g "
             "total %.17g l2 %.17g rmse %.17g; full pass %zu %zu %.17g "
             "%.17g %.17g %.17g", what, points, a->samples, a->covered,
             a->max_error, a->total_abs, a->l2, a->rmse, b->samples,
             b->covered, b->max_error, b->total_abs, b->l2, b->rmse);
}

/* The TIN's triangles as tt_eval_triangles takes them. */
static void eval_tin(const tt_grid *g, const tt_tin *tin, tt_eval_result *out)
{
  size_t nt = tt_tin_triangle_count(tin);
  double *p = malloc(9 * (nt ? nt : 1) * sizeof *p);
  for (size_t t = 0; t < nt; t++) {
    tt_triangle_info ti;
    CHECK_OK(ctx, tt_tin_triangle(tin, t, &ti));
    for (int k = 0; k < 3; k++) {
      tt_vertex_info vi;
      CHECK_OK(ctx, tt_tin_vertex(tin, (size_t)ti.v[k], &vi));
      p[9 * t + 3 * k] = vi.col;
      p[9 * t + 3 * k + 1] = vi.row;
      p[9 * t + 3 * k + 2] = vi.z;
    }
  }
  CHECK_OK(ctx, tt_eval_triangles(ctx, g, nt, p, out));
  free(p);
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
    if (x.col != y.col || x.row != y.row)
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

/* One recorded run to `until` points (and the counts of at), each checked
 * step compared with a single run stopped there. */
static void check_curve(const char *name, const tt_grid *g,
                        tt_criterion crit, tt_optimize optimize,
                        tt_repair repair, size_t until, const size_t *at,
                        size_t nat, const size_t *check, size_t ncheck)
{
  static log_t l;
  memset(&l, 0, sizeof l);
  tt_refine_options o;
  tt_refine_options_init(&o);
  o.max_error = -1;
  o.criterion = crit;
  o.optimize = optimize;
  o.repair = repair;
  size_t most = until;
  for (size_t i = 0; i < nat; i++)
    most = at[i] > most ? at[i] : most;
  o.max_points = most;
  tt_tin *plain = NULL, *rec = NULL;
  CHECK_OK(ctx, tt_refine_run(ctx, g, &o, &plain));
  o.step = record;
  o.step_arg = &l;
  o.step_until = until;
  o.step_at = at;
  o.nstep_at = nat;
  CHECK_OK(ctx, tt_refine_run(ctx, g, &o, &rec));
  if (!plain || !rec)
    return;
  if (!same_tin(plain, rec))
    TT_FAIL_("%s %s: recording changed the TIN", name, tt_criterion_name(crit));
  /* the steps: every count up to until, then the at counts, then last */
  CHECK(l.n >= 2);
  CHECK(l.s[l.n - 1].last);
  tt_tin_summary sum;
  tt_tin_get_summary(rec, &sum);
  CHECK_INT_EQ(l.s[l.n - 1].points, sum.vertices);
  CHECK_INT_EQ(l.s[l.n - 1].triangles, sum.triangles);
  check_errors(name, sum.vertices, &l.s[l.n - 1].errors, &sum.errors, 1e-12,
               true);
  size_t start = l.s[0].points;
  CHECK_INT_EQ(l.s[0].step, 0);
  for (size_t i = 1; i + 1 < l.n; i++) {
    CHECK_INT_EQ(l.s[i].step, l.s[i - 1].step + (l.s[i].points - l.s[i - 1].points));
    CHECK(l.s[i].points > l.s[i - 1].points);
    if (!l.s[i].optimized) /* else each counts its own final pass only */
      CHECK(l.s[i].seconds >= l.s[i - 1].seconds);
    if (l.s[i].points <= until)
      CHECK_INT_EQ(l.s[i].points, start + i);
    CHECK_INT_EQ(l.s[i].optimized, l.s[0].optimized);
  }
  /* the start, the first insertion, the counts asked for that the run
   * reached (a run that ends earlier ends at its last step, checked) */
  size_t want[16] = {start, start + 1};
  size_t nwant = 2;
  for (size_t k = 0; k < ncheck && nwant < 16; k++)
    if (check[k] > start + 1 && check[k] <= sum.vertices)
      want[nwant++] = check[k];
  for (size_t k = 0; k < nwant; k++) {
    const tt_step_info *s = NULL;
    for (size_t i = 0; i < l.n; i++)
      if (l.s[i].points == want[k])
        s = &l.s[i];
    if (!s) {
      TT_FAIL_("%s %s: no step at %zu points", name, tt_criterion_name(crit),
               want[k]);
      continue;
    }
    tt_refine_options one = o;
    one.step = NULL;
    one.max_points = want[k];
    tt_tin *tin = NULL;
    CHECK_OK(ctx, tt_refine_run(ctx, g, &one, &tin));
    if (!tin)
      continue;
    tt_tin_get_summary(tin, &sum);
    CHECK_INT_EQ(sum.vertices, s->points);
    CHECK_INT_EQ(sum.triangles, s->triangles);
    char what[96];
    snprintf(what, sizeof what, "%s %s summary", name, tt_criterion_name(crit));
    check_errors(what, s->points, &s->errors, &sum.errors, 1e-12, true);
    tt_eval_result ev;
    eval_tin(g, tin, &ev);
    ev.errors.samples = sum.errors.samples;
    snprintf(what, sizeof what, "%s %s eval", name, tt_criterion_name(crit));
    /* barycentric heights round otherwise than the scans' plane */
    check_errors(what, s->points, &s->errors, &ev.errors, 1e-9, false);
    tt_tin_destroy(tin);
  }
  tt_tin_destroy(plain);
  tt_tin_destroy(rec);
}

static void test_curves(void)
{
  static const size_t at[] = {260, 200};
  static const size_t check[] = {17, 60, 120, 200, 260};
  struct {
    const char *name;
    size_t nx, ny;
    double noise;
    bool holes, f64;
  } ts[] = {
      {"smooth floats", 61, 47, 0.0, false, false},
      {"rough floats", 70, 52, 8.0, false, false},
      {"rough doubles", 70, 52, 8.0, false, true},
      {"nodata floats", 64, 64, 3.0, true, false},
      {"nodata doubles", 64, 64, 3.0, true, true},
  };
  struct {
    tt_criterion c;
    tt_optimize o;
    tt_repair r;
  } cs[] = {
      {TT_CRITERION_DELAUNAY, TT_OPTIMIZE_AUTO, TT_REPAIR_AUTO},
      {TT_CRITERION_MINMAX_ANGLE, TT_OPTIMIZE_AUTO, TT_REPAIR_AUTO},
      {TT_CRITERION_MIN_AREA, TT_OPTIMIZE_AUTO, TT_REPAIR_AUTO},
      /* a final pass: each step measured on an optimised copy */
      {TT_CRITERION_L2, TT_OPTIMIZE_AUTO, TT_REPAIR_AUTO},
      {TT_CRITERION_MEAN_CURVATURE, TT_OPTIMIZE_LOCAL, TT_REPAIR_DELAUNAY},
      {TT_CRITERION_ABN, TT_OPTIMIZE_LOOKAHEAD, TT_REPAIR_DELAUNAY},
  };
  for (size_t t = 0; t < sizeof ts / sizeof ts[0]; t++) {
    tt_grid *g = terrain(ts[t].nx, ts[t].ny, 11 + t, ts[t].noise,
                         ts[t].holes, ts[t].f64);
    if (!g)
      continue;
    for (size_t c = 0; c < sizeof cs / sizeof cs[0]; c++) {
      check_curve(ts[t].name, g, cs[c].c, cs[c].o, cs[c].r, 120, at, 2, check,
                  sizeof check / sizeof check[0]);
    }
    tt_grid_destroy(g);
  }
}

/* Synthetic terrains of the study, one criterion each. */
static void test_synth(void)
{
  static const size_t check[] = {40, 99, 150};
  tt_synth_kind kinds[] = {TT_SYNTH_FAULT, TT_SYNTH_DIAMOND_SQUARE,
                           TT_SYNTH_CYLINDER};
  tt_criterion crit[] = {TT_CRITERION_GAUSSIAN_CURVATURE, TT_CRITERION_L2,
                         TT_CRITERION_DELAUNAY};
  for (int k = 0; k < 3; k++) {
    tt_synth_options so;
    tt_synth_options_init(&so, kinds[k]);
    if (kinds[k] == TT_SYNTH_DIAMOND_SQUARE)
      so.nx = so.ny = 65;
    tt_grid *g = NULL;
    CHECK_OK(ctx, tt_synth_generate(ctx, &so, &g));
    if (g)
      check_curve(tt_synth_kind_name(kinds[k]), g, crit[k], TT_OPTIMIZE_AUTO,
                  TT_REPAIR_AUTO, 150, NULL, 0, check, 3);
    tt_grid_destroy(g);
  }
}

/* To zero error: the totals come back to zero (no drift). */
static void test_no_drift(void)
{
  tt_grid *g = terrain(40, 33, 3, 9.0, true, false);
  static log_t l;
  memset(&l, 0, sizeof l);
  tt_refine_options o;
  tt_refine_options_init(&o);
  o.max_error = 0;
  o.step = record;
  o.step_arg = &l;
  o.step_until = SIZE_MAX;
  tt_tin *tin = NULL;
  CHECK_OK(ctx, tt_refine_run(ctx, g, &o, &tin));
  CHECK(l.n > 100);
  double most = 0;
  for (size_t i = 0; i < l.n; i++)
    most = fmax(most, l.s[i].errors.total_abs);
  const tt_error_stats *e = &l.s[l.n - 1].errors;
  CHECK_DBL_LE(e->total_abs, 1e-14 * most);
  CHECK_DBL_LE(e->l2, 1e-7 * most);
  CHECK(e->max_error == 0);
  CHECK_INT_EQ(e->max_col, -1);
  tt_tin_destroy(tin);
  /* with an error limit, recording keeps every candidate in the heap (its
   * top is then the worst error of the mesh): the same TIN all the same */
  o.max_error = 2.5;
  o.criterion = TT_CRITERION_L2;
  tin = NULL;
  tt_tin *plain = NULL;
  memset(&l, 0, sizeof l);
  CHECK_OK(ctx, tt_refine_run(ctx, g, &o, &tin));
  o.step = NULL;
  CHECK_OK(ctx, tt_refine_run(ctx, g, &o, &plain));
  if (tin && plain) {
    CHECK(same_tin(tin, plain));
    tt_tin_summary sum;
    tt_tin_get_summary(plain, &sum);
    check_errors("max_error 2.5", sum.vertices, &l.s[l.n - 1].errors,
                 &sum.errors, 1e-12, true);
  }
  tt_tin_destroy(plain);
  tt_tin_destroy(tin);
  tt_grid_destroy(g);
}

/* The callback stops the run; step_at alone reports those counts. */
static void test_stop_and_at(void)
{
  tt_grid *g = terrain(50, 40, 4, 2.0, false, false);
  static log_t l;
  memset(&l, 0, sizeof l);
  l.stop_after = 7;
  tt_refine_options o;
  tt_refine_options_init(&o);
  o.max_error = -1;
  o.max_points = 300;
  o.step = record;
  o.step_arg = &l;
  o.step_until = SIZE_MAX;
  tt_tin *tin = NULL;
  CHECK_INT_EQ(tt_refine_run(ctx, g, &o, &tin), TT_ERR_INTERRUPTED);
  CHECK(tin == NULL);
  CHECK_INT_EQ(l.n, 7);
  memset(&l, 0, sizeof l);
  static const size_t at[] = {100, 7, 5000};
  o.step_until = 0;
  o.step_at = at;
  o.nstep_at = 3;
  CHECK_OK(ctx, tt_refine_run(ctx, g, &o, &tin));
  CHECK_INT_EQ(l.n, 3); /* 7, 100 and the last (300); 5000 never comes */
  CHECK_INT_EQ(l.s[0].points, 7);
  CHECK_INT_EQ(l.s[1].points, 100);
  CHECK_INT_EQ(l.s[2].points, 300);
  CHECK(l.s[2].last && !l.s[1].last);
  tt_tin_destroy(tin);
  tin = NULL;
  o.step_at = NULL;
  CHECK_INT_EQ(tt_refine_run(ctx, g, &o, &tin), TT_ERR_ARG);
  tt_tin_destroy(tin);
  tt_grid_destroy(g);
}

/* Threads: large triangles are scanned in bands, the same bands with and
 * without threads, so the sums are the same bit for bit. */
static void test_threads(void)
{
  tt_grid *g = terrain(530, 520, 8, 5.0, false, false);
  static log_t a, b;
  memset(&a, 0, sizeof a);
  memset(&b, 0, sizeof b);
  tt_refine_options o;
  tt_refine_options_init(&o);
  o.max_error = -1;
  o.max_points = 80;
  o.step = record;
  o.step_until = SIZE_MAX;
  o.threads = 1;
  o.step_arg = &a;
  tt_tin *t1 = NULL, *t2 = NULL;
  CHECK_OK(ctx, tt_refine_run(ctx, g, &o, &t1));
  o.threads = 3;
  o.step_arg = &b;
  CHECK_OK(ctx, tt_refine_run(ctx, g, &o, &t2));
  CHECK_INT_EQ(a.n, b.n);
  for (size_t i = 0; i < a.n && i < b.n; i++)
    if (memcmp(&a.s[i].errors, &b.s[i].errors, sizeof a.s[i].errors) != 0)
      TT_FAIL_("step %zu: 1 thread and 3 give other measures (l2 %.17g, "
               "%.17g)", i, a.s[i].errors.l2, b.s[i].errors.l2);
  if (t1) {
    tt_tin_summary sum;
    tt_tin_get_summary(t1, &sum);
    check_errors("threads", sum.vertices, &a.s[a.n - 1].errors, &sum.errors,
                 1e-12, true);
  }
  tt_tin_destroy(t1);
  tt_tin_destroy(t2);
  tt_grid_destroy(g);
}

/* Decimation: a step per round, from the start, the last the TIN. */
static void test_decimate(void)
{
  tt_grid *g = terrain(45, 38, 6, 4.0, true, false);
  static log_t l;
  memset(&l, 0, sizeof l);
  tt_decimate_options o;
  tt_decimate_options_init(&o);
  o.max_points = 60;
  o.criterion = TT_CRITERION_L2;
  o.step = record;
  o.step_arg = &l;
  tt_tin *tin = NULL;
  CHECK_OK(ctx, tt_decimate_run(ctx, g, &o, &tin));
  if (!tin)
    return;
  tt_tin_summary sum;
  tt_tin_get_summary(tin, &sum);
  CHECK(l.n >= 3);
  CHECK_INT_EQ(l.s[0].step, 0);
  CHECK(l.s[0].errors.max_error == 0); /* every valid sample a vertex */
  CHECK_INT_EQ(l.s[l.n - 1].points, sum.vertices);
  CHECK(l.s[l.n - 1].last);
  CHECK_INT_EQ(l.s[l.n - 1].step, sum.rounds);
  check_errors("decimate last", sum.vertices, &l.s[l.n - 1].errors,
               &sum.errors, 1e-12, true);
  for (size_t i = 1; i + 1 < l.n; i++) {
    CHECK_INT_EQ(l.s[i].step, i);
    CHECK(l.s[i].points < l.s[i - 1].points);
    CHECK_INT_EQ(l.s[i].errors.covered, l.s[0].errors.covered);
  }
  tt_tin_destroy(tin);
  /* sequential selection: a step per removal */
  memset(&l, 0, sizeof l);
  o.selection = TT_SELECTION_SEQUENTIAL;
  o.max_points = 1400;
  tin = NULL;
  CHECK_OK(ctx, tt_decimate_run(ctx, g, &o, &tin));
  if (tin) {
    tt_tin_get_summary(tin, &sum);
    CHECK_INT_EQ(l.s[l.n - 1].points, 1400);
    CHECK_INT_EQ(l.s[l.n - 1].step, sum.rounds);
    check_errors("sequential last", sum.vertices, &l.s[l.n - 1].errors,
                 &sum.errors, 1e-12, true);
    for (size_t i = 1; i + 1 < l.n; i++) {
      CHECK_INT_EQ(l.s[i].step, i);
      CHECK_INT_EQ(l.s[i].points + 1, l.s[i - 1].points);
    }
  }
  tt_tin_destroy(tin);
  tt_grid_destroy(g);
}

int main(void)
{
  ctx = tt_context_create();
  if (!ctx)
    return 1;
  TT_RUN(test_curves());
  TT_RUN(test_synth());
  TT_RUN(test_no_drift());
  TT_RUN(test_stop_and_at());
  TT_RUN(test_threads());
  TT_RUN(test_decimate());
  tt_context_destroy(ctx);
  TT_TEST_DONE();
}
