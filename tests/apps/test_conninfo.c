/*
 * test_conninfo.c -- unit tests of apps/core/conninfo.c: the password of a
 * PostgreSQL connection string masked in every form libpq reads (keyword/
 * value with blanks around '=', quoted values with \' and \\, the URI's
 * user:pw@ and ?password=, each with and without GDAL's "PG:"), checked
 * against libpq's own parser: the shown string parses to the same options
 * with the password "***", and holds no piece of the password. Also: names
 * without a password unchanged, a password libpq cannot parse cut out
 * (-1), passwords of 1 and 2 characters into every buffer size from 0 up
 * (the old mask wrote past the end), GDAL's own keywords kept, and
 * tt_app_mask_words over a message.
 */
#include "terratin_lib.h"
#include "tt_test.h"

#include <libpq-fe.h>

/* The value of key in the parse of s (a copy, "" if absent; NULL if s does
 * not parse). GDAL's own keywords are dropped first, as GDAL does. */
static int parse_val(const char *s, const char *key, char *out, size_t size)
{
  char body[1024];
  snprintf(body, sizeof body, "%s", strncmp(s, "PG:", 3) == 0 ? s + 3 : s);
  char *a = strstr(body, " active_schema=");
  if (a)
    *a = '\0';
  char *err = NULL;
  PQconninfoOption *o = PQconninfoParse(body, &err);
  PQfreemem(err);
  if (!o)
    return 0;
  out[0] = '\0';
  for (PQconninfoOption *p = o; p->keyword; p++)
    if (strcmp(p->keyword, key) == 0 && p->val)
      snprintf(out, size, "%s", p->val);
  PQconninfoFree(o);
  return 1;
}

/* name masks to a string that libpq reads as name with password "***",
 * in which no 3-character piece of the password appears. */
static void check_masked(const char *name, const char *password)
{
  char shown[1024];
  int m = tt_app_mask_password(name, shown, sizeof shown);
  if (m != 1)
    TT_FAIL_("%s: mask returned %d, expected 1 (shown %s)", name, m, shown);
  /* the passwords tested have no 3-character piece in the rest */
  size_t n = strlen(password);
  for (size_t i = 0; i + 3 <= n; i++) {
    char piece[4] = {password[i], password[i + 1], password[i + 2], 0};
    if (strstr(shown, piece))
      TT_FAIL_("%s: shown \"%s\" holds \"%s\" of the password", name,
               shown, piece);
  }
  CHECK(strstr(shown, "***") != NULL);
  CHECK_INT_EQ(strncmp(name, "PG:", 3) == 0, strncmp(shown, "PG:", 3) == 0);
  static const char *const keys[] = {"user", "password", "host", "port",
                                     "dbname", "sslmode", "application_name"};
  for (size_t k = 0; k < sizeof keys / sizeof keys[0]; k++) {
    char a[256], b[256];
    if (!parse_val(name, keys[k], a, sizeof a) ||
        !parse_val(shown, keys[k], b, sizeof b)) {
      TT_FAIL_("%s: shown \"%s\" does not parse", name, shown);
      return;
    }
    const char *want = strcmp(keys[k], "password") == 0 ? "***" : a;
    if (strcmp(want, b) != 0)
      TT_FAIL_("%s -> %s: %s is \"%s\", expected \"%s\"", name, shown,
               keys[k], b, want);
  }
}

static void check_unchanged(const char *name)
{
  char shown[1024];
  CHECK_INT_EQ(tt_app_mask_password(name, shown, sizeof shown), 0);
  if (strcmp(shown, name) != 0)
    TT_FAIL_("\"%s\" shown as \"%s\"", name, shown);
}

static void test_forms(void)
{
  check_masked("PG:dbname=gis password=s3cretpw", "s3cretpw");
  check_masked("dbname=gis password=s3cretpw host=h", "s3cretpw");
  check_masked("PG:dbname=gis password = s3cretpw port=5999", "s3cretpw");
  check_masked("PG:dbname=gis password=\ts3cretpw", "s3cretpw");
  check_masked("PG:dbname=gis password='pa\\'ss x' user=me", "pa'ss x");
  check_masked("PG:dbname=gis password='back\\\\slash' user=me",
               "back\\slash");
  check_masked("PG:password='' dbname=gis", "");
  check_masked("postgresql://user:s3cretpw@localhost:5999/db", "s3cretpw");
  check_masked("PG:postgresql://user:s3cretpw@localhost:5999/db", "s3cretpw");
  check_masked("postgres://user:s3cretpw@localhost/db?sslmode=disable",
               "s3cretpw");
  check_masked("postgresql://us%20er:s3c%40ret@[::1]:5999/d%2Fb", "s3c@ret");
  check_masked("postgresql://localhost/db?password=s3cretpw&user=me",
               "s3cretpw");
  check_masked("postgresql://localhost/db?password=s3cretpw", "s3cretpw");
  check_masked("postgresql://u:s3cretpw@h1:5432,h2:5433/db", "s3cretpw");
  check_masked("postgresql://u:s3cretpw@%2Fvar%2Frun/db", "s3cretpw");
  check_masked("PG:dbname=gis password=ab", "ab");
  check_masked("PG:dbname=gis password=a", "a");
  /* the order the keywords were written in is kept */
  char shown[1024];
  tt_app_mask_password("PG:dbname=gis host=h password=pw user=me", shown,
                       sizeof shown);
  if (strcmp(shown, "PG:dbname=gis host=h password=*** user=me") != 0)
    TT_FAIL_("shown \"%s\"", shown);
  tt_app_mask_password("PG:postgresql://me:pw@h:5999/gis", shown,
                       sizeof shown);
  if (strcmp(shown, "PG:postgresql://me:***@h:5999/gis") != 0)
    TT_FAIL_("shown \"%s\"", shown);
  /* GDAL's own keywords, unknown to libpq, are kept as written */
  tt_app_mask_password("PG:dbname=gis active_schema=tin password=pw", shown,
                       sizeof shown);
  if (strcmp(shown, "PG:dbname=gis password=*** active_schema=tin") != 0)
    TT_FAIL_("shown \"%s\"", shown);
}

static void test_unchanged(void)
{
  check_unchanged("dem.tif");
  check_unchanged("/data/passwords/out.gpkg");
  check_unchanged("PG:dbname=gis");
  check_unchanged("PG:dbname=gis active_schema=tin");
  check_unchanged("postgresql://me@localhost/gis");
  check_unchanged("PG:service=mine");
  check_unchanged("");
}

/* A password libpq cannot parse: -1, cut where its value starts. */
static void test_unparsed(void)
{
  static const struct {
    const char *name, *shown, *piece;
  } cases[] = {
      /* '' is no escape for libpq: the value ends at the second quote */
      {"PG:dbname=db password='pa''ss x'", "PG:dbname=db password=***",
       "ss x"},
      {"PG:dbname=db password='unterminated", "PG:dbname=db password=***",
       "unterm"},
      {"PG:dbname=db PASSWORD=zz", "PG:dbname=db PASSWORD=***", "zz"},
      {"postgresql://u:s3cretpw@h/db?nosuch=1", "postgresql://***", "s3cr"},
  };
  for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
    char shown[1024];
    CHECK_INT_EQ(tt_app_mask_password(cases[i].name, shown, sizeof shown), -1);
    if (strcmp(shown, cases[i].shown) != 0)
      TT_FAIL_("%s: shown \"%s\", expected \"%s\"", cases[i].name, shown,
               cases[i].shown);
    if (strstr(shown, cases[i].piece))
      TT_FAIL_("%s: shown \"%s\" holds \"%s\"", cases[i].name, shown,
               cases[i].piece);
  }
}

/* Every buffer size: NUL-terminated inside it, nothing written past it,
 * never a piece of the password (the old mask grew "pw=a" to "pw=***"
 * past the end of a buffer sized for the name). */
static void test_small_buffers(void)
{
  static const char *const names[] = {
      "PG:password=a", "PG:password=ab", "password=a", "PG:password=ab x=1",
      "postgresql://u:a@h/d", "PG:dbname=db password='pa''ss x'"};
  for (size_t k = 0; k < sizeof names / sizeof names[0]; k++) {
    size_t len = strlen(names[k]);
    for (size_t size = 0; size <= len + 8; size++) {
      char buf[64];
      memset(buf, '#', sizeof buf);
      tt_app_mask_password(names[k], buf, size);
      for (size_t i = size; i < sizeof buf; i++)
        if (buf[i] != '#') {
          TT_FAIL_("%s: size %zu: byte %zu written", names[k], size, i);
          break;
        }
      if (size && memchr(buf, '\0', size) == NULL)
        TT_FAIL_("%s: size %zu: not NUL-terminated", names[k], size);
      if (size && (strstr(buf, "=a") || strstr(buf, "=ab") ||
                   strstr(buf, ":a@") || strstr(buf, "ss x")))
        TT_FAIL_("%s: size %zu: shown \"%s\"", names[k], size, buf);
    }
  }
}

static void test_mask_words(void)
{
  char *words[] = {"simplify", "dem.tif",
                   "PG:dbname=gis password=s3cretpw host=h", NULL};
  char text[TT_APP_MESSAGE_MAX];
  snprintf(text, sizeof text, "PG:dbname=gis password=s3cretpw host=h: "
           "cannot open; dbname=gis password=s3cretpw host=h again");
  tt_app_mask_words(words, text, sizeof text);
  const char *want = "PG:dbname=gis password=*** host=h: cannot open; "
                     "dbname=gis password=*** host=h again";
  if (strcmp(text, want) != 0)
    TT_FAIL_("masked \"%s\", expected \"%s\"", text, want);
  /* the password alone, however a message came by it */
  snprintf(text, sizeof text, "auth failed for s3cretpw");
  tt_app_mask_words(words, text, sizeof text);
  if (strstr(text, "s3cretpw"))
    TT_FAIL_("masked \"%s\"", text);
  /* no word with a password: the text is untouched */
  char *plain[] = {"simplify", "dem.tif", "out.gpkg", NULL};
  snprintf(text, sizeof text, "out.gpkg: exists");
  tt_app_mask_words(plain, text, sizeof text);
  CHECK(strcmp(text, "out.gpkg: exists") == 0);
}

int main(void)
{
  test_forms();
  test_unchanged();
  test_unparsed();
  test_small_buffers();
  test_mask_words();
  if (tt_test_failures)
    fprintf(stderr, "%d failure(s)\n", tt_test_failures);
  return tt_test_failures ? 1 : 0;
}
