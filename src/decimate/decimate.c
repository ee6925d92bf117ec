/*
 * decimate.c -- vertex decimation (SPEC section 3.6; docs/decimation.md):
 * from a fine TIN (start.c), delete the least important vertices
 * (importance.c), filling each hole (hole.c) and restoring the criterion
 * around it, until the first stop condition.
 *
 * Selection. Independent sets: each round scores the vertices whose star
 * changed since they were scored (all of them in the first round; none
 * after it with onepass), takes them in increasing importance (ties: the
 * smaller index) and picks every one with no neighbour picked before it
 * (a maximal independent set in importance order, as the study did), then
 * deletes the picked ones in that order. Sequential: a heap of every
 * removable vertex keyed by importance; the least important goes, and the
 * vertices around its hole are rescored at once.
 *
 * The bound is exact: with max_error E a vertex goes only when the filled
 * hole leaves every valid sample under it within E (the hole's triangles
 * scanned, importance.c), and a flip of the repair or of the final pass
 * is refused when one of its two triangles would hold a sample above E. A
 * vertex refused for the bound is kept until its star changes. The other
 * stops are counts: the run stops as soon as the TIN has at most
 * max_points vertices or at most max_triangles triangles (one removal
 * takes one vertex and two triangles, one on the boundary), within a
 * round too, so the count is exact.
 *
 * Repair around a filled hole (tt_repair, resolved as for refinement):
 * delaunay, the exact incircle flips seeded with the hole's edges (the
 * criterion then acts in the final pass); flip, the same Lawson flips
 * under the criterion's swap value; local and lookahead, the local swap
 * of optimize.c seeded with them.
 *
 * Tiles (tt__decimate_tile, src/tile/): the border vertices of the
 * tile's shared sides are pinned and the side's other samples removed
 * first (trim_borders), so the piece meets its neighbour's border edges
 * exactly; boundary edges are never flipped.
 *
 * Determinism: everything after the start runs in one thread in a fixed
 * order (ties on vertex indices), so the TIN does not depend on threads.
 * Memory: the mesh, 9 bytes per vertex, 4 per vertex of candidates, the
 * scans' tile bounds (0.25 bytes per sample).
 *
 * Part of src/decimate/, the vertex decimation method (tt_decimate_run).
 */
#include "decimate/decimate.h"
#include "mesh/breaklines.h"

#include "base/heap.h"
#include "base/parallel.h"
#include "optimize/optimize.h"
#include "refine/refine.h"
#include "tin/curve.h"
#include "tin/tin.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* --- the run's state ---------------------------------------------------- */

typedef struct run {
  tt__dec d;
  tt__pool *pool;
  size_t target_v, target_t;  /* 0: none */
  int32_t *seeds;             /* half-edges of the last fill */
  size_t seedcap;
  int32_t *dirty;             /* sequential: vertices to rescore */
  size_t ndirty, dirtycap;
  tt__heap heap;
  size_t removed, rounds, refused;
  tt_stop_reason reason;
  size_t since_progress;
  tt__dec_check_fn check;     /* tests only */
  void *check_arg;
  /* curves (opt->step): measured by a full pass at each report */
  size_t valid;
  double t_start, rec_seconds;
} run;

static tt_status oom(run *r)
{
  return tt__error(r->d.ctx, TT_ERR_NOMEM, "out of memory after %zu "
                   "removals", r->removed);
}

/* Whether a count stop is reached (sets the reason). */
static bool count_stop(run *r)
{
  if (r->target_v && r->d.nvert <= r->target_v) {
    r->reason = TT_STOP_MAX_POINTS;
    return true;
  }
  if (r->target_t && r->d.m.nlive <= r->target_t) {
    r->reason = TT_STOP_MAX_TRIANGLES;
    return true;
  }
  return false;
}

/* Reports the mesh as it stands after `rounds` rounds (opt->step): one
 * pass over every sample. TT_ERR_INTERRUPTED when the callback says
 * stop. */
static tt_status report_step(run *r, bool last)
{
  const tt_decimate_options *o = r->d.opt;
  if (!o->step)
    return TT_OK;
  double t0 = tt__now();
  tt_step_info si;
  memset(&si, 0, sizeof si);
  si.step = r->rounds;
  si.points = r->d.nvert;
  si.triangles = r->d.m.nlive;
  tt__curve_measure(&r->d.m, r->d.g, r->valid, &si.errors);
  si.seconds = t0 - r->t_start - r->rec_seconds;
  si.last = last;
  int go = o->step(&si, o->step_arg);
  r->rec_seconds += tt__now() - t0;
  if (!go)
    return tt__error(r->d.ctx, TT_ERR_INTERRUPTED, "interrupted by the step "
                     "callback after %zu removals", r->removed);
  return TT_OK;
}

/* The corners of every slot written since the last call: their stars
 * changed. */
static bool mark_touched(run *r, bool listing)
{
  tt__mesh *m = &r->d.m;
  for (size_t i = 0; i < m->ntouched; i++) {
    int32_t t = m->touched[i];
    if (!tt__mesh_live(m, t))
      continue;
    for (int k = 0; k < 3; k++) {
      int32_t v = m->hv[3 * t + k];
      uint8_t *f = &r->d.vflag[v];
      if (!(*f & TT__DV_DIRTY) && listing) {
        if (!tt__grow((void **)&r->dirty, &r->dirtycap, r->ndirty + 1,
                      sizeof(int32_t)))
          return false;
        r->dirty[r->ndirty++] = v;
      }
      *f = (uint8_t)((*f | TT__DV_DIRTY) & ~TT__DV_BLOCKED);
    }
  }
  tt__mesh_clear_touched(m);
  return true;
}

/* The error check of the repair's flips: no triangle above the bound. */
static bool accept_bound(void *arg, const tt__mesh *m, const int32_t *slots,
                         int nslots)
{
  const tt__dec *d = arg;
  if (d->max_error < 0)
    return true;
  for (int i = 0; i < nslots; i++) {
    int32_t t = slots[i];
    if (t < 0 || !tt__mesh_live(m, t))
      continue;
    if (tt__dec_triangle_error(d, m->hv[3 * t], m->hv[3 * t + 1],
                               m->hv[3 * t + 2]) > d->max_error)
      return false;
  }
  return true;
}

/* Lawson flips from the seeds under crit: an edge is flipped when it is
 * flippable, its swap value is above tol and the bound allows; the four
 * outer edges of its quad are examined next. Delaunay's incircle values
 * make this terminate; for other criteria a budget guards against
 * cycles from rounding. False when out of memory. */
static bool lawson(run *r, const tt__criterion_vt *crit, size_t nseeds)
{
  tt__dec *d = &r->d;
  tt__mesh *m = &d->m;
  tt__edge_stack *s = &d->stack;
  s->n = 0;
  for (size_t i = 0; i < nseeds; i++) {
    if (!tt__grow((void **)&s->e, &s->cap, s->n + 1, sizeof(int32_t)))
      return false;
    s->e[s->n++] = r->seeds[i];
  }
  long budget = 64 + 16 * (long)nseeds;
  double scale = 0;
  bool exact = crit->id == TT_CRITERION_DELAUNAY;
  while (s->n > 0 && budget > 0) {
    int32_t e = s->e[--s->n];
    if (!tt__mesh_live(m, e / 3) || m->twin[e] < 0 ||
        !tt__mesh_flippable(m, e))
      continue;
    double val = crit->swap_value(&d->env, e);
    scale = fmax(scale, fabs(val));
    if (!(val > (exact ? 0.0 : TT__OPT_REL_EPS * scale)))
      continue;
    tt__mesh_flip_undo undo;
    int32_t h = tt__mesh_flip_undoable(m, e, &undo);
    if (h < 0)
      return false;
    int32_t slots[2] = {h / 3, m->twin[h] / 3};
    if (!accept_bound(d, m, slots, 2)) {
      tt__mesh_flip_revert(m, &undo);
      continue;
    }
    if (crit->flipped)
      crit->flipped(&d->env, h);
    budget--;
    int32_t g = m->twin[h];
    int32_t outer[4] = {tt__next(h), tt__prev(h), tt__next(g), tt__prev(g)};
    if (!tt__grow((void **)&s->e, &s->cap, s->n + 4, sizeof(int32_t)))
      return false;
    for (int k = 0; k < 4; k++)
      s->e[s->n++] = outer[k];
  }
  s->n = 0;
  return true;
}

/* Restores the criterion around the hole just filled (its slots are the
 * touched log). */
static bool repair(run *r)
{
  tt__dec *d = &r->d;
  tt__mesh *m = &d->m;
  size_t nseeds = 0;
  if (!tt__grow((void **)&r->seeds, &r->seedcap, 3 * m->ntouched + 1,
                sizeof(int32_t)))
    return false;
  /* each edge once: an inner diagonal of the fill by one half-edge */
  for (size_t i = 0; i < m->ntouched; i++)
    for (int k = 0; k < 3; k++) {
      int32_t e = 3 * m->touched[i] + k, f = m->twin[e];
      bool inner_twice = false;
      for (size_t j = 0; j < m->ntouched && f >= 0 && f < e; j++)
        inner_twice |= m->touched[j] == f / 3;
      if (!inner_twice)
        r->seeds[nseeds++] = e;
    }
  if (d->repair == TT_REPAIR_DELAUNAY ||
      d->crit->id == TT_CRITERION_DELAUNAY)
    return lawson(r, &tt__criterion_delaunay, nseeds);
  if (d->repair == TT_REPAIR_FLIP)
    return lawson(r, d->crit, nseeds);
  tt__opt_params p = {d->crit, &d->env, d->repair == TT_REPAIR_LOOKAHEAD,
                      d->max_error >= 0 ? accept_bound : NULL, d};
  return tt__optimize_run(m, &p, r->seeds, nseeds, NULL);
}

/* Removes v with the fill left in d->h, repairs, marks the changed stars.
 * False when out of memory. */
static bool remove_filled(run *r, int32_t v, bool listing)
{
  tt__dec *d = &r->d;
  tt__mesh_clear_touched(&d->m);
  if (!tt__mesh_remove_vertex(&d->m, v, (const int32_t(*)[3])d->h.tri,
                              d->h.ntri))
    return false;
  d->nvert--;
  r->removed++;
  d->vimp[v] = NAN;
  if (!repair(r) || !mark_touched(r, listing))
    return false;
  if (r->check)
    r->check(r->check_arg, &d->m, v);
  return true;
}

/* Tries to remove v: the fill, the bound (fresh: v's importance is the
 * error of its current star), then the removal. 1 removed, 0 kept, -1
 * out of memory. */
static int try_remove(run *r, int32_t v, bool listing)
{
  tt__dec *d = &r->d;
  bool fresh = d->importance == TT_IMPORTANCE_ERROR &&
               !(d->vflag[v] & TT__DV_DIRTY) && !isnan(d->vimp[v]);
  double imp, err = fresh ? d->vimp[v] : 0;
  tt__dec_eval what = (d->max_error >= 0 && !fresh) ? TT__DEC_CHECK
                                                    : TT__DEC_FILL;
  int ok = tt__dec_evaluate(d, v, what, &imp, &err);
  if (ok <= 0)
    return ok;
  if (d->max_error >= 0 && err > d->max_error) {
    d->vflag[v] |= TT__DV_BLOCKED;
    r->refused++;
    return 0;
  }
  return remove_filled(r, v, listing) ? 1 : -1;
}

static bool progress(run *r)
{
  const tt_decimate_options *o = r->d.opt;
  if (!o->progress || ++r->since_progress < 256)
    return true;
  r->since_progress = 0;
  double f = 0;
  size_t start = r->d.nvert + r->removed;
  if (r->target_v && start > r->target_v)
    f = (double)r->removed / (double)(start - r->target_v);
  return o->progress(fmin(f, 0.99), "decimating", o->progress_arg) != 0;
}

/* Scores vertex v into vimp (NaN when it may not go); clears DIRTY. */
static int score(run *r, int32_t v)
{
  tt__dec *d = &r->d;
  double imp;
  int ok = tt__dec_evaluate(d, v, TT__DEC_SCORE, &imp, NULL);
  d->vimp[v] = ok > 0 ? imp : NAN;
  d->vflag[v] &= (uint8_t)~TT__DV_DIRTY;
  return ok;
}

/* Scores of many vertices at once: jobs of SCORE_CHUNK vertices, each
 * with its own hole scratch, writing only their vertices' vimp and flags
 * (so the result does not depend on the threads). */
#define SCORE_CHUNK 1024

typedef struct score_batch {
  run *r;
  const int32_t *v;
  size_t n;
  int failed;      /* a job ran out of memory (set by any) */
} score_batch;

static void score_job(void *arg, size_t index)
{
  score_batch *b = arg;
  tt__dec *d = &b->r->d;
  tt__dhole h;
  tt__dhole_init(&h);
  if (!tt__dhole_reserve(&h, 16)) {
    b->failed = 1;
    return;
  }
  size_t lo = index * SCORE_CHUNK;
  size_t hi = lo + SCORE_CHUNK < b->n ? lo + SCORE_CHUNK : b->n;
  for (size_t i = lo; i < hi; i++) {
    int32_t v = b->v[i];
    double imp;
    int ok = tt__dec_evaluate_in(d, &h, v, TT__DEC_SCORE, &imp, NULL);
    if (ok < 0)
      b->failed = 1;
    d->vimp[v] = ok > 0 ? imp : NAN;
    d->vflag[v] &= (uint8_t)~TT__DV_DIRTY;
  }
  tt__dhole_free(&h);
}

/* Scores the n vertices of list (distinct); false when out of memory. */
static bool score_many(run *r, const int32_t *list, size_t n)
{
  score_batch b = {r, list, n, 0};
  size_t njobs = (n + SCORE_CHUNK - 1) / SCORE_CHUNK;
  tt__pool_run(njobs > 1 ? r->pool : NULL, njobs, score_job, &b);
  return !b.failed;
}

typedef struct cand {
  double key;
  int32_t v;
} cand;

static int cmp_cand(const void *a, const void *b)
{
  const cand *x = a, *y = b;
  if (x->key != y->key)
    return x->key < y->key ? -1 : 1;
  return (x->v > y->v) - (x->v < y->v);
}

/* Sorts candidates by (key, vertex) like cmp_cand, by a stable LSD radix
 * sort of the keys' bits: the keys are >= 0 (every importance is), where
 * the IEEE order is the unsigned order of the bits, and the list comes in
 * vertex order, which stability keeps for equal keys. A byte that is the
 * same in every key costs no pass. False when out of memory. */
static bool sort_cands(cand *c, size_t n)
{
  if (n < 64) {
    qsort(c, n, sizeof *c, cmp_cand);
    return true;
  }
  cand *tmp = malloc(n * sizeof *tmp);
  if (!tmp)
    return false;
  cand *src = c, *dst = tmp;
  for (int pass = 0; pass < 8; pass++) {
    size_t count[256] = {0};
    int shift = 8 * pass;
    for (size_t i = 0; i < n; i++) {
      uint64_t u;
      memcpy(&u, &src[i].key, sizeof u);
      count[(u >> shift) & 255]++;
    }
    bool one = false;
    for (int b = 0; b < 256; b++)
      one |= count[b] == n;
    if (one)
      continue;
    size_t at = 0;
    for (int b = 0; b < 256; b++) {
      size_t k = count[b];
      count[b] = at;
      at += k;
    }
    for (size_t i = 0; i < n; i++) {
      uint64_t u;
      memcpy(&u, &src[i].key, sizeof u);
      dst[count[(u >> shift) & 255]++] = src[i];
    }
    cand *t = src;
    src = dst;
    dst = t;
  }
  if (src != c)
    memcpy(c, src, n * sizeof *c);
  free(tmp);
  return true;
}

static int cmp_i32(const void *a, const void *b)
{
  int32_t x = *(const int32_t *)a, y = *(const int32_t *)b;
  return (x > y) - (x < y);
}

static tt_status run_independent(run *r)
{
  tt__dec *d = &r->d;
  tt__mesh *m = &d->m;
  tt_status status = TT_OK;
  size_t nv = m->nv;
  cand *c = malloc((nv ? nv : 1) * sizeof *c);
  uint32_t *lock = calloc(nv ? nv : 1, sizeof *lock);
  int32_t *picked = malloc((nv ? nv : 1) * sizeof *picked);
  int32_t *ring = NULL;
  size_t ringcap = 0;
  if (!c || !lock || !picked) {
    status = oom(r);
    goto done;
  }
  for (uint32_t round = 1;; round++) {
    if (count_stop(r))
      break;
    /* onepass: a vertex is scored once (or until it first may go) */
    size_t ns = 0;
    for (size_t v = 0; v < nv; v++) {
      uint8_t f = d->vflag[v];
      if (m->v[v].edge < 0 || (f & TT__DV_PINNED))
        continue;
      if (round == 1 || ((f & TT__DV_DIRTY) &&
                         (!d->opt->onepass || isnan(d->vimp[v]))))
        picked[ns++] = (int32_t)v;
    }
    if (!score_many(r, picked, ns)) {
      status = oom(r);
      goto done;
    }
    size_t nc = 0;
    for (size_t v = 0; v < nv; v++) {
      uint8_t f = d->vflag[v];
      if (m->v[v].edge < 0 || (f & TT__DV_PINNED))
        continue;
      if (isnan(d->vimp[v]) || (f & TT__DV_BLOCKED))
        continue;
      if (d->importance == TT_IMPORTANCE_ERROR && d->max_error >= 0 &&
          !(f & TT__DV_DIRTY) && d->vimp[v] > d->max_error)
        continue; /* its removal, as things are, breaks the bound */
      c[nc].key = d->vimp[v];
      c[nc].v = (int32_t)v;
      nc++;
    }
    if (!sort_cands(c, nc)) {
      status = oom(r);
      goto done;
    }
    /* a maximal independent set in importance order */
    size_t np = 0;
    for (size_t i = 0; i < nc; i++) {
      int32_t v = c[i].v;
      if (lock[v] == round)
        continue;
      picked[np++] = v;
      lock[v] = round;
      bool closed;
      int n = tt__mesh_star(m, v, ring, NULL, (int)ringcap, &closed);
      if (n > (int)ringcap) {
        if (!tt__grow((void **)&ring, &ringcap, (size_t)n, sizeof *ring)) {
          status = oom(r);
          goto done;
        }
        (void)tt__mesh_star(m, v, ring, NULL, n, &closed);
      }
      for (int k = 0; k < n; k++)
        lock[ring[k]] = round;
    }
    /* The set goes together: unless this round may reach a count stop
     * (then in importance order, so the cut keeps the important ones),
     * in index order, which follows the start's spatial order and keeps
     * the mesh walks in cache (about a fifth of a run, measured). */
    bool last = (r->target_v && d->nvert <= r->target_v + np) ||
                (r->target_t && m->nlive <= r->target_t + 2 * np);
    if (!last)
      qsort(picked, np, sizeof *picked, cmp_i32);
    size_t before = r->removed;
    r->rounds++;
    for (size_t i = 0; i < np; i++) {
      if (count_stop(r))
        goto done;
      int ok = try_remove(r, picked[i], false);
      if (ok < 0 || !progress(r)) {
        status = ok < 0 ? oom(r)
                        : tt__error(d->ctx, TT_ERR_INTERRUPTED, "interrupted "
                                    "after %zu removals", r->removed);
        goto done;
      }
    }
    if (r->removed == before) {
      r->rounds--; /* a round that removed nothing is not counted */
      r->reason = d->max_error >= 0 ? TT_STOP_MAX_ERROR : TT_STOP_EXHAUSTED;
      break;
    }
    status = report_step(r, false);
    if (status != TT_OK)
      goto done;
  }
done:
  free(c);
  free(lock);
  free(picked);
  free(ring);
  return status;
}

static tt_status run_sequential(run *r)
{
  tt__dec *d = &r->d;
  tt__mesh *m = &d->m;
  tt__heap *hp = &r->heap;
  if (!tt__heap_reserve_items(hp, m->nv))
    return oom(r);
  for (size_t v = 0; v < m->nv; v++) {
    if (m->v[v].edge < 0 || (d->vflag[v] & TT__DV_PINNED))
      continue;
    int ok = score(r, (int32_t)v);
    if (ok < 0 || (ok > 0 && !tt__heap_set(hp, (int32_t)v, -d->vimp[v])))
      return oom(r);
  }
  for (;;) {
    if (count_stop(r))
      break;
    if (tt__heap_size(hp) == 0) {
      r->reason = d->max_error >= 0 ? TT_STOP_MAX_ERROR : TT_STOP_EXHAUSTED;
      break;
    }
    tt__heap_entry top = tt__heap_pop(hp);
    int32_t v = top.item;
    if (d->importance == TT_IMPORTANCE_ERROR && d->max_error >= 0 &&
        -top.key > d->max_error) {
      /* every other key is as large: nothing can go any more */
      r->reason = TT_STOP_MAX_ERROR;
      break;
    }
    r->ndirty = 0;
    int ok = try_remove(r, v, true);
    if (ok < 0)
      return oom(r);
    for (size_t i = 0; i < r->ndirty; i++) {
      int32_t w = r->dirty[i];
      int s = score(r, w);
      if (s < 0)
        return oom(r);
      if (s > 0) {
        if (!tt__heap_set(hp, w, -d->vimp[w]))
          return oom(r);
      } else {
        tt__heap_remove(hp, w);
      }
    }
    if (ok > 0) {
      r->rounds++;
      tt_status st = report_step(r, false);
      if (st != TT_OK)
        return st;
    }
    if (!progress(r))
      return tt__error(d->ctx, TT_ERR_INTERRUPTED, "interrupted after %zu "
                       "removals", r->removed);
  }
  return TT_OK;
}

/* Tile runs: the samples of the start on shared sides that are not
 * border vertices go first, in index order, without a check (each lies
 * strictly inside a straight run of the side whose cells are all valid,
 * so the boundary rule lets it go, and what is left of the side are the
 * border's chords, which hold its samples within the bound: border.c);
 * the border vertices are pinned. The starting count is taken after. */
static tt_status trim_borders(run *r)
{
  tt__dec *d = &r->d;
  tt__mesh *m = &d->m;
  for (size_t v = 0; v < m->nv; v++) {
    bool kept;
    if (m->v[v].edge < 0 ||
        !tt__tile_on_border(d->borders, d->g->nx, d->g->ny, m->v[v].c,
                            m->v[v].r, &kept))
      continue;
    if (kept) {
      d->vflag[v] |= TT__DV_PINNED;
      continue;
    }
    double imp;
    int ok = tt__dec_evaluate(d, (int32_t)v, TT__DEC_FILL, &imp, NULL);
    if (ok < 0 || (ok > 0 && !remove_filled(r, (int32_t)v, false)))
      return oom(r);
    if (ok == 0)
      return tt__error(d->ctx, TT_ERR_INTERNAL, "sample (%d, %d) of a tile "
                       "border is no border vertex and cannot be removed",
                       (int)m->v[v].c, (int)m->v[v].r);
  }
  r->removed = 0;
  return TT_OK;
}

/* Vertices that may never go: those with several fans (the outline
 * pinches there), the ends of constrained inner edges and of every edge
 * on a breakline. */
static void pin(tt__dec *d)
{
  tt__mesh *m = &d->m;
  uint8_t *out = calloc(m->nv ? m->nv : 1, 1);
  for (size_t e = 0; e < 3 * m->nslots; e++) {
    if (!tt__mesh_live(m, (int32_t)(e / 3)))
      continue;
    int32_t a = m->hv[e];
    if (m->eflag[e] & TT__EDGE_BREAKLINE) /* both ends, on the boundary
                                            too: a line keeps its edges */
      d->vflag[a] |= TT__DV_PINNED,
          d->vflag[m->hv[tt__next((int32_t)e)]] |= TT__DV_PINNED;
    if (m->twin[e] < 0) {
      if (out && out[a] < 2)
        out[a]++;
      if (!out || out[a] > 1)
        d->vflag[a] |= TT__DV_PINNED;
    } else if (m->eflag[e] & TT__EDGE_CONSTRAINED) {
      d->vflag[a] |= TT__DV_PINNED;
    }
  }
  /* an interior vertex met on no boundary edge may still be a pinch of
   * two closed fans: impossible in a valid mesh (a closed fan is the
   * whole neighbourhood) */
  free(out);
}

/* The worst |H - H'| over every live triangle (the bound the final pass
 * keeps when the run has no error limit). */
static double worst_error(const tt__dec *d)
{
  const tt__mesh *m = &d->m;
  double w = 0;
  for (size_t t = 0; t < m->nslots; t++)
    if (tt__mesh_live(m, (int32_t)t))
      w = fmax(w, tt__dec_triangle_error(d, m->hv[3 * t], m->hv[3 * t + 1],
                                         m->hv[3 * t + 2]));
  return w;
}

/* The TIN of the alive vertices (in index order) and their importance. */
static tt_status build_tin(run *r, tt_tin **out_tin)
{
  tt__dec *d = &r->d;
  tt__mesh *m = &d->m;
  tt_status status = TT_OK;
  tt__mesh c;
  tt__mesh_init(&c, &m->metric);
  tt__mesh_use_ground_points(&c, m->gxy, m->gnx);
  int32_t *map = malloc((m->nv ? m->nv : 1) * sizeof *map);
  double *ins = NULL, *imp = NULL;
  if (!map || !tt__mesh_reserve(&c, d->nvert, m->nlive) ||
      (m->vz && !tt__mesh_keep_f64(&c))) {
    status = oom(r);
    goto done;
  }
  for (size_t v = 0; v < m->nv; v++) {
    map[v] = -1;
    if (m->v[v].edge >= 0) {
      map[v] = tt__mesh_add_vertex(&c, m->v[v].c, m->v[v].r, tt__mesh_z(m, (int32_t)v));
      if (map[v] < 0) {
        status = oom(r);
        goto done;
      }
    }
  }
  for (size_t t = 0; t < m->nslots; t++)
    if (tt__mesh_live(m, (int32_t)t) &&
        tt__mesh_add_triangle(&c, map[m->hv[3 * t]], map[m->hv[3 * t + 1]],
                              map[m->hv[3 * t + 2]]) < 0) {
      status = oom(r);
      goto done;
    }
  ins = malloc((c.nv ? c.nv : 1) * sizeof *ins);
  imp = malloc((c.nv ? c.nv : 1) * sizeof *imp);
  if (!ins || !imp || !tt__mesh_link_all(&c)) {
    status = oom(r);
    goto done;
  }
  /* the breaklines' edges, flagged in the copy as in the mesh */
  for (size_t e = 0; e < 3 * m->nslots; e++)
    if ((m->eflag[e] & TT__EDGE_BREAKLINE) && tt__mesh_live(m, (int32_t)(e / 3)))
      (void)tt__breaklines_flag(&c, map[m->hv[e]],
                                map[m->hv[tt__next((int32_t)e)]]);
  if (d->borders) /* the piece's scans follow the neighbour's edges */
    tt__tile_flag_edges(&c, d->g->nx, d->g->ny, d->borders);
  for (size_t v = 0; v < m->nv; v++)
    if (map[v] >= 0) {
      ins[map[v]] = NAN; /* no insertion error: NULL in the outputs */
      imp[map[v]] = d->vimp[v];
    }
  status = d->borders
               ? tt__tin_build_homes(d->ctx, &c, d->g, ins, r->pool, out_tin)
               : tt__tin_build(d->ctx, &c, d->g, ins, r->pool, out_tin);
  ins = NULL; /* taken over */
  if (status != TT_OK)
    goto done;
  (*out_tin)->v_importance = imp;
  imp = NULL;
done:
  free(map);
  free(ins);
  free(imp);
  tt__mesh_free(&c);
  return status;
}

tt_status tt_decimate_run(tt_context *ctx, const tt_grid *grid,
                          const tt_decimate_options *opt, tt_tin **out_tin)
{
  return tt__decimate_run_checked(ctx, grid, opt, NULL, NULL, out_tin);
}

static tt_status decimate(tt_context *ctx, const tt_grid *grid,
                          const tt_decimate_options *opt,
                          const tt__tile_borders *borders,
                          tt__dec_check_fn check, void *check_arg,
                          tt_tin **out_tin);

tt_status tt__decimate_run_checked(tt_context *ctx, const tt_grid *grid,
                                   const tt_decimate_options *opt,
                                   tt__dec_check_fn check, void *check_arg,
                                   tt_tin **out_tin)
{
  return decimate(ctx, grid, opt, NULL, check, check_arg, out_tin);
}

tt_status tt__decimate_tile(tt_context *ctx, const tt_grid *grid,
                            const tt_decimate_options *opt,
                            const tt__tile_borders *borders,
                            tt_tin **out_tin)
{
  if (!borders)
    return tt__error(ctx, TT_ERR_ARG, "borders must not be NULL");
  return decimate(ctx, grid, opt, borders, NULL, NULL, out_tin);
}

static tt_status decimate(tt_context *ctx, const tt_grid *grid,
                          const tt_decimate_options *opt,
                          const tt__tile_borders *borders,
                          tt__dec_check_fn check, void *check_arg,
                          tt_tin **out_tin)
{
  double t_start = tt__now();
  if (!grid || !opt || !out_tin)
    return tt__error(ctx, TT_ERR_ARG, "grid, options and out_tin must not be "
                     "NULL");
  *out_tin = NULL;
  tt_status status = tt__decimate_check_options(ctx, opt);
  if (status != TT_OK)
    return status;
  size_t valid = 0;
  status = tt_grid_check(ctx, grid, &valid);
  if (status != TT_OK)
    return status;
  if (valid < 3)
    return tt__error(ctx, TT_ERR_DATA, "the grid has %zu valid sample%s: a "
                     "triangle needs 3", valid, valid == 1 ? "" : "s");

  run r;
  memset(&r, 0, sizeof r);
  tt__dec *d = &r.d;
  r.check = check;
  r.check_arg = check_arg;
  d->ctx = ctx;
  d->g = grid;
  d->opt = opt;
  d->borders = borders;
  d->crit = tt__criterion_get(opt->criterion);
  d->max_error = opt->max_error;
  d->importance = opt->importance != TT_IMPORTANCE_AUTO ? opt->importance
                  : opt->max_error >= 0                ? TT_IMPORTANCE_ERROR
                                                       : TT_IMPORTANCE_HDH;
  d->hole = opt->hole != TT_HOLE_AUTO ? opt->hole
            : opt->criterion == TT_CRITERION_DELAUNAY ? TT_HOLE_CIRCUMRADIUS
                                                      : TT_HOLE_MINANGLE;
  d->repair = tt_repair_resolve(opt->repair, opt->criterion);
  tt__metric metric;
  tt__metric_from_frame(grid->frame, &metric);
  tt__mesh_init(&d->m, &metric);
  tt__mesh_use_ground_points(&d->m, grid->gxy, grid->nx);
  tt__heap_init(&r.heap);
  if (grid->zd && !tt__mesh_keep_f64(&d->m)) {
    tt__mesh_free(&d->m);
    return tt__error(ctx, TT_ERR_NOMEM, "out of memory for the heights");
  }
  tt__dhole_init(&d->h);
  d->env.mesh = &d->m;
  d->env.grid = grid;
  int nthreads = opt->threads;
  if (nthreads == 0 && grid->nx * grid->ny < ((size_t)1 << 18))
    nthreads = 1; /* small grids: handing jobs over costs more */
  r.pool = tt__pool_create(tt__pool_threads(nthreads));
  r.target_v = opt->max_points;
  if (opt->percent > 0) {
    size_t p = (size_t)floor(opt->percent / 100.0 * (double)valid);
    if (!r.target_v || p < r.target_v)
      r.target_v = p ? p : 1;
  }
  r.target_t = opt->max_triangles;
  /* Every limit is exact: a point budget below the vertices the nodata
   * outline forces (what insertion's start needs, and the fewest a TIN
   * that follows the outline has) is refused before any work, as
   * insertion refuses it, with the count to ask for instead. */
  if (r.target_v && !borders && valid < grid->nx * grid->ny) {
    size_t need = 0;
    status = tt__refine_start_size(ctx, grid, &need);
    if (status != TT_OK)
      goto done;
    if (r.target_v < need) {
      status = tt__error(ctx, TT_ERR_LIMIT, "the point limit %zu%s is "
                         "below the %zu vertices the nodata outline "
                         "forces (the valid samples' hull and the outline's "
                         "corners, which no TIN that follows it can drop); "
                         "ask for at least %zu", r.target_v,
                         opt->percent > 0 && r.target_v != opt->max_points
                             ? " (from the percentage)" : "",
                         need, need);
      goto done;
    }
  }

  status = tt__dec_start(d, valid);
  if (status != TT_OK)
    goto done;
  tt__mesh_clear_touched(&d->m);
  if (d->crit->star_versions)
    (void)tt__mesh_track_stars(&d->m);
  d->env.cache = d->crit->cache_new ? d->crit->cache_new(&d->env) : NULL;
  (void)tt__scan_tiles_build(grid, r.pool, &d->tiles);
  d->vflag = calloc(d->m.nv ? d->m.nv : 1, 1);
  d->vimp = malloc((d->m.nv ? d->m.nv : 1) * sizeof *d->vimp);
  if (!d->vflag || !d->vimp || !tt__dhole_reserve(&d->h, 16)) {
    status = oom(&r);
    goto done;
  }
  for (size_t v = 0; v < d->m.nv; v++) {
    d->vimp[v] = NAN;
    d->nvert += d->m.v[v].edge >= 0;
  }
  if (borders && (status = trim_borders(&r)) != TT_OK)
    goto done;
  pin(d);
  size_t start_vertices = d->nvert;
  size_t pinned_border = 0;
  for (size_t v = 0; borders && v < d->m.nv; v++) {
    bool kept;
    pinned_border += d->m.v[v].edge >= 0 &&
                     tt__tile_on_border(borders, grid->nx, grid->ny,
                                        d->m.v[v].c, d->m.v[v].r, &kept);
  }
  r.valid = valid;
  r.t_start = t_start;
  status = report_step(&r, false);
  if (status != TT_OK)
    goto done;
  if (opt->progress && !opt->progress(0.0, "decimating", opt->progress_arg)) {
    status = tt__error(ctx, TT_ERR_INTERRUPTED, "interrupted");
    goto done;
  }
  status = opt->selection == TT_SELECTION_SEQUENTIAL ? run_sequential(&r)
                                                     : run_independent(&r);
  if (status != TT_OK)
    goto done;
  /* Every limit is exact: a budget the start cannot come down to (the
   * vertices `all`'s cell-by-cell outline keeps, more than the lean
   * outline the check above counts), unless the bound stopped the run
   * first, is refused, not passed with exit 0. */
  if (r.reason != TT_STOP_MAX_ERROR &&
      ((r.target_v && d->nvert > r.target_v) ||
       (r.target_t && d->m.nlive > r.target_t))) {
    status = tt__error(ctx, TT_ERR_LIMIT, "the %s limit %zu%s is below the "
                       "%zu %s this start cannot remove (the nodata "
                       "outline's cell corners); ask for at least %zu, or "
                       "start from -start greedy, which follows the lean "
                       "outline", r.target_v && d->nvert > r.target_v
                                      ? "point" : "triangle",
                       r.target_v && d->nvert > r.target_v ? r.target_v
                                                           : r.target_t,
                       opt->percent > 0 && r.target_v != opt->max_points
                           ? " (from the percentage)" : "",
                       r.target_v && d->nvert > r.target_v ? d->nvert
                                                           : d->m.nlive,
                       r.target_v && d->nvert > r.target_v ? "vertices"
                                                           : "triangles",
                       r.target_v && d->nvert > r.target_v ? d->nvert
                                                           : d->m.nlive);
    goto done;
  }
  /* the final pass keeps the bound (or the worst error left) */
  double bound = d->max_error >= 0 ? d->max_error : worst_error(d);
  tt_optimize mode = tt_optimize_resolve(opt->optimize, opt->criterion,
                                         d->repair);
  if (!tt__optimize_final(&d->m, d->crit, &d->env, mode, d->repair, bound,
                          &opt->anneal, NULL)) {
    status = oom(&r);
    goto done;
  }
  status = report_step(&r, true);
  if (status != TT_OK)
    goto done;
  /* the importance each vertex has now */
  {
    int32_t *all = malloc((d->m.nv ? d->m.nv : 1) * sizeof *all);
    size_t na = 0;
    for (size_t v = 0; all && v < d->m.nv; v++)
      if (d->m.v[v].edge >= 0)
        all[na++] = (int32_t)v;
    bool ok = all && score_many(&r, all, na);
    free(all);
    if (!ok) {
      status = oom(&r);
      goto done;
    }
  }
  tt__heap_free(&r.heap);
  tt__scan_tiles_free(&d->tiles);
  double t_meshed = tt__now();
  status = build_tin(&r, out_tin);
  if (status != TT_OK)
    goto done;
  tt_tin_summary *s = &(*out_tin)->summary;
  s->seconds_mesh = t_meshed - t_start;
  s->seconds_statistics = tt__now() - t_meshed;
  s->criterion = opt->criterion;
  s->stop_reason = r.reason;
  s->valid_samples = valid;
  s->errors.samples = valid;
  s->start_vertices = start_vertices;
  s->removed_vertices = r.removed;
  s->rounds = r.rounds;
  s->refused_bound = r.refused;
  s->forced_vertices = pinned_border;
  if (opt->progress && !opt->progress(1.0, "done", opt->progress_arg)) {
    tt_tin_destroy(*out_tin);
    *out_tin = NULL;
    status = tt__error(ctx, TT_ERR_INTERRUPTED, "interrupted");
  }
done:
  if (d->env.cache)
    d->crit->cache_free(d->env.cache);
  tt__pool_destroy(r.pool);
  tt__scan_tiles_free(&d->tiles);
  tt__heap_free(&r.heap);
  tt__dhole_free(&d->h);
  tt__edge_stack_free(&d->stack);
  free(d->vflag);
  free(d->vimp);
  free(r.seeds);
  free(r.dirty);
  tt__mesh_free(&d->m);
  return status;
}
