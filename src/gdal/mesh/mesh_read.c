/*
 * src/gdal/mesh/ -- the mesh formats: a TIN as SMS 2DM, PLY, OBJ, LandXML
 * or UGRID netCDF, without OGR.
 *
 * mesh_read.c -- a TIN file that is not an OGR dataset, read as a triangle
 * soup for `terratin eval`: the dispatcher that names the format from the
 * file's first bytes (and its extension where the content says little:
 * OBJ, STL), the format readers it calls (mesh_read_<format>.c) and the
 * soup they fill (mesh_read.h). Coordinates come back as the file holds
 * them (OBJ's `# origin X Y` of -obj_local added back, LandXML's
 * northing/easting swapped to x, y); putting them on the DEM is
 * tt_tin_to_pixels' work. Files go through GDAL's VSI layer, so
 * /vsizip/ and /vsicurl/ paths work as for OGR.
 */
#include "gdal/mesh/mesh_read.h"

#include <cpl_conv.h>
#include <cpl_string.h>

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

static int has_ext(const char *path, const char *ext)
{
  const char *base = strrchr(path, '/');
  base = base ? base + 1 : path;
  const char *dot = strrchr(base, '.');
  return dot && strcasecmp(dot + 1, ext) == 0;
}

static int starts(const unsigned char *b, size_t n, const char *word)
{
  size_t m = strlen(word);
  return n >= m && memcmp(b, word, m) == 0;
}

/* Whether the first bytes hold needle (LandXML's root after a prolog and
 * comments). */
static int holds(const unsigned char *b, size_t n, const char *needle)
{
  size_t m = strlen(needle);
  for (size_t i = 0; i + m <= n; i++)
    if (memcmp(b + i, needle, m) == 0)
      return 1;
  return 0;
}

const char *tt_mesh_read_format(const char *path)
{
  unsigned char b[4096];
  size_t n = 0;
  if (!path)
    return NULL;
  VSILFILE *fp = VSIFOpenL(path, "rb");
  if (!fp)
    return NULL;
  n = VSIFReadL(b, 1, sizeof b, fp);
  VSIFCloseL(fp);
  if (starts(b, n, "ply\n") || starts(b, n, "ply\r\n"))
    return "PLY";
  if (starts(b, n, "MESH2D"))
    return "2DM";
  if (holds(b, n, "<LandXML"))
    return "LandXML";
  if ((starts(b, n, "CDF") || starts(b, n, "\x89HDF")) &&
      tt__mesh_is_ugrid(path))
    return "UGRID";
  if (has_ext(path, "stl") || (starts(b, n, "solid") && holds(b, n, "facet")))
    return "STL";
  if (has_ext(path, "obj"))
    return "OBJ";
  return NULL;
}

tt_status tt_mesh_read(tt_context *ctx, const char *path,
                       double **out_xyz, size_t *out_ntriangles,
                       size_t *out_rejected, char **out_crs_wkt)
{
  if (!path || !out_xyz || !out_ntriangles)
    return tt__error(ctx, TT_ERR_ARG, "path, out_xyz and out_ntriangles "
                     "must not be NULL");
  *out_xyz = NULL;
  *out_ntriangles = 0;
  if (out_rejected)
    *out_rejected = 0;
  if (out_crs_wkt)
    *out_crs_wkt = NULL;
  const char *fmt = tt_mesh_read_format(path);
  if (!fmt)
    return tt__error(ctx, TT_ERR_FORMAT, "%s: not an STL, PLY, OBJ, 2DM, "
                     "LandXML or UGRID file", path);
  tt__soup s;
  memset(&s, 0, sizeof s);
  s.ctx = ctx;
  s.path = path;
  tt_status st;
  if (strcmp(fmt, "UGRID") == 0) {
    st = tt__mesh_read_ugrid(&s, path);
  } else {
    VSILFILE *fp = VSIFOpenL(path, "rb");
    if (!fp)
      return tt__error(ctx, TT_ERR_IO, "%s: cannot open: %s", path,
                       strerror(errno));
    if (strcmp(fmt, "STL") == 0)
      st = tt__mesh_read_stl(&s, fp);
    else if (strcmp(fmt, "PLY") == 0)
      st = tt__mesh_read_ply(&s, fp);
    else if (strcmp(fmt, "OBJ") == 0)
      st = tt__mesh_read_obj(&s, fp);
    else if (strcmp(fmt, "2DM") == 0)
      st = tt__mesh_read_2dm(&s, fp);
    else
      st = tt__mesh_read_landxml(&s, fp);
    VSIFCloseL(fp);
  }
  free(s.v);
  if (st != TT_OK) {
    free(s.xyz);
    free(s.crs_wkt);
    return st;
  }
  *out_xyz = s.xyz;
  *out_ntriangles = s.nt;
  if (out_rejected)
    *out_rejected = s.rejected;
  if (out_crs_wkt)
    *out_crs_wkt = s.crs_wkt;
  else
    free(s.crs_wkt);
  return TT_OK;
}

tt_status tt__soup_vertex(tt__soup *s, double x, double y, double z)
{
  return tt__soup_vertex_at(s, s->nv, x, y, z);
}

tt_status tt__soup_vertex_at(tt__soup *s, size_t id, double x, double y,
                             double z)
{
  /* Ids index the vertex array: sparse ones far past the count would
   * cost memory for nothing, and are refused. */
  if (id > 16 * (s->nv + 65536))
    return tt__error(s->ctx, TT_ERR_FORMAT, "%s: vertex id %zu is too "
                     "sparse (%zu vertices before it)", s->path, id + 1,
                     s->nv);
  if (!tt__grow((void **)&s->v, &s->vcap, id + 1, 3 * sizeof(double)))
    return tt__error(s->ctx, TT_ERR_NOMEM, "%s: out of memory after %zu "
                     "vertices", s->path, s->nv);
  for (size_t i = s->nv; i < id; i++)
    s->v[3 * i] = NAN; /* ids the file skips */
  double *p = s->v + 3 * id;
  p[0] = x;
  p[1] = y;
  p[2] = z;
  if (id >= s->nv)
    s->nv = id + 1;
  return TT_OK;
}

tt_status tt__soup_triangle(tt__soup *s, const double c[9])
{
  if (!tt__grow((void **)&s->xyz, &s->tcap, s->nt + 1, 9 * sizeof(double)))
    return tt__error(s->ctx, TT_ERR_NOMEM, "%s: out of memory after %zu "
                     "triangles", s->path, s->nt);
  memcpy(s->xyz + 9 * s->nt, c, 9 * sizeof(double));
  s->nt++;
  return TT_OK;
}

tt_status tt__soup_face(tt__soup *s, const long long *idx, int n,
                        size_t face)
{
  for (int k = 0; k < n; k++)
    if (idx[k] < 0 || (unsigned long long)idx[k] >= s->nv ||
        isnan(s->v[3 * idx[k]]))
      return tt__error(s->ctx, TT_ERR_FORMAT, "%s: face %zu names vertex "
                       "%lld, which the file does not hold (%zu vertices)",
                       s->path, face, idx[k] + 1, s->nv);
  if (n != 3) {
    s->rejected++;
    return TT_OK;
  }
  double c[9];
  for (int k = 0; k < 3; k++)
    memcpy(c + 3 * k, s->v + 3 * idx[k], 3 * sizeof(double));
  return tt__soup_triangle(s, c);
}

void tt__soup_set_crs(tt__soup *s, const char *wkt, size_t len)
{
  free(s->crs_wkt);
  s->crs_wkt = malloc(len + 1);
  if (s->crs_wkt) {
    memcpy(s->crs_wkt, wkt, len);
    s->crs_wkt[len] = '\0';
  }
}

int tt__mesh_words(char *line, char **words, int max)
{
  int n = 0;
  char *p = line;
  while (*p && n < max) {
    while (*p == ' ' || *p == '\t' || *p == '\r' || *p == '\n')
      p++;
    if (!*p)
      break;
    words[n++] = p;
    while (*p && *p != ' ' && *p != '\t' && *p != '\r' && *p != '\n')
      p++;
    if (*p)
      *p++ = '\0';
  }
  return n;
}

int tt__mesh_number(const char *word, double *out)
{
  char *end = NULL;
  errno = 0;
  double v = strtod(word, &end);
  if (end == word || *end)
    return 0;
  *out = v;
  return 1;
}

int tt__mesh_integer(const char *word, long long *out)
{
  char *end = NULL;
  errno = 0;
  long long v = strtoll(word, &end, 10);
  if (end == word || *end || errno == ERANGE)
    return 0;
  *out = v;
  return 1;
}
