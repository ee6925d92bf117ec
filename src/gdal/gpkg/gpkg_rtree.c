/*
 * src/gdal/gpkg/ -- the GeoPackage fast path: a TIN's rows, SQLite database
 * pages, R-trees and a tiled run's streamed write, straight into the file
 * rather than through OGR.
 *
 * gpkg_rtree.c -- bulk-loading the R-tree spatial index of a GeoPackage
 * feature table, on the closed file, with the sqlite3 C API.
 *
 * GDAL 3.6 fills a GPKG R-tree by inserting the features one by one through
 * SQLite's R*Tree module (about 11 us each). Here the tree is packed in
 * memory instead and its nodes are written straight into the shadow tables
 * the module keeps:
 *   rtree_<t>_<c>_node    (nodeno, data): one blob per node, all of the size
 *                         the module chose when the table was created (read
 *                         back from node 1). Blob layout, big-endian: 2 bytes
 *                         tree depth (root only; 0 elsewhere), 2 bytes cell
 *                         count, then cells of an 8-byte rowid (leaves) or
 *                         child node number (inner nodes) and minx maxx miny
 *                         maxy as 32-bit floats.
 *   rtree_<t>_<c>_rowid   (rowid, nodeno): the leaf holding each feature.
 *   rtree_<t>_<c>_parent  (nodeno, parentnode): every node but the root.
 * The root is node 1. Boxes come from the GeoPackage geometry blobs: the
 * header envelope when there is one, else the WKB (GDAL writes no envelope
 * for points). NULL and empty geometries are not indexed, as the triggers of
 * the standard do. Doubles become floats rounded outward exactly as the
 * module rounds the values it is given, so a row written here equals the
 * row an INSERT or a trigger would write.
 *
 * Packing is Sort-Tile-Recursive, level by level (rtree_pack.c); ties
 * break on the rowid: the same table gives the same file.
 *
 * tt_gpkg_build_rtree() does everything in one IMMEDIATE transaction: the
 * virtual table, its nodes, the triggers of the standard (the seven of
 * GeoPackage 1.4 in a 1.4 file, the six of 1.2.1-1.3 otherwise; see
 * trigger_sql()), the gpkg_extensions row, then SQLite's rtreecheck() on
 * the result; only then COMMIT. Any failure or interruption rolls back and
 * leaves the file as it was. tt__gpkg_rtree_from_boxes() (gpkg_rtree.h)
 * does the same inside a transaction of its caller's, from boxes its caller
 * knows, with rtreecheck() only on request: the row writer builds the
 * indexes of its own rows that way, and the tests run the check. The
 * packing needs no database (tt__rtree_pack()): the row writer packs on
 * its second thread while SQLite inserts rows, and hands the packed tree
 * over. The page writer's trees, written with SQLite closed, are made
 * empty here (tt__gpkg_rtree_create_empty: the virtual table, triggers,
 * gpkg_extensions row, and the shadow tables' root pages) and filled by
 * gpkg_rtree_pages.c.
 *
 * Workload: one sequential scan of the table, an O(n log n) sort, one blob
 * per 51 features and one %_rowid row per feature; memory 24 bytes per
 * feature and as much again for the packing.
 */
#include "gdal/gpkg/gpkg_rtree.h"
#include "gdal/gpkg/rtree_pack.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#define WKB_MAX_NESTING 32
#define LINK_BATCH 128   /* %_rowid rows per INSERT statement */

/* One cell: a feature (leaves) or a child node (inner levels). */
typedef tt__rtree_box rt_item;

typedef struct rt_link {
  int64_t rowid, nodeno;
} rt_link;

typedef struct rt_build {
  tt_context *ctx;
  sqlite3 *db;
  const char *path;
  char *table, *column, *fid; /* as stored in the file */
  char *rtree;                /* rtree_<t>_<c> */
  tt_progress_fn progress;
  void *progress_arg;
  rt_item *items;
  size_t nitems, cap_items;
  rt_link *links; /* %_rowid rows */
  size_t nlinks;
  size_t node_size, node_cap; /* bytes per node blob, cells per node */
  unsigned char *blob;
  sqlite3_stmt *ins_node, *ins_parent, *ins_rowid, *ins_rowid_batch;
  sqlite3_stmt *ins_node_batch; /* %_rowid rows of implicit rowids */
  size_t nodes_written, nodes_total;
  int gpkg_version; /* PRAGMA user_version: 10400 for 1.4.0 */
} rt_build;

/* --- small helpers -------------------------------------------------------- */

static tt_status db_error(rt_build *b, tt_status s, const char *what)
{
  return tt__error(b->ctx, s, "%s: table %s: %s: %s", b->path,
                   b->table ? b->table : "?", what,
                   b->db ? sqlite3_errmsg(b->db) : "no database");
}

/* Runs sql (owned by sqlite3_malloc, freed here). */
static tt_status exec_owned(rt_build *b, char *sql, const char *what)
{
  if (!sql)
    return tt__error(b->ctx, TT_ERR_NOMEM, "%s: out of memory", b->path);
  int rc = sqlite3_exec(b->db, sql, NULL, NULL, NULL);
  sqlite3_free(sql);
  return rc == SQLITE_OK ? TT_OK : db_error(b, TT_ERR_IO, what);
}

static tt_status prepare_owned(rt_build *b, char *sql, sqlite3_stmt **out,
                               const char *what)
{
  if (!sql)
    return tt__error(b->ctx, TT_ERR_NOMEM, "%s: out of memory", b->path);
  int rc = sqlite3_prepare_v2(b->db, sql, -1, out, NULL);
  sqlite3_free(sql);
  return rc == SQLITE_OK ? TT_OK : db_error(b, TT_ERR_IO, what);
}

static char *dup_text(const unsigned char *s)
{
  size_t n = strlen((const char *)s);
  char *d = malloc(n + 1);
  if (d)
    memcpy(d, s, n + 1);
  return d;
}

static tt_status report(rt_build *b, double complete)
{
  if (b->progress && !b->progress(complete, "indexing", b->progress_arg))
    return tt__error(b->ctx, TT_ERR_INTERRUPTED, "%s: table %s: building "
                     "the spatial index was interrupted", b->path, b->table);
  return TT_OK;
}

#define round_down tt__rtree_down
#define round_up tt__rtree_up

/* --- GeoPackage geometry blobs -------------------------------------------- */

typedef struct wkb_reader {
  const unsigned char *p;
  size_t len, pos;
} wkb_reader;

static int rd_u32(wkb_reader *r, int little, uint32_t *out)
{
  if (r->len - r->pos < 4)
    return 0;
  const unsigned char *q = r->p + r->pos;
  *out = little ? (uint32_t)q[0] | (uint32_t)q[1] << 8 |
                      (uint32_t)q[2] << 16 | (uint32_t)q[3] << 24
                : (uint32_t)q[3] | (uint32_t)q[2] << 8 |
                      (uint32_t)q[1] << 16 | (uint32_t)q[0] << 24;
  r->pos += 4;
  return 1;
}

static int rd_f64(wkb_reader *r, int little, double *out)
{
  if (r->len - r->pos < 8)
    return 0;
  uint64_t u = 0;
  const unsigned char *q = r->p + r->pos;
  for (int i = 0; i < 8; i++)
    u |= (uint64_t)q[little ? i : 7 - i] << (8 * i);
  memcpy(out, &u, sizeof *out);
  r->pos += 8;
  return 1;
}

typedef struct bounds {
  double minx, maxx, miny, maxy;
  int any; /* a non-empty point was seen */
} bounds;

static void extend(bounds *bx, double x, double y)
{
  if (!bx->any) {
    bx->minx = bx->maxx = x;
    bx->miny = bx->maxy = y;
    bx->any = 1;
    return;
  }
  if (x < bx->minx) bx->minx = x;
  if (x > bx->maxx) bx->maxx = x;
  if (y < bx->miny) bx->miny = y;
  if (y > bx->maxy) bx->maxy = y;
}

/* n points of dims coordinates; a point whose x or y is NaN is empty. */
static int wkb_points(wkb_reader *r, int little, uint32_t n, int dims,
                      bounds *bx)
{
  if ((r->len - r->pos) / (size_t)(8 * dims) < n)
    return 0;
  for (uint32_t i = 0; i < n; i++) {
    double c[4];
    for (int k = 0; k < dims; k++)
      if (!rd_f64(r, little, &c[k]))
        return 0;
    if (!isnan(c[0]) && !isnan(c[1])) {
      if (!isfinite(c[0]) || !isfinite(c[1]))
        return 0;
      extend(bx, c[0], c[1]);
    }
  }
  return 1;
}

/* One WKB geometry (ISO or 0x80000000/0x40000000-flagged types): points,
 * curves of straight segments, polygons, triangles and their collections.
 * Returns 0 when malformed or of a type without straight edges. */
static int wkb_geometry(wkb_reader *r, int nesting, bounds *bx)
{
  if (nesting > WKB_MAX_NESTING || r->pos >= r->len)
    return 0;
  unsigned char order = r->p[r->pos++];
  if (order > 1)
    return 0;
  int little = order == 1;
  uint32_t type;
  if (!rd_u32(r, little, &type))
    return 0;
  int dims = 2;
  if (type & 0x80000000u)
    dims++;
  if (type & 0x40000000u)
    dims++;
  if (type & 0x20000000u) /* EWKB SRID: not GeoPackage */
    return 0;
  type &= 0x0fffffffu;
  if (type >= 1000 && type < 4000) {
    dims += type / 1000 == 3 ? 2 : 1;
    type %= 1000;
  }
  if (dims > 4)
    return 0;
  uint32_t n;
  switch (type) {
  case 1: /* point */
    return wkb_points(r, little, 1, dims, bx);
  case 2: /* linestring */
    return rd_u32(r, little, &n) && wkb_points(r, little, n, dims, bx);
  case 3:  /* polygon */
  case 17: /* triangle */
    if (!rd_u32(r, little, &n) || (r->len - r->pos) / 4 < n)
      return 0;
    for (uint32_t i = 0; i < n; i++) {
      uint32_t np;
      if (!rd_u32(r, little, &np) || !wkb_points(r, little, np, dims, bx))
        return 0;
    }
    return 1;
  case 4: case 5: case 6: case 7: /* multi*, geometry collection */
  case 15: case 16:               /* polyhedral surface, TIN */
    if (!rd_u32(r, little, &n) || (r->len - r->pos) / 5 < n)
      return 0;
    for (uint32_t i = 0; i < n; i++)
      if (!wkb_geometry(r, nesting + 1, bx))
        return 0;
    return 1;
  default:
    return 0;
  }
}

/* Box of a GeoPackage geometry blob: 1 with *bx set, 0 when the geometry is
 * empty, -1 when the blob is not a GeoPackage geometry this file reads. */
static int gpkg_box(const unsigned char *g, size_t len, bounds *bx)
{
  memset(bx, 0, sizeof *bx);
  if (len < 8 || g[0] != 'G' || g[1] != 'P' || g[2] != 0)
    return -1;
  unsigned flags = g[3];
  int little = flags & 1;
  unsigned env = (flags >> 1) & 7;
  if (env > 4)
    return -1;
  if (flags & 0x10) /* the empty flag */
    return 0;
  static const size_t env_doubles[5] = {0, 4, 6, 6, 8};
  wkb_reader r = {g, len, 8};
  if (env) {
    double e[4];
    for (int k = 0; k < 4; k++)
      if (!rd_f64(&r, little, &e[k]))
        return -1;
    if (len - 8 < env_doubles[env] * 8)
      return -1;
    if (isnan(e[0]) || isnan(e[1]) || isnan(e[2]) || isnan(e[3]))
      return 0;
    if (!(e[0] <= e[1]) || !(e[2] <= e[3]) || !isfinite(e[0]) ||
        !isfinite(e[1]) || !isfinite(e[2]) || !isfinite(e[3]))
      return -1;
    bx->minx = e[0];
    bx->maxx = e[1];
    bx->miny = e[2];
    bx->maxy = e[3];
    bx->any = 1;
    return 1;
  }
  if (flags & 0x20) /* extended (non-standard) geometry type */
    return -1;
  if (!wkb_geometry(&r, 0, bx))
    return -1;
  return bx->any ? 1 : 0;
}

/* --- reading the table ---------------------------------------------------- */

/* Finds the table and column as stored (case-insensitive match), the
 * integer primary key, and checks that no index exists yet. */
static tt_status describe(rt_build *b, const char *table, const char *column)
{
  sqlite3_stmt *st = NULL;
  tt_status s = prepare_owned(
      b,
      sqlite3_mprintf("SELECT table_name, column_name FROM "
                      "gpkg_geometry_columns WHERE lower(table_name) = "
                      "lower(%Q) AND lower(column_name) = lower(%Q)",
                      table, column),
      &st, "not a GeoPackage (no gpkg_geometry_columns)");
  if (s != TT_OK)
    goto done;
  if (sqlite3_step(st) != SQLITE_ROW) {
    s = tt__error(b->ctx, TT_ERR_ARG, "%s: table %s: no geometry column %s "
                  "in gpkg_geometry_columns", b->path, table, column);
    goto done;
  }
  free(b->table);
  b->table = dup_text(sqlite3_column_text(st, 0));
  b->column = dup_text(sqlite3_column_text(st, 1));
  sqlite3_finalize(st);
  st = NULL;
  if (!b->table || !b->column) {
    s = tt__error(b->ctx, TT_ERR_NOMEM, "%s: out of memory", b->path);
    goto done;
  }
  b->rtree = sqlite3_mprintf("rtree_%s_%s", b->table, b->column);
  if (!b->rtree) {
    s = tt__error(b->ctx, TT_ERR_NOMEM, "%s: out of memory", b->path);
    goto done;
  }

  /* The integer primary key: exactly one INTEGER column with pk = 1. */
  s = prepare_owned(b, sqlite3_mprintf("PRAGMA table_info(\"%w\")",
                                       b->table),
                    &st, "cannot read the table's columns");
  if (s != TT_OK)
    goto done;
  int npk = 0;
  while (sqlite3_step(st) == SQLITE_ROW) {
    if (sqlite3_column_int(st, 5) == 0)
      continue;
    npk++;
    const unsigned char *type = sqlite3_column_text(st, 2);
    if (type && sqlite3_stricmp((const char *)type, "INTEGER") == 0) {
      free(b->fid);
      b->fid = dup_text(sqlite3_column_text(st, 1));
    }
  }
  if (npk != 1 || !b->fid) {
    s = tt__error(b->ctx, TT_ERR_FORMAT, "%s: table %s has no INTEGER "
                  "PRIMARY KEY column", b->path, b->table);
    goto done;
  }
  sqlite3_finalize(st);
  st = NULL;

  /* No index yet: none of the names the virtual table, its shadow tables
   * or its triggers (any generation) would take, no gpkg_extensions row. */
  static const char *const suffixes[] = {
      "", "_node", "_parent", "_rowid", "_insert", "_update1", "_update2",
      "_update3", "_update4", "_update5", "_update6", "_update7", "_delete"};
  s = prepare_owned(b,
                    sqlite3_mprintf("SELECT name FROM sqlite_master WHERE "
                                    "lower(name) = lower(?1 || ?2)"),
                    &st, "cannot read the schema");
  if (s != TT_OK)
    goto done;
  for (size_t k = 0; k < sizeof suffixes / sizeof suffixes[0]; k++) {
    sqlite3_bind_text(st, 1, b->rtree, -1, SQLITE_STATIC);
    sqlite3_bind_text(st, 2, suffixes[k], -1, SQLITE_STATIC);
    if (sqlite3_step(st) == SQLITE_ROW) {
      s = tt__error(b->ctx, TT_ERR_EXISTS, "%s: table %s already has a "
                    "spatial index (%s exists)", b->path, b->table,
                    (const char *)sqlite3_column_text(st, 0));
      goto done;
    }
    sqlite3_reset(st);
  }
  sqlite3_finalize(st);
  st = NULL;
  if (sqlite3_table_column_metadata(b->db, NULL, "gpkg_extensions",
                                    "extension_name", NULL, NULL, NULL, NULL,
                                    NULL) == SQLITE_OK) {
    s = prepare_owned(
        b,
        sqlite3_mprintf("SELECT 1 FROM gpkg_extensions WHERE "
                        "lower(table_name) = lower(%Q) AND "
                        "lower(column_name) = lower(%Q) AND extension_name "
                        "= 'gpkg_rtree_index'",
                        b->table, b->column),
        &st, "cannot read gpkg_extensions");
    if (s != TT_OK)
      goto done;
    if (sqlite3_step(st) == SQLITE_ROW)
      s = tt__error(b->ctx, TT_ERR_EXISTS, "%s: table %s already has a "
                    "gpkg_rtree_index row in gpkg_extensions", b->path,
                    b->table);
  }
done:
  sqlite3_finalize(st);
  return s;
}

static tt_status read_boxes(rt_build *b)
{
  sqlite3_stmt *st = NULL;
  int64_t maxfid = 0;
  tt_status s = prepare_owned(
      b, sqlite3_mprintf("SELECT max(\"%w\") FROM \"%w\"", b->fid, b->table),
      &st, "cannot read the table");
  if (s != TT_OK)
    goto done;
  if (sqlite3_step(st) == SQLITE_ROW)
    maxfid = sqlite3_column_int64(st, 0);
  sqlite3_finalize(st);
  st = NULL;

  s = prepare_owned(b,
                    sqlite3_mprintf("SELECT \"%w\", \"%w\" FROM \"%w\"",
                                    b->fid, b->column, b->table),
                    &st, "cannot read the table");
  if (s != TT_OK)
    goto done;
  int64_t next_report = maxfid / 100;
  int rc;
  while ((rc = sqlite3_step(st)) == SQLITE_ROW) {
    int64_t fid = sqlite3_column_int64(st, 0);
    if (b->progress && fid >= next_report && maxfid > 0) {
      next_report = fid + maxfid / 100 + 1;
      s = report(b, 0.6 * (double)fid / (double)maxfid);
      if (s != TT_OK)
        goto done;
    }
    int type = sqlite3_column_type(st, 1);
    if (type == SQLITE_NULL)
      continue;
    bounds bx;
    int got = -1;
    if (type == SQLITE_BLOB) {
      const void *g = sqlite3_column_blob(st, 1);
      got = gpkg_box(g, (size_t)sqlite3_column_bytes(st, 1), &bx);
    }
    if (got < 0) {
      s = tt__error(b->ctx, TT_ERR_FORMAT, "%s: table %s: feature %lld: "
                    "column %s is not a GeoPackage geometry this indexer "
                    "reads", b->path, b->table, (long long)fid, b->column);
      goto done;
    }
    if (got == 0)
      continue;
    if (!tt__grow((void **)&b->items, &b->cap_items, b->nitems + 1,
                  sizeof *b->items)) {
      s = tt__error(b->ctx, TT_ERR_NOMEM, "%s: table %s: out of memory for "
                    "%zu index entries", b->path, b->table, b->nitems + 1);
      goto done;
    }
    rt_item *it = &b->items[b->nitems++];
    it->id = fid;
    it->box[0] = round_down(bx.minx);
    it->box[1] = round_up(bx.maxx);
    it->box[2] = round_down(bx.miny);
    it->box[3] = round_up(bx.maxy);
  }
  if (rc != SQLITE_DONE)
    s = db_error(b, TT_ERR_IO, "cannot read the table");
done:
  sqlite3_finalize(st);
  return s;
}

/* --- packing -------------------------------------------------------------- */

static int cmp_link(const void *pa, const void *pb)
{
  const rt_link *a = pa, *b = pb;
  return (a->rowid > b->rowid) - (a->rowid < b->rowid);
}

/* Links in rowid order. Rowids are unique; when they are dense (a table
 * whose fids run 1..n, as the row writer's do) each goes straight to its
 * place, else qsort. */
static void sort_links(rt_link *links, size_t n)
{
  if (n < 2)
    return;
  int64_t lo = links[0].rowid, hi = links[0].rowid;
  for (size_t i = 1; i < n; i++) {
    if (links[i].rowid < lo) lo = links[i].rowid;
    if (links[i].rowid > hi) hi = links[i].rowid;
  }
  if ((uint64_t)(hi - lo) == n - 1) {
    rt_link *tmp = malloc(n * sizeof *tmp);
    if (tmp) {
      for (size_t i = 0; i < n; i++)
        tmp[links[i].rowid - lo] = links[i];
      memcpy(links, tmp, n * sizeof *tmp);
      free(tmp);
      return;
    }
  }
  qsort(links, n, sizeof *links, cmp_link);
}

static tt_status step_reset(rt_build *b, sqlite3_stmt *st, const char *what)
{
  int rc = sqlite3_step(st);
  sqlite3_reset(st);
  return rc == SQLITE_DONE ? TT_OK : db_error(b, TT_ERR_IO, what);
}

/* Writes node nodeno holding items[0..n) (depth written for the root) and
 * links its cells: %_rowid rows for a leaf, %_parent rows for children. */
static tt_status write_node(rt_build *b, int64_t nodeno, const rt_item *items,
                            size_t n, int leaf, int depth)
{
  tt__rtree_node_blob(b->blob, b->node_size, items, n,
                      nodeno == 1 ? (unsigned)depth : 0u);
  sqlite3_bind_int64(b->ins_node, 1, nodeno);
  sqlite3_bind_blob(b->ins_node, 2, b->blob, (int)b->node_size,
                    SQLITE_STATIC);
  tt_status s = step_reset(b, b->ins_node, "cannot write an index node");
  for (size_t i = 0; i < n && s == TT_OK; i++) {
    if (leaf) {
      b->links[b->nlinks].rowid = items[i].id;
      b->links[b->nlinks++].nodeno = nodeno;
    } else {
      sqlite3_bind_int64(b->ins_parent, 1, items[i].id);
      sqlite3_bind_int64(b->ins_parent, 2, nodeno);
      s = step_reset(b, b->ins_parent, "cannot write an index node parent");
    }
  }
  b->nodes_written++;
  if (s == TT_OK && b->nodes_written % 256 == 0)
    s = report(b, 0.6 + 0.3 * (double)b->nodes_written /
                            (double)b->nodes_total);
  return s;
}

size_t tt__gpkg_rtree_node_cap(sqlite3 *db)
{
  sqlite3_stmt *st = NULL;
  int page = 0;
  if (sqlite3_prepare_v2(db, "PRAGMA page_size", -1, &st, NULL) ==
          SQLITE_OK &&
      sqlite3_step(st) == SQLITE_ROW)
    page = sqlite3_column_int(st, 0);
  sqlite3_finalize(st);
  /* SQLite's R*Tree: nodes of the page size less 64 bytes, at most 51
   * cells (RTREE_MAXCELLS) */
  size_t size = page > 64 ? (size_t)page - 64 : 4 + 2 * TT__RTREE_CELL_BYTES;
  if (size > 4 + 51 * TT__RTREE_CELL_BYTES)
    size = 4 + 51 * TT__RTREE_CELL_BYTES;
  return (size - 4) / TT__RTREE_CELL_BYTES;
}

/* Writes the packed tree's nodes, parents and rowid map. */
static tt_status write_packed(rt_build *b, const tt__rtree_packed *pk)
{
  tt_status s = TT_OK;
  b->nlinks = 0;
  b->links = pk->nitems ? malloc(pk->nitems * sizeof *b->links) : NULL;
  if (pk->nitems && !b->links)
    return tt__error(b->ctx, TT_ERR_NOMEM, "%s: table %s: out of memory",
                     b->path, b->table);
  b->nodes_total = pk->nodes_total;
  for (int d = 0; d < pk->nlevels && s == TT_OK; d++) {
    const rt_item *level = pk->level[d];
    size_t n = pk->n[d];
    if (d == pk->nlevels - 1) { /* the root */
      s = write_node(b, 1, level, n, d == 0, d);
      break;
    }
    size_t ngroups = pk->n[d + 1];
    for (size_t g = 0; g < ngroups && s == TT_OK; g++) {
      size_t e0 = tt__rtree_group_start(g, n, ngroups);
      size_t e1 = tt__rtree_group_start(g + 1, n, ngroups);
      s = write_node(b, pk->base[d] + (int64_t)g, level + e0, e1 - e0,
                     d == 0, d);
    }
  }
  if (s != TT_OK)
    return s;
  /* %_rowid rows in rowid order: appends to its B-tree. */
  sort_links(b->links, b->nlinks);
  /* Rowids 1..n (the row writer's fids) into the empty %_rowid table: each
   * is SQLite's next one, so the inserts leave it to SQLite's append path
   * (no seek per row); others are given explicitly. */
  const int dense = b->nlinks && b->links[0].rowid == 1 &&
                    b->links[b->nlinks - 1].rowid == (int64_t)b->nlinks;
  size_t i = 0;
  for (; dense && i + LINK_BATCH <= b->nlinks && s == TT_OK;
       i += LINK_BATCH) {
    for (int k = 0; k < LINK_BATCH; k++)
      sqlite3_bind_int64(b->ins_node_batch, k + 1,
                         b->links[i + (size_t)k].nodeno);
    s = step_reset(b, b->ins_node_batch, "cannot write the index rowid map");
  }
  for (; i + LINK_BATCH <= b->nlinks && s == TT_OK; i += LINK_BATCH) {
    for (int k = 0; k < LINK_BATCH; k++) {
      const rt_link *l = &b->links[i + (size_t)k];
      sqlite3_bind_int64(b->ins_rowid_batch, 2 * k + 1, l->rowid);
      sqlite3_bind_int64(b->ins_rowid_batch, 2 * k + 2, l->nodeno);
    }
    s = step_reset(b, b->ins_rowid_batch,
                   "cannot write the index rowid map");
  }
  for (; i < b->nlinks && s == TT_OK; i++) {
    sqlite3_bind_int64(b->ins_rowid, 1, b->links[i].rowid);
    sqlite3_bind_int64(b->ins_rowid, 2, b->links[i].nodeno);
    s = step_reset(b, b->ins_rowid, "cannot write the index rowid map");
  }
  return s;
}

/* --- schema --------------------------------------------------------------- */

/* The triggers of the RTree Spatial Indexes extension, laid out line for
 * line as the standard prints its templates, identifiers double-quoted.
 * t: table, c: geometry column, i: integer primary key, r: rtree table.
 *   GeoPackage 1.4:       insert update2 update4 update5 update6 update7
 *                         delete (seven; update1 and update3 deprecated)
 *   GeoPackage 1.2.1-1.3: insert update1 update2 update3 update4 delete
 *                         (update3 as corrected in 1.2.1, the body of 1.4's
 *                         update5)
 * A file gets the set of the version it declares (PRAGMA user_version), as
 * GDAL does: GDAL before 3.7 knows only the older names, drops them by name
 * when it renames a layer or disables its index (and fails on the others),
 * and writes 1.2 files itself. */
enum { TR_INSERT, TR_UPDATE1, TR_UPDATE2, TR_UPDATE3, TR_UPDATE4, TR_UPDATE5,
       TR_UPDATE6, TR_UPDATE7, TR_DELETE };
static const int triggers_v14[] = {TR_INSERT, TR_UPDATE2, TR_UPDATE4,
                                   TR_UPDATE5, TR_UPDATE6, TR_UPDATE7,
                                   TR_DELETE};
static const int triggers_v13[] = {TR_INSERT, TR_UPDATE1, TR_UPDATE2,
                                   TR_UPDATE3, TR_UPDATE4, TR_DELETE};

#define NEW_BOX_END "  );\n"
#define NEW_BOX(c)                                                           \
  "    ST_MinX(NEW.\"" c "\"), ST_MaxX(NEW.\"" c "\"),\n"                   \
  "    ST_MinY(NEW.\"" c "\"), ST_MaxY(NEW.\"" c "\")\n"
static char *trigger_sql(int which, const char *t, const char *c,
                         const char *i, const char *r)
{
  switch (which) {
  case TR_INSERT:
    return sqlite3_mprintf(
        "CREATE TRIGGER \"%w_insert\" AFTER INSERT ON \"%w\"\n"
        "  WHEN (new.\"%w\" NOT NULL AND NOT ST_IsEmpty(NEW.\"%w\"))\n"
        "BEGIN\n"
        "  INSERT OR REPLACE INTO \"%w\" VALUES (\n"
        "    NEW.\"%w\",\n" NEW_BOX("%w") NEW_BOX_END
        "END",
        r, t, c, c, r, i, c, c, c, c);
  case TR_UPDATE1:
    return sqlite3_mprintf(
        "CREATE TRIGGER \"%w_update1\" AFTER UPDATE OF \"%w\" ON \"%w\"\n"
        "  WHEN OLD.\"%w\" = NEW.\"%w\" AND\n"
        "       (NEW.\"%w\" NOTNULL AND NOT ST_IsEmpty(NEW.\"%w\"))\n"
        "BEGIN\n"
        "  INSERT OR REPLACE INTO \"%w\" VALUES (\n"
        "    NEW.\"%w\",\n" NEW_BOX("%w") NEW_BOX_END
        "END",
        r, c, t, i, i, c, c, r, i, c, c, c, c);
  case TR_UPDATE2:
    return sqlite3_mprintf(
        "CREATE TRIGGER \"%w_update2\" AFTER UPDATE OF \"%w\" ON \"%w\"\n"
        "  WHEN OLD.\"%w\" = NEW.\"%w\" AND\n"
        "       (NEW.\"%w\" ISNULL OR ST_IsEmpty(NEW.\"%w\"))\n"
        "BEGIN\n"
        "  DELETE FROM \"%w\" WHERE id = OLD.\"%w\";\n"
        "END",
        r, c, t, i, i, c, c, r, i);
  case TR_UPDATE4:
    return sqlite3_mprintf(
        "CREATE TRIGGER \"%w_update4\" AFTER UPDATE ON \"%w\"\n"
        "  WHEN OLD.\"%w\" != NEW.\"%w\" AND\n"
        "       (NEW.\"%w\" ISNULL OR ST_IsEmpty(NEW.\"%w\"))\n"
        "BEGIN\n"
        "  DELETE FROM \"%w\" WHERE id IN (OLD.\"%w\", NEW.\"%w\");\n"
        "END",
        r, t, i, i, c, c, r, i, i);
  case TR_UPDATE3:
  case TR_UPDATE5:
    return sqlite3_mprintf(
        "CREATE TRIGGER \"%w_%s\" AFTER UPDATE ON \"%w\"\n"
        "  WHEN OLD.\"%w\" != NEW.\"%w\" AND\n"
        "       (NEW.\"%w\" NOTNULL AND NOT ST_IsEmpty(NEW.\"%w\"))\n"
        "BEGIN\n"
        "  DELETE FROM \"%w\" WHERE id = OLD.\"%w\";\n"
        "  INSERT OR REPLACE INTO \"%w\" VALUES (\n"
        "    NEW.\"%w\",\n" NEW_BOX("%w") NEW_BOX_END
        "END",
        r, which == TR_UPDATE3 ? "update3" : "update5", t, i, i, c, c, r, i,
        r, i, c, c, c, c);
  case TR_UPDATE6:
    return sqlite3_mprintf(
        "CREATE TRIGGER \"%w_update6\" AFTER UPDATE OF \"%w\" ON \"%w\"\n"
        "  WHEN OLD.\"%w\" = NEW.\"%w\" AND\n"
        "       (NEW.\"%w\" NOTNULL AND NOT ST_IsEmpty(NEW.\"%w\")) AND\n"
        "       (OLD.\"%w\" NOTNULL AND NOT ST_IsEmpty(OLD.\"%w\"))\n"
        "BEGIN\n"
        "  UPDATE \"%w\" SET\n"
        "    minx = ST_MinX(NEW.\"%w\"),\n"
        "    maxx = ST_MaxX(NEW.\"%w\"),\n"
        "    miny = ST_MinY(NEW.\"%w\"),\n"
        "    maxy = ST_MaxY(NEW.\"%w\")\n"
        "  WHERE id = NEW.\"%w\";\n"
        "END",
        r, c, t, i, i, c, c, c, c, r, c, c, c, c, i);
  case TR_UPDATE7:
    return sqlite3_mprintf(
        "CREATE TRIGGER \"%w_update7\" AFTER UPDATE OF \"%w\" ON \"%w\"\n"
        "  WHEN OLD.\"%w\" = NEW.\"%w\" AND\n"
        "       (NEW.\"%w\" NOTNULL AND NOT ST_IsEmpty(NEW.\"%w\")) AND\n"
        "       (OLD.\"%w\" ISNULL OR ST_IsEmpty(OLD.\"%w\"))\n"
        "BEGIN\n"
        "  INSERT INTO \"%w\" VALUES (\n"
        "    NEW.\"%w\",\n" NEW_BOX("%w") NEW_BOX_END
        "END",
        r, c, t, i, i, c, c, c, c, r, i, c, c, c, c);
  default:
    return sqlite3_mprintf(
        "CREATE TRIGGER \"%w_delete\" AFTER DELETE ON \"%w\"\n"
        "  WHEN old.\"%w\" NOT NULL\n"
        "BEGIN\n"
        "  DELETE FROM \"%w\" WHERE id = OLD.\"%w\";\n"
        "END",
        r, t, c, r, i);
  }
}
#undef NEW_BOX
#undef NEW_BOX_END

static tt_status create_schema(rt_build *b)
{
  tt_status s = exec_owned(
      b,
      sqlite3_mprintf("CREATE VIRTUAL TABLE \"%w\" USING rtree(id, minx, "
                      "maxx, miny, maxy)",
                      b->rtree),
      "cannot create the R-tree (is SQLite's R*Tree module there?)");
  int v14 = b->gpkg_version >= 10400;
  const int *set = v14 ? triggers_v14 : triggers_v13;
  size_t nset = v14 ? sizeof triggers_v14 / sizeof triggers_v14[0]
                    : sizeof triggers_v13 / sizeof triggers_v13[0];
  for (size_t k = 0; k < nset && s == TT_OK; k++)
    s = exec_owned(b, trigger_sql(set[k], b->table, b->column, b->fid,
                                  b->rtree),
                   "cannot create the R-tree triggers");
  if (s != TT_OK)
    return s;
  if (sqlite3_table_column_metadata(b->db, NULL, "gpkg_extensions",
                                    "extension_name", NULL, NULL, NULL, NULL,
                                    NULL) != SQLITE_OK) {
    s = exec_owned(b,
                   sqlite3_mprintf(
                       "CREATE TABLE gpkg_extensions (table_name TEXT, "
                       "column_name TEXT, extension_name TEXT NOT NULL, "
                       "definition TEXT NOT NULL, scope TEXT NOT NULL, "
                       "CONSTRAINT ge_tce UNIQUE (table_name, column_name, "
                       "extension_name))"),
                   "cannot create gpkg_extensions");
    if (s != TT_OK)
      return s;
  }
  s = exec_owned(
      b,
      sqlite3_mprintf("INSERT INTO gpkg_extensions (table_name, column_name, "
                      "extension_name, definition, scope) VALUES (%Q, %Q, "
                      "'gpkg_rtree_index', "
                      "'http://www.geopackage.org/spec/#extension_rtree', "
                      "'write-only')",
                      b->table, b->column),
      "cannot register the index in gpkg_extensions");
  if (s != TT_OK)
    return s;

  /* The node size SQLite chose (from the page size) and the capacity. */
  sqlite3_stmt *st = NULL;
  s = prepare_owned(b,
                    sqlite3_mprintf("SELECT length(data) FROM \"%w_node\" "
                                    "WHERE nodeno = 1",
                                    b->rtree),
                    &st, "cannot read the R-tree root");
  if (s != TT_OK)
    return s;
  int size = sqlite3_step(st) == SQLITE_ROW ? sqlite3_column_int(st, 0) : 0;
  sqlite3_finalize(st);
  if (size < 4 + 2 * TT__RTREE_CELL_BYTES || size > 65536)
    return tt__error(b->ctx, TT_ERR_INTERNAL, "%s: table %s: unexpected "
                     "R-tree node size %d", b->path, b->table, size);
  b->node_size = (size_t)size;
  b->node_cap = (b->node_size - 4) / TT__RTREE_CELL_BYTES;
  b->blob = malloc(b->node_size);
  if (!b->blob)
    return tt__error(b->ctx, TT_ERR_NOMEM, "%s: out of memory", b->path);

  s = exec_owned(b,
                 sqlite3_mprintf("DELETE FROM \"%w_node\"; DELETE FROM "
                                 "\"%w_parent\"; DELETE FROM \"%w_rowid\"",
                                 b->rtree, b->rtree, b->rtree),
                 "cannot clear the R-tree");
  if (s == TT_OK)
    s = prepare_owned(b,
                      sqlite3_mprintf("INSERT INTO \"%w_node\" (nodeno, data) "
                                      "VALUES (?, ?)",
                                      b->rtree),
                      &b->ins_node, "cannot write the R-tree");
  if (s == TT_OK)
    s = prepare_owned(b,
                      sqlite3_mprintf("INSERT INTO \"%w_parent\" (nodeno, "
                                      "parentnode) VALUES (?, ?)",
                                      b->rtree),
                      &b->ins_parent, "cannot write the R-tree");
  if (s == TT_OK)
    s = prepare_owned(b,
                      sqlite3_mprintf("INSERT INTO \"%w_rowid\" (rowid, "
                                      "nodeno) VALUES (?, ?)",
                                      b->rtree),
                      &b->ins_rowid, "cannot write the R-tree");
  if (s == TT_OK) {
    char *sql = sqlite3_mprintf("INSERT INTO \"%w_rowid\" (rowid, nodeno) "
                                "VALUES (?, ?)", b->rtree);
    for (int k = 1; sql && k < LINK_BATCH; k++) {
      char *more = sqlite3_mprintf("%s, (?, ?)", sql);
      sqlite3_free(sql);
      sql = more;
    }
    s = prepare_owned(b, sql, &b->ins_rowid_batch, "cannot write the R-tree");
  }
  if (s == TT_OK) {
    char *sql = sqlite3_mprintf("INSERT INTO \"%w_rowid\" (nodeno) VALUES "
                                "(?)", b->rtree);
    for (int k = 1; sql && k < LINK_BATCH; k++) {
      char *more = sqlite3_mprintf("%s, (?)", sql);
      sqlite3_free(sql);
      sql = more;
    }
    s = prepare_owned(b, sql, &b->ins_node_batch, "cannot write the R-tree");
  }
  return s;
}

/* SQLite's own consistency check of the tree, inside the transaction. */
static tt_status check_tree(rt_build *b)
{
  sqlite3_stmt *st = NULL;
  tt_status s = prepare_owned(b, sqlite3_mprintf("SELECT rtreecheck(%Q)",
                                                 b->rtree),
                              &st, "cannot run rtreecheck()");
  if (s != TT_OK)
    return s;
  if (sqlite3_step(st) != SQLITE_ROW) {
    s = db_error(b, TT_ERR_INTERNAL, "rtreecheck() failed");
  } else {
    const char *msg = (const char *)sqlite3_column_text(st, 0);
    if (!msg || strcmp(msg, "ok") != 0) {
      /* One line: the first finding (the check prints one per line). */
      const char *nl = msg ? strchr(msg, '\n') : NULL;
      int len = nl ? (int)(nl - msg) : msg ? (int)strlen(msg) : 0;
      s = tt__error(b->ctx, TT_ERR_INTERNAL, "%s: table %s: the R-tree "
                    "built fails rtreecheck(): %.*s%s", b->path, b->table,
                    len > 300 ? 300 : len, msg ? msg : "",
                    nl && nl[1] ? " (and more)" : "");
    }
  }
  sqlite3_finalize(st);
  return s;
}

/* The index of b->table's column from packed, else from b->items (read
 * from the table when from_table), in the open transaction of b->db. */
static tt_status build_in_transaction(rt_build *b, const char *table,
                                      const char *column, int from_table,
                                      const tt__rtree_packed *packed,
                                      int check)
{
  sqlite3_stmt *uv = NULL;
  if (sqlite3_prepare_v2(b->db, "PRAGMA user_version", -1, &uv, NULL) ==
          SQLITE_OK &&
      sqlite3_step(uv) == SQLITE_ROW)
    b->gpkg_version = sqlite3_column_int(uv, 0);
  sqlite3_finalize(uv);
  tt_status s = describe(b, table, column);
  if (s == TT_OK && from_table)
    s = read_boxes(b);
  if (s == TT_OK)
    s = report(b, 0.6);
  if (s == TT_OK)
    s = create_schema(b);
  /* Packed beforehand for nodes of another size (tt__gpkg_rtree_node_cap()
   * guessed wrong): packed again from its leaves (the order is total, so
   * the same tree as from the boxes). */
  tt__rtree_packed *own = NULL;
  if (s == TT_OK && packed && packed->node_cap != b->node_cap) {
    b->items = malloc((packed->nitems ? packed->nitems : 1) *
                      sizeof *b->items);
    if (!b->items)
      s = tt__error(b->ctx, TT_ERR_NOMEM, "%s: out of memory", b->path);
    else
      memcpy(b->items, packed->items, packed->nitems * sizeof *b->items);
    b->nitems = packed->nitems;
    packed = NULL;
  }
  if (s == TT_OK && !packed) {
    s = tt__rtree_pack_items(b->ctx, b->path, b->items, b->nitems,
                             b->node_cap, 2, &own);
    if (s == TT_OK)
      b->items = NULL; /* taken over */
    packed = own;
  }
  if (s == TT_OK)
    s = write_packed(b, packed);
  tt__rtree_packed_free(own);
  if (s == TT_OK)
    s = report(b, 0.9);
  if (s == TT_OK && check)
    s = check_tree(b);
  if (s == TT_OK)
    s = report(b, 0.99);
  sqlite3_finalize(b->ins_node);
  sqlite3_finalize(b->ins_parent);
  sqlite3_finalize(b->ins_rowid);
  sqlite3_finalize(b->ins_rowid_batch);
  sqlite3_finalize(b->ins_node_batch);
  b->ins_node = b->ins_parent = b->ins_rowid = b->ins_rowid_batch = NULL;
  b->ins_node_batch = NULL;
  return s;
}

static void build_free(rt_build *b)
{
  sqlite3_finalize(b->ins_node);
  sqlite3_finalize(b->ins_parent);
  sqlite3_finalize(b->ins_rowid);
  sqlite3_finalize(b->ins_rowid_batch);
  sqlite3_finalize(b->ins_node_batch);
  free(b->table);
  free(b->column);
  free(b->fid);
  sqlite3_free(b->rtree);
  free(b->items);
  free(b->links);
  free(b->blob);
}

tt_status tt__gpkg_rtree_from_boxes(tt_context *ctx, sqlite3 *db,
                                    const char *gpkg_path, const char *table,
                                    const char *geom_column,
                                    const tt__rtree_box *boxes, size_t n,
                                    const tt__rtree_packed *packed,
                                    int check, tt_progress_fn progress,
                                    void *progress_arg)
{
  rt_build b;
  memset(&b, 0, sizeof b);
  b.ctx = ctx;
  b.db = db;
  b.path = gpkg_path;
  b.progress = progress;
  b.progress_arg = progress_arg;
  tt_status s = TT_OK;
  b.table = malloc(strlen(table) + 1);
  b.items = packed ? NULL : malloc((n ? n : 1) * sizeof *b.items);
  if (!b.table || (!packed && !b.items)) {
    s = tt__error(ctx, TT_ERR_NOMEM, "%s: table %s: out of memory for %zu "
                  "index entries", gpkg_path, table, n);
    goto done;
  }
  memcpy(b.table, table, strlen(table) + 1);
  b.cap_items = n ? n : 1;
  if (!packed) {
    memcpy(b.items, boxes, n * sizeof *b.items);
    b.nitems = n;
  }
  s = build_in_transaction(&b, table, geom_column, 0, packed, check);
done:
  build_free(&b);
  return s;
}

tt_status tt_gpkg_build_rtree(tt_context *ctx, const char *gpkg_path,
                              const char *table, const char *geom_column,
                              tt_progress_fn progress, void *progress_arg)
{
  if (!gpkg_path || !table || !geom_column || !*table || !*geom_column)
    return tt__error(ctx, TT_ERR_ARG, "GeoPackage path, table and geometry "
                     "column must be given");
  rt_build b;
  memset(&b, 0, sizeof b);
  b.ctx = ctx;
  b.path = gpkg_path;
  b.progress = progress;
  b.progress_arg = progress_arg;
  b.table = malloc(strlen(table) + 1);
  if (!b.table)
    return tt__error(ctx, TT_ERR_NOMEM, "out of memory");
  memcpy(b.table, table, strlen(table) + 1);
  int in_transaction = 0;
  tt_status s = report(&b, 0.0);
  if (s != TT_OK)
    goto done;

  /* No SQLITE_OPEN_CREATE: a missing file is an error, not a new file. */
  if (sqlite3_open_v2(gpkg_path, &b.db, SQLITE_OPEN_READWRITE, NULL) !=
      SQLITE_OK) {
    s = db_error(&b, TT_ERR_IO, "cannot open");
    goto done;
  }
  sqlite3_extended_result_codes(b.db, 1);
  sqlite3_busy_timeout(b.db, 5000);
  if (sqlite3_exec(b.db, "BEGIN IMMEDIATE", NULL, NULL, NULL) != SQLITE_OK) {
    s = db_error(&b, TT_ERR_IO, "cannot start a transaction");
    goto done;
  }
  in_transaction = 1;

  s = build_in_transaction(&b, table, geom_column, 1, NULL, 1);
  if (s != TT_OK)
    goto done;
  if (sqlite3_exec(b.db, "COMMIT", NULL, NULL, NULL) != SQLITE_OK) {
    s = db_error(&b, TT_ERR_IO, "cannot commit the spatial index");
    goto done;
  }
  in_transaction = 0;
  if (progress)
    progress(1.0, "indexing", progress_arg); /* done: too late to stop */

done:
  if (in_transaction)
    sqlite3_exec(b.db, "ROLLBACK", NULL, NULL, NULL);
  if (b.db && sqlite3_close(b.db) != SQLITE_OK && s == TT_OK)
    s = db_error(&b, TT_ERR_IO, "cannot close");
  build_free(&b);
  return s;
}

/* --- the empty index the page writer fills, and its removal -------------- */

void tt__rtree_shadow_free(tt__rtree_shadow *sh)
{
  sqlite3_free(sh->rtree);
  memset(sh, 0, sizeof *sh);
}

/* The root page of shadow table rtree<suffix>, checked to be the module's
 * plain (INTEGER PRIMARY KEY, value) table. */
static tt_status shadow_root(rt_build *b, const char *suffix, uint32_t *root)
{
  sqlite3_stmt *st = NULL;
  char *name = sqlite3_mprintf("%s%s", b->rtree, suffix);
  tt_status s = name ? TT_OK
                     : tt__error(b->ctx, TT_ERR_NOMEM, "out of memory");
  if (s == TT_OK)
    s = prepare_owned(b,
                      sqlite3_mprintf("SELECT rootpage FROM sqlite_master "
                                      "WHERE type = 'table' AND name = %Q",
                                      name),
                      &st, "cannot read the schema");
  if (s == TT_OK) {
    sqlite3_int64 r = sqlite3_step(st) == SQLITE_ROW
                          ? sqlite3_column_int64(st, 0) : 0;
    if (r < 2 || r > 0xfffffffe)
      s = tt__error(b->ctx, TT_ERR_FORMAT, "%s: no table %s", b->path,
                    name);
    *root = (uint32_t)r;
  }
  sqlite3_finalize(st);
  st = NULL;
  if (s == TT_OK)
    s = prepare_owned(b, sqlite3_mprintf("PRAGMA table_info(\"%w\")", name),
                      &st, "cannot read the index's columns");
  int ncols = 0, plain = 1;
  while (s == TT_OK && sqlite3_step(st) == SQLITE_ROW) {
    const char *type = (const char *)sqlite3_column_text(st, 2);
    int pk = sqlite3_column_int(st, 5);
    if (ncols == 0)
      plain = plain && pk == 1 && type && sqlite3_stricmp(type, "INTEGER") == 0;
    else
      plain = plain && pk == 0;
    ncols++;
  }
  if (s == TT_OK && (ncols != 2 || !plain))
    s = tt__error(b->ctx, TT_ERR_FORMAT, "%s: index table %s is not "
                  "(INTEGER PRIMARY KEY, value)", b->path, name);
  sqlite3_finalize(st);
  sqlite3_free(name);
  return s;
}

tt_status tt__gpkg_rtree_create_empty(tt_context *ctx, sqlite3 *db,
                                      const char *gpkg_path,
                                      const char *table,
                                      const char *geom_column,
                                      tt__rtree_shadow *out)
{
  memset(out, 0, sizeof *out);
  rt_build b;
  memset(&b, 0, sizeof b);
  b.ctx = ctx;
  b.db = db;
  b.path = gpkg_path;
  sqlite3_stmt *uv = NULL;
  if (sqlite3_prepare_v2(db, "PRAGMA user_version", -1, &uv, NULL) ==
          SQLITE_OK &&
      sqlite3_step(uv) == SQLITE_ROW)
    b.gpkg_version = sqlite3_column_int(uv, 0);
  sqlite3_finalize(uv);
  tt_status s = describe(&b, table, geom_column);
  if (s == TT_OK)
    s = create_schema(&b); /* and the root node deleted */
  static const char *const parts[3] = {"_node", "_parent", "_rowid"};
  for (int k = 0; k < 3 && s == TT_OK; k++)
    s = shadow_root(&b, parts[k], &out->root[k]);
  if (s == TT_OK) {
    out->rtree = sqlite3_mprintf("%s", b.rtree);
    out->node_size = b.node_size;
    out->node_cap = b.node_cap;
    if (!out->rtree)
      s = tt__error(ctx, TT_ERR_NOMEM, "out of memory");
  }
  build_free(&b);
  return s;
}

tt_status tt__gpkg_rtree_drop(tt_context *ctx, sqlite3 *db,
                              const char *gpkg_path, const char *table,
                              const char *geom_column)
{
  char *r = sqlite3_mprintf("rtree_%s_%s", table, geom_column);
  if (!r)
    return tt__error(ctx, TT_ERR_NOMEM, "out of memory");
  static const char *const triggers[] = {
      "_insert", "_update1", "_update2", "_update3", "_update4",
      "_update5", "_update6", "_update7", "_delete"};
  char *sql = sqlite3_mprintf("DROP TABLE IF EXISTS \"%w\";", r);
  for (size_t k = 0; sql && k < sizeof triggers / sizeof triggers[0]; k++) {
    char *more = sqlite3_mprintf("%sDROP TRIGGER IF EXISTS \"%w%s\";", sql,
                                 r, triggers[k]);
    sqlite3_free(sql);
    sql = more;
  }
  tt_status s = TT_OK;
  if (!sql)
    s = tt__error(ctx, TT_ERR_NOMEM, "out of memory");
  else if (sqlite3_exec(db, sql, NULL, NULL, NULL) != SQLITE_OK)
    s = tt__error(ctx, TT_ERR_IO, "%s: cannot remove the index %s: %s",
                  gpkg_path, r, sqlite3_errmsg(db));
  sqlite3_free(sql);
  if (s == TT_OK &&
      sqlite3_table_column_metadata(db, NULL, "gpkg_extensions",
                                    "extension_name", NULL, NULL, NULL, NULL,
                                    NULL) == SQLITE_OK) {
    sql = sqlite3_mprintf("DELETE FROM gpkg_extensions WHERE "
                          "lower(table_name) = lower(%Q) AND "
                          "lower(column_name) = lower(%Q) AND "
                          "extension_name = 'gpkg_rtree_index'",
                          table, geom_column);
    if (!sql || sqlite3_exec(db, sql, NULL, NULL, NULL) != SQLITE_OK)
      s = tt__error(ctx, TT_ERR_IO, "%s: cannot remove the index's "
                    "gpkg_extensions row: %s", gpkg_path,
                    sqlite3_errmsg(db));
    sqlite3_free(sql);
  }
  sqlite3_free(r);
  return s;
}
