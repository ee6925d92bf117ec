/*
 * default_bound.c -- apps/simplify/: the bound used when none is given
 * (no -max_error, no budget): twice the DEM's mean step, the mean absolute
 * height difference between 4-neighbour valid samples, rounded to two
 * significant digits. The step is the height change the DEM resolves
 * from one sample to the next, so the bound keeps a TIN about as detailed
 * relative to the grid whatever the DEM's relief, resolution or unit; the
 * share of samples it keeps on the shared DEMs (bench/default_bound.py,
 * docs/cli.md "The default bound") is a few per cent on each of them,
 * where a fraction of the height range kept from 0.4 % to 87 %.
 *
 * A tiled run sums the step over its tiles: each tile adds the pairs whose
 * first sample it owns, so every pair of the DEM counts once and the bound
 * is the untiled run's.
 */
#include "simplify.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

/* One pair's difference added by Neumaier's compensated sum, so the order
 * of the pairs (rows, or tiles) changes no digit the bound keeps. */
static void add_diff(app_step *s, double d)
{
  double t = s->sum + d;
  if (fabs(s->sum) >= fabs(d))
    s->comp += (s->sum - t) + d;
  else
    s->comp += (d - t) + s->sum;
  s->sum = t;
  s->pairs++;
}

void tt__app_step_add(app_step *s, const tt_grid *g, size_t x0, size_t y0,
                      size_t x1, size_t y1, size_t xmax, size_t ymax)
{
  for (size_t y = y0; y <= y1; y++)
    for (size_t x = x0; x <= x1; x++) {
      double z = tt_grid_sample(g, x, y);
      if (isnan(z))
        continue;
      if (x + 1 <= xmax) {
        double e = tt_grid_sample(g, x + 1, y);
        if (!isnan(e))
          add_diff(s, fabs(e - z));
      }
      if (y + 1 <= ymax) {
        double n = tt_grid_sample(g, x, y + 1);
        if (!isnan(n))
          add_diff(s, fabs(n - z));
      }
    }
}

void tt__app_step_of_grid(app_step *s, const tt_grid *g)
{
  size_t w = tt_grid_width(g), h = tt_grid_height(g);
  if (w > 0 && h > 0)
    tt__app_step_add(s, g, 0, 0, w - 1, h - 1, w - 1, h - 1);
}

void tt__app_step_merge(app_step *into, const app_step *s)
{
  add_diff(into, s->sum);
  add_diff(into, s->comp);
  into->pairs += s->pairs - 2;
}

double tt__app_step_mean(const app_step *s)
{
  return s->pairs ? (s->sum + s->comp) / (double)s->pairs : 0.0;
}

double tt__app_default_bound_of(const app_step *s)
{
  double b = 2.0 * tt__app_step_mean(s);
  if (!(b > 0) || !isfinite(b))
    return 0.0;
  /* two significant digits, as the shortest decimal: a bound a person
   * reads and types again */
  char buf[32];
  snprintf(buf, sizeof buf, "%.2g", b);
  return strtod(buf, NULL);
}
