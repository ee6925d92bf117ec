"""The terratin Processing provider: its algorithms and its one setting,
the terratin executable (empty: the one found on PATH)."""
from qgis.core import QgsProcessingProvider
from processing.core.ProcessingConfig import ProcessingConfig, Setting

from . import runner
from .algorithms import (SimplifyAlgorithm, EvalAlgorithm,
                         RasterizeAlgorithm, OptimizeAlgorithm,
                         StudyAlgorithm)


class TerratinProvider(QgsProcessingProvider):
    def id(self):
        return "terratin"

    def name(self):
        return "terratin"

    def longName(self):
        version = runner.installed_version()
        return "terratin %s" % version if version else "terratin"

    def load(self):
        ProcessingConfig.settingIcons[self.name()] = self.icon()
        ProcessingConfig.addSetting(Setting(
            self.name(), runner.SETTING_PATH,
            "terratin executable (empty: the one on PATH)", "",
            valuetype=Setting.FILE))
        ProcessingConfig.readSettings()
        self.refreshAlgorithms()
        return True

    def unload(self):
        ProcessingConfig.removeSetting(runner.SETTING_PATH)

    def loadAlgorithms(self):
        for alg in (SimplifyAlgorithm(), EvalAlgorithm(),
                    RasterizeAlgorithm(), OptimizeAlgorithm(),
                    StudyAlgorithm()):
            self.addAlgorithm(alg)
