/*
 * raster_scan.c -- the samples a triangle owns, and their errors (see
 * raster_scan.h for the ownership rule and the plane expression).
 *
 * Per row the owned span [xl, xr] comes from the three edge functions in
 * exact 64-bit integer arithmetic, stepped row to row without division
 * (triangles at most 8 columns wide test their box's columns in 32-bit
 * lanes instead); vertex samples on the row are cut out. The per-sample
 * loop is a max reduction over |z - plane|, written with SSE2 where the
 * machine has it (GCC does not vectorise a NaN-aware max by itself), with
 * AVX-512 chosen at run time for the row-by-row search, and portably
 * otherwise; NaN nodata compares false and drops out. Large triangles
 * search tile by tile, skipping the tiles whose error bound (raster_scan.h)
 * is below the best error found. Every path finds the same sample.
 * Heights: everything that reads them is in raster_scan_typed.h, included
 * below once for a grid of floats and once for a grid of doubles; the
 * public functions at the end pick the instance by the grid's type, once
 * per call (a grid of floats runs the code it always ran).
 * Workload: in greedy refinement every sample is rescanned each time the
 * triangle holding it changes, O(log n) times on average; the per-row and
 * per-triangle set-up costs as much as the samples on small triangles, and
 * the rows' cache misses (one a row, on a grid larger than the caches) as
 * much as both on large grids.
 *
 * Part of src/mesh/, the mesh stage: the half-edge mesh, the samples a
 * triangle owns, the nodata domain.
 */
#include "mesh/raster_scan.h"

#include <math.h>
#include <stdlib.h>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif
#if defined(__SSE2__) && defined(__GNUC__)
#define TT_NARROW 1 /* the lane test of narrow triangles (rows_init) */
#endif
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
#include <immintrin.h>
#define TT_WIDE 1 /* AVX-512 row search, chosen at run time */
#endif

void tt__scan_tri_from_mesh(const tt__mesh *m, int32_t t, tt__scan_tri *st)
{
  for (int k = 0; k < 3; k++) {
    int32_t e = 3 * t + k;
    int32_t v = m->hv[e];
    st->x[k] = m->v[v].c;
    st->y[k] = m->v[v].r;
    st->z[k] = tt__mesh_z(m, v);
  }
  /* Interior on the positive side of every normalised edge function; the
   * half-edge with direction (dx, dy) owns its samples iff dy > 0 or
   * (dy == 0 and dx > 0): of an edge's two half-edges exactly one passes.
   * Direction is taken in pixel space, the same for both triangles. A
   * tile's boundary edge that the neighbouring tile's TIN shares follows
   * the same rule (its twin is in the other tile). */
  for (int k = 0; k < 3; k++) {
    int32_t e = 3 * t + k;
    if (m->twin[e] < 0 && !(m->eflag[e] & TT__EDGE_BORDER_SHARED)) {
      st->own[k] = true;
      continue;
    }
    int64_t dx = st->x[(k + 1) % 3] - st->x[k];
    int64_t dy = st->y[(k + 1) % 3] - st->y[k];
    st->own[k] = dy > 0 || (dy == 0 && dx > 0);
  }
}

/* The plane of a triangle in pixel space (raster_scan.h). */
typedef tt__scan_plane plane;
#define plane_of tt__scan_plane_of

/* Row iteration: the normalised edge functions
 * E_k(x, y) = s ((x_{k+1} - x_k)(y - y_k) - (y_{k+1} - y_k)(x - x_k)),
 * s the pixel-space orientation sign, are positive inside. Written as
 * E_k = a x + b(y) with b(y + 1) = b(y) + ey, each sloped edge bounds the
 * row's span by floor or ceil of a quotient N(y) / A that changes by a
 * constant step per row: the quotient and remainder are stepped exactly in
 * integers (a DDA), so a row costs a few additions, not divisions. */
typedef struct edge_dda {
  bool own;
  int64_t q, rem, A;   /* N = q A + rem, 0 <= rem < A */
  int64_t dq, dr;      /* the per-row step of N, as dq A + dr */
} edge_dda;

typedef struct edge_flat {
  bool own;
  int64_t b, ey;       /* E = b(y), stepping by ey */
} edge_flat;

typedef struct rows {
  int64_t ymin, ymax;
  int64_t xmax;        /* grid width - 1 */
  edge_dda lo[3];      /* edges bounding x from below (a > 0) */
  edge_dda hi[3];      /* edges bounding x from above (a < 0) */
  edge_flat flat[3];   /* horizontal edges (a == 0) */
  int nlo, nhi, nflat;
#if defined(TT_NARROW)
  /* Narrow triangles (at most NARROW_W columns): no divisions, no steps
   * per edge. Each row's span comes from the three edge functions on the
   * columns bx0 .. bx0 + 7 at once, as 32-bit lanes E_k + a_k i (small:
   * |E| <= 2 W H about bx0), compared with -own_k (E > 0, or E >= 0 on an
   * owned edge). */
  bool narrow;
  int64_t bx0;
  int64_t nb[3], ney[3];   /* E_k(bx0, y) and its step per row */
  __m128i noff[3][2];      /* a_k i for lanes i = 0..3 and 4..7 */
  __m128i nthr[3];         /* -own_k in every lane */
  __m128i nlive[2];        /* lanes i < box width */
#endif
} rows;

/* The widest triangle (in columns of its bounding box) whose rows are
 * found by the lane test above. */
#define NARROW_W 8

/* Floor division with remainder in [0, d), d > 0. A double division
 * (|n| < 2^57, d < 2^29 here), truncated, is within two of the floor, and
 * the integer remainder corrects it exactly; a 64-bit integer division
 * costs several times more, six times per scanned triangle (and floor()
 * is a library call on plain x86-64). */
static inline void divmod_floor(int64_t n, int64_t d, int64_t *q, int64_t *r)
{
  int64_t qq = (int64_t)((double)n / (double)d);
  int64_t rr = n - qq * d;
  while (rr < 0) {
    rr += d;
    qq--;
  }
  while (rr >= d) {
    rr -= d;
    qq++;
  }
  *q = qq;
  *r = rr;
}

/* Prepares the walk from row `from` (clamped to the triangle's rows). */
static void rows_init(const tt__scan_tri *st, int64_t nx, int64_t from,
                      rows *r)
{
  int64_t dx1 = st->x[1] - st->x[0], dy1 = st->y[1] - st->y[0];
  int64_t dx2 = st->x[2] - st->x[0], dy2 = st->y[2] - st->y[0];
  int64_t s = (dx1 * dy2 - dx2 * dy1) > 0 ? 1 : -1;
  r->ymin = r->ymax = st->y[0];
  for (int k = 1; k < 3; k++) {
    if (st->y[k] < r->ymin)
      r->ymin = st->y[k];
    if (st->y[k] > r->ymax)
      r->ymax = st->y[k];
  }
  r->xmax = nx - 1;
#if defined(TT_NARROW)
  int64_t height = r->ymax - r->ymin; /* of the whole triangle */
#endif
  if (from > r->ymin)
    r->ymin = from;
  r->nlo = r->nhi = r->nflat = 0;
#if defined(TT_NARROW)
  int64_t bx0 = st->x[0], bx1 = st->x[0];
  for (int k = 1; k < 3; k++) {
    bx0 = st->x[k] < bx0 ? st->x[k] : bx0;
    bx1 = st->x[k] > bx1 ? st->x[k] : bx1;
  }
  r->narrow = bx1 - bx0 < NARROW_W && height < (1 << 20);
  if (r->narrow) {
    r->bx0 = bx0;
    for (int k = 0; k < 3; k++) {
      int k1 = (k + 1) % 3;
      int32_t a = (int32_t)(-s * (st->y[k1] - st->y[k]));
      r->ney[k] = s * (st->x[k1] - st->x[k]);
      r->nb[k] = r->ney[k] * (r->ymin - st->y[k]) + a * (bx0 - st->x[k]);
      /* lanes {0, a, 2a, 3a} as a in lanes 1, 3 plus 2a in lanes 2, 3,
       * and 4a more for lanes 4..7: a few vector operations where eight
       * products put into lanes one by one cost twice as many */
      __m128i va = _mm_set1_epi32(a);
      __m128i lo = _mm_add_epi32(
          _mm_and_si128(va, _mm_set_epi32(-1, 0, -1, 0)),
          _mm_and_si128(_mm_add_epi32(va, va), _mm_set_epi32(-1, -1, 0, 0)));
      r->noff[k][0] = lo;
      r->noff[k][1] = _mm_add_epi32(lo, _mm_slli_epi32(va, 2));
      r->nthr[k] = _mm_set1_epi32(st->own[k] ? -1 : 0);
    }
    int32_t w = (int32_t)(bx1 - bx0);
    r->nlive[0] = _mm_cmplt_epi32(_mm_set_epi32(3, 2, 1, 0),
                                  _mm_set1_epi32(w + 1));
    r->nlive[1] = _mm_cmplt_epi32(_mm_set_epi32(7, 6, 5, 4),
                                  _mm_set1_epi32(w + 1));
    return;
  }
#endif
  for (int k = 0; k < 3; k++) {
    int k1 = (k + 1) % 3;
    int64_t a = -s * (st->y[k1] - st->y[k]);
    int64_t ey = s * (st->x[k1] - st->x[k]);
    int64_t b = ey * (r->ymin - st->y[k]) - a * st->x[k]; /* at first row */
    if (a == 0) {
      edge_flat *f = &r->flat[r->nflat++];
      f->own = st->own[k];
      f->b = b;
      f->ey = ey;
    } else if (a > 0) {
      /* x >= -b / a: N = -b, A = a, N steps by -ey */
      edge_dda *d = &r->lo[r->nlo++];
      d->own = st->own[k];
      d->A = a;
      divmod_floor(-b, a, &d->q, &d->rem);
      divmod_floor(-ey, a, &d->dq, &d->dr);
    } else {
      /* x <= b / -a: N = b, A = -a, N steps by +ey */
      edge_dda *d = &r->hi[r->nhi++];
      d->own = st->own[k];
      d->A = -a;
      divmod_floor(b, -a, &d->q, &d->rem);
      divmod_floor(ey, -a, &d->dq, &d->dr);
    }
  }
}

/* Branch-free: whether the remainder wraps is data-dependent and would be
 * mispredicted on about every other row (measured: a third of all
 * refinement time on a 4097^2 grid). */
static inline void dda_step(edge_dda *d)
{
  int64_t rem = d->rem + d->dr;
  int64_t wrap = (int64_t)(rem >= d->A); /* 0 or 1 */
  d->rem = rem - (d->A & -wrap);
  d->q += d->dq + wrap;
}

/* The owned span of the current row, then moves every edge to the next
 * row; false when the span is empty. */
static inline bool row_span_step(rows *r, int64_t *out_xl, int64_t *out_xr)
{
#if defined(TT_NARROW)
  if (r->narrow) {
    /* |E| <= 2 W H < 2^24 fits 32 bits (W <= 8, H < 2^20) */
    __m128i in0 = r->nlive[0], in1 = r->nlive[1];
    for (int k = 0; k < 3; k++) {
      __m128i b = _mm_set1_epi32((int32_t)r->nb[k]);
      in0 = _mm_and_si128(in0, _mm_cmpgt_epi32(_mm_add_epi32(b, r->noff[k][0]),
                                               r->nthr[k]));
      in1 = _mm_and_si128(in1, _mm_cmpgt_epi32(_mm_add_epi32(b, r->noff[k][1]),
                                               r->nthr[k]));
      r->nb[k] += r->ney[k];
    }
    unsigned mask = (unsigned)_mm_movemask_ps(_mm_castsi128_ps(in0)) |
                    (unsigned)_mm_movemask_ps(_mm_castsi128_ps(in1)) << 4;
    if (!mask)
      return false;
    *out_xl = r->bx0 + __builtin_ctz(mask);
    *out_xr = r->bx0 + (31 - __builtin_clz(mask));
    return true;
  }
#endif
  int64_t xl = 0, xr = r->xmax;
  bool empty = false;
  for (int k = 0; k < r->nlo; k++) {
    edge_dda *d = &r->lo[k];
    /* owned: x >= ceil(N / A); else x >= floor(N / A) + 1 */
    int64_t lo = d->own ? d->q + (d->rem != 0) : d->q + 1;
    xl = lo > xl ? lo : xl;
    dda_step(d);
  }
  for (int k = 0; k < r->nhi; k++) {
    edge_dda *d = &r->hi[k];
    /* owned: x <= floor(N / A); else x <= ceil(N / A) - 1 */
    int64_t hi = d->own || d->rem != 0 ? d->q : d->q - 1;
    xr = hi < xr ? hi : xr;
    dda_step(d);
  }
  for (int k = 0; k < r->nflat; k++) {
    edge_flat *f = &r->flat[k];
    empty |= f->b < 0 || (f->b == 0 && !f->own);
    f->b += f->ey;
  }
  *out_xl = xl;
  *out_xr = xr;
  return !empty && xl <= xr;
}

/* Rows are 4 nx bytes apart (8 nx for doubles), too far for the hardware
 * prefetcher: ask for the ends of the span PREFETCH_AHEAD rows below
 * (spans drift slowly, so the current one is a good guess; within a row
 * the hardware follows). */
#define PREFETCH_AHEAD 6

/* Cuts the vertex columns out of [xl, xr] on row y: writes up to 4
 * sub-spans as pairs into out and returns their count. Most rows hold no
 * vertex: the caller checks vertex_row() first. */
static inline bool vertex_row(const tt__scan_tri *st, int64_t y)
{
  return y == st->y[0] || y == st->y[1] || y == st->y[2];
}

static inline bool is_vertex(const tt__scan_tri *st, int64_t x, int64_t y)
{
  return (st->x[0] == x && st->y[0] == y) || (st->x[1] == x && st->y[1] == y) ||
         (st->x[2] == x && st->y[2] == y);
}

static int split_span(const tt__scan_tri *st, int64_t y, int64_t xl,
                      int64_t xr, int64_t out[8])
{
  int64_t vx[3];
  int n = 0;
  for (int k = 0; k < 3; k++)
    if (st->y[k] == y && st->x[k] >= xl && st->x[k] <= xr)
      vx[n++] = st->x[k];
  for (int i = 1; i < n; i++)
    for (int j = i; j > 0 && vx[j - 1] > vx[j]; j--) {
      int64_t tmp = vx[j];
      vx[j] = vx[j - 1];
      vx[j - 1] = tmp;
    }
  int m = 0;
  int64_t lo = xl;
  for (int i = 0; i <= n; i++) {
    int64_t hi = i < n ? vx[i] - 1 : xr;
    if (lo <= hi) {
      out[2 * m] = lo;
      out[2 * m + 1] = hi;
      m++;
    }
    if (i < n)
      lo = vx[i] + 1;
  }
  return m;
}

/* --- per-sample kernels ------------------------------------------------
 * The plane value at column x is rowbase + gx * (double)(x - x0), the same
 * expression in every kernel (the SSE2 lanes hold x - x0 as exact doubles),
 * so a maximum found by row_max is found again by the search bit for bit.
 * NaN (nodata) gives a NaN error, which every comparison drops. */

typedef struct row_acc {
  double max, sum_abs, sum_sq;
  size_t count;
} row_acc;

#if defined(__SSE2__)
typedef struct kern {
  __m128d absmask, gx, two, four;
} kern;

static inline void kern_init(kern *k, double gx)
{
  k->absmask = _mm_castsi128_pd(_mm_set1_epi64x(INT64_MAX));
  k->gx = _mm_set1_pd(gx);
  k->two = _mm_set1_pd(2.0);
  k->four = _mm_set1_pd(4.0);
}

#else /* portable */

typedef struct kern {
  int unused;
} kern;

static inline void kern_init(kern *k, double gx)
{
  (void)gx;
  k->unused = 0;
}

#endif

/* Triangles of fewer samples than this scan every row: measured on 4097^2
 * and 1025^2 fractals, the tiles pay from about 4096 samples on (5 to 7 %
 * off a whole 4097^2 run); below, the bounds and the spans cost more than
 * the rows they skip. */
#define TILED_MIN_AREA 4096

bool tt__scan_tiled(const tt__scan_tri *st)
{
  int64_t area2 = (st->x[1] - st->x[0]) * (st->y[2] - st->y[0]) -
                  (st->x[2] - st->x[0]) * (st->y[1] - st->y[0]);
  return (area2 < 0 ? -area2 : area2) >= 2 * TILED_MIN_AREA;
}

/* The best error of a scan so far: the first sample (row-major) of the
 * largest error > 0 is in row y, columns [xl, xr]; index is its sample
 * index once known (-1 until a tie needs it). */
typedef struct best_t {
  double err;
  int64_t y, xl, xr;
  int64_t index;
} best_t;

static inline void best_set(best_t *b, double err, int64_t y, int64_t xl,
                            int64_t xr, int64_t index)
{
  b->err = err;
  b->y = y;
  b->xl = xl;
  b->xr = xr;
  b->index = index;
}

/* Scratch of a tiled scan: the row spans, and per tile row its first
 * tile column and where its bounds start. On the stack for triangles of
 * up to STACK_ROWS rows and STACK_TILES tiles, else allocated. */
#define STACK_ROWS 512
#define STACK_TILES 2048

#if defined(TT_WIDE)
#define TT_WIDE_TARGET __attribute__((target("avx512f,avx512vl")))

static bool wide_on = true;

void tt__scan_allow_wide(bool allow) { wide_on = allow; }

static inline bool wide_ok(void)
{
  return wide_on && __builtin_cpu_supports("avx512f") &&
         __builtin_cpu_supports("avx512vl");
}
#else
void tt__scan_allow_wide(bool allow) { (void)allow; }
#endif

#define TT_Z float
#define TT_Z_IS_F64 0
#define TT_ZN(name) name##_f32
#include "mesh/raster_scan_typed.h"

#define TT_Z double
#define TT_Z_IS_F64 1
#define TT_ZN(name) name##_f64
#include "mesh/raster_scan_typed.h"

/* --- the entry points: one instance or the other, by the grid's type --- */

void tt__scan_prefetch(const tt_grid *g, const tt__scan_tri *st, int64_t ylo,
                       int64_t yhi)
{
  if (g->zd)
    scan_prefetch_f64(g, st, ylo, yhi);
  else
    scan_prefetch_f32(g, st, ylo, yhi);
}

bool tt__scan_tiles_build(const tt_grid *g, tt__pool *pool,
                          tt__scan_tiles *out)
{
  out->t = NULL;
  out->td = NULL;
  return g->zd ? tiles_build_f64(g, pool, out) : tiles_build_f32(g, pool, out);
}

void tt__scan_tiles_free(tt__scan_tiles *tiles)
{
  free(tiles->t);
  free(tiles->td);
  tiles->t = NULL;
  tiles->td = NULL;
  tiles->ntx = tiles->nty = 0;
}

void tt__scan_candidate(const tt_grid *g, const tt__scan_tri *st,
                        double *out_err, int64_t *out_index)
{
  tt__scan_candidate_rows(g, NULL, st, INT64_MIN, INT64_MAX, out_err,
                          out_index);
}

void tt__scan_candidate_rows(const tt_grid *g, const tt__scan_tiles *tiles,
                             const tt__scan_tri *st, int64_t ylo,
                             int64_t yhi, double *out_err,
                             int64_t *out_index)
{
  if (g->zd)
    candidate_rows_f64(g, tiles, st, ylo, yhi, out_err, out_index);
  else
    candidate_rows_f32(g, tiles, st, ylo, yhi, out_err, out_index);
}

void tt__scan_stats_run(const tt_grid *g, const tt__scan_tri *st,
                        tt__scan_stats *out)
{
  tt__scan_stats_rows(g, st, INT64_MIN, INT64_MAX, out);
}

void tt__scan_stats_rows(const tt_grid *g, const tt__scan_tri *st,
                         int64_t ylo, int64_t yhi, tt__scan_stats *out)
{
  if (g->zd)
    stats_run_f64(g, st, ylo, yhi, out);
  else
    stats_run_f32(g, st, ylo, yhi, out);
}
