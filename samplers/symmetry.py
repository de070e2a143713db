"""A B-rep's mirror planes, found from its own entities.

A part drawn symmetric (a regular prism, a star, a bracket) is scanned best
along its symmetry, and only a symmetric choice turns with the part whatever
the turn: among a model's candidate frames of equal merit, one lined up with
a mirror of the part is the same frame (up to the mirror) in every placement
(:func:`sr33.samplers.frame.model_frame` uses it).

A mirror of a solid fixes its centre of mass and permutes its topological
entities: its vertices go onto vertices, its edges onto edges of the same
length with the centres of mass swapped alike, its faces onto faces of the
same area.  :func:`mirror_normals` tries the plane through the centre of mass
that swaps each pair of vertices (the only planes that can move a vertex onto
another) and keeps those under which all three sets go onto themselves.  The
test reads positions, lengths and areas only, compared within a tolerance of
the model's size, so the answer turns with the model and does not hang on a
float's last bit.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

from .faces import exact_bounds

TOL = 1e-6  # positions, lengths and areas are equal within this share of the model's size
MAX_VERTICES = 400  # the vertex pairs tried: the first this many vertices (B-rep order)


def _entities(solid):
    """Vertices, edges' (centre, length), faces' (centre, area), the solid's
    centre of mass and its size (bounding-box diagonal)."""
    verts = np.array([v.toTuple() for v in solid.Vertices()], dtype=np.float64).reshape(-1, 3)
    edges = solid.Edges()
    ec = np.array([e.Center().toTuple() for e in edges], dtype=np.float64).reshape(-1, 3)
    el = np.array([e.Length() for e in edges], dtype=np.float64)
    faces = solid.Faces()
    fc = np.array([f.Center().toTuple() for f in faces], dtype=np.float64).reshape(-1, 3)
    fa = np.array([f.Area() for f in faces], dtype=np.float64)
    centre = np.asarray(solid.Center().toTuple(), dtype=np.float64)
    lo, hi = exact_bounds(solid)
    return verts, (ec, el), (fc, fa), centre, float(np.linalg.norm(hi - lo))


def _maps_onto(points: np.ndarray, tree, weights, n, centre, tol, wtol) -> bool:
    """Whether reflecting ``points`` (their tree ``tree``) in the plane
    through ``centre`` with unit normal ``n`` puts every point within
    ``tol`` of one of them whose weight (a length, an area; None: no
    weights) is equal within ``wtol``, one to one."""
    if points.shape[0] == 0:
        return True
    image = points - 2.0 * ((points - centre) @ n)[:, None] * n
    d, j = tree.query(image)
    if d.max() > tol or np.unique(j).size != j.size:
        return False
    return weights is None or bool(np.abs(weights[j] - weights).max() <= wtol)


def mirror_normals(solid) -> np.ndarray:
    """Unit normals of the solid's mirror planes (each through its centre of mass).

    Parameters
    ----------
    solid : cadquery.Shape

    Returns
    -------
    (m, 3) float64
        One normal per mirror (its sign as the first vertex pair gave it), in
        the order the vertex pairs are met (B-rep order, which turning the
        model keeps).  Empty for a model without vertices (a ball, a torus)
        or without a mirror that moves one.

    Examples
    --------
    >>> import cadquery as cq
    >>> box = cq.Workplane().box(2, 1, 0.5).val()
    >>> np.abs(mirror_normals(box)).round(6).tolist()
    [[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]]
    """
    verts, (ec, el), (fc, fa), centre, size = _entities(solid)
    tol = TOL * max(size, 1e-300)
    v = verts[:MAX_VERTICES]
    if v.shape[0] < 2:
        return np.zeros((0, 3))
    i, j = np.triu_indices(v.shape[0], 1)
    d = v[i] - v[j]
    length = np.linalg.norm(d, axis=1)
    ok = length > tol
    n = d[ok] / length[ok][:, None]
    mid = 0.5 * (v[i][ok] + v[j][ok])
    # the plane bisecting the pair must hold the centre of mass
    n = n[np.abs(((centre - mid) * n).sum(axis=1)) <= tol]
    # each direction is tried once (its sign made positive on its largest
    # component, rounded well above TOL's spread); the first pair's sign kept
    lead = np.argmax(np.abs(n), axis=1)
    canon = n * np.sign(n[np.arange(n.shape[0]), lead])[:, None]
    _, first = np.unique(np.round(canon, 6), axis=0, return_index=True)
    n = n[np.sort(first)]
    trees = [cKDTree(p) for p in (verts, ec, fc)]
    # a quick cut, all directions at once: the first vertices' images must be vertices
    for p in verts[:8]:
        image = p - 2.0 * ((p - centre) @ n.T)[:, None] * n
        n = n[trees[0].query(image)[0] <= tol]
    out: list[np.ndarray] = []
    for cand in n:
        if any(abs(float(cand @ m)) >= 1.0 - TOL for m in out):
            continue
        if (
            _maps_onto(verts, trees[0], None, cand, centre, tol, 0.0)
            and _maps_onto(ec, trees[1], el, cand, centre, tol, tol)
            and _maps_onto(fc, trees[2], fa, cand, centre, tol, tol * size)
        ):
            out.append(cand)
    return np.array(out, dtype=np.float64).reshape(-1, 3)


def respected(axes: np.ndarray, normals: np.ndarray, tol: float = 1e-7) -> int:
    """How many of the mirrors ``normals`` map the frame ``axes`` (rows) onto
    itself up to signs: the mirror's normal lies along an axis, or is
    perpendicular to one and halfway between the other two (it swaps them).

    Parameters
    ----------
    axes : (3, 3) array_like
    normals : (m, 3) array_like

    Returns
    -------
    int

    Examples
    --------
    >>> respected(np.eye(3), np.array([[0.0, 0.0, 1.0], [1.0, 0.0, -1.0] / np.sqrt(2)]))
    2
    >>> respected(np.eye(3), np.array([[np.cos(0.3), np.sin(0.3), 0.0]]))
    0
    """
    a = np.asarray(axes, dtype=np.float64)
    m = np.asarray(normals, dtype=np.float64).reshape(-1, 3)
    if m.shape[0] == 0:
        return 0
    c = np.abs(m @ a.T)  # (m, 3) cosines with the axes
    along = (c >= 1.0 - tol).any(axis=1)
    half = np.sqrt(0.5)
    swaps = ((c < tol).sum(axis=1) == 1) & ((np.abs(c - half) < tol).sum(axis=1) == 2)
    return int((along | swaps).sum())


__all__ = ["MAX_VERTICES", "TOL", "mirror_normals", "respected"]
