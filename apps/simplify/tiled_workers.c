/*
 * tiled_workers.c -- apps/simplify/, the simplify command: the tiles of a
 * tiled run (tiled.c) on the worker threads, one pass over them at a
 * time.
 *
 * Tiles of N cells share their border rows and columns. Worker threads
 * (-threads, GDAL_NUM_THREADS, else the core count) take the tiles in
 * order; each reads its window (the tile and one line beyond each shared
 * side: tt_tile_window) with tt_gdal_read_grid's WINDOW option -- GDAL
 * datasets are not for concurrent use, so each worker opens the DEM for
 * itself (reads take turns under a mutex on the shared dataset when it
 * cannot) -- and refines it with tt_tile_run, one thread per tile. The
 * main thread merges the pieces strictly in tile order, so the TIN is the
 * same for any thread count, and a worker does not start a tile more than
 * 2 x threads ahead of the merge, so at most that many windows and pieces
 * are held: memory is bounded by the tile size and the threads, not by
 * the DEM. Streamed (a GeoPackage file, tiled_stream.c: every method,
 * bound, budget and frame) the pieces go through a tt__tin_stream and
 * their rows are written as each merges; otherwise a tt_tin_merger holds
 * the merged TIN (its records grow with its vertices, as in any run) for
 * the write.
 * The first failure in tile order, or an interruption, stops the workers
 * at their next check (refinement polls the stop flag every 256
 * insertions).
 */
#include "tiled.h"
#include "gdal/gpkg/gpkg_stream.h"

#include <cpl_conv.h>
#include <cpl_error.h>
#include <cpl_string.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static void tile_of(const tiled *T, size_t k, tt_tile *t)
{
  size_t i = k % T->ntx, j = k / T->ntx;
  t->col0 = i * T->N;
  t->row0 = j * T->N;
  t->col1 = (i + 1) * T->N < T->W - 1 ? (i + 1) * T->N : T->W - 1;
  t->row1 = (j + 1) * T->N < T->H - 1 ? (j + 1) * T->N : T->H - 1;
  t->dem_width = T->W;
  t->dem_height = T->H;
}

int tt__app_tiled_stop_check(double complete, const char *message,
                             void *arg)
{
  (void)complete;
  (void)message;
  return !atomic_load(&((tiled *)arg)->stop);
}

static void fail(tiled *T, size_t k, tt_status st, const char *msg)
{
  pthread_mutex_lock(&T->lock);
  /* the first real failure in tile order; a tile stopped because another
   * failed (interrupted) never hides one */
  bool was_stop = T->failed < T->ntiles &&
                  T->fail_status == TT_ERR_INTERRUPTED;
  bool is_stop = st == TT_ERR_INTERRUPTED;
  if (T->failed == T->ntiles || (was_stop && !is_stop) ||
      (k < T->failed && was_stop == is_stop)) {
    T->failed = k;
    T->fail_status = st;
    snprintf(T->fail_msg, sizeof T->fail_msg, "%s", msg);
  }
  atomic_store(&T->stop, 1);
  pthread_cond_broadcast(&T->cond);
  pthread_mutex_unlock(&T->lock);
}

/* A warning of tile 0's read, kept for the main thread (T->lock). */
static void keep_tile0_warning(void *arg, const char *message)
{
  tiled *T = arg;
  pthread_mutex_lock(&T->lock);
  if (T->ntile0_warn < 4)
    snprintf(T->tile0_warn[T->ntile0_warn++], TT_APP_MESSAGE_MAX, "%s",
             message);
  pthread_mutex_unlock(&T->lock);
}

void tt__app_tiled_run_tile(tiled *T, tt_context *ctx, size_t k,
                            GDALRasterBandH own)
{
  tt_tile t;
  tile_of(T, k, &t);
  size_t c0, r0, w, h;
  tt_tile_window(&t, &c0, &r0, &w, &h);
  char **ro = CSLDuplicate(T->ropts);
  ro = CSLSetNameValue(ro, "WINDOW", CPLSPrintf("%zu,%zu,%zu,%zu", c0, r0,
                                                w, h));
  tt_grid *win = NULL;
  tt_raster_info *info = NULL;
  tt_status st = TT_OK;
  const tt_app_tiles_hook *hook = &tt__app_tiles_hook;
  /* tile 0's read says what is the DEM's own, once a run */
  bool say = k == 0 && !T->tile0_read;
  if (say)
    tt_context_set_log(ctx, keep_tile0_warning, T);
  /* merging pieces from files reads the DEM for tile 0's raster info only */
  if (!(hook->load && k > 0) && own) {
    st = tt_gdal_read_grid(ctx, own, ro, NULL, NULL, &win, &info);
  } else if (!(hook->load && k > 0)) {
    pthread_mutex_lock(&T->gdal);
    st = tt_gdal_read_grid(ctx, T->band, ro, NULL, NULL, &win, &info);
    pthread_mutex_unlock(&T->gdal);
  }
  CSLDestroy(ro);
  if (say) {
    tt_context_set_log(ctx, NULL, NULL);
    T->tile0_read = true;
  }
  /* the area function (geographic DEMs) from tile 0's window, set
   * before done[0]: merged after it */
  if (st == TT_OK && k == 0 && T->merger)
    tt_tin_merger_set_ground(T->merger, win);
  if (st == TT_OK && k == 0 && T->stream)
    tt__tin_stream_set_ground(T->stream, win);
  tt_tin *piece = NULL;
  if (st == TT_OK && hook->load && !T->minmax_only) {
    char msg[TT_APP_MESSAGE_MAX];
    msg[0] = '\0';
    st = hook->load(hook->arg, ctx, k, &piece, msg, sizeof msg);
    if (st != TT_OK) {
      tt_grid_destroy(win);
      tt_raster_info_destroy(info);
      tt_tin_destroy(piece);
      fail(T, k, st, msg);
      return;
    }
  } else if (st == TT_OK && T->minmax_only) {
    double lo = INFINITY, hi = -INFINITY;
    size_t n = 0;
    for (size_t y = 0; y < h; y++)
      for (size_t x = 0; x < w; x++) {
        double z = tt_grid_sample(win, x, y);
        if (!isnan(z)) {
          lo = z < lo ? z : lo;
          hi = z > hi ? z : hi;
          n++;
        }
      }
    T->zmin[k] = lo;
    T->zmax[k] = hi;
    T->valid[k] = n;
    /* the pairs whose first sample the tile owns (its last column and row
     * are the next tile's, but for the DEM's own last ones) */
    size_t x1 = t.col1 - (t.col1 + 1 < t.dem_width);
    size_t y1 = t.row1 - (t.row1 + 1 < t.dem_height);
    tt__app_step_add(&T->steps[k], win, t.col0 - c0, t.row0 - r0, x1 - c0,
                     y1 - r0, t.col1 - c0, t.row1 - r0);
  } else if (st == TT_OK && T->curve_pass) {
    /* a budget's first pass: the tile's curve, its valid samples */
    size_t cells = (t.col1 - t.col0 + 1) * (t.row1 - t.row0 + 1);
    size_t cap = (size_t)ceil(T->curve_per_cell * (double)cells) + 64;
    T->valid[k] = tt__app_tile_owned_valid(win, &t);
    st = tt_tile_curve(ctx, win, &t, &T->ro, cap, tt__app_curve_point,
                       &T->curves[k]);
    if (st == TT_OK && (T->curves[k].failed ||
                        !tt__app_curve_end(&T->curves[k]))) {
      tt_grid_destroy(win);
      tt_raster_info_destroy(info);
      fail(T, k, TT_ERR_NOMEM, "out of memory for its curve");
      return;
    }
  } else if (st == TT_OK) {
    st = T->decimate ? tt_tile_decimate(ctx, win, &t, &T->dec, &piece)
                     : tt_tile_run(ctx, win, &t, &T->ro, &piece);
  }
  tt_grid_destroy(win);
  if (st != TT_OK) {
    fail(T, k, st, tt_context_errmsg(ctx));
    tt_raster_info_destroy(info);
    tt_tin_destroy(piece);
    return;
  }
  pthread_mutex_lock(&T->lock);
  if (k == 0 && !T->info) {
    T->info = info;
    info = NULL;
  }
  T->pieces[k] = piece;
  T->done[k] = true;
  pthread_cond_broadcast(&T->cond);
  pthread_mutex_unlock(&T->lock);
  tt_raster_info_destroy(info);
}

static void *worker(void *arg)
{
  tiled *T = arg;
  tt_context *ctx = tt_context_create();
  tt__app_quiet_push(&T->r->msg);
  /* With more than one worker, each opens the DEM again for itself: a
   * GDAL dataset is for one thread at a time, and with a dataset each the
   * reads go in parallel -- with them the projection of a geographic
   * window's samples, which runs inside the read and is most of a tile's
   * time. The shared band under the mutex when the file cannot be opened
   * again (/vsistdin/). */
  GDALDatasetH own = T->nthreads > 1 ? GDALOpenEx(T->path, GDAL_OF_RASTER |
                                                  GDAL_OF_READONLY, NULL,
                                                  NULL, NULL)
                                     : NULL;
  /* under GDAL's input options, the worker's own view of its dataset,
   * from the arguments the main thread checked (dem_view.c) */
  GDALDatasetH view = NULL;
  if (own && T->r->view_args) {
    char why[TT_APP_MESSAGE_MAX];
    view = tt__app_view_open(own, T->r->view_args, why, sizeof why);
    if (!view) {
      GDALClose(own);
      own = NULL;
    }
  }
  GDALDatasetH reads = view ? view : own;
  GDALRasterBandH band = reads ? GDALGetRasterBand(reads,
                                                   GDALGetBandNumber(T->band))
                               : NULL;
  for (;;) {
    pthread_mutex_lock(&T->lock);
    while (!atomic_load(&T->stop) && T->next < T->ntiles &&
           T->next >= T->merged + 2 * (size_t)T->nthreads)
      pthread_cond_wait(&T->cond, &T->lock);
    size_t k = T->next;
    bool go = !atomic_load(&T->stop) && k < T->ntiles;
    if (go)
      T->next++;
    pthread_mutex_unlock(&T->lock);
    if (!go)
      break;
    if (!ctx) {
      fail(T, k, TT_ERR_NOMEM, "out of memory");
      break;
    }
    tt__app_tiled_run_tile(T, ctx, k, band);
  }
  if (view)
    GDALClose(view);
  if (own)
    GDALClose(own);
  CPLPopErrorHandler();
  tt_context_destroy(ctx);
  return NULL;
}

/* Tile k's piece into the stream, its rows to the GeoPackage (opened
 * before the first piece written: tile 0's raster facts give its CRS). A
 * budget pass whose counts pass the budget is not kept: its rows are
 * dropped at once and the rest of the pass only counts. A failure is the
 * run's, with the message in T->merge_msg. */
static tt_status stream_piece(tiled *T, size_t k)
{
  app_run *r = T->r;
  tt_app_tile_sink *sink = T->sink;
  tt_status st = TT_OK;
  if (T->write && !sink->out)
    st = sink->open(sink, T->info, T->ro.max_error);
  tt__stream_batch b;
  tt_tile t;
  tile_of(T, k, &t);
  if (st == TT_OK)
    st = tt__tin_stream_add(r->ctx, T->stream, T->pieces[k], &t, k, &b);
  size_t nv, nt;
  tt__tin_stream_counts(T->stream, &nv, &nt);
  if (st == TT_OK && T->write && (nv > T->max_v || nt > T->max_t)) {
    sink->discard(sink);
    T->write = false;
  }
  if (st == TT_OK && T->write)
    st = tt__gpkg_stream_batch(sink->out, &b);
  if (st != TT_OK) {
    snprintf(T->merge_msg, sizeof T->merge_msg, "%s",
             tt_context_errmsg(r->ctx));
    return st;
  }
  /* -max_memory: what grows with the TIN here, beside the tiles in
   * flight: the writer's R-tree blocks, leaf boxes and style values, the
   * stream's pending vertices (64 bytes each), outline table, components
   * (4 bytes a vertex) and batch */
  size_t bytes = tt__gpkg_stream_bytes(sink->out) +
                 tt__tin_stream_bytes(T->stream);
  if (T->max_memory && bytes + T->inflight_bytes > T->max_memory) {
    snprintf(T->merge_msg, sizeof T->merge_msg, "while merging tile %zu of "
             "%zu, at %zu vertices written and %zu waiting for their last "
             "tile: the writer's records take %zu MiB, with the tiles in "
             "flight (%zu MiB) more than the memory limit of %zu MiB "
             "(%s); nothing written", k + 1, T->ntiles, nv,
             tt__tin_stream_pending(T->stream), bytes >> 20,
             T->inflight_bytes >> 20, T->max_memory >> 20,
             T->job->mem_source);
    return TT_ERR_NOMEM;
  }
  return TT_OK;
}

tt_status tt__app_tiled_run_all(tiled *T, tt_tin_merger *merger)
{
  app_run *r = T->r;
  tt_status st = TT_OK;
  pthread_t *th = calloc((size_t)T->nthreads, sizeof *th);
  int started = 0;
  T->next = T->merged = 0;
  T->failed = T->ntiles;
  atomic_store(&T->stop, 0);
  if (!th)
    return tt__app_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_NOMEM, NULL,
                        "out of memory");
  for (int i = 0; i < T->nthreads; i++, started++)
    if (pthread_create(&th[i], NULL, worker, T) != 0)
      break;
  if (started == 0) {
    free(th);
    return tt__app_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_INTERNAL, NULL,
                        "cannot start a thread");
  }
  for (size_t k = 0; k < T->ntiles; k++) {
    pthread_mutex_lock(&T->lock);
    while (!T->done[k] && T->failed == T->ntiles) {
      struct timespec ts;
      clock_gettime(CLOCK_REALTIME, &ts);
      ts.tv_nsec += 100000000L;
      if (ts.tv_nsec >= 1000000000L) {
        ts.tv_sec++;
        ts.tv_nsec -= 1000000000L;
      }
      pthread_cond_timedwait(&T->cond, &T->lock, &ts);
      if (!T->done[k] && !tt__app_continue(r, r->prog.lo)) {
        atomic_store(&T->stop, 1);
        break;
      }
    }
    bool ok = T->done[k];
    int nwarn = T->ntile0_warn;
    T->ntile0_warn = 0;
    pthread_mutex_unlock(&T->lock);
    for (int i = 0; i < nwarn; i++)
      tt__app_warn(&r->msg, "%s", T->tile0_warn[i]);
    if (!ok) {
      st = TT_ERR_INTERRUPTED;
      break;
    }
    if (T->stream && T->pieces[k]) {
      st = stream_piece(T, k);
      tt_tin_destroy(T->pieces[k]);
      T->pieces[k] = NULL;
      if (st != TT_OK) {
        atomic_store(&T->stop, 1);
        break;
      }
    } else if (merger && T->pieces[k]) {
      tt_tile t;
      tile_of(T, k, &t);
      st = tt_tin_merger_add(r->ctx, merger, T->pieces[k], &t);
      tt_tin_destroy(T->pieces[k]);
      T->pieces[k] = NULL;
      if (st != TT_OK) {
        atomic_store(&T->stop, 1);
        break;
      }
      /* -max_memory: the merged TIN grows with its vertices, beside the
       * tiles in flight */
      size_t nv, ntri, bytes;
      tt_tin_merger_size(merger, &nv, &ntri, &bytes);
      if (T->max_memory && bytes + T->inflight_bytes > T->max_memory) {
        atomic_store(&T->stop, 1);
        st = TT_ERR_NOMEM;
        snprintf(T->merge_msg, sizeof T->merge_msg, "while merging tile %zu "
                 "of %zu, at %zu vertices and %zu triangles: the TIN's "
                 "records take %zu MiB, with the tiles in flight (%zu MiB) "
                 "more than the memory limit of %zu MiB (%s); nothing "
                 "written", k + 1, T->ntiles, nv, ntri, bytes >> 20,
                 T->inflight_bytes >> 20, T->max_memory >> 20,
                 T->job->mem_source);
        break;
      }
    }
    pthread_mutex_lock(&T->lock);
    T->merged = k + 1;
    pthread_cond_broadcast(&T->cond);
    pthread_mutex_unlock(&T->lock);
    tt__app_phase_fn((double)(k + 1) / (double)T->ntiles, "tiles",
                     &r->prog);
  }
  pthread_mutex_lock(&T->lock);
  atomic_store(&T->stop, 1);
  pthread_cond_broadcast(&T->cond);
  pthread_mutex_unlock(&T->lock);
  for (int i = 0; i < started; i++)
    pthread_join(th[i], NULL);
  free(th);
  for (size_t k = 0; k < T->ntiles; k++) {
    tt_tin_destroy(T->pieces[k]);
    T->pieces[k] = NULL;
  }
  /* A failure of this thread's (the stream's write: a full disk; the
   * merge) stopped the workers: their tiles end "interrupted", which is
   * its consequence, not the run's failure. */
  bool own = st != TT_OK && st != TT_ERR_INTERRUPTED;
  bool worker_failed = T->failed < T->ntiles &&
                       !(own && T->fail_status == TT_ERR_INTERRUPTED);
  if (st == TT_ERR_NOMEM && T->merge_msg[0])
    return tt__app_fail(r, TT_APP_EXIT_FAILURE, st, T->path, "%s",
                        T->merge_msg);
  if (own && T->stream && T->merge_msg[0] && !worker_failed) {
    /* the writer's message may name the output first (by its temporary
     * name): named once */
    char named[TT_APP_MESSAGE_MAX];
    const char *m = tt_output_rename_in_text(T->merge_msg, named,
                                             sizeof named)
                        ? named : T->merge_msg;
    const char *out = r->s->output;
    size_t n = strlen(out);
    if (strncmp(m, out, n) == 0 && m[n] == ':' && m[n + 1] == ' ')
      m += n + 2;
    return tt__app_fail(r, TT_APP_EXIT_FAILURE, st, out, "%s", m);
  }
  if (worker_failed && T->fail_status == TT_ERR_INTERRUPTED)
    return tt__app_fail_tt(r, TT_ERR_INTERRUPTED, r->s->output);
  if (worker_failed) {
    tt_tile t;
    tile_of(T, T->failed, &t);
    int code = T->fail_status == TT_ERR_ARG ? TT_APP_EXIT_USAGE
                                            : TT_APP_EXIT_FAILURE;
    return tt__app_fail(r, code, T->fail_status, T->path, "tile at column "
                        "%zu, row %zu: %s", t.col0, t.row0, T->fail_msg);
  }
  if (st == TT_ERR_INTERRUPTED)
    return tt__app_fail_tt(r, st, r->s->output);
  if (st != TT_OK)
    return tt__app_fail_tt(r, st, T->path);
  return TT_OK;
}
