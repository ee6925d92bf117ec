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
 * Validity: every triangle turns strictly counter-clockwise (exact
 * integer orientation in pixel space with the frame's handedness). That
 * alone makes every path the DP can complete a triangulation of the hole
 * (the argument is at fill_pockets), so no chord or spoke "inside the
 * outline" test is needed; earlier versions made them and no result
 * changed when they were dropped.
 *
 * Areas are 3-D areas on the ground: in the ground frame, or on the
 * grid's ground points when the mesh has them (a geographic DEM, mesh.h),
 * as every criterion measures (criteria/geometry.h); orientation stays the
 * mesh's exact pixel-space one, which is its topology.
 * Areas are computed from the triangle's corners in one canonical order
 * (smallest vertex index first), so the same triangle has the same area,
 * bit for bit, in the current sum and in the DP. Workload: one call per
 * inserted vertex (about 90% of them change the hole on real terrain),
 * n <= 8 after a split. Each of the C(n + 1, 3) triangles of the hole's
 * points has its orientation and area computed at most once per call, in
 * tables on the stack; pockets that cannot beat the best apex found so
 * far skip theirs, and start spokes of the fan path stop as soon as their
 * value cannot beat the current area or the best start. About 1.5 us per
 * call plus the mesh update (tt__mesh_replace_region).
 *
 * Part of src/optimize/, the optimisers: swaps under a criterion, look-ahead,
 * annealing, edge insertion, the dynamic programs.
 */
#include "optimize/hole_dp.h"

#include "criteria/geometry.h"

#define MAXN TT__HOLE_MAX_N

__extension__ typedef __int128 hole_i128;
/* triangles of hole points (local indices 0..MAXN, v last): C(MAXN + 1, 3) */
#define MAXT ((MAXN + 1) * MAXN * (MAXN - 1) / 6)

typedef struct hole {
  const tt__mesh *m;
  double fr[4];
  int32_t v;
  bool closed;          /* v strictly inside; else on the outline */
  int n;                /* outline vertices without v */
  int32_t p[MAXN];
  bool fixed[MAXN];     /* spoke v-p_i must stay */
  int nstar;            /* v's triangles: slots[0..nstar-1] */
  int nslots;           /* the hole's current triangles */
  int32_t slots[MAXN];
  /* the hole's points by local index (p_0..p_{n-1}, then v at n), copied
   * once from the mesh: vertex id, pixel coordinates, height */
  int32_t id[MAXN + 1];
  int64_t c[MAXN + 1], r[MAXN + 1];
  double z[MAXN + 1];
  /* the ground points (x, y) when the mesh has them (mesh.h), else unused */
  bool ground;
  double gx[MAXN + 1], gy[MAXN + 1];
  /* per triangle of local indices i < j < k (tri_index): its orientation
   * in that order, -1, 0 or +1, or 2: not yet computed, 3: +1 and area[]
   * holds its area; each computed at most once per call */
  int8_t orient[MAXT];
  double area[MAXT];
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

/* Index of the triangle of local indices i < j < k in hole.orient/area
 * (the combinatorial number system: dense over 0 <= i < j < k <= n). */
static int tri_index(int i, int j, int k)
{
  return k * (k - 1) * (k - 2) / 6 + j * (j - 1) / 2 + i;
}

/* Ground vector from local point a to local point b: tt__geo_vec's
 * arithmetic on the copied coordinates, so the same bits (on the ground
 * points when the mesh has them). */
static tt__gvec gvec(const hole *h, int a, int b)
{
  if (h->ground) {
    tt__gvec g = {h->gx[b] - h->gx[a], h->gy[b] - h->gy[a],
                  h->z[b] - h->z[a]};
    return g;
  }
  double dc = (double)(h->c[b] - h->c[a]);
  double dr = (double)(h->r[b] - h->r[a]);
  tt__gvec g = {h->fr[0] * dc + h->fr[1] * dr, h->fr[2] * dc + h->fr[3] * dr,
                h->z[b] - h->z[a]};
  return g;
}

/* 3-D area of triangle (a, b, c) of local points, the corners taken from
 * the smallest vertex id on (a rotation: the same triangle gives the same
 * bits, here and in mesh_area). */
static double tri_area(const hole *h, int a, int b, int c)
{
  const int32_t *id = h->id;
  if (id[b] < id[a] && id[b] < id[c]) {
    int t = a;
    a = b;
    b = c;
    c = t;
  } else if (id[c] < id[a] && id[c] < id[b]) {
    int t = c;
    c = b;
    b = a;
    a = t;
  }
  tt__gvec o = {0, 0, 0};
  return tt__garea(o, gvec(h, a, b), gvec(h, a, c));
}

/* 3-D area of the mesh triangle (a, b, c) (vertex ids), the same
 * canonical order and arithmetic as tri_area. */
static double mesh_area(const hole *h, int32_t a, int32_t b, int32_t c)
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

/* Orientation of local points (i, j, k), i < j < k, in the ground frame
 * (tt__mesh_orient's sign: the same formula on the same coordinates),
 * from the table: > 0 when counter-clockwise (1, or 3 once its area is
 * known). */
static int tri_orient(hole *h, int t, int i, int j, int k)
{
  if (h->orient[t] == 2) {
    /* tt__orient_i's exact 128-bit determinant, inline here: it is most
     * of this file's predicate calls */
    hole_i128 det = (hole_i128)(h->c[i] - h->c[k]) * (h->r[j] - h->r[k]) -
                    (hole_i128)(h->r[i] - h->r[k]) * (h->c[j] - h->c[k]);
    int o = det > 0 ? 1 : (det < 0 ? -1 : 0);
    h->orient[t] = (int8_t)(h->m->metric.det_sign * o);
  }
  return h->orient[t];
}

/* The area of a triangle (i, j, k), i < j < k, already found
 * counter-clockwise: computed on first use. */
static double tri_area_at(hole *h, int t, int i, int j, int k)
{
  if (h->orient[t] != 3) { /* 3: counter-clockwise, area known */
    h->area[t] = tri_area(h, i, j, k);
    h->orient[t] = 3;
  }
  return h->area[t];
}

/* The DP tables and the best fan path. */
typedef struct dp {
  double P[MAXN][MAXN];   /* pocket a..b (cyclic when closed) */
  int8_t K[MAXN][MAXN];   /* its best apex */
  double W[MAXN][MAXN];   /* fan step a -> b */
  /* the finite fan steps from each spoke a, in order: to spoke
   * (a + off[a][k]) mod n at cost ws[a][k], up to and including the first
   * fixed spoke after a (no step jumps over it) */
  int nstep[MAXN];
  int8_t off[MAXN][MAXN];
  double ws[MAXN][MAXN];
  double D[MAXN + 1];     /* path values over positions from the start */
  int8_t from[MAXN + 1];  /* the position each came from */
} dp;

/* Why only orientations are tested (no "chord inside the polygon" or
 * "spoke misses the outline" test, which earlier versions had):
 * every combination the DP can form -- a closed fan path of steps
 * (v, p_a, p_b) with a triangulated pocket behind each, or, when v is on
 * the outline, the path from spoke 0 to n-1 -- has triangles whose
 * boundaries sum, as oriented edge chains, to the outline (each chord and
 * spoke is crossed once each way). So at every point off the edges the
 * number of triangles covering it with sign (+1 counter-clockwise, -1
 * clockwise) equals the outline's winding number: 1 inside the hole, 0
 * outside. With every triangle strictly counter-clockwise all signs are
 * +1, so every point inside is covered exactly once and no point outside
 * at all: the triangles tile the hole. Then no edge can pass through v or
 * an outline vertex, or leave the outline (a neighbourhood of that point
 * would be covered twice, or a point outside covered), so every chord
 * and spoke of such a combination is one the old tests accepted, and
 * every triangulation they accepted is such a combination. Dropping the
 * tests lets the tables hold values for chords and spokes that can never
 * be part of a complete combination (any completion would have a
 * triangle that is not counter-clockwise, which the DP never forms), and
 * no completed path uses them. Since sums of non-negative doubles only
 * grow, every P, W and path value is at most the old one and equal to it
 * on every piece of the chosen triangulation, and with the strict "<"
 * scans the same first minimum (apex, step, start) is picked: the result
 * is the same, bit for bit. */
static void fill_pockets(hole *h, dp *t)
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
  /* Closed, a pocket of n - 1 sides is never needed: it is no part of a
   * longer pocket, and its fan step a -> a - 1 closes a path only with the
   * step back, the same triangle the other way round, which cannot also
   * turn counter-clockwise; so W of such a step, finite or not, never
   * enters a finite path value or the chosen path. Open, it is the
   * pocket behind a single fan triangle (v, p_0, p_{n-1}). */
  int maxlen = h->closed ? n - 2 : n - 1;
  for (int len = 2; len <= maxlen; len++)
    for (int a = 0; a < n; a++) {
      if (!h->closed && a + len >= n)
        break;
      int b = a + len < n ? a + len : a + len - n;
      double best = INFINITY;
      int bk = -1;
      for (int i = 1, k = a + 1 < n ? a + 1 : 0; i < len;
           i++, k = k + 1 < n ? k + 1 : 0) {
        double pa = t->P[a][k], pb = t->P[k][b];
        if (pa == INFINITY || pb == INFINITY)
          continue;
        /* (a, k, b) in the outline's cyclic order: its sorted order is a
         * rotation of it, same orientation and area */
        int x = a, y = k, w = b;
        if (k < a) { /* k wrapped, so did b: k < b < a */
          x = k;
          y = b;
          w = a;
        } else if (b < a) { /* only b wrapped: b < a < k */
          x = b;
          y = a;
          w = k;
        }
        /* an area is >= 0 and a rounded sum never below a term, so
         * pa + pb >= best already loses: skip its orientation and area */
        double papb = pa + pb;
        if (!(papb < best))
          continue;
        int ti = tri_index(x, y, w);
        if (tri_orient(h, ti, x, y, w) <= 0)
          continue;
        double val = papb + tri_area_at(h, ti, x, y, w);
        if (val < best) {
          best = val;
          bk = k;
        }
      }
      t->P[a][b] = best;
      t->K[a][b] = (int8_t)bk;
    }
  /* fan steps: (v, p_a, p_b) has the orientation of (p_a, p_b, v), and v
   * is local point n, the largest */
  for (int a = 0; a < n; a++)
    t->W[a][a] = INFINITY;
  for (int a = 0; a < n; a++)
    for (int b = a + 1; b < n; b++) {
      t->W[a][b] = t->W[b][a] = INFINITY;
      int ti = tri_index(a, b, n);
      int o = tri_orient(h, ti, a, b, n);
      if (o > 0 && t->P[a][b] < INFINITY)
        t->W[a][b] = tri_area_at(h, ti, a, b, n) + t->P[a][b];
      else if (o < 0 && t->P[b][a] < INFINITY) {
        /* (b, a) turns counter-clockwise: its area, the same bits */
        t->W[b][a] = tri_area(h, n, b, a) + t->P[b][a];
      }
    }
  for (int a = 0; a < n; a++) {
    int c = 0;
    for (int o = 1, b = a + 1 == n ? 0 : a + 1; o <= n;
         o++, b = b + 1 == n ? 0 : b + 1) {
      if (t->W[a][b] < INFINITY) {
        t->off[a][c] = (int8_t)o;
        t->ws[a][c++] = t->W[a][b];
      }
      if (h->fixed[b])
        break;
    }
    t->nstep[a] = c;
  }
}

/* Shortest fan path from spoke `start` once around v (closed) or from
 * spoke 0 to n-1 (open); positions j = 0..last stand for spoke
 * (start + j) mod n. Returns its value when below `bound`; otherwise
 * something not below it. Positions whose value reached the bound are not
 * expanded: a step adds a non-negative area, and a rounded sum of
 * non-negative doubles is never below either term, so no path through
 * them ends below the bound, and every value below it is the same as
 * without the cut (same bits, same `from`). bound INFINITY: no cut. */
static double fan_path(const hole *h, dp *t, int start, double bound)
{
  int n = h->n, last = h->closed ? n : n - 1;
  for (int j = 0; j <= last; j++) {
    t->D[j] = INFINITY;
    t->from[j] = -1;
  }
  t->D[0] = 0.0;
  /* a: spoke (start + i) mod n, kept by wrapping instead of dividing; the
   * steps with infinite cost, which never lower a value, are not listed */
  for (int i = 0, a = start; i < last; i++, a = a + 1 == n ? 0 : a + 1) {
    if (!(t->D[i] < bound))
      continue;
    double di = t->D[i];
    for (int k = 0; k < t->nstep[a]; k++) {
      int j = i + t->off[a][k];
      if (j > last)
        break;
      double val = di + t->ws[a][k];
      if (val < t->D[j]) {
        t->D[j] = val;
        t->from[j] = (int8_t)i;
      }
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
  h->nstar = h->nslots = d;
  /* the neighbours across the link edges */
  bool grow = (closed ? 2 * d : 2 * d + 1) <= MAXN;
  /* first every neighbour's apex, then the tests: the loads of the
   * neighbours (often cache misses) overlap instead of waiting on each
   * other's tests */
  for (int i = 0; i < d; i++) {
    int32_t le = tt__next(spokes[i]), f = m->twin[le];
    apex[i] = !grow || f < 0 || (m->eflag[le] & TT__EDGE_CONSTRAINED)
                  ? -1
                  : tt__mesh_apex(m, f);
  }
  for (int i = 0; i < d; i++) {
    int32_t w = apex[i];
    bool in_star = w == v;
    for (int k = 0; k < nlink && !in_star; k++)
      in_star = link[k] == w;
    if (in_star)
      apex[i] = -1;
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
  for (int i = 0; i <= h->n; i++) {
    int32_t w = i < h->n ? h->p[i] : v;
    h->id[i] = w;
    h->c[i] = m->v[w].c;
    h->r[i] = m->v[w].r;
    h->z[i] = tt__mesh_z(m, w);
  }
  h->ground = m->gxy != NULL;
  for (int i = 0; h->ground && i <= h->n; i++) {
    const double *g = m->gxy + 2 * ((size_t)h->r[i] * m->gnx +
                                    (size_t)h->c[i]);
    h->gx[i] = g[0];
    h->gy[i] = g[1];
  }
  int nt = tri_index(h->n - 2, h->n - 1, h->n) + 1;
  for (int i = 0; i < nt; i++)
    h->orient[i] = 2;
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
  /* Just the star, no neighbour admitted, around 3 outline points: the
   * current triangles are then the only triangulation with v as a vertex
   * and every triangle strictly counter-clockwise -- closed: a fan step
   * over a link vertex would pair (v, p_a, p_a+2) with its reverse; open
   * (v on the outline between p_2 and p_0): the only other one has
   * (v, p_0, p_2), which must then not turn counter-clockwise (v on the
   * boundary segment p_0-p_2 after a split). The DP would find their area
   * again, summed in another order: a few ulps apart, a tie by tt__snap,
   * kept. */
  if (h.n == 3 && h.nslots == h.nstar &&
      (h.closed || tt__mesh_orient(m, v, h.p[0], h.p[2]) <= 0))
    return link_edges(m, v, opposite, max);
  tt__geo_frame(env, h.fr);
  double now = 0.0;
  for (int i = 0; i < h.nslots; i++) {
    int32_t e = 3 * h.slots[i];
    now += mesh_area(&h, m->hv[e], m->hv[e + 1], m->hv[e + 2]);
  }
  fill_pockets(&h, &t);
  /* the best start: the first fixed spoke, or every spoke; only a value
   * below `now` can replace the current triangles, so it bounds the
   * search from the start (a start whose value is not below the bound
   * cannot be the first strict minimum that changes anything) */
  int first = 0, nstart = h.closed ? h.n : 1;
  for (int i = 0; i < h.n && h.closed; i++)
    if (h.fixed[i]) {
      first = i;
      nstart = 1;
      break;
    }
  double best = now < INFINITY ? now : INFINITY;
  int bstart = -1;
  for (int s = first; s < first + nstart; s++) {
    double val = fan_path(&h, &t, s, best);
    if (val < best) {
      best = val;
      bstart = s;
    }
  }
  if (bstart < 0 || !(tt__snap(now - best, now + best) > 0))
    return link_edges(m, v, opposite, max); /* keep the current one */
  /* the triangles: the fan steps of the best path, then their pockets */
  fan_path(&h, &t, bstart, INFINITY);
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
