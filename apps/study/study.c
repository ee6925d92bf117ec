/*
 * study.c -- apps/study/: the study command, a folder over the core
 * (apps/core/). This file: `terratin study [options] OUTDIR`, the
 * comparison of the triangulation criteria (issue 15) as one command. For
 * every terrain (-terrain: a DEM file, or one of the study's generated
 * terrains by name with its published parameters), method (-methods
 * insert,decimate), criterion (-criteria), final optimiser (-optimizers)
 * and checkpoint (-percent P,P,...) it runs the engine as `terratin
 * simplify -percent P` would, and records the TIN summary's error
 * measures and the seconds the mesh took. study_files.c writes
 * OUTDIR/curves.csv (a row per run), OUTDIR/tables.md (the study's
 * tables: mean absolute error, one table per terrain, method and
 * optimiser, best per row in bold) and OUTDIR/runs.json (every parameter
 * and the version). A study is a pipeline over one study_job: prepare
 * (every check), load the terrains, the -percent runs, the -points runs,
 * the -tin_points runs, then finish (the files, the TINs, the plots, the
 * summary).
 *
 * Each checkpoint is its own run from the start, so its numbers are those
 * of a single simplify run at that percentage (the final optimisation
 * pass included). With -points N, study_curves.c adds the curves: a row at
 * every point count up to N (insertion) or after every round (decimation)
 * from one recorded run each. Insertion uses the study's repair
 * (tt__study_repair: Delaunay's flips for the criteria it optimised after
 * Delaunay insertion).
 *
 * `-terrain crater` is Crater Lake from the shared test data
 * (study_crater.c); -tin_points N adds a run per terrain, method,
 * criterion and optimiser stopped at N points whose TIN goes to
 * OUTDIR/tins (study_files.c); -plot runs tools/plot_study.py on OUTDIR
 * at the end (study_plot.c).
 *
 * Invariants: everything is checked (lists, combinations, every terrain
 * read, python and matplotlib for -plot) before the first run; an
 * existing non-empty OUTDIR is refused without -overwrite; the files are
 * written under temporary names and renamed once all three are complete,
 * and a failure leaves nothing (an OUTDIR the run created is removed
 * again) but the study's files when the plotting after them fails.
 */
#include "app.h"
#include "study.h"

#include <cpl_conv.h>
#include <cpl_string.h>

#include <errno.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

/* The study's generated terrains (SPEC section 4): nx = 0 keeps the
 * kind's default size; the fault and diamond-square fields apply to their
 * kinds only. */
static const struct named_terrain {
  const char *name;
  tt_synth_kind kind;
  size_t nx, ny;
  double displacement, wave_size; /* fault */
  double roughness;               /* diamond-square */
  tt_synth_seeding seeding;
} named_terrains[] = {
    {"fault_smooth", TT_SYNTH_FAULT, 80, 80, 20, 5, 0, TT_SEED_NONE},
    {"fault_rough", TT_SYNTH_FAULT, 100, 100, 100, 0, 0, TT_SEED_NONE},
    {"peak_rough", TT_SYNTH_DIAMOND_SQUARE, 129, 129, 0, 0, 0.7,
     TT_SEED_PEAK},
    {"valley_rough", TT_SYNTH_DIAMOND_SQUARE, 65, 65, 0, 0, 0.7,
     TT_SEED_VALLEY},
    {"hybrid", TT_SYNTH_DIAMOND_SQUARE, 129, 129, 0, 0, 0.7,
     TT_SEED_HYBRID},
    {"sphere", TT_SYNTH_SPHERE, 0, 0, 0, 0, 0, TT_SEED_NONE},
    {"cylinder", TT_SYNTH_CYLINDER, 0, 0, 0, 0, 0, TT_SEED_NONE},
    {"bump", TT_SYNTH_BUMP, 0, 0, 0, 0, 0, TT_SEED_NONE},
};
#define NAMED_COUNT (sizeof named_terrains / sizeof named_terrains[0])

/* Splits list (comma-separated, no empty items) into items of at most
 * size - 1 bytes each, calling item() on each; 0 with a usage failure
 * recorded when an item is empty, too long, too many, or item() refuses it
 * (item() records its own failure then). */
typedef int (*study_item_fn)(app_run *r, study_plan *p, const char *item);

static int split_list(app_run *r, study_plan *p, const char *option,
                      const char *list, study_item_fn item)
{
  char buf[128];
  const char *at = list;
  size_t count = 0;
  for (;;) {
    size_t n = strcspn(at, ",");
    if (n == 0 || n >= sizeof buf || ++count > STUDY_MAX_LIST) {
      tt__app_fail(r, TT_APP_EXIT_USAGE, TT_ERR_ARG, NULL,
                   "study: %s '%s' is not a comma-separated list of at most "
                   "%d non-empty items", option, list, STUDY_MAX_LIST);
      return 0;
    }
    memcpy(buf, at, n);
    buf[n] = '\0';
    if (!item(r, p, buf))
      return 0;
    if (at[n] == '\0')
      return 1;
    at += n + 1;
  }
}

static int add_criterion(app_run *r, study_plan *p, const char *w)
{
  tt_criterion c;
  if (tt_criterion_parse(r->ctx, w, &c) != TT_OK) {
    tt__app_fail(r, TT_APP_EXIT_USAGE, TT_ERR_ARG, NULL, "study: -criteria: %s",
                 tt_context_errmsg(r->ctx));
    return 0;
  }
  for (size_t k = 0; k < p->ncrit; k++)
    if (p->crit[k] == c) {
      tt__app_fail(r, TT_APP_EXIT_USAGE, TT_ERR_ARG, NULL,
                   "study: -criteria names %s twice", tt_criterion_name(c));
      return 0;
    }
  p->crit[p->ncrit++] = c;
  return 1;
}

static int add_method(app_run *r, study_plan *p, const char *w)
{
  int dec = tt__app_str_ieq(w, "decimate");
  if ((!dec && !tt__app_str_ieq(w, "insert")) || p->nmeth >= 2 ||
      (p->nmeth == 1 && p->decimate[0] == dec)) {
    tt__app_fail(r, TT_APP_EXIT_USAGE, TT_ERR_ARG, NULL,
                 "study: -methods takes insert and decimate, each at most "
                 "once, got '%s'", w);
    return 0;
  }
  p->decimate[p->nmeth++] = dec;
  return 1;
}

static int add_optimizer(app_run *r, study_plan *p, const char *w)
{
  if (tt_optimize_parse(r->ctx, w, &p->opt[p->nopt]) != TT_OK) {
    tt__app_fail(r, TT_APP_EXIT_USAGE, TT_ERR_ARG, NULL,
                 "study: unknown -optimizers item '%s'; known: none, local, "
                 "lookahead, anneal, edge_insertion, auto", w);
    return 0;
  }
  for (size_t k = 0; k < p->nopt; k++)
    if (p->opt[k] == p->opt[p->nopt]) {
      tt__app_fail(r, TT_APP_EXIT_USAGE, TT_ERR_ARG, NULL,
                   "study: -optimizers names %s twice", w);
      return 0;
    }
  p->nopt++;
  return 1;
}

static int add_percent(app_run *r, study_plan *p, const char *w)
{
  /* Plain decimals only (strtod would also take hex, exponents, "inf"),
   * each checkpoint once. */
  char *end = NULL;
  double x = strtod(w, &end);
  int seen = 0;
  for (size_t k = 0; k < p->npct; k++)
    seen |= p->pct[k] == x;
  if (!(w[0] >= '0' && w[0] <= '9') || strspn(w, "0123456789.") != strlen(w) ||
      *end || !(x > 0 && x <= 100) || seen ||
      strlen(w) >= sizeof p->pct_text[0]) {
    tt__app_fail(r, TT_APP_EXIT_USAGE, TT_ERR_ARG, NULL,
                 "study: -percent items must be distinct decimal numbers in "
                 "(0, 100], got '%s'", w);
    return 0;
  }
  strcpy(p->pct_text[p->npct], w);
  p->pct[p->npct++] = x;
  return 1;
}

/* Reads the lists and checks every criterion against every optimiser
 * (edge insertion is for minmax_angle only). */
static int make_plan(app_run *r, study_plan *p)
{
  const tt_app_settings *s = r->s;
  memset(p, 0, sizeof *p);
  if (!s->criteria || tt__app_str_ieq(s->criteria, "all")) {
    for (int ci = 0; ci < STUDY_MAX_LIST; ci++) {
      if (!tt_criterion_name((tt_criterion)ci))
        break;
      p->crit[p->ncrit++] = (tt_criterion)ci;
    }
  } else if (!split_list(r, p, "-criteria", s->criteria, add_criterion)) {
    return 0;
  }
  p->points = s->points;
  if (!split_list(r, p, "-methods", s->methods ? s->methods : "insert",
                  add_method) ||
      !split_list(r, p, "-optimizers", s->optimizers ? s->optimizers : "auto",
                  add_optimizer) ||
      /* -points alone: no -percent checkpoints */
      (!(s->points && !s->percents) &&
       !split_list(r, p, "-percent", s->percents ? s->percents : "1,10,25,50",
                   add_percent)))
    return 0;
  for (size_t o = 0; o < p->nopt; o++)
    for (size_t c = 0; c < p->ncrit; c++)
      if (tt_optimize_check(r->ctx, p->opt[o], p->crit[c], &s->anneal) !=
          TT_OK) {
        tt__app_fail(r, TT_APP_EXIT_USAGE, TT_ERR_ARG, NULL,
                     "study: -optimizers %s cannot run with criterion %s: %s",
                     tt_optimize_name(p->opt[o]),
                     tt_criterion_name(p->crit[c]),
                     tt_context_errmsg(r->ctx));
        return 0;
      }
  return 1;
}

/* Reads or generates one terrain; 0 with the failure recorded. */
static int load_terrain(app_run *r, study_terrain *t)
{
  const tt_app_settings *s = r->s;
  tt_status st = TT_OK;
  GDALDatasetH ds = NULL;
  GDALRasterBandH band = NULL;
  tt_raster_info *info = NULL;
  for (size_t i = 0; i < NAMED_COUNT; i++)
    if (tt__app_str_ieq(t->arg, named_terrains[i].name))
      t->named = &named_terrains[i];
  if (t->named) {
    const struct named_terrain *n = t->named;
    tt_synth_options_init(&t->synth, n->kind);
    if (n->nx) {
      t->synth.nx = n->nx;
      t->synth.ny = n->ny;
    }
    if (n->kind == TT_SYNTH_FAULT) {
      t->synth.displacement = n->displacement;
      t->synth.wave_size = n->wave_size;
    } else if (n->kind == TT_SYNTH_DIAMOND_SQUARE) {
      t->synth.roughness = n->roughness;
      t->synth.seeding = n->seeding;
    }
    if (s->seed_set)
      t->synth.seed = s->seed;
    t->label = n->name;
    st = tt_synth_generate(r->ctx, &t->synth, &t->grid);
    if (st != TT_OK)
      tt__app_fail(r, TT_APP_EXIT_FAILURE, st, NULL,
                   "study: -terrain %s: %s", n->name,
                   tt__app_why(r, st, n->name));
    else
      t->valid = tt_grid_width(t->grid) * tt_grid_height(t->grid);
    if (st == TT_OK && s->tin_points > t->valid)
      st = tt__app_fail(r, TT_APP_EXIT_USAGE, TT_ERR_ARG, NULL,
                        "study: -tin_points %zu is more than the %zu "
                        "samples of %s", s->tin_points, t->valid, n->name);
    goto done;
  }
  const char *slash = strrchr(t->arg, '/');
  const char *path = t->arg;
  t->label = slash && slash[1] ? slash + 1 : t->arg;
  int crater = tt__app_study_crater(r, t->arg, &t->path);
  if (crater < 0) {
    st = r->res->status;
    goto done;
  }
  if (crater) {
    t->label = "crater";
    path = t->path;
  }
  ds = tt__app_open_raster(r, path, s->band, &band);
  if (!ds) {
    st = r->res->status;
    goto done;
  }
  st = tt__app_read_dem(r, band, path, NULL, NULL, &t->grid, &info,
                        &t->valid);
  if (st == TT_OK && s->tin_points > t->valid)
    st = tt__app_fail(r, TT_APP_EXIT_USAGE, TT_ERR_ARG, NULL,
                      "study: -tin_points %zu is more than the %zu valid "
                      "samples of %s", s->tin_points, t->valid, path);
done:
  tt_raster_info_destroy(info);
  if (ds)
    tt__app_close_raster(r, ds);
  return st == TT_OK;
}

tt_status tt__study_method_run(app_run *r, const study_terrain *t,
                               const study_method *m, tt_tin **out_tin)
{
  const tt_app_settings *s = r->s;
  if (m->decimate) {
    tt_decimate_options d;
    tt_decimate_options_init(&d);
    d.max_error = -1.0;
    d.percent = m->percent;
    d.max_points = m->max_points;
    d.criterion = m->criterion;
    d.optimize = m->optimize;
    d.anneal = s->anneal;
    d.start = s->start;
    d.start_points = s->start_points;
    d.importance = s->importance;
    d.threads = tt__app_threads(r);
    d.progress = tt__app_phase_fn;
    d.progress_arg = &r->prog;
    d.step = m->step;
    d.step_arg = m->step_arg;
    return tt_decimate_run(r->ctx, t->grid, &d, out_tin);
  }
  tt_refine_options o;
  tt_refine_options_init(&o);
  o.max_error = -1.0;
  o.percent = m->percent;
  o.max_points = m->max_points;
  o.criterion = m->criterion;
  o.repair = tt__study_repair(m->criterion);
  o.optimize = m->optimize;
  o.anneal = s->anneal;
  o.threads = tt__app_threads(r);
  o.progress = tt__app_phase_fn;
  o.progress_arg = &r->prog;
  o.step = m->step;
  o.step_arg = m->step_arg;
  o.step_until = m->step_until;
  return tt_refine_run(r->ctx, t->grid, &o, out_tin);
}

/* One run, as `terratin simplify -percent P` with the same options (or
 * -max_points N when max_points is not 0; *out_tin then keeps the TIN). */
static tt_status run_one(app_run *r, const study_terrain *t,
                         const study_plan *p, study_row *row,
                         size_t max_points, tt_tin **out_tin)
{
  const tt_app_settings *s = r->s;
  tt_tin *tin = NULL;
  tt_tin_summary sum;
  tt_status st;
  int dec = p->decimate[row->method];
  study_method m = {dec, p->crit[row->criterion], p->opt[row->optimizer],
                    max_points ? 0 : p->pct[row->percent], max_points,
                    NULL, NULL, 0};
  st = tt__study_method_run(r, t, &m, &tin);
  if (st == TT_ERR_INTERRUPTED) {
    tt__app_fail_tt(r, st, s->output);
  } else if (st != TT_OK) {
    tt__app_fail(r, st == TT_ERR_LIMIT ? TT_APP_EXIT_USAGE
                                       : TT_APP_EXIT_FAILURE,
                 st, NULL, "study: %s, %s, %s, optimizer %s, %s%s: %s",
                 t->label, dec ? "decimate" : "insert",
                 tt_criterion_name(p->crit[row->criterion]),
                 tt_optimize_name(p->opt[row->optimizer]),
                 max_points ? CPLSPrintf("%zu", max_points)
                            : p->pct_text[row->percent],
                 max_points ? " points" : "%", tt__app_why(r, st, t->arg));
  } else {
    tt_tin_get_summary(tin, &sum);
    row->points = sum.vertices;
    row->e = sum.errors;
    row->seconds = sum.seconds_mesh;
  }
  if (st == TT_OK && out_tin)
    *out_tin = tin;
  else
    tt_tin_destroy(tin);
  return st;
}

/* The final pass a run made: auto resolved as the engine resolves it
 * (with the study's repair for insertion, study_curves.c). */
const char *tt__study_optimizer_used(const study_plan *p, const study_row *w)
{
  tt_criterion c = p->crit[w->criterion];
  tt_repair rep = p->decimate[w->method] ? TT_REPAIR_AUTO
                                         : tt__study_repair(c);
  return tt_optimize_name(tt_optimize_resolve(
      p->opt[w->optimizer], c, tt_repair_resolve(rep, c)));
}

/* One study: the plan, the terrains, the rows made, the files' helpers. */
typedef struct study_job {
  app_run *r;
  const tt_app_settings *s;
  study_plan plan;
  study_terrain *ts;       /* nterr terrains */
  size_t nterr;
  study_row *rows;         /* the -percent runs, in the tables' order */
  size_t nrows;
  study_rows steps;        /* the -points runs' rows */
  size_t nruns;            /* -points runs, then every run but the TINs' */
  size_t ntin;             /* the -tin_points runs */
  size_t total;            /* every run, for the progress */
  int exists;              /* OUTDIR exists */
  char *python, *script;   /* -plot */
  app_study_tins *tins;    /* -tin_points */
} study_job;

/* The plan, OUTDIR, the plotting: every check before the first run. */
static tt_status prepare(study_job *j)
{
  app_run *r = j->r;
  const tt_app_settings *s = j->s;
  while (s->terrains[j->nterr])
    j->nterr++;
  if (!make_plan(r, &j->plan))
    return r->res->status;
  j->exists = tt__app_study_check_outdir(r, s->output);
  if (j->exists < 0 ||
      (s->plot && !tt__app_study_plot_check(r, &j->python, &j->script)))
    return r->res->status;
  const study_plan *p = &j->plan;
  size_t per_terrain = p->nmeth * p->nopt * p->npct * p->ncrit;
  size_t per_run = j->nterr * p->nmeth * p->nopt * p->ncrit;
  j->ts = calloc(j->nterr, sizeof *j->ts);
  j->rows = calloc(per_terrain ? j->nterr * per_terrain : 1, sizeof *j->rows);
  if (!j->ts || !j->rows)
    return tt__app_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_NOMEM, NULL,
                        "out of memory");
  /* the -percent runs, then one -points run and one -tin_points run per
   * terrain, method, optimiser and criterion */
  j->total = j->nterr * per_terrain + (p->points ? per_run : 0) +
             (s->tin_points ? per_run : 0);
  return TT_OK;
}

/* Every terrain first (0 - 5%): a bad one costs no run. */
static tt_status load_terrains(study_job *j)
{
  app_run *r = j->r;
  for (size_t t = 0; t < j->nterr; t++) {
    j->ts[t].arg = j->s->terrains[t];
    if (!tt__app_continue(r, 0.05 * (double)t / (double)j->nterr))
      return tt__app_fail_tt(r, TT_ERR_INTERRUPTED, j->s->output);
    if (!load_terrain(r, &j->ts[t]))
      return r->res->status;
  }
  return TT_OK;
}

/* The runs take 5 - 99%, an equal share each: the share of the run after
 * `done` runs, unless a stop was asked. */
static tt_status next_run(study_job *j, size_t done)
{
  app_run *r = j->r;
  double lo = 0.05 + 0.94 * (double)done / (double)j->total;
  tt__app_phase_set(&r->prog, lo, lo + 0.94 / (double)j->total);
  if (!tt__app_continue(r, lo))
    return tt__app_fail_tt(r, TT_ERR_INTERRUPTED, j->s->output);
  return TT_OK;
}

/* The -percent runs, in the order the tables read them. */
static tt_status run_checkpoints(study_job *j)
{
  const study_plan *p = &j->plan;
  tt_status st = TT_OK;
  for (size_t t = 0; t < j->nterr; t++)
    for (size_t m = 0; m < p->nmeth; m++)
      for (size_t o = 0; o < p->nopt; o++)
        for (size_t k = 0; k < p->npct; k++)
          for (size_t c = 0; c < p->ncrit; c++) {
            study_row *w = &j->rows[j->nrows];
            w->terrain = t;
            w->method = m;
            w->optimizer = o;
            w->percent = k;
            w->criterion = c;
            if ((st = next_run(j, j->nrows)) != TT_OK ||
                (st = run_one(j->r, &j->ts[t], p, w, 0, NULL)) != TT_OK)
              return st;
            j->nrows++;
          }
  return st;
}

/* The -points runs (study_curves.c), one per terrain, method, optimiser
 * and criterion. */
static tt_status run_curves(study_job *j)
{
  const study_plan *p = &j->plan;
  tt_status st = TT_OK;
  for (size_t t = 0; t < j->nterr && p->points; t++)
    for (size_t m = 0; m < p->nmeth; m++)
      for (size_t o = 0; o < p->nopt; o++)
        for (size_t c = 0; c < p->ncrit; c++) {
          study_row key = {t, m, c, o, SIZE_MAX, 0, {0}, 0};
          if ((st = next_run(j, j->nrows + j->nruns)) != TT_OK ||
              (st = tt__study_curve_run(j->r, &j->ts[t], p, &key,
                                        &j->steps)) != TT_OK)
            return st;
          j->nruns++;
        }
  return st;
}

/* The -tin_points runs, as many (the percentages aside), each TIN handed
 * to study_files.c. */
static tt_status run_tins(study_job *j)
{
  app_run *r = j->r;
  const study_plan *p = &j->plan;
  tt_status st = tt__app_study_tins_begin(r, j->s->output, &j->tins);
  for (size_t t = 0; st == TT_OK && t < j->nterr; t++)
    for (size_t m = 0; st == TT_OK && m < p->nmeth; m++)
      for (size_t o = 0; st == TT_OK && o < p->nopt; o++)
        for (size_t c = 0; st == TT_OK && c < p->ncrit; c++, j->ntin++) {
          study_row w = {t, m, c, o, 0, 0, {0}, 0};
          tt_tin *tin = NULL;
          if ((st = next_run(j, j->nrows + j->nruns + j->ntin)) != TT_OK)
            break;
          st = run_one(r, &j->ts[t], p, &w, j->s->tin_points, &tin);
          if (st == TT_OK)
            st = tt__app_study_tins_add(
                r, j->tins, t, j->ts[t].label, j->ts[t].grid,
                p->decimate[m] ? "decimate" : "insert",
                tt_criterion_name(p->crit[c]),
                tt__study_optimizer_used(p, &w), tin);
          tt_tin_destroy(tin);
        }
  return st;
}

/* The files, then the TINs, then the pictures, then the summary. */
static tt_status finish(study_job *j)
{
  app_run *r = j->r;
  const tt_app_settings *s = j->s;
  tt_status st = tt__app_study_write(r, j->exists, j->ts, j->nterr, &j->plan,
                                     j->rows, j->nrows, &j->steps, j->nruns);
  if (st == TT_OK && j->tins)
    st = tt__app_study_tins_commit(r, j->tins);
  if (st == TT_OK && j->python)
    st = tt__app_study_plot_run(r, j->python, j->script, s->output);
  if (st != TT_OK)
    return st;
  /* Draws 100%; a stop asked now is too late: the files are committed. */
  (void)tt__app_continue(r, 1.0);
  if (!s->quiet) {
    fprintf(r->out, "%s: %zu runs over %zu terrain%s (curves.csv, tables.md, "
            "runs.json%s%s); %.2f s\n", s->output, j->nruns + j->ntin,
            j->nterr, j->nterr == 1 ? "" : "s", j->tins ? ", tins/" : "",
            j->python ? ", plots/" : "", tt__app_now() - r->t0);
    if (j->python)
      fprintf(r->out, "plots drawn by %s %s\n", j->python, j->script);
    fflush(r->out);
  }
  return TT_OK;
}

tt_status tt__app_study(app_run *r)
{
  study_job j;
  memset(&j, 0, sizeof j);
  j.r = r;
  j.s = r->s;
  tt_status st = prepare(&j);
  if (st == TT_OK)
    st = load_terrains(&j);
  if (st == TT_OK)
    st = run_checkpoints(&j);
  if (st == TT_OK)
    st = run_curves(&j);
  if (st == TT_OK && j.s->tin_points)
    st = run_tins(&j);
  if (st == TT_OK) {
    j.nruns += j.nrows;
    st = finish(&j);
  }

  for (size_t t = 0; j.ts && t < j.nterr; t++) {
    tt_grid_destroy(j.ts[t].grid);
    CPLFree(j.ts[t].path);
  }
  tt__app_study_tins_free(j.tins);
  CPLFree(j.python);
  CPLFree(j.script);
  free(j.ts);
  free(j.rows);
  free(j.steps.w);
  return st;
}
