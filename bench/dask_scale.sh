#!/usr/bin/env bash
# bench/dask_scale.sh [SIZE [TILE [ERROR [WORK]]]] -- issue 19's cluster
# measurement (docs/scale.md): a SIZE^2 diamond-square fractal (default
# 8193, seed 1, as bench/scale.sh makes it) simplified at ERROR (default
# 3.44597: about 1 % of the 8193^2 samples) in tiles of TILE (default 1024)
# by `simplify -tile_size` on 1 and 2 threads, then by tools/tt_dask.py on
# a LocalCluster of 1, 2 and 4 worker processes. Prints per run the wall
# seconds and peak memory (GNU time: the driver's or the command's own
# resident set), and per Dask run the plan, tiles and merge seconds, the
# per-tile seconds (mean, max, sum) and the per-tile peak resident set of
# `terratin tiles run` (max), and whether the merged layers equal the
# simplify run's (md5 of ogrinfo). Needs /usr/bin/python3 with distributed.
set -eu
SIZE=${1:-8193}
TILE=${2:-1024}
ERR=${3:-3.44597}
HERE=$(cd "$(dirname "$0")/.." && pwd)
T=${TT_TERRATIN:-$HERE/build/terratin}
WORK=${4:-}
KEEP=1
if [ -z "$WORK" ]; then
  WORK=$(mktemp -d "${TMPDIR:-/tmp}/tt_dask_scale.XXXXXX")
  KEEP=0
fi
mkdir -p "$WORK"
cd "$WORK"
[ "$KEEP" = 1 ] || trap 'rm -rf "$WORK"' EXIT
DEM=ds$SIZE.tif
[ -f "$DEM" ] || "$T" generate diamond_square "$DEM" -size "$SIZE" -seed 1 -q
dump() { ogrinfo -ro -al -q "$1" triangles vertices 2>/dev/null | md5sum | cut -d' ' -f1; }
for th in 1 2; do
  /usr/bin/time -f "%e %M" -o s$th.time "$T" simplify -q -overwrite \
    -max_error "$ERR" -tile_size "$TILE" -threads $th "$DEM" s$th.gpkg
  read -r secs kib <s$th.time
  printf 'simplify -tile_size %s -threads %s: %8.1f s %6d MiB\n' "$TILE" $th \
    "$secs" $((kib / 1024))
done
ref=$(dump s1.gpkg)
echo "vertices: $(ogrinfo -ro -so s1.gpkg vertices | sed -n 's/Feature Count: //p')"
for n in 1 2 4; do
  /usr/bin/time -f "%e %M" -o d$n.time /usr/bin/python3 "$HERE/tools/tt_dask.py" \
    --terratin "$T" --workers $n --overwrite --stats d$n.json "$DEM" d$n.gpkg \
    -max_error "$ERR" -tile_size "$TILE" >/dev/null
  read -r secs kib <d$n.time
  same=no
  [ "$(dump d$n.gpkg)" = "$ref" ] && same=yes
  /usr/bin/python3 - d$n.json "$secs" "$n" "$same" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
t = [x["seconds"] for x in d["per_tile"]]
m = max(x["max_rss_kib"] for x in d["per_tile"])
print("dask %s workers: %8.1f s wall (plan %.1f, tiles %.1f, merge %.1f); "
      "%d tiles: %.2f s mean, %.2f s max, %.1f s sum; tile peak %d MiB; "
      "same layers as simplify: %s" % (sys.argv[3], float(sys.argv[2]),
      d["seconds_plan"], d["seconds_tiles"], d["seconds_merge"], len(t),
      sum(t) / len(t), max(t), sum(t), m // 1024, sys.argv[4]))
PY
done
