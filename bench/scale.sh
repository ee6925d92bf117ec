#!/usr/bin/env bash
# bench/scale.sh [SIZE [TILE [WORK]]] -- issue 19's measurement of tiled
# runs (docs/scale.md): a SIZE^2 diamond-square fractal (default 8193, seed
# 1) made by `terratin generate`, its max error for about 1 % of the
# samples found by an untiled -percent 1 run, then simplified untiled and
# in tiles of TILE (default 1024) on 1 and 2 threads at that error. Prints
# per run the wall seconds, peak memory (GNU time's maximum resident set),
# vertices, triangles, max error and RMSE, then checks the tiled TIN with
# `terratin eval` (the bound, coverage) and tests/apps/tin_topology.py
# (conforming). WORK (default a mktemp folder, removed at the end unless
# given) holds the DEM and the TINs.
set -eu
SIZE=${1:-8193}
TILE=${2:-1024}
HERE=$(cd "$(dirname "$0")/.." && pwd)
T=${TT_TERRATIN:-$HERE/build/terratin}
WORK=${3:-}
KEEP=1
if [ -z "$WORK" ]; then
  WORK=$(mktemp -d "${TMPDIR:-/tmp}/tt_scale.XXXXXX")
  KEEP=0
fi
mkdir -p "$WORK"
cd "$WORK"
[ "$KEEP" = 1 ] || trap 'rm -rf "$WORK"' EXIT
DEM=ds$SIZE.tif
[ -f "$DEM" ] || "$T" generate diamond_square "$DEM" -size "$SIZE" -seed 1 -q
j() { python3 -c 'import json,sys
d=json.load(open(sys.argv[1]))
for k in sys.argv[2].split("."): d=d[k]
print(d)' "$1" "$2"; }
# one NAME ARGS...: a simplify run, its figures on one line
one() {
  local name=$1
  shift
  /usr/bin/time -f "%e %M" -o "$name.time" "$T" simplify -q -json -overwrite "$@" \
    "$DEM" "$name.gpkg" >"$name.json"
  read -r secs kib <"$name.time"
  printf '%-22s %8.1f s %8.0f MiB  %9s vertices %9s triangles  max %.6g  rmse %.6g  (read %.1f, simplify %.1f, write %.1f s)\n' \
    "$name" "$secs" "$((kib / 1024))" "$(j "$name.json" vertices)" \
    "$(j "$name.json" triangles)" "$(j "$name.json" max_error)" \
    "$(j "$name.json" rmse)" "$(j "$name.json" seconds.read)" \
    "$(j "$name.json" seconds.simplify)" "$(j "$name.json" seconds.write)"
}
one percent1 -percent 1 -threads 2
E=$(j percent1.json max_error)
echo "max error for 1 % of the samples: $E"
one untiled_t1 -max_error "$E" -threads 1
one untiled_t2 -max_error "$E" -threads 2
one tiled_t1 -max_error "$E" -tile_size "$TILE" -threads 1
one tiled_t2 -max_error "$E" -tile_size "$TILE" -threads 2
cmp_layers() { ogrinfo -ro -al -q "$1" triangles vertices 2>/dev/null | md5sum | cut -d' ' -f1; }
if [ "$(cmp_layers tiled_t1.gpkg)" = "$(cmp_layers tiled_t2.gpkg)" ]; then
  echo "tiled, threads 1 and 2: the same layers"
else
  echo "tiled, threads 1 and 2: DIFFERENT layers"
fi
/usr/bin/time -f "%e %M" -o eval.time "$T" eval -json -max_error "$E" "$DEM" tiled_t2.gpkg >eval.json
read -r secs kib <eval.time
echo "eval of the tiled TIN: max $(j eval.json max_error), rmse $(j eval.json rmse), uncovered $(j eval.json uncovered), overlapped $(j eval.json overlapped) ($secs s, $((kib / 1024)) MiB)"
python3 "$HERE/tests/apps/tin_topology.py" tiled_t2.gpkg
