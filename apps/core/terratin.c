/*
 * terratin.c -- apps/core/: the command's core, what every command's folder
 * shares. This file: main() of the terratin command: parse, run with a progress
 * bar, print the one-line failure, map the outcome to the exit code. All the
 * work is in the app library (options.c parses, run.c runs), so tests and other
 * programs can run it too.
 *
 * Signals: SIGINT, SIGTERM and SIGHUP set a flag that the progress callback
 * turns into a stop; the run then removes its temporary files, and main
 * re-raises the signal with its default action so the shell sees the
 * process killed by it. A run that completed before it saw the flag exits 0
 * with its output in place. SIGPIPE is ignored: a closed stdout must not
 * kill a run halfway through writing a file. SIGXFSZ too: a write past
 * the file size limit (ulimit -f) then fails with EFBIG, and the run
 * removes its temporary files instead of dying with them in place.
 *
 * A driver can keep the run from calling back for minutes (GDAL's LIBKML
 * writer, a close that flushes a large file). So the handler also wakes a
 * watchdog thread through a pipe (write() is async-signal-safe): if the
 * run has not ended GRACE_MS after the signal (or at a second signal), the
 * watchdog removes the temporary files of every output not yet committed
 * (tt_output_abandon_all(), which a mutex orders with the run's own commit)
 * and ends the process by the signal, after ending a half-drawn bar's line
 * and naming the output it stopped, as the run itself would. An output
 * already committed is let finish: its run is only printing its summary.
 */
#ifndef _POSIX_C_SOURCE
#define _POSIX_C_SOURCE 200809L /* sigaction; the build sets it elsewhere */
#endif

#include "terratin_lib.h"
#include "terratin/terratin_gdal.h"

#include <errno.h>
#include <poll.h>
#include <pthread.h>
#include <signal.h>
#include <stdatomic.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#define GRACE_MS 500

/* The global state a signal handler and its watchdog need: nothing else
 * can reach them. */
static volatile sig_atomic_t caught_signal = 0;
static int wake_pipe[2] = {-1, -1};
static atomic_int run_ended = 0;
/* The bar, and the watchdog's line naming the output, made before the run
 * so that the watchdog only calls write(). */
static tt_app_term_progress bar;
static char stop_msg[1100] = "terratin: interrupted; nothing written\n";

static void on_signal(int sig)
{
  int saved = errno;
  caught_signal = sig;
  if (wake_pipe[1] >= 0) {
    ssize_t n = write(wake_pipe[1], "s", 1);
    (void)n; /* a full pipe has woken the watchdog already */
  }
  errno = saved;
}

static int wait_wake(int timeout_ms)
{
  struct pollfd p = {wake_pipe[0], POLLIN, 0};
  int r;
  while ((r = poll(&p, 1, timeout_ms)) < 0 && errno == EINTR)
    ;
  if (r > 0) {
    char c;
    ssize_t n = read(wake_pipe[0], &c, 1);
    (void)n;
  }
  return r > 0;
}

static void *watchdog(void *arg)
{
  (void)arg;
  /* Signals go to the main thread, as they did before this thread. */
  sigset_t all;
  sigfillset(&all);
  pthread_sigmask(SIG_BLOCK, &all, NULL);
  wait_wake(-1);
  if (atomic_load(&run_ended))
    return NULL;
  wait_wake(GRACE_MS); /* the run's own stop, or a second signal */
  if (atomic_load(&run_ended) || !tt_output_abandon_all())
    return NULL;
  int sig = (int)caught_signal;
  /* End a half-drawn bar (flushed at every tick, so nothing of it is
   * left in stdout's buffer), then say what was stopped. */
  ssize_t n = 0;
  if (bar.fp && bar.ticks >= 0 && bar.ticks < 40 && !bar.line_ended)
    n = write(STDOUT_FILENO, "\n", 1);
  n = write(STDERR_FILENO, stop_msg, strlen(stop_msg));
  (void)n;
  signal(sig, SIG_DFL);
  kill(getpid(), sig); /* the main thread takes it: the process ends */
  sleep(2);
  _exit(128 + sig);
}

static void install_handlers(void)
{
  static const int sigs[] = {SIGINT, SIGTERM, SIGHUP};
  struct sigaction sa;
  memset(&sa, 0, sizeof sa);
  sa.sa_handler = on_signal;
  sigemptyset(&sa.sa_mask);
  for (size_t i = 0; i < sizeof sigs / sizeof sigs[0]; i++) {
    /* A signal ignored by the parent stays ignored (nohup, the SIGINT of a
     * shell's background job). */
    struct sigaction old;
    if (sigaction(sigs[i], NULL, &old) == 0 && old.sa_handler == SIG_IGN)
      continue;
    sigaction(sigs[i], &sa, NULL);
  }
  signal(SIGPIPE, SIG_IGN);
  signal(SIGXFSZ, SIG_IGN);
}

int main(int argc, char **argv)
{
  tt_app_options *opts = NULL;
  tt_app_result res;
  (void)argc;
  tt_app_term_progress_init(&bar, NULL, &caught_signal);

  pthread_t dog;
  int have_dog = pipe(wake_pipe) == 0 &&
                 pthread_create(&dog, NULL, watchdog, NULL) == 0;
  install_handlers();
  if (argv[1] && strcmp(argv[1], "tiles") == 0) {
    tt_app_tiles(argv + 2, tt_app_term_progress_fn, &bar, &res);
  } else if (tt_app_options_new(argv + 1, &opts, &res) == TT_OK) {
    const tt_app_settings *s = tt_app_options_settings(opts);
    const char *out = s->error_raster ? s->error_raster : s->output;
    char shown[sizeof stop_msg - 64]; /* room for the words around it */
    if (out && tt_app_mask_password(out, shown, sizeof shown) >= 0 &&
        strlen(shown) + 1 < sizeof shown) /* not cut short */
      snprintf(stop_msg, sizeof stop_msg,
               "terratin: %s: interrupted; nothing written\n", shown);
    tt_app_term_progress_init(
        &bar, tt_app_options_wants_progress_bar(opts) ? stdout : NULL,
        &caught_signal);
    tt_app_options_set_progress(opts, tt_app_term_progress_fn, &bar);
    tt_app_run(opts, &res);
    tt_app_term_progress_break(&bar); /* a bar cut short by a failure */
  }
  atomic_store(&run_ended, 1);
  if (have_dog) {
    ssize_t n = write(wake_pipe[1], "e", 1);
    (void)n;
    pthread_join(dog, NULL);
  }
  fflush(stdout);
  /* a connection string quoted by a failure of the parser or of the
   * tiles commands, which run no tt_app_run of their own */
  tt_app_mask_words(argv + 1, res.message, sizeof res.message);
  if (res.message[0])
    fprintf(stderr, "terratin: %s\n", res.message);
  tt_app_options_destroy(opts);
  /* Stopped by a signal: end by it, as the shell expects. A run that had
   * already finished (the signal came during its last steps) keeps its
   * success: its output is complete. */
  if (caught_signal && res.exit_code != TT_APP_EXIT_OK) {
    signal((int)caught_signal, SIG_DFL);
    raise((int)caught_signal);
  }
  return res.exit_code;
}
