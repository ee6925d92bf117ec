/*
 * src/gdal/raster/ -- the rasters: a band read into a grid, a grid written
 * as a GeoTIFF.
 *
 * raster_read.h -- what the files of the band reader share, private to
 * them: the read's options and its state (one struct a read, filled stage
 * by stage), and the stages each file holds: raster_read.c
 * (tt_gdal_read_grid, the options, the band's type and size checked, the
 * grid made, the info filled), raster_georef.c (the geotransform, the CRS
 * and the height unit; the ground frame) and raster_scan.c (the blocks
 * read, mask, nodata and the heights converted). raster_read.c's opening
 * comment describes the read.
 */
#ifndef TT_RASTER_READ_H
#define TT_RASTER_READ_H

#include "base/internal.h"
#include "terratin/terratin_gdal.h"

#include <gdal.h>
#include <ogr_srs_api.h>

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct read_options {
  double z_factor;
  int has_z_factor;      /* Z_FACTOR was given */
  int z_unit_m;          /* Z_UNIT=m: convert ft and us-ft to metres */
  int z_unit_auto;       /* Z_UNIT=auto: the same when the CRS is in
                            metres or geographic */
  const char *src_z_unit; /* SRC_Z_UNIT: "m", "ft" or "us-ft", NULL */
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
  const char *source_name;   /* SOURCE_NAME, SOURCE_DRIVER: what a view's */
  const char *source_driver; /* band is read from; NULL: its dataset's */
} read_options;

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

/* One read, stage by stage. The grid, the info and the scan's buffers are
 * the read's until tt_gdal_read_grid hands the first two out; the cache
 * limit is restored by tt__raster_scan_end. */
typedef struct raster_read {
  tt_context *ctx;
  GDALRasterBandH band;
  GDALDatasetH ds;          /* the band's dataset, or NULL */
  const char *path;         /* its name, for messages */
  tt_progress_fn progress;
  void *progress_arg;
  double prog_lo, prog_hi;  /* the stage's share of the read's progress:
                               the ground points' (0 - 0.8, when made),
                               then the scan's */
  read_options opt;         /* as given */
  /* the band (raster_read.c) */
  GDALDataType dtype;
  raw_rows raw;             /* where the raw values are read to */
  GDALDataType stage_type;  /* the buffer's type, when raw is not the grid */
  int xsize, ysize;         /* the whole raster's */
  size_t wx, wy;            /* the window's first column and row (0, 0) */
  size_t nx, ny;            /* the samples read */
  /* the georeferencing (raster_georef.c) */
  double gt[6];             /* the whole raster's geotransform */
  int has_gt;
  OGRSpatialReferenceH srs; /* the dataset's CRS (GDAL's), or NULL */
  double scale, offset;     /* the band's, 1 and 0 when not given */
  char unit_declared[128];  /* the height unit as declared, "" */
  const char *unit_source;  /* where it was declared ("band unit", ...) */
  const char *unit_out;     /* the unit of the grid's heights */
  double unit_factor;       /* Z_UNIT=m's factor, else 1 */
  const char *unit_why;     /* why the heights were converted, "" */
  read_options conv;        /* what the scan multiplies by: Z_FACTOR times
                               unit_factor */
  char frame_name[512];
  double frame_scale_error; /* NaN unless ground points were made */
  /* the scan (raster_scan.c) */
  GDALRasterBandH mask_band; /* NULL: SRCNODATA, or every sample valid */
  unsigned char *mask;      /* step x nx mask bytes */
  void *stage;              /* step x nx raw values (8 bytes each) */
  int bw, bh;               /* the band's block size, within the raster */
  size_t step;              /* rows read at once */
  int cache_changed;        /* GDAL's cache limit lowered for the read */
  GIntBig old_cache_max;
  size_t valid;             /* valid samples met */
  /* what the read makes */
  tt_grid *grid;
  tt_raster_info *info;
} raster_read;

/* A copy of s ("" for NULL) that free() releases; NULL when out of
 * memory. */
static inline char *tt__raster_dup_str(const char *s)
{
  if (!s)
    s = "";
  size_t n = strlen(s) + 1;
  char *d = malloc(n);
  if (d)
    memcpy(d, s, n);
  return d;
}

/* Prefixes the context's current message with "path: ". */
static inline tt_status tt__raster_with_path(tt_context *ctx, tt_status s,
                                             const char *path)
{
  if (!ctx || s == TT_OK)
    return s;
  char msg[TT_ERRMSG_MAX];
  snprintf(msg, sizeof msg, "%s", ctx->errmsg);
  return tt__error(ctx, s, "%s: %s", path, msg);
}

/* The read's progress at fraction f of the current stage (prog_lo ..
 * prog_hi); 0 when the run is to stop. */
static inline int tt__raster_progress(raster_read *r, double f,
                                      const char *what)
{
  return !r->progress ||
         r->progress(r->prog_lo + (r->prog_hi - r->prog_lo) * f, what,
                     r->progress_arg);
}

/* --- the georeferencing (raster_georef.c) --------------------------------
 * tt__raster_georef: the geotransform (a GCP-only raster refused), the
 * info (allocated here) with the CRS, the band's scale and offset, the
 * height unit and Z_UNIT=m's factor (r->conv). tt__raster_frame: the
 * grid's ground frame (the affine frame, or ground points for a
 * geographic or Web Mercator raster), and the warning for heights of no
 * unit on a map in feet. tt__raster_check_degrees, once the heights are
 * read: the warning for a raster without a CRS whose coordinates look like
 * longitude/latitude degrees (its frame named so too). */
TT_HIDDEN tt_status tt__raster_georef(raster_read *r);
TT_HIDDEN tt_status tt__raster_frame(raster_read *r);
TT_HIDDEN tt_status tt__raster_check_degrees(raster_read *r);

/* --- the scan (raster_scan.c) --------------------------------------------
 * tt__raster_scan: the band read into r->grid a band of rows at a time
 * (mask, SRCNODATA, scale/offset, Z_FACTOR, the limits), r->valid
 * counted, progress polled; refuses a raster of nodata only.
 * tt__raster_scan_end: GDAL's cache limit given back, the buffers freed
 * (on success and failure alike, once). */
TT_HIDDEN tt_status tt__raster_scan(raster_read *r);
TT_HIDDEN void tt__raster_scan_end(raster_read *r);

#endif /* TT_RASTER_READ_H */
