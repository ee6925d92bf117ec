#!/usr/bin/env bash
# test_passwords.sh -- a PostgreSQL password never shows, through the
# terratin command ($TT_TERRATIN), in any form libpq reads: keyword/value
# (password=pw), blanks around '=' (password = pw), quoted values with \'
# (password='pa\'ss x'), the URI's user:pw@ and ?password=, each bare and
# behind GDAL's "PG:"; a password of 2 characters; '' (no escape for
# libpq) refused before connecting (exit 2), since libpq's error would
# quote a piece of it. Every place a name is printed or stored is looked
# at:
#  - stderr of runs that fail (no server listens on port 1, so no
#    PostgreSQL is needed), as output, as the DEM, as eval's TIN, for a
#    usage error, for `tiles plan`, with -json and with --debug on;
#  - stdout's summary, -json and the run_parameters row of runs that
#    succeed, with DEMs whose file names libpq reads as connection strings
#    (password=s3cretpw.tif, the folders of postgresql://u:pw@h/db).
# tests/apps/test_postgis.sh checks the same against a real server.
# Prints "N passed, M failed"; exits 1 on any failure, 77 (skip) when a tool
# is missing.
set -u
. "$(dirname "${BASH_SOURCE[0]}")/tt_check.sh" || exit 1

T=${TT_TERRATIN:-}
if [ -z "$T" ] || [ ! -x "$T" ]; then
  echo "SKIP: TT_TERRATIN is not set or not executable"
  exit 77
fi
if ! python3 -c 'import sqlite3' 2>/dev/null; then
  echo "SKIP: python3 has no sqlite3 module"
  exit 77
fi

W=$(mktemp -d "${TMPDIR:-/tmp}/tt_passwords.XXXXXX") || exit 1
trap 'rm -rf "$W"' EXIT
cd "$W" || exit 1

"$T" generate bump dem.tif -size 17 -q || exit 1

rc=0
run() {
  "$T" "$@" >out.txt 2>err.txt
  rc=$?
}
# hidden WHAT PIECE...: no PIECE in stdout, stderr or the given files.
hidden() {
  local what=$1 p f
  shift
  for p in "$@"; do
    for f in out.txt err.txt; do
      if grep -qF -- "$p" "$f"; then
        fail "$what: '$p' in $f: $(head -c 400 "$f")"
        return
      fi
    done
  done
  pass
}
# failed WHAT CODE: exit CODE, one "terratin: " line naming *** on stderr.
failed() {
  if [ "$rc" = "$2" ]; then pass; else
    fail "$1: exit code $rc, expected $2 ($(head -c 300 err.txt))"; fi
  if grep -q '^terratin: .*\*\*\*' err.txt &&
     [ "$(grep -vc '^terratin: debug' err.txt)" = 1 ]; then pass
  else fail "$1: stderr is not one line naming ***: $(head -c 400 err.txt)"; fi
}

# --- connections that fail: every form, every command line place --------
# "name|pieces of its password, comma-separated"
NOPORT="host=127.0.0.1 port=1"
FORMS=(
  "PG:dbname=db $NOPORT password=s3cretpw|s3cr,cretpw"
  "PG:dbname=db $NOPORT password = s3cretpw|s3cr,cretpw"
  "PG:dbname=db $NOPORT password='pa\\'ss x'|pa',ss x, x','ss"
  "PG:dbname=db $NOPORT password='pa\\\\ss x'|pa\\,ss x, x'"
  "PG:dbname=db $NOPORT password=ab|=ab"
  "postgresql://user:s3cretpw@127.0.0.1:1/db|s3cr,cretpw"
  "PG:postgresql://user:s3cretpw@127.0.0.1:1/db|s3cr,cretpw"
  "postgresql://user:ab@127.0.0.1:1/db|:ab@"
  "postgresql://127.0.0.1:1/db?password=s3cretpw|s3cr,cretpw"
)
for f in "${FORMS[@]}"; do
  name=${f%%|*}
  IFS=, read -r -a pieces <<<"${f#*|}"
  run simplify dem.tif "$name" -of PostgreSQL -q
  failed "output $name" 1
  hidden "output $name" "${pieces[@]}"
  run simplify dem.tif "$name" -json
  failed "output (guessed, -json) $name" 1
  hidden "output (guessed, -json) $name" "${pieces[@]}"
  run --debug on simplify dem.tif "$name" -q
  hidden "output (--debug on) $name" "${pieces[@]}"
  run simplify "$name" out.gpkg -q
  failed "DEM $name" 1
  hidden "DEM $name" "${pieces[@]}"
  run eval dem.tif "$name"
  failed "eval TIN $name" 1
  hidden "eval TIN $name" "${pieces[@]}"
  run simplify "$name"
  failed "usage error $name" 2
  hidden "usage error $name" "${pieces[@]}"
  run tiles plan "$name" plan.json -max_error 1 -tile_size 16
  failed "tiles plan $name" 1
  hidden "tiles plan $name" "${pieces[@]}"
done
check "no output file was made" test ! -e out.gpkg

# '' is no escape for libpq: refused before any connection, nothing of
# the password quoted
for name in "PG:dbname=db $NOPORT password='pa''ss x'" \
            "PG:dbname=db $NOPORT PASSWORD=s3cretpw"; do
  run simplify dem.tif "$name" -of PostgreSQL
  failed "unparsable $name" 2
  hidden "unparsable $name" "ss x" "'ss" s3cr
  check "unparsable $name: says libpq cannot parse it" \
    grep -q 'libpq cannot parse' err.txt
done

# --- runs that succeed: the summary, -json, run_parameters ---------------
# input_of GPKG: the input recorded in run_parameters.
input_of() {
  python3 - "$1" <<'EOF'
import sqlite3, sys
print(sqlite3.connect(sys.argv[1]).execute(
    "SELECT input FROM run_parameters").fetchone()[0])
EOF
}
mkdir -p "postgresql:/u:s3cretpw@h"
cp dem.tif "postgresql:/u:s3cretpw@h/db"
cp dem.tif "password=s3cretpw.tif"
cp dem.tif "password = s3cretpw.tif"
cp dem.tif "password='pa\\'ss x'"
i=0
for f in "password=s3cretpw.tif|password=***|s3cr,cretpw" \
         "password = s3cretpw.tif|password=***|s3cr,cretpw" \
         "password='pa\\'ss x'|password=***|pa',ss x, x','ss" \
         "postgresql://u:s3cretpw@h/db|postgresql://u:***@h/db|s3cr,cretpw"; do
  name=${f%%|*}
  rest=${f#*|}
  shown=${rest%%|*}
  IFS=, read -r -a pieces <<<"${rest#*|}"
  i=$((i + 1))
  run simplify "$name" "o$i.gpkg"
  check "summary $name: exit 0 ($(head -c 300 err.txt))" test "$rc" = 0
  hidden "summary $name" "${pieces[@]}"
  run simplify "$name" "j$i.gpkg" -json
  check "-json $name: exit 0" test "$rc" = 0
  check "-json $name: input shown as $shown" \
    grep -qF "\"input\": \"$shown\"" out.txt
  hidden "-json $name" "${pieces[@]}"
  run --debug on simplify "$name" "d$i.gpkg" -q
  hidden "--debug on $name" "${pieces[@]}"
  input_of "o$i.gpkg" >out.txt 2>err.txt
  check "run_parameters $name: input is $shown, not $(cat out.txt)" \
    test "$(cat out.txt)" = "$shown"
  hidden "run_parameters $name" "${pieces[@]}"
  run eval "$name" "o$i.gpkg" -json
  check "eval -json $name: exit 0" test "$rc" = 0
  hidden "eval -json $name" "${pieces[@]}"
  run rasterize "$name" "o$i.gpkg" "r$i.tif"
  check "rasterize $name: exit 0" test "$rc" = 0
  hidden "rasterize $name" "${pieces[@]}"
done
# an output named like a connection string: the summary names it masked
run simplify dem.tif "password=s3cretpw.gpkg"
check "output password=s3cretpw.gpkg: exit 0" test "$rc" = 0
check "output password=s3cretpw.gpkg: summary names password=***" \
  grep -qF "output: password=*** (layers " out.txt
hidden "output password=s3cretpw.gpkg" s3cr cretpw

echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
