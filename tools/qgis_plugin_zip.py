#!/usr/bin/env python3
"""qgis_plugin_zip.py -- the zip of the QGIS plugin qgis/terratin/ that
QGIS's Plugins > Manage and Install Plugins > Install from ZIP takes: one
top folder terratin/ with the plugin's files (no caches).

  tools/qgis_plugin_zip.py OUT.zip  (make qgis-plugin: build/terratin-qgis.zip)

The version in the zip's name is the plugin's metadata.txt's; the files
are stored in name order with a fixed time, so the same tree gives the
same zip."""
import os
import sys
import zipfile

HERE = os.path.dirname(os.path.abspath(__file__))
PLUGIN = os.path.join(HERE, os.pardir, "qgis", "terratin")


def plugin_files(root):
    for folder, dirs, files in os.walk(root):
        dirs[:] = sorted(d for d in dirs if d != "__pycache__")
        for name in sorted(files):
            if name.endswith((".pyc", ".pyo")) or name.startswith("."):
                continue
            path = os.path.join(folder, name)
            yield path, os.path.join("terratin", os.path.relpath(path, root))


def main(argv):
    if len(argv) != 2:
        print("usage: qgis_plugin_zip.py OUT.zip", file=sys.stderr)
        return 2
    out = argv[1]
    folder = os.path.dirname(os.path.abspath(out))
    os.makedirs(folder, exist_ok=True)
    tmp = out + ".part"
    with zipfile.ZipFile(tmp, "w", zipfile.ZIP_DEFLATED) as z:
        for path, arcname in plugin_files(os.path.normpath(PLUGIN)):
            info = zipfile.ZipInfo(arcname, (2026, 1, 1, 0, 0, 0))
            info.compress_type = zipfile.ZIP_DEFLATED
            info.external_attr = 0o644 << 16
            with open(path, "rb") as f:
                z.writestr(info, f.read())
    os.replace(tmp, out)
    print("qgis-plugin: wrote %s (Install from ZIP in QGIS)" % out)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
