/*
 * tiles.h -- apps/tiles/: the tiles command, a folder over the core
 * (apps/core/), simplify's tiled run as independent jobs for a cluster. This
 * header: what `terratin tiles plan`, `tiles run` and `tiles merge` share
 * (tiles_plan.c, tiles_run.c, tiles_merge.c): the plan as read back and
 * simplify's command line rebuilt from it.
 */
#ifndef TT_APP_TILES_H
#define TT_APP_TILES_H

#include "app.h"

typedef struct tiles_plan {
  char *path;          /* PLAN.json as given */
  char *dem;           /* the DEM's absolute path */
  uint64_t dem_bytes, dem_mtime_ns;
  size_t width, height, tile_size, tiles;
  char **options;      /* simplify's options, NULL-terminated (CSL) */
  char *pieces;        /* the pieces' folder: PLAN.json's path + ".tiles" */
  uint64_t hash;       /* FNV-1a 64 of the plan's bytes */
} tiles_plan;

/* Reads PLAN.json and checks that its DEM has not changed (size and
 * modification time); false with res set otherwise. */
bool tt__tiles_plan_read(const char *path, tiles_plan *p, tt_app_result *res);
void tt__tiles_plan_free(tiles_plan *p);
/* The piece file of tile k (CPLFree it) and its tag (plan and tile). */
char *tt__tiles_piece_path(const tiles_plan *p, size_t k);
uint64_t tt__tiles_piece_tag(const tiles_plan *p, size_t k);
/* Runs simplify's tiled path on the plan's DEM and options, with extra
 * words before the two names, writing output, under the hook that is
 * set (tt__app_tiles_hook); cleared after. */
void tt__tiles_simplify(const tiles_plan *p, const char *const *extra,
                        const char *output, tt_progress_fn fn, void *arg,
                        tt_app_result *res);

void tt__tiles_run(char **argv, tt_progress_fn fn, void *arg,
                   tt_app_result *res);
void tt__tiles_merge(char **argv, tt_progress_fn fn, void *arg,
                     tt_app_result *res);

#endif
