/*
 * tiles_run.c -- apps/tiles/: the tiles command, a folder over the core
 * (apps/core/), simplify's tiled run as independent jobs for a cluster. This
 * file: `terratin tiles run PLAN.json TILE_ID [-overwrite]`: one tile of a plan
 * refined (simplify's tiled path, tiled.c, on that tile alone) and its piece
 * written to PLAN.json.tiles/TILE_ID.ttp (tt_tin_piece_encode: exact values,
 * the plan's hash, a checksum) through a temporary name and a rename, so a
 * piece is whole or absent.
 */
#include "tiles.h"
#include "option_table.h"

#include <cpl_conv.h>
#include <cpl_string.h>
#include <cpl_vsi.h>

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

typedef struct run_arg {
  const tiles_plan *plan;
  int overwrite;
  char *piece; /* the piece's file */
} run_arg;

static tt_status save(void *arg, app_run *r, size_t k, const tt_tin *piece)
{
  run_arg *a = arg;
  void *buf = NULL;
  size_t len = 0;
  tt_status st = tt_tin_piece_encode(r->ctx, piece,
                                     tt__tiles_piece_tag(a->plan, k), &buf,
                                     &len);
  if (st != TT_OK)
    return tt__app_fail_tt(r, st, a->piece);
  VSIStatBufL sb;
  if (!a->overwrite && VSIStatL(a->piece, &sb) == 0) {
    free(buf);
    return tt__app_fail_exists(r, a->piece);
  }
  char *tmp = CPLStrdup(CPLSPrintf("%s.tmp%ld", a->piece, (long)getpid()));
  FILE *f = fopen(tmp, "wb");
  int bad = !f || fwrite(buf, 1, len, f) != len;
  if (f && fclose(f) != 0)
    bad = 1;
  int err = errno;
  free(buf);
  if (bad || rename(tmp, a->piece) != 0) {
    if (!bad)
      err = errno;
    VSIUnlink(tmp);
    CPLFree(tmp);
    return tt__app_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_IO, a->piece,
                        "cannot write the piece (%s)", strerror(err));
  }
  CPLFree(tmp);
  return TT_OK;
}

void tt__tiles_run(char **argv, tt_progress_fn fn, void *arg,
                   tt_app_result *res)
{
  const char *plan = NULL, *id = NULL;
  run_arg a;
  memset(&a, 0, sizeof a);
  for (size_t i = 0; argv[i]; i++) {
    if (tt__app_str_ieq(argv[i], "-overwrite"))
      a.overwrite = 1;
    else if (argv[i][0] == '-' && argv[i][1] &&
             tt__app_edit_distance(argv[i], "-overwrite") <= 2) {
      tt__app_result_set(res, TT_APP_EXIT_USAGE, TT_ERR_ARG,
                         "tiles run: unknown option '%s'; did you mean "
                         "-overwrite? (see 'terratin tiles run --help')",
                         argv[i]);
      return;
    } else if (argv[i][0] == '-' && argv[i][1]) {
      tt__app_result_set(res, TT_APP_EXIT_USAGE, TT_ERR_ARG,
                         "tiles run: unknown option %s (see 'terratin "
                         "tiles run --help': -overwrite only)", argv[i]);
      return;
    } else if (!plan)
      plan = argv[i];
    else if (!id)
      id = argv[i];
    else {
      tt__app_result_set(res, TT_APP_EXIT_USAGE, TT_ERR_ARG,
                         "tiles run: unexpected argument %s", argv[i]);
      return;
    }
  }
  char *e = NULL;
  errno = 0;
  unsigned long long k = id ? strtoull(id, &e, 10) : 0;
  if (!plan || !id || !*id || *e || errno || id[0] == '-') {
    tt__app_result_set(res, TT_APP_EXIT_USAGE, TT_ERR_ARG,
                       "tiles run: PLAN.json and a TILE_ID (a whole number "
                       "from 0) are needed (see 'terratin tiles run "
                       "--help')");
    return;
  }
  tiles_plan p;
  if (!tt__tiles_plan_read(plan, &p, res)) {
    tt__tiles_plan_free(&p);
    return;
  }
  if (k >= p.tiles) {
    tt__app_result_set(res, TT_APP_EXIT_USAGE, TT_ERR_ARG,
                       "%s: no tile %s: the plan has tiles 0 to %zu", plan,
                       id, p.tiles - 1);
    tt__tiles_plan_free(&p);
    return;
  }
  a.plan = &p;
  a.piece = tt__tiles_piece_path(&p, (size_t)k);
  VSIStatBufL sb;
  if (!a.overwrite && VSIStatL(a.piece, &sb) == 0) {
    tt__app_result_set(res, TT_APP_EXIT_FAILURE, TT_ERR_EXISTS,
                       "%s: exists; use -overwrite to replace it", a.piece);
  } else {
    /* simplify's output is planned (and never written): a name in the
     * pieces' folder */
    char *out = CPLStrdup(CPLSPrintf("%s/.run%llu-%ld.gpkg", p.pieces, k,
                                     (long)getpid()));
    const char *extra[] = {"-q", "-threads", "1", NULL};
    tt__app_tiles_hook.tile = (size_t)k;
    tt__app_tiles_hook.save = save;
    tt__app_tiles_hook.arg = &a;
    tt__tiles_simplify(&p, extra, out, fn, arg, res);
    CPLFree(out);
  }
  CPLFree(a.piece);
  tt__tiles_plan_free(&p);
}
