#!/usr/bin/env bash
# test_ogr_layers.sh -- `terratin simplify` writing OGR outputs as GIS users
# open them ($TT_TERRATIN), issue 17:
#  - -layers: each single-layer format (GeoJSON, FlatGeobuf, KML, GPX)
#    with one layer, read back with ogrinfo: the feature counts equal the
#    run's; KML with all three layers (its writer takes features only into
#    its last layer); GPX written in EPSG:4326 (the summary says so) with
#    the heights in <ele>; DXF (terratin's own 3DFACE writer) read back by
#    OGR as the TIN's triangles, eval within the bound;
#  - a driver that cannot hold the layers asked for is refused before the
#    DEM is read (the progress bar never reaches 10 %), a usage error that
#    names the -layers or the OUTPUT form that works, leaving nothing;
#    -layers usage errors;
#  - a Shapefile's spatial index (.qix) by default, through -overwrite,
#    and a spatial filter through it finding what the GeoPackage finds;
#  - the default QGIS style of a GeoPackage (layer_styles): QGIS's columns,
#    one default row per geometry layer, QML that xmllint parses with a
#    graduated renderer naming max_err / ins_err; -nostyle leaves the table
#    out; QGIS itself loads it when python3-qgis is installed (skipped with
#    a message otherwise).
# Prints "N passed, M failed"; exits 1 on any failure, 77 when a tool is
# missing.
set -u
. "$(dirname "${BASH_SOURCE[0]}")/../apps/tt_check.sh" || exit 1

T=${TT_TERRATIN:-}
if [ -z "$T" ] || [ ! -x "$T" ]; then
  echo "SKIP: TT_TERRATIN is not set or not executable"
  exit 77
fi
for tool in ogrinfo python3 xmllint; do
  if ! command -v $tool >/dev/null 2>&1; then
    echo "SKIP: $tool is missing"
    exit 77
  fi
done

W=$(mktemp -d "${TMPDIR:-/tmp}/tt_ogr_layers.XXXXXX") || exit 1
trap 'rm -rf "$W"' EXIT
cd "$W" || exit 1

not() { ! "$@"; }
rc=0
run() {
  "$T" "$@" >out.txt 2>err.txt
  rc=$?
}
json_get() {
  python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))[sys.argv[2]])' "$1" "$2"
}
# fcount FILE LAYER: the layer's feature count as OGR reads it
fcount() {
  ogrinfo -ro -so "$1" "$2" 2>/dev/null | sed -n 's/^Feature Count: //p'
}

# --- the DEM and the reference run ------------------------------------------
run generate fault dem.tif -size 90x70 -seed 3 -displacement 20 \
  -wave_size 5 -a_srs EPSG:32633 -q
check "generate: exit 0 ($(cat err.txt))" [ "$rc" -eq 0 ]
run simplify -json -max_error 1 dem.tif ref.gpkg
check "reference run: exit 0 ($(cat err.txt))" [ "$rc" -eq 0 ]
cp out.txt ref.json
NV=$(json_get ref.json vertices)
NT=$(json_get ref.json triangles)
check "reference: a real TIN ($NV vertices, $NT triangles)" \
  [ "$NV" -gt 50 -a "$NT" -gt 80 ]

# --- one layer in each single-layer format ----------------------------------
mkdir one
# single DRIVER EXT LAYER OGRLAYER EXPECTED
single() {
  local drv=$1 ext=$2 layer=$3 olayer=$4 want=$5
  # a folder per format: the styles beside them (t.qml) would share a name
  local f=one/$ext/$layer.$ext
  mkdir -p "one/$ext"
  run simplify -q -max_error 1 -of "$drv" -layers "$layer" dem.tif "$f"
  check "$drv -layers $layer: exit 0 ($(head -c 300 err.txt))" [ "$rc" -eq 0 ]
  [ -n "$olayer" ] || olayer=$(ogrinfo -ro -q "$f" 2>/dev/null |
                               sed -n '1s/^1: \([^ ]*\).*/\1/p')
  local got
  got=$(fcount "$f" "$olayer")
  check "$drv -layers $layer: $want features read back (got '$got')" \
    [ "$got" = "$want" ]
}
single GeoJSON geojson triangles triangles "$NT"
single GeoJSON geojson run_parameters run_parameters 1
single FlatGeobuf fgb vertices vertices "$NV"
single FlatGeobuf fgb triangles triangles "$NT"
single KML kml triangles triangles "$NT"
single GPX gpx vertices waypoints "$NV"
# the attributes came along where the format keeps them
check "GeoJSON: the triangles keep max_err" \
  grep -q '"max_err"' one/geojson/triangles.geojson
check "GPX: the vertices keep ins_err in <extensions>" \
  grep -q 'ins_err' one/gpx/vertices.gpx
python3 - one/geojson/triangles.geojson "$NT" <<'EOF' || fail "GeoJSON: 3-D closed rings"
import json, sys
d = json.load(open(sys.argv[1]))
f = d["features"]
assert len(f) == int(sys.argv[2])
for x in f:
    r = x["geometry"]["coordinates"][0]
    assert len(r) == 4 and r[0] == r[3] and all(len(p) == 3 for p in r)
EOF
# GPX holds longitude/latitude only: written in EPSG:4326, said so; the
# heights in <ele>
run simplify -max_error 1 -layers vertices -overwrite dem.tif one/v2.gpx
check "GPX: the summary names EPSG:4326" \
  grep -q "^output: one/v2.gpx (layer vertices): .*, in EPSG:4326 (the only CRS the format holds); " out.txt
check "GPX: heights in <ele>" grep -q "<ele>" one/v2.gpx
python3 - one/v2.gpx <<'EOF' || fail "GPX: longitudes and latitudes, not UTM metres"
import re, sys
t = open(sys.argv[1]).read()
pts = re.findall(r'<wpt lat="([^"]+)" lon="([^"]+)"', t)
assert pts
assert all(-90 <= float(a) <= 90 and -180 <= float(o) <= 180 for a, o in pts)
EOF

# DXF: terratin's own writer, one 3DFACE per triangle at its corners'
# heights (GDAL's DXF driver would write flat hatches)
run simplify -q -max_error 1 dem.tif one/tin.dxf
check "DXF: exit 0 ($(head -c 300 err.txt))" [ "$rc" -eq 0 ]
check "DXF: $NT 3DFACE entities" [ "$(grep -c '^3DFACE$' one/tin.dxf)" = "$NT" ]
check "DXF: $NT features read back" [ "$(fcount one/tin.dxf entities)" = "$NT" ]
run eval -max_error 1 dem.tif one/tin.dxf
check "DXF: eval within the bound ($(tail -1 out.txt) $(head -c 200 err.txt))" \
  [ "$rc" -eq 0 ]

# KML holds several layers, written one after the other
run simplify -q -max_error 1 -of KML dem.tif one/all.kml
check "KML with three layers: exit 0 ($(head -c 300 err.txt))" [ "$rc" -eq 0 ]
check "KML: triangles $NT" [ "$(fcount one/all.kml triangles)" = "$NT" ]
check "KML: vertices $NV" [ "$(fcount one/all.kml vertices)" = "$NV" ]
check "KML: no interleaving failure" not grep -q Interleaved err.txt

# --- refused before the work -------------------------------------------------
mkdir ref
# refused_early NAME EXPECTED_WORDS ARGS...: exit 2, one line naming the
# way out, the bar not past 0 (the DEM not read), nothing written
refused_early() {
  local name=$1 words=$2
  shift 2
  "$T" "$@" >out.txt 2>err.txt
  rc=$?
  check "$name: a usage error (exit $rc: $(head -c 300 err.txt))" [ "$rc" -eq 2 ]
  check "$name: one line" [ "$(wc -l <err.txt)" = 1 ]
  check "$name: names '$words'" grep -q -F -- "$words" err.txt
  check "$name: before the DEM is read (bar: '$(cat out.txt)')" \
    not grep -q '10' out.txt
  check "$name: nothing left" [ -z "$(ls -A ref)" ]
}
refused_early "GeoJSON, three layers" "-layers triangles, -layers vertices" \
  simplify -max_error 1 dem.tif ref/o.geojson
refused_early "GeoJSON, two layers" "-layers vertices" \
  simplify -max_error 1 -layers vertices,triangles dem.tif ref/o.geojson
refused_early "FlatGeobuf .fgb, three layers" "without '.fgb'" \
  simplify -max_error 1 dem.tif ref/o.fgb
refused_early "MapInfo .tab, three layers" "drops the heights" \
  simplify -max_error 1 -of "MapInfo File" dem.tif ref/o.tab
refused_early "MapInfo -layers triangles" "drops the heights" \
  simplify -max_error 1 -of "MapInfo File" -layers triangles dem.tif ref/o.tab
refused_early "GPX, triangles" "-layers vertices" \
  simplify -max_error 1 -layers triangles dem.tif ref/o.gpx
refused_early "DXF -layers" "-layers is for OGR outputs" \
  simplify -max_error 1 -layers triangles dem.tif ref/o.dxf
refused_early "-lco FID= one of the TIN's fields" "v0 is a field of the triangles layer" \
  simplify -max_error 1 -lco FID=v0 dem.tif ref/o.gpkg
refused_early "-lco FID=vertex_id" "vertex_id is a field of the vertices layer" \
  simplify -max_error 1 -lco FID=vertex_id dem.tif ref/o.gpkg
refused_early "-lco FID=max_error" "max_error is a field of the run_parameters" \
  simplify -max_error 1 -lco FID=max_error dem.tif ref/o.gpkg
refused_early "-nln gpkg_" "reserves the table names that begin with \"gpkg\"" \
  simplify -max_error 1 -nln gpkg_ dem.tif ref/o.gpkg
refused_early "-nln sqlite_" "reserves the table names that begin with \"sqlite_\"" \
  simplify -max_error 1 -nln sqlite_ dem.tif ref/o.gpkg
refused_early "-nln sqlite_ into SQLite" "SQLite reserves" \
  simplify -max_error 1 -nln sqlite_ dem.tif ref/o.sqlite
refused_early "a -lco the driver refuses" "-lco" \
  simplify -max_error 1 -lco GEOMETRY_NAME=fid dem.tif ref/o.gpkg
# a failure that is not the driver's is said as the write would say it
run generate bump nocrs.tif -size 30 -q
run simplify -q -t_srs EPSG:4326 -layers triangles nocrs.tif ref/n.geojson
check "no CRS to transform from: exit 2 (refused up front), not a driver refusal ($rc)" [ "$rc" -eq 2 ]
check "no CRS to transform from: says so" grep -q "no CRS" err.txt
check "no CRS to transform from: nothing left" [ -z "$(ls -A ref)" ]
# a DEM without a CRS is in pixel or map units: "Undefined Cartesian SRS"
# (srs_id -1) in the layers and in every geometry blob, whole and tiled
# (the tiled rows are written by terratin's own page writer)
for how in whole tiled; do
  opt=()
  [ $how = tiled ] && opt=(-tile_size 16)
  run simplify -q "${opt[@]}" nocrs.tif nocrs_$how.gpkg
  check "no CRS, $how: exit 0 ($(head -c 200 err.txt))" [ "$rc" -eq 0 ]
  check "no CRS, $how: srs_id -1 in gpkg_geometry_columns and every blob" \
    python3 - nocrs_$how.gpkg <<'EOF'
import sqlite3, struct, sys
db = sqlite3.connect(sys.argv[1])
assert {r[0] for r in db.execute(
    "SELECT srs_id FROM gpkg_geometry_columns")} == {-1}
for t in ("triangles", "vertices"):
    for (g,) in db.execute("SELECT geom FROM " + t):
        assert struct.unpack("<i", g[4:8])[0] == -1, t
EOF
done
# the folder forms hold them all
run simplify -q -max_error 1 -of FlatGeobuf dem.tif ref/fg
check "FlatGeobuf folder: exit 0 ($(cat err.txt))" [ "$rc" -eq 0 ]
check "FlatGeobuf folder: vertices $NV" \
  [ "$(fcount ref/fg/vertices.fgb vertices)" = "$NV" ]
rm -rf ref/fg

for bad in "tri" "triangles,triangles" "" "triangles,,vertices"; do
  run simplify -max_error 1 -layers "$bad" dem.tif ref/o.gpkg
  check "-layers '$bad': usage error" [ "$rc" -eq 2 ]
  check "-layers '$bad': one line naming -layers" grep -q -- "-layers" err.txt
done
run simplify -max_error 1 -layers triangles dem.tif ref/o.ply
check "-layers with a mesh format: usage error" [ "$rc" -eq 2 ]
check "usage errors: nothing left" [ -z "$(ls -A ref)" ]

# a subset into a GeoPackage (its rows written straight through SQLite)
run simplify -q -max_error 1 -layers vertices,run_parameters dem.tif sub.gpkg
check "GPKG -layers vertices,run_parameters: exit 0 ($(cat err.txt))" [ "$rc" -eq 0 ]
check "GPKG subset: vertices $NV" [ "$(fcount sub.gpkg vertices)" = "$NV" ]
check "GPKG subset: no triangles layer" \
  not ogrinfo -ro -q sub.gpkg 2>/dev/null | grep -q ' triangles'
check "GPKG subset: R-tree of the vertices" \
  python3 -c 'import sqlite3,sys; c=sqlite3.connect(sys.argv[1]); assert c.execute("select count(*) from rtree_vertices_geom").fetchone()[0]==int(sys.argv[2])' sub.gpkg "$NV"

# --- Shapefile spatial index -------------------------------------------------
mkdir shp
run simplify -q -max_error 1 dem.tif shp/t.shp
check "Shapefile: exit 0 ($(cat err.txt))" [ "$rc" -eq 0 ]
check "Shapefile: t_triangles.qix" [ -s shp/t_triangles.qix ]
check "Shapefile: t_vertices.qix" [ -s shp/t_vertices.qix ]
check "Shapefile: no temporary left" [ -z "$(ls -A shp | grep '^\.')" ]
run simplify -q -overwrite -max_error 2 dem.tif shp/t.shp
check "Shapefile -overwrite: exit 0 ($(cat err.txt))" [ "$rc" -eq 0 ]
check "Shapefile -overwrite: the new .qix" \
  [ shp/t_triangles.qix -nt dem.tif -a -s shp/t_triangles.qix ]
run simplify -q -max_error 1 -lco SPATIAL_INDEX=NO dem.tif shp/n.shp
check "Shapefile -lco SPATIAL_INDEX=NO: no .qix" [ ! -e shp/n_triangles.qix ]
run simplify -q -overwrite -max_error 1 dem.tif shp/t.shp
# a spatial filter through the index finds what the GeoPackage finds
read -r x0 y0 x1 y1 < <(python3 - dem.tif <<'EOF'
import subprocess, sys, json
info = json.loads(subprocess.run(["gdalinfo", "-json", sys.argv[1]],
                  capture_output=True, text=True).stdout)
c = info["cornerCoordinates"]
xs = [c["upperLeft"][0], c["lowerRight"][0]]
ys = [c["upperLeft"][1], c["lowerRight"][1]]
w, h = xs[1] - xs[0], ys[0] - ys[1]
print(xs[0] + 0.3 * w, ys[1] + 0.3 * h, xs[0] + 0.6 * w, ys[1] + 0.55 * h)
EOF
)
n_shp=$(ogrinfo -ro -so -spat "$x0" "$y0" "$x1" "$y1" shp/t_triangles.shp \
        t_triangles | sed -n 's/^Feature Count: //p')
run simplify -q -overwrite -max_error 1 -lco SPATIAL_INDEX=NO dem.tif shp/n.shp
n_scan=$(ogrinfo -ro -so -spat "$x0" "$y0" "$x1" "$y1" shp/n_triangles.shp \
         n_triangles | sed -n 's/^Feature Count: //p')
n_gpkg=$n_scan
check "Shapefile: a window finds through the .qix the $n_scan triangles a \
scan finds (got $n_shp)" \
  [ -n "$n_shp" -a "$n_shp" = "$n_gpkg" -a "$n_shp" -gt 0 -a "$n_shp" -lt "$NT" ]

# --- the GeoPackage's default style -----------------------------------------
python3 - ref.gpkg "$NT" <<'EOF' >style.txt 2>&1 || fail "layer_styles: $(cat style.txt)"
import sqlite3, sys
c = sqlite3.connect(sys.argv[1])
cols = [r[1] for r in c.execute("PRAGMA table_info(layer_styles)")]
want = ["id", "f_table_catalog", "f_table_schema", "f_table_name",
        "f_geometry_column", "styleName", "styleQML", "styleSLD",
        "useAsDefault", "description", "owner", "ui", "update_time"]
assert cols == want, cols
rows = c.execute("SELECT f_table_catalog, f_table_schema, f_table_name, "
                 "f_geometry_column, useAsDefault, styleName FROM "
                 "layer_styles ORDER BY f_table_name").fetchall()
geom = dict(c.execute("SELECT table_name, column_name FROM "
                      "gpkg_geometry_columns").fetchall())
assert [r[2] for r in rows] == ["triangles", "vertices"], rows
for cat, schema, table, g, default, name in rows:
    assert cat == "" and schema == "" and default == 1 and name == table, rows
    assert g == geom[table], (g, geom)
# registered as an attributes table, as OGR (and QGIS) make it
kind = c.execute("SELECT data_type FROM gpkg_contents WHERE table_name = "
                 "'layer_styles'").fetchone()
assert kind == ("attributes",), kind
for table in ("triangles", "vertices"):
    q = c.execute("SELECT styleQML FROM layer_styles WHERE f_table_name = ?",
                  (table,)).fetchone()[0]
    open("style_%s.qml" % table, "w").write(q)
EOF
for t in triangles vertices; do
  check "style of $t: the QML parses" xmllint --noout style_$t.qml
done
attr() { xmllint --xpath "string(/qgis/renderer-v2/@$2)" "$1" 2>/dev/null; }
check "style of triangles: graduated on max_err" \
  [ "$(attr style_triangles.qml attr)" = "max_err" -a \
    "$(attr style_triangles.qml type)" = "graduatedSymbol" ]
check "style of vertices: graduated on ins_err" \
  grep -q '^coalesce("ins_err", -1)$' <(attr style_vertices.qml attr)
check "style of triangles: colour classes over the triangles' max_err" \
  python3 - style_triangles.qml ref.gpkg <<'EOF'
import sqlite3, sys, xml.etree.ElementTree as ET
r = ET.parse(sys.argv[1]).getroot().find("renderer-v2")
ranges = r.find("ranges").findall("range")
syms = r.find("symbols").findall("symbol")
assert 3 <= len(ranges) <= 5 and len(syms) == len(ranges)
lo = float(ranges[0].get("lower")); hi = float(ranges[-1].get("upper"))
c = sqlite3.connect(sys.argv[2])
mn, mx = c.execute("SELECT MIN(max_err), MAX(max_err) FROM triangles").fetchone()
assert abs(lo - mn) <= 1e-9 * max(1, abs(mn)) and abs(hi - mx) <= 1e-9 * max(1, mx), (lo, hi, mn, mx)
for a, b in zip(ranges, ranges[1:]):
    assert a.get("upper") == b.get("lower")
EOF
run simplify -q -max_error 1 -nostyle dem.tif nostyle.gpkg
check "-nostyle: exit 0 ($(cat err.txt))" [ "$rc" -eq 0 ]
check "-nostyle: no layer_styles" \
  python3 -c 'import sqlite3,sys; c=sqlite3.connect(sys.argv[1]); assert not c.execute("select 1 from sqlite_master where name=\"layer_styles\"").fetchall()' nostyle.gpkg
run simplify -q -max_error 1 -nln tin_ -layers triangles,run_parameters dem.tif pre.gpkg
check "-nln with a style: exit 0 ($(cat err.txt))" [ "$rc" -eq 0 ]
check "-nln: the style names tin_triangles, one row" \
  python3 -c 'import sqlite3,sys; c=sqlite3.connect(sys.argv[1]); r=c.execute("select f_table_name from layer_styles").fetchall(); assert r==[("tin_triangles",)], r' pre.gpkg

# QGIS itself, when installed
if /usr/bin/python3 -c 'import qgis' >/dev/null 2>&1; then
  QT_QPA_PLATFORM=offscreen /usr/bin/python3 - ref.gpkg >qgis.txt 2>&1 <<'EOF'
import sys
from qgis.core import QgsApplication, QgsVectorLayer
app = QgsApplication([], False)
app.initQgis()
for table, field in (("triangles", "max_err"), ("vertices", "ins_err")):
    layer = QgsVectorLayer("%s|layername=%s" % (sys.argv[1], table), table, "ogr")
    assert layer.isValid(), table
    r = layer.renderer()
    assert r.type() == "graduatedSymbol", (table, r.type())
    assert field in r.classAttribute(), (table, r.classAttribute())
    assert len(r.ranges()) >= 3, (table, len(r.ranges()))
    print(table, r.type(), r.classAttribute(), len(r.ranges()))
sys.stdout.flush()
import os
os._exit(0)  # QGIS 3.22's teardown may crash after the checks
EOF
  check "QGIS opens both layers with their graduated style ($(tail -3 qgis.txt))" \
    [ "$(grep -c ' graduatedSymbol ' qgis.txt)" = 2 ]
else
  echo "SKIP: QGIS loading the style: python3-qgis is not installed"
fi

echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
