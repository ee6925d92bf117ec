#!/usr/bin/env bash
# bench/criteria.sh -- seconds of greedy insertion for every criterion, as a
# ratio to Delaunay in the same run (issue 4: goal, every criterion within
# 3x of Delaunay).
#
#   bench/criteria.sh                 # Crater Lake and a 1025^2 fractal
#   TERRATIN=path bench/criteria.sh   # another binary (default build/terratin)
#   PERCENTS="10 25" BENCH_TIMEOUT=300 bench/criteria.sh
#
# DEMs: Crater Lake (../shared/testdata/garland_heckbert_terra_scape/
# crater.stm.vrt; skipped with a message when absent) and a 1025 x 1025
# diamond-square DEM (`terratin generate diamond_square -seed 1`). For each
# DEM, criterion and percentage P (10, 25, 50 % of the valid samples as
# vertices): `terratin simplify -percent P -criterion C -json`, and the
# figure is its seconds.simplify (meshing only, not reading or writing).
# The criteria are the ones the binary knows (read from its own error
# message). A run that passes BENCH_TIMEOUT seconds (default 900) prints
# ">T". Everything lands in bench/out/criteria/ (git-ignored).
set -euo pipefail

ROOT=$(cd "$(dirname "$0")/.." && pwd)
cd "$ROOT"
TT=${TERRATIN:-build/terratin}
OUT=bench/out/criteria
PERCENTS=${PERCENTS:-"10 25 50"}
BENCH_TIMEOUT=${BENCH_TIMEOUT:-900}
CRATER=${CRATER:-$ROOT/../shared/testdata/garland_heckbert_terra_scape/crater.stm.vrt}

if [ ! -x "$TT" ]; then
  echo "criteria.sh: no terratin binary at $TT (build first, or set" \
       "TERRATIN=path)" >&2
  exit 1
fi
mkdir -p "$OUT"

criteria=$({ "$TT" simplify -criterion '?' x.tif y.gpkg 2>&1 || true; } \
             | sed -n 's/.*known: //p' | tr -d ',')
if [ -z "$criteria" ]; then
  echo "criteria.sh: could not read the criteria from $TT" >&2
  exit 1
fi

dems=()
if [ -f "$CRATER" ]; then
  dems+=("crater:$CRATER")
else
  echo "criteria.sh: $CRATER is absent: Crater Lake skipped"
fi
DS="$OUT/ds1025.tif"
if [ ! -f "$DS" ]; then
  "$TT" generate diamond_square "$DS" -size 1025 -seed 1 -q -overwrite
fi
dems+=("ds1025:$DS")

seconds() { # json file -> seconds.simplify
  python3 -c 'import json,sys; print("%.3f" % json.load(open(sys.argv[1]))["seconds"]["simplify"])' "$1"
}

for entry in "${dems[@]}"; do
  name=${entry%%:*}
  dem=${entry#*:}
  declare -A sec=()
  for c in $criteria; do
    for p in $PERCENTS; do
      js="$OUT/$name.$c.$p.json"
      if timeout "$BENCH_TIMEOUT" "$TT" simplify -percent "$p" -criterion "$c" \
           -json -overwrite "$dem" "$OUT/$name.$c.$p.gpkg" > "$js" 2> "$js.err"
      then
        sec[$c.$p]=$(seconds "$js")
      else
        sec[$c.$p]=">T"
      fi
      rm -f "$OUT/$name.$c.$p.gpkg"
    done
  done
  echo
  echo "== $name ($dem): seconds.simplify, and x Delaunay"
  printf '%-20s' criterion
  for p in $PERCENTS; do printf '%18s' "$p%"; done
  echo
  for c in $criteria; do
    printf '%-20s' "$c"
    for p in $PERCENTS; do
      s=${sec[$c.$p]}
      d=${sec[delaunay.$p]}
      if [[ $s == ">T" || $d == ">T" ]]; then
        printf '%18s' "$s"
      else
        printf '%10s %6.2fx' "$s" "$(python3 -c "print($s / max($d, 1e-9))")"
      fi
    done
    echo
  done
  unset sec
done
