#!/usr/bin/env bash
# test_input_options.sh -- GDAL's input options on the DEM ($TT_TERRATIN,
# issue 27): -srcwin, -projwin with -projwin_srs, -a_srs and -s_srs,
# -a_nodata, -a_ullr, each against gdal_translate of the same window or
# georeferencing: the TIN of `simplify -OPTION ... DEM` is the TIN of
# `simplify` on gdal_translate's output, vertex for vertex and triangle for
# triangle (a CSV dump of both layers), whole and tiled on two threads, and
# through `tiles plan/run/merge`; eval, rasterize and optimize read the
# same window; a window partly outside is clipped with a warning, one
# wholly outside and every bad value are refused in one line (exit 2),
# nothing written; -t_srs on a DEM without a CRS names -a_srs. On the
# bundled Jacksboro DEM (403 x 344, EPSG:4326), windows of about 100 x 100.
# Prints "N passed, M failed"; exits 1 on any failure, 77 when a tool is
# missing.
set -u
. "$(dirname "${BASH_SOURCE[0]}")/../apps/tt_check.sh" || exit 1

T=${TT_TERRATIN:-}
if [ -z "$T" ] || [ ! -x "$T" ]; then
  echo "SKIP: TT_TERRATIN is not set or not executable"
  exit 77
fi
for tool in gdal_translate gdalinfo gdaltransform ogr2ogr ogrinfo; do
  if ! command -v $tool >/dev/null 2>&1; then
    echo "SKIP: $tool is missing"
    exit 77
  fi
done
SRC=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)/testdata/jacksboro_fault_dem.tif
W=$(mktemp -d "${TMPDIR:-/tmp}/tt_inputs.XXXXXX") || exit 1
trap 'rm -rf "$W"' EXIT
cd "$W" || exit 1
not() { ! "$@"; }

# Both layers of a TIN as CSV (ids, fields, geometry as WKT).
dump() {
  ogr2ogr -f CSV -lco GEOMETRY=AS_WKT /vsistdout/ "$1" triangles 2>/dev/null
  ogr2ogr -f CSV -lco GEOMETRY=AS_WKT /vsistdout/ "$1" vertices 2>/dev/null
}
# Whether two TINs are the same, and not empty.
same_tin() {
  dump "$1" >a.csv
  dump "$2" >b.csv
  [ "$(wc -l <a.csv)" -gt 10 ] && cmp -s a.csv b.csv
}
# A JSON field of a file.
field() { python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))[sys.argv[2]])' "$1" "$2"; }
S=(simplify -q -max_error 5)

# --- -srcwin: the same TIN as gdal_translate -srcwin's, whole and tiled ---
gdal_translate -q -srcwin 50 40 120 100 "$SRC" win.tif
"$T" "${S[@]}" win.tif ref.gpkg
"$T" "${S[@]}" -srcwin 50 40 120 100 "$SRC" srcwin.gpkg
check "-srcwin: the TIN of gdal_translate -srcwin" same_tin ref.gpkg srcwin.gpkg
check "-srcwin: map coordinates of the full DEM (extent)" \
  [ "$(ogrinfo -so ref.gpkg triangles | grep Extent)" = \
    "$(ogrinfo -so srcwin.gpkg triangles | grep Extent)" ]
"$T" "${S[@]}" -tile_size 32 win.tif ref_t.gpkg
"$T" "${S[@]}" -tile_size 32 -threads 2 -srcwin 50 40 120 100 "$SRC" tiled.gpkg
check "-srcwin, tiled on 2 threads: the tiles of the window" \
  same_tin ref_t.gpkg tiled.gpkg
"$T" simplify -max_error 5 -srcwin 50 40 120 100 -a_srs EPSG:32616 "$SRC" sum.gpkg >sum.txt 2>&1
check "-srcwin, -a_srs: the summary says a window and a CRS given" \
  grep -q "^input:  .*, band 1: 120 x 100 samples (a window), .*; WGS 84 / UTM zone 16N (EPSG:32616) (given); " sum.txt
check "-srcwin: run_parameters names the file and its driver" \
  bash -c "ogrinfo -q srcwin.gpkg -sql 'select input, driver from run_parameters' |
           grep -q 'driver (String) = GTiff'"

# tiles plan / run / merge of a window: simplify -tile_size's TIN
"$T" tiles plan "$SRC" plan.json -q -max_error 5 -tile_size 32 \
  -srcwin 50 40 120 100 2>err.txt
check "tiles plan -srcwin: 16 tiles of the window" \
  grep -q '"tiles": 16' plan.json
for k in $(seq 0 15); do "$T" tiles run plan.json $k 2>>err.txt; done
"$T" tiles merge plan.json merged.gpkg -q 2>>err.txt
check "tiles run/merge -srcwin: simplify -tile_size's TIN ($(head -c 200 err.txt))" \
  same_tin ref_t.gpkg merged.gpkg
"$T" tiles plan "$SRC" plan2.json -q -max_error 5 -tile_size 32 \
  -a_srs ./x.prj 2>err.txt
check "tiles plan: -a_srs other than AUTHORITY:CODE refused" \
  grep -q "a plan takes a CRS as AUTHORITY:CODE" err.txt

# partly outside: clipped with a warning, the window inside
gdal_translate -q -srcwin 350 300 53 44 "$SRC" corner.tif
"$T" "${S[@]}" corner.tif ref_c.gpkg
"$T" "${S[@]}" -srcwin 350 300 200 150 "$SRC" clip.gpkg 2>err.txt
check "-srcwin partly outside: exit 0" [ $? -eq 0 ]
check "-srcwin partly outside: one warning with the window read" \
  grep -q "warning: .*-srcwin 350 300 200 150 falls partly outside the raster (403 x 344 samples): read as -srcwin 350 300 53 44" err.txt
check "-srcwin partly outside: the TIN of the part inside" \
  same_tin ref_c.gpkg clip.gpkg

# --- -projwin in the DEM's CRS, then in another (-projwin_srs) ----------
gdal_translate -q -projwin -84.35 36.68 -84.25 36.60 "$SRC" pw.tif
"$T" "${S[@]}" pw.tif ref_pw.gpkg
"$T" "${S[@]}" -projwin -84.35 36.68 -84.25 36.60 "$SRC" projwin.gpkg
check "-projwin: the TIN of gdal_translate -projwin" \
  same_tin ref_pw.gpkg projwin.gpkg
# a UTM box: its edges (21 points each) reprojected to degrees, the box
# holding them is gdal_translate's -projwin
python3 - >edges.txt <<'EOF'
x0, y0, x1, y1 = 742000.0, 4050000.0, 749000.0, 4059000.0
for i in range(21):
    t = i / 20
    for x, y in ((x0 + t * (x1 - x0), y0), (x0 + t * (x1 - x0), y1),
                 (x0, y0 + t * (y1 - y0)), (x1, y0 + t * (y1 - y0))):
        print(x, y)
EOF
gdaltransform -s_srs EPSG:32616 -t_srs EPSG:4326 <edges.txt >lonlat.txt
box=$(python3 -c '
import sys
p = [tuple(map(float, l.split()[:2])) for l in open("lonlat.txt") if l.strip()]
xs, ys = [a for a, b in p], [b for a, b in p]
print("%.15g %.15g %.15g %.15g" % (min(xs), max(ys), max(xs), min(ys)))')
gdal_translate -q -projwin $box "$SRC" pw_utm.tif
"$T" "${S[@]}" pw_utm.tif ref_utm.gpkg
"$T" simplify -max_error 5 -json -projwin 742000 4059000 749000 4050000 \
  -projwin_srs EPSG:32616 "$SRC" utm.gpkg >utm.json 2>err.txt
check "-projwin_srs: exit 0 ($(head -c 200 err.txt))" [ -s utm.json ]
check "-projwin_srs: the window of the reprojected box ($(gdalinfo pw_utm.tif | grep 'Size is'))" \
  [ "$(field utm.json width) $(field utm.json height)" = \
    "$(gdalinfo pw_utm.tif | sed -n 's/^Size is \([0-9]*\), \([0-9]*\)/\1 \2/p')" ]
check "-projwin_srs: the TIN of gdal_translate -projwin of that box" \
  same_tin ref_utm.gpkg utm.gpkg

# --- -a_srs, -s_srs: the DEM's CRS, in the output layers ------------------
gdal_translate -q -srcwin 0 0 120 100 -co PROFILE=BASELINE \
  --config GDAL_PAM_ENABLED NO "$SRC" nogeo.tif   # no CRS, no geotransform
gdal_translate -q -srcwin 0 0 120 100 -a_srs EPSG:32616 \
  -a_ullr 700000 4100000 708880 4090800 "$SRC" utm_ref.tif
gdal_translate -q -a_srs EPSG:32616 utm_ref.tif utm_nocrs.tif
gdal_translate -q -a_ullr 700000 4100000 708880 4090800 nogeo.tif nocrs.tif
"$T" "${S[@]}" utm_ref.tif ref_srs.gpkg
"$T" "${S[@]}" -a_srs EPSG:32616 nocrs.tif a_srs.gpkg
check "-a_srs: the output layers' CRS is the one assigned" \
  bash -c "ogrinfo -so a_srs.gpkg triangles | grep -q 'UTM zone 16N'"
check "-a_srs: the TIN of gdal_translate -a_srs" same_tin ref_srs.gpkg a_srs.gpkg
"$T" "${S[@]}" -s_srs EPSG:32616 nocrs.tif s_srs.gpkg
check "-s_srs: as -a_srs" same_tin a_srs.gpkg s_srs.gpkg
"$T" "${S[@]}" -a_srs EPSG:32616 "$SRC" wrong.gpkg
check "-a_srs over a DEM's own CRS: replaced" \
  bash -c "ogrinfo -so wrong.gpkg triangles | grep -q 'UTM zone 16N'"
# -t_srs on a DEM without a CRS: the way forward named
"$T" "${S[@]}" -t_srs EPSG:4326 nocrs.tif t_srs.gpkg 2>err.txt
rc=$?
check "-t_srs without a CRS: exit 2" [ $rc -eq 2 ]
check "-t_srs without a CRS: one line naming -a_srs ($(cat err.txt))" \
  bash -c "[ \$(wc -l <err.txt) -eq 1 ] && grep -q 'has no CRS to transform from; give it one with -a_srs' err.txt"
check "-t_srs without a CRS: nothing written" [ ! -e t_srs.gpkg ]
"$T" "${S[@]}" -t_srs EPSG:4326 -a_srs EPSG:32616 nocrs.tif t_srs.gpkg
check "-t_srs with -a_srs: the layers in EPSG:4326" \
  bash -c "ogrinfo -so t_srs.gpkg vertices | grep -q 'ID\[\"EPSG\",4326\]'"

# --- -a_ullr: a raster without a geotransform, or over its own ----------
"$T" "${S[@]}" nocrs.tif ref_ullr.gpkg
"$T" "${S[@]}" -a_ullr 700000 4100000 708880 4090800 nogeo.tif a_ullr.gpkg
check "-a_ullr: the TIN of gdal_translate -a_ullr" same_tin ref_ullr.gpkg a_ullr.gpkg
"$T" "${S[@]}" -a_srs EPSG:32616 -a_ullr 700000 4100000 708880 4090800 \
  "$SRC" -srcwin 0 0 120 100 both.gpkg
check "-a_ullr with -srcwin and -a_srs: gdal_translate's TIN" \
  same_tin ref_srs.gpkg both.gpkg

# --- -a_nodata: gdal_translate -a_nodata's, and -srcnodata's ------------
gdal_translate -q -a_nodata 400 win.tif nd.tif
"$T" simplify -q -max_error 5 -json nd.tif ref_nd.gpkg >ref_nd.json
"$T" simplify -q -max_error 5 -json -a_nodata 400 win.tif a_nd.gpkg >a_nd.json
"$T" simplify -q -max_error 5 -srcnodata 400 win.tif src_nd.gpkg
check "-a_nodata: some samples masked" \
  [ "$(field a_nd.json valid_samples)" -lt "$(field a_nd.json cells)" ]
check "-a_nodata: the valid samples of gdal_translate -a_nodata" \
  [ "$(field a_nd.json valid_samples)" = "$(field ref_nd.json valid_samples)" ]
check "-a_nodata: the TIN of gdal_translate -a_nodata" same_tin ref_nd.gpkg a_nd.gpkg
check "-a_nodata: the TIN of -srcnodata" same_tin src_nd.gpkg a_nd.gpkg

# --- the other commands that read a DEM read the same window -------------
"$T" eval -json -max_error 5 -srcwin 50 40 120 100 "$SRC" srcwin.gpkg >eval.json
check "eval -srcwin: the window's TIN within its bound" [ $? -eq 0 ]
check "eval -srcwin: every valid sample covered" \
  [ "$(field eval.json uncovered 2>/dev/null || echo x)" = 0 ]
"$T" rasterize -q "$SRC" srcwin.gpkg -srcwin 50 40 120 100 tin.tif
check "rasterize -srcwin: the window's grid" \
  [ "$(gdalinfo tin.tif | grep -E '^(Size is|Origin)')" = \
    "$(gdalinfo win.tif | grep -E '^(Size is|Origin)')" ]
"$T" optimize -q -srcwin 50 40 120 100 "$SRC" srcwin.gpkg opt.gpkg
check "optimize -srcwin: exit 0" [ $? -eq 0 ]

# --- refusals: one line, exit 2, nothing written --------------------------
refused() {
  local what=$1 want=$2
  shift 2
  rm -f bad.gpkg
  "$T" simplify -q "$@" bad.gpkg 2>err.txt
  local rc=$?
  check "$what: exit 2 (got $rc: $(head -c 300 err.txt))" [ $rc -eq 2 ]
  check "$what: one line saying '$want'" \
    bash -c "[ \$(wc -l <err.txt) -eq 1 ] && grep -qF -- \"$want\" err.txt"
  check "$what: nothing written" [ ! -e bad.gpkg ]
}
refused "-srcwin wholly outside" \
  "simplify: -srcwin 450 0 10 10: falls completely outside the raster (403 x 344 samples)" \
  -srcwin 450 0 10 10 "$SRC"
refused "-srcwin of three values" "-srcwin needs xoff yoff xsize ysize" \
  -srcwin 1 2 3 "$SRC"
refused "-srcwin of size 0" "-srcwin needs xoff yoff xsize ysize" \
  -srcwin 0 0 0 5 "$SRC"
refused "-srcwin of a fraction" "-srcwin needs xoff yoff xsize ysize" \
  -srcwin 0.5 0 10 10 "$SRC"
refused "-srcwin of one sample inside" "at least 2 x 2 are needed" \
  -srcwin 402 0 10 10 "$SRC"
refused "-projwin upside down" "-projwin needs ulx uly lrx lry" \
  -projwin -84.25 36.60 -84.35 36.68 "$SRC"
refused "-projwin wholly outside" "-projwin 10 20 11 19: falls completely outside" \
  -projwin 10 20 11 19 "$SRC"
refused "-projwin without a geotransform" "-projwin: the DEM has no geotransform" \
  -projwin 0 10 10 0 nogeo.tif
refused "-projwin_srs without -projwin" "-projwin_srs is the CRS of -projwin" \
  -projwin_srs EPSG:32616 "$SRC"
refused "-projwin_srs not a CRS" "-projwin_srs 'nonsense': not a CRS" \
  -projwin 742000 4059000 749000 4050000 -projwin_srs nonsense "$SRC"
refused "-projwin_srs on a DEM without a CRS" "give it one with -a_srs" \
  -projwin 0 10 10 0 -projwin_srs EPSG:32616 nocrs.tif
refused "-srcwin with -projwin" "-srcwin and -projwin both give the window" \
  -srcwin 0 0 10 10 -projwin -84.35 36.68 -84.25 36.60 "$SRC"
refused "-a_srs not a CRS" "-a_srs 'nonsense': not a CRS GDAL can read" \
  -a_srs nonsense "$SRC"
refused "-s_srs not a CRS" "-s_srs 'nonsense': not a CRS GDAL can read" \
  -s_srs nonsense "$SRC"
refused "-a_srs with -s_srs" "-a_srs and -s_srs both give the DEM's CRS" \
  -a_srs EPSG:4326 -s_srs EPSG:4326 "$SRC"
refused "-a_ullr of no width" "-a_ullr needs ulx uly lrx lry" \
  -a_ullr 0 10 0 0 "$SRC"
refused "-a_nodata not a number" "-a_nodata must be a finite decimal number or nan" \
  -a_nodata x "$SRC"
refused "-a_nodata with -srcnodata" "-a_nodata and -srcnodata are the same option" \
  -a_nodata 1 -srcnodata 1 "$SRC"

echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
