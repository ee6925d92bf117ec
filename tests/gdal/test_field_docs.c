/*
 * test_field_docs.c -- the fields' titles and descriptions
 * (src/gdal/ogr/field_docs.c): one for every field of the triangles and
 * vertices layers, in their order (the writers index both tables by the
 * same enum), each with a title and a description; titles unique over
 * every table (GDAL 3.6 makes gpkg_data_columns.name UNIQUE across
 * tables); the run_parameters fields the commands write known by name;
 * "{z}" replaced by the height unit, "z units" when there is none; and
 * the default style's QML carrying the titles as QGIS aliases.
 */
#include "gdal/ogr/field_docs.h"
#include "gdal/ogr/layer_style.h"
#include "tt_test.h"

#include <cpl_conv.h>

#include <string.h>

/* Whether title appears among the first n titles already seen. */
static int seen(const char *const *titles, size_t n, const char *title)
{
  for (size_t i = 0; i < n; i++)
    if (strcmp(titles[i], title) == 0)
      return 1;
  return 0;
}

int main(void)
{
  const char *titles[TT__TF_COUNT + TT__VF_COUNT];
  size_t nt = 0;
  for (int i = 0; i < TT__TF_COUNT; i++) {
    const tt__field_doc *d = &tt__triangle_docs[i];
    CHECK_STR_EQ(d->name, tt__triangle_fields[i].name);
    CHECK(d->title && *d->title && d->description && *d->description);
    CHECK(!seen(titles, nt, d->title));
    titles[nt++] = d->title;
  }
  for (int i = 0; i < TT__VF_COUNT; i++) {
    const tt__field_doc *d = &tt__vertex_docs[i];
    CHECK_STR_EQ(d->name, tt__vertex_fields[i].name);
    CHECK(d->title && *d->title && d->description && *d->description);
    CHECK(!seen(titles, nt, d->title));
    titles[nt++] = d->title;
  }
  /* the run fields' titles differ from the layers' */
  static const char *const run[] = {"input", "method", "max_error",
                                    "ach_max", "z_unit", "tile_size",
                                    "importance", "in_tin", "t_optimize"};
  for (size_t i = 0; i < sizeof run / sizeof run[0]; i++) {
    const tt__field_doc *d = tt__field_doc_run(run[i]);
    CHECK(d != NULL);
    if (d)
      CHECK(!seen(titles, nt, d->title));
  }
  CHECK(tt__field_doc_run("no_such") == NULL);

  char *t = tt__field_doc_text(tt__triangle_docs[TT__TF_MAX_ERR].description,
                               "ft");
  CHECK_STR_EQ(t, "largest |TIN - DEM| of the samples in this triangle (ft)");
  CPLFree(t);
  t = tt__field_doc_text("{z} and {z}", NULL);
  CHECK_STR_EQ(t, "z units and z units");
  CPLFree(t);
  t = tt__field_doc_text("none", "m");
  CHECK_STR_EQ(t, "none");
  CPLFree(t);

  /* the QML: aliases, see-through fills for triangles only */
  const double v[3] = {0, 1, 2};
  char *tri = tt__style_graduated_qml("max_err", v, 3, 0, 0, 0);
  char *pts = tt__style_graduated_qml("x", v, 3, 1, 1, 1);
  CHECK(tri && strstr(tri, "<alias field=\"max_err\" index=\"3\" "
                           "name=\"max error\"/>"));
  CHECK(tri && strstr(tri, "type=\"fill\" name=\"0\" alpha=\"0.45\""));
  CHECK(tri && !strstr(tri, "alpha=\"1\""));
  CHECK(pts && strstr(pts, "<alias field=\"ins_err\" index=\"3\" "
                           "name=\"insertion error\"/>"));
  CHECK(pts && strstr(pts, "type=\"marker\" name=\"0\" alpha=\"1\""));
  CPLFree(tri);
  CPLFree(pts);
  TT_TEST_DONE();
}
