/*
 * parallel.h -- a tiny pool of worker threads running batches of
 * independent jobs ("parallel for"), for the scans of refinement.
 *
 * The caller runs a batch with tt__pool_run(pool, n, fn, arg): fn(arg, i)
 * is called once for every i in [0, n), by the calling thread and the
 * workers together, and tt__pool_run returns when all calls have returned.
 * Jobs must not depend on each other, and must write only their own
 * results: then the outcome does not depend on the number of threads or on
 * scheduling. Batches in refinement are small (a handful of triangles), so
 * idle workers spin briefly before sleeping on a condition variable.
 * A pool of 1 thread runs everything in the caller.
 *
 * Part of src/base/, the base stage: the context and its errors, grids, exact
 * predicates, the heap, threads, memory limits.
 */
#ifndef TT_PARALLEL_H
#define TT_PARALLEL_H

#include "base/internal.h"

typedef struct tt__pool tt__pool;
typedef void (*tt__job_fn)(void *arg, size_t index);

/* Threads to use for `want` (0: automatic = online CPUs, at most 8). */
TT_HIDDEN int tt__pool_threads(int want);
/* Makes a pool of nthreads (including the caller): NULL when out of memory
 * or when threads cannot be started (then run single-threaded). */
TT_HIDDEN tt__pool *tt__pool_create(int nthreads);
TT_HIDDEN void tt__pool_destroy(tt__pool *pool);
/* pool may be NULL: runs the jobs in the caller. */
TT_HIDDEN void tt__pool_run(tt__pool *pool, size_t n, tt__job_fn fn,
                            void *arg);

#endif /* TT_PARALLEL_H */
