/*
 * l2.c -- the L2 (least-squares) criterion, SPEC section 2.7.
 *
 * Definition: minimise the sum over the valid grid samples of (H - H')^2,
 * H the sample's height and H' the TIN's height there (heights in ground
 * units; the frame does not enter: the residual is vertical). A swap
 * changes H' only inside the quad. Swap value: the squared residuals of
 * the samples the two triangles own before the swap minus those the two
 * hypothetical triangles own after, each triangle summed by
 * tt__scan_stats_run (raster_scan.h), the scan a whole-mesh measure uses
 * (the same samples; the residuals agree to the rounding of the plane,
 * whose origin corner may differ). Positive: the swap lowers the error.
 * Differences below 1e-12 of the total read 0.
 *
 * Ownership: the diagonal's samples go to one of its two triangles by the
 * top-left rule, before and after alike; the outer edges keep the mesh's
 * ownership (the quad's triangle owns a sample on an outer edge when its
 * half-edge passes the rule, or on the boundary). Those outer-edge samples
 * do not change the difference: an outer edge belongs to one triangle of
 * the quad before and to one after, and on the edge both planes are the
 * linear interpolation between the edge's two end vertices, so the
 * residual there is the same either way (to the rounding of the plane
 * expression) and cancels. Vertex samples are exact and owned by nobody.
 *
 * The quad is read in geometry.h's canonical form, each triangle scanned
 * with the same corner order whichever diagonal the mesh has, so a swap and
 * the swap back have exactly opposite values.
 * Needs: the grid (env->grid; without one the value is 0). Quads that are
 * not strictly convex score 0 (geometry.h), so the scans never meet a
 * degenerate triangle. Cost: a scan of the quad's samples twice -- the
 * price of a data-dependent criterion, linear in the quad's area.
 */
#include "geometry.h"
#include "../raster_scan.h"

/* The mesh's ownership rule for half-edge x (raster_scan.c). */
static bool owns(const tt__mesh *m, int32_t x)
{
  if (m->twin[x] < 0)
    return true;
  int32_t p = m->hv[x], q = m->hv[tt__next(x)];
  int64_t dx = (int64_t)m->v[q].c - m->v[p].c;
  int64_t dy = (int64_t)m->v[q].r - m->v[p].r;
  return dy > 0 || (dy == 0 && dx > 0);
}

static bool owns_seg(const tt__mesh *m, int32_t p, int32_t q)
{
  int64_t dx = (int64_t)m->v[q].c - m->v[p].c;
  int64_t dy = (int64_t)m->v[q].r - m->v[p].r;
  return dy > 0 || (dy == 0 && dx > 0);
}

/* Sum of squared residuals of triangle (p0, p1, p2) with edge ownership
 * o0 (p0->p1), o1, o2. */
static double tri_sse(const tt_grid *g, const tt__mesh *m, int32_t p0,
                      int32_t p1, int32_t p2, bool o0, bool o1, bool o2)
{
  tt__scan_tri st;
  int32_t p[3] = {p0, p1, p2};
  for (int k = 0; k < 3; k++) {
    st.x[k] = m->v[p[k]].c;
    st.y[k] = m->v[p[k]].r;
    st.z[k] = (double)m->v[p[k]].z;
  }
  st.own[0] = o0;
  st.own[1] = o1;
  st.own[2] = o2;
  tt__scan_stats s;
  tt__scan_stats_run(g, &st, &s);
  return s.sum_sq;
}

static double l2_swap_value(const tt__crit_env *env, int32_t e)
{
  const tt__mesh *m = env->mesh;
  double fr[4];
  tt__quad q;
  if (!env->grid)
    return 0.0;
  tt__geo_frame(env, fr);
  if (!tt__quad_load(env, e, fr, &q))
    return 0.0;
  bool o_bc = owns(m, q.in[0]), o_ca = owns(m, q.in[1]);
  bool o_ad = owns(m, q.in[2]), o_db = owns(m, q.in[3]);
  bool o_ab = owns_seg(m, q.a, q.b), o_cd = owns_seg(m, q.c, q.d);
  const tt_grid *g = env->grid;
  double before = tri_sse(g, m, q.a, q.b, q.c, o_ab, o_bc, o_ca) +
                  tri_sse(g, m, q.b, q.a, q.d, !o_ab, o_ad, o_db);
  double after = tri_sse(g, m, q.c, q.a, q.d, o_ca, o_ad, !o_cd) +
                 tri_sse(g, m, q.d, q.b, q.c, o_db, o_bc, o_cd);
  return q.sign * tt__snap(before - after, before + after);
}

const tt__criterion_vt tt__criterion_l2 = {
    TT_CRITERION_L2, "l2", true, l2_swap_value, NULL, NULL, NULL};
