#!/usr/bin/env bash
# bench/run.sh -- terratin against hmm and delatin, DEM file to TIN file.
#
#   bench/run.sh            # every DEM below (make bench)
#   bench/run.sh --quick    # the 1025 x 1025 fractal only
#   HMM=/path/to/hmm bench/run.sh
#
# DEMs and max errors (override E_* in the environment):
#   ds1025  1025 x 1025 diamond-square fractal, seed 1, E_1025=8 (~2 % of
#           the samples become vertices)
#   ds4097  4097 x 4097 fractal, seed 1, E_4097=10
#   crater  Crater Lake of the 1995 and 2004 papers, E_CRATER=0.945
#           (../shared/testdata; skipped with a message when absent)
#   hood    Mt Hood, LANDFIRE 30 m, E_HOOD=10 (../shared/testdata; nodata
#           collar)
# For each DEM the three tools run REPEAT times (default 3) in alternation
# (a slow spell of this shared machine then slows all three), and for each
# tool the run with the fastest meshing counts for its whole column.
#
# What each tool does and what is timed:
#  - terratin: `simplify -json` from the DEM file to a GeoPackage with every
#    per-triangle and per-vertex attribute, run_parameters and both R-trees.
#    read / mesh / statistics / write seconds from its -json.
#  - hmm (fogleman/hmm, the C++ peer): from a 16-bit PNG of the DEM to a
#    binary STL, with -z the height range and -e E over that range, as hmm
#    reads heights; its read / mesh / write seconds as it prints them. hmm
#    is not built here: set HMM to a binary built from fogleman/hmm at
#    commit 5ea6114 with its own Makefile (Debian's libglm-dev); without it
#    the table has no hmm column.
#  - delatin (npm, the JavaScript port of the same algorithm): from a raw
#    Float32 copy of the DEM to an OBJ of its own coords and triangles (no
#    georeferencing), timed inside node.
#  - wall s: the whole process (start-up included) from date +%s%N; peak
#    MiB: /usr/bin/time -f %M.
#  - max error, RMSE: `terratin eval DEM TIN -json` over every valid
#    sample, the same code for the three TINs, each read as its tool wrote
#    it, with no converter: hmm's binary STL in the DEM's pixel frame
#    (-stl_frame pixel) with its heights less zmin put back
#    (-tin_transform 1,1,1,0,0,ZMIN; they are 16-bit, so its error includes
#    up to half a quantum of the PNG), delatin's OBJ in the pixel frame
#    with rows counted down (-tin_transform 1,-1,1,0,HEIGHT-1,0).
# The peers' inputs (PNG, raw) come from bench/peer_input.py, untimed;
# neither peer knows nodata, which is filled with the DEM's minimum for
# them. Everything lands in bench/out/ (git-ignored); report.txt is the
# table, with the goals of issue 16 checked at its foot.
set -euo pipefail

ROOT=$(cd "$(dirname "$0")/.." && pwd)
cd "$ROOT"
OUT=bench/out
TT=${TERRATIN:-build/terratin}
HMM=${HMM:-}
DELATIN_VERSION=0.2.0
E_1025=${E_1025:-8}
E_4097=${E_4097:-10}
E_CRATER=${E_CRATER:-0.945}
E_HOOD=${E_HOOD:-10}
REPEAT=${REPEAT:-3}
SHARED=${TT_SHARED_TESTDATA:-$ROOT/../shared/testdata}
PY=/usr/bin/python3

quick=0
for arg in "$@"; do
  case "$arg" in
    --quick) quick=1 ;;
    -h|--help) sed -n '2,45p' "$0"; exit 0 ;;
    *) echo "bench: unknown argument '$arg' (try --help)" >&2; exit 2 ;;
  esac
done

say() { printf '\n== %s\n' "$*"; }

# Debian packages this script needs beyond the build's (make deps).
need_pkgs() {
  local missing="" p
  for p in "$@"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" \
      || missing="$missing $p"
  done
  if [ -n "$missing" ]; then
    echo "bench: installing Debian packages:$missing"
    local sudo=""
    [ "$(id -u)" = 0 ] || sudo=sudo
    $sudo apt-get update -qq
    DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq \
      --no-install-recommends $missing
  fi
}

need_pkgs time gdal-bin python3-gdal python3-numpy
command -v node >/dev/null && command -v npm >/dev/null || need_pkgs nodejs npm

if [ ! -x "$TT" ]; then
  echo "bench: $TT not found; run 'make build' first (make bench does)" >&2
  exit 1
fi
if [ -n "$HMM" ] && [ ! -x "$HMM" ]; then
  echo "bench: HMM=$HMM is not an executable" >&2
  exit 1
fi
[ -n "$HMM" ] || echo "bench: hmm not given (HMM=/path/to/hmm, built from" \
  "fogleman/hmm at 5ea6114); running without it"
mkdir -p "$OUT"

say "installing delatin $DELATIN_VERSION into $OUT (npm install --prefix)"
DELATIN_JS=$OUT/node_modules/delatin/index.js
if [ -f "$DELATIN_JS" ] && grep -q "\"version\": \"$DELATIN_VERSION\"" \
     "$OUT/node_modules/delatin/package.json"; then
  echo "already installed"
else
  npm install --prefix "$OUT" --no-audit --no-fund --no-save --loglevel=error \
    "delatin@$DELATIN_VERSION"
fi
[ -f "$DELATIN_JS" ] || { echo "bench: npm did not install $DELATIN_JS" >&2; exit 1; }

# measure NAME CMD...: runs CMD with stdout to NAME.out, stderr to NAME.err,
# wall time (ns) to NAME.ns and peak RSS (KiB) to NAME.rss.
measure() {
  local name=$1; shift
  local t0 t1
  t0=$(date +%s%N)
  if ! /usr/bin/time -f %M -o "$OUT/$name.rss" "$@" >"$OUT/$name.out" 2>"$OUT/$name.err"; then
    echo "bench: failed: $*" >&2
    tail -n 20 "$OUT/$name.err" >&2
    exit 1
  fi
  t1=$(date +%s%N)
  echo $((t1 - t0)) >"$OUT/$name.ns"
}

# hmm prints "loading heightmap... 0.015s", "triangulating... 0.26s",
# "points = N", "triangles = N", "writing output... 0.017s", then the total.
hmm_json() {
  awk '
    /^loading heightmap/ { r = $NF }
    /^triangulating/     { m = $NF }
    /^writing output/    { w = $NF }
    /points = /          { v = $NF }
    /triangles = /       { t = $NF }
    /^[0-9.e-]+s$/       { tot = $1 }
    END {
      gsub("s$", "", r); gsub("s$", "", m); gsub("s$", "", w); gsub("s$", "", tot)
      printf "{\"tool\":\"hmm\",\"vertices\":%s,\"triangles\":%s,\"seconds\":{\"read\":%s,\"mesh\":%s,\"write\":%s,\"total\":%s}}\n", v, t, r, m, w, tot
    }' "$1"
}

# fastest NAME PATTERN: the run r (1..REPEAT) of NAME.r<r>.json whose
# number matched by PATTERN is the smallest.
fastest() {
  local name=$1 pat=$2 r best="" bestv=""
  for r in $(seq 1 "$REPEAT"); do
    local v
    v=$(grep -o "$pat" "$OUT/$name.r$r.json" | head -n 1 | sed 's/.*: *//')
    if [ -z "$bestv" ] || awk -v a="$v" -v b="$bestv" 'BEGIN{exit !(a < b)}'; then
      best=$r
      bestv=$v
    fi
  done
  echo "$best"
}

# run_case NAME DEM E
run_case() {
  local c=$1 dem=$2 e=$3
  say "[$c] peer inputs (bench/peer_input.py, not timed)"
  $PY bench/peer_input.py "$dem" "$OUT/$c"
  local zr he
  zr=$($PY -c "import json;i=json.load(open('$OUT/$c.info.json'));print(max(i['zmax']-i['zmin'],1e-300))")
  he=$($PY -c "print(repr($e / $zr))")
  echo "{\"name\":\"$c\",\"dem\":\"$dem\",\"max_error\":$e,\"hmm_z\":$zr,\"hmm_e\":$he}" >"$OUT/$c.case.json"

  local tools="terratin delatin" r t
  [ -n "$HMM" ] && tools="terratin hmm delatin"
  for r in $(seq 1 "$REPEAT"); do
    say "[$c] run $r of $REPEAT: $tools at E = $e"
    rm -f "$OUT/$c.terratin.gpkg"
    measure "$c.terratin.r$r" "$TT" simplify -json -overwrite -max_error "$e" "$dem" "$OUT/$c.terratin.gpkg"
    cp "$OUT/$c.terratin.r$r.out" "$OUT/$c.terratin.r$r.json"
    if [ -n "$HMM" ]; then
      rm -f "$OUT/$c.hmm.stl"
      measure "$c.hmm.r$r" "$HMM" -z "$zr" -e "$he" "$OUT/$c.png" "$OUT/$c.hmm.stl"
      hmm_json "$OUT/$c.hmm.r$r.out" >"$OUT/$c.hmm.r$r.json"
    fi
    rm -f "$OUT/$c.delatin.obj"
    measure "$c.delatin.r$r" node bench/delatin_run.mjs --delatin "$DELATIN_JS" \
      --raw "$OUT/$c.raw" --info "$OUT/$c.info.json" --max-error "$e" \
      --out "$OUT/$c.delatin.obj"
    cp "$OUT/$c.delatin.r$r.out" "$OUT/$c.delatin.r$r.json"
    for t in $tools; do
      printf '  %-9s mesh %s  wall %.3f s\n' "$t" \
        "$(grep -o '"mesh": *[0-9.e-]*' "$OUT/$c.$t.r$r.json" | sed 's/.*: *//')" \
        "$(awk '{print $1 / 1e9}' "$OUT/$c.$t.r$r.ns")"
    done
  done
  for t in $tools; do
    local best
    best=$(fastest "$c.$t" '"mesh": *[0-9.e-]*')
    for x in json ns rss; do cp "$OUT/$c.$t.r$best.$x" "$OUT/$c.$t.$x"; done
  done

  say "[$c] terratin eval of the TINs"
  "$TT" eval "$dem" "$OUT/$c.terratin.gpkg" -json >"$OUT/$c.terratin.eval.json"
  local zmin h1
  zmin=$($PY -c "import json;print(repr(json.load(open('$OUT/$c.info.json'))['zmin']))")
  h1=$($PY -c "import json;print(json.load(open('$OUT/$c.info.json'))['size'][1] - 1)")
  "$TT" eval "$dem" "$OUT/$c.delatin.obj" -tin_frame pixel \
    -tin_transform "1,-1,1,0,$h1,0" -json >"$OUT/$c.delatin.eval.json"
  if [ -n "$HMM" ]; then
    "$TT" eval "$dem" "$OUT/$c.hmm.stl" -stl_frame pixel \
      -tin_transform "1,1,1,0,0,$zmin" -json >"$OUT/$c.hmm.eval.json"
  fi
}

cases=()
rm -f "$OUT/ds1025.tif"
"$TT" generate diamond_square "$OUT/ds1025.tif" -size 1025 -seed 1 -q
run_case ds1025 "$OUT/ds1025.tif" "$E_1025"; cases+=(ds1025)
if [ "$quick" = 0 ]; then
  if [ -f "$SHARED/garland_heckbert_terra_scape/crater.stm.vrt" ]; then
    run_case crater "$SHARED/garland_heckbert_terra_scape/crater.stm.vrt" "$E_CRATER"
    cases+=(crater)
  else
    echo "bench: $SHARED has no Crater Lake; skipping it"
  fi
  if [ -f "$SHARED/gdalraster/lf_elev_220_mt_hood_utm.tif" ]; then
    run_case hood "$SHARED/gdalraster/lf_elev_220_mt_hood_utm.tif" "$E_HOOD"
    cases+=(hood)
  else
    echo "bench: $SHARED has no Mt Hood; skipping it"
  fi
  rm -f "$OUT/ds4097.tif"
  "$TT" generate diamond_square "$OUT/ds4097.tif" -size 4097 -seed 1 -q
  run_case ds4097 "$OUT/ds4097.tif" "$E_4097"; cases+=(ds4097)
fi

say "results ($(date -u '+%Y-%m-%d %H:%M UTC'), $(nproc) cores, $("$TT" --version 2>&1 | head -n 1))"
echo "terratin scans with all online CPUs on grids of a million samples or more;"
echo "hmm and delatin run on one thread. Load average now: $(cut -d' ' -f1-3 /proc/loadavg)"
node bench/report.mjs "$OUT" "${cases[@]}" | tee "$OUT/report.txt"
