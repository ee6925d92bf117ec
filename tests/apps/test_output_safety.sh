#!/usr/bin/env bash
# test_output_safety.sh -- what -overwrite may and may not do, through the
# terratin command ($TT_TERRATIN), issue 11 items 2-8:
#  - SQLite sidecars: a crashed writer's hot journal and a killed WAL
#    connection's -wal/-shm are not applied to the new GeoPackage
#    (PRAGMA integrity_check says ok); a live WAL connection held by another
#    process (python3's sqlite3) refuses the run in one line, old file intact;
#  - the input is never replaced: GPKG:file:table, /vsizip/ archives, VRT
#    sources (nested too), a shapefile layer file;
#  - no empty TIN (checkerboard nodata), no vertex in no triangle;
#  - folder outputs (FlatGeobuf, MapInfo): nothing left on failure (a full
#    tmpfs when mounting is allowed), -overwrite replaces them, a folder
#    under a file's name is refused;
#  - SIGTERM and SIGINT during a slow LIBKML write end the run within 2 s
#    with nothing left;
#  - triangles counter-clockwise in the written coordinates (no
#    geotransform, south-up, generate's own output, -t_srs mirroring x);
#  - FIFOs and symbolic links are not replaced;
#  - generate refuses parameters giving non-finite heights; a 255-byte
#    output name works.
# Prints "N passed, M failed"; exits 1 on any failure, 77 (skip) when a tool
# is missing.
set -u
. "$(dirname "${BASH_SOURCE[0]}")/../apps/tt_check.sh" || exit 1

T=${TT_TERRATIN:-}
if [ -z "$T" ] || [ ! -x "$T" ]; then
  echo "SKIP: TT_TERRATIN is not set or not executable"
  exit 77
fi
for tool in gdal_translate gdalbuildvrt ogrinfo python3 zip mkfifo; do
  if ! command -v "$tool" >/dev/null 2>&1; then
    echo "SKIP: $tool is missing"
    exit 77
  fi
done
if ! python3 -c 'import sqlite3' 2>/dev/null; then
  echo "SKIP: python3 has no sqlite3 module"
  exit 77
fi

W=$(mktemp -d "${TMPDIR:-/tmp}/tt_safety.XXXXXX") || exit 1
MNT=""
HOLDER=""
cleanup() {
  [ -n "$HOLDER" ] && kill -9 "$HOLDER" 2>/dev/null
  [ -n "$MNT" ] && umount "$MNT" 2>/dev/null
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
# refused NAME ARGS...: exit 1 and one "terratin:" line on stderr.
refused() {
  local name=$1
  shift
  run "$@"
  if [ "$rc" -eq 1 ]; then pass; else
    fail "$name: exit code $rc, expected 1 ($(head -c 300 err.txt))"; fi
  if [ "$(grep -vc '^terratin: warning' err.txt)" = 1 ] &&
     grep -v '^terratin: warning' err.txt | grep -q '^terratin: '; then pass
  else fail "$name: stderr is not one 'terratin:' line: $(cat err.txt)"; fi
}
# no_temp DIR: no temporary name of terratin's in DIR.
no_temp() { [ -z "$(ls -A "$1" | grep '^\.tt')" ]; }
integrity() {
  python3 - "$1" <<'EOF'
import sqlite3, sys
try:
    r = sqlite3.connect(sys.argv[1]).execute("PRAGMA integrity_check").fetchall()
except sqlite3.DatabaseError as e:
    r = [(str(e),)]
if r != [("ok",)]:
    print("integrity_check: %s" % r[0][0], file=sys.stderr)
    sys.exit(1)
EOF
}
# ccw FILE [LAYER]: every polygon of the layer has a positive signed area.
ccw() {
  ogrinfo -q "$1" "${2:-triangles}" 2>/dev/null | python3 -c '
import re, sys
pos = neg = 0
for m in re.finditer(r"POLYGON Z \(\((.*?)\)\)", sys.stdin.read()):
    p = [tuple(map(float, q.split()[:2])) for q in m.group(1).split(",")]
    a = sum(p[i][0] * p[i + 1][1] - p[i + 1][0] * p[i][1]
            for i in range(len(p) - 1))
    pos, neg = (pos + 1, neg) if a > 0 else (pos, neg + 1)
if neg or not pos:
    print("%d counter-clockwise, %d not" % (pos, neg), file=sys.stderr)
sys.exit(0 if pos and not neg else 1)'
}

mkdir in
run generate fault in/fault.tif -size 80x60 -seed 3 -wave_size 4 -q
check "generate: exit 0" [ "$rc" -eq 0 ]
# a north-up copy with a CRS (GPKG rasters need north-up)
gdal_translate -q -a_srs EPSG:32633 -a_ullr 500000 4000600 500800 4000000 \
  in/fault.tif in/north.tif

# --- 2. SQLite sidecars --------------------------------------------------------
mkdir side
run simplify -q -max_error 2 in/north.tif side/tin.gpkg
check "sidecars: first write" [ "$rc" -eq 0 ]
# a crashed writer: a transaction big enough to spill to the file, then
# the process dies; its hot journal stays
python3 - side/tin.gpkg <<'EOF'
import os, sqlite3, sys
c = sqlite3.connect(sys.argv[1], isolation_level=None)
c.execute("PRAGMA journal_mode=DELETE")
c.execute("PRAGMA cache_size=2")
c.execute("BEGIN")
c.execute("CREATE TABLE junk(x)")
for i in range(3000):
    c.execute("INSERT INTO junk VALUES (randomblob(1000))")
os._exit(0)
EOF
check "sidecars: the crashed writer left a journal" [ -s side/tin.gpkg-journal ]
refused "sidecars: existing output and journal without -overwrite" \
  simplify -q -max_error 1 in/north.tif side/tin.gpkg
mv side/tin.gpkg side/keep.gpkg
refused "sidecars: a journal whose database is gone, without -overwrite" \
  simplify -q -max_error 1 in/north.tif side/tin.gpkg
check "sidecars: the refusal names the journal" grep -q -- "-journal" err.txt
check "sidecars: nothing written beside the journal" [ ! -e side/tin.gpkg ]
mv side/keep.gpkg side/tin.gpkg
run simplify -q -overwrite -max_error 1 in/north.tif side/tin.gpkg
check "sidecars: -overwrite over a stale journal: exit 0 ($(cat err.txt))" \
  [ "$rc" -eq 0 ]
check "sidecars: the journal is gone" [ ! -e side/tin.gpkg-journal ]
check "sidecars: integrity_check ok after a crashed writer" \
  integrity side/tin.gpkg
check "sidecars: no temporary file" no_temp side

# a live WAL connection in another process
python3 - side/tin.gpkg side/ready <<'EOF' &
import sqlite3, sys, time
c = sqlite3.connect(sys.argv[1], isolation_level=None)
c.execute("PRAGMA journal_mode=WAL")
c.execute("CREATE TABLE IF NOT EXISTS junk2(x)")
for i in range(200):
    c.execute("INSERT INTO junk2 VALUES (randomblob(1000))")
open(sys.argv[2], "w").close()
time.sleep(120)
EOF
HOLDER=$!
for i in $(seq 100); do [ -e side/ready ] && break; sleep 0.1; done
check "sidecars: the WAL holder is ready" [ -e side/ready ]
rm -f side/ready
check "sidecars: the holder has a -wal" [ -s side/tin.gpkg-wal ]
before=$(cksum <side/tin.gpkg)
refused "sidecars: live WAL connection" simplify -q -overwrite -max_error 1 \
  in/north.tif side/tin.gpkg
check "sidecars: the refusal says the file is open" grep -q "open in another" err.txt
check "sidecars: old file intact" [ "$(cksum <side/tin.gpkg)" = "$before" ]
check "sidecars: no temporary file after the refusal" no_temp side
# the holder dies (QGIS killed): its -wal and -shm are stale
kill -9 "$HOLDER"
wait "$HOLDER" 2>/dev/null
HOLDER=""
check "sidecars: the killed holder left -wal and -shm" \
  [ -s side/tin.gpkg-wal -a -e side/tin.gpkg-shm ]
run simplify -q -overwrite -max_error 1 in/north.tif side/tin.gpkg
check "sidecars: -overwrite over a stale WAL: exit 0 ($(cat err.txt))" \
  [ "$rc" -eq 0 ]
check "sidecars: integrity_check ok after a killed WAL connection" \
  integrity side/tin.gpkg
check "sidecars: only the new file remains" [ "$(ls -A side)" = "tin.gpkg" ]

# --- 3. the input is never replaced ---------------------------------------------
mkdir inp
gdal_translate -q -of GPKG -co RASTER_TABLE=r in/north.tif inp/r.gpkg
cp inp/r.gpkg inp/r.orig
refused "input: GPKG:r.gpkg:r -> r.gpkg" simplify -q -overwrite \
  GPKG:inp/r.gpkg:r inp/r.gpkg
check "input: the GPKG raster intact" cmp -s inp/r.gpkg inp/r.orig
cp in/north.tif inp/dem.tif
(cd inp && zip -q dem.zip dem.tif)
cp inp/dem.zip inp/dem.zip.orig
refused "input: /vsizip/dem.zip/dem.tif -> dem.zip" simplify -q -overwrite \
  -of GPKG /vsizip/inp/dem.zip/dem.tif inp/dem.zip
check "input: the archive intact" cmp -s inp/dem.zip inp/dem.zip.orig
refused "input: /vsizip/ with an absolute path" simplify -q -overwrite \
  -of GPKG "/vsizip/$W/inp/dem.zip/dem.tif" "$W/inp/./dem.zip"
check "input: the archive intact (absolute)" cmp -s inp/dem.zip inp/dem.zip.orig
gdalbuildvrt -q inp/v.vrt inp/dem.tif
gdalbuildvrt -q inp/v2.vrt inp/v.vrt
for v in v v2; do
  refused "input: $v.vrt whose source is the output" simplify -q \
    -overwrite -of GPKG inp/$v.vrt inp/dem.tif
  check "input: $v.vrt's source intact" cmp -s inp/dem.tif in/north.tif
done
# a raster named like one of a shapefile output's files
cp in/north.tif inp/s_vertices.dbf
refused "input: a shapefile layer file" simplify -q -overwrite \
  inp/s_vertices.dbf inp/s.shp
check "input: the raster named s_vertices.dbf intact" \
  cmp -s inp/s_vertices.dbf in/north.tif
check "input: no temporary file" no_temp inp

# --- 4. no empty TIN, no lone vertex -------------------------------------------
mkdir empty
python3 - <<'EOF'
# checkerboard: no cell has three valid corners; speckles: each corner
# sample valid but cut off by nodata around it
n = 12
with open("empty/checker.asc", "w") as f:
    f.write("ncols %d\nnrows %d\nxllcorner 0\nyllcorner 0\ncellsize 1\n"
            "NODATA_value -9999\n" % (n, n))
    for r in range(n):
        f.write(" ".join("-9999" if (r + c) % 2 else str(r + c)
                         for c in range(n)) + "\n")
with open("empty/speckle.asc", "w") as f:
    f.write("ncols %d\nnrows %d\nxllcorner 0\nyllcorner 0\ncellsize 1\n"
            "NODATA_value -9999\n" % (n, n))
    for r in range(n):
        row = []
        for c in range(n):
            near = lambda a, m: a in (1,) or a == m - 2
            cut = (r in (0, 1, n - 2, n - 1) and c in (0, 1, n - 2, n - 1)
                   and (r, c) not in ((0, 0), (0, n - 1), (n - 1, 0),
                                      (n - 1, n - 1)))
            row.append("-9999" if cut else str((r * 7 + c * 3) % 11))
        f.write(" ".join(row) + "\n")
EOF
refused "empty TIN: checkerboard nodata" simplify -q -max_error 0 \
  empty/checker.asc empty/checker.gpkg
check "empty TIN: says why" grep -q "no triangle" err.txt
check "empty TIN: nothing written" [ ! -e empty/checker.gpkg ]
run simplify -q -max_error 0 empty/speckle.asc empty/speckle.gpkg
check "speckled corners: exit 0 ($(cat err.txt))" [ "$rc" -eq 0 ]
nv=$(ogrinfo -q -dialect SQLite -sql "SELECT COUNT(*) AS n FROM vertices" \
       empty/speckle.gpkg | sed -n 's/.*n (Integer) = //p')
nused=$(ogrinfo -q -dialect SQLite -sql "SELECT COUNT(*) AS n FROM (SELECT v0 \
AS v FROM triangles UNION SELECT v1 FROM triangles UNION SELECT v2 FROM \
triangles)" empty/speckle.gpkg | sed -n 's/.*n (Integer) = //p')
check "speckled corners: every vertex in a triangle ($nused of $nv)" \
  [ -n "$nv" -a "$nv" = "$nused" ]

# --- 5. folder outputs ---------------------------------------------------------
mkdir fold
# MapInfo keeps no Z: refused before the work, even as a folder
run simplify -q -of "MapInfo File" in/north.tif fold/mi
check "MapInfo folder: refused, exit 2 ($(cat err.txt))" [ "$rc" -eq 2 ]
check "MapInfo folder: says it drops the heights" \
  grep -q "drops the heights" err.txt
check "MapInfo folder: nothing left" [ ! -e fold/mi ]
run simplify -q -of FlatGeobuf in/north.tif fold/fg
check "FlatGeobuf folder: exit 0 ($(cat err.txt))" [ "$rc" -eq 0 ]
check "FlatGeobuf folder: three .fgb and the two layers' styles in fold/fg" \
  [ "$(ls fold/fg | tr '\n' ' ')" = "run_parameters.fgb triangles.fgb triangles.qml vertices.fgb vertices.qml " ]
run simplify -q -overwrite -max_error 1 -of FlatGeobuf in/north.tif fold/fg
check "FlatGeobuf folder: -overwrite replaces it ($(cat err.txt))" [ "$rc" -eq 0 ]
check "FlatGeobuf folder: only fg remains" [ "$(ls -A fold)" = "fg" ]
mkdir fold/other && echo keep >fold/other/notes.txt
refused "a folder that is not an output" simplify -q -overwrite \
  -of FlatGeobuf in/north.tif fold/other
check "that folder is kept" grep -qx keep fold/other/notes.txt
run simplify -q -of FlatGeobuf in/north.tif fold/fg.gpkg
check "FlatGeobuf folder under a file's name: refused before the work, a \
usage error ($rc: $(cat err.txt))" [ "$rc" -eq 2 ]
check "FlatGeobuf folder under a file's name: says the way out" \
  grep -q "without '.gpkg'" err.txt
check "folder under a file's name: nothing left" \
  [ "$(ls -A fold | tr '\n' ' ')" = "fg other " ]
# a full disk: a small tmpfs, when this user may mount one
mkdir full
if [ "$(id -u)" = 0 ] && mount -t tmpfs -o size=200k tmpfs full 2>/dev/null; then
  MNT=$W/full
  refused "FlatGeobuf on a full disk" simplify -q -max_error 0 \
    -of FlatGeobuf in/north.tif full/fg
  check "full disk: nothing left" [ -z "$(ls -A full)" ]
  refused "GPKG on a full disk" simplify -q -max_error 0 in/north.tif \
    full/t.gpkg
  check "full disk (GPKG): nothing left" [ -z "$(ls -A full)" ]
  umount full && MNT=""
else
  echo "note: cannot mount a tmpfs here; the full-disk cases are skipped"
fi

# --- 6. interrupts during a slow write -----------------------------------------
mkdir sig
if ogrinfo --formats 2>/dev/null | grep -q LIBKML; then
  # 14,000 features: LIBKML would take over an hour; the warning comes just
  # before the write starts. (Before the watchdog, SIGTERM 1 to 25 s into
  # this write went unanswered for over 2 minutes.)
  for s in TERM INT; do
    python3 - "$T" "$s" in/north.tif sig/k.kml <<'EOF' >sig.txt 2>&1
import signal, subprocess, sys, threading, time
t, name, dem, out = sys.argv[1:]
p = subprocess.Popen([t, "simplify", "-q", "-max_error", "0.15", "-of",
                      "LIBKML", dem, out], stderr=subprocess.PIPE, text=True)
first = []
warned = threading.Event()
def read():
    for l in p.stderr:
        first.append(l)
        warned.set()
threading.Thread(target=read, daemon=True).start()
warned.wait(20)                     # the LIBKML warning: the write begins
line = first[0] if first else ""
time.sleep(1.0)
t0 = time.monotonic()
p.send_signal(getattr(signal, "SIG" + name))
try:
    p.wait(timeout=30)
except subprocess.TimeoutExpired:
    p.kill()
    p.wait()
dt = time.monotonic() - t0
print("warned=%d rc=%d seconds=%.2f" % ("LIBKML" in line, p.returncode, dt))
sys.exit(0 if "LIBKML" in line and p.returncode < 0 and dt < 2.0 else 1)
EOF
    sigrc=$?
    check "SIG$s during a LIBKML write: ends within 2 s ($(cat sig.txt))" \
      [ "$sigrc" -eq 0 ]
    check "SIG$s during a LIBKML write: nothing left" [ -z "$(ls -A sig)" ]
  done
else
  echo "note: no LIBKML driver; the interrupt cases are skipped"
fi

# --- 7. orientation and what -overwrite never replaces --------------------------
mkdir ori
run simplify -q -max_error 1 in/fault.tif ori/gen.gpkg
check "orientation: generate's output (y step > 0)" ccw ori/gen.gpkg
gdal_translate -q -a_ullr 0 0 800 600 in/fault.tif in/south.tif
run simplify -q -max_error 1 in/south.tif ori/south.gpkg
check "orientation: south-up raster" ccw ori/south.gpkg
gdal_translate -q -of ENVI in/fault.tif in/nogt.bin
sed -i '/^map info/d' in/nogt.hdr
rm -f in/nogt.bin.aux.xml
run simplify -q -max_error 1 in/nogt.bin ori/nogt.gpkg
check "orientation: no geotransform" ccw ori/nogt.gpkg
run simplify -q -max_error 1 in/north.tif ori/north.gpkg
check "orientation: north-up" ccw ori/north.gpkg
run simplify -q -max_error 1 -t_srs \
  "+proj=utm +zone=33 +datum=WGS84 +axis=wnu +units=m +no_defs" \
  in/north.tif ori/west.gpkg
check "orientation: -t_srs with x pointing west ($(cat err.txt))" \
  ccw ori/west.gpkg
mkfifo ori/fifo.gpkg
ln -s /dev/null ori/null.gpkg
refused "-overwrite onto a FIFO" simplify -q -overwrite in/north.tif \
  ori/fifo.gpkg
check "the FIFO stays a FIFO" [ -p ori/fifo.gpkg ]
refused "-overwrite onto a symlink to /dev/null" simplify -q -overwrite \
  in/north.tif ori/null.gpkg
check "the symlink stays" [ -L ori/null.gpkg ]
check "/dev/null stays a character device" [ -c /dev/null ]
refused "generate -overwrite onto a FIFO" generate fault ori/fifo.gpkg \
  -overwrite
check "the FIFO stays a FIFO (generate)" [ -p ori/fifo.gpkg ]
check "orientation etc.: no temporary file" no_temp ori
echo 'PROJCS["WGS 84 / UTM zone 33N",GEOGCS["WGS 84",DATUM["WGS_1984",SPHEROID["WGS 84",6378137,298.257223563]],PRIMEM["Greenwich",0],UNIT["degree",0.0174532925199433]],PROJECTION["Transverse_Mercator"],PARAMETER["latitude_of_origin",0],PARAMETER["central_meridian",15],PARAMETER["scale_factor",0.9996],PARAMETER["false_easting",500000],PARAMETER["false_northing",0],UNIT["metre",1]]' >ori/crs.prj
cp ori/crs.prj ori/crs.orig
refused "generate -overwrite onto its -a_srs file" generate fault \
  ori/crs.prj -a_srs ori/crs.prj -overwrite
check "the -a_srs file intact" cmp -s ori/crs.prj ori/crs.orig

# --- 8. non-finite synthetic heights, long names ---------------------------------
mkdir gen
refused "generate fault -wave_size 1e308" generate fault gen/w.tif \
  -wave_size 1e308
check "-wave_size 1e308: says why" grep -q "wave size" err.txt
check "-wave_size 1e308: nothing written" [ -z "$(ls -A gen)" ]
long=$(printf 'n%.0s' $(seq 250)).gpkg
check "a 255-byte name" [ "${#long}" -eq 255 ]
run simplify -q -max_error 2 in/north.tif "gen/$long"
check "simplify to a 255-byte name: exit 0 ($(cat err.txt))" [ "$rc" -eq 0 ]
check "the 255-byte output exists" [ -f "gen/$long" ]
longtif=$(printf 'g%.0s' $(seq 251)).tif
run generate fault "gen/$longtif" -q
check "generate to a 255-byte name: exit 0 ($(cat err.txt))" [ "$rc" -eq 0 ]
check "long names: no temporary file" no_temp gen

echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
