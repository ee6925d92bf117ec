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
app = QgsApplication([], False, PROFILE)
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
    """The zip unzipped into the fresh profile's python/plugins, found and
    started by QGIS's plugin loader (its metadata read)."""
    plugins = os.path.join(PROFILE, "python", "plugins")
    os.makedirs(plugins, exist_ok=True)
    with zipfile.ZipFile(ZIP) as z:
        names = z.namelist()
        check("the zip has one top folder terratin/ (%s)" % names[:3],
              all(n.startswith("terratin/") for n in names) and
              "terratin/metadata.txt" in names)
        z.extractall(plugins)
    check("the profile is the fresh one (%s)" %
          QgsApplication.qgisSettingsDirPath(),
          os.path.realpath(QgsApplication.qgisSettingsDirPath()).startswith(
              os.path.realpath(PROFILE)))
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
    return out


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
    r = processing.run("terratin:eval", {"DEM": DEM, "TIN": tin,
                                         "CHECK_MAX_ERROR": 10})
    check("eval: a check failed is PASS false, not an error (%s)" %
          r.get("PASS"), r.get("PASS") is False and r.get("MAX_ERROR") ==
          j["max_error"])


def check_rasterize(tin):
    out = os.path.join(W, "surface.tif")
    r = processing.run("terratin:rasterize", {"TIN": tin, "DEM": DEM,
                                              "OUTPUT": out})
    rc, j = cli("rasterize", tin, DEM, os.path.join(W, "surface_cli.tif"))
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
    ProcessingConfig.setSettingValue("TERRATIN_PATH", "")


def check_cancel():
    """Cancel mid-run (during the simplification, 15 % of the bar): the
    algorithm fails, the process is gone and its folder has nothing."""
    folder = os.path.join(W, "cancel")
    os.mkdir(folder)
    big = os.path.join(W, "big.tif")
    subprocess.run([T, "generate", "diamond_square", big, "-size", "513",
                    "-q"], check=True)
    out = os.path.join(folder, "c.gpkg")
    fb = Feedback(cancel_at=15)
    try:
        processing.run("terratin:simplify", {"INPUT": big, "MAX_ERROR": 0,
                                             "OUTPUT": out}, feedback=fb)
        check("cancel: the run fails", False)
    except QgsProcessingException as e:
        check("cancel: the run fails saying so (%s)" % e,
              "canceled" in str(e))
    check("cancel: stopped before the end (%s)" % fb.values[-1:],
          fb.values and fb.values[-1] < 85)
    check("cancel: nothing left in the folder (%s)" % os.listdir(folder),
          os.listdir(folder) == [])


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
    got = (r.get("eval:max_error"), r.get("eval:rmse"),
           r.get("eval:covered"))
    check("model simplify -> eval: %s (command line %s)" % (got, (
        j["max_error"], j["rmse"], j["covered"])),
        got == (j["max_error"], j["rmse"], j["covered"]) and
        j["max_error"] <= 15)


def main():
    install()
    tin = check_simplify()
    check_eval(tin)
    check_rasterize(tin)
    check_optimize(tin)
    check_study()
    check_error()
    check_cancel()
    check_model()


main()
print("%d passed, %d failed" % (passed, failed))
qgis.utils.unloadPlugin("terratin")
app.exitQgis()
sys.exit(1 if failed else 0)
