/*
 * raster_scan.h -- walking the grid samples a triangle owns.
 *
 * Ownership partitions the samples: every valid sample in the TIN's domain
 * belongs to exactly one triangle, or is a vertex. A sample strictly inside
 * a triangle is its own; a sample on an edge belongs to the triangle whose
 * half-edge passes the "top-left" rule below (or to the only triangle, on
 * the boundary); a vertex sample belongs to no triangle here (its error is
 * zero by construction; metrics.c counts it once). Row spans are computed
 * exactly in integers, so no sample is missed or seen twice.
 *
 * The plane through the three corners is evaluated as
 * z0 + gx (x - x0) + gy (y - y0) in pixel space; every caller (candidate
 * search, statistics) uses the same expression, so they agree bit for bit.
 * This is the hot loop of refinement: keep it branch-free per sample.
 *
 * Part of src/mesh/, the mesh stage: the half-edge mesh, the samples a
 * triangle owns, the nodata domain.
 */
#ifndef TT_RASTER_SCAN_H
#define TT_RASTER_SCAN_H

#include "base/internal.h"
#include "mesh/mesh.h"
#include "base/parallel.h"

typedef struct tt__scan_tri {
  int64_t x[3], y[3];   /* pixel coordinates of the corners */
  double z[3];          /* heights at the corners */
  bool own[3];          /* samples on edge i (corner i -> i+1) are ours */
} tt__scan_tri;

/* The bounding box of the corners. */
static inline void tt__scan_tri_bbox(const tt__scan_tri *st, int64_t *x0,
                                     int64_t *x1, int64_t *y0, int64_t *y1)
{
  *x0 = *x1 = st->x[0];
  *y0 = *y1 = st->y[0];
  for (int k = 1; k < 3; k++) {
    *x0 = st->x[k] < *x0 ? st->x[k] : *x0;
    *x1 = st->x[k] > *x1 ? st->x[k] : *x1;
    *y0 = st->y[k] < *y0 ? st->y[k] : *y0;
    *y1 = st->y[k] > *y1 ? st->y[k] : *y1;
  }
}

/* The plane through the corners, as every scan evaluates it (above):
 * z0 + gx (x - x0) + gy (y - y0). */
typedef struct tt__scan_plane {
  double z0, gx, gy;
  int64_t x0, y0;
} tt__scan_plane;

static inline void tt__scan_plane_of(const tt__scan_tri *st,
                                     tt__scan_plane *p)
{
  int64_t dx1 = st->x[1] - st->x[0], dy1 = st->y[1] - st->y[0];
  int64_t dx2 = st->x[2] - st->x[0], dy2 = st->y[2] - st->y[0];
  double det = (double)(dx1 * dy2 - dx2 * dy1);
  double dz1 = st->z[1] - st->z[0], dz2 = st->z[2] - st->z[0];
  p->gx = (dz1 * (double)dy2 - dz2 * (double)dy1) / det;
  p->gy = ((double)dx1 * dz2 - (double)dx2 * dz1) / det;
  p->z0 = st->z[0];
  p->x0 = st->x[0];
  p->y0 = st->y[0];
}

/* Fills st for live triangle t of the mesh. */
TT_HIDDEN void tt__scan_tri_from_mesh(const tt__mesh *m, int32_t t,
                                      tt__scan_tri *st);

/* The owned sample with the largest |H - H'| > 0; *out_index = -1 (and
 * *out_err = 0) when every owned sample is exact or nodata. Ties go to the
 * first sample in row-major order. */
TT_HIDDEN void tt__scan_candidate(const tt_grid *g, const tt__scan_tri *st,
                                  double *out_err, int64_t *out_index);

/* Error bounds per tile of TT__TILE x TT__TILE samples (tile (i, j) holds
 * columns TT__TILE i .. TT__TILE i + TT__TILE - 1, rows likewise): a plane
 * fitted to the tile's samples, L(x, y) = c + bx (x - xc) + by (y - yc)
 * about the tile's centre (xc, yc), and h, the largest |z - L| of a valid
 * sample (h < 0: the tile has none). For any triangle's plane P, every
 * valid sample of the tile has
 *   |z - P| <= |L - P|(xc, yc) + |bx - gx| hw + |by - gy| hh + h,
 * (hw, hh the tile's half extents), since L - P is linear: so a scan for
 * the largest error may skip the tiles whose bound is below the best error
 * found so far, and still finds exactly the same sample. The floats are
 * the stored plane itself (h is measured from them, rounded up), so their
 * rounding costs tightness, never validity. Memory: 16 bytes per tile,
 * 0.25 bytes per sample (for a grid of doubles the tiles hold doubles:
 * 32 bytes per tile, 0.5 per sample). */
#define TT__TILE_SHIFT 3
#define TT__TILE (1 << TT__TILE_SHIFT)

typedef struct tt__scan_tiles {
  size_t ntx, nty;     /* tiles per row and per column */
  float *t;            /* 4 per tile, row-major: c, bx, by, h */
  double *td;          /* the same as doubles, for a grid of doubles (0.5
                          bytes per sample); the other one is NULL */
} tt__scan_tiles;

/* Builds the bounds of g into *out (its own array); false when out of
 * memory (then *out is empty). pool may be NULL. The caller frees *out with
 * tt__scan_tiles_free(). */
TT_HIDDEN bool tt__scan_tiles_build(const tt_grid *g, tt__pool *pool,
                                    tt__scan_tiles *out);
TT_HIDDEN void tt__scan_tiles_free(tt__scan_tiles *tiles);

/* Whether tt__scan_candidate_rows uses the tiles for this triangle: only
 * for triangles large enough that skipping tiles pays for their bounds. */
TT_HIDDEN bool tt__scan_tiled(const tt__scan_tri *st);

/* The same as tt__scan_candidate, restricted to rows [ylo, yhi] of the
 * triangle (for splitting a large triangle into jobs: the candidate of the
 * whole is the largest of the parts, the earliest part winning ties).
 * With tiles (may be NULL) large triangles skip the tiles that cannot hold
 * an error as large as the best found; the result is the same. */
TT_HIDDEN void tt__scan_candidate_rows(const tt_grid *g,
                                       const tt__scan_tiles *tiles,
                                       const tt__scan_tri *st, int64_t ylo,
                                       int64_t yhi, double *out_err,
                                       int64_t *out_index);

/* Lets the row search use AVX-512 where the processor has it (the
 * default) or keeps it to SSE2 (for tests: both must find the same
 * samples). Process-wide; not for use while scans run. */
TT_HIDDEN void tt__scan_allow_wide(bool allow);

/* Asks the memory system for the bounding-box rows [ylo, yhi] of the
 * triangle (all of them: ylo = INT64_MIN, yhi = INT64_MAX), so that the
 * misses of several small triangles overlap. Only a hint. */
TT_HIDDEN void tt__scan_prefetch(const tt_grid *g, const tt__scan_tri *st,
                                 int64_t ylo, int64_t yhi);

/* Heights of at most this many bytes stay in the second-level cache (2 MiB
 * a core on the machine measured, Crater Lake's 336 x 459 floats take
 * 0.6 MB): scans of such a grid ask for no rows ahead, since on a grid in
 * cache the hints are only instructions (docs/speed.md). */
#define TT__SCAN_PREFETCH_MIN_BYTES ((size_t)1 << 20)

/* Whether scans of g prefetch rows (the grid is larger than the above). */
static inline bool tt__scan_prefetches(const tt_grid *g)
{
  return g->nx * g->ny * (g->zd ? sizeof(double) : sizeof(float)) >
         TT__SCAN_PREFETCH_MIN_BYTES;
}

typedef struct tt__scan_stats {
  size_t count;         /* valid owned samples */
  double max_err;
  int64_t max_index;    /* -1 when count == 0 */
  double sum_abs;
  double sum_sq;
} tt__scan_stats;

/* Statistics of the valid owned samples (reset, then filled). */
TT_HIDDEN void tt__scan_stats_run(const tt_grid *g, const tt__scan_tri *st,
                                  tt__scan_stats *out);
/* The same over rows [ylo, yhi] of the triangle only (the bands of a
 * large triangle, refine.c); the statistics of the whole are the sums of
 * its bands' (the largest error: the first band's on ties). */
TT_HIDDEN void tt__scan_stats_rows(const tt_grid *g, const tt__scan_tri *st,
                                   int64_t ylo, int64_t yhi,
                                   tt__scan_stats *out);

#endif /* TT_RASTER_SCAN_H */
