/* test_tile.c -- tiled runs (src/tile/) against independent oracles:
 *  - the merged TIN is conforming (tt_tin_conform.h: every edge in one or
 *    two triangles, no T-junction, no crack inside the domain, one vertex a
 *    sample, V - E + F = 1 for a grid without nodata);
 *  - every valid sample is within the bound, covered once
 *    (tt_eval_triangles, its own rasteriser), no nodata inside a triangle;
 *  - the statistics the merge reports equal eval's; valid samples add up;
 *  - the TIN does not depend on the order the tiles finish in;
 *  - its vertex count is within a few per cent of an untiled run's;
 *  - grids with nodata across, along and at the corners of tile borders;
 *  - every criterion and final optimisation keeps the borders;
 *  - bad tiles and budgets are refused. */
#include "terratin/terratin.h"
#include "tt_test.h"
#include "tt_tin_conform.h"
#include "tt_tin_oracle.h"

#include <stdbool.h>

static tt_context *ctx;

/* The window of a tile cut from an in-memory grid, as a reader gives it:
 * its geotransform that of its first sample, the grid's ground frame. */
static tt_grid *window_of(const tt_grid *g, const tt_tile *t)
{
  size_t c0, r0, w, h;
  tt_tile_window(t, &c0, &r0, &w, &h);
  double *z = malloc(w * h * sizeof *z);
  tt_grid *win = NULL;
  for (size_t y = 0; y < h; y++)
    for (size_t x = 0; x < w; x++)
      z[y * w + x] = tt_grid_sample(g, c0 + x, r0 + y);
  /* keep floats: every sample of these grids is one */
  float *zf = malloc(w * h * sizeof *zf);
  for (size_t i = 0; i < w * h; i++)
    zf[i] = (float)z[i];
  CHECK(tt_grid_create_from_floats(ctx, w, h, zf, &win) == TT_OK);
  double gt[6], fr[4];
  tt_grid_get_geotransform(g, gt);
  gt[0] += (double)c0 * gt[1] + (double)r0 * gt[2];
  gt[3] += (double)c0 * gt[4] + (double)r0 * gt[5];
  tt_grid_set_geotransform(ctx, win, gt);
  tt_grid_get_ground_frame(g, fr);
  tt_grid_set_ground_frame(ctx, win, fr);
  free(z);
  free(zf);
  return win;
}

/* Tiles of n cells; run in reverse order when reverse, merged in order. */
static tt_tin *run_tiled(const tt_grid *g, size_t n,
                         const tt_refine_options *opt, bool reverse)
{
  size_t W = tt_grid_width(g), H = tt_grid_height(g);
  size_t ntx = (W - 2) / n + 1, nty = (H - 2) / n + 1, nt = ntx * nty;
  tt_tile *tiles = calloc(nt, sizeof *tiles);
  tt_tin **pieces = calloc(nt, sizeof *pieces);
  for (size_t j = 0; j < nty; j++)
    for (size_t i = 0; i < ntx; i++) {
      tt_tile *t = &tiles[j * ntx + i];
      t->col0 = i * n;
      t->row0 = j * n;
      t->col1 = (i + 1) * n < W - 1 ? (i + 1) * n : W - 1;
      t->row1 = (j + 1) * n < H - 1 ? (j + 1) * n : H - 1;
      t->dem_width = W;
      t->dem_height = H;
    }
  for (size_t k = 0; k < nt; k++) {
    size_t i = reverse ? nt - 1 - k : k;
    tt_grid *win = window_of(g, &tiles[i]);
    tt_status st = tt_tile_run(ctx, win, &tiles[i], opt, &pieces[i]);
    if (st != TT_OK)
      fprintf(stderr, "tile %zu: %s\n", i, tt_context_errmsg(ctx));
    CHECK(st == TT_OK);
    tt_grid_destroy(win);
  }
  double gt[6];
  tt_grid_get_geotransform(g, gt);
  tt_tin_merger *m = NULL;
  tt_tin *tin = NULL;
  CHECK(tt_tin_merger_create(ctx, W, H, gt, &m) == TT_OK);
  for (size_t i = 0; i < nt; i++)
    if (pieces[i])
      CHECK(tt_tin_merger_add(ctx, m, pieces[i], &tiles[i]) == TT_OK);
  CHECK(tt_tin_merger_finish(ctx, m, &tin) == TT_OK);
  tt_tin_merger_destroy(m);
  for (size_t i = 0; i < nt; i++)
    tt_tin_destroy(pieces[i]);
  free(pieces);
  free(tiles);
  return tin;
}

/* Everything the oracles say about a tiled TIN; returns its vertices. */
static size_t check_tin(const char *what, const tt_grid *g, const tt_tin *tin,
                        double bound, bool all_valid)
{
  tt_conform c;
  memset(&c, 0, sizeof c);
  CHECK(tt_conform_check(g, tin, &c));
  if (c.over_used || c.t_junctions || c.cracks || c.same_sample)
    fprintf(stderr, "%s: over-used edges %zu, T-junctions %zu, cracks %zu, "
            "shared samples %zu\n", what, c.over_used, c.t_junctions,
            c.cracks, c.same_sample);
  CHECK_INT_EQ(c.over_used, 0);
  CHECK_INT_EQ(c.t_junctions, 0);
  CHECK_INT_EQ(c.cracks, 0);
  CHECK_INT_EQ(c.same_sample, 0);
  tt_tin_summary s;
  tt_tin_get_summary(tin, &s);
  if (all_valid) {
    CHECK_INT_EQ(c.euler, 1);
    CHECK_INT_EQ(s.components, 1);
  }
  double *xyz = tt_oracle_pixel_triangles(tin);
  tt_eval_result ev;
  CHECK(tt_eval_triangles(ctx, g, tt_tin_triangle_count(tin), xyz, &ev) ==
        TT_OK);
  free(xyz);
  size_t valid = 0;
  CHECK(tt_grid_check(ctx, g, &valid) == TT_OK);
  CHECK_INT_EQ(ev.overlapped, 0);
  CHECK_INT_EQ(ev.degenerate, 0);
  CHECK_INT_EQ(ev.uncovered, tt_oracle_uncarriable(g));
  CHECK_INT_EQ(tt_oracle_nodata_inside(g, tin), 0);
  if (!(ev.errors.max_error <= bound))
    fprintf(stderr, "%s: max error %.17g above the bound %.17g\n", what,
            ev.errors.max_error, bound);
  CHECK(ev.errors.max_error <= bound);
  /* the merge's own statistics are the whole TIN's */
  CHECK_INT_EQ(s.valid_samples, valid);
  CHECK_INT_EQ(s.errors.covered, valid - ev.uncovered);
  CHECK_DBL_NEAR(s.errors.max_error, ev.errors.max_error, 1e-9);
  CHECK_DBL_NEAR(s.errors.rmse, ev.errors.rmse, 1e-6 * (1 + ev.errors.rmse));
  size_t star = 0;
  for (size_t t = 0; t < tt_tin_triangle_count(tin); t++) {
    tt_triangle_info ti;
    tt_tin_triangle(tin, t, &ti);
    star += ti.samples;
  }
  CHECK_INT_EQ(star, valid - ev.uncovered);
  return tt_tin_vertex_count(tin);
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
    if (x.col != y.col || x.row != y.row || x.star_samples != y.star_samples)
      return false;
  }
  for (size_t t = 0; t < tt_tin_triangle_count(a); t++) {
    tt_triangle_info x, y;
    tt_tin_triangle(a, t, &x);
    tt_tin_triangle(b, t, &y);
    if (memcmp(x.v, y.v, sizeof x.v) || x.samples != y.samples ||
        x.max_error != y.max_error)
      return false;
  }
  return true;
}

static tt_grid *fractal(size_t size, uint64_t seed)
{
  tt_synth_options so;
  tt_synth_options_init(&so, TT_SYNTH_DIAMOND_SQUARE);
  so.nx = so.ny = size;
  so.seed = seed;
  tt_grid *g = NULL;
  CHECK(tt_synth_generate(ctx, &so, &g) == TT_OK);
  return g;
}

static void test_fractal(void)
{
  tt_grid *g = fractal(513, 7);
  tt_refine_options o;
  tt_refine_options_init(&o);
  o.max_error = 12.0;
  o.threads = 1;
  tt_tin *untiled = NULL;
  CHECK(tt_refine_run(ctx, g, &o, &untiled) == TT_OK);
  size_t nu = tt_tin_vertex_count(untiled);
  static const size_t sizes[] = {128, 100, 257, 37};
  for (size_t k = 0; k < sizeof sizes / sizeof sizes[0]; k++) {
    tt_tin *tin = run_tiled(g, sizes[k], &o, false);
    char what[64];
    snprintf(what, sizeof what, "fractal 513, tiles of %zu", sizes[k]);
    size_t nv = check_tin(what, g, tin, o.max_error, true);
    double more = (double)nv / (double)nu - 1;
    printf("%s: %zu vertices, untiled %zu (%+.2f %%)\n", what, nv, nu,
           100 * more);
    if (sizes[k] >= 100)
      CHECK(more < 0.05 && more > -0.05);
    if (k == 0) {
      tt_tin *rev = run_tiled(g, sizes[k], &o, true);
      CHECK(same_tin(tin, rev));
      tt_tin_destroy(rev);
    }
    tt_tin_destroy(tin);
  }
  tt_tin_destroy(untiled);
  tt_grid_destroy(g);
}

/* Every criterion, with its default repair and final pass, and the
 * optimisers: the borders stay, the bound holds. */
static void test_criteria(void)
{
  tt_grid *g = fractal(129, 3);
  static const tt_criterion crits[] = {
      TT_CRITERION_DELAUNAY, TT_CRITERION_MINMAX_ANGLE, TT_CRITERION_MIN_AREA,
      TT_CRITERION_L2, TT_CRITERION_ABN, TT_CRITERION_MEAN_CURVATURE};
  for (size_t k = 0; k < sizeof crits / sizeof crits[0]; k++) {
    tt_refine_options o;
    tt_refine_options_init(&o);
    o.max_error = 3.0;
    o.threads = 1;
    o.criterion = crits[k];
    if (crits[k] == TT_CRITERION_MINMAX_ANGLE)
      o.optimize = TT_OPTIMIZE_LOOKAHEAD;
    tt_tin *tin = run_tiled(g, 40, &o, false);
    char what[64];
    snprintf(what, sizeof what, "criterion %s", tt_criterion_name(crits[k]));
    check_tin(what, g, tin, o.max_error, true);
    tt_tin_destroy(tin);
  }
  tt_grid_destroy(g);
}

/* Nodata across a border, along one, at a tile corner, in specks. */
static void test_nodata(void)
{
  tt_grid *g = fractal(257, 11);
  float *z = tt_grid_heights(g);
  size_t W = 257;
  uint64_t rng = 5;
  for (size_t r = 0; r < W; r++)
    for (size_t c = 0; c < W; c++) {
      double dx = (double)c - 64, dy = (double)r - 100;
      bool hole = dx * dx + dy * dy < 30 * 30;               /* across x=64 */
      hole |= c == 128 && r > 20 && r < 60;                  /* along x=128 */
      hole |= c >= 126 && c <= 129 && r >= 126 && r <= 131;  /* a corner */
      hole |= r == 64 && c > 150 && c < 170 && c % 3 == 0;   /* along y=64 */
      hole |= c > 190 && r > 190;                            /* a DEM corner */
      hole |= tt_test_uniform(&rng) < 0.003;                 /* specks */
      if (hole)
        z[r * W + c] = NAN;
    }
  tt_refine_options o;
  tt_refine_options_init(&o);
  o.max_error = 1.5;
  o.threads = 1;
  static const size_t sizes[] = {64, 50, 17};
  for (size_t k = 0; k < sizeof sizes / sizeof sizes[0]; k++) {
    tt_tin *tin = run_tiled(g, sizes[k], &o, false);
    char what[64];
    snprintf(what, sizeof what, "nodata, tiles of %zu", sizes[k]);
    check_tin(what, g, tin, o.max_error, false);
    tt_tin *rev = run_tiled(g, sizes[k], &o, true);
    CHECK(same_tin(tin, rev));
    tt_tin_destroy(rev);
    tt_tin_destroy(tin);
  }
  tt_grid_destroy(g);
}

static void test_refusals(void)
{
  tt_grid *g = fractal(65, 1);
  tt_refine_options o;
  tt_refine_options_init(&o);
  o.max_error = 1;
  tt_tile t = {0, 0, 32, 32, 65, 65};
  tt_grid *win = window_of(g, &t);
  tt_tin *piece = NULL;
  o.max_points = 100;
  CHECK(tt_tile_run(ctx, win, &t, &o, &piece) == TT_ERR_ARG);
  CHECK(strstr(tt_context_errmsg(ctx), "budget") != NULL);
  o.max_points = 0;
  tt_tile bad = {0, 0, 32, 32, 65, 65};
  bad.col1 = 0;
  CHECK(tt_tile_run(ctx, win, &bad, &o, &piece) == TT_ERR_ARG);
  tt_tile other = {0, 0, 16, 32, 65, 65}; /* a window of another size */
  CHECK(tt_tile_run(ctx, win, &other, &o, &piece) == TT_ERR_ARG);
  CHECK(strstr(tt_context_errmsg(ctx), "window") != NULL);
  CHECK(piece == NULL);
  tt_grid_destroy(win);
  tt_grid_destroy(g);
}

int main(void)
{
  ctx = tt_context_create();
  test_fractal();
  test_criteria();
  test_nodata();
  test_refusals();
  tt_context_destroy(ctx);
  return tt_test_failures ? 1 : 0;
}
