/*
 * hole_dp.c -- the exact minimum-area re-triangulation of the hole around
 * an inserted vertex (see hole_dp.h and docs/min_area_hole.md).
 *
 * The hole's outline p_0..p_{n-1} runs counter-clockwise in the ground
 * frame. When v is strictly inside ("closed"), every triangulation with v
 * as a vertex is a fan of triangles (v, p_a, p_b) around v, consecutive
 * spokes v-p_a, v-p_b, and behind each fan triangle a pocket: the
 * sub-polygon p_a, p_a+1, ..., p_b closed by the chord p_a-p_b, triangulated
 * on its own. So
 *
 *   P(a, b) = best over a < k < b of P(a, k) + P(k, b) + area(p_a, p_k, p_b)
 *             (the polygon DP of section 3.5, on the cyclic chain a..b),
 *   W(a, b) = area(v, p_a, p_b) + P(a, b)  for a valid fan triangle,
 *
 * and the optimum is the cheapest closed path of fan steps once around v:
 * for each start spoke s, a shortest path over the spokes s, ..., s + n
 * (O(n^2)), the best over s. Fixed spokes (constrained, or on the mesh's
 * boundary) must be path stops: no step jumps over one, and the path
 * starts at the first. When v is on the mesh's boundary ("open") the
 * outline is v, p_0, ..., p_{n-1}; the path runs from spoke 0 to n-1.
 *
 * Validity, all exact integer tests in pixel space with the frame's
 * handedness: a chord is a side or a diagonal of the outline
 * (tt__polygon_diagonal_ok) not passing through v; a spoke v-p_i meets no
 * side of the outline away from p_i; a triangle turns strictly
 * counter-clockwise. A triangle whose three edges are valid lies in the
 * hole and holds no other vertex (the hole is a disk), which is why these
 * edge tests are all the DP needs.
 *
 * Areas are computed from the triangle's corners in one canonical order
 * (smallest vertex index first), so the same triangle has the same area,
 * bit for bit, in the current sum and in the DP. Workload: one call per
 * inserted vertex, n <= 8 after a split: a few hundred area evaluations,
 * all on the stack.
 */
#include "hole_dp.h"

#include "criteria/geometry.h"
#include "polygon_dp.h"
#include "predicates.h"

#define MAXN TT__HOLE_MAX_N

typedef struct hole {
  const tt__mesh *m;
  double fr[4];
  int32_t v;
  bool closed;          /* v strictly inside; else on the outline */
  int n;                /* outline vertices without v */
  int32_t p[MAXN];
  bool fixed[MAXN];     /* spoke v-p_i must stay */
  int nslots;           /* the hole's current triangles */
  int32_t slots[MAXN];
  /* the outline for the diagonal tests: p, or v followed by p (open) */
  int nq;
  int64_t qx[MAXN + 1], qy[MAXN + 1];
} hole;

/* The star of v counter-clockwise: spokes[i] leaves v, link vertex i is its
 * end. Returns the number of triangles (-1: more than cap), with
 * *out_closed false when v is on the boundary (then spokes[0] has no twin
 * and the last link vertex is the end of the last triangle's edge into v). */
static int walk_star(const tt__mesh *m, int32_t v, int32_t *spokes, int cap,
                     bool *out_closed)
{
  int32_t e0 = m->v[v].edge, s = e0;
  *out_closed = true;
  for (int guard = 0;; guard++) { /* clockwise to the boundary, if any */
    int32_t f = m->twin[s];
    if (f < 0) {
      *out_closed = false;
      break;
    }
    s = tt__next(f);
    if (s == e0)
      break;
    if (guard > cap)
      return -1;
  }
  int d = 0;
  for (int32_t e = s;;) {
    if (d >= cap)
      return -1;
    spokes[d++] = e;
    int32_t f = m->twin[tt__prev(e)];
    if (f < 0 || f == s)
      break;
    e = f;
  }
  return d;
}

static int orient3(const tt__mesh *m, int32_t a, int32_t b, int32_t c)
{
  return tt__mesh_orient(m, a, b, c);
}

/* 3-D area of triangle (a, b, c), the corners taken from the smallest
 * index on (a rotation: the same triangle gives the same bits). */
static double area(const hole *h, int32_t a, int32_t b, int32_t c)
{
  if (b < a && b < c) {
    int32_t t = a;
    a = b;
    b = c;
    c = t;
  } else if (c < a && c < b) {
    int32_t t = c;
    c = b;
    b = a;
    a = t;
  }
  tt__gvec o = {0, 0, 0};
  return tt__garea(o, tt__geo_vec(h->fr, h->m, a, b),
                   tt__geo_vec(h->fr, h->m, a, c));
}

/* Whether the closed segments a-b and c-d (vertex ids) meet. */
static bool segments_meet(const tt__mesh *m, int32_t a, int32_t b, int32_t c,
                          int32_t d)
{
  int o1 = orient3(m, a, b, c), o2 = orient3(m, a, b, d);
  int o3 = orient3(m, c, d, a), o4 = orient3(m, c, d, b);
  if (o1 * o2 < 0 && o3 * o4 < 0)
    return true;
  const tt__mesh_vertex *w = m->v;
#define BETWEEN(s, t, u)                                                     \
  ((w[s].c < w[t].c ? w[s].c : w[t].c) <= w[u].c &&                          \
   w[u].c <= (w[s].c < w[t].c ? w[t].c : w[s].c) &&                          \
   (w[s].r < w[t].r ? w[s].r : w[t].r) <= w[u].r &&                          \
   w[u].r <= (w[s].r < w[t].r ? w[t].r : w[s].r))
  return (o1 == 0 && BETWEEN(a, b, c)) || (o2 == 0 && BETWEEN(a, b, d)) ||
         (o3 == 0 && BETWEEN(c, d, a)) || (o4 == 0 && BETWEEN(c, d, b));
#undef BETWEEN
}

static bool is_side(const hole *h, int a, int b)
{
  if (h->closed)
    return (a + 1) % h->n == b || (b + 1) % h->n == a;
  return a + 1 == b || b + 1 == a;
}

/* Chord p_a-p_b: a side of the hole, or a diagonal inside it that misses
 * v. */
static bool chord_ok(const hole *h, int a, int b)
{
  if (a == b)
    return false;
  if (is_side(h, a, b))
    return true;
  int s = h->m->metric.det_sign, off = h->closed ? 0 : 1;
  if (!tt__polygon_diagonal_ok(h->nq, h->qx, h->qy, s, a + off, b + off))
    return false;
  /* (open: v is an outline vertex, the test above covers it) */
  return !h->closed || !segments_meet(h->m, h->p[a], h->p[b], h->v, h->v);
}

/* Spoke v-p_i inside the hole. */
static bool spoke_ok(const hole *h, int i)
{
  if (!h->closed)
    return i == 0 || i == h->n - 1 ||
           tt__polygon_diagonal_ok(h->nq, h->qx, h->qy,
                                   h->m->metric.det_sign, 0, i + 1);
  for (int k = 0; k < h->n; k++) {
    int k1 = (k + 1) % h->n;
    if (k != i && k1 != i &&
        segments_meet(h->m, h->v, h->p[i], h->p[k], h->p[k1]))
      return false;
  }
  return true;
}

/* The DP tables and the best fan path. */
typedef struct dp {
  double P[MAXN][MAXN];   /* pocket a..b (cyclic when closed) */
  int8_t K[MAXN][MAXN];   /* its best apex */
  double W[MAXN][MAXN];   /* fan step a -> b */
  bool spoke[MAXN];
  double D[MAXN + 1];     /* path values over positions from the start */
  int8_t from[MAXN + 1];  /* the position each came from */
} dp;

static void fill_pockets(const hole *h, dp *t)
{
  int n = h->n;
  for (int a = 0; a < n; a++)
    for (int b = 0; b < n; b++) {
      t->P[a][b] = INFINITY;
      t->K[a][b] = -1;
    }
  for (int a = 0; a < n; a++)
    if (h->closed || a + 1 < n)
      t->P[a][(a + 1) % n] = 0.0;
  for (int len = 2; len < n; len++)
    for (int a = 0; a < n; a++) {
      if (!h->closed && a + len >= n)
        break;
      int b = (a + len) % n;
      if (!chord_ok(h, a, b))
        continue;
      double best = INFINITY;
      int bk = -1;
      for (int i = 1; i < len; i++) {
        int k = (a + i) % n;
        double pa = t->P[a][k], pb = t->P[k][b];
        if (pa == INFINITY || pb == INFINITY ||
            orient3(h->m, h->p[a], h->p[k], h->p[b]) <= 0)
          continue;
        double val = pa + pb + area(h, h->p[a], h->p[k], h->p[b]);
        if (val < best) {
          best = val;
          bk = k;
        }
      }
      t->P[a][b] = best;
      t->K[a][b] = (int8_t)bk;
    }
  for (int i = 0; i < n; i++)
    t->spoke[i] = spoke_ok(h, i);
  for (int a = 0; a < n; a++)
    for (int b = 0; b < n; b++) {
      t->W[a][b] = INFINITY;
      if (a != b && t->spoke[a] && t->spoke[b] && t->P[a][b] < INFINITY &&
          orient3(h->m, h->v, h->p[a], h->p[b]) > 0)
        t->W[a][b] = area(h, h->v, h->p[a], h->p[b]) + t->P[a][b];
    }
}

/* Shortest fan path from spoke `start` once around v (closed) or from
 * spoke 0 to n-1 (open); positions j = 0..last stand for spoke
 * (start + j) mod n. Returns its value (INFINITY: none). */
static double fan_path(const hole *h, dp *t, int start)
{
  int n = h->n, last = h->closed ? n : n - 1;
  for (int j = 0; j <= last; j++) {
    t->D[j] = INFINITY;
    t->from[j] = -1;
  }
  t->D[0] = 0.0;
  for (int i = 0; i < last; i++) {
    if (t->D[i] == INFINITY)
      continue;
    int a = (start + i) % n;
    for (int j = i + 1; j <= last; j++) {
      int b = (start + j) % n;
      double val = t->D[i] + t->W[a][b];
      if (val < t->D[j]) {
        t->D[j] = val;
        t->from[j] = (int8_t)i;
      }
      if (h->fixed[b])
        break; /* no step jumps over a fixed spoke */
    }
  }
  return t->D[last];
}

/* Appends the triangles of pocket a..b. */
static void emit_pocket(const hole *h, const dp *t, int a, int b,
                        int32_t (*tris)[3], int *nt)
{
  int stack[2 * MAXN], sp = 0;
  stack[sp++] = a;
  stack[sp++] = b;
  while (sp > 0) {
    int j = stack[--sp], i = stack[--sp];
    int k = t->K[i][j];
    if ((i + 1) % h->n == j || k < 0)
      continue;
    tris[*nt][0] = h->p[i];
    tris[*nt][1] = h->p[k];
    tris[*nt][2] = h->p[j];
    (*nt)++;
    stack[sp++] = i;
    stack[sp++] = k;
    stack[sp++] = k;
    stack[sp++] = j;
  }
}

/* Builds the hole of v (the definition in hole_dp.h). False when v's star
 * is too large to handle. */
static bool build_hole(const tt__mesh *m, int32_t v, hole *h)
{
  int32_t spokes[MAXN];
  bool closed;
  int d = walk_star(m, v, spokes, MAXN, &closed);
  int nlink = closed ? d : d + 1;
  if (d < 1 || nlink > MAXN)
    return false;
  h->m = m;
  h->v = v;
  h->closed = closed;
  int32_t link[MAXN], apex[MAXN];
  bool fixed[MAXN];
  for (int i = 0; i < d; i++) {
    link[i] = m->hv[tt__next(spokes[i])];
    fixed[i] = m->twin[spokes[i]] < 0 ||
               (m->eflag[spokes[i]] & TT__EDGE_CONSTRAINED);
    h->slots[i] = spokes[i] / 3;
  }
  if (!closed) {
    link[d] = m->hv[tt__prev(spokes[d - 1])];
    fixed[d] = true;
  }
  h->nslots = d;
  /* the neighbours across the link edges */
  bool grow = (closed ? 2 * d : 2 * d + 1) <= MAXN;
  for (int i = 0; i < d; i++) {
    int32_t le = tt__next(spokes[i]), f = m->twin[le];
    apex[i] = -1;
    if (!grow || f < 0 || (m->eflag[le] & TT__EDGE_CONSTRAINED))
      continue;
    int32_t w = tt__mesh_apex(m, f);
    bool in_star = w == v;
    for (int k = 0; k < nlink && !in_star; k++)
      in_star = link[k] == w;
    if (!in_star)
      apex[i] = w;
  }
  /* a neighbour whose apex another neighbour shares is left out, both of
   * them (so the hole does not depend on where the walk started) */
  int32_t keep[MAXN];
  for (int i = 0; i < d; i++) {
    keep[i] = apex[i];
    for (int k = 0; k < d && keep[i] >= 0; k++)
      if (k != i && apex[k] == apex[i])
        keep[i] = -1;
  }
  h->n = 0;
  for (int i = 0; i < nlink; i++) {
    h->p[h->n] = link[i];
    h->fixed[h->n] = fixed[i];
    h->n++;
    if (i < d && keep[i] >= 0) {
      h->p[h->n] = keep[i];
      h->fixed[h->n] = false; /* an apex is never a spoke end yet */
      h->n++;
      h->slots[h->nslots++] = m->twin[tt__next(spokes[i])] / 3;
    }
  }
  h->nq = 0;
  if (!closed) {
    h->qx[0] = m->v[v].c;
    h->qy[0] = m->v[v].r;
    h->nq = 1;
  }
  for (int i = 0; i < h->n; i++) {
    h->qx[h->nq] = m->v[h->p[i]].c;
    h->qy[h->nq] = m->v[h->p[i]].r;
    h->nq++;
  }
  return true;
}

/* v's link edges, counter-clockwise from the boundary (if v is on it),
 * into out (at most max). Any degree. */
static int link_edges(const tt__mesh *m, int32_t v, int32_t *out, int max)
{
  int32_t e0 = m->v[v].edge, s = e0;
  for (;;) {
    int32_t f = m->twin[s];
    if (f < 0 || tt__next(f) == e0)
      break;
    s = tt__next(f);
  }
  int k = 0;
  for (int32_t e = s; k < max;) {
    out[k++] = tt__next(e);
    int32_t f = m->twin[tt__prev(e)];
    if (f < 0 || f == s)
      break;
    e = f;
  }
  return k;
}

int tt__hole_min_area(tt__mesh *m, const tt__crit_env *env, int32_t v,
                      int32_t *opposite, int max)
{
  if (m->v[v].edge < 0)
    return 0;
  hole h;
  dp t;
  if (!build_hole(m, v, &h))
    return link_edges(m, v, opposite, max);
  tt__geo_frame(env, h.fr);
  fill_pockets(&h, &t);
  /* the best start: the first fixed spoke, or every spoke */
  int first = 0, nstart = h.closed ? h.n : 1;
  for (int i = 0; i < h.n && h.closed; i++)
    if (h.fixed[i]) {
      first = i;
      nstart = 1;
      break;
    }
  double best = INFINITY;
  int bstart = -1;
  for (int s = first; s < first + nstart; s++) {
    double val = fan_path(&h, &t, s);
    if (val < best) {
      best = val;
      bstart = s;
    }
  }
  double now = 0.0;
  for (int i = 0; i < h.nslots; i++) {
    int32_t e = 3 * h.slots[i];
    now += area(&h, m->hv[e], m->hv[e + 1], m->hv[e + 2]);
  }
  if (bstart < 0 || !(tt__snap(now - best, now + best) > 0))
    return link_edges(m, v, opposite, max); /* keep the current one */
  /* the triangles: the fan steps of the best path, then their pockets */
  fan_path(&h, &t, bstart);
  int32_t tris[MAXN][3];
  int nt = 0, last = h.closed ? h.n : h.n - 1;
  for (int j = last; j > 0; j = t.from[j]) {
    int i = t.from[j];
    int a = (bstart + i) % h.n, b = (bstart + j) % h.n;
    tris[nt][0] = v;
    tris[nt][1] = h.p[a];
    tris[nt][2] = h.p[b];
    nt++;
    emit_pocket(&h, &t, a, b, tris, &nt);
  }
  if (nt != h.nslots) /* cannot happen: every triangulation of the hole
                          has as many triangles */
    return link_edges(m, v, opposite, max);
  if (!tt__mesh_replace_region(m, h.slots, h.nslots,
                               (const int32_t(*)[3])tris, nt))
    return -1; /* out of memory */
  return link_edges(m, v, opposite, max);
}
