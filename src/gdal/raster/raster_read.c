/*
 * raster_read.c -- reading one raster band into a tt_grid.
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
#include "gdal/georef/georef.h"
#include "base/internal.h"
#include "terratin/terratin_gdal.h"

#include <cpl_conv.h>
#include <cpl_error.h>
#include <cpl_string.h>

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <unistd.h>

/* Largest mask buffer used at once; taller blocks are read in bands of rows
 * (the block itself then stays in GDAL's cache between the bands). */
#define TT_READ_MASK_BYTES ((size_t)1 << 20)
/* Largest buffer of raw values (doubles) used at once, likewise. */
#define TT_READ_STAGE_BYTES ((size_t)8 << 20)
/* The largest integer magnitude up to which doubles hold every integer. */
#define TT_READ_MAX_EXACT_INT ((uint64_t)1 << 53)
/* Block-cache limit during the read when the user has not chosen one. */
#define TT_READ_CACHE_BYTES ((GIntBig)2 << 20)

typedef struct read_options {
  double z_factor;
  int has_z_factor;      /* Z_FACTOR was given */
  int z_unit_m;          /* Z_UNIT=m: convert ft and us-ft to metres */
  const char *work_srs;  /* WORK_SRS, NULL: chosen here (points into the
                            options list) */
  int has_srcnodata;
  int srcnodata_is_nan;
  float srcnodata;       /* compared with raw values that are floats */
  double srcnodata_d;    /* compared with the other raw values */
  int srcnodata_is_int;  /* an integer literal, kept exactly for 64-bit */
  int srcnodata_neg;     /* integer bands: sign and magnitude */
  uint64_t srcnodata_mag;
  size_t max_memory;     /* bytes */
  int max_memory_default; /* not given: the system's limit */
  const char *max_memory_source; /* which limit that is (tt_memory_limit) */
  int has_window;        /* WINDOW=col,row,width,height: a tile's window */
  size_t win[4];
} read_options;

static char *dup_str(const char *s)
{
  if (!s)
    s = "";
  size_t n = strlen(s) + 1;
  char *d = malloc(n);
  if (d)
    memcpy(d, s, n);
  return d;
}

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
      if (strcasecmp(value, "m") != 0)
        s = tt__error(ctx, TT_ERR_ARG, "Z_UNIT must be m (heights in ft or "
                      "us-ft converted to metres), got \"%s\"", value);
      else
        opt->z_unit_m = 1;
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
    } else {
      s = tt__error(ctx, TT_ERR_ARG, "unknown read option \"%s\" (known: "
                    "Z_FACTOR, Z_UNIT, SRCNODATA, MAX_MEMORY, WORK_SRS, "
                    "WINDOW)", key);
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

/* Prefixes the context's current message with "path: ". */
static tt_status with_path(tt_context *ctx, tt_status s, const char *path)
{
  if (!ctx || s == TT_OK)
    return s;
  char msg[TT_ERRMSG_MAX];
  snprintf(msg, sizeof msg, "%s", ctx->errmsg);
  return tt__error(ctx, s, "%s: %s", path, msg);
}

/* Fills the CRS fields of info from srs (may be NULL). */
static tt_status describe_crs(tt_context *ctx, OGRSpatialReferenceH srs,
                              tt_raster_info *info)
{
  char *wkt = NULL;
  char name[512] = "";
  if (srs) {
    const char *const wkt_options[] = {"FORMAT=WKT2_2019", NULL};
    if (OSRExportToWktEx(srs, &wkt, wkt_options) != OGRERR_NONE) {
      CPLFree(wkt);
      wkt = NULL;
      OSRExportToWkt(srs, &wkt);
    }
    const char *crs = OSRGetName(srs);
    const char *auth = OSRGetAuthorityName(srs, NULL);
    const char *code = OSRGetAuthorityCode(srs, NULL);
    if (auth && code) {
      snprintf(name, sizeof name, "%s (%s:%s)", crs ? crs : "unnamed", auth,
               code);
    } else {
      /* No code of its own (USGS DEM, .prj files): say what it looks like,
       * which helps more than "unnamed". Only the name is affected. */
      OGRSpatialReferenceH guess = OSRClone(srs);
      CPLPushErrorHandler(CPLQuietErrorHandler);
      int found = guess && OSRAutoIdentifyEPSG(guess) == OGRERR_NONE;
      CPLPopErrorHandler();
      const char *gcode = found ? OSRGetAuthorityCode(guess, NULL) : NULL;
      if (gcode)
        snprintf(name, sizeof name, "%s (like EPSG:%s)",
                 crs ? crs : "unnamed", gcode);
      else
        snprintf(name, sizeof name, "%s", crs ? crs : "unnamed");
      OSRDestroySpatialReference(guess);
    }
    info->crs_is_geographic = OSRIsGeographic(srs) ? 1 : 0;
  }
  info->crs_wkt = dup_str(wkt);
  info->crs_name = dup_str(name);
  CPLFree(wkt);
  if (!info->crs_wkt || !info->crs_name)
    return tt__error(ctx, TT_ERR_NOMEM, "out of memory");
  return TT_OK;
}

/* The short name of a height unit: "m", "ft" (international foot) or
 * "us-ft" (US survey foot); NULL for anything else. */
static const char *unit_short_name(const char *u)
{
  static const char *const m[] = {"m", "metre", "meter", "metres", "meters",
                                  NULL};
  static const char *const ft[] = {"ft", "foot", "feet", "international "
                                   "foot", "foot (international)", "intl ft",
                                   NULL};
  static const char *const usft[] = {"us-ft", "us_ft", "ftus", "us-foot",
                                     "us survey foot", "foot_us",
                                     "us foot", "survey foot",
                                     "foot (us survey)", NULL};
  if (!u)
    return NULL;
  for (int i = 0; m[i]; i++)
    if (strcasecmp(u, m[i]) == 0)
      return "m";
  for (int i = 0; ft[i]; i++)
    if (strcasecmp(u, ft[i]) == 0)
      return "ft";
  for (int i = 0; usft[i]; i++)
    if (strcasecmp(u, usft[i]) == 0)
      return "us-ft";
  return NULL;
}

/* Metres per unit of a short unit name (unit_short_name). */
static double unit_metres(const char *short_name)
{
  if (strcmp(short_name, "ft") == 0)
    return 0.3048;
  if (strcmp(short_name, "us-ft") == 0)
    return 1200.0 / 3937.0;
  return 1.0;
}

/* The unit the heights are declared in: the band's unit type, else the
 * linear unit of the vertical part of a compound CRS (or of a vertical
 * CRS). Writes the name as declared to buf ("" when nothing says) and
 * returns where it came from. */
static const char *declared_z_unit(GDALRasterBandH band,
                                   OGRSpatialReferenceH srs, char *buf,
                                   size_t size)
{
  const char *u = GDALGetRasterUnitType(band);
  buf[0] = '\0';
  if (u && *u) {
    snprintf(buf, size, "%s", u);
    return "band unit";
  }
  if (srs && (OSRIsCompound(srs) || OSRIsVertical(srs))) {
    char *name = NULL;
    double to_m = OSRGetTargetLinearUnits(srs, "VERT_CS", &name);
    if (to_m > 0 && name && *name) {
      const char *sn = unit_short_name(name);
      /* A unit PROJ names oddly but whose size is known still counts. */
      if (!sn && fabs(to_m - 1.0) < 1e-12)
        sn = "m";
      else if (!sn && fabs(to_m - 0.3048) < 1e-12)
        sn = "ft";
      else if (!sn && fabs(to_m - 1200.0 / 3937.0) < 1e-12)
        sn = "us-ft";
      snprintf(buf, size, "%s", sn ? sn : name);
      return "vertical CRS";
    }
  }
  return "";
}

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

/* Where the raw values of a band of rows are: in the grid itself (bands
 * whose raw values are floats), or in the buffer, as doubles or as 64-bit
 * integers. */
typedef enum raw_source {
  RAW_IN_GRID = 0, RAW_F64, RAW_I64, RAW_U64
} raw_source;

typedef struct raw_rows {
  raw_source source;
  const void *buf;       /* nrows x nx values, for RAW_F64/I64/U64 */
} raw_rows;

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

  tt_status s = TT_OK;
  tt_grid *grid = NULL;
  tt_raster_info *info = NULL;
  unsigned char *mask = NULL;
  void *stage = NULL;
  GDALRasterBandH mask_band = NULL;
  int cache_changed = 0;
  GIntBig old_cache_max = 0;

  GDALDatasetH ds = GDALGetBandDataset(band);
  const char *path = ds ? GDALGetDescription(ds) : "";
  if (!path || !*path)
    path = "(unnamed raster)";

  read_options opt;
  s = parse_options(ctx, options, &opt);
  if (s != TT_OK)
    goto done;

  const GDALDataType dtype = GDALGetRasterDataType(band);
  if (GDALDataTypeIsComplex(dtype)) {
    s = tt__error(ctx, TT_ERR_FORMAT, "%s: band %d holds complex numbers "
                  "(%s), not heights", path, GDALGetBandNumber(band),
                  GDALGetDataTypeName(dtype));
    goto done;
  }
  /* Raw values that are all floats are read straight into the grid; the
   * others through the buffer (see the top of the file). */
  raw_rows raw = {RAW_IN_GRID, NULL};
  GDALDataType stage_type = GDT_Float64;
  if (dtype == GDT_Byte || dtype == GDT_Int16 || dtype == GDT_UInt16 ||
#if GDAL_VERSION_NUM >= GDAL_COMPUTE_VERSION(3, 7, 0)
      dtype == GDT_Int8 ||
#endif
      dtype == GDT_Float32) {
    raw.source = RAW_IN_GRID;
#if GDAL_VERSION_NUM >= GDAL_COMPUTE_VERSION(3, 5, 0)
  } else if (dtype == GDT_Int64) {
    raw.source = RAW_I64;
    stage_type = GDT_Int64;
  } else if (dtype == GDT_UInt64) {
    raw.source = RAW_U64;
    stage_type = GDT_UInt64;
#endif
  } else {
    raw.source = RAW_F64;
  }

  /* A SRCNODATA the band's type cannot hold can never match a sample:
   * refuse it rather than mask nothing (1e39 in a Float32 band, -1 in a
   * Byte band, 0.5 in an Int16 band, nan in an integer band). */
  if (opt.has_srcnodata) {
    int clamped = 0, rounded = 0;
    if (opt.srcnodata_is_nan) {
      clamped = !GDALDataTypeIsFloating(dtype);
    } else if ((dtype == GDT_Int64 || dtype == GDT_UInt64) &&
               opt.srcnodata_is_int) {
      /* doubles cannot say near 2^63, 2^64: the integer literal, exactly */
      const uint64_t top = (uint64_t)1 << 63;
      clamped = opt.srcnodata_mag &&
                (dtype == GDT_UInt64 ? opt.srcnodata_neg
                 : opt.srcnodata_neg ? opt.srcnodata_mag > top
                                     : opt.srcnodata_mag >= top);
    } else {
      GDALAdjustValueToDataType(dtype, opt.srcnodata_d, &clamped,
                                &rounded);
    }
    if (clamped || rounded) {
      s = tt__error(ctx, TT_ERR_ARG, "%s: SRCNODATA (-srcnodata) %.15g "
                    "cannot occur in band %d, whose type %s %s", path,
                    opt.srcnodata_is_nan ? NAN : opt.srcnodata_d,
                    GDALGetBandNumber(band), GDALGetDataTypeName(dtype),
                    clamped ? "cannot hold it" : "holds whole numbers only");
      goto done;
    }
  }

  const int xsize = GDALGetRasterBandXSize(band);
  const int ysize = GDALGetRasterBandYSize(band);
  if (xsize < 2 || ysize < 2) {
    s = tt__error(ctx, TT_ERR_DATA, "%s: raster is %d x %d pixels: at least "
                  "2 x 2 are needed to make a triangle", path, xsize, ysize);
    goto done;
  }
  /* A window (a tile): its samples only; the ground frame (and, for a
   * geographic or Web Mercator raster, the ground points) are still the
   * whole raster's, so that every tile measures alike. */
  const size_t wx = opt.has_window ? opt.win[0] : 0;
  const size_t wy = opt.has_window ? opt.win[1] : 0;
  if (opt.has_window && (opt.win[0] + opt.win[2] > (size_t)xsize ||
                         opt.win[1] + opt.win[3] > (size_t)ysize)) {
    s = tt__error(ctx, TT_ERR_ARG, "%s: window of %zu x %zu at column %zu, "
                  "row %zu passes the raster's %d x %d", path, opt.win[2],
                  opt.win[3], opt.win[0], opt.win[1], xsize, ysize);
    goto done;
  }
  const size_t nx = opt.has_window ? opt.win[2] : (size_t)xsize;
  const size_t ny = opt.has_window ? opt.win[3] : (size_t)ysize;
  if (nx > SIZE_MAX / sizeof(float) / ny) {
    s = tt__error(ctx, TT_ERR_LIMIT, "%s: %zu x %zu heights do not fit in "
                  "this machine's address space", path, nx, ny);
    goto done;
  }
  const size_t need = nx * ny * sizeof(float);
  if (need > opt.max_memory) {
    char need_s[32], max_s[32];
    s = tt__error(ctx, TT_ERR_LIMIT, "%s: the %zu x %zu heights need %s, "
                  "more than %s (%s); refused before reading", path, nx, ny,
                  tt__format_bytes(need_s, sizeof need_s, need),
                  opt.max_memory_default ? opt.max_memory_source
                                         : "MAX_MEMORY",
                  tt__format_bytes(max_s, sizeof max_s, opt.max_memory));
    goto done;
  }

  /* Georeferencing, before the big allocation: a GCP-only raster fails
   * here. */
  double gt[6] = {0, 1, 0, 0, 0, 1};
  int has_gt = 0;
  if (ds) {
    CPLPushErrorHandler(CPLQuietErrorHandler);
    has_gt = GDALGetGeoTransform(ds, gt) == CE_None;
    CPLPopErrorHandler();
    if (!has_gt) {
      const double unit_gt[6] = {0, 1, 0, 0, 0, 1};
      memcpy(gt, unit_gt, sizeof gt);
      if (GDALGetGCPCount(ds) > 0) {
        s = tt__error(ctx, TT_ERR_FORMAT, "%s: georeferenced by %d ground "
                      "control points only, not by a geotransform: warp it "
                      "first (gdalwarp)", path, GDALGetGCPCount(ds));
        goto done;
      }
    }
  }

  info = calloc(1, sizeof *info);
  if (!info) {
    s = tt__error(ctx, TT_ERR_NOMEM, "out of memory");
    goto done;
  }
  OGRSpatialReferenceH srs = ds ? GDALGetSpatialRef(ds) : NULL;
  s = describe_crs(ctx, srs, info);
  if (s != TT_OK)
    goto done;

  int has_scale = 0, has_offset = 0;
  double scale = GDALGetRasterScale(band, &has_scale);
  double offset = GDALGetRasterOffset(band, &has_offset);
  if (!has_scale)
    scale = 1.0;
  if (!has_offset)
    offset = 0.0;
  if (!isfinite(scale) || scale == 0 || !isfinite(offset)) {
    s = tt__error(ctx, TT_ERR_FORMAT, "%s: band %d has an unusable scale %g "
                  "or offset %g", path, GDALGetBandNumber(band), scale,
                  offset);
    goto done;
  }

  /* The height unit, and Z_UNIT=m's conversion (before Z_FACTOR). */
  char unit_declared[128];
  const char *unit_source = declared_z_unit(band, srs, unit_declared,
                                            sizeof unit_declared);
  const char *unit_short = unit_short_name(unit_declared);
  double unit_factor = 1.0;
  const char *unit_out = unit_short ? unit_short : unit_declared;
  if (opt.z_unit_m) {
    if (unit_short) {
      unit_factor = unit_metres(unit_short);
    } else if (!opt.has_z_factor) {
      s = tt__error(ctx, TT_ERR_DATA, "%s: heights cannot be converted to "
                    "metres (Z_UNIT=m, -z_unit m): the height unit is %s%s%s"
                    "; give the factor to metres as Z_FACTOR (-z_factor)",
                    path, unit_declared[0] ? "\"" : "unknown (no band unit, no "
                    "vertical CRS)", unit_declared,
                    unit_declared[0] ? "\", which is not m, ft or us-ft" : "");
      goto done;
    }
    unit_out = "m";
  }
  read_options conv = opt; /* what convert_rows() multiplies by */
  conv.z_factor = opt.z_factor * unit_factor;

  s = tt_grid_create(ctx, nx, ny, &grid);
  if (s != TT_OK) {
    s = with_path(ctx, s, path);
    goto done;
  }
  double wgt[6];
  memcpy(wgt, gt, sizeof wgt);
  wgt[0] += (double)wx * gt[1] + (double)wy * gt[2];
  wgt[3] += (double)wx * gt[4] + (double)wy * gt[5];
  s = tt_grid_set_geotransform(ctx, grid, wgt);
  if (s != TT_OK) {
    s = with_path(ctx, s, path);
    goto done;
  }
  char frame_name[512] = "geotransform";
  double frame_scale_error = NAN;
  if (srs || opt.work_srs) {
    double frame[4];
    s = tt__georef_ground_frame(ctx, srs, opt.work_srs, gt, (size_t)xsize,
                                (size_t)ysize, frame, frame_name,
                                sizeof frame_name);
    if (s == TT_ERR_DATA) {
      /* A CRS that says geographic over coordinates that cannot be (a
       * mislabelled projected grid) or a grid centred on a pole: measure
       * in the geotransform's units rather than refuse the DEM. */
      tt__warn(ctx, "%s: %s; angles and areas are measured in the "
               "geotransform's units instead", path, ctx ? ctx->errmsg : "");
      tt_context_clear_error(ctx);
      snprintf(frame_name, sizeof frame_name, "geotransform (the CRS is "
               "geographic but no local frame fits)");
      s = TT_OK;
    } else if (s == TT_OK) {
      s = tt_grid_set_ground_frame(ctx, grid, frame);
      /* Longitude/latitude and Web Mercator: every sample projected
       * into a conformal frame (georef_conformal.c); the affine frame
       * stays only when that fails. */
      /* 16 bytes a sample beside the heights' 4: over MAX_MEMORY, the
       * affine frame stays, with a warning */
      size_t n = nx * ny, with_points = n <= SIZE_MAX / 20 ? n * 20
                                                           : SIZE_MAX;
      int conformal = srs && (OSRIsGeographic(srs) ||
                              tt__georef_is_web_mercator(srs));
      if (s == TT_OK && conformal && with_points > opt.max_memory) {
        char need_s[32], max_s[32];
        tt__warn(ctx, "%s: the heights and ground points of %zu x %zu "
                 "samples would need %s, more than %s (%s): keeping the "
                 "affine frame %s", path, nx, ny,
                 tt__format_bytes(need_s, sizeof need_s, with_points),
                 opt.max_memory_default ? "3/4 of this machine's physical "
                                          "memory"
                                        : "MAX_MEMORY",
                 tt__format_bytes(max_s, sizeof max_s, opt.max_memory), frame_name);
      } else if (s == TT_OK && conformal) {
        char conformal_name[512];
        /* a window (a tile) gets the whole raster's frame and the
         * ground points of its samples as the whole raster has them */
        s = tt__georef_ground_points(ctx, srs, opt.work_srs, gt,
                                     (size_t)xsize, (size_t)ysize, wx, wy,
                                     grid, conformal_name,
                                     sizeof conformal_name,
                                     &frame_scale_error);
        if (s == TT_OK) {
          snprintf(frame_name, sizeof frame_name, "%s", conformal_name);
        } else if (s != TT_ERR_ARG) {
          tt__warn(ctx, "%s: %s; keeping the affine frame %s", path,
                   ctx ? ctx->errmsg : "", frame_name);
          tt_context_clear_error(ctx);
          s = TT_OK;
        }
      }
    }
    if (s != TT_OK) {
      s = with_path(ctx, s, path);
      goto done;
    }
    /* A map in feet is measured in metres (georef_proj.c): heights of no
     * declared unit are taken as metres then, which they rarely are on
     * such a map. Say so once; the TIN is the same either way. */
    char *lin_name = NULL;
    double lin = srs && OSRIsProjected(srs) ? OSRGetLinearUnits(srs, &lin_name)
                                            : 1.0;
    if (lin > 0 && fabs(lin - 1.0) > 1e-9 && !unit_declared[0] &&
        !opt.has_z_factor)
      tt__warn(ctx, "%s: the map unit is %s and the heights declare no "
               "unit: slopes and 3-D areas take them as metres (give "
               "-z_factor %.10g if they are in that unit too)", path,
               lin_name && *lin_name ? lin_name : "not the metre", lin);
  }

  /* Validity: SRCNODATA overrides the mask; GMF_ALL_VALID needs none. */
  if (!opt.has_srcnodata && !(GDALGetMaskFlags(band) & GMF_ALL_VALID))
    mask_band = GDALGetMaskBand(band);

  int bw = 0, bh = 0;
  GDALGetBlockSize(band, &bw, &bh);
  if (bw <= 0 || bw > xsize)
    bw = xsize;
  if (bh <= 0 || bh > ysize)
    bh = ysize;
  /* Rows per step: a block's height, fewer if the mask buffer or the raw
   * buffer of a row of blocks would be large (single-strip files). */
  size_t step = (size_t)bh;
  if (mask_band && step * nx > TT_READ_MASK_BYTES)
    step = TT_READ_MASK_BYTES / nx > 0 ? TT_READ_MASK_BYTES / nx : 1;
  if (raw.source != RAW_IN_GRID && step * nx * 8 > TT_READ_STAGE_BYTES)
    step = TT_READ_STAGE_BYTES / (nx * 8) > 0 ? TT_READ_STAGE_BYTES / (nx * 8)
                                              : 1;
  if (mask_band) {
    mask = malloc(step * nx);
    if (!mask) {
      s = tt__error(ctx, TT_ERR_NOMEM, "out of memory for a mask buffer");
      goto done;
    }
  }
  if (raw.source != RAW_IN_GRID) {
    stage = malloc(step * nx * 8); /* doubles or 64-bit integers */
    if (!stage) {
      s = tt__error(ctx, TT_ERR_NOMEM, "out of memory for a buffer of %zu "
                    "rows", step);
      goto done;
    }
    raw.buf = stage;
  }
  const int identity = scale == 1.0 && offset == 0.0 && conv.z_factor == 1.0;

  /* Hold GDAL's block cache to a few blocks unless the user chose a size. */
  if (!opt.has_window && !CPLGetConfigOption("GDAL_CACHEMAX", NULL)) {
    GIntBig block_bytes = (GIntBig)bw * bh *
                          (GIntBig)(GDALGetDataTypeSizeBytes(dtype) + 1);
    GIntBig want = TT_READ_CACHE_BYTES;
    if (want < 3 * block_bytes)
      want = 3 * block_bytes;
    old_cache_max = GDALGetCacheMax64();
    if (want < old_cache_max) {
      GDALSetCacheMax64(want);
      cache_changed = 1;
    }
  }

  size_t valid = 0;
  if (progress && !progress(0.0, "reading", progress_arg)) {
    s = tt__error(ctx, TT_ERR_INTERRUPTED, "%s: read interrupted",
                  path);
    goto done;
  }
  for (size_t r0 = 0; r0 < ny; r0 += step) {
    const size_t nrows = ny - r0 < step ? ny - r0 : step;
    for (size_t c0 = 0; c0 < nx; c0 += (size_t)bw) {
      const size_t ncols = nx - c0 < (size_t)bw ? nx - c0 : (size_t)bw;
      /* into the buffer, or into the grid as it now is */
      void *dst = NULL;
      GDALDataType type = GDT_Float32;
      size_t es = sizeof(float);
      if (stage) {
        dst = (char *)stage + c0 * 8;
        type = stage_type;
        es = 8;
      } else if (grid->zd) {
        dst = grid->zd + r0 * nx + c0;
        type = GDT_Float64;
        es = sizeof(double);
      } else {
        dst = grid->z + r0 * nx + c0;
      }
      CPLErrorReset();
      CPLErr err = GDALRasterIOEx(band, GF_Read, (int)(c0 + wx),
                                  (int)(r0 + wy),
                                  (int)ncols, (int)nrows, dst, (int)ncols,
                                  (int)nrows, type, (GSpacing)es,
                                  (GSpacing)(nx * es), NULL);
      if (err == CE_None && mask_band)
        err = GDALRasterIOEx(mask_band, GF_Read, (int)(c0 + wx),
                             (int)(r0 + wy),
                             (int)ncols, (int)nrows, mask + c0, (int)ncols,
                             (int)nrows, GDT_Byte, 1, (GSpacing)nx, NULL);
      if (err != CE_None) {
        s = tt__error(ctx, TT_ERR_IO, "%s: reading band %d at row %zu, "
                      "column %zu failed: %s", path, GDALGetBandNumber(band),
                      r0, c0, CPLGetLastErrorMsg());
        goto done;
      }
    }
    if (raw.source == RAW_IN_GRID && identity && !grid->zd)
      s = convert_rows(ctx, path, grid->z, nx, r0, nrows, mask, &conv,
                       &valid);
    else
      s = convert_any(ctx, path, grid, &raw, r0, nrows, mask, &conv, scale,
                      offset, &valid);
    if (s != TT_OK)
      goto done;
    if (progress &&
        !progress((double)(r0 + nrows) / (double)ny, "reading",
                  progress_arg)) {
      s = tt__error(ctx, TT_ERR_INTERRUPTED, "%s: read interrupted at row "
                    "%zu of %zu", path, r0 + nrows, ny);
      goto done;
    }
  }
  if (valid == 0 && !opt.has_window) {
    s = tt__error(ctx, TT_ERR_DATA, "%s: all nodata: band %d has no valid "
                  "sample", path, GDALGetBandNumber(band));
    goto done;
  }

  info->path = dup_str(path);
  GDALDriverH drv = ds ? GDALGetDatasetDriver(ds) : NULL;
  info->driver = dup_str(drv ? GDALGetDriverShortName(drv) : "");
  info->band = GDALGetBandNumber(band);
  info->width = nx;
  info->height = ny;
  info->valid_samples = valid;
  info->nodata_samples = nx * ny - valid;
  memcpy(info->gt, gt, sizeof gt);
  info->has_geotransform = has_gt;
  info->z_unit = dup_str(unit_out);
  info->z_unit_declared = dup_str(unit_declared);
  info->z_unit_source = dup_str(unit_source);
  info->z_unit_factor = unit_factor;
  info->scale = scale;
  info->offset = offset;
  info->z_factor = opt.z_factor;
  info->area_or_point =
      dup_str(ds ? GDALGetMetadataItem(ds, GDALMD_AREA_OR_POINT, NULL) : "");
  info->datatype = dup_str(GDALGetDataTypeName(dtype));
  tt_grid_get_ground_frame(grid, info->frame);
  info->frame_name = dup_str(frame_name);
  info->frame_scale_error = frame_scale_error;
  if (!info->path || !info->driver || !info->z_unit ||
      !info->z_unit_declared || !info->z_unit_source ||
      !info->area_or_point || !info->datatype || !info->frame_name) {
    s = tt__error(ctx, TT_ERR_NOMEM, "out of memory");
    goto done;
  }

done:
  if (cache_changed) {
    /* Drop this read's blocks, then give the user their cache size back. */
    GDALFlushRasterCache(band);
    if (mask_band)
      GDALFlushRasterCache(mask_band);
    GDALSetCacheMax64(old_cache_max);
  }
  free(mask);
  free(stage);
  if (s != TT_OK) {
    tt_grid_destroy(grid);
    tt_raster_info_destroy(info);
    return s;
  }
  *out_grid = grid;
  if (out_info)
    *out_info = info;
  else
    tt_raster_info_destroy(info);
  return TT_OK;
}
