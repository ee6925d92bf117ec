#!/usr/bin/env bash
# bench/outline.sh [TERRATIN] -- what the nodata outline costs at a 5 %
# budget: on the shared DEMs with nodata and on a generated 800 x 800 DEM
# with thousands of nodata patches (tests/apps/outline_grids.py noise,
# seed 5, a blob per 150 samples), the vertices the outline forces
# (-json forced_vertices), their share of the budget, the RMSE and the
# covered samples of `terratin simplify -percent 5`. Prints a Markdown
# table; a DEM missing from the shared data is left out, exit 77 when all
# are. docs/nodata.md holds its table.
set -u
ROOT=$(cd "$(dirname "$0")/.." && pwd)
T=${1:-$ROOT/build/terratin}
S=${TT_SHARED_TESTDATA:-$ROOT/../shared/testdata}
W=$(mktemp -d "${TMPDIR:-/tmp}/tt_outline_bench.XXXXXX") || exit 1
trap 'rm -rf "$W"' EXIT
python3 "$ROOT/tests/apps/outline_grids.py" make noise "$W/noise800.asc" 800 5 150
rows=0
echo "| DEM | samples | valid | forced vertices | share of the 5 % budget | RMSE at 5 % | covered samples |"
echo "|---|---:|---:|---:|---:|---:|---:|"
for dem in gdalraster/lf_elev_220_mt_hood_utm.tif rspatial_terra/elev.tif \
           landlab/west_bijou_gully.asc usgs_dem_san_francisco/sanfranciscos.dem \
           tin-terrain/valid_raster.tif "$W/noise800.asc"; do
  case $dem in /*) f=$dem; name="generated noise 800² (seed 5)" ;;
               *) f=$S/$dem; name=$dem ;; esac
  [ -f "$f" ] || continue
  if ! "$T" simplify -q -json -percent 5 "$f" "$W/o.gpkg" >"$W/s.json" 2>"$W/err"; then
    echo "| $name | | | | $(tr '|' '/' <"$W/err" | head -1) | | |"
  else
    python3 - "$W/s.json" "$name" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
n = d["cells"]
print("| %s | %s | %.1f %% | %d | %.1f %% | %.3f | %d |" % (
    sys.argv[2], "{:,}".format(n) if n else "", 100.0 * d["valid_samples"] / n if n else 0,
    d["forced_vertices"], 100.0 * d["forced_vertices"] / d["vertices"],
    d["rmse"], d["covered_samples"]))
PY
  fi
  rm -f "$W/o.gpkg"
  rows=$((rows + 1))
done
[ $rows -gt 1 ] || exit 77
