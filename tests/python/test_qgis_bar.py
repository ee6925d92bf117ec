"""test_qgis_bar.py -- the QGIS plugin's reading of terratin's progress bar
(qgis/terratin/runner.py, BarParser) without QGIS: the qgis and processing
modules it imports are stood in for, the parser is fed the bar as
apps/core/progress.c draws it (41 ticks, "0...10...20...", " - done."),
whole, character by character and in odd chunks, broken by a warning and
resumed, then the summary lines. Checks the percentages rise by 2.5 to
100 (each of the 41 ticks when the bar comes a character at a time) and
every summary line comes out whole, the bar never as a line."""
import os
import random
import sys
import types

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, os.pardir, os.pardir, "qgis",
                                "terratin"))
for name in ("qgis", "qgis.core", "processing", "processing.core",
             "processing.core.ProcessingConfig"):
    sys.modules[name] = types.ModuleType(name)
sys.modules["qgis.core"].QgsProcessingException = Exception
sys.modules["processing.core.ProcessingConfig"].ProcessingConfig = None
import runner  # noqa: E402

failed = 0


def bar(start, end):
    """The characters progress.c prints for ticks start..end."""
    out = ""
    for t in range(start, end + 1):
        out += str(t // 4 * 10) if t % 4 == 0 else "."
    if end == 40:
        out += " - done.\n"
    return out


def parse(chunks):
    percents, lines = [], []
    p = runner.BarParser(percents.append, lines.append)
    for c in chunks:
        p.feed(c)
    p.close()
    return percents, lines


def check(what, ok):
    global failed
    if not ok:
        failed += 1
        print("FAIL:", what)


SUMMARY = ["input:  dem.tif, band 1: 403 x 344 samples, all valid",
           "output: t.gpkg (layers triangles, vertices, run_parameters): "
           "12213 vertices (8.8% of the valid samples), 24159 triangles",
           "error:  max 20 m, within the bound 20 m; RMS 7.112 m"]
whole = bar(0, 40) + "\n".join(SUMMARY) + "\n"
broken = bar(0, 13) + "\n" + bar(14, 40) + "\n".join(SUMMARY) + "\n"
rng = random.Random(1)
for name, text in (("whole", whole), ("broken by a warning", broken)):
    cuts = sorted(rng.sample(range(1, len(text)), 25))
    odd = [text[a:b] for a, b in zip([0] + cuts, cuts + [len(text)])]
    for how, chunks in (("at once", [text]), ("by character", list(text)),
                        ("in odd chunks", odd)):
        percents, lines = parse(chunks)
        what = "%s, %s" % (name, how)
        check("%s: the summary lines (%s)" % (what, lines), lines == SUMMARY)
        check("%s: rises to 100 (%s)" % (what, percents[-3:]),
              percents and percents[-1] == 100 and
              percents == sorted(set(percents)))
        check("%s: in steps of 2.5 (%d values)" % (what, len(percents)),
              all(round(v / 2.5) * 2.5 == v for v in percents) and
              (how != "by character" or len(percents) == 41))
# no bar (-q, a failed run): lines only, no progress
percents, lines = parse(["terratin simplify: dem.tif: refused\n"])
check("no bar: no progress (%s)" % percents, percents == [])
check("no bar: the line", lines == ["terratin simplify: dem.tif: refused"])
# a half-drawn bar (the run stopped): no 100
percents, lines = parse([bar(0, 9)])
check("stopped at 22.5 %% (%s)" % percents[-1:], percents[-1:] == [22.5]
      and lines == [])
print("%s" % ("FAILED" if failed else "passed"))
sys.exit(1 if failed else 0)
