/*
 * metrics.c -- error measures of a finished mesh against its grid (SPEC
 * section 6) and the per-triangle and per-vertex bookkeeping of the output.
 *
 * One pass over the triangles scans the samples each owns (raster_scan.c),
 * so every valid sample is measured exactly once; a vertex's own sample has
 * error zero and is counted with the triangle its vertex edge belongs to.
 * A vertex's star statistics gather the samples owned by the triangles
 * around it. Cost: O(samples + triangles); memory: the compact tin arrays
 * plus 12 bytes per vertex and 4 per triangle slot while building.
 */
#include "raster_scan.h"
#include "tin.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static tt_status alloc_tin(tt_context *ctx, size_t nv, size_t nt,
                           tt_tin **out)
{
  tt_tin *tin = calloc(1, sizeof *tin);
  if (!tin)
    return tt__error(ctx, TT_ERR_NOMEM, "out of memory for the TIN");
  size_t v1 = nv ? nv : 1, t1 = nt ? nt : 1;
  tin->vc = malloc(v1 * sizeof *tin->vc);
  tin->vr = malloc(v1 * sizeof *tin->vr);
  tin->vz = malloc(v1 * sizeof *tin->vz);
  tin->v_star_max = calloc(v1, sizeof *tin->v_star_max);
  tin->v_star_rmse = calloc(v1, sizeof *tin->v_star_rmse);
  tin->v_star_n = calloc(v1, sizeof *tin->v_star_n);
  tin->tv = malloc(3 * t1 * sizeof *tin->tv);
  tin->t_max = malloc(t1 * sizeof *tin->t_max);
  tin->t_rmse = malloc(t1 * sizeof *tin->t_rmse);
  tin->t_n = malloc(t1 * sizeof *tin->t_n);
  if (!tin->vc || !tin->vr || !tin->vz || !tin->v_star_max ||
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

tt_status tt__tin_build(tt_context *ctx, const tt__mesh *m, const tt_grid *g,
                        double *ins_err, tt_tin **out_tin)
{
  tt_status status;
  tt_tin *tin = NULL;
  int32_t *slot_to_tri = NULL;
  double *t_sq = NULL;
  *out_tin = NULL;

  status = alloc_tin(ctx, m->nv, m->nlive, &tin);
  if (status != TT_OK) {
    free(ins_err);
    return status;
  }
  tin->v_ins_err = ins_err;
  slot_to_tri = malloc((m->nslots ? m->nslots : 1) * sizeof *slot_to_tri);
  t_sq = malloc((m->nlive ? m->nlive : 1) * sizeof *t_sq);
  if (!slot_to_tri || !t_sq) {
    status = tt__error(ctx, TT_ERR_NOMEM, "out of memory for the TIN");
    goto done;
  }
  memcpy(tin->gt, g->gt, sizeof tin->gt);
  memcpy(tin->frame, g->frame, sizeof tin->frame);
  for (size_t v = 0; v < m->nv; v++) {
    tin->vc[v] = m->vc[v];
    tin->vr[v] = m->vr[v];
    tin->vz[v] = g->z[(size_t)m->vr[v] * g->nx + (size_t)m->vc[v]];
  }

  tt_error_stats *es = &tin->summary.errors;
  memset(es, 0, sizeof *es);
  es->max_col = es->max_row = -1;
  double sum_abs = 0, sum_sq = 0;
  size_t count = 0;
  int64_t max_index = -1;
  size_t nt = 0;
  for (size_t s = 0; s < m->nslots; s++) {
    slot_to_tri[s] = -1;
    if (!tt__mesh_live(m, (int32_t)s))
      continue;
    slot_to_tri[s] = (int32_t)nt;
    tt__scan_tri st;
    tt__scan_stats ss;
    tt__scan_tri_from_mesh(m, g, (int32_t)s, &st);
    tt__scan_stats_run(g, &st, &ss);
    for (int k = 0; k < 3; k++)
      tin->tv[3 * nt + k] = m->hv[3 * s + k];
    tin->t_max[nt] = ss.max_err;
    tin->t_n[nt] = ss.count;
    t_sq[nt] = ss.sum_sq;
    if (ss.count && (max_index < 0 || ss.max_err > es->max_error)) {
      es->max_error = ss.max_err;
      max_index = ss.max_index;
    }
    sum_abs += ss.sum_abs;
    sum_sq += ss.sum_sq;
    count += ss.count;
    nt++;
  }
  /* vertex samples: error zero, owned by the triangle of the vertex edge */
  for (size_t v = 0; v < m->nv; v++) {
    int32_t e = m->vedge[v];
    if (e < 0)
      continue;
    int32_t t = slot_to_tri[e / 3];
    tin->t_n[t]++;
    count++;
    if (max_index < 0) {
      max_index = (int64_t)m->vr[v] * (int64_t)g->nx + m->vc[v];
      es->max_error = 0;
    }
  }
  for (size_t t = 0; t < nt; t++) {
    tin->t_rmse[t] = tin->t_n[t] ? (float)sqrt(t_sq[t] / (double)tin->t_n[t])
                                 : 0.0f;
    for (int k = 0; k < 3; k++) {
      int32_t v = tin->tv[3 * t + k];
      if (tin->t_max[t] > tin->v_star_max[v])
        tin->v_star_max[v] = tin->t_max[t];
      tin->v_star_rmse[v] += t_sq[t]; /* sum of squares for now */
      tin->v_star_n[v] += tin->t_n[t];
    }
  }
  for (size_t v = 0; v < m->nv; v++)
    tin->v_star_rmse[v] = tin->v_star_n[v]
                              ? sqrt(tin->v_star_rmse[v] /
                                     (double)tin->v_star_n[v])
                              : 0.0;
  es->samples = count;
  es->covered = count;
  es->total_abs = sum_abs;
  es->l2 = sqrt(sum_sq);
  es->rmse = count ? sqrt(sum_sq / (double)count) : 0;
  es->mean_abs = count ? sum_abs / (double)count : 0;
  if (max_index >= 0) {
    es->max_col = max_index % (int64_t)g->nx;
    es->max_row = max_index / (int64_t)g->nx;
  }
  tin->summary.vertices = m->nv;
  tin->summary.triangles = nt;
  tin->summary.grid_width = g->nx;
  tin->summary.grid_height = g->ny;
  *out_tin = tin;
  tin = NULL;
  status = TT_OK;
done:
  free(slot_to_tri);
  free(t_sq);
  tt_tin_destroy(tin);
  return status;
}
