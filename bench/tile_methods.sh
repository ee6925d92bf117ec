#!/usr/bin/env bash
# tile_methods.sh -- issue 19's methods and budgets in tiles, measured:
# decimation tiled against untiled (vertices, seconds, peak memory) and
# -max_points / -percent in tiles (vertices against the budget, the runs
# it took, seconds against one tiled run at the bound found), on a
# 1025^2 fractal, Mt Hood and Crater Lake (../shared/testdata).
# usage: bench/tile_methods.sh TERRATIN TESTDATA WORKDIR
set -u
T=$1 S=$2 W=$3
mkdir -p "$W" && cd "$W" || exit 1
"$T" generate diamond_square ds1025.tif -size 1025 -seed 1 -q -overwrite
j() { python3 -c 'import json,sys; d=json.load(open(sys.argv[1]))
for k in sys.argv[2:]:
    v=d
    for p in k.split("."): v=v[p]
    print(v, end=" " if k != sys.argv[-1] else "")
print()' "$@"; }
# one RUN_NAME ARGS...: the JSON in RUN_NAME.json, "seconds peak_KiB" printed
one() {
  local name=$1; shift
  /usr/bin/time -f "%e %M" -o "$name.time" "$T" simplify -json -overwrite "$@" >"$name.json" 2>"$name.err" || { echo "$name failed: $(cat $name.err)"; return 1; }
  echo "$name: $(j $name.json vertices triangles max_error limits.max_error) s/KiB $(cat $name.time)"
}
for dem in ds1025.tif:4:256 "$S/gdalraster/lf_elev_220_mt_hood_utm.tif:20:128" "$S/garland_heckbert_terra_scape/crater.stm.vrt:5:128"; do
  IFS=: read -r p e n <<<"$dem"
  b=$(basename "$p" | cut -d. -f1)
  echo "== $b, bound $e, tiles of $n"
  one ${b}_dec_u -method decimate -max_error $e "$p" ${b}_dec_u.gpkg
  one ${b}_dec_t -method decimate -max_error $e -tile_size $n -threads 2 "$p" ${b}_dec_t.gpkg
  "$T" eval -json -max_error $e "$p" ${b}_dec_t.gpkg >${b}_eval.json && echo "eval: $(j ${b}_eval.json max_error uncovered overlapped)"
  one ${b}_ins_t -max_error $e -tile_size $n -threads 2 "$p" ${b}_ins_t.gpkg
  for bud in "-max_points 10000" "-max_points 50000" "-percent 1" "-percent 5"; do
    tag=$(echo "$bud" | tr -d ' -')
    one ${b}_$tag $bud -tile_size $n -threads 2 "$p" ${b}_$tag.gpkg || continue
    echo "  runs $(j ${b}_$tag.json tiling.budget_passes) valid $(j ${b}_$tag.json valid_samples)"
    one ${b}_${tag}_at -max_error "$(j ${b}_$tag.json limits.max_error)" -tile_size $n -threads 2 "$p" ${b}_${tag}_at.gpkg
  done
done
