/*
 * values.c -- apps/core/: the command's core, what every command's folder
 * shares. This file: the values the command line's words stand for: finite
 * decimal numbers (no hex, inf or nan), unsigned integers that say when they
 * are too large, GDAL-style memory sizes, GDAL's booleans, grid sizes (N or
 * NXxNY).
 */
#include "app.h"

#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <stdio.h>
#include <string.h>
#include <strings.h>

/* A finite decimal number, the whole word: [+-]digits[.digits][e[+-]digits].
 * strtod alone would also take hex ("0x10" is 16), "inf", "nan" and
 * leading blanks, none of which is meant where a height or a limit goes.
 * A value too small for a double (1e-320 is subnormal, 1e-400 rounds to
 * 0) is taken as strtod rounds it: it is still the number written. */
int tt__app_parse_double(const char *w, double *out)
{
  const char *p = w;
  int digits = 0;
  if (*p == '+' || *p == '-')
    p++;
  for (; *p >= '0' && *p <= '9'; p++)
    digits++;
  if (*p == '.')
    for (p++; *p >= '0' && *p <= '9'; p++)
      digits++;
  if (!digits)
    return 0;
  if (*p == 'e' || *p == 'E') {
    p++;
    if (*p == '+' || *p == '-')
      p++;
    if (!(*p >= '0' && *p <= '9'))
      return 0;
    while (*p >= '0' && *p <= '9')
      p++;
  }
  if (*p != '\0')
    return 0;
  char *end = NULL;
  errno = 0;
  double d = strtod(w, &end);
  if (end == w || *end != '\0' || !isfinite(d))
    return 0;
  if (errno == ERANGE && fabs(d) > 1.0)
    return 0; /* overflow: strtod gave HUGE_VAL */
  *out = d;
  return 1;
}

/* An unsigned decimal integer, the whole word, no sign. NUM_TOO_LARGE for
 * digits beyond 2^64 - 1, so the message can say "above the limit" as it
 * does for 18446744073709551615. */
int tt__app_parse_u64(const char *w, uint64_t *out)
{
  uint64_t v = 0;
  int over = 0;
  if (!*w)
    return NUM_BAD;
  for (const char *p = w; *p; p++) {
    if (*p < '0' || *p > '9')
      return NUM_BAD;
    unsigned d = (unsigned)(*p - '0');
    if (v > (UINT64_MAX - d) / 10)
      over = 1;
    else
      v = v * 10 + d;
  }
  if (over)
    return NUM_TOO_LARGE;
  *out = v;
  return NUM_OK;
}

int tt__app_parse_size(const char *w, size_t *out)
{
  uint64_t v = 0;
  int k = tt__app_parse_u64(w, &v);
  if (k == NUM_OK && v > (uint64_t)SIZE_MAX)
    k = NUM_TOO_LARGE;
  if (k == NUM_OK)
    *out = (size_t)v;
  return k;
}

/* A memory size as GDAL's utilities write them: bytes, or a decimal number
 * with K, M, G or T (powers of 1024, optionally followed by B or iB:
 * "500M", "1.5GB", "2GiB", "1048576"). NUM_TOO_LARGE beyond SIZE_MAX. */
int tt__app_parse_mem_size(const char *w, size_t *out)
{
  char num[64];
  size_t n = strspn(w, "0123456789.");
  if (n == 0 || n >= sizeof num)
    return n >= sizeof num ? NUM_TOO_LARGE : NUM_BAD;
  memcpy(num, w, n);
  num[n] = '\0';
  double v;
  if (!tt__app_parse_double(num, &v))
    return NUM_BAD;
  const char *u = w + n;
  double mult = 1;
  static const char units[] = "KMGT";
  const char *k = *u ? strchr(units, *u >= 'a' ? *u - 'a' + 'A' : *u) : NULL;
  if (k && *u) {
    for (const char *q = units; q <= k; q++)
      mult *= 1024;
    u++;
    if (tt__app_str_ieq(u, "iB"))
      u += 2;
    else if (*u == 'B' || *u == 'b')
      u++;
  } else if (*u == 'B' || *u == 'b') {
    u++;
  }
  if (*u)
    return NUM_BAD;
  double bytes = floor(v * mult);
  if (bytes >= 18446744073709551616.0 || bytes >= (double)SIZE_MAX)
    return NUM_TOO_LARGE;
  *out = (size_t)bytes;
  return NUM_OK;
}

/* GDAL's booleans for --debug: the words CPLTestBool reads as such. */
int tt__app_is_gdal_bool(const char *w)
{
  static const char *const words[] = {"on", "off", "yes", "no", "true",
                                      "false", "1", "0"};
  for (size_t i = 0; i < sizeof words / sizeof words[0]; i++)
    if (tt__app_str_ieq(w, words[i]))
      return 1;
  return 0;
}

int tt__app_parse_grid_size(const char *w, size_t *nx, size_t *ny)
{
  const char *x = strpbrk(w, "xX");
  char buf[64];
  if (strlen(w) >= sizeof buf)
    return 0;
  if (!x)
    return tt__app_parse_size(w, nx) == NUM_OK && (*ny = *nx, 1);
  memcpy(buf, w, (size_t)(x - w));
  buf[x - w] = '\0';
  return tt__app_parse_size(buf, nx) == NUM_OK &&
         tt__app_parse_size(x + 1, ny) == NUM_OK;
}

int tt__app_is_pow2_plus1(size_t n)
{
  size_t m = n - 1;
  return n >= 3 && (m & (m - 1)) == 0;
}

static const char *const layer_names[] = {"triangles", "vertices",
                                          "run_parameters"};

unsigned tt__app_layer_bit(const char *w, size_t n)
{
  for (unsigned i = 0; i < 3; i++)
    if (strlen(layer_names[i]) == n && strncasecmp(w, layer_names[i], n) == 0)
      return 1u << i;
  return 0;
}

const char *tt__app_layer_list(unsigned mask, char *buf, size_t size)
{
  size_t len = 0;
  if (size)
    buf[0] = '\0';
  for (unsigned i = 0; i < 3; i++)
    if (mask & (1u << i)) {
      int k = snprintf(buf + len, size > len ? size - len : 0, "%s%s",
                       len ? "," : "", layer_names[i]);
      if (k > 0)
        len += (size_t)k;
    }
  return buf;
}
