/*
 * tiled.h -- apps/simplify/, the simplify command: what the files of its
 * tiled path share (internal): the state of a tiled run (tiled), set up
 * and run pass by pass by tiled.c, its tiles run on the worker threads
 * and taken in tile order by tiled_workers.c.
 */
#ifndef TT_APP_TILED_H
#define TT_APP_TILED_H

#include "simplify.h"
#include "tile/tile.h"

#include <pthread.h>
#include <stdatomic.h>
#include <stdbool.h>

/* A tiled run: set up by tiled.c from the job, shared with the worker
 * threads (tiled_workers.c). */
typedef struct tiled {
  app_simplify_job *job;    /* what to run, and where its results go */
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
  app_step *steps;          /* per tile (pre-pass): its pairs' step */
  size_t *valid;            /* per tile: valid samples of its window */
  size_t *filled, *voids;   /* per tile: the samples it owns that
                               -fill_nodata filled, the voids they start */
  atomic_int stop;
  size_t failed;            /* the first tile that failed (ntiles: none) */
  tt_status fail_status;
  char fail_msg[TT_APP_MESSAGE_MAX];
  tt_raster_info *info;     /* from tile 0 */
  tt_tin_merger *merger;    /* tile 0's window gives it the area function */
  size_t max_memory;        /* -max_memory, 0: not given */
  size_t inflight_bytes;    /* what the tiles in flight may hold */
  char merge_msg[TT_APP_MESSAGE_MAX]; /* the main thread's failure */
  /* a streamed GeoPackage (the job's sink, tiled_stream.c): the pieces
   * merged by the stream and their rows written at once, not a merger */
  tt__tin_stream *stream;
  tt_app_tile_sink *sink;
  bool write;               /* this pass's rows are written (stream_all) */
  size_t max_v, max_t;      /* a budget pass: the most vertices and
                               triangles a kept TIN may have */
  double gt[6];             /* the DEM's geotransform */
  tt_tin **out_tin;         /* the merged TIN (not streamed) */
  double range_min, range_max; /* the heights, when the pre-pass ran */
  /* the warnings of tile 0's read (the DEM's own: no CRS, a map in
   * feet), taken on its worker and said once by the main thread; the
   * other tiles' reads would repeat them */
  char tile0_warn[4][TT_APP_MESSAGE_MAX];
  int ntile0_warn;
  bool tile0_read;          /* a pass has read tile 0: not again */
  GIntBig old_cache;        /* GDAL's block cache, to restore */
  int cache_set;            /* ... when it was held for the run */
} tiled;

/* tiled_workers.c: the progress callback of a tile's run (arg: the
 * tiled), 0 once the run is to stop. */
int tt__app_tiled_stop_check(double complete, const char *message,
                             void *arg);
/* Tile k on ctx: read (from own, a worker's own dataset's band, or the
 * shared band under the mutex when own is NULL), then refined, decimated,
 * measured (the pre-pass) or its curve recorded; T->pieces[k] and
 * T->done[k] set, or the failure kept in T (failed, fail_status,
 * fail_msg). */
void tt__app_tiled_run_tile(tiled *T, tt_context *ctx, size_t k,
                            GDALRasterBandH own);
/* One pass: every tile run on the workers, the results taken in tile
 * order by the calling thread (merged into merger unless it is NULL,
 * streamed with T->stream), polling for an interruption. The failure
 * is recorded. */
tt_status tt__app_tiled_run_all(tiled *T, tt_tin_merger *merger);

#endif /* TT_APP_TILED_H */
