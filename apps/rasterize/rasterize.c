/*
 * rasterize.c -- apps/rasterize/: the rasterize command, a folder over the core
 * (apps/core/). `terratin rasterize DEM TIN OUTPUT` (the DEM first, as for
 * eval and optimize; the old order TIN DEM OUTPUT is recognised by opening
 * the words, and taken with a note): a layer of triangles (read
 * as eval reads it) drawn on the DEM's grid, each sample centre in a triangle
 * given the triangle's linear interpolation of its corners' heights, NaN (the
 * band's nodata) outside the TIN, written by the raster writer it shares with
 * `eval -error_raster` (core/raster_output.c).
 *
 * The heights come from tt_eval_triangles_raster, the same pass eval
 * measures with, so a sample's value is the height of the triangle its
 * error is measured against, and the summary's errors are eval's.
 * Invariants: neither input is written; OUTPUT is refused when it exists
 * unless -overwrite, before anything is read; it is written under a
 * temporary name and renamed when complete, so a failure or an interrupt
 * leaves nothing behind.
 *
 * Workload: the DEM's heights, 8 bytes a sample for the TIN's, one pass
 * over the covered samples, one write.
 */
#include "app.h"

#include <cpl_conv.h>
#include <cpl_string.h>
#include <ogr_api.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

/* Whether GDAL opens path as a dataset of that kind (GDAL_OF_RASTER or
 * GDAL_OF_VECTOR), quietly. */
static int opens_as(app_run *r, const char *path, unsigned kind)
{
  tt__app_quiet_push(&r->msg);
  GDALDatasetH ds =
      GDALOpenEx(path, kind | GDAL_OF_READONLY, NULL, NULL, NULL);
  CPLPopErrorHandler();
  if (ds)
    GDALClose(ds);
  return ds != NULL;
}

/* The old order, TIN DEM OUTPUT, is still taken: when the first word is
 * no raster but a vector dataset and the second a raster, the two are
 * swapped (in *swapped, which r->s then points to) with a one-line note
 * on stderr. Returns the run's settings (r->s). */
static const tt_app_settings *take_old_order(app_run *r,
                                             tt_app_settings *swapped)
{
  const tt_app_settings *s = r->s;
  if (opens_as(r, s->input, GDAL_OF_RASTER) ||
      !opens_as(r, s->input, GDAL_OF_VECTOR) ||
      !opens_as(r, s->tin, GDAL_OF_RASTER))
    return r->s;
  *swapped = *s;
  swapped->input = s->tin;
  swapped->tin = s->input;
  r->s = swapped;
  tt_app_term_progress_break(r->msg.bar);
  fprintf(r->err, "terratin: rasterize: note: TIN DEM OUTPUT is the old "
          "order of the arguments, taken as DEM TIN OUTPUT; write "
          "'terratin rasterize %s %s %s'\n", tt__app_shown(r, s->tin),
          tt__app_shown(r, s->input), tt__app_shown(r, s->output));
  fflush(r->err);
  return r->s;
}

tt_status tt__app_rasterize(app_run *r)
{
  tt_app_settings swapped;
  const tt_app_settings *s = take_old_order(r, &swapped);
  tt_status st = TT_OK;
  tt_output *outp = NULL;
  GDALDatasetH tds = NULL;
  tt_grid *grid = NULL;
  tt_raster_info *info = NULL;
  double *xyz = NULL, *z = NULL;
  size_t ntri = 0, rejected = 0, valid = 0;
  tt_eval_result ev;
  memset(&ev, 0, sizeof ev);

  if (tt__app_same_file(s->input, s->output) ||
      tt__app_same_file(s->tin, s->output))
    return tt__app_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_ARG, s->output,
                        "is an input; refusing to replace it");
  GDALDriverH drv = tt__app_raster_driver(r, s->format, s->output);
  if (!drv)
    return r->res->status;
  r->msg.last[0] = '\0';
  st = tt_output_begin(r->ctx, s->output, GDALGetDriverShortName(drv),
                       s->overwrite, &outp);
  if (st == TT_ERR_EXISTS) {
    tt__app_fail_exists(r, s->output);
    goto done;
  }
  if (st != TT_OK) {
    tt__app_fail_tt(r, st, s->output);
    goto done;
  }

  tt__app_phase_set(&r->prog, 0.0, 0.4);
  OGRLayerH layer = NULL;
  st = tt__app_read_dem_and_tin(r, outp, &grid, &info, &valid, &tds, &layer);
  if (st != TT_OK)
    goto done;
  char lname[256];
  snprintf(lname, sizeof lname, "%s", OGR_L_GetName(layer));
  if (tt__app_layer_in_other_crs(layer, info))
    tt__app_warn(&r->msg, "%s: layer '%s' is not in the CRS of %s; it is "
                 "drawn as if it were", s->tin, lname, s->input);
  r->msg.last[0] = '\0';
  st = tt_ogr_read_triangles(r->ctx, layer, info->gt, &xyz, &ntri,
                             &rejected);
  if (st != TT_OK) {
    tt__app_fail_tt(r, st, s->tin);
    goto done;
  }
  GDALClose(tds);
  tds = NULL;
  if (ntri == 0) {
    st = tt__app_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_DATA, s->tin,
                      "layer '%s' holds no triangles (%zu feature%s "
                      "rejected)", lname, rejected, rejected == 1 ? "" : "s");
    goto done;
  }
  /* corners a few 1e-9 pixel off their sample go back on it, as in eval */
  for (size_t i = 0; i < ntri * 9; i++) {
    double rounded = floor(xyz[i] + 0.5);
    if (i % 3 != 2 && fabs(xyz[i] - rounded) <= 1e-6)
      xyz[i] = rounded;
  }
  const size_t nx = tt_grid_width(grid), ny = tt_grid_height(grid);
  double t_read = tt__app_now() - r->t0;
  if (!tt__app_continue(r, 0.4)) {
    st = tt__app_fail_tt(r, TT_ERR_INTERRUPTED, s->output);
    goto done;
  }
  z = malloc(nx * ny * sizeof *z);
  if (!z) {
    st = tt__app_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_NOMEM, s->output,
                      "out of memory for %zu x %zu heights", nx, ny);
    goto done;
  }
  double t = tt__app_now();
  st = tt_eval_triangles_raster(r->ctx, grid, ntri, xyz, &ev, z);
  if (st != TT_OK) {
    tt__app_fail_tt(r, st, s->tin);
    goto done;
  }
  size_t in_tin = 0;
  for (size_t i = 0; i < nx * ny; i++)
    in_tin += !isnan(z[i]);
  double t_raster = tt__app_now() - t;
  if (in_tin == 0) {
    st = tt__app_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_DATA, s->tin,
                      "no sample of %s lies in a triangle of layer '%s' "
                      "(another extent, or another CRS?)", s->input, lname);
    goto done;
  }

  t = tt__app_now();
  tt__app_phase_set(&r->prog, 0.5, 1.0);
  st = tt__app_write_raster(r, outp, drv, grid, info, z);
  if (st != TT_OK)
    goto done;
  double t_write = tt__app_now() - t;

  const char *unit = tt__app_unit_or(info, "z units");
  const tt_error_stats *e = &ev.errors;
  if (s->json) {
    app_json j;
    tt__json_begin(&j, r->out);
    tt__json_str(&j, "tin", tt__app_shown(r, s->tin));
    tt__json_str(&j, "layer", lname);
    tt__json_str(&j, "dem", tt__app_shown(r, s->input));
    tt__json_str(&j, "output", tt__app_shown(r, s->output));
    tt__json_str(&j, "driver", GDALGetDriverShortName(drv));
    tt__json_size(&j, "width", nx);
    tt__json_size(&j, "height", ny);
    tt__json_size(&j, "triangles", ev.triangles);
    tt__json_size(&j, "rejected", rejected);
    tt__json_size(&j, "cells_in_tin", in_tin);
    tt__json_size(&j, "nodata_cells", nx * ny - in_tin);
    tt__json_size(&j, "valid_samples", e->samples);
    tt__json_size(&j, "covered", e->covered);
    tt__json_num(&j, "max_error", e->max_error);
    tt__json_num(&j, "rmse", e->rmse);
    tt__json_str(&j, "z_unit", tt__app_nonempty_or_null(info->z_unit));
    tt__json_open(&j, "seconds");
    tt__json_num(&j, "read", t_read);
    tt__json_num(&j, "rasterize", t_raster);
    tt__json_num(&j, "write", t_write);
    tt__json_num(&j, "total", tt__app_now() - r->t0);
    tt__json_close(&j);
    tt__json_close(&j);
  } else if (!s->quiet) {
    fprintf(r->out, "%s: %zux%zu, %zu samples in %zu triangles of %s "
                    "layer %s, %zu nodata, in %.3f s\n",
            tt__app_shown(r, s->output), nx, ny, in_tin, ev.triangles,
            tt__app_shown(r, s->tin), lname, nx * ny - in_tin,
            t_raster + t_write);
    fprintf(r->out, "against %s: max error %.9g %s, RMS error %.9g %s over "
                    "%zu of %zu valid samples\n", tt__app_shown(r, s->input),
            e->max_error, unit, e->rmse, unit, e->covered, e->samples);
  }
  fflush(r->out);

done:
  if (tds)
    GDALClose(tds);
  tt_output_destroy(outp);
  free(z);
  free(xyz);
  tt_grid_destroy(grid);
  tt_raster_info_destroy(info);
  return st;
}
