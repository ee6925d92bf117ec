/*
 * src/gdal/mesh/ -- the mesh formats: a TIN as SMS 2DM, PLY, OBJ, LandXML
 * or UGRID netCDF, without OGR.
 *
 * mesh_read_ply.c -- PLY (ascii, binary_little_endian, binary_big_endian)
 * as a triangle soup: the element "vertex" with properties x, y, z (any
 * scalar type) and the element "face" with the list "vertex_indices" (or
 * "vertex_index"), whatever other properties and elements come with them
 * (terratin's ins_err, max_err ..., colours, normals); they are read and
 * dropped. MDAL's "comment crs:WKT" header line gives the CRS. Faces of
 * other than 3 corners are rejected.
 *
 * The header is parsed into at most 16 elements of at most 64
 * properties; the body is read element by element, value by value,
 * through a 64 KiB buffer (binary) or word by word (ascii).
 */
#include "gdal/mesh/mesh_read.h"

#include <cpl_conv.h>

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

enum { MAX_ELEMENTS = 16, MAX_PROPS = 64, MAX_LIST = 1024 };
enum { ASCII, LITTLE, BIG };

typedef enum ply_type {
  T_BAD, T_I8, T_U8, T_I16, T_U16, T_I32, T_U32, T_F32, T_F64
} ply_type;

typedef struct ply_prop {
  char name[64];
  ply_type type;      /* the value's, or the list entries' */
  ply_type count;     /* a list's count type; T_BAD: a scalar */
} ply_prop;

typedef struct ply_element {
  char name[64];
  unsigned long long count;
  ply_prop prop[MAX_PROPS];
  int nprop;
} ply_element;

/* The body as a stream of values: a binary buffer or ascii words. */
typedef struct ply_in {
  tt__soup *s;
  VSILFILE *fp;
  int format;
  unsigned char buf[65536];
  size_t pos, len;
  char *line;         /* ascii: a copy of the current line */
  char *words[256];
  int nwords, word;
} ply_in;

static ply_type type_named(const char *t)
{
  static const struct { const char *name; ply_type type; } names[] = {
      {"char", T_I8},     {"int8", T_I8},     {"uchar", T_U8},
      {"uint8", T_U8},    {"short", T_I16},   {"int16", T_I16},
      {"ushort", T_U16},  {"uint16", T_U16},  {"int", T_I32},
      {"int32", T_I32},   {"uint", T_U32},    {"uint32", T_U32},
      {"float", T_F32},   {"float32", T_F32}, {"double", T_F64},
      {"float64", T_F64}};
  for (size_t i = 0; i < sizeof names / sizeof names[0]; i++)
    if (strcmp(t, names[i].name) == 0)
      return names[i].type;
  return T_BAD;
}

static size_t type_size(ply_type t)
{
  static const size_t sizes[] = {0, 1, 1, 2, 2, 4, 4, 4, 8};
  return sizes[t];
}

/* One header line into the elements; 1 at end_header. */
static tt_status header_line(tt__soup *s, const char *line, size_t lineno,
                             ply_element *el, int *nel, int *format,
                             int *done)
{
  char buf[512], *w[8];
  snprintf(buf, sizeof buf, "%s", line);
  int n = tt__mesh_words(buf, w, 8);
  if (n == 0)
    return TT_OK;
  if (strcmp(w[0], "comment") == 0) {
    const char *c = strstr(line, "crs:");
    if (c && strncmp(line, "comment crs:", 12) == 0)
      tt__soup_set_crs(s, c + 4, strlen(c + 4));
    return TT_OK;
  }
  if (strcmp(w[0], "end_header") == 0) {
    *done = 1;
    return TT_OK;
  }
  if (strcmp(w[0], "format") == 0 && n >= 2) {
    *format = strcmp(w[1], "ascii") == 0                  ? ASCII
              : strcmp(w[1], "binary_little_endian") == 0 ? LITTLE
              : strcmp(w[1], "binary_big_endian") == 0    ? BIG
                                                          : -1;
    if (*format < 0)
      return tt__error(s->ctx, TT_ERR_FORMAT, "%s: unknown PLY format '%s'",
                       s->path, w[1]);
    return TT_OK;
  }
  if (strcmp(w[0], "element") == 0 && n == 3) {
    if (*nel == MAX_ELEMENTS)
      return tt__error(s->ctx, TT_ERR_FORMAT, "%s: more than %d PLY "
                       "elements", s->path, MAX_ELEMENTS);
    ply_element *e = &el[(*nel)++];
    memset(e, 0, sizeof *e);
    snprintf(e->name, sizeof e->name, "%s", w[1]);
    e->count = strtoull(w[2], NULL, 10);
    return TT_OK;
  }
  if (strcmp(w[0], "property") == 0 && *nel > 0) {
    ply_element *e = &el[*nel - 1];
    int list = n == 5 && strcmp(w[1], "list") == 0;
    if (e->nprop == MAX_PROPS || (!list && n != 3))
      return tt__error(s->ctx, TT_ERR_FORMAT, "%s: line %zu: bad PLY "
                       "property: %s", s->path, lineno, line);
    ply_prop *p = &e->prop[e->nprop++];
    p->count = list ? type_named(w[2]) : T_BAD;
    p->type = type_named(w[list ? 3 : 1]);
    snprintf(p->name, sizeof p->name, "%s", w[list ? 4 : 2]);
    if (p->type == T_BAD || (list && p->count == T_BAD))
      return tt__error(s->ctx, TT_ERR_FORMAT, "%s: line %zu: unknown PLY "
                       "type: %s", s->path, lineno, line);
    return TT_OK;
  }
  return tt__error(s->ctx, TT_ERR_FORMAT, "%s: line %zu: not a PLY header "
                   "line: %s", s->path, lineno, line);
}

static int fill(ply_in *in, size_t need)
{
  if (in->len - in->pos >= need)
    return 1;
  memmove(in->buf, in->buf + in->pos, in->len - in->pos);
  in->len -= in->pos;
  in->pos = 0;
  in->len += VSIFReadL(in->buf + in->len, 1, sizeof in->buf - in->len,
                       in->fp);
  return in->len >= need;
}

static double decode(const unsigned char *b, ply_type t, int swap)
{
  unsigned char v[8];
  size_t n = type_size(t);
  for (size_t i = 0; i < n; i++)
    v[i] = swap ? b[n - 1 - i] : b[i];
  switch (t) {
  case T_I8: return (double)(int8_t)v[0];
  case T_U8: return (double)v[0];
  case T_I16: { int16_t x; memcpy(&x, v, 2); return x; }
  case T_U16: { uint16_t x; memcpy(&x, v, 2); return x; }
  case T_I32: { int32_t x; memcpy(&x, v, 4); return x; }
  case T_U32: { uint32_t x; memcpy(&x, v, 4); return x; }
  case T_F32: { float x; memcpy(&x, v, 4); return x; }
  case T_F64: { double x; memcpy(&x, v, 8); return x; }
  default: return 0.0;
  }
}

static int host_little(void)
{
  const uint16_t one = 1;
  unsigned char b;
  memcpy(&b, &one, 1);
  return b == 1;
}

/* The next value of type t; 0 at the end of the data. */
static int next_value(ply_in *in, ply_type t, double *out)
{
  if (in->format != ASCII) {
    size_t n = type_size(t);
    if (!fill(in, n))
      return 0;
    int swap = (in->format == LITTLE) != host_little();
    *out = decode(in->buf + in->pos, t, swap);
    in->pos += n;
    return 1;
  }
  while (in->word >= in->nwords) {
    const char *l = CPLReadLine2L(in->fp, 1 << 24, NULL);
    if (!l)
      return 0;
    CPLFree(in->line);
    in->line = CPLStrdup(l);
    in->nwords = tt__mesh_words(in->line, in->words, 256);
    in->word = 0;
  }
  return tt__mesh_number(in->words[in->word++], out);
}

static tt_status read_element(ply_in *in, const ply_element *e)
{
  tt__soup *s = in->s;
  int is_vertex = strcmp(e->name, "vertex") == 0;
  int is_face = strcmp(e->name, "face") == 0;
  int ix = -1, iy = -1, iz = -1, ifc = -1;
  for (int k = 0; k < e->nprop; k++) {
    const char *nm = e->prop[k].name;
    int list = e->prop[k].count != T_BAD;
    if (is_vertex && !list && strcmp(nm, "x") == 0) ix = k;
    if (is_vertex && !list && strcmp(nm, "y") == 0) iy = k;
    if (is_vertex && !list && strcmp(nm, "z") == 0) iz = k;
    if (is_face && list && (strcmp(nm, "vertex_indices") == 0 ||
                            strcmp(nm, "vertex_index") == 0)) ifc = k;
  }
  if (is_vertex && (ix < 0 || iy < 0 || iz < 0))
    return tt__error(s->ctx, TT_ERR_FORMAT, "%s: the PLY vertex element "
                     "has no x, y and z", s->path);
  if (is_face && ifc < 0)
    return tt__error(s->ctx, TT_ERR_FORMAT, "%s: the PLY face element has "
                     "no vertex_indices list", s->path);
  for (unsigned long long i = 0; i < e->count; i++) {
    double xyz[3] = {0, 0, 0};
    long long idx[MAX_LIST];
    int nidx = 0;
    for (int k = 0; k < e->nprop; k++) {
      const ply_prop *p = &e->prop[k];
      double v, cnt = 1;
      if (p->count != T_BAD && !next_value(in, p->count, &cnt))
        goto truncated;
      if (cnt < 0 || cnt > MAX_LIST)
        return tt__error(s->ctx, TT_ERR_FORMAT, "%s: %s %llu: a list of "
                         "%g entries", s->path, e->name, i, cnt);
      for (int j = 0; j < (int)cnt; j++) {
        if (!next_value(in, p->type, &v))
          goto truncated;
        if (k == ix) xyz[0] = v;
        if (k == iy) xyz[1] = v;
        if (k == iz) xyz[2] = v;
        if (k == ifc) idx[nidx++] = (long long)v;
      }
    }
    tt_status st = TT_OK;
    if (is_vertex)
      st = tt__soup_vertex(s, xyz[0], xyz[1], xyz[2]);
    else if (is_face)
      st = tt__soup_face(s, idx, nidx, (size_t)i + 1);
    if (st != TT_OK)
      return st;
  }
  return TT_OK;
truncated:
  return tt__error(s->ctx, TT_ERR_FORMAT, "%s: the PLY data ends inside "
                   "element %s", s->path, e->name);
}

tt_status tt__mesh_read_ply(tt__soup *s, VSILFILE *fp)
{
  ply_element *el = calloc(MAX_ELEMENTS, sizeof *el);
  ply_in *in = calloc(1, sizeof *in);
  int nel = 0, format = -1, done = 0;
  size_t lineno = 0;
  tt_status st = TT_OK;
  const char *line;
  if (!el || !in) {
    st = tt__error(s->ctx, TT_ERR_NOMEM, "%s: out of memory", s->path);
    goto out;
  }
  while (st == TT_OK && !done &&
         (line = CPLReadLine2L(fp, 1 << 20, NULL)) != NULL) {
    if (++lineno == 1)
      continue; /* "ply" */
    st = header_line(s, line, lineno, el, &nel, &format, &done);
  }
  if (st == TT_OK && (!done || format < 0))
    st = tt__error(s->ctx, TT_ERR_FORMAT, "%s: the PLY header has no %s",
                   s->path, done ? "format line" : "end_header");
  in->s = s;
  in->fp = fp;
  in->format = format;
  for (int i = 0; st == TT_OK && i < nel; i++)
    st = read_element(in, &el[i]);
out:
  if (in)
    CPLFree(in->line);
  free(in);
  free(el);
  return st;
}
