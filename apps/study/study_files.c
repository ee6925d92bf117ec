/*
 * study_files.c -- apps/study/: the study command, a folder over the core
 * (apps/core/). This file: the folder `terratin study` writes: OUTDIR
 * checked before the first run (a folder, empty unless -overwrite), its
 * three files once every run is made (curves.csv, a row per run or step;
 * tables.md, the study's tables; runs.json, every parameter), and with
 * -tin_points N the TINs the pictures of plot_study.py draw (the study's
 * Figures 10-11). For every terrain, method, criterion and optimiser the
 * study makes one more run stopped at N points and hands the TIN here;
 * this file writes, into OUTDIR/tins/:
 *   - t<k>_<label>_<method>_<criterion>_<optimizer>.obj: the TIN in pixel
 *     space (x = column, y = row, z = the height; faces 1-based);
 *   - t<k>_<label>.asc: terrain k's grid as an ESRI ASCII grid, pixel
 *     space too (cells of 1, nodata a value below every height), for the
 *     hillshade;
 *   - index.csv: terrain, method, criterion, optimizer, points, tin, grid.
 * k numbers the terrains from 1 so that two DEMs of the same file name
 * stay apart. Everything goes into a temporary folder beside OUTDIR which
 * becomes OUTDIR/tins on commit (an old OUTDIR/tins, from a run with
 * -overwrite, is moved aside and removed after); abort removes it.
 */
#include "study.h"

#include <cpl_conv.h>
#include <cpl_string.h>

#include <dirent.h>
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

/* OUTDIR: refused when it is not a folder, or not empty without
 * -overwrite. */
int tt__app_study_check_outdir(app_run *r, const char *dir)
{
  struct stat sb;
  if (stat(dir, &sb) != 0) {
    if (errno == ENOENT)
      return 0;
    tt__app_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_IO, dir, "%s",
                 strerror(errno));
    return -1;
  }
  if (!S_ISDIR(sb.st_mode)) {
    tt__app_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_EXISTS, dir,
                 "exists and is not a directory");
    return -1;
  }
  DIR *d = opendir(dir);
  if (!d) {
    tt__app_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_IO, dir, "%s",
                 strerror(errno));
    return -1;
  }
  int empty = 1;
  struct dirent *e;
  while (empty && (e = readdir(d)))
    if (strcmp(e->d_name, ".") && strcmp(e->d_name, ".."))
      empty = 0;
  closedir(d);
  if (!empty && !r->s->overwrite) {
    tt__app_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_EXISTS, dir,
                 "is not empty; use -overwrite to write into it");
    return -1;
  }
  return 1;
}

struct app_study_tins {
  char *tmp;   /* the temporary folder */
  char *final; /* OUTDIR/tins */
  FILE *index;
  size_t grid_written; /* terrains whose grid is written: 1 + index */
};

/* Removes the regular files of dir, then dir (no recursion: the folder
 * holds files only). */
static void remove_folder(const char *dir)
{
  DIR *d = opendir(dir);
  if (d) {
    struct dirent *e;
    while ((e = readdir(d)))
      if (strcmp(e->d_name, ".") && strcmp(e->d_name, ".."))
        unlink(CPLSPrintf("%s/%s", dir, e->d_name));
    closedir(d);
  }
  rmdir(dir);
}

/* A file-name-safe copy of s into buf. */
static void safe_name(char *buf, size_t size, const char *s)
{
  size_t n = 0;
  for (; *s && n + 1 < size; s++)
    buf[n++] = ((*s >= 'a' && *s <= 'z') || (*s >= 'A' && *s <= 'Z') ||
                (*s >= '0' && *s <= '9') || *s == '.' || *s == '-')
                   ? *s
                   : '_';
  buf[n] = '\0';
}

tt_status tt__app_study_tins_begin(app_run *r, const char *outdir,
                                   app_study_tins **out)
{
  app_study_tins *w = calloc(1, sizeof *w);
  *out = NULL;
  if (!w)
    return tt__app_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_NOMEM, NULL,
                        "out of memory");
  /* The parent of OUTDIR, so that the commit is a rename. */
  char *base = CPLStrdup(outdir);
  size_t n = strlen(base);
  while (n > 1 && base[n - 1] == '/')
    base[--n] = '\0';
  char *slash = strrchr(base, '/');
  const char *parent = ".";
  if (slash == base)
    parent = "/";
  else if (slash) {
    *slash = '\0';
    parent = base;
  }
  w->tmp = CPLStrdup(CPLSPrintf("%s/.tt_tins.XXXXXX", parent));
  w->final = CPLStrdup(CPLSPrintf("%s/tins", outdir));
  CPLFree(base);
  if (!mkdtemp(w->tmp)) {
    tt_status st = tt__app_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_IO, w->tmp,
                                "cannot create the folder: %s",
                                strerror(errno));
    CPLFree(w->tmp);
    w->tmp = NULL;
    tt__app_study_tins_free(w);
    return st;
  }
  const char *ix = CPLSPrintf("%s/index.csv", w->tmp);
  if (!(w->index = fopen(ix, "w"))) {
    tt_status st = tt__app_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_IO, ix, "%s",
                                strerror(errno));
    tt__app_study_tins_free(w);
    return st;
  }
  fputs("terrain,method,criterion,optimizer,points,tin,grid\n", w->index);
  *out = w;
  return TT_OK;
}

static tt_status close_file(app_run *r, FILE *fp, const char *path)
{
  int bad = ferror(fp);
  if (fclose(fp) != 0 || bad)
    return tt__app_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_IO, path,
                        "write failed: %s", strerror(errno));
  return TT_OK;
}

static tt_status write_grid(app_run *r, const char *path, const tt_grid *g)
{
  size_t nx = tt_grid_width(g), ny = tt_grid_height(g);
  double lo = INFINITY;
  char b[40];
  for (size_t j = 0; j < ny; j++)
    for (size_t i = 0; i < nx; i++) {
      double z = tt_grid_sample(g, i, j);
      if (z < lo)
        lo = z;
    }
  /* Below every height by at least 1, and an integer (exact in text). */
  double nodata = isfinite(lo) ? floor(lo) - 1.0 : -1.0;
  FILE *fp = fopen(path, "w");
  if (!fp)
    return tt__app_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_IO, path, "%s",
                        strerror(errno));
  fprintf(fp, "ncols %zu\nnrows %zu\nxllcorner -0.5\nyllcorner -0.5\n"
          "cellsize 1\nNODATA_value %.17g\n", nx, ny, nodata);
  for (size_t j = 0; j < ny; j++)
    for (size_t i = 0; i < nx; i++) {
      double z = tt_grid_sample(g, i, j);
      tt__app_format_double(b, sizeof b, isnan(z) ? nodata : z);
      fputs(b, fp);
      fputc(i + 1 == nx ? '\n' : ' ', fp);
    }
  return close_file(r, fp, path);
}

tt_status tt__app_study_tins_add(app_run *r, app_study_tins *w,
                                 size_t terrain, const char *label,
                                 const tt_grid *grid, const char *method,
                                 const char *criterion, const char *optimizer,
                                 const tt_tin *tin)
{
  char sl[96], grid_name[128], tin_name[256], b[40];
  tt_status st;
  safe_name(sl, sizeof sl, label);
  snprintf(grid_name, sizeof grid_name, "t%zu_%s.asc", terrain + 1, sl);
  snprintf(tin_name, sizeof tin_name, "t%zu_%s_%s_%s_%s.obj", terrain + 1,
           sl, method, criterion, optimizer);
  if (w->grid_written < terrain + 1) {
    st = write_grid(r, CPLSPrintf("%s/%s", w->tmp, grid_name), grid);
    if (st != TT_OK)
      return st;
    w->grid_written = terrain + 1;
  }
  const char *path = CPLSPrintf("%s/%s", w->tmp, tin_name);
  char *keep = CPLStrdup(path);
  FILE *fp = fopen(keep, "w");
  if (!fp) {
    st = tt__app_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_IO, keep, "%s",
                      strerror(errno));
    CPLFree(keep);
    return st;
  }
  size_t nv = tt_tin_vertex_count(tin), nt = tt_tin_triangle_count(tin);
  fprintf(fp, "# terratin study: %s, %s, %s, optimizer %s: %zu vertices, "
          "%zu triangles\n# pixel space: x = column, y = row, z = height\n",
          label, method, criterion, optimizer, nv, nt);
  for (size_t i = 0; i < nv; i++) {
    tt_vertex_info v;
    tt_tin_vertex(tin, i, &v);
    tt__app_format_double(b, sizeof b, v.z);
    fprintf(fp, "v %d %d %s\n", (int)v.col, (int)v.row, b);
  }
  for (size_t i = 0; i < nt; i++) {
    tt_triangle_info t;
    tt_tin_triangle(tin, i, &t);
    fprintf(fp, "f %d %d %d\n", (int)t.v[0] + 1, (int)t.v[1] + 1,
            (int)t.v[2] + 1);
  }
  st = close_file(r, fp, keep);
  CPLFree(keep);
  if (st != TT_OK)
    return st;
  /* The label may hold a comma or a quote: CSV-quote it. */
  fputc('"', w->index);
  for (const char *c = label; *c; c++) {
    if (*c == '"')
      fputc('"', w->index);
    fputc(*c, w->index);
  }
  fprintf(w->index, "\",%s,%s,%s,%zu,%s,%s\n", method, criterion, optimizer,
          nv, tin_name, grid_name);
  return TT_OK;
}

tt_status tt__app_study_tins_commit(app_run *r, app_study_tins *w)
{
  tt_status st = close_file(r, w->index, CPLSPrintf("%s/index.csv", w->tmp));
  w->index = NULL;
  if (st != TT_OK)
    return st;
  char *old = NULL;
  struct stat sb;
  if (lstat(w->final, &sb) == 0) {
    if (!S_ISDIR(sb.st_mode))
      return tt__app_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_EXISTS, w->final,
                          "exists and is not a folder");
    old = CPLStrdup(CPLSPrintf("%s.old%ld", w->tmp, (long)getpid()));
    if (rename(w->final, old) != 0) {
      st = tt__app_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_IO, w->final, "%s",
                        strerror(errno));
      CPLFree(old);
      return st;
    }
  }
  if (rename(w->tmp, w->final) != 0) {
    st = tt__app_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_IO, w->final, "%s",
                      strerror(errno));
    if (old)
      rename(old, w->final);
    CPLFree(old);
    return st;
  }
  CPLFree(w->tmp);
  w->tmp = NULL;
  if (old)
    remove_folder(old);
  CPLFree(old);
  return TT_OK;
}

void tt__app_study_tins_free(app_study_tins *w)
{
  if (!w)
    return;
  if (w->index)
    fclose(w->index);
  if (w->tmp)
    remove_folder(w->tmp);
  CPLFree(w->tmp);
  CPLFree(w->final);
  free(w);
}

/* --- curves.csv, tables.md, runs.json ---------------------------------- */

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
            tt__study_optimizer_used(p, w), w->points, b[0], b[1],
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
      tt__json_str(&j, "z_to", s->z_to ? s->z_to : "auto");
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

tt_status tt__app_study_write(app_run *r, int exists,
                              const study_terrain *ts, size_t nterr,
                              const study_plan *p, const study_row *rows,
                              size_t nrows, const study_rows *steps,
                              size_t nruns)
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
