/*
 * simplify.h -- what the files of `terratin simplify` share (internal):
 * simplify.c (the run: the options, the method, the output, the report),
 * ogr_output.c (the output's checks before any work: the OGR dry run, the
 * creation options, a database output), tiled.c (the tiled path: tiles
 * read, refined or decimated on the workers, merged), tiled_budget.c (a
 * budget in tiles: the curves and the bound), tiled_tiles.c (a tile's
 * curve and its samples) and tiled_stream.c (a tiled run's GeoPackage
 * written as the tiles merge).
 */
#ifndef TT_APP_SIMPLIFY_H
#define TT_APP_SIMPLIFY_H

#include "app.h"

#include <ogr_api.h>

#include <stdbool.h>

/* ogr_output.c: the dry run of the OGR writer on a two-triangle TIN in
 * /vsimem/ with drv, -layers, the creation options dsco and the writer's
 * options wopts, after
 * the DEM src is opened and before it is read: 1 when the driver holds the
 * layers (or cannot be judged), else 0 with the refusal recorded (a usage
 * error naming the -layers or OUTPUT form that works). */
int tt__app_check_ogr_output(app_run *r, GDALDriverH drv, GDALDatasetH src,
                             char **dsco, char **wopts);
/* The dataset creation options of an OGR output: -dsco, and the defaults
 * terratin adds (GPX: GPX_USE_EXTENSIONS=YES, or it keeps no attribute).
 * The caller frees the list with CSLDestroy(). */
char **tt__app_output_dsco(const char *drvname, const char *const *dsco);
/* The driver of a database output (-of PostgreSQL, or OUTPUT "PG:..."; a
 * driver that writes no file and has a connection prefix), else NULL. */
GDALDriverH tt__app_database_driver(app_run *r);
/* Opens the database OUTPUT for writing and checks it before any work:
 * transactions, layer creation, and (without -overwrite) none of the
 * layers to write there already (in the schema of -lco SCHEMA). shown
 * names it in messages. NULL with the failure recorded. */
GDALDatasetH tt__app_database_open(app_run *r, GDALDriverH drv,
                                   const char *shown);

/* simplify.c: the run_parameters fields of a run from its report so far
 * (created, and start_name of 48 bytes, hold strings they point to); allf
 * has room for TT__APP_RUN_FIELDS. Returns the count used. */
#define TT__APP_RUN_FIELDS 48
size_t tt__app_simplify_fields(app_run *r, const app_simplify_report *rep,
                               const tt_refine_options *ro,
                               const tt_raster_info *info,
                               const char *created, char *start_name,
                               tt_run_field *allf);

void tt__app_print_simplify_json(app_run *r, const app_simplify_report *p);
void tt__app_print_simplify_summary(app_run *r,
                                    const app_simplify_report *p);

/* tiled.c: the DEM of band read and refined in tiles of tile_size cells
 * on the workers, merged into *out_tin; ro's max_error < 0 asks for the
 * default bound (then set, and *default_error); ro's max_points,
 * max_triangles or percent, a budget of the whole DEM, is turned into a
 * bound (tiled_budget.c; ro->max_error is set to it, *out_passes says how
 * many runs at a bound it took). With dopt (else NULL) the
 * tiles are decimated with its options, its max_error that of ro. The
 * failure is recorded. */
tt_status tt__app_simplify_tiled(app_run *r, GDALRasterBandH band,
                                 const char *path, size_t tile_size,
                                 tt_refine_options *ro,
                                 tt_decimate_options *dopt,
                                 int *default_error,
                                 tt_tin **out_tin, tt_raster_info **out_info,
                                 size_t *out_valid, double *out_zmin,
                                 double *out_zmax, size_t *out_tiles,
                                 int *out_threads, int *out_passes);
/* tiled_budget.c: a tile's error-against-count curve, thinned (the points
 * where the error reaches a new low, one every 2 % of vertices, and the
 * last), and the bound that makes the tiles' counts meet a budget. */
typedef struct app_curve {
  uint32_t *pts;
  double *err;
  size_t n, cap;
  double low;                /* the lowest error seen */
  size_t pending_pts;        /* a low skipped by the spacing */
  double pending_err;
  bool has_pending;
  bool failed;               /* out of memory while recording */
} app_curve;
/* Adds one call of tt_tile_curve's callback; ends the curve. False when
 * out of memory. */
bool tt__app_curve_add(app_curve *c, size_t vertices, double err);
bool tt__app_curve_end(app_curve *c);
/* tiled_tiles.c: tt_tile_curve's callback recording into an app_curve
 * (arg); the valid samples tile t counts in its window win (less the
 * margins and its shared right column and bottom row, as tt_tile_run's
 * pieces). */
void tt__app_curve_point(void *arg, size_t vertices, double max_error);
size_t tt__app_tile_owned_valid(const tt_grid *win, const tt_tile *t);
void tt__app_curve_free(app_curve *c);
/* The smallest error of any of the n curves (or 0 when above < 0)
 * strictly between above and below at which the tiles' counts summed are
 * at most target (else the largest of them; NaN when there is none), and
 * that sum. False when out of memory. */
bool tt__app_curves_bound(const app_curve *c, size_t n, size_t target,
                          double above, double below, double *out_bound,
                          size_t *out_estimate);
/* tiled_budget.c: the passes of a budget after the curve pass. run: every
 * tile at bound e, merged or streamed (a streamed pass may drop its rows
 * once its counts pass max_v vertices or max_t triangles), the TIN's
 * counts; drop: the last pass is not kept. */
typedef struct app_budget_pass {
  tt_status (*run)(void *arg, double e, size_t max_v, size_t max_t,
                   size_t *out_nv, size_t *out_nt);
  void (*drop)(void *arg);
  void *arg;
} app_budget_pass;
/* Runs passes at the bounds the n curves give for ro's budget (valid: the
 * DEM's valid samples, for -percent; ro->max_error >= 0: the smallest
 * bound) until one fits the budget and is kept (docs/scale.md), or
 * refuses the budget (exit 2); *out_bound is the kept pass's bound,
 * *out_passes the passes run. The failure is recorded. */
tt_status tt__app_budget_passes(app_run *r, const char *path,
                                const app_curve *curves, size_t n,
                                size_t valid, const tt_refine_options *ro,
                                const app_budget_pass *p, double *out_bound,
                                int *out_passes);
/* A tiled run's GeoPackage built as the tiles merge (tiled_stream.c,
 * docs/scale.md): with r->sink set, tt__app_simplify_tiled() calls open
 * before merging the first piece (tile 0's raster facts, the bound), then
 * hands every piece's rows to out as it is merged, and returns no TIN but
 * the whole TIN's summary and height range here; the caller finishes and
 * closes out. discard drops what out wrote (a budget pass not kept) and
 * closes it; the next open starts the file again. */
typedef struct tt_app_tile_sink {
  tt_status (*open)(struct tt_app_tile_sink *sink,
                    const tt_raster_info *info, double max_error);
  void (*discard)(struct tt_app_tile_sink *sink);
  struct tt__gpkg_stream *out;
  tt_tin_summary sum;
  double zmin, zmax;
} tt_app_tile_sink;
/* tiled_stream.c: the sink of simplify's streamed GeoPackage. */
typedef struct tt_app_stream {
  tt_app_tile_sink sink; /* first: the sink tiled.c calls */
  app_run *r;
  tt_output *outp;
  GDALDriverH drv;
  char **dsco, ***wopts;
  OGRSpatialReferenceH *srs;
  app_simplify_report *rep;
  tt_refine_options *ro;
} tt_app_stream;
/* Whether a tiled run into drvname streams (GPKG files, unless
 * TERRATIN_TILE_STREAM=NO). */
int tt__app_stream_wanted(const char *drvname, int database, int mesh);
void tt__app_stream_init(tt_app_stream *so, app_run *r, tt_output *outp,
                         GDALDriverH drv, char **dsco, char ***wopts,
                         OGRSpatialReferenceH *srs,
                         app_simplify_report *rep, tt_refine_options *ro);
/* After the last tile: the R-trees, extents, counts, the final
 * run_parameters (fields) and styles; closes the writer. */
tt_status tt__app_stream_finish(tt_app_stream *so, const tt_run_field *fields,
                                size_t nfields);
/* Closes the writer (an unfinished write undone; the caller's tt_output
 * removes the file). */
void tt__app_stream_close(tt_app_stream *so);
/* What tiles of N cells of a width x height DEM on threads workers hold
 * at most (tiled.c); ground: the DEM is measured on ground points
 * (tt__app_ground_points). */
size_t tt__app_tile_bytes(size_t N, size_t width, size_t height,
                          int threads, int ground);
/* Whether band's DEM gets ground points (geographic or Web Mercator). */
int tt__app_ground_points(GDALRasterBandH band);

#endif /* TT_APP_SIMPLIFY_H */
