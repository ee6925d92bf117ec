/*
 * raster_scan.c -- the samples a triangle owns, and their errors (see
 * raster_scan.h for the ownership rule and the plane expression).
 *
 * Per row the owned span [xl, xr] comes from the three edge functions in
 * exact 64-bit integer arithmetic; vertex samples on the row are cut out.
 * The per-sample loop is a max reduction over |z - plane| that GCC
 * vectorises (NaN nodata compares false and drops out). Workload: in
 * greedy refinement every sample is rescanned each time the triangle
 * holding it changes, O(log n) times on average.
 */
#include "raster_scan.h"

#include <math.h>

/* floor(a / b) and ceil(a / b) for b > 0 */
static inline int64_t floor_div(int64_t a, int64_t b)
{
  int64_t q = a / b;
  return (a % b != 0 && a < 0) ? q - 1 : q;
}

static inline int64_t ceil_div(int64_t a, int64_t b)
{
  int64_t q = a / b;
  return (a % b != 0 && a > 0) ? q + 1 : q;
}

void tt__scan_tri_from_mesh(const tt__mesh *m, const tt_grid *g, int32_t t,
                            tt__scan_tri *st)
{
  for (int k = 0; k < 3; k++) {
    int32_t e = 3 * t + k;
    int32_t v = m->hv[e];
    st->x[k] = m->vc[v];
    st->y[k] = m->vr[v];
    st->z[k] = (double)g->z[(size_t)m->vr[v] * g->nx + (size_t)m->vc[v]];
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

/* Row iteration state: the normalised edge functions
 * E_k(x, y) = s ((x_{k+1} - x_k)(y - y_k) - (y_{k+1} - y_k)(x - x_k)),
 * s the pixel-space orientation sign, positive inside. */
typedef struct rows {
  int64_t ymin, ymax;
  int64_t ex[3], ey[3];   /* E_k = ex[k] * (x - x_k) + ey[k] * (y - y_k) */
  int64_t xk[3], yk[3];
  bool own[3];
  int64_t xmax;           /* grid width - 1 */
} rows;

static void rows_init(const tt__scan_tri *st, int64_t nx, rows *r)
{
  int64_t dx1 = st->x[1] - st->x[0], dy1 = st->y[1] - st->y[0];
  int64_t dx2 = st->x[2] - st->x[0], dy2 = st->y[2] - st->y[0];
  int64_t s = (dx1 * dy2 - dx2 * dy1) > 0 ? 1 : -1;
  r->ymin = r->ymax = st->y[0];
  for (int k = 0; k < 3; k++) {
    int k1 = (k + 1) % 3;
    r->ex[k] = -s * (st->y[k1] - st->y[k]);
    r->ey[k] = s * (st->x[k1] - st->x[k]);
    r->xk[k] = st->x[k];
    r->yk[k] = st->y[k];
    r->own[k] = st->own[k];
    if (st->y[k] < r->ymin)
      r->ymin = st->y[k];
    if (st->y[k] > r->ymax)
      r->ymax = st->y[k];
  }
  r->xmax = nx - 1;
}

/* The owned span of row y; false when empty. */
static inline bool row_span(const rows *r, int64_t y, int64_t *out_xl,
                            int64_t *out_xr)
{
  int64_t xl = 0, xr = r->xmax;
  for (int k = 0; k < 3; k++) {
    int64_t a = r->ex[k];
    int64_t b = r->ey[k] * (y - r->yk[k]) - a * r->xk[k]; /* E = a x + b */
    if (a > 0) {
      /* owned: a x + b >= 0 -> x >= ceil(-b / a); else x > -b / a */
      int64_t lo = r->own[k] ? ceil_div(-b, a) : floor_div(-b, a) + 1;
      if (lo > xl)
        xl = lo;
    } else if (a < 0) {
      /* owned: x <= floor(b / -a); else x < b / -a */
      int64_t hi = r->own[k] ? floor_div(b, -a) : ceil_div(b, -a) - 1;
      if (hi < xr)
        xr = hi;
    } else if (b < 0 || (b == 0 && !r->own[k])) {
      return false;
    }
  }
  *out_xl = xl;
  *out_xr = xr;
  return xl <= xr;
}

/* Vertex columns on row y inside [xl, xr], sorted; returns their count. */
static inline int row_vertices(const tt__scan_tri *st, int64_t y, int64_t xl,
                               int64_t xr, int64_t out_x[3])
{
  int n = 0;
  for (int k = 0; k < 3; k++)
    if (st->y[k] == y && st->x[k] >= xl && st->x[k] <= xr)
      out_x[n++] = st->x[k];
  for (int i = 1; i < n; i++)
    for (int j = i; j > 0 && out_x[j - 1] > out_x[j]; j--) {
      int64_t tmp = out_x[j];
      out_x[j] = out_x[j - 1];
      out_x[j - 1] = tmp;
    }
  return n;
}

static inline double row_max(const float *zr, int64_t xl, int64_t xr,
                             double rowbase, double gx, int64_t x0)
{
  double m = 0;
  for (int64_t x = xl; x <= xr; x++) {
    double v = rowbase + gx * (double)(x - x0);
    double e = fabs((double)zr[x] - v);
    m = e > m ? e : m;
  }
  return m;
}

static inline int64_t row_find(const float *zr, int64_t xl, int64_t xr,
                               double rowbase, double gx, int64_t x0,
                               double target)
{
  for (int64_t x = xl; x <= xr; x++) {
    double v = rowbase + gx * (double)(x - x0);
    if (fabs((double)zr[x] - v) == target)
      return x;
  }
  return -1;
}

void tt__scan_candidate(const tt_grid *g, const tt__scan_tri *st,
                        double *out_err, int64_t *out_index)
{
  plane p;
  rows r;
  plane_of(st, &p);
  rows_init(st, (int64_t)g->nx, &r);
  double best = 0;
  int64_t best_index = -1;
  for (int64_t y = r.ymin; y <= r.ymax; y++) {
    int64_t xl, xr;
    if (!row_span(&r, y, &xl, &xr))
      continue;
    const float *zr = g->z + (size_t)y * g->nx;
    double rowbase = p.z0 + p.gy * (double)(y - p.y0);
    int64_t vx[3];
    int nvx = row_vertices(st, y, xl, xr, vx);
    int64_t lo = xl;
    for (int i = 0; i <= nvx; i++) {
      int64_t hi = i < nvx ? vx[i] - 1 : xr;
      if (lo <= hi) {
        double m = row_max(zr, lo, hi, rowbase, p.gx, p.x0);
        if (m > best) {
          best = m;
          best_index = (int64_t)((size_t)y * g->nx) +
                       row_find(zr, lo, hi, rowbase, p.gx, p.x0, m);
        }
      }
      if (i < nvx)
        lo = vx[i] + 1;
    }
  }
  *out_err = best;
  *out_index = best_index;
}

void tt__scan_stats_run(const tt_grid *g, const tt__scan_tri *st,
                        tt__scan_stats *out)
{
  plane p;
  rows r;
  plane_of(st, &p);
  rows_init(st, (int64_t)g->nx, &r);
  out->count = 0;
  out->max_err = 0;
  out->max_index = -1;
  out->sum_abs = 0;
  out->sum_sq = 0;
  for (int64_t y = r.ymin; y <= r.ymax; y++) {
    int64_t xl, xr;
    if (!row_span(&r, y, &xl, &xr))
      continue;
    const float *zr = g->z + (size_t)y * g->nx;
    double rowbase = p.z0 + p.gy * (double)(y - p.y0);
    int64_t vx[3];
    int nvx = row_vertices(st, y, xl, xr, vx);
    int64_t lo = xl;
    for (int i = 0; i <= nvx; i++) {
      int64_t hi = i < nvx ? vx[i] - 1 : xr;
      for (int64_t x = lo; x <= hi; x++) {
        float zv = zr[x];
        if (isnan(zv))
          continue;
        double v = rowbase + p.gx * (double)(x - p.x0);
        double e = fabs((double)zv - v);
        out->count++;
        out->sum_abs += e;
        out->sum_sq += e * e;
        if (e > out->max_err || out->max_index < 0) {
          out->max_err = e;
          out->max_index = (int64_t)((size_t)y * g->nx) + x;
        }
      }
      if (i < nvx)
        lo = vx[i] + 1;
    }
  }
}
