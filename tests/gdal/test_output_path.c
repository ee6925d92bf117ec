/*
 * test_output_path.c -- tt_output_begin/temp_path/commit/destroy with real
 * GDAL datasets: GPKG (single file) and ESRI Shapefile (a temporary folder
 * whose files move into place). Checks: the temporary name sits beside the
 * final one with the same extension; commit leaves exactly the final files
 * in the folder; an existing output is refused without overwrite (one line
 * naming the path) and replaced with it, including stale shapefile sidecars;
 * unwritable folders are refused up front (a missing folder and /proc: the
 * tests run as root, where access() ignores permissions); a write abandoned
 * in the middle leaves the old files untouched and no temporary file.
 * Issue 11: FIFOs, devices and symbolic links are never replaced; a 255-byte
 * name works; folder outputs (FlatGeobuf) are removed on failure, renamed
 * into place and replaced only when they hold layer files alone; protected
 * (input) files are refused under any name; stale SQLite sidecars are
 * refused or removed; abandoning removes the temporary files. Stale
 * temporaries: removed when their lock file is held by nobody, spared when
 * a live output of this process holds it, kept when they hold the user's
 * moved-aside files or have no lock file.
 */
#include "terratin/terratin_gdal.h"
#include "tt_test.h"

#include <cpl_string.h>
#include <cpl_vsi.h>

#include <dirent.h>
#include <stdlib.h>
#include <sys/stat.h>
#include <unistd.h>

static char tmpdir[256];

static int cmp_str(const void *a, const void *b)
{
  return strcmp(*(char *const *)a, *(char *const *)b);
}

/* The folder's entries, sorted, joined by spaces. */
static void list_dir(const char *dir, char *buf, size_t size)
{
  char *names[256];
  int n = 0;
  DIR *d = opendir(dir);
  struct dirent *e;
  buf[0] = '\0';
  if (!d)
    return;
  while ((e = readdir(d)) != NULL && n < 256)
    if (strcmp(e->d_name, ".") && strcmp(e->d_name, ".."))
      names[n++] = strdup(e->d_name);
  closedir(d);
  qsort(names, (size_t)n, sizeof *names, cmp_str);
  size_t used = 0;
  for (int i = 0; i < n; i++) {
    int w = snprintf(buf + used, size - used, "%s%s", i ? " " : "",
                     names[i]);
    if (w > 0 && (size_t)w < size - used)
      used += (size_t)w;
    free(names[i]);
  }
}

/* Writes a vector dataset at path with the given layers, each with one
 * point feature whose field "tag" is tag. Returns the open dataset when
 * keep_open (an abandoned write), else closes it. */
static GDALDatasetH write_vector(const char *driver, const char *path,
                                 const char *const *layers, int tag,
                                 int keep_open)
{
  GDALDatasetH ds = GDALCreate(GDALGetDriverByName(driver), path, 0, 0, 0,
                               GDT_Unknown, NULL);
  if (!ds) {
    TT_FAIL_("cannot create %s with %s: %s", path, driver,
             CPLGetLastErrorMsg());
    return NULL;
  }
  OGRSpatialReferenceH srs = OSRNewSpatialReference(NULL);
  OSRImportFromEPSG(srs, 32610);
  for (int i = 0; layers[i]; i++) {
    int table = strstr(layers[i], "run_parameters") != NULL;
    OGRLayerH l = GDALDatasetCreateLayer(ds, layers[i], table ? NULL : srs,
                                         table ? wkbNone : wkbPoint25D,
                                         NULL);
    CHECK(l != NULL);
    OGRFieldDefnH fd = OGR_Fld_Create("tag", OFTInteger);
    OGR_L_CreateField(l, fd, TRUE);
    OGR_Fld_Destroy(fd);
    OGRFeatureH f = OGR_F_Create(OGR_L_GetLayerDefn(l));
    OGR_F_SetFieldInteger(f, 0, tag);
    if (!table) {
      OGRGeometryH g = OGR_G_CreateGeometry(wkbPoint25D);
      OGR_G_SetPoint(g, 0, 1, 2, 3);
      OGR_F_SetGeometryDirectly(f, g);
    }
    CHECK(OGR_L_CreateFeature(l, f) == OGRERR_NONE);
    OGR_F_Destroy(f);
  }
  OSRDestroySpatialReference(srs);
  if (keep_open)
    return ds;
  GDALClose(ds);
  return NULL;
}

/* The "tag" of the first feature of layer in path, -1 when unreadable. */
static int read_tag(const char *path, const char *layer)
{
  GDALDatasetH ds = GDALOpenEx(path, GDAL_OF_VECTOR, NULL, NULL, NULL);
  if (!ds)
    return -1;
  OGRLayerH l = GDALDatasetGetLayerByName(ds, layer);
  int tag = -1;
  if (l) {
    OGRFeatureH f = OGR_L_GetNextFeature(l);
    if (f) {
      tag = OGR_F_GetFieldAsInteger(f, 0);
      OGR_F_Destroy(f);
    }
  }
  GDALClose(ds);
  return tag;
}

static void test_gpkg(tt_context *ctx)
{
  char dir[300], path[400], listing[4096];
  snprintf(dir, sizeof dir, "%s/gpkg", tmpdir);
  mkdir(dir, 0777);
  snprintf(path, sizeof path, "%s/tin.gpkg", dir);
  const char *layers[] = {"triangles", "vertices", "run_parameters", NULL};

  /* Nothing written: commit fails, nothing left. */
  tt_output *out = NULL;
  CHECK_OK(ctx, tt_output_begin(ctx, path, "GPKG", 0, &out));
  CHECK_INT_EQ(tt_output_commit(ctx, out), TT_ERR_IO);
  tt_output_destroy(out);
  list_dir(dir, listing, sizeof listing);
  CHECK_STR_EQ(listing, "");

  /* A first write. */
  out = NULL;
  CHECK_OK(ctx, tt_output_begin(ctx, path, "GPKG", 0, &out));
  if (!out)
    return;
  const char *tmp = tt_output_temp_path(out);
  char prefix[400];
  snprintf(prefix, sizeof prefix, "%s/.tt", dir);
  CHECK(strncmp(tmp, prefix, strlen(prefix)) == 0);
  CHECK(strcmp(tmp + strlen(tmp) - 5, ".gpkg") == 0);
  CHECK(access(tmp, F_OK) != 0);
  CHECK_STR_EQ(tt_output_layer_prefix(out), "");
  CHECK_STR_EQ(tt_output_final_path(out), path);
  write_vector("GPKG", tmp, layers, 1, 0);
  CHECK(access(path, F_OK) != 0); /* not there before commit */
  CHECK_OK(ctx, tt_output_commit(ctx, out));
  tt_output_destroy(out);
  list_dir(dir, listing, sizeof listing);
  CHECK_STR_EQ(listing, "tin.gpkg");
  CHECK_INT_EQ(read_tag(path, "vertices"), 1);

  /* Exists, no overwrite: refused in one line naming the path. */
  out = NULL;
  CHECK_INT_EQ(tt_output_begin(ctx, path, "GPKG", 0, &out), TT_ERR_EXISTS);
  CHECK(out == NULL);
  CHECK(strstr(tt_context_errmsg(ctx), path) != NULL);
  CHECK(strchr(tt_context_errmsg(ctx), '\n') == NULL);

  /* Overwrite, abandoned in the middle: the old file stays, no leftovers. */
  CHECK_OK(ctx, tt_output_begin(ctx, path, "GPKG", 1, &out));
  if (out) {
    GDALDatasetH ds = write_vector("GPKG", tt_output_temp_path(out), layers,
                                   2, 1);
    GDALClose(ds); /* the write "failed": no commit */
    tt_output_destroy(out);
  }
  list_dir(dir, listing, sizeof listing);
  CHECK_STR_EQ(listing, "tin.gpkg");
  CHECK_INT_EQ(read_tag(path, "vertices"), 1);

  /* Overwrite for real. */
  out = NULL;
  CHECK_OK(ctx, tt_output_begin(ctx, path, "GPKG", 1, &out));
  if (out) {
    write_vector("GPKG", tt_output_temp_path(out), layers, 3, 0);
    CHECK_OK(ctx, tt_output_commit(ctx, out));
    /* A second commit is refused. */
    CHECK_INT_EQ(tt_output_commit(ctx, out), TT_ERR_ARG);
    tt_output_destroy(out);
  }
  list_dir(dir, listing, sizeof listing);
  CHECK_STR_EQ(listing, "tin.gpkg");
  CHECK_INT_EQ(read_tag(path, "vertices"), 3);

  /* The final file appears between begin and commit: refused at commit,
   * the newcomer kept. */
  char path2[400];
  snprintf(path2, sizeof path2, "%s/race.gpkg", dir);
  out = NULL;
  CHECK_OK(ctx, tt_output_begin(ctx, path2, "GPKG", 0, &out));
  if (out) {
    write_vector("GPKG", tt_output_temp_path(out), layers, 4, 0);
    write_vector("GPKG", path2, layers, 5, 0);
    CHECK_INT_EQ(tt_output_commit(ctx, out), TT_ERR_EXISTS);
    tt_output_destroy(out);
  }
  CHECK_INT_EQ(read_tag(path2, "vertices"), 5);
  list_dir(dir, listing, sizeof listing);
  CHECK_STR_EQ(listing, "race.gpkg tin.gpkg");

  /* A folder in the way is refused even with overwrite. */
  char sub[400];
  snprintf(sub, sizeof sub, "%s/sub.gpkg", dir);
  mkdir(sub, 0777);
  CHECK_INT_EQ(tt_output_begin(ctx, sub, "GPKG", 1, &out), TT_ERR_EXISTS);
  rmdir(sub);
  snprintf(sub, sizeof sub, "%s/", dir);
  CHECK_INT_EQ(tt_output_begin(ctx, sub, "GPKG", 1, &out), TT_ERR_ARG);
}

static void test_unwritable(tt_context *ctx)
{
  tt_output *out = NULL;
  char path[400];
  snprintf(path, sizeof path, "%s/no/such/folder/tin.gpkg", tmpdir);
  CHECK_INT_EQ(tt_output_begin(ctx, path, "GPKG", 0, &out), TT_ERR_IO);
  CHECK(out == NULL);
  CHECK(strstr(tt_context_errmsg(ctx), "no/such/folder") != NULL);
  CHECK_INT_EQ(tt_output_begin(ctx, path, "ESRI Shapefile", 1, &out),
               TT_ERR_IO);
  /* /proc refuses new files even to root. */
  CHECK_INT_EQ(tt_output_begin(ctx, "/proc/tin.gpkg", "GPKG", 1, &out),
               TT_ERR_IO);
  CHECK_INT_EQ(tt_output_begin(ctx, "/proc/tin.shp", "ESRI Shapefile", 1,
                               &out),
               TT_ERR_IO);
  CHECK(out == NULL);
  /* A file where the folder should be. */
  snprintf(path, sizeof path, "%s/plain", tmpdir);
  FILE *f = fopen(path, "w");
  fclose(f);
  snprintf(path, sizeof path, "%s/plain/tin.gpkg", tmpdir);
  CHECK_INT_EQ(tt_output_begin(ctx, path, "GPKG", 0, &out), TT_ERR_IO);
  CHECK_INT_EQ(tt_output_begin(ctx, "", "GPKG", 0, &out), TT_ERR_ARG);
  CHECK_INT_EQ(tt_output_begin(ctx, "x.gpkg", NULL, 0, &out), TT_ERR_ARG);
  tt_output_destroy(NULL);
}

static const char *const shp_layers[] = {"tin_triangles", "tin_vertices",
                                         "tin_run_parameters", NULL};

static void shp_write(tt_output *out, int tag, int abandon)
{
  char ds_path[600];
  snprintf(ds_path, sizeof ds_path, "%s", tt_output_temp_path(out));
  GDALDatasetH ds = write_vector("ESRI Shapefile", ds_path, shp_layers, tag,
                                 abandon);
  if (ds)
    GDALClose(ds);
}

static void test_shapefile(tt_context *ctx)
{
  char dir[300], path[400], listing[4096], probe[500];
  snprintf(dir, sizeof dir, "%s/shp", tmpdir);
  mkdir(dir, 0777);
  /* Someone else's files in the same folder are left alone. */
  snprintf(probe, sizeof probe, "%s/other.txt", dir);
  FILE *f = fopen(probe, "w");
  fclose(f);
  snprintf(path, sizeof path, "%s/tin.shp", dir);

  tt_output *out = NULL;
  CHECK_OK(ctx, tt_output_begin(ctx, path, "ESRI Shapefile", 0, &out));
  if (!out)
    return;
  CHECK_STR_EQ(tt_output_layer_prefix(out), "tin_");
  struct stat st;
  CHECK(stat(tt_output_temp_path(out), &st) == 0 && S_ISDIR(st.st_mode));
  char prefix[400];
  snprintf(prefix, sizeof prefix, "%s/.tt", dir);
  CHECK(strncmp(tt_output_temp_path(out), prefix, strlen(prefix)) == 0);
  shp_write(out, 1, 0);
  list_dir(dir, listing, sizeof listing);
  CHECK(strstr(listing, "tin_") == NULL); /* nothing final before commit */
  CHECK_OK(ctx, tt_output_commit(ctx, out));
  tt_output_destroy(out);
  list_dir(dir, listing, sizeof listing);
  const char *expect =
      "other.txt tin_run_parameters.dbf tin_triangles.dbf tin_triangles.prj "
      "tin_triangles.shp tin_triangles.shx tin_vertices.dbf "
      "tin_vertices.prj tin_vertices.shp tin_vertices.shx";
  CHECK_STR_EQ(listing, expect);
  snprintf(probe, sizeof probe, "%s/tin_vertices.shp", dir);
  CHECK_INT_EQ(read_tag(probe, "tin_vertices"), 1);

  /* Exists: refused, whether OUTPUT is name or name.shp. */
  char bare[400];
  snprintf(bare, sizeof bare, "%s/tin", dir);
  out = NULL;
  CHECK_INT_EQ(tt_output_begin(ctx, bare, "ESRI Shapefile", 0, &out),
               TT_ERR_EXISTS);
  CHECK(strstr(tt_context_errmsg(ctx), "tin_triangles.shp") != NULL);
  CHECK_INT_EQ(tt_output_begin(ctx, path, "ESRI Shapefile", 0, &out),
               TT_ERR_EXISTS);
  /* One stray file of our names is enough. */
  char other[400];
  snprintf(other, sizeof other, "%s/tan.shp", dir);
  snprintf(probe, sizeof probe, "%s/tan_vertices.qix", dir);
  f = fopen(probe, "w");
  fclose(f);
  CHECK_INT_EQ(tt_output_begin(ctx, other, "ESRI Shapefile", 0, &out),
               TT_ERR_EXISTS);
  CHECK(strstr(tt_context_errmsg(ctx), "tan_vertices.qix") != NULL);
  unlink(probe);

  /* Abandoned overwrite: old files intact, temporary folder gone. */
  snprintf(probe, sizeof probe, "%s/tin_vertices.qix", dir);
  f = fopen(probe, "w"); /* a stale index of the old data */
  fclose(f);
  CHECK_OK(ctx, tt_output_begin(ctx, bare, "ESRI Shapefile", 1, &out));
  if (out) {
    CHECK_STR_EQ(tt_output_layer_prefix(out), "tin_");
    shp_write(out, 2, 1);
    tt_output_destroy(out);
  }
  char listing2[4096];
  list_dir(dir, listing2, sizeof listing2);
  char expect_qix[4096];
  snprintf(expect_qix, sizeof expect_qix,
           "other.txt tin_run_parameters.dbf tin_triangles.dbf "
           "tin_triangles.prj tin_triangles.shp tin_triangles.shx "
           "tin_vertices.dbf tin_vertices.prj tin_vertices.qix "
           "tin_vertices.shp tin_vertices.shx");
  CHECK_STR_EQ(listing2, expect_qix);
  snprintf(probe, sizeof probe, "%s/tin_vertices.shp", dir);
  CHECK_INT_EQ(read_tag(probe, "tin_vertices"), 1);

  /* Overwrite: new data, and the stale .qix is gone. */
  out = NULL;
  CHECK_OK(ctx, tt_output_begin(ctx, path, "ESRI Shapefile", 1, &out));
  if (out) {
    shp_write(out, 7, 0);
    CHECK_OK(ctx, tt_output_commit(ctx, out));
    tt_output_destroy(out);
  }
  list_dir(dir, listing, sizeof listing);
  CHECK_STR_EQ(listing, expect);
  CHECK_INT_EQ(read_tag(probe, "tin_vertices"), 7);
  snprintf(probe, sizeof probe, "%s/tin_run_parameters.dbf", dir);
  CHECK_INT_EQ(read_tag(probe, "tin_run_parameters"), 7);

  /* A folder appears under a final name between begin and commit: refused
   * at commit, nothing moved. */
  out = NULL;
  CHECK_OK(ctx, tt_output_begin(ctx, path, "ESRI Shapefile", 1, &out));
  if (out) {
    shp_write(out, 8, 0);
    snprintf(probe, sizeof probe, "%s/tin_vertices.sbn", dir);
    mkdir(probe, 0777);
    CHECK_INT_EQ(tt_output_commit(ctx, out), TT_ERR_EXISTS);
    tt_output_destroy(out);
    rmdir(probe);
  }
  list_dir(dir, listing, sizeof listing);
  CHECK_STR_EQ(listing, expect);
  snprintf(probe, sizeof probe, "%s/tin_vertices.shp", dir);
  CHECK_INT_EQ(read_tag(probe, "tin_vertices"), 7);

  /* A relative OUTPUT without a folder works in the current folder. */
  char cwd[512];
  CHECK(getcwd(cwd, sizeof cwd) != NULL);
  CHECK(chdir(dir) == 0);
  out = NULL;
  CHECK_OK(ctx, tt_output_begin(ctx, "rel", "ESRI Shapefile", 0, &out));
  if (out) {
    CHECK_STR_EQ(tt_output_layer_prefix(out), "rel_");
    tt_output_destroy(out);
  }
  CHECK(chdir(cwd) == 0);
  list_dir(dir, listing, sizeof listing);
  CHECK_STR_EQ(listing, expect);
}

/* Issue 11 item 7: -overwrite replaces regular files only (and a folder
 * output's own folder, below): a FIFO, a symbolic link to /dev/null and a
 * character device stay. */
static void test_not_regular(tt_context *ctx)
{
  char dir[300], path[400];
  tt_output *out = NULL;
  snprintf(dir, sizeof dir, "%s/kinds", tmpdir);
  mkdir(dir, 0777);
  snprintf(path, sizeof path, "%s/fifo.gpkg", dir);
  CHECK(mkfifo(path, 0666) == 0);
  CHECK_INT_EQ(tt_output_begin(ctx, path, "GPKG", 1, &out), TT_ERR_EXISTS);
  CHECK(strstr(tt_context_errmsg(ctx), "FIFO") != NULL);
  CHECK(out == NULL);
  snprintf(path, sizeof path, "%s/null.gpkg", dir);
  CHECK(symlink("/dev/null", path) == 0);
  CHECK_INT_EQ(tt_output_begin(ctx, path, "GPKG", 1, &out), TT_ERR_EXISTS);
  CHECK(strstr(tt_context_errmsg(ctx), "symbolic link") != NULL);
  CHECK_INT_EQ(tt_output_begin(ctx, "/dev/null", "GPKG", 1, &out),
               TT_ERR_EXISTS);
  CHECK(strstr(tt_context_errmsg(ctx), "character device") != NULL);
  /* A shapefile layer file that is a FIFO. */
  snprintf(path, sizeof path, "%s/s_vertices.dbf", dir);
  CHECK(mkfifo(path, 0666) == 0);
  snprintf(path, sizeof path, "%s/s.shp", dir);
  CHECK_INT_EQ(tt_output_begin(ctx, path, "ESRI Shapefile", 1, &out),
               TT_ERR_EXISTS);
  char listing[1024];
  list_dir(dir, listing, sizeof listing);
  CHECK_STR_EQ(listing, "fifo.gpkg null.gpkg s_vertices.dbf");
  struct stat st;
  snprintf(path, sizeof path, "%s/fifo.gpkg", dir);
  CHECK(lstat(path, &st) == 0 && S_ISFIFO(st.st_mode));
}

/* Issue 11 item 8: a final name of 255 bytes (NAME_MAX) gets a temporary
 * name it fits beside. */
static void test_long_name(tt_context *ctx)
{
  char dir[300], name[256], path[600], listing[1024];
  snprintf(dir, sizeof dir, "%s/long", tmpdir);
  mkdir(dir, 0777);
  memset(name, 'n', 250);
  memcpy(name + 250, ".gpkg", 6);
  CHECK_INT_EQ(strlen(name), 255);
  snprintf(path, sizeof path, "%s/%s", dir, name);
  static const char *const layers[] = {"vertices", NULL};
  tt_output *out = NULL;
  CHECK_OK(ctx, tt_output_begin(ctx, path, "GPKG", 0, &out));
  if (!out)
    return;
  CHECK(strlen(strrchr(tt_output_temp_path(out), '/') + 1) <= 20);
  write_vector("GPKG", tt_output_temp_path(out), layers, 7, 0);
  CHECK_OK(ctx, tt_output_commit(ctx, out));
  tt_output_destroy(out);
  list_dir(dir, listing, sizeof listing);
  CHECK_STR_EQ(listing, name);
  CHECK_INT_EQ(read_tag(path, "vertices"), 7);
}

/* Issue 11 item 5: a driver that makes a folder under the temporary name
 * (FlatGeobuf, MapInfo with several layers): removed on failure; renamed
 * into place when the name has no extension; -overwrite replaces such a
 * folder (only layer files in it) but no other folder; a folder under a
 * name with an extension is refused. */
static void test_folder_output(tt_context *ctx)
{
  char dir[300], path[400], listing[1024], probe[500];
  snprintf(dir, sizeof dir, "%s/fgb", tmpdir);
  mkdir(dir, 0777);
  static const char *const layers[] = {"triangles", "vertices",
                                       "run_parameters", NULL};
  snprintf(path, sizeof path, "%s/tin", dir);
  tt_output *out = NULL;
  /* A failed write: nothing stays. */
  CHECK_OK(ctx, tt_output_begin(ctx, path, "FlatGeobuf", 0, &out));
  if (out)
    write_vector("FlatGeobuf", tt_output_temp_path(out), layers, 1, 0);
  tt_output_destroy(out);
  list_dir(dir, listing, sizeof listing);
  CHECK_STR_EQ(listing, "");
  /* A good one, twice: the second with overwrite replaces the folder. */
  for (int tag = 1; tag <= 2; tag++) {
    out = NULL;
    CHECK_OK(ctx, tt_output_begin(ctx, path, "FlatGeobuf", tag == 2, &out));
    if (!out)
      return;
    write_vector("FlatGeobuf", tt_output_temp_path(out), layers, tag, 0);
    CHECK_OK(ctx, tt_output_commit(ctx, out));
    tt_output_destroy(out);
    list_dir(dir, listing, sizeof listing);
    CHECK_STR_EQ(listing, "tin");
    snprintf(probe, sizeof probe, "%s/vertices.fgb", path);
    CHECK_INT_EQ(read_tag(probe, "vertices"), tag);
  }
  /* Without overwrite: refused. */
  CHECK_INT_EQ(tt_output_begin(ctx, path, "FlatGeobuf", 0, &out),
               TT_ERR_EXISTS);
  /* A folder holding anything else is not replaced. */
  snprintf(probe, sizeof probe, "%s/notes.txt", path);
  FILE *f = fopen(probe, "w");
  fclose(f);
  CHECK_INT_EQ(tt_output_begin(ctx, path, "FlatGeobuf", 1, &out),
               TT_ERR_EXISTS);
  CHECK(strstr(tt_context_errmsg(ctx), "is a folder") != NULL);
  /* A folder under a file's name. */
  snprintf(path, sizeof path, "%s/tin.gpkg", dir);
  out = NULL;
  CHECK_OK(ctx, tt_output_begin(ctx, path, "FlatGeobuf", 0, &out));
  if (out) {
    write_vector("FlatGeobuf", tt_output_temp_path(out), layers, 3, 0);
    CHECK_INT_EQ(tt_output_commit(ctx, out), TT_ERR_FORMAT);
    tt_output_destroy(out);
  }
  list_dir(dir, listing, sizeof listing);
  CHECK_STR_EQ(listing, "tin");
}

/* Issue 11 item 3: a protected file (the input) is never replaced, by
 * whatever name, nor removed as part of a folder output. */
static void test_protect(tt_context *ctx)
{
  char dir[300], path[400], alias[400], listing[1024];
  snprintf(dir, sizeof dir, "%s/prot", tmpdir);
  mkdir(dir, 0777);
  static const char *const layers[] = {"vertices", NULL};
  snprintf(path, sizeof path, "%s/dem.gpkg", dir);
  write_vector("GPKG", path, layers, 1, 0);
  snprintf(alias, sizeof alias, "%s/../prot/./dem.gpkg", dir);
  tt_output *out = NULL;
  CHECK_OK(ctx, tt_output_begin(ctx, alias, "GPKG", 1, &out));
  CHECK_INT_EQ(tt_output_protect(ctx, out, path), TT_ERR_ARG);
  CHECK(strstr(tt_context_errmsg(ctx), "input") != NULL);
  tt_output_destroy(out);
  /* A hard link is the same file. */
  snprintf(alias, sizeof alias, "%s/hard.gpkg", dir);
  CHECK(link(path, alias) == 0);
  out = NULL;
  CHECK_OK(ctx, tt_output_begin(ctx, path, "GPKG", 1, &out));
  CHECK_INT_EQ(tt_output_protect(ctx, out, alias), TT_ERR_ARG);
  tt_output_destroy(out);
  unlink(alias);
  /* An unrelated protected file: the output goes ahead. */
  snprintf(alias, sizeof alias, "%s/other.gpkg", dir);
  out = NULL;
  CHECK_OK(ctx, tt_output_begin(ctx, alias, "GPKG", 0, &out));
  CHECK_OK(ctx, tt_output_protect(ctx, out, path));
  if (out)
    write_vector("GPKG", tt_output_temp_path(out), layers, 2, 0);
  CHECK_OK(ctx, tt_output_commit(ctx, out));
  tt_output_destroy(out);
  list_dir(dir, listing, sizeof listing);
  CHECK_STR_EQ(listing, "dem.gpkg other.gpkg");
  CHECK_INT_EQ(read_tag(path, "vertices"), 1);
}

/* Issue 11 item 2: the SQLite sidecars of the name being replaced. A stale
 * journal (a crashed writer's) is refused without overwrite and removed
 * with it before the new file takes the name. (The live-connection case
 * needs a second process: tests/apps/test_output_safety.sh.) */
static void test_sqlite_sidecars(tt_context *ctx)
{
  char dir[300], path[400], side[420], listing[1024];
  snprintf(dir, sizeof dir, "%s/side", tmpdir);
  mkdir(dir, 0777);
  static const char *const layers[] = {"vertices", NULL};
  snprintf(path, sizeof path, "%s/tin.gpkg", dir);
  snprintf(side, sizeof side, "%s-journal", path);
  FILE *f = fopen(side, "w");
  fputs("stale", f);
  fclose(f);
  tt_output *out = NULL;
  CHECK_INT_EQ(tt_output_begin(ctx, path, "GPKG", 0, &out), TT_ERR_EXISTS);
  CHECK(strstr(tt_context_errmsg(ctx), "-journal") != NULL);
  CHECK_OK(ctx, tt_output_begin(ctx, path, "GPKG", 1, &out));
  if (!out)
    return;
  write_vector("GPKG", tt_output_temp_path(out), layers, 4, 0);
  CHECK_OK(ctx, tt_output_commit(ctx, out));
  tt_output_destroy(out);
  list_dir(dir, listing, sizeof listing);
  CHECK_STR_EQ(listing, "tin.gpkg");
  /* A sidecar that is a FIFO is not replaced. */
  snprintf(side, sizeof side, "%s-wal", path);
  CHECK(mkfifo(side, 0666) == 0);
  CHECK_INT_EQ(tt_output_begin(ctx, path, "GPKG", 1, &out), TT_ERR_EXISTS);
  unlink(side);
}

/* Issue 11 item 6: tt_output_abandon_all() removes the temporary files of
 * an uncommitted output (a watchdog thread does it while the main thread
 * is stuck in a driver), and its commit then fails. */
static void test_abandon(tt_context *ctx)
{
  char dir[300], path[400], listing[1024];
  snprintf(dir, sizeof dir, "%s/abandon", tmpdir);
  mkdir(dir, 0777);
  static const char *const layers[] = {"vertices", NULL};
  snprintf(path, sizeof path, "%s/tin.gpkg", dir);
  tt_output *out = NULL;
  CHECK_OK(ctx, tt_output_begin(ctx, path, "GPKG", 0, &out));
  if (!out)
    return;
  write_vector("GPKG", tt_output_temp_path(out), layers, 5, 0);
  list_dir(dir, listing, sizeof listing);
  CHECK(listing[0] != '\0');
  CHECK_INT_EQ(tt_output_abandon_all(), 1);
  list_dir(dir, listing, sizeof listing);
  CHECK_STR_EQ(listing, "");
  CHECK_INT_EQ(tt_output_commit(ctx, out), TT_ERR_INTERRUPTED);
  tt_output_destroy(out);
  list_dir(dir, listing, sizeof listing);
  CHECK_STR_EQ(listing, "");
  /* A committed output is left alone and reported. */
  out = NULL;
  CHECK_OK(ctx, tt_output_begin(ctx, path, "GPKG", 0, &out));
  if (!out)
    return;
  write_vector("GPKG", tt_output_temp_path(out), layers, 6, 0);
  CHECK_OK(ctx, tt_output_commit(ctx, out));
  CHECK_INT_EQ(tt_output_abandon_all(), 0);
  tt_output_destroy(out);
  CHECK_INT_EQ(tt_output_abandon_all(), 1);
  CHECK_INT_EQ(read_tag(path, "vertices"), 6);
}

/* Writes text to path (or fails the test). */
static void put_file(const char *path, const char *text)
{
  FILE *f = fopen(path, "w");
  CHECK(f != NULL);
  if (f) {
    fputs(text, f);
    fclose(f);
  }
}

/* The first line of path, "" when it cannot be read (static buffer). */
static const char *first_line(const char *path)
{
  static char line[64];
  FILE *f = fopen(path, "r");
  line[0] = '\0';
  if (f) {
    if (!fgets(line, sizeof line, f))
      line[0] = '\0';
    fclose(f);
  }
  return line;
}

/* Issue 17: files written beside a single file (2DM's datasets) through
 * tt_output_add_sidecar(): refused when they exist without overwrite,
 * written under the temporary stem, renamed with the output at commit,
 * removed with it when it is not committed; only regular files replaced;
 * no sidecar for a shapefile. */
static void test_mesh_sidecars(tt_context *ctx)
{
  char dir[300], path[400], side[420], temp[420], listing[1024];
  snprintf(dir, sizeof dir, "%s/mesh", tmpdir);
  mkdir(dir, 0777);
  snprintf(path, sizeof path, "%s/m.2dm", dir);
  snprintf(side, sizeof side, "%s/m_a.dat", dir);
  put_file(side, "old\n");
  tt_output *out = NULL;
  CHECK_OK(ctx, tt_output_begin(ctx, path, "2DM", 0, &out));
  CHECK_INT_EQ(tt_output_add_sidecar(ctx, out, "_a.dat"), TT_ERR_EXISTS);
  CHECK(strstr(tt_context_errmsg(ctx), "m_a.dat exists") != NULL);
  tt_output_destroy(out);
  list_dir(dir, listing, sizeof listing);
  CHECK_STR_EQ(listing, "m_a.dat");

  /* Not committed: the temporary files go, the old one stays. */
  for (int commit = 0; commit < 2; commit++) {
    out = NULL;
    CHECK_OK(ctx, tt_output_begin(ctx, path, "2DM", 1, &out));
    if (!out)
      return;
    CHECK_OK(ctx, tt_output_add_sidecar(ctx, out, "_a.dat"));
    CHECK_OK(ctx, tt_output_add_sidecar(ctx, out, "_b_els.dat"));
    const char *tp = tt_output_temp_path(out);
    put_file(tp, "MESH2D\n");
    snprintf(temp, sizeof temp, "%.*s_a.dat", (int)(strlen(tp) - 4), tp);
    put_file(temp, "new\n");
    snprintf(temp, sizeof temp, "%.*s_b_els.dat", (int)(strlen(tp) - 4), tp);
    put_file(temp, "new\n");
    if (commit)
      CHECK_OK(ctx, tt_output_commit(ctx, out));
    tt_output_destroy(out);
    list_dir(dir, listing, sizeof listing);
    CHECK_STR_EQ(listing, commit ? "m.2dm m_a.dat m_b_els.dat" : "m_a.dat");
    CHECK_STR_EQ(first_line(side), commit ? "new\n" : "old\n");
  }
  /* A sidecar name that is not a regular file is refused, -overwrite or
   * not; a shapefile takes none. */
  snprintf(side, sizeof side, "%s/m_c.dat", dir);
  CHECK(mkfifo(side, 0666) == 0);
  out = NULL;
  CHECK_OK(ctx, tt_output_begin(ctx, path, "2DM", 1, &out));
  CHECK(tt_output_add_sidecar(ctx, out, "_c.dat") != TT_OK);
  tt_output_destroy(out);
  unlink(side);
  snprintf(path, sizeof path, "%s/s.shp", dir);
  out = NULL;
  CHECK_OK(ctx, tt_output_begin(ctx, path, "ESRI Shapefile", 0, &out));
  CHECK_INT_EQ(tt_output_add_sidecar(ctx, out, "_a.dat"), TT_ERR_ARG);
  tt_output_destroy(out);
  list_dir(dir, listing, sizeof listing);
  CHECK_STR_EQ(listing, "m.2dm m_a.dat m_b_els.dat");
}

/* A tt_log_fn counting the sweep's notes into an int. */
static void count_note(void *user, const char *message)
{
  (*(int *)user)++;
  CHECK(strstr(message, "removed stale temporary ") == message);
  CHECK(strstr(message, "(left by a killed run)") != NULL);
}

/* Stale temporaries (output_owner.c): a live output's stem has a lock file
 * that a second output into the same folder of this process leaves alone
 * (its lock is held there, flock() belonging to the open file); a stem
 * whose lock file nobody holds is removed, with a note, except what a
 * killed commit moved aside (STEM.old: the user's old output), which is
 * kept and, without its lock file, never swept again; a temporary with no
 * lock file is never touched. */
static void test_stale(tt_context *ctx)
{
  char dir[300], path[400], p2[400], f[420], listing[1024];
  snprintf(dir, sizeof dir, "%s/stale", tmpdir);
  mkdir(dir, 0777);
  static const char *const layers[] = {"vertices", NULL};
  snprintf(path, sizeof path, "%s/a.gpkg", dir);
  snprintf(p2, sizeof p2, "%s/b.gpkg", dir);
  tt_output *a = NULL, *b = NULL;
  CHECK_OK(ctx, tt_output_begin(ctx, path, "GPKG", 0, &a));
  if (!a)
    return;
  write_vector("GPKG", tt_output_temp_path(a), layers, 1, 0);
  /* .ttXXXXXXXX.gpkg's owner: .ttXXXXXXXX.lock */
  snprintf(f, sizeof f, "%s", tt_output_temp_path(a));
  snprintf(strrchr(f, '.'), 6, ".lock");
  struct stat st;
  CHECK(stat(f, &st) == 0);
  /* stale ones: a dataset and its lock, nobody holding it */
  snprintf(f, sizeof f, "%s/.tt0000beef.gpkg", dir);
  put_file(f, "x");
  snprintf(f, sizeof f, "%s/.tt0000beef.gpkg-journal", dir);
  put_file(f, "x");
  snprintf(f, sizeof f, "%s/.tt0000beef.lock", dir);
  put_file(f, "");
  /* the old output a killed commit had moved aside */
  snprintf(f, sizeof f, "%s/.tt0000cafe.old", dir);
  put_file(f, "old");
  snprintf(f, sizeof f, "%s/.tt0000cafe.lock", dir);
  put_file(f, "");
  /* an older terratin's: no lock */
  snprintf(f, sizeof f, "%s/.tt0000f00d.gpkg", dir);
  put_file(f, "x");
  int notes = 0;
  CHECK_INT_EQ(tt_output_remove_stale(p2, count_note, &notes), 2);
  CHECK_INT_EQ(notes, 2);
  CHECK(stat(tt_output_temp_path(a), &st) == 0);
  snprintf(f, sizeof f, "%s/.tt0000beef.gpkg", dir);
  CHECK(stat(f, &st) != 0);
  snprintf(f, sizeof f, "%s/.tt0000beef.gpkg-journal", dir);
  CHECK(stat(f, &st) != 0);
  snprintf(f, sizeof f, "%s/.tt0000beef.lock", dir);
  CHECK(stat(f, &st) != 0);
  snprintf(f, sizeof f, "%s/.tt0000cafe.old", dir);
  CHECK_STR_EQ(first_line(f), "old");
  snprintf(f, sizeof f, "%s/.tt0000cafe.lock", dir);
  CHECK(stat(f, &st) != 0);
  snprintf(f, sizeof f, "%s/.tt0000f00d.gpkg", dir);
  CHECK(stat(f, &st) == 0);
  /* begin sweeps too, and spares the live output of this process */
  CHECK_OK(ctx, tt_output_begin(ctx, p2, "GPKG", 0, &b));
  CHECK(stat(tt_output_temp_path(a), &st) == 0);
  if (b) {
    write_vector("GPKG", tt_output_temp_path(b), layers, 2, 0);
    CHECK_OK(ctx, tt_output_commit(ctx, b));
    tt_output_destroy(b);
  }
  CHECK_OK(ctx, tt_output_commit(ctx, a));
  tt_output_destroy(a);
  CHECK_INT_EQ(read_tag(path, "vertices"), 1);
  CHECK_INT_EQ(read_tag(p2, "vertices"), 2);
  list_dir(dir, listing, sizeof listing);
  CHECK_STR_EQ(listing, ".tt0000cafe.old .tt0000f00d.gpkg a.gpkg b.gpkg");
}

int main(void)
{
  GDALAllRegister();
  snprintf(tmpdir, sizeof tmpdir, "/tmp/tt_output_path_XXXXXX");
  if (!mkdtemp(tmpdir)) {
    perror("mkdtemp");
    return 1;
  }
  tt_context *ctx = tt_context_create();
  CPLPushErrorHandler(CPLQuietErrorHandler);
  TT_RUN(test_gpkg(ctx));
  TT_RUN(test_unwritable(ctx));
  TT_RUN(test_shapefile(ctx));
  TT_RUN(test_not_regular(ctx));
  TT_RUN(test_long_name(ctx));
  TT_RUN(test_folder_output(ctx));
  TT_RUN(test_protect(ctx));
  TT_RUN(test_sqlite_sidecars(ctx));
  TT_RUN(test_abandon(ctx));
  TT_RUN(test_mesh_sidecars(ctx));
  TT_RUN(test_stale(ctx));
  CPLPopErrorHandler();
  tt_context_destroy(ctx);
  VSIRmdirRecursive(tmpdir);
  TT_TEST_DONE();
}
