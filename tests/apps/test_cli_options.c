/*
 * test_cli_options.c -- unit tests of the terratin command's option parser
 * (apps/core/options.c): defaults, every option of every command, every
 * usage error (exit code 2, one line, no object), --help/--version winning
 * over the rest of the line, the help texts documenting defaults and exit
 * codes, and the text progress bar; then the library shape: commands run
 * without a shell, with a progress callback that sees the phases climb and
 * that can stop a run at any point without leaving a file.
 */
#include "terratin_lib.h"
#include "tt_test.h"

#include <stdarg.h>

#define MAXW 64

/* Parses a NULL-terminated list of words. */
static tt_status parse(tt_app_options **out, tt_app_result *res, ...)
{
  char *words[MAXW + 1];
  size_t n = 0;
  va_list ap;
  va_start(ap, res);
  const char *w;
  while ((w = va_arg(ap, const char *)) != NULL && n < MAXW)
    words[n++] = (char *)w;
  va_end(ap);
  words[n] = NULL;
  return tt_app_options_new(words, out, res);
}

/* A usage error: TT_ERR_ARG, exit code 2, no object, one non-empty line
 * that contains `needle`. */
#define CHECK_USAGE(needle, ...)                                             \
  do {                                                                       \
    tt_app_options *o_ = (tt_app_options *)1;                                \
    tt_app_result r_;                                                        \
    tt_status s_ = parse(&o_, &r_, __VA_ARGS__, (const char *)NULL);         \
    CHECK_INT_EQ(s_, TT_ERR_ARG);                                            \
    CHECK(o_ == NULL);                                                       \
    CHECK_INT_EQ(r_.exit_code, TT_APP_EXIT_USAGE);                           \
    CHECK(r_.message[0] != '\0');                                            \
    CHECK(strchr(r_.message, '\n') == NULL);                                 \
    if (!strstr(r_.message, (needle)))                                       \
      TT_FAIL_("message \"%s\" lacks \"%s\"", r_.message, (needle));         \
  } while (0)

/* A successful parse into `o`. */
#define PARSE_OK(o, ...)                                                     \
  do {                                                                       \
    tt_app_result r_;                                                        \
    tt_status s_ = parse(&(o), &r_, __VA_ARGS__, (const char *)NULL);        \
    if (s_ != TT_OK)                                                         \
      TT_FAIL_("parse failed: %s", r_.message);                              \
    CHECK_INT_EQ(r_.exit_code, 0);                                           \
    CHECK_STR_EQ(r_.message, "");                                            \
  } while (0)

static void test_simplify_defaults(void)
{
  tt_app_options *o = NULL;
  PARSE_OK(o, "simplify", "in.tif", "out.gpkg");
  const tt_app_settings *s = tt_app_options_settings(o);
  CHECK(s != NULL);
  if (!s)
    return;
  CHECK_INT_EQ(s->command, TT_APP_SIMPLIFY);
  CHECK_STR_EQ(s->input, "in.tif");
  CHECK_STR_EQ(s->output, "out.gpkg");
  CHECK_INT_EQ(s->band, 1);
  CHECK(s->max_error < 0);
  CHECK_INT_EQ(s->max_points, 0);
  CHECK_INT_EQ(s->max_triangles, 0);
  CHECK(s->percent == 0);
  CHECK_INT_EQ(s->criterion, TT_CRITERION_DELAUNAY);
  CHECK(s->format == NULL);
  CHECK(s->lco && s->lco[0] == NULL);
  CHECK(s->dsco && s->dsco[0] == NULL);
  CHECK(s->config && s->config[0] == NULL);
  CHECK_STR_EQ(s->nln, "");
  CHECK_INT_EQ(s->overwrite, 0);
  CHECK_INT_EQ(s->quiet, 0);
  CHECK_INT_EQ(s->json, 0);
  CHECK(s->srcnodata == NULL);
  CHECK(s->z_factor == 1.0);
  CHECK_INT_EQ(tt_app_options_wants_progress_bar(o), 1);
  tt_app_options_destroy(o);
}

static void test_simplify_all_options(void)
{
  tt_app_options *o = NULL;
  /* options before, between and after the positional words, mixed case */
  PARSE_OK(o, "--config", "GDAL_CACHEMAX", "64", "simplify", "-b", "2",
           "-max_error", "0.25", "in.tif", "-max_points", "1000",
           "-MAX_TRIANGLES", "2000", "-percent", "12.5", "-of",
           "ESRI Shapefile", "-lco", "SPATIAL_INDEX=YES", "-lco",
           "ENCODING=UTF-8", "-dsco", "A=B", "-nln", "dem_", "-overwrite",
           "-q", "-criterion", "delaunay", "-repair", "lookahead",
           "-optimize", "none", "-json", "out.shp", "--config",
           "CPL_TMPDIR=/tmp", "--debug", "on", "-srcnodata", "nan",
           "-z_factor", "0.3048");
  const tt_app_settings *s = tt_app_options_settings(o);
  if (!s)
    return;
  CHECK_INT_EQ(s->command, TT_APP_SIMPLIFY);
  CHECK_STR_EQ(s->input, "in.tif");
  CHECK_STR_EQ(s->output, "out.shp");
  CHECK_INT_EQ(s->band, 2);
  CHECK_DBL_NEAR(s->max_error, 0.25, 0);
  CHECK_INT_EQ(s->max_points, 1000);
  CHECK_INT_EQ(s->repair, TT_REPAIR_LOOKAHEAD);
  CHECK_INT_EQ(s->optimize, TT_OPTIMIZE_NONE);
  CHECK_INT_EQ(s->max_triangles, 2000);
  CHECK_DBL_NEAR(s->percent, 12.5, 0);
  CHECK_STR_EQ(s->format, "ESRI Shapefile");
  CHECK_STR_EQ(s->lco[0], "SPATIAL_INDEX=YES");
  CHECK_STR_EQ(s->lco[1], "ENCODING=UTF-8");
  CHECK(s->lco[2] == NULL);
  CHECK_STR_EQ(s->dsco[0], "A=B");
  CHECK(s->dsco[1] == NULL);
  CHECK_STR_EQ(s->nln, "dem_");
  CHECK_INT_EQ(s->overwrite, 1);
  CHECK_INT_EQ(s->quiet, 1);
  CHECK_INT_EQ(s->json, 1);
  CHECK_STR_EQ(s->config[0], "GDAL_CACHEMAX");
  CHECK_STR_EQ(s->config[1], "64");
  CHECK_STR_EQ(s->config[2], "CPL_TMPDIR");
  CHECK_STR_EQ(s->config[3], "/tmp");
  CHECK_STR_EQ(s->config[4], "CPL_DEBUG");
  CHECK_STR_EQ(s->config[5], "on");
  CHECK(s->config[6] == NULL);
  CHECK_INT_EQ(tt_app_options_wants_progress_bar(o), 0);
  CHECK_STR_EQ(s->srcnodata, "nan");
  CHECK_DBL_NEAR(s->z_factor, 0.3048, 0);
  tt_app_options_destroy(o);

  /* -max_error -0 is 0, not "no limit" */
  PARSE_OK(o, "simplify", "-max_error", "-0", "a", "b");
  s = tt_app_options_settings(o);
  CHECK(s && s->max_error == 0 && !signbit(s->max_error));
  tt_app_options_destroy(o);

  /* -max_error 0 is meaningful (an exact TIN); -f is ogr2ogr's -of */
  PARSE_OK(o, "simplify", "-max_error", "0", "-f", "GPKG", "a", "b");
  s = tt_app_options_settings(o);
  CHECK(s && s->max_error == 0);
  CHECK(s && s->format && strcmp(s->format, "GPKG") == 0);
  tt_app_options_destroy(o);

  /* --opt is accepted for -opt, as GDAL's utilities do */
  PARSE_OK(o, "simplify", "--max_error", "1.5", "--of", "GPKG", "a", "b");
  s = tt_app_options_settings(o);
  CHECK(s && s->max_error == 1.5 && s->format &&
        strcmp(s->format, "GPKG") == 0);
  tt_app_options_destroy(o);

  /* -json alone: no progress bar either */
  PARSE_OK(o, "simplify", "-json", "a", "b");
  CHECK_INT_EQ(tt_app_options_wants_progress_bar(o), 0);
  tt_app_options_destroy(o);

  /* "-" is a positional word (stdin-like names are the driver's affair) */
  PARSE_OK(o, "simplify", "-", "b");
  s = tt_app_options_settings(o);
  CHECK(s && strcmp(s->input, "-") == 0);
  tt_app_options_destroy(o);
}

static void test_simplify_usage_errors(void)
{
  CHECK_USAGE("missing command", "--debug", "on");
  CHECK_USAGE("before the command", "-q", "simplify", "a", "b");
  CHECK_USAGE("unknown command 'simplfy'", "simplfy", "a", "b");
  CHECK_USAGE("missing INPUT and OUTPUT", "simplify");
  CHECK_USAGE("missing OUTPUT", "simplify", "in.tif");
  CHECK_USAGE("unexpected argument 'c'", "simplify", "a", "b", "c");
  CHECK_USAGE("unknown option '-foo'", "simplify", "-foo", "a", "b");
  CHECK_USAGE("needs a value", "simplify", "a", "b", "-max_error");
  CHECK_USAGE("-max_error", "simplify", "-max_error", "-1", "a", "b");
  CHECK_USAGE("-max_error", "simplify", "-max_error", "nan", "a", "b");
  CHECK_USAGE("-max_error", "simplify", "-max_error", "inf", "a", "b");
  CHECK_USAGE("-max_error", "simplify", "-max_error", "1e999", "a", "b");
  CHECK_USAGE("-max_error", "simplify", "-max_error", "0.5m", "a", "b");
  CHECK_USAGE("-max_error", "simplify", "-max_error", "", "a", "b");
  CHECK_USAGE("-max_points", "simplify", "-max_points", "-5", "a", "b");
  CHECK_USAGE("-max_points", "simplify", "-max_points", "0", "a", "b");
  CHECK_USAGE("-max_points", "simplify", "-max_points", "1.5", "a", "b");
  CHECK_USAGE("-max_points", "simplify", "-max_points",
              "99999999999999999999999", "a", "b");
  CHECK_USAGE("-max_points", "simplify", "-max_points", "4000000000", "a",
              "b");
  CHECK_USAGE("-max_triangles", "simplify", "-max_triangles", "0", "a", "b");
  CHECK_USAGE("-percent", "simplify", "-percent", "0", "a", "b");
  CHECK_USAGE("-percent", "simplify", "-percent", "150", "a", "b");
  CHECK_USAGE("-percent", "simplify", "-percent", "-3", "a", "b");
  CHECK_USAGE("-b", "simplify", "-b", "0", "a", "b");
  CHECK_USAGE("-b", "simplify", "-b", "x", "a", "b");
  CHECK_USAGE("-criterion 'foo'", "simplify", "-criterion", "foo", "a", "b");
  CHECK_USAGE("-repair 'lawson'", "simplify", "-repair", "lawson", "a", "b");
  CHECK_USAGE("-optimize 'global'", "simplify", "-optimize", "global", "a",
              "b");
  CHECK_USAGE("NAME=VALUE", "simplify", "-lco", "SPATIAL_INDEX", "a", "b");
  CHECK_USAGE("NAME=VALUE", "simplify", "-dsco", "=x", "a", "b");
  CHECK_USAGE("-of", "simplify", "-of", "", "a", "b");
  CHECK_USAGE("-srcnodata", "simplify", "-srcnodata", "none", "a", "b");
  CHECK_USAGE("-z_factor", "simplify", "-z_factor", "0", "a", "b");
  CHECK_USAGE("-z_factor", "simplify", "-z_factor", "inf", "a", "b");
  CHECK_USAGE("does not apply", "simplify", "-size", "9", "a", "b");
  CHECK_USAGE("does not apply", "simplify", "-layer", "t", "a", "b");
  CHECK_USAGE("--config", "simplify", "a", "b", "--config");
  CHECK_USAGE("--config K needs a VALUE", "simplify", "a", "b", "--config",
              "K");
  CHECK_USAGE("--debug", "simplify", "a", "b", "--debug");
  CHECK_USAGE("empty KEY", "--config", "=B", "simplify", "a", "b");
  CHECK_USAGE("before the command", "-max_error", "1", "simplify", "a", "b");
}

/* Issue 17: -layers (any subset, each once, any case) and -nostyle. */
static void test_layers(void)
{
  tt_app_options *o = NULL;
  PARSE_OK(o, "simplify", "a.tif", "b.gpkg");
  const tt_app_settings *s = tt_app_options_settings(o);
  if (s) {
    CHECK_INT_EQ(s->layers, TT_APP_LAYERS_ALL);
    CHECK_INT_EQ(s->nostyle, 0);
  }
  tt_app_options_destroy(o);
  o = NULL;
  PARSE_OK(o, "simplify", "-layers", "Run_Parameters,triangles", "-nostyle",
           "a.tif", "b.geojson");
  s = tt_app_options_settings(o);
  if (s) {
    CHECK_INT_EQ(s->layers,
                 TT_APP_LAYER_TRIANGLES | TT_APP_LAYER_RUN_PARAMETERS);
    CHECK_INT_EQ(s->nostyle, 1);
  }
  tt_app_options_destroy(o);
  o = NULL;
  PARSE_OK(o, "simplify", "-layers", "vertices", "a.tif", "b.gpx");
  s = tt_app_options_settings(o);
  if (s)
    CHECK_INT_EQ(s->layers, TT_APP_LAYER_VERTICES);
  tt_app_options_destroy(o);
  CHECK_USAGE("'tri' is not a layer", "simplify", "-layers", "tri", "a", "b");
  CHECK_USAGE("is not a layer", "simplify", "-layers", "", "a", "b");
  CHECK_USAGE("is not a layer", "simplify", "-layers", "vertices,", "a", "b");
  CHECK_USAGE("Vertices is named twice", "simplify", "-layers",
              "vertices,Vertices", "a", "b");
  CHECK_USAGE("does not apply", "eval", "-layers", "vertices", "a", "b");
}

/* Issue 11, "Messages and limits": each message says the true cause, and
 * the parser is as strict as the docs say. */
static void test_issue11_parsing(void)
{
  tt_app_options *o = NULL;
  const tt_app_settings *s;
  /* a subnormal limit is a number >= 0, not a malformed one */
  PARSE_OK(o, "simplify", "-max_error", "1e-320", "a", "b");
  s = tt_app_options_settings(o);
  CHECK(s && s->max_error > 0 && s->max_error < 1e-300);
  tt_app_options_destroy(o);
  /* 20 digits are too many, as 2^64 - 1 is: "above the limit" for both */
  CHECK_USAGE("above the limit", "simplify", "-max_points",
              "99999999999999999999", "a", "b");
  CHECK_USAGE("above the limit", "simplify", "-max_points",
              "18446744073709551615", "a", "b");
  CHECK_USAGE("above the limit", "simplify", "-max_triangles",
              "99999999999999999999", "a", "b");
  /* no hex, inf or nan where a finite decimal number is meant */
  CHECK_USAGE("-max_error", "simplify", "-max_error", "0x10", "a", "b");
  CHECK_USAGE("-max_error", "simplify", "-max_error", " 5", "a", "b");
  CHECK_USAGE("-percent", "simplify", "-percent", "0x1p4", "a", "b");
  CHECK_USAGE("-z_factor", "simplify", "-z_factor", "infinity", "a", "b");
  CHECK_USAGE("-srcnodata", "simplify", "-srcnodata", "0x10", "a", "b");
  CHECK_USAGE("-srcnodata", "simplify", "-srcnodata", "inf", "a", "b");
  CHECK_USAGE("-displacement", "generate", "fault", "o.tif",
              "-displacement", "0x10");
  /* --opt is -opt; ---opt is no option */
  CHECK_USAGE("unknown option '---max_error'", "simplify", "---max_error",
              "1", "a", "b");
  PARSE_OK(o, "simplify", "--max_error", "1", "a", "b");
  tt_app_options_destroy(o);
  /* names are matched without regard to case, as option names are */
  PARSE_OK(o, "simplify", "-criterion", "DELAUNAY", "-repair", "Local",
           "-optimize", "LOOKAHEAD", "a", "b");
  s = tt_app_options_settings(o);
  CHECK(s && s->criterion == TT_CRITERION_DELAUNAY);
  CHECK(s && s->repair == TT_REPAIR_LOCAL);
  CHECK(s && s->optimize == TT_OPTIMIZE_LOOKAHEAD);
  tt_app_options_destroy(o);
  PARSE_OK(o, "simplify", "-criterion", "Min_Area", "a", "b");
  s = tt_app_options_settings(o);
  CHECK(s && s->criterion == TT_CRITERION_MIN_AREA);
  tt_app_options_destroy(o);
  PARSE_OK(o, "generate", "FAULT", "o.tif");
  tt_app_options_destroy(o);
  /* --debug takes GDAL's booleans only */
  CHECK_USAGE("--debug must be on, off", "simplify", "a", "b", "--debug",
              "maybe");
  PARSE_OK(o, "simplify", "a", "b", "--debug", "OFF");
  tt_app_options_destroy(o);
  PARSE_OK(o, "simplify", "a", "b", "--debug", "1");
  tt_app_options_destroy(o);
  /* -threads and -max_memory */
  PARSE_OK(o, "simplify", "-threads", "4", "-max_memory", "500M", "a", "b");
  s = tt_app_options_settings(o);
  CHECK(s && s->threads == 4);
  CHECK(s && s->max_memory == (size_t)500 << 20);
  tt_app_options_destroy(o);
  PARSE_OK(o, "simplify", "-threads", "all_cpus", "-max_memory", "1.5GB",
           "a", "b");
  s = tt_app_options_settings(o);
  CHECK(s && s->threads == -1);
  CHECK(s && s->max_memory == (size_t)3 << 29);
  tt_app_options_destroy(o);
  PARSE_OK(o, "eval", "-max_memory", "1048576", "a", "b");
  s = tt_app_options_settings(o);
  CHECK(s && s->max_memory == 1048576);
  tt_app_options_destroy(o);
  PARSE_OK(o, "simplify", "-max_memory", "2GiB", "a", "b");
  s = tt_app_options_settings(o);
  CHECK(s && s->max_memory == (size_t)2 << 30);
  tt_app_options_destroy(o);
  CHECK_USAGE("-threads must be", "simplify", "-threads", "0", "a", "b");
  CHECK_USAGE("-threads must be", "simplify", "-threads", "two", "a", "b");
  CHECK_USAGE("above the limit", "simplify", "-threads", "100000", "a", "b");
  CHECK_USAGE("-max_memory must be", "simplify", "-max_memory", "0", "a",
              "b");
  CHECK_USAGE("-max_memory must be", "simplify", "-max_memory", "5X", "a",
              "b");
  CHECK_USAGE("-max_memory must be", "simplify", "-max_memory", "-1G", "a",
              "b");
  CHECK_USAGE("above the limit", "simplify", "-max_memory", "99999999T",
              "a", "b");
  CHECK_USAGE("does not apply", "generate", "fault", "o.tif", "-threads",
              "2");
}

static void test_help_and_version(void)
{
  tt_app_options *o = NULL;
  const tt_app_settings *s;

  PARSE_OK(o, "--help");
  s = tt_app_options_settings(o);
  CHECK(s && s->command == TT_APP_HELP && s->help_topic == TT_APP_NONE);
  tt_app_options_destroy(o);

  PARSE_OK(o, "simplify", "--help");
  s = tt_app_options_settings(o);
  CHECK(s && s->command == TT_APP_HELP && s->help_topic == TT_APP_SIMPLIFY);
  tt_app_options_destroy(o);

  /* help wins over errors elsewhere on the line */
  PARSE_OK(o, "simplify", "-max_error", "-1", "-nonsense", "-h");
  s = tt_app_options_settings(o);
  CHECK(s && s->command == TT_APP_HELP && s->help_topic == TT_APP_SIMPLIFY);
  tt_app_options_destroy(o);

  PARSE_OK(o, "help", "eval");
  s = tt_app_options_settings(o);
  CHECK(s && s->command == TT_APP_HELP && s->help_topic == TT_APP_EVAL);
  tt_app_options_destroy(o);

  PARSE_OK(o, "generate", "--help");
  s = tt_app_options_settings(o);
  CHECK(s && s->command == TT_APP_HELP && s->help_topic == TT_APP_GENERATE);
  tt_app_options_destroy(o);

  PARSE_OK(o, "--version");
  s = tt_app_options_settings(o);
  CHECK(s && s->command == TT_APP_VERSION);
  tt_app_options_destroy(o);

  /* a --config value that reads "--help" is a value, not a request */
  CHECK_USAGE("missing command", "--config", "X", "--help");

  /* The texts document what the issue asks them to. */
  const char *top = tt_app_help(TT_APP_NONE);
  const char *sim = tt_app_help(TT_APP_SIMPLIFY);
  const char *gen = tt_app_help(TT_APP_GENERATE);
  const char *ev = tt_app_help(TT_APP_EVAL);
  CHECK(strstr(top, "Exit codes") && strstr(top, "  3  eval"));
  CHECK(strstr(top, "--config KEY VALUE") && strstr(top, "--version"));
  CHECK(strstr(sim, "twice the DEM's mean step") != NULL);
  static const char *const simplify_opts[] = {
      "-b ", "-max_error", "-max_points", "-max_triangles", "-percent",
      "-of ", "-lco", "-dsco", "-nln", "-overwrite", "-q ", "-criterion",
      "-repair", "-optimize", "-json", "-verbose", "Exit codes"};
  for (size_t i = 0; i < sizeof simplify_opts / sizeof *simplify_opts; i++)
    if (!strstr(sim, simplify_opts[i]))
      TT_FAIL_("simplify help lacks %s", simplify_opts[i]);
  static const char *const generate_opts[] = {
      "fault", "diamond_square", "sphere", "cylinder", "bump", "-size",
      "-seed", "-iterations", "-displacement", "-wave_size", "-roughness",
      "-amplitude", "-seeding", "-a_srs", "-overwrite", "-q"};
  for (size_t i = 0; i < sizeof generate_opts / sizeof *generate_opts; i++)
    if (!strstr(gen, generate_opts[i]))
      TT_FAIL_("generate help lacks %s", generate_opts[i]);
  static const char *const eval_opts[] = {"-b ", "-layer", "-json",
                                          "-max_error", "code 3"};
  for (size_t i = 0; i < sizeof eval_opts / sizeof *eval_opts; i++)
    if (!strstr(ev, eval_opts[i]))
      TT_FAIL_("eval help lacks %s", eval_opts[i]);

  /* Running help writes the text to the output stream, exit 0. */
  FILE *out = tmpfile();
  CHECK(out != NULL);
  if (!out)
    return;
  PARSE_OK(o, "eval", "--help");
  tt_app_options_set_streams(o, out, out);
  tt_app_result res;
  CHECK_INT_EQ(tt_app_run(o, &res), TT_OK);
  CHECK_INT_EQ(res.exit_code, 0);
  tt_app_options_destroy(o);
  CHECK_INT_EQ(ftell(out), (long)strlen(ev));
  fclose(out);
}

static void test_generate(void)
{
  tt_app_options *o = NULL;
  const tt_app_settings *s;
  tt_synth_options d;

  PARSE_OK(o, "generate", "fault", "f.tif");
  s = tt_app_options_settings(o);
  tt_synth_options_init(&d, TT_SYNTH_FAULT);
  CHECK(s && s->command == TT_APP_GENERATE);
  CHECK(s && s->synth.kind == TT_SYNTH_FAULT);
  CHECK(s && s->synth.nx == d.nx && s->synth.ny == d.ny);
  CHECK(s && s->synth.seed == d.seed);
  CHECK(s && s->synth.iterations == d.iterations);
  CHECK(s && s->output && strcmp(s->output, "f.tif") == 0);
  CHECK(s && s->srs == NULL);
  tt_app_options_destroy(o);

  PARSE_OK(o, "generate", "-size", "120x80", "fault", "-seed",
           "18446744073709551615", "-iterations", "50", "-displacement", "20",
           "-wave_size", "5", "f.tif", "-a_srs", "EPSG:32633", "-overwrite",
           "-q");
  s = tt_app_options_settings(o);
  CHECK(s && s->synth.nx == 120 && s->synth.ny == 80);
  CHECK(s && s->synth.seed == UINT64_MAX);
  CHECK(s && s->synth.iterations == 50);
  CHECK(s && s->synth.displacement == 20 && s->synth.wave_size == 5);
  CHECK(s && s->srs && strcmp(s->srs, "EPSG:32633") == 0);
  CHECK(s && s->overwrite && s->quiet);
  tt_app_options_destroy(o);

  PARSE_OK(o, "generate", "diamond_square", "d.tif", "-size", "129",
           "-roughness", "0.5", "-amplitude", "10", "-seeding", "hybrid");
  s = tt_app_options_settings(o);
  CHECK(s && s->synth.kind == TT_SYNTH_DIAMOND_SQUARE);
  CHECK(s && s->synth.nx == 129 && s->synth.ny == 129);
  CHECK(s && s->synth.roughness == 0.5 && s->synth.amplitude == 10);
  CHECK(s && s->synth.seeding == TT_SEED_HYBRID);
  tt_app_options_destroy(o);

  PARSE_OK(o, "generate", "bump", "b.tif");
  s = tt_app_options_settings(o);
  tt_synth_options_init(&d, TT_SYNTH_BUMP);
  CHECK(s && s->synth.kind == TT_SYNTH_BUMP && s->synth.nx == d.nx &&
        s->synth.ny == d.ny);
  tt_app_options_destroy(o);

  CHECK_USAGE("missing TYPE", "generate");
  CHECK_USAGE("unknown TYPE 'hill'", "generate", "hill", "x.tif");
  CHECK_USAGE("missing OUTPUT", "generate", "sphere");
  CHECK_USAGE("-size", "generate", "fault", "x.tif", "-size", "1");
  CHECK_USAGE("-size", "generate", "fault", "x.tif", "-size", "100x");
  CHECK_USAGE("-size", "generate", "fault", "x.tif", "-size", "x100");
  CHECK_USAGE("-size", "generate", "fault", "x.tif", "-size", "-5");
  CHECK_USAGE("too large", "generate", "fault", "x.tif", "-size",
              "100000x100000");
  CHECK_USAGE("2^n+1", "generate", "diamond_square", "x.tif", "-size",
              "100");
  CHECK_USAGE("2^n+1", "generate", "diamond_square", "x.tif", "-size",
              "129x65");
  CHECK_USAGE("-seed", "generate", "fault", "x.tif", "-seed", "-1");
  CHECK_USAGE("-seed", "generate", "fault", "x.tif", "-seed",
              "18446744073709551616");
  CHECK_USAGE("-iterations", "generate", "fault", "x.tif", "-iterations",
              "0");
  CHECK_USAGE("-roughness", "generate", "diamond_square", "x.tif",
              "-roughness", "0");
  CHECK_USAGE("-seeding", "generate", "diamond_square", "x.tif", "-seeding",
              "mountain");
  CHECK_USAGE("fault terrains only", "generate", "sphere", "x.tif",
              "-wave_size", "3");
  CHECK_USAGE("diamond_square terrains only", "generate", "fault", "x.tif",
              "-roughness", "0.5");
  CHECK_USAGE("does not apply", "generate", "fault", "x.tif", "-of", "GTiff");
  CHECK_USAGE("does not apply", "generate", "fault", "x.tif", "-json");
}

static void test_eval(void)
{
  tt_app_options *o = NULL;
  const tt_app_settings *s;
  PARSE_OK(o, "eval", "dem.tif", "tin.gpkg");
  s = tt_app_options_settings(o);
  CHECK(s && s->command == TT_APP_EVAL);
  CHECK(s && strcmp(s->input, "dem.tif") == 0);
  CHECK(s && strcmp(s->tin, "tin.gpkg") == 0);
  CHECK(s && s->layer == NULL && s->max_error < 0 && s->band == 1);
  tt_app_options_destroy(o);

  PARSE_OK(o, "eval", "-layer", "my_triangles", "dem.tif", "-b", "3",
           "tin.gpkg", "-json", "-max_error", "0");
  s = tt_app_options_settings(o);
  CHECK(s && s->layer && strcmp(s->layer, "my_triangles") == 0);
  CHECK(s && s->band == 3 && s->json && s->max_error == 0);
  tt_app_options_destroy(o);

  CHECK_USAGE("missing DEM and TIN", "eval");
  CHECK_USAGE("missing TIN", "eval", "dem.tif");
  CHECK_USAGE("-max_error", "eval", "a", "b", "-max_error", "-0.1");
  CHECK_USAGE("does not apply", "eval", "a", "b", "-overwrite");
  CHECK_USAGE("without -error_raster", "eval", "a", "b", "-co", "A=B");
  CHECK_USAGE("does not apply", "eval", "a", "b", "-of", "GTiff");
  CHECK_USAGE("missing TIN and OUTPUT", "rasterize", "dem.tif");
  CHECK_USAGE("missing OUTPUT", "rasterize", "dem.tif", "tin.gpkg");
  CHECK_USAGE("-co expects NAME=VALUE", "rasterize", "a", "b", "c", "-co",
              "X");
  CHECK_USAGE("does not apply", "rasterize", "a", "b", "c", "-lco", "A=B");
  CHECK_USAGE("unexpected argument", "rasterize", "a", "b", "c", "d");
  PARSE_OK(o, "rasterize", "d.tif", "t.gpkg", "o.tif", "-co", "A=1", "-co",
           "B=2", "-of", "AAIGrid", "-layer", "tri");
  s = tt_app_options_settings(o);
  CHECK(s && s->command == TT_APP_RASTERIZE && strcmp(s->tin, "t.gpkg") == 0 &&
        strcmp(s->input, "d.tif") == 0 && strcmp(s->output, "o.tif") == 0 &&
        strcmp(s->format, "AAIGrid") == 0 && s->co[0] && s->co[1] &&
        !s->co[2] && strcmp(s->co[1], "B=2") == 0 &&
        strcmp(s->layer, "tri") == 0);
  tt_app_options_destroy(o);
  PARSE_OK(o, "eval", "d.tif", "t.gpkg", "-error_raster", "e.tif",
           "-overwrite");
  s = tt_app_options_settings(o);
  CHECK(s && s->overwrite && strcmp(s->error_raster, "e.tif") == 0);
  tt_app_options_destroy(o);
  CHECK_USAGE("does not apply", "eval", "a", "b", "-max_points", "5");
}

/* GDAL's input options (issue 27): four words for a window, each the
 * commands that read a DEM take, one of each pair, the refusals. */
static void test_input_options(void)
{
  tt_app_options *o = NULL;
  const tt_app_settings *s;
  PARSE_OK(o, "simplify", "-srcwin", "-5", "0", "100", "80", "-a_srs",
           "EPSG:32633", "-a_ullr", "0", "100", "50", "0", "-a_nodata",
           "-9999", "in.tif", "out.gpkg");
  s = tt_app_options_settings(o);
  CHECK(s && s->srcwin.set && s->srcwin.v[0] == -5 && s->srcwin.v[1] == 0 &&
        s->srcwin.v[2] == 100 && s->srcwin.v[3] == 80);
  CHECK(s && !s->projwin.set && s->a_ullr.set && s->a_ullr.v[1] == 100 &&
        s->a_ullr.v[2] == 50);
  CHECK(s && strcmp(s->srs, "EPSG:32633") == 0 && !s->srs_is_s_srs);
  CHECK(s && strcmp(s->srcnodata, "-9999") == 0);
  CHECK(s && strcmp(s->input, "in.tif") == 0 &&
        strcmp(s->output, "out.gpkg") == 0);
  tt_app_options_destroy(o);
  PARSE_OK(o, "eval", "-projwin", "1.5", "20", "3", "10.25", "-projwin_srs",
           "EPSG:4326", "-s_srs", "EPSG:32633", "d.tif", "t.gpkg");
  s = tt_app_options_settings(o);
  CHECK(s && s->projwin.set && s->projwin.v[0] == 1.5 &&
        s->projwin.v[3] == 10.25 && strcmp(s->projwin_srs, "EPSG:4326") == 0);
  CHECK(s && s->srs_is_s_srs && strcmp(s->srs, "EPSG:32633") == 0);
  tt_app_options_destroy(o);
  PARSE_OK(o, "rasterize", "t.gpkg", "d.tif", "o.tif", "-srcwin", "0", "0",
           "2", "2");
  tt_app_options_destroy(o);
  PARSE_OK(o, "optimize", "-a_srs", "EPSG:4326", "d.tif", "t.gpkg", "o.gpkg");
  tt_app_options_destroy(o);
  PARSE_OK(o, "study", "-terrain", "d.tif", "-srcwin", "0", "0", "9", "9",
           "out");
  tt_app_options_destroy(o);
  CHECK_USAGE("-srcwin needs 4 values", "simplify", "a", "b", "-srcwin", "1",
              "2", "3");
  CHECK_USAGE("-srcwin needs xoff yoff xsize ysize", "simplify", "a", "b",
              "-srcwin", "1", "2", "0", "3");
  CHECK_USAGE("-srcwin needs xoff yoff xsize ysize", "simplify", "a", "b",
              "-srcwin", "1", "2", "3.5", "3");
  CHECK_USAGE("-srcwin needs xoff yoff xsize ysize", "simplify", "a", "b",
              "-srcwin", "1 2", "3", "4", "5");
  CHECK_USAGE("-projwin needs ulx uly lrx lry", "simplify", "a", "b",
              "-projwin", "3", "10", "1", "20");
  CHECK_USAGE("-a_ullr needs ulx uly lrx lry", "simplify", "a", "b",
              "-a_ullr", "0", "5", "0", "0");
  CHECK_USAGE("-a_srs and -s_srs", "simplify", "a", "b", "-a_srs", "EPSG:1",
              "-s_srs", "EPSG:1");
  CHECK_USAGE("-a_nodata and -srcnodata", "eval", "a", "b", "-a_nodata", "1",
              "-srcnodata", "1");
  CHECK_USAGE("-srcwin and -projwin", "simplify", "a", "b", "-srcwin", "0",
              "0", "5", "5", "-projwin", "0", "5", "5", "0");
  CHECK_USAGE("-projwin_srs is the CRS of -projwin", "simplify", "a", "b",
              "-projwin_srs", "EPSG:4326");
  CHECK_USAGE("-projwin with -a_ullr", "simplify", "a", "b", "-projwin", "0",
              "5", "5", "0", "-a_ullr", "0", "5", "5", "0");
  CHECK_USAGE("-a_nodata must be", "simplify", "a", "b", "-a_nodata", "x");
  CHECK_USAGE("does not apply", "generate", "fault", "g.tif", "-srcwin", "0",
              "0", "5", "5");
}

/* optimize DEM IN_TIN OUTPUT and the annealing options (issue 14). */
static void test_optimize(void)
{
  tt_app_options *o = NULL;
  const tt_app_settings *s;
  PARSE_OK(o, "optimize", "dem.tif", "tin.gpkg", "out.gpkg");
  s = tt_app_options_settings(o);
  CHECK(s && s->command == TT_APP_OPTIMIZE);
  CHECK(s && strcmp(s->input, "dem.tif") == 0);
  CHECK(s && strcmp(s->tin, "tin.gpkg") == 0);
  CHECK(s && strcmp(s->output, "out.gpkg") == 0);
  CHECK(s && s->optimize == TT_OPTIMIZE_AUTO && s->max_error < 0);
  CHECK(s && s->anneal.t0 == 0 && s->anneal.stages == 0 &&
        s->anneal.seed == 0);
  tt_app_options_destroy(o);

  PARSE_OK(o, "optimize", "-criterion", "l2", "-optimize", "anneal",
           "-anneal_t0", "0.01", "-anneal_stages", "500", "-anneal_swaps",
           "15", "-anneal_good", "15", "-anneal_r", "0.9", "-seed", "42",
           "-max_error", "2", "-layer", "t", "dem.tif", "tin.gpkg",
           "out.gpkg", "-overwrite", "-json", "-nln", "x_");
  s = tt_app_options_settings(o);
  CHECK(s && s->criterion == TT_CRITERION_L2);
  CHECK(s && s->optimize == TT_OPTIMIZE_ANNEAL && s->max_error == 2);
  CHECK(s && s->anneal.t0 == 0.01 && s->anneal.stages == 500 &&
        s->anneal.swaps == 15 && s->anneal.good == 15 &&
        s->anneal.r == 0.9 && s->anneal.seed == 42);
  CHECK(s && s->overwrite && s->json && strcmp(s->layer, "t") == 0);
  tt_app_options_destroy(o);

  /* simplify takes them too */
  PARSE_OK(o, "simplify", "-optimize", "edge_insertion", "-criterion",
           "minmax_angle", "-seed", "7", "a", "b");
  s = tt_app_options_settings(o);
  CHECK(s && s->optimize == TT_OPTIMIZE_EDGE_INSERTION &&
        s->anneal.seed == 7);
  tt_app_options_destroy(o);

  CHECK_USAGE("missing DEM, IN_TIN and OUTPUT", "optimize");
  CHECK_USAGE("missing IN_TIN and OUTPUT", "optimize", "a");
  CHECK_USAGE("missing OUTPUT", "optimize", "a", "b");
  CHECK_USAGE("unexpected argument", "optimize", "a", "b", "c", "d");
  CHECK_USAGE("Min-Max angle only", "optimize", "-optimize",
              "edge_insertion", "a", "b", "c");
  CHECK_USAGE("Min-Max angle only", "simplify", "-optimize",
              "edge_insertion", "-criterion", "l2", "a", "b");
  CHECK_USAGE("-anneal_r", "optimize", "-anneal_r", "1", "a", "b", "c");
  CHECK_USAGE("-anneal_t0", "optimize", "-anneal_t0", "0", "a", "b", "c");
  CHECK_USAGE("-anneal_stages", "optimize", "-anneal_stages", "0", "a", "b",
              "c");
  CHECK_USAGE("-anneal_swaps", "simplify", "-anneal_swaps", "-1", "a", "b");
  CHECK_USAGE("-anneal_good", "simplify", "-anneal_good", "nan", "a", "b");
  CHECK_USAGE("does not apply", "optimize", "-percent", "5", "a", "b", "c");
  CHECK_USAGE("does not apply", "eval", "-anneal_r", "0.5", "a", "b");
  const char *help = tt_app_help(TT_APP_OPTIMIZE);
  static const char *const opts[] = {
      "IN_TIN", "-criterion", "-optimize", "edge_insertion", "-max_error",
      "-anneal_t0", "-anneal_stages", "-anneal_swaps", "-anneal_good",
      "-anneal_r", "-seed", "-layer", "Exit codes"};
  for (size_t i = 0; i < sizeof opts / sizeof *opts; i++)
    if (!strstr(help, opts[i]))
      TT_FAIL_("optimize help lacks %s", opts[i]);
  CHECK(strstr(tt_app_help(TT_APP_NONE), "optimize") != NULL);
  CHECK(strstr(tt_app_help(TT_APP_SIMPLIFY), "-anneal_t0") != NULL);
}

static char *slurp(FILE *f)
{
  long n = ftell(f);
  char *buf = calloc((size_t)n + 1, 1);
  rewind(f);
  if (buf && fread(buf, 1, (size_t)n, f) != (size_t)n)
    buf[0] = '\0';
  return buf;
}

static void test_progress_bar(void)
{
  FILE *f = tmpfile();
  CHECK(f != NULL);
  if (!f)
    return;
  tt_app_term_progress bar;
  volatile sig_atomic_t stop = 0;
  tt_app_term_progress_init(&bar, f, &stop);
  CHECK_INT_EQ(tt_app_term_progress_fn(0.0, NULL, &bar), 1);
  CHECK_INT_EQ(tt_app_term_progress_fn(0.12, "x", &bar), 1);
  CHECK_INT_EQ(tt_app_term_progress_fn(0.05, NULL, &bar), 1); /* back */
  CHECK_INT_EQ(tt_app_term_progress_fn(0.5, NULL, &bar), 1);
  CHECK_INT_EQ(tt_app_term_progress_fn(NAN, NULL, &bar), 1); /* ignored */
  CHECK_INT_EQ(tt_app_term_progress_fn(0.75, NULL, &bar), 1);
  CHECK_INT_EQ(tt_app_term_progress_fn(1.0, NULL, &bar), 1);
  CHECK_INT_EQ(tt_app_term_progress_fn(1.0, NULL, &bar), 1); /* once */
  char *text = slurp(f);
  CHECK_STR_EQ(text,
               "0...10...20...30...40...50...60...70...80...90...100 - "
               "done.\n");
  free(text);
  fclose(f);

  /* a second bar has its own state; the stop flag stops it */
  tt_app_term_progress quiet;
  tt_app_term_progress_init(&quiet, NULL, &stop);
  CHECK_INT_EQ(tt_app_term_progress_fn(0.3, NULL, &quiet), 1);
  stop = 1;
  CHECK_INT_EQ(tt_app_term_progress_fn(0.4, NULL, &quiet), 0);
  CHECK_INT_EQ(tt_app_term_progress_fn(0.4, NULL, &bar), 0);
}

static void test_no_argv(void)
{
  tt_app_result res;
  tt_app_options *o = (tt_app_options *)1;
  char *none[] = {NULL};
  CHECK_INT_EQ(tt_app_options_new(none, &o, &res), TT_ERR_ARG);
  CHECK(o == NULL);
  CHECK_INT_EQ(res.exit_code, TT_APP_EXIT_USAGE);
  /* A NULL result pointer is allowed. */
  CHECK_INT_EQ(tt_app_options_new(none, &o, NULL), TT_ERR_ARG);
  tt_app_options_destroy(NULL);
  CHECK(tt_app_options_settings(NULL) == NULL);
}

/* ---------------------------------------------------------------------------
 * The library shape: a program runs the commands without a shell, with its
 * own progress callback, and can stop a run at any point.
 * ------------------------------------------------------------------------- */

typedef struct progress_log {
  double last;
  int calls, decreasing, in_read, in_simplify, in_write;
  double stop_at;          /* return 0 once complete >= stop_at */
} progress_log;

static int record_progress(double complete, const char *message, void *arg)
{
  progress_log *p = arg;
  (void)message;
  if (complete < p->last)
    p->decreasing++;
  p->last = complete;
  p->calls++;
  /* read 0 - 0.10, simplify 0.10 - 0.85, write 0.85 - 1 */
  if (complete > 0.0 && complete <= 0.10) p->in_read++;
  if (complete > 0.10 && complete <= 0.85) p->in_simplify++;
  if (complete > 0.85 && complete < 1.0) p->in_write++;
  return complete < p->stop_at;
}

/* Runs a command line (words separated by '|'), streams to out/err. */
static tt_status run_line(const char *line, FILE *out, tt_progress_fn fn,
                          void *arg, tt_app_result *res)
{
  char buf[1024];
  char *words[MAXW + 1];
  size_t n = 0;
  snprintf(buf, sizeof buf, "%s", line);
  for (char *p = strtok(buf, "|"); p && n < MAXW; p = strtok(NULL, "|"))
    words[n++] = p;
  words[n] = NULL;
  tt_app_options *o = NULL;
  tt_status st = tt_app_options_new(words, &o, res);
  if (st != TT_OK)
    return st;
  tt_app_options_set_streams(o, out, out);
  tt_app_options_set_progress(o, fn, arg);
  st = tt_app_run(o, res);
  tt_app_options_destroy(o);
  return st;
}

static size_t count_files(const char *dir)
{
  char cmd[600];
  snprintf(cmd, sizeof cmd, "ls -A '%s' | wc -l", dir);
  FILE *p = popen(cmd, "r");
  size_t n = 0;
  if (p) {
    if (fscanf(p, "%zu", &n) != 1)
      n = (size_t)-1;
    pclose(p);
  }
  return n;
}

static void test_library_runs(void)
{
  char dir[] = "/tmp/tt_cli_lib.XXXXXX";
  char line[1024];
  tt_app_result res;
  if (!mkdtemp(dir)) {
    TT_FAIL_("mkdtemp failed");
    return;
  }
  FILE *out = tmpfile();
  if (!out) {
    TT_FAIL_("tmpfile failed");
    return;
  }

  snprintf(line, sizeof line,
           "generate|fault|%s/f.tif|-size|60x50|-seed|3|-displacement|20|"
           "-wave_size|4|-q", dir);
  CHECK_INT_EQ(run_line(line, out, NULL, NULL, &res), TT_OK);
  CHECK_INT_EQ(res.exit_code, 0);
  CHECK_INT_EQ(count_files(dir), 1);

  /* Stopped while simplifying, then while writing: an interrupted run,
   * exit code 1, one line, nothing left but the input. */
  static const double stops[] = {0.0, 0.5, 0.9, 0.99};
  for (size_t i = 0; i < sizeof stops / sizeof *stops; i++) {
    progress_log log = {0, 0, 0, 0, 0, 0, stops[i]};
    snprintf(line, sizeof line, "simplify|-max_error|0|%s/f.tif|%s/o.gpkg",
             dir, dir);
    CHECK_INT_EQ(run_line(line, out, record_progress, &log, &res),
                 TT_ERR_INTERRUPTED);
    CHECK_INT_EQ(res.exit_code, TT_APP_EXIT_FAILURE);
    CHECK(strstr(res.message, "interrupted") != NULL);
    CHECK(strstr(res.message, "o.gpkg") != NULL);
    if (count_files(dir) != 1)
      TT_FAIL_("stop at %g left files behind", stops[i]);
  }

  /* A full run: the fractions climb through the three phases to 1. */
  progress_log log = {0, 0, 0, 0, 0, 0, 2.0};
  long before = ftell(out);
  snprintf(line, sizeof line,
           "simplify|-json|-max_error|0.5|%s/f.tif|%s/o.gpkg", dir, dir);
  CHECK_INT_EQ(run_line(line, out, record_progress, &log, &res), TT_OK);
  CHECK_INT_EQ(res.exit_code, 0);
  CHECK_INT_EQ(log.decreasing, 0);
  CHECK(log.last == 1.0);
  CHECK(log.in_read > 0);
  CHECK(log.in_simplify > 0);
  CHECK(log.in_write > 0);
  CHECK_INT_EQ(count_files(dir), 2);
  /* the JSON object went to the stream given */
  long after = ftell(out);
  CHECK(after > before);
  if (after > before) {
    char *text = calloc((size_t)(after - before) + 1, 1);
    fseek(out, before, SEEK_SET);
    if (text && fread(text, 1, (size_t)(after - before), out) ==
                    (size_t)(after - before)) {
      CHECK(text[0] == '{');
      CHECK(strstr(text, "\"vertices\": ") != NULL);
      CHECK(strstr(text, "\"max_error_default\": false") != NULL);
    }
    free(text);
    fseek(out, 0, SEEK_END);
  }

  /* eval through the library: within the bound, exit 0; a tighter bound,
   * exit 3 with the status still TT_OK (the run itself worked). */
  snprintf(line, sizeof line, "eval|-q|-max_error|0.5|%s/f.tif|%s/o.gpkg",
           dir, dir);
  CHECK_INT_EQ(run_line(line, out, NULL, NULL, &res), TT_OK);
  CHECK_INT_EQ(res.exit_code, 0);
  snprintf(line, sizeof line, "eval|-q|-max_error|0|%s/f.tif|%s/o.gpkg",
           dir, dir);
  CHECK_INT_EQ(run_line(line, out, NULL, NULL, &res), TT_OK);
  CHECK_INT_EQ(res.exit_code, TT_APP_EXIT_THRESHOLD);
  CHECK(strstr(res.message, "exceeds -max_error") != NULL);

  fclose(out);
  snprintf(line, sizeof line, "rm -rf '%s'", dir);
  if (system(line) != 0)
    TT_FAIL_("cannot remove %s", dir);
}

int main(void)
{
  TT_RUN(test_simplify_defaults());
  TT_RUN(test_simplify_all_options());
  TT_RUN(test_simplify_usage_errors());
  TT_RUN(test_layers());
  TT_RUN(test_issue11_parsing());
  TT_RUN(test_help_and_version());
  TT_RUN(test_generate());
  TT_RUN(test_eval());
  TT_RUN(test_optimize());
  TT_RUN(test_input_options());
  TT_RUN(test_progress_bar());
  TT_RUN(test_no_argv());
  TT_RUN(test_library_runs());
  TT_TEST_DONE();
}
