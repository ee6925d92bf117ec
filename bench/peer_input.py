#!/usr/bin/python3
"""peer_input.py -- a DEM in the forms the peers of bench/run.sh read.

    /usr/bin/python3 bench/peer_input.py DEM OUTPREFIX

Writes, from band 1 of DEM (any GDAL raster), with Debian's python3-gdal:
  OUTPREFIX.raw, .hdr  row-major Float32 samples and their ENVI header
                       (delatin)
  OUTPREFIX.png        16-bit grayscale PNG, zmin..zmax scaled to 0..65535
                       (hmm, which reads 8- or 16-bit images; its -z is then
                       zmax - zmin and its -e the max error / (zmax - zmin))
  OUTPREFIX.info.json  size, geoTransform (as gdalinfo -json names them),
                       zmin, zmax and the count of nodata samples filled
Neither peer knows nodata: nodata samples are filled with zmin (the peers
then mesh a flat apron there; terratin eval measures every TIN against the
valid samples only). Not timed by run.sh.
"""
import json
import sys

import numpy as np
from osgeo import gdal

gdal.UseExceptions()


def main():
    if len(sys.argv) != 3:
        sys.stderr.write(__doc__)
        return 2
    dem, prefix = sys.argv[1], sys.argv[2]
    ds = gdal.Open(dem)
    band = ds.GetRasterBand(1)
    z = band.ReadAsArray().astype(np.float64)
    valid = np.isfinite(z)
    nodata = band.GetNoDataValue()
    if nodata is not None:
        valid &= z != nodata
    mask = band.GetMaskBand().ReadAsArray()
    valid &= mask != 0
    zmin, zmax = float(z[valid].min()), float(z[valid].max())
    z[~valid] = zmin
    z.astype(np.float32).tofile(prefix + ".raw")
    with open(prefix + ".hdr", "w") as f:
        f.write("ENVI\nsamples = %d\nlines = %d\nbands = 1\n"
                "header offset = 0\ndata type = 4\ninterleave = bsq\n"
                "byte order = 0\n" % (ds.RasterXSize, ds.RasterYSize))
    span = zmax - zmin if zmax > zmin else 1.0
    q = np.rint((z - zmin) / span * 65535.0).clip(0, 65535).astype(np.uint16)
    mem = gdal.GetDriverByName("MEM").Create("", ds.RasterXSize,
                                             ds.RasterYSize, 1, gdal.GDT_UInt16)
    mem.GetRasterBand(1).WriteArray(q)
    gdal.GetDriverByName("PNG").CreateCopy(prefix + ".png", mem)
    info = {
        "size": [ds.RasterXSize, ds.RasterYSize],
        "geoTransform": list(ds.GetGeoTransform()),
        "zmin": zmin,
        "zmax": zmax,
        "filled": int((~valid).sum()),
    }
    with open(prefix + ".info.json", "w") as f:
        json.dump(info, f)
    return 0


if __name__ == "__main__":
    sys.exit(main())
