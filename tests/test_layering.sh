#!/usr/bin/env bash
# Fails when a file of the engine (src/ outside src/gdal/, or the engine's
# public header) includes a header of GDAL, OGR, CPL, PROJ, GeographicLib,
# SQLite or netCDF: the engine builds and links with libm and threads alone; and when
# a file of apps/ passes 800 lines.
set -u
root=${1:?usage: test_layering.sh SOURCE_DIR}
pattern='^[[:space:]]*#[[:space:]]*include[[:space:]]*[<"](gdal[a-z_]*\.h|ogr[a-z_]*\.h|ogrsf_frmts\.h|cpl_[a-z_]*\.h|vrtdataset\.h|proj\.h|proj_[a-z_]*\.h|geodesic\.h|sqlite3\.h|sqlite3ext\.h|netcdf\.h)[>"]'
cd "$root" || exit 1
bad=$(find src include/terratin/terratin.h -path src/gdal -prune -o \
        -type f \( -name '*.c' -o -name '*.h' \) -print |
      xargs grep -nE "$pattern" || true)
if [ -n "$bad" ]; then
  echo "test_layering: GDAL-family headers outside src/gdal/:"
  echo "$bad"
  exit 1
fi
# The glue folder holds only files that need those libraries (directly, or
# through the glue's public header or one of its own headers).
for f in src/gdal/*.c src/gdal/*.h; do
  grep -qE "$pattern" "$f" ||
    grep -qE '#include "(terratin/terratin_gdal\.h|gdal/[a-z_]+\.h)"' "$f" || {
      echo "test_layering: $f includes no GDAL-family header: it belongs to the engine"
      exit 1; }
done
# src/ has no file outside a folder.
loose=$(find src -maxdepth 1 -type f)
if [ -n "$loose" ]; then
  echo "test_layering: files directly in src/ (put each in its stage's folder):"
  echo "$loose"
  exit 1
fi
# The command stays in files of a size a reader can hold: one per
# subcommand, the parser, the reports (issue 12: none over 800 lines).
long=$(wc -l apps/*.c apps/*.h | awk '$2 != "total" && $1 > 800 {print}')
if [ -n "$long" ]; then
  echo "test_layering: files of apps/ over 800 lines (split them by concept):"
  echo "$long"
  exit 1
fi
echo "test_layering: the engine includes no GDAL-family header"
