#!/usr/bin/env bash
# test_breaklines.sh -- -breaklines through the terratin command
# ($TT_TERRATIN), on a synthetic valley (120 x 100 samples of 10 m, UTM
# 17N) with a meandering stream and a straight road across it (a GeoJSON
# written here):
#  - each line is followed by a path of the breaklines layer's edges from
#    its first sample on the grid to its last, and that layer is exactly
#    the edges the triangles' constrained field flags
#    (tests/apps/breakline_path.py); without -breaklines the road is not
#    followed even by the TIN's edges, and there is no such layer or field;
#  - so it stays under every optimiser (-optimize local, lookahead,
#    anneal): they never flip a breakline's edge;
#  - the bound holds by `terratin eval`, and the TIN is conforming
#    (tin_topology.py);
#  - the stream leaves the grid: one line clipped, warned; lines across a
#    nodata hole are clipped there and the run still holds the bound;
#  - -breaklines_where picks features, -breaklines_layer a layer; a missing
#    file, layer or bad filter fails on one line naming it, nothing written;
#    tiled runs are refused (not yet);
#  - -method decimate (-start all, greedy) keeps the lines and the bound;
#  - LandXML carries the same edges in Surface/SourceData/Breaklines;
#  - the Jacksboro fault DEM (testdata/) with a line drawn across it in
#    longitude/latitude.
# Prints "N passed, M failed"; exits 1 on any failure, 77 (skip) when a tool
# is missing.
set -u
. "$(dirname "${BASH_SOURCE[0]}")/tt_check.sh" || exit 1
HERE=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)

T=${TT_TERRATIN:-}
if [ -z "$T" ] || [ ! -x "$T" ]; then
  echo "SKIP: TT_TERRATIN is not set or not executable"
  exit 77
fi
for tool in gdal_translate ogrinfo python3; do
  if ! command -v "$tool" >/dev/null 2>&1; then
    echo "SKIP: $tool is missing"
    exit 77
  fi
done

W=$(mktemp -d "${TMPDIR:-/tmp}/tt_breaklines.XXXXXX") || exit 1
trap 'rm -rf "$W"' EXIT
cd "$W" || exit 1

python3 - <<'PYEOF' || exit 1
import json, math
nx, ny = 120, 100
def x0(y): return 60 + 15 * math.sin(y / 12.0)
def write(name, hole):
    rows = []
    for r in range(ny):
        row = []
        for c in range(nx):
            d = abs(c - x0(r))
            z = 100 + 0.8 * d + 0.05 * d * d - 0.3 * r + \
                2 * math.sin(c / 7.0) * math.cos(r / 9.0)
            if hole and (c - 30) ** 2 + (r - 28) ** 2 < 36:
                row.append("-9999")
            else:
                row.append("%.3f" % z)
        rows.append(" ".join(row))
    open(name, "w").write("ncols %d\nnrows %d\nxllcorner 500000\n"
                          "yllcorner 4000000\ncellsize 10\n"
                          "NODATA_value -9999\n" % (nx, ny) +
                          "\n".join(rows) + "\n")
write("valley.asc", False)
write("holed.asc", True)
stream = [[500000 + 10 * (x0(r) + 0.5), 4000000 + 10 * (ny - r - 0.5)]
          for r in [-5 + k * (ny + 10) / 200.0 for k in range(201)]]
crs = {"type": "name", "properties": {"name": "urn:ogc:def:crs:EPSG::32617"}}
def fc(feats):
    return {"type": "FeatureCollection", "crs": crs, "features": [
        {"type": "Feature", "properties": p,
         "geometry": {"type": "LineString", "coordinates": g}}
        for p, g in feats]}
json.dump(fc([({"kind": "stream"}, stream),
              ({"kind": "road"}, [[500050, 4000950], [501150, 4000100]])]),
          open("lines.geojson", "w"))
json.dump(fc([({"kind": "road"}, [[500050, 4000950], [501150, 4000100]])]),
          open("road.geojson", "w"))
PYEOF
gdal_translate -q -a_srs EPSG:32617 valley.asc valley.tif || exit 1
gdal_translate -q -a_srs EPSG:32617 holed.asc holed.tif || exit 1
GRID="500000 4001000 10 120 100"

follows() { python3 "$HERE/breakline_path.py" "$1" "$2" $GRID >path.log; }
bound() { "$T" eval "$1" "$2" -max_error "$3" -q >/dev/null 2>&1; }
conforming() { python3 "$HERE/tin_topology.py" "$1" >/dev/null; }

# the lines followed, the bound held
"$T" simplify valley.tif bl.gpkg -max_error 1 -breaklines lines.geojson \
  -q 2>warn.txt
check "a run with -breaklines succeeds" test $? -eq 0
check "the stream and the road are followed by TIN edges" \
  follows bl.gpkg lines.geojson
check "the bound holds with breaklines" bound valley.tif bl.gpkg 1
check "the TIN with breaklines is conforming" conforming bl.gpkg
check "the stream leaving the grid is warned about once" \
  grep -q "stream.*\|1 of 2 breaklines clipped" warn.txt
check "one warning line" test "$(wc -l <warn.txt)" -eq 1
"$T" simplify valley.tif plain.gpkg -max_error 1 -q 2>/dev/null
if follows plain.gpkg road.geojson; then
  fail "without -breaklines the road is followed: the check tells nothing"
else
  pass
fi

check "a TIN without breaklines has no breaklines layer" \
  sh -c "! ogrinfo -q plain.gpkg breaklines >/dev/null 2>&1"
check "nor a constrained field" \
  sh -c "! ogrinfo -so plain.gpkg triangles | grep -q constrained"
check "a TIN with breaklines has both" \
  sh -c "ogrinfo -so bl.gpkg triangles | grep -q 'constrained: Integer'"

"$T" simplify valley.tif sum.gpkg -max_error 1 -breaklines lines.geojson \
  >sum.txt 2>/dev/null
check "the summary names the breaklines layer" \
  grep -q "layers triangles, vertices, run_parameters, breaklines" sum.txt
check "the summary counts the lines" grep -q "^lines:  2 breaklines read" sum.txt
"$T" simplify valley.tif sum.json.gpkg -max_error 1 -json \
  -breaklines lines.geojson >sum.json 2>/dev/null
check "the JSON counts the lines" python3 -c "
import json, sys
b = json.load(open('sum.json'))['breaklines']
sys.exit(0 if b['lines'] == 2 and b['segments'] > 2 else 1)"

# no optimiser flips a breakline's edge
for o in local lookahead anneal; do
  "$T" simplify valley.tif opt_$o.gpkg -max_error 1 -optimize $o \
    -criterion minmax_angle -breaklines lines.geojson -q 2>/dev/null
  check "-optimize $o runs" test $? -eq 0
  check "-optimize $o keeps the lines" follows opt_$o.gpkg lines.geojson
  check "-optimize $o keeps the bound" bound valley.tif opt_$o.gpkg 1
done

# decimation, from every sample and from the greedy start
for st in all greedy; do
  "$T" simplify valley.tif dec_$st.gpkg -max_error 1 -method decimate \
    -start $st -breaklines lines.geojson -q 2>/dev/null
  check "-method decimate -start $st runs" test $? -eq 0
  check "-method decimate -start $st keeps the lines" \
    follows dec_$st.gpkg lines.geojson
  check "-method decimate -start $st keeps the bound" \
    bound valley.tif dec_$st.gpkg 1
done

# LandXML: the same edges in Surface/SourceData/Breaklines, before the
# Definition as the schema orders them, chained into polylines
"$T" simplify valley.tif bl.xml -max_error 1 -breaklines lines.geojson -q \
  2>/dev/null
check "a LandXML output with breaklines runs" test $? -eq 0
landxml_lines() {
  python3 - "$1" "$2" <<'PYEOF'
import sqlite3, sys, xml.etree.ElementTree as ET
ns = {"l": "http://www.landxml.org/schema/LandXML-1.2"}
s = ET.parse(sys.argv[1]).getroot().find("l:Surfaces/l:Surface", ns)
kids = [c.tag.split("}")[1] for c in s]
pts = {}
for p in s.findall("l:Definition/l:Pnts/l:P", ns):
    pts[tuple(round(float(t), 6) for t in p.text.split())] = int(p.get("id"))
edges = set()
for b in s.findall("l:SourceData/l:Breaklines/l:Breakline", ns):
    t = [float(x) for x in b.find("l:PntList3D", ns).text.split()]
    ids = [pts[tuple(round(v, 6) for v in t[i:i + 3])]
           for i in range(0, len(t), 3)]
    edges |= {(min(a, b) - 1, max(a, b) - 1) for a, b in zip(ids, ids[1:])}
db = sqlite3.connect(sys.argv[2])
gpkg = {(min(a, b), max(a, b)) for a, b in
        db.execute("select v0, v1 from breaklines")}
sys.exit(0 if kids == ["SourceData", "Definition"] and edges == gpkg and
         edges else 1)
PYEOF
}
check "the LandXML breaklines are the GeoPackage's edges" \
  landxml_lines bl.xml bl.gpkg

# the filter and the layer
"$T" simplify valley.tif road.gpkg -max_error 1 -breaklines lines.geojson \
  -breaklines_where "kind = 'road'" -breaklines_layer lines -q 2>warn2.txt
check "-breaklines_where and -breaklines_layer run" test $? -eq 0
check "the road alone, not clipped: no warning" test ! -s warn2.txt
check "the road picked is followed" follows road.gpkg road.geojson

# a nodata hole on the road's path
"$T" simplify holed.tif holed.gpkg -max_error 1 -breaklines lines.geojson \
  -q 2>warn3.txt
check "a line across nodata runs" test $? -eq 0
check "both lines clipped: warned" grep -q "2 of 2 breaklines clipped" warn3.txt
check "the bound holds across the hole" bound holed.tif holed.gpkg 1

# failures: one line naming the thing, nothing written
fails() { # OUTPUT WHAT ARGS...
  local out=$1 what=$2
  shift 2
  "$T" simplify valley.tif "$out" -max_error 1 "$@" -q 2>err.txt
  local rc=$?
  [ $rc -ne 0 ] && [ ! -e "$out" ] && [ "$(wc -l <err.txt)" -eq 1 ] &&
    grep -q -- "$what" err.txt
}
check "a missing LINES fails naming it" \
  fails f1.gpkg "nope.geojson" -breaklines nope.geojson
check "a missing layer fails naming it" \
  fails f2.gpkg "no layer 'zz'" -breaklines lines.geojson \
  -breaklines_layer zz
check "a bad filter fails naming the option" \
  fails f3.gpkg "-breaklines_where" -breaklines lines.geojson \
  -breaklines_where "nosuchfield = 3"
check "a tiled run is refused" \
  fails f4.gpkg "not yet with a tiled run" -breaklines lines.geojson \
  -tile_size 64

# a real DEM: the Jacksboro fault (geographic), a line drawn across it
J="$HERE/../../testdata/jacksboro_fault_dem.tif"
if [ -f "$J" ]; then
  cat >fault.geojson <<'JEOF'
{"type": "FeatureCollection", "features": [{"type": "Feature",
 "properties": {}, "geometry": {"type": "LineString", "coordinates":
 [[-84.25, 36.45], [-84.15, 36.40], [-84.05, 36.38]]}}]}
JEOF
  "$T" simplify "$J" j.gpkg -max_error 20 -breaklines fault.geojson -q \
    2>jwarn.txt
  check "the Jacksboro DEM with a line runs" test $? -eq 0
  check "the bound holds on the Jacksboro DEM" bound "$J" j.gpkg 20
  check "the Jacksboro TIN is conforming" conforming j.gpkg
else
  echo "note: $J missing, the real-DEM checks skipped"
fi

echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
