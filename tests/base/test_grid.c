/*
 * test_grid.c -- the height grid (src/base/grid.c) in its two precisions:
 * creation as floats and as doubles, which accessor answers for which
 * (the other returns NULL), tt_grid_sample at the grid's own precision,
 * tt_grid_check's refusals (infinities, heights beyond TT_MAX_HEIGHT in a
 * grid of doubles) and its count, the padding after the last sample, and
 * tt__grid_widen, which must keep every value (NaN included) exactly.
 */
#include "base/internal.h"
#include "tt_test.h"

#include <float.h>

static void test_floats(tt_context *ctx)
{
  const float z[6] = {1, 2.5f, NAN, 16777217.0f, -3, 0};
  tt_grid *g = NULL;
  CHECK_OK(ctx, tt_grid_create_from_floats(ctx, 3, 2, z, &g));
  if (!g)
    return;
  CHECK_INT_EQ(tt_grid_precision(g), TT_PRECISION_FLOAT32);
  CHECK(tt_grid_heights(g) != NULL && tt_grid_heights_const(g) != NULL);
  CHECK(tt_grid_heights_f64(g) == NULL && tt_grid_heights_f64_const(g) ==
                                              NULL);
  for (size_t i = 0; i < 6; i++) {
    double v = tt_grid_sample(g, i % 3, i / 3);
    CHECK(isnan(z[i]) ? isnan(v) : v == (double)z[i]);
  }
  size_t valid = 0;
  CHECK_OK(ctx, tt_grid_check(ctx, g, &valid));
  CHECK_INT_EQ(valid, 5);
  /* the padding after the last sample is NaN, for the vector kernels */
  for (size_t i = 0; i < TT__GRID_PAD; i++)
    CHECK(isnan(g->z[6 + i]));

  /* widening keeps every value, the padding too */
  CHECK(tt__grid_widen(g));
  CHECK_INT_EQ(tt_grid_precision(g), TT_PRECISION_FLOAT64);
  CHECK(tt_grid_heights(g) == NULL && tt_grid_heights_f64(g) != NULL);
  for (size_t i = 0; i < 6; i++) {
    double v = tt_grid_sample(g, i % 3, i / 3);
    CHECK(isnan(z[i]) ? isnan(v) : v == (double)z[i]);
  }
  for (size_t i = 0; i < TT__GRID_PAD; i++)
    CHECK(isnan(g->zd[6 + i]));
  CHECK(tt__grid_widen(g)); /* a grid of doubles stays as it is */
  CHECK_OK(ctx, tt_grid_check(ctx, g, &valid));
  CHECK_INT_EQ(valid, 5);
  tt_grid_destroy(g);

  /* an infinity is refused, naming its place */
  float zi[4] = {1, 2, 3, INFINITY};
  CHECK_OK(ctx, tt_grid_create_from_floats(ctx, 2, 2, zi, &g));
  CHECK_INT_EQ(tt_grid_check(ctx, g, NULL), TT_ERR_DATA);
  CHECK(strstr(tt_context_errmsg(ctx), "row 1, column 1 is infinite"));
  tt_grid_destroy(g);
}

static void test_doubles(tt_context *ctx)
{
  /* 2^30 + 1 and 10^6 + 0.001: no float holds them */
  const double z[6] = {1073741825.0, 1e6 + 0.001, NAN,
                       -9007199254740992.0, 0.1, TT_MAX_HEIGHT};
  tt_grid *g = NULL;
  CHECK_OK(ctx, tt_grid_create_from_doubles(ctx, 3, 2, z, &g));
  if (!g)
    return;
  CHECK_INT_EQ(tt_grid_precision(g), TT_PRECISION_FLOAT64);
  CHECK(tt_grid_heights(g) == NULL && tt_grid_heights_const(g) == NULL);
  CHECK(tt_grid_heights_f64_const(g) != NULL);
  for (size_t i = 0; i < 6; i++) {
    double v = tt_grid_sample(g, i % 3, i / 3);
    CHECK(isnan(z[i]) ? isnan(v) : v == z[i]);
  }
  size_t valid = 0;
  CHECK_OK(ctx, tt_grid_check(ctx, g, &valid));
  CHECK_INT_EQ(valid, 5);
  for (size_t i = 0; i < TT__GRID_PAD; i++)
    CHECK(isnan(g->zd[6 + i]));
  /* beyond TT_MAX_HEIGHT (the largest float): refused */
  tt_grid_heights_f64(g)[4] = -1e300;
  CHECK_INT_EQ(tt_grid_check(ctx, g, NULL), TT_ERR_DATA);
  CHECK(strstr(tt_context_errmsg(ctx), "row 1, column 1 is -1e+300, "
               "beyond the +-3.40282e+38"));
  tt_grid_heights_f64(g)[4] = -INFINITY;
  CHECK_INT_EQ(tt_grid_check(ctx, g, NULL), TT_ERR_DATA);
  CHECK(strstr(tt_context_errmsg(ctx), "row 1, column 1 is infinite"));
  tt_grid_destroy(g);

  /* a grid of doubles made empty is all NaN */
  CHECK_OK(ctx, tt_grid_create_f64(ctx, 4, 3, &g));
  CHECK_OK(ctx, tt_grid_check(ctx, g, &valid));
  CHECK_INT_EQ(valid, 0);
  tt_grid_destroy(g);
  CHECK_INT_EQ(tt_grid_create_from_doubles(ctx, 4, 3, NULL, &g), TT_ERR_ARG);
  CHECK_INT_EQ(tt_grid_create_f64(ctx, 1, 3, &g), TT_ERR_DATA);
  CHECK(g == NULL);
}

int main(void)
{
  tt_context *ctx = tt_context_create();
  TT_RUN(test_floats(ctx));
  TT_RUN(test_doubles(ctx));
  tt_context_destroy(ctx);
  TT_TEST_DONE();
}
