#!/usr/bin/env python3
"""same_gpkg.py [--rtree-content] A.gpkg B.gpkg -- whether two GeoPackages
hold the same content: the same schema (every table, index, trigger and
view, by its SQL) and, table by table in rowid order, the same rows, blobs
byte for byte (the R-trees through their shadow tables), except what
records when the file was made: gpkg_contents.last_change,
layer_styles.update_time and the times and date of run_parameters (t_*,
created). Prints the first difference and exits 1; exits 0 when they are
the same.

--rtree-content: the R-trees (virtual tables USING rtree) are compared by
what they index, not by their nodes: each file's rtreecheck() must say ok,
and the two must give the same ids with the same boxes (SELECT * from the
virtual table, by id); their shadow tables (_node, _parent, _rowid) are
not compared row by row. Two valid trees of the same boxes packed
differently (the streamed writer packs its leaves block by block,
gpkg_rtree_pages.c) then compare equal; everything else is still byte for
byte.

tests/apps/test_tiles.sh compares a tiled run's GeoPackage written as the
tiles merge with the one written from the merged TIN (--rtree-content)."""
import sqlite3
import sys

SHADOWS = ("_node", "_parent", "_rowid")

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


def same_rows(t, ra, rb):
    """The row count, or None after printing the first difference."""
    i = 0
    while True:
        x, y = ra.fetchone(), rb.fetchone()
        if x != y:
            print("table %s, row %d: %.300r != %.300r" % (t, i + 1, x, y))
            return None
        if x is None:
            return i
        i += 1


def main():
    args = sys.argv[1:]
    content = "--rtree-content" in args
    args = [x for x in args if x != "--rtree-content"]
    if len(args) != 2:
        print(__doc__)
        return 2
    # read-only: a missing file is an error, not a new empty database
    a = sqlite3.connect("file:%s?mode=ro" % args[0], uri=True)
    b = sqlite3.connect("file:%s?mode=ro" % args[1], uri=True)
    sa, sb = schema(a), schema(b)
    if sa != sb:
        print("schemas differ:", [x for x in sa if x not in sb][:3],
              [x for x in sb if x not in sa][:3])
        return 1
    rtrees = [name for kind, name, _, sql in sa if kind == "table" and
              " USING RTREE" in (sql or "").upper()] if content else []
    shadows = {r + s for r in rtrees for s in SHADOWS}
    tables = [name for kind, name, _, sql in sa if kind == "table" and
              not (sql or "").upper().startswith("CREATE VIRTUAL") and
              name not in shadows]
    if not tables:
        print("no tables")
        return 1
    n = 0
    for t in tables:
        ca, ra = rows(a, t)
        cb, rb = rows(b, t)
        i = same_rows(t, ra, rb)
        if i is None:
            return 1
        n += i
    for r in rtrees:
        for db, path in ((a, args[0]), (b, args[1])):
            check = db.execute("SELECT rtreecheck(?)", (r,)).fetchone()[0]
            if check != "ok":
                print("%s: rtreecheck(%s): %s" % (path, r, check[:300]))
                return 1
        q = 'SELECT * FROM "%s" ORDER BY id' % r
        i = same_rows(r + " (by id)", a.execute(q), b.execute(q))
        if i is None:
            return 1
        n += i
    print("same: %d tables, %d R-trees by content, %d rows"
          % (len(tables), len(rtrees), n))
    return 0


if __name__ == "__main__":
    sys.exit(main())
