#!/usr/bin/env bash
# test_estimate.sh -- issue 27, "Memory and size, said before the work",
# through the terratin command ($TT_TERRATIN): simplify's estimate from a
# sample of the DEM (apps/simplify/estimate.c). On a tight bound (a 257^2
# fractal at -max_error 0.2 keeps most of its samples) the JSON's
# "estimate" has every field, predicts the vertices and the GeoPackage's
# bytes within a factor of 2 (bench/estimate.sh measures the real DEMs),
# and its 5 % bound keeps about 5 %; a budget has no estimate. Before a
# long run (a 2049^2 fractal at -max_error 0.5: about 3.3 million
# vertices, 2.3 GB), the line on stderr comes before the work, with the
# share, the vertices, the size and the bound of a 5 % TIN: the run is
# stopped (SIGTERM) once it is there, and leaves nothing. Prints "N
# passed, M failed"; exits 1 on any failure, 77 when it cannot run.
set -u
. "$(dirname "${BASH_SOURCE[0]}")/tt_check.sh" || exit 1

T=${TT_TERRATIN:-}
if [ -z "$T" ] || [ ! -x "$T" ]; then
  echo "SKIP: TT_TERRATIN is not set or not executable"
  exit 77
fi
W=$(mktemp -d "${TMPDIR:-/tmp}/tt_estimate.XXXXXX") || exit 1
pid=""
trap '[ -n "$pid" ] && kill -9 "$pid" 2>/dev/null; rm -rf "$W"' EXIT
cd "$W" || exit 1
mkdir in out
jget() { python3 -c 'import json, sys
d = json.load(open(sys.argv[1]))
for k in sys.argv[2].split("."):
    d = d.get(k) if isinstance(d, dict) else None
print(d)' "$1" "$2"; }
within2() { python3 -c "import sys; sys.exit(not 0.5 <= $1 / $2 <= 2)"; }

"$T" generate diamond_square in/ds257.tif -size 257 -seed 2 -q || exit 1
"$T" simplify -q -json -max_error 0.2 in/ds257.tif out/t.gpkg >t.json 2>err.txt
rc=$?
check "tight bound: exit 0 ($(cat err.txt))" [ "$rc" -eq 0 ]
check "tight bound: no line on stderr with -q" [ ! -s err.txt ]
for k in max_error max_error_default vertices triangles valid_samples share \
         output_bytes memory_untiled max_error_5_percent windows window_size \
         sampled_cells seconds; do
  check "estimate.$k is there" [ "$(jget t.json "estimate.$k")" != None ]
done
check "estimate.max_error is the bound" [ "$(jget t.json estimate.max_error)" = 0.2 ]
check "estimate.valid_samples: the DEM's" [ "$(jget t.json estimate.valid_samples)" = 66049 ]
nv=$(jget t.json vertices)
check "estimate.vertices within 2 ($(jget t.json estimate.vertices) for $nv)" \
  within2 "$(jget t.json estimate.vertices)" "$nv"
check "estimate.share: most samples ($(jget t.json estimate.share))" \
  python3 -c "import sys; sys.exit(not $(jget t.json estimate.share) > 0.5)"
check "estimate.triangles: about twice the vertices" \
  python3 -c "import sys; sys.exit(not 1.9 < $(jget t.json estimate.triangles) / $(jget t.json estimate.vertices) <= 2)"
bytes=$(stat -c %s out/t.gpkg)
check "estimate.output_bytes within 2 ($(jget t.json estimate.output_bytes) for $bytes)" \
  within2 "$(jget t.json estimate.output_bytes)" "$bytes"
check "estimate.windows: a sample, not the DEM ($(jget t.json estimate.sampled_cells) cells)" \
  python3 -c "import sys; sys.exit(not 0 < $(jget t.json estimate.sampled_cells) <= 66049 / 4)"
five=$(jget t.json estimate.max_error_5_percent)
"$T" simplify -q -json -max_error "$five" in/ds257.tif out/five.gpkg >five.json 2>err.txt
check "the 5 % bound ($five) keeps 2.5 to 10 % ($(jget five.json vertices) of 66049)" \
  python3 -c "import sys; sys.exit(not 0.025 <= $(jget five.json vertices) / 66049 <= 0.10)"
"$T" simplify -q -json -max_points 500 in/ds257.tif out/b.gpkg >b.json 2>err.txt
check "a budget: estimate null" grep -q '"estimate": null' b.json

# before a long run: the line, then the work (stopped here)
"$T" generate diamond_square in/ds2049.tif -size 2049 -seed 1 -q || exit 1
"$T" simplify -max_error 0.5 in/ds2049.tif out/long.gpkg >long.out 2>long.err &
pid=$!
i=0
while ! grep -q "this bound" long.err && [ "$i" -lt 600 ] && kill -0 "$pid" 2>/dev/null; do
  sleep 0.05
  i=$((i + 1))
done
kill -TERM "$pid" 2>/dev/null
wait "$pid" 2>/dev/null
pid=""
check "long run: the line on stderr ($(head -c 300 long.err))" \
  grep -q '^terratin: in/ds2049.tif: this bound (0.5) keeps about [0-9.]*% of the samples (~[0-9]* vertices, ~[0-9.]* [MG]B); -max_error [0-9.e+-]* gives about a 5% TIN$' long.err
n=$(sed -n 's/.*(~\([0-9]*\) vertices.*/\1/p' long.err)
check "long run: more than a million vertices predicted ($n)" [ "${n:-0}" -gt 1000000 ]
check "long run: the line came before the work (the bar had not passed 10: $(head -c 40 long.out))" \
  bash -c '! grep -q "20" long.out'
check "long run: stopped, nothing left ($(ls -A out | grep -v '^t.gpkg$\|^five.gpkg$\|^b.gpkg$' | tr '\n' ' '))" \
  [ -z "$(ls -A out | grep -v '^t.gpkg$\|^five.gpkg$\|^b.gpkg$')" ]

echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
