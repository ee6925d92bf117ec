#!/usr/bin/env bash
# make_testdata.sh -- rebuilds terratin's small real DEMs in testdata/ from a
# source that Debian ships, and checks that every format reads back the same.
#
#   testdata/make_testdata.sh          # rebuild and verify
#   testdata/make_testdata.sh --check  # verify the committed files only
#
# Source: the Jacksboro fault DEM of Debian's python-matplotlib-data package
# (/usr/share/matplotlib/mpl-data/sample_data/jacksboro_fault_dem.npz).
# Outputs (see testdata/README.md for what each one tests):
#   jacksboro_fault_dem.tif   the whole grid, GeoTIFF Int16, EPSG:4326, z in m
#   jacksboro_fault_dem.asc   the whole grid, ESRI ASCII grid (+ .prj)
#   jacksboro_fault_dem.dem   a 200 x 316 window, USGS ASCII DEM
#
# The outputs are committed; CI never runs this script. It needs gdal-bin,
# python3-gdal, python3-numpy and python-matplotlib-data, and installs the
# missing ones with apt-get (as root or through sudo), as the Makefile does.
# It runs Debian's /usr/bin/python3 on purpose: a pyenv python3 on PATH has
# no numpy or GDAL bindings.
set -euo pipefail

cd "$(dirname "$0")"
PY=/usr/bin/python3
SRC=/usr/share/matplotlib/mpl-data/sample_data/jacksboro_fault_dem.npz
NAME=jacksboro_fault_dem
# The USGS DEM window (xoff yoff xsize ysize). A USGS DEM stores one
# 1024-byte-blocked ASCII profile per column, so the whole 403 x 344 grid
# takes 1.24 MB; 316 rows fill exactly two blocks per profile and 200
# columns keep the file near 400 kB. The window holds the fault trace from
# its north to its south edge and the south-west end of the Pine Mountain
# ridge.
DEM_WINDOW=(120 14 200 316)
# No .aux.xml side files: everything a test needs is in the files themselves.
export GDAL_PAM_ENABLED=NO

check_only=0
case "${1:-}" in
  --check) check_only=1 ;;
  "") ;;
  *) echo "usage: $0 [--check]" >&2; exit 2 ;;
esac

need_pkgs() {
  local missing="" p
  for p in "$@"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" \
      || missing="$missing $p"
  done
  if [ -n "$missing" ]; then
    echo "make_testdata: installing Debian packages:$missing"
    local sudo=""
    [ "$(id -u)" = 0 ] || sudo=sudo
    $sudo apt-get update -qq
    DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq \
      --no-install-recommends $missing
  fi
}

need_pkgs gdal-bin python3-gdal python3-numpy
if [ "$check_only" = 0 ]; then
  need_pkgs python-matplotlib-data
  [ -f "$SRC" ] || { echo "make_testdata: $SRC not found" >&2; exit 1; }

  echo "== writing $NAME.tif from $SRC"
  rm -f "$NAME.tif" "$NAME.asc" "$NAME.prj" "$NAME.dem"
  "$PY" - "$SRC" "$NAME.tif" <<'EOF'
import sys
import numpy as np
from osgeo import gdal, osr

gdal.UseExceptions()
src, dst = sys.argv[1], sys.argv[2]
d = np.load(src)
print("  arrays in the npz:", ", ".join(
    "%s %s%s" % (k, d[k].dtype, list(d[k].shape)) for k in d.files))
z = d["elevation"]
dx, dy = float(d["dx"]), float(d["dy"])
xmin, xmax = float(d["xmin"]), float(d["xmax"])
# The file's "ymin" (36.7329) is larger than its "ymax" (36.4462): the names
# follow the row order (row 0 first), not the value. Take the extent edges by
# value and check that they span exactly the grid in whole cells, so they
# are pixel edges (not the centres of the outer samples).
north, south = max(float(d["ymin"]), float(d["ymax"])), min(float(d["ymin"]), float(d["ymax"]))
ny, nx = z.shape
for what, span, n, step in (("x", xmax - xmin, nx, dx), ("y", north - south, ny, dy)):
    cells = span / step
    print("  %s extent %.10f deg = %.6f cells of %.10f deg (grid: %d)" % (what, span, cells, step, n))
    if abs(cells - n) > 1e-6:
        sys.exit("extent does not span %d whole %s cells" % (n, what))
if z.dtype != np.int16:
    sys.exit("expected int16 heights, got %s" % z.dtype)
print("  heights %d .. %d, %d distinct, no fill value below 0: %s"
      % (z.min(), z.max(), len(np.unique(z)), bool(z.min() > 0)))
# Row 0 is the north edge: matplotlib's own examples lay y out from "ymin"
# (36.7329) at row 0 to "ymax" at the last row, and only north-up gives the
# region's landforms their known strike (the Jacksboro fault trace NW-SE,
# the Pine Mountain ridge NE-SW). See testdata/README.md.
gt = (xmin, dx, 0.0, north, 0.0, -dy)
drv = gdal.GetDriverByName("GTiff")
ds = drv.Create(dst, nx, ny, 1, gdal.GDT_Int16,
                ["COMPRESS=DEFLATE", "PREDICTOR=2", "TILED=NO"])
ds.SetGeoTransform(gt)
srs = osr.SpatialReference()
srs.ImportFromEPSG(4326)
ds.SetSpatialRef(srs)
ds.SetMetadataItem("AREA_OR_POINT", "Area")
ds.SetMetadataItem("TIFFTAG_IMAGEDESCRIPTION",
                   "Jacksboro fault region, Tennessee: the jacksboro_fault_dem.npz "
                   "sample of Debian's python-matplotlib-data, heights in metres. "
                   "See terratin testdata/README.md.")
band = ds.GetRasterBand(1)
band.SetUnitType("m")
band.SetDescription("elevation")
band.WriteArray(z)
ds = None
print("  geotransform", gt)
EOF

  echo "== converting to $NAME.asc (AAIGrid)"
  gdal_translate -q -of AAIGrid "$NAME.tif" "$NAME.asc"

  echo "== converting window ${DEM_WINDOW[*]} to $NAME.dem (USGSDEM)"
  gdal_translate -q -of USGSDEM -srcwin "${DEM_WINDOW[@]}" \
    -co PRODUCER="terratin testdata from matplotlib sample data" \
    "$NAME.tif" "$NAME.dem"
fi

echo "== gdalinfo summaries"
for f in "$NAME.tif" "$NAME.asc" "$NAME.dem"; do
  [ -f "$f" ] || { echo "make_testdata: $f is missing" >&2; exit 1; }
  echo "-- $f ($(stat -c %s "$f") bytes)"
  gdalinfo -nomd "$f" \
    | grep -E '^(Driver|Size is|GEOGCRS|PROJCRS|Origin|Pixel Size|Band|  NoData|  Unit)' || true
done

echo "== reading the three back"
"$PY" - "$NAME" "${DEM_WINDOW[@]}" <<'EOF'
import sys
import numpy as np
from osgeo import gdal, osr

gdal.UseExceptions()
name = sys.argv[1]
xoff, yoff, xs, ys = (int(v) for v in sys.argv[2:6])

def load(path):
    ds = gdal.Open(path)
    b = ds.GetRasterBand(1)
    a = b.ReadAsArray().astype(np.int64)
    srs = ds.GetSpatialRef()
    epsg = None
    if srs is not None:
        # An ESRI .prj names no authority: ask PROJ for the best match.
        best = srs.FindMatches()
        if best and best[0][1] >= 90:
            epsg = best[0][0].GetAuthorityCode(None)
    return a, ds.GetGeoTransform(), epsg, b.GetNoDataValue(), b.GetUnitType(), \
        gdal.GetDataTypeName(b.DataType)

ref, gt, epsg, nd, unit, dt = load(name + ".tif")
print("  tif: %dx%d %s EPSG:%s unit %r nodata %s, %d..%d"
      % (ref.shape[1], ref.shape[0], dt, epsg, unit, nd, ref.min(), ref.max()))
fail = 0

asc, agt, aepsg, and_, aunit, adt = load(name + ".asc")
same = asc.shape == ref.shape and np.array_equal(asc, ref)
gtd = max(abs(a - b) for a, b in zip(agt, gt))
# AAIGrid writes the cell size with 12 decimals (0.000833333333), so the
# far corner moves by 343 * 3.3e-13 = 1.1e-10 deg (about 0.01 mm).
print("  asc: %s, heights %s the tif's, EPSG:%s, geotransform within %.1e deg"
      % (adt, "identical to" if same else "DIFFERENT from", aepsg, gtd))
fail |= (not same) or gtd > 1e-9 or aepsg != epsg

dem, dgt, depsg, dnd, dunit, ddt = load(name + ".dem")
win = ref[yoff:yoff + ys, xoff:xoff + xs]
same = dem.shape == win.shape and np.array_equal(dem, win)
wgt = (gt[0] + xoff * gt[1], gt[1], 0.0, gt[3] + yoff * gt[5], 0.0, gt[5])
gtd = max(abs(a - b) for a, b in zip(dgt, wgt))
print("  dem: %s unit %r nodata %s, heights %s the tif's window, EPSG:%s, "
      "geotransform within %.1e deg" % (ddt, dunit, dnd,
      "identical to" if same else "DIFFERENT from", depsg, gtd))
fail |= (not same) or gtd > 1e-9 or depsg != epsg or dunit != "m"
if nd is None and dnd is not None and (dem == dnd).any():
    print("  dem: holds its nodata value")
    fail = 1
sys.exit(1 if fail else 0)
EOF
echo "== ok"
