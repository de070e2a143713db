"""Right square pyramids laid out as one lattice (Condition III-ii).

A square pyramid's lateral faces are triangles whose scan rows end on two
slanted edges at once; the boundary layers there, at the base corners
(three faces meeting at 90 + 2 beta degrees) and round the apex (four at
4 alpha) are where the scan rows and their repair left 2% of the samples
breaking Condition III-ii (pyramid of height 0.8 on a unit base).  A right
pyramid whose lateral faces' base angle beta satisfies ``sin(beta) <=
MAX_RATIO`` (height below about 0.55 of the base) needs no repair at all:

* the base is an N x N square lattice of step ``c = W / N`` (N even),
  its edges' samples included;
* each lateral face is swept by the planes parallel to the base through
  the base lattice's rows, ``N / 2`` of them up to the apex: row ``k``
  runs between the two lateral edges ``k / (N / 2)`` of the way up and is
  divided into ``N - 2k`` equal steps of ``c``, so that its samples stand
  on the columns of the base lattice (the rows ``c tan(beta)`` apart in the
  face, the cells rectangles with ratio ``sin(beta)``) and every lateral
  edge is a diagonal of the cells on both its sides (its samples are
  where the rows cross it);
* the rectangle cells on either side of a lateral edge are cocircular
  across it: the intrinsic Delaunay triangulation could join the two
  samples next to it instead (an isosceles triangle of ratio
  ``1 / (2 cos(beta))``, 0.866 at beta = 54.7 degrees).  Those samples step
  ``TIE_SHIFT c`` away from the edge (the one below the apex down the
  face's midline), which decides the tie for the edge (the default
  pyramid: worst ratio 0.830, no sample breaking III-ii; 0.866 with the
  tie left to the triangulation).

N is the even number nearest ``W sqrt(tan(beta)) / h``, so the cells' two
sides are about ``h / sqrt(tan(beta))`` and ``h sqrt(tan(beta))`` (their
geometric mean is h); the sweep directions and the sampler's row ratio do
not apply (the lattice's ratio is the face's ``1 / tan(beta)``).  Taller
pyramids, and pyramids so flat that samples across a base edge would be
closer than ``MIN_GAP`` h (the default's are c apart), keep the scan rows
and their repair (:mod:`sr33.samplers.layers`).
CadQuery is imported when the functions run.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.spatial import Delaunay

from sr33 import libm
from sr33.mesh import dot, norm, triangle_ratios

from .adjacency import EdgeFaces
from .faces import nearest_face, steps
from .repair import BAD
from .samples import Samples

MAX_RATIO = 0.83  # lateral cells of a larger ratio sin(beta): the pyramid keeps its scan rows
TIE_SHIFT = 0.02  # samples next to a lateral edge step this far from it (times c)
MIN_GAP = 0.5  # base and lateral samples closer than this (times h) across a base edge: scan rows


@dataclass(frozen=True)
class Pyramid:
    """A right pyramid on a square base.

    Attributes
    ----------
    apex : (3,) float64
    corners : (4, 3) float64
        The base's corners in order round it.
    base : int
        Index of the base face.
    lateral : tuple of int
        Index of the lateral face on ``corners[k]``, ``corners[k + 1]``.
    """

    apex: np.ndarray
    corners: np.ndarray
    base: int
    lateral: tuple[int, ...]

    @property
    def width(self) -> float:
        return float(norm(self.corners[1] - self.corners[0]))

    @property
    def tan_beta(self) -> float:
        """Tangent of the lateral faces' angle at the base (slant height over half the base)."""
        mid = (self.corners[0] + self.corners[1]) / 2
        return float(norm(self.apex - mid)) / (self.width / 2)


def _vertices(face) -> np.ndarray:
    return np.array([v.toTuple() for v in face.Vertices()], dtype=np.float64)


def find_pyramid(occ, tol: float) -> Pyramid | None:
    """The right square pyramid that ``occ`` is, or None.

    Five planar faces: a square (four equal sides, equal diagonals) and
    four triangles meeting at an apex straight above the square's centre
    (within ``tol``).
    """
    faces = occ.Faces()
    if len(faces) != 5 or any(f.geomType() != "PLANE" for f in faces):
        return None
    quads = [i for i, f in enumerate(faces) if len(f.Edges()) == 4]
    tris = [i for i, f in enumerate(faces) if len(f.Edges()) == 3]
    if len(quads) != 1 or len(tris) != 4:
        return None
    base = quads[0]
    corners = _vertices(faces[base])
    if corners.shape[0] != 4:
        return None
    centre = corners.mean(axis=0)
    normal = np.array(faces[base].normalAt().toTuple())
    others = [q for i in tris for q in _vertices(faces[i])]
    tops = [q for q in others if np.linalg.norm(corners - q, axis=1).min() > tol]
    if not tops or any(norm(q - tops[0]) > tol for q in tops):
        return None
    apex = tops[0]
    # the base's corners in order round the normal, from the one the face lists first
    ref = corners[0] - centre
    side = np.cross(normal, ref)
    rel = corners - centre
    order = np.argsort(libm.arctan2(dot(rel, side), dot(rel, ref)) % (2 * math.pi), kind="stable")
    corners = corners[order]
    sides = np.linalg.norm(np.roll(corners, -1, axis=0) - corners, axis=1)
    diagonals = np.linalg.norm(corners[:2] - corners[2:], axis=1)
    axis = apex - centre
    if (
        np.ptp(sides) > tol
        or abs(diagonals[0] - diagonals[1]) > tol
        or norm(axis - (dot(axis, normal)) * normal) > tol
    ):
        return None
    lateral = []
    for k in range(4):
        a, b = corners[k], corners[(k + 1) % 4]
        for i in tris:
            v = _vertices(faces[i])
            if all(np.linalg.norm(v - q, axis=1).min() < tol for q in (a, b)):
                lateral.append(i)
                break
    if sorted(lateral) != sorted(tris):
        return None
    return Pyramid(apex=apex, corners=corners, base=base, lateral=tuple(lateral))


def pyramid_steps(width: float, tan_beta: float, h: float) -> int:
    """N, the base lattice's steps per side: the even number nearest
    ``width sqrt(tan_beta) / h`` (at least 4)."""
    return 2 * steps(width * math.sqrt(tan_beta) / 2, h, least=2)


def _worst(uv: np.ndarray) -> tuple[int, float]:
    """Triangles at or above the repair's margin, and the largest ratio
    (second-longest over longest edge), of the Delaunay triangulation of a
    face's samples in its plane."""
    ratio = triangle_ratios(uv, Delaunay(uv).simplices)
    return int(np.count_nonzero(ratio >= BAD)), float(ratio.max())


def lattice_pyramid(occ, s: Samples, h: float, size: float) -> tuple[list[dict], set[int]]:
    """Lay a right square pyramid out as one lattice (see the module's docstring).

    Replaces all the samples when ``occ`` is such a pyramid, its lateral
    cells' ratio ``sin(beta)`` is at most ``MAX_RATIO`` and the samples
    nearest to each other across a base edge are at least ``MIN_GAP`` h
    apart (a flat pyramid's base edges are acute); does nothing
    otherwise.  Samples on the edges belong to the edge's first face (as in
    the scan), the corners and the apex to the first face through them;
    every base row and every lateral row is a scan line.  Returns one
    report per face and the indices of the faces laid out.
    """
    tol = 1e-7 * size
    pyr = find_pyramid(occ, tol)
    if pyr is None:
        return [], set()
    tan_beta = pyr.tan_beta
    if tan_beta / math.hypot(1.0, tan_beta) > MAX_RATIO:
        return [], set()
    n = pyramid_steps(pyr.width, tan_beta, h)
    c = pyr.width / n
    # across a base edge (dihedral angle delta, cos(delta) = 1 / tan(beta))
    # the first samples of one column on either side are c sqrt(tan^2 - 1)
    # = 2 c height / width apart; the scan's thinning keeps h / 2
    if c * math.sqrt(max(tan_beta**2 - 1.0, 0.0)) < MIN_GAP * h:
        return [], set()
    adjacency = EdgeFaces(occ)
    faces = adjacency.faces
    a0, apex = pyr.corners[0], pyr.apex
    ex = (pyr.corners[1] - a0) / pyr.width
    ey = (pyr.corners[3] - a0) / pyr.width

    def edge_face(p, q) -> int:
        """The first face of the edge from ``p`` to ``q`` (the scan's owner of its samples)."""
        for e, fids in zip(adjacency.edges, adjacency.faces_of):
            ends = np.array([e.startPoint().toTuple(), e.endPoint().toTuple()])
            if (
                min(np.linalg.norm(ends - p, axis=1)) < tol
                and min(np.linalg.norm(ends - q, axis=1)) < tol
            ):
                return fids[0]
        raise AssertionError("a pyramid edge is missing from the edge map")

    line = int(s.line_id.max()) + 1 if s.line_id.size else 0
    pts: list[np.ndarray] = [apex[None]]
    fid: list[int] = [nearest_face(apex, faces)]
    lid: list[int] = [-1]
    feat: list[bool] = [True]
    reports = []
    # the base: N x N steps, its perimeter on the edges
    i, j = (g.ravel() for g in np.meshgrid(np.arange(n + 1), np.arange(n + 1), indexing="ij"))
    base = a0 + np.outer(i * c, ex) + np.outer(j * c, ey)
    rim = (i == 0) | (i == n) | (j == 0) | (j == n)
    owner = np.full(i.size, pyr.base)
    for k in range(4):
        a, b = pyr.corners[k], pyr.corners[(k + 1) % 4]
        on = rim & (np.abs(np.cross(base - a, b - a)).sum(axis=1) < tol * pyr.width)
        owner[on] = edge_face(a, b)
    corner = rim & ((i % n == 0) & (j % n == 0))
    owner[corner] = [nearest_face(q, faces) for q in base[corner]]
    pts.append(base)
    fid += owner.tolist()
    lid += np.where(rim, -1, line + j).tolist()
    feat += rim.tolist()
    line += n + 1
    bad, worst = _worst(np.stack([i * c, j * c], axis=1).astype(np.float64))
    reports.append(
        {
            "face": pyr.base,
            "kind": "pyramid lattice",
            "rows": n - 1,
            "samples": int(i.size),
            "bad": bad,
            "worst": worst,
        }
    )
    half = n // 2
    for k, fi in enumerate(pyr.lateral):
        a, b = pyr.corners[k], pyr.corners[(k + 1) % 4]
        down = (a + b) / 2 - apex
        down /= norm(down)
        left = edge_face(a, apex)
        ux = (b - a) / pyr.width
        face_pts = [a + np.outer(np.arange(n + 1) * c, ux), apex[None]]
        for row in range(1, half):
            t = row / half
            start, end = a + t * (apex - a), b + t * (apex - b)
            m = n - 2 * row
            f = np.arange(m + 1) / m
            # the samples next to the lateral edges step away from them
            f[1] += TIE_SHIFT / m
            f[m - 1] -= TIE_SHIFT / m
            q = start + np.outer(f, end - start)
            if m == 2:  # below the apex: down the face's midline
                q[1] += TIE_SHIFT * c * down
            pts.append(q[1:-1])
            fid += [fi] * (m - 1)
            lid += [line] * (m - 1)
            feat += [False] * (m - 1)
            line += 1
            # the rows' ends are the lateral edges' samples; each edge is the
            # left one (from corners[k]) of one face
            pts.append(start[None])
            fid.append(left)
            lid.append(-1)
            feat.append(True)
            face_pts.append(q)
        fp = np.vstack(face_pts)
        uy = -down
        fb, fw = _worst(np.stack([dot(fp - a, ux), dot(fp - a, uy)], axis=1))
        reports.append(
            {
                "face": fi,
                "kind": "pyramid lattice",
                "rows": half - 1,
                "samples": int(fp.shape[0]),
                "bad": fb,
                "worst": fw,
            }
        )
    s.replace(
        np.arange(s.points.shape[0]),
        np.vstack(pts),
        np.array(lid, dtype=np.int64),
        np.array(fid, dtype=np.int64),
        np.array(feat, dtype=bool),
    )
    return reports, {pyr.base, *pyr.lateral}
