#!/usr/bin/env bash
# test_band_types.sh -- heights at the band's own precision (issue 11, item
# 1), end to end through the terratin command ($TT_TERRATIN).
#
# For every GDAL band type a DEM whose values floats cannot hold where the
# type allows it (2^30 + [0, 1000) in Int32, 3 2^30 + ... in UInt32,
# 10^6 + k / 1000 in Float64, 2^40 + ... in Int64 and UInt64; the extremes
# of the type for Byte, Int16 and UInt16; floats of a full 24-bit
# significand for Float32), plus a band scale (Int16 x 0.1), a -z_factor on
# Float32 and an Int32 band with nodata, is made with gdal_translate from a
# raw file Python wrote, simplified at a -max_error limit and at 0, and
# measured three ways: by an oracle in exact rational arithmetic (Python's
# fractions) over every sample and every triangle of the written layer,
# by the summary of `simplify -json`, and by `terratin eval -json`. The
# oracle's max error must be within the limit, and the other two must
# report it, to the rounding of double arithmetic (64 ulps of the largest
# height). Int64 and UInt64 heights beyond 2^53, which doubles cannot
# hold, must be refused with one line naming the sample. Prints "N passed,
# M failed"; exits 1 on any failure, 77 (skip) when a tool is missing.
set -u
. "$(dirname "${BASH_SOURCE[0]}")/../apps/tt_check.sh" || exit 1

T=${TT_TERRATIN:-}
if [ -z "$T" ] || [ ! -x "$T" ]; then
  echo "SKIP: TT_TERRATIN is not set or not executable"
  exit 77
fi
for tool in gdal_translate ogr2ogr python3; do
  if ! command -v "$tool" >/dev/null 2>&1; then
    echo "SKIP: $tool is missing"
    exit 77
  fi
done

W=$(mktemp -d "${TMPDIR:-/tmp}/tt_bands.XXXXXX") || exit 1
trap 'rm -rf "$W"' EXIT
cd "$W" || exit 1


cat >oracle.py <<'PY'
"""make TYPE NAME: NAME.raw and NAME.vrt (a raw VRT band), 41 x 33 samples.
check NAME TIN E SIMPLIFY.json EVAL.json [SCALE [ZFACTOR]]: the oracle."""
import json, math, struct, subprocess, sys
from fractions import Fraction

NX, NY = 41, 33
# GDAL data type and struct format of each kind
TYPES = {"Byte": ("Byte", "B"), "Int16": ("Int16", "h"),
         "UInt16": ("UInt16", "H"), "Int32": ("Int32", "i"),
         "UInt32": ("UInt32", "I"), "Float32": ("Float32", "f"),
         "Float64": ("Float64", "d"), "Int64": ("Int64", "q"),
         "UInt64": ("UInt64", "Q"), "Int32nd": ("Int32", "i"),
         "Int64big": ("Int64", "q"), "UInt64big": ("UInt64", "Q")}
NODATA = -2**31

def values(kind):
    seed = 12345
    out = []
    for r in range(NY):
        for c in range(NX):
            seed = (seed * 6364136223846793005 + 1442695040888963407) % 2**64
            u = (seed >> 11) / 2.0**53             # noise in [0, 1)
            s = 0.5 + 0.5 * math.sin(c * 0.23) * math.cos(r * 0.19)  # [0, 1]
            if kind == "Byte":
                v = min(255, int(230 * s + 25 * u))
            elif kind == "Int16":
                v = max(-32768, min(32767, int(65000 * s - 32500 + 200 * u)))
            elif kind == "UInt16":
                v = min(65535, int(65000 * s + 500 * u))
            elif kind in ("Int32", "Int32nd"):
                v = 2**30 + int(900 * s) + int(100 * u)
                if kind == "Int32nd" and 10 <= c < 15 and 8 <= r < 12:
                    v = NODATA
            elif kind == "UInt32":
                v = 3 * 2**30 + int(900 * s) + int(100 * u)
            elif kind == "Int64":
                v = 2**40 + int(900 * s) + int(100 * u)
            elif kind == "UInt64":
                v = 2**41 + int(900 * s) + int(100 * u)
            elif kind == "Int64big":
                v = 2**53 + 1 if (c, r) == (7, 5) else int(1000 * s)
            elif kind == "UInt64big":
                v = 2**63 if (c, r) == (3, 2) else int(1000 * s)
            elif kind == "Float32":
                x = 8848 + 40 * s + u       # rounded to a float below
                v = struct.unpack("<f", struct.pack("<f", x))[0]
            else:  # Float64
                v = 1e6 + int(900 * s + 100 * u) * 0.001
            out.append(v)
    return out

def make(kind, name):
    gdt, fmt = TYPES[kind]
    vals = values(kind)
    size = struct.calcsize(fmt)
    with open(name + ".raw", "wb") as f:
        f.write(struct.pack("<%d%s" % (len(vals), fmt), *vals))
    with open(name + ".vrt", "w") as f:
        f.write('<VRTDataset rasterXSize="%d" rasterYSize="%d">\n'
                ' <VRTRasterBand dataType="%s" band="1" '
                'subClass="VRTRawRasterBand">\n'
                '  <SourceFilename relativetoVRT="1">%s.raw</SourceFilename>\n'
                '  <ImageOffset>0</ImageOffset><PixelOffset>%d</PixelOffset>'
                '<LineOffset>%d</LineOffset><ByteOrder>LSB</ByteOrder>\n'
                ' </VRTRasterBand>\n</VRTDataset>\n'
                % (NX, NY, gdt, name, size, size * NX))

def triangles(tin):
    csv = subprocess.run(
        ["ogr2ogr", "--config", "OGR_WKT_PRECISION", "17", "-f", "CSV",
         "/vsistdout/", tin, "triangles", "-lco", "GEOMETRY=AS_WKT"],
        check=True, capture_output=True, text=True).stdout
    tris = []
    for line in csv.splitlines()[1:]:
        inner = line[line.index("((") + 2:line.index("))")]
        pts = [tuple(float(t) for t in p.split()) for p in inner.split(",")]
        # geotransform (0, 1, 0, 0, 0, -1): pixel centre (c, r) at
        # (c + 0.5, -r - 0.5), exact in binary
        tris.append([(int(x - 0.5), int(-y - 0.5), z) for x, y, z in pts[:3]])
    return tris

def check(kind, name, tin, limit, sjson, ejson, scale="1", zf="1"):
    vals = values(kind)
    scale, zf, limit = float(scale), float(zf), float(limit)
    def height(c, r):
        raw = vals[r * NX + c]
        if kind == "Int32nd" and raw == NODATA:
            return None
        return (float(raw) * scale + 0.0) * zf  # the reader's formula
    zmax = max(abs(height(c, r)) for r in range(NY) for c in range(NX)
               if height(c, r) is not None)
    tol = 64 * 2.0**-52 * zmax
    tris = triangles(tin)
    worst = Fraction(0)
    covered = set()
    problems = []
    for t in tris:
        for c, r, z in t:
            if z != height(c, r):
                problems.append("vertex (%d, %d) has z %r, the sample is %r"
                                % (c, r, z, height(c, r)))
        (c0, r0, z0), (c1, r1, z1), (c2, r2, z2) = t
        det = (c1 - c0) * (r2 - r0) - (c2 - c0) * (r1 - r0)
        if det == 0:
            problems.append("degenerate triangle %r" % (t,))
            continue
        Z0, Z1, Z2 = Fraction(z0), Fraction(z1), Fraction(z2)
        for r in range(min(r0, r1, r2), max(r0, r1, r2) + 1):
            for c in range(min(c0, c1, c2), max(c0, c1, c2) + 1):
                w1 = (c - c0) * (r2 - r0) - (c2 - c0) * (r - r0)
                w2 = (c1 - c0) * (r - r0) - (c - c0) * (r1 - r0)
                w0 = det - w1 - w2
                if det < 0:
                    w0, w1, w2 = -w0, -w1, -w2
                if min(w0, w1, w2) < 0:
                    continue
                h = height(c, r)
                if h is None:
                    problems.append("nodata sample (%d, %d) covered" % (c, r))
                    continue
                covered.add((c, r))
                plane = (w0 * Z0 + w1 * Z1 + w2 * Z2) / abs(det)
                worst = max(worst, abs(Fraction(h) - plane))
    valid = sum(1 for r in range(NY) for c in range(NX)
                if height(c, r) is not None)
    if len(covered) != valid:
        problems.append("%d of %d valid samples covered"
                        % (len(covered), valid))
    true_max = float(worst)
    if not true_max <= limit + tol:
        problems.append("true max error %.17g > -max_error %g"
                        % (true_max, limit))
    s = json.load(open(sjson))
    e = json.load(open(ejson))
    for what, got in (("simplify", s["max_error"]), ("eval", e["max_error"])):
        if abs(got - true_max) > tol:
            problems.append("%s reports max error %.17g, the true one is "
                            "%.17g" % (what, got, true_max))
    if problems:
        print("; ".join(problems[:4]))
        sys.exit(1)

if sys.argv[1] == "make":
    make(sys.argv[2], sys.argv[3])
else:
    check(*sys.argv[2:])
PY

# TYPE LIMIT [-a_scale S | -z_factor F]
for spec in "Byte 3" "Int16 50" "UInt16 50" "Int32 10" "UInt32 10" \
            "Float32 0.5" "Float64 0.01" "Int64 10" "UInt64 10" \
            "Int32nd 10" "Int16 0.5 -a_scale 0.1" \
            "Float32 0.01 -z_factor 0.3048"; do
  set -- $spec
  kind=$1 limit=$2 extra=${3:-} val=${4:-}
  name=$kind${extra:+_${extra#-}}
  python3 oracle.py make "$kind" "$name"
  meta=""
  [ "$kind" = Int32nd ] && meta="-a_nodata -2147483648"
  scale=1 zf=1 zopt=""
  case $extra in
    -a_scale) scale=$val; meta="-a_scale $val" ;;
    -z_factor) zf=$val; zopt="-z_factor $val" ;;
  esac
  if ! gdal_translate -q -a_srs EPSG:32633 -a_ullr 0 0 41 -33 $meta \
       "$name.vrt" "$name.tif" 2>gt.txt; then
    fail "$name: gdal_translate: $(cat gt.txt)"
    continue
  fi
  for e in "$limit" 0; do
    out=$name.$e.gpkg
    "$T" simplify -q -json $zopt -max_error "$e" "$name.tif" "$out" \
      >s.json 2>err.txt
    rc=$?
    check "$name -max_error $e: simplify exit 0 (rc $rc: $(cat err.txt))" \
      [ "$rc" -eq 0 ]
    [ "$rc" -eq 0 ] || continue
    "$T" eval -json $zopt "$name.tif" "$out" >e.json 2>err.txt
    rc=$?
    check "$name -max_error $e: eval exit 0 (rc $rc: $(cat err.txt))" \
      [ "$rc" -eq 0 ]
    [ "$rc" -eq 0 ] || continue
    python3 oracle.py check "$kind" "$name" "$out" "$e" s.json e.json \
      "$scale" "$zf" >why.txt 2>&1
    check "$name -max_error $e: $(cat why.txt)" [ -z "$(cat why.txt)" ]
  done
done

# heights beyond 2^53 cannot be doubles: refused, one line, no output
for kind in Int64big UInt64big; do
  python3 oracle.py make "$kind" "$kind"
  gdal_translate -q -a_ullr 0 0 41 -33 "$kind.vrt" "$kind.tif" 2>/dev/null
  "$T" simplify -q -max_error 1 "$kind.tif" "$kind.gpkg" >out.txt 2>err.txt
  rc=$?
  check "$kind: simplify refuses (rc $rc)" [ "$rc" -eq 1 ]
  check "$kind: one stderr line naming 2^53 ($(cat err.txt))" \
    bash -c '[ "$(wc -l <err.txt)" = 1 ] && grep -q "2^53" err.txt'
  check "$kind: no output" [ ! -e "$kind.gpkg" ]
done

echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
