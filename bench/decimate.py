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
  budget   Crater Lake at 10,000 vertices: insertion and both selections.

Each prints the table of docs/decimation.md it makes (bench/doc_tables.py
reruns them there); it exits 77 when a shared DEM is absent.

Usage: bench/decimate.py WHAT [TERRATIN]   (TERRATIN default build/terratin)
Shared DEMs come from $TT_SHARED_TESTDATA (default ../shared/testdata).
Prints a markdown table; runs are short, one at a time.
"""
import atexit, json, os, resource, shutil, subprocess, sys, tempfile, time

HERE = os.path.dirname(os.path.abspath(__file__))
T = sys.argv[2] if len(sys.argv) > 2 else os.path.join(HERE, "..", "build", "terratin")
SHARED = os.environ.get("TT_SHARED_TESTDATA", os.path.join(HERE, "..", "..", "shared", "testdata"))
CRATER = os.path.join(SHARED, "garland_heckbert_terra_scape", "crater.stm.vrt")
HOOD = os.path.join(SHARED, "gdalraster", "lf_elev_220_mt_hood_utm.tif")
TMP = tempfile.mkdtemp(prefix="tt_bench_dec.")
atexit.register(shutil.rmtree, TMP, True)
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


def need(path):
    """Exit 77 (skipped, for bench/doc_tables.py) when a shared DEM is absent."""
    if not os.path.exists(path):
        sys.stderr.write(f"SKIP: {path} is absent (shared test data)\n")
        raise SystemExit(77)


def table2():
    """docs/decimation.md: the study's Table 2 beside the published column."""
    need(CRATER)
    print("| deleted | | " + " | ".join(CRITERIA).replace("mean_curvature", "mean_curv.")
          .replace("gaussian_curvature", "gaussian") + " |")
    print("|---|---|" + "---|" * len(CRITERIA))
    for pct in (10, 25, 50, 75):
        keep = 100000 - 1000 * pct
        row = [run(CRATER, "-method", "decimate", "-start", "greedy:100000",
                   "-importance", "hdh", "-selection", "independent",
                   "-criterion", c, "-max_points", keep) for c in CRITERIA]
        print(f"| {pct} % | ours | " +
              " | ".join(f"{d['mean_abs_error']:.4f}" for d in row) + " |")
        print("| | study | " +
              " | ".join(f"{v:.4f}" for v in PUBLISHED[pct]) + " |", flush=True)
        sys.stderr.write(f"{pct} %: seconds " +
                         " ".join(f"{d['_wall']:.1f}" for d in row) + "\n")


def budget():
    """docs/decimation.md: Crater Lake at 10,000 vertices, each selection."""
    need(CRATER)
    print("| Crater Lake, 10,000 vertices | RMSE | mean | max |")
    print("|---|---|---|---|")
    runs = [("insert", [])]
    for sel in ("independent", "sequential"):
        runs.append((f"decimate `-importance error -selection {sel}`",
                     ["-method", "decimate", "-start", "greedy",
                      "-importance", "error", "-selection", sel]))
    for label, args in runs:
        d = run(CRATER, *args, "-max_points", 10000)
        print(f"| {label} | {d['rmse']:.4g} | {d['mean_abs_error']:.4g} | "
              f"{d['max_error']:.6g} |", flush=True)


def versus():
    """docs/decimation.md: decimate against insert at a bound and a budget."""
    need(CRATER)
    need(HOOD)
    dems = [("Crater Lake", CRATER, 2, 10000),
            ("Mt Hood", HOOD, 5, 20000),
            ("fractal 1025²", fractal(), 4, 21000)]
    print("| DEM (bound, budget) | method | vertices at the bound | s (CPU) | "
          "RMSE | mean | max |")
    print("|---|---|---|---|---|---|---|")
    for name, dem, e, budget in dems:
        start = "all" if "fractal" in name else "greedy"
        runs = [("insert", ["-max_error", e], ["-max_points", budget])]
        for sel in ("independent", "sequential"):
            dec = ["-method", "decimate", "-start", start, "-importance",
                   "error", "-selection", sel]
            runs.append((f"decimate {sel}", dec + ["-max_error", e],
                         dec + ["-max_points", budget]))
        got = [(label, run(dem, *at_bound), run(dem, *at_budget))
               for label, at_bound, at_budget in runs]
        low = {k: min(x[2 if k != "vertices" else 1][k] for x in got)
               for k in ("vertices", "rmse", "mean_abs_error", "max_error")}

        def cell(d, k, text):
            return f"**{text}**" if d[k] == low[k] else text
        for i, (label, a, b) in enumerate(got):
            dem_cell = f"{name} ({e}, {budget:,})" if i == 0 else ""
            print(f"| {dem_cell} | {label} | "
                  + cell(a, "vertices", format(a["vertices"], ",")) + " | "
                  + f"{a['_wall']:.2f} ({a['_cpu']:.2f}) | "
                  + " | ".join(cell(b, k, format(b[k], ".4g"))
                               for k in ("rmse", "mean_abs_error",
                                         "max_error")) + " |", flush=True)


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
    """docs/decimation.md: vertices left at -max_error 2 (CPU seconds)."""
    need(CRATER)
    sels = (["-selection", "independent"],
            ["-selection", "independent", "-onepass"],
            ["-selection", "sequential"])
    rows = {}
    for imp in ("degree", "hdh", "abh", "volume", "drop", "error"):
        rows[imp] = [run(CRATER, "-method", "decimate", "-start", "greedy",
                         "-importance", imp, *sel, "-max_error", 2)
                     for sel in sels]
    best = min(d["vertices"] for r in rows.values() for d in r)
    print("| importance | independent | independent -onepass | sequential |")
    print("|---|---|---|---|")
    for imp, r in rows.items():
        cell = [(f"**{d['vertices']:,}**" if d["vertices"] == best
                 else f"{d['vertices']:,}") + f" ({d['_cpu']:.2f})" for d in r]
        print(f"| {imp} | " + " | ".join(cell) + " |")


if __name__ == "__main__":
    what = sys.argv[1] if len(sys.argv) > 1 else "table2"
    {"table2": table2, "budget": budget, "versus": versus, "speed": speed,
     "select": select}[what]()
