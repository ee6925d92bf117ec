/*
 * app.h -- the command's core (apps/core/), what every command's folder
 * shares (internal; the public face is terratin_lib.h): the options
 * object, a run's state, the one-line failure helpers, the phase-scaled
 * progress, the JSON writer, the inputs and outputs several commands
 * read and write, and one entry point per command.
 *
 *   terratin.c      main(): the words to an options object, run, exit
 *   options.c       the parser; option_table.c the table it reads and
 *                   the readers of each kind of value
 *   settings.c      the options object's lists and accessors
 *   values.c        numbers, sizes, booleans and grid sizes of words
 *   help.c          the help texts
 *   run.c           tt_app_run (the dispatch), GDAL messages, failures,
 *                   the output driver
 *   dem.c           opening the DEM and reading it into a grid
 *   tin_input.c     opening a TIN and picking its triangle layer
 *   raster_output.c the raster writer (rasterize, eval -error_raster)
 *   progress.c      the text progress bar and the phase scaling
 *   report.c        the JSON writer and simplify's summary and JSON
 *   conninfo.c      connection strings shown with their password masked
 *
 * The commands, a folder each over this core (none includes another's
 * headers): simplify/ (with the tiled path and the output choice; its
 * own simplify.h), tiles/, study/, eval/, rasterize/, optimize/,
 * generate/.
 *
 * Invariants: a run reports at most one failure (the first), as one line;
 * every run either commits its output or leaves nothing behind; GDAL never
 * prints by itself while a run is active.
 */
#ifndef TERRATIN_APP_H
#define TERRATIN_APP_H

/* GDAL's VSIStatBufL is a struct stat64 on glibc: declare it. */
#define _LARGEFILE64_SOURCE 1

#include "terratin_lib.h"

#include "terratin/terratin_gdal.h"

#include <cpl_error.h>
#include <gdal.h>

#include <stdint.h>
#include <stdio.h>

#if defined(__GNUC__)
#define TT_APP_PRINTF_(a, b) __attribute__((format(printf, a, b)))
#else
#define TT_APP_PRINTF_(a, b)
#endif

/* --- the options object (options.c) -------------------------------------- */

/* A NULL-terminated list of owned strings. */
typedef struct app_strlist {
  char **v;
  size_t n, cap;
} app_strlist;

struct tt_app_options {
  tt_app_settings s;     /* the public view; strings point into the lists */
  app_strlist strings;   /* every single string (input, output, -of, ...) */
  app_strlist config, lco, dsco, terrains;
  app_strlist co;        /* -co (rasterize, eval -error_raster) */
  tt_progress_fn progress;
  void *progress_arg;
  FILE *out, *err;
};

/* --- the values of words (values.c) ------------------------------------- */

/* A list of owned strings kept NULL-terminated; 0 when out of memory. */
int tt__app_strlist_add(app_strlist *l, const char *s);
void tt__app_strlist_free(app_strlist *l);

/* What the integer and size parsers found. */
enum { NUM_BAD = 0, NUM_OK = 1, NUM_TOO_LARGE = 2 };

/* A finite decimal number, the whole word ([+-]digits[.digits][e...]):
 * 1 and *out, else 0. */
int tt__app_parse_double(const char *w, double *out);
/* An unsigned decimal integer, the whole word: NUM_OK, NUM_BAD, or
 * NUM_TOO_LARGE beyond 2^64 - 1 (resp. SIZE_MAX). */
int tt__app_parse_u64(const char *w, uint64_t *out);
int tt__app_parse_size(const char *w, size_t *out);
/* Bytes, or a number with K, M, G or T (powers of 1024, then B or iB). */
int tt__app_parse_mem_size(const char *w, size_t *out);
/* One of the words GDAL's CPLTestBool reads as a boolean. */
int tt__app_is_gdal_bool(const char *w);
/* "N" or "NXxNY". */
int tt__app_parse_grid_size(const char *w, size_t *nx, size_t *ny);
int tt__app_is_pow2_plus1(size_t n);
/* The TT_APP_LAYER_* bit of the layer named by the n bytes at w
 * (triangles, vertices, run_parameters; case-insensitive), else 0. */
unsigned tt__app_layer_bit(const char *w, size_t n);
/* The names of the layers of mask, comma-separated, in the writer's order
 * ("triangles,run_parameters"), into buf. */
const char *tt__app_layer_list(unsigned mask, char *buf, size_t size);

/* "simplify", "generate", "eval" or "" (help.c). */
const char *tt__app_command_name(tt_app_command c);

/* --- results and messages (run.c) ---------------------------------------- */

/* Seconds of a monotonic clock (the app's own; the engine keeps its own). */
double tt__app_now(void);
/* Fills a result, keeping the first failure: later ones are consequences. */
void tt__app_result_set(tt_app_result *res, int exit_code, tt_status status,
                        const char *fmt, ...) TT_APP_PRINTF_(4, 5);
void tt__app_result_ok(tt_app_result *res);
int tt__app_str_ieq(const char *a, const char *b);

/* --- connection strings (conninfo.c) ------------------------------------ */

/* What tt__app_mask_password did. */
enum {
  TT_APP_MASK_UNPARSED = -1, /* a password libpq cannot parse: cut at it */
  TT_APP_MASK_NONE = 0,      /* no password: the name unchanged */
  TT_APP_MASK_DONE = 1       /* rebuilt from libpq's parse, password *** */
};
/* name (a datasource name: a file, or a PostgreSQL connection string in
 * libpq's keyword/value or URI form, with or without GDAL's "PG:") with
 * its password replaced by ***, into buf (cut to size, never overrun). */
int tt__app_mask_password(const char *name, char *buf, size_t size);

/* The datasource names of a run that carry a password, with their shown
 * forms; raw points at the caller's string. */
#define TT_APP_MAX_SECRETS 4
typedef struct app_secret {
  const char *raw;
  char shown[TT_APP_MESSAGE_MAX];
  char password[256]; /* "" when longer: the last net then skips it */
  size_t typed_len;   /* the password's value as typed (keyword form) */
} app_secret;
typedef struct app_secrets {
  size_t n;
  app_secret item[TT_APP_MAX_SECRETS];
} app_secrets;
/* Adds name when it carries a password; returns what
 * tt__app_mask_password returned for it. */
int tt__app_secrets_add(app_secrets *sec, const char *name);
/* The shown form of name (name itself when it carries no password). */
const char *tt__app_secrets_shown(const app_secrets *sec, const char *name);
/* text with every name of sec, as given or without its "PG:", replaced
 * by its shown form, the value of any other "password=" masked (at least
 * as many characters as the longest typed password), and any password of
 * 4 or more characters still left replaced by "***": buf, or text itself
 * when sec holds nothing. */
const char *tt__app_secrets_mask(const app_secrets *sec, const char *text,
                                 char *buf, size_t size);

/* GDAL's failures and warnings while a run is active (run.c). */
typedef struct app_messages {
  FILE *err;
  size_t warnings;           /* printed or dropped (repeats not counted) */
  uint64_t seen[32];         /* hashes of the warnings printed */
  size_t nseen;
  tt_app_term_progress *bar; /* the text bar, if the run draws one */
  unsigned failures;         /* GDAL failures seen */
  char last[TT_APP_MESSAGE_MAX];
  app_secrets secrets;       /* the run's names that carry a password */
} app_messages;

/* Pushes a CPL error handler that drops GDAL's failures and warnings (for
 * calls whose failure is expected or told otherwise) but prints debug
 * lines as the run does, "terratin: debug: ..."; CPLPopErrorHandler()
 * removes it. m may be NULL (stderr, nothing masked). */
void tt__app_quiet_push(const app_messages *m);

/* Prints "terratin: warning: ..." (at most a fixed number per run). */
void tt__app_warn(app_messages *m, const char *fmt, ...) TT_APP_PRINTF_(2, 3);

/* --- progress (progress.c) ----------------------------------------------- */

/* Maps a phase's [0,1] onto [lo,hi] of the whole run and passes it on. */
typedef struct app_phase {
  tt_progress_fn fn;
  void *arg;
  double lo, hi;
} app_phase;

/* A tt_progress_fn; arg is an app_phase. */
int tt__app_phase_fn(double complete, const char *message, void *arg);
void tt__app_phase_set(app_phase *p, double lo, double hi);

/* --- a run: what every subcommand shares (run.c) ------------------------- */

typedef struct app_run {
  const tt_app_options *o;
  const tt_app_settings *s;
  tt_app_result *res;
  FILE *out, *err;
  tt_context *ctx;
  app_messages msg;
  app_phase prog;
  double t0;
  /* the DEM under GDAL's input options (dem_view.c): the file's dataset
   * the open view reads from, and the arguments that made the view (a
   * tiled run's workers make their own from them); NULL: none */
  GDALDatasetH dem_file;
  char **view_args;
} app_run;

/* A datasource name of the run as it is shown: a connection string with
 * its password masked, anything else unchanged (conninfo.c). */
const char *tt__app_shown(const app_run *r, const char *name);

/* Records the run's failure "<file>: <problem>" (or "<problem>" when file
 * is NULL) and returns st. */
tt_status tt__app_fail(app_run *r, int exit_code, tt_status st,
                       const char *file, const char *fmt, ...)
    TT_APP_PRINTF_(5, 6);
/* The best one-line explanation of a failed engine or glue call about file
 * (the context's message, GDAL's last failure, or the status's). */
const char *tt__app_why(app_run *r, tt_status st, const char *file);
/* Fails with the glue's or engine's message about file. */
tt_status tt__app_fail_tt(app_run *r, tt_status st, const char *file);
/* Fails a write of output (the file being written: written) with the
 * device's cause when there is one (the file system full, ulimit -f
 * reached; the driver's message follows in parentheses), else with the
 * driver's or engine's message. what ("error while closing") names a
 * failure of GDAL's own, whose last message is then the detail; NULL: the
 * failure of an engine or glue call (its message). */
tt_status tt__app_fail_write(app_run *r, tt_status st, const char *output,
                             const char *written, const char *what);
/* An output refused because something exists in its way. */
tt_status tt__app_fail_exists(app_run *r, const char *output);
/* Polls the progress callback between phases: 0 means stop. */
int tt__app_continue(app_run *r, double at);

/* Opens a raster for reading and checks the band; on failure explains in
 * one line why and returns NULL. With GDAL's input options (-srcwin,
 * -projwin, -a_srs, -a_ullr) the dataset returned is the in-memory view
 * of them over the file's (r->dem_file): close it with
 * tt__app_close_raster(), and protect tt__app_raster_file()'s files. */
GDALDatasetH tt__app_open_raster(app_run *r, const char *path, int band,
                                 GDALRasterBandH *out_band);
/* Closes what tt__app_open_raster returned (NULL: nothing), and the file's
 * dataset under a view. */
void tt__app_close_raster(app_run *r, GDALDatasetH ds);
/* The dataset of the DEM's file: r->dem_file under a view, else ds. */
GDALDatasetH tt__app_raster_file(const app_run *r, GDALDatasetH ds);
/* ropts with, under a view, the file's name (path) and driver for the
 * read's messages and info (SOURCE_NAME, SOURCE_DRIVER). */
char **tt__app_view_read_options(const app_run *r, char **ropts,
                                 const char *path);

/* dem_view.c: GDAL's input options on a DEM. Whether any applies. */
int tt__app_view_wanted(const tt_app_settings *s);
/* gdal_translate's arguments for the view of src (-of VRT, -srcwin with
 * the window checked and clipped, -a_srs, -a_ullr); NULL with the reason
 * in why (*out_usage: the options are at fault). A clipped window is
 * told in warn ("" otherwise). The caller frees the list with
 * CSLDestroy(). */
char **tt__app_view_args(const tt_app_settings *s, GDALDatasetH src,
                         int *out_usage, char *why, size_t size, char *warn,
                         size_t warn_size);
/* The in-memory VRT of src under args, or NULL with the reason in why.
 * It reads from src, which must stay open until it is closed. */
GDALDatasetH tt__app_view_open(GDALDatasetH src, char **args, char *why,
                               size_t size);
/* The read options of -srcnodata, -z_factor, -z_unit, -work_srs and
 * -fill_nodata (FILL_NODATA)
 * (tt_gdal_read_grid's SRCNODATA, Z_FACTOR, Z_UNIT, WORK_SRS), for a
 * whole DEM (tt__app_read_dem adds MAX_MEMORY) and a tiled run's windows
 * alike. The caller frees the list with CSLDestroy(). */
char **tt__app_read_options(const tt_app_settings *s);
/* Reads the band into a grid (with -srcnodata, -z_factor, -z_unit,
 * -work_srs) and checks it has valid samples. The caller owns *out_grid and
 * *out_info. */
tt_status tt__app_read_dem(app_run *r, GDALRasterBandH band, const char *path,
                           tt_progress_fn progress, void *progress_arg,
                           tt_grid **out_grid, tt_raster_info **out_info,
                           size_t *out_valid);
/* optimize's and rasterize's inputs: the DEM (s->input) read into a grid
 * with the progress phase set, then the TIN (s->tin) opened with its
 * triangles layer; both inputs protected from outp. On failure (recorded)
 * the caller still owns and frees whatever was set. */
tt_status tt__app_read_dem_and_tin(app_run *r, tt_output *outp,
                                   tt_grid **out_grid,
                                   tt_raster_info **out_info,
                                   size_t *out_valid, GDALDatasetH *out_tds,
                                   OGRLayerH *out_layer);
/* -min_patch (min_patch.c): the valid patches (4-connected) of fewer than
 * min samples become nodata; the samples and patches dropped. False when
 * out of memory. */
bool tt__app_drop_patches(tt_grid *g, size_t min, size_t *out_samples,
                          size_t *out_patches);
void tt__app_height_range(const tt_grid *grid, double *out_min,
                          double *out_max);
const char *tt__app_unit_or(const tt_raster_info *info, const char *dflt);
const char *tt__app_nonempty_or_null(const char *s);
/* Why the heights were converted to metres, in the command's words ("the
 * CRS is in metres", "asked by -z_to m"); "" when they were not. */
const char *tt__app_z_unit_why(const tt_raster_info *info);
/* Where the heights' unit was said: "band unit", "vertical CRS",
 * "-z_unit", or "". */
const char *tt__app_z_unit_source(const tt_raster_info *info);
/* "2026-11-22T10:38:55Z" */
void tt__app_iso8601_utc(char *buf, size_t size);
/* The engine's thread count (tt_refine_options.threads): -threads, else
 * GDAL_NUM_THREADS (a number or ALL_CPUS, from the environment or
 * --config), else 0 (automatic). A GDAL_NUM_THREADS that is neither is
 * warned about and ignored. */
int tt__app_threads(app_run *r);
/* The output driver of simplify: -of, else OUTPUT's extension, else GPKG. */
GDALDriverH tt__app_output_driver(app_run *r);
/* Whether two paths name the same existing file. */
int tt__app_same_file(const char *a, const char *b);

/* --- JSON (report.c) ----------------------------------------------------- */

/* One object, strings escaped, non-finite numbers as null, bytes that are
 * not UTF-8 replaced by U+FFFD so the output always parses. */
typedef struct app_json {
  FILE *fp;
  int depth;
  int first[8];
} app_json;

/* The shortest "%.Ng" text of d (N = 6..17) that reads back as d. */
void tt__app_format_double(char *buf, size_t size, double d);
void tt__json_begin(app_json *j, FILE *fp);
void tt__json_open(app_json *j, const char *key);
void tt__json_close(app_json *j);
void tt__json_str(app_json *j, const char *key, const char *v);
void tt__json_num(app_json *j, const char *key, double v);
void tt__json_size(app_json *j, const char *key, size_t v);
void tt__json_i64(app_json *j, const char *key, int64_t v);
void tt__json_bool(app_json *j, const char *key, int v);
void tt__json_null(app_json *j, const char *key);
/* A list of strings (NULL-terminated; NULL: an empty list). */
void tt__json_strs(app_json *j, const char *key, char *const *v);

/* What simplify's estimate predicted before the work (apps/simplify/
 * estimate.c). */
typedef struct app_estimate {
  int done;                  /* the pass ran */
  double bound;              /* the bound it predicts for */
  int bound_default;         /* ... the default one, from the sample */
  size_t windows, window_size, sampled_cells, sampled_valid;
  double valid, vertices, triangles, share; /* the DEM's, predicted */
  double output_bytes, memory_whole;        /* bytes */
  double advice_bound;       /* the bound of about a 5 % TIN, or NaN */
  double seconds;
} app_estimate;

/* What simplify reports, as text or JSON (report.c). */
typedef struct app_simplify_report {
  const tt_raster_info *info;
  const char *driver;
  size_t cells, valid;
  size_t min_patch, dropped_samples, dropped_patches; /* -min_patch */
  double zmin, zmax;
  const tt_refine_options *ropt;  /* the limits, for either method */
  const tt_decimate_options *dopt; /* -method decimate; else NULL */
  int default_error;            /* max_error is the default: twice the
                                   mean step */
  double step;                  /* the DEM's mean step, when default */
  tt_tin_summary sum;
  double t_read, t_simplify, t_write, t_total;
  /* tiled runs (tiled.c): the tiles, their size, the threads, whether
   * the memory limit chose tiling, the bytes the tiles in flight hold */
  size_t tiles, tile_size, tile_bytes;
  int tile_threads, auto_tiled;
  size_t mem_limit;            /* the memory limit the tiling was held to */
  const char *mem_source;      /* what set it (-max_memory, the system) */
  app_estimate estimate;       /* done: the estimate ran */
  int budget_passes;  /* tiled runs to a budget: the runs at a bound */
  int streamed;       /* the GeoPackage written as the tiles merged */
  /* the CRS the layers are written in: -t_srs, or the one a format takes
   * only (GPX: EPSG:4326, chosen by the dry run); NULL: the DEM's */
  const char *t_srs;
  int t_srs_auto;     /* t_srs was chosen for the format, not given */
  /* -breaklines (apps/simplify/breaklines.c): the features read, the
   * constrained segments they made */
  size_t breaklines, breakline_segments;
  /* what was written, as the user names it (tt__app_output_names): the
   * files, and the layers of a dataset of several (else NULL) */
  char **files, **layers;
  /* 2DM: the .prj beside it that holds the CRS, which the format (and
   * MDAL) cannot (one of files); NULL: none */
  const char *crs_file;
} app_simplify_report;

/* --- the subcommands ----------------------------------------------------- */

tt_status tt__app_simplify(app_run *r);  /* simplify.c */
tt_status tt__app_generate(app_run *r);  /* generate.c */
tt_status tt__app_eval(app_run *r);      /* eval.c */
tt_status tt__app_optimize(app_run *r);  /* optimize.c */
tt_status tt__app_study(app_run *r);     /* study.c */
tt_status tt__app_rasterize(app_run *r); /* rasterize.c */
/* --formats (simplify/formats.c): the output formats simplify writes, each
 * OGR driver judged by the dry run of its writer (ogr_output.c). */
tt_status tt__app_formats(app_run *r);
/* --help-general (help.c): the options of every command, as GDAL's
 * utilities print them. */
const char *tt__app_help_general(void);
/* The help page of `terratin tiles SUB` (plan, run, merge; anything else:
 * the overview of the three). */
const char *tt__app_tiles_help(const char *sub);

/* The dispatch table (run.c): one entry per command, which the parser
 * (the command word, how many positional words, where they go), the help
 * and tt_app_run read, and the tests walk, so a command is added in one
 * place. */
#define TT_APP_POS_NONE ((size_t)-1) /* a word the command's check reads */
typedef struct tt__app_command_def {
  const char *name;                  /* the command word */
  tt_app_command command;
  size_t npos;                       /* its positional words, all needed */
  size_t pos[3];                     /* offsetof(tt_app_settings, field)
                                        of each (a const char *), or
                                        TT_APP_POS_NONE */
  tt_status (*run)(app_run *r);
} tt__app_command_def;
/* Every command, in the help's order, ended by an entry of NULL name. */
extern const tt__app_command_def tt__app_commands[];
/* The entry of c, or NULL (no command, help, version). */
const tt__app_command_def *tt__app_command_def_of(tt_app_command c);
/* Which of the run's positional words path is (1 for the first), by the
 * dispatch table; 0 when it is none of them (study's -terrain). */
int tt__app_arg_number(const app_run *r, const char *path);
/* raster_output.c, for rasterize and eval -error_raster: the raster
 * driver of -of, else
 * the one path's extension names (NULL path: GTiff), that can write a
 * Float32 or Float64 band; NULL with the failure recorded. */
GDALDriverH tt__app_raster_driver(app_run *r, const char *of,
                                  const char *path);
/* Writes values (the DEM's grid, NaN: nodata) to out's temporary name with
 * drv (GTiff: tiled, DEFLATE, unless -co says otherwise; -co), Float64
 * when the grid holds doubles, else Float32, in the DEM's geotransform and
 * CRS, and commits it; the failure recorded otherwise. */
tt_status tt__app_write_raster(app_run *r, tt_output *out, GDALDriverH drv,
                               const tt_grid *grid,
                               const tt_raster_info *info,
                               const double *values);
/* `terratin tiles run` and `tiles merge` (tiles_*.c) run simplify's tiled
 * path with this set: save, the one tile given is computed and handed to
 * it (nothing else written); load, every tile's piece is read by it
 * instead of computed (then merged and written as simplify does). */
typedef struct tt_app_tiles_hook {
  size_t tile;
  tt_status (*save)(void *arg, app_run *r, size_t k, const tt_tin *piece);
  tt_status (*load)(void *arg, tt_context *ctx, size_t k, tt_tin **piece,
                    char *msg, size_t msgsize);
  void *arg;
} tt_app_tiles_hook;
extern tt_app_tiles_hook tt__app_tiles_hook;
/* tin_input.c, for eval, optimize and rasterize: opens r->s->tin's kind of dataset (a vector
 * dataset, explaining in one line why not), and picks its triangle layer
 * (-layer, else "triangles" or "*_triangles", else the first polygon
 * layer); NULL with the failure recorded. */
GDALDatasetH tt__app_open_vector(app_run *r, const char *path);
OGRLayerH tt__app_tin_layer(app_run *r, GDALDatasetH ds);
/* Whether the layer declares a CRS that is not the DEM's (tin_input.c). */
int tt__app_layer_in_other_crs(OGRLayerH layer, const tt_raster_info *info);

/* tin_read.c, for eval: a TIN from a mesh file or an OGR layer, on the
 * DEM's pixel-centre grid. */
typedef struct app_tin {
  GDALDatasetH ds;       /* the OGR dataset; NULL for a mesh file */
  const char *format;    /* "STL", "PLY", ... or the OGR driver's name */
  const char *layer;     /* the layer's name (ds owns it); NULL: a file */
  double *xyz;           /* ntri triangles, corners in pixel space */
  size_t ntri, rejected;
  char *crs_wkt;         /* the CRS the TIN declares (malloc'd) or NULL */
  char crs_name[128];    /* its name, when it was reprojected */
  int pixel;             /* read in the DEM's pixel frame */
  int reprojected;       /* reprojected from crs_wkt to the DEM's CRS */
  int other_crs;         /* a CRS on a DEM without one: measured as is */
} app_tin;
/* Reads r->s->tin (its OGR dataset protected from outp, which may be
 * NULL) into t, on the DEM of info and grid (whose heights settle an
 * STL's frame when its extent does not). On failure (recorded) the caller still frees t with
 * tt__app_tin_free. */
tt_status tt__app_read_tin(app_run *r, const tt_raster_info *info,
                           const tt_grid *grid, tt_output *outp, app_tin *t);
void tt__app_tin_free(app_tin *t);

#endif /* TERRATIN_APP_H */
