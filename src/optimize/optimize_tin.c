/*
 * optimize_tin.c -- tt_optimize_run: optimise a TIN the caller already has
 * (ours or another tool's), given as a triangle soup in pixel space.
 *
 * The soup becomes a mesh: corners are snapped to the samples they stand
 * on (within 1e-6 pixel) and must be valid samples; equal corners become
 * one vertex (a hash on the pixel position); each triangle is turned
 * counter-clockwise in the ground frame (exact orientation), and one with
 * no area is refused. The mesh must then be a surface laid flat: no edge
 * used twice the same way (a fold or a duplicate), the angles around each
 * vertex summing to at most 2 pi (more: the triangles around it overlap),
 * the mesh's own invariants (tt__mesh_validate), and no valid sample
 * strictly inside two triangles (tt_eval_triangles' overlap count; two
 * triangles can overlap without sharing a vertex). The outline is the
 * boundary of the soup, which no swap crosses (boundary edges have no
 * twin); holes stay holes.
 *
 * Then the optimiser of optimize.h runs over the whole mesh (the local
 * swap for TT_OPTIMIZE_AUTO), refusing moves that lift a triangle above
 * max_error, and the TIN is built with the statistics of every sample.
 * Workload: O(T log T) to rebuild, then the optimiser's own cost.
 *
 * Part of src/optimize/, the optimisers: swaps under a criterion, look-ahead,
 * annealing, edge insertion, the dynamic programs.
 */
#include "base/internal.h"
#include "criteria/criterion.h"
#include "criteria/geometry.h"
#include "mesh/mesh.h"
#include "optimize/optimize.h"
#include "tin/tin.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

void tt_optimize_options_init(tt_optimize_options *opt)
{
  if (!opt)
    return;
  memset(opt, 0, sizeof *opt);
  opt->criterion = TT_CRITERION_DELAUNAY;
  opt->optimize = TT_OPTIMIZE_AUTO;
  opt->max_error = -1.0;
}

static int cmp_i64(const void *x, const void *y)
{
  int64_t a = *(const int64_t *)x, b = *(const int64_t *)y;
  return a < b ? -1 : a > b;
}

/* The vertex of sample (c, r), made when new; -1 when out of memory. */
static int32_t vertex_of(tt__mesh *m, int32_t *hash, size_t hcap, int32_t c,
                         int32_t r, float z)
{
  uint64_t k = ((uint64_t)(uint32_t)c << 32) | (uint32_t)r;
  size_t s = (size_t)((k * 0x9e3779b97f4a7c15ull) >> 17) & (hcap - 1);
  for (; hash[s] >= 0; s = (s + 1) & (hcap - 1))
    if (m->v[hash[s]].c == c && m->v[hash[s]].r == r)
      return hash[s];
  int32_t v = tt__mesh_add_vertex(m, c, r, z);
  if (v >= 0)
    hash[s] = v;
  return v;
}

/* Builds the mesh; TT_OK or TT_ERR_DATA / TT_ERR_NOMEM with the message
 * set. */
static tt_status rebuild(tt_context *ctx, const tt_grid *g, size_t nt,
                         const double *xyz, tt__mesh *m)
{
  tt_status st = TT_OK;
  size_t hcap = 64;
  while (hcap < 6 * nt)
    hcap <<= 1;
  int32_t *hash = malloc(hcap * sizeof *hash);
  int64_t *keys = malloc((3 * nt + 1) * sizeof *keys);
  double *sum = NULL;
  if (!hash || !keys || !tt__mesh_reserve(m, nt / 2 + 3, nt)) {
    st = tt__error(ctx, TT_ERR_NOMEM, "out of memory rebuilding %zu "
                   "triangles", nt);
    goto done;
  }
  for (size_t i = 0; i < hcap; i++)
    hash[i] = -1;
  for (size_t t = 0; t < nt; t++) {
    int32_t v[3];
    for (int k = 0; k < 3; k++) {
      double x = xyz[9 * t + 3 * k], y = xyz[9 * t + 3 * k + 1];
      double cx = floor(x + 0.5), cy = floor(y + 0.5);
      if (!(fabs(x - cx) <= 1e-6 && fabs(y - cy) <= 1e-6) || cx < 0 ||
          cy < 0 || cx >= (double)g->nx || cy >= (double)g->ny) {
        st = tt__error(ctx, TT_ERR_DATA, "triangle %zu: corner %d at pixel "
                       "(%.9g, %.9g) is not a sample of the %zux%zu DEM: "
                       "the corners of a TIN to optimise must be DEM "
                       "samples", t + 1, k + 1, x, y, g->nx, g->ny);
        goto done;
      }
      size_t c = (size_t)cx, r = (size_t)cy;
      float z = g->z[r * g->nx + c];
      if (isnan(z)) {
        st = tt__error(ctx, TT_ERR_DATA, "triangle %zu: corner %d at sample "
                       "(col %zu, row %zu) is nodata in the DEM", t + 1,
                       k + 1, c, r);
        goto done;
      }
      v[k] = vertex_of(m, hash, hcap, (int32_t)c, (int32_t)r, z);
      if (v[k] < 0) {
        st = tt__error(ctx, TT_ERR_NOMEM, "out of memory (or more than %zu "
                       "vertices)", (size_t)TT_MAX_VERTICES);
        goto done;
      }
    }
    int o = tt__mesh_orient(m, v[0], v[1], v[2]);
    if (o == 0) {
      st = tt__error(ctx, TT_ERR_DATA, "triangle %zu has no area (its "
                     "corners are collinear or repeated)", t + 1);
      goto done;
    }
    if (o < 0) {
      int32_t s = v[1];
      v[1] = v[2];
      v[2] = s;
    }
    if (tt__mesh_add_triangle(m, v[0], v[1], v[2]) < 0) {
      st = tt__error(ctx, TT_ERR_NOMEM, "out of memory rebuilding the mesh");
      goto done;
    }
    for (int k = 0; k < 3; k++)
      keys[3 * t + k] = ((int64_t)v[k] << 32) | (uint32_t)v[(k + 1) % 3];
  }
  qsort(keys, 3 * nt, sizeof *keys, cmp_i64);
  for (size_t i = 1; i < 3 * nt; i++)
    if (keys[i] == keys[i - 1]) {
      int32_t a = (int32_t)(keys[i] >> 32), b = (int32_t)(keys[i] & 0xffffffff);
      st = tt__error(ctx, TT_ERR_DATA, "the TIN overlaps itself: the edge "
                     "from sample (col %d, row %d) to (col %d, row %d) has "
                     "two triangles on the same side (a fold or a duplicate "
                     "triangle)", m->v[a].c, m->v[a].r, m->v[b].c, m->v[b].r);
      goto done;
    }
  /* the angles around each vertex: more than a full turn is an overlap */
  sum = calloc(m->nv ? m->nv : 1, sizeof *sum);
  if (!sum || !tt__mesh_link_all(m)) {
    st = tt__error(ctx, TT_ERR_NOMEM, "out of memory rebuilding the mesh");
    goto done;
  }
  tt__crit_env env = {m, g, NULL};
  double fr[4];
  tt__geo_frame(&env, fr);
  for (size_t t = 0; t < m->nslots; t++)
    for (int k = 0; k < 3; k++) {
      int32_t a = m->hv[3 * t + k], b = m->hv[3 * t + (k + 1) % 3],
              c = m->hv[3 * t + (k + 2) % 3];
      sum[a] += tt__gangle2(tt__geo_vec(fr, m, a, b), tt__geo_vec(fr, m, a, c));
    }
  for (size_t v = 0; v < m->nv; v++)
    if (sum[v] > 2 * TT__PI + 1e-9) {
      st = tt__error(ctx, TT_ERR_DATA, "the TIN overlaps itself around "
                     "sample (col %d, row %d): its triangles there turn "
                     "%.6g degrees, more than a full turn", m->v[v].c,
                     m->v[v].r, sum[v] * 180 / TT__PI);
      goto done;
    }
  char why[256];
  if (!tt__mesh_validate(m, why, sizeof why)) {
    st = tt__error(ctx, TT_ERR_DATA, "the triangles do not form a surface "
                   "laid flat: %s", why);
    goto done;
  }
  tt_eval_result ev;
  st = tt_eval_triangles(ctx, g, nt, xyz, &ev);
  if (st != TT_OK)
    goto done;
  if (ev.overlapped) {
    st = tt__error(ctx, TT_ERR_DATA, "the TIN overlaps itself: %zu valid "
                   "sample%s lie%s inside two triangles", ev.overlapped,
                   ev.overlapped == 1 ? "" : "s",
                   ev.overlapped == 1 ? "s" : "");
    goto done;
  }
  tt__mesh_clear_touched(m);
done:
  free(hash);
  free(keys);
  free(sum);
  return st;
}

tt_status tt_optimize_run(tt_context *ctx, const tt_grid *grid,
                          size_t ntriangles, const double *pix_xyz,
                          const tt_optimize_options *opt, tt_tin **out_tin)
{
  double t_start = tt__now();
  if (!grid || !opt || !out_tin || (ntriangles && !pix_xyz))
    return tt__error(ctx, TT_ERR_ARG, "grid, triangles, options and out_tin "
                     "must not be NULL");
  *out_tin = NULL;
  if (ntriangles == 0)
    return tt__error(ctx, TT_ERR_DATA, "no triangles to optimise");
  if (ntriangles > INT32_MAX / 3)
    return tt__error(ctx, TT_ERR_LIMIT, "%zu triangles: above the limit of "
                     "%d", ntriangles, INT32_MAX / 3);
  const tt__criterion_vt *crit = tt__criterion_get(opt->criterion);
  if (!crit)
    return tt__error(ctx, TT_ERR_ARG, "unknown criterion %d",
                     (int)opt->criterion);
  if (isnan(opt->max_error) || isinf(opt->max_error))
    return tt__error(ctx, TT_ERR_ARG, "max error must be a finite number, "
                     "got %g", opt->max_error);
  tt_status st = tt_optimize_check(ctx, opt->optimize, opt->criterion,
                                   &opt->anneal);
  if (st != TT_OK)
    return st;
  size_t valid = 0;
  st = tt_grid_check(ctx, grid, &valid);
  if (st != TT_OK)
    return st;

  tt__mesh m;
  tt__metric metric;
  tt__metric_from_frame(grid->frame, &metric);
  tt__mesh_init(&m, &metric);
  tt__mesh_use_ground_points(&m, grid->gxy, grid->nx);
  tt__crit_env env = {&m, grid, NULL};
  double *ins_err = NULL;
  st = rebuild(ctx, grid, ntriangles, pix_xyz, &m);
  if (st != TT_OK)
    goto done;
  if (crit->star_versions)
    (void)tt__mesh_track_stars(&m);
  env.cache = crit->cache_new ? crit->cache_new(&env) : NULL;
  tt_optimize mode =
      opt->optimize == TT_OPTIMIZE_AUTO ? TT_OPTIMIZE_LOCAL : opt->optimize;
  double bound = opt->max_error < 0 ? INFINITY : opt->max_error;
  if (!tt__optimize_final(&m, crit, &env, mode, TT_REPAIR_FLIP, bound,
                          &opt->anneal, NULL)) {
    st = tt__error(ctx, TT_ERR_NOMEM, "out of memory optimising %zu "
                   "triangles", ntriangles);
    goto done;
  }
  ins_err = malloc((m.nv ? m.nv : 1) * sizeof *ins_err);
  if (!ins_err) {
    st = tt__error(ctx, TT_ERR_NOMEM, "out of memory");
    goto done;
  }
  for (size_t v = 0; v < m.nv; v++)
    ins_err[v] = NAN; /* no vertex was inserted: all were given */
  double t_meshed = tt__now();
  st = tt__tin_build(ctx, &m, grid, ins_err, NULL, out_tin);
  ins_err = NULL; /* taken over by the tin, or freed on failure */
  if (st != TT_OK)
    goto done;
  (*out_tin)->summary.seconds_mesh = t_meshed - t_start;
  (*out_tin)->summary.seconds_statistics = tt__now() - t_meshed;
  (*out_tin)->summary.criterion = opt->criterion;
  (*out_tin)->summary.stop_reason = TT_STOP_NONE;
  (*out_tin)->summary.valid_samples = valid;
  (*out_tin)->summary.errors.samples = valid;
done:
  if (env.cache)
    crit->cache_free(env.cache);
  free(ins_err);
  tt__mesh_free(&m);
  return st;
}
