/*
 * src/gdal/ogr/ -- the OGR layers: a TIN written into an OGR dataset and
 * triangles read from one, the features' records, QGIS's default style,
 * safe output paths and the protection of the input's files.
 *
 * layer_style.h -- the default QGIS style of the TIN's layers: the
 * `layer_styles` table of QGIS's own convention (written by QGIS's OGR
 * provider when a user saves a style into the file, read when the layer is
 * opened) with one row per geometry layer (GeoPackage, PostgreSQL), or a
 * .qml beside each layer's file; graduated colours on max_err for
 * triangles (see-through fills) and on ins_err for vertices, the fields'
 * titles as aliases.
 */
#ifndef TERRATIN_LAYER_STYLE_H
#define TERRATIN_LAYER_STYLE_H

#include "base/internal.h"
#include "terratin/terratin_gdal.h"

#define TT__STYLE_TABLE "layer_styles"

/* The table's fields, as QGIS makes them (the FID column is "id": the
 * caller creates the layer with LCO FID=id). */
TT_HIDDEN tt_status tt__style_create_fields(tt_context *ctx, OGRLayerH layer);

/* One default style row for each of the triangles and vertices layers in
 * layers (TT__LAYER_* bits), named prefix + "triangles" / "vertices" with
 * geometry columns tri_geom / vtx_geom; classes from the TIN's values. */
TT_HIDDEN tt_status tt__style_insert(tt_context *ctx, OGRLayerH layer,
                                     const tt_tin *tin, const char *prefix,
                                     unsigned layers, const char *tri_geom,
                                     const char *vtx_geom);

/* Formats without a style table (Shapefile, FlatGeobuf, GeoJSON): the
 * same default style as a QML file beside each geometry layer's file,
 * which QGIS loads with the layer (NAME.qml beside NAME.shp): in a
 * folder dataset <folder>/<layer>.qml, else the dataset's file with the
 * extension .qml (one geometry layer). tri_layer or vtx_layer may be
 * NULL (not written). */
TT_HIDDEN tt_status tt__style_write_files(tt_context *ctx, GDALDatasetH dst,
                                          const tt_tin *tin,
                                          OGRLayerH tri_layer,
                                          OGRLayerH vtx_layer);

/* PostgreSQL, inside the write's transaction: QGIS's layer_styles table
 * (unqualified: the search path's, where QGIS looks) made as QGIS makes
 * it when missing, and a default row for each geometry layer given (its
 * table in schema, NULL: the current schema), terratin's earlier row for
 * that table deleted. QGIS opens the tables with these styles. */
TT_HIDDEN tt_status tt__style_insert_pg(tt_context *ctx, GDALDatasetH dst,
                                        const tt_tin *tin,
                                        const char *schema,
                                        OGRLayerH tri_layer,
                                        OGRLayerH vtx_layer);

/* The QML of a graduated renderer on the expression attr (XML-escaped
 * here) over values (NaN ignored; n may be 0): five classes coloured
 * yellow to red, equal intervals from the smallest value to the largest,
 * or quantiles when quantiles is set (equal intervals when repeated values
 * leave fewer than three; fewer classes when values repeat); points when
 * point is set, else polygons. nan_class adds a grey first class for NULL
 * values, which attr must map to -1 (coalesce). The caller frees the
 * result with CPLFree(); NULL when out of memory. */
TT_HIDDEN char *tt__style_graduated_qml(const char *attr, const double *values,
                                        size_t n, int point, int nan_class,
                                        int quantiles);

#endif
