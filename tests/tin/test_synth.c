/*
 * test_synth.c -- the synthetic terrains (src/tin/synth.c): reproducibility,
 * the study's default sizes, known values of the functions, the fault
 * displacement arithmetic, diamond-square sizes and seeding, refusals.
 */
#include "tt_test.h"

#include "terratin/terratin.h"

#include <float.h>
#include <math.h>
#include <string.h>

static tt_grid *make(tt_context *ctx, const tt_synth_options *opt)
{
  tt_grid *g = NULL;
  CHECK_OK(ctx, tt_synth_generate(ctx, opt, &g));
  return g;
}

static int same_grid(const tt_grid *a, const tt_grid *b)
{
  if (!a || !b || tt_grid_width(a) != tt_grid_width(b) ||
      tt_grid_height(a) != tt_grid_height(b))
    return 0;
  size_t n = tt_grid_width(a) * tt_grid_height(a);
  return memcmp(tt_grid_heights_const(a), tt_grid_heights_const(b),
                n * sizeof(float)) == 0;
}

static float at(const tt_grid *g, size_t c, size_t r)
{
  return tt_grid_heights_const(g)[r * tt_grid_width(g) + c];
}

static void test_names(tt_context *ctx)
{
  const tt_synth_kind kinds[] = {TT_SYNTH_FAULT, TT_SYNTH_DIAMOND_SQUARE,
                                 TT_SYNTH_SPHERE, TT_SYNTH_CYLINDER,
                                 TT_SYNTH_BUMP};
  for (size_t i = 0; i < sizeof kinds / sizeof kinds[0]; i++) {
    tt_synth_kind k = TT_SYNTH_BUMP;
    const char *name = tt_synth_kind_name(kinds[i]);
    CHECK(name != NULL);
    CHECK_OK(ctx, tt_synth_kind_parse(ctx, name, &k));
    CHECK_INT_EQ(k, kinds[i]);
  }
  CHECK_STR_EQ(tt_synth_kind_name(TT_SYNTH_DIAMOND_SQUARE), "diamond_square");
  CHECK(tt_synth_kind_name((tt_synth_kind)99) == NULL);
  tt_synth_kind k = TT_SYNTH_FAULT;
  CHECK_OK(ctx, tt_synth_kind_parse(ctx, "Diamond-Square", &k));
  CHECK_INT_EQ(k, TT_SYNTH_DIAMOND_SQUARE);
  CHECK_INT_EQ(tt_synth_kind_parse(ctx, "volcano", &k), TT_ERR_ARG);
  CHECK(strstr(tt_context_errmsg(ctx), "volcano") != NULL);
  CHECK_INT_EQ(tt_synth_kind_parse(ctx, NULL, &k), TT_ERR_ARG);
}

static void test_defaults(tt_context *ctx)
{
  static const struct {
    tt_synth_kind kind;
    size_t nx, ny;
  } want[] = {{TT_SYNTH_FAULT, 100, 100},
              {TT_SYNTH_DIAMOND_SQUARE, 257, 257},
              {TT_SYNTH_SPHERE, 41, 41},
              {TT_SYNTH_CYLINDER, 41, 41},
              {TT_SYNTH_BUMP, 20, 30}};
  for (size_t i = 0; i < sizeof want / sizeof want[0]; i++) {
    tt_synth_options opt;
    tt_synth_options_init(&opt, want[i].kind);
    CHECK_INT_EQ(opt.kind, want[i].kind);
    CHECK_INT_EQ(opt.nx, want[i].nx);
    CHECK_INT_EQ(opt.ny, want[i].ny);
    tt_grid *g = make(ctx, &opt);
    if (!g)
      continue;
    CHECK_INT_EQ(tt_grid_width(g), want[i].nx);
    CHECK_INT_EQ(tt_grid_height(g), want[i].ny);
    size_t valid = 0;
    CHECK_OK(ctx, tt_grid_check(ctx, g, &valid));
    CHECK_INT_EQ(valid, want[i].nx * want[i].ny);
    tt_grid_destroy(g);
  }
  tt_synth_options opt;
  tt_synth_options_init(&opt, TT_SYNTH_FAULT);
  CHECK_DBL_NEAR(opt.displacement, 100, 0);
  CHECK_DBL_NEAR(opt.wave_size, 0, 0);
  CHECK(opt.iterations > 0);
  tt_synth_options_init(&opt, TT_SYNTH_DIAMOND_SQUARE);
  CHECK_DBL_NEAR(opt.roughness, 0.7, 0);
  CHECK_INT_EQ(opt.seeding, TT_SEED_NONE);
}

/* Two runs byte-identical; a different seed differs (random kinds). */
static void test_reproducible(tt_context *ctx)
{
  const tt_synth_kind kinds[] = {TT_SYNTH_FAULT, TT_SYNTH_DIAMOND_SQUARE,
                                 TT_SYNTH_SPHERE, TT_SYNTH_CYLINDER,
                                 TT_SYNTH_BUMP};
  for (size_t i = 0; i < sizeof kinds / sizeof kinds[0]; i++) {
    for (int smooth = 0; smooth < 2; smooth++) {
      tt_synth_options opt;
      tt_synth_options_init(&opt, kinds[i]);
      opt.seed = 12345;
      if (smooth) {
        if (kinds[i] != TT_SYNTH_FAULT)
          continue;
        opt.nx = opt.ny = 80;
        opt.displacement = 20;
        opt.wave_size = 5;
      }
      tt_grid *a = make(ctx, &opt), *b = make(ctx, &opt);
      CHECK(same_grid(a, b));
      opt.seed = 12346;
      tt_grid *c = make(ctx, &opt);
      int random = kinds[i] == TT_SYNTH_FAULT ||
                   kinds[i] == TT_SYNTH_DIAMOND_SQUARE;
      CHECK_INT_EQ(same_grid(a, c), !random);
      if (a && c) {
        double ga[6], gc[6];
        tt_grid_get_geotransform(a, ga);
        tt_grid_get_geotransform(c, gc);
        CHECK(memcmp(ga, gc, sizeof ga) == 0);
      }
      tt_grid_destroy(a);
      tt_grid_destroy(b);
      tt_grid_destroy(c);
    }
  }
}

/* Map coordinate of sample (c, r) through the geotransform. */
static void map_xy(const tt_grid *g, double c, double r, double *x, double *y)
{
  double gt[6];
  tt_grid_get_geotransform(g, gt);
  *x = gt[0] + (c + 0.5) * gt[1] + (r + 0.5) * gt[2];
  *y = gt[3] + (c + 0.5) * gt[4] + (r + 0.5) * gt[5];
}

static void test_sphere_cylinder(tt_context *ctx)
{
  tt_synth_options opt;
  tt_synth_options_init(&opt, TT_SYNTH_SPHERE);
  tt_grid *g = make(ctx, &opt);
  if (g) {
    double x, y;
    map_xy(g, 0, 0, &x, &y);
    CHECK_DBL_NEAR(x, 0, 1e-12);
    CHECK_DBL_NEAR(y, 0, 1e-12);
    map_xy(g, 40, 40, &x, &y);
    CHECK_DBL_NEAR(x, 40, 1e-12);
    CHECK_DBL_NEAR(y, 40, 1e-12);
    CHECK_DBL_NEAR(at(g, 20, 20), 20, 0);   /* centre */
    CHECK_DBL_NEAR(at(g, 0, 20), 0, 0);     /* rim */
    CHECK_DBL_NEAR(at(g, 40, 20), 0, 0);
    CHECK_DBL_NEAR(at(g, 20, 0), 0, 0);
    CHECK_DBL_NEAR(at(g, 0, 0), 0, 0);      /* outside */
    /* (30, 20): 20 sqrt(1 - 1/4) */
    CHECK_DBL_NEAR(at(g, 30, 20), 20 * sqrt(0.75), 1e-5);
    CHECK_DBL_NEAR(at(g, 20, 36), 12, 1e-5); /* 20 sqrt(1 - 0.64) */
    float mx = 0;
    for (size_t i = 0; i < 41 * 41; i++)
      if (tt_grid_heights_const(g)[i] > mx)
        mx = tt_grid_heights_const(g)[i];
    CHECK_DBL_NEAR(mx, 20, 0);
    tt_grid_destroy(g);
  }
  /* Another size keeps the domain [0,40]^2. */
  opt.nx = 81;
  opt.ny = 21;
  g = make(ctx, &opt);
  if (g) {
    double x, y;
    map_xy(g, 80, 20, &x, &y);
    CHECK_DBL_NEAR(x, 40, 1e-12);
    CHECK_DBL_NEAR(y, 40, 1e-12);
    CHECK_DBL_NEAR(at(g, 40, 10), 20, 0);
    tt_grid_destroy(g);
  }

  tt_synth_options_init(&opt, TT_SYNTH_CYLINDER);
  g = make(ctx, &opt);
  if (g) {
    CHECK_DBL_NEAR(at(g, 20, 20), 60, 0);
    /* The cliff along row 20: x = 0 is on the circle (inside), then
     * outside for x < 0 is off the grid; along row 4, 12^2 + 16^2 = 400. */
    CHECK_DBL_NEAR(at(g, 0, 20), 60, 0);
    CHECK_DBL_NEAR(at(g, 8, 4), 60, 0);
    CHECK_DBL_NEAR(at(g, 7, 4), 0, 0);
    CHECK_DBL_NEAR(at(g, 32, 4), 60, 0);
    CHECK_DBL_NEAR(at(g, 33, 4), 0, 0);
    CHECK_DBL_NEAR(at(g, 0, 0), 0, 0);
    CHECK_DBL_NEAR(at(g, 40, 40), 0, 0);
    size_t inside = 0;
    for (size_t r = 0; r < 41; r++)
      for (size_t c = 0; c < 41; c++) {
        double u = (double)c - 20, t = (double)r - 20;
        float v = at(g, c, r);
        CHECK(v == 0 || v == 60);
        CHECK_INT_EQ(v == 60, u * u + t * t <= 400);
        inside += v == 60;
      }
    CHECK(inside > 1200 && inside < 1300); /* about pi 20^2 = 1257 */
    tt_grid_destroy(g);
  }
}

static void test_bump(tt_context *ctx)
{
  tt_synth_options opt;
  tt_synth_options_init(&opt, TT_SYNTH_BUMP);
  tt_grid *g = make(ctx, &opt);
  if (!g)
    return;
  double x, y;
  map_xy(g, 19, 29, &x, &y);
  CHECK_DBL_NEAR(x, 1, 1e-12);
  CHECK_DBL_NEAR(y, 1, 1e-12);
  /* The samples nearest (0.5, 0.5): columns 9, 10 (x = 9/19, 10/19), rows
   * 14, 15 (y = 14/29, 15/29); all four are equally far, by symmetry. */
  double dx = 0.5 / 19, dy = 0.5 / 29;
  double peak = exp(-81.0 / 4.0 * (dx * dx + dy * dy));
  float mx = -1;
  size_t mc = 0, mr = 0;
  for (size_t r = 0; r < 30; r++)
    for (size_t c = 0; c < 20; c++)
      if (at(g, c, r) > mx) {
        mx = at(g, c, r);
        mc = c;
        mr = r;
      }
  CHECK_DBL_NEAR(mx, peak, 1e-7);
  CHECK_INT_EQ(mc, 9);
  CHECK_INT_EQ(mr, 14);
  CHECK_DBL_NEAR(at(g, 10, 15), peak, 1e-7);
  CHECK_DBL_NEAR(at(g, 0, 0), exp(-81.0 / 8.0), 1e-9);
  CHECK_DBL_NEAR(at(g, 19, 0), at(g, 0, 29), 0);
  tt_grid_destroy(g);
}

/* Rough faults: every sample is displacement * (raises - lowerings) with
 * raises + lowerings = iterations; smooth faults stay within the bounds. */
static void test_fault(tt_context *ctx)
{
  tt_synth_options opt;
  tt_synth_options_init(&opt, TT_SYNTH_FAULT);
  opt.seed = 7;
  tt_grid *g = make(ctx, &opt);
  if (g) {
    const float *z = tt_grid_heights_const(g);
    size_t n = opt.nx * opt.ny;
    long long lo = 0, hi = 0;
    double mean = 0;
    int bad = 0;
    for (size_t i = 0; i < n; i++) {
      double k = z[i] / opt.displacement;
      long long ki = (long long)llround(k);
      if (k != (double)ki || llabs(ki) > (long long)opt.iterations ||
          (ki - (long long)opt.iterations) % 2 != 0)
        bad++;
      if (ki < lo)
        lo = ki;
      if (ki > hi)
        hi = ki;
      mean += z[i];
    }
    CHECK_INT_EQ(bad, 0);
    CHECK(hi - lo >= 20);       /* a real relief, not a plane */
    mean /= (double)n;
    /* Offsets are centred: the mean stays well inside the range. */
    CHECK_DBL_LE(fabs(mean), 0.5 * (double)opt.iterations * opt.displacement);
    double gt[6];
    tt_grid_get_geotransform(g, gt);
    CHECK_DBL_NEAR(gt[0], -0.5, 0);
    CHECK_DBL_NEAR(gt[1], 1, 0);
    CHECK_DBL_NEAR(gt[3], -0.5, 0);
    CHECK_DBL_NEAR(gt[5], 1, 0);
    tt_grid_destroy(g);
  }

  /* One line splits the grid into exactly +d and -d. */
  opt.iterations = 1;
  g = make(ctx, &opt);
  if (g) {
    size_t up = 0, down = 0;
    for (size_t i = 0; i < opt.nx * opt.ny; i++) {
      float v = tt_grid_heights_const(g)[i];
      up += v == 100;
      down += v == -100;
    }
    CHECK_INT_EQ(up + down, opt.nx * opt.ny);
    tt_grid_destroy(g);
  }
  /* No line: flat. */
  opt.iterations = 0;
  g = make(ctx, &opt);
  if (g) {
    for (size_t i = 0; i < opt.nx * opt.ny; i++)
      CHECK(tt_grid_heights_const(g)[i] == 0);
    tt_grid_destroy(g);
  }

  /* Smooth (the study's smooth terrain): bounded by iterations * d, not
   * all multiples of d, and the cosine ramp keeps neighbours close: a
   * step of one cell changes each line's term by at most d pi / (2 w). */
  tt_synth_options_init(&opt, TT_SYNTH_FAULT);
  opt.nx = opt.ny = 80;
  opt.displacement = 20;
  opt.wave_size = 5;
  opt.iterations = 50;
  g = make(ctx, &opt);
  if (g) {
    const float *z = tt_grid_heights_const(g);
    int off_grid = 0;
    double maxstep = 0;
    for (size_t r = 0; r < 80; r++)
      for (size_t c = 0; c < 80; c++) {
        double v = z[r * 80 + c];
        CHECK_DBL_LE(fabs(v), 50 * 20.0);
        if (fmod(v, 20.0) != 0)
          off_grid++;
        if (c + 1 < 80 && fabs(z[r * 80 + c + 1] - v) > maxstep)
          maxstep = fabs(z[r * 80 + c + 1] - v);
      }
    CHECK(off_grid > 0);
    CHECK_DBL_LE(maxstep, 50 * 20.0 * 3.14159265358979 / 10.0 + 1e-3);
    tt_grid_destroy(g);
  }
}

static void test_diamond_square(tt_context *ctx)
{
  tt_synth_options opt;
  tt_synth_options_init(&opt, TT_SYNTH_DIAMOND_SQUARE);
  tt_grid *g = NULL;

  /* Sizes: 2^n+1 square only. */
  const size_t bad_sizes[][2] = {{256, 256}, {258, 258}, {257, 129},
                                 {2, 2}, {100, 100}, {6, 6}};
  for (size_t i = 0; i < sizeof bad_sizes / sizeof bad_sizes[0]; i++) {
    opt.nx = bad_sizes[i][0];
    opt.ny = bad_sizes[i][1];
    CHECK_INT_EQ(tt_synth_generate(ctx, &opt, &g), TT_ERR_ARG);
    CHECK(g == NULL);
    CHECK(strstr(tt_context_errmsg(ctx), "2^n+1") != NULL);
  }
  const size_t good[] = {3, 5, 9, 17, 33, 65, 129};
  for (size_t i = 0; i < sizeof good / sizeof good[0]; i++) {
    opt.nx = opt.ny = good[i];
    g = make(ctx, &opt);
    if (g) {
      size_t valid = 0;
      CHECK_OK(ctx, tt_grid_check(ctx, g, &valid));
      CHECK_INT_EQ(valid, good[i] * good[i]);
      tt_grid_destroy(g);
    }
  }

  /* Bounds: |z| <= A sum r^i without seeding, and a real relief. */
  tt_synth_options_init(&opt, TT_SYNTH_DIAMOND_SQUARE);
  g = make(ctx, &opt);
  if (g) {
    double bound = 0, p = 1;
    for (int i = 0; i <= 8; i++, p *= 0.7)
      bound += opt.amplitude * p;
    double lo = 1e30, hi = -1e30;
    for (size_t i = 0; i < 257 * 257; i++) {
      double v = tt_grid_heights_const(g)[i];
      CHECK_DBL_LE(fabs(v), bound * (1 + 1e-6));
      lo = v < lo ? v : lo;
      hi = v > hi ? v : hi;
    }
    CHECK(hi - lo > 0.5 * opt.amplitude);
    tt_grid_destroy(g);
  }

  /* Seeding: the seeds keep their value (2 A sum r^i) and are the
   * extremes. */
  const tt_synth_seeding seedings[] = {TT_SEED_PEAK, TT_SEED_VALLEY,
                                       TT_SEED_HYBRID};
  for (size_t s = 0; s < 3; s++) {
    for (uint64_t seed = 1; seed <= 5; seed++) {
      tt_synth_options_init(&opt, TT_SYNTH_DIAMOND_SQUARE);
      opt.nx = opt.ny = 129;
      opt.seed = seed;
      opt.seeding = seedings[s];
      g = make(ctx, &opt);
      if (!g)
        continue;
      const float *z = tt_grid_heights_const(g);
      float mx = -FLT_MAX, mn = FLT_MAX;
      for (size_t i = 0; i < 129 * 129; i++) {
        mx = z[i] > mx ? z[i] : mx;
        mn = z[i] < mn ? z[i] : mn;
      }
      double h = 0, p = 1;
      for (int i = 0; i <= 7; i++, p *= opt.roughness)
        h += p;
      h *= 2 * opt.amplitude;
      if (seedings[s] == TT_SEED_PEAK) {
        CHECK_DBL_NEAR(at(g, 64, 64), h, 1e-3);
        CHECK(at(g, 64, 64) == mx);
      } else if (seedings[s] == TT_SEED_VALLEY) {
        CHECK_DBL_NEAR(at(g, 64, 64), -h, 1e-3);
        CHECK(at(g, 64, 64) == mn);
      } else {
        CHECK_DBL_NEAR(at(g, 32, 32), h, 1e-3);
        CHECK_DBL_NEAR(at(g, 96, 96), -h, 1e-3);
        CHECK(at(g, 32, 32) == mx);
        CHECK(at(g, 96, 96) == mn);
      }
      /* The peak rises above its surroundings: its 8 neighbours lower. */
      if (seedings[s] == TT_SEED_PEAK)
        for (int dr = -1; dr <= 1; dr++)
          for (int dc = -1; dc <= 1; dc++)
            if (dr || dc)
              CHECK(at(g, (size_t)(64 + dc), (size_t)(64 + dr)) < mx);
      tt_grid_destroy(g);
    }
  }
  /* The corners are drawn before any seed, so seeding leaves them alone. */
  tt_synth_options_init(&opt, TT_SYNTH_DIAMOND_SQUARE);
  opt.nx = opt.ny = 65;
  tt_grid *plain = make(ctx, &opt);
  opt.seeding = TT_SEED_PEAK;
  g = make(ctx, &opt);
  if (plain && g) {
    CHECK(at(plain, 0, 0) == at(g, 0, 0));
    CHECK(at(plain, 64, 64) == at(g, 64, 64));
    CHECK(at(plain, 32, 32) != at(g, 32, 32));
  }
  tt_grid_destroy(plain);
  tt_grid_destroy(g);
  opt.nx = opt.ny = 3;
  opt.seeding = TT_SEED_HYBRID;
  CHECK_INT_EQ(tt_synth_generate(ctx, &opt, &g), TT_ERR_ARG);
}

static void test_refusals(tt_context *ctx)
{
  tt_synth_options opt;
  tt_grid *g = NULL;

  tt_synth_options_init(&opt, TT_SYNTH_FAULT);
  CHECK_INT_EQ(tt_synth_generate(ctx, &opt, NULL), TT_ERR_ARG);
  CHECK_INT_EQ(tt_synth_generate(ctx, NULL, &g), TT_ERR_ARG);
  CHECK(g == NULL);

  /* Sizes. */
  opt.nx = 1;
  CHECK_INT_EQ(tt_synth_generate(ctx, &opt, &g), TT_ERR_ARG);
  CHECK(strstr(tt_context_errmsg(ctx), "2 x 2") != NULL);
  tt_synth_options_init(&opt, TT_SYNTH_BUMP);
  opt.ny = 0;
  CHECK_INT_EQ(tt_synth_generate(ctx, &opt, &g), TT_ERR_ARG);
  tt_synth_options_init(&opt, TT_SYNTH_SPHERE);
  opt.nx = TT_MAX_GRID_SIDE + 1;
  CHECK_INT_EQ(tt_synth_generate(ctx, &opt, &g), TT_ERR_LIMIT);

  /* Fault parameters. */
  tt_synth_options_init(&opt, TT_SYNTH_FAULT);
  opt.displacement = NAN;
  CHECK_INT_EQ(tt_synth_generate(ctx, &opt, &g), TT_ERR_ARG);
  opt.displacement = -1;
  CHECK_INT_EQ(tt_synth_generate(ctx, &opt, &g), TT_ERR_ARG);
  opt.displacement = INFINITY;
  CHECK_INT_EQ(tt_synth_generate(ctx, &opt, &g), TT_ERR_ARG);
  opt.displacement = 1e37;
  CHECK_INT_EQ(tt_synth_generate(ctx, &opt, &g), TT_ERR_LIMIT);
  tt_synth_options_init(&opt, TT_SYNTH_FAULT);
  opt.wave_size = -2;
  CHECK_INT_EQ(tt_synth_generate(ctx, &opt, &g), TT_ERR_ARG);
  opt.wave_size = NAN;
  CHECK_INT_EQ(tt_synth_generate(ctx, &opt, &g), TT_ERR_ARG);
  /* Issue 11 item 8: a finite but huge wave size made every height NaN
   * (pi (d + w) overflows) and was written with exit 0. */
  opt.wave_size = 1e308;
  CHECK_INT_EQ(tt_synth_generate(ctx, &opt, &g), TT_ERR_LIMIT);
  CHECK(g == NULL);
  CHECK(strstr(tt_context_errmsg(ctx), "wave size") != NULL);
  opt.wave_size = 1e300; /* large but fine: finite heights */
  CHECK_INT_EQ(tt_synth_generate(ctx, &opt, &g), TT_OK);
  if (g) {
    size_t bad = 0;
    for (size_t i = 0; i < opt.nx * opt.ny; i++)
      bad += !isfinite(tt_grid_heights_const(g)[i]);
    CHECK_INT_EQ(bad, 0);
  }
  tt_grid_destroy(g);
  g = NULL;
  tt_synth_options_init(&opt, TT_SYNTH_FAULT);
  opt.iterations = (size_t)-1;
  CHECK_INT_EQ(tt_synth_generate(ctx, &opt, &g), TT_ERR_LIMIT);

  /* Diamond-square parameters. */
  tt_synth_options_init(&opt, TT_SYNTH_DIAMOND_SQUARE);
  opt.roughness = 1.5;
  CHECK_INT_EQ(tt_synth_generate(ctx, &opt, &g), TT_ERR_ARG);
  opt.roughness = NAN;
  CHECK_INT_EQ(tt_synth_generate(ctx, &opt, &g), TT_ERR_ARG);
  tt_synth_options_init(&opt, TT_SYNTH_DIAMOND_SQUARE);
  opt.amplitude = -1;
  CHECK_INT_EQ(tt_synth_generate(ctx, &opt, &g), TT_ERR_ARG);
  opt.amplitude = INFINITY;
  CHECK_INT_EQ(tt_synth_generate(ctx, &opt, &g), TT_ERR_ARG);
  opt.amplitude = 1e38;
  CHECK_INT_EQ(tt_synth_generate(ctx, &opt, &g), TT_ERR_LIMIT);
  tt_synth_options_init(&opt, TT_SYNTH_DIAMOND_SQUARE);
  opt.seeding = (tt_synth_seeding)42;
  CHECK_INT_EQ(tt_synth_generate(ctx, &opt, &g), TT_ERR_ARG);

  /* Unknown kind. */
  tt_synth_options_init(&opt, TT_SYNTH_FAULT);
  opt.kind = (tt_synth_kind)17;
  CHECK_INT_EQ(tt_synth_generate(ctx, &opt, &g), TT_ERR_ARG);
  CHECK(g == NULL);
  /* Messages are one line. */
  CHECK(strchr(tt_context_errmsg(ctx), '\n') == NULL);
  CHECK(strlen(tt_context_errmsg(ctx)) > 0);

  /* A NULL context is allowed. */
  CHECK_INT_EQ(tt_synth_generate(NULL, &opt, &g), TT_ERR_ARG);
}

int main(void)
{
  tt_context *ctx = tt_context_create();
  CHECK(ctx != NULL);
  if (!ctx)
    return 1;
  TT_RUN(test_names(ctx));
  TT_RUN(test_defaults(ctx));
  TT_RUN(test_reproducible(ctx));
  TT_RUN(test_sphere_cylinder(ctx));
  TT_RUN(test_bump(ctx));
  TT_RUN(test_fault(ctx));
  TT_RUN(test_diamond_square(ctx));
  TT_RUN(test_refusals(ctx));
  tt_context_destroy(ctx);
  TT_TEST_DONE();
}
