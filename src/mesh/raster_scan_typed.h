/*
 * raster_scan_typed.h -- the part of raster_scan.c that reads heights,
 * written once and instantiated per height type: raster_scan.c includes
 * it twice, with TT_Z float (a grid of floats) and with TT_Z double (a
 * grid of doubles), each time with its own suffix on every name. Not a
 * header of its own: no include guard, nothing to include elsewhere.
 *
 * Both instances compute in the same doubles: they differ only in how a
 * sample is loaded (a float widened, or a double as it is), so a grid of
 * floats and a grid of doubles holding the same values give the same
 * candidates and statistics bit for bit. The tile bounds are stored in
 * the grid's type: floats about the heights of a grid of floats (0.25
 * bytes per sample, as raster_scan.h says), doubles for a grid of doubles
 * (0.5 bytes per sample), whose heights (2^30 + small integers, 10^6 +
 * thousandths) a float plane would round by more than the errors sought.
 *
 * The includer defines:
 *   TT_Z          the sample type, float or double
 *   TT_Z_IS_F64   0 or 1, for the loads
 *   TT_ZN(name)   name with the instance's suffix
 * and this file defines and undefines in turn:
 *   TT_ZARR(g)    the grid's array of TT_Z, TT_ZTILES(t) the tiles' array,
 *   TT_ZLINE      samples per 64-byte line, TT_ZNEXTUP(x) the next TT_Z up.
 *
 * Part of src/mesh/, the mesh stage: the half-edge mesh, the samples a
 * triangle owns, the nodata domain.
 */
#if TT_Z_IS_F64
#define TT_ZARR(g) ((g)->zd)
#define TT_ZTILES(tl) ((tl)->td)
#define TT_ZLINE 8
#define TT_ZNEXTUP(x) nextafter((x), INFINITY)
#else
#define TT_ZARR(g) ((g)->z)
#define TT_ZTILES(tl) ((tl)->t)
#define TT_ZLINE 16
#define TT_ZNEXTUP(x) nextafterf((x), INFINITY)
#endif

#define prefetch_row TT_ZN(prefetch_row)
#define scan_prefetch TT_ZN(scan_prefetch)
#define load2 TT_ZN(load2)
#define row_max TT_ZN(row_max)
#define row_stats TT_ZN(row_stats)
#define find_in_row TT_ZN(find_in_row)
#define tile_store TT_ZN(tile_store)
#define tile_fit_full TT_ZN(tile_fit_full)
#define tile_fit TT_ZN(tile_fit)
#define tiles_job TT_ZN(tiles_job)
#define tiles_row_job TT_ZN(tiles_row_job)
#define tiles_build TT_ZN(tiles_build)
#define tile_bound TT_ZN(tile_bound)
#define best_index TT_ZN(best_index)
#define row_max_fn TT_ZN(row_max_fn)
#define segment_max TT_ZN(segment_max)
#define scan_segment TT_ZN(scan_segment)
#define scan_tile TT_ZN(scan_tile)
#define candidate_tiled TT_ZN(candidate_tiled)
#define plain_rows TT_ZN(plain_rows)
#define plain_rows_sse TT_ZN(plain_rows_sse)
#define row_max_wide TT_ZN(row_max_wide)
#define plain_rows_wide TT_ZN(plain_rows_wide)
#define candidate_rows TT_ZN(candidate_rows)
#define stats_run TT_ZN(stats_run)

static inline void prefetch_row(const TT_Z *zr, size_t nx, int64_t y,
                                int64_t ymax, int64_t xl, int64_t xr)
{
#if defined(__GNUC__)
  if (y + PREFETCH_AHEAD <= ymax) {
    const TT_Z *ahead = zr + (size_t)PREFETCH_AHEAD * nx;
    __builtin_prefetch(ahead + xl);
    __builtin_prefetch(ahead + xr);
  }
#else
  (void)zr, (void)nx, (void)y, (void)ymax, (void)xl, (void)xr;
#endif
}

static void scan_prefetch(const tt_grid *g, const tt__scan_tri *st,
                          int64_t ylo, int64_t yhi)
{
#if defined(__GNUC__)
  int64_t xmin, xmax, ymin, ymax;
  tt__scan_tri_bbox(st, &xmin, &xmax, &ymin, &ymax);
  if (ylo > ymin)
    ymin = ylo;
  if (yhi < ymax)
    ymax = yhi;
  for (int64_t y = ymin; y <= ymax; y++) {
    const TT_Z *row = TT_ZARR(g) + (size_t)y * g->nx;
    for (int64_t x = xmin; x <= xmax + TT_ZLINE - 1; x += TT_ZLINE)
      __builtin_prefetch(row + (x < xmax ? x : xmax));
  }
#else
  (void)g, (void)st, (void)ylo, (void)yhi;
#endif
}

#if defined(__SSE2__)
/* Two samples as doubles. */
static inline __m128d load2(const TT_Z *p)
{
#if TT_Z_IS_F64
  return _mm_loadu_pd(p);
#else
  return _mm_cvtps_pd(_mm_castsi128_ps(_mm_loadl_epi64((const __m128i *)p)));
#endif
}

/* Max of |z - plane| over columns [xl, xr]. Works in groups of 4; the last
 * group may run past xr (the grid is padded, grid.c) and its extra lanes
 * are masked to 0, which never wins a maximum of errors >= 0. */
static inline double row_max(const kern *kn, const TT_Z *zr, int64_t xl,
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

static inline void row_stats(const kern *kn, const TT_Z *zr, int64_t xl,
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

static inline double row_max(const kern *kn, const TT_Z *zr, int64_t xl,
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

static inline void row_stats(const kern *kn, const TT_Z *zr, int64_t xl,
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
  const TT_Z *zr = TT_ZARR(g) + (size_t)y * g->nx;
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
 * the valid heights; the stored values (TT_Z) are then re-centred on the
 * residuals, and h is measured from the stored values themselves. */

/* Stores the plane (c, bx, by) as TT_Z about the centre (xc, yc) of the
 * tile [x0, x1) x [y0, y1) and h, the largest |z - plane| of a valid
 * sample measured from those values (re-centred first), rounded up. */
static void tile_store(const tt_grid *g, size_t x0, size_t x1, size_t y0,
                       size_t y1, double c, double bx, double by,
                       TT_Z out[4])
{
  double xc = 0.5 * (double)(x0 + x1 - 1), yc = 0.5 * (double)(y0 + y1 - 1);
  TT_Z cf = (TT_Z)c, bxf = (TT_Z)bx, byf = (TT_Z)by;
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
      const TT_Z *zr = TT_ZARR(g) + y * g->nx + x0;
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
    const TT_Z *zr = TT_ZARR(g) + y * g->nx;
    double base = (double)cf + (double)byf * ((double)y - yc);
    for (size_t x = xs; x < x1; x++) {
      double z = (double)zr[x];
      double r = z - (base + (double)bxf * ((double)x - xc));
      rlo = r < rlo ? r : rlo; /* NaN compares false */
      rhi = r > rhi ? r : rhi;
    }
  }
  TT_Z cm = (TT_Z)((double)cf + 0.5 * (rlo + rhi));
  double shift = (double)cm - (double)cf; /* exact: two nearby TT_Z */
  double h = fmax(rhi - shift, shift - rlo);
  TT_Z hf = (TT_Z)h;
  if ((double)hf < h)
    hf = TT_ZNEXTUP(hf);
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
                          TT_Z out[4])
{
  const __m128d u01 = _mm_set_pd(-2.5, -3.5), step = _mm_set1_pd(2.0);
  __m128d sz = _mm_setzero_pd(), suz = _mm_setzero_pd(),
          svz = _mm_setzero_pd(), bad = _mm_setzero_pd();
  for (size_t k = 0; k < TT__TILE; k++) {
    const TT_Z *zr = TT_ZARR(g) + (y0 + k) * g->nx + x0;
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

static void tile_fit(const tt_grid *g, size_t tx, size_t ty, TT_Z out[4])
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
    const TT_Z *zr = TT_ZARR(g) + y * g->nx;
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
    tile_fit(j->g, tx, ty, TT_ZTILES(j->out) + 4 * (ty * j->out->ntx + tx));
}

static bool tiles_build(const tt_grid *g, tt__pool *pool,
                        tt__scan_tiles *out)
{
  out->ntx = (g->nx + TT__TILE - 1) >> TT__TILE_SHIFT;
  out->nty = (g->ny + TT__TILE - 1) >> TT__TILE_SHIFT;
  TT_ZTILES(out) = malloc(out->ntx * out->nty * 4 * sizeof(TT_Z));
  if (!TT_ZTILES(out)) {
    out->ntx = out->nty = 0;
    return false;
  }
  tiles_job j = {g, out};
  tt__pool_run(pool, out->nty, tiles_row_job, &j);
  return true;
}

/* The bound of tile (tx, ty) for plane p; < 0 for a tile without valid
 * samples. The slack (1e-9 of the magnitudes involved) covers the rounding
 * of the bound and of the kernels' plane values many times over. */
static inline double tile_bound(const tt__scan_tiles *tl, const tt_grid *g,
                                const plane *p, int64_t tx, int64_t ty)
{
  const TT_Z *t = TT_ZTILES(tl) + 4 * ((size_t)ty * tl->ntx + (size_t)tx);
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
typedef double (*row_max_fn)(const kern *kn, const TT_Z *zr, int64_t xl,
                             int64_t xr, double rowbase, double gx,
                             int64_t x0);

/* The largest error in columns [xl, xr] of row y, vertex columns cut out. */
static inline __attribute__((always_inline)) double
segment_max(const tt_grid *g, const tt__scan_tri *st, const plane *p,
            const kern *kn, int64_t y, int64_t xl, int64_t xr,
            row_max_fn kernel)
{
  const TT_Z *zr = TT_ZARR(g) + (size_t)y * g->nx;
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
  /* the last row prefetch_row asks rows ahead for: none (-1, rows are
   * >= 0) on a grid in cache, so the loop tests nothing more per row */
  int64_t pf_ymax = -1;
  if (tt__scan_prefetches(g)) {
    pf_ymax = r.ymax;
    scan_prefetch(g, st, r.ymin, r.ymin + PREFETCH_AHEAD - 1);
  }
  for (int64_t y = r.ymin; y <= r.ymax; y++) {
    int64_t xl, xr;
    if (!row_span_step(&r, &xl, &xr))
      continue;
    prefetch_row(TT_ZARR(g) + (size_t)y * g->nx, g->nx, y, pf_ymax, xl, xr);
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
/* row_max with eight lanes: columns x .. x + 7 as k = x - x0 + lane (exact
 * doubles), the last step masked to the columns left. NaN errors keep the
 * running maximum (max(e, m) returns m when e is NaN), as in row_max. */
static inline __attribute__((always_inline)) TT_WIDE_TARGET double
row_max_wide(const kern *kn, const TT_Z *zr, int64_t xl, int64_t xr,
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
#if TT_Z_IS_F64
    __m512d z = _mm512_loadu_pd(zr + x);
#else
    __m512d z = _mm512_cvtps_pd(_mm256_loadu_ps(zr + x));
#endif
    __m512d e = _mm512_abs_pd(
        _mm512_sub_pd(z, _mm512_add_pd(vbase, _mm512_mul_pd(vgx, k))));
    m = _mm512_max_pd(e, m);
    k = _mm512_add_pd(k, eight);
  }
  if (x <= xr) {
    __mmask8 live = (__mmask8)((1u << (xr - x + 1)) - 1u);
#if TT_Z_IS_F64
    __m512d z = _mm512_maskz_loadu_pd(live, zr + x);
#else
    __m512d z = _mm512_cvtps_pd(_mm256_maskz_loadu_ps(live, zr + x));
#endif
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

#endif

static void candidate_rows(const tt_grid *g, const tt__scan_tiles *tiles,
                           const tt__scan_tri *st, int64_t ylo, int64_t yhi,
                           double *out_err, int64_t *out_index)
{
  plane p;
  kern kn;
  plane_of(st, &p);
  kern_init(&kn, p.gx);
  best_t b = {0, -1, 0, -1, -1};
  if (!(tiles && TT_ZTILES(tiles) && tt__scan_tiled(st) &&
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

static void stats_run(const tt_grid *g, const tt__scan_tri *st,
                      int64_t ylo, int64_t yhi, tt__scan_stats *out)
{
  plane p;
  rows r;
  kern kn;
  plane_of(st, &p);
  rows_init(st, (int64_t)g->nx, ylo, &r);
  if (yhi < r.ymax)
    r.ymax = yhi;
  kern_init(&kn, p.gx);
  row_acc acc = {0, 0, 0, 0};
  int64_t max_y = -1, max_xl = 0, max_xr = -1;
  int64_t pf_ymax = tt__scan_prefetches(g) ? r.ymax : -1; /* as above */
  for (int64_t y = r.ymin; y <= r.ymax; y++) {
    int64_t xl, xr;
    if (!row_span_step(&r, &xl, &xr))
      continue;
    const TT_Z *zr = TT_ZARR(g) + (size_t)y * g->nx;
    prefetch_row(zr, g->nx, y, pf_ymax, xl, xr);
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

#undef prefetch_row
#undef scan_prefetch
#undef load2
#undef row_max
#undef row_stats
#undef find_in_row
#undef tile_store
#undef tile_fit_full
#undef tile_fit
#undef tiles_job
#undef tiles_row_job
#undef tiles_build
#undef tile_bound
#undef best_index
#undef row_max_fn
#undef segment_max
#undef scan_segment
#undef scan_tile
#undef candidate_tiled
#undef plain_rows
#undef plain_rows_sse
#undef row_max_wide
#undef plain_rows_wide
#undef candidate_rows
#undef stats_run
#undef TT_ZARR
#undef TT_ZTILES
#undef TT_ZLINE
#undef TT_ZNEXTUP
#undef TT_Z
#undef TT_Z_IS_F64
#undef TT_ZN
