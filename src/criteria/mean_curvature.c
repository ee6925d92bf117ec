/*
 * mean_curvature.c -- the mean curvature criterion, SPEC section 2.4.
 *
 * Definition: minimise the sum over interior edges of |e| alpha(e), |e|
 * the 3-D edge length in ground units and alpha(e) the angle (radians)
 * between the unit normals of the two triangles sharing e; boundary edges
 * count 0. Swap value: the terms of the quad's five edges (the diagonal
 * and the 4 outer edges against the triangles across them) before minus
 * after; positive when the swap lowers the sum. Differences below 1e-12 of
 * the terms' total are rounding noise and read 0.
 * Needs: the quad's vertices and the apexes of the up to four triangles
 * across its outer edges. Since a swap changes the normals of two
 * triangles, an edge's value changes when its quad or its outer triangles
 * meet them: the affected hook returns the new diagonal, the 4 quad edges
 * and the other edges of the triangles across them (at most 13).
 * Degenerate triangles (only hypothetical, in quads that are not strictly
 * convex, which score 0 anyway) would have zero normals and alpha = 0.
 * The quad is read in geometry.h's canonical form, so a swap and the swap
 * back have exactly opposite values. Cost: 8 cross products and 5 + 5
 * atan2.
 *
 * Part of src/criteria/, the criteria: one file per triangulation criterion
 * behind one vtable.
 */
#include "criteria/geometry.h"

static double mean_curvature_swap_value(const tt__crit_env *env, int32_t e)
{
  double fr[4];
  tt__quad q;
  tt__geo_frame(env, fr);
  if (!tt__quad_load(env, e, fr, &q))
    return 0.0;
  double ab[5], aa[5], len[5], len_cd;
  tt__quad_alphas(env, fr, &q, ab, aa, len, &len_cd);
  double before = len[0] * ab[0], after = len_cd * aa[0];
  for (int k = 1; k < 5; k++) {
    before += len[k] * ab[k];
    after += len[k] * aa[k];
  }
  return q.sign * tt__snap(before - after, before + after);
}

/* Adds the edge of half-edge x to out unless it is there (as either
 * half). */
static int add_edge(const tt__mesh *m, int32_t x, int32_t *out, int n,
                    int max, int *total)
{
  int32_t t = m->twin[x];
  for (int i = 0; i < n && i < max; i++)
    if (out[i] == x || (t >= 0 && out[i] == t))
      return n;
  if (n < max)
    out[n] = x;
  (*total)++;
  return n + 1;
}

int tt__affected_quad_ring(const tt__crit_env *env, int32_t h, int32_t *out,
                           int max)
{
  const tt__mesh *m = env->mesh;
  int32_t g = m->twin[h];
  int32_t quad[4] = {tt__next(h), tt__prev(h), tt__next(g), tt__prev(g)};
  int n = 0, total = 0;
  n = add_edge(m, h, out, n, max, &total);
  for (int k = 0; k < 4; k++)
    n = add_edge(m, quad[k], out, n, max, &total);
  for (int k = 0; k < 4; k++) {
    int32_t t = m->twin[quad[k]];
    if (t < 0)
      continue;
    n = add_edge(m, tt__next(t), out, n, max, &total);
    n = add_edge(m, tt__prev(t), out, n, max, &total);
  }
  return total < max ? total : max;
}

const tt__criterion_vt tt__criterion_mean_curvature = {
    TT_CRITERION_MEAN_CURVATURE, "mean_curvature", true,
    mean_curvature_swap_value, tt__affected_quad_ring, NULL, NULL, NULL, false};
