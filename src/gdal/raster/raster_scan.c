/*
 * src/gdal/raster/ -- the rasters: a band read into a grid, a grid written
 * as a GeoTIFF.
 *
 * raster_scan.c -- the scan of tt_gdal_read_grid (raster_read.h): the
 * band read a band of rows at a time, a block wide, by RasterIO into the
 * grid (raw floats) or into a buffer of doubles or 64-bit integers, with
 * its mask band unless SRCNODATA replaces it; each band of rows then
 * converted in place: validity, scale/offset and Z_FACTOR, finiteness and
 * the limits, the grid turned into doubles at the first height that is not
 * a float (see raster_read.c's opening comment). GDAL's block cache is
 * held to a few blocks for the scan unless the user set GDAL_CACHEMAX.
 *
 * Workload: one pass over the samples; memory beyond the grid: a band of
 * rows of mask bytes (at most TT_READ_MASK_BYTES) and of raw values (at
 * most TT_READ_STAGE_BYTES).
 */
#include "gdal/raster/raster_read.h"

#include <cpl_conv.h>
#include <cpl_error.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Largest mask buffer used at once; taller blocks are read in bands of rows
 * (the block itself then stays in GDAL's cache between the bands). */
#define TT_READ_MASK_BYTES ((size_t)1 << 20)
/* Largest buffer of raw values (doubles) used at once, likewise. */
#define TT_READ_STAGE_BYTES ((size_t)8 << 20)
/* The largest integer magnitude up to which doubles hold every integer. */
#define TT_READ_MAX_EXACT_INT ((uint64_t)1 << 53)
/* Block-cache limit during the read when the user has not chosen one. */
#define TT_READ_CACHE_BYTES ((GIntBig)2 << 20)

/* Converts a band of rows [r0, r0+nrows) of a grid of floats in place, for
 * bands whose raw values are floats and with no scale, offset or factor
 * (the heights are the raw values, so they stay floats): mask or
 * SRCNODATA, finiteness. Every other case goes through convert_any().
 * mask (nx*nrows bytes, 0 = invalid) may be NULL. */
static tt_status convert_rows(tt_context *ctx, const char *path, float *z,
                              size_t nx, size_t r0, size_t nrows,
                              const unsigned char *mask,
                              const read_options *opt, size_t *valid_count)
{
  for (size_t r = 0; r < nrows; r++) {
    float *row = z + (r0 + r) * nx;
    const unsigned char *mrow = mask ? mask + r * nx : NULL;
    for (size_t c = 0; c < nx; c++) {
      float raw = row[c];
      int ok;
      if (opt->has_srcnodata)
        ok = opt->srcnodata_is_nan ? !isnan(raw) : raw != opt->srcnodata;
      else
        ok = mrow ? mrow[c] != 0 : 1;
      if (!ok) {
        row[c] = NAN;
        continue;
      }
      if (!isfinite(raw)) {
        if (isnan(raw) && opt->has_srcnodata)
          return tt__error(ctx, TT_ERR_DATA, "%s: height at row %zu, column "
                           "%zu is NaN, which SRCNODATA %g does not cover "
                           "(use -srcnodata nan)", path, r0 + r, c,
                           (double)opt->srcnodata);
        if (isnan(raw))
          return tt__error(ctx, TT_ERR_DATA, "%s: height at row %zu, column "
                           "%zu is NaN but not marked nodata (use "
                           "-srcnodata nan)", path, r0 + r, c);
        return tt__error(ctx, TT_ERR_DATA, "%s: height at row %zu, column "
                         "%zu is infinite but not marked nodata", path,
                         r0 + r, c);
      }
      (*valid_count)++;
    }
  }
  return TT_OK;
}

/* Turns the grid into doubles for the height h at row r, column c, which a
 * float cannot hold; checks the memory of both arrays against MAX_MEMORY
 * first. */
static tt_status widen_grid(tt_context *ctx, const char *path, tt_grid *g,
                            const read_options *opt, size_t r, size_t c,
                            double h)
{
  size_t n = g->nx * g->ny;
  char need_s[32], max_s[32];
  size_t need = n <= SIZE_MAX / 12 ? n * 12 : SIZE_MAX;
  if (need > opt->max_memory)
    return tt__error(ctx, TT_ERR_LIMIT, "%s: the height at row %zu, column "
                     "%zu (%.17g) is not exactly a float, so the %zu x %zu "
                     "heights are kept as doubles, which needs %s while they "
                     "are converted, more than %s (%s)", path, r, c, h,
                     g->nx, g->ny, tt__format_bytes(need_s, sizeof need_s, need),
                     opt->max_memory_default ? "3/4 of this machine's "
                                               "physical memory"
                                             : "MAX_MEMORY",
                     tt__format_bytes(max_s, sizeof max_s, opt->max_memory));
  if (!tt__grid_widen(g))
    return tt__error(ctx, TT_ERR_NOMEM, "%s: out of memory: the height at "
                     "row %zu, column %zu (%.17g) is not exactly a float, "
                     "and the %zu x %zu heights as doubles need %s", path, r,
                     c, h, g->nx, g->ny,
                     tt__format_bytes(need_s, sizeof need_s, n * 8));
  return TT_OK;
}

/* Whether a 64-bit integer raw value (sign and magnitude) equals SRCNODATA
 * exactly: compared as integers when SRCNODATA is an integer literal (a
 * double near 2^63 would match its neighbours too), else as doubles. */
static int int_is_srcnodata(const read_options *opt, int neg, uint64_t mag)
{
  if (opt->srcnodata_is_nan)
    return 0;
  if (opt->srcnodata_is_int)
    return neg == opt->srcnodata_neg && mag == opt->srcnodata_mag;
  return (neg ? -(double)mag : (double)mag) == opt->srcnodata_d;
}

/* Converts a band of rows [r0, r0+nrows) into the grid, in every case but
 * convert_rows()'s: raw values from raw (see raw_rows), then mask or
 * SRCNODATA, scale/offset and Z_FACTOR in doubles, finiteness and the
 * magnitude limits; each height is stored as a float while it is one, and
 * the first that is not turns the grid into doubles. */
static tt_status convert_any(tt_context *ctx, const char *path, tt_grid *g,
                             const raw_rows *raw, size_t r0, size_t nrows,
                             const unsigned char *mask,
                             const read_options *opt, double scale,
                             double offset, size_t *valid_count)
{
  const size_t nx = g->nx;
  const double zf = opt->z_factor;
  const int identity = scale == 1.0 && offset == 0.0 && zf == 1.0;
  for (size_t r = 0; r < nrows; r++) {
    const unsigned char *mrow = mask ? mask + r * nx : NULL;
    for (size_t c = 0; c < nx; c++) {
      const size_t i = (r0 + r) * nx + c, k = r * nx + c;
      double rawd;
      int ok;
      if (raw->source == RAW_I64 || raw->source == RAW_U64) {
        uint64_t mag;
        int neg = 0;
        if (raw->source == RAW_I64) {
          int64_t v = ((const int64_t *)raw->buf)[k];
          neg = v < 0;
          mag = neg ? (uint64_t)0 - (uint64_t)v : (uint64_t)v;
        } else {
          mag = ((const uint64_t *)raw->buf)[k];
        }
        ok = opt->has_srcnodata ? !int_is_srcnodata(opt, neg, mag)
                                : (mrow ? mrow[c] != 0 : 1);
        if (ok && mag > TT_READ_MAX_EXACT_INT)
          return tt__error(ctx, TT_ERR_DATA, "%s: height at row %zu, column "
                           "%zu is %s%llu, beyond 2^53, where doubles no "
                           "longer hold every integer: %s band values must "
                           "lie within +-2^53", path, r0 + r, c,
                           neg ? "-" : "", (unsigned long long)mag,
                           raw->source == RAW_I64 ? "Int64" : "UInt64");
        rawd = neg ? -(double)mag : (double)mag; /* exact: <= 2^53 */
      } else {
        rawd = raw->source == RAW_F64 ? ((const double *)raw->buf)[k]
                                      : tt__grid_z(g, i);
        if (!opt->has_srcnodata)
          ok = mrow ? mrow[c] != 0 : 1;
        else if (opt->srcnodata_is_nan)
          ok = !isnan(rawd);
        else if (raw->source == RAW_IN_GRID)
          ok = (float)rawd != opt->srcnodata; /* raw floats, as before */
        else
          ok = rawd != opt->srcnodata_d;
      }
      if (!ok) {
        if (g->zd)
          g->zd[i] = NAN;
        else
          g->z[i] = NAN;
        continue;
      }
      /* Scale and offset first, then Z_FACTOR, as documented. */
      double h = identity ? rawd : (rawd * scale + offset) * zf;
      if (!(fabs(h) <= TT_MAX_HEIGHT)) {
        if (isnan(rawd) && opt->has_srcnodata)
          return tt__error(ctx, TT_ERR_DATA, "%s: height at row %zu, column "
                           "%zu is NaN, which SRCNODATA %g does not cover "
                           "(use -srcnodata nan)", path, r0 + r, c,
                           opt->srcnodata_d);
        if (isnan(rawd))
          return tt__error(ctx, TT_ERR_DATA, "%s: height at row %zu, column "
                           "%zu is NaN but not marked nodata (use "
                           "-srcnodata nan)", path, r0 + r, c);
        if (isinf(rawd))
          return tt__error(ctx, TT_ERR_DATA, "%s: height at row %zu, column "
                           "%zu is infinite but not marked nodata", path,
                           r0 + r, c);
        if (identity)
          return tt__error(ctx, TT_ERR_DATA, "%s: height at row %zu, column "
                           "%zu is %g, beyond the +-%g terratin measures",
                           path, r0 + r, c, h, TT_MAX_HEIGHT);
        return tt__error(ctx, TT_ERR_DATA, "%s: height at row %zu, column "
                         "%zu is %g after scale %g, offset %g and Z_FACTOR "
                         "%g: beyond the +-%g terratin measures", path,
                         r0 + r, c, h, scale, offset, zf, TT_MAX_HEIGHT);
      }
      if (!g->zd) {
        float f = (float)h;
        if ((double)f == h) {
          g->z[i] = f;
          (*valid_count)++;
          continue;
        }
        tt_status s = widen_grid(ctx, path, g, opt, r0 + r, c, h);
        if (s != TT_OK)
          return s;
      }
      g->zd[i] = h;
      (*valid_count)++;
    }
  }
  return TT_OK;
}

/* The scan's plan: the mask band (none under SRCNODATA, nor when every
 * sample is valid), the band's block size, the rows read at once, the
 * buffers of mask bytes and raw values. */
static tt_status plan_scan(raster_read *rd)
{
  const size_t nx = rd->nx;
  /* Validity: SRCNODATA overrides the mask; GMF_ALL_VALID needs none. */
  if (!rd->opt.has_srcnodata &&
      !(GDALGetMaskFlags(rd->band) & GMF_ALL_VALID))
    rd->mask_band = GDALGetMaskBand(rd->band);

  int bw = 0, bh = 0;
  GDALGetBlockSize(rd->band, &bw, &bh);
  if (bw <= 0 || bw > rd->xsize)
    bw = rd->xsize;
  if (bh <= 0 || bh > rd->ysize)
    bh = rd->ysize;
  rd->bw = bw;
  rd->bh = bh;
  /* Rows per step: a block's height, fewer if the mask buffer or the raw
   * buffer of a row of blocks would be large (single-strip files). */
  size_t step = (size_t)bh;
  if (rd->mask_band && step * nx > TT_READ_MASK_BYTES)
    step = TT_READ_MASK_BYTES / nx > 0 ? TT_READ_MASK_BYTES / nx : 1;
  if (rd->raw.source != RAW_IN_GRID && step * nx * 8 > TT_READ_STAGE_BYTES)
    step = TT_READ_STAGE_BYTES / (nx * 8) > 0 ? TT_READ_STAGE_BYTES / (nx * 8)
                                              : 1;
  rd->step = step;
  if (rd->mask_band) {
    rd->mask = malloc(step * nx);
    if (!rd->mask)
      return tt__error(rd->ctx, TT_ERR_NOMEM, "out of memory for a mask "
                       "buffer");
  }
  if (rd->raw.source != RAW_IN_GRID) {
    rd->stage = malloc(step * nx * 8); /* doubles or 64-bit integers */
    if (!rd->stage)
      return tt__error(rd->ctx, TT_ERR_NOMEM, "out of memory for a buffer "
                       "of %zu rows", step);
    rd->raw.buf = rd->stage;
  }
  return TT_OK;
}

/* Holds GDAL's block cache to a few blocks unless the user chose a size
 * (a window, a tile of a tiled run, leaves it alone);
 * tt__raster_scan_end gives it back. */
static void hold_cache(raster_read *rd)
{
  if (rd->opt.has_window || CPLGetConfigOption("GDAL_CACHEMAX", NULL))
    return;
  GIntBig block_bytes = (GIntBig)rd->bw * rd->bh *
                        (GIntBig)(GDALGetDataTypeSizeBytes(rd->dtype) + 1);
  GIntBig want = TT_READ_CACHE_BYTES;
  if (want < 3 * block_bytes)
    want = 3 * block_bytes;
  rd->old_cache_max = GDALGetCacheMax64();
  if (want < rd->old_cache_max) {
    GDALSetCacheMax64(want);
    rd->cache_changed = 1;
  }
}

/* The band of rows [r0, r0 + nrows) read a block wide: the raw values into
 * the buffer, or into the grid as it now is (floats or doubles), and the
 * mask bytes beside. */
static tt_status read_rows(raster_read *rd, size_t r0, size_t nrows)
{
  const size_t nx = rd->nx, bw = (size_t)rd->bw;
  tt_grid *grid = rd->grid;
  for (size_t c0 = 0; c0 < nx; c0 += bw) {
    const size_t ncols = nx - c0 < bw ? nx - c0 : bw;
    void *dst = NULL;
    GDALDataType type = GDT_Float32;
    size_t es = sizeof(float);
    if (rd->stage) {
      dst = (char *)rd->stage + c0 * 8;
      type = rd->stage_type;
      es = 8;
    } else if (grid->zd) {
      dst = grid->zd + r0 * nx + c0;
      type = GDT_Float64;
      es = sizeof(double);
    } else {
      dst = grid->z + r0 * nx + c0;
    }
    CPLErrorReset();
    CPLErr err = GDALRasterIOEx(rd->band, GF_Read, (int)(c0 + rd->wx),
                                (int)(r0 + rd->wy), (int)ncols, (int)nrows,
                                dst, (int)ncols, (int)nrows, type,
                                (GSpacing)es, (GSpacing)(nx * es), NULL);
    if (err == CE_None && rd->mask_band)
      err = GDALRasterIOEx(rd->mask_band, GF_Read, (int)(c0 + rd->wx),
                           (int)(r0 + rd->wy), (int)ncols, (int)nrows,
                           rd->mask + c0, (int)ncols, (int)nrows, GDT_Byte,
                           1, (GSpacing)nx, NULL);
    if (err != CE_None)
      return tt__error(rd->ctx, TT_ERR_IO, "%s: reading band %d at row %zu, "
                       "column %zu failed: %s", rd->path,
                       GDALGetBandNumber(rd->band), r0, c0,
                       CPLGetLastErrorMsg());
  }
  return TT_OK;
}

tt_status tt__raster_scan(raster_read *rd)
{
  tt_context *ctx = rd->ctx;
  const size_t nx = rd->nx, ny = rd->ny;
  tt_status s = plan_scan(rd);
  if (s != TT_OK)
    return s;
  const int identity = rd->scale == 1.0 && rd->offset == 0.0 &&
                       rd->conv.z_factor == 1.0;
  hold_cache(rd);

  rd->valid = 0;
  if (!tt__raster_progress(rd, 0.0, "reading"))
    return tt__error(ctx, TT_ERR_INTERRUPTED, "%s: read interrupted",
                     rd->path);
  for (size_t r0 = 0; r0 < ny; r0 += rd->step) {
    const size_t nrows = ny - r0 < rd->step ? ny - r0 : rd->step;
    s = read_rows(rd, r0, nrows);
    if (s != TT_OK)
      return s;
    if (rd->raw.source == RAW_IN_GRID && identity && !rd->grid->zd)
      s = convert_rows(ctx, rd->path, rd->grid->z, nx, r0, nrows, rd->mask,
                       &rd->conv, &rd->valid);
    else
      s = convert_any(ctx, rd->path, rd->grid, &rd->raw, r0, nrows, rd->mask,
                      &rd->conv, rd->scale, rd->offset, &rd->valid);
    if (s != TT_OK)
      return s;
    if (!tt__raster_progress(rd, (double)(r0 + nrows) / (double)ny,
                             "reading"))
      return tt__error(ctx, TT_ERR_INTERRUPTED, "%s: read interrupted at "
                       "row %zu of %zu", rd->path, r0 + nrows, ny);
  }
  if (rd->valid == 0 && !rd->opt.has_window)
    return tt__error(ctx, TT_ERR_DATA, "%s: all nodata: band %d has no "
                     "valid sample", rd->path, GDALGetBandNumber(rd->band));
  return TT_OK;
}

void tt__raster_scan_end(raster_read *rd)
{
  if (rd->cache_changed) {
    /* Drop this read's blocks, then give the user their cache size back. */
    GDALFlushRasterCache(rd->band);
    if (rd->mask_band)
      GDALFlushRasterCache(rd->mask_band);
    GDALSetCacheMax64(rd->old_cache_max);
    rd->cache_changed = 0;
  }
  free(rd->mask);
  free(rd->stage);
  rd->mask = NULL;
  rd->stage = NULL;
  rd->raw.buf = NULL;
}
