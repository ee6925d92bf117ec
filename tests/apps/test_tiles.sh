#!/usr/bin/env bash
# test_tiles.sh -- issue 19, tiled runs through the terratin command
# ($TT_TERRATIN): `simplify -tile_size N` on generated terrains, a DEM with
# nodata across and along tile borders and, when TT_SHARED_TESTDATA has
# them, Mt Hood (nodata collar) and the Vinschgau DEM. Each tiled TIN is
# read back from its GeoPackage tables by tin_topology.py (conforming: every
# edge in one or two triangles, no T-junction, no crack inside the domain,
# Euler characteristic 1 without nodata, vertex ids unique) and measured by
# `terratin eval` (every valid sample within the bound, covered once); the
# layers are the same for 1 and 2 threads; the vertex count is within 5 %
# of an untiled run's; the default bound is the untiled one; -max_memory
# too small for the heights tiles by itself; -max_points, -max_triangles
# and -percent in tiles give at most the budget and within 3 % of it, the
# same for 1 and 2 threads; decimation in tiles keeps
# the border polylines' vertices (those of insertion's tiles), with every
# decimation option, the same for 1 and 2 threads, and meets a budget too;
# bad -tile_size values are refused with nothing written; an interrupted
# tiled run leaves nothing behind. Prints "N passed, M failed"; exits 1 on
# any failure, 77 when a tool is missing.
set -u
. "$(dirname "${BASH_SOURCE[0]}")/../apps/tt_check.sh" || exit 1

T=${TT_TERRATIN:-}
if [ -z "$T" ] || [ ! -x "$T" ]; then
  echo "SKIP: TT_TERRATIN is not set or not executable"
  exit 77
fi
for tool in gdal_translate gdal_rasterize ogrinfo python3 md5sum; do
  if ! command -v "$tool" >/dev/null 2>&1; then
    echo "SKIP: $tool is missing"
    exit 77
  fi
done
TOPO="$(cd "$(dirname "$0")" && pwd)/tin_topology.py"

W=$(mktemp -d "${TMPDIR:-/tmp}/tt_tiles.XXXXXX") || exit 1
trap 'rm -rf "$W"' EXIT
cd "$W" || exit 1
mkdir in out

rc=0
run() {
  "$T" "$@" >out.txt 2>err.txt
  rc=$?
}
jget() { # jget FILE KEY[.KEY...]
  python3 -c 'import json,sys
d=json.load(open(sys.argv[1]))
for k in sys.argv[2].split("."): d=d[k]
print(d)' "$1" "$2"
}
dump() { ogrinfo -ro -al -q "$1" triangles vertices 2>/dev/null | md5sum | cut -d' ' -f1; }
# within A B PCT: |A/B - 1| <= PCT %
within() { python3 -c 'import sys; a,b,p=map(float,sys.argv[1:]); sys.exit(0 if abs(a/b-1)*100<=p else 1)' "$1" "$2" "$3"; }

# conforming NAME GPKG [ASC] [EULER]: topology, and eval within E
conforming() {
  local name=$1 gpkg=$2 asc=${3:-} euler=${4:-1}
  if python3 "$TOPO" "$gpkg" $asc >topo.json 2>topo.err; then pass; else
    fail "$name: not conforming: $(cat topo.json topo.err)"; fi
  if [ -n "$euler" ]; then
    check "$name: Euler characteristic $euler ($(cat topo.json))" \
      [ "$(jget topo.json euler)" = "$euler" ]
  fi
}
# bounded NAME DEM GPKG E: eval says every valid sample is within E, each
# covered once
bounded() {
  local name=$1 dem=$2 gpkg=$3 e=$4
  "$T" eval -json -max_error "$e" "$dem" "$gpkg" >eval.json 2>eval.err
  check "$name: eval within $e ($(cat eval.err))" [ $? -eq 0 ]
  check "$name: no sample overlapped" [ "$(jget eval.json overlapped)" = 0 ]
}

# --- the topology checker catches what it looks for ---
python3 - <<'PY'
import sqlite3
def tin(name, verts, tris):
    db = sqlite3.connect(name)
    db.execute("create table vertices (vertex_id, col, row)")
    db.execute("create table triangles (v0, v1, v2)")
    db.executemany("insert into vertices values (?,?,?)",
                   [(i, c, r) for i, (c, r) in enumerate(verts)])
    db.executemany("insert into triangles values (?,?,?)", tris)
    db.commit()
# a vertex inside the diagonal of another triangle
tin("tj.gpkg", [(0, 0), (2, 0), (2, 2), (0, 2), (1, 1)],
    [(0, 1, 2), (0, 4, 3), (4, 2, 3)])
# a 2 x 2 cell square with a cell missing: a hole inside the raster
tin("crack.gpkg", [(0, 0), (1, 0), (2, 0), (0, 1), (1, 1), (2, 1), (0, 2),
                   (1, 2)],
    [(0, 1, 4), (0, 4, 3), (1, 2, 5), (1, 5, 4), (3, 4, 7), (3, 7, 6)])
PY
python3 "$TOPO" tj.gpkg >topo.json
check "checker: a T-junction is caught ($(cat topo.json))" \
  [ "$(jget topo.json t_junctions)" = 1 ]
python3 "$TOPO" crack.gpkg >topo.json
check "checker: a hole inside the raster is a crack ($(cat topo.json))" \
  [ "$(jget topo.json cracks)" -ge 1 ]

# --- a fractal: tiled against untiled, threads, tile sizes ---
run generate diamond_square in/ds.tif -size 513 -seed 4 -q
run simplify -q -json -max_error 6 in/ds.tif out/u.gpkg
cp out.txt u.json
nu=$(jget u.json vertices)
for n in 128 100 500; do
  run simplify -q -json -max_error 6 -tile_size $n -threads 2 in/ds.tif out/t$n.gpkg
  check "-tile_size $n: exit 0 ($(cat err.txt))" [ "$rc" -eq 0 ]
  cp out.txt t$n.json
  nv=$(jget t$n.json vertices)
  echo "note: fractal 513, max error 6: tiles of $n: $nv vertices, untiled $nu"
  check "-tile_size $n: vertices $nv within 5 % of untiled $nu" within "$nv" "$nu" 5
  check "-tile_size $n: tiles reported" [ "$(jget t$n.json tiling.tile_size)" = $n ]
  conforming "fractal, tiles of $n" out/t$n.gpkg
  bounded "fractal, tiles of $n" in/ds.tif out/t$n.gpkg 6
  check "-tile_size $n: uncovered 0" [ "$(jget eval.json uncovered)" = 0 ]
  check "-tile_size $n: summary max error = eval's" \
    python3 -c 'import sys; sys.exit(0 if abs(float(sys.argv[1])-float(sys.argv[2]))<1e-9 else 1)' \
      "$(jget t$n.json max_error)" "$(jget eval.json max_error)"
done
run simplify -q -max_error 6 -tile_size 128 -threads 1 in/ds.tif out/t1.gpkg
check "threads 1 vs 2: the same layers" [ "$(dump out/t1.gpkg)" = "$(dump out/t128.gpkg)" ]
GDAL_NUM_THREADS=3 "$T" simplify -q -json -max_error 6 -tile_size 128 in/ds.tif out/g3.gpkg >g3.json 2>err.txt
check "GDAL_NUM_THREADS=3: the same layers" [ "$(dump out/g3.gpkg)" = "$(dump out/t128.gpkg)" ]
check "GDAL_NUM_THREADS=3: 3 threads used" [ "$(jget g3.json tiling.threads)" = 3 ]
# the default bound (0.5 % of the range) is the untiled run's
run simplify -q -json in/ds.tif out/d.gpkg
cp out.txt ud.json
run simplify -q -json -tile_size 150 in/ds.tif out/td.gpkg
cp out.txt td.json
check "default bound: tiled $(jget td.json limits.max_error) = untiled $(jget ud.json limits.max_error)" \
  [ "$(jget td.json limits.max_error)" = "$(jget ud.json limits.max_error)" ]
check "default bound: said to be the default" [ "$(jget td.json limits.max_error_default)" = True ]
bounded "default bound" in/ds.tif out/td.gpkg "$(jget td.json limits.max_error)"

# --- a smooth fault terrain, another criterion and a final pass ---
run generate fault in/f.tif -size 300x225 -seed 2 -displacement 20 -wave_size 8 -q
run simplify -q -max_error 0.5 -tile_size 64 -criterion minmax_angle -optimize lookahead in/f.tif out/f.gpkg
check "fault, minmax_angle + lookahead: exit 0 ($(cat err.txt))" [ "$rc" -eq 0 ]
conforming "fault, minmax_angle" out/f.gpkg
bounded "fault, minmax_angle" in/f.tif out/f.gpkg 0.5

# --- nodata across, along and at the corners of tile borders ---
cat >in/holes.csv <<'CSV'
WKT
"POLYGON ((90 -150,170 -150,170 -230,90 -230,90 -150))"
"POLYGON ((255.5 -10,256.5 -10,256.5 -120,255.5 -120,255.5 -10))"
"POLYGON ((250 -250,262 -250,262 -262,250 -262,250 -250))"
"POLYGON ((400 -400,513 -400,513 -513,400 -513,400 -400))"
"POLYGON ((10 -300,60 -330,20 -380,10 -300))"
CSV
run generate diamond_square in/n0.tif -size 513 -seed 9 -q
gdal_translate -q -a_ullr 0 0 513 -513 -a_nodata -9999 in/n0.tif in/n.tif
gdal_rasterize -q -burn -9999 -l holes in/holes.csv in/n.tif 2>err.txt
check "nodata DEM made ($(cat err.txt))" [ $? -eq 0 ]
gdal_translate -q -of AAIGrid in/n.tif in/n.asc
for n in 128 100 50; do
  run simplify -q -json -max_error 4 -tile_size $n in/n.tif out/n$n.gpkg
  check "nodata, tiles of $n: exit 0 ($(cat err.txt))" [ "$rc" -eq 0 ]
  conforming "nodata, tiles of $n" out/n$n.gpkg in/n.asc ""
  bounded "nodata, tiles of $n" in/n.tif out/n$n.gpkg 4
done
run simplify -q -json -max_error 4 in/n.tif out/nu.gpkg
cp out.txt nu.json
check "nodata: the same uncovered samples as untiled" \
  [ "$("$T" eval -json in/n.tif out/n128.gpkg | python3 -c 'import json,sys; print(json.load(sys.stdin)["uncovered"])')" = \
    "$("$T" eval -json in/n.tif out/nu.gpkg | python3 -c 'import json,sys; print(json.load(sys.stdin)["uncovered"])')" ]
run simplify -q -max_error 4 -tile_size 100 -threads 1 in/n.tif out/n1.gpkg
check "nodata: threads 1 vs 2, the same layers" [ "$(dump out/n1.gpkg)" = "$(dump out/n100.gpkg)" ]

# --- decimation in tiles: the border vertices kept, every option ---
run simplify -q -json -method decimate -max_error 6 in/ds.tif out/du.gpkg
cp out.txt du.json
run simplify -q -json -method decimate -max_error 6 -tile_size 128 -threads 2 in/ds.tif out/dt.gpkg
check "decimate, tiles of 128: exit 0 ($(cat err.txt))" [ "$rc" -eq 0 ]
cp out.txt dt.json
nu=$(jget du.json vertices)
nv=$(jget dt.json vertices)
echo "note: fractal 513, decimation at 6: tiles of 128: $nv vertices, untiled $nu"
check "decimate, tiles of 128: vertices $nv within 5 % of untiled $nu" within "$nv" "$nu" 5
check "decimate, tiles of 128: method reported" [ "$(jget dt.json method)" = decimate ]
conforming "decimate, tiles of 128" out/dt.gpkg
bounded "decimate, tiles of 128" in/ds.tif out/dt.gpkg 6
check "decimate: uncovered 0" [ "$(jget eval.json uncovered)" = 0 ]
run simplify -q -method decimate -max_error 6 -tile_size 128 -threads 1 in/ds.tif out/dt1.gpkg
check "decimate: threads 1 vs 2, the same layers" [ "$(dump out/dt1.gpkg)" = "$(dump out/dt.gpkg)" ]
# the border vertices are those of insertion's tiles (the border polylines)
python3 - out/dt.gpkg out/t128.gpkg 128 513 >bv.txt <<'PY'
import sqlite3, sys
def border(p, n, w):
    db = sqlite3.connect(p)
    return {(c, r) for c, r in db.execute("select col, row from vertices")
            if (c % n == 0 and 0 < c < w - 1) or (r % n == 0 and 0 < r < w - 1)}
a, b = border(sys.argv[1], int(sys.argv[3]), int(sys.argv[4])), border(sys.argv[2], int(sys.argv[3]), int(sys.argv[4]))
print(len(a), len(b), len(a ^ b))
PY
read -r nba nbb nbx <bv.txt
check "decimate: $nba border vertices, insertion's $nbb, $nbx differ" [ "$nbx" = 0 ] && [ "$nba" -gt 0 ]
for opts in "-start greedy -importance drop" "-selection sequential -hole minangle" \
            "-onepass -importance volume" "-start greedy:20000 -importance hdh"; do
  run simplify -q -json -method decimate -max_error 4 -tile_size 100 -threads 2 $opts in/n.tif out/dn.gpkg -overwrite
  check "decimate $opts, nodata: exit 0 ($(cat err.txt))" [ "$rc" -eq 0 ]
  conforming "decimate $opts, nodata" out/dn.gpkg in/n.asc ""
  case $opts in
    *greedy:*) ;; # starts above the bound: no removal lowers its error
    *) bounded "decimate $opts, nodata" in/n.tif out/dn.gpkg 4 ;;
  esac
  run simplify -q -method decimate -max_error 4 -tile_size 100 -threads 1 $opts in/n.tif out/dn1.gpkg -overwrite
  check "decimate $opts: threads 1 vs 2, the same layers" [ "$(dump out/dn1.gpkg)" = "$(dump out/dn.gpkg)" ]
done

# --- budgets of the whole DEM in tiles: never over, a few per cent below ---
# budget DEM TILE FLAG N MAXCOUNT_KEY: exit 0, count <= max, within 3 %
budget() {
  local dem=$1 n=$2 flag=$3 val=$4 key=$5
  run simplify -q -json -$flag $val -tile_size $n -threads 2 $dem out/b.gpkg -overwrite
  check "-$flag $val, tiles of $n: exit 0 ($(cat err.txt))" [ "$rc" -eq 0 ]
  cp out.txt b.json
  local got max e
  got=$(jget b.json $key)
  if [ "$flag" = percent ]; then
    max=$(python3 -c 'import sys,math; print(max(1,math.floor(float(sys.argv[1])/100*int(sys.argv[2]))))' "$val" "$(jget b.json valid_samples)")
  else
    max=$val
  fi
  e=$(jget b.json limits.max_error)
  echo "note: $dem -$flag $val in tiles of $n: $got $key of $max at the bound $e, $(jget b.json tiling.budget_passes) runs"
  check "-$flag $val: $got $key <= $max" [ "$got" -le "$max" ]
  check "-$flag $val: $got $key within 3 % below $max" within "$got" "$max" 3
  conforming "-$flag $val, tiles of $n" out/b.gpkg "${6:-}" "${7-1}"
  bounded "-$flag $val, tiles of $n" $dem out/b.gpkg "$e"
  run simplify -q -$flag $val -tile_size $n -threads 1 $dem out/b1.gpkg -overwrite
  check "-$flag $val: threads 1 vs 2, the same layers" [ "$(dump out/b1.gpkg)" = "$(dump out/b.gpkg)" ]
}
budget in/ds.tif 128 max_points 20000 vertices
budget in/ds.tif 128 percent 1 vertices
budget in/ds.tif 100 max_triangles 30000 triangles
budget in/ds.tif 128 max_points 500 vertices
budget in/n.tif 100 percent 2 vertices in/n.asc ""
# decimation to a budget: the same bound search, decimated runs
run simplify -q -json -method decimate -max_points 5000 -tile_size 128 -threads 2 in/ds.tif out/bd.gpkg
check "decimate -max_points 5000: exit 0 ($(cat err.txt))" [ "$rc" -eq 0 ]
cp out.txt bd.json
echo "note: in/ds.tif decimate -max_points 5000 in tiles of 128: $(jget bd.json vertices) vertices at the bound $(jget bd.json limits.max_error), $(jget bd.json tiling.budget_passes) runs"
check "decimate -max_points 5000: $(jget bd.json vertices) <= 5000" [ "$(jget bd.json vertices)" -le 5000 ]
check "decimate -max_points 5000: within 5 % below" within "$(jget bd.json vertices)" 5000 5
conforming "decimate -max_points 5000" out/bd.gpkg
bounded "decimate -max_points 5000" in/ds.tif out/bd.gpkg "$(jget bd.json limits.max_error)"
run simplify -q -method decimate -max_points 5000 -tile_size 128 -threads 1 in/ds.tif out/bd1.gpkg
check "decimate -max_points 5000: threads 1 vs 2, the same layers" [ "$(dump out/bd1.gpkg)" = "$(dump out/bd.gpkg)" ]
# with -max_error too, the first stop wins: the bound is the larger
run simplify -q -json -max_points 20000 -max_error 9 -tile_size 128 in/ds.tif out/b.gpkg -overwrite
check "-max_points with -max_error 9: bound 9 ($(jget out.txt limits.max_error))" [ "$(jget out.txt limits.max_error)" = 9 ]
check "-max_points with -max_error 9: under the budget" [ "$(jget out.txt vertices)" -le 20000 ]
# a budget below the tiles' corners is refused, nothing written
rm -f out/x.gpkg
run simplify -max_points 10 -tile_size 128 in/ds.tif out/x.gpkg
check "-max_points 10 in 16 tiles: exit 2 ($(cat err.txt))" [ "$rc" -eq 2 ]
check "-max_points 10: says the budget is below ($(cat err.txt))" grep -q "budget of 10 vertices is below" err.txt
check "-max_points 10: nothing written" [ ! -e out/x.gpkg ]

# --- the memory limit chooses tiles ---
run simplify -q -json -max_error 30 -max_memory 1500K in/ds.tif out/m.gpkg
check "-max_memory 1500K: exit 0 ($(cat err.txt))" [ "$rc" -eq 0 ]
check "-max_memory 1500K: tiled automatically" [ "$(jget out.txt tiling.automatic)" = True ]
bounded "-max_memory 1500K" in/ds.tif out/m.gpkg 30
run simplify -q -json -max_points 5000 -max_memory 1500K in/ds.tif out/mp.gpkg
check "-max_points 5000 -max_memory 1500K: exit 0 ($(cat err.txt))" [ "$rc" -eq 0 ]
check "-max_points 5000 -max_memory 1500K: tiled automatically" [ "$(jget out.txt tiling.automatic)" = True ]
check "-max_points 5000 -max_memory 1500K: $(jget out.txt vertices) <= 5000" [ "$(jget out.txt vertices)" -le 5000 ]
# the merged TIN counts against the limit too
run simplify -q -max_error 0.5 -tile_size 64 -max_memory 2M in/ds.tif out/mm.gpkg
check "-max_memory 2M, a dense tiled TIN: exit 1 ($rc)" [ "$rc" -eq 1 ]
check "-max_memory 2M: says while merging ($(cat err.txt))" grep -q "while merging tile .* more than the memory limit of 2 MiB" err.txt
check "-max_memory 2M: nothing written" [ ! -e out/mm.gpkg ]

# --- refusals: usage errors, nothing written ---
refused() {
  local name=$1
  shift
  rm -f out/x.gpkg
  run "$@"
  check "$name: exit 2 ($(cat err.txt))" [ "$rc" -eq 2 ]
  check "$name: one line" [ "$(wc -l <err.txt)" -eq 1 ]
  check "$name: nothing written" [ ! -e out/x.gpkg ]
}
refused "-tile_size 0" simplify -tile_size 0 in/ds.tif out/x.gpkg
refused "-tile_size 8" simplify -tile_size 8 in/ds.tif out/x.gpkg
refused "-tile_size -5" simplify -tile_size -5 in/ds.tif out/x.gpkg
refused "-tile_size abc" simplify -tile_size abc in/ds.tif out/x.gpkg
refused "-tile_size 1e3" simplify -tile_size 1e3 in/ds.tif out/x.gpkg
refused "-tile_size 99999" simplify -tile_size 99999 in/ds.tif out/x.gpkg
refused "tiles over -max_memory" simplify -tile_size 512 -max_memory 1M -max_error 6 in/ds.tif out/x.gpkg

# --- an interrupted tiled run leaves nothing (SIGTERM: a background job
# ignores SIGINT, and terratin keeps what its parent ignores) ---
run generate diamond_square in/big.tif -size 1025 -seed 1 -q
"$T" simplify -q -max_error 0 -tile_size 128 -threads 2 in/big.tif out/int.gpkg 2>err.txt &
pid=$!
sleep 1
kill -TERM $pid 2>/dev/null
wait $pid
rc=$?
if [ -e out/int.gpkg ]; then
  check "SIGTERM: finished before the signal ($rc)" [ "$rc" -eq 0 ]
else
  check "SIGTERM: ended by it ($rc)" [ "$rc" -ne 0 ]
  check "SIGTERM: says interrupted ($(cat err.txt))" grep -q "interrupted" err.txt
fi
check "SIGTERM: no temporary file" bash -c "! ls -A out | grep -q '^\\.tt'"

# --- real DEMs, when the shared test data are there ---
S=${TT_SHARED_TESTDATA:-}
for rel in gdalraster/lf_elev_220_mt_hood_utm.tif:20 rspatial_terra/elev_vinschgau.tif:20; do
  p=${rel%%:*}
  e=${rel##*:}
  if [ -z "$S" ] || [ ! -f "$S/$p" ]; then
    echo "note: $p not in TT_SHARED_TESTDATA; skipped"
    continue
  fi
  b=$(basename "$p" .tif)
  gdal_translate -q -of AAIGrid "$S/$p" in/$b.asc
  run simplify -q -json -max_error $e "$S/$p" out/${b}_u.gpkg
  cp out.txt ${b}_u.json
  run simplify -q -json -max_error $e -tile_size 128 "$S/$p" out/${b}_t.gpkg
  check "$b: tiled exit 0 ($(cat err.txt))" [ "$rc" -eq 0 ]
  cp out.txt ${b}_t.json
  nu=$(jget ${b}_u.json vertices)
  nv=$(jget ${b}_t.json vertices)
  echo "note: $b, max error $e: tiles of 128: $nv vertices, untiled $nu"
  check "$b: vertices $nv within 5 % of untiled $nu" within "$nv" "$nu" 5
  conforming "$b, tiles of 128" out/${b}_t.gpkg in/$b.asc ""
  bounded "$b, tiles of 128" "$S/$p" out/${b}_t.gpkg $e
  # decimation
  run simplify -q -json -method decimate -max_error $e "$S/$p" out/${b}_du.gpkg
  cp out.txt ${b}_du.json
  run simplify -q -json -method decimate -max_error $e -tile_size 128 "$S/$p" out/${b}_dt.gpkg
  check "$b: tiled decimation exit 0 ($(cat err.txt))" [ "$rc" -eq 0 ]
  cp out.txt ${b}_dt.json
  nu=$(jget ${b}_du.json vertices)
  nv=$(jget ${b}_dt.json vertices)
  echo "note: $b, decimation at $e: tiles of 128: $nv vertices, untiled $nu"
  check "$b, decimation: vertices $nv within 5 % of untiled $nu" within "$nv" "$nu" 5
  conforming "$b, decimation in tiles of 128" out/${b}_dt.gpkg in/$b.asc ""
  bounded "$b, decimation in tiles of 128" "$S/$p" out/${b}_dt.gpkg $e
done

echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
