/*
 * merge.c -- the pieces of a tiled run joined into one TIN
 * (tt_tin_merger): vertices numbered once, triangles of every tile, the
 * statistics of the whole.
 *
 * Pieces are added in a fixed order (tile order, whatever order the tiles
 * finished in), and everything is appended or summed in that order, so the
 * result does not depend on the number of threads. A vertex on a tile's
 * outline is looked up by its sample in a hash table: a border vertex that
 * an earlier piece already has keeps that piece's id and is written once;
 * its own sample, which each piece counts in one of its triangles
 * (tt_tin.v_home), is uncounted from the later pieces' triangles. Samples
 * on a border edge are counted by one piece only already (tile.c), so the
 * sums of the pieces' errors are the whole TIN's. A vertex's star
 * statistics are gathered again over the merged triangles (its star may
 * span four tiles); the pieces of the TIN (components) are counted over
 * vertices shared by triangles, so two triangles meeting at a single
 * vertex count as one piece here (across an edge in an untiled run).
 *
 * A geographic or Web Mercator DEM's pieces carry their vertices' ground
 * points, scale factors and convergences (tile.c), which are copied with
 * the vertex (a shared vertex's are the same in both pieces: computed
 * from the DEM's column and row, and from the window beyond the border),
 * and the merged TIN measures areas with the pieces' area function.
 *
 * Memory: the TIN's arrays as a refined TIN holds them (with ground
 * points, 24 bytes a vertex more), plus 8 bytes per triangle (its squared
 * errors) and 16 per vertex on a tile outline (the table) until the end;
 * no sample.
 *
 * Part of src/tile/, tiled runs: the tiles, their shared borders, one tile's
 * run, the merge.
 */
#include "tile/tile.h"
#include "tin/tin.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

struct tt_tin_merger {
  size_t W, H;
  double gt[6], frame[4];
  bool have_frame, f64;
  /* a geographic or Web Mercator DEM: the vertices' ground points, scale
   * factors and convergences (every piece has them or none), and the
   * area function (from a piece, or tt_tin_merger_set_ground) */
  bool ground;
  tt_area_fn area_fn;
  double area_par[4];
  tt_tin *t;             /* the arrays, grown as pieces come */
  size_t vcap, tcap;
  double *t_sq;          /* per triangle: sum of squared errors */
  /* outline vertices: sample index -> vertex id, open addressing */
  int64_t *hkey;
  int32_t *hval;
  size_t hcap, hn;
  /* sums, in piece order */
  size_t covered, valid, forced;
  /* decimated pieces: their counts summed (rounds: the most of any), and
   * whether any piece has importances (else the TIN has none) */
  size_t start_vertices, removed, rounds, refused;
  bool importance;
  double sum_abs, sum_sq, max_err;
  int64_t max_index;
  double seconds_mesh, seconds_stats;
};

tt_status tt_tin_merger_create(tt_context *ctx, size_t dem_width,
                               size_t dem_height, const double gt[6],
                               tt_tin_merger **out_merger)
{
  if (!out_merger || !gt)
    return tt__error(ctx, TT_ERR_ARG, "gt and out_merger must not be NULL");
  *out_merger = NULL;
  tt_tin_merger *m = calloc(1, sizeof *m);
  if (!m || !(m->t = calloc(1, sizeof *m->t))) {
    free(m);
    return tt__error(ctx, TT_ERR_NOMEM, "out of memory");
  }
  m->W = dem_width;
  m->H = dem_height;
  memcpy(m->gt, gt, sizeof m->gt);
  m->max_index = -1;
  *out_merger = m;
  return TT_OK;
}

void tt_tin_merger_destroy(tt_tin_merger *m)
{
  if (!m)
    return;
  tt_tin_destroy(m->t);
  free(m->t_sq);
  free(m->hkey);
  free(m->hval);
  free(m);
}

void tt_tin_merger_size(const tt_tin_merger *m, size_t *out_vertices,
                        size_t *out_triangles, size_t *out_bytes)
{
  /* per vertex: col, row, height (8 as doubles), insertion error,
   * importance, and the star statistics finishing adds (24); per triangle: corners, max, rmse,
   * count and squared errors; the outline table */
  *out_vertices = m->t->nv;
  *out_triangles = m->t->nt;
  *out_bytes = m->vcap * (4 + 4 + (m->f64 ? 8 : 4) + 8 + 8 + 24 +
                         (m->ground ? 16 + 4 + 4 : 0)) +
               m->tcap * (12 + 8 + 4 + 8 + 8) + m->hcap * 12;
}

static void set_area_fn(tt_tin_merger *m, tt_area_fn fn,
                        const double params[4]);

static size_t hslot(const tt_tin_merger *m, int64_t key)
{
  uint64_t h = (uint64_t)key * 0x9E3779B97F4A7C15u;
  size_t i = (size_t)(h >> 17) & (m->hcap - 1);
  while (m->hkey[i] >= 0 && m->hkey[i] != key)
    i = (i + 1) & (m->hcap - 1);
  return i;
}

static bool hgrow(tt_tin_merger *m)
{
  if (2 * (m->hn + 1) <= m->hcap)
    return true;
  size_t ncap = m->hcap ? 2 * m->hcap : 1024;
  int64_t *ok = m->hkey;
  int32_t *ov = m->hval;
  size_t ocap = m->hcap;
  m->hkey = malloc(ncap * sizeof *m->hkey);
  m->hval = malloc(ncap * sizeof *m->hval);
  if (!m->hkey || !m->hval) {
    free(m->hkey);
    free(m->hval);
    m->hkey = ok;
    m->hval = ov;
    return false;
  }
  m->hcap = ncap;
  for (size_t i = 0; i < ncap; i++)
    m->hkey[i] = -1;
  for (size_t i = 0; i < ocap; i++)
    if (ok[i] >= 0) {
      size_t j = hslot(m, ok[i]);
      m->hkey[j] = ok[i];
      m->hval[j] = ov[i];
    }
  free(ok);
  free(ov);
  return true;
}

/* Room for nv vertices and nt triangles in the merged arrays. */
static bool reserve(tt_tin_merger *m, size_t nv, size_t nt)
{
  tt_tin *t = m->t;
  if (nv > m->vcap) {
    size_t c = m->vcap + m->vcap / 2 > nv ? m->vcap + m->vcap / 2 : nv;
    void *p;
#define GROW(field, n)                                                     \
  if (!(p = realloc(t->field, (n) * sizeof *t->field)))                    \
    return false;                                                          \
  t->field = p;
    GROW(vc, c) GROW(vr, c) GROW(v_ins_err, c) GROW(v_importance, c)
    if (m->f64) {
      GROW(vzd, c)
    } else {
      GROW(vz, c)
    }
    if (m->ground) {
      GROW(vgxy, 2 * c) GROW(vgk, c) GROW(vgconv, c)
    }
    m->vcap = c;
  }
  if (nt > m->tcap) {
    size_t c = m->tcap + m->tcap / 2 > nt ? m->tcap + m->tcap / 2 : nt;
    void *p;
    GROW(tv, 3 * c) GROW(t_max, c) GROW(t_rmse, c) GROW(t_n, c)
    if (!(p = realloc(m->t_sq, c * sizeof *m->t_sq)))
      return false;
    m->t_sq = p;
    m->tcap = c;
#undef GROW
  }
  return true;
}

/* The merged heights become doubles (a piece of a grid of doubles came). */
static bool widen(tt_tin_merger *m)
{
  tt_tin *t = m->t;
  double *d = malloc((m->vcap ? m->vcap : 1) * sizeof *d);
  if (!d)
    return false;
  for (size_t v = 0; v < t->nv; v++)
    d[v] = (double)t->vz[v];
  free(t->vz);
  t->vz = NULL;
  t->vzd = d;
  m->f64 = true;
  return true;
}

tt_status tt_tin_merger_add(tt_context *ctx, tt_tin_merger *m,
                            const tt_tin *piece, const tt_tile *tile)
{
  if (!m || !piece || !tile)
    return tt__error(ctx, TT_ERR_ARG, "merger, piece and tile must not be "
                     "NULL");
  tt_status status = TT_OK;
  int32_t *map = NULL;
  uint64_t *drop = NULL;
  const tt_error_stats *e = &piece->summary.errors;
  m->valid += piece->summary.valid_samples;
  m->forced += piece->summary.forced_vertices;
  m->start_vertices += piece->summary.start_vertices;
  m->removed += piece->summary.removed_vertices;
  m->refused += piece->summary.refused_bound;
  if (piece->summary.rounds > m->rounds)
    m->rounds = piece->summary.rounds;
  m->importance |= piece->v_importance != NULL;
  m->seconds_mesh += piece->summary.seconds_mesh;
  m->seconds_stats += piece->summary.seconds_statistics;
  m->t->summary.criterion = piece->summary.criterion;
  if (piece->nt == 0)
    return TT_OK;
  if (!m->have_frame) {
    memcpy(m->frame, piece->frame, sizeof m->frame);
    m->have_frame = true;
    m->ground = piece->vgxy != NULL;
  }
  if ((piece->vgxy != NULL) != m->ground)
    return tt__error(ctx, TT_ERR_ARG, "the piece of the tile at column %zu, "
                     "row %zu is %s ground points, the pieces before it %s",
                     tile->col0, tile->row0, piece->vgxy ? "measured on"
                     : "without", m->ground ? "on them" : "without them");
  if (piece->area_fn && !m->area_fn)
    set_area_fn(m, piece->area_fn, piece->area_par);
  if (piece->vzd && !m->f64 && !widen(m))
    goto oom;
  map = malloc(piece->nv * sizeof *map);
  drop = calloc(piece->nt, sizeof *drop);
  if (!map || !drop || !reserve(m, m->t->nv + piece->nv, m->t->nt + piece->nt))
    goto oom;
  tt_tin *t = m->t;
  size_t dups = 0;
  for (size_t v = 0; v < piece->nv; v++) {
    int32_t c = piece->vc[v], r = piece->vr[v];
    bool outline = (size_t)c == tile->col0 || (size_t)c == tile->col1 ||
                   (size_t)r == tile->row0 || (size_t)r == tile->row1;
    int64_t key = (int64_t)r * (int64_t)m->W + c;
    size_t slot = 0;
    if (outline) {
      if (!hgrow(m))
        goto oom;
      slot = hslot(m, key);
      if (m->hkey[slot] == key) {
        map[v] = m->hval[slot];
        dups++;
        if (piece->v_home)
          drop[piece->v_home[v]]++;
        continue;
      }
    }
    size_t id = t->nv++;
    map[v] = (int32_t)id;
    t->vc[id] = c;
    t->vr[id] = r;
    if (t->vzd)
      t->vzd[id] = piece->vzd ? piece->vzd[v] : (double)piece->vz[v];
    else
      t->vz[id] = piece->vz[v];
    t->v_ins_err[id] = piece->v_ins_err ? piece->v_ins_err[v] : NAN;
    if (m->ground) {
      t->vgxy[2 * id] = piece->vgxy[2 * v];
      t->vgxy[2 * id + 1] = piece->vgxy[2 * v + 1];
      t->vgk[id] = piece->vgk[v];
      t->vgconv[id] = piece->vgconv[v];
    }
    t->v_importance[id] = piece->v_importance ? piece->v_importance[v] : NAN;
    if (outline) {
      m->hkey[slot] = key;
      m->hval[slot] = (int32_t)id;
      m->hn++;
    }
  }
  for (size_t i = 0; i < piece->nt; i++) {
    size_t j = t->nt++;
    for (int k = 0; k < 3; k++)
      t->tv[3 * j + k] = map[piece->tv[3 * i + k]];
    double rm = (double)piece->t_rmse[i];
    m->t_sq[j] = rm * rm * (double)piece->t_n[i];
    t->t_max[j] = piece->t_max[i];
    t->t_n[j] = piece->t_n[i] - drop[i];
    t->t_rmse[j] = drop[i] && t->t_n[j]
                       ? (float)sqrt(m->t_sq[j] / (double)t->t_n[j])
                       : piece->t_rmse[i];
  }
  m->covered += e->covered - dups;
  m->sum_abs += e->total_abs;
  m->sum_sq += e->l2 * e->l2;
  if (e->max_col >= 0) {
    int64_t at = e->max_row * (int64_t)m->W + e->max_col;
    if (m->max_index < 0 || e->max_error > m->max_err ||
        (e->max_error == m->max_err && at < m->max_index)) {
      m->max_err = e->max_error;
      m->max_index = at;
    }
  }
  goto done;
oom:
  status = tt__error(ctx, TT_ERR_NOMEM, "out of memory while merging the "
                     "tile at column %zu, row %zu (%zu vertices and %zu "
                     "triangles so far)", tile->col0, tile->row0, m->t->nv,
                     m->t->nt);
done:
  free(map);
  free(drop);
  return status;
}

/* The merged TIN's area function (geodesic areas of a geographic DEM). */
static void set_area_fn(tt_tin_merger *m, tt_area_fn fn,
                        const double params[4])
{
  m->area_fn = fn;
  for (int k = 0; k < 4; k++)
    m->area_par[k] = fn ? params[k] : 0;
}

void tt_tin_merger_set_ground(tt_tin_merger *m, const tt_grid *window)
{
  if (window->area_fn)
    set_area_fn(m, window->area_fn, window->area_par);
}

static int32_t uf_find(int32_t *p, int32_t x)
{
  while (p[x] != x) {
    p[x] = p[p[x]];
    x = p[x];
  }
  return x;
}

tt_status tt_tin_merger_finish(tt_context *ctx, tt_tin_merger *m,
                               tt_tin **out_tin)
{
  if (!m || !out_tin)
    return tt__error(ctx, TT_ERR_ARG, "merger and out_tin must not be NULL");
  *out_tin = NULL;
  tt_tin *t = m->t;
  if (t->nt == 0)
    return tt__error(ctx, TT_ERR_DATA, "no triangle can be made: no grid "
                     "cell has three valid corners (the valid samples are "
                     "isolated by nodata)");
  size_t nv = t->nv ? t->nv : 1;
  t->v_star_max = calloc(nv, sizeof *t->v_star_max);
  t->v_star_rmse = calloc(nv, sizeof *t->v_star_rmse);
  t->v_star_n = calloc(nv, sizeof *t->v_star_n);
  int32_t *p = malloc(nv * sizeof *p);
  if (!t->v_star_max || !t->v_star_rmse || !t->v_star_n || !p) {
    free(p);
    return tt__error(ctx, TT_ERR_NOMEM, "out of memory for the star "
                     "statistics of %zu vertices", t->nv);
  }
  for (size_t v = 0; v < t->nv; v++)
    p[v] = (int32_t)v;
  for (size_t i = 0; i < t->nt; i++)
    for (int k = 0; k < 3; k++) {
      int32_t v = t->tv[3 * i + k];
      if (t->t_max[i] > t->v_star_max[v])
        t->v_star_max[v] = t->t_max[i];
      t->v_star_rmse[v] += m->t_sq[i];
      t->v_star_n[v] += t->t_n[i];
      int32_t a = uf_find(p, t->tv[3 * i]), b = uf_find(p, v);
      if (a != b)
        p[a] = b;
    }
  size_t pieces = 0;
  for (size_t v = 0; v < t->nv; v++) {
    t->v_star_rmse[v] = t->v_star_n[v]
                            ? sqrt(t->v_star_rmse[v] / (double)t->v_star_n[v])
                            : 0.0;
    pieces += uf_find(p, (int32_t)v) == (int32_t)v;
  }
  free(p);
  memcpy(t->gt, m->gt, sizeof t->gt);
  memcpy(t->frame, m->frame, sizeof t->frame);
  t->area_fn = m->area_fn;
  memcpy(t->area_par, m->area_par, sizeof t->area_par);
  tt_tin_summary *s = &t->summary;
  s->vertices = t->nv;
  s->triangles = t->nt;
  s->valid_samples = m->valid;
  s->grid_width = m->W;
  s->grid_height = m->H;
  s->stop_reason = TT_STOP_MAX_ERROR;
  s->components = pieces;
  s->forced_vertices = m->forced;
  s->start_vertices = m->start_vertices;
  s->removed_vertices = m->removed;
  s->rounds = m->rounds;
  s->refused_bound = m->refused;
  if (!m->importance) {
    free(t->v_importance);
    t->v_importance = NULL;
  }
  s->seconds_mesh = m->seconds_mesh;
  s->seconds_statistics = m->seconds_stats;
  tt_error_stats *e = &s->errors;
  e->samples = m->valid;
  e->covered = m->covered;
  e->max_error = m->max_index >= 0 ? m->max_err : 0;
  e->total_abs = m->sum_abs;
  e->l2 = sqrt(m->sum_sq);
  e->rmse = m->covered ? sqrt(m->sum_sq / (double)m->covered) : 0;
  e->mean_abs = m->covered ? m->sum_abs / (double)m->covered : 0;
  e->max_col = m->max_index >= 0 ? m->max_index % (int64_t)m->W : -1;
  e->max_row = m->max_index >= 0 ? m->max_index / (int64_t)m->W : -1;
  *out_tin = t;
  m->t = calloc(1, sizeof *m->t); /* the merger is spent; may be NULL */
  return TT_OK;
}
