/*
 * tiled_tiles.c -- apps/simplify/, the simplify command: what its tiled
 * path (tiled.c, tiled_workers.c) asks of one tile beside running it: the
 * memory the tiles in flight take (for -max_memory and the report),
 * whether a DEM's tiles carry ground points, and, for a budget's curve
 * pass, a tile's curve points and the valid samples it counts.
 */
#include "simplify.h"
#include "gdal/georef/georef.h" /* tt__georef_is_web_mercator */

#include <math.h>
#include <ogr_srs_api.h>

int tt__app_ground_points(GDALRasterBandH band)
{
  GDALDatasetH ds = GDALGetBandDataset(band);
  OGRSpatialReferenceH srs = ds ? GDALGetSpatialRef(ds) : NULL;
  return srs && (OSRIsGeographic(srs) || tt__georef_is_web_mercator(srs));
}

size_t tt__app_tile_bytes(size_t N, size_t width, size_t height,
                          int threads, int ground)
{
  /* per tile in flight: the window and the tile's copy as doubles at
   * worst (16 bytes a sample), the scans' bounds, and refinement's state
   * and the piece for a vertex every 4 samples at most (~60 bytes a
   * vertex): about 32 bytes a sample; with ground points (a geographic
   * or Web Mercator DEM) 16 bytes a sample more in the window and in the
   * tile's copy: 64; up to 2 x threads tiles */
  size_t w = (N < width ? N : width) + 3, h = (N < height ? N : height) + 3;
  size_t tiles = ((width - 2) / N + 1) * ((height - 2) / N + 1);
  size_t inflight = 2 * (size_t)(threads > 0 ? threads : 1);
  return (inflight < tiles ? inflight : tiles) * (ground ? 64 : 32) * w * h;
}

void tt__app_curve_point(void *arg, size_t vertices, double max_error)
{
  app_curve *c = arg;
  if (!c->failed && !tt__app_curve_add(c, vertices, max_error))
    c->failed = true;
}

/* The valid samples a tile counts (its window less the margins and its
 * shared right column and bottom row, as tt_tile_run's pieces). */
size_t tt__app_tile_owned_valid(const tt_grid *win, const tt_tile *t)
{
  size_t c0, r0, w, h, n = 0;
  tt_tile_window(t, &c0, &r0, &w, &h);
  size_t x1 = t->col1 - (t->col1 + 1 < t->dem_width);
  size_t y1 = t->row1 - (t->row1 + 1 < t->dem_height);
  for (size_t y = t->row0; y <= y1; y++)
    for (size_t x = t->col0; x <= x1; x++)
      n += !isnan(tt_grid_sample(win, x - c0, y - r0));
  return n;
}

