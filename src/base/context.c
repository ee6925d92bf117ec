/*
 * context.c -- the context (last error, warning sink), status names, version,
 * and the small helpers every module uses: error formatting, array growth,
 * the clock. The context holds all mutable state a
 * run needs besides its own objects: there is no global mutable state.
 *
 * Part of src/base/, the base stage: the context and its errors, grids, exact
 * predicates, the heap, threads, memory limits.
 */
#include "base/internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static const char *const status_names[] = {
#define TT_NAME_(name, msg) #name,
    TT_STATUS_MAP(TT_NAME_)
#undef TT_NAME_
};

static const char *const status_messages[] = {
#define TT_MSG_(name, msg) msg,
    TT_STATUS_MAP(TT_MSG_)
#undef TT_MSG_
};

const char *tt_status_name(tt_status status)
{
  if ((int)status < 0 || status >= TT_STATUS_COUNT_)
    return "UNKNOWN";
  return status_names[status];
}

const char *tt_status_message(tt_status status)
{
  if ((int)status < 0 || status >= TT_STATUS_COUNT_)
    return "unknown status";
  return status_messages[status];
}

const char *tt_version(void) { return TT_VERSION_STRING; }

tt_context *tt_context_create(void)
{
  return calloc(1, sizeof(tt_context));
}

void tt_context_destroy(tt_context *ctx) { free(ctx); }

tt_status tt_context_errno(const tt_context *ctx)
{
  return ctx ? ctx->last_status : TT_ERR_ARG;
}

const char *tt_context_errmsg(const tt_context *ctx)
{
  return ctx ? ctx->errmsg : "";
}

void tt_context_clear_error(tt_context *ctx)
{
  if (!ctx)
    return;
  ctx->last_status = TT_OK;
  ctx->errmsg[0] = '\0';
}

void tt_context_set_log(tt_context *ctx, tt_log_fn fn, void *user)
{
  if (!ctx)
    return;
  ctx->log_fn = fn;
  ctx->log_user = user;
}

size_t tt_context_warning_count(const tt_context *ctx)
{
  return ctx ? ctx->warnings : 0;
}

const char *tt_text_fit(char *buf, size_t size, const char *text)
{
  const size_t keep = (TT_TEXT_WORD_MAX - 3) / 2; /* each side of "..." */
  size_t o = 0;
  if (!buf || !size)
    return buf;
  for (const char *p = text ? text : ""; *p && o + 1 < size;) {
    size_t word = strcspn(p, " \t");
    if (word == 0) {
      buf[o++] = *p++;
      continue;
    }
    const char *parts[3] = {p, "...", p + word - keep};
    size_t lens[3] = {word, 0, 0};
    if (word > TT_TEXT_WORD_MAX) {
      lens[0] = keep;
      lens[1] = 3;
      lens[2] = keep;
    }
    for (int k = 0; k < 3; k++)
      for (size_t i = 0; i < lens[k] && o + 1 < size; i++)
        buf[o++] = parts[k][i];
    p += word;
  }
  buf[o] = '\0';
  return buf;
}

/* Formats into buf; when the text would not fit, formats it whole on the
 * heap and lets tt_text_fit shorten its long words, so the end of the
 * message (the cause, after the name) survives. */
static void vformat_fit(char *buf, size_t size, const char *fmt, va_list ap)
{
  va_list ap2;
  va_copy(ap2, ap);
  int n = vsnprintf(buf, size, fmt, ap);
  if (n >= 0 && (size_t)n >= size) {
    char *whole = malloc((size_t)n + 1);
    if (whole) {
      vsnprintf(whole, (size_t)n + 1, fmt, ap2);
      tt_text_fit(buf, size, whole);
      free(whole);
    }
  }
  va_end(ap2);
}

tt_status tt__error(tt_context *ctx, tt_status status, const char *fmt, ...)
{
  if (!ctx)
    return status;
  ctx->last_status = status;
  va_list ap;
  va_start(ap, fmt);
  vformat_fit(ctx->errmsg, sizeof ctx->errmsg, fmt, ap);
  va_end(ap);
  return status;
}

void tt__warn(tt_context *ctx, const char *fmt, ...)
{
  if (!ctx)
    return;
  ctx->warnings++;
  if (!ctx->log_fn)
    return;
  char buf[TT_ERRMSG_MAX];
  va_list ap;
  va_start(ap, fmt);
  vformat_fit(buf, sizeof buf, fmt, ap);
  va_end(ap);
  ctx->log_fn(ctx->log_user, buf);
}

bool tt__grow(void **ptr, size_t *cap, size_t need, size_t elem)
{
  if (need <= *cap)
    return true;
  size_t ncap = *cap < 16 ? 16 : *cap + *cap / 2;
  if (ncap < need)
    ncap = need;
  if (ncap > SIZE_MAX / elem)
    return false;
  void *p = realloc(*ptr, ncap * elem);
  if (!p)
    return false;
  *ptr = p;
  *cap = ncap;
  return true;
}

bool tt__name_equal(const char *a, const char *b)
{
  for (;; a++, b++) {
    char ca = *a, cb = *b;
    if (ca >= 'A' && ca <= 'Z')
      ca = (char)(ca - 'A' + 'a');
    if (cb >= 'A' && cb <= 'Z')
      cb = (char)(cb - 'A' + 'a');
    if (ca == '-')
      ca = '_';
    if (cb == '-')
      cb = '_';
    if (ca != cb)
      return false;
    if (ca == '\0')
      return true;
  }
}

double tt__now(void)
{
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}
