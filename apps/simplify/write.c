/*
 * write.c -- apps/simplify/, the simplify command: the write, the last
 * step of every run (85 - 100 % of the progress), whole or tiled. By the
 * kind of output (output.c): the streamed GeoPackage's end (its rows are
 * in: the R-trees, extents, counts, the run's values), a mesh file by
 * tt_mesh_write(), or the layers through OGR by tt_ogr_write_tin() -- a
 * GeoPackage's rows and R-trees then straight into the closed file by
 * tt_gpkg_write_rows(), a database in one transaction. Then the file's
 * commit (tt_output: the temporary name renamed; a database has none).
 *
 * Invariants: an interruption or a failure leaves no file (the job's
 * tt_output removes the temporary one) and no table; the run's
 * run_parameters are taken at the write, with its timings so far.
 */
#include "simplify.h"

#include <cpl_conv.h>
#include <cpl_string.h>
#include <ogr_srs_api.h>

#include <string.h>

void tt__app_write_srs(app_simplify_job *job, const tt_raster_info *info)
{
  if (!info->crs_wkt || !*info->crs_wkt || job->srs)
    return;
  job->srs = OSRNewSpatialReference(info->crs_wkt);
  if (job->srs)
    OSRSetAxisMappingStrategy(job->srs, OAMS_TRADITIONAL_GIS_ORDER);
  else
    tt__app_warn(&job->r->msg,
                 "%s: the raster's CRS could not be parsed; the layers "
                 "have none",
                 job->s->input);
}

GDALDatasetH tt__app_write_create(app_simplify_job *job)
{
  /* Without -dsco there is nothing to validate (our own defaults are
   * valid), and GDAL 3.6's GPKG driver builds its creation option list for
   * the check by parsing its tiling schemes through PROJ: 38 M
   * instructions, 2 % of a Crater Lake run. */
  int validate = job->s->dsco && job->s->dsco[0];
  job->r->msg.last[0] = '\0';
  if (!validate)
    CPLSetThreadLocalConfigOption("GDAL_VALIDATE_CREATION_OPTIONS", "NO");
  GDALDatasetH dst = GDALCreate(job->drv, tt_output_temp_path(job->outp),
                                0, 0, 0, GDT_Unknown,
                                (CSLConstList)job->dsco);
  if (!validate)
    CPLSetThreadLocalConfigOption("GDAL_VALIDATE_CREATION_OPTIONS", NULL);
  return dst;
}

/* A writer's failure recorded: an interruption or a lack of memory as
 * such, else why the temporary file could not be written. */
static tt_status write_failed(app_simplify_job *job, tt_status st)
{
  app_run *r = job->r;
  if (st == TT_ERR_INTERRUPTED || st == TT_ERR_NOMEM)
    tt__app_fail_tt(r, st, job->s->output);
  else if (st != TT_OK)
    tt__app_fail(r, TT_APP_EXIT_FAILURE, st, job->s->output, "%s",
                 tt__app_why(r, st, tt_output_temp_path(job->outp)));
  return st;
}

/* The streamed GeoPackage's rows are in: the R-trees, extents, counts,
 * the run's values. */
static tt_status write_streamed(app_simplify_job *job)
{
  app_run_fields f;
  tt__app_simplify_fields(job, &f);
  return write_failed(job, tt__app_stream_finish(&job->so, f.v, f.n));
}

/* One file, no layers: the mesh named after OUTPUT's base name. */
static tt_status write_mesh(app_simplify_job *job)
{
  app_run *r = job->r;
  const tt_app_settings *s = job->s;
  tt__app_write_srs(job, job->info);
  r->msg.last[0] = '\0';
  char *mname = CPLStrdup(CPLGetBasename(s->output));
  tt_status st = tt_mesh_write(r->ctx, tt_output_temp_path(job->outp),
                               job->mesh, mname, job->tin, job->srs,
                               s->t_srs, s->obj_local, tt__app_phase_fn,
                               &r->prog);
  CPLFree(mname);
  return write_failed(job, st);
}

/* The file's dataset closed around the checks for a stop (the close may
 * flush for long; a stop during it is seen by the watchdog of
 * terratin.c, which removes the temporary files), and GDAL's failures
 * while closing. */
static tt_status close_file(app_simplify_job *job, int gpkg_temp)
{
  app_run *r = job->r;
  const tt_app_settings *s = job->s;
  if (!tt__app_continue(r, r->prog.hi))
    return tt__app_fail_tt(r, TT_ERR_INTERRUPTED, s->output);
  unsigned failures = r->msg.failures;
  GDALClose(job->dst);
  job->dst = NULL;
  if (gpkg_temp)
    CPLSetThreadLocalConfigOption("OGR_SQLITE_JOURNAL", NULL);
  if (!tt__app_continue(r, r->prog.hi))
    return tt__app_fail_tt(r, TT_ERR_INTERRUPTED, s->output);
  if (r->msg.failures != failures)
    return tt__app_fail_write(r, TT_ERR_IO, s->output,
                              tt_output_temp_path(job->outp),
                              "error while closing");
  return TT_OK;
}

/* GPKG: the layers through OGR, their rows to follow straight into the
 * closed file (OGR writes a feature at a time and GDAL 3.6 inserts R-tree
 * entries one by one). */
static void defer_rows(app_simplify_job *job)
{
  job->wopts = CSLSetNameValue(job->wopts, "ROWS", "DEFERRED");
  /* a temporary file: removed on failure, renamed only when complete,
   * so the journal can stay in memory and the big tables can be written
   * as database pages with SQLite closed (gpkg_rows.c) */
  job->wopts = CSLSetNameValue(job->wopts, "JOURNAL", "MEMORY");
  job->wopts = CSLSetNameValue(job->wopts, "PAGES", "YES");
  if (job->ro.threads > 0) /* -threads 1: no thread making the rows either */
    job->wopts = CSLSetNameValue(job->wopts, "THREADS",
                                 CPLSPrintf("%d", job->ro.threads));
  tt__app_phase_set(&job->r->prog, 0.85, 0.86);
}

/* The layers through OGR, into a file's dataset created now or into the
 * database opened when the output was planned (committed: the tables are
 * in place); a GeoPackage's rows then by tt_gpkg_write_rows(). */
static tt_status write_ogr(app_simplify_job *job)
{
  app_run *r = job->r;
  const tt_app_settings *s = job->s;
  const int database = job->kind == APP_OUTPUT_DATABASE;
  tt__app_write_srs(job, job->info);
  r->msg.last[0] = '\0';
  /* A GeoPackage in the temporary file: its rollback journal in memory
   * while GDAL makes the layers too (a file created and deleted for each
   * of GDAL's transactions otherwise); unset after the close. */
  const int gpkg_temp = !database && tt__app_str_ieq(job->drvname, "GPKG");
  if (gpkg_temp)
    CPLSetThreadLocalConfigOption("OGR_SQLITE_JOURNAL", "MEMORY");
  if (!database)
    job->dst = tt__app_write_create(job);
  if (!job->dst)
    return tt__app_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_IO, s->output,
                        "cannot create %s dataset: %s", job->drvname,
                        r->msg.last[0] ? r->msg.last : "unknown reason");
  app_run_fields f;
  tt__app_simplify_fields(job, &f);
  /* the heights' unit, for the fields' descriptions */
  job->wopts = CSLSetNameValue(job->wopts, "Z_UNIT",
                               job->info ? job->info->z_unit : NULL);
  const int direct_rows = tt__app_str_ieq(job->drvname, "GPKG");
  if (direct_rows)
    defer_rows(job);
  /* GDAL's LIBKML writer takes time growing as n^2.7 with the features
   * (GDAL 3.6, Jacksboro: 1,715 features 54 s, 3,586 features 248 s). */
  size_t nfeatures = job->rep.sum.vertices + job->rep.sum.triangles;
  if (tt__app_str_ieq(job->drvname, "LIBKML") && nfeatures > 1000)
    tt__app_warn(&r->msg, "%s: LIBKML writes %zu features slowly (time "
                 "grows as n^2.7 in GDAL: about a minute for 1,700, four "
                 "for 3,600); GPKG writes them in a second",
                 s->output, nfeatures);
  r->msg.last[0] = '\0';
  tt_status st = tt_ogr_write_tin(r->ctx, job->dst, job->tin, job->srs, f.v,
                                  f.n, job->wopts, tt__app_phase_fn,
                                  &r->prog);
  if (st != TT_OK)
    return tt__app_fail_write(r, st, job->shown,
                              tt_output_temp_path(job->outp), NULL);
  if (database) {
    GDALClose(job->dst);
    job->dst = NULL;
    return TT_OK;
  }
  st = close_file(job, gpkg_temp);
  if (st != TT_OK || !direct_rows)
    return st;
  tt__app_phase_set(&r->prog, 0.86, 0.99);
  st = tt_gpkg_write_rows(r->ctx, tt_output_temp_path(job->outp), job->tin,
                          job->srs, job->wopts, tt__app_phase_fn, &r->prog);
  return write_failed(job, st);
}

/* The file renamed into place (a database's tables are already). */
static tt_status commit(app_simplify_job *job)
{
  app_run *r = job->r;
  const char *output = job->s->output;
  if (!tt__app_continue(r, 0.99))
    return tt__app_fail_tt(r, TT_ERR_INTERRUPTED, output);
  tt_status st = tt_output_commit(r->ctx, job->outp);
  if (st == TT_ERR_EXISTS)
    tt__app_fail_exists(r, output); /* it appeared while we worked */
  else if (st != TT_OK)
    tt__app_fail_tt(r, st, output);
  return st;
}

tt_status tt__app_simplify_write(app_simplify_job *job)
{
  app_run *r = job->r;
  double t = tt__app_now();
  tt__app_phase_set(&r->prog, 0.85, 0.99);
  if (!tt__app_continue(r, 0.85))
    return tt__app_fail_tt(r, TT_ERR_INTERRUPTED, job->s->output);
  tt_status st = job->kind == APP_OUTPUT_STREAM ? write_streamed(job)
                 : job->kind == APP_OUTPUT_MESH ? write_mesh(job)
                                                : write_ogr(job);
  if (st == TT_OK && job->kind != APP_OUTPUT_DATABASE)
    st = commit(job);
  if (st != TT_OK)
    return st;
  job->rep.t_write = tt__app_now() - t;
  job->rep.t_total = tt__app_now() - r->t0;
  tt__app_continue(r, 1.0);
  return TT_OK;
}
