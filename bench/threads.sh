#!/usr/bin/env bash
# bench/threads.sh [SIZE [TILE [ERROR [ROUNDS [WORK]]]]] -- issue 19's
# thread scaling of tiled runs (docs/scale.md, "Thread scaling"): a SIZE^2
# diamond-square fractal (default 8193, seed 1; kept in WORK if given),
# `simplify -tile_size TILE -max_error ERROR` (defaults 1024 and 3.44597,
# the 8193^2 bound that keeps about 1 % of the samples) run ROUNDS times
# (default 3) on -threads 1 and 2 alternately (1, 2, 1, 2, ...), so that a
# change of the machine's load falls on both. Every run prints its wall
# seconds, user and system CPU seconds, peak memory (GNU time) and the
# seconds of its phases (simplify -json: read + simplify, the tiles
# refined in parallel and merged; write, the GeoPackage, serial) and the
# 1-minute load average from /proc/loadavg just before and just after it;
# then the fastest run of each thread count, and whether the layers of
# the two are the same (md5 of ogrinfo -al).
set -eu
SIZE=${1:-8193}
TILE=${2:-1024}
E=${3:-3.44597}
ROUNDS=${4:-3}
HERE=$(cd "$(dirname "$0")/.." && pwd)
T=${TT_TERRATIN:-$HERE/build/terratin}
WORK=${5:-}
KEEP=1
if [ -z "$WORK" ]; then
  WORK=$(mktemp -d "${TMPDIR:-/tmp}/tt_threads.XXXXXX")
  KEEP=0
fi
mkdir -p "$WORK"
cd "$WORK"
[ "$KEEP" = 1 ] || trap 'rm -rf "$WORK"' EXIT
DEM=ds$SIZE.tif
[ -f "$DEM" ] || "$T" generate diamond_square "$DEM" -size "$SIZE" -seed 1 -q
load1() { cut -d' ' -f1 /proc/loadavg; }
echo "$(nproc) cores; $(uptime)"
: >runs.txt
for r in $(seq 1 "$ROUNDS"); do
  for th in 1 2; do
    l0=$(load1)
    /usr/bin/time -f "%e %U %S %M" -o t.time "$T" simplify -q -json -overwrite \
      -max_error "$E" -tile_size "$TILE" -threads "$th" "$DEM" "t$th.gpkg" >t.json
    l1=$(load1)
    read -r wall user sys kib <t.time
    cpu=$(awk -v u="$user" -v s="$sys" 'BEGIN { printf "%.2f", u + s }')
    # the phases simplify reports: the tiles (read + simplify: windows read
    # and refined in parallel, merged) and the write (serial)
    read -r tiles write < <(python3 -c 'import json, sys
s = json.load(open(sys.argv[1]))["seconds"]
print("%.2f %.2f" % (s["read"] + s["simplify"], s["write"]))' t.json)
    printf 'round %d  -threads %d  wall %6.2f s  user %6.2f s  sys %5.2f s  cpu %6.2f s  peak %4d MiB  (tiles %5.2f s, write %5.2f s)  load %s -> %s\n' \
      "$r" "$th" "$wall" "$user" "$sys" "$cpu" "$((kib / 1024))" "$tiles" "$write" "$l0" "$l1"
    echo "$th $wall $cpu $((kib / 1024)) $l0 $l1 $tiles $write" >>runs.txt
  done
done
for th in 1 2; do
  awk -v th="$th" '$1 == th' runs.txt | sort -k2,2g | head -1 |
    awk '{ printf "fastest, -threads %d: wall %.2f s, cpu %.2f s, peak %d MiB, tiles %.2f s, write %.2f s, load %s -> %s\n", $1, $2, $3, $4, $7, $8, $5, $6 }'
done
md5() { ogrinfo -ro -al -q "$1" triangles vertices 2>/dev/null | md5sum | cut -d' ' -f1; }
if [ "$(md5 t1.gpkg)" = "$(md5 t2.gpkg)" ]; then
  echo "threads 1 and 2: the same layers"
else
  echo "threads 1 and 2: DIFFERENT layers"
fi
