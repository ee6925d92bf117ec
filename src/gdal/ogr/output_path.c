/*
 * src/gdal/ogr/ -- the OGR layers: a TIN written into an OGR dataset and
 * triangles read from one, the features' records, QGIS's default style,
 * safe output paths and the protection of the input's files.
 *
 * output_path.c -- safe output: never overwrite without permission, never
 * leave a half-written file under a final name, never replace what the run
 * reads or what another program has open.
 *
 * A tt_output plans the final names and a temporary name beside them, in the
 * same folder (so the final step is a rename on one file system). The
 * temporary names are short (`.tt` and 8 hex digits, 11 bytes plus the
 * extension), so that any final name the file system takes (255 bytes)
 * still leaves room for them:
 *  - single-file formats (GPKG, GeoTIFF, ...): the dataset is created as
 *    `<dir>/.ttXXXXXXXX<ext>` (same extension, so drivers accept it) and
 *    renamed to the final path at commit; any sidecar the driver made under
 *    the temporary stem moves with it. A driver that makes a folder instead
 *    (FlatGeobuf or MapInfo with several layers) gets it renamed into place
 *    whole, when the final name has no extension (a folder named like a
 *    file is refused).
 *  - "ESRI Shapefile": OUTPUT is `name` or `name.shp`; the dataset is a
 *    temporary folder `<dir>/.ttXXXXXXXX/` and the writer prefixes its
 *    layers with `<name>_` (tt_output_layer_prefix()), so the files are
 *    `<name>_triangles.shp` etc. At commit every file moves into <dir>; the
 *    old files of those names are first moved aside into the temporary
 *    folder and put back if any move fails.
 * What -overwrite replaces: a regular file, or a folder holding nothing but
 * the layer files of an earlier output (`*triangles.*`, `*vertices.*`,
 * `*run_parameters.*`). Never a FIFO, device, socket or symbolic link, never
 * another folder, never a file registered with tt_output_protect() (the
 * files the input was read from), compared by device and inode.
 * SQLite formats (GPKG, SQLite): the sidecars `OUT-journal`, `OUT-wal` and
 * `OUT-shm` belong to the name. SQLite would apply them to the new file (a
 * hot journal rolled back into it, a WAL replayed over it) and corrupt it,
 * so they are part of what is replaced: without -overwrite an existing one
 * is refused; with it, the output is refused while another process holds
 * the old file open as SQLite's unix VFS shows it (a POSIX lock on the
 * database's lock bytes at 1 GiB, or on the -shm's WAL and DMS bytes
 * 120..128, which every WAL connection holds while open), and otherwise the
 * stale sidecars (a crashed writer's) are moved aside just before the new
 * file is renamed into place and deleted after.
 * Files a format writes beside a single file (2DM's datasets) are
 * registered with tt_output_add_sidecar(): written under the temporary
 * stem, checked like the output, renamed with it.
 * The checks run at begin (fail early) and again at commit.
 * destroy() removes whatever temporary files remain, folders included;
 * clear() removes them earlier, for a writer that starts over. Each
 * temporary stem has an owner, the flock()ed `.ttXXXXXXXX.lock` beside it
 * (output_owner.c), taken before the temporaries are made and given up
 * after they are gone; begin() first removes the temporaries of stems whose
 * owner is gone (a killed run's).
 * Live outputs are kept in a process-wide list, so tt_output_abandon_all()
 * (a signal's watchdog thread) can remove their temporary files while the
 * main thread is stuck in a driver; a mutex orders it with commit and
 * destroy. POSIX only, no GDAL call.
 */
#define _XOPEN_SOURCE 700 /* realpath(), which C11 + POSIX 2008 hide */
#include "base/internal.h"
#include "gdal/ogr/output_owner.h"
#include "terratin/terratin_gdal.h"

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <pthread.h>
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
 * which would be stale next to new data; .qml is QGIS's style, which
 * tt_ogr_write_tin's STYLE=YES writes). */
static const char *const shp_geom_layers[] = {"triangles", "vertices"};
static const char *const shp_geom_exts[] = {"shp", "shx", "dbf", "prj", "cpg",
                                            "qix", "sbn", "sbx", "qml"};
static const char *const shp_table_layers[] = {"run_parameters"};
static const char *const shp_table_exts[] = {"dbf", "cpg"};

/* The files SQLite keeps beside a database of the same name. */
static const char *const sqlite_sidecars[] = {"-journal", "-wal", "-shm"};

#define N_OF(a) (sizeof(a) / sizeof((a)[0]))
#define TT_OLD_DIR ".old"
#define TT_OLD_SUFFIX ".old"

/* A file the output must not replace: device and inode, and its resolved
 * path (NULL when it could not be resolved) for folder outputs. */
typedef struct protected_file {
  dev_t dev;
  ino_t ino;
  char *real;
  char *name;          /* as given, for messages */
} protected_file;

struct tt_output {
  int shapefile;
  int overwrite;
  int committed;
  int abandoned;       /* tt_output_abandon_all() removed the temporaries */
  int sqlite;          /* the format keeps SQLite sidecars */
  int keep_temp;       /* a failed rollback left the user's files there */
  char *dir;           /* folder of the final files */
  char *final_path;    /* as given (shapefile: as given too) */
  char *final_stem;    /* single-file: file name without extension */
  char *temp_path;     /* the dataset name to create */
  char *temp_stem;     /* single-file: temporary file name without ext */
  char *prefix;        /* layer-name prefix: "<name>_" or "" */
  int owner_fd;        /* the flock()ed STEM.lock (output_owner.c), or -1 */
  char **finals;       /* shapefile: every final file name (no folder) */
  size_t nfinals;
  protected_file *prot;
  size_t nprot, capprot;
  char **sidecars;     /* single-file: files written beside the output */
  size_t nsidecars, capsidecars;
  tt_output *prev, *next; /* the list of live outputs */
};

/* Live outputs, for tt_output_abandon_all(); the lock also orders commit,
 * destroy and abandon, which may run on different threads. */
static pthread_mutex_t live_lock = PTHREAD_MUTEX_INITIALIZER;
static tt_output *live_head = NULL;

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

/* Removes the temporary files that remain: the shapefile folder, or every
 * entry of the folder whose name starts with the temporary stem (the
 * dataset, a driver's sidecars, a folder a driver made). Called with
 * live_lock held. */
static void remove_temp(tt_output *out)
{
  if (out->committed || out->keep_temp || out->abandoned || !out->temp_path)
    return;
  if (out->shapefile) {
    tt__owner_remove_tree(out->temp_path);
    return;
  }
  DIR *d = opendir(out->dir);
  size_t n = strlen(out->temp_stem);
  if (!d)
    return;
  struct dirent *e;
  while ((e = readdir(d)) != NULL) {
    if (strncmp(e->d_name, out->temp_stem, n) != 0 ||
        strcmp(e->d_name + n, ".lock") == 0)
      continue; /* the lock goes last, in release_owner() */
    char *p = str_printf("%s/%s", out->dir, e->d_name);
    struct stat st;
    if (p && lstat(p, &st) == 0 && S_ISDIR(st.st_mode))
      tt__owner_remove_tree(p);
    else if (p)
      unlink(p);
    free(p);
  }
  closedir(d);
}

/* Gives the temporary stem up (its lock file removed): after the
 * temporaries are gone or committed, or when they must stay (they hold
 * the user's files) and never be swept. Called with live_lock held. */
static void release_owner(tt_output *out)
{
  if (out->owner_fd >= 0)
    tt__owner_release(out->dir, out->temp_stem, out->owner_fd);
  out->owner_fd = -1;
}

void tt_output_clear(tt_output *out)
{
  if (!out)
    return;
  pthread_mutex_lock(&live_lock);
  remove_temp(out);
  pthread_mutex_unlock(&live_lock);
}

void tt_output_destroy(tt_output *out)
{
  if (!out)
    return;
  pthread_mutex_lock(&live_lock);
  remove_temp(out);
  release_owner(out);
  if (out->prev)
    out->prev->next = out->next;
  else if (live_head == out)
    live_head = out->next;
  if (out->next)
    out->next->prev = out->prev;
  pthread_mutex_unlock(&live_lock);
  for (size_t i = 0; i < out->nfinals; i++)
    free(out->finals[i]);
  for (size_t i = 0; i < out->nprot; i++) {
    free(out->prot[i].real);
    free(out->prot[i].name);
  }
  for (size_t i = 0; i < out->nsidecars; i++)
    free(out->sidecars[i]);
  free(out->sidecars);
  free(out->prot);
  free(out->finals);
  free(out->dir);
  free(out->final_path);
  free(out->final_stem);
  free(out->temp_path);
  free(out->temp_stem);
  free(out->prefix);
  free(out);
}

int tt_output_abandon_all(void)
{
  int all = 1;
  pthread_mutex_lock(&live_lock);
  for (tt_output *o = live_head; o; o = o->next) {
    if (o->committed) {
      all = 0;
      continue;
    }
    remove_temp(o);
    release_owner(o);
    o->abandoned = 1;
  }
  pthread_mutex_unlock(&live_lock);
  return all;
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

/* The absolute, resolved form of path: realpath() when it exists, else
 * the resolved folder and the name (a file that does not exist yet). NULL
 * when neither resolves. */
static char *resolve(const char *path)
{
  char *r = realpath(path, NULL);
  if (r)
    return r;
  const char *slash = strrchr(path, '/');
  char *dir = slash ? str_printf("%.*s", slash == path ? 1 : (int)(slash - path),
                                 path)
                    : str_printf(".");
  char *rdir = dir ? realpath(dir, NULL) : NULL;
  char *out = rdir ? str_printf("%s/%s", strcmp(rdir, "/") ? rdir : "",
                                slash ? slash + 1 : path)
                   : NULL;
  free(dir);
  free(rdir);
  return out;
}

/* The protected file that `path` (a name the output writes, replaces or
 * removes) is or holds, or NULL: the same device and inode, the same
 * resolved name, or (path a folder) a protected file inside it. */
static const protected_file *protected_as(const tt_output *out,
                                          const char *path)
{
  if (out->nprot == 0)
    return NULL;
  struct stat st;
  int exists = stat(path, &st) == 0;
  char *real = resolve(path);
  size_t n = real ? strlen(real) : 0;
  const protected_file *hit = NULL;
  for (size_t i = 0; i < out->nprot && !hit; i++) {
    const protected_file *p = &out->prot[i];
    if (exists && p->ino != 0 && st.st_dev == p->dev && st.st_ino == p->ino)
      hit = p;
    else if (real && p->real && strcmp(real, p->real) == 0)
      hit = p;
    else if (exists && S_ISDIR(st.st_mode) && real && p->real &&
             strncmp(p->real, real, n) == 0 && p->real[n] == '/')
      hit = p;
  }
  free(real);
  return hit;
}

static tt_status refuse_protected(tt_context *ctx, const tt_output *out,
                                  const char *path)
{
  const protected_file *p = protected_as(out, path);
  if (!p)
    return TT_OK;
  if (strcmp(path, p->name) == 0)
    return tt__error(ctx, TT_ERR_ARG, "%s is a file the input is read from; "
                     "refusing to replace it", path);
  return tt__error(ctx, TT_ERR_ARG, "%s is a file the input is read from "
                   "(%s); refusing to replace it", path, p->name);
}

/* What a file that is not a regular file is, for messages. */
static const char *file_kind(mode_t mode)
{
  if (S_ISLNK(mode))
    return "a symbolic link";
  if (S_ISFIFO(mode))
    return "a FIFO";
  if (S_ISCHR(mode))
    return "a character device";
  if (S_ISBLK(mode))
    return "a block device";
  if (S_ISSOCK(mode))
    return "a socket";
  if (S_ISDIR(mode))
    return "a folder";
  return "not a regular file";
}

static tt_status refuse_kind(tt_context *ctx, const char *path, mode_t mode)
{
  return tt__error(ctx, TT_ERR_EXISTS, "%s exists and is %s, not a regular "
                   "file; not replacing it", path, file_kind(mode));
}

/* A layer file of an earlier output: "<prefix>triangles.<ext>",
 * "<prefix>vertices.<ext>" or "<prefix>run_parameters.<ext>". */
static int layer_file_name(const char *name)
{
  static const char *const layers[] = {"triangles", "vertices",
                                       "run_parameters"};
  const char *dot = strchr(name, '.');
  if (!dot || dot == name || name[0] == '.')
    return 0;
  size_t n = (size_t)(dot - name);
  for (size_t i = 0; i < N_OF(layers); i++) {
    size_t k = strlen(layers[i]);
    if (n >= k && strncmp(dot - k, layers[i], k) == 0)
      return 1;
  }
  return 0;
}

/* Whether the folder is the output of a driver that writes one (FlatGeobuf,
 * MapInfo): not empty, and nothing in it but regular layer files. */
static int own_folder(const char *path)
{
  DIR *d = opendir(path);
  if (!d)
    return 0;
  int ok = 1, count = 0;
  struct dirent *e;
  while (ok && (e = readdir(d)) != NULL) {
    if (strcmp(e->d_name, ".") == 0 || strcmp(e->d_name, "..") == 0)
      continue;
    char *p = str_printf("%s/%s", path, e->d_name);
    struct stat st;
    ok = p && lstat(p, &st) == 0 && S_ISREG(st.st_mode) &&
         layer_file_name(e->d_name);
    free(p);
    count++;
  }
  closedir(d);
  return ok && count > 0;
}

/* Whether another process holds a POSIX record lock on bytes [start,
 * start + len) of the regular file path: F_GETLK reports a lock that would
 * conflict with a write lock, that is any lock, of any other process.
 * (This process holds none on these files, so closing the descriptor
 * releases nothing.) */
static int locked_elsewhere(const char *path, off_t start, off_t len)
{
  int fd = open(path, O_RDONLY | O_NONBLOCK | O_NOFOLLOW);
  if (fd < 0)
    return 0;
  struct flock fl;
  memset(&fl, 0, sizeof fl);
  fl.l_type = F_WRLCK;
  fl.l_whence = SEEK_SET;
  fl.l_start = start;
  fl.l_len = len;
  int held = fcntl(fd, F_GETLK, &fl) == 0 && fl.l_type != F_UNLCK;
  close(fd);
  return held;
}

/* SQLite's unix VFS: a connection in a transaction (rollback journal, or
 * WAL with locking_mode=EXCLUSIVE) locks bytes of the database from
 * PENDING_BYTE (1 GiB) on: PENDING, RESERVED and the 510 SHARED bytes; a
 * connection in WAL mode holds a shared lock on the -shm's DMS byte (128)
 * for as long as it is open, and locks the 8 WAL bytes before it (120..127)
 * while it reads or writes. */
#define SQLITE_LOCK_FIRST 0x40000000
#define SQLITE_LOCK_BYTES 512
#define SQLITE_SHM_FIRST 120
#define SQLITE_SHM_BYTES 9

static tt_status refuse_in_use(tt_context *ctx, const tt_output *out)
{
  struct stat st;
  char *shm = str_printf("%s-shm", out->final_path);
  if (!shm)
    return tt__error(ctx, TT_ERR_NOMEM, "out of memory");
  tt_status s = TT_OK;
  if (lstat(shm, &st) == 0 && S_ISREG(st.st_mode) &&
      locked_elsewhere(shm, SQLITE_SHM_FIRST, SQLITE_SHM_BYTES))
    s = tt__error(ctx, TT_ERR_IO, "%s is open in another program (an SQLite "
                  "WAL connection holds %s); close it before replacing it",
                  out->final_path, shm);
  else if (lstat(out->final_path, &st) == 0 && S_ISREG(st.st_mode) &&
           locked_elsewhere(out->final_path, SQLITE_LOCK_FIRST,
                            SQLITE_LOCK_BYTES))
    s = tt__error(ctx, TT_ERR_IO, "%s is open in another program (an SQLite "
                  "connection holds a lock on it); close it before replacing "
                  "it", out->final_path);
  free(shm);
  return s;
}

/* Refuses (TT_ERR_EXISTS) when a final name exists and overwrite is off,
 * or when it is something -overwrite never replaces (a folder that is not
 * an earlier output's, a FIFO, device, socket or symbolic link); refuses a
 * name that is a protected file (TT_ERR_ARG) and an SQLite output whose
 * old file another process has open (TT_ERR_IO). */
/* A file the output writes beside its main one: a regular file (or none),
 * replaced only with -overwrite, never one the input is read from. */
static tt_status check_sidecar(tt_context *ctx, const tt_output *out,
                               const char *p)
{
  struct stat st;
  if (lstat(p, &st) == 0 && !S_ISREG(st.st_mode))
    return refuse_kind(ctx, p, st.st_mode);
  if (lstat(p, &st) == 0 && !out->overwrite)
    return tt__error(ctx, TT_ERR_EXISTS, "%s exists; not overwriting it "
                     "without permission", p);
  return refuse_protected(ctx, out, p);
}

static tt_status check_finals(tt_context *ctx, const tt_output *out)
{
  tt_status s = TT_OK;
  if (!out->shapefile) {
    struct stat st;
    if (lstat(out->final_path, &st) == 0) {
      if (S_ISDIR(st.st_mode) && !own_folder(out->final_path))
        return tt__error(ctx, TT_ERR_EXISTS, "%s exists and is a folder",
                         out->final_path);
      if (!S_ISDIR(st.st_mode) && !S_ISREG(st.st_mode))
        return refuse_kind(ctx, out->final_path, st.st_mode);
      if (!out->overwrite)
        return tt__error(ctx, TT_ERR_EXISTS, "%s exists; not overwriting it "
                         "without permission", out->final_path);
    }
    s = refuse_protected(ctx, out, out->final_path);
    for (size_t i = 0; out->sqlite && s == TT_OK && i < N_OF(sqlite_sidecars);
         i++) {
      char *p = str_printf("%s%s", out->final_path, sqlite_sidecars[i]);
      if (!p)
        return tt__error(ctx, TT_ERR_NOMEM, "out of memory");
      if (lstat(p, &st) == 0 && !S_ISREG(st.st_mode))
        s = refuse_kind(ctx, p, st.st_mode);
      else if (lstat(p, &st) == 0 && !out->overwrite)
        s = tt__error(ctx, TT_ERR_EXISTS, "%s exists; not overwriting it "
                      "without permission", p);
      if (s == TT_OK)
        s = refuse_protected(ctx, out, p);
      free(p);
    }
    for (size_t i = 0; s == TT_OK && i < out->nsidecars; i++)
      s = check_sidecar(ctx, out, out->sidecars[i]);
    if (out->sqlite && s == TT_OK)
      s = refuse_in_use(ctx, out);
    return s;
  }
  for (size_t i = 0; i < out->nfinals && s == TT_OK; i++) {
    char *p = str_printf("%s/%s", out->dir, out->finals[i]);
    if (!p)
      return tt__error(ctx, TT_ERR_NOMEM, "out of memory");
    struct stat st;
    int exists = lstat(p, &st) == 0;
    if (exists && S_ISDIR(st.st_mode))
      s = tt__error(ctx, TT_ERR_EXISTS, "%s exists and is a folder", p);
    else if (exists && !S_ISREG(st.st_mode))
      s = refuse_kind(ctx, p, st.st_mode);
    else if (exists && !out->overwrite)
      s = tt__error(ctx, TT_ERR_EXISTS, "%s exists; not overwriting it "
                    "without permission", p);
    if (s == TT_OK)
      s = refuse_protected(ctx, out, p);
    free(p);
  }
  return s;
}

tt_status tt_output_protect(tt_context *ctx, tt_output *out,
                            const char *path)
{
  if (!out || !path)
    return tt__error(ctx, TT_ERR_ARG, "output and path must not be NULL");
  struct stat st;
  protected_file p;
  memset(&p, 0, sizeof p);
  if (stat(path, &st) == 0) {
    p.dev = st.st_dev;
    p.ino = st.st_ino;
  }
  p.real = resolve(path);
  p.name = str_printf("%s", path);
  if (!p.name || !tt__grow((void **)&out->prot, &out->capprot,
                           out->nprot + 1, sizeof *out->prot)) {
    free(p.real);
    free(p.name);
    return tt__error(ctx, TT_ERR_NOMEM, "out of memory");
  }
  out->prot[out->nprot++] = p;
  return check_finals(ctx, out);
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

/* Makes the temporary name: its owner's lock file first (output_owner.c),
 * then a folder (shapefile) or a probe file that is removed again (drivers
 * refuse to create over an existing file). A failure here is the
 * definitive "folder not writable". */
static tt_status make_temp(tt_context *ctx, tt_output *out, const char *ext)
{
  for (unsigned attempt = 0; attempt < 64; attempt++) {
    unsigned tag = random_tag(out, attempt);
    free(out->temp_stem);
    free(out->temp_path);
    out->temp_stem = str_printf(".tt%08x", tag);
    out->temp_path = out->temp_stem
                         ? str_printf("%s/%s%s", out->dir, out->temp_stem,
                                      out->shapefile ? "" : ext)
                         : NULL;
    if (!out->temp_path)
      return tt__error(ctx, TT_ERR_NOMEM, "out of memory");
    int owned = tt__owner_take(out->dir, out->temp_stem, &out->owner_fd);
    if (owned == TT__OWNER_CLASH)
      continue;
    if (owned == TT__OWNER_FAILED) {
      int e = errno;
      char *failed = out->temp_path;
      out->temp_path = NULL; /* nothing to clean up */
      tt_status s = tt__error(ctx, TT_ERR_IO, "cannot write in folder %s: "
                              "creating %s.lock failed: %s", out->dir,
                              out->temp_stem, strerror(e));
      free(failed);
      return s;
    }
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
    int made_errno = errno;
    pthread_mutex_lock(&live_lock);
    release_owner(out);
    pthread_mutex_unlock(&live_lock);
    errno = made_errno;
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

/* A tt__owner_mine_fn: whether a live output of this process has stem
 * (stems are random: a same stem in another folder only spares it once). */
static int stem_is_live(const char *dir, const char *stem)
{
  (void)dir;
  int mine = 0;
  pthread_mutex_lock(&live_lock);
  for (tt_output *o = live_head; o && !mine; o = o->next)
    mine = o->temp_stem && strcmp(o->temp_stem, stem) == 0;
  pthread_mutex_unlock(&live_lock);
  return mine;
}

/* A tt_log_fn: the sweep's notes as the context's warnings. */
static void warn_note(void *user, const char *message)
{
  tt__warn(user, "%s", message);
}

size_t tt_output_remove_stale(const char *path, tt_log_fn note, void *user)
{
  if (!path || !*path)
    return 0;
  const char *slash = strrchr(path, '/');
  char *dir = !slash ? str_printf(".")
              : slash == path ? str_printf("/")
                              : str_printf("%.*s", (int)(slash - path), path);
  size_t n = dir ? tt__owner_sweep(dir, stem_is_live, note, user) : 0;
  free(dir);
  return n;
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
  out->owner_fd = -1;
  out->shapefile = strcasecmp(format, "ESRI Shapefile") == 0;
  out->sqlite = strcasecmp(format, "GPKG") == 0 ||
                strcasecmp(format, "SQLite") == 0;
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
  if (s == TT_OK) /* what killed runs left there */
    tt__owner_sweep(out->dir, stem_is_live, warn_note, ctx);
  if (s == TT_OK)
    s = make_temp(ctx, out, ext);

done:
  free(name);
  if (s != TT_OK) {
    tt_output_destroy(out);
    return s;
  }
  pthread_mutex_lock(&live_lock);
  out->next = live_head;
  if (live_head)
    live_head->prev = out;
  live_head = out;
  pthread_mutex_unlock(&live_lock);
  *out_output = out;
  return TT_OK;
}

tt_status tt_output_add_sidecar(tt_context *ctx, tt_output *out,
                                const char *suffix)
{
  if (!out || out->shapefile || !suffix || !*suffix || strchr(suffix, '/'))
    return tt__error(ctx, TT_ERR_ARG, "tt_output_add_sidecar: a suffix for "
                     "a single-file output");
  if (!tt__grow((void **)&out->sidecars, &out->capsidecars,
                out->nsidecars + 1, sizeof *out->sidecars))
    return tt__error(ctx, TT_ERR_NOMEM, "out of memory");
  char *p = str_printf("%s/%s%s", out->dir, out->final_stem, suffix);
  if (!p)
    return tt__error(ctx, TT_ERR_NOMEM, "out of memory");
  out->sidecars[out->nsidecars++] = p;
  return check_sidecar(ctx, out, p);
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

/* Whether the file starts with SQLite's header string. */
static int is_sqlite_file(const char *path)
{
  static const char magic[16] = "SQLite format 3";
  char head[16];
  int fd = open(path, O_RDONLY | O_NONBLOCK | O_NOFOLLOW);
  if (fd < 0)
    return 0;
  ssize_t n = read(fd, head, sizeof head);
  close(fd);
  return n == (ssize_t)sizeof head && memcmp(head, magic, sizeof head) == 0;
}

/* Puts back what move_aside() moved: from[i] was renamed to to[i]. */
static void move_back(char **from, char **to, size_t n)
{
  while (n > 0) {
    n--;
    rename(to[n], from[n]);
  }
}

/* Single file (or a driver's folder): sidecars under the temporary stem
 * first, then the old name's stale SQLite sidecars and (when a folder is
 * involved) the old output moved aside, the dataset renamed into place
 * last, and what was moved aside deleted. rename() replaces an old file
 * atomically; a folder needs the move aside. */
static tt_status commit_single(tt_context *ctx, tt_output *out)
{
  struct stat tst, fst;
  if (lstat(out->temp_path, &tst) != 0)
    return tt__error(ctx, TT_ERR_IO, "nothing was written to %s",
                     out->temp_path);
  const int folder = S_ISDIR(tst.st_mode);
  const char *slash = strrchr(out->final_path, '/');
  const char *final_name = slash ? slash + 1 : out->final_path;
  if (folder && strchr(final_name + 1, '.'))
    return tt__error(ctx, TT_ERR_FORMAT, "%s: the driver wrote a folder of "
                     "files, not one file; name the output without an "
                     "extension to get that folder", out->final_path);
  if (!folder && !out->sqlite && is_sqlite_file(out->temp_path))
    out->sqlite = 1;
  tt_status s = check_finals(ctx, out);
  if (s != TT_OK)
    return s;

  size_t n = strlen(out->temp_stem);
  const char *main_name = out->temp_path + strlen(out->dir) + 1;
  DIR *d = opendir(out->dir);
  if (!d)
    return tt__error(ctx, TT_ERR_IO, "cannot list folder %s: %s", out->dir,
                     strerror(errno));
  struct dirent *e;
  while (s == TT_OK && (e = readdir(d)) != NULL) {
    if (strncmp(e->d_name, out->temp_stem, n) != 0 ||
        strcmp(e->d_name, main_name) == 0 ||
        strcmp(e->d_name + n, ".lock") == 0)
      continue; /* the lock is the run's, not a sidecar */
    char *from = str_printf("%s/%s", out->dir, e->d_name);
    char *to = str_printf("%s/%s%s", out->dir, out->final_stem,
                          e->d_name + n);
    struct stat st;
    if (!from || !to)
      s = tt__error(ctx, TT_ERR_NOMEM, "out of memory");
    else if (lstat(to, &st) == 0 && !S_ISREG(st.st_mode))
      s = refuse_kind(ctx, to, st.st_mode);
    else if (!out->overwrite && path_exists(to))
      s = tt__error(ctx, TT_ERR_EXISTS, "%s exists; not overwriting it "
                    "without permission", to);
    if (s == TT_OK)
      s = refuse_protected(ctx, out, to);
    if (s == TT_OK && rename(from, to) != 0)
      s = tt__error(ctx, TT_ERR_IO, "cannot rename %s to %s: %s", from, to,
                    strerror(errno));
    free(from);
    free(to);
  }
  closedir(d);
  if (s != TT_OK)
    return s;
  if (!out->overwrite) {
    /* link() refuses an existing target atomically; folders and file
     * systems without hard links fall back to check-then-rename. */
    if (!folder && link(out->temp_path, out->final_path) == 0) {
      unlink(out->temp_path);
      return TT_OK;
    }
    if (errno == EEXIST || path_exists(out->final_path))
      return tt__error(ctx, TT_ERR_EXISTS, "%s exists; not overwriting it "
                       "without permission", out->final_path);
    if (rename(out->temp_path, out->final_path) != 0)
      return tt__error(ctx, TT_ERR_IO, "cannot rename %s to %s: %s",
                       out->temp_path, out->final_path, strerror(errno));
    return TT_OK;
  }

  /* -overwrite: move aside the old name's SQLite sidecars (stale: nothing
   * holds the file open, check_finals saw to that) and, when the old or the
   * new output is a folder, the old output itself. */
  char *from[N_OF(sqlite_sidecars) + 1], *to[N_OF(sqlite_sidecars) + 1];
  size_t moved = 0;
  int old_aside = 0;
  for (size_t i = 0; out->sqlite && i < N_OF(sqlite_sidecars); i++) {
    from[moved] = str_printf("%s%s", out->final_path, sqlite_sidecars[i]);
    to[moved] = str_printf("%s/%s%s%s", out->dir, out->temp_stem,
                           TT_OLD_SUFFIX, sqlite_sidecars[i]);
    if (!from[moved] || !to[moved]) {
      free(from[moved]);
      free(to[moved]);
      s = tt__error(ctx, TT_ERR_NOMEM, "out of memory");
      break;
    }
    if (!path_exists(from[moved])) {
      free(from[moved]);
      free(to[moved]);
      continue;
    }
    if (rename(from[moved], to[moved]) != 0) {
      s = tt__error(ctx, TT_ERR_IO, "cannot move the stale %s aside: %s",
                    from[moved], strerror(errno));
      free(from[moved]);
      free(to[moved]);
      break;
    }
    moved++;
  }
  if (s == TT_OK && lstat(out->final_path, &fst) == 0 &&
      (folder || S_ISDIR(fst.st_mode))) {
    from[moved] = str_printf("%s", out->final_path);
    to[moved] = str_printf("%s/%s%s", out->dir, out->temp_stem,
                           TT_OLD_SUFFIX);
    if (!from[moved] || !to[moved]) {
      free(from[moved]);
      free(to[moved]);
      s = tt__error(ctx, TT_ERR_NOMEM, "out of memory");
    } else if (rename(from[moved], to[moved]) != 0) {
      s = tt__error(ctx, TT_ERR_IO, "cannot move the old %s aside: %s",
                    out->final_path, strerror(errno));
      free(from[moved]);
      free(to[moved]);
    } else {
      old_aside = 1;
      moved++;
    }
  }
  if (s == TT_OK && rename(out->temp_path, out->final_path) != 0)
    s = tt__error(ctx, TT_ERR_IO, "cannot rename %s to %s: %s",
                  out->temp_path, out->final_path, strerror(errno));
  if (s != TT_OK) {
    move_back(from, to, moved);
  } else {
    for (size_t i = 0; i < moved; i++) {
      struct stat st;
      if (old_aside && i == moved - 1 && lstat(to[i], &st) == 0 &&
          S_ISDIR(st.st_mode))
        tt__owner_remove_tree(to[i]);
      else
        unlink(to[i]);
    }
  }
  for (size_t i = 0; i < moved; i++) {
    free(from[i]);
    free(to[i]);
  }
  return s;
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
    struct stat st;
    if (!p)
      s = tt__error(ctx, TT_ERR_NOMEM, "out of memory");
    else if (lstat(p, &st) == 0 && !S_ISREG(st.st_mode))
      s = refuse_kind(ctx, p, st.st_mode);
    else if (!out->overwrite && path_exists(p))
      s = tt__error(ctx, TT_ERR_EXISTS, "%s exists; not overwriting it "
                    "without permission", p);
    if (s == TT_OK && p)
      s = refuse_protected(ctx, out, p);
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
  tt__owner_remove_tree(out->temp_path);
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
      /* Keep the temporary folder: the user's old files are in it (and
       * no sweep may take it for a dead run's). */
      out->keep_temp = 1;
      release_owner(out);
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
  pthread_mutex_lock(&live_lock);
  tt_status s;
  if (out->abandoned)
    s = tt__error(ctx, TT_ERR_INTERRUPTED, "%s: interrupted; the temporary "
                  "files were removed", out->final_path);
  else
    s = out->shapefile ? commit_shapefile(ctx, out) : commit_single(ctx, out);
  if (s == TT_OK)
    out->committed = 1;
  pthread_mutex_unlock(&live_lock);
  return s;
}

/* Appends src[0..n) to buf at *len, truncating. */
static void put_text(char *buf, size_t size, size_t *len, const char *src,
                     size_t n)
{
  if (*len + 1 >= size)
    return;
  if (n > size - 1 - *len)
    n = size - 1 - *len;
  memcpy(buf + *len, src, n);
  *len += n;
  buf[*len] = '\0';
}

/* buf = text with every `from` replaced by `to` (and, when `from_dir` is
 * set, every "from/" by "to_dir/"); 1 when one was found. */
static int replace_name(const char *text, const char *from, const char *to,
                        const char *to_dir, char *buf, size_t size)
{
  size_t len = 0, n = strlen(from);
  int found = 0;
  buf[0] = '\0';
  for (const char *p = text; *p;) {
    const char *q = n ? strstr(p, from) : NULL;
    if (!q) {
      put_text(buf, size, &len, p, strlen(p));
      break;
    }
    found = 1;
    put_text(buf, size, &len, p, (size_t)(q - p));
    if (to_dir && q[n] == '/') {
      /* a file inside a temporary folder: it goes to the final folder */
      if (strcmp(to_dir, ".") != 0) {
        put_text(buf, size, &len, to_dir, strlen(to_dir));
        put_text(buf, size, &len, "/", 1);
      }
      p = q + n + 1;
    } else {
      put_text(buf, size, &len, to, strlen(to));
      p = q + n;
    }
  }
  return found;
}

int tt_output_rename_in_text(const char *text, char *buf, size_t size)
{
  if (!buf || size == 0)
    return 0;
  buf[0] = '\0';
  if (!text)
    return 0;
  char *tmp = malloc(size);
  if (!tmp) {
    snprintf(buf, size, "%s", text);
    return 0;
  }
  snprintf(buf, size, "%s", text);
  int found = 0;
  pthread_mutex_lock(&live_lock);
  for (tt_output *o = live_head; o; o = o->next) {
    if (!o->temp_path || !o->final_path)
      continue;
    if (replace_name(buf, o->temp_path, o->final_path,
                     o->shapefile ? o->dir : NULL, tmp, size)) {
      found = 1;
      snprintf(buf, size, "%s", tmp);
    }
    /* the bare temporary file name (a driver that names the file only) */
    const char *tb = strrchr(o->temp_path, '/');
    const char *fb = strrchr(o->final_path, '/');
    tb = tb ? tb + 1 : o->temp_path;
    fb = fb ? fb + 1 : o->final_path;
    if (replace_name(buf, tb, fb, NULL, tmp, size)) {
      found = 1;
      snprintf(buf, size, "%s", tmp);
    }
  }
  pthread_mutex_unlock(&live_lock);
  free(tmp);
  return found;
}
