/*
 * src/gdal/ogr/ -- the OGR layers: a TIN written into an OGR dataset and
 * triangles read from one, the features' records, QGIS's default style,
 * safe output paths and the protection of the input's files.
 *
 * tin_records.h -- what a TIN's features hold, shared by the writers: the
 * fields of the triangles and vertices layers, and the output coordinates
 * and areas of each feature in the layers' CRS (the input CRS, or T_SRS
 * with every vertex transformed once, up front; geodesic triangle areas
 * when that CRS is geographic).
 *
 * The OGR writer (ogr_write.c), the GeoPackage row writers (gpkg_rows.c
 * and its files, the streamed gpkg_stream.c) and the mesh writers
 * (mesh_write.c, ugrid_write.c) all take their values from here, so they
 * write the same content.
 */
#ifndef TERRATIN_TIN_RECORDS_H
#define TERRATIN_TIN_RECORDS_H

#include "base/internal.h"
#include "terratin/terratin_gdal.h"

#include <geodesic.h>

typedef struct tt__field_spec {
  const char *name;
  OGRFieldType type;
} tt__field_spec;

/* Column order of the two geometry layers; the writers index the tables
 * below by these values. Names have at most 10 characters (DBF). */
enum { TT__TF_V0, TT__TF_V1, TT__TF_V2, TT__TF_MAX_ERR, TT__TF_RMSE,
       TT__TF_N_SAMPLES, TT__TF_AREA_2D, TT__TF_AREA_3D, TT__TF_SLOPE,
       TT__TF_ASPECT, TT__TF_MIN_ANGLE, TT__TF_MAX_ANGLE, TT__TF_CONSTRAINED,
       TT__TF_COUNT };
/* The last triangle field, constrained (tt_triangle_info.constrained: bit
 * k for edge k on a breakline), exists for TINs made with breaklines
 * only: tt__records_triangle_fields() says how many fields a TIN's
 * triangles layer has. */
/* The last vertex field, importance, exists for decimated TINs only
 * (they also leave ins_err and ins_rank NULL: there was no insertion):
 * tt__records_vertex_fields() says how many fields a TIN's layer has. */
enum { TT__VF_ID, TT__VF_COL, TT__VF_ROW, TT__VF_INS_ERR, TT__VF_INS_RANK,
       TT__VF_STAR_MAX, TT__VF_STAR_RMSE, TT__VF_STAR_N, TT__VF_IMPORTANCE,
       TT__VF_COUNT };

TT_HIDDEN extern const tt__field_spec tt__triangle_fields[TT__TF_COUNT];
TT_HIDDEN extern const tt__field_spec tt__vertex_fields[TT__VF_COUNT];

/* Whether the TIN was decimated (tt_decimate_run), and the number of
 * fields of its vertices layer: TT__VF_COUNT then, one fewer otherwise. */
TT_HIDDEN int tt__records_decimated(const tt_tin *tin);
TT_HIDDEN int tt__records_vertex_fields(const tt_tin *tin);
TT_HIDDEN int tt__records_triangle_fields(const tt_tin *tin);
/* The TIN's edges on breaklines, each once: *out_n pairs of vertex
 * indices (the smaller first, sorted) into *out_pairs, which the caller
 * frees with free(); NULL and 0 without breaklines. False when out of
 * memory. */
TT_HIDDEN bool tt__records_breakline_edges(const tt_tin *tin,
                                           int32_t **out_pairs,
                                           size_t *out_n);

/* The layers a writer makes (option LAYERS=triangles,vertices,
 * run_parameters, any subset in any order; default all three). */
enum { TT__LAYER_TRIANGLES = 1, TT__LAYER_VERTICES = 2,
       TT__LAYER_RUN_PARAMETERS = 4, TT__LAYERS_ALL = 7,
       /* made beside the triangles when the TIN has breaklines: a line
        * feature per edge on a breakline */
       TT__LAYER_BREAKLINES = 8 };
/* The bits of a LAYERS value; TT_ERR_ARG naming the word at fault. */
TT_HIDDEN tt_status tt__records_parse_layers(tt_context *ctx,
                                             const char *value,
                                             unsigned *out_mask);

/* The layers' CRS and the transformed vertices. */
typedef struct tt__records {
  const tt_tin *tin;
  OGRSpatialReferenceH out_srs; /* the layers' CRS (owned), NULL: none */
  double *xy;                   /* T_SRS: 2 doubles per vertex, else NULL */
  int geodesic;                 /* geodesic areas: 1 from the output
                                   coordinates (geographic output CRS),
                                   2 from the input's (geographic input) */
  struct geod_geodesic geod;
  double deg_per_unit;          /* output angular unit in degrees */
} tt__records;

/* Sets up *r for tin: the layers' CRS is srs, or t_srs (any
 * OSRSetFromUserInput form; NULL or "": none) with every vertex transformed
 * from srs. On failure *r holds nothing to free but tt__records_free()
 * accepts it. */
TT_HIDDEN tt_status tt__records_init(tt__records *r, tt_context *ctx,
                                     const tt_tin *tin,
                                     OGRSpatialReferenceH srs,
                                     const char *t_srs);
TT_HIDDEN void tt__records_free(tt__records *r);

/* Triangle i: its record (areas in the output CRS's terms) and its three
 * vertices' output x, y and z, counter-clockwise in those coordinates
 * (out_t->v in the same order). TT_ERR_INTERNAL when the TIN cannot give
 * them. */
TT_HIDDEN tt_status tt__records_triangle(const tt__records *r,
                                         tt_context *ctx, size_t i,
                                         tt_triangle_info *out_t,
                                         double out_x[3], double out_y[3],
                                         double out_z[3]);
/* Triangle i as the mesh writers need it, without the derived fields:
 * out_t->v (counter-clockwise in the output coordinates, as
 * tt__records_triangle() orders them), max_error, rmse and samples; the
 * areas, slope, aspect and angles are left NaN. The TIN's own arrays are
 * read, so the trigonometry of tt_tin_triangle() is skipped (most of a
 * mesh writer's time otherwise). */
TT_HIDDEN tt_status tt__records_face(const tt__records *r, tt_context *ctx,
                                     size_t i, tt_triangle_info *out_t);
/* Vertex i and its output x, y. */
TT_HIDDEN tt_status tt__records_vertex(const tt__records *r, tt_context *ctx,
                                       size_t i, tt_vertex_info *out_v,
                                       double *out_x, double *out_y);

#endif /* TERRATIN_TIN_RECORDS_H */
