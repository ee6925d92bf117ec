/*
 * src/gdal/mesh/ -- the mesh formats: a TIN as SMS 2DM, PLY, OBJ, LandXML
 * or UGRID netCDF, without OGR.
 *
 * mesh_read_obj.c -- Wavefront OBJ as a triangle soup: `v x y z [w]`
 * vertices and `f a b c` faces, whose corners may be written a/t/n (the
 * vertex index is the first number) and negative (relative to the last
 * vertex, as the format allows); texture, normal, group and material
 * lines are skipped. terratin's -obj_local writes vertices relative to an
 * origin given by a `# origin X Y` comment before them, added back here.
 * Faces of other than 3 corners are rejected. No CRS: OBJ has none.
 */
#include "gdal/mesh/mesh_read.h"

#include <cpl_conv.h>

#include <stdlib.h>
#include <string.h>

enum { MAX_WORDS = 64 };

/* The vertex index of a face corner "a", "a/t", "a//n" or "a/t/n",
 * 0-based; negative ones count back from the last vertex. */
static int corner(const tt__soup *s, char *word, long long *out)
{
  char *slash = strchr(word, '/');
  if (slash)
    *slash = '\0';
  long long v;
  if (!tt__mesh_integer(word, &v) || v == 0)
    return 0;
  *out = v > 0 ? v - 1 : (long long)s->nv + v;
  return 1;
}

tt_status tt__mesh_read_obj(tt__soup *s, VSILFILE *fp)
{
  const char *line;
  double origin[2] = {0.0, 0.0};
  size_t lineno = 0, faces = 0;
  char *buf = NULL;
  size_t bufcap = 0;
  tt_status st = TT_OK;
  while (st == TT_OK && (line = CPLReadLine2L(fp, 1 << 20, NULL)) != NULL) {
    char *w[MAX_WORDS];
    size_t len = strlen(line);
    lineno++;
    if (!tt__grow((void **)&buf, &bufcap, len + 1, 1)) {
      st = tt__error(s->ctx, TT_ERR_NOMEM, "%s: out of memory", s->path);
      break;
    }
    memcpy(buf, line, len + 1);
    int n = tt__mesh_words(buf, w, MAX_WORDS);
    if (n == 0)
      continue;
    if (n == 4 && s->nv == 0 && strcmp(w[0], "#") == 0 &&
        strcmp(w[1], "origin") == 0) {
      if (!tt__mesh_number(w[2], &origin[0]) ||
          !tt__mesh_number(w[3], &origin[1]))
        st = tt__error(s->ctx, TT_ERR_FORMAT, "%s: line %zu: bad origin: "
                       "%s", s->path, lineno, line);
    } else if (strcmp(w[0], "v") == 0) {
      double p[3];
      if (n < 4 || !tt__mesh_number(w[1], &p[0]) ||
          !tt__mesh_number(w[2], &p[1]) || !tt__mesh_number(w[3], &p[2]))
        st = tt__error(s->ctx, TT_ERR_FORMAT, "%s: line %zu: a vertex "
                       "needs x y z: %s", s->path, lineno, line);
      else
        st = tt__soup_vertex(s, p[0] + origin[0], p[1] + origin[1], p[2]);
    } else if (strcmp(w[0], "f") == 0) {
      long long idx[MAX_WORDS];
      faces++;
      for (int k = 1; st == TT_OK && k < n; k++)
        if (!corner(s, w[k], &idx[k - 1]))
          st = tt__error(s->ctx, TT_ERR_FORMAT, "%s: line %zu: bad face "
                         "corner '%s'", s->path, lineno, w[k]);
      if (st == TT_OK)
        st = tt__soup_face(s, idx, n - 1, faces);
    }
  }
  free(buf);
  return st;
}
