#!/usr/bin/env bash
# The tree's rules (docs/architecture.md), each failing with the files that
# break it:
#  1. the engine (src/ outside src/gdal/, and the engine's public header)
#     includes no header of GDAL, OGR, CPL, PROJ, GeographicLib, SQLite or
#     netCDF, and no header of the glue: it builds and links with libm and
#     threads alone;
#  2. the glue is in folders by role (src/gdal/raster, georef, ogr, gpkg,
#     mesh), and each of its files needs those libraries (directly, or
#     through the glue's public header or one of its own headers);
#  3. src/ and apps/ have no file outside a folder;
#  4. the command is a folder per command over apps/core/: no command's
#     folder includes a header of another command's folder, and the core
#     includes none of theirs (it reaches a command only through the entry
#     point app.h declares);
#  5. every file opens with a comment that names its folder's role;
#  6. files a reader can hold: no file of apps/ over 800 lines, no function
#     of apps/ or src/gdal/ over 150 lines.
set -u
root=${1:?usage: test_layering.sh SOURCE_DIR}
cd "$root" || exit 1
fail=0
broken() { echo "test_layering: $1"; shift; printf '%s\n' "$@" | sed 's/^/  /'; fail=1; }

lib_pattern='^[[:space:]]*#[[:space:]]*include[[:space:]]*[<"](gdal[a-z_]*\.h|ogr[a-z_]*\.h|ogrsf_frmts\.h|cpl_[a-z_]*\.h|vrtdataset\.h|proj\.h|proj_[a-z_]*\.h|geodesic\.h|sqlite3\.h|sqlite3ext\.h|netcdf\.h)[>"]'
glue_pattern='^[[:space:]]*#[[:space:]]*include[[:space:]]*"(terratin/terratin_gdal\.h|gdal/[a-z_/]+\.h)"'

# 1. the engine
engine=$(find src include/terratin/terratin.h -path src/gdal -prune -o \
           -type f \( -name '*.c' -o -name '*.h' \) -print | sort)
bad=$(echo "$engine" | xargs grep -nE "$lib_pattern" || true)
[ -z "$bad" ] || broken "GDAL-family headers outside src/gdal/:" "$bad"
bad=$(echo "$engine" | xargs grep -nE "$glue_pattern" || true)
[ -z "$bad" ] || broken "engine files including a header of the glue:" "$bad"

# 2. the glue by role
roles="raster georef ogr gpkg mesh"
for d in src/gdal/*/; do
  d=${d%/}; role=${d#src/gdal/}
  case " $roles " in *" $role "*) ;; *)
    broken "src/gdal/$role/ is not one of the glue's roles ($roles)" "$d" ;;
  esac
done
for f in $(find src/gdal -type f \( -name '*.c' -o -name '*.h' \) | sort); do
  grep -qE "$lib_pattern" "$f" || grep -qE "$glue_pattern" "$f" ||
    broken "$f includes no GDAL-family header: it belongs to the engine" "$f"
done

# 3. no loose files
loose=$(find src src/gdal apps -maxdepth 1 -type f | sort)
[ -z "$loose" ] || broken "files directly in src/, src/gdal/ or apps/ (put each in its folder):" "$loose"

# 4. the command's folders: an include "x.h" of apps/A/ may name a file of
# apps/A/, apps/core/, src/ or include/, never one of another apps/B/.
for f in $(find apps -type f \( -name '*.c' -o -name '*.h' \) | sort); do
  dir=$(dirname "$f"); own=${dir#apps/}
  grep -nE '^[[:space:]]*#[[:space:]]*include[[:space:]]*"' "$f" |
  while IFS= read -r line; do
    inc=$(echo "$line" | sed -E 's/.*#[[:space:]]*include[[:space:]]*"([^"]+)".*/\1/')
    [ -e "$dir/$inc" ] && case "$inc" in ../*) ;; *) continue ;; esac
    [ "$own" != core ] && [ -e "apps/core/$inc" ] && continue
    [ -e "src/$inc" ] || [ -e "include/$inc" ] && continue
    echo "$f:$line"
  done
done > /tmp/tt_layering_$$.txt
bad=$(cat /tmp/tt_layering_$$.txt); rm -f /tmp/tt_layering_$$.txt
[ -z "$bad" ] || broken "includes across the command's folders (a command uses apps/core/ and the libraries only):" "$bad"

# 5. every file opens with a paragraph that names its folder's role
# ("Part of src/mesh/, the mesh stage: ...", "apps/eval/: the eval command")
unnamed=$(for f in $(find src include apps -type f \( -name '*.c' -o -name '*.h' \) | sort); do
  dir=$(dirname "$f")/
  awk 'NR == 1 && !/^\/\*/ { exit 1 } { print } /\*\// { exit }' "$f" |
    grep -qF "$dir" || echo "$f"
done)
[ -z "$unnamed" ] || broken "files whose opening comment does not name their folder (its role):" "$unnamed"

# 6. sizes
long=$(find apps -type f \( -name '*.c' -o -name '*.h' \) -print0 | xargs -0 wc -l |
       awk '$2 != "total" && $1 > 800 {print}')
[ -z "$long" ] || broken "files of apps/ over 800 lines (split them by concept):" "$long"
# A function starts on a line at column 0 holding its name and "(", its
# body opens with "{" alone at column 0 and ends at the next "}" at
# column 0 (the project's layout, which every file follows).
long=$(find apps src/gdal -type f -name '*.c' -print0 | sort -z | xargs -0 awk '
  FNR == 1 { sig = 0 }
  /^[A-Za-z_].*\(/ { sig = FNR; line = $0 }
  /^\{/ { start = sig; name = line; sub(/\(.*/, "", name); n = split(name, w, /[ *]+/); name = w[n] }
  /^\}/ && start { if (FNR - start + 1 > 150) printf "%s:%d %s: %d lines\n", FILENAME, start, name, FNR - start + 1; start = 0 }')
# Functions being split (issue 25), each "file name"; the list only shrinks:
# a listed function that is no longer long fails until it is taken off.
known_long="
"
new_long=$(echo "$long" | while read -r at name rest; do
  [ -n "$at" ] || continue
  echo "$known_long" | grep -qxF "${at%%:*} ${name%:}" || echo "$at $name $rest"
done)
[ -z "$new_long" ] || broken "functions of apps/ or src/gdal/ over 150 lines (split them into named steps):" "$new_long"
stale=$(echo "$known_long" | while read -r file name; do
  [ -n "$file" ] || continue
  echo "$long" | grep -q "^$file:[0-9]* $name:" || echo "$file $name"
done)
[ -z "$stale" ] || broken "functions no longer over 150 lines: take them off known_long" "$stale"

[ "$fail" = 0 ] || exit 1
echo "test_layering: the engine is free of GDAL and of the glue, the glue is in its roles, each command in its folder over the core, every file naming its folder, no function over 150 lines"
