/*
 * test_mesh_read.c -- tt_mesh_read() and tt_tin_to_pixels(): one small TIN
 * (4 vertices, 2 triangles) written by hand in every format the readers
 * know -- ASCII and binary STL, ascii and binary PLY (other properties, a
 * quad, the CRS comment), OBJ (an origin comment, v/t/n corners,
 * negative indices), 2DM (elements first, a quad), LandXML (northing
 * first, sparse ids, an invisible face, epsgCode) -- read back to the very
 * corners, with the faces rejected counted and the CRS declared; the
 * format named from the content, NULL for other files; damaged files
 * failing with the face or line named; and the frame: the pixel frame's
 * row counted up, -tin_transform's affine, a reprojection from EPSG:4326
 * onto a UTM grid.
 */
#include "terratin/terratin_gdal.h"
#include "tt_test.h"

#include <cpl_string.h>
#include <cpl_vsi.h>

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

/* The TIN: corners of the two triangles as every file below holds them. */
static const double want[18] = {
    10, 20, 1.5, 11, 20, 2.5, 10, 21, 3.5, /* triangle 1: v1 v2 v3 */
    11, 20, 2.5, 11, 21, 4.5, 10, 21, 3.5  /* triangle 2: v2 v4 v3 */
};

static void put_file(const char *path, const void *data, size_t n)
{
  VSIUnlink(path);
  VSILFILE *f = VSIFOpenL(path, "wb");
  CHECK(f != NULL);
  CHECK(VSIFWriteL(data, 1, n, f) == n);
  VSIFCloseL(f);
}

static void put_text(const char *path, const char *text)
{
  put_file(path, text, strlen(text));
}

/* Reads path and checks its two triangles, the rejected count and the
 * CRS (NULL: none). */
static void check_read(tt_context *ctx, const char *path, const char *fmt,
                       size_t rejected, const char *crs)
{
  double *xyz = NULL;
  size_t n = 0, rej = 99;
  char *wkt = NULL;
  const char *got = tt_mesh_read_format(path);
  CHECK_STR_EQ(got ? got : "(null)", fmt);
  CHECK_OK(ctx, tt_mesh_read(ctx, path, &xyz, &n, &rej, &wkt));
  CHECK_INT_EQ(n, 2);
  CHECK_INT_EQ(rej, rejected);
  for (size_t i = 0; n == 2 && i < 18; i++)
    if (xyz[i] != want[i])
      TT_FAIL_("%s: coordinate %zu is %.17g, not %.17g", path, i, xyz[i],
               want[i]);
  CHECK_STR_EQ(wkt ? wkt : "(none)", crs ? crs : "(none)");
  free(xyz);
  free(wkt);
}

static void test_stl(tt_context *ctx)
{
  char text[2048];
  size_t n = (size_t)snprintf(text, sizeof text, "solid t\n");
  for (int t = 0; t < 2; t++) {
    n += (size_t)snprintf(text + n, sizeof text - n,
                          "facet normal 0 0 1\n outer loop\n");
    for (int k = 0; k < 3; k++)
      n += (size_t)snprintf(text + n, sizeof text - n,
                            "  vertex %g %g %g\n", want[9 * t + 3 * k],
                            want[9 * t + 3 * k + 1], want[9 * t + 3 * k + 2]);
    n += (size_t)snprintf(text + n, sizeof text - n, " endloop\nendfacet\n");
  }
  snprintf(text + n, sizeof text - n,
           "facet normal 0 0 1\n outer loop\n  vertex 0 0 0\n  vertex 1 0 0"
           "\n endloop\nendfacet\nendsolid t\n");
  put_text("/vsimem/t_ascii.stl", text);
  check_read(ctx, "/vsimem/t_ascii.stl", "STL", 1, NULL);

  /* binary: its header opens with "solid" too */
  unsigned char bin[84 + 2 * 50];
  memset(bin, 0, sizeof bin);
  memcpy(bin, "solid binary", 12);
  bin[80] = 2;
  for (int t = 0; t < 2; t++)
    for (int k = 0; k < 9; k++) {
      float f = (float)want[9 * t + k];
      uint32_t u;
      memcpy(&u, &f, 4);
      for (int b = 0; b < 4; b++)
        bin[84 + 50 * t + 12 + 4 * k + b] = (unsigned char)(u >> (8 * b));
    }
  put_file("/vsimem/t_bin.stl", bin, sizeof bin);
  check_read(ctx, "/vsimem/t_bin.stl", "STL", 0, NULL);
  /* truncated: neither binary (size) nor ASCII (no "solid") */
  bin[0] = 'x';
  put_file("/vsimem/t_cut.stl", bin, sizeof bin - 7);
  double *xyz = NULL;
  size_t nt = 0;
  CHECK_INT_EQ(tt_mesh_read(ctx, "/vsimem/t_cut.stl", &xyz, &nt, NULL, NULL),
               TT_ERR_FORMAT);
  CHECK(strstr(tt_context_errmsg(ctx), "neither a binary STL") != NULL);
  CHECK(xyz == NULL);
}

static const char ply_head[] =
    "ply\nformat %s 1.0\ncomment crs:EPSG:4326\n"
    "element vertex 4\nproperty float s\nproperty double x\n"
    "property double y\nproperty double z\n"
    "element face %d\nproperty list uchar int vertex_indices\n"
    "property uchar red\nend_header\n";

static void test_ply(tt_context *ctx)
{
  char text[1024];
  int n = snprintf(text, sizeof text, ply_head, "ascii", 3);
  snprintf(text + n, sizeof text - (size_t)n,
           "0.5 10 20 1.5\n0.5 11 20 2.5\n0.5 10 21 3.5\n0.5 11 21 4.5\n"
           "3 0 1 2 9\n3 1 3 2 9\n4 0 1 3 2 9\n");
  put_text("/vsimem/t.ply", text);
  check_read(ctx, "/vsimem/t.ply", "PLY", 1, "EPSG:4326");

  /* binary big-endian: float, doubles; uchar count, int indices, uchar */
  unsigned char buf[512], *p = buf;
  n = snprintf((char *)buf, sizeof buf, ply_head, "binary_big_endian", 2);
  p += n;
  const double v[4][3] = {{10, 20, 1.5}, {11, 20, 2.5}, {10, 21, 3.5},
                          {11, 21, 4.5}};
  for (int i = 0; i < 4; i++) {
    memset(p, 0, 4), p += 4; /* s = 0.0f */
    for (int k = 0; k < 3; k++) {
      uint64_t u;
      memcpy(&u, &v[i][k], 8);
      for (int b = 7; b >= 0; b--)
        *p++ = (unsigned char)(u >> (8 * b));
    }
  }
  const int f[2][3] = {{0, 1, 2}, {1, 3, 2}};
  for (int t = 0; t < 2; t++) {
    *p++ = 3;
    for (int k = 0; k < 3; k++)
      *p++ = 0, *p++ = 0, *p++ = 0, *p++ = (unsigned char)f[t][k];
    *p++ = 7;
  }
  put_file("/vsimem/tb.ply", buf, (size_t)(p - buf));
  check_read(ctx, "/vsimem/tb.ply", "PLY", 0, "EPSG:4326");
  put_file("/vsimem/tc.ply", buf, (size_t)(p - buf) - 5);
  double *xyz = NULL;
  size_t nt = 0;
  CHECK_INT_EQ(tt_mesh_read(ctx, "/vsimem/tc.ply", &xyz, &nt, NULL, NULL),
               TT_ERR_FORMAT);
  CHECK(strstr(tt_context_errmsg(ctx), "ends inside element face") != NULL);
}

static void test_obj_2dm_landxml(tt_context *ctx)
{
  put_text("/vsimem/t.obj",
           "# origin 10 20\no t\nv 0 0 1.5\nvn 0 0 1\nv 1 0 2.5\n"
           "v 0 1 3.5\nv 1 1 4.5\nf 1/1/1 2//1 3\nf -3 -1 -2\n"
           "f 1 2 4 3\n");
  check_read(ctx, "/vsimem/t.obj", "OBJ", 1, NULL);
  put_text("/vsimem/t.2dm",
           "MESH2D\nE3T 1 4 3 2 1\nE3T 2 3 1 2 1\nE4Q 3 4 3 1 2 1\n"
           "ND 4 10 20 1.5\nND 3 11 20 2.5\nND 2 10 21 3.5\n"
           "ND 1 11 21 4.5\n");
  check_read(ctx, "/vsimem/t.2dm", "2DM", 1, NULL);
  put_text("/vsimem/t.xml",
           "<?xml version=\"1.0\"?>\n<LandXML version=\"1.2\">\n"
           "<CoordinateSystem epsgCode=\"32633\"/>\n<Surfaces>\n"
           "<Surface name=\"s\"><Definition surfType=\"TIN\"><Pnts>\n"
           "<P id=\"7\">20 10 1.5</P><P id=\"8\">20 11 2.5</P>\n"
           "<P id=\"12\">21 10 3.5</P><P id=\"13\">21 11 4.5</P>\n"
           "</Pnts><Faces><F>7 8 12</F><F i=\"1\">7 13 12</F>"
           "<F n=\"1 2 3\">8 13 12</F></Faces></Definition></Surface>\n"
           "</Surfaces></LandXML>\n");
  check_read(ctx, "/vsimem/t.xml", "LandXML", 1, "EPSG:32633");

  double *xyz = NULL;
  size_t nt = 0;
  put_text("/vsimem/bad.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n");
  CHECK_INT_EQ(tt_mesh_read(ctx, "/vsimem/bad.obj", &xyz, &nt, NULL, NULL),
               TT_ERR_FORMAT);
  CHECK(strstr(tt_context_errmsg(ctx), "face 1 names vertex 9") != NULL);
  put_text("/vsimem/bad.xml", "<LandXML><Surfaces/></LandXML>\n");
  CHECK_INT_EQ(tt_mesh_read(ctx, "/vsimem/bad.xml", &xyz, &nt, NULL, NULL),
               TT_ERR_FORMAT);
  put_text("/vsimem/t.geojson", "{\"type\": \"FeatureCollection\"}\n");
  CHECK(tt_mesh_read_format("/vsimem/t.geojson") == NULL);
  CHECK(tt_mesh_read_format("/vsimem/none.stl") == NULL);
}

static void test_frames(tt_context *ctx)
{
  const double gt[6] = {500000, 2, 0, 5000000, 0, -2};
  /* pixel frame, after a transform: x' = 2x + 1, y' = y, z' = z + 100 */
  double a[9] = {1, 0, 5, 2, 9, 6, 0, 4, 7};
  const double tf[6] = {2, 1, 1, 1, 0, 100};
  CHECK_OK(ctx, tt_tin_to_pixels(ctx, a, 1, TT_TIN_FRAME_PIXEL, tf, 10,
                                 NULL, NULL, gt, NULL));
  const double pa[9] = {3, 9, 105, 5, 0, 106, 1, 5, 107};
  for (int i = 0; i < 9; i++)
    CHECK_DBL_NEAR(a[i], pa[i], 0);
  /* map: sample (c, r) of gt is at 500001 + 2c, 4999999 - 2r */
  double b[9] = {500001, 4999999, 1, 500021, 4999999, 2, 500001, 4999979, 3};
  int rep = -1;
  CHECK_OK(ctx, tt_tin_to_pixels(ctx, b, 1, TT_TIN_FRAME_MAP, NULL, 10,
                                 NULL, "EPSG:32633", gt, &rep));
  CHECK_INT_EQ(rep, 0);
  const double pb[9] = {0, 0, 1, 10, 0, 2, 0, 10, 3};
  for (int i = 0; i < 9; i++)
    CHECK_DBL_NEAR(b[i], pb[i], 1e-9);
  /* the same corners in EPSG:4326 (lon, lat), reprojected back */
  OGRSpatialReferenceH utm = OSRNewSpatialReference(NULL);
  OGRSpatialReferenceH geo = OSRNewSpatialReference(NULL);
  OSRSetFromUserInput(utm, "EPSG:32633");
  OSRSetFromUserInput(geo, "EPSG:4326");
  OSRSetAxisMappingStrategy(utm, OAMS_TRADITIONAL_GIS_ORDER);
  OSRSetAxisMappingStrategy(geo, OAMS_TRADITIONAL_GIS_ORDER);
  OGRCoordinateTransformationH ct = OCTNewCoordinateTransformation(utm, geo);
  double c[9] = {500001, 4999999, 1, 500021, 4999999, 2, 500001, 4999979, 3};
  for (int k = 0; k < 3; k++)
    CHECK(OCTTransform(ct, 1, &c[3 * k], &c[3 * k + 1], NULL));
  CHECK(c[0] > 14 && c[0] < 16 && c[1] > 45 && c[1] < 46);
  CHECK_OK(ctx, tt_tin_to_pixels(ctx, c, 1, TT_TIN_FRAME_MAP, NULL, 10,
                                 "EPSG:4326", "EPSG:32633", gt, &rep));
  CHECK_INT_EQ(rep, 1);
  for (int i = 0; i < 9; i++)
    CHECK_DBL_NEAR(c[i], pb[i], 1e-6);
  OCTDestroyCoordinateTransformation(ct);
  OSRDestroySpatialReference(utm);
  OSRDestroySpatialReference(geo);
}

int main(void)
{
  GDALAllRegister();
  tt_context *ctx = tt_context_create();
  TT_RUN(test_stl(ctx));
  TT_RUN(test_ply(ctx));
  TT_RUN(test_obj_2dm_landxml(ctx));
  TT_RUN(test_frames(ctx));
  tt_context_destroy(ctx);
  VSIRmdirRecursive("/vsimem/");
  TT_TEST_DONE();
}
