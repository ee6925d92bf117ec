/*
 * domain.c -- the valid domain of a grid with nodata, made into the
 * starting triangulation of refinement.
 *
 * The domain D is the union over grid cells of the valid part of each cell:
 * the whole cell when its four corners are valid, the triangle of its three
 * valid corners when one is nodata, nothing otherwise. Its
 * outline is made of unit lattice segments: the long side of every
 * three-valid cell, and every axis edge between two valid samples that
 * exactly one of its two cells carries. Straight runs of the outline are
 * merged (the samples between lie on the merged edge, so they stay
 * covered); the corners become vertices of a Delaunay triangulation of the
 * valid samples' convex hull, and every run is then recovered as a
 * constrained edge by flips (Sloan 1993: the edges crossing the segment are
 * flipped until the segment appears; each queued edge is kept by its two
 * vertices, since flips rewrite half-edge slots). Finally the triangles
 * outside D are deleted: with the outline in the mesh, each triangle lies
 * wholly inside or wholly outside D. Refinement then only splits triangles
 * and flips unconstrained inner edges, so the TIN never leaves D, and a
 * valid sample stays uncovered exactly when no valid cell part holds it.
 *
 * Memory: one byte per sample (outline directions) while building.
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

/* A sample in the middle of a straight run: two opposite directions. */
static inline bool straight(uint8_t d)
{
  for (int k = 0; k < 4; k++)
    if (d == (uint8_t)((1u << k) | (1u << (k + 4))))
      return true;
  return false;
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

/* --- the whole step ----------------------------------------------------- */

tt_status tt__domain_build(tt_context *ctx, tt__mesh *m, const tt_grid *g,
                           const tt__criterion_vt *crit,
                           const tt__crit_env *env, tt__edge_stack *stack,
                           tt__domain_add_vertex add_vertex, void *add_arg)
{
  tt_status status = TT_OK;
  size_t n = g->nx * g->ny;
  uint8_t *dirs = calloc(n + 4 * g->nx, 1); /* + outline()'s scratch */
  vmap vm = {NULL, NULL, 0};
  queue q = {NULL, 0, 0, 0};
  if (!dirs) {
    status = tt__error(ctx, TT_ERR_NOMEM, "out of memory for the nodata "
                       "outline (%zu bytes)", n + 4 * g->nx);
    goto done;
  }
  outline(g, dirs, dirs + n);

  /* 1. the outline's corners become vertices (walk-located insertion,
   *    Delaunay-repaired, in row order so walks stay short) */
  int32_t last = -1;
  for (size_t i = 0; i < n; i++) {
    if (!dirs[i] || straight(dirs[i]))
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

  /* 3. every straight run of the outline becomes a constrained edge */
  bool ok = true;
  for (size_t i = 0; i < n && ok; i++) {
    if (!dirs[i] || straight(dirs[i]))
      continue;
    int64_t x = (int64_t)(i % g->nx), y = (int64_t)(i / g->nx);
    for (int d = 0; d < 8 && ok; d++) {
      if (!(dirs[i] & (1u << d)))
        continue;
      int64_t ex = x + DX[d], ey = y + DY[d];
      while (straight(dirs[(size_t)ey * g->nx + (size_t)ex])) {
        ex += DX[d];
        ey += DY[d];
      }
      size_t j = (size_t)ey * g->nx + (size_t)ex;
      if (j < i)
        continue; /* each run once, from its smaller end */
      int32_t a = vmap_get(&vm, (int64_t)i), b = vmap_get(&vm, (int64_t)j);
      if (a < 0 || b < 0) {
        ok = false;
        break;
      }
      if (!recover(m, a, b, &q, 0, &ok))
        goto oom;
    }
  }
  if (!ok) {
    status = tt__error(ctx, TT_ERR_INTERNAL, "could not recover the nodata "
                       "outline as mesh edges");
    goto done;
  }
  /* the constrained Delaunay triangulation of the outline */
  if (tt__swap_all(m, crit, env, stack) < 0)
    goto oom;

  /* 4. delete the triangles outside the domain */
  for (size_t t = 0; t < m->nslots; t++)
    if (tt__mesh_live(m, (int32_t)t) && !centroid_in_domain(g, m, (int32_t)t) &&
        !tt__mesh_delete_triangle(m, (int32_t)t))
      goto oom;
  tt__mesh_fix_vertex_edges(m);
  goto done;
oom:
  status = tt__error(ctx, TT_ERR_NOMEM, "out of memory while following the "
                     "nodata outline");
done:
  free(dirs);
  free(vm.key);
  free(vm.vid);
  free(q.q);
  return status;
}
