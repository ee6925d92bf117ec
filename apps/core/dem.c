/*
 * dem.c -- apps/core/: the command's core, what every command's folder shares.
 * This file: the DEM as every subcommand opens it: the raster opened with a
 * one-line reason when it cannot be (missing, a folder, empty, a vector
 * dataset, a missing member of an archive), the band read into a grid at its
 * own precision with -srcnodata, -z_factor, -z_unit, -work_srs and the memory
 * limit, undeclared fill values warned about, the height range.
 */
#include "app.h"

#include <cpl_conv.h>
#include <cpl_string.h>
#include <cpl_vsi.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

/* A path into an archive (/vsizip/, /vsitar/, /vsi7z/, /vsirar/, /vsigzip/,
 * possibly chained) that does not exist: which part is missing, the
 * archive or the member in it. Writes the reason to why; 0 when path is
 * not such a path. Only local archive file systems are probed (a /vsicurl/
 * prefix would cost a request per level). */
static int explain_missing_vsi(const char *path, char *why, size_t size)
{
  static const char *const fs[] = {"/vsizip/", "/vsitar/", "/vsi7z/",
                                   "/vsirar/", "/vsigzip/"};
  size_t skip = 0;
  for (size_t i = 0; i < sizeof fs / sizeof fs[0] && !skip; i++)
    if (strncmp(path, fs[i], strlen(fs[i])) == 0)
      skip = strlen(fs[i]);
  if (!skip)
    return 0;
  char *buf = CPLStrdup(path);
  VSIStatBufL sb;
  int found = 0;
  for (char *slash = strrchr(buf, '/'); slash && slash > buf + skip;
       slash = strrchr(buf, '/')) {
    *slash = '\0';
    const char *member = path + strlen(buf) + 1;
    const char *real = buf + skip; /* the same name outside the archive */
    int in_archive = VSIStatL(buf, &sb) == 0;
    if (in_archive && VSI_ISDIR(sb.st_mode) && VSIStatL(real, &sb) != 0) {
      snprintf(why, size, "no such file or directory: the folder %s of the "
               "archive holds no '%s'", buf, member);
      found = 1;
    } else if (VSIStatL(real, &sb) == 0 && VSI_ISREG(sb.st_mode)) {
      if (in_archive)
        snprintf(why, size, "no such file or directory: the archive %s "
                 "holds no '%s'", real, member);
      else
        snprintf(why, size, "%s is not an archive %.*s can read (or is "
                 "damaged)", real, (int)(skip - 2), path + 1);
      found = 1;
    }
    if (found)
      break;
  }
  if (!found)
    snprintf(why, size, "no such file or directory (the archive in %s does "
             "not exist)", path + skip);
  CPLFree(buf);
  return 1;
}

/* The view of GDAL's input options over the opened file (dem_view.c),
 * which becomes r->dem_file; NULL with the failure recorded (file closed).
 * The arguments are kept for the workers of a tiled run. */
static GDALDatasetH open_view(app_run *r, const char *path, GDALDatasetH ds)
{
  char why[TT_APP_MESSAGE_MAX], warn[TT_APP_MESSAGE_MAX];
  int usage = 0;
  const char *cmd = tt__app_command_name(r->s->command);
  CSLDestroy(r->view_args);
  r->view_args = tt__app_view_args(r->s, ds, &usage, why, sizeof why, warn,
                                   sizeof warn);
  if (!r->view_args) {
    tt__app_fail(r, usage ? TT_APP_EXIT_USAGE : TT_APP_EXIT_FAILURE,
                 usage ? TT_ERR_ARG : TT_ERR_DATA, NULL, "%s: %s (DEM %s)",
                 cmd, why, path);
    GDALClose(ds);
    return NULL;
  }
  if (warn[0])
    tt__app_warn(&r->msg, "%s: %s", path, warn);
  GDALDatasetH view = tt__app_view_open(ds, r->view_args, why, sizeof why);
  if (!view) {
    tt__app_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_FORMAT, path, "%s", why);
    GDALClose(ds);
    return NULL;
  }
  r->dem_file = ds;
  return view;
}

void tt__app_close_raster(app_run *r, GDALDatasetH ds)
{
  if (ds)
    GDALClose(ds);
  if (r->dem_file)
    GDALClose(r->dem_file);
  r->dem_file = NULL;
}

GDALDatasetH tt__app_raster_file(const app_run *r, GDALDatasetH ds)
{
  return r->dem_file ? r->dem_file : ds;
}

char **tt__app_view_read_options(const app_run *r, char **ropts,
                                 const char *path)
{
  if (!r->dem_file)
    return ropts;
  GDALDriverH drv = GDALGetDatasetDriver(r->dem_file);
  ropts = CSLSetNameValue(ropts, "SOURCE_NAME", path);
  if (drv)
    ropts = CSLSetNameValue(ropts, "SOURCE_DRIVER",
                            GDALGetDriverShortName(drv));
  return ropts;
}

/* Opens a raster for reading and checks the band; on failure explains in
 * one line why: missing, a folder, empty, a vector dataset, unreadable. */
GDALDatasetH tt__app_open_raster(app_run *r, const char *path, int band,
                                GDALRasterBandH *out_band)
{
  VSIStatBufL sb;
  *out_band = NULL;
  r->msg.last[0] = '\0';
  GDALDatasetH ds = GDALOpenEx(path, GDAL_OF_RASTER | GDAL_OF_READONLY |
                                         GDAL_OF_VERBOSE_ERROR,
                               NULL, NULL, NULL);
  if (!ds) {
    char gdal_msg[TT_APP_MESSAGE_MAX];
    snprintf(gdal_msg, sizeof gdal_msg, "%s", r->msg.last);
    int stat_ok = VSIStatL(path, &sb) == 0;
    if (!stat_ok && !strchr(path, ':') && strncmp(path, "/vsi", 4) != 0) {
      struct stat st;
      int too_long = stat(path, &st) != 0 && errno == ENAMETOOLONG;
      tt__app_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_IO, path, "%s",
                   too_long ? "the name is too long for the file system "
                              "(a folder or file name of more than 255 "
                              "bytes, or a path of more than 4096)"
                            : "no such file or directory");
      return NULL;
    }
    char why[TT_APP_MESSAGE_MAX];
    if (!stat_ok && explain_missing_vsi(path, why, sizeof why)) {
      tt__app_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_IO, path, "%s", why);
      return NULL;
    }
    if (stat_ok && VSI_ISDIR(sb.st_mode)) {
      tt__app_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_FORMAT, path,
               "is a folder, not a raster");
      return NULL;
    }
    if (stat_ok && VSI_ISREG(sb.st_mode) && sb.st_size == 0) {
      tt__app_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_FORMAT, path,
               "is an empty file, not a raster");
      return NULL;
    }
    tt__app_quiet_push(&r->msg);
    GDALDatasetH vec = GDALOpenEx(path, GDAL_OF_VECTOR | GDAL_OF_READONLY,
                                  NULL, NULL, NULL);
    CPLPopErrorHandler();
    if (vec) {
      GDALDriverH drv = GDALGetDatasetDriver(vec);
      const char *dname = drv ? GDALGetDriverShortName(drv) : "?";
      int k = tt__app_arg_number(r, path);
      /* a positional word: which one, and what the command expects there
       * (every command that reads a DEM takes it first) */
      if (k)
        tt__app_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_FORMAT, NULL,
                     "%s: %s (argument %d) is a vector dataset (%s); the "
                     "DEM (a raster) comes first",
                     tt__app_command_name(r->s->command),
                     tt__app_shown(r, path), k, dname);
      else
        tt__app_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_FORMAT, path,
                     "is a vector dataset (%s), not a raster", dname);
      GDALClose(vec);
      return NULL;
    }
    if (gdal_msg[0] && !strstr(gdal_msg, "not recognized"))
      tt__app_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_FORMAT, path,
               "cannot be opened as a raster: %s", gdal_msg);
    else
      tt__app_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_FORMAT, path,
               "not a raster format GDAL can read");
    return NULL;
  }
  if (tt__app_view_wanted(r->s) && !(ds = open_view(r, path, ds)))
    return NULL;
  int nbands = GDALGetRasterCount(ds);
  if (nbands < 1) {
    tt__app_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_FORMAT, path,
             "has no raster band");
    tt__app_close_raster(r, ds);
    return NULL;
  }
  if (band > nbands) {
    tt__app_fail(r, TT_APP_EXIT_USAGE, TT_ERR_ARG, path,
             "-b %d: the raster has %d band%s", band, nbands,
             nbands == 1 ? "" : "s");
    tt__app_close_raster(r, ds);
    return NULL;
  }
  int w = GDALGetRasterXSize(ds), h = GDALGetRasterYSize(ds);
  if (w < 2 || h < 2) {
    tt__app_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_DATA, path,
             "raster is %dx%d; at least 2x2 samples are needed", w, h);
    tt__app_close_raster(r, ds);
    return NULL;
  }
  *out_band = GDALGetRasterBand(ds, band);
  return ds;
}

/* Undeclared fill values. Many DEMs mark their voids with a classic value
 * (-9999, -32767, -32768, -32000, -99999, -3.4e38, or 32767 and 65535 at
 * the top of integer types) without declaring it as the band's nodata, and
 * a TIN then dives to the void. A value from that list is suspect when it
 * lies farther from the band's other heights than their whole range, and
 * either forms runs along a row (FILL_RUN samples in a row) or a share of
 * FILL_SHARE of the valid samples: a warning then names it, its count and
 * the -srcnodata that would mask it. One pass; heights far below 9999 are
 * skipped by a single comparison. */
#define FILL_RUN 4
#define FILL_SHARE 0.001

static void warn_fill_values(app_run *r, const tt_grid *grid,
                             const tt_raster_info *info, const char *path,
                             size_t valid)
{
  static const double fills[] = {-9999.0, -32767.0, -32768.0, -32000.0,
                                 -99999.0, -3.4028234663852886e38, -3.4e38,
                                 32767.0, 65535.0};
  enum { NF = sizeof fills / sizeof fills[0] };
  float t[NF];
  size_t count[NF] = {0}, run[NF] = {0}, best_run[NF] = {0};
  double k = (info ? info->z_unit_factor * info->z_factor : 1.0);
  double scale = info ? info->scale : 1.0, offset = info ? info->offset : 0.0;
  float thr = INFINITY;
  for (size_t i = 0; i < NF; i++) {
    t[i] = (float)((fills[i] * scale + offset) * k);
    if (fabsf(t[i]) < thr)
      thr = fabsf(t[i]);
  }
  /* one of the two is set, as the grid's precision says */
  const float *z = tt_grid_heights_const(grid);
  const double *zd = tt_grid_heights_f64_const(grid);
  size_t nx = tt_grid_width(grid), ny = tt_grid_height(grid);
  double lo = INFINITY, hi = -INFINITY;
  for (size_t row = 0; row < ny; row++) {
    for (size_t i = 0; i < NF; i++)
      run[i] = 0;
    for (size_t c = 0; c < nx; c++) {
      /* a double grid's value compared as a float: the fill values are
       * whole numbers or float limits, exact either way */
      float h = zd ? (float)zd[row * nx + c] : z[row * nx + c];
      if (isnan(h))
        continue;
      int which = -1;
      if (fabsf(h) >= thr)
        for (int i = 0; i < (int)NF; i++)
          if (h == t[i]) {
            which = i;
            break;
          }
      for (int i = 0; i < (int)NF; i++)
        if (i != which)
          run[i] = 0;
      if (which < 0) {
        if (h < lo) lo = h;
        if (h > hi) hi = h;
        continue;
      }
      count[which]++;
      if (++run[which] > best_run[which])
        best_run[which] = run[which];
    }
  }
  if (!(lo <= hi))
    return; /* nothing else to compare with */
  double span = hi - lo > 1.0 ? hi - lo : 1.0;
  for (size_t i = 0; i < NF; i++) {
    if (!count[i])
      continue;
    double gap = t[i] < lo ? lo - t[i] : t[i] > hi ? t[i] - hi : 0.0;
    if (gap <= span)
      continue;
    if (best_run[i] < FILL_RUN && (double)count[i] < FILL_SHARE * valid)
      continue;
    char raw[40];
    tt__app_format_double(raw, sizeof raw, fills[i]);
    tt__app_warn(&r->msg, "%s: band %d: %zu sample%s (%.2g%%) %s %s, in "
                 "runs of up to %zu, far from the other heights (%.10g .. "
                 "%.10g): an undeclared nodata value? -srcnodata %s treats "
                 "%s as nodata", path, r->s->band, count[i],
                 count[i] == 1 ? "" : "s", 100.0 * count[i] / valid,
                 count[i] == 1 ? "is" : "are", raw, best_run[i], lo, hi,
                 raw, count[i] == 1 ? "it" : "them");
  }
}

char **tt__app_read_options(const tt_app_settings *s)
{
  char **ropts = NULL;
  if (s->srcnodata)
    ropts = CSLSetNameValue(ropts, "SRCNODATA", s->srcnodata);
  if (s->z_factor != 1.0 || s->z_factor_set) {
    char num[40];
    tt__app_format_double(num, sizeof num, s->z_factor);
    ropts = CSLSetNameValue(ropts, "Z_FACTOR", num);
  }
  /* -z_unit says what the heights are; -z_to whether they become metres
   * (auto unless asked otherwise) */
  if (s->z_unit)
    ropts = CSLSetNameValue(ropts, "SRC_Z_UNIT", s->z_unit);
  if (!s->z_to || strcmp(s->z_to, "auto") == 0)
    ropts = CSLSetNameValue(ropts, "Z_UNIT", "auto");
  else if (strcmp(s->z_to, "m") == 0)
    ropts = CSLSetNameValue(ropts, "Z_UNIT", "m");
  if (s->work_srs)
    ropts = CSLSetNameValue(ropts, "WORK_SRS", s->work_srs);
  return ropts;
}

/* Reads the band into a grid and checks it has usable samples. */
tt_status tt__app_read_dem(app_run *r, GDALRasterBandH band, const char *path,
                          tt_progress_fn progress, void *progress_arg,
                          tt_grid **out_grid, tt_raster_info **out_info,
                          size_t *out_valid)
{
  tt_grid *grid = NULL;
  tt_raster_info *info = NULL;
  size_t valid = 0;
  char **ropts = tt__app_read_options(r->s);
  if (r->s->max_memory)
    ropts = CSLSetNameValue(ropts, "MAX_MEMORY",
                            CPLSPrintf("%zu", r->s->max_memory));
  ropts = tt__app_view_read_options(r, ropts, path);
  r->msg.last[0] = '\0';
  tt_status st = tt_gdal_read_grid(r->ctx, band, ropts, progress,
                                   progress_arg, &grid, &info);
  CSLDestroy(ropts);
  if (st == TT_ERR_ARG) { /* -srcnodata the band cannot hold, ... */
    tt__app_fail(r, TT_APP_EXIT_USAGE, st, path, "%s",
                 tt__app_why(r, st, path));
    goto done;
  }
  if (st != TT_OK) {
    tt__app_fail_tt(r, st, path);
    goto done;
  }
  st = tt_grid_check(r->ctx, grid, &valid);
  if (st != TT_OK) {
    tt__app_fail_tt(r, st, path);
    goto done;
  }
  if (valid == 0) {
    st = tt__app_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_DATA, path,
                  "band %d has no valid samples (all nodata)", r->s->band);
    goto done;
  }
  if (!r->s->srcnodata)
    warn_fill_values(r, grid, info, path, valid);
done:
  if (st != TT_OK) {
    tt_grid_destroy(grid);
    tt_raster_info_destroy(info);
    grid = NULL;
    info = NULL;
  }
  *out_grid = grid;
  *out_info = info;
  *out_valid = valid;
  return st;
}

void tt__app_height_range(const tt_grid *grid, double *out_min,
                         double *out_max)
{
  /* a grid of doubles has no float view (tt_grid_heights_const is NULL) */
  const float *z = tt_grid_heights_const(grid);
  const double *zd = tt_grid_heights_f64_const(grid);
  size_t n = tt_grid_width(grid) * tt_grid_height(grid);
  double lo = INFINITY, hi = -INFINITY;
  for (size_t i = 0; i < n; i++) {
    double v = zd ? zd[i] : (double)z[i];
    if (isnan(v))
      continue;
    if (v < lo) lo = v;
    if (v > hi) hi = v;
  }
  *out_min = lo;
  *out_max = hi;
}

/* What optimize and rasterize read before their work: the DEM into a grid,
 * then the TIN dataset and its triangles layer, each out of the output's
 * reach (every file either input reads from: an archive, a GPKG, VRT
 * sources). The DEM takes the progress phase the caller set. */
tt_status tt__app_read_dem_and_tin(app_run *r, tt_output *outp,
                                   tt_grid **out_grid,
                                   tt_raster_info **out_info,
                                   size_t *out_valid, GDALDatasetH *out_tds,
                                   OGRLayerH *out_layer)
{
  const tt_app_settings *s = r->s;
  GDALRasterBandH band = NULL;
  GDALDatasetH src = tt__app_open_raster(r, s->input, s->band, &band);
  if (!src)
    return r->res->status;
  tt_status st = tt_output_protect_dataset(r->ctx, outp,
                                           tt__app_raster_file(r, src),
                                           s->input);
  if (st != TT_OK) {
    tt__app_close_raster(r, src);
    return tt__app_fail_tt(r, st, s->output);
  }
  st = tt__app_read_dem(r, band, s->input, tt__app_phase_fn, &r->prog,
                        out_grid, out_info, out_valid);
  tt__app_close_raster(r, src);
  if (st != TT_OK)
    return st;
  *out_tds = tt__app_open_vector(r, s->tin);
  if (!*out_tds)
    return r->res->status;
  st = tt_output_protect_dataset(r->ctx, outp, *out_tds, s->tin);
  if (st != TT_OK)
    return tt__app_fail_tt(r, st, s->output);
  *out_layer = tt__app_tin_layer(r, *out_tds);
  return *out_layer ? TT_OK : r->res->status;
}
