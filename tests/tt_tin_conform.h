/*
 * tt_tin_conform.h -- the topology of a TIN checked from its triangles
 * alone, in integers: every edge is used by one or two triangles, no
 * vertex lies strictly inside an edge (a T-junction), no two vertices
 * stand on one sample, the Euler characteristic V - E + F, and the
 * boundary edges that are not on the grid's outline and have a fully valid
 * cell on both sides (a crack inside the domain). Shared by the tile tests.
 */
#ifndef TT_TIN_CONFORM_H
#define TT_TIN_CONFORM_H

#include "terratin/terratin.h"

#include <math.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

typedef struct tt_conform {
  size_t vertices, edges, triangles;
  size_t over_used;      /* edges of three triangles or more */
  size_t boundary;       /* edges of one triangle */
  size_t cracks;         /* boundary unit segments with valid cells both sides */
  size_t t_junctions;    /* vertices strictly inside some edge */
  size_t same_sample;    /* vertices on a sample another vertex has */
  long long euler;       /* V - E + F */
} tt_conform;

static int tt_conform_cmp_u64(const void *a, const void *b)
{
  uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
  return (x > y) - (x < y);
}

static inline bool tt_conform_is_vertex(const uint64_t *keys, size_t n,
                                        uint64_t key)
{
  size_t lo = 0, hi = n;
  while (lo < hi) {
    size_t mid = lo + (hi - lo) / 2;
    if (keys[mid] < key)
      lo = mid + 1;
    else
      hi = mid;
  }
  return lo < n && keys[lo] == key;
}

static inline int tt_conform_cell_valid(const tt_grid *g, long long cx,
                                        long long cy)
{
  long long nx = (long long)tt_grid_width(g), ny = (long long)tt_grid_height(g);
  if (cx < 0 || cy < 0 || cx + 1 >= nx || cy + 1 >= ny)
    return 0;
  int n = 0;
  for (int k = 0; k < 4; k++)
    n += !isnan(tt_grid_sample(g, (size_t)(cx + (k & 1)),
                               (size_t)(cy + (k >> 1))));
  return n;
}

/* False when out of memory. */
static inline bool tt_conform_check(const tt_grid *g, const tt_tin *tin,
                                    tt_conform *out)
{
  size_t nv = tt_tin_vertex_count(tin), nt = tt_tin_triangle_count(tin);
  uint64_t W = tt_grid_width(g);
  int32_t *vc = malloc((nv ? nv : 1) * sizeof *vc);
  int32_t *vr = malloc((nv ? nv : 1) * sizeof *vr);
  uint64_t *keys = malloc((nv ? nv : 1) * sizeof *keys);
  uint64_t *edges = malloc((nt ? 3 * nt : 1) * sizeof *edges);
  if (!vc || !vr || !keys || !edges) {
    free(vc);
    free(vr);
    free(keys);
    free(edges);
    return false;
  }
  memset(out, 0, sizeof *out);
  for (size_t v = 0; v < nv; v++) {
    tt_vertex_info vi;
    tt_tin_vertex(tin, v, &vi);
    vc[v] = vi.col;
    vr[v] = vi.row;
    keys[v] = (uint64_t)vi.row * W + (uint64_t)vi.col;
  }
  qsort(keys, nv, sizeof *keys, tt_conform_cmp_u64);
  for (size_t v = 1; v < nv; v++)
    out->same_sample += keys[v] == keys[v - 1];
  for (size_t t = 0; t < nt; t++) {
    tt_triangle_info ti;
    tt_tin_triangle(tin, t, &ti);
    for (int k = 0; k < 3; k++) {
      uint64_t a = (uint64_t)ti.v[k], b = (uint64_t)ti.v[(k + 1) % 3];
      edges[3 * t + k] = a < b ? a << 32 | b : b << 32 | a;
    }
  }
  qsort(edges, 3 * nt, sizeof *edges, tt_conform_cmp_u64);
  long long ny = (long long)tt_grid_height(g), nxl = (long long)W;
  for (size_t i = 0; i < 3 * nt;) {
    size_t j = i;
    while (j < 3 * nt && edges[j] == edges[i])
      j++;
    size_t use = j - i;
    out->edges++;
    out->over_used += use > 2;
    int32_t a = (int32_t)(edges[i] >> 32), b = (int32_t)(edges[i] & 0xffffffffu);
    long long dx = vc[b] - vc[a], dy = vr[b] - vr[a];
    long long ax = dx < 0 ? -dx : dx, ay = dy < 0 ? -dy : dy;
    long long gcd = ax, r = ay;
    while (r) {
      long long t2 = gcd % r;
      gcd = r;
      r = t2;
    }
    for (long long s = 1; s < gcd; s++) {
      long long x = vc[a] + dx / gcd * s, y = vr[a] + dy / gcd * s;
      out->t_junctions += tt_conform_is_vertex(keys, nv,
                                               (uint64_t)y * W + (uint64_t)x);
    }
    if (use == 1) {
      out->boundary++;
      /* an axis edge inside the grid with full cells both sides */
      if (dx == 0 && vc[a] > 0 && vc[a] < nxl - 1) {
        long long y0 = vr[a] < vr[b] ? vr[a] : vr[b];
        for (long long y = y0; y < y0 + ay; y++)
          out->cracks += tt_conform_cell_valid(g, vc[a] - 1, y) == 4 &&
                         tt_conform_cell_valid(g, vc[a], y) == 4;
      } else if (dy == 0 && vr[a] > 0 && vr[a] < ny - 1) {
        long long x0 = vc[a] < vc[b] ? vc[a] : vc[b];
        for (long long x = x0; x < x0 + ax; x++)
          out->cracks += tt_conform_cell_valid(g, x, vr[a] - 1) == 4 &&
                         tt_conform_cell_valid(g, x, vr[a]) == 4;
      }
    }
    i = j;
  }
  out->vertices = nv;
  out->triangles = nt;
  out->euler = (long long)nv - (long long)out->edges + (long long)nt;
  free(vc);
  free(vr);
  free(keys);
  free(edges);
  return true;
}

#endif /* TT_TIN_CONFORM_H */
