/*
 * tiles_plan.c -- `terratin tiles plan DEM PLAN.json [simplify options]`,
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

static void plan_cmd(char **argv, tt_app_result *res)
{
  const char *dem = NULL, *plan = NULL;
  int overwrite = 0, quiet = 0;
  char **words = NULL;
  for (size_t i = 0; argv[i]; i++) {
    const char *w = argv[i];
    if (tt__app_str_ieq(w, "-overwrite")) {
      overwrite = 1;
      continue;
    }
    if (tt__app_str_ieq(w, "-q")) {
      quiet = 1;
      continue;
    }
    if (w[0] == '-' && w[1] && !(w[1] >= '0' && w[1] <= '9')) {
      const tt__app_opt_def *d = tt__app_find_opt(w);
      if (d && (d->id == O_JSON || !(d->commands & FOR_S))) {
        tt__app_result_set(res, TT_APP_EXIT_USAGE, TT_ERR_ARG,
                           "tiles plan: %s is not an option of the plan", w);
        CSLDestroy(words);
        return;
      }
      words = CSLAddString(words, w);
      if (d && tt__app_opt_takes_value(d) && argv[i + 1])
        words = CSLAddString(words, argv[++i]);
      continue;
    }
    if (!dem)
      dem = w;
    else if (!plan)
      plan = w;
    else {
      tt__app_result_set(res, TT_APP_EXIT_USAGE, TT_ERR_ARG,
                         "tiles plan: unexpected argument %s\n%s", w,
                         PLAN_USAGE);
      CSLDestroy(words);
      return;
    }
  }
  if (!dem || !plan) {
    tt__app_result_set(res, TT_APP_EXIT_USAGE, TT_ERR_ARG,
                       "tiles plan: DEM and PLAN.json are needed\n%s",
                       PLAN_USAGE);
    CSLDestroy(words);
    return;
  }
  /* simplify's own parser checks the options */
  char **sv = CSLAddString(NULL, "simplify");
  for (size_t i = 0; words && words[i]; i++)
    sv = CSLAddString(sv, words[i]);
  sv = CSLAddString(sv, dem);
  sv = CSLAddString(sv, "tiles-plan-check.gpkg");
  tt_app_options *o = NULL;
  char *abs = NULL;
  VSILFILE *f = NULL;
  char *tmp = NULL, *dir = NULL;
  GDALDatasetH ds = NULL;
  if (tt_app_options_new(sv, &o, res) != TT_OK)
    goto done;
  const tt_app_settings *s = tt_app_options_settings(o);
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
    goto done;
  }
  for (size_t i = 0; words && words[i]; i++)
    if (has_control(words[i])) {
      tt__app_result_set(res, TT_APP_EXIT_USAGE, TT_ERR_ARG,
                         "tiles plan: an option holds a control character");
      goto done;
    }
  abs = realpath(dem, NULL);
  uint64_t bytes = 0, ns = 0;
  if (!abs || has_control(abs) || !dem_identity(abs, &bytes, &ns)) {
    tt__app_result_set(res, TT_APP_EXIT_FAILURE, TT_ERR_IO,
                       "%s: cannot open the DEM (%s)", dem,
                       abs ? "control character in its path" : strerror(errno));
    goto done;
  }
  ds = GDALOpenEx(abs, GDAL_OF_RASTER | GDAL_OF_READONLY, NULL, NULL, NULL);
  if (!ds || s->band > GDALGetRasterCount(ds)) {
    tt__app_result_set(res, TT_APP_EXIT_FAILURE, TT_ERR_IO,
                       "%s: %s", dem, ds ? "no such band (-b)"
                                         : "not a raster GDAL can open");
    goto done;
  }
  size_t W = (size_t)GDALGetRasterXSize(ds), H = (size_t)GDALGetRasterYSize(ds);
  if (W < 2 || H < 2) {
    tt__app_result_set(res, TT_APP_EXIT_FAILURE, TT_ERR_DATA, "%s: raster is "
                       "%zu x %zu pixels: at least 2 x 2 are needed", dem, W,
                       H);
    goto done;
  }
  size_t N = s->tile_size, ntx = (W - 2) / N + 1, nty = (H - 2) / N + 1;
  VSIStatBufL sb;
  if (!overwrite && VSIStatL(plan, &sb) == 0) {
    tt__app_result_set(res, TT_APP_EXIT_FAILURE, TT_ERR_EXISTS,
                       "%s: exists; use -overwrite to replace it", plan);
    goto done;
  }
  dir = CPLStrdup(CPLSPrintf("%s.tiles", plan));
  if (mkdir(dir, 0777) != 0 && errno != EEXIST) {
    tt__app_result_set(res, TT_APP_EXIT_FAILURE, TT_ERR_IO,
                       "%s: cannot make the pieces' folder (%s)", dir,
                       strerror(errno));
    goto done;
  }
  tmp = CPLStrdup(CPLSPrintf("%s.tmp%ld", plan, (long)getpid()));
  f = VSIFOpenL(tmp, "wb");
  if (!f) {
    tt__app_result_set(res, TT_APP_EXIT_FAILURE, TT_ERR_IO,
                       "%s: cannot write (%s)", plan, strerror(errno));
    goto done;
  }
  VSIFPrintfL(f, "%s\n  \"dem\": ", PLAN_HEAD);
  put_str(f, abs);
  VSIFPrintfL(f, ",\n  \"dem_bytes\": %llu,\n  \"dem_mtime_ns\": %llu,\n"
              "  \"width\": %zu,\n  \"height\": %zu,\n  \"tile_size\": %zu,\n"
              "  \"tiles_x\": %zu,\n  \"tiles_y\": %zu,\n  \"tiles\": %zu,\n"
              "  \"options\": [", (unsigned long long)bytes,
              (unsigned long long)ns, W, H, N, ntx, nty, ntx * nty);
  for (size_t i = 0; words && words[i]; i++) {
    VSIFPrintfL(f, i ? ", " : "");
    put_str(f, words[i]);
  }
  VSIFPrintfL(f, "],\n  \"tile_list\": [\n");
  for (size_t k = 0; k < ntx * nty; k++) {
    tt_tile t;
    size_t i = k % ntx, j = k / ntx, c0, r0, w, h;
    t.col0 = i * N;
    t.row0 = j * N;
    t.col1 = (i + 1) * N < W - 1 ? (i + 1) * N : W - 1;
    t.row1 = (j + 1) * N < H - 1 ? (j + 1) * N : H - 1;
    t.dem_width = W;
    t.dem_height = H;
    tt_tile_window(&t, &c0, &r0, &w, &h);
    VSIFPrintfL(f, "    {\"id\": %zu, \"cols\": [%zu, %zu], \"rows\": [%zu, "
                "%zu], \"window\": [%zu, %zu, %zu, %zu]}%s\n", k, t.col0,
                t.col1, t.row0, t.row1, c0, r0, w, h,
                k + 1 < ntx * nty ? "," : "");
  }
  VSIFPrintfL(f, "  ]\n}\n");
  int bad = VSIFCloseL(f) != 0;
  f = NULL;
  if (bad || rename(tmp, plan) != 0) {
    tt__app_result_set(res, TT_APP_EXIT_FAILURE, TT_ERR_IO,
                       "%s: cannot write (%s)", plan, strerror(errno));
    goto done;
  }
  if (!quiet)
    printf("%s: %zu tiles of %zu cells (%zu x %zu) of %s; pieces in %s\n",
           plan, ntx * nty, N, ntx, nty, abs, dir);
  tt__app_result_ok(res);
done:
  if (f)
    VSIFCloseL(f);
  if (tmp)
    VSIUnlink(tmp);
  if (ds)
    GDALClose(ds);
  CPLFree(tmp);
  CPLFree(dir);
  free(abs);
  tt_app_options_destroy(o);
  CSLDestroy(sv);
  CSLDestroy(words);
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
    tt_app_run(o, res);
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
  CPLPushErrorHandler(CPLQuietErrorHandler); /* the messages are ours */
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
