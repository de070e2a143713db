"""Which faces of a B-rep bound which edges (OCC's edge-to-face map).

One map serves both the scan-line sampler (which edges are sharp, which
faces an edge's samples belong to) and the boundary-layer repair (the face
across each edge of a planar face).  CadQuery and OCP are imported when
the functions run.
"""

from __future__ import annotations

import numpy as np

from sr33.mesh import norm


def face_index(face, faces) -> int:
    """Index of ``face`` in ``faces`` (same TShape and location), -1 if absent."""
    for i, f in enumerate(faces):
        if f.isSame(face):
            return i
    return -1


class EdgeFaces:
    """The shape's edges with the faces on either side.

    ``edges[i]`` is the i-th edge of OCC's map, ``faces_of[i]`` the indices
    (into ``shape.Faces()``) of the distinct faces it bounds, in the map's
    order, and ``uses[i]`` how many times faces use it (2 with one face is
    a seam).
    """

    def __init__(self, occ):
        import cadquery as cq
        from OCP.TopAbs import TopAbs_EDGE, TopAbs_FACE
        from OCP.TopExp import TopExp
        from OCP.TopTools import TopTools_IndexedDataMapOfShapeListOfShape

        self.faces = occ.Faces()
        self._map = TopTools_IndexedDataMapOfShapeListOfShape()
        TopExp.MapShapesAndAncestors_s(occ.wrapped, TopAbs_EDGE, TopAbs_FACE, self._map)
        self.edges = []
        self.faces_of: list[list[int]] = []
        self.uses: list[int] = []
        for i in range(1, self._map.Extent() + 1):
            self.edges.append(cq.Edge(self._map.FindKey(i)))
            adj = [cq.Face(f) for f in self._map.FindFromIndex(i)]
            uniq: list[int] = []
            for f in adj:
                k = face_index(f, self.faces)
                if k not in uniq:
                    uniq.append(k)
            self.faces_of.append(uniq)
            self.uses.append(len(adj))
        self._bends: dict[int, float | None] = {}
        self._straight: dict[float, tuple[dict, dict]] = {}

    def index(self, edge) -> int:
        """Position of ``edge`` in :attr:`edges` (-1 if it bounds no face)."""
        return self._map.FindIndex(edge.wrapped) - 1

    def other(self, edge, fi: int) -> int:
        """The lowest index of a face other than ``fi`` bounded by ``edge``
        (-1: none, a boundary, a seam, or an edge of no face)."""
        k = self.index(edge)
        others = [j for j in self.faces_of[k] if j != fi] if k >= 0 else []
        return min(others) if others else -1

    def across(self) -> list[list[tuple[object, int]]]:
        """Per face, each of its edges (in the face's order) and the lowest
        index of another face bounded by it (-1: none, a boundary or a seam)."""
        return [
            [(e, self.other(e, fi)) for e in face.Edges()] for fi, face in enumerate(self.faces)
        ]

    def bend(self, k: int) -> float | None:
        """The cosine between the normals of the two faces of edge ``k`` at
        its middle (1: the surface goes on flat across it; -1: it folds
        right back), None unless it bounds two faces; computed once."""
        if k not in self._bends:
            fids = self.faces_of[k]
            out = None
            if len(fids) == 2:
                mid = self.edges[k].positionAt(0.5, mode="length")
                n1 = np.array(self.faces[fids[0]].normalAt(mid).toTuple())
                n2 = np.array(self.faces[fids[1]].normalAt(mid).toTuple())
                out = float(np.dot(n1, n2))
            self._bends[k] = out
        return self._bends[k]

    def straight(self, tol: float) -> tuple[dict, dict]:
        """The straight edges longer than ``tol`` (edge index -> start, unit
        direction, length) and, per face, its straight edges' indices;
        computed once per ``tol`` (the scan's strip rows and its edges'
        followers read the same table: not to be modified)."""
        if tol not in self._straight:
            lines: dict[int, tuple[np.ndarray, np.ndarray, float]] = {}
            for ei, e in enumerate(self.edges):
                if e.geomType() == "LINE" and e.Length() > tol:
                    a = np.array(e.startPoint().toTuple())
                    b = np.array(e.endPoint().toTuple())
                    lines[ei] = (a, (b - a) / norm(b - a), float(norm(b - a)))
            by_face: dict[int, list[int]] = {}
            for ei in lines:
                for k in self.faces_of[ei]:
                    by_face.setdefault(k, []).append(ei)
            self._straight[tol] = (lines, by_face)
        return self._straight[tol]

    def folded(self, degrees: float) -> set[tuple[int, int]]:
        """Pairs of faces (both orders) that meet along an edge where the
        surface folds back sharper than ``degrees``: their normals at the
        edge's middle more than ``180 - degrees`` apart (:meth:`bend`; an
        acute edge, or a narrow slot's reflex one).  Near such an edge the
        two faces' points are near in space and far on the surface."""
        limit = np.cos(np.radians(180.0 - degrees))
        out: set[tuple[int, int]] = set()
        for k, fids in enumerate(self.faces_of):
            bend = self.bend(k)
            if bend is not None and bend < limit:
                out |= {(fids[0], fids[1]), (fids[1], fids[0])}
        return out
