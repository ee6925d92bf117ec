# tt_python.sh -- sourced by the shell tests (through tt_check.sh or on its
# own): `python3` resolved once to the interpreter it names on PATH, so that
# each of the test's many small Python calls starts that interpreter
# directly, not through a version manager's launcher in front of it (pyenv's
# shim is a shell script: about 0.1 s a call, 10 s and more over a test).
# The same interpreter either way; nothing is defined when python3 is
# missing, so the test's own `command -v python3` still skips.
# TT_APPS: this folder (tests/apps), absolute, for the helper scripts
# (same_gpkg.py, tin_topology.py) once the test has left
# for its work folder
TT_APPS=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
if [ -z "${TT_PY:-}" ] && command -v python3 >/dev/null 2>&1; then
  TT_PY=$(command python3 -c 'import sys; print(sys.executable)' 2>/dev/null) || TT_PY=
fi
if [ -n "${TT_PY:-}" ] && [ -x "$TT_PY" ]; then
  python3() { "$TT_PY" "$@"; }
  export TT_PY
  export -f python3
fi
