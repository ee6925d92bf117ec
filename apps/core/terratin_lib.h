/*
 * terratin_lib.h -- apps/core/: the command's core, what every command's folder
 * shares. This header: the terratin command as a library, in the shape of
 * GDAL's apps/gdal_utils.h: tt_app_options_new() parses the words of a command
 * line into an options object, tt_app_run() runs it, and apps/core/terratin.c
 * is a thin main() around the two. Tests and other programs can drive every
 * subcommand (simplify, generate, eval) without a shell.
 *
 * Parsing has no side effects: it only reads the words and checks their
 * values (numbers, ranges, names known to the engine). Everything that needs
 * GDAL -- `--config` options, the output driver, the CRS given to -a_srs --
 * is applied or checked by tt_app_run(), in that order, before any file is
 * opened. `--config` options are set process-wide (CPLSetConfigOption), as
 * GDAL's utilities do, and stay set after the run.
 *
 * Exit codes (documented in `terratin --help` and docs/cli.md):
 *   0 success, 1 processing failure, 2 usage error, 3 eval threshold exceeded.
 *   A run stopped through its progress callback fails with
 *   TT_ERR_INTERRUPTED and exit code 1; the command, stopped by a signal N,
 *   ends by that signal (the shell's 128+N: 130 for SIGINT).
 *
 * Messages: a failure is reported as one line in tt_app_result.message,
 * "<file>: <problem>" or "<problem>" for usage errors, without the leading
 * "terratin: " which main() adds. Warnings are written by tt_app_run() to the
 * error stream as "terratin: warning: <text>".
 */
#ifndef TERRATIN_LIB_H
#define TERRATIN_LIB_H

#include "terratin/terratin.h"

#include <signal.h>
#include <stdio.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Exit codes of the command. */
typedef enum tt_app_exit {
  TT_APP_EXIT_OK = 0,
  TT_APP_EXIT_FAILURE = 1,   /* bad input, I/O error, refused output */
  TT_APP_EXIT_USAGE = 2,     /* unknown option, bad value, missing argument */
  TT_APP_EXIT_THRESHOLD = 3  /* eval: measured max error > -max_error */
} tt_app_exit;

typedef enum tt_app_command {
  TT_APP_NONE = 0,           /* no command (help topic: the top level) */
  TT_APP_HELP,               /* print the help of help_topic */
  TT_APP_VERSION,            /* print terratin, GDAL and PROJ versions */
  TT_APP_SIMPLIFY,
  TT_APP_GENERATE,
  TT_APP_EVAL,
  TT_APP_OPTIMIZE,           /* optimize DEM IN_TIN OUTPUT */
  TT_APP_STUDY,              /* study OUTDIR */
  TT_APP_RASTERIZE,          /* rasterize DEM TIN OUTPUT */
  TT_APP_FORMATS,            /* --formats: the output formats */
  TT_APP_HELP_GENERAL,       /* --help-general: the options of every command */
  TT_APP_TILES               /* a help topic only: `terratin tiles` runs
                                through tt_app_tiles() */
} tt_app_command;

#define TT_APP_MESSAGE_MAX 1024
/* The most threads -threads and GDAL_NUM_THREADS may ask for. */
#define TT_APP_MAX_THREADS 1024

/* The outcome of parsing or running: the exit code and, on failure, one line
 * without a trailing newline ("" on success). */
typedef struct tt_app_result {
  int exit_code;             /* a tt_app_exit value */
  tt_status status;          /* TT_OK, or what failed (TT_ERR_ARG: usage) */
  char message[TT_APP_MESSAGE_MAX];
} tt_app_result;

/* What the command line said, read-only for callers. Strings and lists are
 * owned by the options object; lists are NULL-terminated. A field that does
 * not apply to the command keeps its default. */
/* The layers simplify writes (-layers), as bits of tt_app_settings.layers. */
enum {
  TT_APP_LAYER_TRIANGLES = 1u,
  TT_APP_LAYER_VERTICES = 2u,
  TT_APP_LAYER_RUN_PARAMETERS = 4u,
  TT_APP_LAYERS_ALL = 7u
};

/* Four numbers given to one option (-srcwin, -projwin, -a_ullr). */
typedef struct tt_app_box {
  int set;                   /* the option was given */
  double v[4];               /* its values, in the option's order */
} tt_app_box;

typedef struct tt_app_settings {
  tt_app_command command;
  tt_app_command help_topic; /* TT_APP_HELP: TT_APP_NONE = top level */

  /* all commands */
  const char *const *config; /* --config pairs: KEY, VALUE, KEY, VALUE, NULL */
  int quiet;                 /* -q */
  int json;                  /* -json (simplify, eval) */
  int verbose;               /* -verbose: the whole summary (simplify) */
  int overwrite;             /* -overwrite (simplify, generate) */

  /* simplify INPUT OUTPUT; eval INPUT TIN; generate TYPE OUTPUT */
  const char *input;         /* the DEM (simplify, eval) */
  const char *output;        /* the dataset written (simplify, generate) */
  const char *tin;           /* the triangle dataset read (eval) */
  int band;                  /* -b, 1-based; default 1 */
  const char *srcnodata;     /* -srcnodata: a number or "nan"; NULL: the
                                band's own mask (simplify, eval) */
  double z_factor;           /* -z_factor; default 1 (simplify, eval) */
  int z_factor_set;          /* -z_factor was given */
  const char *z_unit;        /* -z_unit: the heights' unit, "m", "ft" or
                                "us-ft"; NULL: as the file says */
  const char *z_to;          /* -z_to: "m" (convert to metres), "native"
                                (keep the unit) or "auto" (metres when the
                                CRS is in metres or geographic); NULL:
                                auto */
  size_t fill_nodata;        /* -fill_nodata: voids of at most this many
                                samples filled; 0: none (simplify, eval) */
  const char *work_srs;      /* -work_srs: the working CRS; NULL: chosen
                                from the DEM's CRS (simplify) */
  const char *t_srs;         /* -t_srs: the output layers' CRS; NULL: the
                                DEM's (simplify) */
  const char *breaklines;    /* -breaklines: an OGR source of lines the
                                TIN follows; NULL: none (simplify) */
  const char *breaklines_layer; /* -breaklines_layer; NULL: the first */
  const char *breaklines_where; /* -breaklines_where: an attribute filter */
  /* the DEM as GDAL's input options present it (dem_view.c): read
   * through an in-memory VRT of the window, map coordinates unchanged */
  tt_app_box srcwin;         /* -srcwin xoff yoff xsize ysize (samples) */
  tt_app_box projwin;        /* -projwin ulx uly lrx lry */
  const char *projwin_srs;   /* -projwin_srs: projwin's CRS; NULL: the
                                DEM's */
  tt_app_box a_ullr;         /* -a_ullr ulx uly lrx lry: the georeferenced
                                bounds given to the (windowed) DEM */
  int srs_is_s_srs;          /* the DEM's CRS (srs) was given as -s_srs */

  /* simplify; eval uses max_error as its threshold */
  double max_error;          /* -max_error; negative: not given */
  size_t max_points;         /* -max_points; 0: not given */
  size_t max_triangles;      /* -max_triangles; 0: not given */
  double percent;            /* -percent; 0: not given */
  tt_criterion criterion;    /* -criterion; default delaunay */
  tt_optimize optimize;      /* -optimize; default auto (tt_optimize_resolve) */
  tt_repair repair;          /* -repair; default auto (tt_repair_resolve) */
  tt_anneal_options anneal;  /* -anneal_t0, -anneal_stages, -anneal_swaps,
                                -anneal_good, -anneal_r, -seed (simplify,
                                optimize); zero: the study's defaults */
  const char *format;        /* -of; NULL: guessed from the output's
                                extension, else GPKG */
  const char *const *lco;    /* -lco NAME=VALUE, in order */
  const char *const *dsco;   /* -dsco NAME=VALUE, in order */
  int obj_local;             /* -obj_local: OBJ vertices around the
                                centre of the extent */
  const char *nln;           /* -nln layer name prefix; "" by default */
  unsigned layers;           /* -layers: TT_APP_LAYER_* bits; default all */
  int nostyle;               /* -nostyle: no layer_styles in a GeoPackage */
  /* simplify -method decimate (docs/decimation.md); the options below
   * apply to it only */
  int decimate;              /* -method: 0 insert (default), 1 decimate */
  tt_decimate_start start;   /* -start all | greedy | greedy:N */
  size_t start_points;       /* the N of greedy:N */
  tt_importance importance;  /* -importance; default auto */
  tt_selection selection;    /* -selection; default independent */
  int onepass;               /* -onepass */
  tt_hole hole;              /* -hole; default auto */
  int threads;               /* -threads N (>= 1), -1 for ALL_CPUS; 0: not
                                given (GDAL_NUM_THREADS, else automatic) */
  size_t max_memory;         /* -max_memory in bytes (simplify, eval); 0:
                                not given (the system's limit) */
  size_t min_patch;          /* -min_patch N (simplify): valid patches of
                                fewer samples dropped; 0: none */
  size_t tile_size;          /* -tile_size N (simplify): tiles of N cells
                                (docs/scale.md); 0: untiled unless the
                                heights do not fit the memory limit */

  /* eval, optimize (which reads the TIN from tin and writes output) */
  const char *layer;         /* -layer; NULL: the triangles layer */
  int tin_frame;             /* eval -tin_frame (-stl_frame): 0 auto (map;
                                an STL off the DEM's extent: pixel), 1 map,
                                2 pixel */
  double tin_transform[6];   /* eval -tin_transform sx,sy,sz,ox,oy,oz */
  int tin_transform_set;     /* -tin_transform was given */

  /* generate */
  tt_synth_options synth;    /* tt_synth_options_init(kind) + the flags */
  const char *srs;           /* -a_srs (or -s_srs, DEM readers): the CRS
                                given to the output (generate) or to the
                                DEM read (the others); NULL: none */

  /* study OUTDIR (output); the lists are checked by the run (study.c) */
  const char *const *terrains; /* -terrain, in order: a DEM or a name */
  const char *criteria;      /* -criteria all | NAME,NAME; NULL: all */
  const char *methods;       /* -methods insert,decimate; NULL: insert */
  const char *optimizers;    /* -optimizers auto,none,local,...; NULL:
                                auto */
  const char *percents;      /* -percent P,P,...; NULL: 1,10,25,50 (none
                                with -points alone) */
  size_t points;             /* -points N: curves up to N points; 0: none */
  uint64_t seed;             /* -seed (study: the generated terrains) */
  int seed_set;              /* -seed was given */

  /* rasterize TIN DEM OUTPUT (tin, input, output; -of the raster driver);
   * eval -error_raster */
  const char *error_raster;  /* -error_raster: TIN - DEM as a GeoTIFF */
  const char *const *co;     /* -co NAME=VALUE (raster creation options) */
  int plot;                  /* -plot: tools/plot_study.py afterwards */
  size_t tin_points;         /* -tin_points N: each criterion's TIN at N
                                points into OUTDIR/tins; 0: none */
} tt_app_settings;

typedef struct tt_app_options tt_app_options;

/* Parses the words that follow the program name (argv: NULL-terminated, as
 * GDAL's XxxOptionsNew takes them). On success returns TT_OK and the options
 * with out_result->exit_code 0; on a usage error returns TT_ERR_ARG, sets
 * *out_options to NULL and fills out_result (exit code 2, one-line message);
 * TT_ERR_NOMEM when out of memory (exit code 1). out_result may be NULL.
 * The caller owns *out_options and frees it with tt_app_options_destroy(). */
tt_status tt_app_options_new(char **argv, tt_app_options **out_options,
                             tt_app_result *out_result);
void tt_app_options_destroy(tt_app_options *options);

/* The parsed values. Valid while the options live. */
const tt_app_settings *tt_app_options_settings(const tt_app_options *options);

/* The progress callback, called with the overall fraction done, scaled over
 * the phases (read 0-0.10, simplify 0.10-0.85, write 0.85-1). Returning 0
 * stops the run (TT_ERR_INTERRUPTED, nothing left behind). NULL: none. */
void tt_app_options_set_progress(tt_app_options *options, tt_progress_fn fn,
                                 void *arg);
/* Where results (summary, JSON, help) and warnings go; default stdout and
 * stderr. */
void tt_app_options_set_streams(tt_app_options *options, FILE *out,
                                FILE *err);
/* Whether a progress bar belongs on the output stream (simplify without -q
 * and without -json). */
int tt_app_options_wants_progress_bar(const tt_app_options *options);

/* Runs the command. Returns TT_OK and out_result->exit_code 0 (or 3 when an
 * eval threshold was exceeded), else the failure's status with the exit code
 * and one-line message in out_result. */
tt_status tt_app_run(const tt_app_options *options, tt_app_result *out_result);

/* `terratin tiles plan|run|merge ...` (apps/tiles/tiles_plan.c, docs/scale.md):
 * argv holds the words after "tiles"; fn is polled for an interruption. */
void tt_app_tiles(char **argv, tt_progress_fn fn, void *arg,
                  tt_app_result *out_result);

/* name with the password of a PostgreSQL connection string (libpq's
 * keyword/value or URI form, with or without "PG:") replaced by ***, as
 * libpq's parser reads it, into buf; a name without one unchanged.
 * Returns 1 when a password was masked, 0 when there was none, -1 when a
 * password was found that libpq cannot parse (shown up to it). */
int tt_app_mask_password(const char *name, char *buf, size_t size);
/* Masks, in the NUL-terminated text of size bytes, every word of the
 * NULL-terminated list that carries a password (main() passes argv over
 * the failure it prints). */
void tt_app_mask_words(char *const *words, char *text, size_t size);

/* The help text of a command (TT_APP_NONE: the top level). */
const char *tt_app_help(tt_app_command topic);

/* A GDAL-style text progress bar, "0...10...20...30...40...50...60...70...
 * 80...90...100 - done.", whose state lives in this struct (GDALTermProgress
 * keeps it in statics: one bar per process). It also stops the run when
 * *stop becomes non-zero (a signal handler's flag), drawing or not. */
typedef struct tt_app_term_progress {
  FILE *fp;                        /* NULL: draw nothing */
  int ticks;                       /* ticks drawn, 0..41 (-1: none yet) */
  volatile sig_atomic_t *stop;     /* may be NULL */
  int line_ended;                  /* a message ended the bar's line */
} tt_app_term_progress;

void tt_app_term_progress_init(tt_app_term_progress *bar, FILE *fp,
                               volatile sig_atomic_t *stop);
/* A tt_progress_fn; arg is a tt_app_term_progress. */
int tt_app_term_progress_fn(double complete, const char *message, void *arg);
/* Ends the bar's line when it is half drawn, so that a warning or the
 * failure printed next starts a line of its own (a bar that goes on, goes
 * on on the next line). NULL: nothing. */
void tt_app_term_progress_break(tt_app_term_progress *bar);

#ifdef __cplusplus
}
#endif
#endif /* TERRATIN_LIB_H */
