#!/usr/bin/env bash
# test_mesh_formats.sh -- `terratin simplify` writing the mesh and survey
# formats of issue 17 ($TT_TERRATIN): 2DM, PLY, OBJ and LandXML,
#  - chosen by -of (any case, any extension) and by OUTPUT's extension
#    (.2dm, .ply, .obj, .xml), each with the vertex and triangle counts of
#    the run's -json, and -obj_local's origin line;
#  - an existing output refused without -overwrite (untouched), replaced
#    with it;
#  - -obj_local without OBJ and -lco with a mesh format are usage errors;
#  - 2DM's six .dat datasets beside it: a value a vertex or a face, an
#    existing one refused without -overwrite (nothing written), all
#    replaced with it, a name holding "_els" refused; -of UGRID writes a
#    netCDF (CDF-2) file;
#  - nothing left behind by a failure (a missing folder, the file size
#    limit) or an interrupt (SIGINT);
#  - the LandXML file valid against the LandXML 1.2 schema when
#    TT_LANDXML_XSD names a copy of it (skipped with a message otherwise);
#  - QGIS (PyQGIS) mesh layers only when python3-qgis is installed: skipped
#    with a message otherwise (test_qgis_mesh.sh checks their content).
# Prints "N passed, M failed"; exits 1 on any failure, 77 when a tool is
# missing.
set -u
. "$(dirname "${BASH_SOURCE[0]}")/../apps/tt_check.sh" || exit 1

T=${TT_TERRATIN:-}
if [ -z "$T" ] || [ ! -x "$T" ]; then
  echo "SKIP: TT_TERRATIN is not set or not executable"
  exit 77
fi
if ! command -v python3 >/dev/null 2>&1; then
  echo "SKIP: python3 is missing"
  exit 77
fi

W=$(mktemp -d "${TMPDIR:-/tmp}/tt_mesh_formats.XXXXXX") || exit 1
trap 'rm -rf "$W"' EXIT
cd "$W" || exit 1

rc=0
run() {
  "$T" "$@" >out.txt 2>err.txt
  rc=$?
}
json_get() {
  python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))[sys.argv[2]])' "$1" "$2"
}
# counts FORMAT FILE: "vertices triangles" as the file declares or lists them
counts() {
  python3 - "$1" "$2" <<'EOF'
import sys
fmt, path = sys.argv[1], sys.argv[2]
if fmt == "ply":
    nv = nt = None
    with open(path, "rb") as f:
        for line in f:
            if line.startswith(b"element vertex"): nv = int(line.split()[2])
            if line.startswith(b"element face"): nt = int(line.split()[2])
            if line == b"end_header\n": break
    print(nv, nt)
else:
    text = open(path).read().splitlines()
    tag = {"2dm": ("ND ", "E3T "), "obj": ("v ", "f "),
           "xml": ("<P ", "<F>")}[fmt]
    print(sum(l.strip().startswith(tag[0]) for l in text),
          sum(l.strip().startswith(tag[1]) for l in text))
EOF
}
# no_temp: no temporary output (.tt*) in the folder
no_temp() { [ -z "$(ls -A | grep '^\.tt')" ]; }

run generate fault dem.tif -size 60 -seed 5 -q
check "generate" [ "$rc" -eq 0 ]

# --- by extension, then by -of name ---------------------------------------
for ext in 2dm ply obj xml; do
  run simplify dem.tif "t.$ext" -max_error 5 -json
  if [ "$rc" -ne 0 ]; then
    fail ".$ext: exit $rc: $(cat err.txt)"
    continue
  fi
  want="$(json_get out.txt vertices) $(json_get out.txt triangles)"
  check ".$ext: the run's counts ($(counts $ext t.$ext) vs $want)" \
    [ "$(counts $ext "t.$ext")" = "$want" ]
done
check ".2dm: MESH2D first" [ "$(head -1 t.2dm)" = "MESH2D" ]
check ".ply: binary little endian" \
  grep -aq "^format binary_little_endian 1.0" t.ply
check ".xml: a LandXML 1.2 TIN" \
  bash -c 'grep -q "<LandXML xmlns=\"http://www.landxml.org/schema/LandXML-1.2\"" t.xml && grep -q "surfType=\"TIN\"" t.xml'
if command -v xmllint >/dev/null 2>&1; then
  check ".xml: well-formed (xmllint)" xmllint --noout t.xml
fi
# The LandXML 1.2 schema is LandXML.org's; its terms do not say it may be
# redistributed, so no copy is kept here: TT_LANDXML_XSD names one.
if [ -n "${TT_LANDXML_XSD:-}" ] && [ -f "$TT_LANDXML_XSD" ] &&
   command -v xmllint >/dev/null 2>&1; then
  check ".xml: valid against $TT_LANDXML_XSD (xmllint --schema)" \
    xmllint --noout --nonet --schema "$TT_LANDXML_XSD" t.xml
else
  echo "SKIP: LandXML 1.2 schema validation: set TT_LANDXML_XSD to a copy" \
       "of LandXML-1.2.xsd (from landxml.org; not redistributed here) and" \
       "install xmllint (libxml2-utils)"
fi

for pair in "2dm:2DM" "ply:ply" "obj:Obj" "xml:LANDXML"; do
  ext=${pair%%:*}
  name=${pair#*:}
  run simplify dem.tif "named_$ext.out" -of "$name" -max_error 5 -q
  check "-of $name: exit 0 ($(cat err.txt))" [ "$rc" -eq 0 ]
  check "-of $name: the same file as .$ext (but the name)" \
    bash -c "sed 's/named_$ext/t/; s/date=\"[^\"]*\" time=\"[^\"]*\"//' named_$ext.out | cmp -s - <(sed 's/date=\"[^\"]*\" time=\"[^\"]*\"//' t.$ext)"
done

run simplify dem.tif local.obj -obj_local -max_error 5 -q
check "-obj_local: exit 0" [ "$rc" -eq 0 ]
check "-obj_local: the origin line" grep -q "^# origin 29 29$" local.obj
check "-obj_local: the vertices around it" \
  python3 -c 'import sys
v=[l.split() for l in open("local.obj") if l.startswith("v ")]
sys.exit(0 if max(max(abs(float(a[1])),abs(float(a[2]))) for a in v) <= 30 else 1)'

# --- 2DM's datasets beside it, -of UGRID ----------------------------------
dats="t_ins_err.dat t_star_max.dat t_star_rmse.dat t_max_err_els.dat t_rmse_els.dat t_n_samples_els.dat"
check ".2dm: its six datasets beside it" bash -c "for d in $dats; do [ -f \$d ] || exit 1; done"
check ".2dm: a dataset per vertex" \
  [ "$(grep -c . t_ins_err.dat)" -eq "$(( $(grep -c '^ND ' t.2dm) + 8 ))" ]
check ".2dm: a dataset per face" \
  [ "$(grep -c . t_max_err_els.dat)" -eq "$(( $(grep -c '^E3T ' t.2dm) + 8 ))" ]
cp t_rmse_els.dat keep.dat
: >s_rmse_els.dat
run simplify dem.tif s.2dm -max_error 5 -q
check "a dataset exists: exit 1 ($rc)" [ "$rc" -eq 1 ]
check "a dataset exists: one line naming it and -overwrite ($(cat err.txt))" \
  bash -c '[ $(wc -l <err.txt) = 1 ] && grep -q "s_rmse_els.dat" err.txt && grep -q -- "-overwrite" err.txt'
check "a dataset exists: nothing written" \
  bash -c '[ ! -e s.2dm ] && [ ! -e s_ins_err.dat ] && [ ! -s s_rmse_els.dat ]'
run simplify dem.tif t.2dm -percent 50 -q -overwrite
check "-overwrite 2DM: exit 0" [ "$rc" -eq 0 ]
check "-overwrite 2DM: the datasets replaced too" bash -c '! cmp -s t_rmse_els.dat keep.dat'
check "-overwrite 2DM: as many vertex values as vertices" \
  [ "$(grep -c . t_ins_err.dat)" -eq "$(( $(grep -c '^ND ' t.2dm) + 8 ))" ]
run simplify dem.tif x_els.2dm -q
check "_els in a 2DM name: usage error ($rc: $(cat err.txt))" [ "$rc" -eq 2 ]
check "_els in a 2DM name: nothing written" bash -c '[ -z "$(ls -A | grep "^x_els")" ]'
run simplify dem.tif u.nc -of UGRID -max_error 5 -q
check "-of UGRID: exit 0 ($(cat err.txt))" [ "$rc" -eq 0 ]
check "-of UGRID: a netCDF CDF-2 file" \
  bash -c '[ "$(head -c 4 u.nc | od -An -c | tr -d " ")" = "CDF002" ]'
run simplify dem.tif u.nc -of UGRID -max_error 5 -q
check "-of UGRID: an existing one refused ($rc)" [ "$rc" -eq 1 ]

# --- existing outputs, usage errors ---------------------------------------
cp t.ply keep.ply
run simplify dem.tif t.ply -max_error 1 -q
check "existing: exit 1 ($rc)" [ "$rc" -eq 1 ]
check "existing: one line naming -overwrite" \
  bash -c '[ $(wc -l <err.txt) = 1 ] && grep -q -- "-overwrite" err.txt'
check "existing: untouched" cmp -s t.ply keep.ply
run simplify dem.tif t.ply -percent 50 -q -overwrite
check "-overwrite: exit 0" [ "$rc" -eq 0 ]
check "-overwrite: replaced" bash -c '! cmp -s t.ply keep.ply'
run simplify dem.tif u.2dm -obj_local -q
check "-obj_local with 2DM: usage error ($rc)" [ "$rc" -eq 2 ]
run simplify dem.tif u.xml -lco FOO=BAR -q
check "-lco with LandXML: usage error ($rc)" [ "$rc" -eq 2 ]
check "usage errors: nothing written" bash -c '[ ! -e u.2dm ] && [ ! -e u.xml ] && [ ! -e u_ins_err.dat ]'

# --- failures and interrupts leave nothing ---------------------------------
run simplify dem.tif no/such/x.2dm -q
check "missing folder: exit 1 ($rc)" [ "$rc" -eq 1 ]
run generate fault big.tif -size 700 -seed 3 -q
( ulimit -f 40; "$T" simplify big.tif full.ply -max_error 0 -q >out.txt 2>err.txt ); rc=$?
check "file size limit: exit 1 ($rc: $(cat err.txt))" [ "$rc" -eq 1 ]
check "file size limit: names the output" grep -q "full.ply" err.txt
check "file size limit: nothing left" bash -c '[ ! -e full.ply ] && [ -z "$(ls -A | grep "^\.tt")" ]'
# Job control on: a background job of a non-interactive shell starts with
# SIGINT ignored (and keeps it ignored, as it should), so without it the
# signal would never reach terratin.
set -m
for ext in 2dm xml nc; do
  of=()
  [ "$ext" = nc ] && of=(-of UGRID)
  "$T" simplify big.tif "int.$ext" "${of[@]}" -max_error 0 -q >out.txt 2>err.txt &
  pid=$!
  sleep 0.4
  kill -INT "$pid" 2>/dev/null
  wait "$pid"
  rc=$?
  if [ -e "int.$ext" ]; then
    check "SIGINT .$ext: finished before the signal ($rc)" [ "$rc" -eq 0 ]
  else
    check "SIGINT .$ext: ended by it ($rc)" [ "$rc" -ne 0 ]
    check "SIGINT .$ext: no dataset file" bash -c '[ -z "$(ls -A | grep "^int_")" ]'
  fi
  check "SIGINT .$ext: no temporary file" no_temp
done
set +m

# --- QGIS ------------------------------------------------------------------
if /usr/bin/python3 -c 'import qgis' >/dev/null 2>&1; then
  QT_QPA_PLATFORM=offscreen /usr/bin/python3 - t.2dm t.ply >qgis.txt 2>&1 <<'EOF'
import sys
from qgis.core import QgsApplication, QgsMeshLayer
app = QgsApplication([], False)
app.initQgis()
for path in sys.argv[1:]:
    layer = QgsMeshLayer(path, "m", "mdal")
    print(path, layer.isValid())
app.exitQgis()
EOF
  check "QGIS: the 2DM and PLY open as mesh layers ($(cat qgis.txt))" \
    bash -c '[ $(grep -c " True$" qgis.txt) = 2 ]'
else
  echo "SKIP: python3-qgis is not installed: the QGIS mesh-layer checks skipped"
fi

echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
