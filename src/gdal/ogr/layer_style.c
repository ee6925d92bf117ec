/*
 * src/gdal/ogr/ -- the OGR layers: a TIN written into an OGR dataset and
 * triangles read from one, the features' records, QGIS's default style,
 * safe output paths and the protection of the input's files.
 *
 * layer_style.c -- the default QGIS style saved with the layers, so that
 * they open styled: in a GeoPackage the `layer_styles` table of QGIS's convention
 * (the schema QGIS's OGR provider creates when a user saves a style into a
 * GeoPackage: f_table_catalog, f_table_schema, f_table_name,
 * f_geometry_column, styleName, styleQML, styleSLD, useAsDefault,
 * description, owner, ui, update_time, FID id; QGIS takes the row with
 * useAsDefault = 1, f_table_schema = '' and the layer's table and
 * geometry column), one row for each geometry layer written; in
 * PostgreSQL the same table as QGIS's PostgreSQL provider makes it (xml
 * columns, a type column), through SQL in the write's transaction; beside
 * a Shapefile's, FlatGeobuf's or GeoJSON's layer file a NAME.qml, which
 * QGIS loads with NAME.shp by itself.
 *
 * The QML holds a graduated renderer, five classes from the TIN's own
 * values coloured yellow to red (ColorBrewer YlOrRd), the triangles' fills
 * at 45 % opacity so that a hillshade under them shows through: max_err for the
 * triangles in equal intervals from the smallest to the largest (the
 * errors lie under the bound, and an integer DEM gives most triangles an
 * error of 0, which would merge quantile classes into one); ins_err for
 * the vertices in quantiles (insertion errors span orders of magnitude, the
 * first points inserted being the worst: equal intervals would put nearly
 * every vertex in the first class), falling back to equal intervals when
 * repeated values leave fewer than three. ins_err is NULL for the starting
 * corners, the forced outline vertices and every vertex of a decimated
 * TIN: coalesce() maps it to -1, drawn grey in a class of its own, so no
 * vertex disappears. The QML also names every field's title
 * (field_docs.c) as QGIS's alias, which GDAL 3.6 would not pass on from
 * gpkg_data_columns.
 *
 * Workload: one sort of the triangles' and vertices' errors (8 bytes
 * each), a QML of a few kilobytes per layer.
 */
#include "gdal/ogr/field_docs.h"
#include "gdal/ogr/layer_style.h"
#include "gdal/ogr/tin_records.h"
#include "tin/tin.h"

#include <cpl_conv.h>
#include <cpl_error.h>
#include <cpl_string.h>
#include <cpl_vsi.h>

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define N_CLASSES 5

/* ColorBrewer YlOrRd, 5 classes. */
static const char *const ramp[N_CLASSES] = {"255,255,178,255", "254,204,92,255",
                                            "253,141,60,255", "240,59,32,255",
                                            "189,0,38,255"};
static const char *const null_colour = "160,160,160,255";

/* The triangles' fills are see-through, so that a hillshade or an image
 * under the TIN stays visible (the terrain shows through, the classes
 * tint it); their dark outlines stay opaque and draw the mesh. */
#define FILL_OPACITY "0.45"

/* A growing string; on failure of an allocation it stays failed. */
typedef struct text {
  char *s;
  size_t n, cap;
  int failed;
} text;

static void add(text *t, const char *fmt, ...) TT_PRINTF(2, 3);

static void add(text *t, const char *fmt, ...)
{
  if (t->failed)
    return;
  va_list ap;
  va_start(ap, fmt);
  int k = vsnprintf(NULL, 0, fmt, ap);
  va_end(ap);
  if (k < 0) {
    t->failed = 1;
    return;
  }
  if (t->n + (size_t)k + 1 > t->cap) {
    size_t cap = t->cap ? t->cap : 4096;
    while (cap < t->n + (size_t)k + 1)
      cap *= 2;
    char *s = realloc(t->s, cap);
    if (!s) {
      t->failed = 1;
      return;
    }
    t->s = s;
    t->cap = cap;
  }
  va_start(ap, fmt);
  vsnprintf(t->s + t->n, t->cap - t->n, fmt, ap);
  va_end(ap);
  t->n += (size_t)k;
}

/* s with the five XML specials escaped, for an attribute value. */
static void add_escaped(text *t, const char *s)
{
  for (; *s; s++) {
    switch (*s) {
    case '&': add(t, "&amp;"); break;
    case '<': add(t, "&lt;"); break;
    case '>': add(t, "&gt;"); break;
    case '"': add(t, "&quot;"); break;
    case '\'': add(t, "&apos;"); break;
    default: add(t, "%c", *s);
    }
  }
}

/* The fields' titles as QGIS's aliases (the names its attribute table and
 * forms show): every field of the layer (a vertex field the TIN lacks,
 * importance, is ignored by QGIS). */
static void add_aliases(text *t, int point)
{
  const tt__field_doc *docs = point ? tt__vertex_docs : tt__triangle_docs;
  int n = point ? TT__VF_COUNT : TT__TF_COUNT;
  add(t, "  <aliases>\n");
  for (int i = 0; i < n; i++) {
    add(t, "    <alias field=\"%s\" index=\"%d\" name=\"", docs[i].name, i);
    add_escaped(t, docs[i].title);
    add(t, "\"/>\n");
  }
  add(t, "  </aliases>\n");
}

static int cmp_double(const void *a, const void *b)
{
  double x = *(const double *)a, y = *(const double *)b;
  return x < y ? -1 : x > y;
}

/* Puts the k-th smallest of v[lo..hi) at v[k], the smaller ones before it
 * and the others after (quickselect with a three-way partition, so that
 * runs of equal values, common in errors of integer DEMs, cost one pass;
 * a sort when it goes badly). The same value as sorting v would put at k. */
static void select_kth(double *v, size_t lo, size_t hi, size_t k)
{
  int budget = 64;
  while (hi - lo > 16) {
    if (--budget == 0) {
      qsort(v + lo, hi - lo, sizeof *v, cmp_double);
      return;
    }
    double a = v[lo], b = v[lo + (hi - lo) / 2], c = v[hi - 1];
    double pivot = a < b ? (b < c ? b : (a < c ? c : a))
                         : (a < c ? a : (b < c ? c : b));
    /* v[lo..lt) < pivot, v[lt..i) == pivot, v[gt..hi) > pivot */
    size_t lt = lo, i = lo, gt = hi;
    while (i < gt) {
      double x = v[i];
      if (x < pivot) {
        v[i++] = v[lt];
        v[lt++] = x;
      } else if (x > pivot) {
        v[i] = v[--gt];
        v[gt] = x;
      } else {
        i++;
      }
    }
    if (k < lt)
      hi = lt;
    else if (k >= gt)
      lo = gt;
    else
      return; /* v[k] == pivot, in place */
  }
  qsort(v + lo, hi - lo, sizeof *v, cmp_double);
}

static void add_symbol(text *t, int name, const char *colour, int point)
{
  if (point)
    add(t,
        "      <symbol type=\"marker\" name=\"%d\" alpha=\"1\" "
        "clip_to_extent=\"1\" force_rhr=\"0\">\n"
        "        <layer class=\"SimpleMarker\" pass=\"0\" locked=\"0\" "
        "enabled=\"1\">\n"
        "          <Option type=\"Map\">\n"
        "            <Option name=\"name\" type=\"QString\" value=\"circle\"/>\n"
        "            <Option name=\"color\" type=\"QString\" value=\"%s\"/>\n"
        "            <Option name=\"outline_color\" type=\"QString\" "
        "value=\"60,60,60,255\"/>\n"
        "            <Option name=\"outline_width\" type=\"QString\" "
        "value=\"0.1\"/>\n"
        "            <Option name=\"size\" type=\"QString\" value=\"1.6\"/>\n"
        "          </Option>\n"
        "        </layer>\n"
        "      </symbol>\n",
        name, colour);
  else
    add(t,
        "      <symbol type=\"fill\" name=\"%d\" alpha=\"" FILL_OPACITY "\" "
        "clip_to_extent=\"1\" force_rhr=\"0\">\n"
        "        <layer class=\"SimpleFill\" pass=\"0\" locked=\"0\" "
        "enabled=\"1\">\n"
        "          <Option type=\"Map\">\n"
        "            <Option name=\"color\" type=\"QString\" value=\"%s\"/>\n"
        "            <Option name=\"style\" type=\"QString\" value=\"solid\"/>\n"
        "            <Option name=\"outline_color\" type=\"QString\" "
        "value=\"90,90,90,255\"/>\n"
        "            <Option name=\"outline_style\" type=\"QString\" "
        "value=\"solid\"/>\n"
        "            <Option name=\"outline_width\" type=\"QString\" "
        "value=\"0.06\"/>\n"
        "          </Option>\n"
        "        </layer>\n"
        "      </symbol>\n",
        name, colour);
}

char *tt__style_graduated_qml(const char *attr, const double *values,
                              size_t n, int point, int nan_class,
                              int quantiles)
{
  /* The breaks: the smallest and largest finite values, and for
   * quantiles the order statistics between them, each found by selection
   * in what lies above the one before (no sort). */
  double breaks[N_CLASSES + 1], lo = INFINITY, hi = -INFINITY;
  int nb = 0;
  size_t m = 0;
  for (size_t i = 0; i < n; i++)
    if (isfinite(values[i])) {
      m++;
      if (values[i] < lo) lo = values[i];
      if (values[i] > hi) hi = values[i];
    }
  if (m > 0 && quantiles) {
    double *v = malloc(m * sizeof *v);
    if (!v)
      return NULL;
    m = 0;
    for (size_t i = 0; i < n; i++)
      if (isfinite(values[i]))
        v[m++] = values[i];
    breaks[nb++] = lo;
    size_t from = 0;
    for (int k = 1; k <= N_CLASSES; k++) {
      size_t at = k == N_CLASSES ? m - 1 : (size_t)((double)(m - 1) * k /
                                                   N_CLASSES + 0.5);
      double q = hi;
      if (k < N_CLASSES) {
        if (at >= from) /* else the one before, in place */
          select_kth(v, from, m, at);
        q = v[at];
        from = at + 1;
      }
      if (q > breaks[nb - 1])
        breaks[nb++] = q;
    }
    free(v);
    if (nb < 4) /* fewer than three classes */
      quantiles = 0;
  }
  if (m > 0 && !quantiles) {
    nb = 0;
    breaks[nb++] = lo;
    for (int k = 1; k <= N_CLASSES; k++) {
      double b = k == N_CLASSES ? hi : lo + (hi - lo) * k / N_CLASSES;
      if (b > breaks[nb - 1])
        breaks[nb++] = b;
    }
  }
  if (nb == 1) /* every value the same: one class around it */
    breaks[nb++] = lo;

  text t;
  memset(&t, 0, sizeof t);
  add(&t, "<!DOCTYPE qgis PUBLIC 'http://mrcc.com/qgis.dtd' 'SYSTEM'>\n"
          "<qgis version=\"3.22.0\" styleCategories=\"Symbology|Fields\">\n"
          "  <renderer-v2 type=\"graduatedSymbol\" attr=\"");
  add_escaped(&t, attr);
  add(&t, "\" graduatedMethod=\"GraduatedColor\" symbollevels=\"0\" "
          "forceraster=\"0\" enableorderby=\"0\" referencescale=\"-1\">\n"
          "    <ranges>\n");
  int sym = 0;
  if (nan_class)
    add(&t, "      <range lower=\"-1\" upper=\"-1\" symbol=\"%d\" "
            "label=\"none (not inserted)\" render=\"true\"/>\n", sym++);
  int nclasses = nb - 1;
  for (int k = 0; k < nclasses; k++)
    add(&t, "      <range lower=\"%.17g\" upper=\"%.17g\" symbol=\"%d\" "
            "label=\"%.4g - %.4g\" render=\"true\"/>\n",
        breaks[k], breaks[k + 1], sym++, breaks[k], breaks[k + 1]);
  add(&t, "    </ranges>\n    <symbols>\n");
  sym = 0;
  if (nan_class)
    add_symbol(&t, sym++, null_colour, point);
  for (int k = 0; k < nclasses; k++) {
    /* spread the ramp over the classes there are */
    int c = nclasses == 1 ? N_CLASSES - 1
                          : k * (N_CLASSES - 1) / (nclasses - 1);
    add_symbol(&t, sym++, ramp[c], point);
  }
  add(&t, "    </symbols>\n"
          "    <classificationMethod id=\"%s\">\n"
          "      <symmetricMode enabled=\"0\" symmetrypoint=\"0\" "
          "astride=\"0\"/>\n"
          "      <labelFormat format=\"%%1 - %%2\" labelprecision=\"4\" "
          "trimtrailingzeroes=\"1\"/>\n"
          "    </classificationMethod>\n"
          "  </renderer-v2>\n",
      quantiles ? "Quantile" : "EqualInterval");
  add_aliases(&t, point);
  add(&t, "  <layerGeometryType>%d</layerGeometryType>\n"
          "</qgis>\n",
      point ? 0 : 2);
  if (t.failed) {
    free(t.s);
    return NULL;
  }
  char *out = CPLStrdup(t.s);
  free(t.s);
  return out;
}

static const struct style_field {
  const char *name;
  OGRFieldType type;
  int width;
} style_fields[] = {
    {"f_table_catalog", OFTString, 256}, {"f_table_schema", OFTString, 256},
    {"f_table_name", OFTString, 256},    {"f_geometry_column", OFTString, 256},
    {"styleName", OFTString, 30},        {"styleQML", OFTString, 0},
    {"styleSLD", OFTString, 0},          {"useAsDefault", OFTInteger, 0},
    {"description", OFTString, 0},       {"owner", OFTString, 30},
    {"ui", OFTString, 30},               {"update_time", OFTDateTime, 0},
};

tt_status tt__style_create_fields(tt_context *ctx, OGRLayerH layer)
{
  for (size_t i = 0; i < sizeof style_fields / sizeof style_fields[0]; i++) {
    const struct style_field *sf = &style_fields[i];
    OGRFieldDefnH fd = OGR_Fld_Create(sf->name, sf->type);
    if (sf->width)
      OGR_Fld_SetWidth(fd, sf->width);
    if (sf->type == OFTInteger)
      OGR_Fld_SetSubType(fd, OFSTBoolean);
    if (sf->type == OFTDateTime)
      OGR_Fld_SetDefault(fd, "CURRENT_TIMESTAMP");
    CPLErrorReset();
    OGRErr err = OGR_L_CreateField(layer, fd, TRUE);
    OGR_Fld_Destroy(fd);
    if (err != OGRERR_NONE)
      return tt__error(ctx, TT_ERR_IO, "cannot create field %s of the "
                       "layer_styles table: %s", sf->name,
                       CPLGetLastErrorMsg());
  }
  return TT_OK;
}

static tt_status insert_row(tt_context *ctx, OGRLayerH layer,
                            const char *table, const char *geom,
                            const char *qml, const char *description)
{
  OGRFeatureDefnH defn = OGR_L_GetLayerDefn(layer);
  OGRFeatureH f = OGR_F_Create(defn);
#define SET(name, value)                                                       \
  OGR_F_SetFieldString(f, OGR_FD_GetFieldIndex(defn, name), value)
  SET("f_table_catalog", "");
  SET("f_table_schema", "");
  SET("f_table_name", table);
  SET("f_geometry_column", geom ? geom : "");
  SET("styleName", table);
  SET("styleQML", qml);
  SET("styleSLD", "");
  SET("description", description);
  SET("owner", "");
#undef SET
  OGR_F_SetFieldInteger(f, OGR_FD_GetFieldIndex(defn, "useAsDefault"), 1);
  CPLErrorReset();
  OGRErr err = OGR_L_CreateFeature(layer, f);
  OGR_F_Destroy(f);
  if (err != OGRERR_NONE)
    return tt__error(ctx, TT_ERR_IO, "cannot write the style of layer %s: "
                     "%s", table, CPLGetLastErrorMsg());
  return TT_OK;
}

/* The default style of the triangles (tri set) or the vertices of tin:
 * classes from its own values. NULL when out of memory (said). */
static char *layer_qml(tt_context *ctx, const tt_tin *tin, int tri)
{
  size_t n = tri ? tt_tin_triangle_count(tin) : tt_tin_vertex_count(tin);
  double *values = malloc((n ? n : 1) * sizeof *values);
  if (!values) {
    tt__error(ctx, TT_ERR_NOMEM, "out of memory for the style's classes "
              "of %zu features", n);
    return NULL;
  }
  /* the TIN's own arrays (tt_tin_triangle() would work out every field
   * of the triangle for its max_error) */
  memcpy(values, tri ? tin->t_max : tin->v_ins_err, n * sizeof *values);
  char *qml = tt__style_graduated_qml(
      tri ? "max_err" : "coalesce(\"ins_err\", -1)", values, n, !tri, !tri,
      !tri);
  free(values);
  if (!qml)
    tt__error(ctx, TT_ERR_NOMEM, "out of memory for a style");
  return qml;
}

tt_status tt__style_insert(tt_context *ctx, OGRLayerH layer,
                           const tt_tin *tin, const char *prefix,
                           unsigned layers, const char *tri_geom,
                           const char *vtx_geom)
{
  tt_status s = TT_OK;
  for (int k = 0; k < 2 && s == TT_OK; k++) {
    const int tri = k == 0;
    if (!(layers & (tri ? TT__LAYER_TRIANGLES : TT__LAYER_VERTICES)))
      continue;
    char *qml = layer_qml(ctx, tin, tri);
    if (!qml)
      return TT_ERR_NOMEM;
    char *table = CPLStrdup(CPLSPrintf("%s%s", prefix,
                                       tri ? "triangles" : "vertices"));
    s = insert_row(ctx, layer, table, tri ? tri_geom : vtx_geom, qml,
                   tri ? "terratin: triangles by their max error (max_err), "
                         "equal intervals"
                       : "terratin: vertices by their insertion error "
                         "(ins_err), quantile classes; grey: none");
    CPLFree(table);
    CPLFree(qml);
  }
  return s;
}

/* The .qml beside the layer's file: in a folder dataset (a shapefile's
 * temporary folder, FlatGeobuf's folder of layers) <dir>/<layer>.qml,
 * else the dataset's file with the extension .qml. */
static char *qml_path(GDALDatasetH dst, OGRLayerH layer)
{
  const char *desc = GDALGetDescription(dst);
  char **entries = VSIReadDir(desc); /* NULL for a file */
  int folder = entries != NULL;
  CSLDestroy(entries);
  if (folder)
    return CPLStrdup(CPLFormFilename(desc, OGR_L_GetName(layer), "qml"));
  return CPLStrdup(CPLResetExtension(desc, "qml"));
}

static tt_status write_file(tt_context *ctx, const char *path,
                            const char *qml)
{
  VSILFILE *f = VSIFOpenL(path, "wb");
  if (!f)
    return tt__error(ctx, TT_ERR_IO, "%s: cannot create the style file",
                     path);
  size_t n = strlen(qml);
  int ok = VSIFWriteL(qml, 1, n, f) == n;
  if (VSIFCloseL(f) != 0)
    ok = 0;
  if (!ok) {
    VSIUnlink(path);
    return tt__error(ctx, TT_ERR_IO, "%s: cannot write the style file",
                     path);
  }
  return TT_OK;
}

tt_status tt__style_write_files(tt_context *ctx, GDALDatasetH dst,
                                const tt_tin *tin, OGRLayerH tri_layer,
                                OGRLayerH vtx_layer)
{
  tt_status s = TT_OK;
  for (int k = 0; k < 2 && s == TT_OK; k++) {
    OGRLayerH layer = k == 0 ? tri_layer : vtx_layer;
    if (!layer)
      continue;
    char *qml = layer_qml(ctx, tin, k == 0);
    if (!qml)
      return TT_ERR_NOMEM;
    char *path = qml_path(dst, layer);
    s = write_file(ctx, path, qml);
    CPLFree(path);
    CPLFree(qml);
  }
  return s;
}

/* What a failed statement of the PostgreSQL style could not do. */
#define PG_STYLE_WHAT "write the layers' style (layer_styles)"

/* QGIS's layer_styles as its PostgreSQL provider creates it. */
#define PG_STYLE_TABLE                                                         \
  "CREATE TABLE IF NOT EXISTS layer_styles (id SERIAL PRIMARY KEY, "          \
  "f_table_catalog varchar, f_table_schema varchar, f_table_name varchar, "   \
  "f_geometry_column varchar, styleName text, styleQML xml, styleSLD xml, "   \
  "useAsDefault boolean, description text, owner varchar(63) DEFAULT "        \
  "CURRENT_USER, ui xml, update_time timestamp DEFAULT CURRENT_TIMESTAMP, "   \
  "type varchar)"

/* One layer's row: terratin's earlier row for the same table replaced.
 * type NULL: QGIS matches its geometry type with the layer URI's (absent
 * from a URI written by hand: "Unknown geometry") or takes NULL as any. */
static tt_status pg_insert_row(tt_context *ctx, GDALDatasetH dst,
                               const char *schema, OGRLayerH layer,
                               const char *qml, int tri)
{
  /* OGR names a layer of another schema "schema.table" */
  const char *name = OGR_L_GetName(layer);
  const char *dot = schema ? strchr(name, '.') : NULL;
  char *sch = schema ? tt__sql_literal(schema)
                     : CPLStrdup("current_schema()");
  char *table = tt__sql_literal(dot ? dot + 1 : name);
  char *geom = tt__sql_literal(OGR_L_GetGeometryColumn(layer));
  char *doc = tt__sql_literal(qml);
  const char *description =
      tri ? "'terratin: triangles by their max error (max_err), equal "
            "intervals'"
          : "'terratin: vertices by their insertion error (ins_err), "
            "quantile classes; grey: none'";
  char *where = CPLStrdup(CPLSPrintf(
      "f_table_catalog = current_database() AND f_table_schema = %s AND "
      "f_table_name = %s AND f_geometry_column = %s", sch, table, geom));
  char *del = CPLStrdup(CPLSPrintf("DELETE FROM layer_styles WHERE %s AND "
                                   "description LIKE 'terratin:%%'", where));
  char *ins = CPLStrdup(CPLSPrintf(
      "INSERT INTO layer_styles (f_table_catalog, f_table_schema, "
      "f_table_name, f_geometry_column, styleName, styleQML, useAsDefault, "
      "description, type) VALUES (current_database(), %s, %s, %s, %s, "
      "XMLPARSE(DOCUMENT %s), true, %s, NULL)",
      sch, table, geom, table, doc, description));
  tt_status s = tt__sql_exec(ctx, dst, del, PG_STYLE_WHAT);
  if (s == TT_OK)
    s = tt__sql_exec(ctx, dst, ins, PG_STYLE_WHAT);
  CPLFree(ins);
  CPLFree(del);
  CPLFree(where);
  CPLFree(doc);
  CPLFree(geom);
  CPLFree(table);
  CPLFree(sch);
  return s;
}

tt_status tt__style_insert_pg(tt_context *ctx, GDALDatasetH dst,
                              const tt_tin *tin, const char *schema,
                              OGRLayerH tri_layer, OGRLayerH vtx_layer)
{
  tt_status s = tt__sql_exec(ctx, dst, PG_STYLE_TABLE, PG_STYLE_WHAT);
  /* a table of QGIS before 3.14 has no type column; QGIS adds it too */
  if (s == TT_OK)
    s = tt__sql_exec(ctx, dst, "ALTER TABLE layer_styles ADD COLUMN IF NOT "
                     "EXISTS type varchar", PG_STYLE_WHAT);
  for (int k = 0; k < 2 && s == TT_OK; k++) {
    OGRLayerH layer = k == 0 ? tri_layer : vtx_layer;
    if (!layer)
      continue;
    char *qml = layer_qml(ctx, tin, k == 0);
    if (!qml)
      return TT_ERR_NOMEM;
    s = pg_insert_row(ctx, dst, schema, layer, qml, k == 0);
    CPLFree(qml);
  }
  return s;
}
