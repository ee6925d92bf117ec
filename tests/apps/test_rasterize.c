/*
 * test_rasterize.c -- `terratin rasterize DEM TIN OUT` and `terratin eval
 * DEM TIN -error_raster OUT` through the command's library (issue 17), with
 * the rasters read back by GDAL:
 *  - a tilted plane with a lake and a cut corner of nodata: the rasterized
 *    TIN equals the plane at every valid sample (to float rounding), NaN
 *    (the band's nodata) everywhere else, the DEM's geotransform and CRS,
 *    a tiled DEFLATE Float32 GeoTIFF;
 *  - a bumpy surface on the same grid: the error raster's max |value| and
 *    RMS equal the max error and RMSE of an independent evaluation
 *    (tt_ogr_read_triangles + tt_eval_triangles), NaN at the DEM's nodata,
 *    and TIN - DEM = the rasterized TIN minus the DEM, on the DEM's grid
 *    and CRS; a failed -max_error check (exit 3) still writes it;
 *  - a Float64 DEM whose heights are no floats: both rasters Float64, the
 *    same identities to double rounding;
 *  - -of AAIGrid (a driver that only copies) and -co; the driver guessed
 *    from the extension without -of (.asc, .png refused, .foo GTiff);
 *  - refusals that leave nothing behind: an existing output without
 *    -overwrite (untouched), an unreadable TIN or DEM, a driver that cannot
 *    write floats, an interrupt during the write;
 *  - a real DEM from the shared testdata (Luxembourg, with nodata), when
 *    present.
 */
#include "terratin_lib.h"
#include "terratin/terratin_gdal.h"
#include "tt_test.h"

#include <cpl_conv.h>
#include <cpl_string.h>
#include <dirent.h>
#include <gdal.h>
#include <ogr_srs_api.h>
#include <sys/stat.h>
#include <unistd.h>

static char tmpdir[256];
static tt_context *ctx;

static const char *tmp_path(const char *name)
{
  static char buf[32][512];
  static int k = 0;
  k = (k + 1) % 32;
  snprintf(buf[k], sizeof buf[k], "%s/%s", tmpdir, name);
  return buf[k];
}

/* Runs the command's words; returns the exit code, the message in msg. */
static int run(char **argv, char *msg, size_t size)
{
  tt_app_options *opts = NULL;
  tt_app_result res;
  FILE *out = tmpfile();
  if (tt_app_options_new(argv, &opts, &res) == TT_OK) {
    tt_app_options_set_streams(opts, out, stderr);
    tt_app_run(opts, &res);
  }
  tt_app_options_destroy(opts);
  if (out)
    fclose(out);
  if (msg)
    snprintf(msg, size, "%s", res.message);
  if (res.message[0])
    printf("  terratin %s: %s\n", argv[0], res.message);
  return res.exit_code;
}

/* Files whose name starts with ".tt" (temporary outputs) in tmpdir. */
static int leftovers(void)
{
  int n = 0;
  DIR *d = opendir(tmpdir);
  struct dirent *e;
  while (d && (e = readdir(d)))
    if (strncmp(e->d_name, ".tt", 3) == 0) {
      printf("  leftover: %s\n", e->d_name);
      n++;
    }
  if (d)
    closedir(d);
  return n;
}

static int exists(const char *p)
{
  struct stat st;
  return stat(p, &st) == 0;
}

#define NX 61
#define NY 47
static const double gt_dem[6] = {500000.0, 10.0, 0.0, 4100000.0, 0.0, -10.0};

static int is_nodata_cell(int c, int r)
{
  int dc = c - 30, dr = r - 22;
  return dc * dc + dr * dr <= 36 || (c >= 50 && r >= 38);
}

static double plane(int c, int r) { return 100.0 + 0.25 * c - 0.5 * r; }

/* kind 0: the plane; 1: plane + bumps (Float32); 2: 1 in Float64 with
 * heights that are no floats. */
static double height(int kind, int c, int r)
{
  double z = plane(c, r);
  if (kind >= 1)
    z += (double)(float)(3.0 * sin(c / 3.0) * cos(r / 4.0));
  if (kind == 2)
    z += 1e-9 * (c + 1);
  return z;
}

static void write_dem(const char *path, int kind)
{
  GDALDatasetH ds =
      GDALCreate(GDALGetDriverByName("GTiff"), path, NX, NY, 1,
                 kind == 2 ? GDT_Float64 : GDT_Float32, NULL);
  CHECK(ds != NULL);
  if (!ds)
    return;
  GDALSetGeoTransform(ds, (double *)gt_dem);
  OGRSpatialReferenceH srs = OSRNewSpatialReference(NULL);
  OSRImportFromEPSG(srs, 32633);
  char *wkt = NULL;
  OSRExportToWkt(srs, &wkt);
  GDALSetProjection(ds, wkt);
  CPLFree(wkt);
  OSRDestroySpatialReference(srs);
  double *z = malloc(sizeof(double) * NX * NY);
  for (int r = 0; r < NY; r++)
    for (int c = 0; c < NX; c++)
      z[r * NX + c] = is_nodata_cell(c, r) ? -9999.0 : height(kind, c, r);
  GDALRasterBandH b = GDALGetRasterBand(ds, 1);
  GDALSetRasterNoDataValue(b, -9999.0);
  CHECK(GDALRasterIO(b, GF_Write, 0, 0, NX, NY, z, NX, NY, GDT_Float64, 0,
                     0) == CE_None);
  free(z);
  GDALClose(ds);
}

/* Reads band 1 of path as doubles (NULL on failure), its type and size. */
static double *read_raster(const char *path, GDALDataType *type, int *nx,
                           int *ny, double gt[6], char **wkt)
{
  GDALDatasetH ds = GDALOpen(path, GA_ReadOnly);
  CHECK(ds != NULL);
  if (!ds)
    return NULL;
  GDALRasterBandH b = GDALGetRasterBand(ds, 1);
  *nx = GDALGetRasterXSize(ds);
  *ny = GDALGetRasterYSize(ds);
  *type = GDALGetRasterDataType(b);
  if (gt)
    GDALGetGeoTransform(ds, gt);
  if (wkt)
    *wkt = CPLStrdup(GDALGetProjectionRef(ds));
  int has = 0;
  double nd = GDALGetRasterNoDataValue(b, &has);
  CHECK(has && isnan(nd));
  double *v = malloc(sizeof(double) * (size_t)*nx * (size_t)*ny);
  CHECK(GDALRasterIO(b, GF_Read, 0, 0, *nx, *ny, v, *nx, *ny, GDT_Float64,
                     0, 0) == CE_None);
  GDALClose(ds);
  return v;
}

/* The reference: the triangles layer read and measured directly. */
static tt_eval_result reference_eval(const char *dem, const char *tin)
{
  tt_eval_result ev;
  memset(&ev, 0, sizeof ev);
  GDALDatasetH rs = GDALOpen(dem, GA_ReadOnly);
  GDALDatasetH vs = GDALOpenEx(tin, GDAL_OF_VECTOR, NULL, NULL, NULL);
  tt_grid *g = NULL;
  double gt[6], *xyz = NULL;
  size_t n = 0, rej = 0;
  CHECK(rs && vs);
  if (!rs || !vs)
    goto done;
  GDALGetGeoTransform(rs, gt);
  CHECK_OK(ctx, tt_gdal_read_grid(ctx, GDALGetRasterBand(rs, 1), NULL, NULL,
                                  NULL, &g, NULL));
  CHECK_OK(ctx, tt_ogr_read_triangles(
                    ctx, GDALDatasetGetLayerByName(vs, "triangles"), gt,
                    &xyz, &n, &rej));
  for (size_t i = 0; i < 9 * n; i++)
    if (i % 3 != 2 && fabs(xyz[i] - floor(xyz[i] + 0.5)) <= 1e-6)
      xyz[i] = floor(xyz[i] + 0.5);
  CHECK_OK(ctx, tt_eval_triangles(ctx, g, n, xyz, &ev));
done:
  free(xyz);
  tt_grid_destroy(g);
  if (rs)
    GDALClose(rs);
  if (vs)
    GDALClose(vs);
  return ev;
}

static void test_plane(void)
{
  const char *dem = tmp_path("plane.tif"), *tin = tmp_path("plane.gpkg");
  const char *out = tmp_path("plane_tin.tif");
  write_dem(dem, 0);
  char *s[] = {"simplify", "-q", "-max_error", "0.001", (char *)dem,
               (char *)tin, NULL};
  CHECK_INT_EQ(run(s, NULL, 0), 0);
  char *a[] = {"rasterize", "-q", (char *)dem, (char *)tin, (char *)out,
               NULL};
  CHECK_INT_EQ(run(a, NULL, 0), 0);
  GDALDataType type;
  int nx = 0, ny = 0;
  double gt[6];
  char *wkt = NULL;
  double *v = read_raster(out, &type, &nx, &ny, gt, &wkt);
  if (!v)
    return;
  CHECK_INT_EQ(type, GDT_Float32);
  CHECK_INT_EQ(nx, NX);
  CHECK_INT_EQ(ny, NY);
  for (int i = 0; i < 6; i++)
    CHECK_DBL_NEAR(gt[i], gt_dem[i], 0.0);
  CHECK(wkt && strstr(wkt, "32633") != NULL);
  CPLFree(wkt);
  size_t in = 0, bad_in = 0, bad_out = 0;
  double worst = 0;
  for (int r = 0; r < NY; r++)
    for (int c = 0; c < NX; c++) {
      double x = v[r * NX + c];
      if (is_nodata_cell(c, r)) {
        bad_out += !isnan(x);
        continue;
      }
      in++;
      if (isnan(x)) {
        bad_in++;
        continue;
      }
      worst = fmax(worst, fabs(x - plane(c, r)));
    }
  printf("plane: %zu valid samples, max |TIN - plane| %.3g\n", in, worst);
  CHECK_INT_EQ(bad_in, 0);  /* every valid sample is in the TIN */
  CHECK_INT_EQ(bad_out, 0); /* NaN outside the TIN */
  CHECK_DBL_LE(worst, 1e-5); /* float rounding of heights near 100 */
  free(v);
  /* tiled and compressed */
  GDALDatasetH ds = GDALOpen(out, GA_ReadOnly);
  if (ds) {
    const char *comp =
        GDALGetMetadataItem(ds, "COMPRESSION", "IMAGE_STRUCTURE");
    CHECK(comp && strcmp(comp, "DEFLATE") == 0);
    int bx = 0, by = 0;
    GDALGetBlockSize(GDALGetRasterBand(ds, 1), &bx, &by);
    CHECK_INT_EQ(bx, 256);
    CHECK_INT_EQ(by, 256);
    GDALClose(ds);
  }
  CHECK_INT_EQ(leftovers(), 0);
}

/* kind 1 (Float32) or 2 (Float64): eval -error_raster against the
 * reference, and against rasterize. */
static void test_error_raster(int kind)
{
  char name[4][64];
  snprintf(name[0], 64, "bumps%d.tif", kind);
  snprintf(name[1], 64, "bumps%d.gpkg", kind);
  snprintf(name[2], 64, "bumps%d_err.tif", kind);
  snprintf(name[3], 64, "bumps%d_tin.tif", kind);
  const char *dem = tmp_path(name[0]), *tin = tmp_path(name[1]);
  const char *err = tmp_path(name[2]), *ras = tmp_path(name[3]);
  write_dem(dem, kind);
  char *s[] = {"simplify", "-q", "-max_error", "0.4", (char *)dem,
               (char *)tin, NULL};
  CHECK_INT_EQ(run(s, NULL, 0), 0);
  char *e[] = {"eval", "-q", (char *)dem, (char *)tin, "-error_raster",
               (char *)err, NULL};
  CHECK_INT_EQ(run(e, NULL, 0), 0);
  char *a[] = {"rasterize", "-q", (char *)dem, (char *)tin, (char *)ras,
               NULL};
  CHECK_INT_EQ(run(a, NULL, 0), 0);
  tt_eval_result ref = reference_eval(dem, tin);
  GDALDataType te, tr;
  int nx, ny, nx2, ny2;
  double gte[6];
  char *wkt = NULL;
  double *ve = read_raster(err, &te, &nx, &ny, gte, &wkt);
  CHECK_INT_EQ(nx, NX);
  CHECK_INT_EQ(ny, NY);
  for (int i = 0; i < 6; i++)
    CHECK_DBL_NEAR(gte[i], gt_dem[i], 0.0);
  CHECK(wkt && strstr(wkt, "32633") != NULL);
  CPLFree(wkt);
  double *vr = read_raster(ras, &tr, &nx2, &ny2, NULL, NULL);
  if (!ve || !vr) {
    free(ve);
    free(vr);
    return;
  }
  GDALDataType want = kind == 2 ? GDT_Float64 : GDT_Float32;
  CHECK_INT_EQ(te, want);
  CHECK_INT_EQ(tr, want);
  double maxabs = 0, sumsq = 0, worst_id = 0;
  size_t n = 0, nodata_values = 0;
  for (int r = 0; r < NY; r++)
    for (int c = 0; c < NX; c++) {
      double x = ve[r * NX + c];
      if (is_nodata_cell(c, r)) {
        nodata_values += !isnan(x);
        continue;
      }
      if (isnan(x))
        continue;
      n++;
      maxabs = fmax(maxabs, fabs(x));
      sumsq += x * x;
      /* TIN - DEM is the rasterized TIN minus the DEM */
      double d = vr[r * NX + c] - height(kind, c, r);
      if (kind == 1)
        d = (double)(float)d;
      worst_id = fmax(worst_id, fabs(d - x));
    }
  double rms = n ? sqrt(sumsq / (double)n) : 0;
  printf("error raster (%s): %zu values, max |v| %.9g (eval %.9g), RMS "
         "%.9g (eval %.9g), |TIN - DEM - v| <= %.3g\n",
         kind == 2 ? "Float64" : "Float32", n, maxabs, ref.errors.max_error,
         rms, ref.errors.rmse, worst_id);
  CHECK(ref.errors.max_error > 0.1); /* a surface with errors to compare */
  CHECK_INT_EQ(n, ref.errors.covered);
  CHECK_INT_EQ(nodata_values, 0);
  double tol = kind == 2 ? 1e-12 : 1e-6;
  CHECK_DBL_NEAR(maxabs, ref.errors.max_error, tol * ref.errors.max_error);
  CHECK_DBL_NEAR(rms, ref.errors.rmse, tol * ref.errors.rmse);
  CHECK_DBL_LE(worst_id, kind == 2 ? 1e-9 : 1e-5);
  free(ve);
  free(vr);

  /* the error raster exists now: refused without -overwrite, untouched */
  struct stat before, after;
  stat(err, &before);
  char msg[1024];
  CHECK_INT_EQ(run(e, msg, sizeof msg), 1);
  CHECK(strstr(msg, "exists") && strstr(msg, "-overwrite"));
  stat(err, &after);
  CHECK(before.st_ino == after.st_ino &&
        before.st_mtime == after.st_mtime && before.st_size == after.st_size);
  char *eo[] = {"eval", "-q", (char *)dem, (char *)tin, "-error_raster",
                (char *)err, "-overwrite", NULL};
  CHECK_INT_EQ(run(eo, NULL, 0), 0);
  CHECK_INT_EQ(leftovers(), 0);
  /* a failed -max_error check (exit 3) still writes the raster */
  remove(err);
  char *et[] = {"eval", "-q", (char *)dem, (char *)tin, "-error_raster",
                (char *)err, "-max_error", "0.01", NULL};
  CHECK_INT_EQ(run(et, NULL, 0), 3);
  CHECK(exists(err));
  CHECK_INT_EQ(leftovers(), 0);
}

static int stop_in_write(double complete, const char *message, void *arg)
{
  (void)message;
  (void)arg;
  return complete < 0.6; /* past the reading and the rasterization */
}

static void test_refusals(void)
{
  const char *dem = tmp_path("plane.tif"), *tin = tmp_path("plane.gpkg");
  const char *out = tmp_path("refused.tif"), *junk = tmp_path("junk.gpkg");
  char msg[1024];
  FILE *f = fopen(junk, "w");
  if (f) {
    fputs("not a GeoPackage\n", f);
    fclose(f);
  }
  char *a1[] = {"rasterize", (char *)dem, (char *)junk, (char *)out, NULL};
  CHECK_INT_EQ(run(a1, msg, sizeof msg), 1);
  CHECK(strstr(msg, "junk.gpkg") != NULL);
  char *a2[] = {"rasterize", (char *)tmp_path("none.tif"), (char *)tin,
                (char *)out, NULL};
  CHECK_INT_EQ(run(a2, msg, sizeof msg), 1);
  CHECK(strstr(msg, "none.tif") != NULL);
  char *a3[] = {"rasterize", (char *)dem, (char *)tin, (char *)out, "-of",
                "PNG", NULL};
  CHECK_INT_EQ(run(a3, msg, sizeof msg), 2);
  CHECK(strstr(msg, "Float32") != NULL);
  char *a4[] = {"rasterize", (char *)dem, (char *)tin, (char *)out, "-of",
                "NoSuchDriver", NULL};
  CHECK_INT_EQ(run(a4, msg, sizeof msg), 2);
  char *a5[] = {"rasterize", (char *)dem, (char *)tin, (char *)dem,
                "-overwrite", NULL};
  CHECK_INT_EQ(run(a5, msg, sizeof msg), 1);
  CHECK(strstr(msg, "input") != NULL);
  char *a6[] = {"eval", (char *)dem, (char *)tin, "-layer", "vertices",
                "-error_raster", (char *)out, NULL};
  CHECK_INT_EQ(run(a6, msg, sizeof msg), 1);
  CHECK(strstr(msg, "Point") && !strstr(msg, "polygons rejected"));
  CHECK(!exists(out));
  /* a driver's failure names the output, not its temporary file */
  char *a12[] = {"rasterize", (char *)dem, (char *)tin, (char *)out, "-co",
                 "TILED=YES", "-co", "BLOCKXSIZE=7", NULL};
  CHECK_INT_EQ(run(a12, msg, sizeof msg), 1);
  CHECK(strstr(msg, "refused.tif") && !strstr(msg, "/.tt"));
  CHECK(!exists(out));

  /* an interrupt during the write */
  tt_app_options *opts = NULL;
  tt_app_result res;
  char *a7[] = {"rasterize", "-q", (char *)dem, (char *)tin, (char *)out,
                NULL};
  CHECK_INT_EQ(tt_app_options_new(a7, &opts, &res), TT_OK);
  if (opts) {
    tt_app_options_set_progress(opts, stop_in_write, NULL);
    CHECK_INT_EQ(tt_app_run(opts, &res), TT_ERR_INTERRUPTED);
    CHECK_INT_EQ(res.exit_code, 1);
    printf("  interrupted: %s\n", res.message);
  }
  tt_app_options_destroy(opts);
  CHECK(!exists(out));
  CHECK_INT_EQ(leftovers(), 0);

  /* a driver that only copies, and -co */
  const char *asc = tmp_path("plane_tin.asc");
  char *a8[] = {"rasterize", "-q", (char *)dem, (char *)tin, (char *)asc,
                "-of", "AAIGrid", "-co", "DECIMAL_PRECISION=9", NULL};
  CHECK_INT_EQ(run(a8, NULL, 0), 0);
  GDALDataType t;
  int nx, ny;
  double *v = read_raster(asc, &t, &nx, &ny, NULL, NULL);
  if (v) {
    double worst = 0;
    for (int r = 0; r < NY; r++)
      for (int c = 0; c < NX; c++)
        if (!is_nodata_cell(c, r))
          worst = fmax(worst, fabs(v[r * NX + c] - plane(c, r)));
    CHECK_DBL_LE(worst, 1e-5);
    free(v);
  }
  CHECK(exists(tmp_path("plane_tin.prj")));
  CHECK_INT_EQ(leftovers(), 0);

  /* no -of: the extension chooses (.asc AAIGrid, .png refused: no floats;
   * one no driver claims: GTiff) */
  const char *asc2 = tmp_path("guessed.asc"), *png = tmp_path("x.png");
  const char *foo = tmp_path("x.foo");
  char *a9[] = {"rasterize", "-q", (char *)dem, (char *)tin, (char *)asc2,
                NULL};
  CHECK_INT_EQ(run(a9, NULL, 0), 0);
  GDALDatasetH ds = GDALOpen(asc2, GA_ReadOnly);
  CHECK(ds && strcmp(GDALGetDriverShortName(GDALGetDatasetDriver(ds)),
                     "AAIGrid") == 0);
  if (ds)
    GDALClose(ds);
  char *a10[] = {"rasterize", "-q", (char *)dem, (char *)tin, (char *)png,
                 NULL};
  CHECK_INT_EQ(run(a10, msg, sizeof msg), 2);
  CHECK(strstr(msg, "x.png (by its extension: PNG)") != NULL);
  CHECK(!exists(png));
  char *a11[] = {"rasterize", "-q", (char *)dem, (char *)tin, (char *)foo,
                 NULL};
  CHECK_INT_EQ(run(a11, NULL, 0), 0);
  ds = GDALOpen(foo, GA_ReadOnly);
  CHECK(ds && strcmp(GDALGetDriverShortName(GDALGetDatasetDriver(ds)),
                     "GTiff") == 0);
  if (ds)
    GDALClose(ds);
  CHECK_INT_EQ(leftovers(), 0);
}

static void test_real_dem(const char *shared)
{
  char dem[1024];
  snprintf(dem, sizeof dem, "%s/rspatial_terra/elev.tif", shared);
  if (!exists(dem)) {
    printf("note: %s is missing; the real DEM case is skipped\n", dem);
    return;
  }
  const char *tin = tmp_path("lux.gpkg"), *err = tmp_path("lux_err.tif");
  const char *ras = tmp_path("lux_tin.tif");
  char *s[] = {"simplify", "-q", "-max_error", "10", dem, (char *)tin, NULL};
  CHECK_INT_EQ(run(s, NULL, 0), 0);
  char *e[] = {"eval", "-q", dem, (char *)tin, "-error_raster", (char *)err,
               NULL};
  CHECK_INT_EQ(run(e, NULL, 0), 0);
  char *a[] = {"rasterize", "-q", dem, (char *)tin, (char *)ras, NULL};
  CHECK_INT_EQ(run(a, NULL, 0), 0);
  tt_eval_result ref = reference_eval(dem, tin);
  GDALDataType t;
  int nx, ny;
  double *ve = read_raster(err, &t, &nx, &ny, NULL, NULL);
  double *vr = read_raster(ras, &t, &nx, &ny, NULL, NULL);
  if (ve && vr) {
    size_t n = 0, in = 0;
    double maxabs = 0, sumsq = 0;
    for (size_t i = 0; i < (size_t)nx * (size_t)ny; i++) {
      in += !isnan(vr[i]);
      if (isnan(ve[i]))
        continue;
      n++;
      maxabs = fmax(maxabs, fabs(ve[i]));
      sumsq += ve[i] * ve[i];
    }
    printf("Luxembourg: %zu errors, max %.9g (eval %.9g), RMS %.9g (eval "
           "%.9g); %zu samples in the TIN\n", n, maxabs,
           ref.errors.max_error, sqrt(sumsq / (double)n), ref.errors.rmse,
           in);
    CHECK_INT_EQ(n, ref.errors.covered);
    CHECK_INT_LE(n, in); /* nodata samples inside the TIN have no error */
    CHECK_DBL_NEAR(maxabs, ref.errors.max_error, 1e-6 * ref.errors.max_error);
    CHECK_DBL_NEAR(sqrt(sumsq / (double)n), ref.errors.rmse,
                   1e-6 * ref.errors.rmse);
  }
  free(ve);
  free(vr);
}

int main(void)
{
  GDALAllRegister();
  ctx = tt_context_create();
  snprintf(tmpdir, sizeof tmpdir, "%s", "/tmp/tt_rasterize_XXXXXX");
  if (!mkdtemp(tmpdir)) {
    perror("mkdtemp");
    return 1;
  }
  TT_RUN(test_plane());
  TT_RUN(test_error_raster(1));
  TT_RUN(test_error_raster(2));
  TT_RUN(test_refusals());
  const char *shared = getenv("TT_SHARED_TESTDATA");
  if (shared && *shared)
    test_real_dem(shared);
  else
    printf("note: TT_SHARED_TESTDATA is not set; the real DEM case is "
           "skipped\n");
  if (!tt_test_failures) {
    char cmd[600];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", tmpdir);
    if (system(cmd) != 0)
      printf("note: could not remove %s\n", tmpdir);
  }
  tt_context_destroy(ctx);
  TT_TEST_DONE();
}
