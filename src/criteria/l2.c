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
 * Each triangle is scanned from its smallest vertex id (rotated, so its
 * orientation and the ownership of its edges stay), so its sum is a
 * function of the triangle alone, whichever quad asks for it: a swap and
 * the swap back have exactly opposite values, and the sums can be cached.
 *
 * Cache (cache_new, per run): a direct-mapped table of triangle sums keyed
 * by the rotated vertex triple and the three ownership bits, about two
 * entries per triangle of the mesh (grown with it, up to a cap), for the
 * real triangles (the "before" of every edge of a triangle) and the
 * hypothetical ones (the "after", which become real when the swap is
 * taken). A hit returns the very bits the scan would, so the cache never
 * changes a value; a collision overwrites. Vertices never move and the
 * grid does not change during a run, so an entry never goes stale; a
 * cache handed another mesh or grid than the one it was made for is not
 * used.
 * Needs: the grid (env->grid; without one the value is 0). Quads that are
 * not strictly convex score 0 (geometry.h), so the scans never meet a
 * degenerate triangle. Cost: a scan of the quad's samples twice -- the
 * price of a data-dependent criterion, linear in the quad's area.
 *
 * Part of src/criteria/, the criteria: one file per triangulation criterion
 * behind one vtable.
 */
#include "criteria/geometry.h"
#include "mesh/raster_scan.h"

#include <stdlib.h>
#include <string.h>

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

typedef struct l2_entry {
  int32_t v[3];        /* rotated triple; v[0] = -1: empty */
  uint32_t own;        /* ownership bits (0-2); bit 3: no valid sample */
  double sse;
} l2_entry;

#define L2_NO_SAMPLE 8u

typedef struct l2_cache {
  l2_entry *e;
  size_t mask;
  const tt__mesh *mesh;   /* what the entries belong to */
  const tt_grid *grid;
} l2_cache;

/* The table holds about two entries per triangle of the mesh: it starts
 * small and is re-made (emptied) twice as large whenever the mesh has
 * outgrown it, up to L2_CACHE_MAX entries (24 bytes each, 1.5 MiB: the
 * hits come from edges of the same triangles scored one after the other,
 * and a table larger than the processor's caches measured slower). */
#define L2_CACHE_MIN ((size_t)1 << 12)
#define L2_CACHE_MAX ((size_t)1 << 16)

static bool l2_cache_size(l2_cache *c, size_t n)
{
  l2_entry *e = malloc(n * sizeof *e);
  if (!e)
    return false;
  for (size_t i = 0; i < n; i++)
    e[i].v[0] = -1;
  free(c->e);
  c->e = e;
  c->mask = n - 1;
  return true;
}

static void *l2_cache_new(const tt__crit_env *env)
{
  if (!env->grid)
    return NULL;
  l2_cache *c = malloc(sizeof *c);
  if (!c)
    return NULL;
  c->e = NULL;
  c->mesh = env->mesh;
  c->grid = env->grid;
  if (!l2_cache_size(c, L2_CACHE_MIN)) {
    free(c);
    return NULL;
  }
  return c;
}

static void l2_cache_free(void *cache)
{
  l2_cache *c = cache;
  if (c) {
    free(c->e);
    free(c);
  }
}

/* Sum of squared residuals of triangle (p0, p1, p2) with edge ownership
 * o0 (p0->p1), o1, o2: scanned from its smallest vertex, or read from the
 * cache; *out_none tells whether it owns no valid sample at all. */
static double tri_sse(const tt__crit_env *env, int32_t p0, int32_t p1,
                      int32_t p2, bool o0, bool o1, bool o2, bool *out_none)
{
  const tt__mesh *m = env->mesh;
  int32_t p[3] = {p0, p1, p2};
  bool o[3] = {o0, o1, o2};
  int r = p[1] < p[0] ? (p[2] < p[1] ? 2 : 1) : (p[2] < p[0] ? 2 : 0);
  int32_t v[3] = {p[r], p[(r + 1) % 3], p[(r + 2) % 3]};
  uint32_t own = (uint32_t)o[r] | (uint32_t)o[(r + 1) % 3] << 1 |
                 (uint32_t)o[(r + 2) % 3] << 2;
  l2_cache *c = env->cache;
  if (c && (c->mesh != m || c->grid != env->grid))
    c = NULL;
  l2_entry *slot = NULL;
  if (c && c->mask + 1 < 2 * m->nslots && c->mask + 1 < L2_CACHE_MAX) {
    size_t n = 2 * (c->mask + 1);
    while (n < 2 * m->nslots && n < L2_CACHE_MAX)
      n <<= 1;
    l2_cache_size(c, n); /* out of memory: the old table goes on */
  }
  if (c) {
    uint64_t h = ((uint64_t)(uint32_t)v[0] * 0x9e3779b97f4a7c15ull) ^
                 ((uint64_t)(uint32_t)v[1] * 0xc2b2ae3d27d4eb4full) ^
                 ((uint64_t)(uint32_t)v[2] * 0x165667b19e3779f9ull) ^ own;
    h ^= h >> 29;
    slot = &c->e[h & c->mask];
    if (slot->v[0] == v[0] && slot->v[1] == v[1] && slot->v[2] == v[2] &&
        (slot->own & ~L2_NO_SAMPLE) == own) {
      *out_none = slot->own & L2_NO_SAMPLE;
      return slot->sse;
    }
  }
  tt__scan_tri st;
  for (int k = 0; k < 3; k++) {
    st.x[k] = m->v[v[k]].c;
    st.y[k] = m->v[v[k]].r;
    st.z[k] = tt__mesh_z(m, v[k]);
    st.own[k] = (own >> k) & 1u;
  }
  tt__scan_stats s;
  tt__scan_stats_run(env->grid, &st, &s);
  *out_none = s.count == 0;
  if (slot) {
    memcpy(slot->v, v, sizeof v);
    slot->own = own | (s.count == 0 ? L2_NO_SAMPLE : 0u);
    slot->sse = s.sum_sq;
  }
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
  bool none1, none2;
  double before = tri_sse(env, q.a, q.b, q.c, o_ab, o_bc, o_ca, &none1) +
                  tri_sse(env, q.b, q.a, q.d, !o_ab, o_ad, o_db, &none2);
  if (none1 && none2) {
    /* the two triangles after the swap own the same samples as the two
     * before (see the ownership note above): none, so both sums are 0 */
    return q.sign * tt__snap(0.0, 0.0);
  }
  double after = tri_sse(env, q.c, q.a, q.d, o_ca, o_ad, !o_cd, &none1) +
                 tri_sse(env, q.d, q.b, q.c, o_db, o_bc, o_cd, &none2);
  return q.sign * tt__snap(before - after, before + after);
}

const tt__criterion_vt tt__criterion_l2 = {
    TT_CRITERION_L2, "l2", true, l2_swap_value, NULL, l2_cache_new,
    l2_cache_free, NULL, false};
