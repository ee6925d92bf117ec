/*
 * gaussian.c -- the Gaussian curvature criterion (tight triangulation),
 * SPEC section 2.5.
 *
 * Definition: minimise the sum over vertices of |K(v)|, the absolute
 * integral Gaussian curvature of the TIN as a surface in ground units.
 * With theta_i the 3-D angles at v between consecutive edges of its star:
 *  - a boundary vertex has |K| = |pi - sum theta_i|;
 *  - an interior vertex is classified by supporting planes: consecutive
 *    edges e_i, e_{i+1} span one when every other edge e_k lies on one
 *    side of it, (e_i x e_{i+1}) . e_k >= 0 for all k or <= 0 for all k
 *    (the SPEC writes the first, for a surface oriented outwards; a
 *    terrain has no inside, so a peak and a pit are both convex), a tie
 *    counting as supporting. Convex: every consecutive pair supports,
 *    |K| = 2 pi - sum theta. Saddle: none does, |K| = sum theta - 2 pi.
 *    Mixed: otherwise; |K| = 2 pi - 2 sum theta+_j + sum theta_i, theta+
 *    the angles of the convex hull cone of the star's rays.
 * Robustness: the signs of the triple products are exact. A triple product
 * in the ground frame is det(frame) times the same product in pixel space
 * (column, row, height), whose 2x2 minors are exact integers; it is
 * evaluated in doubles with Shewchuk's orient3d error bound (loosened to
 * one bound per pair of rays, see pair_make) and, when the bound does not
 * decide (slivers, coplanar rays), exactly, as a sum of exactly
 * representable products (a height, or each 26-bit half of a double
 * height, times a 21-bit slice of a minor: twelve for float heights, up
 * to twenty-four for doubles) added by expansion arithmetic. With integer
 * heights (most DEMs) within 2^16
 * of each other the double products are exact and the bound is 0: no
 * exact sums at all. The common factor det(frame) does not change which
 * side the rays are on, so it is never needed.
 * Ground points (a geographic DEM, mesh.h): the map from pixels to the
 * ground is no longer affine, so the rays are taken on the ground points
 * themselves -- x, y the differences of the projected coordinates (as
 * tt__geo_vec rounds them), z the height difference -- for the angles and
 * the signs alike; a sign the bound does not decide is then the exact sign
 * of the determinant of those rounded rays (exact_sign_ground: 24 exact
 * partial products summed by expansion arithmetic), and the plan turns of
 * the hull's proof are tt__orient2d on them. Every decision is then the
 * ground's, as the other criteria's are.
 * Classification in O(d) (star_curvature): with t_i the exact sign of
 * (e_i x e_{i+1}) . e_{i+2}, the star is convex iff all t_i >= 0 or all
 * <= 0; only pairs whose t_{i-1}, t_i agree can support, so only those
 * are tested against every ray, in index order up to the first that does
 * (none: a saddle). The hull cone of a mixed star: Graham's scan from that
 * pair in the star's cyclic order with an O(d) proof of its result, else
 * gift wrapping (hull_wrap). Classes, hull rays and so the bits of |K| are
 * those of testing every pair against every ray and gift wrapping
 * (tests/criteria/test_gaussian_speed.c checks it against that reference).
 * Swap value: sum |K| over the quad's four vertices before minus after
 * (the stars of those four change: a and b lose the diagonal, c and d gain
 * the new one); positive when the swap lowers the sum. Differences below
 * 1e-12 of the total read 0. Needs: the stars of the quad's four vertices
 * (heights included), so the affected hook returns every edge of every
 * triangle incident to a quad vertex. Quads that are not strictly convex
 * score 0 (geometry.h), so every star met is a proper fan. Quad and stars
 * are read in a canonical order (geometry.h; interior stars start at
 * their smallest neighbour), so a swap and the swap back have exactly
 * opposite values. A vertex of degree above TT__STAR_MAX (before or after)
 * counts 0 on both sides.
 *
 * Cache (cache_new, below): |K| of a star depends on its canonical
 * neighbour list only, so values are kept per vertex under that whole list
 * (the key proves the star, it is no hash) for the star in the mesh and
 * the last edited one; a cached and an uncached value are the same bits.
 * Its only allocation is its growth with the mesh.
 *
 * Cost: per star d square roots, one atan2 (angle sums as arguments of
 * complex products, below), d triple products for the t_i, d - 2 more per
 * candidate pair tested, about 3d for a mixed star's hull (and a second
 * atan2); eight stars per swap value, of which the star in the mesh mostly
 * comes from the cache and the four of the other configuration never do
 * (they only come back when the swap is taken). Those four stars are the
 * bulk of the criterion's cost; docs/criteria.md gives the measurements and
 * what a cheaper design would need.
 *
 * Part of src/criteria/, the criteria: one file per triangulation criterion
 * behind one vtable.
 */
#include "criteria/geometry.h"

#include "base/predicates.h"

#include <stdlib.h>
#include <string.h>

#define TT__STAR_MAX 256

/* A star: the neighbours of v in counter-clockwise (ground) order. */
typedef struct star {
  int32_t nb[TT__STAR_MAX + 1];
  int n;
  bool boundary;
} star;

/* Gathers v's star from the mesh; false when the degree exceeds the cap or
 * v is in no triangle. An interior star is read in one counter-clockwise
 * walk from v's edge; only when that walk meets the boundary is the star
 * read again from its clockwise end (boundary vertices are few). */
static bool star_gather(const tt__mesh *m, int32_t v, star *s)
{
  int32_t h0 = m->v[v].edge;
  s->n = 0;
  s->boundary = false;
  if (h0 < 0)
    return false;
  int32_t h = h0;
  for (;;) {
    if (s->n >= TT__STAR_MAX)
      return false;
    s->nb[s->n++] = m->hv[tt__next(h)];
    int32_t t = m->twin[tt__prev(h)];
    if (t < 0)
      break;
    h = t;
    if (h == h0)
      return true;
  }
  /* a boundary star: walk clockwise to the boundary, cw(h) =
   * next(twin[h]), then read it counter-clockwise from there */
  s->n = 0;
  s->boundary = true;
  h = h0;
  for (int32_t t; (t = m->twin[h]) >= 0;)
    h = tt__next(t);
  for (;;) {
    if (s->n >= TT__STAR_MAX)
      return false;
    s->nb[s->n++] = m->hv[tt__next(h)];
    int32_t p = tt__prev(h);
    int32_t t = m->twin[p];
    if (t < 0) {
      if (s->n >= TT__STAR_MAX)
        return false;
      s->nb[s->n++] = m->hv[p];
      return true;
    }
    h = t;
  }
}

/* Rotates an interior star to start at its smallest neighbour index, so
 * that a star reached from either configuration of a quad is the same
 * array and gives the same bits. (A boundary star starts at the boundary
 * either way.) */
static void star_canon(star *s)
{
  if (s->boundary || s->n < 2)
    return;
  int r = 0;
  for (int i = 1; i < s->n; i++)
    if (s->nb[i] < s->nb[r])
      r = i;
  if (r == 0)
    return;
  int32_t head[TT__STAR_MAX + 1];
  memcpy(head, s->nb, (size_t)r * sizeof head[0]);
  memmove(s->nb, s->nb + r, (size_t)(s->n - r) * sizeof head[0]);
  memcpy(s->nb + s->n - r, head, (size_t)r * sizeof head[0]);
}

/* o = canonical star s without neighbour x (its first occurrence). The
 * smallest neighbour stays in front unless it is x, so only then does the
 * result need star_canon. */
static void star_without(const star *s, int32_t x, star *o)
{
  int n = 0;
  bool seen = false;
  for (int i = 0; i < s->n; i++) {
    if (!seen && s->nb[i] == x) {
      seen = true;
      continue;
    }
    o->nb[n++] = s->nb[i];
  }
  o->n = n;
  o->boundary = s->boundary;
  if (s->n > 0 && s->nb[0] == x)
    star_canon(o);
}

/* o = canonical star s with y inserted after neighbour x (its first
 * occurrence); false when x is not there or the star is full. Canonical
 * as it is unless y is the new smallest. */
static bool star_with(const star *s, int32_t x, int32_t y, star *o)
{
  if (s->n >= TT__STAR_MAX)
    return false;
  int i = 0;
  while (i < s->n && s->nb[i] != x)
    i++;
  if (i == s->n)
    return false;
  memcpy(o->nb, s->nb, (size_t)(i + 1) * sizeof o->nb[0]);
  o->nb[i + 1] = y;
  memcpy(o->nb + i + 2, s->nb + i + 1,
         (size_t)(s->n - i - 1) * sizeof o->nb[0]);
  o->n = s->n + 1;
  o->boundary = s->boundary;
  if (y < s->nb[0])
    star_canon(o);
  return true;
}

/* --- exact sign of a triple product in pixel space -------------------- */

/* x mod n for 0 <= x < 2n, without a division */
static inline int wrap(int x, int n) { return x >= n ? x - n : x; }

/* A pair's cross product and its error bound. */
typedef struct pair {
  double nx, ny, nz, bound;
} pair;

/* The rays of a star as arrays, each stored twice over (x[n + k] = x[k]),
 * so that loops over consecutive rays run without wrapping: in pixel space
 * (exact column and row steps, z_k - z_v rounded) for the signs, on the
 * ground for the angles, and the exact inputs of exact_sign. */
#define TT__RAYS (2 * TT__STAR_MAX + 2)
typedef struct rays {
  double x[TT__RAYS], y[TT__RAYS], z[TT__RAYS]; /* pixel space */
  double gx[TT__RAYS], gy[TT__RAYS];            /* ground (its z is z[]) */
  double nx[TT__STAR_MAX + 1], ny[TT__STAR_MAX + 1], nz[TT__STAR_MAX + 1],
      nb[TT__STAR_MAX + 1];             /* pair (i, i+1): e_i x e_i+1 and
                                           its bound (pair_make) */
  double c[TT__STAR_MAX + 1], d[TT__STAR_MAX + 1]; /* |g_i x g_i+1|,
                                                      g_i . g_i+1 */
  int64_t dc[TT__STAR_MAX + 1], dr[TT__STAR_MAX + 1];
  double zk[TT__STAR_MAX + 1];         /* heights as the mesh has them */
  double zv;
  double maxc;                          /* largest |x|, |y|, |z| */
  bool ints;                            /* x, y, z are integers of at most
                                           2^16: every triple product is
                                           exact in doubles (below) */
  bool ground;                          /* x, y are ground-point
                                           differences (then x == gx, y ==
                                           gy), not pixel steps */
  signed char t[TT__STAR_MAX + 1];      /* sign of (e_i x e_i+1) . e_i+2 */
  int hull[TT__STAR_MAX + 1];           /* the hull rays of a mixed star */
  pair top[TT__STAR_MAX + 1];           /* their faces (hull_graham) */
} rays;

static inline void two_sum(double a, double b, double *x, double *y)
{
  double s = a + b;
  double bv = s - a;
  double av = s - bv;
  *x = s;
  *y = (a - av) + (b - bv);
}

/* Adds the exact products z * s * 2^(21 k) of the 21-bit slices s of
 * |m| (|m| < 2^63), z of at most 32 significant bits, to expansion h. */
static int add_slices(double *h, int len, double z, uint64_t u)
{
  const double scale[3] = {1.0, 2097152.0, 4398046511104.0}; /* 2^0,21,42 */
  for (int k = 0; k < 3; k++) {
    double b = z * (double)((u >> (21 * k)) & 0x1fffffu) * scale[k];
    for (int i = 0; i < len; i++)
      two_sum(b, h[i], &b, &h[i]);
    h[len++] = b;
  }
  return len;
}

/* Adds the exact product sign * z * |m| (|m| < 2^63) to expansion h. A
 * height of a grid of floats has 24 significant bits, so z times a slice
 * is exact; a double is first split into two halves of at most 26 bits
 * (Veltkamp: hi + lo == z exactly, for |z| between 2^-969 and 2^996,
 * which TT_MAX_HEIGHT bounds from above), each times a slice exact. A
 * float's lo is 0 and adds nothing. */
static int add_products(double *h, int len, double z, int64_t m)
{
  double sz = m < 0 ? -z : z;
  uint64_t u = m < 0 ? (uint64_t)0 - (uint64_t)m : (uint64_t)m;
  double c = 134217729.0 * sz; /* 2^27 + 1 */
  double hi = c - (c - sz), lo = sz - hi;
  len = add_slices(h, len, hi, u);
  if (lo != 0)
    len = add_slices(h, len, lo, u);
  return len;
}

/* Adds the exact product a * b * c of three doubles to expansion h (four
 * exact partial products; no underflow for the ground rays' magnitudes). */
static int add_triple(double *h, int len, double a, double b, double c)
{
  double ab, e, p[4];
  ab = a * b;
  {
    double ca = 134217729.0 * a, ahi = ca - (ca - a), alo = a - ahi;
    double cb = 134217729.0 * b, bhi = cb - (cb - b), blo = b - bhi;
    e = alo * blo - (((ab - ahi * bhi) - alo * bhi) - ahi * blo);
  }
  double parts[2] = {ab, e};
  for (int k = 0; k < 2; k++) {
    double x = parts[k], y = c, xy = x * y;
    double cx = 134217729.0 * x, xhi = cx - (cx - x), xlo = x - xhi;
    double cy = 134217729.0 * y, yhi = cy - (cy - y), ylo = y - yhi;
    p[2 * k] = xy;
    p[2 * k + 1] = xlo * ylo - (((xy - xhi * yhi) - xlo * yhi) - xhi * ylo);
  }
  for (int k = 0; k < 4; k++) {
    double b2 = p[k];
    for (int q = 0; q < len; q++)
      two_sum(b2, h[q], &b2, &h[q]);
    h[len++] = b2;
  }
  return len;
}

/* The exact sign of det(e_i, e_j, e_k) for the ground rays as stored
 * (rounded ground-point differences): six triple products. */
static int exact_sign_ground(const rays *r, int i, int j, int k)
{
  const double *x = r->x, *y = r->y, *z = r->z;
  double h[24];
  int len = 0;
  len = add_triple(h, len, x[i], y[j], z[k]);
  len = add_triple(h, len, y[i], z[j], x[k]);
  len = add_triple(h, len, z[i], x[j], y[k]);
  len = add_triple(h, len, -z[i], y[j], x[k]);
  len = add_triple(h, len, -y[i], x[j], z[k]);
  len = add_triple(h, len, -x[i], z[j], y[k]);
  for (int q = len - 1; q >= 0; q--)
    if (h[q] != 0)
      return h[q] > 0 ? 1 : -1;
  return 0;
}

/* i, j, k < n */
static int exact_sign(const rays *r, int i, int j, int k)
{
  if (r->ground)
    return exact_sign_ground(r, i, j, k);
  int64_t mi = r->dc[j] * r->dr[k] - r->dr[j] * r->dc[k];
  int64_t mj = r->dc[k] * r->dr[i] - r->dr[k] * r->dc[i];
  int64_t mk = r->dc[i] * r->dr[j] - r->dr[i] * r->dc[j];
  double h[24];
  int len = 0;
  len = add_products(h, len, r->zk[i], mi);
  len = add_products(h, len, r->zk[j], mj);
  len = add_products(h, len, r->zk[k], mk);
  len = add_products(h, len, -r->zv, mi + mj + mk);
  for (int x = len - 1; x >= 0; x--)
    if (h[x] != 0)
      return h[x] > 0 ? 1 : -1;
  return 0;
}

/* Shewchuk's orient3d bound is (7 + 56 eps) eps times the permanent
 * sum_k |x_k| (|yi zj| + |zi yj|) + ...; bounding every |x_k| by the
 * star's largest coordinate gives one bound per pair, valid for every
 * third ray, so a test costs a dot product and two comparisons. With
 * integers up to 2^16 the products are below 2^32, n below 2^33, n . e_k
 * below 3 2^49 < 2^53: the double result is exact, and a zero bound lets
 * side() take its sign as it is (integer heights, the common case, meet
 * many exact zeros on flats, which a bound would send to the exact sum). */
static inline double pair_bound(const rays *r, double xi, double yi,
                                double zi, double xj, double yj, double zj)
{
  double per = fabs(yi * zj) + fabs(zi * yj) + fabs(zi * xj) +
               fabs(xi * zj) + fabs(xi * yj) + fabs(yi * xj);
  return 1e-15 * per * r->maxc;
}

static inline void pair_make(const rays *r, int i, int j, pair *p)
{
  double xi = r->x[i], yi = r->y[i], zi = r->z[i];
  double xj = r->x[j], yj = r->y[j], zj = r->z[j];
  p->nx = yi * zj - zi * yj;
  p->ny = zi * xj - xi * zj;
  p->nz = xi * yj - yi * xj;
  p->bound = r->ints ? 0 : pair_bound(r, xi, yi, zi, xj, yj, zj);
}

static inline pair pair_at(const rays *r, int i)
{
  pair p = {r->nx[i], r->ny[i], r->nz[i], r->nb[i]};
  return p;
}

/* sign of (e_i x e_j) . e_k, exact (i, j, k < n) */
static inline int side(const rays *r, const pair *p, int i, int j, int k)
{
  double det = p->nx * r->x[k] + p->ny * r->y[k] + p->nz * r->z[k];
  if (det > p->bound)
    return 1;
  if (det < -p->bound)
    return -1;
  if (p->bound == 0)
    return 0; /* exact (r->ints) or the cross product is exactly zero */
  return exact_sign(r, i, j, k);
}

static inline double max3abs(double m, double x, double y, double z)
{
  x = fabs(x);
  y = fabs(y);
  z = fabs(z);
  m = x > m ? x : m;
  m = y > m ? y : m;
  return z > m ? z : m;
}

/* 1 when z is an integer (not NaN nor infinite) of at most 2^16: adding
 * and taking away 1.5 2^52 rounds z to an integer in one step, without a
 * call and without a conversion that could overflow */
static inline int small_int(double z)
{
  return (fabs(z) <= 65536.0) & ((z + 0x1.8p52) - 0x1.8p52 == z);
}

int tt__gaussian_orient(const int64_t dc[3], const int64_t dr[3],
                        const double z[3], double zv)
{
  rays r;
  double mx = 0;
  int ints = 1;
  r.zv = zv;
  for (int i = 0; i < 3; i++) {
    r.dc[i] = dc[i];
    r.dr[i] = dr[i];
    r.zk[i] = z[i];
    r.x[i] = (double)dc[i];
    r.y[i] = (double)dr[i];
    r.z[i] = z[i] - zv;
    mx = max3abs(mx, r.x[i], r.y[i], r.z[i]);
    ints &= small_int(r.z[i]);
  }
  r.maxc = mx;
  r.ints = ints && mx <= 65536.0;
  r.ground = false;
  pair p;
  pair_make(&r, 0, 1, &p);
  return side(&r, &p, 0, 1, 2);
}

static void rays_load(const tt__mesh *m, const double fr[4], int32_t v,
                      const star *s, rays *r)
{
  const tt__mesh_vertex *o = &m->v[v];
  int n = s->n;
  r->zv = tt__mesh_z(m, v);
  double mx = 0;
  int ints = 1;
  r->ground = m->gxy != NULL;
  if (r->ground) {
    /* rays on the ground points: tt__geo_vec's differences */
    const double *p = m->gxy + 2 * ((size_t)o->r * m->gnx + (size_t)o->c);
    for (int i = 0; i < n; i++) {
      const tt__mesh_vertex *w = &m->v[s->nb[i]];
      const double *q = m->gxy + 2 * ((size_t)w->r * m->gnx + (size_t)w->c);
      r->dc[i] = (int64_t)w->c - o->c;
      r->dr[i] = (int64_t)w->r - o->r;
      r->zk[i] = tt__mesh_z(m, s->nb[i]);
      double gx = q[0] - p[0], gy = q[1] - p[1], dz = r->zk[i] - r->zv;
      r->x[i] = r->x[i + n] = r->gx[i] = r->gx[i + n] = gx;
      r->y[i] = r->y[i + n] = r->gy[i] = r->gy[i + n] = gy;
      r->z[i] = r->z[i + n] = dz;
      mx = max3abs(mx, gx, gy, dz);
    }
    r->maxc = mx;
    r->ints = false;
    return;
  }
  for (int i = 0; i < n; i++) {
    const tt__mesh_vertex *w = &m->v[s->nb[i]];
    int64_t dci = (int64_t)w->c - o->c, dri = (int64_t)w->r - o->r;
    r->dc[i] = dci;
    r->dr[i] = dri;
    r->zk[i] = tt__mesh_z(m, s->nb[i]);
    double dc = (double)dci, dr = (double)dri;
    double dz = r->zk[i] - r->zv;
    double gx = fr[0] * dc + fr[1] * dr, gy = fr[2] * dc + fr[3] * dr;
    r->x[i] = r->x[i + n] = dc;
    r->y[i] = r->y[i + n] = dr;
    r->z[i] = r->z[i + n] = dz;
    r->gx[i] = r->gx[i + n] = gx;
    r->gy[i] = r->gy[i + n] = gy;
    mx = max3abs(mx, dc, dr, dz);
    ints &= small_int(dz);
  }
  r->maxc = mx;
  r->ints = ints && mx <= 65536.0;
}

/* Sums of angles without an atan2 per angle: angle theta = atan2(c, d)
 * in [0, pi] (c = |u x v|, d = u . v) is the argument of d + i c, so a sum
 * of angles is the argument of the product, plus 2 pi for each time the
 * running product passes the positive real axis -- detected as a move from
 * the lower half-plane to the upper, since no step exceeds pi. One sqrt
 * per angle and one atan2 per sum instead of an atan2 per angle (atan2
 * costs eight times a square root). The product is rescaled by powers of
 * two when it grows or shrinks far, which leaves its argument exact. */
typedef struct turn {
  double x, y;
  int k;
  bool up;                              /* upper(x, y), carried */
} turn;

static inline bool upper(double x, double y)
{
  return y > 0 || (y == 0 && x > 0);
}

/* the angle atan2(c, d) of c = |u x v|, d = u . v */
static inline void turn_step(turn *t, double c, double d)
{
  if (c == 0 && d >= 0)
    return; /* angle 0 (or a zero vector: atan2(0, 0) = 0) */
  double x = t->x * d - t->y * c, y = t->x * c + t->y * d;
  bool up = upper(x, y); /* (the rescaling below keeps it) */
  t->k += !t->up & up;
  t->up = up;
  double mag = fabs(x) + fabs(y);
  if (mag > 0x1p200 || mag < 0x1p-200) {
    int ex;
    frexp(mag, &ex);
    x = ldexp(x, -ex);
    y = ldexp(y, -ex);
  }
  t->x = x;
  t->y = y;
}

/* |g_i x g_j| and g_i . g_j, as tt__glen(tt__gcross()) and tt__gdot() */
static inline void ground_cd(const rays *r, int i, int j, double *out_c,
                             double *out_d)
{
  double ux = r->gx[i], uy = r->gy[i], uz = r->z[i];
  double vx = r->gx[j], vy = r->gy[j], vz = r->z[j];
  double cx = uy * vz - uz * vy, cy = uz * vx - ux * vz,
         cz = ux * vy - uy * vx;
  *out_c = sqrt(cx * cx + cy * cy + cz * cz);
  *out_d = ux * vx + uy * vy + uz * vz;
}

static inline double turn_angle(const turn *t)
{
  double a = atan2(t->y, t->x);
  if (a < 0)
    a += 2 * TT__PI;
  return 2 * TT__PI * t->k + a;
}

/* The sides of pair (i, i+1) against every other ray, without early
 * exits: 1 when some ray lies strictly on its positive side, 2 on its
 * negative side (3: both, the pair does not support). The n - 2 rays after
 * the pair are x[i+2 .. i+n-1], in order and without wrapping; a branch
 * per test that the processor cannot predict costs more than the tests it
 * would save. A product within the pair's bound is undecided: that pair is
 * redone with the exact signs (never with integer heights, where the bound
 * is 0). */
static int pair_sides(const rays *r, int n, int i)
{
  double nx = r->nx[i], ny = r->ny[i], nz = r->nz[i], b = r->nb[i];
  const double *x = r->x + i + 2, *y = r->y + i + 2, *z = r->z + i + 2;
  int fp = 0, fn = 0, near = 0;
  if (r->ints) {
    for (int t = 0; t < n - 2; t++) {
      double det = nx * x[t] + ny * y[t] + nz * z[t];
      fp |= det > 0;
      fn |= det < 0;
    }
  } else {
    for (int t = 0; t < n - 2; t++) {
      double det = nx * x[t] + ny * y[t] + nz * z[t];
      fp |= det > b;
      fn |= det < -b;
      near |= fabs(det) <= b;
    }
  }
  if (near && b > 0) {
    int j = wrap(i + 1, n);
    pair p = pair_at(r, i);
    fp = fn = 0;
    for (int t = 2; t < n; t++) {
      int sd = side(r, &p, i, j, wrap(i + t, n));
      fp |= sd > 0;
      fn |= sd < 0;
    }
  }
  return fp | fn << 1;
}

/* The hull of a mixed star by gift wrapping, from hull ray `start` on the
 * side sgn: out_h[] receives the hull rays in order from start, their
 * count is returned. O(d h); the reference that hull_graham must match,
 * and its fallback. */
static int hull_wrap(const rays *r, int n, int start, int sgn, int *out_h)
{
  int tp = 0, m = 0;
  while (tp < n) {
    int p = wrap(start + tp, n);
    int tq = tp + 1, q = wrap(start + tq, n);
    pair pq = pair_at(r, p); /* q = p + 1 */
    for (int tr = tp + 2; tr <= n; tr++) {
      int x = wrap(start + tr, n);
      if (x == p)
        continue; /* the start itself, seen from the start */
      if (sgn * side(r, &pq, p, q, x) < 0) {
        tq = tr;
        q = x;
        pair_make(r, p, q, &pq);
      }
    }
    out_h[m++] = p;
    tp = tq;
  }
  return m;
}

/* sign of (c_i x c_j)_z in pixel space, exact (|dc|, |dr| < 2^28); of
 * the ground rays' plan cross product with ground points */
static inline int cross2_sign(const rays *r, int i, int j)
{
  if (r->ground) {
    const double o[2] = {0, 0}, a[2] = {r->x[i], r->y[i]},
                 b[2] = {r->x[j], r->y[j]};
    return tt__orient2d(o, a, b);
  }
  int64_t c = r->dc[i] * r->dr[j] - r->dr[i] * r->dc[j];
  return (c > 0) - (c < 0);
}

/* The same hull by Graham's scan in the star's cyclic order, O(d), then
 * proved in O(d): consecutive hull rays less than pi apart in plan, a
 * strictly convex turn at every hull ray and every other ray strictly
 * inside the face over its sector. Then the hull's faces are the convex
 * envelope of the star on side sgn, its rays are exactly the envelope's
 * kinks, and gift wrapping from start finds the same rays in the same
 * order (so the same bits). Returns the count, or 0 when the proof fails
 * (coplanar rays, a face spanning pi or more, ...): the caller then wraps.
 * Every sign is exact. The scan itself proves the turns at every hull ray
 * but the start (a ray stays on the stack only after a strict turn
 * towards the next one), and leaves each face's cross product on the
 * stack; what is left is the start's turn, the plan gaps and the rays
 * inside each face. */
static int hull_graham(rays *r, int n, int start, int sgn, int *out_h)
{
  int *h = out_h;
  pair *top = r->top; /* top[k]: pair (h[k-1], h[k]); top[0]: closing */
  int m = 1;
  h[0] = start;
  for (int t = 1; t <= n; t++) {
    int x = wrap(start + t, n);
    while (m >= 2 &&
           sgn * side(r, &top[m - 1], h[m - 2], h[m - 1], x) <= 0)
      m--;
    if (t == n)
      break;
    pair_make(r, h[m - 1], x, &top[m]);
    h[m++] = x;
  }
  if (m < 3)
    return 0;
  pair_make(r, h[m - 1], start, &top[0]);
  if (sgn * side(r, &top[0], h[m - 1], start, h[1]) <= 0)
    return 0;
  int o = cross2_sign(r, 0, 1); /* the plan orientation of the fan */
  for (int k = 0; k < m; k++) {
    int a = h[k], b = k + 1 < m ? h[k + 1] : start;
    const pair *f = &top[k + 1 < m ? k + 1 : 0];
    if (cross2_sign(r, a, b) != o)
      return 0;
    int e = b > a ? b : b + n; /* rays a+1 .. e-1, from the doubled arrays */
    for (int x = a + 1; x < e; x++) {
      double det = f->nx * r->x[x] + f->ny * r->y[x] + f->nz * r->z[x];
      if (sgn * det > f->bound)
        continue;
      if (f->bound == 0 || sgn * side(r, f, a, b, wrap(x, n)) <= 0)
        return 0;
    }
  }
  return m;
}

/* |K| of v with star s; the class in *out_class.
 * Classification in O(d) but for the hull's proof: with t_i the exact
 * sign of (e_i x e_{i+1}) . e_{i+2} (consecutive rays), the star is
 * convex iff every t_i >= 0 or every t_i <= 0 -- the star's height
 * function is then convex (or concave) across every ray, hence
 * everywhere, and each of its faces supports it; conversely a supporting
 * pair (i, i+1) has t_{i-1} and t_i (its tests against rays i-1 and i+2)
 * of its own sign, and supporting pairs of opposite signs force a flat
 * star. So only pairs with t_{i-1}, t_i of one sign are tested in full,
 * in index order, up to the first that supports: no such pair, a saddle;
 * else a mixed star, whose hull (its convex envelope on that side) starts
 * at that pair. These are the same classes and the same start as testing
 * every pair against every ray. */
static double star_curvature(const tt__mesh *m, const double fr[4],
                             int32_t v, const star *s, rays *r,
                             int *out_class)
{
  int n = s->n;
  rays_load(m, fr, v, s, r);
  int nang = s->boundary ? n - 1 : n;
  for (int i = 0; i < nang; i++)
    ground_cd(r, i, i + 1, &r->c[i], &r->d[i]);
  turn tsum = {1, 0, 0, true};
  for (int i = 0; i < nang; i++)
    turn_step(&tsum, r->c[i], r->d[i]);
  double sum = turn_angle(&tsum);
  if (s->boundary) {
    *out_class = TT__VERTEX_BOUNDARY;
    return fabs(TT__PI - sum);
  }
  /* the consecutive pairs, and t_i = their sides against the next ray */
  const double *x = r->x, *y = r->y, *z = r->z;
  for (int i = 0; i < n; i++) {
    r->nx[i] = y[i] * z[i + 1] - z[i] * y[i + 1];
    r->ny[i] = z[i] * x[i + 1] - x[i] * z[i + 1];
    r->nz[i] = x[i] * y[i + 1] - y[i] * x[i + 1];
  }
  int anyp = 0, anyn = 0;
  signed char *t = r->t;
  if (r->ints) {
    for (int i = 0; i < n; i++) {
      r->nb[i] = 0;
      double det = r->nx[i] * x[i + 2] + r->ny[i] * y[i + 2] +
                   r->nz[i] * z[i + 2];
      int sd = (det > 0) - (det < 0);
      t[i] = (signed char)sd;
      anyp |= sd > 0;
      anyn |= sd < 0;
    }
  } else {
    for (int i = 0; i < n; i++) {
      r->nb[i] = pair_bound(r, x[i], y[i], z[i], x[i + 1], y[i + 1],
                            z[i + 1]);
      pair p = pair_at(r, i);
      int sd = side(r, &p, i, wrap(i + 1, n), wrap(i + 2, n));
      t[i] = (signed char)sd;
      anyp |= sd > 0;
      anyn |= sd < 0;
    }
  }
  if (!(anyp && anyn)) {
    *out_class = TT__VERTEX_CONVEX;
    return 2 * TT__PI - sum;
  }
  int start = -1, sgn = 0;
  for (int i = 0; i < n && start < 0; i++) {
    int tl = t[i == 0 ? n - 1 : i - 1], tr = t[i];
    if ((tl < 0 || tr < 0) && (tl > 0 || tr > 0))
      continue; /* t_{i-1} and t_i of opposite signs */
    int sd = pair_sides(r, n, i);
    if (sd == 1 || sd == 2) {
      start = i;
      sgn = sd == 1 ? 1 : -1;
    }
  }
  if (start < 0) {
    *out_class = TT__VERTEX_SADDLE;
    return sum - 2 * TT__PI;
  }
  *out_class = TT__VERTEX_MIXED;
  int *hr = r->hull;
  int nh = hull_graham(r, n, start, sgn, hr);
  if (nh == 0)
    nh = hull_wrap(r, n, start, sgn, hr);
  turn thull = {1, 0, 0, true};
  for (int k = 0; k < nh; k++) {
    double c, d;
    ground_cd(r, hr[k], hr[k + 1 < nh ? k + 1 : 0], &c, &d);
    turn_step(&thull, c, d);
  }
  return 2 * TT__PI - 2 * turn_angle(&thull) + sum;
}

double tt__gaussian_vertex(const tt__crit_env *env, int32_t v, int *out_class)
{
  double fr[4];
  star s;
  rays r;
  int cls = -1;
  double k = 0;
  tt__geo_frame(env, fr);
  if (star_gather(env->mesh, v, &s) && s.n >= 2) {
    star_canon(&s);
    k = star_curvature(env->mesh, fr, v, &s, &r, &cls);
  }
  if (out_class)
    *out_class = cls;
  return k;
}

#if defined(__GNUC__)
#define tt__prefetch(p) __builtin_prefetch(p)
#else
#define tt__prefetch(p) ((void)(p))
#endif

/* --- the per-run cache of |K| ------------------------------------------
 *
 * |K(v)| depends on v's neighbours, their order and whether the star is
 * open, and on nothing else: vertices never move and the frame is the
 * run's. So a value computed once for a canonical neighbour list (star_canon)
 * stays true for that list, and an entry keyed by the whole list can be
 * trusted whenever the list matches -- a proof, not a hash. Two entries per
 * vertex: [0] the star last met in the mesh, [1] the last star made by
 * editing one ("the other configuration" of a quad), which becomes the
 * mesh's own when that swap is taken. Stars of degree above GC_KEY are not
 * cached (a terrain TIN has degree 6 on average; the few higher ones are
 * computed each time). Refinement's flips around a new vertex meet the same
 * stars again and again: the new vertex's in every quad, each neighbour's
 * in two, and after a flip the three stars it changed are the ones just
 * computed as "other". The cache grows with the mesh (vertex ids are
 * dense); when it cannot, values are computed as without it.
 *
 * When the mesh tracks star versions (mesh.h; a refinement run turns it on
 * for this criterion, star_versions in its vtable), entry [0] also keeps
 * the version of v's star it was stored under, and while the mesh still
 * shows that version the star is the entry's list: neither |K| nor the
 * star itself is read from the mesh again. That skips walking the star (a
 * chain of dependent loads) for three stars in four of a swap value. */
#define GC_KEY 12

typedef struct gentry {
  double k;              /* |K| */
  int32_t tag;           /* 2 * degree + boundary; 0: empty */
  uint32_t ver;          /* [0] of a versioned cache: the star's version */
  int32_t nb[GC_KEY];    /* the canonical neighbour list */
} gentry;                /* 64 bytes: one cache line */

typedef struct gcache {
  const tt__mesh *mesh;  /* the mesh and frame it was made for; another */
  uint64_t serial;       /* environment is served without it */
  double fr[4];
  bool versioned;        /* the mesh tracked star versions from the start */
  gentry (*e)[2];        /* per vertex */
  size_t cap;            /* vertices covered */
  /* the last swap value's quad (versioned only): its vertices, their star
   * versions then, and whether entry [1] holds each one's other star */
  int32_t last_vs[4];
  uint32_t last_ver[4];
  bool last_has[4];
} gcache;

static void *gaussian_cache_new(const tt__crit_env *env)
{
  gcache *c = calloc(1, sizeof *c);
  if (!c)
    return NULL;
  c->mesh = env->mesh;
  c->serial = env->mesh->serial;
  c->versioned = env->mesh->vver != NULL;
  c->last_vs[0] = -1;
  tt__geo_frame(env, c->fr);
  return c;
}

static void gaussian_cache_free(void *cache)
{
  gcache *c = cache;
  if (!c)
    return;
  free(c->e);
  free(c);
}

/* The cache of env when it serves env's mesh and frame, grown to cover
 * every vertex of the mesh; else NULL (another mesh or frame, or out of
 * memory). */
static gcache *cache_of(const tt__crit_env *env, const double fr[4])
{
  gcache *c = env->cache;
  const tt__mesh *m = env->mesh;
  if (!c || c->mesh != m || c->serial != m->serial || c->fr[0] != fr[0] ||
      c->fr[1] != fr[1] || c->fr[2] != fr[2] || c->fr[3] != fr[3])
    return NULL;
  if (m->nv > c->cap) {
    size_t old = c->cap;
    if (!tt__grow((void **)&c->e, &c->cap, m->nv, sizeof c->e[0]))
      return NULL;
    memset(c->e + old, 0, (c->cap - old) * sizeof c->e[0]);
  }
  return c;
}

static bool entry_is(const gentry *x, int32_t tag, const star *s)
{
  if (x->tag != tag)
    return false;
  for (int i = 0; i < s->n; i++)
    if (x->nb[i] != s->nb[i])
      return false;
  return true;
}

/* |K| of v with canonical star s, through v's entries x (NULL: no cache);
 * mine: s is v's star in the mesh (else an edited one), and ver its
 * version (stored with a mine value). */
static double star_k(const tt__mesh *m, const double fr[4], gentry *x,
                     int32_t v, const star *s, bool mine, uint32_t ver,
                     rays *r, bool *in_other)
{
  gentry *slot = NULL;
  int32_t tag = 2 * s->n + (s->boundary ? 1 : 0);
  *in_other = false;
  if (x && s->n <= GC_KEY) {
    if (entry_is(&x[0], tag, s)) {
      x[0].ver = mine ? ver : x[0].ver;
      return x[0].k;
    }
    if (entry_is(&x[1], tag, s)) {
      *in_other = !mine;
      if (!mine)
        return x[1].k;
      gentry t = x[0]; /* the mesh took the other configuration */
      x[0] = x[1];
      x[1] = t;
      x[0].ver = ver;
      return x[0].k;
    }
    slot = &x[mine ? 0 : 1];
  }
  int cls;
  double k = star_curvature(m, fr, v, s, r, &cls);
  if (slot) {
    slot->k = k;
    slot->tag = tag;
    slot->ver = ver;
    memcpy(slot->nb, s->nb, (size_t)s->n * sizeof s->nb[0]);
    *in_other = !mine;
  }
  return k;
}

static double gaussian_swap_value(const tt__crit_env *env, int32_t e)
{
  const tt__mesh *m = env->mesh;
  double fr[4];
  tt__quad q;
  tt__geo_frame(env, fr);
  if (!tt__quad_load(env, e, fr, &q))
    return 0.0;
  gcache *c = cache_of(env, fr);
  /* canonical order a, b, c, d; "mine" is the mesh's configuration, the
   * other one is made by editing the stars: with a-b in the mesh, a and b
   * lose each other, c gains d after a, d gains c after b; with c-d in the
   * mesh, c and d lose each other, a gains b after d, b gains a after c */
  bool ab = q.sign > 0;
  int32_t vs[4] = {q.a, q.b, q.c, q.d};
  double sa = 0, sb = 0; /* sum |K| with diagonal a-b, with c-d */
  star st[4], o;
  bool got[4], known[4] = {false, false, false, false};
  bool has[4] = {false, false, false, false};
  double kmine[4] = {0, 0, 0, 0};
  uint32_t ver[4] = {0, 0, 0, 0};
  gentry *x[4] = {NULL, NULL, NULL, NULL};
  rays r;
  /* Most of a value's cost is waiting for memory (the mesh around four
   * scattered vertices, their cache entries): ask for the entries first,
   * take the stars whose version still matches from them, walk the
   * others back to back, then ask for every ray's vertex at once, so that
   * the waits overlap. */
  if (c)
    for (int i = 0; i < 4; i++) {
      x[i] = c->e[vs[i]];
      tt__prefetch(&x[i][0]);
      tt__prefetch(&x[i][1]);
      if (c->versioned)
        tt__prefetch(&m->vver[vs[i]]);
    }
  for (int i = 0; i < 4; i++) {
    star *s = &st[i];
    if (c && c->versioned) {
      ver[i] = m->vver[vs[i]];
      const gentry *y = &x[i][0];
      if (y->tag != 0 && y->ver == ver[i]) {
        s->n = y->tag >> 1;
        s->boundary = (y->tag & 1) != 0;
        memcpy(s->nb, y->nb, (size_t)s->n * sizeof s->nb[0]);
        kmine[i] = y->k;
        known[i] = got[i] = true;
        continue;
      }
    }
    got[i] = star_gather(m, vs[i], s);
    if (got[i])
      star_canon(s);
  }
  for (int i = 0; i < 4; i++)
    if (got[i])
      for (int j = 0; j < st[i].n; j++)
        tt__prefetch(&m->v[st[i].nb[j]]);
  for (int i = 0; i < 4; i++) {
    star *s = &st[i];
    if (!got[i])
      continue;
    bool ok = true;
    switch (i) {
    case 0: ok = ab ? (star_without(s, q.b, &o), true)
                    : star_with(s, q.d, q.b, &o); break;
    case 1: ok = ab ? (star_without(s, q.a, &o), true)
                    : star_with(s, q.c, q.a, &o); break;
    case 2: ok = ab ? star_with(s, q.a, q.d, &o)
                    : (star_without(s, q.d, &o), true); break;
    default: ok = ab ? star_with(s, q.b, q.c, &o)
                     : (star_without(s, q.c, &o), true); break;
    }
    if (!ok)
      continue; /* a star past the cap: the vertex counts 0 both ways */
    bool unused;
    double km = known[i] ? kmine[i]
                         : star_k(m, fr, x[i], vs[i], s, true, ver[i], &r,
                                  &unused);
    double ko = star_k(m, fr, x[i], vs[i], &o, false, 0, &r, &has[i]);
    sa += ab ? km : ko;
    sb += ab ? ko : km;
  }
  if (c && c->versioned)
    for (int i = 0; i < 4; i++) {
      c->last_vs[i] = vs[i];
      c->last_ver[i] = ver[i];
      c->last_has[i] = has[i];
    }
  return q.sign * tt__snap(sa - sb, fabs(sa) + fabs(sb));
}

/* After the flip of the last quad valued: its four stars are now the
 * other configuration's, each in entry [1], so they become entry [0]
 * under their new versions -- no walk around them to prove it. Sound
 * because a flip adds exactly one to each of its four versions (mesh.h):
 * a vertex whose version is one past the value's changed only by this
 * flip, and the four vertices, their triangles unchanged until the flip,
 * make only the one quad, whose diagonal was the edge valued. */
static void gaussian_flipped(const tt__crit_env *env, int32_t h)
{
  double fr[4];
  tt__geo_frame(env, fr);
  gcache *c = cache_of(env, fr);
  const tt__mesh *m = env->mesh;
  int32_t g = m->twin[h];
  if (!c || !c->versioned || c->last_vs[0] < 0 || g < 0)
    return;
  int32_t now[4] = {m->hv[h], m->hv[g], tt__mesh_apex(m, h),
                    tt__mesh_apex(m, g)};
  for (int i = 0; i < 4; i++) {
    bool in = false;
    for (int j = 0; j < 4; j++)
      in |= now[j] == c->last_vs[i];
    if (!in)
      return;
  }
  for (int i = 0; i < 4; i++) {
    int32_t v = c->last_vs[i];
    if (!c->last_has[i] || m->vver[v] != c->last_ver[i] + 1)
      continue;
    gentry *x = c->e[v], t = x[0];
    x[0] = x[1];
    x[1] = t;
    x[0].ver = m->vver[v];
  }
  c->last_vs[0] = -1;
}

/* Adds the three edges of the triangle of half-edge x, one half-edge per
 * edge, skipping those already listed. */
static int add_tri_edges(const tt__mesh *m, int32_t x, int32_t *out, int n,
                         int max)
{
  int32_t t0 = x - x % 3;
  for (int k = 0; k < 3; k++) {
    int32_t y = t0 + k, ty = m->twin[y];
    bool seen = false;
    for (int i = 0; i < n && i < max && !seen; i++)
      seen = out[i] == y || (ty >= 0 && out[i] == ty);
    if (seen)
      continue;
    if (n < max)
      out[n] = y;
    n++;
  }
  return n;
}

/* Every edge of every triangle around the quad's four vertices, one
 * half-edge per edge; at most max of them are written and counted (with
 * max = 1024 that is four vertices of total degree about 340). */
static int gaussian_affected(const tt__crit_env *env, int32_t h,
                             int32_t *out, int max)
{
  const tt__mesh *m = env->mesh;
  int32_t g = m->twin[h];
  int32_t vs[4] = {m->hv[h], m->hv[g], tt__mesh_apex(m, h),
                   tt__mesh_apex(m, g)};
  int n = 0;
  for (int i = 0; i < 4; i++) {
    int32_t h0 = m->v[vs[i]].edge, x = h0;
    if (h0 < 0)
      continue;
    /* counter-clockwise: ccw(x) = twin[prev(x)] */
    bool open = false;
    for (;;) {
      n = add_tri_edges(m, x, out, n, max);
      int32_t t = m->twin[tt__prev(x)];
      if (t < 0) {
        open = true;
        break;
      }
      x = t;
      if (x == h0)
        break;
    }
    if (!open)
      continue;
    /* clockwise from h0 for the rest of a boundary star */
    x = h0;
    for (;;) {
      int32_t t = m->twin[x];
      if (t < 0)
        break;
      x = tt__next(t);
      n = add_tri_edges(m, x, out, n, max);
    }
  }
  return n < max ? n : max;
}

const tt__criterion_vt tt__criterion_gaussian = {
    TT_CRITERION_GAUSSIAN_CURVATURE, "gaussian_curvature", true,
    gaussian_swap_value, gaussian_affected, gaussian_cache_new,
    gaussian_cache_free, gaussian_flipped, true};
