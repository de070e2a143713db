"""The one place gui/ imports PyVista (and VTK's window choice with no display)."""

from __future__ import annotations

import os


def has_display() -> bool:
    """True when an X or Wayland display is available for an interactive window."""
    return bool(os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"))


def pyvista(off_screen: bool = False):
    """Import PyVista; without a display use VTK's EGL window (no X warning)."""
    if off_screen or not has_display():
        os.environ.setdefault("VTK_DEFAULT_OPENGL_WINDOW", "vtkEGLRenderWindow")
    import pyvista as pv

    if off_screen:
        pv.OFF_SCREEN = True
    return pv
