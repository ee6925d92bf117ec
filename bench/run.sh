#!/usr/bin/env bash
# bench/run.sh -- terratin against delatin on fractal DEMs, side by side.
#
#   bench/run.sh            # 1025 x 1025 and 4097 x 4097 (make bench)
#   bench/run.sh --quick    # 1025 x 1025 only
#
# For each DEM: generate it with `terratin generate diamond_square`, mesh it
# with `terratin simplify -json` and with the npm package delatin at the same
# max error, measure both TINs with `terratin eval -json`, and print one
# table (bench/report.mjs). Everything lands in bench/out/ (git-ignored):
# the DEMs, both TINs, every JSON, and report.txt.
#
# Measures:
#  - meshing s: terratin's `seconds.mesh` from -json (refinement up to the
#    finished mesh); delatin's `new Delatin(...)` + `run(E)`, timed with
#    process.hrtime. The row below it adds terratin's error statistics
#    (`seconds.simplify` = mesh + statistics: max, RMS, mean and L2 error
#    and the per-triangle and per-vertex attributes, one more pass over
#    every sample), work that delatin's run() does not do. Each tool
#    runs REPEAT times (default 3), the two in alternation, and the run
#    with the fastest meshing counts for everything in its column: on a
#    shared machine a single pair of runs can be off by 2x.
#  - end-to-end s: wall clock of the whole process (start-up, read, mesh,
#    write), from date +%s%N around it. terratin reads the GeoTIFF and writes
#    a GeoPackage with per-triangle and per-vertex attributes; delatin reads
#    a raw Float32 copy (made beforehand by gdal_translate -of ENVI, not
#    timed: node cannot read GeoTIFF) and writes a GeoJSON text sequence.
#  - peak MiB: maximum resident set of the process, /usr/bin/time -f %M.
#    A baseline (terratin simplifying a 9x9 DEM, `node -e 0`) is measured
#    too, so that memory per sample is reported net of the loaded libraries.
#  - vertices, triangles: as each tool reports them; max error and RMS:
#    `terratin eval DEM TIN -json` over every sample, the same code for both.
#
# Max error per DEM, in the DEM's z units, chosen so that about 2 % of the
# samples become vertices -- a realistic simplification. The generator's
# defaults (amplitude 100, roughness 0.7) give heights of about -48 .. 99
# with seed 1; delatin keeps, at seed 1:
#   1025 x 1025: E =  7 -> 2.9 %, E = 8 -> 2.0 %, E = 10 -> 1.0 %   (E_1025=8)
#   4097 x 4097: E =  3 -> 4.2 %, E = 4 -> 1.9 %, E =  5 -> 1.0 %   (E_4097=4)
# The big DEM needs the smaller E: the random term of its finest level is
# half as large (100 * 0.7^12 = 1.4 against 100 * 0.7^10 = 2.8).
# Override with E_1025=... E_4097=... in the environment; the seeds with
# SEED_1025 / SEED_4097; the binary with TERRATIN=path; the runs per tool
# with REPEAT=n.
set -euo pipefail

ROOT=$(cd "$(dirname "$0")/.." && pwd)
cd "$ROOT"
OUT=bench/out
TT=${TERRATIN:-build/terratin}
DELATIN_VERSION=0.2.0
E_1025=${E_1025:-8}
E_4097=${E_4097:-4}
SEED_1025=${SEED_1025:-1}
SEED_4097=${SEED_4097:-1}
REPEAT=${REPEAT:-3}

quick=0
for arg in "$@"; do
  case "$arg" in
    --quick) quick=1 ;;
    -h|--help) sed -n '2,44p' "$0"; exit 0 ;;
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

need_pkgs time gdal-bin
command -v node >/dev/null && command -v npm >/dev/null || need_pkgs nodejs npm

if [ ! -x "$TT" ]; then
  echo "bench: $TT not found; run 'make build' first (make bench does)" >&2
  exit 1
fi
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

# measure NAME CMD...: runs CMD with stdout to NAME.json, stderr to NAME.err,
# wall time (ns) to NAME.ns and peak RSS (KiB) to NAME.rss.
measure() {
  local name=$1; shift
  local t0 t1
  t0=$(date +%s%N)
  if ! /usr/bin/time -f %M -o "$OUT/$name.rss" "$@" >"$OUT/$name.json" 2>"$OUT/$name.err"; then
    echo "bench: failed: $*" >&2
    tail -n 20 "$OUT/$name.err" >&2
    exit 1
  fi
  t1=$(date +%s%N)
  echo $((t1 - t0)) >"$OUT/$name.ns"
}

say "baselines: peak RSS of the processes doing nothing heavy"
# terratin's baseline is a whole simplify run on a 9x9 DEM: the same code
# path as the real runs (GDAL drivers registered, GeoTIFF read, GeoPackage
# written) with no data to speak of. --version is shown beside it.
measure base_terratin_version "$TT" --version
rm -f "$OUT/tiny.tif" "$OUT/tiny.gpkg"
"$TT" generate diamond_square "$OUT/tiny.tif" -size 9 -seed 1 -q
measure base_terratin "$TT" simplify -q -max_error 1 "$OUT/tiny.tif" "$OUT/tiny.gpkg"
measure base_node node -e 0
echo "terratin simplify 9x9: $(cat $OUT/base_terratin.rss) KiB;" \
  "terratin --version: $(cat $OUT/base_terratin_version.rss) KiB;" \
  "node -e 0: $(cat $OUT/base_node.rss) KiB"

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

run_case() {
  local n=$1 seed=$2 e=$3
  local c=ds$n
  local dem=$OUT/$c.tif

  say "[$c] generating a ${n}x$n diamond-square DEM (seed $seed)"
  rm -f "$dem"
  "$TT" generate diamond_square "$dem" -size "$n" -seed "$seed"
  gdalinfo -json "$dem" >"$OUT/$c.info.json"
  echo "{\"name\":\"$c\",\"size\":$n,\"seed\":$seed,\"max_error\":$e}" >"$OUT/$c.case.json"

  say "[$c] exporting raw Float32 for delatin (gdal_translate -of ENVI, not timed)"
  rm -f "$OUT/$c.raw" "$OUT/$c.hdr"
  GDAL_PAM_ENABLED=NO gdal_translate -q -of ENVI -ot Float32 "$dem" "$OUT/$c.raw"

  # REPEAT runs of each tool, in alternation, so that a slow spell of the
  # machine slows both; the run of the fastest meshing counts (its JSON,
  # wall time and peak RSS become $c.terratin.* and $c.delatin.*).
  local r tt_best="" dl_best=""
  for r in $(seq 1 "$REPEAT"); do
    say "[$c] terratin simplify -max_error $e (run $r of $REPEAT)"
    rm -f "$OUT/$c.terratin.gpkg"
    measure "$c.terratin.r$r" "$TT" simplify -json -overwrite -max_error "$e" "$dem" "$OUT/$c.terratin.gpkg"
    grep -o '"mesh": [0-9.e-]*' "$OUT/$c.terratin.r$r.json"

    say "[$c] delatin run($e) (run $r of $REPEAT)"
    rm -f "$OUT/$c.delatin.geojsonl"
    measure "$c.delatin.r$r" node bench/delatin_run.mjs --delatin "$DELATIN_JS" \
      --raw "$OUT/$c.raw" --info "$OUT/$c.info.json" --max-error "$e" \
      --out "$OUT/$c.delatin.geojsonl"
    grep -o '"mesh":[0-9.e-]*' "$OUT/$c.delatin.r$r.json"
  done
  tt_best=$(fastest "$c.terratin" '"mesh": *[0-9.e-]*')
  dl_best=$(fastest "$c.delatin" '"mesh": *[0-9.e-]*')
  for x in json ns rss err; do
    cp "$OUT/$c.terratin.r$tt_best.$x" "$OUT/$c.terratin.$x"
    cp "$OUT/$c.delatin.r$dl_best.$x" "$OUT/$c.delatin.$x"
  done
  echo "fastest meshing: terratin run $tt_best, delatin run $dl_best"
  cat "$OUT/$c.terratin.json"
  cat "$OUT/$c.delatin.json"

  say "[$c] terratin eval of both TINs"
  "$TT" eval "$dem" "$OUT/$c.terratin.gpkg" -json >"$OUT/$c.terratin.eval.json"
  cat "$OUT/$c.terratin.eval.json"
  "$TT" eval "$dem" "$OUT/$c.delatin.geojsonl" -json >"$OUT/$c.delatin.eval.json"
  cat "$OUT/$c.delatin.eval.json"
}

cases=(ds1025)
run_case 1025 "$SEED_1025" "$E_1025"
if [ "$quick" = 0 ]; then
  run_case 4097 "$SEED_4097" "$E_4097"
  cases+=(ds4097)
fi

say "results ($(date -u '+%Y-%m-%d %H:%M UTC'), $(nproc) cores, $("$TT" --version 2>&1 | head -n 1))"
echo "terratin scans with all online CPUs on grids of a million samples or more;"
echo "delatin runs on one thread. Load average now: $(cut -d' ' -f1-3 /proc/loadavg)"
node bench/report.mjs "$OUT" "${cases[@]}" | tee "$OUT/report.txt"
