#!/usr/bin/env bash
# bench/tile_stream.sh [SIZE [ERROR [TILE [RUNS]]]] -- a tiled run's
# GeoPackage written as the tiles merge (the default) against the merged-TIN
# path (TERRATIN_TILE_STREAM=NO), docs/scale.md "The GeoPackage streamed
# against the merged TIN": a SIZE^2 diamond-square fractal (default 8193,
# seed 1) simplified to ERROR (default 3.446; 2.41 for 16385) in tiles of
# TILE (default 1024) on 2 threads, RUNS times each (default 2),
# alternated. Prints each run's wall seconds and peak memory (GNU time's
# maximum resident set, KiB), then checks that the two files hold the same
# tables (tests/apps/same_gpkg.py; the R-trees by content: the streamed
# one's leaves are packed block by block) and compares their R-trees for
# queries (bench/rtree_queries.py). TT_TERRATIN_BEFORE=<binary> adds a
# streamed run of that binary to each round (a before/after comparison).
# The DEM and files go to a mktemp folder, removed at the end.
set -eu
SIZE=${1:-8193}
ERR=${2:-3.446}
TILE=${3:-1024}
RUNS=${4:-2}
HERE=$(cd "$(dirname "$0")/.." && pwd)
T=${TT_TERRATIN:-$HERE/build/terratin}
WORK=$(mktemp -d "${TMPDIR:-/tmp}/tt_stream.XXXXXX")
trap 'rm -rf "$WORK"' EXIT
"$T" generate diamond_square "$WORK/dem.tif" -size "$SIZE" -seed 1 -q
for i in $(seq 1 "$RUNS"); do
  for mode in ${TT_TERRATIN_BEFORE:+BEFORE} YES NO; do
    rm -f "$WORK/$mode.gpkg"
    bin=$T
    [ "$mode" = BEFORE ] && bin=$TT_TERRATIN_BEFORE
    TERRATIN_TILE_STREAM=${mode/BEFORE/YES} /usr/bin/time -f "stream=$mode run $i: %e s %M KiB" \
      "$bin" simplify -q -tile_size "$TILE" -threads 2 -max_error "$ERR" \
      "$WORK/dem.tif" "$WORK/$mode.gpkg" 2>&1 | grep -v "affine frame" || true
  done
done
python3 "$HERE/tests/apps/same_gpkg.py" --rtree-content "$WORK/YES.gpkg" "$WORK/NO.gpkg"
python3 "$HERE/bench/rtree_queries.py" "$WORK/YES.gpkg" "$WORK/NO.gpkg"
