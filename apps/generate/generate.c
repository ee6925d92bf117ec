/*
 * generate.c -- apps/generate/: the generate command, a folder over the core
 * (apps/core/). `terratin generate KIND OUTPUT`: one of the synthetic test
 * terrains of the engine (tt_synth_generate) written as a GeoTIFF, with an
 * optional CRS.
 */
#include "app.h"

#include <cpl_conv.h>
#include <cpl_vsi.h>
#include <ogr_srs_api.h>

tt_status tt__app_generate(app_run *r)
{
  const tt_app_settings *s = r->s;
  tt_status st = TT_OK;
  tt_grid *grid = NULL;
  char *wkt = NULL;
  OGRSpatialReferenceH srs = NULL;
  VSIStatBufL sb;

  if (s->srs) {
    srs = OSRNewSpatialReference(NULL);
    r->msg.last[0] = '\0';
    if (!srs || OSRSetFromUserInput(srs, s->srs) != OGRERR_NONE ||
        OSRExportToWkt(srs, &wkt) != OGRERR_NONE) {
      st = tt__app_fail(r, TT_APP_EXIT_USAGE, TT_ERR_ARG, NULL,
                    "generate: -a_srs '%s' is not a CRS GDAL understands%s%s",
                    s->srs, r->msg.last[0] ? ": " : "", r->msg.last);
      goto done;
    }
  }
  /* generate reads one file: a CRS given as a file name to -a_srs. */
  if (s->srs && tt__app_same_file(s->srs, s->output)) {
    st = tt__app_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_ARG, s->output,
                      "is the file -a_srs reads; refusing to replace it");
    goto done;
  }
  if (!s->overwrite && VSIStatL(s->output, &sb) == 0) {
    st = tt__app_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_EXISTS, s->output,
                  "exists; use -overwrite to replace it");
    goto done;
  }
  if (!tt__app_continue(r, 0.0)) {
    st = tt__app_fail_tt(r, TT_ERR_INTERRUPTED, s->output);
    goto done;
  }
  st = tt_synth_generate(r->ctx, &s->synth, &grid);
  if (st != TT_OK) {
    tt__app_fail_tt(r, st, s->output);
    goto done;
  }
  if (!tt__app_continue(r, 0.5)) {
    st = tt__app_fail_tt(r, TT_ERR_INTERRUPTED, s->output);
    goto done;
  }
  r->msg.last[0] = '\0';
  st = tt_gdal_write_grid(r->ctx, grid, s->output, wkt ? wkt : "",
                          s->overwrite);
  if (st == TT_ERR_EXISTS) {
    tt__app_fail_exists(r, s->output);
    goto done;
  }
  if (st != TT_OK) {
    tt__app_fail_tt(r, st, s->output);
    goto done;
  }
  if (!s->quiet) {
    double lo, hi;
    tt__app_height_range(grid, &lo, &hi);
    fprintf(r->out,
            "%s: %s terrain, %zux%zu samples, seed %llu, heights %.6g to "
            "%.6g; %.2f s\n",
            tt__app_shown(r, s->output), tt_synth_kind_name(s->synth.kind),
            s->synth.nx,
            s->synth.ny, (unsigned long long)s->synth.seed, lo, hi,
            tt__app_now() - r->t0);
    fflush(r->out);
  }
done:
  CPLFree(wkt);
  if (srs)
    OSRDestroySpatialReference(srs);
  tt_grid_destroy(grid);
  return st;
}
