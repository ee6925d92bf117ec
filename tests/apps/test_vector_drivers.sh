#!/usr/bin/env bash
# test_vector_drivers.sh -- every vector driver this GDAL can create, as
# `terratin simplify -of DRIVER` ($TT_TERRATIN), issue 26: each is either
# refused before the work (exit 2, one line, nothing left) or writes a TIN
# that reads back exactly: OGR reads the triangles back, ogr2ogr brings them
# into the DEM's CRS, every corner matches the reference GeoPackage's (x, y
# within a micrometre, z within 1e-9 of its magnitude) and `terratin eval`
# finds the error within the bound. When the first try is refused with a
# way out (-layers triangles for a one-layer format, OUTPUT without its
# extension for a folder of files), the way out is taken and judged the
# same way. Databases, network services and GPSBabel (an external program)
# are left out. Prints "N passed, M failed"; exits 1 on any failure, 77
# when a tool is missing.
set -u
. "$(dirname "${BASH_SOURCE[0]}")/../apps/tt_check.sh" || exit 1

T=${TT_TERRATIN:-}
if [ -z "$T" ] || [ ! -x "$T" ]; then
  echo "SKIP: TT_TERRATIN is not set or not executable"
  exit 77
fi
for tool in ogrinfo ogr2ogr python3; do
  if ! command -v $tool >/dev/null 2>&1; then
    echo "SKIP: $tool is missing"
    exit 77
  fi
done

W=$(mktemp -d "${TMPDIR:-/tmp}/tt_vector_drivers.XXXXXX") || exit 1
trap 'rm -rf "$W"' EXIT
cd "$W" || exit 1

E=1
"$T" generate fault dem.tif -size 40x30 -seed 5 -displacement 20 \
  -wave_size 5 -a_srs EPSG:32633 -q || { echo "FAIL: generate"; exit 1; }
"$T" simplify -q -max_error $E dem.tif ref.gpkg ||
  { echo "FAIL: the reference run"; exit 1; }

# corners A.gpkg B.gpkg: every triangle corner of B's first polygon layer
# is one of A's triangles layer, and every one of A's is in B
cat >corners.py <<'EOF'
import sqlite3, struct, sys

def points(blob):
    # GeoPackage binary: header, envelope, then WKB
    flags = blob[3]
    env = {0: 0, 1: 32, 2: 48, 3: 48, 4: 64}[(flags >> 1) & 7]
    wkb = memoryview(blob)[8 + env:]
    out = []
    def geom(off):
        bo = '<' if wkb[off] == 1 else '>'
        t, = struct.unpack_from(bo + 'I', wkb, off + 1)
        off += 5
        hasz = t & 0x80000000 or (t % 10000) // 1000 in (1, 3)
        base = (t & 0xffff) % 1000
        dim = 3 if hasz else 2
        if base == 1:
            out.append(struct.unpack_from(bo + 'd' * dim, wkb, off))
            return off + 8 * dim
        if base in (3, 17):  # polygon, triangle: rings
            n, = struct.unpack_from(bo + 'I', wkb, off)
            off += 4
            for _ in range(n):
                m, = struct.unpack_from(bo + 'I', wkb, off)
                off += 4
                for _ in range(m):
                    out.append(struct.unpack_from(bo + 'd' * dim, wkb, off))
                    off += 8 * dim
            return off
        if base in (6, 15, 16, 7):  # multipolygon, polyhedral, TIN, GC
            n, = struct.unpack_from(bo + 'I', wkb, off)
            off += 4
            for _ in range(n):
                off = geom(off)
            return off
        raise SystemExit("geometry type %d" % t)
    geom(0)
    return out

def corners(path, prefer):
    db = sqlite3.connect(path)
    layers = [r[0] for r in db.execute(
        "SELECT table_name FROM gpkg_geometry_columns")]
    layer = next((l for l in layers if l.endswith(prefer)), None) or layers[0]
    col = db.execute("SELECT column_name FROM gpkg_geometry_columns WHERE "
                     "table_name = ?", (layer,)).fetchone()[0]
    pts = []
    for (g,) in db.execute('SELECT "%s" FROM "%s"' % (col, layer)):
        if g is not None:
            pts += points(g)
    return pts

a = corners(sys.argv[1], "triangles")
b = corners(sys.argv[2], "triangles")
if any(len(p) < 3 for p in b):
    raise SystemExit("read back without Z")
key = lambda p: (round(p[0], 3), round(p[1], 3))
ref = {}
for p in a:
    ref[key(p)] = p
seen = set()
for p in b:
    q = ref.get(key(p))
    if q is None or abs(p[0] - q[0]) > 1e-6 or abs(p[1] - q[1]) > 1e-6:
        raise SystemExit("corner %r not written" % (p,))
    if abs(p[2] - q[2]) > 1e-9 * max(1, abs(q[2])):
        raise SystemExit("corner %r at height %r, written %r" % (p[:2], p[2], q[2]))
    seen.add(key(p))
if len(seen) != len(ref):
    raise SystemExit("%d of %d corners read back" % (len(seen), len(ref)))
EOF

drivers=$(ogrinfo --formats | grep -- "vector" | grep -E '\(rw' |
          sed -E 's/^ *(.*) -(raster,)?(multidimensional raster,)?vector- .*/\1/')
n=0
while IFS= read -r d; do
  case "$d" in
  Memory|PostgreSQL|MySQL|MSSQLSpatial|Elasticsearch|Carto|AmigoCloud|NGW|\
  GPSBabel) continue ;;
  esac
  n=$((n + 1))
  ext=$(ogrinfo --format "$d" 2>/dev/null |
        sed -n 's/.*Extensions\{0,1\}: *\([^ ]*\).*/\1/p' | head -1)
  rm -rf out && mkdir out
  o=out/tin${ext:+.$ext}
  args=()
  "$T" simplify -q -max_error $E -of "$d" dem.tif "$o" >out.txt 2>err.txt
  rc=$?
  if [ $rc -eq 2 ] && grep -q -- "-layers triangles" err.txt; then
    args=(-layers triangles)
    "$T" simplify -q -max_error $E -of "$d" "${args[@]}" dem.tif "$o" \
      >out.txt 2>err.txt
    rc=$?
  fi
  if [ $rc -eq 2 ] && [ -n "$ext" ] && grep -q -- "without '.$ext'" err.txt; then
    o=out/tin
    "$T" simplify -q -max_error $E -of "$d" "${args[@]}" dem.tif "$o" \
      >out.txt 2>err.txt
    rc=$?
  fi
  if [ $rc -eq 2 ]; then
    check "$d: refused in one line ($(head -c 200 err.txt))" \
      [ "$(wc -l <err.txt)" = 1 ]
    check "$d: refused, nothing left" [ -z "$(ls -A out)" ]
    continue
  fi
  check "$d: exit 0 or refused (exit $rc: $(head -c 300 err.txt))" [ $rc -eq 0 ]
  [ $rc -eq 0 ] || continue
  rm -f back.gpkg
  # a Shapefile's layers are files of their own in the folder; a layer
  # without a CRS (DXF) is in the DEM's
  [ -e "$o" ] || o=out
  ogr2ogr -q -f GPKG -t_srs EPSG:32633 back.gpkg "$o" 2>ogr.txt ||
    { rm -f back.gpkg; ogr2ogr -q -f GPKG -s_srs EPSG:32633 \
        -t_srs EPSG:32633 back.gpkg "$o" 2>ogr.txt; }
  check "$d: OGR reads it back ($(head -c 200 ogr.txt))" [ -s back.gpkg ]
  msg=$(python3 corners.py ref.gpkg back.gpkg 2>&1)
  check "$d: every corner read back as written ($msg)" [ -z "$msg" ]
  "$T" eval -q -max_error $E dem.tif back.gpkg >out.txt 2>err.txt
  rc=$?
  check "$d: eval within the bound $E (exit $rc: $(head -c 200 err.txt))" \
    [ $rc -eq 0 ]
done <<<"$drivers"
check "drivers tried: $n" [ "$n" -ge 10 ]
echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
