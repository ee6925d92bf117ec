/*
 * study_files.c -- the folder `terratin study` writes: OUTDIR checked
 * before the first run (a folder, empty unless -overwrite), and with
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
