/*
 * tiled.c -- `terratin simplify -tile_size N`, and a DEM whose heights do
 * not fit the memory limit: the DEM read and refined tile by tile
 * (src/tile/), the pieces merged into one TIN as they finish.
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
 * the DEM. With r->sink (a GeoPackage file, tiled_stream.c: every method,
 * bound, budget and frame) the pieces go through a tt__tin_stream and
 * their rows are written as each merges; otherwise a tt_tin_merger holds
 * the merged TIN (its records grow with its vertices, as in any run) for
 * the caller to write.
 * The first failure in tile order, or an interruption, stops the workers
 * at their next check (refinement polls the stop flag every 256
 * insertions).
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
 * -max_error the bound is 0.5 % of the height range, as untiled (one more
 * pass over the tiles finds the range first).
 *
 * GDAL's block cache (5 % of the memory by default) would keep every
 * block read, the whole DEM in the end: unless GDAL_CACHEMAX is set, it
 * is held for the run to the blocks of one row of tiles and its margins,
 * (N + 2 block heights) x width samples (a tile's margin lines are read
 * again by its neighbours), and restored afterwards. On the 8193^2 fractal
 * in tiles of 1024 this took the peak from 344 to 130 MB.
 */
#include "simplify.h"
#include "gdal/gpkg/gpkg_stream.h"
#include "tile/tile.h"

#include <cpl_conv.h>
#include <cpl_error.h>
#include <cpl_string.h>

#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

typedef struct tiled {
  app_run *r;
  GDALRasterBandH band;
  const char *path;
  char **ropts;             /* the read options but WINDOW */
  tt_refine_options ro;     /* per tile: one thread, stop flag polled */
  tt_decimate_options dec;  /* the same for decimation, when decimate */
  bool decimate;
  size_t W, H, N, ntx, nty, ntiles;
  int nthreads;
  bool minmax_only;         /* the pre-pass for the default bound */
  bool curve_pass;          /* the pre-pass of a budget (tiled_budget.c) */
  app_curve *curves;        /* per tile (curve pass) */
  size_t curve_cap;         /* insertions a curve may record, per cell */
  double curve_per_cell;
  pthread_mutex_t lock, gdal;
  pthread_cond_t cond;
  size_t next, merged;      /* the next tile to take, the tiles merged */
  tt_tin **pieces;
  bool *done;
  double *zmin, *zmax;      /* per tile (pre-pass) */
  size_t *valid;            /* per tile: valid samples of its window */
  atomic_int stop;
  size_t failed;            /* the first tile that failed (ntiles: none) */
  tt_status fail_status;
  char fail_msg[TT_APP_MESSAGE_MAX];
  tt_raster_info *info;     /* from tile 0 */
  tt_tin_merger *merger;    /* tile 0's window gives it the area function */
  size_t max_memory;        /* -max_memory, 0: not given */
  size_t inflight_bytes;    /* what the tiles in flight may hold */
  char merge_msg[TT_APP_MESSAGE_MAX]; /* the main thread's failure */
  /* a streamed GeoPackage (r->sink, tiled_stream.c): the pieces merged
   * by the stream and their rows written at once, instead of a merger */
  tt__tin_stream *stream;
  tt_app_tile_sink *sink;
  bool write;               /* this pass's rows are written (stream_all) */
  size_t max_v, max_t;      /* a budget pass: the most vertices and
                               triangles a kept TIN may have */
  double gt[6];             /* the DEM's geotransform */
  tt_tin **out_tin;         /* the merged TIN (not streamed) */
} tiled;

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

static int stop_check(double complete, const char *message, void *arg)
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

/* One tile: read (from own, a worker's own dataset's band, or the shared
 * band under the mutex when own is NULL), then refine (or measure the
 * range). */
static void run_tile(tiled *T, tt_context *ctx, size_t k,
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
  /* merging pieces from files reads the DEM for tile 0's raster info only */
  if (!(hook->load && k > 0) && own) {
    st = tt_gdal_read_grid(ctx, own, ro, NULL, NULL, &win, &info);
  } else if (!(hook->load && k > 0)) {
    pthread_mutex_lock(&T->gdal);
    st = tt_gdal_read_grid(ctx, T->band, ro, NULL, NULL, &win, &info);
    pthread_mutex_unlock(&T->gdal);
  }
  CSLDestroy(ro);
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
  CPLPushErrorHandler(CPLQuietErrorHandler);
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
  GDALRasterBandH band = own ? GDALGetRasterBand(own,
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
    run_tile(T, ctx, k, band);
  }
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
             "(-max_memory); nothing written", k + 1, T->ntiles, nv,
             tt__tin_stream_pending(T->stream), bytes >> 20,
             T->inflight_bytes >> 20, T->max_memory >> 20);
    return TT_ERR_NOMEM;
  }
  return TT_OK;
}

/* Runs every tile on the workers; the main thread takes the results in
 * tile order (merging them unless merger is NULL) and polls for an
 * interruption. */
static tt_status run_all(tiled *T, tt_tin_merger *merger)
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
    pthread_mutex_unlock(&T->lock);
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
                 "more than the memory limit of %zu MiB (-max_memory); "
                 "nothing written", k + 1, T->ntiles, nv, ntri, bytes >> 20,
                 T->inflight_bytes >> 20, T->max_memory >> 20);
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
  if (st == TT_ERR_NOMEM && T->merge_msg[0])
    return tt__app_fail(r, TT_APP_EXIT_FAILURE, st, T->path, "%s",
                        T->merge_msg);
  if (st != TT_OK && st != TT_ERR_INTERRUPTED && T->stream &&
      T->merge_msg[0] && T->failed == T->ntiles)
    return tt__app_fail(r, TT_APP_EXIT_FAILURE, st, r->s->output, "%s",
                        T->merge_msg);
  if (T->failed < T->ntiles && T->fail_status == TT_ERR_INTERRUPTED)
    return tt__app_fail_tt(r, TT_ERR_INTERRUPTED, r->s->output);
  if (T->failed < T->ntiles) {
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
  st = run_all(T, merger);
  if (st == TT_OK) {
    st = tt_tin_merger_finish(T->r->ctx, merger, out_tin);
    if (st != TT_OK)
      tt__app_fail_tt(T->r, st, T->path);
  }
  T->merger = NULL;
  tt_tin_merger_destroy(merger);
  return st;
}

/* Every tile run and streamed (r->sink): the rows written as each piece
 * merges (unless a budget pass drops them), the summary in the sink. */
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
  st = run_all(T, NULL);
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
  st = run_all(T, NULL);
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

tt_status tt__app_simplify_tiled(app_run *r, GDALRasterBandH band,
                                 const char *path, size_t tile_size,
                                 tt_refine_options *ro,
                                 tt_decimate_options *dopt,
                                 int *default_error,
                                 tt_tin **out_tin, tt_raster_info **out_info,
                                 size_t *out_valid, double *out_zmin,
                                 double *out_zmax, size_t *out_tiles,
                                 int *out_threads, int *out_passes)
{
  const tt_app_settings *s = r->s;
  tiled T;
  memset(&T, 0, sizeof T);
  tt_status st = TT_OK;
  *out_tin = NULL;
  *out_passes = 0;
  *out_info = NULL;
  T.r = r;
  T.band = band;
  T.path = path;
  T.W = (size_t)GDALGetRasterBandXSize(band);
  T.H = (size_t)GDALGetRasterBandYSize(band);
  T.N = tile_size;
  if (T.W < 2 || T.H < 2)
    return tt__app_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_DATA, path, "raster "
                        "is %zu x %zu pixels: at least 2 x 2 are needed to "
                        "make a triangle", T.W, T.H);
  T.ntx = (T.W - 2) / T.N + 1;
  T.nty = (T.H - 2) / T.N + 1;
  T.ntiles = T.ntx * T.nty;
  T.nthreads = ro->threads > 0 ? ro->threads
                               : (int)sysconf(_SC_NPROCESSORS_ONLN);
  if (T.nthreads < 1)
    T.nthreads = 1;
  if ((size_t)T.nthreads > T.ntiles)
    T.nthreads = (int)T.ntiles;
  *out_tiles = T.ntiles;
  *out_threads = T.nthreads;
  if (s->srcnodata)
    T.ropts = CSLSetNameValue(T.ropts, "SRCNODATA", s->srcnodata);
  if (s->z_factor != 1.0 || s->z_factor_set) {
    char num[40];
    tt__app_format_double(num, sizeof num, s->z_factor);
    T.ropts = CSLSetNameValue(T.ropts, "Z_FACTOR", num);
  }
  if (s->z_unit)
    T.ropts = CSLSetNameValue(T.ropts, "Z_UNIT", s->z_unit);
  if (s->work_srs)
    T.ropts = CSLSetNameValue(T.ropts, "WORK_SRS", s->work_srs);
  T.max_memory = s->max_memory;
  T.inflight_bytes = tt__app_tile_bytes(T.N, T.W, T.H, T.nthreads,
                                        tt__app_ground_points(band));
  T.ro = *ro;
  T.ro.threads = 1;
  T.ro.max_memory = 0; /* bounded by the tiles in flight (simplify.c) */
  T.ro.progress = stop_check;
  T.ro.progress_arg = &T;
  if (dopt) {
    T.decimate = true;
    T.dec = *dopt;
    T.dec.max_error = ro->max_error;
    T.dec.max_points = T.dec.max_triangles = 0; /* a budget: a bound */
    T.dec.percent = 0;
    T.dec.threads = 1;
    T.dec.progress = stop_check;
    T.dec.progress_arg = &T;
  }
  T.pieces = calloc(T.ntiles, sizeof *T.pieces);
  T.done = calloc(T.ntiles, sizeof *T.done);
  T.zmin = calloc(T.ntiles, sizeof *T.zmin);
  T.zmax = calloc(T.ntiles, sizeof *T.zmax);
  T.valid = calloc(T.ntiles, sizeof *T.valid);
  GIntBig old_cache = 0;
  int cache_set = 0;
  if (!CPLGetConfigOption("GDAL_CACHEMAX", NULL)) {
    int bw = 0, bh = 0;
    GDALGetBlockSize(band, &bw, &bh);
    if (bh < 1)
      bh = 1;
    GIntBig row = (GIntBig)(T.N + 2 * (size_t)bh) * (GIntBig)T.W *
                  (GIntBig)(GDALGetDataTypeSizeBytes(
                                GDALGetRasterDataType(band)) + 1);
    if (row < ((GIntBig)16 << 20))
      row = (GIntBig)16 << 20;
    old_cache = GDALGetCacheMax64();
    if (row < old_cache) {
      GDALSetCacheMax64(row);
      cache_set = 1;
    }
  }
  pthread_mutex_init(&T.lock, NULL);
  pthread_mutex_init(&T.gdal, NULL);
  pthread_cond_init(&T.cond, NULL);
  if (!T.pieces || !T.done || !T.zmin || !T.zmax || !T.valid) {
    st = tt__app_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_NOMEM, NULL,
                      "out of memory for %zu tiles", T.ntiles);
    goto done;
  }

  /* The range of heights: the default bound needs it, the report too. */
  double zmin = INFINITY, zmax = -INFINITY;
  bool budget = ro->max_points || ro->max_triangles || ro->percent > 0;
  T.ro.max_points = T.ro.max_triangles = 0;
  T.ro.percent = 0;
  if (ro->max_error < 0 && !budget) {
    T.minmax_only = true;
    app_phase keep = r->prog;
    tt__app_phase_set(&r->prog, keep.lo, keep.lo + 0.1 * (keep.hi - keep.lo));
    st = run_all(&T, NULL);
    r->prog = keep;
    tt__app_phase_set(&r->prog, keep.lo + 0.1 * (keep.hi - keep.lo), keep.hi);
    if (st != TT_OK)
      goto done;
    size_t valid = 0;
    for (size_t k = 0; k < T.ntiles; k++) {
      zmin = T.zmin[k] < zmin ? T.zmin[k] : zmin;
      zmax = T.zmax[k] > zmax ? T.zmax[k] : zmax;
      valid += T.valid[k];
      T.done[k] = false;
    }
    if (valid == 0) {
      st = tt__app_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_DATA, path,
                        "band %d has no valid samples (all nodata)", s->band);
      goto done;
    }
    ro->max_error = 0.005 * (zmax - zmin);
    T.ro.max_error = ro->max_error;
    T.dec.max_error = ro->max_error;
    if (dopt)
      dopt->max_error = ro->max_error;
    *default_error = 1;
    T.minmax_only = false;
  }

  double gt[6] = {0, 1, 0, 0, 0, 1};
  GDALDatasetH ds = GDALGetBandDataset(band);
  if (ds && GDALGetGeoTransform(ds, gt) != CE_None) {
    const double unit_gt[6] = {0, 1, 0, 0, 0, 1};
    memcpy(gt, unit_gt, sizeof gt);
  }
  if (tt__app_tiles_hook.save) {
    /* `terratin tiles run`: this one tile, handed to the hook */
    size_t k = tt__app_tiles_hook.tile;
    if (k >= T.ntiles) {
      st = tt__app_fail(r, TT_APP_EXIT_USAGE, TT_ERR_ARG, path, "tile %zu "
                        "does not exist: the plan has %zu tiles", k, T.ntiles);
      goto done;
    }
    T.failed = T.ntiles;
    run_tile(&T, r->ctx, k, NULL);
    if (T.failed < T.ntiles) {
      st = tt__app_fail(r, TT_APP_EXIT_FAILURE, T.fail_status, path,
                        "tile %zu: %s", k, T.fail_msg);
      goto done;
    }
    st = tt__app_tiles_hook.save(tt__app_tiles_hook.arg, r, k, T.pieces[k]);
    goto done;
  }
  /* streamed (r->sink, tiled_stream.c): the rows go out as the pieces
   * merge, no TIN is made */
  T.sink = r->sink;
  T.max_v = T.max_t = SIZE_MAX;
  memcpy(T.gt, gt, sizeof gt);
  T.out_tin = out_tin;
  st = budget   ? budget_run(&T, ro, out_passes)
       : T.sink ? stream_all(&T, gt)
                : merge_all(&T, gt, out_tin);
  if (st != TT_OK)
    goto done;
  tt_tin_summary sum;
  if (T.sink)
    sum = T.sink->sum;
  else
    tt_tin_get_summary(*out_tin, &sum);
  if (T.info) {
    T.info->width = T.W;
    T.info->height = T.H;
    T.info->valid_samples = sum.valid_samples;
    T.info->nodata_samples = T.W * T.H - sum.valid_samples;
  }
  if (!(zmin <= zmax) && T.sink) {
    zmin = r->sink->zmin;
    zmax = r->sink->zmax;
  } else if (!(zmin <= zmax)) {
    /* the range of the vertices' heights (the report's; the bound was
     * given) */
    for (size_t v = 0; v < sum.vertices; v++) {
      tt_vertex_info vi;
      tt_tin_vertex(*out_tin, v, &vi);
      zmin = vi.z < zmin ? vi.z : zmin;
      zmax = vi.z > zmax ? vi.z : zmax;
    }
  }
  *out_valid = sum.valid_samples;
  *out_zmin = zmin;
  *out_zmax = zmax;
  *out_info = T.info;
  T.info = NULL;
done:
  if (cache_set) {
    GDALFlushRasterCache(band);
    GDALSetCacheMax64(old_cache);
  }
  if (st != TT_OK) {
    tt_tin_destroy(*out_tin);
    *out_tin = NULL;
  }
  if (T.curves)
    for (size_t k = 0; k < T.ntiles; k++)
      tt__app_curve_free(&T.curves[k]);
  free(T.curves);
  tt__tin_stream_destroy(T.stream);
  if (tt__app_tiles_hook.save && T.pieces && tt__app_tiles_hook.tile < T.ntiles)
    tt_tin_destroy(T.pieces[tt__app_tiles_hook.tile]);
  tt_raster_info_destroy(T.info);
  CSLDestroy(T.ropts);
  free(T.pieces);
  free(T.done);
  free(T.zmin);
  free(T.zmax);
  free(T.valid);
  pthread_mutex_destroy(&T.lock);
  pthread_mutex_destroy(&T.gdal);
  pthread_cond_destroy(&T.cond);
  return st;
}
