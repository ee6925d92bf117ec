/*
 * heap.h -- an indexed 4-ary max-heap of (key, item) pairs.
 *
 * Items are small non-negative integers (triangle or edge slots); the heap
 * keeps each item's position so an item's key can be changed or the item
 * removed in O(log n). Order: larger key first; equal keys break on the
 * smaller item id, so the same pushes give the same pops on every machine
 * (the TIN is reproducible byte for byte). Keys must not be NaN.
 *
 * Part of src/base/, the base stage: the context and its errors, grids, exact
 * predicates, the heap, threads, memory limits.
 */
#ifndef TT_HEAP_H
#define TT_HEAP_H

#include "base/internal.h"

typedef struct tt__heap_entry {
  double key;
  int32_t item;
} tt__heap_entry;

typedef struct tt__heap {
  tt__heap_entry *e;   /* e[0..n) in heap order */
  size_t n, cap;
  int32_t *pos;        /* pos[item] = index in e, or -1 */
  size_t item_cap;
} tt__heap;

TT_HIDDEN void tt__heap_init(tt__heap *h);
TT_HIDDEN void tt__heap_free(tt__heap *h);
/* Makes items 0..nitems-1 usable; false when out of memory. */
TT_HIDDEN bool tt__heap_reserve_items(tt__heap *h, size_t nitems);
/* Inserts the item or changes its key when present; false when out of
 * memory. The item must be < the reserved count. */
TT_HIDDEN bool tt__heap_set(tt__heap *h, int32_t item, double key);
/* Removes the item when present. */
TT_HIDDEN void tt__heap_remove(tt__heap *h, int32_t item);
TT_HIDDEN bool tt__heap_contains(const tt__heap *h, int32_t item);

static inline size_t tt__heap_size(const tt__heap *h) { return h->n; }
/* The top entry; the heap must not be empty. */
static inline tt__heap_entry tt__heap_top(const tt__heap *h) { return h->e[0]; }
/* Removes and returns the top entry; the heap must not be empty. */
TT_HIDDEN tt__heap_entry tt__heap_pop(tt__heap *h);

#endif /* TT_HEAP_H */
