/* A program built against the installed package (CMake config and
 * pkg-config): makes a grid, refines it, checks the bound. */
#include <terratin/terratin.h>
#ifdef TT_WITH_GDAL
#include <terratin/terratin_gdal.h>
#endif
#include <math.h>
#include <stdio.h>

int main(void)
{
  enum { NX = 40, NY = 30 };
  static float z[NX * NY];
  for (int r = 0; r < NY; r++)
    for (int c = 0; c < NX; c++)
      z[r * NX + c] = (float)(10 * sin(0.3 * c) + 5 * cos(0.2 * r));
  tt_context *ctx = tt_context_create();
  tt_grid *grid = NULL;
  tt_tin *tin = NULL;
  tt_refine_options opt;
  tt_refine_options_init(&opt);
  opt.max_error = 0.5;
  int rc = 1;
  if (tt_grid_create_from_floats(ctx, NX, NY, z, &grid) == TT_OK &&
      tt_refine_run(ctx, grid, &opt, &tin) == TT_OK) {
    tt_tin_summary s;
    tt_tin_get_summary(tin, &s);
    printf("%zu vertices, %zu triangles, max error %g\n", s.vertices,
           s.triangles, s.errors.max_error);
    rc = s.errors.max_error <= 0.5 && s.vertices > 4 ? 0 : 1;
  } else {
    fprintf(stderr, "consumer: %s\n", tt_context_errmsg(ctx));
  }
  tt_tin_destroy(tin);
  tt_grid_destroy(grid);
  tt_context_destroy(ctx);
  return rc;
}
