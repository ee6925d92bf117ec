#!/usr/bin/env bash
# test_formats.sh -- the DEM formats the issue names, made on the spot with
# GDAL from the bundled Jacksboro DEM (real heights, real georeferencing):
# SRTM HGT and DTED tiles (the DEM fills part of each one-degree tile, the
# rest is nodata), a VRT, an ASCII grid inside a zip read through /vsizip/,
# and validity from an alpha band and from an external .msk mask. Each is simplified, then measured by `terratin eval`: every
# valid sample covered once, the bound met, the valid count right.
set -u
. "$(dirname "${BASH_SOURCE[0]}")/tt_python.sh"
T=${TT_TERRATIN:?} D=${TT_TESTDATA:?}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$work" || exit 1
pass=0 fail=0
check() {
  local what=$1; shift
  if "$@"; then pass=$((pass + 1)); else echo "FAIL: $what"; fail=$((fail + 1)); fi
}
get() { python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))[sys.argv[2]])' "$1" "$2"; }

src=$D/jacksboro_fault_dem.tif
valid=138632
# one-degree tiles: HGT at 3 arc-seconds, DTED level 0 at 30 arc-seconds
gdalwarp -q -te -85 36 -84 37 -ts 1201 1201 -r near -dstnodata -32768 \
  -ot Int16 "$src" tile3.tif
gdal_translate -q -of SRTMHGT tile3.tif N36W085.hgt
gdalwarp -q -te -85 36 -84 37 -ts 121 121 -r near -dstnodata -32767 \
  -ot Int16 "$src" tile30.tif
gdal_translate -q -of DTED tile30.tif n36.dt0
gdal_translate -q -of VRT "$src" dem.vrt
gdal_translate -q -of AAIGrid "$src" dem.asc && zip -q dem.zip dem.asc dem.prj 2>/dev/null

# validity from GDAL's mask band: an alpha band (the area the warp adds is
# transparent, its heights 0, no nodata value), and an external .msk file
gdalwarp -q -te -84.6 36.3 -83.9 36.9 -tr 0.000833333333333 0.000833333333333 \
  -r near -dstalpha -ot UInt16 "$src" alpha.tif
gdalwarp -q -te -84.6 36.3 -83.9 36.9 -tr 0.000833333333333 0.000833333333333 \
  -r near -dstnodata -32768 -ot Int16 "$src" nd.tif
gdal_translate -q -b 1 -mask 1 -a_nodata none \
  --config GDAL_TIFF_INTERNAL_MASK NO nd.tif msk.tif
check "the .msk file was made" [ -f msk.tif.msk ]
# a real DEM with NaN voids: two lakes burnt into a Float32 copy
gdal_translate -q -ot Float32 -a_nodata nan "$src" voids.tif
cat >lakes.geojson <<'JSON'
{"type":"FeatureCollection","features":[
{"type":"Feature","properties":{},"geometry":{"type":"Polygon","coordinates":[[[-84.30,36.60],[-84.25,36.62],[-84.22,36.58],[-84.27,36.55],[-84.30,36.60]]]}},
{"type":"Feature","properties":{},"geometry":{"type":"Polygon","coordinates":[[[-84.15,36.50],[-84.12,36.51],[-84.13,36.48],[-84.15,36.50]]]}}]}
JSON
gdal_rasterize -q -burn nan lakes.geojson voids.tif

for spec in "N36W085.hgt:$valid" "n36.dt0:" "dem.vrt:$valid" \
            "/vsizip/dem.zip/dem.asc:$valid" "alpha.tif:$valid" "msk.tif:$valid" \
            "voids.tif:"; do
  f=${spec%%:*} want=${spec##*:}
  case $f in /vsizip/*) [ -f dem.zip ] || { echo "SKIP: no zip command"; continue; } ;; esac
  out=$(echo "$f" | tr '/.' '__').gpkg
  "$T" simplify -q -json -max_error 10 "$f" "$out" >s.json 2>err.txt
  rc=$? # before the check: its $(...) would reset $?
  check "$f: simplify exit 0 ($(head -c 200 err.txt))" [ $rc -eq 0 ]
  [ -s s.json ] || continue
  [ -n "$want" ] && check "$f: $want valid samples" [ "$(get s.json valid_samples)" = "$want" ]
  "$T" eval -json -max_error 10 "$f" "$out" >e.json 2>err.txt
  check "$f: eval passes the bound" [ $? -eq 0 ]
  check "$f: every valid sample covered once" python3 -c '
import json, sys
e, s = json.load(open("e.json")), json.load(open("s.json"))
assert e["overlapped"] == 0 and e["uncovered"] == s["lone_samples"], (e, s)
assert e["valid_samples"] == s["valid_samples"], (e, s)'
done
# the lakes stay holes: no triangle holds a point inside the big one, and
# one does hold a point on land
n_in_lake() {
  ogrinfo -q -dialect SQLite -sql "SELECT COUNT(*) AS n FROM triangles WHERE ST_Intersects(geom, MakePoint($1, $2, 4326))" \
    voids_tif.gpkg 2>/dev/null | sed -n 's/.*n (Integer) = //p'
}
check "NaN voids: the lake is a hole" [ "$(n_in_lake -84.26 36.59)" = 0 ]
check "NaN voids: the land is covered" [ "$(n_in_lake -84.20 36.65)" = 1 ]
check "NaN voids: fewer valid samples than the DEM" python3 -c '
import json; d = json.load(open("s.json")); assert d["valid_samples"] < 138632, d'

# the HGT tile holds exactly the Jacksboro samples; its working frame is
# fitted at the tile's centre, not the DEM's, and its outline is a nodata
# outline, so the TINs differ a little: vertex counts within 1 %
"$T" simplify -q -json -max_error 10 "$src" tif.gpkg >t.json 2>/dev/null
"$T" simplify -q -json -max_error 10 N36W085.hgt hgt2.gpkg >h.json 2>/dev/null
check "HGT tile and GeoTIFF: vertex counts within 1 %" python3 -c '
import json
a, b = json.load(open("t.json"))["vertices"], json.load(open("h.json"))["vertices"]
assert abs(a - b) <= 0.01 * a, (a, b)'
echo "$pass passed, $fail failed"
[ "$fail" -eq 0 ]
