/*
 * grid.c -- the height grid: nx*ny samples, row-major, NaN for nodata, a
 * GDAL geotransform and the ground frame (see terratin.h). The samples are
 * floats, or doubles where floats cannot hold the values exactly
 * (tt_precision; internal.h: exactly one of z and zd is set). A grid is
 * written once by its producer (reader, generator, caller) and then only
 * read: the engine never modifies heights. Memory: 4 bytes per sample, 8
 * for a grid of doubles.
 *
 * Part of src/base/, the base stage: the context and its errors, grids, exact
 * predicates, the heap, threads, memory limits.
 */
/* madvise() and MADV_HUGEPAGE are outside ISO C and POSIX. */
#define _DEFAULT_SOURCE 1

#include "base/internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#if defined(__linux__)
#include <sys/mman.h>
#endif

/* Heights of large grids sit on 2 MiB boundaries with transparent huge
 * pages requested: the raster scans walk short rows 4 * nx bytes apart, and
 * with 4 KiB pages nearly every row of a small triangle misses the TLB
 * (measured: 30% of refinement time on a 4097^2 grid). Only advice: where
 * the kernel does not give huge pages, nothing changes. */
#define HUGE_ALIGN ((size_t)2 << 20)

/* Every grid has TT__GRID_PAD samples after its last one, so that the
 * vector kernels may read a whole group past a row's end (the extra lanes
 * are masked out) even on the last row. */
static void *alloc_heights(size_t n, size_t elem)
{
  n += TT__GRID_PAD;
  size_t bytes = n * elem;
  if (bytes < 4 * HUGE_ALIGN)
    return malloc(bytes);
  void *p = NULL;
  size_t rounded = (bytes + HUGE_ALIGN - 1) / HUGE_ALIGN * HUGE_ALIGN;
  if (posix_memalign(&p, HUGE_ALIGN, rounded) != 0)
    return NULL;
#if defined(__linux__) && defined(MADV_HUGEPAGE)
  madvise(p, rounded, MADV_HUGEPAGE);
#endif
  return p;
}

static tt_status grid_create(tt_context *ctx, size_t nx, size_t ny,
                             tt_precision precision, tt_grid **out_grid)
{
  if (!out_grid)
    return tt__error(ctx, TT_ERR_ARG, "out_grid must not be NULL");
  *out_grid = NULL;
  if (nx < 2 || ny < 2)
    return tt__error(ctx, TT_ERR_DATA,
                     "grid is %zu x %zu samples: at least 2 x 2 are needed "
                     "to make a triangle", nx, ny);
  if (nx > TT_MAX_GRID_SIDE || ny > TT_MAX_GRID_SIDE)
    return tt__error(ctx, TT_ERR_LIMIT,
                     "grid is %zu x %zu samples: a side may have at most %zu",
                     nx, ny, (size_t)TT_MAX_GRID_SIDE);
  size_t elem = precision == TT_PRECISION_FLOAT64 ? sizeof(double)
                                                  : sizeof(float);
  if (nx > (SIZE_MAX / elem - TT__GRID_PAD) / ny)
    return tt__error(ctx, TT_ERR_LIMIT, "grid of %zu x %zu samples is too "
                     "large for this machine's address space", nx, ny);
  tt_grid *g = calloc(1, sizeof *g);
  if (!g)
    return tt__error(ctx, TT_ERR_NOMEM, "out of memory for a grid");
  void *z = alloc_heights(nx * ny, elem);
  if (!z) {
    free(g);
    return tt__error(ctx, TT_ERR_NOMEM,
                     "out of memory: a %zu x %zu grid of %s needs %.1f MiB",
                     nx, ny, elem == sizeof(float) ? "floats" : "doubles",
                     (double)(nx * ny * elem) / 1048576.0);
  }
  if (elem == sizeof(float)) {
    g->z = z;
    for (size_t i = 0; i < nx * ny + TT__GRID_PAD; i++)
      g->z[i] = NAN;
  } else {
    g->zd = z;
    for (size_t i = 0; i < nx * ny + TT__GRID_PAD; i++)
      g->zd[i] = NAN;
  }
  g->nx = nx;
  g->ny = ny;
  const double gt[6] = {0, 1, 0, 0, 0, 1};
  memcpy(g->gt, gt, sizeof gt);
  const double frame[4] = {1, 0, 0, 1};
  memcpy(g->frame, frame, sizeof frame);
  *out_grid = g;
  return TT_OK;
}

tt_status tt_grid_create(tt_context *ctx, size_t nx, size_t ny,
                         tt_grid **out_grid)
{
  return grid_create(ctx, nx, ny, TT_PRECISION_FLOAT32, out_grid);
}

tt_status tt_grid_create_f64(tt_context *ctx, size_t nx, size_t ny,
                             tt_grid **out_grid)
{
  return grid_create(ctx, nx, ny, TT_PRECISION_FLOAT64, out_grid);
}

tt_status tt_grid_create_from_floats(tt_context *ctx, size_t nx, size_t ny,
                                     const float *z, tt_grid **out_grid)
{
  if (!z)
    return tt__error(ctx, TT_ERR_ARG, "heights must not be NULL");
  tt_status s = tt_grid_create(ctx, nx, ny, out_grid);
  if (s != TT_OK)
    return s;
  memcpy((*out_grid)->z, z, nx * ny * sizeof(float));
  return TT_OK;
}

tt_status tt_grid_create_from_doubles(tt_context *ctx, size_t nx, size_t ny,
                                      const double *z, tt_grid **out_grid)
{
  if (!z)
    return tt__error(ctx, TT_ERR_ARG, "heights must not be NULL");
  tt_status s = tt_grid_create_f64(ctx, nx, ny, out_grid);
  if (s != TT_OK)
    return s;
  memcpy((*out_grid)->zd, z, nx * ny * sizeof(double));
  return TT_OK;
}

bool tt__grid_widen(tt_grid *g)
{
  if (g->zd)
    return true;
  size_t n = g->nx * g->ny + TT__GRID_PAD;
  double *zd = alloc_heights(g->nx * g->ny, sizeof(double));
  if (!zd)
    return false;
  for (size_t i = 0; i < n; i++)
    zd[i] = (double)g->z[i];
  free(g->z);
  g->z = NULL;
  g->zd = zd;
  return true;
}

void tt_grid_destroy(tt_grid *grid)
{
  if (!grid)
    return;
  free(grid->z);
  free(grid->zd);
  tt_grid_drop_ground_points(grid);
  free(grid);
}

size_t tt_grid_width(const tt_grid *grid) { return grid->nx; }
size_t tt_grid_height(const tt_grid *grid) { return grid->ny; }
tt_precision tt_grid_precision(const tt_grid *grid)
{
  return grid->zd ? TT_PRECISION_FLOAT64 : TT_PRECISION_FLOAT32;
}
float *tt_grid_heights(tt_grid *grid) { return grid->z; }
const float *tt_grid_heights_const(const tt_grid *grid) { return grid->z; }
double *tt_grid_heights_f64(tt_grid *grid) { return grid->zd; }
const double *tt_grid_heights_f64_const(const tt_grid *grid)
{
  return grid->zd;
}

double tt_grid_sample(const tt_grid *grid, size_t col, size_t row)
{
  return tt__grid_z(grid, row * grid->nx + col);
}

tt_status tt_grid_set_geotransform(tt_context *ctx, tt_grid *grid,
                                   const double gt[6])
{
  for (int i = 0; i < 6; i++)
    if (!isfinite(gt[i]))
      return tt__error(ctx, TT_ERR_DATA, "geotransform coefficient %d is "
                       "not finite", i);
  double det = gt[1] * gt[5] - gt[2] * gt[4];
  if (det == 0)
    return tt__error(ctx, TT_ERR_DATA, "geotransform (%g, %g, %g, %g, %g, "
                     "%g) is singular: pixels have no area", gt[0], gt[1],
                     gt[2], gt[3], gt[4], gt[5]);
  memcpy(grid->gt, gt, 6 * sizeof(double));
  grid->frame[0] = gt[1];
  grid->frame[1] = gt[2];
  grid->frame[2] = gt[4];
  grid->frame[3] = gt[5];
  return TT_OK;
}

void tt_grid_get_geotransform(const tt_grid *grid, double out_gt[6])
{
  memcpy(out_gt, grid->gt, 6 * sizeof(double));
}

tt_status tt_grid_set_ground_frame(tt_context *ctx, tt_grid *grid,
                                   const double a[4])
{
  for (int i = 0; i < 4; i++)
    if (!isfinite(a[i]))
      return tt__error(ctx, TT_ERR_ARG, "ground frame coefficient %d is not "
                       "finite", i);
  double det = a[0] * a[3] - a[1] * a[2];
  double gdet = grid->gt[1] * grid->gt[5] - grid->gt[2] * grid->gt[4];
  if (det == 0)
    return tt__error(ctx, TT_ERR_ARG, "ground frame is singular");
  if ((det < 0) != (gdet < 0))
    return tt__error(ctx, TT_ERR_ARG, "ground frame must keep the "
                     "geotransform's orientation");
  memcpy(grid->frame, a, 4 * sizeof(double));
  return TT_OK;
}

void tt_grid_get_ground_frame(const tt_grid *grid, double out_a[4])
{
  memcpy(out_a, grid->frame, 4 * sizeof(double));
}

tt_status tt_grid_alloc_ground_points(tt_context *ctx, tt_grid *grid)
{
  tt_grid_drop_ground_points(grid);
  size_t n = grid->nx * grid->ny;
  grid->gxy = malloc(2 * n * sizeof *grid->gxy);
  if (!grid->gxy)
    return tt__error(ctx, TT_ERR_NOMEM, "out of memory for the ground "
                     "points of %zu samples (16 bytes each)", n);
  return TT_OK;
}

void tt_grid_drop_ground_points(tt_grid *grid)
{
  free(grid->gxy);
  grid->gxy = NULL;
}

void tt_grid_set_ground_metric_fn(tt_grid *grid, tt_ground_metric_fn fn,
                                  const double params[4])
{
  grid->metric_fn = fn;
  for (int k = 0; k < 4; k++)
    grid->metric_par[k] = fn ? params[k] : 0;
}

/* Derivative of f (samples i*stride, i < n, n >= 2) at i in grid steps:
 * central inside, second-order one-sided at the edges. */
static double d1(const double *f, size_t i, size_t n, size_t stride)
{
  if (n == 2)
    return f[stride] - f[0];
  if (i == 0)
    return 0.5 * (-3 * f[0] + 4 * f[stride] - f[2 * stride]);
  if (i == n - 1)
    return 0.5 * (3 * f[i * stride] - 4 * f[(i - 1) * stride] +
                  f[(i - 2) * stride]);
  return 0.5 * (f[(i + 1) * stride] - f[(i - 1) * stride]);
}

void tt__grid_ground_jacobian(const tt_grid *g, size_t c, size_t r,
                              double out_j[4])
{
  size_t nx = g->nx, ny = g->ny;
  const double *rowx = g->gxy + 2 * r * nx, *colx = g->gxy + 2 * c;
  out_j[0] = d1(rowx, c, nx, 2);
  out_j[1] = d1(colx, r, ny, 2 * nx);
  out_j[2] = d1(rowx + 1, c, nx, 2);
  out_j[3] = d1(colx + 1, r, ny, 2 * nx);
}

void tt__grid_set_ground_origin(tt_grid *g, size_t col0, size_t row0,
                                const double raster_gt[6])
{
  g->has_morigin = true;
  g->mc0 = col0;
  g->mr0 = row0;
  memcpy(g->mgt, raster_gt, sizeof g->mgt);
}

void tt__grid_ground_map_xy(const tt_grid *g, size_t c, size_t r,
                            double *out_x, double *out_y)
{
  const double *gt = g->has_morigin ? g->mgt : g->gt;
  if (g->has_morigin) {
    c += g->mc0;
    r += g->mr0;
  }
  *out_x = gt[0] + (c + 0.5) * gt[1] + (r + 0.5) * gt[2];
  *out_y = gt[3] + (c + 0.5) * gt[4] + (r + 0.5) * gt[5];
}

tt_status tt_grid_ground_scale_at(const tt_grid *grid, size_t col,
                                  size_t row, double *out_k,
                                  double *out_convergence)
{
  if (!grid->gxy || col >= grid->nx || row >= grid->ny)
    return TT_ERR_ARG;
  const double *gt = grid->gt;
  double j[4];
  tt__grid_ground_jacobian(grid, col, row, j);
  double jcx = j[0], jrx = j[1], jcy = j[2], jry = j[3];
  double en[2] = {1, 1};
  if (grid->metric_fn) {
    double mx, my;
    tt__grid_ground_map_xy(grid, col, row, &mx, &my);
    grid->metric_fn(grid->metric_par, mx, my, en);
  }
  double ge = en[0], gn = en[1];
  double gdet = gt[1] * gt[5] - gt[2] * gt[4];
  double detj = jcx * jry - jrx * jcy, detg = ge * gn * gdet;
  double k = sqrt(fabs(detj / detg));
  /* true north in pixel steps: G d = (0, 1), G = [ge gt1, ge gt2;
   * gn gt4, gn gt5]; its image J d */
  double dc = -ge * gt[2] / detg, dr = ge * gt[1] / detg;
  double tx = jcx * dc + jrx * dr, ty = jcy * dc + jry * dr;
  if (!isfinite(k) || !(k > 0) || !isfinite(tx) || !isfinite(ty))
    return TT_ERR_DATA;
  *out_k = k;
  *out_convergence = atan2(tx, ty);
  return TT_OK;
}

void tt_grid_set_area_fn(tt_grid *grid, tt_area_fn fn,
                         const double params[4])
{
  grid->area_fn = fn;
  for (int k = 0; k < 4; k++)
    grid->area_par[k] = fn ? params[k] : 0;
}

double *tt_grid_ground_xy(tt_grid *grid) { return grid->gxy; }

/* The first sample of row r that is infinite or beyond TT_MAX_HEIGHT, or
 * -1; counts the row's valid samples into *valid. The row is first read
 * without branches (the count of numbers, and whether any is out of
 * range), which the compiler turns into vector code; only a row with a
 * bad sample is read again for its position. One loop per precision: the
 * float one accepts every finite float, as it always did. */
static int64_t check_row_f32(const float *z, size_t nx, size_t *valid)
{
  size_t n = 0;
  int bad = 0;
  for (size_t c = 0; c < nx; c++) {
    float v = z[c];
    n += v == v;
    bad |= fabsf(v) == INFINITY;
  }
  *valid += n;
  if (!bad)
    return -1;
  for (size_t c = 0; c < nx; c++)
    if (isinf(z[c]))
      return (int64_t)c;
  return -1;
}

static int64_t check_row_f64(const double *z, size_t nx, size_t *valid)
{
  size_t n = 0;
  int bad = 0;
  for (size_t c = 0; c < nx; c++) {
    double v = z[c];
    n += v == v;
    bad |= fabs(v) > TT_MAX_HEIGHT; /* NaN compares false */
  }
  *valid += n;
  if (!bad)
    return -1;
  for (size_t c = 0; c < nx; c++)
    if (!isnan(z[c]) && !(fabs(z[c]) <= TT_MAX_HEIGHT))
      return (int64_t)c;
  return -1;
}

tt_status tt_grid_check(tt_context *ctx, const tt_grid *grid,
                        size_t *out_valid)
{
  size_t valid = 0;
  for (size_t r = 0; r < grid->ny; r++) {
    size_t i = r * grid->nx;
    int64_t c = grid->zd ? check_row_f64(grid->zd + i, grid->nx, &valid)
                         : check_row_f32(grid->z + i, grid->nx, &valid);
    if (c < 0)
      continue;
    double v = tt__grid_z(grid, i + (size_t)c);
    if (isinf(v))
      return tt__error(ctx, TT_ERR_DATA, "height at row %zu, column %lld "
                       "is infinite", r, (long long)c);
    return tt__error(ctx, TT_ERR_DATA, "height at row %zu, column %lld is "
                     "%g, beyond the +-%g the engine measures", r,
                     (long long)c, v, TT_MAX_HEIGHT);
  }
  if (out_valid)
    *out_valid = valid;
  return TT_OK;
}
