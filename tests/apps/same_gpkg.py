#!/usr/bin/env python3
"""same_gpkg.py A.gpkg B.gpkg -- whether two GeoPackages hold the same
content: the same schema (every table, index, trigger and view, by its SQL)
and, table by table in rowid order, the same rows, blobs byte for byte
(the R-trees through their shadow tables), except what records when the
file was made: gpkg_contents.last_change, layer_styles.update_time and the
times and date of run_parameters (t_*, created). Prints the first
difference and exits 1; exits 0 when they are the same.

tests/apps/test_tiles.sh compares a tiled run's GeoPackage written as the
tiles merge with the one written from the merged TIN."""
import sqlite3
import sys

IGNORED = {"gpkg_contents": {"last_change"},
           "layer_styles": {"update_time"}}


def ignored(table):
    if table.endswith("run_parameters"):
        return {"t_read", "t_simplify", "t_mesh", "t_stats", "t_write",
                "created"}
    return IGNORED.get(table, set())


def schema(db):
    return sorted(db.execute("SELECT type, name, tbl_name, sql FROM "
                             "sqlite_master WHERE name NOT LIKE "
                             "'sqlite_autoindex%'"))


def rows(db, table):
    cols = [r[1] for r in db.execute('PRAGMA table_info("%s")' % table)]
    keep = [c for c in cols if c not in ignored(table)]
    sel = ", ".join('"%s"' % c for c in keep)
    return keep, db.execute('SELECT %s FROM "%s" ORDER BY rowid'
                            % (sel, table))


def main():
    # read-only: a missing file is an error, not a new empty database
    a = sqlite3.connect("file:%s?mode=ro" % sys.argv[1], uri=True)
    b = sqlite3.connect("file:%s?mode=ro" % sys.argv[2], uri=True)
    sa, sb = schema(a), schema(b)
    if sa != sb:
        print("schemas differ:", [x for x in sa if x not in sb][:3],
              [x for x in sb if x not in sa][:3])
        return 1
    tables = [name for kind, name, _, sql in sa if kind == "table" and
              not (sql or "").upper().startswith("CREATE VIRTUAL")]
    if not tables:
        print("no tables")
        return 1
    n = 0
    for t in tables:
        ca, ra = rows(a, t)
        cb, rb = rows(b, t)
        i = 0
        while True:
            x, y = ra.fetchone(), rb.fetchone()
            if x != y:
                print("table %s, row %d: %r != %r" % (t, i + 1, x, y))
                return 1
            if x is None:
                break
            i += 1
        n += i
    print("same: %d tables, %d rows" % (len(tables), n))
    return 0


if __name__ == "__main__":
    sys.exit(main())
