# tt_python.sh -- sourced by the shell tests (through tt_check.sh or on its
# own): `python3` resolved once to the interpreter it names on PATH, and a
# link to it put first on PATH, so that each of the test's many small
# Python calls starts that interpreter directly, not through a version
# manager's launcher in front of it (pyenv's shim is a shell script: about
# 0.1 s a call, 10 s and more over a test). The same interpreter either
# way, and a real program (`$!` of `python3 ... &` is the interpreter
# itself); the link lives in TT_BUILD_DIR/tt_python (or TMPDIR). Nothing
# changes when python3 is missing or is the interpreter itself.
# TT_APPS: this folder (tests/apps), absolute, for the helper scripts
# (same_gpkg.py, tin_topology.py) once the test has left for its work
# folder.
TT_APPS=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
if tt_py_=$(command -v python3) && [ -n "$tt_py_" ]; then
  tt_exe_=$(python3 -c 'import sys; print(sys.executable)' 2>/dev/null)
  if [ -n "$tt_exe_" ] && [ -x "$tt_exe_" ] && [ "$tt_exe_" != "$tt_py_" ]; then
    tt_dir_=${TT_BUILD_DIR:-${TMPDIR:-/tmp}}/tt_python
    if [ "$(readlink "$tt_dir_/python3" 2>/dev/null)" != "$tt_exe_" ]; then
      # made under another name and renamed: tests running side by side
      # never see it missing
      mkdir -p "$tt_dir_" 2>/dev/null &&
        ln -sfn "$tt_exe_" "$tt_dir_/python3.$$" 2>/dev/null &&
        mv -f "$tt_dir_/python3.$$" "$tt_dir_/python3" 2>/dev/null
    fi
    if [ "$("$tt_dir_/python3" -c 'import sys; print(sys.executable)' 2>/dev/null)" != "" ]; then
      PATH=$tt_dir_:$PATH
      export PATH
    fi
  fi
fi
unset tt_py_ tt_exe_ tt_dir_
