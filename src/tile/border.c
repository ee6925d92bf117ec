/*
 * border.c -- a tile border (a row or column of samples shared by two
 * tiles) simplified as a 1-D polyline of samples to the run's max error.
 *
 * Both tiles compute the same vertices from the same samples: the border
 * line and the line on either side of it, which each tile's window holds
 * (tile.c reads one row or column beyond every shared side). The line is
 * cut at breaks: its two ends (tile corners) and every sample next to
 * nodata on any of the three lines, nodata samples included (they are never
 * vertices). Between two consecutive breaks every sample is valid and so
 * are the cells on both sides, so both TINs cover that run; each run is
 * simplified top-down like greedy insertion in one dimension: the sample
 * farthest from the chord (the first of equal ones) becomes a vertex and
 * both halves are treated the same way, until every sample is within the
 * bound of its chord. The chord's height at sample i of the run [a, b] is
 * z_a + (z_b - z_a) (i - a) / (b - a), the exact linear interpolation of
 * the two vertices; a triangle's plane evaluated on the same edge
 * (raster_scan.h) differs from it by rounding only, so a sample is accepted
 * only when its error is below max_error by a margin of 2^-24 max_error +
 * 2^-30 max|z| of the run: the refined TIN then keeps it within the bound
 * whatever triangle the edge belongs to.
 *
 * Cost: O(n log n) for a line of n samples in practice (O(n^2) when every
 * sample must be kept, 4096^2 steps for a tile of 4096); memory: a stack of
 * pairs of indices, at most n.
 *
 * Part of src/tile/, tiled runs: the tiles, their shared borders, one tile's
 * run, the merge.
 */
#include "tile/tile.h"
#include "mesh/mesh.h"

#include <math.h>
#include <stdlib.h>

void tt__tile_borders_free(tt__tile_borders *b)
{
  if (!b)
    return;
  free(b->col);
  free(b->row);
  for (int s = 0; s < 4; s++) {
    free(b->cover[s]);
    free(b->kept[s]);
    b->cover[s] = NULL;
    b->kept[s] = NULL;
  }
  b->col = b->row = NULL;
  b->n = b->cap = 0;
}

/* The side of the tile grid that both ends of an edge lie on (tile.h's
 * numbering), or -1. */
static int side_of(size_t nx, size_t ny, const tt__mesh_vertex *a,
                   const tt__mesh_vertex *b)
{
  if (a->c == 0 && b->c == 0)
    return 0;
  if (a->r == 0 && b->r == 0)
    return 1;
  if ((size_t)a->c == nx - 1 && (size_t)b->c == nx - 1)
    return 2;
  if ((size_t)a->r == ny - 1 && (size_t)b->r == ny - 1)
    return 3;
  return -1;
}

void tt__tile_flag_edges(tt__mesh *m, size_t nx, size_t ny,
                         const tt__tile_borders *b)
{
  for (size_t t = 0; t < m->nslots; t++) {
    if (!tt__mesh_live(m, (int32_t)t))
      continue;
    for (int k = 0; k < 3; k++) {
      int32_t e = 3 * (int32_t)t + k;
      if (m->twin[e] >= 0)
        continue;
      const tt__mesh_vertex *va = &m->v[m->hv[e]];
      const tt__mesh_vertex *vb = &m->v[m->hv[tt__next(e)]];
      int s = side_of(nx, ny, va, vb);
      if (s < 0 || !(b->shared & (1u << s)))
        continue;
      int32_t p = (s == 0 || s == 2) ? va->r : va->c;
      int32_t q = (s == 0 || s == 2) ? vb->r : vb->c;
      int32_t lo = p < q ? p : q, len = p < q ? q - p : p - q;
      /* a longer edge spans a run between breaks: covered on both sides
       * (border.c); a unit one is when the neighbour's cell is */
      m->eflag[e] |= TT__EDGE_BORDER;
      if (len >= 2 || b->cover[s][lo])
        m->eflag[e] |= TT__EDGE_BORDER_SHARED;
    }
  }
}

int tt__tile_on_border(const tt__tile_borders *b, size_t nx, size_t ny,
                       int32_t col, int32_t row, bool *out_kept)
{
  int on = 0;
  bool kept = true;
  const int s[4] = {col == 0, row == 0, (size_t)col == nx - 1,
                    (size_t)row == ny - 1};
  for (int k = 0; k < 4; k++)
    if (s[k] && (b->shared & (1u << k))) {
      on = 1;
      kept = kept && b->kept[k] && b->kept[k][k == 0 || k == 2 ? row : col];
    }
  *out_kept = kept;
  return on;
}

/* Simplifies the all-valid run [a, b] (both already kept). */
static bool simplify_run(const double *z, size_t a, size_t b,
                         double max_error, uint8_t *keep, size_t *stack)
{
  double zmax = 0;
  for (size_t i = a; i <= b; i++)
    zmax = fmax(zmax, fabs(z[i]));
  const double margin = ldexp(max_error, -24) + ldexp(zmax, -30);
  size_t n = 0;
  stack[n++] = a;
  stack[n++] = b;
  while (n) {
    size_t hi = stack[--n], lo = stack[--n];
    if (hi - lo < 2)
      continue;
    double za = z[lo], dz = z[hi] - z[lo], len = (double)(hi - lo);
    double worst = -1;
    size_t at = lo;
    for (size_t i = lo + 1; i < hi; i++) {
      double e = fabs(z[i] - (za + dz * ((double)(i - lo) / len)));
      if (e > worst) {
        worst = e;
        at = i;
      }
    }
    if (worst + margin <= max_error)
      continue;
    keep[at] = 1;
    /* the right half below the left one: the left is done first (the
     * order does not change the result, each half being independent) */
    stack[n++] = at;
    stack[n++] = hi;
    stack[n++] = lo;
    stack[n++] = at;
  }
  return true;
}

bool tt__border_simplify(const double *z, const uint8_t *brk, size_t n,
                         double max_error, uint8_t *keep)
{
  for (size_t i = 0; i < n; i++)
    keep[i] = brk[i] && !isnan(z[i]);
  if (n < 3)
    return true;
  /* every chord splits in two, so the stack holds at most 2 entries per
   * kept level: 2 n bounds it */
  size_t *stack = malloc(2 * n * sizeof *stack);
  if (!stack)
    return false;
  size_t a = 0;
  for (size_t i = 1; i < n; i++) {
    if (!brk[i])
      continue;
    /* a run between breaks a and i: all valid when its inner samples are
     * not breaks (a sample next to nodata is one) */
    if (i - a >= 2 && !isnan(z[a]) && !isnan(z[i]))
      simplify_run(z, a, i, max_error, keep, stack);
    a = i;
  }
  free(stack);
  return true;
}
