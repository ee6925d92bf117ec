#!/usr/bin/env bash
# test_tiles_cluster.sh -- issue 19's cluster commands through the terratin
# command ($TT_TERRATIN): `tiles plan`, `tiles run` of every tile (in
# reverse order), `tiles merge` give the same triangles and vertices layers
# as `simplify -tile_size` with the same options (md5 of ogrinfo), on a
# fractal (refined, and decimated: the plan carries -method decimate) and
# on a DEM with nodata across tile borders; a missing piece, a
# stale piece (another tile's), a changed DEM, a tile id out of range, an
# existing plan, piece or output without -overwrite, a plan without
# -max_error and a damaged piece are refused with one line, a non-zero exit
# and nothing written; no temporary file is left in the pieces' folder.
# Prints "N passed, M failed"; exits 1 on any failure, 77 when a tool is
# missing.
set -u
. "$(dirname "${BASH_SOURCE[0]}")/../apps/tt_check.sh" || exit 1

T=${TT_TERRATIN:-}
if [ -z "$T" ] || [ ! -x "$T" ]; then
  echo "SKIP: TT_TERRATIN is not set or not executable"
  exit 77
fi
for tool in gdal_translate gdal_calc.py ogrinfo md5sum sqlite3; do
  if ! command -v "$tool" >/dev/null 2>&1; then
    echo "SKIP: $tool is missing"
    exit 77
  fi
done

W=$(mktemp -d "${TMPDIR:-/tmp}/tt_tcl.XXXXXX") || exit 1
trap 'rm -rf "$W"' EXIT
cd "$W" || exit 1

rc=0
run() {
  "$T" "$@" >out.txt 2>err.txt
  rc=$?
}
# the layers' content: a SHA3 of every row of triangles and vertices, in
# rowid order, every column, blobs byte for byte (the sqlite3 shell's
# sha3_query): equal when `ogrinfo -al` of the layers would be, to the last
# bit rather than to its 15 digits, in a tenth of its time; an unreadable
# file prints its name, so two never compare equal
dump() {
  sqlite3 -readonly "$1" "select hex(sha3_query('select * from triangles order by rowid; select * from vertices order by rowid'))" 2>&1 ||
    echo "error: $1"
}
one_line() { [ "$(wc -l <err.txt)" -eq 1 ] && grep -q "$1" err.txt; }

# all_tiles PLAN N: every tile, last first (order does not matter)
all_tiles() {
  local k
  for k in $(seq $(($2 - 1)) -1 0); do
    "$T" tiles run "$1" "$k" 2>>err.txt || return 1
  done
}

# (a 257^2 fractal in 16 tiles of 64; decimation on 129^2 in 16 tiles of
# 32: under ASan a decimation runs ten times slower than in Release)
"$T" generate diamond_square ds.tif -size 257 -seed 7 -q || exit 1
"$T" generate diamond_square d129.tif -size 129 -seed 7 -q || exit 1
run tiles plan ds.tif p.json -max_error 6 -tile_size 64 -criterion delaunay
check "plan: exit 0" [ $rc -eq 0 ]
check "plan: 16 tiles" grep -q '"tiles": 16,' p.json
check "plan: the pieces' folder" [ -d p.json.tiles ]
: >err.txt
check "run: every tile" all_tiles p.json 16
check "run: 16 pieces" [ "$(ls p.json.tiles | grep -c '^[0-9]*\.ttp$')" -eq 16 ]
check "run: nothing else in the folder" [ "$(ls -A p.json.tiles | wc -l)" -eq 16 ]
run tiles merge p.json m.gpkg -q
check "merge: exit 0" [ $rc -eq 0 ]
run simplify -q -max_error 6 -tile_size 64 -criterion delaunay -threads 2 ds.tif s.gpkg
check "merge = simplify -tile_size (layers)" eval '[ -s m.gpkg ] && [ "$(dump m.gpkg)" = "$(dump s.gpkg)" ]'
nv=$(ogrinfo -ro -so m.gpkg vertices 2>/dev/null | sed -n 's/Feature Count: //p')
echo "fractal 257, tiles of 64: merged vertices $nv"

# decimation: the plan carries -method decimate and its options
run tiles plan d129.tif d.json -max_error 6 -tile_size 32 -method decimate -importance drop
check "plan, decimate: exit 0" [ $rc -eq 0 ]
: >err.txt
check "run, decimate: every tile" all_tiles d.json 16
run tiles merge d.json dm.gpkg -q
check "merge, decimate: exit 0" [ $rc -eq 0 ]
run simplify -q -max_error 6 -tile_size 32 -method decimate -importance drop -threads 2 d129.tif ds.gpkg
check "merge = simplify -tile_size -method decimate (layers)" [ -s dm.gpkg ] && [ "$(dump dm.gpkg)" = "$(dump ds.gpkg)" ]

# refusals
run tiles run p.json 16
check "run: tile out of range refused" eval '[ $rc -eq 2 ] && one_line "no tile 16"'
run tiles run p.json 3
check "run: existing piece refused" eval '[ $rc -eq 1 ] && one_line "exists"'
run tiles merge p.json m.gpkg
check "merge: existing output refused" eval '[ $rc -eq 1 ] && one_line "exists"'
run tiles plan ds.tif p.json -max_error 6 -tile_size 64
check "plan: existing plan refused" eval '[ $rc -eq 1 ] && one_line "exists"'
run tiles plan ds.tif q.json -tile_size 64
check "plan: no -max_error refused" eval '[ $rc -eq 2 ] && one_line "max_error" && [ ! -e q.json ]'
run tiles plan ds.tif q.json -max_error 6 -tile_size 64 -max_points 100
check "plan: a budget refused" eval '[ $rc -eq 2 ] && [ ! -e q.json ]'
run tiles plan nothere.tif q.json -max_error 6 -tile_size 64
check "plan: a missing DEM refused" eval '[ $rc -ne 0 ] && one_line "nothere.tif" && [ ! -e q.json ]'
mv p.json.tiles/5.ttp five.ttp
run tiles merge p.json m2.gpkg
check "merge: missing piece refused" eval '[ $rc -eq 1 ] && one_line "1 of 16 tile pieces missing" && [ ! -e m2.gpkg ]'
cp p.json.tiles/6.ttp p.json.tiles/5.ttp
run tiles merge p.json m2.gpkg
check "merge: stale piece refused" eval '[ $rc -eq 1 ] && one_line "stale" && [ ! -e m2.gpkg ]'
head -c 1000 five.ttp >p.json.tiles/5.ttp
run tiles merge p.json m2.gpkg
check "merge: damaged piece refused" eval '[ $rc -eq 1 ] && one_line "checksum\|not a terratin\|short" && [ ! -e m2.gpkg ]'
mv five.ttp p.json.tiles/5.ttp
check "merge: no stray file" [ "$(ls -A | grep -c 'm2\|tmp')" -eq 0 ]
run tiles run p.json 3 -overwrite
check "run -overwrite: exit 0" [ $rc -eq 0 ]
run tiles merge p.json m.gpkg -overwrite -q
check "merge -overwrite: the same layers" eval '[ $rc -eq 0 ] && [ "$(dump m.gpkg)" = "$(dump s.gpkg)" ]'
touch -d '2001-01-01' ds.tif
run tiles run p.json 3 -overwrite
check "run: changed DEM refused" eval '[ $rc -eq 1 ] && one_line "changed since"'
run tiles merge p.json m3.gpkg
check "merge: changed DEM refused" eval '[ $rc -eq 1 ] && one_line "changed since" && [ ! -e m3.gpkg ]'
run tiles
check "tiles alone: usage" [ $rc -eq 2 ]

# nodata across the tile borders
gdal_calc.py -A ds.tif --outfile=nd.tif --calc="where((A>20)*(A<40),-9999,A)" --NoDataValue=-9999 --type=Float32 --quiet >/dev/null 2>&1 || fail "gdal_calc"
vp=$(gdalinfo -stats nd.tif 2>/dev/null | sed -n 's/.*STATISTICS_VALID_PERCENT=//p')
rm -f nd.tif.aux.xml
echo "nodata DEM: $vp % valid"
check "nodata: some samples are nodata" python3 -c 'import sys; sys.exit(0 if 20 < float(sys.argv[1]) < 99 else 1)' "$vp"
run tiles plan nd.tif n.json -max_error 5 -tile_size 50
: >err.txt
check "nodata: every tile" all_tiles n.json "$(sed -n 's/^  "tiles": \([0-9]*\),/\1/p' n.json)"
run tiles merge n.json nm.gpkg -q
run simplify -q -max_error 5 -tile_size 50 nd.tif ns.gpkg
check "nodata: merge = simplify -tile_size" eval '[ -s nm.gpkg ] && [ "$(dump nm.gpkg)" = "$(dump ns.gpkg)" ]'

# an interrupted tile leaves no piece and no temporary file
"$T" generate diamond_square big.tif -size 2049 -seed 2 -q || exit 1
run tiles plan big.tif b.json -max_error 0 -tile_size 2048
"$T" tiles run b.json 0 >/dev/null 2>err.txt &
pid=$!
sleep 1
kill -TERM $pid
wait $pid
rc=$?
if [ $rc -eq 0 ]; then
  echo "note: the tile finished before the interruption; not checked"
else
  check "interrupted run: nothing in the pieces' folder" [ -z "$(ls -A b.json.tiles)" ]
fi

echo "$passed passed, $failed failed"
[ $failed -eq 0 ]
