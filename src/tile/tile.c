/*
 * tile.c -- one tile of a tiled run (tt_tile_run): its window of the DEM
 * in, its piece of the TIN out, independent of every other tile.
 *
 * Tiles share their border rows and columns: tile (i, j) of size N holds
 * the samples of columns N i .. N (i + 1) and rows N j .. N (j + 1) (the
 * last ones stop at the DEM's edge), so a border sample belongs to two
 * tiles (a corner to four). The window read for a tile adds one column or
 * row beyond each shared side (tt_tile_window): with it, both neighbours
 * see the same three lines around their common border and compute the same
 * border vertices (border.c) without talking to each other. The tile's own
 * samples are then refined with those vertices forced into its outline and
 * its shared sides kept free of any other vertex (refine.c,
 * tt__refine_tile), or decimated with those vertices kept and the sides'
 * other samples removed (decimate.c, tt__decimate_tile); a border edge both neighbours have gives its samples to
 * one of them by the top-left rule, so every valid sample is counted once
 * over the tiles, and valid_samples counts a tile's samples less its
 * shared right column and bottom row.
 *
 * The piece is an ordinary tt_tin in the DEM's pixel coordinates (its
 * vertices' col and row, its geotransform the DEM's), which the merge
 * (merge.c) or a writer can take as it is. This is the unit a cluster runs:
 * a window, the tile's extent and the options give the same piece on any
 * machine.
 *
 * A geographic or Web Mercator DEM is measured on ground points, as
 * untiled: the window holds the whole raster's (tt_gdal_read_grid), the
 * tile's grid a copy of the tile's part, and the piece keeps its
 * vertices' ground points, scale factors and convergences (the latter
 * from the window, so that they are the untiled run's at the borders too).
 *
 * Memory: the window's heights, a copy of the tile's (4 or 8 bytes a
 * sample), with ground points 16 bytes a sample more in each, and
 * refinement's state for the tile.
 *
 * Part of src/tile/, tiled runs: the tiles, their shared borders, one tile's
 * run, the merge.
 */
#include "tile/tile.h"
#include "tin/tin.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

void tt_tile_window(const tt_tile *tile, size_t *out_col, size_t *out_row,
                    size_t *out_width, size_t *out_height)
{
  size_t c0 = tile->col0 - (tile->col0 > 0);
  size_t r0 = tile->row0 - (tile->row0 > 0);
  size_t c1 = tile->col1 + (tile->col1 + 1 < tile->dem_width);
  size_t r1 = tile->row1 + (tile->row1 + 1 < tile->dem_height);
  *out_col = c0;
  *out_row = r0;
  *out_width = c1 - c0 + 1;
  *out_height = r1 - r0 + 1;
}

static unsigned shared_sides(const tt_tile *t)
{
  return (t->col0 > 0 ? 1u : 0u) | (t->row0 > 0 ? 2u : 0u) |
         (t->col1 + 1 < t->dem_width ? 4u : 0u) |
         (t->row1 + 1 < t->dem_height ? 8u : 0u);
}

/* Height at DEM sample (col, row) of the window (NaN outside it). */
static double win_z(const tt_grid *w, size_t wc0, size_t wr0, int64_t col,
                    int64_t row)
{
  int64_t x = col - (int64_t)wc0, y = row - (int64_t)wr0;
  if (x < 0 || y < 0 || (size_t)x >= w->nx || (size_t)y >= w->ny)
    return NAN;
  return tt__grid_z(w, (size_t)y * w->nx + (size_t)x);
}

static bool push_vertex(tt__tile_borders *b, int32_t col, int32_t row)
{
  size_t c1 = b->cap, c2 = b->cap;
  if (b->n == b->cap &&
      (!tt__grow((void **)&b->col, &c1, b->n + 1, sizeof(int32_t)) ||
       !tt__grow((void **)&b->row, &c2, b->n + 1, sizeof(int32_t))))
    return false;
  if (b->n == b->cap)
    b->cap = c1 < c2 ? c1 : c2;
  b->col[b->n] = col;
  b->row[b->n] = row;
  b->n++;
  return true;
}

/* The border vertices and neighbour coverage of every shared side. */
static tt_status make_borders(tt_context *ctx, const tt_grid *w, size_t wc0,
                              size_t wr0, const tt_tile *t, double max_error,
                              tt__tile_borders *b)
{
  tt_status status = TT_OK;
  size_t len = (t->col1 - t->col0 > t->row1 - t->row0 ? t->col1 - t->col0
                                                       : t->row1 - t->row0) +
               1;
  double *line[3] = {NULL, NULL, NULL}; /* the border, inside, outside */
  uint8_t *brk = malloc(len), *keep = malloc(len);
  for (int k = 0; k < 3; k++)
    line[k] = malloc(len * sizeof(double));
  if (!brk || !keep || !line[0] || !line[1] || !line[2])
    goto oom;
  b->shared = shared_sides(t);
  for (int s = 0; s < 4; s++) {
    if (!(b->shared & (1u << s)))
      continue;
    bool vertical = s == 0 || s == 2;
    size_t n = vertical ? t->row1 - t->row0 + 1 : t->col1 - t->col0 + 1;
    /* the line's position, and the step inwards */
    int64_t at = s == 0 ? (int64_t)t->col0 : s == 1 ? (int64_t)t->row0
                 : s == 2 ? (int64_t)t->col1 : (int64_t)t->row1;
    int64_t in = s < 2 ? 1 : -1;
    for (size_t i = 0; i < n; i++)
      for (int k = 0; k < 3; k++) {
        int64_t off = k == 0 ? 0 : k == 1 ? in : -in;
        int64_t col = vertical ? at + off : (int64_t)t->col0 + (int64_t)i;
        int64_t row = vertical ? (int64_t)t->row0 + (int64_t)i : at + off;
        line[k][i] = win_z(w, wc0, wr0, col, row);
      }
    for (size_t i = 0; i < n; i++) {
      bool near_nodata = false;
      for (size_t j = i ? i - 1 : 0; j <= i + 1 && j < n; j++)
        for (int k = 0; k < 3; k++)
          near_nodata |= isnan(line[k][j]);
      brk[i] = i == 0 || i + 1 == n || near_nodata;
    }
    if (!tt__border_simplify(line[0], brk, n, max_error, keep))
      goto oom;
    b->cover[s] = calloc(n, 1);
    b->kept[s] = malloc(n);
    if (!b->cover[s] || !b->kept[s])
      goto oom;
    memcpy(b->kept[s], keep, n);
    for (size_t i = 0; i + 1 < n; i++) {
      int valid = !isnan(line[0][i]) + !isnan(line[0][i + 1]) +
                  !isnan(line[2][i]) + !isnan(line[2][i + 1]);
      b->cover[s][i] = valid >= 3;
    }
    /* tile-grid coordinates */
    for (size_t i = 0; i < n; i++) {
      if (!keep[i])
        continue;
      int32_t col = vertical ? (int32_t)(at - (int64_t)t->col0) : (int32_t)i;
      int32_t row = vertical ? (int32_t)i : (int32_t)(at - (int64_t)t->row0);
      if (!push_vertex(b, col, row))
        goto oom;
    }
  }
  goto done;
oom:
  status = tt__error(ctx, TT_ERR_NOMEM, "out of memory for the borders of "
                     "tile (%zu, %zu)", t->col0, t->row0);
done:
  free(brk);
  free(keep);
  for (int k = 0; k < 3; k++)
    free(line[k]);
  return status;
}

/* The tile's part of the window's ground points (a geographic or Web
 * Mercator DEM: the whole raster's, tt_gdal_read_grid), with its ground
 * metric, origin and area function: the tile is measured on the ground
 * as an untiled run measures it. 16 bytes a sample of the tile. */
static tt_status copy_ground(tt_context *ctx, const tt_grid *w, size_t dx,
                             size_t dy, tt_grid *g)
{
  if (!w->gxy)
    return TT_OK;
  tt_status status = tt_grid_alloc_ground_points(ctx, g);
  if (status != TT_OK)
    return status;
  for (size_t y = 0; y < g->ny; y++)
    memcpy(g->gxy + 2 * y * g->nx, w->gxy + 2 * ((y + dy) * w->nx + dx),
           2 * g->nx * sizeof *g->gxy);
  tt_grid_set_ground_metric_fn(g, w->metric_fn, w->metric_par);
  tt_grid_set_area_fn(g, w->area_fn, w->area_par);
  if (w->has_morigin)
    tt__grid_set_ground_origin(g, w->mc0 + dx, w->mr0 + dy, w->mgt);
  return TT_OK;
}

/* The scale factor and convergence of the piece's vertices (DEM pixel
 * coordinates) from the window rather than the tile: the window holds one
 * line beyond every shared side, so a vertex on a tile's border gets the
 * central differences of an untiled run (and the same values in both
 * tiles that have it), not one-sided ones. */
static void window_scales(const tt_grid *w, size_t wc0, size_t wr0,
                          tt_tin *tin)
{
  for (size_t v = 0; v < tin->nv; v++) {
    double k = 1, conv = 0;
    if (tt_grid_ground_scale_at(w, (size_t)tin->vc[v] - wc0,
                                (size_t)tin->vr[v] - wr0, &k,
                                &conv) != TT_OK) {
      k = 1;
      conv = 0;
    }
    tin->vgk[v] = (float)k;
    tin->vgconv[v] = (float)conv;
  }
}

/* An empty piece: the tile has no triangle (all nodata, or its valid
 * samples in no cell with three valid corners). */
static tt_status empty_piece(tt_context *ctx, size_t owned, tt_tin **out)
{
  tt_tin *tin = calloc(1, sizeof *tin);
  if (!tin)
    return tt__error(ctx, TT_ERR_NOMEM, "out of memory");
  tin->summary.valid_samples = owned;
  tin->summary.errors.samples = owned;
  tin->summary.errors.max_col = tin->summary.errors.max_row = -1;
  tin->summary.stop_reason = TT_STOP_MAX_ERROR;
  *out = tin;
  return TT_OK;
}

/* One tile by refinement (ropt) or decimation (dopt): the other is
 * NULL. */
/* tt_tile_curve's part: the callback and the insertions allowed. */
typedef struct curve_req {
  tt_tile_curve_fn fn;
  void *arg;
  size_t max_insertions;
} curve_req;

static tt_status run_tile(tt_context *ctx, const tt_grid *window,
                          const tt_tile *tile, const tt_refine_options *ropt,
                          const tt_decimate_options *dopt,
                          const curve_req *curve, tt_tin **out_piece)
{
  if (!window || !tile || !(ropt || dopt) || !out_piece)
    return tt__error(ctx, TT_ERR_ARG, "window, tile, options and out_piece "
                     "must not be NULL");
  *out_piece = NULL;
  const tt_tile *t = tile;
  if (t->col1 <= t->col0 || t->row1 <= t->row0 ||
      t->col1 >= t->dem_width || t->row1 >= t->dem_height)
    return tt__error(ctx, TT_ERR_ARG, "tile columns %zu..%zu, rows %zu..%zu "
                     "do not lie in a %zu x %zu DEM with two samples or more "
                     "each way", t->col0, t->col1, t->row0, t->row1,
                     t->dem_width, t->dem_height);
  double max_error = curve ? 0.0 : ropt ? ropt->max_error : dopt->max_error;
  bool budget = (ropt && (ropt->max_points || ropt->max_triangles ||
                          ropt->percent > 0)) ||
                (dopt && (dopt->max_points || dopt->max_triangles ||
                          dopt->percent > 0));
  if (!curve && (budget || !(max_error >= 0)))
    return tt__error(ctx, TT_ERR_ARG, "a tile is simplified to a max error "
                     "only: point, triangle and percentage budgets are for "
                     "the whole DEM (the command turns them into a bound, "
                     "docs/scale.md)");
  size_t wc0, wr0, wnx, wny;
  tt_tile_window(t, &wc0, &wr0, &wnx, &wny);
  if (window->nx != wnx || window->ny != wny)
    return tt__error(ctx, TT_ERR_ARG, "the window of tile (%zu, %zu) must be "
                     "%zu x %zu samples (the tile and one line beyond each "
                     "shared side), got %zu x %zu", t->col0, t->row0, wnx,
                     wny, window->nx, window->ny);

  tt_status status;
  tt_grid *g = NULL;
  tt_tin *tin = NULL;
  tt__tile_borders b;
  memset(&b, 0, sizeof b);
  size_t nx = t->col1 - t->col0 + 1, ny = t->row1 - t->row0 + 1;
  size_t dx = t->col0 - wc0, dy = t->row0 - wr0;
  status = window->zd ? tt_grid_create_f64(ctx, nx, ny, &g)
                      : tt_grid_create(ctx, nx, ny, &g);
  if (status != TT_OK)
    goto done;
  size_t owned = 0;
  size_t own_nx = nx - ((b.shared = shared_sides(t)) & 4u ? 1 : 0);
  size_t own_ny = ny - (b.shared & 8u ? 1 : 0);
  for (size_t y = 0; y < ny; y++) {
    size_t from = (y + dy) * window->nx + dx;
    if (g->zd)
      memcpy(g->zd + y * nx, window->zd + from, nx * sizeof(double));
    else
      memcpy(g->z + y * nx, window->z + from, nx * sizeof(float));
    if (y < own_ny)
      for (size_t x = 0; x < own_nx; x++)
        owned += !isnan(tt__grid_z(g, y * nx + x));
  }
  double gt[6];
  memcpy(gt, window->gt, sizeof gt);
  gt[0] += (double)dx * gt[1] + (double)dy * gt[2];
  gt[3] += (double)dx * gt[4] + (double)dy * gt[5];
  if ((status = tt_grid_set_geotransform(ctx, g, gt)) != TT_OK ||
      (status = tt_grid_set_ground_frame(ctx, g, window->frame)) != TT_OK ||
      (status = copy_ground(ctx, window, dx, dy, g)) != TT_OK)
    goto done;
  size_t valid = 0;
  for (size_t i = 0; i < nx * ny; i++)
    valid += !isnan(tt__grid_z(g, i));
  if (valid < 3) {
    if (!curve)
      status = empty_piece(ctx, owned, out_piece);
    goto done;
  }
  /* a curve's borders keep only the corners and the breaks */
  status = make_borders(ctx, window, wc0, wr0, t,
                        curve ? INFINITY : max_error, &b);
  if (status != TT_OK)
    goto done;
  /* (opt->progress sees the tile's own fraction: a stop flag's poll) */
  if (curve) {
    tt_refine_options o = *ropt;
    o.max_error = -1;
    o.max_points = curve->max_insertions; /* after the start: tile.h */
    o.max_triangles = 0;
    o.percent = 0;
    o.optimize = TT_OPTIMIZE_NONE;
    o.step = NULL;
    b.curve = curve->fn;
    b.curve_arg = curve->arg;
    status = tt__refine_tile(ctx, g, &o, &b, &tin);
    if (status == TT_ERR_DATA) {
      tt_context_clear_error(ctx);
      status = TT_OK;
    }
    goto done; /* no piece */
  }
  if (ropt) {
    status = tt__refine_tile(ctx, g, ropt, &b, &tin);
  } else {
    /* greedy:N: the tile's share of N by its cells, rounded up (at least
     * 1), inserted after its start */
    tt_decimate_options o = *dopt;
    if (o.start == TT_DSTART_GREEDY_N) {
      double share = (double)o.start_points * (double)(nx * ny) /
                     ((double)t->dem_width * (double)t->dem_height);
      o.start_points = (size_t)ceil(share);
      if (o.start_points < 1)
        o.start_points = 1;
    }
    status = tt__decimate_tile(ctx, g, &o, &b, &tin);
  }
  if (status == TT_ERR_DATA) {
    /* no triangle in this tile: its valid samples are uncovered */
    tt_context_clear_error(ctx);
    status = empty_piece(ctx, owned, out_piece);
    goto done;
  }
  if (status != TT_OK)
    goto done;
  /* into the DEM's pixel coordinates */
  for (size_t v = 0; v < tin->nv; v++) {
    tin->vc[v] += (int32_t)t->col0;
    tin->vr[v] += (int32_t)t->row0;
  }
  if (tin->vgxy)
    window_scales(window, wc0, wr0, tin);
  memcpy(tin->gt, window->gt, sizeof tin->gt);
  tin->gt[0] -= (double)wc0 * tin->gt[1] + (double)wr0 * tin->gt[2];
  tin->gt[3] -= (double)wc0 * tin->gt[4] + (double)wr0 * tin->gt[5];
  tt_error_stats *e = &tin->summary.errors;
  if (e->max_col >= 0) {
    e->max_col += (int64_t)t->col0;
    e->max_row += (int64_t)t->row0;
  }
  e->samples = owned;
  tin->summary.valid_samples = owned;
  tin->summary.grid_width = t->dem_width;
  tin->summary.grid_height = t->dem_height;
  *out_piece = tin;
  tin = NULL;
done:
  tt__tile_borders_free(&b);
  tt_tin_destroy(tin);
  tt_grid_destroy(g);
  return status;
}

tt_status tt_tile_run(tt_context *ctx, const tt_grid *window,
                      const tt_tile *tile, const tt_refine_options *opt,
                      tt_tin **out_piece)
{
  if (!opt)
    return tt__error(ctx, TT_ERR_ARG, "options must not be NULL");
  return run_tile(ctx, window, tile, opt, NULL, NULL, out_piece);
}

tt_status tt_tile_decimate(tt_context *ctx, const tt_grid *window,
                           const tt_tile *tile,
                           const tt_decimate_options *opt,
                           tt_tin **out_piece)
{
  if (!opt)
    return tt__error(ctx, TT_ERR_ARG, "options must not be NULL");
  return run_tile(ctx, window, tile, NULL, opt, NULL, out_piece);
}

tt_status tt_tile_curve(tt_context *ctx, const tt_grid *window,
                        const tt_tile *tile, const tt_refine_options *opt,
                        size_t max_insertions, tt_tile_curve_fn fn,
                        void *arg)
{
  if (!opt || !fn || max_insertions < 1)
    return tt__error(ctx, TT_ERR_ARG, "options and fn must not be NULL, "
                     "max_insertions at least 1");
  curve_req c = {fn, arg, max_insertions};
  tt_tin *none = NULL;
  return run_tile(ctx, window, tile, opt, NULL, &c, &none);
}
