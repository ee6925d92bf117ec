#!/usr/bin/env bash
# test_qgis_layers.sh -- terratin's vector outputs opened by QGIS as a GIS
# user would (issue 28): headless PyQGIS (Debian python3-qgis,
# /usr/bin/python3, QT_QPA_PLATFORM=offscreen), layers opened through the
# "ogr" provider with their default style:
#  - GeoPackage (its layer_styles), Shapefile, FlatGeobuf and GeoJSON (the
#    .qml beside each file, which QGIS loads by itself): the triangles
#    graduated on max_err, the vertices on their ins_err expression, the
#    triangles' fills see-through (symbol opacity < 1), and every field's
#    title as its alias ("max error" for max_err, ...);
#  - the style shows the terrain through the TIN: the TIN rendered over
#    `gdaldem hillshade` of the DEM into an image, whose grey levels follow
#    the hillshade's (correlation over the pixels well above what the same
#    TIN with opaque fills leaves) and differ from the TIN's alone.
# Skips (77) when python3-qgis is not installed: it is an optional heavy
# client (apt-get install -y --no-install-recommends python3-qgis).
set -u

T=${TT_TERRATIN:-}
if [ -z "$T" ] || [ ! -x "$T" ]; then
  echo "SKIP: TT_TERRATIN is not set or not executable"
  exit 77
fi
DEM=${TT_TESTDATA:-}/jacksboro_fault_dem.tif
if [ ! -f "$DEM" ]; then
  echo "SKIP: $DEM is missing (TT_TESTDATA)"
  exit 77
fi
if ! /usr/bin/python3 -c 'import qgis.core' >/dev/null 2>&1; then
  echo "SKIP: python3-qgis is not installed (apt-get install -y" \
       "--no-install-recommends python3-qgis): the QGIS style checks need it"
  exit 77
fi

W=$(mktemp -d "${TMPDIR:-/tmp}/tt_qgis_layers.XXXXXX") || exit 1
trap 'rm -rf "$W"' EXIT
cd "$W" || exit 1

failed=0
for out in "t.gpkg" "s.shp" "f.fgb -of FlatGeobuf -layers triangles" \
           "v.geojson -layers vertices"; do
  # shellcheck disable=SC2086 # the options split on purpose
  if ! "$T" simplify "$DEM" $out -max_error 20 -q 2>err.txt; then
    echo "FAIL: simplify $out: $(cat err.txt)"
    failed=1
  fi
done
# the DEM's hillshade (degrees: metres per degree of latitude as the scale)
if ! gdaldem hillshade -q -s 111120 "$DEM" hill.tif 2>err.txt; then
  echo "FAIL: gdaldem hillshade: $(cat err.txt)"
  failed=1
fi
[ "$failed" -eq 0 ] || exit 1

export QT_QPA_PLATFORM=offscreen
export XDG_RUNTIME_DIR="$W/xdg"
mkdir -m 700 "$W/xdg"
/usr/bin/python3 - <<'EOF' 2>qgis_err.txt
import sys
from qgis.core import (QgsApplication, QgsMapRendererSequentialJob,
                       QgsMapSettings, QgsRasterLayer, QgsVectorLayer)
from qgis.PyQt.QtCore import QSize
from qgis.PyQt.QtGui import QColor, qGray

app = QgsApplication([], False)
app.initQgis()
passed = failed = 0

def check(what, ok):
    global passed, failed
    if ok:
        passed += 1
    else:
        failed += 1
        print("FAIL:", what)

TRI_ALIASES = {"max_err": "max error", "rmse": "RMS error",
               "slope": "slope", "n_samples": "samples"}
VTX_ALIASES = {"ins_err": "insertion error", "star_max": "star max error",
               "vertex_id": "vertex id"}

def styled(uri, name, tri):
    layer = QgsVectorLayer(uri, name, "ogr")
    check(name + ": valid", layer.isValid())
    if not layer.isValid():
        return None
    r = layer.renderer()
    check(name + ": the default style loaded (graduated, got %s)"
          % r.type(), r.type() == "graduatedSymbol")
    if r.type() != "graduatedSymbol":
        return layer
    attr = r.classAttribute()
    check(name + ": classes on %s" % attr,
          attr == "max_err" if tri else "ins_err" in attr)
    check(name + ": classes from the TIN's values",
          len(r.ranges()) >= 2 and r.ranges()[-1].upperValue() > 0)
    if tri:
        ops = [rg.symbol().opacity() for rg in r.ranges()]
        check(name + ": see-through fills (opacity %s)" % ops,
              all(0 < o < 1 for o in ops))
    for field, alias in (TRI_ALIASES if tri else VTX_ALIASES).items():
        i = layer.fields().indexOf(field)
        got = layer.attributeAlias(i) if i >= 0 else None
        check(name + ": %s's alias %r (got %r)" % (field, alias, got),
              got == alias)
    return layer

def main():
    # the layers live in here: gone before exitQgis()
    tin = styled("t.gpkg|layername=triangles", "GPKG triangles", True)
    styled("t.gpkg|layername=vertices", "GPKG vertices", False)
    styled("s_triangles.shp", "Shapefile triangles", True)
    styled("s_vertices.shp", "Shapefile vertices", False)
    styled("f.fgb", "FlatGeobuf triangles", True)
    styled("v.geojson", "GeoJSON vertices", False)

    # --- the terrain through the TIN ---------------------------------------
    hill = QgsRasterLayer("hill.tif", "hillshade")
    check("hillshade: valid", hill.isValid())

    def render(layers):
        s = QgsMapSettings()
        s.setLayers(layers)               # the first on top
        s.setDestinationCrs(hill.crs())
        s.setExtent(hill.extent())
        s.setOutputSize(QSize(240, 205))
        s.setBackgroundColor(QColor(255, 255, 255))
        job = QgsMapRendererSequentialJob(s)
        job.start()
        job.waitForFinished()
        img = job.renderedImage()
        return [qGray(img.pixel(x, y)) for y in range(img.height())
                for x in range(img.width())]

    def corr(a, b):
        n = len(a)
        ma, mb = sum(a) / n, sum(b) / n
        sab = sum((x - ma) * (y - mb) for x, y in zip(a, b))
        saa = sum((x - ma) ** 2 for x in a)
        sbb = sum((y - mb) ** 2 for y in b)
        return sab / (saa * sbb) ** 0.5 if saa and sbb else 0.0

    if tin is not None and hill.isValid():
        h = render([hill])
        over = render([tin, hill])
        alone = render([tin])
        # the same TIN with opaque fills: what the see-through style avoids
        r = tin.renderer()
        ranges = r.ranges()  # kept: the symbols belong to this copy
        for i, rg in enumerate(ranges):
            sym = rg.symbol().clone()
            sym.setOpacity(1.0)
            r.updateRangeSymbol(i, sym)
        solid = render([tin, hill])
        c_over, c_solid = corr(over, h), corr(solid, h)
        print("correlation with the hillshade: see-through %.3f, opaque %.3f"
              % (c_over, c_solid))
        check("the hillshade shows through the TIN (correlation %.3f >= 0.6)"
              % c_over, c_over >= 0.6)
        check("... far more than through opaque fills (%.3f vs %.3f)"
              % (c_over, c_solid), c_over >= c_solid + 0.2)
        diff = sum(abs(x - y) for x, y in zip(over, alone)) / len(over)
        check("the TIN over the hillshade is not the TIN alone (mean grey "
              "difference %.1f)" % diff, diff > 5)

main()
print("%d passed, %d failed" % (passed, failed))
app.exitQgis()
sys.exit(1 if failed else 0)
EOF
rc=$?
grep -v -e '^QStandardPaths' -e 'propagateSizeHints' qgis_err.txt >&2
exit $rc
