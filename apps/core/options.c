/*
 * options.c -- apps/core/: the command's core, what every command's
 * folder shares. This file: the command line of terratin, the parser that
 * turns the words after the program name into a tt_app_options object
 * (its accessors are in settings.c, the values of words in values.c). It
 * walks the words: --help and --version first, then the global options,
 * the command word, the options (read through option_table.c's table, an
 * entry per option saying which commands take it, what its value is and
 * where it goes) and the positional words; then it checks what concerns
 * several options or the command's positional words.
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

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char *const empty_list[] = {NULL};

static int is_help_word(const char *w)
{
  return tt__app_str_ieq(w, "--help") || tt__app_str_ieq(w, "-help") ||
         tt__app_str_ieq(w, "-h") || tt__app_str_ieq(w, "-?");
}

/* The command a word names (case-insensitive), or TT_APP_NONE. */
static tt_app_command command_named(const char *w)
{
  for (const tt__app_command_def *d = tt__app_commands; d->name; d++)
    if (tt__app_str_ieq(w, d->name))
      return d->command;
  return TT_APP_NONE;
}

/* An options object holding every default, or NULL. */
static tt_app_options *new_options(void)
{
  tt_app_options *o = calloc(1, sizeof *o);
  if (!o)
    return NULL;
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
  return o;
}

/* --help, --help-general, --version and --formats win over anything else
 * on the line, even over an error earlier in it, as in GDAL's utilities: a
 * user who asks for help gets it. The command word, if any, picks the help
 * page. 1 when the line asks for one (the command set to TT_APP_HELP,
 * TT_APP_HELP_GENERAL, TT_APP_VERSION or TT_APP_FORMATS, in that order of
 * precedence). */
static int asks_help_or_version(tt_app_settings *s, char **argv)
{
  int want_help = 0, want_version = 0, want_general = 0, want_formats = 0;
  tt_app_command first_cmd = TT_APP_NONE;
  for (size_t i = 0; argv[i]; i++) {
    const char *w = argv[i];
    if (is_help_word(w))
      want_help = 1;
    else if (tt__app_str_ieq(w, "--version"))
      want_version = 1;
    else if (tt__app_str_ieq(w, "--help-general"))
      want_general = 1;
    else if (tt__app_str_ieq(w, "--formats"))
      want_formats = 1;
    else if (first_cmd == TT_APP_NONE && w[0] != '-') {
      if (tt__app_str_ieq(w, "help")) {
        want_help = 1;
        continue;
      }
      if (tt__app_str_ieq(w, "tiles")) { /* `terratin help tiles` */
        first_cmd = TT_APP_TILES;
        continue;
      }
      if ((first_cmd = command_named(w)) == TT_APP_NONE)
        break; /* an unknown command: reported by read_words */
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
    s->command = TT_APP_HELP;
    s->help_topic = first_cmd;
  } else if (want_general) {
    s->command = TT_APP_HELP_GENERAL;
  } else if (want_version) {
    s->command = TT_APP_VERSION;
  } else if (want_formats) {
    s->command = TT_APP_FORMATS;
  }
  return want_help || want_general || want_version || want_formats;
}

/* --- the words, one at a time --------------------------------------------- */

/* --config KEY VALUE or --config KEY=VALUE, at argv[*i]. */
static tt_status read_config(tt__app_opt_parse *p, char **argv, size_t *i)
{
  app_strlist *config = &p->o->config;
  const char *k = argv[*i + 1];
  if (!k)
    return OPT_USAGE(p, "--config needs KEY VALUE");
  const char *eq = strchr(k, '=');
  if (eq == k)
    return OPT_USAGE(p, "--config: empty KEY in '%s'", k);
  if (!eq) {
    if (!argv[*i + 2])
      return OPT_USAGE(p, "--config %s needs a VALUE", k);
    if (!*k)
      return OPT_USAGE(p, "--config needs a non-empty KEY");
    if (!tt__app_strlist_add(config, k) ||
        !tt__app_strlist_add(config, argv[*i + 2]))
      return OPT_NOMEM(p);
    *i += 2;
    return TT_OK;
  }
  /* --config KEY=VALUE (GDAL >= 3.9 accepts it too) */
  char *key = malloc((size_t)(eq - k) + 1);
  if (!key)
    return OPT_NOMEM(p);
  memcpy(key, k, (size_t)(eq - k));
  key[eq - k] = '\0';
  int ok = tt__app_strlist_add(config, key) &&
           tt__app_strlist_add(config, eq + 1);
  free(key);
  if (!ok)
    return OPT_NOMEM(p);
  *i += 1;
  return TT_OK;
}

/* --debug on|off, at argv[*i]: GDAL's CPL_DEBUG. */
static tt_status read_debug(tt__app_opt_parse *p, char **argv, size_t *i)
{
  const char *v = argv[*i + 1];
  if (!v)
    return OPT_USAGE(p, "--debug needs a value: on or off");
  if (!tt__app_is_gdal_bool(v))
    return OPT_USAGE(p, "--debug must be on, off, yes, no, true, false, 1 "
                     "or 0, got '%s'", v);
  if (!tt__app_strlist_add(&p->o->config, "CPL_DEBUG") ||
      !tt__app_strlist_add(&p->o->config, v))
    return OPT_NOMEM(p);
  *i += 1;
  return TT_OK;
}

/* The command nearest to a mistyped word (two edits at most), or NULL. */
static const char *command_suggest(const char *w)
{
  const char *names[16];
  size_t n = 0, best = 3;
  const char *name = NULL;
  for (const tt__app_command_def *d = tt__app_commands; d->name && n < 15;
       d++)
    names[n++] = d->name;
  names[n++] = "tiles"; /* dispatched by main() before the parser */
  for (size_t i = 0; i < n; i++) {
    size_t e = tt__app_edit_distance(w, names[i]);
    if (e < best && 2 * e < strlen(w)) {
      best = e;
      name = names[i];
    }
  }
  return name;
}

static tt_status read_command(tt__app_opt_parse *p, const char *w)
{
  if (w[0] == '-' && w[1] != '\0')
    return OPT_USAGE(p, "unknown option '%s' before the command; expected "
                     "simplify, generate, eval, optimize, study, rasterize "
                     "or tiles (see 'terratin --help')", w);
  tt_app_command c = command_named(w);
  if (c == TT_APP_NONE) {
    const char *near = command_suggest(w);
    if (near)
      return OPT_USAGE(p, "unknown command '%s'; did you mean %s? (see "
                       "'terratin --help')", w, near);
    return OPT_USAGE(p, "unknown command '%s'; expected simplify, generate, "
                     "eval, optimize, study, rasterize or tiles (see "
                     "'terratin --help')", w);
  }
  p->o->s.command = c;
  p->cmdname = tt__app_command_name(c);
  snprintf(p->hint, sizeof p->hint, " (see 'terratin %s --help')",
           p->cmdname);
  return TT_OK;
}

/* "-" alone and negative numbers are positional words. */
static int is_option_word(const char *w)
{
  double number;
  return w[0] == '-' && w[1] != '\0' && !tt__app_parse_double(w, &number);
}

/* The option at argv[*i] and its value, through the table. */
static tt_status read_option(tt__app_opt_parse *p, char **argv, size_t *i)
{
  const char *w = argv[*i], *v = NULL;
  char joined[512]; /* the words of a value of several (-srcwin's four) */
  const tt__app_opt_def *d = tt__app_find_opt(w), *mine;
  if (!d) {
    const char *near = tt__app_opt_suggest(w, p->o->s.command);
    if (near)
      return OPT_USAGE(p, "%s: unknown option '%s'; did you mean %s?%s",
                       p->cmdname, w, near, p->hint);
    return OPT_USAGE(p, "%s: unknown option '%s'%s", p->cmdname, w, p->hint);
  }
  if (!(mine = tt__app_opt_for(d, p->o->s.command)))
    return OPT_USAGE(p, "%s: option %s does not apply to this command%s",
                     p->cmdname, d->name, p->hint);
  int n = tt__app_opt_takes_value(mine);
  if (n == 1) {
    if (!(v = argv[*i + 1]))
      return OPT_USAGE(p, "%s: option %s needs a value%s", p->cmdname,
                       d->name, p->hint);
    *i += 1;
  } else if (n > 1) {
    /* the words of one value (-srcwin's four), joined by spaces: a word
     * missing, or one that holds a space, refused by the reader */
    size_t len = 0;
    for (int k = 1; k <= n; k++) {
      const char *word = argv[*i + (size_t)k];
      if (!word || *word == '\0')
        return OPT_USAGE(p, "%s: option %s needs %d values%s", p->cmdname,
                         d->name, n, p->hint);
      int m = snprintf(joined + len, sizeof joined - len, "%s%s",
                       k > 1 ? " " : "", word);
      if (m < 0 || (size_t)m >= sizeof joined - len)
        return OPT_USAGE(p, "%s: option %s: values too long", p->cmdname,
                         d->name);
      len += (size_t)m;
      if (k == n)
        *i += (size_t)n;
    }
    v = joined;
  }
  return tt__app_opt_apply(p, mine, v);
}

static tt_status read_positional(tt__app_opt_parse *p, const char *w)
{
  const tt__app_command_def *d = tt__app_command_def_of(p->o->s.command);
  if (p->npos >= (d ? d->npos : 0))
    return OPT_USAGE(p, "%s: unexpected argument '%s'%s", p->cmdname, w,
                     p->hint);
  p->pos[p->npos++] = w;
  return TT_OK;
}

/* Global options, before or after the command word; then the command
 * word; then its options and positional words. */
static tt_status read_words(tt__app_opt_parse *p, char **argv)
{
  tt_status st = TT_OK;
  for (size_t i = 0; argv[i] && st == TT_OK; i++) {
    const char *w = argv[i];
    if (tt__app_str_ieq(w, "--config"))
      st = read_config(p, argv, &i);
    else if (tt__app_str_ieq(w, "--debug"))
      st = read_debug(p, argv, &i);
    else if (p->o->s.command == TT_APP_NONE)
      st = read_command(p, w);
    else if (is_option_word(w))
      st = read_option(p, argv, &i);
    else
      st = read_positional(p, w);
  }
  return st;
}

/* --formats: only the global options count (--config GDAL_SKIP=... hides
 * a driver from the list as from a run); the other words are ignored, as
 * GDAL's utilities ignore them beside --formats. */
static tt_status read_global_words(tt__app_opt_parse *p, char **argv)
{
  tt_status st = TT_OK;
  for (size_t i = 0; argv[i] && st == TT_OK; i++) {
    if (tt__app_str_ieq(argv[i], "--config"))
      st = read_config(p, argv, &i);
    else if (tt__app_str_ieq(argv[i], "--debug"))
      st = read_debug(p, argv, &i);
  }
  return st;
}

/* --- once the line is read: the positional words and the checks ----------- */

/* One value, several places: -seed is also the anneal's (and the
 * generated terrain's: check_generate); -z_factor says it was given. */
static void apply_given(tt__app_opt_parse *p)
{
  tt_app_settings *s = &p->o->s;
  if (OPT_GIVEN(p, O_SEED)) {
    s->seed_set = 1;
    s->anneal.seed = s->seed;
  }
  if (OPT_GIVEN(p, O_Z_FACTOR))
    s->z_factor_set = 1;
  if (OPT_GIVEN(p, O_S_SRS))
    s->srs_is_s_srs = 1;
}

/* Keeps the positional words where the command's entry in the dispatch
 * table says (run.c), in order. */
static tt_status keep_positional(tt__app_opt_parse *p)
{
  const tt__app_command_def *d = tt__app_command_def_of(p->o->s.command);
  for (size_t k = 0; d && k < d->npos && k < p->npos; k++) {
    if (d->pos[k] == TT_APP_POS_NONE)
      continue;
    const char *kept = tt__app_opt_keep(p->o, p->pos[k]);
    if (!kept)
      return OPT_NOMEM(p);
    *(const char **)((char *)&p->o->s + d->pos[k]) = kept;
  }
  return TT_OK;
}

static tt_status check_simplify(tt__app_opt_parse *p)
{
  tt_app_settings *s = &p->o->s;
  if (p->npos < 1)
    return OPT_USAGE(p, "simplify: missing INPUT and OUTPUT%s", p->hint);
  if (p->npos < 2)
    return OPT_USAGE(p, "simplify: missing OUTPUT after '%s'%s", p->pos[0],
                     p->hint);
  if (keep_positional(p) != TT_OK)
    return TT_ERR_NOMEM;
  if (p->decimate_only && !s->decimate)
    return OPT_USAGE(p, "simplify: %s applies to -method decimate only",
                     p->decimate_only);
  if (s->onepass && s->selection != TT_SELECTION_INDEPENDENT)
    return OPT_USAGE(p, "simplify: -onepass applies to -selection "
                     "independent only");
  if (s->decimate && s->hole == TT_HOLE_DP &&
      s->criterion != TT_CRITERION_DELAUNAY &&
      s->criterion != TT_CRITERION_MINMAX_ANGLE &&
      s->criterion != TT_CRITERION_MINMAX_ANGLE_LEX &&
      s->criterion != TT_CRITERION_MIN_AREA)
    return OPT_USAGE(p, "simplify: -hole dp needs a decomposable criterion "
                     "(delaunay, minmax_angle, minmax_angle_lex, min_area), "
                     "not %s", tt_criterion_name(s->criterion));
  return TT_OK;
}

static tt_status check_study(tt__app_opt_parse *p)
{
  if (p->npos < 1)
    return OPT_USAGE(p, "study: missing OUTDIR%s", p->hint);
  if (!p->o->terrains.n)
    return OPT_USAGE(p, "study: no -terrain given (a DEM file or "
                     "fault_smooth, fault_rough, peak_rough, valley_rough, "
                     "hybrid, sphere, cylinder, bump)%s", p->hint);
  return keep_positional(p);
}

static tt_status check_eval(tt__app_opt_parse *p)
{
  tt_app_settings *s = &p->o->s;
  if (p->npos < 1)
    return OPT_USAGE(p, "eval: missing DEM and TIN%s", p->hint);
  if (p->npos < 2)
    return OPT_USAGE(p, "eval: missing TIN after '%s'%s", p->pos[0], p->hint);
  if (keep_positional(p) != TT_OK)
    return TT_ERR_NOMEM;
  if (!s->error_raster && (s->overwrite || p->o->co.n))
    return OPT_USAGE(p, "eval: option %s does not apply without "
                     "-error_raster%s", s->overwrite ? "-overwrite" : "-co",
                     p->hint);
  return TT_OK;
}

static tt_status check_rasterize(tt__app_opt_parse *p)
{
  if (p->npos < 3)
    return OPT_USAGE(p, "rasterize: missing %s%s",
                     p->npos == 0   ? "DEM, TIN and OUTPUT"
                     : p->npos == 1 ? "TIN and OUTPUT"
                                    : "OUTPUT",
                     p->hint);
  return keep_positional(p);
}

static tt_status check_optimize(tt__app_opt_parse *p)
{
  if (p->npos < 3)
    return OPT_USAGE(p, "optimize: missing %s%s",
                     p->npos == 0   ? "DEM, IN_TIN and OUTPUT"
                     : p->npos == 1 ? "IN_TIN and OUTPUT"
                                    : "OUTPUT",
                     p->hint);
  return keep_positional(p);
}

/* generate TYPE OUTPUT: the kind's defaults, then the parameters given
 * (each for the kinds it applies to). */
static tt_status check_generate(tt__app_opt_parse *p)
{
  tt_app_settings *s = &p->o->s;
  tt_synth_options *y = &s->synth;
  const tt_synth_options *given = &p->synth;
  tt_synth_kind kind;
  if (p->npos < 1)
    return OPT_USAGE(p, "generate: missing TYPE and OUTPUT%s", p->hint);
  if (tt_synth_kind_parse(p->ctx, p->pos[0], &kind) != TT_OK)
    return OPT_USAGE(p, "generate: unknown TYPE '%s'; expected fault, "
                     "diamond_square, sphere, cylinder or bump", p->pos[0]);
  if (p->npos < 2)
    return OPT_USAGE(p, "generate: missing OUTPUT after '%s'%s", p->pos[0],
                     p->hint);
  if (keep_positional(p) != TT_OK)
    return TT_ERR_NOMEM;
  const char *kname = tt_synth_kind_name(kind);
  if (!kname)
    kname = p->pos[0];
  if (kind != TT_SYNTH_FAULT &&
      (OPT_GIVEN(p, O_ITERATIONS) || OPT_GIVEN(p, O_DISPLACEMENT) ||
       OPT_GIVEN(p, O_WAVE_SIZE)))
    return OPT_USAGE(p, "generate: -%s applies to fault terrains only, not %s",
                     (OPT_GIVEN(p, O_ITERATIONS))     ? "iterations"
                     : (OPT_GIVEN(p, O_DISPLACEMENT)) ? "displacement"
                                                     : "wave_size",
                     kname);
  if (kind != TT_SYNTH_DIAMOND_SQUARE &&
      (OPT_GIVEN(p, O_ROUGHNESS) || OPT_GIVEN(p, O_AMPLITUDE) ||
       OPT_GIVEN(p, O_SEEDING)))
    return OPT_USAGE(p, "generate: -%s applies to diamond_square terrains "
                     "only, not %s",
                     (OPT_GIVEN(p, O_ROUGHNESS))   ? "roughness"
                     : (OPT_GIVEN(p, O_AMPLITUDE)) ? "amplitude"
                                                  : "seeding",
                     kname);
  tt_synth_options_init(y, kind);
  if (OPT_GIVEN(p, O_SIZE)) {
    y->nx = given->nx;
    y->ny = given->ny;
  }
  if (kind == TT_SYNTH_DIAMOND_SQUARE &&
      (y->nx != y->ny || !tt__app_is_pow2_plus1(y->nx)))
    return OPT_USAGE(p, "generate: diamond_square needs a square size 2^n+1 "
                     "(e.g. 129, 257, 513), got %zux%zu", y->nx, y->ny);
  if (OPT_GIVEN(p, O_SEED)) y->seed = s->seed;
  if (OPT_GIVEN(p, O_ITERATIONS)) y->iterations = given->iterations;
  if (OPT_GIVEN(p, O_DISPLACEMENT)) y->displacement = given->displacement;
  if (OPT_GIVEN(p, O_WAVE_SIZE)) y->wave_size = given->wave_size;
  if (OPT_GIVEN(p, O_ROUGHNESS)) y->roughness = given->roughness;
  if (OPT_GIVEN(p, O_AMPLITUDE)) y->amplitude = given->amplitude;
  if (OPT_GIVEN(p, O_SEEDING)) y->seeding = given->seeding;
  return TT_OK;
}

/* GDAL's input options (dem_view.c): each said once, windows one way. */
static tt_status check_inputs(tt__app_opt_parse *p)
{
  if (OPT_GIVEN(p, O_A_SRS) && OPT_GIVEN(p, O_S_SRS) &&
      p->o->s.command != TT_APP_GENERATE)
    return OPT_USAGE(p, "%s: -a_srs and -s_srs both give the DEM's CRS: "
                     "give one", p->cmdname);
  if (OPT_GIVEN(p, O_SRCNODATA) && OPT_GIVEN(p, O_A_NODATA))
    return OPT_USAGE(p, "%s: -a_nodata and -srcnodata are the same option: "
                     "give one", p->cmdname);
  if (OPT_GIVEN(p, O_SRCWIN) && OPT_GIVEN(p, O_PROJWIN))
    return OPT_USAGE(p, "%s: -srcwin and -projwin both give the window: "
                     "give one", p->cmdname);
  if (OPT_GIVEN(p, O_PROJWIN_SRS) && !OPT_GIVEN(p, O_PROJWIN))
    return OPT_USAGE(p, "%s: -projwin_srs is the CRS of -projwin, which is "
                     "not given", p->cmdname);
  if (OPT_GIVEN(p, O_PROJWIN) && OPT_GIVEN(p, O_A_ULLR))
    return OPT_USAGE(p, "%s: -projwin with -a_ullr: the window would be in "
                     "the coordinates -a_ullr replaces; give the window with "
                     "-srcwin", p->cmdname);
  return TT_OK;
}

/* What concerns several options, then each command's positional words. */
static tt_status check_line(tt__app_opt_parse *p)
{
  const tt_app_settings *s = &p->o->s;
  apply_given(p);
  if (check_inputs(p) != TT_OK)
    return TT_ERR_ARG;
  if (s->optimize == TT_OPTIMIZE_EDGE_INSERTION &&
      s->criterion != TT_CRITERION_MINMAX_ANGLE)
    return OPT_USAGE(p, "%s: -optimize edge_insertion optimises the Min-Max "
                     "angle only: add -criterion minmax_angle, or use local, "
                     "lookahead or anneal", p->cmdname);
  switch (s->command) {
  case TT_APP_NONE:
    return OPT_USAGE(p, "missing command: simplify, generate, eval, "
                     "optimize, study, rasterize or tiles (see 'terratin "
                     "--help')");
  case TT_APP_SIMPLIFY: return check_simplify(p);
  case TT_APP_STUDY: return check_study(p);
  case TT_APP_EVAL: return check_eval(p);
  case TT_APP_RASTERIZE: return check_rasterize(p);
  case TT_APP_OPTIMIZE: return check_optimize(p);
  case TT_APP_GENERATE: return check_generate(p);
  default: return TT_OK;
  }
}

/* The lists the settings show, NULL-terminated, empty when not given. */
static void publish_lists(tt_app_options *o)
{
  if (o->config.n)
    o->s.config = (const char *const *)o->config.v;
  if (o->lco.n)
    o->s.lco = (const char *const *)o->lco.v;
  if (o->dsco.n)
    o->s.dsco = (const char *const *)o->dsco.v;
  o->s.terrains =
      o->terrains.n ? (const char *const *)o->terrains.v : empty_list;
  o->s.co = o->co.n ? (const char *const *)o->co.v : empty_list;
}

tt_status tt_app_options_new(char **argv, tt_app_options **out_options,
                             tt_app_result *out_result)
{
  tt_app_result local;
  tt__app_opt_parse p;
  tt_status st = TT_OK;
  memset(&p, 0, sizeof p);
  p.res = out_result ? out_result : &local;
  p.cmdname = "";
  tt__app_result_ok(p.res);
  if (out_options)
    *out_options = NULL;
  if (!argv)
    argv = (char **)empty_list;

  if (!(p.o = new_options()) || !(p.ctx = tt_context_create()))
    st = OPT_NOMEM(&p);
  else if (!asks_help_or_version(&p.o->s, argv) &&
           (st = read_words(&p, argv)) == TT_OK)
    st = check_line(&p);
  else if (p.o->s.command == TT_APP_FORMATS)
    st = read_global_words(&p, argv);

  if (p.o)
    publish_lists(p.o);
  tt_context_destroy(p.ctx);
  if (st != TT_OK) {
    tt_app_options_destroy(p.o);
    return st;
  }
  if (out_options)
    *out_options = p.o;
  else
    tt_app_options_destroy(p.o);
  return TT_OK;
}
