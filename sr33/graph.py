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
