#!/usr/bin/env bash
# bench/huge.sh [WORK [SIZE [TILE [WINDOWS]]]] -- issue 19's large run
# (docs/scale.md, "The 32769^2 run"): a SIZE^2 diamond-square fractal
# (default 32769, seed 1; about 4 GiB of Float32 samples) made by `terratin
# generate` in WORK (default /work/huge; the DEM is kept there and reused),
# the max error that keeps about 1 % of the samples found by an untiled
# `-percent 1` run on the top-left 4097^2 crop (gdal_translate), the whole
# DEM simplified in tiles of TILE (default 1024) on 2 threads at that error
# to a GeoPackage, then the bound checked by `terratin eval` on WINDOWS
# (default 4) tiles: the tile's samples (a gdal_translate crop) against the
# triangles whose bounding box lies inside the tile (selected through the
# GeoPackage's R-tree, whose float boxes are widened by a quarter cell).
# Prints wall seconds and peak memory (GNU time's maximum resident set) of
# every step, the vertices and triangles, and each window's max error,
# RMSE, uncovered and overlapped samples, then tests/apps/tin_topology.py
# on the whole TIN (conforming). Needs ~12 GiB free in WORK
# (the DEM 3.4 GiB, the GeoPackage 7.5 GiB for SIZE 32769).
set -eu
WORK=${1:-/work/huge}
SIZE=${2:-32769}
TILE=${3:-1024}
WINDOWS=${4:-4}
HERE=$(cd "$(dirname "$0")/.." && pwd)
T=${TT_TERRATIN:-$HERE/build/terratin}
mkdir -p "$WORK"
cd "$WORK"
DEM=ds$SIZE.tif
j() { python3 -c 'import json,sys
d=json.load(open(sys.argv[1]))
for k in sys.argv[2].split("."): d=d[k]
print(d)' "$1" "$2"; }
# timed NAME CMD...: runs CMD under GNU time (-v, kept in NAME.time)
timed() {
  local name=$1
  shift
  /usr/bin/time -v -o "$name.time" "$@"
}
# said NAME: the seconds and peak memory of a timed run
said() {
  python3 -c 'import re,sys
t=open(sys.argv[1]+".time").read()
w=re.search(r"Elapsed \(wall clock\) time.*: (\S+)", t).group(1).split(":")
s=sum(float(x)*60**i for i,x in enumerate(reversed(w)))
m=int(re.search(r"Maximum resident set size \(kbytes\): (\d+)", t).group(1))
print("%-10s %8.1f s %8d MiB" % (sys.argv[1], s, m//1024))' "$1"
}
echo "load average before: $(cut -d' ' -f1-3 /proc/loadavg)"
[ -f "$DEM" ] || timed generate "$T" generate diamond_square "$DEM" -size "$SIZE" -seed 1 -q
[ ! -f generate.time ] || said generate
ls -l "$DEM"
# 1 % of the samples: untiled -percent 1 on a 4097^2 crop (a fractal's
# local statistics do not depend on where the crop is)
C=4097
[ "$SIZE" -gt "$C" ] || C=$SIZE
gdal_translate -q -srcwin 0 0 $C $C -co TILED=YES "$DEM" crop.tif
timed percent1 "$T" simplify -q -json -overwrite -percent 1 -threads 2 crop.tif crop.gpkg >percent1.json
said percent1
E=$(j percent1.json max_error)
echo "max error for 1 % of a ${C}^2 crop: $E ($(j percent1.json vertices) vertices)"
rm -f crop.tif crop.gpkg
timed tiled "$T" simplify -json -overwrite -max_error "$E" -tile_size "$TILE" -threads 2 \
  "$DEM" tin.gpkg >tiled.json
said tiled
echo "tiled: $(j tiled.json vertices) vertices, $(j tiled.json triangles) triangles, max $(j tiled.json max_error), rmse $(j tiled.json rmse) (read+simplify $(j tiled.json seconds.simplify) s, write $(j tiled.json seconds.write) s)"
ls -l tin.gpkg
# eval on windows: tiles spread along the diagonal and one corner tile
read -r X0 DX Y0 DY < <(gdalinfo -json "$DEM" | python3 -c 'import json,sys
g=json.load(sys.stdin)["geoTransform"]; print(g[0], g[1], g[3], g[5])')
NT=$(( (SIZE - 1 + TILE - 1) / TILE ))
# window LABEL COL ROW W H: eval of the samples COL..COL+W-1, ROW..ROW+H-1
# against the triangles inside them
window() {
  local label=$1 c0=$2 r0=$3 w=$4 h=$5 xa xb ya yb
  gdal_translate -q -srcwin "$c0" "$r0" "$w" "$h" "$DEM" win.tif
  read -r xa xb ya yb < <(python3 -c 'import sys
x0,dx,y0,dy,c,r,w,h=map(float,sys.argv[1:])
xa=x0+(c+.25)*dx; xb=x0+(c+w-.25)*dx
ya=y0+(r+h-.25)*dy; yb=y0+(r+.25)*dy
print(xa,xb,min(ya,yb),max(ya,yb))' "$X0" "$DX" "$Y0" "$DY" "$c0" "$r0" "$w" "$h")
  rm -f win.gpkg
  ogr2ogr -f GPKG win.gpkg tin.gpkg -nln triangles -sql \
    "SELECT t.* FROM triangles t JOIN rtree_triangles_geom r ON t.fid = r.id WHERE r.minx >= $xa AND r.maxx <= $xb AND r.miny >= $ya AND r.maxy <= $yb"
  "$T" eval -json win.tif win.gpkg >"eval_$label.json" || true
  printf 'eval %s, %dx%d samples at (%d,%d): %s triangles, max %s, rmse %s, uncovered %s, overlapped %s\n' \
    "$label" "$w" "$h" "$c0" "$r0" "$(j "eval_$label.json" triangles)" \
    "$(j "eval_$label.json" max_error)" "$(j "eval_$label.json" rmse)" \
    "$(j "eval_$label.json" uncovered)" "$(j "eval_$label.json" overlapped)"
}
k=0
while [ $k -lt "$WINDOWS" ]; do
  i=$(( k * (NT - 1) / (WINDOWS > 1 ? WINDOWS - 1 : 1) ))
  jrow=$(( (NT - 1 - i + k) % NT ))
  c0=$((i * TILE)); r0=$((jrow * TILE))
  w=$((TILE + 1)); [ $((c0 + w)) -le "$SIZE" ] || w=$((SIZE - c0))
  h=$((TILE + 1)); [ $((r0 + h)) -le "$SIZE" ] || h=$((SIZE - r0))
  window "tile_${i}_$jrow" $c0 $r0 $w $h
  k=$((k + 1))
done
# the 2 x 2 tiles around the centre: their shared borders and corner
if [ "$NT" -ge 2 ]; then
  m=$(( NT / 2 - 1 ))
  w=$((2 * TILE + 1)); [ $((m * TILE + w)) -le "$SIZE" ] || w=$((SIZE - m * TILE))
  window "seams_${m}_$m" $((m * TILE)) $((m * TILE)) $w $w
fi
rm -f win.tif win.gpkg
# the whole TIN's topology (python, sqlite3: about 8 GiB and 7 minutes for
# 32769^2; TT_HUGE_TOPOLOGY=0 skips it)
if [ "${TT_HUGE_TOPOLOGY:-1}" != 0 ]; then
  timed topology python3 "$HERE/tests/apps/tin_topology.py" tin.gpkg
  said topology
fi
echo "bound: $E"
echo "load average after: $(cut -d' ' -f1-3 /proc/loadavg)"
