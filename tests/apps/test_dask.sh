#!/usr/bin/env bash
# test_dask.sh -- tools/tt_dask.py, issue 19's Dask driver: a LocalCluster
# of 2 separate worker processes on 127.0.0.1 (no dashboard) runs every tile
# of a 513^2 fractal; the merged layers equal `simplify -tile_size` with the
# same options (md5 of ogrinfo), the tiles ran in 2 processes other than
# the driver, the plan and pieces are gone afterwards; a bad DEM exits 1
# with nothing written. Then docs/scale.md's real-cluster form: `dask
# scheduler` and two `dask worker` commands (one worker process each) on
# 127.0.0.1, every listening socket checked to be on 127.0.0.1, and
# `tt_dask.py --scheduler`: the same layers, the tiles run in both workers,
# a failing tile exits 1 with nothing written. Skips (77) when
# /usr/bin/python3 has no `distributed` (Debian python3-distributed, an
# optional heavy client).
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
# The scheduler and workers of the second part, each the leader of its own
# process group (setsid): stopped with their children on every exit path,
# TERM first, KILL after 10 s.
GROUPS_STARTED=""
stop_groups() {
  local g i
  for g in $GROUPS_STARTED; do kill -TERM -- "-$g" 2>/dev/null; done
  for i in $(seq 1 20); do
    alive=""
    for g in $GROUPS_STARTED; do kill -0 -- "-$g" 2>/dev/null && alive="$alive $g"; done
    [ -z "$alive" ] && break
    sleep 0.5
  done
  for g in $alive; do kill -KILL -- "-$g" 2>/dev/null; done
  GROUPS_STARTED=""
}
trap 'stop_groups; rm -rf "$W"' EXIT
trap 'exit 1' INT TERM HUP
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
check "Dask merge = simplify -tile_size (layers)" eval '[ -s d.gpkg ] && [ "$(dump d.gpkg)" = "$(dump s.gpkg)" ]'
check "2 workers, 16 tiles in 2 other processes" /usr/bin/python3 -c '
import json, sys
d = json.load(open("st.json"))
pids = {t["worker_pid"] for t in d["per_tile"]}
sys.exit(0 if d["workers"] == 2 and d["tiles"] == 16 and len(d["per_tile"]) == 16
         and len(pids) == 2 and int(sys.argv[1]) not in pids else 1)' $$
check "plan and pieces removed" eval '[ ! -e d.gpkg.plan.json ] && [ ! -e d.gpkg.plan.json.tiles ]'

/usr/bin/python3 "$DRIVER" --terratin "$T" --workers 2 ds.tif d.gpkg \
  -max_error 6 -tile_size 128 >out.txt 2>err.txt
rc=$?
check "existing output refused" eval '[ $rc -eq 1 ] && grep -q "exists" err.txt'
/usr/bin/python3 "$DRIVER" --terratin "$T" --workers 2 nothere.tif e.gpkg \
  -max_error 6 -tile_size 128 >out.txt 2>err.txt
rc=$?
check "bad DEM: non-zero exit, one line, nothing written" eval '[ $rc -ne 0 ] && grep -q "nothere.tif" err.txt && [ ! -e e.gpkg ]'

# A scheduler and workers of their own, as docs/scale.md starts them on a
# real cluster ("dask scheduler", "dask worker ADDR --nworkers N
# --nthreads 1", "tt_dask.py --scheduler ADDR"): one scheduler and two
# `dask worker` commands of one worker process each (two "nodes"), all bound
# to 127.0.0.1 and without a dashboard (--no-dashboard alone still starts
# an HTTP server on every interface, the scheduler's on :8787: hence
# --dashboard-address 127.0.0.1:0); the scheduler picks a free port
# (--port 0) and writes its address to a file. Every one of them is bounded
# by `timeout` (180 s) besides the EXIT trap.
DASK=/usr/bin/dask # Debian's, run by /usr/bin/python3
if [ ! -x "$DASK" ]; then
  echo "SKIP (separate scheduler): $DASK is missing (apt-get install python3-distributed)"
else
  setsid timeout 180 "$DASK" scheduler --host 127.0.0.1 --port 0 \
    --no-dashboard --dashboard-address 127.0.0.1:0 \
    --scheduler-file sched.json >sched.log 2>&1 &
  GROUPS_STARTED="$GROUPS_STARTED $!"
  ADDR=""
  for i in $(seq 1 120); do
    ADDR=$(/usr/bin/python3 -c 'import json; print(json.load(open("sched.json"))["address"])' 2>/dev/null) && break
    sleep 0.5
  done
  check "scheduler: up on 127.0.0.1 (${ADDR:-no address})" eval 'case "$ADDR" in tcp://127.0.0.1:*) true ;; *) false ;; esac'
  WPIDS=""
  for i in 1 2; do
    mkdir -p "node$i"
    setsid timeout 180 "$DASK" worker "$ADDR" --nworkers 1 --nthreads 1 \
      --host 127.0.0.1 --no-dashboard --dashboard-address 127.0.0.1:0 \
      --local-directory "node$i" \
      --death-timeout 60 >"worker$i.log" 2>&1 &
    GROUPS_STARTED="$GROUPS_STARTED $!"
    WPIDS="$WPIDS $!"
  done
  # wait for both workers (a driver started earlier would queue its tiles
  # until they come, but would count fewer workers)
  /usr/bin/python3 -c '
import sys, distributed
c = distributed.Client(sys.argv[1], timeout=60)
c.wait_for_workers(2, timeout=90)
c.close()' "$ADDR" >wait.log 2>&1
  check "2 workers registered" [ $? -eq 0 ]
  # every listening socket of the scheduler, the nannies and the workers is
  # on 127.0.0.1 (ss -ltnp names the processes by pid)
  if command -v ss >/dev/null 2>&1; then
    pids=$(for g in $GROUPS_STARTED; do pgrep -g "$g"; done | sort -u)
    ss -Hltnp >ss.txt 2>/dev/null
    mine=$(for p in $pids; do grep "pid=$p," ss.txt; done | sort -u)
    echo "$mine" | awk '{ print "  listening:", $4 }'
    check "the cluster listens on 127.0.0.1 only" eval '[ -n "$mine" ] && ! echo "$mine" | awk "{ print \$4 }" | grep -v "^127\.0\.0\.1:"'
  fi
  /usr/bin/python3 "$DRIVER" --scheduler "$ADDR" --terratin "$T" --stats stc.json \
    ds.tif c.gpkg -max_error 6 -tile_size 128 >out.txt 2>err.txt
  rc=$?
  cat out.txt
  [ $rc -eq 0 ] || cat err.txt
  check "--scheduler: exit 0" [ $rc -eq 0 ]
  check "--scheduler: merge = simplify -tile_size (layers)" eval '[ -s c.gpkg ] && [ "$(dump c.gpkg)" = "$(dump s.gpkg)" ]'
  # the 16 tiles ran in the worker processes of both `dask worker`
  # commands (process groups $WPIDS), not in the driver
  check "--scheduler: 16 tiles on the 2 workers of both dask worker commands" /usr/bin/python3 -c '
import json, subprocess, sys
d = json.load(open("stc.json"))
pids = {t["worker_pid"] for t in d["per_tile"]}
groups = {int(subprocess.run(["ps", "-o", "pgid=", "-p", str(p)], capture_output=True,
                             text=True).stdout.strip() or 0) for p in pids}
sys.exit(0 if d["workers"] == 2 and d["tiles"] == 16 and len(d["per_tile"]) == 16
         and len(pids) == 2 and groups == {int(g) for g in sys.argv[1:]} else 1)' $WPIDS
  check "--scheduler: plan and pieces removed" eval '[ ! -e c.gpkg.plan.json ] && [ ! -e c.gpkg.plan.json.tiles ]'
  # a failing tile on the same cluster (a terratin that refuses tile 5):
  # exit 1 naming it, nothing written
  cat >tt_fail.sh <<EOF
#!/bin/sh
if [ "\$1 \$2 \$4" = "tiles run 5" ]; then echo "tile 5 refused on purpose" >&2; exit 1; fi
exec "$T" "\$@"
EOF
  chmod +x tt_fail.sh
  /usr/bin/python3 "$DRIVER" --scheduler "$ADDR" --terratin "$W/tt_fail.sh" \
    ds.tif f.gpkg -max_error 6 -tile_size 128 >out.txt 2>err.txt
  rc=$?
  check "--scheduler: a failed tile: exit 1, named, nothing written" eval '[ $rc -eq 1 ] && grep -q "tile 5" err.txt && [ ! -e f.gpkg ]'
  stop_groups
fi

echo "$passed passed, $failed failed"
[ $failed -eq 0 ]
