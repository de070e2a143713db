"""Triangulate (line 4 of Algorithm 1, Section 4) and the orientation of faces.

Every face cycle is split into triangles whose interiors are pairwise
disjoint and whose union is bounded by the cycle.  Each cycle is first
oriented coherently with its neighbours (faces sharing an edge traverse it in
opposite directions), so the triangles come out consistently oriented on
every orientable component, outward on closed ones.

A cycle of length L is triangulated by dynamic programming over its
diagonals (O(L³), L <= max cycle length): minimum total area, never a
diagonal that is already an edge of another face (it would be used three
times).  Ties, such as the two diagonals of a planar square, are broken by
the shorter diagonal, then by the diagonal through the vertex nearest to the
centroid of all samples (invariant under rigid motion and scaling), and only
then by the canonical order of the samples.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import sparse
from scipy.sparse import csgraph

from ._kernels import min_area_splits
from ._validate import InputError, as_points
from .cycles import CycleSet
from .graph import cycle_edges
from .mesh import edge_incidence, edge_keys, orientation_double_cover


@dataclass(frozen=True)
class Triangulation:
    """Result of :func:`triangulate`.

    Attributes
    ----------
    triangles : (t, 3) int64
        Vertex indices, consistently oriented where the surface is orientable.
    face_of_triangle : (t,) int64
        The face cycle each triangle came from.
    orientable : bool
        False when some component could not be oriented coherently.
    """

    triangles: np.ndarray
    face_of_triangle: np.ndarray
    orientable: bool


def _reversed(cs: CycleSet, mask: np.ndarray) -> CycleSet:
    """The cycles with those in ``mask`` reversed (first vertex kept)."""
    lengths = cs.lengths
    owner = np.repeat(np.arange(len(cs)), lengths)
    pos = np.arange(cs.vertices.shape[0])
    j = pos - cs.offsets[owner]
    src = np.where(mask[owner] & (j > 0), cs.offsets[owner] + lengths[owner] - j, pos)
    return CycleSet(offsets=cs.offsets, vertices=cs.vertices[src])


def orient_cycles(points: np.ndarray, faces: CycleSet) -> tuple[CycleSet, bool]:
    """Reverse cycles so that neighbours traverse shared edges oppositely.

    Faces sharing an edge used by exactly two faces are linked; on each
    component the faces are oriented like its canonically smallest face,
    read off the orientation double cover
    (:func:`sr33.mesh.orientation_double_cover`); closed
    components are then flipped to enclose positive volume.  Returns the
    oriented cycles and whether every component was orientable.
    """
    n = points.shape[0]
    nf = len(faces)
    if nf == 0:
        return faces, True
    pairs, owner = cycle_edges(faces.offsets, faces.vertices)
    # only edges shared by exactly two faces link faces
    _, fa, fb, coherent = edge_incidence(pairs, owner, n).manifold_pairs()
    g = sparse.csr_matrix(
        (np.ones(fa.shape[0] * 2, dtype=np.int8), (np.r_[fa, fb], np.r_[fb, fa])), shape=(nf, nf)
    )
    ncomp, labels = csgraph.connected_components(g, directed=False)
    dlab = orientation_double_cover(nf, fa, fb, coherent)
    orientable = bool(np.all(dlab[:nf] != dlab[nf:]))
    _, root = np.unique(labels, return_index=True)  # smallest face of each component
    flip = dlab[:nf] != dlab[root[labels]]
    oriented = _reversed(faces, flip)
    # signed volume per component, from a fan triangulation of each cycle
    lengths = faces.lengths
    p0 = points[oriented.vertices[oriented.offsets[:-1]]]
    vol = np.zeros(nf)
    for L in np.unique(lengths):
        sel = np.flatnonzero(lengths == L)
        base = oriented.offsets[sel]
        for j in range(1, L - 1):
            p1 = points[oriented.vertices[base + j]]
            p2 = points[oriented.vertices[base + j + 1]]
            vol[sel] += np.einsum("ij,ij->i", p0[sel], np.cross(p1, p2))
    comp_vol = np.bincount(labels, weights=vol, minlength=ncomp)
    neg = comp_vol[labels] < 0
    if neg.any():
        oriented = _reversed(oriented, neg)
    return oriented, orientable


def _cmp(x: np.ndarray, y: np.ndarray, rtol: float) -> np.ndarray:
    """Elementwise -1, 0, 1 comparison with a relative tie tolerance."""
    tie = np.abs(x - y) <= rtol * np.maximum(np.abs(x), np.abs(y))
    return np.where(tie, 0, np.where(x < y, -1, 1))


def _area(points, a, b, c):
    return 0.5 * np.linalg.norm(np.cross(points[b] - points[a], points[c] - points[a]), axis=-1)


def _triangulate_polygon(points, cyc, forbidden: set, rtol: float):
    """Minimum-area triangulation of one cycle avoiding ``forbidden`` diagonals
    (the dynamic programme is :func:`sr33._kernels.min_area_splits`)."""
    L = cyc.shape[0]
    if L == 3:
        return [tuple(int(v) for v in cyc)]
    c = [int(v) for v in cyc]
    allowed = np.ones((L, L), dtype=bool)
    for i in range(L):
        for j in range(i + 2, L - (i == 0)):
            if (min(c[i], c[j]), max(c[i], c[j])) in forbidden:
                allowed[i, j] = False
    split, feasible = min_area_splits(np.ascontiguousarray(points[cyc]), allowed, float(rtol))
    if not feasible:
        # every diagonal choice is blocked: fall back to a fan from the first vertex
        return [(c[0], c[j], c[j + 1]) for j in range(1, L - 1)]
    out = []
    stack = [(0, L - 1)]
    while stack:
        i, j = stack.pop()
        if j - i < 2:
            continue
        m = int(split[i, j])
        out.append((c[i], c[m], c[j]))
        stack.append((i, m))
        stack.append((m, j))
    return out


def triangulate(
    points,
    faces: CycleSet,
    *,
    rtol: float = 1e-9,
    centres: dict[int, int] | None = None,
    patches: dict[int, np.ndarray] | None = None,
) -> Triangulation:
    """Triangulate(◇): line 4 of Algorithm 1, triangles with disjoint interiors.

    Parameters
    ----------
    points : (n, 3) array_like of float
        The samples.
    faces : CycleSet
        Selected face cycles (:attr:`FaceSelection.faces`).
    rtol : float
        Relative tolerance for area ties (see :mod:`sr33.tolerance`).
    centres : dict of int to int, optional
        Face index -> a sample no face uses that lies inside that face (a
        cone tip the face cycle rings around).  Such a face becomes the cone
        of the paper's Section 5 from that sample: one triangle per cycle
        edge, instead of a triangulation across the ring.
    patches : dict of int to (t, 3) int64, optional
        Face index -> its triangles with the samples inside it
        (:func:`sr33.patches.stray_patches`): a disk bounded by the cycle
        (or by the boundary of several faces: the others map to no
        triangles), its triangles oriented alike.  They are taken as they
        are and oriented with the face; their chords are kept off the other
        faces' triangulations.

    Returns
    -------
    Triangulation

    Examples
    --------
    >>> import numpy as np
    >>> from sr33 import triangulate
    >>> from sr33.cycles import CycleSet
    >>> sq = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], float)
    >>> faces = CycleSet(np.array([0, 4]), np.array([0, 1, 2, 3]))
    >>> triangulate(sq, faces).triangles.shape
    (2, 3)
    """
    pts = as_points(points)
    if not isinstance(faces, CycleSet):
        raise InputError(f"faces must be a CycleSet, got {type(faces).__name__}")
    if len(faces) and (faces.vertices.min() < 0 or faces.vertices.max() >= pts.shape[0]):
        raise InputError("faces index points out of range")
    oriented, orientable = orient_cycles(pts, faces)
    pairs, _ = cycle_edges(oriented.offsets, oriented.vertices)
    n = pts.shape[0]
    lengths = oriented.lengths
    tri_parts: list[np.ndarray] = []
    own_parts: list[np.ndarray] = []
    coned = np.zeros(len(oriented), dtype=bool)
    for fi, apex in sorted((centres or {}).items()):
        if not 0 <= fi < len(oriented) or not 0 <= apex < n:
            raise InputError(f"centres maps face {fi} to sample {apex}: out of range")
        cyc = oriented.cycle(fi)
        fan = np.stack([np.full(cyc.shape[0], apex), cyc, np.roll(cyc, -1)], axis=1)
        tri_parts.append(fan.astype(np.int64))
        own_parts.append(np.full(cyc.shape[0], fi, dtype=np.int64))
        coned[fi] = True
    chords = []
    for fi, given in sorted((patches or {}).items()):
        if not 0 <= fi < len(oriented) or coned[fi]:
            raise InputError(f"patches names face {fi}: out of range or coned from a centre")
        t = np.asarray(given, dtype=np.int64).reshape(-1, 3)
        coned[fi] = True
        if t.shape[0] == 0:
            continue  # a face whose patch another face of its polygon carries
        # oriented by the first of the face's edges on the patch's boundary
        cyc = oriented.cycle(fi)
        ahead = None
        for a, b in zip(cyc.tolist(), np.roll(cyc, -1).tolist()):
            fwd = np.any((t == a) & (np.roll(t, -1, axis=1) == b))
            back = np.any((t == b) & (np.roll(t, -1, axis=1) == a))
            if fwd != back:
                ahead = bool(fwd)
                break
        if ahead is None:
            raise InputError(f"patches gives face {fi} triangles on none of its edges")
        t = t if ahead else t[:, ::-1]
        tri_parts.append(t)
        own_parts.append(np.full(t.shape[0], fi, dtype=np.int64))
        chords.append(edge_keys(t, np.roll(t, -1, axis=1), n).ravel())
    # triangles stay as they are
    t3 = np.flatnonzero((lengths == 3) & ~coned)
    if t3.shape[0]:
        tri_parts.append(oriented.vertices[oriented.offsets[t3][:, None] + np.arange(3)])
        own_parts.append(t3)
    # quads, vectorized: the common case
    q4 = np.flatnonzero((lengths == 4) & ~coned)
    face_keys = np.unique(np.concatenate([edge_keys(pairs[:, 0], pairs[:, 1], n), *chords]))
    sequential = [int(i) for i in np.flatnonzero((lengths > 4) & ~coned)]
    if q4.shape[0]:
        q = oriented.vertices[oriented.offsets[q4][:, None] + np.arange(4)]
        a, b, c, d = q.T
        k_ac = edge_keys(a, c, n)
        k_bd = edge_keys(b, d, n)
        ac_ok = ~np.isin(k_ac, face_keys)
        bd_ok = ~np.isin(k_bd, face_keys)
        area_ac = _area(pts, a, b, c) + _area(pts, a, c, d)
        area_bd = _area(pts, a, b, d) + _area(pts, b, c, d)
        len_ac = np.linalg.norm(pts[a] - pts[c], axis=1)
        len_bd = np.linalg.norm(pts[b] - pts[d], axis=1)
        # ties (planar squares): the diagonal through the vertex nearest to
        # the centroid of all samples, a rigid-motion invariant rule
        g = pts.mean(axis=0)
        r = np.linalg.norm(pts - g, axis=1)
        near_ac = np.minimum(r[a], r[c])
        near_bd = np.minimum(r[b], r[d])
        cmp = _cmp(area_ac, area_bd, rtol)
        cmp = np.where(cmp == 0, _cmp(len_ac, len_bd, rtol), cmp)
        cmp = np.where(cmp == 0, _cmp(near_ac, near_bd, 1e3 * rtol), cmp)
        use_ac = (cmp < 0) | ((cmp == 0) & (np.minimum(a, c) < np.minimum(b, d)))
        use_ac = np.where(ac_ok != bd_ok, ac_ok, use_ac)
        diag = np.where(use_ac, k_ac, k_bd)
        # a diagonal shared by two quads (or blocked both ways) is decided one by one
        _, inv, cnt = np.unique(diag, return_inverse=True, return_counts=True)
        clash = (cnt[inv] > 1) | ~(ac_ok | bd_ok)
        ok = ~clash
        t_ac = np.stack([np.stack([a, b, c], 1), np.stack([a, c, d], 1)], 1)
        t_bd = np.stack([np.stack([a, b, d], 1), np.stack([b, c, d], 1)], 1)
        tq = np.where(use_ac[:, None, None], t_ac, t_bd)[ok].reshape(-1, 3)
        tri_parts.append(tq)
        own_parts.append(np.repeat(q4[ok], 2))
        face_keys = np.union1d(face_keys, diag[ok])
        sequential += [int(i) for i in q4[clash]]
    forbidden = set()
    for key in face_keys.tolist():
        forbidden.add((key // n, key % n))
    for i in sorted(sequential):
        new = _triangulate_polygon(pts, oriented.cycle(i), forbidden, rtol)
        for t in new:
            for x, y in ((t[0], t[1]), (t[1], t[2]), (t[2], t[0])):
                forbidden.add((min(x, y), max(x, y)))
        tri_parts.append(np.array(new, dtype=np.int64).reshape(-1, 3))
        own_parts.append(np.full(len(new), i, dtype=np.int64))
    tri = np.concatenate(tri_parts).astype(np.int64) if tri_parts else np.empty((0, 3), np.int64)
    owner = np.concatenate(own_parts).astype(np.int64) if own_parts else np.empty(0, np.int64)
    order = np.argsort(owner, kind="stable")
    tri, owner = tri[order], owner[order]
    return Triangulation(triangles=tri, face_of_triangle=owner, orientable=orientable)
