#!/usr/bin/env python3
"""outline_grids.py -- nodata patterns for the lean outline's tests, and the
exact check of a TIN against one (pure python3, no GDAL bindings).

  outline_grids.py make PATTERN OUT.asc [SIZE] [SEED] [SPARSITY]
      writes an ESRI ASCII grid (cell size 1, upper left corner at (0, 0):
      sample (c, r) at (c + 0.5, -r - 0.5)) of smooth heights with the
      nodata PATTERN: coast (three straight coastlines of slopes 0.37, 1
      and 2.6), checker (a checkerboard block, one-sample valid and nodata
      lines, lone samples), border (holes and notches touching every side
      and corner), noise (seeded random nodata blobs, one per SPARSITY
      samples, default 60: hundreds of patches on 96 x 96).
  outline_grids.py check GRID.asc TIN [MIN_PATCH]
      reads the TIN's triangles (ogr2ogr to CSV) and prints one JSON line:
      valid samples, the samples of the old domain (a valid corner of a
      cell with three or four valid corners), how many of those no
      triangle covers (missing), nodata samples a triangle covers (its
      closed interior: nodata_covered), and the covered valid samples.
      Exit 1 when missing or nodata_covered is not 0. Exact: integer
      barycentric signs. With MIN_PATCH, the valid patches (4-connected)
      of fewer samples are nodata first, and counted (dropped_samples,
      dropped_patches).
"""
import json
import math
import random
import subprocess
import sys

NODATA = -9999


def height(c, r):
    return 100 + 30 * math.sin(c * 0.11) * math.cos(r * 0.07) + 0.05 * c * r % 7


def pattern(name, nx, ny, seed, sparsity=60):
    valid = [[True] * nx for _ in range(ny)]

    def hole(c, r):
        if 0 <= c < nx and 0 <= r < ny:
            valid[r][c] = False

    if name == "coast":
        for r in range(ny):
            for c in range(nx):
                if r > 4 + 0.37 * c and c < nx // 2:
                    hole(c, r)
                if c > nx // 2 + 8 and r < (c - nx // 2 - 8):
                    hole(c, r)
                if c > nx - 12 and r > ny - 2.6 * (c - nx + 12) - 1:
                    hole(c, r)
    elif name == "checker":
        for r in range(10, 40):
            for c in range(10, 40):
                if (r + c) % 2:
                    hole(c, r)
        for c in range(0, nx):           # a one-sample nodata row
            hole(c, 50)
        for r in range(0, ny):           # a one-sample nodata column
            hole(60, r)
        for k in range(30):              # a one-sample nodata diagonal
            hole(45 + k, 5 + k)
        for r in range(55, ny):          # nodata with a one-sample valid
            for c in range(0, 40):       # line and lone samples in it
                if not (c == 20 or (r == 70 and c % 5 == 0)):
                    hole(c, r)
    elif name == "border":
        for r in range(0, 12):           # corner hole
            for c in range(0, 9):
                hole(c, r)
        for r in range(30, 41):          # hole on the left side
            for c in range(0, 3):
                hole(c, r)
        for c in range(40, nx):          # hole along the top, ragged
            for r in range(0, 1 + (c * 7) % 3):
                hole(c, r)
        for r in range(ny - 6, ny):      # bottom right corner, diagonal
            for c in range(nx - 6, nx):
                if c + r > nx + ny - 8:
                    hole(c, r)
        for r in range(ny - 1, ny):      # one-sample notches at the bottom
            for c in range(5, 60, 4):
                hole(c, r)
        for r in range(50, 70):          # right side, a slanted bay
            for c in range(nx - 1 - (r - 50) // 3, nx):
                hole(c, r)
    elif name == "noise":
        rng = random.Random(seed)
        for _ in range(nx * ny // sparsity):
            c, r = rng.randrange(nx), rng.randrange(ny)
            rad = rng.choice((0, 0, 0, 1, 1, 2, 3))
            for dr in range(-rad, rad + 1):
                for dc in range(-rad, rad + 1):
                    if dr * dr + dc * dc <= rad * rad + rng.randrange(2):
                        hole(c + dc, r + dr)
    else:
        raise SystemExit("outline_grids.py: %s: unknown pattern" % name)
    return valid


def make(name, out, size, seed, sparsity):
    nx = ny = size
    valid = pattern(name, nx, ny, seed, sparsity)
    with open(out, "w") as f:
        f.write("ncols %d\nnrows %d\nxllcorner 0\nyllcorner %d\n"
                "cellsize 1\nNODATA_value %d\n" % (nx, ny, -ny, NODATA))
        for r in range(ny):
            f.write(" ".join("%.3f" % height(c, r) if valid[r][c]
                             else str(NODATA) for c in range(nx)) + "\n")


def read_grid(path):
    lines = open(path).read().split("\n")
    hdr = {}
    k = 0
    while lines[k][:1].isalpha():
        key, val = lines[k].split()
        hdr[key.lower()] = val
        k += 1
    nd = float(hdr["nodata_value"])
    rows = [[float(v) != nd for v in l.split()] for l in lines[k:] if l.strip()]
    return rows


def triangles(tin):
    csv = subprocess.run(
        ["ogr2ogr", "--config", "OGR_WKT_PRECISION", "17", "-f", "CSV",
         "/vsistdout/", tin, "triangles", "-lco", "GEOMETRY=AS_WKT"],
        check=True, capture_output=True, text=True).stdout
    tris = []
    for line in csv.splitlines()[1:]:
        inner = line[line.index("((") + 2:line.index("))")]
        pts = [tuple(float(t) for t in p.split()[:2]) for p in inner.split(",")]
        tris.append([(int(math.floor(x)), int(math.floor(-y))) for x, y in pts[:3]])
    return tris


def drop_patches(valid, nx, ny, min_patch):
    seen = [[False] * nx for _ in range(ny)]
    samples = patches = 0
    for r0 in range(ny):
        for c0 in range(nx):
            if seen[r0][c0] or not valid[r0][c0]:
                continue
            seen[r0][c0] = True
            stack, patch = [(c0, r0)], []
            while stack:
                c, r = stack.pop()
                patch.append((c, r))
                for cc, rr in ((c - 1, r), (c + 1, r), (c, r - 1), (c, r + 1)):
                    if (0 <= cc < nx and 0 <= rr < ny and valid[rr][cc] and
                            not seen[rr][cc]):
                        seen[rr][cc] = True
                        stack.append((cc, rr))
            if len(patch) < min_patch:
                for c, r in patch:
                    valid[r][c] = False
                samples += len(patch)
                patches += 1
    return samples, patches


def check(grid, tin, min_patch=0):
    valid = read_grid(grid)
    ny, nx = len(valid), len(valid[0])
    dropped = drop_patches(valid, nx, ny, min_patch)

    def ok(c, r):
        return 0 <= c < nx and 0 <= r < ny and valid[r][c]

    def in_domain(c, r):
        if not ok(c, r):
            return False
        for cx in (c - 1, c):
            for cy in (r - 1, r):
                if (0 <= cx and cx + 1 < nx and 0 <= cy and cy + 1 < ny and
                        ok(cx, cy) + ok(cx + 1, cy) + ok(cx, cy + 1) +
                        ok(cx + 1, cy + 1) >= 3):
                    return True
        return False

    covered = set()
    nodata_covered = set()
    for (c0, r0), (c1, r1), (c2, r2) in triangles(tin):
        det = (c1 - c0) * (r2 - r0) - (c2 - c0) * (r1 - r0)
        for r in range(min(r0, r1, r2), max(r0, r1, r2) + 1):
            for c in range(min(c0, c1, c2), max(c0, c1, c2) + 1):
                w1 = (c - c0) * (r2 - r0) - (c2 - c0) * (r - r0)
                w2 = (c1 - c0) * (r - r0) - (c - c0) * (r1 - r0)
                w0 = det - w1 - w2
                if det < 0:
                    w0, w1, w2 = -w0, -w1, -w2
                if min(w0, w1, w2) < 0:
                    continue
                (covered if ok(c, r) else nodata_covered).add((c, r))
    domain = [(c, r) for r in range(ny) for c in range(nx) if in_domain(c, r)]
    missing = [p for p in domain if p not in covered]
    out = {"valid": sum(map(sum, valid)), "domain": len(domain),
           "covered": len(covered), "missing": len(missing),
           "nodata_covered": len(nodata_covered),
           "dropped_samples": dropped[0], "dropped_patches": dropped[1],
           "first_missing": missing[:3],
           "first_nodata_covered": sorted(nodata_covered)[:3]}
    print(json.dumps(out))
    return 0 if not missing and not nodata_covered else 1


if __name__ == "__main__":
    a = sys.argv[1:]
    if len(a) >= 3 and a[0] == "make":
        make(a[1], a[2], int(a[3]) if len(a) > 3 else 96,
             int(a[4]) if len(a) > 4 else 1, int(a[5]) if len(a) > 5 else 60)
    elif len(a) in (3, 4) and a[0] == "check":
        sys.exit(check(a[1], a[2], int(a[3]) if len(a) > 3 else 0))
    else:
        sys.exit(__doc__)
