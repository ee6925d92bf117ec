"""The plugin object QGIS loads: it only registers the Processing provider
(initProcessing is what QGIS calls for plugins with hasProcessingProvider,
also in qgis_process)."""
from qgis.core import QgsApplication

from .provider import TerratinProvider


class TerratinPlugin:
    def __init__(self, iface):
        self.iface = iface
        self.provider = None

    def initProcessing(self):
        if self.provider is None:
            self.provider = TerratinProvider()
            QgsApplication.processingRegistry().addProvider(self.provider)

    def initGui(self):
        self.initProcessing()

    def unload(self):
        if self.provider is not None:
            QgsApplication.processingRegistry().removeProvider(self.provider)
            self.provider = None
