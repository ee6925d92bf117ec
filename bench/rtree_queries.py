#!/usr/bin/env python3
"""rtree_queries.py [-n QUERIES] [-seed S] A.gpkg [B.gpkg ...] -- the
R-trees of GeoPackages compared for queries (docs/scale.md, the streamed
R-tree of issue 19): for each file and each index (rtree_triangles_geom,
rtree_vertices_geom), its nodes (count, depth, leaves, mean cells a leaf,
the sum of the leaves' areas over the layer's extent: 1 for leaves that
tile the plane without overlap), then QUERIES random windows (default
1,000) of three sizes (0.1 %, 1 % and 5 % of the extent's side; the same
windows for every file: the seed and the extent make them) run through
SQLite on the virtual table, timed (the fastest of three passes), and the
nodes each visits (the tree read from %_node and descended here as SQLite
does: every child whose box meets the window).

Uses /usr/bin/python3's sqlite3 (SQLite's R*Tree module)."""
import random
import sqlite3
import struct
import sys
import time

SIZES = (0.001, 0.01, 0.05)


def read_nodes(db, rtree):
    nodes = {}
    for nodeno, data in db.execute('SELECT nodeno, data FROM "%s_node"'
                                   % rtree):
        n = struct.unpack(">H", data[2:4])[0]
        cells = []
        for i in range(n):
            off = 4 + 24 * i
            cid = struct.unpack(">q", data[off:off + 8])[0]
            box = struct.unpack(">4f", data[off + 8:off + 24])
            cells.append((cid, box))
        nodes[nodeno] = cells
    depth = struct.unpack(">H", db.execute(
        'SELECT substr(data, 1, 2) FROM "%s_node" WHERE nodeno = 1'
        % rtree).fetchone()[0])[0]
    return nodes, depth


def visits(nodes, depth, w):
    """Nodes visited by window w = (x0, x1, y0, y1), the root included."""
    x0, x1, y0, y1 = w
    count, stack = 0, [(1, depth)]
    while stack:
        node, d = stack.pop()
        count += 1
        if d == 0:
            continue
        for cid, b in nodes[node]:
            if b[0] <= x1 and b[1] >= x0 and b[2] <= y1 and b[3] >= y0:
                stack.append((cid, d - 1))
    return count


def windows(ext, n, seed):
    rnd = random.Random(seed)
    x0, y0, x1, y1 = ext
    out = []
    for size in SIZES:
        ws = []
        for _ in range(n):
            sw, sh = size * (x1 - x0), size * (y1 - y0)
            cx = x0 + (x1 - x0) * rnd.random()
            cy = y0 + (y1 - y0) * rnd.random()
            ws.append((cx - sw / 2, cx + sw / 2, cy - sh / 2, cy + sh / 2))
        out.append((size, ws))
    return out


def main():
    args = sys.argv[1:]
    n, seed = 1000, 1
    while args and args[0].startswith("-"):
        if args[0] == "-n":
            n = int(args[1])
        elif args[0] == "-seed":
            seed = int(args[1])
        args = args[2:]
    for path in args:
        db = sqlite3.connect("file:%s?mode=ro" % path, uri=True)
        for layer in ("triangles", "vertices"):
            rtree = "rtree_%s_geom" % layer
            ext = db.execute("SELECT min_x, min_y, max_x, max_y FROM "
                             "gpkg_contents WHERE table_name = ?",
                             (layer,)).fetchone()
            if not ext or not db.execute(
                    "SELECT 1 FROM sqlite_master WHERE name = ?",
                    (rtree,)).fetchone():
                continue
            nodes, depth = read_nodes(db, rtree)
            # the leaves: the nodes depth levels below the root
            level = [1]
            for _ in range(depth):
                level = [c for node in level for c, _ in nodes[node]]
            cells = sum(len(nodes[x]) for x in level)
            area = 0.0
            for node in level:
                bs = [b for _, b in nodes[node]]
                area += ((max(b[1] for b in bs) - min(b[0] for b in bs)) *
                         (max(b[3] for b in bs) - min(b[2] for b in bs)))
            ext_area = (ext[2] - ext[0]) * (ext[3] - ext[1])
            print("%s %s: %d nodes, depth %d, %d leaves of %.2f cells, "
                  "leaf area / extent %.3f"
                  % (path, layer, len(nodes), depth, len(level),
                     cells / max(len(level), 1), area / ext_area))
            q = ('SELECT count(*) FROM "%s" WHERE minx <= ? AND maxx >= ? '
                 'AND miny <= ? AND maxy >= ?' % rtree)
            for size, ws in windows(ext, n, seed):
                best, found = None, 0
                for _ in range(3):
                    t0 = time.perf_counter()
                    found = 0
                    for w in ws:
                        found += db.execute(q, (w[1], w[0], w[3],
                                                w[2])).fetchone()[0]
                    t = time.perf_counter() - t0
                    best = t if best is None else min(best, t)
                v = sum(visits(nodes, depth, w) for w in ws)
                print("  windows of %.1f %%: %d queries, %.1f features and "
                      "%.1f nodes visited a query, %.3f s"
                      % (100 * size, len(ws), found / len(ws), v / len(ws),
                         best))
    return 0


if __name__ == "__main__":
    sys.exit(main())
