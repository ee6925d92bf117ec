/*
 * simplify.c -- `terratin simplify INPUT OUTPUT`: open the DEM, read the
 * band into a grid, run the refinement (-method insert) or the decimation
 * (-method decimate), write the TIN's layers under a
 * temporary name and commit it, then print the summary or JSON.
 *
 * Invariants: the input is never written; an existing output is replaced
 * only with -overwrite and only once the new one is complete; a failure or
 * an interruption at any phase leaves nothing behind.
 */
#include "simplify.h"

#include <cpl_conv.h>
#include <cpl_string.h>
#include <cpl_vsi.h>
#include <ogr_api.h>
#include <ogr_srs_api.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <unistd.h>

/* -work_srs and -t_srs: a CRS GDAL understands (usage error otherwise);
 * -work_srs must also be projected. */
static int check_srs(app_run *r, const char *option, const char *value,
                     int projected)
{
  if (!value)
    return 1;
  OGRSpatialReferenceH srs = OSRNewSpatialReference(NULL);
  r->msg.last[0] = '\0';
  int ok = srs && OSRSetFromUserInput(srs, value) == OGRERR_NONE;
  if (!ok)
    tt__app_fail(r, TT_APP_EXIT_USAGE, TT_ERR_ARG, NULL,
             "simplify: %s '%s' is not a CRS GDAL understands%s%s", option,
             value, r->msg.last[0] ? ": " : "", r->msg.last);
  else if (projected && !OSRIsProjected(srs)) {
    tt__app_fail(r, TT_APP_EXIT_USAGE, TT_ERR_ARG, NULL,
             "simplify: %s '%s' is not a projected CRS: the working frame "
             "must be in metres", option, value);
    ok = 0;
  }
  if (srs)
    OSRDestroySpatialReference(srs);
  return ok;
}

/* The decimation options of the command: ro's stops, criterion and
 * passes, and the -start, -importance, -selection, -onepass, -hole. */
static void decimate_options(const tt_app_settings *s,
                             const tt_refine_options *ro,
                             tt_decimate_options *dopt)
{
  tt_decimate_options_init(dopt);
  dopt->max_error = ro->max_error;
  dopt->max_points = ro->max_points;
  dopt->max_triangles = ro->max_triangles;
  dopt->percent = ro->percent;
  dopt->criterion = ro->criterion;
  dopt->optimize = ro->optimize;
  dopt->anneal = ro->anneal;
  dopt->repair = ro->repair;
  dopt->start = s->start;
  dopt->start_points = s->start_points;
  dopt->importance = s->importance;
  dopt->selection = s->selection;
  dopt->onepass = s->onepass;
  dopt->hole = s->hole;
  dopt->progress = ro->progress;
  dopt->progress_arg = ro->progress_arg;
  dopt->threads = ro->threads;
}

/* The run_parameters fields of a run (simplify's report so far): created
 * and start_name (48 bytes) hold strings the fields point to; allf has
 * room for TT__APP_RUN_FIELDS. Returns how many are used. */
size_t tt__app_simplify_fields(app_run *r, const app_simplify_report *rep,
                               const tt_refine_options *ro,
                               const tt_raster_info *info,
                               const char *created, char *start_name,
                               tt_run_field *allf)
{
  const tt_app_settings *s = r->s;
  const tt_error_stats *e = &rep->sum.errors;
  const tt_run_field fields[] = {
      {"input", TT_FIELD_STRING, s->input, 0, 0},
      {"band", TT_FIELD_INTEGER, NULL, s->band, 0},
      {"driver", TT_FIELD_STRING, info->driver ? info->driver : "", 0, 0},
      {"method", TT_FIELD_STRING, s->decimate ? "decimate" : "insert", 0,
       0},
      {"criterion", TT_FIELD_STRING, tt_criterion_name(ro->criterion), 0, 0},
      {"repair", TT_FIELD_STRING,
       tt_repair_name(tt_repair_resolve(ro->repair, ro->criterion)), 0, 0},
      {"optimize", TT_FIELD_STRING,
       tt_optimize_name(tt_optimize_resolve(ro->optimize, ro->criterion,
                                            ro->repair)), 0, 0},
      {"max_error", TT_FIELD_REAL, NULL, 0, ro->max_error},
      {"max_points", TT_FIELD_INTEGER, NULL, (int64_t)ro->max_points, 0},
      {"max_tris", TT_FIELD_INTEGER, NULL, (int64_t)ro->max_triangles, 0},
      {"percent", TT_FIELD_REAL, NULL, 0, ro->percent},
      {"stop", TT_FIELD_STRING, tt_stop_reason_name(rep->sum.stop_reason), 0,
       0},
      {"vertices", TT_FIELD_INTEGER, NULL, (int64_t)rep->sum.vertices, 0},
      {"triangles", TT_FIELD_INTEGER, NULL, (int64_t)rep->sum.triangles, 0},
      {"cells", TT_FIELD_INTEGER, NULL, (int64_t)rep->cells, 0},
      {"valid", TT_FIELD_INTEGER, NULL, (int64_t)rep->valid, 0},
      {"lone", TT_FIELD_INTEGER, NULL,
       (int64_t)(e->samples - e->covered), 0},
      {"pieces", TT_FIELD_INTEGER, NULL, (int64_t)rep->sum.components, 0},
      {"ach_max", TT_FIELD_REAL, NULL, 0, e->max_error},
      {"ach_rmse", TT_FIELD_REAL, NULL, 0, e->rmse},
      {"ach_mean", TT_FIELD_REAL, NULL, 0, e->mean_abs},
      {"ach_l2", TT_FIELD_REAL, NULL, 0, e->l2},
      {"z_unit", TT_FIELD_STRING, info->z_unit ? info->z_unit : "", 0, 0},
      {"z_unit_in", TT_FIELD_STRING,
       info->z_unit_declared ? info->z_unit_declared : "", 0, 0},
      {"z_factor", TT_FIELD_REAL, NULL, 0, info->z_unit_factor *
                                               info->z_factor},
      {"pixel_is", TT_FIELD_STRING,
       info->area_or_point ? info->area_or_point : "", 0, 0},
      {"crs", TT_FIELD_STRING, info->crs_name ? info->crs_name : "", 0, 0},
      {"out_crs", TT_FIELD_STRING, s->t_srs ? s->t_srs : "", 0, 0},
      {"frame", TT_FIELD_STRING, info->frame_name ? info->frame_name : "", 0,
       0},
      {"scale_err", TT_FIELD_REAL, NULL, 0, info->frame_scale_error},
      {"version", TT_FIELD_STRING, tt_version(), 0, 0},
      {"t_read", TT_FIELD_REAL, NULL, 0, rep->t_read},
      {"t_simplify", TT_FIELD_REAL, NULL, 0, rep->t_simplify},
      {"t_mesh", TT_FIELD_REAL, NULL, 0, rep->sum.seconds_mesh},
      {"t_stats", TT_FIELD_REAL, NULL, 0, rep->sum.seconds_statistics},
      {"created", TT_FIELD_STRING, created, 0, 0},
  };
  /* Decimation adds what it ran with: start, importance, selection, hole
   * rule (resolved), rounds, and the vertex counts. */
    snprintf(start_name, 48, "greedy:%zu", s->start_points);
  tt_importance imp_used = s->importance != TT_IMPORTANCE_AUTO ? s->importance
                           : ro->max_error >= 0 ? TT_IMPORTANCE_ERROR
                                               : TT_IMPORTANCE_HDH;
  tt_hole hole_used = s->hole != TT_HOLE_AUTO ? s->hole
                      : ro->criterion == TT_CRITERION_DELAUNAY
                          ? TT_HOLE_CIRCUMRADIUS
                          : TT_HOLE_MINANGLE;
  const tt_run_field dfields[] = {
      {"start", TT_FIELD_STRING,
       s->start == TT_DSTART_GREEDY_N ? start_name
                                      : tt_decimate_start_name(s->start),
       0, 0},
      {"importance", TT_FIELD_STRING, tt_importance_name(imp_used), 0, 0},
      {"selection", TT_FIELD_STRING,
       s->selection == TT_SELECTION_SEQUENTIAL ? "sequential"
       : s->onepass                           ? "independent onepass"
                                              : "independent multipass",
       0, 0},
      {"hole", TT_FIELD_STRING, tt_hole_name(hole_used), 0, 0},
      {"rounds", TT_FIELD_INTEGER, NULL, (int64_t)rep->sum.rounds, 0},
      {"start_vtx", TT_FIELD_INTEGER, NULL, (int64_t)rep->sum.start_vertices,
       0},
      {"removed", TT_FIELD_INTEGER, NULL, (int64_t)rep->sum.removed_vertices,
       0},
      {"refused", TT_FIELD_INTEGER, NULL, (int64_t)rep->sum.refused_bound, 0},
  };
  /* A tiled run adds its tiling (docs/scale.md). */
  const tt_run_field tfields[] = {
      {"tile_size", TT_FIELD_INTEGER, NULL, (int64_t)rep->tile_size, 0},
      {"tiles", TT_FIELD_INTEGER, NULL, (int64_t)rep->tiles, 0},
      {"tile_auto", TT_FIELD_INTEGER, NULL, rep->auto_tiled, 0},
  };
  enum { NF = sizeof fields / sizeof fields[0],
         ND = sizeof dfields / sizeof dfields[0],
         NT = sizeof tfields / sizeof tfields[0] };
  _Static_assert(NF + ND + NT <= TT__APP_RUN_FIELDS, "run_parameters");
  memcpy(allf, fields, sizeof fields);
  memcpy(allf + NF, dfields, sizeof dfields);
  size_t nallf = NF + (s->decimate ? ND : 0);
  if (rep->tiles) {
    memcpy(allf + nallf, tfields, sizeof tfields);
    nallf += NT;
  }
  return nallf;
}

tt_status tt__app_simplify(app_run *r)
{
  const tt_app_settings *s = r->s;
  tt_status st = TT_OK;
  tt_output *outp = NULL;
  GDALDatasetH src = NULL, dst = NULL;
  GDALRasterBandH band = NULL;
  tt_grid *grid = NULL;
  tt_raster_info *info = NULL;
  tt_tin *tin = NULL;
  OGRSpatialReferenceH srs = NULL;
  char **wopts = NULL, **dsco = NULL;
  app_simplify_report rep;
  tt_refine_options ro;
  tt_decimate_options dopt;
  size_t valid = 0;
  memset(&rep, 0, sizeof rep);
  tt_decimate_options_init(&dopt);
  tt_app_stream so; /* a tiled GeoPackage built as tiles merge */
  memset(&so, 0, sizeof so);
  int streamed = 0;

  if (tt__app_same_file(s->input, s->output))
    return tt__app_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_ARG, s->output,
                    "is the input raster; refusing to replace it");
  if (!check_srs(r, "-work_srs", s->work_srs, 1) ||
      !check_srs(r, "-t_srs", s->t_srs, 0))
    return r->res->status;
  /* The mesh and survey formats (2DM, PLY, OBJ, LandXML) are written by
   * tt_mesh_write(), not by an OGR driver: -of names them, else OUTPUT's
   * extension (.2dm, .ply, .obj, .xml), before any OGR driver is sought. */
  tt_mesh_format mesh = s->format ? tt_mesh_format_from_name(s->format)
                                  : tt_mesh_format_from_path(s->output);
  GDALDriverH drv = NULL;
  const char *drvname = tt_mesh_format_name(mesh);
  int database = 0; /* a datasource that is no file: PG:... */
  char shown[TT_APP_MESSAGE_MAX]; /* OUTPUT without its password */
  tt__app_mask_password(s->output, shown, sizeof shown);
  if (mesh && s->layers != TT_APP_LAYERS_ALL)
    return tt__app_fail(r, TT_APP_EXIT_USAGE, TT_ERR_ARG, NULL,
                        "simplify: -layers is for OGR outputs; %s writes "
                        "the whole mesh", drvname);
  if (mesh && ((s->lco && s->lco[0]) || (s->dsco && s->dsco[0])))
    return tt__app_fail(r, TT_APP_EXIT_USAGE, TT_ERR_ARG, NULL,
                        "simplify: -lco and -dsco are for OGR drivers; %s "
                        "takes none", drvname);
  if (s->obj_local && mesh != TT_MESH_OBJ)
    return tt__app_fail(r, TT_APP_EXIT_USAGE, TT_ERR_ARG, NULL,
                        "simplify: -obj_local is for -of OBJ outputs");
  if (!mesh) {
    drv = tt__app_database_driver(r);
    database = drv != NULL;
    if (!drv)
      drv = tt__app_output_driver(r);
    if (!drv)
      return r->res->status;
    drvname = GDALGetDriverShortName(drv);
  }

  /* A database is opened and checked now (its tables are made in the
   * write's transaction); it has no temporary name. */
  if (database) {
    dst = tt__app_database_open(r, drv, shown);
    if (!dst)
      return r->res->status;
    goto planned;
  }
  /* Plan the output first: a refusal costs nothing yet. */
  r->msg.last[0] = '\0';
  st = tt_output_begin(r->ctx, s->output, drvname, s->overwrite, &outp);
  /* 2DM's datasets beside it (OUT_ins_err.dat, ...) are part of it. MDAL
   * reads a dataset file whose name holds "_els" as face values: a name
   * with it would turn the vertex datasets into face ones. */
  if (st == TT_OK && mesh == TT_MESH_2DM &&
      strstr(CPLGetFilename(s->output), "_els")) {
    st = tt__app_fail(r, TT_APP_EXIT_USAGE, TT_ERR_ARG, s->output,
                      "2DM: a name holding \"_els\" would make MDAL read "
                      "the vertex datasets beside it as face values; "
                      "name the output otherwise");
    goto done;
  }
  for (const char *const *sc = tt_mesh_format_sidecars(mesh);
       st == TT_OK && *sc; sc++)
    st = tt_output_add_sidecar(r->ctx, outp, *sc);
  if (st == TT_OK && !s->overwrite && s->nln[0] &&
      tt__app_str_ieq(drvname, "ESRI Shapefile")) {
    /* tt_output checked the files of the plain layer names; with -nln the
     * files are named otherwise: check those too, before the work. */
    static const char *const names[] = {"triangles.shp", "triangles.dbf",
                                        "vertices.shp", "vertices.dbf",
                                        "run_parameters.dbf"};
    const char *slash = strrchr(s->output, '/');
    int dirlen = slash ? (int)(slash - s->output) : 1;
    const char *dir = slash ? s->output : ".";
    for (size_t i = 0; i < sizeof names / sizeof names[0]; i++) {
      VSIStatBufL sb;
      const char *p = CPLSPrintf("%.*s/%s%s%s", dirlen, dir,
                                 tt_output_layer_prefix(outp), s->nln,
                                 names[i]);
      if (VSIStatL(p, &sb) == 0) {
        st = tt__app_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_EXISTS, p,
                      "exists; use -overwrite to replace it");
        goto done;
      }
    }
  }
  if (st == TT_ERR_EXISTS) {
    tt__app_fail_exists(r, s->output);
    goto done;
  }
  if (st != TT_OK) {
    tt__app_fail_tt(r, st, s->output);
    goto done;
  }

planned:;
  /* The memory the run may hold: -max_memory, else what the system allows,
   * asked before the DEM is read (the heights count against it). */
  const char *mem_source = "-max_memory";
  size_t mem_limit = s->max_memory ? s->max_memory
                                   : tt_memory_limit(&mem_source);

  /* Decimation does not count its memory as it goes (its start holds a
   * triangle per half sample): an explicit limit would be a promise it
   * cannot keep. Refused before anything is read. */
  if (s->decimate && s->max_memory) {
    st = tt__app_fail(r, TT_APP_EXIT_USAGE, TT_ERR_ARG, NULL,
                      "simplify: -max_memory bounds -method insert only; "
                      "decimation does not count its memory yet");
    goto done;
  }

  /* Read: 0 - 10%. */
  tt__app_phase_set(&r->prog, 0.0, 0.10);
  src = tt__app_open_raster(r, s->input, s->band, &band);
  if (!src) {
    st = r->res->status;
    goto done;
  }
  /* Every file the input is read from (the container of a /vsizip/ or
   * GPKG: name, VRT sources, sidecars) is out of the output's reach. */
  st = outp ? tt_output_protect_dataset(r->ctx, outp, src, s->input)
              : TT_OK;
  if (st != TT_OK) {
    tt__app_fail_tt(r, st, s->output);
    goto done;
  }
  /* The writer's options, and its dry run: a driver that cannot hold the
   * layers is refused before the DEM is read. */
  if (!mesh) {
    /* Shapefile outputs name their files "<name>_<layer>": the planned
     * prefix comes first, then the user's -nln. */
    char *prefix = CPLStrdup(CPLSPrintf(
        "%s%s", outp ? tt_output_layer_prefix(outp) : "", s->nln));
    wopts = CSLSetNameValue(wopts, "NLN_PREFIX", prefix);
    CPLFree(prefix);
    for (size_t i = 0; s->lco[i]; i++)
      wopts = CSLAddNameValue(wopts, "LCO", s->lco[i]);
    if (s->t_srs)
      wopts = CSLSetNameValue(wopts, "T_SRS", s->t_srs);
    char list[64];
    wopts = CSLSetNameValue(wopts, "LAYERS",
                            tt__app_layer_list(s->layers, list, sizeof list));
    if (!s->nostyle && tt__app_str_ieq(drvname, "GPKG"))
      wopts = CSLSetNameValue(wopts, "STYLE", "YES");
    if (database && s->overwrite)
      wopts = CSLSetNameValue(wopts, "OVERWRITE", "YES");
    dsco = tt__app_output_dsco(drvname, s->dsco);
    if (!database && !tt__app_check_ogr_output(r, drv, src, dsco, wopts)) {
      st = r->res->status;
      goto done;
    }
  }
  if (!tt__app_continue(r, 0.0)) {
    st = tt__app_fail_tt(r, TT_ERR_INTERRUPTED, s->output);
    goto done;
  }
  /* Tiles (tiled.c, docs/scale.md): asked for, or because the run (about
   * 8 bytes a sample) would not fit -max_memory (insertion only:
   * decimation refuses -max_memory); a budget becomes a bound. Without -max_memory a DEM past the system's limit is refused as
   * before (the message names the limit): tiling a huge raster for
   * minutes is for the user to ask. */
  size_t tile = s->tile_size;
  size_t dem_w = (size_t)GDALGetRasterBandXSize(band);
  size_t dem_h = (size_t)GDALGetRasterBandYSize(band);
  size_t cells = dem_w * dem_h;
  int threads_asked = tt__app_threads(r);
  int nth = threads_asked > 0 ? threads_asked
                              : (int)sysconf(_SC_NPROCESSORS_ONLN);
  if (nth < 1)
    nth = 1;
  int ground = tt__app_ground_points(band);
  if (!tile && !s->decimate && s->max_memory &&
      dem_w > 2 && dem_h > 2 && cells > mem_limit / 8) {
    /* about 8 bytes a sample untiled: tiles of 1024 (a multiple of the
     * block size), halved until those in flight hold half the limit;
     * when even tiles of 64 do not fit, the untiled run says why */
    int bw = 0, bh = 0;
    GDALGetBlockSize(band, &bw, &bh);
    size_t want = 1024;
    if (bw > 1 && bw <= 4096 && bw == bh)
      want = ((1024 + (size_t)bw - 1) / (size_t)bw) * (size_t)bw;
    while (want > 64 &&
           tt__app_tile_bytes(want, dem_w, dem_h, nth, ground) > mem_limit / 2)
      want /= 2;
    if (tt__app_tile_bytes(want, dem_w, dem_h, nth, ground) <= mem_limit / 2) {
      tile = want;
      rep.auto_tiled = 1;
    }
  }
  if (tile) {
    tt_refine_options_init(&ro);
    ro.max_error = s->max_error;
    /* a budget becomes the bound whose tiles meet it (tiled_budget.c) */
    ro.max_points = s->max_points;
    ro.max_triangles = s->max_triangles;
    ro.percent = s->percent;
    ro.criterion = s->criterion;
    ro.optimize = s->optimize;
    ro.anneal = s->anneal;
    ro.repair = s->repair;
    ro.threads = threads_asked;
    rep.ropt = &ro;
    rep.tile_size = tile;
    rep.tile_bytes = tt__app_tile_bytes(tile, dem_w, dem_h, nth, ground);
    if (s->decimate) /* a start of every sample: 48 bytes a sample more */
      rep.tile_bytes = rep.tile_bytes / (ground ? 64 : 32) * (ground ? 112 : 80);
    if (s->max_memory && rep.tile_bytes > s->max_memory) {
      st = tt__app_fail(r, TT_APP_EXIT_USAGE, TT_ERR_ARG, NULL,
                        "simplify: tiles of %zu cells on %d threads hold up to "
                        "about %zu MiB, more than -max_memory (%zu MiB): use "
                        "a smaller -tile_size or fewer -threads", tile, nth,
                        rep.tile_bytes >> 20, s->max_memory >> 20);
      goto done;
    }
    tt__app_phase_set(&r->prog, 0.0, 0.85);
    double t_tiles = tt__app_now();
    if (s->decimate) {
      decimate_options(s, &ro, &dopt);
      rep.dopt = &dopt;
    }
    /* A GeoPackage file is written as the tiles merge (tiled_stream.c):
     * every method, bound or budget, and frame. The triangles of a
     * geographic or Web Mercator DEM are measured on their pieces' ground
     * points, a decimated TIN's vertices carry their importances, and a
     * budget's passes not kept have their rows dropped (tiled.c). The
     * other formats take the merged TIN, written after the last tile. */
    if (!tt__app_tiles_hook.save &&
        tt__app_stream_wanted(drvname, database, mesh != TT_MESH_NONE)) {
      tt__app_stream_init(&so, r, outp, drv, dsco, &wopts, &srs, &rep, &ro);
      r->sink = &so.sink;
      streamed = 1;
      rep.streamed = 1;
    }
    st = tt__app_simplify_tiled(r, band, s->input, tile, &ro,
                                s->decimate ? &dopt : NULL,
                                &rep.default_error, &tin, &info, &valid,
                                &rep.zmin, &rep.zmax, &rep.tiles,
                                &rep.tile_threads, &rep.budget_passes);
    r->sink = NULL;
    /* no TIN: one tile of `tiles run`, saved, or streamed */
    if (st != TT_OK || (!tin && !streamed))
      goto done;
    GDALClose(src);
    src = NULL;
    rep.info = info;
    rep.driver = drvname;
    rep.cells = cells;
    rep.valid = valid;
    rep.t_simplify = tt__app_now() - t_tiles;
    if (streamed)
      rep.sum = so.sink.sum;
    else
      tt_tin_get_summary(tin, &rep.sum);
    goto write;
  }
  st = tt__app_read_dem(r, band, s->input, tt__app_phase_fn, &r->prog, &grid,
                        &info, &valid);
  if (st != TT_OK)
    goto done;
  GDALClose(src);
  src = NULL;
  rep.info = info;
  rep.driver = drvname;
  rep.cells = tt_grid_width(grid) * tt_grid_height(grid);
  rep.valid = valid;
  tt__app_height_range(grid, &rep.zmin, &rep.zmax);
  rep.t_read = tt__app_now() - r->t0;

  /* Simplify: 10 - 85%. */
  tt_refine_options_init(&ro);
  ro.max_error = s->max_error;
  ro.max_points = s->max_points;
  ro.max_triangles = s->max_triangles;
  ro.percent = s->percent;
  ro.criterion = s->criterion;
  ro.optimize = s->optimize;
  ro.anneal = s->anneal;
  ro.repair = s->repair;
  ro.threads = threads_asked;
  ro.max_memory = mem_limit == SIZE_MAX ? 0 : mem_limit;
  if (s->max_error < 0 && !s->max_points && !s->max_triangles &&
      !(s->percent > 0)) {
    ro.max_error = 0.005 * (rep.zmax - rep.zmin);
    rep.default_error = 1;
  }
  tt__app_phase_set(&r->prog, 0.10, 0.85);
  ro.progress = tt__app_phase_fn;
  ro.progress_arg = &r->prog;
  rep.ropt = &ro;
  if (s->decimate) {
    decimate_options(s, &ro, &dopt);
    rep.dopt = &dopt;
  }
  double t_run = tt__app_now();
  st = s->decimate ? tt_decimate_run(r->ctx, grid, &dopt, &tin)
                   : tt_refine_run(r->ctx, grid, &ro, &tin);
  if (st == TT_ERR_NOMEM && ro.max_memory &&
      strstr(tt_context_errmsg(r->ctx), "memory limit")) {
    tt__app_fail(r, TT_APP_EXIT_FAILURE, st, s->input, "%s (%s); nothing "
                 "written", tt_context_errmsg(r->ctx), mem_source);
    goto done;
  }
  if (st == TT_ERR_LIMIT) { /* a budget below the start's vertices */
    tt__app_fail(r, TT_APP_EXIT_USAGE, st, s->input, "%s",
                 tt_context_errmsg(r->ctx));
    goto done;
  }
  if (st != TT_OK) {
    tt__app_fail_tt(r, st, st == TT_ERR_INTERRUPTED ? s->output : s->input);
    goto done;
  }
  rep.t_simplify = tt__app_now() - t_run;
  tt_tin_get_summary(tin, &rep.sum);
  /* The TIN keeps what it needs; the grid can go before the write. */
  tt_grid_destroy(grid);
  grid = NULL;

  /* Write: 85 - 100%. */
write:;
  double t = tt__app_now();
  tt__app_phase_set(&r->prog, 0.85, 0.99);
  if (!tt__app_continue(r, 0.85)) {
    st = tt__app_fail_tt(r, TT_ERR_INTERRUPTED, s->output);
    goto done;
  }
  if (streamed) {
    /* the rows are in: the R-trees, extents, counts, the run's values */
    char created[32], start_name[48];
    tt__app_iso8601_utc(created, sizeof created);
    tt_run_field allf[TT__APP_RUN_FIELDS];
    size_t nallf = tt__app_simplify_fields(r, &rep, &ro, info, created,
                                           start_name, allf);
    st = tt__app_stream_finish(&so, allf, nallf);
    if (st == TT_ERR_INTERRUPTED || st == TT_ERR_NOMEM) {
      tt__app_fail_tt(r, st, s->output);
      goto done;
    }
    if (st != TT_OK) {
      tt__app_fail(r, TT_APP_EXIT_FAILURE, st, s->output, "%s",
                   tt__app_why(r, st, tt_output_temp_path(outp)));
      goto done;
    }
    goto commit;
  }
  if (info->crs_wkt && *info->crs_wkt) {
    srs = OSRNewSpatialReference(info->crs_wkt);
    if (srs)
      OSRSetAxisMappingStrategy(srs, OAMS_TRADITIONAL_GIS_ORDER);
    else
      tt__app_warn(&r->msg,
                   "%s: the raster's CRS could not be parsed; the layers "
                   "have none",
                   s->input);
  }
  if (mesh) {
    /* One file, no layers: the mesh named after OUTPUT's base name. */
    r->msg.last[0] = '\0';
    char *mname = CPLStrdup(CPLGetBasename(s->output));
    st = tt_mesh_write(r->ctx, tt_output_temp_path(outp), mesh, mname, tin,
                       srs, s->t_srs, s->obj_local, tt__app_phase_fn,
                       &r->prog);
    CPLFree(mname);
    if (st == TT_ERR_INTERRUPTED || st == TT_ERR_NOMEM) {
      tt__app_fail_tt(r, st, s->output);
      goto done;
    }
    if (st != TT_OK) {
      tt__app_fail(r, TT_APP_EXIT_FAILURE, st, s->output, "%s",
                   tt__app_why(r, st, tt_output_temp_path(outp)));
      goto done;
    }
    goto commit;
  }
  r->msg.last[0] = '\0';
  /* Without -dsco there is nothing to validate (our own defaults are
   * valid), and GDAL 3.6's GPKG driver builds its creation option list for
   * the check by parsing its tiling schemes through PROJ: 38 M
   * instructions, 2 % of a Crater Lake run. */
  /* A GeoPackage in the temporary file: its rollback journal in memory
   * while GDAL makes the layers too (a file created and deleted for each
   * of GDAL's transactions otherwise); unset after the close. */
  const int gpkg_temp = !database && tt__app_str_ieq(drvname, "GPKG");
  if (gpkg_temp)
    CPLSetThreadLocalConfigOption("OGR_SQLITE_JOURNAL", "MEMORY");
  if (!database) {
    int validate = s->dsco && s->dsco[0];
    if (!validate)
      CPLSetThreadLocalConfigOption("GDAL_VALIDATE_CREATION_OPTIONS", "NO");
    dst = GDALCreate(drv, tt_output_temp_path(outp), 0, 0, 0, GDT_Unknown,
                     (CSLConstList)dsco);
    if (!validate)
      CPLSetThreadLocalConfigOption("GDAL_VALIDATE_CREATION_OPTIONS", NULL);
  }
  if (!dst) {
    st = tt__app_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_IO, s->output,
                  "cannot create %s dataset: %s", drvname,
                  r->msg.last[0] ? r->msg.last : "unknown reason");
    goto done;
  }

  char created[32], start_name[48];
  tt__app_iso8601_utc(created, sizeof created);
  tt_run_field allf[TT__APP_RUN_FIELDS];
  size_t nallf = tt__app_simplify_fields(r, &rep, &ro, info, created,
                                         start_name, allf);
  /* GPKG: the layers through OGR, then their rows and R-trees straight
   * into the closed file by tt_gpkg_write_rows() (OGR writes a feature at a
   * time and GDAL 3.6 inserts R-tree entries one by one). */
  int direct_rows = tt__app_str_ieq(drvname, "GPKG");
  if (direct_rows) {
    wopts = CSLSetNameValue(wopts, "ROWS", "DEFERRED");
    /* a temporary file: removed on failure, renamed only when complete,
     * so the journal can stay in memory and the big tables can be written
     * as database pages with SQLite closed (gpkg_rows.c) */
    wopts = CSLSetNameValue(wopts, "JOURNAL", "MEMORY");
    wopts = CSLSetNameValue(wopts, "PAGES", "YES");
    if (ro.threads > 0) /* -threads 1: no thread making the rows either */
      wopts = CSLSetNameValue(wopts, "THREADS",
                              CPLSPrintf("%d", ro.threads));
    tt__app_phase_set(&r->prog, 0.85, 0.86);
  }
  /* GDAL's LIBKML writer takes time growing as n^2.7 with the features
   * (GDAL 3.6, Jacksboro: 1,715 features 54 s, 3,586 features 248 s). */
  size_t nfeatures = rep.sum.vertices + rep.sum.triangles;
  if (tt__app_str_ieq(drvname, "LIBKML") && nfeatures > 1000)
    tt__app_warn(&r->msg, "%s: LIBKML writes %zu features slowly (time "
                 "grows as n^2.7 in GDAL: about a minute for 1,700, four "
                 "for 3,600); GPKG writes them in a second",
                 s->output, nfeatures);
  r->msg.last[0] = '\0';
  st = tt_ogr_write_tin(r->ctx, dst, tin, srs, allf, nallf, wopts,
                        tt__app_phase_fn, &r->prog);
  if (st != TT_OK) {
    tt__app_fail_write(r, st, shown, tt_output_temp_path(outp), NULL);
    goto done;
  }
  if (database) {
    /* committed: the tables are in place */
    GDALClose(dst);
    dst = NULL;
    goto written;
  }
  /* Around the close, which may flush for long (a stop during it is seen
   * by the watchdog of terratin.c, which removes the temporary files). */
  if (!tt__app_continue(r, r->prog.hi)) {
    st = tt__app_fail_tt(r, TT_ERR_INTERRUPTED, s->output);
    goto done;
  }
  unsigned failures = r->msg.failures;
  GDALClose(dst);
  dst = NULL;
  if (gpkg_temp)
    CPLSetThreadLocalConfigOption("OGR_SQLITE_JOURNAL", NULL);
  if (!tt__app_continue(r, r->prog.hi)) {
    st = tt__app_fail_tt(r, TT_ERR_INTERRUPTED, s->output);
    goto done;
  }
  if (r->msg.failures != failures) {
    st = tt__app_fail_write(r, TT_ERR_IO, s->output,
                            tt_output_temp_path(outp), "error while closing");
    goto done;
  }
  if (direct_rows) {
    tt__app_phase_set(&r->prog, 0.86, 0.99);
    st = tt_gpkg_write_rows(r->ctx, tt_output_temp_path(outp), tin, srs,
                            wopts, tt__app_phase_fn, &r->prog);
    if (st == TT_ERR_INTERRUPTED || st == TT_ERR_NOMEM) {
      tt__app_fail_tt(r, st, s->output);
      goto done;
    }
    if (st != TT_OK) {
      tt__app_fail(r, TT_APP_EXIT_FAILURE, st, s->output, "%s",
                   tt__app_why(r, st, tt_output_temp_path(outp)));
      goto done;
    }
  }
commit:
  if (!tt__app_continue(r, 0.99)) {
    st = tt__app_fail_tt(r, TT_ERR_INTERRUPTED, s->output);
    goto done;
  }
  st = tt_output_commit(r->ctx, outp);
  if (st == TT_ERR_EXISTS) {
    tt__app_fail_exists(r, s->output); /* it appeared while we worked */
    goto done;
  }
  if (st != TT_OK) {
    tt__app_fail_tt(r, st, s->output);
    goto done;
  }
written:
  rep.t_write = tt__app_now() - t;
  rep.t_total = tt__app_now() - r->t0;
  tt__app_continue(r, 1.0);

  if (s->json)
    tt__app_print_simplify_json(r, &rep);
  else if (!s->quiet)
    tt__app_print_simplify_summary(r, &rep);
  fflush(r->out);

done:
  if (dst)
    GDALClose(dst);
  CPLSetThreadLocalConfigOption("OGR_SQLITE_JOURNAL", NULL);
  if (src)
    GDALClose(src);
  tt__app_stream_close(&so); /* an unfinished write: before the removal */
  tt_output_destroy(outp); /* removes the temporary files unless committed */
  if (srs)
    OSRDestroySpatialReference(srs);
  CSLDestroy(wopts);
  CSLDestroy(dsco);
  tt_tin_destroy(tin);
  tt_grid_destroy(grid);
  tt_raster_info_destroy(info);
  return st;
}
