/*
 * study_curves.c -- apps/study/: the study command, a folder over the core
 * (apps/core/). This file: the curves of `terratin study -points N` (issue 15):
 * for each terrain, method, optimiser and criterion one engine run that reports
 * every step through the engine's recorder, a row per step.
 *
 * Insertion: tt_refine_run to N vertices, a row at every vertex count from
 * the start's to N. The measures come from the per-triangle sums the
 * engine keeps as it rescans triangles, not from a pass over every
 * sample; where the run has a final pass (the criteria the study
 * optimised after Delaunay insertion, optimiser auto or another one), each
 * row is the final pass applied to a copy of the mesh at that count, as
 * the study did and as `terratin simplify -max_points K` returns it.
 * Decimation: tt_decimate_run down to N vertices, a row at the start and
 * after every round (independent set; every removal with sequential
 * selection), each from a full pass over the samples (the engine keeps no
 * sums there), before the final pass; the last row is the TIN returned,
 * after it.
 * A row at the same count as the row before it (the step the run ends at)
 * replaces it.
 */
#include "study.h"

#include <stdlib.h>
#include <string.h>

tt_repair tt__study_repair(tt_criterion c)
{
  switch (c) {
  case TT_CRITERION_MEAN_CURVATURE:
  case TT_CRITERION_GAUSSIAN_CURVATURE:
  case TT_CRITERION_ABN:
  case TT_CRITERION_ABN_SUM:
  case TT_CRITERION_ABN_SUMSQ:
  case TT_CRITERION_L2:
    return TT_REPAIR_DELAUNAY;
  default:
    return TT_REPAIR_AUTO;
  }
}

typedef struct rec_arg {
  study_rows *out;
  size_t first;    /* this run's first row in out */
  study_row key;
  int nomem;
} rec_arg;

static int on_step(const tt_step_info *s, void *arg)
{
  rec_arg *a = arg;
  study_rows *o = a->out;
  study_row *w;
  if (o->n > a->first && o->w[o->n - 1].points == s->points) {
    w = &o->w[o->n - 1]; /* the end of the run, at the last row's count */
  } else {
    if (o->n == o->cap) {
      size_t cap = o->cap ? 2 * o->cap : 256;
      study_row *p = realloc(o->w, cap * sizeof *p);
      if (!p) {
        a->nomem = 1;
        return 0;
      }
      o->w = p;
      o->cap = cap;
    }
    w = &o->w[o->n++];
  }
  *w = a->key;
  w->points = s->points;
  w->e = s->errors;
  w->seconds = s->seconds;
  return 1;
}

tt_status tt__study_curve_run(app_run *r, const study_terrain *t,
                              const study_plan *p, const study_row *key,
                              study_rows *out)
{
  const tt_app_settings *s = r->s;
  tt_tin *tin = NULL;
  tt_status st;
  int dec = p->decimate[key->method];
  tt_criterion crit = p->crit[key->criterion];
  rec_arg a = {out, out->n, *key, 0};
  a.key.percent = SIZE_MAX; /* not a -percent row */
  study_method m = {dec, crit, p->opt[key->optimizer], 0, p->points,
                    on_step, &a, p->points};
  st = tt__study_method_run(r, t, &m, &tin);
  tt_tin_destroy(tin);
  if (a.nomem)
    return tt__app_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_NOMEM, NULL,
                        "study: out of memory for the rows of -points %zu",
                        p->points);
  if (st == TT_ERR_INTERRUPTED)
    return tt__app_fail_tt(r, st, s->output);
  if (st != TT_OK)
    return tt__app_fail(r, st == TT_ERR_LIMIT ? TT_APP_EXIT_USAGE
                                              : TT_APP_EXIT_FAILURE,
                        st, NULL, "study: %s, %s, %s, optimizer %s, -points "
                        "%zu: %s", t->label, dec ? "decimate" : "insert",
                        tt_criterion_name(crit),
                        tt_optimize_name(p->opt[key->optimizer]), p->points,
                        tt__app_why(r, st, t->arg));
  return TT_OK;
}
