/*
 * src/gdal/ogr/ -- the OGR layers: a TIN written into an OGR dataset and
 * triangles read from one, the features' records, QGIS's default style,
 * safe output paths and the protection of the input's files.
 *
 * tin_records.c -- the fields of the TIN layers and the values of each
 * feature in the layers' CRS (see tin_records.h).
 *
 * Output CRS: the layers get srs (the input CRS) unless T_SRS names
 * another; then every vertex is transformed once, up front, from srs to
 * T_SRS with OGR/PROJ (traditional GIS axis order on both sides, so x is
 * easting or longitude) and the triangles are made of the transformed
 * vertices: the triangles themselves (which vertices, which order) do not
 * change.
 *
 * Winding: every triangle is counter-clockwise in the coordinates written
 * (its corners 1 and 2 swap where T_SRS mirrors the plane).
 *
 * Areas: per-triangle area_2d and area_3d come from the TIN (the ground
 * frame, metres) when the output CRS and the input CRS are projected or
 * absent. When the output CRS is geographic, area_2d is the geodesic area
 * of the triangle whose corners are the output longitudes and latitudes,
 * on the output CRS's ellipsoid; when only the input CRS is (T_SRS
 * projects a geographic DEM), the same from the input's longitudes and
 * latitudes on the input's ellipsoid
 * (GeographicLib's geod_polygonarea, shipped with PROJ), and area_3d keeps
 * the TIN's ratio area_3d / area_2d, which is 1 / cos(slope) of the
 * triangle's plane. Slope, aspect and angles stay those of the ground
 * frame.
 *
 * Workload: one batched PROJ transformation of every vertex with T_SRS
 * (16 bytes a vertex), then O(1) per feature.
 */
#include "gdal/ogr/tin_records.h"
#include "tin/tin.h"

#include <cpl_conv.h>
#include <cpl_error.h>
#include <ogr_srs_api.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

const tt__field_spec tt__triangle_fields[TT__TF_COUNT] = {
    {"v0", OFTInteger},         {"v1", OFTInteger},
    {"v2", OFTInteger},         {"max_err", OFTReal},
    {"rmse", OFTReal},          {"n_samples", OFTInteger64},
    {"area_2d", OFTReal},       {"area_3d", OFTReal},
    {"slope", OFTReal},         {"aspect", OFTReal},
    {"min_angle", OFTReal},     {"max_angle", OFTReal},
    {"constrained", OFTInteger}};

const tt__field_spec tt__vertex_fields[TT__VF_COUNT] = {
    {"vertex_id", OFTInteger},  {"col", OFTInteger},
    {"row", OFTInteger},        {"ins_err", OFTReal},
    {"ins_rank", OFTInteger64}, {"star_max", OFTReal},
    {"star_rmse", OFTReal},     {"star_n", OFTInteger64},
    {"importance", OFTReal}};

/* The edge bits of tt_triangle_info.constrained once v[1] and v[2] are
 * swapped: edge 0 (v0 v1) becomes edge 2, edge 2 becomes edge 0. */
static unsigned swap_edge_bits(unsigned b)
{
  return (b & 2u) | ((b & 1u) << 2) | ((b & 4u) >> 2);
}

int tt__records_decimated(const tt_tin *tin)
{
  tt_tin_summary s;
  tt_tin_get_summary(tin, &s);
  return s.start_vertices > 0;
}

int tt__records_triangle_fields(const tt_tin *tin)
{
  return tin->t_brk ? TT__TF_COUNT : TT__TF_COUNT - 1;
}

static int cmp_pair(const void *a, const void *b)
{
  const int32_t *x = a, *y = b;
  return x[0] != y[0] ? (x[0] > y[0]) - (x[0] < y[0])
                      : (x[1] > y[1]) - (x[1] < y[1]);
}

bool tt__records_breakline_edges(const tt_tin *tin, int32_t **out_pairs,
                                 size_t *out_n)
{
  *out_pairs = NULL;
  *out_n = 0;
  if (!tin->t_brk)
    return true;
  size_t n = 0;
  for (size_t t = 0; t < tin->nt; t++)
    for (int k = 0; k < 3; k++)
      n += (tin->t_brk[t] >> k) & 1u;
  int32_t *p = malloc((2 * n + 2) * sizeof *p);
  if (!p)
    return false;
  size_t m = 0;
  for (size_t t = 0; t < tin->nt; t++)
    for (int k = 0; k < 3; k++)
      if ((tin->t_brk[t] >> k) & 1u) {
        int32_t a = tin->tv[3 * t + (size_t)k];
        int32_t b = tin->tv[3 * t + (size_t)(k + 1) % 3];
        p[2 * m] = a < b ? a : b;
        p[2 * m + 1] = a < b ? b : a;
        m++;
      }
  qsort(p, m, 2 * sizeof *p, cmp_pair);
  size_t u = 0; /* an inner edge is in two triangles: once */
  for (size_t i = 0; i < m; i++)
    if (u == 0 || p[2 * i] != p[2 * (u - 1)] ||
        p[2 * i + 1] != p[2 * (u - 1) + 1]) {
      p[2 * u] = p[2 * i];
      p[2 * u + 1] = p[2 * i + 1];
      u++;
    }
  *out_pairs = p;
  *out_n = u;
  return true;
}

int tt__records_vertex_fields(const tt_tin *tin)
{
  return tt__records_decimated(tin) ? TT__VF_COUNT : TT__VF_COUNT - 1;
}

/* The driver's last message, or a generic one. */
static const char *ogr_msg(void)
{
  const char *m = CPLGetLastErrorMsg();
  return m && *m ? m : "no details from GDAL";
}

/* The layers' CRS: srs, or T_SRS with every vertex transformed to it; and
 * the ellipsoid for geodesic areas when that CRS is geographic. */
static tt_status prepare_crs(tt__records *w, tt_context *ctx,
                             const tt_tin *tin, OGRSpatialReferenceH srs,
                             const char *t_srs)
{
  tt_status s = TT_OK;
  OGRSpatialReferenceH src = NULL;
  OGRCoordinateTransformationH ct = NULL;
  if (t_srs) {
    if (!srs)
      return tt__error(ctx, TT_ERR_ARG, "T_SRS=%s: the TIN has no CRS "
                       "to transform from", t_srs);
    w->out_srs = OSRNewSpatialReference(NULL);
    CPLPushErrorHandler(CPLQuietErrorHandler);
    CPLSetCurrentErrorHandlerCatchDebug(FALSE); /* debug: the handler below */
    OGRErr e = w->out_srs ? OSRSetFromUserInput(w->out_srs, t_srs)
                          : OGRERR_FAILURE;
    CPLPopErrorHandler();
    if (e != OGRERR_NONE)
      return tt__error(ctx, TT_ERR_ARG, "T_SRS '%s' is not a CRS GDAL "
                       "understands", t_srs);
    OSRSetAxisMappingStrategy(w->out_srs, OAMS_TRADITIONAL_GIS_ORDER);
    src = OSRClone(srs);
    if (src)
      OSRSetAxisMappingStrategy(src, OAMS_TRADITIONAL_GIS_ORDER);
    CPLErrorReset();
    ct = src ? OCTNewCoordinateTransformation(src, w->out_srs) : NULL;
    if (!ct) {
      s = tt__error(ctx, TT_ERR_ARG, "PROJ cannot transform the TIN's "
                    "CRS to T_SRS '%s': %s", t_srs, ogr_msg());
      goto done;
    }
    const size_t nv = tt_tin_vertex_count(tin);
    w->xy = malloc((nv ? nv : 1) * 2 * sizeof *w->xy);
    double *bx = malloc(4096 * sizeof *bx), *by = malloc(4096 * sizeof *by);
    int *ok = malloc(4096 * sizeof *ok);
    if (!w->xy || !bx || !by || !ok) {
      s = tt__error(ctx, TT_ERR_NOMEM, "out of memory for %zu "
                    "transformed vertices", nv);
    }
    for (size_t i0 = 0; s == TT_OK && i0 < nv; i0 += 4096) {
      size_t n = nv - i0 < 4096 ? nv - i0 : 4096;
      for (size_t k = 0; k < n; k++) {
        tt_vertex_info v;
        tt_tin_vertex(tin, i0 + k, &v);
        bx[k] = v.x;
        by[k] = v.y;
      }
      if (!OCTTransformEx(ct, (int)n, bx, by, NULL, ok)) {
        for (size_t k = 0; k < n; k++)
          if (!ok[k]) {
            s = tt__error(ctx, TT_ERR_DATA, "vertex %zu cannot be "
                          "transformed to T_SRS '%s': %s", i0 + k, t_srs,
                          ogr_msg());
            break;
          }
        if (s == TT_OK)
          s = tt__error(ctx, TT_ERR_DATA, "the vertices cannot be "
                        "transformed to T_SRS '%s': %s", t_srs,
                        ogr_msg());
      }
      for (size_t k = 0; s == TT_OK && k < n; k++) {
        if (!isfinite(bx[k]) || !isfinite(by[k])) {
          s = tt__error(ctx, TT_ERR_DATA, "vertex %zu has no finite "
                        "coordinates in T_SRS '%s'", i0 + k, t_srs);
          break;
        }
        w->xy[2 * (i0 + k)] = bx[k];
        w->xy[2 * (i0 + k) + 1] = by[k];
      }
    }
    free(bx);
    free(by);
    free(ok);
    if (s != TT_OK)
      goto done;
  } else if (srs) {
    w->out_srs = OSRClone(srs);
    if (!w->out_srs)
      return tt__error(ctx, TT_ERR_NOMEM, "out of memory");
  }
  /* geodesic areas on the output's ellipsoid when it is geographic, else
   * on the input's when that is (a projected T_SRS of a geographic DEM) */
  OGRSpatialReferenceH geo_srs =
      w->out_srs && OSRIsGeographic(w->out_srs) ? w->out_srs
      : srs && OSRIsGeographic(srs)              ? srs
                                                 : NULL;
  if (geo_srs) {
    OGRErr e1 = OGRERR_NONE, e2 = OGRERR_NONE;
    double a = OSRGetSemiMajor(geo_srs, &e1);
    double invf = OSRGetInvFlattening(geo_srs, &e2);
    double deg = OSRGetAngularUnits(geo_srs, NULL) * 180.0 /
                 3.14159265358979323846;
    if (e1 == OGRERR_NONE && e2 == OGRERR_NONE && a > 0 && isfinite(a) &&
        invf >= 0 && isfinite(invf) && deg > 0 && isfinite(deg)) {
      geod_init(&w->geod, a, invf > 0 ? 1.0 / invf : 0.0);
      w->deg_per_unit = deg;
      w->geodesic = geo_srs == w->out_srs ? 1 : 2;
      /* the TIN's own areas are already geodesic on the input's
       * ellipsoid (georef_conformal.c): no second computation */
      if (tt_tin_has_area_fn(tin) && srs && OSRIsGeographic(srs) &&
          (w->geodesic == 2 || OSRIsSameGeogCS(w->out_srs, srs)))
        w->geodesic = 0;
    } else {
      tt__warn(ctx, "the output CRS is geographic but has no usable "
               "ellipsoid: triangle areas are those of the ground frame");
    }
  }
done:
  if (ct)
    OCTDestroyCoordinateTransformation(ct);
  OSRDestroySpatialReference(src);
  return s;
}

tt_status tt__records_init(tt__records *r, tt_context *ctx, const tt_tin *tin,
                           OGRSpatialReferenceH srs, const char *t_srs)
{
  memset(r, 0, sizeof *r);
  r->tin = tin;
  return prepare_crs(r, ctx, tin, srs, t_srs && *t_srs ? t_srs : NULL);
}

void tt__records_free(tt__records *r)
{
  if (!r)
    return;
  free(r->xy);
  if (r->out_srs)
    OSRDestroySpatialReference(r->out_srs);
  r->xy = NULL;
  r->out_srs = NULL;
}

/* Vertex v's map x, y: tt_tin_vertex()'s (the same doubles). */
static void map_xy(const tt_tin *tin, size_t v, double *x, double *y)
{
  const double *gt = tin->gt;
  double px = tin->vc[v] + 0.5, py = tin->vr[v] + 0.5;
  *x = gt[0] + px * gt[1] + py * gt[2];
  *y = gt[3] + px * gt[4] + py * gt[5];
}

/* Vertex v's output x, y: its map coordinates, or the T_SRS ones. */
static void output_xy(const tt__records *r, size_t v, double *x, double *y)
{
  if (r->xy) {
    *x = r->xy[2 * v];
    *y = r->xy[2 * v + 1];
    return;
  }
  map_xy(r->tin, v, x, y);
}

tt_status tt__records_triangle(const tt__records *r, tt_context *ctx,
                               size_t i, tt_triangle_info *out_t,
                               double out_x[3], double out_y[3],
                               double out_z[3])
{
  tt_triangle_info *t = out_t;
  const tt_tin *tin = r->tin;
  if (tt_tin_triangle(tin, i, t) != TT_OK)
    return tt__error(ctx, TT_ERR_INTERNAL, "triangle %zu of %zu could not "
                     "be read from the TIN", i, tt_tin_triangle_count(tin));
  for (int k = 0; k < 3; k++) {
    size_t v = (size_t)t->v[k];
    output_xy(r, v, &out_x[k], &out_y[k]);
    out_z[k] = tt__tin_z(tin, v);
  }
  /* Counter-clockwise in the coordinates written: T_SRS may mirror the
   * plane (a CRS whose x axis points west), the TIN's order is that of the
   * input map. Corners 1 and 2 swap, with their vertices and indices. */
  if ((out_x[1] - out_x[0]) * (out_y[2] - out_y[0]) -
          (out_y[1] - out_y[0]) * (out_x[2] - out_x[0]) < 0) {
    double sx = out_x[1], sy = out_y[1], sz = out_z[1];
    out_x[1] = out_x[2], out_y[1] = out_y[2], out_z[1] = out_z[2];
    out_x[2] = sx, out_y[2] = sy, out_z[2] = sz;
    int32_t si = t->v[1];
    t->v[1] = t->v[2], t->v[2] = si;
    t->constrained = swap_edge_bits(t->constrained);
  }
  if (r->geodesic) {
    double lats[3], lons[3], area = 0, perimeter = 0;
    for (int k = 0; k < 3; k++) {
      double x = out_x[k], y = out_y[k];
      if (r->geodesic != 1) /* the input's own (geographic) coordinates */
        map_xy(tin, (size_t)t->v[k], &x, &y);
      lons[k] = x * r->deg_per_unit;
      lats[k] = y * r->deg_per_unit;
    }
    geod_polygonarea(&r->geod, lats, lons, 3, &area, &perimeter);
    area = fabs(area);
    t->area_3d = t->area_2d > 0 ? t->area_3d * (area / t->area_2d) : area;
    t->area_2d = area;
  }
  return TT_OK;
}

tt_status tt__records_face(const tt__records *r, tt_context *ctx, size_t i,
                           tt_triangle_info *out_t)
{
  const tt_tin *tin = r->tin;
  if (i >= tin->nt)
    return tt__error(ctx, TT_ERR_INTERNAL, "triangle %zu of %zu could not "
                     "be read from the TIN", i, tin->nt);
  double x[3], y[3];
  for (int k = 0; k < 3; k++) {
    out_t->v[k] = tin->tv[3 * i + (size_t)k];
    output_xy(r, (size_t)out_t->v[k], &x[k], &y[k]);
  }
  /* the test and the swap of tt__records_triangle() */
  out_t->constrained = tin->t_brk ? tin->t_brk[i] : 0u;
  if ((x[1] - x[0]) * (y[2] - y[0]) - (y[1] - y[0]) * (x[2] - x[0]) < 0) {
    int32_t si = out_t->v[1];
    out_t->v[1] = out_t->v[2], out_t->v[2] = si;
    out_t->constrained = swap_edge_bits(out_t->constrained);
  }
  out_t->max_error = tin->t_max[i];
  out_t->rmse = tin->t_rmse[i];
  out_t->samples = (size_t)tin->t_n[i];
  out_t->area_2d = out_t->area_3d = out_t->slope_deg = out_t->aspect_deg =
      out_t->min_angle_deg = out_t->max_angle_deg = NAN;
  return TT_OK;
}

tt_status tt__records_vertex(const tt__records *r, tt_context *ctx, size_t i,
                             tt_vertex_info *out_v, double *out_x,
                             double *out_y)
{
  if (tt_tin_vertex(r->tin, i, out_v) != TT_OK)
    return tt__error(ctx, TT_ERR_INTERNAL, "vertex %zu of %zu could not be "
                     "read from the TIN", i, tt_tin_vertex_count(r->tin));
  *out_x = r->xy ? r->xy[2 * i] : out_v->x;
  *out_y = r->xy ? r->xy[2 * i + 1] : out_v->y;
  return TT_OK;
}

tt_status tt__records_parse_layers(tt_context *ctx, const char *value,
                                   unsigned *out_mask)
{
  static const char *const names[] = {"triangles", "vertices",
                                      "run_parameters"};
  unsigned mask = 0;
  const char *p = value;
  for (;;) {
    const char *e = strchr(p, ',');
    size_t n = e ? (size_t)(e - p) : strlen(p);
    unsigned bit = 0;
    for (unsigned i = 0; i < 3 && !bit; i++)
      if (strlen(names[i]) == n && strncasecmp(p, names[i], n) == 0)
        bit = 1u << i;
    if (!bit || (mask & bit))
      return tt__error(ctx, TT_ERR_ARG, "LAYERS=%s: '%.*s' is %s", value,
                       (int)n, p, bit ? "named twice" : "not a layer "
                       "(triangles, vertices, run_parameters)");
    mask |= bit;
    if (!e)
      break;
    p = e + 1;
  }
  *out_mask = mask;
  return TT_OK;
}
