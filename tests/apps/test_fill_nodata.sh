#!/usr/bin/env bash
# test_fill_nodata.sh -- simplify -fill_nodata K ($TT_TERRATIN, issue 29) on
# a 120 x 100 ESRI ASCII grid written here: a smooth surface with four
# small voids (1, 6, 5 and 10 samples, the last crossing the border of
# tiles of 40 at row 40), a lake of 441 samples and a 2-sample void on the
# left edge. -fill_nodata 10 fills the 22 samples of the four voids
# (summary note, -json counts), the lake and the edge void stay holes (no
# vertex in them); the TIN is within the bound of the filled DEM (eval
# -fill_nodata: every valid sample covered); whole and tiled (streamed
# GeoPackage, a merged Shapefile, 2 threads), inserted and decimated,
# count the same and, at -max_error 0, give the filled samples the same
# heights; bad values, and a K above a quarter of the tile size, are
# refused in one line. Prints "N passed, M failed"; exits 1 on any
# failure, 77 when a tool is missing.
set -u
. "$(dirname "${BASH_SOURCE[0]}")/../apps/tt_check.sh" || exit 1

T=${TT_TERRATIN:-}
if [ -z "$T" ] || [ ! -x "$T" ]; then
  echo "SKIP: TT_TERRATIN is not set or not executable"
  exit 77
fi
for tool in ogrinfo ogr2ogr python3; do
  if ! command -v $tool >/dev/null 2>&1; then
    echo "SKIP: $tool is missing"
    exit 77
  fi
done
W=$(mktemp -d "${TMPDIR:-/tmp}/tt_fill.XXXXXX") || exit 1
trap 'rm -rf "$W"' EXIT
cd "$W" || exit 1
not() { ! "$@"; }

python3 - <<'EOF'
import math
nx, ny = 120, 100
voids = {(10, 10)}
voids |= {(c, r) for c in range(30, 33) for r in range(20, 22)}
voids |= {(50, 70), (51, 70), (52, 70), (52, 71), (52, 72)}
voids |= {(c, r) for c in range(62, 67) for r in range(40, 42)}
voids |= {(c, r) for r in range(ny) for c in range(nx)
          if (c - 90) ** 2 + (r - 70) ** 2 <= 144}
voids |= {(0, 50), (0, 51)}
with open('dem.asc', 'w') as f:
    f.write('ncols %d\nnrows %d\nxllcorner 0\nyllcorner 0\ncellsize 10\n'
            'NODATA_value -9999\n' % (nx, ny))
    for r in range(ny):
        f.write(' '.join('-9999' if (c, r) in voids else '%.3f' % (
            100 + 20 * math.sin(c / 9.0) + 15 * math.cos(r / 7.0) +
            0.005 * c * r) for c in range(nx)) + '\n')
EOF

field() { python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))[sys.argv[2]])' "$1" "$2"; }
# Vertices whose (col, row) satisfy an SQL condition.
count_where() {
  ogrinfo -q -sql "SELECT COUNT(*) AS n FROM vertices WHERE $2" "$1" |
    sed -n 's/.*n (Integer) = //p'
}
# The vertices "col row z" of a layer (any format), one a line.
heights() {
  ogr2ogr -f CSV -lco GEOMETRY=AS_WKT /vsistdout/ "$1" "$2" 2>/dev/null |
    python3 -c '
import csv, sys
for r in csv.DictReader(sys.stdin):
    print(r["col"], r["row"], r["WKT"].split()[-1].rstrip(")"))'
}
# Whether two "col row z" lists give the samples of the small voids that
# both hold (at least 15) the same heights.
same_filled() {
  python3 - "$1" "$2" <<'PY'
import sys
small = {(10, 10), (50, 70), (51, 70), (52, 70), (52, 71), (52, 72)}
small |= {(c, r) for c in range(30, 33) for r in range(20, 22)}
small |= {(c, r) for c in range(62, 67) for r in range(40, 42)}
def load(p):
    d = {}
    for line in open(p):
        c, r, z = line.split()
        if (int(c), int(r)) in small:
            d[(int(c), int(r))] = z
    return d
a, b = load(sys.argv[1]), load(sys.argv[2])
common = set(a) & set(b)
sys.exit(0 if len(common) >= 15 and all(a[k] == b[k] for k in common) else 1)
PY
}
SMALL="(col = 10 AND row = 10) OR (col BETWEEN 30 AND 32 AND row BETWEEN 20 AND 21) OR (row = 70 AND col BETWEEN 50 AND 52) OR (col = 52 AND row BETWEEN 71 AND 72) OR (col BETWEEN 62 AND 66 AND row BETWEEN 40 AND 41)"
LAKE="(col - 90) * (col - 90) + (row - 70) * (row - 70) <= 144"
EDGE="col = 0 AND row BETWEEN 50 AND 51"

# --- whole, inserted: counts, the note, holes kept, the bound -------------
"$T" simplify -q -max_error 0.5 dem.asc plain.gpkg -json >plain.json
"$T" simplify -max_error 0.5 -fill_nodata 10 dem.asc whole.gpkg \
  >whole.txt 2>&1
"$T" simplify -q -max_error 0.5 -fill_nodata 10 dem.asc whole.gpkg \
  -overwrite -json >whole.json
check "the summary's note" \
  grep -q "^note:   22 nodata samples in 4 voids filled (-fill_nodata 10); the bound holds on the filled grid" whole.txt
check "-json filled_samples" [ "$(field whole.json filled_samples)" = 22 ]
check "-json filled_voids" [ "$(field whole.json filled_voids)" = 4 ]
check "-json fill_nodata" [ "$(field whole.json fill_nodata)" = 10 ]
check "without -fill_nodata: null, none filled" \
  [ "$(field plain.json fill_nodata)" = None -a "$(field plain.json filled_samples)" = 0 ]
check "the valid samples gain the filled ones" \
  [ "$(field whole.json valid_samples)" = $(($(field plain.json valid_samples) + 22)) ]
check "no vertex in the lake" [ "$(count_where whole.gpkg "$LAKE")" = 0 ]
check "no vertex in the edge void" [ "$(count_where whole.gpkg "$EDGE")" = 0 ]
check "without -fill_nodata no vertex in the small voids" \
  [ "$(count_where plain.gpkg "$SMALL")" = 0 ]
"$T" eval -fill_nodata 10 -max_error 0.5 -json dem.asc whole.gpkg >eval.json
check "eval against the filled DEM: within the bound" \
  [ "$(field eval.json pass)" = True ]
check "eval: every sample of the filled DEM covered" \
  [ "$(field eval.json covered)" = "$(field whole.json valid_samples)" ]
"$T" eval -json dem.asc whole.gpkg >eval0.json
check "eval of the DEM as it is: the voids are not its samples" \
  [ "$(field eval0.json valid_samples)" = "$(field plain.json valid_samples)" ]
# a patch above K stays a hole: -fill_nodata 9 leaves the 10-sample bar
"$T" simplify -q -max_error 0.5 -fill_nodata 9 dem.asc k9.gpkg -json >k9.json
check "-fill_nodata 9: 12 samples in 3 voids" \
  [ "$(field k9.json filled_samples)" = 12 -a "$(field k9.json filled_voids)" = 3 ]
check "-fill_nodata 9: no vertex in the bar" \
  [ "$(count_where k9.gpkg "col BETWEEN 62 AND 66 AND row BETWEEN 40 AND 41")" = 0 ]

# --- tiled and decimated: the same counts, the same filled heights --------
"$T" simplify -q -max_error 0 -fill_nodata 10 dem.asc exact.gpkg
heights exact.gpkg vertices >exact.txt
check "at -max_error 0 the filled samples are vertices" \
  [ "$(count_where exact.gpkg "$SMALL")" -gt 15 ]
i=0
for run in "-tile_size 40" "-tile_size 40 -threads 2" \
           "-tile_size 40 -of ESRI_Shapefile" "-method decimate" \
           "-method decimate -tile_size 40"; do
  i=$((i + 1))
  out=t$i.gpkg
  if [[ $run == *Shapefile* ]]; then
    out=t${i}_triangles.shp
    "$T" simplify -q -max_error 0.5 -fill_nodata 10 -tile_size 40 \
      -of "ESRI Shapefile" dem.asc t$i -json >t$i.json
  else
    # shellcheck disable=SC2086
    "$T" simplify -q -max_error 0.5 -fill_nodata 10 $run dem.asc "$out" \
      -json >t$i.json
  fi
  check "$run: 22 samples in 4 voids" \
    [ "$(field t$i.json filled_samples)" = 22 -a "$(field t$i.json filled_voids)" = 4 ]
  "$T" eval -fill_nodata 10 -max_error 0.5 -json dem.asc "$out" >e$i.json
  check "$run: within the bound of the filled DEM, all covered" \
    [ "$(field e$i.json pass)" = True -a "$(field e$i.json covered)" = "$(field whole.json valid_samples)" ]
done
for run in "-tile_size 40" "-tile_size 40 -threads 2" "-method decimate -tile_size 40"; do
  # shellcheck disable=SC2086
  "$T" simplify -q -max_error 0 -fill_nodata 10 $run dem.asc x.gpkg -overwrite
  heights x.gpkg vertices >x.txt
  check "$run at -max_error 0: the filled heights of the whole run" \
    same_filled exact.txt x.txt
done

# --- refused in one line, nothing written ----------------------------------
for bad in 0 -1 x 1.5; do
  "$T" simplify -fill_nodata "$bad" dem.asc bad.gpkg 2>err.txt
  rc=$?
  check "-fill_nodata $bad: exit 2" [ $rc = 2 ]
  check "-fill_nodata $bad: one line" \
    grep -qx "terratin: simplify: -fill_nodata must be a number of samples from 1 to 2147483647, got '$bad'" err.txt
  check "-fill_nodata $bad: nothing written" not test -e bad.gpkg
done

"$T" simplify -q -fill_nodata 11 -tile_size 40 dem.asc bad.gpkg 2>err.txt
rc=$?
check "-fill_nodata 11 in tiles of 40: exit 2" [ $rc = 2 ]
check "-fill_nodata 11 in tiles of 40: one line" \
  grep -qx "terratin: -fill_nodata: 11 in tiles of 40: a tile reads a margin of 24 samples for it; at most 10 (a quarter of the tile size) in a tiled run, or larger tiles (-tile_size)" err.txt
check "-fill_nodata 11 in tiles of 40: nothing written" not test -e bad.gpkg

echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
