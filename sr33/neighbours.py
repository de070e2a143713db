"""k nearest neighbours with their ties, for the reconstruction's N(u; k)
(:func:`sr33.rng.k_neighbourhoods`) and the validators' Condition II-i
(:func:`sr33.validators.conditions.neighbourhood_reach`): one rule, so that
both read the same neighbourhood whatever the samples' order."""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree


def tied_neighbours(
    points: np.ndarray, k: int, rtol: float, tree: cKDTree | None = None
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Each point, its k nearest others and every point tied with the k-th.

    A point within ``(1 + rtol)`` times the k-th distance ties with it and
    joins (the tie rule of :mod:`sr33.tolerance`); the query widens until no
    tie is left out.

    Parameters
    ----------
    points : (n, 3) float64
        Distinct points (the point itself is then the first of its row).
    k : int
        ``1 <= k < n``.
    rtol : float
    tree : cKDTree, optional
        The points' tree, when the caller has one.

    Returns
    -------
    kth : (n,) float64
        Each point's distance to its k-th nearest other point.
    indptr : (n + 1,) int64
    indices : (m,) int64
        Row u of the CSR pair: u and its neighbours, nearest first.
    """
    n = points.shape[0]
    tree = cKDTree(points) if tree is None else tree
    q = min(n, k + 1 + 16)
    while True:
        dist, idx = tree.query(points, q)
        limit = dist[:, k] * (1.0 + rtol)
        keep = dist <= limit[:, None]
        if q == n or not keep[:, -1].any():
            break
        q = min(n, 2 * q)
    indptr = np.zeros(n + 1, dtype=np.int64)
    np.cumsum(keep.sum(axis=1), out=indptr[1:])
    return dist[:, k], indptr, idx[keep].astype(np.int64)
