#!/usr/bin/env bash
# test_decimate_cli.sh -- `terratin simplify -method decimate` end to end:
# a run on a generated fault terrain holds its bound by `terratin eval`
# (an independent measure), writes the importance field with NULL ins_err
# and ins_rank, records the method and the decimation's parameters in
# run_parameters and in -json; every importance, selection and hole rule
# runs; decimation-only options without -method decimate and bad values are
# usage errors (exit 2, one line). Exits 1 on a failure, 77 when a tool is
# missing.
set -u
. "$(dirname "${BASH_SOURCE[0]}")/tt_python.sh"

T=${TT_TERRATIN:-}
if [ -z "$T" ] || [ ! -x "$T" ]; then
  echo "SKIP: TT_TERRATIN is not set or not executable"
  exit 77
fi
for tool in ogrinfo python3; do
  command -v "$tool" >/dev/null 2>&1 || { echo "SKIP: $tool is missing"; exit 77; }
done
W=$(mktemp -d "${TMPDIR:-/tmp}/tt_dec.XXXXXX") || exit 1
trap 'rm -rf "$W"' EXIT
cd "$W" || exit 1
passed=0
failed=0
pass() { passed=$((passed + 1)); }
fail() { failed=$((failed + 1)); echo "FAIL: $*" >&2; }

"$T" generate fault -size 60x50 -seed 3 dem.tif -q || { echo "FAIL: generate"; exit 1; }

# a run, its bound by eval, its JSON
"$T" simplify -method decimate -start greedy -max_error 4 -json dem.tif a.gpkg > a.json 2> a.err
if [ $? -eq 0 ]; then pass; else fail "decimate run: $(cat a.err)"; fi
python3 - a.json <<'PY' && pass || fail "decimate JSON"
import json, sys
d = json.load(open(sys.argv[1]))
assert d["method"] == "decimate", d["method"]
x = d["decimation"]
assert x["start"] == "greedy" and x["importance"] == "error", x
assert x["selection"] == "independent" and x["hole"] == "circumradius", x
assert x["removed_vertices"] == x["start_vertices"] - d["vertices"], x
assert x["rounds"] > 0 and d["max_error"] <= 4, d
PY
"$T" eval -max_error 4 -q dem.tif a.gpkg && pass || fail "eval: bound broken"
ogrinfo -q -al -fid 1 a.gpkg vertices > v.txt 2>&1
grep -q "importance (Real)" v.txt && grep -q "ins_rank (Integer64) = (null)" v.txt &&
  grep -q "ins_err (Real) = (null)" v.txt && pass || fail "vertices layer: $(cat v.txt)"
ogrinfo -q -al a.gpkg run_parameters > p.txt 2>&1
grep -q "method (String) = decimate" p.txt && grep -q "start (String) = greedy" p.txt &&
  grep -q "hole (String) = circumradius" p.txt && grep -q "rounds (Integer" p.txt &&
  pass || fail "run_parameters: $(cat p.txt)"
# insertion keeps its layers, with method = insert
"$T" simplify -max_error 4 -q dem.tif b.gpkg && ogrinfo -q -al b.gpkg run_parameters |
  grep -q "method (String) = insert" && ! ogrinfo -q -al -fid 1 b.gpkg vertices |
  grep -q importance && pass || fail "insert run_parameters/vertices"

# every importance, selection, hole rule; exact counts
n=0
for imp in degree hdh abh volume drop error; do
  for sel in "-selection independent" "-selection independent -onepass" "-selection sequential"; do
    n=$((n + 1))
    "$T" simplify -q -method decimate -importance $imp $sel -max_points 300 -json \
      dem.tif r$n.gpkg > r$n.json 2> r$n.err &&
      python3 -c "import json,sys; d=json.load(open('r$n.json')); sys.exit(d['vertices'] != 300)" &&
      pass || fail "-importance $imp $sel: $(cat r$n.err)"
  done
done
for hole in minangle circumradius dp; do
  "$T" simplify -q -method decimate -hole $hole -criterion minmax_angle -start greedy:800 \
    -percent 5 dem.tif h$hole.gpkg && pass || fail "-hole $hole"
done

# usage errors: exit 2, one line
usage() {
  local what=$1
  shift
  "$T" "$@" > u.out 2> u.err
  local rc=$?
  if [ $rc -eq 2 ] && [ "$(wc -l < u.err)" -eq 1 ]; then pass; else
    fail "$what: rc $rc, stderr $(cat u.err)"; fi
}
usage "importance without decimate" simplify -importance hdh dem.tif u.gpkg
usage "onepass without decimate" simplify -onepass dem.tif u.gpkg
usage "bad method" simplify -method melt dem.tif u.gpkg
usage "bad start" simplify -method decimate -start greedy:x dem.tif u.gpkg
usage "bad importance" simplify -method decimate -importance size dem.tif u.gpkg
usage "onepass sequential" simplify -method decimate -onepass -selection sequential dem.tif u.gpkg
usage "max_memory with decimate" simplify -method decimate -percent 5 -max_memory 1G dem.tif u.gpkg
usage "dp for l2" simplify -method decimate -hole dp -criterion l2 dem.tif u.gpkg
[ ! -e u.gpkg ] && pass || fail "a usage error left u.gpkg"

echo "$passed passed, $failed failed"
[ $failed -eq 0 ]
