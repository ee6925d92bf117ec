#!/usr/bin/python3
"""study_report.py -- docs/study/README.md from the runs of tools/study.sh.

Reads STUDY_OUT/<run>/curves.csv, runs.json and (crater_insert) tins/ of
the runs crater_insert, crater_decimate, generated, anneal and
crater_curves, and writes into --out:
  README.md    ours beside the published figures of SPEC section 6 (Crater
               Lake's Tables 1 and 2 and the run times), the generated
               terrains compared by the ranking of the criteria, and each
               finding of SPEC section 6 marked confirmed or refuted, the
               verdict and its evidence computed here from the numbers;
  <run>_tables.md, <run>_runs.json (and <run>_curves.csv but for the long
               crater_curves) copied from the runs.
Every number of README.md comes from those files; nothing in it is typed
by hand but the published figures below (SPEC section 6) and the rules.

Usage: study_report.py [--out DIR] STUDY_OUT
Exit codes: 0 success, 1 a missing or malformed input (one line naming
the file), 2 usage error.
"""
import argparse
import csv
import json
import math
import os
import shutil
import statistics
import sys

C7 = ["delaunay", "minmax_angle", "min_area", "mean_curvature",
      "gaussian_curvature", "abn", "l2"]
SHORT = {"delaunay": "Delaunay", "minmax_angle": "Min-Max angle",
         "min_area": "Min area", "mean_curvature": "Mean curv.",
         "gaussian_curvature": "Gaussian", "abn": "ABN", "l2": "L2"}
TWO_D = ["delaunay", "minmax_angle"]
DATA_DEP = ["min_area", "mean_curvature", "gaussian_curvature", "abn", "l2"]
WORSE = ["min_area", "mean_curvature", "gaussian_curvature", "abn"]
CRATER_N = 154224

# SPEC section 6: the study's published figures (average absolute error).
PUB_INSERT = {  # points: values in the order of C7
    1542: [5.26211, 5.24758, 7.52188, 6.49782, 6.86634, 6.80974, 4.24232],
    15422: [0.809917, 0.804217, 1.46247, 1.06522, 1.08695, 1.10184,
            0.671814],
    38556: [0.315733, 0.319663, 0.580354, 0.415044, 0.418539, 0.422042,
            0.262467],
    77112: [0.0864432, 0.0892028, 0.198774, 0.128764, 0.126879, 0.115222,
            0.0570321],
}
PUB_INSERT_PCT = {1542: 1, 15422: 10, 38556: 25, 77112: 50}
PUB_DECIMATE = {  # % deleted from 100,000 points: values
    10: [0.0749882, 0.101097, 0.135328, 0.0933276, 0.0924291, 0.079581,
         0.0346918],
    25: [0.192211, 0.21639, 0.253581, 0.188033, 0.184535, 0.184385,
         0.0881985],
    50: [0.461684, 0.484298, 0.586801, 0.452728, 0.409, 0.453085, 0.257116],
    75: [0.886049, 0.908521, 1.17482, 0.922817, 0.828301, 0.943499,
         0.57783],
}
PUB_SECONDS = [9, 16, 14, 38, 1211, 33, 26]  # 100,000 points, 2004
SMOOTH = ["fault_smooth", "sphere"]
ROUGH = ["fault_rough", "peak_rough", "valley_rough"]
QUORUM = 0.9  # a finding over many rows holds when 90 % of them agree
RUNS = ["crater_insert", "crater_decimate", "generated", "anneal",
        "crater_curves"]


class Bad(Exception):
    pass


def read_run(study_out, name):
    d = os.path.join(study_out, name)
    path = os.path.join(d, "curves.csv")
    try:
        with open(path, newline="") as f:
            rows = list(csv.DictReader(f))
        with open(os.path.join(d, "runs.json")) as f:
            meta = json.load(f)
    except OSError as e:
        raise Bad("%s: %s" % (e.filename, e.strerror))
    except ValueError as e:
        raise Bad("%s: does not parse (%s)" % (path, e))
    for r in rows:
        try:
            r["points"] = int(r["points"])
            for k in ("max_error", "l2", "rmse", "mean_abs_error",
                      "total_abs_error", "seconds"):
                r[k] = float(r[k])
        except (KeyError, ValueError):
            raise Bad("%s: a row does not parse: %r" % (path, r))
    return rows, meta


def table(rows, terrain, method, optimizer=None):
    """{points: {criterion: row}} of one terrain and method."""
    out = {}
    for r in rows:
        if r["terrain"] == terrain and r["method"] == method and \
                (optimizer is None or r["optimizer"] == optimizer):
            out.setdefault(r["points"], {})[r["criterion"]] = r
    return out


def checkpoints(rows, terrain, method, optimizer=None):
    """[{criterion: row}] of one terrain and method, a dict per checkpoint
    in the order of curves.csv (each checkpoint's rows are consecutive, one
    per criterion), so checkpoints whose point counts differ between
    criteria stay together."""
    out = []
    for r in rows:
        if r["terrain"] != terrain or r["method"] != method or \
                (optimizer is not None and r["optimizer"] != optimizer):
            continue
        if not out or r["criterion"] in out[-1]:
            out.append({})
        out[-1][r["criterion"]] = r
    return out


def ranks(values):
    """{criterion: rank 1..n} by mean error (ties share the best rank)."""
    order = sorted(values, key=lambda c: values[c])
    return {c: 1 + sum(values[o] < values[c] for o in order) for c in values}


def beside(ours, pub):
    """A published table's cells: ours (the best of the row in bold), then
    the study's and our difference to it, a cell per criterion of C7."""
    best = min(ours.values())
    cells = []
    for c in C7:
        b = "**" if ours[c] == best else ""
        cells.append("%s%s%s (%s, %s)" % (b, fmt(ours[c]), b, fmt(pub[c]),
                                          pct(ours[c] / pub[c] - 1)))
    return cells

def spearman(a, b):
    keys = list(a)
    ra, rb = ranks(a), ranks(b)
    n = len(keys)
    d2 = sum((ra[k] - rb[k]) ** 2 for k in keys)
    return 1 - 6.0 * d2 / (n * (n * n - 1))


def fmt(x):
    return "%.6g" % x


def pct(x):
    return "%+.1f %%" % (100.0 * x)


def ranking_text(values):
    order = sorted(values, key=lambda c: values[c])
    return " < ".join(SHORT.get(c, c) for c in order)


def verdict(ok):
    return "**confirmed**" if ok else "**refuted**"


def quorum(hits, total):
    return total > 0 and hits >= QUORUM * total


def min_angles_pixel(obj_path):
    """Smallest angle (degrees) of each triangle of an OBJ of tins/."""
    verts, out = [], []
    with open(obj_path) as f:
        for line in f:
            w = line.split()
            if not w:
                continue
            if w[0] == "v":
                verts.append((float(w[1]), float(w[2])))
            elif w[0] == "f":
                p = [verts[int(x) - 1] for x in w[1:4]]
                angs = []
                for i in range(3):
                    a, b, c = p[i], p[(i + 1) % 3], p[(i + 2) % 3]
                    u = (b[0] - a[0], b[1] - a[1])
                    v = (c[0] - a[0], c[1] - a[1])
                    nu, nv = math.hypot(*u), math.hypot(*v)
                    cosv = (u[0] * v[0] + u[1] * v[1]) / (nu * nv)
                    angs.append(math.degrees(math.acos(max(-1, min(1, cosv)))))
                out.append(min(angs))
    return out


def main(argv):
    ap = argparse.ArgumentParser(prog="study_report.py")
    ap.add_argument("study_out", metavar="STUDY_OUT")
    ap.add_argument("--out", default="docs/study")
    a = ap.parse_args(argv)
    try:
        return report(a.study_out, a.out)
    except Bad as e:
        sys.stderr.write("study_report.py: %s\n" % e)
        return 1


def report(study_out, out_dir):
    data = {n: read_run(study_out, n) for n in RUNS}
    L = []
    w = L.append
    ins_rows, ins_meta = data["crater_insert"]
    dec_rows, dec_meta = data["crater_decimate"]
    gen_rows, gen_meta = data["generated"]
    ann_rows, _ = data["anneal"]
    cur_rows, cur_meta = data["crater_curves"]
    crater_valid = ins_meta["terrains"]["1"]["valid_samples"]
    if crater_valid != CRATER_N:
        raise Bad("%s/crater_insert/runs.json: Crater Lake has %d valid "
                  "samples, the study's has %d" % (study_out, crater_valid,
                                                   CRATER_N))
    nruns = sum(len(data[n][0]) for n in RUNS)

    w("# Our reproduction of the 2004 criteria study")
    w("")
    w("Generated by `make study` (`tools/study.sh`, then "
      "`tools/study_report.py`): do not edit; every number below is "
      "computed from the runs' `curves.csv` (copied here as "
      "`*_curves.csv`, with their `*_tables.md` and `*_runs.json`, which "
      "hold every parameter). terratin %s, %s; %d runs."
      % (ins_meta["version"], ins_meta["created"], nruns))
    w("")
    def final_passes(rows):
        seen = {}
        for r in rows:
            seen.setdefault(r["criterion"], set()).add(r["optimizer"])
        return ", ".join("%s %s" % (SHORT.get(c, c), "/".join(sorted(seen[c])))
                         for c in C7 if c in seen)
    w("Each criterion is run as `terratin study` runs it by default "
      "(`-optimizers auto`, [docs/cli.md](../cli.md) says how each is "
      "inserted); the final pass of each (the `optimizer` column of the "
      "CSVs) in the insertion runs: %s; in the decimation runs: %s. The "
      "study inserted Delaunay and Min-Max angle with "
      "their flips, min area with the dynamic programme over the hole, "
      "and every other criterion by Delaunay insertion followed by the "
      "local swap (SPEC section 6). The error measure of the tables is "
      "the average absolute error over the valid samples."
      % (final_passes(ins_rows), final_passes(dec_rows)))
    w("")
    w("A finding that is checked over many rows is **confirmed** when it "
      "holds in at least %d %% of them, **refuted** otherwise; the counts "
      "are given." % round(QUORUM * 100))
    w("")

    # --- Table 1 --------------------------------------------------------
    w("## Crater Lake, greedy insertion (the study's Table 1)")
    w("")
    w("Average absolute error: ours, then the study's and our difference "
      "to it; the best of each row of ours in bold.")
    w("")
    t1 = table(ins_rows, "crater", "insert")
    w("| % inserted | points | " + " | ".join(SHORT[c] for c in C7) +
      " | rank agreement |")
    w("|---|---|" + "---|" * len(C7) + "---|")
    t1_ours = {}
    for pts in sorted(PUB_INSERT):
        if pts not in t1 or set(C7) - set(t1[pts]):
            raise Bad("%s/crater_insert/curves.csv: no row at %d points for "
                      "every criterion" % (study_out, pts))
        ours = {c: t1[pts][c]["mean_abs_error"] for c in C7}
        pub = dict(zip(C7, PUB_INSERT[pts]))
        t1_ours[pts] = ours
        cells = beside(ours, pub)
        w("| %d | %d | %s | %.2f |" % (PUB_INSERT_PCT[pts], pts,
                                       " | ".join(cells),
                                       spearman(ours, pub)))
    w("")
    w("Rank agreement: Spearman's coefficient between our ranking of the "
      "seven criteria and the study's in that row (1: the same order).")
    w("")
    for pts in sorted(PUB_INSERT):
        w("- %d %%: ours %s; the study's %s" % (
            PUB_INSERT_PCT[pts], ranking_text(t1_ours[pts]),
            ranking_text(dict(zip(C7, PUB_INSERT[pts])))))
    w("")

    # --- Table 2 --------------------------------------------------------
    w("## Crater Lake, decimation (the study's Table 2)")
    w("")
    start = dec_meta["decimation"]["start"]
    w("From a %s-point Delaunay TIN (`-start %s`), %s importance, "
      "independent sets; average absolute error after deleting the given "
      "share of the 100,000 points: ours (the study's, our difference)."
      % ("{:,}".format(int(start.split(":")[1])) if ":" in start else start,
         start, dec_meta["decimation"]["importance"].upper()))
    w("")
    t2 = table(dec_rows, "crater", "decimate")
    w("| % deleted | points deleted | " + " | ".join(SHORT[c] for c in C7) +
      " | rank agreement |")
    w("|---|---|" + "---|" * len(C7) + "---|")
    t2_ours = {}
    for dele in sorted(PUB_DECIMATE):
        keep = 100000 - dele * 1000
        if keep not in t2 or set(C7) - set(t2[keep]):
            raise Bad("%s/crater_decimate/curves.csv: no row at %d points "
                      "for every criterion" % (study_out, keep))
        ours = {c: t2[keep][c]["mean_abs_error"] for c in C7}
        pub = dict(zip(C7, PUB_DECIMATE[dele]))
        t2_ours[dele] = ours
        cells = beside(ours, pub)
        w("| %d | %d | %s | %.2f |" % (dele, dele * 1000, " | ".join(cells),
                                       spearman(ours, pub)))
    w("")
    for dele in sorted(PUB_DECIMATE):
        w("- %d %% deleted: ours %s; the study's %s" % (
            dele, ranking_text(t2_ours[dele]),
            ranking_text(dict(zip(C7, PUB_DECIMATE[dele])))))
    w("")

    # --- run times ------------------------------------------------------
    w("## Run times: inserting 100,000 Crater Lake points")
    w("")
    if 100000 not in t1:
        raise Bad("%s/crater_insert/curves.csv: no run at 100,000 points"
                  % study_out)
    secs = {c: t1[100000][c]["seconds"] for c in C7}
    w("Seconds building the mesh (`seconds` of curves.csv: one run, on "
      "this machine shared with other work) against the study's (a 900 MHz "
      "Celeron, 2004), and each as a multiple of Delaunay's.")
    w("")
    w("| criterion | ours, s | × Delaunay | study, s | × Delaunay |")
    w("|---|---|---|---|---|")
    for c, ps in zip(C7, PUB_SECONDS):
        w("| %s | %.3f | %.1f | %d | %.1f |" % (
            SHORT[c], secs[c], secs[c] / secs["delaunay"], ps,
            ps / float(PUB_SECONDS[0])))
    w("")
    g_ratio = secs["gaussian_curvature"] / secs["delaunay"]
    pub_g = PUB_SECONDS[4] / float(PUB_SECONDS[0])
    w("The study's Gaussian curvature took %.0f times Delaunay's time; "
      "ours takes %.1f times (SPEC: \"it need not be\" the slowest by far)."
      % (pub_g, g_ratio))
    w("")

    # --- generated terrains ---------------------------------------------
    w("## Generated terrains: the ranking of the criteria")
    w("")
    w("`-seed 1`; the study's draws were its own, so only the order of the "
      "criteria compares. Insertion as above; decimation from a "
      "zero-error greedy TIN with Drop importance (the study's tables of "
      "these terrains). Criteria from best to worst by average absolute "
      "error at each checkpoint (1, 10, 25, 50 % of the samples), and by "
      "their mean rank over the checkpoints.")
    w("")
    terrains = [gen_meta["terrains"][k]["label"]
                for k in sorted(gen_meta["terrains"], key=int)]
    gen = {}
    left_out = []
    for t in terrains:
        for m in ("insert", "decimate"):
            cps = checkpoints(gen_rows, t, m)
            # Past the points that make the TIN exact, a checkpoint only
            # repeats another: insertion stops at zero error, and a
            # decimation whose zero-error start has fewer points deletes
            # nothing. Such checkpoints share their point counts.
            counts = [tuple(sorted({r["points"] for r in cp.values()}))
                      for cp in cps]
            keep = [k for k, cp in enumerate(cps)
                    if set(C7) <= set(cp) and counts.count(counts[k]) == 1]
            for k in range(len(cps)):
                if k not in keep and (t, m, counts[k]) not in left_out:
                    left_out.append((t, m, counts[k]))
            gen[(t, m)] = [{c: cps[k][c]["mean_abs_error"] for c in C7}
                           for k in keep]
            gen[(t, m, "points")] = [cps[k]["delaunay"]["points"]
                                     for k in keep]
    w("| terrain | method | mean rank (best first) | L2's rank per "
      "checkpoint | Delaunay's | Gaussian's |")
    w("|---|---|---|---|---|---|")
    for t in terrains:
        for m in ("insert", "decimate"):
            rk = [ranks(v) for v in gen[(t, m)]]
            mean_rank = {c: statistics.mean(r[c] for r in rk) for c in C7}
            order = sorted(C7, key=lambda c: (mean_rank[c], c))
            w("| %s | %s | %s | %s | %s | %s |" % (
                t, m, ", ".join("%s %.1f" % (SHORT[c], mean_rank[c])
                                for c in order),
                " ".join(str(r["l2"]) for r in rk),
                " ".join(str(r["delaunay"]) for r in rk),
                " ".join(str(r["gaussian_curvature"]) for r in rk)))
    w("")
    w("The checkpoints' points are in `generated_curves.csv`; the tables "
      "of every value in `generated_tables.md`.%s" % (
          "" if not left_out else
          " Left out: the checkpoints past the points that make the TIN "
          "exact, which repeat one another's point counts (insertion stops "
          "at zero error; a decimation whose zero-error start has fewer "
          "points deletes nothing): "
          + ", ".join("%s %s at %s points" % (t, m, "/".join(map(str, c)))
                      for t, m, c in left_out) + "."))
    w("")

    # --- findings --------------------------------------------------------
    w("## The findings of SPEC section 6")
    w("")
    ins_sets = [("crater", pts, v) for pts, v in sorted(t1_ours.items())]
    for t in terrains:
        for i, v in enumerate(gen[(t, "insert")]):
            ins_sets.append((t, gen[(t, "insert", "points")][i], v))
    dec_sets = [("crater", 100000 - d * 1000, v)
                for d, v in sorted(t2_ours.items())]
    for t in terrains:
        for i, v in enumerate(gen[(t, "decimate")]):
            dec_sets.append((t, gen[(t, "decimate", "points")][i], v))

    def where(lst):
        return ", ".join("%s@%d" % (t, p) for t, p in lst[:8]) + \
            (" …" if len(lst) > 8 else "")

    # F1
    miss = [(t, p) for t, p, v in ins_sets if min(v, key=v.get) != "l2"]
    n = len(ins_sets)
    w("1. *In refinement, L2 is best.* %s: L2 has the smallest average "
      "error in %d of %d insertion rows (Crater Lake and the six generated "
      "terrains)%s." % (verdict(quorum(n - len(miss), n)), n - len(miss), n,
                        "; not in " + where(miss) if miss else ""))
    # F2a/F2b
    nxt = [(t, p) for t, p, v in ins_sets
           if sorted(ranks(v)[c] for c in TWO_D) != [2, 3]]
    close = [(t, p, abs(v["delaunay"] / v["minmax_angle"] - 1))
             for t, p, v in ins_sets]
    far = [(t, p) for t, p, d in close if d > 0.10]
    w("2. *Delaunay and Min-Max angle come next* (ranks 2 and 3). %s: in "
      "%d of %d insertion rows%s." % (
          verdict(quorum(n - len(nxt), n)), n - len(nxt), n,
          "; not in " + where(nxt) if nxt else ""))
    w("3. *… and close together* (within 10 %% of each other). %s: in %d "
      "of %d rows; the median difference is %.1f %%, the largest %.1f %%."
      % (verdict(quorum(n - len(far), n)), n - len(far), n,
         100 * statistics.median(d for _, _, d in close),
         100 * max(d for _, _, d in close)))
    # F3
    pairs = [(t, p, c) for t, p, v in ins_sets for c in WORSE]
    worse = [(t, p, c) for t, p, v in ins_sets for c in WORSE
             if v[c] > max(v[x] for x in TWO_D)]
    per_c = {c: sum(1 for x in worse if x[2] == c) for c in WORSE}
    w("4. *The curvature criteria, ABN and min area are worse* (than both "
      "Delaunay and Min-Max angle). %s: in %d of %d (row, criterion) "
      "pairs; by criterion, worse in %s of %d rows." % (
          verdict(quorum(len(worse), len(pairs))), len(worse), len(pairs),
          ", ".join("%s %d" % (SHORT[c], per_c[c]) for c in WORSE), n))

    # F4: gap by terrain
    def gap(rows_list):
        return statistics.mean(
            statistics.mean(v[c] for c in WORSE) /
            statistics.mean(v[c] for c in TWO_D) - 1 for v in rows_list)
    gaps_ins = {t: gap(gen[(t, "insert")]) for t in terrains}
    gaps_ins["crater"] = gap(list(t1_ours.values()))
    ok = gaps_ins["fault_rough"] > gaps_ins["fault_smooth"]
    w("5. *The gap grows with roughness.* %s on the one controlled pair "
      "(the same fault generator, smooth and rough): the four worse "
      "criteria average %s above Delaunay and Min-Max angle on "
      "fault_smooth, %s on fault_rough. Every terrain: %s." % (
          verdict(ok), pct(gaps_ins["fault_smooth"]),
          pct(gaps_ins["fault_rough"]),
          ", ".join("%s %s" % (t, pct(g)) for t, g in
                    sorted(gaps_ins.items(), key=lambda x: x[1]))))
    # F5: catch up in decimation
    gaps_dec = {t: gap(gen[(t, "decimate")]) for t in terrains}
    gaps_dec["crater"] = gap(list(t2_ours.values()))
    caught = [t for t in gaps_dec if gaps_dec[t] < gaps_ins[t]]
    w("6. *In decimation the data-dependent criteria catch up* (their gap "
      "to the 2-D criteria is smaller than in insertion). %s: on %d of %d "
      "terrains (%s)." % (
          verdict(quorum(len(caught), len(gaps_dec))), len(caught),
          len(gaps_dec), ", ".join("%s %s → %s" % (t, pct(gaps_ins[t]),
                                                  pct(gaps_dec[t]))
                                   for t in sorted(gaps_dec))))
    # F6: L2 best by a wide margin in decimation
    nd = len(dec_sets)
    wide = []
    margins = []
    for t, p, v in dec_sets:
        others = sorted(v[c] for c in C7 if c != "l2")
        margins.append(others[0] / v["l2"] if v["l2"] > 0 else float("inf"))
        if v["l2"] < others[0] and others[0] >= 1.2 * v["l2"]:
            wide.append((t, p))
    best_l2 = sum(1 for t, p, v in dec_sets if min(v, key=v.get) == "l2")
    w("7. *In decimation L2 is best by a wide margin* (the second best at "
      "least 20 %% worse). %s: L2 is best in %d of %d decimation rows, by "
      "20 %% or more in %d; the median margin is ×%.2f." % (
          verdict(quorum(len(wide), nd)), best_l2, nd, len(wide),
          statistics.median(margins)))
    # F7
    sm = [(t, p, ranks(v)["gaussian_curvature"]) for t, p, v in dec_sets
          if t in SMOOTH]
    ro = [(t, p, ranks(v)["gaussian_curvature"]) for t, p, v in dec_sets
          if t in ROUGH]
    w("8. *Gaussian is second on smooth terrain in decimation.* %s: second "
      "in %d of %d rows of %s (its ranks: %s)." % (
          verdict(quorum(sum(r == 2 for _, _, r in sm), len(sm))),
          sum(r == 2 for _, _, r in sm), len(sm), " and ".join(SMOOTH),
          " ".join(str(r) for _, _, r in sm)))
    w("9. *… and worst on rough terrain.* %s: last (7th) in %d of %d rows "
      "of %s (its ranks: %s)." % (
          verdict(quorum(sum(r == 7 for _, _, r in ro), len(ro))),
          sum(r == 7 for _, _, r in ro), len(ro), ", ".join(ROUGH),
          " ".join(str(r) for _, _, r in ro)))
    # F8: cylinder
    cyl = [(m, v) for m in ("insert", "decimate") for v in gen[("cylinder",
                                                                m)]]
    beat = []
    for m, v in cyl:
        b2 = min(v[c] for c in TWO_D)
        beat.append(sum(v[c] < b2 for c in DATA_DEP))
    okc = sum(1 for k in beat if k >= 3)
    w("10. *Data-dependent criteria beat the 2-D ones on cliffs* "
      "(cylinder: at least three of the five data-dependent criteria below "
      "the better of Delaunay and Min-Max angle). %s: in %d of %d rows "
      "(insertion, then decimation, the count of the five that beat it: "
      "%s)." % (verdict(quorum(okc, len(cyl))), okc, len(cyl),
                " ".join(str(k) for k in beat)))
    # F9: slivers from the TINs at 500 points
    tdir = os.path.join(study_out, "crater_insert", "tins")
    sliv = {}
    try:
        with open(os.path.join(tdir, "index.csv"), newline="") as f:
            for e in csv.DictReader(f):
                if e["method"] == "insert":
                    angs = min_angles_pixel(os.path.join(tdir, e["tin"]))
                    sliv[e["criterion"]] = (sum(a < 10 for a in angs) /
                                            float(len(angs)), e["points"])
    except OSError as e:
        raise Bad("%s: %s" % (e.filename, e.strerror))
    if set(C7) - set(sliv):
        raise Bad("%s/index.csv: not every criterion's TIN" % tdir)
    base = sliv["delaunay"][0]
    many = [c for c in ("gaussian_curvature", "abn", "l2")
            if sliv[c][0] >= 2 * base]
    w("11. *Gaussian, ABN and L2 make many slivers* (at least twice "
      "Delaunay's share of triangles whose smallest angle is under 10°, "
      "on Crater Lake's TINs at %s points). %s for %s: the shares are %s."
      % (sliv["delaunay"][1], verdict(len(many) == 3),
         ", ".join(SHORT[c] for c in many) if len(many) in (1, 2)
         else "all three" if len(many) == 3 else "none of them",
         ", ".join("%s %.1f %%" % (SHORT[c], 100 * sliv[c][0]) for c in C7)))
    # F10: annealing
    better, better1, total, ratios = 0, 0, 0, []
    for t in sorted({r["terrain"] for r in ann_rows}):
        loc = table(ann_rows, t, "insert", "local")
        ann = table(ann_rows, t, "insert", "anneal")
        for p in loc:
            for c in C7:
                if c == "delaunay" or c not in loc[p] or c not in ann.get(p,
                                                                        {}):
                    continue
                total += 1
                if ann[p][c]["mean_abs_error"] < \
                        loc[p][c]["mean_abs_error"]:
                    better += 1
                if ann[p][c]["mean_abs_error"] < \
                        0.99 * loc[p][c]["mean_abs_error"]:
                    better1 += 1
                if loc[p][c]["seconds"] > 0:
                    ratios.append(ann[p][c]["seconds"] /
                                  loc[p][c]["seconds"])
    med = statistics.median(ratios) if ratios else float("nan")
    rarely = total > 0 and better <= 0.25 * total
    w("12. *Simulated annealing is rarely better than local swap* (better "
      "in at most a quarter of the rows) *and far slower* (a median of 5 "
      "times or more). %s: annealing gave a smaller average error in %d of "
      "%d rows (fault_smooth and valley_rough, every criterion but "
      "Delaunay, 1 to 50 %%; smaller by 1 %% or more in %d), and took a "
      "median ×%.1f the time." % (
          verdict(rarely and med >= 5), better, total, better1, med))
    w("")

    # --- figures ---------------------------------------------------------
    w("## Figures")
    w("")
    # -points gives a row per point count; the fallback, 50 checkpoints.
    have_points = len({r["points"] for r in cur_rows}) > 60
    w("Crater Lake, insertion up to 500 points (%s; the study's Figures "
      "12-36 show these curves):" % (
          "a row per point count, `-points 500`" if have_points else
          "checkpoints every 10 points: this terratin's study has no "
          "-points yet"))
    w("")
    figs = [("crater_insert_mean_abs_error.png", "average error"),
            ("crater_insert_total_abs_error.png", "total error"),
            ("crater_insert_l2.png", "L2 error"),
            ("crater_insert_max_error.png", "max error"),
            ("crater_decimate_mean_abs_error.png",
             "decimation, average error"),
            ("crater_decimate_total_abs_error.png",
             "decimation, total error"),
            ("crater_decimate_l2.png", "decimation, L2 error")]
    for fn, title in figs[:4]:
        w("![Crater Lake, %s](%s)" % (title, fn))
    w("")
    w("Crater Lake, decimation by independent sets from 100,000 points:")
    w("")
    for fn, title in figs[4:]:
        w("![Crater Lake, %s](%s)" % (title, fn))
    w("")
    w("Crater Lake's TINs at 500 points, one per criterion (the study's "
      "Figures 10-11):")
    w("")
    w("![Crater Lake TINs at 500 points](crater_insert_tin500.png)")
    w("")
    w("The generated terrains, average error against points:")
    w("")
    for t in terrains:
        for m in ("insert", "decimate"):
            w("![%s, %s](%s_%s_mean_abs_error.png)" % (t, m, t, m))
    w("")

    os.makedirs(out_dir, exist_ok=True)
    for n in RUNS:
        src = os.path.join(study_out, n)
        if os.path.exists(os.path.join(src, "tables.md")):
            shutil.copyfile(os.path.join(src, "tables.md"),
                            os.path.join(out_dir, n + "_tables.md"))
        shutil.copyfile(os.path.join(src, "runs.json"),
                        os.path.join(out_dir, n + "_runs.json"))
        if n != "crater_curves":
            shutil.copyfile(os.path.join(src, "curves.csv"),
                            os.path.join(out_dir, n + "_curves.csv"))
    final = os.path.join(out_dir, "README.md")
    tmp = final + ".tmp%d" % os.getpid()
    with open(tmp, "w") as f:
        f.write("\n".join(L) + "\n")
    os.replace(tmp, final)
    print("study_report.py: %s" % final)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
