# tt_tiles_lib.sh -- what the tiled-run command tests share (sourced by
# test_tiles.sh and test_tiles_methods.sh after tt_check.sh): the checks
# for TT_TERRATIN and the tools (exit 77 when missing), a work folder
# removed at exit (in/ and out/), and the helpers: run (the command, its
# output in out.txt and err.txt, its status in rc), jget (a JSON field),
# dump (the md5 of the triangles and vertices layers), within (a ratio),
# conforming (tin_topology.py) and bounded (terratin eval).
T=${TT_TERRATIN:-}
if [ -z "$T" ] || [ ! -x "$T" ]; then
  echo "SKIP: TT_TERRATIN is not set or not executable"
  exit 77
fi
for tool in gdal_translate gdal_rasterize ogrinfo python3 md5sum; do
  if ! command -v "$tool" >/dev/null 2>&1; then
    echo "SKIP: $tool is missing"
    exit 77
  fi
done
TOPO="$(cd "$(dirname "$0")" && pwd)/tin_topology.py"

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
dump() { ogrinfo -ro -al -q "$1" triangles vertices 2>/dev/null | md5sum | cut -d' ' -f1; }
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

