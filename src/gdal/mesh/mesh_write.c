/*
 * src/gdal/mesh/ -- the mesh formats: a TIN as SMS 2DM, PLY, OBJ, LandXML
 * or UGRID netCDF, without OGR.
 *
 * mesh_write.c -- a TIN written as one mesh or survey file, without
 * OGR: SMS 2DM (QGIS's MDAL reads it as a mesh layer), binary PLY (vertex
 * and face properties), Wavefront OBJ (3-D and game tools) and a LandXML
 * 1.2 TIN surface (civil and survey software) and an AutoCAD DXF (R12)
 * drawing of 3DFACE entities (CAD; GDAL 3.6's DXF driver writes polygons
 * as HATCH entities, flat at one height); UGRID netCDF is ugrid_write.c's,
 * called from here.
 *
 * The coordinates and the triangles come from tin_records.h, as for the
 * OGR layers: the output CRS is the input's or T_SRS with every vertex
 * transformed once, and each triangle's vertices are counter-clockwise in
 * the output coordinates. Every vertex of the TIN is written, in TIN
 * order, so a vertex's index in the file is its index in the TIN (1-based
 * in 2DM, OBJ and LandXML, 0-based in PLY; DXF holds no vertex list: each
 * 3DFACE carries its three corners, the fourth repeating the first, on
 * the layer "triangles"). Numbers are written with
 * %.17g (ASCII formats) or as IEEE doubles (PLY): a reader gets back the
 * very doubles. The caller gives the path to write (the temporary name of
 * a tt_output); a failure or an interruption removes the partial file.
 *
 * 2DM holds no values but the heights, so its datasets go beside it, one
 * SMS ASCII dataset file (.dat, "DATASET" ... "ENDDS", one time step) per
 * attribute, named after the mesh: OUT_ins_err.dat, OUT_star_max.dat,
 * OUT_star_rmse.dat on the vertices; OUT_max_err_els.dat, OUT_rmse_els.dat,
 * OUT_n_samples_els.dat on the triangles (MDAL takes a dataset file whose
 * name holds "_els" as face values, any other as vertex values; QGIS loads
 * them with "Add extra dataset" or QgsMeshDataProvider::addDataset(), not
 * by itself). The same attributes are PLY's properties. NaN (ins_err of
 * the starting vertices) is written "nan", which MDAL reads back as NaN.
 * 2DM carries no CRS either (MDAL gives the mesh none): a TIN with one
 * gets OUT.prj beside it (ESRI's WKT1), to set the layer's CRS by hand.
 */
#include "gdal/mesh/mesh_ugrid.h"
#include "gdal/ogr/tin_records.h"

#include <cpl_conv.h>
#include <ogr_srs_api.h>

#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <time.h>

/* Names, in -of's spelling, and the extension each format selects. */
static const struct {
  tt_mesh_format fmt;
  const char *name;
  const char *ext;
} mesh_formats[] = {
    {TT_MESH_2DM, "2DM", "2dm"},
    {TT_MESH_PLY, "PLY", "ply"},
    {TT_MESH_OBJ, "OBJ", "obj"},
    {TT_MESH_LANDXML, "LandXML", "xml"},
    /* .nc stays the OGR netCDF driver's: UGRID by -of only. */
    {TT_MESH_UGRID, "UGRID", NULL},
    {TT_MESH_DXF, "DXF", "dxf"},
};
enum { N_MESH_FORMATS = sizeof mesh_formats / sizeof mesh_formats[0] };

/* The attributes written as datasets: 2DM's files beside the mesh (the
 * suffix of each name), PLY's properties. */
enum { DS_INS_ERR, DS_STAR_MAX, DS_STAR_RMSE, DS_MAX_ERR, DS_RMSE,
       DS_N_SAMPLES, N_DATASETS, N_VERTEX_DATASETS = DS_MAX_ERR };
static const char *const dataset_names[N_DATASETS] = {
    "ins_err", "star_max", "star_rmse", "max_err", "rmse", "n_samples"};
static const char *const dat_suffixes[N_DATASETS + 1] = {
    "_ins_err.dat",     "_star_max.dat", "_star_rmse.dat",
    "_max_err_els.dat", "_rmse_els.dat", "_n_samples_els.dat", NULL};
static const char *const no_suffixes[1] = {NULL};
/* 2DM's sidecars: its datasets and the CRS (.prj, WKT1 as ESRI writes it;
 * only when the TIN has a CRS). */
#define PRJ_SUFFIX ".prj"
static const char *const twodm_sidecars[N_DATASETS + 2] = {
    "_ins_err.dat",     "_star_max.dat", "_star_rmse.dat",
    "_max_err_els.dat", "_rmse_els.dat", "_n_samples_els.dat", PRJ_SUFFIX,
    NULL};

const char *const *tt_mesh_format_sidecars(tt_mesh_format fmt)
{
  return fmt == TT_MESH_2DM ? twodm_sidecars : no_suffixes;
}

tt_mesh_format tt_mesh_format_from_name(const char *name)
{
  for (size_t i = 0; name && i < N_MESH_FORMATS; i++)
    if (strcasecmp(name, mesh_formats[i].name) == 0)
      return mesh_formats[i].fmt;
  return TT_MESH_NONE;
}

tt_mesh_format tt_mesh_format_from_path(const char *path)
{
  const char *base = path ? strrchr(path, '/') : NULL;
  base = base ? base + 1 : path;
  const char *dot = base ? strrchr(base, '.') : NULL;
  for (size_t i = 0; dot && i < N_MESH_FORMATS; i++)
    if (mesh_formats[i].ext && strcasecmp(dot + 1, mesh_formats[i].ext) == 0)
      return mesh_formats[i].fmt;
  return TT_MESH_NONE;
}

const char *tt_mesh_format_name(tt_mesh_format fmt)
{
  for (size_t i = 0; i < N_MESH_FORMATS; i++)
    if (mesh_formats[i].fmt == fmt)
      return mesh_formats[i].name;
  return NULL;
}

/* PLY's binary_little_endian body: doubles and ints in little-endian
 * order whatever the host's. */
static int host_big_endian(void)
{
  const uint16_t one = 1;
  unsigned char b;
  memcpy(&b, &one, 1);
  return b == 0;
}

/* Appends value (size bytes) to the record at *p in little-endian order
 * and moves *p past it; a record goes out in one fwrite(). */
static void put_le(unsigned char **p, const void *value, size_t size,
                   int swap)
{
  unsigned char *b = *p;
  memcpy(b, value, size);
  if (swap)
    for (size_t i = 0; i < size / 2; i++) {
      unsigned char t = b[i];
      b[i] = b[size - 1 - i];
      b[size - 1 - i] = t;
    }
  *p = b + size;
}

/* A double as %.17g writes it (the exact value back on reading), with a
 * fast path for the integers below 10^15 that DEMs are full of (heights of
 * integer bands, coordinates of whole-unit grids, sample counts), which
 * %.17g writes as plain digits too: the text is the same, the time a
 * fraction. -0 keeps printf's "-0". */
static void put_num(FILE *f, double v)
{
  if (v > -1e15 && v < 1e15 && v == (double)(int64_t)v &&
      !(v == 0 && signbit(v))) {
    char buf[24], *p = buf + sizeof buf;
    int64_t n = (int64_t)v;
    uint64_t u = n < 0 ? (uint64_t)0 - (uint64_t)n : (uint64_t)n;
    do {
      *--p = (char)('0' + (int)(u % 10));
      u /= 10;
    } while (u);
    if (n < 0)
      *--p = '-';
    fwrite(p, 1, (size_t)(buf + sizeof buf - p), f);
  } else {
    fprintf(f, "%.17g", v);
  }
}

/* Numbers separated by spaces, then end (a newline or a closing tag). */
static void put_nums(FILE *f, const double *v, int n, const char *end)
{
  for (int k = 0; k < n; k++) {
    if (k)
      fputc(' ', f);
    put_num(f, v[k]);
  }
  fputs(end, f);
}

/* Text with XML's five special characters escaped. */
static void put_xml_text(FILE *f, const char *s)
{
  for (; s && *s; s++)
    switch (*s) {
    case '<': fputs("&lt;", f); break;
    case '>': fputs("&gt;", f); break;
    case '&': fputs("&amp;", f); break;
    case '"': fputs("&quot;", f); break;
    case '\'': fputs("&apos;", f); break;
    default: fputc(*s, f);
    }
}

/* A name on one line of a text header (2DM's quoted MESHNAME, PLY's
 * comment, OBJ's object): control characters and double quotes become
 * '_', so an odd file name cannot break the header. */
static void put_plain(FILE *f, const char *s)
{
  for (; s && *s; s++)
    fputc((unsigned char)*s < 0x20 || *s == '"' || *s == 0x7f ? '_' : *s, f);
}

/* The centre of the output extent, rounded to whole units (so the
 * subtraction of map coordinates near it loses nothing in practice and the
 * origin reads plainly). */
static tt_status extent_centre(const tt__records *rec, tt_context *ctx,
                               size_t nv, double *cx, double *cy)
{
  double x0 = INFINITY, x1 = -INFINITY, y0 = INFINITY, y1 = -INFINITY;
  for (size_t i = 0; i < nv; i++) {
    tt_vertex_info v;
    double x, y;
    tt_status st = tt__records_vertex(rec, ctx, i, &v, &x, &y);
    if (st != TT_OK)
      return st;
    x0 = fmin(x0, x);
    x1 = fmax(x1, x);
    y0 = fmin(y0, y);
    y1 = fmax(y1, y);
  }
  *cx = nv ? floor(0.5 * (x0 + x1)) : 0.0;
  *cy = nv ? floor(0.5 * (y0 + y1)) : 0.0;
  return TT_OK;
}

/* Calls progress now and then: 0 when it asks to stop. */
static int keep_going(tt_progress_fn progress, void *arg, size_t done,
                      size_t total)
{
  if (!progress || (done & 4095) != 0)
    return 1;
  return progress(total ? (double)done / (double)total : 1.0, NULL, arg);
}

/* The header of each format, before the vertices. */
static void write_header(FILE *f, tt_mesh_format fmt, const char *name,
                         const tt__records *rec, size_t nv, size_t nt,
                         const double origin[2], int local)
{
  switch (fmt) {
  case TT_MESH_2DM:
    fputs("MESH2D\nMESHNAME \"", f);
    put_plain(f, name);
    fputs("\"\n", f);
    break;
  case TT_MESH_PLY:
    fprintf(f, "ply\nformat binary_little_endian 1.0\n"
               "comment terratin TIN ");
    put_plain(f, name);
    fputc('\n', f);
    if (rec->out_srs) {
      /* MDAL's convention: a "comment crs:" line gives the mesh's CRS
       * (the WKT is one line). */
      char *wkt = NULL;
      if (OSRExportToWkt(rec->out_srs, &wkt) == OGRERR_NONE && wkt) {
        fputs("comment crs:", f);
        for (const char *c = wkt; *c; c++)
          fputc((unsigned char)*c < 0x20 ? ' ' : *c, f);
        fputc('\n', f);
      }
      CPLFree(wkt);
    }
    fprintf(f,
               "element vertex %zu\n"
               "property double x\nproperty double y\nproperty double z\n"
               "property double ins_err\nproperty double star_max\n"
               "property double star_rmse\n"
               "element face %zu\n"
               "property list uchar int vertex_indices\n"
               "property double max_err\nproperty double rmse\n"
               "property int n_samples\nend_header\n",
            nv, nt);
    break;
  case TT_MESH_OBJ:
    fputs("# terratin TIN ", f);
    put_plain(f, name);
    fprintf(f, ": %zu vertices, %zu triangles\n", nv, nt);
    if (local)
      fprintf(f, "# origin %.17g %.17g\n", origin[0], origin[1]);
    fputs("o ", f);
    put_plain(f, name);
    fputc('\n', f);
    break;
  case TT_MESH_LANDXML: {
    time_t now = time(NULL);
    struct tm tmv;
    char date[16] = "1970-01-01", clock[16] = "00:00:00";
    if (gmtime_r(&now, &tmv)) {
      strftime(date, sizeof date, "%Y-%m-%d", &tmv);
      strftime(clock, sizeof clock, "%H:%M:%S", &tmv);
    }
    fprintf(f, "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
               "<LandXML xmlns=\"http://www.landxml.org/schema/LandXML-1.2\" "
               "xmlns:xsi=\"http://www.w3.org/2001/XMLSchema-instance\" "
               "xsi:schemaLocation=\"http://www.landxml.org/schema/"
               "LandXML-1.2 http://www.landxml.org/schema/LandXML-1.2/"
               "LandXML-1.2.xsd\" version=\"1.2\" date=\"%s\" "
               "time=\"%s\">\n"
               "  <Units>\n    <Metric areaUnit=\"squareMeter\" "
               "linearUnit=\"meter\" volumeUnit=\"cubicMeter\" "
               "temperatureUnit=\"celsius\" pressureUnit=\"milliBars\" "
               "angularUnit=\"decimal degrees\" "
               "directionUnit=\"decimal degrees\"/>\n  </Units>\n",
            date, clock);
    if (rec->out_srs) {
      /* CoordinateSystem: the EPSG code when the CRS has one, and its
       * WKT (ogcWktCode) in any case. */
      char *wkt = NULL;
      const char *auth = OSRGetAuthorityName(rec->out_srs, NULL);
      const char *code = OSRGetAuthorityCode(rec->out_srs, NULL);
      fputs("  <CoordinateSystem", f);
      if (auth && code && strcasecmp(auth, "EPSG") == 0) {
        fputs(" epsgCode=\"", f);
        put_xml_text(f, code);
        fputs("\"", f);
      }
      if (OSRExportToWkt(rec->out_srs, &wkt) == OGRERR_NONE && wkt) {
        fputs(" ogcWktCode=\"", f);
        put_xml_text(f, wkt);
        fputs("\"", f);
      }
      CPLFree(wkt);
      fputs("/>\n", f);
    }
    fputs("  <Application name=\"terratin\"/>\n"
          "  <Surfaces>\n    <Surface name=\"", f);
    put_xml_text(f, name);
    fputs("\">\n", f); /* SourceData and Definition follow */
    break;
  }
  case TT_MESH_DXF:
    /* R12 (AC1009): the version, the layer and its line type, then the
     * entities; AutoCAD, QGIS (GDAL) and the CAD tools read it. */
    fputs("  0\nSECTION\n  2\nHEADER\n  9\n$ACADVER\n  1\nAC1009\n"
          "  0\nENDSEC\n"
          "  0\nSECTION\n  2\nTABLES\n"
          "  0\nTABLE\n  2\nLTYPE\n 70\n1\n"
          "  0\nLTYPE\n  2\nCONTINUOUS\n 70\n0\n  3\nSolid line\n"
          " 72\n65\n 73\n0\n 40\n0.0\n"
          "  0\nENDTAB\n"
          "  0\nTABLE\n  2\nLAYER\n 70\n1\n"
          "  0\nLAYER\n  2\ntriangles\n 70\n0\n 62\n7\n  6\nCONTINUOUS\n"
          "  0\nENDTAB\n"
          "  0\nENDSEC\n"
          "  0\nSECTION\n  2\nENTITIES\n", f);
    break;
  default:
    break;
  }
}

/* One vertex: index i (0-based), output x, y. */
static void write_vertex(FILE *f, tt_mesh_format fmt, size_t i,
                         const tt_vertex_info *v, double x, double y,
                         const double origin[2], int swap)
{
  switch (fmt) {
  case TT_MESH_2DM:
    fprintf(f, "ND %zu ", i + 1);
    put_nums(f, (const double[3]){x, y, v->z}, 3, "\n");
    break;
  case TT_MESH_PLY: {
    const double d[6] = {x, y, v->z, v->insert_error, v->star_max_error,
                         v->star_rmse};
    unsigned char rec[sizeof d], *p = rec;
    for (int k = 0; k < 6; k++)
      put_le(&p, &d[k], sizeof d[k], swap);
    fwrite(rec, 1, sizeof rec, f);
    break;
  }
  case TT_MESH_OBJ:
    fputs("v ", f);
    put_nums(f, (const double[3]){x - origin[0], y - origin[1], v->z}, 3,
             "\n");
    break;
  case TT_MESH_LANDXML:
    /* The standard's order: northing (y), easting (x), elevation. */
    fprintf(f, "          <P id=\"%zu\">", i + 1);
    put_nums(f, (const double[3]){y, x, v->z}, 3, "</P>\n");
    break;
  default:
    break;
  }
}

/* LandXML's Surface/SourceData/Breaklines: the TIN's edges on breaklines
 * joined into polylines (a chain goes on through every vertex with two
 * such edges), one Breakline each, its points northing, easting,
 * elevation as the Pnts are (nothing without breaklines); then the
 * Definition's start. */
static tt_status write_source_data(FILE *f, const tt__records *rec,
                                   tt_context *ctx)
{
  int32_t *pairs = NULL;
  size_t n = 0;
  if (!tt__records_breakline_edges(rec->tin, &pairs, &n))
    return tt__error(ctx, TT_ERR_NOMEM, "out of memory");
  if (n == 0) {
    fputs("      <Definition surfType=\"TIN\">\n        <Pnts>\n", f);
    return TT_OK;
  }
  tt_status st = TT_OK;
  size_t nv = tt_tin_vertex_count(rec->tin);
  /* the edges by vertex: first[v] .. first[v + 1] in inc (edge numbers) */
  size_t *first = calloc(nv + 1, sizeof *first);
  size_t *inc = malloc(2 * n * sizeof *inc);
  unsigned char *used = calloc(n, 1);
  if (!first || !inc || !used) {
    st = tt__error(ctx, TT_ERR_NOMEM, "out of memory");
    goto done;
  }
  for (size_t i = 0; i < 2 * n; i++)
    first[pairs[i] + 1]++;
  for (size_t v = 0; v < nv; v++)
    first[v + 1] += first[v];
  {
    size_t *fill = malloc((nv + 1) * sizeof *fill);
    if (!fill) {
      st = tt__error(ctx, TT_ERR_NOMEM, "out of memory");
      goto done;
    }
    memcpy(fill, first, (nv + 1) * sizeof *fill);
    for (size_t i = 0; i < 2 * n; i++)
      inc[fill[pairs[i]]++] = i / 2;
    free(fill);
  }
  fputs("      <SourceData>\n        <Breaklines>\n", f);
  /* chains from the ends (degree != 2) first, then the closed loops */
  for (int pass = 0; pass < 2 && st == TT_OK; pass++)
    for (size_t s = 0; s < nv && st == TT_OK; s++) {
      size_t deg = first[s + 1] - first[s];
      if (deg == 0 || (pass == 0 && deg == 2))
        continue;
      for (size_t k = first[s]; k < first[s + 1] && st == TT_OK; k++) {
        if (used[inc[k]])
          continue;
        fputs("          <Breakline brkType=\"standard\"><PntList3D>", f);
        size_t v = s, e = inc[k];
        for (int firstpt = 1;; firstpt = 0) {
          tt_vertex_info vi;
          double x, y;
          st = tt__records_vertex(rec, ctx, v, &vi, &x, &y);
          if (st != TT_OK)
            break;
          if (!firstpt)
            fputc(' ', f);
          put_nums(f, (const double[3]){y, x, vi.z}, 3, "");
          if (e == (size_t)-1)
            break;
          used[e] = 1;
          v = (size_t)(pairs[2 * e] == (int32_t)v ? pairs[2 * e + 1]
                                                   : pairs[2 * e]);
          e = (size_t)-1;
          if (first[v + 1] - first[v] == 2) /* the chain goes on */
            for (size_t j = first[v]; j < first[v + 1]; j++)
              if (!used[inc[j]])
                e = inc[j];
        }
        fputs("</PntList3D></Breakline>\n", f);
      }
    }
  fputs("        </Breaklines>\n      </SourceData>\n", f);
  fputs("      <Definition surfType=\"TIN\">\n        <Pnts>\n", f);
done:
  free(pairs);
  free(first);
  free(inc);
  free(used);
  return st;
}

/* Between the vertices and the faces. */
static void write_middle(FILE *f, tt_mesh_format fmt)
{
  if (fmt == TT_MESH_LANDXML)
    fputs("        </Pnts>\n        <Faces>\n", f);
}

/* One triangle: index i (0-based), its record with v[] counter-clockwise
 * in the output coordinates. */
static void write_face(FILE *f, tt_mesh_format fmt, size_t i,
                       const tt_triangle_info *t, int swap)
{
  switch (fmt) {
  case TT_MESH_2DM:
    fprintf(f, "E3T %zu %ld %ld %ld 1\n", i + 1, (long)t->v[0] + 1,
            (long)t->v[1] + 1, (long)t->v[2] + 1);
    break;
  case TT_MESH_PLY: {
    /* count (uchar), 3 indices (int), max_err, rmse (double), n_samples
     * (int): 33 bytes */
    unsigned char rec[33], *p = rec;
    *p++ = 3;
    for (int k = 0; k < 3; k++) {
      const int32_t vi = t->v[k];
      put_le(&p, &vi, sizeof vi, swap);
    }
    const double d[2] = {t->max_error, t->rmse};
    put_le(&p, &d[0], sizeof d[0], swap);
    put_le(&p, &d[1], sizeof d[1], swap);
    const int32_t n = t->samples > INT32_MAX ? INT32_MAX : (int32_t)t->samples;
    put_le(&p, &n, sizeof n, swap);
    fwrite(rec, 1, sizeof rec, f);
    break;
  }
  case TT_MESH_OBJ:
    fprintf(f, "f %ld %ld %ld\n", (long)t->v[0] + 1, (long)t->v[1] + 1,
            (long)t->v[2] + 1);
    break;
  case TT_MESH_LANDXML:
    fprintf(f, "          <F>%ld %ld %ld</F>\n", (long)t->v[0] + 1,
            (long)t->v[1] + 1, (long)t->v[2] + 1);
    break;
  default:
    break;
  }
}

/* DXF's 3DFACE of a triangle: its corners' output coordinates, the
 * fourth corner (group codes 13, 23, 33) the first again, which closes
 * the ring GDAL's reader makes of it (the third again leaves it open and
 * the reader warns once per face). */
static void write_3dface(FILE *f, const double c[3][3])
{
  fputs("  0\n3DFACE\n  8\ntriangles\n", f);
  for (int k = 0; k < 4; k++) {
    const double *p = c[k < 3 ? k : 0];
    for (int a = 0; a < 3; a++) {
      fprintf(f, " %d\n", 10 * (a + 1) + k);
      put_nums(f, &p[a], 1, "\n");
    }
  }
}

static void write_footer(FILE *f, tt_mesh_format fmt)
{
  if (fmt == TT_MESH_DXF)
    fputs("  0\nENDSEC\n  0\nEOF\n", f);
  if (fmt == TT_MESH_LANDXML)
    fputs("        </Faces>\n      </Definition>\n    </Surface>\n"
          "  </Surfaces>\n</LandXML>\n", f);
}

/* The file of a 2DM dataset: path with its extension replaced by the
 * dataset's suffix (".tt01234567.2dm" -> ".tt01234567_ins_err.dat"), as
 * tt_output commits a temporary name's sidecars; malloc'd. */
static char *sidecar_path(const char *path, const char *suffix)
{
  const char *slash = strrchr(path, '/');
  const char *dot = strrchr(slash ? slash + 1 : path, '.');
  size_t stem = dot && dot != (slash ? slash + 1 : path)
                    ? (size_t)(dot - path)
                    : strlen(path);
  size_t n = stem + strlen(suffix) + 1;
  char *p = malloc(n);
  if (p)
    snprintf(p, n, "%.*s%s", (int)stem, path, suffix);
  return p;
}

/* 2DM has no CRS and MDAL reads none: the CRS goes beside path as a
 * .prj (WKT1 in ESRI's dialect, as a shapefile's), for whoever loads the
 * mesh by hand and sets its CRS. *out_path: the file written (malloc'd),
 * NULL on failure. */
static tt_status write_prj(tt_context *ctx, const char *path,
                           OGRSpatialReferenceH srs, char **out_path)
{
  const char *const opts[] = {"FORMAT=WKT1_ESRI", NULL};
  char *wkt = NULL;
  char *prj_path = sidecar_path(path, PRJ_SUFFIX);
  *out_path = NULL;
  if (!prj_path)
    return tt__error(ctx, TT_ERR_NOMEM, "out of memory");
  if (OSRExportToWktEx(srs, &wkt, opts) != OGRERR_NONE || !wkt) {
    CPLFree(wkt);
    tt_status st = tt__error(ctx, TT_ERR_FORMAT, "%s: the CRS has no ESRI "
                             "WKT form", prj_path);
    free(prj_path);
    return st;
  }
  FILE *f = fopen(prj_path, "wb");
  tt_status st = TT_OK;
  if (!f) {
    st = tt__error(ctx, TT_ERR_IO, "%s: cannot create: %s", prj_path,
                   strerror(errno));
  } else {
    int bad = fputs(wkt, f) < 0;
    if (fclose(f) != 0)
      bad = 1;
    if (bad) {
      st = tt__error(ctx, TT_ERR_IO, "%s: write failed: %s", prj_path,
                     strerror(errno));
      remove(prj_path);
    }
  }
  CPLFree(wkt);
  if (st == TT_OK)
    *out_path = prj_path;
  else
    free(prj_path);
  return st;
}

/* The value of dataset k for a vertex or a triangle. */
static double vertex_value(int k, const tt_vertex_info *v)
{
  return k == DS_INS_ERR    ? v->insert_error
         : k == DS_STAR_MAX ? v->star_max_error
                            : v->star_rmse;
}

static double face_value(int k, const tt_triangle_info *t)
{
  return k == DS_MAX_ERR ? t->max_error
         : k == DS_RMSE  ? t->rmse
                         : (double)t->samples;
}

tt_status tt_mesh_write(tt_context *ctx, const char *path,
                        tt_mesh_format fmt, const char *name,
                        const tt_tin *tin, OGRSpatialReferenceH srs,
                        const char *t_srs, int local,
                        tt_progress_fn progress, void *progress_arg)
{
  tt_status st = TT_OK;
  tt__records rec;
  FILE *f = NULL;
  FILE *dat[N_DATASETS] = {NULL};
  char *dat_path[N_DATASETS] = {NULL};
  char *prj_path = NULL; /* written: removed on a later failure */
  int made = 0;
  const int ndat = fmt == TT_MESH_2DM ? N_DATASETS : 0;
  memset(&rec, 0, sizeof rec);
  if (!path || !tin || !tt_mesh_format_name(fmt))
    return tt__error(ctx, TT_ERR_ARG, "tt_mesh_write: no path, TIN or "
                                      "mesh format");
  if (!name || !*name)
    name = "TIN";
  st = tt__records_init(&rec, ctx, tin, srs, t_srs);
  if (st != TT_OK)
    goto done;
  const size_t nv = tt_tin_vertex_count(tin), nt = tt_tin_triangle_count(tin);
  const size_t total = nv + nt;
  double origin[2] = {0.0, 0.0};
  local = local && fmt == TT_MESH_OBJ;
  if (local) {
    st = extent_centre(&rec, ctx, nv, &origin[0], &origin[1]);
    if (st != TT_OK)
      goto done;
  }
  if (fmt == TT_MESH_UGRID) {
    made = 1;
    st = tt__ugrid_write(ctx, path, name, &rec, progress, progress_arg);
    goto done;
  }
  for (int k = 0; k < ndat; k++)
    if (!(dat_path[k] = sidecar_path(path, dat_suffixes[k]))) {
      st = tt__error(ctx, TT_ERR_NOMEM, "out of memory");
      goto done;
    }
  f = fopen(path, "wb");
  if (!f) {
    st = tt__error(ctx, TT_ERR_IO, "%s: cannot create: %s", path,
                   strerror(errno));
    goto done;
  }
  made = 1;
  for (int k = 0; k < ndat; k++) {
    dat[k] = fopen(dat_path[k], "wb");
    if (!dat[k]) {
      st = tt__error(ctx, TT_ERR_IO, "%s: cannot create: %s", dat_path[k],
                     strerror(errno));
      goto done;
    }
    /* SMS's ASCII dataset, as MDAL reads it: the counts must be the
     * mesh's; one time step, no status flags. */
    fprintf(dat[k], "DATASET\nOBJTYPE \"mesh2d\"\nBEGSCL\nND %zu\nNC %zu\n"
                    "NAME \"%s\"\nTS 0 0\n", nv, nt, dataset_names[k]);
  }
  const int swap = host_big_endian();
  write_header(f, fmt, name, &rec, nv, nt, origin, local);
  if (fmt == TT_MESH_LANDXML && (st = write_source_data(f, &rec, ctx)))
    goto done;
  for (size_t i = 0; i < nv && st == TT_OK; i++) {
    tt_vertex_info v;
    double x, y;
    st = tt__records_vertex(&rec, ctx, i, &v, &x, &y);
    if (st == TT_OK)
      write_vertex(f, fmt, i, &v, x, y, origin, swap);
    for (int k = 0; st == TT_OK && k < ndat && k < N_VERTEX_DATASETS; k++)
      put_nums(dat[k], (const double[1]){vertex_value(k, &v)}, 1, "\n");
    if (st == TT_OK && !keep_going(progress, progress_arg, i + 1, total))
      st = tt__error(ctx, TT_ERR_INTERRUPTED, "interrupted");
  }
  if (st != TT_OK)
    goto done;
  write_middle(f, fmt);
  for (size_t i = 0; i < nt && st == TT_OK; i++) {
    tt_triangle_info t;
    st = tt__records_face(&rec, ctx, i, &t);
    if (st == TT_OK && fmt == TT_MESH_DXF) {
      double c[3][3];
      for (int k = 0; k < 3 && st == TT_OK; k++) {
        tt_vertex_info v;
        st = tt__records_vertex(&rec, ctx, (size_t)t.v[k], &v, &c[k][0],
                                &c[k][1]);
        c[k][2] = v.z;
      }
      if (st == TT_OK)
        write_3dface(f, c);
    } else if (st == TT_OK) {
      write_face(f, fmt, i, &t, swap);
    }
    for (int k = N_VERTEX_DATASETS; st == TT_OK && k < ndat; k++)
      put_nums(dat[k], (const double[1]){face_value(k, &t)}, 1, "\n");
    if (st == TT_OK &&
        !keep_going(progress, progress_arg, nv + i + 1, total))
      st = tt__error(ctx, TT_ERR_INTERRUPTED, "interrupted");
  }
  if (st != TT_OK)
    goto done;
  write_footer(f, fmt);
  for (int k = 0; k < ndat; k++)
    fputs("ENDDS\n", dat[k]);
  /* Each file flushed and closed, the first failure named. */
  for (int k = -1; k < ndat && st == TT_OK; k++) {
    FILE **pf = k < 0 ? &f : &dat[k];
    const char *p = k < 0 ? path : dat_path[k];
    FILE *g = *pf;
    *pf = NULL;
    int bad = ferror(g);
    int e = errno;
    if (fclose(g) != 0 && !bad) {
      bad = 1;
      e = errno;
    }
    if (bad)
      st = tt__error(ctx, TT_ERR_IO, "%s: write failed: %s", p,
                     strerror(e));
  }
  if (st != TT_OK)
    goto done;
  if (fmt == TT_MESH_2DM && rec.out_srs &&
      (st = write_prj(ctx, path, rec.out_srs, &prj_path)) != TT_OK)
    goto done;
  if (progress && !progress(1.0, NULL, progress_arg))
    st = tt__error(ctx, TT_ERR_INTERRUPTED, "interrupted");

done:
  if (f)
    fclose(f);
  for (int k = 0; k < ndat; k++) {
    if (dat[k])
      fclose(dat[k]);
    if (st != TT_OK && made && dat_path[k])
      remove(dat_path[k]);
    free(dat_path[k]);
  }
  if (st != TT_OK && made)
    remove(path);
  if (st != TT_OK && prj_path)
    remove(prj_path);
  free(prj_path);
  tt__records_free(&rec);
  return st;
}
