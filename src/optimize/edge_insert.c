/*
 * edge_insert.c -- edge insertion for the Min-Max angle (see edge_insert.h
 * for the algorithm, its exactness and its cost).
 *
 * The search from an anchor p is a breadth-first walk over windows: a
 * window is an edge s->t of the triangle just entered (s on the right of
 * the rays from p, t on the left) and the open cone of rays from p, between
 * the rays through rb and lb, that reach it. Entering the triangle across
 * it, its third vertex x is visible from p when x lies strictly inside the
 * cone; the cone then splits at x into the windows of the two far edges,
 * else it passes on through the one far edge it meets. Every path edge's
 * ends lie on or outside the cone, so p-x crosses each of them at an
 * interior point, and the triangles crossed are the near triangle of each
 * path edge plus the last one.
 *
 * The polygons either side of p-x, counter-clockwise on the ground: the
 * left one p, x, then the left ends of the crossed edges back to p; the
 * right one x, p, then their right ends out to x (consecutive repeats
 * dropped: the crossed edges at one vertex are consecutive).
 *
 * Workload: the heap holds every live triangle once; a search visits a few
 * windows when the first candidate improves, at most the windows within
 * TT__EI_MAX_DEPTH crossed edges when none does (once per run, at the end).
 *
 * Part of src/optimize/, the optimisers: swaps under a criterion, look-ahead,
 * annealing, edge insertion, the dynamic programs.
 */
#include "optimize/edge_insert.h"

#include "base/heap.h"
#include "criteria/geometry.h"
#include "optimize/polygon_dp.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Improvements smaller than this (radians) are rounding, not progress. */
#define EI_EPS 1e-12
#define POLY_MAX (TT__EI_MAX_DEPTH + 3)

typedef struct window {
  int32_t he;       /* the edge to cross, in the triangle just entered */
  int32_t rb, lb;   /* the cone's bounding vertices (right, left) */
  int32_t parent;   /* index of the window it came through, -1: the root */
  int depth;        /* crossed edges before this one */
} window;

typedef struct ei {
  tt__mesh *m;
  const tt__crit_env *env;
  double fr[4];
  tt__heap heap;
  window *w;
  size_t nw, wcap;
  tt__opt_accept_fn accept;
  void *accept_arg;
  int max_depth;    /* TT__EI_MAX_DEPTH, TT__EI_MORE_DEPTH past the optimum */
  tt__edge_insert_stats st;
} ei;

/* The largest 2-D angle of triangle (a, b, c). */
static double angle3(const double fr[4], const tt__mesh *m, int32_t a,
                     int32_t b, int32_t c)
{
  tt__gvec ab = tt__geo_vec(fr, m, a, b), ac = tt__geo_vec(fr, m, a, c);
  tt__gvec bc = tt__geo_vec(fr, m, b, c);
  tt__gvec ba = {-ab.x, -ab.y, 0}, ca = {-ac.x, -ac.y, 0};
  tt__gvec cb = {-bc.x, -bc.y, 0};
  double x = tt__gangle2(ab, ac), y = tt__gangle2(bc, ba),
         z = tt__gangle2(ca, cb);
  double mx = x > y ? x : y;
  return mx > z ? mx : z;
}

double tt__edge_insert_tri_angle(const tt__mesh *m, const tt__crit_env *env,
                                 int32_t t)
{
  double fr[4];
  tt__geo_frame(env, fr);
  return angle3(fr, m, m->hv[3 * t], m->hv[3 * t + 1], m->hv[3 * t + 2]);
}

static bool heap_put(ei *s, int32_t t)
{
  const tt__mesh *m = s->m;
  return tt__heap_set(&s->heap, t,
                      angle3(s->fr, m, m->hv[3 * t], m->hv[3 * t + 1],
                             m->hv[3 * t + 2]));
}

typedef struct dp_arg {
  const ei *s;
  const int32_t *v;
} dp_arg;

static double dp_measure(void *arg, int i, int j, int k)
{
  const dp_arg *a = arg;
  return angle3(a->s->fr, a->s->m, a->v[i], a->v[j], a->v[k]);
}

/* The best triangulation of polygon v[0..n) (counter-clockwise, v[0]-v[1]
 * the new edge) into tris (mesh vertex triples); false when it has none
 * with every angle below mu - EI_EPS. */
static bool fill_polygon(ei *s, const int32_t *v, int n, double mu,
                         int32_t (*tris)[3])
{
  const tt__mesh *m = s->m;
  /* cheap test first: some apex j must make (v0, v1, vj) good enough */
  bool any = false;
  for (int j = 2; j < n && !any; j++)
    any = tt__mesh_orient(m, v[0], v[1], v[j]) > 0 &&
          angle3(s->fr, m, v[0], v[1], v[j]) < mu - EI_EPS;
  if (!any)
    return false;
  int64_t x[POLY_MAX], y[POLY_MAX];
  int32_t idx[3 * POLY_MAX];
  for (int i = 0; i < n; i++) {
    x[i] = m->v[v[i]].c;
    y[i] = m->v[v[i]].r;
  }
  dp_arg a = {s, v};
  double val;
  /* false: no triangulation (a degenerate polygon), or out of memory --
   * the DP does not tell them apart, and its buffers are a few kilobytes:
   * the candidate is passed over either way */
  if (!tt__polygon_dp(n, x, y, m->metric.det_sign, TT__DP_MAX, dp_measure,
                      &a, idx, &val))
    return false;
  if (!(val < mu - EI_EPS))
    return false;
  for (int t = 0; t < n - 2; t++)
    for (int k = 0; k < 3; k++)
      tris[t][k] = v[idx[3 * t + k]];
  return true;
}

/* Tries the edge p-q, q the apex beyond window wi. *out_done: the edge
 * went in; *out_refused: it improved but the accept callback refused it
 * (the old triangles are back, maybe in other slots: the search's windows
 * are stale). False when out of memory. */
static bool try_edge(ei *s, size_t wi, int32_t p, int32_t q, double mu,
                     bool *out_done, bool *out_refused)
{
  tt__mesh *m = s->m;
  *out_done = false;
  *out_refused = false;
  s->st.candidates++;
  /* the crossed half-edges, from p outwards */
  int32_t path[TT__EI_MAX_DEPTH + 1];
  int k = s->w[wi].depth + 1;
  for (int32_t i = (int32_t)wi, j = k - 1; i >= 0; i = s->w[i].parent, j--)
    path[j] = s->w[i].he;
  int32_t left[POLY_MAX], right[POLY_MAX];
  int nl = 0, nr = 0;
  right[nr++] = q;
  right[nr++] = p;
  int32_t lrev[POLY_MAX];
  int nlr = 0;
  for (int i = 0; i < k; i++) {
    int32_t rs = m->hv[path[i]], lt = m->hv[tt__next(path[i])];
    if (right[nr - 1] != rs)
      right[nr++] = rs;
    if (nlr == 0 || lrev[nlr - 1] != lt)
      lrev[nlr++] = lt;
  }
  left[nl++] = p;
  left[nl++] = q;
  for (int i = nlr - 1; i >= 0; i--)
    left[nl++] = lrev[i];
  int32_t tris[2 * POLY_MAX][3];
  if (!fill_polygon(s, left, nl, mu, tris) ||
      !fill_polygon(s, right, nr, mu, tris + (nl - 2)))
    return true; /* not better than mu: the next candidate */
  int ntri = nl - 2 + nr - 2;
  /* the old triangles: the near triangle of every crossed edge, and the
   * last one */
  int32_t old[TT__EI_MAX_DEPTH + 2];
  int32_t oldtri[TT__EI_MAX_DEPTH + 2][3];
  for (int i = 0; i < k; i++)
    old[i] = path[i] / 3;
  old[k] = m->twin[path[k - 1]] / 3;
  for (int i = 0; i <= k; i++)
    for (int c = 0; c < 3; c++)
      oldtri[i][c] = m->hv[3 * old[i] + c];
  tt__mesh_clear_touched(m);
  if (!tt__mesh_replace_region(m, old, k + 1, (const int32_t(*)[3])tris,
                               ntri))
    return true; /* does not fit the outline: not a candidate after all */
  size_t nt = m->ntouched;
  int32_t news[2 * POLY_MAX];
  int nnew = 0;
  for (size_t i = 0; i < nt && nnew < 2 * POLY_MAX; i++)
    if (tt__mesh_live(m, m->touched[i]))
      news[nnew++] = m->touched[i];
  if (s->accept && !s->accept(s->accept_arg, m, news, nnew)) {
    s->st.refused++;
    *out_refused = true;
    if (!tt__mesh_replace_region(m, news, nnew,
                                 (const int32_t(*)[3])oldtri, k + 1))
      return false; /* out of memory putting the old triangles back */
    tt__mesh_clear_touched(m);
    return true;
  }
  tt__mesh_clear_touched(m);
  for (int i = 0; i <= k; i++)
    tt__heap_remove(&s->heap, old[i]);
  if (!tt__heap_reserve_items(&s->heap, m->nslots))
    return false;
  for (int i = 0; i < nnew; i++)
    if (!heap_put(s, news[i]))
      return false;
  s->st.insertions++;
  *out_done = true;
  return true;
}

static bool push_window(ei *s, int32_t he, int32_t rb, int32_t lb,
                        int32_t parent, int depth)
{
  if (!tt__grow((void **)&s->w, &s->wcap, s->nw + 1, sizeof(window)))
    return false;
  window w = {he, rb, lb, parent, depth};
  s->w[s->nw++] = w;
  return true;
}

/* Searches the edges from the anchor of triangle t (angle mu) for the
 * first that improves. *out_done: one went in; *out_refused: the search
 * stopped at an improving edge the accept callback refused. False when
 * out of memory. */
static bool improve(ei *s, int32_t t, double mu, bool *out_done,
                    bool *out_refused)
{
  tt__mesh *m = s->m;
  *out_done = false;
  *out_refused = false;
  /* the anchor: the corner of the largest angle */
  int32_t e = 3 * t;
  double best = -1.0;
  for (int i = 0; i < 3; i++) {
    int32_t a = m->hv[3 * t + i], b = m->hv[3 * t + (i + 1) % 3],
            c = m->hv[3 * t + (i + 2) % 3];
    double ang = tt__gangle2(tt__geo_vec(s->fr, m, a, b),
                             tt__geo_vec(s->fr, m, a, c));
    if (ang > best) {
      best = ang;
      e = 3 * t + i;
    }
  }
  int32_t p = m->hv[e], b = m->hv[tt__next(e)], c = m->hv[tt__prev(e)];
  s->nw = 0;
  if (!push_window(s, tt__next(e), b, c, -1, 0))
    return false;
  for (size_t i = 0; i < s->nw; i++) {
    window w = s->w[i];
    int32_t tw = m->twin[w.he];
    if (tw < 0 || (m->eflag[w.he] & TT__EDGE_CONSTRAINED))
      continue;
    int32_t x = m->hv[tt__prev(tw)];
    int o_r = tt__mesh_orient(m, p, w.rb, x);
    int o_l = tt__mesh_orient(m, p, x, w.lb);
    bool deeper = w.depth + 1 < s->max_depth;
    if (o_r > 0 && o_l > 0) {
      if (!try_edge(s, i, p, x, mu, out_done, out_refused))
        return false;
      if (*out_done || *out_refused)
        return true;
      if (deeper && (!push_window(s, tt__next(tw), w.rb, x, (int32_t)i,
                                  w.depth + 1) ||
                     !push_window(s, tt__prev(tw), x, w.lb, (int32_t)i,
                                  w.depth + 1)))
        return false;
    } else if (deeper) {
      /* x on or beyond one bounding ray: the cone leaves through the far
       * edge on the other side */
      int32_t next = o_r <= 0 ? tt__prev(tw) : tt__next(tw);
      if (!push_window(s, next, w.rb, w.lb, (int32_t)i, w.depth + 1))
        return false;
    }
  }
  return true;
}

bool tt__edge_insert_run(tt__mesh *m, const tt__crit_env *env,
                         tt__opt_accept_fn accept, void *accept_arg,
                         tt__edge_insert_stats *out_stats)
{
  ei s;
  memset(&s, 0, sizeof s);
  s.m = m;
  s.env = env;
  s.accept = accept;
  s.accept_arg = accept_arg;
  s.max_depth = TT__EI_MAX_DEPTH;
  tt__geo_frame(env, s.fr);
  tt__heap_init(&s.heap);
  bool ok = tt__heap_reserve_items(&s.heap, m->nslots ? m->nslots : 1);
  for (size_t t = 0; ok && t < m->nslots; t++)
    if (tt__mesh_live(m, (int32_t)t))
      ok = heap_put(&s, (int32_t)t);
  if (ok && tt__heap_size(&s.heap))
    s.st.start_max = s.st.end_max = tt__heap_top(&s.heap).key;
  /* triangles whose improvement the accept callback refused are set
   * aside (out of the heap) and put back at the end */
  int32_t *aside = NULL;
  size_t naside = 0, asidecap = 0;
  while (ok && tt__heap_size(&s.heap) > 0) {
    tt__heap_entry top = tt__heap_top(&s.heap);
    bool done, refused;
    ok = improve(&s, top.item, top.key, &done, &refused);
    if (!ok || done)
      continue;
    /* stuck: the first time with no refusal, the largest angle is the
     * optimum; set the triangle aside and go on with the next worst */
    if (!refused && !s.st.optimum_reached) {
      s.st.optimum_reached = true;
      s.st.optimum_max = top.key;
      s.max_depth = TT__EI_MORE_DEPTH;
    }
    ok = tt__grow((void **)&aside, &asidecap, naside + 1, sizeof *aside);
    if (ok) {
      aside[naside++] = top.item;
      tt__heap_remove(&s.heap, top.item);
    }
  }
  for (size_t i = 0; i < naside; i++)
    if (tt__mesh_live(m, aside[i]) && !heap_put(&s, aside[i]))
      ok = false;
  free(aside);
  if (tt__heap_size(&s.heap))
    s.st.end_max = tt__heap_top(&s.heap).key;
  if (out_stats)
    *out_stats = s.st;
  tt__heap_free(&s.heap);
  free(s.w);
  return ok;
}
