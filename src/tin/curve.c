/*
 * curve.c -- the running error sums of a recorded run (curve.h): per-slot
 * sums and their double-double totals, the measures they give, a full
 * pass for the runs that keep no sums (decimation), and the final pass
 * applied to a copy of the mesh at a step.
 *
 * Workload: tt__curve_set runs once per rescanned triangle (a few per
 * insertion); tt__curve_final once per reported step of a run with a
 * final pass, O(slots) for the copy and the comparison plus the pass
 * itself and the scans of the triangles it changed; tt__curve_measure
 * once per decimation round, O(samples).
 *
 * Part of src/tin/, the finished TIN: its records and error statistics, eval,
 * synthetic terrains.
 */
#include "tin/curve.h"

#include "optimize/optimize.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

bool tt__curve_fit(tt__curve *c, size_t nslots)
{
  if (nslots <= c->cap)
    return true;
  size_t c1 = c->cap, c2 = c->cap, c3 = c->cap, old = c->cap;
  if (!tt__grow((void **)&c->sabs, &c1, nslots, sizeof(double)) ||
      !tt__grow((void **)&c->ssq, &c2, nslots, sizeof(double)) ||
      !tt__grow((void **)&c->count, &c3, nslots, sizeof(size_t))) {
    /* the arrays that grew keep their old entries; cap stays the least */
    return false;
  }
  size_t cap = c1 < c2 ? c1 : c2;
  cap = cap < c3 ? cap : c3;
  memset(c->sabs + old, 0, (cap - old) * sizeof(double));
  memset(c->ssq + old, 0, (cap - old) * sizeof(double));
  memset(c->count + old, 0, (cap - old) * sizeof(size_t));
  c->cap = cap;
  return true;
}

void tt__curve_set(tt__curve *c, int32_t t, const tt__scan_stats *s)
{
  /* subtracting what was added gives back the total up to the
   * double-double's rounding, and exactly 0 - 0 for an empty slot */
  if (c->count[t] || c->sabs[t] != 0 || c->ssq[t] != 0) {
    tt__dd_add(&c->abs, -c->sabs[t]);
    tt__dd_add(&c->sq, -c->ssq[t]);
    c->samples -= c->count[t];
  }
  if (s) {
    c->sabs[t] = s->sum_abs;
    c->ssq[t] = s->sum_sq;
    c->count[t] = s->count;
    tt__dd_add(&c->abs, s->sum_abs);
    tt__dd_add(&c->sq, s->sum_sq);
    c->samples += s->count;
  } else {
    c->sabs[t] = c->ssq[t] = 0;
    c->count[t] = 0;
  }
}

void tt__curve_free(tt__curve *c)
{
  free(c->sabs);
  free(c->ssq);
  free(c->count);
  memset(c, 0, sizeof *c);
}

/* The measures of sums sa, sq over n covered samples (metrics.c's
 * formulas). */
static void fill_errors(const tt_grid *g, double sa, double sq, size_t n,
                        size_t valid, double max, int64_t max_index,
                        tt_error_stats *out)
{
  memset(out, 0, sizeof *out);
  out->samples = valid;
  out->covered = n;
  /* cancellation may leave a sum a hair below zero once everything is
   * exact: a sum of non-negative terms is not negative */
  sa = sa > 0 ? sa : 0;
  sq = sq > 0 ? sq : 0;
  out->max_error = max;
  out->total_abs = sa;
  out->l2 = sqrt(sq);
  out->rmse = n ? sqrt(sq / (double)n) : 0;
  out->mean_abs = n ? sa / (double)n : 0;
  out->max_col = out->max_row = -1;
  if (max_index >= 0) {
    out->max_col = max_index % (int64_t)g->nx;
    out->max_row = max_index / (int64_t)g->nx;
  }
}

void tt__curve_errors(const tt__curve *c, const tt_grid *g, size_t vertices,
                      size_t valid, double max, int64_t max_index,
                      tt_error_stats *out)
{
  fill_errors(g, tt__dd_value(&c->abs), tt__dd_value(&c->sq),
              c->samples + vertices, valid, max, max_index, out);
}

/* Vertices in some triangle: their samples are covered, with error 0. */
static size_t linked_vertices(const tt__mesh *m)
{
  size_t n = 0;
  for (size_t v = 0; v < m->nv; v++)
    n += m->v[v].edge >= 0;
  return n;
}

void tt__curve_measure(const tt__mesh *m, const tt_grid *g, size_t valid,
                       tt_error_stats *out)
{
  tt__dd sa = {0, 0}, sq = {0, 0};
  size_t n = 0;
  double max = 0;
  int64_t max_index = -1;
  for (size_t t = 0; t < m->nslots; t++) {
    if (!tt__mesh_live(m, (int32_t)t))
      continue;
    tt__scan_tri st;
    tt__scan_stats ss;
    tt__scan_tri_from_mesh(m, (int32_t)t, &st);
    tt__scan_stats_run(g, &st, &ss);
    tt__dd_add(&sa, ss.sum_abs);
    tt__dd_add(&sq, ss.sum_sq);
    n += ss.count;
    if (ss.count && ss.max_err > 0 &&
        (ss.max_err > max || (ss.max_err == max && ss.max_index < max_index)))
    {
      max = ss.max_err;
      max_index = ss.max_index;
    }
  }
  fill_errors(g, tt__dd_value(&sa), tt__dd_value(&sq),
              n + linked_vertices(m), valid, max, max_index, out);
}

/* Whether slot t holds the same triangle in a and b (the same corners in
 * the same cyclic order, so the same plane and the same owned samples:
 * the boundary of the domain is the same in both). */
static bool same_triangle(const tt__mesh *a, const tt__mesh *b, size_t t)
{
  bool la = t < a->nslots && tt__mesh_live(a, (int32_t)t);
  bool lb = t < b->nslots && tt__mesh_live(b, (int32_t)t);
  if (la != lb)
    return false;
  if (!la)
    return true;
  const int32_t *p = a->hv + 3 * t, *q = b->hv + 3 * t;
  for (int k = 0; k < 3; k++)
    if (p[0] == q[k] && p[1] == q[(k + 1) % 3] && p[2] == q[(k + 2) % 3])
      return true;
  return false;
}

/* Keeps the largest error, ties to the smaller sample index. */
static void take_max(double err, int64_t index, double *max,
                     int64_t *max_index)
{
  if (index < 0 || err <= 0)
    return;
  if (err > *max || (err == *max && index < *max_index)) {
    *max = err;
    *max_index = index;
  }
}

bool tt__curve_final(const tt__curve *c, const tt__mesh *m,
                     const double *cerr, const int64_t *cand,
                     const tt__criterion_vt *crit, const tt__crit_env *env,
                     tt_optimize mode, tt_repair repair, double bound,
                     const tt_anneal_options *anneal, size_t vertices,
                     size_t valid, tt_error_stats *out)
{
  tt__mesh cp;
  if (!tt__mesh_copy(&cp, m))
    return false;
  tt__crit_env ce = *env;
  ce.mesh = &cp;
  ce.cache = crit->cache_new ? crit->cache_new(&ce) : NULL;
  bool ok = tt__optimize_final(&cp, crit, &ce, mode, repair, bound, anneal,
                               NULL);
  if (ce.cache)
    crit->cache_free(ce.cache);
  if (!ok) {
    tt__mesh_free(&cp);
    return false;
  }
  /* the totals of m, the changed slots' sums replaced by the copy's */
  tt__dd sa = c->abs, sq = c->sq;
  size_t n = c->samples;
  double max = 0;
  int64_t max_index = -1;
  size_t nslots = cp.nslots > m->nslots ? cp.nslots : m->nslots;
  for (size_t t = 0; t < nslots; t++) {
    if (same_triangle(m, &cp, t)) {
      if (t < m->nslots && tt__mesh_live(m, (int32_t)t))
        take_max(cerr[t], cand[t], &max, &max_index);
      continue;
    }
    if (t < m->nslots && tt__mesh_live(m, (int32_t)t)) {
      tt__dd_add(&sa, -c->sabs[t]);
      tt__dd_add(&sq, -c->ssq[t]);
      n -= c->count[t];
    }
    if (t < cp.nslots && tt__mesh_live(&cp, (int32_t)t)) {
      tt__scan_tri st;
      tt__scan_stats ss;
      tt__scan_tri_from_mesh(&cp, (int32_t)t, &st);
      tt__scan_stats_run(env->grid, &st, &ss);
      tt__dd_add(&sa, ss.sum_abs);
      tt__dd_add(&sq, ss.sum_sq);
      n += ss.count;
      take_max(ss.max_err, ss.max_index, &max, &max_index);
    }
  }
  /* a pass changes no vertex: the vertices in triangles stay those */
  fill_errors(env->grid, tt__dd_value(&sa), tt__dd_value(&sq), n + vertices,
              valid, max, max_index, out);
  tt__mesh_free(&cp);
  return true;
}
