#!/usr/bin/env bash
# test_postgis.sh -- `terratin simplify` into PostgreSQL/PostGIS through
# OGR ($TT_TERRATIN), issue 17, against a real server that this test
# starts: initdb into a temporary folder, the server on a Unix socket in
# that folder (no TCP: listen_addresses=''), CREATE EXTENSION postgis, and
# the server stopped on every exit path (trap). As root (CI runs make check
# as root), initdb and postgres refuse to run: they run as the unprivileged
# user nobody, owner of the folder.
#  - -of PostgreSQL "PG:..." and the same guessed from the "PG:" prefix:
#    counts equal the run's, every triangle ST_IsValid, the SRID the DEM's,
#    ST_Area equal to our area_2d;
#  - QGIS's layer_styles table with a default style per geometry layer
#    (catalog, schema, table, geometry column; the triangles' QML on
#    max_err with see-through fills), one per table after -overwrite, in
#    the -lco SCHEMA's name; every column's description as its comment;
#    QGIS opens the table with the style and the comments (when
#    python3-qgis is installed);
#  - existing tables refused without -overwrite (before the work, the old
#    tables untouched), replaced with it; -lco SCHEMA=...;
#  - a write that fails half way (-lco FID=v0 clashing with a field) leaves
#    no table, and with -overwrite leaves the old tables as they were;
#  - SIGTERM (handled as SIGINT) and SIGKILL while the write's
#    transaction is open leave no table;
#  - a password in the connection string never appears in messages, the
#    summary, -json or run_parameters, in every form libpq reads.
# Skipped (77) with a message when PostgreSQL's server or PostGIS is not
# installed (apt-get install postgresql-15 postgresql-15-postgis-3).
# Prints "N passed, M failed"; exits 1 on any failure.
set -u
. "$(dirname "${BASH_SOURCE[0]}")/../apps/tt_check.sh" || exit 1

T=${TT_TERRATIN:-}
if [ -z "$T" ] || [ ! -x "$T" ]; then
  echo "SKIP: TT_TERRATIN is not set or not executable"
  exit 77
fi
PGBIN=$(ls -d /usr/lib/postgresql/*/bin 2>/dev/null | sort -V | tail -1)
if [ -z "$PGBIN" ] || [ ! -x "$PGBIN/initdb" ] || [ ! -x "$PGBIN/pg_ctl" ] ||
   ! command -v psql >/dev/null 2>&1; then
  echo "SKIP: the PostgreSQL server is not installed (apt-get install postgresql-15)"
  exit 77
fi
PGVER=$(basename "$(dirname "$PGBIN")")
if ! ls /usr/share/postgresql/"$PGVER"/extension/postgis.control >/dev/null 2>&1; then
  echo "SKIP: PostGIS is not installed (apt-get install postgresql-$PGVER-postgis-3)"
  exit 77
fi
if ! ogrinfo --formats 2>/dev/null | grep -q PostgreSQL; then
  echo "SKIP: this GDAL has no PostgreSQL driver"
  exit 77
fi

W=$(mktemp -d "${TMPDIR:-/tmp}/tt_pg.XXXXXX") || exit 1
# The server runs as its own user when we are root.
AS=()
if [ "$(id -u)" = 0 ]; then
  if ! id nobody >/dev/null 2>&1 || ! command -v runuser >/dev/null 2>&1; then
    echo "SKIP: running as root without the user nobody or runuser"
    rm -rf "$W"
    exit 77
  fi
  chmod 755 "$W"
  AS=(runuser -u nobody --)
fi
mkdir "$W/db" "$W/work"
[ "${#AS[@]}" -gt 0 ] && chown nobody "$W/db"
started=0
cleanup() {
  if [ "$started" = 1 ]; then
    "${AS[@]}" "$PGBIN/pg_ctl" -D "$W/db/data" -m immediate -w stop \
      >/dev/null 2>&1
  fi
  rm -rf "$W"
}
trap cleanup EXIT
trap 'exit 1' INT TERM HUP

if ! "${AS[@]}" "$PGBIN/initdb" -D "$W/db/data" -U tt --auth=trust -E UTF8 \
     >"$W/initdb.log" 2>&1; then
  echo "FAIL: initdb: $(tail -3 "$W/initdb.log")"
  exit 1
fi
if ! "${AS[@]}" "$PGBIN/pg_ctl" -D "$W/db/data" -l "$W/db/server.log" -w \
     -o "-k $W/db -c listen_addresses=''" start >/dev/null 2>&1; then
  echo "FAIL: the server did not start: $(tail -3 "$W/db/server.log" 2>/dev/null)"
  exit 1
fi
started=1
S=$W/db
q() { psql -h "$S" -U tt -d postgres -X -q -At -c "$1" 2>&1; }
if [ "$(q 'CREATE EXTENSION postgis; SELECT 1')" != 1 ]; then
  echo "FAIL: CREATE EXTENSION postgis failed"
  exit 1
fi
cd "$W/work" || exit 1
PG="PG:host=$S dbname=postgres user=tt"

not() { ! "$@"; }
rc=0
run() {
  "$T" "$@" >out.txt 2>err.txt
  rc=$?
}
json_get() {
  python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))[sys.argv[2]])' "$1" "$2"
}
tables() { # tables in schema $1, sorted, space-separated
  q "SELECT string_agg(table_name, ' ' ORDER BY table_name) FROM
     information_schema.tables WHERE table_schema = '$1'
     AND table_name IN ('triangles', 'vertices', 'run_parameters')"
}

# --- the DEM -----------------------------------------------------------------
run generate fault dem.tif -size 90x70 -seed 3 -displacement 20 \
  -wave_size 5 -a_srs EPSG:32633 -q
check "generate: exit 0 ($(cat err.txt))" [ "$rc" -eq 0 ]

# --- a run into the database ------------------------------------------------
run simplify -json -max_error 1 -of PostgreSQL dem.tif "$PG"
check "simplify into PostgreSQL: exit 0 ($(head -c 300 err.txt))" [ "$rc" -eq 0 ]
cp out.txt run1.json
NV=$(json_get run1.json vertices)
NT=$(json_get run1.json triangles)
check "the three tables" [ "$(tables public)" = "run_parameters triangles vertices" ]
check "triangles: $NT rows" [ "$(q 'SELECT count(*) FROM triangles')" = "$NT" ]
check "vertices: $NV rows" [ "$(q 'SELECT count(*) FROM vertices')" = "$NV" ]
check "run_parameters: one row" [ "$(q 'SELECT count(*) FROM run_parameters')" = 1 ]
check "every triangle valid (ST_IsValid)" \
  [ "$(q 'SELECT bool_and(ST_IsValid(wkb_geometry)) FROM triangles')" = t ]
check "SRID 32633 on both layers" \
  [ "$(q "SELECT Find_SRID('public', 'triangles', 'wkb_geometry') ||
          ',' || Find_SRID('public', 'vertices', 'wkb_geometry')")" = "32633,32633" ]
check "3-D geometry" [ "$(q 'SELECT min(ST_NDims(wkb_geometry)) FROM triangles')" = 3 ]
rel=$(q 'SELECT max(abs(ST_Area(wkb_geometry) - area_2d) / area_2d) FROM triangles')
check "ST_Area equals area_2d (largest relative difference $rel)" \
  python3 -c 'import sys; assert float(sys.argv[1]) < 1e-9' "$rel"
check "vertex ids 0..$((NV - 1))" [ "$(q "SELECT min(vertex_id) || ',' ||
  max(vertex_id) || ',' || count(DISTINCT vertex_id) FROM vertices")" = \
  "0,$((NV - 1)),$NV" ]
check "the run's vertices recorded" \
  [ "$(q 'SELECT vertices FROM run_parameters')" = "$NV" ]
styles() { # the default styles of schema $1: table:geometry column
  q "SELECT string_agg(f_table_name || ':' || f_geometry_column, ' ' ORDER
     BY f_table_name) FROM layer_styles WHERE useAsDefault AND type IS NULL
     AND f_table_catalog = 'postgres' AND f_table_schema = '$1'"
}
check "layer_styles: a default style per geometry layer ($(styles public))" \
  [ "$(styles public)" = "triangles:wkb_geometry vertices:wkb_geometry" ]
check "layer_styles: the triangles' QML on max_err, see-through" \
  [ "$(q "SELECT count(*) FROM layer_styles WHERE f_table_name = 'triangles'
          AND xpath_exists('/qgis/renderer-v2[@attr=\"max_err\"]', styleQML)
          AND xpath_exists('//symbol[@type=\"fill\" and @alpha < 1]',
                           styleQML)")" = 1 ]

uncommented() { # the columns of table $1 (schema public) without a comment
  q "SELECT count(*) FROM pg_attribute WHERE attrelid = 'public.$1'::regclass
     AND attnum > 0 AND NOT attisdropped AND attname NOT IN ('ogc_fid',
     'wkb_geometry') AND col_description(attrelid, attnum) IS NULL"
}
for t in triangles vertices run_parameters; do
  check "every column of $t described (COMMENT ON COLUMN)" \
    [ "$(uncommented $t)" = 0 ]
done
check "max_err's comment and unit" \
  [ "$(q "SELECT col_description('public.triangles'::regclass, attnum) FROM
          pg_attribute WHERE attrelid = 'public.triangles'::regclass AND
          attname = 'max_err'")" = \
    "largest |TIN - DEM| of the samples in this triangle (z units)" ]

# QGIS (when python3-qgis is installed) opens the table with that style
if /usr/bin/python3 -c 'import qgis.core' >/dev/null 2>&1; then
  mkdir -m 700 "$W/xdg"
  QT_QPA_PLATFORM=offscreen XDG_RUNTIME_DIR="$W/xdg" /usr/bin/python3 - "$S" \
    >qgis.txt 2>qgis_err.txt <<'EOF'
import sys
from qgis.core import QgsApplication, QgsVectorLayer
app = QgsApplication([], False)
app.initQgis()
def main():
    uri = ("host=%s dbname=postgres user=tt key='ogc_fid' "
           "table=\"public\".\"triangles\" (wkb_geometry)" % sys.argv[1])
    layer = QgsVectorLayer(uri, "triangles", "postgres")
    r = layer.renderer() if layer.isValid() else None
    print(layer.isValid(), r.type() if r else None,
          r.classAttribute() if r and r.type() == "graduatedSymbol" else None,
          layer.fields().field("max_err").comment().startswith("largest"))
main()
app.exitQgis()
EOF
  check "QGIS opens the triangles styled ($(cat qgis.txt))" \
    [ "$(cat qgis.txt)" = "True graduatedSymbol max_err True" ]
else
  echo "SKIP: python3-qgis is not installed: QGIS reading layer_styles skipped"
fi

# --- existing tables ------------------------------------------------------------
"$T" simplify -max_error 1 dem.tif "$PG" >out.txt 2>err.txt
rc=$?
check "existing tables: refused (exit $rc)" [ "$rc" -eq 1 ]
check "existing tables: one line naming -overwrite" \
  [ "$(wc -l <err.txt)" = 1 -a -n "$(grep -- -overwrite err.txt)" ]
check "existing tables: refused before the DEM is read" not grep -q 10 out.txt
check "existing tables: untouched" [ "$(q 'SELECT count(*) FROM triangles')" = "$NT" ]
run simplify -json -overwrite -max_error 3 dem.tif "$PG"
check "-overwrite (format from the PG: prefix): exit 0 ($(head -c 300 err.txt))" \
  [ "$rc" -eq 0 ]
NT2=$(json_get out.txt triangles)
check "-overwrite: the new triangles ($NT2, fewer than $NT)" \
  [ "$(q 'SELECT count(*) FROM triangles')" = "$NT2" -a "$NT2" -lt "$NT" ]
check "-overwrite: one run_parameters row" \
  [ "$(q 'SELECT count(*) FROM run_parameters')" = 1 ]
check "-overwrite: still one style per layer" \
  [ "$(q 'SELECT count(*) FROM layer_styles')" = 2 ]

# --- -lco SCHEMA -------------------------------------------------------------
q 'CREATE SCHEMA tin' >/dev/null
run simplify -q -max_error 1 -lco SCHEMA=tin dem.tif "$PG"
check "-lco SCHEMA=tin: exit 0 ($(head -c 300 err.txt))" [ "$rc" -eq 0 ]
check "-lco SCHEMA=tin: the tables there" \
  [ "$(tables tin)" = "run_parameters triangles vertices" ]
check "-lco SCHEMA=tin: $NT triangles" [ "$(q 'SELECT count(*) FROM tin.triangles')" = "$NT" ]
check "-lco SCHEMA=tin: public left alone" \
  [ "$(q 'SELECT count(*) FROM public.triangles')" = "$NT2" ]
check "-lco SCHEMA=tin: its styles name the schema ($(styles tin))" \
  [ "$(styles tin)" = "triangles:wkb_geometry vertices:wkb_geometry" ]
run simplify -q -max_error 1 -lco SCHEMA=tin dem.tif "$PG"
check "-lco SCHEMA=tin again: refused" [ "$rc" -eq 1 ]
check "-lco SCHEMA=tin again: names tin.triangles" grep -q 'tin\.triangles' err.txt
run simplify -q -overwrite -max_error 3 -lco SCHEMA=tin -layers triangles dem.tif "$PG"
check "-lco SCHEMA=tin -overwrite -layers triangles: exit 0 ($(head -c 300 err.txt))" \
  [ "$rc" -eq 0 ]
check "-lco SCHEMA=tin -overwrite: replaced" \
  [ "$(q 'SELECT count(*) FROM tin.triangles')" = "$NT2" ]

# --- failures leave nothing ------------------------------------------------------
q 'CREATE SCHEMA fail' >/dev/null
run simplify -q -max_error 1 -lco SCHEMA=fail -lco FID=v0 dem.tif "$PG"
check "a write failing half way: exit 1 ($rc)" [ "$rc" -eq 1 ]
check "a write failing half way: one line" [ "$(wc -l <err.txt)" = 1 ]
check "a write failing half way: no table left" [ -z "$(tables fail)" ]
run simplify -q -overwrite -max_error 1 -lco FID=v0 dem.tif "$PG"
check "-overwrite failing half way: exit 1" [ "$rc" -eq 1 ]
check "-overwrite failing half way: the old tables as they were" \
  [ "$(tables public)" = "run_parameters triangles vertices" -a \
    "$(q 'SELECT count(*) FROM triangles')" = "$NT2" ]
run simplify -q -max_error 1 -lco SCHEMA=nosuch dem.tif "$PG"
check "a schema that does not exist: exit 1" [ "$rc" -eq 1 ]
run simplify -q -max_error 1 dem.tif "PG:host=$S dbname=nosuchdb user=tt password=s3cret"
check "a database that does not exist: exit 1" [ "$rc" -eq 1 ]
check "a database that does not exist: one line" [ "$(wc -l <err.txt)" = 1 ]
check "the password is never shown" not grep -q s3cret err.txt
# Runs that succeed (the server trusts any password): every form libpq
# reads, the summary and -json name the connection with *** and nothing of
# the password (tests/apps/test_passwords.sh has the failing runs).
SENC=$(python3 -c 'import sys, urllib.parse; print(urllib.parse.quote(sys.argv[1], safe=""))' "$S")
for conn in "PG:host=$S dbname=postgres user=tt password=s3cretpw" \
            "PG:host=$S dbname=postgres user=tt password = s3cretpw" \
            "PG:host=$S dbname=postgres user=tt password='s3c\\'ret pw'" \
            "PG:postgresql://tt:s3cretpw@$SENC/postgres" \
            "postgresql://tt:s3cretpw@$SENC/postgres"; do
  run simplify -overwrite -max_error 3 dem.tif "$conn"
  check "summary, $conn: exit 0 ($(head -c 300 err.txt))" [ "$rc" -eq 0 ]
  check "summary, $conn: names ***" grep -qF '***' out.txt
  check "summary, $conn: no password" not grep -qE "s3c|ret pw|cretpw" out.txt err.txt
  run simplify -json -overwrite -max_error 3 dem.tif "$conn"
  check "-json, $conn: exit 0" [ "$rc" -eq 0 ]
  check "-json, $conn: output names ***" \
    python3 -c 'import json,sys; assert "***" in json.load(open(sys.argv[1]))["output"]' out.txt
  check "-json, $conn: no password" not grep -qE "s3c|ret pw|cretpw" out.txt err.txt
  check "run_parameters, $conn: no password" \
    not grep -qE "s3c|cretpw" <<<"$(q 'SELECT * FROM run_parameters')"
done

# Interrupted while the transaction is open: SIGTERM (the run's own stop,
# as for SIGINT, which a background job of a script ignores: the run rolls
# back) and SIGKILL (the server rolls back when the connection drops).
run generate diamond_square big.tif -size 513 -seed 1 -a_srs EPSG:32633 -q
in_transaction() { # the write's connection has an open transaction
  [ "$(q "SELECT count(*) FROM pg_stat_activity WHERE backend_type =
          'client backend' AND xact_start IS NOT NULL AND pid <>
          pg_backend_pid()")" -gt 0 ]
}
for sig in TERM KILL; do
  schema=intr_$(echo $sig | tr A-Z a-z)
  q "CREATE SCHEMA $schema" >/dev/null
  "$T" simplify -q -max_error 0.5 -lco SCHEMA=$schema big.tif "$PG" \
    >out.txt 2>err.txt &
  pid=$!
  seen=0
  for _ in $(seq 600); do
    if in_transaction; then seen=1; break; fi
    kill -0 $pid 2>/dev/null || break
    sleep 0.05
  done
  kill -$sig $pid 2>/dev/null
  { wait $pid; } 2>/dev/null
  rc=$?
  if [ "$seen" = 1 ]; then
    check "SIG$sig during the write: killed by it ($rc)" [ "$rc" -gt 128 ]
    check "SIG$sig during the write: no table left" [ -z "$(tables $schema)" ]
    for _ in $(seq 100); do in_transaction || break; sleep 0.05; done
    check "SIG$sig: no transaction left open" not in_transaction
  else
    fail "SIG$sig: the write's transaction was never seen open (rc $rc: $(head -c 200 err.txt))"
  fi
done

echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
