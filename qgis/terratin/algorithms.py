"""The terratin algorithms of the Processing toolbox: each builds the
command line of one terratin command from its parameters, runs it
(runner.py) and returns the figures the command prints as outputs a model
can use. Every option maps to the command's option of the same name
(terratin COMMAND --help, docs/cli.md); a parameter left empty is an
option not given, so the command's own default holds."""
import csv
import os
import re
import shlex

from qgis.core import (QgsMeshLayer, QgsProcessing, QgsProcessingAlgorithm,
                       QgsProcessingContext, QgsProcessingException,
                       QgsProcessingOutputBoolean, QgsProcessingOutputFile,
                       QgsProcessingOutputFolder, QgsProcessingOutputNumber,
                       QgsProcessingOutputString,
                       QgsProcessingOutputVectorLayer,
                       QgsProcessingParameterBand,
                       QgsProcessingParameterBoolean,
                       QgsProcessingParameterCrs, QgsProcessingParameterEnum,
                       QgsProcessingParameterExtent,
                       QgsProcessingParameterFileDestination,
                       QgsProcessingParameterFolderDestination,
                       QgsProcessingParameterMapLayer,
                       QgsProcessingParameterMultipleLayers,
                       QgsProcessingParameterNumber,
                       QgsProcessingParameterRasterDestination,
                       QgsProcessingParameterRasterLayer,
                       QgsProcessingParameterString,
                       QgsProcessingParameterVectorLayer,
                       QgsProviderRegistry, QgsVectorLayer)

from . import runner

CRITERIA = ["delaunay", "minmax_angle", "minmax_angle_lex", "min_area",
            "mean_curvature", "gaussian_curvature", "abn", "abn_sum",
            "abn_sumsq", "l2"]
REPAIRS = ["default", "flip", "local", "lookahead", "delaunay"]
OPTIMIZERS = ["default", "local", "lookahead", "anneal", "edge_insertion",
              "none"]
METHODS = ["insert", "decimate"]
# The outputs simplify and optimize write: OGR vector datasets of several
# layers and the mesh files QGIS opens as mesh layers (MDAL).
VECTOR_EXTS = {".gpkg": None, ".shp": None, ".sqlite": None,
               ".fgb": None, ".geojson": None}
MESH_EXTS = {".2dm": None, ".ply": None, ".nc": "UGRID"}
OTHER_EXTS = {".obj": None, ".xml": "LandXML", ".dxf": None}
TIN_FILTER = ";;".join([
    "GeoPackage (*.gpkg)", "ESRI Shapefile (*.shp)", "SQLite (*.sqlite)",
    "FlatGeobuf (*.fgb)", "GeoJSON (*.geojson)",
    "2DM mesh, QGIS mesh layer (*.2dm)", "PLY mesh (*.ply)",
    "UGRID netCDF mesh (*.nc)", "Wavefront OBJ (*.obj)",
    "LandXML 1.2 (*.xml)", "DXF 3DFACE (*.dxf)"])
Z_UNITS = ["the band's unit, else the vertical CRS's", "ft", "us-ft", "m"]
Z_TOS = ["auto (when the CRS is in metres or geographic)",
         "m (whatever the CRS)", "native (kept in their unit)"]
TIN_FRAMES = ["default (map; an STL that fits the grid: pixel)",
              "map (map coordinates, in the TIN's CRS)",
              "pixel (the DEM's columns and rows)"]
# optimize writes the layers of a dataset that holds several
OPTIMIZE_EXTS = (".gpkg", ".shp", ".sqlite")
OPTIMIZE_FILTER = ";;".join(["GeoPackage (*.gpkg)", "ESRI Shapefile (*.shp)",
                             "SQLite (*.sqlite)"])
STUDY_TERRAINS = ["fault_smooth", "fault_rough", "peak_rough",
                  "valley_rough", "hybrid", "sphere", "cylinder", "bump"]


def _raster_path(alg, parameters, name, context):
    layer = alg.parameterAsRasterLayer(parameters, name, context)
    if layer is None:
        raise QgsProcessingException(
            "%s: no raster layer" %
            alg.parameterDefinition(name).description())
    if layer.providerType() != "gdal":
        raise QgsProcessingException(
            "%s: %s is not a file GDAL reads" % (name, layer.source()))
    return layer.source()


def _tin_source(alg, parameters, name, context):
    """(path, layer name or None) of a vector layer parameter."""
    layer = alg.parameterAsVectorLayer(parameters, name, context)
    if layer is None:
        raise QgsProcessingException(
            "%s: no vector layer" %
            alg.parameterDefinition(name).description())
    if layer.providerType() != "ogr":
        raise QgsProcessingException(
            "%s: %s is not a file OGR reads" % (name, layer.source()))
    parts = QgsProviderRegistry.instance().decodeUri("ogr", layer.source())
    return parts.get("path") or layer.source(), parts.get("layerName") or None


def _eval_tin_source(alg, parameters, name, context):
    """(path, layer name or None) of eval's TIN: a polygon layer OGR reads
    or a mesh layer (2DM, PLY, UGRID, ... through MDAL)."""
    layer = alg.parameterAsLayer(parameters, name, context)
    if isinstance(layer, QgsMeshLayer):
        parts = QgsProviderRegistry.instance().decodeUri("mdal",
                                                         layer.source())
        path = parts.get("path") or layer.source()
        if not os.path.isfile(path):
            raise QgsProcessingException(
                "%s: %s is not a mesh file" % (name, layer.source()))
        return path, None
    return _tin_source(alg, parameters, name, context)


def _format_args(path):
    """-of for the outputs whose driver the extension does not name."""
    ext = os.path.splitext(path)[1].lower()
    of = {**VECTOR_EXTS, **MESH_EXTS, **OTHER_EXTS}.get(ext)
    return ["-of", of] if of else []


def _output_folder(path):
    """Makes the folder of an output file (Processing's temporary outputs
    name one that does not exist yet)."""
    if not path:
        raise QgsProcessingException("OUTPUT: no output file")
    folder = os.path.dirname(os.path.abspath(path))
    if not os.path.isdir(folder):
        os.makedirs(folder, exist_ok=True)


class TerratinAlgorithm(QgsProcessingAlgorithm):
    """What every terratin algorithm shares: the group, the help and the
    DEM options (band, nodata, heights)."""

    COMMAND = ""
    HELP = ""

    def createInstance(self):
        return type(self)()

    def group(self):
        return "TIN"

    def groupId(self):
        return "tin"

    def shortHelpString(self):
        return self.HELP + (
            "<p>Runs <code>terratin %s</code> (the terratin on PATH, or "
            "the one set in Settings &gt; Options &gt; Processing &gt; "
            "Providers &gt; terratin); <code>terratin %s --help</code> and "
            "docs/cli.md describe every option.</p>" %
            (self.COMMAND, self.COMMAND))

    def helpUrl(self):
        return ""

    def _add_dem_options(self, dem_param, with_band=True):
        if with_band:
            self.addParameter(QgsProcessingParameterBand(
                "BAND", "Band", 1, dem_param, True))
        p = QgsProcessingParameterNumber(
            "SRCNODATA", "Height to treat as nodata (empty: the band's)",
            QgsProcessingParameterNumber.Double, None, True)
        p.setFlags(p.flags() | p.FlagAdvanced)
        self.addParameter(p)
        p = QgsProcessingParameterNumber(
            "Z_FACTOR", "Z factor (heights times F, e.g. 0.3048 feet to "
            "metres)", QgsProcessingParameterNumber.Double, 1.0, True, 1e-12)
        p.setFlags(p.flags() | p.FlagAdvanced)
        self.addParameter(p)
        p = QgsProcessingParameterEnum(
            "Z_UNIT", "The heights' unit (-z_unit)", Z_UNITS, False, 0, True)
        p.setFlags(p.flags() | p.FlagAdvanced)
        self.addParameter(p)
        p = QgsProcessingParameterEnum(
            "Z_TO", "Heights in feet become metres (-z_to)", Z_TOS, False, 0,
            True)
        p.setFlags(p.flags() | p.FlagAdvanced)
        self.addParameter(p)
        p = QgsProcessingParameterExtent(
            "PROJWIN", "Read only this extent of the DEM (-projwin)", None,
            True)
        p.setFlags(p.flags() | p.FlagAdvanced)
        self.addParameter(p)
        p = QgsProcessingParameterCrs(
            "A_SRS", "The DEM's CRS, for one without or with a wrong one "
            "(-a_srs)", None, True)
        p.setFlags(p.flags() | p.FlagAdvanced)
        self.addParameter(p)
        self._add_extra()

    def _add_extra(self):
        p = QgsProcessingParameterString(
            "EXTRA", "Additional command-line options (as terratin %s "
            "--help gives them)" % self.COMMAND, None, False, True)
        p.setFlags(p.flags() | p.FlagAdvanced)
        self.addParameter(p)

    def _extra_args(self, parameters, context):
        text = self.parameterAsString(parameters, "EXTRA", context) or ""
        try:
            return shlex.split(text)
        except ValueError as e:
            raise QgsProcessingException("EXTRA: %s: %s" % (text, e))

    def _dem_args(self, parameters, context):
        args = []
        if "BAND" in [d.name() for d in self.parameterDefinitions()]:
            band = self.parameterAsInt(parameters, "BAND", context)
            if band > 1:
                args += ["-b", band]
        if parameters.get("SRCNODATA") not in (None, ""):
            args += ["-srcnodata", repr(self.parameterAsDouble(
                parameters, "SRCNODATA", context))]
        z = self.parameterAsDouble(parameters, "Z_FACTOR", context)
        if z != 1.0:
            args += ["-z_factor", repr(z)]
        unit = self.parameterAsEnum(parameters, "Z_UNIT", context)
        if unit:
            args += ["-z_unit", Z_UNITS[unit]]
        to = self.parameterAsEnum(parameters, "Z_TO", context)
        if to:
            args += ["-z_to", Z_TOS[to].split(" ")[0]]
        if parameters.get("PROJWIN") not in (None, ""):
            ext = self.parameterAsExtent(parameters, "PROJWIN", context)
            crs = self.parameterAsExtentCrs(parameters, "PROJWIN", context)
            args += ["-projwin"] + [repr(v) for v in (
                ext.xMinimum(), ext.yMaximum(), ext.xMaximum(),
                ext.yMinimum())]
            if crs.isValid():
                args += ["-projwin_srs", crs.authid() or crs.toWkt()]
        crs = self.parameterAsCrs(parameters, "A_SRS", context)
        if parameters.get("A_SRS") not in (None, "") and crs.isValid():
            args += ["-a_srs", crs.authid() or crs.toWkt()]
        return args + self._extra_args(parameters, context)

    def _optional_number(self, parameters, name, context, option, integer):
        if parameters.get(name) in (None, ""):
            return []
        if integer:
            return [option, self.parameterAsInt(parameters, name, context)]
        return [option, repr(self.parameterAsDouble(parameters, name,
                                                    context))]


def _nln(args):
    """The layer names' prefix an -nln among args gives ("" without)."""
    args = [str(a) for a in args]
    for i, a in enumerate(args[:-1]):
        if a.lower() == "-nln":
            return args[i + 1]
    return ""


def _load_tin(path, context, name, output_name, prefix=""):
    """Loads a TIN file when the run is over: the triangles and vertices
    layers of a vector dataset (with the style a GeoPackage carries) or a
    mesh layer; returns the triangles' source for the outputs."""
    ext = os.path.splitext(path)[1].lower()
    layers = []
    tri_source = None
    if ext in MESH_EXTS:
        layers.append(QgsMeshLayer(path, name, "mdal"))
    elif ext == ".shp":
        base = path[:-4] + "_" + prefix
        tri_source = base + "triangles.shp"
        layers.append(QgsVectorLayer(tri_source, name + " triangles", "ogr"))
        layers.append(QgsVectorLayer(base + "vertices.shp",
                                     name + " vertices", "ogr"))
    elif ext in VECTOR_EXTS and ext != ".fgb" and ext != ".geojson":
        tri_source = path + "|layername=%striangles" % prefix
        layers.append(QgsVectorLayer(tri_source, name + " triangles", "ogr"))
        layers.append(QgsVectorLayer(path + "|layername=%svertices" % prefix,
                                     name + " vertices", "ogr"))
    elif ext in (".fgb", ".geojson"):
        tri_source = path
        layers.append(QgsVectorLayer(path, name + " triangles", "ogr"))
    if context is not None:
        for layer in layers:
            if not layer.isValid():
                continue
            context.temporaryLayerStore().addMapLayer(layer)
            context.addLayerToLoadOnCompletion(
                layer.id(), QgsProcessingContext.LayerDetails(
                    layer.name(), context.project(), output_name))
    return tri_source


def _tin_triangles(path, prefix=""):
    """The triangles' source of a TIN file (for a model's next step)."""
    ext = os.path.splitext(path)[1].lower()
    if ext == ".shp":
        return path[:-4] + "_%striangles.shp" % prefix
    if ext in (".gpkg", ".sqlite"):
        return path + "|layername=%striangles" % prefix
    if ext in (".fgb", ".geojson"):
        return path
    return ""


class SimplifyAlgorithm(TerratinAlgorithm):
    COMMAND = "simplify"
    HELP = (
        "<p>Simplifies a DEM into a TIN whose vertices are grid samples, "
        "with an exact error bound: with a max error E every valid sample "
        "of the DEM lies within E (z units) of the TIN.</p>"
        "<p><b>Stop</b>: max error, max points, max triangles, percent of "
        "the samples; they combine and the first reached wins. All empty: "
        "twice the DEM's mean step between samples.</p>"
        "<p><b>Method</b>: insert (greedy insertion) or decimate (from a "
        "fine TIN, deleting the least important vertices; fewer vertices "
        "at the same bound, slower). <b>Criterion</b>: what the best "
        "triangulation is (delaunay; l2 is the most accurate). "
        "<b>Optimiser</b>: a final pass that never lifts an error past "
        "the bound.</p>"
        "<p><b>Output</b>: a GeoPackage (layers triangles, vertices, "
        "run_parameters, with a QGIS style), a Shapefile, SQLite, "
        "FlatGeobuf or GeoJSON (triangles only), or a mesh (2DM, PLY, "
        "UGRID .nc: loaded as a mesh layer; OBJ, LandXML, DXF). The "
        "figures (vertices, triangles, max and RMS error) are outputs: "
        "from the run_parameters layer, or for the formats without it "
        "from the summary (errors to 4 significant digits).</p>")

    def name(self):
        return "simplify"

    def displayName(self):
        return "Simplify DEM to TIN"

    def initAlgorithm(self, config=None):
        self.addParameter(QgsProcessingParameterRasterLayer("INPUT", "DEM"))
        self._add_dem_options("INPUT")
        self.addParameter(QgsProcessingParameterEnum(
            "METHOD", "Method", METHODS, False, 0, True))
        self.addParameter(QgsProcessingParameterEnum(
            "CRITERION", "Criterion", CRITERIA, False, 0, True))
        p = QgsProcessingParameterEnum("REPAIR", "Repair", REPAIRS, False,
                                       0, True)
        p.setFlags(p.flags() | p.FlagAdvanced)
        self.addParameter(p)
        self.addParameter(QgsProcessingParameterEnum(
            "OPTIMIZE", "Optimiser (final pass)", OPTIMIZERS, False, 0,
            True))
        self.addParameter(QgsProcessingParameterNumber(
            "MAX_ERROR", "Max error (z units)",
            QgsProcessingParameterNumber.Double, None, True, 0.0))
        self.addParameter(QgsProcessingParameterNumber(
            "MAX_POINTS", "Max points", QgsProcessingParameterNumber.Integer,
            None, True, 1))
        self.addParameter(QgsProcessingParameterNumber(
            "MAX_TRIANGLES", "Max triangles",
            QgsProcessingParameterNumber.Integer, None, True, 1))
        self.addParameter(QgsProcessingParameterNumber(
            "PERCENT", "Percent of the valid samples as vertices",
            QgsProcessingParameterNumber.Double, None, True, 0.0, 100.0))
        self.addParameter(QgsProcessingParameterCrs(
            "T_SRS", "Output CRS (empty: the DEM's)", None, True))
        for name, desc in (("TILE_SIZE", "Tile size (cells, >= 16; empty: "
                            "untiled unless the DEM does not fit)"),
                           ("THREADS", "Threads (empty: the default)"),
                           ("SEED", "Random seed (annealing)")):
            p = QgsProcessingParameterNumber(
                name, desc, QgsProcessingParameterNumber.Integer, None, True,
                16 if name == "TILE_SIZE" else (1 if name == "THREADS"
                                                else 0))
            p.setFlags(p.flags() | p.FlagAdvanced)
            self.addParameter(p)
        self.addParameter(QgsProcessingParameterFileDestination(
            "OUTPUT", "TIN", TIN_FILTER))
        self.addParameter(QgsProcessingParameterBoolean(
            "LOAD", "Load the result", True, True))
        self.addOutput(QgsProcessingOutputVectorLayer(
            "TRIANGLES", "Triangles layer (vector outputs)",
            QgsProcessing.TypeVectorPolygon))
        for name, desc in (("VERTEX_COUNT", "Vertices"),
                           ("TRIANGLE_COUNT", "Triangles"),
                           ("MAX_ERROR_ACHIEVED", "Max error achieved"),
                           ("RMSE", "RMS error")):
            self.addOutput(QgsProcessingOutputNumber(name, desc))

    def processAlgorithm(self, parameters, context, feedback):
        dem = _raster_path(self, parameters, "INPUT", context)
        out = self.parameterAsFileOutput(parameters, "OUTPUT", context)
        _output_folder(out)
        args = ["simplify"] + self._dem_args(parameters, context)
        method = METHODS[self.parameterAsEnum(parameters, "METHOD", context)]
        if method != "insert":
            args += ["-method", method]
        criterion = CRITERIA[self.parameterAsEnum(parameters, "CRITERION",
                                                  context)]
        if criterion != "delaunay":
            args += ["-criterion", criterion]
        repair = REPAIRS[self.parameterAsEnum(parameters, "REPAIR", context)]
        if repair != "default":
            args += ["-repair", repair]
        optimize = OPTIMIZERS[self.parameterAsEnum(parameters, "OPTIMIZE",
                                                   context)]
        if optimize != "default":
            args += ["-optimize", optimize]
        args += self._optional_number(parameters, "MAX_ERROR", context,
                                      "-max_error", False)
        args += self._optional_number(parameters, "MAX_POINTS", context,
                                      "-max_points", True)
        args += self._optional_number(parameters, "MAX_TRIANGLES", context,
                                      "-max_triangles", True)
        args += self._optional_number(parameters, "PERCENT", context,
                                      "-percent", False)
        args += self._optional_number(parameters, "TILE_SIZE", context,
                                      "-tile_size", True)
        args += self._optional_number(parameters, "THREADS", context,
                                      "-threads", True)
        args += self._optional_number(parameters, "SEED", context, "-seed",
                                      True)
        crs = self.parameterAsCrs(parameters, "T_SRS", context)
        if crs.isValid():
            args += ["-t_srs", crs.authid() or crs.toWkt()]
        args += _format_args(out)
        if (os.path.splitext(out)[1].lower() in (".fgb", ".geojson") and
                "-layers" not in [str(a).lower() for a in args]):
            args += ["-layers", "triangles"]  # a file of one layer
        args += ["-overwrite", dem, out]
        rc, summary = runner.run(args, feedback)
        prefix = _nln(args)
        figures = _summary_figures(summary)
        figures.update(_run_parameters(out, prefix))
        results = {"OUTPUT": out, "TRIANGLES": _tin_triangles(out, prefix)}
        results.update(figures)
        if self.parameterAsBoolean(parameters, "LOAD", context):
            _load_tin(out, context, os.path.splitext(
                os.path.basename(out))[0], "OUTPUT", prefix)
        return results


def _summary_figures(lines):
    """The counts and errors of simplify's summary (the figures of an
    output without a run_parameters layer: mesh files)."""
    figures = {}
    for line in lines:
        m = re.search(r"(\d+) vertices .*?(\d+) triangles", line)
        if line.startswith("output:") and m:
            figures["VERTEX_COUNT"] = int(m.group(1))
            figures["TRIANGLE_COUNT"] = int(m.group(2))
        m = re.search(r"max ([-0-9.eE+]+).*RMS ([-0-9.eE+]+)", line)
        if line.startswith("error:") and m:
            figures["MAX_ERROR_ACHIEVED"] = float(m.group(1))
            figures["RMSE"] = float(m.group(2))
    return figures


def _run_parameters(path, prefix=""):
    """The figures of the run_parameters layer, in full precision, when the
    output has it."""
    ext = os.path.splitext(path)[1].lower()
    if ext in (".gpkg", ".sqlite"):
        source = path + "|layername=%srun_parameters" % prefix
    elif ext == ".shp":
        source = path[:-4] + "_%srun_parameters.dbf" % prefix
    else:
        return {}
    layer = QgsVectorLayer(source, "run_parameters", "ogr")
    if not layer.isValid():
        return {}
    for f in layer.getFeatures():
        return {"VERTEX_COUNT": int(f["vertices"]),
                "TRIANGLE_COUNT": int(f["triangles"]),
                "MAX_ERROR_ACHIEVED": float(f["ach_max"]),
                "RMSE": float(f["ach_rmse"])}
    return {}


class EvalAlgorithm(TerratinAlgorithm):
    COMMAND = "eval"
    HELP = (
        "<p>Measures a TIN (from terratin or any other tool) against the "
        "DEM: a layer of triangles (POLYGON Z, TIN, ...; any format OGR "
        "reads) or a mesh layer (2DM, PLY, UGRID; STL, OBJ and LandXML, "
        "which QGIS does not open, through the command line). A TIN "
        "in another CRS is reprojected to the DEM's. The error |DEM - TIN| "
        "over every valid sample (max, RMS, mean and total absolute, L2, "
        "where the max is) and the coverage (samples covered, uncovered, "
        "overlapped; polygons that are not triangles). Every figure is an "
        "output a model can use.</p>"
        "<p><b>Check against</b>: a max error the TIN must meet; the "
        "output PASS says whether it does (the run does not fail).</p>"
        "<p><b>Error raster</b>: TIN - DEM on the DEM's grid, a GeoTIFF "
        "(NaN outside the TIN).</p>")

    FIGURES = (("MAX_ERROR", "max_error", "Max error"),
               ("RMSE", "rmse", "RMS error"),
               ("MEAN_ABS_ERROR", "mean_abs_error", "Mean absolute error"),
               ("TOTAL_ABS_ERROR", "total_abs_error",
                "Total absolute error"),
               ("L2", "l2", "L2 error"),
               ("TRIANGLE_COUNT", "triangles", "Triangles"),
               ("REJECTED", "rejected", "Polygons rejected (not triangles)"),
               ("DEGENERATE", "degenerate", "Degenerate triangles"),
               ("VALID_SAMPLES", "valid_samples", "Valid samples"),
               ("COVERED", "covered", "Samples covered"),
               ("UNCOVERED", "uncovered", "Samples uncovered"),
               ("OVERLAPPED", "overlapped", "Samples overlapped"))

    def name(self):
        return "eval"

    def displayName(self):
        return "Measure TIN against DEM"

    def initAlgorithm(self, config=None):
        self.addParameter(QgsProcessingParameterRasterLayer("DEM", "DEM"))
        self.addParameter(QgsProcessingParameterMapLayer(
            "TIN", "TIN (a layer of triangles or a mesh)", None, False,
            [QgsProcessing.TypeVectorPolygon, QgsProcessing.TypeMesh]))
        self._add_dem_options("DEM")
        p = QgsProcessingParameterEnum(
            "TIN_FRAME", "The TIN's coordinates", TIN_FRAMES, False, 0, True)
        p.setFlags(p.flags() | p.FlagAdvanced)
        self.addParameter(p)
        p = QgsProcessingParameterString(
            "TIN_TRANSFORM", "Transform of the TIN's corners first: "
            "SX,SY,SZ,OX,OY,OZ (x' = SX x + OX, ...)", None, False, True)
        p.setFlags(p.flags() | p.FlagAdvanced)
        self.addParameter(p)
        self.addParameter(QgsProcessingParameterNumber(
            "CHECK_MAX_ERROR", "Check against max error (empty: no check)",
            QgsProcessingParameterNumber.Double, None, True, 0.0))
        self.addParameter(QgsProcessingParameterRasterDestination(
            "ERROR_RASTER", "Error raster (TIN - DEM, GeoTIFF)", None, True,
            False))
        for name, _, desc in self.FIGURES:
            self.addOutput(QgsProcessingOutputNumber(name, desc))
        self.addOutput(QgsProcessingOutputNumber("MAX_ERROR_X",
                                                 "Max error at x"))
        self.addOutput(QgsProcessingOutputNumber("MAX_ERROR_Y",
                                                 "Max error at y"))
        self.addOutput(QgsProcessingOutputBoolean(
            "PASS", "Within the max error checked"))
        self.addOutput(QgsProcessingOutputString("Z_UNIT", "Height unit"))

    def processAlgorithm(self, parameters, context, feedback):
        dem = _raster_path(self, parameters, "DEM", context)
        tin, layer = _eval_tin_source(self, parameters, "TIN", context)
        args = ["eval", dem, tin] + self._dem_args(parameters, context)
        if layer:
            args += ["-layer", layer]
        frame = self.parameterAsEnum(parameters, "TIN_FRAME", context)
        if frame:
            args += ["-tin_frame", TIN_FRAMES[frame].split(" ")[0]]
        transform = (self.parameterAsString(parameters, "TIN_TRANSFORM",
                                            context) or "").replace(" ", "")
        if transform:
            args += ["-tin_transform", transform]
        args += self._optional_number(parameters, "CHECK_MAX_ERROR",
                                      context, "-max_error", False)
        raster = None
        if parameters.get("ERROR_RASTER") not in (None, ""):
            raster = self.parameterAsOutputLayer(parameters, "ERROR_RASTER",
                                                 context)
        if raster:
            if os.path.splitext(raster)[1].lower() not in (".tif", ".tiff"):
                raise QgsProcessingException(
                    "ERROR_RASTER: %s: the error raster is a GeoTIFF "
                    "(.tif)" % raster)
            _output_folder(raster)
            args += ["-error_raster", raster, "-overwrite"]
        rc, obj = runner.run_json(args, feedback)
        results = {name: obj.get(key) for name, key, _ in self.FIGURES}
        at = obj.get("max_error_at") or {}
        results["MAX_ERROR_X"] = at.get("x")
        results["MAX_ERROR_Y"] = at.get("y")
        results["PASS"] = rc == 0
        results["Z_UNIT"] = obj.get("z_unit") or ""
        if rc == 3:
            feedback.pushWarning(
                "the max error %s exceeds %s" % (obj.get("max_error"),
                                                 obj.get("threshold")))
        if raster:
            results["ERROR_RASTER"] = raster
        return results


class RasterizeAlgorithm(TerratinAlgorithm):
    COMMAND = "rasterize"
    HELP = (
        "<p>Writes the surface of a layer of triangles on the grid of the "
        "DEM: at every sample centre in a triangle, the linear "
        "interpolation of its corners' heights; nodata (NaN) outside the "
        "TIN. One band, the DEM's size, geotransform and CRS; the driver "
        "is the one the output's extension names (GeoTIFF otherwise).</p>"
        "<p>The samples covered and the error against the DEM (as "
        "'Measure TIN against DEM' measures it) are outputs.</p>")

    def name(self):
        return "rasterize"

    def displayName(self):
        return "Rasterize TIN"

    def initAlgorithm(self, config=None):
        self.addParameter(QgsProcessingParameterVectorLayer(
            "TIN", "TIN (triangles)", [QgsProcessing.TypeVectorPolygon]))
        self.addParameter(QgsProcessingParameterRasterLayer(
            "DEM", "DEM (the grid)"))
        self._add_dem_options("DEM")
        self.addParameter(QgsProcessingParameterRasterDestination(
            "OUTPUT", "Surface raster"))
        for name, desc in (("COVERED", "Samples covered"),
                           ("MAX_ERROR", "Max error against the DEM"),
                           ("RMSE", "RMS error against the DEM"),
                           ("TRIANGLE_COUNT", "Triangles")):
            self.addOutput(QgsProcessingOutputNumber(name, desc))

    def processAlgorithm(self, parameters, context, feedback):
        tin, layer = _tin_source(self, parameters, "TIN", context)
        dem = _raster_path(self, parameters, "DEM", context)
        out = self.parameterAsOutputLayer(parameters, "OUTPUT", context)
        _output_folder(out)
        # rasterize TIN DEM OUTPUT; a terratin whose usage says DEM TIN
        # OUTPUT gets them in that order
        if re.search(r"rasterize\s+DEM\s+TIN", runner.usage_of("rasterize")):
            args = ["rasterize", dem, tin, out]
        else:
            args = ["rasterize", tin, dem, out]
        args += self._dem_args(parameters, context)
        if layer:
            args += ["-layer", layer]
        args += ["-overwrite"]
        rc, obj = runner.run_json(args, feedback)
        return {"OUTPUT": out, "COVERED": obj.get("covered"),
                "MAX_ERROR": obj.get("max_error"), "RMSE": obj.get("rmse"),
                "TRIANGLE_COUNT": obj.get("triangles")}


class OptimizeAlgorithm(TerratinAlgorithm):
    COMMAND = "optimize"
    HELP = (
        "<p>Keeps a TIN's vertices (DEM samples) and outline and "
        "re-triangulates it for a criterion, never letting an error pass "
        "the bound (default: the input TIN's own max error, which thus "
        "never grows). Writes the layers simplify writes.</p>"
        "<p>The errors before and after are outputs.</p>")

    def name(self):
        return "optimize"

    def displayName(self):
        return "Re-optimise a TIN"

    def initAlgorithm(self, config=None):
        self.addParameter(QgsProcessingParameterRasterLayer("DEM", "DEM"))
        self.addParameter(QgsProcessingParameterVectorLayer(
            "TIN", "TIN (triangles)", [QgsProcessing.TypeVectorPolygon]))
        self._add_dem_options("DEM")
        self.addParameter(QgsProcessingParameterEnum(
            "CRITERION", "Criterion", CRITERIA, False, 0, True))
        self.addParameter(QgsProcessingParameterEnum(
            "OPTIMIZE", "Optimiser", OPTIMIZERS[1:5], False, 0, True))
        self.addParameter(QgsProcessingParameterNumber(
            "MAX_ERROR", "Max error bound (empty: the input's own)",
            QgsProcessingParameterNumber.Double, None, True, 0.0))
        p = QgsProcessingParameterNumber(
            "SEED", "Random seed (annealing)",
            QgsProcessingParameterNumber.Integer, None, True, 0)
        p.setFlags(p.flags() | p.FlagAdvanced)
        self.addParameter(p)
        self.addParameter(QgsProcessingParameterFileDestination(
            "OUTPUT", "Optimised TIN", OPTIMIZE_FILTER))
        self.addParameter(QgsProcessingParameterBoolean(
            "LOAD", "Load the result", True, True))
        self.addOutput(QgsProcessingOutputVectorLayer(
            "TRIANGLES", "Triangles layer (vector outputs)",
            QgsProcessing.TypeVectorPolygon))
        for name, desc in (("VERTEX_COUNT", "Vertices"),
                           ("TRIANGLE_COUNT", "Triangles"),
                           ("MAX_ERROR_BEFORE", "Max error before"),
                           ("MAX_ERROR_AFTER", "Max error after"),
                           ("RMSE_BEFORE", "RMS error before"),
                           ("RMSE_AFTER", "RMS error after"),
                           ("MEAN_ABS_ERROR_BEFORE", "Mean abs error before"),
                           ("MEAN_ABS_ERROR_AFTER", "Mean abs error after"),
                           ("L2_BEFORE", "L2 error before"),
                           ("L2_AFTER", "L2 error after")):
            self.addOutput(QgsProcessingOutputNumber(name, desc))

    def processAlgorithm(self, parameters, context, feedback):
        dem = _raster_path(self, parameters, "DEM", context)
        tin, layer = _tin_source(self, parameters, "TIN", context)
        out = self.parameterAsFileOutput(parameters, "OUTPUT", context)
        if os.path.splitext(out)[1].lower() not in OPTIMIZE_EXTS:
            raise QgsProcessingException(
                "OUTPUT: %s: optimize writes a GeoPackage, a Shapefile or "
                "an SQLite file (.gpkg, .shp, .sqlite)" % out)
        _output_folder(out)
        args = ["optimize", dem, tin, out] + self._dem_args(parameters,
                                                            context)
        if layer:
            args += ["-layer", layer]
        criterion = CRITERIA[self.parameterAsEnum(parameters, "CRITERION",
                                                  context)]
        args += ["-criterion", criterion, "-optimize", OPTIMIZERS[
            1 + self.parameterAsEnum(parameters, "OPTIMIZE", context)]]
        args += self._optional_number(parameters, "MAX_ERROR", context,
                                      "-max_error", False)
        args += self._optional_number(parameters, "SEED", context, "-seed",
                                      True)
        args += ["-overwrite"]
        rc, obj = runner.run_json(args, feedback)
        before, after = obj.get("before") or {}, obj.get("after") or {}
        prefix = _nln(args)
        results = {"OUTPUT": out, "TRIANGLES": _tin_triangles(out, prefix),
                   "VERTEX_COUNT": obj.get("vertices"),
                   "TRIANGLE_COUNT": obj.get("triangles")}
        for key, name in (("max_error", "MAX_ERROR"), ("rmse", "RMSE"),
                          ("mean_abs_error", "MEAN_ABS_ERROR"),
                          ("l2", "L2")):
            results[name + "_BEFORE"] = before.get(key)
            results[name + "_AFTER"] = after.get(key)
        if self.parameterAsBoolean(parameters, "LOAD", context):
            _load_tin(out, context, os.path.splitext(
                os.path.basename(out))[0], "OUTPUT", prefix)
        return results


class StudyAlgorithm(TerratinAlgorithm):
    COMMAND = "study"
    HELP = (
        "<p>Compares criteria (and methods, optimisers) over terrains: "
        "every terrain x method x optimiser x checkpoint x criterion run as "
        "'Simplify DEM to TIN' with a percent would run it. Terrains: DEM "
        "layers and/or the study's generated terrains.</p>"
        "<p>Writes into the output folder curves.csv (a row per run: "
        "points, max error, L2, RMS, mean and total absolute error), "
        "tables.md (the mean absolute error per percentage and criterion) "
        "and runs.json; with 'Plots', plots/*.png (needs Python 3 with "
        "matplotlib). curves.csv is loaded as a table.</p>")

    def name(self):
        return "study"

    def displayName(self):
        return "Compare criteria"

    def initAlgorithm(self, config=None):
        self.addParameter(QgsProcessingParameterMultipleLayers(
            "TERRAINS", "DEMs", QgsProcessing.TypeRaster, None, True))
        self.addParameter(QgsProcessingParameterEnum(
            "GENERATED", "Generated terrains", STUDY_TERRAINS, True, None,
            True))
        self.addParameter(QgsProcessingParameterEnum(
            "CRITERIA", "Criteria (none: all)", CRITERIA, True, None, True))
        self.addParameter(QgsProcessingParameterEnum(
            "METHODS", "Methods (none: insert)", METHODS, True, None, True))
        self.addParameter(QgsProcessingParameterEnum(
            "OPTIMIZERS", "Optimisers (none: each criterion's default)",
            ["auto"] + OPTIMIZERS[1:], True, None, True))
        self.addParameter(QgsProcessingParameterString(
            "PERCENT", "Checkpoints, % of the valid samples (comma "
            "separated)", "1,10,25,50", False, True))
        self.addParameter(QgsProcessingParameterNumber(
            "POINTS", "Curves up to N points (empty: none)",
            QgsProcessingParameterNumber.Integer, None, True, 1))
        p = QgsProcessingParameterNumber(
            "SEED", "Seed of the generated terrains",
            QgsProcessingParameterNumber.Integer, None, True, 0)
        p.setFlags(p.flags() | p.FlagAdvanced)
        self.addParameter(p)
        self.addParameter(QgsProcessingParameterBoolean(
            "PLOT", "Plots (PNG, needs matplotlib)", False, True))
        self._add_extra()
        self.addParameter(QgsProcessingParameterFolderDestination(
            "OUTPUT", "Output folder"))
        self.addOutput(QgsProcessingOutputFile("CURVES", "curves.csv"))
        self.addOutput(QgsProcessingOutputFile("TABLES", "tables.md"))
        self.addOutput(QgsProcessingOutputFolder("PLOTS", "Plots folder"))
        self.addOutput(QgsProcessingOutputNumber("RUNS", "Runs"))

    def _chosen(self, parameters, name, context):
        """The values chosen of a multiple enum; none when not given
        (parameterAsEnums gives the first value then)."""
        if parameters.get(name) in (None, "", []):
            return []
        return self.parameterAsEnums(parameters, name, context)

    def processAlgorithm(self, parameters, context, feedback):
        out = self.parameterAsString(parameters, "OUTPUT", context)
        if not out or out == QgsProcessing.TEMPORARY_OUTPUT:
            out = self.parameterAsFileOutput(parameters, "OUTPUT", context)
        args = ["study"]
        for layer in self.parameterAsLayerList(parameters, "TERRAINS",
                                               context):
            args += ["-terrain", layer.source()]
        for i in self._chosen(parameters, "GENERATED", context):
            args += ["-terrain", STUDY_TERRAINS[i]]
        if "-terrain" not in args:
            raise QgsProcessingException(
                "TERRAINS: give at least one DEM or generated terrain")
        for name, option, values in (
                ("CRITERIA", "-criteria", CRITERIA),
                ("METHODS", "-methods", METHODS),
                ("OPTIMIZERS", "-optimizers", ["auto"] + OPTIMIZERS[1:])):
            chosen = self._chosen(parameters, name, context)
            if chosen:
                args += [option, ",".join(values[i] for i in chosen)]
        percent = (self.parameterAsString(parameters, "PERCENT", context)
                   or "").replace(" ", "")
        points = self._optional_number(parameters, "POINTS", context,
                                       "-points", True)
        if percent and not (points and parameters.get("PERCENT") is None):
            args += ["-percent", percent]
        args += points
        args += self._optional_number(parameters, "SEED", context, "-seed",
                                      True)
        if self.parameterAsBoolean(parameters, "PLOT", context):
            args += ["-plot"]
        args += self._extra_args(parameters, context)
        args += ["-overwrite", out]
        rc, summary = runner.run(args, feedback)
        curves = os.path.join(out, "curves.csv")
        with open(curves, newline="") as f:
            runs = sum(1 for _ in csv.DictReader(f))
        table = QgsVectorLayer(curves, "curves", "ogr")
        if table.isValid() and context is not None:
            context.temporaryLayerStore().addMapLayer(table)
            context.addLayerToLoadOnCompletion(
                table.id(), QgsProcessingContext.LayerDetails(
                    "study curves", context.project(), "CURVES"))
        return {"OUTPUT": out, "CURVES": curves,
                "TABLES": os.path.join(out, "tables.md"),
                "PLOTS": os.path.join(out, "plots"), "RUNS": runs}
