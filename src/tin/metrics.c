/*
 * metrics.c -- error measures of a finished mesh against its grid (SPEC
 * section 6) and the per-triangle and per-vertex bookkeeping of the output.
 *
 * One pass over the triangles scans the samples each owns (raster_scan.c),
 * so every valid sample is measured exactly once; a vertex's own sample has
 * error zero and is counted with the triangle its vertex edge belongs to.
 * A vertex's star statistics gather the samples owned by the triangles
 * around it. A mesh without triangles is refused (TT_ERR_DATA), and mesh
 * vertices in no triangle are left out of the TIN, so every TIN vertex is a
 * corner of a triangle (vertex indices keep their insertion order). Cost: O(samples + triangles); memory: the compact tin arrays
 * plus 12 bytes per vertex and 4 per triangle slot while building.
 * Every RMS is clamped to its max (rounding could lift it by an ulp).
 *
 * Part of src/tin/, the finished TIN: its records and error statistics, eval,
 * synthetic terrains.
 */
#include "mesh/raster_scan.h"
#include "tin/tin.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static tt_status alloc_tin(tt_context *ctx, size_t nv, size_t nt, bool f64,
                           tt_tin **out)
{
  tt_tin *tin = calloc(1, sizeof *tin);
  if (!tin)
    return tt__error(ctx, TT_ERR_NOMEM, "out of memory for the TIN");
  size_t v1 = nv ? nv : 1, t1 = nt ? nt : 1;
  tin->vc = malloc(v1 * sizeof *tin->vc);
  tin->vr = malloc(v1 * sizeof *tin->vr);
  if (f64)
    tin->vzd = malloc(v1 * sizeof *tin->vzd);
  else
    tin->vz = malloc(v1 * sizeof *tin->vz);
  tin->v_star_max = calloc(v1, sizeof *tin->v_star_max);
  tin->v_star_rmse = calloc(v1, sizeof *tin->v_star_rmse);
  tin->v_star_n = calloc(v1, sizeof *tin->v_star_n);
  tin->tv = malloc(3 * t1 * sizeof *tin->tv);
  tin->t_max = malloc(t1 * sizeof *tin->t_max);
  tin->t_rmse = malloc(t1 * sizeof *tin->t_rmse);
  tin->t_n = malloc(t1 * sizeof *tin->t_n);
  if (!tin->vc || !tin->vr || !(tin->vz || tin->vzd) || !tin->v_star_max ||
      !tin->v_star_rmse || !tin->v_star_n || !tin->tv || !tin->t_max ||
      !tin->t_rmse || !tin->t_n) {
    tt_tin_destroy(tin);
    return tt__error(ctx, TT_ERR_NOMEM, "out of memory for a TIN of %zu "
                     "vertices and %zu triangles", nv, nt);
  }
  tin->nv = nv;
  tin->nt = nt;
  *out = tin;
  return TT_OK;
}

#define CHUNK 1024 /* triangles per job of the final scan */

typedef struct chunk_acc {
  size_t count;
  double max_err, sum_abs, sum_sq;
  int64_t max_index;
} chunk_acc;

typedef struct stats_job_arg {
  const tt__mesh *m;
  const tt_grid *g;
  const int32_t *order;
  tt_tin *tin;
  double *t_sq;
  chunk_acc *chunks;
  size_t nt;
} stats_job_arg;

/* Scans the triangles of one chunk: writes their own entries of the tin and
 * the chunk's partial sums. */
static void stats_job(void *arg, size_t c)
{
  const stats_job_arg *a = arg;
  chunk_acc acc = {0, 0, 0, 0, -1};
  size_t end = (c + 1) * CHUNK < a->nt ? (c + 1) * CHUNK : a->nt;
  for (size_t i = c * CHUNK; i < end; i++) {
    tt__scan_tri st;
    tt__scan_stats ss;
    tt__scan_tri_from_mesh(a->m, a->order[i], &st);
    tt__scan_stats_run(a->g, &st, &ss);
    a->tin->t_max[i] = ss.max_err;
    a->tin->t_n[i] = ss.count;
    a->t_sq[i] = ss.sum_sq;
    if (ss.count && (acc.max_index < 0 || ss.max_err > acc.max_err ||
                     (ss.max_err == acc.max_err &&
                      ss.max_index < acc.max_index))) {
      acc.max_err = ss.max_err;
      acc.max_index = ss.max_index;
    }
    acc.sum_abs += ss.sum_abs;
    acc.sum_sq += ss.sum_sq;
    acc.count += ss.count;
  }
  a->chunks[c] = acc;
}

static int32_t uf_find(int32_t *p, int32_t x)
{
  while (p[x] != x) {
    p[x] = p[p[x]];
    x = p[x];
  }
  return x;
}

/* Pieces of the mesh: triangles joined through shared edges. */
static size_t count_components(const tt__mesh *m)
{
  int32_t *p = malloc((m->nslots ? m->nslots : 1) * sizeof *p);
  if (!p)
    return 0;
  for (size_t t = 0; t < m->nslots; t++)
    p[t] = (int32_t)t;
  for (size_t e = 0; e < 3 * m->nslots; e++)
    if (m->hv[e - e % 3] >= 0 && m->twin[e] >= 0) {
      int32_t a = uf_find(p, (int32_t)(e / 3)), b = uf_find(p, m->twin[e] / 3);
      if (a != b)
        p[a] = b;
    }
  size_t n = 0;
  for (size_t t = 0; t < m->nslots; t++)
    if (m->hv[3 * t] >= 0 && uf_find(p, (int32_t)t) == (int32_t)t)
      n++;
  free(p);
  return n;
}

static size_t top_row(const tt__mesh *m, int32_t t)
{
  int32_t r0 = m->v[m->hv[3 * t]].r, r1 = m->v[m->hv[3 * t + 1]].r,
          r2 = m->v[m->hv[3 * t + 2]].r;
  int32_t r = r0 < r1 ? r0 : r1;
  return (size_t)(r < r2 ? r : r2);
}

/* tin->t_brk from the mesh's breakline flags (order: triangle i's slot),
 * left NULL when no edge has one. */
static tt_status breakline_bits(tt_context *ctx, const tt__mesh *m,
                                const int32_t *order, tt_tin *tin)
{
  bool any = false;
  for (size_t e = 0; e < 3 * m->nslots && !any; e++)
    any = (m->eflag[e] & TT__EDGE_BREAKLINE) && m->hv[e - e % 3] >= 0;
  if (!any)
    return TT_OK;
  tin->t_brk = calloc(m->nlive ? m->nlive : 1, 1);
  if (!tin->t_brk)
    return tt__error(ctx, TT_ERR_NOMEM, "out of memory for the breakline "
                     "flags of %zu triangles", m->nlive);
  for (size_t i = 0; i < m->nlive; i++)
    for (int k = 0; k < 3; k++)
      if (m->eflag[3 * (size_t)order[i] + (size_t)k] & TT__EDGE_BREAKLINE)
        tin->t_brk[i] |= (uint8_t)(1u << k);
  return TT_OK;
}

static tt_status build(tt_context *ctx, const tt__mesh *m, const tt_grid *g,
                       double *ins_err, tt__pool *pool, bool homes,
                       tt_tin **out_tin)
{
  tt_status status;
  tt_tin *tin = NULL;
  int32_t *slot_to_tri = NULL, *order = NULL;
  chunk_acc *chunks = NULL;
  size_t *first = NULL;
  double *t_sq = NULL;
  int32_t *vmap = NULL;
  *out_tin = NULL;

  /* A TIN without triangles is no surface: refuse it here, where every
   * caller gets it, rather than write vertices that eval cannot use. */
  if (m->nlive == 0) {
    free(ins_err);
    return tt__error(ctx, TT_ERR_DATA, "no triangle can be made: no grid "
                     "cell has three valid corners (the valid samples are "
                     "isolated by nodata)");
  }
  /* Vertices in no triangle (the starting corners of a raster whose
   * corners fall in nodata specks) are dropped: vmap[v] is a mesh vertex's
   * index in the TIN, or -1. Kept vertices stay in insertion order. */
  vmap = malloc((m->nv ? m->nv : 1) * sizeof *vmap);
  if (!vmap) {
    free(ins_err);
    return tt__error(ctx, TT_ERR_NOMEM, "out of memory for the TIN");
  }
  size_t nv = 0;
  for (size_t v = 0; v < m->nv; v++)
    vmap[v] = m->v[v].edge >= 0 ? (int32_t)nv++ : -1;
  for (size_t v = 0; v < m->nv; v++)
    if (vmap[v] >= 0 && ins_err)
      ins_err[vmap[v]] = ins_err[v]; /* vmap[v] <= v: in place */

  status = alloc_tin(ctx, nv, m->nlive, m->vz != NULL, &tin);
  if (status != TT_OK) {
    free(ins_err);
    free(vmap);
    return status;
  }
  tin->v_ins_err = ins_err;
  if (homes && !(tin->v_home = malloc((nv ? nv : 1) * sizeof *tin->v_home))) {
    status = tt__error(ctx, TT_ERR_NOMEM, "out of memory for the TIN");
    goto done;
  }
  slot_to_tri = malloc((m->nslots ? m->nslots : 1) * sizeof *slot_to_tri);
  t_sq = malloc((m->nlive ? m->nlive : 1) * sizeof *t_sq);
  if (!slot_to_tri || !t_sq) {
    status = tt__error(ctx, TT_ERR_NOMEM, "out of memory while measuring "
                       "the TIN of %zu vertices and %zu triangles",
                       m->nv, m->nlive);
    goto done;
  }
  memcpy(tin->gt, g->gt, sizeof tin->gt);
  memcpy(tin->frame, g->frame, sizeof tin->frame);
  tin->area_fn = g->area_fn;
  memcpy(tin->area_par, g->area_par, sizeof tin->area_par);
  if (g->gxy) {
    size_t v1 = m->nv ? m->nv : 1;
    tin->vgxy = malloc(2 * v1 * sizeof *tin->vgxy);
    tin->vgk = malloc(v1 * sizeof *tin->vgk);
    tin->vgconv = malloc(v1 * sizeof *tin->vgconv);
    if (!tin->vgxy || !tin->vgk || !tin->vgconv) {
      status = tt__error(ctx, TT_ERR_NOMEM, "out of memory for the TIN");
      goto done;
    }
    /* indexed as the TIN's vertices (vmap): a vertex in no triangle
     * (removed by decimation, outside the valid domain) is skipped */
    for (size_t v = 0; v < m->nv; v++) {
      if (vmap[v] < 0)
        continue;
      size_t i = (size_t)m->v[v].r * g->nx + (size_t)m->v[v].c;
      size_t o = (size_t)vmap[v];
      tin->vgxy[2 * o] = g->gxy[2 * i];
      tin->vgxy[2 * o + 1] = g->gxy[2 * i + 1];
      /* the scale and convergence of the vertex's sample, derived here
       * for vertices only (the grid keeps 16 bytes a sample) */
      double k = 1, conv = 0;
      if (tt_grid_ground_scale_at(g, m->v[v].c, m->v[v].r, &k, &conv) !=
          TT_OK) {
        k = 1;
        conv = 0;
      }
      tin->vgk[o] = (float)k;
      tin->vgconv[o] = (float)conv;
    }
  }
  for (size_t v = 0; v < m->nv; v++) {
    if (vmap[v] < 0)
      continue;
    tin->vc[vmap[v]] = m->v[v].c;
    tin->vr[vmap[v]] = m->v[v].r;
    if (tin->vzd)
      tin->vzd[vmap[v]] = tt__mesh_z(m, (int32_t)v);
    else
      tin->vz[vmap[v]] = m->v[v].z;
  }

  tt_error_stats *es = &tin->summary.errors;
  memset(es, 0, sizeof *es);
  es->max_col = es->max_row = -1;
  double sum_abs = 0, sum_sq = 0;
  size_t count = 0;
  int64_t max_index = -1;
  /* Triangles go out in spatial order: by the row of their top corner,
   * then by slot (a counting sort, O(T + rows)). The scan below then walks
   * the grid band by band, which keeps the rows it reads in cache (10x
   * faster than slot order on a 4097^2 grid), and the output layers get
   * the locality that R-trees and map renderers like. */
  order = malloc((m->nlive ? m->nlive : 1) * sizeof *order);
  first = calloc(g->ny + 1, sizeof *first);
  if (!order || !first) {
    status = tt__error(ctx, TT_ERR_NOMEM, "out of memory while measuring "
                       "the TIN of %zu vertices and %zu triangles",
                       m->nv, m->nlive);
    goto done;
  }
  /* slot_to_tri holds each live slot's top row for the two passes of the
   * sort, then the slot's triangle index */
  for (size_t s = 0; s < m->nslots; s++) {
    slot_to_tri[s] = -1;
    if (tt__mesh_live(m, (int32_t)s)) {
      slot_to_tri[s] = (int32_t)top_row(m, (int32_t)s);
      first[slot_to_tri[s] + 1]++;
    }
  }
  for (size_t y = 0; y < g->ny; y++)
    first[y + 1] += first[y];
  for (size_t s = 0; s < m->nslots; s++)
    if (slot_to_tri[s] >= 0)
      order[first[slot_to_tri[s]]++] = (int32_t)s;
  size_t nt = m->nlive;
  for (size_t i = 0; i < nt; i++) {
    int32_t s = order[i];
    slot_to_tri[s] = (int32_t)i;
    for (int k = 0; k < 3; k++)
      tin->tv[3 * i + k] = vmap[m->hv[3 * (size_t)s + k]];
  }
  status = breakline_bits(ctx, m, order, tin);
  if (status != TT_OK)
    goto done;
  /* the scans, in fixed chunks reduced in chunk order: the sums do not
   * depend on the number of threads */
  size_t nchunks = (nt + CHUNK - 1) / CHUNK;
  chunks = calloc(nchunks ? nchunks : 1, sizeof *chunks);
  if (!chunks) {
    status = tt__error(ctx, TT_ERR_NOMEM, "out of memory while measuring "
                       "the TIN of %zu vertices and %zu triangles",
                       m->nv, m->nlive);
    goto done;
  }
  stats_job_arg ja = {m, g, order, tin, t_sq, chunks, nt};
  tt__pool_run(pool, nchunks, stats_job, &ja);
  for (size_t c = 0; c < nchunks; c++) {
    const chunk_acc *ca = &chunks[c];
    if (ca->count && (max_index < 0 || ca->max_err > es->max_error ||
                      (ca->max_err == es->max_error &&
                       ca->max_index < max_index))) {
      es->max_error = ca->max_err;
      max_index = ca->max_index;
    }
    sum_abs += ca->sum_abs;
    sum_sq += ca->sum_sq;
    count += ca->count;
  }
  /* vertex samples: error zero, owned by the triangle of the vertex edge */
  for (size_t v = 0; v < m->nv; v++) {
    int32_t e = m->v[v].edge;
    if (e < 0)
      continue;
    int32_t t = slot_to_tri[e / 3];
    tin->t_n[t]++;
    if (tin->v_home)
      tin->v_home[vmap[v]] = t;
    count++;
    if (max_index < 0) {
      max_index = (int64_t)m->v[v].r * (int64_t)g->nx + m->v[v].c;
      es->max_error = 0;
    }
  }
  for (size_t t = 0; t < nt; t++) {
    /* An RMS is at most the max, but sqrt(sum / n) of n equal errors may
     * round one ulp above it: clamp, so rmse <= max_err holds in every
     * row written. */
    tin->t_rmse[t] = tin->t_n[t] ? fmin(sqrt(t_sq[t] / (double)tin->t_n[t]),
                                        tin->t_max[t])
                                 : 0.0;
    for (int k = 0; k < 3; k++) {
      int32_t v = tin->tv[3 * t + k];
      if (tin->t_max[t] > tin->v_star_max[v])
        tin->v_star_max[v] = tin->t_max[t];
      tin->v_star_rmse[v] += t_sq[t]; /* sum of squares for now */
      tin->v_star_n[v] += tin->t_n[t];
    }
  }
  for (size_t v = 0; v < nv; v++)
    tin->v_star_rmse[v] = tin->v_star_n[v]
                              ? fmin(sqrt(tin->v_star_rmse[v] /
                                          (double)tin->v_star_n[v]),
                                     tin->v_star_max[v])
                              : 0.0;
  es->samples = count; /* the caller sets the valid count */
  es->covered = count;
  tin->summary.components = count_components(m);
  es->total_abs = sum_abs;
  es->l2 = sqrt(sum_sq);
  es->rmse = count ? fmin(sqrt(sum_sq / (double)count), es->max_error) : 0;
  es->mean_abs = count ? sum_abs / (double)count : 0;
  if (max_index >= 0) {
    es->max_col = max_index % (int64_t)g->nx;
    es->max_row = max_index / (int64_t)g->nx;
  }
  tin->summary.vertices = nv;
  tin->summary.triangles = nt;
  tin->summary.grid_width = g->nx;
  tin->summary.grid_height = g->ny;
  *out_tin = tin;
  tin = NULL;
  status = TT_OK;
done:
  free(chunks);
  free(order);
  free(first);
  free(slot_to_tri);
  free(t_sq);
  free(vmap);
  tt_tin_destroy(tin);
  return status;
}

tt_status tt__tin_build(tt_context *ctx, const tt__mesh *m, const tt_grid *g,
                        double *ins_err, tt__pool *pool, tt_tin **out_tin)
{
  return build(ctx, m, g, ins_err, pool, false, out_tin);
}

tt_status tt__tin_build_homes(tt_context *ctx, const tt__mesh *m,
                              const tt_grid *g, double *ins_err,
                              tt__pool *pool, tt_tin **out_tin)
{
  return build(ctx, m, g, ins_err, pool, true, out_tin);
}
