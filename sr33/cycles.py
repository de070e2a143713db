"""TrivialIsometricCycles (Algorithm 3 of the paper, Section 4).

An isometric cycle is one in which, for every two of its vertices, the
shortest path *in the whole graph* (unit edge lengths) has the same length as
the shorter way round the cycle (Section 1.2).  Algorithm 3 keeps the
isometric cycles contained in some N(u; 33k); we bound their *length*
instead (``max_length``, default 8), which is the practical form of the same
smallness: Condition II-iii puts every face cycle of the basis inside one
k-neighbourhood, and Condition II-iv makes every non-trivial isometric cycle
longer than 33k, so a length bound far below 33k keeps every face cycle and
no non-trivial one.  The enumeration is a numba kernel
(:func:`sr33._kernels.isometric_cycles`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import _kernels
from ._validate import InputError, as_edges, check_max_cycle_length
from .graph import adjacency
from .mesh import unique_edges
from .progress import chunks
from .threads import thread_map


@dataclass(frozen=True)
class CycleSet:
    """A collection of vertex cycles in CSR form.

    Attributes
    ----------
    offsets : (c + 1,) int64
        Cycle i is ``vertices[offsets[i]:offsets[i + 1]]``.
    vertices : (offsets[-1],) int64
        Vertex ids; each cycle starts at its smallest vertex and its second
        vertex is smaller than its last (a canonical, order-free form).
    """

    offsets: np.ndarray
    vertices: np.ndarray

    def __len__(self) -> int:
        return self.offsets.shape[0] - 1

    @property
    def lengths(self) -> np.ndarray:
        """(c,) int64 number of vertices of every cycle."""
        return np.diff(self.offsets)

    def used(self, n: int) -> np.ndarray:
        """(n,) bool: which of ``n`` samples some cycle passes through."""
        out = np.zeros(n, dtype=bool)
        out[self.vertices] = True
        return out

    def cycle(self, i: int) -> np.ndarray:
        """The vertices of cycle ``i`` in order."""
        return self.vertices[self.offsets[i] : self.offsets[i + 1]]

    def as_tuples(self) -> list[tuple[int, ...]]:
        """All cycles as tuples (for tests and small inputs)."""
        return [tuple(int(v) for v in self.cycle(i)) for i in range(len(self))]

    def subset(self, keep: np.ndarray) -> CycleSet:
        """The cycles whose indices (or boolean mask) are ``keep``."""
        idx = np.flatnonzero(keep) if np.asarray(keep).dtype == bool else np.asarray(keep)
        lengths = self.lengths[idx]
        offsets = np.zeros(idx.shape[0] + 1, dtype=np.int64)
        np.cumsum(lengths, out=offsets[1:])
        parts = [self.cycle(int(i)) for i in idx]
        verts = np.concatenate(parts) if parts else np.empty(0, np.int64)
        return CycleSet(offsets=offsets, vertices=verts.astype(np.int64))


def concat(*sets: CycleSet) -> CycleSet:
    """The cycles of every set, in the order given."""
    base = np.cumsum([0] + [len(cs.vertices) for cs in sets[:-1]])
    return CycleSet(
        offsets=np.concatenate(
            [np.zeros(1, np.int64)] + [cs.offsets[1:] + b for cs, b in zip(sets, base)]
        ).astype(np.int64),
        vertices=np.concatenate([np.zeros(0, np.int64)] + [cs.vertices for cs in sets]).astype(
            np.int64
        ),
    )


def trivial_isometric_cycles(edges, n_points: int, *, max_length: int = 8) -> CycleSet:
    """TrivialIsometricCycles(RNG, k): Algorithm 3, the small isometric cycles.

    Parameters
    ----------
    edges : (m, 2) array_like of int
        The graph (normally :attr:`LocalizedRNG.edges`).
    n_points : int
        Number of vertices of the graph.
    max_length : int
        Longest cycle kept (at least 3).  See the module docstring for why a
        length bound stands in for the paper's ``⊂ N(u; 33k)`` test.

    Returns
    -------
    CycleSet
        Cycles sorted by (length, vertices).

    Examples
    --------
    >>> from sr33 import trivial_isometric_cycles
    >>> square_with_tail = [(0, 1), (1, 2), (2, 3), (0, 3), (3, 4)]
    >>> trivial_isometric_cycles(square_with_tail, 5).as_tuples()
    [(0, 1, 2, 3)]
    """
    if isinstance(n_points, bool) or not isinstance(n_points, (int, np.integer)) or n_points < 1:
        raise InputError(f"n_points must be a positive integer, got {n_points!r}")
    e = as_edges(edges, int(n_points))
    max_length = check_max_cycle_length(max_length)
    if e.shape[0]:
        e = unique_edges(e)
    indptr, indices = adjacency(e, int(n_points))
    n = int(n_points)
    cs = concat(
        *thread_map(
            lambda r: CycleSet(*_kernels.isometric_cycles(indptr, indices, max_length, *r)),
            chunks(n, 16),  # starts of low index search more: many pieces
        )
    )
    offsets, verts = cs.offsets, cs.vertices
    # canonical order: by length, then lexicographically by vertices
    lengths = cs.lengths
    if len(cs) == 0:
        return cs
    width = int(lengths.max())
    table = np.full((len(cs), width), -1, dtype=np.int64)
    rows = np.repeat(np.arange(len(cs)), lengths)
    cols = np.arange(verts.shape[0]) - np.repeat(offsets[:-1], lengths)
    table[rows, cols] = verts
    order = np.lexsort(tuple(table[:, j] for j in range(width - 1, -1, -1)) + (lengths,))
    return cs.subset(order)
