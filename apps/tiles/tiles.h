/*
 * tiles.h -- apps/tiles/: the tiles command, a folder over the core
 * (apps/core/), simplify's tiled run as independent jobs for a cluster. This
 * header: what `terratin tiles plan`, `tiles run` and `tiles merge` share
 * (tiles_plan.c, tiles_plan_file.c, tiles_run.c, tiles_merge.c): the plan as
 * read back, the options a plan may carry, and simplify's command line
 * rebuilt from it.
 */
#ifndef TT_APP_TILES_H
#define TT_APP_TILES_H

#include "app.h"

/* A plan file is at most this large (about a million tiles). */
#define TT_TILES_PLAN_MAX_BYTES (64u << 20)

typedef struct tiles_plan {
  char *path;          /* PLAN.json as given */
  char *dem;           /* the DEM's absolute, canonical path */
  uint64_t dem_bytes, dem_mtime_ns;
  size_t width, height, tile_size;
  size_t tiles_x, tiles_y, tiles; /* the tiles' grid, row-major */
  char **options;      /* simplify's options, NULL-terminated (CSL) */
  char *pieces;        /* the pieces' folder: PLAN.json's path + ".tiles" */
  uint64_t hash;       /* FNV-1a 64 of the plan's bytes */
} tiles_plan;

/* The tiles' grid of width x height samples in tiles of tile_size cells:
 * sets tiles_x, tiles_y and tiles. */
void tt__tiles_grid(tiles_plan *p);
/* The plan's text as `tiles plan` writes it, from dem to the closing
 * checksum, with *out_len its length; NULL when it would pass
 * TT_TILES_PLAN_MAX_BYTES. The caller frees it with CPLFree. */
char *tt__tiles_plan_text(const tiles_plan *p, size_t *out_len);
/* Whether words (simplify's options, NULL-terminated) are what a plan may
 * carry: -NAME [VALUE] pairs of the options that shape the TIN, short
 * words of printable characters, no path; false with the option named in
 * res (exit code 2, the message starting with who) otherwise. */
bool tt__tiles_plan_check_words(const char *who, char *const *words,
                                tt_app_result *res);
/* Whether w is an option of simplify's output, which `tiles merge` takes
 * on its own command line and a plan never carries: -1 no, 0 a flag, 1 an
 * option followed by a value. */
int tt__tiles_output_option(const char *w);

/* Reads PLAN.json and checks it as input, never as trusted code: whole
 * (its closing checksum), every field against the DEM it names (which has
 * not changed: size and modification time), its options those a plan may
 * carry, and its text byte for byte what `tiles plan` writes from them;
 * false with res set otherwise. tt__tiles_plan_free(p) either way. */
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
