/*
 * heap.c -- the indexed 4-ary max-heap of heap.h. Workload: in greedy
 * refinement one pop and a handful of updates per inserted vertex, so every
 * operation is O(log n) with no allocation but amortised growth.
 *
 * Part of src/base/, the base stage: the context and its errors, grids, exact
 * predicates, the heap, threads, memory limits.
 */
#include "base/heap.h"

#include <stdlib.h>

/* a ranks above b */
static inline bool above(const tt__heap_entry *a, const tt__heap_entry *b)
{
  return a->key > b->key || (a->key == b->key && a->item < b->item);
}

static void place(tt__heap *h, size_t i, tt__heap_entry x)
{
  h->e[i] = x;
  h->pos[x.item] = (int32_t)i;
}

/* A 4-ary heap: children of i are 4i+1 .. 4i+4, parent (i-1)/4. Half the
 * depth of a binary heap, and the four children of a node (16 bytes each)
 * lie in one or two 64-byte cache lines (malloc aligns e to 16 bytes):
 * sift-downs touch fewer lines, which matters once the heap (16 bytes a
 * triangle) outgrows the caches. */
#define ARITY 4

static void sift_up(tt__heap *h, size_t i)
{
  tt__heap_entry x = h->e[i];
  while (i > 0) {
    size_t parent = (i - 1) / ARITY;
    if (!above(&x, &h->e[parent]))
      break;
    place(h, i, h->e[parent]);
    i = parent;
  }
  place(h, i, x);
}

static void sift_down(tt__heap *h, size_t i)
{
  tt__heap_entry x = h->e[i];
  for (;;) {
    size_t first = ARITY * i + 1;
    if (first >= h->n)
      break;
    size_t last = first + ARITY < h->n ? first + ARITY : h->n;
    size_t best = first;
    for (size_t c = first + 1; c < last; c++)
      if (above(&h->e[c], &h->e[best]))
        best = c;
    if (!above(&h->e[best], &x))
      break;
    place(h, i, h->e[best]);
    i = best;
  }
  place(h, i, x);
}

void tt__heap_init(tt__heap *h)
{
  h->e = NULL;
  h->n = h->cap = 0;
  h->pos = NULL;
  h->item_cap = 0;
}

void tt__heap_free(tt__heap *h)
{
  free(h->e);
  free(h->pos);
  tt__heap_init(h);
}

bool tt__heap_reserve_items(tt__heap *h, size_t nitems)
{
  size_t old = h->item_cap;
  if (nitems <= old)
    return true;
  if (!tt__grow((void **)&h->pos, &h->item_cap, nitems, sizeof(int32_t)))
    return false;
  for (size_t i = old; i < h->item_cap; i++)
    h->pos[i] = -1;
  return true;
}

bool tt__heap_contains(const tt__heap *h, int32_t item)
{
  return item >= 0 && (size_t)item < h->item_cap && h->pos[item] >= 0;
}

bool tt__heap_set(tt__heap *h, int32_t item, double key)
{
  int32_t p = h->pos[item];
  if (p >= 0) {
    double old = h->e[p].key;
    h->e[p].key = key;
    if (key > old)
      sift_up(h, (size_t)p);
    else if (key < old)
      sift_down(h, (size_t)p);
    return true;
  }
  if (!tt__grow((void **)&h->e, &h->cap, h->n + 1, sizeof(tt__heap_entry)))
    return false;
  tt__heap_entry x = {key, item};
  h->e[h->n] = x;
  h->pos[item] = (int32_t)h->n;
  h->n++;
  sift_up(h, h->n - 1);
  return true;
}

void tt__heap_remove(tt__heap *h, int32_t item)
{
  if (!tt__heap_contains(h, item))
    return;
  size_t i = (size_t)h->pos[item];
  h->pos[item] = -1;
  h->n--;
  if (i == h->n)
    return;
  tt__heap_entry last = h->e[h->n];
  h->e[i] = last;
  h->pos[last.item] = (int32_t)i;
  if (i > 0 && above(&last, &h->e[(i - 1) / ARITY]))
    sift_up(h, i);
  else
    sift_down(h, i);
}

tt__heap_entry tt__heap_pop(tt__heap *h)
{
  tt__heap_entry top = h->e[0];
  tt__heap_remove(h, top.item);
  return top;
}
