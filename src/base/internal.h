/*
 * internal.h -- what the engine's files share and the public API hides: the
 * context and grid structures, the error helpers, hidden-visibility
 * declarations. Internal cross-file symbols are named tt__<module>_<verb>.
 *
 * Part of src/base/, the base stage: the context and its errors, grids, exact
 * predicates, the heap, threads, memory limits.
 */
#ifndef TT_INTERNAL_H
#define TT_INTERNAL_H

#include "terratin/terratin.h"

#include <stdarg.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#if defined(__GNUC__)
#define TT_HIDDEN __attribute__((visibility("hidden")))
#define TT_PRINTF(a, b) __attribute__((format(printf, a, b)))
#else
#define TT_HIDDEN
#define TT_PRINTF(a, b)
#endif

#define TT_ERRMSG_MAX 1024

struct tt_context {
  tt_status last_status;
  char errmsg[TT_ERRMSG_MAX];
  tt_log_fn log_fn;
  void *log_user;
  size_t warnings;
};

/* Samples of padding after a grid's last sample (see grid.c). */
#define TT__GRID_PAD 16

/* Exactly one of z and zd holds the heights: z for a grid of floats, zd
 * for one of doubles (tt_precision); the other is NULL. */
struct tt_grid {
  size_t nx, ny;
  float *z;          /* nx*ny, row-major, NaN = nodata */
  double *zd;        /* the same, as doubles */
  double gt[6];      /* GDAL geotransform */
  double frame[4];   /* ground frame: pixel step -> ground units */
  /* Ground points (tt_grid_alloc_ground_points), NULL when the affine frame
   * measures everything: per sample, x and y in a conformal working
   * projection (gxy, 2 doubles); the scale factor and convergence come
   * from them and the ground metric (tt_grid_ground_scale_at). */
  double *gxy;
  tt_ground_metric_fn metric_fn;  /* tt_grid_set_ground_metric_fn, or NULL */
  double metric_par[4];
  /* Where the ground metric is evaluated (tt__grid_set_ground_origin): a
   * window of a raster gives its samples' map coordinates from the
   * raster's geotransform mgt and the raster's column mc0 + c and row
   * mr0 + r, so a tile computes exactly what the whole raster does; when
   * has_morigin is false, from gt and (c, r). */
  bool has_morigin;
  size_t mc0, mr0;
  double mgt[6];
  tt_area_fn area_fn;  /* tt_grid_set_area_fn, or NULL */
  double area_par[4];
};

/* Sample i (row-major) of a grid, at its own precision. */
static inline double tt__grid_z(const tt_grid *g, size_t i)
{
  return g->zd ? g->zd[i] : (double)g->z[i];
}

/* Turns a grid of floats into one of doubles with the same values (for a
 * reader that meets a height a float cannot hold); a grid of doubles stays
 * as it is. False when out of memory (the grid is unchanged). For a
 * moment both arrays exist: 12 bytes per sample. */
TT_HIDDEN bool tt__grid_widen(tt_grid *g);

/* The Jacobian of pixel -> ground point at sample (c, r) by finite
 * differences, J = [x_c x_r; y_c y_r] as out_j[0..3] (a grid with ground
 * points, c < nx, r < ny). */
TT_HIDDEN void tt__grid_ground_jacobian(const tt_grid *g, size_t c, size_t r,
                                        double out_j[4]);

/* Makes g a window of a raster for the ground metric: its sample (c, r)
 * is the raster's (col0 + c, row0 + r), whose map coordinates come from
 * raster_gt (tt_grid_ground_scale_at then gives the whole raster's values
 * bit for bit, where the finite differences see the same neighbours). */
TT_HIDDEN void tt__grid_set_ground_origin(tt_grid *g, size_t col0,
                                          size_t row0,
                                          const double raster_gt[6]);
/* The map coordinates at which g's ground metric is evaluated for sample
 * (c, r) (the centre of the pixel, in the raster of the ground origin). */
TT_HIDDEN void tt__grid_ground_map_xy(const tt_grid *g, size_t c, size_t r,
                                      double *out_x, double *out_y);

/* Sets the context's status and message and returns the status, so a
 * failure reads `return tt__error(ctx, TT_ERR_ARG, "...", ...);`. A NULL
 * context is allowed (nothing is recorded). */
TT_HIDDEN tt_status tt__error(tt_context *ctx, tt_status status,
                              const char *fmt, ...) TT_PRINTF(3, 4);
/* Sends a warning to the context's log function and counts it. */
TT_HIDDEN void tt__warn(tt_context *ctx, const char *fmt, ...)
    TT_PRINTF(2, 3);

/* Growable arrays: grows *ptr (element size elem) to hold at least need
 * elements, by 1.5x steps; returns false when out of memory (the old array is
 * kept). */
TT_HIDDEN bool tt__grow(void **ptr, size_t *cap, size_t need, size_t elem);

/* Metric tensor of a ground frame a[4]: |A v|^2 = m11 dc^2 + 2 m12 dc dr +
 * m22 dr^2, and the exact sign of det(A) (predicates.c). The m's are
 * rounded to doubles: the Delaunay test is exact for that metric. */
typedef struct tt__metric {
  double m11, m12, m22;
  int det_sign;      /* +1 or -1 */
} tt__metric;

TT_HIDDEN void tt__metric_from_frame(const double a[4], tt__metric *out);

/* Whether two option words name the same thing: ASCII case-insensitive,
 * '-' matching '_' ("Min-Area" is "min_area"), as the command's option
 * names are matched. */
TT_HIDDEN bool tt__name_equal(const char *a, const char *b);

/* tt_memory_limit() with its inputs given (memory.c; the tests pass a
 * folder holding proc/meminfo, proc/self/cgroup and sys/fs/cgroup/... as
 * root, "" is the real system): phys_bytes of physical memory (0: unknown), an address-space
 * limit as_limit (0: none) of which as_used is mapped already. */
TT_HIDDEN size_t tt__memory_limit_at(const char *root, uint64_t phys_bytes,
                                     uint64_t as_limit, uint64_t as_used,
                                     const char **out_source);
/* "31.2 KiB", "1.5 GiB", "12 bytes": sizes for messages; returns buf. */
TT_HIDDEN const char *tt__format_bytes(char *buf, size_t size,
                                       uint64_t bytes);

/* Seconds of a monotonic clock. */
TT_HIDDEN double tt__now(void);

#endif /* TT_INTERNAL_H */
