/*
 * stream.c -- the pieces of a tiled run joined as they come, for a writer
 * that writes each row as soon as it is final (tt__tin_stream): the
 * streamed counterpart of merge.c, which holds the whole merged TIN.
 *
 * Pieces are added in tile order, as to tt_tin_merger, and everything is
 * numbered, appended and summed in the same order with the same
 * arithmetic, so the rows a writer makes from the batches are those it
 * would make from tt_tin_merger_finish()'s TIN, value for value:
 *  - a piece's triangles are handed out at once (their global fids follow
 *    on), with the piece's own vertex arrays and a map from its vertex
 *    indices to the global ids (a border vertex keeps the first piece's
 *    id, found by its sample in a hash table of the open outline
 *    vertices); their sample counts less the border vertices' own samples
 *    counted by an earlier piece, as merge.c does;
 *  - a vertex's star statistics (max, sum of squares, count) are summed
 *    over the triangles of every piece touching it, in triangle order (the
 *    order finish() sums them in). A vertex is final once the last tile
 *    holding its sample has been added (tile (min(r / N, nty - 1),
 *    min(c / N, ntx - 1)) in tile order); vertices are handed out in id
 *    order, so the final ones wait behind the first that is not: a border
 *    vertex on the bottom side of a row of tiles waits for the next row,
 *    and holds back what came after it. Pending vertices are therefore
 *    those of about one row of tiles (64 bytes each).
 * The pieces (components) are counted by union-find over every vertex id:
 * 4 bytes a vertex until the end, the one array that grows with the TIN.
 *
 * A geographic or Web Mercator DEM's pieces carry their vertices' ground
 * points, scale factors and convergences (tile.c). Only the triangles'
 * areas, slopes, aspects and angles use them, and a triangle's batch is
 * its own piece's arrays, so they are handed out with it and never kept:
 * a border vertex's are the same bits in every piece that holds it (from
 * the DEM's column and row, and the window beyond the border), so the
 * triangles of a later piece measure it as the merged TIN's copy of the
 * first piece's would. The area function (geodesic areas) comes from tile
 * 0's window (tt__tin_stream_set_ground) or the first piece that has it,
 * as tt_tin_merger takes it.
 * A decimated piece's vertices have importances: kept with the pending
 * vertex (8 bytes) and handed out with it, NaN from a piece without them;
 * the decimation counts (start, removed, refused; rounds: the most of any
 * piece) are summed as merge.c sums them.
 *
 * Memory: the pending vertices, the open outline vertices' table (about 40
 * bytes each, a row of tile borders), 4 bytes a vertex for the
 * components, and per piece, while its batch is out, 16 bytes a triangle
 * and 20 a vertex (tt__tin_stream_bytes counts them all).
 *
 * Part of src/tile/, tiled runs: the tiles, their shared borders, one tile's
 * run, the merge.
 */
#include "tile/tile.h"
#include "tin/tin.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

struct tt__tin_stream {
  size_t W, H, N, ntx, nty;
  double gt[6], frame[4];
  bool have_frame;
  size_t nv, nt;         /* ids given so far */
  /* pending vertices: ids [base, base + np) at [off, off + np) */
  int32_t *pc, *pr;
  double *pz, *pins, *psmax, *pssq, *pimp;
  uint64_t *pn;
  size_t *plast;         /* the last tile holding the vertex's sample */
  size_t base, off, np, pcap;
  size_t handed;         /* vertices of the last batch, popped next time */
  /* open outline vertices: sample index -> id, open addressing */
  int64_t *hkey;
  int32_t *hval;
  size_t hcap, hn;
  int32_t *open;         /* their ids */
  size_t nopen, opencap;
  /* components */
  int32_t *uf;
  size_t ufcap;
  /* the batch's own arrays */
  int32_t *map;
  double *b_rmse, *b_zero;
  uint64_t *b_n, *b_zero_n;
  size_t bvcap, btcap;
  tt_tin tri, vtx;       /* shallow views handed out */
  /* sums, in piece order */
  size_t covered, valid, forced;
  size_t start_vertices, removed, rounds, refused; /* decimated pieces */
  /* the vertices' ground points: every piece has them or none (ground,
   * decided by the first piece with triangles); the area function */
  bool ground;
  tt_area_fn area_fn;
  double area_par[4];
  double sum_abs, sum_sq, max_err, zmin, zmax;
  int64_t max_index;
  double seconds_mesh, seconds_stats;
  tt_criterion criterion;
};

tt_status tt__tin_stream_create(tt_context *ctx, size_t dem_width,
                                size_t dem_height, size_t tile_size,
                                const double gt[6], tt__tin_stream **out)
{
  *out = NULL;
  if (dem_width < 2 || dem_height < 2 || tile_size < 1)
    return tt__error(ctx, TT_ERR_ARG, "stream of a %zu x %zu DEM in tiles "
                     "of %zu", dem_width, dem_height, tile_size);
  tt__tin_stream *s = calloc(1, sizeof *s);
  if (!s)
    return tt__error(ctx, TT_ERR_NOMEM, "out of memory");
  s->W = dem_width;
  s->H = dem_height;
  s->N = tile_size;
  s->ntx = (dem_width - 2) / tile_size + 1;
  s->nty = (dem_height - 2) / tile_size + 1;
  memcpy(s->gt, gt, sizeof s->gt);
  s->max_index = -1;
  s->zmin = INFINITY;
  s->zmax = -INFINITY;
  *out = s;
  return TT_OK;
}

void tt__tin_stream_destroy(tt__tin_stream *s)
{
  if (!s)
    return;
  free(s->pc);
  free(s->pr);
  free(s->pz);
  free(s->pins);
  free(s->psmax);
  free(s->pssq);
  free(s->pimp);
  free(s->pn);
  free(s->plast);
  free(s->hkey);
  free(s->hval);
  free(s->open);
  free(s->uf);
  free(s->map);
  free(s->b_rmse);
  free(s->b_zero);
  free(s->b_n);
  free(s->b_zero_n);
  free(s);
}

static size_t hslot(const tt__tin_stream *s, int64_t key)
{
  uint64_t h = (uint64_t)key * 0x9E3779B97F4A7C15u;
  size_t i = (size_t)(h >> 17) & (s->hcap - 1);
  while (s->hkey[i] >= 0 && s->hkey[i] != key)
    i = (i + 1) & (s->hcap - 1);
  return i;
}

static int64_t key_of(const tt__tin_stream *s, int32_t id)
{
  size_t at = s->off + (size_t)id - s->base;
  return (int64_t)s->pr[at] * (int64_t)s->W + s->pc[at];
}

/* The table again from the open outline vertices, with room for want
 * more; the closed ones were dropped from the list. */
static bool rehash(tt__tin_stream *s, size_t want)
{
  size_t cap = 1024;
  while (cap < 2 * (s->nopen + want))
    cap *= 2;
  if (cap != s->hcap) {
    int64_t *k = malloc(cap * sizeof *k);
    int32_t *v = malloc(cap * sizeof *v);
    if (!k || !v) {
      free(k);
      free(v);
      return false;
    }
    free(s->hkey);
    free(s->hval);
    s->hkey = k;
    s->hval = v;
    s->hcap = cap;
  }
  for (size_t i = 0; i < s->hcap; i++)
    s->hkey[i] = -1;
  for (size_t i = 0; i < s->nopen; i++) {
    int64_t key = key_of(s, s->open[i]);
    size_t j = hslot(s, key);
    s->hkey[j] = key;
    s->hval[j] = s->open[i];
  }
  s->hn = s->nopen;
  return true;
}

#define GROW(p, n)                                                         \
  do {                                                                     \
    void *q_ = realloc((p), (n) * sizeof *(p));                           \
    if (!q_)                                                               \
      return false;                                                        \
    (p) = q_;                                                              \
  } while (0)

/* Room for n more pending vertices (moving them down first when the
 * handed-out ones left half the arrays free). */
static bool pending_room(tt__tin_stream *s, size_t n)
{
  if (s->off && s->off >= s->np) {
    size_t o = s->off, k = s->np;
    memmove(s->pc, s->pc + o, k * sizeof *s->pc);
    memmove(s->pr, s->pr + o, k * sizeof *s->pr);
    memmove(s->pz, s->pz + o, k * sizeof *s->pz);
    memmove(s->pins, s->pins + o, k * sizeof *s->pins);
    memmove(s->psmax, s->psmax + o, k * sizeof *s->psmax);
    memmove(s->pssq, s->pssq + o, k * sizeof *s->pssq);
    memmove(s->pimp, s->pimp + o, k * sizeof *s->pimp);
    memmove(s->pn, s->pn + o, k * sizeof *s->pn);
    memmove(s->plast, s->plast + o, k * sizeof *s->plast);
    s->off = 0;
  }
  size_t need = s->off + s->np + n;
  if (need > s->pcap) {
    size_t c = s->pcap + s->pcap / 2 > need ? s->pcap + s->pcap / 2 : need;
    GROW(s->pc, c);
    GROW(s->pr, c);
    GROW(s->pz, c);
    GROW(s->pins, c);
    GROW(s->psmax, c);
    GROW(s->pssq, c);
    GROW(s->pimp, c);
    GROW(s->pn, c);
    GROW(s->plast, c);
    s->pcap = c;
  }
  if (s->nv + n > s->ufcap) {
    size_t c = s->ufcap + s->ufcap / 2 > s->nv + n ? s->ufcap + s->ufcap / 2
                                                   : s->nv + n;
    GROW(s->uf, c);
    s->ufcap = c;
  }
  return true;
}

/* The batch arrays for a piece of nv vertices and nt triangles. */
static bool batch_room(tt__tin_stream *s, size_t nv, size_t nt)
{
  if (nv > s->bvcap) {
    GROW(s->map, nv);
    GROW(s->b_zero, nv);
    GROW(s->b_zero_n, nv);
    s->bvcap = nv;
  }
  if (nt > s->btcap) {
    GROW(s->b_rmse, nt);
    GROW(s->b_n, nt);
    s->btcap = nt;
  }
  return true;
}
#undef GROW

static int32_t uf_find(int32_t *p, int32_t x)
{
  while (p[x] != x) {
    p[x] = p[p[x]];
    x = p[x];
  }
  return x;
}

/* The last tile, in tile order, whose cells hold sample (c, r). */
static size_t last_tile(const tt__tin_stream *s, size_t c, size_t r)
{
  size_t i = c / s->N < s->ntx - 1 ? c / s->N : s->ntx - 1;
  size_t j = r / s->N < s->nty - 1 ? r / s->N : s->nty - 1;
  return j * s->ntx + i;
}

/* The first n pending vertices as out->vtx, popped at the next add. */
static void hand_out(tt__tin_stream *s, size_t n,
                     tt__stream_batch *out)
{
  tt_tin *v = &s->vtx;
  memset(v, 0, sizeof *v);
  v->nv = n;
  v->vc = s->pc + s->off;
  v->vr = s->pr + s->off;
  v->vzd = s->pz + s->off;
  v->v_ins_err = s->pins + s->off;
  v->v_star_max = s->psmax + s->off;
  v->v_star_rmse = s->pssq + s->off;
  v->v_star_n = s->pn + s->off;
  v->v_importance = s->pimp + s->off;
  v->area_fn = s->area_fn;
  memcpy(v->area_par, s->area_par, sizeof v->area_par);
  memcpy(v->gt, s->gt, sizeof v->gt);
  memcpy(v->frame, s->frame, sizeof v->frame);
  out->vtx = v;
  out->vtx_first = s->base;
  s->handed = n;
}

/* The batches' area function (geodesic areas of a geographic DEM). */
static void set_area(tt__tin_stream *s, tt_area_fn fn, const double params[4])
{
  s->area_fn = fn;
  for (int k = 0; k < 4; k++)
    s->area_par[k] = fn ? params[k] : 0;
}

void tt__tin_stream_set_ground(tt__tin_stream *s, const tt_grid *window)
{
  if (window->area_fn)
    set_area(s, window->area_fn, window->area_par);
}

tt_status tt__tin_stream_add(tt_context *ctx, tt__tin_stream *s,
                             const tt_tin *piece, const tt_tile *tile,
                             size_t k, tt__stream_batch *out)
{
  memset(out, 0, sizeof *out);
  /* the vertices handed out last time are written: pop them */
  s->base += s->handed;
  s->off += s->handed;
  s->np -= s->handed;
  s->handed = 0;
  const tt_error_stats *e = &piece->summary.errors;
  s->valid += piece->summary.valid_samples;
  s->forced += piece->summary.forced_vertices;
  s->seconds_mesh += piece->summary.seconds_mesh;
  s->seconds_stats += piece->summary.seconds_statistics;
  s->criterion = piece->summary.criterion;
  s->start_vertices += piece->summary.start_vertices;
  s->removed += piece->summary.removed_vertices;
  s->refused += piece->summary.refused_bound;
  if (piece->summary.rounds > s->rounds)
    s->rounds = piece->summary.rounds;
  if (piece->nt > 0) {
    if (!s->have_frame) {
      memcpy(s->frame, piece->frame, sizeof s->frame);
      s->have_frame = true;
      s->ground = piece->vgxy != NULL;
    }
    if ((piece->vgxy != NULL) != s->ground)
      return tt__error(ctx, TT_ERR_ARG, "the piece of the tile at column "
                       "%zu, row %zu is %s ground points, the pieces before "
                       "it %s", tile->col0, tile->row0, piece->vgxy
                       ? "measured on" : "without", s->ground ? "on them"
                       : "without them");
    if (piece->area_fn && !s->area_fn)
      set_area(s, piece->area_fn, piece->area_par);
    if (s->nv + piece->nv > INT32_MAX)
      return tt__error(ctx, TT_ERR_LIMIT, "more than %d vertices",
                       INT32_MAX);
    if (!pending_room(s, piece->nv) || !batch_room(s, piece->nv, piece->nt))
      goto oom;
    if (s->hn + piece->nv > s->hcap / 2 && !rehash(s, piece->nv))
      goto oom;
    size_t dups = 0;
    for (size_t i = 0; i < piece->nt; i++)
      s->b_n[i] = piece->t_n[i];
    for (size_t v = 0; v < piece->nv; v++) {
      int32_t c = piece->vc[v], r = piece->vr[v];
      bool outline = (size_t)c == tile->col0 || (size_t)c == tile->col1 ||
                     (size_t)r == tile->row0 || (size_t)r == tile->row1;
      int64_t key = (int64_t)r * (int64_t)s->W + c;
      size_t slot = 0;
      s->b_zero[v] = 0;
      s->b_zero_n[v] = 0;
      if (outline) {
        slot = hslot(s, key);
        if (s->hkey[slot] == key) {
          s->map[v] = s->hval[slot];
          dups++;
          if (piece->v_home)
            s->b_n[piece->v_home[v]]--;
          continue;
        }
      }
      size_t id = s->nv++;
      size_t at = s->off + s->np++;
      s->map[v] = (int32_t)id;
      s->pc[at] = c;
      s->pr[at] = r;
      s->pz[at] = piece->vzd ? piece->vzd[v] : (double)piece->vz[v];
      s->pins[at] = piece->v_ins_err ? piece->v_ins_err[v] : NAN;
      s->pimp[at] = piece->v_importance ? piece->v_importance[v] : NAN;
      s->psmax[at] = 0;
      s->pssq[at] = 0;
      s->pn[at] = 0;
      s->plast[at] = last_tile(s, (size_t)c, (size_t)r);
      s->uf[id] = (int32_t)id;
      s->zmin = s->pz[at] < s->zmin ? s->pz[at] : s->zmin;
      s->zmax = s->pz[at] > s->zmax ? s->pz[at] : s->zmax;
      if (outline && s->plast[at] > k) {
        if (s->nopen == s->opencap) {
          size_t c2 = s->opencap ? 2 * s->opencap : 1024;
          int32_t *o = realloc(s->open, c2 * sizeof *o);
          if (!o)
            goto oom;
          s->open = o;
          s->opencap = c2;
        }
        s->open[s->nopen++] = (int32_t)id;
        s->hkey[slot] = key;
        s->hval[slot] = (int32_t)id;
        s->hn++;
      }
    }
    /* the triangles: merge.c's sample counts and rmse, then the star sums
     * of their corners in triangle order */
    for (size_t i = 0; i < piece->nt; i++) {
      uint64_t dropped = piece->t_n[i] - s->b_n[i];
      double rm = (double)piece->t_rmse[i];
      double sq = rm * rm * (double)piece->t_n[i];
      s->b_rmse[i] = dropped && s->b_n[i]
                         ? (float)sqrt(sq / (double)s->b_n[i])
                         : piece->t_rmse[i];
      int32_t g0 = s->map[piece->tv[3 * i]];
      for (int c = 0; c < 3; c++) {
        int32_t g = s->map[piece->tv[3 * i + c]];
        size_t at = s->off + (size_t)g - s->base;
        if (piece->t_max[i] > s->psmax[at])
          s->psmax[at] = piece->t_max[i];
        s->pssq[at] += sq;
        s->pn[at] += s->b_n[i];
        int32_t a = uf_find(s->uf, g0), b = uf_find(s->uf, g);
        if (a != b)
          s->uf[a] = b;
      }
    }
    s->covered += e->covered - dups;
    /* the triangles' batch: the piece's arrays, the sums above */
    tt_tin *t = &s->tri;
    memset(t, 0, sizeof *t);
    t->nv = piece->nv;
    t->vc = piece->vc;
    t->vr = piece->vr;
    t->vz = piece->vz;
    t->vzd = piece->vzd;
    t->v_ins_err = s->b_zero;
    t->v_star_max = s->b_zero;
    t->v_star_rmse = s->b_zero;
    t->v_star_n = s->b_zero_n;
    t->nt = piece->nt;
    t->tv = piece->tv;
    t->t_max = piece->t_max;
    t->t_rmse = s->b_rmse;
    t->t_n = s->b_n;
    t->vgxy = piece->vgxy;
    t->vgk = piece->vgk;
    t->vgconv = piece->vgconv;
    t->area_fn = s->area_fn;
    memcpy(t->area_par, s->area_par, sizeof t->area_par);
    memcpy(t->gt, s->gt, sizeof t->gt);
    memcpy(t->frame, s->frame, sizeof t->frame);
    out->tri = t;
    out->map = s->map;
    out->tri_first = s->nt;
    s->nt += piece->nt;
    s->sum_abs += e->total_abs;
    s->sum_sq += e->l2 * e->l2;
    if (e->max_col >= 0) {
      int64_t at = e->max_row * (int64_t)s->W + e->max_col;
      if (s->max_index < 0 || e->max_error > s->max_err ||
          (e->max_error == s->max_err && at < s->max_index)) {
        s->max_err = e->max_error;
        s->max_index = at;
      }
    }
  }
  /* outline vertices closed by this tile leave the table */
  size_t kept = 0;
  for (size_t i = 0; i < s->nopen; i++) {
    size_t at = s->off + (size_t)s->open[i] - s->base;
    if (s->plast[at] > k)
      s->open[kept++] = s->open[i];
  }
  if (kept != s->nopen) {
    s->nopen = kept;
    if (!rehash(s, 0))
      goto oom;
  }
  /* the final vertices at the front, in id order */
  size_t n = 0;
  while (n < s->np && s->plast[s->off + n] <= k) {
    size_t at = s->off + n;
    s->pssq[at] = s->pn[at] ? sqrt(s->pssq[at] / (double)s->pn[at]) : 0.0;
    n++;
  }
  hand_out(s, n, out);
  return TT_OK;
oom:
  return tt__error(ctx, TT_ERR_NOMEM, "out of memory while merging the "
                   "tile at column %zu, row %zu (%zu vertices and %zu "
                   "triangles so far)", tile->col0, tile->row0, s->nv,
                   s->nt);
}

size_t tt__tin_stream_pending(const tt__tin_stream *s)
{
  return s->np - s->handed;
}

void tt__tin_stream_counts(const tt__tin_stream *s, size_t *out_vertices,
                           size_t *out_triangles)
{
  *out_vertices = s->nv;
  *out_triangles = s->nt;
}

size_t tt__tin_stream_bytes(const tt__tin_stream *s)
{
  if (!s)
    return 0;
  /* pending: col, row (4 each), height, insertion error, star max, sum of
   * squares, count, last tile, importance (8 each); the table and the
   * open list; the components; the batch's arrays */
  return s->pcap * (4 + 4 + 7 * 8) + s->hcap * (8 + 4) + s->opencap * 4 +
         s->ufcap * 4 + s->bvcap * (4 + 8 + 8) + s->btcap * (8 + 8);
}

void tt__tin_stream_summary(const tt__tin_stream *s, tt_tin_summary *out,
                            double *out_zmin, double *out_zmax)
{
  memset(out, 0, sizeof *out);
  size_t pieces = 0;
  for (size_t v = 0; v < s->nv; v++)
    pieces += s->uf[v] == (int32_t)v;
  out->criterion = s->criterion;
  out->vertices = s->nv;
  out->triangles = s->nt;
  out->valid_samples = s->valid;
  out->grid_width = s->W;
  out->grid_height = s->H;
  out->stop_reason = TT_STOP_MAX_ERROR;
  out->components = pieces;
  out->forced_vertices = s->forced;
  out->start_vertices = s->start_vertices;
  out->removed_vertices = s->removed;
  out->rounds = s->rounds;
  out->refused_bound = s->refused;
  out->seconds_mesh = s->seconds_mesh;
  out->seconds_statistics = s->seconds_stats;
  tt_error_stats *e = &out->errors;
  e->samples = s->valid;
  e->covered = s->covered;
  e->max_error = s->max_index >= 0 ? s->max_err : 0;
  e->total_abs = s->sum_abs;
  e->l2 = sqrt(s->sum_sq);
  e->rmse = s->covered ? sqrt(s->sum_sq / (double)s->covered) : 0;
  e->mean_abs = s->covered ? s->sum_abs / (double)s->covered : 0;
  e->max_col = s->max_index >= 0 ? s->max_index % (int64_t)s->W : -1;
  e->max_row = s->max_index >= 0 ? s->max_index / (int64_t)s->W : -1;
  *out_zmin = s->zmin;
  *out_zmax = s->zmax;
}
