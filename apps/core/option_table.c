/*
 * option_table.c -- apps/core/: the command's core, what every command's
 * folder shares. This file: the table of the terratin command's options
 * (see option_table.h), the look-up of a word in it, and the readers that
 * put a value where its entry says, one per kind of value. Adding an
 * option: an id in option_table.h, a line here (a new reader only for a
 * value of a new kind), and its field in tt_app_settings.
 *
 * Workload: a linear search over some 70 names per word of the command line.
 */
#include "option_table.h"

#include <limits.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

_Static_assert(2 * TT_MAX_VERTICES == 2147483646,
               "-max_triangles' message spells out TT_MAX_VERTICES");

/* --- the names, as the engine (or the table) knows them ------------------ */

/* Whether the value w is the name: case-insensitive, '-' as '_'. */
static int name_matches_word(const char *w, const char *name)
{
  for (;; w++, name++) {
    char a = *w, b = *name;
    if (a >= 'A' && a <= 'Z')
      a = (char)(a - 'A' + 'a');
    if (b >= 'A' && b <= 'Z')
      b = (char)(b - 'A' + 'a');
    if (a == '-')
      a = '_';
    if (b == '-')
      b = '_';
    if (a != b)
      return 0;
    if (!a)
      return 1;
  }
}

static int name_criterion(tt_context *ctx, const char *w, void *out)
{
  return tt_criterion_parse(ctx, w, out) == TT_OK;
}

static int name_optimize(tt_context *ctx, const char *w, void *out)
{
  return tt_optimize_parse(ctx, w, out) == TT_OK;
}

static int name_repair(tt_context *ctx, const char *w, void *out)
{
  return tt_repair_parse(ctx, w, out) == TT_OK;
}

static int name_importance(tt_context *ctx, const char *w, void *out)
{
  return tt_importance_parse(ctx, w, out) == TT_OK;
}

static int name_selection(tt_context *ctx, const char *w, void *out)
{
  return tt_selection_parse(ctx, w, out) == TT_OK;
}

static int name_hole(tt_context *ctx, const char *w, void *out)
{
  return tt_hole_parse(ctx, w, out) == TT_OK;
}

/* -start: out is the settings, as the start and its N both go there. */
static int name_start(tt_context *ctx, const char *w, void *out)
{
  tt_app_settings *s = out;
  return tt_decimate_start_parse(ctx, w, &s->start, &s->start_points) ==
         TT_OK;
}

/* -method: the int tt_app_settings.decimate. */
static int name_method(tt_context *ctx, const char *w, void *out)
{
  (void)ctx;
  if (!tt__app_str_ieq(w, "insert") && !tt__app_str_ieq(w, "decimate"))
    return 0;
  *(int *)out = tt__app_str_ieq(w, "decimate");
  return 1;
}

static int name_seeding(tt_context *ctx, const char *w, void *out)
{
  static const struct {
    const char *name;
    tt_synth_seeding value;
  } names[] = {{"none", TT_SEED_NONE},
               {"peak", TT_SEED_PEAK},
               {"valley", TT_SEED_VALLEY},
               {"hybrid", TT_SEED_HYBRID}};
  (void)ctx;
  for (size_t i = 0; i < sizeof names / sizeof names[0]; i++)
    if (tt__app_str_ieq(w, names[i].name)) {
      *(tt_synth_seeding *)out = names[i].value;
      return 1;
    }
  return 0;
}

/* -z_unit: the unit the heights are in. */
static int name_z_unit(tt_context *ctx, const char *w, void *out)
{
  static const char *const units[] = {"m", "ft", "us-ft"};
  (void)ctx;
  for (size_t i = 0; i < sizeof units / sizeof units[0]; i++)
    if (name_matches_word(w, units[i])) {
      *(const char **)out = units[i];
      return 1;
    }
  return 0;
}

/* -z_to: whether the heights are converted to metres. */
static int name_z_to(tt_context *ctx, const char *w, void *out)
{
  static const char *const modes[] = {"m", "native", "auto"};
  (void)ctx;
  for (size_t i = 0; i < sizeof modes / sizeof modes[0]; i++)
    if (tt__app_str_ieq(w, modes[i])) {
      *(const char **)out = modes[i];
      return 1;
    }
  return 0;
}

/* -tin_frame (eval): the int tt_app_settings.tin_frame, 1 map, 2 pixel. */
static int name_tin_frame(tt_context *ctx, const char *w, void *out)
{
  (void)ctx;
  if (!tt__app_str_ieq(w, "map") && !tt__app_str_ieq(w, "pixel"))
    return 0;
  *(int *)out = tt__app_str_ieq(w, "map") ? 1 : 2;
  return 1;
}

/* --- the values that fit no kind (OPT_OWN) ------------------------------- */

static tt_status own_srcnodata(tt__app_opt_parse *p, const tt__app_opt_def *d,
                               const char *v, void *out);
static tt_status own_threads(tt__app_opt_parse *p, const tt__app_opt_def *d,
                             const char *v, void *out);
static tt_status own_size(tt__app_opt_parse *p, const tt__app_opt_def *d,
                          const char *v, void *out);
static tt_status own_layers(tt__app_opt_parse *p, const tt__app_opt_def *d,
                            const char *v, void *out);
static tt_status own_box(tt__app_opt_parse *p, const tt__app_opt_def *d,
                         const char *v, void *out);
static tt_status own_tin_transform(tt__app_opt_parse *p,
                                   const tt__app_opt_def *d, const char *v,
                                   void *out);

/* --- the table ------------------------------------------------------------ */

#define ALL_COMMANDS (FOR_S | FOR_G | FOR_E | FOR_O | FOR_T | FOR_R)
#define DEM_READERS (FOR_S | FOR_E | FOR_O | FOR_T | FOR_R)
#define AT(field) .to = TO_OPTIONS, .at = offsetof(tt_app_options, field)
#define SYNTH(field) .to = TO_SYNTH, .at = offsetof(tt_synth_options, field)
#define CRS_NEEDED "needs a CRS (EPSG:n, WKT, ...)"
#define LIST_NEEDED "needs a comma-separated list"
#define AT_LEAST_1 "must be an integer >= 1"

static const tt__app_opt_def opt_defs[] = {
    {"-b", O_B, DEM_READERS, OPT_INT, AT(s.band), .min = 1, .max = INT_MAX,
     .bad = "must be a band number >= 1"},
    {"-max_error", O_MAX_ERROR, FOR_S | FOR_E | FOR_O, OPT_REAL,
     AT(s.max_error), .lo = 0, .hi = HUGE_VAL,
     .flags = OPT_PLUS_ZERO, /* -0 reads as "no limit" to the engine */
     .bad = "must be a finite number >= 0 (z units)"},
    {"-max_points", O_MAX_POINTS, FOR_S, OPT_SIZE, AT(s.max_points),
     .min = 1, .max = TT_MAX_VERTICES, .bad = AT_LEAST_1,
     .unit = "vertices"},
    {"-max_triangles", O_MAX_TRIANGLES, FOR_S, OPT_SIZE, AT(s.max_triangles),
     .min = 1, .max = 2 * TT_MAX_VERTICES, .bad = AT_LEAST_1,
     .unit = "triangles (twice the 1073741823 vertices a TIN may have)"},
    {"-percent", O_PERCENT, FOR_S, OPT_REAL, AT(s.percent), .lo = 0,
     .hi = 100, .flags = OPT_GT, .bad = "must be in (0, 100]"},
    /* study: a list, checked by the run */
    {"-percent", O_PERCENT, FOR_T, OPT_TEXT, AT(s.percents)},
    {"-of", O_OF, FOR_S | FOR_O | FOR_R, OPT_TEXT, AT(s.format),
     .flags = OPT_HINT, .need = "needs a driver name"},
    {"-f", O_OF, FOR_S | FOR_O, OPT_TEXT, AT(s.format), /* ogr2ogr's */
     .flags = OPT_HINT, .need = "needs a driver name"},
    {"-lco", O_LCO, FOR_S | FOR_O, OPT_LIST, AT(lco), .flags = OPT_PAIR,
     .bad = "expects NAME=VALUE"},
    {"-dsco", O_DSCO, FOR_S | FOR_O, OPT_LIST, AT(dsco), .flags = OPT_PAIR,
     .bad = "expects NAME=VALUE"},
    {"-nln", O_NLN, FOR_S | FOR_O, OPT_TEXT, AT(s.nln)},
    {"-overwrite", O_OVERWRITE, ALL_COMMANDS, OPT_FLAG, AT(s.overwrite)},
    {"-obj_local", O_OBJ_LOCAL, FOR_S, OPT_FLAG, AT(s.obj_local)},
    {"-q", O_Q, ALL_COMMANDS, OPT_FLAG, AT(s.quiet)},
    {"-quiet", O_Q, ALL_COMMANDS, OPT_FLAG, AT(s.quiet)},
    {"-criterion", O_CRITERION, FOR_S | FOR_O, OPT_NAME, AT(s.criterion),
     .name_fn = name_criterion}, /* .known: the engine's list */
    {"-optimize", O_OPTIMIZE, FOR_S | FOR_O, OPT_NAME, AT(s.optimize),
     .name_fn = name_optimize,
     .known = "local, lookahead, anneal, edge_insertion, none, auto"},
    {"-repair", O_REPAIR, FOR_S, OPT_NAME, AT(s.repair),
     .name_fn = name_repair,
     .known = "flip, local, lookahead, delaunay, auto"},
    {"-json", O_JSON, FOR_S | FOR_E | FOR_O | FOR_R, OPT_FLAG, AT(s.json)},
    {"-verbose", O_VERBOSE, FOR_S, OPT_FLAG, AT(s.verbose)},
    {"-layer", O_LAYER, FOR_E | FOR_O | FOR_R, OPT_TEXT, AT(s.layer),
     .need = "needs a layer name"},
    {"-size", O_SIZE, FOR_G, OPT_OWN, .to = TO_SYNTH, .at = 0, /* nx, ny */
     .own_fn = own_size,
     .bad = "must be N or NXxNY with sides >= 2"},
    /* also the anneal's seed and generate's (options.c) */
    {"-seed", O_SEED, FOR_G | FOR_S | FOR_O | FOR_T, OPT_U64, AT(s.seed),
     .bad = "must be an unsigned integer"},
    {"-iterations", O_ITERATIONS, FOR_G, OPT_SIZE, SYNTH(iterations),
     .min = 1, .max = SIZE_MAX, .bad = AT_LEAST_1},
    {"-displacement", O_DISPLACEMENT, FOR_G, OPT_REAL, SYNTH(displacement),
     .lo = 0, .hi = HUGE_VAL, .bad = "must be a finite number >= 0"},
    {"-wave_size", O_WAVE_SIZE, FOR_G, OPT_REAL, SYNTH(wave_size), .lo = 0,
     .hi = HUGE_VAL, .bad = "must be a finite number >= 0"},
    {"-roughness", O_ROUGHNESS, FOR_G, OPT_REAL, SYNTH(roughness), .lo = 0,
     .hi = HUGE_VAL, .flags = OPT_GT, .bad = "must be a finite number > 0"},
    {"-amplitude", O_AMPLITUDE, FOR_G, OPT_REAL, SYNTH(amplitude), .lo = 0,
     .hi = HUGE_VAL, .bad = "must be a finite number >= 0"},
    {"-seeding", O_SEEDING, FOR_G, OPT_NAME, SYNTH(seeding),
     .name_fn = name_seeding, .bad = "must be none, peak, valley or hybrid"},
    /* generate: the output's CRS; the DEM readers: the DEM's (dem_view.c) */
    {"-a_srs", O_A_SRS, FOR_G | DEM_READERS, OPT_TEXT, AT(s.srs),
     .need = CRS_NEEDED},
    {"-srcnodata", O_SRCNODATA, DEM_READERS, OPT_OWN, AT(s.srcnodata),
     .own_fn = own_srcnodata,
     .bad = "must be a finite decimal number or nan"},
    /* -z_factor_set follows (options.c) */
    {"-z_factor", O_Z_FACTOR, DEM_READERS, OPT_REAL, AT(s.z_factor),
     .lo = -HUGE_VAL, .hi = HUGE_VAL, .flags = OPT_NONZERO,
     .bad = "must be a finite non-zero number"},
    {"-z_unit", O_Z_UNIT, DEM_READERS, OPT_NAME, AT(s.z_unit),
     .name_fn = name_z_unit,
     .bad = "must be ft, us-ft or m (the unit the heights are in; -z_to m "
            "converts them to metres)"},
    {"-z_to", O_Z_TO, DEM_READERS, OPT_NAME, AT(s.z_to), .name_fn = name_z_to,
     .bad = "must be m (heights converted to metres), native (kept in their "
            "unit) or auto (metres when the CRS is in metres or geographic)"},
    {"-work_srs", O_WORK_SRS, FOR_S, OPT_TEXT, AT(s.work_srs),
     .need = CRS_NEEDED},
    {"-t_srs", O_T_SRS, FOR_S, OPT_TEXT, AT(s.t_srs), .need = CRS_NEEDED},
    {"-breaklines", O_BREAKLINES, FOR_S, OPT_TEXT, AT(s.breaklines)},
    {"-breaklines_layer", O_BREAKLINES_LAYER, FOR_S, OPT_TEXT,
     AT(s.breaklines_layer)},
    {"-breaklines_where", O_BREAKLINES_WHERE, FOR_S, OPT_TEXT,
     AT(s.breaklines_where)},
    {"-anneal_t0", O_ANNEAL_T0, FOR_S | FOR_O | FOR_T, OPT_REAL,
     AT(s.anneal.t0), .lo = 0, .hi = HUGE_VAL, .flags = OPT_GT,
     .bad = "must be a finite number > 0 (the start temperature, in swap "
            "value units)"},
    {"-anneal_stages", O_ANNEAL_STAGES, FOR_S | FOR_O | FOR_T, OPT_INT,
     AT(s.anneal.stages), .min = 1, .max = 1000000,
     .bad = "must be an integer in [1, 1000000]"},
    {"-anneal_swaps", O_ANNEAL_SWAPS, FOR_S | FOR_O | FOR_T, OPT_REAL,
     AT(s.anneal.swaps), .lo = 0, .hi = 1e6, .flags = OPT_GT,
     .bad = "must be a number in (0, 1e6] (per edge)"},
    {"-anneal_good", O_ANNEAL_GOOD, FOR_S | FOR_O | FOR_T, OPT_REAL,
     AT(s.anneal.good), .lo = 0, .hi = 1e6, .flags = OPT_GT,
     .bad = "must be a number in (0, 1e6] (per edge)"},
    {"-anneal_r", O_ANNEAL_R, FOR_S | FOR_O | FOR_T, OPT_REAL, AT(s.anneal.r),
     .lo = 0, .hi = 1, .flags = OPT_GT | OPT_LT, .bad = "must be in (0, 1)"},
    {"-method", O_METHOD, FOR_S, OPT_NAME, AT(s.decimate),
     .name_fn = name_method, .known = "insert, decimate"},
    {"-start", O_START, FOR_S | FOR_T, OPT_NAME, AT(s),
     .flags = OPT_DECIMATE, .name_fn = name_start,
     .known = "all, greedy, greedy:N (N >= 3)"},
    {"-importance", O_IMPORTANCE, FOR_S | FOR_T, OPT_NAME, AT(s.importance),
     .flags = OPT_DECIMATE, .name_fn = name_importance,
     .known = "degree, hdh, abh, volume, drop, error, auto"},
    {"-selection", O_SELECTION, FOR_S, OPT_NAME, AT(s.selection),
     .flags = OPT_DECIMATE, .name_fn = name_selection,
     .known = "independent, sequential"},
    {"-onepass", O_ONEPASS, FOR_S, OPT_FLAG, AT(s.onepass),
     .flags = OPT_DECIMATE},
    {"-hole", O_HOLE, FOR_S, OPT_NAME, AT(s.hole), .flags = OPT_DECIMATE,
     .name_fn = name_hole, .known = "minangle, circumradius, dp, auto"},
    /* a count, or ALL_CPUS */
    {"-threads", O_THREADS, FOR_S | FOR_T, OPT_OWN, AT(s.threads),
     .own_fn = own_threads, .min = 1, .max = TT_APP_MAX_THREADS,
     .bad = "must be an integer >= 1 or ALL_CPUS", .unit = "threads"},
    {"-max_memory", O_MAX_MEMORY, FOR_S | FOR_E | FOR_R, OPT_SIZE,
     AT(s.max_memory), .flags = OPT_MEM, .min = 1, .max = SIZE_MAX,
     .bad = "must be a size of at least 1 byte: bytes, or a number with K, "
            "M, G or T (e.g. 500M, 2G)",
     .unit = "bytes"},
    {"-fill_nodata", O_FILL_NODATA, FOR_S | FOR_E, OPT_SIZE,
     AT(s.fill_nodata), .min = 1, .max = INT32_MAX,
     .bad = "must be a number of samples from 1 to 2147483647",
     .unit = "samples"},
    {"-min_patch", O_MIN_PATCH, FOR_S, OPT_SIZE, AT(s.min_patch), .min = 1,
     .max = SIZE_MAX, .bad = AT_LEAST_1, .unit = "samples"},
    {"-tile_size", O_TILE_SIZE, FOR_S, OPT_SIZE, AT(s.tile_size), .min = 16,
     .max = 65536, .bad = "must be 16 to 65536 cells"},
    {"-terrain", O_TERRAIN, FOR_T, OPT_LIST, AT(terrains), .flags = OPT_HINT,
     .need = "needs a DEM file or a terrain name"},
    {"-criteria", O_CRITERIA, FOR_T, OPT_TEXT, AT(s.criteria),
     .flags = OPT_HINT, .need = LIST_NEEDED},
    {"-methods", O_METHODS, FOR_T, OPT_TEXT, AT(s.methods), .flags = OPT_HINT,
     .need = LIST_NEEDED},
    {"-optimizers", O_OPTIMIZERS, FOR_T, OPT_TEXT, AT(s.optimizers),
     .flags = OPT_HINT, .need = LIST_NEEDED},
    {"-error_raster", O_ERROR_RASTER, FOR_E, OPT_TEXT, AT(s.error_raster),
     .flags = OPT_HINT, .need = "needs a file name"},
    {"-co", O_CO, FOR_E | FOR_R, OPT_LIST, AT(co), .flags = OPT_PAIR,
     .bad = "expects NAME=VALUE"},
    /* study: a row at every point count up to N */
    {"-points", O_POINTS, FOR_T, OPT_SIZE, AT(s.points), .min = 1,
     .max = TT_MAX_VERTICES, .bad = AT_LEAST_1, .unit = "vertices"},
    {"-plot", O_PLOT, FOR_T, OPT_FLAG, AT(s.plot)},
    {"-tin_points", O_TIN_POINTS, FOR_T, OPT_SIZE, AT(s.tin_points),
     .min = 3, .max = SIZE_MAX,
     .bad = "must be an integer >= 3 (the points of the TINs to draw)"},
    {"-layers", O_LAYERS, FOR_S, OPT_OWN, AT(s.layers),
     .own_fn = own_layers},
    {"-nostyle", O_NOSTYLE, FOR_S, OPT_FLAG, AT(s.nostyle)},
    /* GDAL's input options (dem_view.c); -s_srs as gdalwarp's: reading,
     * the same as -a_srs; -a_nodata is -srcnodata's GDAL name */
    {"-s_srs", O_S_SRS, DEM_READERS, OPT_TEXT, AT(s.srs), .need = CRS_NEEDED},
    {"-a_nodata", O_A_NODATA, DEM_READERS, OPT_OWN, AT(s.srcnodata),
     .own_fn = own_srcnodata,
     .bad = "must be a finite decimal number or nan"},
    {"-srcwin", O_SRCWIN, DEM_READERS, OPT_OWN, AT(s.srcwin),
     .own_fn = own_box, .nwords = 4,
     .bad = "needs xoff yoff xsize ysize: integers, sizes >= 1"},
    {"-projwin", O_PROJWIN, DEM_READERS, OPT_OWN, AT(s.projwin),
     .own_fn = own_box, .nwords = 4,
     .bad = "needs ulx uly lrx lry: finite numbers, ulx < lrx, uly > lry"},
    {"-projwin_srs", O_PROJWIN_SRS, DEM_READERS, OPT_TEXT,
     AT(s.projwin_srs), .need = CRS_NEEDED},
    {"-a_ullr", O_A_ULLR, DEM_READERS, OPT_OWN, AT(s.a_ullr),
     .own_fn = own_box, .nwords = 4,
     .bad = "needs ulx uly lrx lry: finite numbers, ulx != lrx, uly != lry"},
    /* eval: the frame of a TIN file's coordinates, and an affine before */
    {"-tin_frame", O_TIN_FRAME, FOR_E, OPT_NAME, AT(s.tin_frame),
     .name_fn = name_tin_frame, .known = "map, pixel"},
    {"-stl_frame", O_TIN_FRAME, FOR_E, OPT_NAME, AT(s.tin_frame),
     .name_fn = name_tin_frame, .known = "map, pixel"},
    {"-tin_transform", O_TIN_TRANSFORM, FOR_E, OPT_OWN, AT(s),
     .own_fn = own_tin_transform,
     .bad = "must be six comma-separated numbers sx,sy,sz,ox,oy,oz "
            "(x' = sx x + ox, ...), sx, sy, sz non-zero"},
};

#define OPT_DEFS (sizeof opt_defs / sizeof opt_defs[0])

/* Whether the word w spells the option name: case-insensitive, and '-'
 * inside the name matches '_' (-max-error is -max_error); the leading dash
 * is the option's, not a letter of its name. */
static int name_matches(const char *w, const char *name)
{
  return *w == '-' && *name == '-' && name_matches_word(w + 1, name + 1);
}

const tt__app_opt_def *tt__app_find_opt(const char *w)
{
  for (size_t i = 0; i < OPT_DEFS; i++)
    if (name_matches(w, opt_defs[i].name))
      return &opt_defs[i];
  /* GDAL accepts --of as well as -of for its own options: do the same,
   * with exactly two dashes ("---of" is a typo, not an option). */
  if (w[0] == '-' && w[1] == '-' && w[2] != '\0' && w[2] != '-')
    return tt__app_find_opt(w + 1);
  return NULL;
}

/* The optimal string alignment distance between a and b (Levenshtein's
 * edits plus the swap of two neighbours: -max_erorr is one edit away),
 * without regard to case, '-' as '_'; anything past 63 characters counts
 * as far. */
size_t tt__app_edit_distance(const char *a, const char *b)
{
  enum { MAXLEN = 63 };
  char x[MAXLEN + 1], y[MAXLEN + 1];
  size_t n = 0, m = 0;
  for (; a[n] && n < MAXLEN; n++)
    x[n] = a[n] == '-' ? '_' : (char)((a[n] >= 'A' && a[n] <= 'Z')
                                          ? a[n] - 'A' + 'a' : a[n]);
  for (; b[m] && m < MAXLEN; m++)
    y[m] = b[m] == '-' ? '_' : (char)((b[m] >= 'A' && b[m] <= 'Z')
                                          ? b[m] - 'A' + 'a' : b[m]);
  if (a[n] || b[m])
    return SIZE_MAX;
  /* three rows of the dynamic programme: i-2, i-1, i */
  size_t rows[3][MAXLEN + 1];
  for (size_t j = 0; j <= m; j++)
    rows[0][j] = j;
  for (size_t i = 1; i <= n; i++) {
    size_t *cur = rows[i % 3], *prev = rows[(i - 1) % 3],
           *prev2 = rows[(i + 1) % 3];
    cur[0] = i;
    for (size_t j = 1; j <= m; j++) {
      size_t cost = x[i - 1] != y[j - 1];
      size_t best = prev[j - 1] + cost;
      if (prev[j] + 1 < best)
        best = prev[j] + 1;
      if (cur[j - 1] + 1 < best)
        best = cur[j - 1] + 1;
      if (i > 1 && j > 1 && x[i - 1] == y[j - 2] && x[i - 2] == y[j - 1] &&
          prev2[j - 2] + 1 < best)
        best = prev2[j - 2] + 1;
      cur[j] = best;
    }
  }
  return rows[n % 3][m];
}

const char *tt__app_opt_suggest(const char *w, tt_app_command command)
{
  while (w[0] == '-' && w[1] == '-') /* --max-eror: as -max-eror */
    w++;
  size_t len = strlen(w), best = SIZE_MAX;
  const char *name = NULL;
  /* a third of the word's letters, at least 1, at most 3 */
  size_t limit = len / 3 < 1 ? 1 : len / 3 > 3 ? 3 : len / 3;
  for (size_t i = 0; i < OPT_DEFS; i++) {
    if (!(opt_defs[i].commands & (1u << command)))
      continue;
    size_t d = tt__app_edit_distance(w, opt_defs[i].name);
    if (d < best) { /* ties: the table's first, the more common option */
      best = d;
      name = opt_defs[i].name;
    }
  }
  /* and fewer edits than half the letters: -x is no typo of -b */
  return best <= limit && 2 * best < len - 1 ? name : NULL;
}

const tt__app_opt_def *tt__app_opt_for(const tt__app_opt_def *d,
                                       tt_app_command command)
{
  for (size_t i = 0; i < OPT_DEFS; i++)
    if (name_matches(d->name, opt_defs[i].name) &&
        (opt_defs[i].commands & (1u << command)))
      return &opt_defs[i];
  return NULL;
}

int tt__app_opt_takes_value(const tt__app_opt_def *d)
{
  if (d->kind == OPT_FLAG)
    return 0;
  return d->nwords ? (int)d->nwords : 1;
}

/* The option's name in the messages about its value: its first spelling. */
static const char *label(const tt__app_opt_def *d)
{
  for (size_t i = 0; i < OPT_DEFS; i++)
    if (opt_defs[i].id == d->id)
      return opt_defs[i].name;
  return d->name;
}

const char *tt__app_opt_keep(tt_app_options *o, const char *w)
{
  if (!tt__app_strlist_add(&o->strings, w))
    return NULL;
  return o->strings.v[o->strings.n - 1];
}

/* --- the readers, one per kind ------------------------------------------ */

static tt_status refuse(tt__app_opt_parse *p, const tt__app_opt_def *d,
                        const char *v)
{
  return OPT_USAGE(p, "%s: %s %s, got '%s'", p->cmdname, label(d), d->bad, v);
}

/* OPT_TEXT and OPT_LIST: an empty value, when the option needs one. */
static tt_status refuse_empty(tt__app_opt_parse *p, const tt__app_opt_def *d)
{
  return OPT_USAGE(p, "%s: %s %s%s", p->cmdname, label(d), d->need,
                   (d->flags & OPT_HINT) ? p->hint : "");
}

static tt_status read_text(tt__app_opt_parse *p, const tt__app_opt_def *d,
                           const char *v, void *out)
{
  if (d->need && !*v)
    return refuse_empty(p, d);
  const char *kept = tt__app_opt_keep(p->o, v);
  if (!kept)
    return OPT_NOMEM(p);
  *(const char **)out = kept;
  return TT_OK;
}

static tt_status read_list(tt__app_opt_parse *p, const tt__app_opt_def *d,
                           const char *v, void *out)
{
  if (d->need && !*v)
    return refuse_empty(p, d);
  const char *eq = strchr(v, '=');
  if ((d->flags & OPT_PAIR) && (!eq || eq == v))
    return refuse(p, d, v);
  if (!tt__app_strlist_add(out, v))
    return OPT_NOMEM(p);
  return TT_OK;
}

static tt_status read_real(tt__app_opt_parse *p, const tt__app_opt_def *d,
                           const char *v, void *out)
{
  double x;
  if (!tt__app_parse_double(v, &x) || ((d->flags & OPT_NONZERO) && x == 0) ||
      ((d->flags & OPT_GT) ? !(x > d->lo) : !(x >= d->lo)) ||
      ((d->flags & OPT_LT) ? !(x < d->hi) : !(x <= d->hi)))
    return refuse(p, d, v);
  *(double *)out = (d->flags & OPT_PLUS_ZERO) ? x + 0.0 : x;
  return TT_OK;
}

/* OPT_INT and OPT_SIZE: below min is bad; above max (or beyond SIZE_MAX)
 * is above the limit, said so when the entry has a unit. */
static tt_status read_count(tt__app_opt_parse *p, const tt__app_opt_def *d,
                            const char *v, void *out)
{
  size_t z = 0;
  int k = (d->flags & OPT_MEM) ? tt__app_parse_mem_size(v, &z)
                               : tt__app_parse_size(v, &z);
  if (k == NUM_BAD || (k == NUM_OK && z < d->min))
    return refuse(p, d, v);
  if (k != NUM_OK || z > d->max) {
    if (!d->unit)
      return refuse(p, d, v);
    return OPT_USAGE(p, "%s: %s %s is above the limit of %zu %s", p->cmdname,
                     label(d), v, d->max, d->unit);
  }
  if (d->kind == OPT_INT)
    *(int *)out = (int)z;
  else
    *(size_t *)out = z;
  return TT_OK;
}

static tt_status read_u64(tt__app_opt_parse *p, const tt__app_opt_def *d,
                          const char *v, void *out)
{
  uint64_t u;
  if (tt__app_parse_u64(v, &u) != NUM_OK)
    return refuse(p, d, v);
  *(uint64_t *)out = u;
  return TT_OK;
}

/* The engine's criteria, so new ones show up in the message by themselves. */
static const char *known_criteria(char *known, size_t size)
{
  size_t n = 0;
  known[0] = '\0';
  for (int ci = 0; ci < 64 && n < size; ci++) {
    const char *name = tt_criterion_name((tt_criterion)ci);
    if (!name)
      break;
    n += (size_t)snprintf(known + n, size - n, "%s%s", ci ? ", " : "", name);
  }
  return known;
}

static tt_status read_name(tt__app_opt_parse *p, const tt__app_opt_def *d,
                           const char *v, void *out)
{
  char known[256];
  if (d->name_fn(p->ctx, v, out))
    return TT_OK;
  if (d->bad)
    return refuse(p, d, v);
  if (!d->known)
    known_criteria(known, sizeof known);
  return OPT_USAGE(p, "%s: unknown %s '%s'; known: %s", p->cmdname, label(d),
                   v, d->known ? d->known : known);
}

/* The band's own mask is used unless -srcnodata names a number or nan. */
static tt_status own_srcnodata(tt__app_opt_parse *p, const tt__app_opt_def *d,
                               const char *v, void *out)
{
  double x;
  if (!tt__app_str_ieq(v, "nan") && !tt__app_parse_double(v, &x))
    return refuse(p, d, v);
  const char *kept = tt__app_opt_keep(p->o, v);
  if (!kept)
    return OPT_NOMEM(p);
  *(const char **)out = kept;
  return TT_OK;
}

static tt_status own_threads(tt__app_opt_parse *p, const tt__app_opt_def *d,
                             const char *v, void *out)
{
  if (tt__app_str_ieq(v, "ALL_CPUS")) {
    *(int *)out = -1;
    return TT_OK;
  }
  size_t z = 0; /* read_count stores a size_t for every kind but OPT_INT */
  tt_status st = read_count(p, d, v, &z);
  if (st == TT_OK)
    *(int *)out = (int)z;
  return st;
}

/* -srcwin, -projwin, -a_ullr: four numbers, the words joined by spaces.
 * -srcwin's are samples (offsets may be negative: the window is clipped
 * to the raster when read, as dem_view.c says), -projwin's a window
 * whose upper left is above and left of its lower right, -a_ullr's any
 * box of non-zero width and height. */
static tt_status own_box(tt__app_opt_parse *p, const tt__app_opt_def *d,
                         const char *v, void *out)
{
  tt_app_box *b = out;
  double x[4];
  char word[64];
  const char *at = v;
  for (int i = 0; i < 4; i++) {
    const char *e = strchr(at, ' ');
    size_t n = e ? (size_t)(e - at) : strlen(at);
    if (n == 0 || n >= sizeof word || (i < 3) != (e != NULL))
      return refuse(p, d, v);
    memcpy(word, at, n);
    word[n] = '\0';
    if (!tt__app_parse_double(word, &x[i]))
      return refuse(p, d, v);
    at = e ? e + 1 : at + n;
  }
  if (d->id == O_SRCWIN) {
    for (int i = 0; i < 4; i++)
      if (x[i] != floor(x[i]) || fabs(x[i]) > (double)INT_MAX)
        return refuse(p, d, v);
    if (x[2] < 1 || x[3] < 1)
      return refuse(p, d, v);
  } else if (d->id == O_PROJWIN && !(x[0] < x[2] && x[1] > x[3])) {
    return refuse(p, d, v);
  } else if (d->id == O_A_ULLR && (x[0] == x[2] || x[1] == x[3])) {
    return refuse(p, d, v);
  }
  b->set = 1;
  memcpy(b->v, x, sizeof x);
  return TT_OK;
}

/* -size N or NXxNY: out is the parameters (nx and ny). */
static tt_status own_size(tt__app_opt_parse *p, const tt__app_opt_def *d,
                          const char *v, void *out)
{
  tt_synth_options *y = out;
  size_t nx = 0, ny = 0;
  if (!tt__app_parse_grid_size(v, &nx, &ny) || nx < 2 || ny < 2 ||
      nx > TT_MAX_GRID_SIDE || ny > TT_MAX_GRID_SIDE)
    return refuse(p, d, v);
  if (nx > SIZE_MAX / ny || nx * ny > (size_t)1 << 31)
    return OPT_USAGE(p, "%s: -size '%s' is too large (at most 2^31 samples)",
                     p->cmdname, v);
  y->nx = nx;
  y->ny = ny;
  return TT_OK;
}

/* -layers: a comma-separated subset of the three layers, each once. */
static tt_status own_layers(tt__app_opt_parse *p, const tt__app_opt_def *d,
                            const char *v, void *out)
{
  unsigned mask = 0;
  const char *at = v;
  (void)d;
  for (;;) {
    const char *e = strchr(at, ',');
    size_t n = e ? (size_t)(e - at) : strlen(at);
    unsigned bit = tt__app_layer_bit(at, n);
    if (!bit)
      return OPT_USAGE(p, "%s: -layers '%s': '%.*s' is not a layer "
                       "(triangles, vertices, run_parameters)",
                       p->cmdname, v, (int)n, at);
    if (mask & bit)
      return OPT_USAGE(p, "%s: -layers '%s': %.*s is named twice",
                       p->cmdname, v, (int)n, at);
    mask |= bit;
    if (!e)
      break;
    at = e + 1;
  }
  *(unsigned *)out = mask;
  return TT_OK;
}

tt_status tt__app_opt_apply(tt__app_opt_parse *p, const tt__app_opt_def *d,
                            const char *v)
{
  char *base = d->to == TO_SYNTH ? (char *)&p->synth : (char *)p->o;
  void *out = base + d->at;
  tt_status st = TT_OK;
  switch (d->kind) {
  case OPT_FLAG: *(int *)out = 1; break;
  case OPT_TEXT: st = read_text(p, d, v, out); break;
  case OPT_LIST: st = read_list(p, d, v, out); break;
  case OPT_REAL: st = read_real(p, d, v, out); break;
  case OPT_INT:
  case OPT_SIZE: st = read_count(p, d, v, out); break;
  case OPT_U64: st = read_u64(p, d, v, out); break;
  case OPT_NAME: st = read_name(p, d, v, out); break;
  case OPT_OWN: st = d->own_fn(p, d, v, out); break;
  }
  if (st != TT_OK)
    return st;
  OPT_SET_GIVEN(p, d->id);
  if ((d->flags & OPT_DECIMATE) && !p->decimate_only)
    p->decimate_only = d->name;
  return TT_OK;
}

/* -tin_transform sx,sy,sz,ox,oy,oz: out is the settings (the six numbers
 * and the flag both go there). */
static tt_status own_tin_transform(tt__app_opt_parse *p,
                                   const tt__app_opt_def *d, const char *v,
                                   void *out)
{
  tt_app_settings *s = out;
  double t[6];
  const char *at = v;
  for (int k = 0; k < 6; k++) {
    char word[64];
    const char *comma = strchr(at, ',');
    size_t n = comma ? (size_t)(comma - at) : strlen(at);
    if ((comma == NULL) != (k == 5) || n == 0 || n >= sizeof word)
      return refuse(p, d, v);
    memcpy(word, at, n);
    word[n] = '\0';
    if (!tt__app_parse_double(word, &t[k]) || (k < 3 && t[k] == 0))
      return refuse(p, d, v);
    at = comma ? comma + 1 : at + n;
  }
  memcpy(s->tin_transform, t, sizeof t);
  s->tin_transform_set = 1;
  return TT_OK;
}
