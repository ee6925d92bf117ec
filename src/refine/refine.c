/*
 * refine.c -- greedy insertion (Garland & Heckbert 1995; SPEC section 3.1).
 *
 * Start from the grid's four corners (or, when there is nodata, from the
 * convex hull of the valid samples), made to satisfy the criterion. Each
 * live triangle keeps its candidate: the sample it owns with the largest
 * |H - H'| (raster_scan.c); candidates sit in an indexed max-heap keyed by
 * that error -- those above max_error only: one within it can never be
 * taken, and at the end most triangles are such (keeping them out makes
 * the heap small and its misses fewer). Repeat: take the worst candidate,
 * check the stop conditions, insert it (split its triangle, or the edge it
 * lies on), restore the criterion around it by flips (swap.c), and rescan
 * only the triangles the mesh logged as written.
 *
 * Stop conditions (the first reached wins, and each is exact): the worst
 * error is <= max_error; one more vertex would pass max_points (or the
 * percentage); the next insertion would pass max_triangles; no sample has
 * a non-zero error left.
 *
 * Nodata (domain.c): the starting triangulation follows the outline of
 * the valid domain with constrained edges and holds no triangle outside
 * it; splits and flips of unconstrained inner edges never leave it, so the
 * TIN covers exactly the valid samples that a valid cell part holds (the
 * others, lone samples amid nodata, are counted as uncovered).
 *
 * Curves (opt->step, curve.h): each rescan also keeps its triangle's sums
 * of |H - H'| and (H - H')^2, so every step's measures are known without a
 * pass over the samples; with a final pass, a reported step applies it to
 * a copy of the mesh. Without a recorder none of that runs.
 *
 * Tiles (tt__refine_tile, src/tile/): the border vertices of the tile's
 * shared sides are inserted into the starting triangulation's boundary
 * edges, the boundary edges on those sides are flagged TT__EDGE_BORDER,
 * and the candidate scans skip their samples (the border's 1-D
 * simplification bounds them), so no vertex is ever added on a shared side
 * and the neighbouring tile meets the same edges. Boundary edges are never
 * flipped, so neither repairs nor optimisers move a border edge.
 *
 * Memory per triangle slot: mesh 27 bytes, candidate 8 + error 8, heap 4
 * (+ 16 per triangle above max_error; + 24 for the sums when recording);
 * per sample, while inserting: the scans' tile bounds, 0.25 bytes.
 * Cost: O((m + n) log n) for m samples and n inserted vertices in practice.
 *
 * Part of src/refine/, the greedy insertion method (tt_refine_run).
 */
#include "refine/refine.h"

#include "criteria/criterion.h"
#include "mesh/breaklines.h"
#include "mesh/domain.h"
#include "base/heap.h"
#include "mesh/mesh.h"
#include "optimize/optimize.h" /* [optimize.c hook] */
#include "base/parallel.h"
#include "base/predicates.h"
#include "mesh/raster_scan.h"
#include "optimize/swap.h"
#include "tin/curve.h"
#include "tin/tin.h"
#include "tile/tile.h"

#include <float.h>
#include <stdio.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

void tt_refine_options_init(tt_refine_options *opt)
{
  memset(opt, 0, sizeof *opt);
  opt->max_error = 1.0;
  opt->criterion = TT_CRITERION_DELAUNAY;
}

typedef struct refine {
  tt_context *ctx;
  const tt_grid *g;
  const tt_refine_options *opt;
  const tt__criterion_vt *crit;
  tt_repair repair;    /* resolved */
  tt__crit_env env;
  tt__mesh m;
  tt__heap heap;
  int64_t *cand;       /* per triangle slot: candidate sample or -1 */
  double *cerr;        /* per triangle slot: its error */
  size_t ccap;
  double *ins_err;     /* per vertex */
  size_t inscap;
  tt__edge_stack stack;
  tt__pool *pool;      /* NULL: single-threaded */
  bool prefetch;       /* the grid is larger than the caches: rows are
                          asked for ahead (tt__scan_prefetches) */
  tt__scan_tiles tiles; /* error bounds per tile (empty: none) */
  struct scan_job_t *jobs; /* scans of this round */
  size_t jobcap;
  size_t max_points, max_tris;
  double max_error;    /* < 0: none */
  size_t forced;       /* vertices the nodata outline required */
  size_t *start_size;  /* tt__refine_start_size: stop after the start,
                          its vertex count here (no scan of the samples) */
  const tt__tile_borders *borders; /* tile runs, else NULL */
  const char *phase;   /* for messages: "inserting", ... */
  /* progress */
  double e0, frac;
  /* curves (opt->step): the running sums, and what a step report needs */
  bool rec;            /* opt->step is set */
  tt__curve curve;
  double heap_floor;   /* candidates above this enter the heap: max_error,
                          or -1 (all) when recording, so that the heap's top
                          is the worst error of the whole mesh */
  size_t valid;        /* valid samples of the grid */
  size_t linked;       /* vertices in some triangle */
  tt_optimize final;   /* the final pass, resolved */
  double t_start, rec_seconds; /* the time spent reporting steps */
  tt_step_info prev;   /* the last step reported (prev.points 0: none) */
} refine;

/* --- memory ------------------------------------------------------------
 * What the run holds, counted from the arrays' capacities: the grid's
 * heights, the mesh, the insertion state, and the TIN's records that the
 * end of the run adds (tin.h: 44 bytes per vertex and 32 per triangle,
 * with metrics.c's 12 per vertex and 4 per slot while building them).
 * Criterion caches and the scans' jobs are small and not counted. */
#define TIN_BYTES_PER_VERTEX 56
#define TIN_BYTES_PER_TRIANGLE 36

typedef struct mem_use {
  uint64_t grid, mesh, tin;
} mem_use;

/* The bytes held if the vertex and triangle arrays had room for nv and
 * nt (their capacities, or the capacities they are about to grow to). */
static void mem_count(const refine *r, size_t nv, size_t nt, mem_use *u)
{
  const tt__mesh *m = &r->m;
  u->grid = (uint64_t)r->g->nx * r->g->ny *
                (sizeof(float) + (r->g->zd ? sizeof(double) : 0)) +
            (uint64_t)r->tiles.ntx * r->tiles.nty * 4 * sizeof(float);
  uint64_t per_v = sizeof(tt__mesh_vertex) + sizeof(double) +
                   (m->vver ? sizeof(uint32_t) : 0);
  uint64_t per_t = 6 * sizeof(int32_t) + 3 + sizeof(int64_t) +
                   sizeof(double) + sizeof(int32_t) + sizeof(tt__heap_entry) +
                   (r->rec ? 2 * sizeof(double) + sizeof(size_t) : 0);
  u->mesh = per_v * nv + per_t * nt +
            (uint64_t)(m->freecap + m->touchedcap + r->stack.cap) *
                sizeof(int32_t);
  u->tin = (uint64_t)TIN_BYTES_PER_VERTEX * nv +
           (uint64_t)TIN_BYTES_PER_TRIANGLE * nt;
}

/* TT_ERR_NOMEM when holding room for nv vertices and nt triangle slots
 * would pass opt->max_memory; names the phase and the sizes. */
static tt_status mem_check(refine *r, size_t nv, size_t nt)
{
  if (!r->opt->max_memory)
    return TT_OK;
  mem_use u;
  mem_count(r, nv, nt, &u);
  uint64_t total = u.grid + u.mesh + u.tin;
  if (total <= (uint64_t)r->opt->max_memory)
    return TT_OK;
  char a[32], b[32], c[32], d[32], e[32];
  return tt__error(r->ctx, TT_ERR_NOMEM, "%s, at %zu vertices and %zu "
                   "triangles: room for %zu vertices needs %s (heights %s, "
                   "mesh and insertion state %s, the TIN's records %s), "
                   "more than the memory limit of %s", r->phase, r->m.nv,
                   r->m.nlive, nv,
                   tt__format_bytes(a, sizeof a, total),
                   tt__format_bytes(b, sizeof b, u.grid),
                   tt__format_bytes(c, sizeof c, u.mesh),
                   tt__format_bytes(d, sizeof d, u.tin),
                   tt__format_bytes(e, sizeof e, r->opt->max_memory));
}

/* Before an insertion: when the next one grows the vertex or slot arrays
 * (by tt__grow's 1.5 steps), the room they grow to must fit. */
static tt_status mem_check_growth(refine *r)
{
  const tt__mesh *m = &r->m;
  if (!r->opt->max_memory ||
      (m->nv + 1 <= m->vcap && m->nslots + 2 <= m->tcap &&
       m->nslots + 2 <= r->ccap && r->heap.n + 3 <= r->heap.cap))
    return TT_OK;
  size_t nv = m->vcap + m->vcap / 2, nt = m->tcap + m->tcap / 2;
  return mem_check(r, nv < m->nv + 1 ? m->nv + 1 : nv,
                   nt < m->nslots + 2 ? m->nslots + 2 : nt);
}

static tt_status oom(refine *r)
{
  mem_use u;
  char a[32];
  mem_count(r, r->m.vcap, r->m.tcap, &u);
  return tt__error(r->ctx, TT_ERR_NOMEM,
                   "out of memory %s, at %zu vertices and %zu triangles "
                   "(the run held about %s)", r->phase, r->m.nv, r->m.nlive,
                   tt__format_bytes(a, sizeof a, u.grid + u.mesh));
}

/* Per-slot arrays follow the mesh's slot count. */
static bool fit_slots(refine *r)
{
  size_t need = r->m.nslots;
  if (need <= r->ccap)
    return true;
  size_t c1 = r->ccap, c2 = r->ccap;
  if (!tt__grow((void **)&r->cand, &c1, need, sizeof(int64_t)) ||
      !tt__grow((void **)&r->cerr, &c2, need, sizeof(double)))
    return false;
  r->ccap = c1 < c2 ? c1 : c2;
  if (r->rec && !tt__curve_fit(&r->curve, r->ccap))
    return false;
  return tt__heap_reserve_items(&r->heap, r->ccap);
}

static bool add_vertex(refine *r, int32_t col, int32_t row, double err,
                       int32_t *out_v)
{
  size_t at = (size_t)row * r->g->nx + (size_t)col;
  int32_t v = tt__mesh_add_vertex(&r->m, col, row, tt__grid_z(r->g, at));
  if (v < 0 || !tt__grow((void **)&r->ins_err, &r->inscap, (size_t)v + 1,
                         sizeof(double)))
    return false;
  r->ins_err[v] = err;
  *out_v = v;
  return true;
}

/* A job of the scan pool: the candidate of a band of rows of one live
 * triangle (a whole small triangle is one band), written into the job's own
 * result; jobs share nothing else. */
typedef struct scan_job_t {
  int32_t t;
  int64_t ylo, yhi;
  tt__scan_tri st;      /* the triangle, read once from the mesh */
  double err;
  int64_t index;
  tt__scan_stats ss;    /* when recording: the band's sums */
} scan_job_t;

/* Triangles with more rows than this and a large area are cut into bands
 * of this many rows, so that all threads share the early, huge triangles. */
#define BAND_ROWS 256
#define BAND_MIN_AREA ((int64_t)1 << 16)
/* Batches smaller than this (in samples, estimated from areas) run in the
 * calling thread: a hand-over costs about a microsecond, and a worker that
 * the system has descheduled would hold the batch for a whole timeslice. */
#define PARALLEL_MIN_SAMPLES ((int64_t)1 << 15)

static void scan_job(void *arg, size_t i)
{
  refine *r = arg;
  scan_job_t *j = &r->jobs[i];
  const tt__scan_tri st = j->st;
  if (r->rec) {
    /* recording: one pass gives both, the sums and the candidate (the
     * statistics' largest error is the candidate search's, bit for bit:
     * the same plane expression, the first sample in row-major order on
     * ties; an exact triangle has none) */
    tt__scan_stats_rows(r->g, &st, j->ylo, j->yhi, &j->ss);
    bool any = j->ss.max_err > 0 && j->ss.max_index >= 0;
    j->err = any ? j->ss.max_err : 0;
    j->index = any ? j->ss.max_index : -1;
    return;
  }
  tt__scan_candidate_rows(r->g, &r->tiles, &st, j->ylo, j->yhi, &j->err,
                          &j->index);
}

/* Appends the jobs of live triangle t. */
static bool add_jobs(refine *r, int32_t t, size_t *njobs, int64_t *samples)
{
  tt__scan_tri st;
  tt__scan_tri_from_mesh(&r->m, t, &st);
  if (r->borders)
    for (int k = 0; k < 3; k++)
      if (r->m.eflag[3 * t + k] & TT__EDGE_BORDER)
        st.own[k] = false; /* bounded by the border's simplification */
  int64_t xlo, xhi, ylo, yhi;
  tt__scan_tri_bbox(&st, &xlo, &xhi, &ylo, &yhi);
  int64_t area2 = (st.x[1] - st.x[0]) * (st.y[2] - st.y[0]) -
                  (st.x[2] - st.x[0]) * (st.y[1] - st.y[0]);
  if (area2 < 0)
    area2 = -area2;
  *samples += area2 / 2;
  /* recording, the bands are the same with or without threads, so that
   * the sums are too (the candidates are the same either way) */
  int64_t band = ((r->pool || r->rec) && area2 / 2 >= BAND_MIN_AREA)
                     ? BAND_ROWS
                     : yhi - ylo + 1;
  for (int64_t y0 = ylo; y0 <= yhi; y0 += band) {
    if (!tt__grow((void **)&r->jobs, &r->jobcap, *njobs + 1,
                  sizeof(scan_job_t)))
      return false;
    scan_job_t *j = &r->jobs[(*njobs)++];
    j->t = t;
    j->st = st;
    j->ylo = y0;
    j->yhi = y0 + band - 1 < yhi ? y0 + band - 1 : yhi;
  }
  return true;
}

/* Sorts a short list of slots (the handful an insertion touches). */
static void sort_slots(int32_t *a, size_t n)
{
  for (size_t i = 1; i < n; i++) {
    int32_t v = a[i];
    size_t j = i;
    for (; j > 0 && a[j - 1] > v; j--)
      a[j] = a[j - 1];
    a[j] = v;
  }
}

static int cmp_i32(const void *a, const void *b)
{
  int32_t x = *(const int32_t *)a, y = *(const int32_t *)b;
  return (x > y) - (x < y);
}

/* A live slot's scan result into its candidate and the heap. */
static bool set_candidate(refine *r, int32_t t, double err, int64_t index)
{
  r->cand[t] = index;
  r->cerr[t] = err;
  /* (max_error < 0, none: every candidate enters) */
  if (index < 0 || err <= r->heap_floor) {
    tt__heap_remove(&r->heap, t);
    return true;
  }
  return tt__heap_set(&r->heap, t, err);
}

/* Rescans the given triangle slots, each once: dead slots leave the heap,
 * live ones are scanned (in parallel when there is a pool) and then, in
 * slot order, enter the heap or leave it. */
static bool rescan(refine *r, int32_t *slots, size_t n)
{
  if (!fit_slots(r))
    return false;
  if (n <= 32)
    sort_slots(slots, n);
  else
    qsort(slots, n, sizeof(int32_t), cmp_i32);
  if (!r->pool && !r->rec && !r->prefetch) {
    /* one thread on a grid in cache: each triangle scanned where it is
     * met, without the jobs (their hand-over, the copies, the second
     * pass); the heap's order is total (ties by slot), so the order of
     * its updates changes nothing */
    for (size_t i = 0; i < n; i++) {
      int32_t t = slots[i];
      if (i > 0 && t == slots[i - 1])
        continue;
      if (!tt__mesh_live(&r->m, t)) {
        tt__heap_remove(&r->heap, t);
        continue;
      }
      tt__scan_tri st;
      tt__scan_tri_from_mesh(&r->m, t, &st);
      double err;
      int64_t index;
      tt__scan_candidate_rows(r->g, &r->tiles, &st, INT64_MIN, INT64_MAX,
                              &err, &index);
      if (!set_candidate(r, t, err, index))
        return false;
    }
    return true;
  }
  size_t njobs = 0;
  int64_t samples = 0;
  for (size_t i = 0; i < n; i++) {
    int32_t t = slots[i];
    if (i > 0 && t == slots[i - 1])
      continue;
    if (!tt__mesh_live(&r->m, t)) {
      tt__heap_remove(&r->heap, t);
      if (r->rec)
        tt__curve_set(&r->curve, t, NULL);
    } else if (!add_jobs(r, t, &njobs, &samples))
      return false;
  }
  if (samples < PARALLEL_MIN_SAMPLES && r->prefetch) {
    /* small triangles, cold in cache (on a grid larger than the caches):
     * ask for all their rows first, so the misses overlap instead of
     * queueing one row at a time */
    for (size_t i = 0; i < njobs; i++)
      if (!tt__scan_tiled(&r->jobs[i].st))
        tt__scan_prefetch(r->g, &r->jobs[i].st, INT64_MIN, INT64_MAX);
  }
  tt__pool_run(samples >= PARALLEL_MIN_SAMPLES ? r->pool : NULL, njobs,
               scan_job, r);
  /* jobs of one triangle are adjacent and in row order: the first largest
   * error wins, as in a single scan */
  for (size_t i = 0; i < njobs;) {
    int32_t t = r->jobs[i].t;
    double err = r->jobs[i].err;
    int64_t index = r->jobs[i].index;
    size_t first = i;
    for (i++; i < njobs && r->jobs[i].t == t; i++)
      if (r->jobs[i].err > err) {
        err = r->jobs[i].err;
        index = r->jobs[i].index;
      }
    if (r->rec) {
      /* the bands' sums, in row order */
      tt__scan_stats ss = r->jobs[first].ss;
      for (size_t k = first + 1; k < i; k++) {
        ss.sum_abs += r->jobs[k].ss.sum_abs;
        ss.sum_sq += r->jobs[k].ss.sum_sq;
        ss.count += r->jobs[k].ss.count;
      }
      tt__curve_set(&r->curve, t, &ss);
    }
    if (!set_candidate(r, t, err, index))
      return false;
  }
  return true;
}

/* Rescans each triangle slot the mesh logged, once. */
static bool drain(refine *r)
{
  tt__mesh *m = &r->m;
  bool ok = rescan(r, m->touched, m->ntouched);
  tt__mesh_clear_touched(m);
  return ok;
}

/* --- starting triangulation -------------------------------------------- */

/* Adds triangle (a, b, c) with its ground-frame orientation fixed. */
static bool add_ccw(refine *r, int32_t a, int32_t b, int32_t c)
{
  int o = tt__mesh_orient(&r->m, a, b, c);
  if (o == 0)
    return true; /* degenerate: skipped (hull fans never make one) */
  return (o > 0 ? tt__mesh_add_triangle(&r->m, a, b, c)
                : tt__mesh_add_triangle(&r->m, a, c, b)) >= 0;
}

static tt_status start_rectangle(refine *r)
{
  const tt_grid *g = r->g;
  int32_t w = (int32_t)g->nx - 1, h = (int32_t)g->ny - 1;
  int32_t v[4];
  if (!add_vertex(r, 0, 0, NAN, &v[0]) || !add_vertex(r, w, 0, NAN, &v[1]) ||
      !add_vertex(r, w, h, NAN, &v[2]) || !add_vertex(r, 0, h, NAN, &v[3]))
    return oom(r);
  if (!add_ccw(r, v[0], v[1], v[2]) || !add_ccw(r, v[0], v[2], v[3]))
    return oom(r);
  return TT_OK;
}

/* Andrew's monotone chain over the leftmost and rightmost valid sample of
 * every row, exact in integers; the hull has no collinear vertices. */
static tt_status start_hull(refine *r, size_t valid)
{
  const tt_grid *g = r->g;
  tt_status status = TT_OK;
  int64_t *px = NULL, *py = NULL;
  size_t *hull = NULL;
  size_t n = 0;
  px = malloc(2 * g->ny * sizeof *px);
  py = malloc(2 * g->ny * sizeof *py);
  hull = malloc((2 * g->ny + 2) * 2 * sizeof *hull);
  if (!px || !py || !hull) {
    status = oom(r);
    goto done;
  }
  /* points sorted by (y, x): row by row, left end then right end */
  for (size_t row = 0; row < g->ny; row++) {
    size_t lo = SIZE_MAX, hi = 0;
    for (size_t c = 0; c < g->nx; c++)
      if (!isnan(tt__grid_z(g, row * g->nx + c))) {
        if (lo == SIZE_MAX)
          lo = c;
        hi = c;
      }
    if (lo == SIZE_MAX)
      continue;
    px[n] = (int64_t)lo;
    py[n++] = (int64_t)row;
    if (hi != lo) {
      px[n] = (int64_t)hi;
      py[n++] = (int64_t)row;
    }
  }
  /* lower and upper chains (counter-clockwise in pixel space) */
  size_t k = 0;
  for (size_t i = 0; i < n; i++) {
    while (k >= 2 && tt__orient_i(px[hull[k - 2]], py[hull[k - 2]],
                                  px[hull[k - 1]], py[hull[k - 1]], px[i],
                                  py[i]) <= 0)
      k--;
    hull[k++] = i;
  }
  for (size_t i = n - 1, lower = k + 1; i-- > 0;) {
    while (k >= lower && tt__orient_i(px[hull[k - 2]], py[hull[k - 2]],
                                      px[hull[k - 1]], py[hull[k - 1]], px[i],
                                      py[i]) <= 0)
      k--;
    hull[k++] = i;
  }
  if (k > 1)
    k--; /* the last point repeats the first */
  if (k < 3) {
    status = tt__error(r->ctx, TT_ERR_DATA,
                       "the %zu valid sample%s lie on one line: no triangle "
                       "can be made", valid, valid == 1 ? "" : "s");
    goto done;
  }
  int32_t first = (int32_t)r->m.nv;
  for (size_t i = 0; i < k; i++) {
    int32_t v;
    if (!add_vertex(r, (int32_t)px[hull[i]], (int32_t)py[hull[i]], NAN, &v)) {
      status = oom(r);
      goto done;
    }
  }
  for (size_t i = 1; i + 1 < k; i++)
    if (!add_ccw(r, first, first + (int32_t)i, first + (int32_t)i + 1)) {
      status = oom(r);
      goto done;
    }
done:
  free(px);
  free(py);
  free(hull);
  return status;
}

static bool domain_vertex(void *arg, int32_t col, int32_t row,
                          int32_t *out_v)
{
  return add_vertex(arg, col, row, NAN, out_v);
}

/* Tile runs: the border vertices split the boundary edges they lie on
 * (those outside this tile's TIN are the neighbour's alone), then every
 * boundary edge on a shared side is flagged. */
static tt_status start_borders(refine *r)
{
  const tt__tile_borders *b = r->borders;
  tt__mesh *m = &r->m;
  int32_t last = -1;
  for (size_t i = 0; i < b->n; i++) {
    int32_t on;
    int32_t t = tt__mesh_locate(m, last, b->col[i], b->row[i], &on);
    if (t < 0)
      continue;
    last = t;
    if (on <= -2)
      continue; /* a vertex already: a corner of the start or the outline */
    if (on < 0 || m->twin[on] >= 0)
      return tt__error(r->ctx, TT_ERR_INTERNAL, "border vertex (%d, %d) "
                       "is not on the tile's boundary", (int)b->col[i],
                       (int)b->row[i]);
    int32_t v, opp[4];
    if (!add_vertex(r, b->col[i], b->row[i], NAN, &v) ||
        !tt__mesh_split_edge(m, on, v, opp) ||
        tt__swap_repair(m, r->crit, &r->env, opp, 4, &r->stack) < 0)
      return oom(r);
    last = m->v[v].edge >= 0 ? m->v[v].edge / 3 : -1;
    r->forced++;
  }
  tt__tile_flag_edges(m, r->g->nx, r->g->ny, b);
  return TT_OK;
}

static tt_status start(refine *r, size_t valid)
{
  const tt_grid *g = r->g;
  tt_status s = valid == g->nx * g->ny ? start_rectangle(r)
                                       : start_hull(r, valid);
  if (s != TT_OK)
    return s;
  if (!tt__mesh_link_all(&r->m) ||
      tt__swap_all(&r->m, r->crit, &r->env, &r->stack) < 0)
    return oom(r);
  if (valid < g->nx * g->ny) {
    size_t before = r->m.nv;
    s = tt__domain_build(r->ctx, &r->m, g, r->crit, &r->env, &r->stack,
                         domain_vertex, r);
    if (s != TT_OK)
      return s;
    r->forced = r->m.nv - before;
  }
  if (r->opt->breaklines.n) {
    size_t before = r->m.nv;
    s = tt__breaklines_insert(r->ctx, &r->m, g, &r->opt->breaklines, r->crit,
                              &r->env, &r->stack, domain_vertex, r);
    if (s != TT_OK)
      return s;
    r->forced += r->m.nv - before;
  }
  if (r->borders && (s = start_borders(r)) != TT_OK)
    return s;
  /* every slot written so far is logged: scan them all */
  if (!r->start_size && !drain(r))
    return oom(r);
  return TT_OK;
}

/* --- the loop ----------------------------------------------------------- */

static double progress_fraction(refine *r, double err)
{
  double f = 0;
  if (r->max_points)
    f = fmax(f, (double)r->m.nv / (double)r->max_points);
  if (r->max_tris)
    f = fmax(f, (double)r->m.nlive / (double)r->max_tris);
  if (r->max_error >= 0 && r->e0 > 0 && err > 0) {
    double target = r->max_error > 0 ? r->max_error : r->e0 * 1e-6;
    if (target < r->e0)
      f = fmax(f, log(r->e0 / err) / log(r->e0 / target));
  }
  f = fmin(fmax(f, 0), 1);
  if (f > r->frac)
    r->frac = f;
  return r->frac;
}

/* Where sample (col,row) sits in triangle t: -1 strictly inside, else the
 * half-edge it lies on. */
static int32_t locate_in(const refine *r, int32_t t, int64_t col, int64_t row)
{
  const tt__mesh *m = &r->m;
  int s = m->metric.det_sign; /* pixel-space orientation of live triangles */
  for (int k = 0; k < 3; k++) {
    int32_t a = m->hv[3 * t + k], b = m->hv[3 * t + (k + 1) % 3];
    if (s * tt__orient_i(m->v[a].c, m->v[a].r, m->v[b].c, m->v[b].r, col,
                         row) == 0)
      return 3 * t + k;
  }
  return -1;
}

/* The insertion after this one is most often the heap's second entry (the
 * new triangles of this one tend to fit better). Its data is cold: ask for
 * it one insertion early, in two stages, so the misses overlap this
 * insertion's work instead of stalling the next one. Stage 2 (for the
 * triangle named last time, whose slot words are now near): its corners,
 * its neighbours' slots and the samples around its candidate. Stage 1:
 * the slot words and the candidate of the current second entry. Only
 * hints: nothing here changes what is computed. */
static void prefetch_next(const refine *r, int32_t *ahead)
{
#if defined(__GNUC__)
  const tt__mesh *m = &r->m;
  int32_t t = *ahead;
  if (t >= 0 && (size_t)t < m->nslots && tt__mesh_live(m, t)) {
    for (int k = 0; k < 3; k++) {
      __builtin_prefetch(&m->v[m->hv[3 * t + k]]);
      int32_t f = m->twin[3 * t + k];
      if (f >= 0)
        __builtin_prefetch(&m->hv[f - f % 3]);
    }
    int64_t s = r->cand[t];
    if (s >= 0 && r->prefetch) {
      /* the rows around the sample it will insert */
      int64_t nx = (int64_t)r->g->nx, ny = (int64_t)r->g->ny;
      int64_t col = s % nx, row = s / nx;
      int64_t x0 = col >= 16 ? col - 16 : 0, x1 = col + 16 < nx ? col + 16
                                                                : nx - 1;
      const tt_grid *g = r->g;
      size_t es = g->zd ? sizeof(double) : sizeof(float);
      const char *z0 = g->zd ? (const char *)g->zd : (const char *)g->z;
      for (int64_t y = row >= 4 ? row - 4 : 0; y <= row + 4 && y < ny; y++) {
        const char *z = z0 + (size_t)(y * nx) * es;
        __builtin_prefetch(z + (size_t)x0 * es);
        __builtin_prefetch(z + (size_t)x1 * es);
        if (x1 - x0 > 16)
          __builtin_prefetch(z + (size_t)((x0 + x1) / 2) * es);
      }
    }
  }
  *ahead = -1;
  const tt__heap *h = &r->heap;
  size_t n = tt__heap_size(h);
  if (n < 2)
    return;
  size_t best = 1;
  for (size_t i = 2; i <= 4 && i < n; i++)
    if (h->e[i].key > h->e[best].key)
      best = i;
  int32_t t2 = h->e[best].item;
  __builtin_prefetch(&m->hv[3 * t2]);
  __builtin_prefetch(&m->twin[3 * t2]);
  __builtin_prefetch(&r->cand[t2]);
  *ahead = t2;
#else
  (void)r;
  *ahead = -1;
#endif
}

/* --- curves (opt->step) --------------------------------------------------
 * A step is reported with the measures of the TIN a run stopped there
 * would return: the running sums and the heap's top, or, with a final
 * pass, a copy of the mesh after that pass (curve.c). */

static bool step_wanted(const refine *r, size_t points)
{
  const tt_refine_options *o = r->opt;
  if (points <= o->step_until)
    return true;
  for (size_t i = 0; i < o->nstep_at; i++)
    if (o->step_at[i] == points)
      return true;
  return false;
}

/* Reports step `iter` (insertions done) when it is wanted, or when last
 * (the step the run ends at; the previous report again when it was this
 * one). */
static tt_status report_step(refine *r, size_t iter, bool last)
{
  const tt_refine_options *o = r->opt;
  if (!r->rec || (!last && !step_wanted(r, r->linked)))
    return TT_OK;
  double t0 = tt__now();
  tt_step_info si;
  if (last && r->prev.points && r->prev.step == iter) {
    si = r->prev;
  } else {
    memset(&si, 0, sizeof si);
    si.step = iter;
    si.points = r->linked;
    si.triangles = r->m.nlive;
    bool any = tt__heap_size(&r->heap) > 0;
    double top = any ? tt__heap_top(&r->heap).key : 0.0;
    int64_t at = any ? r->cand[tt__heap_top(&r->heap).item] : -1;
    /* the run's time so far, the reports' own left out; plus, below,
     * this step's final pass */
    si.seconds = t0 - r->t_start - r->rec_seconds;
    if (r->final != TT_OPTIMIZE_NONE) {
      /* the bound of the run's own final pass */
      if (!tt__curve_final(&r->curve, &r->m, r->cerr, r->cand, r->crit,
                           &r->env, r->final, r->repair,
                           fmax(r->max_error, top), &o->anneal, r->linked,
                           r->valid, &si.errors))
        return oom(r);
      si.optimized = 1;
      si.seconds += tt__now() - t0;
    } else {
      tt__curve_errors(&r->curve, r->g, r->linked, r->valid, top, at,
                       &si.errors);
    }
  }
  si.last = last;
  r->prev = si;
  int go = o->step(&si, o->step_arg);
  r->rec_seconds += tt__now() - t0;
  if (!go)
    return tt__error(r->ctx, TT_ERR_INTERRUPTED, "interrupted by the step "
                     "callback after %zu vertices", r->linked);
  return TT_OK;
}

static tt_status check_options(tt_context *ctx, const tt_refine_options *o)
{
  if (isnan(o->max_error) || isinf(o->max_error))
    return tt__error(ctx, TT_ERR_ARG, "max error must be a finite number, "
                     "got %g", o->max_error);
  if (isnan(o->percent) || o->percent < 0 || o->percent > 100)
    return tt__error(ctx, TT_ERR_ARG, "percent must be in (0, 100], got %g",
                     o->percent);
  if (o->max_error < 0 && !o->max_points && !o->max_triangles &&
      o->percent == 0)
    return tt__error(ctx, TT_ERR_ARG, "no stop condition: set a max error, "
                     "a point or triangle budget, or a percentage");
  if (o->max_points > TT_MAX_VERTICES)
    return tt__error(ctx, TT_ERR_LIMIT, "max points %zu is above the limit "
                     "of %zu vertices", o->max_points,
                     (size_t)TT_MAX_VERTICES);
  if (!tt__criterion_get(o->criterion))
    return tt__error(ctx, TT_ERR_ARG, "unknown criterion %d",
                     (int)o->criterion);
  tt_status st = tt_optimize_check(ctx, o->optimize, o->criterion, &o->anneal);
  if (st != TT_OK)
    return st;
  if (!tt_repair_name(o->repair))
    return tt__error(ctx, TT_ERR_ARG, "unknown repair %d", (int)o->repair);
  if (o->breaklines.n && !o->breaklines.ends)
    return tt__error(ctx, TT_ERR_ARG, "breaklines.ends is NULL with n %zu",
                     o->breaklines.n);
  if (o->nstep_at && !o->step_at)
    return tt__error(ctx, TT_ERR_ARG, "step_at is NULL with nstep_at %zu",
                     o->nstep_at);
  return TT_OK;
}

static tt_status run(tt_context *ctx, const tt_grid *grid,
                     const tt_refine_options *opt,
                     const tt__tile_borders *borders, tt_tin **out_tin,
                     size_t *start_size)
{
  double t_start = tt__now();
  if (!grid || !opt || !out_tin)
    return tt__error(ctx, TT_ERR_ARG, "grid, options and out_tin must not be "
                     "NULL");
  *out_tin = NULL;
  tt_status status = check_options(ctx, opt);
  if (status != TT_OK)
    return status;
  size_t valid = 0;
  status = tt_grid_check(ctx, grid, &valid);
  if (status != TT_OK)
    return status;
  if (valid < 3)
    return tt__error(ctx, TT_ERR_DATA, "the grid has %zu valid sample%s: a "
                     "triangle needs 3", valid, valid == 1 ? "" : "s");

  refine r;
  memset(&r, 0, sizeof r);
  r.ctx = ctx;
  r.g = grid;
  r.opt = opt;
  r.borders = borders;
  r.start_size = start_size;
  r.crit = tt__criterion_get(opt->criterion);
  r.repair = tt_repair_resolve(opt->repair, opt->criterion);
  tt__metric metric;
  tt__metric_from_frame(grid->frame, &metric);
  tt__mesh_init(&r.m, &metric);
  tt__mesh_use_ground_points(&r.m, grid->gxy, grid->nx);
  tt__heap_init(&r.heap);
  r.env.mesh = &r.m;
  r.env.grid = grid;
  /* the vertices of a grid of doubles keep their exact heights */
  if (grid->zd && !tt__mesh_keep_f64(&r.m)) {
    status = oom(&r);
    goto done;
  }
  /* a criterion's cache may key its values by star versions (mesh.h);
   * without them (out of memory) it proves its entries by other means */
  if (r.crit->star_versions)
    (void)tt__mesh_track_stars(&r.m);
  r.env.cache = r.crit->cache_new ? r.crit->cache_new(&r.env) : NULL;

  int nthreads = opt->threads;
  if (nthreads == 0 && grid->nx * grid->ny < ((size_t)1 << 20))
    nthreads = 1; /* small grids: handing jobs over costs more than it saves */
  r.pool = tt__pool_create(tt__pool_threads(nthreads));
  /* the scans' error bounds per tile: without them (out of memory) large
   * triangles are scanned row by row, with the same results */
  if (!opt->step) /* recording scans every sample: no use for them */
    (void)tt__scan_tiles_build(grid, r.pool, &r.tiles);
  r.prefetch = tt__scan_prefetches(grid);
  r.max_error = opt->max_error;
  r.rec = opt->step != NULL;
  r.heap_floor = r.rec ? -1.0 : opt->max_error;
  r.valid = valid;
  r.t_start = t_start;
  r.final = tt_optimize_resolve(opt->optimize, opt->criterion, r.repair);
  r.max_points = opt->max_points;
  r.max_tris = opt->max_triangles;
  if (opt->percent > 0) {
    size_t p = (size_t)floor(opt->percent / 100.0 * (double)valid);
    if (!r.max_points || p < r.max_points)
      r.max_points = p;
  }
  if (r.max_points == 0 && (opt->percent > 0))
    r.max_points = 1; /* below the start: refused below */

  tt_stop_reason reason = TT_STOP_NONE;
  r.phase = "while building the starting triangulation";
  status = start(&r, valid);
  if (status == TT_OK)
    status = mem_check(&r, r.m.vcap, r.m.tcap);
  if (status != TT_OK)
    goto done;
  /* The limits count the TIN's vertices: those in a triangle. A vertex of
   * the start in none (a lone valid sample on the hull, amid nodata) is
   * not written, so it does not count. */
  for (size_t v = 0; v < r.m.nv; v++)
    r.linked += r.m.v[v].edge >= 0;
  if (start_size) {
    *start_size = r.linked;
    goto done;
  }
  /* a tile's max_points counts the insertions after its start (tile.h) */
  if (borders && r.max_points)
    r.max_points += r.linked;
  /* Every limit is exact: a budget below what the start needs (the four
   * corners, or the hull and the nodata outline's forced vertices, which
   * the run cannot drop) is refused before any insertion, with the count
   * to ask for instead. */
  char why[128];
  if (r.forced)
    snprintf(why, sizeof why, "%zu of its %zu vertices forced by the %s",
             r.forced, r.linked, opt->breaklines.n ? "nodata outline and "
             "the breaklines" : "nodata outline");
  else
    snprintf(why, sizeof why, "%s", valid == grid->nx * grid->ny
                                        ? "the grid's four corners"
                                        : "the valid samples' convex hull");
  if (r.max_points && r.linked > r.max_points) {
    status = tt__error(ctx, TT_ERR_LIMIT, "the point limit %zu%s is below "
                       "the %zu vertices the starting triangulation needs "
                       "(%s); ask for at least %zu", r.max_points,
                       opt->percent > 0 && r.max_points != opt->max_points
                           ? " (from the percentage)" : "",
                       r.linked, why, r.linked);
    goto done;
  }
  if (r.max_tris && r.m.nlive > r.max_tris) {
    status = tt__error(ctx, TT_ERR_LIMIT, "the triangle limit %zu is below "
                       "the %zu triangles the starting triangulation needs "
                       "(%s); ask for at least %zu", r.max_tris, r.m.nlive,
                       why, r.m.nlive);
    goto done;
  }
  r.phase = "while inserting";
  r.e0 = tt__heap_size(&r.heap) ? tt__heap_top(&r.heap).key : 0;
  size_t nv0 = r.m.nv; /* vertices before the first insertion */
  status = report_step(&r, 0, false);
  if (status != TT_OK)
    goto done;
  if (opt->progress && !opt->progress(0.0, "inserting", opt->progress_arg)) {
    status = tt__error(ctx, TT_ERR_INTERRUPTED, "interrupted");
    goto done;
  }

  int32_t ahead = -1; /* the likely next insertion's triangle (prefetch) */
  for (size_t iter = 1;; iter++) {
    prefetch_next(&r, &ahead);
    if (borders && borders->curve)
      borders->curve(borders->curve_arg, r.m.nv,
                     tt__heap_size(&r.heap) ? tt__heap_top(&r.heap).key
                                            : 0.0);
    if (tt__heap_size(&r.heap) == 0) {
      /* every sample is exact: an error limit, if any, is met */
      reason = r.max_error >= 0 ? TT_STOP_MAX_ERROR : TT_STOP_EXHAUSTED;
      break;
    }
    tt__heap_entry top = tt__heap_top(&r.heap);
    int32_t t = top.item;
    double err = top.key;
    if (r.max_error >= 0 && err <= r.max_error) {
      reason = TT_STOP_MAX_ERROR;
      break;
    }
    if (r.max_points && r.linked + 1 > r.max_points) {
      reason = TT_STOP_MAX_POINTS;
      break;
    }
    int64_t s = r.cand[t];
    int64_t col = s % (int64_t)grid->nx, row = s / (int64_t)grid->nx;
    int32_t on = locate_in(&r, t, col, row);
    size_t more = (on >= 0 && r.m.twin[on] < 0) ? 1 : 2;
    if (r.max_tris && r.m.nlive + more > r.max_tris) {
      reason = TT_STOP_MAX_TRIANGLES;
      break;
    }
    status = mem_check_growth(&r);
    if (status != TT_OK)
      goto done;
    int32_t v;
    if (!add_vertex(&r, (int32_t)col, (int32_t)row, err, &v)) {
      status = oom(&r);
      goto done;
    }
    int32_t opposite[4];
    int nopp;
    bool ok;
    if (on < 0) {
      ok = tt__mesh_split_triangle(&r.m, t, v, opposite);
      nopp = 3;
    } else {
      ok = tt__mesh_split_edge(&r.m, on, v, opposite);
      nopp = 4;
    }
    /* [optimize.c hook] the criterion restored around the new vertex as
     * opt->repair says: flips outward from it (Delaunay's exact incircle
     * flips, or any other criterion's swap values; min_area's exact hole
     * first), the local swap over its region, or Delaunay's flips alone */
    if (!ok || tt__optimize_insert(&r.m, r.crit, &r.env, r.repair, v,
                                   opposite, nopp, &r.stack) < 0 ||
        !drain(&r)) {
      status = oom(&r);
      goto done;
    }
    r.linked++;
    status = report_step(&r, iter, false);
    if (status != TT_OK)
      goto done;
    if (opt->progress && (iter & 255) == 0 &&
        !opt->progress(progress_fraction(&r, err), "inserting",
                       opt->progress_arg)) {
      status = tt__error(ctx, TT_ERR_INTERRUPTED, "interrupted after %zu "
                         "vertices", r.m.nv);
      goto done;
    }
  }
  status = report_step(&r, r.m.nv - nv0, true);
  if (status != TT_OK)
    goto done;
  /* [optimize.c hook] the final whole-mesh pass (opt->optimize). Flips
   * of unconstrained edges keep every triangle in the domain. A move that
   * would give one of its triangles an error above the larger of max_error
   * and the worst error left is refused, so the bound the loop reached
   * still holds. */
  r.phase = "in the final optimisation pass";
  if (!tt__optimize_final(&r.m, r.crit, &r.env, opt->optimize, r.repair,
                          fmax(r.max_error, tt__heap_size(&r.heap)
                                                ? tt__heap_top(&r.heap).key
                                                : 0.0),
                          &opt->anneal, NULL)) {
    status = oom(&r);
    goto done;
  }
  /* The insertion state is no longer needed: free it before the TIN's
   * arrays are made, to keep the peak low. */
  tt__heap_free(&r.heap);
  tt__scan_tiles_free(&r.tiles);
  free(r.cand);
  free(r.cerr);
  r.cand = NULL;
  r.cerr = NULL;
  tt__edge_stack_free(&r.stack);
  r.phase = "while building the TIN's records";
  status = mem_check(&r, r.m.nv, r.m.nlive);
  if (status != TT_OK)
    goto done;
  double t_meshed = tt__now();
  status = borders ? tt__tin_build_homes(ctx, &r.m, grid, r.ins_err, r.pool,
                                         out_tin)
                   : tt__tin_build(ctx, &r.m, grid, r.ins_err, r.pool,
                                   out_tin);
  r.ins_err = NULL; /* taken over by the tin, or freed on failure */
  if (status != TT_OK)
    goto done;
  (*out_tin)->summary.seconds_mesh = t_meshed - t_start;
  (*out_tin)->summary.seconds_statistics = tt__now() - t_meshed;
  (*out_tin)->summary.criterion = opt->criterion;
  (*out_tin)->summary.stop_reason = reason;
  (*out_tin)->summary.valid_samples = valid;
  (*out_tin)->summary.errors.samples = valid;
  (*out_tin)->summary.forced_vertices = r.forced;
  if (opt->progress && !opt->progress(1.0, "done", opt->progress_arg)) {
    tt_tin_destroy(*out_tin);
    *out_tin = NULL;
    status = tt__error(ctx, TT_ERR_INTERRUPTED, "interrupted");
  }
done:
  if (r.env.cache)
    r.crit->cache_free(r.env.cache);
  tt__pool_destroy(r.pool);
  tt__scan_tiles_free(&r.tiles);
  free(r.jobs);
  tt__heap_free(&r.heap);
  free(r.cand);
  free(r.cerr);
  free(r.ins_err);
  tt__edge_stack_free(&r.stack);
  tt__mesh_free(&r.m);
  tt__curve_free(&r.curve);
  return status;
}

tt_status tt_refine_run(tt_context *ctx, const tt_grid *grid,
                        const tt_refine_options *opt, tt_tin **out_tin)
{
  return run(ctx, grid, opt, NULL, out_tin, NULL);
}

tt_status tt__refine_start_size(tt_context *ctx, const tt_grid *grid,
                                size_t *out_vertices)
{
  tt_refine_options o;
  tt_refine_options_init(&o);
  o.max_error = 0;
  tt_tin *none = NULL;
  *out_vertices = 0;
  return run(ctx, grid, &o, NULL, &none, out_vertices);
}

tt_status tt__refine_tile(tt_context *ctx, const tt_grid *grid,
                          const tt_refine_options *opt,
                          const tt__tile_borders *borders, tt_tin **out_tin)
{
  if (!borders)
    return tt__error(ctx, TT_ERR_ARG, "borders must not be NULL");
  return run(ctx, grid, opt, borders, out_tin, NULL);
}
