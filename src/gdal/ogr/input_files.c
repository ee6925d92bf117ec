/*
 * src/gdal/ogr/ -- the OGR layers: a TIN written into an OGR dataset and
 * triangles read from one, the features' records, QGIS's default style,
 * safe output paths and the protection of the input's files.
 *
 * input_files.c -- the local files a raster read depends on, registered
 * with tt_output_protect() so that no output can replace or remove the
 * input, whatever spelling names it.
 *
 * GDALGetFileList() gives the files of the open dataset: the main file,
 * its sidecars (.aux.xml, .ovr, world files, .msk) and, for a VRT, its
 * sources. VRT sources that are VRTs themselves are opened and listed in
 * turn (up to MAX_DEPTH levels), since GDAL lists only the first level.
 * Each name, and the name the dataset was opened under, may be a path into
 * a container ("/vsizip/dem.zip/x.tif", "/vsitar//abs/a.tar/x.tif",
 * "/vsigzip/x.tif.gz", "GPKG:r.gpkg:r", 'NETCDF:"f.nc":z',
 * "/vsisubfile/0_100,f.bin"): after the /vsi prefixes are dropped, every
 * piece that starts at the beginning or after ':', ',', '"', '{' and ends
 * at '/', ':', ',', '"', '}' or the end, and that is an existing regular
 * file, is registered. That over-approximates (a stray file named "GPKG"
 * in the working folder would be protected too), which can only refuse an
 * output, never lose an input. /vsimem/ and network paths name no local
 * file and register nothing.
 *
 * Workload: a few stat() calls per name (quadratic in the number of
 * separators of a name, a few dozen at most).
 */
#include "base/internal.h"
#include "terratin/terratin_gdal.h"

#include <cpl_conv.h>
#include <cpl_error.h>
#include <cpl_string.h>

#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>

#define MAX_DEPTH 8

static int starts_piece(char c)
{
  return c == ':' || c == ',' || c == '"' || c == '{';
}

static int ends_piece(char c)
{
  return c == '/' || c == ':' || c == ',' || c == '"' || c == '}' ||
         c == '\0';
}

/* Registers name and the containers in it; seen holds the pieces already
 * registered (a CSL list). */
static tt_status protect_name(tt_context *ctx, tt_output *out,
                              const char *name, char ***seen)
{
  const char *p = name;
  while (strncmp(p, "/vsi", 4) == 0) {
    if (strncmp(p, "/vsimem/", 8) == 0)
      return TT_OK; /* in memory: nothing on disk to lose */
    const char *slash = strchr(p + 4, '/');
    if (!slash)
      return TT_OK;
    p = slash + 1;
  }
  const size_t n = strlen(p);
  tt_status s = TT_OK;
  for (size_t i = 0; i < n && s == TT_OK; i++) {
    if (i > 0 && !starts_piece(p[i - 1]))
      continue;
    for (size_t j = i + 1; j <= n && s == TT_OK; j++) {
      if (!ends_piece(p[j]))
        continue;
      /* (CPLSPrintf knows no %.*s) */
      char *piece = CPLStrdup(p + i);
      piece[j - i] = '\0';
      struct stat st;
      if (CSLFindString(*seen, piece) < 0 && stat(piece, &st) == 0 &&
          S_ISREG(st.st_mode)) {
        *seen = CSLAddString(*seen, piece);
        s = tt_output_protect(ctx, out, piece);
      }
      CPLFree(piece);
    }
  }
  return s;
}

static int is_vrt(const char *path)
{
  size_t n = strlen(path);
  return n > 4 && strcasecmp(path + n - 4, ".vrt") == 0;
}

static tt_status protect_files(tt_context *ctx, tt_output *out,
                               GDALDatasetH ds, const char *name, int depth,
                               char ***seen, char ***opened)
{
  tt_status s = protect_name(ctx, out, name, seen);
  char **files = ds ? GDALGetFileList(ds) : NULL;
  for (char **f = files; s == TT_OK && f && *f; f++) {
    s = protect_name(ctx, out, *f, seen);
    if (s != TT_OK || depth >= MAX_DEPTH || !is_vrt(*f) ||
        CSLFindString(*opened, *f) >= 0)
      continue;
    /* A VRT among the sources: its own sources are not in the list. */
    *opened = CSLAddString(*opened, *f);
    CPLPushErrorHandler(CPLQuietErrorHandler);
    CPLSetCurrentErrorHandlerCatchDebug(FALSE); /* debug: the handler below */
    GDALDatasetH sub = GDALOpenEx(*f, GDAL_OF_RASTER | GDAL_OF_READONLY,
                                  NULL, NULL, NULL);
    CPLPopErrorHandler();
    if (sub) {
      s = protect_files(ctx, out, sub, *f, depth + 1, seen, opened);
      GDALClose(sub);
    }
  }
  CSLDestroy(files);
  return s;
}

tt_status tt_output_protect_dataset(tt_context *ctx, tt_output *out,
                                    GDALDatasetH src, const char *name)
{
  if (!out || !name)
    return tt__error(ctx, TT_ERR_ARG, "output and name must not be NULL");
  char **seen = NULL, **opened = NULL;
  if (src)
    opened = CSLAddString(opened, GDALGetDescription(src));
  tt_status s = protect_files(ctx, out, src, name, 0, &seen, &opened);
  CSLDestroy(seen);
  CSLDestroy(opened);
  return s;
}
