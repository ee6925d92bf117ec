"""Running the terratin command for an algorithm: finding it (the
provider's setting, else PATH), checking its version, and running it with
its progress bar mapped onto a QgsProcessingFeedback.

The bar is the one terratin prints on stdout ("0...10...20...", 41 ticks
of 2.5 %, " - done." at the end; apps/core/progress.c); the lines after it
are the summary, shown as information. stderr carries warnings and errors
("terratin simplify: dem.tif: ..."), shown as they are. Cancel sends
SIGTERM: terratin removes its temporary files and leaves nothing (exit
143). POSIX only (select on the pipes)."""
import codecs
import json
import os
import re
import select
import shutil
import signal
import subprocess
import time

from qgis.core import QgsProcessingException
from processing.core.ProcessingConfig import ProcessingConfig

SETTING_PATH = "TERRATIN_PATH"
MIN_VERSION = (0, 1, 0)

_versions = {}


def executable():
    """The terratin to run: the provider's setting, else the one on PATH;
    None when there is none."""
    path = ProcessingConfig.getSetting(SETTING_PATH) or ""
    path = path.strip()
    if path:
        return path
    return shutil.which("terratin")


def version_of(path):
    """(version tuple, the --version line) of the binary at path, cached
    by path and modification time; raises QgsProcessingException when it
    does not run or does not say it is terratin."""
    try:
        key = (path, os.stat(path).st_mtime)
    except OSError as e:
        raise QgsProcessingException("terratin: %s: %s" % (path, e.strerror))
    if key in _versions:
        return _versions[key]
    try:
        out = subprocess.run([path, "--version"], stdout=subprocess.PIPE,
                             stderr=subprocess.STDOUT, timeout=30)
    except (OSError, subprocess.SubprocessError) as e:
        raise QgsProcessingException("terratin: %s: %s" % (path, e))
    line = out.stdout.decode("utf-8", "replace").strip().splitlines()
    line = line[0] if line else ""
    m = re.match(r"terratin (\d+)\.(\d+)\.(\d+)", line)
    if out.returncode != 0 or not m:
        raise QgsProcessingException(
            "terratin: %s: not terratin ('--version' said '%s')" %
            (path, line))
    _versions[key] = (tuple(int(g) for g in m.groups()), line)
    return _versions[key]


def checked_executable():
    """The terratin to run, its version checked, or an exception saying
    where to set it."""
    path = executable()
    if not path:
        raise QgsProcessingException(
            "terratin: not found on PATH; set its path in Settings > "
            "Options > Processing > Providers > terratin")
    version, line = version_of(path)
    if version < MIN_VERSION:
        raise QgsProcessingException(
            "terratin: %s is %s; this plugin needs %d.%d.%d or later" %
            ((path, line) + MIN_VERSION))
    return path


_usages = {}


def usage_of(command):
    """The usage lines of `terratin COMMAND --help` (to follow the
    arguments' order of the binary that runs), cached as the version."""
    path = checked_executable()
    key = (path, os.stat(path).st_mtime, command)
    if key not in _usages:
        out = subprocess.run([path, command, "--help"],
                             stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                             timeout=30)
        text = out.stdout.decode("utf-8", "replace")
        _usages[key] = text.split("\n\n")[0]
    return _usages[key]


def installed_version():
    """The --version line of the terratin that would run, or None."""
    try:
        return checked_executable() and version_of(executable())[1]
    except QgsProcessingException:
        return None


class BarParser:
    """Reads terratin's stdout as it comes: the ticks of the bar become a
    percentage, every other line a message. A bar broken by a warning
    resumes on a line of its own ("...30..."), its tens absolute."""

    BAR = re.compile(r"^[0-9.]+(?: - done\.?)?$|^[0-9.]+ [- donea.]*$")

    def __init__(self, on_percent, on_line):
        self.on_percent = on_percent
        self.on_line = on_line
        self.line = ""
        self.ticks = -1       # ticks shown
        self.line_base = -1   # ticks before this line of the bar

    def _bar_ticks(self, line, complete):
        head = line.split(" ")[0]
        tokens = re.findall(r"\d+|\.", head)
        ticks = self.line_base
        for i, tok in enumerate(tokens):
            if tok == ".":
                ticks += 1
                continue
            value = int(tok) // 10 * 4
            last = i == len(tokens) - 1 and not complete and head == line
            # a number still being printed counts once it is the next
            # tick's ("1" may be the start of "10", "10" of "100")
            if last and not (int(tok) % 10 == 0 and value == ticks + 1):
                break
            ticks = value
        return ticks

    def _show(self, ticks):
        if ticks > self.ticks:
            self.ticks = ticks
            self.on_percent(min(100.0, max(0, ticks) * 2.5))

    def feed(self, text):
        for c in text:
            if c == "\n":
                self._end_line()
                continue
            self.line += c
            if self.BAR.match(self.line):
                self._show(self._bar_ticks(self.line, False))

    def _end_line(self):
        line, self.line = self.line, ""
        if self.BAR.match(line):
            self.line_base = self._bar_ticks(line, True)
            self._show(self.line_base)
        elif line.strip():
            self.on_line(line)

    def close(self):
        if self.line:
            self._end_line()


def run(args, feedback, bar=True):
    """Runs terratin with args (the command first), its progress and
    messages on feedback; returns (exit code, stdout text when bar is
    False, else the summary lines). A cancel stops the process with
    SIGTERM and raises. stderr lines are shown as warnings while it runs;
    a failure (exit code other than 0 and 3) raises with them."""
    exe = checked_executable()
    cmd = [exe] + [str(a) for a in args]
    feedback.pushCommandInfo(" ".join(_quoted(a) for a in cmd))
    try:
        proc = subprocess.Popen(cmd, stdout=subprocess.PIPE,
                                stderr=subprocess.PIPE,
                                stdin=subprocess.DEVNULL)
    except OSError as e:
        raise QgsProcessingException("terratin: %s: %s" % (exe, e.strerror))
    summary = []
    errors = []
    out_text = []

    def on_line(line):
        summary.append(line)
        feedback.pushInfo(line)

    parser = BarParser(feedback.setProgress, on_line)
    # a character may straddle two reads
    decoder = codecs.getincrementaldecoder("utf-8")("replace")
    err_buf = [b""]
    open_fds = {proc.stdout.fileno(): "out", proc.stderr.fileno(): "err"}
    canceled = None
    while open_fds:
        if feedback.isCanceled() and canceled is None:
            canceled = time.monotonic()
            proc.send_signal(signal.SIGTERM)
        elif (canceled is not None and time.monotonic() - canceled > 10 and
              proc.poll() is None):
            # terratin's own watchdog ends a stopped run within a second;
            # this is the last resort
            proc.kill()
        ready, _, _ = select.select(list(open_fds), [], [], 0.1)
        for fd in ready:
            chunk = os.read(fd, 65536)
            if not chunk:
                del open_fds[fd]
                continue
            if open_fds[fd] == "out":
                text = decoder.decode(chunk)
                if bar:
                    parser.feed(text)
                else:
                    out_text.append(text)
            else:
                err_buf[0] += chunk
                *lines, err_buf[0] = err_buf[0].split(b"\n")
                for raw in lines:
                    _err_line(raw, errors, feedback)
    if err_buf[0]:
        _err_line(err_buf[0], errors, feedback)
    parser.close()
    proc.stdout.close()
    proc.stderr.close()
    rc = _wait(proc)
    if canceled is not None or feedback.isCanceled():
        if rc == 0:
            raise QgsProcessingException(
                "terratin %s: canceled after the run had finished (exit 0): "
                "its output is written" % args[0])
        raise QgsProcessingException(
            "terratin %s: canceled (exit %d); nothing was written" %
            (args[0], rc))
    if rc not in (0, 3):
        message = "\n".join(errors) or (
            "terratin %s: failed with exit code %d" % (args[0], rc))
        raise QgsProcessingException(message)
    for line in errors:
        feedback.pushWarning(line)
    if bar:
        feedback.setProgress(100)
        return rc, summary
    return rc, "".join(out_text)


def run_json(args, feedback):
    """Runs terratin with -json; returns (exit code, the object)."""
    rc, text = run(list(args) + ["-json"], feedback, bar=False)
    try:
        obj = json.loads(text)
    except ValueError:
        raise QgsProcessingException(
            "terratin %s: its -json output does not parse: %s" %
            (args[0], text[:200]))
    for line in json.dumps(obj, indent=1).splitlines():
        feedback.pushConsoleInfo(line)
    return rc, obj


def _err_line(raw, errors, feedback):
    """A line of stderr: "terratin: warning: ..." shown as a warning as it
    comes; the others (the error that ends a failed run) kept for the
    exception, or shown as warnings after a run that succeeds."""
    line = raw.decode("utf-8", "replace").rstrip("\r")
    if not line.strip():
        return
    if ": warning: " in line or line.startswith("warning: "):
        feedback.pushWarning(line)
    else:
        errors.append(line)


def _wait(proc):
    deadline = time.monotonic() + 30
    while proc.poll() is None and time.monotonic() < deadline:
        time.sleep(0.05)
    if proc.poll() is None:
        proc.kill()
    return proc.wait()


def _quoted(a):
    return a if re.match(r"^[\w@%+=:,./-]+$", a) else "'%s'" % a.replace(
        "'", "'\\''")
