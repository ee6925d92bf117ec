#!/usr/bin/env bash
# test_dask.sh -- tools/tt_dask.py, issue 19's Dask driver: a LocalCluster
# of 2 separate worker processes on 127.0.0.1 (no dashboard) runs every tile
# of a 513^2 fractal; the merged layers equal `simplify -tile_size` with the
# same options (md5 of ogrinfo), the tiles ran in 2 processes other than
# the driver, the plan and pieces are gone afterwards; a bad DEM exits 1
# with nothing written. Skips (77) when /usr/bin/python3 has no
# `distributed` (Debian python3-distributed, an optional heavy client).
set -u
. "$(dirname "${BASH_SOURCE[0]}")/../apps/tt_check.sh" || exit 1

T=${TT_TERRATIN:-}
if [ -z "$T" ] || [ ! -x "$T" ]; then
  echo "SKIP: TT_TERRATIN is not set or not executable"
  exit 77
fi
if ! /usr/bin/python3 -c 'import distributed' >/dev/null 2>&1; then
  echo "SKIP: /usr/bin/python3 has no distributed (apt-get install python3-distributed)"
  exit 77
fi
if ! command -v ogrinfo >/dev/null 2>&1; then
  echo "SKIP: ogrinfo is missing"
  exit 77
fi
DRIVER="$(cd "$(dirname "$0")/../.." && pwd)/tools/tt_dask.py"

W=$(mktemp -d "${TMPDIR:-/tmp}/tt_dask.XXXXXX") || exit 1
trap 'rm -rf "$W"' EXIT
cd "$W" || exit 1
export TMPDIR="$W" # the workers' spill folders too
export DASK_TEMPORARY_DIRECTORY="$W"

dump() { ogrinfo -ro -al -q "$1" triangles vertices 2>/dev/null | md5sum | cut -d' ' -f1; }

"$T" generate diamond_square ds.tif -size 513 -seed 11 -q || exit 1
/usr/bin/python3 "$DRIVER" --terratin "$T" --workers 2 --stats st.json \
  ds.tif d.gpkg -max_error 6 -tile_size 128 >out.txt 2>err.txt
rc=$?
cat out.txt
check "driver: exit 0" [ $rc -eq 0 ]
"$T" simplify -q -max_error 6 -tile_size 128 ds.tif s.gpkg
check "Dask merge = simplify -tile_size (layers)" [ -s d.gpkg ] && [ "$(dump d.gpkg)" = "$(dump s.gpkg)" ]
check "2 workers, 16 tiles in 2 other processes" /usr/bin/python3 -c '
import json, sys
d = json.load(open("st.json"))
pids = {t["worker_pid"] for t in d["per_tile"]}
sys.exit(0 if d["workers"] == 2 and d["tiles"] == 16 and len(d["per_tile"]) == 16
         and len(pids) == 2 and int(sys.argv[1]) not in pids else 1)' $$
check "plan and pieces removed" [ ! -e d.gpkg.plan.json ] && [ ! -e d.gpkg.plan.json.tiles ]

/usr/bin/python3 "$DRIVER" --terratin "$T" --workers 2 ds.tif d.gpkg \
  -max_error 6 -tile_size 128 >out.txt 2>err.txt
check "existing output refused" [ $? -eq 1 ] && grep -q "exists" err.txt
/usr/bin/python3 "$DRIVER" --terratin "$T" --workers 2 nothere.tif e.gpkg \
  -max_error 6 -tile_size 128 >out.txt 2>err.txt
rc=$?
check "bad DEM: non-zero exit, one line, nothing written" [ $rc -ne 0 ] && grep -q "nothere.tif" err.txt && [ ! -e e.gpkg ]

echo "$passed passed, $failed failed"
[ $failed -eq 0 ]
