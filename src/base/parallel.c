/*
 * parallel.c -- the worker pool of parallel.h, on C11 threads and atomics.
 *
 * Protocol. One 64-bit ticket holds (epoch << 32 | next job). To run a
 * batch the caller (1) closes the ticket: (new epoch, CLOSED), (2) stores
 * the batch fields (fn, arg, n, done = 0) with release order, so they can
 * only be seen after the close, (3) opens the ticket: (new epoch, 0).
 * A worker claims job i only by compare-and-swap of (e, i) -> (e, i + 1),
 * having read the fields after seeing (e, i) open: if the fields it read
 * belong to a later batch, the ticket was closed before they were written,
 * so its CAS fails. A claimed job keeps the caller from finishing the batch
 * (it waits for done == n), so the fields stay put while the job runs.
 * Idle workers spin, then sleep on a condition variable; the caller wakes
 * them when it sees the `sleeping` flag, which both sides access with
 * sequentially consistent order, so no wake-up is lost.
 *
 * Part of src/base/, the base stage: the context and its errors, grids, exact
 * predicates, the heap, threads, memory limits.
 */
#include "base/parallel.h"

#include <stdatomic.h>
#include <stdlib.h>
#include <threads.h>
#include <unistd.h>

#define MAX_THREADS 8
#define SPINS_BEFORE_SLEEP 20000
#define CLOSED 0xffffffffu

struct tt__pool {
  int nworkers;
  thrd_t workers[MAX_THREADS];
  mtx_t lock;
  cnd_t wake;
  uint32_t epoch;                /* the caller's batch counter */
  _Atomic uint64_t ticket;
  _Atomic(tt__job_fn) fn;
  _Atomic(void *) arg;
  atomic_size_t n;
  atomic_size_t done;
  atomic_int sleeping;
  atomic_int quit;
};

int tt__pool_threads(int want)
{
  if (want > 0)
    return want > MAX_THREADS ? MAX_THREADS : want;
  long cpus = sysconf(_SC_NPROCESSORS_ONLN);
  if (cpus < 1)
    cpus = 1;
  return cpus > MAX_THREADS ? MAX_THREADS : (int)cpus;
}

static inline void cpu_relax(void)
{
#if defined(__x86_64__) || defined(__i386__)
  __builtin_ia32_pause();
#endif
}

/* Runs jobs of batch `epoch` until none is left to claim. */
static void work(tt__pool *p, uint32_t epoch)
{
  for (;;) {
    uint64_t t = atomic_load(&p->ticket);
    uint32_t i = (uint32_t)t;
    if ((uint32_t)(t >> 32) != epoch || i == CLOSED)
      return;
    size_t n = atomic_load_explicit(&p->n, memory_order_acquire);
    if (i >= n)
      return;
    tt__job_fn fn = atomic_load_explicit(&p->fn, memory_order_acquire);
    void *arg = atomic_load_explicit(&p->arg, memory_order_acquire);
    if (!atomic_compare_exchange_weak(&p->ticket, &t, t + 1))
      continue;
    fn(arg, i);
    atomic_fetch_add_explicit(&p->done, 1, memory_order_release);
  }
}

static int worker_main(void *arg)
{
  tt__pool *p = arg;
  uint32_t seen = 0;
  for (;;) {
    int spins = 0;
    uint32_t e;
    while ((e = (uint32_t)(atomic_load(&p->ticket) >> 32)) == seen &&
           !atomic_load(&p->quit)) {
      if (++spins < SPINS_BEFORE_SLEEP) {
        cpu_relax();
        continue;
      }
      mtx_lock(&p->lock);
      atomic_store(&p->sleeping, 1);
      while ((uint32_t)(atomic_load(&p->ticket) >> 32) == seen &&
             !atomic_load(&p->quit))
        cnd_wait(&p->wake, &p->lock);
      atomic_store(&p->sleeping, 0);
      mtx_unlock(&p->lock);
      spins = 0;
    }
    if (atomic_load(&p->quit))
      return 0;
    /* the ticket may still be closed: wait for it to open */
    while ((uint32_t)atomic_load(&p->ticket) == CLOSED &&
           (uint32_t)(atomic_load(&p->ticket) >> 32) == e)
      cpu_relax();
    seen = e;
    work(p, e);
  }
}

tt__pool *tt__pool_create(int nthreads)
{
  if (nthreads <= 1)
    return NULL;
  if (nthreads > MAX_THREADS)
    nthreads = MAX_THREADS;
  tt__pool *p = calloc(1, sizeof *p);
  if (!p)
    return NULL;
  if (mtx_init(&p->lock, mtx_plain) != thrd_success) {
    free(p);
    return NULL;
  }
  if (cnd_init(&p->wake) != thrd_success) {
    mtx_destroy(&p->lock);
    free(p);
    return NULL;
  }
  atomic_init(&p->ticket, 0);
  atomic_init(&p->fn, NULL);
  atomic_init(&p->arg, NULL);
  atomic_init(&p->n, 0);
  atomic_init(&p->done, 0);
  atomic_init(&p->sleeping, 0);
  atomic_init(&p->quit, 0);
  for (int i = 0; i < nthreads - 1; i++) {
    if (thrd_create(&p->workers[i], worker_main, p) != thrd_success)
      break;
    p->nworkers++;
  }
  if (p->nworkers == 0) {
    tt__pool_destroy(p);
    return NULL;
  }
  return p;
}

void tt__pool_destroy(tt__pool *p)
{
  if (!p)
    return;
  mtx_lock(&p->lock);
  atomic_store(&p->quit, 1);
  cnd_broadcast(&p->wake);
  mtx_unlock(&p->lock);
  for (int i = 0; i < p->nworkers; i++)
    thrd_join(p->workers[i], NULL);
  cnd_destroy(&p->wake);
  mtx_destroy(&p->lock);
  free(p);
}

void tt__pool_run(tt__pool *p, size_t n, tt__job_fn fn, void *arg)
{
  if (!p || n <= 1 || n >= CLOSED) {
    for (size_t i = 0; i < n; i++)
      fn(arg, i);
    return;
  }
  uint32_t e = ++p->epoch;
  if (e == 0)
    e = ++p->epoch; /* workers start having seen epoch 0 */
  atomic_store(&p->ticket, ((uint64_t)e << 32) | CLOSED);
  atomic_store_explicit(&p->fn, fn, memory_order_release);
  atomic_store_explicit(&p->arg, arg, memory_order_release);
  atomic_store_explicit(&p->n, n, memory_order_release);
  atomic_store_explicit(&p->done, 0, memory_order_release);
  atomic_store(&p->ticket, (uint64_t)e << 32);
  if (atomic_load(&p->sleeping)) {
    mtx_lock(&p->lock);
    cnd_broadcast(&p->wake);
    mtx_unlock(&p->lock);
  }
  work(p, e);
  while (atomic_load_explicit(&p->done, memory_order_acquire) < n)
    cpu_relax();
}
