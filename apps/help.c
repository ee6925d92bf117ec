/*
 * help.c -- the help texts of terratin: the top level and one page per
 * subcommand, as `terratin [COMMAND] --help` prints them. docs/cli.md says
 * the same at more length; the two are kept in step by hand.
 */
#include "app.h"

static const char help_top[] =
    "Usage: terratin COMMAND [options] ARGUMENTS...\n"
    "       terratin --help | --version\n"
    "\n"
    "Turns a DEM into a TIN (triangulated irregular network) whose vertices\n"
    "are grid samples, and measures triangle layers against DEMs.\n"
    "\n"
    "Commands:\n"
    "  simplify   DEM -> TIN layers (GeoPackage, Shapefile, other formats)\n"
    "  generate   write a synthetic test terrain as a GeoTIFF\n"
    "  eval       measure the error of a triangle layer against a DEM\n"
    "  optimize   re-triangulate a TIN's vertices for a criterion\n"
    "\n"
    "Options of every command:\n"
    "  --help              this help, or the help of COMMAND\n"
    "  --version           terratin, GDAL and PROJ versions\n"
    "  --config KEY VALUE  set a GDAL configuration option before anything is\n"
    "                      opened (repeatable; KEY=VALUE also accepted)\n"
    "  --debug on|off      GDAL debug messages on stderr (CPL_DEBUG)\n"
    "\n"
    "Exit codes:\n"
    "  0  success\n"
    "  1  processing failure: bad input, I/O error, refused output,\n"
    "     interruption (nothing is left behind)\n"
    "  2  usage error: unknown option, bad value, missing argument\n"
    "  3  eval: the measured max error exceeds -max_error\n"
    "\n"
    "Run 'terratin COMMAND --help' for the options of a command.\n";

/* The annealing options, shared by simplify and optimize. */
#define ANNEAL_HELP                                                           \
  "  -anneal_t0 T      -optimize anneal: start temperature, in swap value\n" \
  "                    units (default: 2 x the largest |swap value|)\n"     \
  "  -anneal_stages K  stages, the temperature times R each (default 100)\n"\
  "  -anneal_swaps S   random edges tried per stage, per edge (default 5)\n"\
  "  -anneal_good G    a stage ends after G x edges improving swaps\n"      \
  "                    (default 5); a stage with no swap ends the run\n"    \
  "  -anneal_r R       cooling factor, 0 < R < 1 (default 0.95)\n"         \
  "  -seed N           the random sequence (default 0): the same seed, the\n"\
  "                    same TIN; the best triangulation seen is returned\n"

static const char help_simplify[] =
    "Usage: terratin simplify [-b BAND] [-max_error E] [-max_points N]\n"
    "           [-max_triangles N] [-percent P] [-criterion NAME]\n"
    "           [-repair flip|local|lookahead|delaunay]\n"
    "           [-optimize local|lookahead|anneal|edge_insertion|none]\n"
    "           [-anneal_t0 T] [-anneal_stages K] [-anneal_swaps S]\n"
    "           [-anneal_good G] [-anneal_r R] [-seed N]\n"
    "           [-srcnodata VALUE] [-z_factor F] [-z_unit m]\n"
    "           [-work_srs SRS] [-t_srs SRS]\n"
    "           [-of FORMAT] [-dsco NAME=VALUE]... [-lco NAME=VALUE]...\n"
    "           [-nln PREFIX] [-overwrite] [-q] [-json]\n"
    "           [--config KEY VALUE]... INPUT OUTPUT\n"
    "\n"
    "Simplifies band BAND of the raster INPUT into a TIN whose vertices are\n"
    "grid samples (greedy insertion) and writes the vector dataset OUTPUT\n"
    "with three layers: PREFIXtriangles (POLYGON Z), PREFIXvertices\n"
    "(POINT Z) and PREFIXrun_parameters (one row: limits, results, timing).\n"
    "\n"
    "Stop conditions (they combine: the first one reached wins):\n"
    "  -max_error E      stop when every valid sample is within E of the TIN\n"
    "                    (z units of the DEM, E >= 0)\n"
    "  -max_points N     at most N vertices (N >= 1)\n"
    "  -max_triangles N  at most N triangles (N >= 1)\n"
    "  -percent P        at most P% of the valid samples as vertices\n"
    "                    (0 < P <= 100)\n"
    "  Default when none is given: -max_error = 0.5% of the DEM's valid\n"
    "  height range (max - min), printed in the summary; a flat DEM gives\n"
    "  the two triangles of the corners.\n"
    "\n"
    "Options:\n"
    "  -b BAND           band of INPUT to read (default 1)\n"
    "  -srcnodata VALUE  height to treat as nodata, a number or nan\n"
    "                    (default: the band's nodata value and mask)\n"
    "  -z_factor F       multiply heights by F, e.g. 0.3048 for feet to\n"
    "                    metres (default 1; after the band's scale/offset)\n"
    "  -z_unit m         heights declared in ft or us-ft (band unit, else\n"
    "                    vertical CRS) converted to metres. Combined:\n"
    "                    z = (raw * scale + offset) * unit factor * F; with\n"
    "                    an unknown unit it needs -z_factor, which then is\n"
    "                    the whole conversion. Errors and -max_error are in\n"
    "                    the output z unit, which the summary names\n"
    "  -work_srs SRS     projected CRS in metres whose local affine frame\n"
    "                    measures angles, areas and the Delaunay test\n"
    "                    (default: the UTM zone of the DEM's centre for\n"
    "                    geographic DEMs and map units that are not ground\n"
    "                    metres, e.g. Web Mercator, feet; else the DEM's own\n"
    "                    grid). Heights and output coordinates are unchanged\n"
    "  -t_srs SRS        write the layers in SRS (vertices reprojected with\n"
    "                    PROJ, triangles unchanged; default: the DEM's CRS).\n"
    "                    A geographic output gets geodesic triangle areas\n"
    "  -criterion NAME   triangulation criterion (docs/criteria.md):\n"
    "                    delaunay (default), minmax_angle, minmax_angle_lex,\n"
    "                    min_area, mean_curvature, gaussian_curvature, abn,\n"
    "                    abn_sum, abn_sumsq, l2\n"
    "  -repair MODE      how the criterion is restored around each new\n"
    "                    vertex: flip (Lawson flips outward from it; the\n"
    "                    default), local, lookahead (swaps over the region\n"
    "                    around it), delaunay (Delaunay while inserting,\n"
    "                    the criterion in the final pass only; the default\n"
    "                    for l2). Except with delaunay, min_area first\n"
    "                    re-triangulates the hole around it exactly\n"
    "  -optimize MODE    final pass over the whole mesh: local, lookahead,\n"
    "                    anneal (simulated annealing), edge_insertion (the\n"
    "                    global Min-Max angle optimum; -criterion\n"
    "                    minmax_angle only) or none (default: local after\n"
    "                    -repair delaunay with another criterion, else\n"
    "                    none); it never lifts an error past the bound\n"
    ANNEAL_HELP
    "  -of FORMAT        OGR vector driver that can create datasets: GPKG,\n"
    "                    \"ESRI Shapefile\", ... (default: guessed from\n"
    "                    OUTPUT's extension, else GPKG)\n"
    "  -dsco NAME=VALUE  dataset creation option (repeatable)\n"
    "  -lco NAME=VALUE   layer creation option, for every layer (repeatable)\n"
    "  -nln PREFIX       prefix of the three layer names (default: none)\n"
    "  -overwrite        replace OUTPUT when it exists (default: refuse)\n"
    "  -q                quiet: no progress bar, no summary line\n"
    "  -json             print one JSON object with the results instead of\n"
    "                    the progress bar and the summary line\n"
    "\n"
    "A shapefile OUTPUT dir/name (or dir/name.shp) makes the files\n"
    "dir/name_triangles.shp, dir/name_vertices.shp and\n"
    "dir/name_run_parameters.dbf (with their .shx, .dbf, .prj, .cpg).\n"
    "\n"
    "OUTPUT is written under a temporary name and renamed when complete: a\n"
    "failure or an interruption leaves nothing behind. Progress goes to\n"
    "stdout, warnings and errors to stderr.\n"
    "\n"
    "Exit codes: 0 success, 1 processing failure, 2 usage error.\n"
    "\n"
    "Example:\n"
    "  terratin simplify -max_error 0.5 dem.tif tin.gpkg\n";

static const char help_generate[] =
    "Usage: terratin generate TYPE OUTPUT [-size N|NXxNY] [-seed S]\n"
    "           [-iterations N] [-displacement D] [-wave_size W]\n"
    "           [-roughness R] [-amplitude A]\n"
    "           [-seeding none|peak|valley|hybrid] [-a_srs SRS]\n"
    "           [-overwrite] [-q]\n"
    "\n"
    "Writes a synthetic, seeded, bit-reproducible terrain as a single-band\n"
    "Float32 GeoTIFF.\n"
    "\n"
    "TYPE:\n"
    "  fault            fault lines; a step (rough) or, with -wave_size > 0,\n"
    "                   a cosine ramp (smooth). Default 100x100,\n"
    "                   displacement 100\n"
    "  diamond_square   midpoint displacement on a (2^n+1)x(2^n+1) grid.\n"
    "                   Default 257x257, roughness 0.7\n"
    "  sphere           a half sphere of radius 20 on [0,40]^2 (41x41)\n"
    "  cylinder         a cylinder of height 60, radius 20 (a cliff; 41x41)\n"
    "  bump             exp(-81/4 ((x-.5)^2+(y-.5)^2)) on [0,1]^2 (20x30)\n"
    "\n"
    "Options:\n"
    "  -size N|NXxNY     grid size in samples (each side >= 2)\n"
    "  -seed S           random seed, an unsigned integer (all types)\n"
    "  -iterations N     fault: number of fault lines (N >= 1)\n"
    "  -displacement D   fault: height step per fault line (D >= 0)\n"
    "  -wave_size W      fault: cosine ramp half-width in cells; 0 = step\n"
    "  -roughness R      diamond_square: amplitude factor per level (R > 0)\n"
    "  -amplitude A      diamond_square: first-level amplitude (A >= 0)\n"
    "  -seeding MODE     diamond_square: none, peak, valley or hybrid\n"
    "  -a_srs SRS        CRS to assign (EPSG:n, WKT, PROJ string, ...)\n"
    "  -overwrite        replace OUTPUT when it exists (default: refuse)\n"
    "  -q                quiet: no summary line\n"
    "\n"
    "Exit codes: 0 success, 1 processing failure, 2 usage error.\n"
    "\n"
    "Example:\n"
    "  terratin generate fault fault.tif -size 200 -seed 7\n";

static const char help_eval[] =
    "Usage: terratin eval DEM TIN [-b BAND] [-layer NAME] [-max_error E]\n"
    "           [-srcnodata VALUE] [-z_factor F] [-z_unit m] [-json] [-q]\n"
    "\n"
    "Measures a layer of triangles (POLYGON Z, MULTIPOLYGON Z or TIN, from\n"
    "terratin or any other tool) against band BAND of the raster DEM: the\n"
    "error |DEM - TIN| over every valid sample (max, RMS, mean and total\n"
    "absolute, L2, where the max is) and the coverage (valid samples covered,\n"
    "uncovered, overlapped; polygons that are not triangles, degenerate\n"
    "triangles). The triangles must be in the DEM's CRS.\n"
    "\n"
    "Options:\n"
    "  -b BAND         band of DEM to read (default 1)\n"
    "  -srcnodata V    height to treat as nodata, a number or nan\n"
    "  -z_factor F     multiply heights by F (as given to simplify)\n"
    "  -z_unit m       ft or us-ft heights to metres (as given to simplify)\n"
    "  -layer NAME     layer to measure (default: a layer named 'triangles'\n"
    "                  or ending in '_triangles', else the first polygon\n"
    "                  layer)\n"
    "  -max_error E    check: exit with code 3 when the measured max error\n"
    "                  exceeds E (E >= 0)\n"
    "  -json           print one JSON object instead of text\n"
    "  -q              print nothing on success (for scripts with -max_error)\n"
    "\n"
    "Exit codes: 0 success (and within -max_error), 1 processing failure,\n"
    "2 usage error, 3 the measured max error exceeds -max_error.\n"
    "\n"
    "Example:\n"
    "  terratin eval dem.tif tin.gpkg -max_error 0.5 -q || echo too coarse\n";

static const char help_optimize[] =
    "Usage: terratin optimize DEM IN_TIN OUTPUT [-b BAND] [-layer NAME]\n"
    "           [-criterion NAME]\n"
    "           [-optimize local|lookahead|anneal|edge_insertion]\n"
    "           [-max_error E] [-anneal_t0 T] [-anneal_stages K]\n"
    "           [-anneal_swaps S] [-anneal_good G] [-anneal_r R] [-seed N]\n"
    "           [-srcnodata VALUE] [-z_factor F] [-z_unit m]\n"
    "           [-of FORMAT] [-dsco NAME=VALUE]... [-lco NAME=VALUE]...\n"
    "           [-nln PREFIX] [-overwrite] [-q] [-json]\n"
    "\n"
    "Reads a layer of triangles (from terratin or another tool, as eval\n"
    "reads it) whose corners are samples of band BAND of DEM, keeps its\n"
    "vertices and its outline, re-triangulates it for the criterion, and\n"
    "writes OUTPUT with the layers simplify writes (PREFIXtriangles,\n"
    "PREFIXvertices, PREFIXrun_parameters). A corner that is not a valid\n"
    "DEM sample, a triangle with no area, or triangles that overlap are\n"
    "refused with a message naming them.\n"
    "\n"
    "Options:\n"
    "  -layer NAME       layer of IN_TIN (default as eval: 'triangles' or\n"
    "                    '*_triangles', else the first polygon layer)\n"
    "  -criterion NAME   as simplify (default delaunay)\n"
    "  -optimize MODE    local (default), lookahead, anneal or\n"
    "                    edge_insertion (-criterion minmax_angle only)\n"
    "  -max_error E      refuse every move that makes a triangle with a\n"
    "                    sample farther than E from it (z units)\n"
    ANNEAL_HELP
    "  -b, -srcnodata, -z_factor, -z_unit   as simplify\n"
    "  -of, -dsco, -lco, -nln, -overwrite, -q, -json   as simplify\n"
    "\n"
    "Exit codes: 0 success, 1 processing failure, 2 usage error.\n"
    "\n"
    "Example:\n"
    "  terratin optimize dem.tif tin.gpkg l2.gpkg -criterion l2 "
    "-optimize anneal\n";

const char *tt_app_help(tt_app_command topic)
{
  switch (topic) {
  case TT_APP_SIMPLIFY: return help_simplify;
  case TT_APP_GENERATE: return help_generate;
  case TT_APP_EVAL: return help_eval;
  case TT_APP_OPTIMIZE: return help_optimize;
  default: return help_top;
  }
}

const char *tt__app_command_name(tt_app_command c)
{
  switch (c) {
  case TT_APP_SIMPLIFY: return "simplify";
  case TT_APP_GENERATE: return "generate";
  case TT_APP_EVAL: return "eval";
  case TT_APP_OPTIMIZE: return "optimize";
  default: return "";
  }
}
