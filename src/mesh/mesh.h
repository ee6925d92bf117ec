/*
 * mesh.h -- the triangle mesh: flat arrays of half-edges.
 *
 * Triangle t owns half-edges 3t, 3t+1, 3t+2. Half-edge e starts at vertex
 * hv[e] and ends at hv[tt__next(e)]; twin[e] is the opposite half-edge in
 * the neighbouring triangle, or -1 on the boundary. Every live triangle is
 * counter-clockwise in the ground frame (see predicates.h for the sign
 * convention and mesh->metric.det_sign for how pixel space maps to it).
 * A free triangle slot has hv[3t] == -1 and sits on the free list, so flips,
 * splits and (later) vertex removals make no garbage.
 *
 * Vertices are grid samples: integer pixel coordinates (col, row). v[i].edge
 * is one half-edge leaving vertex i (hv[v[i].edge] == i), or -1 for a
 * vertex in no triangle. eflag[e] holds TT__EDGE_CONSTRAINED for edges that flips must
 * keep (domain boundaries; both half-edges carry it).
 *
 * Only mesh.c writes these arrays. Each operation appends the slots of the
 * triangles it wrote to the touched log, which the caller drains (to rescan
 * candidates); a logged slot may have been freed since, or logged twice.
 *
 * Limits: at most TT_MAX_VERTICES vertices and INT32_MAX/3 triangle slots.
 *
 * Part of src/mesh/, the mesh stage: the half-edge mesh, the samples a
 * triangle owns, the nodata domain.
 */
#ifndef TT_MESH_H
#define TT_MESH_H

#include "base/internal.h"

#define TT__EDGE_CONSTRAINED 1u
/* Tile runs (src/tile/): a boundary edge on a side shared with another
 * tile. Its samples are within the bound by the border's simplification,
 * so refinement never takes one as a candidate (no vertex the neighbour
 * does not have); BORDER_SHARED when the neighbour's TIN has the same edge,
 * whose samples then belong to one of the two by the top-left rule
 * (raster_scan.h), as if the edge were an inner one. */
#define TT__EDGE_BORDER 2u
#define TT__EDGE_BORDER_SHARED 4u
/* A constrained edge on one of the caller's breaklines (breaklines.c),
 * kept by splits and region replacements with TT__EDGE_CONSTRAINED, so
 * that the TIN can say which of its edges follow a line. */
#define TT__EDGE_BREAKLINE 8u

/* A vertex: one 16-byte record, so a triangle's corners cost three cache
 * lines, not twelve. Its height is read through tt__mesh_z(): the record's
 * float, or for a mesh of a grid of doubles (tt__mesh_keep_f64) the exact
 * double kept beside it. */
typedef struct tt__mesh_vertex {
  int32_t c, r;          /* pixel column, row */
  float z;               /* height (kept here so scans need not fetch it
                            from the grid at a random place); only rounded
                            when the mesh keeps doubles */
  int32_t edge;          /* a half-edge leaving the vertex, or -1 */
} tt__mesh_vertex;

typedef struct tt__mesh {
  /* vertices */
  tt__mesh_vertex *v;
  size_t nv, vcap;
  double *vz;            /* exact heights (tt__mesh_keep_f64), else NULL */
  size_t vzcap;
  /* triangles (3 half-edges each) */
  int32_t *hv;           /* start vertex; hv[3t] == -1: free slot */
  int32_t *twin;         /* opposite half-edge or -1 */
  uint8_t *eflag;
  size_t nslots;         /* triangle slots in use or free */
  size_t tcap;           /* triangle slots allocated */
  size_t nlive;          /* live triangles */
  int32_t *freelist;
  size_t nfree, freecap;
  /* the ground frame */
  tt__metric metric;
  /* the grid's ground points (tt__mesh_use_ground_points), or NULL: the
   * conformal x, y of the sample at (c, r) are gxy[2 (r gnx + c)] and the
   * next double */
  const double *gxy;
  size_t gnx;
  /* slots written since the caller last drained the log */
  int32_t *touched;
  size_t ntouched, touchedcap;
  /* star versions (tt__mesh_track_stars), NULL when not tracked: vver[v]
   * changes whenever the triangles around v change, so a value computed
   * from v's star stays true while vver[v] (and serial) are what they were
   * then */
  uint32_t *vver;
  size_t vvercap;
  uint64_t serial;       /* unique per tt__mesh_init in the process */
} tt__mesh;

static inline int32_t tt__next(int32_t e) { return e % 3 == 2 ? e - 2 : e + 1; }
static inline int32_t tt__prev(int32_t e) { return e % 3 == 0 ? e + 2 : e - 1; }
static inline bool tt__mesh_live(const tt__mesh *m, int32_t t)
{
  return m->hv[3 * (size_t)t] >= 0;
}
/* The height of vertex v, exact: the only way to read it. */
static inline double tt__mesh_z(const tt__mesh *m, int32_t v)
{
  return m->vz ? m->vz[v] : (double)m->v[v].z;
}

TT_HIDDEN void tt__mesh_init(tt__mesh *m, const tt__metric *metric);
/* Starts tracking star versions (vver above, all 0 from here on); call it
 * before making a cache that relies on them. False when out of memory
 * (nothing tracked). Every operation below then adds at least one to the
 * version of each vertex whose star (the triangles around it, their order,
 * their twins) it may change: the corners of every triangle it writes or
 * frees, and the ends of every edge it links. tt__mesh_flip adds exactly
 * one to each of its quad's four vertices (a criterion's cache may rely on
 * it, criterion.h). A version wraps after 2^32 changes of one star. */
TT_HIDDEN bool tt__mesh_track_stars(tt__mesh *m);
/* Keeps every vertex height as a double (vz above, 8 bytes per vertex), for
 * the mesh of a grid of doubles; call it before adding vertices. False
 * when out of memory (the mesh keeps floats only). */
TT_HIDDEN bool tt__mesh_keep_f64(tt__mesh *m);
TT_HIDDEN void tt__mesh_free(tt__mesh *m);
/* Reserves room for about nv vertices and nt triangles (a hint). */
TT_HIDDEN bool tt__mesh_reserve(tt__mesh *m, size_t nv, size_t nt);

/* Adds an unconnected vertex; returns its index, or -1 when out of memory
 * or past TT_MAX_VERTICES. z is kept exactly when the mesh keeps doubles,
 * else as a float (it must be one: a sample of a grid of floats). */
TT_HIDDEN int32_t tt__mesh_add_vertex(tt__mesh *m, int32_t col, int32_t row,
                                      double z);

/* Adds triangle (a, b, c), which must be counter-clockwise in the ground
 * frame, with no twins; returns its slot or -1 when out of memory. */
TT_HIDDEN int32_t tt__mesh_add_triangle(tt__mesh *m, int32_t a, int32_t b,
                                        int32_t c);
/* Links every boundary half-edge with its reverse, if present, among the
 * live triangles (used once after building a starting triangulation). */
TT_HIDDEN bool tt__mesh_link_all(tt__mesh *m);

/* Measures the Delaunay test on a grid's ground points (its gxy, an nx-wide
 * grid) instead of the affine metric; NULL keeps the metric. Call it before
 * the first triangle. */
TT_HIDDEN void tt__mesh_use_ground_points(tt__mesh *m, const double *gxy,
                                          size_t nx);

/* Ground-frame orientation of three vertices / incircle of four (d inside
 * the circle through a, b, c given counter-clockwise: > 0). Exact.
 * Orientation is always the pixel-space one (the mesh's topology); with
 * ground points the incircle is the adaptive exact test on them, signed by
 * their own orientation of a, b, c (a triangle can only turn the other way
 * there when it is a sliver long enough for the projection to bend it; its
 * pixel-space metric test decides then if that orientation is zero). */
TT_HIDDEN int tt__mesh_orient(const tt__mesh *m, int32_t a, int32_t b,
                              int32_t c);
TT_HIDDEN int tt__mesh_incircle(const tt__mesh *m, int32_t a, int32_t b,
                                int32_t c, int32_t d);

/* Inserts vertex p strictly inside live triangle t: t becomes three
 * triangles around p. out_opposite receives the three half-edges opposite
 * p (for the criterion's repair). False when out of memory (mesh unchanged). */
TT_HIDDEN bool tt__mesh_split_triangle(tt__mesh *m, int32_t t, int32_t p,
                                       int32_t out_opposite[3]);
/* Inserts vertex p strictly inside the edge of half-edge e: its two
 * triangles (one on the boundary) become four (two). out_opposite receives
 * the half-edges opposite p (4, or 2 on the boundary; unused slots -1).
 * A constrained edge stays constrained in both halves. False when out of
 * memory (mesh unchanged). */
TT_HIDDEN bool tt__mesh_split_edge(tt__mesh *m, int32_t e, int32_t p,
                                   int32_t out_opposite[4]);

/* True when the edge of e has two triangles, is not constrained, and its
 * quadrilateral is strictly convex. */
TT_HIDDEN bool tt__mesh_flippable(const tt__mesh *m, int32_t e);
/* Flips the edge of e (which must be flippable). With e = a->b in
 * (a, b, c) and its twin b->a in (b, a, d), the two triangles become
 * (c, a, d) in e's slot and (d, b, c) in the twin's; the returned half-edge
 * is the new diagonal d->c, in e's slot:
 *
 *          c                       c
 *         / \                     /|\
 *        /   \                   / | \
 *       a-----b        ==>      a  |  b
 *        \   /                   \ | /
 *         \ /                     \|/
 *          d                       d
 *
 * Afterwards tt__prev(h) is a->d and tt__next(twin[h]) is d->b: the two
 * edges opposite c, for the next round of a repair that started at c.
 * Returns -1 (mesh unchanged) when out of memory. */
TT_HIDDEN int32_t tt__mesh_flip(tt__mesh *m, int32_t e);

/* Undoable flips (optimize.c's look-ahead): tt__mesh_flip_undoable flips
 * the flippable edge of e like tt__mesh_flip and saves what it overwrote;
 * tt__mesh_flip_revert restores the two slots word for word (half-edge
 * indices included), the vertex edges and the touched log. Reverts must
 * come in the reverse order of the flips, with no other write between. */
typedef struct tt__mesh_flip_undo {
  int32_t slot[2];
  int32_t hv[6], twin[6];
  uint8_t eflag[6];
  int32_t vert[4], vedge[4];
  size_t ntouched;
} tt__mesh_flip_undo;

TT_HIDDEN int32_t tt__mesh_flip_undoable(tt__mesh *m, int32_t e,
                                         tt__mesh_flip_undo *out_undo);
TT_HIDDEN void tt__mesh_flip_revert(tt__mesh *m,
                                    const tt__mesh_flip_undo *undo);

/* Removes live triangle t: its neighbours' edges across it become
 * boundary edges (a hole or a new outline). Vertex edges that pointed into
 * t are left stale: call tt__mesh_fix_vertex_edges() after a batch of
 * deletions. False (mesh unchanged) when out of memory. */
TT_HIDDEN bool tt__mesh_delete_triangle(tt__mesh *m, int32_t t);
/* Points every vertex at a live half-edge leaving it, or -1 when it is in
 * no triangle any more. O(V + T). */
TT_HIDDEN void tt__mesh_fix_vertex_edges(tt__mesh *m);

/* The half-edge from vertex a to vertex b, or -1 when there is none.
 * O(degree of a). */
TT_HIDDEN int32_t tt__mesh_find_edge(const tt__mesh *m, int32_t a, int32_t b);

/* Locates pixel point (col, row) by a walk from live triangle `start`
 * (any live triangle when -1). Returns the triangle holding it (closed)
 * and sets *out_on to -1 (strictly inside), to the half-edge it lies on,
 * or to -2 - v when it is vertex v. Returns -1 when the point is outside
 * the mesh. Meant for Delaunay-like meshes (walks terminate there); gives
 * up after a linear number of steps and falls back to a scan. */
TT_HIDDEN int32_t tt__mesh_locate(const tt__mesh *m, int32_t start,
                                  int64_t col, int64_t row,
                                  int32_t *out_on);

/* Vertex opposite half-edge e in its triangle. */
static inline int32_t tt__mesh_apex(const tt__mesh *m, int32_t e)
{
  return m->hv[tt__prev(e)];
}

/* Checks every invariant: live triangles counter-clockwise and
 * non-degenerate, twins symmetric and reversed, constraint flags symmetric,
 * vertex edges leaving their vertex, free list consistent, Euler's formula
 * V - E + F = 2C - L (C components, L boundary loops). On failure writes a
 * reason into why and returns false. */
TT_HIDDEN bool tt__mesh_validate(const tt__mesh *m, char *why, size_t whylen);

/* Empties the touched log. */
static inline void tt__mesh_clear_touched(tt__mesh *m) { m->ntouched = 0; }

/* Replaces the nold live triangles in old_slots (distinct, one connected
 * region) by the ntri triangles tris (vertex triples, counter-clockwise in
 * the ground frame) triangulating the same outline: every edge of tris is
 * either shared by two of them or is an outline edge of the region, and
 * every outline edge is used once. The old slots are reused (then slots
 * from the free list or new ones; unused old slots go to the free list);
 * twins are set inside and to the outside neighbours, outline edges keep
 * their constraint flags, a constrained edge inside the region stays
 * constrained (tris must contain it), other inner edges are not
 * constrained, vertex edges point into the new triangles (-1 for a vertex
 * left in no triangle), and the written slots are logged as touched.
 * False, with the mesh unchanged, when tris does not fit the outline that
 * way, drops an inner constrained edge, has a triangle that is not
 * strictly counter-clockwise, or when out of memory. O((nold + ntri)^2). */
TT_HIDDEN bool tt__mesh_replace_region(tt__mesh *m, const int32_t *old_slots,
                                       int nold, const int32_t (*tris)[3],
                                       int ntri);

/* A copy of the triangles and vertex edges (anneal.c keeps the best
 * triangulation seen in one). Zero-initialise it; take may be called
 * again on the same snapshot. restore writes it back into a mesh that
 * since changed only by flips (same slots, same free list, same vertices),
 * logs every live slot as touched and bumps every star version; false
 * (mesh unchanged) when the mesh does not fit or out of memory. */
typedef struct tt__mesh_snapshot {
  int32_t *hv, *twin, *vedge;
  uint8_t *eflag;
  size_t nslots, nv, nlive, cap_h, cap_v;
} tt__mesh_snapshot;

TT_HIDDEN bool tt__mesh_snapshot_take(const tt__mesh *m,
                                      tt__mesh_snapshot *s);
TT_HIDDEN bool tt__mesh_snapshot_restore(tt__mesh *m,
                                         const tt__mesh_snapshot *s);
TT_HIDDEN void tt__mesh_snapshot_free(tt__mesh_snapshot *s);

/* A whole copy of src into dst (uninitialised or freed before): the same
 * vertices, slots, free list, constraint flags and star versions, an empty
 * touched log and a serial of its own, so that an optimiser may change the
 * copy (curve.c: the final pass at a step of a recorded run) while src
 * stays as it was. False when out of memory (dst then holds nothing). The
 * caller frees dst with tt__mesh_free(). */
TT_HIDDEN bool tt__mesh_copy(tt__mesh *dst, const tt__mesh *src);

/* The star of vertex v: its triangles in counter-clockwise order around
 * it and the link, the other ends of its edges (ring) in the same order. An
 * interior vertex (a closed fan) has n neighbours and n triangles;
 * a vertex on the boundary has n neighbours and n - 1 triangles,
 * ring[0] the end of its outgoing boundary edge, ring[n - 1] the start
 * of its incoming one. Writes at most max entries into each array; returns
 * n (> max: the arrays hold only the first max), -1 when v is in no
 * triangle. slots may be NULL. *out_closed tells which kind. O(degree). */
TT_HIDDEN int tt__mesh_star(const tt__mesh *m, int32_t v, int32_t *ring,
                            int32_t *slots, int max, bool *out_closed);

/* Removes vertex v and fills its star with the ntri triangles tris
 * (vertex triples of link vertices, counter-clockwise in the ground frame)
 * that triangulate the link polygon: for an interior v, the closed link;
 * for a boundary v, the link closed by the new boundary edge from its last
 * to its first vertex, which keeps the constraint flag of v's outgoing
 * boundary edge. Every star slot is reused or freed, twins are set to the
 * outside neighbours, v's edge becomes -1, written slots are logged.
 * False, with the mesh unchanged, when tris does not fit the hole that
 * way, has a triangle that is not strictly counter-clockwise, or when out
 * of memory. O(degree^2) (holes are small; large ones are rare). */
TT_HIDDEN bool tt__mesh_remove_vertex(tt__mesh *m, int32_t v,
                                      const int32_t (*tris)[3], int ntri);

#endif /* TT_MESH_H */
