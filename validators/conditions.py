"""Sample-condition checks (Section 3 of the paper), Euclidean local form.

:func:`local_delaunay` approximates the intrinsic Delaunay triangulation
DT_M around each sample by the Delaunay triangulation of its k nearest
samples projected onto their best-fit (PCA) tangent plane, and measures
Condition III: the degree of each sample (III-i, at most 33) and, for every
triangle at the sample, the ratio of its second-longest to its longest edge
(III-ii: below √3/2, the two shorter edges both shorter than √3/2 of the
longest).  Near a sharp edge the projection flattens a fold, so the figures
there are an approximation; the geodesic version on a ground-truth surface
belongs to the validators issue.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial import Delaunay, QhullError, cKDTree

SQRT3_2 = float(np.sqrt(3.0) / 2.0)


@dataclass(frozen=True)
class LocalDelaunay:
    """Per-sample Condition III figures.

    Attributes
    ----------
    degree : (n,) int64
        Neighbours of each sample in its local Delaunay triangulation.
    worst_ratio : (n,) float64
        Largest (second-longest / longest edge) over the sample's triangles;
        NaN where the neighbourhood could not be triangulated.
    """

    degree: np.ndarray
    worst_ratio: np.ndarray

    @property
    def max_degree(self) -> int:
        """The largest degree (Condition III-i wants at most 33)."""
        return int(self.degree.max()) if self.degree.size else 0

    @property
    def max_ratio(self) -> float:
        """The worst ratio (Condition III-ii wants below √3/2 ≈ 0.866)."""
        finite = self.worst_ratio[np.isfinite(self.worst_ratio)]
        return float(finite.max()) if finite.size else float("nan")

    def violations(self) -> np.ndarray:
        """Samples breaking III-i or III-ii."""
        bad = (self.degree > 33) | ~(self.worst_ratio < SQRT3_2)
        return np.flatnonzero(bad)


def local_delaunay(points, k: int = 12) -> LocalDelaunay:
    """Local tangent-plane Delaunay figures for Condition III at every sample.

    Parameters
    ----------
    points : (n, 3) array_like of float
        The samples.
    k : int
        Neighbours used for the tangent plane and the local triangulation.

    Returns
    -------
    LocalDelaunay

    Examples
    --------
    >>> import numpy as np
    >>> g = np.stack(np.meshgrid(np.arange(6.0), np.arange(6.0), [0.0]), -1).reshape(-1, 3)
    >>> ld = local_delaunay(g + np.random.default_rng(0).normal(0, 1e-3, g.shape))
    >>> round(float(ld.worst_ratio[14]), 2)  # right isosceles triangles: 1/sqrt(2)
    0.71
    """
    pts = np.asarray(points, dtype=np.float64)
    if pts.ndim != 2 or pts.shape[1] != 3:
        raise ValueError(f"points must have shape (n, 3), got {pts.shape}")
    n = pts.shape[0]
    if not 3 <= k < n:
        raise ValueError(f"k must be within [3, {n - 1}], got {k}")
    _, nb = cKDTree(pts).query(pts, k + 1)
    degree = np.zeros(n, dtype=np.int64)
    worst = np.full(n, np.nan)
    for u in range(n):
        q = pts[nb[u]]
        c = q - q.mean(axis=0)
        _, _, vt = np.linalg.svd(c, full_matrices=False)
        uv = c @ vt[:2].T
        try:
            tri = Delaunay(uv)
        except QhullError:
            continue
        simp = tri.simplices[(tri.simplices == 0).any(axis=1)]
        if simp.size == 0:
            continue
        degree[u] = np.unique(simp[simp != 0]).shape[0]
        p = q[simp]
        e = np.stack(
            [
                np.linalg.norm(p[:, 0] - p[:, 1], axis=1),
                np.linalg.norm(p[:, 1] - p[:, 2], axis=1),
                np.linalg.norm(p[:, 2] - p[:, 0], axis=1),
            ],
            axis=1,
        )
        e.sort(axis=1)
        worst[u] = float((e[:, 1] / e[:, 2]).max())
    return LocalDelaunay(degree=degree, worst_ratio=worst)
