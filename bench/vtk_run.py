#!/usr/bin/python3
"""vtk_run.py -- VTK's vtkQuadricDecimation on the full-grid TIN of a DEM,
for bench/decimate_peers.sh.

  python3 bench/vtk_run.py DEM.raw DEM.info.json N TIN.geojsonl

The full-grid TIN (one vertex per sample at (column, row, z), two triangles
per cell) is decimated to about N vertices (SetTargetReduction(1 - N/V);
the boundary constraint where the VTK has it, 9.3 on: Debian 12's 9.1 has
none, so the outline may move and samples near it may be left uncovered). Quadric decimation places each merged vertex at
its quadric's optimum, so the vertices are not samples any more; the
triangles are written in map coordinates as GeoJSON text sequence for
`terratin eval`. Prints one JSON object: vertices, triangles, seconds.
"""
import json, sys, time

import numpy as np
import vtk
from vtk.util import numpy_support as ns

raw, info_path, n_want, out = sys.argv[1], sys.argv[2], int(sys.argv[3]), sys.argv[4]
info = json.load(open(info_path))
w, h = info["size"]
gt = info["geoTransform"]
z = np.fromfile(raw, dtype="<f4", count=w * h)
cols, rows = np.meshgrid(np.arange(w, dtype=np.float64), np.arange(h, dtype=np.float64))
pts = np.column_stack([cols.ravel(), rows.ravel(), z.astype(np.float64)])
a = (np.arange(h - 1)[:, None] * w + np.arange(w - 1)[None, :]).ravel()
tris = np.concatenate([np.column_stack([a, a + 1, a + w + 1]),
                       np.column_stack([a, a + w + 1, a + w])])
cells = np.column_stack([np.full(len(tris), 3), tris]).astype(np.int64).ravel()
poly = vtk.vtkPolyData()
p = vtk.vtkPoints()
p.SetData(ns.numpy_to_vtk(pts, deep=True))
poly.SetPoints(p)
ca = vtk.vtkCellArray()
ca.SetCells(len(tris), ns.numpy_to_vtkIdTypeArray(cells, deep=True))
poly.SetPolys(ca)

t0 = time.monotonic()
dec = vtk.vtkQuadricDecimation()
dec.SetInputData(poly)
dec.SetTargetReduction(1.0 - n_want / float(w * h))
if hasattr(dec, "BoundaryConstraintOn"):  # VTK >= 9.3; Debian 12 has 9.1
    dec.BoundaryConstraintOn()            # keep the outline (weighted)
dec.Update()
secs = time.monotonic() - t0
o = dec.GetOutput()
opts = ns.vtk_to_numpy(o.GetPoints().GetData()).astype(np.float64)
conn = ns.vtk_to_numpy(o.GetPolys().GetConnectivityArray()).reshape(-1, 3)
mx = gt[0] + (opts[:, 0] + 0.5) * gt[1] + (opts[:, 1] + 0.5) * gt[2]
my = gt[3] + (opts[:, 0] + 0.5) * gt[4] + (opts[:, 1] + 0.5) * gt[5]
with open(out, "w") as f:
    for t in conn:
        i, j, k = (int(v) for v in t)
        cross = (mx[j] - mx[i]) * (my[k] - my[i]) - (my[j] - my[i]) * (mx[k] - mx[i])
        if cross < 0:
            j, k = k, j
        c = ",".join(f"[{mx[q]!r},{my[q]!r},{opts[q, 2]!r}]" for q in (i, j, k, i))
        f.write('{"type":"Feature","properties":{},"geometry":{"type":"Polygon",'
                f'"coordinates":[[{c}]]}}}}\n')
used = len(np.unique(conn))
print(json.dumps({"tool": "vtkQuadricDecimation", "vertices": used,
                  "triangles": int(len(conn)), "seconds": secs}))
