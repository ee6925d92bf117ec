#!/usr/bin/env bash
# test_web_mercator_feet.sh -- projected DEMs whose map units are not ground
# metres, made by gdalwarp from the bundled Jacksboro DEM (real heights):
# Web Mercator (EPSG:3857, scale 1.24 there and growing as sec(lat)) and
# the Tennessee state plane in US survey feet (EPSG:2274), with metre
# heights and with the heights in feet (band unit ft, -z_to m). Every
# triangle's area_2d and slope in the output are checked against the same
# triangle measured independently: its vertices reprojected by ogr2ogr into
# a Lambert azimuthal equal-area projection centred on the DEM (areas
# exact on the ellipsoid, angles within a few 1e-6 over 30 km), the slope
# from the plane through the three corners. The Web Mercator DEM must say
# it has ground points ("per vertex"), the feet one the unit factor; a
# feet map whose heights declare no unit warns that they are taken as
# metres.
# Exits 1 on a failure, 77 when a tool is missing.
set -u
. "$(dirname "${BASH_SOURCE[0]}")/../apps/tt_python.sh"
T=${TT_TERRATIN:-}
D=${TT_TESTDATA:-}
if [ -z "$T" ] || [ ! -x "$T" ] || [ -z "$D" ]; then
  echo "SKIP: TT_TERRATIN or TT_TESTDATA is not set"
  exit 77
fi
for tool in gdalwarp gdal_translate ogr2ogr python3; do
  command -v "$tool" >/dev/null 2>&1 || { echo "SKIP: $tool is missing"; exit 77; }
done
W=$(mktemp -d "${TMPDIR:-/tmp}/tt_wmft.XXXXXX") || exit 1
trap 'rm -rf "$W"' EXIT
cd "$W" || exit 1
passed=0
failed=0
pass() { passed=$((passed + 1)); }
fail() { failed=$((failed + 1)); echo "FAIL: $*" >&2; }

src=$D/jacksboro_fault_dem.tif
# nodata 0 (the DEM's heights are 236 to 1076 m): scaling keeps it 0
gdalwarp -q -t_srs EPSG:3857 -r near -dstnodata 0 "$src" wm.tif &&
  gdalwarp -q -t_srs EPSG:2274 -r near -dstnodata 0 "$src" ft.tif ||
  { echo "FAIL: gdalwarp"; exit 1; }
# heights in feet: the metre heights divided by 0.3048, band unit ft
gdal_translate -q -of VRT -ot Float64 -scale 0 0.3048 0 1 ft.tif ftz.vrt &&
  sed -i 's|<VRTRasterBand \(.*\)>|<VRTRasterBand \1><UnitType>ft</UnitType>|' \
    ftz.vrt && grep -q '<UnitType>ft</UnitType>' ftz.vrt ||
  { echo "FAIL: the feet-heights VRT"; exit 1; }

LAEA="+proj=laea +lat_0=36.59 +lon_0=-84.24 +datum=WGS84 +units=m"

# check NAME TIN AREA_TOL SLOPE_TOL: every triangle's area_2d and slope
# against the LAEA measure; prints the largest relative differences
check() {
  local name=$1 tin=$2 atol=$3 stol=$4
  ogr2ogr -f CSV -t_srs "$LAEA" -lco GEOMETRY=AS_WKT "$name.csv" "$tin" \
    triangles 2>/dev/null || { fail "$name: ogr2ogr"; return; }
  if python3 - "$name" "$name.csv" "$atol" "$stol" <<'PY'; then pass; else fail "$name: triangles against the LAEA measure"; fi
import csv, math, re, sys
name, path = sys.argv[1], sys.argv[2]
csv.field_size_limit(1 << 24)
darea = dslope = 0.0
n = 0
for row in csv.DictReader(open(path)):
    nums = [float(v) for v in re.findall(r"[-0-9.eE+]+", row["WKT"].split("((")[1])]
    p = [nums[3 * k:3 * k + 3] for k in range(3)]
    ux, uy, uz = (p[1][i] - p[0][i] for i in range(3))
    vx, vy, vz = (p[2][i] - p[0][i] for i in range(3))
    nx, ny, nz = uy * vz - uz * vy, uz * vx - ux * vz, ux * vy - uy * vx
    area = 0.5 * abs(nz)
    darea = max(darea, abs(float(row["area_2d"]) / area - 1))
    tan_oracle = math.hypot(nx, ny) / abs(nz)
    tan_mine = math.tan(math.radians(float(row["slope"])))
    if tan_oracle > 0.02:
        dslope = max(dslope, abs(tan_mine / tan_oracle - 1))
    n += 1
print("%s: %d triangles; area_2d within %.3g, slope within %.3g of the "
      "LAEA measure" % (name, n, darea, dslope))
ok = n > 1000 and darea <= float(sys.argv[3]) and dslope <= float(sys.argv[4])
sys.exit(0 if ok else 1)
PY
}

"$T" simplify -q -json -max_error 5 wm.tif wm.gpkg >wm.json 2>wm.err ||
  fail "Web Mercator: simplify failed: $(cat wm.err)"
grep -q 'per vertex' wm.json && pass || fail "Web Mercator: no ground points: $(grep -o '"frame": *"[^"]*"' wm.json)"
# ground points: the ground itself, to the LAEA measure's own few 1e-6
check wm wm.gpkg 1e-5 1e-4

"$T" simplify -q -json -max_error 5 ft.tif ft.gpkg >ft.json 2>ft.err ||
  fail "feet: simplify failed: $(cat ft.err)"
grep -q 'm per US survey foot' ft.json && pass || fail "feet: frame $(grep -o '"frame": *"[^"]*"' ft.json)"
# the state plane's own map, in metres: its scale factor (within 1e-4 of
# 1 there) is all that is left, as for a DEM in metres on UTM (0.9996);
# feet taken for metres would be 10.8 times off in area, 3.3 in slope
check ft ft.gpkg 5e-4 5e-4

# heights in feet on a map in feet: kept so by default (-z_to auto), and
# converted by -z_to m, the vertices' z in metres
"$T" simplify -q -json -max_error 5 -z_to m ftz.vrt ftz.gpkg >ftz.json \
  2>ftz.err || fail "feet heights: simplify failed: $(cat ftz.err)"
check ftz ftz.gpkg 5e-4 5e-4

# a map in feet whose heights declare no unit: one warning that they are
# taken as metres; none when they declare one
gdal_translate -q -of VRT ft.tif nounit.vrt && sed -i '/<UnitType>/d' nounit.vrt
"$T" simplify -q -max_error 20 nounit.vrt nounit.gpkg 2>nounit.err ||
  fail "no height unit: simplify failed: $(cat nounit.err)"
grep -q 'heights declare no unit' nounit.err && pass ||
  fail "no height unit: no warning: $(cat nounit.err)"
grep -q 'declare no unit' ft.err ftz.err && fail "a warning with a height unit" || pass
echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
