"""numba kernel: the Delaunay triangulation of a few hundred points.

The repair (:mod:`sr33.samplers.repair`) triangulates anew wherever its
samples' ids change (every edit's trial, every local status), inside the
descent's numba loop too, and the corners' annealing
(:mod:`sr33.samplers._anneal_kernels`) after every move: 12,000 calls on
30-130 points.  Qhull took 0.2 ms for 140 points in general position,
0.56 ms on a lattice's cocircular squares, and cannot be called from
numba; this kernel 24 µs (docs/sampler.md, stops 61-63).

This is the sweep-hull construction of Delaunator (V. Agafonkin, 2017;
after Sinclair's s-hull, 2010) with Lawson's flips, in one loop: the points are
added in order of their distance from the circumcentre of a seed triangle,
each one outside the hull of those before it, joined to the hull edges it
sees, and the edges opposite it flipped until locally Delaunay.

Ties are decided by one documented rule, not by a triangulator's internals:
an edge is flipped only when the far corner lies inside the circumcircle by
more than ``tol_circle`` (the in-circle determinant), so four points
cocircular within it (a lattice's squares, within rounding) keep the
diagonal they were first given, and that depends on the points' order of
insertion only: by distance from the seed circle's centre, equal distances
by x, then y (the seeds likewise), so that the triangles are the same
whatever the order of the points in the input.  A
hull edge is seen from a point only when the point lies beyond it by more
than ``tol_area`` (twice the triangle's area), so no flat triangle is made
on a row of collinear samples along the hull.  Where the sweep cannot place
a point (one within rounding of the hull or of another point) the kernel
gives up and the caller triangulates otherwise.
"""

from __future__ import annotations

import math

import numpy as np

from sr33.jit import njit

from ._repair_kernels import incircle


@njit(cache=True)
def orient(pts, a, b, c):
    """Twice the signed area of (a, b, c): positive counter-clockwise."""
    return (pts[b, 0] - pts[a, 0]) * (pts[c, 1] - pts[a, 1]) - (pts[b, 1] - pts[a, 1]) * (
        pts[c, 0] - pts[a, 0]
    )


@njit(cache=True)
def checkable(pts, tri, keep_area):
    """Whether a triangulation of ``pts`` can be mended by edge flips at the
    next step (kept for it, :func:`sr33.samplers._repair_kernels.delaunay_flips_since`):
    every point a corner, and no triangle flat (twice its area at most
    ``keep_area``)."""
    used = np.zeros(pts.shape[0], dtype=np.bool_)
    for t in range(tri.shape[0]):
        for j in range(3):
            used[tri[t, j]] = True
        if abs(orient(pts, tri[t, 0], tri[t, 1], tri[t, 2])) <= keep_area:
            return False
    return used.all()


@njit(cache=True)
def _pseudo_angle(dx, dy):
    """A monotone stand-in for the angle of (dx, dy), in [0, 1)."""
    p = dx / (abs(dx) + abs(dy))
    return (3.0 - p if dy > 0.0 else 1.0 + p) / 4.0


@njit(cache=True)
def _first(pts, i, j):
    """Whether point ``i`` comes before ``j`` by (x, y): the rule for ties,
    so that they turn on the points and not on their order in the input."""
    return pts[i, 0] < pts[j, 0] or (pts[i, 0] == pts[j, 0] and pts[i, 1] < pts[j, 1])


@njit(cache=True)
def _circumradius2(pts, a, b, c):
    dx = pts[b, 0] - pts[a, 0]
    dy = pts[b, 1] - pts[a, 1]
    ex = pts[c, 0] - pts[a, 0]
    ey = pts[c, 1] - pts[a, 1]
    bl = dx * dx + dy * dy
    cl = ex * ex + ey * ey
    d = dx * ey - dy * ex
    if d == 0.0:
        return np.inf
    x = (ey * bl - dy * cl) * 0.5 / d
    y = (dx * cl - ex * bl) * 0.5 / d
    return x * x + y * y


@njit(cache=True)
def _link(halfedges, a, b):
    halfedges[a] = b
    if b >= 0:
        halfedges[b] = a


@njit(cache=True)
def _legalize(pts, tris, halfedges, hull_tri, hull_prev, hull_start, a, tol_circle, stack):
    """Lawson's flips from the half-edge ``a`` (Delaunator's ``_legalize``):
    returns the half-edge that ends where ``a``'s triangle's third side now
    is, or -1 when the flips run away (then the caller gives up)."""
    top = 0
    ar = 0
    count = 0
    while True:
        b = halfedges[a]
        a0 = a - a % 3
        ar = a0 + (a + 2) % 3
        if b < 0:
            if top == 0:
                break
            top -= 1
            a = stack[top]
            continue
        b0 = b - b % 3
        bl = b0 + (b + 2) % 3
        p0 = tris[ar]
        p1 = tris[bl]
        if incircle(pts, tris[a0], tris[a0 + 1], tris[a0 + 2], p1) > tol_circle:
            tris[a] = p1
            tris[b] = p0
            hbl = halfedges[bl]
            if hbl < 0:  # the flipped side was on the hull: it is a's now
                e = hull_start
                while True:
                    if hull_tri[e] == bl:
                        hull_tri[e] = a
                        break
                    e = hull_prev[e]  # (the old cycle: a vertex left off the hull keeps its prev)
                    if e == hull_start:
                        break
            _link(halfedges, a, hbl)
            _link(halfedges, b, halfedges[ar])
            _link(halfedges, ar, bl)
            br = b0 + (b + 1) % 3
            count += 1
            if top >= stack.size or count > 4 * tris.size + 64:
                return -1
            stack[top] = br
            top += 1
        else:
            if top == 0:
                break
            top -= 1
            a = stack[top]
    return ar


@njit(cache=True)
def delaunay_triangles(pts, tol_area, tol_circle):
    """The Delaunay triangles of ``pts`` ((n, 2) float64), or None.

    Returns ``(tri, nbr)``: counter-clockwise triangles (int64, (m, 3)) and
    for each corner the triangle across the side opposite it (-1 on the
    hull), as Qhull's ``simplices`` and ``neighbors``; they tile the convex
    hull of the points once, every point a corner.  Ties and the hull's
    collinear points by the rule of the module's docstring.  None when the
    points are fewer than three or all collinear (within ``tol_area``), or
    when a point cannot be placed (within rounding of the hull, or a
    duplicate): the caller then triangulates by other means.
    """
    n = pts.shape[0]
    if n < 3:
        return None
    min_x = pts[:, 0].min()
    max_x = pts[:, 0].max()
    min_y = pts[:, 1].min()
    max_y = pts[:, 1].max()
    cx = 0.5 * (min_x + max_x)
    cy = 0.5 * (min_y + max_y)
    # seed: the point nearest the box's centre, its nearest point, and the
    # point making the smallest circle with them (equals by :func:`_first`)
    i0 = 0
    best = np.inf
    for i in range(n):
        d = (pts[i, 0] - cx) ** 2 + (pts[i, 1] - cy) ** 2
        if d < best or (d == best and _first(pts, i, i0)):
            best, i0 = d, i
    i1 = -1
    best = np.inf
    for i in range(n):
        if i == i0:
            continue
        d = (pts[i, 0] - pts[i0, 0]) ** 2 + (pts[i, 1] - pts[i0, 1]) ** 2
        if d == 0.0:
            return None  # a duplicate
        if d < best or (d == best and _first(pts, i, i1)):
            best, i1 = d, i
    if i1 < 0:
        return None
    i2 = -1
    best = np.inf
    for i in range(n):
        if i == i0 or i == i1:
            continue
        if abs(orient(pts, i0, i1, i)) <= tol_area:
            continue
        r = _circumradius2(pts, i0, i1, i)
        if r < best or (r == best and _first(pts, i, i2)):
            best, i2 = r, i
    if i2 < 0:
        return None
    if orient(pts, i0, i1, i2) < 0.0:
        i1, i2 = i2, i1
    # the seed circle's centre
    ax, ay = pts[i0, 0], pts[i0, 1]
    dx, dy = pts[i1, 0] - ax, pts[i1, 1] - ay
    ex, ey = pts[i2, 0] - ax, pts[i2, 1] - ay
    bl, cl = dx * dx + dy * dy, ex * ex + ey * ey
    d = dx * ey - dy * ex
    ccx = ax + (ey * bl - dy * cl) * 0.5 / d
    ccy = ay + (dx * cl - ex * bl) * 0.5 / d
    dist = np.empty(n)
    for i in range(n):
        dist[i] = (pts[i, 0] - ccx) ** 2 + (pts[i, 1] - ccy) ** 2
    order = np.argsort(dist, kind="mergesort")
    # equal distances (a lattice about the seed circle's centre) by _first
    lo = 0
    while lo < n:
        hi = lo + 1
        while hi < n and dist[order[hi]] == dist[order[lo]]:
            hi += 1
        for a in range(lo + 1, hi):
            v = order[a]
            b = a - 1
            while b >= lo and _first(pts, v, order[b]):
                order[b + 1] = order[b]
                b -= 1
            order[b + 1] = v
        lo = hi

    max_tri = 2 * n
    tris = np.full(3 * max_tri, -1, dtype=np.int64)
    halfedges = np.full(3 * max_tri, -1, dtype=np.int64)
    hull_prev = np.full(n, -1, dtype=np.int64)
    hull_next = np.full(n, -1, dtype=np.int64)
    hull_tri = np.full(n, -1, dtype=np.int64)
    hash_size = max(int(math.ceil(math.sqrt(n))), 1)
    hull_hash = np.full(hash_size, -1, dtype=np.int64)
    stack = np.empty(3 * max_tri + 64, dtype=np.int64)

    def key(x, y):
        return int(math.floor(_pseudo_angle(x - ccx, y - ccy) * hash_size)) % hash_size

    hull_start = i0
    hull_next[i0], hull_prev[i2] = i1, i1
    hull_next[i1], hull_prev[i0] = i2, i2
    hull_next[i2], hull_prev[i1] = i0, i0
    hull_tri[i0], hull_tri[i1], hull_tri[i2] = 0, 1, 2
    hull_hash[key(pts[i0, 0], pts[i0, 1])] = i0
    hull_hash[key(pts[i1, 0], pts[i1, 1])] = i1
    hull_hash[key(pts[i2, 0], pts[i2, 1])] = i2
    tris[0], tris[1], tris[2] = i0, i1, i2
    nt = 3  # half-edges used
    placed = 3
    px, py = np.nan, np.nan
    for k in range(n):
        i = order[k]
        x, y = pts[i, 0], pts[i, 1]
        if i == i0 or i == i1 or i == i2:
            continue
        if x == px and y == py:
            return None  # a duplicate
        px, py = x, y
        # a hull edge the point sees: from the hash's start, forward
        start = -1
        h0 = key(x, y)
        for j in range(hash_size):
            s = hull_hash[(h0 + j) % hash_size]
            if s >= 0 and hull_next[s] != s:
                start = s
                break
        if start < 0:
            return None
        start = hull_prev[start]
        e = start
        while True:
            q = hull_next[e]
            if orient(pts, e, q, i) < -tol_area:
                break
            e = q
            if e == start:
                return None  # inside the hull, or on it within rounding
        # the first triangle, (e, i, next): its side (next, e) is the hull's
        q = hull_next[e]
        t = nt
        tris[t], tris[t + 1], tris[t + 2] = e, i, q
        halfedges[t] = -1
        halfedges[t + 1] = -1
        _link(halfedges, t + 2, hull_tri[e])
        nt += 3
        r = _legalize(
            pts, tris, halfedges, hull_tri, hull_prev, hull_start, t + 2, tol_circle, stack
        )
        if r < 0:
            return None
        hull_tri[i] = r
        hull_tri[e] = t
        # forward: every further hull edge the point sees
        m = hull_next[e]
        while True:
            q = hull_next[m]
            if not orient(pts, m, q, i) < -tol_area:
                break
            t = nt
            tris[t], tris[t + 1], tris[t + 2] = m, i, q
            _link(halfedges, t, hull_tri[i])
            halfedges[t + 1] = -1
            _link(halfedges, t + 2, hull_tri[m])
            nt += 3
            r = _legalize(
                pts, tris, halfedges, hull_tri, hull_prev, hull_start, t + 2, tol_circle, stack
            )
            if r < 0:
                return None
            hull_tri[i] = r
            hull_next[m] = m  # off the hull
            m = q
        # backward likewise
        while True:
            q = hull_prev[e]
            if not orient(pts, q, e, i) < -tol_area:
                break
            t = nt
            tris[t], tris[t + 1], tris[t + 2] = q, i, e
            halfedges[t] = -1
            _link(halfedges, t + 1, hull_tri[e])
            _link(halfedges, t + 2, hull_tri[q])
            nt += 3
            if (
                _legalize(
                    pts, tris, halfedges, hull_tri, hull_prev, hull_start, t + 2, tol_circle, stack
                )
                < 0
            ):
                return None
            hull_tri[q] = t
            hull_next[e] = e
            e = q
        hull_start = e
        hull_prev[i] = e
        hull_next[e] = i
        hull_prev[m] = i
        hull_next[i] = m
        hull_hash[key(x, y)] = i
        hull_hash[key(pts[e, 0], pts[e, 1])] = e
        placed += 1
    if placed != n:
        return None
    m = nt // 3
    tri = np.empty((m, 3), dtype=np.int64)
    nbr = np.empty((m, 3), dtype=np.int64)
    for t in range(m):
        for k in range(3):
            tri[t, k] = tris[3 * t + k]
            h = halfedges[3 * t + (k + 1) % 3]
            nbr[t, k] = h // 3 if h >= 0 else -1
    return tri, nbr
