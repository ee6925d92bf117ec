/*
 * src/gdal/ogr/ -- the OGR layers: a TIN written into an OGR dataset and
 * triangles read from one, the features' records, QGIS's default style,
 * safe output paths and the protection of the input's files.
 *
 * output_owner.c -- who owns a temporary name. A run cannot clean up after
 * SIGKILL (or a crash, a power cut): its `.ttXXXXXXXX.gpkg` stays, hidden
 * and half written. So each stem has an owner: the lock file
 * `.ttXXXXXXXX.lock` beside it, held with flock() for as long as the run
 * lives; the kernel lets go of the lock when the process ends, however it
 * ends. The next run into the folder (tt__owner_sweep) removes the
 * temporaries of every stem whose lock it can take, and only those: a lock
 * it cannot take is a run in progress (in another process, or in this one,
 * since flock() locks belong to an open file, not to a process), and
 * temporaries without a lock file (an older terratin's, or kept because
 * they hold the user's files) are never touched. flock() works across PID
 * namespaces (containers) on one kernel and, on Linux, over NFS (as POSIX
 * locks), where a process's own locks do not stop it: the caller says
 * which stems are its own.
 *
 * Invariant: while its owner lives, dir/stem.lock names a locked file. It
 * is made as stem.new (exclusively), locked, then hard-linked to its name,
 * so it never appears unlocked; a sweep that catches stem.new in the
 * instant before its lock removes it, and the owner, whose link then fails,
 * picks another stem. A file system without flock() gets no lock file (its
 * temporaries are then never swept); one without hard links gets the lock
 * file made and locked at once under its name.
 *
 * POSIX plus flock(); no GDAL call. Workload: one directory listing per
 * output begun.
 */
#include "gdal/ogr/output_owner.h"

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#define STEM_LEN 11 /* ".tt" and 8 hex digits */

static char *join(const char *dir, const char *name, const char *suffix)
{
  size_t n = strlen(dir) + strlen(name) + strlen(suffix) + 2;
  char *p = malloc(n);
  if (p)
    snprintf(p, n, "%s/%s%s", dir, name, suffix);
  return p;
}

/* Whether name starts with a temporary stem; its suffix in *out_suffix. */
static int has_stem(const char *name, const char **out_suffix)
{
  if (strncmp(name, ".tt", 3) != 0)
    return 0;
  for (int i = 3; i < STEM_LEN; i++) {
    char c = name[i];
    if (!((c >= '0' && c <= '9') || (c >= 'a' && c <= 'f')))
      return 0;
  }
  *out_suffix = name + STEM_LEN;
  return 1;
}

int tt__owner_take(const char *dir, const char *stem, int *out_fd)
{
  *out_fd = -1;
  char *newp = join(dir, stem, ".new"), *lockp = join(dir, stem, ".lock");
  int r = TT__OWNER_FAILED, fd = -1;
  if (!newp || !lockp) {
    errno = ENOMEM;
    goto done;
  }
  fd = open(newp, O_RDWR | O_CREAT | O_EXCL | O_CLOEXEC | O_NOFOLLOW, 0666);
  if (fd < 0) {
    r = errno == EEXIST ? TT__OWNER_CLASH : TT__OWNER_FAILED;
    goto done;
  }
  if (flock(fd, LOCK_EX | LOCK_NB) != 0) {
    /* a sweep holds it (it removes it): another stem; or no flock() */
    int e = errno;
    close(fd);
    fd = -1;
    unlink(newp);
    r = e == EWOULDBLOCK || e == EINTR ? TT__OWNER_CLASH : TT__OWNER_NONE;
    goto done;
  }
  if (link(newp, lockp) == 0) {
    unlink(newp);
    r = TT__OWNER_TAKEN;
    goto done;
  }
  int e = errno;
  close(fd);
  fd = -1;
  unlink(newp);
  if (e == EEXIST || e == ENOENT) { /* taken, or swept before our lock */
    r = TT__OWNER_CLASH;
    goto done;
  }
  /* no hard links here: made and locked at once under its name */
  fd = open(lockp, O_RDWR | O_CREAT | O_EXCL | O_CLOEXEC | O_NOFOLLOW, 0666);
  if (fd < 0) {
    r = errno == EEXIST ? TT__OWNER_CLASH : TT__OWNER_FAILED;
    goto done;
  }
  if (flock(fd, LOCK_EX | LOCK_NB) != 0) {
    e = errno;
    close(fd);
    fd = -1;
    unlink(lockp);
    r = e == EWOULDBLOCK || e == EINTR ? TT__OWNER_CLASH : TT__OWNER_NONE;
    goto done;
  }
  r = TT__OWNER_TAKEN;

done:
  if (r == TT__OWNER_TAKEN)
    *out_fd = fd;
  free(newp);
  free(lockp);
  return r;
}

void tt__owner_release(const char *dir, const char *stem, int fd)
{
  if (fd < 0)
    return;
  char *lockp = join(dir, stem, ".lock");
  if (lockp)
    unlink(lockp);
  free(lockp);
  close(fd); /* the lock goes with the last descriptor */
}

void tt__owner_remove_tree(const char *path)
{
  DIR *d = opendir(path);
  if (d) {
    struct dirent *e;
    while ((e = readdir(d)) != NULL) {
      if (strcmp(e->d_name, ".") == 0 || strcmp(e->d_name, "..") == 0)
        continue;
      char *p = join(path, e->d_name, "");
      if (!p)
        continue;
      struct stat st;
      if (lstat(p, &st) == 0 && S_ISDIR(st.st_mode))
        tt__owner_remove_tree(p);
      else
        unlink(p);
      free(p);
    }
    closedir(d);
  }
  rmdir(path);
}

/* Takes the lock of dir/stem + suffix if its owner is gone: 1 and *out_fd
 * (-1 when there is no such file), or 0 when it is held (or is no plain
 * file, or changed under us: then it is not ours to judge). */
static int take_stale(const char *dir, const char *stem, const char *suffix,
                      int *out_fd)
{
  *out_fd = -1;
  char *p = join(dir, stem, suffix);
  if (!p)
    return 0;
  int ok = 0;
  int fd = open(p, O_RDONLY | O_CLOEXEC | O_NOFOLLOW | O_NONBLOCK);
  if (fd < 0) {
    ok = errno == ENOENT;
    goto done;
  }
  struct stat a, b;
  if (fstat(fd, &a) != 0 || !S_ISREG(a.st_mode) ||
      flock(fd, LOCK_EX | LOCK_NB) != 0 || lstat(p, &b) != 0 ||
      a.st_dev != b.st_dev || a.st_ino != b.st_ino) {
    close(fd);
    goto done;
  }
  *out_fd = fd;
  ok = 1;

done:
  free(p);
  return ok;
}

/* Whether the entry p (its stat st, its suffix after the stem) holds the
 * user's files: what a commit under -overwrite moved aside before the new
 * output took the name (STEM.old, STEM.old-journal, ...; a shapefile
 * folder's .old/). */
static int holds_user_files(const char *p, const struct stat *st,
                            const char *suffix)
{
  if (strncmp(suffix, ".old", 4) == 0)
    return 1;
  if (!S_ISDIR(st->st_mode))
    return 0;
  char *old = join(p, ".old", "");
  struct stat o;
  int yes = old && lstat(old, &o) == 0;
  free(old);
  return yes;
}

/* Removes the entries of dir that start with stem, but its lock files and
 * what holds the user's files (returns how many such were kept); the name
 * of one removed (the dataset rather than a sidecar: the shortest) into
 * shown, "" if none. */
static size_t remove_stem(const char *dir, const char *stem, char *shown,
                          size_t size)
{
  shown[0] = '\0';
  DIR *d = opendir(dir);
  if (!d)
    return 0;
  size_t best = 0, kept = 0;
  struct dirent *e;
  while ((e = readdir(d)) != NULL) {
    const char *suffix;
    if (!has_stem(e->d_name, &suffix) ||
        strncmp(e->d_name, stem, STEM_LEN) != 0 ||
        strcmp(suffix, ".lock") == 0 || strcmp(suffix, ".new") == 0)
      continue;
    char *p = join(dir, e->d_name, "");
    if (!p)
      continue;
    struct stat st;
    if (lstat(p, &st) != 0) {
      free(p);
      continue;
    }
    if (holds_user_files(p, &st, suffix)) {
      kept++;
      free(p);
      continue;
    }
    if (S_ISDIR(st.st_mode))
      tt__owner_remove_tree(p);
    else
      unlink(p);
    size_t n = strlen(e->d_name);
    if (!best || n < best) {
      best = n;
      snprintf(shown, size, "%s", strcmp(dir, ".") == 0 ? e->d_name : p);
    }
    free(p);
  }
  closedir(d);
  return kept;
}

size_t tt__owner_sweep(const char *dir, tt__owner_mine_fn mine,
                       tt_log_fn note, void *user)
{
  /* the stems that have a lock file, listed first: removing changes the
   * folder under readdir() */
  DIR *d = opendir(dir);
  if (!d)
    return 0;
  char (*stems)[STEM_LEN + 1] = NULL;
  size_t n = 0, cap = 0, removed = 0;
  struct dirent *e;
  while ((e = readdir(d)) != NULL) {
    const char *suffix;
    if (!has_stem(e->d_name, &suffix) ||
        (strcmp(suffix, ".lock") != 0 && strcmp(suffix, ".new") != 0))
      continue;
    size_t i = 0;
    while (i < n && strncmp(stems[i], e->d_name, STEM_LEN) != 0)
      i++;
    if (i < n)
      continue;
    if (!tt__grow((void **)&stems, &cap, n + 1, sizeof *stems))
      break;
    memcpy(stems[n], e->d_name, STEM_LEN);
    stems[n++][STEM_LEN] = '\0';
  }
  closedir(d);

  for (size_t i = 0; i < n; i++) {
    if (mine && mine(dir, stems[i]))
      continue;
    int lock_fd, new_fd;
    if (!take_stale(dir, stems[i], ".lock", &lock_fd))
      continue;
    if (!take_stale(dir, stems[i], ".new", &new_fd)) {
      if (lock_fd >= 0)
        close(lock_fd);
      continue;
    }
    /* What holds the user's files is kept, without its lock file: never
     * swept again, for the user to take back. */
    char shown[4096];
    size_t kept = remove_stem(dir, stems[i], shown, sizeof shown);
    char *lockp = join(dir, stems[i], ".lock");
    char *newp = join(dir, stems[i], ".new");
    /* only a lock file was left: it is what the note names */
    const char *left = lock_fd >= 0 ? lockp : newp;
    if (!shown[0] && left)
      snprintf(shown, sizeof shown, "%s",
               strcmp(dir, ".") == 0 ? left + 2 : left);
    if (newp && new_fd >= 0)
      unlink(newp);
    if (lockp && lock_fd >= 0)
      unlink(lockp);
    free(lockp);
    free(newp);
    if (new_fd >= 0)
      close(new_fd);
    if (lock_fd >= 0)
      close(lock_fd);
    if (note) {
      char msg[4300];
      snprintf(msg, sizeof msg,
               "removed stale temporary %s (left by a killed run)%s", shown,
               kept ? "; kept the files it had moved aside, which start with "
                      "the same name" : "");
      note(user, msg);
    }
    removed++;
  }
  free(stems);
  return removed;
}
