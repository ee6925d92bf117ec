/*
 * test_tin_output.c -- what a finished TIN promises its writers (issue 11,
 * items 4 and 7): triangles are counter-clockwise in map coordinates for
 * every sign of the geotransform's steps (north-up, no geotransform,
 * south-up, east-left); every vertex is a corner of some triangle (the
 * starting corners of a raster with nodata specks included); a grid whose
 * valid samples make no triangle (a checkerboard of nodata) is refused with
 * TT_ERR_DATA instead of giving a TIN of lone vertices; a triangle's rmse
 * never exceeds its max_err, nor a vertex's star_rmse its star_max (issue
 * 17: rmse was a float, rounded above max_err in 1,929 of Mt Hood's
 * triangles).
 */
#include "tt_test.h"

#include "terratin/terratin.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define NX 23
#define NY 17

static float height(size_t c, size_t r)
{
  return (float)(10.0 * sin(0.37 * (double)c) * cos(0.29 * (double)r) +
                 0.05 * (double)(c * r));
}

static tt_tin *run(tt_context *ctx, const float *z, const double *gt,
                   tt_status expect)
{
  tt_grid *g = NULL;
  tt_tin *tin = NULL;
  CHECK_OK(ctx, tt_grid_create_from_floats(ctx, NX, NY, z, &g));
  if (gt)
    CHECK_OK(ctx, tt_grid_set_geotransform(ctx, g, gt));
  tt_refine_options ro;
  tt_refine_options_init(&ro);
  ro.max_error = 0.5;
  tt_status s = tt_refine_run(ctx, g, &ro, &tin);
  CHECK_INT_EQ(s, expect);
  tt_grid_destroy(g);
  return tin;
}

/* Signed area of every triangle in map coordinates is > 0; every vertex is
 * used by some triangle. */
static void check_tin(const tt_tin *tin, const char *what)
{
  size_t nv = tt_tin_vertex_count(tin), nt = tt_tin_triangle_count(tin);
  char *used = calloc(nv ? nv : 1, 1);
  size_t cw = 0;
  CHECK(nt > 0);
  for (size_t i = 0; i < nt; i++) {
    tt_triangle_info t;
    tt_vertex_info v[3];
    CHECK_INT_EQ(tt_tin_triangle(tin, i, &t), TT_OK);
    for (int k = 0; k < 3; k++) {
      CHECK_INT_EQ(tt_tin_vertex(tin, (size_t)t.v[k], &v[k]), TT_OK);
      used[t.v[k]] = 1;
    }
    double a2 = (v[1].x - v[0].x) * (v[2].y - v[0].y) -
                (v[1].y - v[0].y) * (v[2].x - v[0].x);
    if (!(a2 > 0))
      cw++;
  }
  size_t lone = 0;
  for (size_t i = 0; i < nv; i++)
    lone += !used[i];
  if (cw || lone)
    fprintf(stderr, "%s: %zu of %zu triangles not counter-clockwise, %zu of "
            "%zu vertices in no triangle\n", what, cw, nt, lone, nv);
  CHECK_INT_EQ(cw, 0);
  CHECK_INT_EQ(lone, 0);
  free(used);
}

static void test_orientation(tt_context *ctx)
{
  float z[NX * NY];
  for (size_t r = 0; r < NY; r++)
    for (size_t c = 0; c < NX; c++)
      z[r * NX + c] = height(c, r);
  const double north_up[6] = {500000, 30, 0, 4000000, 0, -30};
  const double south_up[6] = {500000, 30, 0, 4000000, 0, 30};
  const double east_left[6] = {500000, -30, 0, 4000000, 0, -30};
  const double rotated[6] = {0, 0, 2, 0, 2, 0}; /* x from rows: a mirror */
  const struct { const char *name; const double *gt; } cases[] = {
      {"no geotransform", NULL}, {"north-up", north_up},
      {"south-up", south_up},    {"east-left", east_left},
      {"transposed", rotated}};
  for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
    tt_tin *tin = run(ctx, z, cases[i].gt, TT_OK);
    if (tin)
      check_tin(tin, cases[i].name);
    tt_tin_destroy(tin);
  }
}

static void test_speckled_corners(tt_context *ctx)
{
  /* Each grid corner is valid but cut off from the rest by nodata on its
   * two neighbours: the starting triangulation's corners make no
   * triangle of the domain. */
  float z[NX * NY];
  for (size_t r = 0; r < NY; r++)
    for (size_t c = 0; c < NX; c++)
      z[r * NX + c] = height(c, r);
  const size_t cc[2] = {0, NX - 1}, rr[2] = {0, NY - 1};
  for (int i = 0; i < 2; i++)
    for (int k = 0; k < 2; k++) {
      size_t c = cc[i], r = rr[k];
      size_t c1 = c ? c - 1 : 1, r1 = r ? r - 1 : 1;
      z[r * NX + c1] = NAN;
      z[r1 * NX + c] = NAN;
      z[r1 * NX + c1] = NAN;
    }
  tt_tin *tin = run(ctx, z, NULL, TT_OK);
  if (tin)
    check_tin(tin, "speckled corners");
  tt_tin_destroy(tin);
}

static void test_checkerboard(tt_context *ctx)
{
  float z[NX * NY];
  for (size_t r = 0; r < NY; r++)
    for (size_t c = 0; c < NX; c++)
      z[r * NX + c] = (r + c) % 2 ? NAN : height(c, r);
  tt_tin *tin = run(ctx, z, NULL, TT_ERR_DATA);
  CHECK(tin == NULL);
  CHECK(strstr(tt_context_errmsg(ctx), "no triangle") != NULL);
  tt_tin_destroy(tin);
}

/* A 129^2 fractal at max error 5 has 3,007 triangles whose rmse equals
 * their max_err (most own one sample); rounded to a float, 206 of them
 * would exceed it. */
static void test_rmse_le_max(tt_context *ctx)
{
  tt_synth_options so;
  tt_synth_options_init(&so, TT_SYNTH_DIAMOND_SQUARE);
  so.nx = so.ny = 129;
  so.seed = 17;
  tt_grid *g = NULL;
  tt_tin *tin = NULL;
  CHECK_OK(ctx, tt_synth_generate(ctx, &so, &g));
  tt_refine_options ro;
  tt_refine_options_init(&ro);
  ro.max_error = 5;
  CHECK_OK(ctx, tt_refine_run(ctx, g, &ro, &tin));
  size_t above = 0, as_float = 0, star_above = 0, eq = 0;
  for (size_t i = 0; tin && i < tt_tin_triangle_count(tin); i++) {
    tt_triangle_info t;
    CHECK_INT_EQ(tt_tin_triangle(tin, i, &t), TT_OK);
    above += t.rmse > t.max_error;
    as_float += (double)(float)t.rmse > t.max_error;
    eq += t.rmse == t.max_error && t.max_error > 0;
  }
  for (size_t i = 0; tin && i < tt_tin_vertex_count(tin); i++) {
    tt_vertex_info v;
    CHECK_INT_EQ(tt_tin_vertex(tin, i, &v), TT_OK);
    star_above += v.star_rmse > v.star_max_error;
  }
  printf("rmse > max_err: %zu of %zu triangles (%zu if stored as floats; "
         "%zu with rmse = max_err > 0); star_rmse > star_max: %zu\n", above,
         tin ? tt_tin_triangle_count(tin) : 0, as_float, eq, star_above);
  CHECK(as_float > 0); /* the case is exercised */
  CHECK_INT_EQ(above, 0);
  CHECK_INT_EQ(star_above, 0);
  tt_tin_destroy(tin);
  tt_grid_destroy(g);
}

int main(void)
{
  tt_context *ctx = tt_context_create();
  TT_RUN(test_rmse_le_max(ctx));
  TT_RUN(test_orientation(ctx));
  TT_RUN(test_speckled_corners(ctx));
  TT_RUN(test_checkerboard(ctx));
  tt_context_destroy(ctx);
  TT_TEST_DONE();
}
