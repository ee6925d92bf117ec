/*
 * study_crater.c -- apps/study/: the study command, a folder over the core
 * (apps/core/). This file: where `terratin study -terrain crater` finds Crater
 * Lake, the DEM of the 2004 study's Tables 1 and 2 (336 x 459 samples,
 * garland_heckbert_terra_scape/crater.stm.vrt of the shared test data, see its
 * CATALOG.md). "crater=PATH" reads PATH instead; "crater" looks in
 * $TT_SHARED_TESTDATA when it is set (and nowhere else then), else in
 * ../shared/testdata of the current directory, then ../shared/testdata beside
 * the source tree the command was built from. The terrain is labelled "crater"
 * either way.
 */
#include "study.h"

#include <cpl_conv.h>
#include <cpl_string.h>

#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#define CRATER_FILE "garland_heckbert_terra_scape/crater.stm.vrt"

#ifndef TT_SOURCE_DIR
#define TT_SOURCE_DIR "."
#endif

int tt__app_study_crater(app_run *r, const char *arg, char **out_path)
{
  *out_path = NULL;
  if (tt__app_str_ieq(arg, "crater")) {
    const char *env = getenv("TT_SHARED_TESTDATA");
    const char *dirs[3] = {env, "../shared/testdata",
                           TT_SOURCE_DIR "/../shared/testdata"};
    if (env && *env)
      dirs[1] = dirs[2] = NULL;
    else
      dirs[0] = NULL;
    for (int i = 0; i < 3; i++) {
      if (!dirs[i])
        continue;
      const char *p = CPLSPrintf("%s/%s", dirs[i], CRATER_FILE);
      if (access(p, R_OK) == 0) {
        *out_path = CPLStrdup(p);
        return 1;
      }
    }
    if (env && *env)
      tt__app_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_IO, NULL,
                   "study: -terrain crater: Crater Lake (%s) is not in "
                   "TT_SHARED_TESTDATA=%s; give the DEM as -terrain "
                   "crater=PATH", CRATER_FILE, env);
    else
      tt__app_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_IO, NULL,
                   "study: -terrain crater: Crater Lake (%s) is neither in "
                   "../shared/testdata nor in %s/../shared/testdata; give "
                   "the DEM as -terrain crater=PATH or set "
                   "TT_SHARED_TESTDATA", CRATER_FILE, TT_SOURCE_DIR);
    return -1;
  }
  if (!strncmp(arg, "crater=", 7) || !strncmp(arg, "CRATER=", 7)) {
    if (!arg[7]) {
      tt__app_fail(r, TT_APP_EXIT_USAGE, TT_ERR_ARG, NULL,
                   "study: -terrain crater= needs the path of the DEM");
      return -1;
    }
    *out_path = CPLStrdup(arg + 7);
    return 1;
  }
  return 0;
}
