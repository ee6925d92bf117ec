# tt_check.sh -- the counters every shell test keeps, sourced by them (not
# a test itself: ctest runs tests/*/test_*.sh). `check WHAT CMD...` runs CMD
# and counts it passed, or failed with "FAIL: WHAT" on stderr; each test
# prints "N passed, M failed" at its end and exits 1 on any failure.
# It also resolves python3 once (tt_python.sh).
. "$(dirname "${BASH_SOURCE[0]}")/tt_python.sh"
passed=0
failed=0
pass() { passed=$((passed + 1)); }
fail() { failed=$((failed + 1)); echo "FAIL: $*" >&2; }
check() {
  local what=$1
  shift
  if "$@"; then pass; else fail "$what"; fi
}
