"""terratin's QGIS plugin: a Processing provider whose algorithms run the
terratin command (qgis/terratin/provider.py lists them)."""


def classFactory(iface):
    from .plugin import TerratinPlugin
    return TerratinPlugin(iface)
