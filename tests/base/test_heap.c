/* test_heap.c -- the indexed heap against a linear scan (differential
 * test): random pushes, key changes, removals and pops, with ties. */
#include "base/heap.h"
#include "tt_test.h"

#define N 500

int main(void)
{
  uint64_t seed = 0x5eed0001u, rng = seed;
  tt__heap h;
  tt__heap_init(&h);
  CHECK(tt__heap_reserve_items(&h, N));
  double key[N];
  int in[N] = {0};
  for (int step = 0; step < 200000; step++) {
    int item = (int)(tt_test_rand(&rng) % N);
    int op = (int)(tt_test_rand(&rng) % 4);
    /* few distinct keys, so ties are common */
    double k = (double)(tt_test_rand(&rng) % 50);
    if (op <= 1) {
      CHECK(tt__heap_set(&h, item, k));
      key[item] = k;
      in[item] = 1;
    } else if (op == 2) {
      tt__heap_remove(&h, item);
      in[item] = 0;
    } else if (tt__heap_size(&h) > 0) {
      /* oracle: largest key, smallest item among equals */
      int best = -1;
      for (int i = 0; i < N; i++)
        if (in[i] && (best < 0 || key[i] > key[best]))
          best = i;
      tt__heap_entry e = tt__heap_pop(&h);
      if (e.item != best || e.key != key[best]) {
        TT_FAIL_("seed %#llx step %d: popped (%d, %g), expected (%d, %g)",
                 (unsigned long long)seed, step, e.item, e.key, best,
                 key[best]);
        break;
      }
      in[best] = 0;
    }
    size_t n = 0;
    for (int i = 0; i < N; i++) {
      n += (size_t)in[i];
      if (tt__heap_contains(&h, i) != (in[i] != 0)) {
        TT_FAIL_("seed %#llx step %d: contains(%d) wrong",
                 (unsigned long long)seed, step, i);
        goto out;
      }
    }
    CHECK_INT_EQ(tt__heap_size(&h), n);
  }
out:
  tt__heap_free(&h);
  TT_TEST_DONE();
}
