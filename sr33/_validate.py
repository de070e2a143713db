"""The one validation layer: every message names the argument, the rule and
what was found.  Errors subclass :class:`ValueError`."""

from __future__ import annotations

import numpy as np

from .mesh import as_coordinates


class InputError(ValueError):
    """Bad input to sr33: the message says which argument and why."""


def as_points(points, name: str = "points") -> np.ndarray:
    """Return ``points`` as a C-contiguous float64 (n, 3) array or raise."""
    if np.iscomplexobj(points):
        raise InputError(f"{name} must be real numbers, got a complex array")
    try:
        arr = as_coordinates(points, name)
    except ValueError as exc:
        raise InputError(str(exc)) from None
    if arr.shape[0] < 4:
        raise InputError(f"{name} must hold at least 4 points, got {arr.shape[0]}")
    return np.ascontiguousarray(arr)


def check_not_degenerate(points: np.ndarray, name: str = "points") -> None:
    """Raise if the points span less than a plane (all collinear or equal)."""
    centred = points - points.mean(axis=0)
    s = np.linalg.svd(centred, compute_uv=False)
    if s[0] == 0.0 or s[1] <= 1e-12 * s[0]:
        raise InputError(
            f"{name} are degenerate: all {points.shape[0]} points lie on one line, "
            "a surface needs points spanning at least a plane"
        )


def check_unique(points: np.ndarray, name: str = "points") -> None:
    """Raise if ``points`` holds exact duplicates (the steps need distinct samples)."""
    n_unique = np.unique(points, axis=0).shape[0]
    if n_unique != points.shape[0]:
        raise InputError(
            f"{name} contain {points.shape[0] - n_unique} exact duplicate points; "
            "merge them first (sr33.reconstruct does this and reports the count)"
        )


MAX_K = 256  # the budget of a neighbourhood: larger k is minutes of work for no guarantee


def check_k(k, n: int) -> int:
    """Return ``k`` as int if 3 <= k < n and k <= ``MAX_K``, else raise."""
    if isinstance(k, bool) or not isinstance(k, (int, np.integer)):
        raise InputError(f"k must be an integer, got {type(k).__name__} {k!r}")
    k = int(k)
    if k < 3:
        raise InputError(f"k must be at least 3, got {k}")
    if k >= n:
        raise InputError(f"k must be less than the number of distinct points ({n}), got {k}")
    if k > MAX_K:
        raise InputError(
            f"k must be at most {MAX_K}, got {k}: the localized RNG's work grows as n k^2.6 "
            "(2000 points: k = 400 takes 8 s, k = 1999 over 10 minutes), and Condition III "
            "needs only k >= 33"
        )
    return k


def check_max_cycle_length(max_length, name: str = "max_cycle_length") -> int:
    """Return the cycle length bound as int if it is at least 3."""
    if isinstance(max_length, bool) or not isinstance(max_length, (int, np.integer)):
        raise InputError(f"{name} must be an integer, got {type(max_length).__name__}")
    if max_length < 3:
        raise InputError(f"{name} must be at least 3, got {max_length}")
    return int(max_length)


def as_edges(edges, n: int, name: str = "edges") -> np.ndarray:
    """Return ``edges`` as int64 (m, 2) with endpoints in range and distinct."""
    arr = np.asarray(edges)
    if arr.ndim != 2 or arr.shape[1] != 2:
        raise InputError(f"{name} must have shape (m, 2), got {arr.shape}")
    if arr.size and not np.issubdtype(arr.dtype, np.integer):
        raise InputError(f"{name} must be integer indices, got dtype {arr.dtype}")
    arr = arr.astype(np.int64)
    if arr.size and (arr.min() < 0 or arr.max() >= n):
        raise InputError(f"{name} index points out of range 0..{n - 1}")
    if np.any(arr[:, 0] == arr[:, 1]):
        raise InputError(f"{name} contain loops (an edge from a point to itself)")
    return np.ascontiguousarray(arr)
