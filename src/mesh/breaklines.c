/*
 * breaklines.c -- breaklines as constrained edges of the starting
 * triangulation, before refinement.
 *
 * The caller gives segments between grid samples (tt_breaklines: a line
 * already made a chain of samples and simplified). Each end is inserted
 * as a vertex by a walk-located split with the criterion repaired around
 * it (a sample that is a vertex already is taken as it is), then each
 * segment is recovered as constrained edges by the outline's flips
 * (tt__domain_recover_segment), split at any vertex on it. Refinement
 * only splits triangles and flips unconstrained edges afterwards, and a
 * vertex inserted on a constrained edge splits it into two constrained
 * halves, so the lines stay in the TIN; optimisers never flip them.
 *
 * Workload: a few thousand segments at most in practice; each end costs
 * a walk, each segment a flip sequence over the edges it crosses.
 *
 * Part of src/mesh/, the mesh stage: the half-edge mesh, the samples a
 * triangle owns, the nodata domain.
 */
#include "mesh/breaklines.h"

#include "base/predicates.h"

#include <math.h>
#include <stdlib.h>

/* The vertex of sample s, inserted when it is none yet; -1 with the
 * error set in ctx. *last is the walk's start, updated. */
static int32_t end_vertex(tt_context *ctx, tt__mesh *m, const tt_grid *g,
                          int64_t s, const tt__criterion_vt *crit,
                          const tt__crit_env *env, tt__edge_stack *stack,
                          tt__domain_add_vertex add_vertex, void *add_arg,
                          int32_t *last)
{
  int64_t n = (int64_t)(g->nx * g->ny);
  if (s < 0 || s >= n) {
    tt__error(ctx, TT_ERR_DATA, "breakline sample %lld is off the %zu x %zu "
              "grid", (long long)s, g->nx, g->ny);
    return -1;
  }
  int64_t x = s % (int64_t)g->nx, y = s / (int64_t)g->nx;
  int32_t on;
  int32_t t = isnan(tt__grid_z(g, (size_t)s)) ? -1
                                              : tt__mesh_locate(m, *last, x,
                                                                y, &on);
  if (t < 0) {
    tt__error(ctx, TT_ERR_DATA, "breakline sample (%lld, %lld) is not in "
              "the valid domain", (long long)x, (long long)y);
    return -1;
  }
  *last = t;
  if (on <= -2)
    return -2 - on;
  int32_t v, opp[4];
  if (!add_vertex(add_arg, (int32_t)x, (int32_t)y, &v))
    goto oom;
  bool split = on < 0 ? tt__mesh_split_triangle(m, t, v, opp)
                      : tt__mesh_split_edge(m, on, v, opp);
  if (!split || tt__swap_repair(m, crit, env, opp, on < 0 ? 3 : 4,
                                stack) < 0)
    goto oom;
  *last = m->v[v].edge >= 0 ? m->v[v].edge / 3 : -1;
  return v;
oom:
  tt__error(ctx, TT_ERR_NOMEM, "out of memory while inserting the "
            "breaklines");
  return -1;
}

static void flag_edge(tt__mesh *m, int32_t e)
{
  m->eflag[e] |= TT__EDGE_CONSTRAINED | TT__EDGE_BREAKLINE;
  if (m->twin[e] >= 0)
    m->eflag[m->twin[e]] |= TT__EDGE_CONSTRAINED | TT__EDGE_BREAKLINE;
}

bool tt__breaklines_flag(tt__mesh *m, int32_t a, int32_t b)
{
  int32_t e = tt__mesh_find_edge(m, a, b);
  if (e < 0)
    e = tt__mesh_find_edge(m, b, a);
  if (e < 0)
    return false;
  flag_edge(m, e);
  return true;
}

/* Whether vertex c lies on segment pb, strictly after p (c == b too). */
static bool ahead(const tt__mesh *m, int32_t p, int32_t b, int32_t c)
{
  const tt__mesh_vertex *P = &m->v[p], *B = &m->v[b], *C = &m->v[c];
  if (tt__orient_i(P->c, P->r, B->c, B->r, C->c, C->r) != 0)
    return false;
  int64_t dx = B->c - P->c, dy = B->r - P->r;
  int64_t t = (int64_t)(C->c - P->c) * dx + (int64_t)(C->r - P->r) * dy;
  return t > 0 && t <= dx * dx + dy * dy;
}

/* The ring of p's star into *ring (grown); -1 when p is in no triangle,
 * -2 when out of memory. */
static int star_ring(const tt__mesh *m, int32_t p, int32_t **ring, int *cap)
{
  bool closed;
  int n = tt__mesh_star(m, p, *ring, NULL, *cap, &closed);
  if (n > *cap) {
    int32_t *r = realloc(*ring, (size_t)n * sizeof *r);
    if (!r)
      return -2;
    *ring = r;
    *cap = n;
    n = tt__mesh_star(m, p, *ring, NULL, *cap, &closed);
  }
  return n;
}

/* Recovers segment ab: step by step along the vertices on it that are
 * neighbours already (the outline's recovery finds those inside a star,
 * not those across the boundary, where a line along the grid's edge
 * meets them), then the rest by flips. */
static bool recover_line(tt__mesh *m, int32_t a, int32_t b, int32_t **ring,
                         int *cap, bool *ok)
{
  int32_t p = a;
  *ok = true;
  while (p != b && *ok) {
    int n = star_ring(m, p, ring, cap);
    if (n == -2)
      return false;
    int32_t q = -1;
    for (int i = 0; i < n && q < 0; i++)
      if (ahead(m, p, b, (*ring)[i]))
        q = (*ring)[i];
    if (q < 0)
      return tt__domain_recover_segment(m, p, b, ok);
    if (!tt__domain_recover_segment(m, p, q, ok))
      return false;
    p = q;
  }
  return true;
}

/* Flags the recovered edges from a to b (split at the vertices on the
 * segment) as a breakline's. False when out of memory or when the chain
 * of edges is not there (then the recovery failed). */
static bool flag_segment(tt__mesh *m, int32_t a, int32_t b, int32_t **ring,
                         int *cap)
{
  int32_t p = a;
  size_t guard = 0;
  while (p != b) {
    int n = star_ring(m, p, ring, cap);
    if (n == -2)
      return false;
    int32_t q = -1;
    for (int i = 0; i < n && q < 0; i++)
      if (ahead(m, p, b, (*ring)[i]))
        q = (*ring)[i];
    int32_t e = q >= 0 ? tt__mesh_find_edge(m, p, q) : -1;
    if (e < 0)
      e = q >= 0 ? tt__mesh_find_edge(m, q, p) : -1;
    if (e < 0 || ++guard > m->nv)
      return false;
    flag_edge(m, e);
    p = q;
  }
  return true;
}

tt_status tt__breaklines_insert(tt_context *ctx, tt__mesh *m,
                                const tt_grid *g, const tt_breaklines *bl,
                                const tt__criterion_vt *crit,
                                const tt__crit_env *env,
                                tt__edge_stack *stack,
                                tt__domain_add_vertex add_vertex,
                                void *add_arg)
{
  tt_status status = TT_OK;
  int32_t *ring = NULL;
  int ringcap = 0;
  int32_t *vid = malloc((2 * bl->n + 1) * sizeof *vid);
  if (!vid)
    return tt__error(ctx, TT_ERR_NOMEM, "out of memory for %zu breakline "
                     "segments", bl->n);
  /* 1. the ends become vertices */
  int32_t last = -1;
  for (size_t i = 0; i < 2 * bl->n; i++) {
    vid[i] = end_vertex(ctx, m, g, bl->ends[i], crit, env, stack,
                        add_vertex, add_arg, &last);
    if (vid[i] < 0) {
      status = tt_context_errno(ctx);
      goto done;
    }
  }
  /* 2. every segment becomes constrained edges */
  for (size_t i = 0; i < bl->n; i++) {
    bool ok = true;
    if (vid[2 * i] == vid[2 * i + 1])
      continue; /* a segment of one sample: nothing to recover */
    if (!recover_line(m, vid[2 * i], vid[2 * i + 1], &ring, &ringcap,
                      &ok)) {
      status = tt__error(ctx, TT_ERR_NOMEM, "out of memory while "
                         "recovering the breaklines");
      goto done;
    }
    if (!ok) {
      int64_t a = bl->ends[2 * i], b = bl->ends[2 * i + 1];
      int64_t nx = (int64_t)g->nx;
      status = tt__error(ctx, TT_ERR_DATA, "breakline segment (%lld, %lld) "
                         "- (%lld, %lld) cannot be made an edge: it crosses "
                         "another breakline or the nodata outline",
                         (long long)(a % nx), (long long)(a / nx),
                         (long long)(b % nx), (long long)(b / nx));
      goto done;
    }
  }
  /* 3. each segment's edges flagged as a breakline's, once all are in
   *    (a later recovery may split an earlier segment at a vertex) */
  for (size_t i = 0; i < bl->n; i++)
    if (vid[2 * i] != vid[2 * i + 1] &&
        !flag_segment(m, vid[2 * i], vid[2 * i + 1], &ring, &ringcap)) {
      status = tt__error(ctx, TT_ERR_INTERNAL, "a recovered breakline "
                         "segment is not a chain of mesh edges");
      goto done;
    }
  /* 4. the criterion restored around the constrained edges */
  if (tt__swap_all(m, crit, env, stack) < 0)
    status = tt__error(ctx, TT_ERR_NOMEM, "out of memory while inserting "
                       "the breaklines");
done:
  free(vid);
  free(ring);
  return status;
}
