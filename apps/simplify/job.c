/*
 * job.c -- apps/simplify/, the simplify command: its job description
 * (app_simplify_job, simplify.h) made from the settings that
 * apps/core/options.c parsed, as GDAL's GDALTranslateOptionsNew() makes
 * one options object of argv. Every option of the method is read here,
 * once, for both the whole and the tiled run: the limits, the criterion,
 * the optimiser and the repair into the refinement options, the same and
 * the decimation's own into the decimation options; then what the run
 * finds out fills them in (the threads, the memory limit, the default
 * bound). The job's release is here too.
 *
 * Invariants: the refinement and decimation options always hold the same
 * limits, criterion, optimiser, threads and progress; nothing is opened
 * by tt__app_job_init().
 */
#include "simplify.h"

#include <cpl_conv.h>
#include <cpl_string.h>
#include <ogr_srs_api.h>

#include <stdint.h>
#include <string.h>
#include <sys/resource.h>
#include <unistd.h>
#ifdef __GLIBC__
#include <malloc.h>
#endif

/* The decimation options of the command: ro's limits, criterion and
 * passes, and the -start, -importance, -selection, -onepass, -hole. */
static void decimate_options(const tt_app_settings *s,
                             const tt_refine_options *ro,
                             tt_decimate_options *dopt)
{
  tt_decimate_options_init(dopt);
  dopt->max_error = ro->max_error;
  dopt->max_points = ro->max_points;
  dopt->max_triangles = ro->max_triangles;
  dopt->percent = ro->percent;
  dopt->criterion = ro->criterion;
  dopt->optimize = ro->optimize;
  dopt->anneal = ro->anneal;
  dopt->repair = ro->repair;
  dopt->start = s->start;
  dopt->start_points = s->start_points;
  dopt->importance = s->importance;
  dopt->selection = s->selection;
  dopt->onepass = s->onepass;
  dopt->hole = s->hole;
  dopt->progress = ro->progress;
  dopt->progress_arg = ro->progress_arg;
  dopt->threads = ro->threads;
}

void tt__app_job_init(app_simplify_job *job, app_run *r)
{
  const tt_app_settings *s = r->s;
  memset(job, 0, sizeof *job);
  job->r = r;
  job->s = s;
  job->rep.t_srs = s->t_srs;
  job->decimate = s->decimate;
  tt_refine_options_init(&job->ro);
  job->ro.max_error = s->max_error;
  job->ro.max_points = s->max_points;
  job->ro.max_triangles = s->max_triangles;
  job->ro.percent = s->percent;
  job->ro.criterion = s->criterion;
  job->ro.optimize = s->optimize;
  job->ro.anneal = s->anneal;
  job->ro.repair = s->repair;
  /* the run's progress (a tiled run gives each tile its own) */
  job->ro.progress = tt__app_phase_fn;
  job->ro.progress_arg = &r->prog;
  decimate_options(s, &job->ro, &job->dopt);
  job->kind = APP_OUTPUT_FILE;
  tt__app_mask_password(s->output, job->shown, sizeof job->shown);
}

/* -work_srs and -t_srs: a CRS GDAL understands (usage error otherwise);
 * -work_srs must also be projected. */
static int check_srs(app_run *r, const char *option, const char *value,
                     int projected)
{
  if (!value)
    return 1;
  OGRSpatialReferenceH srs = OSRNewSpatialReference(NULL);
  r->msg.last[0] = '\0';
  int ok = srs && OSRSetFromUserInput(srs, value) == OGRERR_NONE;
  if (!ok)
    tt__app_fail(r, TT_APP_EXIT_USAGE, TT_ERR_ARG, NULL,
             "simplify: %s '%s' is not a CRS GDAL understands%s%s", option,
             value, r->msg.last[0] ? ": " : "", r->msg.last);
  else if (projected && !OSRIsProjected(srs)) {
    tt__app_fail(r, TT_APP_EXIT_USAGE, TT_ERR_ARG, NULL,
             "simplify: %s '%s' is not a projected CRS: the working frame "
             "must be in metres", option, value);
    ok = 0;
  }
  if (srs)
    OSRDestroySpatialReference(srs);
  return ok;
}

tt_status tt__app_job_check(app_simplify_job *job)
{
  app_run *r = job->r;
  const tt_app_settings *s = job->s;
  if (tt__app_same_file(s->input, s->output))
    return tt__app_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_ARG, s->output,
                    "is the input raster; refusing to replace it");
  if (!check_srs(r, "-work_srs", s->work_srs, 1) ||
      !check_srs(r, "-t_srs", s->t_srs, 0))
    return r->res->status;
  return TT_OK;
}

/* Under ulimit -v (RLIMIT_AS) every thread's malloc arena counts: glibc
 * reserves 64 MiB of address space for each, and a realloc that its full
 * arena cannot hold fails rather than move to another, so that the worker
 * threads of a tiled run failed at random (1 run in 16 at 90 MB of room,
 * test_auto_tiling.sh) with memory to spare. One arena then, for the
 * process: the threads share it. */
static void one_arena_under_rlimit_as(void)
{
#ifdef __GLIBC__
  struct rlimit rl;
  if (getrlimit(RLIMIT_AS, &rl) == 0 && rl.rlim_cur != RLIM_INFINITY)
    mallopt(M_ARENA_MAX, 1);
#endif
}

tt_status tt__app_job_memory(app_simplify_job *job)
{
  one_arena_under_rlimit_as();
  const tt_app_settings *s = job->s;
  /* -max_memory, else what the system allows, asked before the DEM is
   * read (the heights count against it) */
  job->mem_source = "-max_memory";
  job->mem_limit = s->max_memory ? s->max_memory
                                 : tt_memory_limit(&job->mem_source);
  job->ro.max_memory = job->mem_limit == SIZE_MAX ? 0 : job->mem_limit;
  job->rep.mem_limit = job->mem_limit;
  job->rep.mem_source = job->mem_source;
  /* Decimation does not count its memory as it goes (its start holds a
   * triangle per half sample): an explicit limit would be a promise it
   * cannot keep. Refused before anything is read. */
  if (job->decimate && s->max_memory)
    return tt__app_fail(job->r, TT_APP_EXIT_USAGE, TT_ERR_ARG, NULL,
                        "simplify: -max_memory bounds -method insert only; "
                        "decimation does not count its memory yet");
  return TT_OK;
}

void tt__app_job_threads(app_simplify_job *job)
{
  int threads = tt__app_threads(job->r);
  job->ro.threads = threads;
  job->dopt.threads = threads;
  job->workers = threads > 0 ? threads : (int)sysconf(_SC_NPROCESSORS_ONLN);
  if (job->workers < 1)
    job->workers = 1;
}

int tt__app_job_default_wanted(const app_simplify_job *job)
{
  const tt_refine_options *ro = &job->ro;
  return ro->max_error < 0 && !ro->max_points && !ro->max_triangles &&
         !(ro->percent > 0);
}

void tt__app_job_default_bound(app_simplify_job *job, const app_step *step)
{
  job->rep.step = tt__app_step_mean(step);
  job->ro.max_error = tt__app_default_bound_of(step);
  job->dopt.max_error = job->ro.max_error;
  job->rep.default_error = 1;
}

void tt__app_job_free(app_simplify_job *job)
{
  if (job->dst)
    GDALClose(job->dst);
  CPLSetThreadLocalConfigOption("OGR_SQLITE_JOURNAL", NULL);
  if (job->src)
    tt__app_close_raster(job->r, job->src);
  /* an unfinished streamed write undone, then the temporary files removed
   * unless committed */
  tt__app_stream_close(&job->so);
  tt_output_destroy(job->outp);
  if (job->srs)
    OSRDestroySpatialReference(job->srs);
  CSLDestroy(job->wopts);
  CPLFree(job->t_srs_auto);
  CSLDestroy(job->dsco);
  tt_tin_destroy(job->tin);
  free(job->bl_ends);
  tt_grid_destroy(job->grid);
  tt_raster_info_destroy(job->info);
}
