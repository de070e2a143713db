"""Cones for stray samples (end of Section 5 of the paper).

Theorem 5 leaves a defect: the output need not use every sample.  The paper
remedies it by attaching stray samples with cones whose triangles keep
interiors disjoint.  Here a stray sample p is coned over the triangle t
nearest to it: t is replaced by the three triangles joining p to t's edges.
That is a subdivision of t, so the topology of the surface is unchanged and
no two triangle interiors meet.  Orientation is inherited from t.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

from ._validate import InputError, as_points
from .mesh import closest_points_on_triangles


def ring_centres(points, faces) -> dict[int, int]:
    """Stray samples that sit inside a face cycle ringing around them.

    At a cone tip the selected face cycle can be the ring of samples around
    the tip, leaving the tip itself unused; triangulating across the ring and
    then coning the tip over one triangle would fold the other triangles over
    it.  The cone of Section 5 is then the whole ring: this returns, for such
    faces, face index -> the stray sample to fan from.  A stray qualifies
    when, in the frame of the face's best-fit plane, its offset from the
    centroid is less than the face's radius (farthest vertex from the
    centroid) within the plane and less than twice that radius across it;
    each face takes at most one stray, nearest faces first.

    Returns
    -------
    dict of int to int
    """
    pts = np.asarray(points, dtype=np.float64)
    n = pts.shape[0]
    if len(faces) == 0:
        return {}
    used = np.zeros(n, dtype=bool)
    used[faces.vertices] = True
    strays = np.flatnonzero(~used)
    if strays.shape[0] == 0:
        return {}
    lengths = faces.lengths
    owner = np.repeat(np.arange(len(faces)), lengths)
    cen = np.zeros((len(faces), 3))
    np.add.at(cen, owner, pts[faces.vertices])
    cen /= lengths[:, None]
    reach = np.zeros(len(faces))
    np.maximum.at(reach, owner, np.linalg.norm(pts[faces.vertices] - cen[owner], axis=1))
    tree = cKDTree(cen)
    out: dict[int, int] = {}
    for p in strays.tolist():
        _, idx = tree.query(pts[p], min(8, len(faces)))
        for fi in np.atleast_1d(idx).tolist():
            if fi in out or lengths[fi] < 4:
                continue
            q = pts[faces.cycle(fi)] - cen[fi]
            normal = np.linalg.svd(q, full_matrices=False)[2][-1]
            off = pts[p] - cen[fi]
            across = abs(float(off @ normal))
            within = float(np.linalg.norm(off - (off @ normal) * normal))
            if within < reach[fi] and across < 2 * reach[fi]:
                out[int(fi)] = int(p)
                break
    return out


def attach_cones(points, triangles, *, candidates: int = 16) -> tuple[np.ndarray, np.ndarray]:
    """Attach every sample no triangle uses, by a cone over its nearest triangle.

    Parameters
    ----------
    points : (n, 3) array_like of float
        The samples.
    triangles : (t, 3) array_like of int
        The triangulated output.
    candidates : int
        How many triangles (nearest by centroid) are searched per stray sample.

    Returns
    -------
    triangles : (t + 2s, 3) int64
        The triangles with every stray sample coned in.
    strays : (s,) int64
        The samples that were attached, in the order they were processed
        (ascending index).

    Examples
    --------
    >>> import numpy as np
    >>> from sr33 import attach_cones
    >>> p = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0.2, 0.2, 0.01]])
    >>> tri, strays = attach_cones(p, [(0, 1, 2)])
    >>> strays.tolist(), tri.shape
    ([3], (3, 3))
    """
    pts = as_points(points)
    tri = np.asarray(triangles, dtype=np.int64).reshape(-1, 3)
    if tri.shape[0] == 0:
        raise InputError("triangles is empty: there is no surface to attach samples to")
    if tri.min() < 0 or tri.max() >= pts.shape[0]:
        raise InputError("triangles index points out of range")
    used = np.zeros(pts.shape[0], dtype=bool)
    used[tri.ravel()] = True
    strays = np.flatnonzero(~used)
    if strays.shape[0] == 0:
        return tri.copy(), strays
    tris = [tuple(t) for t in tri.tolist()]
    alive = [True] * len(tris)
    for p in strays.tolist():
        live = [i for i, ok in enumerate(alive) if ok]
        cen = pts[np.array([tris[i] for i in live])].mean(axis=1)
        tree = cKDTree(cen)
        kq = min(candidates, len(live))
        _, near = tree.query(pts[p], kq)
        near = np.atleast_1d(near)
        cand = np.array([live[j] for j in near.tolist()], dtype=np.int64)
        d2, _ = closest_points_on_triangles(
            np.repeat(pts[p][None], cand.size, axis=0), pts[np.array([tris[i] for i in cand])]
        )
        best = int(cand[np.lexsort((cand, d2))[0]])  # nearest; ties: the earliest triangle
        a, b, c = tris[best]
        alive[best] = False
        for new in ((a, b, p), (b, c, p), (c, a, p)):
            tris.append(new)
            alive.append(True)
    out = np.array([t for t, ok in zip(tris, alive) if ok], dtype=np.int64)
    return out, strays
