/*
 * tin.c -- reading a finished TIN: counts, the run summary, and per-vertex
 * and per-triangle records. Geometry attributes (areas, slope, aspect,
 * angles) are derived on demand in the ground frame from the stored
 * corners, so the TIN holds only what cannot be recomputed cheaply.
 *
 * Part of src/tin/, the finished TIN: its records and error statistics, eval,
 * synthetic terrains.
 */
#include "tin/tin.h"

#include <math.h>
#include <stdlib.h>

static const double RAD2DEG = 57.29577951308232;

void tt_tin_destroy(tt_tin *tin)
{
  if (!tin)
    return;
  free(tin->vc);
  free(tin->vr);
  free(tin->vz);
  free(tin->vzd);
  free(tin->v_ins_err);
  free(tin->v_star_max);
  free(tin->v_star_rmse);
  free(tin->v_star_n);
  free(tin->v_importance);
  free(tin->v_home);
  free(tin->tv);
  free(tin->t_max);
  free(tin->t_rmse);
  free(tin->t_n);
  free(tin->t_brk);
  free(tin->vgxy);
  free(tin->vgk);
  free(tin->vgconv);
  free(tin);
}

const char *tt_stop_reason_name(tt_stop_reason reason)
{
  switch (reason) {
  case TT_STOP_NONE: return "none";
  case TT_STOP_MAX_ERROR: return "max_error";
  case TT_STOP_MAX_POINTS: return "max_points";
  case TT_STOP_MAX_TRIANGLES: return "max_triangles";
  case TT_STOP_EXHAUSTED: return "exhausted";
  }
  return "unknown";
}

void tt_tin_get_summary(const tt_tin *tin, tt_tin_summary *out_summary)
{
  *out_summary = tin->summary;
}

size_t tt_tin_vertex_count(const tt_tin *tin) { return tin->nv; }
size_t tt_tin_triangle_count(const tt_tin *tin) { return tin->nt; }
int tt_tin_has_area_fn(const tt_tin *tin) { return tin->area_fn != NULL; }

tt_status tt_tin_vertex(const tt_tin *tin, size_t index,
                        tt_vertex_info *out_vertex)
{
  if (!tin || !out_vertex || index >= tin->nv)
    return TT_ERR_ARG;
  tt_vertex_info *o = out_vertex;
  const double *gt = tin->gt;
  double px = tin->vc[index] + 0.5, py = tin->vr[index] + 0.5;
  o->col = tin->vc[index];
  o->row = tin->vr[index];
  o->x = gt[0] + px * gt[1] + py * gt[2];
  o->y = gt[3] + px * gt[4] + py * gt[5];
  o->z = tt__tin_z(tin, index);
  o->insert_error = tin->v_ins_err[index];
  o->rank = index;
  o->star_max_error = tin->v_star_max[index];
  o->star_rmse = tin->v_star_rmse[index];
  o->star_samples = (size_t)tin->v_star_n[index];
  o->importance = tin->v_importance ? tin->v_importance[index] : NAN;
  return TT_OK;
}

/* Angle at p between the directions to q and r, radians. */
static double angle_at(const double p[2], const double q[2], const double r[2])
{
  double ux = q[0] - p[0], uy = q[1] - p[1];
  double vx = r[0] - p[0], vy = r[1] - p[1];
  return atan2(fabs(ux * vy - uy * vx), ux * vx + uy * vy);
}

/* The corners of triangle index on the ground, relative to the first, from
 * the ground points: the conformal coordinates divided by the mean scale
 * factor of the corners and turned by their mean convergence, so that +y
 * is true north and lengths are metres (to the second order in the
 * triangle's size: the scale and the convergence vary smoothly). */
static void ground_corners(const tt_tin *tin, size_t index, double p[3][2])
{
  const int32_t *tv = tin->tv + 3 * index;
  double k = 0, sc = 0, cc = 0;
  for (int j = 0; j < 3; j++) {
    k += tin->vgk[tv[j]];
    sc += sin(tin->vgconv[tv[j]]);
    cc += cos(tin->vgconv[tv[j]]);
  }
  k /= 3;
  /* a direction at grid azimuth A has true azimuth A - conv: turn the
   * vectors counter-clockwise by conv */
  double conv = atan2(sc, cc), cs = cos(conv) / k, sn = sin(conv) / k;
  const double *o = tin->vgxy + 2 * (size_t)tv[0];
  for (int j = 0; j < 3; j++) {
    const double *q = tin->vgxy + 2 * (size_t)tv[j];
    double x = q[0] - o[0], y = q[1] - o[1];
    p[j][0] = cs * x - sn * y;
    p[j][1] = sn * x + cs * y;
  }
}

tt_status tt_tin_triangle(const tt_tin *tin, size_t index,
                          tt_triangle_info *out_triangle)
{
  if (!tin || !out_triangle || index >= tin->nt)
    return TT_ERR_ARG;
  tt_triangle_info *o = out_triangle;
  const double *a = tin->frame;
  double p[3][2], z[3];
  for (int k = 0; k < 3; k++) {
    int32_t v = tin->tv[3 * index + k];
    o->v[k] = v;
    /* ground frame, relative to the first corner for precision */
    double dc = (double)(tin->vc[v] - tin->vc[tin->tv[3 * index]]);
    double dr = (double)(tin->vr[v] - tin->vr[tin->tv[3 * index]]);
    p[k][0] = a[0] * dc + a[1] * dr;
    p[k][1] = a[2] * dc + a[3] * dr;
    z[k] = tt__tin_z(tin, (size_t)v);
  }
  if (tin->vgxy)
    ground_corners(tin, index, p);
  o->max_error = tin->t_max[index];
  o->rmse = tin->t_rmse[index];
  o->samples = (size_t)tin->t_n[index];
  o->constrained = tin->t_brk ? tin->t_brk[index] : 0u;
  double ux = p[1][0] - p[0][0], uy = p[1][1] - p[0][1];
  double vx = p[2][0] - p[0][0], vy = p[2][1] - p[0][1];
  double uz = z[1] - z[0], vz = z[2] - z[0];
  double cross2 = ux * vy - uy * vx; /* > 0: counter-clockwise */
  o->area_2d = 0.5 * fabs(cross2);
  double nx = uy * vz - uz * vy, ny = uz * vx - ux * vz, nz = cross2;
  o->area_3d = 0.5 * sqrt(nx * nx + ny * ny + nz * nz);
  if (tin->area_fn) {
    /* the ground's own area (geodesic), area_3d in proportion */
    const double *gt = tin->gt;
    double mx[3], my[3];
    for (int k = 0; k < 3; k++) {
      int32_t v = tin->tv[3 * index + k];
      double px = tin->vc[v] + 0.5, py = tin->vr[v] + 0.5;
      mx[k] = gt[0] + px * gt[1] + py * gt[2];
      my[k] = gt[3] + px * gt[4] + py * gt[5];
    }
    double ga = tin->area_fn(tin->area_par, mx, my);
    o->area_3d = o->area_2d > 0 ? o->area_3d * (ga / o->area_2d) : ga;
    o->area_2d = ga;
  }
  /* plane z = gx X + gy Y + c: gradient (gx, gy) = -(nx, ny) / nz */
  double gx = -nx / nz, gy = -ny / nz;
  double grad = hypot(gx, gy);
  o->slope_deg = atan(grad) * RAD2DEG;
  if (grad == 0) {
    o->aspect_deg = NAN;
  } else {
    /* downslope direction (-gx, -gy), azimuth clockwise from +y */
    double az = atan2(-gx, -gy) * RAD2DEG;
    o->aspect_deg = az < 0 ? az + 360.0 : az;
    if (o->aspect_deg >= 360.0)
      o->aspect_deg = 0.0;
  }
  double ang[3] = {angle_at(p[0], p[1], p[2]), angle_at(p[1], p[2], p[0]),
                   angle_at(p[2], p[0], p[1])};
  double mn = ang[0], mx = ang[0];
  for (int k = 1; k < 3; k++) {
    mn = fmin(mn, ang[k]);
    mx = fmax(mx, ang[k]);
  }
  o->min_angle_deg = mn * RAD2DEG;
  o->max_angle_deg = mx * RAD2DEG;
  return TT_OK;
}
