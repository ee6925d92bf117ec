/*
 * tt_test.h -- a tiny assertion header for terratin's tests (after libuv's
 * test/task.h): each check prints both sides and the place on failure and
 * makes the test exit non-zero. TT_SKIP() exits with 77, which ctest reports
 * as skipped (SKIP_RETURN_CODE).
 *
 * In a libFuzzer build (TT_FUZZ_LIBFUZZER defined, cmake -DTT_FUZZ=ON) a
 * failed check aborts at once: libFuzzer sees crashes only, so an oracle
 * that merely counted its failures would let every wrong result pass and
 * never save the input that found it.
 */
#ifndef TT_TEST_H
#define TT_TEST_H

#include <inttypes.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static int tt_test_failures = 0;

#ifdef TT_FUZZ_LIBFUZZER
#define TT_FAIL_ABORT_() abort()
#else
#define TT_FAIL_ABORT_() ((void)0)
#endif

#define TT_FAIL_(...)                                                        \
  do {                                                                       \
    fprintf(stderr, "%s:%d: ", __FILE__, __LINE__);                          \
    fprintf(stderr, __VA_ARGS__);                                            \
    fputc('\n', stderr);                                                     \
    tt_test_failures++;                                                      \
    TT_FAIL_ABORT_();                                                        \
  } while (0)

#define CHECK(cond)                                                          \
  do {                                                                       \
    if (!(cond))                                                             \
      TT_FAIL_("CHECK(%s) failed", #cond);                                   \
  } while (0)

#define CHECK_INT_EQ(a, b)                                                   \
  do {                                                                       \
    long long a_ = (long long)(a), b_ = (long long)(b);                      \
    if (a_ != b_)                                                            \
      TT_FAIL_("%s == %s failed: %lld != %lld", #a, #b, a_, b_);             \
  } while (0)

#define CHECK_INT_LE(a, b)                                                   \
  do {                                                                       \
    long long a_ = (long long)(a), b_ = (long long)(b);                      \
    if (!(a_ <= b_))                                                         \
      TT_FAIL_("%s <= %s failed: %lld > %lld", #a, #b, a_, b_);              \
  } while (0)

#define CHECK_DBL_NEAR(a, b, tol)                                            \
  do {                                                                       \
    double a_ = (double)(a), b_ = (double)(b), t_ = (double)(tol);           \
    if (!(fabs(a_ - b_) <= t_))                                              \
      TT_FAIL_("%s ~= %s failed: %.17g vs %.17g (tol %g)", #a, #b, a_, b_,   \
               t_);                                                          \
  } while (0)

#define CHECK_DBL_LE(a, b)                                                   \
  do {                                                                       \
    double a_ = (double)(a), b_ = (double)(b);                               \
    if (!(a_ <= b_))                                                         \
      TT_FAIL_("%s <= %s failed: %.17g > %.17g", #a, #b, a_, b_);            \
  } while (0)

#define CHECK_STR_EQ(a, b)                                                   \
  do {                                                                       \
    const char *a_ = (a), *b_ = (b);                                         \
    if (!a_ || !b_ || strcmp(a_, b_) != 0)                                   \
      TT_FAIL_("%s == %s failed: \"%s\" != \"%s\"", #a, #b,                  \
               a_ ? a_ : "(null)", b_ ? b_ : "(null)");                      \
  } while (0)

/* Checks a tt_status is TT_OK, printing the context's message otherwise. */
#define CHECK_OK(ctx, expr)                                                  \
  do {                                                                       \
    tt_status s_ = (expr);                                                   \
    if (s_ != TT_OK)                                                         \
      TT_FAIL_("%s failed: %s: %s", #expr, tt_status_name(s_),               \
               tt_context_errmsg(ctx));                                      \
  } while (0)

#define TT_SKIP(...)                                                         \
  do {                                                                       \
    printf("SKIP: ");                                                        \
    printf(__VA_ARGS__);                                                     \
    printf("\n");                                                            \
    exit(77);                                                                \
  } while (0)

#define TT_TEST_DONE()                                                       \
  do {                                                                       \
    if (tt_test_failures) {                                                  \
      fprintf(stderr, "%d check(s) failed\n", tt_test_failures);             \
      return 1;                                                              \
    }                                                                        \
    return 0;                                                                \
  } while (0)

/* TT_RUN(test_x(args)): runs one test function of main(); with
 * TT_TEST_TIMES set in the environment it prints the seconds it took
 * ("time: test_x(args) 1.234 s" on stderr), to see what makes a test slow
 * (STYLE.md: each property on the smallest input that shows it). */
static inline double tt_test_now(void)
{
  struct timespec t;
  timespec_get(&t, TIME_UTC);
  return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}
#define TT_RUN(...)                                                          \
  do {                                                                       \
    double t0_ = tt_test_now();                                              \
    __VA_ARGS__;                                                             \
    if (getenv("TT_TEST_TIMES"))                                             \
      fprintf(stderr, "time: %s %.3f s\n", #__VA_ARGS__,                     \
              tt_test_now() - t0_);                                          \
  } while (0)

/* A seeded generator for property tests (splitmix64); print the seed on
 * failure so the case can be replayed. */
static inline uint64_t tt_test_rand(uint64_t *state)
{
  uint64_t z = (*state += 0x9e3779b97f4a7c15ull);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}

static inline double tt_test_uniform(uint64_t *state)
{
  return (double)(tt_test_rand(state) >> 11) * (1.0 / 9007199254740992.0);
}

#endif /* TT_TEST_H */
