/*
 * raster_scan.c -- the samples a triangle owns, and their errors (see
 * raster_scan.h for the ownership rule and the plane expression).
 *
 * Per row the owned span [xl, xr] comes from the three edge functions in
 * exact 64-bit integer arithmetic, stepped row to row without division;
 * vertex samples on the row are cut out. The per-sample loop is a max
 * reduction over |z - plane|, written with SSE2 where the machine has it
 * (GCC does not vectorise a NaN-aware max by itself) and portably
 * otherwise; NaN nodata compares false and drops out. Workload: in
 * greedy refinement every sample is rescanned each time the triangle
 * holding it changes, O(log n) times on average.
 */
#include "raster_scan.h"

#include <math.h>

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

/* The plane of a triangle in pixel space. */
typedef struct plane {
  double z0, gx, gy;
  int64_t x0, y0;
} plane;

static void plane_of(const tt__scan_tri *st, plane *p)
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
} rows;

/* Floor division with remainder in [0, d), d > 0. A double division
 * (|n| < 2^57, d < 2^29 here) is within one of the floor, and the integer
 * remainder corrects it exactly; a 64-bit integer division costs several
 * times more, six times per scanned triangle. */
static inline void divmod_floor(int64_t n, int64_t d, int64_t *q, int64_t *r)
{
  int64_t qq = (int64_t)floor((double)n / (double)d);
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
  if (from > r->ymin)
    r->ymin = from;
  r->nlo = r->nhi = r->nflat = 0;
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
#include <emmintrin.h>

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

void tt__scan_candidate(const tt_grid *g, const tt__scan_tri *st,
                        double *out_err, int64_t *out_index)
{
  tt__scan_candidate_rows(g, st, INT64_MIN, INT64_MAX, out_err, out_index);
}

void tt__scan_candidate_rows(const tt_grid *g, const tt__scan_tri *st,
                             int64_t ylo, int64_t yhi, double *out_err,
                             int64_t *out_index)
{
  plane p;
  rows r;
  kern kn;
  plane_of(st, &p);
  rows_init(st, (int64_t)g->nx, ylo, &r);
  if (yhi < r.ymax)
    r.ymax = yhi;
  kern_init(&kn, p.gx);
  tt__scan_prefetch(g, st, r.ymin, r.ymin + PREFETCH_AHEAD - 1);
  double best = 0;
  int64_t best_y = -1, best_xl = 0, best_xr = -1;
  for (int64_t y = r.ymin; y <= r.ymax; y++) {
    int64_t xl, xr;
    if (!row_span_step(&r, &xl, &xr))
      continue;
    const float *zr = g->z + (size_t)y * g->nx;
    prefetch_row(zr, g->nx, y, r.ymax, xl, xr);
    double rowbase = p.z0 + p.gy * (double)(y - p.y0);
    double m;
    if (!vertex_row(st, y)) {
      m = row_max(&kn, zr, xl, xr, rowbase, p.gx, p.x0);
    } else {
      int64_t sp[8];
      int n = split_span(st, y, xl, xr, sp);
      m = 0;
      for (int i = 0; i < n; i++) {
        double mi = row_max(&kn, zr, sp[2 * i], sp[2 * i + 1], rowbase, p.gx,
                            p.x0);
        m = mi > m ? mi : m;
      }
    }
    if (m > best) {
      best = m;
      best_y = y;
      best_xl = xl;
      best_xr = xr;
    }
  }
  *out_err = best;
  *out_index = -1;
  if (best_y >= 0) {
    int64_t x = find_in_row(g, st, &p, best_y, best_xl, best_xr, best);
    if (x >= 0)
      *out_index = (int64_t)((size_t)best_y * g->nx) + x;
    else
      *out_err = 0; /* cannot happen: the kernels agree bit for bit */
  }
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
