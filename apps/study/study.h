/*
 * study.h -- apps/study/: the study command, a folder over the core
 * (apps/core/). This header: what the files of `terratin study` share
 * (internal): study.c (the plan, the terrains, the runs), study_curves.c
 * (the -points runs: a row at every step, from the engine's recorder),
 * study_crater.c (Crater Lake found), study_plot.c (the plots) and
 * study_files.c (OUTDIR, its curves.csv, tables.md and runs.json, and the
 * TINs of -tin_points).
 */
#ifndef TT_APP_STUDY_H
#define TT_APP_STUDY_H

#include "app.h"

/* study_crater.c: whether a -terrain names Crater Lake ("crater", found in
 * the shared test data, or "crater=PATH"): 1 with *out_path (CPLFree) the
 * DEM to read, 0 when it is another terrain, -1 with the failure recorded
 * when Crater Lake is not found. */
int tt__app_study_crater(app_run *r, const char *arg, char **out_path);
/* study_plot.c: finds the python (with matplotlib) and plot_study.py for
 * -plot: 1 with both (CPLFree), 0 with the failure recorded, saying how
 * to get matplotlib. Then runs the script on OUTDIR. */
int tt__app_study_plot_check(app_run *r, char **out_python,
                             char **out_script);
tt_status tt__app_study_plot_run(app_run *r, const char *python,
                                 const char *script, const char *outdir);
/* study_files.c: whether the study's OUTDIR exists (1), not (0), or is in
 * the way (not a folder, not empty without -overwrite) or not readable
 * (-1, failure recorded). */
int tt__app_study_check_outdir(app_run *r, const char *dir);
/* study_files.c: the TINs of -tin_points, written into a temporary folder
 * that commit renames to OUTDIR/tins; free removes it when not committed
 * (and accepts NULL). */
typedef struct app_study_tins app_study_tins;
tt_status tt__app_study_tins_begin(app_run *r, const char *outdir,
                                   app_study_tins **out);
tt_status tt__app_study_tins_add(app_run *r, app_study_tins *w,
                                 size_t terrain, const char *label,
                                 const tt_grid *grid, const char *method,
                                 const char *criterion, const char *optimizer,
                                 const tt_tin *tin);
tt_status tt__app_study_tins_commit(app_run *r, app_study_tins *w);
void tt__app_study_tins_free(app_study_tins *w);

#define STUDY_MAX_LIST 64

struct named_terrain; /* study.c */

/* A terrain of the study, read or generated before the first run. */
typedef struct study_terrain {
  const char *arg;   /* as given to -terrain */
  const char *label; /* the generator's name or the DEM's file name */
  const struct named_terrain *named; /* NULL: a DEM file */
  char *path;                        /* crater: the DEM read (CPLFree) */
  tt_synth_options synth;            /* named terrains */
  tt_grid *grid;
  size_t valid;
} study_terrain;

/* One run's outcome, or one step of a recorded run: a row of curves.csv. */
typedef struct study_row {
  size_t terrain, method, criterion, optimizer, percent; /* plan indices */
  size_t points;
  tt_error_stats e;
  double seconds;
} study_row;

/* What the lists said. */
typedef struct study_plan {
  tt_criterion crit[STUDY_MAX_LIST];
  size_t ncrit;
  int decimate[2]; /* per method: 0 insert, 1 decimate */
  size_t nmeth;
  tt_optimize opt[STUDY_MAX_LIST];
  size_t nopt;
  double pct[STUDY_MAX_LIST];
  char pct_text[STUDY_MAX_LIST][32]; /* the checkpoint as given */
  size_t npct;
  size_t points;   /* -points N: a row at every step up to N; 0: none */
} study_plan;

/* A growing list of rows. */
typedef struct study_rows {
  study_row *w;
  size_t n, cap;
} study_rows;

/* The repair an insertion run of the study uses for criterion c: the
 * criteria that the study optimised after Delaunay insertion (SPEC
 * section 6: every data-dependent one but min_area) are inserted by
 * Delaunay's flips (TT_REPAIR_DELAUNAY, so that the optimiser 'auto' is
 * the local swap); the others as the engine resolves them. */
tt_repair tt__study_repair(tt_criterion c);
/* One run of the study's: a method, criterion and optimiser to a
 * -percent (percent > 0) or a point count, with -start, -importance,
 * -anneal_* and the threads of the command line, and an optional step
 * recorder (step_until: refinement reports steps up to it). study.c's
 * -percent runs and study_curves.c's -points runs both make their TINs
 * here. The caller owns *out_tin (tt_tin_destroy()). */
typedef struct study_method {
  int decimate;
  tt_criterion criterion;
  tt_optimize optimize;
  double percent;
  size_t max_points;
  tt_step_fn step;
  void *step_arg;
  size_t step_until;
} study_method;
tt_status tt__study_method_run(app_run *r, const study_terrain *t,
                               const study_method *m, tt_tin **out_tin);

/* The -points run of one terrain, method, optimiser and criterion (plan
 * indices in `key`: terrain, method, optimizer, criterion): insertion up to
 * p->points vertices with a row at every step, or decimation down to
 * p->points with a row after every round; the rows are appended to out.
 * TT_OK, or the failure recorded. */
tt_status tt__study_curve_run(app_run *r, const study_terrain *t,
                              const study_plan *p, const study_row *key,
                              study_rows *out);

/* The final pass a run made: auto resolved as the engine resolves it
 * (with the study's repair for insertion). study.c. */
const char *tt__study_optimizer_used(const study_plan *p, const study_row *w);

/* study_files.c: OUTDIR's three files (curves.csv: the nrows -percent
 * rows, then the -points steps; tables.md; runs.json, counting nruns
 * runs) under temporary names, then renamed; OUTDIR made first unless it
 * exists. TT_OK, or the failure recorded and nothing left behind. */
tt_status tt__app_study_write(app_run *r, int exists,
                              const study_terrain *ts, size_t nterr,
                              const study_plan *p, const study_row *rows,
                              size_t nrows, const study_rows *steps,
                              size_t nruns);

#endif /* TT_APP_STUDY_H */
