#!/usr/bin/env bash
# test_tiles.sh -- issue 19, tiled runs through the terratin command
# ($TT_TERRATIN): `simplify -tile_size N` on generated terrains (a 257^2
# fractal in tiles of 16 to 250, a 300 x 225 fault terrain), a 257^2 DEM
# with nodata across and along tile borders and, when TT_SHARED_TESTDATA
# has them, a corner of Mt Hood (its nodata collar) and the Vinschgau DEM
# (the whole of Mt Hood: tests/long/test_long_tiles.sh). Each tiled TIN is
# read back from its GeoPackage tables by tin_topology.py (conforming: every
# edge in one or two triangles, no T-junction, no crack inside the domain,
# Euler characteristic 1 without nodata, vertex ids unique) and measured by
# `terratin eval` (every valid sample within the bound, covered once); the
# layers are the same for 1 and 2 threads; the vertex count is within 5 %
# of an untiled run's; the default bound is the untiled one; -max_memory
# too small for the heights tiles by itself (with a budget too); bad
# -tile_size values are refused with nothing written (decimation and
# budgets in tiles: test_tiles_methods.sh); an interrupted tiled run
# leaves nothing behind; the GeoPackage written as the tiles merge is the
# merged TIN's, table by table (geographic DEMs: test_tiles_geo.sh;
# decimation and budgets: test_tiles_methods.sh). Prints "N passed, M
# failed"; exits 1 on any failure, 77 when a tool is missing.
set -u
. "$(dirname "${BASH_SOURCE[0]}")/../apps/tt_check.sh" || exit 1

. "$(dirname "${BASH_SOURCE[0]}")/tt_tiles_lib.sh" || exit 1

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
# (257^2 at max error 6: 16,000 vertices; tiles of 16 are the smallest
# allowed, 250 leaves strips of 7 cells; the same holds on 8193^2 in tiles
# of 1024, tests/long/)
run generate diamond_square in/ds.tif -size 257 -seed 4 -q
run simplify -q -json -max_error 6 in/ds.tif out/u.gpkg
cp out.txt u.json
nu=$(jget u.json vertices)
for n in 64 50 250 16; do
  run simplify -q -json -max_error 6 -tile_size $n -threads 2 in/ds.tif out/t$n.gpkg
  check "-tile_size $n: exit 0 ($(cat err.txt))" [ "$rc" -eq 0 ]
  cp out.txt t$n.json
  nv=$(jget t$n.json vertices)
  echo "note: fractal 257, max error 6: tiles of $n: $nv vertices, untiled $nu"
  check "-tile_size $n: vertices $nv within 5 % of untiled $nu" within "$nv" "$nu" 5
  check "-tile_size $n: tiles reported" [ "$(jget t$n.json tiling.tile_size)" = $n ]
  conforming "fractal, tiles of $n" out/t$n.gpkg
  bounded "fractal, tiles of $n" in/ds.tif out/t$n.gpkg 6
  check "-tile_size $n: uncovered 0" [ "$(jget eval.json uncovered)" = 0 ]
  check "-tile_size $n: summary max error = eval's" \
    python3 -c 'import sys; sys.exit(0 if abs(float(sys.argv[1])-float(sys.argv[2]))<1e-9 else 1)' \
      "$(jget t$n.json max_error)" "$(jget eval.json max_error)"
done
run simplify -q -max_error 6 -tile_size 64 -threads 1 in/ds.tif out/t1.gpkg
check "threads 1 vs 2: the same layers" [ "$(dump out/t1.gpkg)" = "$(dump out/t64.gpkg)" ]
GDAL_NUM_THREADS=3 "$T" simplify -q -json -max_error 6 -tile_size 64 in/ds.tif out/g3.gpkg >g3.json 2>err.txt
check "GDAL_NUM_THREADS=3: the same layers" [ "$(dump out/g3.gpkg)" = "$(dump out/t64.gpkg)" ]
check "GDAL_NUM_THREADS=3: 3 threads used" [ "$(jget g3.json tiling.threads)" = 3 ]

# --- a smooth fault terrain, another criterion and a final pass ---
run generate fault in/f.tif -size 300x225 -seed 2 -displacement 20 -wave_size 8 -q
run simplify -q -max_error 2 -tile_size 64 -criterion minmax_angle -optimize lookahead in/f.tif out/f.gpkg
check "fault, minmax_angle + lookahead: exit 0 ($(cat err.txt))" [ "$rc" -eq 0 ]
conforming "fault, minmax_angle" out/f.gpkg
bounded "fault, minmax_angle" in/f.tif out/f.gpkg 2
# the default bound (twice the mean step) is the untiled run's
run simplify -q -json in/f.tif out/d.gpkg
cp out.txt ud.json
run simplify -q -json -tile_size 150 in/f.tif out/td.gpkg
cp out.txt td.json
check "default bound: tiled $(jget td.json limits.max_error) = untiled $(jget ud.json limits.max_error)" \
  [ "$(jget td.json limits.max_error)" = "$(jget ud.json limits.max_error)" ]
check "default bound: said to be the default" [ "$(jget td.json limits.max_error_default)" = True ]
bounded "default bound" in/f.tif out/td.gpkg "$(jget td.json limits.max_error)"

# --- nodata across, along and at the corners of tile borders ---
# (two columns: GDAL's CSV driver does not open a file of one column)
# (a 257^2 fractal: a one-cell strip along column 128, the border of
# tiles of 64, a square around the corner of four such tiles, a corner
# and a triangle)
cat >in/holes.csv <<'CSV'
id,WKT
1,"POLYGON ((45 -75,85 -75,85 -115,45 -115,45 -75))"
2,"POLYGON ((127.5 -5,128.5 -5,128.5 -60,127.5 -60,127.5 -5))"
3,"POLYGON ((125 -125,131 -125,131 -131,125 -131,125 -125))"
4,"POLYGON ((200 -200,257 -200,257 -257,200 -257,200 -200))"
5,"POLYGON ((5 -150,30 -165,10 -190,5 -150))"
CSV
run generate diamond_square in/n0.tif -size 257 -seed 9 -q
gdal_translate -q -a_ullr 0 0 257 -257 -a_nodata -9999 in/n0.tif in/n.tif
gdal_rasterize -q -burn -9999 -l holes in/holes.csv in/n.tif 2>err.txt
rc=$?
check "nodata DEM made ($(cat err.txt))" [ $rc -eq 0 ]
gdal_translate -q -of AAIGrid in/n.tif in/n.asc
# The domain has holes, so its Euler characteristic is not 1: the tiled
# TINs must have the untiled TIN's.
run simplify -q -max_error 6 in/n.tif out/n_untiled.gpkg
check "nodata, untiled: exit 0 ($(cat err.txt))" [ "$rc" -eq 0 ]
python3 "$TOPO" out/n_untiled.gpkg in/n.asc >topo.json 2>topo.err
n_euler=$(jget topo.json euler)
check "nodata, untiled: the holes make the Euler characteristic < 1" \
  [ "$n_euler" -lt 1 ]
for n in 64 50 25; do
  run simplify -q -json -max_error 6 -tile_size $n in/n.tif out/n$n.gpkg
  check "nodata, tiles of $n: exit 0 ($(cat err.txt))" [ "$rc" -eq 0 ]
  cp out.txt out/n$n.json
  # the holes are there: every sample not valid is one of the burnt ones
  check "nodata, tiles of $n: holes in the DEM" \
    [ "$(jget out/n$n.json valid_samples)" -lt $((257 * 257 - 5000)) ]
  conforming "nodata, tiles of $n" out/n$n.gpkg in/n.asc "$n_euler"
  bounded "nodata, tiles of $n" in/n.tif out/n$n.gpkg 6
  [ $n = 64 ] && n64_uncovered=$(jget eval.json uncovered)
done
"$T" eval -json -max_error 6 in/n.tif out/n_untiled.gpkg >eval.json 2>eval.err
check "nodata: the same uncovered samples as untiled ($n64_uncovered, $(jget eval.json uncovered))" \
  [ "$n64_uncovered" = "$(jget eval.json uncovered)" ]
run simplify -q -max_error 6 -tile_size 50 -threads 1 in/n.tif out/n1.gpkg
check "nodata: threads 1 vs 2, the same layers" [ "$(dump out/n1.gpkg)" = "$(dump out/n50.gpkg)" ]

# --- streamed (the default for a GeoPackage: rows written as the tiles
# merge, tiled_stream.c) against the merged-TIN path
# (TERRATIN_TILE_STREAM=NO): the same rows, byte for byte, extents,
# counts, run_parameters (but times), styles; the R-trees by content (the
# same id and box for every feature, rtreecheck ok: the streamed writer
# packs its leaves block by block, TERRATIN_RTREE_BLOCK=RB features a block
# here so that a small DEM makes many blocks; RB unset: the default block,
# more than these layers hold, gives the merged path's nodes byte for
# byte, SAME_MODE= compares them so) ---
RB=5000 streamed_vs_merged "fractal, tiles of 64, 2 threads, R-tree blocks of 5000" in/ds.tif -max_error 6 -tile_size 64 -threads 2
RB=1 streamed_vs_merged "fractal, tiles of 50, 1 thread, an R-tree block a piece" in/ds.tif -max_error 6 -tile_size 50 -threads 1
SAME_MODE= streamed_vs_merged "fractal, tiles of 250, 2 threads, one R-tree block: the same nodes" in/ds.tif -max_error 6 -tile_size 250 -threads 2
RB=2000 streamed_vs_merged "fault, default bound, tiles of 64, R-tree blocks of 2000" in/f.tif -tile_size 64 -threads 2
RB=3000 streamed_vs_merged "nodata, tiles of 25, 2 threads, R-tree blocks of 3000" in/n.tif -max_error 6 -tile_size 25 -threads 2
streamed_vs_merged "nodata, tiles of 64, 1 thread" in/n.tif -max_error 6 -tile_size 64 -threads 1
streamed_vs_merged "fault, minmax_angle + lookahead" in/f.tif -max_error 2 -tile_size 64 -criterion minmax_angle -optimize lookahead
JB="$(cd "$(dirname "$0")/../../testdata" && pwd)/jacksboro_fault_dem.tif"
# (Jacksboro at max error 20: 12,500 vertices; at 2 it kept 98,000)
RB=700 LAYERS_OF="x_triangles x_vertices" streamed_vs_merged "-t_srs, -nln, -layers" "$JB" -max_error 20 -tile_size 64 -t_srs EPSG:3857 -nln x_ -layers vertices,triangles
streamed_vs_merged "-lco SPATIAL_INDEX=NO, -nostyle" in/ds.tif -max_error 6 -tile_size 64 -lco SPATIAL_INDEX=NO -nostyle
# GDAL's spatial filter goes through the streamed R-tree (in blocks of
# 2000 features: packed leaves, upper levels and the root patched at the
# end)
TERRATIN_RTREE_BLOCK=2000 "$T" simplify -q -max_error 6 -tile_size 50 in/ds.tif out/sf.gpkg 2>err.txt
# a window in the middle of the layer's extent
win=$(python3 -c 'import sqlite3,sys
x0,y0,x1,y1=sqlite3.connect(sys.argv[1]).execute("select min_x,min_y,max_x,max_y from gpkg_contents where table_name=\"triangles\"").fetchone()
w,h=x1-x0,y1-y0
print(x0+0.3*w, y0+0.3*h, x0+0.6*w, y0+0.55*h)' out/sf.gpkg)
n1=$(ogrinfo -ro -so out/sf.gpkg triangles -spat $win 2>/dev/null | sed -n 's/Feature Count: //p')
# the same window by a scan of the geometries (no index)
n2=$(ogrinfo -ro -q -sql "SELECT count(*) AS n FROM triangles WHERE ST_MaxX(geom) >= $(echo $win | cut -d' ' -f1) AND ST_MinX(geom) <= $(echo $win | cut -d' ' -f3) AND ST_MaxY(geom) >= $(echo $win | cut -d' ' -f2) AND ST_MinY(geom) <= $(echo $win | cut -d' ' -f4)" out/sf.gpkg 2>/dev/null | sed -n 's/.*n (Integer[64]*) = //p')
check "streamed: a spatial filter finds triangles ($n1)" [ "${n1:-0}" -gt 0 ]
check "streamed: the R-tree's answer ($n1) is the scan's ($n2)" [ "$n1" = "$n2" ]
check "streamed: rtreecheck ok" [ "$(python3 -c 'import sqlite3,sys
db=sqlite3.connect(sys.argv[1])
print(" ".join(db.execute("select rtreecheck(?)",(t,)).fetchone()[0] for t in ("rtree_triangles_geom","rtree_vertices_geom")))' out/sf.gpkg 2>&1)" = "ok ok" ]
# ... and the GeoPackage's triggers keep it right when the file changes: an
# append through OGR (new fids), an SQL UPDATE and a DELETE of geometries
cp out/sf.gpkg out/sf_src.gpkg
ogr2ogr -q -update -append out/sf.gpkg out/sf_src.gpkg triangles -where "fid <= 500" 2>err.txt
rc=$?
check "streamed R-tree: ogr2ogr -update -append exit 0 ($(cat err.txt))" [ $rc -eq 0 ]
check "streamed R-tree: 500 features appended" \
  [ "$(sqlite3 out/sf.gpkg 'select count(*) from triangles') " = "$(( $(sqlite3 out/sf_src.gpkg 'select count(*) from triangles') + 500 )) " ]
ogrinfo -q out/sf.gpkg -sql "UPDATE triangles SET geom = (SELECT geom FROM triangles WHERE fid = 7) WHERE fid IN (3, 1000, 20000)" >/dev/null 2>err.txt
ogrinfo -q out/sf.gpkg -sql "DELETE FROM triangles WHERE fid IN (5, 6000)" >/dev/null 2>>err.txt
check "streamed R-tree: SQL UPDATE and DELETE ran ($(cat err.txt))" [ ! -s err.txt ]
check "streamed R-tree after the changes: rtreecheck, one entry a feature, each holding its geometry's envelope, the updated ones at their new place" \
  [ "$(python3 -c 'import sqlite3,struct,sys
db=sqlite3.connect(sys.argv[1])
ok=db.execute("select rtreecheck(?)",("rtree_triangles_geom",)).fetchone()[0]
n=db.execute("select count(*) from triangles").fetchone()[0]
r=db.execute("select count(*) from rtree_triangles_geom").fetchone()[0]
bad=0
for g,a,b,c,d in db.execute("select t.geom, r.minx, r.maxx, r.miny, r.maxy from triangles t join rtree_triangles_geom r on r.id = t.fid"):
    if (g[3] >> 1) & 7: # the envelope: min x, max x, min y, max y
        e=struct.unpack("<4d" if g[3] & 1 else ">4d", g[8:40])
        bad+=not (a<=e[0] and b>=e[1] and c<=e[2] and d>=e[3])
moved=db.execute("select count(distinct minx || maxx || miny || maxy) from rtree_triangles_geom where id in (3, 7, 1000, 20000)").fetchone()[0]
print(ok, n == r, bad, moved)' out/sf.gpkg 2>&1)" = "ok True 0 1" ]

# --- the memory limit chooses tiles ---
# (on a 513^2 fractal: the limits are said in MiB, and smaller DEMs fit in
# the smallest)
run generate diamond_square in/ds513.tif -size 513 -seed 4 -q
run simplify -q -json -max_error 30 -max_memory 1200K in/ds513.tif out/m.gpkg
check "-max_memory 1200K: exit 0 ($(cat err.txt))" [ "$rc" -eq 0 ]
check "-max_memory 1200K: tiled automatically" [ "$(jget out.txt tiling.automatic)" = True ]
bounded "-max_memory 1200K" in/ds513.tif out/m.gpkg 30
run simplify -q -json -max_points 5000 -max_memory 1200K in/ds513.tif out/mp.gpkg
check "-max_points 5000 -max_memory 1200K: exit 0 ($(cat err.txt))" [ "$rc" -eq 0 ]
check "-max_points 5000 -max_memory 1200K: tiled automatically" [ "$(jget out.txt tiling.automatic)" = True ]
check "-max_points 5000 -max_memory 1200K: $(jget out.txt vertices) <= 5000" [ "$(jget out.txt vertices)" -le 5000 ]
# the merged TIN counts against the limit too
run simplify -q -max_error 0.5 -tile_size 64 -max_memory 2M in/ds513.tif out/mm.gpkg
check "-max_memory 2M, a dense tiled TIN: exit 1 ($rc)" [ "$rc" -eq 1 ]
check "-max_memory 2M: says while merging ($(cat err.txt))" grep -q "while merging tile .* more than the memory limit of 2 MiB" err.txt
check "-max_memory 2M: nothing written" [ ! -e out/mm.gpkg ]
check "-max_memory 2M: no temporary file" bash -c "! ls -A out | grep -q '^\\.tt'"

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
# (a 513^2 fractal: 2.3 s at max error 0.3 in Release, longer under the
# sanitizers, so the signals fall from the first tiles to the R-trees in
# one build or the other)
run generate diamond_square in/big.tif -size 513 -seed 1 -q
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
# the same while the streamed GeoPackage is being written: at several
# moments, from the first tiles to the R-trees
for d in 0.3 0.8 1.5 2.2; do
  interrupted "streamed" $d -max_error 0.3 -tile_size 64 -threads 2 in/big.tif
done

# --- real DEMs, when the shared test data are there ---
real_dems ""

echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
