/*
 * src/gdal/raster/ -- the rasters: a band read into a grid, a grid written
 * as a GeoTIFF.
 *
 * raster_fill.c -- FILL_NODATA=K of tt_gdal_read_grid: the nodata voids of
 * at most K samples filled by GDAL's GDALFillNodata (inverse distance
 * weighting, as gdal_fillnodata -md D, no smoothing) before anything is
 * meshed.
 *
 * A void is a 4-connected patch of nodata samples. One of at most K
 * samples that does not touch the raster's edge is filled; larger patches
 * (a lake, the sea) and patches touching the edge (whose true size the
 * raster does not show) stay holes. Every 4-neighbour of a void outside it
 * is valid, so with D = the void's larger side + 1 every sample of it
 * reaches a valid sample along a row or a column: GDALFillNodata gives
 * each a value. Each void is filled on its own, on an in-memory copy of
 * its bounding box widened by D on every side (clipped to the raster), so
 * its values depend on that neighbourhood alone, not on where a tile's
 * window falls.
 *
 * A window (a tile) reads a margin of 2K + 2 samples around itself (a
 * second read of the same band, the same options): a void of at most K
 * samples that reaches into the window lies within K - 1 samples of it
 * and its copy within another K + 1, so the margin holds the same copy
 * the whole raster's read makes and the window's filled samples equal the
 * untiled run's. A void counts in the window that holds its first sample
 * in row-major order, so the windows' counts add up to the raster's.
 *
 * Filled heights are GDAL's doubles rounded to the nearest float
 * (relative 6e-8; they are made up) in a grid of floats and of doubles
 * alike: a grid of floats stays one rather than doubling its memory, and
 * a tile whose grid holds floats fills as the whole raster's of doubles.
 *
 * Memory: a byte per sample of the (margin) grid to mark visited nodata,
 * and 8 bytes a sample of the search's queue: every sample of a void of
 * at most K, the frontier only of a larger one (a sea); the copies are a
 * void's neighbourhood, a few times its size.
 */
#include "gdal/raster/raster_read.h"

#include <cpl_string.h>
#include <gdal_alg.h>

#include <math.h>
#include <strings.h>

/* The grid the voids are found in: the read's own (the whole raster), or
 * the window widened by the margin, read again. */
typedef struct fill_src {
  tt_grid *grid;        /* the samples, NaN = nodata */
  tt_grid *owned;       /* the margin read's, freed after */
  size_t x0, y0;        /* its first sample in the raster */
  size_t nx, ny;
} fill_src;

/* A void found: its samples (indices into the source grid) and box. */
typedef struct fill_void {
  size_t *cell;         /* every sample while it may be filled; then the
                           search's frontier only */
  size_t n, cap;
  size_t count;         /* its samples */
  size_t cmin, cmax, rmin, rmax;
  int edge;             /* touches the source's edge */
} fill_void;

static double src_height(const fill_src *f, size_t i)
{
  return tt_grid_sample(f->grid, i % f->nx, i / f->nx);
}

/* The window widened by 2K + 2 samples, read with the same options but
 * WINDOW (and without FILL_NODATA). */
static tt_status read_margin(raster_read *r, fill_src *f)
{
  const size_t m = 2 * r->opt.fill_max + 2;
  const size_t X = (size_t)r->xsize, Y = (size_t)r->ysize;
  f->x0 = r->wx > m ? r->wx - m : 0;
  f->y0 = r->wy > m ? r->wy - m : 0;
  size_t x1 = r->wx + r->nx + m < X ? r->wx + r->nx + m : X;
  size_t y1 = r->wy + r->ny + m < Y ? r->wy + r->ny + m : Y;
  f->nx = x1 - f->x0;
  f->ny = y1 - f->y0;
  char **ro = NULL;
  for (char **o = r->options; o && *o; o++)
    if (strncasecmp(*o, "FILL_NODATA=", 12) != 0 &&
        strncasecmp(*o, "WINDOW=", 7) != 0)
      ro = CSLAddString(ro, *o);
  ro = CSLSetNameValue(ro, "WINDOW", CPLSPrintf("%zu,%zu,%zu,%zu", f->x0,
                                                f->y0, f->nx, f->ny));
  tt_status s = tt_gdal_read_grid(r->ctx, r->band, ro, NULL, NULL,
                                  &f->owned, NULL);
  CSLDestroy(ro);
  f->grid = f->owned;
  return s;
}

static int push(fill_void *v, size_t i)
{
  if (v->n == v->cap) {
    size_t cap = v->cap ? 2 * v->cap : 64;
    size_t *c = realloc(v->cell, cap * sizeof *c);
    if (!c)
      return 0;
    v->cell = c;
    v->cap = cap;
  }
  v->cell[v->n++] = i;
  return 1;
}

/* The 4-connected nodata patch of seed, breadth first; seen marks it.
 * Once it has more than max samples it will not be filled: the samples
 * searched are dropped, so that a sea holds its frontier only. */
static int collect(const fill_src *f, unsigned char *seen, size_t seed,
                   size_t max, fill_void *v)
{
  v->n = 0;
  v->count = 1;
  v->edge = 0;
  v->cmin = v->rmin = SIZE_MAX;
  v->cmax = v->rmax = 0;
  seen[seed] = 1;
  if (!push(v, seed))
    return 0;
  for (size_t q = 0; q < v->n; q++) {
    if (v->count > max && q >= 4096 && q >= v->n - q) {
      memmove(v->cell, v->cell + q, (v->n - q) * sizeof *v->cell);
      v->n -= q;
      q = 0;
    }
    const size_t i = v->cell[q], c = i % f->nx, r = i / f->nx;
    v->cmin = c < v->cmin ? c : v->cmin;
    v->cmax = c > v->cmax ? c : v->cmax;
    v->rmin = r < v->rmin ? r : v->rmin;
    v->rmax = r > v->rmax ? r : v->rmax;
    if (c == 0 || r == 0 || c + 1 == f->nx || r + 1 == f->ny)
      v->edge = 1;
    size_t nb[4];
    int k = 0;
    if (c > 0) nb[k++] = i - 1;
    if (c + 1 < f->nx) nb[k++] = i + 1;
    if (r > 0) nb[k++] = i - f->nx;
    if (r + 1 < f->ny) nb[k++] = i + f->nx;
    for (int j = 0; j < k; j++)
      if (!seen[nb[j]] && isnan(src_height(f, nb[j]))) {
        seen[nb[j]] = 1;
        v->count++;
        if (!push(v, nb[j]))
          return 0;
      }
  }
  return 1;
}

/* Fills v's samples with GDALFillNodata on a copy of its box widened by
 * its search distance; out_z[q] is cell q's value (NaN if GDAL left it). */
static tt_status fill_one(raster_read *r, const fill_src *f,
                          const fill_void *v, double *out_z)
{
  const size_t w = v->cmax - v->cmin + 1, h = v->rmax - v->rmin + 1;
  const size_t d = (w > h ? w : h) + 1;
  const size_t c0 = v->cmin > d ? v->cmin - d : 0;
  const size_t r0 = v->rmin > d ? v->rmin - d : 0;
  const size_t c1 = v->cmax + d + 1 < f->nx ? v->cmax + d + 1 : f->nx;
  const size_t r1 = v->rmax + d + 1 < f->ny ? v->rmax + d + 1 : f->ny;
  const size_t cw = c1 - c0, ch = r1 - r0;
  double *z = malloc(cw * ch * sizeof *z);
  GByte *m = malloc(cw * ch);
  GDALDriverH mem = GDALGetDriverByName("MEM");
  GDALDatasetH zs = NULL, ms = NULL;
  tt_status s = TT_OK;
  if (!z || !m) {
    s = tt__error(r->ctx, TT_ERR_NOMEM, "out of memory");
    goto done;
  }
  for (size_t y = 0; y < ch; y++)
    for (size_t x = 0; x < cw; x++) {
      double hgt = src_height(f, (r0 + y) * f->nx + c0 + x);
      z[y * cw + x] = hgt; /* NaN stays where GDAL finds no source */
      m[y * cw + x] = isnan(hgt) ? 0 : 1;
    }
  zs = mem ? GDALCreate(mem, "", (int)cw, (int)ch, 1, GDT_Float64, NULL)
           : NULL;
  ms = mem ? GDALCreate(mem, "", (int)cw, (int)ch, 1, GDT_Byte, NULL) : NULL;
  if (!zs || !ms) {
    s = tt__error(r->ctx, TT_ERR_IO, "%s: FILL_NODATA: GDAL's MEM driver "
                  "cannot make the void's copy", r->path);
    goto done;
  }
  GDALRasterBandH zb = GDALGetRasterBand(zs, 1), mb = GDALGetRasterBand(ms, 1);
  char **fo = CSLSetNameValue(NULL, "TEMP_FILE_DRIVER", "MEM");
  CPLErr e = GDALRasterIO(zb, GF_Write, 0, 0, (int)cw, (int)ch, z, (int)cw,
                          (int)ch, GDT_Float64, 0, 0);
  if (e == CE_None)
    e = GDALRasterIO(mb, GF_Write, 0, 0, (int)cw, (int)ch, m, (int)cw,
                     (int)ch, GDT_Byte, 0, 0);
  if (e == CE_None)
    e = GDALFillNodata(zb, mb, (double)d, 0, 0, fo, NULL, NULL);
  if (e == CE_None)
    e = GDALRasterIO(zb, GF_Read, 0, 0, (int)cw, (int)ch, z, (int)cw,
                     (int)ch, GDT_Float64, 0, 0);
  CSLDestroy(fo);
  if (e != CE_None) {
    s = tt__error(r->ctx, TT_ERR_IO, "%s: FILL_NODATA: GDALFillNodata "
                  "failed: %s", r->path, CPLGetLastErrorMsg());
    goto done;
  }
  /* a sample GDAL found no source for stays NaN (a hole) */
  for (size_t q = 0; q < v->n; q++) {
    const size_t i = v->cell[q];
    const size_t k = (i / f->nx - r0) * cw + (i % f->nx - c0);
    out_z[q] = z[k];
  }
done:
  if (zs)
    GDALClose(zs);
  if (ms)
    GDALClose(ms);
  free(z);
  free(m);
  return s;
}

/* Stores height h, rounded to a float, at window sample (c, row) of the
 * read's grid. */
static void store(tt_grid *g, size_t c, size_t row, double h)
{
  float *z = tt_grid_heights(g);
  double *zd = tt_grid_heights_f64(g);
  const size_t i = row * tt_grid_width(g) + c;
  if (zd)
    zd[i] = (double)(float)h;
  else
    z[i] = (float)h;
}

/* Void v of the source, if it qualifies: its samples inside the window
 * filled, counted in r->fill. */
static tt_status fill_void_in_window(raster_read *r, const fill_src *f,
                                     fill_void *v, size_t seed, double **zbuf,
                                     size_t *zcap)
{
  const size_t wx0 = r->wx - f->x0, wy0 = r->wy - f->y0;
  const size_t wx1 = wx0 + r->nx, wy1 = wy0 + r->ny;
  if (v->count > r->opt.fill_max || v->edge)
    return TT_OK;
  if (v->cmax < wx0 || v->cmin >= wx1 || v->rmax < wy0 || v->rmin >= wy1)
    return TT_OK; /* outside the window (a margin's) */
  if (v->n > *zcap) {
    double *z = realloc(*zbuf, v->n * sizeof *z);
    if (!z)
      return tt__error(r->ctx, TT_ERR_NOMEM, "out of memory");
    *zbuf = z;
    *zcap = v->n;
  }
  tt_status s = fill_one(r, f, v, *zbuf);
  if (s != TT_OK)
    return s;
  /* the samples counted: FILL_OWNED's, else the window's (source
   * coordinates) */
  size_t ox0 = wx0, oy0 = wy0, ox1 = wx1, oy1 = wy1;
  if (r->opt.has_fill_own) {
    ox0 = r->opt.fill_own[0] - f->x0;
    oy0 = r->opt.fill_own[1] - f->y0;
    ox1 = ox0 + r->opt.fill_own[2];
    oy1 = oy0 + r->opt.fill_own[3];
  }
  size_t inside = 0, owned = 0;
  for (size_t q = 0; q < v->n; q++) {
    const size_t c = v->cell[q] % f->nx, row = v->cell[q] / f->nx;
    if (c < wx0 || c >= wx1 || row < wy0 || row >= wy1 || isnan((*zbuf)[q]))
      continue;
    store(r->grid, c - wx0, row - wy0, (*zbuf)[q]);
    inside++;
    owned += c >= ox0 && c < ox1 && row >= oy0 && row < oy1;
  }
  const size_t sc = seed % f->nx, sr = seed / f->nx;
  if (inside && sc >= ox0 && sc < ox1 && sr >= oy0 && sr < oy1)
    r->filled_voids++;
  r->filled_samples += owned;
  r->valid += inside;
  return TT_OK;
}

tt_status tt__raster_fill(raster_read *r)
{
  if (!r->opt.fill_max)
    return TT_OK;
  fill_src f;
  memset(&f, 0, sizeof f);
  tt_status s = TT_OK;
  if (r->opt.has_window) {
    s = read_margin(r, &f);
    if (s != TT_OK)
      return s;
  } else {
    f.grid = r->grid;
    f.nx = r->nx;
    f.ny = r->ny;
  }
  unsigned char *seen = calloc(f.nx * f.ny, 1);
  fill_void v;
  memset(&v, 0, sizeof v);
  double *zbuf = NULL;
  size_t zcap = 0;
  if (!seen)
    s = tt__error(r->ctx, TT_ERR_NOMEM, "out of memory");
  for (size_t i = 0; s == TT_OK && i < f.nx * f.ny; i++) {
    if (seen[i] || !isnan(src_height(&f, i)))
      continue;
    if (!collect(&f, seen, i, r->opt.fill_max, &v))
      s = tt__error(r->ctx, TT_ERR_NOMEM, "out of memory");
    else
      s = fill_void_in_window(r, &f, &v, i, &zbuf, &zcap);
  }
  free(seen);
  free(v.cell);
  free(zbuf);
  tt_grid_destroy(f.owned);
  return s;
}
