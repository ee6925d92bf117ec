/* test_georef.c -- where pixels stand on the ground, checked against PROJ
 * and GeographicLib themselves (no mocks):
 *  - the affine ground frame of geographic DEMs (Jacksboro, the DTED tile
 *    n43.dt0) against PROJ's UTM coordinates of pixel centres: distances
 *    between pixel centres across the DEM, frame vs UTM;
 *  - Web Mercator (warp_52_dem.tif): a frame scaled by about cos(lat);
 *  - the same DEM warped to UTM with GDALWarp: vertex counts and errors;
 *  - geodesic triangle areas against geod_polygonarea computed here;
 *  - T_SRS round trip; Z_UNIT=m on a DEM in feet; the CLI's summary;
 *  - the Delaunay property in true UTM coordinates, projected here with
 *    PROJ: the count of interior edges whose opposite angles sum to more
 *    than pi, printed with their size (the frame is affine, UTM is not).
 * The figures are printed on stdout (ctest -V shows them). */
#include "terratin/terratin_gdal.h"
#include "terratin_lib.h"
#include "tt_test.h"

#include <cpl_conv.h>
#include <cpl_string.h>
#include <gdal_utils.h>
#include <geodesic.h>

#include <sys/stat.h>
#include <unistd.h>

static tt_context *ctx;
static char tmpdir[512];

#define PI 3.14159265358979323846

static const char *tmp_path(const char *name)
{
  static char buf[4][700];
  static int k = 0;
  k = (k + 1) % 4;
  snprintf(buf[k], sizeof buf[k], "%s/%s", tmpdir, name);
  return buf[k];
}

static tt_grid *read_dem(const char *path, char **options,
                         tt_raster_info **out_info)
{
  GDALDatasetH ds = GDALOpenEx(path, GDAL_OF_RASTER | GDAL_OF_READONLY, NULL,
                               NULL, NULL);
  if (!ds) {
    TT_FAIL_("cannot open %s", path);
    return NULL;
  }
  tt_grid *g = NULL;
  tt_raster_info *info = NULL;
  CHECK_OK(ctx, tt_gdal_read_grid(ctx, GDALGetRasterBand(ds, 1), options,
                                  NULL, NULL, &g, &info));
  GDALClose(ds);
  if (out_info)
    *out_info = info;
  else
    tt_raster_info_destroy(info);
  return g;
}

static tt_tin *refine(const tt_grid *g, double max_error)
{
  tt_refine_options ro;
  tt_refine_options_init(&ro);
  ro.max_error = max_error;
  tt_tin *tin = NULL;
  CHECK_OK(ctx, tt_refine_run(ctx, g, &ro, &tin));
  return tin;
}

/* x = lon / easting, y = lat / northing, whatever the CRS's axis order. */
static OGRCoordinateTransformationH transform(const char *from,
                                              const char *to)
{
  OGRSpatialReferenceH a = OSRNewSpatialReference(NULL);
  OGRSpatialReferenceH b = OSRNewSpatialReference(NULL);
  OGRCoordinateTransformationH ct = NULL;
  if (OSRSetFromUserInput(a, from) == OGRERR_NONE &&
      OSRSetFromUserInput(b, to) == OGRERR_NONE) {
    OSRSetAxisMappingStrategy(a, OAMS_TRADITIONAL_GIS_ORDER);
    OSRSetAxisMappingStrategy(b, OAMS_TRADITIONAL_GIS_ORDER);
    ct = OCTNewCoordinateTransformation(a, b);
  }
  OSRDestroySpatialReference(a);
  OSRDestroySpatialReference(b);
  if (!ct)
    TT_FAIL_("no transformation %s -> %s", from, to);
  return ct;
}

/* The frame against PROJ: for a 5 x 5 lattice of pixel centres spanning
 * the DEM, every pair's distance in the frame vs in UTM (epsg). Returns
 * the largest relative difference; *out_predicted gets the part no affine
 * frame of a longitude/latitude grid can remove: the metres per degree of
 * longitude change by tan(lat) * dlat between the centre row and the top
 * or bottom row (the grid is a trapezoid on the ground); *out_inner the
 * largest difference over the pairs of the central 3 x 3 of the lattice
 * (the middle half of the DEM). */
static double frame_vs_utm(const char *path, const char *epsg,
                           const char *want_name, double *out_predicted,
                           double *out_inner)
{
  tt_raster_info *info = NULL;
  tt_grid *g = read_dem(path, NULL, &info);
  if (!g)
    return INFINITY;
  if (!strstr(info->frame_name, want_name))
    TT_FAIL_("%s: frame \"%s\" does not name %s", path, info->frame_name,
             want_name);
  double a[4], gt[6];
  tt_grid_get_ground_frame(g, a);
  tt_grid_get_geotransform(g, gt);
  OGRCoordinateTransformationH ct = transform(info->crs_wkt, epsg);
  const size_t nx = tt_grid_width(g), ny = tt_grid_height(g);
  enum { K = 5 };
  double c[K * K], r[K * K], x[K * K], y[K * K];
  for (int i = 0; i < K; i++)
    for (int j = 0; j < K; j++) {
      int k = i * K + j;
      c[k] = floor((double)(nx - 1) * i / (K - 1));
      r[k] = floor((double)(ny - 1) * j / (K - 1));
      x[k] = gt[0] + (c[k] + 0.5) * gt[1] + (r[k] + 0.5) * gt[2];
      y[k] = gt[3] + (c[k] + 0.5) * gt[4] + (r[k] + 0.5) * gt[5];
    }
  CHECK(ct && OCTTransform(ct, K * K, x, y, NULL));
  double worst = 0, inner = 0;
  for (int p = 0; p < K * K; p++)
    for (int q = p + 1; q < K * K; q++) {
      double dc = c[q] - c[p], dr = r[q] - r[p];
      double fx = a[0] * dc + a[1] * dr, fy = a[2] * dc + a[3] * dr;
      double df = hypot(fx, fy), du = hypot(x[q] - x[p], y[q] - y[p]);
      worst = fmax(worst, fabs(df / du - 1));
      int pi = p / K, pj = p % K, qi = q / K, qj = q % K;
      if (pi && pj && qi && qj && pi < K - 1 && pj < K - 1 && qi < K - 1 &&
          qj < K - 1)
        inner = fmax(inner, fabs(df / du - 1));
    }
  double lat_c = gt[3] + 0.5 * ny * gt[5], half = 0.5 * ny * fabs(gt[5]);
  *out_predicted = tan(fabs(lat_c) * PI / 180) * half * PI / 180;
  *out_inner = inner;
  printf("%s: frame %s\n  frame (%.6f %.6f; %.6f %.6f) m per pixel; "
         "relative distance error vs PROJ %s over %zux%zu pixels: largest "
         "%.3g (tan(lat) * half the latitude span: %.3g), middle half of "
         "the DEM %.3g\n",
         path, info->frame_name, a[0], a[1], a[2], a[3], epsg, nx, ny,
         worst, *out_predicted, inner);
  if (ct)
    OCTDestroyCoordinateTransformation(ct);
  tt_grid_destroy(g);
  tt_raster_info_destroy(info);
  return worst;
}

/* Web Mercator: its map metres are 1/cos(lat) ground metres. */
static void test_web_mercator(const char *path)
{
  tt_raster_info *info = NULL;
  tt_grid *g = read_dem(path, NULL, &info);
  if (!g)
    return;
  double a[4], gt[6];
  tt_grid_get_ground_frame(g, a);
  tt_grid_get_geotransform(g, gt);
  /* centre latitude from PROJ */
  OGRCoordinateTransformationH ct = transform(info->crs_wkt, "EPSG:4326");
  double x = gt[0] + 0.5 * tt_grid_width(g) * gt[1];
  double y = gt[3] + 0.5 * tt_grid_height(g) * gt[5];
  CHECK(ct && OCTTransform(ct, 1, &x, &y, NULL));
  double coslat = cos(y * PI / 180);
  double kc = hypot(a[0], a[2]) / fabs(gt[1]);
  double kr = hypot(a[1], a[3]) / fabs(gt[5]);
  printf("%s: frame %s\n  column step %.4f m of %.4f map m (ratio %.6f), "
         "row ratio %.6f, cos(lat %.4f) = %.6f\n",
         path, info->frame_name, hypot(a[0], a[2]), gt[1], kc, kr, y,
         coslat);
  CHECK(strstr(info->frame_name, "UTM zone 43N (EPSG:32643)") != NULL);
  /* UTM's own scale (0.9996..1.0004 here) and the ellipsoid: 0.5% */
  CHECK_DBL_NEAR(kc / coslat, 1.0, 5e-3);
  CHECK_DBL_NEAR(kr / coslat, 1.0, 5e-3);
  if (ct)
    OCTDestroyCoordinateTransformation(ct);
  tt_grid_destroy(g);
  tt_raster_info_destroy(info);
}

/* Interior edges of a TIN, and the opposite vertices of each. */
typedef struct edge_rec {
  int32_t a, b;  /* a < b */
  int32_t opp;   /* the third vertex of the triangle */
} edge_rec;

static int edge_cmp(const void *p, const void *q)
{
  const edge_rec *x = p, *y = q;
  if (x->a != y->a)
    return x->a < y->a ? -1 : 1;
  if (x->b != y->b)
    return x->b < y->b ? -1 : 1;
  return 0;
}

static double angle_at(const double *p, const double *q, const double *r)
{
  double ux = q[0] - p[0], uy = q[1] - p[1];
  double vx = r[0] - p[0], vy = r[1] - p[1];
  return atan2(fabs(ux * vy - uy * vx), ux * vx + uy * vy);
}

/* Counts interior edges whose opposite angles sum to more than pi + tol
 * (tol in radians) for the vertex coordinates xy (2 per vertex). */
static void delaunay_violations(const tt_tin *tin, const double *xy,
                                const double *tols, int ntols,
                                size_t *out_counts, size_t *out_interior,
                                double *out_worst)
{
  size_t nt = tt_tin_triangle_count(tin);
  edge_rec *e = malloc(3 * nt * sizeof *e);
  size_t n = 0;
  for (size_t t = 0; t < nt; t++) {
    tt_triangle_info ti;
    tt_tin_triangle(tin, t, &ti);
    for (int k = 0; k < 3; k++) {
      int32_t u = ti.v[k], v = ti.v[(k + 1) % 3];
      e[n].a = u < v ? u : v;
      e[n].b = u < v ? v : u;
      e[n].opp = ti.v[(k + 2) % 3];
      n++;
    }
  }
  qsort(e, n, sizeof *e, edge_cmp);
  for (int k = 0; k < ntols; k++)
    out_counts[k] = 0;
  *out_interior = 0;
  *out_worst = -INFINITY;
  for (size_t i = 0; i + 1 < n; i++) {
    if (edge_cmp(&e[i], &e[i + 1]) != 0)
      continue;
    (*out_interior)++;
    /* relative to the edge's first vertex, for precision */
    const double *o = xy + 2 * (size_t)e[i].a;
    double pa[2] = {0, 0};
    double pb[2] = {xy[2 * (size_t)e[i].b] - o[0],
                    xy[2 * (size_t)e[i].b + 1] - o[1]};
    double pc[2] = {xy[2 * (size_t)e[i].opp] - o[0],
                    xy[2 * (size_t)e[i].opp + 1] - o[1]};
    double pd[2] = {xy[2 * (size_t)e[i + 1].opp] - o[0],
                    xy[2 * (size_t)e[i + 1].opp + 1] - o[1]};
    double excess = angle_at(pc, pa, pb) + angle_at(pd, pa, pb) - PI;
    *out_worst = fmax(*out_worst, excess);
    for (int k = 0; k < ntols; k++)
      if (excess > tols[k])
        out_counts[k]++;
    i++;
  }
  free(e);
}

/* Jacksboro: Delaunay in the affine frame (exact by construction) and in
 * true UTM (PROJ), geodesic areas, T_SRS round trip. */
static void test_jacksboro_tin(const char *path)
{
  tt_raster_info *info = NULL;
  tt_grid *g = read_dem(path, NULL, &info);
  if (!g)
    return;
  tt_tin *tin = refine(g, 5.0);
  if (!tin) {
    tt_grid_destroy(g);
    tt_raster_info_destroy(info);
    return;
  }
  const size_t nv = tt_tin_vertex_count(tin);
  double a[4];
  tt_grid_get_ground_frame(g, a);
  double *frame_xy = malloc(2 * nv * sizeof(double));
  double *utm_xy = malloc(2 * nv * sizeof(double));
  double *lon = malloc(nv * sizeof(double)), *lat = malloc(nv * sizeof(double));
  for (size_t i = 0; i < nv; i++) {
    tt_vertex_info v;
    tt_tin_vertex(tin, i, &v);
    /* the frame terratin measures in: the ground points (issue 18) */
    const double *gp = tt_grid_ground_xy(g) + 2 * (v.row * tt_grid_width(g) +
                                                   v.col);
    frame_xy[2 * i] = gp[0];
    frame_xy[2 * i + 1] = gp[1];
    lon[i] = v.x;
    lat[i] = v.y;
  }
  /* PROJ, here: every vertex into UTM zone 16N */
  OGRCoordinateTransformationH ct = transform("EPSG:4326", "EPSG:32616");
  double *ux = malloc(nv * sizeof(double)), *uy = malloc(nv * sizeof(double));
  memcpy(ux, lon, nv * sizeof(double));
  memcpy(uy, lat, nv * sizeof(double));
  CHECK(ct && OCTTransform(ct, (int)nv, ux, uy, NULL));
  for (size_t i = 0; i < nv; i++) {
    utm_xy[2 * i] = ux[i];
    utm_xy[2 * i + 1] = uy[i];
  }
  static const double tols[4] = {1e-12, 1e-9, 1e-6, 1e-3};
  size_t cnt_f[4], cnt_u[4], interior = 0;
  double worst_f, worst_u;
  delaunay_violations(tin, frame_xy, tols, 4, cnt_f, &interior, &worst_f);
  delaunay_violations(tin, utm_xy, tols, 4, cnt_u, &interior, &worst_u);
  printf("Delaunay check, %zu vertices, %zu interior edges; edges whose "
         "opposite angles sum to more than pi + tol:\n"
         "  ground points:         tol 1e-12: %zu, 1e-9: %zu, 1e-6: %zu, "
         "1e-3: %zu (largest excess %.3g rad)\n"
         "  true UTM 16N (PROJ):   tol 1e-12: %zu, 1e-9: %zu, 1e-6: %zu, "
         "1e-3: %zu (largest excess %.3g rad)\n",
         nv, interior, cnt_f[0], cnt_f[1], cnt_f[2], cnt_f[3], worst_f,
         cnt_u[0], cnt_u[1], cnt_u[2], cnt_u[3], worst_u);
  /* In the frame the engine's exact test holds: only rounding of atan2
   * (about 1e-15 rad) may show. The frame is UTM 16N itself, per vertex:
   * the same in PROJ's coordinates. */
  CHECK_INT_EQ(cnt_f[1], 0);
  CHECK_INT_EQ(cnt_u[1], 0);

  /* Written in the input CRS (geographic): geodesic areas. */
  GDALDriverH gpkg = GDALGetDriverByName("GPKG");
  OGRSpatialReferenceH srs = OSRNewSpatialReference(info->crs_wkt);
  OSRSetAxisMappingStrategy(srs, OAMS_TRADITIONAL_GIS_ORDER);
  unlink(tmp_path("geo.gpkg"));
  GDALDatasetH ds = GDALCreate(gpkg, tmp_path("geo.gpkg"), 0, 0, 0,
                               GDT_Unknown, NULL);
  CHECK_OK(ctx, tt_ogr_write_tin(ctx, ds, tin, srs, NULL, 0, NULL, NULL,
                                 NULL));
  GDALClose(ds);
  struct geod_geodesic geod;
  geod_init(&geod, 6378137, 1 / 298.257223563);
  ds = GDALOpenEx(tmp_path("geo.gpkg"), GDAL_OF_VECTOR, NULL, NULL, NULL);
  OGRLayerH l = ds ? GDALDatasetGetLayerByName(ds, "triangles") : NULL;
  CHECK(l != NULL);
  double worst_area = 0, worst_3d = 0, sum_geo = 0, sum_frame = 0;
  size_t nf = 0;
  OGRFeatureH f;
  while (l && (f = OGR_L_GetNextFeature(l)) != NULL) {
    OGRGeometryH ring = OGR_G_GetGeometryRef(OGR_F_GetGeometryRef(f), 0);
    double la[3], lo[3], A = 0, P = 0;
    for (int k = 0; k < 3; k++) {
      lo[k] = OGR_G_GetX(ring, k);
      la[k] = OGR_G_GetY(ring, k);
    }
    geod_polygonarea(&geod, la, lo, 3, &A, &P);
    double area = OGR_F_GetFieldAsDouble(f, OGR_F_GetFieldIndex(f,
                                                                "area_2d"));
    double a3 = OGR_F_GetFieldAsDouble(f, OGR_F_GetFieldIndex(f, "area_3d"));
    double slope = OGR_F_GetFieldAsDouble(f, OGR_F_GetFieldIndex(f,
                                                                 "slope"));
    worst_area = fmax(worst_area, fabs(area / fabs(A) - 1));
    worst_3d = fmax(worst_3d,
                    fabs(a3 * cos(slope * PI / 180) / area - 1));
    tt_triangle_info ti;
    tt_tin_triangle(tin, (size_t)nf, &ti);
    sum_geo += area;
    sum_frame += ti.area_2d;
    nf++;
    OGR_F_Destroy(f);
  }
  printf("geodesic areas: %zu triangles, largest relative difference from "
         "geod_polygonarea %.3g; area_3d*cos(slope)/area_2d - 1 at most "
         "%.3g; total %.6g m^2 geodesic vs %.6g m^2 in the frame (%.3g)\n",
         nf, worst_area, worst_3d, sum_geo, sum_frame,
         sum_geo / sum_frame - 1);
  CHECK_INT_EQ(nf, tt_tin_triangle_count(tin));
  CHECK_DBL_LE(worst_area, 1e-12);
  CHECK_DBL_LE(worst_3d, 1e-9);
  CHECK_DBL_NEAR(sum_geo / sum_frame, 1.0, 2e-3);
  if (ds)
    GDALClose(ds);

  /* T_SRS: UTM out, back to WGS 84 here, equal to the originals. */
  unlink(tmp_path("utm.gpkg"));
  ds = GDALCreate(gpkg, tmp_path("utm.gpkg"), 0, 0, 0, GDT_Unknown, NULL);
  char **wopts = CSLSetNameValue(NULL, "T_SRS", "EPSG:32616");
  CHECK_OK(ctx, tt_ogr_write_tin(ctx, ds, tin, srs, NULL, 0, wopts, NULL,
                                 NULL));
  CSLDestroy(wopts);
  GDALClose(ds);
  ds = GDALOpenEx(tmp_path("utm.gpkg"), GDAL_OF_VECTOR, NULL, NULL, NULL);
  l = ds ? GDALDatasetGetLayerByName(ds, "vertices") : NULL;
  CHECK(l != NULL);
  OGRCoordinateTransformationH back = transform("EPSG:32616", "EPSG:4326");
  double worst_rt = 0;
  size_t i = 0;
  if (l) {
    const char *code = OSRGetAuthorityCode(OGR_L_GetSpatialRef(l), NULL);
    CHECK(code && strcmp(code, "32616") == 0);
  }
  while (l && (f = OGR_L_GetNextFeature(l)) != NULL) {
    OGRGeometryH pt = OGR_F_GetGeometryRef(f);
    double x = OGR_G_GetX(pt, 0), y = OGR_G_GetY(pt, 0);
    int id = OGR_F_GetFieldAsInteger(f, OGR_F_GetFieldIndex(f,
                                                            "vertex_id"));
    CHECK(back && OCTTransform(back, 1, &x, &y, NULL));
    if (id >= 0 && (size_t)id < nv)
      worst_rt = fmax(worst_rt, fmax(fabs(x - lon[id]), fabs(y - lat[id])));
    i++;
    OGR_F_Destroy(f);
  }
  /* the triangles are the same (same vertices in the same order) */
  OGRLayerH lt = ds ? GDALDatasetGetLayerByName(ds, "triangles") : NULL;
  size_t same = 0, ntri = 0;
  while (lt && (f = OGR_L_GetNextFeature(lt)) != NULL) {
    tt_triangle_info ti;
    tt_tin_triangle(tin, ntri, &ti);
    same += OGR_F_GetFieldAsInteger(f, OGR_F_GetFieldIndex(f, "v0")) ==
                ti.v[0] &&
            OGR_F_GetFieldAsInteger(f, OGR_F_GetFieldIndex(f, "v1")) ==
                ti.v[1] &&
            OGR_F_GetFieldAsInteger(f, OGR_F_GetFieldIndex(f, "v2")) ==
                ti.v[2];
    ntri++;
    OGR_F_Destroy(f);
  }
  printf("T_SRS EPSG:32616 round trip: %zu vertices, largest difference "
         "%.3g degrees; %zu of %zu triangles unchanged\n",
         i, worst_rt, same, ntri);
  CHECK_INT_EQ(i, nv);
  CHECK_DBL_LE(worst_rt, 1e-6);
  CHECK_INT_EQ(same, tt_tin_triangle_count(tin));
  CHECK_INT_EQ(ntri, tt_tin_triangle_count(tin));
  if (ds)
    GDALClose(ds);
  if (back)
    OCTDestroyCoordinateTransformation(back);
  if (ct)
    OCTDestroyCoordinateTransformation(ct);
  OSRDestroySpatialReference(srs);
  free(frame_xy);
  free(utm_xy);
  free(lon);
  free(lat);
  free(ux);
  free(uy);
  tt_tin_destroy(tin);
  tt_grid_destroy(g);
  tt_raster_info_destroy(info);
}

/* The geographic DEM and the same DEM warped to UTM give TINs of about the
 * same size, both within the bound. */
static void test_warped(const char *path)
{
  GDALDatasetH src = GDALOpen(path, GA_ReadOnly);
  if (!src) {
    TT_FAIL_("cannot open %s", path);
    return;
  }
  /* Same sample count as the geographic grid, nearest neighbour (heights
   * are samples of the original, not blends). */
  char w[32], h[32];
  snprintf(w, sizeof w, "%d", GDALGetRasterXSize(src));
  snprintf(h, sizeof h, "%d", GDALGetRasterYSize(src));
  const char *argv[] = {"-t_srs", "EPSG:32616", "-r", "near", "-ts", w, h,
                        "-dstnodata", "-32768", "-of", "GTiff", NULL};
  GDALWarpAppOptions *wo = GDALWarpAppOptionsNew((char **)argv, NULL);
  int usage = 0;
  unlink(tmp_path("warped.tif"));
  GDALDatasetH dst = GDALWarp(tmp_path("warped.tif"), NULL, 1, &src, wo,
                              &usage);
  GDALWarpAppOptionsFree(wo);
  CHECK(dst != NULL);
  if (dst)
    GDALClose(dst);
  GDALClose(src);
  const double bound = 5.0;
  tt_raster_info *ig = NULL, *iu = NULL;
  tt_grid *gg = read_dem(path, NULL, &ig);
  tt_grid *gu = read_dem(tmp_path("warped.tif"), NULL, &iu);
  if (gg && gu) {
    tt_tin *tg = refine(gg, bound), *tu = refine(gu, bound);
    if (tg && tu) {
      tt_tin_summary sg, su;
      tt_tin_get_summary(tg, &sg);
      tt_tin_get_summary(tu, &su);
      double vpg = (double)sg.vertices / (double)sg.valid_samples;
      double vpu = (double)su.vertices / (double)su.valid_samples;
      printf("geographic vs warped to UTM 16N (nearest, same size), "
             "max_error %g:\n  geographic: %zu valid samples, %zu vertices "
             "(%.4f per sample), max error %.4g, RMS %.4g; frame %s\n"
             "  warped:     %zu valid samples, %zu vertices (%.4f per "
             "sample), max error %.4g, RMS %.4g; frame %s\n"
             "  vertices %+.2f%%, per valid sample %+.2f%%\n",
             bound, sg.valid_samples, sg.vertices, vpg, sg.errors.max_error,
             sg.errors.rmse, ig->frame_name, su.valid_samples, su.vertices,
             vpu, su.errors.max_error, su.errors.rmse, iu->frame_name,
             100.0 * ((double)su.vertices / (double)sg.vertices - 1),
             100.0 * (vpu / vpg - 1));
      CHECK_DBL_LE(sg.errors.max_error, bound);
      CHECK_DBL_LE(su.errors.max_error, bound);
      /* the warped grid covers a larger, rotated extent with the same
       * pixel count (a nodata collar, larger pixels): compare the TINs */
      CHECK_DBL_NEAR((double)su.vertices / (double)sg.vertices, 1.0, 0.05);
      CHECK(strncmp(iu->frame_name, "geotransform", 12) == 0);
    }
    tt_tin_destroy(tg);
    tt_tin_destroy(tu);
  }
  tt_grid_destroy(gg);
  tt_grid_destroy(gu);
  tt_raster_info_destroy(ig);
  tt_raster_info_destroy(iu);
}

/* Z_UNIT=m on a DEM in feet: heights x 0.3048; the CLI says m. */
static void test_feet(const char *path)
{
  tt_raster_info *ift = NULL, *im = NULL;
  tt_grid *gft = read_dem(path, NULL, &ift);
  char **o = CSLSetNameValue(NULL, "Z_UNIT", "m");
  tt_grid *gm = read_dem(path, o, &im);
  CSLDestroy(o);
  if (gft && gm) {
    CHECK_STR_EQ(ift->z_unit, "ft");
    CHECK_STR_EQ(im->z_unit, "m");
    CHECK_STR_EQ(im->z_unit_declared, "ft");
    CHECK_STR_EQ(im->z_unit_source, "band unit");
    CHECK_DBL_NEAR(im->z_unit_factor, 0.3048, 0);
    /* converted in doubles and kept so: a foot in metres is no float */
    CHECK_INT_EQ(tt_grid_precision(gm), TT_PRECISION_FLOAT64);
    size_t nx = tt_grid_width(gft), ny = tt_grid_height(gft), bad = 0;
    for (size_t i = 0; i < nx * ny; i++) {
      double a = tt_grid_sample(gft, i % nx, i / nx);
      double b = tt_grid_sample(gm, i % nx, i / nx);
      if (isnan(a) != isnan(b))
        bad++;
      else if (!isnan(a) && b != a * 0.3048)
        bad++;
    }
    CHECK_INT_EQ(bad, 0);
  }
  tt_grid_destroy(gft);
  tt_grid_destroy(gm);
  tt_raster_info_destroy(ift);
  tt_raster_info_destroy(im);

  /* An unknown unit is refused unless Z_FACTOR is given. */
  GDALDatasetH ds = GDALOpen(path, GA_ReadOnly);
  GDALDatasetH mem = ds ? GDALCreateCopy(GDALGetDriverByName("GTiff"),
                                         tmp_path("nounit.tif"), ds, FALSE,
                                         NULL, NULL, NULL)
                        : NULL;
  if (mem) {
    GDALSetRasterUnitType(GDALGetRasterBand(mem, 1), "");
    GDALClose(mem);
  }
  if (ds)
    GDALClose(ds);
  GDALDatasetH nd = GDALOpen(tmp_path("nounit.tif"), GA_ReadOnly);
  if (nd) {
    tt_grid *g = NULL;
    char **zo = CSLSetNameValue(NULL, "Z_UNIT", "m");
    CHECK_INT_EQ(tt_gdal_read_grid(ctx, GDALGetRasterBand(nd, 1), zo, NULL,
                                   NULL, &g, NULL),
                 TT_ERR_DATA);
    CHECK(strstr(tt_context_errmsg(ctx), "Z_FACTOR") != NULL);
    zo = CSLSetNameValue(zo, "Z_FACTOR", "0.3048");
    CHECK_OK(ctx, tt_gdal_read_grid(ctx, GDALGetRasterBand(nd, 1), zo, NULL,
                                    NULL, &g, NULL));
    CSLDestroy(zo);
    tt_grid_destroy(g);
    GDALClose(nd);
  }

  /* The command: the summary names m, the CRS, the frame, valid samples. */
  char *argv[] = {"simplify", "-verbose", "-z_to", "m", "-max_error", "1",
                  (char *)path, (char *)tmp_path("sf.gpkg"), "-overwrite",
                  NULL};
  tt_app_options *opts = NULL;
  tt_app_result res;
  CHECK_INT_EQ(tt_app_options_new(argv, &opts, &res), TT_OK);
  FILE *out = tmpfile();
  if (opts && out) {
    tt_app_options_set_streams(opts, out, stderr);
    CHECK_INT_EQ(tt_app_run(opts, &res), TT_OK);
    char text[8192] = "";
    rewind(out);
    size_t n = fread(text, 1, sizeof text - 1, out);
    text[n] = '\0';
    printf("summary:\n%s", text);
    CHECK(strstr(text, "\nerror:  max ") && strstr(text, " m, within the "
                                                        "bound 1 m; RMS "));
    CHECK(strstr(text, "valid;") != NULL);
    CHECK(strstr(text, "; unnamed (like EPSG:26710); heights in ft, "
                       "converted to m (asked by -z_to m)\n") != NULL);
    CHECK(strstr(text, "\nframe:  geotransform") != NULL);
    CHECK(strstr(text, "(the band unit's ft times 0.3048: asked by -z_to "
                       "m)") != NULL);
  }
  if (out)
    fclose(out);
  tt_app_options_destroy(opts);
}

/* No band unit: the vertical part of a compound CRS says US survey feet
 * (NAD83 + NAVD88 height (ftUS), EPSG:4269+6360). */
static void test_vertical_crs(const char *path)
{
  GDALDatasetH src = GDALOpen(path, GA_ReadOnly);
  if (!src) {
    TT_FAIL_("cannot open %s", path);
    return;
  }
  GDALDatasetH d = GDALCreateCopy(GDALGetDriverByName("GTiff"),
                                  tmp_path("compound.tif"), src, FALSE, NULL,
                                  NULL, NULL);
  GDALClose(src);
  CHECK(d != NULL);
  if (!d)
    return;
  OGRSpatialReferenceH srs = OSRNewSpatialReference(NULL);
  CHECK(OSRSetFromUserInput(srs, "EPSG:4269+6360") == OGRERR_NONE);
  GDALSetSpatialRef(d, srs);
  GDALSetRasterUnitType(GDALGetRasterBand(d, 1), "");
  GDALClose(d);
  OSRDestroySpatialReference(srs);
  /* GTiff reports the vertical unit as the band's unit type; a VRT of it
   * without a unit type leaves only the CRS to say. */
  CPLSetConfigOption("GTIFF_REPORT_COMPD_CS", "YES");
  GDALDatasetH t = GDALOpen(tmp_path("compound.tif"), GA_ReadOnly);
  GDALDatasetH v = t ? GDALCreateCopy(GDALGetDriverByName("VRT"),
                                      tmp_path("compound.vrt"), t, FALSE,
                                      NULL, NULL, NULL)
                     : NULL;
  if (v) {
    GDALSetRasterUnitType(GDALGetRasterBand(v, 1), "");
    GDALClose(v);
  }
  if (t)
    GDALClose(t);
  tt_raster_info *info = NULL;
  char **o = CSLSetNameValue(NULL, "Z_UNIT", "m");
  tt_grid *g = read_dem(tmp_path("compound.tif"), o, &info);
  if (g) {
    printf("compound CRS GeoTIFF: band unit \"%s\" (%s), x%.12g to %s\n",
           info->z_unit_declared, info->z_unit_source, info->z_unit_factor,
           info->z_unit);
    CHECK_DBL_NEAR(info->z_unit_factor, 1200.0 / 3937.0, 1e-15);
    CHECK_STR_EQ(info->z_unit, "m");
  }
  tt_grid_destroy(g);
  tt_raster_info_destroy(info);
  info = NULL;
  g = read_dem(tmp_path("compound.vrt"), o, &info);
  CSLDestroy(o);
  CPLSetConfigOption("GTIFF_REPORT_COMPD_CS", NULL);
  if (g) {
    printf("compound CRS %s: heights declared in %s (%s), converted x%.12g "
           "to %s; frame %s\n", info->crs_name, info->z_unit_declared,
           info->z_unit_source, info->z_unit_factor, info->z_unit,
           info->frame_name);
    CHECK_STR_EQ(info->z_unit_declared, "us-ft");
    CHECK_STR_EQ(info->z_unit_source, "vertical CRS");
    CHECK_STR_EQ(info->z_unit, "m");
    CHECK_DBL_NEAR(info->z_unit_factor, 1200.0 / 3937.0, 1e-15);
    CHECK(strstr(info->frame_name, "UTM zone 16N") != NULL);
  }
  tt_grid_destroy(g);
  tt_raster_info_destroy(info);
}

int main(void)
{
  GDALAllRegister();
  ctx = tt_context_create();
  const char *td = getenv("TT_TESTDATA");
  const char *sd = getenv("TT_SHARED_TESTDATA");
  if (!td)
    TT_SKIP("TT_TESTDATA is not set");
  snprintf(tmpdir, sizeof tmpdir, "%s", "/tmp/tt_georef_XXXXXX");
  if (!mkdtemp(tmpdir)) {
    perror("mkdtemp");
    return 1;
  }
  char p[1024];
  snprintf(p, sizeof p, "%s/jacksboro_fault_dem.tif", td);
  /* The Jacobian frame is exact at the centre; away from it the error is
   * the trapezoid term (no affine map removes it) plus UTM's own scale
   * change (a few 1e-4). */
  double predicted = 0, inner = 0;
  double e = frame_vs_utm(p, "EPSG:32616", "UTM zone 16N (EPSG:32616)",
                          &predicted, &inner);
  CHECK_DBL_LE(e, 1.05 * predicted + 3e-4);
  CHECK_DBL_LE(inner, 1e-3);
  TT_RUN(test_jacksboro_tin(p));
  TT_RUN(test_warped(p));
  TT_RUN(test_vertical_crs(p));

  /* Twenty degrees: ground points in an oblique stereographic, named. */
  GDALDatasetH jd = GDALOpen(p, GA_ReadOnly);
  const char *targv[] = {"-of", "VRT", "-a_ullr", "-100", "50", "-80", "30",
                         NULL};
  GDALTranslateOptions *to = GDALTranslateOptionsNew((char **)targv, NULL);
  GDALDatasetH big = jd ? GDALTranslate(tmp_path("big.vrt"), jd, to, NULL)
                        : NULL;
  GDALTranslateOptionsFree(to);
  if (big)
    GDALClose(big);
  if (jd)
    GDALClose(jd);
  size_t warnings = tt_context_warning_count(ctx);
  tt_raster_info *bi = NULL;
  tt_grid *bg = read_dem(tmp_path("big.vrt"), NULL, &bi);
  if (bg) {
    /* per vertex in an oblique stereographic: no warning, the scale
     * error over the whole DEM in the name */
    printf("20-degree grid: frame %s\n", bi->frame_name);
    CHECK(strstr(bi->frame_name, "oblique stereographic") != NULL);
    CHECK(strstr(bi->frame_name, "% off over the whole DEM") != NULL);
    CHECK_INT_EQ(tt_context_warning_count(ctx), warnings);
  }
  tt_grid_destroy(bg);
  tt_raster_info_destroy(bi);

  struct stat st;
  if (sd && stat(sd, &st) == 0) {
    snprintf(p, sizeof p, "%s/gdal_autotest/n43.dt0", sd);
    e = frame_vs_utm(p, "EPSG:32617", "UTM zone 17N (EPSG:32617)",
                     &predicted, &inner);
    /* a whole degree: the trapezoid term is 8e-3 at the edges */
    CHECK_DBL_LE(e, 1.05 * predicted + 3e-4);
    CHECK_DBL_LE(inner, 5e-3);
    snprintf(p, sizeof p, "%s/gdal_autotest/warp_52_dem.tif", sd);
    test_web_mercator(p);
    snprintf(p, sizeof p, "%s/usgs_dem_san_francisco/sanfranciscos.dem", sd);
    test_feet(p);
  } else {
    printf("shared test data absent: n43.dt0, warp_52_dem.tif and "
           "sanfranciscos.dem skipped\n");
  }

  /* clean up */
  char **files = VSIReadDir(tmpdir);
  for (char **f = files; f && *f; f++)
    if (strcmp(*f, ".") && strcmp(*f, ".."))
      unlink(tmp_path(*f));
  CSLDestroy(files);
  rmdir(tmpdir);
  tt_context_destroy(ctx);
  TT_TEST_DONE();
}
