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
 * Workload: in greedy refinement every sample is rescanned each time the
 * triangle holding it changes, O(log n) times on average; the per-row and
 * per-triangle set-up costs as much as the samples on small triangles, and
 * the rows' cache misses (one a row, on a grid larger than the caches) as
 * much as both on large grids.
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
    st->z[k] = (double)m->v[v].z;
  }
  /* Interior on the positive side of every normalised edge function; the
   * half-edge with direction (dx, dy) owns its samples iff dy > 0 or
   * (dy == 0 and dx > 0): of an edge's two half-edges exactly one passes.
   * Direction is taken in pixel space, the same for both triangles. */
  for (int k = 0; k < 3; k++) {
    int32_t e = 3 * t + k;
    if (m->twin[e] < 0) {
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
      r->noff[k][0] = _mm_set_epi32(3 * a, 2 * a, a, 0);
      r->noff[k][1] = _mm_set_epi32(7 * a, 6 * a, 5 * a, 4 * a);
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

/* Rows are 4 nx bytes apart, too far for the hardware prefetcher: ask for
 * the ends of the span PREFETCH_AHEAD rows below (spans drift slowly, so
 * the current one is a good guess; within a row the hardware follows). */
#define PREFETCH_AHEAD 6

static inline void prefetch_row(const float *zr, size_t nx, int64_t y,
                                int64_t ymax, int64_t xl, int64_t xr)
{
#if defined(__GNUC__)
  if (y + PREFETCH_AHEAD <= ymax) {
    const float *ahead = zr + (size_t)PREFETCH_AHEAD * nx;
    __builtin_prefetch(ahead + xl);
    __builtin_prefetch(ahead + xr);
  }
#else
  (void)zr, (void)nx, (void)y, (void)ymax, (void)xl, (void)xr;
#endif
}

void tt__scan_prefetch(const tt_grid *g, const tt__scan_tri *st, int64_t ylo,
                       int64_t yhi)
{
#if defined(__GNUC__)
  int64_t xmin, xmax, ymin, ymax;
  tt__scan_tri_bbox(st, &xmin, &xmax, &ymin, &ymax);
  if (ylo > ymin)
    ymin = ylo;
  if (yhi < ymax)
    ymax = yhi;
  for (int64_t y = ymin; y <= ymax; y++) {
    const float *row = g->z + (size_t)y * g->nx;
    for (int64_t x = xmin; x <= xmax + 15; x += 16)
      __builtin_prefetch(row + (x < xmax ? x : xmax));
  }
#else
  (void)g, (void)st, (void)ylo, (void)yhi;
#endif
}

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

static inline __m128d load2(const float *p)
{
  return _mm_cvtps_pd(_mm_castsi128_ps(_mm_loadl_epi64((const __m128i *)p)));
}

/* Max of |z - plane| over columns [xl, xr]. Works in groups of 4; the last
 * group may run past xr (the grid is padded, grid.c) and its extra lanes
 * are masked to 0, which never wins a maximum of errors >= 0. */
static inline double row_max(const kern *kn, const float *zr, int64_t xl,
                             int64_t xr, double rowbase, double gx, int64_t x0)
{
  (void)gx;
  const __m128d vbase = _mm_set1_pd(rowbase);
  __m128d m0 = _mm_setzero_pd(), m1 = _mm_setzero_pd();
  __m128d k0 = _mm_set_pd((double)(xl - x0 + 1), (double)(xl - x0));
  __m128d k1 = _mm_add_pd(k0, kn->two);
  int64_t x = xl;
  for (; x + 3 <= xr; x += 4) {
    __m128d v0 = _mm_add_pd(vbase, _mm_mul_pd(kn->gx, k0));
    __m128d v1 = _mm_add_pd(vbase, _mm_mul_pd(kn->gx, k1));
    __m128d e0 = _mm_and_pd(_mm_sub_pd(load2(zr + x), v0), kn->absmask);
    __m128d e1 = _mm_and_pd(_mm_sub_pd(load2(zr + x + 2), v1), kn->absmask);
    m0 = _mm_max_pd(e0, m0); /* e > m ? e : m: a NaN e keeps m */
    m1 = _mm_max_pd(e1, m1);
    k0 = _mm_add_pd(k0, kn->four);
    k1 = _mm_add_pd(k1, kn->four);
  }
  if (x <= xr) {
    /* 1 to 3 columns left: lanes with k <= xr - x0 count */
    __m128d last = _mm_set1_pd((double)(xr - x0));
    __m128d v0 = _mm_add_pd(vbase, _mm_mul_pd(kn->gx, k0));
    __m128d v1 = _mm_add_pd(vbase, _mm_mul_pd(kn->gx, k1));
    __m128d e0 = _mm_and_pd(_mm_sub_pd(load2(zr + x), v0), kn->absmask);
    __m128d e1 = _mm_and_pd(_mm_sub_pd(load2(zr + x + 2), v1), kn->absmask);
    e0 = _mm_and_pd(e0, _mm_cmple_pd(k0, last));
    e1 = _mm_and_pd(e1, _mm_cmple_pd(k1, last));
    m0 = _mm_max_pd(e0, m0);
    m1 = _mm_max_pd(e1, m1);
  }
  m0 = _mm_max_pd(m0, m1);
  m0 = _mm_max_pd(m0, _mm_unpackhi_pd(m0, m0));
  return _mm_cvtsd_f64(m0);
}

static inline void row_stats(const kern *kn, const float *zr, int64_t xl,
                             int64_t xr, double rowbase, double gx,
                             int64_t x0, row_acc *acc)
{
  const __m128d vbase = _mm_set1_pd(rowbase);
  const __m128d one = _mm_set1_pd(1.0);
  __m128d m = _mm_setzero_pd(), sa = _mm_setzero_pd(), sq = _mm_setzero_pd();
  __m128d cnt = _mm_setzero_pd();
  __m128d k = _mm_set_pd((double)(xl - x0 + 1), (double)(xl - x0));
  int64_t x = xl;
  for (; x + 1 <= xr; x += 2) {
    __m128d z = load2(zr + x);
    __m128d ok = _mm_cmpord_pd(z, z);
    __m128d v = _mm_add_pd(vbase, _mm_mul_pd(kn->gx, k));
    __m128d e = _mm_and_pd(_mm_and_pd(_mm_sub_pd(z, v), kn->absmask), ok);
    m = _mm_max_pd(e, m);
    sa = _mm_add_pd(sa, e);
    sq = _mm_add_pd(sq, _mm_mul_pd(e, e));
    cnt = _mm_add_pd(cnt, _mm_and_pd(one, ok));
    k = _mm_add_pd(k, kn->two);
  }
  m = _mm_max_pd(m, _mm_unpackhi_pd(m, m));
  sa = _mm_add_pd(sa, _mm_unpackhi_pd(sa, sa));
  sq = _mm_add_pd(sq, _mm_unpackhi_pd(sq, sq));
  cnt = _mm_add_pd(cnt, _mm_unpackhi_pd(cnt, cnt));
  double mx = _mm_cvtsd_f64(m), s1 = _mm_cvtsd_f64(sa),
         s2 = _mm_cvtsd_f64(sq);
  size_t c = (size_t)_mm_cvtsd_f64(cnt);
  for (; x <= xr; x++) {
    double zv = (double)zr[x];
    if (zv != zv)
      continue;
    double v = rowbase + gx * (double)(x - x0);
    double e = fabs(zv - v);
    mx = e > mx ? e : mx;
    s1 += e;
    s2 += e * e;
    c++;
  }
  acc->max = mx > acc->max ? mx : acc->max;
  acc->sum_abs += s1;
  acc->sum_sq += s2;
  acc->count += c;
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

static inline double row_max(const kern *kn, const float *zr, int64_t xl,
                             int64_t xr, double rowbase, double gx, int64_t x0)
{
  (void)kn;
  double m = 0;
  for (int64_t x = xl; x <= xr; x++) {
    double v = rowbase + gx * (double)(x - x0);
    double e = fabs((double)zr[x] - v);
    m = e > m ? e : m;
  }
  return m;
}

static inline void row_stats(const kern *kn, const float *zr, int64_t xl,
                             int64_t xr, double rowbase, double gx,
                             int64_t x0, row_acc *acc)
{
  (void)kn;
  for (int64_t x = xl; x <= xr; x++) {
    double zv = (double)zr[x];
    if (zv != zv)
      continue;
    double v = rowbase + gx * (double)(x - x0);
    double e = fabs(zv - v);
    acc->max = e > acc->max ? e : acc->max;
    acc->sum_abs += e;
    acc->sum_sq += e * e;
    acc->count++;
  }
}
#endif

/* The first column of row y in [xl, xr], not a vertex, whose error equals
 * target; -1 if none. */
static int64_t find_in_row(const tt_grid *g, const tt__scan_tri *st,
                           const plane *p, int64_t y, int64_t xl, int64_t xr,
                           double target)
{
  const float *zr = g->z + (size_t)y * g->nx;
  double rowbase = p->z0 + p->gy * (double)(y - p->y0);
  for (int64_t x = xl; x <= xr; x++) {
    double v = rowbase + p->gx * (double)(x - p->x0);
    if (fabs((double)zr[x] - v) == target && !is_vertex(st, x, y))
      return x;
  }
  return -1;
}

/* --- tile bounds ---------------------------------------------------------
 * The bound of raster_scan.h, tile by tile. Building: per tile a least-
 * squares plane when every sample is valid (its normal equations are
 * diagonal about the centre), else the flat plane through the middle of
 * the valid heights; the stored floats are then re-centred on the
 * residuals, and h is measured from the stored floats themselves. */

/* Stores the plane (c, bx, by) as floats about the centre (xc, yc) of the
 * tile [x0, x1) x [y0, y1) and h, the largest |z - plane| of a valid
 * sample measured from those floats (re-centred first), rounded up. */
static void tile_store(const tt_grid *g, size_t x0, size_t x1, size_t y0,
                       size_t y1, double c, double bx, double by,
                       float out[4])
{
  double xc = 0.5 * (double)(x0 + x1 - 1), yc = 0.5 * (double)(y0 + y1 - 1);
  float cf = (float)c, bxf = (float)bx, byf = (float)by;
  double rlo = INFINITY, rhi = -INFINITY;
  size_t xs = x0;
#if defined(__SSE2__)
  if (x1 - x0 == TT__TILE) {
    /* min(r, acc) keeps acc when r is NaN (nodata) */
    __m128d lo = _mm_set1_pd(INFINITY), hi = _mm_set1_pd(-INFINITY);
    __m128d vb = _mm_set1_pd((double)bxf);
    __m128d u0 = _mm_set_pd((double)(x0 + 1) - xc, (double)x0 - xc);
    __m128d step = _mm_set1_pd(2.0);
    for (size_t y = y0; y < y1; y++) {
      const float *zr = g->z + y * g->nx + x0;
      __m128d base = _mm_set1_pd((double)cf + (double)byf * ((double)y - yc));
      __m128d u = u0;
      for (int i = 0; i < TT__TILE; i += 2) {
        __m128d r = _mm_sub_pd(load2(zr + i),
                               _mm_add_pd(base, _mm_mul_pd(vb, u)));
        lo = _mm_min_pd(r, lo);
        hi = _mm_max_pd(r, hi);
        u = _mm_add_pd(u, step);
      }
    }
    double l[2], h2[2];
    _mm_storeu_pd(l, lo);
    _mm_storeu_pd(h2, hi);
    rlo = l[0] < l[1] ? l[0] : l[1];
    rhi = h2[0] > h2[1] ? h2[0] : h2[1];
    xs = x1;
  }
#endif
  for (size_t y = y0; xs < x1 && y < y1; y++) {
    const float *zr = g->z + y * g->nx;
    double base = (double)cf + (double)byf * ((double)y - yc);
    for (size_t x = xs; x < x1; x++) {
      double z = (double)zr[x];
      double r = z - (base + (double)bxf * ((double)x - xc));
      rlo = r < rlo ? r : rlo; /* NaN compares false */
      rhi = r > rhi ? r : rhi;
    }
  }
  float cm = (float)((double)cf + 0.5 * (rlo + rhi));
  double shift = (double)cm - (double)cf; /* exact: two nearby floats */
  double h = fmax(rhi - shift, shift - rlo);
  float hf = (float)h;
  if ((double)hf < h)
    hf = nextafterf(hf, INFINITY);
  out[0] = cm;
  out[1] = bxf;
  out[2] = byf;
  out[3] = hf;
}

#if defined(__SSE2__)
/* A whole tile of valid samples, the common case: the least-squares plane
 * from sums in two double lanes (about the centre the normal equations are
 * diagonal: sum u^2 = sum v^2 = 8 * 42), false when a sample is nodata. */
static bool tile_fit_full(const tt_grid *g, size_t x0, size_t y0,
                          float out[4])
{
  const __m128d u01 = _mm_set_pd(-2.5, -3.5), step = _mm_set1_pd(2.0);
  __m128d sz = _mm_setzero_pd(), suz = _mm_setzero_pd(),
          svz = _mm_setzero_pd(), bad = _mm_setzero_pd();
  for (size_t k = 0; k < TT__TILE; k++) {
    const float *zr = g->z + (y0 + k) * g->nx + x0;
    __m128d v = _mm_set1_pd((double)k - 3.5), u = u01, rz = _mm_setzero_pd();
    for (int i = 0; i < TT__TILE; i += 2) {
      __m128d z = load2(zr + i);
      bad = _mm_or_pd(bad, _mm_cmpunord_pd(z, z));
      rz = _mm_add_pd(rz, z);
      suz = _mm_add_pd(suz, _mm_mul_pd(u, z));
      u = _mm_add_pd(u, step);
    }
    sz = _mm_add_pd(sz, rz);
    svz = _mm_add_pd(svz, _mm_mul_pd(v, rz));
  }
  if (_mm_movemask_pd(bad))
    return false;
  double a[2], b[2], c[2];
  _mm_storeu_pd(a, sz);
  _mm_storeu_pd(b, suz);
  _mm_storeu_pd(c, svz);
  tile_store(g, x0, x0 + TT__TILE, y0, y0 + TT__TILE, (a[0] + a[1]) / 64.0,
             (b[0] + b[1]) / 336.0, (c[0] + c[1]) / 336.0, out);
  return true;
}
#endif

static void tile_fit(const tt_grid *g, size_t tx, size_t ty, float out[4])
{
  size_t x0 = tx << TT__TILE_SHIFT, y0 = ty << TT__TILE_SHIFT;
  size_t x1 = x0 + TT__TILE < g->nx ? x0 + TT__TILE : g->nx; /* exclusive */
  size_t y1 = y0 + TT__TILE < g->ny ? y0 + TT__TILE : g->ny;
#if defined(__SSE2__)
  if (x1 - x0 == TT__TILE && y1 - y0 == TT__TILE &&
      tile_fit_full(g, x0, y0, out))
    return;
#endif
  double xc = 0.5 * (double)(x0 + x1 - 1), yc = 0.5 * (double)(y0 + y1 - 1);
  double n = 0, sz = 0, suz = 0, svz = 0, suu = 0, svv = 0;
  double zmin = INFINITY, zmax = -INFINITY;
  for (size_t y = y0; y < y1; y++) {
    const float *zr = g->z + y * g->nx;
    double v = (double)y - yc;
    for (size_t x = x0; x < x1; x++) {
      double z = (double)zr[x];
      if (z != z)
        continue;
      double u = (double)x - xc;
      n += 1;
      sz += z;
      suz += u * z;
      svz += v * z;
      suu += u * u;
      svv += v * v;
      zmin = z < zmin ? z : zmin;
      zmax = z > zmax ? z : zmax;
    }
  }
  if (n == 0) {
    out[0] = out[1] = out[2] = 0;
    out[3] = -1;
    return;
  }
  double c = 0.5 * (zmin + zmax), bx = 0, by = 0;
  if (n == (double)((x1 - x0) * (y1 - y0))) {
    c = sz / n;
    bx = suu > 0 ? suz / suu : 0;
    by = svv > 0 ? svz / svv : 0;
  }
  tile_store(g, x0, x1, y0, y1, c, bx, by, out);
}

typedef struct tiles_job {
  const tt_grid *g;
  tt__scan_tiles *out;
} tiles_job;

static void tiles_row_job(void *arg, size_t ty)
{
  tiles_job *j = arg;
  for (size_t tx = 0; tx < j->out->ntx; tx++)
    tile_fit(j->g, tx, ty, j->out->t + 4 * (ty * j->out->ntx + tx));
}

bool tt__scan_tiles_build(const tt_grid *g, tt__pool *pool,
                          tt__scan_tiles *out)
{
  out->ntx = (g->nx + TT__TILE - 1) >> TT__TILE_SHIFT;
  out->nty = (g->ny + TT__TILE - 1) >> TT__TILE_SHIFT;
  out->t = malloc(out->ntx * out->nty * 4 * sizeof(float));
  if (!out->t) {
    out->ntx = out->nty = 0;
    return false;
  }
  tiles_job j = {g, out};
  tt__pool_run(pool, out->nty, tiles_row_job, &j);
  return true;
}

void tt__scan_tiles_free(tt__scan_tiles *tiles)
{
  free(tiles->t);
  tiles->t = NULL;
  tiles->ntx = tiles->nty = 0;
}

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

/* The bound of tile (tx, ty) for plane p; < 0 for a tile without valid
 * samples. The slack (1e-9 of the magnitudes involved) covers the rounding
 * of the bound and of the kernels' plane values many times over. */
static inline double tile_bound(const tt__scan_tiles *tl, const tt_grid *g,
                                const plane *p, int64_t tx, int64_t ty)
{
  const float *t = tl->t + 4 * ((size_t)ty * tl->ntx + (size_t)tx);
  if (t[3] < 0)
    return -1;
  int64_t x0 = tx << TT__TILE_SHIFT, y0 = ty << TT__TILE_SHIFT;
  int64_t w = (int64_t)g->nx - x0, h = (int64_t)g->ny - y0;
  double hw = 0.5 * (double)((w < TT__TILE ? w : TT__TILE) - 1);
  double hh = 0.5 * (double)((h < TT__TILE ? h : TT__TILE) - 1);
  double px = p->gx * ((double)(x0 - p->x0) + hw);
  double py = p->gy * ((double)(y0 - p->y0) + hh);
  double sx = fabs(p->gx) * hw, sy = fabs(p->gy) * hh;
  double d = fabs((double)t[0] - (p->z0 + py + px)) +
             fabs((double)t[1] - p->gx) * hw +
             fabs((double)t[2] - p->gy) * hh + (double)t[3];
  return d + 1e-9 * (fabs(p->z0) + fabs(px) + fabs(py) + sx + sy +
                     fabs((double)t[0]) + fabs((double)t[1]) * hw +
                     fabs((double)t[2]) * hh + d);
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

static int64_t best_index(const tt_grid *g, const tt__scan_tri *st,
                          const plane *p, best_t *b)
{
  if (b->index < 0 && b->y >= 0) {
    int64_t x = find_in_row(g, st, p, b->y, b->xl, b->xr, b->err);
    if (x >= 0)
      b->index = (int64_t)((size_t)b->y * g->nx) + x;
  }
  return b->index;
}

/* A row kernel: the largest error in columns [xl, xr] (row_max, or its
 * wide twin below). */
typedef double (*row_max_fn)(const kern *kn, const float *zr, int64_t xl,
                             int64_t xr, double rowbase, double gx,
                             int64_t x0);

/* The largest error in columns [xl, xr] of row y, vertex columns cut out. */
static inline __attribute__((always_inline)) double
segment_max(const tt_grid *g, const tt__scan_tri *st, const plane *p,
            const kern *kn, int64_t y, int64_t xl, int64_t xr,
            row_max_fn kernel)
{
  const float *zr = g->z + (size_t)y * g->nx;
  double rowbase = p->z0 + p->gy * (double)(y - p->y0);
  if (!vertex_row(st, y))
    return kernel(kn, zr, xl, xr, rowbase, p->gx, p->x0);
  int64_t sp[8];
  int n = split_span(st, y, xl, xr, sp);
  double m = 0;
  for (int i = 0; i < n; i++) {
    double mi = kernel(kn, zr, sp[2 * i], sp[2 * i + 1], rowbase, p->gx,
                       p->x0);
    m = mi > m ? mi : m;
  }
  return m;
}

/* Scans columns [xl, xr] of row y into b (vertex columns cut out). */
static inline void scan_segment(const tt_grid *g, const tt__scan_tri *st,
                                const plane *p, const kern *kn, int64_t y,
                                int64_t xl, int64_t xr, best_t *b)
{
  double m = segment_max(g, st, p, kn, y, xl, xr, row_max);
  if (m > b->err) {
    best_set(b, m, y, xl, xr, -1);
  } else if (m == b->err && m > 0) {
    /* a tie in a later tile may still come earlier in row-major order */
    int64_t x = find_in_row(g, st, p, y, xl, xr, m);
    int64_t i = (int64_t)((size_t)y * g->nx) + x;
    if (x >= 0 && i < best_index(g, st, p, b))
      best_set(b, m, y, xl, xr, i);
  }
}

/* Scratch of a tiled scan: the row spans, and per tile row its first
 * tile column and where its bounds start. On the stack for triangles of
 * up to STACK_ROWS rows and STACK_TILES tiles, else allocated. */
#define STACK_ROWS 512
#define STACK_TILES 2048

/* Scans tile column tx over rows [y0, y1] (one tile row), the spans of
 * the triangle's rows starting at row ybase. */
static void scan_tile(const tt_grid *g, const tt__scan_tri *st,
                      const plane *p, const kern *kn, const int32_t *span,
                      int64_t ybase, int64_t y0, int64_t y1, int64_t tx,
                      best_t *b)
{
  int64_t x0 = tx << TT__TILE_SHIFT, x1 = x0 + TT__TILE - 1;
  for (int64_t y = y0; y <= y1; y++) {
    const int32_t *sp = span + 2 * (y - ybase);
    int64_t xl = sp[0] > x0 ? sp[0] : x0;
    int64_t xr = sp[1] < x1 ? sp[1] : x1;
    if (xl <= xr)
      scan_segment(g, st, p, kn, y, xl, xr, b);
  }
}

/* The tiled scan of rows [ylo, yhi]: first the tile of the largest bound,
 * then, in row-major order, every other tile whose bound reaches the best
 * error found so far. Skipped tiles cannot hold that error (raster_scan.h),
 * and ties are settled by sample index, so the result is the row scan's.
 * False when out of memory for the scratch (nothing scanned). */
static bool candidate_tiled(const tt_grid *g, const tt__scan_tiles *tl,
                            const tt__scan_tri *st, const plane *p,
                            const kern *kn, int64_t ylo, int64_t yhi,
                            best_t *b)
{
  rows r;
  rows_init(st, (int64_t)g->nx, ylo, &r);
  if (yhi < r.ymax)
    r.ymax = yhi;
  if (r.ymin > r.ymax)
    return true;
  int64_t nrows = r.ymax - r.ymin + 1;
  int64_t ty0 = r.ymin >> TT__TILE_SHIFT, ty1 = r.ymax >> TT__TILE_SHIFT;
  int64_t ntr = ty1 - ty0 + 1;
  int32_t span_s[2 * STACK_ROWS];
  int64_t row_s[2 * (STACK_ROWS / TT__TILE + 3)];
  double bound_s[STACK_TILES];
  int32_t *span = span_s;
  int64_t *row = row_s; /* per tile row: first tile column, first bound */
  double *bound = bound_s;
  bool ok = true;
  if (nrows > STACK_ROWS) {
    span = malloc((size_t)nrows * 2 * sizeof *span);
    row = malloc((size_t)(ntr + 1) * 2 * sizeof *row);
    if (!span || !row) {
      ok = false;
      goto done;
    }
  }
  for (int64_t y = r.ymin; y <= r.ymax; y++) {
    int64_t xl, xr;
    if (!row_span_step(&r, &xl, &xr)) {
      xl = 1;
      xr = 0;
    }
    span[2 * (y - r.ymin)] = (int32_t)xl;
    span[2 * (y - r.ymin) + 1] = (int32_t)xr;
  }
  /* the tile columns of each tile row, and how many bounds in all */
  int64_t ntiles = 0;
  for (int64_t k = 0; k < ntr; k++) {
    int64_t ya = (ty0 + k) << TT__TILE_SHIFT, yb = ya + TT__TILE - 1;
    ya = ya > r.ymin ? ya : r.ymin;
    yb = yb < r.ymax ? yb : r.ymax;
    int64_t lo = INT64_MAX, hi = INT64_MIN;
    for (int64_t y = ya; y <= yb; y++) {
      const int32_t *sp = span + 2 * (y - r.ymin);
      if (sp[0] <= sp[1]) {
        lo = sp[0] < lo ? sp[0] : lo;
        hi = sp[1] > hi ? sp[1] : hi;
      }
    }
    int64_t txl = lo == INT64_MAX ? 1 : lo >> TT__TILE_SHIFT;
    int64_t txr = lo == INT64_MAX ? 0 : hi >> TT__TILE_SHIFT;
    row[2 * k] = txl;
    row[2 * k + 1] = ntiles;
    ntiles += txr - txl + 1;
  }
  row[2 * ntr] = 0;
  row[2 * ntr + 1] = ntiles;
  if (ntiles > STACK_TILES) {
    bound = malloc((size_t)ntiles * sizeof *bound);
    if (!bound) {
      ok = false;
      goto done;
    }
  }
  double top = -1;
  int64_t top_i = -1, top_k = -1;
  for (int64_t k = 0; k < ntr; k++) {
    int64_t txl = row[2 * k];
    for (int64_t i = row[2 * k + 1]; i < row[2 * k + 3]; i++) {
      bound[i] = tile_bound(tl, g, p, txl + (i - row[2 * k + 1]), ty0 + k);
      if (bound[i] > top) {
        top = bound[i];
        top_i = i;
        top_k = k;
      }
    }
  }
  if (top < 0)
    goto done;
  for (int pass = 0; pass < 2; pass++)
    for (int64_t k = pass ? 0 : top_k; k < (pass ? ntr : top_k + 1); k++) {
      int64_t ya = (ty0 + k) << TT__TILE_SHIFT, yb = ya + TT__TILE - 1;
      ya = ya > r.ymin ? ya : r.ymin;
      yb = yb < r.ymax ? yb : r.ymax;
      int64_t i0 = row[2 * k + 1], i1 = row[2 * k + 3];
      for (int64_t i = pass ? i0 : top_i; i < (pass ? i1 : top_i + 1); i++) {
        if (pass && (i == top_i || bound[i] < b->err))
          continue;
        scan_tile(g, st, p, kn, span, r.ymin, ya, yb, row[2 * k] + (i - i0),
                  b);
      }
    }
done:
  if (span != span_s)
    free(span);
  if (row != row_s)
    free(row);
  if (bound != bound_s)
    free(bound);
  return ok;
}

/* --- the row-by-row search, in two instruction sets --------------------
 * plain_rows is written once and instantiated per kernel: with SSE2 (two
 * doubles a step) and, where the processor has AVX-512, with eight doubles
 * a step and a masked last step, so that the short rows of small triangles
 * take one step. The kernels evaluate the same expression in the same
 * double operations (no fused multiply-add: -ffp-contract=off), so both
 * find the same maximum bit for bit; a maximum does not depend on the
 * order it is taken in. */
static inline __attribute__((always_inline)) void
plain_rows(const tt_grid *g, const tt__scan_tri *st, const plane *p,
           const kern *kn, int64_t ylo, int64_t yhi, best_t *b,
           row_max_fn kernel)
{
  rows r;
  rows_init(st, (int64_t)g->nx, ylo, &r);
  if (yhi < r.ymax)
    r.ymax = yhi;
  tt__scan_prefetch(g, st, r.ymin, r.ymin + PREFETCH_AHEAD - 1);
  for (int64_t y = r.ymin; y <= r.ymax; y++) {
    int64_t xl, xr;
    if (!row_span_step(&r, &xl, &xr))
      continue;
    prefetch_row(g->z + (size_t)y * g->nx, g->nx, y, r.ymax, xl, xr);
    double m = segment_max(g, st, p, kn, y, xl, xr, kernel);
    if (m > b->err)
      best_set(b, m, y, xl, xr, -1);
  }
}

static void plain_rows_sse(const tt_grid *g, const tt__scan_tri *st,
                           const plane *p, const kern *kn, int64_t ylo,
                           int64_t yhi, best_t *b)
{
  plain_rows(g, st, p, kn, ylo, yhi, b, row_max);
}

#if defined(TT_WIDE)
#define TT_WIDE_TARGET __attribute__((target("avx512f,avx512vl")))

/* row_max with eight lanes: columns x .. x + 7 as k = x - x0 + lane (exact
 * doubles), the last step masked to the columns left. NaN errors keep the
 * running maximum (max(e, m) returns m when e is NaN), as in row_max. */
static inline __attribute__((always_inline)) TT_WIDE_TARGET double
row_max_wide(const kern *kn, const float *zr, int64_t xl, int64_t xr,
             double rowbase, double gx, int64_t x0)
{
  (void)kn;
  const __m512d vbase = _mm512_set1_pd(rowbase), vgx = _mm512_set1_pd(gx);
  const __m512d eight = _mm512_set1_pd(8.0);
  __m512d k = _mm512_add_pd(_mm512_set1_pd((double)(xl - x0)),
                            _mm512_set_pd(7, 6, 5, 4, 3, 2, 1, 0));
  __m512d m = _mm512_setzero_pd();
  int64_t x = xl;
  for (; x + 7 <= xr; x += 8) {
    __m512d z = _mm512_cvtps_pd(_mm256_loadu_ps(zr + x));
    __m512d e = _mm512_abs_pd(
        _mm512_sub_pd(z, _mm512_add_pd(vbase, _mm512_mul_pd(vgx, k))));
    m = _mm512_max_pd(e, m);
    k = _mm512_add_pd(k, eight);
  }
  if (x <= xr) {
    __mmask8 live = (__mmask8)((1u << (xr - x + 1)) - 1u);
    __m512d z = _mm512_cvtps_pd(_mm256_maskz_loadu_ps(live, zr + x));
    __m512d e = _mm512_abs_pd(
        _mm512_sub_pd(z, _mm512_add_pd(vbase, _mm512_mul_pd(vgx, k))));
    m = _mm512_mask_max_pd(m, live, e, m);
  }
  return _mm512_reduce_max_pd(m);
}

static TT_WIDE_TARGET void plain_rows_wide(const tt_grid *g,
                                           const tt__scan_tri *st,
                                           const plane *p, const kern *kn,
                                           int64_t ylo, int64_t yhi,
                                           best_t *b)
{
  plain_rows(g, st, p, kn, ylo, yhi, b, row_max_wide);
}

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
  plane p;
  kern kn;
  plane_of(st, &p);
  kern_init(&kn, p.gx);
  best_t b = {0, -1, 0, -1, -1};
  if (!(tiles && tiles->t && tt__scan_tiled(st) &&
        candidate_tiled(g, tiles, st, &p, &kn, ylo, yhi, &b))) {
#if defined(TT_WIDE)
    if (wide_ok())
      plain_rows_wide(g, st, &p, &kn, ylo, yhi, &b);
    else
#endif
      plain_rows_sse(g, st, &p, &kn, ylo, yhi, &b);
  }
  *out_err = b.err;
  *out_index = b.y >= 0 ? best_index(g, st, &p, &b) : -1;
  if (*out_index < 0)
    *out_err = 0; /* b.y >= 0 and no index cannot happen: the kernels
                     agree bit for bit */
}

void tt__scan_stats_run(const tt_grid *g, const tt__scan_tri *st,
                        tt__scan_stats *out)
{
  plane p;
  rows r;
  kern kn;
  plane_of(st, &p);
  rows_init(st, (int64_t)g->nx, INT64_MIN, &r);
  kern_init(&kn, p.gx);
  row_acc acc = {0, 0, 0, 0};
  int64_t max_y = -1, max_xl = 0, max_xr = -1;
  for (int64_t y = r.ymin; y <= r.ymax; y++) {
    int64_t xl, xr;
    if (!row_span_step(&r, &xl, &xr))
      continue;
    const float *zr = g->z + (size_t)y * g->nx;
    prefetch_row(zr, g->nx, y, r.ymax, xl, xr);
    double rowbase = p.z0 + p.gy * (double)(y - p.y0);
    double before = acc.max;
    size_t nbefore = acc.count;
    if (!vertex_row(st, y)) {
      row_stats(&kn, zr, xl, xr, rowbase, p.gx, p.x0, &acc);
    } else {
      int64_t sp[8];
      int n = split_span(st, y, xl, xr, sp);
      for (int i = 0; i < n; i++)
        row_stats(&kn, zr, sp[2 * i], sp[2 * i + 1], rowbase, p.gx, p.x0,
                  &acc);
    }
    if (acc.count > nbefore && (acc.max > before || max_y < 0)) {
      max_y = y;
      max_xl = xl;
      max_xr = xr;
    }
  }
  out->count = acc.count;
  out->max_err = acc.max;
  out->sum_abs = acc.sum_abs;
  out->sum_sq = acc.sum_sq;
  out->max_index = -1;
  if (max_y >= 0) {
    int64_t x = find_in_row(g, st, &p, max_y, max_xl, max_xr, acc.max);
    if (x >= 0)
      out->max_index = (int64_t)((size_t)max_y * g->nx) + x;
  }
}
