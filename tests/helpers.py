"""Shared test helpers: data paths, triangle sets, relabelling."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

DATA = Path(__file__).resolve().parents[1].parent / "shared" / "datasets"
PAPER_LARGE = DATA / "paper" / "large"
PAPER_SMALL = DATA / "paper" / "small"
MESHES = DATA / "meshes"


def need(path: Path) -> Path:
    """Skip (with the reason) when the shared data set is not beside the repo."""
    if not path.exists():
        pytest.skip(f"shared data set missing: {path}")
    return path


def triangle_set(triangles, labels=None) -> set[tuple[int, ...]]:
    """Orientation-free set of triangles, optionally relabelled by ``labels``."""
    t = np.asarray(triangles)
    if labels is not None:
        t = np.asarray(labels)[t]
    return {tuple(sorted(row)) for row in t.tolist()}


def oriented_triangle_set(triangles, labels=None) -> set[tuple[int, ...]]:
    """Triangles up to cyclic rotation (orientation kept)."""
    t = np.asarray(triangles)
    if labels is not None:
        t = np.asarray(labels)[t]
    out = set()
    for a, b, c in t.tolist():
        m = min(a, b, c)
        out.add((a, b, c) if a == m else (b, c, a) if b == m else (c, a, b))
    return out


def grid_edges(nx: int, ny: int) -> set[tuple[int, int]]:
    """Edges of an nx x ny square grid whose point ``i * ny + j`` is at (i, j)."""
    out = set()
    for i in range(nx):
        for j in range(ny):
            v = i * ny + j
            if i + 1 < nx:
                out.add((v, v + ny))
            if j + 1 < ny:
                out.add((v, v + 1))
    return out
