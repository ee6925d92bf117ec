#!/usr/bin/env bash
# test_limits.sh -- issue 11, "Messages and limits", end to end through the
# terratin command ($TT_TERRATIN): every message says its true cause (huge
# Float64 values, subnormal and 20-digit limits, missing archive members, a
# full disk, 100 kB names, memory), the parser is strict (hex, ---opt,
# --debug maybe) and matches names without regard to case, -srcnodata must
# fit the band's type, every limit is exact (a budget below the starting
# triangulation is refused with the count to ask for), -max_memory and
# ulimit -v stop a run cleanly with the phase and the size and write
# nothing, -threads and GDAL_NUM_THREADS give the same layers for every
# count, and undeclared fill values (-9999, -32000, -32767 runs) are warned
# about. Inputs are made in a mktemp folder with GDAL's tools; the shared
# DEMs (TT_SHARED_TESTDATA) are used when present. Prints "N passed, M
# failed"; exits 1 on any failure, 77 when a tool is missing.
set -u
. "$(dirname "${BASH_SOURCE[0]}")/../apps/tt_check.sh" || exit 1

T=${TT_TERRATIN:-}
if [ -z "$T" ] || [ ! -x "$T" ]; then
  echo "SKIP: TT_TERRATIN is not set or not executable"
  exit 77
fi
for tool in gdal_create gdal_translate ogrinfo python3 md5sum sqlite3; do
  if ! command -v "$tool" >/dev/null 2>&1; then
    echo "SKIP: $tool is missing"
    exit 77
  fi
done

W=$(mktemp -d "${TMPDIR:-/tmp}/tt_limits.XXXXXX") || exit 1
MOUNTED=""
cleanup() {
  [ -n "$MOUNTED" ] && umount "$MOUNTED" 2>/dev/null
  rm -rf "$W"
}
trap cleanup EXIT
cd "$W" || exit 1

rc=0
run() {
  "$T" "$@" >out.txt 2>err.txt
  rc=$?
}
lines() { wc -l <"$1" | tr -d ' '; }
has() { grep -q -- "$1" err.txt; }
json_get() {
  python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))[sys.argv[2]])' "$1" "$2"
}
# expect_failure NAME CODE NEEDLE ARGS...: terratin fails with CODE, one
# stderr line that contains NEEDLE, and out/ stays empty.
expect_failure() {
  local name=$1 code=$2 needle=$3
  shift 3
  run "$@"
  if [ "$rc" -eq "$code" ]; then pass; else
    fail "$name: exit code $rc, expected $code ($(head -c 400 err.txt))"
  fi
  if [ "$(lines err.txt)" = 1 ] && grep -q '^terratin: ' err.txt; then pass
  else fail "$name: stderr is not one 'terratin:' line: $(head -c 600 err.txt)"; fi
  if has "$needle"; then pass; else
    fail "$name: message lacks '$needle': $(head -c 600 err.txt)"
  fi
  if [ -z "$(ls -A out)" ]; then pass; else
    fail "$name: left files behind in out: $(ls -A out)"; rm -rf out/* out/.[!.]*
  fi
}

mkdir in out
run generate fault in/f.tif -size 200x150 -seed 5 -displacement 20 -wave_size 5 -q
check "generate: exit 0 ($(cat err.txt))" [ "$rc" -eq 0 ]
# a DEM with declared nodata: ragged edges and a hole, so the outline
# forces vertices of its own
python3 - <<'EOF'
import math
nx, ny = 60, 50
rows = []
for r in range(ny):
    row = []
    for c in range(nx):
        hole = (c - 30) ** 2 + (r - 25) ** 2 < 64
        edge = c < (r * 7) % 5 or c > nx - 1 - (r * 3) % 4
        row.append("-9999" if hole or edge else "%.2f" % (100 + 10 * math.sin(c / 5.0) * math.cos(r / 7.0)))
    rows.append(" ".join(row))
open("in/hole.asc", "w").write("ncols %d\nnrows %d\nxllcorner 0\nyllcorner 0\ncellsize 10\nNODATA_value -9999\n%s\n" % (nx, ny, "\n".join(rows)))
EOF

# --- exact limits: a budget below the starting triangulation is refused ---
for n in 1 2 3; do
  expect_failure "-max_points $n" 2 "ask for at least 4" simplify -q -max_points $n in/f.tif out/x.gpkg
done
expect_failure "-max_triangles 1" 2 "ask for at least 2" simplify -q -max_triangles 1 in/f.tif out/x.gpkg
expect_failure "-percent below 4 vertices" 2 "from the percentage" simplify -q -percent 0.001 in/f.tif out/x.gpkg
run simplify -q -json -max_points 4 in/f.tif out/p4.gpkg
check "-max_points 4: exit 0 ($(cat err.txt))" [ "$rc" -eq 0 ]
check "-max_points 4: 4 vertices, no warning" \
  bash -c "[ \"\$(python3 -c 'import json; print(json.load(open(\"out.txt\"))[\"vertices\"])')\" = 4 ] && [ ! -s err.txt ]"
rm -f out/*
expect_failure "-max_points 300 on a nodata DEM" 2 "forced by the nodata outline" simplify -q -max_points 30 in/hole.asc out/x.gpkg
need=$(sed -n 's/.*ask for at least \([0-9]*\).*/\1/p' err.txt)
check "the refusal names the count ($need)" [ -n "$need" ]
if [ -n "$need" ]; then
  run simplify -q -json -max_points "$need" in/hole.asc out/h.gpkg
  check "-max_points $need: exit 0 ($(cat err.txt))" [ "$rc" -eq 0 ]
  v=$(json_get out.txt vertices 2>/dev/null)
  check "-max_points $need: at most $need vertices (got $v)" eval '[ -n "$v" ] && [ "$v" -le "$need" ]'
  rm -f out/*
  expect_failure "-max_points $((need - 1))" 2 "at least $need" simplify -q -max_points $((need - 1)) in/hole.asc out/x.gpkg
  rm -f out/*
  # decimation takes the same budgets: below the outline refused before
  # any work (it wrote a TIN of RMSE 312 m with exit 0), at it exact
  expect_failure "decimate -max_points $((need - 1))" 2 "ask for at least $need" \
    simplify -q -method decimate -max_points $((need - 1)) in/hole.asc out/x.gpkg
  rm -f out/*
  for n in "$need" $((need + 40)); do
    run simplify -q -json -method decimate -max_points "$n" in/hole.asc out/d.gpkg
    check "decimate -max_points $n: exit 0 ($(cat err.txt))" [ "$rc" -eq 0 ]
    check "decimate -max_points $n: $n vertices" \
      [ "$(json_get out.txt vertices 2>/dev/null)" = "$n" ]
    rm -f out/*
  done
fi
# a lone valid sample on the hull (a corner amid nodata) is in no triangle
# and not written: the budget counts the TIN's vertices, so -max_points N
# gives N (it gave N - 1)
python3 - <<'EOF'
import math
nx, ny = 60, 50
rows = []
for r in range(ny):
    row = []
    for c in range(nx):
        lone_corner = (r, c) == (0, 0)
        near = r < 3 and c < 3
        hole = (c - 30) ** 2 + (r - 25) ** 2 < 64
        z = "%.2f" % (100 + 10 * math.sin(c / 5.0) * math.cos(r / 7.0))
        row.append(z if lone_corner or not (near or hole) else "-9999")
    rows.append(" ".join(row))
open("in/lone.asc", "w").write("ncols %d\nnrows %d\nxllcorner 0\nyllcorner 0\ncellsize 10\nNODATA_value -9999\n%s\n" % (nx, ny, "\n".join(rows)))
EOF
for n in 200 333; do
  run simplify -q -json -max_points $n in/lone.asc out/l.gpkg
  check "lone hull sample, -max_points $n: $n vertices (got $(json_get out.txt vertices 2>/dev/null))" \
    [ "$(json_get out.txt vertices 2>/dev/null)" = "$n" ]
  rm -f out/*
done

# --- memory: -max_memory, counted as the mesh grows; ulimit -v ---
expect_failure "-max_memory 2M, dense TIN" 1 "while inserting" simplify -q -max_error 0 -max_memory 2M in/f.tif out/x.gpkg
check "-max_memory: names the size and the limit" \
  bash -c "grep -q 'more than the memory limit of 2.0 MiB (-max_memory); nothing written' err.txt && grep -q 'needs [0-9.]* MiB' err.txt"
expect_failure "-max_memory 64K: the heights alone" 1 "refused before reading" simplify -q -max_memory 64K in/f.tif out/x.gpkg
run simplify -q -max_error 0 -max_memory 1G in/f.tif out/m.gpkg
check "-max_memory 1G: exit 0 ($(cat err.txt))" [ "$rc" -eq 0 ]
rm -f out/*
gdal_translate -q -of VRT -outsize 20000 20000 in/f.tif in/huge.vrt
if (ulimit -v 600000 && "$T" --version >/dev/null 2>&1); then
  ( ulimit -v 900000; "$T" simplify -q -max_error 0 in/f.tif out/u.gpkg >out.txt 2>err.txt ); rc=$?
  check "ulimit -v, a small DEM: exit 0 ($(cat err.txt))" [ "$rc" -eq 0 ]
  # a command that reads the whole DEM (simplify tiles it instead:
  # test_auto_tiling.sh)
  ( ulimit -v 600000; "$T" rasterize -q in/huge.vrt out/u.gpkg out/x.tif >out.txt 2>err.txt ); rc=$?
  check "ulimit -v: exit 1 (got $rc)" [ "$rc" -eq 1 ]
  check "ulimit -v: names the limit and the size ($(cat err.txt))" \
    bash -c "grep -q 'ulimit -v' err.txt && grep -q '1.5 GiB' err.txt && [ \$(wc -l <err.txt) = 1 ]"
  check "ulimit -v: nothing written" [ ! -e out/x.tif ]
  rm -f out/*
else
  echo "note: the command does not start under ulimit -v (sanitizer build); ulimit checks skipped"
fi

# --- threads: the same layers for every count ---
run generate diamond_square in/ds.tif -size 513 -seed 3 -q
# the layers' content: a SHA3 of every row of triangles and vertices, in
# rowid order, every column, blobs byte for byte (the sqlite3 shell's
# sha3_query): equal when `ogrinfo -al` of the layers would be, to the last
# bit rather than to its 15 digits, in a tenth of its time; an unreadable
# file prints its name, so two never compare equal
dump() {
  sqlite3 -readonly "$1" "select hex(sha3_query('select * from triangles order by rowid; select * from vertices order by rowid'))" 2>&1 ||
    echo "error: $1"
}
ref=""
for n in 1 2 4; do
  run simplify -q -threads $n -max_error 6 in/ds.tif out/t$n.gpkg
  check "-threads $n: exit 0 ($(cat err.txt))" [ "$rc" -eq 0 ]
  d=$(dump out/t$n.gpkg)
  [ -z "$ref" ] && ref=$d
  check "-threads $n: same layers as -threads 1" [ "$d" = "$ref" ]
done
GDAL_NUM_THREADS=3 "$T" simplify -q -max_error 6 in/ds.tif out/g3.gpkg 2>err.txt
check "GDAL_NUM_THREADS=3: same layers" [ "$(dump out/g3.gpkg)" = "$ref" ]
run --config GDAL_NUM_THREADS ALL_CPUS simplify -q -max_error 6 in/ds.tif out/ga.gpkg
check "--config GDAL_NUM_THREADS ALL_CPUS: same layers" [ "$(dump out/ga.gpkg)" = "$ref" ]
GDAL_NUM_THREADS=lots "$T" simplify -q -max_error 6 in/ds.tif out/gl.gpkg 2>err.txt
check "GDAL_NUM_THREADS=lots: warned about" has "GDAL_NUM_THREADS='lots'"
rm -f out/*

# --- undeclared fill values ---
python3 - <<'EOF'
import math
for name, fill in (("m9999", -9999), ("m32000", -32000), ("m32767", -32767)):
    rows = []
    for r in range(40):
        row = []
        for c in range(50):
            v = int(500 + 40 * math.sin(c / 6.0) + 30 * math.cos(r / 4.0))
            if r in (10, 11) and 5 <= c < 30:
                v = fill
            row.append(str(v))
        rows.append(" ".join(row))
    open("in/%s.asc" % name, "w").write("ncols 50\nnrows 40\nxllcorner 0\nyllcorner 0\ncellsize 30\n%s\n" % "\n".join(rows))
EOF
for f in m9999:-9999 m32000:-32000 m32767:-32767; do
  name=${f%%:*} val=${f#*:}
  gdal_translate -q -ot Int16 in/$name.asc in/$name.tif
  run simplify -q -max_error 5 in/$name.tif out/$name.gpkg
  check "fill $val: exit 0" [ "$rc" -eq 0 ]
  check "fill $val: warned, with -srcnodata $val ($(cat err.txt))" \
    bash -c "grep -q 'undeclared nodata' err.txt && grep -q -- '-srcnodata $val treats' err.txt"
  run simplify -q -overwrite -srcnodata "$val" -max_error 5 in/$name.tif out/$name.gpkg
  check "fill $val with -srcnodata: no warning ($(cat err.txt))" [ ! -s err.txt ]
done
# a grid of doubles (Float64 band) is scanned as well
gdal_translate -q -ot Float64 in/m9999.asc in/m9999_f64.tif
run simplify -q -max_error 5 in/m9999_f64.tif out/f64fill.gpkg
check "fill -9999 in a Float64 band: warned ($(cat err.txt))" has "srcnodata -9999 treats"
run simplify -q -max_error 5 in/f.tif out/nofill.gpkg
check "no fill value: no warning ($(cat err.txt))" [ ! -s err.txt ]
rm -f out/*
S=${TT_SHARED_TESTDATA:-}
for f in gdalraster/storm_lake.lcp:-9999 gdal_autotest/usgsdem_edge_cases/4619old_truncated.dem:-32000; do
  p=${f%%:*} val=${f#*:}
  if [ -n "$S" ] && [ -f "$S/$p" ]; then
    run simplify -q -max_error 5 "$S/$p" out/shared.gpkg
    check "$p: warned about $val ($(head -c 300 err.txt))" has "srcnodata $val treats"
    rm -f out/*
  else
    echo "note: $p not in TT_SHARED_TESTDATA; its fill value check skipped"
  fi
done

# --- messages that say the true cause ---
gdal_create -q -ot Float64 -outsize 4 4 -burn 1e300 in/f64.tif
expect_failure "Float64 1e300" 1 "is 1e+300, beyond the" simplify -q in/f64.tif out/x.gpkg
check "Float64 1e300: not called infinite" bash -c '! grep -q infinite err.txt'
expect_failure "-srcnodata 1e39 on Float32" 2 "type Float32 cannot hold it" simplify -q -srcnodata 1e39 in/f.tif out/x.gpkg
gdal_translate -q -ot Int16 in/f.tif in/i16.tif
expect_failure "-srcnodata 0.5 on Int16" 2 "Int16 holds whole numbers only" simplify -q -srcnodata 0.5 in/i16.tif out/x.gpkg
expect_failure "-srcnodata nan on Int16" 2 "Int16 cannot hold it" eval -srcnodata nan in/i16.tif in/none.gpkg
if command -v zip >/dev/null 2>&1; then
  (cd in && zip -q d.zip f.tif)
  expect_failure "/vsizip/ missing member" 1 "the archive in/d.zip holds no 'g.tif'" simplify -q /vsizip/in/d.zip/g.tif out/x.gpkg
  expect_failure "/vsizip/ missing archive" 1 "does not exist" simplify -q /vsizip/in/nothing.zip/g.tif out/x.gpkg
  expect_failure "/vsizip/ on a non-archive" 1 "in/f.tif is not an archive" simplify -q /vsizip/in/f.tif/g.tif out/x.gpkg
fi
run simplify -q -max_error 1e-320 in/f.tif out/sub.gpkg
check "-max_error 1e-320: accepted ($(cat err.txt))" [ "$rc" -eq 0 ]
rm -f out/*
expect_failure "-max_points 20 digits" 2 "above the limit" simplify -max_points 99999999999999999999 in/f.tif out/x.gpkg
expect_failure "-max_error 0x10" 2 "-max_error must be" simplify -max_error 0x10 in/f.tif out/x.gpkg
expect_failure "---max_error" 2 "unknown option '---max_error'" simplify ---max_error 1 in/f.tif out/x.gpkg
expect_failure "--debug maybe" 2 "--debug must be" --debug maybe simplify in/f.tif out/x.gpkg
run simplify -q -criterion DELAUNAY -repair FLIP -optimize None in/f.tif out/c.gpkg
check "-criterion DELAUNAY -repair FLIP -optimize None: exit 0 ($(cat err.txt))" [ "$rc" -eq 0 ]
rm -f out/*
# a 100 kB name: the message keeps the cause at its end
long=$(python3 -c 'print("n" * 100000)')
expect_failure "100 kB input name" 1 "too long for the file system" simplify -q "in/$long.tif" out/x.gpkg
check "100 kB input name: a short line" [ "$(wc -c <err.txt)" -lt 1100 ]
mid=$(python3 -c 'print("/".join(["d" * 200] * 8))')
expect_failure "1.6 kB missing folder" 1 "x.gpkg: cannot write in folder out/ddd" simplify -q in/f.tif "out/$mid/x.gpkg"
check "1.6 kB missing folder: shortened in the middle, the cause at the end" \
  bash -c "grep -q 'ddd\.\.\.ddd' err.txt && grep -q 'No such file or directory\$' err.txt"
# a full file system and the file size limit: the device is named first
( ulimit -f 64; trap '' XFSZ; "$T" simplify -q -max_error 0 in/f.tif out/fs.gpkg >out.txt 2>err.txt ); rc=$?
check "ulimit -f: exit 1 ($rc)" [ "$rc" -eq 1 ]
check "ulimit -f: says so ($(head -c 200 err.txt))" grep -q '^terratin: out/fs.gpkg: the file size limit (ulimit -f)' err.txt
check "ulimit -f: nothing written" [ -z "$(ls -A out)" ]
mkdir full
if [ "$(id -u)" = 0 ] && mount -t tmpfs -o size=64k tmpfs full 2>/dev/null; then
  MOUNTED=$W/full
  run simplify -q -max_error 0 in/f.tif full/x.gpkg
  check "full disk: exit 1 ($rc)" [ "$rc" -eq 1 ]
  check "full disk: no space left ($(head -c 200 err.txt))" grep -q '^terratin: full/x.gpkg: no space left on the device of full' err.txt
  check "full disk: nothing left" [ -z "$(ls -A full)" ]
  umount full && MOUNTED=""
else
  echo "note: cannot mount a small tmpfs (not root?); full-disk check skipped"
fi

echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
