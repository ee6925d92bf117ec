#!/usr/bin/env bash
# test_conventions.sh -- the command's messages and GDAL's conventions
# (issue 27), through the terratin command ($TT_TERRATIN):
#  - a mistyped option gets "did you mean" the nearest option of that
#    command (-max_eror, -maxerror, -max-eror), and only of that command
#    (tiles plan, run and merge too); a mistyped command the nearest one;
#  - '-' matches '_' in option names: -max-error is -max_error (same TIN);
#  - --formats lists GPKG, ESRI Shapefile (all layers), GeoJSON (one
#    layer), leaves CSV out, lists the mesh formats, and sees --config
#    GDAL_SKIP as a run would; --help-general lists the general options;
#  - tiles --help, and a page of its own for tiles plan, run and merge;
#    tiles in the command list of --help;
#  - rasterize DEM TIN OUTPUT and the old TIN DEM OUTPUT give the same
#    raster, the old one with a one-line note on stderr;
#  - a vector where the DEM is expected (eval, optimize, simplify,
#    rasterize), or a raster where the TIN is, names the argument;
#  - -z_unit says what the heights are, -z_to whether they become metres:
#    checked on the heights written (OBJ vertices) of a DEM whose band says
#    ft, on a UTM grid and on a state plane in feet.
# Prints "N passed, M failed"; exits 1 on any failure, 77 (skip) when a
# tool is missing.
set -u
. "$(dirname "${BASH_SOURCE[0]}")/tt_check.sh" || exit 1

T=${TT_TERRATIN:-}
if [ -z "$T" ] || [ ! -x "$T" ]; then
  echo "SKIP: TT_TERRATIN is not set or not executable"
  exit 77
fi
if ! command -v gdal_translate >/dev/null 2>&1; then
  echo "SKIP: gdal_translate is missing"
  exit 77
fi

W=$(mktemp -d "${TMPDIR:-/tmp}/tt_conventions.XXXXXX") || exit 1
trap 'rm -rf "$W"' EXIT
cd "$W" || exit 1

# run ARGS...: terratin ARGS, stdout in out.txt, stderr in err.txt, $rc
run() {
  "$T" "$@" >out.txt 2>err.txt
  rc=$?
}
# usage WHAT EXPECTED ARGS...: exit 2 and one stderr line holding EXPECTED
usage() {
  local what=$1 expected=$2
  shift 2
  run "$@"
  check "$what: exit 2 (got $rc)" test "$rc" -eq 2
  check "$what: one line" test "$(wc -l <err.txt)" -eq 1
  check "$what: says '$expected' ($(cat err.txt))" grep -qF -- "$expected" err.txt
}

"$T" generate fault dem.tif -size 40x30 -seed 3 -a_srs EPSG:32633 -q || exit 1

# --- did you mean ---------------------------------------------------------
for typo in -max_eror -maxerror -max-eror -MAX_EROR --max_eror -max_errror; do
  usage "simplify $typo" "unknown option '$typo'; did you mean -max_error?" \
    simplify "$typo" 1 dem.tif o.gpkg
done
usage "eval -max_eror" "did you mean -max_error?" eval dem.tif t.gpkg -max_eror 1
usage "generate -sise" "did you mean -size?" generate bump b.tif -sise 9
usage "rasterize -layr" "did you mean -layer?" rasterize dem.tif t.gpkg o.tif -layr x
# eval has no -max_points: no suggestion of it
run eval dem.tif t.gpkg -max_pionts 5
check "eval -max_pionts: exit 2" test "$rc" -eq 2
check "eval -max_pionts: no option of another command suggested" \
  bash -c '! grep -q "did you mean" err.txt'
usage "a word far from every option" "unknown option '-frobnicate'" \
  simplify -frobnicate dem.tif o.gpkg
check "-frobnicate: no suggestion" bash -c '! grep -q "did you mean" err.txt'
usage "simplfy" "unknown command 'simplfy'; did you mean simplify?" simplfy a b
usage "rasterise" "did you mean rasterize?" rasterise a b c
usage "tiles plan -max_eror" "unknown option '-max_eror'; did you mean -max_error?" \
  tiles plan dem.tif p.json -max_eror 1 -tile_size 16
usage "tiles merge -overwrit" "did you mean -overwrite?" \
  tiles merge p.json o.gpkg -overwrit
usage "tiles merge -max_eror: not merge's" "unknown option -max_eror (see" \
  tiles merge p.json o.gpkg -max_eror 1
usage "tiles run -overwrit" "did you mean -overwrite?" tiles run p.json 0 -overwrit

# --- '-' for '_' ----------------------------------------------------------
run simplify -json -max_error 1 dem.tif u.gpkg
vu=$(python3 -c 'import json; print(json.load(open("out.txt"))["vertices"])')
run simplify -json -max-error 1 -Max-Points 100000 dem.tif d.gpkg
check "-max-error: exit 0 ($(cat err.txt))" test "$rc" -eq 0
vd=$(python3 -c 'import json; print(json.load(open("out.txt"))["vertices"])' 2>/dev/null)
check "-max-error: the TIN of -max_error ($vu vertices, got $vd)" test "$vu" = "$vd"
run simplify -q -max_error 1 -z-factor 2 dem.tif z2.gpkg
check "-z-factor: exit 0 ($(cat err.txt))" test "$rc" -eq 0

# --- --formats, --help-general ------------------------------------------
# --formats reads back a dry run of every driver; GDAL 3.6's JML reader
# leaks its expat parser (as `simplify -of JML` does under ASan): leaks
# are not ours to see in these two runs, every other error still is.
formats() {
  ASAN_OPTIONS=${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_leaks=0 "$T" "$@" \
    >out.txt 2>err.txt
  rc=$?
}
formats --formats
check "--formats: exit 0" test "$rc" -eq 0
check "--formats: GPKG, all layers" grep -qE '^  GPKG +GeoPackage.*: all layers' out.txt
check "--formats: ESRI Shapefile, all layers" \
  grep -qE '^  ESRI Shapefile +.*: all layers' out.txt
check "--formats: GeoJSON holds one layer" \
  grep -qE '^  GeoJSON +.*one layer \(-layers triangles\|vertices' out.txt
check "--formats: CSV (refused by a run) left out" bash -c '! grep -qE "^  CSV " out.txt'
check "--formats: PostgreSQL among the databases" \
  grep -qE '^  PostgreSQL +.*PG:' out.txt
for m in 2DM PLY OBJ LandXML DXF UGRID; do
  check "--formats: mesh format $m" grep -qE "^  $m " out.txt
done
formats --config GDAL_SKIP GeoJSON --formats
check "--formats after --config GDAL_SKIP GeoJSON: no GeoJSON" \
  bash -c '! grep -qE "^  GeoJSON " out.txt && grep -qE "^  GPKG " out.txt'
# every OGR driver listed is one a run writes: GeoJSON's one layer, as listed
run simplify -q -of GeoJSON -layers triangles -max_error 0.1 dem.tif t.geojson
check "a listed layer of GeoJSON is written ($(cat err.txt))" test "$rc" -eq 0
run --help-general
check "--help-general: exit 0" test "$rc" -eq 0
for o in --help --help-general --version --formats --config --debug -q; do
  check "--help-general lists $o" grep -qE "^  $o( |,)" out.txt
done
check "--help-general: '-' matches '_'" grep -q -- "-max-error is -max_error" out.txt
run --help
check "--help names --help-general and --formats" \
  grep -qF -- "--help | --help-general | --version | --formats" out.txt

# --- tiles --help ----------------------------------------------------------
run --help
check "--help lists tiles" grep -qE '^  tiles +plan, run and merge' out.txt
for words in "tiles --help" "tiles -h" "help tiles" "--help tiles"; do
  # shellcheck disable=SC2086
  run $words
  check "$words: exit 0" test "$rc" -eq 0
  check "$words: the tiles page" bash -c \
    'head -1 out.txt | grep -q "^Usage: terratin tiles plan" &&
     grep -q "tiles plan|run|merge --help" out.txt'
done
for sub in plan run merge; do
  for h in --help -h; do
    run tiles "$sub" "$h"
    check "tiles $sub $h: exit 0" test "$rc" -eq 0
    check "tiles $sub $h: its own page" bash -c \
      "head -1 out.txt | grep -q '^Usage: terratin tiles $sub ' &&
       grep -q '^Example:' out.txt && grep -q '^Exit codes' out.txt"
  done
done
run tiles merge plan.json out.gpkg -of GPKG --help
check "tiles merge ... --help wins over the rest" test "$rc" -eq 0
usage "tiles alone" "see 'terratin tiles --help'" tiles

# --- rasterize: both orders --------------------------------------------------
"$T" simplify -q -max_error 2 dem.tif tin.gpkg || exit 1
run rasterize -q dem.tif tin.gpkg new.tif
check "rasterize DEM TIN OUT: exit 0 ($(cat err.txt))" test "$rc" -eq 0
check "rasterize DEM TIN OUT: nothing on stderr" test ! -s err.txt
run rasterize -q tin.gpkg dem.tif old.tif
check "rasterize TIN DEM OUT: exit 0 ($(cat err.txt))" test "$rc" -eq 0
check "rasterize TIN DEM OUT: one line on stderr" test "$(wc -l <err.txt)" -eq 1
check "rasterize TIN DEM OUT: the note names the new order" \
  grep -q "note: TIN DEM OUTPUT is the old order.*'terratin rasterize dem.tif tin.gpkg old.tif'" err.txt
sum_new=$(gdalinfo -checksum new.tif 2>/dev/null | grep Checksum)
sum_old=$(gdalinfo -checksum old.tif 2>/dev/null | grep Checksum)
check "both orders: the same raster ($sum_new, $sum_old)" \
  test -n "$sum_new" -a "$sum_new" = "$sum_old"
check "both orders: the same bytes" cmp -s new.tif old.tif
usage "rasterize: missing TIN" "rasterize: missing TIN and OUTPUT" rasterize dem.tif

# --- a vector where a raster is expected, and the other way ------------------
for c in "eval tin.gpkg dem.tif" "optimize tin.gpkg dem.tif o.gpkg" \
         "simplify tin.gpkg o.gpkg" "rasterize tin.gpkg tin.gpkg r.tif"; do
  # shellcheck disable=SC2086
  run $c
  cmd=${c%% *}
  check "$c: exit 1 (got $rc)" test "$rc" -eq 1
  check "$c: names argument 1 ($(cat err.txt))" grep -qF \
    "terratin: $cmd: tin.gpkg (argument 1) is a vector dataset (GPKG); the DEM (a raster) comes first" err.txt
done
run tiles plan tin.gpkg p.json -max_error 1 -tile_size 16
check "tiles plan TIN: names argument 1 ($(cat err.txt))" grep -qF \
  "terratin: tiles plan: tin.gpkg (argument 1) is a vector dataset (GPKG); the DEM (a raster) comes first" err.txt
check "tiles plan TIN: no plan written" test ! -e p.json
run eval dem.tif dem.tif
check "eval DEM DEM: names argument 2 ($(cat err.txt))" grep -qF \
  "terratin: eval: dem.tif (argument 2) is a raster; the TIN (a vector dataset of triangles) comes after the DEM" err.txt
check "no output left" test ! -e o.gpkg -a ! -e r.tif

# --- -z_unit and -z_to -------------------------------------------------------
# max_z FILE.obj: the largest vertex height written
max_z() { python3 -c '
import sys
print(max(float(l.split()[3]) for l in open(sys.argv[1]) if l.startswith("v ")))' "$1"; }
raw=$(gdal_translate -q -of AAIGrid -co DECIMAL_PRECISION=17 dem.tif \
  /vsistdout/ | python3 -c '
import sys
print(max(float(v) for l in sys.stdin if l.strip()[:1] in "-0123456789" for v in l.split()))')
gdal_translate -q -of VRT dem.tif ft.vrt || exit 1
sed -i 's|\(<VRTRasterBand[^>]*>\)|\1<UnitType>ft</UnitType>|' ft.vrt
gdal_translate -q -of VRT -a_srs EPSG:2263 dem.tif ftcrs.vrt || exit 1
"$T" generate fault geo.tif -size 40x30 -seed 3 -a_srs EPSG:4326 -q || exit 1
# zrun WHAT FACTOR UNIT SOURCE WHY ARGS...: max z = raw x FACTOR, and -json
# says z_unit UNIT, z_unit_source SOURCE and z_unit_conversion WHY ("" for
# none: null)
zrun() {
  local what=$1 factor=$2 unit=$3 source=$4 why=$5
  shift 5
  rm -f z.obj
  run simplify -json -max_error 0 -of OBJ "$@" z.obj
  check "$what: exit 0 ($(cat err.txt))" test "$rc" -eq 0
  local z
  z=$(max_z z.obj 2>/dev/null)
  check "$what: max z $z = $raw x $factor" python3 -c '
import sys
z, raw, f = map(float, sys.argv[1:])
assert abs(z - raw * f) <= 1e-6 * max(1, abs(z)), (z, raw * f)' "${z:-nan}" "$raw" "$factor"
  check "$what: -json z_unit $unit, source '$source', why '$why'" python3 -c '
import json, sys
d = json.load(open("out.txt"))
unit, source, why = sys.argv[1:]
got = (d["z_unit"], d["z_unit_source"], d["z_unit_conversion"])
assert got == (unit or None, source or None, why or None), got' \
    "$unit" "$source" "$why"
}
zrun "band ft, UTM: metres by default" 0.3048 m "band unit" \
  "the CRS is in metres" ft.vrt
zrun "band ft, UTM, -z_to native: ft kept" 1 ft "band unit" "" -z_to native ft.vrt
zrun "band ft, -z_unit m: the heights are metres" 1 m -z_unit "" -z_unit m ft.vrt
zrun "no unit, UTM, -z_unit us-ft" 0.3048006096 m -z_unit \
  "the CRS is in metres" -z_unit us-ft dem.tif
zrun "no unit, UTM: unknown, kept" 1 "" "" "" dem.tif
zrun "state plane in ft, -z_unit ft: kept in ft" 1 ft -z_unit "" -z_unit ft ftcrs.vrt
zrun "state plane in ft, -z_unit ft -z_to m: converted" 0.3048 m -z_unit \
  "asked by -z_to m" -z_unit ft -z_to m ftcrs.vrt
zrun "geographic, -z_unit ft: converted" 0.3048 m -z_unit \
  "the CRS is geographic" -z_unit ft geo.tif
run simplify -max_error 0 -z_unit ft ft.vrt zs.gpkg
check "the summary says why (-z_unit ft on UTM)" grep -q "the CRS is in metres" out.txt
run simplify -q -json -max_error 0 -z_unit ft dem.tif zj.gpkg
check "-json says why: z_unit_conversion" python3 -c '
import json
d = json.load(open("out.txt"))
assert d["z_unit"] == "m" and d["z_unit_source"] == "-z_unit", d
assert d["z_unit_conversion"] == "the CRS is in metres", d
assert abs(d["z_multiplier"] - 0.3048) < 1e-15, d'
run simplify -q -max_error 0 -z_to m dem.tif x.gpkg
check "-z_to m, unknown unit: exit 1" test "$rc" -eq 1
check "-z_to m, unknown unit: says why and the way out ($(cat err.txt))" \
  grep -q "asked by .*-z_to m.*unknown.*-z_unit ft|us-ft|m.*-z_factor" err.txt
usage "-z_unit cm" "-z_unit must be ft, us-ft or m" simplify -z_unit cm dem.tif x.gpkg
usage "-z_to x" "-z_to must be m" simplify -z_to x dem.tif x.gpkg
check "nothing written by the refusals" test ! -e x.gpkg
# eval reads the DEM as simplify did: a TIN of the ft DEM in metres
# measures within its bound with the same options, and is 1/0.3048 off
# without them (the heights then stay ft)
"$T" simplify -q -max_error 0.5 ft.vrt ftm.gpkg || exit 1
run eval -json ft.vrt ftm.gpkg
e_m=$(python3 -c 'import json; print(json.load(open("out.txt"))["max_error"])')
check "eval, default -z_to: the TIN within its bound ($e_m)" \
  python3 -c 'import sys; assert float(sys.argv[1]) <= 0.5' "$e_m"
run eval -json -z_to native ft.vrt ftm.gpkg
e_ft=$(python3 -c 'import json; print(json.load(open("out.txt"))["max_error"])')
check "eval -z_to native: the TIN is far off in ft ($e_ft)" \
  python3 -c 'import sys; assert float(sys.argv[1]) > 10' "$e_ft"

echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
