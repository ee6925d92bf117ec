#!/usr/bin/env bash
# test_eval_formats.sh -- `terratin eval` ($TT_TERRATIN) reading the same
# TIN from every file that may hold it, and giving the same figures
# (triangles, covered samples, max error, RMS error) for each:
#  - every format terratin writes: GeoPackage, Shapefile, SQLite,
#    GeoJSON, FlatGeobuf, GML, 2DM, PLY, OBJ (and -obj_local), LandXML,
#    DXF (3DFACE), UGRID netCDF;
#  - other tools' files, made by eval_formats.py from the OBJ: ASCII STL
#    (map coordinates), binary STL in hmm's pixel frame (found by itself,
#    by its extent on a georeferenced DEM, by its heights on generate's
#    DEM whose map coordinates are its grid, and with -stl_frame pixel;
#    hmm's heights less 100 put back by -tin_transform, or a refusal
#    asking for -stl_frame when neither frame is evident), ascii and big-endian binary PLY with extra
#    properties and elements, OBJ with v/t/n corners and negative indices,
#    2DM with the elements first, LandXML with sparse ids and an invisible
#    face, CSV with the whole TIN as one TIN Z WKT, DXF 3DFACE with the
#    fourth corner repeating the third;
#  - OGR conversions (ogr2ogr): TIN Z, POLYHEDRALSURFACE Z and
#    MULTIPOLYGON Z layers, a MULTIPATCH Shapefile (a layer of "Unknown"
#    geometry), CSV with GEOMETRY=AS_WKT;
#  - the TIN in another CRS, reprojected for the measurement: ogr2ogr
#    -t_srs to EPSG:4326, 3857 and 32632, and terratin's own -t_srs into
#    PLY (comment crs:), LandXML (CoordinateSystem) and UGRID (crs_wkt);
#  - failures in one line: a face naming a missing vertex, -layer with a
#    mesh file (exit 1), a bad
#    -tin_transform or -tin_frame (exit 2), a pixel-frame STL read as map
#    coordinates (exit 1, naming the options), and -error_raster from an
#    STL matching its max error.
# The DEM: a 65 x 65 fractal placed in UTM 33N (1 m pixels). Exact formats
# must give the very figures of the GeoPackage (%.17g), reprojected ones
# included; those that round (GML, CSV: 15 digits) or reorder the
# triangles (FlatGeobuf) within 1e-12; float32 ones (binary STL heights
# less an offset) within 1e-5.
# Prints "N passed, M failed"; exits 1 on any failure, 77 when a tool is
# missing.
set -u
. "$(dirname "${BASH_SOURCE[0]}")/../apps/tt_check.sh" || exit 1
HERE=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)

T=${TT_TERRATIN:-}
if [ -z "$T" ] || [ ! -x "$T" ]; then
  echo "SKIP: TT_TERRATIN is not set or not executable"
  exit 77
fi
for tool in gdal_translate ogr2ogr; do
  if ! command -v $tool >/dev/null 2>&1; then
    echo "SKIP: $tool is missing (gdal-bin)"
    exit 77
  fi
done
if ! command -v python3 >/dev/null 2>&1; then
  echo "SKIP: python3 is missing"
  exit 77
fi

W=$(mktemp -d "${TMPDIR:-/tmp}/tt_eval_formats.XXXXXX") || exit 1
trap 'rm -rf "$W"' EXIT
cd "$W" || exit 1

"$T" generate diamond_square d0.tif -size 65 -seed 3 -q || exit 1
gdal_translate -q -a_srs EPSG:32633 -a_ullr 500000 5000065 500065 5000000 \
  d0.tif dem.tif || exit 1

# figures FILE [eval options]: "triangles covered max_error rmse" from
# eval's JSON, or the exit code and message on failure.
figures() {
  local f=$1
  shift
  "$T" eval "${DEM:-dem.tif}" "$f" -json "$@" >e.json 2>e.err || {
    echo "exit $?: $(head -c 300 e.err)"
    return
  }
  python3 -c '
import json, sys
d = json.load(open("e.json"))
print(d["triangles"], d["covered"], repr(d["max_error"]), repr(d["rmse"]))'
}
field() { # field NAME: one value of the last e.json
  python3 -c 'import json,sys; print(json.load(open("e.json"))[sys.argv[1]])' "$1"
}
same() { # same WHAT FILE [options]: the reference figures exactly
  local what=$1
  shift
  local got
  got=$(figures "$@")
  check "$what: same figures as the GeoPackage (got '$got', want '$REF')" \
    [ "$got" = "$REF" ]
}
close() { # close TOL WHAT FILE [options]: within TOL
  local tol=$1 what=$2
  shift 2
  local got
  got=$(figures "$@")
  check "$what: figures within $tol of the GeoPackage's ('$got' vs '$REF')" \
    python3 -c '
import sys
a, b = sys.argv[1].split(), sys.argv[2].split()
ok = len(a) == 4 and a[:2] == b[:2] and all(
    abs(float(x) - float(y)) <= float(sys.argv[3])
    for x, y in zip(a[2:], b[2:]))
sys.exit(0 if ok else 1)' "$got" "$REF" "$tol"
}

# one_line PATTERN: err.txt is one line that holds PATTERN.
one_line() { [ "$(wc -l <err.txt)" -eq 1 ] && grep -q -- "$1" err.txt; }

simplify() { "$T" simplify -q -overwrite -max_error 2 dem.tif "$@"; }

# --- terratin's own formats ------------------------------------------------
simplify t.gpkg || exit 1
REF=$(figures t.gpkg)
check "reference: 7000+ triangles covering the 4225 samples ($REF)" \
  python3 -c 'import sys; a=sys.argv[1].split(); sys.exit(not (int(a[0]) > 7000 and a[1] == "4225"))' "$REF"

mkdir shp
simplify shp/t -of "ESRI Shapefile"
same "Shapefile" shp/t_triangles.shp
simplify t.sqlite
same "SQLite" t.sqlite
simplify t.geojson -layers triangles
same "GeoJSON" t.geojson
simplify t.fgb -layers triangles
# FlatGeobuf's spatial index reorders the triangles (the sums then differ
# in the last bit); GML and CSV write 15 significant digits.
close 1e-12 "FlatGeobuf" t.fgb
simplify t.gml -layers triangles
close 1e-12 "GML" t.gml
for ext in 2dm ply obj xml dxf; do
  simplify t.$ext
  same "terratin .$ext" t.$ext
done
simplify tl.obj -obj_local
check "-obj_local: an origin line" grep -q '^# origin ' tl.obj
same "terratin -obj_local OBJ" tl.obj
simplify t.nc -of UGRID
same "terratin UGRID" t.nc
figures t.nc >/dev/null
check "UGRID: format named in the JSON" [ "$(field format)" = UGRID ]

# --- other tools' files -------------------------------------------------------
mkdir o
python3 "$HERE/eval_formats.py" t.obj 65 65 500000,1,0,5000065,0,-1 o ||
  fail "eval_formats.py"
same "ASCII STL" o/ascii.stl
same "binary STL, pixel frame found by itself" o/pixel.stl
figures o/pixel.stl >/dev/null
check "binary STL: frame pixel in the JSON" [ "$(field frame)" = pixel ]
same "binary STL, -stl_frame pixel" o/pixel.stl -stl_frame pixel
close 1e-5 "hmm's STL (z - 100), -tin_transform 1,1,1,0,0,100" o/hmm.stl \
  -tin_transform 1,1,1,0,0,100
# generate's own grid: map coordinates are the sample indices, so the
# pixel STL fits both frames and its heights decide; hmm's, whose heights
# match no sample without -tin_transform, asks for -stl_frame
DEM=d0.tif same "pixel STL on a DEM whose map frame is its grid" o/pixel.stl
DEM=d0.tif close 1e-5 "hmm's STL on that DEM, with -tin_transform" \
  o/hmm.stl -tin_transform 1,1,1,0,0,100
"$T" eval d0.tif o/hmm.stl >/dev/null 2>err.txt
rc=$?
check "hmm's STL, both frames fit, no height matches: exit 1 ($rc)" [ "$rc" -eq 1 ]
check "hmm's STL, both frames fit: asks for -stl_frame ($(cat err.txt))" \
  one_line "-stl_frame map or -stl_frame pixel"
"$T" eval dem.tif o/pixel.stl -stl_frame map >/dev/null 2>err.txt
rc=$?
check "pixel STL read as map: exit 1 ($rc)" [ "$rc" -eq 1 ]
check "pixel STL read as map: one line naming -tin_frame ($(cat err.txt))" \
  one_line "-tin_frame"
same "ascii PLY with an extra property and a quad" o/ascii.ply
figures o/ascii.ply >/dev/null
check "ascii PLY: the quad rejected" [ "$(field rejected)" = 1 ]
same "big-endian PLY with an extra element" o/big.ply
same "OBJ with v/t/n corners and negative indices" o/hand.obj
same "2DM with the elements first" o/sms.2dm
same "LandXML with sparse ids and an invisible face" o/hand.xml
figures o/hand.xml >/dev/null
check "LandXML: the invisible face rejected" [ "$(field rejected)" = 1 ]
same "CSV, the TIN as one TIN Z WKT" o/wkt.csv
same "DXF 3DFACE, fourth corner = third" o/faces.dxf

# --- OGR conversions ---------------------------------------------------------
for nlt in TINZ POLYHEDRALSURFACEZ MULTIPOLYGONZ; do
  ogr2ogr -f GPKG "$nlt.gpkg" t.gpkg triangles -nlt "$nlt" 2>/dev/null
  same "ogr2ogr -nlt $nlt" "$nlt.gpkg"
done
mkdir mp
ogr2ogr -f "ESRI Shapefile" mp/mp.shp TINZ.gpkg 2>/dev/null
check "MULTIPATCH Shapefile: its layer is of Unknown geometry" \
  sh -c 'ogrinfo -so mp/mp.shp mp | grep -q "Geometry: Unknown"'
same "MULTIPATCH Shapefile" mp/mp.shp
ogr2ogr -f CSV wkt2.csv t.gpkg triangles -lco GEOMETRY=AS_WKT 2>/dev/null
close 1e-12 "ogr2ogr CSV GEOMETRY=AS_WKT" wkt2.csv

# --- another CRS ---------------------------------------------------------------
for srs in EPSG:4326 EPSG:3857 EPSG:32632; do
  n=r_${srs#EPSG:}.gpkg
  ogr2ogr -t_srs "$srs" "$n" t.gpkg triangles
  same "ogr2ogr -t_srs $srs, reprojected back" "$n"
  figures "$n" >/dev/null
  check "-t_srs $srs: reprojected in the JSON" [ "$(field reprojected)" = True ]
done
simplify g.ply -t_srs EPSG:4326
same "terratin PLY in EPSG:4326 (comment crs:)" g.ply
simplify g.xml -t_srs EPSG:32632
same "terratin LandXML in EPSG:32632 (CoordinateSystem)" g.xml
simplify g.nc -of UGRID -t_srs EPSG:4326
same "terratin UGRID in EPSG:4326 (crs_wkt)" g.nc

# --- failures ------------------------------------------------------------------
printf 'ply\nformat ascii 1.0\nelement vertex 3\nproperty double x\nproperty double y\nproperty double z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n' >bad.ply
"$T" eval dem.tif bad.ply >/dev/null 2>err.txt
rc=$?
check "a face naming a missing vertex: exit 1 ($rc)" [ "$rc" -eq 1 ]
check "a face naming a missing vertex: one line ($(cat err.txt))" \
  one_line "face 1 names vertex 8"
for bad in "1,1,1,0,0" "1,1,0,0,0,0" "1,1,1,0,0,x"; do
  "$T" eval dem.tif o/hmm.stl -tin_transform "$bad" >/dev/null 2>err.txt
  rc=$?
  check "-tin_transform $bad: exit 2 ($rc)" [ "$rc" -eq 2 ]
  check "-tin_transform $bad: one line ($(cat err.txt))" \
    one_line "-tin_transform"
done
"$T" eval dem.tif t.ply -layer triangles >/dev/null 2>err.txt
rc=$?
check "-layer with a PLY file: exit 1 ($rc)" [ "$rc" -eq 1 ]
check "-layer with a PLY file: one line ($(cat err.txt))" one_line "no layers"
"$T" eval dem.tif o/hmm.stl -tin_frame grid >/dev/null 2>err.txt
rc=$?
check "-tin_frame grid: exit 2 ($rc)" [ "$rc" -eq 2 ]
"$T" eval dem.tif o/pixel.stl -error_raster lost.tif -json >e.json 2>err.txt
check "STL -error_raster: written" [ -s lost.tif ]
check "STL -error_raster: its max |value| is eval's max error" \
  python3 -c '
import json, subprocess, sys
d = json.load(open("e.json"))
info = json.loads(subprocess.run(["gdalinfo", "-json", "-stats", "lost.tif"],
                                 capture_output=True, text=True).stdout)
md = info["bands"][0]["metadata"][""]
m = max(abs(float(md["STATISTICS_MINIMUM"])),
        abs(float(md["STATISTICS_MAXIMUM"])))
sys.exit(0 if abs(m - d["max_error"]) <= 1e-5 else 1)'
rm -f lost.tif.aux.xml

echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
