"""LocalizedRNG (Algorithm 2 of the paper, Section 4).

The union, over every sample u, of the Euclidean relative neighbourhood graph
of the k-neighbourhood N(u; k).  Neighbourhoods come from scipy's cKDTree;
the all-pairs lune test of each neighbourhood is a numba kernel.  Ties are
decided by :mod:`sr33.tolerance` (neighbourhood rule and lune rule), which
makes the edge set independent of input order and invariant under rigid
motions and uniform scaling.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import _kernels
from ._validate import as_points, check_k, check_not_degenerate, check_unique
from .neighbours import tied_neighbours
from .progress import bar, chunks
from .threads import thread_map
from .tolerance import DEFAULT, Tolerance


@dataclass(frozen=True)
class Neighbourhoods:
    """k-neighbourhoods N(u; k) in CSR form.

    Attributes
    ----------
    indptr : (n + 1,) int64
        ``indices[indptr[u]:indptr[u + 1]]`` is N(u; k).
    indices : (nnz,) int64
        Members, u itself first, then by increasing distance.  Each
        neighbourhood holds at least k + 1 samples, more where samples tie
        with the k-th neighbour (tolerance's neighbourhood rule).
    """

    indptr: np.ndarray
    indices: np.ndarray

    def of(self, u: int) -> np.ndarray:
        """The members of N(u; k), u first."""
        return self.indices[self.indptr[u] : self.indptr[u + 1]]


@dataclass(frozen=True)
class LocalizedRNG:
    """Result of :func:`localized_rng`.

    Attributes
    ----------
    edges : (m, 2) int64
        Undirected edges, each row ``(a, b)`` with ``a < b``, rows sorted.
    neighbourhoods : Neighbourhoods
        The N(u; k) the edges were computed on.
    """

    edges: np.ndarray
    neighbourhoods: Neighbourhoods


def k_neighbourhoods(points, k: int, *, tolerance: Tolerance = DEFAULT) -> Neighbourhoods:
    """N(u; k) for every sample, with the tie rule of :mod:`sr33.tolerance`.

    Parameters
    ----------
    points : (n, 3) array_like of float
        Distinct samples.
    k : int
        Neighbourhood size, ``3 <= k < n``.
    tolerance : Tolerance
        ``rtol`` decides which samples tie with the k-th neighbour.

    Returns
    -------
    Neighbourhoods
    """
    pts = as_points(points)
    k = check_k(k, pts.shape[0])
    # samples are distinct, so u (distance 0) is always the first of its row.
    _, indptr, indices = tied_neighbours(pts, k, tolerance.rtol)
    return Neighbourhoods(indptr=indptr, indices=indices)


def localized_rng(
    points,
    k: int,
    *,
    tolerance: Tolerance = DEFAULT,
    quiet: bool = True,
) -> LocalizedRNG:
    """LocalizedRNG(S, k): Algorithm 2, the union of the RNGs of all N(u; k).

    A pair (a, b) of N(u; k) is an edge of that neighbourhood's relative
    neighbourhood graph when no c of N(u; k) lies in the open lune
    ``B(a, |ab|) ∩ B(b, |ab|)`` (Section 1.2); with ties decided by the lune
    rule of :mod:`sr33.tolerance`.  Section 5 (Theorem 2) shows this graph
    equals the intrinsic Urquhart graph under the sample conditions.

    Parameters
    ----------
    points : (n, 3) array_like of float
        Distinct, finite samples (duplicates are an error here; see
        :func:`sr33.reconstruct`, which merges them).
    k : int
        Neighbourhood size, ``3 <= k < n``.
    tolerance : Tolerance
        Tie rules.
    quiet : bool
        Hide the progress bar.

    Returns
    -------
    LocalizedRNG

    Examples
    --------
    >>> import numpy as np
    >>> from sr33 import localized_rng
    >>> g = np.stack(np.meshgrid(np.arange(3.0), np.arange(3.0), [0.0]), -1).reshape(-1, 3)
    >>> localized_rng(g, 8).edges.shape  # the 12 edges of a 3x3 grid
    (12, 2)
    """
    pts = as_points(points)
    check_not_degenerate(pts)
    check_unique(pts)
    nb = k_neighbourhoods(pts, k, tolerance=tolerance)
    shrink2 = (1.0 - tolerance.rtol) ** 2
    parts = []
    n = pts.shape[0]
    pieces = list(chunks(n))
    with bar(n, "localized RNG", quiet) as pbar:
        for (lo, hi), part in zip(
            pieces,
            thread_map(
                lambda r: _kernels.local_rng_pairs(pts, nb.indptr, nb.indices, shrink2, *r),
                pieces,
            ),
        ):
            parts.append(part)
            pbar.update(hi - lo)
    pairs = np.concatenate(parts) if parts else np.empty((0, 2), np.int64)
    # 1-D keys are an order of magnitude faster to deduplicate than rows
    keys = np.unique(pairs[:, 0] * n + pairs[:, 1])
    edges = np.stack([keys // n, keys % n], axis=1)
    return LocalizedRNG(edges=np.ascontiguousarray(edges, dtype=np.int64), neighbourhoods=nb)
