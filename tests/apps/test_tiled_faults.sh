#!/usr/bin/env bash
# test_tiled_faults.sh -- a tiled run (`simplify -tile_size`, streamed into
# a GeoPackage as the tiles merge) meets what an untiled run meets, and says
# the same, through the terratin command ($TT_TERRATIN):
#  - a full disk (a 1 MiB tmpfs, when this user may mount one; a 513^2 DEM
#    at -max_error 0 fills it while tiles still run): exit 1, one line
#    "terratin: OUT: ... No space left on device" naming OUT once, on 1 and
#    2 threads,
#    as untiled, never "interrupted" (the workers that the failure stopped
#    are its consequence); nothing left;
#  - a GeoPackage GDAL makes with auto-vacuum or in WAL mode
#    (--config OGR_SQLITE_PRAGMA), whose file cannot take the rows as
#    pages: decided before the tiles run, the merged TIN then goes through
#    SQLite as an untiled run's does: exit 0, the same triangles as without
#    the pragma, PRAGMA integrity_check ok, the pragma kept.
# Prints "N passed, M failed"; exits 1 on any failure, 77 (skip) when a tool
# is missing.
set -u
. "$(dirname "${BASH_SOURCE[0]}")/tt_check.sh" || exit 1

T=${TT_TERRATIN:-}
if [ -z "$T" ] || [ ! -x "$T" ]; then
  echo "SKIP: TT_TERRATIN is not set or not executable"
  exit 77
fi
if ! python3 -c 'import sqlite3' 2>/dev/null; then
  echo "SKIP: python3 has no sqlite3 module"
  exit 77
fi

W=$(mktemp -d "${TMPDIR:-/tmp}/tt_tiled_faults.XXXXXX") || exit 1
MNT=""
cleanup() {
  [ -n "$MNT" ] && umount "$MNT" 2>/dev/null
  rm -rf "$W"
}
trap cleanup EXIT
cd "$W" || exit 1

"$T" generate diamond_square dem.tif -size 257 -seed 5 -q || exit 1
# a DEM whose TIN at -max_error 0 fills 1 MiB while tiles are still running
"$T" generate diamond_square big.tif -size 513 -seed 11 -q || exit 1
rc=0
not_grep() { ! grep -q "$@"; }
run() {
  "$T" "$@" >out.txt 2>err.txt
  rc=$?
}

# --- a full disk -------------------------------------------------------------
mkdir full
if [ "$(id -u)" = 0 ] && mount -t tmpfs -o size=1m tmpfs full 2>/dev/null; then
  MNT=$W/full
  for mode in "untiled" "tiled, 1 thread|-tile_size 64 -threads 1" \
              "tiled, 2 threads|-tile_size 64 -threads 2" \
              "tiled decimation, 2 threads|-tile_size 64 -threads 2 -method decimate"; do
    what=${mode%%|*}
    opts=""
    [ "$mode" != "$what" ] && opts=${mode#*|}
    # shellcheck disable=SC2086
    run simplify -q -max_error 0 $opts big.tif full/x.gpkg
    check "full disk, $what: exit 1 ($rc)" [ "$rc" = 1 ]
    check "full disk, $what: no space left, named ($(head -c 300 err.txt))" \
      grep -q '^terratin: full/x\.gpkg: .*[Nn]o space left on' err.txt
    check "full disk, $what: not 'interrupted'" not_grep interrupted err.txt
    check "full disk, $what: one line" [ "$(wc -l <err.txt)" = 1 ]
    check "full disk, $what: the output named once" \
      not_grep 'x\.gpkg: .*x\.gpkg' err.txt
    check "full disk, $what: nothing left ($(ls -A full | tr '\n' ' '))" \
      [ -z "$(ls -A full)" ]
  done
  umount full && MNT=""
else
  echo "note: cannot mount a tmpfs here; the full-disk cases are skipped"
fi

# --- auto-vacuum and WAL -----------------------------------------------------------
facts() { # triangles, auto_vacuum, integrity of GPKG $1
  python3 - "$1" <<'EOF'
import sqlite3, sys
c = sqlite3.connect(sys.argv[1])
print(c.execute("SELECT count(*) FROM triangles").fetchone()[0],
      c.execute("PRAGMA auto_vacuum").fetchone()[0],
      c.execute("PRAGMA integrity_check").fetchone()[0])
EOF
}
run simplify -q -max_error 0.5 -tile_size 64 -threads 2 dem.tif plain.gpkg
check "plain tiled run: exit 0 ($(head -c 300 err.txt))" [ "$rc" = 0 ]
NT=$(facts plain.gpkg | cut -d' ' -f1)
for p in "auto_vacuum=1|1 ok" "auto_vacuum=2|2 ok" "journal_mode=WAL|0 ok"; do
  pragma=${p%%|*}
  want=${p#*|}
  for th in 1 2; do
    out="p${th}_${pragma%%=*}_${pragma#*=}.gpkg"
    run --config OGR_SQLITE_PRAGMA "$pragma" simplify -q -max_error 0.5 \
      -tile_size 64 -threads "$th" dem.tif "$out"
    check "$pragma, $th thread(s): exit 0 ($(head -c 300 err.txt))" [ "$rc" = 0 ]
    check "$pragma, $th thread(s): $NT triangles, auto_vacuum as asked, intact ($(facts "$out" 2>&1))" \
      [ "$(facts "$out" 2>&1)" = "$NT $want" ]
  done
done
run --config OGR_SQLITE_PRAGMA auto_vacuum=1 simplify -q -max_error 0.5 \
  dem.tif whole.gpkg
check "auto_vacuum, untiled: the same decision ($(facts whole.gpkg 2>&1))" \
  [ "$rc" = 0 -a "$(facts whole.gpkg 2>&1 | cut -d' ' -f2-)" = "1 ok" ]
check "nothing hidden left ($(ls -A | grep '^\.tt' | tr '\n' ' '))" \
  [ -z "$(ls -A | grep '^\.tt')" ]

echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
