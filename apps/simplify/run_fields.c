/*
 * run_fields.c -- apps/simplify/, the simplify command: the values of the
 * run_parameters layer of its OGR outputs (one row; the mesh formats
 * have no such layer): what was asked (input, band, method, criterion,
 * repair and optimiser as resolved, the limits), what was made (stop,
 * counts, errors), where the numbers stand (units, CRS, frame), the
 * timings so far, and what decimation and tiling ran with.
 * Taken from the job when the output is written -- twice for a streamed
 * GeoPackage: when its layers are made, and at its end.
 */
#include "simplify.h"

#include <string.h>

void tt__app_simplify_fields(const app_simplify_job *job,
                             app_run_fields *out)
{
  const tt_app_settings *s = job->s;
  const app_simplify_report *rep = &job->rep;
  const tt_refine_options *ro = &job->ro;
  const tt_raster_info *info = rep->info;
  char *start_name = out->start_name;
  tt__app_iso8601_utc(out->created, sizeof out->created);
  const tt_error_stats *e = &rep->sum.errors;
  const tt_run_field fields[] = {
      {"input", TT_FIELD_STRING, tt__app_shown(job->r, s->input), 0, 0},
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
      {"components", TT_FIELD_INTEGER, NULL, (int64_t)rep->sum.components, 0},
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
      {"out_crs", TT_FIELD_STRING, job->rep.t_srs ? job->rep.t_srs : "", 0,
       0},
      {"frame", TT_FIELD_STRING, info->frame_name ? info->frame_name : "", 0,
       0},
      {"scale_err", TT_FIELD_REAL, NULL, 0, info->frame_scale_error},
      {"version", TT_FIELD_STRING, tt_version(), 0, 0},
      {"t_read", TT_FIELD_REAL, NULL, 0, rep->t_read},
      {"t_simplify", TT_FIELD_REAL, NULL, 0, rep->t_simplify},
      {"t_mesh", TT_FIELD_REAL, NULL, 0, rep->sum.seconds_mesh},
      {"t_stats", TT_FIELD_REAL, NULL, 0, rep->sum.seconds_statistics},
      {"created", TT_FIELD_STRING, out->created, 0, 0},
  };
  /* Decimation adds what it ran with: start, importance, selection, hole
   * rule (resolved), rounds, and the vertex counts. */
  snprintf(start_name, sizeof out->start_name, "greedy:%zu",
           s->start_points);
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
  memcpy(out->v, fields, sizeof fields);
  memcpy(out->v + NF, dfields, sizeof dfields);
  out->n = NF + (s->decimate ? ND : 0);
  if (rep->tiles) {
    memcpy(out->v + out->n, tfields, sizeof tfields);
    out->n += NT;
  }
}
