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
  snprintf(prefix, sizeof prefix, "%s/.tin.tmp-", dir);
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
  snprintf(prefix, sizeof prefix, "%s/.tin.tmp-", dir);
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
  test_gpkg(ctx);
  test_unwritable(ctx);
  test_shapefile(ctx);
  CPLPopErrorHandler();
  tt_context_destroy(ctx);
  VSIRmdirRecursive(tmpdir);
  TT_TEST_DONE();
}
