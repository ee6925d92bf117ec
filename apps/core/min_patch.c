/*
 * min_patch.c -- -min_patch N: the valid patches of fewer than N samples
 * made nodata before the run.
 *
 * A patch is a set of valid samples connected through their four
 * neighbours (left, right, up, down): the nodata domain's rule, where two
 * valid samples that touch only diagonally share no cell with three valid
 * corners and so no triangle (src/mesh/domain.c). Each patch is flooded
 * once with an explicit stack; the first N - 1 of its samples are kept
 * aside, and when the flood ends before N they become NaN.
 *
 * Memory: one byte per sample (visited), the stack (at most the largest
 * patch) and N - 1 indices. Part of apps/core/, the commands' shared core.
 */
#include "app.h"

#include <math.h>
#include <stdlib.h>

static bool grow_idx(size_t **a, size_t *cap, size_t need)
{
  if (need <= *cap)
    return true;
  size_t c = *cap ? *cap : 64;
  while (c < need)
    c *= 2;
  size_t *p = realloc(*a, c * sizeof **a);
  if (!p)
    return false;
  *a = p;
  *cap = c;
  return true;
}

/* Whether sample i is valid (the grid holds floats or doubles). */
static bool valid_at(const float *zf, const double *zd, size_t i)
{
  return zf ? !isnan(zf[i]) : !isnan(zd[i]);
}

/* Floods the patch of sample i0; its size, capped at min, in *out_size,
 * its first min - 1 samples in keep. False when out of memory. */
static bool flood(size_t nx, size_t ny, const float *zf, const double *zd,
                  uint8_t *seen, size_t i0, size_t min, size_t **stack,
                  size_t *scap, size_t *keep, size_t *out_size)
{
  size_t top = 0, size = 0;
  (*stack)[top++] = i0;
  seen[i0] = 1;
  while (top) {
    size_t i = (*stack)[--top];
    if (size < min - 1)
      keep[size] = i;
    size++;
    size_t x = i % nx, y = i / nx;
    size_t nb[4];
    int n = 0;
    if (x > 0)
      nb[n++] = i - 1;
    if (x + 1 < nx)
      nb[n++] = i + 1;
    if (y > 0)
      nb[n++] = i - nx;
    if (y + 1 < ny)
      nb[n++] = i + nx;
    for (int k = 0; k < n; k++) {
      if (seen[nb[k]] || !valid_at(zf, zd, nb[k]))
        continue;
      if (!grow_idx(stack, scap, top + 1))
        return false;
      seen[nb[k]] = 1;
      (*stack)[top++] = nb[k];
    }
  }
  *out_size = size;
  return true;
}

bool tt__app_drop_patches(tt_grid *g, size_t min, size_t *out_samples,
                          size_t *out_patches)
{
  size_t nx = tt_grid_width(g), ny = tt_grid_height(g), n = nx * ny;
  float *zf = tt_grid_heights(g);
  double *zd = zf ? NULL : tt_grid_heights_f64(g);
  *out_samples = *out_patches = 0;
  if (min < 2)
    return true;
  uint8_t *seen = calloc(n ? n : 1, 1);
  size_t *keep = malloc((min - 1) * sizeof *keep);
  size_t *stack = NULL, scap = 0;
  bool ok = seen && keep && grow_idx(&stack, &scap, 64);
  for (size_t i = 0; ok && i < n; i++) {
    if (seen[i] || !valid_at(zf, zd, i))
      continue;
    size_t size;
    ok = flood(nx, ny, zf, zd, seen, i, min, &stack, &scap, keep, &size);
    if (!ok || size >= min)
      continue;
    for (size_t k = 0; k < size; k++) {
      if (zf)
        zf[keep[k]] = NAN;
      else
        zd[keep[k]] = NAN;
    }
    *out_samples += size;
    (*out_patches)++;
  }
  free(seen);
  free(keep);
  free(stack);
  return ok;
}
