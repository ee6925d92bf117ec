/*
 * terratin_lib.c -- the terratin command as a library (see terratin_lib.h):
 * the option parser and help texts, the phase-scaled progress and the text
 * progress bar, the GDAL error capture, a small JSON writer, and the three
 * subcommands simplify, generate and eval.
 *
 * Invariants: parsing touches nothing but the options object; a run reports
 * at most one failure (the first), as one line; every run either commits its
 * output or leaves nothing behind (tt_output_* removes temporary files); GDAL
 * never prints by itself while a run is active (a pushed CPL error handler
 * stores failures and turns warnings into "terratin: warning:" lines).
 *
 * Workload: parsing is a single pass over a few dozen words; a run is
 * dominated by the engine and the glue, the code here only sequences them.
 */
/* GDAL's VSIStatBufL is a struct stat64 on glibc: declare it. */
#define _LARGEFILE64_SOURCE 1

#include "terratin_lib.h"

#include "terratin/terratin_gdal.h"

#include <cpl_conv.h>
#include <cpl_error.h>
#include <cpl_string.h>
#include <cpl_vsi.h>
#include <gdal.h>
#include <ogr_api.h>
#include <ogr_srs_api.h>

#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>
#include <time.h>

#if defined(__GNUC__)
#define TT_APP_PRINTF_(a, b) __attribute__((format(printf, a, b)))
#else
#define TT_APP_PRINTF_(a, b)
#endif

/* ===========================================================================
 * Small helpers
 * ========================================================================= */

/* Seconds of a monotonic clock (the app's own; the engine keeps its own). */
static double app_now(void)
{
  struct timespec ts;
  if (clock_gettime(CLOCK_MONOTONIC, &ts) != 0)
    return 0.0;
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static void result_set(tt_app_result *res, int exit_code, tt_status status,
                       const char *fmt, ...) TT_APP_PRINTF_(4, 5);

/* Fills a result, keeping the first failure: later ones are consequences. */
static void result_set(tt_app_result *res, int exit_code, tt_status status,
                       const char *fmt, ...)
{
  if (!res || res->exit_code != TT_APP_EXIT_OK)
    return;
  res->exit_code = exit_code;
  res->status = status;
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(res->message, sizeof res->message, fmt, ap);
  va_end(ap);
  /* One line: fold any newline GDAL or a driver put into a message. */
  for (char *p = res->message; *p; p++)
    if (*p == '\n' || *p == '\r')
      *p = ' ';
}

static void result_ok(tt_app_result *res)
{
  if (!res)
    return;
  res->exit_code = TT_APP_EXIT_OK;
  res->status = TT_OK;
  res->message[0] = '\0';
}

static int str_ieq(const char *a, const char *b)
{
  return strcasecmp(a, b) == 0;
}

/* A NULL-terminated list of owned strings. */
typedef struct strlist {
  char **v;
  size_t n, cap;
} strlist;

static int strlist_add(strlist *l, const char *s)
{
  if (l->n + 2 > l->cap) {
    size_t cap = l->cap ? 2 * l->cap : 8;
    char **v = realloc(l->v, cap * sizeof *v);
    if (!v)
      return 0;
    l->v = v;
    l->cap = cap;
  }
  char *copy = malloc(strlen(s) + 1);
  if (!copy)
    return 0;
  strcpy(copy, s);
  l->v[l->n++] = copy;
  l->v[l->n] = NULL;
  return 1;
}

static void strlist_free(strlist *l)
{
  for (size_t i = 0; i < l->n; i++)
    free(l->v[i]);
  free(l->v);
  l->v = NULL;
  l->n = l->cap = 0;
}

/* ===========================================================================
 * The options object
 * ========================================================================= */

struct tt_app_options {
  tt_app_settings s;     /* the public view; strings point into the lists */
  strlist strings;       /* every single string (input, output, -of, ...) */
  strlist config, lco, dsco;
  tt_progress_fn progress;
  void *progress_arg;
  FILE *out, *err;
};

static const char *const empty_list[] = {NULL};

void tt_app_options_destroy(tt_app_options *o)
{
  if (!o)
    return;
  strlist_free(&o->strings);
  strlist_free(&o->config);
  strlist_free(&o->lco);
  strlist_free(&o->dsco);
  free(o);
}

const tt_app_settings *tt_app_options_settings(const tt_app_options *o)
{
  return o ? &o->s : NULL;
}

void tt_app_options_set_progress(tt_app_options *o, tt_progress_fn fn,
                                 void *arg)
{
  if (!o)
    return;
  o->progress = fn;
  o->progress_arg = arg;
}

void tt_app_options_set_streams(tt_app_options *o, FILE *out, FILE *err)
{
  if (!o)
    return;
  o->out = out ? out : stdout;
  o->err = err ? err : stderr;
}

int tt_app_options_wants_progress_bar(const tt_app_options *o)
{
  return o && o->s.command == TT_APP_SIMPLIFY && !o->s.quiet && !o->s.json;
}

/* ===========================================================================
 * Help texts
 * ========================================================================= */

static const char help_top[] =
    "Usage: terratin COMMAND [options] ARGUMENTS...\n"
    "       terratin --help | --version\n"
    "\n"
    "Turns a DEM into a TIN (triangulated irregular network) whose vertices\n"
    "are grid samples, and measures triangle layers against DEMs.\n"
    "\n"
    "Commands:\n"
    "  simplify   DEM -> TIN layers (GeoPackage, Shapefile, other formats)\n"
    "  generate   write a synthetic test terrain as a GeoTIFF\n"
    "  eval       measure the error of a triangle layer against a DEM\n"
    "\n"
    "Options of every command:\n"
    "  --help              this help, or the help of COMMAND\n"
    "  --version           terratin, GDAL and PROJ versions\n"
    "  --config KEY VALUE  set a GDAL configuration option before anything is\n"
    "                      opened (repeatable; KEY=VALUE also accepted)\n"
    "  --debug on|off      GDAL debug messages on stderr (CPL_DEBUG)\n"
    "\n"
    "Exit codes:\n"
    "  0  success\n"
    "  1  processing failure: bad input, I/O error, refused output,\n"
    "     interruption (nothing is left behind)\n"
    "  2  usage error: unknown option, bad value, missing argument\n"
    "  3  eval: the measured max error exceeds -max_error\n"
    "\n"
    "Run 'terratin COMMAND --help' for the options of a command.\n";

static const char help_simplify[] =
    "Usage: terratin simplify [-b BAND] [-max_error E] [-max_points N]\n"
    "           [-max_triangles N] [-percent P] [-criterion NAME]\n"
    "           [-repair flip|local|lookahead|delaunay]\n"
    "           [-optimize local|lookahead|none]\n"
    "           [-srcnodata VALUE] [-z_factor F] [-z_unit m]\n"
    "           [-work_srs SRS] [-t_srs SRS]\n"
    "           [-of FORMAT] [-dsco NAME=VALUE]... [-lco NAME=VALUE]...\n"
    "           [-nln PREFIX] [-overwrite] [-q] [-json]\n"
    "           [--config KEY VALUE]... INPUT OUTPUT\n"
    "\n"
    "Simplifies band BAND of the raster INPUT into a TIN whose vertices are\n"
    "grid samples (greedy insertion) and writes the vector dataset OUTPUT\n"
    "with three layers: PREFIXtriangles (POLYGON Z), PREFIXvertices\n"
    "(POINT Z) and PREFIXrun_parameters (one row: limits, results, timing).\n"
    "\n"
    "Stop conditions (they combine: the first one reached wins):\n"
    "  -max_error E      stop when every valid sample is within E of the TIN\n"
    "                    (z units of the DEM, E >= 0)\n"
    "  -max_points N     at most N vertices (N >= 1)\n"
    "  -max_triangles N  at most N triangles (N >= 1)\n"
    "  -percent P        at most P% of the valid samples as vertices\n"
    "                    (0 < P <= 100)\n"
    "  Default when none is given: -max_error = 0.5% of the DEM's valid\n"
    "  height range (max - min), printed in the summary; a flat DEM gives\n"
    "  the two triangles of the corners.\n"
    "\n"
    "Options:\n"
    "  -b BAND           band of INPUT to read (default 1)\n"
    "  -srcnodata VALUE  height to treat as nodata, a number or nan\n"
    "                    (default: the band's nodata value and mask)\n"
    "  -z_factor F       multiply heights by F, e.g. 0.3048 for feet to\n"
    "                    metres (default 1; after the band's scale/offset)\n"
    "  -z_unit m         heights declared in ft or us-ft (band unit, else\n"
    "                    vertical CRS) converted to metres. Combined:\n"
    "                    z = (raw * scale + offset) * unit factor * F; with\n"
    "                    an unknown unit it needs -z_factor, which then is\n"
    "                    the whole conversion. Errors and -max_error are in\n"
    "                    the output z unit, which the summary names\n"
    "  -work_srs SRS     projected CRS in metres whose local affine frame\n"
    "                    measures angles, areas and the Delaunay test\n"
    "                    (default: the UTM zone of the DEM's centre for\n"
    "                    geographic DEMs and map units that are not ground\n"
    "                    metres, e.g. Web Mercator, feet; else the DEM's own\n"
    "                    grid). Heights and output coordinates are unchanged\n"
    "  -t_srs SRS        write the layers in SRS (vertices reprojected with\n"
    "                    PROJ, triangles unchanged; default: the DEM's CRS).\n"
    "                    A geographic output gets geodesic triangle areas\n"
    "  -criterion NAME   triangulation criterion (docs/criteria.md):\n"
    "                    delaunay (default), minmax_angle, minmax_angle_lex,\n"
    "                    min_area, mean_curvature, gaussian_curvature, abn,\n"
    "                    abn_sum, abn_sumsq, l2\n"
    "  -repair MODE      how the criterion is restored around each new\n"
    "                    vertex: flip (Lawson flips outward from it; the\n"
    "                    default), local, lookahead (swaps over the region\n"
    "                    around it), delaunay (Delaunay while inserting,\n"
    "                    the criterion in the final pass only; the default\n"
    "                    for l2). Except with delaunay, min_area first\n"
    "                    re-triangulates the hole around it exactly\n"
    "  -optimize MODE    final swap pass over the whole mesh: local,\n"
    "                    lookahead or none (default: local after -repair\n"
    "                    delaunay with another criterion, else none); it\n"
    "                    never lifts an error past the bound\n"
    "  -of FORMAT        OGR vector driver that can create datasets: GPKG,\n"
    "                    \"ESRI Shapefile\", ... (default: guessed from\n"
    "                    OUTPUT's extension, else GPKG)\n"
    "  -dsco NAME=VALUE  dataset creation option (repeatable)\n"
    "  -lco NAME=VALUE   layer creation option, for every layer (repeatable)\n"
    "  -nln PREFIX       prefix of the three layer names (default: none)\n"
    "  -overwrite        replace OUTPUT when it exists (default: refuse)\n"
    "  -q                quiet: no progress bar, no summary line\n"
    "  -json             print one JSON object with the results instead of\n"
    "                    the progress bar and the summary line\n"
    "\n"
    "A shapefile OUTPUT dir/name (or dir/name.shp) makes the files\n"
    "dir/name_triangles.shp, dir/name_vertices.shp and\n"
    "dir/name_run_parameters.dbf (with their .shx, .dbf, .prj, .cpg).\n"
    "\n"
    "OUTPUT is written under a temporary name and renamed when complete: a\n"
    "failure or an interruption leaves nothing behind. Progress goes to\n"
    "stdout, warnings and errors to stderr.\n"
    "\n"
    "Exit codes: 0 success, 1 processing failure, 2 usage error.\n"
    "\n"
    "Example:\n"
    "  terratin simplify -max_error 0.5 dem.tif tin.gpkg\n";

static const char help_generate[] =
    "Usage: terratin generate TYPE OUTPUT [-size N|NXxNY] [-seed S]\n"
    "           [-iterations N] [-displacement D] [-wave_size W]\n"
    "           [-roughness R] [-amplitude A]\n"
    "           [-seeding none|peak|valley|hybrid] [-a_srs SRS]\n"
    "           [-overwrite] [-q]\n"
    "\n"
    "Writes a synthetic, seeded, bit-reproducible terrain as a single-band\n"
    "Float32 GeoTIFF.\n"
    "\n"
    "TYPE:\n"
    "  fault            fault lines; a step (rough) or, with -wave_size > 0,\n"
    "                   a cosine ramp (smooth). Default 100x100,\n"
    "                   displacement 100\n"
    "  diamond_square   midpoint displacement on a (2^n+1)x(2^n+1) grid.\n"
    "                   Default 257x257, roughness 0.7\n"
    "  sphere           a half sphere of radius 20 on [0,40]^2 (41x41)\n"
    "  cylinder         a cylinder of height 60, radius 20 (a cliff; 41x41)\n"
    "  bump             exp(-81/4 ((x-.5)^2+(y-.5)^2)) on [0,1]^2 (20x30)\n"
    "\n"
    "Options:\n"
    "  -size N|NXxNY     grid size in samples (each side >= 2)\n"
    "  -seed S           random seed, an unsigned integer (all types)\n"
    "  -iterations N     fault: number of fault lines (N >= 1)\n"
    "  -displacement D   fault: height step per fault line (D >= 0)\n"
    "  -wave_size W      fault: cosine ramp half-width in cells; 0 = step\n"
    "  -roughness R      diamond_square: amplitude factor per level (R > 0)\n"
    "  -amplitude A      diamond_square: first-level amplitude (A >= 0)\n"
    "  -seeding MODE     diamond_square: none, peak, valley or hybrid\n"
    "  -a_srs SRS        CRS to assign (EPSG:n, WKT, PROJ string, ...)\n"
    "  -overwrite        replace OUTPUT when it exists (default: refuse)\n"
    "  -q                quiet: no summary line\n"
    "\n"
    "Exit codes: 0 success, 1 processing failure, 2 usage error.\n"
    "\n"
    "Example:\n"
    "  terratin generate fault fault.tif -size 200 -seed 7\n";

static const char help_eval[] =
    "Usage: terratin eval DEM TIN [-b BAND] [-layer NAME] [-max_error E]\n"
    "           [-srcnodata VALUE] [-z_factor F] [-z_unit m] [-json] [-q]\n"
    "\n"
    "Measures a layer of triangles (POLYGON Z, MULTIPOLYGON Z or TIN, from\n"
    "terratin or any other tool) against band BAND of the raster DEM: the\n"
    "error |DEM - TIN| over every valid sample (max, RMS, mean and total\n"
    "absolute, L2, where the max is) and the coverage (valid samples covered,\n"
    "uncovered, overlapped; polygons that are not triangles, degenerate\n"
    "triangles). The triangles must be in the DEM's CRS.\n"
    "\n"
    "Options:\n"
    "  -b BAND         band of DEM to read (default 1)\n"
    "  -srcnodata V    height to treat as nodata, a number or nan\n"
    "  -z_factor F     multiply heights by F (as given to simplify)\n"
    "  -z_unit m       ft or us-ft heights to metres (as given to simplify)\n"
    "  -layer NAME     layer to measure (default: a layer named 'triangles'\n"
    "                  or ending in '_triangles', else the first polygon\n"
    "                  layer)\n"
    "  -max_error E    check: exit with code 3 when the measured max error\n"
    "                  exceeds E (E >= 0)\n"
    "  -json           print one JSON object instead of text\n"
    "  -q              print nothing on success (for scripts with -max_error)\n"
    "\n"
    "Exit codes: 0 success (and within -max_error), 1 processing failure,\n"
    "2 usage error, 3 the measured max error exceeds -max_error.\n"
    "\n"
    "Example:\n"
    "  terratin eval dem.tif tin.gpkg -max_error 0.5 -q || echo too coarse\n";

const char *tt_app_help(tt_app_command topic)
{
  switch (topic) {
  case TT_APP_SIMPLIFY: return help_simplify;
  case TT_APP_GENERATE: return help_generate;
  case TT_APP_EVAL: return help_eval;
  default: return help_top;
  }
}

static const char *command_name(tt_app_command c)
{
  switch (c) {
  case TT_APP_SIMPLIFY: return "simplify";
  case TT_APP_GENERATE: return "generate";
  case TT_APP_EVAL: return "eval";
  default: return "";
  }
}

/* ===========================================================================
 * Parsing
 * ========================================================================= */

/* A finite double, the whole word. */
static int parse_double(const char *w, double *out)
{
  char *end = NULL;
  if (!*w || strchr(" \t\n", w[0]))
    return 0;
  errno = 0;
  double d = strtod(w, &end);
  if (end == w || *end != '\0' || errno == ERANGE || !isfinite(d))
    return 0;
  *out = d;
  return 1;
}

/* An unsigned decimal integer, the whole word, no sign, no overflow. */
static int parse_u64(const char *w, uint64_t *out)
{
  uint64_t v = 0;
  if (!*w)
    return 0;
  for (const char *p = w; *p; p++) {
    if (*p < '0' || *p > '9')
      return 0;
    unsigned d = (unsigned)(*p - '0');
    if (v > (UINT64_MAX - d) / 10)
      return 0;
    v = v * 10 + d;
  }
  *out = v;
  return 1;
}

static int parse_size(const char *w, size_t *out)
{
  uint64_t v;
  if (!parse_u64(w, &v) || v > (uint64_t)SIZE_MAX)
    return 0;
  *out = (size_t)v;
  return 1;
}

/* Which option applies to which command: one table, so the parser, the
 * error messages and the tests agree. */
enum opt_id {
  O_B, O_MAX_ERROR, O_MAX_POINTS, O_MAX_TRIANGLES, O_PERCENT, O_OF, O_LCO,
  O_DSCO, O_NLN, O_OVERWRITE, O_Q, O_CRITERION, O_OPTIMIZE, O_REPAIR, O_JSON, O_LAYER, O_SIZE,
  O_SEED, O_ITERATIONS, O_DISPLACEMENT, O_WAVE_SIZE, O_ROUGHNESS,
  O_AMPLITUDE, O_SEEDING, O_A_SRS, O_SRCNODATA, O_Z_FACTOR, O_Z_UNIT,
  O_WORK_SRS, O_T_SRS
};

#define FOR_S (1u << TT_APP_SIMPLIFY)
#define FOR_G (1u << TT_APP_GENERATE)
#define FOR_E (1u << TT_APP_EVAL)

static const struct opt_def {
  const char *name;
  enum opt_id id;
  int takes_value;
  unsigned commands;
} opt_defs[] = {
    {"-b", O_B, 1, FOR_S | FOR_E},
    {"-max_error", O_MAX_ERROR, 1, FOR_S | FOR_E},
    {"-max_points", O_MAX_POINTS, 1, FOR_S},
    {"-max_triangles", O_MAX_TRIANGLES, 1, FOR_S},
    {"-percent", O_PERCENT, 1, FOR_S},
    {"-of", O_OF, 1, FOR_S},
    {"-f", O_OF, 1, FOR_S}, /* ogr2ogr's spelling */
    {"-lco", O_LCO, 1, FOR_S},
    {"-dsco", O_DSCO, 1, FOR_S},
    {"-nln", O_NLN, 1, FOR_S},
    {"-overwrite", O_OVERWRITE, 0, FOR_S | FOR_G},
    {"-q", O_Q, 0, FOR_S | FOR_G | FOR_E},
    {"-quiet", O_Q, 0, FOR_S | FOR_G | FOR_E},
    {"-criterion", O_CRITERION, 1, FOR_S},
    {"-optimize", O_OPTIMIZE, 1, FOR_S},
    {"-repair", O_REPAIR, 1, FOR_S},
    {"-json", O_JSON, 0, FOR_S | FOR_E},
    {"-layer", O_LAYER, 1, FOR_E},
    {"-size", O_SIZE, 1, FOR_G},
    {"-seed", O_SEED, 1, FOR_G},
    {"-iterations", O_ITERATIONS, 1, FOR_G},
    {"-displacement", O_DISPLACEMENT, 1, FOR_G},
    {"-wave_size", O_WAVE_SIZE, 1, FOR_G},
    {"-roughness", O_ROUGHNESS, 1, FOR_G},
    {"-amplitude", O_AMPLITUDE, 1, FOR_G},
    {"-seeding", O_SEEDING, 1, FOR_G},
    {"-a_srs", O_A_SRS, 1, FOR_G},
    {"-srcnodata", O_SRCNODATA, 1, FOR_S | FOR_E},
    {"-z_factor", O_Z_FACTOR, 1, FOR_S | FOR_E},
    {"-z_unit", O_Z_UNIT, 1, FOR_S | FOR_E},
    {"-work_srs", O_WORK_SRS, 1, FOR_S},
    {"-t_srs", O_T_SRS, 1, FOR_S},
};

static const struct opt_def *find_opt(const char *w)
{
  for (size_t i = 0; i < sizeof opt_defs / sizeof opt_defs[0]; i++)
    if (str_ieq(w, opt_defs[i].name))
      return &opt_defs[i];
  /* GDAL accepts --of as well as -of for its own options: do the same. */
  if (w[0] == '-' && w[1] == '-' && w[2] != '\0')
    return find_opt(w + 1);
  return NULL;
}

/* What generate was told, applied after tt_synth_options_init(kind). */
typedef struct synth_flags {
  int size, seed, iterations, displacement, wave_size, roughness, amplitude,
      seeding;
  size_t nx, ny;
  uint64_t seed_value;
  size_t iterations_value;
  double displacement_value, wave_size_value, roughness_value,
      amplitude_value;
  tt_synth_seeding seeding_value;
} synth_flags;

static int parse_grid_size(const char *w, size_t *nx, size_t *ny)
{
  const char *x = strpbrk(w, "xX");
  char buf[64];
  if (strlen(w) >= sizeof buf)
    return 0;
  if (!x)
    return parse_size(w, nx) && (*ny = *nx, 1);
  memcpy(buf, w, (size_t)(x - w));
  buf[x - w] = '\0';
  return parse_size(buf, nx) && parse_size(x + 1, ny);
}

static int is_pow2_plus1(size_t n)
{
  size_t m = n - 1;
  return n >= 3 && (m & (m - 1)) == 0;
}

#define USAGE(...)                                                           \
  do {                                                                       \
    result_set(res, TT_APP_EXIT_USAGE, TT_ERR_ARG, __VA_ARGS__);             \
    st = TT_ERR_ARG;                                                         \
    goto done;                                                               \
  } while (0)

#define NOMEM()                                                              \
  do {                                                                       \
    result_set(res, TT_APP_EXIT_FAILURE, TT_ERR_NOMEM, "out of memory");     \
    st = TT_ERR_NOMEM;                                                       \
    goto done;                                                               \
  } while (0)

static int is_help_word(const char *w)
{
  return str_ieq(w, "--help") || str_ieq(w, "-help") || str_ieq(w, "-h") ||
         str_ieq(w, "-?");
}

static const char *keep(tt_app_options *o, const char *w)
{
  if (!strlist_add(&o->strings, w))
    return NULL;
  return o->strings.v[o->strings.n - 1];
}

tt_status tt_app_options_new(char **argv, tt_app_options **out_options,
                             tt_app_result *out_result)
{
  tt_app_result local;
  tt_app_result *res = out_result ? out_result : &local;
  tt_status st = TT_OK;
  tt_context *ctx = NULL;
  const char *pos[3] = {NULL, NULL, NULL};
  size_t npos = 0;
  synth_flags sf;
  const char *cmdname = "";
  char hint[64] = "";
  memset(&sf, 0, sizeof sf);
  result_ok(res);
  if (out_options)
    *out_options = NULL;

  tt_app_options *o = calloc(1, sizeof *o);
  if (!o || !(ctx = tt_context_create()))
    NOMEM();
  o->out = stdout;
  o->err = stderr;
  o->s.command = TT_APP_NONE;
  o->s.band = 1;
  o->s.z_factor = 1.0;
  o->s.max_error = -1.0;
  o->s.criterion = TT_CRITERION_DELAUNAY;
  o->s.nln = "";
  o->s.config = empty_list;
  o->s.lco = empty_list;
  o->s.dsco = empty_list;

  if (!argv)
    argv = (char **)empty_list;

  /* --help and --version win over anything else on the line, even over an
   * error earlier in it, as in GDAL's utilities: a user who asks for help
   * gets it. The command word, if any, picks the help page. */
  int want_help = 0, want_version = 0;
  tt_app_command first_cmd = TT_APP_NONE;
  for (size_t i = 0; argv[i]; i++) {
    const char *w = argv[i];
    if (is_help_word(w))
      want_help = 1;
    else if (str_ieq(w, "--version"))
      want_version = 1;
    else if (first_cmd == TT_APP_NONE && w[0] != '-') {
      if (str_ieq(w, "simplify")) first_cmd = TT_APP_SIMPLIFY;
      else if (str_ieq(w, "generate")) first_cmd = TT_APP_GENERATE;
      else if (str_ieq(w, "eval")) first_cmd = TT_APP_EVAL;
      else if (str_ieq(w, "help")) { want_help = 1; continue; }
      if (first_cmd == TT_APP_NONE)
        break; /* an unknown command: reported below */
    }
    /* skip the values of the global options */
    if (str_ieq(w, "--config")) {
      size_t skip = (argv[i + 1] && strchr(argv[i + 1], '=')) ? 1 : 2;
      for (size_t k = 0; k < skip && argv[i + 1]; k++)
        i++;
    } else if (str_ieq(w, "--debug") && argv[i + 1]) {
      i++;
    }
  }
  if (want_help) {
    o->s.command = TT_APP_HELP;
    o->s.help_topic = first_cmd;
    goto done;
  }
  if (want_version) {
    o->s.command = TT_APP_VERSION;
    goto done;
  }

  for (size_t i = 0; argv[i]; i++) {
    const char *w = argv[i];
    const char *v = NULL;

    /* Global options, before or after the command word. */
    if (str_ieq(w, "--config")) {
      const char *k = argv[i + 1];
      if (!k)
        USAGE("--config needs KEY VALUE");
      const char *eq = strchr(k, '=');
      if (eq == k)
        USAGE("--config: empty KEY in '%s'", k);
      if (eq) {
        /* --config KEY=VALUE (GDAL >= 3.9 accepts it too) */
        char *key = malloc((size_t)(eq - k) + 1);
        if (!key)
          NOMEM();
        memcpy(key, k, (size_t)(eq - k));
        key[eq - k] = '\0';
        int ok = strlist_add(&o->config, key) &&
                 strlist_add(&o->config, eq + 1);
        free(key);
        if (!ok)
          NOMEM();
        i += 1;
      } else {
        if (!argv[i + 2])
          USAGE("--config %s needs a VALUE", k);
        if (!*k)
          USAGE("--config needs a non-empty KEY");
        if (!strlist_add(&o->config, k) ||
            !strlist_add(&o->config, argv[i + 2]))
          NOMEM();
        i += 2;
      }
      continue;
    }
    if (str_ieq(w, "--debug")) {
      if (!argv[i + 1])
        USAGE("--debug needs a value: on or off");
      if (!strlist_add(&o->config, "CPL_DEBUG") ||
          !strlist_add(&o->config, argv[i + 1]))
        NOMEM();
      i += 1;
      continue;
    }

    if (o->s.command == TT_APP_NONE) {
      if (w[0] == '-' && w[1] != '\0')
        USAGE("unknown option '%s' before the command; expected simplify, "
              "generate or eval (see 'terratin --help')", w);
      if (str_ieq(w, "simplify")) o->s.command = TT_APP_SIMPLIFY;
      else if (str_ieq(w, "generate")) o->s.command = TT_APP_GENERATE;
      else if (str_ieq(w, "eval")) o->s.command = TT_APP_EVAL;
      else
        USAGE("unknown command '%s'; expected simplify, generate or eval "
              "(see 'terratin --help')", w);
      cmdname = command_name(o->s.command);
      snprintf(hint, sizeof hint, " (see 'terratin %s --help')", cmdname);
      continue;
    }

    /* "-" alone and negative numbers are positional words. */
    const struct opt_def *d = NULL;
    double dummy;
    if (w[0] == '-' && w[1] != '\0' && !parse_double(w, &dummy)) {
      d = find_opt(w);
      if (!d)
        USAGE("%s: unknown option '%s'%s", cmdname, w, hint);
      if (!(d->commands & (1u << o->s.command)))
        USAGE("%s: option %s does not apply to this command%s", cmdname,
              d->name, hint);
      if (d->takes_value) {
        v = argv[i + 1];
        if (!v)
          USAGE("%s: option %s needs a value%s", cmdname, d->name, hint);
        i++;
      }
    } else {
      if (npos >= 2)
        USAGE("%s: unexpected argument '%s'%s", cmdname, w, hint);
      pos[npos++] = w;
      continue;
    }

    size_t z;
    double x;
    uint64_t u;
    switch (d->id) {
    case O_B:
      if (!parse_size(v, &z) || z < 1 || z > INT_MAX)
        USAGE("%s: -b must be a band number >= 1, got '%s'", cmdname, v);
      o->s.band = (int)z;
      break;
    case O_MAX_ERROR:
      if (!parse_double(v, &x) || x < 0)
        USAGE("%s: -max_error must be a finite number >= 0 (z units), got "
              "'%s'", cmdname, v);
      o->s.max_error = x + 0.0; /* -0 reads as "no limit" to the engine */
      break;
    case O_MAX_POINTS:
      if (!parse_size(v, &z) || z < 1)
        USAGE("%s: -max_points must be an integer >= 1, got '%s'", cmdname,
              v);
      if (z > TT_MAX_VERTICES)
        USAGE("%s: -max_points %s is above the limit of %zu vertices",
              cmdname, v, (size_t)TT_MAX_VERTICES);
      o->s.max_points = z;
      break;
    case O_MAX_TRIANGLES:
      if (!parse_size(v, &z) || z < 1)
        USAGE("%s: -max_triangles must be an integer >= 1, got '%s'",
              cmdname, v);
      if (z > 2 * TT_MAX_VERTICES)
        USAGE("%s: -max_triangles %s is above the limit of %zu triangles "
              "(twice the %zu vertices a TIN may have)", cmdname, v,
              2 * (size_t)TT_MAX_VERTICES, (size_t)TT_MAX_VERTICES);
      o->s.max_triangles = z;
      break;
    case O_PERCENT:
      if (!parse_double(v, &x) || !(x > 0 && x <= 100))
        USAGE("%s: -percent must be in (0, 100], got '%s'", cmdname, v);
      o->s.percent = x;
      break;
    case O_OF:
      if (!*v)
        USAGE("%s: -of needs a driver name%s", cmdname, hint);
      if (!(o->s.format = keep(o, v)))
        NOMEM();
      break;
    case O_LCO:
    case O_DSCO: {
      const char *eq = strchr(v, '=');
      if (!eq || eq == v)
        USAGE("%s: %s expects NAME=VALUE, got '%s'", cmdname,
              d->id == O_LCO ? "-lco" : "-dsco", v);
      if (!strlist_add(d->id == O_LCO ? &o->lco : &o->dsco, v))
        NOMEM();
      break;
    }
    case O_NLN:
      if (!(o->s.nln = keep(o, v)))
        NOMEM();
      break;
    case O_OVERWRITE: o->s.overwrite = 1; break;
    case O_Q: o->s.quiet = 1; break;
    case O_JSON: o->s.json = 1; break;
    case O_CRITERION: {
      tt_criterion c;
      if (tt_criterion_parse(ctx, v, &c) != TT_OK) {
        /* The engine's list, so new criteria show up here by themselves. */
        char known[256] = "";
        size_t n = 0;
        for (int k = 0; k < 64 && n < sizeof known; k++) {
          const char *name = tt_criterion_name((tt_criterion)k);
          if (!name)
            break;
          n += (size_t)snprintf(known + n, sizeof known - n, "%s%s",
                                k ? ", " : "", name);
        }
        USAGE("%s: unknown -criterion '%s'; known: %s", cmdname, v, known);
      }
      o->s.criterion = c;
      break;
    }
    case O_OPTIMIZE:
      if (tt_optimize_parse(ctx, v, &o->s.optimize) != TT_OK)
        USAGE("%s: unknown -optimize '%s'; known: local, lookahead, none, "
              "auto", cmdname, v);
      break;
    case O_REPAIR:
      if (tt_repair_parse(ctx, v, &o->s.repair) != TT_OK)
        USAGE("%s: unknown -repair '%s'; known: flip, local, lookahead, "
              "delaunay, auto", cmdname, v);
      break;
    case O_LAYER:
      if (!*v)
        USAGE("%s: -layer needs a layer name", cmdname);
      if (!(o->s.layer = keep(o, v)))
        NOMEM();
      break;
    case O_SIZE:
      if (!parse_grid_size(v, &sf.nx, &sf.ny) || sf.nx < 2 || sf.ny < 2 ||
          sf.nx > TT_MAX_GRID_SIDE || sf.ny > TT_MAX_GRID_SIDE)
        USAGE("%s: -size must be N or NXxNY with sides >= 2, got '%s'",
              cmdname, v);
      if (sf.nx > SIZE_MAX / sf.ny ||
          sf.nx * sf.ny > (size_t)1 << 31)
        USAGE("%s: -size '%s' is too large (at most 2^31 samples)", cmdname,
              v);
      sf.size = 1;
      break;
    case O_SEED:
      if (!parse_u64(v, &u))
        USAGE("%s: -seed must be an unsigned integer, got '%s'", cmdname, v);
      sf.seed = 1;
      sf.seed_value = u;
      break;
    case O_ITERATIONS:
      if (!parse_size(v, &z) || z < 1)
        USAGE("%s: -iterations must be an integer >= 1, got '%s'", cmdname,
              v);
      sf.iterations = 1;
      sf.iterations_value = z;
      break;
    case O_DISPLACEMENT:
      if (!parse_double(v, &x) || x < 0)
        USAGE("%s: -displacement must be a finite number >= 0, got '%s'",
              cmdname, v);
      sf.displacement = 1;
      sf.displacement_value = x;
      break;
    case O_WAVE_SIZE:
      if (!parse_double(v, &x) || x < 0)
        USAGE("%s: -wave_size must be a finite number >= 0, got '%s'",
              cmdname, v);
      sf.wave_size = 1;
      sf.wave_size_value = x;
      break;
    case O_ROUGHNESS:
      if (!parse_double(v, &x) || x <= 0)
        USAGE("%s: -roughness must be a finite number > 0, got '%s'",
              cmdname, v);
      sf.roughness = 1;
      sf.roughness_value = x;
      break;
    case O_AMPLITUDE:
      if (!parse_double(v, &x) || x < 0)
        USAGE("%s: -amplitude must be a finite number >= 0, got '%s'",
              cmdname, v);
      sf.amplitude = 1;
      sf.amplitude_value = x;
      break;
    case O_SEEDING:
      sf.seeding = 1;
      if (str_ieq(v, "none")) sf.seeding_value = TT_SEED_NONE;
      else if (str_ieq(v, "peak")) sf.seeding_value = TT_SEED_PEAK;
      else if (str_ieq(v, "valley")) sf.seeding_value = TT_SEED_VALLEY;
      else if (str_ieq(v, "hybrid")) sf.seeding_value = TT_SEED_HYBRID;
      else
        USAGE("%s: -seeding must be none, peak, valley or hybrid, got '%s'",
              cmdname, v);
      break;
    case O_SRCNODATA:
      if (!str_ieq(v, "nan") && !parse_double(v, &x))
        USAGE("%s: -srcnodata must be a number or nan, got '%s'", cmdname,
              v);
      if (!(o->s.srcnodata = keep(o, v)))
        NOMEM();
      break;
    case O_Z_FACTOR:
      if (!parse_double(v, &x) || x == 0)
        USAGE("%s: -z_factor must be a finite non-zero number, got '%s'",
              cmdname, v);
      o->s.z_factor = x;
      o->s.z_factor_set = 1;
      break;
    case O_Z_UNIT:
      if (!str_ieq(v, "m"))
        USAGE("%s: -z_unit must be m (heights in ft or us-ft converted to "
              "metres), got '%s'", cmdname, v);
      o->s.z_unit = "m";
      break;
    case O_WORK_SRS:
    case O_T_SRS:
      if (!*v)
        USAGE("%s: %s needs a CRS (EPSG:n, WKT, ...)", cmdname, d->name);
      if (!(*(d->id == O_WORK_SRS ? &o->s.work_srs : &o->s.t_srs) =
                keep(o, v)))
        NOMEM();
      break;
    case O_A_SRS:
      if (!*v)
        USAGE("%s: -a_srs needs a CRS (EPSG:n, WKT, ...)", cmdname);
      if (!(o->s.srs = keep(o, v)))
        NOMEM();
      break;
    }
  }

  switch (o->s.command) {
  case TT_APP_NONE:
    USAGE("missing command: simplify, generate or eval (see 'terratin "
          "--help')");
  case TT_APP_SIMPLIFY:
    if (npos < 1)
      USAGE("simplify: missing INPUT and OUTPUT%s", hint);
    if (npos < 2)
      USAGE("simplify: missing OUTPUT after '%s'%s", pos[0], hint);
    if (!(o->s.input = keep(o, pos[0])) || !(o->s.output = keep(o, pos[1])))
      NOMEM();
    break;
  case TT_APP_EVAL:
    if (npos < 1)
      USAGE("eval: missing DEM and TIN%s", hint);
    if (npos < 2)
      USAGE("eval: missing TIN after '%s'%s", pos[0], hint);
    if (!(o->s.input = keep(o, pos[0])) || !(o->s.tin = keep(o, pos[1])))
      NOMEM();
    break;
  case TT_APP_GENERATE: {
    tt_synth_kind kind;
    if (npos < 1)
      USAGE("generate: missing TYPE and OUTPUT%s", hint);
    if (tt_synth_kind_parse(ctx, pos[0], &kind) != TT_OK)
      USAGE("generate: unknown TYPE '%s'; expected fault, diamond_square, "
            "sphere, cylinder or bump", pos[0]);
    if (npos < 2)
      USAGE("generate: missing OUTPUT after '%s'%s", pos[0], hint);
    if (!(o->s.output = keep(o, pos[1])))
      NOMEM();
    const char *kname = tt_synth_kind_name(kind);
    if (!kname)
      kname = pos[0];
    if (kind != TT_SYNTH_FAULT &&
        (sf.iterations || sf.displacement || sf.wave_size))
      USAGE("generate: -%s applies to fault terrains only, not %s",
            sf.iterations ? "iterations"
                          : sf.displacement ? "displacement" : "wave_size",
            kname);
    if (kind != TT_SYNTH_DIAMOND_SQUARE &&
        (sf.roughness || sf.amplitude || sf.seeding))
      USAGE("generate: -%s applies to diamond_square terrains only, not %s",
            sf.roughness ? "roughness"
                         : sf.amplitude ? "amplitude" : "seeding",
            kname);
    tt_synth_options_init(&o->s.synth, kind);
    if (sf.size) {
      o->s.synth.nx = sf.nx;
      o->s.synth.ny = sf.ny;
    }
    if (kind == TT_SYNTH_DIAMOND_SQUARE &&
        (o->s.synth.nx != o->s.synth.ny || !is_pow2_plus1(o->s.synth.nx)))
      USAGE("generate: diamond_square needs a square size 2^n+1 (e.g. 129, "
            "257, 513), got %zux%zu", o->s.synth.nx, o->s.synth.ny);
    if (sf.seed) o->s.synth.seed = sf.seed_value;
    if (sf.iterations) o->s.synth.iterations = sf.iterations_value;
    if (sf.displacement) o->s.synth.displacement = sf.displacement_value;
    if (sf.wave_size) o->s.synth.wave_size = sf.wave_size_value;
    if (sf.roughness) o->s.synth.roughness = sf.roughness_value;
    if (sf.amplitude) o->s.synth.amplitude = sf.amplitude_value;
    if (sf.seeding) o->s.synth.seeding = sf.seeding_value;
    break;
  }
  default:
    break;
  }

done:
  if (o) {
    if (o->config.n)
      o->s.config = (const char *const *)o->config.v;
    if (o->lco.n)
      o->s.lco = (const char *const *)o->lco.v;
    if (o->dsco.n)
      o->s.dsco = (const char *const *)o->dsco.v;
  }
  tt_context_destroy(ctx);
  if (st != TT_OK) {
    tt_app_options_destroy(o);
    return st;
  }
  if (out_options)
    *out_options = o;
  else
    tt_app_options_destroy(o);
  return TT_OK;
}

/* ===========================================================================
 * Progress
 * ========================================================================= */

void tt_app_term_progress_init(tt_app_term_progress *bar, FILE *fp,
                               volatile sig_atomic_t *stop)
{
  bar->fp = fp;
  bar->ticks = -1;
  bar->stop = stop;
}

/* 41 ticks, one per 2.5%: tick 0 prints "0", every fourth prints the tens,
 * the others a dot, and tick 40 "100 - done." and the newline. */
int tt_app_term_progress_fn(double complete, const char *message, void *arg)
{
  tt_app_term_progress *bar = arg;
  (void)message;
  if (!bar)
    return 1;
  if (bar->fp) {
    if (!(complete >= 0)) /* also NaN */
      complete = 0;
    if (complete > 1)
      complete = 1;
    int target = (int)floor(complete * 40.0 + 1e-9);
    if (bar->ticks < target) {
      for (int t = bar->ticks + 1; t <= target; t++) {
        if (t % 4 == 0)
          fprintf(bar->fp, "%d", t / 4 * 10);
        else
          fputc('.', bar->fp);
      }
      if (target == 40)
        fputs(" - done.\n", bar->fp);
      bar->ticks = target;
      fflush(bar->fp);
    }
  }
  return !(bar->stop && *bar->stop);
}

/* Maps a phase's [0,1] onto [lo,hi] of the whole run and passes it on. */
typedef struct phase_progress {
  tt_progress_fn fn;
  void *arg;
  double lo, hi;
} phase_progress;

static int phase_fn(double complete, const char *message, void *arg)
{
  phase_progress *p = arg;
  if (!(complete >= 0))
    complete = 0;
  if (complete > 1)
    complete = 1;
  if (!p->fn)
    return 1;
  return p->fn(p->lo + (p->hi - p->lo) * complete, message, p->arg);
}

static void phase_set(phase_progress *p, double lo, double hi)
{
  p->lo = lo;
  p->hi = hi;
}

/* ===========================================================================
 * GDAL messages and engine warnings
 *
 * While a run is active a CPL error handler is pushed: failures are stored
 * (the run turns them into its one-line message, so the user never sees
 * GDAL's line and ours), warnings are printed as "terratin: warning: ..."
 * (at most MAX_WARNINGS, then one line saying the rest were dropped), debug
 * messages (only emitted with CPL_DEBUG on) pass through.
 * ========================================================================= */

#define MAX_WARNINGS 20

typedef struct app_messages {
  FILE *err;
  size_t warnings;           /* printed or dropped */
  unsigned failures;         /* GDAL failures seen */
  char last[TT_APP_MESSAGE_MAX];
} app_messages;

static void one_line(char *s)
{
  for (; *s; s++)
    if (*s == '\n' || *s == '\r')
      *s = ' ';
}

static void warn(app_messages *m, const char *fmt, ...) TT_APP_PRINTF_(2, 3);

static void warn(app_messages *m, const char *fmt, ...)
{
  char buf[TT_APP_MESSAGE_MAX];
  va_list ap;
  m->warnings++;
  if (m->warnings > MAX_WARNINGS + 1)
    return;
  if (m->warnings == MAX_WARNINGS + 1) {
    fprintf(m->err, "terratin: warning: further warnings are not shown\n");
    return;
  }
  va_start(ap, fmt);
  vsnprintf(buf, sizeof buf, fmt, ap);
  va_end(ap);
  one_line(buf);
  fprintf(m->err, "terratin: warning: %s\n", buf);
}

static void CPL_STDCALL on_gdal_message(CPLErr cls, CPLErrorNum num,
                                        const char *msg)
{
  app_messages *m = CPLGetErrorHandlerUserData();
  (void)num;
  if (!m || !msg)
    return;
  if (cls == CE_Debug) {
    fprintf(m->err, "terratin: debug: %s\n", msg);
  } else if (cls == CE_Warning) {
    warn(m, "%s", msg);
  } else if (cls != CE_None) {
    m->failures++;
    snprintf(m->last, sizeof m->last, "%s", msg);
    one_line(m->last);
  }
}

static void on_engine_warning(void *user, const char *message)
{
  warn(user, "%s", message);
}

/* ===========================================================================
 * JSON output: one object, strings escaped, non-finite numbers as null,
 * bytes that are not UTF-8 replaced by U+FFFD so the output always parses.
 * ========================================================================= */

typedef struct json_w {
  FILE *fp;
  int depth;
  int first[8];
} json_w;

/* Length of the valid UTF-8 sequence at s, 0 when invalid. */
static size_t utf8_len(const unsigned char *s)
{
  unsigned c = s[0];
  size_t n;
  unsigned min;
  if (c < 0x80)
    return 1;
  if (c >= 0xc2 && c <= 0xdf) { n = 2; min = 0x80; }
  else if (c >= 0xe0 && c <= 0xef) { n = 3; min = 0x800; }
  else if (c >= 0xf0 && c <= 0xf4) { n = 4; min = 0x10000; }
  else return 0;
  unsigned cp = c & (0x7f >> n);
  for (size_t i = 1; i < n; i++) {
    if ((s[i] & 0xc0) != 0x80)
      return 0;
    cp = (cp << 6) | (s[i] & 0x3f);
  }
  if (cp < min || cp > 0x10ffff || (cp >= 0xd800 && cp <= 0xdfff))
    return 0;
  return n;
}

static void json_string(FILE *fp, const char *s)
{
  const unsigned char *p = (const unsigned char *)(s ? s : "");
  fputc('"', fp);
  while (*p) {
    unsigned c = *p;
    if (c == '"' || c == '\\') {
      fputc('\\', fp);
      fputc((int)c, fp);
      p++;
    } else if (c < 0x20) {
      switch (c) {
      case '\n': fputs("\\n", fp); break;
      case '\r': fputs("\\r", fp); break;
      case '\t': fputs("\\t", fp); break;
      case '\b': fputs("\\b", fp); break;
      case '\f': fputs("\\f", fp); break;
      default: fprintf(fp, "\\u%04x", c); break;
      }
      p++;
    } else {
      size_t n = utf8_len(p);
      if (n == 0) {
        fputs("\\ufffd", fp);
        p++;
      } else {
        fwrite(p, 1, n, fp);
        p += n;
      }
    }
  }
  fputc('"', fp);
}

/* The shortest %g form that reads back to the same double. */
static void format_double(char *buf, size_t size, double d)
{
  for (int prec = 6; prec <= 17; prec++) {
    snprintf(buf, size, "%.*g", prec, d);
    if (strtod(buf, NULL) == d)
      return;
  }
}

static void json_number(FILE *fp, double d)
{
  char buf[40];
  if (!isfinite(d)) {
    fputs("null", fp);
    return;
  }
  format_double(buf, sizeof buf, d);
  fputs(buf, fp);
}

static void json_begin(json_w *j, FILE *fp)
{
  j->fp = fp;
  j->depth = 0;
  j->first[0] = 1;
  fputc('{', fp);
}

static void json_key(json_w *j, const char *key)
{
  if (!j->first[j->depth])
    fputc(',', j->fp);
  j->first[j->depth] = 0;
  fputs(j->depth ? " " : "\n  ", j->fp);
  json_string(j->fp, key);
  fputs(": ", j->fp);
}

static void json_open(json_w *j, const char *key)
{
  json_key(j, key);
  fputc('{', j->fp);
  if (j->depth + 1 < (int)(sizeof j->first / sizeof j->first[0]))
    j->depth++;
  j->first[j->depth] = 1;
}

static void json_close(json_w *j)
{
  fputs(j->depth ? "}" : "\n}\n", j->fp);
  if (j->depth > 0)
    j->depth--;
}

static void json_str(json_w *j, const char *key, const char *v)
{
  json_key(j, key);
  if (v)
    json_string(j->fp, v);
  else
    fputs("null", j->fp);
}

static void json_num(json_w *j, const char *key, double v)
{
  json_key(j, key);
  json_number(j->fp, v);
}

static void json_size(json_w *j, const char *key, size_t v)
{
  json_key(j, key);
  fprintf(j->fp, "%zu", v);
}

static void json_i64(json_w *j, const char *key, int64_t v)
{
  json_key(j, key);
  fprintf(j->fp, "%lld", (long long)v);
}

static void json_bool(json_w *j, const char *key, int v)
{
  json_key(j, key);
  fputs(v ? "true" : "false", j->fp);
}

static void json_null(json_w *j, const char *key)
{
  json_key(j, key);
  fputs("null", j->fp);
}

/* ===========================================================================
 * A run: what every subcommand shares
 * ========================================================================= */

typedef struct app_run {
  const tt_app_options *o;
  const tt_app_settings *s;
  tt_app_result *res;
  FILE *out, *err;
  tt_context *ctx;
  app_messages msg;
  phase_progress prog;
  double t0;
} app_run;

static tt_status run_fail(app_run *r, int exit_code, tt_status st,
                          const char *file, const char *fmt, ...)
    TT_APP_PRINTF_(5, 6);

/* Records the run's failure "<file>: <problem>" (or "<problem>"). */
static tt_status run_fail(app_run *r, int exit_code, tt_status st,
                          const char *file, const char *fmt, ...)
{
  char buf[TT_APP_MESSAGE_MAX];
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(buf, sizeof buf, fmt, ap);
  va_end(ap);
  if (file)
    result_set(r->res, exit_code, st, "%s: %s", file, buf);
  else
    result_set(r->res, exit_code, st, "%s", buf);
  return st;
}

/* The best one-line explanation of a failed engine or glue call: the
 * context's message, else GDAL's last failure, else the status's generic
 * message. A leading "<file>: " or "<file> " is dropped, the caller puts
 * the file first ("out.gpkg exists and is a folder" reads
 * "out.gpkg: exists and is a folder"). */
static const char *why(app_run *r, tt_status st, const char *file)
{
  const char *m = tt_context_errmsg(r->ctx);
  if (!m || !*m)
    m = r->msg.last;
  if (!m || !*m)
    m = tt_status_message(st);
  size_t n = file ? strlen(file) : 0;
  if (n && strncmp(m, file, n) == 0 && m[n] == ':' && m[n + 1] == ' ')
    m += n + 2;
  else if (n && strncmp(m, file, n) == 0 && m[n] == ' ' && m[n + 1])
    m += n + 1;
  return m;
}

/* Fails with the glue's or engine's message about file. */
static tt_status run_fail_tt(app_run *r, tt_status st, const char *file)
{
  if (st == TT_ERR_INTERRUPTED)
    return run_fail(r, TT_APP_EXIT_FAILURE, st, file,
                    "interrupted; nothing written");
  if (st == TT_ERR_NOMEM)
    return run_fail(r, TT_APP_EXIT_FAILURE, st, file, "out of memory");
  return run_fail(r, TT_APP_EXIT_FAILURE, st, file, "%s", why(r, st, file));
}

/* An output refused because something exists: name the file that is in
 * the way (for a shapefile, one of the layer files), and the way out. */
static tt_status run_fail_exists(app_run *r, const char *output)
{
  static const char tail[] = " exists; not overwriting it without permission";
  const char *m = tt_context_errmsg(r->ctx);
  size_t n = m ? strlen(m) : 0, t = sizeof tail - 1;
  if (n > t && strcmp(m + n - t, tail) == 0)
    return run_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_EXISTS, NULL,
                    "%.*s: exists; use -overwrite to replace it",
                    (int)(n - t), m);
  if (m && *m)
    return run_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_EXISTS, output, "%s",
                    why(r, TT_ERR_EXISTS, output));
  return run_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_EXISTS, output,
                  "exists; use -overwrite to replace it");
}

/* Polls the progress callback outside the phases that report progress, so
 * an interruption is seen between steps too. */
static int run_continue(app_run *r, double at)
{
  if (!r->o->progress)
    return 1;
  return r->o->progress(at, NULL, r->o->progress_arg);
}

static void apply_config(const tt_app_settings *s)
{
  for (size_t i = 0; s->config[i] && s->config[i + 1]; i += 2)
    CPLSetConfigOption(s->config[i], s->config[i + 1]);
}

/* Opens a raster for reading and checks the band; on failure explains in
 * one line why: missing, a folder, empty, a vector dataset, unreadable. */
static GDALDatasetH open_raster(app_run *r, const char *path, int band,
                                GDALRasterBandH *out_band)
{
  VSIStatBufL sb;
  *out_band = NULL;
  r->msg.last[0] = '\0';
  GDALDatasetH ds = GDALOpenEx(path, GDAL_OF_RASTER | GDAL_OF_READONLY |
                                         GDAL_OF_VERBOSE_ERROR,
                               NULL, NULL, NULL);
  if (!ds) {
    char gdal_msg[TT_APP_MESSAGE_MAX];
    snprintf(gdal_msg, sizeof gdal_msg, "%s", r->msg.last);
    int stat_ok = VSIStatL(path, &sb) == 0;
    if (!stat_ok && !strchr(path, ':') && strncmp(path, "/vsi", 4) != 0) {
      run_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_IO, path,
               "no such file or directory");
      return NULL;
    }
    if (stat_ok && VSI_ISDIR(sb.st_mode)) {
      run_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_FORMAT, path,
               "is a folder, not a raster");
      return NULL;
    }
    if (stat_ok && VSI_ISREG(sb.st_mode) && sb.st_size == 0) {
      run_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_FORMAT, path,
               "is an empty file, not a raster");
      return NULL;
    }
    CPLPushErrorHandler(CPLQuietErrorHandler);
    GDALDatasetH vec = GDALOpenEx(path, GDAL_OF_VECTOR | GDAL_OF_READONLY,
                                  NULL, NULL, NULL);
    CPLPopErrorHandler();
    if (vec) {
      GDALDriverH drv = GDALGetDatasetDriver(vec);
      run_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_FORMAT, path,
               "is a vector dataset (%s), not a raster",
               drv ? GDALGetDriverShortName(drv) : "?");
      GDALClose(vec);
      return NULL;
    }
    if (gdal_msg[0] && !strstr(gdal_msg, "not recognized"))
      run_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_FORMAT, path,
               "cannot be opened as a raster: %s", gdal_msg);
    else
      run_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_FORMAT, path,
               "not a raster format GDAL can read");
    return NULL;
  }
  int nbands = GDALGetRasterCount(ds);
  if (nbands < 1) {
    run_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_FORMAT, path,
             "has no raster band");
    GDALClose(ds);
    return NULL;
  }
  if (band > nbands) {
    run_fail(r, TT_APP_EXIT_USAGE, TT_ERR_ARG, path,
             "-b %d: the raster has %d band%s", band, nbands,
             nbands == 1 ? "" : "s");
    GDALClose(ds);
    return NULL;
  }
  int w = GDALGetRasterXSize(ds), h = GDALGetRasterYSize(ds);
  if (w < 2 || h < 2) {
    run_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_DATA, path,
             "raster is %dx%d; at least 2x2 samples are needed", w, h);
    GDALClose(ds);
    return NULL;
  }
  *out_band = GDALGetRasterBand(ds, band);
  return ds;
}

/* Reads the band into a grid and checks it has usable samples. */
static tt_status read_dem(app_run *r, GDALRasterBandH band, const char *path,
                          tt_progress_fn progress, void *progress_arg,
                          tt_grid **out_grid, tt_raster_info **out_info,
                          size_t *out_valid)
{
  tt_grid *grid = NULL;
  tt_raster_info *info = NULL;
  size_t valid = 0;
  char **ropts = NULL;
  if (r->s->srcnodata)
    ropts = CSLSetNameValue(ropts, "SRCNODATA", r->s->srcnodata);
  if (r->s->z_factor != 1.0 || r->s->z_factor_set) {
    char num[40];
    format_double(num, sizeof num, r->s->z_factor);
    ropts = CSLSetNameValue(ropts, "Z_FACTOR", num);
  }
  if (r->s->z_unit)
    ropts = CSLSetNameValue(ropts, "Z_UNIT", r->s->z_unit);
  if (r->s->work_srs)
    ropts = CSLSetNameValue(ropts, "WORK_SRS", r->s->work_srs);
  r->msg.last[0] = '\0';
  tt_status st = tt_gdal_read_grid(r->ctx, band, ropts, progress,
                                   progress_arg, &grid, &info);
  CSLDestroy(ropts);
  if (st != TT_OK) {
    run_fail_tt(r, st, path);
    goto done;
  }
  st = tt_grid_check(r->ctx, grid, &valid);
  if (st != TT_OK) {
    run_fail_tt(r, st, path);
    goto done;
  }
  if (valid == 0) {
    st = run_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_DATA, path,
                  "band %d has no valid samples (all nodata)", r->s->band);
    goto done;
  }
done:
  if (st != TT_OK) {
    tt_grid_destroy(grid);
    tt_raster_info_destroy(info);
    grid = NULL;
    info = NULL;
  }
  *out_grid = grid;
  *out_info = info;
  *out_valid = valid;
  return st;
}

static void height_range(const tt_grid *grid, double *out_min,
                         double *out_max)
{
  const float *z = tt_grid_heights_const(grid);
  const double *zd = tt_grid_heights_f64_const(grid);
  size_t n = tt_grid_width(grid) * tt_grid_height(grid);
  double lo = INFINITY, hi = -INFINITY;
  for (size_t i = 0; i < n; i++) {
    double v = zd ? zd[i] : (double)z[i];
    if (isnan(v))
      continue;
    if (v < lo) lo = v;
    if (v > hi) hi = v;
  }
  *out_min = lo;
  *out_max = hi;
}

static const char *unit_or(const tt_raster_info *info, const char *dflt)
{
  return info && info->z_unit && *info->z_unit ? info->z_unit : dflt;
}

static const char *nonempty_or_null(const char *s)
{
  return s && *s ? s : NULL;
}

/* "2026-11-22T10:38:55Z" */
static void iso8601_utc(char *buf, size_t size)
{
  time_t now = time(NULL);
  struct tm tm;
  if (!gmtime_r(&now, &tm) ||
      strftime(buf, size, "%Y-%m-%dT%H:%M:%SZ", &tm) == 0)
    snprintf(buf, size, "unknown");
}

static int driver_can_create_vector(GDALDriverH drv)
{
  return GDALGetMetadataItem(drv, GDAL_DCAP_VECTOR, NULL) &&
         GDALGetMetadataItem(drv, GDAL_DCAP_CREATE, NULL);
}

/* Whether the space-separated list holds ext (case-insensitive). */
static int ext_in_list(const char *list, const char *ext)
{
  size_t n = strlen(ext);
  const char *p = list;
  while (p && *p) {
    while (*p == ' ')
      p++;
    const char *e = strchr(p, ' ');
    size_t len = e ? (size_t)(e - p) : strlen(p);
    if (len == n && strncasecmp(p, ext, n) == 0)
      return 1;
    p = e;
  }
  return 0;
}

/* Drivers whose datasets tt_output cannot keep safe: they write no file
 * (Memory, database connections), or they put each further layer in a file
 * of its own beside OUTPUT (CSV), outside the temporary name, where it could
 * replace a file without -overwrite and survive a failure. */
static int refuse_driver(app_run *r, GDALDriverH drv)
{
  const char *name = GDALGetDriverShortName(drv);
  if (!GDALGetMetadataItem(drv, GDAL_DMD_EXTENSIONS, NULL) &&
      !GDALGetMetadataItem(drv, GDAL_DMD_EXTENSION, NULL)) {
    run_fail(r, TT_APP_EXIT_USAGE, TT_ERR_ARG, NULL,
             "simplify: -of '%s': the driver does not write files", name);
    return 1;
  }
  if (str_ieq(name, "CSV")) {
    run_fail(r, TT_APP_EXIT_USAGE, TT_ERR_ARG, NULL,
             "simplify: -of CSV writes each layer to a file of its own "
             "beside OUTPUT, which cannot be written safely; use GPKG, "
             "SQLite or \"ESRI Shapefile\"");
    return 1;
  }
  return 0;
}

/* The output driver: -of, else the first vector driver that can create and
 * claims OUTPUT's extension (GPKG and ESRI Shapefile first), else GPKG. */
static GDALDriverH output_driver(app_run *r)
{
  const char *of = r->s->format;
  if (of) {
    GDALDriverH drv = GDALGetDriverByName(of);
    if (!drv) {
      run_fail(r, TT_APP_EXIT_USAGE, TT_ERR_ARG, NULL,
               "simplify: -of '%s': no such GDAL driver (see 'ogrinfo "
               "--formats')", of);
      return NULL;
    }
    if (!driver_can_create_vector(drv)) {
      run_fail(r, TT_APP_EXIT_USAGE, TT_ERR_ARG, NULL,
               "simplify: -of '%s': the driver cannot create vector "
               "datasets", of);
      return NULL;
    }
    return refuse_driver(r, drv) ? NULL : drv;
  }
  char ext[32] = "";
  const char *base = strrchr(r->s->output, '/');
  base = base ? base + 1 : r->s->output;
  const char *dot = strrchr(base, '.');
  if (dot && dot[1] && strlen(dot + 1) < sizeof ext)
    snprintf(ext, sizeof ext, "%s", dot + 1);
  if (ext[0]) {
    static const char *const preferred[] = {"GPKG", "ESRI Shapefile"};
    for (size_t i = 0; i < 2; i++) {
      GDALDriverH drv = GDALGetDriverByName(preferred[i]);
      if (drv && driver_can_create_vector(drv) &&
          ext_in_list(GDALGetMetadataItem(drv, GDAL_DMD_EXTENSIONS, NULL),
                      ext))
        return drv;
    }
    for (int i = 0; i < GDALGetDriverCount(); i++) {
      GDALDriverH drv = GDALGetDriver(i);
      if (!driver_can_create_vector(drv))
        continue;
      const char *exts = GDALGetMetadataItem(drv, GDAL_DMD_EXTENSIONS, NULL);
      if (!exts)
        exts = GDALGetMetadataItem(drv, GDAL_DMD_EXTENSION, NULL);
      if (exts && ext_in_list(exts, ext))
        return refuse_driver(r, drv) ? NULL : drv;
    }
  }
  GDALDriverH drv = GDALGetDriverByName("GPKG");
  if (!drv || !driver_can_create_vector(drv)) {
    run_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_FORMAT, NULL,
             "simplify: this GDAL has no GPKG driver; choose one with -of");
    return NULL;
  }
  if (ext[0])
    warn(&r->msg, "%s: no vector driver claims the extension '.%s'; "
                  "writing a GeoPackage (use -of to choose)",
         r->s->output, ext);
  return drv;
}

/* Whether two paths name the same existing file. */
static int same_file(const char *a, const char *b)
{
  struct stat sa, sb;
  return stat(a, &sa) == 0 && stat(b, &sb) == 0 && sa.st_dev == sb.st_dev &&
         sa.st_ino == sb.st_ino;
}

/* ===========================================================================
 * simplify
 * ========================================================================= */

/* -work_srs and -t_srs: a CRS GDAL understands (usage error otherwise);
 * -work_srs must also be projected. */
static int check_srs(app_run *r, const char *option, const char *value,
                     int projected)
{
  if (!value)
    return 1;
  OGRSpatialReferenceH srs = OSRNewSpatialReference(NULL);
  r->msg.last[0] = '\0';
  int ok = srs && OSRSetFromUserInput(srs, value) == OGRERR_NONE;
  if (!ok)
    run_fail(r, TT_APP_EXIT_USAGE, TT_ERR_ARG, NULL,
             "simplify: %s '%s' is not a CRS GDAL understands%s%s", option,
             value, r->msg.last[0] ? ": " : "", r->msg.last);
  else if (projected && !OSRIsProjected(srs)) {
    run_fail(r, TT_APP_EXIT_USAGE, TT_ERR_ARG, NULL,
             "simplify: %s '%s' is not a projected CRS: the working frame "
             "must be in metres", option, value);
    ok = 0;
  }
  if (srs)
    OSRDestroySpatialReference(srs);
  return ok;
}

typedef struct simplify_report {
  const tt_raster_info *info;
  const char *driver;
  size_t cells, valid;
  double zmin, zmax;
  const tt_refine_options *ropt;
  int default_error;            /* max_error came from the 0.5% rule */
  tt_tin_summary sum;
  double t_read, t_simplify, t_write, t_total;
} simplify_report;

static void print_simplify_json(app_run *r, const simplify_report *p)
{
  json_w j;
  const tt_refine_options *ro = p->ropt;
  const tt_error_stats *e = &p->sum.errors;
  json_begin(&j, r->out);
  json_str(&j, "input", r->s->input);
  json_size(&j, "band", (size_t)r->s->band);
  json_str(&j, "output", r->s->output);
  json_str(&j, "format", p->driver);
  json_str(&j, "criterion", tt_criterion_name(p->sum.criterion));
  tt_repair rep = tt_repair_resolve(r->s->repair, p->sum.criterion);
  json_str(&j, "repair", tt_repair_name(rep));
  json_str(&j, "optimize",
           tt_optimize_name(tt_optimize_resolve(r->s->optimize,
                                                p->sum.criterion, rep)));
  json_size(&j, "width", p->info->width);
  json_size(&j, "height", p->info->height);
  json_size(&j, "cells", p->cells);
  json_size(&j, "valid_samples", p->valid);
  json_num(&j, "z_min", p->zmin);
  json_num(&j, "z_max", p->zmax);
  json_open(&j, "limits");
  if (ro->max_error >= 0) json_num(&j, "max_error", ro->max_error);
  else json_null(&j, "max_error");
  json_bool(&j, "max_error_default", p->default_error);
  if (ro->max_points) json_size(&j, "max_points", ro->max_points);
  else json_null(&j, "max_points");
  if (ro->max_triangles) json_size(&j, "max_triangles", ro->max_triangles);
  else json_null(&j, "max_triangles");
  if (ro->percent > 0) json_num(&j, "percent", ro->percent);
  else json_null(&j, "percent");
  json_close(&j);
  json_str(&j, "stop_reason", tt_stop_reason_name(p->sum.stop_reason));
  json_size(&j, "vertices", p->sum.vertices);
  json_size(&j, "triangles", p->sum.triangles);
  json_size(&j, "covered_samples", e->covered);
  json_size(&j, "lone_samples", e->samples - e->covered);
  json_size(&j, "components", p->sum.components);
  json_size(&j, "forced_vertices", p->sum.forced_vertices);
  json_num(&j, "max_error", e->max_error);
  json_num(&j, "rmse", e->rmse);
  json_num(&j, "mean_abs_error", e->mean_abs);
  json_num(&j, "total_abs_error", e->total_abs);
  json_num(&j, "l2", e->l2);
  if (e->max_col >= 0) {
    const double *gt = p->info->gt;
    double c = (double)e->max_col + 0.5, rw = (double)e->max_row + 0.5;
    json_open(&j, "max_error_at");
    json_i64(&j, "col", e->max_col);
    json_i64(&j, "row", e->max_row);
    json_num(&j, "x", gt[0] + c * gt[1] + rw * gt[2]);
    json_num(&j, "y", gt[3] + c * gt[4] + rw * gt[5]);
    json_close(&j);
  } else {
    json_null(&j, "max_error_at");
  }
  json_str(&j, "z_unit", nonempty_or_null(p->info->z_unit));
  json_str(&j, "z_unit_declared", nonempty_or_null(p->info->z_unit_declared));
  json_str(&j, "z_unit_source", nonempty_or_null(p->info->z_unit_source));
  json_num(&j, "z_multiplier", p->info->z_unit_factor * p->info->z_factor);
  json_str(&j, "pixel_is", nonempty_or_null(p->info->area_or_point));
  json_str(&j, "crs", nonempty_or_null(p->info->crs_name));
  json_str(&j, "output_crs", r->s->t_srs ? r->s->t_srs
                                          : nonempty_or_null(p->info->crs_name));
  json_str(&j, "frame", p->info->frame_name);
  json_size(&j, "warnings", r->msg.warnings);
  json_open(&j, "seconds");
  json_num(&j, "read", p->t_read);
  json_num(&j, "simplify", p->t_simplify);
  json_num(&j, "mesh", p->sum.seconds_mesh);
  json_num(&j, "statistics", p->sum.seconds_statistics);
  json_num(&j, "write", p->t_write);
  json_num(&j, "total", p->t_total);
  json_close(&j);
  json_str(&j, "version", tt_version());
  json_close(&j);
}

static void print_simplify_summary(app_run *r, const simplify_report *p)
{
  const char *unit = unit_or(p->info, "z units");
  const tt_refine_options *ro = p->ropt;
  char lim[256] = "", num[40];
  size_t n = 0;
  if (ro->max_error >= 0) {
    snprintf(num, sizeof num, "%.6g", ro->max_error);
    n += (size_t)snprintf(lim + n, sizeof lim - n, "%smax_error %s %s%s",
                          n ? ", " : "", num, unit,
                          p->default_error ? " (default: 0.5% of the height "
                                             "range)"
                                           : "");
  }
  if (ro->max_points && n < sizeof lim)
    n += (size_t)snprintf(lim + n, sizeof lim - n, "%smax_points %zu",
                          n ? ", " : "", ro->max_points);
  if (ro->max_triangles && n < sizeof lim)
    n += (size_t)snprintf(lim + n, sizeof lim - n, "%smax_triangles %zu",
                          n ? ", " : "", ro->max_triangles);
  if (ro->percent > 0 && n < sizeof lim) {
    snprintf(num, sizeof num, "%.6g", ro->percent);
    snprintf(lim + n, sizeof lim - n, "%spercent %s", n ? ", " : "", num);
  }
  /* Where the numbers stand: CRS, working frame, height unit. */
  const tt_raster_info *in = p->info;
  char zu[160];
  if (in->z_unit_factor != 1.0)
    snprintf(zu, sizeof zu, "%s (from %s, x%.10g)", unit,
             in->z_unit_declared, in->z_unit_factor);
  else if (in->z_unit && *in->z_unit)
    snprintf(zu, sizeof zu, "%s (%s)", unit, in->z_unit_source);
  else
    snprintf(zu, sizeof zu, "unknown");
  fprintf(r->out,
          "%s: %zu cells, %zu valid samples -> %zu vertices, %zu triangles; "
          "max error %.6g %s, RMS %.6g %s; limits: %s; stop: %s; CRS %s%s%s; "
          "frame %s; z unit %s; %.2f s\n",
          r->s->output, p->cells, p->valid, p->sum.vertices,
          p->sum.triangles, p->sum.errors.max_error, unit,
          p->sum.errors.rmse, unit, lim,
          tt_stop_reason_name(p->sum.stop_reason),
          in->crs_name && *in->crs_name ? in->crs_name : "none",
          r->s->t_srs ? ", written in " : "", r->s->t_srs ? r->s->t_srs : "",
          in->frame_name, zu, p->t_total);
  /* nodata outlines: what the TIN could not carry is said, not dropped */
  size_t lone = p->sum.errors.samples - p->sum.errors.covered;
  if (lone || p->sum.components > 1)
    fprintf(r->out,
            "%s: %zu separate piece%s; %zu valid sample%s amid nodata "
            "(in no cell with 3 valid corners) cannot carry a triangle and "
            "%s left out\n",
            r->s->output, p->sum.components,
            p->sum.components == 1 ? "" : "s", lone, lone == 1 ? "" : "s",
            lone == 1 ? "is" : "are");
}

static tt_status run_simplify(app_run *r)
{
  const tt_app_settings *s = r->s;
  tt_status st = TT_OK;
  tt_output *outp = NULL;
  GDALDatasetH src = NULL, dst = NULL;
  GDALRasterBandH band = NULL;
  tt_grid *grid = NULL;
  tt_raster_info *info = NULL;
  tt_tin *tin = NULL;
  OGRSpatialReferenceH srs = NULL;
  char **wopts = NULL;
  simplify_report rep;
  tt_refine_options ro;
  size_t valid = 0;
  memset(&rep, 0, sizeof rep);

  if (same_file(s->input, s->output))
    return run_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_ARG, s->output,
                    "is the input raster; refusing to replace it");
  if (!check_srs(r, "-work_srs", s->work_srs, 1) ||
      !check_srs(r, "-t_srs", s->t_srs, 0))
    return r->res->status;
  GDALDriverH drv = output_driver(r);
  if (!drv)
    return r->res->status;
  const char *drvname = GDALGetDriverShortName(drv);

  /* Plan the output first: a refusal costs nothing yet. */
  r->msg.last[0] = '\0';
  st = tt_output_begin(r->ctx, s->output, drvname, s->overwrite, &outp);
  if (st == TT_OK && !s->overwrite && s->nln[0] &&
      str_ieq(drvname, "ESRI Shapefile")) {
    /* tt_output checked the files of the plain layer names; with -nln the
     * files are named otherwise: check those too, before the work. */
    static const char *const names[] = {"triangles.shp", "triangles.dbf",
                                        "vertices.shp", "vertices.dbf",
                                        "run_parameters.dbf"};
    const char *slash = strrchr(s->output, '/');
    int dirlen = slash ? (int)(slash - s->output) : 1;
    const char *dir = slash ? s->output : ".";
    for (size_t i = 0; i < sizeof names / sizeof names[0]; i++) {
      VSIStatBufL sb;
      const char *p = CPLSPrintf("%.*s/%s%s%s", dirlen, dir,
                                 tt_output_layer_prefix(outp), s->nln,
                                 names[i]);
      if (VSIStatL(p, &sb) == 0) {
        st = run_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_EXISTS, p,
                      "exists; use -overwrite to replace it");
        goto done;
      }
    }
  }
  if (st == TT_ERR_EXISTS) {
    run_fail_exists(r, s->output);
    goto done;
  }
  if (st != TT_OK) {
    run_fail_tt(r, st, s->output);
    goto done;
  }

  /* Read: 0 - 10%. */
  phase_set(&r->prog, 0.0, 0.10);
  src = open_raster(r, s->input, s->band, &band);
  if (!src) {
    st = r->res->status;
    goto done;
  }
  if (!run_continue(r, 0.0)) {
    st = run_fail_tt(r, TT_ERR_INTERRUPTED, s->output);
    goto done;
  }
  st = read_dem(r, band, s->input, phase_fn, &r->prog, &grid, &info, &valid);
  if (st != TT_OK)
    goto done;
  GDALClose(src);
  src = NULL;
  rep.info = info;
  rep.driver = drvname;
  rep.cells = tt_grid_width(grid) * tt_grid_height(grid);
  rep.valid = valid;
  height_range(grid, &rep.zmin, &rep.zmax);
  rep.t_read = app_now() - r->t0;

  /* Simplify: 10 - 85%. */
  tt_refine_options_init(&ro);
  ro.max_error = s->max_error;
  ro.max_points = s->max_points;
  ro.max_triangles = s->max_triangles;
  ro.percent = s->percent;
  ro.criterion = s->criterion;
  ro.optimize = s->optimize;
  ro.repair = s->repair;
  if (s->max_error < 0 && !s->max_points && !s->max_triangles &&
      !(s->percent > 0)) {
    ro.max_error = 0.005 * (rep.zmax - rep.zmin);
    rep.default_error = 1;
  }
  phase_set(&r->prog, 0.10, 0.85);
  ro.progress = phase_fn;
  ro.progress_arg = &r->prog;
  rep.ropt = &ro;
  double t = app_now();
  st = tt_refine_run(r->ctx, grid, &ro, &tin);
  if (st != TT_OK) {
    run_fail_tt(r, st, st == TT_ERR_INTERRUPTED ? s->output : s->input);
    goto done;
  }
  rep.t_simplify = app_now() - t;
  tt_tin_get_summary(tin, &rep.sum);
  /* The TIN keeps what it needs; the grid can go before the write. */
  tt_grid_destroy(grid);
  grid = NULL;

  /* Write: 85 - 100%. */
  t = app_now();
  phase_set(&r->prog, 0.85, 0.99);
  if (!run_continue(r, 0.85)) {
    st = run_fail_tt(r, TT_ERR_INTERRUPTED, s->output);
    goto done;
  }
  r->msg.last[0] = '\0';
  dst = GDALCreate(drv, tt_output_temp_path(outp), 0, 0, 0, GDT_Unknown,
                   (CSLConstList)s->dsco);
  if (!dst) {
    st = run_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_IO, s->output,
                  "cannot create %s dataset: %s", drvname,
                  r->msg.last[0] ? r->msg.last : "unknown reason");
    goto done;
  }
  if (info->crs_wkt && *info->crs_wkt) {
    srs = OSRNewSpatialReference(info->crs_wkt);
    if (srs)
      OSRSetAxisMappingStrategy(srs, OAMS_TRADITIONAL_GIS_ORDER);
    else
      warn(&r->msg, "%s: the raster's CRS could not be parsed; the layers "
                    "have none", s->input);
  }

  char created[32];
  iso8601_utc(created, sizeof created);
  const tt_error_stats *e = &rep.sum.errors;
  const tt_run_field fields[] = {
      {"input", TT_FIELD_STRING, s->input, 0, 0},
      {"band", TT_FIELD_INTEGER, NULL, s->band, 0},
      {"driver", TT_FIELD_STRING, info->driver ? info->driver : "", 0, 0},
      {"criterion", TT_FIELD_STRING, tt_criterion_name(ro.criterion), 0, 0},
      {"repair", TT_FIELD_STRING,
       tt_repair_name(tt_repair_resolve(ro.repair, ro.criterion)), 0, 0},
      {"optimize", TT_FIELD_STRING,
       tt_optimize_name(tt_optimize_resolve(ro.optimize, ro.criterion,
                                            ro.repair)), 0, 0},
      {"max_error", TT_FIELD_REAL, NULL, 0, ro.max_error},
      {"max_points", TT_FIELD_INTEGER, NULL, (int64_t)ro.max_points, 0},
      {"max_tris", TT_FIELD_INTEGER, NULL, (int64_t)ro.max_triangles, 0},
      {"percent", TT_FIELD_REAL, NULL, 0, ro.percent},
      {"stop", TT_FIELD_STRING, tt_stop_reason_name(rep.sum.stop_reason), 0,
       0},
      {"vertices", TT_FIELD_INTEGER, NULL, (int64_t)rep.sum.vertices, 0},
      {"triangles", TT_FIELD_INTEGER, NULL, (int64_t)rep.sum.triangles, 0},
      {"cells", TT_FIELD_INTEGER, NULL, (int64_t)rep.cells, 0},
      {"valid", TT_FIELD_INTEGER, NULL, (int64_t)rep.valid, 0},
      {"lone", TT_FIELD_INTEGER, NULL,
       (int64_t)(e->samples - e->covered), 0},
      {"pieces", TT_FIELD_INTEGER, NULL, (int64_t)rep.sum.components, 0},
      {"ach_max", TT_FIELD_REAL, NULL, 0, e->max_error},
      {"ach_rmse", TT_FIELD_REAL, NULL, 0, e->rmse},
      {"ach_mean", TT_FIELD_REAL, NULL, 0, e->mean_abs},
      {"ach_l2", TT_FIELD_REAL, NULL, 0, e->l2},
      {"z_unit", TT_FIELD_STRING, info->z_unit ? info->z_unit : "", 0, 0},
      {"z_unit_in", TT_FIELD_STRING,
       info->z_unit_declared ? info->z_unit_declared : "", 0, 0},
      {"z_factor", TT_FIELD_REAL, NULL, 0, info->z_unit_factor *
                                               info->z_factor},
      {"pixel_is", TT_FIELD_STRING,
       info->area_or_point ? info->area_or_point : "", 0, 0},
      {"crs", TT_FIELD_STRING, info->crs_name ? info->crs_name : "", 0, 0},
      {"out_crs", TT_FIELD_STRING, s->t_srs ? s->t_srs : "", 0, 0},
      {"frame", TT_FIELD_STRING, info->frame_name ? info->frame_name : "", 0,
       0},
      {"version", TT_FIELD_STRING, tt_version(), 0, 0},
      {"t_read", TT_FIELD_REAL, NULL, 0, rep.t_read},
      {"t_simplify", TT_FIELD_REAL, NULL, 0, rep.t_simplify},
      {"t_mesh", TT_FIELD_REAL, NULL, 0, rep.sum.seconds_mesh},
      {"t_stats", TT_FIELD_REAL, NULL, 0, rep.sum.seconds_statistics},
      {"created", TT_FIELD_STRING, created, 0, 0},
  };
  /* Shapefile outputs name their files "<name>_<layer>": the planned
   * prefix comes first, then the user's -nln. */
  char *prefix = CPLStrdup(CPLSPrintf("%s%s", tt_output_layer_prefix(outp),
                                      s->nln));
  wopts = CSLSetNameValue(wopts, "NLN_PREFIX", prefix);
  CPLFree(prefix);
  for (size_t i = 0; s->lco[i]; i++)
    wopts = CSLAddNameValue(wopts, "LCO", s->lco[i]);
  if (s->t_srs)
    wopts = CSLSetNameValue(wopts, "T_SRS", s->t_srs);
  /* GPKG R-trees: bulk-loaded on the closed file by tt_gpkg_build_rtree()
   * (GDAL 3.6 inserts them one by one); -lco SPATIAL_INDEX=NO: none. */
  const char *si = CSLFetchNameValue((CSLConstList)s->lco, "SPATIAL_INDEX");
  int rtree = str_ieq(drvname, "GPKG") && (!si || CPLTestBool(si));
  if (rtree) {
    wopts = CSLSetNameValue(wopts, "RTREE", "DEFERRED");
    phase_set(&r->prog, 0.85, 0.95);
  }
  r->msg.last[0] = '\0';
  st = tt_ogr_write_tin(r->ctx, dst, tin, srs, fields,
                        sizeof fields / sizeof fields[0], wopts, phase_fn,
                        &r->prog);
  if (st != TT_OK) {
    run_fail_tt(r, st, s->output);
    goto done;
  }
  unsigned failures = r->msg.failures;
  GDALClose(dst);
  dst = NULL;
  if (r->msg.failures != failures) {
    st = run_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_IO, s->output,
                  "error while closing: %s", r->msg.last);
    goto done;
  }
  for (int k = 0; rtree && k < 2; k++) {
    const char *geom = CSLFetchNameValueDef((CSLConstList)s->lco,
                                            "GEOMETRY_NAME", "geom");
    char *layer = CPLStrdup(CPLSPrintf("%s%s", s->nln,
                                       k ? "vertices" : "triangles"));
    phase_set(&r->prog, k ? 0.98 : 0.95, k ? 0.99 : 0.98);
    st = tt_gpkg_build_rtree(r->ctx, tt_output_temp_path(outp), layer, geom,
                             phase_fn, &r->prog);
    CPLFree(layer);
    if (st == TT_ERR_INTERRUPTED || st == TT_ERR_NOMEM) {
      run_fail_tt(r, st, s->output);
      goto done;
    }
    if (st != TT_OK) {
      run_fail(r, TT_APP_EXIT_FAILURE, st, s->output, "%s",
               why(r, st, tt_output_temp_path(outp)));
      goto done;
    }
  }
  if (!run_continue(r, 0.99)) {
    st = run_fail_tt(r, TT_ERR_INTERRUPTED, s->output);
    goto done;
  }
  st = tt_output_commit(r->ctx, outp);
  if (st == TT_ERR_EXISTS) {
    run_fail_exists(r, s->output); /* it appeared while we worked */
    goto done;
  }
  if (st != TT_OK) {
    run_fail_tt(r, st, s->output);
    goto done;
  }
  rep.t_write = app_now() - t;
  rep.t_total = app_now() - r->t0;
  run_continue(r, 1.0);

  if (s->json)
    print_simplify_json(r, &rep);
  else if (!s->quiet)
    print_simplify_summary(r, &rep);
  fflush(r->out);

done:
  if (dst)
    GDALClose(dst);
  if (src)
    GDALClose(src);
  tt_output_destroy(outp); /* removes the temporary files unless committed */
  if (srs)
    OSRDestroySpatialReference(srs);
  CSLDestroy(wopts);
  tt_tin_destroy(tin);
  tt_grid_destroy(grid);
  tt_raster_info_destroy(info);
  return st;
}

/* ===========================================================================
 * generate
 * ========================================================================= */

static tt_status run_generate(app_run *r)
{
  const tt_app_settings *s = r->s;
  tt_status st = TT_OK;
  tt_grid *grid = NULL;
  char *wkt = NULL;
  OGRSpatialReferenceH srs = NULL;
  VSIStatBufL sb;

  if (s->srs) {
    srs = OSRNewSpatialReference(NULL);
    r->msg.last[0] = '\0';
    if (!srs || OSRSetFromUserInput(srs, s->srs) != OGRERR_NONE ||
        OSRExportToWkt(srs, &wkt) != OGRERR_NONE) {
      st = run_fail(r, TT_APP_EXIT_USAGE, TT_ERR_ARG, NULL,
                    "generate: -a_srs '%s' is not a CRS GDAL understands%s%s",
                    s->srs, r->msg.last[0] ? ": " : "", r->msg.last);
      goto done;
    }
  }
  if (!s->overwrite && VSIStatL(s->output, &sb) == 0) {
    st = run_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_EXISTS, s->output,
                  "exists; use -overwrite to replace it");
    goto done;
  }
  if (!run_continue(r, 0.0)) {
    st = run_fail_tt(r, TT_ERR_INTERRUPTED, s->output);
    goto done;
  }
  st = tt_synth_generate(r->ctx, &s->synth, &grid);
  if (st != TT_OK) {
    run_fail_tt(r, st, s->output);
    goto done;
  }
  if (!run_continue(r, 0.5)) {
    st = run_fail_tt(r, TT_ERR_INTERRUPTED, s->output);
    goto done;
  }
  r->msg.last[0] = '\0';
  st = tt_gdal_write_grid(r->ctx, grid, s->output, wkt ? wkt : "",
                          s->overwrite);
  if (st == TT_ERR_EXISTS) {
    run_fail_exists(r, s->output);
    goto done;
  }
  if (st != TT_OK) {
    run_fail_tt(r, st, s->output);
    goto done;
  }
  if (!s->quiet) {
    double lo, hi;
    height_range(grid, &lo, &hi);
    fprintf(r->out,
            "%s: %s terrain, %zux%zu samples, seed %llu, heights %.6g to "
            "%.6g; %.2f s\n",
            s->output, tt_synth_kind_name(s->synth.kind), s->synth.nx,
            s->synth.ny, (unsigned long long)s->synth.seed, lo, hi,
            app_now() - r->t0);
    fflush(r->out);
  }
done:
  CPLFree(wkt);
  if (srs)
    OSRDestroySpatialReference(srs);
  tt_grid_destroy(grid);
  return st;
}

/* ===========================================================================
 * eval
 * ========================================================================= */

static int is_polygon_layer(OGRLayerH layer)
{
  OGRwkbGeometryType t = wkbFlatten(OGR_L_GetGeomType(layer));
  return t == wkbPolygon || t == wkbMultiPolygon || t == wkbTIN ||
         t == wkbTriangle || t == wkbPolyhedralSurface;
}

static int ends_with(const char *s, const char *suffix)
{
  size_t n = strlen(s), m = strlen(suffix);
  return n >= m && strcasecmp(s + n - m, suffix) == 0;
}

/* -layer, else "triangles" or "*_triangles", else the first polygon layer. */
static OGRLayerH eval_layer(app_run *r, GDALDatasetH ds)
{
  const char *path = r->s->tin;
  int n = GDALDatasetGetLayerCount(ds);
  if (r->s->layer) {
    OGRLayerH l = GDALDatasetGetLayerByName(ds, r->s->layer);
    if (!l)
      run_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_ARG, path,
               "no layer named '%s'", r->s->layer);
    return l;
  }
  for (int pass = 0; pass < 2; pass++) {
    for (int i = 0; i < n; i++) {
      OGRLayerH l = GDALDatasetGetLayer(ds, i);
      const char *name = OGR_L_GetName(l);
      if (pass == 0 && name &&
          (strcasecmp(name, "triangles") == 0 ||
           ends_with(name, "_triangles")))
        return l;
      if (pass == 1 && is_polygon_layer(l))
        return l;
    }
  }
  run_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_FORMAT, path,
           "no triangles layer and no polygon layer (%d layer%s)", n,
           n == 1 ? "" : "s");
  return NULL;
}

static GDALDatasetH open_vector(app_run *r, const char *path)
{
  VSIStatBufL sb;
  r->msg.last[0] = '\0';
  GDALDatasetH ds = GDALOpenEx(path, GDAL_OF_VECTOR | GDAL_OF_READONLY |
                                         GDAL_OF_VERBOSE_ERROR,
                               NULL, NULL, NULL);
  if (ds)
    return ds;
  if (VSIStatL(path, &sb) != 0 && !strchr(path, ':') &&
      strncmp(path, "/vsi", 4) != 0) {
    run_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_IO, path,
             "no such file or directory");
    return NULL;
  }
  CPLPushErrorHandler(CPLQuietErrorHandler);
  GDALDatasetH ras = GDALOpenEx(path, GDAL_OF_RASTER | GDAL_OF_READONLY,
                                NULL, NULL, NULL);
  CPLPopErrorHandler();
  if (ras) {
    GDALClose(ras);
    run_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_FORMAT, path,
             "is a raster, not a vector dataset of triangles");
    return NULL;
  }
  if (r->msg.last[0] && !strstr(r->msg.last, "not recognized"))
    run_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_FORMAT, path,
             "cannot be opened as a vector dataset: %s", r->msg.last);
  else
    run_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_FORMAT, path,
             "not a vector format GDAL can read");
  return NULL;
}

static tt_status run_eval(app_run *r)
{
  const tt_app_settings *s = r->s;
  tt_status st = TT_OK;
  GDALDatasetH src = NULL, tds = NULL;
  GDALRasterBandH band = NULL;
  tt_grid *grid = NULL;
  tt_raster_info *info = NULL;
  double *xyz = NULL;
  size_t ntri = 0, rejected = 0, valid = 0;
  tt_eval_result ev;
  OGRSpatialReferenceH rsrs = NULL;
  memset(&ev, 0, sizeof ev);

  src = open_raster(r, s->input, s->band, &band);
  if (!src)
    return r->res->status;
  /* No bar for eval, but the reading still polls for an interruption. */
  phase_set(&r->prog, 0.0, 0.3);
  st = read_dem(r, band, s->input, phase_fn, &r->prog, &grid, &info, &valid);
  if (st != TT_OK)
    goto done;
  GDALClose(src);
  src = NULL;
  double t_read = app_now() - r->t0;
  if (!run_continue(r, 0.3)) {
    st = run_fail_tt(r, TT_ERR_INTERRUPTED, s->tin);
    goto done;
  }

  tds = open_vector(r, s->tin);
  if (!tds) {
    st = r->res->status;
    goto done;
  }
  OGRLayerH layer = eval_layer(r, tds);
  if (!layer) {
    st = r->res->status;
    goto done;
  }
  const char *lname = OGR_L_GetName(layer);

  /* Triangles in another CRS would be measured in the wrong place. */
  int other_crs = 0;
  OGRSpatialReferenceH lsrs = OGR_L_GetSpatialRef(layer);
  if (lsrs && info->crs_wkt && *info->crs_wkt) {
    static const char *const same_opts[] = {
        "IGNORE_DATA_AXIS_TO_SRS_AXIS_MAPPING=YES",
        "CRITERION=EQUIVALENT_EXCEPT_AXIS_ORDER_GEOGCRS", NULL};
    rsrs = OSRNewSpatialReference(info->crs_wkt);
    other_crs =
        rsrs && !OSRIsSameEx(rsrs, lsrs, (const char *const *)same_opts);
  }

  r->msg.last[0] = '\0';
  st = tt_ogr_read_triangles(r->ctx, layer, info->gt, &xyz, &ntri,
                             &rejected);
  if (st != TT_OK) {
    run_fail_tt(r, st, s->tin);
    goto done;
  }
  /* Map coordinates stored in a file carry round-off: a TIN vertex on a
   * grid sample comes back a few 1e-9 pixel away when pixels are tiny
   * next to the coordinates (lidar in degrees), and the boundary samples
   * would then fall outside every triangle. Put corners within 1e-6 pixel
   * of a sample centre back on it; no other corner moves. */
  for (size_t i = 0; i < ntri * 9; i++) {
    if (i % 3 == 2)
      continue; /* z */
    double rounded = floor(xyz[i] + 0.5);
    if (fabs(xyz[i] - rounded) <= 1e-6)
      xyz[i] = rounded;
  }
  if (ntri == 0) {
    st = run_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_DATA, s->tin,
                  "layer '%s' holds no triangles (%zu polygon%s rejected)",
                  lname, rejected, rejected == 1 ? "" : "s");
    goto done;
  }
  double t = app_now();
  st = tt_eval_triangles(r->ctx, grid, ntri, xyz, &ev);
  if (st != TT_OK) {
    run_fail_tt(r, st, s->tin);
    goto done;
  }
  double t_eval = app_now() - t;
  if (ev.errors.covered == 0) {
    st = run_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_DATA, s->tin,
                  "no valid sample of %s lies in a triangle of layer '%s' "
                  "(%s)", s->input, lname,
                  other_crs ? "the layer is in another CRS"
                            : "another extent?");
    goto done;
  }
  if (other_crs)
    warn(&r->msg, "%s: layer '%s' is not in the CRS of %s; the error is "
                  "measured as if it were", s->tin, lname, s->input);
  if (ev.uncovered)
    warn(&r->msg, "%s: %zu of %zu valid samples lie in no triangle; their "
                  "error is not measured", s->tin, ev.uncovered,
         ev.errors.samples);

  const tt_error_stats *e = &ev.errors;
  const double *gt = info->gt;
  double mc = (double)e->max_col + 0.5, mr = (double)e->max_row + 0.5;
  double mx = gt[0] + mc * gt[1] + mr * gt[2];
  double my = gt[3] + mc * gt[4] + mr * gt[5];
  int checked = s->max_error >= 0;
  /* The same round-off moves the interpolated heights by ~1e-10 relative:
   * a bound met by construction must not fail the check because of it. */
  int pass = !checked ||
             e->max_error <= s->max_error + 1e-6 * fmax(s->max_error, 1.0);
  const char *unit = unit_or(info, "z units");

  if (s->json) {
    json_w j;
    json_begin(&j, r->out);
    json_str(&j, "dem", s->input);
    json_size(&j, "band", (size_t)s->band);
    json_str(&j, "tin", s->tin);
    json_str(&j, "layer", lname);
    json_size(&j, "cells", info->width * info->height);
    json_size(&j, "valid_samples", e->samples);
    json_size(&j, "covered", e->covered);
    json_size(&j, "uncovered", ev.uncovered);
    json_size(&j, "overlapped", ev.overlapped);
    json_size(&j, "triangles", ev.triangles);
    json_size(&j, "rejected", rejected);
    json_size(&j, "degenerate", ev.degenerate);
    json_num(&j, "max_error", e->max_error);
    if (e->max_col >= 0) {
      json_open(&j, "max_error_at");
      json_i64(&j, "col", e->max_col);
      json_i64(&j, "row", e->max_row);
      json_num(&j, "x", mx);
      json_num(&j, "y", my);
      json_close(&j);
    } else {
      json_null(&j, "max_error_at");
    }
    json_num(&j, "rmse", e->rmse);
    json_num(&j, "mean_abs_error", e->mean_abs);
    json_num(&j, "total_abs_error", e->total_abs);
    json_num(&j, "l2", e->l2);
    json_str(&j, "z_unit", nonempty_or_null(info->z_unit));
    json_str(&j, "crs", nonempty_or_null(info->crs_name));
    if (checked) {
      json_num(&j, "threshold", s->max_error);
      json_bool(&j, "pass", pass);
    } else {
      json_null(&j, "threshold");
      json_null(&j, "pass");
    }
    json_open(&j, "seconds");
    json_num(&j, "read", t_read);
    json_num(&j, "eval", t_eval);
    json_num(&j, "total", app_now() - r->t0);
    json_close(&j);
    json_close(&j);
  } else if (!s->quiet) {
    FILE *o = r->out;
    fprintf(o, "DEM: %s, band %d: %zux%zu = %zu cells, %zu valid samples\n",
            s->input, s->band, info->width, info->height,
            info->width * info->height, e->samples);
    fprintf(o, "TIN: %s, layer %s: %zu triangles, %zu polygons rejected "
               "(not triangles), %zu degenerate\n",
            s->tin, lname, ev.triangles, rejected, ev.degenerate);
    if (e->max_col >= 0)
      fprintf(o, "max error:       %.9g %s at column %lld, row %lld "
                 "(x %.10g, y %.10g)\n",
              e->max_error, unit, (long long)e->max_col,
              (long long)e->max_row, mx, my);
    else
      fprintf(o, "max error:       %.9g %s\n", e->max_error, unit);
    fprintf(o, "RMS error:       %.9g %s\n", e->rmse, unit);
    fprintf(o, "mean abs error:  %.9g %s\n", e->mean_abs, unit);
    fprintf(o, "total abs error: %.9g %s\n", e->total_abs, unit);
    fprintf(o, "L2 error:        %.9g %s\n", e->l2, unit);
    fprintf(o, "coverage:        %zu of %zu valid samples covered, %zu "
               "uncovered, %zu overlapped\n",
            e->covered, e->samples, ev.uncovered, ev.overlapped);
    if (checked)
      fprintf(o, "check:           max error %.9g %s -max_error %.9g: %s\n",
              e->max_error, pass ? "<=" : ">", s->max_error,
              pass ? "pass" : "FAIL");
  }
  fflush(r->out);
  if (!pass) {
    char a[40], b[40];
    snprintf(a, sizeof a, "%.9g", e->max_error);
    snprintf(b, sizeof b, "%.9g", s->max_error);
    result_set(r->res, TT_APP_EXIT_THRESHOLD, TT_OK,
               "%s: max error %s %s exceeds -max_error %s", s->tin, a, unit,
               b);
  }

done:
  if (rsrs)
    OSRDestroySpatialReference(rsrs);
  if (tds)
    GDALClose(tds);
  if (src)
    GDALClose(src);
  free(xyz);
  tt_grid_destroy(grid);
  tt_raster_info_destroy(info);
  return st;
}

/* ===========================================================================
 * Running
 * ========================================================================= */

static void print_version(FILE *out)
{
  int maj = 0, min = 0, pat = 0;
  OSRGetPROJVersion(&maj, &min, &pat);
  fprintf(out, "terratin %s (%s; PROJ %d.%d.%d)\n", tt_version(),
          GDALVersionInfo("--version"), maj, min, pat);
}

tt_status tt_app_run(const tt_app_options *o, tt_app_result *out_result)
{
  tt_app_result local;
  tt_app_result *res = out_result ? out_result : &local;
  app_run r;
  tt_status st = TT_OK;
  result_ok(res);
  if (!o) {
    result_set(res, TT_APP_EXIT_USAGE, TT_ERR_ARG, "no options");
    return TT_ERR_ARG;
  }
  memset(&r, 0, sizeof r);
  r.o = o;
  r.s = &o->s;
  r.res = res;
  r.out = o->out ? o->out : stdout;
  r.err = o->err ? o->err : stderr;
  r.msg.err = r.err;
  r.prog.fn = o->progress;
  r.prog.arg = o->progress_arg;
  r.t0 = app_now();

  switch (o->s.command) {
  case TT_APP_HELP:
    fputs(tt_app_help(o->s.help_topic), r.out);
    fflush(r.out);
    return TT_OK;
  case TT_APP_VERSION:
    print_version(r.out);
    fflush(r.out);
    return TT_OK;
  case TT_APP_SIMPLIFY:
  case TT_APP_GENERATE:
  case TT_APP_EVAL:
    break;
  default:
    result_set(res, TT_APP_EXIT_USAGE, TT_ERR_ARG,
               "missing command: simplify, generate or eval");
    return TT_ERR_ARG;
  }

  /* Configuration first, so that GDAL_SKIP, GDAL_DRIVER_PATH and friends
   * apply to the drivers registered and to every file opened. */
  apply_config(&o->s);
  CPLPushErrorHandlerEx(on_gdal_message, &r.msg);
  GDALAllRegister();
  r.ctx = tt_context_create();
  if (!r.ctx) {
    result_set(res, TT_APP_EXIT_FAILURE, TT_ERR_NOMEM, "out of memory");
    st = TT_ERR_NOMEM;
    goto done;
  }
  tt_context_set_log(r.ctx, on_engine_warning, &r.msg);

  switch (o->s.command) {
  case TT_APP_SIMPLIFY: st = run_simplify(&r); break;
  case TT_APP_GENERATE: st = run_generate(&r); break;
  default: st = run_eval(&r); break;
  }
done:
  tt_context_destroy(r.ctx);
  CPLPopErrorHandler();
  fflush(r.out);
  fflush(r.err);
  if (st != TT_OK && res->exit_code == TT_APP_EXIT_OK)
    result_set(res, TT_APP_EXIT_FAILURE, st, "%s", tt_status_message(st));
  return st;
}
