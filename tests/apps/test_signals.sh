#!/usr/bin/env bash
# test_signals.sh -- what a signal does to a run, through the terratin
# command ($TT_TERRATIN), and that --help says so: SIGINT (Ctrl-C),
# SIGTERM and SIGHUP sent to a running simplify (whole and tiled, on 2
# threads) end it with the shell's 128 + the signal (130, 143, 129), one
# "interrupted" line on stderr, and nothing in the output folder (neither
# the output nor a temporary); `terratin --help` and every command's help
# give the same codes, and no longer put an interruption under exit 1.
# Prints "N passed, M failed"; exits 1 on any failure, 77 (skip) when a tool
# is missing.
set -u
. "$(dirname "${BASH_SOURCE[0]}")/tt_check.sh" || exit 1

T=${TT_TERRATIN:-}
if [ -z "$T" ] || [ ! -x "$T" ]; then
  echo "SKIP: TT_TERRATIN is not set or not executable"
  exit 77
fi

W=$(mktemp -d "${TMPDIR:-/tmp}/tt_signals.XXXXXX") || exit 1
trap 'rm -rf "$W"' EXIT
cd "$W" || exit 1

# --- the help ----------------------------------------------------------------
"$T" --help >help.txt 2>&1
check "--help: 128+N for a signal" grep -q '128+N' help.txt
check "--help: 130 for SIGINT" grep -q '130 SIGINT' help.txt
check "--help: 143 for SIGTERM" grep -q '143 SIGTERM' help.txt
check "--help: 129 for SIGHUP" grep -q '129 SIGHUP' help.txt
check "--help: an interruption is not exit 1" \
  bash -c '! sed -n "/^Exit codes/,/^$/p" help.txt | grep -q interrupt'
for c in simplify generate eval optimize study rasterize tiles "tiles plan" \
         "tiles run" "tiles merge"; do
  # shellcheck disable=SC2086
  "$T" $c --help >help.txt 2>&1
  check "$c --help: 128+N, 130 for Ctrl-C" \
    bash -c 'grep -q "128+N" help.txt && grep -q "130 Ctrl-C" help.txt'
done

# --- signals during a run ------------------------------------------------------
# A DEM that takes seconds at -max_error 0 (2 s for 513^2 here; this is 4
# times that), so the signal comes while the run works.
"$T" generate diamond_square big.tif -size 1025 -seed 11 -q ||
  { echo "FAIL: generate"; exit 1; }

# stop SIG CODE DELAY ARGS...: sends SIG after DELAY seconds to a run of
# simplify ARGS big.tif sig/o.gpkg; it must end with CODE, say so in one
# line, and leave sig/ empty.
stop() {
  local sig=$1 code=$2 delay=$3
  shift 3
  rm -rf sig && mkdir sig
  # job control: the background job keeps SIGINT's default disposition,
  # as a terminal's foreground job has (a script's & ignores SIGINT)
  set -m
  "$T" simplify "$@" big.tif sig/o.gpkg >/dev/null 2>sig.err &
  local pid=$!
  set +m
  sleep "$delay"
  kill "-$sig" "$pid" 2>/dev/null
  wait "$pid"
  local rc=$?
  local what="SIG$sig after ${delay}s ($*)"
  if [ "$rc" = "$code" ]; then pass; else
    fail "$what: exit code $rc, expected $code ($(head -c 300 sig.err))"; fi
  check "$what: nothing left ($(ls -A sig | tr '\n' ' '))" \
    [ -z "$(ls -A sig)" ]
  check "$what: one line saying interrupted ($(head -c 300 sig.err))" \
    bash -c '[ "$(wc -l <sig.err)" -le 1 ] && { [ ! -s sig.err ] ||
             grep -q "^terratin: .*interrupted" sig.err; }'
}
for d in 0.3 1.5; do
  stop INT 130 "$d" -max_error 0 -q
  stop TERM 143 "$d" -max_error 0 -q
  stop HUP 129 "$d" -max_error 0 -q
  stop INT 130 "$d" -max_error 0 -q -tile_size 128 -threads 2
  stop TERM 143 "$d" -max_error 0 -q -tile_size 128 -threads 2
done

echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
