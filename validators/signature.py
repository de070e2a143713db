"""Topology signature of a triangle mesh and the homeomorphism verdict.

By the classification of compact surfaces, a 2-manifold (with boundary) is
determined up to homeomorphism by, per connected component, its
orientability, Euler characteristic and number of boundary loops.
:func:`signature` computes these (plus genus and defects) with vectorized
numpy and ``scipy.sparse.csgraph``; :func:`homeomorphic` compares two
signatures and lists every reason when they differ.

Orientability uses the orientation double cover: every triangle t gets two
nodes (t, +) and (t, −); two triangles sharing a manifold edge are joined
"straight" when they traverse it in opposite directions (coherent) and
"crossed" otherwise.  A component is orientable exactly when no (t, +) is
connected to its own (t, −).  The rule for a flipped face: it is still
orientable (flip it back) — orientability is a property of the surface, not
of the stored winding; ``incoherent_edges`` counts edges whose two triangles
disagree as stored.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy import sparse
from scipy.sparse import csgraph

from sr33.mesh import (
    as_triangles,
    edge_incidence,
    half_edges,
    orientation_double_cover,
    unique_rows,
)

__all__ = [
    "Component",
    "Signature",
    "Verdict",
    "homeomorphic",
    "orientation_double_cover",
    "signature",
]


@dataclass(frozen=True)
class Component:
    """One connected component of a mesh.

    Attributes
    ----------
    faces : int
    vertices : int
    euler : int
    boundary_loops : int
    orientable : bool
    genus : int
        Orientable: ``(2 - euler - boundary_loops) / 2``; non-orientable: the
        number of cross-caps ``2 - euler - boundary_loops``.
    """

    faces: int
    vertices: int
    euler: int
    boundary_loops: int
    orientable: bool
    genus: int

    def key(self) -> tuple[bool, int, int]:
        """What the classification of surfaces compares."""
        return (self.orientable, self.euler, self.boundary_loops)


@dataclass(frozen=True)
class Signature:
    """Topology signature and defects of a triangle mesh.

    Attributes
    ----------
    components : tuple of Component
        Sorted by (orientable, euler, boundary loops, faces).
    manifold : bool
        No overloaded edge, no non-manifold vertex, no duplicate or
        degenerate face.
    overloaded_edges : int
        Edges with three or more triangles.
    non_manifold_vertices : (q,) int64
        Vertices whose triangles form more than one fan (or sit on an
        overloaded edge).
    duplicate_faces : int
        Triangles repeating another's vertex set.
    degenerate_faces : int
        Triangles with a repeated vertex (or zero area when points are given).
    incoherent_edges : int
        Manifold edges whose two triangles traverse them in the same direction.
    unused_points : int
        Points of the vertex table no triangle uses (when ``n_points`` given).
    """

    components: tuple[Component, ...]
    manifold: bool
    overloaded_edges: int
    non_manifold_vertices: np.ndarray
    duplicate_faces: int
    degenerate_faces: int
    incoherent_edges: int
    unused_points: int = 0
    notes: tuple[str, ...] = field(default=())

    @property
    def orientable(self) -> bool:
        return all(c.orientable for c in self.components)

    @property
    def euler(self) -> int:
        return sum(c.euler for c in self.components)


def _fans(tri: np.ndarray, n: int) -> np.ndarray:
    """Number of fans (edge-connected triangle groups) around every vertex."""
    t = tri.shape[0]
    # corner c of triangle i at vertex v; its two edges at v are (v, a) and (v, b)
    v = tri.ravel()
    a = np.roll(tri, -1, axis=1).ravel()
    b = np.roll(tri, 1, axis=1).ravel()
    corner = np.arange(3 * t)
    # corners at the same vertex sharing an edge (v, x) are in one fan
    keys = np.concatenate([v * n + a, v * n + b])
    owner = np.concatenate([corner, corner])
    order = np.argsort(keys, kind="stable")
    ks, ow = keys[order], owner[order]
    same = np.flatnonzero(ks[1:] == ks[:-1])
    g = sparse.csr_matrix(
        (np.ones(same.shape[0], dtype=np.int8), (ow[same], ow[same + 1])), shape=(3 * t, 3 * t)
    )
    _, labels = csgraph.connected_components(g, directed=False)
    pairs = np.unique(v * (3 * t) + labels)
    return np.bincount(pairs // (3 * t), minlength=n)


def signature(triangles, n_points: int | None = None, points=None) -> Signature:
    """Topology signature of a triangle mesh (classification of surfaces).

    Parameters
    ----------
    triangles : (t, 3) array_like of int
    n_points : int, optional
        Size of the vertex table (for ``unused_points``).
    points : (n, 3) array_like of float, optional
        Vertex positions, to flag zero-area triangles as degenerate.

    Returns
    -------
    Signature

    Examples
    --------
    >>> s = signature([(0, 1, 2), (0, 3, 1), (1, 3, 2), (2, 3, 0)])
    >>> [c.key() for c in s.components], s.manifold
    ([(True, 2, 0)], True)
    """
    tri = as_triangles(triangles)
    n = int(tri.max()) + 1 if tri.size else 0
    if n_points is not None:
        n = max(n, int(n_points))
    t = tri.shape[0]
    if t == 0:
        return Signature((), True, 0, np.empty(0, np.int64), 0, 0, 0, n)
    degenerate = (tri[:, 0] == tri[:, 1]) | (tri[:, 1] == tri[:, 2]) | (tri[:, 0] == tri[:, 2])
    if points is not None:
        p = np.asarray(points, dtype=np.float64)
        cr = np.cross(p[tri[:, 1]] - p[tri[:, 0]], p[tri[:, 2]] - p[tri[:, 0]])
        degenerate |= np.linalg.norm(cr, axis=1) == 0
    duplicate = int(t - unique_rows(np.sort(tri, axis=1)).shape[0])
    inc = edge_incidence(*half_edges(tri), n)
    counts = inc.counts
    overloaded = int((counts > 2).sum())
    # manifold edges: exactly two uses
    _, fa, fb, coherent = inc.manifold_pairs()
    incoherent = int((~coherent).sum())
    # components through shared vertices (a pinch joins them, as the surface does)
    vert_adj = sparse.csr_matrix(
        (np.ones(3 * t, dtype=np.int8), (np.repeat(np.arange(t), 3), tri.ravel())), shape=(t, n)
    )
    gf = (vert_adj @ vert_adj.T).tocsr()
    ncomp, comp = csgraph.connected_components(gf, directed=False)
    dlab = orientation_double_cover(t, fa, fb, coherent)
    twisted = dlab[:t] == dlab[t:]
    comp_orientable = np.ones(ncomp, dtype=bool)
    comp_orientable[comp[twisted]] = False
    # per component figures
    f_per = np.bincount(comp, minlength=ncomp)
    edge_face = inc.face[inc.order[inc.start]]  # a triangle of every edge
    e_per = np.bincount(comp[edge_face], minlength=ncomp)
    used = np.unique(tri)
    vcomp = np.full(n, -1)
    vcomp[tri.ravel()] = np.repeat(comp, 3)
    v_per = np.bincount(vcomp[used], minlength=ncomp)
    open_e = inc.edges[counts == 1]
    ol, oh = open_e[:, 0], open_e[:, 1]
    og = sparse.csr_matrix((np.ones(ol.shape[0], dtype=np.int8), (ol, oh)), shape=(n, n))
    _, olab = csgraph.connected_components(og, directed=False)
    onodes = np.unique(np.concatenate([ol, oh]))
    loop_ids = np.unique(olab[onodes])
    loops_per = np.zeros(ncomp, dtype=np.int64)
    if loop_ids.shape[0]:
        first_node = {int(lbl): int(nd) for nd, lbl in zip(onodes[::-1], olab[onodes][::-1])}
        for lbl in loop_ids.tolist():
            loops_per[vcomp[first_node[lbl]]] += 1
    comps = []
    for c in range(ncomp):
        chi = int(v_per[c] - e_per[c] + f_per[c])
        b = int(loops_per[c])
        orient = bool(comp_orientable[c])
        genus = (2 - chi - b) // 2 if orient else 2 - chi - b
        comps.append(Component(int(f_per[c]), int(v_per[c]), chi, b, orient, int(genus)))
    comps.sort(key=lambda c: (c.orientable, c.euler, c.boundary_loops, c.faces))
    fans = _fans(tri, n)
    nm = np.flatnonzero(fans > 1)
    if overloaded:
        nm = np.union1d(nm, inc.edges[counts > 2].ravel())
    unused = int(n - used.shape[0]) if n_points is not None else 0
    manifold = overloaded == 0 and nm.shape[0] == 0 and duplicate == 0 and not degenerate.any()
    return Signature(
        components=tuple(comps),
        manifold=bool(manifold),
        overloaded_edges=overloaded,
        non_manifold_vertices=nm.astype(np.int64),
        duplicate_faces=duplicate,
        degenerate_faces=int(degenerate.sum()),
        incoherent_edges=incoherent,
        unused_points=unused,
    )


@dataclass(frozen=True)
class Verdict:
    """Answer of :func:`homeomorphic`: ``bool(verdict)`` and every reason."""

    homeomorphic: bool
    reasons: tuple[str, ...]

    def __bool__(self) -> bool:
        return self.homeomorphic


def homeomorphic(mesh, truth) -> Verdict:
    """Whether two triangle meshes are homeomorphic surfaces, with reasons.

    Parameters
    ----------
    mesh, truth : (t, 3) array_like of int, or Signature
        Triangles (or precomputed signatures).

    Returns
    -------
    Verdict
        False with reasons when either is not a 2-manifold, or their
        components differ in number, orientability, Euler characteristic or
        boundary loops.
    """
    a = mesh if isinstance(mesh, Signature) else signature(mesh)
    b = truth if isinstance(truth, Signature) else signature(truth)
    reasons: list[str] = []
    for name, s in (("mesh", a), ("truth", b)):
        if s.overloaded_edges:
            reasons.append(f"{name} has {s.overloaded_edges} overloaded edges")
        if s.non_manifold_vertices.shape[0]:
            reasons.append(f"{name} has {s.non_manifold_vertices.shape[0]} non-manifold vertices")
        if s.duplicate_faces:
            reasons.append(f"{name} has {s.duplicate_faces} duplicate faces")
        if s.degenerate_faces:
            reasons.append(f"{name} has {s.degenerate_faces} degenerate faces")
    if len(a.components) != len(b.components):
        reasons.append(f"components: mesh has {len(a.components)}, truth has {len(b.components)}")
    ka = sorted(c.key() for c in a.components)
    kb = sorted(c.key() for c in b.components)
    if len(a.components) == len(b.components) and ka != kb:
        for x, y in zip(ka, kb):
            if x == y:
                continue
            if x[0] != y[0]:
                word = {True: "orientable", False: "non-orientable"}
                reasons.append(
                    f"orientability: mesh component is {word[x[0]]}, truth's is {word[y[0]]}"
                )
            if x[1] != y[1]:
                reasons.append(f"Euler characteristic: mesh {x[1]}, truth {y[1]}")
            if x[2] != y[2]:
                reasons.append(f"boundary loops: mesh {x[2]}, truth {y[2]}")
    return Verdict(homeomorphic=not reasons, reasons=tuple(reasons))
