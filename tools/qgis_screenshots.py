#!/usr/bin/python3
"""qgis_screenshots.py TERRATIN OUTDIR -- the pictures of docs/qgis.md,
taken in QGIS (run under Xvfb: xvfb-run -a /usr/bin/python3 ...):

  qgis_simplify_dialog.png  the "Simplify DEM to TIN" dialog of the
                            Processing toolbox, as a user opens it
  qgis_simplify_log.png     that dialog after Run: its log
  qgis_eval_dialog.png      the "Measure TIN against DEM" dialog
  qgis_result.png           the TIN that dialog makes of the Jacksboro
                            DEM (testdata/), with the style the
                            GeoPackage carries, over gdaldem's hillshade

The plugin is loaded from qgis/terratin/ of this tree, the run is
processing.run() as the dialog's Run button does it."""
import os
import shutil
import subprocess
import sys
import tempfile
import time

T, OUT = sys.argv[1:3]
HERE = os.path.dirname(os.path.abspath(__file__))
SRC = os.path.normpath(os.path.join(HERE, os.pardir))
DEM = os.path.join(SRC, "testdata", "jacksboro_fault_dem.tif")
sys.path.insert(0, "/usr/share/qgis/python/plugins")
sys.path.insert(0, os.path.join(SRC, "qgis"))
os.environ["PATH"] = os.path.dirname(os.path.abspath(T)) + ":" + \
    os.environ["PATH"]

from qgis.core import (QgsApplication, QgsMapRendererParallelJob,  # noqa
                       QgsMapSettings, QgsRasterLayer, QgsVectorLayer)
from qgis.PyQt.QtCore import QSize  # noqa: E402
from qgis.PyQt.QtGui import QColor  # noqa: E402

work = tempfile.mkdtemp(prefix="tt_qgis_shots.")
# a copy: QGIS's statistics of a raster layer go to a .aux.xml beside it
shutil.copy(DEM, os.path.join(work, "jacksboro_fault_dem.tif"))
DEM = os.path.join(work, "jacksboro_fault_dem.tif")
app = QgsApplication([], True, os.path.join(work, "profile"))
app.initQgis()
from processing.core.Processing import Processing  # noqa: E402
Processing.initialize()
import processing  # noqa: E402
from processing.gui.AlgorithmDialog import AlgorithmDialog  # noqa: E402
import terratin  # noqa: E402

plugin = terratin.classFactory(None)
plugin.initProcessing()
os.makedirs(OUT, exist_ok=True)


def dialog_shot(alg_id, png, params):
    alg = QgsApplication.processingRegistry().createAlgorithmById(alg_id)
    d = AlgorithmDialog(alg, False, None)
    d.resize(980, 760)
    panel = d.mainWidget()
    panel.setParameters(params)
    d.show()
    for _ in range(20):
        app.processEvents()
    d.grab().save(os.path.join(OUT, png))
    d.close()
    d.deleteLater()
    app.processEvents()


tin = os.path.join(work, "jacksboro_tin.gpkg")
r = processing.run("terratin:simplify", {"INPUT": DEM, "MAX_ERROR": 20,
                                         "CRITERION": 9, "LOAD": False,
                                         "OUTPUT": tin})
dialog_shot("terratin:simplify", "qgis_simplify_dialog.png",
            {"INPUT": DEM, "MAX_ERROR": 20, "CRITERION": 9,
             "OUTPUT": os.path.join(work, "jacksboro_tin.gpkg")})
dialog_shot("terratin:eval", "qgis_eval_dialog.png",
            {"DEM": DEM, "TIN": r["TRIANGLES"], "CHECK_MAX_ERROR": 20,
             "ERROR_RASTER": os.path.join(work, "error.tif")})

# the dialog after Run: the log with the command, the summary and the
# results, the progress bar full
alg = QgsApplication.processingRegistry().createAlgorithmById(
    "terratin:simplify")
d = AlgorithmDialog(alg, False, None)
d.resize(980, 760)
d.mainWidget().setParameters({
    "INPUT": DEM, "MAX_ERROR": 20, "CRITERION": 9, "LOAD": False,
    "OUTPUT": os.path.join(work, "jacksboro_tin_run.gpkg")})
d.show()
app.processEvents()
d.runAlgorithm()
for _ in range(600):
    app.processEvents()
    if d.results():
        break
    time.sleep(0.05)
for _ in range(20):
    app.processEvents()
d.showLog()
app.processEvents()
d.grab().save(os.path.join(OUT, "qgis_simplify_log.png"))
d.close()
d.deleteLater()
app.processEvents()

shade = os.path.join(work, "hillshade.tif")
subprocess.run(["gdaldem", "hillshade", "-q", "-s", "111120", DEM, shade],
               check=True)
hill = QgsRasterLayer(shade, "hillshade", "gdal")
tri = QgsVectorLayer(r["TRIANGLES"], "triangles", "ogr")
tri.loadDefaultStyle()
# the GeoPackage's style fills the triangles opaque; at 55 % the hillshade
# shows through (what a user sets in the layer's Symbology)
tri.setOpacity(0.55)
settings = QgsMapSettings()
settings.setLayers([tri, hill])
settings.setDestinationCrs(tri.crs())
settings.setBackgroundColor(QColor(255, 255, 255))
ext = tri.extent()
# a third of the width, north-east, at a scale the triangles show
x0, y0, w, h = ext.xMinimum(), ext.yMinimum(), ext.width(), ext.height()
ext.setXMinimum(x0 + w * 0.5)
ext.setXMaximum(x0 + w * 0.85)
ext.setYMinimum(y0 + h * 0.5)
ext.setYMaximum(y0 + h * 0.85)
settings.setExtent(ext)
settings.setOutputSize(QSize(900, 760))
job = QgsMapRendererParallelJob(settings)
job.start()
job.waitForFinished()
job.renderedImage().save(os.path.join(OUT, "qgis_result.png"))
del job, settings, tri, hill  # before exitQgis(): PyQGIS crashes otherwise
print("qgis_screenshots: %s: %d vertices, %d triangles, max error %g; "
      "wrote %s" % (tin, r["VERTEX_COUNT"], r["TRIANGLE_COUNT"],
                    r["MAX_ERROR_ACHIEVED"], OUT))
plugin.unload()
app.exitQgis()
shutil.rmtree(work)
