#!/usr/bin/env python3
"""How much of each shared DEM a default bound keeps.

For every DEM of ../shared/testdata (the surveyed and lidar grids, not the
parser edge cases) this runs `terratin simplify -json` under the default
bound (twice the mean step between 4-neighbour samples) and, for the
comparison, at 1 and 4 times the mean step and at the former default, 0.5 %
of the height range; it prints the share of the valid samples each keeps
as vertices. docs/cli.md "The default bound" has the table and the reason
for the rule.

  bench/default_bound.py [build/terratin] [SHARED_TESTDATA]

(the table on stdout, the range of the shares on stderr; exit 77 without
the shared DEMs)
"""
import json
import os
import subprocess
import sys
import tempfile

DEMS = [
    "garland_heckbert_terra_scape/crater.stm.vrt",
    "garland_heckbert_terra_scape/ashby.stm.vrt",
    "garland_heckbert_terra_scape/ozark.stm.vrt",
    "garland_heckbert_terra_scape/ntc.stm.vrt",
    "gdal_autotest/n43.tif",
    "gdal_autotest/warp_52_dem.tif",
    "usgs_dem_san_francisco/sanfranciscos.dem",
    "gdalraster/lf_elev_220_mt_hood_utm.tif",
    "gdalraster/storml_elev_orig.tif",
    "rspatial_terra/elev.tif",
    "rspatial_terra/elev_vinschgau.tif",
    "pysheds/dem.tif",
    "landlab/west_bijou_gully.asc",
    "landlab/west_bijou_escarpment_snippet.asc",
    "landlab/DEM-kootenai_37x50_1x1.asc",
    "landlab/pre_runout_DEM.asc",
    "topotoolbox/exampleDEM_orkhon.asc",
    "mesher_granger_lidar/dem.tif",
    "hoppe_grand_canyon/gcanyon_elev_crop.bw.png",
    "whiteboxR/DEM.tif",
    "spatial.tools_tahoe_lidar/tahoe_lidar_bareearth.tif",
    "spatial.tools_tahoe_lidar/tahoe_lidar_highesthit.tif",
    "Rsagacmd/srtm.tif",
    "tin-terrain/valid_raster.tif",
]


def run(terratin, dem, out, extra):
    cmd = [terratin, "simplify", "-q", "-json", "-overwrite", "-layers",
           "run_parameters"] + extra + [dem, out]
    p = subprocess.run(cmd, capture_output=True, text=True)
    if p.returncode != 0:
        raise RuntimeError(p.stderr.strip())
    return json.loads(p.stdout)


def main():
    terratin = sys.argv[1] if len(sys.argv) > 1 else "build/terratin"
    data = sys.argv[2] if len(sys.argv) > 2 else os.environ.get(
        "TT_SHARED_TESTDATA", os.path.join(os.path.dirname(__file__), "..",
                                           "..", "shared", "testdata"))
    if not os.path.isdir(data):
        print(f"default_bound: skipped: {data} is not there", file=sys.stderr)
        return 77
    head = ("DEM", "valid", "step", "1 step", "2 steps (default)",
            "4 steps", "0.5 % range")
    print("| " + " | ".join(head) + " |")
    print("|" + "|".join("---" for _ in head) + "|")
    shares = []
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "t.gpkg")
        for name in DEMS:
            dem = os.path.join(data, name)
            if not os.path.exists(dem):
                continue
            try:
                d = run(terratin, dem, out, [])
            except RuntimeError as e:
                print(f"| {name} | failed: {e} |")
                continue
            valid = d["valid_samples"]
            step = d["limits"]["mean_step"]
            default = d["limits"]["max_error"]

            def share(j):
                return 100.0 * j["vertices"] / valid

            cells = []
            for k in (1, 4):
                cells.append(share(run(terratin, dem, out,
                                       ["-max_error", f"{k * step:.6g}"])))
            rng = 0.005 * (d["z_max"] - d["z_min"])
            old = share(run(terratin, dem, out, ["-max_error", f"{rng:.6g}"]))
            shares.append(share(d))
            print(f"| {name} | {valid} | {step:.3g} | {cells[0]:.1f} % | "
                  f"{share(d):.1f} % (E = {default:g}) | {cells[1]:.1f} % | "
                  f"{old:.1f} % |")
    if shares:
        shares.sort()
        print(f"default bound: {len(shares)} DEMs keep {shares[0]:.1f} % to "
              f"{shares[-1]:.1f} % of their valid samples, median "
              f"{shares[len(shares) // 2]:.1f} %", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
