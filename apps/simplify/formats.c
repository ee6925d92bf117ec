/*
 * formats.c -- apps/simplify/, the simplify command: `terratin --formats`,
 * the outputs -of accepts, as GDAL's utilities list their drivers. The OGR
 * drivers of this GDAL that can create vector datasets are each judged by
 * the dry run simplify makes before a run (ogr_output.c): the three layers
 * written into a file in memory and read back, then each layer alone, so
 * that the list says what a run would do (all layers, one layer a file, or
 * refused and left out) rather than what the drivers' metadata claims.
 * A driver that holds neither the triangles nor the vertices faithfully
 * (only the table of run parameters) is left out. Then the databases (a
 * driver that writes no file, by its connection prefix), then the mesh
 * and survey formats terratin writes itself.
 *
 * Workload: about 40 tiny dry runs in /vsimem/, a fraction of a second.
 */
#include "simplify.h"

#include <cpl_conv.h>
#include <cpl_string.h>

#include <stdio.h>
#include <string.h>

/* The mesh and survey formats by their -of name, with what they hold. */
static const struct {
  tt_mesh_format fmt;
  const char *what;
} mesh_formats[] = {
    {TT_MESH_2DM, ".2dm, SMS 2DM mesh (QGIS mesh layer), error datasets "
                  "in .dat files beside it"},
    {TT_MESH_PLY, ".ply, binary PLY, vertex and face error properties "
                  "(QGIS mesh layer)"},
    {TT_MESH_OBJ, ".obj, Wavefront OBJ (-obj_local: relative coordinates)"},
    {TT_MESH_LANDXML, ".xml, LandXML 1.2 TIN surface"},
    {TT_MESH_DXF, ".dxf, DXF R12 3DFACE entities"},
    {TT_MESH_UGRID, "by -of only, netCDF UGRID 1.0 mesh with the error "
                    "datasets (QGIS mesh layer)"},
};

static int is_vector_creator(GDALDriverH drv)
{
  return GDALGetMetadataItem(drv, GDAL_DCAP_VECTOR, NULL) &&
         GDALGetMetadataItem(drv, GDAL_DCAP_CREATE, NULL);
}

/* The driver's first file extension with its dot, or "" (none). */
static void first_extension(GDALDriverH drv, char *buf, size_t size)
{
  const char *exts = GDALGetMetadataItem(drv, GDAL_DMD_EXTENSIONS, NULL);
  if (!exts)
    exts = GDALGetMetadataItem(drv, GDAL_DMD_EXTENSION, NULL);
  buf[0] = '\0';
  if (exts && *exts)
    snprintf(buf, size, ".%.*s", (int)strcspn(exts, " "), exts);
}

/* One OGR driver that writes files: its line, or nothing when a run
 * would refuse it. */
static void print_file_driver(FILE *out, GDALDriverH drv)
{
  const char *name = GDALGetDriverShortName(drv);
  const char *longname = GDALGetDriverLongName(drv);
  char ext[32], list[96];
  unsigned alone = 0;
  int imposed = 0;
  /* CSV puts each layer in a file beside OUTPUT: refused by the run */
  if (tt__app_str_ieq(name, "CSV"))
    return;
  first_extension(drv, ext, sizeof ext);
  unsigned together = tt__app_probe_format(drv, ext, &alone, &imposed);
  if (!together && !alone && ext[0]) /* a folder of files, OUTPUT without */
    together = tt__app_probe_format(drv, "", &alone, &imposed);
  /* a driver that takes the geometry-less run_parameters only cannot
   * hold the TIN: left out as refused */
  if (!(alone & (TT_APP_LAYER_TRIANGLES | TT_APP_LAYER_VERTICES)))
    return;
  if (together) {
    snprintf(list, sizeof list, "all layers");
  } else {
    /* "one layer (-layers triangles|vertices)" */
    char layers[48];
    tt__app_layer_list(alone, layers, sizeof layers);
    for (char *c = layers; *c; c++)
      if (*c == ',')
        *c = '|';
    snprintf(list, sizeof list, "one layer (-layers %s)", layers);
  }
  fprintf(out, "  %-16s %s", name, longname);
  if (!ext[0] || !strstr(longname, ext)) /* "GMT ASCII Vectors (.gmt)" */
    fprintf(out, " (%s)", ext[0] ? ext : "a folder");
  fprintf(out, ": %s%s\n", list, imposed ? ", written in EPSG:4326" : "");
}

/* A driver that writes no file but a database terratin writes in one
 * transaction (tt__app_database_driver's rule). */
static void print_database_driver(FILE *out, GDALDriverH drv)
{
  const char *name = GDALGetDriverShortName(drv);
  const char *prefix =
      GDALGetMetadataItem(drv, GDAL_DMD_CONNECTION_PREFIX, NULL);
  if (!prefix && !tt__app_str_ieq(name, "PostgreSQL"))
    return;
  fprintf(out, "  %-16s %s (OUTPUT \"%s...\"): all layers, in one "
          "transaction%s\n", name, GDALGetDriverLongName(drv),
          prefix ? prefix : "PG:",
          tt__app_str_ieq(name, "PostgreSQL")
              ? ""
              : " (a database without transactions is refused when opened)");
}

tt_status tt__app_formats(app_run *r)
{
  FILE *out = r->out;
  int n = GDALGetDriverCount();
  fprintf(out, "Output formats of simplify and optimize (-of NAME; the "
          "default is guessed\nfrom OUTPUT's extension, else GPKG).\n\n"
          "OGR vector drivers (each checked by writing a TIN and reading it "
          "back):\n");
  for (int i = 0; i < n; i++) {
    GDALDriverH drv = GDALGetDriver(i);
    const char *name = GDALGetDriverShortName(drv);
    if (!is_vector_creator(drv) || tt_mesh_format_from_name(name) ||
        (!GDALGetMetadataItem(drv, GDAL_DMD_EXTENSIONS, NULL) &&
         !GDALGetMetadataItem(drv, GDAL_DMD_EXTENSION, NULL)))
      continue;
    print_file_driver(out, drv);
    if (!tt__app_continue(r, 0))
      return tt__app_fail_tt(r, TT_ERR_INTERRUPTED, NULL);
  }
  fprintf(out, "\nDatabases:\n");
  for (int i = 0; i < n; i++) {
    GDALDriverH drv = GDALGetDriver(i);
    if (is_vector_creator(drv) &&
        !GDALGetMetadataItem(drv, GDAL_DMD_EXTENSIONS, NULL) &&
        !GDALGetMetadataItem(drv, GDAL_DMD_EXTENSION, NULL))
      print_database_driver(out, drv);
  }
  fprintf(out, "\nMesh and survey formats (written by terratin; the whole "
          "mesh, no -layers):\n");
  for (size_t i = 0; i < sizeof mesh_formats / sizeof mesh_formats[0]; i++)
    fprintf(out, "  %-16s %s\n", tt_mesh_format_name(mesh_formats[i].fmt),
            mesh_formats[i].what);
  return TT_OK;
}
