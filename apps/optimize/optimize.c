/*
 * optimize.c -- `terratin optimize DEM IN_TIN OUTPUT`: read the DEM and a
 * layer of triangles (as eval reads them), rebuild the mesh, optimise it
 * for the criterion (tt_optimize_run), write the layers simplify writes
 * under a temporary name and commit them, then print a summary or JSON.
 *
 * Invariants: neither input is written; an existing output is replaced
 * only with -overwrite and only once the new one is complete; a failure at
 * any phase leaves nothing behind. The summary gives the mean error and
 * the largest angle before and after, so a run says what it changed.
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

tt_status tt__app_optimize(app_run *r)
{
  const tt_app_settings *s = r->s;
  tt_status st = TT_OK;
  tt_output *outp = NULL;
  GDALDatasetH tds = NULL, dst = NULL;
  tt_grid *grid = NULL;
  tt_raster_info *info = NULL;
  tt_tin *tin = NULL;
  OGRSpatialReferenceH srs = NULL;
  char **wopts = NULL;
  double *xyz = NULL;
  size_t ntri = 0, rejected = 0, valid = 0;
  tt_eval_result before;
  memset(&before, 0, sizeof before);

  if (tt__app_same_file(s->input, s->output) ||
      tt__app_same_file(s->tin, s->output))
    return tt__app_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_ARG, s->output,
                        "is an input; refusing to replace it");
  GDALDriverH drv = tt__app_output_driver(r);
  if (!drv)
    return r->res->status;
  const char *drvname = GDALGetDriverShortName(drv);
  r->msg.last[0] = '\0';
  st = tt_output_begin(r->ctx, s->output, drvname, s->overwrite, &outp);
  if (st == TT_ERR_EXISTS) {
    tt__app_fail_exists(r, s->output);
    goto done;
  }
  if (st != TT_OK) {
    tt__app_fail_tt(r, st, s->output);
    goto done;
  }

  /* Read the DEM and the triangles. */
  tt__app_phase_set(&r->prog, 0.0, 0.10);
  OGRLayerH layer = NULL;
  st = tt__app_read_dem_and_tin(r, outp, &grid, &info, &valid, &tds, &layer);
  if (st != TT_OK)
    goto done;
  char lname[256];
  snprintf(lname, sizeof lname, "%s", OGR_L_GetName(layer));
  r->msg.last[0] = '\0';
  st = tt_ogr_read_triangles(r->ctx, layer, info->gt, &xyz, &ntri,
                             &rejected);
  if (st != TT_OK) {
    tt__app_fail_tt(r, st, s->tin);
    goto done;
  }
  if (ntri == 0) {
    st = tt__app_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_DATA, s->tin,
                      "layer '%s' holds no triangles (%zu polygon%s "
                      "rejected)", lname, rejected, rejected == 1 ? "" : "s");
    goto done;
  }
  if (rejected) {
    st = tt__app_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_DATA, s->tin,
                      "layer '%s': %zu polygon%s not triangles (or without "
                      "Z): a TIN to optimise must be triangles only", lname,
                      rejected, rejected == 1 ? " is" : "s are");
    goto done;
  }
  GDALClose(tds);
  tds = NULL;
  /* corners a few 1e-9 pixel off their sample (map coordinates round-off)
   * go back on it, as eval does; the engine refuses any farther off */
  for (size_t i = 0; i < ntri * 9; i++) {
    double rounded = floor(xyz[i] + 0.5);
    if (i % 3 != 2 && fabs(xyz[i] - rounded) <= 1e-6)
      xyz[i] = rounded;
  }
  double t_read = tt__app_now() - r->t0;
  st = tt_eval_triangles(r->ctx, grid, ntri, xyz, &before);
  if (st != TT_OK) {
    tt__app_fail_tt(r, st, s->tin);
    goto done;
  }
  double angle_before = largest_angle(grid, ntri, xyz);

  /* Optimise. */
  tt_optimize_options oo;
  tt_optimize_options_init(&oo);
  oo.criterion = s->criterion;
  oo.optimize = s->optimize;
  oo.max_error = s->max_error;
  oo.anneal = s->anneal;
  double t = tt__app_now();
  st = tt_optimize_run(r->ctx, grid, ntri, xyz, &oo, &tin);
  if (st != TT_OK) {
    tt__app_fail(r, TT_APP_EXIT_FAILURE, st, s->tin, "%s",
                 tt__app_why(r, st, s->tin));
    goto done;
  }
  double t_opt = tt__app_now() - t;
  tt_tin_summary sum;
  tt_tin_get_summary(tin, &sum);
  double angle_after = tin_largest_angle(tin);
  tt_optimize mode =
      s->optimize == TT_OPTIMIZE_AUTO ? TT_OPTIMIZE_LOCAL : s->optimize;

  /* Write. */
  t = tt__app_now();
  tt__app_phase_set(&r->prog, 0.85, 0.99);
  r->msg.last[0] = '\0';
  dst = GDALCreate(drv, tt_output_temp_path(outp), 0, 0, 0, GDT_Unknown,
                   (CSLConstList)s->dsco);
  if (!dst) {
    st = tt__app_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_IO, s->output,
                      "cannot create %s dataset: %s", drvname,
                      r->msg.last[0] ? r->msg.last : "unknown reason");
    goto done;
  }
  if (info->crs_wkt && *info->crs_wkt) {
    srs = OSRNewSpatialReference(info->crs_wkt);
    if (srs)
      OSRSetAxisMappingStrategy(srs, OAMS_TRADITIONAL_GIS_ORDER);
  }
  char created[32];
  tt__app_iso8601_utc(created, sizeof created);
  const tt_error_stats *e = &sum.errors;
  const tt_run_field fields[] = {
      {"input", TT_FIELD_STRING, s->input, 0, 0},
      {"in_tin", TT_FIELD_STRING, s->tin, 0, 0},
      {"band", TT_FIELD_INTEGER, NULL, s->band, 0},
      {"criterion", TT_FIELD_STRING, tt_criterion_name(s->criterion), 0, 0},
      {"optimize", TT_FIELD_STRING, tt_optimize_name(mode), 0, 0},
      {"max_error", TT_FIELD_REAL, NULL, 0, s->max_error},
      {"seed", TT_FIELD_INTEGER, NULL, (int64_t)s->anneal.seed, 0},
      {"vertices", TT_FIELD_INTEGER, NULL, (int64_t)sum.vertices, 0},
      {"triangles", TT_FIELD_INTEGER, NULL, (int64_t)sum.triangles, 0},
      {"in_mean", TT_FIELD_REAL, NULL, 0, before.errors.mean_abs},
      {"in_angle", TT_FIELD_REAL, NULL, 0, angle_before},
      {"ach_max", TT_FIELD_REAL, NULL, 0, e->max_error},
      {"ach_rmse", TT_FIELD_REAL, NULL, 0, e->rmse},
      {"ach_mean", TT_FIELD_REAL, NULL, 0, e->mean_abs},
      {"ach_l2", TT_FIELD_REAL, NULL, 0, e->l2},
      {"ach_angle", TT_FIELD_REAL, NULL, 0, angle_after},
      {"version", TT_FIELD_STRING, tt_version(), 0, 0},
      {"t_read", TT_FIELD_REAL, NULL, 0, t_read},
      {"t_optimize", TT_FIELD_REAL, NULL, 0, t_opt},
      {"created", TT_FIELD_STRING, created, 0, 0},
  };
  char *prefix = CPLStrdup(CPLSPrintf("%s%s", tt_output_layer_prefix(outp),
                                      s->nln));
  wopts = CSLSetNameValue(wopts, "NLN_PREFIX", prefix);
  CPLFree(prefix);
  for (size_t i = 0; s->lco[i]; i++)
    wopts = CSLAddNameValue(wopts, "LCO", s->lco[i]);
  st = tt_ogr_write_tin(r->ctx, dst, tin, srs, fields,
                        sizeof fields / sizeof fields[0], wopts,
                        tt__app_phase_fn, &r->prog);
  if (st != TT_OK) {
    tt__app_fail_tt(r, st, s->output);
    goto done;
  }
  unsigned failures = r->msg.failures;
  GDALClose(dst);
  dst = NULL;
  if (r->msg.failures != failures) {
    st = tt__app_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_IO, s->output,
                      "error while closing: %s", r->msg.last);
    goto done;
  }
  st = tt_output_commit(r->ctx, outp);
  if (st == TT_ERR_EXISTS) {
    tt__app_fail_exists(r, s->output);
    goto done;
  }
  if (st != TT_OK) {
    tt__app_fail_tt(r, st, s->output);
    goto done;
  }
  double t_write = tt__app_now() - t;

  const char *unit = tt__app_unit_or(info, "z units");
  if (s->json) {
    app_json j;
    tt__json_begin(&j, r->out);
    tt__json_str(&j, "dem", s->input);
    tt__json_str(&j, "in_tin", s->tin);
    tt__json_str(&j, "layer", lname);
    tt__json_str(&j, "output", s->output);
    tt__json_str(&j, "criterion", tt_criterion_name(s->criterion));
    tt__json_str(&j, "optimize", tt_optimize_name(mode));
    tt__json_size(&j, "vertices", sum.vertices);
    tt__json_size(&j, "triangles", sum.triangles);
    tt__json_open(&j, "before");
    tt__json_num(&j, "mean_abs_error", before.errors.mean_abs);
    tt__json_num(&j, "max_error", before.errors.max_error);
    tt__json_num(&j, "rmse", before.errors.rmse);
    tt__json_num(&j, "largest_angle_deg", angle_before);
    tt__json_close(&j);
    tt__json_open(&j, "after");
    tt__json_num(&j, "mean_abs_error", e->mean_abs);
    tt__json_num(&j, "max_error", e->max_error);
    tt__json_num(&j, "rmse", e->rmse);
    tt__json_num(&j, "largest_angle_deg", angle_after);
    tt__json_close(&j);
    tt__json_str(&j, "z_unit", tt__app_nonempty_or_null(info->z_unit));
    tt__json_open(&j, "seconds");
    tt__json_num(&j, "read", t_read);
    tt__json_num(&j, "optimize", t_opt);
    tt__json_num(&j, "write", t_write);
    tt__json_num(&j, "total", tt__app_now() - r->t0);
    tt__json_close(&j);
    tt__json_close(&j);
  } else if (!s->quiet) {
    FILE *o = r->out;
    fprintf(o, "%s: %zu vertices, %zu triangles of %s layer %s, %s by %s "
               "in %.3f s\n", s->output, sum.vertices, sum.triangles, s->tin,
            lname, tt_criterion_name(s->criterion), tt_optimize_name(mode),
            t_opt);
    fprintf(o, "mean abs error %.9g -> %.9g %s, max error %.9g -> %.9g, "
               "largest angle %.6g -> %.6g degrees\n",
            before.errors.mean_abs, e->mean_abs, unit, before.errors.max_error,
            e->max_error, angle_before, angle_after);
  }
  fflush(r->out);

done:
  if (dst)
    GDALClose(dst);
  if (tds)
    GDALClose(tds);
  tt_output_destroy(outp);
  if (srs)
    OSRDestroySpatialReference(srs);
  CSLDestroy(wopts);
  free(xyz);
  tt_tin_destroy(tin);
  tt_grid_destroy(grid);
  tt_raster_info_destroy(info);
  return st;
}
