/*
 * start.c -- the fine TIN a decimation starts from (SPEC section 3.6).
 *
 *   all       every valid sample a triangle can carry, triangulated over
 *             the valid domain of domain.c: a cell with four valid
 *             corners gives two triangles, a cell with three the triangle
 *             of its three (its long side is then part of the outline),
 *             so the triangles cover exactly the union of the valid cell
 *             parts that refinement's outline bounds, nodata holes stay
 *             holes, and a lone sample amid nodata stays uncovered as in
 *             refinement. Then Lawson's flips make it Delaunay (grid
 *             cells are co-circular: ties never flip).
 *   greedy    a greedy Delaunay insertion (tt_refine_run) down to zero
 *             error: every sample is then exact;
 *   greedy:N  the same stopped at N vertices (the study's start).
 * A tile (tt__decimate_tile) starts the same ways; its greedy starts are
 * tt__refine_tile's, with the tile's border vertices forced and no other
 * vertex on its shared sides; `all` keeps every sample, and decimate.c
 * removes the shared sides' samples that are not border vertices first.
 * The greedy TINs are taken over vertex for vertex (index = insertion
 * rank) and triangle for triangle.
 *
 * Memory of `all`: the mesh itself, about 16 bytes per vertex and 27 per
 * triangle slot (two per sample), plus the link table while linking.
 *
 * Part of src/decimate/, the vertex decimation method (tt_decimate_run).
 */
#include "decimate/decimate.h"

#include "mesh/breaklines.h"
#include "tin/tin.h"

#include <math.h>
#include <stdlib.h>

static tt_status oom(tt__dec *d)
{
  return tt__error(d->ctx, TT_ERR_NOMEM, "out of memory for the starting "
                   "TIN (%zu vertices, %zu triangles)", d->m.nv, d->m.nlive);
}

static bool add_ccw(tt__mesh *m, int32_t a, int32_t b, int32_t c)
{
  int o = tt__mesh_orient(m, a, b, c);
  if (o == 0)
    return true;
  return (o > 0 ? tt__mesh_add_triangle(m, a, b, c)
                : tt__mesh_add_triangle(m, a, c, b)) >= 0;
}

static tt_status start_all(tt__dec *d)
{
  const tt_grid *g = d->g;
  tt__mesh *m = &d->m;
  size_t nx = g->nx, ny = g->ny;
  tt_status status = TT_OK;
  int32_t *id = malloc(nx * ny * sizeof *id);
  if (!id)
    return oom(d);
  /* a vertex for every sample that is a corner of a valid cell part */
  size_t nvert = 0;
  for (size_t r = 0; r < ny; r++)
    for (size_t c = 0; c < nx; c++) {
      id[r * nx + c] = -1;
      if (isnan(tt__grid_z(g, r * nx + c)))
        continue;
      bool carried = false;
      for (size_t cy = r ? r - 1 : 0; cy <= r && cy + 1 < ny && !carried;
           cy++)
        for (size_t cx = c ? c - 1 : 0; cx <= c && cx + 1 < nx && !carried;
             cx++) {
          int k = !isnan(tt__grid_z(g, cy * nx + cx)) +
                  !isnan(tt__grid_z(g, cy * nx + cx + 1)) +
                  !isnan(tt__grid_z(g, (cy + 1) * nx + cx)) +
                  !isnan(tt__grid_z(g, (cy + 1) * nx + cx + 1));
          carried = k >= 3;
        }
      if (carried)
        nvert++;
    }
  if (nvert > TT_MAX_VERTICES) {
    status = tt__error(d->ctx, TT_ERR_LIMIT, "%zu samples are more than the "
                       "%zu vertices a TIN may hold", nvert,
                       (size_t)TT_MAX_VERTICES);
    goto done;
  }
  if (!tt__mesh_reserve(m, nvert, 2 * nx * ny)) {
    status = oom(d);
    goto done;
  }
  for (size_t r = 0; r < ny; r++)
    for (size_t c = 0; c < nx; c++) {
      if (isnan(tt__grid_z(g, r * nx + c)))
        continue;
      bool carried = false;
      for (size_t cy = r ? r - 1 : 0; cy <= r && cy + 1 < ny && !carried;
           cy++)
        for (size_t cx = c ? c - 1 : 0; cx <= c && cx + 1 < nx && !carried;
             cx++) {
          int k = !isnan(tt__grid_z(g, cy * nx + cx)) +
                  !isnan(tt__grid_z(g, cy * nx + cx + 1)) +
                  !isnan(tt__grid_z(g, (cy + 1) * nx + cx)) +
                  !isnan(tt__grid_z(g, (cy + 1) * nx + cx + 1));
          carried = k >= 3;
        }
      if (carried) {
        id[r * nx + c] =
            tt__mesh_add_vertex(m, (int32_t)c, (int32_t)r,
                                tt__grid_z(g, r * nx + c));
        if (id[r * nx + c] < 0) {
          status = oom(d);
          goto done;
        }
      }
    }
  for (size_t r = 0; r + 1 < ny; r++)
    for (size_t c = 0; c + 1 < nx; c++) {
      int32_t a = id[r * nx + c], b = id[r * nx + c + 1];
      int32_t e = id[(r + 1) * nx + c], f = id[(r + 1) * nx + c + 1];
      bool ok = true;
      if (a >= 0 && b >= 0 && e >= 0 && f >= 0)
        ok = add_ccw(m, a, b, f) && add_ccw(m, a, f, e);
      else if (a < 0 && b >= 0 && e >= 0 && f >= 0)
        ok = add_ccw(m, b, f, e);
      else if (b < 0 && a >= 0 && e >= 0 && f >= 0)
        ok = add_ccw(m, a, f, e);
      else if (e < 0 && a >= 0 && b >= 0 && f >= 0)
        ok = add_ccw(m, a, b, f);
      else if (f < 0 && a >= 0 && b >= 0 && e >= 0)
        ok = add_ccw(m, a, b, e);
      if (!ok) {
        status = oom(d);
        goto done;
      }
    }
  if (!tt__mesh_link_all(m) ||
      tt__swap_all(m, &tt__criterion_delaunay, &d->env, &d->stack) < 0)
    status = oom(d);
done:
  free(id);
  return status;
}

static tt_status start_greedy(tt__dec *d, size_t points)
{
  const tt_decimate_options *o = d->opt;
  tt_refine_options ro;
  tt_refine_options_init(&ro);
  ro.criterion = TT_CRITERION_DELAUNAY;
  ro.max_error = points ? -1.0 : 0.0;
  ro.max_points = points;
  ro.threads = o->threads;
  ro.optimize = TT_OPTIMIZE_NONE;
  ro.breaklines = o->breaklines;
  tt_tin *tin = NULL;
  /* a tile starts from its border vertices, as refinement does, and N
   * counts the insertions after them (tile.h) */
  tt_status status = d->borders
                         ? tt__refine_tile(d->ctx, d->g, &ro, d->borders, &tin)
                         : tt_refine_run(d->ctx, d->g, &ro, &tin);
  if (status != TT_OK)
    return status;
  tt__mesh *m = &d->m;
  if (!tt__mesh_reserve(m, tin->nv, tin->nt + 16)) {
    status = oom(d);
    goto done;
  }
  for (size_t v = 0; v < tin->nv; v++)
    if (tt__mesh_add_vertex(m, tin->vc[v], tin->vr[v], tt__tin_z(tin, v)) < 0) {
      status = oom(d);
      goto done;
    }
  for (size_t t = 0; t < tin->nt; t++)
    if (!add_ccw(m, tin->tv[3 * t], tin->tv[3 * t + 1], tin->tv[3 * t + 2])) {
      status = oom(d);
      goto done;
    }
  if (!tt__mesh_link_all(m)) {
    status = oom(d);
    goto done;
  }
  /* the breaklines' edges, as the greedy TIN has them */
  for (size_t t = 0; tin->t_brk && t < tin->nt; t++)
    for (int k = 0; k < 3; k++)
      if (((tin->t_brk[t] >> k) & 1u) &&
          !tt__breaklines_flag(m, tin->tv[3 * t + (size_t)k],
                               tin->tv[3 * t + (size_t)(k + 1) % 3])) {
        status = tt__error(d->ctx, TT_ERR_INTERNAL, "a breakline edge of "
                           "the greedy start is not in the mesh");
        goto done;
      }
done:
  tt_tin_destroy(tin);
  return status;
}

/* A vertex for a breakline's end (start_all has every usable sample
 * already: a safety net). */
static bool add_end(void *arg, int32_t col, int32_t row, int32_t *out_v)
{
  tt__dec *d = arg;
  size_t at = (size_t)row * d->g->nx + (size_t)col;
  *out_v = tt__mesh_add_vertex(&d->m, col, row, tt__grid_z(d->g, at));
  return *out_v >= 0;
}

/* Every sample, then the breaklines recovered in it as constrained
 * edges (their vertices are pinned by decimate.c). */
static tt_status start_all_lines(tt__dec *d)
{
  tt_status s = start_all(d);
  if (s == TT_OK && d->opt->breaklines.n)
    s = tt__breaklines_insert(d->ctx, &d->m, d->g, &d->opt->breaklines,
                              &tt__criterion_delaunay, &d->env, &d->stack,
                              add_end, d);
  return s;
}

tt_status tt__dec_start(tt__dec *d, size_t valid)
{
  (void)valid;
  switch (d->opt->start) {
  case TT_DSTART_ALL:
    return start_all_lines(d);
  case TT_DSTART_GREEDY:
    return start_greedy(d, 0);
  default:
    return start_greedy(d, d->opt->start_points);
  }
}
