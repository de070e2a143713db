"""Numba kernels of the triangle intersection test (:func:`sr33.mesh.self_intersections`).

The predicate is the one :func:`sr33.mesh.self_intersections` documents,
pair by pair: two non-coplanar triangles intersect exactly when an edge of
one crosses the other (Möller–Trumbore, with the same tolerances); an edge
that touches a vertex of the other triangle is not tested; two triangles
sharing an edge intersect only when they fold onto each other (their third
vertices coplanar with the edge and on the same side).  The arithmetic is
the numpy version's, operation for operation (products rounded one by one,
sums left to right, no fused multiply-add, no ``fastmath``), so both give
the same answers; ``tests/naive.py`` keeps the vectorized numpy version as
the reference.
"""

from __future__ import annotations

import numpy as np

from .jit import njit

_TOL = 1e-12  # barycentric and segment-parameter slack of the crossing test
_FOLD = 1.0 - 1e-12  # cosine above which two triangles on one edge fold


@njit(cache=True)
def _diff(v, a, b):
    """v[a] - v[b] as three scalars."""
    return v[a, 0] - v[b, 0], v[a, 1] - v[b, 1], v[a, 2] - v[b, 2]


@njit(cache=True)
def _cross(ax, ay, az, bx, by, bz):
    """(a x b), component by component (no fused multiply-add)."""
    return ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx


@njit(cache=True)
def _segment_crosses(v, p0, p1, a, b, c, eps):
    """Does the open segment v[p0]-v[p1] cross triangle (a, b, c)?"""
    dx, dy, dz = _diff(v, p1, p0)
    e1x, e1y, e1z = _diff(v, b, a)
    e2x, e2y, e2z = _diff(v, c, a)
    hx, hy, hz = _cross(dx, dy, dz, e2x, e2y, e2z)
    det = e1x * hx + e1y * hy + e1z * hz
    if not abs(det) > eps:
        return False
    inv = 1.0 / det
    sx, sy, sz = _diff(v, p0, a)
    u = inv * (sx * hx + sy * hy + sz * hz)
    qx, qy, qz = _cross(sx, sy, sz, e1x, e1y, e1z)
    w = inv * (dx * qx + dy * qy + dz * qz)
    t = inv * (e2x * qx + e2y * qy + e2z * qz)
    return u >= -_TOL and w >= -_TOL and u + w <= 1.0 + _TOL and t > _TOL and t < 1.0 - _TOL


@njit(cache=True)
def _boxes_overlap(v, s, d):
    """Whether the bounding boxes of triangles ``s`` and ``d`` (rows of
    vertex indices) overlap (closed boxes)."""
    for k in range(3):
        lo_s = min(v[s[0], k], v[s[1], k], v[s[2], k])
        hi_s = max(v[s[0], k], v[s[1], k], v[s[2], k])
        lo_d = min(v[d[0], k], v[d[1], k], v[d[2], k])
        hi_d = max(v[d[0], k], v[d[1], k], v[d[2], k])
        if lo_s > hi_d or lo_d > hi_s:
            return False
    return True


@njit(cache=True)
def _in(x, tri):
    return x == tri[0] or x == tri[1] or x == tri[2]


@njit(cache=True)
def triangles_meet(v, s, d, eps):
    """Whether the interiors of triangles ``s`` and ``d`` (vertex index
    rows) intersect; the boxes are assumed to overlap."""
    shared = 0
    for a in range(3):
        for b in range(3):
            if s[a] == d[b]:
                shared += 1
    for k in range(3):
        a, b = s[k], s[(k + 1) % 3]
        if not (_in(a, d) or _in(b, d)):
            if _segment_crosses(v, a, b, d[0], d[1], d[2], eps):
                return True
    for k in range(3):
        a, b = d[k], d[(k + 1) % 3]
        if not (_in(a, s) or _in(b, s)):
            if _segment_crosses(v, a, b, s[0], s[1], s[2], eps):
                return True
    if shared != 2:
        return False
    # one shared edge: a fold when the third vertices are coplanar with it
    # and on the same side; the edge runs in the order s lists it
    oa = -1
    ob = -1
    e0 = -1
    e1 = -1
    for k in range(3):
        if not _in(s[k], d):
            oa = s[k]
        elif e0 < 0:
            e0 = s[k]
        else:
            e1 = s[k]
        if not _in(d[k], s):
            ob = d[k]
    if oa < 0 or ob < 0 or e1 < 0:
        return False
    ex, ey, ez = _diff(v, e1, e0)
    nax, nay, naz = _cross(ex, ey, ez, *_diff(v, oa, e0))
    nbx, nby, nbz = _cross(ex, ey, ez, *_diff(v, ob, e0))
    la = np.sqrt(nax * nax + nay * nay + naz * naz)
    lb = np.sqrt(nbx * nbx + nby * nby + nbz * nbz)
    cos = (nax * nbx + nay * nby + naz * nbz) / max(la * lb, 1e-300)
    return cos > _FOLD


@njit(cache=True)
def pairs_meet(v, t, pairs, eps):
    """For every candidate pair (rows of ``pairs``), whether the boxes of the
    two triangles overlap and their interiors intersect."""
    out = np.zeros(pairs.shape[0], dtype=np.bool_)
    for r in range(pairs.shape[0]):
        s = t[pairs[r, 0]]
        d = t[pairs[r, 1]]
        if _boxes_overlap(v, s, d) and triangles_meet(v, s, d, eps):
            out[r] = True
    return out


@njit(cache=True)
def first_crossing(v, patch, m, eps):
    """The first pair (i, j), i < j, i < m, of ``patch`` rows whose interiors
    meet, in row order, or (-1, -1): the new triangles (the first ``m``
    rows) against each other and against the rest of the patch."""
    n = patch.shape[0]
    for i in range(min(m, n)):
        s = patch[i]
        for j in range(i + 1, n):
            d = patch[j]
            if _boxes_overlap(v, s, d) and triangles_meet(v, s, d, eps):
                return i, j
    return -1, -1


_CELL_LIMIT = float(2**62)  # grid coordinates are clamped to +-2^62 (int64)


@njit(cache=True)
def _cell(x, origin, cell):
    """Grid coordinate of ``x``: floor((x - origin) / cell) as int64."""
    f = np.floor((x - origin) / cell)
    if f > _CELL_LIMIT:
        return np.int64(2**62)
    if not f > -_CELL_LIMIT:
        return -np.int64(2**62)
    return np.int64(f)


@njit(cache=True)
def _key(x, y, z):
    """A 64-bit hash of a cell (splitmix64 steps); two cells that collide
    only share a bucket: pairs are deduplicated afterwards."""
    gold = np.uint64(0x9E3779B97F4A7C15)
    h = gold
    for c in (x, y, z):
        h ^= np.uint64(c) + gold + (h << np.uint64(6)) + (h >> np.uint64(2))
        h = (h ^ (h >> np.uint64(30))) * np.uint64(0xBF58476D1CE4E5B9)
        h = (h ^ (h >> np.uint64(27))) * np.uint64(0x94D049BB133111EB)
        h = h ^ (h >> np.uint64(31))
    return np.int64(h)


@njit(cache=True)
def _grow(a, need):
    if need <= a.shape[0]:
        return a
    b = np.empty((max(need, 2 * a.shape[0]), 2), dtype=np.int64)
    b[: a.shape[0]] = a
    return b


@njit(cache=True)
def _overlap(lo, hi, i, j):
    for k in range(3):
        if lo[i, k] > hi[j, k] or lo[j, k] > hi[i, k]:
            return False
    return True


@njit(cache=True)
def box_pairs(lo, hi):
    """Every pair (i, j), i < j, of closed boxes that overlap, sorted by (i, j).

    A uniform grid whose cell is the largest side among the boxes up to
    eight times the median half-side (each such box meets at most 2 x 2 x 2
    cells), stored as sorted (cell key, box) entries: memory follows the
    number of boxes, never the extent.  A pair is reported from the one
    cell holding the smaller corner of the two boxes' intersection.  Boxes
    larger than that (an outlier's long triangles) are compared with every
    box.  Cells are hashed (no grid array), so far-apart clusters of boxes
    cost nothing more than near ones.
    """
    n = lo.shape[0]
    out = np.empty((max(16, 4 * n), 2), dtype=np.int64)
    m = 0
    if n < 2:
        return out[:0]
    radius = np.empty(n)
    for i in range(n):
        radius[i] = 0.5 * max(hi[i, 0] - lo[i, 0], hi[i, 1] - lo[i, 1], hi[i, 2] - lo[i, 2])
    positive = radius[radius > 0]
    typical = np.median(positive) if positive.shape[0] else 0.0
    big = radius > 8.0 * typical if typical > 0 else radius > np.inf
    cell = 0.0
    origin = np.full(3, np.inf)
    for i in range(n):
        if not big[i]:
            cell = max(cell, 2.0 * radius[i])
            for k in range(3):
                origin[k] = min(origin[k], lo[i, k])
    if cell == 0.0:  # every box a point: cells of the spacing a uniform spread would have
        ext = 0.0
        for i in range(n):
            for k in range(3):
                ext = max(ext, hi[i, k] - origin[k])
        cell = ext / np.cbrt(n) if ext > 0 else 1.0
    # entries (cell key, box), two passes: count, then fill
    cnt = 0
    for i in range(n):
        if not big[i]:
            nx = _cell(hi[i, 0], origin[0], cell) - _cell(lo[i, 0], origin[0], cell) + 1
            ny = _cell(hi[i, 1], origin[1], cell) - _cell(lo[i, 1], origin[1], cell) + 1
            nz = _cell(hi[i, 2], origin[2], cell) - _cell(lo[i, 2], origin[2], cell) + 1
            cnt += nx * ny * nz
    keys = np.empty(cnt, dtype=np.int64)
    box = np.empty(cnt, dtype=np.int64)
    e = 0
    for i in range(n):
        if big[i]:
            continue
        for x in range(_cell(lo[i, 0], origin[0], cell), _cell(hi[i, 0], origin[0], cell) + 1):
            for y in range(_cell(lo[i, 1], origin[1], cell), _cell(hi[i, 1], origin[1], cell) + 1):
                for z in range(
                    _cell(lo[i, 2], origin[2], cell), _cell(hi[i, 2], origin[2], cell) + 1
                ):
                    keys[e] = _key(x, y, z)
                    box[e] = i
                    e += 1
    order = np.argsort(keys, kind="mergesort")
    keys = keys[order]
    box = box[order]
    s = 0
    while s < cnt:
        t = s + 1
        while t < cnt and keys[t] == keys[s]:
            t += 1
        here = keys[s]
        for p in range(s, t):
            i = box[p]
            for q in range(p + 1, t):
                j = box[q]
                if not _overlap(lo, hi, i, j):
                    continue
                x = _cell(max(lo[i, 0], lo[j, 0]), origin[0], cell)
                y = _cell(max(lo[i, 1], lo[j, 1]), origin[1], cell)
                z = _cell(max(lo[i, 2], lo[j, 2]), origin[2], cell)
                if i == j or _key(x, y, z) != here:
                    continue
                out = _grow(out, m + 1)
                out[m, 0] = min(i, j)
                out[m, 1] = max(i, j)
                m += 1
        s = t
    for i in range(n):
        if not big[i]:
            continue
        for j in range(n):
            if j == i or (big[j] and j < i):
                continue
            if _overlap(lo, hi, i, j):
                out = _grow(out, m + 1)
                out[m, 0] = min(i, j)
                out[m, 1] = max(i, j)
                m += 1
    res = out[:m]
    flat = np.sort(res[:, 0] * n + res[:, 1])
    keep = np.ones(m, dtype=np.bool_)
    for r in range(1, m):
        keep[r] = flat[r] != flat[r - 1]  # a bucket two cells share reports twice
    flat = flat[keep]
    done = np.empty((flat.shape[0], 2), dtype=np.int64)
    done[:, 0] = flat // n
    done[:, 1] = flat % n
    return done
