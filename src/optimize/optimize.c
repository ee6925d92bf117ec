/*
 * optimize.c -- local swap and look-ahead swap (see optimize.h for the
 * algorithm, the noise guard and what a run guarantees).
 *
 * State of a run: a table of the edges met so far (id -> vertex pair and a
 * current half-edge), an open-addressing hash from vertex pair to id, a
 * per-id "resting" mark, and the indexed heap of positive keys. Half-edges
 * of the table are refreshed for every edge of the slots a move wrote, so
 * an id's half-edge is either current or detectably stale (its vertex pair
 * no longer matches, for the diagonal a flip removed).
 *
 * Workload: after an insertion, a region of a few dozen edges (a handful
 * of allocations per call); a whole-mesh pass is O(E log E) for the heap
 * plus one criterion evaluation per edge and per re-scored edge, and the
 * look-ahead phase one trial flip and four evaluations per edge.
 *
 * Part of src/optimize/, the optimisers: swaps under a criterion, look-ahead,
 * annealing, edge insertion, the dynamic programs.
 */
#include "optimize/optimize.h"

#include "base/heap.h"
#include "criteria/geometry.h"
#include "optimize/anneal.h"
#include "optimize/edge_insert.h"
#include "optimize/hole_dp.h"
#include "mesh/raster_scan.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* --- public names -------------------------------------------------------- */

static const char *const optimize_names[] = {"auto",      "none",
                                             "local",     "lookahead",
                                             "anneal",    "edge_insertion"};
#define NOPT (sizeof optimize_names / sizeof optimize_names[0])
static const char *const repair_names[] = {"auto", "flip", "local",
                                           "lookahead", "delaunay"};
#define NREP (sizeof repair_names / sizeof repair_names[0])

/* The index of name in names[0..n), or -1. */
static int name_index(const char *const *names, size_t n, const char *name)
{
  for (size_t i = 0; name && i < n; i++)
    if (tt__name_equal(names[i], name))
      return (int)i;
  return -1;
}

const char *tt_optimize_name(tt_optimize optimize)
{
  return (unsigned)optimize < NOPT ? optimize_names[optimize] : NULL;
}

tt_status tt_optimize_parse(tt_context *ctx, const char *name,
                            tt_optimize *out_optimize)
{
  int i = name_index(optimize_names, NOPT, name);
  if (i >= 0 && out_optimize) {
    *out_optimize = (tt_optimize)i;
    return TT_OK;
  }
  return tt__error(ctx, TT_ERR_ARG, "unknown optimisation '%s' (known: auto, "
                   "none, local, lookahead, anneal, edge_insertion)",
                   name ? name : "(null)");
}

tt_status tt_optimize_check(tt_context *ctx, tt_optimize optimize,
                            tt_criterion criterion,
                            const tt_anneal_options *anneal)
{
  if (!tt_optimize_name(optimize))
    return tt__error(ctx, TT_ERR_ARG, "unknown optimisation %d",
                     (int)optimize);
  if (optimize == TT_OPTIMIZE_EDGE_INSERTION &&
      criterion != TT_CRITERION_MINMAX_ANGLE)
    return tt__error(ctx, TT_ERR_ARG, "edge insertion optimises the Min-Max "
                     "angle only: use -criterion minmax_angle, or another "
                     "-optimize (local, lookahead, anneal)");
  if (!anneal)
    return TT_OK;
  if (!(anneal->t0 >= 0) || isinf(anneal->t0))
    return tt__error(ctx, TT_ERR_ARG, "anneal t0 must be a finite number "
                     ">= 0 (0: automatic), got %g", anneal->t0);
  if (anneal->stages < 0)
    return tt__error(ctx, TT_ERR_ARG, "anneal stages must be >= 0 (0: 100), "
                     "got %d", anneal->stages);
  if (!(anneal->swaps >= 0) || !(anneal->good >= 0) || isinf(anneal->swaps) ||
      isinf(anneal->good) || anneal->swaps > 1e6 || anneal->good > 1e6)
    return tt__error(ctx, TT_ERR_ARG, "anneal swaps and good swaps per edge "
                     "must be in [0, 1e6] (0: 5), got %g and %g",
                     anneal->swaps, anneal->good);
  if (!(anneal->r >= 0 && anneal->r < 1))
    return tt__error(ctx, TT_ERR_ARG, "anneal r must be in (0, 1) (0: 0.95), "
                     "got %g", anneal->r);
  return TT_OK;
}

const char *tt_repair_name(tt_repair repair)
{
  return (unsigned)repair < NREP ? repair_names[repair] : NULL;
}

tt_status tt_repair_parse(tt_context *ctx, const char *name,
                          tt_repair *out_repair)
{
  int i = name_index(repair_names, NREP, name);
  if (i >= 0 && out_repair) {
    *out_repair = (tt_repair)i;
    return TT_OK;
  }
  return tt__error(ctx, TT_ERR_ARG, "unknown repair '%s' (known: auto, "
                   "flip, local, lookahead, delaunay)",
                   name ? name : "(null)");
}

tt_repair tt_repair_resolve(tt_repair repair, tt_criterion criterion)
{
  if (repair != TT_REPAIR_AUTO)
    return repair;
  return criterion == TT_CRITERION_L2 ? TT_REPAIR_DELAUNAY : TT_REPAIR_FLIP;
}

tt_optimize tt_optimize_resolve(tt_optimize optimize, tt_criterion criterion,
                                tt_repair repair)
{
  if (optimize != TT_OPTIMIZE_AUTO)
    return optimize;
  return criterion != TT_CRITERION_DELAUNAY &&
                 tt_repair_resolve(repair, criterion) == TT_REPAIR_DELAUNAY
             ? TT_OPTIMIZE_LOCAL
             : TT_OPTIMIZE_NONE;
}

/* --- the run's state ----------------------------------------------------- */

typedef struct edge_list {
  int32_t *e;
  size_t n, cap;
} edge_list;

typedef struct opt {
  tt__mesh *m;
  const tt__opt_params *p;
  tt__heap heap;
  int32_t *ea, *eb;    /* per id: vertex pair, ea < eb */
  int32_t *he;         /* per id: a half-edge of it (maybe stale) */
  uint8_t *rest;       /* per id: resting (a move on it was taken back) */
  uint8_t *led;        /* per id: has started a look-ahead pair */
  uint32_t *stamp;     /* per id: the last batch that scored it */
  uint32_t batch;
  size_t n, cap;
  int32_t *hash;       /* hcap slots, -1 empty */
  size_t hcap;
  double scale, tol;
  bool phase2, oom;
  long moves, budget;
  tt__opt_stats st;
  edge_list batch_edges; /* rescore's list, kept from move to move */
} opt;

static void opt_free(opt *o)
{
  tt__heap_free(&o->heap);
  free(o->ea);
  free(o->eb);
  free(o->he);
  free(o->rest);
  free(o->led);
  free(o->stamp);
  free(o->hash);
  free(o->batch_edges.e);
}

static size_t hash_pair(int32_t a, int32_t b, size_t hcap)
{
  uint64_t k = ((uint64_t)(uint32_t)a << 32) | (uint32_t)b;
  k *= 0x9e3779b97f4a7c15ull;
  return (size_t)(k >> 20) & (hcap - 1);
}

static bool rehash(opt *o, size_t hcap)
{
  int32_t *h = malloc(hcap * sizeof *h);
  if (!h)
    return false;
  for (size_t i = 0; i < hcap; i++)
    h[i] = -1;
  for (size_t id = 0; id < o->n; id++) {
    size_t s = hash_pair(o->ea[id], o->eb[id], hcap);
    while (h[s] >= 0)
      s = (s + 1) & (hcap - 1);
    h[s] = (int32_t)id;
  }
  free(o->hash);
  o->hash = h;
  o->hcap = hcap;
  return true;
}

/* The id of half-edge e's edge, made when new; its half-edge becomes e.
 * -1 when out of memory. */
static int32_t id_of(opt *o, int32_t e)
{
  const tt__mesh *m = o->m;
  int32_t a = m->hv[e], b = m->hv[tt__next(e)];
  if (a > b) {
    int32_t t = a;
    a = b;
    b = t;
  }
  size_t s = hash_pair(a, b, o->hcap);
  for (; o->hash[s] >= 0; s = (s + 1) & (o->hcap - 1)) {
    int32_t id = o->hash[s];
    if (o->ea[id] == a && o->eb[id] == b) {
      o->he[id] = e;
      return id;
    }
  }
  if (o->n + 1 > o->cap) {
    size_t c1 = o->cap, c2 = o->cap, c3 = o->cap, c4 = o->cap, c5 = o->cap,
           c6 = o->cap;
    if (!tt__grow((void **)&o->ea, &c1, o->n + 1, sizeof(int32_t)) ||
        !tt__grow((void **)&o->eb, &c2, o->n + 1, sizeof(int32_t)) ||
        !tt__grow((void **)&o->he, &c3, o->n + 1, sizeof(int32_t)) ||
        !tt__grow((void **)&o->rest, &c4, o->n + 1, 1) ||
        !tt__grow((void **)&o->led, &c5, o->n + 1, 1) ||
        !tt__grow((void **)&o->stamp, &c6, o->n + 1, sizeof(uint32_t)))
      return -1;
    size_t c = c1 < c2 ? c1 : c2;
    c = c < c3 ? c : c3;
    c = c < c4 ? c : c4;
    c = c < c5 ? c : c5;
    c = c < c6 ? c : c6;
    if (!tt__heap_reserve_items(&o->heap, c))
      return -1;
    o->cap = c;
  }
  int32_t id = (int32_t)o->n++;
  o->ea[id] = a;
  o->eb[id] = b;
  o->he[id] = e;
  o->rest[id] = 0;
  o->led[id] = 0;
  o->stamp[id] = 0;
  o->hash[s] = id;
  if (2 * o->n > o->hcap && !rehash(o, 2 * o->hcap))
    return -1;
  return id;
}

/* Whether id's half-edge is live and still joins its vertex pair. */
static bool current(const opt *o, int32_t id)
{
  const tt__mesh *m = o->m;
  int32_t e = o->he[id];
  if (!tt__mesh_live(m, e / 3))
    return false;
  int32_t a = m->hv[e], b = m->hv[tt__next(e)];
  return (a == o->ea[id] && b == o->eb[id]) ||
         (b == o->ea[id] && a == o->eb[id]);
}

static bool swappable(const tt__mesh *m, int32_t e)
{
  return m->twin[e] >= 0 && !(m->eflag[e] & TT__EDGE_CONSTRAINED) &&
         tt__mesh_flippable(m, e);
}

static double value(opt *o, int32_t e)
{
  double v = o->p->crit->swap_value(o->p->env, e);
  if (isnan(v))
    return -INFINITY; /* a criterion that cannot tell: no swap */
  if (fabs(v) > o->scale && isfinite(v)) {
    o->scale = fabs(v);
    o->tol = TT__OPT_REL_EPS * o->scale;
  }
  return v;
}

/* The best swap value among the four quad edges of the new diagonal h,
 * -INFINITY when none is swappable; *out_f gets that edge. */
static double best_follow_up(opt *o, int32_t h, int32_t *out_f)
{
  const tt__mesh *m = o->m;
  int32_t g = m->twin[h];
  int32_t quad[4] = {tt__next(h), tt__prev(h), tt__next(g), tt__prev(g)};
  double best = -INFINITY;
  *out_f = -1;
  for (int i = 0; i < 4; i++)
    if (swappable(m, quad[i])) {
      double w = value(o, quad[i]);
      if (w > best) {
        best = w;
        *out_f = quad[i];
      }
    }
  return best;
}

/* The heap key of swappable half-edge e: its swap value v when above the
 * threshold, else in the look-ahead phase SwapValue+ (one trial flip, taken
 * back exactly), else -INFINITY. */
static double key_of(opt *o, int32_t e, double *out_v)
{
  double v = value(o, e);
  *out_v = v;
  if (v > o->tol || !o->phase2)
    return v;
  tt__mesh_flip_undo u;
  int32_t h = tt__mesh_flip_undoable(o->m, e, &u);
  if (h < 0) {
    o->oom = true;
    return -INFINITY;
  }
  int32_t f;
  double w = best_follow_up(o, h, &f);
  tt__mesh_flip_revert(o->m, &u);
  double k = v + w;
  return isnan(k) ? -INFINITY : k;
}

static double pair_tol(const opt *o)
{
  double t = TT__OPT_PAIR_EPS * o->scale;
  return t > o->tol ? t : o->tol;
}

/* Puts id in the heap with its current key, or takes it out. */
static bool score(opt *o, int32_t id)
{
  int32_t e = o->he[id];
  if (o->rest[id] || !current(o, id) || !swappable(o->m, e)) {
    tt__heap_remove(&o->heap, id);
    return true;
  }
  double v, k = key_of(o, e, &v);
  bool pair = !(v > o->tol);
  if (pair && o->led[id])
    k = -INFINITY; /* one pair per edge: see pair_move */
  if (k > (pair ? pair_tol(o) : o->tol))
    return tt__heap_set(&o->heap, id, k);
  tt__heap_remove(&o->heap, id);
  return true;
}

/* --- re-scoring after a move --------------------------------------------- */

static bool list_push(edge_list *l, int32_t e)
{
  if (!tt__grow((void **)&l->e, &l->cap, l->n + 1, sizeof(int32_t)))
    return false;
  l->e[l->n++] = e;
  return true;
}

/* Takes the edges of the slots out of the heap (before a move). */
static bool unscore_slots(opt *o, const int32_t *slots, int ns)
{
  for (int i = 0; i < ns; i++)
    for (int k = 0; k < 3; k++) {
      int32_t id = id_of(o, 3 * slots[i] + k);
      if (id < 0)
        return false;
      tt__heap_remove(&o->heap, id);
    }
  return true;
}

/* Re-scores the edges of the slots a move wrote (or restored), the edges
 * of the neighbouring triangles in the look-ahead phase, and the edges
 * the criterion names for each new diagonal. wake: clear their resting
 * marks (their neighbourhood changed). */
static bool rescore(opt *o, const int32_t *slots, int ns, const int32_t *diag,
                    int nd, bool wake)
{
  const tt__mesh *m = o->m;
  edge_list l = o->batch_edges;
  l.n = 0;
  bool ok = true;
  o->batch++;
  for (int i = 0; i < ns && ok; i++)
    for (int k = 0; k < 3 && ok; k++) {
      int32_t e = 3 * slots[i] + k;
      ok = list_push(&l, e);
      if (ok && o->phase2 && m->twin[e] >= 0) {
        int32_t f = m->twin[e];
        ok = list_push(&l, tt__next(f)) && list_push(&l, tt__prev(f));
      }
    }
  if (o->p->crit->affected) {
    int32_t buf[1024];
    for (int i = 0; i < nd && ok; i++) {
      int c = o->p->crit->affected(o->p->env, diag[i], buf, 1024);
      for (int j = 0; j < c && ok; j++)
        ok = list_push(&l, buf[j]);
    }
  }
  for (size_t i = 0; i < l.n && ok; i++) {
    int32_t e = l.e[i];
    if (e < 0 || !tt__mesh_live(m, e / 3))
      continue;
    int32_t id = id_of(o, e);
    if (id < 0) {
      ok = false;
      break;
    }
    if (o->stamp[id] == o->batch)
      continue; /* met twice in this batch */
    o->stamp[id] = o->batch;
    if (wake)
      o->rest[id] = 0;
    ok = score(o, id);
  }
  o->batch_edges = l;
  return ok && !o->oom;
}

/* --- moves ---------------------------------------------------------------- */

static bool accepted(opt *o, const int32_t *slots, int ns)
{
  return !o->p->accept || o->p->accept(o->p->accept_arg, o->m, slots, ns);
}

/* Swaps e (value v > tol) unless the noise guard or the accept callback
 * says no. */
static bool single_move(opt *o, int32_t id, int32_t e, double v)
{
  tt__mesh *m = o->m;
  int32_t slots[2] = {e / 3, m->twin[e] / 3};
  if (!unscore_slots(o, slots, 2))
    return false;
  tt__mesh_flip_undo u;
  int32_t h = tt__mesh_flip_undoable(m, e, &u);
  if (h < 0)
    return false;
  double r = value(o, h);
  bool keep = r < 0 && v > fabs(v + r);
  if (!keep)
    o->st.noisy++;
  else if (!accepted(o, slots, 2)) {
    keep = false;
    o->st.refused++;
  }
  if (!keep) {
    tt__mesh_flip_revert(m, &u);
    o->rest[id] = 1;
    return rescore(o, slots, 2, NULL, 0, false);
  }
  o->st.swaps++;
  o->moves++;
  return rescore(o, slots, 2, &h, 1, true);
}

/* --- pairs under the max-type criteria ----------------------------------
 * For min-max angle (and its lexicographic form) and lexicographic ABN, the
 * score v + w of a pair says nothing certain about the global value: a
 * pair is kept only when the region of its three triangles gets a better
 * vector -- their angles, or the angles between normals across every edge
 * of theirs (the edges of the rest of the mesh keep their values) -- so
 * that look-ahead, too, never ends worse than it started. */

/* 1: min-max angle (the largest entry decides), 2: min-max angle lex, 3:
 * abn (the sorted vector decides), 0: an additive criterion. */
static int max_kind(const tt__criterion_vt *c)
{
  return c->id == TT_CRITERION_MINMAX_ANGLE       ? 1
         : c->id == TT_CRITERION_MINMAX_ANGLE_LEX ? 2
         : c->id == TT_CRITERION_ABN              ? 3
                                                  : 0;
}

static tt__gvec slot_normal(const double fr[4], const tt__mesh *m, int32_t t)
{
  int32_t p = m->hv[3 * t];
  return tt__gcross(tt__geo_vec(fr, m, p, m->hv[3 * t + 1]),
                    tt__geo_vec(fr, m, p, m->hv[3 * t + 2]));
}

/* The region's vector (at most 9 entries), sorted in decreasing order;
 * its length. */
static int region_vector(const opt *o, const int32_t slots[3], int kind,
                         double *out)
{
  const tt__mesh *m = o->m;
  double fr[4];
  tt__geo_frame(o->p->env, fr);
  int n = 0;
  for (int i = 0; i < 3; i++) {
    int32_t t = slots[i];
    if (kind != 3) {
      for (int k = 0; k < 3; k++) {
        int32_t a = m->hv[3 * t + k], b = m->hv[3 * t + (k + 1) % 3],
                c = m->hv[3 * t + (k + 2) % 3];
        out[n++] = tt__gangle2(tt__geo_vec(fr, m, a, b),
                               tt__geo_vec(fr, m, a, c));
      }
      continue;
    }
    tt__gvec nt = slot_normal(fr, m, t);
    for (int k = 0; k < 3; k++) {
      int32_t h = 3 * t + k, tw = m->twin[h];
      if (tw < 0)
        continue;
      bool inner = false;
      for (int j = 0; j < 3; j++)
        inner |= tw / 3 == slots[j];
      if (inner && tw < h)
        continue; /* an inner edge, counted from its other side */
      out[n++] = tt__gangle(nt, slot_normal(fr, m, tw / 3));
    }
  }
  for (int i = 1; i < n; i++)
    for (int j = i; j > 0 && out[j - 1] < out[j]; j--) {
      double x = out[j];
      out[j] = out[j - 1];
      out[j - 1] = x;
    }
  return n;
}

/* Whether vector a beats b: smaller at the first of the n entries where
 * they differ by more than 1e-12 (the criteria's own tie width). */
static bool region_better(const double *a, const double *b, int n)
{
  for (int i = 0; i < n; i++)
    if (fabs(a[i] - b[i]) > 1e-12)
      return a[i] < b[i];
  return false;
}

/* Swaps e (value v <= tol) and then its best follow-up, when the pair
 * improves by more than the pair threshold (for the max-type criteria:
 * when it makes its region's vector better, above) and is accepted. */
static bool pair_move(opt *o, int32_t id, int32_t e, double v)
{
  tt__mesh *m = o->m;
  int32_t slots[3] = {e / 3, m->twin[e] / 3, -1};
  o->led[id] = 1;
  if (!unscore_slots(o, slots, 2))
    return false;
  tt__mesh_flip_undo u1, u2;
  int32_t h = tt__mesh_flip_undoable(m, e, &u1);
  if (h < 0)
    return false;
  int32_t c = m->hv[h], d = m->hv[tt__next(h)]; /* the first diagonal */
  int32_t f;
  double w = best_follow_up(o, h, &f);
  bool keep = f >= 0 && v + w > pair_tol(o);
  int ns = 2;
  if (keep) {
    int32_t fs[2] = {f / 3, m->twin[f] / 3};
    int32_t other = fs[0] == slots[0] || fs[0] == slots[1] ? fs[1] : fs[0];
    slots[2] = other;
    ns = 3;
    if (!unscore_slots(o, &slots[2], 1))
      return false;
    int kind = max_kind(o->p->crit);
    double before[9], after[9];
    int nb = 0;
    if (kind) {
      /* the region's vector before the pair: back, measure, and the same
       * flip again (word for word the same, so f is still f) */
      tt__mesh_flip_revert(m, &u1);
      nb = region_vector(o, slots, kind, before);
      if (tt__mesh_flip_undoable(m, e, &u1) < 0)
        return false;
    }
    int32_t h2 = tt__mesh_flip_undoable(m, f, &u2);
    if (h2 < 0) {
      tt__mesh_flip_revert(m, &u1);
      return false;
    }
    bool better = true;
    if (kind) {
      int na = region_vector(o, slots, kind, after);
      better = na == nb && region_better(after, before, kind == 1 ? 1 : na);
      if (!better)
        o->st.noisy++;
    }
    if (better && accepted(o, slots, 3)) {
      o->st.pairs++;
      o->moves++;
      /* the first diagonal c-d survives the second flip: find it */
      int32_t diag[2] = {h2, -1};
      for (int i = 0; i < 3; i++)
        for (int k = 0; k < 3; k++) {
          int32_t x = 3 * slots[i] + k;
          if (m->hv[x] == c && m->hv[tt__next(x)] == d)
            diag[1] = x;
        }
      return rescore(o, slots, 3, diag, diag[1] >= 0 ? 2 : 1, true);
    }
    if (better)
      o->st.refused++;
    tt__mesh_flip_revert(m, &u2);
  }
  tt__mesh_flip_revert(m, &u1);
  o->rest[id] = 1;
  return rescore(o, slots, ns, NULL, 0, false);
}

/* Pops and moves until no key above the threshold is left. */
static bool drain_heap(opt *o)
{
  while (tt__heap_size(&o->heap) > 0) {
    if (o->moves >= o->budget) {
      o->st.budget_hit = true;
      return true;
    }
    tt__heap_entry top = tt__heap_pop(&o->heap);
    int32_t id = top.item;
    int32_t e = o->he[id];
    if (o->rest[id] || !current(o, id) || !swappable(o->m, e))
      continue;
    double v, k = key_of(o, e, &v);
    if (o->oom)
      return false;
    if (k != top.key) {
      /* stale (a look-ahead key whose wider neighbourhood changed, or a
       * threshold that rose): back in with its fresh key */
      if (!score(o, id))
        return false;
      continue;
    }
    bool ok;
    if (v > o->tol)
      ok = single_move(o, id, e, v);
    else if (o->phase2 && k > pair_tol(o) && !o->led[id])
      ok = pair_move(o, id, e, v);
    else
      continue;
    if (!ok)
      return false;
  }
  return true;
}

bool tt__optimize_run(tt__mesh *m, const tt__opt_params *p,
                      const int32_t *seeds, size_t nseeds,
                      tt__opt_stats *out_stats)
{
  opt o;
  memset(&o, 0, sizeof o);
  o.m = m;
  o.p = p;
  tt__heap_init(&o.heap);
  /* the hash at most half full without rehashing: a whole-mesh run meets
   * about 1.5 edges per triangle slot and the edges its swaps make */
  size_t hcap = 64;
  while (!seeds && hcap < 4 * m->nslots)
    hcap <<= 1;
  bool ok = rehash(&o, hcap);
  size_t scope = 0;
  if (ok && !seeds) {
    for (size_t e = 0; e < 3 * m->nslots && ok; e++)
      if (m->hv[e - e % 3] >= 0 && m->twin[e] > (int32_t)e) {
        int32_t id = id_of(&o, (int32_t)e);
        ok = id >= 0 && score(&o, id);
        scope++;
      }
  } else {
    o.batch = 1;
    for (size_t i = 0; i < nseeds && ok; i++)
      if (seeds[i] >= 0) {
        int32_t id = id_of(&o, seeds[i]);
        ok = id >= 0;
        if (ok && o.stamp[id] != o.batch) {
          o.stamp[id] = o.batch;
          ok = score(&o, id);
          scope++;
        }
      }
  }
  o.budget = 32 * (long)scope + 1024;
  ok = ok && !o.oom && drain_heap(&o);
  if (ok && p->lookahead && p->crit->id != TT_CRITERION_DELAUNAY &&
      !o.st.budget_hit) {
    o.phase2 = true;
    for (size_t id = 0; id < o.n && ok; id++)
      ok = score(&o, (int32_t)id);
    ok = ok && !o.oom && drain_heap(&o);
  }
  o.st.tol = o.tol;
  if (out_stats)
    *out_stats = o.st;
  opt_free(&o);
  return ok && !o.oom;
}

/* --- refinement hooks ---------------------------------------------------- */

static bool push(tt__edge_stack *s, int32_t e)
{
  if (!tt__grow((void **)&s->e, &s->cap, s->n + 1, sizeof(int32_t)))
    return false;
  s->e[s->n++] = e;
  return true;
}

/* Pushes the edges of every triangle around vertex x. */
static bool push_ring(const tt__mesh *m, int32_t x, tt__edge_stack *s)
{
  int32_t start = m->v[x].edge;
  if (start < 0)
    return true;
  /* counter-clockwise through leaving half-edges, then, when a boundary
   * stops the walk, clockwise from the start */
  int32_t e = start;
  do {
    if (!push(s, e) || !push(s, tt__next(e)) || !push(s, tt__prev(e)))
      return false;
    int32_t in = m->twin[tt__prev(e)];
    if (in < 0)
      break;
    e = in;
  } while (e != start);
  if (e == start && m->twin[tt__prev(e)] >= 0)
    return true;
  for (int32_t f = m->twin[start]; f >= 0;) {
    e = tt__next(f);
    if (!push(s, e) || !push(s, tt__next(e)) || !push(s, tt__prev(e)))
      return false;
    f = m->twin[e];
  }
  return true;
}

long tt__optimize_insert(tt__mesh *m, const tt__criterion_vt *crit,
                         const tt__crit_env *env, tt_repair repair,
                         int32_t v, const int32_t *opposite, int n,
                         tt__edge_stack *stack)
{
  if (crit->id == TT_CRITERION_DELAUNAY || repair == TT_REPAIR_DELAUNAY)
    return tt__swap_repair(m, &tt__criterion_delaunay, env, opposite, n,
                           stack);
  int32_t link[TT__HOLE_MAX_N];
  if (crit->id == TT_CRITERION_MIN_AREA) {
    /* the exact least-area triangulation of the hole around v (SPEC 2.3,
     * docs/min_area_hole.md), then the swaps carry on from its link */
    int k = tt__hole_min_area(m, env, v, link, TT__HOLE_MAX_N);
    if (k < 0)
      return -1;
    opposite = link;
    n = k;
  }
  if (repair == TT_REPAIR_FLIP)
    return tt__swap_repair(m, crit, env, opposite, n, stack);
  stack->n = 0;
  for (int i = 0; i < n; i++) {
    int32_t o = opposite[i];
    if (o < 0)
      continue;
    if (!push(stack, o) || !push(stack, tt__next(o)) ||
        !push(stack, tt__prev(o)))
      return -1;
    if (crit->affected && (!push_ring(m, m->hv[o], stack) ||
                           !push_ring(m, m->hv[tt__next(o)], stack)))
      return -1;
  }
  tt__opt_params p = {crit, env, repair == TT_REPAIR_LOOKAHEAD, NULL, NULL};
  tt__opt_stats st;
  if (!tt__optimize_run(m, &p, stack->e, stack->n, &st))
    return -1;
  return st.swaps + 2 * st.pairs;
}

typedef struct bound_arg {
  const tt_grid *g;
  double bound;
} bound_arg;

static bool within_bound(void *arg, const tt__mesh *m, const int32_t *slots,
                         int ns)
{
  const bound_arg *b = arg;
  for (int i = 0; i < ns; i++) {
    tt__scan_tri st;
    tt__scan_tri_from_mesh(m, slots[i], &st);
    double err;
    int64_t index;
    tt__scan_candidate(b->g, &st, &err, &index);
    if (err > b->bound)
      return false;
  }
  return true;
}

bool tt__optimize_final(tt__mesh *m, const tt__criterion_vt *crit,
                        const tt__crit_env *env, tt_optimize mode,
                        tt_repair repair, double bound,
                        const tt_anneal_options *anneal,
                        tt__opt_stats *out_stats)
{
  if (out_stats)
    memset(out_stats, 0, sizeof *out_stats);
  mode = tt_optimize_resolve(mode, crit->id, repair);
  if (mode == TT_OPTIMIZE_NONE)
    return true;
  bound_arg b = {env->grid, bound};
  if (mode == TT_OPTIMIZE_ANNEAL && crit->id != TT_CRITERION_DELAUNAY) {
    tt__anneal_stats as;
    bool ok = tt__anneal_run(m, crit, env, anneal, within_bound, &b, &as);
    if (out_stats) {
      out_stats->swaps = as.swaps;
      out_stats->refused = as.refused;
    }
    return ok;
  }
  if (mode == TT_OPTIMIZE_EDGE_INSERTION) {
    tt__edge_insert_stats es;
    bool ok = tt__edge_insert_run(m, env, within_bound, &b, &es);
    if (out_stats) {
      out_stats->swaps = es.insertions;
      out_stats->refused = es.refused;
    }
    return ok;
  }
  /* Delaunay's flips reach its global optimum: its annealing is the
   * local swap */
  tt__opt_params p = {crit, env, mode == TT_OPTIMIZE_LOOKAHEAD, within_bound,
                      &b};
  return tt__optimize_run(m, &p, NULL, 0, out_stats);
}
