/*
 * mesh.c -- the only writer of the half-edge arrays of mesh.h.
 *
 * Operations: add vertices and triangles, split a triangle or an edge at a
 * new vertex, flip an edge, validate. Each keeps the invariants listed in
 * mesh.h and logs the triangle slots it wrote. Workload: greedy refinement
 * does one split and a few flips per inserted vertex, so operations are
 * O(1) with amortised array growth; validate() is O(V + T) and meant for
 * tests.
 *
 * Part of src/mesh/, the mesh stage: the half-edge mesh, the samples a
 * triangle owns, the nodata domain.
 */
#include "mesh/mesh.h"

#include "base/predicates.h"

#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void tt__mesh_init(tt__mesh *m, const tt__metric *metric)
{
  static atomic_uint_fast64_t serials = 1;
  memset(m, 0, sizeof *m);
  m->metric = *metric;
  m->serial = (uint64_t)atomic_fetch_add(&serials, 1);
}

/* One more version of v's star (when tracked). */
static inline void bump(tt__mesh *m, int32_t v)
{
  if (m->vver)
    m->vver[v]++;
}

static void bump_slot(tt__mesh *m, int32_t t)
{
  if (m->vver && m->hv[3 * t] >= 0)
    for (int k = 0; k < 3; k++)
      m->vver[m->hv[3 * t + k]]++;
}

bool tt__mesh_track_stars(tt__mesh *m)
{
  if (m->vver)
    return true;
  size_t cap = 0;
  uint32_t *p = NULL;
  if (!tt__grow((void **)&p, &cap, m->vcap > 16 ? m->vcap : 16, sizeof *p))
    return false;
  memset(p, 0, cap * sizeof *p);
  m->vver = p;
  m->vvercap = cap;
  return true;
}

bool tt__mesh_keep_f64(tt__mesh *m)
{
  if (m->vz)
    return true;
  size_t cap = 0;
  double *p = NULL;
  if (!tt__grow((void **)&p, &cap, m->vcap > 16 ? m->vcap : 16, sizeof *p))
    return false;
  for (size_t i = 0; i < m->nv; i++)
    p[i] = (double)m->v[i].z;
  m->vz = p;
  m->vzcap = cap;
  return true;
}

void tt__mesh_free(tt__mesh *m)
{
  free(m->v);
  free(m->vz);
  free(m->hv);
  free(m->twin);
  free(m->eflag);
  free(m->freelist);
  free(m->touched);
  free(m->vver);
  memset(m, 0, sizeof *m);
}

static bool grow_vertices(tt__mesh *m, size_t need)
{
  if (m->vver && need > m->vvercap) {
    size_t old = m->vvercap;
    if (!tt__grow((void **)&m->vver, &m->vvercap, need, sizeof(uint32_t)))
      return false;
    memset(m->vver + old, 0, (m->vvercap - old) * sizeof(uint32_t));
  }
  if (m->vz && need > m->vzcap &&
      !tt__grow((void **)&m->vz, &m->vzcap, need, sizeof(double)))
    return false;
  return tt__grow((void **)&m->v, &m->vcap, need, sizeof(tt__mesh_vertex));
}

static bool grow_triangles(tt__mesh *m, size_t need)
{
  if (need <= m->tcap)
    return true;
  if (need > (size_t)INT32_MAX / 3)
    return false;
  size_t ncap = m->tcap < 16 ? 16 : m->tcap + m->tcap / 2;
  if (ncap < need)
    ncap = need;
  if (ncap > (size_t)INT32_MAX / 3)
    ncap = (size_t)INT32_MAX / 3;
  size_t c1 = 3 * m->tcap, c2 = 3 * m->tcap, c3 = 3 * m->tcap;
  if (!tt__grow((void **)&m->hv, &c1, 3 * ncap, sizeof(int32_t)) ||
      !tt__grow((void **)&m->twin, &c2, 3 * ncap, sizeof(int32_t)) ||
      !tt__grow((void **)&m->eflag, &c3, 3 * ncap, sizeof(uint8_t)))
    return false;
  m->tcap = ncap;
  return true;
}

bool tt__mesh_reserve(tt__mesh *m, size_t nv, size_t nt)
{
  return grow_vertices(m, nv) && grow_triangles(m, nt);
}

int32_t tt__mesh_add_vertex(tt__mesh *m, int32_t col, int32_t row, double z)
{
  if (m->nv >= TT_MAX_VERTICES || !grow_vertices(m, m->nv + 1))
    return -1;
  int32_t v = (int32_t)m->nv++;
  m->v[v].c = col;
  m->v[v].r = row;
  m->v[v].z = (float)z;
  if (m->vz)
    m->vz[v] = z;
  m->v[v].edge = -1;
  return v;
}

/* Takes a slot (recycled or new) and reserves room in the touched log, so
 * that the operations below cannot fail half-way: callers take all their
 * slots first. */
static int32_t take_slot(tt__mesh *m)
{
  if (!tt__grow((void **)&m->touched, &m->touchedcap, m->ntouched + 4,
                sizeof(int32_t)))
    return -1;
  if (m->nfree > 0)
    return m->freelist[--m->nfree];
  if (!grow_triangles(m, m->nslots + 1))
    return -1;
  int32_t t = (int32_t)m->nslots++;
  m->hv[3 * t] = -1;
  return t;
}

/* Returns an unused slot to the free list (used when an operation has to
 * give back slots it took before failing). */
static void give_back(tt__mesh *m, int32_t t)
{
  /* the free list has room: it held this slot before, or the slot is new
   * and the list's capacity grows with the slots in release_slot */
  if (!tt__grow((void **)&m->freelist, &m->freecap, m->nfree + 1,
                sizeof(int32_t))) {
    /* cannot happen for slots taken from the free list; for a new slot at
     * the end, shrink the slot count instead */
    if ((size_t)t + 1 == m->nslots)
      m->nslots--;
    return;
  }
  m->hv[3 * t] = -1;
  m->freelist[m->nfree++] = t;
}

/* Writes triangle (a, b, c) into slot t with the given twins (-1 allowed)
 * and constraint flags, and fixes the twins' back links. */
static void set_triangle(tt__mesh *m, int32_t t, int32_t a, int32_t b,
                         int32_t c)
{
  int32_t e = 3 * t;
  if (m->hv[e] < 0)
    m->nlive++;
  m->hv[e] = a;
  m->hv[e + 1] = b;
  m->hv[e + 2] = c;
  m->twin[e] = m->twin[e + 1] = m->twin[e + 2] = -1;
  m->eflag[e] = m->eflag[e + 1] = m->eflag[e + 2] = 0;
  m->v[a].edge = e;
  m->v[b].edge = e + 1;
  m->v[c].edge = e + 2;
  m->touched[m->ntouched++] = t;
}

/* Links half-edges e and f (f may be -1: e becomes a boundary edge). The
 * constraint flag is taken from `flag`. */
static void link(tt__mesh *m, int32_t e, int32_t f, uint8_t flag)
{
  m->twin[e] = f;
  m->eflag[e] = flag;
  if (f >= 0) {
    m->twin[f] = e;
    m->eflag[f] = flag;
  }
}

int32_t tt__mesh_add_triangle(tt__mesh *m, int32_t a, int32_t b, int32_t c)
{
  int32_t t = take_slot(m);
  if (t < 0)
    return -1;
  set_triangle(m, t, a, b, c);
  bump_slot(m, t);
  return t;
}

bool tt__mesh_link_all(tt__mesh *m)
{
  /* Bucket the unlinked half-edges by start vertex (a counting sort,
   * O(E + V)) and pair each a -> b with the b -> a in b's bucket (a
   * degree's worth of entries). Once per starting triangulation, which
   * for decimation's start is the whole grid (a sort of the half-edges
   * took 40 % of a 513^2 decimation). Memory: 4 bytes per unlinked
   * half-edge and per vertex, while linking. */
  size_t n = 0, nv = m->nv;
  for (size_t e = 0; e < 3 * m->nslots; e++)
    if (m->hv[e - e % 3] >= 0 && m->twin[e] < 0)
      n++;
  size_t *first = calloc(nv + 1, sizeof *first);
  int32_t *bucket = malloc((n ? n : 1) * sizeof *bucket);
  if (!first || !bucket) {
    free(first);
    free(bucket);
    return false;
  }
  for (size_t e = 0; e < 3 * m->nslots; e++)
    if (m->hv[e - e % 3] >= 0 && m->twin[e] < 0)
      first[m->hv[e] + 1]++;
  for (size_t v = 0; v < nv; v++)
    first[v + 1] += first[v];
  /* fill in half-edge order, so each bucket is sorted (deterministic) */
  for (size_t e = 0; e < 3 * m->nslots; e++)
    if (m->hv[e - e % 3] >= 0 && m->twin[e] < 0)
      bucket[first[m->hv[e]]++] = (int32_t)e;
  for (size_t v = nv; v > 0; v--)
    first[v] = first[v - 1];
  first[0] = 0;
  for (size_t i = 0; i < n; i++) {
    int32_t e = bucket[i];
    if (m->twin[e] >= 0)
      continue;
    int32_t a = m->hv[e], b = m->hv[tt__next(e)];
    for (size_t j = first[b]; j < first[b + 1]; j++) {
      int32_t f = bucket[j];
      if (m->twin[f] < 0 && m->hv[tt__next(f)] == a) {
        link(m, e, f, 0);
        bump(m, a);
        bump(m, b);
        break;
      }
    }
  }
  free(first);
  free(bucket);
  return true;
}

int tt__mesh_orient(const tt__mesh *m, int32_t a, int32_t b, int32_t c)
{
  return m->metric.det_sign *
         tt__orient_i(m->v[a].c, m->v[a].r, m->v[b].c, m->v[b].r, m->v[c].c,
                      m->v[c].r);
}

void tt__mesh_use_ground_points(tt__mesh *m, const double *gxy, size_t nx)
{
  m->gxy = gxy;
  m->gnx = nx;
}

static inline const double *ground_point(const tt__mesh *m, int32_t v)
{
  return m->gxy + 2 * ((size_t)m->v[v].r * m->gnx + (size_t)m->v[v].c);
}

int tt__mesh_incircle(const tt__mesh *m, int32_t a, int32_t b, int32_t c,
                      int32_t d)
{
  if (m->gxy) {
    const double *pa = ground_point(m, a), *pb = ground_point(m, b),
                 *pc = ground_point(m, c);
    int o = tt__orient2d(pa, pb, pc);
    if (o != 0)
      return o * tt__incircle(pa, pb, pc, ground_point(m, d));
  }
  return tt__incircle_metric(&m->metric, m->v[a].c, m->v[a].r, m->v[b].c,
                             m->v[b].r, m->v[c].c, m->v[c].r, m->v[d].c,
                             m->v[d].r);
}

bool tt__mesh_split_triangle(tt__mesh *m, int32_t t, int32_t p,
                             int32_t out_opposite[3])
{
  int32_t t1 = take_slot(m);
  if (t1 < 0)
    return false;
  int32_t t2 = take_slot(m);
  if (t2 < 0) {
    give_back(m, t1);
    return false;
  }
  int32_t e0 = 3 * t;
  int32_t a = m->hv[e0], b = m->hv[e0 + 1], c = m->hv[e0 + 2];
  int32_t o_ab = m->twin[e0], o_bc = m->twin[e0 + 1], o_ca = m->twin[e0 + 2];
  uint8_t f_ab = m->eflag[e0], f_bc = m->eflag[e0 + 1],
          f_ca = m->eflag[e0 + 2];
  /*
   *            c                      c
   *           / \                    /|\
   *          /   \                  / | \      t  = (a, b, p)
   *         /  t  \       ==>      /t2p t1\    t1 = (b, c, p)
   *        a-------b               a-------b   t2 = (c, a, p)
   */
  set_triangle(m, t, a, b, p);
  set_triangle(m, t1, b, c, p);
  set_triangle(m, t2, c, a, p);
  bump_slot(m, t1);
  bump(m, a);
  link(m, 3 * t, o_ab, f_ab);
  link(m, 3 * t1, o_bc, f_bc);
  link(m, 3 * t2, o_ca, f_ca);
  link(m, 3 * t + 1, 3 * t1 + 2, 0);  /* b->p with p->b */
  link(m, 3 * t1 + 1, 3 * t2 + 2, 0); /* c->p with p->c */
  link(m, 3 * t2 + 1, 3 * t + 2, 0);  /* a->p with p->a */
  out_opposite[0] = 3 * t;
  out_opposite[1] = 3 * t1;
  out_opposite[2] = 3 * t2;
  return true;
}

bool tt__mesh_split_edge(tt__mesh *m, int32_t e, int32_t p,
                         int32_t out_opposite[4])
{
  int32_t f = m->twin[e];
  int32_t t = e / 3, u = f >= 0 ? f / 3 : -1;
  int32_t t1 = take_slot(m);
  if (t1 < 0)
    return false;
  int32_t u1 = -1;
  if (f >= 0) {
    u1 = take_slot(m);
    if (u1 < 0) {
      give_back(m, t1);
      return false;
    }
  }
  int32_t a = m->hv[e], b = m->hv[tt__next(e)], c = m->hv[tt__prev(e)];
  int32_t o_bc = m->twin[tt__next(e)], o_ca = m->twin[tt__prev(e)];
  uint8_t f_bc = m->eflag[tt__next(e)], f_ca = m->eflag[tt__prev(e)];
  uint8_t f_ab = m->eflag[e];
  int32_t d = -1, o_ad = -1, o_db = -1;
  uint8_t f_ad = 0, f_db = 0;
  if (f >= 0) {
    d = m->hv[tt__prev(f)];
    o_ad = m->twin[tt__next(f)];
    o_db = m->twin[tt__prev(f)];
    f_ad = m->eflag[tt__next(f)];
    f_db = m->eflag[tt__prev(f)];
  }
  /*
   *          c                        c
   *         / \                      /|\
   *        / t \                    / | \      t  = (c, a, p)
   *       a-----b       ==>        a--p--b     t1 = (c, p, b)
   *        \ u /                    \ | /      u  = (d, b, p)
   *         \ /                      \|/       u1 = (d, p, a)
   *          d                        d
   */
  set_triangle(m, t, c, a, p);
  set_triangle(m, t1, c, p, b);
  bump_slot(m, t);
  bump(m, b);
  if (d >= 0)
    bump(m, d);
  link(m, 3 * t, o_ca, f_ca);
  link(m, 3 * t1 + 2, o_bc, f_bc);
  link(m, 3 * t + 2, 3 * t1, 0); /* p->c with c->p */
  out_opposite[0] = 3 * t;
  out_opposite[1] = 3 * t1 + 2;
  if (f >= 0) {
    set_triangle(m, u, d, b, p);
    set_triangle(m, u1, d, p, a);
    link(m, 3 * u, o_db, f_db);
    link(m, 3 * u1 + 2, o_ad, f_ad);
    link(m, 3 * u + 2, 3 * u1, 0);     /* p->d with d->p */
    link(m, 3 * t + 1, 3 * u1 + 1, f_ab); /* a->p with p->a */
    link(m, 3 * t1 + 1, 3 * u + 1, f_ab); /* p->b with b->p */
    out_opposite[2] = 3 * u;
    out_opposite[3] = 3 * u1 + 2;
  } else {
    link(m, 3 * t + 1, -1, f_ab); /* the halves keep its flags */
    link(m, 3 * t1 + 1, -1, f_ab);
    out_opposite[2] = out_opposite[3] = -1;
  }
  return true;
}

bool tt__mesh_flippable(const tt__mesh *m, int32_t e)
{
  int32_t f = m->twin[e];
  if (f < 0 || (m->eflag[e] & TT__EDGE_CONSTRAINED))
    return false;
  int32_t a = m->hv[e], b = m->hv[f];
  int32_t c = m->hv[tt__prev(e)], d = m->hv[tt__prev(f)];
  /* Strictly convex iff the segment c-d separates a and b strictly (a, b, c
   * and b, a, d are already strictly counter-clockwise). */
  return tt__mesh_orient(m, c, d, b) > 0 && tt__mesh_orient(m, d, c, a) > 0;
}

int32_t tt__mesh_flip(tt__mesh *m, int32_t e)
{
  int32_t f = m->twin[e];
  int32_t t = e / 3, u = f / 3;
  int32_t a = m->hv[e], b = m->hv[f];
  int32_t c = m->hv[tt__prev(e)], d = m->hv[tt__prev(f)];
  int32_t o_bc = m->twin[tt__next(e)], o_ca = m->twin[tt__prev(e)];
  int32_t o_ad = m->twin[tt__next(f)], o_db = m->twin[tt__prev(f)];
  uint8_t f_bc = m->eflag[tt__next(e)], f_ca = m->eflag[tt__prev(e)];
  uint8_t f_ad = m->eflag[tt__next(f)], f_db = m->eflag[tt__prev(f)];
  if (!tt__grow((void **)&m->touched, &m->touchedcap, m->ntouched + 2,
                sizeof(int32_t)))
    return -1; /* out of memory: nothing changed */
  m->nlive -= 2; /* set_triangle counts them live again */
  m->hv[3 * t] = -1;
  m->hv[3 * u] = -1;
  set_triangle(m, t, c, a, d);
  set_triangle(m, u, d, b, c);
  bump(m, a);
  bump(m, b);
  bump(m, c);
  bump(m, d);
  link(m, 3 * t, o_ca, f_ca);
  link(m, 3 * t + 1, o_ad, f_ad);
  link(m, 3 * u, o_db, f_db);
  link(m, 3 * u + 1, o_bc, f_bc);
  link(m, 3 * t + 2, 3 * u + 2, 0); /* d->c with c->d */
  return 3 * t + 2;
}

bool tt__mesh_delete_triangle(tt__mesh *m, int32_t t)
{
  if (!tt__grow((void **)&m->freelist, &m->freecap, m->nfree + 1,
                sizeof(int32_t)))
    return false;
  bump_slot(m, t);
  for (int k = 0; k < 3; k++) {
    int32_t f = m->twin[3 * t + k];
    if (f >= 0) {
      m->twin[f] = -1;
      m->eflag[f] = 0;
    }
    m->twin[3 * t + k] = -1;
  }
  m->hv[3 * t] = -1;
  m->nlive--;
  m->freelist[m->nfree++] = t;
  return true;
}

void tt__mesh_fix_vertex_edges(tt__mesh *m)
{
  for (size_t v = 0; v < m->nv; v++)
    m->v[v].edge = -1;
  for (size_t e = 0; e < 3 * m->nslots; e++)
    if (m->hv[e - e % 3] >= 0)
      m->v[m->hv[e]].edge = (int32_t)e;
}

int32_t tt__mesh_find_edge(const tt__mesh *m, int32_t a, int32_t b)
{
  int32_t e0 = m->v[a].edge;
  if (e0 < 0)
    return -1;
  /* around a one way (through twin(prev)), then the other way (through
   * next(twin)) in case a boundary stopped the first turn */
  int32_t e = e0;
  do {
    if (m->hv[tt__next(e)] == b)
      return e;
    int32_t f = m->twin[tt__prev(e)];
    if (f < 0)
      break;
    e = f;
  } while (e != e0);
  e = e0;
  for (;;) {
    int32_t f = m->twin[e];
    if (f < 0)
      return -1;
    e = tt__next(f);
    if (e == e0)
      return -1;
    if (m->hv[tt__next(e)] == b)
      return e;
  }
}

/* Where (col, row) is in triangle t: 1 outside edge *out_k, 0 inside or on
 * (sets *out_on as tt__mesh_locate does). */
static int where_in(const tt__mesh *m, int32_t t, int64_t col, int64_t row,
                    int *out_k, int32_t *out_on)
{
  int s = m->metric.det_sign, zero = -1, nzero = 0;
  for (int k = 0; k < 3; k++) {
    int32_t a = m->hv[3 * t + k], b = m->hv[3 * t + (k + 1) % 3];
    int o = s * tt__orient_i(m->v[a].c, m->v[a].r, m->v[b].c, m->v[b].r,
                             col, row);
    if (o < 0) {
      *out_k = k;
      return 1;
    }
    if (o == 0) {
      zero = k;
      nzero++;
    }
  }
  if (nzero == 0) {
    *out_on = -1;
  } else if (nzero == 1) {
    *out_on = 3 * t + zero;
  } else {
    /* on two edges: a corner */
    for (int k = 0; k < 3; k++) {
      int32_t v = m->hv[3 * t + k];
      if (m->v[v].c == col && m->v[v].r == row)
        *out_on = -2 - v;
    }
  }
  return 0;
}

int32_t tt__mesh_locate(const tt__mesh *m, int32_t start, int64_t col,
                        int64_t row, int32_t *out_on)
{
  int32_t t = start;
  if (t < 0 || !tt__mesh_live(m, t))
    for (t = 0; (size_t)t < m->nslots && !tt__mesh_live(m, t); t++)
      ;
  if ((size_t)t >= m->nslots)
    return -1;
  size_t limit = 4 * m->nlive + 16;
  int k = 0;
  for (size_t step = 0; step < limit; step++) {
    if (!where_in(m, t, col, row, &k, out_on))
      return t;
    int32_t f = m->twin[3 * t + k];
    if (f < 0)
      break; /* outside this way; a scan decides */
    t = f / 3;
  }
  for (size_t u = 0; u < m->nslots; u++)
    if (tt__mesh_live(m, (int32_t)u) &&
        !where_in(m, (int32_t)u, col, row, &k, out_on))
      return (int32_t)u;
  return -1;
}

/* --- validation --------------------------------------------------------- */

static int32_t uf_find(int32_t *parent, int32_t x)
{
  while (parent[x] != x) {
    parent[x] = parent[parent[x]];
    x = parent[x];
  }
  return x;
}

bool tt__mesh_validate(const tt__mesh *m, char *why, size_t whylen)
{
#define FAIL(...)                                                            \
  do {                                                                       \
    snprintf(why, whylen, __VA_ARGS__);                                      \
    ok = false;                                                              \
    goto done;                                                               \
  } while (0)
  bool ok = true;
  int32_t *parent = NULL;
  uint8_t *used = NULL;
  uint8_t *seen = NULL;
  size_t live = 0, half_interior = 0, boundary = 0;

  parent = malloc((m->nslots ? m->nslots : 1) * sizeof *parent);
  used = calloc(m->nv ? m->nv : 1, 1);
  seen = calloc(3 * m->nslots + 1, 1);
  if (!parent || !used || !seen)
    FAIL("out of memory while validating");

  for (size_t t = 0; t < m->nslots; t++) {
    parent[t] = (int32_t)t;
    if (m->hv[3 * t] < 0)
      continue;
    live++;
    for (int k = 0; k < 3; k++) {
      int32_t e = (int32_t)(3 * t) + k;
      int32_t v = m->hv[e];
      if (v < 0 || (size_t)v >= m->nv)
        FAIL("triangle %zu: vertex %d out of range", t, v);
      used[v] = 1;
    }
    int32_t a = m->hv[3 * t], b = m->hv[3 * t + 1], c = m->hv[3 * t + 2];
    if (a == b || b == c || c == a)
      FAIL("triangle %zu repeats a vertex (%d %d %d)", t, a, b, c);
    if (tt__mesh_orient(m, a, b, c) <= 0)
      FAIL("triangle %zu (%d %d %d) is not counter-clockwise in the ground "
           "frame", t, a, b, c);
  }
  if (live != m->nlive)
    FAIL("live triangle count %zu, recorded %zu", live, m->nlive);
  for (size_t i = 0; i < m->nfree; i++) {
    int32_t t = m->freelist[i];
    if (t < 0 || (size_t)t >= m->nslots || m->hv[3 * t] >= 0)
      FAIL("free list entry %zu (slot %d) is not a free slot", i, t);
  }
  if (live + m->nfree != m->nslots)
    FAIL("%zu live + %zu free != %zu slots", live, m->nfree, m->nslots);

  for (size_t e = 0; e < 3 * m->nslots; e++) {
    if (m->hv[e - e % 3] < 0)
      continue;
    int32_t f = m->twin[e];
    int32_t a = m->hv[e], b = m->hv[tt__next((int32_t)e)];
    if (f < 0) {
      boundary++;
      continue;
    }
    half_interior++;
    if ((size_t)f >= 3 * m->nslots || m->hv[f - f % 3] < 0)
      FAIL("half-edge %zu: twin %d is not live", e, f);
    if (m->twin[f] != (int32_t)e)
      FAIL("half-edge %zu: twin %d does not point back (%d)", e, f,
           m->twin[f]);
    if (m->hv[f] != b || m->hv[tt__next(f)] != a)
      FAIL("half-edge %zu (%d->%d): twin %d is not its reverse", e, a, b, f);
    if (m->eflag[e] != m->eflag[f])
      FAIL("half-edge %zu: constraint flag differs from its twin", e);
    int32_t r1 = uf_find(parent, (int32_t)(e / 3)), r2 = uf_find(parent, f / 3);
    if (r1 != r2)
      parent[r1] = r2;
  }
  size_t nvused = 0;
  for (size_t v = 0; v < m->nv; v++) {
    if (!used[v]) {
      if (m->v[v].edge >= 0)
        FAIL("vertex %zu is in no triangle but has an edge", v);
      continue;
    }
    nvused++;
    int32_t e = m->v[v].edge;
    if (e < 0 || (size_t)e >= 3 * m->nslots || m->hv[e - e % 3] < 0 ||
        m->hv[e] != (int32_t)v)
      FAIL("vertex %zu: its edge %d does not leave it", v, e);
  }
  /* Euler: V - E + F = 2C - L, with E = interior/2 + boundary. */
  {
    size_t comps = 0;
    for (size_t t = 0; t < m->nslots; t++)
      if (m->hv[3 * t] >= 0 && uf_find(parent, (int32_t)t) == (int32_t)t)
        comps++;
    size_t loops = 0;
    for (size_t e = 0; e < 3 * m->nslots; e++) {
      if (m->hv[e - e % 3] < 0 || m->twin[e] >= 0 || seen[e])
        continue;
      loops++;
      /* walk the boundary loop: from half-edge e (a->b), the next boundary
       * half-edge leaves b: rotate around b through interior edges */
      int32_t cur = (int32_t)e;
      size_t guard = 0;
      while (!seen[cur]) {
        seen[cur] = 1;
        int32_t g = tt__next(cur); /* leaves b */
        while (m->twin[g] >= 0) {
          g = tt__next(m->twin[g]);
          if (++guard > 6 * m->nslots + 6)
            FAIL("boundary walk does not close near half-edge %d", cur);
        }
        cur = g;
      }
    }
    long long chi = (long long)nvused - (long long)(half_interior / 2) -
                    (long long)boundary + (long long)live;
    long long want = 2 * (long long)comps - (long long)loops;
    if (chi != want)
      FAIL("Euler: V - E + F = %lld, expected 2C - L = %lld (V %zu, "
           "interior half-edges %zu, boundary %zu, F %zu, C %zu, L %zu)",
           chi, want, nvused, half_interior, boundary, live, comps, loops);
  }
done:
  free(parent);
  free(used);
  free(seen);
  return ok;
#undef FAIL
}

/* --- undoable flips (optimize.c) ----------------------------------------
 * The look-ahead optimiser tries a flip, scores the edges around it and
 * takes it back. A second flip would give the same triangles back, but in
 * the other slots and rotated, so every half-edge index would change and
 * both slots would need rescanning. tt__mesh_flip_revert instead restores
 * the saved words exactly, and the touched log with them. */

int32_t tt__mesh_flip_undoable(tt__mesh *m, int32_t e,
                               tt__mesh_flip_undo *out_undo)
{
  int32_t f = m->twin[e];
  int32_t slot[2] = {e / 3, f / 3};
  out_undo->ntouched = m->ntouched;
  for (int s = 0; s < 2; s++) {
    out_undo->slot[s] = slot[s];
    for (int k = 0; k < 3; k++) {
      int32_t h = 3 * slot[s] + k;
      out_undo->hv[3 * s + k] = m->hv[h];
      out_undo->twin[3 * s + k] = m->twin[h];
      out_undo->eflag[3 * s + k] = m->eflag[h];
    }
  }
  int32_t quad[4] = {m->hv[e], m->hv[f], m->hv[tt__prev(e)],
                     m->hv[tt__prev(f)]};
  for (int k = 0; k < 4; k++) {
    out_undo->vert[k] = quad[k];
    out_undo->vedge[k] = m->v[quad[k]].edge;
  }
  return tt__mesh_flip(m, e);
}

void tt__mesh_flip_revert(tt__mesh *m, const tt__mesh_flip_undo *undo)
{
  for (int s = 0; s < 2; s++)
    for (int k = 0; k < 3; k++) {
      int32_t h = 3 * undo->slot[s] + k;
      m->hv[h] = undo->hv[3 * s + k];
      m->twin[h] = undo->twin[3 * s + k];
      m->eflag[h] = undo->eflag[3 * s + k];
    }
  /* the outer neighbours point back at the restored half-edges */
  for (int s = 0; s < 2; s++)
    for (int k = 0; k < 3; k++) {
      int32_t h = 3 * undo->slot[s] + k, o = m->twin[h];
      if (o >= 0) {
        m->twin[o] = h;
        m->eflag[o] = m->eflag[h];
      }
    }
  for (int k = 0; k < 4; k++) {
    m->v[undo->vert[k]].edge = undo->vedge[k];
    bump(m, undo->vert[k]);
  }
  m->ntouched = undo->ntouched;
}

/* --- region replacement (hole_dp.c) ---------------------------------------
 * Swaps a set of triangles for another triangulation of the same outline.
 * Everything that can fail (the outline check, memory) happens before the
 * first write, so a refusal leaves the mesh as it was. Regions are small
 * (the hole around one vertex): the edge matching is quadratic. */

bool tt__mesh_replace_region(tt__mesh *m, const int32_t *old_slots, int nold,
                             const int32_t (*tris)[3], int ntri)
{
  if (nold < 1 || ntri < 1 || nold > INT32_MAX / 3 || ntri > INT32_MAX / 3)
    return false;
  bool ok = false;
  int nhalf = 3 * ntri, nouter = 0, ntaken = 0;
  size_t nextra = ntri > nold ? (size_t)(ntri - nold) : 0;
  /* the outline: half-edges of the region whose twin is outside it, with
   * that twin and the constraint flag (read before any slot is rewritten);
   * per new half-edge 3 * t + k: the new half-edge it pairs with (>= 0),
   * or -2 - o for outline half-edge o; constrained edges inside the region
   * (a vertex inserted on one): the new triangles must have them too, and
   * they stay constrained. Small regions (every hole of refinement) live
   * on the stack, larger ones on the heap. */
  enum { SMALL = 32 };
  int32_t s_outer[3 * SMALL], s_otwin[3 * SMALL], s_pair[3 * SMALL],
      s_slot[SMALL], s_icons[3 * SMALL];
  uint8_t s_oflag[3 * SMALL], s_iflag[3 * SMALL];
  bool small = nold <= SMALL && ntri <= SMALL;
  int32_t *outer = small ? s_outer : malloc(3 * (size_t)nold * sizeof *outer);
  int32_t *otwin = small ? s_otwin : malloc(3 * (size_t)nold * sizeof *otwin);
  uint8_t *oflag = small ? s_oflag : malloc(3 * (size_t)nold);
  int32_t *pair = small ? s_pair : malloc((size_t)nhalf * sizeof *pair);
  int32_t *slot = small ? s_slot : malloc((size_t)ntri * sizeof *slot);
  int32_t *icons = small ? s_icons : malloc(3 * (size_t)nold * sizeof *icons);
  uint8_t *iflag = small ? s_iflag : malloc((size_t)nhalf);
  int nicons = 0;
  if (!outer || !otwin || !oflag || !pair || !slot || !icons || !iflag)
    goto done;
  for (int i = 0; i < nold; i++)
    for (int k = 0; k < 3; k++) {
      int32_t e = 3 * old_slots[i] + k, f = m->twin[e];
      bool inside = false;
      for (int j = 0; j < nold && f >= 0 && !inside; j++)
        inside = f / 3 == old_slots[j];
      if (!inside) {
        outer[nouter] = e;
        otwin[nouter] = f;
        oflag[nouter] = m->eflag[e];
        nouter++;
      } else if ((m->eflag[e] & TT__EDGE_CONSTRAINED) && e < f) {
        icons[nicons++] = e; /* an inner constrained edge, once */
      }
    }
  /* each new half-edge pairs with its reverse among the new triangles or
   * with the outline half-edge it takes the place of; each outline
   * half-edge exactly once */
  int used = 0;
  for (int h = 0; h < nhalf; h++) {
    int32_t a = tris[h / 3][h % 3], b = tris[h / 3][(h % 3 + 1) % 3];
    pair[h] = -1;
    for (int g = 0; g < nhalf && pair[h] == -1; g++)
      if (g != h && tris[g / 3][g % 3] == b &&
          tris[g / 3][(g % 3 + 1) % 3] == a)
        pair[h] = g;
    for (int o = 0; o < nouter && pair[h] == -1; o++)
      if (m->hv[outer[o]] == a && m->hv[tt__next(outer[o])] == b)
        pair[h] = -2 - o;
    if (pair[h] == -1)
      goto done; /* an edge of the new triangulation leads nowhere */
    used += pair[h] <= -2;
  }
  for (int h = 0; h < nhalf; h++) {
    if (pair[h] >= 0 && pair[pair[h]] != h)
      goto done; /* an inner edge used twice */
    for (int g = 0; g < h && pair[h] <= -2; g++)
      if (pair[g] == pair[h])
        goto done; /* an outline edge used twice */
  }
  if (used != nouter)
    goto done; /* part of the outline is not covered */
  for (int h = 0; h < nhalf; h++)
    iflag[h] = 0;
  for (int i = 0; i < nicons; i++) {
    int32_t a = m->hv[icons[i]], b = m->hv[tt__next(icons[i])];
    bool kept = false;
    for (int h = 0; h < nhalf; h++) {
      int32_t x = tris[h / 3][h % 3], y = tris[h / 3][(h % 3 + 1) % 3];
      if ((x == a && y == b) || (x == b && y == a)) {
        iflag[h] = m->eflag[icons[i]]; /* breakline bit included */
        kept = true;
      }
    }
    if (!kept)
      goto done; /* a constrained edge would vanish */
  }
  for (int t = 0; t < ntri; t++)
    if (tris[t][0] == tris[t][1] || tris[t][1] == tris[t][2] ||
        tris[t][2] == tris[t][0] ||
        tt__mesh_orient(m, tris[t][0], tris[t][1], tris[t][2]) <= 0)
      goto done;
  /* memory: the touched log, the free list, extra slots */
  if (!tt__grow((void **)&m->touched, &m->touchedcap,
                m->ntouched + (size_t)ntri + 4, sizeof(int32_t)) ||
      !tt__grow((void **)&m->freelist, &m->freecap,
                m->nfree + (size_t)nold, sizeof(int32_t)))
    goto done;
  for (int t = 0; t < ntri && t < nold; t++)
    slot[t] = old_slots[t];
  for (; (size_t)ntaken < nextra; ntaken++) {
    int32_t s = take_slot(m);
    if (s < 0) {
      while (ntaken > 0)
        give_back(m, slot[nold + --ntaken]);
      goto done;
    }
    slot[nold + ntaken] = s;
  }
  /* write. The region's vertices lose their edges; set_triangle gives one
   * back to every corner of a new triangle (the outline's vertices among
   * them), so only a vertex no triangle uses any more keeps -1. */
  for (int i = 0; i < nold; i++)
    for (int k = 0; k < 3; k++) {
      m->v[m->hv[3 * old_slots[i] + k]].edge = -1;
      bump(m, m->hv[3 * old_slots[i] + k]);
    }
  for (int i = 0; i < nold; i++) {
    m->hv[3 * old_slots[i]] = -1;
    m->nlive--;
  }
  for (int t = 0; t < ntri; t++) {
    set_triangle(m, slot[t], tris[t][0], tris[t][1], tris[t][2]);
    bump_slot(m, slot[t]);
  }
  for (int i = ntri; i < nold; i++)
    m->freelist[m->nfree++] = old_slots[i];
  for (int h = 0; h < nhalf; h++) {
    int32_t e = 3 * slot[h / 3] + h % 3;
    if (pair[h] >= 0)
      link(m, e, 3 * slot[pair[h] / 3] + pair[h] % 3, iflag[h]);
    else
      link(m, e, otwin[-2 - pair[h]], oflag[-2 - pair[h]]);
  }
  ok = true;
done:
  if (!small) {
    free(outer);
    free(otwin);
    free(oflag);
    free(pair);
    free(slot);
    free(icons);
    free(iflag);
  }
  return ok;
}

/* --- snapshots (anneal.c) -------------------------------------------------
 * Simulated annealing keeps the best triangulation seen while it wanders
 * through worse ones. Its undo log is bounded, so now and then it saves
 * the best one whole: the triangle and vertex-edge words, which flips (the
 * only writes between a snapshot and its restore) change in place, never
 * the slot count or the free list. */

bool tt__mesh_snapshot_take(const tt__mesh *m, tt__mesh_snapshot *s)
{
  size_t nh = 3 * m->nslots;
  if (s->cap_h < nh) {
    int32_t *hv = realloc(s->hv, (nh ? nh : 1) * sizeof *hv);
    if (hv)
      s->hv = hv;
    int32_t *tw = hv ? realloc(s->twin, (nh ? nh : 1) * sizeof *tw) : NULL;
    if (tw)
      s->twin = tw;
    uint8_t *fl = tw ? realloc(s->eflag, nh ? nh : 1) : NULL;
    if (!fl)
      return false;
    s->eflag = fl;
    s->cap_h = nh;
  }
  if (s->cap_v < m->nv) {
    int32_t *ve = realloc(s->vedge, m->nv * sizeof *ve);
    if (!ve)
      return false;
    s->vedge = ve;
    s->cap_v = m->nv;
  }
  if (nh) {
    memcpy(s->hv, m->hv, nh * sizeof *s->hv);
    memcpy(s->twin, m->twin, nh * sizeof *s->twin);
    memcpy(s->eflag, m->eflag, nh);
  }
  for (size_t i = 0; i < m->nv; i++)
    s->vedge[i] = m->v[i].edge;
  s->nslots = m->nslots;
  s->nv = m->nv;
  s->nlive = m->nlive;
  return true;
}

bool tt__mesh_snapshot_restore(tt__mesh *m, const tt__mesh_snapshot *s)
{
  if (s->nslots != m->nslots || s->nv != m->nv)
    return false;
  size_t nh = 3 * m->nslots;
  if (!tt__grow((void **)&m->touched, &m->touchedcap,
                m->ntouched + m->nslots, sizeof(int32_t)))
    return false;
  for (size_t t = 0; t < m->nslots; t++)
    bump_slot(m, (int32_t)t);
  if (nh) {
    memcpy(m->hv, s->hv, nh * sizeof *s->hv);
    memcpy(m->twin, s->twin, nh * sizeof *s->twin);
    memcpy(m->eflag, s->eflag, nh);
  }
  for (size_t i = 0; i < m->nv; i++)
    m->v[i].edge = s->vedge[i];
  m->nlive = s->nlive;
  for (size_t t = 0; t < m->nslots; t++)
    if (m->hv[3 * t] >= 0) {
      bump_slot(m, (int32_t)t);
      m->touched[m->ntouched++] = (int32_t)t;
    }
  return true;
}

void tt__mesh_snapshot_free(tt__mesh_snapshot *s)
{
  free(s->hv);
  free(s->twin);
  free(s->eflag);
  free(s->vedge);
  memset(s, 0, sizeof *s);
}

/* --- copies (curve.c) ------------------------------------------------- */

/* malloc of n elements of size elem copied from src (n = 0: one element,
 * so that NULL means only out of memory). */
static void *dup_array(const void *src, size_t n, size_t elem)
{
  void *p = malloc((n ? n : 1) * elem);
  if (p && n)
    memcpy(p, src, n * elem);
  return p;
}

bool tt__mesh_copy(tt__mesh *dst, const tt__mesh *src)
{
  tt__mesh_init(dst, &src->metric);
  dst->gxy = src->gxy;
  dst->gnx = src->gnx;
  size_t nh = 3 * src->nslots;
  dst->v = dup_array(src->v, src->nv, sizeof *src->v);
  dst->hv = dup_array(src->hv, nh, sizeof *src->hv);
  dst->twin = dup_array(src->twin, nh, sizeof *src->twin);
  dst->eflag = dup_array(src->eflag, nh, sizeof *src->eflag);
  dst->freelist = dup_array(src->freelist, src->nfree, sizeof *src->freelist);
  bool ok = dst->v && dst->hv && dst->twin && dst->eflag && dst->freelist;
  if (ok && src->vz)
    ok = (dst->vz = dup_array(src->vz, src->nv, sizeof *src->vz)) != NULL;
  if (ok && src->vver)
    ok = (dst->vver = dup_array(src->vver, src->nv, sizeof *src->vver)) !=
         NULL;
  if (!ok) {
    tt__mesh_free(dst);
    return false;
  }
  dst->nv = dst->vcap = src->nv;
  dst->vzcap = src->vz ? src->nv : 0;
  dst->vvercap = src->vver ? src->nv : 0;
  dst->nslots = dst->tcap = src->nslots;
  dst->nlive = src->nlive;
  dst->nfree = dst->freecap = src->nfree;
  return true;
}

/* The counter-clockwise walk of tt__mesh_star from half-edge e (leaving
 * v): the triangle of e is (v, a, b); the next one around v holds
 * twin(prev(e)) = v -> b. Stops at the boundary or back at e. */
static int star_walk(const tt__mesh *m, int32_t e, int32_t *ring,
                     int32_t *slots, int max, bool *out_closed)
{
  int n = 0, nt = 0;
  int32_t start = e;
  if (n < max)
    ring[n] = m->hv[tt__next(e)];
  n++;
  for (;;) {
    if (slots && nt < max)
      slots[nt] = e / 3;
    nt++;
    int32_t b = m->hv[tt__prev(e)];
    int32_t f = m->twin[tt__prev(e)];
    if (f < 0) {
      if (n < max)
        ring[n] = b;
      n++;
      *out_closed = false;
      return n;
    }
    if (f == start) {
      *out_closed = true;
      return n;
    }
    if (n < max)
      ring[n] = b;
    n++;
    e = f;
  }
}

int tt__mesh_star(const tt__mesh *m, int32_t v, int32_t *ring,
                  int32_t *slots, int max, bool *out_closed)
{
  int32_t e0 = m->v[v].edge;
  if (e0 < 0)
    return -1;
  /* one walk when the fan is closed (most vertices); otherwise turn
   * clockwise (e -> next(twin(e))) to the boundary and walk again */
  int n = star_walk(m, e0, ring, slots, max, out_closed);
  if (*out_closed)
    return n;
  int32_t e = e0;
  for (int32_t f = m->twin[e]; f >= 0; f = m->twin[e])
    e = tt__next(f);
  return star_walk(m, e, ring, slots, max, out_closed);
}

bool tt__mesh_remove_vertex(tt__mesh *m, int32_t v, const int32_t (*tris)[3],
                            int ntri)
{
  enum { SMALL = 64 };
  bool ok = false, closed = false;
  int32_t s_ring[SMALL], s_slot[SMALL], s_otwin[SMALL], s_pair[3 * SMALL];
  uint8_t s_oflag[SMALL];
  int32_t *ring = s_ring, *slot = s_slot, *otwin = s_otwin, *pair = s_pair;
  uint8_t *oflag = s_oflag;
  int n = tt__mesh_star(m, v, ring, slot, SMALL, &closed);
  if (n < 0)
    return false;
  int nstar = closed ? n : n - 1;
  if (ntri != n - 2 || ntri < 1)
    return false;
  if (n > SMALL) {
    ring = malloc((size_t)n * sizeof *ring);
    slot = malloc((size_t)n * sizeof *slot);
    otwin = malloc((size_t)n * sizeof *otwin);
    oflag = malloc((size_t)n);
    pair = malloc(3 * (size_t)ntri * sizeof *pair);
    if (!ring || !slot || !otwin || !oflag || !pair)
      goto done;
    (void)tt__mesh_star(m, v, ring, slot, n, &closed);
  }
  /* the hole's outline: link edge i runs ring[i] -> ring[i + 1] (opposite
   * v in star triangle i), with its outside twin and flag; for an open
   * star, edge n - 1 is the new boundary edge ring[n-1] -> ring[0] */
  for (int i = 0; i < nstar; i++) {
    int32_t t = slot[i], e = -1;
    for (int k = 0; k < 3; k++)
      if (m->hv[3 * t + k] == v)
        e = tt__next(3 * t + k);
    otwin[i] = m->twin[e];
    oflag[i] = m->eflag[e];
  }
  if (!closed) {
    otwin[n - 1] = -1;
    int32_t out = -1; /* v's outgoing boundary edge, in star triangle 0 */
    for (int k = 0; k < 3; k++)
      if (m->hv[3 * slot[0] + k] == v)
        out = 3 * slot[0] + k;
    oflag[n - 1] = m->eflag[out];
  }
  /* pair each new half-edge with its reverse among the new ones or with
   * the outline edge it replaces; each outline edge once */
  int nhalf = 3 * ntri, used = 0;
  for (int h = 0; h < nhalf; h++) {
    int32_t a = tris[h / 3][h % 3], b = tris[h / 3][(h % 3 + 1) % 3];
    pair[h] = -1;
    for (int g = 0; g < nhalf && pair[h] == -1; g++)
      if (g != h && tris[g / 3][g % 3] == b &&
          tris[g / 3][(g % 3 + 1) % 3] == a)
        pair[h] = g;
    for (int i = 0; i < n && pair[h] == -1; i++)
      if (ring[i] == a && ring[(i + 1) % n] == b)
        pair[h] = -2 - i;
    if (pair[h] == -1)
      goto done;
    used += pair[h] <= -2;
  }
  for (int h = 0; h < nhalf; h++) {
    if (pair[h] >= 0 && pair[pair[h]] != h)
      goto done;
    for (int g = 0; g < h && pair[h] <= -2; g++)
      if (pair[g] == pair[h])
        goto done;
  }
  if (used != n)
    goto done;
  for (int t = 0; t < ntri; t++)
    if (tris[t][0] == tris[t][1] || tris[t][1] == tris[t][2] ||
        tris[t][2] == tris[t][0] ||
        tt__mesh_orient(m, tris[t][0], tris[t][1], tris[t][2]) <= 0)
      goto done;
  if (!tt__grow((void **)&m->touched, &m->touchedcap,
                m->ntouched + (size_t)ntri, sizeof(int32_t)) ||
      !tt__grow((void **)&m->freelist, &m->freecap,
                m->nfree + (size_t)nstar, sizeof(int32_t)))
    goto done;
  /* write: ntri < nstar, so the star's slots suffice */
  for (int i = 0; i < nstar; i++) {
    bump_slot(m, slot[i]);
    m->hv[3 * slot[i]] = -1;
    m->nlive--;
  }
  m->v[v].edge = -1;
  bump(m, v);
  for (int t = 0; t < ntri; t++) {
    set_triangle(m, slot[t], tris[t][0], tris[t][1], tris[t][2]);
    bump_slot(m, slot[t]);
  }
  for (int i = ntri; i < nstar; i++)
    m->freelist[m->nfree++] = slot[i];
  for (int h = 0; h < nhalf; h++) {
    int32_t e = 3 * slot[h / 3] + h % 3;
    if (pair[h] >= 0)
      link(m, e, 3 * slot[pair[h] / 3] + pair[h] % 3, 0);
    else
      link(m, e, otwin[-2 - pair[h]], oflag[-2 - pair[h]]);
  }
  ok = true;
done:
  if (ring != s_ring) {
    free(ring);
    free(slot);
    free(otwin);
    free(oflag);
    free(pair);
  }
  return ok;
}
