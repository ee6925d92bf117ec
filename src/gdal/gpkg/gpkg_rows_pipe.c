/*
 * src/gdal/gpkg/ -- the GeoPackage fast path: a TIN's rows, SQLite database
 * pages, R-trees and a tiled run's streamed write, straight into the file
 * rather than through OGR.
 *
 * gpkg_rows_pipe.c -- the rows of the GeoPackage row writer (gpkg_rows.h)
 * made: each feature's values (tin_records.h), geometry blob, R-tree box
 * and extent, a chunk of rows at a time.
 *
 * The rows are made by a second thread, a chunk of CHUNK_ROWS rows at a
 * time, through a ring of NCHUNKS chunks, while the writing side (SQLite
 * inserting from the virtual table, or the page path appending) writes the
 * previous ones: the triangles' rows, then the vertices'. With one thread
 * (THREADS=1, or no second CPU) the writing side makes each chunk itself
 * when it needs it. Only the writing side reports progress; a failure on
 * either side (an interruption, a row the TIN cannot give) stops the
 * other, the maker's message kept in its own context.
 *
 * Once every row is given, the maker packs the R-trees of the boxes
 * (rtree_pack.c) while the writing side writes the last rows; the writing
 * side packs the ones the maker has not begun.
 */
#include "gdal/gpkg/gpkg_rows.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static void set_int(row_value *v, int64_t i)
{
  v->type = V_INT;
  v->i = i;
}

static void set_real(row_value *v, double d)
{
  v->type = isfinite(d) ? V_REAL : V_NULL; /* NaN as NULL */
  v->d = d;
}

static tt_status fill_triangle(const rows_pipe *p, tt_context *ctx,
                               size_t i, row_value *vals,
                               unsigned char *blob, int *blob_len,
                               double *ext)
{
  layer_table *t = p->layer[0];
  tt_triangle_info tr;
  double px[3], py[3], pz[3];
  tt_status s = tt__records_triangle(p->rec, ctx, i, &tr, px, py, pz);
  if (s != TT_OK)
    return s;
  double lo[3], hi[3];
  *blob_len = (int)put_triangle_blob(blob, t->srs_id, px, py, pz, lo, hi);
  extend(ext, lo[0], lo[1]);
  extend(ext, hi[0], hi[1]);
  if (t->boxes)
    tt__rtree_box_set(&t->boxes[i], (int64_t)i + 1, lo[0], hi[0], lo[1],
                      hi[1]);
  row_value *f = vals + 1;
  set_int(&f[TT__TF_V0], tr.v[0]);
  set_int(&f[TT__TF_V1], tr.v[1]);
  set_int(&f[TT__TF_V2], tr.v[2]);
  set_real(&f[TT__TF_MAX_ERR], tr.max_error);
  set_real(&f[TT__TF_RMSE], tr.rmse);
  set_int(&f[TT__TF_N_SAMPLES], (sqlite3_int64)tr.samples);
  set_real(&f[TT__TF_AREA_2D], tr.area_2d);
  set_real(&f[TT__TF_AREA_3D], tr.area_3d);
  set_real(&f[TT__TF_SLOPE], tr.slope_deg);
  set_real(&f[TT__TF_ASPECT], tr.aspect_deg);
  set_real(&f[TT__TF_MIN_ANGLE], tr.min_angle_deg);
  set_real(&f[TT__TF_MAX_ANGLE], tr.max_angle_deg);
  if (p->ncols[0] > 1 + TT__TF_CONSTRAINED)
    set_int(&f[TT__TF_CONSTRAINED], (sqlite3_int64)tr.constrained);
  return TT_OK;
}

static tt_status fill_vertex(const rows_pipe *p, tt_context *ctx, size_t i,
                             row_value *vals, unsigned char *blob,
                             int *blob_len, double *ext)
{
  layer_table *t = p->layer[1];
  tt_vertex_info v;
  double x, y;
  tt_status s = tt__records_vertex(p->rec, ctx, i, &v, &x, &y);
  if (s != TT_OK)
    return s;
  *blob_len = (int)put_point_blob(blob, t->srs_id, x, y, v.z);
  extend(ext, x, y);
  if (t->boxes)
    tt__rtree_box_set(&t->boxes[i], (int64_t)i + 1, x, x, y, y);
  row_value *f = vals + 1;
  set_int(&f[TT__VF_ID], (sqlite3_int64)i);
  set_int(&f[TT__VF_COL], v.col);
  set_int(&f[TT__VF_ROW], v.row);
  set_real(&f[TT__VF_INS_ERR], v.insert_error);
  if (p->decimated)
    f[TT__VF_INS_RANK].type = V_NULL;
  else
    set_int(&f[TT__VF_INS_RANK], (sqlite3_int64)v.rank);
  set_real(&f[TT__VF_STAR_MAX], v.star_max_error);
  set_real(&f[TT__VF_STAR_RMSE], v.star_rmse);
  set_int(&f[TT__VF_STAR_N], (sqlite3_int64)v.star_samples);
  if (p->decimated)
    set_real(&f[TT__VF_IMPORTANCE], v.importance);
  return TT_OK;
}

/* The rows of chunk number p->claim given to ch (p->claim then the next
 * one); 0 when every row has been given. Called with the lock held. */
static int claim_rows(rows_pipe *p, chunk *ch)
{
  while (p->m_layer < 2 && p->m_first >= p->count[p->m_layer]) {
    p->m_layer++;
    p->m_first = 0;
  }
  if (p->m_layer >= 2)
    return 0;
  size_t left = p->count[p->m_layer] - p->m_first;
  ch->layer = p->m_layer;
  ch->first = p->m_first;
  ch->n = left < CHUNK_ROWS ? left : CHUNK_ROWS;
  ch->state = CH_MAKING;
  p->m_first += ch->n;
  p->claim++;
  return 1;
}

/* Makes the rows given to ch (either thread, without the lock: the rows,
 * boxes and extent are the chunk's own). Errors go to ctx. */
static tt_status fill_chunk(rows_pipe *p, chunk *ch, tt_context *ctx)
{
  tt_status s = TT_OK;
  ch->ext[0] = ch->ext[1] = INFINITY;
  ch->ext[2] = ch->ext[3] = -INFINITY;
  for (size_t r = 0; r < ch->n && s == TT_OK; r++)
    s = (ch->layer == 0 ? fill_triangle : fill_vertex)(
        p, ctx, ch->first + r, ch->v[r], ch->blob[r], &ch->blob_len[r],
        ch->ext);
  return s;
}

static void pipe_lock(rows_pipe *p)
{
  if (p->threaded)
    pthread_mutex_lock(&p->lock);
}

static void pipe_unlock(rows_pipe *p)
{
  if (p->threaded)
    pthread_mutex_unlock(&p->lock);
}

/* ch made (lock held): its rows count, the other side may go on. */
static void chunk_made(rows_pipe *p, chunk *ch)
{
  ch->state = CH_FULL;
  p->made[ch->layer] += ch->n;
  if (p->threaded)
    pthread_cond_broadcast(&p->cond);
}

/* The maker: takes the next chunk of rows when its slot of the ring is
 * free and makes it, until every row is given (the writing side makes the
 * chunks it finds not yet taken: neither waits for the other but for a
 * chunk being made); then packs the R-trees. */
static void *maker_main(void *arg)
{
  rows_pipe *p = arg;
  for (;;) {
    pthread_mutex_lock(&p->lock);
    chunk *ch = &p->ring[p->claim % NCHUNKS];
    while (!p->stop && ch->state != CH_EMPTY) {
      pthread_cond_wait(&p->cond, &p->lock);
      ch = &p->ring[p->claim % NCHUNKS];
    }
    int more = !p->stop && claim_rows(p, ch);
    pthread_mutex_unlock(&p->lock);
    if (!more)
      break;
    tt_status s = fill_chunk(p, ch, p->m_ctx);
    pthread_mutex_lock(&p->lock);
    if (s != TT_OK)
      p->failed = 1;
    else
      chunk_made(p, ch);
    pthread_cond_broadcast(&p->cond);
    pthread_mutex_unlock(&p->lock);
    if (s != TT_OK)
      break;
  }
  /* Every row given: the R-trees' packing (sorts) goes on here while the
   * writing side writes the last rows, each tree once all its rows are
   * made (the writing side may make the last ones). The boxes become the
   * packed trees' leaves. */
  for (int k = 0; k < 2 && p->node_cap; k++) {
    pthread_mutex_lock(&p->lock);
    while (!p->stop && !p->failed && p->made[k] < p->count[k])
      pthread_cond_wait(&p->cond, &p->lock);
    int stop = p->stop || p->failed, claimed = p->claimed[k];
    p->claimed[k] = 1;
    pthread_mutex_unlock(&p->lock);
    layer_table *t = p->layer[k];
    if (stop)
      break;
    if (claimed)
      continue; /* the other thread packs it */
    if (!t->boxes || p->count[k] == 0)
      continue; /* a layer left out by LAYERS */
    if (tt__rtree_pack(p->m_ctx, t->name, t->boxes, p->count[k],
                       p->node_cap, &p->packed[k]) != TT_OK)
      break; /* the writing side packs from the boxes */
    t->boxes = NULL; /* the packed tree's */
  }
  return NULL;
}

/* The writing side: points p at row i of layer p->layer_now, taking the
 * next chunk when row i is past the one held: made by the maker, or made
 * here when the maker has not taken it yet. */
tt_status tt__rows_pipe_row(rows_pipe *p, rows_state *w, size_t i)
{
  chunk *ch = p->c_held ? &p->ring[p->c_slot % NCHUNKS] : NULL;
  if (!ch || ch->layer != p->layer_now || i < ch->first ||
      i >= ch->first + ch->n) {
    pipe_lock(p);
    if (ch) { /* done with it */
      ch->state = CH_EMPTY;
      p->c_slot++;
      p->c_held = 0;
      if (p->threaded)
        pthread_cond_broadcast(&p->cond);
    }
    ch = &p->ring[p->c_slot % NCHUNKS];
    tt_status s = TT_OK;
    while (ch->state != CH_FULL) {
      if (ch->state == CH_EMPTY && p->claim == p->c_slot) {
        /* not taken: made here */
        if (!claim_rows(p, ch)) {
          s = tt__error(w->ctx, TT_ERR_INTERNAL, "%s: row %zu of layer %s "
                        "asked for past its end", w->path, i,
                        p->layer[p->layer_now]->name);
          break;
        }
        pipe_unlock(p);
        s = fill_chunk(p, ch, w->ctx);
        pipe_lock(p);
        if (s != TT_OK)
          break;
        chunk_made(p, ch);
        break;
      }
      if (p->failed || !p->threaded) {
        s = tt__error(w->ctx, TT_ERR_INTERNAL, "%s", p->failed
                      ? tt_context_errmsg(p->m_ctx) : "rows out of order");
        break;
      }
      pthread_cond_wait(&p->cond, &p->lock); /* the maker's, being made */
    }
    pipe_unlock(p);
    if (s != TT_OK)
      return s;
    p->c_held = 1;
    if (ch->layer != p->layer_now || i != ch->first)
      return tt__error(w->ctx, TT_ERR_INTERNAL, "%s: rows of layer %s out "
                       "of order (%zu)", w->path,
                       p->layer[p->layer_now]->name, i);
    /* the chunks' extents, merged in order on this side */
    double *ext = p->layer[ch->layer]->ext;
    extend(ext, ch->ext[0], ch->ext[1]);
    extend(ext, ch->ext[2], ch->ext[3]);
  }
  size_t r = i - ch->first;
  p->vals = ch->v[r];
  p->blob = ch->blob[r];
  p->blob_len = ch->blob_len[r];
  p->row = i;
  return report(w);
}

/* The writing thread, its rows all written, packs the R-trees the maker
 * has not begun (the vertices' first: the maker begins with the
 * triangles'), so that the two share the sorts. Returns the trees it
 * packed (bit k: layer k). */
unsigned tt__rows_pipe_pack_too(rows_pipe *p, size_t node_cap)
{
  unsigned mine = 0;
  if (!p->threaded || !node_cap)
    return 0;
  for (int k = 1; k >= 0; k--) {
    pthread_mutex_lock(&p->lock);
    int claimed = p->claimed[k], failed = p->failed;
    p->claimed[k] = 1;
    pthread_mutex_unlock(&p->lock);
    layer_table *t = p->layer[k];
    if (claimed || failed || !t->boxes || p->count[k] == 0)
      continue;
    /* a failure (out of memory) leaves the boxes for the page writer */
    if (tt__rtree_pack(NULL, t->name, t->boxes, p->count[k], node_cap,
                       &p->packed[k]) == TT_OK)
      t->boxes = NULL; /* the packed tree's */
    mine |= 1u << k;
  }
  return mine;
}

/* Joins the maker: after its packing when the rows went in (ok), else
 * stopping it first. */
void tt__rows_pipe_join(rows_pipe *p, int ok)
{
  if (p->threaded) {
    pthread_mutex_lock(&p->lock);
    p->stop = !ok;
    pthread_cond_broadcast(&p->cond);
    pthread_mutex_unlock(&p->lock);
    pthread_join(p->thread, NULL);
    pthread_cond_destroy(&p->cond);
    pthread_mutex_destroy(&p->lock);
    p->threaded = 0;
  }
  free(p->ring);
  p->ring = NULL;
}

void tt__rows_pipe_free(rows_pipe *p)
{
  tt__rows_pipe_join(p, 0);
  for (int k = 0; k < 2; k++)
    tt__rtree_packed_free(p->packed[k]);
  if (p->m_ctx)
    tt_context_destroy(p->m_ctx);
  memset(p, 0, sizeof *p);
}

/* Sets up the rows of both layers (nt triangles, nv vertices: 0 for a layer
 * left out by LAYERS); a maker thread when threads allow. */
tt_status tt__rows_pipe_begin(rows_pipe *p, rows_state *w,
                            const tt__records *rec, layer_table *tri,
                            layer_table *vtx, size_t nt, size_t nv,
                            int threads, size_t node_cap)
{
  memset(p, 0, sizeof *p);
  p->rec = rec;
  p->layer[0] = tri;
  p->layer[1] = vtx;
  p->count[0] = nt;
  p->count[1] = nv;
  p->ncols[0] = 1 + tt__records_triangle_fields(rec->tin);
  p->ncols[1] = 1 + tt__records_vertex_fields(rec->tin);
  p->decimated = tt__records_decimated(rec->tin);
  p->ring = calloc(NCHUNKS, sizeof *p->ring);
  if (!p->ring)
    return tt__error(w->ctx, TT_ERR_NOMEM, "out of memory");
  if (threads == 1 || p->count[0] + p->count[1] <= CHUNK_ROWS ||
      (threads <= 0 && sysconf(_SC_NPROCESSORS_ONLN) < 2))
    return TT_OK;
  p->m_ctx = tt_context_create();
  if (!p->m_ctx)
    return TT_OK;
  if (pthread_mutex_init(&p->lock, NULL) != 0)
    return TT_OK;
  if (pthread_cond_init(&p->cond, NULL) != 0) {
    pthread_mutex_destroy(&p->lock);
    return TT_OK;
  }
  p->node_cap = node_cap; /* read by the maker */
  if (pthread_create(&p->thread, NULL, maker_main, p) != 0) {
    p->node_cap = 0;
    pthread_cond_destroy(&p->cond);
    pthread_mutex_destroy(&p->lock);
    return TT_OK; /* the SQLite thread makes the rows itself */
  }
  p->threaded = 1;
  return TT_OK;
}
