/*
 * importance.c -- what removing one vertex would do (SPEC section 3.6's
 * importance measures), computed on the hole the removal would really
 * leave: the star's link, re-triangulated by the run's hole rule, so that
 * the importance, the error check and the removal agree.
 *
 *   degree  the number of neighbours;
 *   hdh     |sum over neighbours of (z(v) - z(v_i))|;
 *   abh     |neighbours below v - neighbours above v|: a peak and a pit
 *           are equally important (the signed count would delete pits
 *           first and keep every peak);
 *   volume  |volume under the star - volume under the filled hole|, in
 *           ground units^3: the integral of the height change over the
 *           hole (each triangle's prism is its ground area times its mean
 *           height);
 *   drop    |z(v) - the filled hole's height at v| (Locate of section
 *           3.5: the new triangle holding v, closed, by exact tests);
 *   error   the largest |H - H'| over the valid samples under the filled
 *           hole, samples of vertices removed earlier included (each new
 *           triangle scanned closed, with the tile bounds).
 *
 * The boundary rule: an interior vertex may always go; a vertex on the
 * boundary only when its two boundary neighbours and it are collinear with
 * it between them (a straight run of the grid border or of the nodata
 * outline: the outline stays where it is); corners and pinned vertices
 * never. Workload: one call per vertex and round (independent sets) or
 * per changed star (sequential); error dominates, a scan of the star's
 * samples.
 *
 * Part of src/decimate/, the vertex decimation method (tt_decimate_run).
 */
#include "decimate/decimate.h"

#include "base/predicates.h"

#include <math.h>
#include <stdlib.h>

/* Small triangles (most fills): the bounding box's samples one by one,
 * each tested against the three closed edges exactly in integers, the
 * plane evaluated as the scans do (rowbase + gx (x - x0)). Cheaper than
 * the scan's row set-up for a handful of samples; same samples. */
#define SMALL_BOX 192

static double small_error(const tt__dec *d, const tt__scan_tri *st)
{
  int64_t x0, x1, y0, y1;
  tt__scan_tri_bbox(st, &x0, &x1, &y0, &y1);
  tt__scan_plane p;
  tt__scan_plane_of(st, &p);
  /* orientation of the corners in pixel space: inside means every edge
   * function has that sign or is zero */
  int64_t o = (st->x[1] - st->x[0]) * (st->y[2] - st->y[0]) -
              (st->y[1] - st->y[0]) * (st->x[2] - st->x[0]);
  int s = o > 0 ? 1 : -1;
  const size_t nx = d->g->nx;
  double err = 0;
  const tt_grid *g = d->g;
  for (int64_t y = y0; y <= y1; y++) {
    size_t row = (size_t)y * nx;
    double rowbase = p.z0 + p.gy * (double)(y - p.y0);
    for (int64_t x = x0; x <= x1; x++) {
      bool in = true;
      for (int k = 0; k < 3 && in; k++) {
        int k1 = k == 2 ? 0 : k + 1;
        int64_t e = (st->x[k1] - st->x[k]) * (y - st->y[k]) -
                    (st->y[k1] - st->y[k]) * (x - st->x[k]);
        in = s * e >= 0;
      }
      if (!in)
        continue;
      double v = rowbase + p.gx * (double)(x - p.x0);
      double e = fabs(tt__grid_z(g, row + (size_t)x) - v);
      if (e > err) /* false for NaN (nodata) */
        err = e;
    }
  }
  return err;
}

double tt__dec_triangle_error(const tt__dec *d, int32_t a, int32_t b,
                              int32_t c)
{
  const tt__mesh *m = &d->m;
  tt__scan_tri st;
  int32_t w[3] = {a, b, c};
  for (int k = 0; k < 3; k++) {
    st.x[k] = m->v[w[k]].c;
    st.y[k] = m->v[w[k]].r;
    st.z[k] = tt__mesh_z(m, w[k]);
    st.own[k] = true;
  }
  int64_t bx0, bx1, by0, by1;
  tt__scan_tri_bbox(&st, &bx0, &bx1, &by0, &by1);
  if ((bx1 - bx0 + 1) * (by1 - by0 + 1) <= SMALL_BOX)
    return small_error(d, &st);
  double err = 0;
  int64_t idx = -1;
  tt__scan_candidate_rows(d->g, d->tiles.t ? &d->tiles : NULL, &st,
                          INT64_MIN, INT64_MAX, &err, &idx);
  return idx < 0 ? 0.0 : err;
}

/* Ground area of triangle (a, b, c) times its mean height. */
static double prism(const tt__dec *d, int32_t a, int32_t b, int32_t c)
{
  const tt__mesh *m = &d->m;
  const double *f = d->g->frame;
  double dc1 = m->v[b].c - m->v[a].c, dr1 = m->v[b].r - m->v[a].r;
  double dc2 = m->v[c].c - m->v[a].c, dr2 = m->v[c].r - m->v[a].r;
  double det = fabs(f[0] * f[3] - f[1] * f[2]);
  double area = 0.5 * fabs(dc1 * dr2 - dc2 * dr1) * det;
  return area * (tt__mesh_z(m, a) + tt__mesh_z(m, b) + tt__mesh_z(m, c)) /
         3.0;
}

/* Height of the filled hole at v's position (v lies in or on one of its
 * triangles: the star covers v). */
static double hole_height_at(const tt__dec *d, const tt__dhole *h,
                             int32_t v)
{
  const tt__mesh *m = &d->m;
  for (int t = 0; t < h->ntri; t++) {
    const int32_t *q = h->tri[t];
    if (tt__mesh_orient(m, q[0], q[1], v) >= 0 &&
        tt__mesh_orient(m, q[1], q[2], v) >= 0 &&
        tt__mesh_orient(m, q[2], q[0], v) >= 0) {
      tt__scan_tri st;
      for (int k = 0; k < 3; k++) {
        st.x[k] = m->v[q[k]].c;
        st.y[k] = m->v[q[k]].r;
        st.z[k] = tt__mesh_z(m, q[k]);
      }
      tt__scan_plane p;
      tt__scan_plane_of(&st, &p);
      return p.z0 + p.gx * (double)(m->v[v].c - p.x0) +
             p.gy * (double)(m->v[v].r - p.y0);
    }
  }
  return tt__mesh_z(m, v); /* not reached for a valid fill */
}

/* The largest error over the filled hole's triangles. */
static double fill_error(const tt__dec *d, const tt__dhole *h)
{
  double err = 0;
  for (int t = 0; t < h->ntri; t++)
    err = fmax(err, tt__dec_triangle_error(d, h->tri[t][0], h->tri[t][1],
                                           h->tri[t][2]));
  return err;
}

int tt__dec_evaluate(tt__dec *d, int32_t v, tt__dec_eval what,
                     double *out_importance, double *out_error)
{
  return tt__dec_evaluate_in(d, &d->h, v, what, out_importance, out_error);
}

int tt__dec_evaluate_in(const tt__dec *d, tt__dhole *h, int32_t v,
                        tt__dec_eval what, double *out_importance,
                        double *out_error)
{
  const tt__mesh *m = &d->m;
  *out_importance = NAN;
  if (out_error)
    *out_error = NAN;
  if (m->v[v].edge < 0 || (d->vflag[v] & TT__DV_PINNED))
    return 0;
  bool closed;
  int n = tt__mesh_star(m, v, h->p, NULL, (int)h->cap, &closed);
  if (n > (int)h->cap) {
    if (!tt__dhole_reserve(h, n))
      return -1;
    (void)tt__mesh_star(m, v, h->p, NULL, n, &closed);
  }
  if (n < 3)
    return 0;
  h->n = n;
  if (!closed) {
    /* the boundary rule: prev -> v -> next straight, v between */
    int32_t a = h->p[n - 1], b = h->p[0];
    if (tt__mesh_orient(m, a, v, b) != 0)
      return 0;
    int64_t ux = m->v[a].c - m->v[v].c, uy = m->v[a].r - m->v[v].r;
    int64_t wx = m->v[b].c - m->v[v].c, wy = m->v[b].r - m->v[v].r;
    if (ux * wx + uy * wy >= 0)
      return 0;
  }
  bool score = what == TT__DEC_SCORE;
  bool topological = d->importance == TT_IMPORTANCE_DEGREE ||
                     d->importance == TT_IMPORTANCE_HDH ||
                     d->importance == TT_IMPORTANCE_ABH;
  if ((!score || !topological) &&
      !tt__dhole_fill(h, m, d->g->frame, d->hole, d->opt->criterion))
    return 0;
  if (what == TT__DEC_CHECK) {
    double err = fill_error(d, h);
    if (out_error)
      *out_error = err;
    if (d->importance == TT_IMPORTANCE_ERROR)
      *out_importance = err;
    return 1;
  }
  if (!score)
    return 1;
  double zv = tt__mesh_z(m, v), imp = 0;
  switch (d->importance) {
  case TT_IMPORTANCE_DEGREE:
    imp = n;
    break;
  case TT_IMPORTANCE_HDH: {
    double s = 0;
    for (int i = 0; i < n; i++)
      s += zv - tt__mesh_z(m, h->p[i]);
    imp = fabs(s);
    break;
  }
  case TT_IMPORTANCE_ABH: {
    int below = 0, above = 0;
    for (int i = 0; i < n; i++) {
      double z = tt__mesh_z(m, h->p[i]);
      below += z < zv;
      above += z > zv;
    }
    imp = abs(below - above);
    break;
  }
  case TT_IMPORTANCE_VOLUME: {
    double before = 0, after = 0;
    int nstar = closed ? n : n - 1;
    for (int i = 0; i < nstar; i++)
      before += prism(d, v, h->p[i], h->p[(i + 1) % n]);
    for (int t = 0; t < h->ntri; t++)
      after += prism(d, h->tri[t][0], h->tri[t][1], h->tri[t][2]);
    imp = fabs(before - after);
    break;
  }
  case TT_IMPORTANCE_DROP:
    imp = fabs(zv - hole_height_at(d, h, v));
    break;
  default: /* error */
    imp = fill_error(d, h);
    if (out_error)
      *out_error = imp;
    break;
  }
  *out_importance = imp;
  return 1;
}
