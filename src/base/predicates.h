/*
 * predicates.h -- exact geometric predicates.
 *
 * Sign convention, stated once for the whole engine: orient2d(a,b,c) > 0
 * when a, b, c turn counter-clockwise in a right-handed (x right, y up)
 * frame; incircle(a,b,c,d) > 0 when d lies strictly inside the circle through
 * a, b, c given counter-clockwise. The grid's row axis points south on a
 * north-up raster, so in pixel space (col, row) "counter-clockwise" is the
 * mirror image: the mesh never uses pixel-space orientation without the
 * frame's det_sign (see mesh.h).
 *
 * Two families:
 *  - double-precision adaptive predicates (tt__orient2d, tt__incircle): a
 *    floating-point filter and an exact expansion-arithmetic fallback
 *    (Shewchuk 1997). Exact for any finite doubles.
 *  - grid predicates on integer pixel coordinates (|c|, |r| < 2^28):
 *    tt__orient_i is exact in 128-bit integers; tt__incircle_metric is the
 *    incircle test in the ground frame given by a metric tensor (see
 *    internal.h), evaluated exactly from integer determinants and the three
 *    double coefficients.
 * All return -1, 0 or +1. Compile without -ffast-math or FMA contraction.
 *
 * Part of src/base/, the base stage: the context and its errors, grids, exact
 * predicates, the heap, threads, memory limits.
 */
#ifndef TT_PREDICATES_H
#define TT_PREDICATES_H

#include "base/internal.h"

TT_HIDDEN int tt__orient2d(const double a[2], const double b[2],
                           const double c[2]);
TT_HIDDEN int tt__incircle(const double a[2], const double b[2],
                           const double c[2], const double d[2]);

TT_HIDDEN int tt__orient_i(int64_t ax, int64_t ay, int64_t bx, int64_t by,
                           int64_t cx, int64_t cy);
/* Incircle in the ground frame of metric m for points given in pixel space.
 * Positive when d is strictly inside the ground-frame circle through a, b, c
 * and a, b, c are counter-clockwise in the ground frame. */
TT_HIDDEN int tt__incircle_metric(const tt__metric *m, int64_t ax, int64_t ay,
                                  int64_t bx, int64_t by, int64_t cx,
                                  int64_t cy, int64_t dx, int64_t dy);

#endif /* TT_PREDICATES_H */
