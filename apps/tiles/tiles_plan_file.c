/*
 * tiles_plan_file.c -- apps/tiles/: the tiles command, a folder over the
 * core (apps/core/), simplify's tiled run as independent jobs for a
 * cluster. This file: PLAN.json, its text as `tiles plan` writes it and
 * the reader of `tiles run` and `tiles merge`, which takes a plan as input
 * from anywhere, never as trusted code.
 *
 * The text has one layout, written by tt__tiles_plan_text alone:
 *
 *   {
 *     "terratin_tiles_plan": 2,
 *     "dem": "/abs/path.tif",
 *     "dem_bytes": B, "dem_mtime_ns": T,       (one key a line)
 *     "width": W, "height": H, "tile_size": N,
 *     "tiles_x": X, "tiles_y": Y, "tiles": X*Y,
 *     "options": ["-max_error", "2", ...],
 *     "tile_list": [ {"id": 0, "cols": ..., "rows": ..., "window": ...}, ...
 *     ],
 *     "checksum": "fnv1a64:<16 hex digits>"     (of every byte before it)
 *   }
 *
 * Invariants of a plan read back: it is whole (the closing checksum is
 * there and matches, so a truncated or damaged plan is refused), its grid
 * is the one W, H and N give and W x H is the DEM's, its options are -NAME
 * [VALUE] pairs of the options that shape the TIN (a whitelist: never
 * --config, --debug, an output, a budget, a positional word, a long word
 * or a path), and its text is byte for byte what the writer makes of the
 * fields read (so nothing else can hide in it). Every refusal of what the
 * plan says exits 2 with the field or option named; an unreadable or
 * changed DEM exits 1.
 *
 * Workload: one pass over a plan of at most TT_TILES_PLAN_MAX_BYTES, the
 * text rebuilt once, the DEM's header opened once.
 */
#define _XOPEN_SOURCE 700 /* realpath */
#include "tiles.h"
#include "option_table.h"

#include <cpl_conv.h>
#include <cpl_string.h>
#include <cpl_vsi.h>

#include <errno.h>
#include <limits.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#define PLAN_HEAD "{\n  \"terratin_tiles_plan\": 2,"
#define PLAN_HEAD_V1 "{\n  \"terratin_tiles_plan\": 1,"
#define SUM_KEY "  \"checksum\": \"fnv1a64:"
#define SUM_END "\"\n}\n"
#define SUM_LEN (sizeof SUM_KEY - 1 + 16 + sizeof SUM_END - 1)
/* an option word, and the words of a plan, at most */
#define WORD_MAX 256
#define WORDS_MAX 64
/* a tile's line is at least 64 bytes */
#define TILES_MAX (TT_TILES_PLAN_MAX_BYTES / 64)

/* A refusal of what the plan says (exit code 2), as an expression. */
#define REFUSE(res, st, ...)                                                 \
  (tt__app_result_set((res), TT_APP_EXIT_USAGE, (st), __VA_ARGS__), false)

static uint64_t fnv1a(const char *p, size_t n)
{
  uint64_t h = UINT64_C(14695981039346656037);
  for (size_t i = 0; i < n; i++) {
    h ^= (unsigned char)p[i];
    h *= UINT64_C(1099511628211);
  }
  return h;
}

static bool has_control(const char *s)
{
  for (; *s; s++)
    if ((unsigned char)*s < 0x20 || *s == 0x7f)
      return true;
  return false;
}

void tt__tiles_grid(tiles_plan *p)
{
  p->tiles_x = (p->width - 2) / p->tile_size + 1;
  p->tiles_y = (p->height - 2) / p->tile_size + 1;
  p->tiles = p->tiles_x * p->tiles_y;
}

/* --- the text ------------------------------------------------------------- */

/* A text built in memory, dropped whole past TT_TILES_PLAN_MAX_BYTES. */
typedef struct plan_text {
  char *s;
  size_t n, cap;
  bool full;
} plan_text;

static void add_bytes(plan_text *t, const char *b, size_t n)
{
  if (t->full || n >= TT_TILES_PLAN_MAX_BYTES - t->n) {
    t->full = true;
    return;
  }
  if (t->n + n >= t->cap) {
    size_t cap = t->cap ? t->cap : 4096;
    while (t->n + n >= cap)
      cap *= 2;
    t->s = CPLRealloc(t->s, cap);
    t->cap = cap;
  }
  memcpy(t->s + t->n, b, n);
  t->n += n;
  t->s[t->n] = '\0';
}

static void add(plan_text *t, const char *fmt, ...) TT_APP_PRINTF_(2, 3);
static void add(plan_text *t, const char *fmt, ...)
{
  char buf[256]; /* every formatted piece is a few numbers */
  va_list ap;
  va_start(ap, fmt);
  int k = vsnprintf(buf, sizeof buf, fmt, ap);
  va_end(ap);
  if (k < 0 || (size_t)k >= sizeof buf)
    t->full = true;
  else
    add_bytes(t, buf, (size_t)k);
}

/* A JSON string of s (plan words and paths: no control characters). */
static void add_str(plan_text *t, const char *s)
{
  add_bytes(t, "\"", 1);
  for (const char *q = s; *q; q++) {
    size_t run = strcspn(q, "\"\\");
    add_bytes(t, q, run);
    q += run;
    if (!*q)
      break;
    add_bytes(t, "\\", 1);
    add_bytes(t, q, 1);
  }
  add_bytes(t, "\"", 1);
}

static void add_tile(plan_text *t, const tiles_plan *p, size_t k)
{
  size_t W = p->width, H = p->height, N = p->tile_size;
  size_t i = k % p->tiles_x, j = k / p->tiles_x, c0, r0, w, h;
  tt_tile tile;
  tile.col0 = i * N;
  tile.row0 = j * N;
  tile.col1 = (i + 1) * N < W - 1 ? (i + 1) * N : W - 1;
  tile.row1 = (j + 1) * N < H - 1 ? (j + 1) * N : H - 1;
  tile.dem_width = W;
  tile.dem_height = H;
  tt_tile_window(&tile, &c0, &r0, &w, &h);
  add(t, "    {\"id\": %zu, \"cols\": [%zu, %zu], \"rows\": [%zu, %zu], "
      "\"window\": [%zu, %zu, %zu, %zu]}%s\n", k, tile.col0, tile.col1,
      tile.row0, tile.row1, c0, r0, w, h, k + 1 < p->tiles ? "," : "");
}

char *tt__tiles_plan_text(const tiles_plan *p, size_t *out_len)
{
  plan_text t = {NULL, 0, 0, p->tiles > TILES_MAX};
  add(&t, "%s\n  \"dem\": ", PLAN_HEAD);
  add_str(&t, p->dem);
  add(&t, ",\n  \"dem_bytes\": %llu,\n  \"dem_mtime_ns\": %llu,\n",
      (unsigned long long)p->dem_bytes, (unsigned long long)p->dem_mtime_ns);
  add(&t, "  \"width\": %zu,\n  \"height\": %zu,\n  \"tile_size\": %zu,\n",
      p->width, p->height, p->tile_size);
  add(&t, "  \"tiles_x\": %zu,\n  \"tiles_y\": %zu,\n  \"tiles\": %zu,\n"
      "  \"options\": [", p->tiles_x, p->tiles_y, p->tiles);
  for (size_t i = 0; p->options && p->options[i]; i++) {
    add(&t, "%s", i ? ", " : "");
    add_str(&t, p->options[i]);
  }
  add(&t, "],\n  \"tile_list\": [\n");
  for (size_t k = 0; k < p->tiles && !t.full; k++)
    add_tile(&t, p, k);
  add(&t, "  ],\n");
  if (!t.full)
    add(&t, "%s%016llx%s", SUM_KEY, (unsigned long long)fnv1a(t.s, t.n),
        SUM_END);
  if (t.full) {
    CPLFree(t.s);
    return NULL;
  }
  *out_len = t.n;
  return t.s;
}

/* --- what a plan may carry ------------------------------------------------ */

/* The options that shape the TIN: the bound and the tiles, the method and
 * its choices, the criterion and its passes, the band, nodata, heights and
 * the frame they are measured in. Their values are numbers or names that
 * simplify's parser checks against its lists, but for -work_srs's
 * (checked below). */
static const enum opt_id plan_opts[] = {
    O_MAX_ERROR, O_TILE_SIZE, O_METHOD, O_START, O_IMPORTANCE, O_SELECTION,
    O_ONEPASS, O_HOLE, O_CRITERION, O_REPAIR, O_OPTIMIZE, O_SEED,
    O_ANNEAL_T0, O_ANNEAL_STAGES, O_ANNEAL_SWAPS, O_ANNEAL_GOOD, O_ANNEAL_R,
    O_B, O_SRCNODATA, O_Z_FACTOR, O_Z_UNIT, O_Z_TO, O_WORK_SRS,
    /* GDAL's input options: every tile reads the same window alike */
    O_A_SRS, O_S_SRS, O_A_NODATA, O_SRCWIN, O_PROJWIN, O_PROJWIN_SRS,
    O_A_ULLR};
/* The output's: `tiles merge` takes them from its own command line. */
static const enum opt_id output_opts[] = {
    O_OF, O_LCO, O_DSCO, O_NLN, O_LAYERS, O_NOSTYLE, O_OBJ_LOCAL, O_T_SRS};
static const enum opt_id budget_opts[] = {O_MAX_POINTS, O_MAX_TRIANGLES,
                                          O_PERCENT};

static bool in_list(const enum opt_id *l, size_t n, enum opt_id id)
{
  for (size_t i = 0; i < n; i++)
    if (l[i] == id)
      return true;
  return false;
}
#define IN(list, id) in_list(list, sizeof list / sizeof list[0], id)

/* simplify's entry of an option word, or NULL. */
static const tt__app_opt_def *simplify_opt(const char *w)
{
  const tt__app_opt_def *d = w[0] == '-' ? tt__app_find_opt(w) : NULL;
  return d ? tt__app_opt_for(d, TT_APP_SIMPLIFY) : NULL;
}

int tt__tiles_output_option(const char *w)
{
  const tt__app_opt_def *d = simplify_opt(w);
  if (!d || !IN(output_opts, d->id))
    return -1;
  return tt__app_opt_takes_value(d);
}

/* AUTHORITY:CODE (EPSG:32633, IAU_2015:30100): a CRS from PROJ's database.
 * Any other form GDAL reads may name a file to read (a .prj, a PROJ grid
 * in +nadgrids=, ESRI::) or a URL to fetch, on every job's machine. */
static bool is_auth_code(const char *v)
{
  const char *colon = strchr(v, ':');
  if (!colon || colon == v || !colon[1] || strlen(v) > 64)
    return false;
  for (const char *q = v; *q; q++)
    if (q != colon && !(*q == '_' || *q == '.' || (*q >= '0' && *q <= '9') ||
                        (*q >= 'A' && *q <= 'Z') || (*q >= 'a' && *q <= 'z')))
      return false;
  return true;
}

static bool refuse_option(const char *who, const char *w,
                          const tt__app_opt_def *d, tt_app_result *res)
{
  if (!d && w[0] != '-')
    return REFUSE(res, TT_ERR_ARG, "%s: '%s' is not an option: a plan holds "
                  "-NAME [VALUE] pairs only (a word of its own would "
                  "become an input or output name)", who, w);
  const char *near = d ? NULL : tt__app_opt_suggest(w, TT_APP_SIMPLIFY);
  if (near)
    return REFUSE(res, TT_ERR_ARG, "%s: unknown option '%s'; did you mean "
                  "%s?", who, w, near);
  if (d && IN(budget_opts, d->id))
    return REFUSE(res, TT_ERR_ARG, "%s: %s is a budget: a plan needs "
                  "-tile_size N and -max_error E (each tile is simplified "
                  "to a bound alone; no -max_points, -max_triangles or "
                  "-percent: their bound needs a pass over every tile "
                  "first, which simplify -tile_size makes)", who, w);
  if (d && IN(output_opts, d->id))
    return REFUSE(res, TT_ERR_ARG, "%s: %s is an option of the output, "
                  "which a plan never carries: give it to `terratin tiles "
                  "merge`", who, w);
  return REFUSE(res, TT_ERR_ARG, "%s: %s is not an option a plan may carry "
                "(only those that shape the TIN: see `terratin tiles "
                "--help`)", who, w);
}

bool tt__tiles_plan_check_words(const char *who, char *const *words,
                                tt_app_result *res)
{
  size_t n = 0;
  for (; words && words[n]; n++) {
    size_t len = strlen(words[n]);
    if (len > WORD_MAX)
      return REFUSE(res, TT_ERR_ARG, "%s: an option word of %zu bytes (at "
                    "most %d in a plan)", who, len, WORD_MAX);
    if (has_control(words[n]))
      return REFUSE(res, TT_ERR_ARG, "%s: an option word holds a control "
                    "character", who);
  }
  if (n > WORDS_MAX)
    return REFUSE(res, TT_ERR_ARG, "%s: %zu option words (at most %d in a "
                  "plan)", who, n, WORDS_MAX);
  for (size_t i = 0; i < n; i++) {
    const tt__app_opt_def *d = simplify_opt(words[i]);
    if (!d || !IN(plan_opts, d->id))
      return refuse_option(who, words[i], d, res);
    size_t nv = (size_t)tt__app_opt_takes_value(d);
    if (!nv)
      continue;
    if (i + nv >= n)
      return REFUSE(res, TT_ERR_ARG, "%s: option %s needs %s", who,
                    words[i], nv == 1 ? "a value" : "its values");
    const char *opt = words[i], *v = words[i + 1];
    i += nv;
    if ((d->id == O_WORK_SRS || d->id == O_A_SRS || d->id == O_S_SRS ||
         d->id == O_PROJWIN_SRS) && !is_auth_code(v))
      return REFUSE(res, TT_ERR_ARG, "%s: %s '%s': a plan takes a "
                    "CRS as AUTHORITY:CODE only (e.g. EPSG:32633), never a "
                    "file name, URL, WKT or PROJ string", who, opt, v);
  }
  return true;
}

/* --- the plan read back ------------------------------------------------- */

/* The text still to read. */
typedef struct cursor {
  const char *p, *end;
} cursor;

static bool lit(cursor *c, const char *s)
{
  size_t n = strlen(s);
  if ((size_t)(c->end - c->p) < n || memcmp(c->p, s, n) != 0)
    return false;
  c->p += n;
  return true;
}

static bool num(cursor *c, uint64_t *v)
{
  uint64_t x = 0;
  const char *start = c->p;
  for (; c->p < c->end && *c->p >= '0' && *c->p <= '9'; c->p++) {
    unsigned d = (unsigned)(*c->p - '0');
    if (x > (UINT64_MAX - d) / 10)
      return false;
    x = 10 * x + d;
  }
  *v = x;
  return c->p > start;
}

/* A JSON string as the writer makes it (escapes \" and \\ only, no control
 * character) into *out (CPLFree it): 1; 0 when it is none; -1 when it is
 * longer than max bytes (*out_len its length). */
static int str(cursor *c, size_t max, char **out, size_t *out_len)
{
  if (!lit(c, "\""))
    return 0;
  size_t n = 0;
  const char *q = c->p;
  for (; q < c->end && *q != '"'; q++, n++) {
    if ((unsigned char)*q < 0x20)
      return 0;
    if (*q == '\\' && (++q == c->end || (*q != '"' && *q != '\\')))
      return 0;
  }
  if (q == c->end)
    return 0;
  *out_len = n;
  if (n > max)
    return -1;
  char *s = CPLMalloc(n + 1), *o = s;
  for (const char *r = c->p; r < q; r++)
    *o++ = *r == '\\' ? *++r : *r;
  *o = '\0';
  *out = s;
  c->p = q + 1;
  return 1;
}

/* Whole: the closing checksum is there, and is that of what precedes it. */
static bool check_sum(const char *path, const char *t, size_t len,
                      tt_app_result *res)
{
  if (len >= sizeof PLAN_HEAD_V1 - 1 &&
      memcmp(t, PLAN_HEAD_V1, sizeof PLAN_HEAD_V1 - 1) == 0)
    return REFUSE(res, TT_ERR_DATA, "%s: a plan of an older terratin "
                  "(version 1, without a checksum): make it again with "
                  "`terratin tiles plan`", path);
  if (len < sizeof PLAN_HEAD - 1 ||
      memcmp(t, PLAN_HEAD, sizeof PLAN_HEAD - 1) != 0)
    return REFUSE(res, TT_ERR_DATA, "%s: not a plan of `terratin tiles "
                  "plan`", path);
  const char *k = len >= SUM_LEN ? t + len - SUM_LEN : NULL;
  if (!k || memcmp(k, SUM_KEY, sizeof SUM_KEY - 1) != 0 ||
      memcmp(t + len - (sizeof SUM_END - 1), SUM_END, sizeof SUM_END - 1))
    return REFUSE(res, TT_ERR_DATA, "%s: truncated or damaged: a plan ends "
                  "with its \"checksum\" key; make it again", path);
  char want[17];
  snprintf(want, sizeof want, "%016llx",
           (unsigned long long)fnv1a(t, (size_t)(k - t)));
  if (memcmp(k + sizeof SUM_KEY - 1, want, 16) != 0)
    return REFUSE(res, TT_ERR_DATA, "%s: checksum mismatch (the plan says "
                  "%.16s, its text gives %s): damaged or edited; make it "
                  "again", path, k + sizeof SUM_KEY - 1, want);
  return true;
}

/* The options' words, "options": [...] at c. */
static bool parse_options(const char *path, cursor *c, tiles_plan *p,
                          tt_app_result *res)
{
  for (size_t i = 0;; i++) {
    if (lit(c, "]"))
      return true;
    if (i >= WORDS_MAX)
      return REFUSE(res, TT_ERR_ARG, "%s: more than %d option words (the "
                    "most a plan holds)", path, WORDS_MAX);
    char *w = NULL;
    size_t wlen = 0;
    int r = (i == 0 || lit(c, ", ")) ? str(c, WORD_MAX, &w, &wlen) : 0;
    if (r < 0)
      return REFUSE(res, TT_ERR_ARG, "%s: an option word of %zu bytes (at "
                    "most %d in a plan)", path, wlen, WORD_MAX);
    if (r == 0)
      return REFUSE(res, TT_ERR_DATA, "%s: not a plan of `terratin tiles "
                    "plan`: \"options\" is malformed", path);
    p->options = CSLAddString(p->options, w);
    CPLFree(w);
  }
}

/* The fields, in the writer's order, up to the tile list (which
 * check_text compares whole). */
static bool parse_plan(const char *path, const char *t, size_t len,
                       tiles_plan *p, tt_app_result *res)
{
  static const char *const keys[] = {"dem_bytes", "dem_mtime_ns", "width",
                                     "height",    "tile_size",    "tiles_x",
                                     "tiles_y",   "tiles"};
  uint64_t v[sizeof keys / sizeof keys[0]];
  cursor c = {t, t + len};
  const char *bad = "dem";
  size_t n = 0;
  if (!lit(&c, PLAN_HEAD "\n  \"dem\": ") ||
      str(&c, PATH_MAX, &p->dem, &n) != 1 || p->dem[0] != '/')
    goto malformed;
  for (size_t i = 0; i < sizeof keys / sizeof keys[0]; i++) {
    bad = keys[i];
    if (!lit(&c, ",\n  \"") || !lit(&c, keys[i]) || !lit(&c, "\": ") ||
        !num(&c, &v[i]))
      goto malformed;
  }
  bad = "options";
  if (!lit(&c, ",\n  \"options\": ["))
    goto malformed;
  if (!parse_options(path, &c, p, res))
    return false;
  bad = "tile_list";
  if (!lit(&c, ",\n  \"tile_list\": [\n"))
    goto malformed;
  p->dem_bytes = v[0];
  p->dem_mtime_ns = v[1];
  /* the sizes' ranges: check_grid */
  if (v[2] > INT_MAX || v[3] > INT_MAX || v[4] > 65536)
    return REFUSE(res, TT_ERR_DATA, "%s: \"width\" %llu, \"height\" %llu "
                  "or \"tile_size\" %llu out of range", path,
                  (unsigned long long)v[2], (unsigned long long)v[3],
                  (unsigned long long)v[4]);
  p->width = (size_t)v[2];
  p->height = (size_t)v[3];
  p->tile_size = (size_t)v[4];
  p->tiles_x = (size_t)v[5];
  p->tiles_y = (size_t)v[6];
  p->tiles = (size_t)v[7];
  if (v[5] != p->tiles_x || v[6] != p->tiles_y || v[7] != p->tiles)
    return REFUSE(res, TT_ERR_DATA, "%s: \"tiles\" out of range", path);
  return true;
malformed:
  return REFUSE(res, TT_ERR_DATA, "%s: not a plan of `terratin tiles plan`: "
                "\"%s\" is missing or malformed", path, bad);
}

/* The grid: the one width, height and tile size give, of sizes in range. */
static bool check_grid(const char *path, const tiles_plan *p,
                       tt_app_result *res)
{
  if (p->width < 2 || p->height < 2)
    return REFUSE(res, TT_ERR_DATA, "%s: a DEM of %zu x %zu samples (at "
                  "least 2 x 2)", path, p->width, p->height);
  if (p->tile_size < 16)
    return REFUSE(res, TT_ERR_DATA, "%s: \"tile_size\" %zu (16 to 65536)",
                  path, p->tile_size);
  tiles_plan g = *p;
  tt__tiles_grid(&g);
  if (g.tiles_x != p->tiles_x || g.tiles_y != p->tiles_y ||
      g.tiles != p->tiles)
    return REFUSE(res, TT_ERR_DATA, "%s: \"tiles\" %zu (%zu x %zu) is not "
                  "the %zu (%zu x %zu) tiles of %zu cells of a %zu x %zu "
                  "DEM", path, p->tiles, p->tiles_x, p->tiles_y, g.tiles,
                  g.tiles_x, g.tiles_y, p->tile_size, p->width, p->height);
  if (p->tiles > TILES_MAX)
    return REFUSE(res, TT_ERR_DATA, "%s: %zu tiles (a plan holds at most "
                  "%u)", path, p->tiles, (unsigned)TILES_MAX);
  return true;
}

/* simplify's parser reads the options as `tiles run` will pass them: a
 * bound, the plan's tile size, no budget. *out_band: -b. */
static bool check_line(const tiles_plan *p, tt_app_options **out_o,
                       tt_app_result *res)
{
  char **sv = CSLAddString(NULL, "simplify");
  for (size_t i = 0; p->options && p->options[i]; i++)
    sv = CSLAddString(sv, p->options[i]);
  sv = CSLAddString(sv, p->dem);
  sv = CSLAddString(sv, "tiles-plan-check.gpkg");
  tt_app_options *o = NULL;
  tt_app_result pr;
  bool ok = tt_app_options_new(sv, &o, &pr) == TT_OK;
  CSLDestroy(sv);
  if (!ok)
    return REFUSE(res, TT_ERR_ARG, "%s: its options: %s", p->path,
                  pr.message);
  const tt_app_settings *s = tt_app_options_settings(o);
  if (s->tile_size != p->tile_size)
    ok = REFUSE(res, TT_ERR_DATA, "%s: its options' -tile_size %zu is not "
                "its \"tile_size\" %zu", p->path, s->tile_size,
                p->tile_size);
  else if (s->max_error < 0)
    ok = REFUSE(res, TT_ERR_ARG, "%s: its options have no -max_error",
                p->path);
  if (ok)
    *out_o = o;
  else
    tt_app_options_destroy(o);
  return ok;
}

static bool dem_identity(const char *path, uint64_t *bytes, uint64_t *ns)
{
  struct stat sb;
  if (stat(path, &sb) != 0)
    return false;
  *bytes = (uint64_t)sb.st_size;
  *ns = (uint64_t)sb.st_mtim.tv_sec * UINT64_C(1000000000) +
        (uint64_t)sb.st_mtim.tv_nsec;
  return S_ISREG(sb.st_mode);
}

/* The DEM: a file by its canonical path, unchanged since the plan, a
 * raster of the plan's size with the band. */
static bool check_dem(const tiles_plan *p, const tt_app_settings *s,
                      tt_app_result *res)
{
  int band = s->band;
  char *real = realpath(p->dem, NULL);
  uint64_t bytes = 0, ns = 0;
  bool ok = false;
  if (!real)
    tt__app_result_set(res, TT_APP_EXIT_FAILURE, TT_ERR_IO, "%s: the plan's "
                       "DEM cannot be read (%s)", p->dem, strerror(errno));
  else if (strcmp(real, p->dem) != 0)
    tt__app_result_set(res, TT_APP_EXIT_USAGE, TT_ERR_DATA, "%s: its \"dem\" "
                       "%s is not a canonical path (it is %s)", p->path,
                       p->dem, real);
  else if (!dem_identity(p->dem, &bytes, &ns))
    tt__app_result_set(res, TT_APP_EXIT_USAGE, TT_ERR_DATA, "%s: its \"dem\" "
                       "%s is not a file", p->path, p->dem);
  else if (bytes != p->dem_bytes || ns != p->dem_mtime_ns)
    tt__app_result_set(res, TT_APP_EXIT_FAILURE, TT_ERR_DATA, "%s: changed "
                       "since %s was made (size or modification time); make "
                       "the plan again", p->dem, p->path);
  else
    ok = true;
  free(real);
  if (!ok)
    return false;
  GDALDatasetH ds = GDALOpenEx(p->dem, GDAL_OF_RASTER | GDAL_OF_READONLY,
                               NULL, NULL, NULL);
  if (!ds) {
    tt__app_result_set(res, TT_APP_EXIT_FAILURE, TT_ERR_IO, "%s: not a "
                       "raster GDAL can open", p->dem);
    return false;
  }
  /* the size of the window GDAL's input options read (dem_view.c) */
  GDALDatasetH view = NULL;
  if (tt__app_view_wanted(s)) {
    char why[TT_APP_MESSAGE_MAX], warn[TT_APP_MESSAGE_MAX];
    int usage = 0;
    char **args = tt__app_view_args(s, ds, &usage, why, sizeof why, warn,
                                    sizeof warn);
    if (args)
      view = tt__app_view_open(ds, args, why, sizeof why);
    CSLDestroy(args);
    if (!view) {
      GDALClose(ds);
      return REFUSE(res, TT_ERR_DATA, "%s: its options on its DEM %s: %s",
                    p->path, p->dem, why);
    }
  }
  GDALDatasetH seen = view ? view : ds;
  size_t W = (size_t)GDALGetRasterXSize(seen);
  size_t H = (size_t)GDALGetRasterYSize(seen);
  int nbands = GDALGetRasterCount(ds);
  if (view)
    GDALClose(view);
  GDALClose(ds);
  if (W != p->width || H != p->height)
    return REFUSE(res, TT_ERR_DATA, "%s: its \"width\" and \"height\" are "
                  "%zu x %zu, its DEM %s is %zu x %zu", p->path, p->width,
                  p->height, p->dem, W, H);
  if (band > nbands)
    return REFUSE(res, TT_ERR_ARG, "%s: its -b %d: the DEM has %d band(s)",
                  p->path, band, nbands);
  return true;
}

/* Byte for byte what the writer makes of the fields read. */
static bool check_text(const tiles_plan *p, const char *t, size_t len,
                       tt_app_result *res)
{
  size_t n = 0;
  char *want = tt__tiles_plan_text(p, &n);
  size_t at = 0;
  while (want && at < n && at < len && want[at] == t[at])
    at++;
  bool same = want && n == len && at == n;
  CPLFree(want);
  if (same)
    return true;
  size_t line = 1;
  for (size_t i = 0; i < at; i++)
    line += t[i] == '\n';
  return REFUSE(res, TT_ERR_DATA, "%s: line %zu is not what `terratin tiles "
                "plan` writes for its fields (edited?); make it again",
                p->path, line);
}

static bool ingest(const char *path, GByte **buf, vsi_l_offset *len,
                   tt_app_result *res)
{
  VSIStatBufL sb;
  bool file = VSIStatL(path, &sb) == 0 && VSI_ISREG(sb.st_mode);
  if (file && (vsi_l_offset)sb.st_size > TT_TILES_PLAN_MAX_BYTES)
    return REFUSE(res, TT_ERR_DATA, "%s: %llu bytes: a plan has at most %u",
                  path, (unsigned long long)sb.st_size,
                  (unsigned)TT_TILES_PLAN_MAX_BYTES);
  if (!file || !VSIIngestFile(NULL, path, buf, len, TT_TILES_PLAN_MAX_BYTES)) {
    tt__app_result_set(res, TT_APP_EXIT_FAILURE, TT_ERR_IO,
                       "%s: cannot read the plan", path);
    return false;
  }
  return true;
}

bool tt__tiles_plan_read(const char *path, tiles_plan *p, tt_app_result *res)
{
  memset(p, 0, sizeof *p);
  p->path = CPLStrdup(path);
  p->pieces = CPLStrdup(CPLSPrintf("%s.tiles", path));
  GByte *buf = NULL;
  vsi_l_offset len = 0;
  if (!ingest(path, &buf, &len, res))
    return false;
  const char *t = (const char *)buf;
  size_t n = (size_t)len;
  tt_app_options *o = NULL;
  bool ok = check_sum(path, t, n, res) && parse_plan(path, t, n, p, res) &&
            check_grid(path, p, res) &&
            tt__tiles_plan_check_words(path, p->options, res) &&
            check_line(p, &o, res) &&
            check_dem(p, tt_app_options_settings(o), res) &&
            check_text(p, t, n, res);
  tt_app_options_destroy(o);
  if (ok)
    p->hash = fnv1a(t, n);
  CPLFree(buf);
  return ok;
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
