"""The PyVista inspector of sr33 reconstructions (``sr33 view``).

PyVista is imported through :mod:`gui._pv` only.
"""

from .inspector import COLOURS, LAYERS, Inspector, InspectorState

__all__ = ["COLOURS", "LAYERS", "Inspector", "InspectorState"]
