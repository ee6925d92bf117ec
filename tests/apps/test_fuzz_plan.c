/*
 * test_fuzz_plan.c -- a fuzz target for the tile plan's reader
 * (tt__tiles_plan_read, apps/tiles/tiles_plan_file.c), which `tiles run`
 * and `tiles merge` apply to a PLAN.json anyone may have written.
 *
 * Input: a flags byte, then the plan's text, in which @DEM@, @BYTES@ and
 * @MTIME@ stand for the absolute path, size and modification time (ns) of
 * a 40 x 30 DEM this target makes once in a temporary folder, so that a
 * corpus plan names a DEM on any machine. Flag 1: the closing checksum is
 * recomputed over the text before it, so that the fuzzer gets past it to
 * the fields. The text is read from /vsimem/.
 *
 * Oracle: a refusal is one non-empty line with exit code 1 or 2; an
 * acceptance names the target's DEM with its size, a grid of tiles of
 * 16 to 65536 cells that width, height and tile size give, options a plan
 * may carry, and a text byte for byte what the writer makes of it (so the
 * reader accepts exactly the plans `tiles plan` writes). In the replay
 * build a corpus file named refuse_* must be refused and one named
 * accept_* accepted.
 *
 * Two builds, as test_fuzz_options.c:
 *  - ctest (default): main() replays $TT_CORPUS/plan/, then plans written
 *    by `tiles plan` itself (each accepted) and 600 seeded mutations of
 *    them (bytes flipped, inserted, deleted, cut; half with the checksum
 *    recomputed), each under the oracle.
 *  - libFuzzer (docs/fuzzing.md): TT_FUZZ_LIBFUZZER defined, a failed
 *    check aborts:
 *      cmake -S . -B build-fuzz -DCMAKE_C_COMPILER=clang -DTT_FUZZ=ON
 *      cmake --build build-fuzz -j2 --target fuzz_plan
 *      build-fuzz/tests/fuzz_plan -max_total_time=60 RUN_DIR tests/corpus/plan
 */
#define _XOPEN_SOURCE 700 /* realpath */
#include "terratin_lib.h"
#include "tiles.h"
#include "tt_test.h"

#include <cpl_conv.h>
#include <cpl_error.h>
#include <cpl_string.h>
#include <cpl_vsi.h>
#include <gdal.h>

#include <dirent.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#define DEM_W 40
#define DEM_H 30
#define PLAN_PATH "/vsimem/fuzz_plan/plan.json"
#define SUM_KEY "  \"checksum\": \"fnv1a64:"

/* The target's DEM and folder, made once. */
static char dir[4096], dem[4096], dem_bytes[32], dem_mtime[32];

static void remove_dem(void)
{
  if (dem[0])
    unlink(dem);
  if (dir[0])
    rmdir(dir);
}

static bool make_dem(void)
{
  GDALAllRegister();
  CPLPushErrorHandler(CPLQuietErrorHandler);
  const char *tmp = getenv("TMPDIR");
  snprintf(dir, sizeof dir, "%s/tt_fuzz_plan.XXXXXX", tmp ? tmp : "/tmp");
  if (!mkdtemp(dir))
    return false;
  char *real = realpath(dir, NULL);
  if (!real)
    return false;
  snprintf(dem, sizeof dem, "%s/dem.tif", real);
  free(real);
  atexit(remove_dem);
  GDALDriverH drv = GDALGetDriverByName("GTiff");
  GDALDatasetH ds = drv ? GDALCreate(drv, dem, DEM_W, DEM_H, 1, GDT_Float32,
                                     NULL)
                        : NULL;
  if (!ds)
    return false;
  float z[DEM_W * DEM_H];
  for (int i = 0; i < DEM_W * DEM_H; i++)
    z[i] = (float)((i * 37) % 101) * 0.5f;
  CPLErr err = GDALRasterIO(GDALGetRasterBand(ds, 1), GF_Write, 0, 0, DEM_W,
                            DEM_H, z, DEM_W, DEM_H, GDT_Float32, 0, 0);
  GDALClose(ds);
  struct stat sb;
  if (err != CE_None || stat(dem, &sb) != 0)
    return false;
  snprintf(dem_bytes, sizeof dem_bytes, "%llu", (unsigned long long)sb.st_size);
  snprintf(dem_mtime, sizeof dem_mtime, "%llu",
           (unsigned long long)sb.st_mtim.tv_sec * 1000000000ull +
               (unsigned long long)sb.st_mtim.tv_nsec);
  return true;
}

static uint64_t fnv1a(const char *p, size_t n)
{
  uint64_t h = UINT64_C(14695981039346656037);
  for (size_t i = 0; i < n; i++) {
    h ^= (unsigned char)p[i];
    h *= UINT64_C(1099511628211);
  }
  return h;
}

/* The plan's text of an input: placeholders replaced, the checksum
 * recomputed when asked (malloc'd, *out_len its length). */
static char *plan_of(const uint8_t *data, size_t size, size_t *out_len)
{
  static const char *const keys[] = {"@DEM@", "@BYTES@", "@MTIME@"};
  const char *vals[] = {dem, dem_bytes, dem_mtime};
  const char *t = (const char *)data + 1;
  size_t n = size - 1, cap = n + 1, len = 0;
  for (size_t i = 0; i < n; i++)
    if (t[i] == '@')
      cap += strlen(dem) + 32;
  char *s = malloc(cap);
  for (size_t i = 0; i < n;) {
    size_t k = 0;
    while (k < 3 && (n - i < strlen(keys[k]) ||
                     memcmp(t + i, keys[k], strlen(keys[k])) != 0))
      k++;
    if (k < 3) {
      memcpy(s + len, vals[k], strlen(vals[k]));
      len += strlen(vals[k]);
      i += strlen(keys[k]);
    } else {
      s[len++] = t[i++];
    }
  }
  s[len] = '\0';
  if (data[0] & 1) {
    /* the last checksum key with its 16 characters after it */
    char *k = NULL;
    for (size_t i = 0; i + sizeof SUM_KEY - 1 <= len; i++)
      if (memcmp(s + i, SUM_KEY, sizeof SUM_KEY - 1) == 0)
        k = s + i;
    if (k && (size_t)(k - s) + sizeof SUM_KEY - 1 + 16 <= len) {
      char hex[17];
      snprintf(hex, sizeof hex, "%016llx",
               (unsigned long long)fnv1a(s, (size_t)(k - s)));
      memcpy(k + sizeof SUM_KEY - 1, hex, 16);
    }
  }
  *out_len = len;
  return s;
}

static void check_accepted(const tiles_plan *p, const char *text, size_t len)
{
  CHECK(strcmp(p->dem, dem) == 0);
  CHECK(p->width == DEM_W && p->height == DEM_H);
  CHECK(p->tile_size >= 16 && p->tile_size <= 65536);
  tiles_plan g = *p;
  tt__tiles_grid(&g);
  CHECK(g.tiles_x == p->tiles_x && g.tiles_y == p->tiles_y &&
        g.tiles == p->tiles && p->tiles >= 1);
  tt_app_result res;
  tt__app_result_ok(&res);
  CHECK(tt__tiles_plan_check_words("fuzz", p->options, &res));
  size_t n = 0;
  char *want = tt__tiles_plan_text(p, &n);
  CHECK(want && n == len && memcmp(want, text, len) == 0);
  CPLFree(want);
  CHECK(p->hash == fnv1a(text, len));
  CHECK(strcmp(p->pieces, PLAN_PATH ".tiles") == 0);
}

static void check_refused(const tt_app_result *res)
{
  CHECK(res->exit_code == TT_APP_EXIT_USAGE ||
        res->exit_code == TT_APP_EXIT_FAILURE);
  CHECK(res->message[0] != '\0');
  CHECK(memchr(res->message, '\0', sizeof res->message) != NULL);
  CHECK(strchr(res->message, '\n') == NULL);
}

/* The DEM, made at the first call. */
static bool have_dem(void)
{
  static int made = -1;
  if (made < 0 && !(made = make_dem()))
    TT_FAIL_("cannot make the DEM in %s", dir);
  return made;
}

/* The last refusal's message (replay: printed with TT_FUZZ_PLAN_VERBOSE). */
static char last_message[TT_APP_MESSAGE_MAX];

/* 1 accepted, 0 refused, -1 no input */
static int check_input(const uint8_t *data, size_t size)
{
  if (!have_dem() || size < 1)
    return -1;
  size_t len = 0;
  char *text = plan_of(data, size, &len);
  VSILFILE *f = VSIFileFromMemBuffer(PLAN_PATH, (GByte *)text, len, FALSE);
  if (!f) {
    free(text);
    return -1;
  }
  VSIFCloseL(f);
  tiles_plan p;
  tt_app_result res;
  tt__app_result_ok(&res);
  bool ok = tt__tiles_plan_read(PLAN_PATH, &p, &res);
  if (ok) {
    CHECK(res.exit_code == TT_APP_EXIT_OK && res.message[0] == '\0');
    check_accepted(&p, text, len);
  } else {
    check_refused(&res);
  }
  snprintf(last_message, sizeof last_message, "%s", res.message);
  tt__tiles_plan_free(&p);
  VSIUnlink(PLAN_PATH);
  free(text);
  return ok;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
  check_input(data, size);
  return 0;
}

#ifndef TT_FUZZ_LIBFUZZER

static uint8_t *slurp(const char *path, size_t *out_size)
{
  FILE *f = fopen(path, "rb");
  if (!f)
    return NULL;
  uint8_t *data = NULL;
  size_t size = 0, cap = 0, got;
  do {
    if (size == cap) {
      cap = cap ? 2 * cap : 65536;
      data = realloc(data, cap);
    }
    got = fread(data + size, 1, cap - size, f);
    size += got;
  } while (got > 0);
  fclose(f);
  *out_size = size;
  return data;
}

/* Every file of the corpus; refuse_* refused, accept_* accepted. */
static size_t replay_corpus(void)
{
  const char *corpus = getenv("TT_CORPUS");
  char path[8192];
  snprintf(path, sizeof path, "%s/plan", corpus ? corpus : "tests/corpus");
  DIR *d = opendir(path);
  size_t files = 0;
  if (!d) {
    TT_FAIL_("cannot open the corpus folder %s", path);
    return 0;
  }
  struct dirent *de;
  while ((de = readdir(d)) != NULL) {
    if (de->d_name[0] == '.')
      continue;
    char file[8192 + 256];
    snprintf(file, sizeof file, "%s/%s", path, de->d_name);
    size_t size = 0;
    uint8_t *data = slurp(file, &size);
    if (!data)
      continue;
    int before = tt_test_failures;
    int got = check_input(data, size);
    if (strncmp(de->d_name, "refuse_", 7) == 0 && got != 0)
      TT_FAIL_("accepted, should be refused");
    if (strncmp(de->d_name, "accept_", 7) == 0 && got != 1)
      TT_FAIL_("refused, should be accepted");
    if (tt_test_failures != before)
      fprintf(stderr, "  (corpus file %s)\n", de->d_name);
    if (getenv("TT_FUZZ_PLAN_VERBOSE"))
      printf("%s: %s\n", de->d_name, got == 1 ? "accepted" : last_message);
    free(data);
    files++;
  }
  closedir(d);
  return files;
}

/* A plan `tiles plan` writes on the target's DEM with the words, as an
 * input (flags 0, the text as written); NULL when it refused them. */
static uint8_t *written_plan(const char *const *words, size_t *out_size)
{
  char path[4200];
  snprintf(path, sizeof path, "%s/p.json", dir);
  char **argv = CSLAddString(NULL, "plan");
  argv = CSLAddString(argv, dem);
  argv = CSLAddString(argv, path);
  argv = CSLAddString(argv, "-q");
  argv = CSLAddString(argv, "-overwrite");
  for (size_t i = 0; words[i]; i++)
    argv = CSLAddString(argv, words[i]);
  tt_app_result res;
  tt_app_tiles(argv, NULL, NULL, &res);
  CSLDestroy(argv);
  size_t size = 0;
  uint8_t *text = res.exit_code == 0 ? slurp(path, &size) : NULL;
  unlink(path);
  char pieces[4300];
  snprintf(pieces, sizeof pieces, "%s.tiles", path);
  rmdir(pieces);
  if (!text)
    return NULL;
  uint8_t *in = malloc(size + 1);
  in[0] = 0;
  memcpy(in + 1, text, size);
  free(text);
  *out_size = size + 1;
  return in;
}

static uint64_t next(uint64_t *s)
{
  *s ^= *s << 13;
  *s ^= *s >> 7;
  *s ^= *s << 17;
  return *s;
}

/* One seeded mutation of a plan: a byte changed, inserted or deleted, or
 * the text cut; the checksum recomputed for half of them. */
static size_t mutate(uint8_t *buf, size_t size, size_t cap, uint64_t *rng)
{
  size_t at = 1 + next(rng) % (size - 1);
  static const char bytes[] = "0123456789\"\\,:[]{} -\n\x01@";
  uint8_t b = (uint8_t)bytes[next(rng) % (sizeof bytes - 1)];
  switch (next(rng) % 4) {
  case 0: buf[at] = b; break;
  case 1:
    if (size < cap) {
      memmove(buf + at + 1, buf + at, size - at);
      buf[at] = b;
      size++;
    }
    break;
  case 2:
    memmove(buf + at, buf + at + 1, size - at - 1);
    size--;
    break;
  default: size = at; break;
  }
  buf[0] = (uint8_t)(next(rng) & 1);
  return size;
}

int main(void)
{
  if (!have_dem())
    return 1;
  size_t files = replay_corpus();
  static const char *const sets[][12] = {
      {"-max_error", "2", "-tile_size", "16", NULL},
      {"-max_error", "0.5", "-tile_size", "20", "-criterion", "minmax_angle",
       "-optimize", "lookahead", NULL},
      {"-max_error", "1", "-tile_size", "16", "-method", "decimate",
       "-importance", "drop", "-z_factor", "0.3048", NULL},
      {"-max_error", "1", "-tile_size", "64", "-srcnodata", "-9999", "-b",
       "1", NULL}};
  size_t plans = 0, mutants = 0, kept = 0;
  uint64_t seed = 0x91a7u, rng = seed;
  for (size_t s = 0; s < sizeof sets / sizeof sets[0]; s++) {
    size_t size = 0;
    uint8_t *in = written_plan(sets[s], &size);
    if (!in) {
      TT_FAIL_("tiles plan refused option set %zu", s);
      continue;
    }
    if (check_input(in, size) != 1)
      TT_FAIL_("the plan of option set %zu, as written, refused", s);
    plans++;
    uint8_t *buf = malloc(size + 64);
    for (int i = 0; i < 150; i++) {
      memcpy(buf, in, size);
      size_t n = size;
      for (int m = 0; m < 1 + (int)(next(&rng) % 3) && n > 1; m++)
        n = mutate(buf, n, size + 64, &rng);
      int before = tt_test_failures;
      kept += check_input(buf, n) == 1;
      mutants++;
      if (tt_test_failures != before) {
        fprintf(stderr, "  (mutation %d of option set %zu, seed %#llx)\n", i,
                s, (unsigned long long)seed);
        break;
      }
    }
    free(buf);
    free(in);
  }
  printf("replayed %zu corpus files, %zu written plans and %zu mutations "
         "(%zu accepted: they are still plans the writer makes)\n", files,
         plans, mutants, kept);
  CHECK(files > 0);
  TT_TEST_DONE();
}
#endif
