/*
 * hole.c -- filling the hole of a removed vertex (hole.h).
 *
 * Ear cutting: vertex i of the current polygon is an ear when its corner
 * turns strictly counter-clockwise (exact, tt__mesh_orient) and no other
 * polygon vertex lies in the closed triangle (prev, i, next): then the
 * diagonal prev-next runs inside the polygon, touches no other vertex,
 * and cutting the ear leaves a simple polygon. Among the ears the best by
 * the rule is cut (ties: the smallest position in the polygon), and only
 * the two neighbours are re-examined. A simple polygon of four or more
 * vertices, collinear runs allowed, always has such an ear (Meisters' two
 * ears theorem holds with strictly convex ears: a strictly convex vertex
 * whose triangle holds other vertices gives a diagonal to the one farthest
 * from the line prev-next, and the smaller side has an ear of its own), so
 * the loop never stalls. Scores are in the ground frame (on the ground
 * points when the mesh has them) and only choose;
 * they never decide validity. O(n^2) per hole; holes have about six
 * vertices.
 *
 * DP: the polygon goes to tt__polygon_dp with the criterion's measure.
 *
 * Part of src/decimate/, the vertex decimation method (tt_decimate_run).
 */
#include "decimate/hole.h"

#include "optimize/polygon_dp.h"

#include <math.h>
#include <stdlib.h>

void tt__dhole_init(tt__dhole *h)
{
  h->n = h->ntri = 0;
  h->p = NULL;
  h->tri = NULL;
  h->prev = h->next = NULL;
  h->ear = NULL;
  h->convex = NULL;
  h->score = h->gx = h->gy = NULL;
  h->px = h->py = NULL;
  h->idx = NULL;
  h->cap = 0;
}

void tt__dhole_free(tt__dhole *h)
{
  free(h->p);
  free(h->tri);
  free(h->prev);
  free(h->next);
  free(h->ear);
  free(h->convex);
  free(h->score);
  free(h->gx);
  free(h->gy);
  free(h->px);
  free(h->py);
  free(h->idx);
  tt__dhole_init(h);
}

bool tt__dhole_reserve(tt__dhole *h, int n)
{
  if (n < 3)
    n = 3;
  if ((size_t)n <= h->cap)
    return true;
  size_t cap = h->cap < 16 ? 16 : h->cap;
  while (cap < (size_t)n)
    cap *= 2;
  int32_t *p = realloc(h->p, cap * sizeof *p);
  if (p)
    h->p = p;
  int32_t(*tri)[3] = realloc(h->tri, cap * sizeof *tri);
  if (tri)
    h->tri = tri;
  int *pv = realloc(h->prev, cap * sizeof *pv);
  if (pv)
    h->prev = pv;
  int *nx = realloc(h->next, cap * sizeof *nx);
  if (nx)
    h->next = nx;
  bool *ear = realloc(h->ear, cap * sizeof *ear);
  if (ear)
    h->ear = ear;
  bool *cv = realloc(h->convex, cap * sizeof *cv);
  if (cv)
    h->convex = cv;
  double *sc = realloc(h->score, cap * sizeof *sc);
  if (sc)
    h->score = sc;
  double *gx = realloc(h->gx, cap * sizeof *gx);
  if (gx)
    h->gx = gx;
  double *gy = realloc(h->gy, cap * sizeof *gy);
  if (gy)
    h->gy = gy;
  int64_t *px = realloc(h->px, cap * sizeof *px);
  if (px)
    h->px = px;
  int64_t *py = realloc(h->py, cap * sizeof *py);
  if (py)
    h->py = py;
  int32_t *idx = realloc(h->idx, 3 * cap * sizeof *idx);
  if (idx)
    h->idx = idx;
  if (!p || !tri || !pv || !nx || !ear || !cv || !sc || !gx || !gy || !px || !py ||
      !idx)
    return false;
  h->cap = cap;
  return true;
}

bool tt__dhole_dp_supported(tt_criterion crit)
{
  return crit == TT_CRITERION_DELAUNAY || crit == TT_CRITERION_MINMAX_ANGLE ||
         crit == TT_CRITERION_MINMAX_ANGLE_LEX ||
         crit == TT_CRITERION_MIN_AREA;
}

/* Angle at (ax, ay) between the directions to b and c, radians. */
static double angle_at(double ax, double ay, double bx, double by, double cx,
                       double cy)
{
  double ux = bx - ax, uy = by - ay, vx = cx - ax, vy = cy - ay;
  return atan2(fabs(ux * vy - uy * vx), ux * vx + uy * vy);
}

/* Triangle (i, j, k) of the polygon in the ground frame. */
static double min_angle(const tt__dhole *h, int i, int j, int k)
{
  double a = angle_at(h->gx[i], h->gy[i], h->gx[j], h->gy[j], h->gx[k],
                      h->gy[k]);
  double b = angle_at(h->gx[j], h->gy[j], h->gx[k], h->gy[k], h->gx[i],
                      h->gy[i]);
  double c = 3.14159265358979323846 - a - b;
  return fmin(a, fmin(b, c));
}

static double max_angle(const tt__dhole *h, int i, int j, int k)
{
  double a = angle_at(h->gx[i], h->gy[i], h->gx[j], h->gy[j], h->gx[k],
                      h->gy[k]);
  double b = angle_at(h->gx[j], h->gy[j], h->gx[k], h->gy[k], h->gx[i],
                      h->gy[i]);
  double c = angle_at(h->gx[k], h->gy[k], h->gx[i], h->gy[i], h->gx[j],
                      h->gy[j]);
  return fmax(a, fmax(b, c));
}

/* The squared circumradius R^2 = a^2 b^2 c^2 / (4 area)^2 (no square
 * roots: it only ranks ears). */
static double circumradius2(const tt__dhole *h, int i, int j, int k)
{
  double ax = h->gx[j] - h->gx[i], ay = h->gy[j] - h->gy[i];
  double bx = h->gx[k] - h->gx[j], by = h->gy[k] - h->gy[j];
  double cx = h->gx[i] - h->gx[k], cy = h->gy[i] - h->gy[k];
  double cross = ax * (h->gy[k] - h->gy[i]) - ay * (h->gx[k] - h->gx[i]);
  double a2 = ax * ax + ay * ay, b2 = bx * bx + by * by,
         c2 = cx * cx + cy * cy;
  return cross != 0 ? a2 * b2 * c2 / (4 * cross * cross) : INFINITY;
}

/* The ground-frame orientation of polygon positions i, j, k, exactly:
 * the pixel-space determinant (differences below 2^29, products below
 * 2^58: int64 suffices for grid sides below 2^28) times the frame's
 * handedness s, the same sign tt__mesh_orient gives, from the hole's own
 * contiguous coordinates. */
static inline int orient3(const tt__dhole *h, int s, int i, int j, int k)
{
  int64_t det = (h->px[i] - h->px[k]) * (h->py[j] - h->py[k]) -
                (h->py[i] - h->py[k]) * (h->px[j] - h->px[k]);
  return det > 0 ? s : (det < 0 ? -s : 0);
}

/* The ear status and score of position i (larger score: cut first).
 * Only a vertex whose own corner does not turn strictly can lie in the
 * closed triangle of an ear candidate of a simple polygon (a strictly
 * convex one inside would put a reflex or straight one inside too, the
 * classic ear-clipping argument, which holds with straight corners counted
 * among the reflex ones), so only those are tested. */
static void examine(tt__dhole *h, int s, int i, tt_hole rule)
{
  int a = h->prev[i], c = h->next[i];
  h->ear[i] = false;
  if (!h->convex[i])
    return;
  for (int q = h->next[c]; q != a; q = h->next[q]) {
    if (h->convex[q])
      continue;
    if (orient3(h, s, a, i, q) >= 0 && orient3(h, s, i, c, q) >= 0 &&
        orient3(h, s, c, a, q) >= 0)
      return;
  }
  h->ear[i] = true;
  h->score[i] = rule == TT_HOLE_CIRCUMRADIUS ? -circumradius2(h, a, i, c)
                                             : min_angle(h, a, i, c);
}

static bool ear_cut(tt__dhole *h, const tt__mesh *m, tt_hole rule)
{
  int n = h->n, left = n;
  for (int i = 0; i < n; i++) {
    h->prev[i] = i == 0 ? n - 1 : i - 1;
    h->next[i] = i == n - 1 ? 0 : i + 1;
  }
  int s = m->metric.det_sign;
  for (int i = 0; i < n; i++)
    h->convex[i] = orient3(h, s, h->prev[i], i, h->next[i]) > 0;
  for (int i = 0; i < n; i++)
    examine(h, s, i, rule);
  h->ntri = 0;
  int first = 0; /* a position still in the polygon */
  while (left > 3) {
    int best = -1, i = first;
    do {
      if (h->ear[i] && (best < 0 || h->score[i] > h->score[best] ||
                        (h->score[i] == h->score[best] && i < best)))
        best = i;
      i = h->next[i];
    } while (i != first);
    if (best < 0)
      return false;
    int a = h->prev[best], c = h->next[best];
    h->tri[h->ntri][0] = h->p[a];
    h->tri[h->ntri][1] = h->p[best];
    h->tri[h->ntri][2] = h->p[c];
    h->ntri++;
    h->next[a] = c;
    h->prev[c] = a;
    left--;
    if (first == best)
      first = c;
    h->convex[a] = orient3(h, s, h->prev[a], a, c) > 0;
    h->convex[c] = orient3(h, s, a, c, h->next[c]) > 0;
    examine(h, s, a, rule);
    examine(h, s, c, rule);
  }
  int a = first, b = h->next[a], c = h->next[b];
  if (orient3(h, m->metric.det_sign, a, b, c) <= 0)
    return false;
  h->tri[h->ntri][0] = h->p[a];
  h->tri[h->ntri][1] = h->p[b];
  h->tri[h->ntri][2] = h->p[c];
  h->ntri++;
  return true;
}

typedef struct dp_arg {
  const tt__dhole *h;
  const tt__mesh *m;
  const double *frame;
  tt_criterion crit;
} dp_arg;

/* 3-D area of the triangle, heights from the mesh. */
static double area3(const dp_arg *d, int i, int j, int k)
{
  const tt__dhole *h = d->h;
  double z0 = tt__mesh_z(d->m, h->p[i]);
  double ux = h->gx[j] - h->gx[i], uy = h->gy[j] - h->gy[i];
  double uz = tt__mesh_z(d->m, h->p[j]) - z0;
  double vx = h->gx[k] - h->gx[i], vy = h->gy[k] - h->gy[i];
  double vz = tt__mesh_z(d->m, h->p[k]) - z0;
  double nx = uy * vz - uz * vy, ny = uz * vx - ux * vz,
         nz = ux * vy - uy * vx;
  return 0.5 * sqrt(nx * nx + ny * ny + nz * nz);
}

static double dp_measure(void *arg, int i, int j, int k)
{
  const dp_arg *d = arg;
  switch (d->crit) {
  case TT_CRITERION_DELAUNAY:
    return -min_angle(d->h, i, j, k); /* the largest smallest angle */
  case TT_CRITERION_MIN_AREA:
    return area3(d, i, j, k);
  default:
    return max_angle(d->h, i, j, k);
  }
}

bool tt__dhole_fill(tt__dhole *h, const tt__mesh *m, const double frame[4],
                    tt_hole rule, tt_criterion crit)
{
  int n = h->n;
  if (n < 3 || (size_t)n > h->cap)
    return false;
  int32_t c0 = m->v[h->p[0]].c, r0 = m->v[h->p[0]].r;
  /* on the ground points when the mesh has them (a geographic DEM) */
  const double *g0 = m->gxy ? m->gxy + 2 * ((size_t)r0 * m->gnx +
                                            (size_t)c0)
                            : NULL;
  for (int i = 0; i < n; i++) {
    const tt__mesh_vertex *q = &m->v[h->p[i]];
    double dc = (double)(q->c - c0), dr = (double)(q->r - r0);
    h->gx[i] = frame[0] * dc + frame[1] * dr;
    h->gy[i] = frame[2] * dc + frame[3] * dr;
    if (g0) {
      const double *g = m->gxy + 2 * ((size_t)q->r * m->gnx + (size_t)q->c);
      h->gx[i] = g[0] - g0[0];
      h->gy[i] = g[1] - g0[1];
    }
    h->px[i] = q->c;
    h->py[i] = q->r;
  }
  if (n == 3) {
    h->ntri = 0;
    if (tt__mesh_orient(m, h->p[0], h->p[1], h->p[2]) <= 0)
      return false;
    h->tri[0][0] = h->p[0];
    h->tri[0][1] = h->p[1];
    h->tri[0][2] = h->p[2];
    h->ntri = 1;
    return true;
  }
  if (rule != TT_HOLE_DP)
    return ear_cut(h, m, rule);
  if (n > TT__DP_MAX_N)
    return ear_cut(h, m, TT_HOLE_MINANGLE);
  dp_arg d = {h, m, frame, crit};
  if (!tt__polygon_dp(n, h->px, h->py, m->metric.det_sign,
                      crit == TT_CRITERION_MIN_AREA ? TT__DP_SUM : TT__DP_MAX,
                      dp_measure, &d, h->idx, NULL))
    return false;
  for (int t = 0; t < n - 2; t++)
    for (int k = 0; k < 3; k++)
      h->tri[t][k] = h->p[h->idx[3 * t + k]];
  h->ntri = n - 2;
  return true;
}
