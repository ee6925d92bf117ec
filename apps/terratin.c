/*
 * terratin.c -- main() of the terratin command: parse, run with a progress
 * bar, print the one-line failure, map the outcome to the exit code. All the
 * work is in the app library (options.c parses, run.c runs), so tests and
 * other programs can run it too.
 *
 * Signals: SIGINT, SIGTERM and SIGHUP set a flag that the progress callback
 * turns into a stop; the run then removes its temporary files, and main
 * re-raises the signal with its default action so the shell sees the
 * process killed by it (a second signal kills at once). A run that
 * completed before it saw the flag exits 0 with its output in place.
 * SIGPIPE is ignored: a closed stdout must not kill a run halfway through
 * writing a file.
 */
#ifndef _POSIX_C_SOURCE
#define _POSIX_C_SOURCE 200809L /* sigaction; the build sets it elsewhere */
#endif

#include "terratin_lib.h"

#include <signal.h>
#include <stdio.h>
#include <string.h>

/* The one piece of global state: a signal handler can reach nothing else. */
static volatile sig_atomic_t caught_signal = 0;

static void on_signal(int sig)
{
  caught_signal = sig;
  signal(sig, SIG_DFL); /* a second signal ends the process at once */
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
}

int main(int argc, char **argv)
{
  tt_app_options *opts = NULL;
  tt_app_result res;
  tt_app_term_progress bar;
  (void)argc;

  install_handlers();
  if (tt_app_options_new(argv + 1, &opts, &res) == TT_OK) {
    tt_app_term_progress_init(
        &bar, tt_app_options_wants_progress_bar(opts) ? stdout : NULL,
        &caught_signal);
    tt_app_options_set_progress(opts, tt_app_term_progress_fn, &bar);
    tt_app_run(opts, &res);
    if (bar.fp && bar.ticks >= 0 && bar.ticks < 40)
      fputc('\n', stdout); /* end a bar cut short by a failure */
  }
  fflush(stdout);
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
