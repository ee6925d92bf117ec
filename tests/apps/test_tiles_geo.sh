#!/usr/bin/env bash
# test_tiles_geo.sh -- issue 19: tiled runs of geographic and Web Mercator
# DEMs measured on the ground, as untiled runs are ($TT_TERRATIN). A
# 257^2 fractal given three georeferencings: EPSG:4326 over 1 x 0.5 degree
# at 69.5-70 N (a UTM frame), EPSG:4326 over 10 x 6 degrees at 70-76 N (an
# oblique stereographic frame with its constant scale) and EPSG:3857 at
# 58-61 N (map scale about 2). For each, `simplify -tile_size 64` on 2
# threads against an untiled run at the same bound: the frame reported is
# the untiled one and no affine-frame warning is given; the tiled TIN is
# conforming (tin_topology.py) and within the bound by `terratin eval`;
# its vertex count is within 5 % of the untiled one; every triangle that
# both TINs have (the same three samples) has the same area_2d, area_3d,
# slope, aspect and angles, to 1e-12 relative (the same ground points,
# scale factors, convergences and geodesic areas; only the rotation of the
# corners, and so the rounding, may differ; in the affine frame of the
# whole raster that tiles had before, slopes differed by up to 1.2 % in
# the UTM case and 17 % in the stereographic one); 1 thread gives
# the same layers; the GeoPackage written as the tiles merge (the
# default) is the merged TIN's (TERRATIN_TILE_STREAM=NO) table by table,
# with 1 and 2 threads, decimated and to a budget too (the triangles
# measured on their pieces' ground points); SIGTERM during a streamed
# geographic run leaves nothing; and
# `tiles plan/run/merge` gives the same layers as `simplify -tile_size`
# (the pieces carry the ground points, the merge the geodesic areas).
# Prints "N passed, M failed"; exits 1 on any failure, 77 when a tool is
# missing.
set -u
. "$(dirname "${BASH_SOURCE[0]}")/../apps/tt_check.sh" || exit 1

. "$(dirname "${BASH_SOURCE[0]}")/tt_tiles_lib.sh" || exit 1

# same_triangles A.gpkg B.gpkg: the attributes of the triangles both TINs
# have (the same three samples) are equal; prints how many there are (at
# least 1,000 and a tenth of them)
cat >same.py <<'PY'
import sqlite3, sys
COLS = "area_2d, area_3d, slope, aspect, min_angle, max_angle"
def tris(path):
    db = sqlite3.connect(path)
    v = {i: (c, r) for i, c, r in
         db.execute("select vertex_id, col, row from vertices")}
    return {tuple(sorted(v[i] for i in row[:3])): row[3:] for row in
            db.execute("select v0, v1, v2, %s from triangles" % COLS)}
a, b = tris(sys.argv[1]), tris(sys.argv[2])
common = [k for k in a if k in b]
# the corners may come in another rotation: rounding differs by an ulp
worst, at = 0.0, None
for k in common:
    for i, (x, y) in enumerate(zip(a[k], b[k])):
        d = abs(x - y)
        if i == 3:  # aspect: 0 and 360 are one azimuth
            d = min(d, 360 - d)
        d /= max(1.0, abs(x), abs(y))
        if d > worst:
            worst, at = d, k
print("%d of %d triangles in common, largest relative difference %.3g%s" % (
    len(common), len(a), worst,
    (" at %s: %s vs %s" % (at, a[at], b[at])) if at else ""))
# enough of them to mean something: thousands (a fifth of the triangles at
# max error 8; more than half at 4, whose TINs are three times the size)
sys.exit(0 if len(common) >= 1000 and len(common) * 10 > len(a) and worst <= 1e-12 else 1)
PY

run generate diamond_square ds.tif -size 257 -seed 7 -q
check "generate: exit 0 ($(cat err.txt))" [ "$rc" -eq 0 ]
# (max error 8: 9,500 vertices in each frame; 30,000 at 4)
E=8
# name, SRS, extent (ulx uly lrx lry), the frame the untiled run chooses
cases=(
  "utm|EPSG:4326|10 70 11 69.5|UTM zone 32N"
  "stereo|EPSG:4326|10 76 20 70|oblique stereographic"
  "webmerc|EPSG:3857|1000000 8600000 1300000 8000000|UTM zone 32N"
)
for c in "${cases[@]}"; do
  IFS='|' read -r name srs ullr frame <<<"$c"
  # shellcheck disable=SC2086
  gdal_translate -q -a_srs "$srs" -a_ullr $ullr ds.tif $name.tif
  run simplify -q -json -max_error $E $name.tif u_$name.gpkg
  check "$name untiled: exit 0 ($(cat err.txt))" [ "$rc" -eq 0 ]
  cp out.txt u.json
  run simplify -json -max_error $E -tile_size 64 -threads 2 $name.tif t_$name.gpkg
  check "$name tiled: exit 0 ($(cat err.txt))" [ "$rc" -eq 0 ]
  cp out.txt t.json
  check "$name tiled: no affine-frame warning ($(cat err.txt))" \
    bash -c "! grep -qi 'affine' err.txt"
  fu=$(jget u.json frame); ft=$(jget t.json frame)
  check "$name: frame '$ft' is the untiled '$fu'" [ "$ft" = "$fu" ]
  check "$name: frame is $frame" bash -c "echo '$fu' | grep -q '$frame'"
  check "$name: per vertex" bash -c "echo '$ft' | grep -q 'per vertex'"
  nu=$(jget u.json vertices); nt=$(jget t.json vertices)
  echo "note: $name: tiled $nt vertices, untiled $nu; frame $ft"
  check "$name: tiled vertices $nt within 5 % of untiled $nu" within "$nt" "$nu" 5
  if python3 "$TOPO" t_$name.gpkg >topo.json 2>topo.err; then pass; else
    fail "$name: not conforming: $(cat topo.json topo.err)"; fi
  check "$name: Euler characteristic 1 ($(cat topo.json))" \
    [ "$(jget topo.json euler)" = 1 ]
  "$T" eval -json -max_error $E $name.tif t_$name.gpkg >eval.json 2>eval.err
  erc=$?
  check "$name: eval within $E ($(cat eval.err))" [ $erc -eq 0 ]
  check "$name: none uncovered" [ "$(jget eval.json uncovered)" = 0 ]
  check "$name: none overlapped" [ "$(jget eval.json overlapped)" = 0 ]
  python3 same.py t_$name.gpkg u_$name.gpkg >same.txt 2>&1
  src=$?
  check "$name: common triangles' attributes equal ($(cat same.txt))" [ $src -eq 0 ]
  echo "note: $name: $(cat same.txt)"
  # written as the tiles merge against the merged TIN, 2 and 1 threads
  streamed_vs_merged "$name, streamed, 2 threads" $name.tif -max_error $E -tile_size 64 -threads 2
  streamed_vs_merged "$name, streamed, 1 thread" $name.tif -max_error $E -tile_size 64 -threads 1
  check "$name: 1 and 2 threads give the same layers" \
    [ "$(dump out/sv_s.gpkg)" = "$(dump t_$name.gpkg)" ]
done
# decimation and budgets of geographic and Web Mercator DEMs, streamed
# (decimation on 129^2 versions of the same extents, in tiles of 32: it
# runs ten times slower under ASan than in Release, insertion four)
run generate diamond_square ds129.tif -size 129 -seed 7 -q
for c in "${cases[@]}"; do
  IFS='|' read -r name srs ullr frame <<<"$c"
  # shellcheck disable=SC2086
  gdal_translate -q -a_srs "$srs" -a_ullr $ullr ds129.tif ${name}129.tif
done
streamed_vs_merged "stereo, decimation, 2 threads" stereo129.tif -method decimate -max_error $E -tile_size 32 -threads 2
streamed_vs_merged "webmerc, decimation, 1 thread" webmerc129.tif -method decimate -max_error $E -tile_size 32 -threads 1
streamed_vs_merged "stereo, -max_points 3000, 2 threads" stereo.tif -max_points 3000 -tile_size 64 -threads 2
streamed_vs_merged "webmerc, -percent 3, 1 thread" webmerc.tif -percent 3 -tile_size 64 -threads 1
# 2 % of the 66,049 samples is 1,320 vertices: every pass at the bounds the
# tiles' curves give makes one to three too many (their borders thin out
# as the bound grows, the curves' do not), so the passes over the budget
# step further each time, and bounds beyond the curves' are tried
streamed_vs_merged "webmerc, -percent 2, 2 threads" webmerc.tif -percent 2 -tile_size 64 -threads 2
check "webmerc, -percent 2: $(jget s.json vertices) <= 1320 vertices" [ "$(jget s.json vertices)" -le 1320 ]
check "webmerc, -percent 2: at least 97 % of them" [ "$(jget s.json vertices)" -ge 1280 ]
streamed_vs_merged "utm, decimation -max_triangles 1500, 2 threads" utm129.tif -method decimate -max_triangles 1500 -tile_size 32 -threads 2
check "utm, decimation -max_triangles 1500: $(jget s.json triangles) <= 1500" [ "$(jget s.json triangles)" -le 1500 ]

# interrupted while a geographic DEM's GeoPackage is streamed
# (513^2: 2.1 s in Release, longer under the sanitizers)
run generate diamond_square in/big.tif -size 513 -seed 1 -q
gdal_translate -q -a_srs EPSG:4326 -a_ullr 10 76 20 70 in/big.tif in/big_geo.tif
for d in 0.3 0.8 1.4; do
  interrupted "geographic, streamed" $d -max_error 0.5 -tile_size 128 -threads 2 in/big_geo.tif
done

# tiles plan/run/merge of the stereographic DEM: the pieces keep the
# ground points, the merge takes the geodesic areas from a window
run tiles plan stereo.tif p.json -max_error $E -tile_size 64
check "plan: exit 0 ($(cat err.txt))" [ "$rc" -eq 0 ]
n=$(jget p.json tiles)
ok=0
for k in $(seq 0 $((n - 1))); do
  "$T" tiles run p.json "$k" >/dev/null 2>>err.txt || ok=1
done
check "tiles run: $n tiles exit 0 ($(cat err.txt))" [ "$ok" -eq 0 ]
run tiles merge p.json m.gpkg -q
check "merge: exit 0 ($(cat err.txt))" [ "$rc" -eq 0 ]
check "merge: the layers of simplify -tile_size" \
  [ "$(dump m.gpkg)" = "$(dump t_stereo.gpkg)" ]
# the merge streamed (its pieces read back have no area function: tile 0's
# window gives it) against the merged TIN
TERRATIN_TILE_STREAM=NO "$T" tiles merge p.json m2.gpkg -q 2>err.txt
rc=$?
check "merge, TERRATIN_TILE_STREAM=NO: exit 0 ($(cat err.txt))" [ $rc -eq 0 ]
same "tiles merge, streamed and merged" m.gpkg m2.gpkg

echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
