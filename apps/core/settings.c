/*
 * settings.c -- apps/core/: the command's core, what every command's folder
 * shares. This file: the options object outside the parser: the owned string
 * lists it keeps (every word it returns points into them), its accessors, the
 * progress callback and streams a caller sets, and its destruction.
 */
#include "app.h"

#include <stdlib.h>
#include <string.h>

int tt__app_strlist_add(app_strlist *l, const char *s)
{
  if (l->n + 2 > l->cap) {
    size_t cap = l->cap ? 2 * l->cap : 8;
    char **v = realloc(l->v, cap * sizeof *v);
    if (!v)
      return 0;
    l->v = v;
    l->cap = cap;
  }
  char *copy = malloc(strlen(s) + 1);
  if (!copy)
    return 0;
  strcpy(copy, s);
  l->v[l->n++] = copy;
  l->v[l->n] = NULL;
  return 1;
}

void tt__app_strlist_free(app_strlist *l)
{
  for (size_t i = 0; i < l->n; i++)
    free(l->v[i]);
  free(l->v);
  l->v = NULL;
  l->n = l->cap = 0;
}

void tt_app_options_destroy(tt_app_options *o)
{
  if (!o)
    return;
  tt__app_strlist_free(&o->strings);
  tt__app_strlist_free(&o->config);
  tt__app_strlist_free(&o->lco);
  tt__app_strlist_free(&o->dsco);
  tt__app_strlist_free(&o->terrains);
  tt__app_strlist_free(&o->co);
  free(o);
}

const tt_app_settings *tt_app_options_settings(const tt_app_options *o)
{
  return o ? &o->s : NULL;
}

void tt_app_options_set_progress(tt_app_options *o, tt_progress_fn fn,
                                 void *arg)
{
  if (!o)
    return;
  o->progress = fn;
  o->progress_arg = arg;
}

void tt_app_options_set_streams(tt_app_options *o, FILE *out, FILE *err)
{
  if (!o)
    return;
  o->out = out ? out : stdout;
  o->err = err ? err : stderr;
}

int tt_app_options_wants_progress_bar(const tt_app_options *o)
{
  return o && (o->s.command == TT_APP_SIMPLIFY ||
               o->s.command == TT_APP_STUDY) &&
         !o->s.quiet && !o->s.json;
}
