#!/usr/bin/env bash
# test_study.sh -- end-to-end tests of `terratin study OUTDIR`
# ($TT_TERRATIN, issue 15) on tiny terrains:
#  - every row of curves.csv (a DEM file, and the generated 'bump' against
#    the same terrain written by `terratin generate`) has the numbers of a
#    single `terratin simplify -json -percent P` run with that method,
#    criterion and optimiser: points, max_error, l2, rmse, mean_abs_error,
#    total_abs_error, exactly;
#  - curves.csv parses with python3's csv, with exactly the issue's
#    columns and a row per run; tables.md has a table per terrain and
#    method, a row per percentage, the smallest mean absolute error of each
#    row in bold; runs.json parses and names the version;
#  - -points N: a row at every count up to N (insertion) or per round
#    (decimation), equal to single `simplify -max_points K` runs;
#  - a terrain that cannot be read, an existing non-empty OUTDIR, an
#    unknown criterion and edge insertion with another criterion fail with
#    one line and leave nothing behind; -overwrite writes into OUTDIR.
# Prints "N passed, M failed"; exits 1 on any failure, 77 when a tool is
# missing.
set -u
. "$(dirname "${BASH_SOURCE[0]}")/tt_python.sh"

T=${TT_TERRATIN:-}
if [ -z "$T" ] || [ ! -x "$T" ]; then
  echo "SKIP: TT_TERRATIN is not set or not executable"
  exit 77
fi
if ! command -v python3 >/dev/null 2>&1; then
  echo "SKIP: python3 is missing"
  exit 77
fi

W=$(mktemp -d "${TMPDIR:-/tmp}/tt_study.XXXXXX") || exit 1
trap 'rm -rf "$W"' EXIT
cd "$W" || exit 1

passed=0
failed=0
pass() { passed=$((passed + 1)); }
fail() { failed=$((failed + 1)); echo "FAIL: $*" >&2; }
rc=0
run() {
  "$T" "$@" >out.txt 2>err.txt
  rc=$?
}
lines() { wc -l <"$1" | tr -d ' '; }

# expect_failure NAME CODE NEEDLE OUTDIR ARGS...: exit code CODE, one
# stderr line containing NEEDLE, OUTDIR not created.
expect_failure() {
  local name=$1 code=$2 needle=$3 outdir=$4
  shift 4
  run "$@"
  if [ "$rc" -ne "$code" ]; then
    fail "$name: exit code $rc, expected $code ($(cat err.txt))"
    return
  fi
  if [ "$(lines err.txt)" -ne 1 ] || ! grep -q -- "$needle" err.txt; then
    fail "$name: stderr is not one line with '$needle': $(cat err.txt)"
    return
  fi
  if [ -e "$outdir" ]; then
    fail "$name: $outdir was created"
    return
  fi
  pass
}

"$T" generate fault tiny.tif -size 24x20 -seed 7 -q || exit 1
"$T" generate bump bump.tif -q || exit 1

# The study: a DEM and a generated terrain, both methods, two optimisers
# (none, and auto which is local for minmax_angle), three criteria.
CRITERIA=delaunay,minmax_angle,l2
PERCENTS=5,20,50
run study -q -terrain tiny.tif -terrain bump -criteria "$CRITERIA" \
  -methods insert,decimate -optimizers none,auto -percent "$PERCENTS" out
if [ "$rc" -eq 0 ] && [ -f out/curves.csv ] && [ -f out/tables.md ] &&
  [ -f out/runs.json ]; then
  pass
else
  fail "study run: rc $rc, $(cat err.txt)"
fi
if [ -z "$(ls -A out | grep -v -e '^curves.csv$' -e '^tables.md$' \
  -e '^runs.json$')" ]; then pass; else fail "stray files in out: $(ls -A out)"; fi

# The CSV: the columns, a row per run (2 terrains x 2 methods x 2
# optimisers x 3 percents x 3 criteria = 72).
if python3 - out/curves.csv <<'EOF'; then pass; else fail "curves.csv shape"; fi
import csv, sys
rows = list(csv.reader(open(sys.argv[1], newline="")))
want = ["terrain", "method", "criterion", "optimizer", "points", "max_error",
        "l2", "rmse", "mean_abs_error", "total_abs_error", "seconds"]
if rows[0] != want:
    sys.exit("header %r" % rows[0])
body = rows[1:]
if len(body) != 72:
    sys.exit("%d rows" % len(body))
for r in body:
    if len(r) != len(want):
        sys.exit("row %r" % r)
    int(r[4])
    [float(x) for x in r[5:]]
if {r[0] for r in body} != {"tiny.tif", "bump"}:
    sys.exit("terrains %r" % {r[0] for r in body})
if {r[3] for r in body} != {"none", "local"}:
    sys.exit("optimizers %r" % {r[3] for r in body})
EOF

# Each row against a single simplify run. The generated 'bump' is the
# terrain `terratin generate bump` writes. (The runs write a 2DM mesh: the
# JSON summary does not depend on the format, and a GeoPackage takes 60 %
# longer to make than the whole run of a 24 x 20 terrain.)
python3 - out/curves.csv >cases.txt <<'EOF'
import csv, sys
for r in csv.DictReader(open(sys.argv[1], newline="")):
    print(r["terrain"], r["method"], r["criterion"], r["optimizer"],
          r["points"], r["max_error"], r["l2"], r["rmse"],
          r["mean_abs_error"], r["total_abs_error"])
EOF
# The percentages, in the order of the rows: per (terrain, method,
# optimiser) block, each percent for every criterion.
mismatch=0
checked=0
i=0
while read -r terr meth crit opt points mx l2 rmse mae tae; do
  ncrit=3
  npct=3
  k=$(((i / ncrit) % npct))
  pct=$(echo "$PERCENTS" | cut -d, -f$((k + 1)))
  i=$((i + 1))
  dem=$terr
  [ "$terr" = bump ] && dem=bump.tif
  "$T" simplify "$dem" one.2dm -overwrite -json -percent "$pct" \
    -method "$meth" -criterion "$crit" -optimize "$opt" >one$i.json 2>/dev/null ||
    { mismatch=$((mismatch + 1)); echo "simplify failed: $terr $meth $crit $opt $pct" >&2; continue; }
  echo "one$i.json $points $mx $l2 $rmse $mae $tae $terr $meth $crit $opt $pct%" >>want.txt
done <cases.txt
# every run against its row, in one Python (112 of them took 28 s): the
# mismatches, then how many were checked
python3 - want.txt >got.txt <<'EOF'
import json, sys
bad = n = 0
for line in open(sys.argv[1]):
    f = line.split()
    d = json.load(open(f[0]))
    got = [d["vertices"], d["max_error"], d["l2"], d["rmse"],
           d["mean_abs_error"], d["total_abs_error"]]
    want = [int(f[1])] + [float(x) for x in f[2:7]]
    n += 1
    if got != want:
        bad += 1
        print("simplify %r, study %r at %s" % (got, want, " ".join(f[7:])))
print(bad, n)
EOF
read -r bad checked < <(tail -1 got.txt)
sed '$d' got.txt >&2
mismatch=$((mismatch + bad))
if [ "$mismatch" -eq 0 ] && [ "$checked" -eq 72 ]; then
  pass
else
  fail "study vs simplify: $mismatch of $checked rows differ"
fi

# tables.md: 2 terrains x 2 methods x 2 optimisers = 8 tables of 3 rows,
# the smallest value of each row bold (and only the smallest).
if python3 - out/tables.md <<'EOF'; then pass; else fail "tables.md"; fi
import sys
tables = 0
rows = 0
for line in open(sys.argv[1]):
    if line.startswith("## "):
        tables += 1
    if not line.startswith("| ") or line.startswith("| %"):
        continue
    cells = [c.strip() for c in line.strip().strip("|").split("|")]
    vals = cells[2:]
    if len(vals) != 3:
        sys.exit("row %r" % line)
    nums = [float(v.strip("*")) for v in vals]
    best = min(nums)
    for v, x in zip(vals, nums):
        if v.startswith("**") != (x == best):
            sys.exit("bold wrong in %r" % line)
    rows += 1
if tables != 8 or rows != 24:
    sys.exit("%d tables, %d rows" % (tables, rows))
EOF

if python3 -c 'import json,sys; d=json.load(open(sys.argv[1]))
assert d["version"] and d["runs"] == 72 and d["terrains"]["2"]["generator"] == "bump", d' out/runs.json; then
  pass
else
  fail "runs.json"
fi

# -points N (the curves): one recorded run per terrain, method, optimiser
# and criterion. Insertion: a row at every count from the start's (the
# grid's 4 corners) to N, each equal to a single `simplify -max_points K`
# run with the study's repair (Delaunay's for the criteria the study
# optimised after Delaunay insertion: l2, mean_curvature) and optimiser
# (auto: the local swap for those, on a copy at each count), the counts and
# max exactly, the sums to 1e-12 relative (running sums against a full
# pass). Decimation: a row per round, from every sample down to N, the last
# one the TIN `simplify -method decimate -max_points N` returns. The
# -percent rows stay those of single runs, exactly.
PCRIT=delaunay,min_area,l2,mean_curvature
run study -q -terrain tiny.tif -terrain bump -criteria "$PCRIT" \
  -methods insert,decimate -points 30 -percent 20 outp
if [ "$rc" -eq 0 ] && [ -f outp/curves.csv ]; then pass; else fail "study -points: rc $rc, $(cat err.txt)"; fi
if python3 - outp/curves.csv >pcases.txt <<'EOF'; then pass; else fail "study -points: curves.csv rows"; fi
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1], newline="")))
valid = {"tiny.tif": 480, "bump": 600}
pct = {"tiny.tif": 96, "bump": 120}
seen = {}
for r in rows:
    k = (r["terrain"], r["method"], r["criterion"], r["optimizer"])
    seen.setdefault(k, []).append(int(r["points"]))
    [float(r[c]) for c in ("max_error", "l2", "rmse", "mean_abs_error",
                           "total_abs_error", "seconds")]
if len(seen) != 16:
    sys.exit("%d curves: %r" % (len(seen), sorted(seen)))
for (terr, meth, crit, opt), pts in seen.items():
    # decimation resolves the repair as the engine does (flip but for l2)
    want_opt = "local" if crit == "l2" or (
        meth == "insert" and crit == "mean_curvature") else "none"
    if opt != want_opt:
        sys.exit("%s %s %s: optimizer %s" % (terr, meth, crit, opt))
    if pts[0] != pct[terr]:
        sys.exit("%s %s %s: the -percent row first, got %r" % (terr, meth, crit, pts[:3]))
    curve = pts[1:]
    if meth == "insert" and curve != list(range(4, 31)):
        sys.exit("%s insert %s: points %r" % (terr, crit, curve))
    if meth == "decimate" and (curve[0] != valid[terr] or curve[-1] != 30 or
                               any(a <= b for a, b in zip(curve, curve[1:]))):
        sys.exit("%s decimate %s: points %r" % (terr, crit, curve))
    for r in rows:
        if (r["terrain"], r["method"], r["criterion"]) == (terr, meth, crit):
            p = int(r["points"])
            if (meth == "insert" and p in (4, 5, 17, 30)) or \
               (meth == "decimate" and p == 30):
                print(terr, meth, crit, p, r["max_error"], r["l2"], r["rmse"],
                      r["mean_abs_error"], r["total_abs_error"])
EOF
mismatch=0
checked=0
j=0
while read -r terr meth crit points mx l2 rmse mae tae; do
  dem=$terr
  [ "$terr" = bump ] && dem=bump.tif
  rep=auto
  case $crit in l2 | mean_curvature) [ "$meth" = insert ] && rep=delaunay ;; esac
  j=$((j + 1))
  "$T" simplify "$dem" one.2dm -overwrite -json -max_points "$points" \
    -method "$meth" -criterion "$crit" -repair "$rep" >pone$j.json 2>one.err ||
    { mismatch=$((mismatch + 1)); echo "simplify failed: $terr $meth $crit $points: $(cat one.err)" >&2; continue; }
  echo "pone$j.json $points $mx $l2 $rmse $mae $tae $terr $meth $crit" >>pwant.txt
done <pcases.txt
python3 - pwant.txt >got.txt <<'EOF'
import json, sys
bad = n = 0
for line in open(sys.argv[1]):
    f = line.split()
    d = json.load(open(f[0]))
    want = [float(x) for x in f[2:7]]
    got = [d["max_error"], d["l2"], d["rmse"], d["mean_abs_error"],
           d["total_abs_error"]]
    n += 1
    if d["vertices"] != int(f[1]) or got[0] != want[0] or any(
            abs(a - b) > 1e-12 * max(abs(a), abs(b)) for a, b in zip(got, want)):
        bad += 1
        print("simplify %r %r, study %r %r at %s" % (
            d["vertices"], got, f[1], want, " ".join(f[7:])))
print(bad, n)
EOF
read -r bad checked < <(tail -1 got.txt)
sed '$d' got.txt >&2
mismatch=$((mismatch + bad))
if [ "$mismatch" -eq 0 ] && [ "$checked" -eq 40 ]; then
  pass
else
  fail "study -points vs simplify: $mismatch of $checked rows differ"
fi
# -points alone: no -percent checkpoints, tables.md says so.
run study -q -terrain bump -criteria delaunay -points 12 outq
if [ "$rc" -eq 0 ] && [ "$(lines outq/curves.csv)" -eq 10 ] &&
  grep -q "No -percent checkpoints" outq/tables.md &&
  python3 -c 'import json,sys; d=json.load(open(sys.argv[1])); assert d["points"] == 12 and d["rows"] == 9 and d["runs"] == 1, d' outq/runs.json; then
  pass
else
  fail "-points alone: rc $rc, $(cat err.txt), $(head -3 outq/curves.csv 2>/dev/null)"
fi
expect_failure "points 0" 2 "-points" bad10 \
  study -q -terrain bump -points 0 bad10
expect_failure "points below the start" 2 "point limit" bad11 \
  study -q -terrain bump -criteria delaunay -points 3 bad11

# Failures: one line, nothing left.
expect_failure "unreadable terrain" 1 "nosuch.tif" bad1 \
  study -q -terrain bump -terrain nosuch.tif -percent 10 bad1
echo "not a raster" >junk.tif
expect_failure "not a raster" 1 "junk.tif" bad2 \
  study -q -terrain junk.tif -percent 10 bad2
expect_failure "edge insertion with delaunay" 2 "edge_insertion" bad3 \
  study -q -terrain bump -criteria delaunay,minmax_angle \
  -optimizers edge_insertion -percent 10 bad3
expect_failure "unknown criterion" 2 "nosuch" bad4 \
  study -q -terrain bump -criteria delaunay,nosuch bad4
expect_failure "bad percent" 2 "-percent" bad5 \
  study -q -terrain bump -percent 10,200 bad5
expect_failure "no terrain" 2 "-terrain" bad6 study -q bad6
expect_failure "hex percent" 2 "-percent" bad7 \
  study -q -terrain bump -percent 0x10 bad7
expect_failure "criterion twice" 2 "twice" bad8 \
  study -q -terrain bump -criteria delaunay,DELAUNAY bad8
expect_failure "unknown method" 2 "-methods" bad9 \
  study -q -terrain bump -methods insert,refine bad9

# An existing non-empty OUTDIR: refused, untouched; -overwrite writes.
mkdir full && echo keep >full/mine.txt
run study -q -terrain bump -percent 10 full
if [ "$rc" -eq 1 ] && [ "$(lines err.txt)" -eq 1 ] &&
  grep -q -- "-overwrite" err.txt && [ "$(ls -A full)" = mine.txt ]; then
  pass
else
  fail "non-empty OUTDIR: rc $rc, $(cat err.txt), $(ls -A full)"
fi
run study -q -overwrite -terrain bump -criteria delaunay -percent 10 full
if [ "$rc" -eq 0 ] && [ -f full/mine.txt ] && [ -f full/curves.csv ] &&
  [ "$(lines full/curves.csv)" -eq 2 ]; then
  pass
else
  fail "-overwrite: rc $rc, $(cat err.txt)"
fi
# An empty OUTDIR needs no -overwrite.
mkdir empty
run study -q -terrain bump -criteria delaunay -percent 10 empty
if [ "$rc" -eq 0 ] && [ -f empty/tables.md ]; then pass; else fail "empty OUTDIR: $(cat err.txt)"; fi

echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
