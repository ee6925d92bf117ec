#!/usr/bin/env python3
"""breakline_path.py GPKG LINES.geojson X0 YTOP CELL NX NY -- whether the
TIN of GPKG (read with sqlite3) follows each line of LINES (a GeoJSON of
LineStrings in the DEM's map units; the DEM's grid: upper-left corner X0,
YTOP, square cells of CELL, NX x NY samples): a path of TIN edges from the
vertex at the line's first sample on the grid to the one at its last,
every edge within 1.5 samples of the line all along. When GPKG has a
breaklines layer (a TIN made with -breaklines), the path may take only
its edges, and the layer must be exactly the edges the triangles'
constrained field flags, each an edge of the TIN flagged on both sides.
Prints one JSON object per line; exits 1 when some line has no such path
or the layer and the flags disagree."""
import json
import math
import sqlite3
import sys
from collections import deque


def dist_to_polyline(p, pts):
    best = float("inf")
    for (ax, ay), (bx, by) in zip(pts, pts[1:]):
        dx, dy = bx - ax, by - ay
        l2 = dx * dx + dy * dy
        t = 0.0 if l2 == 0 else max(0.0, min(1.0, ((p[0] - ax) * dx +
                                                  (p[1] - ay) * dy) / l2))
        best = min(best, math.hypot(p[0] - ax - t * dx, p[1] - ay - t * dy))
    return best


def main():
    gpkg, lines = sys.argv[1], sys.argv[2]
    x0, ytop, cell = map(float, sys.argv[3:6])
    nx, ny = int(sys.argv[6]), int(sys.argv[7])
    db = sqlite3.connect(gpkg)
    verts = {vid: (c, r) for vid, c, r in
             db.execute("select vertex_id, col, row from vertices")}
    tables = {r[0] for r in db.execute(
        "select name from sqlite_master where type = 'table'")}
    layer = "breaklines" in tables
    adj = {}
    sides, flagged = {}, {}
    cols = "v0, v1, v2" + (", constrained" if layer else ", 0")
    for a, b, c, k in db.execute("select %s from triangles" % cols):
        for i, (p, q) in enumerate(((a, b), (b, c), (c, a))):
            e = (min(p, q), max(p, q))
            sides[e] = sides.get(e, 0) + 1
            flagged[e] = flagged.get(e, 0) + ((k >> i) & 1)
    bad = 0
    if layer:
        edges = {(min(a, b), max(a, b)) for a, b in
                 db.execute("select v0, v1 from breaklines")}
        flags = {e for e, n in flagged.items() if n}
        both = all(flagged[e] == sides[e] for e in flags)
        agree = edges == flags and both
        print(json.dumps({"breakline_edges": len(edges),
                          "flags_agree": agree}))
        bad += not agree
    else:
        edges = set(sides)
    for p, q in edges:
        adj.setdefault(p, set()).add(q)
        adj.setdefault(q, set()).add(p)
    for feat in json.load(open(lines))["features"]:
        pts = [((x - x0) / cell - 0.5, (ytop - y) / cell - 0.5)
               for x, y in feat["geometry"]["coordinates"]]
        # the line's first and last points on the grid, densely sampled
        on = []
        for (ax, ay), (bx, by) in zip(pts, pts[1:]):
            for k in range(21):
                u, v = ax + (bx - ax) * k / 20, ay + (by - ay) * k / 20
                if -0.5 < u < nx - 0.5 and -0.5 < v < ny - 0.5:
                    on.append((u, v))
        near = {v for v, p in verts.items() if dist_to_polyline(p, pts) <= 1.5}

        def along(p, q):
            (a, b), (c, d) = verts[p], verts[q]
            return all(dist_to_polyline((a + (c - a) * k / 8,
                                         b + (d - b) * k / 8), pts) <= 1.5
                       for k in range(9))

        def closest(pt):
            return min(near, key=lambda v: math.hypot(verts[v][0] - pt[0],
                                                      verts[v][1] - pt[1]))
        start, end = closest(on[0]), closest(on[-1])
        seen, todo = {start: None}, deque([start])
        while todo:
            p = todo.popleft()
            for q in adj.get(p, ()):
                if q in near and q not in seen and along(p, q):
                    seen[q] = p
                    todo.append(q)
        hops = 0
        if end in seen:
            p = end
            while seen[p] is not None:
                p, hops = seen[p], hops + 1
        ok = end in seen and math.hypot(
            verts[start][0] - on[0][0], verts[start][1] - on[0][1]) <= 1.5 \
            and math.hypot(verts[end][0] - on[-1][0],
                           verts[end][1] - on[-1][1]) <= 1.5
        bad += not ok
        print(json.dumps({"line": feat.get("properties", {}), "followed": ok,
                          "edges": hops, "start": verts[start],
                          "end": verts[end]}))
    sys.exit(1 if bad else 0)


if __name__ == "__main__":
    main()
