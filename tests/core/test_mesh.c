/* test_mesh.c -- mesh invariants after random sequences of splits and
 * flips, in several ground frames (square, non-square, sheared, mirrored
 * north-up), with tt__mesh_validate() after every operation; a Delaunay
 * repair leaves every interior edge legal under the exact incircle test.
 * Points are placed with tt__mesh_locate (its walk, and its scan fallback
 * on the non-Delaunay meshes that random flips make). */
#include "mesh.h"
#include "predicates.h"
#include "swap.h"
#include "tt_test.h"

static bool validate(const tt__mesh *m, uint64_t seed, int step)
{
  char why[256];
  if (!tt__mesh_validate(m, why, sizeof why)) {
    TT_FAIL_("seed %#llx step %d: %s", (unsigned long long)seed, step, why);
    return false;
  }
  return true;
}

static void run(const double frame[4], uint64_t seed)
{
  tt__metric metric;
  tt__metric_from_frame(frame, &metric);
  tt__mesh m;
  tt__mesh_init(&m, &metric);
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
      if (on < 0)
        CHECK(tt__mesh_split_triangle(&m, t, v, opp));
      else {
        CHECK(tt__mesh_split_edge(&m, on, v, opp));
        nopp = 4;
      }
      if (!validate(&m, seed, step))
        goto out;
      if (op == 1) {
        /* Delaunay repair around v */
        tt__crit_env env = {&m, NULL, NULL};
        CHECK(tt__swap_repair(&m, &tt__criterion_delaunay, &env, opp, nopp,
                              &stack) >= 0);
        if (!validate(&m, seed, step))
          goto out;
      }
    } else {
      /* a random flippable edge */
      for (int tries = 0; tries < 20; tries++) {
        int32_t e = (int32_t)(tt_test_rand(&rng) % (3 * m.nslots));
        if (!tt__mesh_live(&m, e / 3) || !tt__mesh_flippable(&m, e))
          continue;
        CHECK(tt__mesh_flip(&m, e) >= 0);
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
