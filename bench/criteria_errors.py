#!/usr/bin/env python3
"""bench/criteria_errors.py -- the error tables of docs/criteria.md.

  l2     Crater Lake, mean absolute error of L2 insertion under each
         -repair / -optimize setting at 1, 10, 25, 50 % of the samples,
         beside Delaunay's and the 2004 study's L2 (SPEC section 6)
  ours   Crater Lake, mean absolute error of every criterion with its
         defaults (`simplify -percent P -criterion NAME`) at 1, 10, 25, 50 %

Usage: bench/criteria_errors.py l2|ours [TERRATIN]  (default build/terratin)
Prints the markdown table (bench/doc_tables.py reruns it in the docs);
exits 77 when Crater Lake (../shared/testdata or $TT_SHARED_TESTDATA) is
absent.
"""
import atexit, json, os, shutil, subprocess, sys, tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
T = sys.argv[2] if len(sys.argv) > 2 else os.path.join(HERE, "..", "build", "terratin")
SHARED = os.environ.get("TT_SHARED_TESTDATA", os.path.join(HERE, "..", "..", "shared", "testdata"))
CRATER = os.path.join(SHARED, "garland_heckbert_terra_scape", "crater.stm.vrt")
PERCENTS = (1, 10, 25, 50)
STUDY_L2 = (4.24232, 0.671814, 0.262467, 0.0570321)  # SPEC section 6
TMP = tempfile.mkdtemp(prefix="tt_bench_crit.")
atexit.register(shutil.rmtree, TMP, True)


def mean_error(*args):
    out = os.path.join(TMP, "out.gpkg")
    cmd = [T, "simplify", "-q", "-json", "-overwrite", *map(str, args), CRATER, out]
    p = subprocess.run(cmd, capture_output=True, text=True)
    if p.returncode != 0:
        raise SystemExit(f"{' '.join(cmd)}: {p.stderr.strip()}")
    return json.loads(p.stdout)["mean_abs_error"]


def row(*args):
    return [mean_error("-percent", p, *args) for p in PERCENTS]


def l2():
    settings = [
        ("`-repair delaunay -optimize local` (default)",
         ["-repair", "delaunay", "-optimize", "local"]),
        ("`-repair delaunay -optimize lookahead`",
         ["-repair", "delaunay", "-optimize", "lookahead"]),
        ("`-repair flip`", ["-repair", "flip"]),
        ("`-repair local` (the maximal-reduction swap after each insertion)",
         ["-repair", "local"])]
    print("| `l2` with | " + " | ".join(f"{p} %" for p in PERCENTS) + " |")
    print("|---|" + "---|" * len(PERCENTS))
    for i, (label, args) in enumerate(settings):
        v = row("-criterion", "l2", *args)
        text = [f"{x:.4g}" for x in v]
        if i == 0:
            text = [f"**{t}**" for t in text]
        print(f"| {label} | " + " | ".join(text) + " |", flush=True)
    v = row("-criterion", "delaunay")
    print("| `delaunay`, for comparison | " +
          " | ".join(f"{x:.4g}" for x in v) + " |")
    print("| the 2004 study's L2 (SPEC §6) | " +
          " | ".join(f"{x:.4g}" for x in STUDY_L2) + " |")


def ours():
    print("| % inserted | Delaunay | Min-Max angle (lex) | Min area | "
          "Mean curv. | Gaussian | ABN (sum, sumsq) | L2 |")
    print("|---|---|---|---|---|---|---|---|")
    for p in PERCENTS:
        e = {c: mean_error("-percent", p, "-criterion", c) for c in (
            "delaunay", "minmax_angle", "minmax_angle_lex", "min_area",
            "mean_curvature", "gaussian_curvature", "abn", "abn_sum",
            "abn_sumsq", "l2")}
        g = lambda c: f"{e[c]:.4g}"
        print(f"| {p} | {g('delaunay')} | {g('minmax_angle')} "
              f"({g('minmax_angle_lex')}) | {g('min_area')} | "
              f"{g('mean_curvature')} | {g('gaussian_curvature')} | "
              f"{g('abn')} ({g('abn_sum')}, {g('abn_sumsq')}) | "
              f"**{g('l2')}** |", flush=True)


if __name__ == "__main__":
    if not os.path.exists(CRATER):
        sys.stderr.write(f"SKIP: {CRATER} is absent (shared test data)\n")
        sys.exit(77)
    {"l2": l2, "ours": ours}[sys.argv[1] if len(sys.argv) > 1 else "l2"]()
