"""skip_lines.py TESTS_DIR -- every way a test can skip says why in one line.

ctest reports exit code 77 as skipped (SKIP_RETURN_CODE), and `make check`
lists each skipped test with its reason (tests/skipped.py), the line the test
printed that starts with "SKIP: ". This checks the sources under TESTS_DIR:
every `exit 77` of a shell test, `sys.exit(77)` of a Python one and
`exit(77)` / `return 77` of a C one follows, within the few lines before it
(or on its own line), an echo, print or printf of a line starting with
"SKIP: "; C tests may use TT_SKIP(), which prints it. Prints each offending
place and exits 1, or prints how many skip paths it checked.
"""
import os
import re
import sys

EXIT = {
    ".sh": re.compile(r"\bexit\s+77\b"),
    ".py": re.compile(r"\bsys\.exit\(\s*77\s*\)"),
    ".c": re.compile(r"\b(exit\s*\(\s*77\s*\)|return\s+77\s*;)"),
    ".h": re.compile(r"\b(exit\s*\(\s*77\s*\)|return\s+77\s*;)"),
}
SAY = {
    ".sh": re.compile(r"""\b(echo|printf)\s+(-[a-z]+\s+)?["']SKIP: """),
    ".py": re.compile(r"""\bprint\(\s*["']SKIP: """),
    ".c": re.compile(r"""\b(printf|puts|fprintf\s*\([^,]*,)\s*\(?\s*"SKIP: """),
    ".h": re.compile(r"""\b(printf|puts|fprintf\s*\([^,]*,)\s*\(?\s*"SKIP: """),
}
WINDOW = 4  # lines before the exit that may hold the message


def comment(ext, line):
    s = line.strip()
    return s.startswith("#") if ext in (".sh", ".py") else \
        s.startswith(("*", "/*", "//"))


def main(root):
    bad, seen = [], 0
    for d, _, files in os.walk(root):
        if os.sep + "corpus" in d:
            continue
        for f in sorted(files):
            ext = os.path.splitext(f)[1]
            if ext not in EXIT or f == os.path.basename(__file__):
                continue
            path = os.path.join(d, f)
            lines = open(path, errors="replace").read().splitlines()
            for i, line in enumerate(lines):
                if comment(ext, line) or not EXIT[ext].search(line):
                    continue
                seen += 1
                before = lines[max(0, i - WINDOW):i + 1]
                if not any(SAY[ext].search(b) for b in before):
                    bad.append("%s:%d: exits 77 without a 'SKIP: ' line "
                               "before it: %s" % (os.path.relpath(path, root),
                                                   i + 1, line.strip()))
    for b in bad:
        print(b)
    if bad:
        return 1
    print("%d skip paths, each says why in a 'SKIP: ' line" % seen)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1]))
