/*
 * ogr_output.c -- apps/simplify/, the simplify command: what it checks
 * about an OGR output before any work (output.c asks), and the outputs
 * that are no file.
 *
 *  - The dry run: tt_ogr_write_tin() itself, with the same driver, layers
 *    (-layers), -dsco, -lco and -t_srs, writes a TIN of two triangles into
 *    a dataset under /vsimem/ right after the DEM is opened and before it
 *    is read. A driver that cannot hold the layers asked for (GeoJSON and
 *    FlatGeobuf files hold one, DXF one of entities, GPX no polygons and no
 *    table without geometry, MapInfo's .tab one) is thus refused in a
 *    fraction of a second instead of after the whole run, with the way out:
 *    the -layers that the driver takes (each layer is then tried alone) or,
 *    for a format that writes a folder of files when OUTPUT has no
 *    extension, that form. What the drivers' metadata says is not enough:
 *    DXF and GPX claim several layers. A driver that cannot create a
 *    dataset in memory gets its dry run in a folder of the system's
 *    temporary directory; one that can create none is refused.
 *  - The read-back (ogr_readback.c): what the dry run wrote is read back
 *    and every x, y and z compared with the TIN written; a format that
 *    changes them is refused, naming what changed, and one that holds
 *    longitude/latitude only (GPX) is written in that CRS (the summary
 *    says so).
 *  - Databases (PostgreSQL through "PG:..."; any driver that writes no file
 *    and holds transactions): the datasource is opened before the work,
 *    its layers of our names refused without -overwrite, and the TIN is
 *    written in one transaction with the tables made inside it, so that a
 *    failure, an interruption or the end of the process leaves no table and
 *    -overwrite replaces the old tables only at the commit. A connection
 *    string's password never appears in a message.
 */
#include "simplify.h"

#include <cpl_conv.h>
#include <cpl_string.h>
#include <cpl_vsi.h>
#include <ogr_api.h>
#include <ogr_srs_api.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

/* The representative run_parameters of the dry run: one field of each
 * type. */
static const tt_run_field probe_fields[] = {
    {"input", TT_FIELD_STRING, "dem.tif", 0, 0},
    {"band", TT_FIELD_INTEGER, NULL, 1, 0},
    {"max_error", TT_FIELD_REAL, NULL, 0, 1.5},
};

/* A two-triangle TIN on the DEM's first 2 x 2 samples (its geotransform,
 * its origin moved by an irrational share of a pixel so that the
 * coordinates have every digit), for the dry run: heights that use every
 * bit of a float, so that a format that rounds them shows it. NULL when
 * the engine cannot make it. */
static tt_tin *probe_tin(tt_context *ctx, const double dem_gt[6])
{
  static const float z[4] = {2602.37f, 2578.13f, 2597.91f, -12.3457f};
  double gt[6];
  memcpy(gt, dem_gt, sizeof gt);
  gt[0] += 0.3183098861837907 * gt[1];
  gt[3] += 0.2718281828459045 * gt[5];
  tt_grid *grid = NULL;
  tt_tin *tin = NULL;
  tt_refine_options ro;
  tt_refine_options_init(&ro);
  ro.max_error = 0;
  if (tt_grid_create_from_floats(ctx, 2, 2, z, &grid) == TT_OK &&
      tt_grid_set_geotransform(ctx, grid, gt) == TT_OK)
    tt_refine_run(ctx, grid, &ro, &tin);
  tt_grid_destroy(grid);
  return tin;
}

typedef struct probe {
  GDALDriverH drv;
  const char *ext;        /* OUTPUT's extension with its dot, or "" */
  char **dsco, **wopts;   /* wopts without LAYERS */
  tt_tin *tin;
  OGRSpatialReferenceH srs;
  char why[TT_APP_MESSAGE_MAX];
  unsigned seq;
  const app_messages *msg; /* the run's, for the debug lines */
  /* the read-back (ogr_readback.c) of what a probe wrote */
  const char *t_srs;      /* T_SRS of wopts, or NULL */
  double tol_xy;          /* in the TIN's CRS */
  int lossy;              /* the last probe written did not read back */
  char lost[TT_APP_MESSAGE_MAX]; /* what changed */
  char *imposed;          /* the driver's own geographic CRS (GPX) */
} probe;

/* 1: the driver wrote the layers of mask (p->lossy: not as they were
 * given); 0: it refused or could create no dataset (p->why says why); -1:
 * nothing is known (no context). */
static int probe_run(probe *p, unsigned mask, const char *ext)
{
  char list[64];
  char *dir = CPLStrdup(CPLSPrintf("/vsimem/terratin_probe_%p_%u", (void *)p,
                                   p->seq++));
  char *name = CPLStrdup(CPLSPrintf("%s/out%s", dir, ext));
  char **opts = CSLDuplicate(p->wopts);
  opts = CSLSetNameValue(opts, "LAYERS",
                         tt__app_layer_list(mask, list, sizeof list));
  opts = CSLSetNameValue(opts, "ROWS", "NOW");
  tt_context *ctx = tt_context_create(); /* silent: no warnings printed */
  int result = -1;
  tt__app_quiet_push(p->msg);
  VSIMkdir(dir, 0755);
  CPLErrorReset();
  GDALDatasetH ds = ctx ? GDALCreate(p->drv, name, 0, 0, 0, GDT_Unknown,
                                     (CSLConstList)p->dsco)
                        : NULL;
  if (!ds && ctx) {
    /* A driver that writes only real files (FITS, netCDF, BAG): the dry
     * run in a folder of the system's temporary directory instead. */
    const char *tmp = getenv("TMPDIR");
    char *real = CPLStrdup(CPLSPrintf("%s/terratin_probe_XXXXXX",
                                      tmp && *tmp ? tmp : "/tmp"));
    VSIRmdirRecursive(dir);
    if (mkdtemp(real)) {
      CPLFree(dir);
      CPLFree(name);
      dir = real;
      name = CPLStrdup(CPLSPrintf("%s/out%s", dir, ext));
      CPLErrorReset();
      ds = GDALCreate(p->drv, name, 0, 0, 0, GDT_Unknown,
                      (CSLConstList)p->dsco);
    } else {
      CPLFree(real);
    }
    if (!ds) {
      /* nowhere: the real write would fail the same way */
      snprintf(p->why, sizeof p->why, "cannot create a %s dataset: %s",
               GDALGetDriverShortName(p->drv),
               *CPLGetLastErrorMsg() ? CPLGetLastErrorMsg()
                                     : "no details from GDAL");
      result = 0;
    }
  }
  if (ds) {
    tt_status st = tt_ogr_write_tin(ctx, ds, p->tin, p->srs, probe_fields,
                                    sizeof probe_fields /
                                        sizeof probe_fields[0],
                                    opts, NULL, NULL);
    if (st != TT_OK)
      snprintf(p->why, sizeof p->why, "%s", tt_context_errmsg(ctx));
    CPLErrorReset();
    GDALClose(ds);
    if (st == TT_OK && CPLGetLastErrorType() >= CE_Failure) {
      snprintf(p->why, sizeof p->why, "%s", CPLGetLastErrorMsg());
      st = TT_ERR_IO;
    }
    result = st == TT_OK;
    /* A folder where OUTPUT names a file (FlatGeobuf and MapInfo put
     * each layer in a file of its own there): one layer a file. */
    VSIStatBufL sb;
    if (result == 1 && *ext && VSIStatL(name, &sb) == 0 &&
        VSI_ISDIR(sb.st_mode)) {
      snprintf(p->why, sizeof p->why, "the driver writes a folder of one "
               "file a layer for them");
      result = 0;
    }
    /* Written: does it read back as written? */
    p->lossy = 0;
    if (result == 1 && (mask & 3u)) {
      char *imposed = NULL;
      /* Shapefile layers are files of their own beside OUTPUT: the
       * folder reads as one dataset of them */
      VSIStatBufL nb;
      const char *back =
          tt__app_str_ieq(GDALGetDriverShortName(p->drv), "ESRI Shapefile") &&
                  !(VSIStatL(name, &nb) == 0 && VSI_ISDIR(nb.st_mode))
              ? dir
              : name;
      if (!tt__app_read_back(p->drv, back, mask, p->tin, p->srs, p->t_srs,
                             p->tol_xy, p->lost, sizeof p->lost,
                             &imposed)) {
        p->lossy = 1;
        if (imposed && !p->imposed)
          p->imposed = imposed;
        else
          CPLFree(imposed);
      }
    }
  }
  VSIRmdirRecursive(dir);
  CPLPopErrorHandler();
  CPLErrorReset();
  tt_context_destroy(ctx);
  CSLDestroy(opts);
  CPLFree(name);
  CPLFree(dir);
  return result;
}

/* "-layers triangles, -layers vertices or -layers run_parameters" */
static void layer_choices(unsigned mask, char *buf, size_t size)
{
  static const char *const names[] = {"triangles", "vertices",
                                      "run_parameters"};
  int n = 0, total = 0;
  for (int i = 0; i < 3; i++)
    total += (mask >> i) & 1;
  buf[0] = '\0';
  for (int i = 0; i < 3; i++)
    if (mask & (1u << i)) {
      size_t len = strlen(buf);
      snprintf(buf + len, size - len, "%s-layers %s",
               n == 0 ? "" : n == total - 1 ? " or " : ", ", names[i]);
      n++;
    }
}

char **tt__app_output_dsco(const char *drvname, const char *const *dsco)
{
  char **out = CSLDuplicate((CSLConstList)dsco);
  /* GPX keeps attributes only in <extensions>: without them, none. */
  if (tt__app_str_ieq(drvname, "GPX") &&
      !CSLFetchNameValue(out, "GPX_USE_EXTENSIONS"))
    out = CSLSetNameValue(out, "GPX_USE_EXTENSIONS", "YES");
  return out;
}

/* opts with the user's -nln taken off the end of NLN_PREFIX (which may
 * begin with the prefix a Shapefile's OUTPUT gives). */
static char **without_nln(char **opts, const char *nln)
{
  const char *pre = CSLFetchNameValue(opts, "NLN_PREFIX");
  size_t n = pre ? strlen(pre) : 0, m = strlen(nln);
  if (!m || n < m || strcmp(pre + n - m, nln) != 0)
    return opts;
  char *kept = CPLStrdup(CPLSPrintf("%.*s", (int)(n - m), pre));
  opts = CSLSetNameValue(opts, "NLN_PREFIX", kept);
  CPLFree(kept);
  return opts;
}

/* A driver that does not keep the TIN as written: refused, naming what
 * changed and what works instead. */
static void refuse_lossy(app_run *r, const char *dname, const char *lost)
{
  tt__app_fail(r, TT_APP_EXIT_USAGE, TT_ERR_ARG, NULL,
               "simplify: -of %s cannot hold the TIN faithfully (%s); "
               "write -of GPKG or \"ESRI Shapefile\", or a mesh format "
               "(2DM, PLY, OBJ, LandXML, DXF)", dname, lost);
}

/* The probe of drv for OUTPUT output, on the DEM src's geotransform and
 * CRS, with its creation options dsco and the writer's options wopts
 * (LAYERS taken out: each probe sets its own); p->tin is NULL when ctx is
 * (nothing to judge with). */
static void probe_init(probe *p, tt_context *ctx, GDALDriverH drv,
                       GDALDatasetH src, const char *output, char **dsco,
                       char **wopts)
{
  memset(p, 0, sizeof *p);
  p->drv = drv;
  p->dsco = dsco;
  const char *base = strrchr(output, '/');
  base = base ? base + 1 : output;
  const char *dot = strrchr(base, '.');
  p->ext = dot && dot != base ? dot : "";
  for (char **o = wopts; o && *o; o++)
    if (strncasecmp(*o, "LAYERS=", 7) != 0)
      p->wopts = CSLAddString(p->wopts, *o);
  double gt[6] = {0, 1, 0, 0, 0, -1};
  GDALGetGeoTransform(src, gt);
  p->t_srs = CSLFetchNameValue(wopts, "T_SRS");
  p->tol_xy = 1e-6 * fmin(fabs(gt[1]), fabs(gt[5]));
  const char *wkt = GDALGetProjectionRef(src);
  if (wkt && *wkt) {
    p->srs = OSRNewSpatialReference(wkt);
    if (p->srs)
      OSRSetAxisMappingStrategy(p->srs, OAMS_TRADITIONAL_GIS_ORDER);
  }
  p->tin = ctx ? probe_tin(ctx, gt) : NULL;
}

/* A driver that takes only longitude/latitude of its own CRS (GPX): the
 * probe again in that CRS; when it keeps the TIN so, that CRS (the
 * caller's to CPLFree, p->imposed taken over), else NULL. */
static char *in_own_crs(probe *p, unsigned want)
{
  probe q = *p;
  q.wopts = CSLSetNameValue(CSLDuplicate(p->wopts), "T_SRS", p->imposed);
  q.t_srs = p->imposed;
  q.imposed = NULL;
  int again = probe_run(&q, want, p->ext);
  CSLDestroy(q.wopts);
  CPLFree(q.imposed);
  if (again != 1 || q.lossy)
    return NULL;
  char *crs = p->imposed;
  p->imposed = NULL;
  return crs;
}

int tt__app_check_ogr_output(app_run *r, GDALDriverH drv, GDALDatasetH src,
                             char **dsco, char **wopts, char **auto_t_srs)
{
  *auto_t_srs = NULL;
  const tt_app_settings *s = r->s;
  const char *dname = GDALGetDriverShortName(drv);
  probe p;
  tt_context *ctx = tt_context_create();
  probe_init(&p, ctx, drv, src, s->output, dsco, wopts);
  p.msg = &r->msg;
  int ok = 1;
  if (!p.tin)
    goto done; /* nothing to judge with */

  const unsigned want = s->layers;
  int all = probe_run(&p, want, p.ext);
  if (all == 1 && p.lossy && p.imposed && !p.t_srs &&
      (*auto_t_srs = in_own_crs(&p, want)) != NULL)
    goto done;
  if (all == 1 && p.lossy) {
    ok = 0;
    refuse_lossy(r, dname, p.lost);
    goto done;
  }
  if (all != 0)
    goto done; /* it holds them, or it cannot be judged */
  char why_all[TT_APP_MESSAGE_MAX];
  snprintf(why_all, sizeof why_all, "%s", p.why);

  {
    /* The same into a GeoPackage, which holds everything: when that fails
     * too, the fault is not the driver's (a -t_srs the DEM's CRS cannot
     * reach): said now, as the write would say it after the work. */
    probe g = p;
    static const char *const none[] = {NULL};
    GDALDriverH gpkg = GDALGetDriverByName("GPKG");
    g.drv = gpkg;
    g.wopts = NULL;
    for (char **o = p.wopts; o && *o; o++)
      if (strncasecmp(*o, "LCO=", 4) != 0 && strncasecmp(*o, "STYLE=", 6))
        g.wopts = CSLAddString(g.wopts, *o);
    g.wopts = without_nln(g.wopts, s->nln);
    g.dsco = (char **)none;
    int control = gpkg ? probe_run(&g, want, ".gpkg") : -1;
    CSLDestroy(g.wopts);
    if (control == 0) {
      ok = 0;
      tt__app_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_ARG, s->output, "%s",
                   g.why);
      goto done;
    }
  }
  if ((s->lco && s->lco[0]) || (s->dsco && s->dsco[0]) || s->nln[0]) {
    /* Without the user's -lco, -dsco and -nln? Then those are at fault
     * (a name the format reserves, a FID column named as a field). */
    probe q = p;
    static const char *const none[] = {NULL};
    q.wopts = NULL;
    for (char **o = p.wopts; o && *o; o++)
      if (strncasecmp(*o, "LCO=", 4) != 0)
        q.wopts = CSLAddString(q.wopts, *o);
    q.wopts = without_nln(q.wopts, s->nln);
    q.dsco = tt__app_output_dsco(dname, none);
    int plain = probe_run(&q, want, p.ext);
    CSLDestroy(q.wopts);
    CSLDestroy(q.dsco);
    if (plain == 1) {
      ok = 0;
      tt__app_fail(r, TT_APP_EXIT_USAGE, TT_ERR_ARG, NULL,
                   "simplify: -of %s cannot write the TIN with the -nln, "
                   "-lco and -dsco given: %s", dname, why_all);
      goto done;
    }
  }
  /* Which layers it takes alone; the first one it refuses names why. */
  unsigned alone = 0, refused = 0;
  char why_one[TT_APP_MESSAGE_MAX] = "";
  for (unsigned bit = 1; bit <= 4; bit <<= 1) {
    int k = probe_run(&p, bit, p.ext);
    if (k == 1 && p.lossy && !p.imposed) {
      ok = 0;
      refuse_lossy(r, dname, p.lost);
      goto done;
    }
    if (k != 0)
      alone |= bit;
    else if (want & bit) {
      if (!refused)
        snprintf(why_one, sizeof why_one, "%s", p.why);
      refused |= bit;
    }
  }
  char list[64], choices[160];
  ok = 0;
  /* A folder of files may hold what one file cannot (FlatGeobuf,
   * MapInfo): OUTPUT without its extension. */
  if (p.ext[0] && probe_run(&p, want, "") == 1) {
    tt__app_layer_list(want, list, sizeof list);
    layer_choices(alone, choices, sizeof choices);
    tt__app_fail(r, TT_APP_EXIT_USAGE, TT_ERR_ARG, NULL,
                 "simplify: -of %s cannot write %s into one '%s' file "
                 "(%s): name OUTPUT without '%s' to write a folder of "
                 "files%s%s", dname, list, p.ext,
                 refused ? why_one : why_all, p.ext,
                 alone && (alone & (alone - 1)) == 0 ? ", or write "
                 : alone ? ", or write one with " : "",
                 alone ? choices : "");
    goto done;
  }
  if (refused) {
    tt__app_layer_list(refused, list, sizeof list);
    if (alone) {
      /* the layers it takes, together when it holds them together */
      if ((alone & (alone - 1)) && probe_run(&p, alone, p.ext) == 1) {
        char together[64];
        snprintf(choices, sizeof choices, "-layers %s",
                 tt__app_layer_list(alone, together, sizeof together));
      } else {
        layer_choices(alone, choices, sizeof choices);
      }
      tt__app_fail(r, TT_APP_EXIT_USAGE, TT_ERR_ARG, NULL,
                   "simplify: -of %s cannot hold the %s layer%s (%s); it "
                   "takes %s", dname, list, strchr(list, ',') ? "s" : "",
                   why_one, choices);
    } else {
      tt__app_fail(r, TT_APP_EXIT_USAGE, TT_ERR_ARG, NULL,
                   "simplify: -of %s cannot hold the %s layer%s (%s); use "
                   "-of GPKG", dname, list, strchr(list, ',') ? "s" : "",
                   why_one);
    }
    goto done;
  }
  /* Each alone, not together: one layer a file. */
  layer_choices(want, choices, sizeof choices);
  tt__app_layer_list(want, list, sizeof list);
  tt__app_fail(r, TT_APP_EXIT_USAGE, TT_ERR_ARG, NULL,
               "simplify: -of %s holds one layer, not %s (%s): write one "
               "with %s", dname, list, why_all, choices);

done:
  CPLFree(p.imposed);
  tt_tin_destroy(p.tin);
  tt_context_destroy(ctx);
  if (p.srs)
    OSRDestroySpatialReference(p.srs);
  CSLDestroy(p.wopts);
  return ok;
}

unsigned tt__app_probe_format(GDALDriverH drv, const char *ext,
                              unsigned *out_alone, int *out_imposed)
{
  /* a DEM of 30 m cells in UTM zone 33N, as the dry run of a run sees it;
   * all three layers first, then each alone */
  static const double gt[6] = {500000, 30, 0, 5000000, 0, -30};
  static const unsigned masks[] = {TT_APP_LAYERS_ALL, 1u, 2u, 4u};
  static const char *const none[] = {NULL};
  probe p;
  unsigned held = 0, together = 0;
  *out_imposed = 0;
  memset(&p, 0, sizeof p);
  tt_context *ctx = tt_context_create();
  p.drv = drv;
  p.ext = ext;
  p.tol_xy = 1e-6 * gt[1];
  p.dsco = tt__app_output_dsco(GDALGetDriverShortName(drv), none);
  p.srs = OSRNewSpatialReference(NULL);
  if (p.srs && OSRImportFromEPSG(p.srs, 32633) == OGRERR_NONE)
    OSRSetAxisMappingStrategy(p.srs, OAMS_TRADITIONAL_GIS_ORDER);
  p.tin = ctx && p.srs ? probe_tin(ctx, gt) : NULL;
  for (size_t i = 0; p.tin && i < sizeof masks / sizeof masks[0]; i++) {
    int k = probe_run(&p, masks[i], ext);
    char *crs = NULL;
    if (k == 1 && p.lossy && p.imposed &&
        (crs = in_own_crs(&p, masks[i])) != NULL) {
      *out_imposed = 1; /* written in the driver's own CRS (GPX) */
      p.lossy = 0;
      CPLFree(crs);
    }
    if (k == 1 && !p.lossy && i == 0) {
      held = together = TT_APP_LAYERS_ALL;
      break;
    }
    if (k == 1 && !p.lossy)
      held |= masks[i];
  }
  *out_alone = held;
  CPLFree(p.imposed);
  tt_tin_destroy(p.tin);
  tt_context_destroy(ctx);
  if (p.srs)
    OSRDestroySpatialReference(p.srs);
  CSLDestroy(p.dsco);
  return together;
}

/* ===========================================================================
 * Databases
 * ========================================================================= */

static int has_file_extension(GDALDriverH drv)
{
  return GDALGetMetadataItem(drv, GDAL_DMD_EXTENSIONS, NULL) ||
         GDALGetMetadataItem(drv, GDAL_DMD_EXTENSION, NULL);
}

GDALDriverH tt__app_database_driver(app_run *r)
{
  const char *of = r->s->format, *out = r->s->output;
  if (of) {
    GDALDriverH drv = GDALGetDriverByName(of);
    if (!drv || has_file_extension(drv) ||
        !GDALGetMetadataItem(drv, GDAL_DCAP_VECTOR, NULL))
      return NULL; /* tt__app_output_driver says what is wrong */
    /* Memory and the like write nothing that lasts: refused there */
    const char *prefix =
        GDALGetMetadataItem(drv, GDAL_DMD_CONNECTION_PREFIX, NULL);
    if (prefix || tt__app_str_ieq(of, "PostgreSQL"))
      return drv;
    return NULL;
  }
  /* No -of: a connection string names its driver (GDAL 3.6 does not
   * declare PostgreSQL's "PG:" prefix, nor the libpq URI its driver also
   * opens). */
  if (strncasecmp(out, "PG:", 3) == 0 ||
      strncmp(out, "postgresql://", 13) == 0 ||
      strncmp(out, "postgres://", 11) == 0)
    return GDALGetDriverByName("PostgreSQL");
  for (int i = 0; i < GDALGetDriverCount(); i++) {
    GDALDriverH drv = GDALGetDriver(i);
    const char *prefix =
        GDALGetMetadataItem(drv, GDAL_DMD_CONNECTION_PREFIX, NULL);
    if (prefix && *prefix && strncasecmp(out, prefix, strlen(prefix)) == 0 &&
        GDALGetMetadataItem(drv, GDAL_DCAP_VECTOR, NULL) &&
        GDALGetMetadataItem(drv, GDAL_DCAP_CREATE, NULL))
      return drv;
  }
  return NULL;
}

GDALDatasetH tt__app_database_open(app_run *r, GDALDriverH drv,
                                   const char *shown)
{
  const tt_app_settings *s = r->s;
  const char *dname = GDALGetDriverShortName(drv);
  const char *allowed[] = {dname, NULL};
  r->msg.last[0] = '\0';
  GDALDatasetH ds = GDALOpenEx(s->output, GDAL_OF_VECTOR | GDAL_OF_UPDATE,
                               allowed, NULL, NULL);
  if (!ds) {
    tt__app_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_IO, shown,
                 "cannot open the %s datasource for writing: %s", dname,
                 r->msg.last[0] ? r->msg.last : "no details from GDAL");
    return NULL;
  }
  if (!GDALDatasetTestCapability(ds, ODsCTransactions) ||
      !GDALDatasetTestCapability(ds, ODsCCreateLayer)) {
    tt__app_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_ARG, shown,
                 "the %s datasource %s; a TIN is written in one "
                 "transaction or not at all", dname,
                 GDALDatasetTestCapability(ds, ODsCCreateLayer)
                     ? "has no transactions"
                     : "cannot create layers");
    GDALClose(ds);
    return NULL;
  }
  /* Our tables must not be there already, unless -overwrite. */
  const char *schema = NULL;
  for (size_t i = 0; s->lco[i]; i++)
    if (strncasecmp(s->lco[i], "SCHEMA=", 7) == 0)
      schema = s->lco[i] + 7;
  static const char *const names[] = {"triangles", "vertices",
                                      "run_parameters"};
  for (unsigned i = 0; i < 3 && !s->overwrite; i++) {
    if (!(s->layers & (1u << i)))
      continue;
    char *name = CPLStrdup(CPLSPrintf("%s%s%s%s", schema ? schema : "",
                                      schema ? "." : "", s->nln, names[i]));
    tt__app_quiet_push(&r->msg);
    OGRLayerH l = GDALDatasetGetLayerByName(ds, name);
    CPLPopErrorHandler();
    CPLErrorReset();
    if (l) {
      tt__app_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_EXISTS, shown,
                   "layer %s exists; use -overwrite to replace it", name);
      CPLFree(name);
      GDALClose(ds);
      return NULL;
    }
    CPLFree(name);
  }
  return ds;
}
