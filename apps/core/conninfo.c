/*
 * conninfo.c -- apps/core/: the command's core, what every command's folder
 * shares. This file: PostgreSQL connection strings kept out of everything
 * terratin prints or stores. A datasource name in libpq's keyword/value
 * form ("dbname=gis password = pw", "password='pa\'ss x'") or its URI form
 * ("postgresql://user:pw@host/db", "...?password=pw"), either behind GDAL's
 * "PG:" prefix, may carry a password; the one-line failure, warnings, debug
 * lines, the summary, -json, run_parameters and the interruption line show
 * it with the password replaced by "***".
 *
 * The string is read by libpq's own parser (PQconninfoParse), so what is
 * hidden is exactly what libpq would send whatever the quoting, spacing or
 * form, and the shown string is rebuilt from the parsed values, never cut
 * out of the typed one: no character of the password can survive. GDAL's
 * own keywords (active_schema, schemas, tables), which libpq does not know,
 * are set apart first, as GDAL does, and shown as typed. A string that
 * holds a password but that libpq cannot parse is shown up to where the
 * password starts, then "***"; a run refuses it before connecting, since
 * libpq's error would quote the words it could not read.
 *
 * A run keeps its datasource names with their shown forms (app_secrets)
 * and replaces every occurrence of a name in the text it prints, so a
 * driver's message that echoes the name is masked too. Workload: a few
 * names, a few messages a run.
 */
#include "app.h"

#include <libpq-fe.h>

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

/* ===========================================================================
 * Bounded string building: the output is cut, never overrun.
 * ========================================================================= */

typedef struct text_buf {
  char *p;
  size_t size, n;
} text_buf;

static void tb_init(text_buf *b, char *p, size_t size)
{
  b->p = p;
  b->size = size;
  b->n = 0;
  if (size)
    p[0] = '\0';
}

static void tb_putn(text_buf *b, const char *s, size_t len)
{
  if (b->size == 0)
    return;
  size_t room = b->size - 1 - b->n;
  if (len > room)
    len = room;
  memcpy(b->p + b->n, s, len);
  b->n += len;
  b->p[b->n] = '\0';
}

static void tb_put(text_buf *b, const char *s)
{
  tb_putn(b, s, strlen(s));
}

/* ===========================================================================
 * Recognising a connection string
 * ========================================================================= */

static int has_prefix_ci(const char *s, const char *prefix)
{
  return strncasecmp(s, prefix, strlen(prefix)) == 0;
}

/* The first occurrence of word in s, in any case, else NULL. */
static char *find_ci(const char *s, const char *word)
{
  size_t n = strlen(word);
  for (; *s; s++)
    if (strncasecmp(s, word, n) == 0)
      return (char *)s;
  return NULL;
}

static int is_uri(const char *s)
{
  return strncmp(s, "postgresql://", 13) == 0 ||
         strncmp(s, "postgres://", 11) == 0;
}

/* Where "password" (any case) followed by optional blanks and '=' starts
 * in s, else NULL; *out_value (if not NULL) is where its value starts. */
static const char *password_key(const char *s, const char **out_value)
{
  for (const char *p = s; (p = find_ci(p, "password")) != NULL; p++) {
    const char *e = p + 8;
    while (*e == ' ' || *e == '\t' || *e == '\n' || *e == '\r')
      e++;
    if (*e == '=') {
      if (out_value)
        *out_value = e + 1;
      return p;
    }
  }
  return NULL;
}

/* Where a URI's user information ("user:pw@") starts, when it holds a
 * password, else NULL. */
static const char *uri_userinfo_password(const char *body)
{
  if (!is_uri(body))
    return NULL;
  const char *a = strstr(body, "://") + 3;
  size_t alen = strcspn(a, "/?");
  const char *at = memchr(a, '@', alen);
  if (!at)
    return NULL;
  return memchr(a, ':', (size_t)(at - a)) ? a : NULL;
}

/* The length of a keyword/value value as typed at v: a quoted one up to
 * its closing quote (\' and \\ inside), else up to the next blank. */
static size_t typed_value_len(const char *v)
{
  const char *e = v;
  if (*e == '\'') {
    for (e++; *e && *e != '\''; e++)
      if (*e == '\\' && e[1])
        e++;
    return (size_t)(e - v) + (*e ? 1 : 0);
  }
  while (*e && *e != ' ' && *e != '\t' && *e != '\n' && *e != '\r')
    e++;
  return (size_t)(e - v);
}

static const char *skip_blanks(const char *s)
{
  while (*s == ' ' || *s == '\t' || *s == '\n' || *s == '\r')
    s++;
  return s;
}

/* Whether name is, or may be, a PostgreSQL connection string. */
static int looks_like_conninfo(const char *name)
{
  return has_prefix_ci(name, "PG:") || is_uri(name) || password_key(name, NULL);
}

/* ===========================================================================
 * Rebuilding a parsed connection string
 * ========================================================================= */

/* A keyword/value value, quoted as libpq reads it when it must be. */
static void put_value(text_buf *b, const char *v)
{
  int quote = *v == '\0' || strpbrk(v, " \t\n\r\f\v'\\") != NULL;
  if (!quote) {
    tb_put(b, v);
    return;
  }
  tb_put(b, "'");
  for (; *v; v++) {
    if (*v == '\'' || *v == '\\')
      tb_put(b, "\\");
    tb_putn(b, v, 1);
  }
  tb_put(b, "'");
}

/* Where keyword key first appears in body as "key =" (blanks allowed),
 * else SIZE_MAX: the order the user wrote the keywords in. A value that
 * holds such a text only moves a keyword in the rebuilt string. */
static size_t keyword_pos(const char *body, const char *key)
{
  size_t n = strlen(key);
  for (const char *p = body; (p = strstr(p, key)) != NULL; p++) {
    if (p != body && p[-1] != ' ' && p[-1] != '\t' && p[-1] != '\n')
      continue;
    const char *e = p + n;
    while (*e == ' ' || *e == '\t' || *e == '\n' || *e == '\r')
      e++;
    if (*e == '=')
      return (size_t)(p - body);
  }
  return SIZE_MAX;
}

/* The keyword/value form, keywords in the order they were written. */
static void put_keywords(text_buf *b, const char *body,
                         const PQconninfoOption *opts)
{
  enum { MAX_KEYS = 64 };
  const PQconninfoOption *given[MAX_KEYS];
  size_t pos[MAX_KEYS], n = 0;
  for (const PQconninfoOption *o = opts; o->keyword && n < MAX_KEYS; o++)
    if (o->val) {
      /* insertion sort on the position, stable for equal ones */
      size_t at = keyword_pos(body, o->keyword), i = n++;
      for (; i > 0 && pos[i - 1] > at; i--) {
        given[i] = given[i - 1];
        pos[i] = pos[i - 1];
      }
      given[i] = o;
      pos[i] = at;
    }
  for (size_t i = 0; i < n; i++) {
    if (i)
      tb_put(b, " ");
    tb_put(b, given[i]->keyword);
    tb_put(b, "=");
    if (strcmp(given[i]->keyword, "password") == 0)
      tb_put(b, "***");
    else
      put_value(b, given[i]->val);
  }
}

/* RFC 3986 percent-encoding of everything but the unreserved characters. */
static void put_pct(text_buf *b, const char *v)
{
  static const char hex[] = "0123456789ABCDEF";
  for (; *v; v++) {
    unsigned char c = (unsigned char)*v;
    if ((c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') ||
        (c >= '0' && c <= '9') || c == '-' || c == '.' || c == '_' ||
        c == '~') {
      tb_putn(b, v, 1);
    } else {
      char e[3] = {'%', hex[c >> 4], hex[c & 15]};
      tb_putn(b, e, 3);
    }
  }
}

static const char *opt_val(const PQconninfoOption *opts, const char *key)
{
  for (const PQconninfoOption *o = opts; o->keyword; o++)
    if (strcmp(o->keyword, key) == 0)
      return o->val;
  return NULL;
}

/* The URI form: scheme://[user:***@][host][:port][/dbname][?k=v&...]. A
 * host list, a socket folder or an IPv6 address goes in the query
 * (host=...), which libpq reads the same. */
static void put_uri(text_buf *b, const char *scheme, size_t scheme_len,
                    const PQconninfoOption *opts)
{
  const char *user = opt_val(opts, "user");
  const char *host = opt_val(opts, "host");
  const char *port = opt_val(opts, "port");
  const char *db = opt_val(opts, "dbname");
  int host_in_query = host && strpbrk(host, ",/:") != NULL;
  int port_in_query = port && (host_in_query || strchr(port, ','));
  tb_putn(b, scheme, scheme_len);
  if (user) {
    put_pct(b, user);
    tb_put(b, ":***@");
  }
  if (host && !host_in_query)
    put_pct(b, host);
  if (port && !port_in_query) {
    tb_put(b, ":");
    put_pct(b, port);
  }
  if (db) {
    tb_put(b, "/");
    put_pct(b, db);
  }
  char sep = '?';
  for (const PQconninfoOption *o = opts; o->keyword; o++) {
    const char *k = o->keyword;
    if (!o->val || strcmp(k, "user") == 0 || strcmp(k, "dbname") == 0 ||
        (strcmp(k, "host") == 0 && !host_in_query) ||
        (strcmp(k, "port") == 0 && !port_in_query) ||
        (strcmp(k, "password") == 0 && user))
      continue;
    tb_putn(b, &sep, 1);
    sep = '&';
    tb_put(b, k);
    tb_put(b, "=");
    if (strcmp(k, "password") == 0)
      tb_put(b, "***");
    else
      put_pct(b, o->val);
  }
}

/* GDAL's own keywords in a keyword/value string, which libpq does not
 * know: moved from body (in place) to extra, as GDAL's PostgreSQL driver
 * takes them out, each "key=value" up to the next blank. */
static void take_gdal_keys(char *body, text_buf *extra)
{
  static const char *const keys[] = {"active_schema=", "schemas=", "tables="};
  for (size_t k = 0; k < sizeof keys / sizeof keys[0]; k++) {
    size_t klen = strlen(keys[k]);
    char *p = body;
    while ((p = find_ci(p, keys[k])) != NULL) {
      if (p != body && p[-1] != ' ' && p[-1] != '\t') {
        p += klen;
        continue;
      }
      size_t len = strcspn(p, " \t");
      if (extra->n)
        tb_put(extra, " ");
      tb_putn(extra, p, len);
      memmove(p, p + len, strlen(p + len) + 1);
    }
  }
}

/* The shown form of a string libpq cannot parse: up to where the
 * password's value (or a URI's user information) starts, then "***". */
static void put_unparsed(text_buf *b, const char *name)
{
  const char *body = has_prefix_ci(name, "PG:") ? name + 3 : name;
  const char *value = NULL;
  const char *cut = password_key(name, &value) ? value : NULL;
  const char *ui = uri_userinfo_password(body);
  if (!cut || (ui && ui < cut))
    cut = ui;
  if (!cut)
    cut = body;
  tb_putn(b, name, (size_t)(cut - name));
  tb_put(b, "***");
}

int tt__app_mask_password(const char *name, char *buf, size_t size)
{
  text_buf b;
  tb_init(&b, buf, size);
  if (!name)
    return TT_APP_MASK_NONE;
  if (!looks_like_conninfo(name)) {
    tb_put(&b, name);
    return TT_APP_MASK_NONE;
  }
  size_t plen = has_prefix_ci(name, "PG:") ? 3 : 0;
  char *body = strdup(name + plen);
  char extra_buf[TT_APP_MESSAGE_MAX];
  text_buf extra;
  tb_init(&extra, extra_buf, sizeof extra_buf);
  if (!body) { /* out of memory: show nothing of it */
    tb_putn(&b, name, plen);
    tb_put(&b, "***");
    return TT_APP_MASK_UNPARSED;
  }
  int uri = is_uri(body);
  if (!uri)
    take_gdal_keys(body, &extra);
  char *err = NULL;
  PQconninfoOption *opts = PQconninfoParse(body, &err);
  PQfreemem(err); /* it may quote the words it could not read */
  int ret;
  if (!opts) {
    if (password_key(name, NULL) || uri_userinfo_password(name + plen)) {
      put_unparsed(&b, name);
      ret = TT_APP_MASK_UNPARSED;
    } else {
      tb_put(&b, name);
      ret = TT_APP_MASK_NONE;
    }
  } else if (!opt_val(opts, "password")) {
    tb_put(&b, name);
    ret = TT_APP_MASK_NONE;
  } else {
    tb_putn(&b, name, plen);
    if (uri)
      put_uri(&b, body, (size_t)(strstr(body, "://") + 3 - body), opts);
    else
      put_keywords(&b, body, opts);
    if (extra.n) {
      tb_put(&b, " ");
      tb_put(&b, extra_buf);
    }
    ret = TT_APP_MASK_DONE;
  }
  PQconninfoFree(opts);
  free(body);
  return ret;
}

/* The password libpq would read from name, into buf ("" if none or it
 * does not fit). */
static void password_of(const char *name, char *buf, size_t size)
{
  buf[0] = '\0';
  size_t plen = has_prefix_ci(name, "PG:") ? 3 : 0;
  char *body = strdup(name + plen);
  if (!body)
    return;
  char extra_buf[TT_APP_MESSAGE_MAX];
  text_buf extra;
  tb_init(&extra, extra_buf, sizeof extra_buf);
  if (!is_uri(body))
    take_gdal_keys(body, &extra);
  char *err = NULL;
  PQconninfoOption *opts = PQconninfoParse(body, &err);
  PQfreemem(err);
  const char *pw = opts ? opt_val(opts, "password") : NULL;
  if (pw && strlen(pw) < size)
    memcpy(buf, pw, strlen(pw) + 1);
  PQconninfoFree(opts);
  free(body);
}

/* ===========================================================================
 * A run's names and the text it prints
 * ========================================================================= */

int tt__app_secrets_add(app_secrets *sec, const char *name)
{
  if (!name)
    return TT_APP_MASK_NONE;
  for (size_t i = 0; i < sec->n; i++)
    if (strcmp(sec->item[i].raw, name) == 0)
      return TT_APP_MASK_DONE;
  char shown[TT_APP_MESSAGE_MAX];
  int m = tt__app_mask_password(name, shown, sizeof shown);
  if (m == TT_APP_MASK_NONE || sec->n == TT_APP_MAX_SECRETS)
    return m;
  app_secret *it = &sec->item[sec->n++];
  it->raw = name;
  memcpy(it->shown, shown, sizeof shown);
  password_of(name, it->password, sizeof it->password);
  const char *value = NULL;
  it->typed_len = !is_uri(name + (has_prefix_ci(name, "PG:") ? 3 : 0)) &&
                          password_key(name, &value)
                      ? typed_value_len(skip_blanks(value))
                      : 0;
  return m;
}

const char *tt__app_secrets_shown(const app_secrets *sec, const char *name)
{
  if (!sec || !name)
    return name;
  for (size_t i = 0; i < sec->n; i++)
    if (strcmp(sec->item[i].raw, name) == 0)
      return sec->item[i].shown;
  return name;
}

const char *tt__app_shown(const app_run *r, const char *name)
{
  return tt__app_secrets_shown(&r->msg.secrets, name);
}

/* Shortest password the last net looks for in a text: shorter ones would
 * match inside ordinary words, and "***" there would tell what they are. */
#define NET_MIN_PASSWORD 4

const char *tt__app_secrets_mask(const app_secrets *sec, const char *text,
                                 char *buf, size_t size)
{
  if (!sec || sec->n == 0 || !text)
    return text;
  size_t typed = 0;
  for (size_t i = 0; i < sec->n; i++)
    if (sec->item[i].typed_len > typed)
      typed = sec->item[i].typed_len;
  text_buf b;
  tb_init(&b, buf, size);
  const char *p = text;
  while (*p) {
    /* "password=" in a text that is not the name as given (GDAL's debug
     * lines print the name with only the value's first word masked): the
     * value, at least as long as the longest typed one, is masked. */
    if (strncasecmp(p, "password", 8) == 0 && *skip_blanks(p + 8) == '=') {
      const char *v = skip_blanks(skip_blanks(p + 8) + 1);
      if (strncmp(v, "***", 3) != 0) {
        size_t n = typed_value_len(v), left = strlen(v);
        if (n < typed)
          n = typed < left ? typed : left;
        tb_putn(&b, p, (size_t)(v - p));
        tb_put(&b, "***");
        p = v + n;
        continue;
      }
    }
    size_t best = 0;
    const char *with = NULL;
    for (size_t i = 0; i < sec->n; i++) {
      const app_secret *it = &sec->item[i];
      /* the name as given, or as a driver echoes it without "PG:" */
      const char *forms[2] = {it->raw, has_prefix_ci(it->raw, "PG:")
                                           ? it->raw + 3 : NULL};
      for (int f = 0; f < 2; f++) {
        size_t n = forms[f] ? strlen(forms[f]) : 0;
        if (n > best && strncmp(p, forms[f], n) == 0) {
          best = n;
          with = f == 0 ? it->shown
                        : it->shown + (has_prefix_ci(it->shown, "PG:") ? 3
                                                                      : 0);
        }
      }
      /* the last net: the password itself, however the text came by it */
      size_t pn = strlen(it->password);
      if (!best && pn >= NET_MIN_PASSWORD && strncmp(p, it->password, pn) == 0) {
        best = pn;
        with = "***";
      }
    }
    if (best) {
      tb_put(&b, with);
      p += best;
    } else {
      tb_putn(&b, p, 1);
      p++;
    }
  }
  return buf;
}

/* ===========================================================================
 * The public face (terratin_lib.h)
 * ========================================================================= */

int tt_app_mask_password(const char *name, char *buf, size_t size)
{
  return tt__app_mask_password(name, buf, size);
}

void tt_app_mask_words(char *const *words, char *text, size_t size)
{
  app_secrets sec;
  sec.n = 0;
  for (size_t i = 0; words && words[i]; i++)
    tt__app_secrets_add(&sec, words[i]);
  if (sec.n == 0 || size == 0)
    return;
  char buf[TT_APP_MESSAGE_MAX];
  const char *m = tt__app_secrets_mask(&sec, text, buf, sizeof buf);
  if (m != text)
    snprintf(text, size, "%s", m);
}
