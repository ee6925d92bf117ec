#!/usr/bin/env python3
"""bench/optimize_tables.py -- the tables of docs/optimize.md.

  bump        `generate bump` (20 x 30), Delaunay TINs of 10 % and 25 %:
              L2's RMS error after local swap, look-ahead, annealing with
              the study's parameters (t0 0.01, S = G = 15, K = 500) for
              seeds 1-5, and annealing with the defaults
  bumpmean    the same bump, the 25 % TIN: mean absolute error after the
              local swap and annealing (the study's parameters, seeds 1-5)
              under mean curvature, abn_sum and Gaussian curvature
  crater P    Crater Lake, the greedy Delaunay TIN of P % re-optimised by
              `terratin optimize` under every criterion and mode: mean
              absolute error / seconds / (Min-Max criteria) largest angle
  optimum B   the optimisers against the true optimum of small point sets
              (tests/optimize/test_optimum.c, built in build folder B) over
              seeds 1-5: how often each reaches it from a random
              triangulation
  edges       Crater Lake, Delaunay TINs of 1,000, 10,000, 100,000
              vertices: seconds of local swap and edge insertion under
              minmax_angle, and triangles above 120 and 150 degrees

Usage: bench/optimize_tables.py bump|bumpmean|crater P|edges|optimum B
       [TERRATIN]
Prints the markdown table (bench/doc_tables.py reruns it in the docs);
exits 77 when Crater Lake is absent (../shared/testdata or
$TT_SHARED_TESTDATA).
"""
import atexit, json, math, os, shutil, sqlite3, subprocess, sys, tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
ARGS = sys.argv[1:]
WHAT = ARGS.pop(0) if ARGS else "bump"
PCT = ARGS.pop(0) if WHAT in ("crater", "optimum") and ARGS else "1"
T = ARGS[0] if ARGS else os.path.join(HERE, "..", "build", "terratin")
SHARED = os.environ.get("TT_SHARED_TESTDATA", os.path.join(HERE, "..", "..", "shared", "testdata"))
CRATER = os.path.join(SHARED, "garland_heckbert_terra_scape", "crater.stm.vrt")
TMP = tempfile.mkdtemp(prefix="tt_bench_opt.")
atexit.register(shutil.rmtree, TMP, True)
CRITERIA = ["delaunay", "minmax_angle", "minmax_angle_lex", "min_area",
            "mean_curvature", "gaussian_curvature", "abn", "abn_sum",
            "abn_sumsq", "l2"]
STUDY_ANNEAL = ["-anneal_t0", "0.01", "-anneal_swaps", "15", "-anneal_good",
                "15", "-anneal_stages", "500"]


def tt(*args):
    p = subprocess.run([T, *map(str, args)], capture_output=True, text=True)
    if p.returncode != 0:
        raise SystemExit(f"terratin {' '.join(map(str, args))}: {p.stderr.strip()}")
    return json.loads(p.stdout) if "-json" in args else None


def start(dem, *args):
    out = os.path.join(TMP, "start.gpkg")
    tt("simplify", "-q", "-overwrite", *args, dem, out)
    return out


def optimize(dem, tin, *args):
    out = os.path.join(TMP, "opt.gpkg")
    d = tt("optimize", "-q", "-json", "-overwrite", *args, dem, tin, out)
    d["_out"] = out
    return d


def bump():
    dem = os.path.join(TMP, "bump.tif")
    tt("generate", "bump", "-q", dem)
    print("| TIN | local | lookahead | anneal, seeds 1–5 | anneal, defaults |")
    print("|---|---|---|---|---|")
    for pct in (10, 25):
        tin = start(dem, "-percent", pct)
        rms = lambda *a: f"{optimize(dem, tin, '-criterion', 'l2', *a)['after']['rmse']:.6g}"
        seeds = ", ".join(rms("-optimize", "anneal", *STUDY_ANNEAL, "-seed", s)
                          for s in range(1, 6))
        print(f"| {pct} % | {rms('-optimize', 'local')} | "
              f"{rms('-optimize', 'lookahead')} | {seeds} | "
              f"{rms('-optimize', 'anneal')} |", flush=True)


def bumpmean():
    dem = os.path.join(TMP, "bump.tif")
    tt("generate", "bump", "-q", dem)
    tin = start(dem, "-percent", 25)
    print("| criterion | local | anneal, seeds 1–5 |")
    print("|---|---|---|")
    for c in ("mean_curvature", "abn_sum", "gaussian_curvature"):
        mean = lambda *a: f"{optimize(dem, tin, '-criterion', c, *a)['after']['mean_abs_error']:.6g}"
        seeds = ", ".join(mean("-optimize", "anneal", *STUDY_ANNEAL, "-seed", s)
                          for s in range(1, 6))
        print(f"| {c} | {mean('-optimize', 'local')} | {seeds} |", flush=True)


def crater():
    tin = start(CRATER, "-percent", PCT)
    modes = ["local", "lookahead", "anneal", "edge_insertion"]
    print("| criterion | local | lookahead | anneal | edge insertion |")
    print("|---|---|---|---|---|")
    for c in CRITERIA:
        cells = []
        for m in modes:
            if m == "edge_insertion" and c != "minmax_angle":
                cells.append("—")
                continue
            if m == "anneal" and c == "delaunay":
                cells.append("(local)")
                continue
            d = optimize(CRATER, tin, "-criterion", c, "-optimize", m)
            cell = (f"{d['after']['mean_abs_error']:#.4g} / "
                    f"{d['seconds']['optimize']:.3g} s")
            if c.startswith("minmax_angle"):
                cell += f" / {d['after']['largest_angle_deg']:.2f}°"
            cells.append(cell)
        print(f"| {c} | " + " | ".join(cells) + " |", flush=True)


def obtuse(gpkg):
    """Triangles of a TIN whose largest angle exceeds 120 and 150 degrees."""
    con = sqlite3.connect(gpkg)
    fields = [r[1] for r in con.execute("PRAGMA table_info(triangles)")]
    col = next(f for f in fields if "angle" in f and "max" in f)
    n120, n150 = con.execute(f"SELECT SUM({col} > 120), SUM({col} > 150) "
                             "FROM triangles").fetchone()
    con.close()
    return n120, n150


def edges():
    print("| vertices | local swap | edge insertion | > 120° (Delaunay / "
          "local / insertion) | > 150° |")
    print("|---|---|---|---|---|")
    for n in (1000, 10000, 100000):
        tin = start(CRATER, "-max_points", n)
        d0 = obtuse(tin)
        a = optimize(CRATER, tin, "-criterion", "minmax_angle", "-optimize", "local")
        d1 = obtuse(a["_out"])
        b = optimize(CRATER, tin, "-criterion", "minmax_angle", "-optimize",
                     "edge_insertion")
        d2 = obtuse(b["_out"])
        print(f"| {n:,} | {a['seconds']['optimize']:.3g} s | "
              f"{b['seconds']['optimize']:.3g} s | {d0[0]} / {d1[0]} / {d2[0]} | "
              f"{d0[1]} / {d1[1]} / {d2[1]} |", flush=True)


def optimum():
    test = os.path.join(PCT, "tests", "test_optimum")
    counts, sets = {}, 0
    for seed in range(1, 6):
        p = subprocess.run([test], capture_output=True, text=True,
                           env={**os.environ, "TT_SEED": str(seed)})
        if p.returncode != 0:
            raise SystemExit(f"TT_SEED={seed} {test}: {p.stdout[-300:]}")
        lines = p.stdout.splitlines()
        head = next(i for i, l in enumerate(lines)
                    if l.startswith("optimum reached from a random"))
        sets += int(lines[head].split("(of ")[1].split()[0])
        for l in lines[head + 2:]:
            f = l.split()
            if len(f) != 4 or not f[1].isdigit():
                break
            c = counts.setdefault(f[0], [0, 0, 0])
            for k in range(3):
                c[k] += int(f[k + 1])
    print("| criterion | local | lookahead | anneal |")
    print("|---|---|---|---|")
    for c, v in counts.items():
        print(f"| {c} | {v[0]} | {v[1]} | {v[2]} |")
    sys.stderr.write(f"{sets} sets\n")


if __name__ == "__main__":
    if WHAT == "optimum":
        optimum()
        sys.exit(0)
    if WHAT not in ("bump", "bumpmean") and not os.path.exists(CRATER):
        sys.stderr.write(f"SKIP: {CRATER} is absent (shared test data)\n")
        sys.exit(77)
    {"bump": bump, "bumpmean": bumpmean, "crater": crater,
     "edges": edges}[WHAT]()
