"""Square-lattice samples of simple sharp surfaces (Figure 1 of the paper).

Exact lattices are the hardest case for tie handling: many sample pairs are
at exactly equal distances.  These generators give the known answer for
unit tests: a planar grid (a disk) and the surface of a cube (a sphere with
8 corners and 12 sharp edges).
"""

from __future__ import annotations

import numpy as np


def grid_lattice(nx: int, ny: int, spacing: float = 1.0) -> np.ndarray:
    """Points of an ``nx`` by ``ny`` planar square grid in the z = 0 plane.

    Row-major: point ``i * ny + j`` is at ``(i, j, 0) * spacing``.

    >>> grid_lattice(2, 3).shape
    (6, 3)
    """
    if nx < 2 or ny < 2:
        raise ValueError(f"grid_lattice needs nx, ny >= 2, got {nx}, {ny}")
    i, j = np.meshgrid(np.arange(nx), np.arange(ny), indexing="ij")
    return np.stack([i.ravel(), j.ravel(), np.zeros(i.size)], axis=1).astype(float) * spacing


def cube_lattice(m: int, spacing: float = 1.0) -> np.ndarray:
    """Lattice points on the surface of the cube ``[0, m]^3`` (spacing apart).

    Every face carries an ``(m+1) x (m+1)`` grid; points on edges and corners
    appear once.  The count is ``6 m^2 + 2``.

    >>> cube_lattice(2).shape
    (26, 3)
    """
    if m < 1:
        raise ValueError(f"cube_lattice needs m >= 1, got {m}")
    r = np.arange(m + 1)
    g = np.stack(np.meshgrid(r, r, r, indexing="ij"), -1).reshape(-1, 3)
    on_surface = ((g == 0) | (g == m)).any(axis=1)
    return g[on_surface].astype(float) * spacing
