/*
 * geometry.h -- ground-frame geometry shared by the criteria: points,
 * vectors, normals, angles, and the quadrilateral of an edge.
 *
 * Everything is measured on the ground: a vertex at pixel (c, r) with
 * height z sits at (a0 c + a1 r, a2 c + a3 r, z), a = grid->frame, or at
 * its ground point (x, y, z) when the mesh has them (mesh.h) (or, when
 * the environment has no grid, a frame with the same metric and
 * orientation, from mesh->metric). Points are taken relative to one vertex
 * of the neighbourhood (integer pixel differences are exact), so
 * coordinates stay small whatever the georeferencing.
 *
 * Angles come from atan2(|u x v|, u . v), accurate near 0 and pi and
 * defined for every input: a zero vector gives 0, never NaN. The normal of
 * a zero-area triangle is the zero vector, and the angle between a zero
 * normal and any other is 0 (atan2(0, 0) = 0): a degenerate triangle bends
 * nothing. The mesh holds no such triangle; they can only be met as
 * hypothetical triangles of a quad that is not strictly convex, and those
 * quads are answered before any geometry (tt__quad_load).
 *
 * All static inline: each criterion's hot path compiles to straight-line
 * arithmetic with no call and no allocation.
 *
 * Part of src/criteria/, the criteria: one file per triangulation criterion
 * behind one vtable.
 */
#ifndef TT_CRITERIA_GEOMETRY_H
#define TT_CRITERIA_GEOMETRY_H

#include "criteria/criterion.h"

#include <math.h>

#define TT__PI 3.14159265358979323846

typedef struct tt__gvec {
  double x, y, z;
} tt__gvec;

/* The ground frame of an environment. Without a grid, the upper-triangular
 * factor of the mesh's metric tensor (same lengths and angles as the true
 * frame; orientation from det_sign). */
static inline void tt__geo_frame(const tt__crit_env *env, double out_a[4])
{
  if (env->grid) {
    for (int k = 0; k < 4; k++)
      out_a[k] = env->grid->frame[k];
    return;
  }
  const tt__metric *mt = &env->mesh->metric;
  double s11 = sqrt(mt->m11);
  double s12 = s11 > 0 ? mt->m12 / s11 : 0;
  double q = mt->m22 - s12 * s12;
  double s22 = q > 0 ? sqrt(q) : 0;
  out_a[0] = s11;
  out_a[1] = s12;
  out_a[2] = 0;
  out_a[3] = mt->det_sign * s22;
}

/* Ground vector from vertex `from` to vertex `to`. */
static inline tt__gvec tt__geo_vec(const double a[4], const tt__mesh *m,
                                   int32_t from, int32_t to)
{
  if (m->gxy) {
    /* ground points: the conformal projection's own coordinates (angles
     * true, lengths times the local scale factor, within 1e-3 of 1 for
     * the frames georef_conformal.c picks over a zone) */
    const double *p = m->gxy + 2 * ((size_t)m->v[from].r * m->gnx +
                                    (size_t)m->v[from].c);
    const double *q = m->gxy + 2 * ((size_t)m->v[to].r * m->gnx +
                                    (size_t)m->v[to].c);
    tt__gvec g = {q[0] - p[0], q[1] - p[1],
                  tt__mesh_z(m, to) - tt__mesh_z(m, from)};
    return g;
  }
  double dc = (double)((int64_t)m->v[to].c - m->v[from].c);
  double dr = (double)((int64_t)m->v[to].r - m->v[from].r);
  tt__gvec g = {a[0] * dc + a[1] * dr, a[2] * dc + a[3] * dr,
                tt__mesh_z(m, to) - tt__mesh_z(m, from)};
  return g;
}

static inline tt__gvec tt__gsub(tt__gvec p, tt__gvec q)
{
  tt__gvec g = {p.x - q.x, p.y - q.y, p.z - q.z};
  return g;
}

static inline tt__gvec tt__gcross(tt__gvec u, tt__gvec v)
{
  tt__gvec g = {u.y * v.z - u.z * v.y, u.z * v.x - u.x * v.z,
                u.x * v.y - u.y * v.x};
  return g;
}

static inline double tt__gdot(tt__gvec u, tt__gvec v)
{
  return u.x * v.x + u.y * v.y + u.z * v.z;
}

static inline double tt__glen(tt__gvec u) { return sqrt(tt__gdot(u, u)); }

/* The 3-D angle between u and v, in [0, pi]; 0 when either is zero. */
static inline double tt__gangle(tt__gvec u, tt__gvec v)
{
  return atan2(tt__glen(tt__gcross(u, v)), tt__gdot(u, v));
}

/* The 2-D (map) angle between u and v, heights ignored, in [0, pi]. */
static inline double tt__gangle2(tt__gvec u, tt__gvec v)
{
  return atan2(fabs(u.x * v.y - u.y * v.x), u.x * v.x + u.y * v.y);
}

/* Normal of triangle (p, q, r) given as points: (q - p) x (r - p), not
 * normalised (its length is twice the 3-D area); counter-clockwise
 * triangles have normals pointing up. */
static inline tt__gvec tt__gnormal(tt__gvec p, tt__gvec q, tt__gvec r)
{
  return tt__gcross(tt__gsub(q, p), tt__gsub(r, p));
}

/* 3-D area of triangle (p, q, r). */
static inline double tt__garea(tt__gvec p, tt__gvec q, tt__gvec r)
{
  return 0.5 * tt__glen(tt__gnormal(p, q, r));
}

/* The quadrilateral of an edge, in a canonical form. Its corners in
 * counter-clockwise order are w0, w1, w2, w3, w0 the one of smallest
 * index; the quad is then described as if its diagonal were w0-w2:
 * a = w0, d = w1, b = w2, c = w3, so that
 *
 *          c                       c
 *         / \                     /|\
 *        /   \                   / | \
 *       a-----b     swapped:    a  |  b
 *        \   /                   \ | /
 *         \ /                     \|/
 *          d                       d
 *
 * "before" is (a, b, c) and (b, a, d), "after" is (c, a, d) and (d, b, c),
 * and sign is +1 when the mesh's diagonal is a-b, -1 when it is c-d. Every
 * criterion computes Quality(before) - Quality(after) from this form and
 * multiplies by sign: an edge and the edge that replaces it after a swap
 * see the same quad the same way, so their swap values are exact
 * negatives of each other, bit for bit, and an optimiser can never undo a
 * swap on rounding. The outer edges are b-c, c-a, a-d, d-b; in[k] is the
 * half-edge of outer edge k inside the quad (b->c, c->a, a->d, d->b) and
 * out[k] its twin across, or -1 on the boundary. Points are ground
 * coordinates relative to a. */
typedef struct tt__quad {
  int32_t a, b, c, d;
  double sign;              /* +1: the mesh has a-b, -1: it has c-d */
  int32_t in[4];            /* b->c, c->a, a->d, d->b inside the quad */
  int32_t out[4];           /* their twins, or -1 */
  tt__gvec pa, pb, pc, pd;  /* ground points, pa = 0 */
} tt__quad;

/* Loads e's quad; false when it is not strictly convex in the ground
 * frame (exact test): such an edge cannot be swapped, and every criterion
 * answers 0 for it (no change), which keeps hypothetical triangles from
 * ever being degenerate or inverted. The caller guarantees e has a twin. */
static inline bool tt__quad_load(const tt__crit_env *env, int32_t e,
                                 const double fr[4], tt__quad *q)
{
  const tt__mesh *m = env->mesh;
  int32_t f = m->twin[e];
  int32_t va = m->hv[e], vb = m->hv[f];
  int32_t vc = m->hv[tt__prev(e)], vd = m->hv[tt__prev(f)];
  if (tt__mesh_orient(m, vc, vd, vb) <= 0 ||
      tt__mesh_orient(m, vd, vc, va) <= 0)
    return false;
  /* counter-clockwise corners and the side half-edges leaving them:
   * a->d, d->b, b->c, c->a */
  int32_t w[4] = {va, vd, vb, vc};
  int32_t side[4] = {tt__next(f), tt__prev(f), tt__next(e), tt__prev(e)};
  int r = 0;
  for (int k = 1; k < 4; k++)
    if (w[k] < w[r])
      r = k;
  q->a = w[r];
  q->d = w[(r + 1) & 3];
  q->b = w[(r + 2) & 3];
  q->c = w[(r + 3) & 3];
  q->sign = (r & 1) ? -1.0 : 1.0; /* the mesh's diagonal is w0-w2 iff r
                                     is even */
  q->in[0] = side[(r + 2) & 3];   /* b->c */
  q->in[1] = side[(r + 3) & 3];   /* c->a */
  q->in[2] = side[r];             /* a->d */
  q->in[3] = side[(r + 1) & 3];   /* d->b */
  for (int k = 0; k < 4; k++)
    q->out[k] = m->twin[q->in[k]];
  tt__gvec zero = {0, 0, 0};
  q->pa = zero;
  q->pb = tt__geo_vec(fr, m, q->a, q->b);
  q->pc = tt__geo_vec(fr, m, q->a, q->c);
  q->pd = tt__geo_vec(fr, m, q->a, q->d);
  return true;
}

/* The ground point (relative to the quad's a) of the vertex across outer
 * half-edge out (the apex of the neighbouring triangle). */
static inline tt__gvec tt__quad_outer_apex(const tt__crit_env *env,
                                           const double fr[4],
                                           const tt__quad *q, int32_t out)
{
  return tt__geo_vec(fr, env->mesh, q->a, tt__mesh_apex(env->mesh, out));
}

/* The angles between the unit normals (alpha, SPEC section 2.4) of the
 * five edges of e's quad, before and after the swap: index 0 is the
 * diagonal (a-b before, c-d after), 1..4 the outer edges b-c, c-a, a-d,
 * d-b against the triangles across them (0 on the boundary). len[] holds
 * the 3-D lengths of the before edges (len[0] = |ab|), len_cd that of the
 * new diagonal. Both triangles' normals are counter-clockwise, so alpha is
 * the dihedral bend: 0 for coplanar triangles, near pi for a fold. */
static inline void tt__quad_alphas(const tt__crit_env *env,
                                   const double fr[4], const tt__quad *q,
                                   double before[5], double after[5],
                                   double len[5], double *len_cd)
{
  tt__gvec n_abc = tt__gnormal(q->pa, q->pb, q->pc);
  tt__gvec n_bad = tt__gnormal(q->pb, q->pa, q->pd);
  tt__gvec n_cad = tt__gnormal(q->pc, q->pa, q->pd);
  tt__gvec n_dbc = tt__gnormal(q->pd, q->pb, q->pc);
  before[0] = tt__gangle(n_abc, n_bad);
  after[0] = tt__gangle(n_cad, n_dbc);
  len[0] = tt__glen(q->pb);
  *len_cd = tt__glen(tt__gsub(q->pd, q->pc));
  /* outer edge k: its end points (as ground points), the inner normal
   * before and after */
  const tt__gvec *from[4] = {&q->pb, &q->pc, &q->pa, &q->pd};
  const tt__gvec *to[4] = {&q->pc, &q->pa, &q->pd, &q->pb};
  const tt__gvec *nb[4] = {&n_abc, &n_abc, &n_bad, &n_bad};
  const tt__gvec *na[4] = {&n_dbc, &n_cad, &n_cad, &n_dbc};
  for (int k = 0; k < 4; k++) {
    len[k + 1] = tt__glen(tt__gsub(*to[k], *from[k]));
    if (q->out[k] < 0) {
      before[k + 1] = after[k + 1] = 0.0;
      continue;
    }
    /* the outer triangle runs to -> from -> apex */
    tt__gvec o = tt__quad_outer_apex(env, fr, q, q->out[k]);
    tt__gvec n_out = tt__gnormal(*to[k], *from[k], o);
    before[k + 1] = tt__gangle(*nb[k], n_out);
    after[k + 1] = tt__gangle(*na[k], n_out);
  }
}

/* Snaps a difference of two nearly equal sums to 0: |diff| <= 1e-12 *
 * scale is rounding noise (scale: the sum of the magnitudes of the terms).
 * Without it, an optimiser would "improve" a flat region forever on noise. */
static inline double tt__snap(double diff, double scale)
{
  return fabs(diff) <= 1e-12 * scale ? 0.0 : diff;
}

/* Sorts n values (n small) in decreasing order. */
static inline void tt__sort_desc(double *x, int n)
{
  for (int i = 1; i < n; i++) {
    double v = x[i];
    int j = i;
    for (; j > 0 && x[j - 1] < v; j--)
      x[j] = x[j - 1];
    x[j] = v;
  }
}

/* Lexicographic comparison of two decreasing vectors of angles (radians):
 * the first difference larger than 1e-12, before - after, or 0. Positive:
 * `after` is lexicographically smaller (better). */
static inline double tt__lex_diff(const double *before, const double *after,
                                  int n)
{
  for (int i = 0; i < n; i++) {
    double d = before[i] - after[i];
    if (fabs(d) > 1e-12)
      return d;
  }
  return 0.0;
}

/* Vertex classes of the Gaussian-curvature criterion (SPEC section 2.5). */
enum {
  TT__VERTEX_CONVEX = 0,
  TT__VERTEX_SADDLE = 1,
  TT__VERTEX_MIXED = 2,
  TT__VERTEX_BOUNDARY = 3
};

/* |K(v)| of vertex v in the mesh as it is, and its class in *out_class
 * (may be NULL); gaussian.c. For tests and diagnostics. */
TT_HIDDEN double tt__gaussian_vertex(const tt__crit_env *env, int32_t v,
                                     int *out_class);

/* The exact sign of (e0 x e1) . e2 for rays e_i = (dc_i, dr_i, z_i - zv)
 * in pixel space (|dc|, |dr| < 2^28), as the Gaussian criterion's
 * supporting-plane tests take it (gaussian.c). For tests. */
TT_HIDDEN int tt__gaussian_orient(const int64_t dc[3], const int64_t dr[3],
                                  const double z[3], double zv);

/* The criteria defined beside Delaunay, one file each (registry.c lists
 * them). */
TT_HIDDEN extern const tt__criterion_vt tt__criterion_minmax_angle;
TT_HIDDEN extern const tt__criterion_vt tt__criterion_minmax_angle_lex;
TT_HIDDEN extern const tt__criterion_vt tt__criterion_min_area;
TT_HIDDEN extern const tt__criterion_vt tt__criterion_mean_curvature;
TT_HIDDEN extern const tt__criterion_vt tt__criterion_gaussian;
TT_HIDDEN extern const tt__criterion_vt tt__criterion_abn;
TT_HIDDEN extern const tt__criterion_vt tt__criterion_abn_sum;
TT_HIDDEN extern const tt__criterion_vt tt__criterion_abn_sumsq;
TT_HIDDEN extern const tt__criterion_vt tt__criterion_l2;

/* The affected-edges hook of the criteria whose swap value reads the
 * normals of the triangles across the quad's outer edges (mean curvature,
 * ABN): the new diagonal h, the 4 quad edges and the other edges of the
 * triangles across them, one half-edge per edge (mean_curvature.c);
 * returns how many it wrote, at most max (13 suffice). */
TT_HIDDEN int tt__affected_quad_ring(const tt__crit_env *env, int32_t h,
                                     int32_t *out, int max);

#endif /* TT_CRITERIA_GEOMETRY_H */
