/*
 * synth.c -- the synthetic test terrains of SPEC section 4: fault lines,
 * diamond-square, and the sphere, cylinder and bump functions.
 *
 * Invariants. Every generator is a pure function of its options: the random
 * generators draw from a private xoshiro256** stream seeded (through
 * splitmix64) from opt->seed, held in a local struct, in a fixed loop order,
 * so two runs give byte-identical grids. The only libm calls are cos, sin,
 * sqrt and exp; sqrt is exact (IEEE) and glibc's cos/sin/exp are the same
 * on every run on one machine, so results are bit-reproducible there; a
 * different libm may differ in the last bit of those three functions (the
 * step fault and diamond-square use no transcendental per sample, only for
 * the line angles). Heights are computed in double and rounded once to
 * float per sample (diamond-square reads back the rounded floats of the
 * coarser levels, which is deterministic too).
 *
 * Geotransforms. Map x,y at a pixel centre are the function's own x,y: the
 * sphere and cylinder live on [0,40]^2 with step 40/(n-1), the bump on
 * [0,1]^2 with step 1/(n-1) (the corner samples sit on the domain corners),
 * fault and diamond-square on unit pixels (sample (c,r) at map (c,r)). The
 * origin is the pixel edge half a step before the first centre; rows go
 * towards +y, like the grid's default geotransform.
 *
 * Workload. Fault: O(iterations * samples) time, one row of doubles plus
 * 3 doubles per line of scratch. Diamond-square: O(samples), no scratch (it
 * works in the grid's floats). The functions: O(samples). Only the grid is
 * allocated beyond that.
 *
 * Part of src/tin/, the finished TIN: its records and error statistics, eval,
 * synthetic terrains.
 */
#include "base/internal.h"
#include "base/random.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Defaults (tt_synth_options_init). */
#define SYNTH_SEED 1u
#define SYNTH_FAULT_SIDE 100          /* the study's rough fault terrain */
#define SYNTH_FAULT_ITERATIONS 200    /* not given by the study: 200 lines
                                         make a varied, not yet saturated
                                         relief on 100x100 */
#define SYNTH_FAULT_DISPLACEMENT 100.0
#define SYNTH_DS_SIDE 257             /* 2^8 + 1 */
#define SYNTH_DS_ROUGHNESS 0.7        /* the study's value */
#define SYNTH_DS_AMPLITUDE 100.0
#define SYNTH_FUNC_SIDE 41            /* sphere, cylinder on [0,40]^2 */
#define SYNTH_BUMP_NX 20
#define SYNTH_BUMP_NY 30

/* Limits: more fault lines than this is a mistake, not a terrain. */
#define SYNTH_MAX_ITERATIONS ((size_t)1000000)

static const double synth_pi = 3.14159265358979323846;

/* Uniform in [-1, 1). */
static double rng_signed(tt__rng *rng)
{
  return 2.0 * tt__rng_unit(rng) - 1.0;
}

/* ---------------------------------------------------------------------------
 * Options, names.
 * ------------------------------------------------------------------------- */
void tt_synth_options_init(tt_synth_options *opt, tt_synth_kind kind)
{
  if (!opt)
    return;
  memset(opt, 0, sizeof *opt);
  opt->kind = kind;
  opt->seed = SYNTH_SEED;
  /* Every parameter gets its default whatever the kind, so switching kind
   * afterwards still leaves sensible values. The study's smooth fault
   * terrain is nx = ny = 80, displacement 20, wave_size 5. */
  opt->iterations = SYNTH_FAULT_ITERATIONS;
  opt->displacement = SYNTH_FAULT_DISPLACEMENT;
  opt->wave_size = 0.0;
  opt->roughness = SYNTH_DS_ROUGHNESS;
  opt->amplitude = SYNTH_DS_AMPLITUDE;
  opt->seeding = TT_SEED_NONE;
  switch (kind) {
  case TT_SYNTH_FAULT:
    opt->nx = opt->ny = SYNTH_FAULT_SIDE;
    break;
  case TT_SYNTH_DIAMOND_SQUARE:
    opt->nx = opt->ny = SYNTH_DS_SIDE;
    break;
  case TT_SYNTH_SPHERE:
  case TT_SYNTH_CYLINDER:
    opt->nx = opt->ny = SYNTH_FUNC_SIDE;
    break;
  case TT_SYNTH_BUMP:
    opt->nx = SYNTH_BUMP_NX;
    opt->ny = SYNTH_BUMP_NY;
    break;
  default:
    /* Unknown kind: tt_synth_generate() will refuse it. */
    break;
  }
}

static const char *const synth_kind_names[] = {
    "fault", "diamond_square", "sphere", "cylinder", "bump"};
#define SYNTH_KIND_COUNT \
  (sizeof synth_kind_names / sizeof synth_kind_names[0])

const char *tt_synth_kind_name(tt_synth_kind kind)
{
  if ((int)kind < 0 || (size_t)kind >= SYNTH_KIND_COUNT)
    return NULL;
  return synth_kind_names[kind];
}

tt_status tt_synth_kind_parse(tt_context *ctx, const char *name,
                              tt_synth_kind *out_kind)
{
  if (!name || !out_kind)
    return tt__error(ctx, TT_ERR_ARG, "synthetic terrain kind and out_kind "
                     "must not be NULL");
  for (size_t i = 0; i < SYNTH_KIND_COUNT; i++) {
    if (tt__name_equal(name, synth_kind_names[i])) {
      *out_kind = (tt_synth_kind)i;
      return TT_OK;
    }
  }
  return tt__error(ctx, TT_ERR_ARG, "unknown synthetic terrain \"%s\": "
                   "expected fault, diamond_square, sphere, cylinder or bump",
                   name);
}

/* ---------------------------------------------------------------------------
 * Validation.
 * ------------------------------------------------------------------------- */

/* Returns k when n == 2^k + 1 (k >= 1), else -1. */
static int synth_ds_levels(size_t n)
{
  if (n < 3)
    return -1;
  size_t m = n - 1;
  if ((m & (m - 1)) != 0)
    return -1;
  int k = 0;
  while (m > 1) {
    m >>= 1;
    k++;
  }
  return k;
}

/* Sum of roughness^i for i = 0..levels: the largest |height| the unseeded
 * diamond-square process can reach, per unit of amplitude. */
static double synth_ds_bound(double roughness, int levels)
{
  double sum = 0.0, p = 1.0;
  for (int i = 0; i <= levels; i++) {
    sum += p;
    p *= roughness;
  }
  return sum;
}

static tt_status synth_check(tt_context *ctx, const tt_synth_options *opt)
{
  const char *name = tt_synth_kind_name(opt->kind);
  if (!name)
    return tt__error(ctx, TT_ERR_ARG, "unknown synthetic terrain kind %d",
                     (int)opt->kind);
  if (opt->nx < 2 || opt->ny < 2)
    return tt__error(ctx, TT_ERR_ARG, "%s terrain of %zu x %zu samples: "
                     "at least 2 x 2 are needed", name, opt->nx, opt->ny);
  if (opt->nx > TT_MAX_GRID_SIDE || opt->ny > TT_MAX_GRID_SIDE)
    return tt__error(ctx, TT_ERR_LIMIT, "%s terrain of %zu x %zu samples: "
                     "a side may have at most %zu", name, opt->nx, opt->ny,
                     (size_t)TT_MAX_GRID_SIDE);

  if (opt->kind == TT_SYNTH_FAULT) {
    if (opt->iterations > SYNTH_MAX_ITERATIONS)
      return tt__error(ctx, TT_ERR_LIMIT, "fault terrain with %zu lines: "
                       "at most %zu are allowed", opt->iterations,
                       (size_t)SYNTH_MAX_ITERATIONS);
    if (!isfinite(opt->displacement) || opt->displacement < 0)
      return tt__error(ctx, TT_ERR_ARG, "fault displacement must be finite "
                       "and >= 0, got %g", opt->displacement);
    if (opt->displacement * (double)opt->iterations > 0.5 * FLT_MAX)
      return tt__error(ctx, TT_ERR_LIMIT, "fault displacement %g times %zu "
                       "lines overflows float heights", opt->displacement,
                       opt->iterations);
    if (!isfinite(opt->wave_size) || opt->wave_size < 0)
      return tt__error(ctx, TT_ERR_ARG, "fault wave size must be finite and "
                       ">= 0 (0: step faults), got %g", opt->wave_size);
    /* The ramp's phase pi (d + w) / (2 w), d up to the grid's diagonal:
     * past DBL_MAX / pi, pi (d + w) overflows and every height is NaN
     * (inf / inf); a quarter of DBL_MAX keeps a margin. */
    if (opt->wave_size > 0.25 * DBL_MAX)
      return tt__error(ctx, TT_ERR_LIMIT, "fault wave size %g is too large: "
                       "the cosine ramp overflows (at most %g)",
                       opt->wave_size, 0.25 * DBL_MAX);
  } else if (opt->kind == TT_SYNTH_DIAMOND_SQUARE) {
    int levels = synth_ds_levels(opt->nx);
    if (opt->nx != opt->ny || levels < 0)
      return tt__error(ctx, TT_ERR_ARG, "diamond-square needs a square grid "
                       "of 2^n+1 samples a side (3, 5, 9, ..., 257, ...), "
                       "got %zu x %zu", opt->nx, opt->ny);
    if (!isfinite(opt->roughness) || opt->roughness < 0 ||
        opt->roughness > 1)
      return tt__error(ctx, TT_ERR_ARG, "diamond-square roughness must be "
                       "in [0, 1], got %g", opt->roughness);
    if (!isfinite(opt->amplitude) || opt->amplitude < 0)
      return tt__error(ctx, TT_ERR_ARG, "diamond-square amplitude must be "
                       "finite and >= 0, got %g", opt->amplitude);
    if ((int)opt->seeding < 0 || opt->seeding > TT_SEED_HYBRID)
      return tt__error(ctx, TT_ERR_ARG, "unknown diamond-square seeding %d",
                       (int)opt->seeding);
    if (opt->seeding == TT_SEED_HYBRID && opt->nx < 5)
      return tt__error(ctx, TT_ERR_ARG, "hybrid seeding needs at least 5 x 5 "
                       "samples, got %zu x %zu", opt->nx, opt->ny);
    /* Seeds stand at twice the unseeded bound (see synth_diamond_square). */
    if (opt->amplitude * 2.0 * synth_ds_bound(opt->roughness, levels) >
        0.5 * FLT_MAX)
      return tt__error(ctx, TT_ERR_LIMIT, "diamond-square amplitude %g "
                       "overflows float heights", opt->amplitude);
  }
  return TT_OK;
}

/* ---------------------------------------------------------------------------
 * Fault lines.
 *
 * Line k: unit normal (cos t, sin t), t uniform in [0, 2 pi), and offset o
 * uniform in [-D/2, D/2), D = sqrt((nx-1)^2 + (ny-1)^2) the diagonal between
 * the corner samples, in a frame centred on the grid centre
 * ((nx-1)/2, (ny-1)/2). A sample at signed distance d = n.p - o from the
 * line gets +displacement where d >= 0 (the line itself is on the raised
 * side) and -displacement where d < 0. Smooth mode (wave_size w > 0) ramps
 * instead: -displacement * cos(pi (d + w) / (2 w)) for |d| < w, a cosine
 * going from -displacement at d = -w to +displacement at d = w with zero
 * slope at both ends. The random draws are, per line, the angle then the
 * offset.
 * ------------------------------------------------------------------------- */
static tt_status synth_fault(tt_context *ctx, const tt_synth_options *opt,
                             tt_grid *grid)
{
  tt_status status = TT_OK;
  const size_t nx = opt->nx, ny = opt->ny, n = opt->iterations;
  const double disp = opt->displacement, w = opt->wave_size;
  double *lines = NULL, *acc = NULL;

  /* Three doubles per line (a, b, o), at least one to keep malloc(0) out. */
  lines = malloc((n ? n : 1) * 3 * sizeof(double));
  acc = malloc(nx * sizeof(double));
  if (!lines || !acc) {
    status = tt__error(ctx, TT_ERR_NOMEM, "out of memory for %zu fault "
                       "lines", n);
    goto done;
  }

  tt__rng rng;
  tt__rng_seed(&rng, opt->seed);
  const double cx = 0.5 * (double)(nx - 1), cy = 0.5 * (double)(ny - 1);
  const double diag = sqrt(4.0 * cx * cx + 4.0 * cy * cy);
  for (size_t k = 0; k < n; k++) {
    double t = 2.0 * synth_pi * tt__rng_unit(&rng);
    double o = (tt__rng_unit(&rng) - 0.5) * diag;
    lines[3 * k + 0] = cos(t);
    lines[3 * k + 1] = sin(t);
    lines[3 * k + 2] = o;
  }

  float *z = grid->z;
  for (size_t r = 0; r < ny; r++) {
    const double py = (double)r - cy;
    for (size_t c = 0; c < nx; c++)
      acc[c] = 0.0;
    /* Lines outer, columns inner: each sample still sums its lines in the
     * order k = 0..n-1, so the result does not depend on this choice. */
    for (size_t k = 0; k < n; k++) {
      const double a = lines[3 * k], base = lines[3 * k + 1] * py -
                                            lines[3 * k + 2];
      if (w > 0) {
        for (size_t c = 0; c < nx; c++) {
          double d = a * ((double)c - cx) + base;
          if (d >= w)
            acc[c] += disp;
          else if (d <= -w)
            acc[c] -= disp;
          else
            acc[c] -= disp * cos(synth_pi * (d + w) / (2.0 * w));
        }
      } else {
        for (size_t c = 0; c < nx; c++) {
          double d = a * ((double)c - cx) + base;
          acc[c] += d >= 0 ? disp : -disp;
        }
      }
    }
    for (size_t c = 0; c < nx; c++)
      z[r * nx + c] = (float)acc[c];
  }

done:
  free(lines);
  free(acc);
  return status;
}

/* ---------------------------------------------------------------------------
 * Diamond-square on an n x n grid, n = 2^k + 1, without wrap-around.
 *
 * Level 0: the four corners, uniform in [-A, A] (A = amplitude). Level
 * i = 1..k (half step h = (n-1)/2^i): the diamond step sets each square's
 * centre to the mean of its 4 corners, the square step each edge midpoint
 * to the mean of its 3 or 4 in-grid neighbours (3 on the border), each plus
 * a uniform term in [-A r^i, A r^i) (r = roughness). Draws go in row-major
 * order within each step. Every sample is set exactly once, by the level
 * that creates it, so no later pass rewrites an earlier value.
 *
 * Seeding: seeds are set at creation instead of the random value (whose
 * draw is still made, so the random stream, and so the rest of the relief,
 * is the same as unseeded). Peak: the centre, made by the level-1 diamond
 * step, at +H; valley: the centre at -H; hybrid: a peak at the centre of the
 * upper-left quadrant and a valley at the centre of the lower-right one,
 * made by the level-2 diamond step. H = 2 A sum_{i=0..k} r^i, twice the
 * largest height the unseeded process can reach. Averaging near a seed can
 * still overshoot it by the fine-level noise, so with seeding every other
 * sample is clamped to [-H, H] (only to the sides that are seeded): a peak
 * is always the maximum, a valley always the minimum (possibly tied).
 * ------------------------------------------------------------------------- */
typedef struct synth_ds {
  float *z;
  size_t n;
  tt__rng rng;
  size_t peak, valley;   /* sample indices of the seeds, SIZE_MAX: none */
  double hi, lo;         /* clamp range of unseeded samples */
  double seed_height;
} synth_ds;

/* Sets sample i to value (or to its seed), drawing no random number. */
static void synth_ds_set(synth_ds *ds, size_t i, double value)
{
  if (i == ds->peak)
    value = ds->seed_height;
  else if (i == ds->valley)
    value = -ds->seed_height;
  else if (value > ds->hi)
    value = ds->hi;
  else if (value < ds->lo)
    value = ds->lo;
  ds->z[i] = (float)value;
}

static void synth_diamond_square(const tt_synth_options *opt, tt_grid *grid)
{
  synth_ds ds;
  const size_t n = opt->nx;
  const int levels = synth_ds_levels(n);
  const double amp = opt->amplitude, rough = opt->roughness;
  ds.z = grid->z;
  ds.n = n;
  tt__rng_seed(&ds.rng, opt->seed);
  ds.peak = ds.valley = SIZE_MAX;
  ds.hi = INFINITY;
  ds.lo = -INFINITY;
  ds.seed_height = 2.0 * amp * synth_ds_bound(rough, levels);
  const size_t mid = (n - 1) / 2, quarter = (n - 1) / 4;
  switch (opt->seeding) {
  case TT_SEED_PEAK:
    ds.peak = mid * n + mid;
    break;
  case TT_SEED_VALLEY:
    ds.valley = mid * n + mid;
    break;
  case TT_SEED_HYBRID:
    ds.peak = quarter * n + quarter;
    ds.valley = (3 * quarter) * n + 3 * quarter;
    break;
  default:
    break;
  }
  if (ds.peak != SIZE_MAX)
    ds.hi = ds.seed_height;
  if (ds.valley != SIZE_MAX)
    ds.lo = -ds.seed_height;

  float *z = ds.z;
  const size_t last = n - 1;
  const size_t corners[4] = {0, last, last * n, last * n + last};
  for (int i = 0; i < 4; i++)
    synth_ds_set(&ds, corners[i], amp * rng_signed(&ds.rng));

  double scale = amp;
  for (size_t h = (n - 1) / 2; h >= 1; h /= 2) {
    scale *= rough;
    /* Diamond step: centres of the squares of side 2h. */
    for (size_t y = h; y < n; y += 2 * h) {
      for (size_t x = h; x < n; x += 2 * h) {
        double mean = 0.25 * ((double)z[(y - h) * n + x - h] +
                              (double)z[(y - h) * n + x + h] +
                              (double)z[(y + h) * n + x - h] +
                              (double)z[(y + h) * n + x + h]);
        double noise = scale * rng_signed(&ds.rng);
        synth_ds_set(&ds, y * n + x, mean + noise);
      }
    }
    /* Square step: midpoints of the edges, rows alternating their start. */
    for (size_t y = 0; y < n; y += h) {
      for (size_t x = ((y / h) % 2 == 0) ? h : 0; x < n; x += 2 * h) {
        double sum = 0.0;
        int count = 0;
        if (x >= h) {
          sum += z[y * n + x - h];
          count++;
        }
        if (x + h < n) {
          sum += z[y * n + x + h];
          count++;
        }
        if (y >= h) {
          sum += z[(y - h) * n + x];
          count++;
        }
        if (y + h < n) {
          sum += z[(y + h) * n + x];
          count++;
        }
        double noise = scale * rng_signed(&ds.rng);
        synth_ds_set(&ds, y * n + x, sum / count + noise);
      }
    }
  }
}

/* ---------------------------------------------------------------------------
 * The functions. Sample (c, r) stands at x = c * sx, y = r * sy.
 * ------------------------------------------------------------------------- */
static void synth_function(const tt_synth_options *opt, double sx, double sy,
                           tt_grid *grid)
{
  const size_t nx = opt->nx, ny = opt->ny;
  for (size_t r = 0; r < ny; r++) {
    const double y = (double)r * sy;
    for (size_t c = 0; c < nx; c++) {
      const double x = (double)c * sx;
      double v = 0.0;
      if (opt->kind == TT_SYNTH_SPHERE) {
        double u = x / 20.0 - 1.0, t = y / 20.0 - 1.0;
        double q = 1.0 - u * u - t * t;
        v = q > 0 ? 20.0 * sqrt(q) : 0.0;
      } else if (opt->kind == TT_SYNTH_CYLINDER) {
        /* The circle of radius 20 itself is inside (z = 60). */
        double u = x - 20.0, t = y - 20.0;
        v = u * u + t * t <= 400.0 ? 60.0 : 0.0;
      } else {
        double u = x - 0.5, t = y - 0.5;
        v = exp(-81.0 / 4.0 * (u * u + t * t));
      }
      grid->z[r * nx + c] = (float)v;
    }
  }
}

/* ---------------------------------------------------------------------------
 * Entry point.
 * ------------------------------------------------------------------------- */
tt_status tt_synth_generate(tt_context *ctx, const tt_synth_options *opt,
                            tt_grid **out_grid)
{
  tt_status status = TT_OK;
  tt_grid *grid = NULL;

  if (!out_grid)
    return tt__error(ctx, TT_ERR_ARG, "out_grid must not be NULL");
  *out_grid = NULL;
  if (!opt)
    return tt__error(ctx, TT_ERR_ARG, "synthetic terrain options must not "
                     "be NULL");
  status = synth_check(ctx, opt);
  if (status != TT_OK)
    goto done;
  status = tt_grid_create(ctx, opt->nx, opt->ny, &grid);
  if (status != TT_OK)
    goto done;

  /* Pixel steps in the function's own units. */
  double sx = 1.0, sy = 1.0;
  if (opt->kind == TT_SYNTH_SPHERE || opt->kind == TT_SYNTH_CYLINDER) {
    sx = 40.0 / (double)(opt->nx - 1);
    sy = 40.0 / (double)(opt->ny - 1);
  } else if (opt->kind == TT_SYNTH_BUMP) {
    sx = 1.0 / (double)(opt->nx - 1);
    sy = 1.0 / (double)(opt->ny - 1);
  }
  const double gt[6] = {-0.5 * sx, sx, 0.0, -0.5 * sy, 0.0, sy};
  status = tt_grid_set_geotransform(ctx, grid, gt);
  if (status != TT_OK)
    goto done;

  switch (opt->kind) {
  case TT_SYNTH_FAULT:
    status = synth_fault(ctx, opt, grid);
    break;
  case TT_SYNTH_DIAMOND_SQUARE:
    synth_diamond_square(opt, grid);
    break;
  default:
    synth_function(opt, sx, sy, grid);
    break;
  }
  if (status != TT_OK)
    goto done;
  /* The last guard: parameters that pass the checks above but still give
   * a height that is not finite are refused rather than written. */
  const float *z = tt_grid_heights_const(grid);
  for (size_t i = 0; i < opt->nx * opt->ny; i++)
    if (!isfinite(z[i])) {
      status = tt__error(ctx, TT_ERR_LIMIT, "%s terrain: the height at "
                         "column %zu, row %zu is %g; the parameters "
                         "overflow", tt_synth_kind_name(opt->kind),
                         i % opt->nx, i / opt->nx, (double)z[i]);
      goto done;
    }

  *out_grid = grid;
  grid = NULL;

done:
  tt_grid_destroy(grid);
  return status;
}
