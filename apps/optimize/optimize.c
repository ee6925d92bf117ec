/*
 * optimize.c -- apps/optimize/: the optimize command, a folder over the
 * core (apps/core/). `terratin optimize DEM IN_TIN OUTPUT`: read the DEM
 * and a layer of triangles (as eval reads them), rebuild the mesh,
 * optimise it for the criterion (tt_optimize_run), write the layers
 * simplify writes under a temporary name and commit them, then print a
 * summary or JSON.
 *
 * A run is a pipeline over one optimize_run: begin the output, read the
 * inputs, optimise, write, report; each step records its failure, and
 * tt__app_optimize frees what they made.
 *
 * Invariants: neither input is written; an existing output is replaced
 * only with -overwrite and only once the new one is complete; a failure at
 * any phase leaves nothing behind. The max error never grows unless asked:
 * without -max_error the input TIN's own max error is the bound (a move
 * that would pass it is refused). The summary gives every measure before
 * and after, so a run says what it changed.
 */
#include "app.h"

#include <cpl_conv.h>
#include <cpl_string.h>
#include <ogr_api.h>
#include <ogr_srs_api.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* One optimize run: the output, the inputs as read, the TIN made, the
 * measures before and after, the times. */
typedef struct optimize_run {
  app_run *r;
  const tt_app_settings *s;
  GDALDriverH drv;          /* the output's driver */
  tt_output *outp;
  GDALDatasetH tds, dst;    /* the input TIN's dataset, the output's */
  tt_grid *grid;
  tt_raster_info *info;
  size_t valid;             /* the DEM's valid samples */
  char lname[256];          /* the input's triangle layer */
  double *xyz;              /* ntri triangles, corners in pixel space */
  size_t ntri, rejected;
  tt_eval_result before;    /* the input's errors */
  double angle_before;
  tt_tin *tin;              /* the optimised TIN */
  tt_tin_summary sum;       /* and its errors */
  double angle_after;
  tt_optimize mode;         /* the optimiser that ran */
  double bound;             /* the max error no move may pass */
  int bound_given;          /* -max_error set it; else the input's own */
  OGRSpatialReferenceH srs; /* the layers' CRS: the DEM's */
  char **wopts;
  double t_read, t_opt, t_write;
} optimize_run;

/* The largest 2-D angle, degrees, of triangles given in pixel space, in
 * the DEM's ground frame. */
static double largest_angle(const tt_grid *g, size_t nt, const double *xyz)
{
  double fr[4], best = 0.0;
  tt_grid_get_ground_frame(g, fr);
  for (size_t t = 0; t < nt; t++)
    for (int k = 0; k < 3; k++) {
      const double *a = xyz + 9 * t + 3 * k;
      const double *b = xyz + 9 * t + 3 * ((k + 1) % 3);
      const double *c = xyz + 9 * t + 3 * ((k + 2) % 3);
      double ux = fr[0] * (b[0] - a[0]) + fr[1] * (b[1] - a[1]);
      double uy = fr[2] * (b[0] - a[0]) + fr[3] * (b[1] - a[1]);
      double vx = fr[0] * (c[0] - a[0]) + fr[1] * (c[1] - a[1]);
      double vy = fr[2] * (c[0] - a[0]) + fr[3] * (c[1] - a[1]);
      double ang = atan2(fabs(ux * vy - uy * vx), ux * vx + uy * vy);
      if (ang > best)
        best = ang;
    }
  return best * 180.0 / 3.14159265358979323846;
}

static double tin_largest_angle(const tt_tin *tin)
{
  double best = 0.0;
  for (size_t i = 0; i < tt_tin_triangle_count(tin); i++) {
    tt_triangle_info ti;
    if (tt_tin_triangle(tin, i, &ti) == TT_OK && ti.max_angle_deg > best)
      best = ti.max_angle_deg;
  }
  return best;
}

/* The output's driver and temporary name; an input as output refused. */
static tt_status begin_output(optimize_run *p)
{
  app_run *r = p->r;
  const tt_app_settings *s = p->s;
  if (tt__app_same_file(s->input, s->output) ||
      tt__app_same_file(s->tin, s->output))
    return tt__app_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_ARG, s->output,
                        "is an input; refusing to replace it");
  if (!(p->drv = tt__app_output_driver(r)))
    return r->res->status;
  r->msg.last[0] = '\0';
  tt_status st = tt_output_begin(r->ctx, s->output,
                                 GDALGetDriverShortName(p->drv),
                                 s->overwrite, &p->outp);
  if (st == TT_ERR_EXISTS)
    return tt__app_fail_exists(r, s->output);
  if (st != TT_OK)
    return tt__app_fail_tt(r, st, s->output);
  return TT_OK;
}

/* The DEM and the triangles (triangles only), measured as they are. */
static tt_status read_inputs(optimize_run *p)
{
  app_run *r = p->r;
  const tt_app_settings *s = p->s;
  OGRLayerH layer = NULL;
  tt__app_phase_set(&r->prog, 0.0, 0.10);
  tt_status st = tt__app_read_dem_and_tin(r, p->outp, &p->grid, &p->info,
                                          &p->valid, &p->tds, &layer);
  if (st != TT_OK)
    return st;
  snprintf(p->lname, sizeof p->lname, "%s", OGR_L_GetName(layer));
  r->msg.last[0] = '\0';
  st = tt_ogr_read_triangles(r->ctx, layer, p->info->gt, &p->xyz, &p->ntri,
                             &p->rejected);
  if (st != TT_OK)
    return tt__app_fail_tt(r, st, s->tin);
  if (p->ntri == 0)
    return tt__app_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_DATA, s->tin,
                        "layer '%s' holds no triangles (%zu polygon%s "
                        "rejected)", p->lname, p->rejected,
                        p->rejected == 1 ? "" : "s");
  if (p->rejected)
    return tt__app_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_DATA, s->tin,
                        "layer '%s': %zu polygon%s not triangles (or "
                        "without Z): a TIN to optimise must be triangles "
                        "only", p->lname, p->rejected,
                        p->rejected == 1 ? " is" : "s are");
  GDALClose(p->tds);
  p->tds = NULL;
  /* corners a few 1e-9 pixel off their sample (map coordinates round-off)
   * go back on it, as eval does; the engine refuses any farther off */
  for (size_t i = 0; i < p->ntri * 9; i++) {
    double rounded = floor(p->xyz[i] + 0.5);
    if (i % 3 != 2 && fabs(p->xyz[i] - rounded) <= 1e-6)
      p->xyz[i] = rounded;
  }
  p->t_read = tt__app_now() - r->t0;
  st = tt_eval_triangles(r->ctx, p->grid, p->ntri, p->xyz, &p->before);
  if (st != TT_OK)
    return tt__app_fail_tt(r, st, s->tin);
  p->angle_before = largest_angle(p->grid, p->ntri, p->xyz);
  return TT_OK;
}

static tt_status optimise(optimize_run *p)
{
  app_run *r = p->r;
  const tt_app_settings *s = p->s;
  tt_optimize_options oo;
  tt_optimize_options_init(&oo);
  oo.criterion = s->criterion;
  oo.optimize = s->optimize;
  /* the input's own max error, unless -max_error sets another */
  p->bound_given = s->max_error >= 0;
  p->bound = p->bound_given ? s->max_error : p->before.errors.max_error;
  oo.max_error = p->bound;
  oo.anneal = s->anneal;
  double t = tt__app_now();
  tt_status st = tt_optimize_run(r->ctx, p->grid, p->ntri, p->xyz, &oo,
                                 &p->tin);
  if (st != TT_OK)
    return tt__app_fail(r, TT_APP_EXIT_FAILURE, st, s->tin, "%s",
                        tt__app_why(r, st, s->tin));
  p->t_opt = tt__app_now() - t;
  tt_tin_get_summary(p->tin, &p->sum);
  p->angle_after = tin_largest_angle(p->tin);
  p->mode = s->optimize == TT_OPTIMIZE_AUTO ? TT_OPTIMIZE_LOCAL : s->optimize;
  return TT_OK;
}

/* The layers into the output's temporary name, closed, then committed. */
static tt_status write_output(optimize_run *p)
{
  app_run *r = p->r;
  const tt_app_settings *s = p->s;
  const char *drvname = GDALGetDriverShortName(p->drv);
  double t = tt__app_now();
  tt__app_phase_set(&r->prog, 0.85, 0.99);
  r->msg.last[0] = '\0';
  p->dst = GDALCreate(p->drv, tt_output_temp_path(p->outp), 0, 0, 0,
                      GDT_Unknown, (CSLConstList)s->dsco);
  if (!p->dst)
    return tt__app_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_IO, s->output,
                        "cannot create %s dataset: %s", drvname,
                        r->msg.last[0] ? r->msg.last : "unknown reason");
  if (p->info->crs_wkt && *p->info->crs_wkt) {
    p->srs = OSRNewSpatialReference(p->info->crs_wkt);
    if (p->srs)
      OSRSetAxisMappingStrategy(p->srs, OAMS_TRADITIONAL_GIS_ORDER);
  }
  char created[32];
  tt__app_iso8601_utc(created, sizeof created);
  const tt_error_stats *e = &p->sum.errors;
  const tt_run_field fields[] = {
      {"input", TT_FIELD_STRING, tt__app_shown(r, s->input), 0, 0},
      {"in_tin", TT_FIELD_STRING, tt__app_shown(r, s->tin), 0, 0},
      {"band", TT_FIELD_INTEGER, NULL, s->band, 0},
      {"criterion", TT_FIELD_STRING, tt_criterion_name(s->criterion), 0, 0},
      {"optimize", TT_FIELD_STRING, tt_optimize_name(p->mode), 0, 0},
      {"max_error", TT_FIELD_REAL, NULL, 0, p->bound},
      {"seed", TT_FIELD_INTEGER, NULL, (int64_t)s->anneal.seed, 0},
      {"vertices", TT_FIELD_INTEGER, NULL, (int64_t)p->sum.vertices, 0},
      {"triangles", TT_FIELD_INTEGER, NULL, (int64_t)p->sum.triangles, 0},
      {"in_mean", TT_FIELD_REAL, NULL, 0, p->before.errors.mean_abs},
      {"in_max", TT_FIELD_REAL, NULL, 0, p->before.errors.max_error},
      {"in_rmse", TT_FIELD_REAL, NULL, 0, p->before.errors.rmse},
      {"in_l2", TT_FIELD_REAL, NULL, 0, p->before.errors.l2},
      {"in_angle", TT_FIELD_REAL, NULL, 0, p->angle_before},
      {"ach_max", TT_FIELD_REAL, NULL, 0, e->max_error},
      {"ach_rmse", TT_FIELD_REAL, NULL, 0, e->rmse},
      {"ach_mean", TT_FIELD_REAL, NULL, 0, e->mean_abs},
      {"ach_l2", TT_FIELD_REAL, NULL, 0, e->l2},
      {"ach_angle", TT_FIELD_REAL, NULL, 0, p->angle_after},
      {"version", TT_FIELD_STRING, tt_version(), 0, 0},
      {"t_read", TT_FIELD_REAL, NULL, 0, p->t_read},
      {"t_optimize", TT_FIELD_REAL, NULL, 0, p->t_opt},
      {"created", TT_FIELD_STRING, created, 0, 0},
  };
  char *prefix = CPLStrdup(CPLSPrintf("%s%s",
                                      tt_output_layer_prefix(p->outp),
                                      s->nln));
  p->wopts = CSLSetNameValue(p->wopts, "NLN_PREFIX", prefix);
  CPLFree(prefix);
  for (size_t i = 0; s->lco[i]; i++)
    p->wopts = CSLAddNameValue(p->wopts, "LCO", s->lco[i]);
  /* the heights' unit, for the fields' descriptions */
  p->wopts = CSLSetNameValue(p->wopts, "Z_UNIT", p->info->z_unit);
  tt_status st = tt_ogr_write_tin(r->ctx, p->dst, p->tin, p->srs, fields,
                                  sizeof fields / sizeof fields[0], p->wopts,
                                  tt__app_phase_fn, &r->prog);
  if (st != TT_OK)
    return tt__app_fail_tt(r, st, s->output);
  unsigned failures = r->msg.failures;
  GDALClose(p->dst);
  p->dst = NULL;
  if (r->msg.failures != failures)
    return tt__app_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_IO, s->output,
                        "error while closing: %s", r->msg.last);
  st = tt_output_commit(r->ctx, p->outp);
  if (st == TT_ERR_EXISTS)
    return tt__app_fail_exists(r, s->output);
  if (st != TT_OK)
    return tt__app_fail_tt(r, st, s->output);
  p->t_write = tt__app_now() - t;
  return TT_OK;
}

static void report_json(const optimize_run *p)
{
  const tt_app_settings *s = p->s;
  const tt_error_stats *e = &p->sum.errors;
  app_json j;
  tt__json_begin(&j, p->r->out);
  tt__json_str(&j, "dem", tt__app_shown(p->r, s->input));
  tt__json_str(&j, "in_tin", tt__app_shown(p->r, s->tin));
  tt__json_str(&j, "layer", p->lname);
  tt__json_str(&j, "output", tt__app_shown(p->r, s->output));
  tt__json_str(&j, "criterion", tt_criterion_name(s->criterion));
  tt__json_str(&j, "optimize", tt_optimize_name(p->mode));
  tt__json_size(&j, "vertices", p->sum.vertices);
  tt__json_size(&j, "triangles", p->sum.triangles);
  tt__json_num(&j, "max_error_bound", p->bound);
  tt__json_str(&j, "max_error_bound_from",
               p->bound_given ? "-max_error" : "input");
  tt__json_open(&j, "before");
  tt__json_num(&j, "mean_abs_error", p->before.errors.mean_abs);
  tt__json_num(&j, "max_error", p->before.errors.max_error);
  tt__json_num(&j, "rmse", p->before.errors.rmse);
  tt__json_num(&j, "l2", p->before.errors.l2);
  tt__json_num(&j, "largest_angle_deg", p->angle_before);
  tt__json_close(&j);
  tt__json_open(&j, "after");
  tt__json_num(&j, "mean_abs_error", e->mean_abs);
  tt__json_num(&j, "max_error", e->max_error);
  tt__json_num(&j, "rmse", e->rmse);
  tt__json_num(&j, "l2", e->l2);
  tt__json_num(&j, "largest_angle_deg", p->angle_after);
  tt__json_close(&j);
  tt__json_str(&j, "z_unit", tt__app_nonempty_or_null(p->info->z_unit));
  tt__json_open(&j, "seconds");
  tt__json_num(&j, "read", p->t_read);
  tt__json_num(&j, "optimize", p->t_opt);
  tt__json_num(&j, "write", p->t_write);
  tt__json_num(&j, "total", tt__app_now() - p->r->t0);
  tt__json_close(&j);
  tt__json_close(&j);
}

static void report(const optimize_run *p)
{
  const tt_app_settings *s = p->s;
  const tt_error_stats *e = &p->sum.errors;
  FILE *o = p->r->out;
  if (s->json) {
    report_json(p);
  } else if (!s->quiet) {
    fprintf(o, "%s: %zu vertices, %zu triangles of %s layer %s, %s by %s "
               "in %.3f s\n", tt__app_shown(p->r, s->output), p->sum.vertices,
            p->sum.triangles, tt__app_shown(p->r, s->tin), p->lname, tt_criterion_name(s->criterion),
            tt_optimize_name(p->mode), p->t_opt);
    const char *u = tt__app_unit_or(p->info, "z units");
    fprintf(o, "max error %.9g -> %.9g %s (bound %.9g %s: %s), RMS %.9g -> "
               "%.9g, mean abs %.9g -> %.9g, L2 %.9g -> %.9g, largest "
               "angle %.6g -> %.6g degrees\n",
            p->before.errors.max_error, e->max_error, u, p->bound, u,
            p->bound_given ? "-max_error"
                           : "the input's own; -max_error sets another",
            p->before.errors.rmse, e->rmse, p->before.errors.mean_abs,
            e->mean_abs, p->before.errors.l2, e->l2, p->angle_before,
            p->angle_after);
  }
  fflush(o);
}

tt_status tt__app_optimize(app_run *r)
{
  optimize_run p;
  memset(&p, 0, sizeof p);
  p.r = r;
  p.s = r->s;
  tt_status st = begin_output(&p);
  if (st == TT_OK)
    st = read_inputs(&p);
  if (st == TT_OK)
    st = optimise(&p);
  if (st == TT_OK)
    st = write_output(&p);
  if (st == TT_OK)
    report(&p);

  if (p.dst)
    GDALClose(p.dst);
  if (p.tds)
    GDALClose(p.tds);
  tt_output_destroy(p.outp);
  if (p.srs)
    OSRDestroySpatialReference(p.srs);
  CSLDestroy(p.wopts);
  free(p.xyz);
  tt_tin_destroy(p.tin);
  tt_grid_destroy(p.grid);
  tt_raster_info_destroy(p.info);
  return st;
}
