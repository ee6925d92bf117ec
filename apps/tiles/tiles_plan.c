/*
 * tiles_plan.c -- apps/tiles/: the tiles command, a folder over the core
 * (apps/core/), simplify's tiled run as independent jobs for a cluster.
 * This file: `terratin tiles plan DEM PLAN.json [simplify options]`,
 * the dispatch of `terratin tiles ...`, and simplify's run on a plan that
 * `tiles run` and `tiles merge` share (docs/scale.md); the plan's text and
 * its reader are in tiles_plan_file.c.
 *
 * The plan holds the DEM's identity (absolute path, size in bytes,
 * modification time: a changed DEM is refused), its size, the tiles and
 * their windows, and simplify's options as words. It holds no border
 * vertices: a tile computes its borders from its window, which holds the
 * three lines around every shared side, so both neighbours compute the
 * same vertices on any machine (src/tile/, docs/scale.md) -- the plan only
 * has to make sure they read the same DEM with the same options. `tiles
 * run` and `tiles merge` rebuild simplify's command line from the words and
 * run its tiled path (tiled.c) under a hook, so a merge is byte for byte
 * the TIN `simplify -tile_size` makes.
 */
#define _XOPEN_SOURCE 700 /* realpath */
#include "tiles.h"
#include "option_table.h"

#include <cpl_conv.h>
#include <cpl_error.h>
#include <cpl_string.h>
#include <cpl_vsi.h>

#include <errno.h>
#include <limits.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

/* Where a usage error of the tiles commands points (help.c has the pages). */
#define SEE_PLAN_HELP " (see 'terratin tiles plan --help')"

static bool has_control(const char *s)
{
  for (; *s; s++)
    if ((unsigned char)*s < 0x20)
      return true;
  return false;
}

/* One `tiles plan` job: the words, simplify's options checked, the DEM,
 * the plan's files. */
typedef struct plan_job {
  const char *dem, *plan;  /* as given */
  int overwrite, quiet;
  tiles_plan p;            /* what the plan says; p.options: the words */
  char **sv;               /* simplify's command line that checks them */
  tt_app_options *o;       /* and what it said */
  GDALDatasetH ds;
  char *tmp;               /* the plan's temporary name */
  VSILFILE *f;
} plan_job;

/* The words: DEM, PLAN.json, -overwrite, -q, and simplify's options,
 * which must be those a plan may carry. */
static bool read_words(plan_job *j, char **argv, tt_app_result *res)
{
  for (size_t i = 0; argv[i]; i++) {
    const char *w = argv[i];
    if (w[0] == '-' && w[1] && !(w[1] >= '0' && w[1] <= '9')) {
      const tt__app_opt_def *d = tt__app_find_opt(w);
      if (d && d->id == O_OVERWRITE) {
        j->overwrite = 1;
        continue;
      }
      if (d && d->id == O_Q) {
        j->quiet = 1;
        continue;
      }
      j->p.options = CSLAddString(j->p.options, w);
      d = d ? tt__app_opt_for(d, TT_APP_SIMPLIFY) : NULL;
      if (!d) { /* refused by its name, before its words become names */
        char *one[] = {argv[i], NULL};
        tt__tiles_plan_check_words("tiles plan", one, res);
        return false;
      }
      for (int k = tt__app_opt_takes_value(d); k > 0 && argv[i + 1]; k--)
        j->p.options = CSLAddString(j->p.options, argv[++i]);
      continue;
    }
    if (!j->dem)
      j->dem = w;
    else if (!j->plan)
      j->plan = w;
    else {
      tt__app_result_set(res, TT_APP_EXIT_USAGE, TT_ERR_ARG,
                         "tiles plan: unexpected argument '%s'" SEE_PLAN_HELP,
                         w);
      return false;
    }
  }
  if (!j->dem || !j->plan) {
    tt__app_result_set(res, TT_APP_EXIT_USAGE, TT_ERR_ARG,
                       "tiles plan: DEM and PLAN.json are needed"
                       SEE_PLAN_HELP);
    return false;
  }
  return tt__tiles_plan_check_words("tiles plan", j->p.options, res);
}

/* simplify's own parser checks the options; a plan needs a bound. */
static bool check_options(plan_job *j, tt_app_result *res)
{
  j->sv = CSLAddString(NULL, "simplify");
  for (size_t i = 0; j->p.options && j->p.options[i]; i++)
    j->sv = CSLAddString(j->sv, j->p.options[i]);
  j->sv = CSLAddString(j->sv, j->dem);
  j->sv = CSLAddString(j->sv, "tiles-plan-check.gpkg");
  if (tt_app_options_new(j->sv, &j->o, res) != TT_OK)
    return false;
  const tt_app_settings *s = tt_app_options_settings(j->o);
  /* A budget becomes a bound only after a pass over every tile
   * (tiled_budget.c): not a plan's job, whose tiles are independent. */
  if (!s->tile_size || s->max_error < 0 || s->max_points ||
      s->max_triangles || s->percent > 0) {
    tt__app_result_set(res, TT_APP_EXIT_USAGE, TT_ERR_ARG,
                       "tiles plan: -tile_size N and -max_error E are needed "
                       "(each tile is simplified to a bound alone; no "
                       "-max_points, -max_triangles or -percent: their bound "
                       "needs a pass over every tile first, which simplify "
                       "-tile_size makes)");
    return false;
  }
  j->p.tile_size = s->tile_size;
  return true;
}

static bool dem_identity(const char *path, uint64_t *bytes, uint64_t *ns)
{
  struct stat sb;
  if (stat(path, &sb) != 0)
    return false;
  *bytes = (uint64_t)sb.st_size;
  *ns = (uint64_t)sb.st_mtim.tv_sec * UINT64_C(1000000000) +
        (uint64_t)sb.st_mtim.tv_nsec;
  return true;
}

/* The DEM's identity and size, and the tiles of tile_size cells. */
static bool open_dem(plan_job *j, tt_app_result *res)
{
  const tt_app_settings *s = tt_app_options_settings(j->o);
  j->p.dem = realpath(j->dem, NULL);
  if (!j->p.dem || has_control(j->p.dem) ||
      !dem_identity(j->p.dem, &j->p.dem_bytes, &j->p.dem_mtime_ns)) {
    tt__app_result_set(res, TT_APP_EXIT_FAILURE, TT_ERR_IO,
                       "%s: cannot open the DEM (%s)", j->dem,
                       j->p.dem ? "control character in its path"
                                : strerror(errno));
    return false;
  }
  j->ds = GDALOpenEx(j->p.dem, GDAL_OF_RASTER | GDAL_OF_READONLY, NULL,
                     NULL, NULL);
  GDALDatasetH vec = j->ds ? NULL
                           : GDALOpenEx(j->p.dem,
                                        GDAL_OF_VECTOR | GDAL_OF_READONLY,
                                        NULL, NULL, NULL);
  if (vec) { /* the words swapped, or a TIN for the DEM */
    GDALDriverH drv = GDALGetDatasetDriver(vec);
    tt__app_result_set(res, TT_APP_EXIT_FAILURE, TT_ERR_FORMAT,
                       "tiles plan: %s (argument 1) is a vector dataset "
                       "(%s); the DEM (a raster) comes first", j->dem,
                       drv ? GDALGetDriverShortName(drv) : "?");
    GDALClose(vec);
    return false;
  }
  if (!j->ds || s->band > GDALGetRasterCount(j->ds)) {
    tt__app_result_set(res, TT_APP_EXIT_FAILURE, TT_ERR_IO,
                       "%s: %s", j->dem, j->ds ? "no such band (-b)"
                                               : "not a raster GDAL can open");
    return false;
  }
  /* the tiles of the window GDAL's input options read (dem_view.c) */
  GDALDatasetH view = NULL;
  if (tt__app_view_wanted(s)) {
    char why[TT_APP_MESSAGE_MAX], warn[TT_APP_MESSAGE_MAX];
    int usage = 0;
    char **args = tt__app_view_args(s, j->ds, &usage, why, sizeof why, warn,
                                    sizeof warn);
    if (args)
      view = tt__app_view_open(j->ds, args, why, sizeof why);
    CSLDestroy(args);
    if (!view) {
      tt__app_result_set(res, usage ? TT_APP_EXIT_USAGE : TT_APP_EXIT_FAILURE,
                         usage ? TT_ERR_ARG : TT_ERR_DATA, "tiles plan: %s "
                         "(DEM %s)", why, j->dem);
      return false;
    }
    if (warn[0] && !j->quiet)
      fprintf(stderr, "terratin: warning: %s: %s\n", j->dem, warn);
  }
  size_t W = (size_t)GDALGetRasterXSize(view ? view : j->ds);
  size_t H = (size_t)GDALGetRasterYSize(view ? view : j->ds);
  if (view)
    GDALClose(view);
  if (W < 2 || H < 2) {
    tt__app_result_set(res, TT_APP_EXIT_FAILURE, TT_ERR_DATA, "%s: raster is "
                       "%zu x %zu pixels: at least 2 x 2 are needed", j->dem,
                       W, H);
    return false;
  }
  j->p.width = W;
  j->p.height = H;
  tt__tiles_grid(&j->p);
  return true;
}

/* PLAN.json through a temporary name, and the pieces' folder. */
static bool write_plan(plan_job *j, tt_app_result *res)
{
  size_t len = 0;
  char *text = tt__tiles_plan_text(&j->p, &len);
  if (!text) {
    tt__app_result_set(res, TT_APP_EXIT_USAGE, TT_ERR_LIMIT,
                       "tiles plan: %zu tiles of %zu cells make a plan of "
                       "more than %u bytes: use a larger -tile_size",
                       j->p.tiles, j->p.tile_size,
                       (unsigned)TT_TILES_PLAN_MAX_BYTES);
    return false;
  }
  VSIStatBufL sb;
  bool ok = false;
  if (!j->overwrite && VSIStatL(j->plan, &sb) == 0) {
    tt__app_result_set(res, TT_APP_EXIT_FAILURE, TT_ERR_EXISTS,
                       "%s: exists; use -overwrite to replace it", j->plan);
    goto done;
  }
  j->p.pieces = CPLStrdup(CPLSPrintf("%s.tiles", j->plan));
  if (mkdir(j->p.pieces, 0777) != 0 && errno != EEXIST) {
    tt__app_result_set(res, TT_APP_EXIT_FAILURE, TT_ERR_IO,
                       "%s: cannot make the pieces' folder (%s)",
                       j->p.pieces, strerror(errno));
    goto done;
  }
  j->tmp = CPLStrdup(CPLSPrintf("%s.tmp%ld", j->plan, (long)getpid()));
  if (!(j->f = VSIFOpenL(j->tmp, "wb"))) {
    tt__app_result_set(res, TT_APP_EXIT_FAILURE, TT_ERR_IO,
                       "%s: cannot write (%s)", j->plan, strerror(errno));
    goto done;
  }
  int bad = VSIFWriteL(text, 1, len, j->f) != len;
  bad |= VSIFCloseL(j->f) != 0;
  j->f = NULL;
  if (bad || rename(j->tmp, j->plan) != 0) {
    tt__app_result_set(res, TT_APP_EXIT_FAILURE, TT_ERR_IO,
                       "%s: cannot write (%s)", j->plan, strerror(errno));
    goto done;
  }
  ok = true;
done:
  CPLFree(text);
  return ok;
}

static void plan_cmd(char **argv, tt_app_result *res)
{
  plan_job j;
  memset(&j, 0, sizeof j);
  if (read_words(&j, argv, res) && check_options(&j, res) &&
      open_dem(&j, res) && write_plan(&j, res)) {
    if (!j.quiet)
      printf("%s: %zu tiles of %zu cells (%zu x %zu) of %s; pieces in %s\n",
             j.plan, j.p.tiles, j.p.tile_size, j.p.tiles_x, j.p.tiles_y,
             j.p.dem, j.p.pieces);
    tt__app_result_ok(res);
  }
  if (j.f)
    VSIFCloseL(j.f);
  if (j.tmp)
    VSIUnlink(j.tmp);
  if (j.ds)
    GDALClose(j.ds);
  CPLFree(j.tmp);
  CPLFree(j.p.pieces);
  free(j.p.dem);
  CSLDestroy(j.p.options);
  tt_app_options_destroy(j.o);
  CSLDestroy(j.sv);
}

void tt__tiles_simplify(const tiles_plan *p, const char *const *extra,
                        const char *output, tt_progress_fn fn, void *arg,
                        tt_app_result *res)
{
  char **sv = CSLAddString(NULL, "simplify");
  for (size_t i = 0; p->options && p->options[i]; i++)
    sv = CSLAddString(sv, p->options[i]);
  for (size_t i = 0; extra && extra[i]; i++)
    sv = CSLAddString(sv, extra[i]);
  sv = CSLAddString(sv, p->dem);
  sv = CSLAddString(sv, output);
  tt_app_options *o = NULL;
  if (tt_app_options_new(sv, &o, res) == TT_OK) {
    tt_app_options_set_progress(o, fn, arg);
    /* the run catches GDAL's messages itself, from an empty handler
     * stack (tt_app_tiles pushed one for the tiles commands' own) */
    CPLPopErrorHandler();
    tt_app_run(o, res);
    tt__app_quiet_push(NULL);
  }
  tt_app_options_destroy(o);
  CSLDestroy(sv);
  memset(&tt__app_tiles_hook, 0, sizeof tt__app_tiles_hook);
}

/* Whether the words ask for help: --help, -help, -h or -? anywhere, which
 * wins over the rest of the line as for the other commands. */
static bool asks_help(char **argv)
{
  for (size_t i = 0; argv[i]; i++)
    if (tt__app_str_ieq(argv[i], "--help") ||
        tt__app_str_ieq(argv[i], "-help") || tt__app_str_ieq(argv[i], "-h") ||
        tt__app_str_ieq(argv[i], "-?"))
      return true;
  return false;
}

void tt_app_tiles(char **argv, tt_progress_fn fn, void *arg,
                  tt_app_result *res)
{
  memset(res, 0, sizeof *res);
  const char *sub = argv[0];
  if (asks_help(argv)) {
    fputs(tt__app_tiles_help(sub), stdout);
    fflush(stdout);
    tt__app_result_ok(res);
    return;
  }
  GDALAllRegister();
  tt__app_quiet_push(NULL); /* the messages are ours; debug lines pass */
  if (sub && strcmp(sub, "plan") == 0)
    plan_cmd(argv + 1, res);
  else if (sub && strcmp(sub, "run") == 0)
    tt__tiles_run(argv + 1, fn, arg, res);
  else if (sub && strcmp(sub, "merge") == 0)
    tt__tiles_merge(argv + 1, fn, arg, res);
  else
    tt__app_result_set(res, TT_APP_EXIT_USAGE, TT_ERR_ARG,
                       "tiles: plan, run or merge is needed (see 'terratin "
                       "tiles --help')");
  CPLPopErrorHandler();
}
