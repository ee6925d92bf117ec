/*
 * src/gdal/ogr/ -- the OGR layers: a TIN written into an OGR dataset and
 * triangles read from one, the features' records, QGIS's default style,
 * safe output paths and the protection of the input's files.
 *
 * ogr_write.c -- writing a TIN into an open OGR dataset.
 *
 * Three layers, named with an optional prefix (NLN_PREFIX, which the
 * shapefile output uses to make `<name>_triangles.shp` etc.):
 *   <prefix>triangles       POLYGON Z, one feature per triangle; the ring is
 *                           v0 v1 v2 v0 (closed, 4 points), counter-clockwise
 *                           in the coordinates written (tt_tin_triangle()'s
 *                           order, corners 1 and 2 swapped where T_SRS
 *                           mirrors the plane).
 *                           (The Shapefile driver rewinds outer rings to the
 *                           clockwise order its format prescribes.)
 *   <prefix>vertices        POINT Z, one feature per vertex.
 *   <prefix>run_parameters  no geometry, one feature of typed fields.
 * Field names have at most 10 characters so they survive DBF. Real values
 * that are NaN (aspect of a flat triangle, insertion error of a starting
 * vertex) are written as NULL.
 *
 * LAYERS says which of the three are written (single-layer formats take
 * one).
 *
 * The rows are written in one transaction when the driver has them (GPKG,
 * SQLite, PostgreSQL): nothing is visible until the commit, and an error or
 * an interruption rolls it back. For GPKG and SQLite the layers themselves
 * are created just before it and deleted again on failure: GDAL 3.6's GPKG
 * driver keeps the layer objects of a rolled-back CREATE TABLE and then
 * writes triggers for tables that do not exist when the dataset closes. A
 * database (PostgreSQL) creates its tables inside the transaction, and
 * OVERWRITE drops the old ones there too: a failure, an interruption or a
 * connection lost before the commit (the process killed) leaves the
 * database as it was. Drivers without transactions (Shapefile, KML) get
 * each layer made and filled before the next (KML takes features only into
 * its last layer: "Interleaved feature adding to different layers is not
 * supported"), and their layers deleted on failure; the temporary names of
 * tt_output guard the final files either way.
 *
 * Fields: Integer64 becomes Integer where the driver has no Integer64
 * (MapInfo); a layer that creates no fields (DXF's fixed set) gets the
 * features without attributes, warned once. STYLE=YES writes QGIS's
 * layer_styles table of a GeoPackage or a PostgreSQL database
 * (layer_style.c) in the same transaction, or a .qml beside each layer's
 * file (Shapefile, FlatGeobuf, GeoJSON) once the layers are written. A GeoPackage gets every field's title and description in
 * gpkg_data_columns (field_docs.c), with the height unit Z_UNIT.
 *
 * Spatial index: GPKG layers are created with SPATIAL_INDEX=NO (its R-tree
 * triggers would update the index per insert) and the R-tree is built once,
 * in bulk, by the driver's CreateSpatialIndex() SQL function after the
 * inserts and inside the transaction; LCO=SPATIAL_INDEX=NO skips it, and
 * RTREE=DEFERRED leaves it to the caller (tt_gpkg_build_rtree() on the
 * closed file, several times faster than GDAL 3.6's one-by-one inserts). Other
 * drivers index as their own options say (Shapefile: .qix at close with
 * LCO=SPATIAL_INDEX=YES, the default here). Shapefile layers default to
 * ENCODING=UTF-8 (.cpg).
 *
 * Output CRS and areas: tin_records.c (the layers get srs, or T_SRS with
 * every vertex transformed once; geodesic areas for a geographic output).
 *
 * ROWS=DEFERRED (GPKG only): the layers, their fields and the
 * run_parameters row are written here, the triangles and vertices rows
 * later by tt_gpkg_write_rows() on the closed file, straight through
 * SQLite (several times faster than a feature at a time through OGR).
 *
 * Each layer's feature and geometry are made once and reused: per feature
 * only field values and coordinates change. Progress is reported after
 * every feature, so an interruption is seen after at most one.
 *
 * Workload: O(vertices + triangles) feature inserts (about 16 us each into
 * GPKG, R-tree included); memory O(1) beyond what the driver buffers.
 */
#include "gdal/ogr/field_docs.h"
#include "gdal/ogr/layer_style.h"
#include "gdal/ogr/tin_records.h"

#include <cpl_conv.h>
#include <cpl_error.h>
#include <cpl_string.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#define TT_SHP_FIELD_NAME_MAX 10
#define TT_DBF_STRING_MAX 254

typedef struct write_state {
  tt_context *ctx;
  GDALDatasetH dst;
  int shapefile;
  char *prefix;
  char **lco;              /* layer creation options */
  char *created[5];        /* names of the layers made, for cleanup */
  int ncreated;
  int gpkg;
  unsigned layers;         /* LAYERS: the TT__LAYER_* bits to write */
  int overwrite;           /* OVERWRITE=YES: drop layers of those names */
  int style;               /* STYLE=YES: QGIS's layer_styles (GPKG,
                              PostgreSQL), .qml files (style_files) */
  int style_files;         /* a QML file beside each layer's file:
                              Shapefile, FlatGeobuf, GeoJSON */
  char *z_unit;            /* Z_UNIT: the heights' unit, for the fields'
                              descriptions; NULL: unknown */
  int no_int64;            /* the driver has no Integer64 fields */
  int warned_fields;       /* a field the driver dropped, said once */
  int build_rtree;         /* GPKG: bulk-build the R-trees before commit */
  int rtree_deferred;      /* RTREE=DEFERRED: the caller builds them */
  int rows_deferred;       /* ROWS=DEFERRED: tt_gpkg_write_rows() writes
                              the triangles and vertices */
  OGRLayerH tri_layer, vtx_layer, run_layer, style_layer, brk_layer;
  int tri_idx[TT__TF_COUNT], vtx_idx[TT__VF_COUNT];
  int ele_idx;             /* GPX: the waypoints' "ele" field, else -1 */
  int brk_fields;          /* the TIN has breaklines: the triangles'
                              constrained field, the breaklines layer */
  int brk_idx[2];          /* the breaklines layer's v0, v1 */
  int *run_idx;
  tt_progress_fn progress;
  void *progress_arg;
  char *t_srs;             /* T_SRS as given, NULL: none */
  tt__records rec;         /* the layers' CRS, transformed vertices */
  size_t done, total;
  double scale;            /* share of the progress range the rows take */
  const char *drv_name;    /* the driver's short name, "" */
  int database;            /* transactions that hold the tables too
                              (PostgreSQL): see write_in_transaction() */
  int in_transaction;      /* a transaction to roll back on failure */
  int rolled_back;         /* the layers made went with a rollback */
} write_state;

/* The driver's last message, or a generic one. */
static const char *ogr_msg(void)
{
  const char *m = CPLGetLastErrorMsg();
  return m && *m ? m : "no details from GDAL";
}

/* The layer and column names the options give, checked before anything
 * is written: a GeoPackage reserves table names that begin with "gpkg",
 * SQLite those that begin with "sqlite_"; a FID column (LCO FID=) named as
 * one of the layers' own fields would collide with it. */
static tt_status check_names(write_state *w)
{
  const char *prefix = w->prefix ? w->prefix : "";
  int sqlite = strcasecmp(w->drv_name, "SQLite") == 0;
  if ((w->gpkg || sqlite) && strncasecmp(prefix, "sqlite_", 7) == 0)
    return tt__error(w->ctx, TT_ERR_ARG, "layer name prefix \"%s\": "
                     "SQLite reserves the table names that begin with "
                     "\"sqlite_\"; choose another prefix", prefix);
  if (w->gpkg && strncasecmp(prefix, "gpkg", 4) == 0)
    return tt__error(w->ctx, TT_ERR_ARG, "layer name prefix \"%s\": a "
                     "GeoPackage reserves the table names that begin with "
                     "\"gpkg\"; choose another prefix", prefix);
  const char *fid = CSLFetchNameValue(w->lco, "FID");
  if (fid) {
    for (int i = 0; i < TT__TF_COUNT; i++)
      if (strcasecmp(fid, tt__triangle_fields[i].name) == 0)
        return tt__error(w->ctx, TT_ERR_ARG, "layer creation option "
                         "FID=%s: %s is a field of the triangles layer; the "
                         "FID column needs a name of its own", fid,
                         tt__triangle_fields[i].name);
    for (int i = 0; i < TT__VF_COUNT; i++)
      if (strcasecmp(fid, tt__vertex_fields[i].name) == 0)
        return tt__error(w->ctx, TT_ERR_ARG, "layer creation option "
                         "FID=%s: %s is a field of the vertices layer; the "
                         "FID column needs a name of its own", fid,
                         tt__vertex_fields[i].name);
  }
  return TT_OK;
}

static tt_status parse_options(write_state *w, char **options)
{
  for (char **o = options; o && *o; o++) {
    char *key = NULL;
    const char *value = CPLParseNameValue(*o, &key);
    if (!key || !value) {
      CPLFree(key);
      return tt__error(w->ctx, TT_ERR_ARG, "write option \"%s\" is not "
                       "NAME=VALUE", *o);
    }
    tt_status s = TT_OK;
    if (strcasecmp(key, "NLN_PREFIX") == 0) {
      CPLFree(w->prefix);
      w->prefix = CPLStrdup(value);
    } else if (strcasecmp(key, "LCO") == 0) {
      char *lkey = NULL;
      const char *lvalue = CPLParseNameValue(value, &lkey);
      if (!lkey || !lvalue)
        s = tt__error(w->ctx, TT_ERR_ARG, "LCO=%s is not LCO=NAME=VALUE",
                      value);
      else
        w->lco = CSLSetNameValue(w->lco, lkey, lvalue);
      CPLFree(lkey);
    } else if (strcasecmp(key, "T_SRS") == 0) {
      CPLFree(w->t_srs);
      w->t_srs = *value ? CPLStrdup(value) : NULL;
    } else if (strcasecmp(key, "LAYERS") == 0) {
      s = tt__records_parse_layers(w->ctx, value, &w->layers);
    } else if (strcasecmp(key, "OVERWRITE") == 0) {
      w->overwrite = CPLTestBool(value);
    } else if (strcasecmp(key, "STYLE") == 0) {
      w->style = CPLTestBool(value);
    } else if (strcasecmp(key, "Z_UNIT") == 0) {
      CPLFree(w->z_unit);
      w->z_unit = *value ? CPLStrdup(value) : NULL;
    } else if (strcasecmp(key, "ROWS") == 0) {
      if (strcasecmp(value, "DEFERRED") == 0)
        w->rows_deferred = 1;
      else if (strcasecmp(value, "NOW") == 0)
        w->rows_deferred = 0;
      else
        s = tt__error(w->ctx, TT_ERR_ARG, "ROWS=%s: expected NOW or "
                      "DEFERRED", value);
    } else if (strcasecmp(key, "RTREE") == 0) {
      if (strcasecmp(value, "DEFERRED") == 0)
        w->rtree_deferred = 1;
      else if (strcasecmp(value, "NOW") == 0)
        w->rtree_deferred = 0;
      else
        s = tt__error(w->ctx, TT_ERR_ARG, "RTREE=%s: expected NOW or "
                      "DEFERRED", value);
    } else if (strcasecmp(key, "THREADS") != 0 &&
               strcasecmp(key, "JOURNAL") != 0 &&
               strcasecmp(key, "PAGES") != 0) {
      /* THREADS, JOURNAL and PAGES are tt_gpkg_write_rows()'s */
      s = tt__error(w->ctx, TT_ERR_ARG, "unknown write option \"%s\" "
                    "(known: JOURNAL, NLN_PREFIX, LAYERS, LCO, OVERWRITE, "
                    "PAGES, ROWS, RTREE, STYLE, T_SRS, THREADS, Z_UNIT)", key);
    }
    CPLFree(key);
    if (s != TT_OK)
      return s;
  }
  if (!w->prefix)
    w->prefix = CPLStrdup("");
  if (w->rows_deferred && !w->gpkg)
    return tt__error(w->ctx, TT_ERR_ARG, "ROWS=DEFERRED is for GPKG "
                     "datasets only");
  /* GPKG: no R-tree at creation (its triggers would update it per insert);
   * it is built in bulk after the inserts, inside the transaction, unless
   * the user asked for none. */
  if (w->gpkg) {
    const char *si = CSLFetchNameValue(w->lco, "SPATIAL_INDEX");
    /* RTREE=DEFERRED: tt_gpkg_build_rtree() on the closed file instead;
     * ROWS=DEFERRED: tt_gpkg_write_rows() builds them with the rows. */
    w->build_rtree = (!si || CPLTestBool(si)) && !w->rtree_deferred &&
                     !w->rows_deferred;
    w->lco = CSLSetNameValue(w->lco, "SPATIAL_INDEX", "NO");
  }
  /* DBF strings are Latin-1 unless told otherwise; CRS names and paths may
   * not be. A .cpg file tells QGIS. And a spatial index (.qix, written at
   * close), as QGIS would otherwise build none. */
  if (w->shapefile && !CSLFetchNameValue(w->lco, "ENCODING"))
    w->lco = CSLSetNameValue(w->lco, "ENCODING", "UTF-8");
  if (w->shapefile && !CSLFetchNameValue(w->lco, "SPATIAL_INDEX"))
    w->lco = CSLSetNameValue(w->lco, "SPATIAL_INDEX", "YES");
  return check_names(w);
}

/* Called after every feature: the callback is asked every time, so a stop
 * is seen after one feature even with a driver that takes seconds per
 * feature (LIBKML); a callback that draws does so only as its bar moves. */
static tt_status report(write_state *w)
{
  w->done++;
  if (!w->progress)
    return TT_OK;
  if (!w->progress(w->scale * (double)w->done / (double)w->total,
                   "writing", w->progress_arg))
    return tt__error(w->ctx, TT_ERR_INTERRUPTED, "writing the TIN was "
                     "interrupted after %zu of %zu features", w->done,
                     w->total);
  return TT_OK;
}

/* OVERWRITE=YES: drops the dataset's layer of that name (in a database,
 * in the schema LCO=SCHEMA names, where GDAL lists it as schema.name). */
static tt_status delete_existing(write_state *w, const char *name)
{
  const char *schema = CSLFetchNameValue(w->lco, "SCHEMA");
  char *full = CPLStrdup(schema && *schema
                             ? CPLSPrintf("%s.%s", schema, name)
                             : name);
  tt_status s = TT_OK;
  /* by name first: PostgreSQL lists no table without geometry, and adds
   * one to its list when it is asked for by name */
  CPLPushErrorHandler(CPLQuietErrorHandler);
  CPLSetCurrentErrorHandlerCatchDebug(FALSE); /* debug: the handler below */
  OGRLayerH named = GDALDatasetGetLayerByName(w->dst, full);
  CPLPopErrorHandler();
  CPLErrorReset();
  int n = named ? GDALDatasetGetLayerCount(w->dst) : 0;
  for (int i = 0; i < n; i++) {
    OGRLayerH l = GDALDatasetGetLayer(w->dst, i);
    if (l == named) {
      CPLErrorReset();
      if (GDALDatasetDeleteLayer(w->dst, i) != OGRERR_NONE)
        s = tt__error(w->ctx, TT_ERR_IO, "cannot replace layer %s: %s",
                      full, ogr_msg());
      break;
    }
  }
  CPLFree(full);
  return s;
}

/* A layer of that name (prefixed by the caller), with lco (the user's -lco
 * for the TIN's layers, none for layer_styles). */
static tt_status create_named_layer(write_state *w, const char *layer_name,
                                    OGRSpatialReferenceH srs,
                                    OGRwkbGeometryType type, char **lco,
                                    OGRLayerH *out_layer)
{
  char *name = CPLStrdup(layer_name);
  if (w->overwrite) {
    /* inside the transaction (databases): a failure puts it back */
    tt_status s = delete_existing(w, name);
    if (s != TT_OK) {
      CPLFree(name);
      return s;
    }
  }
  CPLErrorReset();
  OGRLayerH layer = GDALDatasetCreateLayer(w->dst, name,
                                           type == wkbNone ? NULL : srs,
                                           type, lco);
  if (!layer) {
    tt_status s = tt__error(w->ctx, TT_ERR_IO, "cannot create layer %s: %s",
                            name, ogr_msg());
    CPLFree(name);
    return s;
  }
  w->created[w->ncreated++] = name;
  *out_layer = layer;
  return TT_OK;
}

static tt_status create_layer(write_state *w, const char *suffix,
                              OGRSpatialReferenceH srs,
                              OGRwkbGeometryType type, OGRLayerH *out_layer)
{
  char *name = CPLStrdup(CPLSPrintf("%s%s", w->prefix, suffix));
  /* A GeoPackage layer without a CRS gets srs_id 0, "Undefined geographic
   * SRS", from GDAL; a DEM without one is in pixel or map units, which is
   * -1, "Undefined Cartesian SRS": GDAL maps this WKT to it. */
  OGRSpatialReferenceH undefined = NULL;
  if (!srs && w->gpkg && type != wkbNone) {
    undefined = OSRNewSpatialReference(
        "LOCAL_CS[\"Undefined cartesian SRS\"]");
    srs = undefined;
  }
  tt_status s = create_named_layer(w, name, srs, type, w->lco, out_layer);
  if (undefined)
    OSRDestroySpatialReference(undefined);
  CPLFree(name);
  return s;
}

/* Integer64 where the driver has it; else Integer (MapInfo, whose counts
 * here stay below 2^31: the writer refuses larger TINs, and a triangle's
 * samples are fewer than the DEM's). */
static OGRFieldType field_type(const write_state *w, OGRFieldType t)
{
  return t == OFTInteger64 && w->no_int64 ? OFTInteger : t;
}

/* The index of a field just created; -1 when the layer keeps no such
 * attribute (DXF has a fixed set and creates none): said once, and its
 * values are then skipped. */
static int field_index(write_state *w, OGRLayerH layer, const char *name)
{
  int idx = OGR_FD_GetFieldIndex(OGR_L_GetLayerDefn(layer), name);
  if (idx < 0 && !w->warned_fields) {
    w->warned_fields = 1;
    GDALDriverH drv = GDALGetDatasetDriver(w->dst);
    tt__warn(w->ctx, "the %s driver keeps no attribute fields such as %s "
             "(layer %s): the features are written without them",
             drv ? GDALGetDriverShortName(drv) : "output", name,
             OGR_L_GetName(layer));
  }
  return idx;
}

/* Creates the fields and returns their indices in the layer definition. */
static tt_status create_fields(write_state *w, OGRLayerH layer,
                               const tt__field_spec *spec, int n, int *out_index)
{
  if (!OGR_L_TestCapability(layer, OLCCreateField)) {
    /* DXF: a fixed set of fields, none of ours */
    for (int i = 0; i < n; i++)
      out_index[i] = field_index(w, layer, spec[i].name);
    return TT_OK;
  }
  for (int i = 0; i < n; i++) {
    OGRFieldDefnH fd = OGR_Fld_Create(spec[i].name, field_type(w, spec[i].type));
    CPLErrorReset();
    OGRErr err = OGR_L_CreateField(layer, fd, TRUE);
    OGR_Fld_Destroy(fd);
    if (err != OGRERR_NONE)
      return tt__error(w->ctx, TT_ERR_IO, "cannot create field %s in layer "
                       "%s: %s", spec[i].name, OGR_L_GetName(layer),
                       ogr_msg());
    out_index[i] = field_index(w, layer, spec[i].name);
  }
  return TT_OK;
}

static void set_int(OGRFeatureH f, int idx, int v)
{
  if (idx >= 0)
    OGR_F_SetFieldInteger(f, idx, v);
}

static void set_int64(OGRFeatureH f, int idx, int64_t v)
{
  if (idx >= 0)
    OGR_F_SetFieldInteger64(f, idx, (GIntBig)v);
}

static void set_null(OGRFeatureH f, int idx)
{
  if (idx >= 0)
    OGR_F_SetFieldNull(f, idx);
}

static void set_real(OGRFeatureH f, int idx, double v)
{
  if (idx < 0)
    return;
  if (isfinite(v))
    OGR_F_SetFieldDouble(f, idx, v);
  else
    OGR_F_SetFieldNull(f, idx);
}

static tt_status insert(write_state *w, OGRLayerH layer, OGRFeatureH f,
                        size_t index)
{
  OGR_F_SetFID(f, OGRNullFID);
  CPLErrorReset();
  if (OGR_L_CreateFeature(layer, f) != OGRERR_NONE)
    return tt__error(w->ctx, TT_ERR_IO, "cannot write feature %zu of layer "
                     "%s: %s", index, OGR_L_GetName(layer), ogr_msg());
  return report(w);
}

static tt_status write_triangles(write_state *w, const tt_tin *tin)
{
  OGRLayerH layer = w->tri_layer;
  const int *idx = w->tri_idx;
  tt_status s = TT_OK;
  OGRFeatureH f = OGR_F_Create(OGR_L_GetLayerDefn(layer));
  OGRGeometryH poly = OGR_G_CreateGeometry(wkbPolygon25D);
  OGRGeometryH ring = OGR_G_CreateGeometry(wkbLinearRing);
  OGR_G_AddGeometryDirectly(poly, ring); /* poly owns ring; ring stays ours
                                            to edit through poly */
  OGR_G_Set3D(poly, TRUE); /* CreateGeometry(wkbPolygon25D) makes it 2D */
  const size_t nt = tt_tin_triangle_count(tin);
  for (size_t i = 0; i < nt && s == TT_OK; i++) {
    tt_triangle_info t;
    double px[3], py[3], pz[3];
    s = tt__records_triangle(&w->rec, w->ctx, i, &t, px, py, pz);
    if (s != TT_OK)
      break;
    ring = OGR_G_GetGeometryRef(poly, 0);
    for (int k = 0; k < 4; k++)
      OGR_G_SetPoint(ring, k, px[k % 3], py[k % 3], pz[k % 3]);
    OGR_F_SetGeometry(f, poly);
    set_int(f, idx[TT__TF_V0], t.v[0]);
    set_int(f, idx[TT__TF_V1], t.v[1]);
    set_int(f, idx[TT__TF_V2], t.v[2]);
    set_real(f, idx[TT__TF_MAX_ERR], t.max_error);
    set_real(f, idx[TT__TF_RMSE], t.rmse);
    set_int64(f, idx[TT__TF_N_SAMPLES], (int64_t)t.samples);
    set_real(f, idx[TT__TF_AREA_2D], t.area_2d);
    set_real(f, idx[TT__TF_AREA_3D], t.area_3d);
    set_real(f, idx[TT__TF_SLOPE], t.slope_deg);
    set_real(f, idx[TT__TF_ASPECT], t.aspect_deg);
    set_real(f, idx[TT__TF_MIN_ANGLE], t.min_angle_deg);
    set_real(f, idx[TT__TF_MAX_ANGLE], t.max_angle_deg);
    if (w->brk_fields)
      set_int(f, idx[TT__TF_CONSTRAINED], (int)t.constrained);
    s = insert(w, layer, f, i);
  }
  OGR_G_DestroyGeometry(poly);
  OGR_F_Destroy(f);
  return s;
}

static tt_status write_vertices(write_state *w, const tt_tin *tin)
{
  OGRLayerH layer = w->vtx_layer;
  const int *idx = w->vtx_idx;
  tt_status s = TT_OK;
  OGRFeatureH f = OGR_F_Create(OGR_L_GetLayerDefn(layer));
  OGRGeometryH pt = OGR_G_CreateGeometry(wkbPoint25D);
  OGR_G_Set3D(pt, TRUE);
  const size_t nv = tt_tin_vertex_count(tin);
  const int decimated = tt__records_decimated(tin);
  for (size_t i = 0; i < nv && s == TT_OK; i++) {
    tt_vertex_info v;
    double x, y;
    s = tt__records_vertex(&w->rec, w->ctx, i, &v, &x, &y);
    if (s != TT_OK)
      break;
    OGR_G_SetPoint(pt, 0, x, y, v.z);
    OGR_F_SetGeometry(f, pt);
    set_int(f, idx[TT__VF_ID], (int)i);
    set_int(f, idx[TT__VF_COL], v.col);
    set_int(f, idx[TT__VF_ROW], v.row);
    set_real(f, idx[TT__VF_INS_ERR], v.insert_error);
    if (decimated)
      set_null(f, idx[TT__VF_INS_RANK]);
    else
      set_int64(f, idx[TT__VF_INS_RANK], (int64_t)v.rank);
    set_real(f, idx[TT__VF_STAR_MAX], v.star_max_error);
    set_real(f, idx[TT__VF_STAR_RMSE], v.star_rmse);
    set_int64(f, idx[TT__VF_STAR_N], (int64_t)v.star_samples);
    if (decimated)
      set_real(f, idx[TT__VF_IMPORTANCE], v.importance);
    if (w->ele_idx >= 0)
      OGR_F_SetFieldDouble(f, w->ele_idx, v.z);
    s = insert(w, layer, f, i);
  }
  OGR_G_DestroyGeometry(pt);
  OGR_F_Destroy(f);
  return s;
}

/* The breaklines layer's rows: a 3-D line per TIN edge on a breakline,
 * with its two vertex indices. */
static tt_status write_breaklines(write_state *w, const tt_tin *tin)
{
  int32_t *pairs = NULL;
  size_t n = 0;
  if (!tt__records_breakline_edges(tin, &pairs, &n))
    return tt__error(w->ctx, TT_ERR_NOMEM, "out of memory for the "
                     "breaklines layer");
  tt_status s = TT_OK;
  OGRFeatureH f = OGR_F_Create(OGR_L_GetLayerDefn(w->brk_layer));
  OGRGeometryH line = OGR_G_CreateGeometry(wkbLineString25D);
  OGR_G_Set3D(line, TRUE);
  for (size_t i = 0; i < n && s == TT_OK; i++) {
    for (int k = 0; k < 2 && s == TT_OK; k++) {
      tt_vertex_info v;
      double x, y;
      s = tt__records_vertex(&w->rec, w->ctx, (size_t)pairs[2 * i + k], &v,
                             &x, &y);
      OGR_G_SetPoint(line, k, x, y, v.z);
    }
    if (s != TT_OK)
      break;
    OGR_F_SetGeometry(f, line);
    set_int(f, w->brk_idx[0], pairs[2 * i]);
    set_int(f, w->brk_idx[1], pairs[2 * i + 1]);
    OGR_F_SetFID(f, OGRNullFID);
    CPLErrorReset();
    if (OGR_L_CreateFeature(w->brk_layer, f) != OGRERR_NONE)
      s = tt__error(w->ctx, TT_ERR_IO, "cannot write feature %zu of layer "
                    "%s: %s", i, OGR_L_GetName(w->brk_layer), ogr_msg());
  }
  OGR_G_DestroyGeometry(line);
  OGR_F_Destroy(f);
  free(pairs);
  return s;
}

static tt_status create_run_fields(write_state *w,
                                   const tt_run_field *fields,
                                   size_t nfields)
{
  OGRLayerH layer = w->run_layer;
  w->run_idx = nfields ? malloc(nfields * sizeof *w->run_idx) : NULL;
  if (nfields && !w->run_idx)
    return tt__error(w->ctx, TT_ERR_NOMEM, "out of memory");
  for (size_t i = 0; i < nfields; i++) {
    const tt_run_field *rf = &fields[i];
    if (!OGR_L_TestCapability(layer, OLCCreateField)) {
      w->run_idx[i] = field_index(w, layer, rf->name);
      continue;
    }
    OGRFieldType type = rf->type == TT_FIELD_STRING ? OFTString
                        : rf->type == TT_FIELD_INTEGER
                            ? field_type(w, OFTInteger64)
                            : OFTReal;
    OGRFieldDefnH fd = OGR_Fld_Create(rf->name, type);
    if (w->shapefile && type == OFTString) {
      /* DBF strings are fixed-width: as wide as the value, at most 254. */
      size_t n = rf->s ? strlen(rf->s) : 0;
      if (n > TT_DBF_STRING_MAX)
        tt__warn(w->ctx, "run parameter %s is %zu characters long; a "
                 "shapefile keeps only the first %d", rf->name, n,
                 TT_DBF_STRING_MAX);
      OGR_Fld_SetWidth(fd, n == 0 ? 1 : n > TT_DBF_STRING_MAX
                                            ? TT_DBF_STRING_MAX
                                            : (int)n);
    }
    CPLErrorReset();
    OGRErr err = OGR_L_CreateField(layer, fd, TRUE);
    OGR_Fld_Destroy(fd);
    if (err != OGRERR_NONE)
      return tt__error(w->ctx, TT_ERR_IO, "cannot create field %s in layer "
                       "%s: %s", rf->name, OGR_L_GetName(layer), ogr_msg());
    w->run_idx[i] = field_index(w, layer, rf->name);
  }
  return TT_OK;
}

static tt_status write_run_parameters(write_state *w,
                                      const tt_run_field *fields,
                                      size_t nfields)
{
  OGRFeatureH f = OGR_F_Create(OGR_L_GetLayerDefn(w->run_layer));
  for (size_t i = 0; i < nfields; i++) {
    const tt_run_field *rf = &fields[i];
    int idx = w->run_idx[i];
    if (idx < 0)
      continue;
    if (rf->type == TT_FIELD_STRING) {
      if (rf->s)
        OGR_F_SetFieldString(f, idx, rf->s);
      else
        OGR_F_SetFieldNull(f, idx);
    } else if (rf->type == TT_FIELD_INTEGER) {
      OGR_F_SetFieldInteger64(f, idx, (GIntBig)rf->i);
    } else {
      set_real(f, idx, rf->r);
    }
  }
  tt_status s = insert(w, w->run_layer, f, 0);
  OGR_F_Destroy(f);
  return s;
}

/* A copy of s with single quotes doubled, for an SQL string literal. */
static char *sql_quote(const char *s)
{
  size_t n = 0;
  for (const char *p = s; *p; p++)
    n += *p == '\'' ? 2 : 1;
  char *q = CPLMalloc(n + 1), *o = q;
  for (const char *p = s; *p; p++) {
    *o++ = *p;
    if (*p == '\'')
      *o++ = '\'';
  }
  *o = '\0';
  return q;
}

/* GPKG: builds a layer's R-tree in one pass over its rows (the driver's
 * CreateSpatialIndex() SQL function), inside the open transaction. */
static tt_status build_rtree(write_state *w, OGRLayerH layer)
{
  char *name = sql_quote(OGR_L_GetName(layer));
  char *geom = sql_quote(OGR_L_GetGeometryColumn(layer));
  char *sql = CPLStrdup(
      CPLSPrintf("SELECT CreateSpatialIndex('%s', '%s')", name, geom));
  CPLErrorReset();
  OGRLayerH rs = GDALDatasetExecuteSQL(w->dst, sql, NULL, NULL);
  if (rs)
    GDALDatasetReleaseResultSet(w->dst, rs);
  tt_status s = TT_OK;
  if (CPLGetLastErrorType() >= CE_Failure)
    s = tt__error(w->ctx, TT_ERR_IO, "cannot build the spatial index of "
                  "layer %s: %s", OGR_L_GetName(layer), ogr_msg());
  CPLFree(sql);
  CPLFree(geom);
  CPLFree(name);
  return s;
}

static tt_status check_run_fields(write_state *w, const tt_run_field *fields,
                                  size_t nfields)
{
  for (size_t i = 0; i < nfields; i++) {
    const tt_run_field *rf = &fields[i];
    if (!rf->name || !*rf->name)
      return tt__error(w->ctx, TT_ERR_ARG, "run parameter %zu has no name",
                       i);
    if (rf->type != TT_FIELD_STRING && rf->type != TT_FIELD_INTEGER &&
        rf->type != TT_FIELD_REAL)
      return tt__error(w->ctx, TT_ERR_ARG, "run parameter %s has an unknown "
                       "type %d", rf->name, (int)rf->type);
    if (w->shapefile && strlen(rf->name) > TT_SHP_FIELD_NAME_MAX)
      return tt__error(w->ctx, TT_ERR_ARG, "run parameter name \"%s\" is "
                       "longer than the %d characters a shapefile allows",
                       rf->name, TT_SHP_FIELD_NAME_MAX);
    for (size_t k = 0; k < i; k++)
      if (strcasecmp(fields[k].name, rf->name) == 0)
        return tt__error(w->ctx, TT_ERR_ARG, "run parameter \"%s\" is given "
                         "twice", rf->name);
    const char *fid = CSLFetchNameValue(w->lco, "FID");
    if (fid && strcasecmp(fid, rf->name) == 0)
      return tt__error(w->ctx, TT_ERR_ARG, "layer creation option "
                       "FID=%s: %s is a field of the run_parameters layer; "
                       "the FID column needs a name of its own", fid,
                       rf->name);
  }
  return TT_OK;
}

/* After a failure without a transaction: drop the layers this call made. */
static void delete_created_layers(write_state *w)
{
  for (int k = w->ncreated - 1; k >= 0; k--) {
    int n = GDALDatasetGetLayerCount(w->dst);
    for (int i = 0; i < n; i++) {
      OGRLayerH l = GDALDatasetGetLayer(w->dst, i);
      if (l && strcmp(OGR_L_GetName(l), w->created[k]) == 0) {
        GDALDatasetDeleteLayer(w->dst, i);
        break;
      }
    }
  }
}

/* A layer and its fields. */
static tt_status make_layer(write_state *w, const tt_tin *tin,
                            unsigned which, const tt_run_field *fields,
                            size_t nfields)
{
  tt_status s;
  if (which == TT__LAYER_TRIANGLES) {
    s = create_layer(w, "triangles", w->rec.out_srs, wkbPolygon25D,
                     &w->tri_layer);
    if (s == TT_OK)
      s = create_fields(w, w->tri_layer, tt__triangle_fields,
                        tt__records_triangle_fields(tin), w->tri_idx);
  } else if (which == TT__LAYER_VERTICES) {
    s = create_layer(w, "vertices", w->rec.out_srs, wkbPoint25D,
                     &w->vtx_layer);
    if (s == TT_OK)
      s = create_fields(w, w->vtx_layer, tt__vertex_fields,
                        tt__records_vertex_fields(tin), w->vtx_idx);
    /* GDAL 3.6's GPX writer takes a waypoint's height from its "ele"
     * field (<ele>), not from the point's Z */
    w->ele_idx = -1;
    if (s == TT_OK && strcasecmp(w->drv_name, "GPX") == 0)
      w->ele_idx = OGR_FD_GetFieldIndex(OGR_L_GetLayerDefn(w->vtx_layer),
                                        "ele");
  } else if (which == TT__LAYER_BREAKLINES) {
    static const tt__field_spec brk_fields[2] = {{"v0", OFTInteger},
                                                 {"v1", OFTInteger}};
    s = create_layer(w, "breaklines", w->rec.out_srs, wkbLineString25D,
                     &w->brk_layer);
    if (s == TT_OK)
      s = create_fields(w, w->brk_layer, brk_fields, 2, w->brk_idx);
  } else {
    s = create_layer(w, "run_parameters", NULL, wkbNone, &w->run_layer);
    if (s == TT_OK)
      s = create_run_fields(w, fields, nfields);
  }
  return s;
}

/* A layer's rows (the triangles and vertices unless ROWS=DEFERRED). */
static tt_status fill_layer(write_state *w, const tt_tin *tin,
                            unsigned which, const tt_run_field *fields,
                            size_t nfields)
{
  if (which == TT__LAYER_RUN_PARAMETERS)
    return write_run_parameters(w, fields, nfields);
  if (which == TT__LAYER_BREAKLINES) /* a few rows: never deferred */
    return write_breaklines(w, tin);
  if (w->rows_deferred)
    return TT_OK;
  return which == TT__LAYER_TRIANGLES ? write_triangles(w, tin)
                                      : write_vertices(w, tin);
}

static tt_status start_transaction(write_state *w)
{
  CPLErrorReset();
  if (GDALDatasetStartTransaction(w->dst, FALSE) != OGRERR_NONE)
    return tt__error(w->ctx, TT_ERR_IO, "cannot start a transaction: %s",
                     ogr_msg());
  return TT_OK;
}

/* The order the layers are made and filled in. */
#define NLAYERS 4
static const unsigned layer_order[NLAYERS] = {
    TT__LAYER_TRIANGLES, TT__LAYER_VERTICES, TT__LAYER_BREAKLINES,
    TT__LAYER_RUN_PARAMETERS};

/* The state of a write into dst: the driver's name and what it takes. */
static void begin_write(write_state *w, tt_context *ctx, GDALDatasetH dst,
                        tt_progress_fn progress, void *progress_arg)
{
  memset(w, 0, sizeof *w);
  w->ctx = ctx;
  w->dst = dst;
  w->layers = TT__LAYERS_ALL;
  GDALDriverH drv = GDALGetDatasetDriver(dst);
  w->drv_name = drv ? GDALGetDriverShortName(drv) : "";
  w->shapefile = strcasecmp(w->drv_name, "ESRI Shapefile") == 0;
  w->gpkg = strcasecmp(w->drv_name, "GPKG") == 0;
  w->style_files = w->shapefile ||
                   strcasecmp(w->drv_name, "FlatGeobuf") == 0 ||
                   strcasecmp(w->drv_name, "GeoJSON") == 0;
  const char *types =
      drv ? GDALGetMetadataItem(drv, GDAL_DMD_CREATIONFIELDDATATYPES, NULL)
          : NULL;
  w->no_int64 = types && !strstr(types, "Integer64");
  w->progress = progress;
  w->progress_arg = progress_arg;
}

/* The TIN's size for 32-bit fields, the records of the output CRS, the
 * features to report progress over; progress starts. */
static tt_status prepare_rows(write_state *w, const tt_tin *tin,
                              OGRSpatialReferenceH srs)
{
  const size_t nv = tt_tin_vertex_count(tin);
  const size_t nt = tt_tin_triangle_count(tin);
  if (nv > (size_t)INT32_MAX || nt > (size_t)INT32_MAX)
    return tt__error(w->ctx, TT_ERR_LIMIT, "TIN of %zu vertices and %zu "
                     "triangles is too large for 32-bit feature fields", nv,
                     nt);
  tt_status s = tt__records_init(&w->rec, w->ctx, tin, srs, w->t_srs);
  if (s != TT_OK)
    return s;
  w->total = (w->layers & TT__LAYER_RUN_PARAMETERS) ? 1 : 0;
  if (!w->rows_deferred)
    w->total += ((w->layers & TT__LAYER_TRIANGLES) ? nt : 0) +
                ((w->layers & TT__LAYER_VERTICES) ? nv : 0);
  if (w->total == 0)
    w->total = 1;
  w->scale = w->build_rtree ? 0.75 : 1.0; /* the R-trees take about a
                                              quarter */
  if (w->progress && !w->progress(0.0, "writing", w->progress_arg))
    return tt__error(w->ctx, TT_ERR_INTERRUPTED, "writing the TIN was "
                     "interrupted before the first feature");
  return TT_OK;
}

/* Drivers without transactions: one layer after the other, each complete
 * before the next is made: KML takes features only into its last layer. */
static tt_status write_layer_by_layer(write_state *w, const tt_tin *tin,
                                      const tt_run_field *fields,
                                      size_t nfields)
{
  tt_status s = TT_OK;
  for (int k = 0; k < NLAYERS && s == TT_OK; k++)
    if (w->layers & layer_order[k]) {
      s = make_layer(w, tin, layer_order[k], fields, nfields);
      if (s == TT_OK)
        s = fill_layer(w, tin, layer_order[k], fields, nfields);
    }
  return s;
}

/* With transactions: the layers, their fields and QGIS's style table
 * made, inside the transaction for a database, before it (then started
 * here) otherwise. */
static tt_status make_layers(write_state *w, const tt_tin *tin,
                             const tt_run_field *fields, size_t nfields)
{
  tt_status s = TT_OK;
  if (w->database) {
    s = start_transaction(w);
    if (s != TT_OK)
      return s;
    w->in_transaction = 1;
  }
  for (int k = 0; k < NLAYERS && s == TT_OK; k++)
    if (w->layers & layer_order[k])
      s = make_layer(w, tin, layer_order[k], fields, nfields);
  if (s == TT_OK && w->style && w->gpkg &&
      (w->layers & (TT__LAYER_TRIANGLES | TT__LAYER_VERTICES))) {
    /* as QGIS makes it: the FID column is "id" */
    char **style_lco = CSLSetNameValue(NULL, "FID", "id");
    s = create_named_layer(w, TT__STYLE_TABLE, NULL, wkbNone, style_lco,
                           &w->style_layer);
    CSLDestroy(style_lco);
    if (s == TT_OK)
      s = tt__style_create_fields(w->ctx, w->style_layer);
  }
  if (s != TT_OK || w->database)
    return s;
  /* Drivers that create tables lazily (GPKG) make them now, so that the
   * transaction holds only rows (and the R-trees). */
  CPLErrorReset();
  GDALFlushCache(w->dst);
  if (CPLGetLastErrorType() >= CE_Failure)
    return tt__error(w->ctx, TT_ERR_IO, "cannot create the layers: %s",
                     ogr_msg());
  s = start_transaction(w);
  if (s != TT_OK)
    return s;
  w->in_transaction = 1;
  return TT_OK;
}

/* With transactions, the layers made: their rows, the style rows, the
 * R-trees, then the commit. */
static tt_status fill_and_commit(write_state *w, const tt_tin *tin,
                                 const tt_run_field *fields, size_t nfields)
{
  tt_status s = TT_OK;
  for (int k = 0; k < NLAYERS && s == TT_OK; k++)
    if (w->layers & layer_order[k])
      s = fill_layer(w, tin, layer_order[k], fields, nfields);
  if (s == TT_OK && w->style_layer)
    s = tt__style_insert(w->ctx, w->style_layer, tin, w->prefix, w->layers,
                         w->tri_layer ? OGR_L_GetGeometryColumn(w->tri_layer)
                                      : NULL,
                         w->vtx_layer ? OGR_L_GetGeometryColumn(w->vtx_layer)
                                      : NULL);
  if (s == TT_OK && w->style && w->database &&
      strcasecmp(w->drv_name, "PostgreSQL") == 0)
    s = tt__style_insert_pg(w->ctx, w->dst, tin,
                            CSLFetchNameValue(w->lco, "SCHEMA"),
                            w->tri_layer, w->vtx_layer);
  if (s == TT_OK && w->database &&
      strcasecmp(w->drv_name, "PostgreSQL") == 0)
    s = tt__field_docs_comment_pg(w->ctx, w->dst,
                                  CSLFetchNameValue(w->lco, "SCHEMA"),
                                  w->prefix, w->layers,
                                  tt__records_vertex_fields(tin), fields,
                                  nfields, w->z_unit);
  if (s == TT_OK && w->gpkg)
    s = tt__field_docs_write_gpkg(w->ctx, w->dst, w->prefix, w->layers,
                                  tt__records_vertex_fields(tin), fields,
                                  nfields, w->z_unit);
  if (s == TT_OK && w->build_rtree && w->tri_layer)
    s = build_rtree(w, w->tri_layer);
  if (s == TT_OK && w->build_rtree && w->progress &&
      !w->progress(0.95, "indexing", w->progress_arg))
    s = tt__error(w->ctx, TT_ERR_INTERRUPTED, "writing the TIN was "
                  "interrupted while indexing");
  if (s == TT_OK && w->build_rtree && w->vtx_layer)
    s = build_rtree(w, w->vtx_layer);
  if (s != TT_OK)
    return s;
  CPLErrorReset();
  w->in_transaction = 0; /* a failed commit leaves nothing to roll back */
  if (GDALDatasetCommitTransaction(w->dst) != OGRERR_NONE) {
    w->rolled_back = w->database; /* the tables went with the rows */
    return tt__error(w->ctx, TT_ERR_IO, "cannot commit the TIN: %s",
                     ogr_msg());
  }
  return TT_OK;
}

/* Flushes now so that write errors (disk full) surface here rather than
 * unreported at close; progress ends. */
static tt_status flush_output(write_state *w)
{
  CPLErrorReset();
  GDALFlushCache(w->dst);
  if (CPLGetLastErrorType() >= CE_Failure)
    return tt__error(w->ctx, TT_ERR_IO, "cannot write the TIN: %s",
                     ogr_msg());
  if (w->progress)
    w->progress(1.0, "writing", w->progress_arg); /* done: too late to stop */
  return TT_OK;
}

/* After a failure: the transaction rolled back (a database's tables went
 * with it; its layers that OVERWRITE dropped came back), else the layers
 * made deleted. Then the state freed. */
static void end_write(write_state *w, tt_status s)
{
  if (s != TT_OK) {
    if (w->in_transaction) {
      GDALDatasetRollbackTransaction(w->dst);
      w->rolled_back = w->database;
    }
    if (!w->rolled_back)
      delete_created_layers(w);
  }
  for (int k = 0; k < w->ncreated; k++)
    CPLFree(w->created[k]);
  free(w->run_idx);
  tt__records_free(&w->rec);
  CPLFree(w->t_srs);
  CPLFree(w->z_unit);
  CPLFree(w->prefix);
  CSLDestroy(w->lco);
}

tt_status tt_ogr_write_tin(tt_context *ctx, GDALDatasetH dst,
                           const tt_tin *tin, OGRSpatialReferenceH srs,
                           const tt_run_field *fields, size_t nfields,
                           char **options, tt_progress_fn progress,
                           void *progress_arg)
{
  if (!dst || !tin)
    return tt__error(ctx, TT_ERR_ARG, "dataset and TIN must not be NULL");
  if (nfields && !fields)
    return tt__error(ctx, TT_ERR_ARG, "run parameters must not be NULL");

  write_state w;
  begin_write(&w, ctx, dst, progress, progress_arg);
  tt_status s = parse_options(&w, options);
  if (s == TT_OK)
    s = check_run_fields(&w, fields, nfields);
  /* a TIN with breaklines: their layer beside the triangles */
  w.brk_fields = tt__records_triangle_fields(tin) == TT__TF_COUNT;
  if (w.brk_fields && (w.layers & TT__LAYER_TRIANGLES))
    w.layers |= TT__LAYER_BREAKLINES;
  if (s == TT_OK)
    s = prepare_rows(&w, tin, srs);
  if (s != TT_OK)
    goto done;

  const int transactions = GDALDatasetTestCapability(dst, ODsCTransactions);
  /* A database (PostgreSQL): its tables are made inside the transaction
   * too, so that a failure, an interruption or the end of the process
   * before the commit leaves none. The SQLite formats make theirs before
   * it: GDAL 3.6's GPKG driver keeps the layer objects of a rolled-back
   * CREATE TABLE and then breaks the file at close; on failure they are
   * deleted instead (the temporary name guards the file either way). */
  w.database = transactions && !w.gpkg &&
               strcasecmp(w.drv_name, "SQLite") != 0;
  if (!transactions) {
    s = write_layer_by_layer(&w, tin, fields, nfields);
  } else {
    s = make_layers(&w, tin, fields, nfields);
    if (s == TT_OK)
      s = fill_and_commit(&w, tin, fields, nfields);
  }
  if (s == TT_OK && w.style && w.style_files)
    s = tt__style_write_files(ctx, dst, tin, w.tri_layer, w.vtx_layer);
  if (s == TT_OK)
    s = flush_output(&w);

done:
  end_write(&w, s);
  return s;
}
