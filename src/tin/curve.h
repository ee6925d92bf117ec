/*
 * curve.h -- the error measures of a mesh after every step of a run
 * (issue 15's curves), kept up to date instead of measured afresh.
 *
 * Greedy insertion rescans every triangle it writes (refine.c); with a
 * recorder that rescan is the statistics scan (raster_scan.h), which also
 * sums |H - H'| and (H - H')^2 over the samples the triangle owns and
 * gives the same candidate, and the sums are kept per slot here, with
 * their totals over the live triangles. A step's L2, RMS, mean and total then cost
 * nothing more, and its L-infinity is the top of the candidate heap.
 *
 * Drift: the totals only ever add and subtract the per-slot doubles, so
 * they are held as double-double sums (Dekker / Knuth two-sum, about 106
 * bits): after a million replacements their error stays near 1e-16 of the
 * largest total they ever held, where plain doubles would drift by 1e-10
 * of it and more. The per-slot sums are plain doubles (the sum of one
 * triangle's samples in the order the scan visits them, as metrics.c
 * adds them), so a step's measures agree with a full pass to about 1e-15
 * relative, not bit for bit.
 *
 * Part of src/tin/, the finished TIN: its records and error statistics, eval,
 * synthetic terrains.
 */
#ifndef TT_CURVE_H
#define TT_CURVE_H

#include "base/internal.h"
#include "criteria/criterion.h"
#include "mesh/mesh.h"
#include "mesh/raster_scan.h"

/* A double-double: the value is hi + lo, |lo| <= ulp(hi) / 2. */
typedef struct tt__dd {
  double hi, lo;
} tt__dd;

static inline void tt__dd_add(tt__dd *a, double x)
{
  /* two-sum of hi and x: s + e == hi + x exactly */
  double s = a->hi + x;
  double bb = s - a->hi;
  double e = (a->hi - (s - bb)) + (x - bb);
  double t = a->lo + e;
  /* renormalise (fast two-sum: |s| >= |t| but for cancellation, where the
   * result is exact anyway) */
  a->hi = s + t;
  a->lo = t - (a->hi - s);
}

static inline double tt__dd_value(const tt__dd *a) { return a->hi + a->lo; }

typedef struct tt__curve {
  double *sabs, *ssq;    /* per triangle slot: sums over its owned samples */
  size_t *count;         /* per slot: its valid owned samples */
  size_t cap;            /* slots the arrays hold (new ones zeroed) */
  tt__dd abs, sq;        /* totals over the live slots */
  size_t samples;        /* valid owned samples of the live slots */
} tt__curve;

/* Room for nslots slots; false when out of memory (the curve unchanged). */
TT_HIDDEN bool tt__curve_fit(tt__curve *c, size_t nslots);
/* Slot t now holds s (a live triangle's statistics), or nothing (s NULL:
 * a dead slot): its old sums leave the totals, the new ones enter. */
TT_HIDDEN void tt__curve_set(tt__curve *c, int32_t t,
                             const tt__scan_stats *s);
TT_HIDDEN void tt__curve_free(tt__curve *c);

/* The measures from the totals: max and max_index (-1: none) as the caller
 * knows them, vertices the mesh's vertices in triangles (their samples are
 * exact and counted as covered), valid the grid's valid samples. */
TT_HIDDEN void tt__curve_errors(const tt__curve *c, const tt_grid *g,
                                size_t vertices, size_t valid, double max,
                                int64_t max_index, tt_error_stats *out);

/* The measures of mesh m by one pass over every sample (decimation's
 * steps): as metrics.c's, samples = valid. */
TT_HIDDEN void tt__curve_measure(const tt__mesh *m, const tt_grid *g,
                                 size_t valid, tt_error_stats *out);

/* The final pass at a step: copies m, runs tt__optimize_final on the copy
 * (mode, repair, bound, anneal as the run would) and measures the copy
 * from c (the sums of m's slots) and cerr, cand (m's per-slot candidate
 * errors and samples), scanning only the slots the pass changed. vertices
 * and valid as for tt__curve_errors. False when out of memory. */
TT_HIDDEN bool tt__curve_final(const tt__curve *c, const tt__mesh *m,
                               const double *cerr, const int64_t *cand,
                               const tt__criterion_vt *crit,
                               const tt__crit_env *env, tt_optimize mode,
                               tt_repair repair, double bound,
                               const tt_anneal_options *anneal,
                               size_t vertices, size_t valid,
                               tt_error_stats *out);

#endif /* TT_CURVE_H */
