/*
 * tt_test_sqlite.h -- what the GeoPackage tests read files and databases
 * with (test_gpkg_rtree.c, test_rtree_stream.c): a whole file into memory,
 * a database opened for writing, the first value of a query as text or an
 * integer, a statement run; failures are reported through tt_test.h.
 * Static inline: each test takes what it uses.
 */
#ifndef TT_TEST_SQLITE_H
#define TT_TEST_SQLITE_H

#include "tt_test.h"

#include <sqlite3.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* The bytes of path (malloc'd, *out_len of them), NULL when unreadable. */
static inline unsigned char *slurp(const char *path, size_t *out_len)
{
  FILE *f = fopen(path, "rb");
  *out_len = 0;
  if (!f)
    return NULL;
  fseek(f, 0, SEEK_END);
  long n = ftell(f);
  fseek(f, 0, SEEK_SET);
  unsigned char *p = n >= 0 ? malloc((size_t)n + 1) : NULL;
  if (p && fread(p, 1, (size_t)n, f) != (size_t)n) {
    free(p);
    p = NULL;
  }
  fclose(f);
  *out_len = p ? (size_t)n : 0;
  return p;
}

static inline sqlite3 *db_open(const char *path)
{
  sqlite3 *db = NULL;
  if (sqlite3_open_v2(path, &db, SQLITE_OPEN_READWRITE, NULL) != SQLITE_OK) {
    TT_FAIL_("cannot open %s: %s", path, db ? sqlite3_errmsg(db) : "?");
    sqlite3_close(db);
    return NULL;
  }
  return db;
}

/* First column of the first row as a malloc'ed string ("(null)" for NULL,
 * NULL on error). */
static inline char *sql_text(sqlite3 *db, const char *sql)
{
  sqlite3_stmt *st = NULL;
  char *out = NULL;
  if (sqlite3_prepare_v2(db, sql, -1, &st, NULL) != SQLITE_OK) {
    TT_FAIL_("prepare %s: %s", sql, sqlite3_errmsg(db));
    return NULL;
  }
  if (sqlite3_step(st) == SQLITE_ROW) {
    const unsigned char *t = sqlite3_column_text(st, 0);
    out = strdup(t ? (const char *)t : "(null)");
  }
  sqlite3_finalize(st);
  return out;
}

static inline long long sql_int(sqlite3 *db, const char *sql)
{
  char *t = sql_text(db, sql);
  long long v = t ? atoll(t) : -1;
  free(t);
  return v;
}

static inline void sql_exec(sqlite3 *db, const char *sql)
{
  char *err = NULL;
  if (sqlite3_exec(db, sql, NULL, NULL, &err) != SQLITE_OK)
    TT_FAIL_("%s: %s", sql, err ? err : "?");
  sqlite3_free(err);
}

#endif /* TT_TEST_SQLITE_H */
