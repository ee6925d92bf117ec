/*
 * study_plot.c -- apps/study/: the study command, a folder over the core
 * (apps/core/). This file: `terratin study -plot`: runs tools/plot_study.py on
 * the study's OUTDIR once its files are written. The python is $TT_PYTHON when
 * set, else Debian's /usr/bin/python3 when it exists, else python3 from PATH
 * (which may be a python without Debian's packages, such as a pyenv one: hence
 * Debian's first). The script is the installed one,
 * <prefix>/share/terratin/plot_study.py beside <prefix>/bin/terratin, else the
 * source tree's tools/plot_study.py.
 *
 * Both are checked before the first run of the study (`plot_study.py
 * --check` imports matplotlib), so a study that cannot be plotted fails
 * at once, in one line that says how to get matplotlib, and writes
 * nothing. A failure of the script itself comes after the study's files
 * are committed: they stay, and its message is the run's one line.
 */
#include "study.h"

#include <cpl_conv.h>
#include <cpl_string.h>

#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <spawn.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#ifndef TT_SOURCE_DIR
#define TT_SOURCE_DIR "."
#endif

extern char **environ;

/* Runs argv (argv[0] looked up in PATH when it holds no slash) with stdin
 * and stdout on /dev/null; the last non-empty line of its stderr into
 * last (may be empty). Returns the exit status, 127 when it cannot start,
 * 128 + N when killed by signal N. */
static int run_child(char *const argv[], char *last, size_t size)
{
  int fd[2];
  last[0] = '\0';
  if (pipe(fd) != 0)
    return 127;
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_addopen(&fa, 0, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&fa, 1, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_adddup2(&fa, fd[1], 2);
  posix_spawn_file_actions_addclose(&fa, fd[0]);
  posix_spawn_file_actions_addclose(&fa, fd[1]);
  pid_t pid;
  int err = posix_spawnp(&pid, argv[0], &fa, NULL, argv, environ);
  posix_spawn_file_actions_destroy(&fa);
  close(fd[1]);
  if (err != 0) {
    close(fd[0]);
    snprintf(last, size, "%s: %s", argv[0], strerror(err));
    return 127;
  }
  /* Keep the last non-empty line, whatever the length of the output. */
  char buf[512], line[512];
  size_t n = 0;
  ssize_t got;
  line[0] = '\0';
  while ((got = read(fd[0], buf, sizeof buf)) != 0) {
    if (got < 0) {
      if (errno == EINTR)
        continue;
      break;
    }
    for (ssize_t i = 0; i < got; i++) {
      if (buf[i] == '\n') {
        if (n) {
          line[n] = '\0';
          snprintf(last, size, "%s", line);
        }
        n = 0;
      } else if (n + 1 < sizeof line) {
        line[n++] = buf[i];
      }
    }
  }
  if (n) {
    line[n] = '\0';
    snprintf(last, size, "%s", line);
  }
  close(fd[0]);
  int status = 0;
  while (waitpid(pid, &status, 0) < 0)
    if (errno != EINTR)
      return 127;
  if (WIFSIGNALED(status))
    return 128 + WTERMSIG(status);
  return WEXITSTATUS(status);
}

/* The installed script beside the executable, else the source tree's,
 * into path (of size bytes); NULL when neither is there. */
static const char *find_script(char *path, size_t size)
{
  char exe[PATH_MAX];
  ssize_t n = readlink("/proc/self/exe", exe, sizeof exe - 1);
  if (n > 0) {
    exe[n] = '\0';
    char *slash = strrchr(exe, '/');
    if (slash) {
      *slash = '\0';
      snprintf(path, size, "%s/../share/terratin/plot_study.py", exe);
      if (access(path, R_OK) == 0)
        return path;
    }
  }
  snprintf(path, size, "%s/tools/plot_study.py", TT_SOURCE_DIR);
  return access(path, R_OK) == 0 ? path : NULL;
}

int tt__app_study_plot_check(app_run *r, char **out_python, char **out_script)
{
  *out_python = *out_script = NULL;
  char buf[PATH_MAX + 64];
  const char *script = find_script(buf, sizeof buf);
  if (!script) {
    tt__app_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_IO, NULL,
                 "study: -plot: plot_study.py is neither installed beside "
                 "the command (../share/terratin/) nor in %s/tools/",
                 TT_SOURCE_DIR);
    return 0;
  }
  const char *env = getenv("TT_PYTHON");
  const char *python = env && *env ? env
                       : access("/usr/bin/python3", X_OK) == 0
                           ? "/usr/bin/python3"
                           : "python3";
  char last[512];
  char *argv[] = {(char *)python, (char *)script, "--check", NULL};
  int rc = run_child(argv, last, sizeof last);
  if (rc != 0) {
    tt__app_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_IO, NULL,
                 "study: -plot needs Python 3 with matplotlib, and %s %s "
                 "(Debian: apt-get install python3-matplotlib; TT_PYTHON="
                 "PATH picks another python)", python,
                 rc == 127 ? "cannot be run" : "cannot import it");
    return 0;
  }
  *out_python = CPLStrdup(python);
  *out_script = CPLStrdup(script);
  return 1;
}

tt_status tt__app_study_plot_run(app_run *r, const char *python,
                                 const char *script, const char *outdir)
{
  char last[512];
  char *argv[] = {(char *)python, (char *)script, (char *)outdir, NULL};
  int rc = run_child(argv, last, sizeof last);
  if (rc == 0)
    return TT_OK;
  if (rc > 128)
    return tt__app_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_INTERRUPTED, NULL,
                        "study: plot_study.py was stopped by signal %d; "
                        "the study's files are written", rc - 128);
  return tt__app_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_IO, NULL,
                      "study: plotting failed (the study's files are "
                      "written): %s", last[0] ? last : "no message");
}
