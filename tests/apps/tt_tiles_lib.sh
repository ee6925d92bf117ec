# tt_tiles_lib.sh -- what the tiled-run command tests share (sourced by
# test_tiles.sh, test_tiles_methods.sh and test_tiles_geo.sh after
# tt_check.sh): the checks for TT_TERRATIN and the tools (exit 77 when
# missing), a work folder removed at exit (in/ and out/), and the helpers:
# run (the command, its output in out.txt and err.txt, its status in rc),
# jget (a JSON field), dump (the md5 of the triangles and vertices layers),
# within (a ratio), conforming (tin_topology.py), bounded (terratin eval),
# streamed_vs_merged (a GeoPackage written as the tiles merge against the
# merged TIN's, table by table), interrupted (SIGTERM during a run leaves
# nothing) and real_dems (Mt Hood and Vinschgau in tiles, when the shared
# test data have them).
T=${TT_TERRATIN:-}
if [ -z "$T" ] || [ ! -x "$T" ]; then
  echo "SKIP: TT_TERRATIN is not set or not executable"
  exit 77
fi
for tool in gdal_translate gdal_rasterize ogrinfo python3 md5sum sqlite3; do
  if ! command -v "$tool" >/dev/null 2>&1; then
    echo "SKIP: $tool is missing"
    exit 77
  fi
done
TOPO="$TT_APPS/tin_topology.py"
SAME="$TT_APPS/same_gpkg.py"

W=$(mktemp -d "${TMPDIR:-/tmp}/tt_tiles.XXXXXX") || exit 1
trap 'rm -rf "$W"' EXIT
cd "$W" || exit 1
mkdir in out

rc=0
run() {
  "$T" "$@" >out.txt 2>err.txt
  rc=$?
}
jget() { # jget FILE KEY[.KEY...]
  python3 -c 'import json,sys
d=json.load(open(sys.argv[1]))
for k in sys.argv[2].split("."): d=d[k]
print(d)' "$1" "$2"
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
# within A B PCT: |A/B - 1| <= PCT %
within() { python3 -c 'import sys; a,b,p=map(float,sys.argv[1:]); sys.exit(0 if abs(a/b-1)*100<=p else 1)' "$1" "$2" "$3"; }

# conforming NAME GPKG [ASC] [EULER]: topology, and eval within E
conforming() {
  local name=$1 gpkg=$2 asc=${3:-} euler=${4-1} # "": not checked
  if python3 "$TOPO" "$gpkg" $asc >topo.json 2>topo.err; then pass; else
    fail "$name: not conforming: $(cat topo.json topo.err)"; fi
  if [ -n "$euler" ]; then
    check "$name: Euler characteristic $euler ($(cat topo.json))" \
      [ "$(jget topo.json euler)" = "$euler" ]
  fi
}
# bounded NAME DEM GPKG E: eval says every valid sample is within E, each
# covered once
bounded() {
  local name=$1 dem=$2 gpkg=$3 e=$4
  "$T" eval -json -max_error "$e" "$dem" "$gpkg" >eval.json 2>eval.err
  local rc=$? # before the check: its $(...) would reset $?
  check "$name: eval within $e ($(cat eval.err))" [ $rc -eq 0 ]
  check "$name: no sample overlapped" [ "$(jget eval.json overlapped)" = 0 ]
}

# same NAME A B: the files' tables hold the same content (same_gpkg.py);
# the R-trees by content (each feature's id and box, rtreecheck) unless
# SAME_MODE is set, to empty for their nodes byte for byte
same() {
  if python3 "$SAME" ${SAME_MODE---rtree-content} "$2" "$3" >same.txt 2>&1; then pass; else
    fail "$1: streamed and merged differ: $(head -c 600 same.txt)"; fi
}
# streamed_vs_merged NAME DEM OPTIONS...: `simplify -q -json OPTIONS DEM`
# into a GeoPackage written as the tiles merge (the default, JSON
# tiling.streamed true) and with TERRATIN_TILE_STREAM=NO (the merged TIN,
# tiling.streamed false): the same tables row by row (R-tree nodes,
# extents, counts, run_parameters but its times, styles), the same
# ogrinfo -al of the layers (LAYERS_OF, default triangles vertices), the
# same JSON statistics, bound and budget passes, as many database pages
# outside the R-trees (none free; the streamed R-trees' leaves are packed
# in blocks, of RB features when RB is set, TERRATIN_RTREE_BLOCK, so
# their nodes may differ).
streamed_vs_merged() {
  local name=$1 dem=$2
  shift 2
  rm -f out/sv_s.gpkg out/sv_m.gpkg
  TERRATIN_RTREE_BLOCK=${RB:-} "$T" simplify -q -json "$@" "$dem" out/sv_s.gpkg >s.json 2>err.txt
  rc=$?
  check "$name: streamed exit 0 ($(cat err.txt))" [ $rc -eq 0 ]
  TERRATIN_TILE_STREAM=NO "$T" simplify -q -json "$@" "$dem" out/sv_m.gpkg >m.json 2>err.txt
  rc=$?
  check "$name: merged exit 0 ($(cat err.txt))" [ $rc -eq 0 ]
  # the JSON: streamed and merged said, the same statistics, bound and
  # budget passes (one Python for all the keys)
  python3 - s.json m.json >json.txt 2>&1 <<'PY'
import json, sys
s, m = (json.load(open(p)) for p in sys.argv[1:3])
def get(d, k):
    for part in k.split("."):
        d = d[part]
    return d
bad = []
if get(s, "tiling.streamed") is not True:
    bad.append("streamed: tiling.streamed %r" % get(s, "tiling.streamed"))
if get(m, "tiling.streamed") is not False:
    bad.append("TERRATIN_TILE_STREAM=NO: tiling.streamed %r" % get(m, "tiling.streamed"))
for k in ("vertices triangles components max_error rmse covered_samples "
          "lone_samples forced_vertices valid_samples z_min z_max "
          "limits.max_error tiling.budget_passes").split():
    if get(s, k) != get(m, k):
        bad.append("JSON %s: %r streamed, %r merged" % (k, get(s, k), get(m, k)))
print("; ".join(bad))
sys.exit(1 if bad else 0)
PY
  rc=$? # before the check: its $(...) would reset $?
  check "$name: streamed and merged said, the same JSON statistics ($(cat json.txt))" [ $rc -eq 0 ]
  same "$name" out/sv_s.gpkg out/sv_m.gpkg
  # no page of a dropped budget pass left over: as many pages outside the
  # R-trees (whose leaves the streamed writer packs in blocks, so their
  # node count may differ), none free, every page in use
  local q="select count(*) from dbstat where name not like 'rtree%'; pragma freelist_count; pragma integrity_check"
  local ps pm
  ps=$(sqlite3 out/sv_s.gpkg "$q" | tr '\n' ' ')
  pm=$(sqlite3 out/sv_m.gpkg "$q" | tr '\n' ' ')
  check "$name: the same pages but the R-trees', none free, intact ($ps, $pm)" [ "$ps" = "$pm" ]
  check "$name: streamed: none free, intact ($ps)" [ "${ps#* }" = "0 ok " ]
  # what GDAL says of the layers (counts, extents, fields, SRS): the same;
  # their features are the same rows byte for byte (same_gpkg.py above), so
  # the same `ogrinfo -al`, which took two thirds of this function's time
  local la lb
  la=$(ogrinfo -ro -so -al out/sv_s.gpkg ${LAYERS_OF:-triangles vertices} 2>&1 | grep -v '^INFO: Open of')
  lb=$(ogrinfo -ro -so -al out/sv_m.gpkg ${LAYERS_OF:-triangles vertices} 2>&1 | grep -v '^INFO: Open of')
  check "$name: the same ogrinfo -so of the layers" eval '[ -n "$la" ] && [ "$la" = "$lb" ]'
}

# interrupted NAME DELAY OPTIONS...: `simplify -q OPTIONS out/int.gpkg`
# in the background, SIGTERM after DELAY seconds (a background job ignores
# SIGINT, and terratin keeps what its parent ignores): either it finished
# first (exit 0, a whole file) or it says it was interrupted; no temporary
# file either way.
interrupted() {
  local name=$1 d=$2 pid
  shift 2
  rm -f out/int.gpkg
  "$T" simplify -q "$@" out/int.gpkg 2>err.txt &
  pid=$!
  sleep "$d"
  kill -TERM $pid 2>/dev/null
  wait $pid
  rc=$?
  if [ -e out/int.gpkg ]; then
    check "$name, SIGTERM at $d s: finished before it ($rc)" [ "$rc" -eq 0 ]
    check "$name, SIGTERM at $d s: a whole file" \
      [ "$(sqlite3 out/int.gpkg 'pragma integrity_check' 2>&1 || echo bad)" = ok ]
  else
    check "$name, SIGTERM at $d s: ended by it ($rc)" [ "$rc" -ne 0 ]
    check "$name, SIGTERM at $d s: says interrupted ($(cat err.txt))" grep -q "interrupted" err.txt
  fi
  check "$name, SIGTERM at $d s: no temporary file ($(ls -A out | grep '^\.tt'))" \
    bash -c "! ls -A out | grep -q '^\\.tt'"
}

# real_dems LABEL OPTIONS...: Mt Hood (nodata collar) and Vinschgau, when
# TT_SHARED_TESTDATA has them, simplified with OPTIONS at max error 20
# untiled and in tiles on 2 threads: the tiled TIN within 5 % of the
# untiled vertices, conforming (Euler characteristic 1), every valid
# sample within the bound, and its GeoPackage written as the tiles merged
# the same as the merged TIN's (streamed_vs_merged). Of Mt Hood its top
# left 320 x 256 corner (2,100 vertices; the collar along two sides) in
# tiles of 64, or with REAL_FULL=1 (tests/long/) the whole 1013 x 799 in
# tiles of 128; Vinschgau (252 x 194) whole at max error 60 in tiles of
# 64, or at 20 in tiles of 128. REAL_DEMS="PATH:E ..." (relative to the
# shared test data) names other DEMs, or only one of these.
real_dems() {
  local label=$1
  shift
  local S=${TT_SHARED_TESTDATA:-} rel p e b nu nv dem n=64
  [ -n "${REAL_FULL:-}" ] && n=128
  for rel in ${REAL_DEMS:-gdalraster/lf_elev_220_mt_hood_utm.tif:20 rspatial_terra/elev_vinschgau.tif:20}; do
    p=${rel%%:*}
    e=${rel##*:}
    if [ -z "$S" ] || [ ! -f "$S/$p" ]; then
      echo "note: $p not in TT_SHARED_TESTDATA; skipped"
      continue
    fi
    b=$(basename "$p" .tif)
    dem=$S/$p
    if [ -z "${REAL_FULL:-}" ]; then
      case $b in
        *mt_hood*)
          b=${b}_corner
          dem=in/$b.tif
          gdal_translate -q -srcwin 0 0 320 256 "$S/$p" "$dem" ;;
        *vinschgau*) e=60 ;; # 11,000 vertices rather than 28,600
      esac
    fi
    gdal_translate -q -of AAIGrid "$dem" in/$b.asc
    run simplify -q -json "$@" -max_error $e "$dem" out/${b}_u.gpkg -overwrite
    cp out.txt ${b}_u.json
    streamed_vs_merged "$b$label, tiles of $n" "$dem" "$@" -max_error $e -tile_size $n -threads 2
    mv out/sv_s.gpkg out/${b}_t.gpkg
    cp s.json ${b}_t.json
    nu=$(jget ${b}_u.json vertices)
    nv=$(jget ${b}_t.json vertices)
    echo "note: $b$label, max error $e: tiles of $n: $nv vertices, untiled $nu"
    check "$b$label: vertices $nv within 5 % of untiled $nu" within "$nv" "$nu" 5
    conforming "$b$label, tiles of $n" out/${b}_t.gpkg in/$b.asc 1
    bounded "$b$label, tiles of $n" "$dem" out/${b}_t.gpkg $e
  done
}
