/* test_refine.c -- greedy insertion, checked by independent oracles:
 *  - a brute-force scan of every sample against every triangle (barycentric
 *    in doubles, no shared code with raster_scan.c) finds no error above the
 *    requested bound, and every valid sample inside some triangle;
 *  - every interior edge passes the exact incircle test in the ground frame;
 *  - stop conditions are honoured exactly; two runs give identical TINs;
 *  - the reported statistics equal the oracle's;
 *  - nodata, bad options and interruption behave;
 *  - a grid of doubles gives the TIN of a grid of floats holding the same
 *    values, bit for bit, under every criterion; with heights no float
 *    holds (2^30 + integers, 10^6 + thousandths) the bound holds on the
 *    exact heights, -max_error 0 reproduces every sample. */
#include "base/predicates.h"
#include "terratin/terratin.h"
#include "tt_test.h"
#include "tt_tin_oracle.h"

#include <float.h>
#include <stdbool.h>

static tt_context *ctx;

/* A deterministic rough terrain: sines plus hashed noise. */
static tt_grid *terrain(size_t nx, size_t ny, uint64_t seed, double noise)
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
  return g;
}

typedef struct oracle {
  double max_err, sum_sq, sum_abs;
  size_t covered, valid, uncovered;
} oracle;

/* Every valid sample: find a triangle containing it (closed) and measure
 * |H - H'| by barycentric interpolation. */
static void brute_force(const tt_grid *g, const tt_tin *tin, oracle *o)
{
  size_t nx = tt_grid_width(g), ny = tt_grid_height(g);
  size_t nt = tt_tin_triangle_count(tin);
  double *tri = tt_oracle_pixel_triangles(tin);
  memset(o, 0, sizeof *o);
  for (size_t r = 0; r < ny; r++)
    for (size_t c = 0; c < nx; c++) {
      double h = tt_grid_sample(g, c, r);
      if (isnan(h))
        continue;
      o->valid++;
      bool found = false;
      for (size_t t = 0; t < nt && !found; t++) {
        const double *p = tri + 9 * t;
        double x = (double)c, y = (double)r;
        double d = (p[3] - p[0]) * (p[7] - p[1]) - (p[6] - p[0]) * (p[4] - p[1]);
        double l1 = ((x - p[0]) * (p[7] - p[1]) - (p[6] - p[0]) * (y - p[1])) / d;
        double l2 = ((p[3] - p[0]) * (y - p[1]) - (x - p[0]) * (p[4] - p[1])) / d;
        double l0 = 1 - l1 - l2;
        const double eps = -1e-12;
        if (l0 < eps || l1 < eps || l2 < eps)
          continue;
        found = true;
        double hp = l0 * p[2] + l1 * p[5] + l2 * p[8];
        double e = fabs(h - hp);
        if (e > o->max_err)
          o->max_err = e;
        o->sum_sq += e * e;
        o->sum_abs += e;
      }
      if (found)
        o->covered++;
      else
        o->uncovered++;
    }
  free(tri);
}

/* Every interior edge of the TIN passes the exact incircle test in the
 * grid's ground frame (edges paired by a quadratic search: small TINs). */
static void check_delaunay(const tt_grid *g, const tt_tin *tin)
{
  double a[4];
  tt_grid_get_ground_frame(g, a);
  tt__metric m = {a[0] * a[0] + a[2] * a[2], a[0] * a[1] + a[2] * a[3],
                  a[1] * a[1] + a[3] * a[3],
                  (a[0] * a[3] - a[1] * a[2]) < 0 ? -1 : 1};
  size_t nt = tt_tin_triangle_count(tin);
  tt_triangle_info *ti = malloc(nt * sizeof *ti);
  tt_vertex_info *vi = malloc(tt_tin_vertex_count(tin) * sizeof *vi);
  for (size_t v = 0; v < tt_tin_vertex_count(tin); v++)
    tt_tin_vertex(tin, v, &vi[v]);
  for (size_t t = 0; t < nt; t++)
    tt_tin_triangle(tin, t, &ti[t]);
  size_t bad = 0;
  for (size_t t = 0; t < nt; t++)
    for (int k = 0; k < 3; k++) {
      int32_t A = ti[t].v[k], B = ti[t].v[(k + 1) % 3], C = ti[t].v[(k + 2) % 3];
      for (size_t u = t + 1; u < nt; u++)
        for (int j = 0; j < 3; j++)
          if (ti[u].v[j] == B && ti[u].v[(j + 1) % 3] == A) {
            int32_t D = ti[u].v[(j + 2) % 3];
            if (tt__incircle_metric(&m, vi[A].col, vi[A].row, vi[B].col,
                                    vi[B].row, vi[C].col, vi[C].row,
                                    vi[D].col, vi[D].row) > 0)
              bad++;
          }
    }
  if (bad)
    TT_FAIL_("%zu interior edges are not locally Delaunay", bad);
  free(ti);
  free(vi);
}

static bool same_tin(const tt_tin *a, const tt_tin *b)
{
  if (tt_tin_vertex_count(a) != tt_tin_vertex_count(b) ||
      tt_tin_triangle_count(a) != tt_tin_triangle_count(b))
    return false;
  for (size_t v = 0; v < tt_tin_vertex_count(a); v++) {
    tt_vertex_info x, y;
    tt_tin_vertex(a, v, &x);
    tt_tin_vertex(b, v, &y);
    if (x.col != y.col || x.row != y.row || x.z != y.z ||
        memcmp(&x.insert_error, &y.insert_error, sizeof x.insert_error) != 0)
      return false;
  }
  for (size_t t = 0; t < tt_tin_triangle_count(a); t++) {
    tt_triangle_info x, y;
    tt_tin_triangle(a, t, &x);
    tt_tin_triangle(b, t, &y);
    if (memcmp(x.v, y.v, sizeof x.v) != 0 || x.max_error != y.max_error)
      return false;
  }
  return true;
}

static void check_run(tt_grid *g, const double frame[4], double max_error,
                      const char *what)
{
  if (frame)
    CHECK_OK(ctx, tt_grid_set_ground_frame(ctx, g, frame));
  tt_refine_options opt;
  tt_refine_options_init(&opt);
  opt.max_error = max_error;
  tt_tin *tin = NULL, *again = NULL;
  double t0 = tt__now();
  CHECK_OK(ctx, tt_refine_run(ctx, g, &opt, &tin));
  double wall = tt__now() - t0;
  if (!tin)
    return;
  oracle o;
  brute_force(g, tin, &o);
  tt_tin_summary s;
  tt_tin_get_summary(tin, &s);
  if (o.uncovered)
    TT_FAIL_("%s: %zu valid samples in no triangle", what, o.uncovered);
  if (!(o.max_err <= max_error + 1e-9 * (1 + fabs(max_error))))
    TT_FAIL_("%s: brute-force max error %.17g above the bound %g", what,
             o.max_err, max_error);
  CHECK_DBL_NEAR(s.errors.max_error, o.max_err, 1e-9);
  CHECK_INT_EQ(s.errors.samples, o.valid);
  CHECK_DBL_NEAR(s.errors.rmse, sqrt(o.sum_sq / (double)o.valid), 1e-9);
  CHECK_DBL_NEAR(s.errors.mean_abs, o.sum_abs / (double)o.valid, 1e-9);
  CHECK_INT_EQ(s.stop_reason, TT_STOP_MAX_ERROR);
  /* the two phases were timed, within the call */
  CHECK(s.seconds_mesh > 0 && s.seconds_statistics > 0);
  CHECK_DBL_LE(s.seconds_mesh + s.seconds_statistics, wall);
  /* the triangles' owned samples partition the valid samples */
  size_t owned = 0;
  for (size_t t = 0; t < tt_tin_triangle_count(tin); t++) {
    tt_triangle_info ti;
    tt_tin_triangle(tin, t, &ti);
    owned += ti.samples;
    CHECK_DBL_LE(ti.max_error, max_error + 1e-9);
    CHECK(ti.area_2d > 0);
    CHECK(ti.area_3d >= ti.area_2d * (1 - 1e-12));
    CHECK(ti.min_angle_deg > 0 && ti.max_angle_deg < 180);
  }
  CHECK_INT_EQ(owned, o.valid);
  check_delaunay(g, tin);
  CHECK_OK(ctx, tt_refine_run(ctx, g, &opt, &again));
  if (again && !same_tin(tin, again))
    TT_FAIL_("%s: two runs differ", what);
  tt_tin_destroy(tin);
  tt_tin_destroy(again);
}

static void test_bounds_and_frames(void)
{
  const double frames[][4] = {
      {1, 0, 0, 1}, {30, 0, 0, -30}, {89.98, 0, 0, -90.02}, {2, 1, 0, 3},
      {0.7, -0.2, 0.3, -1.1}};
  for (size_t i = 0; i < sizeof frames / sizeof frames[0]; i++) {
    double gt[6] = {500000, frames[i][0], frames[i][1], 4000000,
                    frames[i][2], frames[i][3]};
    for (uint64_t seed = 1; seed <= 3; seed++) {
      tt_grid *g = terrain(37 + 5 * seed, 29 + 3 * seed, seed, 4.0);
      CHECK_OK(ctx, tt_grid_set_geotransform(ctx, g, gt));
      char what[64];
      snprintf(what, sizeof what, "frame %zu seed %llu", i,
               (unsigned long long)seed);
      check_run(g, NULL, 2.5, what);
      check_run(g, NULL, 0.0, what); /* exact reproduction */
      tt_grid_destroy(g);
    }
  }
}

static void test_stop_conditions(void)
{
  tt_grid *g = terrain(64, 48, 7, 10.0);
  size_t valid = 64 * 48;
  tt_refine_options opt;
  tt_tin *tin = NULL;
  tt_tin_summary s;

  tt_refine_options_init(&opt);
  opt.max_error = -1;
  opt.max_points = 137;
  CHECK_OK(ctx, tt_refine_run(ctx, g, &opt, &tin));
  tt_tin_get_summary(tin, &s);
  CHECK_INT_EQ(s.vertices, 137);
  CHECK_INT_EQ(s.stop_reason, TT_STOP_MAX_POINTS);
  tt_tin_destroy(tin);

  for (size_t lim = 50; lim <= 53; lim++) {
    tt_refine_options_init(&opt);
    opt.max_error = -1;
    opt.max_triangles = lim;
    CHECK_OK(ctx, tt_refine_run(ctx, g, &opt, &tin));
    tt_tin_get_summary(tin, &s);
    CHECK_INT_LE(s.triangles, lim);
    CHECK_INT_LE(lim, s.triangles + 1);
    CHECK_INT_EQ(s.stop_reason, TT_STOP_MAX_TRIANGLES);
    tt_tin_destroy(tin);
  }

  tt_refine_options_init(&opt);
  opt.max_error = -1;
  opt.percent = 10;
  CHECK_OK(ctx, tt_refine_run(ctx, g, &opt, &tin));
  tt_tin_get_summary(tin, &s);
  CHECK_INT_EQ(s.vertices, (size_t)(0.10 * (double)valid));
  tt_tin_destroy(tin);

  /* the first condition reached wins: a loose error bound before points */
  tt_refine_options_init(&opt);
  opt.max_error = 30;
  opt.max_points = 2000;
  CHECK_OK(ctx, tt_refine_run(ctx, g, &opt, &tin));
  tt_tin_get_summary(tin, &s);
  CHECK_INT_EQ(s.stop_reason, TT_STOP_MAX_ERROR);
  CHECK(s.vertices < 2000);
  CHECK_DBL_LE(s.errors.max_error, 30);
  tt_tin_destroy(tin);

  /* max_error 0 inserts until every sample is exact */
  tt_refine_options_init(&opt);
  opt.max_error = 0;
  CHECK_OK(ctx, tt_refine_run(ctx, g, &opt, &tin));
  tt_tin_get_summary(tin, &s);
  CHECK_DBL_NEAR(s.errors.max_error, 0, 1e-9);
  tt_tin_destroy(tin);
  tt_grid_destroy(g);
}

static void test_flat_and_plane(void)
{
  /* a tilted plane is reproduced exactly by the two corner triangles */
  tt_grid *g = NULL;
  CHECK_OK(ctx, tt_grid_create(ctx, 33, 17, &g));
  float *z = tt_grid_heights(g);
  for (size_t r = 0; r < 17; r++)
    for (size_t c = 0; c < 33; c++)
      z[r * 33 + c] = (float)(2.0 * (double)c - 3.0 * (double)r);
  tt_refine_options opt;
  tt_refine_options_init(&opt);
  opt.max_error = -1;
  opt.max_points = 100;
  tt_tin *tin = NULL;
  CHECK_OK(ctx, tt_refine_run(ctx, g, &opt, &tin));
  CHECK_INT_EQ(tt_tin_vertex_count(tin), 4);
  CHECK_INT_EQ(tt_tin_triangle_count(tin), 2);
  tt_tin_summary s;
  tt_tin_get_summary(tin, &s);
  CHECK_INT_EQ(s.stop_reason, TT_STOP_EXHAUSTED);
  tt_tin_destroy(tin);
  tt_grid_destroy(g);
}

/* Nodata domains (issue 3): the TIN covers the valid samples and nothing
 * else. Masks: a disc with a one-sample hole, a ring (a hole of a lake),
 * two islands, a checkerboard corner, a diagonal staircase, a one-pixel
 * line, and a lone valid sample. */
static void test_nodata(void)
{
  size_t n = 41;
  for (int mask = 0; mask < 6; mask++) {
    tt_grid *g = terrain(n, n, 3 + (uint64_t)mask, 5);
    float *z = tt_grid_heights(g);
    size_t valid = 0;
    for (size_t r = 0; r < n; r++)
      for (size_t c = 0; c < n; c++) {
        double dx = (double)c - 20, dy = (double)r - 20;
        double d2 = dx * dx + dy * dy;
        bool keep = true;
        switch (mask) {
        case 0: /* disc with a one-sample hole */
          keep = d2 <= 19.5 * 19.5 && !(c == 20 && r == 20);
          break;
        case 1: /* ring: a lake inside */
          keep = d2 <= 19.5 * 19.5 && d2 >= 8 * 8;
          break;
        case 2: /* two islands and a lone sample */
          keep = (c < 15 && r < 20) || (c > 24 && r > 10) ||
                 (c == 20 && r == 35);
          break;
        case 3: /* checkerboard corner, staircase edge */
          keep = (c + r < 50) && !((c < 10 && r < 10) && (c + r) % 2);
          break;
        case 4: /* a one-pixel line amid nodata, beside a block */
          keep = r == 30 || (r < 20 && c < 30);
          break;
        default: /* a diagonal one-pixel staircase and a block */
          keep = (c == r) || (c == r + 1) || (r > 30 && c > 5);
          break;
        }
        if (!keep)
          z[r * n + c] = NAN;
        else
          valid++;
      }
    for (int b = 0; b < 2; b++) {
      double bound = b ? 0.0 : 1.5;
      tt_refine_options opt;
      tt_refine_options_init(&opt);
      opt.max_error = bound;
      tt_tin *tin = NULL;
      CHECK_OK(ctx, tt_refine_run(ctx, g, &opt, &tin));
      if (!tin)
        continue;
      oracle o;
      brute_force(g, tin, &o);
      tt_tin_summary s;
      tt_tin_get_summary(tin, &s);
      CHECK_INT_EQ(o.valid, valid);
      CHECK_INT_EQ(s.errors.samples, valid);
      CHECK_INT_EQ(s.valid_samples, valid);
      CHECK_INT_EQ(o.uncovered, s.errors.samples - s.errors.covered);
      /* uncovered: exactly the samples no valid cell part holds */
      CHECK_INT_EQ(o.uncovered, tt_oracle_uncarriable(g));
      if (tt_oracle_nodata_inside(g, tin))
        TT_FAIL_("mask %d: %zu nodata samples strictly inside triangles",
                 mask, tt_oracle_nodata_inside(g, tin));
      CHECK_DBL_LE(o.max_err, bound + 1e-9);
      if (mask == 1 || mask == 2)
        CHECK(s.components >= (mask == 2 ? 2u : 1u));
      if (mask == 2)
        CHECK(o.uncovered >= 1); /* the lone sample */
      if (mask == 4 && b == 1)
        CHECK(o.uncovered >= 1); /* the line cannot carry a triangle */
      tt_tin_destroy(tin);
    }
    tt_grid_destroy(g);
  }
}

static int stop_after(double complete, const char *msg, void *user)
{
  (void)complete;
  (void)msg;
  int *calls = user;
  return ++*calls < 3;
}

static void test_errors(void)
{
  tt_grid *g = terrain(20, 20, 1, 1);
  tt_refine_options opt;
  tt_tin *tin = NULL;

  tt_refine_options_init(&opt);
  opt.max_error = -1;
  CHECK_INT_EQ(tt_refine_run(ctx, g, &opt, &tin), TT_ERR_ARG);
  CHECK(strstr(tt_context_errmsg(ctx), "stop condition") != NULL);

  tt_refine_options_init(&opt);
  opt.percent = 150;
  CHECK_INT_EQ(tt_refine_run(ctx, g, &opt, &tin), TT_ERR_ARG);
  opt.percent = 0;
  opt.max_error = NAN;
  CHECK_INT_EQ(tt_refine_run(ctx, g, &opt, &tin), TT_ERR_ARG);

  /* interruption */
  int calls = 0;
  tt_refine_options_init(&opt);
  opt.max_error = 0;
  opt.progress = stop_after;
  opt.progress_arg = &calls;
  tt_grid *big = terrain(200, 200, 2, 30);
  CHECK_INT_EQ(tt_refine_run(ctx, big, &opt, &tin), TT_ERR_INTERRUPTED);
  CHECK(tin == NULL);
  tt_grid_destroy(big);

  /* all nodata, and collinear valid samples */
  float *z = tt_grid_heights(g);
  for (size_t i = 0; i < 400; i++)
    z[i] = NAN;
  tt_refine_options_init(&opt);
  CHECK_INT_EQ(tt_refine_run(ctx, g, &opt, &tin), TT_ERR_DATA);
  for (size_t c = 0; c < 20; c++)
    z[5 * 20 + c] = 1.0f;
  CHECK_INT_EQ(tt_refine_run(ctx, g, &opt, &tin), TT_ERR_DATA);
  CHECK(strstr(tt_context_errmsg(ctx), "one line") != NULL);
  z[0] = INFINITY;
  CHECK_INT_EQ(tt_refine_run(ctx, g, &opt, &tin), TT_ERR_DATA);
  tt_grid_destroy(g);
}

/* Issue 11: every budget is exact, so one below the starting
 * triangulation is refused before any insertion, with the count; and
 * max_memory stops a run that would pass it with the phase and the size,
 * while a run that fits is unchanged by it. */
static void test_budgets_and_memory(void)
{
  tt_grid *g = terrain(120, 90, 4, 3);
  tt_refine_options opt;
  tt_tin *tin = NULL;
  for (size_t n = 1; n <= 3; n++) {
    tt_refine_options_init(&opt);
    opt.max_points = n;
    CHECK_INT_EQ(tt_refine_run(ctx, g, &opt, &tin), TT_ERR_LIMIT);
    CHECK(tin == NULL);
    CHECK(strstr(tt_context_errmsg(ctx), "ask for at least 4") != NULL);
  }
  tt_refine_options_init(&opt);
  opt.max_triangles = 1;
  CHECK_INT_EQ(tt_refine_run(ctx, g, &opt, &tin), TT_ERR_LIMIT);
  CHECK(strstr(tt_context_errmsg(ctx), "at least 2") != NULL);
  tt_refine_options_init(&opt);
  opt.max_error = -1;
  opt.percent = 0.01; /* 1 of 10800 samples */
  CHECK_INT_EQ(tt_refine_run(ctx, g, &opt, &tin), TT_ERR_LIMIT);
  CHECK(strstr(tt_context_errmsg(ctx), "from the percentage") != NULL);
  tt_refine_options_init(&opt);
  opt.max_points = 4;
  CHECK_OK(ctx, tt_refine_run(ctx, g, &opt, &tin));
  CHECK_INT_EQ(tt_tin_vertex_count(tin), 4);
  tt_tin_destroy(tin);
  tin = NULL;

  /* a dense TIN in 1 MiB: refused while inserting, naming the sizes */
  tt_refine_options_init(&opt);
  opt.max_error = 0;
  opt.max_memory = (size_t)1 << 20;
  CHECK_INT_EQ(tt_refine_run(ctx, g, &opt, &tin), TT_ERR_NOMEM);
  CHECK(tin == NULL);
  const char *m = tt_context_errmsg(ctx);
  CHECK(strstr(m, "while inserting") != NULL);
  CHECK(strstr(m, "more than the memory limit of 1.0 MiB") != NULL);
  /* the heights alone pass a few KiB: refused at the start */
  opt.max_memory = 4096;
  CHECK_INT_EQ(tt_refine_run(ctx, g, &opt, &tin), TT_ERR_NOMEM);
  CHECK(strstr(tt_context_errmsg(ctx), "starting triangulation") != NULL);
  /* with room to spare: the same TIN as without a limit */
  opt.max_memory = (size_t)1 << 30;
  CHECK_OK(ctx, tt_refine_run(ctx, g, &opt, &tin));
  tt_tin *ref = NULL;
  opt.max_memory = 0;
  CHECK_OK(ctx, tt_refine_run(ctx, g, &opt, &ref));
  CHECK_INT_EQ(tt_tin_vertex_count(tin), tt_tin_vertex_count(ref));
  CHECK_INT_EQ(tt_tin_triangle_count(tin), tt_tin_triangle_count(ref));
  tt_tin_destroy(tin);
  tt_tin_destroy(ref);
  tt_grid_destroy(g);
}

/* The worker pool changes nothing: 1 and 3 threads give the same TIN and
 * the same statistics. */
static void test_threads(void)
{
  tt_grid *g = terrain(301, 257, 11, 25.0);
  tt_refine_options opt;
  tt_refine_options_init(&opt);
  opt.max_error = 3;
  tt_tin *one = NULL, *three = NULL;
  opt.threads = 1;
  CHECK_OK(ctx, tt_refine_run(ctx, g, &opt, &one));
  opt.threads = 3;
  CHECK_OK(ctx, tt_refine_run(ctx, g, &opt, &three));
  if (one && three) {
    CHECK(same_tin(one, three));
    tt_tin_summary a, b;
    tt_tin_get_summary(one, &a);
    tt_tin_get_summary(three, &b);
    CHECK(a.errors.max_error == b.errors.max_error);
    CHECK(a.errors.rmse == b.errors.rmse);
    CHECK(a.errors.total_abs == b.errors.total_abs);
    CHECK_INT_EQ(a.errors.samples, b.errors.samples);
  }
  tt_tin_destroy(one);
  tt_tin_destroy(three);
  tt_grid_destroy(g);
}

/* The grid's values as a grid of doubles. */
static tt_grid *as_doubles(const tt_grid *g)
{
  size_t nx = tt_grid_width(g), ny = tt_grid_height(g);
  double *z = malloc(nx * ny * sizeof *z);
  for (size_t i = 0; i < nx * ny; i++)
    z[i] = tt_grid_sample(g, i % nx, i / nx);
  tt_grid *d = NULL;
  CHECK_OK(ctx, tt_grid_create_from_doubles(ctx, nx, ny, z, &d));
  double gt[6], a[4];
  tt_grid_get_geotransform(g, gt);
  tt_grid_get_ground_frame(g, a);
  if (d) {
    CHECK_OK(ctx, tt_grid_set_geotransform(ctx, d, gt));
    CHECK_OK(ctx, tt_grid_set_ground_frame(ctx, d, a));
  }
  free(z);
  return d;
}

/* Floats or doubles, the same values: the same TIN, bit for bit, under
 * every criterion (with nodata holes and a tilted frame too). */
static void test_doubles_same_tin(void)
{
  tt_grid *g = terrain(53, 41, 5, 6.0);
  float *z = tt_grid_heights(g);
  for (size_t i = 0; i < 53 * 41; i += 29)
    z[i] = NAN;
  const double gt[6] = {500000, 0.7, -0.2, 4000000, 0.3, -1.1};
  const double frame[4] = {0.9, -0.1, 0.2, -1.3};
  CHECK_OK(ctx, tt_grid_set_geotransform(ctx, g, gt));
  CHECK_OK(ctx, tt_grid_set_ground_frame(ctx, g, frame));
  tt_grid *d = as_doubles(g);
  CHECK_INT_EQ(tt_grid_precision(g), TT_PRECISION_FLOAT32);
  CHECK_INT_EQ(tt_grid_precision(d), TT_PRECISION_FLOAT64);
  for (int c = TT_CRITERION_DELAUNAY; c <= TT_CRITERION_L2 && d; c++) {
    tt_refine_options opt;
    tt_refine_options_init(&opt);
    opt.max_error = 4;
    opt.criterion = (tt_criterion)c;
    tt_tin *a = NULL, *b = NULL;
    CHECK_OK(ctx, tt_refine_run(ctx, g, &opt, &a));
    CHECK_OK(ctx, tt_refine_run(ctx, d, &opt, &b));
    if (a && b && !same_tin(a, b))
      TT_FAIL_("%s: a grid of doubles gives another TIN than a grid of "
               "floats with the same values", tt_criterion_name(opt.criterion));
    if (a && b) {
      tt_tin_summary sa, sb;
      tt_tin_get_summary(a, &sa);
      tt_tin_get_summary(b, &sb);
      CHECK(sa.errors.max_error == sb.errors.max_error);
      CHECK(sa.errors.total_abs == sb.errors.total_abs);
      CHECK(sa.errors.l2 == sb.errors.l2);
    }
    tt_tin_destroy(a);
    tt_tin_destroy(b);
  }
  tt_grid_destroy(g);
  tt_grid_destroy(d);
}

/* Heights no float holds: the bound, and -max_error 0, on the exact
 * values, by the brute force (in doubles; its rounding is far below the
 * floats' 64 or 0.03) and by tt_eval_triangles. */
static void test_doubles_exact(void)
{
  const size_t nx = 61, ny = 47;
  for (int kind = 0; kind < 2; kind++) {
    /* Int32-like: 2^30 + [0, 1000); Float64-like: 10^6 + k / 1000 */
    double base = kind == 0 ? 1073741824.0 : 1e6;
    double unit = kind == 0 ? 1.0 : 0.001;
    double limit = kind == 0 ? 10 : 0.01;
    double *z = malloc(nx * ny * sizeof *z);
    uint64_t rng = 77 + (uint64_t)kind;
    for (size_t r = 0; r < ny; r++)
      for (size_t c = 0; c < nx; c++) {
        double s = 0.5 + 0.5 * sin(0.2 * (double)c) * cos(0.15 * (double)r);
        z[r * nx + c] = base + unit * floor(900 * s +
                                            100 * tt_test_uniform(&rng));
      }
    z[7] = z[nx * ny - 9] = NAN;
    tt_grid *g = NULL;
    CHECK_OK(ctx, tt_grid_create_from_doubles(ctx, nx, ny, z, &g));
    const double tol = 64 * DBL_EPSILON * (base + 1000 * unit);
    for (int pass = 0; pass < 2 && g; pass++) {
      tt_refine_options opt;
      tt_refine_options_init(&opt);
      opt.max_error = pass ? 0 : limit;
      opt.criterion = pass ? TT_CRITERION_L2 : TT_CRITERION_DELAUNAY;
      tt_tin *tin = NULL;
      CHECK_OK(ctx, tt_refine_run(ctx, g, &opt, &tin));
      if (!tin)
        continue;
      oracle o;
      brute_force(g, tin, &o);
      if (!(o.max_err <= opt.max_error + tol))
        TT_FAIL_("kind %d, -max_error %g: the exact heights are %.17g off",
                 kind, opt.max_error, o.max_err);
      tt_tin_summary s;
      tt_tin_get_summary(tin, &s);
      CHECK_DBL_NEAR(s.errors.max_error, o.max_err, tol);
      CHECK_INT_EQ(o.uncovered, tt_oracle_uncarriable(g));
      CHECK_INT_EQ(tt_oracle_nodata_inside(g, tin), 0);
      for (size_t v = 0; v < tt_tin_vertex_count(tin); v++) {
        tt_vertex_info vi;
        tt_tin_vertex(tin, v, &vi);
        if (vi.z != z[(size_t)vi.row * nx + (size_t)vi.col]) {
          TT_FAIL_("vertex %zu: z %.17g, the sample is %.17g", v, vi.z,
                   z[(size_t)vi.row * nx + (size_t)vi.col]);
          break;
        }
      }
      double *xyz = tt_oracle_pixel_triangles(tin);
      tt_eval_result ev;
      CHECK_OK(ctx, tt_eval_triangles(ctx, g, tt_tin_triangle_count(tin), xyz,
                                      &ev));
      CHECK_DBL_NEAR(ev.errors.max_error, o.max_err, tol);
      free(xyz);
      tt_tin_destroy(tin);
    }
    tt_grid_destroy(g);
    free(z);
  }
}

int main(void)
{
  ctx = tt_context_create();
  TT_RUN(test_doubles_same_tin());
  TT_RUN(test_doubles_exact());
  TT_RUN(test_threads());
  TT_RUN(test_bounds_and_frames());
  TT_RUN(test_stop_conditions());
  TT_RUN(test_flat_and_plane());
  TT_RUN(test_nodata());
  TT_RUN(test_errors());
  TT_RUN(test_budgets_and_memory());
  tt_context_destroy(ctx);
  TT_TEST_DONE();
}
