#!/usr/bin/env bash
# bench/decimate_peers.sh -- terratin's decimation against the decimators
# people use, on the full-grid TIN of the same DEM, to the same vertex
# count: meshoptimizer's simplifier (npm; what glTF pipelines use) and
# VTK's vtkQuadricDecimation (Debian python3-vtk9). Every TIN is measured
# by `terratin eval -json` over every sample (max vertical error, RMSE);
# seconds are each tool's own simplification time (terratin: seconds.mesh,
# the start included). Everything lands in bench/out/peers/ (git-ignored).
#
#   bench/decimate_peers.sh [DEM] [PERCENT]   (default: a 513^2 fractal, 2 %)
set -eu
HERE=$(cd "$(dirname "$0")" && pwd)
TT=${TT:-$HERE/../build/terratin}
OUT=$HERE/out/peers
mkdir -p "$OUT"
if [ ! -f "$OUT/npm/node_modules/meshoptimizer/index.js" ]; then
  npm install --prefix "$OUT/npm" --no-audit --no-fund --no-save \
    --loglevel=error meshoptimizer@1.3.0
fi
PY=/usr/bin/python3  # Debian's, where python3-vtk9 lives
"$PY" -c "import vtk" 2>/dev/null || {
  echo "bench: needs python3-vtk9 (apt-get install python3-vtk9)" >&2; exit 1; }
DEM=${1:-}
PCT=${2:-2}
if [ -z "$DEM" ]; then
  DEM=$OUT/fractal513.tif
  [ -f "$DEM" ] || "$TT" generate diamond_square -size 513 -seed 1 -q "$DEM"
fi
gdal_translate -q -of ENVI -ot Float32 "$DEM" "$OUT/dem.raw"
gdalinfo -json "$DEM" > "$OUT/dem.info.json"

"$TT" simplify -q -json -overwrite -method decimate -start all \
  -importance error -selection sequential -percent "$PCT" "$DEM" \
  "$OUT/terratin.gpkg" > "$OUT/terratin.json"
N=$(python3 -c "import json; print(json.load(open('$OUT/terratin.json'))['vertices'])")
node "$HERE/meshopt_run.mjs" --meshopt "$OUT/npm/node_modules/meshoptimizer/index.js" \
  --raw "$OUT/dem.raw" --info "$OUT/dem.info.json" --vertices "$N" \
  --out "$OUT/meshopt.geojsonl" > "$OUT/meshopt.json"
"$PY" "$HERE/vtk_run.py" "$OUT/dem.raw" "$OUT/dem.info.json" "$N" \
  "$OUT/vtk.geojsonl" > "$OUT/vtk.json"
for t in terratin meshopt vtk; do
  f=$OUT/$t.gpkg; [ "$t" = terratin ] || f=$OUT/$t.geojsonl
  "$TT" eval -json "$DEM" "$f" > "$OUT/$t.eval.json"
done
python3 - "$OUT" <<'PY'
import json, sys
o = sys.argv[1]
rows = []
for t, name in (("terratin", "terratin decimate (error, sequential)"), ("meshopt", "meshoptimizer"),
                ("vtk", "vtkQuadricDecimation")):
    run = json.load(open(f"{o}/{t}.json"))
    ev = json.load(open(f"{o}/{t}.eval.json"))
    secs = run["seconds"]["mesh"] if t == "terratin" else run["seconds"]
    e = ev.get("errors", ev)
    rows.append((name, run["vertices"], e["max_error"], e["rmse"], secs))
base = rows[0]
print("| tool | vertices | max error | RMSE | seconds | max / ours | RMSE / ours |")
print("|---|---|---|---|---|---|---|")
for r in rows:
    print(f"| {r[0]} | {r[1]} | {r[2]:.4g} | {r[3]:.4g} | {r[4]:.2f} | "
          f"{r[2] / base[2]:.2f} | {r[3] / base[3]:.2f} |")
PY
