/*
 * src/gdal/gpkg/ -- the GeoPackage fast path: a TIN's rows, SQLite database
 * pages, R-trees and a tiled run's streamed write, straight into the file
 * rather than through OGR.
 *
 * sqlite_pages.h -- a table B-tree appended in rowid order, written as
 * pages straight into an SQLite database file while SQLite is closed.
 *
 * For tables that have never had rows (their root page is an empty leaf)
 * and are filled with rows of increasing rowids: leaves are packed full as
 * the rows come, interior pages are made level by level as the pages below
 * are done, and every new page goes after the file's last page. The root
 * pages and the database header are written only by tt__sqlite_file_commit;
 * until then the file's first pages are untouched, and closing without a
 * commit cuts the file back to its size at the open: the database is then
 * byte for byte what it was. See sqlite_pages.c for the format and what is
 * refused.
 *
 * Use: tt__sqlite_file_open; for each table tt__sqlite_table_begin, any
 * number of tt__sqlite_table_append calls in rowid order (any batches, any
 * interleaving of tables), tt__sqlite_table_finish; then
 * tt__sqlite_file_commit and tt__sqlite_file_close.
 */
#ifndef TERRATIN_SQLITE_PAGES_H
#define TERRATIN_SQLITE_PAGES_H

#include "base/internal.h"

#include <sqlite3.h> /* the library whose file format this writes */

#include <stddef.h>
#include <stdint.h>
#include <string.h>

/* Big-endian from the host's order. */
#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ == __ORDER_BIG_ENDIAN__
#define TT__BE64(x) ((uint64_t)(x))
#define TT__BE32(x) ((uint32_t)(x))
#else
#define TT__BE64(x) __builtin_bswap64((uint64_t)(x))
#define TT__BE32(x) __builtin_bswap32((uint32_t)(x))
#endif

typedef struct tt__sqlite_file tt__sqlite_file;
typedef struct tt__sqlite_table tt__sqlite_table;

/* --- records --------------------------------------------------------------
 * A value in SQLite's storage classes; p and n for a blob or text. */
enum { TT__SQV_NULL, TT__SQV_INT, TT__SQV_REAL, TT__SQV_TEXT, TT__SQV_BLOB };
typedef struct tt__sqlite_value {
  int type;
  int64_t i;
  double d;
  const void *p;
  size_t n;
} tt__sqlite_value;

/* Column affinities, from a declared type by SQLite's rules (section 3.1 of
 * datatype3.html: INT, then CHAR/CLOB/TEXT, then BLOB or none, then
 * REAL/FLOA/DOUB, else NUMERIC). */
enum { TT__AFF_BLOB, TT__AFF_TEXT, TT__AFF_NUMERIC, TT__AFF_INTEGER,
       TT__AFF_REAL };
TT_HIDDEN int tt__sqlite_affinity(const char *decl_type);

/* *v as an INSERT stores it in a column of affinity aff (not TEXT): a real
 * with an integer value becomes an integer under INTEGER and NUMERIC
 * affinity, and under REAL affinity too when it fits in 6 bytes (SQLite
 * stores it so and reads it back as a real); an integer under REAL
 * affinity that does not fit in 6 bytes becomes a real. An integer value:
 * the round trip exact, neither end of the int64 range. */
#define TT__SQLITE_MAX_6BYTE ((int64_t)0x00007fffffffffffLL)
static inline void tt__sqlite_apply_affinity(tt__sqlite_value *v, int aff)
{
  if (aff < TT__AFF_NUMERIC)
    return;
  if (v->type == TT__SQV_REAL) {
    double d = v->d;
    if (!(d > -9223372036854775808.0 && d < 9223372036854775808.0))
      return;
    int64_t i = (int64_t)d;
    if ((double)i != d || i == INT64_MIN || i == INT64_MAX)
      return;
    if (aff == TT__AFF_REAL &&
        (i > TT__SQLITE_MAX_6BYTE || i < -TT__SQLITE_MAX_6BYTE - 1))
      return;
    v->type = TT__SQV_INT; /* under REAL: stored so, read back a real */
    v->i = i;
  } else if (v->type == TT__SQV_INT && aff == TT__AFF_REAL &&
             (v->i > TT__SQLITE_MAX_6BYTE ||
              v->i < -TT__SQLITE_MAX_6BYTE - 1)) {
    v->type = TT__SQV_REAL;
    v->d = (double)v->i;
  }
}

/* A record built value by value (SQLite's record format: a header of the
 * size and the serial types, then the values), in two pieces: the header
 * here, the body in the caller's buffer (body, at least 8 bytes a value
 * plus the blobs and texts, and 8 more). Up to TT__SQLITE_REC_COLS values.
 * file_format is the database's schema format number (header offset 44):
 * from 4 on, 0 and 1 take no byte in the body. */
#define TT__SQLITE_REC_COLS 64
typedef struct tt__sqlite_rec {
  unsigned char head[9 + 9 * TT__SQLITE_REC_COLS]; /* room for the size */
  size_t nh;             /* bytes of serial types, from head + 9 */
  unsigned char *body;
  size_t nb;
  int format;
} tt__sqlite_rec;

static inline void tt__sqlite_rec_begin(tt__sqlite_rec *r,
                                        unsigned char *body, int format)
{
  r->nh = 0;
  r->body = body;
  r->nb = 0;
  r->format = format;
}

static inline void tt__sqlite_rec_null(tt__sqlite_rec *r)
{
  r->head[9 + r->nh++] = 0;
}

static inline void tt__sqlite_rec_int(tt__sqlite_rec *r, int64_t i)
{
  uint64_t u = i < 0 ? ~(uint64_t)i : (uint64_t)i;
  unsigned type;
  size_t len;
  if (u <= 127) {
    if ((uint64_t)i <= 1 && r->format >= 4) {
      r->head[9 + r->nh++] = (unsigned char)(8 + i);
      return;
    }
    type = 1, len = 1;
  } else if (u <= 32767) {
    type = 2, len = 2;
  } else if (u <= 8388607) {
    type = 3, len = 3;
  } else if (u <= 2147483647) {
    type = 4, len = 4;
  } else if (u <= (uint64_t)TT__SQLITE_MAX_6BYTE) {
    type = 5, len = 6;
  } else {
    type = 6, len = 8;
  }
  r->head[9 + r->nh++] = (unsigned char)type;
  /* big-endian, the len low bytes: 8 bytes stored, len of them kept (the
   * body has 8 bytes a value) */
  uint64_t be = TT__BE64((uint64_t)i << (64 - 8 * len));
  memcpy(r->body + r->nb, &be, 8);
  r->nb += len;
}

static inline void tt__sqlite_rec_real(tt__sqlite_rec *r, double d)
{
  uint64_t u;
  memcpy(&u, &d, 8);
  u = TT__BE64(u);
  r->head[9 + r->nh++] = 7;
  memcpy(r->body + r->nb, &u, 8);
  r->nb += 8;
}

/* The serial type of a blob (text: 1) of n bytes, its bytes left to the
 * caller (a body that is that blob alone: no copy). */
static inline void tt__sqlite_rec_bytes_type(tt__sqlite_rec *r, size_t n,
                                             int text)
{
  uint64_t type = 2 * (uint64_t)n + 12 + (text ? 1 : 0);
  unsigned char *h = r->head + 9 + r->nh;
  if (type <= 0x7f) {
    h[0] = (unsigned char)type;
    r->nh += 1;
  } else if (type <= 0x3fff) {
    h[0] = (unsigned char)(0x80 | (type >> 7));
    h[1] = (unsigned char)(type & 0x7f);
    r->nh += 2;
  } else {
    int k = 0;
    unsigned char tmp[10];
    do {
      tmp[k++] = (unsigned char)(type & 0x7f);
      type >>= 7;
    } while (type);
    for (int i = 0; i < k; i++)
      h[i] = (unsigned char)(tmp[k - 1 - i] | (i + 1 < k ? 0x80 : 0));
    r->nh += (size_t)k;
  }
}

/* A blob (text: 1) of n bytes. */
static inline void tt__sqlite_rec_bytes(tt__sqlite_rec *r, const void *p,
                                        size_t n, int text)
{
  tt__sqlite_rec_bytes_type(r, n, text);
  if (n)
    memcpy(r->body + r->nb, p, n);
  r->nb += n;
}

/* The value v (after tt__sqlite_apply_affinity, if any). */
static inline void tt__sqlite_rec_value(tt__sqlite_rec *r,
                                        const tt__sqlite_value *v)
{
  switch (v->type) {
  case TT__SQV_INT: tt__sqlite_rec_int(r, v->i); break;
  case TT__SQV_REAL: tt__sqlite_rec_real(r, v->d); break;
  case TT__SQV_TEXT: tt__sqlite_rec_bytes(r, v->p, v->n, 1); break;
  case TT__SQV_BLOB: tt__sqlite_rec_bytes(r, v->p, v->n, 0); break;
  default: tt__sqlite_rec_null(r); break;
  }
}

/* Ends the header: its first byte (the size in front of the serial types)
 * into *head, its length returned. The body is r->body[0..r->nb). */
static inline size_t tt__sqlite_rec_head(tt__sqlite_rec *r,
                                         const unsigned char **head)
{
  size_t n = r->nh + 1; /* the size counts its own varint */
  if (n <= 127) {
    r->head[8] = (unsigned char)n;
    *head = r->head + 8;
    return n;
  }
  n++; /* two bytes: up to 16383, far beyond TT__SQLITE_REC_COLS */
  r->head[7] = (unsigned char)(0x80 | (n >> 7));
  r->head[8] = (unsigned char)(n & 0x7f);
  *head = r->head + 7;
  return n;
}

/* The record of the n values (n <= TT__SQLITE_REC_COLS) in one piece into
 * out, cap bytes: its length, 0 when it does not fit. */
TT_HIDDEN size_t tt__sqlite_record(unsigned char *out, size_t cap,
                                   const tt__sqlite_value *v, int n,
                                   int file_format);

/* --- the file -------------------------------------------------------------
 * Opens path (an SQLite database no connection has open: nothing here
 * locks it) for appending pages. Refused (TT_ERR_FORMAT): a WAL database,
 * auto-vacuum (pointer-map pages), an in-header size that does not match
 * the file. */
TT_HIDDEN tt_status tt__sqlite_file_open(tt_context *ctx, const char *path,
                                         tt__sqlite_file **out);
/* Page size, usable bytes a page (the page size less the reserved bytes),
 * schema format number, pages in the file now. */
TT_HIDDEN size_t tt__sqlite_file_page_size(const tt__sqlite_file *f);
TT_HIDDEN size_t tt__sqlite_file_usable(const tt__sqlite_file *f);
TT_HIDDEN int tt__sqlite_file_format(const tt__sqlite_file *f);
TT_HIDDEN uint32_t tt__sqlite_file_page_count(const tt__sqlite_file *f);
/* The largest payload a table leaf holds without overflow pages (the
 * usable size less 35): a row above it is refused by
 * tt__sqlite_table_append. */
TT_HIDDEN size_t tt__sqlite_max_payload(size_t usable);

/* Writes the root pages of the finished tables, then the header (page
 * count, change counter, version-valid-for, library version). The freelist
 * and the schema are untouched. */
TT_HIDDEN tt_status tt__sqlite_file_commit(tt__sqlite_file *f);
/* Closes f; without a commit, cuts the file back to its size at the open
 * (every page appended goes). Tables not finished are freed. */
TT_HIDDEN tt_status tt__sqlite_file_close(tt__sqlite_file *f);

/* --- tables ---------------------------------------------------------------
 * Begins the table B-tree rooted at page root, which must be an empty table
 * leaf (a table that has no row). name is for messages. */
TT_HIDDEN tt_status tt__sqlite_table_begin(tt__sqlite_file *f,
                                           const char *name, uint32_t root,
                                           tt__sqlite_table **out);
/* Appends the row of rowid (above every rowid appended before) whose
 * record is payload[0..n). */
TT_HIDDEN tt_status tt__sqlite_table_append(tt__sqlite_table *t,
                                            int64_t rowid,
                                            const unsigned char *payload,
                                            size_t n);
/* The same, the record in two pieces: a[0..na) then b[0..nb) (a record of
 * tt__sqlite_rec: its header, then its body). */
TT_HIDDEN tt_status tt__sqlite_table_append2(tt__sqlite_table *t,
                                             int64_t rowid,
                                             const unsigned char *a,
                                             size_t na,
                                             const unsigned char *b,
                                             size_t nb);
/* The same for the record of (NULL, value), an integer: a row of a table
 * (INTEGER PRIMARY KEY, value) as the R*Tree module's %_rowid and
 * %_parent. */
TT_HIDDEN tt_status tt__sqlite_table_append_int(tt__sqlite_table *t,
                                                int64_t rowid,
                                                int64_t value);
/* Where a row's payload lies in the file once its page is done: page
 * number and the payload's first byte in that page (known: 1). */
typedef struct tt__sqlite_spot {
  uint32_t pgno;
  uint32_t offset;
  int known;
} tt__sqlite_spot;
/* tt__sqlite_table_append2, and *spot set to the row's place when its
 * page is done: by a later append that fills the page, or by
 * tt__sqlite_table_finish (the caller keeps *spot until then; one spot a
 * table at a time). For a row whose payload is patched in place before
 * the commit (tt__sqlite_file_patch): the R*Tree's root, node 1, known
 * last but stored first. */
TT_HIDDEN tt_status tt__sqlite_table_append2_spot(tt__sqlite_table *t,
                                                  int64_t rowid,
                                                  const unsigned char *a,
                                                  size_t na,
                                                  const unsigned char *b,
                                                  size_t nb,
                                                  tt__sqlite_spot *spot);
/* Overwrites n bytes of the payload at spot, from its byte at on, with p:
 * wherever the page is now (a root kept for the commit, a page queued,
 * or one written past the file's old end). Before the commit only; the
 * payload's length is the caller's to respect. */
TT_HIDDEN tt_status tt__sqlite_file_patch(tt__sqlite_file *f,
                                          const tt__sqlite_spot *spot,
                                          size_t at, const void *p,
                                          size_t n);
/* Ends the table: its last pages and its root (kept for the commit).
 * Frees t, also on failure. */
TT_HIDDEN tt_status tt__sqlite_table_finish(tt__sqlite_table *t);
/* Rows appended so far. */
TT_HIDDEN uint64_t tt__sqlite_table_rows(const tt__sqlite_table *t);

#endif /* TERRATIN_SQLITE_PAGES_H */
