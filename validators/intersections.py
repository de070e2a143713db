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
from scipy.spatial import cKDTree


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


def self_intersections(vertices, triangles) -> np.ndarray:
    """Pairs (i, j), i < j, of triangles whose interiors intersect.

    Parameters
    ----------
    vertices : (n, 3) array_like of float
    triangles : (t, 3) array_like of int

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
    cen = p.mean(axis=1)
    rad = np.linalg.norm(p - cen[:, None, :], axis=2).max(axis=1)
    scale = float(np.abs(v).max()) or 1.0
    eps = 1e-14 * scale * scale
    pairs = cKDTree(cen).query_pairs(2 * float(rad.max()), output_type="ndarray")
    if pairs.shape[0] == 0:
        return np.empty((0, 2), dtype=np.int64)
    i, j = pairs[:, 0], pairs[:, 1]
    lo, hi = p.min(axis=1), p.max(axis=1)
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
        common = np.array([np.intersect1d(x, y)[:2] for x, y in zip(a, b)])
        oa = np.array([np.setdiff1d(x, y)[0] for x, y in zip(a, b)])
        ob = np.array([np.setdiff1d(y, x)[0] for x, y in zip(a, b)])
        e0, e1 = v[common[:, 0]], v[common[:, 1]]
        na = np.cross(e1 - e0, v[oa] - e0)
        nb = np.cross(e1 - e0, v[ob] - e0)
        la, lb = np.linalg.norm(na, axis=1), np.linalg.norm(nb, axis=1)
        cos = np.einsum("ij,ij->i", na, nb) / np.maximum(la * lb, 1e-300)
        hit[two[cos > 1 - 1e-12]] = True
    out = np.stack([np.minimum(i[hit], j[hit]), np.maximum(i[hit], j[hit])], axis=1)
    return np.unique(out, axis=0) if out.shape[0] else out.reshape(0, 2)
