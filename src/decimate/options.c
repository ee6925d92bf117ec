/*
 * options.c -- vertex decimation's names and options (SPEC section 3.6):
 * the names of the importance measures, selections, hole rules and
 * starts and their parsing, the options' defaults, and the check of a
 * whole option set that every entry of decimate.c makes first.
 *
 * Part of src/decimate/, the vertex decimation method (tt_decimate_run).
 */
#include "decimate/decimate.h"

#include "optimize/optimize.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static const char *const IMPORTANCE_NAMES[] = {
    "auto", "degree", "hdh", "abh", "volume", "drop", "error"};
static const char *const SELECTION_NAMES[] = {"independent", "sequential"};
static const char *const HOLE_NAMES[] = {"auto", "minangle", "circumradius",
                                         "dp"};

const char *tt_importance_name(tt_importance i)
{
  return (unsigned)i < 7 ? IMPORTANCE_NAMES[i] : NULL;
}

const char *tt_selection_name(tt_selection s)
{
  return (unsigned)s < 2 ? SELECTION_NAMES[s] : NULL;
}

const char *tt_hole_name(tt_hole h)
{
  return (unsigned)h < 4 ? HOLE_NAMES[h] : NULL;
}

const char *tt_decimate_start_name(tt_decimate_start s)
{
  switch (s) {
  case TT_DSTART_ALL: return "all";
  case TT_DSTART_GREEDY: return "greedy";
  case TT_DSTART_GREEDY_N: return "greedy:N";
  }
  return NULL;
}

static int find_name(const char *const *names, int n, const char *name)
{
  for (int i = 0; name && i < n; i++)
    if (strcmp(names[i], name) == 0)
      return i;
  return -1;
}

tt_status tt_importance_parse(tt_context *ctx, const char *name,
                              tt_importance *out)
{
  int i = find_name(IMPORTANCE_NAMES, 7, name);
  if (i < 0)
    return tt__error(ctx, TT_ERR_ARG, "unknown importance '%s' (auto, "
                     "degree, hdh, abh, volume, drop, error)",
                     name ? name : "");
  *out = (tt_importance)i;
  return TT_OK;
}

tt_status tt_selection_parse(tt_context *ctx, const char *name,
                             tt_selection *out)
{
  int i = find_name(SELECTION_NAMES, 2, name);
  if (i < 0)
    return tt__error(ctx, TT_ERR_ARG, "unknown selection '%s' (independent, "
                     "sequential)", name ? name : "");
  *out = (tt_selection)i;
  return TT_OK;
}

tt_status tt_hole_parse(tt_context *ctx, const char *name, tt_hole *out)
{
  int i = find_name(HOLE_NAMES, 4, name);
  if (i < 0)
    return tt__error(ctx, TT_ERR_ARG, "unknown hole rule '%s' (auto, "
                     "minangle, circumradius, dp)", name ? name : "");
  *out = (tt_hole)i;
  return TT_OK;
}

tt_status tt_decimate_start_parse(tt_context *ctx, const char *name,
                                  tt_decimate_start *out_start,
                                  size_t *out_points)
{
  if (name && strcmp(name, "all") == 0) {
    *out_start = TT_DSTART_ALL;
    *out_points = 0;
    return TT_OK;
  }
  if (name && strcmp(name, "greedy") == 0) {
    *out_start = TT_DSTART_GREEDY;
    *out_points = 0;
    return TT_OK;
  }
  if (name && strncmp(name, "greedy:", 7) == 0) {
    const char *s = name + 7;
    char *end = NULL;
    unsigned long long n = 0;
    if (*s >= '0' && *s <= '9')
      n = strtoull(s, &end, 10);
    if (end && *end == '\0' && n >= 3 && n <= TT_MAX_VERTICES) {
      *out_start = TT_DSTART_GREEDY_N;
      *out_points = (size_t)n;
      return TT_OK;
    }
  }
  return tt__error(ctx, TT_ERR_ARG, "unknown start '%s' (all, greedy, "
                   "greedy:N with N >= 3)", name ? name : "");
}

void tt_decimate_options_init(tt_decimate_options *opt)
{
  memset(opt, 0, sizeof *opt);
  opt->max_error = -1.0;
  opt->criterion = TT_CRITERION_DELAUNAY;
  opt->start = TT_DSTART_ALL;
}

tt_status tt__decimate_check_options(tt_context *ctx,
                                     const tt_decimate_options *o)
{
  if (isnan(o->max_error) || isinf(o->max_error))
    return tt__error(ctx, TT_ERR_ARG, "max error must be a finite number, "
                     "got %g", o->max_error);
  if (isnan(o->percent) || o->percent < 0 || o->percent > 100)
    return tt__error(ctx, TT_ERR_ARG, "percent must be in (0, 100], got %g",
                     o->percent);
  if (o->max_error < 0 && !o->max_points && !o->max_triangles &&
      o->percent == 0)
    return tt__error(ctx, TT_ERR_ARG, "no stop condition: set a max error, "
                     "a point or triangle budget, or a percentage");
  if (o->breaklines.n && !o->breaklines.ends)
    return tt__error(ctx, TT_ERR_ARG, "breaklines.ends is NULL with n %zu",
                     o->breaklines.n);
  if (!tt__criterion_get(o->criterion))
    return tt__error(ctx, TT_ERR_ARG, "unknown criterion %d",
                     (int)o->criterion);
  if (!tt_decimate_start_name(o->start))
    return tt__error(ctx, TT_ERR_ARG, "unknown start %d", (int)o->start);
  if (o->start == TT_DSTART_GREEDY_N &&
      (o->start_points < 3 || o->start_points > TT_MAX_VERTICES))
    return tt__error(ctx, TT_ERR_ARG, "start greedy:N needs N >= 3, got %zu",
                     o->start_points);
  if (!tt_importance_name(o->importance))
    return tt__error(ctx, TT_ERR_ARG, "unknown importance %d",
                     (int)o->importance);
  if (!tt_selection_name(o->selection))
    return tt__error(ctx, TT_ERR_ARG, "unknown selection %d",
                     (int)o->selection);
  if (o->onepass && o->selection != TT_SELECTION_INDEPENDENT)
    return tt__error(ctx, TT_ERR_ARG, "onepass applies to independent sets "
                     "only");
  if (!tt_hole_name(o->hole))
    return tt__error(ctx, TT_ERR_ARG, "unknown hole rule %d", (int)o->hole);
  if (o->hole == TT_HOLE_DP && !tt__dhole_dp_supported(o->criterion))
    return tt__error(ctx, TT_ERR_ARG, "hole dp needs a decomposable "
                     "criterion (delaunay, minmax_angle, minmax_angle_lex, "
                     "min_area), not %s", tt_criterion_name(o->criterion));
  if (!tt_repair_name(o->repair))
    return tt__error(ctx, TT_ERR_ARG, "unknown repair %d", (int)o->repair);
  if (!tt_optimize_name(o->optimize))
    return tt__error(ctx, TT_ERR_ARG, "unknown optimisation %d",
                     (int)o->optimize);
  /* edge insertion's criterion, the annealing schedule */
  tt_status st = tt_optimize_check(ctx, o->optimize, o->criterion,
                                   &o->anneal);
  if (st != TT_OK)
    return st;
  return TT_OK;
}
