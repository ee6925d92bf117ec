/*
 * option_table.h -- apps/core/: the command's core, what every command's
 * folder shares. This header: the options of the terratin command as
 * data. Each option's entry says which subcommands take it (a bit per
 * tt_app_command), what kind of value it has (a flag, a number in a range,
 * a count, a name, a text, a list of words) and where the value goes (a
 * field of the options object, or generate's terrain parameters);
 * tt__app_opt_apply() reads one value into its place. options.c walks the
 * command line with it (the global options, the command word, the
 * positional words, the checks across options); option_table.c holds the
 * table and the readers of each kind of value.
 *
 * Invariant: every message about a value is one line, "<command>: <option>
 * ..." (the option by its first spelling in the table: -f's by -of), and a
 * value is stored only once it is accepted.
 */
#ifndef TT_APP_OPTION_TABLE_H
#define TT_APP_OPTION_TABLE_H

#include "app.h"

#include <stddef.h>
#include <stdint.h>

enum opt_id {
  O_B, O_MAX_ERROR, O_MAX_POINTS, O_MAX_TRIANGLES, O_PERCENT, O_OF, O_LCO,
  O_DSCO, O_NLN, O_OVERWRITE, O_OBJ_LOCAL, O_Q, O_CRITERION, O_OPTIMIZE,
  O_REPAIR, O_JSON, O_LAYER, O_SIZE, O_SEED, O_ITERATIONS, O_DISPLACEMENT,
  O_WAVE_SIZE, O_ROUGHNESS, O_AMPLITUDE, O_SEEDING, O_A_SRS, O_SRCNODATA,
  O_Z_FACTOR, O_Z_UNIT, O_WORK_SRS, O_T_SRS, O_ANNEAL_T0, O_ANNEAL_STAGES,
  O_ANNEAL_SWAPS, O_ANNEAL_GOOD, O_ANNEAL_R, O_METHOD, O_START, O_IMPORTANCE,
  O_SELECTION, O_ONEPASS, O_HOLE, O_THREADS, O_MAX_MEMORY, O_TERRAIN,
  O_CRITERIA, O_METHODS, O_OPTIMIZERS, O_ERROR_RASTER, O_CO,
  O_POINTS, O_PLOT, O_TIN_POINTS, O_LAYERS, O_NOSTYLE, O_TILE_SIZE,
  O_VERBOSE,
  O_S_SRS, O_A_NODATA, O_SRCWIN, O_PROJWIN, O_PROJWIN_SRS, O_A_ULLR,
  O_TIN_FRAME, O_TIN_TRANSFORM,
  O_Z_TO,
  O_FILL_NODATA,
  O_MIN_PATCH,
  O_BREAKLINES, O_BREAKLINES_LAYER, O_BREAKLINES_WHERE,
  O_COUNT
};

/* Whether option id was read (tt__app_opt_parse.given: a bit per option,
 * as many words as the options need). */
#define OPT_WORDS ((O_COUNT + 63) / 64)
#define OPT_GIVEN(p, id) ((((p)->given[(id) / 64]) >> ((id) % 64)) & 1u)
#define OPT_SET_GIVEN(p, id) ((p)->given[(id) / 64] |= (uint64_t)1 << ((id) % 64))

#define FOR_S (1u << TT_APP_SIMPLIFY)
#define FOR_G (1u << TT_APP_GENERATE)
#define FOR_E (1u << TT_APP_EVAL)
#define FOR_O (1u << TT_APP_OPTIMIZE)
#define FOR_T (1u << TT_APP_STUDY)
#define FOR_R (1u << TT_APP_RASTERIZE)

/* What kind of value an option has, so how tt__app_opt_apply reads it. */
typedef enum opt_kind {
  OPT_FLAG, /* no value: the int at `at` becomes 1 */
  OPT_TEXT, /* a word, kept, as the const char * at `at` */
  OPT_LIST, /* a word appended to the app_strlist at `at` */
  OPT_REAL, /* a finite decimal number in [lo, hi] (see OPT_GT, OPT_LT,
               OPT_NONZERO), as a double */
  OPT_INT,  /* an unsigned integer in [min, max], as an int */
  OPT_SIZE, /* an unsigned integer (OPT_MEM: a memory size) in [min, max],
               as a size_t */
  OPT_U64,  /* any unsigned 64-bit integer, as a uint64_t */
  OPT_NAME, /* a name that name_fn reads into `at` */
  OPT_OWN   /* what fits no kind above: own_fn reads it into `at` */
} opt_kind;

/* Where `at` is an offset into. */
typedef enum opt_to {
  TO_OPTIONS, /* the tt_app_options object: its settings (s.) and lists */
  TO_SYNTH    /* generate's terrain parameters as given
                 (tt__app_opt_parse.synth: they apply once the terrain's
                 kind has set its defaults) */
} opt_to;

/* tt__app_opt_def.flags */
enum {
  OPT_GT = 1u,        /* OPT_REAL: above lo, not at it */
  OPT_LT = 2u,        /* OPT_REAL: below hi, not at it */
  OPT_NONZERO = 4u,   /* OPT_REAL: 0 refused */
  OPT_PLUS_ZERO = 8u, /* OPT_REAL: -0 stored as 0 */
  OPT_MEM = 16u,      /* OPT_SIZE: bytes, or a number with K, M, G or T */
  OPT_PAIR = 32u,     /* OPT_LIST: NAME=VALUE */
  OPT_HINT = 64u,     /* an empty value's refusal ends with the help page */
  OPT_DECIMATE = 128u /* applies to -method decimate only (simplify checks
                         it once the line is read) */
};

typedef struct tt__app_opt_def tt__app_opt_def;

/* One command line being read: what options.c and the readers share. */
typedef struct tt__app_opt_parse {
  tt_app_options *o;
  tt_app_result *res;
  tt_context *ctx;          /* for the engine's name parsers */
  const char *cmdname;      /* "simplify", ...: the messages' first word */
  char hint[64];            /* " (see 'terratin simplify --help')" */
  tt_synth_options synth;   /* generate's terrain parameters as given */
  uint64_t given[OPT_WORDS]; /* a bit per option read (OPT_GIVEN) */
  const char *decimate_only; /* the first OPT_DECIMATE option read */
  const char *pos[3];       /* the positional words */
  size_t npos;
} tt__app_opt_parse;

struct tt__app_opt_def {
  const char *name;
  enum opt_id id;
  unsigned commands; /* FOR_* bits */
  opt_kind kind;
  opt_to to;
  size_t at;         /* offsetof the value's place in `to` */
  unsigned flags;    /* OPT_* */
  double lo, hi;     /* OPT_REAL's range */
  size_t min, max;   /* OPT_INT's and OPT_SIZE's range */
  /* The refusals: a bad value, "<command>: <option> <bad>, got '<word>'";
   * an empty one (OPT_TEXT, OPT_LIST; NULL: accepted), "<command>:
   * <option> <need>"; a count above max, "<command>: <option> <word> is
   * above the limit of <max> <unit>" (NULL: refused as bad); a name that
   * name_fn refuses, "<command>: unknown <option> '<word>'; known:
   * <known>" (NULL: the criteria the engine knows), unless bad is set. */
  const char *bad, *need, *unit, *known;
  /* OPT_NAME: 1 with the value at out, else 0 */
  int (*name_fn)(tt_context *ctx, const char *word, void *out);
  /* OPT_OWN: TT_OK with the value at out, else the failure recorded */
  tt_status (*own_fn)(tt__app_opt_parse *p, const tt__app_opt_def *d,
                      const char *word, void *out);
  /* The words of the value (0: one; -srcwin's four), which the parser
   * joins with spaces into the one word the reader gets. */
  unsigned nwords;
};

/* The option a word names (case-insensitive; "--of" as "-of"; '-' inside
 * the name as '_': "-max-error"), or NULL.
 * An option spelt alike for several commands (-percent: a number for
 * simplify, a list for study) is found by its first entry. */
const tt__app_opt_def *tt__app_find_opt(const char *w);
/* The option of command nearest to the unknown word w (a typo: a few
 * letters added, dropped, changed or swapped, '-' for '_', any case), for
 * "did you mean"; NULL when none is close. */
const char *tt__app_opt_suggest(const char *w, tt_app_command command);
/* The edits (insert, delete, change, swap two neighbours) from a to b,
 * without regard to case, '-' as '_'; SIZE_MAX past 63 characters. */
size_t tt__app_edit_distance(const char *a, const char *b);
/* The entry of d's spelling that command takes, or NULL. */
const tt__app_opt_def *tt__app_opt_for(const tt__app_opt_def *d,
                                       tt_app_command command);
/* How many words of value follow the option: 0 (a flag), 1, or more
 * (-srcwin xoff yoff xsize ysize: 4). */
int tt__app_opt_takes_value(const tt__app_opt_def *d);

/* Reads the value word v of option d (v is NULL for a flag) into its place
 * and marks the option given: TT_OK, TT_ERR_ARG with the usage error in
 * p->res, or TT_ERR_NOMEM. */
tt_status tt__app_opt_apply(tt__app_opt_parse *p, const tt__app_opt_def *d,
                            const char *v);

/* A copy of w in the options object's strings, or NULL (out of memory). */
const char *tt__app_opt_keep(tt_app_options *o, const char *w);

/* Records a usage error (exit code 2) in p's result and is TT_ERR_ARG:
 * `return OPT_USAGE(p, "%s: ...", ...);`. OPT_NOMEM: out of memory. */
#define OPT_USAGE(p, ...)                                                    \
  (tt__app_result_set((p)->res, TT_APP_EXIT_USAGE, TT_ERR_ARG, __VA_ARGS__), \
   TT_ERR_ARG)
#define OPT_NOMEM(p)                                                         \
  (tt__app_result_set((p)->res, TT_APP_EXIT_FAILURE, TT_ERR_NOMEM,           \
                      "out of memory"),                                      \
   TT_ERR_NOMEM)

#endif
