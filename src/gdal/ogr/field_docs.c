/*
 * src/gdal/ogr/ -- the OGR layers: a TIN written into an OGR dataset and
 * triangles read from one, the features' records, QGIS's default style,
 * safe output paths and the protection of the input's files.
 *
 * field_docs.c -- the title and description of every field of the
 * triangles and vertices layers, and their rows in a GeoPackage's
 * gpkg_data_columns (see field_docs.h).
 *
 * The schema extension of the GeoPackage standard (OGC 12-128r18, F.9):
 * gpkg_data_columns holds, per table and column, a name, a title and a
 * description; with it comes gpkg_data_column_constraints (left empty
 * here), and both are registered in gpkg_extensions as "gpkg_schema",
 * scope read-write. name and title both get the field's title: GDAL's
 * GPKG driver reads the name as the field's alternative name (the alias
 * QGIS shows), readers of the standard show the title; (table_name, name)
 * is unique, so the titles of a layer differ. Heights and errors are in
 * the run's height unit, said in the description ("{z}" in the tables).
 *
 * A PostgreSQL table gets the same descriptions as its columns' comments
 * (COMMENT ON COLUMN), which QGIS shows as the fields' comments.
 *
 * Workload: a few dozen INSERTs or COMMENTs through the driver's SQL.
 */
#include "gdal/ogr/field_docs.h"

#include <cpl_conv.h>
#include <cpl_error.h>
#include <cpl_string.h>

#include <string.h>

const tt__field_doc tt__triangle_docs[TT__TF_COUNT] = {
    {"v0", "vertex 0", "vertex_id of the triangle's first corner (the "
     "corners run counter-clockwise)"},
    {"v1", "vertex 1", "vertex_id of the triangle's second corner"},
    {"v2", "vertex 2", "vertex_id of the triangle's third corner"},
    {"max_err", "max error", "largest |TIN - DEM| of the samples in this "
     "triangle ({z})"},
    {"rmse", "RMS error", "root mean square of TIN - DEM over the samples "
     "in this triangle ({z})"},
    {"n_samples", "samples", "number of valid DEM samples in this triangle"},
    {"area_2d", "plan area", "area of the triangle seen from above (square "
     "metres for a DEM in metres or in degrees, else the square of the "
     "DEM's ground unit)"},
    {"area_3d", "surface area", "area of the triangle's sloping surface "
     "(the unit of area_2d)"},
    {"slope", "slope", "slope of the triangle's plane (degrees from "
     "horizontal)"},
    {"aspect", "aspect", "direction the triangle's plane faces downhill "
     "(degrees clockwise from north); NULL for a flat triangle"},
    {"min_angle", "smallest angle", "smallest interior angle of the "
     "triangle (degrees)"},
    {"max_angle", "largest angle", "largest interior angle of the triangle "
     "(degrees)"},
    {"constrained", "breakline edges", "edges of the triangle on a "
     "breakline: 1 for v0-v1, 2 for v1-v2, 4 for v2-v0, summed (only in "
     "a TIN made with -breaklines)"}};

/* The triangles layer's fields: constrained only beside a breaklines
 * layer (a TIN made with breaklines, tin_records.h). */
static int tri_fields(unsigned layers)
{
  return (layers & TT__LAYER_BREAKLINES) ? TT__TF_COUNT : TT__TF_COUNT - 1;
}

const tt__field_doc tt__vertex_docs[TT__VF_COUNT] = {
    {"vertex_id", "vertex id", "the vertex's number, as the triangles' v0, "
     "v1 and v2 give it"},
    {"col", "DEM column", "column of the DEM sample this vertex is (0: the "
     "leftmost)"},
    {"row", "DEM row", "row of the DEM sample this vertex is (0: the top)"},
    {"ins_err", "insertion error", "|TIN - DEM| at this sample when it was "
     "inserted, the worst of the TIN then ({z}); NULL for the vertices the "
     "run started from and in a decimated TIN"},
    {"ins_rank", "insertion rank", "order of insertion (0: the first "
     "inserted); NULL in a decimated TIN"},
    {"star_max", "star max error", "largest |TIN - DEM| of the samples in "
     "the triangles around this vertex ({z})"},
    {"star_rmse", "star RMS error", "root mean square of TIN - DEM over the "
     "samples in the triangles around this vertex ({z})"},
    {"star_n", "star samples", "number of valid DEM samples in the "
     "triangles around this vertex"},
    {"importance", "importance", "the vertex's importance when the "
     "decimation stopped (with -importance error, the error its removal "
     "would leave, {z}); NULL for a vertex that may not go"}};

/* The run_parameters fields the commands write (apps/simplify/
 * run_fields.c, apps/optimize/optimize.c), by name; another field gets
 * its name as its title and no description. */
static const tt__field_doc run_docs[] = {
    {"input", "input DEM", "the DEM the TIN was made from (or measured "
     "against)"},
    {"in_tin", "input TIN", "the TIN that was re-optimised"},
    {"band", "band", "band of the DEM read (1: the first)"},
    {"driver", "DEM driver", "GDAL driver that read the DEM"},
    {"method", "method", "how the TIN was made: insert (greedy insertion) "
     "or decimate (vertex removal)"},
    {"criterion", "criterion", "triangulation criterion of the swaps "
     "(-criterion)"},
    {"repair", "repair", "local repair after each insertion, as resolved "
     "(-repair)"},
    {"optimize", "optimiser", "final swap pass over the whole mesh, as "
     "resolved (-optimize)"},
    {"max_error", "error bound", "the bound every valid sample was to meet "
     "({z}); NULL or negative: none"},
    {"max_points", "point limit", "the -max_points limit (0: none)"},
    {"max_tris", "triangle limit", "the -max_triangles limit (0: none)"},
    {"percent", "percent limit", "the -percent limit, share of the valid "
     "samples kept (%; 0: none)"},
    {"stop", "stop reason", "the condition that ended the run"},
    {"vertices", "vertex count", "number of vertices of the TIN"},
    {"triangles", "triangle count", "number of triangles of the TIN"},
    {"cells", "DEM cells", "number of cells of the DEM read"},
    {"valid", "valid samples", "number of DEM samples that are not "
     "nodata"},
    {"lone", "uncovered samples", "valid samples no triangle covers "
     "(isolated by nodata)"},
    {"components", "components", "number of separate pieces of the TIN"},
    {"ach_max", "achieved max error", "largest |TIN - DEM| over the valid "
     "samples ({z})"},
    {"ach_rmse", "achieved RMS error", "root mean square of TIN - DEM over "
     "the valid samples ({z})"},
    {"ach_mean", "achieved mean error", "mean |TIN - DEM| over the valid "
     "samples ({z})"},
    {"ach_l2", "achieved L2 error", "square root of the sum of (TIN - DEM)^2 "
     "over the valid samples ({z})"},
    {"z_unit", "height unit", "unit of the TIN's heights and errors"},
    {"z_unit_in", "declared height unit", "height unit as the DEM declares "
     "it"},
    {"z_factor", "height factor", "factor the DEM's values were multiplied "
     "by (unit conversion times -z_factor)"},
    {"pixel_is", "pixel is", "whether a DEM value is the cell's area "
     "(Area) or its centre point (Point), as declared"},
    {"crs", "DEM CRS", "coordinate reference system of the DEM"},
    {"out_crs", "output CRS", "coordinate reference system the layers were "
     "transformed to (-t_srs); empty: the DEM's"},
    {"frame", "ground frame", "the plane the TIN was made in (a "
     "geographic DEM is mapped to metres)"},
    {"scale_err", "frame scale error", "largest |k - 1| of the ground "
     "frame's scale factor k over the samples"},
    {"version", "terratin version", "version of terratin that wrote this "
     "file"},
    {"t_read", "read time", "seconds spent reading the DEM"},
    {"t_simplify", "simplify time", "seconds spent making the TIN"},
    {"t_mesh", "mesh time", "seconds spent in the mesh operations"},
    {"t_stats", "statistics time", "seconds spent measuring the errors"},
    {"t_optimize", "optimise time", "seconds spent re-optimising"},
    {"created", "created", "when the file was written (UTC, ISO 8601)"},
    {"start", "decimation start", "the TIN decimation started from"},
    {"importance", "importance measure", "which vertex is removed first "
     "(-importance), as resolved"},
    {"selection", "selection", "how vertices are chosen for removal "
     "(-selection)"},
    {"hole", "hole rule", "how a removed vertex's hole is triangulated, as "
     "resolved"},
    {"rounds", "rounds", "rounds of independent removals"},
    {"start_vtx", "start vertices", "vertices of the starting TIN"},
    {"removed", "removed vertices", "vertices removed by the decimation"},
    {"refused", "refused removals", "removals refused because they would "
     "break the error bound"},
    {"tile_size", "tile size", "side of a tile in samples (tiled runs)"},
    {"tiles", "tiles", "number of tiles the DEM was cut into"},
    {"tile_auto", "tiled by itself", "1 when the tiling was chosen "
     "automatically (memory), 0 when asked for"},
    {"seed", "seed", "random seed of the annealing"},
    {"in_mean", "input mean error", "mean |TIN - DEM| of the input TIN "
     "({z})"},
    {"in_max", "input max error", "largest |TIN - DEM| of the input TIN "
     "({z})"},
    {"in_rmse", "input RMS error", "root mean square of TIN - DEM of the "
     "input TIN ({z})"},
    {"in_l2", "input L2 error", "square root of the sum of (TIN - DEM)^2 "
     "of the input TIN ({z})"},
    {"in_angle", "input smallest angle", "smallest interior angle of the "
     "input TIN (degrees)"},
    {"ach_angle", "achieved smallest angle", "smallest interior angle of "
     "the TIN (degrees)"},
};

const tt__field_doc *tt__field_doc_run(const char *name)
{
  for (size_t i = 0; i < sizeof run_docs / sizeof run_docs[0]; i++)
    if (strcmp(run_docs[i].name, name) == 0)
      return &run_docs[i];
  return NULL;
}

char *tt__field_doc_text(const char *description, const char *z_unit)
{
  const char *unit = z_unit && *z_unit ? z_unit : "z units";
  size_t n = 1, nu = strlen(unit);
  for (const char *p = description; *p; p++)
    n += strncmp(p, "{z}", 3) == 0 ? nu : 1;
  char *out = CPLMalloc(n), *o = out;
  for (const char *p = description; *p;) {
    if (strncmp(p, "{z}", 3) == 0) {
      memcpy(o, unit, nu);
      o += nu;
      p += 3;
    } else {
      *o++ = *p++;
    }
  }
  *o = '\0';
  return out;
}

/* An SQL string literal of s (quotes doubled), NULL for none; CPLFree. */
char *tt__sql_literal(const char *s)
{
  if (!s)
    return CPLStrdup("NULL");
  size_t n = 3;
  for (const char *p = s; *p; p++)
    n += *p == '\'' ? 2 : 1;
  char *q = CPLMalloc(n), *o = q;
  *o++ = '\'';
  for (const char *p = s; *p; p++) {
    *o++ = *p;
    if (*p == '\'')
      *o++ = '\'';
  }
  *o++ = '\'';
  *o = '\0';
  return q;
}

/* Runs one statement that returns no rows. */
tt_status tt__sql_exec(tt_context *ctx, GDALDatasetH dst, const char *sql,
                       const char *what)
{
  CPLErrorReset();
  OGRLayerH rs = GDALDatasetExecuteSQL(dst, sql, NULL, NULL);
  if (rs)
    GDALDatasetReleaseResultSet(dst, rs);
  if (CPLGetLastErrorType() >= CE_Failure) {
    const char *m = CPLGetLastErrorMsg();
    return tt__error(ctx, TT_ERR_IO, "cannot %s: %s", what,
                     m && *m ? m : "no details from GDAL");
  }
  return TT_OK;
}

/* The tables of the schema extension and their registration. */
static tt_status create_schema_tables(tt_context *ctx, GDALDatasetH dst)
{
  static const char *const sql[] = {
      "CREATE TABLE IF NOT EXISTS gpkg_extensions (table_name TEXT, "
      "column_name TEXT, extension_name TEXT NOT NULL, definition TEXT NOT "
      "NULL, scope TEXT NOT NULL, CONSTRAINT ge_tce UNIQUE (table_name, "
      "column_name, extension_name))",
      "CREATE TABLE IF NOT EXISTS gpkg_data_columns (table_name TEXT NOT "
      "NULL, column_name TEXT NOT NULL, name TEXT, title TEXT, description "
      "TEXT, mime_type TEXT, constraint_name TEXT, CONSTRAINT pk_gdc "
      "PRIMARY KEY (table_name, column_name), CONSTRAINT gdc_tn UNIQUE "
      "(table_name, name))",
      "CREATE TABLE IF NOT EXISTS gpkg_data_column_constraints "
      "(constraint_name TEXT NOT NULL, constraint_type TEXT NOT NULL, value "
      "TEXT, min NUMERIC, min_is_inclusive BOOLEAN, max NUMERIC, "
      "max_is_inclusive BOOLEAN, description TEXT, CONSTRAINT gdcc_ntv "
      "UNIQUE (constraint_name, constraint_type, value))",
      "INSERT OR IGNORE INTO gpkg_extensions VALUES ('gpkg_data_columns', "
      "NULL, 'gpkg_schema', 'http://www.geopackage.org/spec121/"
      "#extension_schema', 'read-write')",
      "INSERT OR IGNORE INTO gpkg_extensions VALUES "
      "('gpkg_data_column_constraints', NULL, 'gpkg_schema', "
      "'http://www.geopackage.org/spec121/#extension_schema', 'read-write')"};
  tt_status s = TT_OK;
  for (size_t i = 0; i < sizeof sql / sizeof sql[0] && s == TT_OK; i++)
    s = tt__sql_exec(ctx, dst, sql[i], "describe the fields");
  return s;
}

static tt_status insert_row(tt_context *ctx, GDALDatasetH dst,
                            const char *table, const char *column,
                            const char *title, const char *description,
                            const char *z_unit)
{
  char *text = description ? tt__field_doc_text(description, z_unit) : NULL;
  char *t = tt__sql_literal(table), *c = tt__sql_literal(column), *ti = tt__sql_literal(title),
       *d = tt__sql_literal(text);
  char *sql = CPLStrdup(CPLSPrintf(
      "INSERT OR REPLACE INTO gpkg_data_columns (table_name, column_name, "
      "name, title, description) VALUES (%s, %s, %s, %s, %s)",
      t, c, ti, ti, d));
  tt_status s = tt__sql_exec(ctx, dst, sql, "describe the fields");
  CPLFree(sql);
  CPLFree(t);
  CPLFree(c);
  CPLFree(ti);
  CPLFree(d);
  CPLFree(text);
  return s;
}

tt_status tt__field_docs_write_gpkg(tt_context *ctx, GDALDatasetH dst,
                                    const char *prefix, unsigned layers,
                                    int n_vertex_fields,
                                    const tt_run_field *fields,
                                    size_t nfields, const char *z_unit)
{
  tt_status s = create_schema_tables(ctx, dst);
  char *table = CPLStrdup(CPLSPrintf("%striangles", prefix));
  for (int i = 0; i < tri_fields(layers) && s == TT_OK &&
                  (layers & TT__LAYER_TRIANGLES); i++)
    s = insert_row(ctx, dst, table, tt__triangle_docs[i].name,
                   tt__triangle_docs[i].title,
                   tt__triangle_docs[i].description, z_unit);
  CPLFree(table);
  table = CPLStrdup(CPLSPrintf("%svertices", prefix));
  for (int i = 0; i < n_vertex_fields && s == TT_OK &&
                  (layers & TT__LAYER_VERTICES); i++)
    s = insert_row(ctx, dst, table, tt__vertex_docs[i].name,
                   tt__vertex_docs[i].title, tt__vertex_docs[i].description,
                   z_unit);
  CPLFree(table);
  table = CPLStrdup(CPLSPrintf("%srun_parameters", prefix));
  for (size_t i = 0; i < nfields && s == TT_OK &&
                     (layers & TT__LAYER_RUN_PARAMETERS); i++) {
    const tt__field_doc *d = tt__field_doc_run(fields[i].name);
    s = insert_row(ctx, dst, table, fields[i].name,
                   d ? d->title : fields[i].name,
                   d ? d->description : NULL, z_unit);
  }
  CPLFree(table);
  return s;
}

/* A PostgreSQL identifier in double quotes (doubled inside), CPLFree. */
static char *identifier(const char *s)
{
  size_t n = 3;
  for (const char *p = s; *p; p++)
    n += *p == '"' ? 2 : 1;
  char *q = CPLMalloc(n), *o = q;
  *o++ = '"';
  for (const char *p = s; *p; p++) {
    *o++ = *p;
    if (*p == '"')
      *o++ = '"';
  }
  *o++ = '"';
  *o = '\0';
  return q;
}

static tt_status comment_column(tt_context *ctx, GDALDatasetH dst,
                                const char *qualified, const char *column,
                                const char *description, const char *z_unit)
{
  if (!description)
    return TT_OK;
  char *text = tt__field_doc_text(description, z_unit);
  char *c = identifier(column), *d = tt__sql_literal(text);
  char *sql = CPLStrdup(CPLSPrintf("COMMENT ON COLUMN %s.%s IS %s",
                                   qualified, c, d));
  tt_status s = tt__sql_exec(ctx, dst, sql, "describe the fields");
  CPLFree(sql);
  CPLFree(d);
  CPLFree(c);
  CPLFree(text);
  return s;
}

tt_status tt__field_docs_comment_pg(tt_context *ctx, GDALDatasetH dst,
                                    const char *schema, const char *prefix,
                                    unsigned layers, int n_vertex_fields,
                                    const tt_run_field *fields,
                                    size_t nfields, const char *z_unit)
{
  tt_status s = TT_OK;
  static const char *const suffix[3] = {"triangles", "vertices",
                                        "run_parameters"};
  static const unsigned bit[3] = {TT__LAYER_TRIANGLES, TT__LAYER_VERTICES,
                                  TT__LAYER_RUN_PARAMETERS};
  for (int k = 0; k < 3 && s == TT_OK; k++) {
    if (!(layers & bit[k]))
      continue;
    char *t = identifier(CPLSPrintf("%s%s", prefix, suffix[k]));
    char *sch = schema && *schema ? identifier(schema) : NULL;
    char *qualified = CPLStrdup(sch ? CPLSPrintf("%s.%s", sch, t) : t);
    size_t n = k == 0 ? (size_t)tri_fields(layers)
             : k == 1 ? (size_t)n_vertex_fields
                                              : nfields;
    for (size_t i = 0; i < n && s == TT_OK; i++) {
      const tt__field_doc *d = k == 0   ? &tt__triangle_docs[i]
                               : k == 1 ? &tt__vertex_docs[i]
                                        : tt__field_doc_run(fields[i].name);
      const char *column = k == 2 ? fields[i].name : d->name;
      s = comment_column(ctx, dst, qualified, column,
                         d ? d->description : NULL, z_unit);
    }
    CPLFree(qualified);
    CPLFree(sch);
    CPLFree(t);
  }
  return s;
}
