/*
 * simplify.c -- apps/simplify/, the simplify command: `terratin simplify
 * INPUT OUTPUT`, one pipeline over one job description (simplify.h), as
 * GDAL's apps/gdal_utils.h runs a utility from its options object: the
 * settings read into the job (job.c), the output chosen and planned
 * (output.c), the DEM opened, the writer's options checked, the tiling
 * chosen, the TIN made -- the whole DEM read into a grid and refined
 * (-method insert) or decimated (-method decimate), or tile by tile
 * (tiled.c) -- then written and committed (write.c), and the summary or
 * JSON printed (apps/core/report.c).
 *
 * Progress: read 0 - 10 % (0 - 30 % with ground points: 0 - 24 % projecting
 * them, then the scan), simplify to 85 % (a tiled run reads as it goes:
 * 0 - 85 %), write 85 - 100 %.
 *
 * Invariants: the input is never written; an existing output is replaced
 * only with -overwrite and only once the new one is complete; a failure or
 * an interruption at any phase leaves nothing behind (tt__app_job_free).
 */
#include "simplify.h"
#include "base/internal.h" /* tt__format_bytes */

#include <cpl_string.h>

#include <stdint.h>
#include <string.h>

/* The DEM opened (its band checked), and every file it is read from (the
 * container of a /vsizip/ or GPKG: name, VRT sources, sidecars) put out
 * of the output's reach. */
static tt_status open_input(app_simplify_job *job)
{
  app_run *r = job->r;
  const tt_app_settings *s = job->s;
  tt__app_phase_set(&r->prog, 0.0, 0.10);
  job->src = tt__app_open_raster(r, s->input, s->band, &job->band);
  if (!job->src)
    return r->res->status;
  /* a CRS to go from, said before any work: the way forward is -a_srs */
  const char *needs = s->t_srs ? "-t_srs" : s->work_srs ? "-work_srs" : NULL;
  if (needs && !GDALGetSpatialRef(job->src))
    return tt__app_fail(r, TT_APP_EXIT_USAGE, TT_ERR_ARG, NULL,
                        "simplify: %s %s: the DEM %s has no CRS to transform "
                        "from; give it one with -a_srs SRS", needs,
                        s->t_srs ? s->t_srs : s->work_srs, s->input);
  job->width = (size_t)GDALGetRasterBandXSize(job->band);
  job->height = (size_t)GDALGetRasterBandYSize(job->band);
  tt_status st = job->outp ? tt_output_protect_dataset(
                                 r->ctx, job->outp,
                                 tt__app_raster_file(r, job->src), s->input)
                           : TT_OK;
  if (st != TT_OK)
    tt__app_fail_tt(r, st, s->output);
  return st;
}

/* The bytes a whole run holds a sample, about: the heights and the
 * refinement's share (8), the ground points of a geographic or Web
 * Mercator DEM (16), decimation's start of every sample (a vertex and two
 * triangles a sample in the mesh: 150). */
static size_t whole_bytes_per_sample(const app_simplify_job *job)
{
  return 8 + (job->ground ? 16 : 0) + (job->decimate ? 150 : 0);
}

/* The tiles of an automatic tiling: 1024 cells (a multiple of the block
 * size), halved until those in flight hold half the limit; 0 when even
 * tiles of 64 do not fit (the whole run then says why). */
static size_t auto_tile_size(const app_simplify_job *job)
{
  size_t w = job->width, h = job->height, limit = job->mem_limit;
  int bw = 0, bh = 0, nth = job->workers;
  GDALGetBlockSize(job->band, &bw, &bh);
  size_t want = 1024;
  if (bw > 1 && bw <= 4096 && bw == bh)
    want = ((1024 + (size_t)bw - 1) / (size_t)bw) * (size_t)bw;
  /* tiled_tiles.c's bytes a sample; for decimation twice its figure
   * (80): a tile's start of every sample, with the allocator's arenas of
   * the worker threads, took more under ulimit -v */
  size_t per = job->decimate ? 160 : 32;
  while (want > 64 && tt__app_tile_bytes(want, w, h, nth, job->ground) /
                              32 * per > limit / 2)
    want /= 2;
  if (tt__app_tile_bytes(want, w, h, nth, job->ground) / 32 * per >
      limit / 2)
    return 0;
  return want;
}

/* Tiles (tiled.c, docs/scale.md): asked for (-tile_size), or chosen when
 * the whole run would not fit the memory limit (-max_memory, else what
 * the system allows: tt_memory_limit), for either method, as the
 * estimate says (its heights and TIN, estimate.c) or, without one, a few
 * bytes a sample; a budget becomes a bound. A DEM of more than TT_APP_AUTO_TILE_CELLS samples is
 * not tiled unasked (such a run takes an hour or more): when its heights
 * do not fit either, it is refused here, before anything is read, naming
 * -tile_size. The failure is recorded. */
static tt_status choose_tiling(app_simplify_job *job)
{
  const tt_app_settings *s = job->s;
  size_t w = job->width, h = job->height, limit = job->mem_limit;
  tt__app_job_threads(job);
  job->ground = tt__app_ground_points(job->band);
  job->tile_size = s->tile_size;
  if (!job->tile_size && limit != SIZE_MAX && w * h > TT_APP_AUTO_TILE_CELLS &&
      w * h > limit / sizeof(float)) {
    size_t tile = auto_tile_size(job);
    char need[32], lim[32];
    return tt__app_fail(job->r, TT_APP_EXIT_FAILURE, TT_ERR_LIMIT,
                        s->input, "the %zu x %zu heights need %s, more "
                        "than the memory limit of %s (%s); refused before "
                        "reading: -tile_size %zu runs it in tiles (a DEM "
                        "of more than %zu samples is tiled only when "
                        "asked)", w, h,
                        tt__format_bytes(need, sizeof need,
                                         (uint64_t)w * h * sizeof(float)),
                        tt__format_bytes(lim, sizeof lim, limit),
                        job->mem_source, tile ? tile : 64,
                        (size_t)TT_APP_AUTO_TILE_CELLS);
  }
  if (tt__app_estimate_wanted(job)) {
    tt_status st = tt__app_estimate(job);
    if (st != TT_OK)
      return st;
    tt__app_estimate_say(job);
  }
  /* the whole run's memory: the estimate's (the heights and its TIN, a
   * quarter more for the estimate's own error), else a few bytes a
   * sample */
  const app_estimate *e = &job->rep.estimate;
  int fits = e->done && !job->decimate
                 ? 1.25 * e->memory_whole <= (double)limit
                 : w * h <= limit / whole_bytes_per_sample(job);
  if (job->tile_size || w <= 2 || h <= 2 || limit == SIZE_MAX || fits ||
      w * h > TT_APP_AUTO_TILE_CELLS)
    return TT_OK;
  size_t tile = auto_tile_size(job);
  if (tile) {
    job->tile_size = tile;
    job->rep.auto_tiled = 1;
  }
  return TT_OK;
}

/* The tiled run (tiled.c): the tiles in flight checked against
 * -max_memory first, the output streamed when it is a GeoPackage file.
 * No TIN (and nothing streamed): one tile of `tiles run`, handed to its
 * hook. */
static tt_status run_tiled(app_simplify_job *job)
{
  app_run *r = job->r;
  const tt_app_settings *s = job->s;
  app_simplify_report *rep = &job->rep;
  size_t tile = job->tile_size;
  rep->ropt = &job->ro;
  rep->tile_size = tile;
  rep->tile_bytes = tt__app_tile_bytes(tile, job->width, job->height,
                                       job->workers, job->ground);
  if (job->decimate) /* a start of every sample: 48 bytes a sample more */
    rep->tile_bytes = rep->tile_bytes / (job->ground ? 64 : 32) *
                      (job->ground ? 112 : 80);
  if (s->max_memory && rep->tile_bytes > s->max_memory)
    return tt__app_fail(r, TT_APP_EXIT_USAGE, TT_ERR_ARG, NULL,
                        "simplify: tiles of %zu cells on %d threads hold up "
                        "to about %zu MiB, more than -max_memory (%zu MiB): "
                        "use a smaller -tile_size or fewer -threads", tile,
                        job->workers, rep->tile_bytes >> 20,
                        s->max_memory >> 20);
  tt__app_phase_set(&r->prog, 0.0, 0.85);
  double t = tt__app_now();
  if (job->decimate)
    rep->dopt = &job->dopt;
  tt__app_output_choose_stream(job);
  tt_status st = tt__app_simplify_tiled(job);
  if (st != TT_OK || (!job->tin && job->kind != APP_OUTPUT_STREAM))
    return st;
  tt__app_close_raster(job->r, job->src);
  job->src = NULL;
  rep->info = job->info;
  rep->driver = job->drvname;
  rep->cells = job->width * job->height;
  rep->t_simplify = tt__app_now() - t;
  if (job->kind == APP_OUTPUT_STREAM)
    rep->sum = job->so.sink.sum;
  else
    tt_tin_get_summary(job->tin, &rep->sum);
  return TT_OK;
}

/* The read's share of a whole run's progress: 10 %, 30 % for a DEM
 * whose samples are all projected to ground points as they are read
 * (raster_georef.c: ten times the scan's time). */
static double read_share(const app_simplify_job *job)
{
  return job->ground ? 0.30 : 0.10;
}

/* The whole DEM read into a grid (0 - 10 %, or 30 %), and its height
 * range. */
static tt_status read_whole(app_simplify_job *job)
{
  app_run *r = job->r;
  app_simplify_report *rep = &job->rep;
  size_t valid = 0;
  tt__app_phase_set(&r->prog, 0.0, read_share(job));
  tt_status st = tt__app_read_dem(r, job->band, job->s->input,
                                  tt__app_phase_fn, &r->prog, &job->grid,
                                  &job->info, &valid);
  if (st != TT_OK)
    return st;
  tt__app_close_raster(job->r, job->src);
  job->src = NULL;
  rep->info = job->info;
  rep->driver = job->drvname;
  rep->cells = tt_grid_width(job->grid) * tt_grid_height(job->grid);
  rep->min_patch = job->s->min_patch;
  if (!tt__app_drop_patches(job->grid, job->s->min_patch,
                            &rep->dropped_samples, &rep->dropped_patches))
    return tt__app_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_NOMEM, job->s->input,
                        "out of memory for -min_patch");
  valid -= rep->dropped_samples;
  rep->valid = valid;
  tt__app_height_range(job->grid, &rep->zmin, &rep->zmax);
  rep->t_read = tt__app_now() - r->t0;
  return TT_OK;
}

/* The whole run: the grid refined or decimated (10 - 85 %); the TIN
 * keeps what it needs, the grid goes before the write. */
static tt_status run_whole(app_simplify_job *job)
{
  app_run *r = job->r;
  const tt_app_settings *s = job->s;
  app_simplify_report *rep = &job->rep;
  tt_status st = read_whole(job);
  if (st != TT_OK)
    return st;
  if (tt__app_job_default_wanted(job)) {
    app_step step = {0};
    tt__app_step_of_grid(&step, job->grid);
    tt__app_job_default_bound(job, &step);
  }
  if (s->breaklines && (st = tt__app_breaklines(job)) != TT_OK)
    return st;
  tt__app_phase_set(&r->prog, read_share(job), 0.85);
  rep->ropt = &job->ro;
  if (job->decimate)
    rep->dopt = &job->dopt;
  double t = tt__app_now();
  st = job->decimate ? tt_decimate_run(r->ctx, job->grid, &job->dopt,
                                       &job->tin)
                     : tt_refine_run(r->ctx, job->grid, &job->ro, &job->tin);
  if (st == TT_ERR_NOMEM && job->ro.max_memory &&
      strstr(tt_context_errmsg(r->ctx), "memory limit"))
    return tt__app_fail(r, TT_APP_EXIT_FAILURE, st, s->input, "%s (%s); "
                        "nothing written", tt_context_errmsg(r->ctx),
                        job->mem_source);
  if (st == TT_ERR_LIMIT) /* a budget below the start's vertices */
    return tt__app_fail(r, TT_APP_EXIT_USAGE, st, s->input, "%s",
                        tt_context_errmsg(r->ctx));
  if (st != TT_OK)
    return tt__app_fail_tt(r, st, st == TT_ERR_INTERRUPTED ? s->output
                                                           : s->input);
  rep->t_simplify = tt__app_now() - t;
  tt_tin_get_summary(job->tin, &rep->sum);
  tt_grid_destroy(job->grid);
  job->grid = NULL;
  return TT_OK;
}

static void report(app_simplify_job *job)
{
  app_run *r = job->r;
  app_simplify_report *rep = &job->rep;
  tt__app_output_names(job, &rep->files, &rep->layers);
  rep->crs_file = NULL;
  int nf = CSLCount(rep->files);
  if (job->mesh == TT_MESH_2DM && job->srs && nf > 1)
    rep->crs_file = rep->files[nf - 1]; /* the last sidecar */
  if (job->s->json)
    tt__app_print_simplify_json(r, rep);
  else if (!job->s->quiet)
    tt__app_print_simplify_summary(r, rep);
  fflush(r->out);
  CSLDestroy(rep->files);
  CSLDestroy(rep->layers);
  rep->files = rep->layers = NULL;
}

tt_status tt__app_simplify(app_run *r)
{
  app_simplify_job job;
  tt__app_job_init(&job, r);
  tt_status st = tt__app_job_check(&job);
  if (st == TT_OK)
    st = tt__app_output_choose(&job);
  /* the output planned first: a refusal costs nothing yet */
  if (st == TT_OK)
    st = tt__app_output_plan(&job);
  if (st == TT_OK)
    st = tt__app_job_memory(&job);
  if (st == TT_OK)
    st = open_input(&job);
  if (st == TT_OK)
    st = tt__app_output_options(&job);
  if (st == TT_OK && !tt__app_continue(r, 0.0))
    st = tt__app_fail_tt(r, TT_ERR_INTERRUPTED, r->s->output);
  if (st == TT_OK)
    st = choose_tiling(&job);
  if (st == TT_OK && job.tile_size && r->s->min_patch)
    st = tt__app_fail(r, TT_APP_EXIT_USAGE, TT_ERR_ARG, "-min_patch",
                      "a tiled run (-tile_size, or tiles chosen by the "
                      "memory limit) cannot count patches across its "
                      "tiles: run untiled");
  if (st == TT_OK && r->s->breaklines && job.tile_size)
    st = tt__app_fail(r, TT_APP_EXIT_USAGE, TT_ERR_ARG, NULL,
                      "simplify: -breaklines: not yet with a tiled run "
                      "(-tile_size, or a DEM tiled automatically for "
                      "memory)");
  if (st == TT_OK)
    st = job.tile_size ? run_tiled(&job) : run_whole(&job);
  /* nothing to write: one tile of `tiles run`, handed to its hook */
  int made = job.tin || job.kind == APP_OUTPUT_STREAM;
  if (st == TT_OK && made)
    st = tt__app_simplify_write(&job);
  if (st == TT_OK && made)
    report(&job);
  tt__app_job_free(&job);
  return st;
}
