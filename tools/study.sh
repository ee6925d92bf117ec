#!/usr/bin/env bash
# study.sh -- `make study`: our reproduction of the 2004 criteria study
# (issue 15, SPEC section 6), written into docs/study/.
#
#   tools/study.sh [TERRATIN]      (default build/terratin)
#
# The runs (each a `terratin study` into $STUDY_OUT, default build/study):
#   crater_insert   Crater Lake, greedy insertion, the study's 7 criteria at
#                   1, 10, 25, 50 % (Table 1) and 64.8408 % (100,000 points:
#                   the run times), and each criterion's TIN at 500 points
#   crater_decimate Crater Lake, decimation from a 100,000-point Delaunay TIN
#                   (-start greedy:100000), HDH importance, independent sets;
#                   10, 25, 50, 75 % of the points deleted (Table 2) and
#                   more checkpoints for the curves
#   generated       fault_smooth, fault_rough, peak_rough, valley_rough,
#                   sphere, cylinder (-seed 1), insertion and decimation
#                   (from a zero-error greedy TIN, Drop importance, as the
#                   study's tables of these terrains) at 1, 10, 25, 50 %
#   anneal          fault_smooth and valley_rough, insertion with the final
#                   pass local against anneal
#   crater_curves   Crater Lake insertion curves up to 500 points: one row
#                   per point count with `-points 500` when this terratin
#                   has it, else -percent checkpoints every 10 points
# then the PNGs (tools/plot_study.py) and docs/study/README.md
# (tools/study_report.py). Needs /usr/bin/python3 with matplotlib (Debian:
# apt-get install python3-matplotlib) and Crater Lake in ../shared/testdata
# (or TT_SHARED_TESTDATA, or CRATER=PATH).
set -eu

ROOT=$(cd "$(dirname "$0")/.." && pwd)
T=${1:-$ROOT/build/terratin}
case "$T" in /*) ;; *) T=$(pwd)/$T ;; esac
# From the repository's root, so that the paths in the runs.json files
# (OUTDIR, Crater Lake's ../shared/testdata/...) are relative to it.
cd "$ROOT"
OUT=${STUDY_OUT:-build/study}
DOCS=${STUDY_DOCS:-docs/study}
PY=${TT_PYTHON:-/usr/bin/python3}
CRATER_ARG=crater
[ -n "${CRATER:-}" ] && CRATER_ARG="crater=$CRATER"

if [ ! -x "$T" ]; then
  echo "study.sh: $T is not an executable terratin (run make build)" >&2
  exit 1
fi
if ! "$PY" tools/plot_study.py --check; then
  echo "study.sh: $PY has no matplotlib (apt-get install python3-matplotlib)" >&2
  exit 1
fi

C7=delaunay,minmax_angle,min_area,mean_curvature,gaussian_curvature,abn,l2
# Crater Lake has 154,224 valid samples; -percent keeps floor(P% of them)
# points. The smallest 4-decimal P giving each point count:
pct() {
  "$PY" -c 'import math, sys
n = 154224
out = []
for k in sys.argv[1:]:
    k = int(k)
    p = math.ceil(k * 1e6 / n) / 1e4
    assert math.floor(p / 100.0 * n) == k, k
    out.append(("%.4f" % p).rstrip("0").rstrip("."))
print(",".join(out))' "$@"
}

mkdir -p "$OUT"
t0=$(date +%s)
step() {
  local name=$1
  shift
  echo "== $name: terratin study $*"
  local s=$(date +%s)
  "$T" study -overwrite "$@" "$OUT/$name"
  echo "== $name: $(($(date +%s) - s)) s"
}

step crater_insert -terrain "$CRATER_ARG" -criteria "$C7" -methods insert \
  -percent "1,10,25,50,$(pct 100000)" -tin_points 500
step crater_decimate -terrain "$CRATER_ARG" -criteria "$C7" \
  -methods decimate -start greedy:100000 -importance hdh \
  -percent "$(pct 90000 80000 75000 60000 50000 40000 25000 15000 10000)"
step generated -seed 1 -terrain fault_smooth -terrain fault_rough \
  -terrain peak_rough -terrain valley_rough -terrain sphere \
  -terrain cylinder -criteria "$C7" -methods insert,decimate -start greedy \
  -importance drop -percent 1,10,25,50
step anneal -seed 1 -terrain fault_smooth -terrain valley_rough \
  -criteria "$C7" -methods insert -optimizers local,anneal \
  -percent 1,10,25,50
if "$T" study --help 2>&1 | grep -q -- '-points'; then
  step crater_curves -terrain "$CRATER_ARG" -criteria "$C7" -points 500
else
  echo "== crater_curves: this terratin has no study -points yet:" \
    "checkpoints every 10 points instead"
  step crater_curves -terrain "$CRATER_ARG" -criteria "$C7" \
    -percent "$(pct $(seq 10 10 500))"
fi

echo "== plots and docs/study/README.md"
mkdir -p "$DOCS"
"$PY" tools/plot_study.py --measures "" --out "$DOCS" --dpi 72 \
  "$OUT/crater_insert"
"$PY" tools/plot_study.py --no-tins --out "$DOCS" \
  --measures mean_abs_error,total_abs_error,l2,max_error "$OUT/crater_curves"
"$PY" tools/plot_study.py --no-tins --out "$DOCS" \
  --measures mean_abs_error,total_abs_error,l2 "$OUT/crater_decimate"
"$PY" tools/plot_study.py --no-tins --out "$DOCS" \
  --measures mean_abs_error "$OUT/generated"
"$PY" tools/study_report.py --out "$DOCS" "$OUT"
echo "== study: $(($(date +%s) - t0)) s in all; docs in $DOCS"
