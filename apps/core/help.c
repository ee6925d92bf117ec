/*
 * help.c -- apps/core/: the command's core, what every command's folder shares.
 * This file: the help texts of terratin: the top level and one page per
 * subcommand, as `terratin [COMMAND] --help` prints them. docs/cli.md says the
 * same at more length; the two are kept in step by hand.
 */
#include "app.h"

/* The options of every command: the top help and --help-general. */
#define GENERAL_OPTIONS                                                       \
  "  --help              this help, or the help of COMMAND (also -h,\n"      \
  "                      'terratin help COMMAND')\n"                         \
  "  --help-general      these options of every command\n"                   \
  "  --version           terratin, GDAL and PROJ versions\n"                 \
  "  --formats           the output formats -of accepts: the OGR drivers\n"  \
  "                      terratin can write, the databases, the mesh formats\n"\
  "  --config KEY VALUE  set a GDAL configuration option before anything is\n"\
  "                      opened (repeatable; KEY=VALUE also accepted)\n"     \
  "  --debug on|off      GDAL debug messages on stderr (CPL_DEBUG; also\n"   \
  "                      yes|no|true|false|1|0)\n"                           \
  "  -q, -quiet          no progress bar, no summary line (every command but\n" \
  "                      tiles run, which prints nothing)\n"

static const char help_general[] =
    "Generic terratin options (every command takes them, before or after\n"
    "the command word):\n"
    GENERAL_OPTIONS
    "\n"
    "Option names and named values are matched without regard to case, and\n"
    "'-' matches '_' in them (-max-error is -max_error); --opt is -opt.\n"
    "A mistyped option is refused with the nearest option of the command\n"
    "('did you mean -max_error?').\n";

const char *tt__app_help_general(void)
{
  return help_general;
}

static const char help_top[] =
    "Usage: terratin COMMAND [options] ARGUMENTS...\n"
    "       terratin --help | --help-general | --version | --formats\n"
    "\n"
    "Turns a DEM into a TIN (triangulated irregular network) whose vertices\n"
    "are grid samples, and measures triangle layers against DEMs.\n"
    "\n"
    "Commands:\n"
    "  simplify   DEM -> TIN layers (GeoPackage, Shapefile, other formats)\n"
    "  generate   write a synthetic test terrain as a GeoTIFF\n"
    "  eval       measure the error of a triangle layer against a DEM\n"
    "  optimize   re-triangulate a TIN's vertices for a criterion\n"
    "  study      compare criteria, methods and optimisers over terrains\n"
    "  rasterize  a TIN's surface on a DEM's grid, as a raster\n"
    "  tiles      plan, run and merge a tiled run as separate jobs (clusters)\n"
    "\n"
    "Options of every command:\n"
    GENERAL_OPTIONS
    "\n"
    "Option names and named values (criteria, modes, TYPE) are matched\n"
    "without regard to case, '-' as '_'; numbers are decimal (no hex, inf\n"
    "or nan).\n"
    "\n"
    "Exit codes:\n"
    "  0  success\n"
    "  1  processing failure: bad input, I/O error, refused output\n"
    "  2  usage error: unknown option, bad value, missing argument\n"
    "  3  eval: the measured max error exceeds -max_error\n"
    "  128+N  stopped by signal N, as the shell reports a process the signal\n"
    "     ended: 130 SIGINT (Ctrl-C), 143 SIGTERM, 129 SIGHUP; nothing is\n"
    "     left behind (a run that had already finished keeps its 0)\n"
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

/* GDAL's input options on the DEM (dem_view.c), shared by the commands
 * that read one. */
#define INPUT_USAGE                                                          \
  "           [-a_srs SRS | -s_srs SRS] [-a_nodata V] [-a_ullr ulx uly lrx lry]\n"\
  "           [-srcwin xoff yoff xsize ysize | -projwin ulx uly lrx lry\n"    \
  "           [-projwin_srs SRS]]\n"
#define INPUT_HELP                                                           \
  "  -a_srs SRS        the DEM's CRS, for one without or with a wrong one\n"\
  "  -s_srs SRS        as gdalwarp's source CRS: the same as -a_srs\n"      \
  "  -a_nodata V       GDAL's name of -srcnodata\n"                         \
  "  -a_ullr ulx uly lrx lry  the georeferenced bounds of the (windowed)\n" \
  "                    DEM, for one without a geotransform or over its own\n"\
  "  -srcwin xoff yoff xsize ysize  read that window of samples only\n"    \
  "  -projwin ulx uly lrx lry  read the window of those map coordinates\n" \
  "                    (in the DEM's CRS, or -projwin_srs's, reprojected),\n"\
  "                    rounded to samples as gdal_translate does. A window\n"\
  "                    partly outside is read as its part inside (with a\n"\
  "                    warning); one wholly outside is refused. Coordinates\n"\
  "                    stay the DEM's; col and row count from the window\n"

static const char help_simplify[] =
    "Usage: terratin simplify [-b BAND] [-max_error E] [-max_points N]\n"
    "           [-max_triangles N] [-percent P] [-criterion NAME]\n"
    "           [-repair flip|local|lookahead|delaunay]\n"
    "           [-optimize local|lookahead|anneal|edge_insertion|none]\n"
    "           [-anneal_t0 T] [-anneal_stages K] [-anneal_swaps S]\n"
    "           [-anneal_good G] [-anneal_r R] [-seed N]\n"
    "           [-method insert|decimate] [-start all|greedy|greedy:N]\n"
    "           [-importance degree|hdh|abh|volume|drop|error]\n"
    "           [-selection independent|sequential] [-onepass]\n"
    "           [-hole minangle|circumradius|dp]\n"
    "           [-srcnodata VALUE] [-z_factor F] [-z_unit ft|us-ft|m]\n"
    "           [-z_to m|native|auto]\n"
    "           [-fill_nodata MAXCELLS]\n"
    INPUT_USAGE
    "           [-work_srs SRS] [-t_srs SRS]\n"
    "           [-breaklines LINES [-breaklines_layer L]\n"
    "            [-breaklines_where SQL]]\n"
    "           [-of FORMAT] [-dsco NAME=VALUE]... [-lco NAME=VALUE]...\n"
    "           [-nln PREFIX] [-overwrite] [-q] [-json] [-verbose]\n"
    "           [-layers LIST] [-nostyle]\n"
    "           [-threads N|ALL_CPUS] [-max_memory SIZE]\n"
    "           [-tile_size N] [-min_patch N]\n"
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
    "  Default when none is given: -max_error = twice the DEM's mean step\n"
    "  (the mean height difference between neighbouring valid samples),\n"
    "  to two significant digits, printed in the summary: a TIN of a few\n"
    "  per cent of the samples on most DEMs; a flat DEM gives the two\n"
    "  triangles of the corners.\n"
    "  Every limit is exact. A point or triangle budget (or a percentage)\n"
    "  below what the starting triangulation needs -- the 4 corners, or\n"
    "  the hull and the vertices a nodata outline forces -- is refused\n"
    "  before the run (exit 2) with the count to ask for; the counts are\n"
    "  the TIN's vertices and triangles, for either -method.\n"
    "\n"
    "Options:\n"
    "  -b BAND           band of INPUT to read (default 1)\n"
    "  -srcnodata VALUE  height to treat as nodata, a number or nan\n"
    "                    (default: the band's nodata value and mask)\n"
    "  -fill_nodata MAXCELLS  fill the nodata voids of at most MAXCELLS\n"
    "                    samples (4-connected, not touching the raster's\n"
    "                    edge) with GDAL's GDALFillNodata (inverse\n"
    "                    distance, search distance the void's larger side\n"
    "                    + 1, no smoothing) before meshing; larger ones\n"
    "                    (lakes, the sea) stay holes. The bound holds on\n"
    "                    the filled DEM (eval -fill_nodata measures it)\n"
    INPUT_HELP
    "  -z_factor F       multiply heights by F, e.g. 0.3048 for feet to\n"
    "                    metres (default 1; after the band's scale/offset)\n"
    "  -z_unit U         the unit the heights are in: ft, us-ft or m (default:\n"
    "                    the band's unit, else the vertical CRS's)\n"
    "  -z_to MODE        auto (default): heights in ft or us-ft converted to\n"
    "                    metres when the CRS is in metres or geographic,\n"
    "                    kept when it is in feet or absent; m: converted\n"
    "                    to metres whatever the CRS (an unknown unit then\n"
    "                    needs -z_unit or -z_factor, which is then the\n"
    "                    whole conversion); native: kept in their unit.\n"
    "                    z = (raw * scale + offset) * unit factor * F.\n"
    "                    Errors and -max_error are in the output z unit,\n"
    "                    which the summary names with the reason\n"
    "  -work_srs SRS     conformal projected CRS in metres that measures\n"
    "                    angles, areas and the Delaunay test (default: a\n"
    "                    conformal frame for the extent, every sample\n"
    "                    projected, for geographic and Web Mercator DEMs;\n"
    "                    the DEM's own grid, feet converted, for projected\n"
    "                    ones). Heights and output coordinates are unchanged\n"
    "  -t_srs SRS        write the layers in SRS (vertices reprojected with\n"
    "                    PROJ, triangles unchanged; default: the DEM's CRS).\n"
    "                    A geographic output gets geodesic triangle areas\n"
    "  -breaklines LINES the TIN follows the lines of LINES (any OGR\n"
    "                    source, reprojected to the DEM's CRS) as\n"
    "                    constrained edges through the samples nearest them,\n"
    "                    simplified along each line under the bound; lines\n"
    "                    are split where they cross and clipped at the DEM's\n"
    "                    edge and nodata (warned). Not yet in tiled runs\n"
    "                    (docs/cli.md)\n"
    "  -breaklines_layer L  LINES's layer (default: the first)\n"
    "  -breaklines_where SQL  only LINES's features that match SQL\n"
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
    "  -method M         insert (greedy insertion, the default) or\n"
    "                    decimate (start from a fine TIN and delete the\n"
    "                    least important vertices; docs/decimation.md).\n"
    "                    With decimate, -max_error is a bound no removal\n"
    "                    may break, the counts are targets reached exactly,\n"
    "                    -repair acts around each filled hole\n"
    "Decimation only:\n"
    "  -start S          all (every valid sample; default), greedy (greedy\n"
    "                    Delaunay insertion to zero error) or greedy:N\n"
    "                    (the same, N vertices)\n"
    "  -importance I     which vertex goes first: degree, hdh, abh, volume,\n"
    "                    drop, error (the largest error the removal would\n"
    "                    leave; default with -max_error, else hdh)\n"
    "  -selection S      independent (rounds of independent sets, rescored\n"
    "                    each round; default) or sequential (a heap, the\n"
    "                    least important first)\n"
    "  -onepass          independent sets scored once, at the start\n"
    "  -hole H           hole re-triangulation: minangle or circumradius\n"
    "                    ear cutting (default: circumradius for delaunay,\n"
    "                    else minangle), or dp (the exact optimum; delaunay,\n"
    "                    minmax_angle[_lex] and min_area only)\n"
    "  -of FORMAT        OGR vector driver that can create datasets: GPKG,\n"
    "                    \"ESRI Shapefile\", ... (default: guessed from\n"
    "                    OUTPUT's extension, else GPKG); or a mesh file:\n"
    "                    2DM (SMS mesh, .2dm, QGIS mesh layer; datasets\n"
    "                    beside it: OUTPUT_ins_err.dat, ...), PLY\n"
    "                    (binary, vertex and face error properties, .ply),\n"
    "                    OBJ (.obj), LandXML (1.2 TIN surface, .xml),\n"
    "                    DXF (3DFACE entities, .dxf), UGRID (netCDF\n"
    "                    UGRID 1.0 mesh with the error datasets; by -of\n"
    "                    only). An OGR format that does not give back every\n"
    "                    x, y and z written (MapInfo, DGN, ...) is refused\n"
    "                    before the run; GPX is written in EPSG:4326\n"
    "                    or a database: PostgreSQL, OUTPUT \"PG:dbname=...\"\n"
    "                    (tables in one transaction; -lco SCHEMA=NAME)\n"
    "  -obj_local        OBJ: vertices relative to the centre of the extent\n"
    "                    (given in the file as '# origin X Y')\n"
    "  -dsco NAME=VALUE  dataset creation option (repeatable)\n"
    "  -lco NAME=VALUE   layer creation option, for every layer (repeatable)\n"
    "  -nln PREFIX       prefix of the three layer names (default: none)\n"
    "  -layers LIST      the layers to write: triangles,vertices,\n"
    "                    run_parameters or any subset (default: all); one\n"
    "                    layer for GeoJSON, FlatGeobuf, GPX files\n"
    "  -nostyle          no QGIS default style (layer_styles in a GPKG or\n"
    "                    PostgreSQL, a .qml beside Shapefile, FlatGeobuf,\n"
    "                    GeoJSON files)\n"
    "  -overwrite        replace OUTPUT when it exists (default: refuse)\n"
    "  -q                quiet: no progress bar, no summary\n"
    "  -json             print one JSON object with the results instead of\n"
    "                    the progress bar and the summary\n"
    "  -verbose          the summary's details too: method, stop, frame,\n"
    "                    heights, components, tiles, times\n"
    "  -threads N        threads for the raster scans, or ALL_CPUS; the TIN\n"
    "                    is the same for every N (default: GDAL_NUM_THREADS,\n"
    "                    else all CPUs for a million samples or more)\n"
    "  -max_memory SIZE  memory the run may hold: heights, mesh and the TIN\n"
    "                    (bytes, or 500M, 2G, ...; default: the smallest of\n"
    "                    MemAvailable, the cgroup's limit and ulimit -v,\n"
    "                    less a margin). A run that would pass it stops\n"
    "                    with the phase and the size, and writes nothing\n"
    "  -min_patch N      make nodata the valid patches (samples joined through\n"
    "                    their 4 neighbours) of fewer than N samples; the\n"
    "                    summary and -json count them (untiled runs)\n"
    "  -tile_size N      read and simplify the DEM in tiles of N cells\n"
    "                    (>= 16) sharing their borders, one tile a thread,\n"
    "                    merged into one conforming TIN within -max_error;\n"
    "                    chosen by itself when the run does not fit the\n"
    "                    memory limit (-max_memory or the system's), as a\n"
    "                    quick estimate before the work says (JSON\n"
    "                    estimate). -method decimate keeps the borders'\n"
    "                    vertices; -max_points, -max_triangles, -percent\n"
    "                    become the one bound that meets them, found by a\n"
    "                    first pass over the tiles (never more than the\n"
    "                    budget) (docs/scale.md)\n"
    "\n"
    "Undeclared fill values (-9999, -32767, -32000, ... in runs, far from\n"
    "the other heights) are warned about with the -srcnodata to use.\n"
    "\n"
    "A shapefile OUTPUT dir/name (or dir/name.shp) makes the files\n"
    "dir/name_triangles.shp, dir/name_vertices.shp and\n"
    "dir/name_run_parameters.dbf (with their .shx, .dbf, .prj, .cpg).\n"
    "\n"
    "OUTPUT is written under a temporary name and renamed when complete: a\n"
    "failure or an interruption leaves nothing behind. Progress goes to\n"
    "stdout, warnings and errors to stderr.\n"
    "\n"
    "Exit codes: 0 success, 1 processing failure, 2 usage error, 128+N\n"
    "stopped by signal N (130 Ctrl-C, 143 SIGTERM; nothing left behind).\n"
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
    "Exit codes: 0 success, 1 processing failure, 2 usage error, 128+N\n"
    "stopped by signal N (130 Ctrl-C, 143 SIGTERM; nothing left behind).\n"
    "\n"
    "Example:\n"
    "  terratin generate fault fault.tif -size 200 -seed 7\n";

static const char help_eval[] =
    "Usage: terratin eval DEM TIN [-b BAND] [-layer NAME] [-max_error E]\n"
    "           [-srcnodata VALUE] [-z_factor F] [-z_unit ft|us-ft|m]\n"
    "           [-z_to m|native|auto] [-json] [-q]\n"
    "           [-fill_nodata MAXCELLS]\n"
    INPUT_USAGE
    "           [-tin_frame map|pixel] [-tin_transform SX,SY,SZ,OX,OY,OZ]\n"
    "           [-max_memory SIZE] [-error_raster OUT.tif [-co NAME=VALUE]...\n"
    "           [-overwrite]]\n"
    "\n"
    "Measures a TIN (from terratin or any other tool) against band BAND of\n"
    "the raster DEM: the error |DEM - TIN| over every valid sample (max,\n"
    "RMS, mean and total absolute, L2, where the max is) and the coverage\n"
    "(valid samples covered, uncovered, overlapped; polygons or faces that\n"
    "are not triangles, degenerate triangles). TIN is a mesh file: STL\n"
    "(binary or ASCII), PLY (ascii or binary), OBJ, SMS 2DM, LandXML\n"
    "(first Surface), UGRID netCDF; or any OGR layer of triangles: POLYGON\n"
    "Z, MULTIPOLYGON Z, TIN, POLYHEDRALSURFACE, or of Unknown type (CSV\n"
    "with WKT, DXF 3DFACE, MULTIPATCH Shapefile): every format simplify\n"
    "writes. A TIN in another CRS than the DEM's (the layer's, or the one\n"
    "a PLY, LandXML or UGRID file declares) is reprojected; one without a\n"
    "CRS is taken to be in the DEM's.\n"
    "\n"
    "Options:\n"
    "  -b BAND         band of DEM to read (default 1)\n"
    "  -srcnodata V    height to treat as nodata, a number or nan\n"
    "  -fill_nodata MAXCELLS  the DEM's small voids filled (as given to\n"
    "                  simplify): measure a TIN against the filled DEM\n"
    "  -a_srs, -s_srs, -a_nodata, -a_ullr, -srcwin, -projwin, -projwin_srs\n"
    "                  the DEM as simplify reads it (the TIN's window)\n"
    "  -z_factor F     multiply heights by F (as given to simplify)\n"
    "  -z_unit U, -z_to MODE  the heights' unit, and whether they become\n"
    "                  metres (as given to simplify)\n"
    "  -layer NAME     layer to measure (default: a layer named 'triangles'\n"
    "                  or ending in '_triangles', else the first polygon\n"
    "                  layer)\n"
    "  -max_error E    check: exit with code 3 when the measured max error\n"
    "                  exceeds E (E >= 0)\n"
    "  -json           print one JSON object instead of text\n"
    "  -q              print nothing on success (for scripts with -max_error)\n"
    "  -max_memory SIZE  memory the DEM's heights may take (500M, 2G, bytes;\n"
    "                  default: as for simplify)\n"
    "  -error_raster OUT  write TIN - DEM on the DEM's grid as a GeoTIFF\n"
    "                  (Float32, Float64 for a DEM of doubles; tiled, DEFLATE;\n"
    "                  nodata NaN outside the TIN and at the DEM's nodata)\n"
    "  -co NAME=VALUE  GeoTIFF creation option of OUT (repeatable)\n"
    "  -overwrite      replace OUT when it exists (default: refuse)\n"
    "  -tin_frame F    (or -stl_frame) the frame of TIN's coordinates: map\n"
    "                  (map coordinates, reprojected from the TIN's CRS)\n"
    "                  or pixel (the DEM's samples: x the column, y the row\n"
    "                  counted up from the last row, as hmm writes STL).\n"
    "                  Default map, but an STL whose corners miss the DEM's\n"
    "                  extent and fit its grid is read as pixel (fitting\n"
    "                  both: the frame whose corners land on samples of\n"
    "                  their heights, else the run asks for -stl_frame)\n"
    "  -tin_transform SX,SY,SZ,OX,OY,OZ  first put every corner at\n"
    "                  x' = SX x + OX, y' = SY y + OY, z' = SZ z + OZ (hmm's\n"
    "                  STL heights less the DEM's minimum: 1,1,1,0,0,ZMIN;\n"
    "                  delatin's rows down: 1,-1,1,0,HEIGHT-1,0 -tin_frame\n"
    "                  pixel)\n"
    "\n"
    "Exit codes: 0 success (and within -max_error), 1 processing failure,\n"
    "2 usage error, 3 the measured max error exceeds -max_error, 128+N\n"
    "stopped by signal N (130 Ctrl-C, 143 SIGTERM; nothing left behind).\n"
    "\n"
    "Example:\n"
    "  terratin eval dem.tif tin.gpkg -max_error 0.5 -q || echo too coarse\n"
    "  terratin eval dem.tif hmm.stl -tin_transform 1,1,1,0,0,412.5\n";

static const char help_optimize[] =
    "Usage: terratin optimize DEM IN_TIN OUTPUT [-b BAND] [-layer NAME]\n"
    "           [-criterion NAME]\n"
    "           [-optimize local|lookahead|anneal|edge_insertion]\n"
    "           [-max_error E] [-anneal_t0 T] [-anneal_stages K]\n"
    "           [-anneal_swaps S] [-anneal_good G] [-anneal_r R] [-seed N]\n"
    "           [-srcnodata VALUE] [-z_factor F] [-z_unit U] [-z_to MODE]\n"
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
    "                    sample farther than E from it (z units; default:\n"
    "                    the input TIN's own max error, which thus never\n"
    "                    grows)\n"
    ANNEAL_HELP
    "  -b, -srcnodata, -z_factor, -z_unit, -z_to   as simplify\n"
    "  -a_srs, -s_srs, -a_nodata, -a_ullr, -srcwin, -projwin, -projwin_srs\n"
    "                    the DEM, as simplify\n"
    "  -of, -dsco, -lco, -nln, -overwrite, -q, -json   as simplify\n"
    "\n"
    "Exit codes: 0 success, 1 processing failure, 2 usage error, 128+N\n"
    "stopped by signal N (130 Ctrl-C, 143 SIGTERM; nothing left behind).\n"
    "\n"
    "Example:\n"
    "  terratin optimize dem.tif tin.gpkg l2.gpkg -criterion l2 "
    "-optimize anneal\n";

static const char help_study[] =
    "Usage: terratin study [options] OUTDIR\n"
    "           -terrain DEM|NAME [-terrain ...] [-seed N]\n"
    "           [-criteria all|NAME,NAME...] [-methods insert,decimate]\n"
    "           [-optimizers auto,none,local,lookahead,anneal,...]\n"
    "           [-percent P,P,...] [-start all|greedy|greedy:N]\n"
    "           [-points N]\n"
    "           [-importance NAME] [-b BAND] [-srcnodata VALUE]\n"
    "           [-z_factor F] [-z_unit U] [-z_to MODE] [-threads N]\n"
    "           [-overwrite] [-q]\n"
    "           [-tin_points N] [-plot]\n"
    "\n"
    "Runs every terrain x method x optimiser x checkpoint x criterion as\n"
    "'terratin simplify -percent P' would (each checkpoint a run of its\n"
    "own, the final pass included) and writes into OUTDIR:\n"
    "  curves.csv  a row per run: terrain, method, criterion, optimizer,\n"
    "              points, max_error, l2, rmse, mean_abs_error,\n"
    "              total_abs_error, seconds (building the mesh)\n"
    "  tables.md   mean absolute error, a table per terrain, method and\n"
    "              optimiser: a row per percentage, a column per\n"
    "              criterion, the best of each row in bold\n"
    "  runs.json   every parameter and the version, to repeat the run\n"
    "\n"
    "With -points N, curves.csv also has the curves: insertion, a row at\n"
    "every point count from the start's up to N, from one run per\n"
    "terrain, method, optimiser and criterion whose error measures come\n"
    "from per-triangle sums kept as triangles are rescanned (not a pass\n"
    "over every sample); where the run has a final pass, each row is that\n"
    "pass applied to a copy of the mesh at that count, so every row equals\n"
    "'terratin simplify -max_points K'. Decimation, a row at the start and\n"
    "after every round (independent set) down to N, each from a full pass\n"
    "over the samples before the final pass (the last row: the TIN, after\n"
    "it). mean_curvature, gaussian_curvature, abn, abn_sum, abn_sumsq and\n"
    "l2 are inserted as the study did: Delaunay insertion, then the\n"
    "optimiser for the criterion (auto: the local swap).\n"
    "\n"
    "Options:\n"
    "  -terrain T        repeatable: a DEM file, or a generated terrain of\n"
    "                    the study by name: fault_smooth (80x80,\n"
    "                    displacement 20, wave size 5), fault_rough\n"
    "                    (100x100, displacement 100), peak_rough (diamond-\n"
    "                    square 129x129, roughness 0.7, a peak),\n"
    "                    valley_rough (65x65, a valley), hybrid (129x129, a\n"
    "                    peak and a valley), sphere, cylinder, bump (a file\n"
    "                    of such a name: write ./NAME); crater: Crater\n"
    "                    Lake from ../shared/testdata (or\n"
    "                    $TT_SHARED_TESTDATA), crater=PATH: from PATH\n"
    "  -seed N           the generated terrains' seed (and annealing's)\n"
    "  -criteria LIST    all (default) or criteria as simplify names them\n"
    "  -methods LIST     insert (default), decimate, or both\n"
    "  -optimizers LIST  the final pass: auto (default: simplify's choice\n"
    "                    per criterion), none, local, lookahead, anneal,\n"
    "                    edge_insertion (minmax_angle only)\n"
    "  -percent LIST     checkpoints, % of the valid samples (default\n"
    "                    1,10,25,50)\n"
    "  -points N         curves: a row at every point count up to N (the\n"
    "                    study's 500), per round for decimation; alone, no\n"
    "                    -percent checkpoints\n"
    "  -start, -importance   decimation's, as simplify\n"
    "  -b, -srcnodata, -z_factor, -z_unit, -z_to, -threads   as simplify\n"
    "  -a_srs, -s_srs, -a_nodata, -a_ullr, -srcwin, -projwin, -projwin_srs\n"
    "                    every DEM file, as simplify\n"
    "  -overwrite        write into an OUTDIR that is not empty\n"
    "  -tin_points N     also each criterion's TIN at N points (a run of\n"
    "                    its own) into OUTDIR/tins: OBJ in pixel space,\n"
    "                    each terrain as an ASCII grid, index.csv\n"
    "  -plot             draw OUTDIR/plots/*.png with plot_study.py: a PNG\n"
    "                    per terrain, method and error measure, and the\n"
    "                    TINs of -tin_points over a hillshade. Needs\n"
    "                    Python 3 with matplotlib (Debian: apt-get install\n"
    "                    python3-matplotlib; TT_PYTHON=PATH picks the\n"
    "                    python, default /usr/bin/python3 then python3),\n"
    "                    checked before the first run: exit 1 without it\n"
    "\n"
    "Exit codes: 0 success, 1 processing failure, 2 usage error, 128+N\n"
    "stopped by signal N (130 Ctrl-C, 143 SIGTERM; nothing left behind).\n"
    "\n"
    "Example:\n"
    "  terratin study -terrain fault_smooth -terrain dem.tif -criteria\n"
    "      delaunay,minmax_angle,l2 -methods insert,decimate out/\n";

static const char help_rasterize[] =
    "Usage: terratin rasterize DEM TIN OUTPUT [-layer NAME] [-b BAND]\n"
    "           [-srcnodata VALUE] [-z_factor F] [-z_unit U] [-z_to MODE]\n"
    "           [-of FORMAT] [-co NAME=VALUE]... [-max_memory SIZE]\n"
    "           [-overwrite] [-q] [-json]\n"
    "\n"
    "Writes the surface of a layer of triangles (read as eval reads it) on\n"
    "the grid of band BAND of DEM: at every sample centre in a triangle, the\n"
    "triangle's linear interpolation of its corners' heights; nodata (NaN)\n"
    "outside the TIN. One band, Float32 (Float64 when DEM's heights are read\n"
    "as doubles), the DEM's size, geotransform and CRS. The summary gives\n"
    "the samples covered and the error against DEM, as eval measures it.\n"
    "\n"
    "Options:\n"
    "  -layer NAME       layer of TIN (default as eval)\n"
    "  -of FORMAT        a GDAL raster driver (default: the one OUTPUT's\n"
    "                    extension names, else GTiff: tiled, DEFLATE)\n"
    "  -co NAME=VALUE    creation option of the driver (repeatable)\n"
    "  -b, -srcnodata, -z_factor, -z_unit, -z_to, -max_memory   the DEM,\n"
    "                    as eval\n"
    "  -a_srs, -s_srs, -a_nodata, -a_ullr, -srcwin, -projwin, -projwin_srs\n"
    "                    the DEM, as simplify (OUTPUT on the window's grid)\n"
    "  -overwrite        replace OUTPUT when it exists (default: refuse)\n"
    "  -q, -json         no summary; one JSON object instead of the summary\n"
    "\n"
    "Exit codes: 0 success, 1 processing failure, 2 usage error, 128+N\n"
    "stopped by signal N (130 Ctrl-C, 143 SIGTERM; nothing left behind).\n"
    "\n"
    "Example:\n"
    "  terratin rasterize dem.tif tin.gpkg tin.tif\n"
    "  terratin eval dem.tif tin.gpkg -error_raster diff.tif  (TIN - DEM)\n";

/* The tiles commands: the overview and a page per subcommand. */
#define TILES_USAGE                                                          \
  "Usage: terratin tiles plan DEM PLAN.json -max_error E -tile_size N\n"      \
  "           [options that shape the TIN] [-overwrite] [-q]\n"               \
  "       terratin tiles run PLAN.json TILE_ID [-overwrite]\n"                \
  "       terratin tiles merge PLAN.json OUTPUT [-overwrite] [-q] [-json]\n"  \
  "           [-of FORMAT] [-lco ...] [-dsco ...] [-nln PREFIX] [-layers L]\n"\
  "           [-nostyle] [-obj_local] [-t_srs SRS]\n"

#define TILES_CARRIED                                                        \
  "A plan carries the options that shape the TIN only: -max_error,\n"         \
  "-tile_size, -method, -start, -importance, -selection, -onepass, -hole,\n"  \
  "-criterion, -repair, -optimize, -seed, -anneal_*, -b, -srcnodata,\n"       \
  "-z_factor, -z_unit, -z_to, -work_srs AUTHORITY:CODE, and the DEM's\n"    \
  "window and georeferencing: -srcwin, -projwin, -a_ullr, -a_nodata,\n"      \
  "-a_srs, -s_srs, -projwin_srs (CRSs as AUTHORITY:CODE). The output's\n"    \
  "options (-of, -lco, -dsco, -nln, -layers, -nostyle, -obj_local, -t_srs)\n" \
  "go to merge. run and merge refuse a plan that is truncated, edited (its\n" \
  "checksum), or whose fields or options are not what plan writes.\n"

#define TILES_EXIT                                                           \
  "\n"                                                                        \
  "Exit codes: 0 success, 1 processing failure (a missing or stale piece,\n"  \
  "a changed DEM), 2 usage error (an option a plan may not carry, a bad\n"    \
  "plan), 128+N stopped by signal N (130 Ctrl-C, 143 SIGTERM; nothing left\n" \
  "behind).\n"

static const char help_tiles[] =
    TILES_USAGE
    "\n"
    "A tiled run (simplify -tile_size) as independent jobs, for a cluster:\n"
    "  plan   checks simplify's options (-tile_size and -max_error needed),\n"
    "         writes PLAN.json (the DEM's path, size and time, the tiles and\n"
    "         their windows, the options, a closing checksum) and makes the\n"
    "         folder PLAN.json.tiles\n"
    "  run    simplifies tile TILE_ID (0 .. tiles-1) alone (-method insert\n"
    "         or decimate), on one thread, and\n"
    "         writes its piece PLAN.json.tiles/TILE_ID.ttp\n"
    "  merge  joins every piece into OUTPUT as simplify writes it: the same\n"
    "         triangles and vertices as simplify -tile_size with the plan's\n"
    "         options; a missing or stale piece, or a changed DEM, is refused\n"
    TILES_CARRIED
    "Each job can run on any machine that sees the same paths; the borders\n"
    "of neighbouring tiles are computed alike by both. tools/tt_dask.py runs\n"
    "the jobs on Dask distributed; docs/scale.md shows Slurm too.\n"
    "\n"
    "Run 'terratin tiles plan|run|merge --help' for the page of each.\n"
    TILES_EXIT
    "\n"
    "Example:\n"
    "  terratin tiles plan dem.tif plan.json -max_error 0.5 -tile_size 1024\n"
    "  for i in $(seq 0 15); do terratin tiles run plan.json $i; done\n"
    "  terratin tiles merge plan.json tin.gpkg\n";

static const char help_tiles_plan[] =
    "Usage: terratin tiles plan DEM PLAN.json -max_error E -tile_size N\n"
    "           [options that shape the TIN] [-overwrite] [-q]\n"
    "\n"
    "Checks simplify's options with simplify's parser and writes PLAN.json:\n"
    "the DEM's absolute path, size in bytes and modification time, its\n"
    "width and height, the tiles (each tile's columns, rows and the window\n"
    "it reads), the options as words and a closing checksum; makes the\n"
    "folder PLAN.json.tiles for the pieces. No budget (-max_points,\n"
    "-max_triangles, -percent): its bound needs a pass over every tile\n"
    "first, which simplify -tile_size makes.\n"
    "\n"
    TILES_CARRIED
    "\n"
    "Options:\n"
    "  -max_error E      every sample within E of the TIN (needed)\n"
    "  -tile_size N      tiles of N cells, 16 to 65536 (needed)\n"
    "  -overwrite        replace PLAN.json when it exists\n"
    "  -q                no summary line\n"
    TILES_EXIT
    "\n"
    "Example:\n"
    "  terratin tiles plan dem.tif plan.json -max_error 0.5 -tile_size 1024\n";

static const char help_tiles_run[] =
    "Usage: terratin tiles run PLAN.json TILE_ID [-overwrite]\n"
    "\n"
    "Simplifies tile TILE_ID (0 to tiles - 1, row-major) of the plan alone,\n"
    "on one thread, by the plan's method, and writes its piece\n"
    "PLAN.json.tiles/TILE_ID.ttp (the piece's arrays, the plan's hash and\n"
    "the tile id, a checksum) through a temporary name and a rename. The\n"
    "DEM must be the one planned (same size and modification time).\n"
    "\n"
    "Options:\n"
    "  -overwrite        replace the piece when it exists (default: keep it)\n"
    TILES_EXIT
    "\n"
    "Example:\n"
    "  terratin tiles run plan.json 7\n";

static const char help_tiles_merge[] =
    "Usage: terratin tiles merge PLAN.json OUTPUT [-overwrite] [-q] [-json]\n"
    "           [-of FORMAT] [-lco NAME=VALUE]... [-dsco NAME=VALUE]...\n"
    "           [-nln PREFIX] [-layers LIST] [-nostyle] [-obj_local]\n"
    "           [-t_srs SRS]\n"
    "\n"
    "Joins every piece of the plan in tile order and writes OUTPUT as\n"
    "simplify writes it (temporary name, rename, nothing left behind on a\n"
    "failure): the triangles and vertices of simplify -tile_size with the\n"
    "plan's options. A missing piece (counted, the first named), a piece of\n"
    "another plan or tile, a damaged one, or a changed DEM is refused\n"
    "before anything is written.\n"
    "\n"
    "Options: the output options of simplify (see 'terratin simplify\n"
    "--help'): -of, -lco, -dsco, -nln, -layers, -nostyle, -obj_local,\n"
    "-t_srs; and\n"
    "  -overwrite        replace OUTPUT when it exists (default: refuse)\n"
    "  -q, -json         no summary; one JSON object instead of it\n"
    TILES_EXIT
    "\n"
    "Example:\n"
    "  terratin tiles merge plan.json tin.gpkg -nln dem_\n";

const char *tt__app_tiles_help(const char *sub)
{
  if (sub && tt__app_str_ieq(sub, "plan"))
    return help_tiles_plan;
  if (sub && tt__app_str_ieq(sub, "run"))
    return help_tiles_run;
  if (sub && tt__app_str_ieq(sub, "merge"))
    return help_tiles_merge;
  return help_tiles;
}

const char *tt_app_help(tt_app_command topic)
{
  switch (topic) {
  case TT_APP_SIMPLIFY: return help_simplify;
  case TT_APP_GENERATE: return help_generate;
  case TT_APP_EVAL: return help_eval;
  case TT_APP_OPTIMIZE: return help_optimize;
  case TT_APP_STUDY: return help_study;
  case TT_APP_RASTERIZE: return help_rasterize;
  case TT_APP_TILES: return help_tiles;
  default: return help_top;
  }
}

const char *tt__app_command_name(tt_app_command c)
{
  const tt__app_command_def *d = tt__app_command_def_of(c);
  return d ? d->name : "";
}
