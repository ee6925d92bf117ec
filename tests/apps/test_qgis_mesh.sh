#!/usr/bin/env bash
# test_qgis_mesh.sh -- terratin's mesh outputs opened by QGIS as a GIS user
# would (issue 17): headless PyQGIS (Debian python3-qgis, /usr/bin/python3,
# QT_QPA_PLATFORM=offscreen) opens -of 2DM (with its .dat datasets added),
# PLY and UGRID as QgsMeshLayer through the "mdal" provider, and each is
# checked against the GeoPackage of the same run read through QGIS's "ogr"
# provider:
#  - the layer is valid, its vertex and face counts are the layers';
#  - every vertex's x, y, z and every face's three vertices (in order) are
#    the GeoPackage's (vertex_id, fid - 1);
#  - the CRS is the GeoPackage's (PLY, UGRID; 2DM holds none);
#  - every dataset group is listed, on vertices (ins_err, star_max,
#    star_rmse, and the heights as "Bed Elevation") or faces (max_err,
#    rmse, n_samples), and its value at every vertex or face equals the
#    GeoPackage's field (NaN where the field is NULL);
#  - 2DM: QGIS does not load the .dat files by itself (only "Bed
#    Elevation" before), each loads with addDataset().
# OBJ and LandXML are not here: QGIS 3.22's MDAL (0.9.4) has no driver
# for them ("not recognized as a supported file format").
# Skips (77) when python3-qgis is not installed: it is an optional heavy
# client (apt-get install -y --no-install-recommends python3-qgis).
set -u

T=${TT_TERRATIN:-}
if [ -z "$T" ] || [ ! -x "$T" ]; then
  echo "SKIP: TT_TERRATIN is not set or not executable"
  exit 77
fi
DEM=${TT_TESTDATA:-}/jacksboro_fault_dem.tif
if [ ! -f "$DEM" ]; then
  echo "SKIP: $DEM is missing (TT_TESTDATA)"
  exit 77
fi
if ! /usr/bin/python3 -c 'import qgis.core' >/dev/null 2>&1; then
  echo "SKIP: python3-qgis is not installed (apt-get install -y" \
       "--no-install-recommends python3-qgis): the QGIS mesh-layer checks" \
       "need it"
  exit 77
fi

W=$(mktemp -d "${TMPDIR:-/tmp}/tt_qgis_mesh.XXXXXX") || exit 1
trap 'rm -rf "$W"' EXIT
cd "$W" || exit 1

failed=0
for out in t.gpkg t.2dm t.ply "t.nc -of UGRID"; do
  # shellcheck disable=SC2086 # the -of words split on purpose
  if ! "$T" simplify "$DEM" $out -max_error 20 -q 2>err.txt; then
    echo "FAIL: simplify $out: $(cat err.txt)"
    failed=1
  fi
done
[ "$failed" -eq 0 ] || exit 1

export QT_QPA_PLATFORM=offscreen
export XDG_RUNTIME_DIR="$W/xdg"
mkdir -m 700 "$W/xdg"
/usr/bin/python3 - t.gpkg t.2dm t.ply t.nc <<'EOF' 2>qgis_err.txt
import glob, math, sys
from qgis.core import (QgsApplication, QgsMeshDatasetIndex, QgsMeshLayer,
                       QgsMesh, QgsVectorLayer, QgsMeshDatasetGroupMetadata,
                       NULL)

app = QgsApplication([], False)
app.initQgis()
gpkg, meshes = sys.argv[1], sys.argv[2:]
passed = failed = 0

def check(what, ok):
    global passed, failed
    if ok:
        passed += 1
    else:
        failed += 1
        print("FAIL:", what)

def same(a, b):
    return (a is None and math.isnan(b)) or (
        a is not None and (a == b or (math.isnan(a) and math.isnan(b))))

def main():
    # Layers live in here, so they are gone before exitQgis() (PyQGIS
    # crashes at exit otherwise).
    # What the GeoPackage holds, through QGIS's own OGR provider.
    vl = QgsVectorLayer(gpkg + "|layername=vertices", "v", "ogr")
    tl = QgsVectorLayer(gpkg + "|layername=triangles", "t", "ogr")
    check("the GeoPackage layers open", vl.isValid() and tl.isValid())
    V = {}
    for f in vl.getFeatures():
        p = f.geometry().constGet()
        val = lambda k: None if f[k] is None or f[k] == NULL else float(f[k])
        V[f["vertex_id"]] = (p.x(), p.y(), p.z(), val("ins_err"),
                             val("star_max"), val("star_rmse"))
    Tr = {}
    for f in tl.getFeatures():
        Tr[f.id() - 1] = ([f["v0"], f["v1"], f["v2"]], float(f["max_err"]),
                          float(f["rmse"]), float(f["n_samples"]))
    nv, nt = len(V), len(Tr)
    check("vertex ids 0..n-1", sorted(V) == list(range(nv)))
    check("fids 1..n", sorted(Tr) == list(range(nt)))
    crs = vl.crs()
    vertex_sets = {"Bed Elevation": 2, "ins_err": 3, "star_max": 4,
                   "star_rmse": 5}
    face_sets = {"max_err": 1, "rmse": 2, "n_samples": 3}

    for path in meshes:
        layer = QgsMeshLayer(path, "mesh", "mdal")
        check(path + ": a valid mesh layer", layer.isValid())
        if not layer.isValid():
            continue
        dp = layer.dataProvider()
        check("%s: %d vertices (%d)" % (path, dp.vertexCount(), nv),
              dp.vertexCount() == nv)
        check("%s: %d faces (%d)" % (path, dp.faceCount(), nt),
              dp.faceCount() == nt)
        mesh = QgsMesh()
        dp.populateMesh(mesh)
        bad = sum(1 for i in range(min(nv, mesh.vertexCount()))
                  if (mesh.vertex(i).x(), mesh.vertex(i).y(),
                      mesh.vertex(i).z()) != V[i][:3])
        check("%s: every vertex's x, y, z (%d differ)" % (path, bad), bad == 0)
        bad = sum(1 for i in range(min(nt, mesh.faceCount()))
                  if list(mesh.face(i)) != Tr[i][0])
        check("%s: every face's vertices (%d differ)" % (path, bad), bad == 0)
        if path.endswith(".2dm"):
            check(path + ": no CRS (2DM holds none)", not layer.crs().isValid())
            names = [dp.datasetGroupMetadata(g).name()
                     for g in range(dp.datasetGroupCount())]
            check(path + ": QGIS loads no .dat by itself (%s)" % names,
                  names == ["Bed Elevation"])
            dats = sorted(glob.glob(path[:-4] + "_*.dat"))
            check(path + ": six dataset files beside it", len(dats) == 6)
            for d in dats:
                check(d + ": addDataset()", dp.addDataset(d))
        else:
            check("%s: the CRS (%s, %s)" % (path, layer.crs().authid(),
                                            crs.authid()),
                  layer.crs() == crs)
        listed = {}
        for g in range(dp.datasetGroupCount()):
            m = dp.datasetGroupMetadata(g)
            listed[m.name()] = (g, m)
        for name in list(vertex_sets) + list(face_sets):
            check("%s: dataset %s listed (%s)" % (path, name, sorted(listed)),
                  name in listed)
            if name not in listed:
                continue
            g, m = listed[name]
            on_vertices = name in vertex_sets
            where = (QgsMeshDatasetGroupMetadata.DataOnVertices if on_vertices
                     else QgsMeshDatasetGroupMetadata.DataOnFaces)
            check("%s: %s on the %s" % (path, name,
                                        "vertices" if on_vertices else "faces"),
                  m.dataType() == where and m.isScalar() and
                  dp.datasetCount(g) == 1)
            n = nv if on_vertices else nt
            block = dp.datasetValues(QgsMeshDatasetIndex(g, 0), 0, n)
            ref = [V[i][vertex_sets[name]] if on_vertices
                   else Tr[i][face_sets[name]] for i in range(n)]
            bad = [i for i in range(n) if not same(ref[i],
                                                   block.value(i).scalar())]
            check("%s: %s equal at each of %d %s (%d differ%s)" % (
                      path, name, n, "vertices" if on_vertices else "faces",
                      len(bad), ", first %d: %r vs %r" % (
                          bad[0], ref[bad[0]], block.value(bad[0]).scalar())
                      if bad else ""), not bad)
            # one value as a user's identify tool reads it
            one = dp.datasetValue(QgsMeshDatasetIndex(g, 0), n // 2).scalar()
            check("%s: %s at %s %d" % (path, name,
                                       "vertex" if on_vertices else "face",
                                       n // 2), same(ref[n // 2], one))
    return len(V), len(Tr)


nv, nt = main()
print("%d passed, %d failed (%d vertices, %d triangles)" % (passed, failed,
                                                            nv, nt))
app.exitQgis()
sys.exit(1 if failed else 0)
EOF
rc=$?
if [ "$rc" -ne 0 ]; then
  grep -v "^HDF5-DIAG\|^  #\|^    major\|^    minor" qgis_err.txt | head -20
fi
exit "$rc"
