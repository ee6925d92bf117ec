#!/usr/bin/env bash
# test_long_tiles.sh -- the long tier (ctest label `long`, `make check-long`;
# not in `make check`): the tiled-run properties of test_tiles.sh and
# test_tiles_methods.sh at the sizes where they were first measured, for
# a change to the tiling, the merge or the streamed writer:
#  - an 8193^2 diamond-square fractal (seed 1) at max error 3.446 (about
#    1 % of the samples, docs/scale.md) in tiles of 1024 on 2 threads:
#    the GeoPackage written as the tiles merge the same as the merged TIN's
#    (streamed_vs_merged), within 5 % of the untiled vertex count,
#    conforming (tin_topology.py, Euler characteristic 1), every sample
#    within the bound by `terratin eval`; 1 thread the same layers, and
#    the seconds of each thread count printed (their ratio is
#    bench/threads.sh's business: here the load of a shared machine would
#    make any bound on it flaky);
#  - the whole of Mt Hood (1013 x 799, nodata collar) and Vinschgau at max
#    error 20 in tiles of 128, inserted and decimated (each untiled and in
#    tiles), streamed against merged (real_dems with REAL_FULL=1), when
#    TT_SHARED_TESTDATA has them.
# About 4 minutes in Release on 2 cores (README, "Tests"). Prints "N
# passed, M failed"; exits 1 on any failure, 77 when a tool is missing.
set -u
. "$(dirname "${BASH_SOURCE[0]}")/../apps/tt_check.sh" || exit 1
. "$(dirname "${BASH_SOURCE[0]}")/../apps/tt_tiles_lib.sh" || exit 1

SIZE=${TT_LONG_SIZE:-8193} # smaller to try the test itself
E=3.446
secs() { python3 -c 'import sys; print("%.1f" % (float(sys.argv[2]) - float(sys.argv[1])))' "$1" "$2"; }

t0=$EPOCHREALTIME
run generate diamond_square in/big.tif -size "$SIZE" -seed 1 -q
check "generate ${SIZE}^2: exit 0 ($(cat err.txt))" [ "$rc" -eq 0 ]
echo "note: ${SIZE}^2 generated in $(secs "$t0" "$EPOCHREALTIME") s"

t0=$EPOCHREALTIME
run simplify -q -json -max_error $E -threads 2 in/big.tif out/u.gpkg
check "untiled: exit 0 ($(cat err.txt))" [ "$rc" -eq 0 ]
cp out.txt u.json
echo "note: untiled, 2 threads: $(jget u.json vertices) vertices in $(secs "$t0" "$EPOCHREALTIME") s"

t0=$EPOCHREALTIME
streamed_vs_merged "${SIZE}^2, tiles of 1024, 2 threads" in/big.tif -max_error $E -tile_size 1024 -threads 2
echo "note: tiles of 1024 streamed and merged, 2 threads: $(secs "$t0" "$EPOCHREALTIME") s for both"
mv out/sv_s.gpkg out/t2.gpkg
cp s.json t2.json
nu=$(jget u.json vertices)
nv=$(jget t2.json vertices)
echo "note: ${SIZE}^2 at $E: tiles of 1024: $nv vertices, untiled $nu"
check "tiles of 1024: vertices $nv within 5 % of untiled $nu" within "$nv" "$nu" 5
conforming "${SIZE}^2, tiles of 1024" out/t2.gpkg
bounded "${SIZE}^2, tiles of 1024" in/big.tif out/t2.gpkg $E
check "${SIZE}^2: none uncovered" [ "$(jget eval.json uncovered)" = 0 ]

t0=$EPOCHREALTIME
run simplify -q -json -max_error $E -tile_size 1024 -threads 1 in/big.tif out/t1.gpkg
check "tiles of 1024, 1 thread: exit 0 ($(cat err.txt))" [ "$rc" -eq 0 ]
t1s=$(secs "$t0" "$EPOCHREALTIME")
t0=$EPOCHREALTIME
run simplify -q -json -max_error $E -tile_size 1024 -threads 2 in/big.tif out/t2b.gpkg
t2s=$(secs "$t0" "$EPOCHREALTIME")
echo "note: tiles of 1024: 1 thread $t1s s, 2 threads $t2s s (load $(cut -d' ' -f1 /proc/loadavg))"
check "tiles of 1024: threads 1 vs 2, the same layers" [ "$(dump out/t1.gpkg)" = "$(dump out/t2.gpkg)" ]
rm -f out/*.gpkg

# --- the real DEMs whole, inserted and decimated ---
REAL_FULL=1 real_dems ""
REAL_FULL=1 real_dems ", decimation" -method decimate

echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
