#!/usr/bin/env python3
"""bench/decimate.py -- the measurements of docs/decimation.md.

  table2   the study's Table 2 on Crater Lake: start greedy:100000,
           -importance hdh, independent sets, average error after deleting
           10/25/50/75 % of the points, every criterion, beside the
           published column (SPEC section 6).
  versus   decimate against insert at the same -max_error (vertices,
           seconds) and at the same vertex budget (RMSE, mean error) on
           Crater Lake, Mt Hood and a 1025^2 diamond-square fractal.
  speed    1025^2 fractal from -start all to 2 % against greedy insertion
           to the same vertex count, wall and CPU seconds, peak memory.
  select   importance x selection at one bound on Crater Lake.

Usage: bench/decimate.py WHAT [TERRATIN]   (TERRATIN default build/terratin)
Shared DEMs come from $TT_SHARED_TESTDATA (default ../shared/testdata).
Prints a markdown table; runs are short, one at a time.
"""
import json, os, resource, subprocess, sys, tempfile, time

HERE = os.path.dirname(os.path.abspath(__file__))
T = sys.argv[2] if len(sys.argv) > 2 else os.path.join(HERE, "..", "build", "terratin")
SHARED = os.environ.get("TT_SHARED_TESTDATA", os.path.join(HERE, "..", "..", "shared", "testdata"))
CRATER = os.path.join(SHARED, "garland_heckbert_terra_scape", "crater.stm.vrt")
HOOD = os.path.join(SHARED, "gdalraster", "lf_elev_220_mt_hood_utm.tif")
TMP = tempfile.mkdtemp(prefix="tt_bench_dec.")
CRITERIA = ["delaunay", "minmax_angle", "min_area", "mean_curvature",
            "gaussian_curvature", "abn", "l2"]
PUBLISHED = {  # SPEC section 6, decimation of Crater Lake, average error
    10: [0.0749882, 0.101097, 0.135328, 0.0933276, 0.0924291, 0.079581, 0.0346918],
    25: [0.192211, 0.21639, 0.253581, 0.188033, 0.184535, 0.184385, 0.0881985],
    50: [0.461684, 0.484298, 0.586801, 0.452728, 0.409, 0.453085, 0.257116],
    75: [0.886049, 0.908521, 1.17482, 0.922817, 0.828301, 0.943499, 0.57783]}


def run(dem, *args):
    """One simplify run: its JSON, wall and CPU seconds, peak RSS (MB)."""
    out = os.path.join(TMP, "out.gpkg")
    cmd = [T, "simplify", "-q", "-json", "-overwrite", *map(str, args), dem, out]
    r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.monotonic()
    p = subprocess.run(cmd, capture_output=True, text=True)
    wall = time.monotonic() - t0
    r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    if p.returncode != 0:
        raise SystemExit(f"{' '.join(cmd)}: {p.stderr.strip()}")
    d = json.loads(p.stdout)
    d["_wall"] = wall
    d["_cpu"] = (r1.ru_utime - r0.ru_utime) + (r1.ru_stime - r0.ru_stime)
    d["_rss_mb"] = r1.ru_maxrss / 1024.0  # max over children so far
    return d


def fractal():
    f = os.path.join(TMP, "fractal1025.tif")
    if not os.path.exists(f):
        subprocess.run([T, "generate", "diamond_square", "-size", "1025",
                        "-seed", "1", "-q", f], check=True)
    return f


def table2():
    print("| % deleted | points | " + " | ".join(CRITERIA) + " |")
    print("|---|---|" + "---|" * len(CRITERIA))
    res = {}
    for pct in (10, 25, 50, 75):
        keep = 100000 - 1000 * pct
        row = []
        for c in CRITERIA:
            d = run(CRATER, "-method", "decimate", "-start", "greedy:100000",
                    "-importance", "hdh", "-selection", "independent",
                    "-criterion", c, "-max_points", keep)
            row.append(d)
            res[(pct, c)] = d
        print(f"| {pct} ours | {keep} | " +
              " | ".join(f"{d['mean_abs_error']:.6g}" for d in row) + " |")
        print(f"| {pct} study | {100000 - keep} deleted | " +
              " | ".join(f"{v:.6g}" for v in PUBLISHED[pct]) + " |")
        print(f"| {pct} seconds | | " +
              " | ".join(f"{d['_wall']:.1f}" for d in row) + " |", flush=True)


def versus():
    dems = [("Crater Lake", CRATER, 2.0, 10000),
            ("Mt Hood", HOOD, 5.0, 20000),
            ("fractal 1025^2", fractal(), 4.0, 21000)]
    print("| DEM | method | at -max_error: vertices | s (cpu) | "
          "at the budget: RMSE | mean | max |")
    print("|---|---|---|---|---|---|---|")
    for name, dem, e, budget in dems:
        start = "all" if "fractal" in name else "greedy"
        runs = [("insert", ["-max_error", e], ["-max_points", budget])]
        for sel in ("independent", "sequential"):
            dec = ["-method", "decimate", "-start", start, "-importance",
                   "error", "-selection", sel]
            runs.append((f"decimate {sel}", dec + ["-max_error", e],
                         dec + ["-max_points", budget]))
        for label, at_bound, at_budget in runs:
            a = run(dem, *at_bound)
            b = run(dem, *at_budget)
            print(f"| {name} (E {e}, budget {budget}) | {label} | "
                  f"{a['vertices']} | {a['_wall']:.2f} ({a['_cpu']:.2f}) | "
                  f"{b['rmse']:.4g} | {b['mean_abs_error']:.4g} | "
                  f"{b['max_error']:.4g} |", flush=True)


def speed():
    f = fractal()
    n = int(0.02 * 1025 * 1025)
    a = run(f, "-max_points", n)
    b = run(f, "-method", "decimate", "-start", "all", "-importance", "error",
            "-percent", 2)
    c = run(f, "-method", "decimate", "-start", "all", "-importance", "hdh",
            "-percent", 2)
    for name, d in (("insert", a), ("decimate error", b), ("decimate hdh", c)):
        print(f"| {name} | {d['vertices']} | {d['_wall']:.2f} | "
              f"{d['_cpu']:.2f} | {d['seconds']['mesh']:.2f} | "
              f"{d['rmse']:.4g} | {d['max_error']:.4g} |", flush=True)


def select():
    print("| importance | selection | vertices | wall s | cpu s |")
    print("|---|---|---|---|---|")
    for imp in ("degree", "hdh", "abh", "volume", "drop", "error"):
        for sel in (["-selection", "independent"],
                    ["-selection", "independent", "-onepass"],
                    ["-selection", "sequential"]):
            d = run(CRATER, "-method", "decimate", "-start", "greedy",
                    "-importance", imp, *sel, "-max_error", 2)
            print(f"| {imp} | {' '.join(sel[1:])} | {d['vertices']} | "
                  f"{d['_wall']:.2f} | {d['_cpu']:.2f} |", flush=True)


if __name__ == "__main__":
    what = sys.argv[1] if len(sys.argv) > 1 else "table2"
    {"table2": table2, "versus": versus, "speed": speed,
     "select": select}[what]()
