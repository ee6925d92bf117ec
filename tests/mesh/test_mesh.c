/* test_mesh.c -- mesh invariants after random sequences of splits and
 * flips, in several ground frames (square, non-square, sheared, mirrored
 * north-up), with tt__mesh_validate() after every operation; a Delaunay
 * repair leaves every interior edge legal under the exact incircle test.
 * Points are placed with tt__mesh_locate (its walk, and its scan fallback
 * on the non-Delaunay meshes that random flips make). Star versions: every
 * operation that changes a vertex's star changes its version, and a flip
 * adds exactly one to its four vertices' (a flip tried and reverted too). */
#include "mesh/mesh.h"
#include "base/predicates.h"
#include "optimize/swap.h"
#include "tt_test.h"

#include <stdlib.h>
#include <string.h>

static bool validate(const tt__mesh *m, uint64_t seed, int step)
{
  char why[256];
  if (!tt__mesh_validate(m, why, sizeof why)) {
    TT_FAIL_("seed %#llx step %d: %s", (unsigned long long)seed, step, why);
    return false;
  }
  return true;
}

/* --- star versions (tt__mesh_track_stars) ------------------------------
 * A signature of every vertex's star: its corners (next and previous
 * vertex, which of the corner's two edges have twins), sorted and hashed.
 * Whenever an operation changes a signature, that vertex's version must
 * have changed too. */
static int cmp_u64(const void *a, const void *b)
{
  uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
  return (x > y) - (x < y);
}

static void star_signatures(const tt__mesh *m, uint64_t *sig)
{
  size_t n = 0;
  uint64_t *key = malloc((3 * m->nslots + 1) * sizeof *key);
  if (!key)
    return;
  for (size_t e = 0; e < 3 * m->nslots; e++) {
    if (m->hv[e - e % 3] < 0)
      continue;
    int32_t x = (int32_t)e, p = tt__prev(x);
    key[n++] = (uint64_t)m->hv[x] << 44 | (uint64_t)m->hv[tt__next(x)] << 24 |
               (uint64_t)m->hv[p] << 4 | (uint64_t)(m->twin[x] >= 0) << 1 |
               (uint64_t)(m->twin[p] >= 0);
  }
  qsort(key, n, sizeof *key, cmp_u64);
  for (size_t v = 0; v < m->nv; v++)
    sig[v] = 0x9e3779b97f4a7c15u;
  for (size_t i = 0; i < n; i++) {
    uint64_t *h = &sig[key[i] >> 44];
    *h = (*h ^ (key[i] & 0xfffffffffffu)) * 0x100000001b3u;
  }
  free(key);
}

static uint64_t sig_before[2048], sig_after[2048];
static uint32_t ver_before[2048];

static void versions_snap(const tt__mesh *m)
{
  star_signatures(m, sig_before);
  memcpy(ver_before, m->vver, m->nv * sizeof ver_before[0]);
}

/* every changed star has a new version; a flip adds exactly one to each of
 * its quad's four vertices (quad: NULL for other operations) */
static void versions_check(const tt__mesh *m, uint64_t seed, int step,
                           const char *op, const int32_t *quad)
{
  star_signatures(m, sig_after);
  for (size_t v = 0; v < m->nv; v++) { /* at most 41 x 31 < 2048 */
    bool changed = sig_after[v] != sig_before[v];
    if (changed && m->vver[v] == ver_before[v]) {
      TT_FAIL_("seed %#llx step %d: %s changed the star of %zu but not its "
               "version", (unsigned long long)seed, step, op, v);
      return;
    }
  }
  for (int k = 0; quad && k < 4; k++)
    if (m->vver[quad[k]] != ver_before[quad[k]] + 1) {
      TT_FAIL_("seed %#llx step %d: a flip moved the version of %d by %u",
               (unsigned long long)seed, step, quad[k],
               m->vver[quad[k]] - ver_before[quad[k]]);
      return;
    }
}

static void run(const double frame[4], uint64_t seed)
{
  tt__metric metric;
  tt__metric_from_frame(frame, &metric);
  tt__mesh m;
  tt__mesh_init(&m, &metric);
  CHECK(tt__mesh_track_stars(&m));
  const int W = 40, H = 30;
  int32_t v0 = tt__mesh_add_vertex(&m, 0, 0, 0.0f);
  int32_t v1 = tt__mesh_add_vertex(&m, W, 0, 0.0f);
  int32_t v2 = tt__mesh_add_vertex(&m, W, H, 0.0f);
  int32_t v3 = tt__mesh_add_vertex(&m, 0, H, 0.0f);
  if (tt__mesh_orient(&m, v0, v1, v2) > 0) {
    tt__mesh_add_triangle(&m, v0, v1, v2);
    tt__mesh_add_triangle(&m, v0, v2, v3);
  } else {
    tt__mesh_add_triangle(&m, v0, v2, v1);
    tt__mesh_add_triangle(&m, v0, v3, v2);
  }
  CHECK(tt__mesh_link_all(&m));
  if (!validate(&m, seed, -1))
    goto out;
  uint64_t rng = seed;
  unsigned char used[41][31] = {{0}};
  used[0][0] = used[W][0] = used[W][H] = used[0][H] = 1;
  tt__edge_stack stack = {0};
  for (int step = 0; step < 400; step++) {
    int op = (int)(tt_test_rand(&rng) % 3);
    if (op < 2) {
      int c = (int)(tt_test_rand(&rng) % (W + 1));
      int r = (int)(tt_test_rand(&rng) % (H + 1));
      if (used[c][r])
        continue;
      int32_t on;
      int32_t t = tt__mesh_locate(&m, -1, c, r, &on);
      CHECK(t >= 0 && on > -2);
      if (t < 0 || on <= -2)
        goto out;
      used[c][r] = 1;
      int32_t v = tt__mesh_add_vertex(&m, c, r, 0.0f);
      int32_t opp[4];
      int nopp = 3;
      versions_snap(&m);
      if (on < 0)
        CHECK(tt__mesh_split_triangle(&m, t, v, opp));
      else {
        CHECK(tt__mesh_split_edge(&m, on, v, opp));
        nopp = 4;
      }
      versions_check(&m, seed, step, "a split", NULL);
      if (!validate(&m, seed, step))
        goto out;
      if (op == 1) {
        /* Delaunay repair around v */
        tt__crit_env env = {&m, NULL, NULL};
        versions_snap(&m);
        CHECK(tt__swap_repair(&m, &tt__criterion_delaunay, &env, opp, nopp,
                              &stack) >= 0);
        versions_check(&m, seed, step, "a repair", NULL);
        if (!validate(&m, seed, step))
          goto out;
      }
    } else {
      /* a random flippable edge: kept, or tried and reverted */
      for (int tries = 0; tries < 20; tries++) {
        int32_t e = (int32_t)(tt_test_rand(&rng) % (3 * m.nslots));
        if (!tt__mesh_live(&m, e / 3) || !tt__mesh_flippable(&m, e))
          continue;
        int32_t f = m.twin[e];
        int32_t quad[4] = {m.hv[e], m.hv[f], tt__mesh_apex(&m, e),
                           tt__mesh_apex(&m, f)};
        versions_snap(&m);
        if (tt_test_rand(&rng) % 4 == 0) {
          tt__mesh_flip_undo u;
          CHECK(tt__mesh_flip_undoable(&m, e, &u) >= 0);
          versions_check(&m, seed, step, "an undoable flip", quad);
          versions_snap(&m);
          tt__mesh_flip_revert(&m, &u);
          versions_check(&m, seed, step, "a revert", NULL);
        } else {
          CHECK(tt__mesh_flip(&m, e) >= 0);
          versions_check(&m, seed, step, "a flip", quad);
        }
        break;
      }
      if (!validate(&m, seed, step))
        goto out;
    }
  }
  /* make it Delaunay and check every interior edge */
  {
    tt__crit_env env = {&m, NULL, NULL};
    CHECK(tt__swap_all(&m, &tt__criterion_delaunay, &env, &stack) >= 0);
    validate(&m, seed, 9999);
    for (size_t e = 0; e < 3 * m.nslots; e++) {
      if (!tt__mesh_live(&m, (int32_t)(e / 3)) || m.twin[e] < 0)
        continue;
      int32_t f = m.twin[e];
      int ic = tt__mesh_incircle(&m, m.hv[e], m.hv[f],
                                 tt__mesh_apex(&m, (int32_t)e),
                                 tt__mesh_apex(&m, f));
      if (ic > 0) {
        TT_FAIL_("seed %#llx: edge %zu is not locally Delaunay",
                 (unsigned long long)seed, e);
        break;
      }
    }
  }
  /* free-slot recycling: slots never exceed what the live count needs */
  CHECK_INT_EQ(m.nslots, m.nlive + m.nfree);
  /* versions under region replacement (a quad re-triangulated the other
   * way) and triangle deletion */
  for (int i = 0; i < 20; i++) {
    int32_t e = (int32_t)(tt_test_rand(&rng) % (3 * m.nslots));
    if (!tt__mesh_live(&m, e / 3) || !tt__mesh_flippable(&m, e))
      continue;
    int32_t f = m.twin[e];
    int32_t a = m.hv[e], b = m.hv[f], c = tt__mesh_apex(&m, e),
            d = tt__mesh_apex(&m, f);
    int32_t slots[2] = {e / 3, f / 3}, tris[2][3] = {{c, a, d}, {d, b, c}};
    versions_snap(&m);
    CHECK(tt__mesh_replace_region(&m, slots, 2, (const int32_t(*)[3])tris,
                                  2));
    versions_check(&m, seed, 10000 + i, "a region replacement", NULL);
  }
  for (int i = 0; i < 20; i++) {
    int32_t t = (int32_t)(tt_test_rand(&rng) % m.nslots);
    if (!tt__mesh_live(&m, t))
      continue;
    versions_snap(&m);
    CHECK(tt__mesh_delete_triangle(&m, t));
    versions_check(&m, seed, 20000 + i, "a deletion", NULL);
  }
  tt__edge_stack_free(&stack);
out:
  tt__mesh_free(&m);
}

int main(void)
{
  const double frames[][4] = {
      {1, 0, 0, 1},        /* pixel units */
      {30, 0, 0, -30},     /* north-up, square pixels: mirrored */
      {89.98, 0, 0, -90.02}, /* non-square pixels */
      {2, 1, 0, 3},        /* sheared */
      {0.7, -0.2, 0.3, -1.1}, /* rotated, mirrored */
  };
  for (size_t i = 0; i < sizeof frames / sizeof frames[0]; i++)
    for (uint64_t s = 1; s <= 6; s++)
      run(frames[i], 0x1000u * (i + 1) + s);
  TT_TEST_DONE();
}
