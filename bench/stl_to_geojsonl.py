#!/usr/bin/python3
"""stl_to_geojsonl.py -- hmm's binary STL back on the DEM, for terratin eval.

    /usr/bin/python3 bench/stl_to_geojsonl.py TIN.stl DEM.info.json OUT.geojsonl

hmm writes vertex (x, y, z) = (column, height - 1 - row, normalized height
* zscale); with the zscale and PNG of bench/peer_input.py the DEM height is
zmin + z. Each triangle becomes a Polygon Z feature in the DEM's map
coordinates at pixel centres (geotransform of column + 0.5, row + 0.5), as
terratin places its samples, one per line (GeoJSON text sequence).
"""
import json
import struct
import sys


def main():
    if len(sys.argv) != 4:
        sys.stderr.write(__doc__)
        return 2
    stl, info_path, out = sys.argv[1:]
    with open(info_path) as f:
        info = json.load(f)
    gt = info["geoTransform"]
    h1 = info["size"][1] - 1
    zmin = info["zmin"]
    with open(stl, "rb") as f:
        data = f.read()
    (n,) = struct.unpack_from("<I", data, 80)
    with open(out, "w") as o:
        for i in range(n):
            v = struct.unpack_from("<9f", data, 84 + 50 * i + 12)
            ring = []
            for k in range(3):
                c, r = v[3 * k], h1 - v[3 * k + 1]
                x = gt[0] + (c + 0.5) * gt[1] + (r + 0.5) * gt[2]
                y = gt[3] + (c + 0.5) * gt[4] + (r + 0.5) * gt[5]
                ring.append([x, y, zmin + v[3 * k + 2]])
            ring.append(ring[0])
            o.write(json.dumps({"type": "Feature", "properties": {},
                                "geometry": {"type": "Polygon",
                                             "coordinates": [ring]}}) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
