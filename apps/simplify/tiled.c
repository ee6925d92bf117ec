/*
 * tiled.c -- apps/simplify/, the simplify command: its tiled path,
 * `terratin simplify -tile_size N` and a DEM whose heights do not fit the
 * memory limit: the DEM read and refined tile by tile (src/tile/), the
 * pieces merged into one TIN as they finish. This file sets a tiled run
 * up from the job (simplify.h) and runs its passes over the tiles; each
 * pass runs the tiles on worker threads and takes them in tile order
 * (tiled_workers.c), merged into the TIN the write takes, or, for a
 * GeoPackage file, streamed into it (tiled_stream.c).
 *
 * A geographic or Web Mercator DEM is measured on the ground as untiled:
 * every window comes with the whole raster's ground points of its samples
 * (tt_gdal_read_grid), the pieces with their vertices' (src/tile/), and
 * the merger or the stream takes the geodesic area function from tile 0's
 * window.
 *
 * With -method decimate each tile is decimated instead (tt_tile_decimate),
 * with the same borders. A budget of the whole DEM (-max_points,
 * -max_triangles, -percent) is turned into one bound (budget_run): a
 * pass records every tile's error-against-count curve (tt_tile_curve,
 * tiled_budget.c), then the tiles are run at the bound the curves give,
 * again while the TIN passes the budget (tt__app_budget_passes decides,
 * docs/scale.md); streamed, a pass writes as if kept, and has its rows
 * dropped if it is not (at once when its counts pass the budget). Without
 * -max_error the bound is twice the DEM's mean step, as untiled (one more
 * pass over the tiles finds the step and the height range first).
 *
 * GDAL's block cache (5 % of the memory by default) would keep every
 * block read, the whole DEM in the end: unless GDAL_CACHEMAX is set, it
 * is held for the run to the blocks of one row of tiles and its margins,
 * (N + 2 block heights) x width samples (a tile's margin lines are read
 * again by its neighbours), and restored afterwards. On the 8193^2 fractal
 * in tiles of 1024 this took the peak from 344 to 130 MB.
 */
#include "tiled.h"

#include <cpl_conv.h>
#include <cpl_string.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Every tile refined (or decimated) and merged into *out_tin. */
static tt_status merge_all(tiled *T, const double gt[6], tt_tin **out_tin)
{
  tt_tin_merger *merger = NULL;
  tt_status st = tt_tin_merger_create(T->r->ctx, T->W, T->H, gt, &merger);
  if (st != TT_OK)
    return tt__app_fail_tt(T->r, st, T->path);
  for (size_t k = 0; k < T->ntiles; k++)
    T->done[k] = false;
  T->merger = merger; /* for tile 0's window to give the area function */
  st = tt__app_tiled_run_all(T, merger);
  if (st == TT_OK) {
    st = tt_tin_merger_finish(T->r->ctx, merger, out_tin);
    if (st != TT_OK)
      tt__app_fail_tt(T->r, st, T->path);
  }
  T->merger = NULL;
  tt_tin_merger_destroy(merger);
  return st;
}

/* Every tile run and streamed (the job's sink): the rows written as each
 * piece merges (unless a budget pass drops them), the summary in the
 * sink. */
static tt_status stream_all(tiled *T, const double gt[6])
{
  app_run *r = T->r;
  tt_status st = tt__tin_stream_create(r->ctx, T->W, T->H, T->N, gt,
                                       &T->stream);
  if (st != TT_OK)
    return tt__app_fail_tt(r, st, T->path);
  for (size_t k = 0; k < T->ntiles; k++)
    T->done[k] = false;
  T->write = true;
  st = tt__app_tiled_run_all(T, NULL);
  if (st == TT_OK) {
    tt__tin_stream_summary(T->stream, &T->sink->sum, &T->sink->zmin,
                           &T->sink->zmax);
    if (T->sink->sum.triangles == 0)
      st = tt__app_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_DATA, T->path, "no "
                        "triangle can be made: no grid cell has three "
                        "valid corners (the valid samples are isolated by "
                        "nodata)");
  }
  tt__tin_stream_destroy(T->stream);
  T->stream = NULL;
  return st;
}

/* One pass of a budget (tt__app_budget_passes): every tile run at bound
 * e, merged into *T->out_tin or streamed, its counts; budget_drop drops
 * it when it is not kept. */
static tt_status budget_pass(void *arg, double e, size_t max_v, size_t max_t,
                             size_t *out_nv, size_t *out_nt)
{
  tiled *T = arg;
  T->ro.max_error = e;
  T->dec.max_error = e;
  T->max_v = max_v;
  T->max_t = max_t;
  tt_status st = T->sink ? stream_all(T, T->gt)
                         : merge_all(T, T->gt, T->out_tin);
  if (st != TT_OK)
    return st;
  *out_nv = T->sink ? T->sink->sum.vertices
                    : tt_tin_vertex_count(*T->out_tin);
  *out_nt = T->sink ? T->sink->sum.triangles
                    : tt_tin_triangle_count(*T->out_tin);
  return TT_OK;
}

static void budget_drop(void *arg)
{
  tiled *T = arg;
  if (T->sink && T->sink->out)
    T->sink->discard(T->sink); /* the rows of a pass not kept */
  tt_tin_destroy(*T->out_tin);
  *T->out_tin = NULL;
}

/* A budget of the whole DEM (-max_points, -max_triangles, -percent;
 * tiled_budget.c): the curve pass, then the passes at the bounds the
 * curves give until one is kept. ro->max_error, when set, is a floor of
 * the bound (its stop may come first, as untiled); it is set to the bound
 * kept. */
static tt_status budget_run(tiled *T, tt_refine_options *ro,
                            int *out_passes)
{
  app_run *r = T->r;
  tt_status st = TT_OK;
  size_t cells = T->W * T->H;
  /* the curves are recorded to 4 times a tile's share of the budget by
   * its cells (the percentage taken of every cell) */
  double want = ro->max_points ? (double)ro->max_points : INFINITY;
  if (ro->percent > 0)
    want = fmin(want, ro->percent / 100.0 * (double)cells);
  if (ro->max_triangles)
    want = fmin(want, (double)ro->max_triangles / 2.0);
  T->curve_per_cell = 4.0 * want / (double)cells;
  T->curves = calloc(T->ntiles, sizeof *T->curves);
  if (!T->curves)
    return tt__app_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_NOMEM, NULL,
                        "out of memory for %zu curves", T->ntiles);
  T->curve_pass = true;
  app_phase keep = r->prog;
  tt__app_phase_set(&r->prog, keep.lo, keep.lo + 0.3 * (keep.hi - keep.lo));
  st = tt__app_tiled_run_all(T, NULL);
  T->curve_pass = false;
  r->prog = keep;
  tt__app_phase_set(&r->prog, keep.lo + 0.3 * (keep.hi - keep.lo), keep.hi);
  if (st != TT_OK)
    return st;
  size_t valid = 0;
  for (size_t k = 0; k < T->ntiles; k++)
    valid += T->valid[k];
  app_budget_pass pass = {budget_pass, budget_drop, T};
  return tt__app_budget_passes(r, T->path, T->curves, T->ntiles, valid, ro,
                               &pass, &ro->max_error, out_passes);
}


/* The tiling of the job's DEM: its tiles and the threads that run them.
 * A raster too small for a triangle is refused (recorded). */
static tt_status tiled_size(tiled *T, app_simplify_job *job)
{
  memset(T, 0, sizeof *T);
  T->job = job;
  T->r = job->r;
  T->band = job->band;
  T->path = job->s->input;
  T->W = (size_t)GDALGetRasterBandXSize(job->band);
  T->H = (size_t)GDALGetRasterBandYSize(job->band);
  T->N = job->tile_size;
  if (T->W < 2 || T->H < 2)
    return tt__app_fail(T->r, TT_APP_EXIT_FAILURE, TT_ERR_DATA, T->path,
                        "raster is %zu x %zu pixels: at least 2 x 2 are "
                        "needed to make a triangle", T->W, T->H);
  T->ntx = (T->W - 2) / T->N + 1;
  T->nty = (T->H - 2) / T->N + 1;
  T->ntiles = T->ntx * T->nty;
  T->nthreads = job->workers;
  if ((size_t)T->nthreads > T->ntiles)
    T->nthreads = (int)T->ntiles;
  job->rep.tiles = T->ntiles;
  job->rep.tile_threads = T->nthreads;
  return TT_OK;
}

/* Each tile's options: the job's, on one thread, polling the stop flag,
 * without a memory limit (the tiles in flight are bounded, simplify.c);
 * a budget of the whole DEM becomes a bound (budget_run). */
static void tile_options(tiled *T)
{
  const app_simplify_job *job = T->job;
  T->ro = job->ro;
  T->ro.threads = 1;
  T->ro.max_memory = 0;
  T->ro.progress = tt__app_tiled_stop_check;
  T->ro.progress_arg = T;
  T->ro.max_points = T->ro.max_triangles = 0;
  T->ro.percent = 0;
  if (!job->decimate)
    return;
  T->decimate = true;
  T->dec = job->dopt;
  T->dec.max_error = job->ro.max_error;
  T->dec.max_points = T->dec.max_triangles = 0;
  T->dec.percent = 0;
  T->dec.threads = 1;
  T->dec.progress = tt__app_tiled_stop_check;
  T->dec.progress_arg = T;
}

/* GDAL's block cache held for the run to the blocks of one row of tiles
 * and its margins, unless GDAL_CACHEMAX is set (restored by tiled_free). */
static void hold_cache(tiled *T)
{
  if (CPLGetConfigOption("GDAL_CACHEMAX", NULL))
    return;
  int bw = 0, bh = 0;
  GDALGetBlockSize(T->band, &bw, &bh);
  if (bh < 1)
    bh = 1;
  GIntBig row = (GIntBig)(T->N + 2 * (size_t)bh) * (GIntBig)T->W *
                (GIntBig)(GDALGetDataTypeSizeBytes(
                              GDALGetRasterDataType(T->band)) + 1);
  if (row < ((GIntBig)16 << 20))
    row = (GIntBig)16 << 20;
  T->old_cache = GDALGetCacheMax64();
  if (row < T->old_cache) {
    GDALSetCacheMax64(row);
    T->cache_set = 1;
  }
}

/* The run's state: read and tile options, the per-tile arrays, the
 * cache, the locks (tiled_free releases them, even on a failure). */
static tt_status tiled_init(tiled *T)
{
  const app_simplify_job *job = T->job;
  /* every window's read options but its WINDOW: a whole DEM's, but
   * -max_memory (the tiles in flight are bounded instead); what grows
   * with the TIN is held to -max_memory, or to the system's limit when
   * that chose the tiles */
  T->ropts = tt__app_view_read_options(T->r, tt__app_read_options(job->s),
                                       T->path);
  T->max_memory = job->s->max_memory ? job->s->max_memory
                  : job->rep.auto_tiled ? job->mem_limit
                                        : 0;
  T->inflight_bytes = tt__app_tile_bytes(T->N, T->W, T->H, T->nthreads,
                                         job->ground);
  tile_options(T);
  T->pieces = calloc(T->ntiles, sizeof *T->pieces);
  T->done = calloc(T->ntiles, sizeof *T->done);
  T->zmin = calloc(T->ntiles, sizeof *T->zmin);
  T->zmax = calloc(T->ntiles, sizeof *T->zmax);
  T->valid = calloc(T->ntiles, sizeof *T->valid);
  T->steps = calloc(T->ntiles, sizeof *T->steps);
  hold_cache(T);
  pthread_mutex_init(&T->lock, NULL);
  pthread_mutex_init(&T->gdal, NULL);
  pthread_cond_init(&T->cond, NULL);
  T->range_min = INFINITY;
  T->range_max = -INFINITY;
  if (!T->pieces || !T->done || !T->zmin || !T->zmax || !T->valid ||
      !T->steps)
    return tt__app_fail(T->r, TT_APP_EXIT_FAILURE, TT_ERR_NOMEM, NULL,
                        "out of memory for %zu tiles", T->ntiles);
  return TT_OK;
}

/* The DEM's step, which the default bound needs (no -max_error and no
 * budget), and its range of heights (the report): a pass over the tiles
 * that only reads them, then the bound set. */
static tt_status height_range(tiled *T)
{
  app_run *r = T->r;
  if (!tt__app_job_default_wanted(T->job))
    return TT_OK;
  T->minmax_only = true;
  app_phase keep = r->prog;
  tt__app_phase_set(&r->prog, keep.lo, keep.lo + 0.1 * (keep.hi - keep.lo));
  tt_status st = tt__app_tiled_run_all(T, NULL);
  r->prog = keep;
  tt__app_phase_set(&r->prog, keep.lo + 0.1 * (keep.hi - keep.lo), keep.hi);
  if (st != TT_OK)
    return st;
  size_t valid = 0;
  app_step step = {0};
  for (size_t k = 0; k < T->ntiles; k++) {
    T->range_min = T->zmin[k] < T->range_min ? T->zmin[k] : T->range_min;
    T->range_max = T->zmax[k] > T->range_max ? T->zmax[k] : T->range_max;
    valid += T->valid[k];
    tt__app_step_merge(&step, &T->steps[k]);
    T->done[k] = false;
  }
  if (valid == 0)
    return tt__app_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_DATA, T->path,
                        "band %d has no valid samples (all nodata)",
                        r->s->band);
  tt__app_job_default_bound(T->job, &step);
  T->ro.max_error = T->job->ro.max_error;
  T->dec.max_error = T->job->ro.max_error;
  T->minmax_only = false;
  return TT_OK;
}

/* The DEM's geotransform, else the unit one. */
static void geotransform(tiled *T)
{
  static const double unit_gt[6] = {0, 1, 0, 0, 0, 1};
  memcpy(T->gt, unit_gt, sizeof T->gt);
  GDALDatasetH ds = GDALGetBandDataset(T->band);
  if (ds && GDALGetGeoTransform(ds, T->gt) != CE_None)
    memcpy(T->gt, unit_gt, sizeof T->gt);
}

/* `terratin tiles run`: this one tile, handed to the hook. */
static tt_status one_tile(tiled *T)
{
  app_run *r = T->r;
  size_t k = tt__app_tiles_hook.tile;
  if (k >= T->ntiles)
    return tt__app_fail(r, TT_APP_EXIT_USAGE, TT_ERR_ARG, T->path, "tile %zu "
                        "does not exist: the plan has %zu tiles", k,
                        T->ntiles);
  T->failed = T->ntiles;
  tt__app_tiled_run_tile(T, r->ctx, k, NULL);
  if (T->failed < T->ntiles)
    return tt__app_fail(r, TT_APP_EXIT_FAILURE, T->fail_status, T->path,
                        "tile %zu: %s", k, T->fail_msg);
  return tt__app_tiles_hook.save(tt__app_tiles_hook.arg, r, k, T->pieces[k]);
}

/* Every tile run at the bound, or to the budget (budget_run): streamed
 * (the job's sink, tiled_stream.c: the rows go out as the pieces merge,
 * no TIN is made) or merged into job->tin. */
static tt_status run_passes(tiled *T)
{
  app_simplify_job *job = T->job;
  const tt_refine_options *ro = &job->ro;
  bool budget = ro->max_points || ro->max_triangles || ro->percent > 0;
  T->sink = job->kind == APP_OUTPUT_STREAM ? &job->so.sink : NULL;
  T->max_v = T->max_t = SIZE_MAX;
  T->out_tin = &job->tin;
  return budget   ? budget_run(T, &job->ro, &job->rep.budget_passes)
         : T->sink ? stream_all(T, T->gt)
                   : merge_all(T, T->gt, &job->tin);
}

/* What the passes made, for the report: the raster facts (tile 0's, for
 * the whole DEM), the valid samples, the height range (the pre-pass's,
 * else the stream's, else that of the TIN's vertices: the bound was
 * given). */
static void finish(tiled *T)
{
  app_simplify_job *job = T->job;
  tt_tin_summary sum;
  if (T->sink)
    sum = T->sink->sum;
  else
    tt_tin_get_summary(job->tin, &sum);
  if (T->info) {
    T->info->width = T->W;
    T->info->height = T->H;
    T->info->valid_samples = sum.valid_samples;
    T->info->nodata_samples = T->W * T->H - sum.valid_samples;
  }
  double zmin = T->range_min, zmax = T->range_max;
  if (!(zmin <= zmax) && T->sink) {
    zmin = T->sink->zmin;
    zmax = T->sink->zmax;
  } else if (!(zmin <= zmax)) {
    for (size_t v = 0; v < sum.vertices; v++) {
      tt_vertex_info vi;
      tt_tin_vertex(job->tin, v, &vi);
      zmin = vi.z < zmin ? vi.z : zmin;
      zmax = vi.z > zmax ? vi.z : zmax;
    }
  }
  job->rep.valid = sum.valid_samples;
  job->rep.zmin = zmin;
  job->rep.zmax = zmax;
  job->info = T->info;
  T->info = NULL;
}

static void tiled_free(tiled *T)
{
  if (T->cache_set) {
    GDALFlushRasterCache(T->band);
    GDALSetCacheMax64(T->old_cache);
  }
  if (T->curves)
    for (size_t k = 0; k < T->ntiles; k++)
      tt__app_curve_free(&T->curves[k]);
  free(T->curves);
  tt__tin_stream_destroy(T->stream);
  if (tt__app_tiles_hook.save && T->pieces &&
      tt__app_tiles_hook.tile < T->ntiles)
    tt_tin_destroy(T->pieces[tt__app_tiles_hook.tile]);
  tt_raster_info_destroy(T->info);
  CSLDestroy(T->ropts);
  free(T->pieces);
  free(T->done);
  free(T->zmin);
  free(T->steps);
  free(T->zmax);
  free(T->valid);
  pthread_mutex_destroy(&T->lock);
  pthread_mutex_destroy(&T->gdal);
  pthread_cond_destroy(&T->cond);
}

tt_status tt__app_simplify_tiled(app_simplify_job *job)
{
  tiled T;
  tt_status st = tiled_size(&T, job);
  if (st != TT_OK)
    return st;
  st = tiled_init(&T);
  if (st == TT_OK)
    st = height_range(&T);
  if (st == TT_OK) {
    geotransform(&T);
    if (tt__app_tiles_hook.save)
      st = one_tile(&T);
    else if ((st = run_passes(&T)) == TT_OK)
      finish(&T);
  }
  tiled_free(&T);
  if (st != TT_OK) {
    tt_tin_destroy(job->tin);
    job->tin = NULL;
  }
  return st;
}
