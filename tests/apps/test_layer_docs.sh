#!/usr/bin/env bash
# test_layer_docs.sh -- the outputs of `terratin simplify` ($TT_TERRATIN)
# explain themselves (issue 28):
#  - a GeoPackage's gpkg_data_columns has a row for every column of
#    triangles, vertices and run_parameters (as PRAGMA table_info lists
#    them, fid and geometry aside), each with a title (in name and title)
#    and a description, the errors' in the run's height unit (m; ft for a
#    DEM in feet); the schema extension registered in gpkg_extensions (both
#    tables), and the titles unique; the same through the streamed writer
#    of a tiled run, and a decimated TIN's importance field described;
#  - the default style (layer_styles) has see-through triangle fills
#    (symbol opacity < 1) and the fields' titles as QGIS aliases;
#  - a .qml beside each geometry layer of a Shapefile, a FlatGeobuf file
#    (and each layer of a FlatGeobuf folder) and a GeoJSON file, the
#    GeoPackage's style; none with -nostyle; an existing .qml refused
#    without -overwrite (nothing written), replaced with it;
#  - 2DM: OUT.prj (ESRI WKT1) beside it and the summary saying the CRS is
#    there; no .prj and no note for a DEM without a CRS.
# Needs sqlite3 (the CLI). Prints "N passed, M failed"; exits 1 on any
# failure, 77 when a tool is missing.
set -u
. "$(dirname "${BASH_SOURCE[0]}")/../apps/tt_check.sh" || exit 1

T=${TT_TERRATIN:-}
if [ -z "$T" ] || [ ! -x "$T" ]; then
  echo "SKIP: TT_TERRATIN is not set or not executable"
  exit 77
fi
if ! command -v sqlite3 >/dev/null 2>&1; then
  echo "SKIP: sqlite3 (the CLI) is missing: apt-get install sqlite3"
  exit 77
fi

W=$(mktemp -d "${TMPDIR:-/tmp}/tt_layer_docs.XXXXXX") || exit 1
trap 'rm -rf "$W"' EXIT
cd "$W" || exit 1

rc=0
run() {
  "$T" "$@" >out.txt 2>err.txt
  rc=$?
}
q() { sqlite3 "$1" "$2"; }

"$T" generate diamond_square dem.tif -size 129 -seed 5 -q 2>err.txt ||
  { echo "FAIL: generate: $(cat err.txt)"; exit 1; }
# heights in metres (the band's unit), and in feet
gdal_translate -q -a_srs EPSG:32633 dem.tif utm.tif
gdal_translate -q -a_srs EPSG:32633 dem.tif ft.tif
for u in utm:m ft:ft; do
  printf '<PAMDataset><PAMRasterBand band="1"><UnitType>%s</UnitType></PAMRasterBand></PAMDataset>\n' \
    "${u#*:}" >"${u%%:*}.tif.aux.xml"
done

# Every column of a table has its row: title and description.
columns_described() { # GPKG TABLE
  local cols rows
  cols=$(q "$1" "SELECT name FROM pragma_table_info('$2') WHERE name NOT IN
              ('fid', 'geom') ORDER BY name")
  rows=$(q "$1" "SELECT column_name FROM gpkg_data_columns WHERE table_name =
              '$2' AND name <> '' AND title = name AND description <> ''
              ORDER BY column_name")
  [ -n "$cols" ] && [ "$cols" = "$rows" ]
}

gpkg_docs() { # GPKG WHAT UNIT
  for t in triangles vertices run_parameters; do
    check "$2: every field of $t described" columns_described "$1" "$t"
  done
  check "$2: max_err's description and unit" \
    [ "$(q "$1" "SELECT description FROM gpkg_data_columns WHERE
                 table_name = 'triangles' AND column_name = 'max_err'")" \
      = "largest |TIN - DEM| of the samples in this triangle ($3)" ]
  check "$2: ins_err's unit" \
    bash -c "sqlite3 '$1' \"SELECT description FROM gpkg_data_columns WHERE
             column_name = 'ins_err'\" | grep -q '($3)'"
  check "$2: ach_max's unit" \
    bash -c "sqlite3 '$1' \"SELECT description FROM gpkg_data_columns WHERE
             column_name = 'ach_max'\" | grep -q '($3)'"
  check "$2: the schema extension registered for both tables" \
    [ "$(q "$1" "SELECT group_concat(table_name || ':' || scope, ' ') FROM
                 (SELECT * FROM gpkg_extensions WHERE extension_name =
                 'gpkg_schema' ORDER BY table_name)")" \
      = "gpkg_data_column_constraints:read-write gpkg_data_columns:read-write" ]
  check "$2: the titles unique" \
    [ "$(q "$1" "SELECT count(*) - count(DISTINCT name) FROM
                 gpkg_data_columns")" = 0 ]
  check "$2: the file is sound" \
    [ "$(q "$1" "PRAGMA foreign_key_check; PRAGMA integrity_check")" = ok ]
}

run simplify utm.tif t.gpkg -max_error 2 -q
check "GPKG: exit 0 ($(cat err.txt))" [ "$rc" -eq 0 ]
gpkg_docs t.gpkg "GPKG" m
check "GPKG: the triangles' fills see-through" \
  bash -c "sqlite3 t.gpkg \"SELECT styleQML FROM layer_styles WHERE
           f_table_name = 'triangles'\" |
           grep -q 'type=\"fill\" name=\"0\" alpha=\"0.4'"
check "GPKG: the fields' titles as QGIS aliases" \
  bash -c "sqlite3 t.gpkg \"SELECT styleQML FROM layer_styles WHERE
           f_table_name = 'triangles'\" |
           grep -q '<alias field=\"max_err\" index=\"3\" name=\"max error\"/>'"

run simplify utm.tif tiled.gpkg -max_error 2 -tile_size 64 -q
check "tiled GPKG: exit 0 ($(cat err.txt))" [ "$rc" -eq 0 ]
gpkg_docs tiled.gpkg "tiled GPKG" m
check "tiled GPKG: the layers' rows as whole" \
  [ "$(q tiled.gpkg "SELECT * FROM gpkg_data_columns WHERE table_name <>
                     'run_parameters' ORDER BY 1, 2")" = \
    "$(q t.gpkg "SELECT * FROM gpkg_data_columns WHERE table_name <>
                 'run_parameters' ORDER BY 1, 2")" ]
check "tiled GPKG: the tiling described" \
  [ "$(q tiled.gpkg "SELECT title FROM gpkg_data_columns WHERE column_name =
                     'tile_size'")" = "tile size" ]

run simplify utm.tif dec.gpkg -method decimate -max_error 2 -q
check "decimated GPKG: exit 0 ($(cat err.txt))" [ "$rc" -eq 0 ]
gpkg_docs dec.gpkg "decimated GPKG" m
check "decimated GPKG: importance described" \
  [ "$(q dec.gpkg "SELECT title FROM gpkg_data_columns WHERE table_name =
                   'vertices' AND column_name = 'importance'")" = importance ]

# heights in feet on a metric map become metres unless kept (-z_to native)
run simplify ft.tif ft.gpkg -max_error 2 -z_to native -q
check "feet GPKG: exit 0 ($(cat err.txt))" [ "$rc" -eq 0 ]
check "feet GPKG: the errors in ft" \
  bash -c "sqlite3 ft.gpkg \"SELECT description FROM gpkg_data_columns WHERE
           column_name = 'max_err'\" | grep -q '(ft)'"
run simplify dem.tif none.gpkg -max_error 2 -q
check "no height unit: exit 0 ($(cat err.txt))" [ "$rc" -eq 0 ]
check "no height unit: the errors in z units" \
  bash -c "sqlite3 none.gpkg \"SELECT description FROM gpkg_data_columns WHERE
           column_name = 'max_err'\" | grep -q '(z units)'"

# --- .qml beside the layers' files --------------------------------------
mkdir shp
run simplify utm.tif shp/t.shp -max_error 2 -q
check "Shapefile: exit 0 ($(cat err.txt))" [ "$rc" -eq 0 ]
for l in triangles vertices; do
  check "Shapefile: t_$l.qml, the GeoPackage's style" \
    bash -c "[ \"\$(cat shp/t_$l.qml)\" = \"\$(sqlite3 t.gpkg \"SELECT styleQML
             FROM layer_styles WHERE f_table_name = '$l'\")\" ]"
done
check "Shapefile: no style for run_parameters" [ ! -e shp/t_run_parameters.qml ]
run simplify utm.tif t.fgb -of FlatGeobuf -layers triangles -max_error 2 -q
check "FlatGeobuf: exit 0 ($(cat err.txt))" [ "$rc" -eq 0 ]
check "FlatGeobuf: t.qml the triangles' style" \
  bash -c "[ \"\$(cat t.qml)\" = \"\$(sqlite3 t.gpkg \"SELECT styleQML FROM
           layer_styles WHERE f_table_name = 'triangles'\")\" ]"
run simplify utm.tif fgbdir -of FlatGeobuf -max_error 2 -q
check "FlatGeobuf folder: exit 0 ($(cat err.txt))" [ "$rc" -eq 0 ]
check "FlatGeobuf folder: a style per geometry layer" \
  bash -c '[ -s fgbdir/triangles.qml ] && [ -s fgbdir/vertices.qml ] &&
           [ ! -e fgbdir/run_parameters.qml ]'
run simplify utm.tif v.geojson -layers vertices -max_error 2 -q
check "GeoJSON: exit 0 ($(cat err.txt))" [ "$rc" -eq 0 ]
check "GeoJSON: v.qml, the vertices' style" \
  bash -c "[ \"\$(cat v.qml)\" = \"\$(sqlite3 t.gpkg \"SELECT styleQML FROM
           layer_styles WHERE f_table_name = 'vertices'\")\" ]"
check "no temporary file left" bash -c '! ls -A . shp | grep -q "^\.tt"'
run simplify utm.tif n.fgb -of FlatGeobuf -layers triangles -nostyle -q
check "-nostyle: exit 0" [ "$rc" -eq 0 ]
check "-nostyle: no .qml" [ ! -e n.qml ]
echo keep >s.qml
run simplify utm.tif s.fgb -of FlatGeobuf -layers triangles -q
check "an existing .qml: exit 1 ($rc)" [ "$rc" -eq 1 ]
check "an existing .qml: named, -overwrite said ($(cat err.txt))" \
  bash -c 'grep -q "s.qml" err.txt && grep -q -- "-overwrite" err.txt'
check "an existing .qml: nothing written" \
  bash -c '[ ! -e s.fgb ] && [ "$(cat s.qml)" = keep ]'
run simplify utm.tif s.fgb -of FlatGeobuf -layers triangles -q -overwrite
check "-overwrite: the .qml replaced" grep -q "renderer-v2" s.qml

# --- 2DM: its CRS beside it -------------------------------------------
run simplify utm.tif m.2dm -max_error 2
check "2DM: exit 0 ($(cat err.txt))" [ "$rc" -eq 0 ]
check "2DM: m.prj in ESRI's WKT1" grep -q '^PROJCS\["WGS_1984_UTM_Zone_33N"' m.prj
check "2DM: the summary names m.prj and why ($(grep output: out.txt))" \
  grep -q "the CRS in m.prj: 2DM holds none" out.txt
run simplify dem.tif n.2dm -max_error 2
check "2DM without a CRS: exit 0 ($(cat err.txt))" [ "$rc" -eq 0 ]
check "2DM without a CRS: no .prj, no note" \
  bash -c '[ ! -e n.prj ] && ! grep -q "CRS in" out.txt'

echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
