/*
 * src/gdal/mesh/ -- the mesh formats: a TIN as SMS 2DM, PLY, OBJ, LandXML
 * or UGRID netCDF, without OGR.
 *
 * mesh_read.h -- what the readers of mesh files share (mesh_read.c, the
 * dispatcher, and one mesh_read_<format>.c per format): a triangle soup
 * built from a vertex list and faces that index it (PLY, OBJ, 2DM,
 * LandXML, UGRID) or from triangles that carry their corners (STL).
 *
 * A reader adds vertices with tt__soup_vertex (or at an id with
 * tt__soup_vertex_at, for 2DM's ND and LandXML's P, whose ids are the
 * faces' references), then faces with tt__soup_face; a face of 3 corners
 * becomes a triangle, any other is counted as rejected (a TIN holds
 * triangles; quads are not split, as the OGR reader does not split
 * them). A face that names a vertex the file does not hold is a format
 * error that names the face. Memory: 24 bytes per vertex, 72 per
 * triangle, each array grown by 1.5x steps.
 */
#ifndef TERRATIN_MESH_READ_H
#define TERRATIN_MESH_READ_H

#include "base/internal.h"
#include "terratin/terratin_gdal.h"

#include <cpl_vsi.h>

typedef struct tt__soup {
  tt_context *ctx;
  const char *path;  /* names the file in messages */
  double *v;         /* nv vertices, x y z; NaN x: an id without vertex */
  size_t nv, vcap;
  double *xyz;       /* nt triangles, 9 doubles each */
  size_t nt, tcap;
  size_t rejected;   /* faces that are not triangles */
  char *crs_wkt;     /* the CRS the file declares (malloc'd) or NULL */
} tt__soup;

TT_HIDDEN tt_status tt__soup_vertex(tt__soup *s, double x, double y,
                                    double z);
/* Vertex at index id (0-based), the ids skipped in between left empty. */
TT_HIDDEN tt_status tt__soup_vertex_at(tt__soup *s, size_t id, double x,
                                       double y, double z);
/* A face of n corners, idx[] 0-based into the vertices; face names it in
 * messages (1-based, as the file counts). */
TT_HIDDEN tt_status tt__soup_face(tt__soup *s, const long long *idx, int n,
                                  size_t face);
/* A triangle given by its corners (STL). */
TT_HIDDEN tt_status tt__soup_triangle(tt__soup *s, const double c[9]);
TT_HIDDEN void tt__soup_set_crs(tt__soup *s, const char *wkt, size_t len);

/* The per-format readers: fp is open at the start of the file (the UGRID
 * reader opens path itself with libnetcdf). */
TT_HIDDEN tt_status tt__mesh_read_stl(tt__soup *s, VSILFILE *fp);
TT_HIDDEN tt_status tt__mesh_read_ply(tt__soup *s, VSILFILE *fp);
TT_HIDDEN tt_status tt__mesh_read_obj(tt__soup *s, VSILFILE *fp);
TT_HIDDEN tt_status tt__mesh_read_2dm(tt__soup *s, VSILFILE *fp);
TT_HIDDEN tt_status tt__mesh_read_landxml(tt__soup *s, VSILFILE *fp);
TT_HIDDEN tt_status tt__mesh_read_ugrid(tt__soup *s, const char *path);
/* Whether path is a netCDF file with a UGRID mesh_topology variable. */
TT_HIDDEN int tt__mesh_is_ugrid(const char *path);

/* Splits a text line into at most max whitespace-separated words, in
 * place; returns their count. */
TT_HIDDEN int tt__mesh_words(char *line, char **words, int max);
/* A number word: 1 and *out when the whole word is one, else 0. */
TT_HIDDEN int tt__mesh_number(const char *word, double *out);
TT_HIDDEN int tt__mesh_integer(const char *word, long long *out);

#endif /* TERRATIN_MESH_READ_H */
