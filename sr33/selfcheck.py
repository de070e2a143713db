"""Expensive self-checks of the pipeline's own invariants (the ``strict`` switch).

These are not input validation: they verify that the steps kept the promises
of Section 4 (Algorithm 4's invariant, Triangulate's disjoint interiors) on
the result just computed, and raise :class:`InternalError` when they did
not.  ``reconstruct(strict=True)`` runs them; the test suite turns them on
for every reconstruction through the ``SR33_STRICT`` environment variable.
"""

from __future__ import annotations

import os

import numpy as np

from .cycles import CycleSet
from .graph import cycle_edges
from .mesh import unique_edges


class InternalError(RuntimeError):
    """A self-check of sr33 failed: a bug, please report it with the input."""


def strict_default() -> bool:
    """True when the environment variable ``SR33_STRICT`` is set to 1."""
    return os.environ.get("SR33_STRICT", "") == "1"


def check_faces_and_triangles(
    faces: CycleSet,
    triangles: np.ndarray,
    face_of_triangle: np.ndarray,
    centres: dict[int, int] | None = None,
    patched: dict[int, int] | None = None,
) -> None:
    """Edge use <= 2 in the faces and the triangles; L - 2 triangles per face
    (L for a face coned from a centre sample; for a patched face, the
    count its patch gives, ``patched``); the triangles' Euler
    characteristic equals the faces' (a cone adds one vertex, L edges and
    L - 1 faces: no change)."""
    if len(faces) == 0:
        return
    pairs, _ = cycle_edges(faces.offsets, faces.vertices)
    fe, fc = unique_edges(pairs, return_counts=True)
    if fc.max() > 2:
        raise InternalError(f"backtracking invariant broken: an edge is used {fc.max()} times")
    per_face = np.bincount(face_of_triangle, minlength=len(faces))
    want = faces.lengths - 2
    for fi in centres or {}:
        want[fi] += 2
    for fi, count in (patched or {}).items():
        want[fi] = count
    if not np.array_equal(per_face, want):
        raise InternalError("triangulate: a face did not become length - 2 triangles")
    tp = np.concatenate([triangles[:, [0, 1]], triangles[:, [1, 2]], triangles[:, [2, 0]]])
    te, tc = unique_edges(tp, return_counts=True)
    if tc.max() > 2:
        raise InternalError(f"triangulate: an edge is used by {tc.max()} triangles")
    v = np.unique(faces.vertices).shape[0]
    chi_faces = v - fe.shape[0] + len(faces)
    chi_tri = np.unique(triangles).shape[0] - te.shape[0] + triangles.shape[0]
    if chi_faces != chi_tri:
        raise InternalError(
            f"triangulate changed the Euler characteristic from {chi_faces} to {chi_tri}"
        )
