/*
 * option_table.h -- the options of the terratin command as data: an id per
 * option, the subcommands each applies to (a bit per tt_app_command), and
 * whether it takes a value. options.c parses with it; option_table.c holds
 * the table itself.
 */
#ifndef TT_APP_OPTION_TABLE_H
#define TT_APP_OPTION_TABLE_H

#include "app.h"

/* Which option applies to which command: one table, so the parser, the
 * error messages and the tests agree. */
enum opt_id {
  O_B, O_MAX_ERROR, O_MAX_POINTS, O_MAX_TRIANGLES, O_PERCENT, O_OF, O_LCO,
  O_DSCO, O_NLN, O_OVERWRITE, O_OBJ_LOCAL, O_Q, O_CRITERION, O_OPTIMIZE,
  O_REPAIR, O_JSON, O_LAYER, O_SIZE, O_SEED, O_ITERATIONS, O_DISPLACEMENT,
  O_WAVE_SIZE, O_ROUGHNESS, O_AMPLITUDE, O_SEEDING, O_A_SRS, O_SRCNODATA,
  O_Z_FACTOR, O_Z_UNIT, O_WORK_SRS, O_T_SRS, O_ANNEAL_T0, O_ANNEAL_STAGES,
  O_ANNEAL_SWAPS, O_ANNEAL_GOOD, O_ANNEAL_R, O_METHOD, O_START, O_IMPORTANCE,
  O_SELECTION, O_ONEPASS, O_HOLE, O_THREADS, O_MAX_MEMORY, O_TERRAIN,
  O_CRITERIA, O_METHODS, O_OPTIMIZERS, O_ERROR_RASTER, O_CO,
  O_POINTS, O_PLOT, O_TIN_POINTS, O_LAYERS, O_NOSTYLE, O_TILE_SIZE
};

#define FOR_S (1u << TT_APP_SIMPLIFY)
#define FOR_G (1u << TT_APP_GENERATE)
#define FOR_E (1u << TT_APP_EVAL)
#define FOR_O (1u << TT_APP_OPTIMIZE)
#define FOR_T (1u << TT_APP_STUDY)
#define FOR_R (1u << TT_APP_RASTERIZE)

typedef struct tt__app_opt_def {
  const char *name;
  enum opt_id id;
  int takes_value;
  unsigned commands; /* FOR_* bits */
} tt__app_opt_def;

/* The option a word names (case-insensitive; "--of" as "-of"), or NULL. */
const tt__app_opt_def *tt__app_find_opt(const char *w);

#endif
