/*
 * tiles_merge.c -- apps/tiles/: the tiles command, a folder over the core
 * (apps/core/), simplify's tiled run as independent jobs for a cluster. This
 * file: `terratin tiles merge PLAN.json OUT.gpkg [-overwrite] [-q] [-json]
 * [output options]`: every piece of a plan read back (tt_tin_piece_decode)
 * and merged by simplify's tiled path (tiled.c) in tile order, written as
 * simplify writes (triangles, vertices, run_parameters; temporary name,
 * rename, nothing left behind on failure or interruption): the same layers
 * as `simplify -tile_size` with the plan's options and the output options
 * of this command line (-of, -lco, ...: the user's, which a plan never
 * carries). A missing piece, or one of another plan (stale), is refused
 * before anything is written.
 */
#include "tiles.h"
#include "option_table.h"

#include <cpl_conv.h>
#include <cpl_string.h>
#include <cpl_vsi.h>

#include <errno.h>
#include <stdlib.h>
#include <string.h>

static tt_status load(void *arg, tt_context *ctx, size_t k, tt_tin **piece,
                      char *msg, size_t msgsize)
{
  const tiles_plan *p = arg;
  char *path = tt__tiles_piece_path(p, k);
  GByte *buf = NULL;
  vsi_l_offset len = 0;
  tt_status st = TT_OK;
  if (!VSIIngestFile(NULL, path, &buf, &len, -1)) {
    snprintf(msg, msgsize, "%s: missing; run `terratin tiles run %s %zu`",
             path, p->path, k);
    st = TT_ERR_DATA;
  } else {
    st = tt_tin_piece_decode(ctx, buf, (size_t)len,
                             tt__tiles_piece_tag(p, k), piece);
    if (st != TT_OK)
      snprintf(msg, msgsize, "%s: %s; run `terratin tiles run %s %zu "
               "-overwrite`", path, tt_context_errmsg(ctx), p->path, k);
  }
  CPLFree(buf);
  CPLFree(path);
  return st;
}

void tt__tiles_merge(char **argv, tt_progress_fn fn, void *arg,
                     tt_app_result *res)
{
  const char *plan = NULL, *out = NULL;
  char **extra = NULL;
  for (size_t i = 0; argv[i]; i++) {
    int out_opt = tt__tiles_output_option(argv[i]);
    if (tt__app_str_ieq(argv[i], "-overwrite") ||
        tt__app_str_ieq(argv[i], "-q") || tt__app_str_ieq(argv[i], "-json") ||
        out_opt == 0)
      extra = CSLAddString(extra, argv[i]);
    else if (out_opt == 1 && argv[i + 1]) {
      extra = CSLAddString(extra, argv[i]);
      extra = CSLAddString(extra, argv[++i]);
    } else if (argv[i][0] == '-' && argv[i][1]) {
      /* a typo of one of merge's options: the nearest (simplify's
       * table), when merge takes it */
      const char *near = tt__app_opt_suggest(argv[i], TT_APP_SIMPLIFY);
      if (near && tt__tiles_output_option(near) < 0 &&
          !tt__app_str_ieq(near, "-overwrite") &&
          !tt__app_str_ieq(near, "-q") && !tt__app_str_ieq(near, "-json"))
        near = NULL;
      if (out_opt == 1)
        tt__app_result_set(res, TT_APP_EXIT_USAGE, TT_ERR_ARG,
                           "tiles merge: option %s needs a value", argv[i]);
      else if (near)
        tt__app_result_set(res, TT_APP_EXIT_USAGE, TT_ERR_ARG,
                           "tiles merge: unknown option '%s'; did you mean "
                           "%s? (see 'terratin tiles merge --help')",
                           argv[i], near);
      else
        tt__app_result_set(res, TT_APP_EXIT_USAGE, TT_ERR_ARG,
                           "tiles merge: unknown option %s (see 'terratin "
                           "tiles merge --help': -overwrite, -q, -json, "
                           "-of, -lco, -dsco, -nln, -layers, -nostyle, "
                           "-obj_local, -t_srs)", argv[i]);
      CSLDestroy(extra);
      return;
    } else if (!plan)
      plan = argv[i];
    else if (!out)
      out = argv[i];
    else {
      tt__app_result_set(res, TT_APP_EXIT_USAGE, TT_ERR_ARG,
                         "tiles merge: unexpected argument %s", argv[i]);
      CSLDestroy(extra);
      return;
    }
  }
  if (!plan || !out) {
    tt__app_result_set(res, TT_APP_EXIT_USAGE, TT_ERR_ARG,
                       "tiles merge: PLAN.json and OUTPUT are needed (see "
                       "'terratin tiles merge --help')");
    CSLDestroy(extra);
    return;
  }
  tiles_plan p;
  if (tt__tiles_plan_read(plan, &p, res)) {
    /* every piece there first: a clear refusal before any work */
    size_t missing = 0, first = 0;
    for (size_t k = 0; k < p.tiles; k++) {
      char *path = tt__tiles_piece_path(&p, k);
      VSIStatBufL sb;
      if (VSIStatL(path, &sb) != 0 && missing++ == 0)
        first = k;
      CPLFree(path);
    }
    if (missing) {
      char *path = tt__tiles_piece_path(&p, first);
      tt__app_result_set(res, TT_APP_EXIT_FAILURE, TT_ERR_DATA,
                         "%s: %zu of %zu tile pieces missing (the first: %s); "
                         "run `terratin tiles run %s TILE_ID` for each; "
                         "nothing written", plan, missing, p.tiles, path, plan);
      CPLFree(path);
    } else {
      tt__app_tiles_hook.load = load;
      tt__app_tiles_hook.arg = &p;
      tt__tiles_simplify(&p, (const char *const *)extra, out, fn, arg, res);
    }
  }
  tt__tiles_plan_free(&p);
  CSLDestroy(extra);
}
