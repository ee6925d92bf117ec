#!/usr/bin/env bash
# test_qgis_plugin.sh -- the QGIS plugin qgis/terratin/ (issue 28): its zip
# (tools/qgis_plugin_zip.py, what `make qgis-plugin` builds) unzipped into
# a fresh QGIS profile's python/plugins and loaded there by QGIS's plugin
# loader, then every algorithm of its Processing provider run by
# processing.run() in headless QGIS (Debian python3-qgis, /usr/bin/python3,
# QT_QPA_PLATFORM=offscreen) against the command line of the same run:
# same counts and figures (qgis_plugin_check.py says each check). Skips
# (77) when python3-qgis is not installed: an optional heavy client
# (apt-get install -y --no-install-recommends python3-qgis qgis-providers).
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
       "--no-install-recommends python3-qgis qgis-providers): the QGIS" \
       "plugin's checks need it"
  exit 77
fi
HERE=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
SRC=$(cd "$HERE/../.." && pwd)

W=$(mktemp -d "${TMPDIR:-/tmp}/tt_qgis_plugin.XXXXXX") || exit 1
trap 'rm -rf "$W"' EXIT
cd "$W" || exit 1

# a copy: QGIS computes a raster layer's statistics, which GDAL keeps in
# a .aux.xml beside the file, and testdata/ is the source tree's
cp "$DEM" "$W/jacksboro.tif" || exit 1
DEM=$W/jacksboro.tif
/usr/bin/python3 "$SRC/tools/qgis_plugin_zip.py" "$W/terratin-qgis.zip" >/dev/null || {
  echo "FAIL: tools/qgis_plugin_zip.py"; exit 1; }

export QT_QPA_PLATFORM=offscreen
export XDG_RUNTIME_DIR="$W/xdg"
mkdir -m 700 "$W/xdg"
# terratin found on PATH, as a user's would be (the provider's setting is
# checked in the script too)
# (Processing's temporary outputs under TMPDIR: in here, removed with it)
TMPDIR=$W PATH=$(dirname "$T"):$PATH /usr/bin/python3 "$HERE/qgis_plugin_check.py" \
  "$W/terratin-qgis.zip" "$T" "$DEM" "$W" 2>qgis_err.txt
rc=$?
if [ "$rc" -ne 0 ]; then
  grep -v "^HDF5-DIAG\|^  #\|^    major\|^    minor" qgis_err.txt | tail -30
fi
exit "$rc"
