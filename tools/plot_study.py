#!/usr/bin/python3
"""plot_study.py -- the pictures of a `terratin study` run (issue 15).

From STUDYDIR/curves.csv it draws one PNG per terrain, method and measure:
the error (log scale) against the TIN's points, one line per criterion and
optimiser, like the 2004 study's Figures 12-36. The rows may be few (the
-percent checkpoints, drawn with markers) or one per point count (-points,
drawn as lines); a row that repeats a point count already drawn for the
same line is skipped.

When the study was run with -tin_points N, STUDYDIR/tins/ holds each
criterion's TIN at N points (OBJ in pixel space: x = column, y = row) and
each terrain's grid (ESRI ASCII grid); index.csv lists them. Then it also
draws, per terrain and method, one PNG with a panel per criterion and
optimiser: the triangles over a hillshade of the terrain, like the study's
Figures 10-11.

Usage: plot_study.py [--out DIR] [--measures LIST] [--dpi N] STUDYDIR
       plot_study.py --check      (exits 0 when matplotlib can be used)

Writes into DIR (default STUDYDIR/plots), each PNG under a temporary name
renamed when complete. Exit codes: 0 success, 1 bad input (one line on
stderr naming the file), 2 usage error.
"""
import argparse
import csv
import math
import os
import re
import sys

MEASURES = {
    "max_error": "L\u221e error (max |H - H'|)",
    "l2": "L2 error (sqrt of the sum of squares)",
    "rmse": "RMS error",
    "mean_abs_error": "average absolute error",
    "total_abs_error": "total absolute error",
    "seconds": "seconds (building the mesh)",
}
COLUMNS = ["terrain", "method", "criterion", "optimizer", "points",
           "max_error", "l2", "rmse", "mean_abs_error", "total_abs_error",
           "seconds"]
# The study's order of the criteria, then the others as they come.
ORDER = ["delaunay", "minmax_angle", "minmax_angle_lex", "min_area",
         "mean_curvature", "gaussian_curvature", "abn", "abn_sum",
         "abn_sumsq", "l2"]


class Bad(Exception):
    """Bad input: the message names the file."""


def import_pyplot():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt


def safe(name):
    return re.sub(r"[^A-Za-z0-9._-]+", "_", name).strip("_") or "x"


def crit_key(c):
    return (ORDER.index(c) if c in ORDER else len(ORDER), c)


def read_curves(path):
    try:
        f = open(path, newline="")
    except OSError as e:
        raise Bad("%s: %s" % (path, e.strerror))
    with f:
        rows = list(csv.reader(f))
    if not rows or rows[0] != COLUMNS:
        raise Bad("%s: not a curves.csv of terratin study (the header is "
                  "not %s)" % (path, ",".join(COLUMNS)))
    out = []
    for n, r in enumerate(rows[1:], start=2):
        if len(r) != len(COLUMNS):
            raise Bad("%s: line %d has %d fields, expected %d"
                      % (path, n, len(r), len(COLUMNS)))
        d = dict(zip(COLUMNS, r))
        try:
            d["points"] = int(d["points"])
            for m in MEASURES:
                d[m] = float(d[m])
        except ValueError:
            raise Bad("%s: line %d: a number does not parse" % (path, n))
        out.append(d)
    if not out:
        raise Bad("%s: no rows" % path)
    return out


def save(fig, out_dir, name, dpi):
    """Writes fig as a PNG of at most 256 colours (a quarter of the bytes
    of a true-colour one for the hillshades), under a temporary name."""
    import io
    final = os.path.join(out_dir, name)
    tmp = os.path.join(out_dir, ".%s.tmp%d" % (name, os.getpid()))
    try:
        buf = io.BytesIO()
        fig.savefig(buf, dpi=dpi, format="png")
        try:
            from PIL import Image
            buf.seek(0)
            img = Image.open(buf).convert("RGB").quantize(colors=64)
            img.save(tmp, format="PNG", optimize=True)
        except ImportError:
            with open(tmp, "wb") as f:
                f.write(buf.getvalue())
        os.replace(tmp, final)
    except OSError as e:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise Bad("%s: %s" % (final, e.strerror))
    return final


def plot_curves(plt, rows, out_dir, measures, dpi):
    """One PNG per terrain, method and measure."""
    written = []
    groups = {}
    for r in rows:
        groups.setdefault((r["terrain"], r["method"]), []).append(r)
    for (terrain, method), grp in groups.items():
        lines = {}
        for r in grp:
            lines.setdefault((r["criterion"], r["optimizer"]), {}) \
                 .setdefault(r["points"], r)
        keys = sorted(lines, key=lambda k: (crit_key(k[0]), k[1]))
        for m in measures:
            fig, ax = plt.subplots(figsize=(6.4, 4.4))
            drawn = 0
            for k in keys:
                pts = sorted(lines[k])
                ys = [lines[k][p][m] for p in pts]
                if not any(y > 0 and math.isfinite(y) for y in ys):
                    continue
                style = "-o" if len(pts) <= 40 else "-"
                ax.plot(pts, ys, style, markersize=3, linewidth=1.2,
                        label="%s / %s / %s" % (k[0], k[1], method))
                drawn += 1
            if not drawn:
                plt.close(fig)
                continue
            ax.set_yscale("log", nonpositive="mask")
            ax.set_xlabel("points of the TIN")
            ax.set_ylabel(MEASURES[m])
            ax.set_title("%s, %s: %s" % (terrain, method, MEASURES[m]),
                         fontsize=10)
            ax.grid(True, which="both", linewidth=0.3, alpha=0.6)
            ax.legend(fontsize=7, title="criterion / optimizer / method",
                      title_fontsize=7)
            fig.tight_layout()
            written.append(save(fig, out_dir, "%s_%s_%s.png"
                                % (safe(terrain), method, m), dpi))
            plt.close(fig)
    return written


def read_asc(path):
    """An ESRI ASCII grid as rows of floats (NaN for nodata)."""
    import numpy as np
    try:
        with open(path) as f:
            head = {}
            for _ in range(6):
                k, v = f.readline().split()
                head[k.lower()] = float(v)
            z = np.loadtxt(f, dtype=float, ndmin=2)
    except (OSError, ValueError) as e:
        raise Bad("%s: not an ESRI ASCII grid (%s)" % (path, e))
    if z.shape != (int(head["nrows"]), int(head["ncols"])):
        raise Bad("%s: %dx%d values, the header says %dx%d"
                  % (path, z.shape[1], z.shape[0], head["ncols"],
                     head["nrows"]))
    if "nodata_value" in head:
        z[z == head["nodata_value"]] = np.nan
    return z


def hillshade(z):
    """Grey hillshade, light from the north-west 45 degrees up."""
    import numpy as np
    zz = np.where(np.isnan(z), np.nanmean(z), z)
    gy, gx = np.gradient(zz)
    # Heights and cells come in unrelated units: scale the relief so that
    # the steepest tenth of the terrain leans at 45 degrees or more.
    g = np.hypot(gx, gy)
    p90 = float(np.percentile(g, 90)) if g.size else 0.0
    if p90 > 0:
        gx, gy = gx / p90, gy / p90
    slope = np.arctan(np.hypot(gx, gy))
    aspect = np.arctan2(-gx, gy)
    az, alt = math.radians(315.0), math.radians(45.0)
    hs = (math.sin(alt) * np.cos(slope) +
          math.cos(alt) * np.sin(slope) * np.cos(az - aspect))
    # Pale, so that the triangles stand out.
    return np.ma.masked_where(np.isnan(z), 0.45 + 0.55 * np.clip(hs, 0, 1))


def read_obj(path):
    verts, tris = [], []
    try:
        with open(path) as f:
            for line in f:
                w = line.split()
                if not w or w[0] == "#":
                    continue
                if w[0] == "v":
                    verts.append((float(w[1]), float(w[2]), float(w[3])))
                elif w[0] == "f":
                    tris.append([int(x.split("/")[0]) - 1 for x in w[1:4]])
    except (OSError, ValueError, IndexError) as e:
        raise Bad("%s: not a TIN of terratin study (%s)" % (path, e))
    for t in tris:
        if min(t) < 0 or max(t) >= len(verts):
            raise Bad("%s: a face names a vertex that is not there" % path)
    return verts, tris


def plot_tins(plt, study_dir, out_dir, dpi):
    """Per terrain and method: a panel per criterion and optimiser."""
    index = os.path.join(study_dir, "tins", "index.csv")
    if not os.path.exists(index):
        return []
    with open(index, newline="") as f:
        entries = list(csv.DictReader(f))
    want = {"terrain", "method", "criterion", "optimizer", "points", "tin",
            "grid"}
    if entries and not want <= set(entries[0]):
        raise Bad("%s: the columns are not %s" % (index, sorted(want)))
    groups = {}
    for e in entries:
        groups.setdefault((e["terrain"], e["method"], e["grid"]),
                          []).append(e)
    written = []
    for (terrain, method, grid), grp in groups.items():
        z = read_asc(os.path.join(study_dir, "tins", grid))
        hs = hillshade(z)
        grp.sort(key=lambda e: (crit_key(e["criterion"]), e["optimizer"]))
        n = len(grp)
        cols = min(n, 4)
        nrows = (n + cols - 1) // cols
        aspect = z.shape[0] / float(z.shape[1])
        w = 2.4 * cols
        fig, axes = plt.subplots(nrows, cols, squeeze=False,
                                 figsize=(w, 2.4 * aspect * nrows + 0.5))
        for ax in axes.flat:
            ax.set_axis_off()
        for ax, e in zip(axes.flat, grp):
            verts, tris = read_obj(os.path.join(study_dir, "tins", e["tin"]))
            ax.imshow(hs, cmap="gray", vmin=0, vmax=1,
                      interpolation="bilinear",
                      extent=(-0.5, z.shape[1] - 0.5, z.shape[0] - 0.5, -0.5))
            if tris:
                ax.triplot([v[0] for v in verts], [v[1] for v in verts],
                           tris, color="#d62728", linewidth=0.25)
            ax.set_xlim(-0.5, z.shape[1] - 0.5)
            ax.set_ylim(z.shape[0] - 0.5, -0.5)
            ax.set_title("%s / %s" % (e["criterion"], e["optimizer"]),
                         fontsize=7)
        fig.suptitle("%s, %s: the TIN at %s points over a hillshade"
                     % (terrain, method, grp[0]["points"]), fontsize=8)
        fig.tight_layout()
        written.append(save(fig, out_dir, "%s_%s_tin%s.png"
                            % (safe(terrain), method, grp[0]["points"]),
                            dpi))
        plt.close(fig)
    return written


def main(argv):
    ap = argparse.ArgumentParser(
        prog="plot_study.py",
        description="Draw the curves and TINs of a terratin study run.")
    ap.add_argument("study_dir", nargs="?", metavar="STUDYDIR")
    ap.add_argument("--out", metavar="DIR",
                    help="where the PNGs go (default STUDYDIR/plots)")
    ap.add_argument("--measures", default=",".join(list(MEASURES)[:5]),
                    help="comma-separated, of %s (default: the five "
                    "errors)" % ", ".join(MEASURES))
    ap.add_argument("--dpi", type=int, default=80)
    ap.add_argument("--no-tins", action="store_true",
                    help="skip the TIN pictures")
    ap.add_argument("--check", action="store_true",
                    help="exit 0 when matplotlib can be imported")
    a = ap.parse_args(argv)
    try:
        plt = import_pyplot()
    except ImportError:
        sys.stderr.write("plot_study.py: matplotlib is missing (Debian: "
                         "apt-get install python3-matplotlib)\n")
        return 1
    if a.check:
        return 0
    if not a.study_dir:
        ap.error("STUDYDIR is required")
    measures = [m for m in a.measures.split(",") if m]
    for m in measures:
        if m not in MEASURES:
            ap.error("unknown measure '%s'; known: %s"
                     % (m, ", ".join(MEASURES)))
    if not 20 <= a.dpi <= 600:
        ap.error("--dpi must be in 20..600")
    out_dir = a.out or os.path.join(a.study_dir, "plots")
    try:
        rows = read_curves(os.path.join(a.study_dir, "curves.csv"))
        try:
            os.makedirs(out_dir, exist_ok=True)
        except OSError as e:
            raise Bad("%s: %s" % (out_dir, e.strerror))
        n = len(plot_curves(plt, rows, out_dir, measures, a.dpi))
        if not a.no_tins:
            n += len(plot_tins(plt, a.study_dir, out_dir, a.dpi))
    except Bad as e:
        sys.stderr.write("plot_study.py: %s\n" % e)
        return 1
    print("plot_study.py: %d PNG%s in %s" % (n, "" if n == 1 else "s",
                                            out_dir))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
