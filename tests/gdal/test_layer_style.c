/*
 * test_layer_style.c -- the class breaks of the default QGIS style
 * (tt__style_graduated_qml, src/gdal/ogr/layer_style.c), found by selection,
 * against the same breaks from a full sort: quantiles and equal intervals
 * over values with NaNs, long runs of one value (an integer DEM's errors
 * of 0), few values, one value, none.
 */
#include "gdal/ogr/layer_style.h"
#include "tt_test.h"

#include <cpl_conv.h>

#include <stdlib.h>

static int cmp_double(const void *a, const void *b)
{
  double x = *(const double *)a, y = *(const double *)b;
  return x < y ? -1 : x > y;
}

/* The breaks as the style had them: from the sorted finite values. */
static int reference_breaks(const double *values, size_t n, int quantiles,
                            double *breaks)
{
  double *v = malloc((n ? n : 1) * sizeof *v);
  size_t m = 0;
  for (size_t i = 0; i < n; i++)
    if (isfinite(values[i]))
      v[m++] = values[i];
  qsort(v, m, sizeof *v, cmp_double);
  int nb = 0;
  if (m > 0 && quantiles) {
    breaks[nb++] = v[0];
    for (int k = 1; k <= 5; k++) {
      size_t at = k == 5 ? m - 1 : (size_t)((double)(m - 1) * k / 5 + 0.5);
      if (v[at] > breaks[nb - 1])
        breaks[nb++] = v[at];
    }
    if (nb < 4)
      quantiles = 0;
  }
  if (m > 0 && !quantiles) {
    nb = 0;
    breaks[nb++] = v[0];
    for (int k = 1; k <= 5; k++) {
      double b = k == 5 ? v[m - 1] : v[0] + (v[m - 1] - v[0]) * k / 5;
      if (b > breaks[nb - 1])
        breaks[nb++] = b;
    }
  }
  if (nb == 1)
    breaks[nb++] = v[0];
  free(v);
  return nb;
}

/* The breaks of the QML's ranges (the grey class of NULLs left out). */
static int qml_breaks(const char *qml, double *breaks)
{
  int nb = 0;
  for (const char *p = qml; (p = strstr(p, "<range lower=\"")) != NULL;) {
    p += 14;
    double lo = strtod(p, NULL);
    const char *u = strstr(p, "upper=\"");
    double hi = u ? strtod(u + 7, NULL) : NAN;
    if (lo == -1 && hi == -1)
      continue;
    if (nb == 0)
      breaks[nb++] = lo;
    breaks[nb++] = hi;
  }
  return nb;
}

static void check(const double *values, size_t n, int quantiles,
                  const char *what)
{
  double want[8], got[16];
  int nw = n ? reference_breaks(values, n, quantiles, want) : 0;
  char *qml = tt__style_graduated_qml("x", values, n, 1, 1, quantiles);
  CHECK(qml != NULL);
  if (!qml)
    return;
  int ng = qml_breaks(qml, got);
  int same = ng == nw;
  for (int k = 0; same && k < nw; k++)
    same = got[k] == want[k];
  if (!same)
    TT_FAIL_("%s (%s): %d breaks, %d expected", what,
             quantiles ? "quantiles" : "equal intervals", ng, nw);
  CPLFree(qml);
}

int main(void)
{
  uint64_t seed = 7;
  size_t sizes[] = {1, 2, 3, 5, 6, 17, 100, 1001, 54176};
  double *v = malloc(60000 * sizeof *v);
  for (size_t s = 0; s < sizeof sizes / sizeof sizes[0]; s++) {
    size_t n = sizes[s];
    for (int kind = 0; kind < 5; kind++) {
      for (size_t i = 0; i < n; i++) {
        double u = tt_test_uniform(&seed);
        switch (kind) {
        case 0: v[i] = u * 100; break;                       /* spread */
        case 1: v[i] = u < 0.7 ? 0 : floor(u * 10); break;  /* runs */
        case 2: v[i] = u < 0.1 ? NAN : exp(20 * u); break;  /* NaNs */
        case 3: v[i] = 3.5; break;                          /* one value */
        default: /* descending, signs alternating */
          v[i] = ((double)(n - i) + 0.5) * (i % 3 ? 1 : -1);
        }
      }
      char what[64];
      snprintf(what, sizeof what, "%zu values of kind %d", n, kind);
      check(v, n, 1, what);
      check(v, n, 0, what);
    }
  }
  for (size_t i = 0; i < 10; i++)
    v[i] = NAN;
  check(v, 10, 1, "only NaNs");
  check(v, 0, 1, "none");
  free(v);
  TT_TEST_DONE();
}
