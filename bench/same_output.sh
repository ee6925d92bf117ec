#!/usr/bin/env bash
# bench/same_output.sh -- fingerprints of a dozen runs, to show that a
# refactoring changed nothing a user sees.
#
#   bench/same_output.sh TERRATIN [WORKDIR] > fingerprints.txt
#   diff before.txt after.txt
#
# Each line is "<run> <md5>". GeoPackage, Shapefile and SQLite outputs are
# fingerprinted through `ogr2ogr -f CSV` of their triangles and vertices
# layers (geometry as WKT, every attribute); run_parameters is left out, as
# it holds timings and the creation time. Mesh files (2DM, PLY, OBJ) are
# fingerprinted whole, LandXML without its date and time attributes, and a
# raster by `gdalinfo -checksum`. The runs cover both methods, several
# criteria and optimisers, geographic (ground frame), projected and Web
# Mercator DEMs, nodata, budgets, tiled runs (merged and streamed), and
# the commands eval, optimize and rasterize.
set -euo pipefail
tt=${1:?usage: same_output.sh TERRATIN [WORKDIR]}
tt=$(readlink -f "$tt")
here=$(cd "$(dirname "$0")/.." && pwd)
work=${2:-$(mktemp -d)}
mkdir -p "$work"
cd "$work"
# the DEM copied in, so that no output or report holds this checkout's path
cp "$here/testdata/jacksboro_fault_dem.tif" geo.tif
dem=geo.tif

# Inputs: the bundled geographic DEM, a UTM copy with a nodata hole, a Web
# Mercator copy, and a generated fractal.
if [ ! -f utm.tif ]; then
  gdalwarp -q -t_srs EPSG:32616 -r bilinear -dstnodata -9999 geo.tif utm0.tif
  # a round nodata hole (a lake masked out), burnt in by gdal_rasterize
  gdalinfo -json utm0.tif | python3 -c 'import json, math, sys
c = json.load(sys.stdin)["cornerCoordinates"]
x = (c["upperLeft"][0] + c["lowerRight"][0]) / 2
y = (c["upperLeft"][1] + c["lowerRight"][1]) / 2
r = (c["lowerRight"][0] - c["upperLeft"][0]) / 8
ring = [[x + r * math.cos(k * math.pi / 12), y + r * math.sin(k * math.pi / 12)]
        for k in range(25)]
print(json.dumps({"type": "Polygon", "coordinates": [ring]}))' > lake.json
  cp utm0.tif utm.tif
  gdal_rasterize -q -burn -9999 lake.json utm.tif
  gdalwarp -q -t_srs EPSG:3857 -r bilinear "$dem" merc.tif
  "$tt" generate diamond_square fractal.tif -q -size 129 -seed 3
fi

layers() { # dataset: md5 of the triangles and vertices layers as CSV
  for l in triangles vertices; do
    case "$1" in # a Shapefile output is one file a layer: OUT_triangles.shp
      *.shp) ogr2ogr -f CSV /vsistdout/ "${1%.shp}_$l.shp" -lco GEOMETRY=AS_WKT ;;
      *) ogr2ogr -f CSV /vsistdout/ "$1" "$l" -lco GEOMETRY=AS_WKT ;;
    esac
  done | md5sum | cut -d' ' -f1
}
run() { # name output-to-fingerprint args...
  local name=$1 out=$2; shift 2
  rm -rf "$out"
  "$tt" "$@" >/dev/null
  local sum
  case "$out" in
    *.gpkg|*.shp|*.sqlite) sum=$(layers "$out") ;;
    *.xml) sum=$(sed -E 's/ (date|time)="[^"]*"//g' "$out" | md5sum | cut -d' ' -f1) ;;
    *.tif) sum=$(gdalinfo -checksum "$out" | grep -i checksum | md5sum | cut -d' ' -f1) ;;
    *) sum=$(md5sum "$out" | cut -d' ' -f1) ;;
  esac
  echo "$name $sum"
}

run insert_delaunay_geo      a.gpkg simplify -q -overwrite -max_error 5 "$dem" a.gpkg
run insert_l2_lookahead      b.gpkg simplify -q -overwrite -criterion l2 -optimize lookahead -percent 2 "$dem" b.gpkg
run insert_minmax_anneal_utm c.gpkg simplify -q -overwrite -criterion minmax_angle -optimize anneal -seed 4 -max_points 1200 utm.tif c.gpkg
run insert_abn_merc          d.gpkg simplify -q -overwrite -criterion abn -max_error 8 merc.tif d.gpkg
run decimate_hdh_fractal     e.gpkg simplify -q -overwrite -method decimate -percent 3 fractal.tif e.gpkg
run decimate_error_seq_utm   f.gpkg simplify -q -overwrite -method decimate -importance error -selection sequential -max_error 6 utm.tif f.gpkg
run tiled_streamed_geo       g.gpkg simplify -q -overwrite -tile_size 64 -max_error 5 "$dem" g.gpkg
run tiled_budget_utm         h.gpkg simplify -q -overwrite -tile_size 64 -max_points 1500 utm.tif h.gpkg
run tiled_merged_shp         i.shp  simplify -q -overwrite -tile_size 64 -max_error 5 -of "ESRI Shapefile" utm.tif i.shp
run insert_gaussian_sqlite   j.sqlite simplify -q -overwrite -criterion gaussian_curvature -max_error 10 -of SQLite utm.tif j.sqlite
run mesh_2dm                 k.2dm  simplify -q -overwrite -max_error 5 utm.tif k.2dm
run mesh_ply                 l.ply  simplify -q -overwrite -max_error 5 utm.tif l.ply
run mesh_obj                 m.obj  simplify -q -overwrite -max_error 5 fractal.tif m.obj
run mesh_landxml             n.xml  simplify -q -overwrite -max_error 5 utm.tif n.xml
run optimize_cmd             o.gpkg optimize -q -overwrite -criterion minmax_angle utm.tif c.gpkg o.gpkg
run rasterize_cmd            p.tif  rasterize -q -overwrite a.gpkg "$dem" p.tif
# eval: the JSON without timings
"$tt" eval -json "$dem" a.gpkg 2>/dev/null |
  python3 -c 'import json,sys
d=json.load(sys.stdin)
def strip(o):
  if isinstance(o,dict): return {k:strip(v) for k,v in o.items() if "time" not in k and "seconds" not in k}
  if isinstance(o,list): return [strip(v) for v in o]
  return o
print(json.dumps(strip(d),sort_keys=True))' | md5sum | sed 's/^/eval_json /; s/ *-$//'
