#!/usr/bin/env python3
"""bench/doc_tables.py -- every figure table in docs/ is the output of a script.

A table of figures in docs/*.md (and docs/*/*.md) sits between two markers:

    <!-- table: bench/decimate.py table2 | tier: long | compare: all -->
    | ... the table the command printed ... |
    <!-- /table -->

  table:    the command that prints the table (markdown, on stdout), run from
            the repository's root; {terratin} stands for the binary and
            {build} for its build folder (for test programs).
  tier:     check   cheap (seconds): `make check` reruns it (Release build)
            long    minutes: `make check-long` reruns it
            bench   a full-size or timed measurement: rerun only by hand
  compare:  all     every cell must come back the same
            figures the cells without their parenthesised parts and
                    their "/ N s" parts (the seconds beside a figure)
            cols=N,M  only those columns (0-based): the others are timings
            none    timings only: never compared, rewritten by --update

A command may need the shared DEMs (../shared/testdata, or
$TT_SHARED_TESTDATA); when they are absent it exits 77 and the table is
skipped with its message.

Usage:
  bench/doc_tables.py --list
  bench/doc_tables.py --check [--tier check|long|bench] [TERRATIN]
  bench/doc_tables.py --update [--tier ...] [--file docs/x.md] [TERRATIN]

--check reruns the tables of the tier (and the cheaper tiers) and prints
every cell that drifted, "docs/x.md:LINE: row R column C: docs A, now B";
exit 1 when one did, 0 when none did (77 when every table was skipped).
--update rewrites the tables in place (only those of the tier and cheaper).
A table of figures that no command reruns -- a timed measurement of a
past day, a before/after comparison of two commits -- is a record and says
so, with what measured it and when, in the line before it:

    <!-- record: bench/scale.sh 8193 1024 | 2026-12-02 -->

docs/study/ is written whole by `make study` and exempt.
A table counts as figures when at least a third of its cells right of the
first start with a number. --check fails on a table of figures that is
neither generated nor a record (docs/ cannot grow hand-typed figures), and
on a record whose script (its first word, when it names a file of the
repository) does not exist. --list names every table and what it is.
"""
import argparse
import glob
import os
import re
import shlex
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
TIERS = ["check", "long", "bench"]
OPEN = re.compile(r"^<!-- table: (.*?) -->\s*$")
CLOSE = "<!-- /table -->"
SKIP = 77


class Block:
    def __init__(self, path, line, spec, body_start, body_end):
        self.path, self.line = path, line
        self.body_start, self.body_end = body_start, body_end
        fields = [f.strip() for f in spec.split("|")]
        self.command = fields[0]
        self.tier, self.compare = "bench", "all"
        for f in fields[1:]:
            key, _, value = f.partition(":")
            key, value = key.strip(), value.strip()
            if key == "tier" and value in TIERS:
                self.tier = value
            elif key == "compare":
                self.compare = value
            else:
                raise SystemExit("%s:%d: bad table marker field '%s'"
                                 % (self.rel(), line, f))

    def rel(self):
        return os.path.relpath(self.path, ROOT)


def blocks_of(path):
    with open(path) as f:
        lines = f.read().split("\n")
    found, i = [], 0
    while i < len(lines):
        m = OPEN.match(lines[i])
        if m:
            j = i + 1
            while j < len(lines) and lines[j].strip() != CLOSE:
                j += 1
            if j == len(lines):
                raise SystemExit("%s:%d: table marker without %s"
                                 % (os.path.relpath(path, ROOT), i + 1, CLOSE))
            found.append(Block(path, i + 1, m.group(1), i + 1, j))
            i = j
        i += 1
    return lines, found


def docs():
    return sorted(glob.glob(os.path.join(ROOT, "docs", "*.md")) +
                  glob.glob(os.path.join(ROOT, "docs", "*", "*.md")))


def run(block, terratin):
    build = os.path.dirname(terratin)
    argv = [a.replace("{terratin}", terratin).replace("{build}", build)
            for a in shlex.split(block.command)]
    p = subprocess.run(argv, cwd=ROOT, capture_output=True, text=True)
    if p.returncode == SKIP:
        return None, p.stderr.strip().splitlines()[-1:] or ["skipped"]
    if p.returncode != 0:
        raise SystemExit("%s:%d: %s failed (exit %d): %s"
                         % (block.rel(), block.line, block.command,
                            p.returncode, p.stderr.strip()[-400:]))
    return p.stdout.rstrip("\n").split("\n"), None


def cells(row):
    return [c.strip() for c in row.strip().strip("|").split("|")]


def comparable(block, row):
    c = cells(row)
    if block.compare == "figures":
        return [re.sub(r"\s*/\s*[0-9.]+ s\b", "",
                       re.sub(r"\s*\([0-9.]+\)", "", x)) for x in c]
    if block.compare.startswith("cols="):
        keep = [int(k) for k in block.compare[5:].split(",")]
        return [c[k] if k < len(c) else "" for k in keep]
    return c


def drift(block, old, new):
    """The differences between the doc's rows and the rerun's, as lines."""
    if block.compare == "none":
        return []
    out = []
    if len(old) != len(new):
        out.append("%s:%d: %d rows in the docs, %d now"
                   % (block.rel(), block.line, len(old), len(new)))
    for r, (a, b) in enumerate(zip(old, new)):
        ca, cb = comparable(block, a), comparable(block, b)
        if ca == cb:
            continue
        for k in range(max(len(ca), len(cb))):
            x = ca[k] if k < len(ca) else ""
            y = cb[k] if k < len(cb) else ""
            if x != y:
                out.append("%s:%d: row %d column %d: docs %s, now %s"
                           % (block.rel(), block.line + 1 + r, r, k, x, y))
    return out


def selected(args):
    limit = TIERS.index(args.tier)
    paths = [os.path.join(ROOT, args.file)] if args.file else docs()
    for path in paths:
        lines, found = blocks_of(path)
        for b in found:
            if TIERS.index(b.tier) <= limit:
                yield lines, b


def check(args):
    drifted, ran, skipped = [], 0, 0
    for lines, b in selected(args):
        new, why = run(b, args.terratin)
        if new is None:
            print("SKIP: %s:%d (%s): %s" % (b.rel(), b.line, b.command,
                                            why[0]))
            skipped += 1
            continue
        ran += 1
        d = drift(b, lines[b.body_start:b.body_end], new)
        print("%s %s:%d %s" % ("DRIFT" if d else "ok   ", b.rel(), b.line,
                               b.command), flush=True)
        drifted += d
    loose = loose_problems()
    for line in drifted + loose:
        print(line)
    print("doc_tables: %d tables rerun, %d skipped, %d cells drifted"
          % (ran, skipped, len(drifted)))
    if loose:
        print("doc_tables: %d tables of figures neither generated nor "
              "recorded" % len(loose))
    if drifted or loose:
        print("doc_tables: rerun bench/doc_tables.py --update and read the "
              "prose around each table again")
        return 1
    return SKIP if ran == 0 and skipped else 0


def update(args):
    by_path = {}
    for lines, b in selected(args):
        new, why = run(b, args.terratin)
        if new is None:
            print("SKIP: %s:%d: %s" % (b.rel(), b.line, why[0]))
            continue
        by_path.setdefault(b.path, (lines, []))[1].append((b, new))
        print("updated %s:%d %s" % (b.rel(), b.line, b.command), flush=True)
    for path, (lines, done) in by_path.items():
        for b, new in sorted(done, key=lambda x: -x[0].line):
            lines[b.body_start:b.body_end] = new
        tmp = path + ".tmp"
        with open(tmp, "w") as f:
            f.write("\n".join(lines))
        os.replace(tmp, path)
    return 0


RECORD = re.compile(r"^<!-- record: (.*?) -->\s*$")
NUMBER = re.compile(r"^[*~<>≈−+-]*\d")


def loose_tables(lines, found):
    """The tables outside every marker: (header line number, kind, text),
    kind "record" (with its marker's text), "figures" or "prose"."""
    inside = set()
    for b in found:
        inside.update(range(b.body_start, b.body_end))
    out = []
    for i, line in enumerate(lines):
        if not line.startswith("|---") or i in inside or i == 0:
            continue
        head = i - 1
        m = RECORD.match(lines[head - 1]) if head > 0 else None
        if m:
            out.append((head + 1, "record", m.group(1)))
            continue
        body, j = [], i + 1
        while j < len(lines) and lines[j].startswith("|"):
            body += cells(lines[j])[1:]
            j += 1
        numeric = sum(1 for c in body if NUMBER.match(c))
        kind = "figures" if body and 3 * numeric >= len(body) else "prose"
        out.append((head + 1, kind, lines[head][:60]))
    return out


def study_made(path):
    """docs/study/ is written whole by `make study` (tools/study.sh)."""
    return os.path.relpath(path, ROOT).startswith(os.path.join("docs", "study") + os.sep)


def loose_problems():
    """Figure tables neither generated nor recorded, records whose script
    is gone."""
    bad = []
    for path in docs():
        if study_made(path):
            continue
        lines, found = blocks_of(path)
        rel = os.path.relpath(path, ROOT)
        for n, kind, text in loose_tables(lines, found):
            if kind == "figures":
                bad.append("%s:%d: a table of figures that no command "
                           "reruns and no record marker dates: %s"
                           % (rel, n, text))
            elif kind == "record":
                first = text.split()[0] if text.split() else ""
                if "/" in first and not os.path.exists(os.path.join(ROOT, first)):
                    bad.append("%s:%d: the record names %s, which does not "
                               "exist" % (rel, n, first))
    return bad


def listing(args):
    for path in docs():
        lines, found = blocks_of(path)
        for b in found:
            print("%-6s %-10s %s:%d  %s" % (b.tier, b.compare, b.rel(),
                                            b.line, b.command))
        for n, kind, text in loose_tables(lines, found):
            if study_made(path):
                kind = "study"
            print("%-6s %-10s %s:%d  %s" % (kind, "-", os.path.relpath(path, ROOT),
                                            n, text))
    return 0


def main(argv):
    ap = argparse.ArgumentParser(prog="doc_tables.py")
    g = ap.add_mutually_exclusive_group(required=True)
    g.add_argument("--list", action="store_true")
    g.add_argument("--check", action="store_true")
    g.add_argument("--update", action="store_true")
    ap.add_argument("--tier", choices=TIERS, default="check")
    ap.add_argument("--file")
    ap.add_argument("terratin", nargs="?",
                    default=os.path.join(ROOT, "build", "terratin"))
    a = ap.parse_args(argv)
    a.terratin = os.path.abspath(a.terratin)
    if a.list:
        return listing(a)
    return check(a) if a.check else update(a)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
