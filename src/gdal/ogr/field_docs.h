/*
 * src/gdal/ogr/ -- the OGR layers: a TIN written into an OGR dataset and
 * triangles read from one, the features' records, QGIS's default style,
 * safe output paths and the protection of the input's files.
 *
 * field_docs.h -- what each field of the TIN's layers means: a title (the
 * alias QGIS shows as the column's name) and a description with its unit,
 * written into a GeoPackage's gpkg_data_columns table (the GeoPackage
 * schema extension).
 */
#ifndef TERRATIN_FIELD_DOCS_H
#define TERRATIN_FIELD_DOCS_H

#include "base/internal.h"
#include "gdal/ogr/tin_records.h"
#include "terratin/terratin_gdal.h"

typedef struct tt__field_doc {
  const char *name;
  const char *title;
  const char *description; /* "{z}" stands for the height unit */
} tt__field_doc;

/* In the order of tt__triangle_fields and tt__vertex_fields. */
TT_HIDDEN extern const tt__field_doc tt__triangle_docs[TT__TF_COUNT];
TT_HIDDEN extern const tt__field_doc tt__vertex_docs[TT__VF_COUNT];

/* The description of a run_parameters field the commands write, by
 * name; NULL for another. */
TT_HIDDEN const tt__field_doc *tt__field_doc_run(const char *name);

/* description with each "{z}" replaced by z_unit ("z units" when z_unit
 * is NULL or ""). The caller frees the result with CPLFree(). */
TT_HIDDEN char *tt__field_doc_text(const char *description,
                                   const char *z_unit);

/* Into the GeoPackage dst (inside the caller's transaction): the tables
 * gpkg_data_columns and gpkg_data_column_constraints when missing, their
 * registration in gpkg_extensions (extension gpkg_schema), and one row per
 * field of the layers in layers (TT__LAYER_* bits) named prefix +
 * "triangles", "vertices", "run_parameters" (the triangles' constrained
 * field only with TT__LAYER_BREAKLINES in layers): n_vertex_fields of the vertex
 * fields, and fields[0..nfields) of run_parameters, described by
 * tt__field_doc_run() (a field it does not know: its name as title, no
 * description). Rows of
 * those tables already there are replaced. */
TT_HIDDEN tt_status tt__field_docs_write_gpkg(tt_context *ctx,
                                              GDALDatasetH dst,
                                              const char *prefix,
                                              unsigned layers,
                                              int n_vertex_fields,
                                              const tt_run_field *fields,
                                              size_t nfields,
                                              const char *z_unit);

/* PostgreSQL, inside the write's transaction: the same descriptions as
 * comments on the columns of the tables prefix + "triangles", ... in
 * schema (NULL: the search path's). */
TT_HIDDEN tt_status tt__field_docs_comment_pg(tt_context *ctx,
                                              GDALDatasetH dst,
                                              const char *schema,
                                              const char *prefix,
                                              unsigned layers,
                                              int n_vertex_fields,
                                              const tt_run_field *fields,
                                              size_t nfields,
                                              const char *z_unit);

/* The SQL the descriptions and styles are written with (field_docs.c,
 * layer_style.c): s as a string literal, quotes doubled ("NULL" for NULL;
 * CPLFree), and one statement run on dst, a failure recorded as "cannot
 * WHAT: GDAL's message". */
TT_HIDDEN char *tt__sql_literal(const char *s);
TT_HIDDEN tt_status tt__sql_exec(tt_context *ctx, GDALDatasetH dst,
                                 const char *sql, const char *what);

#endif /* TERRATIN_FIELD_DOCS_H */
