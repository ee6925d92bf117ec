/*
 * output_path.c -- safe output: never overwrite without permission, never
 * leave a half-written file under a final name.
 *
 * A tt_output plans the final names and a temporary name beside them, in the
 * same folder (so the final step is a rename on one file system):
 *  - single-file formats (GPKG, GeoTIFF, ...): the dataset is created as
 *    `<dir>/.<stem>.tmp-<pid>-<random><ext>` (same extension, so drivers
 *    accept it) and renamed to the final path at commit; any sidecar the
 *    driver made under the temporary stem moves with it.
 *  - "ESRI Shapefile": OUTPUT is `name` or `name.shp`; the dataset is a
 *    temporary folder `<dir>/.<name>.tmp-<pid>-<random>/` and the writer
 *    prefixes its layers with `<name>_` (tt_output_layer_prefix()), so the
 *    files are `<name>_triangles.shp` etc. At commit every file moves into
 *    <dir>; the old files of those names are first moved aside into the
 *    temporary folder and put back if any move fails.
 * The existence checks run at begin (fail early) and again at commit.
 * destroy() removes whatever temporary files remain. POSIX only, no GDAL.
 */
#include "base/internal.h"
#include "terratin/terratin_gdal.h"

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <time.h>
#include <unistd.h>

/* The layers the TIN writer makes, and the files a shapefile layer may
 * have (.qix with SPATIAL_INDEX=YES; .sbn/.sbx are ESRI's index files,
 * which would be stale next to new data). */
static const char *const shp_geom_layers[] = {"triangles", "vertices"};
static const char *const shp_geom_exts[] = {"shp", "shx", "dbf", "prj",
                                            "cpg", "qix", "sbn", "sbx"};
static const char *const shp_table_layers[] = {"run_parameters"};
static const char *const shp_table_exts[] = {"dbf", "cpg"};

#define N_OF(a) (sizeof(a) / sizeof((a)[0]))
#define TT_OLD_DIR ".old"

struct tt_output {
  int shapefile;
  int overwrite;
  int committed;
  int keep_temp;       /* a failed rollback left the user's files there */
  char *dir;           /* folder of the final files */
  char *final_path;    /* as given (shapefile: as given too) */
  char *final_stem;    /* single-file: file name without extension */
  char *temp_path;     /* the dataset name to create */
  char *temp_stem;     /* single-file: temporary file name without ext */
  char *prefix;        /* layer-name prefix: "<name>_" or "" */
  char **finals;       /* shapefile: every final file name (no folder) */
  size_t nfinals;
};

static char *str_printf(const char *fmt, ...) TT_PRINTF(1, 2);

static char *str_printf(const char *fmt, ...)
{
  va_list ap;
  va_start(ap, fmt);
  int n = vsnprintf(NULL, 0, fmt, ap);
  va_end(ap);
  if (n < 0)
    return NULL;
  char *s = malloc((size_t)n + 1);
  if (!s)
    return NULL;
  va_start(ap, fmt);
  vsnprintf(s, (size_t)n + 1, fmt, ap);
  va_end(ap);
  return s;
}

static int path_exists(const char *path)
{
  struct stat st;
  return lstat(path, &st) == 0;
}

/* A random 32-bit tag from the clock, the pid and an address: the names
 * are also created exclusively, so a clash only costs a retry. */
static unsigned random_tag(const void *salt, unsigned attempt)
{
  struct timespec ts;
  clock_gettime(CLOCK_REALTIME, &ts);
  uint64_t x = (uint64_t)ts.tv_nsec ^ ((uint64_t)ts.tv_sec << 30) ^
               ((uint64_t)getpid() << 16) ^ (uint64_t)(uintptr_t)salt ^
               ((uint64_t)attempt * 0x9e3779b97f4a7c15ull);
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
  return (unsigned)((x ^ (x >> 31)) & 0xffffffffu);
}

/* Removes a folder and the files and folders in it (symbolic links are
 * removed, not followed). */
static void remove_tree(const char *path)
{
  DIR *d = opendir(path);
  if (d) {
    struct dirent *e;
    while ((e = readdir(d)) != NULL) {
      if (strcmp(e->d_name, ".") == 0 || strcmp(e->d_name, "..") == 0)
        continue;
      char *p = str_printf("%s/%s", path, e->d_name);
      if (!p)
        continue;
      struct stat st;
      if (lstat(p, &st) == 0 && S_ISDIR(st.st_mode))
        remove_tree(p);
      else
        unlink(p);
      free(p);
    }
    closedir(d);
  }
  rmdir(path);
}

void tt_output_destroy(tt_output *out)
{
  if (!out)
    return;
  if (!out->committed && !out->keep_temp && out->temp_path) {
    if (out->shapefile) {
      remove_tree(out->temp_path);
    } else {
      /* The dataset and any sidecar the driver made under its stem. */
      unlink(out->temp_path);
      DIR *d = opendir(out->dir);
      size_t n = strlen(out->temp_stem);
      if (d) {
        struct dirent *e;
        while ((e = readdir(d)) != NULL) {
          if (strncmp(e->d_name, out->temp_stem, n) != 0)
            continue;
          char *p = str_printf("%s/%s", out->dir, e->d_name);
          if (p)
            unlink(p);
          free(p);
        }
        closedir(d);
      }
    }
  }
  for (size_t i = 0; i < out->nfinals; i++)
    free(out->finals[i]);
  free(out->finals);
  free(out->dir);
  free(out->final_path);
  free(out->final_stem);
  free(out->temp_path);
  free(out->temp_stem);
  free(out->prefix);
  free(out);
}

/* Splits path into a folder ("." when none) and a file name. */
static tt_status split_path(tt_context *ctx, const char *path, char **dir,
                            char **name)
{
  const char *slash = strrchr(path, '/');
  if (slash && slash[1] == '\0')
    return tt__error(ctx, TT_ERR_ARG, "output \"%s\" names a folder, not a "
                     "file", path);
  if (!slash) {
    *dir = str_printf(".");
    *name = str_printf("%s", path);
  } else if (slash == path) {
    *dir = str_printf("/");
    *name = str_printf("%s", slash + 1);
  } else {
    *dir = str_printf("%.*s", (int)(slash - path), path);
    *name = str_printf("%s", slash + 1);
  }
  if (!*dir || !*name)
    return tt__error(ctx, TT_ERR_NOMEM, "out of memory");
  if (strcmp(*name, ".") == 0 || strcmp(*name, "..") == 0)
    return tt__error(ctx, TT_ERR_ARG, "output \"%s\" names a folder, not a "
                     "file", path);
  return TT_OK;
}

static tt_status check_folder(tt_context *ctx, const char *dir)
{
  struct stat st;
  if (stat(dir, &st) != 0)
    return tt__error(ctx, TT_ERR_IO, "cannot write in folder %s: %s", dir,
                     strerror(errno));
  if (!S_ISDIR(st.st_mode))
    return tt__error(ctx, TT_ERR_IO, "cannot write in %s: not a folder",
                     dir);
  if (access(dir, W_OK | X_OK) != 0)
    return tt__error(ctx, TT_ERR_IO, "cannot write in folder %s: %s", dir,
                     strerror(errno));
  return TT_OK;
}

/* Refuses (TT_ERR_EXISTS) when a final file exists and overwrite is off;
 * a folder in the way is refused even with overwrite. */
static tt_status check_finals(tt_context *ctx, const tt_output *out)
{
  if (!out->shapefile) {
    struct stat st;
    if (lstat(out->final_path, &st) != 0)
      return TT_OK;
    if (S_ISDIR(st.st_mode))
      return tt__error(ctx, TT_ERR_EXISTS, "%s exists and is a folder",
                       out->final_path);
    if (!out->overwrite)
      return tt__error(ctx, TT_ERR_EXISTS, "%s exists; not overwriting it "
                       "without permission", out->final_path);
    return TT_OK;
  }
  for (size_t i = 0; i < out->nfinals; i++) {
    char *p = str_printf("%s/%s", out->dir, out->finals[i]);
    if (!p)
      return tt__error(ctx, TT_ERR_NOMEM, "out of memory");
    struct stat st;
    int exists = lstat(p, &st) == 0;
    tt_status s = TT_OK;
    if (exists && S_ISDIR(st.st_mode))
      s = tt__error(ctx, TT_ERR_EXISTS, "%s exists and is a folder", p);
    else if (exists && !out->overwrite)
      s = tt__error(ctx, TT_ERR_EXISTS, "%s exists; not overwriting it "
                    "without permission", p);
    free(p);
    if (s != TT_OK)
      return s;
  }
  return TT_OK;
}

static tt_status add_final(tt_context *ctx, tt_output *out, char *name)
{
  if (!name)
    return tt__error(ctx, TT_ERR_NOMEM, "out of memory");
  out->finals[out->nfinals++] = name;
  return TT_OK;
}

static tt_status plan_shapefile(tt_context *ctx, tt_output *out,
                                const char *name)
{
  size_t n = strlen(name);
  if (n > 4 && strcasecmp(name + n - 4, ".shp") == 0)
    n -= 4;
  if (n == 0)
    return tt__error(ctx, TT_ERR_ARG, "output \"%s\" has an empty name",
                     out->final_path);
  out->final_stem = str_printf("%.*s", (int)n, name);
  out->prefix = str_printf("%.*s_", (int)n, name);
  size_t count = N_OF(shp_geom_layers) * N_OF(shp_geom_exts) +
                 N_OF(shp_table_layers) * N_OF(shp_table_exts);
  out->finals = calloc(count, sizeof *out->finals);
  if (!out->final_stem || !out->prefix || !out->finals)
    return tt__error(ctx, TT_ERR_NOMEM, "out of memory");
  tt_status s = TT_OK;
  for (size_t i = 0; i < N_OF(shp_geom_layers) && s == TT_OK; i++)
    for (size_t k = 0; k < N_OF(shp_geom_exts) && s == TT_OK; k++)
      s = add_final(ctx, out, str_printf("%s%s.%s", out->prefix,
                                         shp_geom_layers[i],
                                         shp_geom_exts[k]));
  for (size_t i = 0; i < N_OF(shp_table_layers) && s == TT_OK; i++)
    for (size_t k = 0; k < N_OF(shp_table_exts) && s == TT_OK; k++)
      s = add_final(ctx, out, str_printf("%s%s.%s", out->prefix,
                                         shp_table_layers[i],
                                         shp_table_exts[k]));
  return s;
}

/* Makes the temporary name: a folder (shapefile) or a probe file that is
 * removed again (drivers refuse to create over an existing file). A
 * failure here is the definitive "folder not writable". */
static tt_status make_temp(tt_context *ctx, tt_output *out, const char *ext)
{
  for (unsigned attempt = 0; attempt < 64; attempt++) {
    unsigned tag = random_tag(out, attempt);
    free(out->temp_stem);
    free(out->temp_path);
    out->temp_stem = str_printf(".%s.tmp-%ld-%08x", out->final_stem,
                                (long)getpid(), tag);
    out->temp_path = out->temp_stem
                         ? str_printf("%s/%s%s", out->dir, out->temp_stem,
                                      out->shapefile ? "" : ext)
                         : NULL;
    if (!out->temp_path)
      return tt__error(ctx, TT_ERR_NOMEM, "out of memory");
    int ok;
    if (out->shapefile) {
      ok = mkdir(out->temp_path, 0777) == 0;
    } else {
      int fd = open(out->temp_path, O_WRONLY | O_CREAT | O_EXCL, 0666);
      ok = fd >= 0;
      if (ok) {
        close(fd);
        unlink(out->temp_path);
      }
    }
    if (ok)
      return TT_OK;
    if (errno != EEXIST) {
      int e = errno;
      char *failed = out->temp_path;
      out->temp_path = NULL; /* nothing to clean up */
      tt_status s = tt__error(ctx, TT_ERR_IO, "cannot write in folder %s: "
                              "creating %s failed: %s", out->dir, failed,
                              strerror(e));
      free(failed);
      return s;
    }
  }
  char *failed = out->temp_path;
  out->temp_path = NULL;
  tt_status s = tt__error(ctx, TT_ERR_IO, "cannot find a free temporary "
                          "name like %s", failed);
  free(failed);
  return s;
}

tt_status tt_output_begin(tt_context *ctx, const char *path,
                          const char *format, int overwrite,
                          tt_output **out_output)
{
  if (!out_output)
    return tt__error(ctx, TT_ERR_ARG, "out_output must not be NULL");
  *out_output = NULL;
  if (!path || !*path)
    return tt__error(ctx, TT_ERR_ARG, "output path must not be empty");
  if (!format || !*format)
    return tt__error(ctx, TT_ERR_ARG, "output format must not be empty");

  tt_output *out = calloc(1, sizeof *out);
  if (!out)
    return tt__error(ctx, TT_ERR_NOMEM, "out of memory");
  out->shapefile = strcasecmp(format, "ESRI Shapefile") == 0;
  out->overwrite = overwrite != 0;
  char *name = NULL;
  const char *ext = "";
  tt_status s = TT_OK;
  out->final_path = str_printf("%s", path);
  if (!out->final_path) {
    s = tt__error(ctx, TT_ERR_NOMEM, "out of memory");
    goto done;
  }
  s = split_path(ctx, path, &out->dir, &name);
  if (s != TT_OK)
    goto done;

  if (out->shapefile) {
    s = plan_shapefile(ctx, out, name);
  } else {
    const char *dot = strrchr(name, '.');
    ext = dot && dot != name ? dot : "";
    out->final_stem = str_printf("%.*s", (int)(strlen(name) - strlen(ext)),
                                 name);
    out->prefix = str_printf("%s", "");
    if (!out->final_stem || !out->prefix)
      s = tt__error(ctx, TT_ERR_NOMEM, "out of memory");
  }
  if (s == TT_OK)
    s = check_finals(ctx, out);
  if (s == TT_OK)
    s = check_folder(ctx, out->dir);
  if (s == TT_OK)
    s = make_temp(ctx, out, ext);

done:
  free(name);
  if (s != TT_OK) {
    tt_output_destroy(out);
    return s;
  }
  *out_output = out;
  return TT_OK;
}

const char *tt_output_temp_path(const tt_output *out)
{
  return out ? out->temp_path : NULL;
}

const char *tt_output_final_path(const tt_output *out)
{
  return out ? out->final_path : NULL;
}

const char *tt_output_layer_prefix(const tt_output *out)
{
  return out && out->prefix ? out->prefix : "";
}

/* Single file: sidecars under the temporary stem first, the dataset last,
 * each by rename(), which replaces an old file atomically. */
static tt_status commit_single(tt_context *ctx, tt_output *out)
{
  if (!path_exists(out->temp_path))
    return tt__error(ctx, TT_ERR_IO, "nothing was written to %s",
                     out->temp_path);
  size_t n = strlen(out->temp_stem);
  const char *main_name = out->temp_path + strlen(out->dir) + 1;
  DIR *d = opendir(out->dir);
  if (!d)
    return tt__error(ctx, TT_ERR_IO, "cannot list folder %s: %s", out->dir,
                     strerror(errno));
  tt_status s = TT_OK;
  struct dirent *e;
  while (s == TT_OK && (e = readdir(d)) != NULL) {
    if (strncmp(e->d_name, out->temp_stem, n) != 0 ||
        strcmp(e->d_name, main_name) == 0)
      continue;
    char *from = str_printf("%s/%s", out->dir, e->d_name);
    char *to = str_printf("%s/%s%s", out->dir, out->final_stem,
                          e->d_name + n);
    if (!from || !to)
      s = tt__error(ctx, TT_ERR_NOMEM, "out of memory");
    else if (!out->overwrite && path_exists(to))
      s = tt__error(ctx, TT_ERR_EXISTS, "%s exists; not overwriting it "
                    "without permission", to);
    else if (rename(from, to) != 0)
      s = tt__error(ctx, TT_ERR_IO, "cannot rename %s to %s: %s", from, to,
                    strerror(errno));
    free(from);
    free(to);
  }
  closedir(d);
  if (s != TT_OK)
    return s;
  if (!out->overwrite) {
    /* link() refuses an existing target atomically; file systems without
     * hard links fall back to check-then-rename. */
    if (link(out->temp_path, out->final_path) == 0) {
      unlink(out->temp_path);
      return TT_OK;
    }
    if (errno == EEXIST)
      return tt__error(ctx, TT_ERR_EXISTS, "%s exists; not overwriting it "
                       "without permission", out->final_path);
    if (path_exists(out->final_path))
      return tt__error(ctx, TT_ERR_EXISTS, "%s exists; not overwriting it "
                       "without permission", out->final_path);
  }
  if (rename(out->temp_path, out->final_path) != 0)
    return tt__error(ctx, TT_ERR_IO, "cannot rename %s to %s: %s",
                     out->temp_path, out->final_path, strerror(errno));
  return TT_OK;
}

/* Shapefile: move the old files of our names aside into the temporary
 * folder, move the new ones into place, and undo both on any failure. */
static tt_status commit_shapefile(tt_context *ctx, tt_output *out)
{
  tt_status s = TT_OK;
  char **news = NULL, **olds = NULL;
  size_t nnew = 0, capnew = 0, nold = 0, moved_new = 0, moved_old = 0;
  char *old_dir = NULL;

  DIR *d = opendir(out->temp_path);
  if (!d)
    return tt__error(ctx, TT_ERR_IO, "cannot list folder %s: %s",
                     out->temp_path, strerror(errno));
  struct dirent *e;
  while ((e = readdir(d)) != NULL) {
    if (e->d_name[0] == '.')
      continue; /* ".", "..", and our own TT_OLD_DIR */
    if (!tt__grow((void **)&news, &capnew, nnew + 1, sizeof *news)) {
      s = tt__error(ctx, TT_ERR_NOMEM, "out of memory");
      break;
    }
    news[nnew] = str_printf("%s", e->d_name);
    if (!news[nnew]) {
      s = tt__error(ctx, TT_ERR_NOMEM, "out of memory");
      break;
    }
    nnew++;
  }
  closedir(d);
  if (s != TT_OK)
    goto done;
  if (nnew == 0) {
    s = tt__error(ctx, TT_ERR_IO, "nothing was written to %s",
                  out->temp_path);
    goto done;
  }

  /* Every name that will be replaced or must not linger: our fixed set and
   * whatever the driver wrote. */
  s = check_finals(ctx, out);
  for (size_t i = 0; s == TT_OK && i < nnew; i++) {
    char *p = str_printf("%s/%s", out->dir, news[i]);
    if (!p)
      s = tt__error(ctx, TT_ERR_NOMEM, "out of memory");
    else if (!out->overwrite && path_exists(p))
      s = tt__error(ctx, TT_ERR_EXISTS, "%s exists; not overwriting it "
                    "without permission", p);
    free(p);
  }
  if (s != TT_OK)
    goto done;

  olds = calloc(out->nfinals + nnew, sizeof *olds);
  old_dir = str_printf("%s/%s", out->temp_path, TT_OLD_DIR);
  if (!olds || !old_dir) {
    s = tt__error(ctx, TT_ERR_NOMEM, "out of memory");
    goto done;
  }
  for (size_t i = 0; i < out->nfinals + nnew; i++) {
    const char *name = i < out->nfinals ? out->finals[i]
                                        : news[i - out->nfinals];
    char *p = str_printf("%s/%s", out->dir, name);
    if (!p) {
      s = tt__error(ctx, TT_ERR_NOMEM, "out of memory");
      goto done;
    }
    int dup = 0; /* a driver file may also be in the fixed set */
    for (size_t k = 0; k < nold; k++)
      dup |= strcmp(olds[k], name) == 0;
    if (!dup && path_exists(p))
      olds[nold++] = (char *)name;
    free(p);
  }
  if (nold > 0 && mkdir(old_dir, 0700) != 0) {
    s = tt__error(ctx, TT_ERR_IO, "cannot create %s: %s", old_dir,
                  strerror(errno));
    goto done;
  }
  for (; moved_old < nold; moved_old++) {
    char *from = str_printf("%s/%s", out->dir, olds[moved_old]);
    char *to = str_printf("%s/%s", old_dir, olds[moved_old]);
    int ok = from && to && rename(from, to) == 0;
    if (!ok)
      s = tt__error(ctx, TT_ERR_IO, "cannot move %s aside: %s",
                    from ? from : "?", strerror(errno));
    free(from);
    free(to);
    if (!ok)
      goto rollback;
  }
  for (; moved_new < nnew; moved_new++) {
    char *from = str_printf("%s/%s", out->temp_path, news[moved_new]);
    char *to = str_printf("%s/%s", out->dir, news[moved_new]);
    int ok = from && to && rename(from, to) == 0;
    if (!ok)
      s = tt__error(ctx, TT_ERR_IO, "cannot move %s into place: %s",
                    to ? to : "?", strerror(errno));
    free(from);
    free(to);
    if (!ok)
      goto rollback;
  }
  /* Done: the old files go, then the temporary folder. */
  remove_tree(out->temp_path);
  goto done;

rollback:
  while (moved_new > 0) {
    moved_new--;
    char *p = str_printf("%s/%s", out->dir, news[moved_new]);
    if (p)
      unlink(p);
    free(p);
  }
  while (moved_old > 0) {
    moved_old--;
    char *from = str_printf("%s/%s", old_dir, olds[moved_old]);
    char *to = str_printf("%s/%s", out->dir, olds[moved_old]);
    if (!from || !to || rename(from, to) != 0) {
      /* Keep the temporary folder: the user's old files are in it. */
      out->keep_temp = 1;
      s = tt__error(ctx, TT_ERR_IO, "commit failed and the old file %s "
                    "could not be put back; it is in %s", to ? to : "?",
                    old_dir);
    }
    free(from);
    free(to);
  }

done:
  for (size_t i = 0; i < nnew; i++)
    free(news[i]);
  free(news);
  free(olds); /* its strings belong to finals and news */
  free(old_dir);
  return s;
}

tt_status tt_output_commit(tt_context *ctx, tt_output *out)
{
  if (!out || !out->temp_path)
    return tt__error(ctx, TT_ERR_ARG, "no output to commit");
  if (out->committed)
    return tt__error(ctx, TT_ERR_ARG, "output %s was already committed",
                     out->final_path);
  tt_status s = out->shapefile ? commit_shapefile(ctx, out)
                               : commit_single(ctx, out);
  if (s == TT_OK)
    out->committed = 1;
  return s;
}
