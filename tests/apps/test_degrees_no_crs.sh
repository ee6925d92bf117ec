#!/usr/bin/env bash
# test_degrees_no_crs.sh -- a DEM whose geotransform looks like
# longitude/latitude degrees but that carries no CRS ($TT_TERRATIN), issue
# 26: the bundled Jacksboro DEM (3 arc-seconds) as an ESRI ASCII grid
# without its .prj, as SRTM tiles travel. simplify warns once, loudly, with
# the way out (-a_srs, or a VRT with it), whole and tiled on two threads, and
# names the frame so in the summary and -json; the same grid with its .prj,
# a synthetic terrain on the unit square and a DEM in pixel units get no
# such warning. Prints "N passed, M failed"; exits 1 on any failure, 77
# when a tool is missing.
set -u
. "$(dirname "${BASH_SOURCE[0]}")/../apps/tt_check.sh" || exit 1

T=${TT_TERRATIN:-}
if [ -z "$T" ] || [ ! -x "$T" ]; then
  echo "SKIP: TT_TERRATIN is not set or not executable"
  exit 77
fi
if ! command -v gdal_translate >/dev/null 2>&1; then
  echo "SKIP: gdal_translate is missing"
  exit 77
fi
SRC=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)/testdata/jacksboro_fault_dem.tif
W=$(mktemp -d "${TMPDIR:-/tmp}/tt_degrees.XXXXXX") || exit 1
trap 'rm -rf "$W"' EXIT
cd "$W" || exit 1
not() { ! "$@"; }

gdal_translate -q -of AAIGrid -srcwin 0 0 120 100 "$SRC" srtm.asc ||
  { echo "FAIL: gdal_translate"; exit 1; }
cp srtm.prj kept.prj
rm -f srtm.prj

for how in whole tiled; do
  opt=()
  [ $how = tiled ] && opt=(-tile_size 40 -threads 2)
  "$T" simplify "${opt[@]}" -json srtm.asc $how.gpkg >out.json 2>err.txt
  rc=$?
  check "$how: exit 0 ($(head -c 200 err.txt))" [ $rc -eq 0 ]
  check "$how: one warning that it looks like degrees" \
    [ "$(grep -c 'has no CRS, but its geotransform looks like longitude/latitude degrees' err.txt)" = 1 ]
  check "$how: the warning gives the way out" grep -q -- "-a_srs EPSG:4326" err.txt
  "$T" simplify "${opt[@]}" -q -a_srs EPSG:4326 srtm.asc ${how}_a.gpkg 2>err.txt
  check "$how: with -a_srs EPSG:4326, no such warning" not grep -q "looks like" err.txt
  check "$how: -json names the frame" python3 -c '
import json, sys
d = json.load(open("out.json"))
assert "look like degrees" in d["frame"], d["frame"]
assert d["warnings"] >= 1
'
done

# with its .prj: a geographic DEM, measured on the ground, no warning
cp kept.prj srtm.prj
"$T" simplify -q srtm.asc prj.gpkg 2>err.txt
check "with its .prj: no such warning" not grep -q "looks like" err.txt
rm -f srtm.prj
# a synthetic terrain on the unit square (no CRS) and pixel units
"$T" generate bump bump.tif -size 40 -q
"$T" simplify -q bump.tif bump.gpkg 2>err.txt
check "unit-square terrain: no such warning" not grep -q "looks like" err.txt
gdal_translate -q -a_ullr 0 100 120 0 srtm.asc pixels.tif
"$T" simplify -q pixels.tif pixels.gpkg 2>err.txt
check "pixel units: no such warning" not grep -q "looks like" err.txt

echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
