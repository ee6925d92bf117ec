#!/usr/bin/env bash
# bench/tile_stream.sh [SIZE [ERROR [TILE [RUNS [KIND]]]]] -- a tiled run's
# GeoPackage written as the tiles merge (the default) against the merged-TIN
# path (TERRATIN_TILE_STREAM=NO), docs/scale.md "The GeoPackage streamed
# against the merged TIN": a SIZE^2 diamond-square fractal (default 8193,
# seed 1) simplified to ERROR (default 3.446; 2.41 for 16385) in tiles of
# TILE (default 1024) on 2 threads, RUNS times each (default 2),
# alternated. KIND (default projected) is what runs:
#   projected   insertion to ERROR, the DEM as `terratin generate` writes it
#   geographic  insertion to ERROR, the DEM given EPSG:4326 over 10-14 E,
#               60-62 N (gdal_translate -a_srs -a_ullr: an oblique
#               stereographic frame, ground points per sample)
#   decimate    -method decimate to ERROR
#   points:N    insertion to the budget -max_points N (ERROR unused)
# Prints each run's wall seconds, user + system CPU seconds and peak memory
# (GNU time's maximum resident set, KiB), the vertices and, for a budget,
# the passes; then checks that the two files hold the same tables
# (tests/apps/same_gpkg.py; the R-trees by content: the streamed one's
# leaves are packed block by block) and compares their R-trees for
# queries (bench/rtree_queries.py). TT_TERRATIN_BEFORE=<binary> adds a
# streamed run of that binary to each round (a before/after comparison).
# The DEM and files go to a mktemp folder, removed at the end.
set -eu
SIZE=${1:-8193}
ERR=${2:-3.446}
TILE=${3:-1024}
RUNS=${4:-2}
KIND=${5:-projected}
HERE=$(cd "$(dirname "$0")/.." && pwd)
T=${TT_TERRATIN:-$HERE/build/terratin}
PY=/usr/bin/python3
WORK=$(mktemp -d "${TMPDIR:-/tmp}/tt_stream.XXXXXX")
trap 'rm -rf "$WORK"' EXIT
"$T" generate diamond_square "$WORK/dem.tif" -size "$SIZE" -seed 1 -q
DEM=$WORK/dem.tif
OPTS=(-max_error "$ERR")
case $KIND in
  projected) ;;
  geographic)
    gdal_translate -q -co TILED=YES -a_srs EPSG:4326 -a_ullr 10 62 14 60 \
      "$DEM" "$WORK/geo.tif"
    DEM=$WORK/geo.tif ;;
  decimate) OPTS+=(-method decimate) ;;
  points:*) OPTS=(-max_points "${KIND#points:}") ;;
  *) echo "tile_stream.sh: unknown KIND $KIND" >&2; exit 2 ;;
esac
for i in $(seq 1 "$RUNS"); do
  for mode in ${TT_TERRATIN_BEFORE:+BEFORE} YES NO; do
    rm -f "$WORK/$mode.gpkg"
    bin=$T
    [ "$mode" = BEFORE ] && bin=$TT_TERRATIN_BEFORE
    TERRATIN_TILE_STREAM=${mode/BEFORE/YES} /usr/bin/time -o "$WORK/time.txt" \
      -f "%e s wall, %U + %S s CPU, %M KiB" \
      "$bin" simplify -q -json -tile_size "$TILE" -threads 2 "${OPTS[@]}" \
      "$DEM" "$WORK/$mode.gpkg" >"$WORK/run.json"
    echo "$KIND stream=$mode run $i: $(cat "$WORK/time.txt"), $("$PY" -c '
import json, sys
d = json.load(open(sys.argv[1]))
t = d["tiling"]
print("%d vertices, streamed %s, %d budget passes" % (d["vertices"],
      t["streamed"], t["budget_passes"]))' "$WORK/run.json")"
  done
done
"$PY" "$HERE/tests/apps/same_gpkg.py" --rtree-content "$WORK/YES.gpkg" "$WORK/NO.gpkg"
"$PY" "$HERE/bench/rtree_queries.py" "$WORK/YES.gpkg" "$WORK/NO.gpkg"
