#!/usr/bin/env bash
# breaklines_picture.sh TERRATIN [OUT.png] -- docs/breaklines.png: the
# Jacksboro fault DEM (testdata/) simplified at -max_error 20 with a line
# drawn along the fault as a breakline, a window of it drawn with GDAL's
# tools only: the hillshade (gdaldem), the TIN's edges in blue and the
# breaklines layer's edges in red (ogr2ogr, gdal_rasterize), six times
# the DEM's resolution.
set -eu
T=${1:?usage: breaklines_picture.sh TERRATIN [OUT.png]}
HERE=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
OUT=${2:-$HERE/../docs/breaklines.png}
J=$HERE/../testdata/jacksboro_fault_dem.tif
W=$(mktemp -d "${TMPDIR:-/tmp}/tt_blpic.XXXXXX")
trap 'rm -rf "$W"' EXIT
cat >"$W/fault.geojson" <<'JEOF'
{"type": "FeatureCollection", "features": [{"type": "Feature",
 "properties": {}, "geometry": {"type": "LineString", "coordinates":
 [[-84.40, 36.55], [-84.30, 36.60], [-84.20, 36.62], [-84.09, 36.70]]}}]}
JEOF
"$T" simplify "$J" "$W/j.gpkg" -max_error 20 -breaklines "$W/fault.geojson" -q
# the window: columns 150-300, rows 100-200 of the DEM
gdal_translate -q -srcwin 150 100 150 100 "$J" "$W/win.tif"
gdaldem hillshade -q -s 111120 "$W/win.tif" "$W/hs.tif"
gdal_translate -q -outsize 600% 600% -r bilinear -b 1 -b 1 -b 1 \
  "$W/hs.tif" "$W/rgb.tif"
ogr2ogr -q -nlt MULTILINESTRING "$W/edges.gpkg" "$W/j.gpkg" triangles
gdal_rasterize -q -b 1 -b 2 -b 3 -burn 40 -burn 70 -burn 160 -l triangles \
  "$W/edges.gpkg" "$W/rgb.tif"
gdal_rasterize -q -at -b 1 -b 2 -b 3 -burn 230 -burn 20 -burn 20 \
  -l breaklines "$W/j.gpkg" "$W/rgb.tif"
gdal_translate -q -of PNG "$W/rgb.tif" "$OUT"
rm -f "$OUT.aux.xml"
echo "$OUT"
