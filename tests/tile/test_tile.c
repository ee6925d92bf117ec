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
 *  - decimation in tiles keeps the border polylines' vertices, with every
 *    decimation option; no optimiser swaps a border edge;
 *  - a tile's error-against-count curve (budgets) matches untiled runs;
 *  - bad tiles and budgets are refused;
 *  - the streamed merge (src/tile/stream.c) hands out every triangle and
 *    vertex of the merged TIN once, in order, with the same values, star
 *    statistics and importances bit for bit, triangles whose records
 *    (areas, slope, aspect, angles) are the merged TIN's bit for bit, and
 *    the same summary: insertion and decimation, in the affine frame and
 *    on ground points with an area function (as a geographic DEM's
 *    windows have them). */
#include "terratin/terratin.h"
#include "tt_test.h"
#include "tt_tin_conform.h"
#include "tt_tin_oracle.h"
#include "tile/tile.h"
#include "tin/tin.h"

#include <math.h>
#include <stdbool.h>

static tt_context *ctx;
/* window_of gives the windows ground points and an area function */
static bool ground_windows;

/* A geodesic-like area: the plane's, scaled by the mean map y. */
static double warped_area(const double p[4], const double x[3],
                          const double y[3])
{
  double a = 0.5 * fabs((x[1] - x[0]) * (y[2] - y[0]) -
                        (x[2] - x[0]) * (y[1] - y[0]));
  return a * (1 + p[0] * (y[0] + y[1] + y[2]) / 3);
}

/* Ground points of window win (its first sample at column c0, row r0 of
 * the raster of geotransform gt): the map coordinates, warped smoothly,
 * computed from the raster's column and row as the GDAL reader does, so
 * two windows agree on every sample they share. */
static void add_ground(tt_grid *win, size_t c0, size_t r0, const double gt[6])
{
  CHECK(tt_grid_alloc_ground_points(ctx, win) == TT_OK);
  double *xy = tt_grid_ground_xy(win);
  size_t w = tt_grid_width(win), h = tt_grid_height(win);
  for (size_t y = 0; y < h; y++)
    for (size_t x = 0; x < w; x++) {
      double c = (double)(c0 + x) + 0.5, r = (double)(r0 + y) + 0.5;
      double mx = gt[0] + c * gt[1] + r * gt[2];
      double my = gt[3] + c * gt[4] + r * gt[5];
      xy[2 * (y * w + x)] = mx * (1 + 1e-3 * sin(my * 0.013));
      xy[2 * (y * w + x) + 1] = my * (1 + 1e-3 * cos(mx * 0.011));
    }
  tt__grid_set_ground_origin(win, c0, r0, gt);
  const double par[4] = {1e-4, 0, 0, 0};
  tt_grid_set_area_fn(win, warped_area, par);
}

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
  if (ground_windows) {
    tt_grid_get_geotransform(g, gt);
    add_ground(win, c0, r0, gt);
  }
  free(z);
  free(zf);
  return win;
}

/* The pieces through tt__tin_stream against the merged TIN: the same
 * triangles (corners mapped to the global ids, counts, rmse), the same
 * vertices in id order with the same star statistics, the same summary;
 * the reorder buffer stays within about a row of tiles. */
static void check_stream(tt_tin *const *pieces, const tt_tile *tiles,
                         size_t nt, size_t n, const double gt[6],
                         const tt_tin *tin)
{
  size_t W = tiles[0].dem_width, H = tiles[0].dem_height;
  size_t ntx = (W - 2) / n + 1;
  tt__tin_stream *s = NULL;
  CHECK(tt__tin_stream_create(ctx, W, H, n, gt, &s) == TT_OK);
  size_t tri = 0, vtx = 0, max_pending = 0, row_max = 0, bad = 0;
  for (size_t k = 0; k < nt; k++) {
    tt__stream_batch b;
    CHECK(tt__tin_stream_add(ctx, s, pieces[k], &tiles[k], k, &b) == TT_OK);
    if (b.tri) {
      CHECK(b.tri_first == tri);
      for (size_t i = 0; i < b.tri->nt; i++, tri++)
        for (int c = 0; c < 3; c++)
          bad += b.map[b.tri->tv[3 * i + c]] != tin->tv[3 * tri + c];
      for (size_t i = 0; i < b.tri->nt; i++) {
        size_t j = b.tri_first + i;
        bad += b.tri->t_n[i] != tin->t_n[j];
        bad += memcmp(&b.tri->t_rmse[i], &tin->t_rmse[j], sizeof(double)) != 0;
        bad += b.tri->t_max[i] != tin->t_max[j];
        /* the record a writer makes: on the ground points, with the area
         * function, when the TIN has them */
        tt_triangle_info x, y;
        CHECK(tt_tin_triangle(b.tri, i, &x) == TT_OK);
        CHECK(tt_tin_triangle(tin, j, &y) == TT_OK);
        const double a[] = {x.area_2d, x.area_3d, x.slope_deg, x.aspect_deg,
                            x.min_angle_deg, x.max_angle_deg};
        const double m[] = {y.area_2d, y.area_3d, y.slope_deg, y.aspect_deg,
                            y.min_angle_deg, y.max_angle_deg};
        bad += memcmp(a, m, sizeof a) != 0;
      }
      bad += (b.tri->vgxy != NULL) != (tin->vgxy != NULL);
      bad += (b.tri->area_fn != NULL) != (tin->area_fn != NULL);
    }
    CHECK(b.vtx_first == vtx);
    for (size_t i = 0; b.vtx && i < b.vtx->nv; i++, vtx++) {
      bad += b.vtx->vc[i] != tin->vc[vtx] || b.vtx->vr[i] != tin->vr[vtx];
      bad += b.vtx->vzd[i] != tt__tin_z(tin, vtx);
      bad += memcmp(&b.vtx->v_ins_err[i], &tin->v_ins_err[vtx],
                    sizeof(double)) != 0;
      bad += b.vtx->v_star_max[i] != tin->v_star_max[vtx];
      bad += memcmp(&b.vtx->v_star_rmse[i], &tin->v_star_rmse[vtx],
                    sizeof(double)) != 0;
      bad += b.vtx->v_star_n[i] != tin->v_star_n[vtx];
      tt_vertex_info x, y;
      CHECK(tt_tin_vertex(b.vtx, i, &x) == TT_OK);
      CHECK(tt_tin_vertex(tin, vtx, &y) == TT_OK);
      bad += memcmp(&x.importance, &y.importance, sizeof(double)) != 0;
    }
    size_t p = tt__tin_stream_pending(s);
    max_pending = p > max_pending ? p : max_pending;
    /* the vertices a row of tiles and one more tile made */
    size_t row = 0;
    for (size_t q = k + 1 > ntx + 1 ? k - ntx : 0; q <= k; q++)
      row += pieces[q]->nv;
    row_max = row > row_max ? row : row_max;
    CHECK(p <= row);
  }
  if (bad)
    fprintf(stderr, "stream: %zu values differ from the merged TIN's\n",
            bad);
  CHECK(bad == 0);
  CHECK(tri == tin->nt);
  CHECK(vtx == tin->nv);
  tt_tin_summary a, m;
  double zmin, zmax;
  tt__tin_stream_summary(s, &a, &zmin, &zmax);
  tt_tin_get_summary(tin, &m);
  CHECK(a.vertices == m.vertices && a.triangles == m.triangles);
  CHECK(a.components == m.components);
  CHECK(a.valid_samples == m.valid_samples);
  CHECK(a.forced_vertices == m.forced_vertices);
  CHECK(a.errors.covered == m.errors.covered);
  CHECK(a.errors.max_error == m.errors.max_error);
  CHECK(a.errors.max_col == m.errors.max_col &&
        a.errors.max_row == m.errors.max_row);
  CHECK(a.errors.rmse == m.errors.rmse && a.errors.l2 == m.errors.l2);
  CHECK(a.errors.total_abs == m.errors.total_abs);
  CHECK(a.start_vertices == m.start_vertices);
  CHECK(a.removed_vertices == m.removed_vertices);
  CHECK(a.rounds == m.rounds && a.refused_bound == m.refused_bound);
  printf("stream, tiles of %zu: %zu vertices, at most %zu pending (a row "
         "of tiles and one: at most %zu)\n", n, vtx, max_pending, row_max);
  tt__tin_stream_destroy(s);
}

/* Tiles of n cells; run in reverse order when reverse, merged in order. */
static tt_tin *run_tiled_by(const tt_grid *g, size_t n,
                            const tt_refine_options *opt,
                            const tt_decimate_options *dopt, bool reverse)
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
    tt_status st = dopt ? tt_tile_decimate(ctx, win, &tiles[i], dopt,
                                           &pieces[i])
                        : tt_tile_run(ctx, win, &tiles[i], opt, &pieces[i]);
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
  check_stream(pieces, tiles, nt, n, gt, tin);
  for (size_t i = 0; i < nt; i++)
    tt_tin_destroy(pieces[i]);
  free(pieces);
  free(tiles);
  return tin;
}

static tt_tin *run_tiled(const tt_grid *g, size_t n,
                         const tt_refine_options *opt, bool reverse)
{
  return run_tiled_by(g, n, opt, NULL, reverse);
}

static tt_tin *run_tiled_dec(const tt_grid *g, size_t n,
                             const tt_decimate_options *opt, bool reverse)
{
  return run_tiled_by(g, n, NULL, opt, reverse);
}

static int cmp_u64(const void *a, const void *b)
{
  uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
  return (x > y) - (x < y);
}

/* The tile borders of a TIN in tiles of n: every pair of consecutive
 * vertices along a shared border line (both valid samples whose segment
 * lies in the TIN) is joined by an edge of the TIN (no border edge was
 * swapped or split); and when ref is given, the vertices on the border
 * lines are exactly ref's (the border polylines). Returns the number of
 * vertices on border lines. */
static size_t check_borders(const char *what, const tt_grid *g, size_t n,
                            const tt_tin *tin, const tt_tin *ref)
{
  size_t W = tt_grid_width(g), H = tt_grid_height(g);
  size_t nv = tt_tin_vertex_count(tin), nt = tt_tin_triangle_count(tin);
  int32_t *id = malloc(W * H * sizeof *id);
  for (size_t i = 0; i < W * H; i++)
    id[i] = -1;
  for (size_t v = 0; v < nv; v++) {
    tt_vertex_info vi;
    tt_tin_vertex(tin, v, &vi);
    id[(size_t)vi.row * W + (size_t)vi.col] = (int32_t)v;
  }
  uint8_t *ref_id = calloc(W * H, 1);
  for (size_t v = 0; ref && v < tt_tin_vertex_count(ref); v++) {
    tt_vertex_info vi;
    tt_tin_vertex(ref, v, &vi);
    ref_id[(size_t)vi.row * W + (size_t)vi.col] = 1;
  }
  uint64_t *edges = malloc(3 * nt * sizeof *edges);
  for (size_t t = 0; t < nt; t++) {
    tt_triangle_info ti;
    tt_tin_triangle(tin, t, &ti);
    for (int k = 0; k < 3; k++) {
      uint64_t a = (uint64_t)ti.v[k], b = (uint64_t)ti.v[(k + 1) % 3];
      edges[3 * t + k] = a < b ? a << 32 | b : b << 32 | a;
    }
  }
  qsort(edges, 3 * nt, sizeof *edges, cmp_u64);
  size_t on_lines = 0, missing = 0, differ = 0;
  /* vertical lines x = n i, horizontal lines y = n j, inside the DEM */
  for (int dir = 0; dir < 2; dir++) {
    size_t lines = dir == 0 ? W : H, len = dir == 0 ? H : W;
    for (size_t at = n; at + 1 < lines; at += n) {
      int32_t prev = -1;
      size_t prev_i = 0;
      for (size_t i = 0; i < len; i++) {
        size_t c = dir == 0 ? at : i, r = dir == 0 ? i : at;
        int32_t v = id[r * W + c];
        if (ref)
          differ += (v >= 0) != (ref_id[r * W + c] != 0);
        if (v < 0)
          continue;
        on_lines++;
        /* the segment from the previous vertex: all valid samples */
        bool valid_run = prev >= 0;
        for (size_t k = prev_i; valid_run && k <= i; k++)
          valid_run = !isnan(tt_grid_sample(g, dir == 0 ? at : k,
                                            dir == 0 ? k : at));
        if (valid_run && i - prev_i >= 2) {
          uint64_t a = (uint64_t)prev, b = (uint64_t)v;
          uint64_t key = a < b ? a << 32 | b : b << 32 | a;
          if (!bsearch(&key, edges, 3 * nt, sizeof *edges, cmp_u64))
            missing++;
        }
        prev = v;
        prev_i = i;
      }
    }
  }
  if (missing || differ)
    fprintf(stderr, "%s: %zu border segments without their edge, %zu "
            "border samples differing from the polylines\n", what, missing,
            differ);
  CHECK_INT_EQ(missing, 0);
  CHECK_INT_EQ(differ, 0);
  free(id);
  free(ref_id);
  free(edges);
  return on_lines;
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

/* Decimation in tiles: every start, importance, selection and hole rule;
 * the bound on every sample, conformity, the border vertices exactly the
 * border polylines (those of insertion's tiles at the same bound), the
 * tile order irrelevant. */
static void dec_case(const char *what, const tt_grid *g, size_t n,
                     const tt_decimate_options *o, const tt_tin *ref,
                     bool all_valid, bool reverse)
{
  tt_tin *tin = run_tiled_dec(g, n, o, false);
  /* greedy:N starts above the bound (no removal adds to its error) */
  double bound = o->start == TT_DSTART_GREEDY_N ? INFINITY : o->max_error;
  size_t nv = check_tin(what, g, tin, bound, all_valid);
  size_t nb = check_borders(what, g, n, tin, ref);
  printf("%s: %zu vertices, %zu on tile borders\n", what, nv, nb);
  if (reverse) {
    tt_tin *rev = run_tiled_dec(g, n, o, true);
    CHECK(same_tin(tin, rev));
    tt_tin_destroy(rev);
  }
  tt_tin_destroy(tin);
}

static void test_decimate(void)
{
  tt_grid *g = fractal(65, 5);
  tt_refine_options ro;
  tt_refine_options_init(&ro);
  ro.max_error = 2.0;
  ro.threads = 1;
  tt_tin *ref = run_tiled(g, 20, &ro, false);
  tt_decimate_options o;
  tt_decimate_options_init(&o);
  o.max_error = ro.max_error;
  o.threads = 1;
  tt_tin *untiled = NULL;
  CHECK(tt_decimate_run(ctx, g, &o, &untiled) == TT_OK);
  tt_tin *tiled = run_tiled_dec(g, 20, &o, false);
  printf("decimation, fractal 65 at 2: tiles of 20 %zu vertices, untiled "
         "%zu, insertion in tiles %zu\n", tt_tin_vertex_count(tiled),
         tt_tin_vertex_count(untiled), tt_tin_vertex_count(ref));
  /* within a few per cent of the untiled decimation */
  double more = (double)tt_tin_vertex_count(tiled) /
                (double)tt_tin_vertex_count(untiled) - 1;
  CHECK(more < 0.10 && more > -0.10);
  tt_tin_destroy(tiled);
  tt_tin_destroy(untiled);
  dec_case("decimate, start all", g, 20, &o, ref, true, true);
  static const tt_importance imps[] = {
      TT_IMPORTANCE_DEGREE, TT_IMPORTANCE_HDH, TT_IMPORTANCE_ABH,
      TT_IMPORTANCE_VOLUME, TT_IMPORTANCE_DROP};
  for (size_t k = 0; k < sizeof imps / sizeof imps[0]; k++) {
    tt_decimate_options oi = o;
    oi.importance = imps[k];
    char what[80];
    snprintf(what, sizeof what, "decimate, importance %s",
             tt_importance_name(imps[k]));
    dec_case(what, g, 20, &oi, ref, true, false);
  }
  tt_decimate_options os = o;
  os.selection = TT_SELECTION_SEQUENTIAL;
  dec_case("decimate, sequential", g, 20, &os, ref, true, false);
  tt_decimate_options op = o;
  op.onepass = 1;
  dec_case("decimate, onepass", g, 20, &op, ref, true, false);
  tt_decimate_options oh = o;
  oh.hole = TT_HOLE_DP;
  dec_case("decimate, hole dp", g, 20, &oh, ref, true, false);
  tt_decimate_options om = o;
  om.hole = TT_HOLE_MINANGLE;
  om.criterion = TT_CRITERION_MINMAX_ANGLE;
  om.optimize = TT_OPTIMIZE_LOOKAHEAD;
  dec_case("decimate, minmax_angle, lookahead", g, 20, &om, ref, true,
           false);
  tt_decimate_options og = o;
  og.start = TT_DSTART_GREEDY;
  dec_case("decimate, start greedy", g, 20, &og, ref, true, false);
  og.start = TT_DSTART_GREEDY_N;
  og.start_points = 1200; /* a tile of 20 inserts 1200 x 21^2 / 65^2 */
  dec_case("decimate, start greedy:1200", g, 20, &og, ref, true, false);
  tt_tin_destroy(ref);
  tt_grid_destroy(g);

  /* nodata across, along and at the corners of borders */
  g = fractal(65, 9);
  float *z = tt_grid_heights(g);
  uint64_t rng = 3;
  for (size_t r = 0; r < 65; r++)
    for (size_t c = 0; c < 65; c++) {
      double dx = (double)c - 16, dy = (double)r - 27;
      bool hole = dx * dx + dy * dy < 7 * 7;
      hole |= c == 32 && r > 5 && r < 15;
      hole |= c >= 31 && c <= 33 && r >= 31 && r <= 34;
      hole |= c > 50 && r > 50;
      hole |= tt_test_uniform(&rng) < 0.003;
      if (hole)
        z[r * 65 + c] = NAN;
    }
  ref = run_tiled(g, 16, &ro, false);
  dec_case("decimate, nodata", g, 16, &o, ref, false, true);
  og.start = TT_DSTART_GREEDY;
  dec_case("decimate, nodata, start greedy", g, 16, &og, ref, false, false);
  tt_tin_destroy(ref);
  tt_grid_destroy(g);
}

/* The optimisers per tile never swap a border edge: the border vertices
 * stay the polylines' and each border segment stays an edge
 * (check_borders), with the bound and conformity (check_tin). */
static void test_optimizers(void)
{
  tt_grid *g = fractal(65, 13);
  tt_refine_options o;
  tt_refine_options_init(&o);
  o.max_error = 2.0;
  o.threads = 1;
  o.optimize = TT_OPTIMIZE_NONE;
  tt_tin *ref = run_tiled(g, 20, &o, false);
  static const struct {
    tt_criterion c;
    tt_optimize opt;
  } cases[] = {
      {TT_CRITERION_DELAUNAY, TT_OPTIMIZE_LOCAL},
      {TT_CRITERION_L2, TT_OPTIMIZE_LOCAL},
      {TT_CRITERION_ABN, TT_OPTIMIZE_LOOKAHEAD},
      {TT_CRITERION_MIN_AREA, TT_OPTIMIZE_ANNEAL},
      {TT_CRITERION_MINMAX_ANGLE, TT_OPTIMIZE_EDGE_INSERTION}};
  for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
    tt_refine_options oo = o;
    oo.criterion = cases[k].c;
    oo.optimize = cases[k].opt;
    tt_tin *tin = run_tiled(g, 20, &oo, false);
    char what[80];
    snprintf(what, sizeof what, "optimize %s, %s",
             tt_optimize_name(cases[k].opt), tt_criterion_name(cases[k].c));
    check_tin(what, g, tin, o.max_error, true);
    check_borders(what, g, 20, tin, ref);
    tt_tin *rev = run_tiled(g, 20, &oo, true);
    CHECK(same_tin(tin, rev));
    tt_tin_destroy(rev);
    tt_tin_destroy(tin);
  }
  tt_tin_destroy(ref);
  tt_grid_destroy(g);
}

/* tt_tile_curve: on a tile that is the whole DEM (no shared side) a run
 * to a bound E stops at the curve's first point at or below E, so the
 * curve's count at E is an untiled run's, for any E. */
typedef struct curve_rec {
  size_t n, pts[20000];
  double err[20000];
} curve_rec;

static void record(void *arg, size_t vertices, double max_error)
{
  curve_rec *c = arg;
  if (c->n < 20000) {
    c->pts[c->n] = vertices;
    c->err[c->n] = max_error;
    c->n++;
  }
}

static void test_curve(void)
{
  tt_grid *g = fractal(129, 21);
  tt_tile t = {0, 0, 128, 128, 129, 129};
  tt_grid *win = window_of(g, &t);
  tt_refine_options o;
  tt_refine_options_init(&o);
  o.threads = 1;
  curve_rec *c = calloc(1, sizeof *c);
  CHECK(tt_tile_curve(ctx, win, &t, &o, 129 * 129, record, c) == TT_OK);
  CHECK(c->n > 100);
  CHECK_INT_EQ(c->pts[0], 4); /* the corners */
  CHECK(c->pts[c->n - 1] <= 129 * 129);
  static const double bounds[] = {20, 8, 3, 1.5};
  for (size_t k = 0; k < 4; k++) {
    size_t at = 0;
    while (at < c->n && c->err[at] > bounds[k])
      at++;
    CHECK(at < c->n);
    o.max_error = bounds[k];
    tt_tin *tin = NULL;
    CHECK(tt_refine_run(ctx, g, &o, &tin) == TT_OK);
    printf("curve: at %g, %zu vertices; a run to it %zu\n", bounds[k],
           c->pts[at], tt_tin_vertex_count(tin));
    CHECK_INT_EQ(c->pts[at], tt_tin_vertex_count(tin));
    tt_tin_destroy(tin);
  }
  /* a tile with shared sides: its vertices never drop, its errors are
   * the candidates' (the sides left out), and it ends at the cap */
  tt_tile in = {40, 40, 80, 80, 129, 129};
  tt_grid *w2 = window_of(g, &in);
  c->n = 0;
  CHECK(tt_tile_curve(ctx, w2, &in, &o, 200, record, c) == TT_OK);
  CHECK(c->n > 10);
  for (size_t i = 1; i < c->n; i++)
    CHECK(c->pts[i] == c->pts[i - 1] + 1 || i + 1 == c->n);
  CHECK(c->pts[c->n - 1] <= c->pts[0] + 200);
  o.max_error = 1;
  tt_tin *none = NULL;
  CHECK(tt_tile_curve(ctx, w2, &in, &o, 0, record, c) == TT_ERR_ARG);
  CHECK(none == NULL);
  free(c);
  tt_grid_destroy(w2);
  tt_grid_destroy(win);
  tt_grid_destroy(g);
}

/* The streamed merge on ground points (a geographic DEM's windows):
 * insertion and decimation, each triangle's record the merged TIN's bit
 * for bit (check_stream), the TIN measured on the ground. */
static void test_stream_ground(void)
{
  tt_grid *g = fractal(129, 5);
  ground_windows = true;
  tt_refine_options o;
  tt_refine_options_init(&o);
  o.max_error = 3.0;
  o.threads = 1;
  tt_tin *tin = run_tiled(g, 40, &o, false);
  CHECK(tin->vgxy != NULL && tin->area_fn != NULL);
  check_tin("ground points, tiles of 40", g, tin, o.max_error, true);
  tt_tin_destroy(tin);
  tt_decimate_options d;
  tt_decimate_options_init(&d);
  d.max_error = 3.0;
  d.threads = 1;
  tin = run_tiled_dec(g, 40, &d, false);
  CHECK(tin->vgxy != NULL && tin->v_importance != NULL);
  tt_tin_destroy(tin);
  ground_windows = false;
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
  TT_RUN(test_fractal());
  TT_RUN(test_criteria());
  TT_RUN(test_nodata());
  TT_RUN(test_decimate());
  TT_RUN(test_optimizers());
  TT_RUN(test_curve());
  TT_RUN(test_stream_ground());
  TT_RUN(test_refusals());
  tt_context_destroy(ctx);
  return tt_test_failures ? 1 : 0;
}
