#!/usr/bin/env bash
# Post-install test: installs the build tree into a scratch prefix, checks
# the manual page terratin(1) is there and says what --help says, then
# builds and runs a small program against the installed package twice:
# through the CMake package config, and through pkg-config.
set -u
build=${TT_BUILD_DIR:?} src=${TT_SOURCE_DIR:?}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
pass=0 fail=0
check() { if "$@"; then pass=$((pass + 1)); else echo "FAIL: $*"; fail=$((fail + 1)); fi; }

check cmake --install "$build" --prefix "$work/prefix" >/dev/null
check test -f "$work/prefix/include/terratin/terratin.h"
check test -f "$work/prefix/include/terratin/terratin_gdal.h"
check test -x "$work/prefix/bin/terratin"
check "$work/prefix/bin/terratin" --version

# The manual page: installed, generated from the same help texts as
# --help (each page's usage line is in it, roff-escaped), and readable by
# man when man is installed.
page="$work/prefix/share/man/man1/terratin.1"
check test -f "$page"
for c in simplify generate eval optimize study rasterize "tiles plan" \
         "tiles run" "tiles merge"; do
  # shellcheck disable=SC2086
  usage=$("$work/prefix/bin/terratin" $c --help | head -1 | sed 's/-/\\-/g')
  check grep -qF -- "$usage" "$page"
done
check grep -qF -- '\-\-help\-general' "$page"
if command -v man >/dev/null; then
  check bash -c "MANWIDTH=80 man -l '$page' 2>&1 | grep -q 'terratin rasterize DEM TIN OUTPUT'"
else
  echo "note: man is not installed; the page is not rendered"
fi

# CMake package
check cmake -S "$src/tests/install" -B "$work/cmake-build" \
  -DCMAKE_PREFIX_PATH="$work/prefix" -DCMAKE_BUILD_TYPE=Release >/dev/null
check cmake --build "$work/cmake-build" >/dev/null
check "$work/cmake-build/consumer"
check "$work/cmake-build/consumer_gdal"

# pkg-config
if command -v pkg-config >/dev/null; then
  export PKG_CONFIG_PATH="$work/prefix/lib/pkgconfig:$work/prefix/lib/$(gcc -print-multiarch 2>/dev/null)/pkgconfig"
  check pkg-config --exists terratin
  # shellcheck disable=SC2046
  check cc -std=c11 -o "$work/consumer_pc" "$src/tests/install/consumer.c" \
    $(pkg-config --cflags terratin) $(pkg-config --libs terratin)
  check "$work/consumer_pc"
  check pkg-config --exists terratin-gdal
  # shellcheck disable=SC2046
  check cc -std=c11 -DTT_WITH_GDAL -o "$work/consumer_pc_gdal" \
    "$src/tests/install/consumer.c" $(pkg-config --cflags terratin-gdal) \
    $(pkg-config --libs terratin-gdal)
  check "$work/consumer_pc_gdal"
fi
echo "$pass passed, $fail failed"
[ "$fail" -eq 0 ]
