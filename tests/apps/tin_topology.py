#!/usr/bin/env python3
"""tin_topology.py GPKG [GRID.asc] -- the topology of a terratin TIN read
straight from its GeoPackage tables (sqlite3, no GDAL): every edge in one
or two triangles, no vertex strictly inside an edge (T-junction), vertex
ids unique and one vertex a sample, the Euler characteristic V - E + F, and
the boundary edges: without a grid, every one must lie on the raster's
outline; with the DEM as an ESRI ASCII grid, a boundary edge with a fully
valid cell on both sides anywhere along it is a crack. Prints one JSON
object; exits 1 when the TIN is not conforming."""
import json
import math
import sqlite3
import sys


def read_asc(path):
    head, rows = {}, []
    with open(path) as f:
        for line in f:
            parts = line.split()
            if not parts:
                continue
            if parts[0][0].isalpha() and len(parts) == 2:
                head[parts[0].lower()] = float(parts[1])
                continue
            rows.append(parts)
    nodata = head.get("nodata_value")
    valid = [[not (v == "nan" or v.lower() == "nan" or
                   (nodata is not None and float(v) == nodata))
              for v in r] for r in rows]
    return valid


def main():
    db = sqlite3.connect(sys.argv[1])
    grid = read_asc(sys.argv[2]) if len(sys.argv) > 2 else None
    verts = {}
    samples = set()
    dup_ids = dup_samples = 0
    W = H = 0
    for vid, c, r in db.execute("select vertex_id, col, row from vertices"):
        if vid in verts:
            dup_ids += 1
        verts[vid] = (c, r)
        if (c, r) in samples:
            dup_samples += 1
        samples.add((c, r))
    if grid is not None:
        H, W = len(grid), len(grid[0])
    edges = {}
    nt = 0
    for a, b, c in db.execute("select v0, v1, v2 from triangles"):
        nt += 1
        for p, q in ((a, b), (b, c), (c, a)):
            k = (p, q) if p < q else (q, p)
            edges[k] = edges.get(k, 0) + 1
    # the raster's size: from the grid, else the vertices' extent
    if grid is None:
        W = max(c for c, r in verts.values()) + 1
        H = max(r for c, r in verts.values()) + 1

    def cell_full(cx, cy):
        if grid is None:
            return 0 <= cx < W - 1 and 0 <= cy < H - 1
        if cx < 0 or cy < 0 or cx + 1 >= W or cy + 1 >= H:
            return False
        return (grid[cy][cx] and grid[cy][cx + 1] and grid[cy + 1][cx] and
                grid[cy + 1][cx + 1])

    over = tj = boundary = cracks = 0
    for (p, q), n in edges.items():
        over += n > 2
        (x0, y0), (x1, y1) = verts[p], verts[q]
        dx, dy = x1 - x0, y1 - y0
        g = math.gcd(abs(dx), abs(dy))
        for s in range(1, g):
            if (x0 + dx // g * s, y0 + dy // g * s) in samples:
                tj += 1
        if n == 1:
            boundary += 1
            # a boundary edge: any unit step along it with full cells on
            # both sides is inside the domain
            if dx == 0:
                for y in range(min(y0, y1), max(y0, y1)):
                    cracks += cell_full(x0 - 1, y) and cell_full(x0, y)
            elif dy == 0:
                for x in range(min(x0, x1), max(x0, x1)):
                    cracks += cell_full(x, y0 - 1) and cell_full(x, y0)
    out = {"vertices": len(verts), "triangles": nt, "edges": len(edges),
           "euler": len(verts) - len(edges) + nt, "over_used": over,
           "t_junctions": tj, "boundary_edges": boundary, "cracks": cracks,
           "duplicate_ids": dup_ids, "duplicate_samples": dup_samples}
    print(json.dumps(out))
    bad = over or tj or cracks or dup_ids or dup_samples
    sys.exit(1 if bad else 0)


if __name__ == "__main__":
    main()
