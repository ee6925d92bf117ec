/*
 * eval.c -- `terratin eval DEM TIN`: read any layer of triangles (the
 * triangles layer of a terratin output, or any POLYGON Z layer), measure it
 * against the DEM's valid samples (tt_eval_triangles), print the errors, and
 * exit with code 3 when -max_error is exceeded. With -error_raster, also
 * write TIN - DEM on the DEM's grid (core/raster_output.c's writer), refused before
 * anything is read when it exists without -overwrite.
 */
#include "app.h"

#include <cpl_conv.h>
#include <cpl_string.h>
#include <cpl_vsi.h>
#include <ogr_api.h>
#include <ogr_srs_api.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

tt_status tt__app_eval(app_run *r)
{
  const tt_app_settings *s = r->s;
  tt_status st = TT_OK;
  GDALDatasetH src = NULL, tds = NULL;
  GDALRasterBandH band = NULL;
  tt_grid *grid = NULL;
  tt_raster_info *info = NULL;
  double *xyz = NULL, *err = NULL;
  size_t ntri = 0, rejected = 0, valid = 0;
  tt_eval_result ev;
  tt_output *outp = NULL;
  GDALDriverH rdrv = NULL;
  memset(&ev, 0, sizeof ev);

  /* -error_raster: refused when it exists, before anything is read */
  if (s->error_raster) {
    if (tt__app_same_file(s->input, s->error_raster) ||
        tt__app_same_file(s->tin, s->error_raster))
      return tt__app_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_ARG,
                          s->error_raster,
                          "is an input; refusing to replace it");
    if (!(rdrv = tt__app_raster_driver(r, NULL, NULL)))
      return r->res->status;
    st = tt_output_begin(r->ctx, s->error_raster, "GTiff", s->overwrite,
                         &outp);
    if (st == TT_ERR_EXISTS)
      return tt__app_fail_exists(r, s->error_raster);
    if (st != TT_OK)
      return tt__app_fail_tt(r, st, s->error_raster);
  }

  src = tt__app_open_raster(r, s->input, s->band, &band);
  if (!src) {
    st = r->res->status;
    goto done;
  }
  if (outp &&
      (st = tt_output_protect_dataset(r->ctx, outp, src, s->input)) !=
          TT_OK) {
    tt__app_fail_tt(r, st, s->error_raster);
    goto done;
  }
  /* No bar for eval, but the reading still polls for an interruption. */
  tt__app_phase_set(&r->prog, 0.0, 0.3);
  st = tt__app_read_dem(r, band, s->input, tt__app_phase_fn, &r->prog, &grid,
                        &info, &valid);
  if (st != TT_OK)
    goto done;
  GDALClose(src);
  src = NULL;
  double t_read = tt__app_now() - r->t0;
  if (!tt__app_continue(r, 0.3)) {
    st = tt__app_fail_tt(r, TT_ERR_INTERRUPTED, s->tin);
    goto done;
  }

  tds = tt__app_open_vector(r, s->tin);
  if (!tds) {
    st = r->res->status;
    goto done;
  }
  if (outp &&
      (st = tt_output_protect_dataset(r->ctx, outp, tds, s->tin)) != TT_OK) {
    tt__app_fail_tt(r, st, s->error_raster);
    goto done;
  }
  OGRLayerH layer = tt__app_tin_layer(r, tds);
  if (!layer) {
    st = r->res->status;
    goto done;
  }
  const char *lname = OGR_L_GetName(layer);

  /* Triangles in another CRS would be measured in the wrong place. */
  int other_crs = tt__app_layer_in_other_crs(layer, info);

  r->msg.last[0] = '\0';
  st = tt_ogr_read_triangles(r->ctx, layer, info->gt, &xyz, &ntri,
                             &rejected);
  if (st != TT_OK) {
    tt__app_fail_tt(r, st, s->tin);
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
    st = tt__app_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_DATA, s->tin,
                  "layer '%s' holds no triangles (%zu polygon%s rejected)",
                  lname, rejected, rejected == 1 ? "" : "s");
    goto done;
  }
  const size_t ncells = info->width * info->height;
  if (outp && !(err = malloc(ncells * sizeof *err))) {
    st = tt__app_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_NOMEM, s->error_raster,
                      "out of memory for %zu x %zu errors", info->width,
                      info->height);
    goto done;
  }
  double t = tt__app_now();
  st = tt_eval_triangles_raster(r->ctx, grid, ntri, xyz, &ev, err);
  if (st != TT_OK) {
    tt__app_fail_tt(r, st, s->tin);
    goto done;
  }
  double t_eval = tt__app_now() - t;
  if (ev.errors.covered == 0) {
    st = tt__app_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_DATA, s->tin,
                  "no valid sample of %s lies in a triangle of layer '%s' "
                  "(%s)", s->input, lname,
                  other_crs ? "the layer is in another CRS"
                            : "another extent?");
    goto done;
  }
  if (other_crs)
    tt__app_warn(&r->msg,
                 "%s: layer '%s' is not in the CRS of %s; the error is "
                 "measured as if it were",
                 s->tin, lname, s->input);
  if (ev.uncovered)
    tt__app_warn(&r->msg,
                 "%s: %zu of %zu valid samples lie in no triangle; their "
                 "error is not measured",
                 s->tin, ev.uncovered, ev.errors.samples);

  /* TIN - DEM: NaN outside the TIN and at the DEM's nodata. */
  double t_raster = 0.0;
  if (outp) {
    t = tt__app_now();
    const float *zf = tt_grid_heights_const(grid);
    const double *zd = tt_grid_heights_f64_const(grid);
    for (size_t i = 0; i < ncells; i++)
      err[i] -= zd ? zd[i] : (double)zf[i];
    tt__app_phase_set(&r->prog, 0.5, 1.0);
    st = tt__app_write_raster(r, outp, rdrv, grid, info, err);
    if (st != TT_OK)
      goto done;
    t_raster = tt__app_now() - t;
  }

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
  const char *unit = tt__app_unit_or(info, "z units");

  if (s->json) {
    app_json j;
    tt__json_begin(&j, r->out);
    tt__json_str(&j, "dem", s->input);
    tt__json_size(&j, "band", (size_t)s->band);
    tt__json_str(&j, "tin", s->tin);
    tt__json_str(&j, "layer", lname);
    tt__json_size(&j, "cells", info->width * info->height);
    tt__json_size(&j, "valid_samples", e->samples);
    tt__json_size(&j, "covered", e->covered);
    tt__json_size(&j, "uncovered", ev.uncovered);
    tt__json_size(&j, "overlapped", ev.overlapped);
    tt__json_size(&j, "triangles", ev.triangles);
    tt__json_size(&j, "rejected", rejected);
    tt__json_size(&j, "degenerate", ev.degenerate);
    tt__json_num(&j, "max_error", e->max_error);
    if (e->max_col >= 0) {
      tt__json_open(&j, "max_error_at");
      tt__json_i64(&j, "col", e->max_col);
      tt__json_i64(&j, "row", e->max_row);
      tt__json_num(&j, "x", mx);
      tt__json_num(&j, "y", my);
      tt__json_close(&j);
    } else {
      tt__json_null(&j, "max_error_at");
    }
    tt__json_num(&j, "rmse", e->rmse);
    tt__json_num(&j, "mean_abs_error", e->mean_abs);
    tt__json_num(&j, "total_abs_error", e->total_abs);
    tt__json_num(&j, "l2", e->l2);
    tt__json_str(&j, "z_unit", tt__app_nonempty_or_null(info->z_unit));
    tt__json_str(&j, "crs", tt__app_nonempty_or_null(info->crs_name));
    tt__json_str(&j, "error_raster", s->error_raster);
    if (checked) {
      tt__json_num(&j, "threshold", s->max_error);
      tt__json_bool(&j, "pass", pass);
    } else {
      tt__json_null(&j, "threshold");
      tt__json_null(&j, "pass");
    }
    tt__json_open(&j, "seconds");
    tt__json_num(&j, "read", t_read);
    tt__json_num(&j, "eval", t_eval);
    if (outp)
      tt__json_num(&j, "error_raster", t_raster);
    tt__json_num(&j, "total", tt__app_now() - r->t0);
    tt__json_close(&j);
    tt__json_close(&j);
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
    if (outp)
      fprintf(o, "error raster:    %s (TIN - DEM, %s)\n", s->error_raster,
              tt_grid_precision(grid) == TT_PRECISION_FLOAT64 ? "Float64"
                                                              : "Float32");
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
    tt__app_result_set(r->res, TT_APP_EXIT_THRESHOLD, TT_OK,
               "%s: max error %s %s exceeds -max_error %s", s->tin, a, unit,
               b);
  }

done:
  tt_output_destroy(outp);
  free(err);
  if (tds)
    GDALClose(tds);
  if (src)
    GDALClose(src);
  free(xyz);
  tt_grid_destroy(grid);
  tt_raster_info_destroy(info);
  return st;
}
