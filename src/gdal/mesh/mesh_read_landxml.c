/*
 * src/gdal/mesh/ -- the mesh formats: a TIN as SMS 2DM, PLY, OBJ, LandXML
 * or UGRID netCDF, without OGR.
 *
 * mesh_read_landxml.c -- the first <Surface> of a LandXML file as a
 * triangle soup: <Definition><Pnts><P id="n">northing easting
 * elevation</P>... and <Faces><F>a b c</F>..., F naming P ids. The
 * standard's point order is northing (y) first; x, y come back in map
 * order. A face flagged invisible (i="1") lies outside the surface (civil
 * tools use it for holes and the hull's concavities) and is counted as
 * rejected, as are faces of other than 3 corners. The CRS is the
 * <CoordinateSystem>'s ogcWktCode, else its epsgCode.
 *
 * The file is read whole into memory and scanned by hand (no XML library:
 * the glue links none); the scan knows the elements above and their
 * attributes, skipping anything else, comments and CDATA included only
 * where they do not hold "<P" or "<F" markup. Workload: the file's size in
 * memory, one pass.
 */
#include "gdal/mesh/mesh_read.h"

#include <cpl_conv.h>
#include <cpl_string.h>

#include <stdlib.h>
#include <string.h>

/* The value of attribute name inside the tag [tag, end), unescaped;
 * CPLMalloc'd, NULL when absent. */
static char *attribute(const char *tag, const char *end, const char *name)
{
  size_t n = strlen(name);
  for (const char *p = tag; p + n + 2 < end; p++) {
    if ((p[-1] != ' ' && p[-1] != '\t' && p[-1] != '\n' && p[-1] != '\r') ||
        strncmp(p, name, n) != 0 || p[n] != '=' ||
        (p[n + 1] != '"' && p[n + 1] != '\''))
      continue;
    const char q = p[n + 1];
    const char *v = p + n + 2, *e = v;
    while (e < end && *e != q)
      e++;
    char *raw = CPLMalloc((size_t)(e - v) + 1);
    memcpy(raw, v, (size_t)(e - v));
    raw[e - v] = '\0';
    char *un = CPLUnescapeString(raw, NULL, CPLES_XML);
    CPLFree(raw);
    return un;
  }
  return NULL;
}

/* The next element <name ...>text</name> from *p, before limit: its tag
 * [*out_tag, *out_tag_end) and text [*out_text, *out_text_end); 0 when
 * there is none. */
static int next_element(const char **p, const char *limit, const char *name,
                        const char **out_tag, const char **out_tag_end,
                        const char **out_text, const char **out_text_end)
{
  size_t n = strlen(name);
  const char *q = *p;
  while ((q = strstr(q, "<")) != NULL && q < limit) {
    if (strncmp(q + 1, name, n) == 0 &&
        (q[n + 1] == ' ' || q[n + 1] == '>' || q[n + 1] == '\t' ||
         q[n + 1] == '\n' || q[n + 1] == '\r' || q[n + 1] == '/'))
      break;
    q++;
  }
  if (!q || q >= limit)
    return 0;
  const char *te = strchr(q, '>');
  if (!te || te >= limit)
    return 0;
  *out_tag = q + 1 + n;
  *out_tag_end = te;
  if (te[-1] == '/') { /* <F .../>: empty */
    *out_text = *out_text_end = te;
    *p = te + 1;
    return 1;
  }
  const char *close = strstr(te, "</");
  if (!close || close >= limit)
    return 0;
  *out_text = te + 1;
  *out_text_end = close;
  *p = close + 2;
  return 1;
}

/* Up to max numbers of the text [t, e); their count. */
static int numbers(const char *t, const char *e, double *v, int max)
{
  char buf[256], *w[8];
  size_t len = (size_t)(e - t) < sizeof buf - 1 ? (size_t)(e - t)
                                                 : sizeof buf - 1;
  memcpy(buf, t, len);
  buf[len] = '\0';
  int n = tt__mesh_words(buf, w, max < 8 ? max + 1 : 8);
  for (int k = 0; k < n; k++)
    if (k >= max || !tt__mesh_number(w[k], &v[k]))
      return -1;
  return n;
}

static void read_crs(tt__soup *s, const char *doc, const char *limit)
{
  const char *p = doc, *tag, *tag_end, *t, *te;
  if (!next_element(&p, limit, "CoordinateSystem", &tag, &tag_end, &t, &te))
    return;
  char *wkt = attribute(tag, tag_end, "ogcWktCode");
  char *epsg = attribute(tag, tag_end, "epsgCode");
  if (wkt && *wkt) {
    tt__soup_set_crs(s, wkt, strlen(wkt));
  } else if (epsg && *epsg) {
    char buf[64];
    snprintf(buf, sizeof buf, "EPSG:%s", epsg);
    tt__soup_set_crs(s, buf, strlen(buf));
  }
  CPLFree(wkt);
  CPLFree(epsg);
}

static tt_status read_points(tt__soup *s, const char *p, const char *limit)
{
  const char *tag, *tag_end, *t, *te;
  size_t count = 0;
  while (next_element(&p, limit, "P", &tag, &tag_end, &t, &te)) {
    double v[3];
    char *id = attribute(tag, tag_end, "id");
    long long idv = 0;
    int ok = id && tt__mesh_integer(id, &idv) && idv >= 1 &&
             numbers(t, te, v, 3) == 3;
    CPLFree(id);
    count++;
    if (!ok)
      return tt__error(s->ctx, TT_ERR_FORMAT, "%s: point %zu is not <P "
                       "id=\"n\">northing easting elevation</P>", s->path,
                       count);
    tt_status st = tt__soup_vertex_at(s, (size_t)(idv - 1), v[1], v[0],
                                      v[2]);
    if (st != TT_OK)
      return st;
  }
  return TT_OK;
}

static tt_status read_faces(tt__soup *s, const char *p, const char *limit)
{
  const char *tag, *tag_end, *t, *te;
  size_t count = 0;
  while (next_element(&p, limit, "F", &tag, &tag_end, &t, &te)) {
    double v[4];
    long long idx[4];
    count++;
    char *inv = attribute(tag, tag_end, "i");
    int invisible = inv && strcmp(inv, "1") == 0;
    CPLFree(inv);
    int n = numbers(t, te, v, 4);
    if (n < 0)
      return tt__error(s->ctx, TT_ERR_FORMAT, "%s: face %zu is not <F>a b "
                       "c</F>", s->path, count);
    if (invisible) {
      s->rejected++;
      continue;
    }
    for (int k = 0; k < n; k++)
      idx[k] = (long long)v[k] - 1;
    tt_status st = tt__soup_face(s, idx, n, count);
    if (st != TT_OK)
      return st;
  }
  return TT_OK;
}

tt_status tt__mesh_read_landxml(tt__soup *s, VSILFILE *fp)
{
  (void)fp; /* VSIIngestFile reads by name */
  GByte *data = NULL;
  vsi_l_offset size = 0;
  if (!VSIIngestFile(NULL, s->path, &data, &size, -1))
    return tt__error(s->ctx, TT_ERR_IO, "%s: cannot read the file",
                     s->path);
  const char *doc = (const char *)data, *limit = doc + size;
  const char *p = doc, *tag, *tag_end, *t, *te;
  tt_status st = TT_OK;
  read_crs(s, doc, limit);
  /* The first Surface (not Surfaces), then its Pnts and Faces. */
  const char *surf = NULL;
  while (next_element(&p, limit, "Surface", &tag, &tag_end, &t, &te)) {
    surf = tag_end;
    break;
  }
  const char *send = surf ? strstr(surf, "</Surface>") : NULL;
  if (!surf || !send) {
    st = tt__error(s->ctx, TT_ERR_FORMAT, "%s: a LandXML file without a "
                   "<Surface>", s->path);
  } else {
    const char *pnts = strstr(surf, "<Pnts"), *faces = strstr(surf, "<Faces");
    if (!pnts || pnts > send || !faces || faces > send)
      st = tt__error(s->ctx, TT_ERR_FORMAT, "%s: its first <Surface> has "
                     "no <Pnts> and <Faces>", s->path);
    else if ((st = read_points(s, pnts + 5, faces)) == TT_OK)
      st = read_faces(s, faces + 6, send);
  }
  VSIFree(data);
  return st;
}
