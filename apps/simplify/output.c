/*
 * output.c -- apps/simplify/, the simplify command: the choice of its
 * output, made once for every path. The kind (app_output_kind): a mesh or
 * survey format (2DM, PLY, OBJ, LandXML: -of names it, else OUTPUT's
 * extension) written by tt_mesh_write(), a database that is no file
 * (PG:...), an OGR dataset in a file, and, for a tiled run into a
 * GeoPackage file, the rows streamed as the tiles merge. Then the plan,
 * before any work: a database is opened and checked, a file gets its
 * temporary name (tt_output) and its sidecars, and what stands in its way
 * is refused; and, once the DEM is open, the OGR writer's options and the
 * dry run (ogr_output.c).
 *
 * Invariants: a refusal here costs nothing (the DEM is not read yet); an
 * existing output is never touched here.
 */
#include "simplify.h"

#include <cpl_conv.h>
#include <cpl_string.h>
#include <cpl_vsi.h>

#include <string.h>

tt_status tt__app_output_choose(app_simplify_job *job)
{
  app_run *r = job->r;
  const tt_app_settings *s = job->s;
  /* The mesh and survey formats are written by tt_mesh_write(), not by an
   * OGR driver: -of names them, else OUTPUT's extension (.2dm, .ply, .obj,
   * .xml), before any OGR driver is sought. */
  job->mesh = s->format ? tt_mesh_format_from_name(s->format)
                        : tt_mesh_format_from_path(s->output);
  job->drvname = tt_mesh_format_name(job->mesh);
  if (job->mesh && s->layers != TT_APP_LAYERS_ALL)
    return tt__app_fail(r, TT_APP_EXIT_USAGE, TT_ERR_ARG, NULL,
                        "simplify: -layers is for OGR outputs; %s writes "
                        "the whole mesh", job->drvname);
  if (job->mesh && ((s->lco && s->lco[0]) || (s->dsco && s->dsco[0])))
    return tt__app_fail(r, TT_APP_EXIT_USAGE, TT_ERR_ARG, NULL,
                        "simplify: -lco and -dsco are for OGR drivers; %s "
                        "takes none", job->drvname);
  if (s->obj_local && job->mesh != TT_MESH_OBJ)
    return tt__app_fail(r, TT_APP_EXIT_USAGE, TT_ERR_ARG, NULL,
                        "simplify: -obj_local is for -of OBJ outputs");
  if (job->mesh) {
    job->kind = APP_OUTPUT_MESH;
    return TT_OK;
  }
  job->drv = tt__app_database_driver(r);
  job->kind = job->drv ? APP_OUTPUT_DATABASE : APP_OUTPUT_FILE;
  if (!job->drv)
    job->drv = tt__app_output_driver(r);
  if (!job->drv)
    return r->res->status;
  job->drvname = GDALGetDriverShortName(job->drv);
  return TT_OK;
}

/* With -nln a Shapefile output's files are named otherwise than the plain
 * layer names tt_output checked: those are checked too, before the work
 * (without -overwrite). */
static tt_status check_shapefile_names(app_simplify_job *job)
{
  const tt_app_settings *s = job->s;
  static const char *const names[] = {"triangles.shp", "triangles.dbf",
                                      "vertices.shp", "vertices.dbf",
                                      "run_parameters.dbf"};
  const char *slash = strrchr(s->output, '/');
  /* OUTPUT's folder (CPLSPrintf knows no %.*s) */
  char *dir = CPLStrdup(slash ? s->output : ".");
  if (slash)
    dir[slash - s->output] = '\0';
  tt_status st = TT_OK;
  for (size_t i = 0; i < sizeof names / sizeof names[0] && st == TT_OK;
       i++) {
    VSIStatBufL sb;
    const char *p = CPLSPrintf("%s/%s%s%s", dir,
                               tt_output_layer_prefix(job->outp), s->nln,
                               names[i]);
    if (VSIStatL(p, &sb) == 0)
      st = tt__app_fail(job->r, TT_APP_EXIT_FAILURE, TT_ERR_EXISTS, p,
                        "exists; use -overwrite to replace it");
  }
  CPLFree(dir);
  return st;
}

/* The formats that get QGIS's default style: a layer_styles table
 * (GPKG, PostgreSQL) or a .qml file beside each layer's file. */
static int styled(const char *drvname)
{
  static const char *const names[] = {"GPKG", "PostgreSQL", "ESRI Shapefile",
                                      "FlatGeobuf", "GeoJSON"};
  for (size_t i = 0; i < sizeof names / sizeof names[0]; i++)
    if (tt__app_str_ieq(drvname, names[i]))
      return 1;
  return 0;
}

/* FlatGeobuf and GeoJSON in one file: its style is OUTPUT's name with
 * .qml, written and renamed with it (a FlatGeobuf folder holds its layers'
 * styles itself). */
static int qml_sidecar(const app_simplify_job *job)
{
  return !job->s->nostyle && *CPLGetExtension(job->s->output) &&
         (tt__app_str_ieq(job->drvname, "FlatGeobuf") ||
          tt__app_str_ieq(job->drvname, "GeoJSON"));
}

tt_status tt__app_output_plan(app_simplify_job *job)
{
  app_run *r = job->r;
  const tt_app_settings *s = job->s;
  /* A database is opened and checked now (its tables are made in the
   * write's transaction); it has no temporary name. */
  if (job->kind == APP_OUTPUT_DATABASE) {
    job->dst = tt__app_database_open(r, job->drv, job->shown);
    return job->dst ? TT_OK : r->res->status;
  }
  r->msg.last[0] = '\0';
  tt_status st = tt_output_begin(r->ctx, s->output, job->drvname,
                                 s->overwrite, &job->outp);
  /* 2DM's datasets beside it (OUT_ins_err.dat, ...) are part of it. MDAL
   * reads a dataset file whose name holds "_els" as face values: a name
   * with it would turn the vertex datasets into face ones. */
  if (st == TT_OK && job->mesh == TT_MESH_2DM &&
      strstr(CPLGetFilename(s->output), "_els"))
    return tt__app_fail(r, TT_APP_EXIT_USAGE, TT_ERR_ARG, s->output,
                        "2DM: a name holding \"_els\" would make MDAL read "
                        "the vertex datasets beside it as face values; "
                        "name the output otherwise");
  for (const char *const *sc = tt_mesh_format_sidecars(job->mesh);
       st == TT_OK && *sc; sc++)
    st = tt_output_add_sidecar(r->ctx, job->outp, *sc);
  if (st == TT_OK && qml_sidecar(job))
    st = tt_output_add_sidecar(r->ctx, job->outp, ".qml");
  if (st == TT_OK && !s->overwrite && s->nln[0] &&
      tt__app_str_ieq(job->drvname, "ESRI Shapefile")) {
    tt_status nst = check_shapefile_names(job);
    if (nst != TT_OK)
      return nst;
  }
  if (st == TT_ERR_EXISTS)
    tt__app_fail_exists(r, s->output);
  else if (st != TT_OK)
    tt__app_fail_tt(r, st, s->output);
  return st;
}

tt_status tt__app_output_options(app_simplify_job *job)
{
  app_run *r = job->r;
  const tt_app_settings *s = job->s;
  if (job->kind == APP_OUTPUT_MESH)
    return TT_OK;
  /* Shapefile outputs name their files "<name>_<layer>": the planned
   * prefix comes first, then the user's -nln. */
  char *prefix = CPLStrdup(CPLSPrintf(
      "%s%s", job->outp ? tt_output_layer_prefix(job->outp) : "", s->nln));
  job->wopts = CSLSetNameValue(job->wopts, "NLN_PREFIX", prefix);
  CPLFree(prefix);
  for (size_t i = 0; s->lco[i]; i++)
    job->wopts = CSLAddNameValue(job->wopts, "LCO", s->lco[i]);
  if (s->t_srs)
    job->wopts = CSLSetNameValue(job->wopts, "T_SRS", s->t_srs);
  char list[64];
  job->wopts = CSLSetNameValue(job->wopts, "LAYERS",
                               tt__app_layer_list(s->layers, list,
                                                  sizeof list));
  if (!s->nostyle && styled(job->drvname))
    job->wopts = CSLSetNameValue(job->wopts, "STYLE", "YES");
  int database = job->kind == APP_OUTPUT_DATABASE;
  if (database && s->overwrite)
    job->wopts = CSLSetNameValue(job->wopts, "OVERWRITE", "YES");
  job->dsco = tt__app_output_dsco(job->drvname, s->dsco);
  /* The dry run: a driver that cannot hold the layers is refused before
   * the DEM is read. */
  if (!database) {
    char *auto_t_srs = NULL;
    if (!tt__app_check_ogr_output(r, job->drv, job->src, job->dsco,
                                  job->wopts, &auto_t_srs))
      return r->res->status;
    if (auto_t_srs) {
      job->wopts = CSLSetNameValue(job->wopts, "T_SRS", auto_t_srs);
      job->t_srs_auto = auto_t_srs;
      job->rep.t_srs = auto_t_srs;
      job->rep.t_srs_auto = 1;
    }
  }
  return TT_OK;
}

void tt__app_output_choose_stream(app_simplify_job *job)
{
  /* A GeoPackage file is written as the tiles merge (tiled_stream.c):
   * every method, bound or budget, and frame. The triangles of a
   * geographic or Web Mercator DEM are measured on their pieces' ground
   * points, a decimated TIN's vertices carry their importances, and a
   * budget's passes not kept have their rows dropped (tiled.c). The
   * other formats take the merged TIN, written after the last tile. */
  if (tt__app_tiles_hook.save || job->kind != APP_OUTPUT_FILE ||
      !tt__app_stream_wanted(job->drvname) || !tt__app_stream_possible(job))
    return;
  tt__app_stream_init(&job->so, job);
  job->kind = APP_OUTPUT_STREAM;
  job->rep.streamed = 1;
}

/* The layers the output holds, under their written names (-nln first):
 * the breaklines' beside the triangles when the run had some. */
static char **layer_names(const app_simplify_job *job, const char *prefix,
                          const char *const suffix[4])
{
  static const char *const names[] = {"triangles", "vertices",
                                      "run_parameters", "breaklines"};
  unsigned want = job->s->layers;
  if (job->rep.breakline_segments && (want & 1u))
    want |= 8u;
  char **out = NULL;
  for (unsigned i = 0; i < 4; i++)
    if (want & (1u << i))
      out = CSLAddString(out, CPLSPrintf("%s%s%s%s", prefix, job->s->nln,
                                         names[i], suffix ? suffix[i] : ""));
  return out;
}

/* name added to list as messages show it: any password in it masked (a
 * file named like a connection string, and the names made from it) */
static char **add_shown(char **list, const app_run *r, const char *name)
{
  char buf[TT_APP_MESSAGE_MAX];
  return CSLAddString(list, tt__app_secrets_mask(&r->msg.secrets,
                                                 tt__app_shown(r, name), buf,
                                                 sizeof buf));
}

void tt__app_output_names(const app_simplify_job *job, char ***out_files,
                          char ***out_layers)
{
  const tt_app_settings *s = job->s;
  char **files = NULL, **layers = NULL;
  /* the names as every message shows them: a password never */
  app_run *r = job->r;
  if (job->kind == APP_OUTPUT_DATABASE) {
    files = add_shown(files, r, job->shown);
    layers = layer_names(job, "", NULL);
  } else if (job->kind == APP_OUTPUT_MESH) {
    files = add_shown(files, r, s->output);
    /* the sidecars replace OUTPUT's extension (2DM's datasets; its .prj,
     * last, when the TIN has a CRS) */
    char *stem = CPLStrdup(CPLFormFilename(CPLGetPath(s->output),
                                           CPLGetBasename(s->output), NULL));
    for (const char *const *sc = tt_mesh_format_sidecars(job->mesh); *sc;
         sc++)
      if (job->srs || strcmp(*sc, ".prj") != 0)
        files = add_shown(files, r, CPLSPrintf("%s%s", stem, *sc));
    CPLFree(stem);
  } else if (tt__app_str_ieq(job->drvname, "ESRI Shapefile")) {
    /* files of their own beside OUTPUT: <name>_triangles.shp, ... */
    static const char *const ext[4] = {".shp", ".shp", ".dbf", ".shp"};
    const char *slash = strrchr(s->output, '/');
    char *dir = CPLStrdup(s->output);
    dir[slash ? (size_t)(slash - s->output) + 1 : 0] = '\0';
    char **names = layer_names(
        job, CPLSPrintf("%s%s", dir, tt_output_layer_prefix(job->outp)),
        ext);
    CPLFree(dir);
    for (size_t i = 0; names && names[i]; i++)
      files = add_shown(files, r, names[i]);
    CSLDestroy(names);
  } else {
    VSIStatBufL sb;
    if (VSIStatL(s->output, &sb) == 0 && VSI_ISDIR(sb.st_mode)) {
      /* a folder of a file per layer (FlatGeobuf, MapInfo) */
      char **entries = VSIReadDir(s->output);
      char **mine = layer_names(job, "", NULL);
      for (size_t i = 0; entries && entries[i]; i++)
        for (size_t k = 0; mine && mine[k]; k++)
          if (strncmp(entries[i], mine[k], strlen(mine[k])) == 0 &&
              entries[i][strlen(mine[k])] == '.')
            files = add_shown(files, r,
                              CPLFormFilename(s->output, entries[i], NULL));
      CSLDestroy(entries);
      CSLDestroy(mine);
    } else {
      files = add_shown(files, r, s->output);
      layers = layer_names(job, "", NULL);
    }
  }
  *out_files = files;
  *out_layers = layers;
}
