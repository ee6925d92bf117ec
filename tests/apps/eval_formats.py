#!/usr/bin/env python3
"""eval_formats.py -- the TIN of a terratin OBJ rewritten in the formats
other tools write, for test_eval_formats.sh (pure python3, no GDAL).

    eval_formats.py TIN.obj DEM_WIDTH DEM_HEIGHT GT0,GT1,GT2,GT3,GT4,GT5 OUTDIR

Reads the OBJ's vertices (map x y z, %.17g) and faces, and writes into
OUTDIR, each holding the very same triangles:
  ascii.stl       ASCII STL in map coordinates (%.17g: exact)
  pixel.stl       binary STL in the DEM's pixel frame as hmm writes it
                  (x column, y = height - 1 - row, float32 z: exact for a
                  Float32 DEM)
  hmm.stl         the same with z - 100 (-tin_transform 1,1,1,0,0,100)
  ascii.ply       ascii PLY, vertex x y z nx (an extra property), face
                  vertex_indices, plus one quad face (rejected)
  big.ply         binary_big_endian PLY, double x y z, an extra element
  hand.obj        OBJ with v/t/n corners, negative indices and a group
  sms.2dm         2DM with the elements before the nodes, ids reversed
  hand.xml        LandXML, P ids from 1001, one invisible face extra
  wkt.csv         one CSV row holding the whole TIN as TIN Z WKT
  faces.dxf       DXF 3DFACE entities, the fourth corner = the third
"""
import struct
import sys


def read_obj(path):
    v, f = [], []
    with open(path) as fh:
        for line in fh:
            w = line.split()
            if not w:
                continue
            if w[0] == "v":
                v.append(tuple(float(x) for x in w[1:4]))
            elif w[0] == "f":
                f.append(tuple(int(x) - 1 for x in w[1:4]))
    return v, f


def g(x):
    return repr(float(x))


def main():
    if len(sys.argv) != 6:
        sys.stderr.write(__doc__)
        return 2
    obj, width, height, gts, out = sys.argv[1:]
    height = int(height)
    gt = [float(x) for x in gts.split(",")]
    v, f = read_obj(obj)

    def pixel(p):
        # map -> pixel centre (north-up geotransform)
        c = (p[0] - gt[0]) / gt[1] - 0.5
        r = (p[1] - gt[3]) / gt[5] - 0.5
        return (round(c), height - 1 - round(r), p[2])

    with open(out + "/ascii.stl", "w") as o:
        o.write("solid tin\n")
        for t in f:
            o.write(" facet normal 0 0 1\n  outer loop\n")
            for i in t:
                o.write("   vertex %s %s %s\n" % tuple(g(c) for c in v[i]))
            o.write("  endloop\n endfacet\n")
        o.write("endsolid tin\n")
    for name, dz in (("pixel.stl", 0.0), ("hmm.stl", 100.0)):
        with open(out + "/" + name, "wb") as o:
            o.write(b"solid but binary".ljust(80, b" "))
            o.write(struct.pack("<I", len(f)))
            for t in f:
                o.write(struct.pack("<3f", 0, 0, 1))
                for i in t:
                    c, r, z = pixel(v[i])
                    o.write(struct.pack("<3f", c, r, z - dz))
                o.write(struct.pack("<H", 0))
    with open(out + "/ascii.ply", "w") as o:
        o.write("ply\nformat ascii 1.0\ncomment by hand\n")
        o.write("element vertex %d\nproperty double x\nproperty double y\n"
                "property double z\nproperty float nx\n" % len(v))
        o.write("element face %d\nproperty list uchar int vertex_indices\n"
                "end_header\n" % (len(f) + 1))
        for p in v:
            o.write("%s %s %s 0.5\n" % tuple(g(c) for c in p))
        for t in f:
            o.write("3 %d %d %d\n" % t)
        o.write("4 0 1 2 3\n")
    with open(out + "/big.ply", "wb") as o:
        o.write(("ply\nformat binary_big_endian 1.0\n"
                 "element camera 1\nproperty float fov\n"
                 "element vertex %d\nproperty double x\nproperty double y\n"
                 "property double z\nelement face %d\n"
                 "property list uchar uint vertex_index\n"
                 "property uchar red\nend_header\n" % (len(v), len(f))).encode())
        o.write(struct.pack(">f", 60.0))
        for p in v:
            o.write(struct.pack(">3d", *p))
        for t in f:
            o.write(struct.pack(">B3IB", 3, t[0], t[1], t[2], 200))
    with open(out + "/hand.obj", "w") as o:
        o.write("# by hand\nmtllib none.mtl\ng tin\n")
        for p in v:
            o.write("v %s %s %s\nvn 0 0 1\n" % tuple(g(c) for c in p))
        n = len(v)
        for k, t in enumerate(f):
            if k % 2:
                o.write("f %d %d %d\n" % tuple(i - n for i in t))
            else:
                o.write("f %d/1/%d %d//%d %d\n" % (t[0] + 1, t[0] + 1,
                                                 t[1] + 1, t[1] + 1, t[2] + 1))
    with open(out + "/sms.2dm", "w") as o:
        o.write("MESH2D\n")
        n = len(v)
        for k, t in enumerate(f):
            o.write("E3T %d %d %d %d 1\n" % (k + 1, n - t[0], n - t[1], n - t[2]))
        for k, p in enumerate(v):
            o.write("ND %d %s %s %s\n" % ((n - k,) + tuple(g(c) for c in p)))
    with open(out + "/hand.xml", "w") as o:
        o.write('<?xml version="1.0"?>\n<!-- by hand -->\n'
                '<LandXML xmlns="http://www.landxml.org/schema/LandXML-1.2" '
                'version="1.2">\n<Surfaces>\n<Surface name="ground">\n'
                '<Definition surfType="TIN">\n<Pnts>\n')
        for k, p in enumerate(v):
            o.write('<P id="%d">%s %s %s</P>\n' % (1001 + k, g(p[1]), g(p[0]), g(p[2])))
        o.write("</Pnts>\n<Faces>\n")
        for t in f:
            o.write("<F>%d %d %d</F>\n" % tuple(1001 + i for i in t))
        o.write('<F i="1">1001 1002 1003</F>\n</Faces>\n</Definition>\n'
                "</Surface>\n</Surfaces>\n</LandXML>\n")
    with open(out + "/wkt.csv", "w") as o:
        o.write("id,WKT\n1,\"TIN Z (")
        o.write(",".join("((%s))" % ",".join(
            "%s %s %s" % tuple(g(c) for c in v[i]) for i in (t + (t[0],)))
            for t in f))
        o.write(")\"\n")
    with open(out + "/faces.dxf", "w") as o:
        o.write("  0\nSECTION\n  2\nENTITIES\n")
        for t in f:
            o.write("  0\n3DFACE\n  8\n0\n")
            for k, i in enumerate(t + (t[2],)):
                for a in range(3):
                    o.write(" %d\n%s\n" % (10 * (a + 1) + k, g(v[i][a])))
        o.write("  0\nENDSEC\n  0\nEOF\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
