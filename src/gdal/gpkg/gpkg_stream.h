/*
 * src/gdal/gpkg/ -- the GeoPackage fast path: a TIN's rows, SQLite database
 * pages, R-trees and a tiled run's streamed write, straight into the file
 * rather than through OGR.
 *
 * gpkg_stream.h -- a tiled run's GeoPackage written as its tiles finish
 * (gpkg_stream.c), and what it needs of the page writer of
 * gpkg_rows_pages.c: the two layers' tables filled row by row as
 * database pages, in fid order, with SQLite closed, then their R-trees,
 * extents and counts (tt__gpkg_pages_*); and the pieces both write their
 * geometry blobs with, so that they write the same bytes.
 */
#ifndef TERRATIN_GPKG_STREAM_H
#define TERRATIN_GPKG_STREAM_H

#include "base/internal.h"
#include "gdal/gpkg/gpkg_rtree.h"
#include "terratin/terratin_gdal.h"
#include "tile/tile.h"

/* One field value of a row: NULL, an integer or a real. */
enum { TT__GV_NULL, TT__GV_INT, TT__GV_REAL };
typedef struct tt__gpkg_value {
  int type;
  int64_t i;
  double d;
} tt__gpkg_value;

/* --- gpkg_rows_pages.c: the layers' pages appended row by row ---------
 * Opens the GeoPackage whose empty layers tt_ogr_write_tin(ROWS=DEFERRED)
 * made (closed by GDAL), with the write options it got (NLN_PREFIX,
 * LAYERS, LCO=SPATIAL_INDEX, RTREE_CHECK, JOURNAL; RTREE_BLOCK, the boxes
 * an R-tree block gathers before its leaves are written, default 65,536:
 * tt__rtree_stream in gpkg_rtree.h; the rest ignored), makes the
 * R-trees' schema (committed), and opens both tables for appending as
 * pages (PAGES=YES's steps 1 and 2). TT_ERR_FORMAT when the file cannot
 * take pages. nvfields: the vertices layer's fields. Only for
 * a file no one else opens and that is thrown away unless
 * tt__gpkg_pages_finish() succeeds. The caller frees *out with
 * tt__gpkg_pages_close(), which, unless finished, cuts the file back and
 * drops the R-trees' schema. layer: 0 triangles, 1 vertices. */
typedef struct tt__gpkg_pages tt__gpkg_pages;
TT_HIDDEN tt_status tt__gpkg_pages_open(tt_context *ctx, const char *path,
                                        char **options, int nvfields,
                                        tt__gpkg_pages **out);
/* Whether the layer is written (LAYERS), its srs_id; whether R-trees are
 * made. */
TT_HIDDEN int tt__gpkg_pages_has(const tt__gpkg_pages *p, int layer);
TT_HIDDEN int32_t tt__gpkg_pages_srs_id(const tt__gpkg_pages *p, int layer);
TT_HIDDEN int tt__gpkg_pages_rtree(const tt__gpkg_pages *p);
/* Appends a row: fid (1, 2, ... in order), the layer's fields in
 * tin_records.h's order, the geometry blob, and its box for the R-tree
 * (id the fid; needed when tt__gpkg_pages_rtree(), else NULL): the
 * R-tree's leaves are packed and written block by block
 * (tt__rtree_stream). */
TT_HIDDEN tt_status tt__gpkg_pages_row(tt__gpkg_pages *p, int layer,
                                       int64_t fid,
                                       const tt__gpkg_value *fields,
                                       const unsigned char *blob,
                                       size_t blob_len,
                                       const tt__rtree_box *box);
/* The layer's rows so far make whole pieces (a tiled run's batch): a
 * block of the R-tree may end here (tt__rtree_stream_cut). */
TT_HIDDEN tt_status tt__gpkg_pages_cut(tt__gpkg_pages *p, int layer);
/* The bytes the R-trees hold: the blocks gathering, the leaves' boxes. */
TT_HIDDEN size_t tt__gpkg_pages_bytes(const tt__gpkg_pages *p);
/* Ends the tables (count[k] rows each), writes the R-trees' last blocks,
 * upper levels and roots as pages, commits them, then sets
 * sqlite_sequence, the extents ext[k] (min x, min y, max x, max y) and
 * counts, and runs rtreecheck() when RTREE_CHECK asked. */
TT_HIDDEN tt_status tt__gpkg_pages_finish(tt__gpkg_pages *p,
                                          const size_t count[2],
                                          const double ext[2][4],
                                          tt_progress_fn progress,
                                          void *progress_arg);
TT_HIDDEN void tt__gpkg_pages_close(tt__gpkg_pages *p);

/* Whether the rows can be written as pages into the GeoPackage at path
 * (made by GDAL, with or without its layers): TT_OK, or TT_ERR_FORMAT
 * saying why not (WAL mode, auto-vacuum, an unusual page layout): then a
 * streamed merge cannot be written into it, and the whole TIN goes
 * through SQLite instead (tt_gpkg_write_rows' fallback). */
TT_HIDDEN tt_status tt__gpkg_pages_check(tt_context *ctx, const char *path);

/* --- gpkg_stream.c: the rows of a streamed merge ----------------------
 * tt__gpkg_stream_open() after the layers were made (as above, srs the
 * layers' input CRS, options those of tt_gpkg_write_rows(), T_SRS
 * included); tt__gpkg_stream_batch() for each batch tt__tin_stream_add()
 * gave, in order; tt__gpkg_stream_finish() after the last tile. decimated:
 * the vertices layer has the importance field (the TIN is decimated,
 * tt__records_decimated). The rows, blobs, extents and counts are those
 * tt_gpkg_write_rows() writes for the merged TIN, byte for byte; the
 * R-trees hold the same boxes (their nodes the same only for a layer of
 * one block). The caller frees *out with
 * tt__gpkg_stream_close() (which undoes an unfinished write, as above). */
typedef struct tt__gpkg_stream tt__gpkg_stream;
TT_HIDDEN tt_status tt__gpkg_stream_open(tt_context *ctx, const char *path,
                                         OGRSpatialReferenceH srs,
                                         char **options, int decimated,
                                         tt__gpkg_stream **out);
TT_HIDDEN tt_status tt__gpkg_stream_batch(tt__gpkg_stream *g,
                                          const tt__stream_batch *b);
/* Ends the tables and writes the R-trees, extents and counts
 * (tt__gpkg_pages_finish), then sets the run_parameters row (made with
 * provisional values) to fields and the default styles (STYLE=YES) to the
 * classes of the rows written. */
TT_HIDDEN tt_status tt__gpkg_stream_finish(tt__gpkg_stream *g,
                                           const tt_run_field *fields,
                                           size_t nfields,
                                           tt_progress_fn progress,
                                           void *progress_arg);
TT_HIDDEN void tt__gpkg_stream_close(tt__gpkg_stream *g);
/* The bytes the writer holds: the R-trees' blocks and leaves' boxes
 * (tt__gpkg_pages_bytes), the vertices' insertion errors for the style. */
TT_HIDDEN size_t tt__gpkg_stream_bytes(const tt__gpkg_stream *g);

/* --- GeoPackage geometry blobs, as gpkg_rows_pipe.c and gpkg_stream.c
 * write them: the blob header ("GP", version 0, flags, srs_id; GeoPackage
 * 1.4 section 2.1.3), then ISO WKB, little-endian whatever the host's
 * order, for a triangle and for a vertex; and a layer's extent grown
 * point by point. Static inline with
 * short names, so that the blob code reads as the format does. */
#include <string.h>

/* Little-endian stores; each returns the byte after the value. */
static inline unsigned char *put_u32(unsigned char *p, uint32_t v)
{
  for (int k = 0; k < 4; k++)
    *p++ = (unsigned char)(v >> (8 * k));
  return p;
}

static inline unsigned char *put_f64(unsigned char *p, double d)
{
  uint64_t v;
  memcpy(&v, &d, sizeof v);
  for (int k = 0; k < 8; k++)
    *p++ = (unsigned char)(v >> (8 * k));
  return p;
}

/* The blob header: magic, version 0 (version 1 of the format), flags
 * (byte order, envelope kind, empty), srs_id. */
static inline unsigned char *put_header(unsigned char *p, unsigned flags,
                                        int32_t srs_id)
{
  *p++ = 'G';
  *p++ = 'P';
  *p++ = 0;
  *p++ = (unsigned char)flags;
  return put_u32(p, (uint32_t)srs_id);
}

/* ext (minx, miny, maxx, maxy) grown to (x, y). */
static inline void extend(double *ext, double x, double y)
{
  if (x < ext[0]) ext[0] = x;
  if (y < ext[1]) ext[1] = y;
  if (x > ext[2]) ext[2] = x;
  if (y > ext[3]) ext[3] = y;
}

/* A triangle's blob: the XYZ envelope (flags 0x05), then a WKB
 * PolygonZ of one closed ring of 4 points. lo and hi get the envelope's
 * (x, y, z) corners. Returns the blob's length, TT__TRI_BLOB_BYTES. */
#define TT__TRI_BLOB_BYTES (8 + 48 + 1 + 4 + 4 + 4 + 4 * 24) /* 165 */
static inline size_t put_triangle_blob(unsigned char *blob, int32_t srs_id,
                                       const double px[3],
                                       const double py[3],
                                       const double pz[3], double lo[3],
                                       double hi[3])
{
  lo[0] = hi[0] = px[0];
  lo[1] = hi[1] = py[0];
  lo[2] = hi[2] = pz[0];
  for (int k = 1; k < 3; k++) {
    double c[3] = {px[k], py[k], pz[k]};
    for (int d = 0; d < 3; d++) {
      if (c[d] < lo[d]) lo[d] = c[d];
      if (c[d] > hi[d]) hi[d] = c[d];
    }
  }
  unsigned char *q = put_header(blob, 0x05, srs_id);
  for (int d = 0; d < 3; d++) {
    q = put_f64(q, lo[d]);
    q = put_f64(q, hi[d]);
  }
  *q++ = 1; /* WKB little endian */
  q = put_u32(q, 1003);
  q = put_u32(q, 1);
  q = put_u32(q, 4);
  for (int k = 0; k < 4; k++) {
    q = put_f64(q, px[k % 3]);
    q = put_f64(q, py[k % 3]);
    q = put_f64(q, pz[k % 3]);
  }
  return (size_t)(q - blob);
}

/* A vertex's blob: no envelope (flags 0x01), a WKB PointZ. Returns the
 * blob's length, TT__PT_BLOB_BYTES. */
#define TT__PT_BLOB_BYTES (8 + 1 + 4 + 24) /* 37 */
static inline size_t put_point_blob(unsigned char *blob, int32_t srs_id,
                                    double x, double y, double z)
{
  unsigned char *q = put_header(blob, 0x01, srs_id);
  *q++ = 1; /* WKB little endian */
  q = put_u32(q, 1001);
  q = put_f64(q, x);
  q = put_f64(q, y);
  q = put_f64(q, z);
  return (size_t)(q - blob);
}

#endif /* TERRATIN_GPKG_STREAM_H */
