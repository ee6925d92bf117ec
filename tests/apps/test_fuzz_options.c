/*
 * test_fuzz_options.c -- a fuzz target for the terratin command's option
 * parser (tt_app_options_new), after c-ares' test/ares-fuzz.c: the input is
 * split into argv words at NUL and newline bytes, parsed, and the outcome
 * checked for consistency (a failure is one non-empty line with exit code 1
 * or 2 and no object; a success holds values inside their documented
 * ranges, and is help, version or a command of the dispatch table,
 * tt__app_commands in apps/core/run.c, with every positional word the
 * table gives it). Help and version requests are run against /dev/null
 * too. The replay also requires that the corpus parses every command of
 * the table at least once, so a new command needs a corpus entry.
 *
 * Two builds:
 *  - ctest (default): a plain main() replays every file of the checked-in
 *    corpus, $TT_CORPUS/options/ (or the files and folders named on the
 *    command line), so every past crash stays a test without clang.
 *  - libFuzzer (docs/fuzzing.md): TT_FUZZ_LIBFUZZER defined, linked with
 *    -fsanitize=fuzzer; CMake does it with clang and -DTT_FUZZ=ON:
 *      cmake -S . -B build-fuzz -DCMAKE_C_COMPILER=clang -DTT_FUZZ=ON
 *      cmake --build build-fuzz -j2 --target fuzz_options
 *      build-fuzz/tests/fuzz_options -max_total_time=60 RUN_DIR \
 *        tests/corpus/options
 *    A failed REQUIRE aborts, which libFuzzer reports as a crash and saves
 *    the input of.
 *    New crashes go into tests/corpus/options/ named after their issue;
 *    the cov-* files there are a coverage corpus merged from such runs
 *    (./fuzz_options -merge=1 NEW_DIR tests/corpus/options RUN_DIR).
 */
#include "app.h"

#include <dirent.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#define MAX_WORDS 64

#define REQUIRE(cond)                                                        \
  do {                                                                       \
    if (!(cond)) {                                                           \
      fprintf(stderr, "%s:%d: REQUIRE(%s) failed\n", __FILE__, __LINE__,     \
              #cond);                                                        \
      abort();                                                               \
    }                                                                        \
  } while (0)

static int valid_list(const char *const *l, int need_equals)
{
  if (!l)
    return 0;
  for (size_t i = 0; l[i]; i++)
    if (need_equals && (!strchr(l[i], '=') || l[i][0] == '='))
      return 0;
  return 1;
}

static void check_settings(const tt_app_settings *s)
{
  REQUIRE(s != NULL);
  const tt__app_command_def *cmd = tt__app_command_def_of(s->command);
  REQUIRE(cmd || s->command == TT_APP_HELP || s->command == TT_APP_VERSION ||
          s->command == TT_APP_HELP_GENERAL || s->command == TT_APP_FORMATS);
  REQUIRE(s->help_topic == TT_APP_NONE || s->help_topic == TT_APP_TILES ||
          tt__app_command_def_of(s->help_topic) != NULL);
  for (size_t k = 0; cmd && k < cmd->npos; k++)
    if (cmd->pos[k] != TT_APP_POS_NONE)
      REQUIRE(*(const char *const *)((const char *)s + cmd->pos[k]));
  REQUIRE(s->band >= 1);
  REQUIRE(s->max_error < 0 || (isfinite(s->max_error) && s->max_error >= 0));
  REQUIRE(s->percent == 0 || (s->percent > 0 && s->percent <= 100));
  REQUIRE(isfinite(s->z_factor) && s->z_factor != 0);
  REQUIRE(s->max_points <= TT_MAX_VERTICES);
  REQUIRE(s->threads >= -1 && s->threads <= TT_APP_MAX_THREADS);
  REQUIRE(valid_list(s->lco, 1) && valid_list(s->dsco, 1));
  size_t nconfig = 0;
  REQUIRE(s->config != NULL);
  while (s->config[nconfig])
    nconfig++;
  REQUIRE(nconfig % 2 == 0);
  REQUIRE(s->nln != NULL);
  REQUIRE(tt_app_help(s->help_topic) != NULL);
  /* what the table does not say, per command */
  switch (s->command) {
  case TT_APP_SIMPLIFY:
  case TT_APP_OPTIMIZE:
    REQUIRE(tt_criterion_name(s->criterion) != NULL);
    break;
  case TT_APP_STUDY:
    REQUIRE(s->terrains && s->terrains[0]);
    break;
  case TT_APP_GENERATE:
    REQUIRE(s->output);
    REQUIRE(tt_synth_kind_name(s->synth.kind) != NULL);
    REQUIRE(s->synth.nx >= 2 && s->synth.ny >= 2);
    if (s->synth.kind == TT_SYNTH_DIAMOND_SQUARE)
      REQUIRE(s->synth.nx == s->synth.ny);
    break;
  default:
    break;
  }
}

/* The commands parsed so far, a bit each (the replay's coverage check). */
static uint64_t commands_seen;

static void run_one(const uint8_t *data, size_t size)
{
  char *buf = malloc(size + 1);
  char *words[MAX_WORDS + 1];
  size_t n = 0;
  if (!buf)
    return;
  if (size)
    memcpy(buf, data, size);
  buf[size] = '\0';
  /* Words end at NUL or newline; a trailing newline makes no empty word. */
  size_t start = 0;
  for (size_t i = 0; i <= size && n < MAX_WORDS; i++) {
    if (i == size || buf[i] == '\0' || buf[i] == '\n') {
      if (i == size && start == size)
        break;
      buf[i] = '\0';
      words[n++] = buf + start;
      start = i + 1;
    }
  }
  words[n] = NULL;

  tt_app_options *o = (tt_app_options *)&n; /* must be overwritten */
  tt_app_result res;
  tt_status st = tt_app_options_new(words, &o, &res);
  if (st == TT_OK) {
    REQUIRE(o != NULL);
    REQUIRE(res.exit_code == TT_APP_EXIT_OK && res.message[0] == '\0');
    check_settings(tt_app_options_settings(o));
    const tt_app_settings *s = tt_app_options_settings(o);
    if (s->command < 64)
      commands_seen |= UINT64_C(1) << s->command;
    /* (--formats registers every GDAL driver: not run per input) */
    if (s->command == TT_APP_HELP || s->command == TT_APP_VERSION ||
        s->command == TT_APP_HELP_GENERAL) {
      FILE *null = fopen("/dev/null", "w");
      if (null) {
        tt_app_result rr;
        tt_app_options_set_streams(o, null, null);
        REQUIRE(tt_app_run(o, &rr) == TT_OK && rr.exit_code == 0);
        fclose(null);
      }
    }
    tt_app_options_destroy(o);
  } else {
    REQUIRE(o == NULL);
    REQUIRE(st == TT_ERR_ARG || st == TT_ERR_NOMEM);
    REQUIRE(res.exit_code == (st == TT_ERR_ARG ? TT_APP_EXIT_USAGE
                                               : TT_APP_EXIT_FAILURE));
    REQUIRE(res.message[0] != '\0');
    REQUIRE(strchr(res.message, '\n') == NULL);
    REQUIRE(memchr(res.message, '\0', sizeof res.message) != NULL);
  }
  free(buf);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
  run_one(data, size);
  return 0;
}

#ifndef TT_FUZZ_LIBFUZZER

static int replay_file(const char *path)
{
  FILE *f = fopen(path, "rb");
  if (!f) {
    fprintf(stderr, "cannot open %s\n", path);
    return 0;
  }
  uint8_t *data = NULL;
  size_t size = 0, cap = 0;
  for (;;) {
    if (size == cap) {
      cap = cap ? 2 * cap : 4096;
      uint8_t *d = realloc(data, cap);
      if (!d) {
        free(data);
        fclose(f);
        return 0;
      }
      data = d;
    }
    size_t got = fread(data + size, 1, cap - size, f);
    size += got;
    if (got == 0)
      break;
  }
  fclose(f);
  LLVMFuzzerTestOneInput(data, size);
  free(data);
  return 1;
}

/* Replays a file, or every regular file of a folder; returns the count. */
static size_t replay(const char *path)
{
  struct stat st;
  if (stat(path, &st) != 0) {
    fprintf(stderr, "cannot stat %s\n", path);
    return 0;
  }
  if (!S_ISDIR(st.st_mode))
    return (size_t)replay_file(path);
  DIR *d = opendir(path);
  size_t count = 0;
  struct dirent *e;
  if (!d)
    return 0;
  while ((e = readdir(d)) != NULL) {
    if (e->d_name[0] == '.')
      continue;
    size_t len = strlen(path) + strlen(e->d_name) + 2;
    char *p = malloc(len);
    if (!p)
      break;
    snprintf(p, len, "%s/%s", path, e->d_name);
    if (stat(p, &st) == 0 && S_ISREG(st.st_mode))
      count += (size_t)replay_file(p);
    free(p);
  }
  closedir(d);
  return count;
}

int main(int argc, char **argv)
{
  size_t count = 0;
  if (argc > 1) {
    for (int i = 1; i < argc; i++)
      count += replay(argv[i]);
  } else {
    const char *corpus = getenv("TT_CORPUS");
    if (!corpus) {
      printf("SKIP: TT_CORPUS is not set\n");
      return 77;
    }
    size_t len = strlen(corpus) + sizeof "/options";
    char *dir = malloc(len);
    if (!dir)
      return 1;
    snprintf(dir, len, "%s/options", corpus);
    count = replay(dir);
    free(dir);
  }
  printf("replayed %zu input(s)\n", count);
  int missing = 0;
  for (const tt__app_command_def *d = tt__app_commands; argc == 1 && d->name;
       d++)
    if (!(commands_seen & (UINT64_C(1) << d->command))) {
      fprintf(stderr, "no corpus input parses the command %s: add one to "
              "tests/corpus/options/\n", d->name);
      missing = 1;
    }
  return count > 0 && !missing ? 0 : 1;
}
#endif /* TT_FUZZ_LIBFUZZER */
