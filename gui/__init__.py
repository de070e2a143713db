"""The PyVista inspector of sr33 reconstructions (``sr33 view``).

PyVista is imported through :mod:`sr33.gui._pv` only.
"""

if __name__ != "sr33.gui":  # the folder installs as sr33.gui (pyproject.toml)
    raise ImportError(f"this folder is sr33.gui; import it by that name, not {__name__}")

from ._pv import has_display, pyvista  # noqa: E402
from .inspector import (  # noqa: E402
    COLOURS,
    LAYERS,
    Inspector,
    InspectorState,
    mesh_as_reconstruction,
)

__all__ = [
    "COLOURS",
    "LAYERS",
    "Inspector",
    "InspectorState",
    "has_display",
    "mesh_as_reconstruction",
    "pyvista",
]
