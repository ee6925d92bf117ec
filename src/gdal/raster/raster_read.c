/*
 * src/gdal/raster/ -- the rasters: a band read into a grid, a grid written
 * as a GeoTIFF.
 *
 * raster_read.c -- reading one raster band into a tt_grid. Here the read's
 * recipe (tt_gdal_read_grid: options, the band's type and size checked,
 * georeferencing, the grid made, its frame, the scan, the info), the
 * options and the band's checks; the georeferencing and the ground frame
 * are raster_georef.c's, the scan of the blocks raster_scan.c's, and
 * raster_read.h holds the state of a read they share.
 *
 * The band is read block by block in its natural block size, one row of
 * blocks at a time. Validity comes from GDAL's mask band (nodata value, NaN
 * nodata, alpha, .msk) unless SRCNODATA overrides it; masked samples
 * become NaN. Then scale/offset and Z_FACTOR are applied in doubles, and
 * every valid height must be finite and within TT_MAX_HEIGHT.
 *
 * Precision: no height is rounded. The grid holds floats while every valid
 * height met is exactly a float, and turns into doubles (tt__grid_widen)
 * at the first that is not. Bands whose raw values are floats (Byte, Int8,
 * Int16, UInt16, Float32) are read by RasterIO straight into the grid's
 * own array, with no temporary, and with no scale, offset or factor stay
 * floats: the common case reads as it always did. The others (Int32,
 * UInt32, Float64, Int64, UInt64) go through a buffer of one band of rows
 * as doubles (64-bit integers as themselves, refused beyond 2^53, where
 * doubles no longer hold every integer); an Int32 DEM of heights in
 * centimetres, all below 2^24, still ends as floats.
 *
 * Memory: the grid (4 bytes per sample, 8 once it holds doubles; 12 for
 * the moment of widening, checked against MAX_MEMORY then) plus one band
 * of rows of mask bytes and, for the buffered types, of doubles, plus
 * GDAL's block cache, which is held to a few blocks for the duration of the
 * read unless the user set GDAL_CACHEMAX (the cache limit is process-wide
 * state of GDAL's: it is restored afterwards). The heights' memory as
 * floats is checked against MAX_MEMORY before anything is allocated.
 */
#include "gdal/raster/raster_read.h"

#include <cpl_conv.h>
#include <cpl_string.h>

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

void tt_raster_info_destroy(tt_raster_info *info)
{
  if (!info)
    return;
  free(info->path);
  free(info->driver);
  free(info->crs_wkt);
  free(info->crs_name);
  free(info->z_unit);
  free(info->z_unit_declared);
  free(info->z_unit_source);
  free(info->area_or_point);
  free(info->datatype);
  free(info->frame_name);
  free(info);
}

/* The smallest of 3/4 of physical memory, the cgroup's room and the
 * address-space room (tt_memory_limit); SIZE_MAX when the system cannot
 * say. */
static size_t default_max_memory(const char **out_source)
{
  return tt_memory_limit(out_source);
}

/* Parses a whole string as a finite double. */
static int parse_double(const char *s, double *out)
{
  char *end = NULL;
  errno = 0;
  double v = strtod(s, &end);
  if (end == s || (errno == ERANGE && fabs(v) > 1.0)) /* subnormals pass */
    return 0;
  while (*end == ' ')
    end++;
  if (*end != '\0' || !isfinite(v))
    return 0;
  *out = v;
  return 1;
}

/* Parses a whole string as an integer of magnitude below 2^64 (sign and
 * magnitude, so that every Int64 and UInt64 value is one). */
static int parse_integer(const char *s, int *out_neg, uint64_t *out_mag)
{
  while (*s == ' ')
    s++;
  int neg = *s == '-';
  if (*s == '-' || *s == '+')
    s++;
  if (*s < '0' || *s > '9')
    return 0;
  char *end = NULL;
  errno = 0;
  unsigned long long m = strtoull(s, &end, 10);
  if (errno == ERANGE)
    return 0;
  while (*end == ' ')
    end++;
  if (*end != '\0')
    return 0;
  *out_neg = neg && m != 0;
  *out_mag = (uint64_t)m;
  return 1;
}

static tt_status parse_options(tt_context *ctx, char **options,
                               read_options *opt)
{
  opt->z_factor = 1.0;
  opt->has_z_factor = 0;
  opt->z_unit_m = 0;
  opt->z_unit_auto = 0;
  opt->src_z_unit = NULL;
  opt->work_srs = NULL;
  opt->has_srcnodata = 0;
  opt->srcnodata_is_nan = 0;
  opt->srcnodata = 0.0f;
  opt->srcnodata_d = 0.0;
  opt->srcnodata_is_int = 0;
  opt->srcnodata_neg = 0;
  opt->srcnodata_mag = 0;
  opt->max_memory = 0;
  opt->has_window = 0;
  opt->source_name = NULL;
  opt->source_driver = NULL;
  int has_max_memory = 0;
  for (char **o = options; o && *o; o++) {
    char *key = NULL;
    const char *value = CPLParseNameValue(*o, &key);
    if (!key || !value) {
      CPLFree(key);
      return tt__error(ctx, TT_ERR_ARG, "read option \"%s\" is not "
                       "NAME=VALUE", *o);
    }
    tt_status s = TT_OK;
    double v = 0;
    if (strcasecmp(key, "Z_FACTOR") == 0) {
      if (!parse_double(value, &v) || v == 0)
        s = tt__error(ctx, TT_ERR_ARG, "Z_FACTOR must be a non-zero number, "
                      "got \"%s\"", value);
      else {
        opt->z_factor = v;
        opt->has_z_factor = 1;
      }
    } else if (strcasecmp(key, "Z_UNIT") == 0) {
      if (strcasecmp(value, "m") == 0)
        opt->z_unit_m = 1;
      else if (strcasecmp(value, "auto") == 0)
        opt->z_unit_auto = 1;
      else
        s = tt__error(ctx, TT_ERR_ARG, "Z_UNIT must be m (heights in ft or "
                      "us-ft converted to metres) or auto (the same when "
                      "the CRS is in metres or geographic), got \"%s\"",
                      value);
    } else if (strcasecmp(key, "SRC_Z_UNIT") == 0) {
      static const char *const units[] = {"m", "ft", "us-ft"};
      opt->src_z_unit = NULL;
      for (int k = 0; k < 3; k++)
        if (strcasecmp(value, units[k]) == 0 ||
            (k == 2 && strcasecmp(value, "us_ft") == 0))
          opt->src_z_unit = units[k];
      if (!opt->src_z_unit)
        s = tt__error(ctx, TT_ERR_ARG, "SRC_Z_UNIT must be m, ft or us-ft "
                      "(the unit the heights are in), got \"%s\"", value);
    } else if (strcasecmp(key, "WORK_SRS") == 0) {
      if (!*value)
        s = tt__error(ctx, TT_ERR_ARG, "WORK_SRS needs a CRS");
      else
        opt->work_srs = value;
    } else if (strcasecmp(key, "SRCNODATA") == 0) {
      opt->has_srcnodata = 1;
      if (strcasecmp(value, "nan") == 0) {
        opt->srcnodata_is_nan = 1;
      } else if (!parse_double(value, &v)) {
        s = tt__error(ctx, TT_ERR_ARG, "SRCNODATA must be a number or nan, "
                      "got \"%s\"", value);
      } else {
        opt->srcnodata = (float)v;
        opt->srcnodata_d = v;
        opt->srcnodata_is_int = parse_integer(value, &opt->srcnodata_neg,
                                              &opt->srcnodata_mag);
      }
    } else if (strcasecmp(key, "MAX_MEMORY") == 0) {
      if (!parse_double(value, &v) || v <= 0)
        s = tt__error(ctx, TT_ERR_ARG, "MAX_MEMORY must be a positive number "
                      "of bytes, got \"%s\"", value);
      else {
        opt->max_memory = v >= (double)SIZE_MAX ? SIZE_MAX : (size_t)v;
        has_max_memory = 1;
      }
    } else if (strcasecmp(key, "WINDOW") == 0) {
      unsigned long long w[4];
      char tail;
      if (sscanf(value, "%llu,%llu,%llu,%llu%c", &w[0], &w[1], &w[2], &w[3],
                 &tail) != 4 || w[2] < 2 || w[3] < 2)
        s = tt__error(ctx, TT_ERR_ARG, "WINDOW must be col,row,width,height "
                      "(width and height 2 or more), got \"%s\"", value);
      else {
        for (int k = 0; k < 4; k++)
          opt->win[k] = (size_t)w[k];
        opt->has_window = 1;
      }
    } else if (strcasecmp(key, "SOURCE_NAME") == 0) {
      opt->source_name = value;
    } else if (strcasecmp(key, "SOURCE_DRIVER") == 0) {
      opt->source_driver = value;
    } else {
      s = tt__error(ctx, TT_ERR_ARG, "unknown read option \"%s\" (known: "
                    "Z_FACTOR, Z_UNIT, SRCNODATA, MAX_MEMORY, WORK_SRS, "
                    "WINDOW, SOURCE_NAME, SOURCE_DRIVER)", key);
    }
    CPLFree(key);
    if (s != TT_OK)
      return s;
  }
  opt->max_memory_default = !has_max_memory;
  if (!has_max_memory)
    opt->max_memory = default_max_memory(&opt->max_memory_source);
  return TT_OK;
}

/* The band's type: refuses complex numbers, chooses where the raw values
 * are read (raw floats straight into the grid, the others through the
 * buffer: see the top of the file), and refuses a SRCNODATA the type
 * cannot hold. */
static tt_status check_band_type(raster_read *r)
{
  const GDALDataType dtype = GDALGetRasterDataType(r->band);
  const read_options *opt = &r->opt;
  r->dtype = dtype;
  if (GDALDataTypeIsComplex(dtype))
    return tt__error(r->ctx, TT_ERR_FORMAT, "%s: band %d holds complex "
                     "numbers (%s), not heights", r->path,
                     GDALGetBandNumber(r->band), GDALGetDataTypeName(dtype));
  r->raw.source = RAW_F64;
  r->raw.buf = NULL;
  r->stage_type = GDT_Float64;
  if (dtype == GDT_Byte || dtype == GDT_Int16 || dtype == GDT_UInt16 ||
#if GDAL_VERSION_NUM >= GDAL_COMPUTE_VERSION(3, 7, 0)
      dtype == GDT_Int8 ||
#endif
      dtype == GDT_Float32) {
    r->raw.source = RAW_IN_GRID;
#if GDAL_VERSION_NUM >= GDAL_COMPUTE_VERSION(3, 5, 0)
  } else if (dtype == GDT_Int64) {
    r->raw.source = RAW_I64;
    r->stage_type = GDT_Int64;
  } else if (dtype == GDT_UInt64) {
    r->raw.source = RAW_U64;
    r->stage_type = GDT_UInt64;
#endif
  }

  /* A SRCNODATA the band's type cannot hold can never match a sample:
   * refuse it rather than mask nothing (1e39 in a Float32 band, -1 in a
   * Byte band, 0.5 in an Int16 band, nan in an integer band). */
  if (!opt->has_srcnodata)
    return TT_OK;
  int clamped = 0, rounded = 0;
  if (opt->srcnodata_is_nan) {
    clamped = !GDALDataTypeIsFloating(dtype);
  } else if ((dtype == GDT_Int64 || dtype == GDT_UInt64) &&
             opt->srcnodata_is_int) {
    /* doubles cannot say near 2^63, 2^64: the integer literal, exactly */
    const uint64_t top = (uint64_t)1 << 63;
    clamped = opt->srcnodata_mag &&
              (dtype == GDT_UInt64 ? opt->srcnodata_neg
               : opt->srcnodata_neg ? opt->srcnodata_mag > top
                                    : opt->srcnodata_mag >= top);
  } else {
    GDALAdjustValueToDataType(dtype, opt->srcnodata_d, &clamped, &rounded);
  }
  if (clamped || rounded)
    return tt__error(r->ctx, TT_ERR_ARG, "%s: SRCNODATA (-srcnodata) %.15g "
                     "cannot occur in band %d, whose type %s %s", r->path,
                     opt->srcnodata_is_nan ? NAN : opt->srcnodata_d,
                     GDALGetBandNumber(r->band), GDALGetDataTypeName(dtype),
                     clamped ? "cannot hold it" : "holds whole numbers only");
  return TT_OK;
}

/* The samples to read: the raster's size (2 x 2 at least), the window's
 * place in it, and the heights' memory as floats against MAX_MEMORY. */
static tt_status check_band_size(raster_read *r)
{
  const read_options *opt = &r->opt;
  r->xsize = GDALGetRasterBandXSize(r->band);
  r->ysize = GDALGetRasterBandYSize(r->band);
  const int xsize = r->xsize, ysize = r->ysize;
  if (xsize < 2 || ysize < 2)
    return tt__error(r->ctx, TT_ERR_DATA, "%s: raster is %d x %d pixels: at "
                     "least 2 x 2 are needed to make a triangle", r->path,
                     xsize, ysize);
  /* A window (a tile): its samples only; the ground frame (and, for a
   * geographic or Web Mercator raster, the ground points) are still the
   * whole raster's, so that every tile measures alike. */
  r->wx = opt->has_window ? opt->win[0] : 0;
  r->wy = opt->has_window ? opt->win[1] : 0;
  if (opt->has_window && (opt->win[0] + opt->win[2] > (size_t)xsize ||
                          opt->win[1] + opt->win[3] > (size_t)ysize))
    return tt__error(r->ctx, TT_ERR_ARG, "%s: window of %zu x %zu at column "
                     "%zu, row %zu passes the raster's %d x %d", r->path,
                     opt->win[2], opt->win[3], opt->win[0], opt->win[1],
                     xsize, ysize);
  const size_t nx = opt->has_window ? opt->win[2] : (size_t)xsize;
  const size_t ny = opt->has_window ? opt->win[3] : (size_t)ysize;
  r->nx = nx;
  r->ny = ny;
  if (nx > SIZE_MAX / sizeof(float) / ny)
    return tt__error(r->ctx, TT_ERR_LIMIT, "%s: %zu x %zu heights do not "
                     "fit in this machine's address space", r->path, nx, ny);
  const size_t need = nx * ny * sizeof(float);
  if (need > opt->max_memory) {
    char need_s[32], max_s[32];
    return tt__error(r->ctx, TT_ERR_LIMIT, "%s: the %zu x %zu heights need "
                     "%s, more than %s (%s); refused before reading", r->path,
                     nx, ny, tt__format_bytes(need_s, sizeof need_s, need),
                     opt->max_memory_default ? opt->max_memory_source
                                             : "MAX_MEMORY",
                     tt__format_bytes(max_s, sizeof max_s, opt->max_memory));
  }
  return TT_OK;
}

/* The grid of the samples read, with the geotransform of its first
 * sample (the window's). */
static tt_status make_grid(raster_read *r)
{
  tt_status s = tt_grid_create(r->ctx, r->nx, r->ny, &r->grid);
  if (s != TT_OK)
    return tt__raster_with_path(r->ctx, s, r->path);
  const double *gt = r->gt;
  double wgt[6];
  memcpy(wgt, gt, sizeof wgt);
  wgt[0] += (double)r->wx * gt[1] + (double)r->wy * gt[2];
  wgt[3] += (double)r->wx * gt[4] + (double)r->wy * gt[5];
  s = tt_grid_set_geotransform(r->ctx, r->grid, wgt);
  if (s != TT_OK)
    return tt__raster_with_path(r->ctx, s, r->path);
  return TT_OK;
}

/* What the read found, into r->info (the CRS is there already). */
static tt_status fill_info(raster_read *r)
{
  tt_raster_info *info = r->info;
  GDALDatasetH ds = r->ds;
  info->path = tt__raster_dup_str(r->path);
  GDALDriverH drv = ds ? GDALGetDatasetDriver(ds) : NULL;
  info->driver = tt__raster_dup_str(
      r->opt.source_driver ? r->opt.source_driver
      : drv               ? GDALGetDriverShortName(drv)
                          : "");
  info->band = GDALGetBandNumber(r->band);
  info->width = r->nx;
  info->height = r->ny;
  info->valid_samples = r->valid;
  info->nodata_samples = r->nx * r->ny - r->valid;
  memcpy(info->gt, r->gt, sizeof r->gt);
  info->has_geotransform = r->has_gt;
  info->z_unit = tt__raster_dup_str(r->unit_out);
  info->z_unit_declared = tt__raster_dup_str(r->unit_declared);
  info->z_unit_source = tt__raster_dup_str(r->unit_source);
  info->z_unit_factor = r->unit_factor;
  info->z_unit_why = r->unit_why ? r->unit_why : "";
  info->scale = r->scale;
  info->offset = r->offset;
  info->z_factor = r->opt.z_factor;
  info->area_or_point = tt__raster_dup_str(
      ds ? GDALGetMetadataItem(ds, GDALMD_AREA_OR_POINT, NULL) : "");
  info->datatype = tt__raster_dup_str(GDALGetDataTypeName(r->dtype));
  tt_grid_get_ground_frame(r->grid, info->frame);
  info->frame_name = tt__raster_dup_str(r->frame_name);
  info->frame_scale_error = r->frame_scale_error;
  if (!info->path || !info->driver || !info->z_unit ||
      !info->z_unit_declared || !info->z_unit_source ||
      !info->area_or_point || !info->datatype || !info->frame_name)
    return tt__error(r->ctx, TT_ERR_NOMEM, "out of memory");
  return TT_OK;
}

tt_status tt_gdal_read_grid(tt_context *ctx, GDALRasterBandH band,
                            char **options, tt_progress_fn progress,
                            void *progress_arg, tt_grid **out_grid,
                            tt_raster_info **out_info)
{
  if (!out_grid)
    return tt__error(ctx, TT_ERR_ARG, "out_grid must not be NULL");
  *out_grid = NULL;
  if (out_info)
    *out_info = NULL;
  if (!band)
    return tt__error(ctx, TT_ERR_ARG, "band must not be NULL");

  raster_read r;
  memset(&r, 0, sizeof r);
  r.ctx = ctx;
  r.band = band;
  r.progress = progress;
  r.progress_arg = progress_arg;
  r.prog_lo = 0.0;
  r.prog_hi = 1.0;
  r.ds = GDALGetBandDataset(band);
  r.path = r.ds ? GDALGetDescription(r.ds) : "";
  if (!r.path || !*r.path)
    r.path = "(unnamed raster)";

  tt_status s = parse_options(ctx, options, &r.opt);
  if (s != TT_OK)
    goto done;
  if (r.opt.source_name && *r.opt.source_name)
    r.path = r.opt.source_name;
  s = check_band_type(&r);
  if (s != TT_OK)
    goto done;
  s = check_band_size(&r);
  if (s != TT_OK)
    goto done;
  s = tt__raster_georef(&r); /* before the big allocation */
  if (s != TT_OK)
    goto done;
  s = make_grid(&r);
  if (s != TT_OK)
    goto done;
  s = tt__raster_frame(&r);
  if (s != TT_OK)
    goto done;
  s = tt__raster_scan(&r);
  if (s != TT_OK)
    goto done;
  s = tt__raster_check_degrees(&r);
  if (s != TT_OK)
    goto done;
  s = fill_info(&r);

done:
  tt__raster_scan_end(&r);
  if (s != TT_OK) {
    tt_grid_destroy(r.grid);
    tt_raster_info_destroy(r.info);
    return s;
  }
  *out_grid = r.grid;
  if (out_info)
    *out_info = r.info;
  else
    tt_raster_info_destroy(r.info);
  return TT_OK;
}
