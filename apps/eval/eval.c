/*
 * eval.c -- apps/eval/: the eval command, a folder over the core
 * (apps/core/). `terratin eval DEM TIN`: read a TIN from any file that
 * holds one (a mesh file: STL, PLY, OBJ, 2DM, LandXML, UGRID; or an OGR
 * layer of triangles: terratin's, any POLYGON Z, TIN or PolyhedralSurface
 * layer, CSV WKT, DXF 3DFACE; core/tin_read.c), put it on the DEM (its
 * frame, -tin_transform, reprojected from its CRS), measure it against
 * the DEM's valid samples (tt_eval_triangles), print the errors, and
 * exit with code 3 when -max_error is exceeded. With -error_raster, also
 * write TIN - DEM on the DEM's grid (core/raster_output.c's writer), refused
 * before anything is read when it exists without -overwrite.
 *
 * A run is a pipeline over one eval_run: begin the error raster, read the
 * DEM, read the triangles, measure, write the error raster, report; each
 * step records its failure, and tt__app_eval frees what they made.
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

/* One eval run: its inputs as read, what was measured, the times. */
typedef struct eval_run {
  app_run *r;
  const tt_app_settings *s;
  tt_output *outp;         /* -error_raster's output, or NULL */
  GDALDriverH rdrv;        /* and its driver */
  GDALDatasetH src;        /* the DEM, while read */
  tt_grid *grid;
  tt_raster_info *info;
  size_t valid;            /* the DEM's valid samples */
  app_tin tin;             /* the triangles, in pixel space */
  double *err;             /* -error_raster: TIN - DEM per cell */
  tt_eval_result ev;
  double t_read, t_eval, t_raster;
} eval_run;

/* -error_raster: refused when it exists, before anything is read. */
static tt_status begin_error_raster(eval_run *e)
{
  app_run *r = e->r;
  const tt_app_settings *s = e->s;
  if (tt__app_same_file(s->input, s->error_raster) ||
      tt__app_same_file(s->tin, s->error_raster))
    return tt__app_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_ARG, s->error_raster,
                        "is an input; refusing to replace it");
  if (!(e->rdrv = tt__app_raster_driver(r, NULL, NULL)))
    return r->res->status;
  tt_status st = tt_output_begin(r->ctx, s->error_raster, "GTiff",
                                 s->overwrite, &e->outp);
  if (st == TT_ERR_EXISTS)
    return tt__app_fail_exists(r, s->error_raster);
  if (st != TT_OK)
    return tt__app_fail_tt(r, st, s->error_raster);
  return TT_OK;
}

/* The DEM into a grid, the dataset closed again. */
static tt_status read_dem(eval_run *e)
{
  app_run *r = e->r;
  const tt_app_settings *s = e->s;
  GDALRasterBandH band = NULL;
  tt_status st;
  if (!(e->src = tt__app_open_raster(r, s->input, s->band, &band)))
    return r->res->status;
  if (e->outp &&
      (st = tt_output_protect_dataset(r->ctx, e->outp,
                                      tt__app_raster_file(r, e->src),
                                      s->input)) !=
          TT_OK)
    return tt__app_fail_tt(r, st, s->error_raster);
  /* No bar for eval, but the reading still polls for an interruption. */
  tt__app_phase_set(&r->prog, 0.0, 0.3);
  st = tt__app_read_dem(r, band, s->input, tt__app_phase_fn, &r->prog,
                        &e->grid, &e->info, &e->valid);
  if (st != TT_OK)
    return st;
  tt__app_close_raster(r, e->src);
  e->src = NULL;
  e->t_read = tt__app_now() - r->t0;
  if (!tt__app_continue(r, 0.3))
    return tt__app_fail_tt(r, TT_ERR_INTERRUPTED, s->tin);
  return TT_OK;
}

/* The triangles of the TIN, in the DEM's pixel space. */
static tt_status read_triangles(eval_run *e)
{
  app_run *r = e->r;
  const tt_app_settings *s = e->s;
  app_tin *t = &e->tin;
  tt_status st = tt__app_read_tin(r, e->info, e->grid, e->outp, t);
  if (st != TT_OK)
    return st;
  /* Map coordinates stored in a file carry round-off: a TIN vertex on a
   * grid sample comes back a few 1e-9 pixel away when pixels are tiny
   * next to the coordinates (lidar in degrees), and the boundary samples
   * would then fall outside every triangle. Put corners within 1e-6 pixel
   * of a sample centre back on it; no other corner moves. */
  for (size_t i = 0; i < t->ntri * 9; i++) {
    if (i % 3 == 2)
      continue; /* z */
    double rounded = floor(t->xyz[i] + 0.5);
    if (fabs(t->xyz[i] - rounded) <= 1e-6)
      t->xyz[i] = rounded;
  }
  if (t->ntri == 0)
    return tt__app_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_DATA, s->tin,
                        "%s%s%s holds no triangles (%zu %s%s rejected)",
                        t->layer ? "layer '" : "the ",
                        t->layer ? t->layer : t->format,
                        t->layer ? "'" : " file", t->rejected,
                        t->layer ? "polygon" : "face",
                        t->rejected == 1 ? "" : "s");
  return TT_OK;
}

/* "layer 'NAME'" or "the STL file", for messages. */
static const char *shown_layer(const eval_run *e, char *buf, size_t size)
{
  const app_tin *t = &e->tin;
  if (t->layer)
    snprintf(buf, size, "layer %s", t->layer);
  else
    snprintf(buf, size, "the %s file", t->format);
  return buf;
}

/* The errors of the triangles at the DEM's valid samples (and, for
 * -error_raster, the TIN's height at every cell). */
static tt_status measure(eval_run *e)
{
  app_run *r = e->r;
  const tt_app_settings *s = e->s;
  const tt_raster_info *info = e->info;
  if (e->outp &&
      !(e->err = malloc(info->width * info->height * sizeof *e->err)))
    return tt__app_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_NOMEM,
                        s->error_raster, "out of memory for %zu x %zu errors",
                        info->width, info->height);
  double t0 = tt__app_now();
  const app_tin *t = &e->tin;
  char shown[320];
  tt_status st = tt_eval_triangles_raster(r->ctx, e->grid, t->ntri, t->xyz,
                                          &e->ev, e->err);
  if (st != TT_OK)
    return tt__app_fail_tt(r, st, s->tin);
  e->t_eval = tt__app_now() - t0;
  if (e->ev.errors.covered == 0)
    return tt__app_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_DATA, s->tin,
                        "no valid sample of %s lies in a triangle of %s "
                        "(%s)", s->input, shown_layer(e, shown, sizeof shown),
                        t->other_crs ? "the TIN has a CRS, the DEM none"
                        : t->pixel   ? "another grid? -tin_frame pixel "
                                       "takes x as the column, y as the "
                                       "row counted up"
                                     : "another extent? -tin_frame, "
                                       "-tin_transform");
  if (e->ev.uncovered)
    tt__app_warn(&r->msg,
                 "%s: %zu of %zu valid samples lie in no triangle; their "
                 "error is not measured",
                 s->tin, e->ev.uncovered, e->ev.errors.samples);
  return TT_OK;
}

/* TIN - DEM: NaN outside the TIN and at the DEM's nodata. */
static tt_status write_error_raster(eval_run *e)
{
  app_run *r = e->r;
  const size_t ncells = e->info->width * e->info->height;
  double t = tt__app_now();
  const float *zf = tt_grid_heights_const(e->grid);
  const double *zd = tt_grid_heights_f64_const(e->grid);
  for (size_t i = 0; i < ncells; i++)
    e->err[i] -= zd ? zd[i] : (double)zf[i];
  tt__app_phase_set(&r->prog, 0.5, 1.0);
  tt_status st = tt__app_write_raster(r, e->outp, e->rdrv, e->grid, e->info,
                                      e->err);
  if (st != TT_OK)
    return st;
  e->t_raster = tt__app_now() - t;
  return TT_OK;
}

/* Whether the -max_error check passes (or there is none). The same
 * round-off as read_triangles' moves the interpolated heights by ~1e-10
 * relative: a bound met by construction must not fail the check because
 * of it. */
static int passes(const eval_run *e)
{
  double bound = e->s->max_error;
  return bound < 0 ||
         e->ev.errors.max_error <= bound + 1e-6 * fmax(bound, 1.0);
}

/* The map coordinates of the sample with the largest error. */
static void max_error_at(const eval_run *e, double *out_x, double *out_y)
{
  const tt_error_stats *er = &e->ev.errors;
  const double *gt = e->info->gt;
  double mc = (double)er->max_col + 0.5, mr = (double)er->max_row + 0.5;
  *out_x = gt[0] + mc * gt[1] + mr * gt[2];
  *out_y = gt[3] + mc * gt[4] + mr * gt[5];
}

static void report_json(const eval_run *e)
{
  const app_run *r = e->r;
  const tt_app_settings *s = e->s;
  const tt_raster_info *info = e->info;
  const tt_error_stats *er = &e->ev.errors;
  double mx, my;
  app_json j;
  max_error_at(e, &mx, &my);
  tt__json_begin(&j, r->out);
  tt__json_str(&j, "dem", tt__app_shown(r, s->input));
  tt__json_size(&j, "band", (size_t)s->band);
  tt__json_str(&j, "tin", tt__app_shown(r, s->tin));
  tt__json_str(&j, "layer", e->tin.layer);
  tt__json_str(&j, "format", e->tin.format);
  tt__json_str(&j, "frame", e->tin.pixel ? "pixel" : "map");
  tt__json_bool(&j, "reprojected", e->tin.reprojected);
  tt__json_str(&j, "tin_crs", e->tin.reprojected ? e->tin.crs_name : NULL);
  tt__json_size(&j, "cells", info->width * info->height);
  tt__json_size(&j, "valid_samples", er->samples);
  tt__json_size(&j, "covered", er->covered);
  tt__json_size(&j, "uncovered", e->ev.uncovered);
  tt__json_size(&j, "overlapped", e->ev.overlapped);
  tt__json_size(&j, "triangles", e->ev.triangles);
  tt__json_size(&j, "rejected", e->tin.rejected);
  tt__json_size(&j, "degenerate", e->ev.degenerate);
  tt__json_num(&j, "max_error", er->max_error);
  if (er->max_col >= 0) {
    tt__json_open(&j, "max_error_at");
    tt__json_i64(&j, "col", er->max_col);
    tt__json_i64(&j, "row", er->max_row);
    tt__json_num(&j, "x", mx);
    tt__json_num(&j, "y", my);
    tt__json_close(&j);
  } else {
    tt__json_null(&j, "max_error_at");
  }
  tt__json_num(&j, "rmse", er->rmse);
  tt__json_num(&j, "mean_abs_error", er->mean_abs);
  tt__json_num(&j, "total_abs_error", er->total_abs);
  tt__json_num(&j, "l2", er->l2);
  tt__json_str(&j, "z_unit", tt__app_nonempty_or_null(info->z_unit));
  tt__json_str(&j, "crs", tt__app_nonempty_or_null(info->crs_name));
  tt__json_str(&j, "error_raster", tt__app_shown(r, s->error_raster));
  if (s->max_error >= 0) {
    tt__json_num(&j, "threshold", s->max_error);
    tt__json_bool(&j, "pass", passes(e));
  } else {
    tt__json_null(&j, "threshold");
    tt__json_null(&j, "pass");
  }
  tt__json_open(&j, "seconds");
  tt__json_num(&j, "read", e->t_read);
  tt__json_num(&j, "eval", e->t_eval);
  if (e->outp)
    tt__json_num(&j, "error_raster", e->t_raster);
  tt__json_num(&j, "total", tt__app_now() - r->t0);
  tt__json_close(&j);
  tt__json_close(&j);
}

static void report_text(const eval_run *e)
{
  const tt_app_settings *s = e->s;
  const tt_raster_info *info = e->info;
  const tt_error_stats *er = &e->ev.errors;
  const char *unit = tt__app_unit_or(info, "z units");
  FILE *o = e->r->out;
  char shown[320];
  double mx, my;
  int pass = passes(e);
  max_error_at(e, &mx, &my);
  fprintf(o, "DEM: %s, band %d: %zux%zu = %zu cells, %zu valid samples\n",
          tt__app_shown(e->r, s->input), s->band, info->width, info->height,
          info->width * info->height, er->samples);
  fprintf(o, "TIN: %s, %s: %zu triangles, %zu %s rejected "
             "(not triangles), %zu degenerate\n",
          tt__app_shown(e->r, s->tin), shown_layer(e, shown, sizeof shown),
          e->ev.triangles,
          e->tin.rejected, e->tin.layer ? "polygons" : "faces",
          e->ev.degenerate);
  if (e->tin.pixel || e->tin.reprojected || s->tin_transform_set)
    fprintf(o, "TIN frame:       %s%s%s%s\n",
            e->tin.pixel ? "the DEM's pixels (x column, y row up)"
                         : "map coordinates",
            s->tin_transform_set ? ", after -tin_transform" : "",
            e->tin.reprojected ? ", reprojected from " : "",
            e->tin.reprojected ? e->tin.crs_name : "");
  if (er->max_col >= 0)
    fprintf(o, "max error:       %.9g %s at column %lld, row %lld "
               "(x %.10g, y %.10g)\n",
            er->max_error, unit, (long long)er->max_col,
            (long long)er->max_row, mx, my);
  else
    fprintf(o, "max error:       %.9g %s\n", er->max_error, unit);
  fprintf(o, "RMS error:       %.9g %s\n", er->rmse, unit);
  fprintf(o, "mean abs error:  %.9g %s\n", er->mean_abs, unit);
  fprintf(o, "total abs error: %.9g %s\n", er->total_abs, unit);
  fprintf(o, "L2 error:        %.9g %s\n", er->l2, unit);
  fprintf(o, "coverage:        %zu of %zu valid samples covered, %zu "
             "uncovered, %zu overlapped\n",
          er->covered, er->samples, e->ev.uncovered, e->ev.overlapped);
  if (e->outp)
    fprintf(o, "error raster:    %s (TIN - DEM, %s)\n",
            tt__app_shown(e->r, s->error_raster),
            tt_grid_precision(e->grid) == TT_PRECISION_FLOAT64 ? "Float64"
                                                               : "Float32");
  if (s->max_error >= 0)
    fprintf(o, "check:           max error %.9g %s -max_error %.9g: %s\n",
            er->max_error, pass ? "<=" : ">", s->max_error,
            pass ? "pass" : "FAIL");
}

/* The report, then exit code 3 when -max_error is exceeded. */
static void report(const eval_run *e)
{
  const tt_app_settings *s = e->s;
  if (s->json)
    report_json(e);
  else if (!s->quiet)
    report_text(e);
  fflush(e->r->out);
  if (!passes(e)) {
    char a[40], b[40];
    snprintf(a, sizeof a, "%.9g", e->ev.errors.max_error);
    snprintf(b, sizeof b, "%.9g", s->max_error);
    tt__app_result_set(e->r->res, TT_APP_EXIT_THRESHOLD, TT_OK,
                       "%s: max error %s %s exceeds -max_error %s",
                       tt__app_shown(e->r, s->tin),
                       a, tt__app_unit_or(e->info, "z units"), b);
  }
}

tt_status tt__app_eval(app_run *r)
{
  eval_run e;
  memset(&e, 0, sizeof e);
  e.r = r;
  e.s = r->s;
  tt_status st = e.s->error_raster ? begin_error_raster(&e) : TT_OK;
  if (st == TT_OK)
    st = read_dem(&e);
  if (st == TT_OK)
    st = read_triangles(&e);
  if (st == TT_OK)
    st = measure(&e);
  if (st == TT_OK && e.outp)
    st = write_error_raster(&e);
  if (st == TT_OK)
    report(&e);

  tt_output_destroy(e.outp);
  free(e.err);
  tt__app_tin_free(&e.tin);
  if (e.src)
    tt__app_close_raster(r, e.src);
  tt_grid_destroy(e.grid);
  tt_raster_info_destroy(e.info);
  return st;
}
