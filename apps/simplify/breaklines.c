/*
 * breaklines.c -- apps/simplify/: -breaklines LINES made the engine's
 * constraint segments (tt_breaklines) for a whole run.
 *
 * Every line of LINES's layer (-breaklines_layer, -breaklines_where; the
 * rings of polygons too) is reprojected to the DEM's CRS and traced as a
 * 4-connected chain of the samples nearest its path. A sample is kept in
 * a chain only when it and the four cells around it are valid, so a line
 * is cut where it leaves the DEM or meets nodata (the lines cut are
 * counted in a warning). Two chains that cross share a sample (two
 * 4-connected paths cannot cross between samples), which stays a vertex:
 * lines are split there. Each piece between such samples is simplified by
 * Douglas-Peucker on its profile (heights against the position along the
 * simplified segment), exactly: every chain sample is within the bound of
 * its segment in height and within one sample step of it in the plane, and a segment is kept only when every cell of its bounding
 * box is valid, so it never crosses the nodata outline. Simplified
 * segments that cross each other are split again (back towards the unit
 * steps, which never cross) until none does. Refinement then keeps the
 * bound everywhere, along the lines as elsewhere.
 *
 * Workload: lines of up to some thousands of segments; the crossing test
 * is pairwise over the segments (O(S^2) per round).
 */
#include "simplify.h"

#include <gdal.h>
#include <ogr_srs_api.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Grows *ptr to hold need elements of elem bytes (doubling). */
static bool grow(void **ptr, size_t *cap, size_t need, size_t elem)
{
  if (need <= *cap)
    return true;
  size_t c = *cap ? *cap : 16;
  while (c < need)
    c *= 2;
  void *p = realloc(*ptr, c * elem);
  if (!p)
    return false;
  *ptr = p;
  *cap = c;
  return true;
}

/* The chains: samples of all chains back to back, chain k from
 * s[start[k]] to s[start[k + 1] - 1]. */
typedef struct chains {
  int64_t *s;
  size_t n, cap;
  size_t *start;
  size_t nchains, ccap;
  size_t open;       /* first sample of the chain being traced */
} chains;

/* What tracing needs: the grid, its fully valid cells' prefix sums. */
typedef struct tracer {
  const tt_grid *g;
  size_t nx, ny;
  uint32_t *bad;     /* (nx) x (ny) prefix sums of cells not fully valid:
                        bad[y nx + x] counts cells (< x, < y) */
  chains c;
  int cut;           /* the current line was cut somewhere */
} tracer;

static int valid_at(const tracer *T, size_t x, size_t y)
{
  return !isnan(tt_grid_sample(T->g, x, y));
}

static bool tracer_init(tracer *T, const tt_grid *g)
{
  memset(T, 0, sizeof *T);
  T->g = g;
  T->nx = tt_grid_width(g);
  T->ny = tt_grid_height(g);
  size_t nx = T->nx, ny = T->ny;
  T->bad = calloc(nx * ny, sizeof *T->bad);
  if (!T->bad)
    return false;
  /* cells are (nx - 1) x (ny - 1); the sums are indexed by their ends */
  for (size_t y = 1; y < ny; y++)
    for (size_t x = 1; x < nx; x++) {
      uint32_t full = valid_at(T, x - 1, y - 1) && valid_at(T, x, y - 1) &&
                      valid_at(T, x - 1, y) && valid_at(T, x, y);
      T->bad[y * nx + x] = (uint32_t)!full + T->bad[(y - 1) * nx + x] +
                           T->bad[y * nx + x - 1] -
                           T->bad[(y - 1) * nx + x - 1];
    }
  return true;
}

/* Whether every cell with a corner in samples x0..x1, y0..y1 is valid. */
static bool box_valid(const tracer *T, int64_t x0, int64_t y0, int64_t x1,
                      int64_t y1)
{
  int64_t cx0 = x0 > 0 ? x0 - 1 : 0, cy0 = y0 > 0 ? y0 - 1 : 0;
  int64_t cx1 = x1 < (int64_t)T->nx - 1 ? x1 : (int64_t)T->nx - 2;
  int64_t cy1 = y1 < (int64_t)T->ny - 1 ? y1 : (int64_t)T->ny - 2;
  size_t nx = T->nx;
  /* cells cx0..cx1, cy0..cy1: the sums at their ends + 1 */
  uint32_t sum = T->bad[(size_t)(cy1 + 1) * nx + (size_t)(cx1 + 1)] -
                 T->bad[(size_t)cy0 * nx + (size_t)(cx1 + 1)] -
                 T->bad[(size_t)(cy1 + 1) * nx + (size_t)cx0] +
                 T->bad[(size_t)cy0 * nx + (size_t)cx0];
  return sum == 0;
}

/* A sample a chain may hold: on the grid, valid, its cells valid. */
static bool usable(const tracer *T, int64_t x, int64_t y)
{
  if (x < 0 || y < 0 || x >= (int64_t)T->nx || y >= (int64_t)T->ny ||
      !valid_at(T, (size_t)x, (size_t)y))
    return false;
  return box_valid(T, x, y, x, y);
}

static bool push_sample(chains *c, int64_t s)
{
  return grow((void **)&c->s, &c->cap, c->n + 1, sizeof *c->s) &&
         (c->s[c->n++] = s, true);
}

/* Ends the chain being traced: kept with two samples or more. */
static bool close_chain(chains *c)
{
  if (c->n - c->open < 2) {
    c->n = c->open;
    return true;
  }
  if (!grow((void **)&c->start, &c->ccap, c->nchains + 2,
                    sizeof *c->start))
    return false;
  c->start[c->nchains++] = c->open;
  c->start[c->nchains] = c->n;
  c->open = c->n;
  return true;
}

/* Adds sample (x, y) to the chain being traced, a unit step from its last
 * sample (the caller makes sure); an unusable sample cuts the chain. */
static bool step_to(tracer *T, int64_t x, int64_t y)
{
  chains *c = &T->c;
  if (!usable(T, x, y)) {
    T->cut = 1;
    return close_chain(c);
  }
  int64_t s = y * (int64_t)T->nx + x;
  if (c->n > c->open && c->s[c->n - 1] == s)
    return true;
  return push_sample(c, s);
}

/* The samples nearest segment (u0, v0) - (u1, v1), in sample coordinates,
 * added as 4-connected steps: a diagonal move goes through the corner
 * nearer the segment's point. */
static bool trace_segment(tracer *T, double u0, double v0, double u1,
                          double v1, int64_t *lx, int64_t *ly, bool *have)
{
  double len = fmax(fabs(u1 - u0), fabs(v1 - v0));
  if (!(len < 4.0e9))
    return true; /* not finite or absurd: nothing near the grid */
  size_t steps = (size_t)ceil(4 * len) + 1;
  for (size_t k = 0; k <= steps; k++) {
    double t = (double)k / (double)steps;
    double u = u0 + t * (u1 - u0), v = v0 + t * (v1 - v0);
    if (fabs(u) > 4.0e9 || fabs(v) > 4.0e9) {
      T->cut = 1;
      *have = false;
      if (!close_chain(&T->c))
        return false;
      continue;
    }
    int64_t x = (int64_t)llround(u), y = (int64_t)llround(v);
    if (*have && x == *lx && y == *ly)
      continue;
    if (*have && llabs(x - *lx) + llabs(y - *ly) == 2 && x != *lx &&
        y != *ly) {
      /* the corner nearer (u, v): (x, ly) or (lx, y) */
      double d1 = fabs(v - (double)*ly), d2 = fabs(u - (double)*lx);
      bool ok = d1 <= d2 ? step_to(T, x, *ly) : step_to(T, *lx, y);
      if (!ok)
        return false;
    } else if (*have && llabs(x - *lx) + llabs(y - *ly) > 1) {
      if (!close_chain(&T->c)) /* a jump (cannot happen at 1/4 steps) */
        return false;
    }
    if (!step_to(T, x, y))
      return false;
    *lx = x;
    *ly = y;
    *have = true;
  }
  return true;
}

/* Traces one line string of geometry l (in the DEM's CRS) into chains. */
static bool trace_line(tracer *T, OGRGeometryH l, const double inv[6])
{
  int n = OGR_G_GetPointCount(l);
  int64_t lx = 0, ly = 0;
  bool have = false;
  double pu = 0, pv = 0;
  for (int i = 0; i < n; i++) {
    double X = OGR_G_GetX(l, i), Y = OGR_G_GetY(l, i);
    double u = inv[0] + inv[1] * X + inv[2] * Y - 0.5;
    double v = inv[3] + inv[4] * X + inv[5] * Y - 0.5;
    if (i > 0 && !trace_segment(T, pu, pv, u, v, &lx, &ly, &have))
      return false;
    pu = u;
    pv = v;
  }
  if (n == 1 && !trace_segment(T, pu, pv, pu, pv, &lx, &ly, &have))
    return false;
  return close_chain(&T->c);
}

/* Every line string in g (lines, rings, collections of them). */
static bool trace_geometry(tracer *T, OGRGeometryH g, const double inv[6])
{
  OGRwkbGeometryType t = wkbFlatten(OGR_G_GetGeometryType(g));
  if (t == wkbLineString || t == wkbLinearRing || t == wkbCircularString)
    return trace_line(T, g, inv);
  int n = OGR_G_GetGeometryCount(g);
  for (int i = 0; i < n; i++)
    if (!trace_geometry(T, OGR_G_GetGeometryRef(g, i), inv))
      return false;
  return true;
}

/* --- simplification ----------------------------------------------------- */

static int64_t sx(const tracer *T, int64_t s) { return s % (int64_t)T->nx; }
static int64_t sy(const tracer *T, int64_t s) { return s / (int64_t)T->nx; }

static double sz(const tracer *T, int64_t s)
{
  return tt_grid_sample(T->g, (size_t)sx(T, s), (size_t)sy(T, s));
}

static int cmp_i64(const void *a, const void *b)
{
  int64_t x = *(const int64_t *)a, y = *(const int64_t *)b;
  return (x > y) - (x < y);
}

/* Whether sample s occurs twice or more among the chains (sorted). */
static bool shared(const int64_t *sorted, size_t n, int64_t s)
{
  size_t lo = 0, hi = n;
  while (lo < hi) {
    size_t mid = lo + (hi - lo) / 2;
    if (sorted[mid] < s)
      lo = mid + 1;
    else
      hi = mid;
  }
  return lo + 1 < n && sorted[lo] == s && sorted[lo + 1] == s;
}

/* The sample of chain samples i < k < j farthest from segment i - j in
 * height (heights interpolated at each sample's projection on it), and
 * that distance; i + 1 == j: -1. A sample farther than one sample step
 * from the segment in the plane counts as infinitely far: a line keeps
 * its path, not only its profile. */
static size_t worst(const tracer *T, size_t i, size_t j, double *out_err)
{
  const int64_t *s = T->c.s;
  double xi = (double)sx(T, s[i]), yi = (double)sy(T, s[i]), zi = sz(T, s[i]);
  double dx = (double)sx(T, s[j]) - xi, dy = (double)sy(T, s[j]) - yi;
  double dz = sz(T, s[j]) - zi, len2 = dx * dx + dy * dy;
  size_t at = (size_t)-1;
  *out_err = -1;
  for (size_t k = i + 1; k < j; k++) {
    double t = len2 > 0 ? (((double)sx(T, s[k]) - xi) * dx +
                           ((double)sy(T, s[k]) - yi) * dy) / len2 : 0;
    t = t < 0 ? 0 : t > 1 ? 1 : t;
    double ex = (double)sx(T, s[k]) - (xi + t * dx);
    double ey = (double)sy(T, s[k]) - (yi + t * dy);
    double e = ex * ex + ey * ey > 1.0 ? HUGE_VAL
                                       : fabs(sz(T, s[k]) - (zi + t * dz));
    if (e > *out_err) {
      *out_err = e;
      at = k;
    }
  }
  return at;
}

/* Douglas-Peucker between kept samples i and j of one chain: keep[k] set
 * for every sample the simplified chain keeps. stack: scratch. */
static bool simplify_span(const tracer *T, size_t i, size_t j, double bound,
                          unsigned char *keep, size_t **stack, size_t *cap)
{
  size_t n = 0;
  if (!grow((void **)stack, cap, 2, sizeof **stack))
    return false;
  (*stack)[n++] = i;
  (*stack)[n++] = j;
  while (n) {
    size_t b = (*stack)[--n], a = (*stack)[--n];
    if (b <= a + 1)
      continue;
    double err;
    size_t k = worst(T, a, b, &err);
    const int64_t *s = T->c.s;
    int64_t x0 = sx(T, s[a]), x1 = sx(T, s[b]), y0 = sy(T, s[a]),
            y1 = sy(T, s[b]);
    bool inside = box_valid(T, x0 < x1 ? x0 : x1, y0 < y1 ? y0 : y1,
                            x0 < x1 ? x1 : x0, y0 < y1 ? y1 : y0);
    if (err <= bound && inside)
      continue;
    if (err <= bound)
      k = a + (b - a) / 2; /* within the bound, but across nodata */
    keep[k] = 1;
    if (!grow((void **)stack, cap, n + 4, sizeof **stack))
      return false;
    (*stack)[n++] = a;
    (*stack)[n++] = k;
    (*stack)[n++] = k;
    (*stack)[n++] = b;
  }
  return true;
}

/* --- crossings ------------------------------------------------------------ */

static int orient(int64_t ax, int64_t ay, int64_t bx, int64_t by, int64_t cx,
                  int64_t cy)
{
  __int128 d = (__int128)(bx - ax) * (cy - ay) - (__int128)(by - ay) * (cx - ax);
  return (d > 0) - (d < 0);
}

/* Whether segments pq and ab cross at a point inside both. */
static bool cross(const tracer *T, int64_t p, int64_t q, int64_t a, int64_t b)
{
  int64_t px = sx(T, p), py = sy(T, p), qx = sx(T, q), qy = sy(T, q);
  int64_t ax = sx(T, a), ay = sy(T, a), bx = sx(T, b), by = sy(T, b);
  return orient(ax, ay, bx, by, px, py) * orient(ax, ay, bx, by, qx, qy) < 0 &&
         orient(px, py, qx, qy, ax, ay) * orient(px, py, qx, qy, bx, by) < 0;
}

/* The kept segments as pairs of chain positions into *seg (*nseg). */
static bool segments(const tracer *T, const unsigned char *keep,
                     size_t **seg, size_t *cap, size_t *out_n)
{
  size_t n = 0;
  for (size_t k = 0; k < T->c.nchains; k++) {
    size_t a = T->c.start[k];
    for (size_t i = a + 1; i < T->c.start[k + 1]; i++)
      if (keep[i]) {
        if (!grow((void **)seg, cap, 2 * n + 2, sizeof **seg))
          return false;
        (*seg)[2 * n] = a;
        (*seg)[2 * n + 1] = i;
        n++;
        a = i;
      }
  }
  *out_n = n;
  return true;
}

/* Splits simplified segments that cross, at their middle sample, until
 * none does (unit steps never cross, so it ends). */
static bool uncross(const tracer *T, unsigned char *keep, size_t **seg,
                    size_t *cap, size_t *out_n)
{
  for (;;) {
    size_t n;
    if (!segments(T, keep, seg, cap, &n))
      return false;
    *out_n = n;
    bool split = false;
    const int64_t *s = T->c.s;
    for (size_t i = 0; i < n; i++)
      for (size_t j = i + 1; j < n; j++) {
        size_t a = (*seg)[2 * i], b = (*seg)[2 * i + 1];
        size_t c = (*seg)[2 * j], d = (*seg)[2 * j + 1];
        if (!cross(T, s[a], s[b], s[c], s[d]))
          continue;
        if (b > a + 1)
          keep[a + (b - a) / 2] = 1;
        if (d > c + 1)
          keep[c + (d - c) / 2] = 1;
        split = true;
      }
    if (!split)
      return true;
  }
}

/* --- reading -------------------------------------------------------------- */

/* LINES's layer, filtered; NULL with the failure recorded. */
static OGRLayerH open_layer(app_run *r, const tt_app_settings *s,
                            GDALDatasetH *out_ds)
{
  r->msg.last[0] = '\0';
  GDALDatasetH ds = GDALOpenEx(s->breaklines, GDAL_OF_VECTOR |
                               GDAL_OF_READONLY | GDAL_OF_VERBOSE_ERROR,
                               NULL, NULL, NULL);
  *out_ds = ds;
  if (!ds) {
    tt__app_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_IO, s->breaklines,
                 "cannot open as a vector dataset%s%s",
                 r->msg.last[0] ? ": " : "", r->msg.last);
    return NULL;
  }
  OGRLayerH l = s->breaklines_layer
                    ? GDALDatasetGetLayerByName(ds, s->breaklines_layer)
                    : GDALDatasetGetLayer(ds, 0);
  if (!l) {
    tt__app_fail(r, TT_APP_EXIT_USAGE, TT_ERR_ARG, s->breaklines,
                 "has no layer %s%s%s", s->breaklines_layer ? "'" : "",
                 s->breaklines_layer ? s->breaklines_layer : "at all",
                 s->breaklines_layer ? "'" : "");
    return NULL;
  }
  if (s->breaklines_where &&
      OGR_L_SetAttributeFilter(l, s->breaklines_where) != OGRERR_NONE) {
    tt__app_fail(r, TT_APP_EXIT_USAGE, TT_ERR_ARG, NULL,
                 "simplify: -breaklines_where: '%s' is not a filter of "
                 "layer '%s'%s%s", s->breaklines_where, OGR_L_GetName(l),
                 r->msg.last[0] ? ": " : "", r->msg.last);
    return NULL;
  }
  return l;
}

/* The transformation from the layer's CRS to the DEM's: NULL when either
 * has none (coordinates taken as they are) or when they are the same. */
static OGRCoordinateTransformationH to_dem(app_run *r, OGRLayerH l,
                                           const tt_raster_info *info,
                                           int *out_failed)
{
  *out_failed = 0;
  OGRSpatialReferenceH from = OGR_L_GetSpatialRef(l);
  if (!from || !info->crs_wkt || !info->crs_wkt[0])
    return NULL;
  OGRSpatialReferenceH to = OSRNewSpatialReference(info->crs_wkt);
  OGRSpatialReferenceH src = OSRClone(from);
  OGRCoordinateTransformationH ct = NULL;
  if (to && src) {
    OSRSetAxisMappingStrategy(to, OAMS_TRADITIONAL_GIS_ORDER);
    OSRSetAxisMappingStrategy(src, OAMS_TRADITIONAL_GIS_ORDER);
    if (!OSRIsSame(src, to)) {
      ct = OCTNewCoordinateTransformation(src, to);
      if (!ct) {
        tt__app_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_ARG, r->s->breaklines,
                     "cannot be reprojected to the DEM's CRS%s%s",
                     r->msg.last[0] ? ": " : "", r->msg.last);
        *out_failed = 1;
      }
    }
  }
  OSRDestroySpatialReference(to);
  OSRDestroySpatialReference(src);
  return ct;
}

/* Traces every feature of l into T's chains; the lines and the lines
 * cut are counted. */
static tt_status trace_layer(app_run *r, tracer *T, OGRLayerH l,
                             OGRCoordinateTransformationH ct,
                             const double inv[6], size_t *out_lines,
                             size_t *out_cut)
{
  OGRFeatureH f;
  OGR_L_ResetReading(l);
  while ((f = OGR_L_GetNextFeature(l)) != NULL) {
    OGRGeometryH g0 = OGR_F_GetGeometryRef(f);
    OGRGeometryH g = g0 ? OGR_G_Clone(g0) : NULL;
    bool ok = true;
    if (g && ct && OGR_G_Transform(g, ct) != OGRERR_NONE) {
      T->cut = 1; /* outside the area the transformation covers */
      OGR_G_DestroyGeometry(g);
      g = NULL;
    }
    if (g) {
      if (OGR_G_HasCurveGeometry(g, 0)) {
        OGRGeometryH lin = OGR_G_GetLinearGeometry(g, 0, NULL);
        OGR_G_DestroyGeometry(g);
        g = lin;
      }
      T->cut = 0;
      ok = !g || trace_geometry(T, g, inv);
      (*out_lines)++;
      *out_cut += T->cut != 0;
      OGR_G_DestroyGeometry(g);
    }
    OGR_F_Destroy(f);
    if (!ok)
      return tt__app_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_NOMEM,
                          r->s->breaklines, "out of memory tracing the "
                          "breaklines");
  }
  return TT_OK;
}

/* The chains simplified and uncrossed, as the engine's segments. */
static bool chains_to_segments(tracer *T, double bound, int64_t **out_ends,
                               size_t *out_n)
{
  chains *c = &T->c;
  bool ok = false;
  int64_t *sorted = malloc((c->n + 1) * sizeof *sorted);
  unsigned char *keep = calloc(c->n + 1, 1);
  size_t *stack = NULL, scap = 0, *seg = NULL, segcap = 0, nseg = 0;
  if (!sorted || !keep)
    goto done;
  memcpy(sorted, c->s, c->n * sizeof *sorted);
  qsort(sorted, c->n, sizeof *sorted, cmp_i64);
  for (size_t k = 0; k < c->nchains; k++) {
    size_t a = c->start[k], b = c->start[k + 1] - 1;
    keep[a] = keep[b] = 1;
    for (size_t i = a + 1; i < b; i++)
      keep[i] = shared(sorted, c->n, c->s[i]);
    for (size_t i = a, j = a + 1; j <= b; j++)
      if (keep[j]) {
        if (!simplify_span(T, i, j, bound, keep, &stack, &scap))
          goto done;
        i = j;
      }
  }
  if (!uncross(T, keep, &seg, &segcap, &nseg))
    goto done;
  *out_ends = malloc((2 * nseg + 1) * sizeof **out_ends);
  if (!*out_ends)
    goto done;
  for (size_t i = 0; i < 2 * nseg; i++)
    (*out_ends)[i] = c->s[seg[i]];
  *out_n = nseg;
  ok = true;
done:
  free(sorted);
  free(keep);
  free(stack);
  free(seg);
  return ok;
}

tt_status tt__app_breaklines(app_simplify_job *job)
{
  app_run *r = job->r;
  const tt_app_settings *s = job->s;
  tt_status st = TT_OK;
  GDALDatasetH ds = NULL;
  OGRCoordinateTransformationH ct = NULL;
  tracer T;
  size_t lines = 0, cut = 0;
  if (!tracer_init(&T, job->grid)) {
    st = tt__app_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_NOMEM, s->breaklines,
                      "out of memory for the breaklines' grid");
    goto done;
  }
  OGRLayerH l = open_layer(r, s, &ds);
  if (!l) {
    st = TT_ERR_ARG;
    goto done;
  }
  int failed;
  ct = to_dem(r, l, job->info, &failed);
  double inv[6];
  if (failed || !GDALInvGeoTransform(job->info->gt, inv)) {
    st = failed ? TT_ERR_ARG
                : tt__app_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_DATA,
                               s->input, "has a geotransform that cannot be "
                               "inverted");
    goto done;
  }
  st = trace_layer(r, &T, l, ct, inv, &lines, &cut);
  if (st != TT_OK)
    goto done;
  double e = job->decimate ? job->dopt.max_error : job->ro.max_error;
  double bound = e > 0 ? e : 0;
  if (!chains_to_segments(&T, bound, &job->bl_ends, &job->ro.breaklines.n)) {
    st = tt__app_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_NOMEM, s->breaklines,
                      "out of memory simplifying the breaklines");
    goto done;
  }
  job->ro.breaklines.ends = job->bl_ends;
  job->dopt.breaklines = job->ro.breaklines;
  job->rep.breaklines = lines;
  job->rep.breakline_segments = job->ro.breaklines.n;
  if (cut)
    tt__app_warn(&r->msg, "%s: %zu of %zu breaklines clipped at the DEM's "
                 "edge or nodata", tt__app_shown(r, s->breaklines), cut,
                 lines);
  if (!job->ro.breaklines.n)
    tt__app_warn(&r->msg, "%s: no breakline crosses the DEM's valid "
                 "samples", tt__app_shown(r, s->breaklines));
done:
  if (ct)
    OCTDestroyCoordinateTransformation(ct);
  if (ds)
    GDALClose(ds);
  free(T.bad);
  free(T.c.s);
  free(T.c.start);
  return st;
}
