/*
 * piece.c -- one tile's TIN piece as bytes and back, for cluster runs
 * (`terratin tiles run` writes a piece to its own file, `tiles merge` reads
 * them all): every array of the piece as it is in memory, so the merge of
 * pieces read back is the merge of the pieces computed, bit for bit.
 *
 * Layout: the magic "TTPIECE1", a byte-order mark (the pieces are for
 * machines of one byte order, as a cluster's are), the caller's tag (the
 * plan's hash and the tile's id: a piece of another plan is refused), the
 * counts, a bit per array present, the summary, the georeference, the
 * arrays, and an FNV-1a 64 checksum of everything before it. A piece of a
 * geographic or Web Mercator DEM has its vertices' ground points, scale
 * factors and convergences among the arrays; its area function is code,
 * not data: the merge takes it from a window of the DEM
 * (tt_tin_merger_set_ground).
 *
 * Part of src/tile/, tiled runs: the tiles, their shared borders, one tile's
 * run, the merge.
 */
#include "tile/tile.h"
#include "tin/tin.h"

#include <stdlib.h>
#include <string.h>

#define PIECE_MAGIC "TTPIECE1"
#define PIECE_BOM UINT32_C(0x01020304)

typedef struct field {
  void **p;   /* the array's pointer in the tin */
  size_t per; /* elements per vertex or triangle */
  size_t size;
  int tri;    /* 1: per triangle, 0: per vertex */
} field;

static size_t fields_of(tt_tin *t, field *f)
{
  size_t n = 0;
#define F(ptr, per_, tri_)                                                 \
  f[n].p = (void **)&t->ptr;                                               \
  f[n].per = per_;                                                         \
  f[n].size = sizeof *t->ptr;                                              \
  f[n].tri = tri_;                                                         \
  n++;
  F(vc, 1, 0) F(vr, 1, 0) F(vz, 1, 0) F(vzd, 1, 0) F(v_ins_err, 1, 0)
  F(v_star_max, 1, 0) F(v_star_rmse, 1, 0) F(v_star_n, 1, 0)
  F(v_importance, 1, 0) F(v_home, 1, 0) F(tv, 3, 1) F(t_max, 1, 1)
  F(t_rmse, 1, 1) F(t_n, 1, 1) F(vgxy, 2, 0) F(vgk, 1, 0) F(vgconv, 1, 0)
#undef F
  return n;
}

static uint64_t fnv1a(const unsigned char *p, size_t n)
{
  uint64_t h = UINT64_C(14695981039346656037);
  for (size_t i = 0; i < n; i++) {
    h ^= p[i];
    h *= UINT64_C(1099511628211);
  }
  return h;
}

typedef struct head {
  char magic[8];
  uint32_t bom, mask;
  uint64_t tag, nv, nt;
  tt_tin_summary summary;
  double gt[6], frame[4], area_par[4];
} head;

tt_status tt_tin_piece_encode(tt_context *ctx, const tt_tin *piece,
                              uint64_t tag, void **out, size_t *out_len)
{
  *out = NULL;
  *out_len = 0;
  if (!piece)
    return tt__error(ctx, TT_ERR_ARG, "piece must not be NULL");
  field f[20];
  tt_tin *t = (tt_tin *)piece; /* read only */
  size_t nf = fields_of(t, f), len = sizeof(head) + 8;
  head h;
  memset(&h, 0, sizeof h);
  memcpy(h.magic, PIECE_MAGIC, 8);
  h.bom = PIECE_BOM;
  h.tag = tag;
  h.nv = piece->nv;
  h.nt = piece->nt;
  h.summary = piece->summary;
  memcpy(h.gt, piece->gt, sizeof h.gt);
  memcpy(h.frame, piece->frame, sizeof h.frame);
  memcpy(h.area_par, piece->area_par, sizeof h.area_par);
  for (size_t i = 0; i < nf; i++)
    if (*f[i].p) {
      h.mask |= 1u << i;
      len += (f[i].tri ? piece->nt : piece->nv) * f[i].per * f[i].size;
    }
  unsigned char *b = malloc(len);
  if (!b)
    return tt__error(ctx, TT_ERR_NOMEM, "out of memory");
  memcpy(b, &h, sizeof h);
  size_t at = sizeof h;
  for (size_t i = 0; i < nf; i++)
    if (*f[i].p) {
      size_t n = (f[i].tri ? piece->nt : piece->nv) * f[i].per * f[i].size;
      if (n)
        memcpy(b + at, *f[i].p, n);
      at += n;
    }
  uint64_t sum = fnv1a(b, at);
  memcpy(b + at, &sum, 8);
  *out = b;
  *out_len = len;
  return TT_OK;
}

tt_status tt_tin_piece_decode(tt_context *ctx, const void *bytes, size_t len,
                              uint64_t tag, tt_tin **out_piece)
{
  const unsigned char *b = bytes;
  *out_piece = NULL;
  head h;
  if (len < sizeof h + 8 || memcmp(b, PIECE_MAGIC, 8) != 0)
    return tt__error(ctx, TT_ERR_DATA, "not a terratin tile piece");
  memcpy(&h, b, sizeof h);
  if (h.bom != PIECE_BOM)
    return tt__error(ctx, TT_ERR_DATA, "a tile piece of a machine of "
                         "another byte order");
  uint64_t sum;
  memcpy(&sum, b + len - 8, 8);
  if (fnv1a(b, len - 8) != sum)
    return tt__error(ctx, TT_ERR_DATA, "tile piece checksum mismatch "
                         "(truncated or damaged file)");
  if (h.tag != tag)
    return tt__error(ctx, TT_ERR_DATA, "stale tile piece: made for "
                         "another plan or tile");
  tt_tin *t = calloc(1, sizeof *t);
  if (!t)
    return tt__error(ctx, TT_ERR_NOMEM, "out of memory");
  t->nv = (size_t)h.nv;
  t->nt = (size_t)h.nt;
  t->summary = h.summary;
  memcpy(t->gt, h.gt, sizeof h.gt);
  memcpy(t->frame, h.frame, sizeof h.frame);
  memcpy(t->area_par, h.area_par, sizeof h.area_par);
  field f[20];
  size_t nf = fields_of(t, f), at = sizeof h;
  for (size_t i = 0; i < nf; i++) {
    if (!(h.mask & (1u << i)))
      continue;
    size_t cnt = f[i].tri ? t->nt : t->nv;
    if (cnt > (len - at) / (f[i].per * f[i].size)) {
      tt_tin_destroy(t);
      return tt__error(ctx, TT_ERR_DATA, "tile piece too short");
    }
    size_t n = cnt * f[i].per * f[i].size;
    *f[i].p = malloc(n ? n : 1);
    if (!*f[i].p) {
      tt_tin_destroy(t);
      return tt__error(ctx, TT_ERR_NOMEM, "out of memory");
    }
    memcpy(*f[i].p, b + at, n);
    at += n;
  }
  if (at + 8 != len) {
    tt_tin_destroy(t);
    return tt__error(ctx, TT_ERR_DATA, "tile piece of the wrong size");
  }
  *out_piece = t;
  return TT_OK;
}
