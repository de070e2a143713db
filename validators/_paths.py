"""numba kernel of the sample conditions (:mod:`sr33.validators.conditions`):
shortest paths from every sample to its own neighbourhood, cut off at a
length.

One bounded Dijkstra per source over a weighted graph in CSR form; it stops
when every target of the source is settled or nothing within the limit is
left, so that its cost is that of the source's neighbourhood, not of the
graph (scipy's ``csgraph.dijkstra`` returns a dense sources × vertices
matrix: 288 MB for 6,000 samples).
"""

from __future__ import annotations

import heapq

import numpy as np

from sr33.jit import njit


@njit(cache=True)
def bounded_paths(indptr, indices, weights, sources, limits, targets_ptr, targets):
    """Shortest-path length from ``sources[s]`` to each of its targets
    ``targets[targets_ptr[s]:targets_ptr[s + 1]]``, inf where it exceeds
    ``limits[s]``.

    Parameters
    ----------
    indptr, indices : (V + 1,), (E,) int64
        The graph's adjacency (CSR, both directions of every edge).
    weights : (E,) float64
        Non-negative edge lengths.
    sources : (s,) int64
    limits : (s,) float64
    targets_ptr : (s + 1,) int64
    targets : (t,) int64

    Returns
    -------
    (t,) float64
    """
    nv = indptr.shape[0] - 1
    dist = np.full(nv, np.inf)
    want = np.full(nv, -1, np.int64)
    out = np.full(targets.shape[0], np.inf)
    touched = np.empty(nv, np.int64)
    for s in range(sources.shape[0]):
        remaining = 0
        for t in range(targets_ptr[s], targets_ptr[s + 1]):
            if want[targets[t]] != s:
                want[targets[t]] = s
                remaining += 1
        src = sources[s]
        lim = limits[s]
        dist[src] = 0.0
        touched[0] = src
        nt = 1
        heap = [(0.0, src)]
        while len(heap):
            d, v = heapq.heappop(heap)
            if d > dist[v]:
                continue
            if want[v] == s:
                want[v] = -1
                remaining -= 1
                if remaining == 0:
                    break
            for j in range(indptr[v], indptr[v + 1]):
                w = indices[j]
                nd = d + weights[j]
                if nd <= lim and nd < dist[w]:
                    if dist[w] == np.inf:
                        touched[nt] = w
                        nt += 1
                    dist[w] = nd
                    heapq.heappush(heap, (nd, w))
        for t in range(targets_ptr[s], targets_ptr[s + 1]):
            out[t] = dist[targets[t]]
            want[targets[t]] = -1
        for i in range(nt):
            dist[touched[i]] = np.inf
    return out
