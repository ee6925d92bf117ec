/*
 * run.c -- apps/core/: the command's core, what every command's folder shares.
 * This file: tt_app_run() and the commands' dispatch table (tt__app_commands,
 * which the parser and the help read too), and what every subcommand shares: the result and its
 * one-line failure, GDAL's messages while a run is active (failures stored,
 * warnings printed as "terratin: warning: ..."), the causes of a failed write,
 * choosing the output driver and the thread count (the DEM itself is opened and
 * read in dem.c).
 *
 * Invariants: a run reports at most one failure (the first; later ones are
 * consequences); GDAL never prints by itself while a run is active (a pushed
 * CPL error handler catches everything); --config options are applied
 * before any driver is registered or file opened.
 */
#include "app.h"

#include <cpl_conv.h>
#include <cpl_string.h>
#include <cpl_vsi.h>
#include <ogr_srs_api.h>

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/statvfs.h>
#include <time.h>
#include <unistd.h>

/* Seconds of a monotonic clock (the app's own; the engine keeps its own). */
double tt__app_now(void)
{
  struct timespec ts;
  if (clock_gettime(CLOCK_MONOTONIC, &ts) != 0)
    return 0.0;
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

void tt__app_result_set(tt_app_result *res, int exit_code, tt_status status,
                       const char *fmt, ...) TT_APP_PRINTF_(4, 5);

/* vsnprintf that keeps the cause: a message that would not fit is made
 * whole on the heap and its long words (100 kB names) shortened in the
 * middle by tt_text_fit, instead of being cut at the end. */
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

/* Fills a result, keeping the first failure: later ones are consequences. */
void tt__app_result_set(tt_app_result *res, int exit_code, tt_status status,
                       const char *fmt, ...)
{
  if (!res || res->exit_code != TT_APP_EXIT_OK)
    return;
  res->exit_code = exit_code;
  res->status = status;
  va_list ap;
  va_start(ap, fmt);
  vformat_fit(res->message, sizeof res->message, fmt, ap);
  va_end(ap);
  /* One line: fold any newline GDAL or a driver put into a message. */
  for (char *p = res->message; *p; p++)
    if (*p == '\n' || *p == '\r')
      *p = ' ';
}

void tt__app_result_ok(tt_app_result *res)
{
  if (!res)
    return;
  res->exit_code = TT_APP_EXIT_OK;
  res->status = TT_OK;
  res->message[0] = '\0';
}

int tt__app_str_ieq(const char *a, const char *b)
{
  return strcasecmp(a, b) == 0;
}

/* ===========================================================================
 * GDAL messages and engine warnings
 *
 * While a run is active a CPL error handler is pushed: failures are stored
 * (the run turns them into its one-line message, so the user never sees
 * GDAL's line and ours), warnings are printed as "terratin: warning: ..."
 * (at most MAX_WARNINGS, then one line saying the rest were dropped), debug
 * messages (only emitted with CPL_DEBUG on) as "terratin: debug: ...".
 * Every debug line carries that prefix, whoever emits it: a handler that
 * silences GDAL for a while (tt__app_quiet_push) still prints debug lines
 * so, the glue's CPLQuietErrorHandler passes them down to ours
 * (CPLSetCurrentErrorHandlerCatchDebug), and threads that push no handler
 * (GDAL's own, the tiled run's workers before they push theirs) meet the
 * run's process-wide handler, which prefixes their lines too.
 * ========================================================================= */

#define MAX_WARNINGS 20

static void one_line(char *s)
{
  for (; *s; s++)
    if (*s == '\n' || *s == '\r')
      *s = ' ';
}

void tt__app_warn(app_messages *m, const char *fmt, ...) TT_APP_PRINTF_(2, 3);

/* FNV-1a: a warning said once is not said again (a driver warns about a
 * creation option once per layer). */
static uint64_t text_hash(const char *s)
{
  uint64_t h = 1469598103934665603ull;
  for (; *s; s++)
    h = (h ^ (unsigned char)*s) * 1099511628211ull;
  return h;
}

void tt__app_warn(app_messages *m, const char *fmt, ...)
{
  char raw[TT_APP_MESSAGE_MAX], buf[TT_APP_MESSAGE_MAX];
  va_list ap;
  va_start(ap, fmt);
  vformat_fit(raw, sizeof raw, fmt, ap);
  va_end(ap);
  /* a connection string a driver echoed, with its password masked */
  if (tt__app_secrets_mask(&m->secrets, raw, buf, sizeof buf) == raw)
    memcpy(buf, raw, sizeof buf);
  uint64_t h = text_hash(buf);
  for (size_t i = 0; i < m->nseen; i++)
    if (m->seen[i] == h)
      return;
  if (m->nseen < sizeof m->seen / sizeof m->seen[0])
    m->seen[m->nseen++] = h;
  m->warnings++;
  if (m->warnings > MAX_WARNINGS + 1)
    return;
  if (m->warnings == MAX_WARNINGS + 1) {
    tt_app_term_progress_break(m->bar);
    fprintf(m->err, "terratin: warning: further warnings are not shown\n");
    return;
  }
  one_line(buf);
  tt_app_term_progress_break(m->bar);
  fprintf(m->err, "terratin: warning: %s\n", buf);
}

/* "terratin: debug: <msg>", the run's connection strings masked. Called
 * from any thread: reads m's secrets only (set before any thread runs). */
static void print_debug(const app_messages *m, const char *msg, int bar)
{
  char masked[TT_APP_MESSAGE_MAX];
  msg = m ? tt__app_secrets_mask(&m->secrets, msg, masked, sizeof masked)
          : msg;
  if (bar && m)
    tt_app_term_progress_break(m->bar);
  fprintf(m && m->err ? m->err : stderr, "terratin: debug: %s\n", msg);
}

/* The handler of tt__app_quiet_push: failures and warnings dropped, debug
 * lines printed. */
static void CPL_STDCALL on_gdal_quiet(CPLErr cls, CPLErrorNum num,
                                      const char *msg)
{
  (void)num;
  if (cls == CE_Debug && msg)
    print_debug(CPLGetErrorHandlerUserData(), msg, 0);
}

void tt__app_quiet_push(const app_messages *m)
{
  CPLPushErrorHandlerEx(on_gdal_quiet, (void *)m);
}

/* The process-wide handler while a run is active, for the threads that
 * push none: debug lines and warnings prefixed (not counted: the run's
 * counters belong to its own thread), failures, which the thread's caller
 * reports, as "terratin: warning: ". */
static void CPL_STDCALL on_gdal_thread_message(CPLErr cls, CPLErrorNum num,
                                               const char *msg)
{
  const app_messages *m = CPLGetErrorHandlerUserData();
  (void)num;
  if (!msg || cls == CE_None)
    return;
  if (cls == CE_Debug) {
    print_debug(m, msg, 0);
    return;
  }
  char masked[TT_APP_MESSAGE_MAX];
  msg = m ? tt__app_secrets_mask(&m->secrets, msg, masked, sizeof masked)
          : msg;
  fprintf(m && m->err ? m->err : stderr, "terratin: warning: %s\n", msg);
}

static void CPL_STDCALL on_gdal_message(CPLErr cls, CPLErrorNum num,
                                        const char *msg)
{
  app_messages *m = CPLGetErrorHandlerUserData();
  char named[TT_APP_MESSAGE_MAX], masked[TT_APP_MESSAGE_MAX];
  (void)num;
  if (!m || !msg)
    return;
  /* GDAL names the dataset it was given: the temporary name of an output;
   * the user knows it by its final name. A connection string is shown
   * with its password masked. */
  if (tt_output_rename_in_text(msg, named, sizeof named))
    msg = named;
  msg = tt__app_secrets_mask(&m->secrets, msg, masked, sizeof masked);
  if (cls == CE_Debug) {
    print_debug(m, msg, 1);
  } else if (cls == CE_Warning) {
    tt__app_warn(m, "%s", msg);
  } else if (cls != CE_None) {
    m->failures++;
    tt_text_fit(m->last, sizeof m->last, msg);
    one_line(m->last);
  }
}

static void on_engine_warning(void *user, const char *message)
{
  tt__app_warn(user, "%s", message);
}

/* ===========================================================================
 * A run: what every subcommand shares
 * ========================================================================= */

tt_status tt__app_fail(app_run *r, int exit_code, tt_status st,
                          const char *file, const char *fmt, ...)
    TT_APP_PRINTF_(5, 6);

/* Records the run's failure "<file>: <problem>" (or "<problem>"), with
 * the password of any connection string in it masked. */
tt_status tt__app_fail(app_run *r, int exit_code, tt_status st,
                          const char *file, const char *fmt, ...)
{
  char buf[TT_APP_MESSAGE_MAX], name[TT_TEXT_WORD_MAX + 1];
  char named[TT_APP_MESSAGE_MAX], masked[TT_APP_MESSAGE_MAX];
  char masked_file[TT_APP_MESSAGE_MAX];
  va_list ap;
  va_start(ap, fmt);
  vformat_fit(buf, sizeof buf, fmt, ap);
  va_end(ap);
  /* a driver's message kept by the glue may name a temporary file */
  if (tt_output_rename_in_text(buf, named, sizeof named))
    memcpy(buf, named, sizeof buf);
  const app_secrets *sec = &r->msg.secrets;
  const char *why = tt__app_secrets_mask(sec, buf, masked, sizeof masked);
  if (file)
    tt__app_result_set(r->res, exit_code, st, "%s: %s",
                       tt_text_fit(name, sizeof name,
                                   tt__app_secrets_mask(sec, file, masked_file,
                                                        sizeof masked_file)),
                       why);
  else
    tt__app_result_set(r->res, exit_code, st, "%s", why);
  return st;
}

/* The best one-line explanation of a failed engine or glue call: the
 * context's message, else GDAL's last failure, else the status's generic
 * message. A leading "<file>: " or "<file> " is dropped, the caller puts
 * the file first ("out.gpkg exists and is a folder" reads
 * "out.gpkg: exists and is a folder"). */
const char *tt__app_why(app_run *r, tt_status st, const char *file)
{
  const char *m = tt_context_errmsg(r->ctx);
  if (!m || !*m)
    m = r->msg.last;
  if (!m || !*m)
    m = tt_status_message(st);
  /* the file as it was named, or shortened as tt_text_fit does it */
  char fit[TT_TEXT_WORD_MAX + 1];
  for (int pass = 0; pass < 2 && file; pass++) {
    const char *f = pass ? tt_text_fit(fit, sizeof fit, file) : file;
    size_t n = strlen(f);
    if (n && strncmp(m, f, n) == 0 && m[n] == ':' && m[n + 1] == ' ')
      return m + n + 2;
    if (n && strncmp(m, f, n) == 0 && m[n] == ' ' && m[n + 1])
      return m + n + 1;
  }
  return m;
}

/* Fails with the glue's or engine's message about file. */
tt_status tt__app_fail_tt(app_run *r, tt_status st, const char *file)
{
  if (st == TT_ERR_INTERRUPTED)
    return tt__app_fail(r, TT_APP_EXIT_FAILURE, st, file,
                    "interrupted; nothing written");
  if (st == TT_ERR_NOMEM) {
    /* the engine's and glue's messages name the phase and the size */
    const char *m = tt_context_errmsg(r->ctx);
    return tt__app_fail(r, TT_APP_EXIT_FAILURE, st, file, "%s",
                        m && strstr(m, "memory") ? tt__app_why(r, st, file)
                                                 : "out of memory");
  }
  return tt__app_fail(r, TT_APP_EXIT_FAILURE, st, file, "%s",
                      tt__app_why(r, st, file));
}

/* Why a write failed when the cause is the device rather than the data:
 * the folder's file system (almost) full, or the file size limit (ulimit
 * -f) reached by the file being written. SQLite and the drivers report
 * these as whatever failed next ("no such table: gpkg_contents", "disk I/O
 * error"). Writes the cause to buf and returns 1, else 0. */
static int device_cause(const char *written, char *buf, size_t size)
{
  char folder[4096];
  snprintf(folder, sizeof folder, "%s", written);
  char *slash = strrchr(folder, '/');
  if (slash)
    *(slash == folder ? slash + 1 : slash) = '\0';
  else
    snprintf(folder, sizeof folder, ".");
  struct rlimit rl;
  struct stat st;
  if (getrlimit(RLIMIT_FSIZE, &rl) == 0 && rl.rlim_cur != RLIM_INFINITY &&
      stat(written, &st) == 0 && (uint64_t)st.st_size + 65536 >=
                                     (uint64_t)rl.rlim_cur) {
    snprintf(buf, size, "the file size limit (ulimit -f) of %llu bytes was "
             "reached", (unsigned long long)rl.rlim_cur);
    return 1;
  }
  struct statvfs vfs;
  if (statvfs(folder, &vfs) == 0) {
    uint64_t avail = (uint64_t)vfs.f_bavail * vfs.f_frsize;
    if (avail < ((uint64_t)1 << 20) || (vfs.f_favail == 0 && vfs.f_files)) {
      char fit[TT_TEXT_WORD_MAX + 1];
      snprintf(buf, size, "no space left on the device of %s (%llu bytes "
               "free%s)", tt_text_fit(fit, sizeof fit, folder),
               (unsigned long long)avail,
               vfs.f_favail == 0 && vfs.f_files ? ", no free inode" : "");
      return 1;
    }
  }
  return 0;
}

tt_status tt__app_fail_write(app_run *r, tt_status st, const char *output,
                             const char *written, const char *what)
{
  char cause[512];
  /* with `what`, the failure is GDAL's own (a close): its last message */
  const char *detail = what ? r->msg.last : tt__app_why(r, st, output);
  if (st != TT_ERR_INTERRUPTED && st != TT_ERR_NOMEM && written &&
      device_cause(written, cause, sizeof cause))
    return tt__app_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_IO, output,
                        "%s%s%s (the driver said: %s)", what ? what : "",
                        what ? ": " : "", cause, detail);
  if (what)
    return tt__app_fail(r, TT_APP_EXIT_FAILURE, st, output, "%s: %s", what,
                        detail);
  return tt__app_fail_tt(r, st, output);
}

/* An output refused because something exists: name the file that is in
 * the way (for a shapefile, one of the layer files), and the way out. */
tt_status tt__app_fail_exists(app_run *r, const char *output)
{
  static const char tail[] = " exists; not overwriting it without permission";
  const char *m = tt_context_errmsg(r->ctx);
  size_t n = m ? strlen(m) : 0, t = sizeof tail - 1;
  if (n > t && strcmp(m + n - t, tail) == 0)
    return tt__app_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_EXISTS, NULL,
                    "%.*s: exists; use -overwrite to replace it",
                    (int)(n - t), m);
  if (m && *m)
    return tt__app_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_EXISTS, output, "%s",
                    tt__app_why(r, TT_ERR_EXISTS, output));
  return tt__app_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_EXISTS, output,
                  "exists; use -overwrite to replace it");
}

/* Polls the progress callback outside the phases that report progress, so
 * an interruption is seen between steps too. */
int tt__app_continue(app_run *r, double at)
{
  if (!r->o->progress)
    return 1;
  return r->o->progress(at, NULL, r->o->progress_arg);
}

static void apply_config(const tt_app_settings *s)
{
  for (size_t i = 0; s->config[i] && s->config[i + 1]; i += 2)
    CPLSetConfigOption(s->config[i], s->config[i + 1]);
}

const char *tt__app_unit_or(const tt_raster_info *info, const char *dflt)
{
  return info && info->z_unit && *info->z_unit ? info->z_unit : dflt;
}

const char *tt__app_z_unit_why(const tt_raster_info *info)
{
  const char *why = info ? info->z_unit_why : NULL;
  if (!why || !*why)
    return "";
  return strcmp(why, "asked") == 0 ? "asked by -z_to m" : why;
}

const char *tt__app_z_unit_source(const tt_raster_info *info)
{
  const char *src = info && info->z_unit_source ? info->z_unit_source : "";
  return strcmp(src, "given") == 0 ? "-z_unit" : src;
}

const char *tt__app_nonempty_or_null(const char *s)
{
  return s && *s ? s : NULL;
}

/* "2026-11-22T10:38:55Z" */
void tt__app_iso8601_utc(char *buf, size_t size)
{
  time_t now = time(NULL);
  struct tm tm;
  if (!gmtime_r(&now, &tm) ||
      strftime(buf, size, "%Y-%m-%dT%H:%M:%SZ", &tm) == 0)
    snprintf(buf, size, "unknown");
}

static int driver_can_create_vector(GDALDriverH drv)
{
  return GDALGetMetadataItem(drv, GDAL_DCAP_VECTOR, NULL) &&
         GDALGetMetadataItem(drv, GDAL_DCAP_CREATE, NULL);
}

/* Whether the space-separated list holds ext (case-insensitive). */
static int ext_in_list(const char *list, const char *ext)
{
  size_t n = strlen(ext);
  const char *p = list;
  while (p && *p) {
    while (*p == ' ')
      p++;
    const char *e = strchr(p, ' ');
    size_t len = e ? (size_t)(e - p) : strlen(p);
    if (len == n && strncasecmp(p, ext, n) == 0)
      return 1;
    p = e;
  }
  return 0;
}

/* Drivers whose datasets tt_output cannot keep safe: they write no file
 * (Memory, database connections), or they put each further layer in a file
 * of its own beside OUTPUT (CSV), outside the temporary name, where it could
 * replace a file without -overwrite and survive a failure. */
static int refuse_driver(app_run *r, GDALDriverH drv)
{
  const char *name = GDALGetDriverShortName(drv);
  if (!GDALGetMetadataItem(drv, GDAL_DMD_EXTENSIONS, NULL) &&
      !GDALGetMetadataItem(drv, GDAL_DMD_EXTENSION, NULL)) {
    tt__app_fail(r, TT_APP_EXIT_USAGE, TT_ERR_ARG, NULL,
             "simplify: -of '%s': the driver does not write files", name);
    return 1;
  }
  if (tt__app_str_ieq(name, "CSV")) {
    tt__app_fail(r, TT_APP_EXIT_USAGE, TT_ERR_ARG, NULL,
             "simplify: -of CSV writes each layer to a file of its own "
             "beside OUTPUT, which cannot be written safely; use GPKG, "
             "SQLite or \"ESRI Shapefile\"");
    return 1;
  }
  return 0;
}

/* The output driver: -of, else the first vector driver that can create and
 * claims OUTPUT's extension (GPKG and ESRI Shapefile first), else GPKG. */
GDALDriverH tt__app_output_driver(app_run *r)
{
  const char *of = r->s->format;
  if (of) {
    GDALDriverH drv = GDALGetDriverByName(of);
    if (!drv) {
      tt__app_fail(r, TT_APP_EXIT_USAGE, TT_ERR_ARG, NULL,
               "simplify: -of '%s': no such GDAL driver (see 'ogrinfo "
               "--formats')", of);
      return NULL;
    }
    if (!driver_can_create_vector(drv)) {
      tt__app_fail(r, TT_APP_EXIT_USAGE, TT_ERR_ARG, NULL,
               "simplify: -of '%s': the driver cannot create vector "
               "datasets", of);
      return NULL;
    }
    return refuse_driver(r, drv) ? NULL : drv;
  }
  char ext[32] = "";
  const char *base = strrchr(r->s->output, '/');
  base = base ? base + 1 : r->s->output;
  const char *dot = strrchr(base, '.');
  if (dot && dot[1] && strlen(dot + 1) < sizeof ext)
    snprintf(ext, sizeof ext, "%s", dot + 1);
  if (ext[0]) {
    static const char *const preferred[] = {"GPKG", "ESRI Shapefile"};
    for (size_t i = 0; i < 2; i++) {
      GDALDriverH drv = GDALGetDriverByName(preferred[i]);
      if (drv && driver_can_create_vector(drv) &&
          ext_in_list(GDALGetMetadataItem(drv, GDAL_DMD_EXTENSIONS, NULL),
                      ext))
        return drv;
    }
    for (int i = 0; i < GDALGetDriverCount(); i++) {
      GDALDriverH drv = GDALGetDriver(i);
      if (!driver_can_create_vector(drv))
        continue;
      const char *exts = GDALGetMetadataItem(drv, GDAL_DMD_EXTENSIONS, NULL);
      if (!exts)
        exts = GDALGetMetadataItem(drv, GDAL_DMD_EXTENSION, NULL);
      if (exts && ext_in_list(exts, ext))
        return refuse_driver(r, drv) ? NULL : drv;
    }
  }
  GDALDriverH drv = GDALGetDriverByName("GPKG");
  if (!drv || !driver_can_create_vector(drv)) {
    tt__app_fail(r, TT_APP_EXIT_FAILURE, TT_ERR_FORMAT, NULL,
             "simplify: this GDAL has no GPKG driver; choose one with -of");
    return NULL;
  }
  if (ext[0])
    tt__app_warn(&r->msg, "%s: no vector driver claims the extension '.%s'; "
                  "writing a GeoPackage (use -of to choose)",
         r->s->output, ext);
  return drv;
}

static int online_cpus(void)
{
  long n = sysconf(_SC_NPROCESSORS_ONLN);
  return n < 1 ? 1 : n > TT_APP_MAX_THREADS ? TT_APP_MAX_THREADS : (int)n;
}

int tt__app_threads(app_run *r)
{
  if (r->s->threads > 0)
    return r->s->threads;
  if (r->s->threads < 0)
    return online_cpus();
  const char *v = CPLGetConfigOption("GDAL_NUM_THREADS", NULL);
  if (!v || !*v)
    return 0;
  if (tt__app_str_ieq(v, "ALL_CPUS"))
    return online_cpus();
  char *end = NULL;
  errno = 0;
  long n = strtol(v, &end, 10);
  if (end != v && *end == '\0' && errno == 0 && n >= 1 &&
      n <= TT_APP_MAX_THREADS && v[0] >= '0' && v[0] <= '9')
    return (int)n;
  tt__app_warn(&r->msg, "GDAL_NUM_THREADS='%s' is neither a number of "
               "threads from 1 to %d nor ALL_CPUS; ignored", v,
               TT_APP_MAX_THREADS);
  return 0;
}

/* Whether two paths name the same existing file. */
int tt__app_same_file(const char *a, const char *b)
{
  struct stat sa, sb;
  return stat(a, &sa) == 0 && stat(b, &sb) == 0 && sa.st_dev == sb.st_dev &&
         sa.st_ino == sb.st_ino;
}

/* ===========================================================================
 * Running
 * ========================================================================= */

static void print_version(FILE *out)
{
  int maj = 0, min = 0, pat = 0;
  OSRGetPROJVersion(&maj, &min, &pat);
  fprintf(out, "terratin %s (%s; PROJ %d.%d.%d)\n", tt_version(),
          GDALVersionInfo("--version"), maj, min, pat);
}

/* A tt_log_fn: "terratin: removed stale temporary ... (left by a killed
 * run)", a note rather than a warning (nothing is wrong with this run). */
static void on_stale_note(void *user, const char *message)
{
  app_messages *m = user;
  char masked[TT_APP_MESSAGE_MAX];
  tt_app_term_progress_break(m->bar);
  fprintf(m->err, "terratin: %s\n",
          tt__app_secrets_mask(&m->secrets, message, masked, sizeof masked));
}

/* The temporaries that killed runs left in the folder of the file this run
 * writes (output_owner.c): removed before the run adds its own. Names that
 * are no local file (a connection string, a /vsi path, DRIVER:...) have no
 * folder to look in. */
static void remove_stale(app_run *r)
{
  const tt_app_settings *s = r->s;
  const char *out = NULL;
  switch (s->command) {
  case TT_APP_SIMPLIFY:
  case TT_APP_GENERATE:
  case TT_APP_OPTIMIZE:
  case TT_APP_RASTERIZE: out = s->output; break;
  case TT_APP_EVAL: out = s->error_raster; break;
  default: break;
  }
  if (!out || strncmp(out, "/vsi", 4) == 0 ||
      strcspn(out, ":") < strcspn(out, "/") ||
      tt__app_secrets_shown(&r->msg.secrets, out) != out)
    return;
  tt_output_remove_stale(out, on_stale_note, &r->msg);
}

/* Set by `terratin tiles run` and `tiles merge` around a simplify run
 * (app.h); all zero otherwise. */
tt_app_tiles_hook tt__app_tiles_hook;

#define POS(field) offsetof(tt_app_settings, field)
#define NONE TT_APP_POS_NONE

const tt__app_command_def tt__app_commands[] = {
    {"simplify", TT_APP_SIMPLIFY, 2, {POS(input), POS(output), NONE},
     tt__app_simplify},
    {"generate", TT_APP_GENERATE, 2, {NONE, POS(output), NONE},
     tt__app_generate},
    {"eval", TT_APP_EVAL, 2, {POS(input), POS(tin), NONE}, tt__app_eval},
    {"optimize", TT_APP_OPTIMIZE, 3, {POS(input), POS(tin), POS(output)},
     tt__app_optimize},
    {"study", TT_APP_STUDY, 1, {POS(output), NONE, NONE}, tt__app_study},
    /* rasterize.c also takes the old order TIN DEM OUTPUT, with a note */
    {"rasterize", TT_APP_RASTERIZE, 3, {POS(input), POS(tin), POS(output)},
     tt__app_rasterize},
    {NULL, TT_APP_NONE, 0, {NONE, NONE, NONE}, NULL}};

const tt__app_command_def *tt__app_command_def_of(tt_app_command c)
{
  for (const tt__app_command_def *d = tt__app_commands; d->name; d++)
    if (d->command == c)
      return d;
  return NULL;
}

int tt__app_arg_number(const app_run *r, const char *path)
{
  const tt__app_command_def *d = tt__app_command_def_of(r->s->command);
  /* the setting itself first (eval a.tif a.tif: the TIN is the second),
   * then any word spelt alike */
  for (int same = 0; same < 2; same++)
    for (size_t k = 0; d && path && k < d->npos; k++) {
      if (d->pos[k] == TT_APP_POS_NONE)
        continue;
      const char *w =
          *(const char *const *)((const char *)r->s + d->pos[k]);
      if (w && (same ? strcmp(w, path) == 0 : w == path))
        return (int)k + 1;
    }
  return 0;
}

tt_status tt_app_run(const tt_app_options *o, tt_app_result *out_result)
{
  tt_app_result local;
  tt_app_result *res = out_result ? out_result : &local;
  app_run r;
  tt_status st = TT_OK;
  tt__app_result_ok(res);
  if (!o) {
    tt__app_result_set(res, TT_APP_EXIT_USAGE, TT_ERR_ARG, "no options");
    return TT_ERR_ARG;
  }
  memset(&r, 0, sizeof r);
  r.o = o;
  r.s = &o->s;
  r.res = res;
  r.out = o->out ? o->out : stdout;
  r.err = o->err ? o->err : stderr;
  r.msg.err = r.err;
  if (o->progress == tt_app_term_progress_fn)
    r.msg.bar = o->progress_arg;
  r.prog.fn = o->progress;
  r.prog.arg = o->progress_arg;
  r.t0 = tt__app_now();

  const tt__app_command_def *cmd = tt__app_command_def_of(o->s.command);
  if (o->s.command == TT_APP_HELP) {
    fputs(tt_app_help(o->s.help_topic), r.out);
    fflush(r.out);
    return TT_OK;
  }
  if (o->s.command == TT_APP_HELP_GENERAL) {
    fputs(tt__app_help_general(), r.out);
    fflush(r.out);
    return TT_OK;
  }
  if (o->s.command == TT_APP_VERSION) {
    print_version(r.out);
    fflush(r.out);
    return TT_OK;
  }
  if (!cmd && o->s.command != TT_APP_FORMATS) {
    tt__app_result_set(res, TT_APP_EXIT_USAGE, TT_ERR_ARG,
                       "missing command: simplify, generate, eval, optimize, "
                       "study, rasterize or tiles");
    return TT_ERR_ARG;
  }

  /* The names that may be connection strings carrying a password: shown
   * masked from here on. One libpq cannot parse is refused before it is
   * passed on: libpq's error would quote the words it could not read. */
  const char *names[] = {o->s.input, o->s.output, o->s.tin,
                         o->s.error_raster};
  for (size_t i = 0; i < sizeof names / sizeof names[0]; i++)
    if (tt__app_secrets_add(&r.msg.secrets, names[i]) ==
        TT_APP_MASK_UNPARSED) {
      tt__app_result_set(res, TT_APP_EXIT_USAGE, TT_ERR_ARG,
                         "%s: libpq cannot parse this connection string, "
                         "so it is not used (quote a value with blanks or "
                         "quotes as 'a b', and write ' and \\ in it as "
                         "\\' and \\\\)",
                         tt__app_secrets_shown(&r.msg.secrets, names[i]));
      return TT_ERR_ARG;
    }

  /* Configuration first, so that GDAL_SKIP, GDAL_DRIVER_PATH and friends
   * apply to the drivers registered and to every file opened. */
  apply_config(&o->s);
  /* The process-wide handler first: set while this thread's stack is
   * empty, GDAL takes it without a debug line saying it will not. It is
   * restored at the end (GDAL tells no previous user data: none then). */
  CPLErrorHandler old_handler =
      CPLSetErrorHandlerEx(on_gdal_thread_message, &r.msg);
  CPLPushErrorHandlerEx(on_gdal_message, &r.msg);
  GDALAllRegister();
  r.ctx = tt_context_create();
  if (!r.ctx) {
    tt__app_result_set(res, TT_APP_EXIT_FAILURE, TT_ERR_NOMEM, "out of memory");
    st = TT_ERR_NOMEM;
    goto done;
  }
  tt_context_set_log(r.ctx, on_engine_warning, &r.msg);
  remove_stale(&r);

  /* --formats: the drivers as this run would see them (after --config) */
  st = cmd ? cmd->run(&r) : tt__app_formats(&r);
done:
  tt__app_close_raster(&r, NULL);
  CSLDestroy(r.view_args);
  tt_context_destroy(r.ctx);
  CPLPopErrorHandler();
  CPLSetErrorHandler(old_handler);
  fflush(r.out);
  fflush(r.err);
  if (st != TT_OK && res->exit_code == TT_APP_EXIT_OK)
    tt__app_result_set(res, TT_APP_EXIT_FAILURE, st, "%s",
                       tt_status_message(st));
  return st;
}
