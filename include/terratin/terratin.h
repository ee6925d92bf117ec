/*
 * terratin.h -- the public C API of the terratin engine.
 *
 * The engine turns a height grid into a TIN whose vertices are grid samples,
 * by greedy insertion under a triangulation criterion, and measures how well
 * the TIN approximates the grid. It knows nothing of GDAL: a program fills a
 * tt_grid from memory, runs tt_refine_run() and reads the tt_tin it returns.
 * terratin_gdal.h adds reading rasters and writing vector layers.
 *
 * Conventions used throughout:
 *  - Every object is opaque and made by a _create (or _run) function that
 *    returns a status and hands the object back through its last argument;
 *    its _destroy function accepts NULL.
 *  - Ownership is stated in one fixed sentence: "The caller owns *out_X and
 *    frees it with tt_X_destroy()."
 *  - Fallible functions return tt_status; the context keeps the last code and
 *    a formatted one-line message (tt_context_errmsg()).
 *  - Samples stand at pixel centres. Column c, row r of the grid is the point
 *    (c, r) in pixel space and (gt0 + (c+0.5)gt1 + (r+0.5)gt2,
 *    gt3 + (c+0.5)gt4 + (r+0.5)gt5) in map space (GDAL geotransform).
 *  - Heights are floats, or doubles where floats cannot hold a DEM's
 *    values exactly (tt_precision); NaN marks nodata. Every computation on
 *    them is in doubles, so a grid of doubles and one of floats holding the
 *    same values give the same TIN bit for bit. Counts are size_t; mesh
 *    indices are int32_t, so a TIN holds at most TT_MAX_VERTICES vertices.
 *  - No global mutable state: everything lives in the context.
 *
 * The header compiles alone, in C11 and in C++.
 *
 * Part of include/terratin/, the public C API.
 */
#ifndef TERRATIN_H
#define TERRATIN_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define TT_VERSION_MAJOR 0
#define TT_VERSION_MINOR 1
#define TT_VERSION_PATCH 0
#define TT_VERSION_STRING "0.1.0"

/* The largest vertex count of a TIN (triangles: about twice that). */
#define TT_MAX_VERTICES ((size_t)0x3fffffff)
/* The largest grid side accepted (columns or rows). */
#define TT_MAX_GRID_SIDE ((size_t)0x0fffffff)
/* The largest height magnitude accepted: the largest float (FLT_MAX), so
 * that no difference, square or sum of squares of heights overflows a
 * double, in a grid of doubles too. */
#define TT_MAX_HEIGHT 3.4028234663852886e38

/* ---------------------------------------------------------------------------
 * Status codes: one table makes the enum, the names and the messages.
 * ------------------------------------------------------------------------- */
#define TT_STATUS_MAP(X)                                                      \
  X(OK, "success")                                                            \
  X(ERR_ARG, "invalid argument")                                              \
  X(ERR_NOMEM, "out of memory")                                               \
  X(ERR_IO, "input/output error")                                             \
  X(ERR_FORMAT, "unsupported or malformed data")                              \
  X(ERR_DATA, "invalid data")                                                 \
  X(ERR_LIMIT, "size limit exceeded")                                         \
  X(ERR_EXISTS, "output exists")                                              \
  X(ERR_INTERRUPTED, "interrupted by the progress callback")                  \
  X(ERR_INTERNAL, "internal error")

typedef enum tt_status {
#define TT_STATUS_ENUM_(name, msg) TT_##name,
  TT_STATUS_MAP(TT_STATUS_ENUM_)
#undef TT_STATUS_ENUM_
  TT_STATUS_COUNT_
} tt_status;

/* "OK", "ERR_ARG", ...; "UNKNOWN" for a value outside the table. */
const char *tt_status_name(tt_status status);
/* The generic message of a status ("invalid argument"). */
const char *tt_status_message(tt_status status);
/* "0.1.0" */
const char *tt_version(void);

/* ---------------------------------------------------------------------------
 * Context: last error, warnings sink. One per thread of use.
 * ------------------------------------------------------------------------- */
typedef struct tt_context tt_context;

/* Called for each warning (a complete sentence, no trailing newline). */
typedef void (*tt_log_fn)(void *user, const char *message);

/* Progress callback, GDAL's GDALProgressFunc shape: complete in [0,1];
 * returning 0 stops the run with TT_ERR_INTERRUPTED. */
typedef int (*tt_progress_fn)(double complete, const char *message,
                              void *user);

/* Returns NULL when out of memory. The caller owns the context and frees it
 * with tt_context_destroy(). */
tt_context *tt_context_create(void);
void tt_context_destroy(tt_context *ctx);
tt_status tt_context_errno(const tt_context *ctx);
/* The last error's one-line message, "" when none. Valid until the next call
 * that fails on this context. */
const char *tt_context_errmsg(const tt_context *ctx);
void tt_context_clear_error(tt_context *ctx);
/* Warnings go to fn (default: none are shown, but they are counted). */
void tt_context_set_log(tt_context *ctx, tt_log_fn fn, void *user);
size_t tt_context_warning_count(const tt_context *ctx);

/* ---------------------------------------------------------------------------
 * Height grid.
 * ------------------------------------------------------------------------- */
typedef struct tt_grid tt_grid;

/* How a grid holds its heights: 4-byte floats, or 8-byte doubles for
 * values a float cannot hold exactly (32- and 64-bit integers beyond 2^24,
 * Float64 rasters, heights scaled by a factor; docs/cli.md lists which
 * band types get which). Doubles cost twice the memory of the heights and
 * some time in refinement (docs/architecture.md gives the figures). */
typedef enum tt_precision {
  TT_PRECISION_FLOAT32 = 0,
  TT_PRECISION_FLOAT64
} tt_precision;

/* Makes an nx x ny grid of floats, every sample NaN (nodata), geotransform
 * (0,1,0,0,0,1). nx and ny must be >= 2 and <= TT_MAX_GRID_SIDE.
 * The caller owns *out_grid and frees it with tt_grid_destroy(). */
tt_status tt_grid_create(tt_context *ctx, size_t nx, size_t ny,
                         tt_grid **out_grid);
/* The same, holding doubles. The caller owns *out_grid and frees it with
 * tt_grid_destroy(). */
tt_status tt_grid_create_f64(tt_context *ctx, size_t nx, size_t ny,
                             tt_grid **out_grid);
/* A grid of floats filled from a row-major array of nx*ny heights (NaN =
 * nodata). The caller owns *out_grid and frees it with tt_grid_destroy(). */
tt_status tt_grid_create_from_floats(tt_context *ctx, size_t nx, size_t ny,
                                     const float *z, tt_grid **out_grid);
/* A grid of doubles filled from a row-major array of nx*ny heights (NaN =
 * nodata), whatever the values. The caller owns *out_grid and frees it
 * with tt_grid_destroy(). */
tt_status tt_grid_create_from_doubles(tt_context *ctx, size_t nx, size_t ny,
                                      const double *z, tt_grid **out_grid);
void tt_grid_destroy(tt_grid *grid);

size_t tt_grid_width(const tt_grid *grid);
size_t tt_grid_height(const tt_grid *grid);
tt_precision tt_grid_precision(const tt_grid *grid);
/* Row-major heights, nx*ny floats; write them before the first run.
 * NaN marks nodata; infinities are refused by tt_grid_check(). NULL for a
 * grid of doubles (use tt_grid_heights_f64). */
float *tt_grid_heights(tt_grid *grid);
const float *tt_grid_heights_const(const tt_grid *grid);
/* The same as doubles, for a grid of doubles; NULL for a grid of floats. */
double *tt_grid_heights_f64(tt_grid *grid);
const double *tt_grid_heights_f64_const(const tt_grid *grid);
/* The height at column col, row row (both in range), at the grid's own
 * precision, whichever it is; NaN for nodata. */
double tt_grid_sample(const tt_grid *grid, size_t col, size_t row);

/* GDAL geotransform: map x = gt[0] + px*gt[1] + py*gt[2],
 * y = gt[3] + px*gt[4] + py*gt[5], px/py in pixel-edge units. Sets the ground
 * frame to the geotransform's linear part too. The determinant must not be
 * zero. */
tt_status tt_grid_set_geotransform(tt_context *ctx, tt_grid *grid,
                                   const double gt[6]);
void tt_grid_get_geotransform(const tt_grid *grid, double out_gt[6]);

/* The ground frame: the linear map from a pixel step to metres (or the CRS's
 * linear unit) on the ground, x = a[0]*dc + a[1]*dr, y = a[2]*dc + a[3]*dr.
 * Angles, areas and the Delaunay test are measured in this frame. The glue
 * sets it for geographic grids; by default it is the geotransform's linear
 * part. Its orientation must match the geotransform's (same determinant
 * sign). */
tt_status tt_grid_set_ground_frame(tt_context *ctx, tt_grid *grid,
                                   const double a[4]);
void tt_grid_get_ground_frame(const tt_grid *grid, double out_a[4]);

/* Ground points: for a grid whose pixels map to the ground through no
 * affine frame (longitude/latitude), every sample's position in a
 * conformal working projection. tt_grid_alloc_ground_points() makes room
 * for them (16 bytes a sample) and the caller fills, per sample i
 * (row-major): xy[2i], xy[2i+1] the projected x, y (any origin; differences
 * must be ground lengths times the scale). The projection's scale factor k
 * (projected length / ground length) and convergence (the angle, radians
 * clockwise, from the projection's +y to true north) at a sample are not
 * stored: tt_grid_ground_scale_at() derives them from the neighbouring
 * ground points (finite differences) and the ground metric function
 * (tt_grid_set_ground_metric_fn), for the TIN's vertices only. The
 * ground frame (tt_grid_set_ground_frame) must still be set, to the
 * projection's Jacobian near the centre: it gives the pixel-space
 * orientation and the fallbacks. Once filled, the Delaunay test runs on the
 * points with exact adaptive predicates (triangle orientation stays exact
 * in pixel space), criteria measure angles on them, and a TIN's triangle
 * areas, slopes and aspects divide out the local scale and turn by the
 * convergence. tt_grid_drop_ground_points() returns to the affine frame.
 * The accessors return NULL when the grid has no ground points. */
tt_status tt_grid_alloc_ground_points(tt_context *ctx, tt_grid *grid);
/* The area of a triangle on the ground from its corners' map coordinates
 * (the geotransform's x, y of three pixel centres), for a frame whose
 * plane triangles are not the ground's (the glue gives geodesic areas for
 * a geographic CRS); params: four numbers the function reads. A TIN made
 * from the grid then reports these areas (tt_triangle_info.area_2d, and
 * area_3d in proportion). NULL: areas in the frame. */
typedef double (*tt_area_fn)(const double params[4], const double x[3],
                             const double y[3]);
void tt_grid_set_area_fn(tt_grid *grid, tt_area_fn fn,
                         const double params[4]);
/* Metres on the ground per map unit east and north (out[0], out[1]) at
 * map point (x, y) of the geotransform, whose axes point east and north
 * (the glue's: the ellipsoid's radii for longitude/latitude); params:
 * four numbers the function reads. NULL (the default): map units are
 * metres. */
typedef void (*tt_ground_metric_fn)(const double params[4], double x,
                                    double y, double out[2]);
void tt_grid_set_ground_metric_fn(tt_grid *grid, tt_ground_metric_fn fn,
                                  const double params[4]);
/* The scale factor k and the convergence (radians clockwise from the
 * projection's +y to true north) of the ground points at sample (col,
 * row): the Jacobian J of pixel -> ground point by finite differences
 * (central, second-order one-sided at the edges) against the ground
 * Jacobian G of pixel -> east/north metres (the metric function times the
 * geotransform): k = sqrt(|det J / det G|), true north J G^-1 (0, 1).
 * TT_ERR_ARG without ground points or outside the grid; TT_ERR_DATA when
 * k is not finite and positive (a pole). */
tt_status tt_grid_ground_scale_at(const tt_grid *grid, size_t col,
                                  size_t row, double *out_k,
                                  double *out_convergence);
void tt_grid_drop_ground_points(tt_grid *grid);
double *tt_grid_ground_xy(tt_grid *grid);

/* Checks the heights: refuses infinities and heights beyond
 * +-TT_MAX_HEIGHT (naming the first row/column) and counts the valid
 * (non-NaN) samples. out_valid may be NULL. */
tt_status tt_grid_check(tt_context *ctx, const tt_grid *grid,
                        size_t *out_valid);

/* ---------------------------------------------------------------------------
 * Criteria and refinement options.
 * ------------------------------------------------------------------------- */
/* Triangulation criteria (SPEC section 2; docs/criteria.md explains each
 * one and when to pick it). All measure in the ground frame. */
typedef enum tt_criterion {
  TT_CRITERION_DELAUNAY = 0,      /* max-min angle, exact incircle */
  TT_CRITERION_MINMAX_ANGLE,      /* minimise the largest map angle */
  TT_CRITERION_MINMAX_ANGLE_LEX,  /* the same, sorted angles compared
                                     lexicographically */
  TT_CRITERION_MIN_AREA,          /* minimise the 3-D surface area */
  TT_CRITERION_MEAN_CURVATURE,    /* minimise sum |e| * normal angle */
  TT_CRITERION_GAUSSIAN_CURVATURE,/* minimise sum |K| (tight) */
  TT_CRITERION_ABN,               /* angles between normals, sorted,
                                     lexicographic */
  TT_CRITERION_ABN_SUM,           /* sum of the angles between normals */
  TT_CRITERION_ABN_SUMSQ,         /* sum of their squares */
  TT_CRITERION_L2                 /* least squares: sum (H - H')^2 */
} tt_criterion;

/* "delaunay", "minmax_angle", "minmax_angle_lex", "min_area",
 * "mean_curvature", "gaussian_curvature", "abn", "abn_sum", "abn_sumsq",
 * "l2"; NULL for an unknown value. */
const char *tt_criterion_name(tt_criterion criterion);
/* Parses a name; TT_ERR_ARG for an unknown one. */
tt_status tt_criterion_parse(tt_context *ctx, const char *name,
                             tt_criterion *out_criterion);

/* How the criterion is restored around each inserted vertex (SPEC
 * sections 3.1 and 3.2). */
typedef enum tt_repair {
  TT_REPAIR_AUTO = 0,      /* delaunay for l2 (measured: the vertices that
                              Delaunay insertion picks, then the L2 swaps
                              of the final pass, fit the grid best), flip
                              for every other criterion */
  TT_REPAIR_FLIP,          /* Lawson flips outward from the new vertex: an
                              edge opposite it is swapped while its swap
                              value is positive (exact incircle flips for
                              Delaunay). With flip, local and lookahead,
                              min_area first re-triangulates the hole
                              around the vertex by exact dynamic
                              programming */
  TT_REPAIR_LOCAL,         /* maximal-reduction local swap over the edges
                              around the new vertex and every edge a swap
                              reaches from them */
  TT_REPAIR_LOOKAHEAD,     /* that, then two-swap look-ahead moves */
  TT_REPAIR_DELAUNAY       /* Delaunay during the insertions; the criterion
                              acts in the final pass only (optimize) */
} tt_repair;

/* "auto", "flip", "local", "lookahead", "delaunay"; NULL for an unknown
 * value. */
const char *tt_repair_name(tt_repair repair);
/* Parses one of those names; TT_ERR_ARG for an unknown one. */
tt_status tt_repair_parse(tt_context *ctx, const char *name,
                          tt_repair *out_repair);
/* What TT_REPAIR_AUTO means for a criterion (other values are returned as
 * they are). */
tt_repair tt_repair_resolve(tt_repair repair, tt_criterion criterion);

/* Swap optimisation of the criterion over the whole mesh once the
 * insertions are done (SPEC section 3.2). */
typedef enum tt_optimize {
  TT_OPTIMIZE_AUTO = 0,    /* local when the criterion was not restored
                              during the insertions (repair delaunay with
                              a criterion other than Delaunay), else none */
  TT_OPTIMIZE_NONE,
  TT_OPTIMIZE_LOCAL,       /* maximal-reduction local swap */
  TT_OPTIMIZE_LOOKAHEAD,   /* local swap, then two-swap look-ahead moves
                              (Dyn, Hormann, Kim, Levin) */
  TT_OPTIMIZE_ANNEAL,      /* simulated annealing (Schumaker, SPEC 3.3),
                              tt_anneal_options; the best triangulation
                              seen is kept */
  TT_OPTIMIZE_EDGE_INSERTION /* edge insertion, the global Min-Max angle
                              optimum (SPEC 3.4); minmax_angle only */
} tt_optimize;

/* Simulated annealing's schedule (SPEC 3.3). Zero in any field means the
 * study's default, so a zeroed struct is the default schedule. Stages
 * k = 1..stages run at t_k = r^k t0; each tries up to swaps x E random
 * swappable edges (E: the interior unconstrained edges at the start) and
 * ends after good x E improving swaps; a stage with no swap ends the run. */
typedef struct tt_anneal_options {
  double t0;        /* start temperature; <= 0: 2 x the largest |swap
                       value| at the start */
  int stages;       /* K; 0: 100 */
  double swaps;     /* S per edge; 0: 5 */
  double good;      /* G per edge; 0: 5 */
  double r;         /* cooling factor in (0, 1); 0: 0.95 */
  uint64_t seed;    /* the random sequence; the same seed, the same TIN */
} tt_anneal_options;

/* "auto", "none", "local", "lookahead", "anneal", "edge_insertion"; NULL
 * for an unknown value. */
const char *tt_optimize_name(tt_optimize optimize);
/* Parses one of those names; TT_ERR_ARG for an unknown one. */
tt_status tt_optimize_parse(tt_context *ctx, const char *name,
                            tt_optimize *out_optimize);
/* Checks that an optimisation fits a criterion (edge insertion is for
 * minmax_angle only) and that an annealing schedule is in range (anneal
 * may be NULL): TT_ERR_ARG with a message naming the problem. */
tt_status tt_optimize_check(tt_context *ctx, tt_optimize optimize,
                            tt_criterion criterion,
                            const tt_anneal_options *anneal);
/* What TT_OPTIMIZE_AUTO means for a criterion and a resolved repair
 * (other values are returned as they are). */
tt_optimize tt_optimize_resolve(tt_optimize optimize, tt_criterion criterion,
                                tt_repair repair);

/* Curves (issue 15): a run can report the error measures of its TIN after
 * every step (tt_step_info, below the error measures), through this
 * callback; returning 0 stops the run with TT_ERR_INTERRUPTED. */
typedef struct tt_step_info tt_step_info;
typedef int (*tt_step_fn)(const tt_step_info *step, void *arg);

/* Breaklines: segments between grid samples that the TIN must have as
 * edges. Sample s is the one at column s % width, row s / width of the
 * grid. The edges are constrained: no flip of the criterion and no
 * optimiser removes them, and a vertex inserted on one splits it into two
 * constrained edges. Every end must be a valid sample in the valid domain
 * (not across nodata), and two segments may meet only at their ends or
 * overlap along a line; a run that cannot make them edges fails with
 * TT_ERR_DATA naming the segment. The ends count as forced vertices of the
 * start, like the nodata outline's. The caller keeps ends alive during the
 * run; { NULL, 0 } (the default): none. */
typedef struct tt_breaklines {
  const int64_t *ends;  /* 2 n sample indices: segment i from ends[2 i]
                           to ends[2 i + 1] */
  size_t n;
} tt_breaklines;

typedef struct tt_refine_options {
  /* Stop when the worst remaining sample error is <= max_error (z units).
   * Negative: no error limit. */
  double max_error;
  /* Stop before the TIN would have more than max_points vertices; 0: none. */
  size_t max_points;
  /* Stop before the TIN would have more than max_triangles; 0: none. */
  size_t max_triangles;
  /* Stop at floor(percent/100 * valid samples) vertices; 0: none. */
  double percent;
  tt_criterion criterion;
  /* The final whole-mesh pass. Its swaps never raise a triangle's error
   * above the larger of max_error and the worst error left when the
   * insertions stopped, so the error bound of the run still holds. */
  tt_optimize optimize;
  /* The criterion's restoration around each inserted vertex. */
  tt_repair repair;
  /* The schedule of optimize = TT_OPTIMIZE_ANNEAL. */
  tt_anneal_options anneal;
  /* Threads for the raster scans: 0 = automatic (all online CPUs for grids
   * of a million samples or more, else 1), 1 = the caller's only, N = N.
   * The result does not depend on it. */
  int threads;
  /* Called now and then with the fraction done; may be NULL. */
  tt_progress_fn progress;
  void *progress_arg;
  /* Bytes the run may hold, the grid's heights included: the mesh, the
   * insertion state and the TIN's records to come are counted as they
   * grow, and a run that would pass the limit stops with TT_ERR_NOMEM and
   * a message naming the phase and the size it needed. 0: no limit. */
  size_t max_memory;
  /* Curves: when step is set, it is called after the starting
   * triangulation and after each insertion whose vertex count is at most
   * step_until (SIZE_MAX: every one) or one of the nstep_at counts of
   * step_at (any order), and once more for the step the run ends at
   * (tt_step_info.last), with the measures of the TIN the run would return
   * had it stopped there. They come from per-triangle sums of |H - H'| and
   * (H - H')^2 kept up to date as the triangles are rescanned (24 bytes per
   * triangle slot; each rescan reads every sample of its triangle, where
   * an unrecorded one skips the tiles that cannot hold its candidate),
   * not from a pass over every sample. When the final pass
   * (optimize, resolved) is not none, each reported step applies it to a
   * copy of the mesh and measures the copy (only the triangles it changed
   * are scanned), as a run stopped there would. NULL (the default): none
   * of this, and the run costs what it always did. */
  tt_step_fn step;
  void *step_arg;
  size_t step_until;
  const size_t *step_at;
  size_t nstep_at;
  /* Edges the TIN must have (tt_breaklines above). */
  tt_breaklines breaklines;
} tt_refine_options;

/* Default: max_error 1 z unit, no other limit, Delaunay, no progress. */
void tt_refine_options_init(tt_refine_options *opt);

/* The bytes this process may still use as the system says: the smallest
 * of the physical memory available (MemAvailable; without it 3/4 of
 * physical memory), its cgroup's limit less the group's use (v2
 * memory.max, v1 memory.limit_in_bytes) and its address-space limit
 * (ulimit -v, RLIMIT_AS) less what is mapped already, less a safety margin
 * (an eighth and 32 MiB; half of a room under 64 MiB) for what no run
 * counts. *out_source (may be NULL) names the one that decided, a static
 * string. SIZE_MAX when the system says nothing. */
size_t tt_memory_limit(const char **out_source);

/* Copies text into buf (size bytes, always terminated), shortening every
 * run of more than TT_TEXT_WORD_MAX bytes without a blank (a path, a
 * layer name) in the middle to its first and last parts around "...", so
 * that a message about a 100 kB name still fits and still says its cause.
 * Returns buf. */
#define TT_TEXT_WORD_MAX 200
const char *tt_text_fit(char *buf, size_t size, const char *text);

/* ---------------------------------------------------------------------------
 * The TIN: the result of a run, with its bookkeeping.
 * ------------------------------------------------------------------------- */
typedef struct tt_tin tt_tin;

/* Greedy insertion (Garland-Heckbert) of the grid's samples under the
 * criterion, until the first stop condition is met. At least one stop
 * condition must be set. The caller owns *out_tin and frees it with
 * tt_tin_destroy(). */
tt_status tt_refine_run(tt_context *ctx, const tt_grid *grid,
                        const tt_refine_options *opt, tt_tin **out_tin);
void tt_tin_destroy(tt_tin *tin);

/* Optimising a TIN the caller already has (tt_optimize_run). */
typedef struct tt_optimize_options {
  tt_criterion criterion;
  tt_optimize optimize;    /* TT_OPTIMIZE_AUTO: local */
  /* A move is refused when one of the triangles it makes has a sample
   * with |H - H'| > max_error (z units). Negative: no bound. */
  double max_error;
  tt_anneal_options anneal;
} tt_optimize_options;

/* Default: Delaunay, local swap, no bound, the default schedule. */
void tt_optimize_options_init(tt_optimize_options *opt);

/* Rebuilds the mesh of ntriangles triangles given as tt_eval_triangles
 * takes them (9 doubles each, pixel-centre space; corners within 1e-6
 * pixel of a sample are put on it, the z given is ignored: heights come
 * from the grid), optimises it for the criterion with opt->optimize, and
 * returns it as a TIN (vertex ranks in order of first appearance, no
 * insertion errors). TT_ERR_DATA with a message naming the triangle when
 * a corner is not a valid sample of the grid, a triangle has no area, an
 * edge is used twice the same way, the triangles overlap (around a vertex,
 * or over a sample), or they do not form a surface. The caller owns
 * *out_tin and frees it with tt_tin_destroy(). */
tt_status tt_optimize_run(tt_context *ctx, const tt_grid *grid,
                          size_t ntriangles, const double *pix_xyz,
                          const tt_optimize_options *opt, tt_tin **out_tin);

typedef enum tt_stop_reason {
  TT_STOP_NONE = 0,        /* not stopped */
  TT_STOP_MAX_ERROR,       /* every sample within max_error */
  TT_STOP_MAX_POINTS,      /* max_points (or percent) reached */
  TT_STOP_MAX_TRIANGLES,   /* the next insertion would pass max_triangles */
  TT_STOP_EXHAUSTED        /* every sample is exact and no error limit
                              was set */
} tt_stop_reason;

const char *tt_stop_reason_name(tt_stop_reason reason);

/* Error measures over the valid samples (SPEC section 6), z units. */
typedef struct tt_error_stats {
  size_t samples;       /* valid samples */
  size_t covered;       /* of those, lying in or on some triangle: the
                           measures below are over these. The others are
                           valid samples that cannot carry a triangle
                           (lone samples, one-sample-wide lines amid
                           nodata); a TIN keeps them as lone vertices. */
  double max_error;     /* L-infinity */
  double rmse;          /* L2 / sqrt(samples) */
  double mean_abs;      /* sum |H - H'| / samples */
  double total_abs;     /* sum |H - H'| */
  double l2;            /* sqrt(sum (H - H')^2) */
  int64_t max_col;      /* where max_error was found (-1 if none) */
  int64_t max_row;
} tt_error_stats;

/* One step of a recorded run (tt_refine_options.step,
 * tt_decimate_options.step). */
struct tt_step_info {
  size_t step;          /* insertions done (refinement); rounds done
                           (decimation: independent sets, or removals with
                           sequential selection); 0: the start */
  size_t points;        /* vertices of the TIN at this step */
  size_t triangles;
  /* The measures, as tt_tin_summary.errors would give them for the TIN of
   * this step (samples = the valid samples); max_col, max_row: a sample
   * where max_error is reached (-1 when every sample is exact). */
  tt_error_stats errors;
  /* Seconds of the run up to this step, the time spent reporting earlier
   * steps left out (this step's final pass on a copy counted). */
  double seconds;
  int optimized;        /* non-zero: measured on a copy after the final
                           pass */
  int last;             /* non-zero: the step the run ends at */
};

typedef struct tt_tin_summary {
  size_t vertices;
  size_t triangles;
  size_t valid_samples;
  size_t grid_width, grid_height;
  tt_criterion criterion;
  tt_stop_reason stop_reason;
  tt_error_stats errors;
  size_t components;      /* separate pieces of the TIN (islands) */
  size_t forced_vertices; /* inserted to follow nodata outlines, whatever
                             their error */
  /* Decimation only (0 after refinement): vertices of the starting TIN,
   * vertices removed, rounds (independent sets; removals for sequential),
   * and removals refused because they would break the error bound. */
  size_t start_vertices;
  size_t removed_vertices;
  size_t rounds;
  size_t refused_bound;
  /* Wall-clock seconds tt_refine_run spent building the mesh (from the
   * call to the end of the final optimisation pass) and then measuring it
   * (`errors` above and the per-triangle and per-vertex statistics: one
   * more pass over every sample). */
  double seconds_mesh;
  double seconds_statistics;
} tt_tin_summary;

void tt_tin_get_summary(const tt_tin *tin, tt_tin_summary *out_summary);
size_t tt_tin_vertex_count(const tt_tin *tin);
size_t tt_tin_triangle_count(const tt_tin *tin);
/* Non-zero when the triangles' areas come from the grid's area function
 * (tt_grid_set_area_fn: geodesic for a geographic DEM) rather than the
 * ground frame. */
int tt_tin_has_area_fn(const tt_tin *tin);

typedef struct tt_vertex_info {
  int32_t col, row;       /* source sample */
  double x, y;            /* map coordinates (geotransform of the grid) */
  double z;               /* height */
  /* |H - H'| at this sample just before it was inserted; NaN for the
   * vertices of the starting triangulation. */
  double insert_error;
  size_t rank;            /* insertion order, 0-based; equals the index */
  double star_max_error;  /* max |H - H'| over the samples of its star */
  double star_rmse;       /* RMS of the same samples */
  size_t star_samples;
  /* Decimation: the importance the vertex had when the run stopped (with
   * importance error, the largest error its removal would now leave); NaN
   * after refinement and for a vertex that may not go (a grid or outline
   * corner, a pinch of the outline). */
  double importance;
} tt_vertex_info;

typedef struct tt_triangle_info {
  int32_t v[3];           /* vertex indices, counter-clockwise in map space */
  double max_error;       /* over the samples the triangle owns */
  double rmse;
  size_t samples;         /* samples owned: every valid sample is owned by
                             exactly one triangle */
  double area_2d;         /* ground units squared (ground frame) */
  double area_3d;
  double slope_deg;       /* 0 = flat */
  double aspect_deg;      /* downslope azimuth clockwise from map north
                             (+y), [0,360); NaN when flat */
  double min_angle_deg;   /* in the ground frame */
  double max_angle_deg;
  /* Bit k (1, 2, 4) set when edge v[k] -> v[(k + 1) % 3] lies on one of
   * the run's breaklines (tt_breaklines); 0 without breaklines. */
  unsigned constrained;
} tt_triangle_info;

/* index < count, else TT_ERR_ARG (the context may be NULL here). */
tt_status tt_tin_vertex(const tt_tin *tin, size_t index,
                        tt_vertex_info *out_vertex);
tt_status tt_tin_triangle(const tt_tin *tin, size_t index,
                          tt_triangle_info *out_triangle);

/* ---------------------------------------------------------------------------
 * Decimation (SPEC section 3.6, docs/decimation.md): start from a fine TIN
 * and delete the least important vertices.
 * ------------------------------------------------------------------------- */
typedef enum tt_decimate_start {
  TT_DSTART_ALL = 0,     /* every valid sample, over the valid domain */
  TT_DSTART_GREEDY,      /* greedy Delaunay insertion to zero error */
  TT_DSTART_GREEDY_N     /* greedy Delaunay insertion of start_points */
} tt_decimate_start;

typedef enum tt_importance {
  TT_IMPORTANCE_AUTO = 0, /* error with a max error, else hdh */
  TT_IMPORTANCE_DEGREE,   /* number of neighbours */
  TT_IMPORTANCE_HDH,      /* |sum (z(v) - z(v_i))| over the neighbours */
  TT_IMPORTANCE_ABH,      /* |neighbours below - neighbours above| */
  TT_IMPORTANCE_VOLUME,   /* |volume under the star - under the hole| */
  TT_IMPORTANCE_DROP,     /* |z(v) - the hole's height at v| */
  TT_IMPORTANCE_ERROR     /* largest |H - H'| the removal would leave over
                             the valid samples under the hole */
} tt_importance;

typedef enum tt_selection {
  TT_SELECTION_INDEPENDENT = 0, /* rounds of independent sets */
  TT_SELECTION_SEQUENTIAL       /* least important first, from a heap */
} tt_selection;

typedef enum tt_hole {
  TT_HOLE_AUTO = 0,       /* circumradius for delaunay, minangle else */
  TT_HOLE_MINANGLE,       /* ear cutting, largest smallest angle first */
  TT_HOLE_CIRCUMRADIUS,   /* ear cutting, smallest circumradius first */
  TT_HOLE_DP              /* exact optimum of the criterion's decomposable
                             measure (delaunay, minmax_angle[_lex],
                             min_area only) */
} tt_hole;

/* Names: "all", "greedy", "greedy:N" (tt_decimate_start_parse also sets
 * the N); "auto", "degree", "hdh", "abh", "volume", "drop", "error";
 * "independent", "sequential"; "auto", "minangle", "circumradius", "dp".
 * NULL for an unknown value; parsing an unknown name is TT_ERR_ARG. */
const char *tt_importance_name(tt_importance importance);
tt_status tt_importance_parse(tt_context *ctx, const char *name,
                              tt_importance *out_importance);
const char *tt_selection_name(tt_selection selection);
tt_status tt_selection_parse(tt_context *ctx, const char *name,
                             tt_selection *out_selection);
const char *tt_hole_name(tt_hole hole);
tt_status tt_hole_parse(tt_context *ctx, const char *name,
                        tt_hole *out_hole);
const char *tt_decimate_start_name(tt_decimate_start start);
tt_status tt_decimate_start_parse(tt_context *ctx, const char *name,
                                  tt_decimate_start *out_start,
                                  size_t *out_points);

typedef struct tt_decimate_options {
  /* No removal may leave a valid sample more than max_error away (z
   * units); negative: no error limit. */
  double max_error;
  /* Stop as soon as the TIN has at most max_points vertices (percent:
   * floor(percent/100 * valid samples)) or at most max_triangles
   * triangles; 0: none. The first reached wins. */
  size_t max_points;
  size_t max_triangles;
  double percent;
  tt_criterion criterion;
  tt_decimate_start start;
  size_t start_points;     /* N of TT_DSTART_GREEDY_N */
  tt_importance importance;
  tt_selection selection;
  int onepass;             /* independent sets: score once at the start
                              (non-zero) */
  tt_hole hole;
  tt_repair repair;        /* the criterion restored around each hole */
  tt_optimize optimize;    /* the final whole-mesh pass */
  tt_anneal_options anneal; /* its schedule with TT_OPTIMIZE_ANNEAL */
  int threads;             /* as in tt_refine_options */
  tt_progress_fn progress;
  void *progress_arg;
  /* Curves: when step is set, it is called with the measures of the mesh
   * after the start and after every round (every removal with sequential
   * selection), before the final pass, and once more at the end
   * (tt_step_info.last, after the final pass), each from one pass over
   * every sample (decimation keeps no running sums). NULL: none. */
  tt_step_fn step;
  void *step_arg;
  /* Edges the TIN must have (tt_breaklines): made constrained edges of
   * the start (every start); their vertices are never removed. */
  tt_breaklines breaklines;
} tt_decimate_options;

/* Default: no limit at all (set one), Delaunay, start all, importance
 * auto, independent multi-pass, hole auto, repair and optimize auto. */
void tt_decimate_options_init(tt_decimate_options *opt);

/* Vertex decimation of the grid under the criterion until the first stop
 * condition is met; at least one must be set. The caller owns *out_tin
 * and frees it with tt_tin_destroy(). */
tt_status tt_decimate_run(tt_context *ctx, const tt_grid *grid,
                          const tt_decimate_options *opt, tt_tin **out_tin);

/* ---------------------------------------------------------------------------
 * Tiled runs (src/tile/): a DEM cut into tiles that share their border rows
 * and columns, each refined alone to the same max error, the pieces joined
 * into one conforming TIN. A tile's borders are first simplified as 1-D
 * polylines of samples to the bound, by both neighbours alike, then kept
 * as the tile's outline: no crack, no T-junction, every valid sample
 * within the bound.
 * ------------------------------------------------------------------------- */
typedef struct tt_tile {
  /* the tile's samples in the DEM: columns col0..col1, rows row0..row1
   * (inclusive, at least two each way); neighbouring tiles share the
   * column or row where they meet */
  size_t col0, row0, col1, row1;
  size_t dem_width, dem_height;
} tt_tile;

/* The window of the DEM a tile is run on: its samples and one column or
 * row more beyond each side it shares with another tile. */
void tt_tile_window(const tt_tile *tile, size_t *out_col, size_t *out_row,
                    size_t *out_width, size_t *out_height);

/* Refines one tile: window holds the samples tt_tile_window names (its
 * geotransform that of its first sample, the DEM's ground frame, and for
 * a geographic or Web Mercator DEM the whole DEM's ground points of its
 * samples, as tt_gdal_read_grid's WINDOW reads them); opt must have a
 * max error and no point, triangle or percentage budget (any criterion,
 * repair and final optimisation). The piece's vertices keep their ground
 * points, scale factors and convergences (from the window). The
 * piece is a TIN in the DEM's pixel coordinates, with no triangle when the
 * tile has none; its valid_samples counts the tile's samples less the
 * column and row it shares on its right and bottom sides, so the pieces'
 * counts add up to the DEM's. The caller owns *out_piece and frees it with
 * tt_tin_destroy(). */
tt_status tt_tile_run(tt_context *ctx, const tt_grid *window,
                      const tt_tile *tile, const tt_refine_options *opt,
                      tt_tin **out_piece);

/* The same by vertex decimation (tt_decimate_run): the tile's start
 * (every option of opt, but a max error as the only stop condition) keeps
 * its border vertices and no other sample of its shared sides, and no
 * removal, repair or final pass touches them, so the pieces meet as
 * refined ones do. With start greedy:N a tile inserts ceil(N x its cells /
 * the DEM's cells) vertices after its corners, outline and border
 * vertices. */
tt_status tt_tile_decimate(tt_context *ctx, const tt_grid *window,
                           const tt_tile *tile,
                           const tt_decimate_options *opt,
                           tt_tin **out_piece);

/* The error-against-count curve of one tile, for budgets of the whole
 * DEM (the command's -max_points, -max_triangles and -percent in tiles,
 * docs/scale.md): the tile refined as tt_tile_run does with opt (its
 * criterion, repair and threads; its stops ignored), but with its shared
 * sides simplified to no bound (only the tile's corners and the samples
 * next to nodata on them are border vertices), until max_insertions
 * vertices were inserted or every candidate is exact. fn is called before
 * each insertion and once at the end with the tile's vertices and the
 * largest error of its samples off the shared sides: a run to a bound E
 * stops at the first call whose error is <= E. No piece is kept. */
typedef void (*tt_tile_curve_fn)(void *arg, size_t vertices,
                                 double max_error);
tt_status tt_tile_curve(tt_context *ctx, const tt_grid *window,
                        const tt_tile *tile, const tt_refine_options *opt,
                        size_t max_insertions, tt_tile_curve_fn fn,
                        void *arg);

/* Joins pieces into one TIN: create with the DEM's size and geotransform,
 * add every tile's piece in a fixed order (the result depends on the
 * order, never on which tile finished first), finish. Shared border
 * vertices get one id (that of the first piece holding them); the errors
 * and counts are the whole TIN's. The caller owns *out_merger and frees it
 * with tt_tin_merger_destroy(), and owns *out_tin (tt_tin_destroy()). */
typedef struct tt_tin_merger tt_tin_merger;
tt_status tt_tin_merger_create(tt_context *ctx, size_t dem_width,
                               size_t dem_height, const double gt[6],
                               tt_tin_merger **out_merger);
tt_status tt_tin_merger_add(tt_context *ctx, tt_tin_merger *merger,
                            const tt_tin *piece, const tt_tile *tile);
tt_status tt_tin_merger_finish(tt_context *ctx, tt_tin_merger *merger,
                               tt_tin **out_tin);
/* The merged TIN measures areas with the area function of window (any
 * window of the DEM as tt_gdal_read_grid reads it: geodesic areas for a
 * geographic or Web Mercator DEM). Pieces from tt_tile_run bring it
 * themselves; pieces decoded from bytes (tt_tin_piece_decode) do not. */
void tt_tin_merger_set_ground(tt_tin_merger *merger, const tt_grid *window);
void tt_tin_merger_destroy(tt_tin_merger *merger);
/* The vertices and triangles merged so far, and the bytes the merger holds
 * for them (what finishing hands over, and its own tables). */
void tt_tin_merger_size(const tt_tin_merger *merger, size_t *out_vertices,
                        size_t *out_triangles, size_t *out_bytes);

/* A piece as bytes and back (src/tile/piece.c), for cluster runs that make
 * each tile in its own process: every array as it is in memory (one byte
 * order), tag (the caller's: the plan and the tile) and a checksum. A
 * decoded piece merges exactly as the encoded one. The caller frees *out
 * with free() and *out_piece with tt_tin_destroy(). Decoding refuses bytes
 * that are damaged or carry another tag (TT_ERR_DATA). */
tt_status tt_tin_piece_encode(tt_context *ctx, const tt_tin *piece,
                              uint64_t tag, void **out, size_t *out_len);
tt_status tt_tin_piece_decode(tt_context *ctx, const void *bytes, size_t len,
                              uint64_t tag, tt_tin **out_piece);

/* ---------------------------------------------------------------------------
 * Evaluation of any triangle soup (ours or another tool's) against a grid.
 * ------------------------------------------------------------------------- */
typedef struct tt_eval_result {
  tt_error_stats errors;   /* over covered samples; samples = valid */
  size_t triangles;        /* triangles given */
  size_t degenerate;       /* zero-area triangles skipped */
  size_t uncovered;        /* valid samples in no triangle */
  size_t overlapped;       /* valid samples in more than one triangle */
} tt_eval_result;

/* Triangles as 9 doubles each: (col,row,z) of 3 corners in pixel-centre
 * space (sample (c,r) at (c,r)). A sample within 1e-9 pixel of a triangle
 * counts as inside. */
tt_status tt_eval_triangles(tt_context *ctx, const tt_grid *grid,
                            size_t ntriangles, const double *pix_xyz,
                            tt_eval_result *out_result);
/* tt_eval_triangles, and the TIN on the grid: out_heights (width x height
 * doubles, row by row, owned by the caller) receives at every sample
 * within 1e-9 pixel of a triangle the height there of the first triangle
 * (in input order) covering it -- the one its error is measured against,
 * so TIN - DEM is exactly the difference measured -- nodata samples
 * included, and NaN at every sample no triangle covers. */
tt_status tt_eval_triangles_raster(tt_context *ctx, const tt_grid *grid,
                                   size_t ntriangles, const double *pix_xyz,
                                   tt_eval_result *out_result,
                                   double *out_heights);

/* ---------------------------------------------------------------------------
 * Synthetic terrains (SPEC section 4). All are seeded and bit-reproducible.
 * ------------------------------------------------------------------------- */
typedef enum tt_synth_kind {
  TT_SYNTH_FAULT = 0,     /* fault lines, step (rough) or cosine (smooth) */
  TT_SYNTH_DIAMOND_SQUARE,
  TT_SYNTH_SPHERE,
  TT_SYNTH_CYLINDER,
  TT_SYNTH_BUMP
} tt_synth_kind;

typedef enum tt_synth_seeding {
  TT_SEED_NONE = 0, TT_SEED_PEAK, TT_SEED_VALLEY, TT_SEED_HYBRID
} tt_synth_seeding;

typedef struct tt_synth_options {
  tt_synth_kind kind;
  size_t nx, ny;            /* grid size; diamond-square needs 2^n+1 square */
  uint64_t seed;
  /* fault */
  size_t iterations;        /* number of fault lines */
  double displacement;
  double wave_size;         /* > 0: smooth (cosine ramp half-width, cells) */
  /* diamond-square */
  double roughness;         /* amplitude factor per level, 0.7 in the study */
  double amplitude;         /* first-level random amplitude */
  tt_synth_seeding seeding;
} tt_synth_options;

/* Defaults per kind: the study's sizes (fault rough 100x100 displacement 100,
 * diamond-square 257x257 roughness 0.7, sphere/cylinder 41x41 on [0,40]^2,
 * bump 20x30). */
void tt_synth_options_init(tt_synth_options *opt, tt_synth_kind kind);
/* "fault", "diamond_square", "sphere", "cylinder", "bump" */
const char *tt_synth_kind_name(tt_synth_kind kind);
tt_status tt_synth_kind_parse(tt_context *ctx, const char *name,
                              tt_synth_kind *out_kind);
/* The caller owns *out_grid and frees it with tt_grid_destroy(). The grid's
 * geotransform gives the function's own x,y units (e.g. [0,40]^2). */
tt_status tt_synth_generate(tt_context *ctx, const tt_synth_options *opt,
                            tt_grid **out_grid);

#ifdef __cplusplus
}
#endif
#endif /* TERRATIN_H */
