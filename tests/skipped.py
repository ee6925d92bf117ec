"""skipped.py BUILD_DIR... -- the tests a ctest run skipped, and why.

Reads BUILD_DIR/Testing/ctest-junit.xml, which `make test`, `make test-san`
and `make check` have ctest write (--output-junit), and prints per build
the count of skipped tests and one line for each, its reason: the line the
test printed that starts with "SKIP: " (tests/skip_lines.py checks that
every skip path prints one). Also the slowest tests of the run, to keep an
eye on the suite's budget (STYLE.md, Tests). Last, the builds' counts
together in one line, "check: N passed, M failed, K skipped". Never fails
the run: a build without the file is said to have none.
"""
import os
import sys
import xml.etree.ElementTree as ET

SLOWEST = 5


def reason(out):
    lines = [l.strip() for l in (out or "").splitlines() if l.strip()]
    said = [l for l in lines if l.startswith("SKIP:")]
    if said:
        return said[-1][len("SKIP:"):].strip()
    return "(said no 'SKIP: ' line; its last: %s)" % (lines[-1] if lines else "nothing")


def main(builds):
    total = {"passed": 0, "failed": 0, "skipped": 0}
    for build in builds:
        path = os.path.join(build, "Testing", "ctest-junit.xml")
        name = os.path.basename(os.path.abspath(build))
        if not os.path.exists(path):
            print("%s: no ctest results (%s)" % (name, path))
            continue
        cases = ET.parse(path).getroot().iter("testcase")
        skipped, times = [], []
        for c in cases:
            times.append((float(c.get("time", 0)), c.get("name")))
            if c.find("skipped") is not None and c.get("status") == "notrun":
                skipped.append((c.get("name"), reason(c.findtext("system-out"))))
                total["skipped"] += 1
            elif c.find("failure") is not None or c.get("status") == "fail":
                total["failed"] += 1
            else:
                total["passed"] += 1
        print("%s: %d of %d tests skipped" % (name, len(skipped), len(times)))
        for n, why in sorted(skipped):
            print("  skipped: %s: %s" % (n, why))
        slow = sorted(times, reverse=True)[:SLOWEST]
        print("  slowest: " + ", ".join("%s %.1f s" % (n, t) for t, n in slow))
    # the builds together, in the plain closing line CI reads
    print("check: %(passed)d passed, %(failed)d failed, %(skipped)d skipped" % total)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
