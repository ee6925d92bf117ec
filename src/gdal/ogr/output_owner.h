/*
 * src/gdal/ogr/ -- the OGR layers: a TIN written into an OGR dataset and
 * triangles read from one, the features' records, QGIS's default style,
 * safe output paths and the protection of the input's files.
 *
 * output_owner.h -- who owns a temporary name of output_path.c: the lock
 * file `.ttXXXXXXXX.lock` beside the temporaries, held with flock() by the
 * run that made them, and the sweep that removes the temporaries of runs
 * that no longer hold theirs (killed: SIGKILL, a crash, a power cut).
 */
#ifndef TERRATIN_OUTPUT_OWNER_H
#define TERRATIN_OUTPUT_OWNER_H

#include "base/internal.h"
#include "terratin/terratin_gdal.h"

/* What tt__owner_take found. */
enum {
  TT__OWNER_TAKEN = 0,  /* *out_fd holds the lock of dir/stem.lock */
  TT__OWNER_CLASH = 1,  /* the stem is someone else's: try another */
  TT__OWNER_NONE = 2,   /* the file system has no flock(): no lock, go on */
  TT__OWNER_FAILED = 3  /* the folder refused a file: errno says why */
};

/* Takes the ownership of the temporary stem (".ttXXXXXXXX") in dir: makes
 * dir/stem.lock, already locked when it appears (made as stem.new, locked,
 * then linked to its name), so a sweep never sees it unlocked while its
 * owner lives. *out_fd is -1 unless TT__OWNER_TAKEN. */
TT_HIDDEN int tt__owner_take(const char *dir, const char *stem, int *out_fd);

/* Gives the ownership up: removes dir/stem.lock and closes fd (-1: none).
 * Called after the temporaries are gone, or when they must never be swept
 * (they hold the user's files). */
TT_HIDDEN void tt__owner_release(const char *dir, const char *stem, int fd);

/* Removes a folder and the files and folders in it (symbolic links are
 * removed, not followed). */
TT_HIDDEN void tt__owner_remove_tree(const char *path);

/* Whether stem in dir belongs to a live output of this process (where
 * flock() is emulated by POSIX locks, on NFS, a process's own lock does
 * not stop itself). */
typedef int (*tt__owner_mine_fn)(const char *dir, const char *stem);

/* Removes, in dir, the temporaries of every stem whose lock file is not
 * held (its run is gone), the lock file last; note(user, message) is told
 * "removed stale temporary PATH (left by a killed run)" for each stem.
 * Temporaries without a lock file, those whose lock is held (a run in
 * progress, in this process or another) and those mine() claims are never
 * touched. Returns how many stems were removed. */
TT_HIDDEN size_t tt__owner_sweep(const char *dir, tt__owner_mine_fn mine,
                                 tt_log_fn note, void *user);

#endif /* TERRATIN_OUTPUT_OWNER_H */
