/*
 * src/gdal/mesh/ -- the mesh formats: a TIN as SMS 2DM, PLY, OBJ, LandXML
 * or UGRID netCDF, without OGR.
 *
 * mesh_read_stl.c -- STL, binary or ASCII, as a triangle soup: each facet
 * carries its three corners (its normal is ignored). Binary is told from
 * ASCII by the size (84 + 50 bytes per facet, as the header's count says:
 * many binary files open with "solid" too); ASCII facets are the
 * `vertex x y z` lines of each `outer loop`, and a loop of other than 3
 * vertices is counted as rejected. STL holds no CRS and no units: hmm
 * writes the DEM's pixel frame, other tools map coordinates; which one is
 * said by eval's -stl_frame and -tin_transform (tt_tin_to_pixels).
 * Binary corners are float32, so a map coordinate of 6 digits or more
 * comes back rounded (eval snaps corners to within 1e-6 pixel of a
 * sample only).
 */
#include "gdal/mesh/mesh_read.h"

#include <cpl_conv.h>

#include <stdint.h>
#include <string.h>
#include <strings.h>

static float le_float(const unsigned char *b)
{
  uint32_t u = (uint32_t)b[0] | (uint32_t)b[1] << 8 | (uint32_t)b[2] << 16 |
               (uint32_t)b[3] << 24;
  float f;
  memcpy(&f, &u, sizeof f);
  return f;
}

static tt_status read_binary(tt__soup *s, VSILFILE *fp, uint32_t n)
{
  enum { CHUNK = 4096 };
  unsigned char *buf = CPLMalloc((size_t)CHUNK * 50);
  tt_status st = TT_OK;
  if (VSIFSeekL(fp, 84, SEEK_SET) != 0)
    st = tt__error(s->ctx, TT_ERR_IO, "%s: cannot seek", s->path);
  for (uint32_t done = 0; st == TT_OK && done < n;) {
    size_t m = n - done < CHUNK ? n - done : CHUNK;
    if (VSIFReadL(buf, 50, m, fp) != m) {
      st = tt__error(s->ctx, TT_ERR_IO, "%s: truncated after %u of %u "
                     "facets", s->path, done, n);
      break;
    }
    for (size_t i = 0; st == TT_OK && i < m; i++) {
      double c[9];
      for (int k = 0; k < 9; k++)
        c[k] = le_float(buf + 50 * i + 12 + 4 * k);
      st = tt__soup_triangle(s, c);
    }
    done += (uint32_t)m;
  }
  CPLFree(buf);
  return st;
}

static tt_status read_ascii(tt__soup *s, VSILFILE *fp)
{
  const char *line;
  double c[9];
  int in_loop = 0, nc = 0;
  size_t lineno = 0;
  VSIRewindL(fp);
  while ((line = CPLReadLine2L(fp, 1 << 20, NULL)) != NULL) {
    char buf[256], *w[5];
    lineno++;
    snprintf(buf, sizeof buf, "%s", line);
    int n = tt__mesh_words(buf, w, 5);
    if (n == 0)
      continue;
    if (strcasecmp(w[0], "outer") == 0) {
      in_loop = 1;
      nc = 0;
    } else if (strcasecmp(w[0], "vertex") == 0) {
      double p[3];
      if (!in_loop || n != 4 || !tt__mesh_number(w[1], &p[0]) ||
          !tt__mesh_number(w[2], &p[1]) || !tt__mesh_number(w[3], &p[2]))
        return tt__error(s->ctx, TT_ERR_FORMAT, "%s: line %zu: not a "
                         "vertex inside a loop: %s", s->path, lineno, line);
      if (nc < 3)
        memcpy(c + 3 * nc, p, sizeof p);
      nc++;
    } else if (strcasecmp(w[0], "endloop") == 0) {
      tt_status st = TT_OK;
      if (nc == 3)
        st = tt__soup_triangle(s, c);
      else
        s->rejected++;
      if (st != TT_OK)
        return st;
      in_loop = 0;
    }
  }
  if (lineno == 0)
    return tt__error(s->ctx, TT_ERR_FORMAT, "%s: empty STL file", s->path);
  return TT_OK;
}

tt_status tt__mesh_read_stl(tt__soup *s, VSILFILE *fp)
{
  unsigned char head[84];
  size_t got = VSIFReadL(head, 1, sizeof head, fp);
  VSIFSeekL(fp, 0, SEEK_END);
  vsi_l_offset size = VSIFTellL(fp);
  if (got == sizeof head) {
    uint32_t n = (uint32_t)head[80] | (uint32_t)head[81] << 8 |
                 (uint32_t)head[82] << 16 | (uint32_t)head[83] << 24;
    if (size == 84 + 50 * (vsi_l_offset)n)
      return read_binary(s, fp, n);
  }
  if (got >= 5 && strncasecmp((const char *)head, "solid", 5) == 0)
    return read_ascii(s, fp);
  return tt__error(s->ctx, TT_ERR_FORMAT, "%s: neither a binary STL (its "
                   "size is not 84 + 50 bytes per facet) nor an ASCII one "
                   "(it does not start with \"solid\")", s->path);
}
