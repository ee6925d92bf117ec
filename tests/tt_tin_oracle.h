/*
 * tt_tin_oracle.h -- independent checks of a TIN against its grid, shared
 * by the engine and GDAL tests. Nothing here uses raster_scan.c: the
 * triangles go through tt_eval_triangles (its own rasteriser) or through
 * plain integer edge tests. Heights are read through tt_grid_sample, at
 * the grid's own precision.
 */
#ifndef TT_TIN_ORACLE_H
#define TT_TIN_ORACLE_H

#include "terratin/terratin.h"

#include <math.h>
#include <stdbool.h>
#include <stdlib.h>

/* The TIN's triangles as 9 doubles each, (col, row, z) of the corners in
 * pixel space, as tt_eval_triangles takes them. The caller frees it. */
static inline double *tt_oracle_pixel_triangles(const tt_tin *tin)
{
  size_t nt = tt_tin_triangle_count(tin);
  double *xyz = malloc((nt ? nt : 1) * 9 * sizeof *xyz);
  if (!xyz)
    return NULL;
  for (size_t t = 0; t < nt; t++) {
    tt_triangle_info ti;
    tt_tin_triangle(tin, t, &ti);
    for (int k = 0; k < 3; k++) {
      tt_vertex_info vi;
      tt_tin_vertex(tin, (size_t)ti.v[k], &vi);
      xyz[9 * t + 3 * k] = vi.col;
      xyz[9 * t + 3 * k + 1] = vi.row;
      xyz[9 * t + 3 * k + 2] = vi.z;
    }
  }
  return xyz;
}

/* Exact, in integers: how many nodata samples lie strictly inside some
 * triangle (each counted once per triangle). */
static inline size_t tt_oracle_nodata_inside(const tt_grid *g,
                                             const tt_tin *tin)
{
  size_t bad = 0;
  for (size_t t = 0; t < tt_tin_triangle_count(tin); t++) {
    tt_triangle_info ti;
    tt_tin_triangle(tin, t, &ti);
    long long x[3], y[3];
    for (int k = 0; k < 3; k++) {
      tt_vertex_info vi;
      tt_tin_vertex(tin, (size_t)ti.v[k], &vi);
      x[k] = vi.col;
      y[k] = vi.row;
    }
    long long x0 = x[0], x1 = x[0], y0 = y[0], y1 = y[0];
    for (int k = 1; k < 3; k++) {
      x0 = x[k] < x0 ? x[k] : x0;
      x1 = x[k] > x1 ? x[k] : x1;
      y0 = y[k] < y0 ? y[k] : y0;
      y1 = y[k] > y1 ? y[k] : y1;
    }
    for (long long r = y0; r <= y1; r++)
      for (long long c = x0; c <= x1; c++) {
        int pos = 0, neg = 0;
        for (int k = 0; k < 3; k++) {
          int k1 = (k + 1) % 3;
          long long o =
              (x[k1] - x[k]) * (r - y[k]) - (y[k1] - y[k]) * (c - x[k]);
          pos += o > 0;
          neg += o < 0;
        }
        if ((pos == 3 || neg == 3) &&
            isnan(tt_grid_sample(g, (size_t)c, (size_t)r)))
          bad++;
      }
  }
  return bad;
}

/* The valid samples that no valid cell part holds (no cell around them has
 * three or more valid corners): exactly those a TIN confined to the valid
 * domain cannot cover. */
static inline size_t tt_oracle_uncarriable(const tt_grid *g)
{
  long long nx = (long long)tt_grid_width(g);
  long long ny = (long long)tt_grid_height(g);
  size_t n = 0;
#define TT_ORACLE_Z_(c, r) tt_grid_sample(g, (size_t)(c), (size_t)(r))
  for (long long r = 0; r < ny; r++)
    for (long long c = 0; c < nx; c++) {
      if (isnan(TT_ORACLE_Z_(c, r)))
        continue;
      bool carried = false;
      for (long long cy = r - 1; cy <= r && !carried; cy++)
        for (long long cx = c - 1; cx <= c && !carried; cx++) {
          if (cx < 0 || cy < 0 || cx + 1 >= nx || cy + 1 >= ny)
            continue;
          int nv = 0;
          for (int k = 0; k < 4; k++)
            nv += !isnan(TT_ORACLE_Z_(cx + (k & 1), cy + (k >> 1)));
          carried = nv >= 3;
        }
      n += !carried;
    }
#undef TT_ORACLE_Z_
  return n;
}

#endif /* TT_TIN_ORACLE_H */
