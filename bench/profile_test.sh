#!/usr/bin/env bash
# bench/profile_test.sh -- where a shell test's seconds go: runs one of
# tests/*/test_*.sh under `bash -x` with a time stamp on every traced
# command and prints the lines of the test script (not of the helpers it
# sources) that took longest, each with the time until the next command
# of the script itself, so a helper call or a loop counts whole on the
# line that called it. For finding what to shrink when a test is slow.
#
#   bench/profile_test.sh [-n TOP] [-f FILE] BUILD_DIR tests/apps/test_tiles.sh
#
# -f FILE: the lines of FILE instead (a helper the test sources, such as
# tt_tiles_lib.sh), to see inside a helper that a test calls.
#
# BUILD_DIR gives the command (BUILD_DIR/terratin) and the environment of
# the ctest (TT_TESTDATA, TT_SHARED_TESTDATA=../shared/testdata).
set -u
top=15
file=
while [ $# -gt 2 ]; do
  case $1 in
    -n) top=$2; shift 2 ;;
    -f) file=$2; shift 2 ;;
    *) break ;;
  esac
done
if [ $# -ne 2 ]; then
  echo "usage: $0 [-n TOP] [-f FILE] BUILD_DIR TEST.sh" >&2
  exit 2
fi
build=$(cd "$1" && pwd) || exit 2
test=$(cd "$(dirname "$2")" && pwd)/$(basename "$2")
src=$(cd "$(dirname "$0")/.." && pwd)
trace=$(mktemp "${TMPDIR:-/tmp}/tt_profile.XXXXXX")
trap 'rm -f "$trace"' EXIT

export TT_TERRATIN="$build/terratin" TT_TESTDATA="$src/testdata" \
  TT_SHARED_TESTDATA="${TT_SHARED_TESTDATA:-$src/../shared/testdata}" \
  TT_SOURCE_DIR="$src" TT_BUILD_DIR="$build" TT_CORPUS="$src/tests/corpus"
start=$EPOCHREALTIME
# the trace on fd 9, the test's own output as usual; PS4 is set inside
# (bash run as root does not take it from the environment) and the test
# sourced with $0 its own path
bash -c 'PS4='\''+${EPOCHREALTIME}|${BASH_SOURCE[0]-}:${LINENO}|'\''
BASH_XTRACEFD=9; set -x; . "$0"' "$test" 9>"$trace"
rc=$?
end=$EPOCHREALTIME
python3 - "$trace" "$(basename "${file:-$test}")" "$top" "$start" "$end" "$rc" <<'PY'
import collections, re, sys
trace, script, top, start, end, rc = sys.argv[1], sys.argv[2], int(sys.argv[3]), float(sys.argv[4]), float(sys.argv[5]), sys.argv[6]
pat = re.compile(r"^\++(\d+\.\d+)\|(?:[^:|]*/)?([^/:|]*):(\d+)\|(.*)$")
marks = []  # (time, line, text) of the script's own commands
for raw in open(trace, errors="replace"):
    m = pat.match(raw.rstrip("\n"))
    if m and m.group(2) == script:
        marks.append((float(m.group(1)), int(m.group(3)), m.group(4)))
marks.sort()
spent = collections.Counter()
text = {}
for (t, line, cmd), nxt in zip(marks, marks[1:] + [(end, 0, "")]):
    spent[line] += nxt[0] - t
    text.setdefault(line, cmd[:90])
total = end - start
print("%s: %.1f s in all (exit %s); the slowest lines:" % (script, total, rc))
for line, s in spent.most_common(top):
    print("%7.2f s %5.1f %%  line %4d  %s" % (s, 100 * s / total, line, text[line]))
PY
