/*
 * random.h -- the engine's one random generator: xoshiro256** seeded by
 * splitmix64 (both public-domain algorithms by Blackman and Vigna, written
 * here from their description). Its state lives with its user (synthetic
 * terrains, simulated annealing): no global state, and the same seed gives
 * the same sequence on every machine, so runs repeat byte for byte.
 *
 * Part of src/base/, the base stage: the context and its errors, grids, exact
 * predicates, the heap, threads, memory limits.
 */
#ifndef TT_RANDOM_H
#define TT_RANDOM_H

#include <stdint.h>

typedef struct tt__rng {
  uint64_t s[4];
} tt__rng;

static inline uint64_t tt__splitmix64(uint64_t *x)
{
  uint64_t z = (*x += 0x9e3779b97f4a7c15ull);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}

static inline void tt__rng_seed(tt__rng *g, uint64_t seed)
{
  for (int i = 0; i < 4; i++)
    g->s[i] = tt__splitmix64(&seed);
}

static inline uint64_t tt__rotl64(uint64_t v, int k)
{
  return (v << k) | (v >> (64 - k));
}

static inline uint64_t tt__rng_next(tt__rng *g)
{
  uint64_t *s = g->s;
  uint64_t out = tt__rotl64(s[1] * 5, 7) * 9;
  uint64_t t = s[1] << 17;
  s[2] ^= s[0];
  s[3] ^= s[1];
  s[1] ^= s[2];
  s[0] ^= s[3];
  s[2] ^= t;
  s[3] = tt__rotl64(s[3], 45);
  return out;
}

/* Uniform in [0, 1), 53 random bits. */
static inline double tt__rng_unit(tt__rng *g)
{
  return (double)(tt__rng_next(g) >> 11) * 0x1.0p-53;
}

#endif /* TT_RANDOM_H */
