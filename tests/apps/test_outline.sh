#!/usr/bin/env bash
# test_outline.sh -- the lean nodata outline (src/mesh/domain.c), through
# the terratin command ($TT_TERRATIN), on the adversarial patterns of
# outline_grids.py (straight coastlines of three slopes, a checkerboard,
# one-sample valid and nodata lines, lone samples, holes and notches on
# every side and corner, hundreds of random blobs):
#  - exactness: every sample of the old domain (a valid corner of a cell
#    with three or four valid corners) is covered and no nodata sample is
#    inside or on a triangle, checked exactly in python on the TIN's
#    triangles, for insertion, decimation from a greedy start, and tiles;
#  - the count: the coastlines force at most a third of the vertices the
#    old outline forced (56 at c5bf8c1, the cell-step outline);
#  - covered_samples in -json is the old domain's count;
#  - -min_patch 5 drops the 4-connected valid patches of fewer than 5
#    samples (the checkerboard's, the lone samples), counted in -json and
#    the summary as python counts them, and the TIN stays exact on the
#    grid without them; a tiled run refuses it.
# Prints "N passed, M failed"; exits 1 on any failure, 77 (skip) when a tool
# is missing.
set -u
. "$(dirname "${BASH_SOURCE[0]}")/../apps/tt_check.sh" || exit 1

T=${TT_TERRATIN:-}
if [ -z "$T" ] || [ ! -x "$T" ]; then
  echo "SKIP: TT_TERRATIN is not set or not executable"
  exit 77
fi
for tool in ogr2ogr python3; do
  if ! command -v "$tool" >/dev/null 2>&1; then
    echo "SKIP: $tool is missing"
    exit 77
  fi
done
G=$TT_APPS/outline_grids.py

W=$(mktemp -d "${TMPDIR:-/tmp}/tt_outline.XXXXXX") || exit 1
trap 'rm -rf "$W"' EXIT
cd "$W" || exit 1

jget() { # jget FILE KEY
  python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))[sys.argv[2]])' "$1" "$2"
}

# exact WHAT GRID TIN [MIN_PATCH]: the python check passes (its line is
# kept in chk.json)
exact() {
  python3 "$G" check "$2" "$3" ${4:-} >chk.json 2>chk.err
  local rc=$?
  check "$1: every domain sample covered, no nodata covered ($(cat chk.json chk.err))" \
    [ $rc -eq 0 ]
}

for p in coast checker border noise; do
  python3 "$G" make $p $p.asc 96 1
  "$T" simplify -q -json -max_error 1 $p.asc $p.gpkg >$p.json 2>err.txt
  rc=$?
  check "$p: insert exits 0 ($(cat err.txt))" [ $rc -eq 0 ]
  exact "$p, insert" $p.asc $p.gpkg
  check "$p: covered_samples is the old domain's ($(jget $p.json covered_samples))" \
    [ "$(jget $p.json covered_samples)" = "$(jget chk.json domain)" ]
  "$T" simplify -q -method decimate -start greedy -max_error 1 $p.asc \
    ${p}_dec.gpkg >/dev/null 2>err.txt
  rc=$?
  check "$p: decimate exits 0 ($(cat err.txt))" [ $rc -eq 0 ]
  exact "$p, decimate from greedy" $p.asc ${p}_dec.gpkg
done
for p in border noise; do
  "$T" simplify -q -max_error 1 -tile_size 32 $p.asc ${p}_t.gpkg 2>err.txt
  rc=$?
  check "$p: tiles of 32 exit 0 ($(cat err.txt))" [ $rc -eq 0 ]
  exact "$p, tiles of 32" $p.asc ${p}_t.gpkg
done

forced=$(jget coast.json forced_vertices)
check "coast: at most 18 forced vertices (a third of the old 56), got $forced" \
  [ "$forced" -le 18 ]

# a larger noise grid: hundreds of patches, a 15 % budget (5 % is below the forced vertices)
python3 "$G" make noise big.asc 200 7
"$T" simplify -q -json -percent 15 big.asc big.gpkg >big.json 2>err.txt
rc=$?
check "noise 200: exits 0 ($(cat err.txt))" [ $rc -eq 0 ]
exact "noise 200, -percent 15" big.asc big.gpkg

# -min_patch
"$T" simplify -q -json -max_error 1 -min_patch 5 checker.asc mp.gpkg >mp.json 2>err.txt
rc=$?
check "-min_patch 5: exits 0 ($(cat err.txt))" [ $rc -eq 0 ]
exact "-min_patch 5" checker.asc mp.gpkg 5
mp() { python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["min_patch"][sys.argv[2]])' mp.json "$1"; }
check "-min_patch 5: dropped samples $(mp dropped_samples) = python's $(jget chk.json dropped_samples)" \
  [ "$(mp dropped_samples)" = "$(jget chk.json dropped_samples)" ]
check "-min_patch 5: dropped patches $(mp dropped_patches) = python's $(jget chk.json dropped_patches)" \
  [ "$(mp dropped_patches)" = "$(jget chk.json dropped_patches)" ]
check "-min_patch 5: some dropped" [ "$(mp dropped_samples)" -gt 300 ]
check "-min_patch 5: valid_samples less the dropped" \
  [ "$(jget mp.json valid_samples)" -eq $(($(jget chk.json valid))) ]
"$T" simplify -max_error 1 -min_patch 5 -overwrite checker.asc mp.gpkg >mp.txt 2>&1
check "-min_patch 5: the summary's note ($(grep min_patch mp.txt))" \
  grep -q "^note:   $(mp dropped_samples) valid samples in $(mp dropped_patches) patches of fewer than 5 samples dropped (-min_patch)" mp.txt
"$T" simplify -q -max_error 1 -min_patch 5 -tile_size 32 checker.asc mpt.gpkg 2>err.txt
rc=$?
check "-min_patch with tiles: refused, exit 2 ($rc: $(cat err.txt))" [ $rc -eq 2 ]
check "-min_patch with tiles: one line naming the option" \
  grep -q "^terratin: -min_patch: a tiled run" err.txt
check "-min_patch with tiles: nothing written" [ ! -e mpt.gpkg ]

echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
