/*
 * option_table.c -- the table of the terratin command's options (see
 * option_table.h) and the look-up of a word in it. Adding an option: an id
 * in option_table.h, a line here, its case in options.c's parser.
 *
 * Workload: a linear search over some 70 names per word of the command line.
 */
#include "option_table.h"

static const tt__app_opt_def opt_defs[] = {
    {"-b", O_B, 1, FOR_S | FOR_E | FOR_O | FOR_T | FOR_R},
    {"-max_error", O_MAX_ERROR, 1, FOR_S | FOR_E | FOR_O},
    {"-max_points", O_MAX_POINTS, 1, FOR_S},
    {"-max_triangles", O_MAX_TRIANGLES, 1, FOR_S},
    {"-percent", O_PERCENT, 1, FOR_S | FOR_T}, /* study: a list */
    {"-of", O_OF, 1, FOR_S | FOR_O | FOR_R},
    {"-f", O_OF, 1, FOR_S | FOR_O}, /* ogr2ogr's spelling */
    {"-lco", O_LCO, 1, FOR_S | FOR_O},
    {"-dsco", O_DSCO, 1, FOR_S | FOR_O},
    {"-nln", O_NLN, 1, FOR_S | FOR_O},
    {"-overwrite", O_OVERWRITE, 0,
     FOR_S | FOR_G | FOR_E | FOR_O | FOR_T | FOR_R},
    {"-obj_local", O_OBJ_LOCAL, 0, FOR_S},
    {"-q", O_Q, 0, FOR_S | FOR_G | FOR_E | FOR_O | FOR_T | FOR_R},
    {"-quiet", O_Q, 0, FOR_S | FOR_G | FOR_E | FOR_O | FOR_T | FOR_R},
    {"-criterion", O_CRITERION, 1, FOR_S | FOR_O},
    {"-optimize", O_OPTIMIZE, 1, FOR_S | FOR_O},
    {"-repair", O_REPAIR, 1, FOR_S},
    {"-json", O_JSON, 0, FOR_S | FOR_E | FOR_O | FOR_R},
    {"-layer", O_LAYER, 1, FOR_E | FOR_O | FOR_R},
    {"-size", O_SIZE, 1, FOR_G},
    {"-seed", O_SEED, 1, FOR_G | FOR_S | FOR_O | FOR_T},
    {"-iterations", O_ITERATIONS, 1, FOR_G},
    {"-displacement", O_DISPLACEMENT, 1, FOR_G},
    {"-wave_size", O_WAVE_SIZE, 1, FOR_G},
    {"-roughness", O_ROUGHNESS, 1, FOR_G},
    {"-amplitude", O_AMPLITUDE, 1, FOR_G},
    {"-seeding", O_SEEDING, 1, FOR_G},
    {"-a_srs", O_A_SRS, 1, FOR_G},
    {"-srcnodata", O_SRCNODATA, 1, FOR_S | FOR_E | FOR_O | FOR_T | FOR_R},
    {"-z_factor", O_Z_FACTOR, 1, FOR_S | FOR_E | FOR_O | FOR_T | FOR_R},
    {"-z_unit", O_Z_UNIT, 1, FOR_S | FOR_E | FOR_O | FOR_T | FOR_R},
    {"-work_srs", O_WORK_SRS, 1, FOR_S},
    {"-t_srs", O_T_SRS, 1, FOR_S},
    {"-anneal_t0", O_ANNEAL_T0, 1, FOR_S | FOR_O | FOR_T},
    {"-anneal_stages", O_ANNEAL_STAGES, 1, FOR_S | FOR_O | FOR_T},
    {"-anneal_swaps", O_ANNEAL_SWAPS, 1, FOR_S | FOR_O | FOR_T},
    {"-anneal_good", O_ANNEAL_GOOD, 1, FOR_S | FOR_O | FOR_T},
    {"-anneal_r", O_ANNEAL_R, 1, FOR_S | FOR_O | FOR_T},
    {"-method", O_METHOD, 1, FOR_S},
    {"-start", O_START, 1, FOR_S | FOR_T},
    {"-importance", O_IMPORTANCE, 1, FOR_S | FOR_T},
    {"-selection", O_SELECTION, 1, FOR_S},
    {"-onepass", O_ONEPASS, 0, FOR_S},
    {"-hole", O_HOLE, 1, FOR_S},
    {"-threads", O_THREADS, 1, FOR_S | FOR_T},
    {"-max_memory", O_MAX_MEMORY, 1, FOR_S | FOR_E | FOR_R},
    {"-tile_size", O_TILE_SIZE, 1, FOR_S},
    {"-terrain", O_TERRAIN, 1, FOR_T},
    {"-criteria", O_CRITERIA, 1, FOR_T},
    {"-methods", O_METHODS, 1, FOR_T},
    {"-optimizers", O_OPTIMIZERS, 1, FOR_T},
    {"-error_raster", O_ERROR_RASTER, 1, FOR_E},
    {"-co", O_CO, 1, FOR_E | FOR_R},
    {"-points", O_POINTS, 1, FOR_T},
    {"-plot", O_PLOT, 0, FOR_T},
    {"-tin_points", O_TIN_POINTS, 1, FOR_T},
    {"-layers", O_LAYERS, 1, FOR_S},
    {"-nostyle", O_NOSTYLE, 0, FOR_S},
};

const tt__app_opt_def *tt__app_find_opt(const char *w)
{
  for (size_t i = 0; i < sizeof opt_defs / sizeof opt_defs[0]; i++)
    if (tt__app_str_ieq(w, opt_defs[i].name))
      return &opt_defs[i];
  /* GDAL accepts --of as well as -of for its own options: do the same,
   * with exactly two dashes ("---of" is a typo, not an option). */
  if (w[0] == '-' && w[1] == '-' && w[2] != '\0' && w[2] != '-')
    return tt__app_find_opt(w + 1);
  return NULL;
}

