/*
 * report.c -- apps/core/: the command's core, what every command's folder
 * shares. This file: what the command prints: a small JSON writer (one object;
 * strings escaped, invalid UTF-8 replaced by U+FFFD, non-finite numbers as
 * null, so the output always parses) and simplify's summary line and JSON
 * object. eval builds its JSON with the same writer.
 */
#include "app.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Length of the valid UTF-8 sequence at s, 0 when invalid. */
static size_t utf8_len(const unsigned char *s)
{
  unsigned c = s[0];
  size_t n;
  unsigned min;
  if (c < 0x80)
    return 1;
  if (c >= 0xc2 && c <= 0xdf) { n = 2; min = 0x80; }
  else if (c >= 0xe0 && c <= 0xef) { n = 3; min = 0x800; }
  else if (c >= 0xf0 && c <= 0xf4) { n = 4; min = 0x10000; }
  else return 0;
  unsigned cp = c & (0x7f >> n);
  for (size_t i = 1; i < n; i++) {
    if ((s[i] & 0xc0) != 0x80)
      return 0;
    cp = (cp << 6) | (s[i] & 0x3f);
  }
  if (cp < min || cp > 0x10ffff || (cp >= 0xd800 && cp <= 0xdfff))
    return 0;
  return n;
}

static void json_string(FILE *fp, const char *s)
{
  const unsigned char *p = (const unsigned char *)(s ? s : "");
  fputc('"', fp);
  while (*p) {
    unsigned c = *p;
    if (c == '"' || c == '\\') {
      fputc('\\', fp);
      fputc((int)c, fp);
      p++;
    } else if (c < 0x20) {
      switch (c) {
      case '\n': fputs("\\n", fp); break;
      case '\r': fputs("\\r", fp); break;
      case '\t': fputs("\\t", fp); break;
      case '\b': fputs("\\b", fp); break;
      case '\f': fputs("\\f", fp); break;
      default: fprintf(fp, "\\u%04x", c); break;
      }
      p++;
    } else {
      size_t n = utf8_len(p);
      if (n == 0) {
        fputs("\\ufffd", fp);
        p++;
      } else {
        fwrite(p, 1, n, fp);
        p += n;
      }
    }
  }
  fputc('"', fp);
}

/* The shortest %g form that reads back to the same double. */
void tt__app_format_double(char *buf, size_t size, double d)
{
  for (int prec = 6; prec <= 17; prec++) {
    snprintf(buf, size, "%.*g", prec, d);
    if (strtod(buf, NULL) == d)
      return;
  }
}

static void json_number(FILE *fp, double d)
{
  char buf[40];
  if (!isfinite(d)) {
    fputs("null", fp);
    return;
  }
  tt__app_format_double(buf, sizeof buf, d);
  fputs(buf, fp);
}

void tt__json_begin(app_json *j, FILE *fp)
{
  j->fp = fp;
  j->depth = 0;
  j->first[0] = 1;
  fputc('{', fp);
}

static void json_key(app_json *j, const char *key)
{
  if (!j->first[j->depth])
    fputc(',', j->fp);
  j->first[j->depth] = 0;
  fputs(j->depth ? " " : "\n  ", j->fp);
  json_string(j->fp, key);
  fputs(": ", j->fp);
}

void tt__json_open(app_json *j, const char *key)
{
  json_key(j, key);
  fputc('{', j->fp);
  if (j->depth + 1 < (int)(sizeof j->first / sizeof j->first[0]))
    j->depth++;
  j->first[j->depth] = 1;
}

void tt__json_close(app_json *j)
{
  fputs(j->depth ? "}" : "\n}\n", j->fp);
  if (j->depth > 0)
    j->depth--;
}

void tt__json_str(app_json *j, const char *key, const char *v)
{
  json_key(j, key);
  if (v)
    json_string(j->fp, v);
  else
    fputs("null", j->fp);
}

void tt__json_num(app_json *j, const char *key, double v)
{
  json_key(j, key);
  json_number(j->fp, v);
}

void tt__json_size(app_json *j, const char *key, size_t v)
{
  json_key(j, key);
  fprintf(j->fp, "%zu", v);
}

void tt__json_i64(app_json *j, const char *key, int64_t v)
{
  json_key(j, key);
  fprintf(j->fp, "%lld", (long long)v);
}

void tt__json_bool(app_json *j, const char *key, int v)
{
  json_key(j, key);
  fputs(v ? "true" : "false", j->fp);
}

void tt__json_null(app_json *j, const char *key)
{
  json_key(j, key);
  fputs("null", j->fp);
}

/* "estimate": what the quick pass predicted before the work, or null
 * (a budget; apps/simplify/estimate.c). */
static void print_estimate_json(app_json *j, const app_estimate *e)
{
  if (!e->done) {
    tt__json_null(j, "estimate");
    return;
  }
  tt__json_open(j, "estimate");
  tt__json_num(j, "max_error", e->bound);
  tt__json_bool(j, "max_error_default", e->bound_default);
  tt__json_num(j, "vertices", round(e->vertices));
  tt__json_num(j, "triangles", round(e->triangles));
  tt__json_num(j, "valid_samples", round(e->valid));
  tt__json_num(j, "share", e->share);
  tt__json_num(j, "output_bytes", round(e->output_bytes));
  tt__json_num(j, "memory_untiled", round(e->memory_whole));
  tt__json_num(j, "max_error_5_percent", e->advice_bound);
  tt__json_size(j, "windows", e->windows);
  tt__json_size(j, "window_size", e->window_size);
  tt__json_size(j, "sampled_cells", e->sampled_cells);
  tt__json_num(j, "seconds", e->seconds);
  tt__json_close(j);
}

void tt__app_print_simplify_json(app_run *r, const app_simplify_report *p)
{
  app_json j;
  const tt_refine_options *ro = p->ropt;
  const tt_error_stats *e = &p->sum.errors;
  tt__json_begin(&j, r->out);
  tt__json_str(&j, "input", tt__app_shown(r, r->s->input));
  tt__json_size(&j, "band", (size_t)r->s->band);
  tt__json_str(&j, "output", tt__app_shown(r, r->s->output));
  tt__json_str(&j, "format", p->driver);
  tt__json_str(&j, "method", p->dopt ? "decimate" : "insert");
  tt__json_str(&j, "criterion", tt_criterion_name(p->sum.criterion));
  tt_repair rep = tt_repair_resolve(r->s->repair, p->sum.criterion);
  tt__json_str(&j, "repair", tt_repair_name(rep));
  tt__json_str(&j, "optimize",
           tt_optimize_name(tt_optimize_resolve(r->s->optimize,
                                                p->sum.criterion, rep)));
  tt__json_size(&j, "width", p->info->width);
  tt__json_size(&j, "height", p->info->height);
  tt__json_size(&j, "cells", p->cells);
  tt__json_size(&j, "valid_samples", p->valid);
  tt__json_num(&j, "z_min", p->zmin);
  tt__json_num(&j, "z_max", p->zmax);
  tt__json_open(&j, "limits");
  if (ro->max_error >= 0) tt__json_num(&j, "max_error", ro->max_error);
  else tt__json_null(&j, "max_error");
  tt__json_bool(&j, "max_error_default", p->default_error);
  if (ro->max_points) tt__json_size(&j, "max_points", ro->max_points);
  else tt__json_null(&j, "max_points");
  if (ro->max_triangles) tt__json_size(&j, "max_triangles", ro->max_triangles);
  else tt__json_null(&j, "max_triangles");
  if (ro->percent > 0) tt__json_num(&j, "percent", ro->percent);
  else tt__json_null(&j, "percent");
  tt__json_close(&j);
  if (p->dopt) {
    const tt_decimate_options *d = p->dopt;
    tt__json_open(&j, "decimation");
    if (d->start == TT_DSTART_GREEDY_N) {
      char sn[48];
      snprintf(sn, sizeof sn, "greedy:%zu", d->start_points);
      tt__json_str(&j, "start", sn);
    } else {
      tt__json_str(&j, "start", tt_decimate_start_name(d->start));
    }
    tt_importance imp = d->importance != TT_IMPORTANCE_AUTO ? d->importance
                        : d->max_error >= 0 ? TT_IMPORTANCE_ERROR
                                            : TT_IMPORTANCE_HDH;
    tt__json_str(&j, "importance", tt_importance_name(imp));
    tt__json_str(&j, "selection", tt_selection_name(d->selection));
    tt__json_bool(&j, "onepass", d->onepass);
    tt_hole hole = d->hole != TT_HOLE_AUTO ? d->hole
                   : d->criterion == TT_CRITERION_DELAUNAY
                       ? TT_HOLE_CIRCUMRADIUS
                       : TT_HOLE_MINANGLE;
    tt__json_str(&j, "hole", tt_hole_name(hole));
    tt__json_size(&j, "start_vertices", p->sum.start_vertices);
    tt__json_size(&j, "removed_vertices", p->sum.removed_vertices);
    tt__json_size(&j, "rounds", p->sum.rounds);
    tt__json_size(&j, "refused_for_bound", p->sum.refused_bound);
    tt__json_close(&j);
  }
  tt__json_str(&j, "stop_reason", tt_stop_reason_name(p->sum.stop_reason));
  tt__json_size(&j, "vertices", p->sum.vertices);
  tt__json_size(&j, "triangles", p->sum.triangles);
  tt__json_size(&j, "covered_samples", e->covered);
  tt__json_size(&j, "lone_samples", e->samples - e->covered);
  tt__json_size(&j, "components", p->sum.components);
  tt__json_size(&j, "forced_vertices", p->sum.forced_vertices);
  tt__json_num(&j, "max_error", e->max_error);
  tt__json_num(&j, "rmse", e->rmse);
  tt__json_num(&j, "mean_abs_error", e->mean_abs);
  tt__json_num(&j, "total_abs_error", e->total_abs);
  tt__json_num(&j, "l2", e->l2);
  if (e->max_col >= 0) {
    const double *gt = p->info->gt;
    double c = (double)e->max_col + 0.5, rw = (double)e->max_row + 0.5;
    tt__json_open(&j, "max_error_at");
    tt__json_i64(&j, "col", e->max_col);
    tt__json_i64(&j, "row", e->max_row);
    tt__json_num(&j, "x", gt[0] + c * gt[1] + rw * gt[2]);
    tt__json_num(&j, "y", gt[3] + c * gt[4] + rw * gt[5]);
    tt__json_close(&j);
  } else {
    tt__json_null(&j, "max_error_at");
  }
  tt__json_str(&j, "z_unit", tt__app_nonempty_or_null(p->info->z_unit));
  tt__json_str(&j, "z_unit_declared",
               tt__app_nonempty_or_null(p->info->z_unit_declared));
  tt__json_str(&j, "z_unit_source",
               tt__app_nonempty_or_null(p->info->z_unit_source));
  tt__json_num(&j, "z_multiplier", p->info->z_unit_factor * p->info->z_factor);
  tt__json_str(&j, "pixel_is",
               tt__app_nonempty_or_null(p->info->area_or_point));
  tt__json_str(&j, "crs", tt__app_nonempty_or_null(p->info->crs_name));
  tt__json_str(&j, "output_crs",
               p->t_srs ? p->t_srs
                           : tt__app_nonempty_or_null(p->info->crs_name));
  tt__json_bool(&j, "output_crs_automatic", p->t_srs_auto);
  tt__json_str(&j, "frame", p->info->frame_name);
  tt__json_size(&j, "warnings", r->msg.warnings);
  if (p->mem_limit && p->mem_limit != SIZE_MAX)
    tt__json_size(&j, "memory_limit", p->mem_limit);
  else
    tt__json_null(&j, "memory_limit");
  tt__json_str(&j, "memory_limit_source", p->mem_source);
  if (p->tiles) {
    tt__json_open(&j, "tiling");
    tt__json_size(&j, "tiles", p->tiles);
    tt__json_size(&j, "tile_size", p->tile_size);
    tt__json_size(&j, "threads", (size_t)p->tile_threads);
    tt__json_bool(&j, "automatic", p->auto_tiled);
    tt__json_size(&j, "memory_in_flight", p->tile_bytes);
    tt__json_size(&j, "budget_passes", (size_t)p->budget_passes);
    tt__json_bool(&j, "streamed", p->streamed);
    tt__json_close(&j);
  }
  print_estimate_json(&j, &p->estimate);
  tt__json_open(&j, "seconds");
  tt__json_num(&j, "read", p->t_read);
  tt__json_num(&j, "simplify", p->t_simplify);
  tt__json_num(&j, "mesh", p->sum.seconds_mesh);
  tt__json_num(&j, "statistics", p->sum.seconds_statistics);
  tt__json_num(&j, "write", p->t_write);
  tt__json_num(&j, "total", p->t_total);
  tt__json_close(&j);
  tt__json_str(&j, "version", tt_version());
  tt__json_close(&j);
}

void tt__app_print_simplify_summary(app_run *r, const app_simplify_report *p)
{
  const char *unit = tt__app_unit_or(p->info, "z units");
  const tt_refine_options *ro = p->ropt;
  char lim[256] = "", num[40];
  size_t n = 0;
  if (ro->max_error >= 0) {
    snprintf(num, sizeof num, "%.6g", ro->max_error);
    n += (size_t)snprintf(lim + n, sizeof lim - n, "%smax_error %s %s%s",
                          n ? ", " : "", num, unit,
                          p->default_error ? " (default: 0.5% of the height "
                                             "range)"
                                           : "");
  }
  if (ro->max_points && n < sizeof lim)
    n += (size_t)snprintf(lim + n, sizeof lim - n, "%smax_points %zu",
                          n ? ", " : "", ro->max_points);
  if (ro->max_triangles && n < sizeof lim)
    n += (size_t)snprintf(lim + n, sizeof lim - n, "%smax_triangles %zu",
                          n ? ", " : "", ro->max_triangles);
  if (ro->percent > 0 && n < sizeof lim) {
    snprintf(num, sizeof num, "%.6g", ro->percent);
    snprintf(lim + n, sizeof lim - n, "%spercent %s", n ? ", " : "", num);
  }
  /* Where the numbers stand: CRS, working frame, height unit. */
  const tt_raster_info *in = p->info;
  char zu[160];
  if (in->z_unit_factor != 1.0)
    snprintf(zu, sizeof zu, "%s (from %s, x%.10g)", unit,
             in->z_unit_declared, in->z_unit_factor);
  else if (in->z_unit && *in->z_unit)
    snprintf(zu, sizeof zu, "%s (%s)", unit, in->z_unit_source);
  else
    snprintf(zu, sizeof zu, "unknown");
  const char *shown = tt__app_shown(r, r->s->output);
  fprintf(r->out,
          "%s: %zu cells, %zu valid samples -> %zu vertices, %zu triangles; "
          "max error %.6g %s, RMS %.6g %s; limits: %s; stop: %s; CRS %s%s%s%s; "
          "frame %s; z unit %s; mesh %.2f s, write %.2f s (%s); %.2f s\n",
          shown, p->cells, p->valid, p->sum.vertices,
          p->sum.triangles, p->sum.errors.max_error, unit,
          p->sum.errors.rmse, unit, lim,
          tt_stop_reason_name(p->sum.stop_reason),
          in->crs_name && *in->crs_name ? in->crs_name : "none",
          p->t_srs ? ", written in " : "", p->t_srs ? p->t_srs : "",
          p->t_srs_auto ? " (the only CRS the format holds)" : "",
          in->frame_name, zu, p->sum.seconds_mesh, p->t_write,
          p->driver ? p->driver : "?", p->t_total);
  if (p->tiles && p->auto_tiled) {
    fprintf(r->out, "%s: tiled automatically: %zu tiles of %zu cells on %d "
            "thread%s, memory limit %.1f MiB (%s); the tiles in flight hold "
            "at most about %.0f MiB\n", shown, p->tiles, p->tile_size,
            p->tile_threads, p->tile_threads == 1 ? "" : "s",
            (double)p->mem_limit / 1048576.0,
            p->mem_source ? p->mem_source : "?",
            (double)p->tile_bytes / 1048576.0);
  } else if (p->tiles) {
    fprintf(r->out, "%s: %zu tiles of %zu cells on %d thread%s; the tiles "
            "in flight hold at most about %.0f MiB\n", shown, p->tiles,
            p->tile_size, p->tile_threads, p->tile_threads == 1 ? "" : "s",
            (double)p->tile_bytes / 1048576.0);
  }
  if (p->tiles) {
    if (p->budget_passes)
      fprintf(r->out, "%s: the budget is met at the bound %g, found from "
              "the tiles' curves (one pass) and %d run%s at a bound\n",
              shown, p->ropt ? p->ropt->max_error : 0.0,
              p->budget_passes, p->budget_passes == 1 ? "" : "s");
  }
  if (p->dopt)
    fprintf(r->out,
            "%s: decimated from %zu vertices: %zu removed in %zu %s\n",
            shown, p->sum.start_vertices, p->sum.removed_vertices,
            p->sum.rounds,
            p->dopt->selection == TT_SELECTION_SEQUENTIAL ? "steps"
                                                          : "rounds");
  /* nodata outlines: what the TIN could not carry is said, not dropped */
  size_t lone = p->sum.errors.samples - p->sum.errors.covered;
  if (p->sum.components > 1)
    fprintf(r->out, "%s: %zu separate pieces%s", shown, p->sum.components,
            lone ? "; " : "\n");
  else if (lone)
    fprintf(r->out, "%s: ", shown);
  if (lone)
    fprintf(r->out,
            "%zu valid sample%s amid nodata (in no cell with 3 valid "
            "corners) cannot carry a triangle and %s left out\n",
            lone, lone == 1 ? "" : "s", lone == 1 ? "is" : "are");
}
