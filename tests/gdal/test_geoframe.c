/* test_geoframe.c -- geographic DEMs measured on the ground through ground
 * points in a conformal frame (src/gdal/georef/georef_conformal.c, issue 18),
 * checked against PROJ and GeographicLib themselves:
 *  - an SRTM-like crop at 57 N (350 x 400 samples of 1 arc-second, heights
 *    generated here): every interior edge of the Delaunay TIN is Delaunay
 *    within 1e-9 (relative to the circumradius) in the frame terratin
 *    reports, and the frame's distortion against true UTM (PROJ, here) is
 *    measured; the same grid through today's affine frame (ground points
 *    dropped) for the count of its violations in true UTM and the cost;
 *  - a 10 x 7.5 degree one-arc-minute grid (a Lambert conformal conic):
 *    triangle areas against geod_polygonarea on the corners, the output's
 *    geodesic areas, slopes against slopes fitted on the ellipsoid (local
 *    east/north from geodesics at the triangle's centroid);
 *  - a plane tilted on the ground over 60 degrees of latitude (heights
 *    proportional to the meridian arc, so every true slope is the same):
 *    one slope, and aspect south, everywhere; the same plane on a Web
 *    Mercator grid (EPSG:3857, scale 1 to 2 over it): one slope again, and
 *    areas and slopes against GeographicLib on PROJ's longitudes and
 *    latitudes of the vertices;
 *  - a DEM in US survey feet (EPSG:2277) and the same samples in metres
 *    (EPSG:32139, the same projection): the same triangles, areas and
 *    slopes; with heights in feet too (band unit us-ft, Z_UNIT=m), the
 *    same slopes.
 * Figures go to stdout (ctest -V). */
#include "gdal/ogr/tin_records.h"
#include "terratin/terratin_gdal.h"
#include "terratin_lib.h"
#include "tt_test.h"

#include <cpl_conv.h>
#include <gdal.h>
#include <geodesic.h>

#include <time.h>

#define PI 3.14159265358979323846

static tt_context *ctx;
static struct geod_geodesic wgs84;

static double now(void)
{
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* A WGS 84 longitude/latitude grid of nx x ny samples of step degrees from
 * (lon0, lat_top), heights from z(lon, lat), read through the glue. */
static tt_grid *make_dem(size_t nx, size_t ny, double lon0, double lat_top,
                         double step, double (*z)(double, double),
                         tt_raster_info **out_info)
{
  GDALDriverH mem = GDALGetDriverByName("MEM");
  GDALDatasetH ds = mem ? GDALCreate(mem, "", (int)nx, (int)ny, 1,
                                     GDT_Float64, NULL)
                        : NULL;
  if (!ds) {
    TT_FAIL_("cannot make a MEM dataset");
    return NULL;
  }
  double gt[6] = {lon0, step, 0, lat_top, 0, -step};
  GDALSetGeoTransform(ds, gt);
  OGRSpatialReferenceH srs = OSRNewSpatialReference(NULL);
  OSRImportFromEPSG(srs, 4326);
  GDALSetSpatialRef(ds, srs);
  OSRDestroySpatialReference(srs);
  double *row = malloc(nx * sizeof *row);
  GDALRasterBandH band = GDALGetRasterBand(ds, 1);
  for (size_t r = 0; r < ny && row; r++) {
    for (size_t c = 0; c < nx; c++)
      row[c] = z(lon0 + (c + 0.5) * step, lat_top - (r + 0.5) * step);
    CHECK(GDALRasterIO(band, GF_Write, 0, (int)r, (int)nx, 1, row, (int)nx,
                       1, GDT_Float64, 0, 0) == CE_None);
  }
  free(row);
  tt_grid *g = NULL;
  CHECK_OK(ctx, tt_gdal_read_grid(ctx, band, NULL, NULL, NULL, &g,
                                  out_info));
  GDALClose(ds);
  if (g)
    printf("%zu x %zu grid at (%.4f, %.4f), %.6f degree: frame %s\n", nx,
           ny, lon0, lat_top, step, (*out_info)->frame_name);
  return g;
}

/* max_error < 0: every sample a vertex */
static tt_tin *refine(const tt_grid *g, double max_error, double *seconds)
{
  tt_refine_options ro;
  tt_refine_options_init(&ro);
  ro.max_error = max_error;
  if (max_error < 0)
    ro.percent = 100;
  ro.criterion = TT_CRITERION_DELAUNAY;
  tt_tin *tin = NULL;
  double t0 = now();
  CHECK_OK(ctx, tt_refine_run(ctx, g, &ro, &tin));
  if (seconds)
    *seconds = now() - t0;
  return tin;
}

/* Integer-valued rolling hills with a little noise, like an SRTM tile. */
static double srtm_like(double lon, double lat)
{
  double x = lon * 3600, y = lat * 3600;
  uint64_t h = (uint64_t)(int64_t)floor(x) * 0x9E3779B97F4A7C15u ^
               (uint64_t)(int64_t)floor(y) * 0xC2B2AE3D27D4EB4Fu;
  h ^= h >> 29;
  double noise = (double)(h % 1000) / 1000.0;
  return floor(400 + 180 * sin(x / 41) * cos(y / 29) +
               60 * sin((x + 2 * y) / 13) + 4 * noise);
}

typedef struct edge_rec {
  int32_t a, b, opp;
} edge_rec;

static int edge_cmp(const void *p, const void *q)
{
  const edge_rec *x = p, *y = q;
  if (x->a != y->a)
    return x->a < y->a ? -1 : 1;
  return x->b < y->b ? -1 : x->b > y->b;
}

/* How far d is inside the circle through a, b, c, relative to its radius
 * (positive: inside), coordinates relative to a for precision. */
static double inside(const double *a, const double *b, const double *c,
                     const double *d)
{
  double bx = b[0] - a[0], by = b[1] - a[1];
  double cx = c[0] - a[0], cy = c[1] - a[1];
  double dx = d[0] - a[0], dy = d[1] - a[1];
  double den = 2 * (bx * cy - by * cx);
  double ux = (cy * (bx * bx + by * by) - by * (cx * cx + cy * cy)) / den;
  double uy = (bx * (cx * cx + cy * cy) - cx * (bx * bx + by * by)) / den;
  double rad = hypot(ux, uy);
  return (rad - hypot(dx - ux, dy - uy)) / rad;
}

/* The largest relative incircle excess over the interior edges for the
 * vertex coordinates xy; counts those above tol. */
static double delaunay_excess(const tt_tin *tin, const double *xy,
                              double tol, size_t *out_over,
                              size_t *out_interior)
{
  size_t nt = tt_tin_triangle_count(tin), n = 0;
  edge_rec *e = malloc(3 * nt * sizeof *e);
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
  double worst = -INFINITY;
  *out_over = *out_interior = 0;
  for (size_t i = 0; i + 1 < n; i++) {
    if (edge_cmp(&e[i], &e[i + 1]) != 0)
      continue;
    (*out_interior)++;
    const double *pa = xy + 2 * (size_t)e[i].a, *pb = xy + 2 * (size_t)e[i].b;
    double x = inside(pa, pb, xy + 2 * (size_t)e[i].opp,
                      xy + 2 * (size_t)e[i + 1].opp);
    worst = fmax(worst, x);
    if (x > tol)
      (*out_over)++;
    i++;
  }
  free(e);
  return worst;
}

/* Vertex coordinates: the grid's ground points, or PROJ's UTM (epsg). */
static double *vertex_ground_xy(tt_grid *g, const tt_tin *tin)
{
  size_t nv = tt_tin_vertex_count(tin), nx = tt_grid_width(g);
  const double *gxy = tt_grid_ground_xy(g);
  double *xy = malloc(2 * nv * sizeof *xy);
  for (size_t i = 0; i < nv; i++) {
    tt_vertex_info v;
    tt_tin_vertex(tin, i, &v);
    size_t s = v.row * nx + v.col;
    xy[2 * i] = gxy[2 * s];
    xy[2 * i + 1] = gxy[2 * s + 1];
  }
  return xy;
}

static double *vertex_utm_xy(const tt_tin *tin, int epsg)
{
  size_t nv = tt_tin_vertex_count(tin);
  double *x = malloc(nv * sizeof *x), *y = malloc(nv * sizeof *y);
  double *xy = malloc(2 * nv * sizeof *xy);
  for (size_t i = 0; i < nv; i++) {
    tt_vertex_info v;
    tt_tin_vertex(tin, i, &v);
    x[i] = v.x;
    y[i] = v.y;
  }
  OGRSpatialReferenceH a = OSRNewSpatialReference(NULL);
  OGRSpatialReferenceH b = OSRNewSpatialReference(NULL);
  OSRImportFromEPSG(a, 4326);
  OSRImportFromEPSG(b, epsg);
  OSRSetAxisMappingStrategy(a, OAMS_TRADITIONAL_GIS_ORDER);
  OSRSetAxisMappingStrategy(b, OAMS_TRADITIONAL_GIS_ORDER);
  OGRCoordinateTransformationH ct = OCTNewCoordinateTransformation(a, b);
  CHECK(ct && OCTTransform(ct, (int)nv, x, y, NULL));
  for (size_t i = 0; i < nv; i++) {
    xy[2 * i] = x[i];
    xy[2 * i + 1] = y[i];
  }
  if (ct)
    OCTDestroyCoordinateTransformation(ct);
  OSRDestroySpatialReference(a);
  OSRDestroySpatialReference(b);
  free(x);
  free(y);
  return xy;
}

static void test_srtm_57n(void)
{
  tt_raster_info *info = NULL;
  const double step = 1.0 / 3600;
  tt_grid *g = make_dem(350, 400, -4.05, 57.1, step, srtm_like, &info);
  if (!g)
    return;
  CHECK(strstr(info->frame_name, "UTM zone 30N") != NULL);
  CHECK(strstr(info->frame_name, "per vertex") != NULL);
  CHECK(info->frame_scale_error > 0 && info->frame_scale_error < 1e-3);
  double t_points = 0, t_affine = 0;
  tt_tin *tin = refine(g, 1.0, &t_points);
  if (!tin)
    goto done;
  size_t over = 0, interior = 0;
  double *fxy = vertex_ground_xy(g, tin);
  double *uxy = vertex_utm_xy(tin, 32630);
  double worst = delaunay_excess(tin, fxy, 1e-9, &over, &interior);
  printf("  ground points: %zu triangles, %zu interior edges; largest "
         "incircle excess in the frame %.3g, edges over 1e-9: %zu\n",
         tt_tin_triangle_count(tin), interior, worst, over);
  CHECK_INT_EQ(over, 0);
  CHECK(interior > 100000);
  /* the frame against PROJ's own UTM 30N coordinates of the vertices */
  double dist = 0;
  size_t nv = tt_tin_vertex_count(tin);
  for (size_t i = 1; i < nv; i++) {
    double df = hypot(fxy[2 * i] - fxy[0], fxy[2 * i + 1] - fxy[1]);
    double du = hypot(uxy[2 * i] - uxy[0], uxy[2 * i + 1] - uxy[1]);
    dist = fmax(dist, fabs(df / du - 1));
    dist = fmax(dist, fabs(fxy[2 * i] - uxy[2 * i]) /
                          fmax(1.0, fabs(uxy[2 * i])));
  }
  double wu = delaunay_excess(tin, uxy, 1e-9, &over, &interior);
  printf("  frame vs true UTM 30N: largest relative distance difference "
         "%.3g; in true UTM: largest excess %.3g, over 1e-9: %zu\n", dist,
         wu, over);
  CHECK_DBL_LE(dist, 1e-12);
  CHECK_INT_EQ(over, 0);
  free(fxy);

  /* Decimation's removals are repaired by the same incircle test: its
   * Delaunay TIN is Delaunay in the frame too (to a vertex budget: under
   * an error bound a flip that would break it is refused). */
  tt_decimate_options dopt;
  tt_decimate_options_init(&dopt);
  dopt.percent = 5;
  dopt.start = TT_DSTART_GREEDY;
  dopt.selection = TT_SELECTION_SEQUENTIAL;
  tt_tin *dec = NULL;
  CHECK_OK(ctx, tt_decimate_run(ctx, g, &dopt, &dec));
  if (dec) {
    double *dxy = vertex_ground_xy(g, dec);
    double wd = delaunay_excess(dec, dxy, 1e-9, &over, &interior);
    printf("  decimated: %zu triangles, %zu interior edges; largest excess "
           "in the frame %.3g, over 1e-9: %zu\n", tt_tin_triangle_count(dec),
           interior, wd, over);
    CHECK_INT_EQ(over, 0);
    CHECK(interior > 1000);
    free(dxy);
    tt_tin_destroy(dec);
  }

  /* today's path: the affine frame (the UTM Jacobian at the centre) */
  tt_grid_drop_ground_points(g);
  tt_tin *affine = refine(g, 1.0, &t_affine);
  if (affine) {
    double *axy = vertex_utm_xy(affine, 32630);
    double wa = delaunay_excess(affine, axy, 1e-9, &over, &interior);
    printf("  affine frame: %zu triangles; in true UTM %zu of %zu interior "
           "edges over 1e-9, largest excess %.3g\n",
           tt_tin_triangle_count(affine), over, interior, wa);
    CHECK(over > 0);
    free(axy);
  }
  printf("  cost: refine %.3f s with ground points, %.3f s affine (%+.1f%%);"
         " ground points 16 bytes a sample = %.2f MB here\n", t_points,
         t_affine, 100 * (t_points / t_affine - 1),
         16.0 * 350 * 400 / 1e6);
  free(uxy);
  tt_tin_destroy(affine);
  tt_tin_destroy(tin);
done:
  tt_grid_destroy(g);
  tt_raster_info_destroy(info);
}

/* A smooth sea floor: kilometres of relief over degrees. */
static double sea_floor(double lon, double lat)
{
  return -3000 + 1200 * sin(lon * 0.9) * cos(lat * 1.3) +
         400 * sin((lon + lat) * 3.1);
}

/* The slope (tan) and aspect (degrees) of the plane through the corners
 * on the ellipsoid: each corner's local east/north offset from the
 * triangle's centroid by a geodesic from it. */
static void ellipsoid_slope(const double lon[3], const double lat[3],
                            const double z[3], double *out_tan,
                            double *out_aspect)
{
  double clon = (lon[0] + lon[1] + lon[2]) / 3;
  double clat = (lat[0] + lat[1] + lat[2]) / 3;
  double e[3], n[3];
  for (int k = 0; k < 3; k++) {
    double s12 = 0, az1 = 0, az2 = 0;
    geod_inverse(&wgs84, clat, clon, lat[k], lon[k], &s12, &az1, &az2);
    e[k] = s12 * sin(az1 * PI / 180);
    n[k] = s12 * cos(az1 * PI / 180);
  }
  double ux = e[1] - e[0], uy = n[1] - n[0], uz = z[1] - z[0];
  double vx = e[2] - e[0], vy = n[2] - n[0], vz = z[2] - z[0];
  double nx = uy * vz - uz * vy, ny = uz * vx - ux * vz, nz = ux * vy - uy * vx;
  double gx = -nx / nz, gy = -ny / nz;
  *out_tan = hypot(gx, gy);
  double az = atan2(-gx, -gy) * 180 / PI;
  *out_aspect = az < 0 ? az + 360 : az;
}

static double angle_diff(double a, double b)
{
  double d = fmod(fabs(a - b), 360.0);
  return d > 180 ? 360 - d : d;
}

/* Area and slope checks of every triangle of tin (vertex lon/lat in the
 * vertex records); out_plane: the largest relative difference between the
 * geodesic area and the plane triangle of the ground points divided by
 * the mean corner scale squared (the frame's own area). */
static void check_triangles(tt_grid *g, const tt_tin *tin, double area_tol,
                            double slope_tol, double *out_area,
                            double *out_slope, double *out_aspect,
                            double *out_plane)
{
  *out_area = *out_slope = *out_aspect = *out_plane = 0;
  const double *gxy = tt_grid_ground_xy(g);
  size_t nx = tt_grid_width(g);
  for (size_t t = 0; t < tt_tin_triangle_count(tin); t++) {
    tt_triangle_info ti;
    tt_tin_triangle(tin, t, &ti);
    double lon[3], lat[3], z[3], px[3], py[3], k = 0;
    for (int j = 0; j < 3; j++) {
      tt_vertex_info v;
      tt_tin_vertex(tin, (size_t)ti.v[j], &v);
      lon[j] = v.x;
      lat[j] = v.y;
      z[j] = v.z;
      size_t i = (size_t)v.row * nx + (size_t)v.col;
      px[j] = gxy[2 * i];
      py[j] = gxy[2 * i + 1];
      double ki = 0, conv = 0;
      CHECK_INT_EQ(tt_grid_ground_scale_at(g, (size_t)v.col, (size_t)v.row,
                                           &ki, &conv), TT_OK);
      k += ki / 3.0;
    }
    double area = 0, perim = 0;
    geod_polygonarea(&wgs84, lat, lon, 3, &area, &perim);
    *out_area = fmax(*out_area, fabs(ti.area_2d / fabs(area) - 1));
    double plane = 0.5 * fabs((px[1] - px[0]) * (py[2] - py[0]) -
                              (py[1] - py[0]) * (px[2] - px[0])) / (k * k);
    *out_plane = fmax(*out_plane, fabs(plane / fabs(area) - 1));
    double tn = 0, asp = 0;
    ellipsoid_slope(lon, lat, z, &tn, &asp);
    double mine = tan(ti.slope_deg * PI / 180);
    if (tn > 1e-6) {
      *out_slope = fmax(*out_slope, fabs(mine / tn - 1));
      *out_aspect = fmax(*out_aspect, angle_diff(ti.aspect_deg, asp));
    }
  }
  CHECK_DBL_LE(*out_area, area_tol);
  CHECK_DBL_LE(*out_slope, slope_tol);
}

static void test_ten_degrees(void)
{
  tt_raster_info *info = NULL;
  const double step = 1.0 / 60;
  tt_grid *g = make_dem(600, 450, -40.0, 60.0, step, sea_floor, &info);
  if (!g)
    return;
  /* 10 x 7.5 degrees at 56 N is taller than wide on the ground */
  CHECK(strstr(info->frame_name, "oblique stereographic") != NULL);
  printf("  largest scale error %.3g\n", info->frame_scale_error);
  CHECK(info->frame_scale_error < 2e-3);
  double area = 0, slope = 0, aspect = 0, plane = 0;
  /* every sample a vertex: triangles of an arc-minute, where the plane
   * triangle of the projection and the geodesic one agree */
  tt_tin *full = refine(g, -1, NULL);
  if (full) {
    check_triangles(g, full, 1e-6, 1e-3, &area, &slope, &aspect, &plane);
    printf("  all samples, %zu triangles: area vs geod_polygonarea %.3g "
           "(the frame's plane area / k^2: %.3g), slope vs the ellipsoid's "
           "%.3g, aspect %.3g degree\n", tt_tin_triangle_count(full), area,
           plane, slope, aspect);
    CHECK_DBL_LE(aspect, 0.05);
    /* the scale factors are right: an arc-minute plane triangle differs
     * from the geodesic one by its sides' curvature only */
    CHECK_DBL_LE(plane, 1e-5);
  }
  tt_tin_destroy(full);
  tt_tin *tin = refine(g, 5.0, NULL);
  if (!tin)
    goto done;
  /* simplified: triangles up to degrees wide, where the frame's plane
   * area drifts from the geodesic triangle's (reported); the TIN's areas
   * are geodesic (tt_grid_set_area_fn), as are the output's (below) */
  check_triangles(g, tin, 1e-12, 1e-3, &area, &slope, &aspect, &plane);
  printf("  max_error 5, %zu triangles: area vs geod_polygonarea %.3g (the "
         "frame's plane area / k^2: %.3g), slope vs the ellipsoid's %.3g, "
         "aspect %.3g degree\n", tt_tin_triangle_count(tin), area, plane,
         slope, aspect);
  /* the output's areas: geodesic whatever the output CRS */
  OGRSpatialReferenceH srs = OSRNewSpatialReference(NULL);
  OSRImportFromEPSG(srs, 4326);
  const char *t_srs[2] = {NULL, "EPSG:3035"};
  for (int k = 0; k < 2; k++) {
    tt__records rec;
    CHECK_OK(ctx, tt__records_init(&rec, ctx, tin, srs, t_srs[k]));
    double worst = 0;
    for (size_t t = 0; t < tt_tin_triangle_count(tin); t += 97) {
      tt_triangle_info ti;
      tt_vertex_info v;
      double x[3], y[3], z[3], lat[3], lon[3], a = 0, p = 0;
      CHECK_OK(ctx, tt__records_triangle(&rec, ctx, t, &ti, x, y, z));
      for (int j = 0; j < 3; j++) {
        CHECK_OK(ctx, tt_tin_vertex(tin, (size_t)ti.v[j], &v));
        lon[j] = v.x;
        lat[j] = v.y;
      }
      geod_polygonarea(&wgs84, lat, lon, 3, &a, &p);
      worst = fmax(worst, fabs(ti.area_2d / fabs(a) - 1));
    }
    printf("  output areas (%s): vs geodesic %.3g\n",
           t_srs[k] ? t_srs[k] : "input CRS", worst);
    CHECK_DBL_LE(worst, 1e-12);
    tt__records_free(&rec);
  }
  OSRDestroySpatialReference(srs);
  tt_tin_destroy(tin);
done:
  tt_grid_destroy(g);
  tt_raster_info_destroy(info);
}

/* Heights 1e-4 of the meridian arc from the equator: a ground slope of
 * 1e-4 everywhere, downhill due south (to 1e-4, the noise below). */
static double tilted(double lon, double lat)
{
  double s12 = 0, a1 = 0, a2 = 0;
  geod_inverse(&wgs84, 0.0, lon, lat, lon, &s12, &a1, &a2);
  /* +-1e-4 m of deterministic noise (1e-4 of a cell's rise) puts every
   * sample off its neighbours' plane, so that every one becomes a vertex
   * and the triangles stay a cell wide */
  double noise = 1e-4 * sin(lon * 7919.0 + lat * 104729.0);
  return 1e-4 * s12 * (lat < 0 ? -1 : 1) + noise;
}

/* A one-band Float64 MEM dataset of nx x ny heights z in CRS epsg with
 * geotransform gt (band unit unit, or none), read through the glue with
 * options opts. */
static tt_grid *read_mem(size_t nx, size_t ny, const double gt[6], int epsg,
                         const double *z, const char *unit, char **opts,
                         tt_raster_info **out_info)
{
  GDALDriverH mem = GDALGetDriverByName("MEM");
  GDALDatasetH ds = mem ? GDALCreate(mem, "", (int)nx, (int)ny, 1,
                                     GDT_Float64, NULL)
                        : NULL;
  if (!ds) {
    TT_FAIL_("cannot make a MEM dataset");
    return NULL;
  }
  GDALSetGeoTransform(ds, (double *)gt);
  OGRSpatialReferenceH srs = OSRNewSpatialReference(NULL);
  OSRImportFromEPSG(srs, epsg);
  GDALSetSpatialRef(ds, srs);
  OSRDestroySpatialReference(srs);
  GDALRasterBandH band = GDALGetRasterBand(ds, 1);
  if (unit)
    GDALSetRasterUnitType(band, unit);
  CHECK(GDALRasterIO(band, GF_Write, 0, 0, (int)nx, (int)ny, (void *)z,
                     (int)nx, (int)ny, GDT_Float64, 0, 0) == CE_None);
  tt_grid *g = NULL;
  CHECK_OK(ctx, tt_gdal_read_grid(ctx, band, opts, NULL, NULL, &g,
                                  out_info));
  GDALClose(ds);
  if (g)
    printf("%zu x %zu grid in EPSG:%d: frame %s\n", nx, ny, epsg,
           (*out_info)->frame_name);
  return g;
}

/* PROJ's longitudes and latitudes (degrees) of n points of CRS epsg. */
static void to_wgs84(int epsg, size_t n, double *x, double *y)
{
  OGRSpatialReferenceH a = OSRNewSpatialReference(NULL);
  OGRSpatialReferenceH b = OSRNewSpatialReference(NULL);
  OSRImportFromEPSG(a, epsg);
  OSRImportFromEPSG(b, 4326);
  OSRSetAxisMappingStrategy(a, OAMS_TRADITIONAL_GIS_ORDER);
  OSRSetAxisMappingStrategy(b, OAMS_TRADITIONAL_GIS_ORDER);
  OGRCoordinateTransformationH ct = OCTNewCoordinateTransformation(a, b);
  CHECK(ct && OCTTransform(ct, (int)n, x, y, NULL));
  if (ct)
    OCTDestroyCoordinateTransformation(ct);
  OSRDestroySpatialReference(a);
  OSRDestroySpatialReference(b);
}

static void test_sixty_degrees(void)
{
  tt_raster_info *info = NULL;
  tt_grid *g = make_dem(40, 600, 10.0, 60.0, 0.1, tilted, &info);
  if (!g)
    return;
  printf("  largest scale error %.3g\n", info->frame_scale_error);
  /* every sample a vertex: a simplified TIN of a plane keeps triangles
   * degrees long along the parallels, whose curvature on the ground no
   * plane triangle follows */
  tt_tin *tin = refine(g, -1, NULL);
  if (!tin)
    goto done;
  double lo = INFINITY, hi = 0, asp = 0;
  for (size_t t = 0; t < tt_tin_triangle_count(tin); t++) {
    tt_triangle_info ti;
    tt_tin_triangle(tin, t, &ti);
    double s = tan(ti.slope_deg * PI / 180);
    lo = fmin(lo, s);
    hi = fmax(hi, s);
    asp = fmax(asp, angle_diff(ti.aspect_deg, 180.0));
  }
  printf("  %zu triangles: slope %.7g to %.7g (spread %.3g), aspect within "
         "%.3g degree of south\n", tt_tin_triangle_count(tin), lo, hi,
         hi / lo - 1, asp);
  CHECK_DBL_LE(hi / 1e-4 - 1, 1e-3);
  CHECK_DBL_LE(1 - lo / 1e-4, 1e-3);
  CHECK_DBL_LE(asp, 0.1);
  tt_tin_destroy(tin);
done:
  tt_grid_destroy(g);
  tt_raster_info_destroy(info);
}

/* The tilted plane of test_sixty_degrees on a Web Mercator grid: 10-14 E,
 * 0-60 N, 40 x 600 samples (the scale of the map grows from 1 to 2 over
 * it). Every sample a vertex: one slope, aspect south; every triangle's
 * area the geodesic one, and its slope the ellipsoid's, on PROJ's
 * longitudes and latitudes of its corners. */
static void test_web_mercator(void)
{
  const double R = 6378137.0, d2r = PI / 180;
  const size_t nx = 40, ny = 600;
  double x0 = 10 * d2r * R, x1 = 14 * d2r * R;
  double y1 = R * log(tan(PI / 4 + 30 * d2r));
  const double gt[6] = {x0, (x1 - x0) / nx, 0, y1, 0, -y1 / ny};
  double *z = malloc(nx * ny * sizeof *z), *lx = malloc(nx * sizeof *lx),
         *ly = malloc(nx * sizeof *ly);
  for (size_t r = 0; r < ny; r++) {
    for (size_t c = 0; c < nx; c++) {
      lx[c] = gt[0] + (c + 0.5) * gt[1];
      ly[c] = gt[3] + (r + 0.5) * gt[5];
    }
    to_wgs84(3857, nx, lx, ly);
    for (size_t c = 0; c < nx; c++)
      z[r * nx + c] = tilted(lx[c], ly[c]);
  }
  tt_raster_info *info = NULL;
  tt_grid *g = read_mem(nx, ny, gt, 3857, z, NULL, NULL, &info);
  free(lx);
  free(ly);
  free(z);
  if (!g)
    return;
  CHECK(strstr(info->frame_name, "per vertex") != NULL);
  CHECK(tt_grid_ground_xy(g) != NULL);
  tt_tin *tin = refine(g, -1, NULL);
  if (!tin)
    goto done;
  size_t nt = tt_tin_triangle_count(tin), nv = tt_tin_vertex_count(tin);
  double *vx = malloc(nv * sizeof *vx), *vy = malloc(nv * sizeof *vy),
         *vz = malloc(nv * sizeof *vz);
  for (size_t i = 0; i < nv; i++) {
    tt_vertex_info v;
    tt_tin_vertex(tin, i, &v);
    vx[i] = v.x;
    vy[i] = v.y;
    vz[i] = v.z;
  }
  to_wgs84(3857, nv, vx, vy);
  double lo = INFINITY, hi = 0, asp = 0, darea = 0, dslope = 0;
  for (size_t t = 0; t < nt; t++) {
    tt_triangle_info ti;
    tt_tin_triangle(tin, t, &ti);
    double s = tan(ti.slope_deg * PI / 180);
    lo = fmin(lo, s);
    hi = fmax(hi, s);
    asp = fmax(asp, angle_diff(ti.aspect_deg, 180.0));
    double lon[3], lat[3], zz[3], area = 0, perim = 0, tn = 0, a2 = 0;
    for (int j = 0; j < 3; j++) {
      lon[j] = vx[ti.v[j]];
      lat[j] = vy[ti.v[j]];
      zz[j] = vz[ti.v[j]];
    }
    geod_polygonarea(&wgs84, lat, lon, 3, &area, &perim);
    darea = fmax(darea, fabs(ti.area_2d / fabs(area) - 1));
    ellipsoid_slope(lon, lat, zz, &tn, &a2);
    dslope = fmax(dslope, fabs(s / tn - 1));
  }
  printf("  %zu triangles: slope %.7g to %.7g (spread %.3g), aspect within "
         "%.3g degree of south; areas within %.3g of geodesic, slopes "
         "within %.3g of the ellipsoid's\n", nt, lo, hi, hi / lo - 1, asp,
         darea, dslope);
  CHECK_DBL_LE(hi / 1e-4 - 1, 1e-3);
  CHECK_DBL_LE(1 - lo / 1e-4, 1e-3);
  CHECK_DBL_LE(asp, 0.1);
  CHECK_DBL_LE(darea, 1e-9);
  CHECK_DBL_LE(dslope, 1e-3);
  free(vx);
  free(vy);
  free(vz);
  tt_tin_destroy(tin);
done:
  tt_grid_destroy(g);
  tt_raster_info_destroy(info);
}

/* The same samples in US survey feet (EPSG:2277, NAD83 / Texas Central
 * ftUS) and in metres (EPSG:32139, the same projection): the same TIN,
 * areas and slopes; and with the heights in (international) feet as well
 * (band unit ft, converted by Z_UNIT=m), the same again. */
static void test_feet(void)
{
  const double ft = 1200.0 / 3937.0; /* metres per US survey foot */
  const size_t nx = 300, ny = 240;
  const double gtf[6] = {2950000.0, 100.0, 0, 10100000.0, 0, -100.0};
  const double gtm[6] = {gtf[0] * ft, gtf[1] * ft, 0, gtf[3] * ft, 0,
                         gtf[5] * ft};
  double *z = malloc(nx * ny * sizeof *z), *zf = malloc(nx * ny * sizeof *zf);
  for (size_t r = 0; r < ny; r++)
    for (size_t c = 0; c < nx; c++) {
      /* integer feet, and their metres as the reader converts them */
      zf[r * nx + c] = srtm_like(-97.5 + c * 0.0003, 30.5 + r * 0.0003);
      z[r * nx + c] = zf[r * nx + c] * 0.3048;
    }
  tt_raster_info *im = NULL, *iff = NULL, *izf = NULL;
  char *zopts[] = {"Z_UNIT=m", NULL};
  tt_grid *gm = read_mem(nx, ny, gtm, 32139, z, NULL, NULL, &im);
  tt_grid *gf = read_mem(nx, ny, gtf, 2277, z, NULL, NULL, &iff);
  tt_grid *gz = read_mem(nx, ny, gtf, 2277, zf, "ft", zopts, &izf);
  free(z);
  free(zf);
  tt_tin *tm = gm ? refine(gm, 2.0, NULL) : NULL;
  tt_tin *tf = gf ? refine(gf, 2.0, NULL) : NULL;
  tt_tin *tz = gz ? refine(gz, 2.0, NULL) : NULL;
  if (!tm || !tf || !tz)
    goto done;
  CHECK(strstr(iff->frame_name, "m per US survey foot") != NULL);
  CHECK(tt_grid_ground_xy(gf) == NULL);
  CHECK_INT_EQ(tt_tin_triangle_count(tf), tt_tin_triangle_count(tm));
  size_t nt = tt_tin_triangle_count(tm), same = 0;
  double darea = 0, dslope = 0, dzslope = 0, darea3 = 0;
  for (size_t t = 0; t < nt && t < tt_tin_triangle_count(tf) &&
                     t < tt_tin_triangle_count(tz); t++) {
    tt_triangle_info a, b, c;
    tt_tin_triangle(tm, t, &a);
    tt_tin_triangle(tf, t, &b);
    tt_tin_triangle(tz, t, &c);
    same += a.v[0] == b.v[0] && a.v[1] == b.v[1] && a.v[2] == b.v[2] &&
            a.v[0] == c.v[0] && a.v[1] == c.v[1] && a.v[2] == c.v[2];
    darea = fmax(darea, fabs(b.area_2d / a.area_2d - 1));
    darea3 = fmax(darea3, fabs(b.area_3d / a.area_3d - 1));
    if (a.slope_deg > 0.01) {
      dslope = fmax(dslope, fabs(b.slope_deg / a.slope_deg - 1));
      dzslope = fmax(dzslope, fabs(c.slope_deg / a.slope_deg - 1));
    }
  }
  printf("  feet: %zu of %zu triangles the same as in metres (heights in "
         "feet too: %zu triangles); areas within %.3g (3-D %.3g), slopes "
         "within %.3g (heights in feet too: %.3g)\n", same, nt,
         tt_tin_triangle_count(tz), darea, darea3, dslope, dzslope);
  CHECK_INT_EQ(same, nt);
  CHECK_DBL_LE(darea, 1e-12);
  CHECK_DBL_LE(darea3, 1e-12);
  CHECK_DBL_LE(dslope, 1e-12);
  CHECK_DBL_LE(dzslope, 1e-12);
done:
  tt_tin_destroy(tm);
  tt_tin_destroy(tf);
  tt_tin_destroy(tz);
  tt_grid_destroy(gm);
  tt_grid_destroy(gf);
  tt_grid_destroy(gz);
  tt_raster_info_destroy(im);
  tt_raster_info_destroy(iff);
  tt_raster_info_destroy(izf);
}

/* The frame for the extent, and its scale error over the DEM. */
static void test_frame_choice(void)
{
  static const struct {
    double lon0, lat_top, step;
    size_t nx, ny;
    const char *want;
    double max_error;
  } cases[] = {
      {-100.0, 50.0, 0.25, 80, 20, "Lambert conformal conic", 4e-3},
      {20.0, 3.0, 0.25, 80, 24, "Mercator", 4e-3},
      {-30.0, 90.0, 0.25, 120, 24, "polar stereographic (north pole", 1e-2},
      {170.0, -80.5, 0.25, 40, 30, "polar stereographic (south pole", 1e-2},
      {8.0, 48.0, 0.1, 40, 40, "UTM zone 32N (EPSG:32632)", 1e-3},
  };
  for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
    tt_raster_info *info = NULL;
    tt_grid *g = make_dem(cases[i].nx, cases[i].ny, cases[i].lon0,
                          cases[i].lat_top, cases[i].step, sea_floor, &info);
    if (!g)
      continue;
    if (!strstr(info->frame_name, cases[i].want))
      TT_FAIL_("frame \"%s\" is not %s", info->frame_name, cases[i].want);
    CHECK_DBL_LE(info->frame_scale_error, cases[i].max_error);
    /* the TIN's slopes are finite and its triangles have area */
    tt_tin *tin = refine(g, 50.0, NULL);
    for (size_t t = 0; tin && t < tt_tin_triangle_count(tin); t++) {
      tt_triangle_info ti;
      tt_tin_triangle(tin, t, &ti);
      CHECK(ti.area_2d > 0 && isfinite(ti.slope_deg));
    }
    tt_tin_destroy(tin);
    tt_grid_destroy(g);
    tt_raster_info_destroy(info);
  }
}

/* Over MAX_MEMORY with the ground points, the affine frame stays. */
static void test_memory_limit(void)
{
  const char *td = getenv("TT_TESTDATA");
  if (!td)
    return;
  char path[1024];
  snprintf(path, sizeof path, "%s/jacksboro_fault_dem.tif", td);
  GDALDatasetH ds = GDALOpen(path, GA_ReadOnly);
  if (!ds) {
    TT_FAIL_("cannot open %s", path);
    return;
  }
  /* 138,632 samples: 0.55 MB of heights, 2.8 MB with ground points */
  char *opts[] = {"MAX_MEMORY=2000000", NULL};
  size_t warnings = tt_context_warning_count(ctx);
  tt_grid *g = NULL;
  tt_raster_info *info = NULL;
  CHECK_OK(ctx, tt_gdal_read_grid(ctx, GDALGetRasterBand(ds, 1), opts, NULL,
                                  NULL, &g, &info));
  if (g) {
    printf("MAX_MEMORY=2000000: frame %s\n", info->frame_name);
    CHECK(tt_grid_ground_xy(g) == NULL);
    CHECK(strstr(info->frame_name, "affine at the centre") != NULL);
    CHECK_INT_EQ(tt_context_warning_count(ctx), warnings + 1);
  }
  tt_grid_destroy(g);
  tt_raster_info_destroy(info);
  GDALClose(ds);
}

int main(void)
{
  GDALAllRegister();
  ctx = tt_context_create();
  geod_init(&wgs84, 6378137.0, 1 / 298.257223563);
  TT_RUN(test_srtm_57n());
  TT_RUN(test_ten_degrees());
  TT_RUN(test_sixty_degrees());
  TT_RUN(test_web_mercator());
  TT_RUN(test_feet());
  TT_RUN(test_frame_choice());
  TT_RUN(test_memory_limit());
  tt_context_destroy(ctx);
  TT_TEST_DONE();
}
