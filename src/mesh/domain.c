/*
 * domain.c -- the valid domain of a grid with nodata, made into the
 * starting triangulation of refinement.
 *
 * The domain D is the union over grid cells of the valid part of each cell:
 * the whole cell when its four corners are valid, the triangle of its three
 * valid corners when one is nodata, nothing otherwise. Its
 * outline is made of unit lattice segments: the long side of every
 * three-valid cell, and every axis edge between two valid samples that
 * exactly one of its two cells carries. The TIN follows not that outline
 * but a lean polygon P that separates the same samples with fewer
 * vertices (see "the lean outline" below): P holds D and adds only regions
 * without samples. P's vertices are inserted into a Delaunay triangulation
 * of the valid samples' convex hull, and each of its segments is then
 * recovered as a constrained edge by flips (Sloan 1993: the edges crossing
 * the segment are flipped until the segment appears; each queued edge is
 * kept by its two vertices, since flips rewrite half-edge slots). Finally
 * the triangles outside P are deleted: with P in the mesh, each triangle
 * lies wholly on one side, told by the segments' orientation. Refinement
 * then only splits triangles and flips unconstrained inner edges, so the
 * TIN never leaves P, and a valid sample stays uncovered exactly when no
 * valid cell part holds it.
 *
 * Memory: three bytes per sample (outline directions, traced steps, kept
 * vertices) while building, and the current chain's corners. Time: linear
 * in the samples, and in the outline's corners times the 128 one segment
 * may replace.
 *
 * Part of src/mesh/, the mesh stage: the half-edge mesh, the samples a
 * triangle owns, the nodata domain.
 */
#include "mesh/domain.h"

#include "base/predicates.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* the eight unit steps, indexed so that d ^ 4 is the opposite step */
static const int DX[8] = {1, 1, 0, -1, -1, -1, 0, 1};
static const int DY[8] = {0, 1, 1, 1, 0, -1, -1, -1};

static inline bool ok_at(const tt_grid *g, int64_t x, int64_t y)
{
  return x >= 0 && y >= 0 && (size_t)x < g->nx && (size_t)y < g->ny &&
         !isnan(tt__grid_z(g, (size_t)y * g->nx + (size_t)x));
}

/* valid corners of cell (x, y): corners (x..x+1, y..y+1); 0 off the grid */
static int cell_valid(const tt_grid *g, int64_t x, int64_t y)
{
  if (x < 0 || y < 0 || (size_t)x + 1 >= g->nx || (size_t)y + 1 >= g->ny)
    return 0;
  return ok_at(g, x, y) + ok_at(g, x + 1, y) + ok_at(g, x, y + 1) +
         ok_at(g, x + 1, y + 1);
}

static int dir_of(int dx, int dy)
{
  for (int d = 0; d < 8; d++)
    if (DX[d] == dx && DY[d] == dy)
      return d;
  return -1;
}

static void mark(uint8_t *dirs, const tt_grid *g, int64_t x, int64_t y,
                 int dx, int dy)
{
  dirs[(size_t)y * g->nx + (size_t)x] |= (uint8_t)(1u << dir_of(dx, dy));
  dirs[(size_t)(y + dy) * g->nx + (size_t)(x + dx)] |=
      (uint8_t)(1u << dir_of(-dx, -dy));
}

/* Validity of row y into v[0 .. nx - 1]: all 0 past the last row. */
static void valid_row(const tt_grid *g, int64_t y, uint8_t *v)
{
  size_t nx = g->nx;
  if ((size_t)y >= g->ny) {
    memset(v, 0, nx);
    return;
  }
  for (size_t x = 0; x < nx; x++)
    v[x] = !isnan(tt__grid_z(g, (size_t)y * nx + x));
}

/* cell_valid() of a row of cells from the validity of its two rows of
 * samples (va above, vb below): 0 in the last column, and all 0 when the
 * row is not a row of cells (in false). */
static void cell_row(const uint8_t *va, const uint8_t *vb, size_t nx,
                     bool in, uint8_t *c)
{
  for (size_t x = 0; x + 1 < nx; x++)
    c[x] = in ? (uint8_t)(va[x] + va[x + 1] + vb[x] + vb[x + 1]) : 0;
  c[nx - 1] = 0;
}

/* The outline as unit-step directions per sample. One pass down the
 * rows with the validity of two sample rows and the corner counts of two
 * cell rows at hand (scratch: 4 nx bytes), where asking ok_at() and
 * cell_valid() per sample read each height about nine times. */
static void outline(const tt_grid *g, uint8_t *dirs, uint8_t *scratch)
{
  int64_t nx = (int64_t)g->nx, ny = (int64_t)g->ny;
  uint8_t *va = scratch, *vb = scratch + nx;   /* rows y, y + 1 */
  uint8_t *cprev = scratch + 2 * nx, *ccur = scratch + 3 * nx; /* cells
                                                   of rows y - 1, y */
  memset(cprev, 0, (size_t)nx);
  valid_row(g, 0, va);
  for (int64_t y = 0; y < ny; y++) {
    valid_row(g, y + 1, vb);
    cell_row(va, vb, (size_t)nx, y + 1 < ny, ccur);
    for (int64_t x = 0; x < nx; x++) {
      if (!va[x])
        continue;
      /* axis edge to the right: cells above (x, y-1) and below (x, y) */
      if (x + 1 < nx && va[x + 1] && (cprev[x] >= 3) != (ccur[x] >= 3))
        mark(dirs, g, x, y, 1, 0);
      /* axis edge downwards: cells left (x-1, y) and right (x, y) */
      if (vb[x] && ((x > 0 ? ccur[x - 1] : 0) >= 3) != (ccur[x] >= 3))
        mark(dirs, g, x, y, 0, 1);
    }
    /* the long side of every three-valid cell */
    for (int64_t x = 0; x + 1 < nx; x++) {
      if (ccur[x] != 3)
        continue;
      if (!va[x] || !vb[x + 1])
        mark(dirs, g, x + 1, y, -1, 1); /* (x+1,y) - (x,y+1) */
      else
        mark(dirs, g, x, y, 1, 1);      /* (x,y) - (x+1,y+1) */
    }
    uint8_t *t = va;
    va = vb;
    vb = t;
    t = cprev;
    cprev = ccur;
    ccur = t;
  }
}

typedef struct vmap {
  int64_t *key;   /* sample index, sorted */
  int32_t *vid;
  size_t n;
} vmap;

static int32_t vmap_get(const vmap *vm, int64_t key)
{
  size_t lo = 0, hi = vm->n;
  while (lo < hi) {
    size_t mid = lo + (hi - lo) / 2;
    if (vm->key[mid] < key)
      lo = mid + 1;
    else
      hi = mid;
  }
  return lo < vm->n && vm->key[lo] == key ? vm->vid[lo] : -1;
}

/* --- edge recovery ------------------------------------------------------ */

typedef struct vpair {
  int32_t a, b;
} vpair;

typedef struct queue {
  vpair *q;
  size_t head, n, cap;
} queue;

static bool q_push(queue *q, int32_t a, int32_t b)
{
  if (q->head > 0 && q->head == q->n) {
    q->head = q->n = 0;
  }
  if (!tt__grow((void **)&q->q, &q->cap, q->n + 1, sizeof(vpair)))
    return false;
  q->q[q->n].a = a;
  q->q[q->n].b = b;
  q->n++;
  return true;
}

static inline int orient_v(const tt__mesh *m, int32_t a, int32_t b, int32_t c)
{
  return tt__orient_i(m->v[a].c, m->v[a].r, m->v[b].c, m->v[b].r, m->v[c].c,
                      m->v[c].r);
}

/* Whether vertex c lies strictly between a and b on segment ab. */
static bool between(const tt__mesh *m, int32_t a, int32_t b, int32_t c)
{
  if (orient_v(m, a, b, c) != 0)
    return false;
  int64_t ax = m->v[a].c, ay = m->v[a].r, bx = m->v[b].c, by = m->v[b].r;
  int64_t cx = m->v[c].c, cy = m->v[c].r;
  int64_t dot1 = (cx - ax) * (bx - ax) + (cy - ay) * (by - ay);
  int64_t dot2 = (cx - bx) * (ax - bx) + (cy - by) * (ay - by);
  return dot1 > 0 && dot2 > 0;
}

/* Whether segments pq and ab cross at a point interior to both. */
static bool crosses(const tt__mesh *m, int32_t p, int32_t q, int32_t a,
                    int32_t b)
{
  int o1 = orient_v(m, a, b, p), o2 = orient_v(m, a, b, q);
  int o3 = orient_v(m, p, q, a), o4 = orient_v(m, p, q, b);
  return o1 * o2 < 0 && o3 * o4 < 0;
}

static void constrain(tt__mesh *m, int32_t e)
{
  m->eflag[e] |= TT__EDGE_CONSTRAINED;
  if (m->twin[e] >= 0)
    m->eflag[m->twin[e]] |= TT__EDGE_CONSTRAINED;
}

/* Recovers segment ab as a constrained edge (splitting it at vertices
 * that lie on it). Returns false when out of memory or when the mesh
 * defeats the recovery (then ok is cleared: the caller falls back). */
static bool recover(tt__mesh *m, int32_t a, int32_t b, queue *q, int depth,
                    bool *ok)
{
  int32_t e = tt__mesh_find_edge(m, a, b);
  if (e < 0)
    e = tt__mesh_find_edge(m, b, a);
  if (e >= 0) {
    constrain(m, e);
    return true;
  }
  if (depth > 64) {
    *ok = false;
    return true;
  }
  /* collect the edges crossing ab, walking from a's star */
  q->head = q->n = 0;
  int32_t e0 = m->v[a].edge, f = e0;
  int32_t start = -1;
  /* turn around a (both directions, the star may touch the boundary) */
  for (int pass = 0; pass < 2 && start < 0; pass++) {
    f = e0;
    do {
      int32_t p = m->hv[tt__next(f)], r = m->hv[tt__prev(f)];
      if (between(m, a, b, p))
        return recover(m, a, p, q, depth + 1, ok) &&
               recover(m, p, b, q, depth + 1, ok);
      if (crosses(m, p, r, a, b)) {
        start = tt__next(f); /* the edge p -> r opposite a */
        break;
      }
      int32_t g = pass == 0 ? m->twin[tt__prev(f)] : m->twin[f];
      if (g < 0)
        break;
      f = pass == 0 ? g : tt__next(g);
    } while (f != e0);
  }
  if (start < 0) {
    *ok = false;
    return true;
  }
  int32_t cur = start;
  size_t guard = 0;
  for (;;) {
    int32_t p = m->hv[cur], r = m->hv[tt__next(cur)];
    if (!q_push(q, p, r))
      return false;
    int32_t tw = m->twin[cur];
    if (tw < 0 || ++guard > 4 * m->nlive + 8) {
      *ok = false;
      return true;
    }
    int32_t s = tt__mesh_apex(m, tw);
    if (s == b)
      break;
    if (between(m, a, b, s))
      return recover(m, a, s, q, depth + 1, ok) &&
             recover(m, s, b, q, depth + 1, ok);
    /* tw = r -> p in triangle (r, p, s): the segment leaves it through
     * p -> s (next of tw) or s -> r (prev of tw) */
    cur = crosses(m, p, s, a, b) ? tt__next(tw) : tt__prev(tw);
  }
  /* flip crossing edges away */
  size_t budget = 64 * (q->n + 8) * (q->n + 8);
  while (q->head < q->n) {
    if (budget-- == 0) {
      *ok = false;
      return true;
    }
    vpair pr = q->q[q->head++];
    int32_t h = tt__mesh_find_edge(m, pr.a, pr.b);
    if (h < 0 || m->twin[h] < 0)
      continue; /* flipped away already */
    if ((m->eflag[h] & TT__EDGE_CONSTRAINED) || !tt__mesh_flippable(m, h)) {
      if (!q_push(q, pr.a, pr.b))
        return false;
      continue;
    }
    int32_t d = tt__mesh_flip(m, h);
    if (d < 0)
      return false;
    int32_t c0 = m->hv[d], c1 = m->hv[tt__next(d)];
    if (crosses(m, c0, c1, a, b) && !q_push(q, c0, c1))
      return false;
  }
  e = tt__mesh_find_edge(m, a, b);
  if (e < 0)
    e = tt__mesh_find_edge(m, b, a);
  if (e < 0) {
    *ok = false;
    return true;
  }
  constrain(m, e);
  return true;
}

bool tt__domain_recover_segment(tt__mesh *m, int32_t a, int32_t b,
                                bool *out_ok)
{
  queue q = {NULL, 0, 0, 0};
  *out_ok = true;
  bool done = recover(m, a, b, &q, 0, out_ok);
  free(q.q);
  return done;
}

/* Whether triangle t lies in the domain. No triangle crosses the outline
 * once it is recovered, so one interior point decides: the centroid, exact
 * in thrice-scaled integer coordinates. The cell holding it decides in
 * turn: wholly valid, or three-valid with the point in its valid half. */
static bool centroid_in_domain(const tt_grid *g, const tt__mesh *m,
                               int32_t t)
{
  int64_t X = 0, Y = 0;
  for (int k = 0; k < 3; k++) {
    const tt__mesh_vertex *v = &m->v[m->hv[3 * t + k]];
    X += v->c;
    Y += v->r;
  }
  int64_t cx = X / 3, cy = Y / 3; /* coordinates are >= 0 */
  int nvalid = cell_valid(g, cx, cy);
  if (nvalid == 4)
    return true;
  if (nvalid < 3)
    return false;
  /* the three valid corners, scaled by 3 like the centroid */
  int64_t vx[3], vy[3];
  int n = 0;
  for (int k = 0; k < 4; k++) {
    int64_t x = cx + (k & 1), y = cy + (k >> 1);
    if (ok_at(g, x, y)) {
      vx[n] = 3 * x;
      vy[n] = 3 * y;
      n++;
    }
  }
  int pos = 0, neg = 0;
  for (int k = 0; k < 3; k++) {
    int o = tt__orient_i(vx[k], vy[k], vx[(k + 1) % 3], vy[(k + 1) % 3], X, Y);
    pos += o > 0;
    neg += o < 0;
  }
  return pos == 0 || neg == 0;
}

/* --- the lean outline --------------------------------------------------- */

/* The outline is drawn as a separating polygon with few vertices: each
 * unit step is directed with the domain on its left (tt__orient_i > 0),
 * the steps form chains between samples where the outline does not simply
 * pass (degree other than 2: pinches where two loops touch) or closed
 * loops, and each chain is string-pulled greedily: a run of its corners
 * c[a..j] is replaced by the segment c[a] c[j] when every corner lies left
 * of or on it and the region Q between the segment and the chain holds no
 * lattice point but the chain's own. The polygon then only grows, by
 * regions free of samples: every valid sample of the domain stays inside,
 * every nodata sample outside, and no other part of the outline can enter
 * Q (its vertices would be samples in Q), so the polygon stays simple. Q's
 * emptiness is exact by Pick's theorem (2 area = 2 interior + boundary - 2)
 * on each piece of Q between the corners that lie on the segment. Corners
 * on the grid's border stay vertices and no segment runs along a border
 * unless the outline does: a tile's border samples are covered exactly as
 * the old outline covered them, which tile/border.c relies on. */

#define LEAN_MAX_CORNERS 128 /* corners one segment may replace */

/* Whether the domain lies left of the unit step from (x, y) in direction d
 * (the step is an outline step). Axis steps: the cell on the left carries
 * it (three or four valid corners). Diagonals: the cell's valid third
 * corner is on the left. */
static bool domain_left(const tt_grid *g, int64_t x, int64_t y, int d)
{
  int64_t dx = DX[d], dy = DY[d];
  if (dx == 0 || dy == 0) {
    int64_t lx = -dy, ly = dx; /* left normal: cross((dx,dy),(lx,ly)) = 1 */
    int64_t cx = x < x + dx ? x : x + dx, cy = y < y + dy ? y : y + dy;
    if (lx < 0)
      cx -= 1;
    if (ly < 0)
      cy -= 1;
    return cell_valid(g, cx, cy) >= 3;
  }
  if (ok_at(g, x + dx, y)) /* corner (x+dx, y): cross = -dx dy */
    return -dx * dy > 0;
  return dx * dy > 0;
}

static inline int popcount8(uint8_t b)
{
  int n = 0;
  for (; b; b &= (uint8_t)(b - 1))
    n++;
  return n;
}

typedef struct pt {
  int64_t x, y;
} pt;

typedef struct lean {
  const tt_grid *g;
  const uint8_t *dirs;
  uint8_t *seen;      /* per sample: directed steps already traced */
  uint8_t *keep;      /* per sample: 1 = a vertex of the lean outline */
  pt *c;              /* the chain being traced: its corners */
  size_t nc, ccap;
  int64_t *seg;       /* segments as pairs of sample indices, left = in */
  size_t nseg, segcap;
} lean;

static int64_t gcd64(int64_t a, int64_t b)
{
  if (a < 0)
    a = -a;
  if (b < 0)
    b = -b;
  while (b) {
    int64_t t = a % b;
    a = b;
    b = t;
  }
  return a;
}

static int64_t steps_between(pt p, pt q)
{
  int64_t dx = llabs(q.x - p.x), dy = llabs(q.y - p.y);
  return dx > dy ? dx : dy;
}

/* Whether the piece c[s..t] of the chain (every corner strictly between
 * left of segment c[s] c[t], or t == s + 1) closed by that segment
 * encloses no lattice point but the chain's. */
static bool piece_empty(const pt *c, size_t s, size_t t)
{
  if (t == s + 1)
    return true; /* a straight run on the segment */
  if (gcd64(c[t].x - c[s].x, c[t].y - c[s].y) != 1)
    return false; /* a lattice point on the open segment */
  int64_t area2 = 0, steps = 0;
  for (size_t k = s; k < t; k++) {
    int64_t ax = c[k].x - c[s].x, ay = c[k].y - c[s].y;
    int64_t bx = c[k + 1].x - c[s].x, by = c[k + 1].y - c[s].y;
    area2 += ax * by - ay * bx;
    steps += steps_between(c[k], c[k + 1]);
  }
  if (area2 < 0)
    area2 = -area2;
  /* boundary points: steps + 1 on the chain, none on the open segment */
  return area2 == steps - 1;
}

static bool on_border(const tt_grid *g, pt p)
{
  return p.x == 0 || p.y == 0 || (size_t)p.x + 1 == g->nx ||
         (size_t)p.y + 1 == g->ny;
}

/* Whether p and q lie on one side of the grid's border. */
static bool same_border(const tt_grid *g, pt p, pt q)
{
  return (p.x == 0 && q.x == 0) || (p.y == 0 && q.y == 0) ||
         ((size_t)p.x + 1 == g->nx && (size_t)q.x + 1 == g->nx) ||
         ((size_t)p.y + 1 == g->ny && (size_t)q.y + 1 == g->ny);
}

/* Whether segment c[a] c[j] may replace the corners c[a+1 .. j-1]. */
static bool shortcut_ok(const tt_grid *g, const pt *c, size_t a, size_t j)
{
  pt p = c[a], q = c[j];
  if (same_border(g, p, q))
    return false;
  size_t s = a;
  for (size_t k = a + 1; k <= j; k++) {
    int o = k == j ? 0 : tt__orient_i(p.x, p.y, q.x, q.y, c[k].x, c[k].y);
    if (o < 0)
      return false;
    if (o > 0)
      continue;
    if (k < j) {
      int64_t d1 = (c[k].x - p.x) * (q.x - p.x) + (c[k].y - p.y) * (q.y - p.y);
      int64_t d2 = (c[k].x - q.x) * (p.x - q.x) + (c[k].y - q.y) * (p.y - q.y);
      if (d1 <= 0 || d2 <= 0)
        return false; /* on the line but off the segment */
    }
    if (!piece_empty(c, s, k))
      return false;
    s = k;
  }
  return true;
}

static bool push_corner(lean *L, int64_t x, int64_t y)
{
  if (!tt__grow((void **)&L->c, &L->ccap, L->nc + 1, sizeof(pt)))
    return false;
  L->c[L->nc].x = x;
  L->c[L->nc].y = y;
  L->nc++;
  return true;
}

static bool push_seg(lean *L, pt p, pt q)
{
  if (!tt__grow((void **)&L->seg, &L->segcap, 2 * L->nseg + 2,
                sizeof(int64_t)))
    return false;
  L->seg[2 * L->nseg] = p.y * (int64_t)L->g->nx + p.x;
  L->seg[2 * L->nseg + 1] = q.y * (int64_t)L->g->nx + q.x;
  L->nseg++;
  return true;
}

/* String-pulls the traced chain L->c[0 .. nc-1] into segments. */
static bool pull(lean *L)
{
  const pt *c = L->c;
  size_t last = L->nc - 1, a = 0;
  L->keep[(size_t)c[0].y * L->g->nx + (size_t)c[0].x] = 1;
  while (a < last) {
    size_t best = a + 1, fails = 0;
    for (size_t j = a + 2; j <= last && j <= a + LEAN_MAX_CORNERS; j++) {
      if (on_border(L->g, c[j - 1]))
        break; /* border corners stay */
      if (shortcut_ok(L->g, c, a, j)) {
        best = j;
        fails = 0;
      } else if (++fails > 4) {
        break;
      }
    }
    if (!push_seg(L, c[a], c[best]))
      return false;
    L->keep[(size_t)c[best].y * L->g->nx + (size_t)c[best].x] = 1;
    a = best;
  }
  return true;
}

static uint8_t out_dirs(const tt_grid *g, const uint8_t *dirs, size_t i)
{
  uint8_t o = 0;
  int64_t x = (int64_t)(i % g->nx), y = (int64_t)(i / g->nx);
  for (int d = 0; d < 8; d++)
    if ((dirs[i] & (1u << d)) && domain_left(g, x, y, d))
      o |= (uint8_t)(1u << d);
  return o;
}

/* Traces the chain leaving sample i in direction d up to the next sample
 * of degree other than 2 or back to i, then pulls it. */
static bool trace(lean *L, size_t i, int d)
{
  const tt_grid *g = L->g;
  int64_t x = (int64_t)(i % g->nx), y = (int64_t)(i / g->nx);
  L->nc = 0;
  if (!push_corner(L, x, y))
    return false;
  for (;;) {
    size_t p = (size_t)y * g->nx + (size_t)x;
    L->seen[p] |= (uint8_t)(1u << d);
    x += DX[d];
    y += DY[d];
    size_t q = (size_t)y * g->nx + (size_t)x;
    if (q == i || popcount8(L->dirs[q]) != 2)
      break;
    int nd = -1;
    for (int k = 0; k < 8; k++)
      if ((L->dirs[q] & (1u << k)) && k != (d ^ 4))
        nd = k;
    if (nd < 0 || !domain_left(g, x, y, nd))
      break; /* not a simple pass: end the chain here */
    if (nd != d && !push_corner(L, x, y))
      return false;
    d = nd;
  }
  return push_corner(L, x, y) && pull(L);
}

/* Fills L->keep and L->seg: the chains from samples of degree other than
 * 2 first, then the closed loops, each from its first sample in row order
 * (a corner: no straight run passes the first sample of a loop). */
static bool lean_outline(lean *L)
{
  const tt_grid *g = L->g;
  size_t n = g->nx * g->ny;
  for (int pass = 0; pass < 2; pass++)
    for (size_t i = 0; i < n; i++) {
      if (!L->dirs[i] || (popcount8(L->dirs[i]) == 2) != (pass == 1))
        continue;
      uint8_t o = out_dirs(g, L->dirs, i);
      for (int d = 0; d < 8; d++)
        if ((o & (1u << d)) && !(L->seen[i] & (1u << d)) && !trace(L, i, d))
          return false;
    }
  return true;
}

/* --- inside and outside --------------------------------------------------- */

enum { SIDE_NONE = 0, SIDE_IN = 1, SIDE_OUT = 2 };

/* Labels the triangles on both sides of the recovered segment a -> b
 * (the domain on its left), piece by piece where recovery split it at
 * vertices on it. False when a piece is missing. */
static bool label_segment(const tt__mesh *m, int32_t a, int32_t b,
                          uint8_t *side)
{
  int32_t cur = a;
  size_t guard = 0;
  while (cur != b) {
    if (++guard > m->nv + 1)
      return false;
    int32_t w = -1, e0 = m->v[cur].edge;
    for (int pass = 0; pass < 2 && w < 0; pass++) {
      int32_t f = e0;
      do {
        int32_t p = m->hv[tt__next(f)], r = m->hv[tt__prev(f)];
        if (p == b || between(m, cur, b, p))
          w = p;
        else if (r == b || between(m, cur, b, r))
          w = r;
        if (w >= 0)
          break;
        int32_t gg = pass == 0 ? m->twin[tt__prev(f)] : m->twin[f];
        if (gg < 0)
          break;
        f = pass == 0 ? gg : tt__next(gg);
      } while (f != e0);
    }
    if (w < 0)
      return false;
    int32_t h[2] = {tt__mesh_find_edge(m, cur, w), tt__mesh_find_edge(m, w, cur)};
    for (int k = 0; k < 2; k++) {
      if (h[k] < 0)
        continue;
      int32_t apex = m->hv[tt__prev(h[k])];
      uint8_t s = orient_v(m, cur, w, apex) > 0 ? SIDE_IN : SIDE_OUT;
      int32_t t = h[k] / 3;
      if (side[t] && side[t] != s)
        return false;
      side[t] = s;
    }
    cur = w;
  }
  return true;
}

/* Spreads the labels across unconstrained edges; a triangle no label
 * reaches (a part of the hull the outline does not bound) takes the old
 * domain's verdict on its centroid. False on a contradiction. */
static bool spread_sides(const tt_grid *g, const tt__mesh *m, uint8_t *side,
                         int32_t *stack)
{
  for (int round = 0; round < 2; round++)
    for (size_t t0 = 0; t0 < m->nslots; t0++) {
      if (!tt__mesh_live(m, (int32_t)t0) ||
          (round == 0 ? !side[t0] : side[t0] != SIDE_NONE))
        continue;
      if (round == 1)
        side[t0] = centroid_in_domain(g, m, (int32_t)t0) ? SIDE_IN : SIDE_OUT;
      size_t top = 0;
      stack[top++] = (int32_t)t0;
      while (top) {
        int32_t t = stack[--top];
        for (int k = 0; k < 3; k++) {
          int32_t e = 3 * t + k, tw = m->twin[e];
          if (tw < 0 || (m->eflag[e] & TT__EDGE_CONSTRAINED))
            continue;
          int32_t u = tw / 3;
          if (side[u] == side[t])
            continue;
          if (side[u] != SIDE_NONE)
            return false;
          side[u] = side[t];
          stack[top++] = u;
        }
      }
    }
  return true;
}

/* --- the whole step ----------------------------------------------------- */

tt_status tt__domain_build(tt_context *ctx, tt__mesh *m, const tt_grid *g,
                           const tt__criterion_vt *crit,
                           const tt__crit_env *env, tt__edge_stack *stack,
                           tt__domain_add_vertex add_vertex, void *add_arg)
{
  tt_status status = TT_OK;
  size_t n = g->nx * g->ny;
  /* outline directions, traced steps, kept vertices, outline()'s scratch */
  uint8_t *dirs = calloc(3 * n + 4 * g->nx, 1);
  vmap vm = {NULL, NULL, 0};
  queue q = {NULL, 0, 0, 0};
  lean L;
  memset(&L, 0, sizeof L);
  uint8_t *side = NULL;
  int32_t *tstack = NULL;
  if (!dirs) {
    status = tt__error(ctx, TT_ERR_NOMEM, "out of memory for the nodata "
                       "outline (%zu bytes)", 3 * n + 4 * g->nx);
    goto done;
  }
  outline(g, dirs, dirs + 3 * n);
  L.g = g;
  L.dirs = dirs;
  L.seen = dirs + n;
  L.keep = dirs + 2 * n;
  if (!lean_outline(&L))
    goto oom;

  /* 1. the lean outline's vertices become vertices (walk-located
   *    insertion, Delaunay-repaired, in row order so walks stay short) */
  int32_t last = -1;
  for (size_t i = 0; i < n; i++) {
    if (!L.keep[i])
      continue;
    int64_t x = (int64_t)(i % g->nx), y = (int64_t)(i / g->nx);
    int32_t on;
    int32_t t = tt__mesh_locate(m, last, x, y, &on);
    if (t < 0) {
      status = tt__error(ctx, TT_ERR_INTERNAL, "outline sample (%lld, %lld) "
                         "is outside the valid samples' hull",
                         (long long)x, (long long)y);
      goto done;
    }
    last = t;
    if (on <= -2)
      continue; /* already a vertex (a hull corner) */
    int32_t v;
    if (!add_vertex(add_arg, (int32_t)x, (int32_t)y, &v))
      goto oom;
    int32_t opp[4];
    int nopp;
    bool split = on < 0 ? tt__mesh_split_triangle(m, t, v, opp)
                        : tt__mesh_split_edge(m, on, v, opp);
    nopp = on < 0 ? 3 : 4;
    if (!split || tt__swap_repair(m, crit, env, opp, nopp, stack) < 0)
      goto oom;
    last = m->v[v].edge >= 0 ? m->v[v].edge / 3 : -1;
  }

  /* 2. sample -> vertex map */
  vm.key = malloc((m->nv ? m->nv : 1) * sizeof *vm.key);
  vm.vid = malloc((m->nv ? m->nv : 1) * sizeof *vm.vid);
  if (!vm.key || !vm.vid)
    goto oom;
  {
    /* vertices are added in increasing sample order except the hull's:
     * sort all by sample index (insertion sort would be quadratic) */
    int64_t *tmp = malloc((m->nv ? m->nv : 1) * sizeof *tmp);
    if (!tmp)
      goto oom;
    for (size_t v = 0; v < m->nv; v++)
      tmp[v] = ((int64_t)m->v[v].r * (int64_t)g->nx + m->v[v].c) << 31 |
               (int64_t)v;
    /* heap sort on int64 keys (no comparator context needed) */
    size_t cnt = m->nv;
    for (size_t k = cnt / 2; k-- > 0;) {
      size_t i = k;
      for (;;) {
        size_t c = 2 * i + 1;
        if (c >= cnt)
          break;
        if (c + 1 < cnt && tmp[c + 1] > tmp[c])
          c++;
        if (tmp[i] >= tmp[c])
          break;
        int64_t s = tmp[i];
        tmp[i] = tmp[c];
        tmp[c] = s;
        i = c;
      }
    }
    for (size_t end = cnt; end > 1; end--) {
      int64_t s = tmp[0];
      tmp[0] = tmp[end - 1];
      tmp[end - 1] = s;
      size_t i = 0;
      for (;;) {
        size_t c = 2 * i + 1;
        if (c >= end - 1)
          break;
        if (c + 1 < end - 1 && tmp[c + 1] > tmp[c])
          c++;
        if (tmp[i] >= tmp[c])
          break;
        int64_t s2 = tmp[i];
        tmp[i] = tmp[c];
        tmp[c] = s2;
        i = c;
      }
    }
    for (size_t k = 0; k < cnt; k++) {
      vm.key[k] = tmp[k] >> 31;
      vm.vid[k] = (int32_t)(tmp[k] & 0x7fffffff);
    }
    vm.n = cnt;
    free(tmp);
  }

  /* 3. every segment of the lean outline becomes a constrained edge */
  bool ok = true;
  for (size_t k = 0; k < L.nseg && ok; k++) {
    int32_t a = vmap_get(&vm, L.seg[2 * k]), b = vmap_get(&vm, L.seg[2 * k + 1]);
    if (a < 0 || b < 0) {
      ok = false;
      break;
    }
    if (!recover(m, a, b, &q, 0, &ok))
      goto oom;
  }
  if (!ok) {
    status = tt__error(ctx, TT_ERR_INTERNAL, "could not recover the nodata "
                       "outline as mesh edges");
    goto done;
  }
  /* the constrained Delaunay triangulation of the outline */
  if (tt__swap_all(m, crit, env, stack) < 0)
    goto oom;

  /* 4. delete the triangles outside the polygon: the left of every
   *    segment is inside, spread across unconstrained edges */
  side = calloc(m->nslots ? m->nslots : 1, 1);
  tstack = malloc((m->nslots ? m->nslots : 1) * sizeof *tstack);
  if (!side || !tstack)
    goto oom;
  for (size_t k = 0; k < L.nseg && ok; k++)
    ok = label_segment(m, vmap_get(&vm, L.seg[2 * k]),
                       vmap_get(&vm, L.seg[2 * k + 1]), side);
  if (!ok || !spread_sides(g, m, side, tstack)) {
    status = tt__error(ctx, TT_ERR_INTERNAL, "the nodata outline does not "
                       "separate the mesh into inside and outside");
    goto done;
  }
  for (size_t t = 0; t < m->nslots; t++)
    if (tt__mesh_live(m, (int32_t)t) && side[t] == SIDE_OUT &&
        !tt__mesh_delete_triangle(m, (int32_t)t))
      goto oom;
  tt__mesh_fix_vertex_edges(m);
  goto done;
oom:
  status = tt__error(ctx, TT_ERR_NOMEM, "out of memory while following the "
                     "nodata outline");
done:
  free(dirs);
  free(L.c);
  free(L.seg);
  free(side);
  free(tstack);
  free(vm.key);
  free(vm.vid);
  free(q.q);
  return status;
}
