/*
 * tin.h -- the finished TIN (struct tt_tin): compact vertex and triangle
 * arrays with the bookkeeping of the run, built from a mesh by metrics.c
 * and read through the accessors of tin.c. Vertex index = insertion rank
 * among the vertices kept (those in some triangle).
 * Triangles are counter-clockwise in map space (the ground frame keeps the
 * geotransform's orientation, grid.c).
 *
 * Part of src/tin/, the finished TIN: its records and error statistics, eval,
 * synthetic terrains.
 */
#ifndef TT_TIN_H
#define TT_TIN_H

#include "base/internal.h"
#include "mesh/mesh.h"
#include "base/parallel.h"

struct tt_tin {
  size_t nv, nt;
  /* vertices */
  int32_t *vc, *vr;
  float *vz;             /* heights; NULL when vzd holds them */
  double *vzd;           /* heights of a TIN of a grid of doubles */
  double *v_ins_err;     /* NaN for starting vertices */
  double *v_star_max, *v_star_rmse;
  uint64_t *v_star_n;
  double *v_importance;  /* decimation (NULL after refinement: NaN) */
  int32_t *v_home;       /* tile runs (tt__tin_build_homes): the triangle
                            whose t_n counts the vertex's own sample; NULL
                            otherwise */
  /* triangles */
  int32_t *tv;           /* 3 per triangle */
  double *t_max;
  double *t_rmse;        /* doubles, clamped to t_max: a float's rounding
                            put 1,929 of Mt Hood's rmse above max_err */
  uint64_t *t_n;
  uint8_t *t_brk;        /* bit k: edge v[k] -> v[k+1] lies on a breakline;
                            NULL when the TIN has none */
  /* georeference */
  double gt[6];
  double frame[4];
  /* the vertices' ground points, scale factors and convergences (struct
   * tt_grid), NULL when the grid had none */
  double *vgxy;
  float *vgk, *vgconv;
  tt_area_fn area_fn;    /* the grid's, or NULL */
  double area_par[4];
  tt_tin_summary summary;
};

/* Vertex v's height. */
static inline double tt__tin_z(const tt_tin *tin, size_t v)
{
  return tin->vzd ? tin->vzd[v] : (double)tin->vz[v];
}

/* Builds a tin from the mesh's live triangles (in spatial order) with the
 * error statistics of every sample (metrics.c). ins_err: per mesh vertex
 * (taken over, freed by the tin). Frees nothing of the mesh. The scans
 * run on pool (may be NULL); the result does not depend on it. */
TT_HIDDEN tt_status tt__tin_build(tt_context *ctx, const tt__mesh *m,
                                  const tt_grid *g, double *ins_err,
                                  tt__pool *pool, tt_tin **out_tin);

/* tt__tin_build that also fills v_home (for merging tiles, src/tile/). */
TT_HIDDEN tt_status tt__tin_build_homes(tt_context *ctx, const tt__mesh *m,
                                        const tt_grid *g, double *ins_err,
                                        tt__pool *pool, tt_tin **out_tin);

#endif /* TT_TIN_H */
