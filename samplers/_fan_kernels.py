"""numba kernels of the search for a designed fan round a cone's apex
(:func:`sr33.samplers.layers._apex_fan`): the figures of every candidate fan
in one loop, with no temporary arrays.

The uneven search tries every pair of gaps on a 2° grid with every pair of
spoke lengths: two million fans of three spokes for a development of 126°
(cone_tip).  As numpy expressions over those rows it made a dozen arrays of
6 million floats (4.4 s); here each fan's figures come from the same
arithmetic in the same order (``cos``, ``sqrt`` and ``acos`` of the C
library, as :mod:`sr33.libm` and numpy call them), so the figures, and the
fan chosen, are bit for bit those of the numpy form
(``tests/test_sampling_shapes.py`` compares them).
"""

from __future__ import annotations

import numpy as np

from sr33.jit import njit


@njit(cache=True)
def _clip1(x):
    return min(max(x, -1.0), 1.0)


@njit(cache=True)
def _row(r, p, this, out, row):
    """The figures of one fan (spoke lengths ``r``, angles ``p`` between
    spoke k and k + 1; ``this`` a (2, m) scratch) into ``out[row]``: the
    worst Condition III-ii ratio of its triangles, the largest sum of the
    two angles opposite a spoke (radians) and the shortest chord between
    neighbouring spokes' ends."""
    m = r.size
    worst = -np.inf
    chord = np.inf
    for k in range(m):  # triangle (apex, k, k + 1)
        a = r[k]
        b = r[(k + 1) % m]
        c = np.sqrt(a * a + b * b - 2 * a * b * np.cos(p[k]))
        lo, mid, hi = a, b, c  # sorted, as np.sort of three
        if lo > mid:
            lo, mid = mid, lo
        if mid > hi:
            mid, hi = hi, mid
        if lo > mid:
            lo, mid = mid, lo
        worst = max(worst, mid / hi)
        chord = min(chord, c)
        this[0, k] = np.arccos(_clip1((a * a + c * c - b * b) / (2 * a * c)))  # at k
        this[1, k] = np.arccos(_clip1((b * b + c * c - a * a) / (2 * b * c)))  # at k + 1
    widest = -np.inf
    for k in range(m):  # spoke k: faced by the angle at k + 1 here, at k - 1 in triangle k - 1
        widest = max(widest, this[1, k] + this[0, (k - 1) % m])
    out[row, 0] = worst
    out[row, 1] = widest
    out[row, 2] = chord


@njit(cache=True)
def fan_figures(radii, phi):
    """Per row of ``radii`` (spoke lengths) and ``phi`` (angles between
    spoke k and k + 1, rows like ``radii``): the worst ratio, the largest
    opposite-angle sum (radians) and the shortest chord, as columns."""
    out = np.empty((radii.shape[0], 3))
    this = np.empty((2, radii.shape[1]))
    for i in range(radii.shape[0]):
        _row(radii[i], phi[i], this, out, i)
    return out


@njit(cache=True)
def uneven_figures(g1, g2, theta, r2, r3):
    """:func:`fan_figures` of the fans of three spokes (lengths 1, ``r2[j]``,
    ``r3[j]``) with gaps ``g1[i]``, ``g2[i]`` and ``theta - g1[i] - g2[i]``,
    in rows ``i * r2.size + j`` (gaps outer, lengths inner)."""
    out = np.empty((g1.size * r2.size, 3))
    r = np.empty(3)
    p = np.empty(3)
    this = np.empty((2, 3))
    r[0] = 1.0
    for i in range(g1.size):
        p[0], p[1], p[2] = g1[i], g2[i], theta - g1[i] - g2[i]
        for j in range(r2.size):
            r[1], r[2] = r2[j], r3[j]
            _row(r, p, this, out, i * r2.size + j)
    return out
