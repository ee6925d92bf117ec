#!/usr/bin/env bash
# test_long_issue17.sh -- the long tier (ctest label `long`, `make
# check-long`): tests/apps/test_issue17.sh with the whole of Mt Hood
# (1013 x 799, 165,600 triangles at max error 10, where 1,929 had an rmse
# above their max_err when it was stored as a float) instead of its
# corner, GeoPackage and Shapefile. About 20 s in Release. Skips when
# TT_SHARED_TESTDATA lacks Mt Hood.
HOOD=${TT_SHARED_TESTDATA:-}/gdalraster/lf_elev_220_mt_hood_utm.tif
if [ -z "${TT_SHARED_TESTDATA:-}" ] || [ ! -f "$HOOD" ]; then
  echo "SKIP: Mt Hood (gdalraster/lf_elev_220_mt_hood_utm.tif) is not in TT_SHARED_TESTDATA"
  exit 77
fi
HOOD_FULL=1 exec bash "$(dirname "${BASH_SOURCE[0]}")/../apps/test_issue17.sh"
