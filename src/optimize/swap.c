/*
 * swap.c -- flip loops under a criterion (see swap.h). Workload: a repair
 * after one insertion examines O(degree) edges; tt__swap_all is O(E) flips
 * for Delaunay in practice. Iterative with a growable stack, never
 * recursive.
 *
 * Part of src/optimize/, the optimisers: swaps under a criterion, look-ahead,
 * annealing, edge insertion, the dynamic programs.
 */
#include "optimize/swap.h"

#include <stdlib.h>

void tt__edge_stack_free(tt__edge_stack *s)
{
  free(s->e);
  s->e = NULL;
  s->n = s->cap = 0;
}

static bool push(tt__edge_stack *s, int32_t e)
{
  if (!tt__grow((void **)&s->e, &s->cap, s->n + 1, sizeof(int32_t)))
    return false;
  s->e[s->n++] = e;
  return true;
}

static bool should_flip(const tt__mesh *m, const tt__criterion_vt *crit,
                        const tt__crit_env *env, int32_t e)
{
  if (m->twin[e] < 0 || (m->eflag[e] & TT__EDGE_CONSTRAINED))
    return false;
  return crit->swap_value(env, e) > 0 && tt__mesh_flippable(m, e);
}

/* The triangles across the edges a repair starts from, and their far
 * corners, are cold in cache: ask for all of them first, in two stages
 * (slot words, then corners), so that their misses overlap instead of
 * queueing one flip test at a time. Only hints. */
static void prefetch_quads(const tt__mesh *m, const int32_t *opposite, int n)
{
#if defined(__GNUC__)
  for (int i = 0; i < n; i++) {
    int32_t f = opposite[i] >= 0 ? m->twin[opposite[i]] : -1;
    if (f >= 0)
      __builtin_prefetch(&m->hv[f - f % 3]);
  }
  for (int i = 0; i < n; i++) {
    int32_t f = opposite[i] >= 0 ? m->twin[opposite[i]] : -1;
    if (f >= 0)
      __builtin_prefetch(&m->v[tt__mesh_apex(m, f)]);
  }
#else
  (void)m, (void)opposite, (void)n;
#endif
}

long tt__swap_repair(tt__mesh *m, const tt__criterion_vt *crit,
                     const tt__crit_env *env, const int32_t *opposite, int n,
                     tt__edge_stack *stack)
{
  long flips = 0;
  stack->n = 0;
  for (int i = n - 1; i >= 0; i--)
    if (opposite[i] >= 0 && !push(stack, opposite[i]))
      return -1;
  prefetch_quads(m, opposite, n);
  while (stack->n > 0) {
    int32_t e = stack->e[--stack->n];
    if (!should_flip(m, crit, env, e))
      continue;
    /* e = a->b in (a, b, p); after the flip the new vertex p sees a->d and
     * d->b opposite it (mesh.h). */
    int32_t h = tt__mesh_flip(m, e);
    if (h < 0)
      return -1;
    if (crit->flipped)
      crit->flipped(env, h);
    flips++;
    if (!push(stack, tt__next(m->twin[h])) || !push(stack, tt__prev(h)))
      return -1;
  }
  return flips;
}

long tt__swap_all(tt__mesh *m, const tt__criterion_vt *crit,
                  const tt__crit_env *env, tt__edge_stack *stack)
{
  long flips = 0;
  stack->n = 0;
  for (size_t e = 0; e < 3 * m->nslots; e++)
    if (m->hv[e - e % 3] >= 0 && m->twin[e] > (int32_t)e &&
        !push(stack, (int32_t)e))
      return -1;
  while (stack->n > 0) {
    int32_t e = stack->e[--stack->n];
    if (m->hv[e - e % 3] < 0 || !should_flip(m, crit, env, e))
      continue;
    int32_t h = tt__mesh_flip(m, e);
    if (h < 0)
      return -1;
    if (crit->flipped)
      crit->flipped(env, h);
    flips++;
    /* the four outer edges of the quadrilateral may have become illegal */
    int32_t g = m->twin[h];
    int32_t quad[4] = {tt__next(h), tt__prev(h), tt__next(g), tt__prev(g)};
    for (int i = 0; i < 4; i++)
      if (m->twin[quad[i]] >= 0 && !push(stack, quad[i]))
        return -1;
  }
  return flips;
}
