/*
 * src/gdal/mesh/ -- the mesh formats: a TIN as SMS 2DM, PLY, OBJ, LandXML
 * or UGRID netCDF, without OGR.
 *
 * mesh_read_2dm.c -- SMS 2DM as a triangle soup: `ND id x y z` nodes and
 * `E3T id n1 n2 n3 [material]` elements; the node ids are what elements
 * name, in any order and with gaps; SMS writes the elements before the
 * nodes, so elements are kept as ids and resolved at the end. Other elements (E4Q quads, E6T, E8Q,
 * E9Q, E2L and E3L lines) are counted as rejected; NS, BC and the other
 * cards are skipped. No CRS: 2DM has none (MDAL's .prj beside it is not
 * read).
 */
#include "gdal/mesh/mesh_read.h"

#include <cpl_conv.h>

#include <stdlib.h>
#include <string.h>

/* The E3T elements as read: id and node ids, resolved once all nodes are
 * in. */
typedef struct elements {
  long long *e; /* 4 per element */
  size_t n, cap;
} elements;

static tt_status resolve(tt__soup *s, const elements *el)
{
  tt_status st = TT_OK;
  for (size_t i = 0; st == TT_OK && i < el->n; i++) {
    long long idx[3];
    for (int k = 0; k < 3; k++)
      idx[k] = el->e[4 * i + 1 + k] - 1;
    st = tt__soup_face(s, idx, 3, (size_t)el->e[4 * i]);
  }
  return st;
}

tt_status tt__mesh_read_2dm(tt__soup *s, VSILFILE *fp)
{
  const char *line;
  size_t lineno = 0;
  elements el = {NULL, 0, 0};
  tt_status st = TT_OK;
  while (st == TT_OK && (line = CPLReadLine2L(fp, 1 << 20, NULL)) != NULL) {
    char buf[512], *w[8];
    lineno++;
    snprintf(buf, sizeof buf, "%s", line);
    int n = tt__mesh_words(buf, w, 8);
    if (n == 0)
      continue;
    if (strcmp(w[0], "ND") == 0) {
      long long id;
      double p[3];
      if (n < 5 || !tt__mesh_integer(w[1], &id) || id < 1 ||
          !tt__mesh_number(w[2], &p[0]) || !tt__mesh_number(w[3], &p[1]) ||
          !tt__mesh_number(w[4], &p[2]))
        st = tt__error(s->ctx, TT_ERR_FORMAT, "%s: line %zu: a node is "
                       "ND id x y z: %s", s->path, lineno, line);
      else
        st = tt__soup_vertex_at(s, (size_t)(id - 1), p[0], p[1], p[2]);
    } else if (strcmp(w[0], "E3T") == 0) {
      long long id, idx[3];
      if (n < 5 || !tt__mesh_integer(w[1], &id) ||
          !tt__mesh_integer(w[2], &idx[0]) ||
          !tt__mesh_integer(w[3], &idx[1]) ||
          !tt__mesh_integer(w[4], &idx[2])) {
        st = tt__error(s->ctx, TT_ERR_FORMAT, "%s: line %zu: a triangle "
                       "is E3T id n1 n2 n3: %s", s->path, lineno, line);
      } else if (!tt__grow((void **)&el.e, &el.cap, el.n + 1,
                           4 * sizeof(long long))) {
        st = tt__error(s->ctx, TT_ERR_NOMEM, "%s: out of memory after %zu "
                       "elements", s->path, el.n);
      } else {
        long long *o = el.e + 4 * el.n++;
        o[0] = id;
        memcpy(o + 1, idx, sizeof idx);
      }
    } else if (w[0][0] == 'E' &&
               (strcmp(w[0], "E4Q") == 0 || strcmp(w[0], "E6T") == 0 ||
                strcmp(w[0], "E8Q") == 0 || strcmp(w[0], "E9Q") == 0 ||
                strcmp(w[0], "E2L") == 0 || strcmp(w[0], "E3L") == 0)) {
      s->rejected++;
    }
  }
  if (st == TT_OK)
    st = resolve(s, &el);
  free(el.e);
  return st;
}
