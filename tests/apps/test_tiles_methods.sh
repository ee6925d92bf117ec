#!/usr/bin/env bash
# test_tiles_methods.sh -- issue 19, every method and budget in tiles
# through the terratin command ($TT_TERRATIN):
#  - `-method decimate -tile_size`: conforming (tin_topology.py), every
#    valid sample within the bound (terratin eval), within 5 % of untiled
#    decimation, the same layers for 1 and 2 threads, the vertices on the
#    tile border lines exactly those of insertion's tiles (the border
#    polylines), and the decimation options (-start, -importance,
#    -selection, -onepass, -hole) on a DEM with nodata across borders;
#  - -max_points, -max_triangles and -percent in tiles (insertion and
#    decimation): never more than the budget, within 3 % below it (5 %
#    for decimation), conforming, within the bound the run reports, the
#    same for 1 and 2 threads; with -max_error the larger bound wins; a
#    budget below the tiles' corners is refused with nothing written;
#  - the GeoPackage written as the tiles merge (the default) is the merged
#    TIN's (TERRATIN_TILE_STREAM=NO), table by table (same_gpkg.py), for
#    decimation (with options, on nodata) and each budget kind, with 1 and
#    2 threads; a budget's passes not kept leave no row behind; SIGTERM
#    during a streamed decimation and a streamed budget run (its curve
#    pass, a pass dropped, the pass kept) leaves nothing;
#  - a corner of Mt Hood decimated in tiles, when TT_SHARED_TESTDATA has
#    it (streamed against merged too; the whole of Mt Hood and Vinschgau:
#    tests/long/test_long_tiles.sh).
# Decimation on a 129^2 fractal and a 129^2 one with nodata, in tiles of
# 32, at max error 6 (6,200 vertices; decimation runs ten times slower
# under ASan than in Release, insertion four); the budgets of insertion on
# a 257^2 fractal in tiles of 64 and 50.
# Prints "N passed, M failed"; exits 1 on any failure, 77 when a tool is
# missing.
set -u
. "$(dirname "${BASH_SOURCE[0]}")/../apps/tt_check.sh" || exit 1
. "$(dirname "${BASH_SOURCE[0]}")/tt_tiles_lib.sh" || exit 1

run generate diamond_square in/ds.tif -size 257 -seed 4 -q
run generate diamond_square in/d.tif -size 129 -seed 4 -q
# nodata across, along and at the corners of tiles of 32
# (two columns: GDAL's CSV driver does not open a file of one column)
cat >in/holes.csv <<'CSV'
id,WKT
1,"POLYGON ((20 -35,45 -35,45 -60,20 -60,20 -35))"
2,"POLYGON ((63.5 -5,64.5 -5,64.5 -30,63.5 -30,63.5 -5))"
3,"POLYGON ((62 -62,66 -62,66 -66,62 -66,62 -62))"
4,"POLYGON ((100 -100,129 -100,129 -129,100 -129,100 -100))"
CSV
run generate diamond_square in/n0.tif -size 129 -seed 9 -q
gdal_translate -q -a_ullr 0 0 129 -129 -a_nodata -9999 in/n0.tif in/n.tif
gdal_rasterize -q -burn -9999 -l holes in/holes.csv in/n.tif 2>err.txt
rc=$? # before the check: its $(...) would reset $?
check "nodata DEM made ($(cat err.txt))" [ $rc -eq 0 ]
gdal_translate -q -of AAIGrid in/n.tif in/n.asc
# the holes are there, and the untiled TIN's Euler characteristic is the
# one the tiled TINs must have (1 less the holes inside the domain)
run simplify -q -json -max_error 6 in/n.tif out/n_untiled.gpkg
check "nodata, untiled: holes in the DEM" \
  [ "$(jget out.txt valid_samples)" -lt $((129 * 129 - 750)) ]
python3 "$TOPO" out/n_untiled.gpkg in/n.asc >topo.json 2>topo.err
n_euler=$(jget topo.json euler)
check "nodata, untiled: the holes make the Euler characteristic < 1" \
  [ "$n_euler" -lt 1 ]

# --- decimation in tiles: the border vertices kept, every option ---
run simplify -q -json -max_error 6 -tile_size 32 -threads 2 in/d.tif out/t32.gpkg
check "insertion, tiles of 32: exit 0 ($(cat err.txt))" [ "$rc" -eq 0 ]
run simplify -q -json -method decimate -max_error 6 in/d.tif out/du.gpkg
cp out.txt du.json
streamed_vs_merged "decimate, tiles of 32, 2 threads" in/d.tif -method decimate -max_error 6 -tile_size 32 -threads 2
mv out/sv_s.gpkg out/dt.gpkg
cp s.json dt.json
nu=$(jget du.json vertices)
nv=$(jget dt.json vertices)
echo "note: fractal 129, decimation at 6: tiles of 32: $nv vertices, untiled $nu"
check "decimate, tiles of 32: vertices $nv within 5 % of untiled $nu" within "$nv" "$nu" 5
check "decimate, tiles of 32: method reported" [ "$(jget dt.json method)" = decimate ]
conforming "decimate, tiles of 32" out/dt.gpkg
bounded "decimate, tiles of 32" in/d.tif out/dt.gpkg 6
check "decimate: uncovered 0" [ "$(jget eval.json uncovered)" = 0 ]
streamed_vs_merged "decimate, tiles of 32, 1 thread" in/d.tif -method decimate -max_error 6 -tile_size 32 -threads 1
check "decimate: threads 1 vs 2, the same layers" [ "$(dump out/sv_s.gpkg)" = "$(dump out/dt.gpkg)" ]
# the importance field, NULL for the vertices no removal measured (the
# corners and border vertices), and no ins_rank
read -r n_imp n_rank <<<"$(sqlite3 -separator ' ' out/dt.gpkg 'select count(importance), count(ins_rank) from vertices')"
check "decimate: $n_imp of $nv vertices have an importance" \
  python3 -c 'import sys; a,b=map(int,sys.argv[1:]); sys.exit(0 if 0.9*b<a<b else 1)' "$n_imp" "$nv"
check "decimate: no ins_rank ($n_rank)" [ "$n_rank" = 0 ]
# the border vertices are those of insertion's tiles (the border polylines)
python3 - out/dt.gpkg out/t32.gpkg 32 129 >bv.txt <<'PY'
import sqlite3, sys
def border(p, n, w):
    db = sqlite3.connect(p)
    return {(c, r) for c, r in db.execute("select col, row from vertices")
            if (c % n == 0 and 0 < c < w - 1) or (r % n == 0 and 0 < r < w - 1)}
n, w = int(sys.argv[3]), int(sys.argv[4])
a, b = border(sys.argv[1], n, w), border(sys.argv[2], n, w)
print(len(a), len(b), len(a ^ b))
PY
read -r nba nbb nbx <bv.txt
check "decimate: $nba border vertices, insertion's $nbb, $nbx differ" eval '[ "$nbx" = 0 ] && [ "$nba" -gt 0 ]'
for opts in "-start greedy -importance drop" "-selection sequential -hole minangle" \
            "-onepass -importance volume" "-start greedy:1200 -importance hdh"; do
  streamed_vs_merged "decimate $opts, nodata" in/n.tif -method decimate -max_error 6 -tile_size 32 -threads 2 $opts
  mv out/sv_s.gpkg out/dn.gpkg
  conforming "decimate $opts, nodata" out/dn.gpkg in/n.asc "$n_euler"
  case $opts in
    *greedy:*) ;; # starts above the bound: no removal lowers its error
    *) bounded "decimate $opts, nodata" in/n.tif out/dn.gpkg 6 ;;
  esac
  run simplify -q -method decimate -max_error 6 -tile_size 32 -threads 1 $opts in/n.tif out/dn1.gpkg -overwrite
  check "decimate $opts: threads 1 vs 2, the same layers" [ "$(dump out/dn1.gpkg)" = "$(dump out/dn.gpkg)" ]
done

# --- budgets of the whole DEM in tiles: never over, a few per cent below ---
# budget DEM TILE FLAG N KEY [ASC EULER]: exit 0, count <= max, within 3 %;
# streamed as the merged TIN, with 1 and 2 threads
budget() {
  local dem=$1 n=$2 flag=$3 val=$4 key=$5
  streamed_vs_merged "-$flag $val, tiles of $n, 2 threads" $dem -$flag $val -tile_size $n -threads 2
  mv out/sv_s.gpkg out/b.gpkg
  cp s.json b.json
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
  # 1 thread: the same layers (streamed against merged too for the first
  # budget, FULL1 set; for the others the layers equal the 2 threads'
  # streamed ones, which equal the merged TIN's)
  if [ -n "${FULL1:-}" ]; then
    streamed_vs_merged "-$flag $val, tiles of $n, 1 thread" $dem -$flag $val -tile_size $n -threads 1
  else
    rm -f out/sv_s.gpkg
    run simplify -q -$flag $val -tile_size $n -threads 1 $dem out/sv_s.gpkg
  fi
  check "-$flag $val: threads 1 vs 2, the same layers" [ "$(dump out/sv_s.gpkg)" = "$(dump out/b.gpkg)" ]
}
FULL1=1 budget in/ds.tif 64 max_points 3000 vertices
budget in/ds.tif 64 percent 1 vertices
budget in/ds.tif 50 max_triangles 5000 triangles
budget in/ds.tif 64 max_points 300 vertices
budget in/n.tif 32 percent 5 vertices in/n.asc "$n_euler"
# decimation to a budget: the same bound search, decimated runs
streamed_vs_merged "decimate -max_points 800, 2 threads" in/d.tif -method decimate -max_points 800 -tile_size 32 -threads 2
mv out/sv_s.gpkg out/bd.gpkg
cp s.json bd.json
echo "note: fractal 129, decimate -max_points 800 in tiles of 32: $(jget bd.json vertices) vertices at the bound $(jget bd.json limits.max_error), $(jget bd.json tiling.budget_passes) runs"
check "decimate -max_points 800: $(jget bd.json vertices) <= 800" [ "$(jget bd.json vertices)" -le 800 ]
check "decimate -max_points 800: within 5 % below" within "$(jget bd.json vertices)" 800 5
conforming "decimate -max_points 800" out/bd.gpkg
bounded "decimate -max_points 800" in/d.tif out/bd.gpkg "$(jget bd.json limits.max_error)"
streamed_vs_merged "decimate -max_points 800, 1 thread" in/d.tif -method decimate -max_points 800 -tile_size 32 -threads 1
check "decimate -max_points 800: threads 1 vs 2, the same layers" [ "$(dump out/sv_s.gpkg)" = "$(dump out/bd.gpkg)" ]
# with -max_error too, the first stop wins: the bound is the larger
run simplify -q -json -max_points 3000 -max_error 14 -tile_size 64 in/ds.tif out/b.gpkg -overwrite
check "-max_points with -max_error 14: bound 14 ($(jget out.txt limits.max_error))" [ "$(jget out.txt limits.max_error)" = 14 ]
check "-max_points with -max_error 14: under the budget" [ "$(jget out.txt vertices)" -le 3000 ]
# a budget below the tiles' corners is refused, nothing written
rm -f out/x.gpkg
run simplify -max_points 10 -tile_size 64 in/ds.tif out/x.gpkg
check "-max_points 10 in 16 tiles: exit 2 ($(cat err.txt))" [ "$rc" -eq 2 ]
check "-max_points 10: one line" [ "$(wc -l <err.txt)" -eq 1 ]
check "-max_points 10: says the budget is below ($(cat err.txt))" grep -q "budget of 10 vertices is below" err.txt
check "-max_points 10: nothing written" [ ! -e out/x.gpkg ]

# --- interrupted while streamed: nothing left (a budget's dropped passes
# and the file made again included) ---
# (a 513^2 fractal: decimation 1.2 s in Release, the budget two passes of
# about 0.3 s after a curve pass; longer under the sanitizers)
run generate diamond_square in/big.tif -size 513 -seed 1 -q
for d in 0.2 0.5 0.9; do
  interrupted "decimation, streamed" $d -method decimate -max_error 1 -tile_size 128 -threads 2 in/big.tif
done
for d in 0.2 0.5 0.8; do
  interrupted "-max_points 40000, streamed" $d -max_points 40000 -tile_size 128 -threads 2 in/big.tif
done

# --- real DEMs decimated in tiles, when the shared test data are there ---
# (Mt Hood's corner only: Vinschgau decimated took 18 s under ASan; it is
# in tests/long/test_long_tiles.sh, with the whole of Mt Hood)
REAL_DEMS=gdalraster/lf_elev_220_mt_hood_utm.tif:20 real_dems ", decimation" -method decimate

echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
