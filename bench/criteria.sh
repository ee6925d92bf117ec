#!/usr/bin/env bash
# bench/criteria.sh -- seconds of greedy insertion for every criterion, as a
# ratio to Delaunay in the same run (issue 4: goal, every criterion within
# 3x of Delaunay).
#
#   bench/criteria.sh                 # Crater Lake and a 1025^2 fractal
#   TERRATIN=path bench/criteria.sh   # another binary (default build/terratin)
#   PERCENTS="10 25" BENCH_TIMEOUT=300 bench/criteria.sh
#
# Each criterion is run REPEAT times (default 3) in alternation with
# Delaunay at the same percentage and the fastest of each counts, so a
# busy machine disturbs the ratios less; EXTRA adds options to every run
# (e.g. EXTRA="-repair local"). Printed with each time: its ratio to
# Delaunay's at the same percentage and the mean absolute error reached.
#
# DEMs: Crater Lake (../shared/testdata/garland_heckbert_terra_scape/
# crater.stm.vrt; skipped with a message when absent) and a 1025 x 1025
# diamond-square DEM (`terratin generate diamond_square -seed 1`). For each
# DEM, criterion and percentage P (10, 25, 50 % of the valid samples as
# vertices): `terratin simplify -percent P -criterion C -json`, and the
# figure is its seconds.simplify (meshing only, not reading or writing).
# The criteria are the ones the binary knows (read from its own error
# message), or those listed in CRITERIA (e.g. CRITERIA="delaunay l2").
# A run that passes BENCH_TIMEOUT seconds (default 900) prints ">T".
# Everything lands in bench/out/criteria/ (git-ignored).
set -euo pipefail

ROOT=$(cd "$(dirname "$0")/.." && pwd)
cd "$ROOT"
TT=${TERRATIN:-build/terratin}
OUT=bench/out/criteria
PERCENTS=${PERCENTS:-"10 25 50"}
BENCH_TIMEOUT=${BENCH_TIMEOUT:-900}
REPEAT=${REPEAT:-3}
EXTRA=${EXTRA:-}
CRATER=${CRATER:-$ROOT/../shared/testdata/garland_heckbert_terra_scape/crater.stm.vrt}

if [ ! -x "$TT" ]; then
  echo "criteria.sh: no terratin binary at $TT (build first, or set" \
       "TERRATIN=path)" >&2
  exit 1
fi
mkdir -p "$OUT"

criteria=${CRITERIA:-$({ "$TT" simplify -criterion '?' x.tif y.gpkg 2>&1 \
                           || true; } | sed -n 's/.*known: //p' | tr -d ',')}
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
meanerr() { # json file -> mean_abs_error
  python3 -c 'import json,sys; print("%.4g" % json.load(open(sys.argv[1]))["mean_abs_error"])' "$1"
}
modes() { # json file -> repair/optimize as resolved
  python3 -c 'import json,sys; d=json.load(open(sys.argv[1])); print(d["repair"] + "/" + d["optimize"])' "$1"
}

# one timed run: run_once NAME DEM CRITERION P -> prints seconds.simplify
# (">T" on a timeout or failure); the JSON stays in $OUT for the errors
run_once() {
  local js="$OUT/$1.$3.$4.json"
  if timeout "$BENCH_TIMEOUT" "$TT" simplify -percent "$4" -criterion "$3" \
       $EXTRA -json -overwrite "$2" "$OUT/$1.$3.$4.gpkg" > "$js" 2> "$js.err"
  then
    seconds "$js"
  else
    echo ">T"
  fi
  rm -f "$OUT/$1.$3.$4.gpkg"
}
fmin() { # fmin A B: the smaller, ">T" counting as infinite
  if [[ $1 == ">T" ]]; then echo "$2"; elif [[ $2 == ">T" || -z $2 ]]; then
    echo "$1"; else python3 -c "print(min($1, $2))"; fi
}

for entry in "${dems[@]}"; do
  name=${entry%%:*}
  dem=${entry#*:}
  declare -A sec=() ref=() err=() mode=()
  # Each criterion is timed right beside Delaunay: REPEAT alternating pairs
  # (Delaunay, criterion), the fastest of each; the ratio is taken against
  # the Delaunay runs of the same pairs, so that a slow spell of a shared
  # machine weighs on both sides of the ratio.
  for c in $criteria; do
    for p in $PERCENTS; do
      best="" dbest=""
      for ((k = 0; k < REPEAT; k++)); do
        d=$(run_once "$name" "$dem" delaunay "$p")
        dbest=$(fmin "$d" "$dbest")
        if [ "$c" = delaunay ]; then
          best=$dbest
          continue
        fi
        s=$(run_once "$name" "$dem" "$c" "$p")
        best=$(fmin "$s" "$best")
        [[ $s == ">T" ]] && break
      done
      sec[$c.$p]=$best
      ref[$c.$p]=$dbest
      js="$OUT/$name.$c.$p.json"
      if [[ $best != ">T" ]]; then
        err[$c.$p]=$(meanerr "$js")
        mode[$c]=$(modes "$js")
      fi
    done
  done
  echo
  echo "== $name ($dem): seconds.simplify (fastest of $REPEAT), x Delaunay" \
       "(timed in alternation with it), mean |error|"
  printf '%-18s%-16s' criterion repair/optimize
  for p in $PERCENTS; do printf '%27s' "$p%"; done
  echo
  for c in $criteria; do
    printf '%-18s%-16s' "$c" "${mode[$c]:-?}"
    for p in $PERCENTS; do
      s=${sec[$c.$p]}
      d=${ref[$c.$p]}
      if [[ $s == ">T" || $d == ">T" ]]; then
        printf '%27s' "$s"
      else
        printf '%8s %6.2fx %10s' "$s" "$(python3 -c "print($s / max($d, 1e-9))")" "${err[$c.$p]}"
      fi
    done
    echo
  done
  unset sec ref err mode
done
