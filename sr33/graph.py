"""Small graph helpers shared by the steps: CSR adjacency and edge lookup."""

from __future__ import annotations

import numpy as np
from scipy import sparse

from .mesh import edge_keys


def adjacency(edges: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray]:
    """Symmetric CSR adjacency ``(indptr, indices)`` with sorted rows."""
    m = edges.shape[0]
    data = np.ones(2 * m, dtype=np.int8)
    rows = np.concatenate([edges[:, 0], edges[:, 1]])
    cols = np.concatenate([edges[:, 1], edges[:, 0]])
    a = sparse.csr_matrix((data, (rows, cols)), shape=(n, n))
    a.sort_indices()
    return a.indptr.astype(np.int64), a.indices.astype(np.int64)


def cycle_edges(offsets: np.ndarray, vertices: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The consecutive vertex pairs of every cycle, and the cycle of each pair."""
    lengths = np.diff(offsets)
    owner = np.repeat(np.arange(lengths.shape[0]), lengths)
    nxt = np.arange(vertices.shape[0]) + 1
    nxt[offsets[1:] - 1] = offsets[:-1]
    return np.stack([vertices, vertices[nxt]], axis=1), owner


def lookup_edges(edges: np.ndarray, pairs: np.ndarray, n: int) -> np.ndarray:
    """Row index in sorted ``edges`` of each pair, or -1 where absent."""
    keys = edge_keys(edges[:, 0], edges[:, 1], n)
    q = edge_keys(pairs[:, 0], pairs[:, 1], n)
    pos = np.searchsorted(keys, q)
    pos = np.minimum(pos, max(keys.shape[0] - 1, 0))
    found = keys.shape[0] > 0
    ok = (keys[pos] == q) if found else np.zeros(q.shape, bool)
    return np.where(ok, pos, -1)


def link_is_disk(corners: list[tuple[int, int]]) -> bool:
    """True when the corner pairs (prev, next) at a vertex form one path or one cycle.

    The vertex form of the success condition of Algorithm 4 (Section 4): the
    faces round a sample make a disk exactly when their corners there, as
    edges between its neighbours, form one path (a boundary sample) or one
    cycle.  An empty link is not a disk.
    """
    if not corners:
        return False
    deg: dict[int, int] = {}
    adj: dict[int, list[int]] = {}
    for p, q in corners:
        if p == q:
            return False
        deg[p] = deg.get(p, 0) + 1
        deg[q] = deg.get(q, 0) + 1
        adj.setdefault(p, []).append(q)
        adj.setdefault(q, []).append(p)
    if max(deg.values()) > 2:
        return False
    # connected?
    start = next(iter(adj))
    seen = {start}
    stack = [start]
    while stack:
        x = stack.pop()
        for y in adj[x]:
            if y not in seen:
                seen.add(y)
                stack.append(y)
    return len(seen) == len(adj)
