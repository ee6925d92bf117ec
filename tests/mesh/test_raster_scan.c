/*
 * test_raster_scan.c -- the tiled candidate scan (raster_scan.h) against
 * the plain row scan, and both against a brute force.
 *
 * The tiled scan skips the tiles whose error bound is below the best error
 * found so far; it must find exactly the same sample as the row scan (same
 * error, same index: ties go to the first sample in row-major order). The
 * grids are made to break it: plateaus of integer heights (ties of equal
 * errors across tiles), nodata holes and whole nodata tiles, heights far
 * from zero, steep planes, sides that are not multiples of the tile size;
 * triangles are random, from slivers to the whole grid, each also scanned
 * in random bands of rows (as the parallel jobs of refine.c do).
 * The brute force evaluates every owned sample with the kernels' own plane
 * expression and takes the largest error, the first in row-major order;
 * the statistics (count, max, sums) are checked against it too. Narrow
 * triangles (raster_scan.c finds their rows by a lane test, not by
 * stepping the edges) are most of the small ones here. Everything runs
 * twice: with the SSE2 row search and with the AVX-512 one (where the
 * processor has it; else SSE2 again).
 * Grids of doubles (tt_precision) run the same checks, and two more kinds
 * whose heights floats cannot hold (2^30 + integers, 10^6 + thousandths:
 * a float plane in the tiles would be looser than the errors sought);
 * each float grid is also copied into a grid of doubles, which must give
 * the same candidates and statistics bit for bit.
 */
#include "mesh/raster_scan.h"
#include "tt_test.h"

static uint64_t rng_state = 0x9e3779b97f4a7c15ull;

static uint64_t rnd(void)
{
  uint64_t x = rng_state;
  x ^= x << 13;
  x ^= x >> 7;
  x ^= x << 17;
  return rng_state = x;
}

static double rnd_unit(void) { return (double)(rnd() >> 11) / 9007199254740992.0; }

static int64_t rnd_in(int64_t lo, int64_t hi)
{
  return lo + (int64_t)(rnd() % (uint64_t)(hi - lo + 1));
}

enum { G_NOISE, G_PLATEAU, G_HOLES, G_FAR, G_STEEP, G_FLAT, G_FLOATS,
       G_INT30 = G_FLOATS, G_MICRO, G_COUNT };

static const char *grid_name[G_COUNT] = {"noise", "plateau", "holes",
                                         "far", "steep", "flat",
                                         "2^30 + integers (doubles)",
                                         "1e6 + thousandths (doubles)"};

/* Kinds below G_FLOATS are grids of floats (as doubles when f64); the
 * others hold doubles that no float holds. */
static tt_grid *make_grid(tt_context *ctx, int kind, size_t nx, size_t ny,
                          bool f64)
{
  tt_grid *g = NULL;
  f64 = f64 || kind >= G_FLOATS;
  if ((f64 ? tt_grid_create_f64(ctx, nx, ny, &g)
           : tt_grid_create(ctx, nx, ny, &g)) != TT_OK)
    return NULL;
  float *z = tt_grid_heights(g);
  double *zd = tt_grid_heights_f64(g);
  for (size_t y = 0; y < ny; y++)
    for (size_t x = 0; x < nx; x++) {
      double v = 0;
      double sx = (double)x, sy = (double)y;
      switch (kind) {
      case G_NOISE:
        v = 20 * sin(sx * 0.07) * cos(sy * 0.05) + 3 * rnd_unit();
        break;
      case G_PLATEAU: /* integer steps: equal errors everywhere */
        v = (double)((x / 9 + y / 7) % 5);
        break;
      case G_HOLES:
        v = 10 * sin(sx * 0.11 + sy * 0.03) + rnd_unit();
        if ((x / 8 + y / 8) % 7 == 3 || rnd() % 13 == 0)
          v = NAN; /* whole nodata tiles and scattered holes */
        break;
      case G_FAR:
        v = 8848.0 + 0.01 * rnd_unit() + 0.001 * sx;
        break;
      case G_STEEP:
        v = 250.0 * sx - 180.0 * sy + 2 * rnd_unit();
        break;
      case G_FLAT:
        v = 5.0;
        break;
      case G_INT30: /* plateaus and noise of integers far above 2^24 */
        v = 1073741824.0 + (double)((x / 9 + y / 7) % 5) * 40 +
            floor(30 * rnd_unit());
        break;
      case G_MICRO:
        v = 1e6 + 0.001 * floor(400 * sin(sx * 0.05) * cos(sy * 0.04) +
                                100 * rnd_unit());
        if (rnd() % 17 == 0)
          v = NAN;
        break;
      }
      if (kind < G_FLOATS)
        v = (float)v;
      if (zd)
        zd[y * nx + x] = v;
      else
        z[y * nx + x] = (float)v;
    }
  return g;
}

/* The oracles take the kernels' own plane (raster_scan.h), so that their
 * errors are the same bits; what they check is which samples are scanned
 * and which one wins. */
typedef tt__scan_plane plane;
#define plane_of tt__scan_plane_of

/* Whether (x, y) is owned: strictly inside, or on an owned edge, and not a
 * corner (exact integer edge functions). */
static bool owned(const tt__scan_tri *st, int64_t x, int64_t y)
{
  int64_t dx1 = st->x[1] - st->x[0], dy1 = st->y[1] - st->y[0];
  int64_t dx2 = st->x[2] - st->x[0], dy2 = st->y[2] - st->y[0];
  int64_t s = (dx1 * dy2 - dx2 * dy1) > 0 ? 1 : -1;
  for (int k = 0; k < 3; k++)
    if (st->x[k] == x && st->y[k] == y)
      return false;
  for (int k = 0; k < 3; k++) {
    int k1 = (k + 1) % 3;
    int64_t e = s * ((st->x[k1] - st->x[k]) * (y - st->y[k]) -
                     (st->y[k1] - st->y[k]) * (x - st->x[k]));
    if (e < 0 || (e == 0 && !st->own[k]))
      return false;
  }
  return true;
}

static void brute(const tt_grid *g, const tt__scan_tri *st, int64_t ylo,
                  int64_t yhi, double *out_err, int64_t *out_index)
{
  plane p;
  plane_of(st, &p);
  double best = 0;
  int64_t bi = -1;
  size_t nx = tt_grid_width(g), ny = tt_grid_height(g);
  for (int64_t y = ylo < 0 ? 0 : ylo; y <= yhi && y < (int64_t)ny; y++) {
    double rowbase = p.z0 + p.gy * (double)(y - p.y0);
    for (int64_t x = 0; x < (int64_t)nx; x++) {
      if (!owned(st, x, y))
        continue;
      double e = fabs(tt_grid_sample(g, (size_t)x, (size_t)y) -
                      (rowbase + p.gx * (double)(x - p.x0)));
      if (e > best) { /* NaN compares false */
        best = e;
        bi = y * (int64_t)nx + x;
      }
    }
  }
  *out_err = best;
  *out_index = bi;
}

static void brute_stats(const tt_grid *g, const tt__scan_tri *st,
                        size_t *out_n, double *out_max, double *out_abs,
                        double *out_sq)
{
  plane p;
  plane_of(st, &p);
  size_t nx = tt_grid_width(g), ny = tt_grid_height(g);
  for (int64_t y = 0; y < (int64_t)ny; y++) {
    double rowbase = p.z0 + p.gy * (double)(y - p.y0);
    for (int64_t x = 0; x < (int64_t)nx; x++) {
      double h = tt_grid_sample(g, (size_t)x, (size_t)y);
      if (h != h || !owned(st, x, y))
        continue;
      double e = fabs(h - (rowbase + p.gx * (double)(x - p.x0)));
      (*out_n)++;
      *out_max = e > *out_max ? e : *out_max;
      *out_abs += e;
      *out_sq += e * e;
    }
  }
}

static bool random_tri(const tt_grid *g, int64_t span, tt__scan_tri *st)
{
  int64_t nx = (int64_t)tt_grid_width(g), ny = (int64_t)tt_grid_height(g);
  int64_t cx = rnd_in(0, nx - 1), cy = rnd_in(0, ny - 1);
  for (int k = 0; k < 3; k++) {
    st->x[k] = rnd_in(cx - span > 0 ? cx - span : 0,
                      cx + span < nx - 1 ? cx + span : nx - 1);
    st->y[k] = rnd_in(cy - span > 0 ? cy - span : 0,
                      cy + span < ny - 1 ? cy + span : ny - 1);
  }
  if (rnd() % 4 == 0) { /* the whole grid's corners */
    st->x[0] = 0, st->y[0] = 0;
    st->x[1] = nx - 1, st->y[1] = ny - 1;
    st->x[2] = rnd() % 2 ? 0 : nx - 1;
    st->y[2] = st->x[2] ? 0 : ny - 1;
  }
  int64_t a2 = (st->x[1] - st->x[0]) * (st->y[2] - st->y[0]) -
               (st->x[2] - st->x[0]) * (st->y[1] - st->y[0]);
  if (a2 == 0)
    return false;
  for (int k = 0; k < 3; k++) {
    double h = tt_grid_sample(g, (size_t)st->x[k], (size_t)st->y[k]);
    st->z[k] = h == h && rnd() % 8 ? h : 40 * rnd_unit() - 20;
    st->own[k] = rnd() % 2;
  }
  return true;
}

/* The same values as a grid of doubles. */
static tt_grid *copy_f64(tt_context *ctx, const tt_grid *g)
{
  size_t nx = tt_grid_width(g), ny = tt_grid_height(g);
  tt_grid *d = NULL;
  if (tt_grid_create_f64(ctx, nx, ny, &d) != TT_OK)
    return NULL;
  double *zd = tt_grid_heights_f64(d);
  for (size_t i = 0; i < nx * ny; i++)
    zd[i] = tt_grid_sample(g, i % nx, i / nx);
  return d;
}

/* The scans of triangle st (rows [ylo, yhi]) on grid d, with and without
 * tiles, and its statistics, must be those found on g, bit for bit. */
static int same_as(const tt_grid *g, const tt_grid *d,
                   const tt__scan_tiles *tg, const tt__scan_tiles *td,
                   const tt__scan_tri *st, int64_t ylo, int64_t yhi)
{
  double e[4];
  int64_t i[4];
  tt__scan_candidate_rows(g, NULL, st, ylo, yhi, &e[0], &i[0]);
  tt__scan_candidate_rows(d, NULL, st, ylo, yhi, &e[1], &i[1]);
  tt__scan_candidate_rows(g, tg, st, ylo, yhi, &e[2], &i[2]);
  tt__scan_candidate_rows(d, td, st, ylo, yhi, &e[3], &i[3]);
  for (int k = 1; k < 4; k++)
    if (memcmp(&e[0], &e[k], sizeof e[0]) != 0 || i[0] != i[k]) {
      TT_FAIL_("floats and doubles differ: %.17g at %lld, %.17g at %lld "
               "(scan %d)", e[0], (long long)i[0], e[k], (long long)i[k], k);
      return 1;
    }
  tt__scan_stats a, b;
  tt__scan_stats_run(g, st, &a);
  tt__scan_stats_run(d, st, &b);
  if (a.count != b.count || a.max_index != b.max_index ||
      memcmp(&a.max_err, &b.max_err, sizeof a.max_err) != 0 ||
      memcmp(&a.sum_abs, &b.sum_abs, sizeof a.sum_abs) != 0 ||
      memcmp(&a.sum_sq, &b.sum_sq, sizeof a.sum_sq) != 0) {
    TT_FAIL_("floats and doubles: other statistics (%zu, %.17g; %zu, %.17g)",
             a.count, a.max_err, b.count, b.max_err);
    return 1;
  }
  return 0;
}

static void test_grid(tt_context *ctx, int kind, size_t nx, size_t ny,
                      int ntri, size_t *tiled_count)
{
  tt_grid *g = make_grid(ctx, kind, nx, ny, false);
  CHECK(g != NULL);
  if (!g)
    return;
  CHECK_INT_EQ(tt_grid_precision(g), kind < G_FLOATS ? TT_PRECISION_FLOAT32
                                                     : TT_PRECISION_FLOAT64);
  tt__scan_tiles tiles;
  CHECK(tt__scan_tiles_build(g, NULL, &tiles));
  CHECK_INT_EQ(tiles.ntx, (nx + TT__TILE - 1) / TT__TILE);
  CHECK_INT_EQ(tiles.nty, (ny + TT__TILE - 1) / TT__TILE);
  CHECK((tiles.t != NULL) == (kind < G_FLOATS));
  CHECK((tiles.td != NULL) == (kind >= G_FLOATS));
  /* a float grid's values as doubles, and their tiles */
  tt_grid *d = kind < G_FLOATS ? copy_f64(ctx, g) : NULL;
  tt__scan_tiles dtiles = {0, 0, NULL, NULL};
  if (d)
    CHECK(tt__scan_tiles_build(d, NULL, &dtiles));
  int bad = 0;
  for (int i = 0; i < ntri && bad < 5; i++) {
    tt__scan_tri st;
    int64_t span = (int64_t)(1u << rnd_in(1, 9));
    if (!random_tri(g, span, &st))
      continue;
    if (tt__scan_tiled(&st))
      (*tiled_count)++;
    double e0, e1, e2;
    int64_t i0, i1, i2;
    tt__scan_candidate_rows(g, NULL, &st, INT64_MIN, INT64_MAX, &e0, &i0);
    tt__scan_candidate_rows(g, &tiles, &st, INT64_MIN, INT64_MAX, &e1, &i1);
    if (memcmp(&e0, &e1, sizeof e0) != 0 || i0 != i1) {
      TT_FAIL_("%s grid, triangle (%lld,%lld) (%lld,%lld) (%lld,%lld): "
               "row scan %.17g at %lld, tiled %.17g at %lld", grid_name[kind],
               (long long)st.x[0], (long long)st.y[0], (long long)st.x[1],
               (long long)st.y[1], (long long)st.x[2], (long long)st.y[2], e0,
               (long long)i0, e1, (long long)i1);
      bad++;
    }
    if (i % 8 == 0) {
      /* the statistics walk the same rows: count and max exactly, the
       * sums to rounding */
      size_t n = 0;
      double mx = 0, sa = 0, sq = 0;
      brute_stats(g, &st, &n, &mx, &sa, &sq);
      tt__scan_stats ss;
      tt__scan_stats_run(g, &st, &ss);
      CHECK_INT_EQ(ss.count, n);
      CHECK(memcmp(&ss.max_err, &mx, sizeof mx) == 0);
      CHECK(fabs(ss.sum_abs - sa) <= 1e-12 * (sa + 1));
      CHECK(fabs(ss.sum_sq - sq) <= 1e-12 * (sq + 1));
      brute(g, &st, INT64_MIN, INT64_MAX, &e2, &i2);
      if (memcmp(&e0, &e2, sizeof e0) != 0 || i0 != i2) {
        TT_FAIL_("%s grid: row scan %.17g at %lld, brute force %.17g at "
                 "%lld", grid_name[kind], e0, (long long)i0, e2,
                 (long long)i2);
        bad++;
      }
    }
    /* a band of rows, as a parallel job scans it */
    int64_t ylo = rnd_in(-3, (int64_t)ny), yhi = rnd_in(ylo, (int64_t)ny + 3);
    tt__scan_candidate_rows(g, NULL, &st, ylo, yhi, &e0, &i0);
    tt__scan_candidate_rows(g, &tiles, &st, ylo, yhi, &e1, &i1);
    if (memcmp(&e0, &e1, sizeof e0) != 0 || i0 != i1) {
      TT_FAIL_("%s grid, rows [%lld, %lld]: row scan %.17g at %lld, tiled "
               "%.17g at %lld", grid_name[kind], (long long)ylo,
               (long long)yhi, e0, (long long)i0, e1, (long long)i1);
      bad++;
    }
    if (i % 8 == 0) {
      brute(g, &st, ylo, yhi, &e2, &i2);
      CHECK(memcmp(&e0, &e2, sizeof e0) == 0 && i0 == i2);
    }
    if (d && (same_as(g, d, &tiles, &dtiles, &st, INT64_MIN, INT64_MAX) ||
              same_as(g, d, &tiles, &dtiles, &st, ylo, yhi)))
      bad++;
  }
  tt__scan_tiles_free(&dtiles);
  tt_grid_destroy(d);
  tt__scan_tiles_free(&tiles);
  CHECK(tiles.t == NULL);
  tt_grid_destroy(g);
}

int main(void)
{
  tt_context *ctx = tt_context_create();
  size_t tiled = 0;
  const size_t sizes[][2] = {{403, 297}, {64, 64}, {9, 300}, {1030, 61}};
  /* the row search with SSE2 only, then with AVX-512 where there is one */
  for (int wide = 0; wide < 2; wide++) {
    tt__scan_allow_wide(wide);
    for (int kind = 0; kind < G_COUNT; kind++)
      for (size_t s = 0; s < sizeof sizes / sizeof sizes[0]; s++)
        test_grid(ctx, kind, sizes[s][0], sizes[s][1], 600, &tiled);
  }
  /* the tiled path must really have run */
  CHECK(tiled > 3000);
  printf("%zu of the triangles took the tiled path\n", tiled);
  tt_context_destroy(ctx);
  return tt_test_failures ? 1 : 0;
}
