/*
 * progress.c -- apps/core/: the command's core, what every command's folder
 * shares. This file: the text progress bar of `terratin simplify` (GDAL's
 * "0...10...20..." bar, with its state in a struct rather than in statics as
 * GDALTermProgress keeps it, and a stop flag a signal handler can set), and the
 * scaling of each phase's progress onto the whole run.
 */
#include "app.h"

#include <math.h>

void tt_app_term_progress_init(tt_app_term_progress *bar, FILE *fp,
                               volatile sig_atomic_t *stop)
{
  bar->fp = fp;
  bar->ticks = -1;
  bar->stop = stop;
  bar->line_ended = 0;
}

void tt_app_term_progress_break(tt_app_term_progress *bar)
{
  if (!bar || !bar->fp || bar->ticks < 0 || bar->ticks >= 40 ||
      bar->line_ended)
    return;
  fputc('\n', bar->fp);
  fflush(bar->fp);
  bar->line_ended = 1;
}

/* 41 ticks, one per 2.5%: tick 0 prints "0", every fourth prints the tens,
 * the others a dot, and tick 40 "100 - done." and the newline. */
int tt_app_term_progress_fn(double complete, const char *message, void *arg)
{
  tt_app_term_progress *bar = arg;
  (void)message;
  if (!bar)
    return 1;
  if (bar->fp) {
    if (!(complete >= 0)) /* also NaN */
      complete = 0;
    if (complete > 1)
      complete = 1;
    int target = (int)floor(complete * 40.0 + 1e-9);
    if (bar->ticks < target) {
      for (int t = bar->ticks + 1; t <= target; t++) {
        if (t % 4 == 0)
          fprintf(bar->fp, "%d", t / 4 * 10);
        else
          fputc('.', bar->fp);
      }
      if (target == 40)
        fputs(" - done.\n", bar->fp);
      bar->ticks = target;
      bar->line_ended = 0;
      fflush(bar->fp);
    }
  }
  return !(bar->stop && *bar->stop);
}

int tt__app_phase_fn(double complete, const char *message, void *arg)
{
  app_phase *p = arg;
  if (!(complete >= 0))
    complete = 0;
  if (complete > 1)
    complete = 1;
  if (!p->fn)
    return 1;
  return p->fn(p->lo + (p->hi - p->lo) * complete, message, p->arg);
}

void tt__app_phase_set(app_phase *p, double lo, double hi)
{
  p->lo = lo;
  p->hi = hi;
}
