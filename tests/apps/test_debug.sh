#!/usr/bin/env bash
# test_debug.sh -- `--debug on` through the terratin command
# ($TT_TERRATIN): every line on stderr is terratin's ("terratin: debug: ",
# "terratin: warning: " or the one failure line), whoever emitted it (the
# run's thread, a handler that silences GDAL for a while in the command or
# in the glue, the tiled run's worker threads, the tiles commands), and
# GDAL never complains of a format it does not know ("CPLvsnprintf()
# called with unsupported formatting string: %.*s") nor of a handler set
# while another is pushed. Runs: whole and tiled on 2 threads, a
# geographic DEM (its conformal frame), a VRT input (the files it reads are
# protected), a shapefile made then refused as existing, eval, rasterize,
# optimize, generate, and tiles plan/run/merge (CPL_DEBUG=ON: tiles takes
# no --debug).
# Prints "N passed, M failed"; exits 1 on any failure, 77 (skip) when a tool
# is missing.
set -u
. "$(dirname "${BASH_SOURCE[0]}")/tt_check.sh" || exit 1

T=${TT_TERRATIN:-}
if [ -z "$T" ] || [ ! -x "$T" ]; then
  echo "SKIP: TT_TERRATIN is not set or not executable"
  exit 77
fi
if ! command -v gdal_translate >/dev/null 2>&1; then
  echo "SKIP: gdal_translate is missing"
  exit 77
fi

W=$(mktemp -d "${TMPDIR:-/tmp}/tt_debug.XXXXXX") || exit 1
trap 'rm -rf "$W"' EXIT
cd "$W" || exit 1

"$T" generate fault dem.tif -size 65 -seed 3 -q || exit 1
"$T" generate fault geo.tif -size 33 -seed 3 -a_srs EPSG:4326 -q || exit 1
gdal_translate -q -of VRT dem.tif dem.vrt || exit 1
mkdir shp

# debug WHAT CODE ARGS...: terratin ARGS exits CODE, prints debug lines
# (when it succeeds), and every stderr line is terratin's, none about a CPL
# format.
debug() {
  local what=$1 code=$2
  shift 2
  "$T" "$@" >out.txt 2>err.txt
  local rc=$?
  if [ "$rc" = "$code" ]; then pass; else
    fail "$what: exit code $rc, expected $code ($(tail -c 300 err.txt))"; fi
  # (a run refused before it opens anything may have none)
  [ "$code" != 0 ] || check "$what: debug lines" grep -q '^terratin: debug: ' err.txt
  local bad
  bad=$(grep -v '^terratin: ' err.txt | head -3)
  check "$what: every stderr line is terratin's (not: $bad)" [ -z "$bad" ]
  bad=$(grep -E 'CPLvsnprintf|unsupported formatting|on the local stack' \
        err.txt | head -3)
  check "$what: no complaint of GDAL's ($bad)" [ -z "$bad" ]
}
debug "simplify" 0 --debug on simplify dem.tif a.gpkg -max_error 5 -q
debug "simplify -json" 0 --debug on simplify dem.tif j.gpkg -max_error 5 -json
debug "tiled, 2 threads" 0 --debug on simplify dem.tif t.gpkg -max_error 5 \
  -tile_size 16 -threads 2 -q
debug "tiled decimation, 2 threads" 0 --debug on simplify dem.tif td.gpkg \
  -max_error 5 -tile_size 16 -threads 2 -method decimate -q
debug "geographic DEM" 0 --debug on simplify geo.tif g.gpkg -max_error 5 -q
debug "VRT input" 0 --debug on simplify dem.vrt v.gpkg -max_error 5 -q
debug "shapefile" 0 --debug on simplify dem.tif shp/t.shp -max_error 5 -q
debug "shapefile exists" 1 --debug on simplify dem.tif shp/t.shp -max_error 5 -q
check "shapefile exists: named" grep -q 't_triangles\|exists' err.txt
debug "eval" 0 --debug on eval dem.tif a.gpkg
debug "rasterize" 0 --debug on rasterize dem.tif a.gpkg r.tif -q
debug "optimize" 0 --debug on optimize dem.tif a.gpkg o.gpkg -q
debug "generate" 0 --debug on generate bump b.tif -q
debug "missing DEM" 1 --debug on simplify nosuch.tif n.gpkg -q
export CPL_DEBUG=ON
debug "tiles plan" 0 tiles plan dem.tif p.json -max_error 5 -tile_size 32
for k in 0 1 2 3; do
  debug "tiles run $k" 0 tiles run p.json "$k"
done
debug "tiles merge" 0 tiles merge p.json m.gpkg -q
unset CPL_DEBUG

echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
