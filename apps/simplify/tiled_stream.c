/*
 * tiled_stream.c -- apps/simplify/, the simplify command: a tiled run's
 * GeoPackage built as its tiles merge (issue 19, docs/scale.md): the
 * layers are made when the first piece is about to merge, every piece's
 * rows are appended to them at once (tiled.c, src/tile/stream.c,
 * src/gdal/gpkg/gpkg_stream.c), and after the
 * last tile the R-trees, extents, counts, the run_parameters row and the
 * styles are written. The rows are those the merged-TIN path writes for
 * the same run, byte for byte; memory is the tiles in flight, about one
 * row of tiles of vertices waiting for their last tile, and what the
 * writer keeps for the end (the R-trees' leaves' boxes, about half a
 * byte a feature, their leaves being packed as the rows come; 8 bytes a
 * vertex for the style, 4 a vertex for the count of pieces).
 *
 * Every tiled run into a GeoPackage file streams: insertion and
 * decimation (the vertices layer then has the importance field), to a
 * bound or a budget, projected, geographic or Web Mercator DEMs (the
 * triangles measured on their pieces' ground points). A budget's pass
 * whose TIN is not kept (tiled.c: it passes the budget, or falls short of
 * it before the bound is calibrated) has its rows dropped (discard: the
 * writer closed, the temporary file removed) and the next pass creates
 * the file again when its first piece merges, so the file written is the
 * last pass's alone, made exactly as a single pass makes it.
 *
 * Like every output, the file is the temporary name of tt_output (removed
 * on any failure or interruption, renamed only when complete).
 *
 * Only for a GeoPackage file (not a database, a mesh or another OGR
 * format, which take the merged TIN as before), and unless
 * TERRATIN_TILE_STREAM=NO (a configuration option or environment
 * variable) asks for the merged-TIN path.
 */
#include "simplify.h"
#include "gdal/gpkg/gpkg_stream.h"
#include "tin/tin.h"

#include <cpl_conv.h>
#include <cpl_string.h>
#include <ogr_srs_api.h>

#include <string.h>

int tt__app_stream_wanted(const char *drvname)
{
  return tt__app_str_ieq(drvname, "GPKG") &&
         CPLTestBool(CPLGetConfigOption("TERRATIN_TILE_STREAM", "YES"));
}

int tt__app_stream_possible(app_simplify_job *job)
{
  app_run *r = job->r;
  GDALDatasetH dst = tt__app_write_create(job);
  if (!dst) /* the writer will say why, when it tries */
    return 1;
  GDALClose(dst);
  const char *temp = tt_output_temp_path(job->outp);
  int ok = tt__gpkg_pages_check(r->ctx, temp) == TT_OK;
  if (!ok)
    CPLDebug("terratin", "%s: not streamed as the tiles merge, the rows "
             "go through SQLite after the last tile: %s", temp,
             tt_context_errmsg(r->ctx));
  tt_context_clear_error(r->ctx);
  r->msg.last[0] = '\0';
  tt_output_clear(job->outp);
  return ok;
}

/* The layers (as tt_ogr_write_tin(ROWS=DEFERRED) makes them for the
 * merged TIN, from an empty TIN and the run's fields so far), then the
 * rows' writer. */
static tt_status stream_open(tt_app_tile_sink *sink,
                             const tt_raster_info *info, double max_error)
{
  app_simplify_job *job = ((tt_app_stream *)sink)->job;
  app_run *r = job->r;
  const char *temp = tt_output_temp_path(job->outp);
  tt_status st = TT_OK;
  if (!info)
    return tt__error(r->ctx, TT_ERR_INTERNAL, "no raster facts from tile 0");
  tt__app_write_srs(job, info);
  job->ro.max_error = max_error;
  job->rep.info = info;
  app_run_fields f;
  tt__app_simplify_fields(job, &f);
  job->wopts = CSLSetNameValue(job->wopts, "Z_UNIT", info->z_unit);
  job->wopts = CSLSetNameValue(job->wopts, "ROWS", "DEFERRED");
  job->wopts = CSLSetNameValue(job->wopts, "JOURNAL", "MEMORY");
  job->wopts = CSLSetNameValue(job->wopts, "PAGES", "YES");
  GDALDatasetH dst = tt__app_write_create(job);
  if (!dst)
    return tt__error(r->ctx, TT_ERR_IO, "cannot create GPKG dataset: %s",
                     r->msg.last[0] ? r->msg.last : "unknown reason");
  /* an empty TIN of the run's frame: the layers, their fields and CRS */
  tt_tin empty;
  double none = 0; /* arrays of no element, never read */
  memset(&empty, 0, sizeof empty);
  empty.t_max = empty.v_ins_err = &none;
  empty.summary.criterion = job->ro.criterion;
  /* decimated (tt__records_decimated): the vertices' importance field */
  empty.summary.start_vertices = job->decimate ? 1 : 0;
  st = tt_ogr_write_tin(r->ctx, dst, &empty, job->srs, f.v, f.n, job->wopts,
                        NULL, NULL);
  unsigned failures = r->msg.failures;
  GDALClose(dst);
  if (st == TT_OK && r->msg.failures != failures)
    st = tt__error(r->ctx, TT_ERR_IO, "%s: error while closing: %s", temp,
                   r->msg.last);
  /* TERRATIN_RTREE_BLOCK: the boxes an R-tree block gathers before its
   * leaves are written (the page writer's RTREE_BLOCK; tests make it small
   * to get many blocks from a small DEM) */
  const char *block = CPLGetConfigOption("TERRATIN_RTREE_BLOCK", NULL);
  char **o = CSLDuplicate(job->wopts);
  if (block && *block)
    o = CSLSetNameValue(o, "RTREE_BLOCK", block);
  if (st == TT_OK)
    st = tt__gpkg_stream_open(r->ctx, temp, job->srs, o, job->decimate,
                              &sink->out);
  CSLDestroy(o);
  return st;
}

/* The rows written so far dropped: the writer closed (its page writer cuts
 * the file back) and the file removed, for open to create it again. */
static void stream_discard(tt_app_tile_sink *sink)
{
  tt_app_stream *so = (tt_app_stream *)sink;
  tt__gpkg_stream_close(sink->out);
  sink->out = NULL;
  tt_output_clear(so->job->outp);
}

void tt__app_stream_init(tt_app_stream *so, app_simplify_job *job)
{
  memset(so, 0, sizeof *so);
  so->sink.open = stream_open;
  so->sink.discard = stream_discard;
  so->job = job;
}

tt_status tt__app_stream_finish(tt_app_stream *so, const tt_run_field *fields,
                                size_t nfields)
{
  app_run *r = so->job->r;
  tt_status st = tt__gpkg_stream_finish(so->sink.out, fields, nfields,
                                        tt__app_phase_fn, &r->prog);
  tt__gpkg_stream_close(so->sink.out);
  so->sink.out = NULL;
  return st;
}

void tt__app_stream_close(tt_app_stream *so)
{
  tt__gpkg_stream_close(so->sink.out);
  so->sink.out = NULL;
}
