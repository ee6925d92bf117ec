#!/usr/bin/env bash
# tests/docs/test_doc_tables.sh -- the figures in docs/ are still what the
# binary gives: bench/doc_tables.py --check reruns every table of the
# `check` tier (the cheap ones, seconds each: the `long` tier runs in
# tests/long/test_long_doc_tables.sh) and fails on any cell that drifted,
# and on a table of figures that is neither generated nor a dated record.
# Tables that need the shared DEMs are skipped with their message when
# ../shared/testdata is absent; exits 77 when every one was.
set -u
ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
T=${TT_TERRATIN:-$ROOT/build/terratin}
TIER=${TT_DOC_TIER:-check}
if [ ! -x "$T" ]; then
  echo "SKIP: no terratin binary at $T"
  exit 77
fi
exec python3 "$ROOT/bench/doc_tables.py" --check --tier "$TIER" "$T"
