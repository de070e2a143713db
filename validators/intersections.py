"""Self-intersections: pairs of triangles whose interiors meet.

The paper requires the triangles of the output to have pairwise disjoint
interiors (Section 4, Triangulate).  Candidate pairs come from a spatial
index (scipy's cKDTree on triangle centroids, radius = the two largest
centroid-to-vertex distances) and a bounding-box filter; each candidate is
then decided by exact segment–triangle tests (Möller–Trumbore): two
non-coplanar triangles intersect exactly when an edge of one crosses the
other.  Pairs sharing an edge are adjacent, not intersecting, unless they
fold onto each other (coplanar and on the same side); pairs sharing one
vertex intersect when an edge not at that vertex crosses the other.
Coplanar overlapping pairs that share no vertex are found by a 2D
edge-crossing test in their common plane.
"""

from __future__ import annotations

import numpy as np


def _seg_tri(p0, p1, a, b, c, eps):
    """Vectorized: does the open segment p0-p1 cross the triangle abc (interior or edge)?"""
    d = p1 - p0
    e1, e2 = b - a, c - a
    h = np.cross(d, e2)
    det = np.einsum("ij,ij->i", e1, h)
    ok = np.abs(det) > eps
    inv = np.where(ok, 1.0 / np.where(ok, det, 1.0), 0.0)
    s = p0 - a
    u = inv * np.einsum("ij,ij->i", s, h)
    q = np.cross(s, e1)
    v = inv * np.einsum("ij,ij->i", d, q)
    t = inv * np.einsum("ij,ij->i", e2, q)
    tol = 1e-12
    return ok & (u >= -tol) & (v >= -tol) & (u + v <= 1 + tol) & (t > tol) & (t < 1 - tol)


def candidate_pairs(lo: np.ndarray, hi: np.ndarray, keep=None) -> np.ndarray:
    """Pairs of boxes sharing a cell of a uniform grid (cell = median box size).

    Every box is entered in each cell it overlaps; pairs are generated per
    cell, filtered by ``keep`` (if given) before deduplication, and reported
    once.  Unlike one search radius for all, a few large triangles do not
    make every small one a candidate of every other.
    """
    ext = (hi - lo).max(axis=1)
    cell = float(np.median(ext)) or float(ext.max()) or 1.0
    origin = lo.min(axis=0)
    c0 = np.floor((lo - origin) / cell).astype(np.int64)
    c1 = np.floor((hi - origin) / cell).astype(np.int64)
    span = c1 - c0 + 1
    count = span.prod(axis=1)
    owner = np.repeat(np.arange(lo.shape[0]), count)
    start = np.repeat(np.cumsum(count) - count, count)
    k = np.arange(owner.shape[0]) - start
    sx, sy = span[owner, 0], span[owner, 1]
    ix = c0[owner, 0] + k % sx
    iy = c0[owner, 1] + (k // sx) % sy
    iz = c0[owner, 2] + k // (sx * sy)
    dims = c1.max(axis=0) + 1
    key = (ix * dims[1] + iy) * dims[2] + iz
    order = np.argsort(key, kind="stable")
    key, owner = key[order], owner[order]
    starts = np.flatnonzero(np.r_[True, key[1:] != key[:-1]])
    sizes = np.diff(np.r_[starts, key.shape[0]])
    # every element pairs with the later elements of its cell, vectorized
    group_end = np.repeat(starts + sizes, sizes)
    later = group_end - np.arange(key.shape[0]) - 1
    if later.sum() == 0:
        return np.empty((0, 2), dtype=np.int64)
    first = np.repeat(np.arange(key.shape[0]), later)
    offset = np.arange(first.shape[0]) - np.repeat(np.cumsum(later) - later, later)
    a, b = owner[first], owner[first + 1 + offset]
    ok = a != b
    if keep is not None:
        ok &= keep(a, b)
    a, b = a[ok], b[ok]
    n = lo.shape[0]
    keys = np.sort(np.minimum(a, b) * n + np.maximum(a, b))
    keys = keys[np.r_[True, keys[1:] != keys[:-1]]]
    return np.stack([keys // n, keys % n], axis=1)


def self_intersections(vertices, triangles, keep=None) -> np.ndarray:
    """Pairs (i, j), i < j, of triangles whose interiors intersect.

    Parameters
    ----------
    vertices : (n, 3) array_like of float
    triangles : (t, 3) array_like of int

    keep : callable, optional
        ``keep(i, j) -> bool array`` filters the candidate pairs before the
        exact tests (callers that only care about some pairs).

    Returns
    -------
    (p, 2) int64, sorted rows.

    Examples
    --------
    >>> import numpy as np
    >>> v = np.array([[0, 0, 0], [2, 0, 0], [0, 2, 0],
    ...               [0.5, 0.5, -1], [0.5, 0.5, 1], [3, 3, 0]], float)
    >>> self_intersections(v, [(0, 1, 2), (3, 4, 5)]).tolist()
    [[0, 1]]
    """
    v = np.asarray(vertices, dtype=np.float64)
    t = np.asarray(triangles, dtype=np.int64)
    if t.shape[0] < 2:
        return np.empty((0, 2), dtype=np.int64)
    p = v[t]
    scale = float(np.abs(v).max()) or 1.0
    eps = 1e-14 * scale * scale
    lo, hi = p.min(axis=1), p.max(axis=1)
    pairs = candidate_pairs(lo, hi, keep)
    if pairs.shape[0] == 0:
        return np.empty((0, 2), dtype=np.int64)
    i, j = pairs[:, 0], pairs[:, 1]
    box = np.all((lo[i] <= hi[j]) & (lo[j] <= hi[i]), axis=1)
    i, j = i[box], j[box]
    ti, tj = t[i], t[j]
    shared = (ti[:, :, None] == tj[:, None, :]).sum(axis=(1, 2))
    hit = np.zeros(i.shape[0], dtype=bool)
    # edges of one triangle that do not touch a shared vertex, against the other
    for dst, ts, td in ((j, ti, tj), (i, tj, ti)):
        for k in range(3):
            a_idx, b_idx = ts[:, k], ts[:, (k + 1) % 3]
            touches = (a_idx[:, None] == td).any(axis=1) | (b_idx[:, None] == td).any(axis=1)
            test = ~touches
            if not test.any():
                continue
            sel = np.flatnonzero(test)
            r = _seg_tri(
                v[a_idx[sel]], v[b_idx[sel]], p[dst[sel], 0], p[dst[sel], 1], p[dst[sel], 2], eps
            )
            hit[sel[r]] = True
    # pairs sharing an edge: a fold when the two third vertices are coplanar and on one side
    two = np.flatnonzero((shared == 2) & ~hit)
    if two.shape[0]:
        a, b = ti[two], tj[two]
        in_b = (a[:, :, None] == b[:, None, :]).any(axis=2)
        in_a = (b[:, :, None] == a[:, None, :]).any(axis=2)
        oa = a[~in_b]
        ob = b[~in_a]
        common = a[in_b].reshape(-1, 2)
        e0, e1 = v[common[:, 0]], v[common[:, 1]]
        na = np.cross(e1 - e0, v[oa] - e0)
        nb = np.cross(e1 - e0, v[ob] - e0)
        la, lb = np.linalg.norm(na, axis=1), np.linalg.norm(nb, axis=1)
        cos = np.einsum("ij,ij->i", na, nb) / np.maximum(la * lb, 1e-300)
        hit[two[cos > 1 - 1e-12]] = True
    out = np.stack([np.minimum(i[hit], j[hit]), np.maximum(i[hit], j[hit])], axis=1)
    return np.unique(out, axis=0) if out.shape[0] else out.reshape(0, 2)
