#!/usr/bin/env bash
# test_cli.sh -- end-to-end tests of the terratin command ($TT_TERRATIN).
#
# Every bad input the issue lists (missing file, not a raster, a vector file,
# empty and 1x1 rasters, all nodata, NaN and infinite heights, unknown option,
# bad limits, existing output, unwritable place, failed and interrupted
# writes) must give a non-zero exit code, exactly one line on stderr, and
# leave no output and no temporary file. A good run on a generated fault
# terrain is checked against ogrinfo and against `terratin eval` (an
# independent measure of the error bound). The inputs are made in a mktemp
# folder with GDAL's own tools. Prints "N passed, M failed"; exits 1 on any
# failure, 77 (skip) when a tool is missing.
set -u
. "$(dirname "${BASH_SOURCE[0]}")/tt_python.sh"

T=${TT_TERRATIN:-}
if [ -z "$T" ] || [ ! -x "$T" ]; then
  echo "SKIP: TT_TERRATIN is not set or not executable"
  exit 77
fi
for tool in gdal_create gdal_translate gdal_rasterize gdalinfo ogrinfo \
            ogr2ogr python3; do
  if ! command -v "$tool" >/dev/null 2>&1; then
    echo "SKIP: $tool is missing"
    exit 77
  fi
done

W=$(mktemp -d "${TMPDIR:-/tmp}/tt_cli.XXXXXX") || exit 1
trap 'chmod -R u+w "$W" 2>/dev/null; rm -rf "$W"' EXIT
cd "$W" || exit 1

passed=0
failed=0
pass() { passed=$((passed + 1)); }
fail() { failed=$((failed + 1)); echo "FAIL: $*" >&2; }
# check DESCRIPTION COMMAND...: passes when the command succeeds.
check() {
  local what=$1
  shift
  if "$@"; then pass; else fail "$what"; fi
}

# run ARGS...: runs terratin, stdout in out.txt, stderr in err.txt, exit
# code in $rc.
rc=0
run() {
  "$T" "$@" >out.txt 2>err.txt
  rc=$?
}
lines() { wc -l <"$1" | tr -d ' '; }
json_get() { # json_get FILE KEY -> value printed by python
  python3 -c 'import json,sys; d=json.load(open(sys.argv[1])); v=d
for k in sys.argv[2].split("."): v=v[k]
print(v)' "$1" "$2"
}
# float_le A B: A <= B
float_le() { python3 -c 'import sys; sys.exit(0 if float(sys.argv[1]) <= float(sys.argv[2]) else 1)' "$1" "$2"; }

# expect_failure NAME CODE DIR ARGS...: terratin fails with CODE, one
# stderr line "terratin: ...", and DIR (the output folder) stays empty.
expect_failure() {
  local name=$1 code=$2 dir=$3
  shift 3
  run "$@"
  if [ "$rc" -eq "$code" ]; then pass; else
    fail "$name: exit code $rc, expected $code ($(head -c 300 err.txt))"
  fi
  if [ "$(lines err.txt)" = 1 ] && grep -q '^terratin: ' err.txt; then pass
  else fail "$name: stderr is not one 'terratin:' line: $(cat err.txt)"; fi
  if [ -z "$(ls -A "$dir")" ]; then pass; else
    fail "$name: left files behind in $dir: $(ls -A "$dir")"
  fi
}

# --- inputs ------------------------------------------------------------------
mkdir in out
# a smooth fault terrain (cosine ramps): errors vary continuously
FAULT="-size 120x100 -seed 7 -displacement 20 -wave_size 5 -a_srs EPSG:32633"
run generate fault in/fault.tif $FAULT -q
check "generate fault: exit 0 (got $rc: $(cat err.txt))" [ "$rc" -eq 0 ]
check "generate -q: nothing on stdout" [ ! -s out.txt ]
check "generate: 120x100 GeoTIFF" \
  grep -q "Size is 120, 100" <(gdalinfo in/fault.tif 2>/dev/null)
run generate fault in/fault.tif
check "generate: refuses an existing output" [ "$rc" -eq 1 ]
check "generate: one stderr line when refusing" [ "$(lines err.txt)" = 1 ]
run generate fault in/fault.tif $FAULT -overwrite
check "generate -overwrite: exit 0" [ "$rc" -eq 0 ]
check "generate: a summary line on stdout" grep -q "fault terrain" out.txt
run generate fault in/x.tif -a_srs NOT_A_CRS
check "generate -a_srs garbage: exit 2" [ "$rc" -eq 2 ]
check "generate -a_srs garbage: no file" [ ! -e in/x.tif ]
run generate diamond_square in/ds.tif -size 65 -seed 3 -q
check "generate diamond_square: exit 0" [ "$rc" -eq 0 ]

echo "just text" >in/text.txt
: >in/empty.tif
gdal_create -q -of GTiff -ot Float32 -outsize 1 1 -burn 5 in/one.tif
gdal_create -q -of GTiff -ot Float32 -outsize 10 8 -a_nodata 0 -burn 0 \
  in/nodata.tif
gdal_create -q -of GTiff -ot Float32 -outsize 50 40 -a_ullr 0 40 50 0 \
  -burn 7 in/flat.tif
echo '{"type":"FeatureCollection","features":[{"type":"Feature",
"properties":{},"geometry":{"type":"Point","coordinates":[2.5,2.5]}}]}' \
  >in/point.geojson
for v in nan inf; do
  gdal_create -q -of GTiff -ot Float32 -outsize 5 5 -a_ullr 0 5 5 0 \
    -burn 1 in/$v.tif
  gdal_rasterize -q -burn $v in/point.geojson in/$v.tif 2>/dev/null
done
check "test input: the NaN raster holds a NaN" \
  grep -qi nan <(gdal_translate -q -of AAIGrid in/nan.tif /vsistdout/)

# --- bad inputs: one line, non-zero exit, nothing left ------------------------
expect_failure "missing input" 1 out simplify in/nosuch.tif out/o.gpkg
grep -q "in/nosuch.tif" err.txt && pass || fail "missing input: file not named"
expect_failure "not a raster" 1 out simplify in/text.txt out/o.gpkg
expect_failure "vector input" 1 out simplify in/point.geojson out/o.gpkg
grep -q "vector" err.txt && pass || fail "vector input: $(cat err.txt)"
expect_failure "empty file" 1 out simplify in/empty.tif out/o.gpkg
expect_failure "1x1 raster" 1 out simplify in/one.tif out/o.gpkg
expect_failure "all nodata" 1 out simplify in/nodata.tif out/o.gpkg
expect_failure "NaN heights" 1 out simplify in/nan.tif out/o.gpkg
expect_failure "infinite heights" 1 out simplify in/inf.tif out/o.gpkg
expect_failure "folder as input" 1 out simplify in out/o.gpkg
expect_failure "unknown option" 2 out simplify -frobnicate in/fault.tif \
  out/o.gpkg
expect_failure "-max_error -1" 2 out simplify -max_error -1 in/fault.tif \
  out/o.gpkg
expect_failure "-max_points -5" 2 out simplify -max_points -5 in/fault.tif \
  out/o.gpkg
expect_failure "-max_points 0" 2 out simplify -max_points 0 in/fault.tif \
  out/o.gpkg
expect_failure "-max_triangles 0" 2 out simplify -max_triangles 0 \
  in/fault.tif out/o.gpkg
expect_failure "-percent 0" 2 out simplify -percent 0 in/fault.tif out/o.gpkg
expect_failure "-percent 150" 2 out simplify -percent 150 in/fault.tif \
  out/o.gpkg
expect_failure "-max_error abc" 2 out simplify -max_error abc in/fault.tif \
  out/o.gpkg
expect_failure "-criterion unknown" 2 out simplify -criterion nope \
  in/fault.tif out/o.gpkg
expect_failure "-repair unknown" 2 out simplify -repair lawson \
  in/fault.tif out/o.gpkg
expect_failure "missing OUTPUT" 2 out simplify in/fault.tif
expect_failure "missing option value" 2 out simplify in/fault.tif \
  out/o.gpkg -b
expect_failure "-b 2 of a 1-band raster" 2 out simplify -b 2 in/fault.tif \
  out/o.gpkg
expect_failure "-of a raster driver" 2 out simplify -of GTiff in/fault.tif \
  out/o.tif
expect_failure "-of an unknown driver" 2 out simplify -of NoSuchDriver \
  in/fault.tif out/o.gpkg
expect_failure "unknown command" 2 out simplfy in/fault.tif out/o.gpkg
expect_failure "no command" 2 out
expect_failure "unwritable place (no such folder)" 1 out simplify \
  in/fault.tif out/nosuchdir/o.gpkg
expect_failure "unwritable place (/proc)" 1 out simplify in/fault.tif \
  /proc/terratin_test.gpkg
if [ "$(id -u)" != 0 ]; then
  mkdir ro && chmod 555 ro
  expect_failure "unwritable place (read-only folder)" 1 ro simplify \
    in/fault.tif ro/o.gpkg
fi
# --config is applied before the drivers are registered
expect_failure "--config GDAL_SKIP GPKG" 1 out --config GDAL_SKIP GPKG \
  simplify in/fault.tif out/o.gpkg

# an output that exists is refused and kept
mkdir keep
echo "precious" >keep/o.gpkg
run simplify in/fault.tif keep/o.gpkg
check "existing output: exit 1" [ "$rc" -eq 1 ]
check "existing output: one stderr line" [ "$(lines err.txt)" = 1 ]
check "existing output: kept as it was" grep -qx precious keep/o.gpkg
check "existing output: no temporary file" [ "$(ls -A keep)" = "o.gpkg" ]
# ... and the input is never replaced, even with -overwrite
cp in/fault.tif keep/same.tif
run simplify -overwrite keep/same.tif keep/same.tif
check "input as output: refused" [ "$rc" -eq 1 ]
check "input as output: input intact" cmp -s in/fault.tif keep/same.tif

# a write that would fail half way (a GPKG FID column clashing with a
# field): the writer's dry run refuses it before the work, naming -lco
expect_failure "failed write" 2 out simplify -lco FID=v0 in/fault.tif \
  out/o.gpkg
check "failed write: the -lco named" grep -q -- "-lco" err.txt
# a driver that cannot hold three layers is refused before the work too
expect_failure "GeoJSON (one layer only)" 2 out simplify -of GeoJSON \
  in/fault.tif out/o.geojson
check "GeoJSON: -layers named" grep -q -- "-layers triangles" err.txt

# --- a good run ---------------------------------------------------------------
run simplify -json -max_error 2 in/fault.tif out/tin.gpkg
check "simplify -json: exit 0 ($(cat err.txt))" [ "$rc" -eq 0 ]
cp out.txt tin.json
check "-json: stdout is one JSON object" \
  python3 -c 'import json,sys; d=json.load(sys.stdin); assert isinstance(d, dict)' <tin.json
check "-json: required keys" python3 -c '
import json, sys
d = json.load(sys.stdin)
need = ["vertices", "triangles", "max_error", "rmse", "mean_abs_error",
        "seconds", "input", "output", "format", "valid_samples", "cells",
        "stop_reason", "criterion", "limits", "z_unit", "crs"]
missing = [k for k in need if k not in d]
missing += ["seconds." + k for k in ["read", "simplify", "mesh",
                                     "statistics", "write", "total"]
            if k not in d["seconds"]]
assert not missing, missing
t = d["seconds"]
assert t["mesh"] > 0 and t["statistics"] > 0, t
assert t["mesh"] + t["statistics"] <= t["simplify"] <= t["total"], t
assert d["format"] == "GPKG" and d["criterion"] == "delaunay"
assert d["limits"]["max_error"] == 2 and d["cells"] == 12000
assert d["valid_samples"] == 12000 and d["max_error"] <= 2
assert d["stop_reason"] == "max_error"
assert d["repair"] == "flip" and d["optimize"] == "none", d
assert "32633" in d["crs"] or "UTM" in d["crs"], d["crs"]
' <tin.json
check "-json: no progress bar" bash -c '! grep -q "\.\.\.10" tin.json'
check "simplify: no warning on a clean run" [ ! -s err.txt ]
ogrinfo -so out/tin.gpkg >layers.txt 2>&1
for layer in triangles vertices run_parameters; do
  check "ogrinfo lists layer $layer" grep -q "^[0-9]*: $layer" layers.txt
done
count() { ogrinfo -so "$1" "$2" 2>/dev/null | sed -n 's/^Feature Count: //p'; }
check "triangle count matches -json" \
  [ "$(count out/tin.gpkg triangles)" = "$(json_get tin.json triangles)" ]
check "vertex count matches -json" \
  [ "$(count out/tin.gpkg vertices)" = "$(json_get tin.json vertices)" ]
check "run_parameters has one row" [ "$(count out/tin.gpkg run_parameters)" = 1 ]
check "run_parameters holds the limit and the results" bash -c '
ogrinfo -q out/tin.gpkg run_parameters >rp.txt 2>&1
grep -q "max_error (Real) = 2$" rp.txt && grep -q "stop (String) = max_error" rp.txt &&
grep -q "vertices (Integer64) = $(python3 -c "import json;print(json.load(open(\"tin.json\"))[\"vertices\"])")" rp.txt &&
grep -q "created (String) = 20[0-9-]*T[0-9:]*Z" rp.txt &&
grep -q "t_mesh (Real) = [0-9]" rp.txt && grep -q "t_stats (Real) = [0-9]" rp.txt'
check "the layers carry the raster's CRS" \
  grep -q 'ID\["EPSG",32633\]' <(ogrinfo -so out/tin.gpkg triangles 2>&1)
check "only the output in the folder" [ "$(ls -A out)" = "tin.gpkg" ]

# l2 by default: Delaunay while inserting, then the L2 swaps of the final
# pass; an explicit -repair and -optimize are recorded as given
run simplify -json -criterion l2 -max_error 2 in/fault.tif out/l2.gpkg
check "l2: exit 0 ($(cat err.txt))" [ "$rc" -eq 0 ]
check "l2: resolved repair and optimize in -json" python3 -c '
import json, sys
d = json.load(sys.stdin)
assert d["repair"] == "delaunay" and d["optimize"] == "local", d
assert d["max_error"] <= 2, d' <out.txt
check "l2: run_parameters names them" bash -c '
ogrinfo -q out/l2.gpkg run_parameters >rp2.txt 2>&1
grep -q "repair (String) = delaunay" rp2.txt &&
grep -q "optimize (String) = local" rp2.txt &&
grep -q "criterion (String) = l2" rp2.txt'
run simplify -json -criterion abn -repair lookahead -optimize lookahead \
  -max_error 2 in/fault.tif out/abn.gpkg
check "abn lookahead: exit 0 ($(cat err.txt))" [ "$rc" -eq 0 ]
check "abn lookahead: recorded, bound kept" python3 -c '
import json, sys
d = json.load(sys.stdin)
assert d["repair"] == "lookahead" and d["optimize"] == "lookahead", d
assert d["max_error"] <= 2, d' <out.txt
rm -f out/l2.gpkg out/abn.gpkg

# the error bound, measured independently by eval
run eval -json in/fault.tif out/tin.gpkg
check "eval: exit 0 ($(cat err.txt))" [ "$rc" -eq 0 ]
cp out.txt eval.json
check "eval: max error <= the requested -max_error" \
  float_le "$(json_get eval.json max_error)" 2
check "eval: every valid sample covered" python3 -c '
import json, sys
d = json.load(sys.stdin)
assert d["uncovered"] == 0 and d["covered"] == d["valid_samples"] == 12000, d
assert d["overlapped"] == 0 and d["rejected"] == 0 and d["layer"] == "triangles"
' <eval.json
check "eval agrees with simplify on the max error" python3 -c '
import json
a = json.load(open("tin.json")); b = json.load(open("eval.json"))
assert abs(a["max_error"] - b["max_error"]) <= 1e-6 * max(1, a["max_error"]), (a["max_error"], b["max_error"])
assert b["triangles"] == a["triangles"]
'
run eval in/fault.tif out/tin.gpkg
check "eval text: exit 0" [ "$rc" -eq 0 ]
check "eval text: the measures" bash -c 'grep -q "^max error:" out.txt &&
  grep -q "^RMS error:" out.txt && grep -q "^mean abs error:" out.txt &&
  grep -q "^total abs error:" out.txt && grep -q "^L2 error:" out.txt &&
  grep -q "^coverage: *12000 of 12000" out.txt'
run eval in/fault.tif out/tin.gpkg -max_error 2 -q
check "eval -max_error 2: exit 0" [ "$rc" -eq 0 ]
check "eval -q: nothing on stdout" [ ! -s out.txt ]
run eval in/fault.tif out/tin.gpkg -max_error 0.001
check "eval -max_error 0.001: exit 3" [ "$rc" -eq 3 ]
check "eval exceeded: one stderr line" [ "$(lines err.txt)" = 1 ]
# another tool's layer: a copy under another name, found as the first
# polygon layer
ogr2ogr -q -f GPKG -nln surface other.gpkg out/tin.gpkg triangles
run eval -json in/fault.tif other.gpkg
check "eval of another file's polygon layer: exit 0" [ "$rc" -eq 0 ]
check "eval of another file: same max error" python3 -c '
import json
a = json.load(open("eval.json")); b = json.loads(open("out.txt").read())
assert b["layer"] == "surface" and b["max_error"] == a["max_error"]'
mkdir none
expect_failure "eval: a raster as TIN" 1 none eval in/fault.tif in/fault.tif
expect_failure "eval: unknown layer" 1 none eval -layer nope in/fault.tif \
  out/tin.gpkg
expect_failure "eval: missing DEM" 1 none eval in/nosuch.tif out/tin.gpkg
expect_failure "eval: a TIN with no triangles" 1 none eval in/fault.tif \
  in/point.geojson

# progress bar and summary, -q
run simplify -max_points 200 in/fault.tif out/p.gpkg
check "progress: exit 0" [ "$rc" -eq 0 ]
check "progress bar on stdout" \
  grep -q "^0\.\.\.10\.\.\.20\.\.\.30\.\.\.40\.\.\.50\.\.\.60\.\.\.70\.\.\.80\.\.\.90\.\.\.100 - done\.$" out.txt
check "summary: the input" grep -q "^input:  in/fault.tif, band 1: 120 x 100 samples, all valid; WGS 84 / UTM zone 33N (EPSG:32633); heights in unknown units$" out.txt
check "summary: the output" grep -q "^output: out/p.gpkg (layers triangles, vertices, run_parameters): 200 vertices (1.7% of the valid samples), [0-9]* triangles; [0-9.]* s$" out.txt
check "summary: the error of the budget" grep -q "^error:  max [0-9.e+]* z units (the budget -max_points 200); RMS [0-9.e+]* z units$" out.txt
check "summary: three lines after the bar" [ "$(grep -vc "^0\.\.\." out.txt)" -eq 3 ]
run simplify -overwrite -verbose -max_points 200 in/fault.tif out/p.gpkg
check "-verbose: the method, frame, heights and times" bash -c '
grep -q "^method: insert, criterion delaunay, repair flip, optimize none; stopped with the vertex budget reached$" out.txt &&
grep -q "^frame:  " out.txt && grep -q "^heights: .* to .* z units$" out.txt &&
grep -q "^time:   read .* s, mesh .* s, write .* s (GPKG), total .* s$" out.txt'
run simplify -overwrite -max_error 5 in/fault.tif out/p.shp
check "summary: a Shapefile output names its files" grep -q "^output: out/p_triangles.shp, out/p_vertices.shp, out/p_run_parameters.dbf: " out.txt
check "summary: the bound given" grep -q "^error:  max [0-9.]* z units, within the bound 5 z units; RMS " out.txt
check "summary: the files exist" bash -c '[ -f out/p_triangles.shp ] && [ -f out/p_vertices.shp ] && [ -f out/p_run_parameters.dbf ]'
run simplify -overwrite -json -max_error 5 in/fault.tif out/p.shp
check "-json: files and layers" python3 -c '
import json
d = json.load(open("out.txt"))
assert d["files"] == ["out/p_triangles.shp", "out/p_vertices.shp", "out/p_run_parameters.dbf"], d["files"]
assert d["layers"] == [], d["layers"]'

run simplify -q -overwrite -percent 1 in/fault.tif out/p.gpkg
check "-q: exit 0" [ "$rc" -eq 0 ]
check "-q: nothing on stdout" [ ! -s out.txt ]
check "-percent 1 of 12000: at most 120 vertices" \
  [ "$(count out/p.gpkg vertices)" -le 120 ]
run simplify -q -max_triangles 50 -overwrite in/fault.tif out/p.gpkg
check "-max_triangles 50 honoured" [ "$(count out/p.gpkg triangles)" -le 50 ]

# -overwrite replaces; without it the old file stays
before=$(count out/tin.gpkg vertices)
run simplify -q -max_error 10 in/fault.tif out/tin.gpkg
check "no -overwrite: refused" [ "$rc" -eq 1 ]
check "no -overwrite: file unchanged" [ "$(count out/tin.gpkg vertices)" = "$before" ]
run simplify -q -max_error 10 -overwrite in/fault.tif out/tin.gpkg
check "-overwrite: exit 0" [ "$rc" -eq 0 ]
check "-overwrite: file replaced" [ "$(count out/tin.gpkg vertices)" -lt "$before" ]

# default limit: twice the mean step between 4-neighbour valid samples, to
# two significant digits, computed here from the heights of a grid with a
# nodata hole (pairs with a nodata end do not count)
python3 - <<'PY'
import math
with open("step.asc", "w") as f:
    f.write("ncols 37\nnrows 29\nxllcorner 0\nyllcorner 0\ncellsize 10\n"
            "NODATA_value -9999\n")
    for y in range(29):
        row = []
        for x in range(37):
            hole = 10 <= x < 16 and 8 <= y < 13
            z = 100 + 7.3 * math.sin(x / 3.1) * math.cos(y / 4.7) + 0.013 * x * y
            row.append("-9999" if hole else "%.3f" % z)
        f.write(" ".join(row) + "\n")
PY
run simplify -json step.asc out/default.gpkg
check "default limit: exit 0 ($(cat err.txt))" [ "$rc" -eq 0 ]
check "default limit is twice the mean step" python3 -c '
import json, sys
d = json.load(open("out.txt"))
rows = [l.split() for l in open("step.asc")]
nd = -9999.0
z = [[float(v) for v in r] for r in rows[6:]]
diffs = []
for y, row in enumerate(z):
    for x, v in enumerate(row):
        if v == nd:
            continue
        if x + 1 < len(row) and row[x + 1] != nd:
            diffs.append(abs(row[x + 1] - v))
        if y + 1 < len(z) and z[y + 1][x] != nd:
            diffs.append(abs(z[y + 1][x] - v))
step = sum(diffs) / len(diffs)
lim = d["limits"]["max_error"]
assert d["valid_samples"] == 37 * 29 - 30, d
assert d["limits"]["max_error_default"] is True, d["limits"]
# the grid holds the heights as Float32 (AAIGrid reads decimals so)
assert abs(d["limits"]["mean_step"] - step) <= 1e-6 * step, (d["limits"], step)
assert lim == float("%.2g" % (2 * step)), (lim, step)
assert d["max_error"] <= lim, d'
cp out.txt default.json
run simplify -json -tile_size 16 step.asc out/default_tiled.gpkg
check "default limit: tiled, the same step and bound ($(cat err.txt))" python3 -c '
import json
u = json.load(open("default.json"))["limits"]
d = json.load(open("out.txt"))
t = d["limits"]
assert d["tiling"]["tiles"] > 1, d.get("tiling")
assert t["max_error_default"] is True, t
assert abs(t["mean_step"] - u["mean_step"]) <= 1e-12 * u["mean_step"], (t, u)
assert t["max_error"] == u["max_error"], (t, u)
assert d["max_error"] <= t["max_error"], d' 
run simplify in/flat.tif out/flat.gpkg
check "flat DEM: exit 0 ($(cat err.txt))" [ "$rc" -eq 0 ]
check "flat DEM: two triangles" [ "$(count out/flat.gpkg triangles)" = 2 ]
check "flat DEM: summary states the default" grep -q "default" out.txt

# Shapefile output: the expected files, nothing else
mkdir shp
run simplify -q -of "ESRI Shapefile" -max_error 2 in/fault.tif shp/tin.shp
check "shapefile: exit 0 ($(cat err.txt))" [ "$rc" -eq 0 ]
for f in tin_triangles.shp tin_triangles.shx tin_triangles.dbf \
         tin_triangles.prj tin_vertices.shp tin_vertices.shx \
         tin_vertices.dbf tin_run_parameters.dbf; do
  check "shapefile: $f written" [ -f "shp/$f" ]
done
check "shapefile: no temporary folder" \
  bash -c '! ls -A shp | grep -q "^\."'
check "shapefile: triangle count" \
  [ "$(count shp/tin_triangles.shp tin_triangles)" = "$(json_get tin.json triangles)" ]
mkdir shp2
run simplify -q -max_error 2 in/fault.tif shp2/t.shp
check "the .shp extension picks the shapefile driver" [ -f shp2/t_triangles.shp ]
run simplify -q -max_error 2 in/fault.tif shp2/t.shp
check "shapefile: refuses to overwrite" [ "$rc" -eq 1 ]

# warnings are prefixed (an extension no driver claims warns)
run simplify -q -max_points 20 in/fault.tif out/w.nodriver
check "warnings: prefixed 'terratin: warning: '" \
  bash -c '[ -s err.txt ] && ! grep -v "^terratin: warning: " err.txt'

# interrupted runs leave nothing: SIGTERM at several moments of a long run
run generate diamond_square in/big.tif -size 513 -seed 11 -q
check "generate big: exit 0" [ "$rc" -eq 0 ]
for delay in 0.05 0.3 1 2; do
  rm -rf sig && mkdir sig
  "$T" simplify -max_error 0 in/big.tif sig/o.gpkg >/dev/null 2>sig.err &
  pid=$!
  sleep "$delay"
  kill -TERM "$pid" 2>/dev/null
  wait "$pid"
  code=$?
  if [ "$code" -eq 143 ]; then
    pass
    check "interrupted after ${delay}s: nothing left ($(ls -A sig))" \
      [ -z "$(ls -A sig)" ]
    # none when the signal came before the handlers were installed
    check "interrupted after ${delay}s: at most one stderr line" \
      [ "$(lines sig.err)" -le 1 ]
  elif [ "$code" -eq 0 ]; then
    pass # finished first: then the output is complete and alone
    check "finished before the signal: only the output" \
      [ "$(ls -A sig)" = "o.gpkg" ]
  else
    fail "interrupted after ${delay}s: exit code $code ($(cat sig.err))"
  fi
done

# SIGINT (Ctrl-C) too: job control gives the background job the default
# SIGINT disposition a terminal's foreground job has
rm -rf sig && mkdir sig
set -m
"$T" simplify -max_error 0 in/big.tif sig/o.gpkg >/dev/null 2>sig.err &
pid=$!
set +m
sleep 1
kill -INT "$pid" 2>/dev/null
wait "$pid"
code=$?
check "SIGINT: killed by SIGINT or finished (exit $code)" \
  [ "$code" -eq 130 -o "$code" -eq 0 ]
if [ "$code" -eq 130 ]; then
  check "SIGINT: nothing left ($(ls -A sig))" [ -z "$(ls -A sig)" ]
  check "SIGINT: says so in one line" grep -q "interrupted" sig.err
fi

# -dsco and -lco reach the driver
run simplify -q -dsco VERSION=1.2 -lco GEOMETRY_NAME=shape -max_error 5 \
  in/fault.tif out/co.gpkg
check "-dsco/-lco: exit 0" [ "$rc" -eq 0 ]
check "-dsco VERSION=1.2 applied" \
  grep -q "user_version (Integer) = 10200" \
  <(ogrinfo -q out/co.gpkg -sql "PRAGMA user_version" 2>&1)
check "-lco GEOMETRY_NAME=shape applied to every layer" bash -c '
  ogrinfo -so out/co.gpkg triangles | grep -q "Geometry Column = shape" &&
  ogrinfo -so out/co.gpkg vertices | grep -q "Geometry Column = shape"'

# -nln: layer names; eval finds "<prefix>triangles" by itself
run simplify -q -nln dem_ -max_error 2 in/fault.tif out/nln.gpkg
check "-nln: exit 0" [ "$rc" -eq 0 ]
check "-nln: prefixed layers" bash -c 'ogrinfo -so out/nln.gpkg >l.txt 2>&1 &&
  grep -q ": dem_triangles" l.txt && grep -q ": dem_vertices" l.txt &&
  grep -q ": dem_run_parameters" l.txt'
run eval -json in/fault.tif out/nln.gpkg
check "eval picks dem_triangles" \
  [ "$rc:$(json_get out.txt layer 2>/dev/null)" = "0:dem_triangles" ]
mkdir shp3
run simplify -q -f "ESRI Shapefile" -nln a_ -max_error 5 in/fault.tif shp3/x
check "shapefile -nln: exit 0 (-f spelling)" [ "$rc" -eq 0 ]
check "shapefile -nln: files named name_prefix_layer" [ -f shp3/x_a_triangles.shp ]
cp -r shp3 shp3.before
run simplify -q -f "ESRI Shapefile" -nln a_ -max_error 9 in/fault.tif shp3/x
check "shapefile -nln: refuses to overwrite" [ "$rc" -eq 1 ]
check "shapefile -nln: old files intact" diff -r shp3 shp3.before

# real DEMs, when ../shared/testdata is there: the bound and the coverage
# hold on geographic lidar with tiny pixels, a feet DEM with a nodata
# collar, and a 54%-valid country outline
S=${TT_SHARED_TESTDATA:-}
for spec in "spatial.tools_tahoe_lidar/tahoe_lidar_bareearth.tif:0.1" \
            "usgs_dem_san_francisco/sanfranciscos.dem:5" \
            "rspatial_terra/elev.tif:3"; do
  f=${spec%%:*}
  e=${spec##*:}
  [ -n "$S" ] && [ -f "$S/$f" ] || continue
  rm -f real.gpkg
  run simplify -q -max_error "$e" "$S/$f" real.gpkg
  check "$f: simplify exit 0 ($(cat err.txt))" [ "$rc" -eq 0 ]
  run eval -json -max_error "$e" "$S/$f" real.gpkg
  check "$f: eval -max_error $e passes" [ "$rc" -eq 0 ]
  # every valid sample is covered once, but the lone samples amid nodata
  # (in no cell with 3 valid corners) that simplify reported
  run simplify -q -json -overwrite -max_error "$e" "$S/$f" real.gpkg
  lone=$(json_get out.txt lone_samples)
  run eval -json -max_error "$e" "$S/$f" real.gpkg
  check "$f: every valid sample covered but $lone lone ones, none twice" \
    python3 -c '
import json, sys
d = json.load(sys.stdin)
lone = int(sys.argv[1])
assert d["overlapped"] == 0, d
assert d["uncovered"] == lone, (d, lone)
assert d["covered"] + lone == d["valid_samples"] > 0, d' "${lone:-x}" <out.txt
done
if [ -n "$S" ] && [ -f "$S/usgs_dem_san_francisco/sanfranciscos.dem" ]; then
  # heights in ft on a UTM grid: metres by default (-z_to auto), feet kept
  # with -z_to native
  run simplify -json -max_points 500 \
    "$S/usgs_dem_san_francisco/sanfranciscos.dem" real_m.gpkg
  check "ft heights on UTM: metres, because the CRS is in metres" python3 -c '
import json
d = json.load(open("out.txt"))
assert d["z_unit"] == "m" and d["z_unit_declared"] == "ft", d
assert d["z_unit_conversion"] == "the CRS is in metres", d
assert abs(d["z_multiplier"] - 0.3048) < 1e-15, d'
  run simplify -z_to native -max_points 500 \
    "$S/usgs_dem_san_francisco/sanfranciscos.dem" real_ft.gpkg
  check "the summary carries the z unit (ft)" bash -c 'grep -q "^input: .*; heights in ft$" out.txt && grep -q "^error:  max .* ft (.*); RMS .* ft$" out.txt'
fi

# --- georeferencing, units, output CRS, robustness (issue 3) ----------------
J=${TT_TESTDATA:-}/jacksboro_fault_dem.tif
if [ -f "$J" ]; then
  run simplify -json -max_error 10 "$J" out/geo.gpkg
  check "geographic DEM: exit 0 ($(cat err.txt))" [ "$rc" -eq 0 ]
  check "-json: frame UTM zone 16N" \
    grep -q '"frame": "UTM zone 16N (EPSG:32616), per vertex; scale ' out.txt
  check "-json: crs, z unit, pixel_is, valid samples" python3 -c '
import json, sys
d = json.load(open("out.txt"))
assert d["crs"] == "WGS 84 (EPSG:4326)", d["crs"]
assert d["z_unit"] == "m" and d["z_unit_source"] == "band unit", d
assert d["pixel_is"] == "Area", d
assert d["valid_samples"] == 138632, d'
  check "run_parameters: frame, crs, z_unit, pixel_is, valid" bash -c \
    'ogrinfo -q out/geo.gpkg run_parameters | grep -q "frame (String) = UTM zone 16N" &&
     ogrinfo -q out/geo.gpkg run_parameters | grep -q "pixel_is (String) = Area" &&
     ogrinfo -q out/geo.gpkg run_parameters | grep -q "z_unit (String) = m" &&
     ogrinfo -q out/geo.gpkg run_parameters | grep -q "crs (String) = WGS 84" &&
     ogrinfo -q out/geo.gpkg run_parameters | grep -q "valid (Integer64) = 138632"'
  run simplify -verbose -max_error 10 "$J" out/geo_line.gpkg
  check "summary: CRS and heights' unit" grep -q \
    "^input:  .*jacksboro_fault_dem.tif, band 1: 403 x 344 samples, all valid; WGS 84 (EPSG:4326); heights in m$" out.txt
  check "summary -verbose: frame, the unit's source" bash -c '
grep -q "^frame:  UTM zone 16N (EPSG:32616), per vertex; scale .* off over the whole DEM)$" out.txt &&
grep -q "^heights: 236 to 1076 m (the unit from the band unit)$" out.txt' 
  run simplify -q -max_error 10 -t_srs EPSG:32616 "$J" out/utm.gpkg
  check "-t_srs: exit 0 ($(cat err.txt))" [ "$rc" -eq 0 ]
  check "-t_srs: the layers are in UTM 16N" \
    grep -q 'ID\["EPSG",32616\]' <(ogrinfo -so out/utm.gpkg triangles 2>/dev/null)
  check "-t_srs: same triangles, eastings in metres" python3 -c '
import subprocess, sys
def ext(f):
    o = subprocess.run(["ogrinfo", "-so", f, "triangles"], capture_output=True, text=True).stdout
    n = [l for l in o.splitlines() if l.startswith("Feature Count")][0]
    e = [l for l in o.splitlines() if l.startswith("Extent")][0]
    return n, e
ng, eg = ext("out/geo.gpkg"); nu, eu = ext("out/utm.gpkg")
assert ng == nu, (ng, nu)
x0 = float(eu.split("(")[1].split(",")[0])
assert 700000 < x0 < 800000, eu'
  run simplify -q -max_error 10 -work_srs EPSG:32617 "$J" out/w17.gpkg
  check "-work_srs: exit 0 ($(cat err.txt))" [ "$rc" -eq 0 ]
  check "-work_srs: the frame names it" bash -c \
    'ogrinfo -q out/w17.gpkg run_parameters | grep -q "frame (String) = WGS 84 / UTM zone 17N (EPSG:32617), per vertex"'
  rm -f out/*
  expect_failure "-work_srs geographic" 2 out simplify -work_srs EPSG:4326 "$J" out/x.gpkg
  expect_failure "-work_srs garbage" 2 out simplify -work_srs NOT_A_CRS "$J" out/x.gpkg
  expect_failure "-t_srs garbage" 2 out simplify -t_srs NOT_A_CRS "$J" out/x.gpkg
  expect_failure "-z_unit cm" 2 out simplify -z_unit cm "$J" out/x.gpkg
fi
expect_failure "-z_to m, unknown unit" 1 out simplify -z_to m in/fault.tif out/x.gpkg
check "-z_to m, unknown unit: says -z_unit and -z_factor" \
  grep -q -- "-z_unit ft|us-ft|m.*-z_factor" err.txt
run simplify -q -z_to m -z_factor 0.5 in/fault.tif out/zf.gpkg
check "-z_to m with -z_factor: exit 0 ($(cat err.txt))" [ "$rc" -eq 0 ]
rm -f out/*
expect_failure "-max_points 0" 2 out simplify -max_points 0 in/fault.tif out/x.gpkg
expect_failure "-max_triangles 0" 2 out simplify -max_triangles 0 in/fault.tif out/x.gpkg
expect_failure "-max_triangles absurd" 2 out simplify -max_triangles 99999999999999 in/fault.tif out/x.gpkg
expect_failure "-max_points absurd" 2 out simplify -max_points 99999999999999999999 in/fault.tif out/x.gpkg
# 100k x 100k: refused before anything is allocated, with the size needed
gdal_translate -q -of VRT -outsize 100000 100000 in/fault.tif in/huge.vrt
expect_failure "100k x 100k raster" 1 out simplify in/huge.vrt out/x.gpkg
check "100k x 100k: says how much memory (37.3 GiB)" grep -q "need 37.3 GiB" err.txt
check "100k x 100k: names -tile_size" grep -q -- "-tile_size 1024 runs it in tiles" err.txt
# GCPs only, no geotransform
gdal_translate -q -of VRT -gcp 0 0 10 10 -gcp 100 0 20 10 -gcp 0 100 10 0 \
  in/fault.tif in/gcp.vrt
sed -i -e 's|<GeoTransform>.*</GeoTransform>||' in/gcp.vrt
expect_failure "GCP-only raster" 1 out simplify in/gcp.vrt out/x.gpkg
check "GCP-only raster: says so" grep -q "ground control points only" err.txt

# help and version
run --help
check "--help: exit 0" [ "$rc" -eq 0 ]
check "--help: usage and exit codes" bash -c 'grep -q "^Usage: terratin" out.txt && grep -q "Exit codes" out.txt'
for c in simplify generate eval; do
  run "$c" --help
  check "$c --help: exit 0 and its usage" \
    bash -c "[ $rc -eq 0 ] && grep -q '^Usage: terratin $c' out.txt"
done
check "simplify --help documents the default limit" grep -q "twice the DEM's mean step" <("$T" simplify --help)
run --version
check "--version: exit 0" [ "$rc" -eq 0 ]
check "--version: terratin, GDAL and PROJ" \
  grep -q "^terratin [0-9.]* (GDAL [0-9.]*.*PROJ [0-9.]*)" out.txt

echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
