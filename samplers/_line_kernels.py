"""numba kernels of a planar face's straight edges and arcs
(:mod:`sr33.samplers.layers`, :mod:`sr33.samplers.chart`): every point's
foot parameter on and distance to every edge, the projection onto the
nearest edge or arc, the clamps that keep free samples inside them and the
ghosts of the faces across them.

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
def _segment_distance(x, y, a, d, dd, k):
    """The distance of (x, y) to edge ``k`` (see :func:`along`)."""
    t = ((x - a[k, 0]) * d[k, 0] + (y - a[k, 1]) * d[k, 1]) / dd[k]
    t = min(max(t, 0.0), 1.0)
    qx = x - (a[k, 0] + t * d[k, 0])
    qy = y - (a[k, 1] + t * d[k, 1])
    return np.sqrt(qx * qx + qy * qy)


@njit(cache=True)
def distance(p, a, d, dd):
    """(n, m): every point's distance to every edge (see :func:`along`)."""
    n, m = p.shape[0], a.shape[0]
    out = np.empty((n, m))
    for i in range(n):
        for k in range(m):
            out[i, k] = _segment_distance(p[i, 0], p[i, 1], a, d, dd, k)
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


#: a ghost nearer (by more than this times h) to another edge of the face
#: than to its own is dropped (:func:`ghosts`)
OWN_SLACK = 1e-9


@njit(cache=True)
def _own_nearest(x, y, k, a, d, dd, slack):
    """Whether no edge is nearer to (x, y) than edge ``k`` by more than ``slack``."""
    bound = _segment_distance(x, y, a, d, dd, k) - slack
    for q in range(a.shape[0]):
        if q != k and _segment_distance(x, y, a, d, dd, q) < bound:
            return False
    return True


@njit(cache=True)
def owned(q, k, a, d, dd, h):
    """(n,): whether each point ``q`` (n, 2) lies no farther from its edge
    ``k[i]`` than from every other edge (see :func:`ghosts`)."""
    out = np.empty(q.shape[0], dtype=np.bool_)
    for i in range(q.shape[0]):
        out[i] = _own_nearest(q[i, 0], q[i, 1], k[i], a, d, dd, OWN_SLACK * h)
    return out


#: what an edge of :func:`ghosts` gives: none (another edge of the face,
#: there for the nearest-edge test), its points' ghosts, or those of them
#: no other edge is nearer to
NO_GHOSTS, GHOSTS, OWN_GHOSTS = 0, 1, 2


@njit(cache=True)
def ghosts(p, a, d, dd, inward, h, corners, own):
    """The neighbouring faces unfolded across straight edges
    (:func:`sr33.samplers.layers._line_ghosts`): ``corners``, then edge by
    edge, of those ``own`` marks ``GHOSTS`` or ``OWN_GHOSTS`` (``inward``
    its unit normal into the face), the points of ``p`` on it (within
    1e-6 h), moved h and then 2h outwards; for ``OWN_GHOSTS``, each kept
    only where no edge of the face (``a``, ``d``, ``dd``: all of them) is
    nearer to it than its own (by ``OWN_SLACK`` h).  Beside a
    reflex corner the faces across its two edges unfold onto one another
    (the corner is a saddle: more than 2 pi round it); there a ghost of one
    edge beyond the other is no sample the geodesics see, and kept, it hid
    the triangles of the face's corner from the repair's judge (a star
    prism's cap: 7 triangles up to 0.975 judged 0.830)."""
    on = distance(p, a, d, dd) < 1e-6 * h
    count = corners.shape[0]
    for k in range(a.shape[0]):
        if own[k] != NO_GHOSTS:
            for i in range(p.shape[0]):
                if on[i, k]:
                    count += 2
    out = np.empty((count, 2))
    out[: corners.shape[0]] = corners
    row = corners.shape[0]
    slack = OWN_SLACK * h
    for k in range(a.shape[0]):
        if own[k] == NO_GHOSTS:
            continue
        for j in (1.0, 2.0):
            sx = j * h * inward[k, 0]
            sy = j * h * inward[k, 1]
            for i in range(p.shape[0]):
                if on[i, k]:
                    x = p[i, 0] - sx
                    y = p[i, 1] - sy
                    if own[k] == GHOSTS or _own_nearest(x, y, k, a, d, dd, slack):
                        out[row, 0] = x
                        out[row, 1] = y
                        row += 1
    return out[:row]


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


TWO_PI = 2 * np.pi


@njit(cache=True)
def _arc_distance(x, y, cx, cy, r):
    dx = x - cx
    dy = y - cy
    return abs(np.sqrt(dx * dx + dy * dy) - r)


@njit(cache=True)
def project_curves(p, kind, a, d, dd, lo, centre, radius, start, span, closed, margin):
    """Each point moved to the nearest point of its nearest curve (the
    first of equally near ones): a straight edge (``kind`` 0, see
    :func:`project`) or an arc (``kind`` 1: of ``radius`` about ``centre``,
    from angle ``start`` over ``span``, or all round where ``closed``),
    kept ``margin`` from an open arc's ends (a point past either end goes to
    the nearer end).  Bit for bit ``layers._project_onto``'s numpy code."""
    m = kind.shape[0]
    dist = np.empty(m)
    out = p.copy()
    for i in range(p.shape[0]):
        x, y = p[i, 0], p[i, 1]
        for k in range(m):
            if kind[k] == 0:
                t = ((x - a[k, 0]) * d[k, 0] + (y - a[k, 1]) * d[k, 1]) / dd[k]
                t = min(max(t, 0.0), 1.0)
                qx = x - (a[k, 0] + t * d[k, 0])
                qy = y - (a[k, 1] + t * d[k, 1])
                dist[k] = np.sqrt(qx * qx + qy * qy)
            else:
                dist[k] = _arc_distance(x, y, centre[k, 0], centre[k, 1], radius[k])
        k = 0
        for q in range(1, m):
            if dist[q] < dist[k]:
                k = q
        if kind[k] == 0:
            t = ((x - a[k, 0]) * d[k, 0] + (y - a[k, 1]) * d[k, 1]) / dd[k]
            t = min(max(t, lo[k]), 1.0 - lo[k])
            out[i, 0] = a[k, 0] + t * d[k, 0]
            out[i, 1] = a[k, 1] + t * d[k, 1]
        else:
            ang = np.arctan2(y - centre[k, 1], x - centre[k, 0])
            if not closed[k]:
                rel = (ang - start[k]) % TWO_PI
                low = margin / radius[k]
                high = span[k] - margin / radius[k]
                if rel > span[k] + (TWO_PI - span[k]) / 2:
                    rel = low
                else:
                    rel = min(max(rel, low), high)
                ang = start[k] + rel
            out[i, 0] = centre[k, 0] + radius[k] * np.cos(ang)
            out[i, 1] = centre[k, 1] + radius[k] * np.sin(ang)
    return out


@njit(cache=True)
def clamp_arcs(p, centre, radius, start, span, closed, side, margin):
    """Points moved onto the face's side of every arc (see
    :func:`project_curves`; ``side`` +1 where the face lies inside its
    circle), at least ``margin`` from it where they fall within its span
    and are nearer: arc after arc, each seeing the points the ones before
    it moved.  Returns a new array (``chart.ArcClamp``)."""
    out = p.copy()
    for k in range(centre.shape[0]):
        target = radius[k] - side[k] * margin[k]
        for i in range(out.shape[0]):
            wx = out[i, 0] - centre[k, 0]
            wy = out[i, 1] - centre[k, 1]
            r = np.sqrt(wx * wx + wy * wy)
            ang = (np.arctan2(wy, wx) - start[k]) % TWO_PI
            within = closed[k] or ang <= span[k]
            inward = side[k] * (radius[k] - r)
            if within and inward < margin[k] and r > 1e-12:
                out[i, 0] = centre[k, 0] + wx / r * target
                out[i, 1] = centre[k, 1] + wy / r * target
    return out


@njit(cache=True)
def ghosts_arcs(p, centre, radius, side, h):
    """The faces across arcs unfolded (``chart.ArcGhosts``): arc by arc,
    the points of ``p`` on it (within 1e-6 h of their nearest arc, the
    first of equally near ones) moved h and then 2h across it, straight out
    from its centre (``side`` +1 where the face lies inside the circle)."""
    n, m = p.shape[0], centre.shape[0]
    which = np.full(n, -1, dtype=np.int64)
    for i in range(n):
        best = np.inf
        k = -1
        for q in range(m):
            dq = _arc_distance(p[i, 0], p[i, 1], centre[q, 0], centre[q, 1], radius[q])
            if k < 0 or dq < best:
                best, k = dq, q
        if k >= 0 and best < 1e-6 * h:
            which[i] = k
    count = 0
    for i in range(n):
        if which[i] >= 0:
            count += 1
    out = np.empty((2 * count, 2))
    row = 0
    for k in range(m):
        for j in (1.0, 2.0):
            reach = radius[k] + side[k] * j * h
            for i in range(n):
                if which[i] == k:
                    wx = p[i, 0] - centre[k, 0]
                    wy = p[i, 1] - centre[k, 1]
                    length = np.sqrt(wx * wx + wy * wy)
                    wx = wx / length
                    wy = wy / length
                    out[row, 0] = centre[k, 0] + reach * wx
                    out[row, 1] = centre[k, 1] + reach * wy
                    row += 1
    return out


@njit(cache=True)
def clamp_radial(p, lo, hi):
    """Points moved to a distance from the origin within [lo, hi] (the
    origin stays; ``chart.RadialClamp``).  Returns a new array."""
    out = p.copy()
    for i in range(p.shape[0]):
        x, y = p[i, 0], p[i, 1]
        r = np.sqrt(x * x + y * y)
        f = min(max(r, lo), hi) / max(r, 1e-300)
        if r > 0:
            out[i, 0] = x * f
            out[i, 1] = y * f
    return out


@njit(cache=True)
def inside_sector(c, outer, inner, theta, full):
    """Which points ``c`` lie farther than ``inner`` and nearer than
    ``outer`` from the origin, at an angle in [0, ``theta``) unless
    ``full`` (``chart.Sector``)."""
    out = np.empty(c.shape[0], dtype=np.bool_)
    for i in range(c.shape[0]):
        x, y = c[i, 0], c[i, 1]
        r = np.sqrt(x * x + y * y)
        ok = r < outer and r > inner
        if ok and not full:
            ok = np.arctan2(y, x) % TWO_PI < theta
        out[i] = ok
    return out
