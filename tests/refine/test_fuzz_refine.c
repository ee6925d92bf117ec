/* test_fuzz_refine.c -- fuzz target for the engine: the bytes become a
 * small grid (size, ground frame, heights with NaN holes, flat runs and
 * cliffs) and refinement options; every result must satisfy the oracle
 * (tt_eval_triangles: bound, cover, no overlap) and the mesh must be valid.
 *
 * Built with -DTT_FUZZ_LIBFUZZER it is a libFuzzer target, in which a
 * failed check aborts (tt_test.h) so that libFuzzer sees the oracle's
 * failures as crashes and keeps their inputs:
 *   cmake -S . -B build-fuzz -DCMAKE_C_COMPILER=clang -DTT_FUZZ=ON
 *   cmake --build build-fuzz -j2 --target fuzz_refine
 *   build-fuzz/tests/fuzz_refine -max_total_time=60 RUN_DIR tests/corpus/refine
 * (docs/fuzzing.md). Otherwise its main() replays every file of
 * $TT_CORPUS/refine (past crashes and seeds, named after the issue that
 * found them) and 400 inputs from a seeded generator, so ctest runs them
 * all without clang. */
#include "terratin/terratin.h"
#include "tt_test.h"
#include "tt_tin_oracle.h"

#include <stdbool.h>

static int check_input(const uint8_t *data, size_t size)
{
  if (size < 8)
    return 0;
  size_t nx = 2 + data[0] % 40, ny = 2 + data[1] % 40;
  static const double frames[][4] = {
      {1, 0, 0, 1}, {30, 0, 0, -30}, {89.98, 0, 0, -90.02}, {2, 1, 0, 3},
      {0.7, -0.2, 0.3, -1.1}, {1e-5, 0, 0, -1e-5}};
  const double *frame = frames[data[2] % 6];
  uint8_t mode = data[3];
  double max_error = (data[4] % 8) * 0.5;
  size_t max_points = data[5] % 4 == 0 ? 4 + data[6] : 0;
  const uint8_t *h = data + 8;
  size_t nh = size - 8;

  tt_context *ctx = tt_context_create();
  tt_grid *g = NULL;
  tt_tin *tin = NULL;
  if (tt_grid_create(ctx, nx, ny, &g) != TT_OK)
    goto out;
  double gt[6] = {1000, frame[0], frame[1], 2000, frame[2], frame[3]};
  tt_grid_set_geotransform(ctx, g, gt);
  float *z = tt_grid_heights(g);
  for (size_t i = 0; i < nx * ny; i++) {
    uint8_t b = nh ? h[i % nh] : 0;
    if ((mode & 1) && b >= 240)
      z[i] = NAN;                       /* holes */
    else if (mode & 2)
      z[i] = (float)(b / 64) * 10.0f;   /* terraces: flats and cliffs */
    else
      z[i] = (float)b * 0.37f;
  }
  tt_refine_options opt;
  tt_refine_options_init(&opt);
  opt.max_error = max_error;
  opt.max_points = max_points;
  opt.threads = (mode & 4) ? 2 : 1;
  tt_status s = tt_refine_run(ctx, g, &opt, &tin);
  if (s != TT_OK) {
    /* only data errors are acceptable: too few or collinear valid
     * samples; and a point budget below the start's vertices (the
     * corners, the hull, the nodata outline), refused since issue 11 */
    if (s != TT_ERR_DATA && !(s == TT_ERR_LIMIT && max_points))
      TT_FAIL_("refine failed with %s: %s", tt_status_name(s),
               tt_context_errmsg(ctx));
    goto out;
  }
  size_t nt = tt_tin_triangle_count(tin);
  double *xyz = tt_oracle_pixel_triangles(tin);
  tt_eval_result ev;
  if (tt_eval_triangles(ctx, g, nt, xyz, &ev) != TT_OK)
    TT_FAIL_("eval failed: %s", tt_context_errmsg(ctx));
  free(xyz);
  tt_tin_summary sum;
  tt_tin_get_summary(tin, &sum);
  if (ev.overlapped)
    TT_FAIL_("%zux%zu mode %u: %zu overlapped", nx, ny, mode, ev.overlapped);
  /* only samples that no valid cell part holds stay uncovered */
  if (ev.uncovered != tt_oracle_uncarriable(g))
    TT_FAIL_("%zux%zu mode %u: %zu uncovered, %zu cannot be carried", nx,
             ny, mode, ev.uncovered, tt_oracle_uncarriable(g));
  if (ev.uncovered != sum.errors.samples - sum.errors.covered)
    TT_FAIL_("%zux%zu mode %u: %zu uncovered, summary says %zu", nx, ny,
             mode, ev.uncovered, sum.errors.samples - sum.errors.covered);
  if (tt_oracle_nodata_inside(g, tin))
    TT_FAIL_("%zux%zu mode %u: a triangle has nodata strictly inside", nx,
             ny, mode);
  if (sum.stop_reason == TT_STOP_MAX_ERROR &&
      !(ev.errors.max_error <= max_error + 1e-9 * (1 + max_error)))
    TT_FAIL_("%zux%zu mode %u: max error %.17g above %g", nx, ny, mode,
             ev.errors.max_error, max_error);
  /* past the point limit only when the starting hull alone is larger
   * (then nothing was inserted), or for the nodata outline */
  if (max_points && sum.vertices > max_points && !sum.forced_vertices) {
    for (size_t v = 0; v < sum.vertices; v++) {
      tt_vertex_info vi;
      tt_tin_vertex(tin, v, &vi);
      if (!isnan(vi.insert_error)) {
        TT_FAIL_("%zu vertices above the limit %zu", sum.vertices,
                 max_points);
        break;
      }
    }
  }
out:
  tt_tin_destroy(tin);
  tt_grid_destroy(g);
  tt_context_destroy(ctx);
  return 0;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
  return check_input(data, size);
}

#ifndef TT_FUZZ_LIBFUZZER
#include <dirent.h>

int main(void)
{
  size_t files = 0;
  const char *corpus = getenv("TT_CORPUS");
  char dir[4096];
  snprintf(dir, sizeof dir, "%s/refine", corpus ? corpus : "tests/corpus");
  DIR *d = opendir(dir);
  if (!d) {
    TT_FAIL_("cannot open the corpus folder %s", dir);
  } else {
    struct dirent *de;
    while ((de = readdir(d)) != NULL) {
      if (de->d_name[0] == '.')
        continue;
      char path[8192];
      snprintf(path, sizeof path, "%s/%s", dir, de->d_name);
      FILE *f = fopen(path, "rb");
      if (!f)
        continue;
      uint8_t buf[8192];
      size_t n = fread(buf, 1, sizeof buf, f);
      fclose(f);
      int before = tt_test_failures;
      check_input(buf, n);
      if (tt_test_failures != before)
        fprintf(stderr, "  (corpus file %s)\n", de->d_name);
      files++;
    }
    closedir(d);
  }
  uint64_t seed = 0xf022u, rng = seed;
  for (int i = 0; i < 400; i++) {
    uint8_t buf[512];
    size_t n = 8 + tt_test_rand(&rng) % (sizeof buf - 8);
    for (size_t k = 0; k < n; k++)
      buf[k] = (uint8_t)tt_test_rand(&rng);
    int before = tt_test_failures;
    check_input(buf, n);
    if (tt_test_failures != before) {
      fprintf(stderr, "  (generated input %d of seed %#llx)\n", i,
              (unsigned long long)seed);
      break;
    }
  }
  printf("replayed %zu corpus files and 400 generated inputs\n", files);
  TT_TEST_DONE();
}
#endif
