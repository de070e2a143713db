"""numba kernels of a planar face's straight edges (:mod:`sr33.samplers.layers`):
every point's foot parameter on and distance to every edge, and the clamp
that keeps free samples inside them.

The repair calls them at every descent step, on a few hundred samples: as
numpy expressions they cost more in calls than in arithmetic.  Bit for bit
the numpy code they replaced: the same operations in the same order (a dot
product of two 2-vectors is ``x0 * y0 + x1 * y1``, as
:func:`sr33.mesh.dot` sums it), so that no sampling moves.
"""

from __future__ import annotations

import numpy as np

from sr33.jit import njit


@njit(cache=True)
def along(p, a, d, dd):
    """(n, m): the foot parameter of every point ``p`` (n, 2) on every edge
    from ``a`` (m, 2) along ``d`` (m, 2) (``dd``: their squared lengths), 0 at
    ``a``, 1 at its other end."""
    n, m = p.shape[0], a.shape[0]
    out = np.empty((n, m))
    for i in range(n):
        for k in range(m):
            out[i, k] = ((p[i, 0] - a[k, 0]) * d[k, 0] + (p[i, 1] - a[k, 1]) * d[k, 1]) / dd[k]
    return out


@njit(cache=True)
def distance(p, a, d, dd):
    """(n, m): every point's distance to every edge (see :func:`along`)."""
    n, m = p.shape[0], a.shape[0]
    out = np.empty((n, m))
    for i in range(n):
        for k in range(m):
            t = ((p[i, 0] - a[k, 0]) * d[k, 0] + (p[i, 1] - a[k, 1]) * d[k, 1]) / dd[k]
            t = min(max(t, 0.0), 1.0)
            qx = p[i, 0] - (a[k, 0] + t * d[k, 0])
            qy = p[i, 1] - (a[k, 1] + t * d[k, 1])
            out[i, k] = np.sqrt(qx * qx + qy * qy)
    return out


@njit(cache=True)
def _measure(x, y, a, d, dd, normals, t, inward):
    for k in range(a.shape[0]):
        ux = x - a[k, 0]
        uy = y - a[k, 1]
        t[k] = (ux * d[k, 0] + uy * d[k, 1]) / dd[k]
        inward[k] = ux * normals[k, 0] + uy * normals[k, 1]


@njit(cache=True)
def clamp(p, a, d, dd, normals, least, beyond):
    """Points ``p`` moved at least ``least`` inside every edge (see
    :func:`along`; ``normals`` (m, 2) unit, into the face) whose foot lies
    within it and that they are less than ``least`` inside and more than
    ``beyond`` (negative) outside of: edge after edge, each seeing the
    points the ones before it moved.  Returns a new array."""
    m = a.shape[0]
    out = p.copy()
    t = np.empty(m)
    inward = np.empty(m)
    for i in range(p.shape[0]):
        _measure(out[i, 0], out[i, 1], a, d, dd, normals, t, inward)
        for k in range(m):
            if t[k] > 0 and t[k] < 1 and inward[k] < least and inward[k] > beyond:
                c = least - inward[k]
                out[i, 0] += c * normals[k, 0]
                out[i, 1] += c * normals[k, 1]
                _measure(out[i, 0], out[i, 1], a, d, dd, normals, t, inward)
    return out


@njit(cache=True)
def ghosts(p, a, d, dd, inward, h, corners):
    """The neighbouring faces unfolded across straight edges
    (:func:`sr33.samplers.layers._line_ghosts`): ``corners``, then edge by
    edge (``inward`` its unit normal into the face) the points of ``p`` on
    it (within 1e-6 h), moved h and then 2h outwards."""
    on = distance(p, a, d, dd) < 1e-6 * h
    count = corners.shape[0] + 2 * int(on.sum())
    out = np.empty((count, 2))
    out[: corners.shape[0]] = corners
    row = corners.shape[0]
    for k in range(a.shape[0]):
        for j in (1.0, 2.0):
            sx = j * h * inward[k, 0]
            sy = j * h * inward[k, 1]
            for i in range(p.shape[0]):
                if on[i, k]:
                    out[row, 0] = p[i, 0] - sx
                    out[row, 1] = p[i, 1] - sy
                    row += 1
    return out


@njit(cache=True)
def project(p, a, d, dd, lo):
    """Each point moved to the nearest point of its nearest edge (the first
    of equally near ones), its parameter within ``[lo, 1 - lo]`` of that
    edge (see :func:`along`)."""
    dist = distance(p, a, d, dd)
    out = p.copy()
    for i in range(p.shape[0]):
        k = 0
        for q in range(1, a.shape[0]):
            if dist[i, q] < dist[i, k]:
                k = q
        t = ((p[i, 0] - a[k, 0]) * d[k, 0] + (p[i, 1] - a[k, 1]) * d[k, 1]) / dd[k]
        t = min(max(t, lo[k]), 1.0 - lo[k])
        out[i, 0] = a[k, 0] + t * d[k, 0]
        out[i, 1] = a[k, 1] + t * d[k, 1]
    return out
