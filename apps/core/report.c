/*
 * report.c -- apps/core/: the command's core, what every command's folder
 * shares. This file: what the command prints: a small JSON writer (one object;
 * strings escaped, invalid UTF-8 replaced by U+FFFD, non-finite numbers as
 * null, so the output always parses) and simplify's summary (three short
 * lines: what went in, what came out, the error; -verbose adds how) and
 * JSON object. eval builds its JSON with the same writer.
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

void tt__json_strs(app_json *j, const char *key, char *const *v)
{
  json_key(j, key);
  fputc('[', j->fp);
  for (size_t i = 0; v && v[i]; i++) {
    if (i)
      fputs(", ", j->fp);
    json_string(j->fp, v[i]);
  }
  fputc(']', j->fp);
}

/* simplify -json: the limits the run had (the default bound and its step). */
static void json_limits(app_json *j, const app_simplify_report *p)
{
  const tt_refine_options *ro = p->ropt;
  tt__json_open(j, "limits");
  if (ro->max_error >= 0) tt__json_num(j, "max_error", ro->max_error);
  else tt__json_null(j, "max_error");
  tt__json_bool(j, "max_error_default", p->default_error);
  if (p->default_error)
    tt__json_num(j, "mean_step", p->step);
  if (ro->max_points) tt__json_size(j, "max_points", ro->max_points);
  else tt__json_null(j, "max_points");
  if (ro->max_triangles) tt__json_size(j, "max_triangles", ro->max_triangles);
  else tt__json_null(j, "max_triangles");
  if (ro->percent > 0) tt__json_num(j, "percent", ro->percent);
  else tt__json_null(j, "percent");
  tt__json_close(j);
}

/* simplify -json: decimation's options as resolved, and its counts. */
static void json_decimation(app_json *j, const app_simplify_report *p)
{
  const tt_decimate_options *d = p->dopt;
  tt__json_open(j, "decimation");
  if (d->start == TT_DSTART_GREEDY_N) {
    char sn[48];
    snprintf(sn, sizeof sn, "greedy:%zu", d->start_points);
    tt__json_str(j, "start", sn);
  } else {
    tt__json_str(j, "start", tt_decimate_start_name(d->start));
  }
  tt_importance imp = d->importance != TT_IMPORTANCE_AUTO ? d->importance
                      : d->max_error >= 0 ? TT_IMPORTANCE_ERROR
                                          : TT_IMPORTANCE_HDH;
  tt__json_str(j, "importance", tt_importance_name(imp));
  tt__json_str(j, "selection", tt_selection_name(d->selection));
  tt__json_bool(j, "onepass", d->onepass);
  tt_hole hole = d->hole != TT_HOLE_AUTO ? d->hole
                 : d->criterion == TT_CRITERION_DELAUNAY
                     ? TT_HOLE_CIRCUMRADIUS
                     : TT_HOLE_MINANGLE;
  tt__json_str(j, "hole", tt_hole_name(hole));
  tt__json_size(j, "start_vertices", p->sum.start_vertices);
  tt__json_size(j, "removed_vertices", p->sum.removed_vertices);
  tt__json_size(j, "rounds", p->sum.rounds);
  tt__json_size(j, "refused_for_bound", p->sum.refused_bound);
  tt__json_close(j);
}

/* simplify -json: the heights' unit and conversion, the CRSs, the frame. */
static void json_units_crs(app_json *j, const app_simplify_report *p)
{
  tt__json_str(j, "z_unit", tt__app_nonempty_or_null(p->info->z_unit));
  tt__json_str(j, "z_unit_declared",
               tt__app_nonempty_or_null(p->info->z_unit_declared));
  tt__json_str(j, "z_unit_source",
               tt__app_nonempty_or_null(tt__app_z_unit_source(p->info)));
  tt__json_str(j, "z_unit_conversion",
               tt__app_nonempty_or_null(tt__app_z_unit_why(p->info)));
  tt__json_num(j, "z_multiplier", p->info->z_unit_factor * p->info->z_factor);
  tt__json_str(j, "pixel_is",
               tt__app_nonempty_or_null(p->info->area_or_point));
  tt__json_str(j, "crs", tt__app_nonempty_or_null(p->info->crs_name));
  tt__json_str(j, "output_crs",
               p->t_srs ? p->t_srs
                           : tt__app_nonempty_or_null(p->info->crs_name));
  tt__json_bool(j, "output_crs_automatic", p->t_srs_auto);
  tt__json_str(j, "frame", p->info->frame_name);
}

void tt__app_print_simplify_json(app_run *r, const app_simplify_report *p)
{
  app_json j;
  const tt_error_stats *e = &p->sum.errors;
  tt__json_begin(&j, r->out);
  tt__json_str(&j, "input", tt__app_shown(r, r->s->input));
  tt__json_size(&j, "band", (size_t)r->s->band);
  tt__json_str(&j, "output", tt__app_shown(r, r->s->output));
  tt__json_strs(&j, "files", p->files);
  tt__json_strs(&j, "layers", p->layers);
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
  if (p->info->fill_max) {
    tt__json_size(&j, "fill_nodata", p->info->fill_max);
    tt__json_size(&j, "filled_samples", p->info->filled_samples);
    tt__json_size(&j, "filled_voids", p->info->filled_voids);
  } else {
    tt__json_null(&j, "fill_nodata");
    tt__json_size(&j, "filled_samples", 0);
    tt__json_size(&j, "filled_voids", 0);
  }
  tt__json_num(&j, "z_min", p->zmin);
  tt__json_num(&j, "z_max", p->zmax);
  json_limits(&j, p);
  if (p->dopt)
    json_decimation(&j, p);
  tt__json_str(&j, "stop_reason", tt_stop_reason_name(p->sum.stop_reason));
  tt__json_size(&j, "vertices", p->sum.vertices);
  tt__json_size(&j, "triangles", p->sum.triangles);
  tt__json_size(&j, "covered_samples", e->covered);
  tt__json_size(&j, "lone_samples", e->samples - e->covered);
  tt__json_size(&j, "components", p->sum.components);
  tt__json_size(&j, "forced_vertices", p->sum.forced_vertices);
  if (p->min_patch) {
    tt__json_open(&j, "min_patch");
    tt__json_size(&j, "samples", p->min_patch);
    tt__json_size(&j, "dropped_patches", p->dropped_patches);
    tt__json_size(&j, "dropped_samples", p->dropped_samples);
    tt__json_close(&j);
  }
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
  json_units_crs(&j, p);
  tt__json_size(&j, "warnings", r->msg.warnings);
  if (p->mem_limit && p->mem_limit != SIZE_MAX)
    tt__json_size(&j, "memory_limit", p->mem_limit);
  else
    tt__json_null(&j, "memory_limit");
  tt__json_str(&j, "memory_limit_source", p->mem_source);
  if (p->breaklines) {
    tt__json_open(&j, "breaklines");
    tt__json_size(&j, "lines", p->breaklines);
    tt__json_size(&j, "segments", p->breakline_segments);
    tt__json_close(&j);
  }
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

/* " (-max_points 2000, -percent 5)": the budget as it was given. */
static void budget_words(const tt_refine_options *ro, char *buf, size_t size)
{
  size_t n = 0;
  buf[0] = '\0';
  if (ro->max_points && n < size)
    n += (size_t)snprintf(buf + n, size - n, "%s-max_points %zu",
                          n ? ", " : "", ro->max_points);
  if (ro->max_triangles && n < size)
    n += (size_t)snprintf(buf + n, size - n, "%s-max_triangles %zu",
                          n ? ", " : "", ro->max_triangles);
  if (ro->percent > 0 && n < size)
    snprintf(buf + n, size - n, "%s-percent %g", n ? ", " : "", ro->percent);
}

/* What went in: the file, the band, its size, the CRS, the heights' unit. */
static void say_input(app_run *r, const app_simplify_report *p)
{
  const tt_raster_info *in = p->info;
  char valid[64], heights[200];
  if (p->valid == p->cells)
    snprintf(valid, sizeof valid, "all valid");
  else
    snprintf(valid, sizeof valid, "%zu valid", p->valid);
  if (in->z_unit_factor != 1.0)
    snprintf(heights, sizeof heights, "heights in %s, converted to %s (%s)",
             in->z_unit_declared, tt__app_unit_or(in, "?"),
             tt__app_z_unit_why(in));
  else if (in->z_unit && *in->z_unit)
    snprintf(heights, sizeof heights, "heights in %s", in->z_unit);
  else
    snprintf(heights, sizeof heights, "heights in unknown units");
  if (in->z_factor != 1.0) {
    size_t n = strlen(heights);
    snprintf(heights + n, sizeof heights - n, ", times %g", in->z_factor);
  }
  const tt_app_settings *s = r->s;
  fprintf(r->out, "input:  %s, band %d: %zu x %zu samples%s, %s; %s%s; %s\n",
          tt__app_shown(r, s->input), s->band, in->width, in->height,
          s->srcwin.set || s->projwin.set ? " (a window)" : "", valid,
          in->crs_name && *in->crs_name ? in->crs_name : "no CRS",
          s->srs ? " (given)" : "", heights);
  if (in->fill_max)
    fprintf(r->out, "note:   %zu nodata sample%s in %zu void%s filled "
            "(-fill_nodata %zu); the bound holds on the filled grid\n",
            in->filled_samples, in->filled_samples == 1 ? "" : "s",
            in->filled_voids, in->filled_voids == 1 ? "" : "s",
            in->fill_max);
}

/* What came out: the files (and layers) written, the TIN's size. */
static void say_output(app_run *r, const app_simplify_report *p)
{
  fputs("output: ", r->out);
  size_t nf = 0;
  while (p->files && p->files[nf])
    nf++;
  /* a file and its many sidecars (2DM's datasets): the file, and a count */
  for (size_t i = 0; i < nf && (nf <= 3 || i == 0); i++)
    fprintf(r->out, "%s%s", i ? ", " : "", p->files[i]);
  if (nf > 3)
    fprintf(r->out, " and %zu files beside it", nf - 1);
  /* 2DM has no place for a CRS, and QGIS's MDAL reads none */
  if (p->crs_file)
    fprintf(r->out, " (the CRS in %s: 2DM holds none, set it by hand in "
            "QGIS)", p->crs_file);
  for (size_t i = 0; p->layers && p->layers[i]; i++)
    fprintf(r->out, "%s%s", i ? ", " : (p->layers[1] ? " (layers " :
                                                      " (layer "),
            p->layers[i]);
  if (p->layers && p->layers[0])
    fputc(')', r->out);
  double share = p->valid ? 100.0 * (double)p->sum.vertices /
                                (double)p->valid
                          : 0.0;
  fprintf(r->out, ": %zu vertices (%.2g%% of the valid samples), %zu "
          "triangles", p->sum.vertices, share, p->sum.triangles);
  /* nodata splits the TIN: the parts that share no edge */
  if (p->sum.components > 1)
    fprintf(r->out, " in %zu components", p->sum.components);
  if (p->t_srs)
    fprintf(r->out, ", in %s%s", p->t_srs,
            p->t_srs_auto ? " (the only CRS the format holds)" : "");
  if (p->tiles && p->auto_tiled)
    fprintf(r->out, "; tiled automatically in %zu tiles, memory limit "
            "%.1f MiB", p->tiles, (double)p->mem_limit / 1048576.0);
  fprintf(r->out, "; %.1f s\n", p->t_total);
}

/* The guarantee: the largest error, against the bound that holds it, and
 * the RMS; or what the budget gave. */
static void say_error(app_run *r, const app_simplify_report *p)
{
  const char *unit = tt__app_unit_or(p->info, "z units");
  const tt_refine_options *ro = p->ropt;
  const tt_error_stats *e = &p->sum.errors;
  char budget[160];
  budget_words(ro, budget, sizeof budget);
  fprintf(r->out, "error:  max %.4g %s", e->max_error, unit);
  if (ro->max_error >= 0 && p->sum.stop_reason != TT_STOP_MAX_POINTS &&
      p->sum.stop_reason != TT_STOP_MAX_TRIANGLES) {
    if (p->default_error)
      fprintf(r->out, ", within the default bound %g %s (twice the DEM's "
              "mean step between samples, %.3g %s; -max_error sets it)",
              ro->max_error, unit, p->step, unit);
    else
      fprintf(r->out, ", within the bound %g %s", ro->max_error, unit);
  } else if (ro->max_error >= 0) {
    fprintf(r->out, " (%s reached before the bound %g %s)", budget,
            ro->max_error, unit);
  } else {
    fprintf(r->out, " (the budget %s)", budget);
  }
  fprintf(r->out, "; RMS %.4g %s\n", e->rmse, unit);
  /* nodata outlines: what the TIN could not carry is said, not dropped */
  size_t lone = e->samples - e->covered;
  if (lone)
    fprintf(r->out,
            "note:   %zu valid sample%s amid nodata (in no cell with 3 "
            "valid corners) cannot carry a triangle and %s left out\n",
            lone, lone == 1 ? "" : "s", lone == 1 ? "is" : "are");
  if (p->dropped_patches)
    fprintf(r->out,
            "note:   %zu valid sample%s in %zu patch%s of fewer than %zu "
            "samples dropped (-min_patch)\n", p->dropped_samples,
            p->dropped_samples == 1 ? "" : "s", p->dropped_patches,
            p->dropped_patches == 1 ? "" : "es", p->min_patch);
}

/* How the stop came, in words. */
static const char *stop_words(tt_stop_reason why)
{
  switch (why) {
  case TT_STOP_MAX_ERROR: return "every sample within the bound";
  case TT_STOP_MAX_POINTS: return "the vertex budget reached";
  case TT_STOP_MAX_TRIANGLES: return "the triangle budget reached";
  case TT_STOP_EXHAUSTED: return "every sample exact";
  default: return "not stopped";
  }
}

/* -verbose: how the TIN was made, where its numbers stand, the time. */
static void say_details(app_run *r, const app_simplify_report *p)
{
  const tt_raster_info *in = p->info;
  FILE *o = r->out;
  tt_repair rep = tt_repair_resolve(r->s->repair, p->sum.criterion);
  fprintf(o, "method: %s, criterion %s, repair %s, optimize %s; stopped "
          "with %s\n", p->dopt ? "decimate" : "insert",
          tt_criterion_name(p->sum.criterion), tt_repair_name(rep),
          tt_optimize_name(tt_optimize_resolve(r->s->optimize,
                                               p->sum.criterion, rep)),
          stop_words(p->sum.stop_reason));
  if (p->dopt)
    fprintf(o, "        decimated from %zu vertices: %zu removed in %zu "
            "%s\n", p->sum.start_vertices, p->sum.removed_vertices,
            p->sum.rounds,
            p->dopt->selection == TT_SELECTION_SEQUENTIAL ? "steps"
                                                          : "rounds");
  fprintf(o, "frame:  %s\n", in->frame_name);
  fprintf(o, "heights: %.6g to %.6g %s", p->zmin, p->zmax,
          tt__app_unit_or(in, "z units"));
  const char *source = tt__app_z_unit_source(in);
  int given = strcmp(source, "-z_unit") == 0;
  if (in->z_unit_factor != 1.0)
    fprintf(o, given ? " (%s %s times %.10g: %s)"
                     : " (the %s's %s times %.10g: %s)",
            source, in->z_unit_declared, in->z_unit_factor,
            tt__app_z_unit_why(in));
  else if (*source)
    fprintf(o, given ? " (as %s says)" : " (the unit from the %s)", source);
  fputc('\n', o);
  if (p->tiles) {
    char lim[200] = "";
    if (p->auto_tiled)
      snprintf(lim, sizeof lim, " (tiled automatically: the run does not "
               "fit the memory limit of %.1f MiB, %s)",
               (double)p->mem_limit / 1048576.0,
               p->mem_source ? p->mem_source : "?");
    fprintf(o, "tiles:  %zu tiles of %zu cells on %d thread%s%s; the tiles "
            "in flight hold at most about %.0f MiB\n", p->tiles,
            p->tile_size, p->tile_threads, p->tile_threads == 1 ? "" : "s",
            lim, (double)p->tile_bytes / 1048576.0);
    if (p->budget_passes)
      fprintf(o, "        the budget is met at the bound %g, found from the "
              "tiles' curves (one pass) and %d run%s at a bound\n",
              p->ropt ? p->ropt->max_error : 0.0, p->budget_passes,
              p->budget_passes == 1 ? "" : "s");
  }
  fprintf(o, "time:   read %.2f s, mesh %.2f s, write %.2f s (%s), total "
          "%.2f s\n", p->t_read, p->sum.seconds_mesh, p->t_write,
          p->driver ? p->driver : "?", p->t_total);
}

void tt__app_print_simplify_summary(app_run *r, const app_simplify_report *p)
{
  say_input(r, p);
  say_output(r, p);
  say_error(r, p);
  if (p->breaklines)
    fprintf(r->out, "lines:  %zu breakline%s read, %zu constrained "
            "segment%s after simplification along them\n", p->breaklines,
            p->breaklines == 1 ? "" : "s", p->breakline_segments,
            p->breakline_segments == 1 ? "" : "s");
  if (r->s->verbose)
    say_details(r, p);
}
