/*
 * estimate.c -- apps/simplify/, the simplify command: what a run is about
 * to make, said before the work (issue 27): the vertices, the output's
 * bytes and the whole run's memory a bound will take, from a quick pass
 * over a sample of the DEM.
 *
 * The pass reads a few windows of the DEM at full resolution, spread on a
 * lattice over it (the tiles of a tiling of 256 cells -- fewer on a DEM
 * where 4 of them would pass an eighth of it --, every k-th one each way:
 * at least 4, about 1/64 of the samples, at most some 2 M), and
 * records each one's error-against-count curve (tt_tile_curve: the window
 * refined without its shared sides' vertices, as the inside of a whole
 * run is). A curve runs until its error is within the bound and it holds
 * 5 % of its samples, whichever comes last. The vertices at the bound per
 * sampled cell, times the DEM's cells, predict the TIN; the curves also
 * give the bound that keeps about 5 % of the samples, for the advice.
 * Without -max_error the bound is the default's (default_bound.c: twice
 * the mean step), from the sampled windows' steps.
 *
 * The output's bytes are the vertices times what one costs in the format
 * (a GeoPackage: about 700 bytes a vertex with its two triangles, measured
 * on 12000^2 runs); the whole run's memory those of docs/cli.md's
 * *Limits* (4 bytes a sample for the heights, 20 with ground points, and
 * about 280 a vertex, at the capacity of the last growth step: 1.5 x).
 * Accuracy: bench/estimate.sh prints predicted against actual on the DEMs
 * of ../shared/testdata.
 *
 * Workload: the windows are read and refined on the calling thread, one
 * at a time; some 1-2 % of a run's refinement time on a large DEM.
 */
#include "simplify.h"

#include <cpl_conv.h>
#include <cpl_string.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* The sample's lattice: windows of EST_WINDOW cells (less on a small
 * DEM), about 1/EST_SHARE of the cells, at least EST_MIN_WINDOWS, at
 * most EST_MAX_CELLS cells. */
#define EST_WINDOW 256
#define EST_SHARE 64
#define EST_MIN_WINDOWS 4
#define EST_MAX_CELLS ((size_t)2 << 20)
/* The share of a window's samples its curve reaches at least (for the
 * advice of a bound that keeps about that share). */
#define EST_ADVICE_SHARE 0.05
/* Bytes a vertex: a GeoPackage or another OGR dataset (its two triangles
 * with their attributes and R-tree rows), a mesh file; the whole run. */
#define EST_OGR_BYTES 700.0
#define EST_MESH_BYTES 120.0
#define EST_RUN_BYTES 280.0

/* One window's curve, and when to stop it. */
typedef struct est_window {
  app_curve curve;
  double bound;      /* stop once the error is within it ... */
  size_t need;       /* ... and the vertices are at least this many */
  int reached;       /* both are: the progress poll stops the run */
} est_window;

static void est_point(void *arg, size_t vertices, double max_error)
{
  est_window *w = arg;
  tt__app_curve_point(&w->curve, vertices, max_error);
  if (max_error <= w->bound && vertices >= w->need)
    w->reached = 1;
}

static int est_poll(double complete, const char *message, void *arg)
{
  (void)complete;
  (void)message;
  return !((est_window *)arg)->reached;
}

/* The lattice: the window size, the tiling's tiles each way, and the
 * sampled tiles each way (kx x ky). */
static void lattice(size_t W, size_t H, size_t *out_n, size_t *out_ntx,
                    size_t *out_nty, size_t *out_kx, size_t *out_ky)
{
  size_t small = W < H ? W : H;
  size_t n = EST_WINDOW;
  /* smaller windows on a small DEM, so the fewest of them still sample
   * at most an eighth of it */
  while (n > 16 && (n * 2 > small ||
                    8.0 * EST_MIN_WINDOWS * (double)n * (double)n >
                        (double)W * (double)H))
    n /= 2;
  size_t ntx = (W - 2) / n + 1, nty = (H - 2) / n + 1;
  double want = (double)W * (double)H / EST_SHARE;
  if (want > (double)EST_MAX_CELLS)
    want = (double)EST_MAX_CELLS;
  double k = ceil(want / ((double)n * (double)n));
  if (k < EST_MIN_WINDOWS)
    k = EST_MIN_WINDOWS;
  size_t side = (size_t)ceil(sqrt(k));
  *out_n = n;
  *out_ntx = ntx;
  *out_nty = nty;
  *out_kx = side < ntx ? side : ntx;
  *out_ky = side < nty ? side : nty;
}

/* Reads the sampled windows (tile (i, j) of the lattice each), into
 * grids[] and tiles[]; their mean step (default_bound.c) into step. The
 * failure is recorded. */
static tt_status read_windows(app_simplify_job *job, tt_context *ctx,
                              size_t n, size_t ntx,
                              size_t nty, size_t kx, size_t ky,
                              tt_grid **grids, tt_tile *tiles,
                              app_step *step)
{
  app_run *r = job->r;
  size_t W = job->width, H = job->height;
  char **base = tt__app_view_read_options(r, tt__app_read_options(job->s),
                                          job->s->input);
  tt_status st = TT_OK;
  /* the read's warnings are the DEM's: the whole run says them (ctx has
   * no log) */
  tt__app_quiet_push(&r->msg);
  for (size_t b = 0; b < ky && st == TT_OK; b++)
    for (size_t a = 0; a < kx && st == TT_OK; a++) {
      size_t i = (size_t)(((double)a + 0.5) * (double)ntx / (double)kx);
      size_t j = (size_t)(((double)b + 0.5) * (double)nty / (double)ky);
      tt_tile *t = &tiles[b * kx + a];
      t->col0 = i * n;
      t->row0 = j * n;
      t->col1 = (i + 1) * n < W - 1 ? (i + 1) * n : W - 1;
      t->row1 = (j + 1) * n < H - 1 ? (j + 1) * n : H - 1;
      t->dem_width = W;
      t->dem_height = H;
      size_t c0, r0, w, h;
      tt_tile_window(t, &c0, &r0, &w, &h);
      char **ro = CSLDuplicate(base);
      ro = CSLSetNameValue(ro, "WINDOW", CPLSPrintf("%zu,%zu,%zu,%zu", c0,
                                                    r0, w, h));
      st = tt_gdal_read_grid(ctx, job->band, ro, NULL, NULL,
                             &grids[b * kx + a], NULL);
      CSLDestroy(ro);
      if (st == TT_OK)
        tt__app_step_of_grid(step, grids[b * kx + a]);
    }
  CPLPopErrorHandler();
  CSLDestroy(base);
  if (st != TT_OK)
    tt__app_fail(r, TT_APP_EXIT_FAILURE, st, NULL, "%s",
                 tt_context_errmsg(ctx));
  return st;
}

/* Each window's curve to the bound and the advice's share. */
static tt_status run_curves(app_simplify_job *job, tt_context *ctx,
                            tt_grid **grids,
                            const tt_tile *tiles, size_t nw, double bound,
                            est_window *ws, size_t *out_cells,
                            size_t *out_valid)
{
  app_run *r = job->r;
  tt_refine_options o = job->ro;
  o.threads = 1;
  o.max_memory = 0;
  o.max_points = o.max_triangles = 0;
  o.percent = 0;
  o.progress = est_poll;
  *out_cells = *out_valid = 0;
  for (size_t k = 0; k < nw; k++) {
    const tt_tile *t = &tiles[k];
    size_t valid = tt__app_tile_owned_valid(grids[k], t);
    size_t cells = (t->col1 - t->col0 + (t->col1 + 1 == t->dem_width)) *
                   (t->row1 - t->row0 + (t->row1 + 1 == t->dem_height));
    *out_cells += cells;
    *out_valid += valid;
    ws[k].bound = bound;
    ws[k].need = (size_t)ceil(EST_ADVICE_SHARE * (double)valid);
    o.progress_arg = &ws[k];
    tt_status st = tt_tile_curve(ctx, grids[k], t, &o, cells, est_point,
                                 &ws[k]);
    if (st == TT_ERR_INTERRUPTED && ws[k].reached)
      st = TT_OK; /* the curve is as far as it needs to be */
    if (st != TT_OK)
      return tt__app_fail(r, TT_APP_EXIT_FAILURE, st, job->s->input,
                          "estimating: %s", tt_context_errmsg(ctx));
    if (ws[k].curve.failed || !tt__app_curve_end(&ws[k].curve))
      return tt__app_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_NOMEM, NULL,
                          "out of memory for the estimate's curves");
    if (!tt__app_continue(r, 0.0))
      return tt__app_fail_tt(r, TT_ERR_INTERRUPTED, job->s->output);
  }
  return TT_OK;
}

/* The prediction from the curves (the sample's cells and valid samples
 * scaled to the DEM's). */
static void predict(app_simplify_job *job, const est_window *ws, size_t nw,
                    size_t cells, size_t valid, app_estimate *e)
{
  double scale = (double)job->width * (double)job->height / (double)cells;
  size_t v = 0;
  for (size_t k = 0; k < nw; k++)
    v += tt__app_curve_count_at(&ws[k].curve, e->bound);
  e->sampled_cells = cells;
  e->sampled_valid = valid;
  e->valid = (double)valid * scale;
  e->vertices = (double)v * scale;
  if (e->vertices < 3 && e->valid >= 3)
    e->vertices = 3;
  e->triangles = 2.0 * e->vertices;
  e->share = e->valid > 0 ? e->vertices / e->valid : NAN;
  e->output_bytes = e->vertices * (job->kind == APP_OUTPUT_MESH
                                       ? EST_MESH_BYTES
                                       : EST_OGR_BYTES);
  /* the refinement holds its arrays at the capacity of its next growth
   * step: up to half as much again */
  e->memory_whole = (double)job->width * (double)job->height *
                        (job->ground ? 20.0 : 4.0) +
                    1.5 * e->vertices * EST_RUN_BYTES;
  /* the bound of about a 5 % TIN, from the same curves */
  app_curve *c = malloc(nw * sizeof *c);
  e->advice_bound = NAN;
  if (c) {
    for (size_t k = 0; k < nw; k++)
      c[k] = ws[k].curve;
    double b = NAN;
    size_t got = 0;
    if (tt__app_curves_bound(c, nw, (size_t)(EST_ADVICE_SHARE *
                                             (double)valid),
                             -1.0, INFINITY, &b, &got))
      e->advice_bound = b;
    free(c);
  }
}

int tt__app_estimate_wanted(const app_simplify_job *job)
{
  const tt_refine_options *ro = &job->ro;
  if (ro->max_points || ro->max_triangles || ro->percent > 0 ||
      tt__app_tiles_hook.save || tt__app_tiles_hook.load ||
      job->width < 4 || job->height < 4 ||
      strncmp(job->s->input, "/vsistdin/", 10) == 0) /* read once */
    return 0;
  /* always in the JSON; else only where it may say something: past a
   * million samples, or a DEM the whole run may not hold */
  size_t cells = job->width * job->height;
  return job->s->json || cells > ((size_t)1 << 20) ||
         (job->mem_limit != SIZE_MAX && cells * 8 > job->mem_limit / 8);
}

tt_status tt__app_estimate(app_simplify_job *job)
{
  app_estimate *e = &job->rep.estimate;
  memset(e, 0, sizeof *e);
  double t0 = tt__app_now();
  size_t n, ntx, nty, kx, ky;
  lattice(job->width, job->height, &n, &ntx, &nty, &kx, &ky);
  size_t nw = kx * ky;
  tt_grid **grids = calloc(nw, sizeof *grids);
  tt_tile *tiles = calloc(nw, sizeof *tiles);
  est_window *ws = calloc(nw, sizeof *ws);
  tt_context *ctx = tt_context_create();
  tt_status st = TT_OK;
  app_step step = {0};
  if (!grids || !tiles || !ws || !ctx)
    st = tt__app_fail(job->r, TT_APP_EXIT_FAILURE, TT_ERR_NOMEM, NULL,
                      "out of memory for the estimate");
  if (st == TT_OK)
    st = read_windows(job, ctx, n, ntx, nty, kx, ky, grids, tiles, &step);
  if (st == TT_OK) {
    e->bound = job->ro.max_error;
    e->bound_default = e->bound < 0;
    if (e->bound_default)
      e->bound = tt__app_default_bound_of(&step);
    size_t cells = 0, valid = 0;
    st = run_curves(job, ctx, grids, tiles, nw, e->bound, ws, &cells,
                    &valid);
    if (st == TT_OK && cells > 0)
      predict(job, ws, nw, cells, valid, e);
  }
  for (size_t k = 0; grids && k < nw; k++)
    tt_grid_destroy(grids[k]);
  for (size_t k = 0; ws && k < nw; k++)
    tt__app_curve_free(&ws[k].curve);
  free(grids);
  free(tiles);
  free(ws);
  tt_context_destroy(ctx);
  if (st != TT_OK)
    return st;
  e->done = 1;
  e->windows = nw;
  e->window_size = n;
  e->seconds = tt__app_now() - t0;
  return TT_OK;
}

/* "307 MB", "1.2 GB": decimal units, as a disk's size is sold. */
static void decimal_bytes(char *buf, size_t size, double b)
{
  if (b >= 1e9)
    snprintf(buf, size, "%.1f GB", b / 1e9);
  else if (b >= 1e6)
    snprintf(buf, size, "%.0f MB", b / 1e6);
  else
    snprintf(buf, size, "%.0f kB", b / 1e3);
}

void tt__app_estimate_say(app_simplify_job *job)
{
  const app_estimate *e = &job->rep.estimate;
  app_run *r = job->r;
  if (!e->done || job->s->quiet ||
      (e->vertices <= 1e6 && e->output_bytes <= 1e9))
    return;
  char out[32], advice[160] = "";
  decimal_bytes(out, sizeof out, e->output_bytes);
  if (isfinite(e->advice_bound) && e->share > 2 * EST_ADVICE_SHARE)
    snprintf(advice, sizeof advice, "; -max_error %.3g gives about a %.0f%% "
             "TIN", e->advice_bound, 100 * EST_ADVICE_SHARE);
  tt_app_term_progress_break(r->msg.bar);
  fprintf(r->msg.err, "terratin: %s: this bound (%.6g) keeps about %.2g%% "
          "of the samples (~%.0f vertices, ~%s)%s\n",
          tt__app_shown(r, job->s->input), e->bound, 100 * e->share,
          e->vertices, out, advice);
  fflush(r->msg.err);
}
