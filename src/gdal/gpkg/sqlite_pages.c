/*
 * src/gdal/gpkg/ -- the GeoPackage fast path: a TIN's rows, SQLite database
 * pages, R-trees and a tiled run's streamed write, straight into the file
 * rather than through OGR.
 *
 * sqlite_pages.c -- a table B-tree appended in rowid order: SQLite database
 * pages built here and written straight into the file, SQLite closed
 * (sqlite_pages.h). The format is SQLite's documented file format
 * (https://www.sqlite.org/fileformat2.html); no SQLite code is used but
 * sqlite3_libversion_number() and the lock-byte offset.
 *
 * What is written, all integers big-endian:
 *   table leaf page (0x0D): 8-byte header (flag, first freeblock 0, cell
 *     count, start of the cell content area, fragmented bytes 0), the cell
 *     pointer array, free space, then the cells packed at the end of the
 *     usable area; a cell is varint payload size, varint rowid, payload.
 *     Leaves are filled as full as the rows allow, in rowid order.
 *   table interior page (0x05): 12-byte header (the same, then the right
 *     child), cells of a 4-byte left child and a varint key, the largest
 *     rowid of that child's subtree; the right child holds the rest. Each
 *     level is made from the pages of the level below as they are done:
 *     pages are filled while their cells fit, one full page of each level
 *     is held back so that the last page of a level never has a lone child
 *     (SQLite counts an interior page without cells as corrupt): at the end
 *     the last two pages of a level share their children.
 *   the root: the table's own root page (rootpage in sqlite_schema), an
 *     empty leaf before; it gets the one page of the top level (a leaf when
 *     every row fits in one).
 * Every other page is new, appended after the file's last page in the
 * order the pages are done, skipping the lock-byte page (the page holding
 * byte 2^30 of the file, SQLite's PENDING_BYTE; never used). Rows are never
 * spilled onto overflow pages: a payload above the usable size less 35
 * (the largest a table leaf keeps in its cell) is refused, which a
 * GeoPackage row of the TIN layers is far from (about 230 bytes against
 * 4,061 with pages of 4,096). The commit writes the root pages, then the
 * header: the page count (offset 28), the change counter (24) and
 * version-valid-for (92) one up, so that the in-header size is valid, and
 * the library version (96). The freelist, the schema and its cookie are
 * untouched: no page is taken from the freelist and no table is made.
 *
 * One exception to append-only: a row whose payload is known only at the
 * end but must come first in rowid order (the R*Tree's root, node 1, of
 * a tree whose leaves are written as they are packed) is appended with a
 * placeholder of its final length, its place kept (a spot: page and
 * offset), and its bytes overwritten before the commit
 * (tt__sqlite_file_patch): in the root page kept for the commit, in the
 * queue, or with a pwrite into a page appended here (never into a page of
 * the file before the open, so cutting the file back still undoes all).
 *
 * Refused: a database in WAL mode (the pages would have to go through the
 * WAL), auto-vacuum or incremental vacuum (every new page would need its
 * pointer-map entry), an in-header size that disagrees with the file's,
 * a root page that is not an empty table leaf. Indexes are the caller's
 * business: a table with an index (UNIQUE, PRIMARY KEY other than INTEGER)
 * needs that index's B-tree too, which this file does not write.
 *
 * Crash and failure safety: nothing locks the file and nothing journals the
 * writes. Until the commit only new pages beyond the old end are written,
 * and closing without a commit truncates them away (an I/O error or an
 * interruption leaves the database as it was); a crash during the commit
 * can leave the root pages and the header out of step. So this is for a
 * file no other connection has open, which is discarded unless the whole
 * write completes: the row writer (gpkg_rows.c) uses it only when its
 * caller says so (PAGES=YES: the command's temporary output, renamed only
 * on success). Durability is the caller's: no fsync here (the row writer's
 * last SQLite transaction syncs the file).
 *
 * Workload: one pass over the rows; per row a cell copy and a pointer;
 * the pages done are handed over (not copied) to a queue of up to 256,
 * written with one pwritev, and their writeback started at once
 * (sync_file_range, Linux: a hint, so that the caller's final sync has
 * little left to wait for). Memory: the queue (1 MiB with pages of 4 KiB)
 * and its spare buffers, a leaf and two pages of children for each
 * interior level of each open table, and one page per finished root until
 * the commit.
 */
#define _GNU_SOURCE 1 /* pwritev, sync_file_range */
#include "gdal/gpkg/sqlite_pages.h"

#include <sqlite3.h>

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/uio.h>
#include <unistd.h>

#define HEADER_BYTES 100
#define BUF_PAGES 256
#define MAX_LEVELS 20 /* SQLite's cursors descend at most 20 levels */
#define MAX_PAGE 0xfffffffeu

/* --- varints and big-endian integers -------------------------------------- */

static inline int varint_len(uint64_t v)
{
  if (v <= 0x7f)
    return 1;
  if (v <= 0x3fff)
    return 2;
  if (v <= 0x1fffff)
    return 3;
  if (v >> 56)
    return 9;
  int n = 4;
  for (v >>= 28; v; v >>= 7)
    n++;
  return n;
}

/* SQLite's varint: 7 bits a byte, most significant first, the high bit set
 * on every byte but the last; a ninth byte holds 8 bits. */
static inline int put_varint(unsigned char *p, uint64_t v)
{
  if (v <= 0x7f) {
    p[0] = (unsigned char)v;
    return 1;
  }
  if (v <= 0x3fff) {
    p[0] = (unsigned char)(0x80 | (v >> 7));
    p[1] = (unsigned char)(v & 0x7f);
    return 2;
  }
  if (v >> 56) {
    p[8] = (unsigned char)v;
    v >>= 8;
    for (int i = 7; i >= 0; i--) {
      p[i] = (unsigned char)(0x80 | (v & 0x7f));
      v >>= 7;
    }
    return 9;
  }
  int n = varint_len(v);
  for (int i = n - 1; i >= 0; i--) {
    p[i] = (unsigned char)(0x80 | (v & 0x7f));
    v >>= 7;
  }
  p[n - 1] &= 0x7f;
  return n;
}

static void put_be16(unsigned char *p, unsigned v)
{
  p[0] = (unsigned char)(v >> 8);
  p[1] = (unsigned char)v;
}

static void put_be32(unsigned char *p, uint32_t v)
{
  p[0] = (unsigned char)(v >> 24);
  p[1] = (unsigned char)(v >> 16);
  p[2] = (unsigned char)(v >> 8);
  p[3] = (unsigned char)v;
}

static unsigned get_be16(const unsigned char *p)
{
  return (unsigned)p[0] << 8 | p[1];
}

static uint32_t get_be32(const unsigned char *p)
{
  return (uint32_t)p[0] << 24 | (uint32_t)p[1] << 16 | (uint32_t)p[2] << 8 |
         p[3];
}

/* --- records -------------------------------------------------------------- */

int tt__sqlite_affinity(const char *t)
{
  if (!t || !*t)
    return TT__AFF_BLOB;
  /* the rules in order; substrings, any case */
  char up[256];
  size_t n = 0;
  for (; t[n] && n + 1 < sizeof up; n++)
    up[n] = (char)((t[n] >= 'a' && t[n] <= 'z') ? t[n] - 32 : t[n]);
  up[n] = '\0';
  if (strstr(up, "INT"))
    return TT__AFF_INTEGER;
  if (strstr(up, "CHAR") || strstr(up, "CLOB") || strstr(up, "TEXT"))
    return TT__AFF_TEXT;
  if (strstr(up, "BLOB"))
    return TT__AFF_BLOB;
  if (strstr(up, "REAL") || strstr(up, "FLOA") || strstr(up, "DOUB"))
    return TT__AFF_REAL;
  return TT__AFF_NUMERIC;
}

size_t tt__sqlite_record(unsigned char *out, size_t cap,
                         const tt__sqlite_value *v, int n, int format)
{
  if (n < 0 || n > TT__SQLITE_REC_COLS)
    return 0;
  size_t need = 8;
  for (int k = 0; k < n; k++)
    need += 8 + (v[k].type == TT__SQV_BLOB || v[k].type == TT__SQV_TEXT
                     ? v[k].n : 0);
  unsigned char small[1024];
  unsigned char *body = need <= sizeof small ? small : malloc(need);
  if (!body)
    return 0;
  tt__sqlite_rec r;
  tt__sqlite_rec_begin(&r, body, format);
  for (int k = 0; k < n; k++)
    tt__sqlite_rec_value(&r, &v[k]);
  const unsigned char *head;
  size_t nh = tt__sqlite_rec_head(&r, &head), len = 0;
  if (nh + r.nb <= cap) {
    memcpy(out, head, nh);
    memcpy(out + nh, body, r.nb);
    len = nh + r.nb;
  }
  if (body != small)
    free(body);
  return len;
}

size_t tt__sqlite_max_payload(size_t usable)
{
  return usable - 35;
}

/* --- the file ------------------------------------------------------------- */

typedef struct root_page {
  uint32_t pgno;
  unsigned char *page;
} root_page;

struct tt__sqlite_file {
  tt_context *ctx;
  char *path;
  int fd;
  size_t page_size, usable;
  int format;
  unsigned char header[HEADER_BYTES];
  uint32_t orig_pages; /* pages at the open */
  off_t orig_bytes;
  uint32_t next;       /* the next page to append */
  uint32_t lock_page;  /* never used; 0: beyond any page number */
  /* pages buf_first .. buf_first + buf_n - 1, handed over, not yet
   * written; spare page buffers */
  unsigned char *buf[BUF_PAGES];
  uint32_t buf_first;
  size_t buf_n;
  unsigned char *spare[BUF_PAGES + 8];
  size_t nspare;
  root_page *roots;
  size_t nroots, cap_roots;
  tt__sqlite_table *tables; /* begun, not finished */
  int committed, failed;
};

static tt_status io_error(tt__sqlite_file *f, const char *what)
{
  f->failed = 1;
  return tt__error(f->ctx, TT_ERR_IO, "%s: %s: %s", f->path, what,
                   strerror(errno));
}

static int pwrite_all(int fd, const unsigned char *p, size_t n, off_t off)
{
  while (n) {
    ssize_t w = pwrite(fd, p, n, off);
    if (w < 0 && errno == EINTR)
      continue;
    if (w <= 0) {
      if (w == 0)
        errno = EIO;
      return 0;
    }
    p += w;
    n -= (size_t)w;
    off += w;
  }
  return 1;
}

static int pread_all(int fd, unsigned char *p, size_t n, off_t off)
{
  while (n) {
    ssize_t r = pread(fd, p, n, off);
    if (r < 0 && errno == EINTR)
      continue;
    if (r <= 0) {
      if (r == 0)
        errno = EIO;
      return 0;
    }
    p += r;
    n -= (size_t)r;
    off += r;
  }
  return 1;
}

static off_t page_offset(const tt__sqlite_file *f, uint32_t pgno)
{
  return (off_t)(pgno - 1) * (off_t)f->page_size;
}

/* A page buffer: a spare one, else a new one (zeroed: the reserved bytes
 * at the end of a page are never written and stay zero). */
static unsigned char *page_get(tt__sqlite_file *f)
{
  if (f->nspare)
    return f->spare[--f->nspare];
  return calloc(1, f->page_size);
}

static void page_put(tt__sqlite_file *f, unsigned char *page)
{
  if (f->nspare < sizeof f->spare / sizeof f->spare[0])
    f->spare[f->nspare++] = page;
  else
    free(page);
}

static tt_status flush(tt__sqlite_file *f)
{
  if (!f->buf_n)
    return TT_OK;
  struct iovec iov[BUF_PAGES];
  for (size_t k = 0; k < f->buf_n; k++) {
    iov[k].iov_base = f->buf[k];
    iov[k].iov_len = f->page_size;
  }
  /* one call for them all, unless the system writes less */
  size_t first = 0;
  off_t off = page_offset(f, f->buf_first);
  while (first < f->buf_n) {
    ssize_t w = pwritev(f->fd, iov + first, (int)(f->buf_n - first), off);
    if (w < 0 && errno == EINTR)
      continue;
    if (w <= 0) {
      if (w == 0)
        errno = EIO;
      return io_error(f, "cannot write the database pages");
    }
    size_t whole = (size_t)w / f->page_size;
    if ((size_t)w % f->page_size) { /* a page in part: the rest of it */
      size_t part = (size_t)w % f->page_size;
      if (!pwrite_all(f->fd, f->buf[first + whole] + part,
                      f->page_size - part, off + w))
        return io_error(f, "cannot write the database pages");
      whole++;
    }
    first += whole;
    off += (off_t)(whole * f->page_size);
  }
#ifdef SYNC_FILE_RANGE_WRITE
  /* Starts writing them to the disk now, without waiting: the sync at the
   * end (the caller's) then has less left to wait for. A hint only. */
  (void)sync_file_range(f->fd, page_offset(f, f->buf_first),
                        (off_t)(f->buf_n * f->page_size),
                        SYNC_FILE_RANGE_WRITE);
#endif
  for (size_t k = 0; k < f->buf_n; k++)
    page_put(f, f->buf[k]);
  f->buf_n = 0;
  return TT_OK;
}

/* Appends *page (page_size bytes), handed over, as the next page: its
 * number in *pgno; *page becomes a spare buffer to fill next (NULL when
 * out of memory: then an error). */
static tt_status page_out(tt__sqlite_file *f, unsigned char **page,
                          uint32_t *pgno)
{
  if (f->failed)
    return tt__error(f->ctx, TT_ERR_IO, "%s: the page write failed before",
                     f->path);
  if (f->next > MAX_PAGE)
    return tt__error(f->ctx, TT_ERR_IO, "%s: more than %u pages", f->path,
                     MAX_PAGE);
  tt_status s = TT_OK;
  if (f->buf_n && (f->buf_n == BUF_PAGES ||
                   f->buf_first + (uint32_t)f->buf_n != f->next))
    s = flush(f);
  if (s != TT_OK)
    return s;
  if (!f->buf_n)
    f->buf_first = f->next;
  f->buf[f->buf_n++] = *page;
  *page = page_get(f);
  *pgno = f->next++;
  if (f->next == f->lock_page)
    f->next++;
  if (!*page)
    return tt__error(f->ctx, TT_ERR_NOMEM, "out of memory");
  return TT_OK;
}

tt_status tt__sqlite_file_open(tt_context *ctx, const char *path,
                               tt__sqlite_file **out)
{
  *out = NULL;
  tt__sqlite_file *f = calloc(1, sizeof *f);
  if (!f)
    return tt__error(ctx, TT_ERR_NOMEM, "out of memory");
  f->ctx = ctx;
  f->fd = -1;
  f->path = malloc(strlen(path) + 1);
  if (!f->path) {
    free(f);
    return tt__error(ctx, TT_ERR_NOMEM, "out of memory");
  }
  strcpy(f->path, path);
  tt_status s = TT_OK;
  f->fd = open(path, O_RDWR | O_CLOEXEC);
  if (f->fd < 0) {
    s = io_error(f, "cannot open the database");
    goto fail;
  }
  struct stat sb;
  if (fstat(f->fd, &sb) != 0) {
    s = io_error(f, "cannot read the database's size");
    goto fail;
  }
  const unsigned char *h = f->header;
  if (!pread_all(f->fd, f->header, HEADER_BYTES, 0) ||
      memcmp(h, "SQLite format 3", 16) != 0) {
    s = tt__error(ctx, TT_ERR_FORMAT, "%s: not an SQLite database", path);
    goto fail;
  }
  unsigned ps = get_be16(h + 16);
  f->page_size = ps == 1 ? 65536 : ps;
  if (f->page_size < 512 || f->page_size > 65536 ||
      (f->page_size & (f->page_size - 1)) != 0 || h[21] != 64 ||
      h[22] != 32 || h[23] != 32 || f->page_size - h[20] < 480) {
    s = tt__error(ctx, TT_ERR_FORMAT, "%s: unexpected SQLite header (page "
                  "size %zu, %u reserved bytes)", path, f->page_size, h[20]);
    goto fail;
  }
  f->usable = f->page_size - h[20];
  if (h[18] != 1 || h[19] != 1) {
    s = tt__error(ctx, TT_ERR_FORMAT, "%s: the database is in WAL mode "
                  "(file format %u/%u)", path, h[18], h[19]);
    goto fail;
  }
  if (get_be32(h + 52) != 0) {
    s = tt__error(ctx, TT_ERR_FORMAT, "%s: the database has auto-vacuum "
                  "(pointer-map pages)", path);
    goto fail;
  }
  f->format = (int)get_be32(h + 44);
  uint32_t in_header = get_be32(h + 28);
  if (in_header == 0 || memcmp(h + 24, h + 92, 4) != 0)
    in_header = (uint32_t)(sb.st_size / (off_t)f->page_size);
  if ((off_t)in_header * (off_t)f->page_size != sb.st_size) {
    s = tt__error(ctx, TT_ERR_FORMAT, "%s: %lld bytes, but the header says "
                  "%u pages of %zu", path, (long long)sb.st_size,
                  in_header, f->page_size);
    goto fail;
  }
  f->orig_pages = in_header;
  f->orig_bytes = sb.st_size;
  /* The lock-byte page: PENDING_BYTE, asked of SQLite (a test may move it;
   * 0 when the build has no test controls: the default, 2^30). */
  unsigned pending =
      (unsigned)sqlite3_test_control(SQLITE_TESTCTRL_PENDING_BYTE, 0);
  if (pending == 0)
    pending = 0x40000000u;
  f->lock_page = (uint32_t)(pending / f->page_size) + 1;
  f->next = f->orig_pages + 1;
  if (f->next == f->lock_page)
    f->next++;
  *out = f;
  return TT_OK;
fail:
  if (f->fd >= 0)
    close(f->fd);
  free(f->path);
  free(f);
  return s;
}

size_t tt__sqlite_file_page_size(const tt__sqlite_file *f)
{
  return f->page_size;
}

size_t tt__sqlite_file_usable(const tt__sqlite_file *f)
{
  return f->usable;
}

int tt__sqlite_file_format(const tt__sqlite_file *f)
{
  return f->format;
}

uint32_t tt__sqlite_file_page_count(const tt__sqlite_file *f)
{
  return f->next - 1;
}

static tt_status keep_root(tt__sqlite_file *f, uint32_t pgno,
                           const unsigned char *page)
{
  if (!tt__grow((void **)&f->roots, &f->cap_roots, f->nroots + 1,
                sizeof *f->roots))
    return tt__error(f->ctx, TT_ERR_NOMEM, "out of memory");
  unsigned char *copy = malloc(f->page_size);
  if (!copy)
    return tt__error(f->ctx, TT_ERR_NOMEM, "out of memory");
  memcpy(copy, page, f->page_size);
  f->roots[f->nroots].pgno = pgno;
  f->roots[f->nroots].page = copy;
  f->nroots++;
  return TT_OK;
}

tt_status tt__sqlite_file_commit(tt__sqlite_file *f)
{
  if (f->failed || f->committed)
    return tt__error(f->ctx, TT_ERR_INTERNAL, "%s: commit after a failure "
                     "or twice", f->path);
  if (f->tables)
    return tt__error(f->ctx, TT_ERR_INTERNAL, "%s: commit with a table not "
                     "finished", f->path);
  tt_status s = flush(f);
  if (s != TT_OK)
    return s;
  for (size_t k = 0; k < f->nroots; k++)
    if (!pwrite_all(f->fd, f->roots[k].page, f->page_size,
                    page_offset(f, f->roots[k].pgno)))
      return io_error(f, "cannot write a root page");
  unsigned char *h = f->header;
  uint32_t counter = get_be32(h + 24) + 1;
  put_be32(h + 24, counter);
  put_be32(h + 28, f->next - 1);
  put_be32(h + 92, counter);
  put_be32(h + 96, (uint32_t)sqlite3_libversion_number());
  if (!pwrite_all(f->fd, h, HEADER_BYTES, 0))
    return io_error(f, "cannot write the database header");
  f->committed = 1;
  return TT_OK;
}

static void table_free(tt__sqlite_table *t);

tt_status tt__sqlite_file_close(tt__sqlite_file *f)
{
  if (!f)
    return TT_OK;
  tt_status s = TT_OK;
  while (f->tables)
    table_free(f->tables);
  if (f->fd >= 0) {
    if (!f->committed && ftruncate(f->fd, f->orig_bytes) != 0)
      s = io_error(f, "cannot cut the database back to its size");
    if (close(f->fd) != 0 && s == TT_OK && f->committed)
      s = io_error(f, "cannot close the database");
  }
  for (size_t k = 0; k < f->nroots; k++)
    free(f->roots[k].page);
  free(f->roots);
  for (size_t k = 0; k < f->buf_n; k++)
    free(f->buf[k]);
  for (size_t k = 0; k < f->nspare; k++)
    free(f->spare[k]);
  free(f->path);
  free(f);
  return s;
}

/* --- tables --------------------------------------------------------------- */

typedef struct child {
  uint32_t pgno;
  int64_t key; /* the largest rowid under it */
} child;

/* An interior level: the page being filled (cur) and the last full one,
 * held back (prev). */
typedef struct level {
  child *cur, *prev;
  size_t cur_n, prev_n;
  size_t cur_bytes; /* header, pointers and cells of cur[0..cur_n-2] */
  int has_prev;
} level;

struct tt__sqlite_table {
  tt__sqlite_file *f;
  tt__sqlite_table *next;
  char *name;
  uint32_t root;
  unsigned char *leaf, *page; /* the leaf being filled; scratch */
  size_t nc, content; /* the leaf's cells, start of its content area */
  int64_t last;       /* the last rowid appended */
  uint64_t rows, leaves_out;
  tt__sqlite_spot *spot; /* a row's place, set when its leaf is done */
  uint32_t spot_offset;
  size_t max_payload, cap_children;
  level lv[MAX_LEVELS + 1]; /* 1..nlv; lv[0] unused (the leaves) */
  int nlv;
};

static void table_free(tt__sqlite_table *t)
{
  tt__sqlite_file *f = t->f;
  for (tt__sqlite_table **p = &f->tables; *p; p = &(*p)->next)
    if (*p == t) {
      *p = t->next;
      break;
    }
  for (int l = 1; l <= t->nlv; l++) {
    free(t->lv[l].cur);
    free(t->lv[l].prev);
  }
  if (t->leaf)
    page_put(f, t->leaf);
  if (t->page)
    page_put(f, t->page);
  free(t->name);
  free(t);
}

uint64_t tt__sqlite_table_rows(const tt__sqlite_table *t)
{
  return t->rows;
}

tt_status tt__sqlite_table_begin(tt__sqlite_file *f, const char *name,
                                 uint32_t root, tt__sqlite_table **out)
{
  *out = NULL;
  if (root < 2 || root > f->orig_pages || root == f->lock_page)
    return tt__error(f->ctx, TT_ERR_FORMAT, "%s: table %s: root page %u is "
                     "not a page of the database", f->path, name, root);
  for (size_t k = 0; k < f->nroots; k++)
    if (f->roots[k].pgno == root)
      return tt__error(f->ctx, TT_ERR_INTERNAL, "%s: root page %u written "
                       "twice", f->path, root);
  for (const tt__sqlite_table *o = f->tables; o; o = o->next)
    if (o->root == root)
      return tt__error(f->ctx, TT_ERR_INTERNAL, "%s: root page %u begun "
                       "twice", f->path, root);
  tt__sqlite_table *t = calloc(1, sizeof *t);
  if (!t)
    return tt__error(f->ctx, TT_ERR_NOMEM, "out of memory");
  t->f = f;
  t->root = root;
  t->name = malloc(strlen(name) + 1);
  t->leaf = page_get(f);
  t->page = page_get(f);
  if (!t->name || !t->leaf || !t->page) {
    free(t->name);
    free(t->leaf);
    free(t->page);
    free(t);
    return tt__error(f->ctx, TT_ERR_NOMEM, "out of memory");
  }
  memset(t->leaf, 0, f->page_size);
  strcpy(t->name, name);
  t->next = f->tables;
  f->tables = t;
  /* The root as it is: an empty table leaf (the table never had a row,
   * or had all deleted without being split). */
  if (!pread_all(f->fd, t->page, f->page_size, page_offset(f, root))) {
    tt_status s = io_error(f, "cannot read a root page");
    table_free(t);
    return s;
  }
  if (t->page[0] != 0x0D || get_be16(t->page + 3) != 0) {
    tt_status s = tt__error(f->ctx, TT_ERR_FORMAT, "%s: table %s: its root "
                            "page %u is not an empty table leaf (type %u, "
                            "%u cells)", f->path, name, root, t->page[0],
                            get_be16(t->page + 3));
    table_free(t);
    return s;
  }
  t->content = f->usable;
  t->max_payload = tt__sqlite_max_payload(f->usable);
  /* the most children an interior page can have: cells of 4 + 1 bytes
   * and their 2-byte pointers */
  t->cap_children = (f->usable - 12) / 7 + 2;
  *out = t;
  return TT_OK;
}

/* The leaf's header, and its free space zeroed (a recycled buffer holds an
 * older page there). */
static void leaf_header(tt__sqlite_table *t)
{
  unsigned char *p = t->leaf;
  size_t gap = 8 + 2 * t->nc;
  memset(p + gap, 0, t->content - gap);
  p[0] = 0x0D;
  put_be16(p + 1, 0);
  put_be16(p + 3, (unsigned)t->nc);
  put_be16(p + 5, t->content == 65536 ? 0 : (unsigned)t->content);
  p[7] = 0;
}

/* The interior page of children c[0..n) (n >= 2) into t->page. */
static void interior_page(tt__sqlite_table *t, const child *c, size_t n)
{
  unsigned char *p = t->page;
  size_t content = t->f->usable;
  memset(p, 0, t->f->page_size);
  p[0] = 0x05;
  put_be16(p + 3, (unsigned)(n - 1));
  put_be32(p + 8, c[n - 1].pgno);
  for (size_t i = 0; i + 1 < n; i++) {
    unsigned char cell[13];
    put_be32(cell, c[i].pgno);
    size_t len = 4 + (size_t)put_varint(cell + 4, (uint64_t)c[i].key);
    content -= len;
    memcpy(p + content, cell, len);
    put_be16(p + 12 + 2 * i, (unsigned)content);
  }
  put_be16(p + 5, content == 65536 ? 0 : (unsigned)content);
}

static size_t interior_cell(const child *c)
{
  return 2 + 4 + (size_t)varint_len((uint64_t)c->key);
}

static tt_status push_child(tt__sqlite_table *t, int l, uint32_t pgno,
                            int64_t key);

/* Writes the interior page of c[0..n) at level l and hands it to l + 1. */
static tt_status emit_interior(tt__sqlite_table *t, int l, const child *c,
                               size_t n)
{
  interior_page(t, c, n);
  uint32_t pgno = 0;
  tt_status s = page_out(t->f, &t->page, &pgno);
  return s == TT_OK ? push_child(t, l + 1, pgno, c[n - 1].key) : s;
}

/* A page of level l - 1 is done: it becomes a child at level l. */
static tt_status push_child(tt__sqlite_table *t, int l, uint32_t pgno,
                            int64_t key)
{
  if (l > MAX_LEVELS)
    return tt__error(t->f->ctx, TT_ERR_INTERNAL, "%s: table %s: B-tree "
                     "deeper than %d levels", t->f->path, t->name,
                     MAX_LEVELS);
  level *lv = &t->lv[l];
  if (l > t->nlv) {
    lv->cur = malloc(t->cap_children * sizeof *lv->cur);
    lv->prev = malloc(t->cap_children * sizeof *lv->prev);
    t->nlv = l;
    if (!lv->cur || !lv->prev)
      return tt__error(t->f->ctx, TT_ERR_NOMEM, "out of memory");
    lv->cur_bytes = 12;
  }
  if (lv->cur_n) {
    /* the last child becomes a cell when another comes after it */
    size_t add = interior_cell(&lv->cur[lv->cur_n - 1]);
    if (lv->cur_bytes + add > t->f->usable) {
      if (lv->has_prev) {
        tt_status s = emit_interior(t, l, lv->prev, lv->prev_n);
        if (s != TT_OK)
          return s;
      }
      child *tmp = lv->prev;
      lv->prev = lv->cur;
      lv->prev_n = lv->cur_n;
      lv->has_prev = 1;
      lv->cur = tmp;
      lv->cur_n = 0;
      lv->cur_bytes = 12;
    } else {
      lv->cur_bytes += add;
    }
  }
  lv->cur[lv->cur_n++] = (child){pgno, key};
  return TT_OK;
}

static tt_status emit_leaf(tt__sqlite_table *t)
{
  leaf_header(t);
  uint32_t pgno = 0;
  tt_status s = page_out(t->f, &t->leaf, &pgno);
  if (s != TT_OK)
    return s;
  if (t->spot) {
    t->spot->pgno = pgno;
    t->spot->offset = t->spot_offset;
    t->spot->known = 1;
    t->spot = NULL;
  }
  t->leaves_out++;
  t->nc = 0;
  t->content = t->f->usable;
  return push_child(t, 1, pgno, t->last);
}

/* Room for a cell of size bytes in the leaf (the leaf written out first
 * when it is full); its place returned. */
static tt_status cell_room(tt__sqlite_table *t, size_t size,
                           unsigned char **out)
{
  if (t->content < size + 8 + 2 * (t->nc + 1)) {
    tt_status s = emit_leaf(t);
    if (s != TT_OK)
      return s;
  }
  t->content -= size;
  put_be16(t->leaf + 8 + 2 * t->nc, (unsigned)t->content);
  t->nc++;
  t->rows++;
  *out = t->leaf + t->content;
  return TT_OK;
}

static tt_status row_checks(tt__sqlite_table *t, int64_t rowid, size_t n)
{
  if (t->rows && rowid <= t->last)
    return tt__error(t->f->ctx, TT_ERR_INTERNAL, "%s: table %s: rowid %lld "
                     "after %lld", t->f->path, t->name, (long long)rowid,
                     (long long)t->last);
  if (n > t->max_payload)
    return tt__error(t->f->ctx, TT_ERR_FORMAT, "%s: table %s: a row of %zu "
                     "bytes does not fit in a page (at most %zu without "
                     "overflow pages)", t->f->path, t->name, n,
                     t->max_payload);
  return TT_OK;
}

tt_status tt__sqlite_table_append2(tt__sqlite_table *t, int64_t rowid,
                                   const unsigned char *a, size_t na,
                                   const unsigned char *b, size_t nb)
{
  const size_t n = na + nb;
  if ((t->rows && rowid <= t->last) || n > t->max_payload)
    return row_checks(t, rowid, n);
  int lp = varint_len(n), lr = varint_len((uint64_t)rowid);
  unsigned char *p;
  tt_status s = cell_room(t, (size_t)(lp + lr) + n, &p);
  if (s != TT_OK)
    return s;
  p += put_varint(p, n);
  p += put_varint(p, (uint64_t)rowid);
  memcpy(p, a, na);
  if (nb)
    memcpy(p + na, b, nb);
  t->last = rowid;
  return TT_OK;
}

tt_status tt__sqlite_table_append2_spot(tt__sqlite_table *t, int64_t rowid,
                                        const unsigned char *a, size_t na,
                                        const unsigned char *b, size_t nb,
                                        tt__sqlite_spot *spot)
{
  spot->known = 0;
  if (t->spot)
    return tt__error(t->f->ctx, TT_ERR_INTERNAL, "%s: table %s: a second "
                     "row's place asked before the first's is known",
                     t->f->path, t->name);
  tt_status s = tt__sqlite_table_append2(t, rowid, a, na, b, nb);
  if (s != TT_OK)
    return s;
  /* the cell just made is the leaf's lowest: its sizes, then the payload */
  size_t n = na + nb;
  t->spot = spot;
  t->spot_offset = (uint32_t)(t->content + (size_t)varint_len(n) +
                              (size_t)varint_len((uint64_t)rowid));
  return TT_OK;
}

tt_status tt__sqlite_file_patch(tt__sqlite_file *f,
                                const tt__sqlite_spot *spot, size_t at,
                                const void *p, size_t n)
{
  if (f->failed || f->committed || !spot->known ||
      spot->offset + at + n > f->usable)
    return tt__error(f->ctx, TT_ERR_INTERNAL, "%s: cannot patch page %u "
                     "at %zu (%s)", f->path, spot->pgno,
                     (size_t)spot->offset + at,
                     !spot->known ? "its place is not known yet"
                                  : "after a failure, a commit or past the "
                                    "page");
  size_t off = spot->offset + at;
  for (size_t k = 0; k < f->nroots; k++)
    if (f->roots[k].pgno == spot->pgno) {
      memcpy(f->roots[k].page + off, p, n);
      return TT_OK;
    }
  if (f->buf_n && spot->pgno >= f->buf_first &&
      spot->pgno - f->buf_first < f->buf_n) {
    memcpy(f->buf[spot->pgno - f->buf_first] + off, p, n);
    return TT_OK;
  }
  if (spot->pgno <= f->orig_pages || spot->pgno >= f->next)
    return tt__error(f->ctx, TT_ERR_INTERNAL, "%s: page %u is not a page "
                     "written here", f->path, spot->pgno);
  if (!pwrite_all(f->fd, p, n, page_offset(f, spot->pgno) + (off_t)off))
    return io_error(f, "cannot patch a page");
  return TT_OK;
}

tt_status tt__sqlite_table_append_int(tt__sqlite_table *t, int64_t rowid,
                                      int64_t value)
{
  /* the record of NULL and value: a header of 3 bytes, the value's bytes */
  tt__sqlite_rec r;
  unsigned char body[16];
  tt__sqlite_rec_begin(&r, body, t->f->format);
  tt__sqlite_rec_null(&r);
  tt__sqlite_rec_int(&r, value);
  const size_t n = 3 + r.nb;
  if (t->rows && rowid <= t->last)
    return row_checks(t, rowid, n);
  int lr = varint_len((uint64_t)rowid);
  unsigned char *p;
  tt_status s = cell_room(t, 1 + (size_t)lr + n, &p);
  if (s != TT_OK)
    return s;
  *p++ = (unsigned char)n; /* a payload of at most 11 bytes */
  p += put_varint(p, (uint64_t)rowid);
  p[0] = 3;
  p[1] = 0;
  p[2] = r.head[10];
  memcpy(p + 3, body, r.nb);
  t->last = rowid;
  return TT_OK;
}

tt_status tt__sqlite_table_append(tt__sqlite_table *t, int64_t rowid,
                                  const unsigned char *payload, size_t n)
{
  return tt__sqlite_table_append2(t, rowid, payload, n, NULL, 0);
}

/* Bytes of an interior page of c[0..n). */
static size_t interior_bytes(const child *c, size_t n)
{
  size_t b = 12;
  for (size_t i = 0; i + 1 < n; i++)
    b += interior_cell(&c[i]);
  return b;
}

tt_status tt__sqlite_table_finish(tt__sqlite_table *t)
{
  tt__sqlite_file *f = t->f;
  tt_status s = TT_OK;
  if (t->leaves_out == 0) {
    if (t->nc) { /* every row in the root leaf */
      leaf_header(t);
      s = keep_root(f, t->root, t->leaf);
      if (s == TT_OK && t->spot) {
        t->spot->pgno = t->root;
        t->spot->offset = t->spot_offset;
        t->spot->known = 1;
        t->spot = NULL;
      }
    }
    table_free(t);
    return s;
  }
  s = emit_leaf(t); /* the last leaf has a row: it began with one */
  for (int l = 1; s == TT_OK; l++) {
    level *lv = &t->lv[l];
    if (!lv->has_prev) { /* the top: every child in one page, the root */
      if (lv->cur_n < 2) {
        s = tt__error(f->ctx, TT_ERR_INTERNAL, "%s: table %s: a root of "
                      "one child", f->path, t->name);
        break;
      }
      interior_page(t, lv->cur, lv->cur_n);
      s = keep_root(f, t->root, t->page);
      break;
    }
    if (lv->cur_n == 1) {
      /* a lone child: the two last pages share their children */
      size_t total = lv->prev_n + 1, k = total / 2 - 1;
      memmove(lv->cur + k, lv->cur, sizeof *lv->cur);
      memcpy(lv->cur, lv->prev + lv->prev_n - k, k * sizeof *lv->cur);
      lv->prev_n -= k;
      lv->cur_n += k;
      if (lv->prev_n < 2 || lv->cur_n < 2 ||
          interior_bytes(lv->cur, lv->cur_n) > f->usable) {
        s = tt__error(f->ctx, TT_ERR_INTERNAL, "%s: table %s: cannot share "
                      "the last interior pages", f->path, t->name);
        break;
      }
    }
    s = emit_interior(t, l, lv->prev, lv->prev_n);
    if (s == TT_OK)
      s = emit_interior(t, l, lv->cur, lv->cur_n);
  }
  table_free(t);
  return s;
}
