/*
 * tiles_plan.c -- apps/tiles/: the tiles command, a folder over the core
 * (apps/core/), simplify's tiled run as independent jobs for a cluster.
 * This file: `terratin tiles plan DEM PLAN.json [simplify options]`,
 * the dispatch of `terratin tiles ...`, and the plan read back by `tiles
 * run` and `tiles merge` (docs/scale.md).
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

#define PLAN_USAGE                                                          \
  "usage: terratin tiles plan DEM PLAN.json [-overwrite] [simplify "        \
  "options: -max_error E -tile_size N ...]\n"                              \
  "       terratin tiles run PLAN.json TILE_ID [-overwrite]\n"              \
  "       terratin tiles merge PLAN.json OUT.gpkg [-overwrite] [-q]"

#define PLAN_HEAD "{\n  \"terratin_tiles_plan\": 1,"

#define PLAN_HELP                                                           \
  "A tiled run (simplify -tile_size) as independent jobs, for a cluster:\n" \
  "  plan   checks simplify's options (-tile_size and -max_error needed),\n"\
  "         writes PLAN.json (the DEM's path, size and time, the tiles and\n"\
  "         their windows, the options) and makes the folder PLAN.json.tiles\n"\
  "  run    simplifies tile TILE_ID (0 .. tiles-1) alone (-method insert\n"\
  "         or decimate), on one thread, and\n"                            \
  "         writes its piece PLAN.json.tiles/TILE_ID.ttp\n"                 \
  "  merge  joins every piece into OUT as simplify writes it: the same\n"   \
  "         triangles and vertices as simplify -tile_size with the plan's\n"\
  "         options; a missing or stale piece, or a changed DEM, is refused\n"\
  "Each job can run on any machine that sees the same paths; the borders\n" \
  "of neighbouring tiles are computed alike by both. tools/tt_dask.py runs\n"\
  "the jobs on Dask distributed; docs/scale.md shows Slurm too.\n"

static uint64_t fnv1a(const char *p, size_t n)
{
  uint64_t h = UINT64_C(14695981039346656037);
  for (size_t i = 0; i < n; i++) {
    h ^= (unsigned char)p[i];
    h *= UINT64_C(1099511628211);
  }
  return h;
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

/* A JSON string of s (plan words: no control characters). */
static void put_str(VSILFILE *f, const char *s)
{
  VSIFPrintfL(f, "\"");
  for (; *s; s++) {
    if (*s == '"' || *s == '\\')
      VSIFPrintfL(f, "\\%c", *s);
    else
      VSIFPrintfL(f, "%c", *s);
  }
  VSIFPrintfL(f, "\"");
}

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
  char **words;            /* simplify's options as given (CSL) */
  char **sv;               /* simplify's command line that checks them */
  tt_app_options *o;       /* and what it said */
  char *abs;               /* the DEM's absolute path */
  uint64_t bytes, ns;      /* its size and modification time */
  GDALDatasetH ds;
  size_t width, height, tile_size, tiles_x, tiles_y;
  char *dir;               /* the pieces' folder */
  char *tmp;               /* the plan's temporary name */
  VSILFILE *f;
} plan_job;

/* The words: DEM, PLAN.json, -overwrite, -q, and simplify's options. */
static bool read_words(plan_job *j, char **argv, tt_app_result *res)
{
  for (size_t i = 0; argv[i]; i++) {
    const char *w = argv[i];
    if (tt__app_str_ieq(w, "-overwrite")) {
      j->overwrite = 1;
      continue;
    }
    if (tt__app_str_ieq(w, "-q")) {
      j->quiet = 1;
      continue;
    }
    if (w[0] == '-' && w[1] && !(w[1] >= '0' && w[1] <= '9')) {
      const tt__app_opt_def *d = tt__app_find_opt(w);
      if (d && (d->id == O_JSON || !(d->commands & FOR_S))) {
        tt__app_result_set(res, TT_APP_EXIT_USAGE, TT_ERR_ARG,
                           "tiles plan: %s is not an option of the plan", w);
        return false;
      }
      j->words = CSLAddString(j->words, w);
      if (d && tt__app_opt_takes_value(d) && argv[i + 1])
        j->words = CSLAddString(j->words, argv[++i]);
      continue;
    }
    if (!j->dem)
      j->dem = w;
    else if (!j->plan)
      j->plan = w;
    else {
      tt__app_result_set(res, TT_APP_EXIT_USAGE, TT_ERR_ARG,
                         "tiles plan: unexpected argument %s\n%s", w,
                         PLAN_USAGE);
      return false;
    }
  }
  if (!j->dem || !j->plan) {
    tt__app_result_set(res, TT_APP_EXIT_USAGE, TT_ERR_ARG,
                       "tiles plan: DEM and PLAN.json are needed\n%s",
                       PLAN_USAGE);
    return false;
  }
  return true;
}

/* simplify's own parser checks the options; a plan needs a bound. */
static bool check_options(plan_job *j, tt_app_result *res)
{
  j->sv = CSLAddString(NULL, "simplify");
  for (size_t i = 0; j->words && j->words[i]; i++)
    j->sv = CSLAddString(j->sv, j->words[i]);
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
  for (size_t i = 0; j->words && j->words[i]; i++)
    if (has_control(j->words[i])) {
      tt__app_result_set(res, TT_APP_EXIT_USAGE, TT_ERR_ARG,
                         "tiles plan: an option holds a control character");
      return false;
    }
  j->tile_size = s->tile_size;
  return true;
}

/* The DEM's identity and size, and the tiles of tile_size cells. */
static bool open_dem(plan_job *j, tt_app_result *res)
{
  const tt_app_settings *s = tt_app_options_settings(j->o);
  j->abs = realpath(j->dem, NULL);
  if (!j->abs || has_control(j->abs) ||
      !dem_identity(j->abs, &j->bytes, &j->ns)) {
    tt__app_result_set(res, TT_APP_EXIT_FAILURE, TT_ERR_IO,
                       "%s: cannot open the DEM (%s)", j->dem,
                       j->abs ? "control character in its path"
                              : strerror(errno));
    return false;
  }
  j->ds = GDALOpenEx(j->abs, GDAL_OF_RASTER | GDAL_OF_READONLY, NULL, NULL,
                     NULL);
  if (!j->ds || s->band > GDALGetRasterCount(j->ds)) {
    tt__app_result_set(res, TT_APP_EXIT_FAILURE, TT_ERR_IO,
                       "%s: %s", j->dem, j->ds ? "no such band (-b)"
                                               : "not a raster GDAL can open");
    return false;
  }
  size_t W = (size_t)GDALGetRasterXSize(j->ds);
  size_t H = (size_t)GDALGetRasterYSize(j->ds);
  if (W < 2 || H < 2) {
    tt__app_result_set(res, TT_APP_EXIT_FAILURE, TT_ERR_DATA, "%s: raster is "
                       "%zu x %zu pixels: at least 2 x 2 are needed", j->dem,
                       W, H);
    return false;
  }
  j->width = W;
  j->height = H;
  j->tiles_x = (W - 2) / j->tile_size + 1;
  j->tiles_y = (H - 2) / j->tile_size + 1;
  return true;
}

/* The plan's text: the DEM, its tiles and their windows, the options. */
static void put_plan(const plan_job *j, VSILFILE *f)
{
  size_t W = j->width, H = j->height, N = j->tile_size, ntx = j->tiles_x;
  size_t ntiles = ntx * j->tiles_y;
  VSIFPrintfL(f, "%s\n  \"dem\": ", PLAN_HEAD);
  put_str(f, j->abs);
  VSIFPrintfL(f, ",\n  \"dem_bytes\": %llu,\n  \"dem_mtime_ns\": %llu,\n"
              "  \"width\": %zu,\n  \"height\": %zu,\n  \"tile_size\": %zu,\n"
              "  \"tiles_x\": %zu,\n  \"tiles_y\": %zu,\n  \"tiles\": %zu,\n"
              "  \"options\": [", (unsigned long long)j->bytes,
              (unsigned long long)j->ns, W, H, N, ntx, j->tiles_y, ntiles);
  for (size_t i = 0; j->words && j->words[i]; i++) {
    VSIFPrintfL(f, i ? ", " : "");
    put_str(f, j->words[i]);
  }
  VSIFPrintfL(f, "],\n  \"tile_list\": [\n");
  for (size_t k = 0; k < ntiles; k++) {
    tt_tile t;
    size_t i = k % ntx, jj = k / ntx, c0, r0, w, h;
    t.col0 = i * N;
    t.row0 = jj * N;
    t.col1 = (i + 1) * N < W - 1 ? (i + 1) * N : W - 1;
    t.row1 = (jj + 1) * N < H - 1 ? (jj + 1) * N : H - 1;
    t.dem_width = W;
    t.dem_height = H;
    tt_tile_window(&t, &c0, &r0, &w, &h);
    VSIFPrintfL(f, "    {\"id\": %zu, \"cols\": [%zu, %zu], \"rows\": [%zu, "
                "%zu], \"window\": [%zu, %zu, %zu, %zu]}%s\n", k, t.col0,
                t.col1, t.row0, t.row1, c0, r0, w, h,
                k + 1 < ntiles ? "," : "");
  }
  VSIFPrintfL(f, "  ]\n}\n");
}

/* PLAN.json through a temporary name, and the pieces' folder. */
static bool write_plan(plan_job *j, tt_app_result *res)
{
  VSIStatBufL sb;
  if (!j->overwrite && VSIStatL(j->plan, &sb) == 0) {
    tt__app_result_set(res, TT_APP_EXIT_FAILURE, TT_ERR_EXISTS,
                       "%s: exists; use -overwrite to replace it", j->plan);
    return false;
  }
  j->dir = CPLStrdup(CPLSPrintf("%s.tiles", j->plan));
  if (mkdir(j->dir, 0777) != 0 && errno != EEXIST) {
    tt__app_result_set(res, TT_APP_EXIT_FAILURE, TT_ERR_IO,
                       "%s: cannot make the pieces' folder (%s)", j->dir,
                       strerror(errno));
    return false;
  }
  j->tmp = CPLStrdup(CPLSPrintf("%s.tmp%ld", j->plan, (long)getpid()));
  if (!(j->f = VSIFOpenL(j->tmp, "wb"))) {
    tt__app_result_set(res, TT_APP_EXIT_FAILURE, TT_ERR_IO,
                       "%s: cannot write (%s)", j->plan, strerror(errno));
    return false;
  }
  put_plan(j, j->f);
  int bad = VSIFCloseL(j->f) != 0;
  j->f = NULL;
  if (bad || rename(j->tmp, j->plan) != 0) {
    tt__app_result_set(res, TT_APP_EXIT_FAILURE, TT_ERR_IO,
                       "%s: cannot write (%s)", j->plan, strerror(errno));
    return false;
  }
  return true;
}

static void plan_cmd(char **argv, tt_app_result *res)
{
  plan_job j;
  memset(&j, 0, sizeof j);
  if (read_words(&j, argv, res) && check_options(&j, res) &&
      open_dem(&j, res) && write_plan(&j, res)) {
    if (!j.quiet)
      printf("%s: %zu tiles of %zu cells (%zu x %zu) of %s; pieces in %s\n",
             j.plan, j.tiles_x * j.tiles_y, j.tile_size, j.tiles_x,
             j.tiles_y, j.abs, j.dir);
    tt__app_result_ok(res);
  }
  if (j.f)
    VSIFCloseL(j.f);
  if (j.tmp)
    VSIUnlink(j.tmp);
  if (j.ds)
    GDALClose(j.ds);
  CPLFree(j.tmp);
  CPLFree(j.dir);
  free(j.abs);
  tt_app_options_destroy(j.o);
  CSLDestroy(j.sv);
  CSLDestroy(j.words);
}

/* --- the plan read back: only what plan_cmd writes, in its layout --- */

static const char *key_at(const char *text, const char *key)
{
  const char *p = strstr(text, CPLSPrintf("\n  \"%s\": ", key));
  return p ? p + strlen(key) + 7 : NULL;
}

/* A JSON string at p into a new string (CPLFree it); *end after it. */
static char *get_str(const char *p, const char **end)
{
  if (!p || *p != '"')
    return NULL;
  char *s = CPLMalloc(strlen(p) + 1), *q = s;
  for (p++; *p && *p != '"'; p++) {
    if (*p == '\\' && (p[1] == '"' || p[1] == '\\'))
      p++;
    *q++ = *p;
  }
  *q = '\0';
  if (*p != '"') {
    CPLFree(s);
    return NULL;
  }
  *end = p + 1;
  return s;
}

static bool get_u64(const char *text, const char *key, uint64_t *v)
{
  const char *p = key_at(text, key);
  char *e;
  if (!p || *p < '0' || *p > '9')
    return false;
  errno = 0;
  unsigned long long x = strtoull(p, &e, 10);
  if (errno || e == p)
    return false;
  *v = (uint64_t)x;
  return true;
}

bool tt__tiles_plan_read(const char *path, tiles_plan *p, tt_app_result *res)
{
  memset(p, 0, sizeof *p);
  GByte *buf = NULL;
  vsi_l_offset len = 0;
  if (!VSIIngestFile(NULL, path, &buf, &len, 64 << 20)) {
    tt__app_result_set(res, TT_APP_EXIT_FAILURE, TT_ERR_IO,
                       "%s: cannot read the plan", path);
    return false;
  }
  const char *t = (const char *)buf, *e = NULL;
  uint64_t w = 0, h = 0, n = 0, k = 0;
  p->path = CPLStrdup(path);
  p->hash = fnv1a(t, (size_t)len);
  p->dem = get_str(key_at(t, "dem"), &e);
  const char *o = key_at(t, "options");
  bool ok = strncmp(t, PLAN_HEAD, strlen(PLAN_HEAD)) == 0 &&
            p->dem && get_u64(t, "dem_bytes", &p->dem_bytes) &&
            get_u64(t, "dem_mtime_ns", &p->dem_mtime_ns) &&
            get_u64(t, "width", &w) && get_u64(t, "height", &h) &&
            get_u64(t, "tile_size", &n) && get_u64(t, "tiles", &k) && o &&
            *o == '[';
  if (ok) {
    for (o++; *o == '"';) {
      char *s = get_str(o, &e);
      if (!s)
        break;
      p->options = CSLAddString(p->options, s);
      CPLFree(s);
      o = e;
      if (*o == ',' && o[1] == ' ')
        o += 2;
    }
    ok = *o == ']';
  }
  CPLFree(buf);
  if (!ok) {
    tt__app_result_set(res, TT_APP_EXIT_FAILURE, TT_ERR_DATA,
                       "%s: not a plan of `terratin tiles plan`", path);
    return false;
  }
  p->width = (size_t)w;
  p->height = (size_t)h;
  p->tile_size = (size_t)n;
  p->tiles = (size_t)k;
  p->pieces = CPLStrdup(CPLSPrintf("%s.tiles", path));
  uint64_t bytes, ns;
  if (!dem_identity(p->dem, &bytes, &ns)) {
    tt__app_result_set(res, TT_APP_EXIT_FAILURE, TT_ERR_IO,
                       "%s: the plan's DEM cannot be read (%s)", p->dem,
                       strerror(errno));
    return false;
  }
  if (bytes != p->dem_bytes || ns != p->dem_mtime_ns) {
    tt__app_result_set(res, TT_APP_EXIT_FAILURE, TT_ERR_DATA,
                       "%s: changed since %s was made (size or modification "
                       "time); make the plan again", p->dem, path);
    return false;
  }
  return true;
}

void tt__tiles_plan_free(tiles_plan *p)
{
  CPLFree(p->path);
  CPLFree(p->dem);
  CPLFree(p->pieces);
  CSLDestroy(p->options);
  memset(p, 0, sizeof *p);
}

char *tt__tiles_piece_path(const tiles_plan *p, size_t k)
{
  return CPLStrdup(CPLSPrintf("%s/%zu.ttp", p->pieces, k));
}

uint64_t tt__tiles_piece_tag(const tiles_plan *p, size_t k)
{
  uint64_t h = p->hash;
  for (int i = 0; i < 8; i++) {
    h ^= (uint64_t)(k >> (8 * i)) & 0xff;
    h *= UINT64_C(1099511628211);
  }
  return h;
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

void tt_app_tiles(char **argv, tt_progress_fn fn, void *arg,
                  tt_app_result *res)
{
  memset(res, 0, sizeof *res);
  const char *sub = argv[0];
  GDALAllRegister();
  tt__app_quiet_push(NULL); /* the messages are ours; debug lines pass */
  if (sub && strcmp(sub, "plan") == 0)
    plan_cmd(argv + 1, res);
  else if (sub && strcmp(sub, "run") == 0)
    tt__tiles_run(argv + 1, fn, arg, res);
  else if (sub && strcmp(sub, "merge") == 0)
    tt__tiles_merge(argv + 1, fn, arg, res);
  else if (sub && (strcmp(sub, "-h") == 0 || strcmp(sub, "--help") == 0)) {
    printf("%s\n\n%s", PLAN_USAGE, PLAN_HELP);
    tt__app_result_ok(res);
  } else
    tt__app_result_set(res, TT_APP_EXIT_USAGE, TT_ERR_ARG,
                       "tiles: plan, run or merge is needed\n%s", PLAN_USAGE);
  CPLPopErrorHandler();
}
