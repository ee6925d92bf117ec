/*
 * options.c -- the command line of terratin: one table of options (which
 * option applies to which subcommand, whether it takes a value), the parser
 * that turns the words after the program name into a tt_app_options object
 * (its accessors are in settings.c, the values of words in values.c).
 *
 * Invariants: parsing has no side effects beyond the options object (GDAL is
 * not touched: --config is applied by tt_app_run); --help and --version win
 * over anything else on the line; a usage error is one line naming the word
 * at fault and the help page to read.
 *
 * Workload: a single pass over a few dozen words.
 */
#include "app.h"
#include "option_table.h"

#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

static const char *const empty_list[] = {NULL};

/* ===========================================================================
 * Parsing
 * ========================================================================= */

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

#define USAGE(...)                                                             \
  do {                                                                         \
    tt__app_result_set(res, TT_APP_EXIT_USAGE, TT_ERR_ARG, __VA_ARGS__);       \
    st = TT_ERR_ARG;                                                           \
    goto done;                                                                 \
  } while (0)

#define NOMEM()                                                                \
  do {                                                                         \
    tt__app_result_set(res, TT_APP_EXIT_FAILURE, TT_ERR_NOMEM,                 \
                       "out of memory");                                       \
    st = TT_ERR_NOMEM;                                                         \
    goto done;                                                                 \
  } while (0)

static int is_help_word(const char *w)
{
  return tt__app_str_ieq(w, "--help") || tt__app_str_ieq(w, "-help") ||
         tt__app_str_ieq(w, "-h") || tt__app_str_ieq(w, "-?");
}

static const char *keep(tt_app_options *o, const char *w)
{
  if (!tt__app_strlist_add(&o->strings, w))
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
  const char *decimate_only = NULL; /* the first decimation-only option */
  const char *cmdname = "";
  char hint[64] = "";
  memset(&sf, 0, sizeof sf);
  tt__app_result_ok(res);
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
  o->s.layers = TT_APP_LAYERS_ALL;
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
    else if (tt__app_str_ieq(w, "--version"))
      want_version = 1;
    else if (first_cmd == TT_APP_NONE && w[0] != '-') {
      if (tt__app_str_ieq(w, "simplify")) first_cmd = TT_APP_SIMPLIFY;
      else if (tt__app_str_ieq(w, "generate")) first_cmd = TT_APP_GENERATE;
      else if (tt__app_str_ieq(w, "eval")) first_cmd = TT_APP_EVAL;
      else if (tt__app_str_ieq(w, "optimize")) first_cmd = TT_APP_OPTIMIZE;
      else if (tt__app_str_ieq(w, "study")) first_cmd = TT_APP_STUDY;
      else if (tt__app_str_ieq(w, "rasterize")) first_cmd = TT_APP_RASTERIZE;
      else if (tt__app_str_ieq(w, "help")) { want_help = 1; continue; }
      if (first_cmd == TT_APP_NONE)
        break; /* an unknown command: reported below */
    }
    /* skip the values of the global options */
    if (tt__app_str_ieq(w, "--config")) {
      size_t skip = (argv[i + 1] && strchr(argv[i + 1], '=')) ? 1 : 2;
      for (size_t k = 0; k < skip && argv[i + 1]; k++)
        i++;
    } else if (tt__app_str_ieq(w, "--debug") && argv[i + 1]) {
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
    if (tt__app_str_ieq(w, "--config")) {
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
        int ok = tt__app_strlist_add(&o->config, key) &&
                 tt__app_strlist_add(&o->config, eq + 1);
        free(key);
        if (!ok)
          NOMEM();
        i += 1;
      } else {
        if (!argv[i + 2])
          USAGE("--config %s needs a VALUE", k);
        if (!*k)
          USAGE("--config needs a non-empty KEY");
        if (!tt__app_strlist_add(&o->config, k) ||
            !tt__app_strlist_add(&o->config, argv[i + 2]))
          NOMEM();
        i += 2;
      }
      continue;
    }
    if (tt__app_str_ieq(w, "--debug")) {
      if (!argv[i + 1])
        USAGE("--debug needs a value: on or off");
      if (!tt__app_is_gdal_bool(argv[i + 1]))
        USAGE("--debug must be on, off, yes, no, true, false, 1 or 0, got "
              "'%s'", argv[i + 1]);
      if (!tt__app_strlist_add(&o->config, "CPL_DEBUG") ||
          !tt__app_strlist_add(&o->config, argv[i + 1]))
        NOMEM();
      i += 1;
      continue;
    }

    if (o->s.command == TT_APP_NONE) {
      if (w[0] == '-' && w[1] != '\0')
        USAGE("unknown option '%s' before the command; expected simplify, "
              "generate, eval, optimize, study or rasterize (see 'terratin "
              "--help')", w);
      if (tt__app_str_ieq(w, "simplify")) o->s.command = TT_APP_SIMPLIFY;
      else if (tt__app_str_ieq(w, "generate")) o->s.command = TT_APP_GENERATE;
      else if (tt__app_str_ieq(w, "eval")) o->s.command = TT_APP_EVAL;
      else if (tt__app_str_ieq(w, "optimize")) o->s.command = TT_APP_OPTIMIZE;
      else if (tt__app_str_ieq(w, "study")) o->s.command = TT_APP_STUDY;
      else if (tt__app_str_ieq(w, "rasterize")) o->s.command = TT_APP_RASTERIZE;
      else
        USAGE("unknown command '%s'; expected simplify, generate, eval, "
              "optimize, study or rasterize (see 'terratin --help')", w);
      cmdname = tt__app_command_name(o->s.command);
      snprintf(hint, sizeof hint, " (see 'terratin %s --help')", cmdname);
      continue;
    }

    /* "-" alone and negative numbers are positional words. */
    const tt__app_opt_def *d = NULL;
    double dummy;
    if (w[0] == '-' && w[1] != '\0' && !tt__app_parse_double(w, &dummy)) {
      d = tt__app_find_opt(w);
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
      if (npos >= (o->s.command == TT_APP_OPTIMIZE ||
                   o->s.command == TT_APP_RASTERIZE ? 3u : 2u))
        USAGE("%s: unexpected argument '%s'%s", cmdname, w, hint);
      pos[npos++] = w;
      continue;
    }

    size_t z = 0;
    double x;
    uint64_t u;
    int k; /* what parse_size or parse_mem_size found */
    switch (d->id) {
    case O_B:
      if ((k = tt__app_parse_size(v, &z)) == NUM_BAD || (k == NUM_OK && z < 1))
        USAGE("%s: -b must be a band number >= 1, got '%s'", cmdname, v);
      if (k != NUM_OK || z > INT_MAX)
        USAGE("%s: -b must be a band number >= 1, got '%s'", cmdname, v);
      o->s.band = (int)z;
      break;
    case O_MAX_ERROR:
      if (!tt__app_parse_double(v, &x) || x < 0)
        USAGE("%s: -max_error must be a finite number >= 0 (z units), got "
              "'%s'", cmdname, v);
      o->s.max_error = x + 0.0; /* -0 reads as "no limit" to the engine */
      break;
    case O_MAX_POINTS:
      if ((k = tt__app_parse_size(v, &z)) == NUM_BAD || (k == NUM_OK && z < 1))
        USAGE("%s: -max_points must be an integer >= 1, got '%s'", cmdname,
              v);
      if (k != NUM_OK || z > TT_MAX_VERTICES)
        USAGE("%s: -max_points %s is above the limit of %zu vertices",
              cmdname, v, (size_t)TT_MAX_VERTICES);
      o->s.max_points = z;
      break;
    case O_MAX_TRIANGLES:
      if ((k = tt__app_parse_size(v, &z)) == NUM_BAD || (k == NUM_OK && z < 1))
        USAGE("%s: -max_triangles must be an integer >= 1, got '%s'",
              cmdname, v);
      if (k != NUM_OK || z > 2 * TT_MAX_VERTICES)
        USAGE("%s: -max_triangles %s is above the limit of %zu triangles "
              "(twice the %zu vertices a TIN may have)", cmdname, v,
              2 * (size_t)TT_MAX_VERTICES, (size_t)TT_MAX_VERTICES);
      o->s.max_triangles = z;
      break;
    case O_PERCENT:
      if (o->s.command == TT_APP_STUDY) { /* a list, checked by the run */
        if (!(o->s.percents = keep(o, v)))
          NOMEM();
        break;
      }
      if (!tt__app_parse_double(v, &x) || !(x > 0 && x <= 100))
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
    case O_DSCO:
    case O_CO: {
      const char *eq = strchr(v, '=');
      if (!eq || eq == v)
        USAGE("%s: %s expects NAME=VALUE, got '%s'", cmdname, d->name, v);
      if (!tt__app_strlist_add(d->id == O_LCO    ? &o->lco
                               : d->id == O_DSCO ? &o->dsco
                                                 : &o->co, v))
        NOMEM();
      break;
    }
    case O_NLN:
      if (!(o->s.nln = keep(o, v)))
        NOMEM();
      break;
    case O_OVERWRITE: o->s.overwrite = 1; break;
    case O_OBJ_LOCAL: o->s.obj_local = 1; break;
    case O_NOSTYLE: o->s.nostyle = 1; break;
    case O_LAYERS: {
      /* a comma-separated subset of the three layers, each once */
      unsigned mask = 0;
      const char *p = v;
      for (;;) {
        const char *e = strchr(p, ',');
        size_t n = e ? (size_t)(e - p) : strlen(p);
        unsigned bit = tt__app_layer_bit(p, n);
        if (!bit)
          USAGE("%s: -layers '%s': '%.*s' is not a layer (triangles, "
                "vertices, run_parameters)", cmdname, v, (int)n, p);
        if (mask & bit)
          USAGE("%s: -layers '%s': %.*s is named twice", cmdname, v,
                (int)n, p);
        mask |= bit;
        if (!e)
          break;
        p = e + 1;
      }
      o->s.layers = mask;
      break;
    }
    case O_Q: o->s.quiet = 1; break;
    case O_JSON: o->s.json = 1; break;
    case O_CRITERION: {
      tt_criterion c;
      if (tt_criterion_parse(ctx, v, &c) != TT_OK) {
        /* The engine's list, so new criteria show up here by themselves. */
        char known[256] = "";
        size_t n = 0;
        for (int ci = 0; ci < 64 && n < sizeof known; ci++) {
          const char *name = tt_criterion_name((tt_criterion)ci);
          if (!name)
            break;
          n += (size_t)snprintf(known + n, sizeof known - n, "%s%s",
                                ci ? ", " : "", name);
        }
        USAGE("%s: unknown -criterion '%s'; known: %s", cmdname, v, known);
      }
      o->s.criterion = c;
      break;
    }
    case O_OPTIMIZE:
      if (tt_optimize_parse(ctx, v, &o->s.optimize) != TT_OK)
        USAGE("%s: unknown -optimize '%s'; known: local, lookahead, anneal, "
              "edge_insertion, none, auto", cmdname, v);
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
      if (!tt__app_parse_grid_size(v, &sf.nx, &sf.ny) || sf.nx < 2 ||
          sf.ny < 2 || sf.nx > TT_MAX_GRID_SIDE || sf.ny > TT_MAX_GRID_SIDE)
        USAGE("%s: -size must be N or NXxNY with sides >= 2, got '%s'",
              cmdname, v);
      if (sf.nx > SIZE_MAX / sf.ny ||
          sf.nx * sf.ny > (size_t)1 << 31)
        USAGE("%s: -size '%s' is too large (at most 2^31 samples)", cmdname,
              v);
      sf.size = 1;
      break;
    case O_SEED:
      if (tt__app_parse_u64(v, &u) != NUM_OK)
        USAGE("%s: -seed must be an unsigned integer, got '%s'", cmdname, v);
      sf.seed = 1;
      sf.seed_value = u;
      o->s.seed = u;
      o->s.seed_set = 1;
      o->s.anneal.seed = u;
      break;
    case O_ANNEAL_T0:
      if (!tt__app_parse_double(v, &x) || !(x > 0))
        USAGE("%s: -anneal_t0 must be a finite number > 0 (the start "
              "temperature, in swap value units), got '%s'", cmdname, v);
      o->s.anneal.t0 = x;
      break;
    case O_ANNEAL_STAGES:
      if (!tt__app_parse_size(v, &z) || z < 1 || z > 1000000)
        USAGE("%s: -anneal_stages must be an integer in [1, 1000000], got "
              "'%s'", cmdname, v);
      o->s.anneal.stages = (int)z;
      break;
    case O_ANNEAL_SWAPS:
    case O_ANNEAL_GOOD:
      if (!tt__app_parse_double(v, &x) || !(x > 0 && x <= 1e6))
        USAGE("%s: %s must be a number in (0, 1e6] (per edge), got '%s'",
              cmdname, d->name, v);
      *(d->id == O_ANNEAL_SWAPS ? &o->s.anneal.swaps : &o->s.anneal.good) = x;
      break;
    case O_ANNEAL_R:
      if (!tt__app_parse_double(v, &x) || !(x > 0 && x < 1))
        USAGE("%s: -anneal_r must be in (0, 1), got '%s'", cmdname, v);
      o->s.anneal.r = x;
      break;
    case O_ITERATIONS:
      if (tt__app_parse_size(v, &z) != NUM_OK || z < 1)
        USAGE("%s: -iterations must be an integer >= 1, got '%s'", cmdname,
              v);
      sf.iterations = 1;
      sf.iterations_value = z;
      break;
    case O_DISPLACEMENT:
      if (!tt__app_parse_double(v, &x) || x < 0)
        USAGE("%s: -displacement must be a finite number >= 0, got '%s'",
              cmdname, v);
      sf.displacement = 1;
      sf.displacement_value = x;
      break;
    case O_WAVE_SIZE:
      if (!tt__app_parse_double(v, &x) || x < 0)
        USAGE("%s: -wave_size must be a finite number >= 0, got '%s'",
              cmdname, v);
      sf.wave_size = 1;
      sf.wave_size_value = x;
      break;
    case O_ROUGHNESS:
      if (!tt__app_parse_double(v, &x) || x <= 0)
        USAGE("%s: -roughness must be a finite number > 0, got '%s'",
              cmdname, v);
      sf.roughness = 1;
      sf.roughness_value = x;
      break;
    case O_AMPLITUDE:
      if (!tt__app_parse_double(v, &x) || x < 0)
        USAGE("%s: -amplitude must be a finite number >= 0, got '%s'",
              cmdname, v);
      sf.amplitude = 1;
      sf.amplitude_value = x;
      break;
    case O_SEEDING:
      sf.seeding = 1;
      if (tt__app_str_ieq(v, "none")) sf.seeding_value = TT_SEED_NONE;
      else if (tt__app_str_ieq(v, "peak")) sf.seeding_value = TT_SEED_PEAK;
      else if (tt__app_str_ieq(v, "valley")) sf.seeding_value = TT_SEED_VALLEY;
      else if (tt__app_str_ieq(v, "hybrid")) sf.seeding_value = TT_SEED_HYBRID;
      else
        USAGE("%s: -seeding must be none, peak, valley or hybrid, got '%s'",
              cmdname, v);
      break;
    case O_SRCNODATA:
      if (!tt__app_str_ieq(v, "nan") && !tt__app_parse_double(v, &x))
        USAGE("%s: -srcnodata must be a finite decimal number or nan, got "
              "'%s'", cmdname, v);
      if (!(o->s.srcnodata = keep(o, v)))
        NOMEM();
      break;
    case O_Z_FACTOR:
      if (!tt__app_parse_double(v, &x) || x == 0)
        USAGE("%s: -z_factor must be a finite non-zero number, got '%s'",
              cmdname, v);
      o->s.z_factor = x;
      o->s.z_factor_set = 1;
      break;
    case O_Z_UNIT:
      if (!tt__app_str_ieq(v, "m"))
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
    case O_METHOD:
      if (tt__app_str_ieq(v, "insert"))
        o->s.decimate = 0;
      else if (tt__app_str_ieq(v, "decimate"))
        o->s.decimate = 1;
      else
        USAGE("%s: unknown -method '%s'; known: insert, decimate", cmdname,
              v);
      break;
    case O_START:
      if (tt_decimate_start_parse(ctx, v, &o->s.start, &o->s.start_points) !=
          TT_OK)
        USAGE("%s: unknown -start '%s'; known: all, greedy, greedy:N (N >= "
              "3)", cmdname, v);
      decimate_only = decimate_only ? decimate_only : "-start";
      break;
    case O_IMPORTANCE:
      if (tt_importance_parse(ctx, v, &o->s.importance) != TT_OK)
        USAGE("%s: unknown -importance '%s'; known: degree, hdh, abh, "
              "volume, drop, error, auto", cmdname, v);
      decimate_only = decimate_only ? decimate_only : "-importance";
      break;
    case O_SELECTION:
      if (tt_selection_parse(ctx, v, &o->s.selection) != TT_OK)
        USAGE("%s: unknown -selection '%s'; known: independent, sequential",
              cmdname, v);
      decimate_only = decimate_only ? decimate_only : "-selection";
      break;
    case O_ONEPASS:
      o->s.onepass = 1;
      decimate_only = decimate_only ? decimate_only : "-onepass";
      break;
    case O_HOLE:
      if (tt_hole_parse(ctx, v, &o->s.hole) != TT_OK)
        USAGE("%s: unknown -hole '%s'; known: minangle, circumradius, dp, "
              "auto", cmdname, v);
      decimate_only = decimate_only ? decimate_only : "-hole";
      break;
    case O_THREADS:
      if (tt__app_str_ieq(v, "ALL_CPUS")) {
        o->s.threads = -1;
        break;
      }
      if ((k = tt__app_parse_size(v, &z)) == NUM_BAD || (k == NUM_OK && z < 1))
        USAGE("%s: -threads must be an integer >= 1 or ALL_CPUS, got '%s'",
              cmdname, v);
      if (k != NUM_OK || z > TT_APP_MAX_THREADS)
        USAGE("%s: -threads %s is above the limit of %d threads", cmdname,
              v, TT_APP_MAX_THREADS);
      o->s.threads = (int)z;
      break;
    case O_TILE_SIZE: /* values.c */
      if (!tt__app_parse_tile_size(v, &o->s.tile_size))
        USAGE("%s: -tile_size must be 16 to 65536 cells, got '%s'", cmdname, v);
      break;
    case O_MAX_MEMORY: {
      k = tt__app_parse_mem_size(v, &z);
      if (k == NUM_BAD || (k == NUM_OK && z < 1))
        USAGE("%s: -max_memory must be a size of at least 1 byte: bytes, "
              "or a number with K, M, G or T (e.g. 500M, 2G), got '%s'",
              cmdname, v);
      if (k != NUM_OK)
        USAGE("%s: -max_memory %s is above the limit of %zu bytes", cmdname,
              v, (size_t)SIZE_MAX);
      o->s.max_memory = z;
      break;
    }
    case O_TERRAIN:
      if (!*v)
        USAGE("%s: -terrain needs a DEM file or a terrain name%s", cmdname,
              hint);
      if (!tt__app_strlist_add(&o->terrains, v))
        NOMEM();
      break;
    case O_CRITERIA:
    case O_METHODS:
    case O_OPTIMIZERS:
      if (!*v)
        USAGE("%s: %s needs a comma-separated list%s", cmdname, d->name,
              hint);
      if (!(*(d->id == O_CRITERIA  ? &o->s.criteria
              : d->id == O_METHODS ? &o->s.methods
                                   : &o->s.optimizers) = keep(o, v)))
        NOMEM();
      break;
    case O_ERROR_RASTER:
      if (!*v)
        USAGE("%s: -error_raster needs a file name%s", cmdname, hint);
      if (!(o->s.error_raster = keep(o, v)))
        NOMEM();
      break;
    case O_POINTS: /* study: a row at every point count up to N */
      if ((k = tt__app_parse_size(v, &z)) == NUM_BAD || (k == NUM_OK && z < 1))
        USAGE("%s: -points must be an integer >= 1, got '%s'", cmdname, v);
      if (k != NUM_OK || z > TT_MAX_VERTICES)
        USAGE("%s: -points %s is above the limit of %zu vertices", cmdname,
              v, (size_t)TT_MAX_VERTICES);
      o->s.points = z;
      break;
    case O_PLOT:
      o->s.plot = 1;
      break;
    case O_TIN_POINTS:
      if (tt__app_parse_size(v, &z) != NUM_OK || z < 3)
        USAGE("%s: -tin_points must be an integer >= 3 (the points of the "
              "TINs to draw), got '%s'", cmdname, v);
      o->s.tin_points = z;
      break;
    case O_A_SRS:
      if (!*v)
        USAGE("%s: -a_srs needs a CRS (EPSG:n, WKT, ...)", cmdname);
      if (!(o->s.srs = keep(o, v)))
        NOMEM();
      break;
    }
  }

  if (o->s.optimize == TT_OPTIMIZE_EDGE_INSERTION &&
      o->s.criterion != TT_CRITERION_MINMAX_ANGLE)
    USAGE("%s: -optimize edge_insertion optimises the Min-Max angle only: "
          "add -criterion minmax_angle, or use local, lookahead or anneal",
          cmdname);
  switch (o->s.command) {
  case TT_APP_NONE:
    USAGE("missing command: simplify, generate, eval, optimize, study or "
          "rasterize (see "
          "'terratin --help')");
  case TT_APP_SIMPLIFY:
    if (npos < 1)
      USAGE("simplify: missing INPUT and OUTPUT%s", hint);
    if (npos < 2)
      USAGE("simplify: missing OUTPUT after '%s'%s", pos[0], hint);
    if (!(o->s.input = keep(o, pos[0])) || !(o->s.output = keep(o, pos[1])))
      NOMEM();
    if (decimate_only && !o->s.decimate)
      USAGE("simplify: %s applies to -method decimate only", decimate_only);
    if (o->s.onepass && o->s.selection != TT_SELECTION_INDEPENDENT)
      USAGE("simplify: -onepass applies to -selection independent only");
    if (o->s.decimate && o->s.hole == TT_HOLE_DP &&
        o->s.criterion != TT_CRITERION_DELAUNAY &&
        o->s.criterion != TT_CRITERION_MINMAX_ANGLE &&
        o->s.criterion != TT_CRITERION_MINMAX_ANGLE_LEX &&
        o->s.criterion != TT_CRITERION_MIN_AREA)
      USAGE("simplify: -hole dp needs a decomposable criterion (delaunay, "
            "minmax_angle, minmax_angle_lex, min_area), not %s",
            tt_criterion_name(o->s.criterion));
    break;
  case TT_APP_STUDY:
    if (npos < 1)
      USAGE("study: missing OUTDIR%s", hint);
    if (npos > 1)
      USAGE("study: unexpected argument '%s'%s", pos[1], hint);
    if (!o->terrains.n)
      USAGE("study: no -terrain given (a DEM file or fault_smooth, "
            "fault_rough, peak_rough, valley_rough, hybrid, sphere, "
            "cylinder, bump)%s", hint);
    if (!(o->s.output = keep(o, pos[0])))
      NOMEM();
    break;
  case TT_APP_EVAL:
    if (npos < 1)
      USAGE("eval: missing DEM and TIN%s", hint);
    if (npos < 2)
      USAGE("eval: missing TIN after '%s'%s", pos[0], hint);
    if (!(o->s.input = keep(o, pos[0])) || !(o->s.tin = keep(o, pos[1])))
      NOMEM();
    if (!o->s.error_raster && (o->s.overwrite || o->co.n))
      USAGE("eval: option %s does not apply without -error_raster%s",
            o->s.overwrite ? "-overwrite" : "-co", hint);
    break;
  case TT_APP_RASTERIZE:
    if (npos < 3)
      USAGE("rasterize: missing %s%s", npos == 0 ? "TIN, DEM and OUTPUT"
                                       : npos == 1 ? "DEM and OUTPUT"
                                                   : "OUTPUT", hint);
    if (!(o->s.tin = keep(o, pos[0])) || !(o->s.input = keep(o, pos[1])) ||
        !(o->s.output = keep(o, pos[2])))
      NOMEM();
    break;
  case TT_APP_OPTIMIZE:
    if (npos < 3)
      USAGE("optimize: missing %s%s", npos == 0 ? "DEM, IN_TIN and OUTPUT"
                                      : npos == 1 ? "IN_TIN and OUTPUT"
                                                  : "OUTPUT", hint);
    if (!(o->s.input = keep(o, pos[0])) || !(o->s.tin = keep(o, pos[1])) ||
        !(o->s.output = keep(o, pos[2])))
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
        (o->s.synth.nx != o->s.synth.ny ||
         !tt__app_is_pow2_plus1(o->s.synth.nx)))
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
    o->s.terrains = o->terrains.n ? (const char *const *)o->terrains.v
                                  : empty_list;
    o->s.co = o->co.n ? (const char *const *)o->co.v : empty_list;
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
