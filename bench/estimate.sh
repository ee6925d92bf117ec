#!/usr/bin/env bash
# bench/estimate.sh -- how well simplify's estimate before the work
# (apps/simplify/estimate.c, JSON "estimate") predicts the TIN it then
# makes: predicted against actual vertices and output bytes, on the DEMs
# of ../shared/testdata and on a generated fractal, at a tight and a
# moderate bound each (issue 27: the goal is within a factor of 2).
#
#   bench/estimate.sh                 # the shared DEMs and a 2049^2 fractal
#   BIG=1 bench/estimate.sh           # also a 12000^2 VRT of Mt Hood (~2 min)
#   TERRATIN=path bench/estimate.sh   # another binary (default build/terratin)
#
# Each line: DEM, bound, predicted and actual vertices, their ratio,
# predicted and actual GeoPackage bytes, their ratio, the bound the
# estimate gives for a 5 % TIN and the share it really keeps, and the
# estimate's seconds against the run's. A DEM missing from the shared
# folder is skipped with a message. Outputs go to bench/out/estimate/
# (git-ignored).
set -euo pipefail

ROOT=$(cd "$(dirname "$0")/.." && pwd)
cd "$ROOT"
TT=${TERRATIN:-build/terratin}
SHARED=${TT_SHARED_TESTDATA:-$ROOT/../shared/testdata}
OUT=$ROOT/bench/out/estimate
mkdir -p "$OUT"
[ -x "$TT" ] || { echo "estimate.sh: $TT: not built" >&2; exit 1; }

# DEM (relative to SHARED, or a path made here) and its two bounds
cases=(
  "garland_heckbert_terra_scape/crater.stm.vrt|1 5"
  "garland_heckbert_terra_scape/ntc.stm.vrt|1 4"
  "gdalraster/lf_elev_220_mt_hood_utm.tif|2 10"
  "mesher_granger_lidar/dem.tif|0.1 0.5"
  "hoppe_grand_canyon/gcanyon_elev_crop.bw.png|1 3"
  "spatial.tools_tahoe_lidar/tahoe_lidar_highesthit.tif|0.5 2"
  "pysheds/dem.tif|1 3"
)
"$TT" generate diamond_square "$OUT/ds2049.tif" -size 2049 -seed 1 -q \
  -overwrite 2>/dev/null || "$TT" generate diamond_square "$OUT/ds2049.tif" \
  -size 2049 -seed 1 -q 2>/dev/null || true
cases+=("$OUT/ds2049.tif|0.5 2")
if [ "${BIG:-0}" = 1 ]; then
  gdal_translate -q -of VRT -outsize 12000 12000 \
    "$SHARED/gdalraster/lf_elev_220_mt_hood_utm.tif" "$OUT/hood12000.vrt"
  cases+=("$OUT/hood12000.vrt|5 20")
fi

printf '%-28s %6s %10s %10s %6s %11s %11s %6s %9s %6s %6s %6s\n' DEM bound \
  est_v actual_v ratio est_bytes actual_b ratio 5%bound kept est_s run_s
for c in "${cases[@]}"; do
  dem=${c%%|*}
  bounds=${c#*|}
  case "$dem" in /*) path=$dem ;; *) path=$SHARED/$dem ;; esac
  if [ ! -r "$path" ]; then
    echo "SKIP: $dem is not in $SHARED"
    continue
  fi
  name=$(basename "$(dirname "$dem")")/$(basename "$dem")
  for e in $bounds; do
    rm -f "$OUT/tin.gpkg"
    "$TT" simplify -q -json -max_error "$e" "$path" "$OUT/tin.gpkg" \
      >"$OUT/run.json"
    bytes=$(stat -c %s "$OUT/tin.gpkg")
    five=$(python3 -c 'import json,sys; d=json.load(open(sys.argv[1])); print(d["estimate"]["max_error_5_percent"])' "$OUT/run.json")
    kept=-
    if [ "$five" != None ]; then
      rm -f "$OUT/five.gpkg"
      "$TT" simplify -q -json -max_error "$five" "$path" "$OUT/five.gpkg" \
        >"$OUT/five.json"
      kept=$(python3 -c 'import json,sys; d=json.load(open(sys.argv[1])); print("%.1f%%" % (100.0 * d["vertices"] / d["valid_samples"]))' "$OUT/five.json")
    fi
    python3 - "$OUT/run.json" "$name" "$e" "$bytes" "$five" "$kept" <<'EOF'
import json, sys
d = json.load(open(sys.argv[1]))
est = d["estimate"]
v, ev = d["vertices"], est["vertices"]
b, eb = int(sys.argv[4]), est["output_bytes"]
five = sys.argv[5]
five = "%.3g" % float(five) if five != "None" else "-"
print("%-28s %6s %10d %10d %6.2f %11d %11d %6.2f %9s %6s %6.2f %6.2f" % (
    sys.argv[2][-28:], sys.argv[3], ev, v, ev / v, eb, b, eb / b, five,
    sys.argv[6], est["seconds"], d["seconds"]["total"]))
EOF
  done
done
