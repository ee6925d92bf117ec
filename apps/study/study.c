/*
 * study.c -- `terratin study [options] OUTDIR`: the comparison of the
 * triangulation criteria (issue 15) as one command. For every terrain
 * (-terrain: a DEM file, or one of the study's generated terrains by name
 * with its published parameters), method (-methods insert,decimate),
 * criterion (-criteria), final optimiser (-optimizers) and checkpoint
 * (-percent P,P,...) it runs the engine as `terratin simplify -percent P`
 * would, and records the TIN summary's error measures and the seconds the
 * mesh took. It writes OUTDIR/curves.csv (a row per run), OUTDIR/tables.md
 * (the study's tables: mean absolute error, one table per terrain, method
 * and optimiser, best per row in bold) and OUTDIR/runs.json (every
 * parameter and the version).
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
    GDALClose(ds);
  return st == TT_OK;
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
  if (dec) {
    tt_decimate_options d;
    tt_decimate_options_init(&d);
    d.max_error = -1.0;
    d.percent = max_points ? 0 : p->pct[row->percent];
    d.max_points = max_points;
    d.criterion = p->crit[row->criterion];
    d.optimize = p->opt[row->optimizer];
    d.anneal = s->anneal;
    d.start = s->start;
    d.start_points = s->start_points;
    d.importance = s->importance;
    d.threads = tt__app_threads(r);
    d.progress = tt__app_phase_fn;
    d.progress_arg = &r->prog;
    st = tt_decimate_run(r->ctx, t->grid, &d, &tin);
  } else {
    tt_refine_options o;
    tt_refine_options_init(&o);
    o.max_error = -1.0;
    o.percent = max_points ? 0 : p->pct[row->percent];
    o.max_points = max_points;
    o.criterion = p->crit[row->criterion];
    o.repair = tt__study_repair(o.criterion);
    o.optimize = p->opt[row->optimizer];
    o.anneal = s->anneal;
    o.threads = tt__app_threads(r);
    o.progress = tt__app_phase_fn;
    o.progress_arg = &r->prog;
    st = tt_refine_run(r->ctx, t->grid, &o, &tin);
  }
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

/* A CSV field: quoted when it holds a comma, a quote or a line break. */
static void csv_field(FILE *fp, const char *v)
{
  if (!strpbrk(v, ",\"\r\n")) {
    fputs(v, fp);
    return;
  }
  fputc('"', fp);
  for (; *v; v++) {
    if (*v == '"')
      fputc('"', fp);
    fputc(*v, fp);
  }
  fputc('"', fp);
}

/* The final pass a run made: auto resolved as the engine resolves it
 * (with the study's repair for insertion, study_curves.c). */
static const char *optimizer_used(const study_plan *p, const study_row *w)
{
  tt_criterion c = p->crit[w->criterion];
  tt_repair rep = p->decimate[w->method] ? TT_REPAIR_AUTO
                                         : tt__study_repair(c);
  return tt_optimize_name(tt_optimize_resolve(
      p->opt[w->optimizer], c, tt_repair_resolve(rep, c)));
}

/* Whether a -points row repeats a -percent row (the same run at the same
 * count: the -percent run, a TIN of its own, is kept). */
static int repeats(const study_row *w, const study_row *rows, size_t nrows)
{
  for (size_t i = 0; i < nrows; i++)
    if (rows[i].points == w->points && rows[i].terrain == w->terrain &&
        rows[i].method == w->method && rows[i].optimizer == w->optimizer &&
        rows[i].criterion == w->criterion)
      return 1;
  return 0;
}

/* The -percent rows, then the -points rows (in run order, each run's
 * steps in the order the run took them). */
static size_t write_curves(FILE *fp, const study_terrain *ts,
                           const study_plan *p, const study_row *rows,
                           size_t nrows, const study_rows *steps)
{
  char b[6][40];
  size_t written = 0;
  fputs("terrain,method,criterion,optimizer,points,max_error,l2,rmse,"
        "mean_abs_error,total_abs_error,seconds\n", fp);
  for (size_t i = 0; i < nrows + steps->n; i++) {
    const study_row *w = i < nrows ? &rows[i] : &steps->w[i - nrows];
    if (i >= nrows && repeats(w, rows, nrows))
      continue;
    csv_field(fp, ts[w->terrain].label);
    tt__app_format_double(b[0], sizeof b[0], w->e.max_error);
    tt__app_format_double(b[1], sizeof b[1], w->e.l2);
    tt__app_format_double(b[2], sizeof b[2], w->e.rmse);
    tt__app_format_double(b[3], sizeof b[3], w->e.mean_abs);
    tt__app_format_double(b[4], sizeof b[4], w->e.total_abs);
    tt__app_format_double(b[5], sizeof b[5], w->seconds);
    fprintf(fp, ",%s,%s,%s,%zu,%s,%s,%s,%s,%s,%s\n",
            p->decimate[w->method] ? "decimate" : "insert",
            tt_criterion_name(p->crit[w->criterion]),
            optimizer_used(p, w), w->points, b[0], b[1],
            b[2], b[3], b[4], b[5]);
    written++;
  }
  return written;
}

/* The study's tables: rows are laid out terrain, method, optimiser,
 * percent, criterion (the loop order of the runs), so a table is a block
 * of npct x ncrit consecutive rows. */
static void write_tables(FILE *fp, const study_terrain *ts, size_t nterr,
                         const study_plan *p, const study_row *rows)
{
  size_t block = p->npct * p->ncrit, at = 0;
  fputs("# terratin study: mean absolute error\n\n"
        "Mean absolute error (z units) of the TIN at each percentage of "
        "the valid samples; the best criterion of each row in bold.\n",
        fp);
  if (!p->npct) {
    fputs("\nNo -percent checkpoints were asked for: the curves are in "
          "curves.csv.\n", fp);
    return;
  }
  for (size_t t = 0; t < nterr; t++)
    for (size_t m = 0; m < p->nmeth; m++)
      for (size_t o = 0; o < p->nopt; o++, at += block) {
        const study_row *b = rows + at;
        fprintf(fp, "\n## %s, %s, optimizer %s\n\n| %% | points |",
                ts[t].label, p->decimate[m] ? "decimate" : "insert",
                tt_optimize_name(p->opt[o]));
        for (size_t c = 0; c < p->ncrit; c++)
          fprintf(fp, " %s |", tt_criterion_name(p->crit[c]));
        fputs("\n|---|---|", fp);
        for (size_t c = 0; c < p->ncrit; c++)
          fputs("---|", fp);
        fputc('\n', fp);
        for (size_t k = 0; k < p->npct; k++) {
          const study_row *line = b + k * p->ncrit;
          double best = line[0].e.mean_abs;
          for (size_t c = 1; c < p->ncrit; c++)
            if (line[c].e.mean_abs < best)
              best = line[c].e.mean_abs;
          fprintf(fp, "| %s | %zu |", p->pct_text[k], line[0].points);
          for (size_t c = 0; c < p->ncrit; c++) {
            const char *bold = line[c].e.mean_abs == best ? "**" : "";
            fprintf(fp, " %s%.6g%s |", bold, line[c].e.mean_abs, bold);
          }
          fputc('\n', fp);
        }
      }
}

static const char *seeding_name(tt_synth_seeding s)
{
  switch (s) {
  case TT_SEED_PEAK: return "peak";
  case TT_SEED_VALLEY: return "valley";
  case TT_SEED_HYBRID: return "hybrid";
  default: return "none";
  }
}

static void write_runs(app_run *r, FILE *fp, const study_terrain *ts,
                       size_t nterr, size_t nrows, size_t nruns)
{
  const tt_app_settings *s = r->s;
  app_json j;
  char created[32], key[24];
  tt__app_iso8601_utc(created, sizeof created);
  tt__json_begin(&j, fp);
  tt__json_str(&j, "command", "study");
  tt__json_str(&j, "version", tt_version());
  tt__json_str(&j, "created", created);
  tt__json_str(&j, "outdir", s->output);
  tt__json_open(&j, "terrains");
  for (size_t t = 0; t < nterr; t++) {
    const study_terrain *x = &ts[t];
    snprintf(key, sizeof key, "%zu", t + 1);
    tt__json_open(&j, key);
    tt__json_str(&j, "terrain", x->arg);
    tt__json_str(&j, "label", x->label);
    tt__json_size(&j, "width", tt_grid_width(x->grid));
    tt__json_size(&j, "height", tt_grid_height(x->grid));
    tt__json_size(&j, "valid_samples", x->valid);
    if (x->named) {
      const tt_synth_options *o = &x->synth;
      tt__json_str(&j, "generator", tt_synth_kind_name(o->kind));
      tt__json_i64(&j, "seed", (int64_t)o->seed);
      if (o->kind == TT_SYNTH_FAULT) {
        tt__json_size(&j, "iterations", o->iterations);
        tt__json_num(&j, "displacement", o->displacement);
        tt__json_num(&j, "wave_size", o->wave_size);
      } else if (o->kind == TT_SYNTH_DIAMOND_SQUARE) {
        tt__json_num(&j, "roughness", o->roughness);
        tt__json_num(&j, "amplitude", o->amplitude);
        tt__json_str(&j, "seeding", seeding_name(o->seeding));
      }
    } else {
      tt__json_null(&j, "generator");
      if (x->path)
        tt__json_str(&j, "path", x->path);
      tt__json_i64(&j, "band", s->band);
      tt__json_str(&j, "srcnodata", s->srcnodata);
      tt__json_num(&j, "z_factor", s->z_factor);
      tt__json_str(&j, "z_unit", s->z_unit);
    }
    tt__json_close(&j);
  }
  tt__json_close(&j);
  tt__json_str(&j, "criteria", s->criteria ? s->criteria : "all");
  tt__json_str(&j, "methods", s->methods ? s->methods : "insert");
  tt__json_str(&j, "optimizers", s->optimizers ? s->optimizers : "auto");
  tt__json_str(&j, "percent", s->percents   ? s->percents
                              : s->points ? ""
                                          : "1,10,25,50");
  if (s->points)
    tt__json_size(&j, "points", s->points);
  else
    tt__json_null(&j, "points");
  if (s->seed_set)
    tt__json_i64(&j, "seed", (int64_t)s->seed);
  else
    tt__json_null(&j, "seed");
  tt__json_open(&j, "decimation");
  if (s->start == TT_DSTART_GREEDY_N) {
    snprintf(key, sizeof key, "greedy:%zu", s->start_points);
    tt__json_str(&j, "start", key);
  } else {
    tt__json_str(&j, "start", tt_decimate_start_name(s->start));
  }
  tt__json_str(&j, "importance", tt_importance_name(s->importance));
  tt__json_close(&j);
  tt__json_open(&j, "anneal");
  tt__json_num(&j, "t0", s->anneal.t0);
  tt__json_i64(&j, "stages", s->anneal.stages);
  tt__json_num(&j, "swaps", s->anneal.swaps);
  tt__json_num(&j, "good", s->anneal.good);
  tt__json_num(&j, "r", s->anneal.r);
  tt__json_i64(&j, "seed", (int64_t)s->anneal.seed);
  tt__json_close(&j);
  tt__json_size(&j, "tin_points", s->tin_points);
  tt__json_bool(&j, "plot", s->plot);
  tt__json_size(&j, "runs", nruns);
  tt__json_size(&j, "rows", nrows);
  tt__json_str(&j, "seconds", "mesh: tt_tin_summary.seconds_mesh");
  tt__json_close(&j);
}

enum { F_CURVES, F_TABLES, F_RUNS, F_COUNT };
static const char *const out_names[F_COUNT] = {"curves.csv", "tables.md",
                                               "runs.json"};

/* Writes the three files under temporary names, then renames them. */
static tt_status write_outputs(app_run *r, int exists, const study_terrain *ts,
                               size_t nterr, const study_plan *p,
                               const study_row *rows, size_t nrows,
                               const study_rows *steps, size_t nruns)
{
  const char *dir = r->s->output;
  tt_status st = TT_OK;
  char *tmp[F_COUNT] = {NULL, NULL, NULL}, *fin[F_COUNT] = {NULL, NULL, NULL};
  int created = 0, renamed = 0;
  size_t written = 0;
  if (!exists) {
    if (mkdir(dir, 0777) != 0) {
      st = tt__app_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_IO, dir,
                        "cannot create the directory: %s", strerror(errno));
      goto done;
    }
    created = 1;
  }
  for (int f = 0; f < F_COUNT; f++) {
    tmp[f] = CPLStrdup(CPLSPrintf("%s/.%s.tmp%ld", dir, out_names[f],
                                  (long)getpid()));
    fin[f] = CPLStrdup(CPLSPrintf("%s/%s", dir, out_names[f]));
    FILE *fp = fopen(tmp[f], "w");
    if (!fp) {
      st = tt__app_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_IO, tmp[f], "%s",
                        strerror(errno));
      goto done;
    }
    if (f == F_CURVES)
      written = write_curves(fp, ts, p, rows, nrows, steps);
    else if (f == F_TABLES)
      write_tables(fp, ts, nterr, p, rows);
    else
      write_runs(r, fp, ts, nterr, written, nruns);
    int bad = ferror(fp);
    if (fclose(fp) != 0 || bad) {
      st = tt__app_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_IO, tmp[f],
                        "write failed: %s", strerror(errno));
      goto done;
    }
  }
  for (; renamed < F_COUNT; renamed++)
    if (rename(tmp[renamed], fin[renamed]) != 0) {
      st = tt__app_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_IO, fin[renamed],
                        "%s", strerror(errno));
      goto done;
    }
done:
  for (int f = 0; f < F_COUNT; f++) {
    if (st != TT_OK && tmp[f]) {
      unlink(tmp[f]);
      if (f < renamed)
        unlink(fin[f]);
    }
    CPLFree(tmp[f]);
    CPLFree(fin[f]);
  }
  if (st != TT_OK && created)
    rmdir(dir);
  return st;
}

tt_status tt__app_study(app_run *r)
{
  const tt_app_settings *s = r->s;
  tt_status st = TT_OK;
  study_plan plan;
  study_terrain *ts = NULL;
  study_row *rows = NULL;
  study_rows steps = {NULL, 0, 0};
  size_t nterr = 0, nrows = 0, nruns = 0;
  char *python = NULL, *script = NULL;
  app_study_tins *tins = NULL;
  while (s->terrains[nterr])
    nterr++;

  if (!make_plan(r, &plan)) {
    st = r->res->status;
    goto done;
  }
  int exists = tt__app_study_check_outdir(r, s->output);
  if (exists < 0 || (s->plot && !tt__app_study_plot_check(r, &python,
                                                           &script))) {
    st = r->res->status;
    goto done;
  }
  size_t per_terrain = plan.nmeth * plan.nopt * plan.npct * plan.ncrit;
  ts = calloc(nterr, sizeof *ts);
  rows = calloc(per_terrain ? nterr * per_terrain : 1, sizeof *rows);
  if (!ts || !rows) {
    st = tt__app_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_NOMEM, NULL,
                      "out of memory");
    goto done;
  }

  /* Every terrain first (0 - 5%): a bad one costs no run. */
  for (size_t t = 0; t < nterr; t++) {
    ts[t].arg = s->terrains[t];
    if (!tt__app_continue(r, 0.05 * (double)t / (double)nterr)) {
      st = tt__app_fail_tt(r, TT_ERR_INTERRUPTED, s->output);
      goto done;
    }
    if (!load_terrain(r, &ts[t])) {
      st = r->res->status;
      goto done;
    }
  }

  /* The runs (5 - 99%), in the order the tables read them; then the
   * -points runs (study_curves.c), one per terrain, method, optimiser and
   * criterion; then the runs of -tin_points, as many (the percentages
   * aside). */
  size_t ncurves = plan.points ? nterr * plan.nmeth * plan.nopt * plan.ncrit
                               : 0;
  size_t total = nterr * per_terrain + ncurves, ntin = 0;
  if (s->tin_points)
    total += nterr * plan.nmeth * plan.nopt * plan.ncrit;
  for (size_t t = 0; t < nterr; t++)
    for (size_t m = 0; m < plan.nmeth; m++)
      for (size_t o = 0; o < plan.nopt; o++)
        for (size_t k = 0; k < plan.npct; k++)
          for (size_t c = 0; c < plan.ncrit; c++) {
            study_row *w = &rows[nrows];
            double lo = 0.05 + 0.94 * (double)nrows / (double)total;
            w->terrain = t;
            w->method = m;
            w->optimizer = o;
            w->percent = k;
            w->criterion = c;
            tt__app_phase_set(&r->prog, lo, lo + 0.94 / (double)total);
            if (!tt__app_continue(r, lo)) {
              st = tt__app_fail_tt(r, TT_ERR_INTERRUPTED, s->output);
              goto done;
            }
            st = run_one(r, &ts[t], &plan, w, 0, NULL);
            if (st != TT_OK)
              goto done;
            nrows++;
          }
  for (size_t t = 0; t < nterr && plan.points; t++)
    for (size_t m = 0; m < plan.nmeth; m++)
      for (size_t o = 0; o < plan.nopt; o++)
        for (size_t c = 0; c < plan.ncrit; c++) {
          study_row key = {t, m, c, o, SIZE_MAX, 0, {0}, 0};
          double lo = 0.05 + 0.94 * (double)(nrows + nruns) / (double)total;
          tt__app_phase_set(&r->prog, lo, lo + 0.94 / (double)total);
          if (!tt__app_continue(r, lo)) {
            st = tt__app_fail_tt(r, TT_ERR_INTERRUPTED, s->output);
            goto done;
          }
          st = tt__study_curve_run(r, &ts[t], &plan, &key, &steps);
          if (st != TT_OK)
            goto done;
          nruns++;
        }
  if (s->tin_points &&
      (st = tt__app_study_tins_begin(r, s->output, &tins)) != TT_OK)
    goto done;
  for (size_t t = 0; s->tin_points && t < nterr; t++)
    for (size_t m = 0; m < plan.nmeth; m++)
      for (size_t o = 0; o < plan.nopt; o++)
        for (size_t c = 0; c < plan.ncrit; c++, ntin++) {
          study_row w = {t, m, c, o, 0, 0, {0}, 0};
          tt_tin *tin = NULL;
          double lo =
              0.05 + 0.94 * (double)(nrows + nruns + ntin) / (double)total;
          tt__app_phase_set(&r->prog, lo, lo + 0.94 / (double)total);
          if (!tt__app_continue(r, lo)) {
            st = tt__app_fail_tt(r, TT_ERR_INTERRUPTED, s->output);
            goto done;
          }
          st = run_one(r, &ts[t], &plan, &w, s->tin_points, &tin);
          if (st == TT_OK)
            st = tt__app_study_tins_add(
                r, tins, t, ts[t].label, ts[t].grid,
                plan.decimate[m] ? "decimate" : "insert",
                tt_criterion_name(plan.crit[c]), optimizer_used(&plan, &w),
                tin);
          tt_tin_destroy(tin);
          if (st != TT_OK)
            goto done;
        }
  nruns += nrows;

  st = write_outputs(r, exists, ts, nterr, &plan, rows, nrows, &steps,
                     nruns);
  if (st != TT_OK)
    goto done;
  /* The TINs, then the pictures, once the tables are committed. */
  if (tins && (st = tt__app_study_tins_commit(r, tins)) != TT_OK)
    goto done;
  if (python &&
      (st = tt__app_study_plot_run(r, python, script, s->output)) != TT_OK)
    goto done;
  /* Draws 100%; a stop asked now is too late: the files are committed. */
  (void)tt__app_continue(r, 1.0);
  if (!s->quiet) {
    fprintf(r->out, "%s: %zu runs over %zu terrain%s (curves.csv, tables.md, "
            "runs.json%s%s); %.2f s\n", s->output, nruns + ntin, nterr,
            nterr == 1 ? "" : "s", tins ? ", tins/" : "",
            python ? ", plots/" : "", tt__app_now() - r->t0);
    if (python)
      fprintf(r->out, "plots drawn by %s %s\n", python, script);
    fflush(r->out);
  }
done:
  for (size_t t = 0; ts && t < nterr; t++) {
    tt_grid_destroy(ts[t].grid);
    CPLFree(ts[t].path);
  }
  tt__app_study_tins_free(tins);
  CPLFree(python);
  CPLFree(script);
  free(ts);
  free(rows);
  free(steps.w);
  return st;
}
