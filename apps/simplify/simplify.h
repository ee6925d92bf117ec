/*
 * simplify.h -- what the files of apps/simplify/, the simplify command,
 * share (internal). A run is one pipeline over one job description
 * (app_simplify_job): the settings read into it, the output chosen and
 * planned, the DEM opened, the tiling chosen, the TIN made whole or in
 * tiles, written, reported.
 *
 *   simplify.c      tt__app_simplify: the pipeline, the input, the
 *                   tiling's choice, the whole run and the tiled run
 *   job.c           the job from the settings: the method's options, the
 *                   memory, the threads, the default bound set
 *   default_bound.c the default bound: the DEM's mean step
 *   output.c        the output's choice (OGR file, database, mesh file,
 *                   streamed GeoPackage), its plan and writer options
 *   ogr_output.c    the OGR output's checks before any work (the dry run,
 *                   the creation options, a database output)
 *   write.c         the write of the TIN into the output, and its commit
 *   run_fields.c    the run_parameters layer's fields of a run
 *   breaklines.c    -breaklines: lines made chains of samples, simplified,
 *                   the engine's constrained segments
 *   tiled.c         the tiled path: the passes over the tiles, merged
 *   tiled_workers.c the tiles read and run on worker threads (tiled.h)
 *   tiled_budget.c  a budget in tiles: the curves and the bound
 *   tiled_tiles.c   a tile's curve, its samples, the tiles' memory
 *   tiled_stream.c  a tiled run's GeoPackage written as the tiles merge
 *   estimate.c      what a bound will make, from a sample of the DEM
 */
#ifndef TT_APP_SIMPLIFY_H
#define TT_APP_SIMPLIFY_H

#include "app.h"

#include <ogr_api.h>

#include <stdbool.h>

/* A tiled run's GeoPackage built as the tiles merge (tiled_stream.c,
 * docs/scale.md): with the job's output streamed, tt__app_simplify_tiled()
 * calls open before merging the first piece (tile 0's raster facts, the
 * bound), then hands every piece's rows to out as it is merged, and
 * returns no TIN but the whole TIN's summary and height range here; the
 * write finishes and closes out. discard drops what out wrote (a budget
 * pass not kept) and closes it; the next open starts the file again. */
typedef struct tt_app_tile_sink {
  tt_status (*open)(struct tt_app_tile_sink *sink,
                    const tt_raster_info *info, double max_error);
  void (*discard)(struct tt_app_tile_sink *sink);
  struct tt__gpkg_stream *out;
  tt_tin_summary sum;
  double zmin, zmax;
} tt_app_tile_sink;

typedef struct app_simplify_job app_simplify_job;
/* tiled_stream.c: the sink of simplify's streamed GeoPackage. */
typedef struct tt_app_stream {
  tt_app_tile_sink sink; /* first: the sink tiled.c calls */
  app_simplify_job *job;
} tt_app_stream;

/* Where the TIN goes (output.c). */
typedef enum app_output_kind {
  APP_OUTPUT_FILE,     /* an OGR dataset in a file: written under
                          tt_output's temporary name, then committed */
  APP_OUTPUT_DATABASE, /* a datasource that is no file (PG:...), opened
                          before the work, written in one transaction */
  APP_OUTPUT_MESH,     /* a mesh or survey file (2DM, PLY, OBJ, LandXML)
                          written by tt_mesh_write() */
  APP_OUTPUT_STREAM    /* a tiled run's GeoPackage file, its rows written
                          as the tiles merge (tiled_stream.c) */
} app_output_kind;

/* One run of simplify, from the settings to the report: what it reads,
 * how it simplifies, where it writes, and what it made. The pipeline
 * (simplify.c) fills it step by step; tt__app_job_free() releases what it
 * holds. */
struct app_simplify_job {
  app_run *r;
  const tt_app_settings *s;
  /* the method (job.c): the options of the whole run for either method,
   * from the settings; a tiled run makes each tile's from them */
  int decimate;               /* -method decimate */
  tt_refine_options ro;       /* limits, criterion, optimiser, repair,
                                 threads, memory limit, progress */
  tt_decimate_options dopt;   /* the same, and -start, -importance,
                                 -selection, -onepass, -hole */
  size_t mem_limit;           /* -max_memory, else what the system allows */
  const char *mem_source;     /* what set mem_limit, for messages */
  int workers;                /* the threads of a tiled run (>= 1) */
  /* the input (simplify.c): s->input's band s->band */
  GDALDatasetH src;           /* open until the DEM is read */
  GDALRasterBandH band;
  size_t width, height;
  /* the tiling (simplify.c): 0 for a whole run, else the tiles' size */
  size_t tile_size;
  int ground;                 /* the DEM is measured on ground points */
  /* the output (output.c) */
  app_output_kind kind;
  tt_mesh_format mesh;        /* APP_OUTPUT_MESH's format, else none */
  GDALDriverH drv;            /* the OGR driver (not for a mesh) */
  const char *drvname;        /* the driver's or the mesh format's name */
  char shown[TT_APP_MESSAGE_MAX]; /* OUTPUT without its password */
  tt_output *outp;            /* the planned file (not for a database) */
  GDALDatasetH dst;           /* a database's, or a file's while written */
  char **wopts, **dsco;       /* tt_ogr_write_tin's options, -dsco */
  OGRSpatialReferenceH srs;   /* the layers' CRS (the DEM's), or NULL */
  char *t_srs_auto;           /* the CRS the format takes only (GPX), in
                                 which the layers are written (CPLFree) */
  tt_app_stream so;           /* APP_OUTPUT_STREAM's sink */
  /* what the run made */
  tt_grid *grid;              /* a whole run's DEM, until simplified */
  tt_raster_info *info;
  tt_tin *tin;                /* NULL when streamed */
  int64_t *bl_ends;           /* -breaklines: ro.breaklines's ends (free) */
  app_simplify_report rep;
};

/* The most samples a DEM may have to be tiled without -tile_size (4.3
 * G, a 65536^2 DEM: some ten minutes of tiles here; docs/scale.md). */
#define TT_APP_AUTO_TILE_CELLS ((size_t)1 << 32)

/* job.c: the job of r's settings (nothing is opened yet): the method's
 * options, OUTPUT's shown name. */
void tt__app_job_init(app_simplify_job *job, app_run *r);
/* The settings' checks that need GDAL: OUTPUT is not the input, -work_srs
 * and -t_srs are CRSs (-work_srs projected). The failure is recorded. */
tt_status tt__app_job_check(app_simplify_job *job);
/* The memory the run may hold (asked after the output is planned, before
 * the DEM is read: the heights count against it), and decimation's
 * refusal of -max_memory. The failure is recorded. */
tt_status tt__app_job_memory(app_simplify_job *job);
/* The engine's threads (-threads, GDAL_NUM_THREADS: tt__app_threads, which
 * may warn) into the options, and the workers of a tiled run. */
void tt__app_job_threads(app_simplify_job *job);
/* The DEM's mean step (default_bound.c): the sum of the absolute height
 * differences of 4-neighbour valid samples, and their count. */
typedef struct app_step {
  double sum, comp; /* the sum, and its compensation (Neumaier) */
  size_t pairs;
} app_step;
/* The pairs of g whose first sample lies in columns x0..x1 and rows
 * y0..y1 and whose second lies at most at column xmax, row ymax, added
 * to s (all in g's cells). */
void tt__app_step_add(app_step *s, const tt_grid *g, size_t x0, size_t y0,
                      size_t x1, size_t y1, size_t xmax, size_t ymax);
/* All the pairs of g added to s. */
void tt__app_step_of_grid(app_step *s, const tt_grid *g);
/* s's pairs added to into (a tile's to the DEM's). */
void tt__app_step_merge(app_step *into, const app_step *s);
/* The mean absolute difference (0 without pairs). */
double tt__app_step_mean(const app_step *s);
/* The default bound: twice the mean step, two significant digits; 0 for
 * a flat DEM or one without pairs. */
double tt__app_default_bound_of(const app_step *s);

/* Whether the bound is the default one (no -max_error, no budget), and
 * that bound set from the DEM's step (tt__app_default_bound_of). */
int tt__app_job_default_wanted(const app_simplify_job *job);
void tt__app_job_default_bound(app_simplify_job *job, const app_step *step);
/* Closes and frees what the job holds; an unfinished output is removed. */
void tt__app_job_free(app_simplify_job *job);

/* breaklines.c: -breaklines read and traced on the whole run's grid into
 * job->ro.breaklines (the ends kept in job->bl_ends), the lines clipped
 * warned about. The failure is recorded. */
tt_status tt__app_breaklines(app_simplify_job *job);

/* output.c: the kind of output and its driver (-of, else OUTPUT's form),
 * the mesh formats' refusals of the OGR options. */
tt_status tt__app_output_choose(app_simplify_job *job);
/* What the run wrote, as the user names it: the files (a database: its
 * name without password) and, for a dataset of several layers, the layers
 * in it (else NULL); CSLDestroy both. */
void tt__app_output_names(const app_simplify_job *job, char ***out_files,
                          char ***out_layers);
/* The output planned before any work: a database opened and checked, a
 * file's temporary name and sidecars, what is in the way refused. */
tt_status tt__app_output_plan(app_simplify_job *job);
/* The OGR writer's options and creation options, and (for a file) the
 * dry run, once the DEM is open. */
tt_status tt__app_output_options(app_simplify_job *job);
/* A tiled run into a GeoPackage file streams (unless `tiles run` keeps
 * its one tile, or TERRATIN_TILE_STREAM=NO): the kind becomes
 * APP_OUTPUT_STREAM. */
void tt__app_output_choose_stream(app_simplify_job *job);

/* write.c: the TIN (or the streamed rows) written into the output and
 * committed; the write's times in the report. The failure is recorded. */
tt_status tt__app_simplify_write(app_simplify_job *job);
/* The layers' CRS from info's (a warning when it cannot be parsed), unless
 * the job has it already. */
void tt__app_write_srs(app_simplify_job *job, const tt_raster_info *info);
/* The OGR dataset created at the output's temporary name with -dsco
 * (checked only when given); NULL with GDAL's reason in r->msg.last. */
GDALDatasetH tt__app_write_create(app_simplify_job *job);

/* run_fields.c: the run_parameters fields of a run from its job and report
 * so far (its info among them); the strings they point to are kept
 * beside them. */
#define TT__APP_RUN_FIELDS 48
typedef struct app_run_fields {
  char created[32], start_name[48];
  tt_run_field v[TT__APP_RUN_FIELDS];
  size_t n;
} app_run_fields;
void tt__app_simplify_fields(const app_simplify_job *job,
                             app_run_fields *out);

/* ogr_output.c: the dry run of the OGR writer on a two-triangle TIN in
 * /vsimem/ with drv, -layers, the creation options dsco and the writer's
 * options wopts, after
 * the DEM src is opened and before it is read: 1 when the driver holds the
 * layers (or cannot be judged), else 0 with the refusal recorded (a usage
 * error naming the -layers or OUTPUT form that works). */
int tt__app_check_ogr_output(app_run *r, GDALDriverH drv, GDALDatasetH src,
                             char **dsco, char **wopts, char **auto_t_srs);
/* ogr_output.c, for --formats: the dry run of drv (with the -dsco terratin
 * adds) into a file named with extension ext ("" for a folder), on a TIN
 * in UTM zone 33N, read back: TT_APP_LAYERS_ALL when it holds the three
 * layers together as written, else 0, with *out_alone the layers it
 * holds each alone (all three when together; 0: the driver cannot write
 * the TIN faithfully) and *out_imposed 1 when it writes them in a CRS of
 * its own (GPX: EPSG:4326). */
unsigned tt__app_probe_format(GDALDriverH drv, const char *ext,
                              unsigned *out_alone, int *out_imposed);
/* ogr_readback.c: 1 when the dataset name, just written by drv with the
 * layers (TT_APP_LAYERS_* bits) of tin
 * (in tin_srs, NULL: none) reprojected to t_srs (NULL: none), reads back
 * with every vertex's x and y within tol_xy (in tin_srs's units) and its z
 * within 1e-9 of its magnitude; else 0 with what changed in why, and
 * *imposed (CPLFree) the geographic CRS the driver wrote in of its own
 * accord (GPX), if it did. */
int tt__app_read_back(GDALDriverH drv, const char *name, unsigned layers,
                      const tt_tin *tin,
                      OGRSpatialReferenceH tin_srs, const char *t_srs,
                      double tol_xy, char *why, size_t n, char **imposed);
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

/* report.c (the core): the summary and the JSON. */
void tt__app_print_simplify_json(app_run *r, const app_simplify_report *p);
void tt__app_print_simplify_summary(app_run *r,
                                    const app_simplify_report *p);

/* tiled.c: the job's DEM read and simplified in tiles of job->tile_size
 * cells on job->workers threads (fewer if there are fewer tiles), merged
 * into job->tin or, when streamed, written as they merge; job->ro's
 * max_error < 0 asks for the default bound (then set), a budget of the
 * whole DEM (max_points, max_triangles, percent) is turned into a bound
 * (tiled_budget.c; job->ro.max_error is set to it). job->info, the
 * report's tiles, threads, passes, valid samples and height range are
 * set. With `tiles run`'s hook the one tile is handed to it and no TIN
 * is made. The failure is recorded. */
tt_status tt__app_simplify_tiled(app_simplify_job *job);
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
/* tiled_budget.c: the vertices a curve's tile has at bound e. */
size_t tt__app_curve_count_at(const app_curve *c, double e);

/* estimate.c: whether the run is estimated before its work (always for
 * -json; a DEM past a million samples, or one the whole run may not
 * hold; never for a budget or a tile of `tiles run`), the estimate into
 * job->rep.estimate (the failure recorded), and its line on stderr when
 * the TIN passes a million vertices or its output 1 GB. */
int tt__app_estimate_wanted(const app_simplify_job *job);
tt_status tt__app_estimate(app_simplify_job *job);
void tt__app_estimate_say(app_simplify_job *job);

/* tiled_stream.c: whether a tiled run into a file of drvname streams
 * (GPKG, unless TERRATIN_TILE_STREAM=NO), and the sink of job's. */
int tt__app_stream_wanted(const char *drvname);
/* Whether the GeoPackage GDAL makes for job's output can take the rows as
 * pages, as a stream writes them (no WAL, no auto-vacuum: GDAL's
 * OGR_SQLITE_PRAGMA may ask for either), found before the tiles run by
 * making it and removing it again; when not, the merged TIN is written
 * through SQLite after the last tile, as an untiled run falls back. */
int tt__app_stream_possible(app_simplify_job *job);
void tt__app_stream_init(tt_app_stream *so, app_simplify_job *job);
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
