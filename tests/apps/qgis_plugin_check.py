"""qgis_plugin_check.py ZIP TERRATIN DEM WORKDIR -- test_qgis_plugin.sh's
checks in headless QGIS: the plugin's zip installed into a fresh profile
and loaded, each algorithm through processing.run() against terratin's
command line (-json) on the same input, the progress, an error as the
command says it, a cancel mid-run that leaves nothing, and a model that
chains simplify -> eval. Prints a FAIL line per failed check, then the
count; exit 1 when one failed."""
import csv
import json
import os
import subprocess
import sys
import zipfile

ZIP, T, DEM, W = sys.argv[1:5]
sys.path.insert(0, "/usr/share/qgis/python/plugins")

from qgis.core import (QgsApplication, QgsMeshLayer,  # noqa: E402
                       QgsProcessingContext, QgsProcessingException,
                       QgsProcessingFeedback, QgsProcessingModelAlgorithm,
                       QgsProcessingModelChildAlgorithm,
                       QgsProcessingModelChildParameterSource,
                       QgsProcessingModelOutput, QgsProcessingModelParameter,
                       QgsProcessingParameterRasterLayer, QgsProject,
                       QgsRasterLayer, QgsVectorLayer)

PROFILE = os.path.join(W, "profile")
# with its GUI (offscreen): the algorithm dialog is run too
app = QgsApplication([], True, PROFILE)
app.initQgis()
from processing.core.Processing import Processing  # noqa: E402
Processing.initialize()
import processing  # noqa: E402
from processing.core.ProcessingConfig import ProcessingConfig  # noqa: E402
import qgis.utils  # noqa: E402

passed = failed = 0


def check(what, ok):
    global passed, failed
    if ok:
        passed += 1
    else:
        failed += 1
        print("FAIL:", what)
    return ok


def cli(*args):
    """terratin's own -json object and exit code for the same run."""
    out = subprocess.run([T] + [str(a) for a in args] + ["-json"],
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    return out.returncode, json.loads(out.stdout.decode())


class Feedback(QgsProcessingFeedback):
    """Keeps the progress values and the messages; cancels itself once
    the progress passes cancel_at."""

    def __init__(self, cancel_at=None):
        super().__init__()
        self.values = []
        self.infos = []
        self.errors = []
        self.cancel_at = cancel_at
        self.progressChanged.connect(self._progress)

    def _progress(self, v):
        self.values.append(v)
        if self.cancel_at is not None and v >= self.cancel_at:
            self.cancel()

    def pushInfo(self, text):
        self.infos.append(text)

    def reportError(self, text, fatal=False):
        self.errors.append(text)


def install():
    """The zip installed as Plugins > Install from ZIP installs it
    (pyplugin_installer's installFromZipFile: the plugin's name from the
    shortest metadata.txt, its unzip() into the profile's
    python/plugins), then found and started by QGIS's plugin loader."""
    sys.path.insert(0, "/usr/share/qgis/python")
    from pyplugin_installer.unzip import unzip
    with zipfile.ZipFile(ZIP) as z:
        names = z.namelist()
    metadata = sorted(n for n in names if n.endswith("metadata.txt"))
    check("the zip's plugin is terratin/ (%s)" % metadata[:1],
          metadata[:1] == ["terratin/metadata.txt"] and
          all(n.startswith("terratin/") for n in names))
    check("the profile is the fresh one (%s)" %
          QgsApplication.qgisSettingsDirPath(),
          os.path.realpath(QgsApplication.qgisSettingsDirPath()).startswith(
              os.path.realpath(PROFILE)))
    # what QGIS sets qgis.utils.home_plugin_path to (QgsPythonUtils, not
    # run in a headless application)
    plugins = os.path.join(QgsApplication.qgisSettingsDirPath(), "python",
                           "plugins")
    check("the profile's plugin folder (%s)" % plugins,
          os.path.realpath(plugins).startswith(os.path.realpath(PROFILE)))
    check("no terratin plugin there before", not os.path.exists(
        os.path.join(plugins, "terratin")))
    unzip(ZIP, plugins)
    if plugins not in sys.path:
        sys.path.insert(0, plugins)
    qgis.utils.plugin_paths = [plugins]
    qgis.utils.updateAvailablePlugins()
    check("QGIS lists the plugin (%s)" % qgis.utils.available_plugins,
          "terratin" in qgis.utils.available_plugins)
    check("the plugin loads", qgis.utils.loadPlugin("terratin"))
    check("its Processing part starts",
          qgis.utils.startProcessingPlugin("terratin"))
    import terratin
    check("loaded from the profile (%s)" % terratin.__file__,
          os.path.realpath(terratin.__file__).startswith(
              os.path.realpath(plugins)))
    reg = QgsApplication.processingRegistry()
    provider = reg.providerById("terratin")
    ids = sorted(a.id() for a in provider.algorithms()) if provider else []
    check("the provider's algorithms (%s)" % ids, ids == [
        "terratin:eval", "terratin:optimize", "terratin:rasterize",
        "terratin:simplify", "terratin:study"])
    for a in provider.algorithms() if provider else []:
        check(a.id() + ": a help string", len(a.shortHelpString()) > 100)
        check(a.id() + ": a display name", bool(a.displayName()))
        f = a.flags()
        check(a.id() + ": batch mode, cancel, threads (flags %s)" % int(f),
              f & a.FlagSupportsBatch and f & a.FlagCanCancel and
              not f & a.FlagNoThreading)
    check("the version in the provider's name (%s)" % provider.longName(),
          provider is not None and "terratin 0." in provider.longName())


def check_simplify():
    fb = Feedback()
    out = os.path.join(W, "s.gpkg")
    context = QgsProcessingContext()
    context.setProject(QgsProject.instance())
    r = processing.run("terratin:simplify", {
        "INPUT": DEM, "MAX_ERROR": 20, "CRITERION": 9, "OUTPUT": out},
        feedback=fb, context=context)
    rc, j = cli("simplify", DEM, os.path.join(W, "s_cli.gpkg"),
                "-max_error", 20, "-criterion", "l2")
    for name, key in (("VERTEX_COUNT", "vertices"),
                      ("TRIANGLE_COUNT", "triangles"),
                      ("MAX_ERROR_ACHIEVED", "max_error"),
                      ("RMSE", "rmse")):
        check("simplify %s: %s (command line %s)" % (name, r.get(name),
                                                     j[key]),
              r.get(name) == j[key])
    tl = QgsVectorLayer(r["TRIANGLES"], "t", "ogr")
    check("simplify: the triangles layer (%s) has the count" %
          r["TRIANGLES"], tl.isValid() and tl.featureCount() ==
          j["triangles"])
    v = fb.values
    check("simplify: progress rises to 100 in steps (%d values, %s)" %
          (len(v), v[-1:] if v else v),
          len(v) >= 20 and v == sorted(v) and v[-1] == 100)
    check("simplify: the summary as messages (%s)" % fb.infos[:1],
          any(s.startswith("output: ") for s in fb.infos))
    loaded = context.layersToLoadOnCompletion()
    names = sorted(d.name for d in loaded.values())
    check("simplify: triangles and vertices to load (%s)" % names,
          names == ["s triangles", "s vertices"])
    styled = [context.getMapLayer(i).renderer().type()
              for i in loaded if context.getMapLayer(i)]
    check("simplify: the layers with the GeoPackage's style (%s)" % styled,
          styled == ["graduatedSymbol", "graduatedSymbol"])
    # a mesh output: the figures from the summary, a mesh layer to load
    context = QgsProcessingContext()
    context.setProject(QgsProject.instance())
    mesh = os.path.join(W, "s.2dm")
    r = processing.run("terratin:simplify", {
        "INPUT": DEM, "MAX_POINTS": 2000, "OUTPUT": mesh}, context=context)
    rc, j = cli("simplify", DEM, os.path.join(W, "s_cli.2dm"),
                "-max_points", 2000)
    check("simplify 2DM: counts %s, %s (command line %s, %s)" % (
          r.get("VERTEX_COUNT"), r.get("TRIANGLE_COUNT"), j["vertices"],
          j["triangles"]), (r.get("VERTEX_COUNT"), r.get("TRIANGLE_COUNT"))
          == (j["vertices"], j["triangles"]))
    layers = [context.getMapLayer(i)
              for i in context.layersToLoadOnCompletion()]
    check("simplify 2DM: one mesh layer to load (%s)" % layers,
          len(layers) == 1 and isinstance(layers[0], QgsMeshLayer) and
          layers[0].dataProvider().faceCount() == j["triangles"])
    check_simplify_options()
    return out


def check_simplify_options():
    """Option sets through the dialog's parameters, each against the
    command line given the same options, on the DEM's north-west 200 x
    160 samples (fast)."""
    dem = os.path.join(W, "nw.tif")
    subprocess.run(["gdal_translate", "-q", "-srcwin", "0", "0", "200",
                    "160", DEM, dem], check=True)
    runs = [
        ({"METHOD": 1, "MAX_ERROR": 20, "TILE_SIZE": 128,
          "T_SRS": "EPSG:32616"},
         ["-method", "decimate", "-max_error", 20, "-tile_size", 128,
          "-t_srs", "EPSG:32616"]),
        ({"MAX_ERROR": 20, "SRCNODATA": 300, "Z_FACTOR": 0.5,
          "THREADS": 2, "CRITERION": 1, "REPAIR": 3, "OPTIMIZE": 2},
         ["-max_error", 20, "-srcnodata", 300, "-z_factor", 0.5,
          "-threads", 2, "-criterion", "minmax_angle", "-repair",
          "lookahead", "-optimize", "lookahead"]),
        ({"PERCENT": 3, "MAX_TRIANGLES": 5000, "OUTPUT_EXT": ".shp"},
         ["-percent", 3, "-max_triangles", 5000]),
        ({"MAX_POINTS": 800, "OUTPUT_EXT": ".fgb"}, ["-max_points", 800,
                                                    "-layers", "triangles"]),
        # heights declared in feet, converted to metres (fewer vertices at
        # the same bound than the heights as they are)
        ({"MAX_ERROR": 30, "Z_UNIT": 1, "Z_TO": 1},
         ["-max_error", 30, "-z_unit", "ft", "-z_to", "m"]),
        # a window of the DEM (map coordinates, the extent's CRS) and
        # options the dialog has no field for
        ({"MAX_ERROR": 10, "PROJWIN": "-84.4,-84.3,36.62,36.72 [EPSG:4326]",
          "EXTRA": "-nln tt_ -max_memory 500M"},
         ["-max_error", 10, "-projwin", -84.4, 36.72, -84.3, 36.62,
          "-projwin_srs", "EPSG:4326", "-nln", "tt_", "-max_memory",
          "500M"]),
    ]
    for i, (params, options) in enumerate(runs):
        ext = params.pop("OUTPUT_EXT", ".gpkg")
        out = os.path.join(W, "opt%d%s" % (i, ext))
        params.update({"INPUT": dem, "OUTPUT": out, "LOAD": False})
        r = processing.run("terratin:simplify", params)
        rc, j = cli("simplify", dem, os.path.join(W, "opt%d_cli%s" %
                                                  (i, ext)), *options)
        got = tuple(r.get(k) for k in ("VERTEX_COUNT", "TRIANGLE_COUNT",
                                       "MAX_ERROR_ACHIEVED", "RMSE"))
        want = (j["vertices"], j["triangles"], j["max_error"], j["rmse"])
        if ext == ".fgb":
            # no run_parameters: the summary's errors, 4 digits
            want = want[:2] + tuple(float("%.4g" % v) for v in want[2:])
        check("simplify %s: %s (command line %s)" % (
            " ".join(str(o) for o in options), got, want), got == want)
        tl = QgsVectorLayer(r["TRIANGLES"], "t", "ogr")
        check("simplify %s: the triangles layer %s in %s" % (
            options[:2], r["TRIANGLES"], tl.crs().authid()),
            tl.isValid() and tl.featureCount() == j["triangles"] and
            tl.crs().authid() == ("EPSG:32616" if "-t_srs" in options
                                  else "EPSG:4326"))


def check_task():
    """A run as the dialog (and batch mode) makes it: a task on QGIS's
    task manager, the algorithm in another thread."""
    from qgis.core import QgsProcessingAlgRunnerTask
    alg = QgsApplication.processingRegistry().createAlgorithmById(
        "terratin:simplify")
    context = QgsProcessingContext()
    context.setProject(QgsProject.instance())
    fb = Feedback()
    out = os.path.join(W, "task.gpkg")
    results = {}
    task = QgsProcessingAlgRunnerTask(alg, {"INPUT": DEM, "MAX_POINTS": 3000,
                                            "OUTPUT": out}, context, fb)
    task.executed.connect(lambda ok, res: results.update(ok=ok, res=res))
    QgsApplication.taskManager().addTask(task)
    import time
    deadline = time.monotonic() + 60
    while "ok" not in results and time.monotonic() < deadline:
        QgsApplication.processEvents()
        time.sleep(0.02)
    rc, j = cli("simplify", DEM, os.path.join(W, "task_cli.gpkg"),
                "-max_points", 3000)
    res = results.get("res") or {}
    check("a task in another thread: %s, %s vertices (command line %s)" % (
        results.get("ok"), res.get("VERTEX_COUNT"), j["vertices"]),
        results.get("ok") is True and res.get("VERTEX_COUNT") ==
        j["vertices"] and fb.values and fb.values[-1] == 100)
    del task


def check_eval(tin):
    err = os.path.join(W, "err.tif")
    r = processing.run("terratin:eval", {
        "DEM": DEM, "TIN": tin + "|layername=triangles",
        "ERROR_RASTER": err})
    rc, j = cli("eval", DEM, tin)
    for name, key in (("MAX_ERROR", "max_error"), ("RMSE", "rmse"),
                      ("MEAN_ABS_ERROR", "mean_abs_error"),
                      ("TOTAL_ABS_ERROR", "total_abs_error"), ("L2", "l2"),
                      ("TRIANGLE_COUNT", "triangles"),
                      ("COVERED", "covered"), ("UNCOVERED", "uncovered"),
                      ("OVERLAPPED", "overlapped")):
        check("eval %s: %s (command line %s)" % (name, r.get(name), j[key]),
              r.get(name) == j[key])
    check("eval: PASS without a check", r.get("PASS") is True)
    raster = QgsRasterLayer(err, "err", "gdal")
    dem = QgsRasterLayer(DEM, "dem", "gdal")
    if check("eval: the error raster opens", raster.isValid()):
        stats = raster.dataProvider().bandStatistics(1)
        big = max(abs(stats.minimumValue), abs(stats.maximumValue))
        check("eval: the error raster's largest |TIN - DEM| %g is the max "
              "error %g" % (big, j["max_error"]),
              abs(big - j["max_error"]) < 1e-3)
        check("eval: the error raster is on the DEM's grid",
              (raster.width(), raster.height()) == (dem.width(),
                                                    dem.height()))
    # a mesh: simplify's 2DM, as a path and as a loaded mesh layer
    mesh = os.path.join(W, "s.2dm")
    rc, j2 = cli("eval", DEM, mesh)
    for what, value in (("path", mesh),
                        ("mesh layer", QgsMeshLayer(mesh, "m", "mdal"))):
        r = processing.run("terratin:eval", {"DEM": DEM, "TIN": value})
        got = (r.get("MAX_ERROR"), r.get("RMSE"), r.get("COVERED"),
               r.get("TRIANGLE_COUNT"))
        want = (j2["max_error"], j2["rmse"], j2["covered"], j2["triangles"])
        check("eval of a 2DM %s: %s (command line %s)" % (what, got, want),
              got == want)
    r = processing.run("terratin:eval", {"DEM": DEM, "TIN": tin,
                                         "CHECK_MAX_ERROR": 10})
    check("eval: a check failed is PASS false, not an error (%s)" %
          r.get("PASS"), r.get("PASS") is False and r.get("MAX_ERROR") ==
          j["max_error"])


def dem_first():
    """Whether this terratin's rasterize takes DEM TIN OUTPUT (its usage
    says; older ones took TIN DEM OUTPUT)."""
    out = subprocess.run([T, "rasterize", "--help"], stdout=subprocess.PIPE)
    return b"rasterize DEM TIN" in out.stdout


def rasterize_cli(tin, dem, out):
    first, second = (dem, tin) if dem_first() else (tin, dem)
    return cli("rasterize", first, second, out)


def check_rasterize(tin):
    out = os.path.join(W, "surface.tif")
    r = processing.run("terratin:rasterize", {"TIN": tin, "DEM": DEM,
                                              "OUTPUT": out})
    rc, j = rasterize_cli(tin, DEM, os.path.join(W, "surface_cli.tif"))
    for name, key in (("COVERED", "covered"), ("MAX_ERROR", "max_error"),
                      ("RMSE", "rmse"), ("TRIANGLE_COUNT", "triangles")):
        check("rasterize %s: %s (command line %s)" % (name, r.get(name),
                                                      j[key]),
              r.get(name) == j[key])
    la = QgsRasterLayer(out, "a", "gdal")
    lb = QgsRasterLayer(os.path.join(W, "surface_cli.tif"), "b", "gdal")
    a = la.dataProvider().bandStatistics(1)
    b = lb.dataProvider().bandStatistics(1)
    check("rasterize: the same surface (min, max, mean)",
          (a.minimumValue, a.maximumValue, a.mean) ==
          (b.minimumValue, b.maximumValue, b.mean))


def check_optimize(tin):
    try:
        processing.run("terratin:optimize", {
            "DEM": DEM, "TIN": tin, "OUTPUT": os.path.join(W, "o.2dm")})
        check("optimize into a 2DM: refused", False)
    except QgsProcessingException as e:
        check("optimize into a 2DM: refused (%s)" % e,
              "optimize writes a GeoPackage" in str(e) and
              not os.path.exists(os.path.join(W, "o.2dm")))
    out = os.path.join(W, "o.gpkg")
    r = processing.run("terratin:optimize", {
        "DEM": DEM, "TIN": tin, "CRITERION": 9, "OUTPUT": out})
    rc, j = cli("optimize", DEM, tin, os.path.join(W, "o_cli.gpkg"),
                "-criterion", "l2", "-optimize", "local")
    for name, key in (("VERTEX_COUNT", "vertices"),
                      ("TRIANGLE_COUNT", "triangles")):
        check("optimize %s: %s (command line %s)" % (name, r.get(name),
                                                     j[key]),
              r.get(name) == j[key])
    for side in ("before", "after"):
        for key in ("max_error", "rmse", "mean_abs_error", "l2"):
            name = "%s_%s" % (key.upper(), side.upper())
            check("optimize %s: %s (command line %s)" % (
                name, r.get(name), j[side][key]),
                r.get(name) == j[side][key])
    check("optimize: the output's triangles",
          QgsVectorLayer(r["TRIANGLES"], "t", "ogr").featureCount() ==
          j["triangles"])


def check_study():
    out = os.path.join(W, "study")
    r = processing.run("terratin:study", {
        "GENERATED": [0], "CRITERIA": [0, 1, 9], "PERCENT": "1,10",
        "OUTPUT": out})
    ref = os.path.join(W, "study_cli")
    subprocess.run([T, "study", "-terrain", "fault_smooth", "-criteria",
                    "delaunay,minmax_angle,l2", "-percent", "1,10", "-q",
                    ref], check=True)

    def rows(folder):
        with open(os.path.join(folder, "curves.csv"), newline="") as f:
            return [{k: v for k, v in row.items() if k != "seconds"}
                    for row in csv.DictReader(f)]
    got, want = rows(out), rows(ref)
    check("study: curves.csv as the command line's (%d rows, %d)" %
          (len(got), len(want)), got == want and len(got) == 6)
    check("study: RUNS %s" % r.get("RUNS"), r.get("RUNS") == 6)
    check("study: tables.md", os.path.isfile(r.get("TABLES", "")))
    # -plot, when matplotlib is there (the command checks it first)
    have_mpl = subprocess.run(["/usr/bin/python3", "-c", "import matplotlib"],
                              stderr=subprocess.DEVNULL).returncode == 0
    if have_mpl:
        from qgis.PyQt.QtGui import QImage
        r = processing.run("terratin:study", {
            "GENERATED": [0], "CRITERIA": [0, 9], "PERCENT": "1,10",
            "PLOT": True, "OUTPUT": os.path.join(W, "study_plot")})
        pngs = sorted(os.listdir(r["PLOTS"])) if os.path.isdir(
            r.get("PLOTS", "")) else []
        check("study -plot: the PNGs (%s)" % pngs,
              "fault_smooth_insert_mean_abs_error.png" in pngs and
              all(not QImage(os.path.join(r["PLOTS"], f)).isNull()
                  for f in pngs))
    else:
        print("note: matplotlib is not installed: study -plot not checked")
    # a DEM layer as a terrain, into a temporary folder
    small = os.path.join(W, "small.tif")
    subprocess.run(["gdal_translate", "-q", "-srcwin", "0", "0", "120",
                    "100", DEM, small], check=True)
    r = processing.run("terratin:study", {
        "TERRAINS": [small], "CRITERIA": [0], "METHODS": [0, 1],
        "PERCENT": "5", "OUTPUT": "TEMPORARY_OUTPUT"})
    ref = os.path.join(W, "study_dem_cli")
    subprocess.run([T, "study", "-terrain", small, "-criteria", "delaunay",
                    "-methods", "insert,decimate", "-percent", "5", "-q",
                    ref], check=True)
    got, want = rows(r["OUTPUT"]), rows(ref)
    check("study of a DEM layer, both methods: curves.csv as the command "
          "line's (%d rows, %d)" % (len(got), len(want)),
          got == want and len(got) == 2)


def check_error():
    """A refusal says what the command says, on one line."""
    out = os.path.join(W, "refused.gpkg")
    cmd = subprocess.run([T, "simplify", DEM, out, "-max_points", "2"],
                         stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    said = cmd.stderr.decode().strip()
    try:
        processing.run("terratin:simplify", {"INPUT": DEM, "MAX_POINTS": 2,
                                             "OUTPUT": out})
        check("simplify -max_points 2: refused", False)
    except QgsProcessingException as e:
        check("the error as the command says it (%r; command line %r)" %
              (str(e), said), said and said in str(e) and cmd.returncode
              == 2)
    check("refused: no output", not os.path.exists(out))
    # a binary that is not terratin, set in the provider's settings
    fake = os.path.join(W, "fake_terratin")
    with open(fake, "w") as f:
        f.write("#!/bin/sh\necho 'gdal 3.6'\n")
    os.chmod(fake, 0o755)
    ProcessingConfig.setSettingValue("TERRATIN_PATH", fake)
    try:
        processing.run("terratin:simplify", {"INPUT": DEM, "OUTPUT": out})
        check("a binary that is not terratin: refused", False)
    except QgsProcessingException as e:
        check("the setting's binary is version-checked (%s)" % e,
              "not terratin" in str(e) and fake in str(e))
    ProcessingConfig.setSettingValue("TERRATIN_PATH", T)
    r = processing.run("terratin:simplify", {"INPUT": DEM, "MAX_POINTS": 100,
                                             "OUTPUT": out})
    check("the setting's terratin runs", r.get("VERTEX_COUNT") == 100)
    # a terratin whose rasterize takes its two inputs the other way round
    # (its usage says so; rasterize was TIN DEM OUTPUT before DEM TIN
    # OUTPUT): the plugin follows the usage
    swapped = os.path.join(W, "swapped_terratin")
    usage = "TIN DEM" if dem_first() else "DEM TIN"
    with open(swapped, "w") as f:
        f.write('#!/bin/sh\n'
                'if [ "$1" = rasterize ] && [ "$2" = --help ]; then\n'
                '  echo "Usage: terratin rasterize %s OUTPUT"; exit 0\n'
                'fi\n'
                'if [ "$1" = rasterize ]; then\n'
                '  shift; a=$1; b=$2; shift 2\n'
                '  exec "%s" rasterize "$b" "$a" "$@"\n'
                'fi\n'
                'exec "%s" "$@"\n' % (usage, T, T))
    os.chmod(swapped, 0o755)
    ProcessingConfig.setSettingValue("TERRATIN_PATH", swapped)
    tin = os.path.join(W, "s.gpkg")
    r = processing.run("terratin:rasterize", {
        "TIN": tin, "DEM": DEM, "OUTPUT": os.path.join(W, "swapped.tif")})
    rc, j = rasterize_cli(tin, DEM, os.path.join(W, "swapped_cli.tif"))
    check("rasterize %s OUTPUT followed from the usage (%s, %s)" % (
        usage, r.get("COVERED"), j["covered"]),
        r.get("COVERED") == j["covered"])
    ProcessingConfig.setSettingValue("TERRATIN_PATH", "")


def running_with(word):
    """Processes whose command line names word (the run's output)."""
    found = []
    for pid in os.listdir("/proc"):
        try:
            with open("/proc/%s/cmdline" % pid, "rb") as f:
                if word.encode() in f.read():
                    found.append(pid)
        except OSError:
            pass
    return found


def check_cancel():
    """Cancel mid-run, while simplifying (15 % of the bar) and while
    writing (90 %): the algorithm fails, the process is gone, the folder
    holds nothing new and an output that was there is as it was."""
    big = os.path.join(W, "big.tif")
    subprocess.run([T, "generate", "diamond_square", big, "-size", "513",
                    "-q"], check=True)
    for at, old in ((15, None), (90, b"the old output")):
        folder = os.path.join(W, "cancel%d" % at)
        os.mkdir(folder)
        out = os.path.join(folder, "c.gpkg")
        if old:
            with open(out, "wb") as f:
                f.write(old)
        fb = Feedback(cancel_at=at)
        try:
            processing.run("terratin:simplify", {
                "INPUT": big, "MAX_ERROR": 0, "OUTPUT": out}, feedback=fb)
            check("cancel at %d%%: the run fails" % at, False)
        except QgsProcessingException as e:
            check("cancel at %d%%: the run fails saying so (%s)" % (at, e),
                  "canceled" in str(e))
        check("cancel at %d%%: stopped before the end (%s)" % (
            at, fb.values[-1:]), fb.values and fb.values[-1] < 100)
        check("cancel at %d%%: no terratin left running" % at,
              running_with(out) == [])
        left = sorted(os.listdir(folder))
        check("cancel at %d%%: nothing new in the folder (%s)" % (at, left),
              left == (["c.gpkg"] if old else []))
        if old:
            with open(out, "rb") as f:
                check("cancel at %d%%: the old output as it was" % at,
                      f.read() == old)


def check_model():
    """A model built in code: its DEM into simplify, simplify's
    triangles into eval, eval's max error and RMS as the model's
    outputs."""
    model = QgsProcessingModelAlgorithm("tin_and_check", "terratin")
    model.addModelParameter(QgsProcessingParameterRasterLayer("dem", "DEM"),
                            QgsProcessingModelParameter("dem"))
    simplify = QgsProcessingModelChildAlgorithm("terratin:simplify")
    simplify.setChildId("simplify")
    simplify.addParameterSources("INPUT", [
        QgsProcessingModelChildParameterSource.fromModelParameter("dem")])
    simplify.addParameterSources("MAX_ERROR", [
        QgsProcessingModelChildParameterSource.fromStaticValue(15)])
    simplify.addParameterSources("LOAD", [
        QgsProcessingModelChildParameterSource.fromStaticValue(False)])
    simplify.addParameterSources("OUTPUT", [
        QgsProcessingModelChildParameterSource.fromStaticValue(
            os.path.join(W, "model_tin.gpkg"))])
    model.addChildAlgorithm(simplify)
    ev = QgsProcessingModelChildAlgorithm("terratin:eval")
    ev.setChildId("eval")
    ev.addParameterSources("DEM", [
        QgsProcessingModelChildParameterSource.fromModelParameter("dem")])
    ev.addParameterSources("TIN", [
        QgsProcessingModelChildParameterSource.fromChildOutput(
            "simplify", "TRIANGLES")])
    outputs = {}
    for name in ("MAX_ERROR", "RMSE", "COVERED"):
        o = QgsProcessingModelOutput(name.lower())
        o.setChildId("eval")
        o.setChildOutputName(name)
        outputs[name.lower()] = o
    ev.setModelOutputs(outputs)
    model.addChildAlgorithm(ev)
    ok, errors = model.validate()
    check("the model validates (%s)" % errors, ok)
    r = processing.run(model, {"dem": DEM})
    rc, j = cli("eval", DEM, os.path.join(W, "model_tin.gpkg"))
    # saved as the modeler saves it (.model3) and read back
    path = os.path.join(W, "tin_and_check.model3")
    check("the model saved", model.toFile(path))
    again = QgsProcessingModelAlgorithm()
    check("the model read back", again.fromFile(path))
    r2 = processing.run(again, {"dem": DEM})
    check("the model read back gives the same (%s)" % r2.get(
        "eval:max_error"), all(r2.get(k) == r.get(k) for k in (
            "eval:max_error", "eval:rmse", "eval:covered")))
    got = (r.get("eval:max_error"), r.get("eval:rmse"),
           r.get("eval:covered"))
    check("model simplify -> eval: %s (command line %s)" % (got, (
        j["max_error"], j["rmse"], j["covered"])),
        got == (j["max_error"], j["rmse"], j["covered"]) and
        j["max_error"] <= 15)


def check_dialog():
    """The toolbox's dialog, Run pressed: the run in its task, the result
    loaded into the project (the GeoPackage's layers, a mesh layer, the
    error raster), nothing twice."""
    import time
    from processing.gui.AlgorithmDialog import AlgorithmDialog
    project = QgsProject.instance()
    project.clear()
    runs = [("terratin:simplify", {"INPUT": DEM, "MAX_POINTS": 1500,
                                   "OUTPUT": os.path.join(W, "dlg.gpkg")}),
            ("terratin:simplify", {"INPUT": DEM, "MAX_POINTS": 1500,
                                   "OUTPUT": os.path.join(W, "dlg.2dm")}),
            ("terratin:eval", {"DEM": DEM,
                               "TIN": os.path.join(W, "dlg.gpkg") +
                               "|layername=triangles",
                               "ERROR_RASTER": os.path.join(W, "dlg.tif")})]
    for alg_id, params in runs:
        alg = QgsApplication.processingRegistry().createAlgorithmById(alg_id)
        d = AlgorithmDialog(alg, False, None)
        d.mainWidget().setParameters(params)
        d.show()
        d.runAlgorithm()
        deadline = time.monotonic() + 60
        while not d.results() and time.monotonic() < deadline:
            QgsApplication.processEvents()
            time.sleep(0.02)
        for _ in range(20):
            QgsApplication.processEvents()
        check("the %s dialog ran (%s)" % (alg_id, sorted(d.results())),
              bool(d.results()))
        d.close()
        d.deleteLater()
    layers = sorted((type(la).__name__, la.name(), la.isValid())
                    for la in project.mapLayers().values())
    check("the dialogs' results in the project (%s)" % layers, layers == [
        ("QgsMeshLayer", "dlg", True),
        ("QgsRasterLayer", "Error raster (TIN - DEM, GeoTIFF)", True),
        ("QgsVectorLayer", "dlg triangles", True),
        ("QgsVectorLayer", "dlg vertices", True)])
    project.clear()


def check_batch():
    """Batch mode: the toolbox's batch dialog with two rows, Run: each
    row's TIN as the command line's, both loaded."""
    from processing.gui.BatchAlgorithmDialog import BatchAlgorithmDialog
    from processing.tools import dataobjects
    project = QgsProject.instance()
    project.clear()
    alg = QgsApplication.processingRegistry().createAlgorithmById(
        "terratin:simplify")
    d = BatchAlgorithmDialog(alg)
    panel = d.mainWidget()
    context = dataobjects.createContext()
    rows = [({"INPUT": DEM, "MAX_POINTS": 300}, ["-max_points", 300]),
            ({"INPUT": DEM, "MAX_ERROR": 30, "METHOD": 1},
             ["-max_error", 30, "-method", "decimate"])]
    while panel.batchRowCount() < len(rows):
        panel.addRow()
    for row, (values, _) in enumerate(rows):
        for name, value in values.items():
            panel.wrappers[row][panel.parameter_to_column[name]] \
                .setParameterValue(value, context)
        panel.tblParameters.cellWidget(
            row + 1, panel.parameter_to_column["OUTPUT"]).setValue(
                os.path.join(W, "batch%d.gpkg" % row))
    d.show()
    d.runAlgorithm()
    for _ in range(20):
        QgsApplication.processEvents()
    for row, (_, options) in enumerate(rows):
        rc, j = cli("simplify", DEM, os.path.join(W, "batch%d_cli.gpkg" %
                                                  row), *options)
        tl = QgsVectorLayer(os.path.join(W, "batch%d.gpkg" % row) +
                            "|layername=triangles", "t", "ogr")
        check("batch row %d: %s triangles (command line %s)" % (
            row, tl.featureCount(), j["triangles"]),
            tl.isValid() and tl.featureCount() == j["triangles"])
    names = sorted(la.name() for la in project.mapLayers().values())
    check("batch: both rows loaded (%s)" % names, names == [
        "batch0 triangles", "batch0 vertices", "batch1 triangles",
        "batch1 vertices"])
    d.close()
    d.deleteLater()
    del panel, d
    for _ in range(5):
        QgsApplication.processEvents()
    project.clear()


def main():
    install()
    tin = check_simplify()
    check_task()
    check_eval(tin)
    check_rasterize(tin)
    check_optimize(tin)
    check_study()
    check_error()
    check_cancel()
    check_model()
    check_dialog()
    check_batch()


main()
print("%d passed, %d failed" % (passed, failed))
qgis.utils.unloadPlugin("terratin")
app.exitQgis()
sys.exit(1 if failed else 0)
