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


def check_homeomorphism(shape, points: np.ndarray, spacing: float, rec) -> None:
    """The homeomorphism guarantee: same signature as the shape, no open or
    overloaded edges beyond the shape's boundary, disjoint interiors, every
    sample used, Hausdorff distance to the truth at most h."""
    from sr33.validators import mesh_stats
    from sr33.validators.fidelity import hausdorff
    from sr33.validators.intersections import self_intersections
    from sr33.validators.signature import homeomorphic, signature

    sig = signature(rec.triangles, rec.vertices.shape[0], points=rec.vertices)
    truth = signature(shape.truth_triangles, shape.truth_vertices.shape[0])
    verdict = homeomorphic(sig, truth)
    assert verdict, verdict.reasons
    st_ = mesh_stats(rec.triangles, rec.vertices.shape[0])
    assert st_.overloaded_edges == 0, f"{st_.overloaded_edges} overloaded edges"
    assert st_.used_vertices == points.shape[0], (
        f"{st_.used_vertices} of {points.shape[0]} samples used"
    )
    crossing = self_intersections(rec.vertices, rec.triangles).shape[0]
    assert crossing == 0, f"{crossing} crossing triangle pairs"
    fid = hausdorff(
        rec.vertices, rec.triangles, shape.truth_vertices, shape.truth_triangles, samples=2000
    )
    assert fid.hausdorff <= spacing, f"Hausdorff {fid.hausdorff / spacing:.2f} h"
