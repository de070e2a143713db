"""Numba kernel grouping the sides of faces by their undirected edge
(:func:`sr33.mesh.edge_incidence`).

The order is the one of a stable sort of the keys ``min * n + max``: by the
smaller vertex (a counting sort, stable), then within each vertex's group
by the larger one (an insertion sort, stable: the groups are a vertex's
edges).  Linear in the number of sides where ``np.argsort`` of the keys is
not, and without numpy's temporaries (the truth meshes the validators
refine reach millions of triangles).
"""

from __future__ import annotations

import numpy as np

from .jit import njit


@njit(cache=True, nogil=True)
def group_sides(lo, hi, n):
    """Stable order of the sides by (lo, hi), each side's edge, and where
    each edge's sides begin in that order.

    Parameters
    ----------
    lo, hi : (h,) int64
        The smaller and the larger vertex of every side, ``0 <= lo <= hi < n``.
    n : int
        Number of vertices.

    Returns
    -------
    order : (h,) int64
    edge_of : (h,) int64
    start : (e,) int64
    """
    h = lo.shape[0]
    first = np.zeros(n + 1, dtype=np.int64)
    for i in range(h):
        first[lo[i] + 1] += 1
    for v in range(n):
        first[v + 1] += first[v]
    pos = first[:n].copy()
    order = np.empty(h, dtype=np.int64)
    for i in range(h):
        order[pos[lo[i]]] = i
        pos[lo[i]] += 1
    for v in range(n):
        a = first[v]
        for j in range(a + 1, first[v + 1]):
            x = order[j]
            key = hi[x]
            k = j - 1
            while k >= a and hi[order[k]] > key:
                order[k + 1] = order[k]
                k -= 1
            order[k + 1] = x
    edge_of = np.empty(h, dtype=np.int64)
    start = np.empty(h, dtype=np.int64)
    e = -1
    for j in range(h):
        x = order[j]
        if j == 0 or lo[x] != lo[order[j - 1]] or hi[x] != hi[order[j - 1]]:
            e += 1
            start[e] = j
        edge_of[x] = e
    return order, edge_of, start[: e + 1].copy()
