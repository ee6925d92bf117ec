/*
 * test_mesh_breaklines.c -- breaklines in the engine (src/mesh/breaklines.c
 * through tt_refine_run and tt_decimate_run): on a grid with a ridge
 * across a valley, two lines that meet at a sample, every segment is
 * covered by TIN edges flagged constrained (tt_triangle_info.constrained)
 * and nothing else is flagged, under every optimiser and both methods,
 * with the error bound kept; segments that cross away from a sample, an
 * end on nodata and missing ends are refused.
 *
 * Part of tests/mesh/, the mesh stage's tests.
 */
#include "terratin/terratin.h"
#include "tt_test.h"

#define NX 41
#define NY 31

static tt_context *ctx;

static float height(int x, int y)
{
  /* a valley along x = 20, a ridge along the line (3,3)-(35,25) */
  double d = fabs((double)(x - 20));
  double r = fabs(22.0 * (x - 3) - 32.0 * (y - 3)) / 38.8;
  return (float)(d + 0.1 * y + (r < 3 ? 3 - r : 0) + 0.3 * sin(x * 0.7));
}

static tt_grid *make_grid(int hole)
{
  static float z[NX * NY];
  for (int y = 0; y < NY; y++)
    for (int x = 0; x < NX; x++)
      z[y * NX + x] = hole && (x - 8) * (x - 8) + (y - 22) * (y - 22) < 9
                          ? NAN : height(x, y);
  tt_grid *g = NULL;
  CHECK_INT_EQ(tt_grid_create_from_floats(ctx, NX, NY, z, &g), TT_OK);
  return g;
}

static int64_t S(int x, int y) { return (int64_t)y * NX + x; }

/* the lines: (3,3)-(20,14)-(35,25) and (20,2)-(20,14)-(20,28) */
static const int64_t *lines(size_t *out_n)
{
  static int64_t e[8];
  e[0] = S(3, 3), e[1] = S(20, 14), e[2] = S(20, 14), e[3] = S(35, 25);
  e[4] = S(20, 2), e[5] = S(20, 14), e[6] = S(20, 14), e[7] = S(20, 28);
  *out_n = 4;
  return e;
}

/* Whether vertex p lies on segment ab (closed), and its parameter. */
static int on_segment(int64_t a, int64_t b, double px, double py, double *t)
{
  double ax = (double)(a % NX), ay = (double)(a / NX);
  double bx = (double)(b % NX), by = (double)(b / NX);
  double cr = (bx - ax) * (py - ay) - (by - ay) * (px - ax);
  if (cr != 0)
    return 0;
  double l2 = (bx - ax) * (bx - ax) + (by - ay) * (by - ay);
  *t = ((px - ax) * (bx - ax) + (py - ay) * (by - ay)) / l2;
  return *t >= 0 && *t <= 1;
}

/* Every segment covered by flagged edges, every flagged edge on one. */
static void check_lines(const tt_tin *tin, double bound)
{
  size_t n;
  const int64_t *e = lines(&n);
  double covered[4] = {0, 0, 0, 0};
  size_t stray = 0, flagged = 0;
  for (size_t i = 0; i < tt_tin_triangle_count(tin); i++) {
    tt_triangle_info t;
    CHECK_INT_EQ(tt_tin_triangle(tin, i, &t), TT_OK);
    for (int k = 0; k < 3; k++) {
      if (!((t.constrained >> k) & 1u))
        continue;
      flagged++;
      tt_vertex_info p, q;
      tt_tin_vertex(tin, (size_t)t.v[k], &p);
      tt_tin_vertex(tin, (size_t)t.v[(k + 1) % 3], &q);
      int found = 0;
      for (size_t s = 0; s < n && !found; s++) {
        double t0, t1;
        if (on_segment(e[2 * s], e[2 * s + 1], p.col, p.row, &t0) &&
            on_segment(e[2 * s], e[2 * s + 1], q.col, q.row, &t1)) {
          covered[s] += fabs(t1 - t0) / 2; /* inner edges: two sides */
          found = 1;
        }
      }
      stray += !found;
    }
  }
  CHECK(flagged > 0);
  CHECK_INT_EQ(stray, 0);
  for (size_t s = 0; s < n; s++)
    CHECK_DBL_NEAR(covered[s], 1.0, 1e-9);
  tt_tin_summary sum;
  tt_tin_get_summary(tin, &sum);
  CHECK(sum.errors.max_error <= bound);
}

static void test_refine_optimisers(void)
{
  tt_grid *g = make_grid(0);
  const tt_optimize opts[] = {TT_OPTIMIZE_NONE, TT_OPTIMIZE_LOCAL,
                              TT_OPTIMIZE_LOOKAHEAD, TT_OPTIMIZE_ANNEAL};
  for (size_t i = 0; i < sizeof opts / sizeof *opts; i++) {
    tt_refine_options o;
    tt_refine_options_init(&o);
    o.max_error = 0.5;
    o.criterion = TT_CRITERION_MINMAX_ANGLE;
    o.optimize = opts[i];
    o.breaklines.ends = lines(&o.breaklines.n);
    tt_tin *tin = NULL;
    CHECK_INT_EQ(tt_refine_run(ctx, g, &o, &tin), TT_OK);
    if (tin)
      check_lines(tin, 0.5);
    tt_tin_destroy(tin);
  }
  tt_grid_destroy(g);
}

static void test_decimate(void)
{
  tt_grid *g = make_grid(1);
  const tt_decimate_start starts[] = {TT_DSTART_ALL, TT_DSTART_GREEDY};
  for (size_t i = 0; i < 2; i++) {
    tt_decimate_options o;
    tt_decimate_options_init(&o);
    o.max_error = 0.5;
    o.start = starts[i];
    o.breaklines.ends = lines(&o.breaklines.n);
    tt_tin *tin = NULL;
    CHECK_INT_EQ(tt_decimate_run(ctx, g, &o, &tin), TT_OK);
    if (tin)
      check_lines(tin, 0.5);
    tt_tin_destroy(tin);
  }
  tt_grid_destroy(g);
}

static void test_refused(void)
{
  tt_grid *g = make_grid(1);
  tt_refine_options o;
  tt_refine_options_init(&o);
  o.max_error = 0.5;
  tt_tin *tin = NULL;
  /* two segments crossing between samples */
  const int64_t cross[4] = {S(2, 2), S(12, 12), S(2, 12), S(12, 2)};
  o.breaklines.ends = cross;
  o.breaklines.n = 2;
  CHECK_INT_EQ(tt_refine_run(ctx, g, &o, &tin), TT_ERR_DATA);
  CHECK(strstr(tt_context_errmsg(ctx), "crosses") != NULL);
  CHECK(tin == NULL);
  /* an end on nodata */
  const int64_t wet[2] = {S(8, 22), S(30, 5)};
  o.breaklines.ends = wet;
  o.breaklines.n = 1;
  CHECK_INT_EQ(tt_refine_run(ctx, g, &o, &tin), TT_ERR_DATA);
  CHECK(strstr(tt_context_errmsg(ctx), "(8, 22)") != NULL);
  /* no ends */
  o.breaklines.ends = NULL;
  CHECK_INT_EQ(tt_refine_run(ctx, g, &o, &tin), TT_ERR_ARG);
  /* none: no flags at all */
  o.breaklines.n = 0;
  CHECK_INT_EQ(tt_refine_run(ctx, g, &o, &tin), TT_OK);
  for (size_t i = 0; tin && i < tt_tin_triangle_count(tin); i++) {
    tt_triangle_info t;
    tt_tin_triangle(tin, i, &t);
    CHECK_INT_EQ(t.constrained, 0);
  }
  tt_tin_destroy(tin);
  tt_grid_destroy(g);
}

int main(void)
{
  ctx = tt_context_create();
  TT_RUN(test_refine_optimisers());
  TT_RUN(test_decimate());
  TT_RUN(test_refused());
  tt_context_destroy(ctx);
  TT_TEST_DONE();
}
