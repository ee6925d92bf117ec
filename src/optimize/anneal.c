/*
 * anneal.c -- simulated annealing (see anneal.h for the schedule, how the
 * best triangulation is kept, and what a run guarantees).
 *
 * State of a run: the generator, the running sum of swap values taken
 * (energy) and the best one, for the max-type criteria an indexed max-heap
 * of per-item values (triangle slot -> its largest angle, or half-edge ->
 * the angle between the normals across it) whose top is the criterion's
 * global value, the undo log of the swaps since the best (or since the
 * last snapshot of it), and that snapshot.
 *
 * Workload: one swap-value evaluation per try, at most K x S tries (with
 * the defaults 500 per swappable edge), each swap two slots' worth of heap
 * updates for the max-type criteria. Memory: the log, at most LOG_MAX
 * records of about 110 bytes, and one snapshot (13 bytes per slot).
 *
 * Part of src/optimize/, the optimisers: swaps under a criterion, look-ahead,
 * annealing, edge insertion, the dynamic programs.
 */
#include "optimize/anneal.h"

#include "base/heap.h"
#include "base/random.h"
#include "criteria/geometry.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* --- the generator: base/random.h (xoshiro256**) ------------------------ */

/* Uniform in [0, n), n > 0 (the modulo bias is below n / 2^64). */
static uint64_t rng_below(tt__rng *g, uint64_t n)
{
  return tt__rng_next(g) % n;
}

/* --- the run's state ----------------------------------------------------- */

enum { KIND_SUM, KIND_TRI_ANGLE, KIND_EDGE_ALPHA };

/* Records in the undo log before the best is saved whole. */
#define LOG_MIN 65536
#define LOG_MAX (1 << 20)

typedef struct logrec {
  tt__mesh_flip_undo u;
  int32_t e;            /* the half-edge flipped (to replay it) */
} logrec;

typedef struct ann {
  tt__mesh *m;
  const tt__criterion_vt *crit;
  const tt__crit_env *env;
  tt__opt_accept_fn accept;
  void *accept_arg;
  double fr[4];
  int kind;
  tt__heap heap;        /* KIND_TRI_ANGLE / KIND_EDGE_ALPHA */
  double energy, best_energy, best_global, tol, best_tol;
  logrec *log;
  size_t nlog, logcap, logmax;
  tt__mesh_snapshot snap;
  bool snap_is_best;    /* the best is in snap, the log runs from it */
  tt__anneal_stats st;
} ann;

static bool swappable(const tt__mesh *m, int32_t e)
{
  return m->twin[e] >= 0 && !(m->eflag[e] & TT__EDGE_CONSTRAINED) &&
         tt__mesh_flippable(m, e);
}

/* The largest 2-D angle of live triangle t. */
static double tri_max_angle(const ann *a, int32_t t)
{
  const tt__mesh *m = a->m;
  int32_t p = m->hv[3 * t], q = m->hv[3 * t + 1], r = m->hv[3 * t + 2];
  tt__gvec pq = tt__geo_vec(a->fr, m, p, q), pr = tt__geo_vec(a->fr, m, p, r);
  tt__gvec qr = tt__geo_vec(a->fr, m, q, r);
  tt__gvec qp = {-pq.x, -pq.y, -pq.z}, rp = {-pr.x, -pr.y, -pr.z};
  tt__gvec rq = {-qr.x, -qr.y, -qr.z};
  double x = tt__gangle2(pq, pr), y = tt__gangle2(qr, qp),
         z = tt__gangle2(rp, rq);
  double mx = x > y ? x : y;
  return mx > z ? mx : z;
}

/* The normal of live triangle t (length: twice its 3-D area). */
static tt__gvec tri_normal(const ann *a, int32_t t)
{
  const tt__mesh *m = a->m;
  int32_t p = m->hv[3 * t];
  return tt__gcross(tt__geo_vec(a->fr, m, p, m->hv[3 * t + 1]),
                    tt__geo_vec(a->fr, m, p, m->hv[3 * t + 2]));
}

/* Puts the items of slot t into the heap with their current values. */
static bool heap_slot(ann *a, int32_t t)
{
  const tt__mesh *m = a->m;
  if (a->kind == KIND_TRI_ANGLE)
    return tt__heap_set(&a->heap, t, tri_max_angle(a, t));
  tt__gvec n = tri_normal(a, t);
  for (int k = 0; k < 3; k++) {
    int32_t h = 3 * t + k, o = m->twin[h];
    if (o < 0)
      continue;
    double alpha = tt__gangle(n, tri_normal(a, o / 3));
    if (!tt__heap_set(&a->heap, h, alpha) || !tt__heap_set(&a->heap, o, alpha))
      return false;
  }
  return true;
}

/* The global value of the max-type criteria (lower is better); 0 for the
 * additive ones. */
static double global(const ann *a)
{
  if (a->kind == KIND_SUM || tt__heap_size(&a->heap) == 0)
    return 0.0;
  return tt__heap_top(&a->heap).key;
}

static bool heap_all(ann *a)
{
  const tt__mesh *m = a->m;
  if (a->kind == KIND_SUM)
    return true;
  size_t items = a->kind == KIND_TRI_ANGLE ? m->nslots : 3 * m->nslots;
  if (!tt__heap_reserve_items(&a->heap, items ? items : 1))
    return false;
  for (size_t t = 0; t < m->nslots; t++)
    if (tt__mesh_live(m, (int32_t)t) && !heap_slot(a, (int32_t)t))
      return false;
  return true;
}

/* --- the lexicographic guard ---------------------------------------------
 * For minmax_angle_lex and abn the quality is a sorted vector, of which the
 * heap's top is only the first entry: the start is saved, and at the end
 * the vectors of the start and of the best are compared in full. */

static int cmp_desc(const void *x, const void *y)
{
  double a = *(const double *)x, b = *(const double *)y;
  return a < b ? 1 : a > b ? -1 : 0;
}

/* The criterion's vector of the current mesh, sorted in decreasing order,
 * into *out (malloc'd); its length, or 0 when out of memory. */
static size_t lex_vector(const ann *a, double **out)
{
  const tt__mesh *m = a->m;
  double *v = malloc((3 * m->nslots + 1) * sizeof *v);
  size_t n = 0;
  *out = v;
  if (!v)
    return 0;
  for (size_t t = 0; t < m->nslots; t++) {
    if (!tt__mesh_live(m, (int32_t)t))
      continue;
    int32_t c[3] = {m->hv[3 * t], m->hv[3 * t + 1], m->hv[3 * t + 2]};
    if (a->crit->id == TT_CRITERION_MINMAX_ANGLE_LEX) {
      for (int k = 0; k < 3; k++)
        v[n++] = tt__gangle2(tt__geo_vec(a->fr, m, c[k], c[(k + 1) % 3]),
                             tt__geo_vec(a->fr, m, c[k], c[(k + 2) % 3]));
      continue;
    }
    tt__gvec nt = tri_normal(a, (int32_t)t);
    for (int k = 0; k < 3; k++) {
      int32_t h = 3 * (int32_t)t + k, o = m->twin[h];
      if (o > h)
        v[n++] = tt__gangle(nt, tri_normal(a, o / 3));
    }
  }
  if (n == 0)
    v[n++] = 0.0;
  qsort(v, n, sizeof *v, cmp_desc);
  return n;
}

/* > 0 when vector x (the best) is lexicographically worse than y (the
 * start): a larger entry first, differences below 1e-12 ignored. */
static int lex_worse(const double *x, const double *y, size_t n)
{
  for (size_t i = 0; i < n; i++)
    if (fabs(x[i] - y[i]) > 1e-12)
      return x[i] > y[i] ? 1 : -1;
  return 0;
}

/* --- the log and the best ------------------------------------------------ */

/* The current triangulation is the best seen: forget the way back. */
static void mark_best(ann *a)
{
  a->best_energy = a->energy;
  a->best_global = global(a);
  a->nlog = 0;
  a->snap_is_best = false;
  tt__mesh_clear_touched(a->m);
}

static bool better_than_best(const ann *a)
{
  double g = global(a);
  if (a->kind != KIND_SUM && g != a->best_global)
    return g < a->best_global;
  return a->energy > a->best_energy + a->best_tol;
}

/* Takes back the last swap of the log (heap included). */
static bool undo_last(ann *a)
{
  logrec *r = &a->log[--a->nlog];
  tt__mesh_flip_revert(a->m, &r->u);
  return a->kind == KIND_SUM ||
         (heap_slot(a, r->u.slot[0]) && heap_slot(a, r->u.slot[1]));
}

/* The log is full: back to the best, save it, replay the log, empty it. */
static bool save_best(ann *a)
{
  size_t n = a->nlog;
  if (!a->snap_is_best) {
    while (a->nlog > 0)
      if (!undo_last(a))
        return false;
    if (!tt__mesh_snapshot_take(a->m, &a->snap))
      return false;
    a->st.saves++;
    for (size_t i = 0; i < n; i++) {
      logrec *r = &a->log[i];
      if (tt__mesh_flip_undoable(a->m, r->e, &r->u) < 0)
        return false;
      if (a->kind != KIND_SUM &&
          (!heap_slot(a, r->u.slot[0]) || !heap_slot(a, r->u.slot[1])))
        return false;
    }
    a->snap_is_best = true;
  }
  a->nlog = 0;
  tt__mesh_clear_touched(a->m);
  return true;
}

/* Leaves the best triangulation in the mesh. */
static bool back_to_best(ann *a)
{
  if (a->snap_is_best) {
    a->nlog = 0;
    tt__mesh_clear_touched(a->m);
    return tt__mesh_snapshot_restore(a->m, &a->snap);
  }
  while (a->nlog > 0)
    if (!undo_last(a))
      return false;
  return true;
}

/* Swaps e (swap value d); false when out of memory. *out_done: whether
 * the swap stands (the accept callback may refuse it). */
static bool do_swap(ann *a, int32_t e, double d, bool *out_done)
{
  *out_done = false;
  if (a->nlog == a->logcap &&
      !tt__grow((void **)&a->log, &a->logcap, a->nlog + 1, sizeof(logrec)))
    return false;
  logrec *r = &a->log[a->nlog];
  r->e = e;
  if (tt__mesh_flip_undoable(a->m, e, &r->u) < 0)
    return false;
  a->nlog++;
  if (a->accept && !a->accept(a->accept_arg, a->m, r->u.slot, 2)) {
    a->nlog--;
    tt__mesh_flip_revert(a->m, &r->u);
    a->st.refused++;
    return true;
  }
  if (a->kind != KIND_SUM &&
      (!heap_slot(a, r->u.slot[0]) || !heap_slot(a, r->u.slot[1])))
    return false;
  a->energy += d;
  *out_done = true;
  if (better_than_best(a))
    mark_best(a);
  else if (a->nlog >= a->logmax)
    return save_best(a);
  return true;
}

/* A random swappable half-edge, or -1 when none was found in a long run
 * of draws (a mesh with no swappable edge left). */
static int32_t draw(ann *a, tt__rng *g)
{
  const tt__mesh *m = a->m;
  uint64_t nh = 3 * (uint64_t)m->nslots;
  for (uint64_t i = 0; i < 64 + 4 * nh; i++) {
    int32_t e = (int32_t)rng_below(g, nh);
    if (tt__mesh_live(m, e / 3) && swappable(m, e))
      return e;
  }
  return -1;
}

bool tt__anneal_run(tt__mesh *m, const tt__criterion_vt *crit,
                    const tt__crit_env *env, const tt_anneal_options *opt,
                    tt__opt_accept_fn accept, void *accept_arg,
                    tt__anneal_stats *out_stats)
{
  return tt__anneal_run_log(m, crit, env, opt, accept, accept_arg, 0,
                            out_stats);
}

bool tt__anneal_run_log(tt__mesh *m, const tt__criterion_vt *crit,
                        const tt__crit_env *env, const tt_anneal_options *opt,
                        tt__opt_accept_fn accept, void *accept_arg,
                        size_t log_records, tt__anneal_stats *out_stats)
{
  ann a;
  memset(&a, 0, sizeof a);
  a.m = m;
  a.crit = crit;
  a.env = env;
  a.accept = accept;
  a.accept_arg = accept_arg;
  tt__geo_frame(env, a.fr);
  tt__heap_init(&a.heap);
  a.kind = crit->id == TT_CRITERION_MINMAX_ANGLE ||
                   crit->id == TT_CRITERION_MINMAX_ANGLE_LEX
               ? KIND_TRI_ANGLE
               : crit->id == TT_CRITERION_ABN ? KIND_EDGE_ALPHA : KIND_SUM;
  a.logmax = log_records     ? log_records
             : m->nslots < LOG_MIN ? LOG_MIN
             : m->nslots > LOG_MAX ? LOG_MAX
                                   : m->nslots;
  bool ok = true;
  /* E and the largest |swap value| (the scale of t0 and of the noise) */
  double scale = 0.0;
  for (size_t e = 0; e < 3 * m->nslots; e++)
    if (tt__mesh_live(m, (int32_t)(e / 3)) && m->twin[e] > (int32_t)e &&
        swappable(m, (int32_t)e)) {
      a.st.edges++;
      double v = fabs(crit->swap_value(env, (int32_t)e));
      if (isfinite(v) && v > scale)
        scale = v;
    }
  double t0 = opt && opt->t0 > 0 ? opt->t0 : 2.0 * scale;
  int stages = opt && opt->stages > 0 ? opt->stages : 100;
  double sper = opt && opt->swaps > 0 ? opt->swaps : 5.0;
  double gper = opt && opt->good > 0 ? opt->good : 5.0;
  double r = opt && opt->r > 0 && opt->r < 1 ? opt->r : 0.95;
  a.st.t0 = t0;
  a.tol = TT__OPT_REL_EPS * scale;
  a.best_tol = TT__OPT_PAIR_EPS * scale;
  long S = (long)ceil(sper * (double)a.st.edges);
  long G = (long)ceil(gper * (double)a.st.edges);
  tt__rng g;
  tt__rng_seed(&g, opt ? opt->seed : 0);
  ok = heap_all(&a);
  bool lex = crit->id == TT_CRITERION_MINMAX_ANGLE_LEX ||
             crit->id == TT_CRITERION_ABN;
  tt__mesh_snapshot start;
  memset(&start, 0, sizeof start);
  double *vstart = NULL, *vbest = NULL;
  size_t nvec = 0;
  if (ok && lex) {
    nvec = lex_vector(&a, &vstart);
    ok = nvec > 0 && tt__mesh_snapshot_take(m, &start);
  }
  if (ok)
    mark_best(&a);
  double t = t0;
  for (int k = 1; ok && k <= stages && a.st.edges > 0 && t0 > 0; k++) {
    t *= r;
    long tries = 0, good = 0, swaps = 0;
    a.st.stages++;
    while (ok && tries < S && good < G) {
      int32_t e = draw(&a, &g);
      if (e < 0)
        break;
      tries++;
      double d = crit->swap_value(env, e);
      if (isnan(d))
        continue;
      bool take = d >= -a.tol || tt__rng_unit(&g) < exp(d / t);
      if (!take)
        continue;
      bool done;
      ok = do_swap(&a, e, d, &done);
      if (ok && done) {
        swaps++;
        good += d > a.tol;
        a.st.worse += d < -a.tol;
      }
    }
    a.st.tries += tries;
    a.st.swaps += swaps;
    if (swaps == 0)
      break;
  }
  /* out of memory or not, the mesh goes back to the best seen */
  bool back = back_to_best(&a);
  a.st.gain = a.best_energy;
  if (back && lex && vstart && start.hv) {
    size_t nb = lex_vector(&a, &vbest);
    if (nb == nvec && lex_worse(vbest, vstart, nvec) > 0) {
      tt__mesh_clear_touched(m);
      back = tt__mesh_snapshot_restore(m, &start);
      a.st.gain = 0.0;
    } else if (nb != nvec) {
      back = false;
    }
  }
  free(vstart);
  free(vbest);
  tt__mesh_snapshot_free(&start);
  if (out_stats)
    *out_stats = a.st;
  tt__heap_free(&a.heap);
  free(a.log);
  tt__mesh_snapshot_free(&a.snap);
  return ok && back;
}
