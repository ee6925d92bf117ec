/*
 * src/gdal/gpkg/ -- the GeoPackage fast path: a TIN's rows, SQLite database
 * pages, R-trees and a tiled run's streamed write, straight into the file
 * rather than through OGR.
 *
 * gpkg_stream.c -- the triangles and vertices rows of a tiled run
 * written into its GeoPackage as the tiles are merged (tt__gpkg_stream),
 * instead of from the whole merged TIN after the last tile.
 *
 * The merge in tile order (src/tile/stream.c) hands out, after each
 * piece, its triangles (with the global vertex ids) and the vertices that
 * became final, in id order; here they become rows appended as database
 * pages (tt__gpkg_pages_*, gpkg_rows_pages.c's page writer, opened
 * once for the whole run): the same values, the same geometry blobs
 * (gpkg_stream.h's put_triangle_blob and put_point_blob, which
 * gpkg_rows_pipe.c's fill_triangle and fill_vertex use, from
 * tin_records.h's records), the same fids and ids, so the
 * file's rows are those the merged-TIN path writes, byte for byte
 * (tests/apps/test_tiles.sh compares them). The extents are min/max over
 * the rows, whatever the order.
 *
 * Each row's box (rounded outward to the floats the index stores) goes
 * with it to the page writer, whose R-trees pack their leaves block by
 * block as the rows come (tt__rtree_stream, gpkg_rtree_pages.c): a
 * block ends after a batch, a piece's triangles or the vertices final
 * after it (tt__gpkg_pages_cut), once it holds 65,536 boxes (earlier where
 * a row of tiles wrapped), so a block is a strip of whole pieces, a few
 * tiles of 1,024 at 1 % of the samples. Only the
 * leaves' boxes (24 bytes a leaf of about 51 features) are kept until the
 * end, when the upper levels and the root are written: the trees hold the
 * same boxes as the merged-TIN path's but not the same nodes (their
 * queries visit as many: docs/scale.md). Left to grow with the TIN: 8
 * bytes a vertex for the style's quantile classes.
 *
 * A geographic or Web Mercator DEM's triangles come with their piece's
 * ground points and the area function (src/tile/stream.c), so
 * tt__records_triangle() measures them as for the merged TIN; a decimated
 * TIN's vertex rows have the importance field and no ins_rank, as
 * gpkg_rows.c writes them.
 *
 * Workload: per triangle row tt_tin_triangle()'s arithmetic and a 165-byte
 * blob, per vertex a 37-byte one; T_SRS transforms each piece's vertices
 * once per piece (tt__records_init), border vertices once per piece that
 * holds them.
 */
#include "gdal/gpkg/gpkg_stream.h"
#include "gdal/ogr/layer_style.h"
#include "gdal/ogr/tin_records.h"

#include <cpl_conv.h>
#include <cpl_string.h>

#include <sqlite3.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>


struct tt__gpkg_stream {
  tt_context *ctx;
  const char *path;
  tt__gpkg_pages *pages;
  OGRSpatialReferenceH srs;
  char *t_srs;
  int todo[2], rtree;
  int32_t srs_id[2];
  size_t count[2];
  double ext[2][4];
  /* the layers' default style (STYLE=YES), whose classes the whole TIN's
   * values make: the triangles' max_err range, every vertex's finite
   * ins_err (quantiles: 8 bytes a vertex) */
  int style;
  double tmax_lo, tmax_hi;
  double *ins;
  size_t nins, inscap;
  char *prefix;
  unsigned layers;
  int decimated; /* the importance field; ins_rank NULL */
};

static void set_int(tt__gpkg_value *v, int64_t i)
{
  v->type = TT__GV_INT;
  v->i = i;
}

static void set_real(tt__gpkg_value *v, double d)
{
  v->type = isfinite(d) ? TT__GV_REAL : TT__GV_NULL; /* NaN as NULL */
  v->d = d;
}

tt_status tt__gpkg_stream_open(tt_context *ctx, const char *path,
                               OGRSpatialReferenceH srs, char **options,
                               int decimated, tt__gpkg_stream **out)
{
  *out = NULL;
  tt__gpkg_stream *g = calloc(1, sizeof *g);
  if (!g)
    return tt__error(ctx, TT_ERR_NOMEM, "out of memory");
  *out = g;
  g->ctx = ctx;
  g->path = path;
  g->srs = srs;
  const char *t_srs = CSLFetchNameValue(options, "T_SRS");
  if (t_srs && *t_srs)
    g->t_srs = CPLStrdup(t_srs);
  const char *style = CSLFetchNameValue(options, "STYLE");
  g->style = style && CPLTestBool(style);
  const char *prefix = CSLFetchNameValue(options, "NLN_PREFIX");
  g->prefix = CPLStrdup(prefix ? prefix : "");
  g->layers = TT__LAYERS_ALL;
  const char *layers = CSLFetchNameValue(options, "LAYERS");
  if (layers && tt__records_parse_layers(ctx, layers, &g->layers) != TT_OK)
    return TT_ERR_ARG;
  g->tmax_lo = INFINITY;
  g->tmax_hi = -INFINITY;
  for (int k = 0; k < 2; k++) {
    g->ext[k][0] = g->ext[k][1] = INFINITY;
    g->ext[k][2] = g->ext[k][3] = -INFINITY;
  }
  /* a decimated TIN's vertices have the importance field (the layer
   * was made with it, tt__records_vertex_fields) */
  g->decimated = decimated;
  tt_status s = tt__gpkg_pages_open(ctx, path, options,
                                    decimated ? TT__VF_COUNT
                                              : TT__VF_COUNT - 1,
                                    &g->pages);
  if (s != TT_OK)
    return s;
  g->rtree = tt__gpkg_pages_rtree(g->pages);
  for (int k = 0; k < 2; k++) {
    g->todo[k] = tt__gpkg_pages_has(g->pages, k);
    g->srs_id[k] = g->todo[k] ? tt__gpkg_pages_srs_id(g->pages, k) : 0;
  }
  return TT_OK;
}

/* The triangles of batch b: fill_triangle() of gpkg_rows_pipe.c, the
 * vertex ids mapped to the global ones. */
static tt_status triangles(tt__gpkg_stream *g, const tt__stream_batch *b)
{
  const tt_tin *tin = b->tri;
  tt__records rec;
  tt_status s = tt__records_init(&rec, g->ctx, tin, g->srs, g->t_srs);
  unsigned char blob[TT__TRI_BLOB_BYTES];
  tt__gpkg_value f[TT__TF_COUNT];
  for (size_t i = 0; i < tt_tin_triangle_count(tin) && s == TT_OK; i++) {
    tt_triangle_info tr;
    double px[3], py[3], pz[3];
    s = tt__records_triangle(&rec, g->ctx, i, &tr, px, py, pz);
    if (s != TT_OK)
      break;
    double lo[3], hi[3];
    size_t len = put_triangle_blob(blob, g->srs_id[0], px, py, pz, lo, hi);
    size_t fid = b->tri_first + i + 1;
    extend(g->ext[0], lo[0], lo[1]);
    extend(g->ext[0], hi[0], hi[1]);
    tt__rtree_box box;
    tt__rtree_box_set(&box, (int64_t)fid, lo[0], hi[0], lo[1], hi[1]);
    set_int(&f[TT__TF_V0], b->map[tr.v[0]]);
    set_int(&f[TT__TF_V1], b->map[tr.v[1]]);
    set_int(&f[TT__TF_V2], b->map[tr.v[2]]);
    set_real(&f[TT__TF_MAX_ERR], tr.max_error);
    if (isfinite(tr.max_error)) {
      g->tmax_lo = tr.max_error < g->tmax_lo ? tr.max_error : g->tmax_lo;
      g->tmax_hi = tr.max_error > g->tmax_hi ? tr.max_error : g->tmax_hi;
    }
    set_real(&f[TT__TF_RMSE], tr.rmse);
    set_int(&f[TT__TF_N_SAMPLES], (int64_t)tr.samples);
    set_real(&f[TT__TF_AREA_2D], tr.area_2d);
    set_real(&f[TT__TF_AREA_3D], tr.area_3d);
    set_real(&f[TT__TF_SLOPE], tr.slope_deg);
    set_real(&f[TT__TF_ASPECT], tr.aspect_deg);
    set_real(&f[TT__TF_MIN_ANGLE], tr.min_angle_deg);
    set_real(&f[TT__TF_MAX_ANGLE], tr.max_angle_deg);
    s = tt__gpkg_pages_row(g->pages, 0, (int64_t)fid, f, blob, len,
                           g->rtree ? &box : NULL);
    g->count[0]++;
  }
  tt__records_free(&rec);
  return s;
}

/* The final vertices of batch b: fill_vertex() of gpkg_rows_pipe.c, ids and
 * ranks counted from b->vtx_first. */
static tt_status vertices(tt__gpkg_stream *g, const tt__stream_batch *b)
{
  const tt_tin *tin = b->vtx;
  tt__records rec;
  tt_status s = tt__records_init(&rec, g->ctx, tin, g->srs, g->t_srs);
  unsigned char blob[TT__PT_BLOB_BYTES];
  tt__gpkg_value f[TT__VF_COUNT];
  for (size_t i = 0; i < tt_tin_vertex_count(tin) && s == TT_OK; i++) {
    tt_vertex_info v;
    double x, y;
    s = tt__records_vertex(&rec, g->ctx, i, &v, &x, &y);
    if (s != TT_OK)
      break;
    size_t id = b->vtx_first + i;
    size_t len = put_point_blob(blob, g->srs_id[1], x, y, v.z);
    extend(g->ext[1], x, y);
    tt__rtree_box box;
    tt__rtree_box_set(&box, (int64_t)id + 1, x, x, y, y);
    set_int(&f[TT__VF_ID], (int64_t)id);
    set_int(&f[TT__VF_COL], v.col);
    set_int(&f[TT__VF_ROW], v.row);
    set_real(&f[TT__VF_INS_ERR], v.insert_error);
    if (g->style && isfinite(v.insert_error)) {
      if (g->nins == g->inscap) {
        size_t c = g->inscap ? 2 * g->inscap : 4096;
        double *a = realloc(g->ins, c * sizeof *a);
        if (!a) {
          s = tt__error(g->ctx, TT_ERR_NOMEM, "out of memory for the "
                        "style's classes");
          break;
        }
        g->ins = a;
        g->inscap = c;
      }
      g->ins[g->nins++] = v.insert_error;
    }
    if (g->decimated)
      f[TT__VF_INS_RANK].type = TT__GV_NULL; /* no insertion */
    else
      set_int(&f[TT__VF_INS_RANK], (int64_t)id);
    set_real(&f[TT__VF_STAR_MAX], v.star_max_error);
    set_real(&f[TT__VF_STAR_RMSE], v.star_rmse);
    set_int(&f[TT__VF_STAR_N], (int64_t)v.star_samples);
    if (g->decimated)
      set_real(&f[TT__VF_IMPORTANCE], v.importance);
    s = tt__gpkg_pages_row(g->pages, 1, (int64_t)id + 1, f, blob, len,
                           g->rtree ? &box : NULL);
    g->count[1]++;
  }
  tt__records_free(&rec);
  return s;
}

tt_status tt__gpkg_stream_batch(tt__gpkg_stream *g, const tt__stream_batch *b)
{
  tt_status s = TT_OK;
  /* a batch is a piece's triangles and the vertices final after it: an
   * R-tree block may end after either (tt__gpkg_pages_cut) */
  if (b->tri && tt_tin_triangle_count(b->tri)) {
    if (g->todo[0]) {
      s = triangles(g, b);
      if (s == TT_OK)
        s = tt__gpkg_pages_cut(g->pages, 0);
    } else {
      g->count[0] += tt_tin_triangle_count(b->tri);
    }
  }
  if (s == TT_OK && b->vtx && tt_tin_vertex_count(b->vtx)) {
    if (g->todo[1]) {
      s = vertices(g, b);
      if (s == TT_OK)
        s = tt__gpkg_pages_cut(g->pages, 1);
    } else {
      g->count[1] += tt_tin_vertex_count(b->vtx);
    }
  }
  return s;
}

/* The run_parameters row (made by OGR with the values known when the
 * first tile merged) gets the run's final values, and the default styles
 * their classes, as tt_ogr_write_tin() would have written them from the
 * whole TIN: the same columns, types and NULLs. */
static tt_status final_values(tt__gpkg_stream *g, const tt_run_field *fields,
                              size_t nfields)
{
  sqlite3 *db = NULL;
  sqlite3_stmt *st = NULL;
  tt_status s = TT_OK;
  char *qml[2] = {NULL, NULL};
  if (sqlite3_open_v2(g->path, &db, SQLITE_OPEN_READWRITE, NULL) !=
          SQLITE_OK ||
      sqlite3_exec(db, "BEGIN IMMEDIATE", NULL, NULL, NULL) != SQLITE_OK) {
    s = tt__error(g->ctx, TT_ERR_IO, "%s: cannot open the GeoPackage: %s",
                  g->path, db ? sqlite3_errmsg(db) : "out of memory");
    goto done;
  }
  for (size_t i = 0; i < nfields && s == TT_OK &&
                     (g->layers & TT__LAYER_RUN_PARAMETERS); i++) {
    const tt_run_field *rf = &fields[i];
    char *sql = sqlite3_mprintf("UPDATE \"%w\" SET \"%w\" = ?",
                                CPLSPrintf("%srun_parameters", g->prefix),
                                rf->name);
    if (!sql || sqlite3_prepare_v2(db, sql, -1, &st, NULL) != SQLITE_OK) {
      s = tt__error(g->ctx, TT_ERR_IO, "%s: cannot set run_parameters.%s: "
                    "%s", g->path, rf->name, sqlite3_errmsg(db));
      sqlite3_free(sql);
      break;
    }
    sqlite3_free(sql);
    if (rf->type == TT_FIELD_STRING && rf->s)
      sqlite3_bind_text(st, 1, rf->s, -1, SQLITE_STATIC);
    else if (rf->type == TT_FIELD_INTEGER)
      sqlite3_bind_int64(st, 1, (sqlite3_int64)rf->i);
    else if (rf->type == TT_FIELD_REAL && isfinite(rf->r))
      sqlite3_bind_double(st, 1, rf->r);
    else
      sqlite3_bind_null(st, 1);
    if (sqlite3_step(st) != SQLITE_DONE)
      s = tt__error(g->ctx, TT_ERR_IO, "%s: cannot set run_parameters.%s: "
                    "%s", g->path, rf->name, sqlite3_errmsg(db));
    sqlite3_finalize(st);
    st = NULL;
  }
  if (s == TT_OK && g->style) {
    /* the classes of layer_style.c's tt__style_insert(): equal intervals
     * need the range only */
    double range[2] = {g->tmax_lo, g->tmax_hi};
    qml[0] = tt__style_graduated_qml("max_err", range,
                                     g->tmax_lo <= g->tmax_hi ? 2 : 0, 0, 0,
                                     0);
    qml[1] = tt__style_graduated_qml("coalesce(\"ins_err\", -1)", g->ins,
                                     g->nins, 1, 1, 1);
    if (!qml[0] || !qml[1])
      s = tt__error(g->ctx, TT_ERR_NOMEM, "out of memory for a style");
  }
  for (int k = 0; k < 2 && s == TT_OK && g->style; k++) {
    if (!g->todo[k])
      continue;
    if (sqlite3_prepare_v2(db, "UPDATE " TT__STYLE_TABLE " SET styleQML = ? "
                           "WHERE f_table_name = ?", -1, &st, NULL) !=
        SQLITE_OK) {
      s = tt__error(g->ctx, TT_ERR_IO, "%s: cannot set the style: %s",
                    g->path, sqlite3_errmsg(db));
      break;
    }
    sqlite3_bind_text(st, 1, qml[k], -1, SQLITE_STATIC);
    sqlite3_bind_text(st, 2, CPLSPrintf("%s%s", g->prefix,
                                        k ? "vertices" : "triangles"),
                      -1, SQLITE_TRANSIENT);
    if (sqlite3_step(st) != SQLITE_DONE)
      s = tt__error(g->ctx, TT_ERR_IO, "%s: cannot set the style: %s",
                    g->path, sqlite3_errmsg(db));
    sqlite3_finalize(st);
    st = NULL;
  }
  if (s == TT_OK && sqlite3_exec(db, "COMMIT", NULL, NULL, NULL) != SQLITE_OK)
    s = tt__error(g->ctx, TT_ERR_IO, "%s: cannot commit: %s", g->path,
                  sqlite3_errmsg(db));
done:
  CPLFree(qml[0]);
  CPLFree(qml[1]);
  if (db && sqlite3_close(db) != SQLITE_OK && s == TT_OK)
    s = tt__error(g->ctx, TT_ERR_IO, "%s: cannot close", g->path);
  return s;
}

tt_status tt__gpkg_stream_finish(tt__gpkg_stream *g,
                                 const tt_run_field *fields, size_t nfields,
                                 tt_progress_fn progress, void *progress_arg)
{
  size_t count[2];
  for (int k = 0; k < 2; k++)
    count[k] = g->todo[k] ? g->count[k] : 0;
  tt_status s = tt__gpkg_pages_finish(g->pages, count,
                                      (const double(*)[4])g->ext, progress,
                                      progress_arg);
  tt__gpkg_pages_close(g->pages); /* SQLite's connection too */
  g->pages = NULL;
  if (s == TT_OK)
    s = final_values(g, fields, nfields);
  return s;
}

size_t tt__gpkg_stream_bytes(const tt__gpkg_stream *g)
{
  return g ? tt__gpkg_pages_bytes(g->pages) + g->inscap * sizeof(double)
           : 0;
}

void tt__gpkg_stream_close(tt__gpkg_stream *g)
{
  if (!g)
    return;
  tt__gpkg_pages_close(g->pages);
  free(g->ins);
  CPLFree(g->t_srs);
  CPLFree(g->prefix);
  free(g);
}
