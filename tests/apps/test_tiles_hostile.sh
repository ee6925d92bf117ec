#!/usr/bin/env bash
# test_tiles_hostile.sh -- a tile plan is input, not trusted code: `tiles
# run` and `tiles merge` ($TT_TERRATIN) read PLAN.json as a file anyone
# could have written, and refuse, with one line naming the option or field,
# exit 2 and nothing written (no piece, no output, no file named by the
# plan): --config (CPL_LOG would write any file), --debug, output names and
# options (-of, -nln), budgets, a positional word injected among the
# options, ../ and absolute names (-work_srs takes AUTHORITY:CODE only), a
# 10 MB option word, too many words, 2^64-1 tiles, a tile count or a size
# that is not the DEM's, a tile size out of range, a non-canonical DEM
# path, a truncated plan, a bad checksum, a tile list edited under a
# recomputed checksum, a version 1 plan, an empty file. `tiles plan`
# refuses the same options before it writes anything; `tiles merge` takes
# the output options on its own command line. The plans are edited by a
# forger that recomputes the closing checksum (FNV-1a 64) unless told not
# to, so each check reaches the field it is about. Prints "N passed, M
# failed"; exits 1 on any failure, 77 when a tool is missing.
set -u
. "$(dirname "${BASH_SOURCE[0]}")/../apps/tt_check.sh" || exit 1

T=${TT_TERRATIN:-}
if [ -z "$T" ] || [ ! -x "$T" ]; then
  echo "SKIP: TT_TERRATIN is not set or not executable"
  exit 77
fi
for tool in python3 sqlite3; do
  if ! command -v "$tool" >/dev/null 2>&1; then
    echo "SKIP: $tool is missing"
    exit 77
  fi
done

W=$(mktemp -d "${TMPDIR:-/tmp}/tt_hostile.XXXXXX") || exit 1
trap 'rm -rf "$W"' EXIT
cd "$W" || exit 1
W=$(pwd -P)

rc=0
run() {
  "$T" "$@" >out.txt 2>err.txt
  rc=$?
}
one_line() { [ "$(wc -l <err.txt)" -eq 1 ] && grep -q -- "$1" err.txt; }
dump() {
  sqlite3 -readonly "$1" "select hex(sha3_query('select * from triangles order by rowid; select * from vertices order by rowid'))" 2>&1 ||
    echo "error: $1"
}

# forge OUT EDIT [keep]: p.json's text before its checksum line, edited by
# the Python statements EDIT (on the str `body`), written to OUT with the
# checksum of the edited text (with "keep": the old checksum line)
forge() {
  python3 - "$1" "$2" "${3:-}" <<'PY'
import sys
out, edit, keep = sys.argv[1:4]
text = open("p.json").read()
cut = text.rindex('  "checksum": ')
body, tail = text[:cut], text[cut:]
exec(edit)
def fnv(b):
    h = 14695981039346656037
    for c in b:
        h = ((h ^ c) * 1099511628211) & 0xFFFFFFFFFFFFFFFF
    return h
if not keep:
    tail = '  "checksum": "fnv1a64:%016x"\n}\n' % fnv(body.encode())
open(out, "w").write(body + tail)
PY
}
# opts PYLIST: the "options" line replaced by the words of the Python list
opts() {
  printf '%s' "import json, re
body = re.sub(r'  \"options\": \[.*\],\n', lambda m: '  \"options\": [' + ', '.join(json.dumps(w) for w in $1) + '],\n', body)"
}

# refused NAME PLAN PATTERN: run (tile 0) and merge both exit 2 with one
# line matching PATTERN, and write nothing: no piece, no output, no
# pwned file
refused() {
  local name=$1 plan=$2 pat=$3
  mkdir -p "$plan.tiles"
  run tiles run "$plan" 0
  check "$name: run exit 2, one line ($rc: $(cat err.txt))" eval '[ $rc -eq 2 ] && one_line "$pat"'
  run tiles merge "$plan" m.gpkg
  check "$name: merge exit 2, one line ($rc: $(cat err.txt))" eval '[ $rc -eq 2 ] && one_line "$pat"'
  check "$name: nothing written ($(ls -A "$plan.tiles" pwned* m.gpkg 2>/dev/null | tr '\n' ' '))" \
    eval '[ -z "$(ls -A "$plan.tiles")" ] && [ ! -e m.gpkg ] && ! ls pwned* >/dev/null 2>&1'
}

"$T" generate diamond_square ds.tif -size 129 -seed 7 -q || exit 1
run tiles plan ds.tif p.json -max_error 6 -tile_size 64 -criterion delaunay -q
check "plan: exit 0 ($(cat err.txt))" [ $rc -eq 0 ]
check "plan: closes with its checksum" grep -q '^  "checksum": "fnv1a64:[0-9a-f]\{16\}"$' p.json
check "plan: JSON (as tt_dask.py reads it): 4 tiles" \
  python3 -c 'import json, sys; sys.exit(0 if json.load(open("p.json"))["tiles"] == 4 else 1)'
G="[\"-max_error\", \"6\", \"-tile_size\", \"64\""

# --- options a plan never carries ---
forge h_config.json "$(opts "$G, \"--config\", \"CPL_LOG\", \"$W/pwned.log\", \"--debug\", \"on\"]")"
refused "--config CPL_LOG" h_config.json "h_config.json: --config is not an option a plan may carry"
forge h_debug.json "$(opts "[\"--debug\", \"on\"] + $G]")"
refused "--debug" h_debug.json "--debug is not an option a plan may carry"
forge h_of.json "$(opts "$G, \"-of\", \"GeoJSON\"]")"
refused "-of" h_of.json "-of is an option of the output.*tiles merge"
forge h_nln.json "$(opts "$G, \"-nln\", \"../../pwned\"]")"
refused "-nln ../../pwned" h_nln.json "-nln is an option of the output"
forge h_lco.json "$(opts "$G, \"-lco\", \"TEMPORARY_DIR=/tmp\"]")"
refused "-lco naming a path" h_lco.json "-lco is an option of the output"
forge h_budget.json "$(opts "$G, \"-max_points\", \"100\"]")"
refused "a budget" h_budget.json "-max_points is a budget"
forge h_threads.json "$(opts "$G, \"-threads\", \"1024\"]")"
refused "-threads" h_threads.json "-threads is not an option a plan may carry"
# a positional word among the options would become simplify's INPUT or
# OUTPUT: an output name the plan chose
forge h_pos.json "$(opts "$G, \"$W/pwned.gpkg\"]")"
refused "an injected positional word" h_pos.json "'$W/pwned.gpkg' is not an option"
forge h_pos2.json "$(opts "$G, \"-criterion\", \"delaunay\", \"ds.tif\", \"pwned.gpkg\", \"-nln\"]")"
refused "injected positional words" h_pos2.json "'ds.tif' is not an option"
forge h_novalue.json "$(opts "$G, \"-criterion\"]")"
refused "an option without its value" h_novalue.json "option -criterion needs a value"
forge h_srs_rel.json "$(opts "$G, \"-work_srs\", \"../crs.prj\"]")"
refused "-work_srs ../crs.prj" h_srs_rel.json "-work_srs '../crs.prj': a plan takes a CRS as AUTHORITY:CODE only"
forge h_srs_abs.json "$(opts "$G, \"-work_srs\", \"/etc/passwd\"]")"
refused "-work_srs /etc/passwd" h_srs_abs.json "AUTHORITY:CODE only"
forge h_srs_url.json "$(opts "$G, \"-work_srs\", \"http://127.0.0.1:9/crs\"]")"
refused "-work_srs URL" h_srs_url.json "AUTHORITY:CODE only"
forge h_crit.json "$(opts "$G, \"-criterion\", \"../../etc\"]")"
refused "a ../ name as a criterion" h_crit.json "h_crit.json: its options: simplify: unknown -criterion"
forge h_big.json "$(opts "$G, \"-criterion\", \"d\" * 10485760]")"
check "a 10 MB option word: the plan is over 10 MB" [ "$(stat -c %s h_big.json)" -gt 10485760 ]
refused "a 10 MB option word" h_big.json "an option word of 10485760 bytes (at most 256 in a plan)"
forge h_many.json "$(opts "$G] + [\"-onepass\"] * 70")"
refused "70 option words" h_many.json "more than 64 option words (the most"
forge h_ctl.json "$(opts "$G, \"-criterion\", \"dela\\nunay\"]")"
refused "a control character" h_ctl.json "control character\|malformed"

# --- fields that are not the DEM's ---
forge h_tiles.json "body = body.replace('\"tiles\": 4,', '\"tiles\": 18446744073709551615,')"
SECONDS=0
refused "2^64-1 tiles" h_tiles.json '"tiles" 18446744073709551615 (2 x 2) is not the 4 (2 x 2) tiles'
check "2^64-1 tiles: refused at once ($SECONDS s)" [ $SECONDS -lt 20 ]
forge h_tiles5.json "body = body.replace('\"tiles\": 4,', '\"tiles\": 5,')"
refused "5 tiles for 4" h_tiles5.json '"tiles" 5 (2 x 2) is not the 4'
forge h_tiles_big.json "body = body.replace('\"tiles\": 4,', '\"tiles\": 99999999999999999999999,')"
refused "a tile count past 2^64" h_tiles_big.json '"tiles" is missing or malformed'
# width, tiles_x and tiles agree with one another, not with the DEM
forge h_width.json "body = body.replace('\"width\": 129,', '\"width\": 513,').replace('\"tiles_x\": 2,', '\"tiles_x\": 8,').replace('\"tiles\": 4,', '\"tiles\": 16,')"
refused "a width that is not the DEM's" h_width.json '"width" and "height" are 513 x 129, its DEM .* is 129 x 129'
forge h_ts.json "body = body.replace('\"tile_size\": 64,', '\"tile_size\": 1,')"
refused "tile size 1" h_ts.json '"tile_size" 1 (16 to 65536)'
forge h_ts2.json "body = body.replace('\"tile_size\": 64,', '\"tile_size\": 128,').replace('\"tiles_x\": 2,', '\"tiles_x\": 1,').replace('\"tiles_y\": 2,', '\"tiles_y\": 1,').replace('\"tiles\": 4,', '\"tiles\": 1,')"
refused "tile_size not the options' -tile_size" h_ts2.json "its options' -tile_size 64 is not its \"tile_size\" 128"
forge h_dem.json "body = body.replace('\"dem\": \"$W/', '\"dem\": \"$W/../$(basename "$W")/')"
refused "a non-canonical DEM path" h_dem.json "is not a canonical path"
forge h_demrel.json "body = body.replace('\"dem\": \"$W/', '\"dem\": \"')"
refused "a relative DEM path" h_demrel.json '"dem" is missing or malformed'
mkdir -p dir.tif
forge h_demdir.json "body = body.replace('\"dem\": \"$W/ds.tif', '\"dem\": \"$W/dir.tif')"
refused "a folder as the DEM" h_demdir.json "is not a file"

# --- the plan's text: whole, unedited, of this version ---
head -c 400 p.json >h_trunc.json
refused "a truncated plan" h_trunc.json "truncated or damaged"
head -n 12 p.json >h_trunc2.json
refused "a plan cut after its header keys" h_trunc2.json "truncated or damaged"
forge h_sum.json "body = body.replace('\"window\": [0, 0, 66, 66]', '\"window\": [0, 0, 99, 66]')" keep
refused "a bad checksum" h_sum.json "checksum mismatch"
forge h_list.json "body = body.replace('\"window\": [0, 0, 66, 66]', '\"window\": [0, 0, 99, 66]')"
refused "a tile list edited under a new checksum" h_list.json "line 14 is not what \`terratin tiles plan\` writes"
forge h_extra.json "body = body.replace('  \"tile_list\"', '  \"dem2\": 1,\n  \"tile_list\"')"
refused "an extra key" h_extra.json '"tile_list" is missing or malformed'
forge h_v1.json "body = body.replace('\"terratin_tiles_plan\": 2', '\"terratin_tiles_plan\": 1')"
refused "a version 1 plan" h_v1.json "version 1, without a checksum"
: >h_empty.json
refused "an empty file" h_empty.json "not a plan of"

# --- tiles plan refuses the same before writing anything ---
run tiles plan ds.tif q.json -max_error 6 -tile_size 64 --config CPL_LOG "$W/pwned.log"
check "plan --config: exit 2, nothing written ($(cat err.txt))" \
  eval '[ $rc -eq 2 ] && one_line "tiles plan: --config is not an option a plan may carry" && [ ! -e q.json ] && [ ! -e q.json.tiles ] && ! ls pwned* >/dev/null 2>&1'
run tiles plan ds.tif q.json -max_error 6 -tile_size 64 -of GeoJSON
check "plan -of: exit 2, merge named ($(cat err.txt))" eval '[ $rc -eq 2 ] && one_line "tiles merge" && [ ! -e q.json ]'
run tiles plan ds.tif q.json -max_error 6 -tile_size 64 -work_srs /etc/passwd
check "plan -work_srs PATH: exit 2 ($(cat err.txt))" eval '[ $rc -eq 2 ] && one_line "AUTHORITY:CODE" && [ ! -e q.json ]'
run tiles plan ds.tif q.json -max_error 6 -tile_size 64 -criterion "$(head -c 300 /dev/zero | tr '\0' d)"
check "plan, a 300-byte word: exit 2 ($(cat err.txt))" eval '[ $rc -eq 2 ] && one_line "an option word of 300 bytes" && [ ! -e q.json ]'

# --- the good plan still runs, and merge takes the output's options ---
for k in 0 1 2 3; do "$T" tiles run p.json $k 2>>err.txt; done
run tiles merge p.json m.gpkg -q
check "good plan: merge exit 0 ($(cat err.txt))" [ $rc -eq 0 ]
run simplify -q -max_error 6 -tile_size 64 -criterion delaunay ds.tif s.gpkg
check "good plan: merge = simplify -tile_size" eval '[ -s m.gpkg ] && [ "$(dump m.gpkg)" = "$(dump s.gpkg)" ]'
run tiles merge p.json n.gpkg -q -nln pre_
check "merge -nln pre_: exit 0 ($(cat err.txt))" [ $rc -eq 0 ]
check "merge -nln pre_: the layers named by the merge's line" \
  eval '[ "$(sqlite3 n.gpkg "select count(*) from gpkg_contents where table_name = '"'"'pre_triangles'"'"'")" = 1 ]'
run tiles merge p.json n2.gpkg -nln
check "merge -nln without its value: exit 2 ($(cat err.txt))" eval '[ $rc -eq 2 ] && one_line "option -nln needs a value"'

echo "$passed passed, $failed failed"
[ $failed -eq 0 ]
