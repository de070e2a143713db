"""Facts about the faces of a CAD shape, as plain arrays.

Shared by the scan rows (:mod:`sr33.samplers.scanline`) and the layouts
and repairs that follow them: exact bounds, the face nearest a point, a
face's boundary in its own 2-D coordinates, its axis of revolution, the
angle of an edge to the face's rows, and the greedy thinning of samples.
CadQuery and OCP are imported only when these run.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.spatial import cKDTree

from sr33.mesh import dot, edge_uses, norm

RIM_SAMPLED = 0.75  # an edge is sampled when a feature sample is this near its middle (times h)
FEATURE_CLEARANCE = 0.75  # no scan-line sample nearer to a sampled edge, times h
#: a planar face narrower than this (times h) along one of its straight
#: edges holds no scan row: a strip, whose two long edges carry one set of
#: samples across it (the scan rows' strip followers; the repair keeps them)
STRIP_WIDTH = 2.0 * FEATURE_CLEARANCE
#: a band narrower than this (times h) is laid by the steps of its edges:
#: a planar face between two parallel straight edges, not a strip, is
#: scanned along them, at most two rows between them
#: (:func:`sr33.samplers.scanline.scan`'s strip rows); a frustum's band
#: steps by its rim's gaps (:func:`sr33.samplers.layers.lay_cone`)
NARROW_BAND = 3.0


def axis_index(u: np.ndarray) -> int | None:
    """Which coordinate axis the unit vector ``u`` runs along, if any."""
    k = int(np.argmax(np.abs(u)))
    return k if abs(abs(u[k]) - 1.0) < 1e-12 else None


def row_direction(face, d) -> np.ndarray | None:
    """The direction of a planar face's rows (its sections by the planes
    normal to ``d``); None for a curved face or one the planes do not cut."""
    if face.geomType() != "PLANE":
        return None
    rows = np.cross(np.array(face.normalAt().toTuple()), d)
    if norm(rows) < 1e-9:
        return None
    return rows / norm(rows)


def width_across(face, a: np.ndarray, u: np.ndarray) -> float:
    """How far a face's corners reach from the line through ``a`` along the
    unit vector ``u``: a strip's width along its edge there."""
    q = np.array([v.toTuple() for v in face.Vertices()]).reshape(-1, 3) - a
    return float(np.linalg.norm(q - dot(q, u)[:, None] * u, axis=1).max())


def exact_bounds(shape) -> tuple[np.ndarray, np.ndarray]:
    """Bounding box from the exact geometry (CadQuery's uses any cached
    triangulation, which would make the scan planes depend on history)."""
    from OCP.Bnd import Bnd_Box
    from OCP.BRepBndLib import BRepBndLib

    box = Bnd_Box()
    BRepBndLib.AddOptimal_s(shape.wrapped, box, False, False)
    xmin, ymin, zmin, xmax, ymax, zmax = box.Get()
    return np.array([xmin, ymin, zmin]), np.array([xmax, ymax, zmax])


def rims_sampled(face, feature: np.ndarray, h: float) -> bool:
    """Whether every edge of the face carries feature samples (a sharp rim):
    one lies within ``RIM_SAMPLED`` h of the edge's middle."""
    if feature.shape[0] == 0:
        return False
    mids = np.array([e.positionAt(0.5).toTuple() for e in face.Edges()])
    if mids.shape[0] == 0:
        return False
    gap, _ = cKDTree(feature).query(mids)
    return bool(gap.max() <= RIM_SAMPLED * h)


def row_cosine(face, row_dir, u: np.ndarray) -> float | None:
    """|cos| of the angle between the direction ``u`` (in the plane of
    ``face``) and the face's scan rows (those of the planes with normal
    ``row_dir``); None where the planes run along the face (no rows)."""
    rows = np.cross(np.array(face.normalAt().toTuple()), row_dir)
    n = float(norm(rows))
    return None if n < 1e-9 else abs(float(dot(u, rows))) / n


def nearest_face(p, faces) -> int:
    import cadquery as cq

    v = cq.Vertex.makeVertex(*p)
    d = [v.distance(f) for f in faces]
    return int(np.argmin(d))


def thin(
    points: np.ndarray,
    radius: float,
    labels: np.ndarray | None = None,
    across: float = 0.0,
    folded: set[tuple[int, int]] = frozenset(),
) -> np.ndarray:
    """Indices kept by a greedy pass in order: drop points within radius of a kept one.

    With ``labels`` (a face per point, negative for points every face
    shares, an edge's samples), a point of a face is dropped within only
    ``across`` of a kept point of a face it makes a pair of ``folded``
    with (:meth:`sr33.samplers.adjacency.EdgeFaces.folded`): across an
    acute edge two faces' samples are near in space and far on the
    surface (a 25° prism's rows 1 h off its edge stand 0.43 h apart, and
    thinning them at 0.5 h left one face's first row 2 h off the edge, 54
    samples breaking Condition III-ii there).  Any other pair, across a
    fillet's tangent seam say, is thinned at ``radius``."""
    cell = radius
    grid: dict[tuple[int, int, int], list[int]] = {}
    keep: list[int] = []
    r2 = radius * radius
    a2 = across * across
    keys = np.floor(points / cell).astype(np.int64)
    for i in range(points.shape[0]):
        kx, ky, kz = keys[i]
        p = points[i]
        pair = int(labels[i]) if labels is not None and folded else None
        ok = True
        for dx in (-1, 0, 1):
            for dy in (-1, 0, 1):
                for dz in (-1, 0, 1):
                    for j in grid.get((kx + dx, ky + dy, kz + dz), ()):
                        q = points[j]
                        d2 = (p[0] - q[0]) ** 2 + (p[1] - q[1]) ** 2 + (p[2] - q[2]) ** 2
                        # between across and radius: dropped unless the faces fold apart
                        if d2 < a2 or (
                            d2 < r2 and (pair is None or (pair, int(labels[j])) not in folded)
                        ):
                            ok = False
                            break
                    if not ok:
                        break
                if not ok:
                    break
            if not ok:
                break
        if ok:
            keep.append(i)
            grid.setdefault((int(kx), int(ky), int(kz)), []).append(i)
    return np.array(keep, dtype=np.int64)


def face_mesh(shape, tol: float, angular: float) -> tuple[np.ndarray, np.ndarray]:
    """A fresh OCC tessellation of ``shape`` (face or solid): vertices (n, 3), triangles (t, 3).

    CadQuery's ``tessellate`` keeps any triangulation the shape already
    carries that is at least as fine as asked, and stores the one it makes
    on the shape; the mesh of a face would then depend on what was meshed
    before, in this sampling or in an earlier one of the same solid (two
    scans of one solid in one process gave different samples).  A copy
    without triangulation is meshed instead, so the mesh depends on
    ``shape``, ``tol`` and ``angular`` only and the input is not modified.
    """
    verts, tris = shape.copy(mesh=False).tessellate(tol, angular)
    v = np.array([q.toTuple() for q in verts], dtype=np.float64).reshape(-1, 3)
    return v, np.array(tris, dtype=np.int64).reshape(-1, 3)


def boundary_segments(face, to2d, tol: float) -> np.ndarray:
    """Boundary edges of the face's own fine tessellation, in 2-D, as (s, 2, 2)."""
    v, t = face_mesh(face, tol, 0.05)
    uniq, counts = edge_uses(t)
    free = uniq[counts == 1]
    return to2d(v)[free]


#: half-way step counts within this relative margin are ties (see :func:`steps`)
STEP_TIE = 1e-9


def steps(length: float, step: float, least: int = 1) -> int:
    """The whole number of equal steps nearest ``length / step`` (at least ``least``).

    A half-way case goes to the even count, as Python's ``round`` does for
    an exact half, and so does any quotient within ``STEP_TIE`` of a half:
    on a model measured in round numbers the quotient is often exactly a
    half (a 0.5 high block sampled 0.04 apart: 12.5 steps), and the last
    bit of a coordinate (the model turned into its frame: 12.500000000000002)
    must not decide between 12 and 13 steps.

    Examples
    --------
    >>> steps(0.5, 0.04), steps(0.5 + 1e-15, 0.04), steps(0.5 - 1e-15, 0.04)
    (12, 12, 12)
    >>> steps(0.54, 0.04), steps(0.01, 0.04), steps(0.01, 0.04, least=3)
    (14, 1, 3)
    """
    q = length / step
    n = math.floor(q)
    frac = q - n
    if abs(frac - 0.5) <= STEP_TIE * max(1.0, q):
        n = n if n % 2 == 0 else n + 1
    elif frac > 0.5:
        n += 1
    return max(least, int(n))


def perpendicular(v: np.ndarray) -> np.ndarray:
    """A unit vector perpendicular to ``v``: ``v`` crossed with the coordinate
    axis least aligned with it (a fixed choice, so frames are reproducible)."""
    u = np.cross(v, np.eye(3)[int(np.argmin(np.abs(v)))])
    return u / norm(u)


class Stereographic:
    """The stereographic projection of a sphere from the point opposite
    ``pole`` (a unit vector from the centre), scaled to be isometric at the
    pole: a point at angle θ from it maps to ``2 R tan(θ / 2)``.  It takes
    the sphere's circles to the plane's (their insides to insides), so the
    map's Delaunay triangles are the sphere's intrinsic ones."""

    def __init__(self, centre: np.ndarray, radius: float, pole: np.ndarray):
        self.centre, self.radius, self.pole = centre, radius, pole
        self.e1 = perpendicular(pole)
        self.e2 = np.cross(pole, self.e1)

    def __call__(self, p) -> np.ndarray:
        u = (np.asarray(p, dtype=np.float64) - self.centre) / self.radius
        den = 1.0 + dot(u, self.pole)
        uv = np.stack([dot(u, self.e1), dot(u, self.e2)], axis=1)
        return 2.0 * self.radius * uv / den[:, None]

    def inverse(self, q: np.ndarray) -> np.ndarray:
        x = q / (2.0 * self.radius)
        s2 = (x**2).sum(axis=1)
        u = (
            2.0 * x[:, :1] * self.e1 + 2.0 * x[:, 1:] * self.e2 + (1.0 - s2)[:, None] * self.pole
        ) / (1.0 + s2)[:, None]
        return self.centre + self.radius * u


def goes_round(face) -> bool:
    """Whether a face of revolution goes all the way round its axis."""
    umin, umax, _, _ = face._uvBounds()
    return abs((umax - umin) - 2 * math.pi) <= 1e-9


def whole_band(face) -> bool:
    """Whether a face of revolution goes all the way round its axis between
    whole circles only: every boundary edge but its seam and a degenerate
    apex is a closed circle.  A cone or cylinder notched by a boolean cut
    also spans the full turn of its parameter, but part of each row round it
    is missing (the layouts that lay whole rings round such a band put
    samples in the notch, off the face)."""
    from OCP.BRep import BRep_Tool

    if not goes_round(face):
        return False
    for edge in face.Edges():
        w = edge.wrapped
        if BRep_Tool.Degenerated_s(w) or BRep_Tool.IsClosed_s(w, face.wrapped):
            continue  # the apex; the seam (both sides of the face)
        if edge.geomType() != "CIRCLE" or not BRep_Tool.IsClosed_s(w):
            return False
    return True


#: a band of revolution links the circles on its two sides into one column
#: count (:func:`linked_across`) when its smaller circle's radius is at least
#: this share of the larger one's: with the larger circle's count, the
#: smaller one's gaps stay within 20 % of the larger one's
LINK_RATIO = 0.8
#: ... or, whatever the ratio, when the band is narrower than this (times h):
#: no row fits between its circles to change the count (a hole of radius
#: 0.137 chamfered by 0.036, its circles 0.79 apart in ratio and 1.4 h apart
#: on the cone, kept 24 columns below and 31 above, and every sample of the
#: band broke Condition III-ii)
LINK_WIDTH = 2.0


def _other_circle(face, edge):
    """The closed circle edge of ``face`` other than ``edge`` (its seam and a
    degenerate apex aside), or None."""
    for e in face.Edges():
        if e.geomType() == "CIRCLE" and e.IsClosed() and not e.isSame(edge):
            return e
    return None


def linked_across(adjacency, fi: int, edge, h: float | None = None):
    """The band across a circle edge of face ``fi`` that carries that
    circle's columns on to another circle: (the band's index, its other
    circle edge), or None.

    A band is a full cylinder, or a full cone between two whole circles
    (:func:`whole_band`) whose smaller radius is at least ``LINK_RATIO`` of
    its larger one, or (given the spacing ``h``) whose circles lie less
    than ``LINK_WIDTH`` h apart: a chamfer's cone between a cylinder's rim
    and the disk it bevels.  Samples at the same angles on both circles
    make the band's cells rectangles however narrow the band is; two
    column counts make a band narrower than a row a strip of needle
    triangles (a cylinder of radius 0.33 chamfered by 0.05, its cone
    band's inner rim laid by the disk and its outer one by the wall:
    III-ii ratios 0.93 to 1.0).
    """
    other = adjacency.other(edge, fi)
    if other < 0 or edge.geomType() != "CIRCLE":
        return None
    face = adjacency.faces[other]
    if face.geomType() not in ("CYLINDER", "CONE") or not whole_band(face):
        return None
    far = _other_circle(face, edge)
    if far is None:
        return None
    small, large = sorted((float(edge.radius()), float(far.radius())))
    if small < (LINK_RATIO - 1e-9) * large:
        width = norm(np.array(edge.Center().toTuple()) - np.array(far.Center().toTuple()))
        if h is None or math.hypot(width, large - small) >= LINK_WIDTH * h:
            return None
    return other, far


def linked_radii(adjacency, fi: int, edge, h: float | None = None) -> list[float]:
    """The radii of the circles linked to ``edge`` (a circle edge of face
    ``fi``) through bands (:func:`linked_across`, with the spacing ``h``),
    one after another, ``edge``'s own first: the circles that must carry
    one column count."""
    radii = [float(edge.radius())]
    seen = {fi}
    while (step := linked_across(adjacency, fi, edge, h)) is not None and step[0] not in seen:
        fi, edge = step
        seen.add(fi)
        radii.append(float(edge.radius()))
    return radii


def linked_radius(adjacency, fi: int, edge, h: float | None = None) -> float:
    """The largest radius of the circles linked to ``edge`` (a circle edge
    of face ``fi``) through bands (:func:`linked_radii`), ``edge``'s own
    included: the circle whose column count the chain shares (a chamfered
    cylinder's two disks, of radii r and r - c, both take the count of r,
    the wall's)."""
    return max(linked_radii(adjacency, fi, edge, h))


def cone_frame(face, tol: float = 0.0):
    """A cone face's apex, unit axis (from the apex into the cone), the
    directions across it (``ex`` its surface's, ``ey`` = axis × ex) and its
    half-angle; None where its surface's reference circle lies within
    ``tol`` of its apex."""
    cone = basis_surface(face).Cone()
    pos = cone.Position()
    apex = np.array(cone.Apex().Coord())
    loc = np.array(pos.Location().Coord())
    length = float(norm(loc - apex))
    if length <= 0.0 or length < tol:
        return None
    axis = (loc - apex) / length
    ex = np.array(pos.XDirection().Coord())
    return apex, axis, ex, np.cross(axis, ex), abs(cone.SemiAngle())


def revolution_axis(face):
    """(point, unit direction) of a cone's, cylinder's, sphere's or torus's
    axis (a sphere's and a torus's point is its centre)."""
    g = basis_surface(face)
    kind = {"CONE": "Cone", "CYLINDER": "Cylinder", "TORUS": "Torus"}.get(face.geomType(), "Sphere")
    pos = getattr(g, kind)().Position()
    return np.array(pos.Location().Coord()), np.array(pos.Direction().Coord())


def basis_surface(face):
    """The analytic surface under a B-rep face (``face._geomAdaptor()``),
    through any rectangular trimming: a lofted frustum's face says "CONE"
    but its surface is a trimmed one, whose ``Cone()`` does not exist."""
    from OCP.Geom import Geom_RectangularTrimmedSurface

    g = face._geomAdaptor()
    while isinstance(g, Geom_RectangularTrimmedSurface):
        g = g.BasisSurface()
    return g


def cap_rim(face, tol: float) -> tuple[np.ndarray, np.ndarray, float] | None:
    """The one circle a spherical cap's boundary runs round: (centre, unit
    normal, radius); None when the face's edges (seams and degenerate poles
    aside) are not arcs of one circle making it whole (a dome fused onto a
    face, a dimple, a hemisphere: a cap; cutcube's scoop, bounded by three
    arcs: not one)."""
    from OCP.BRep import BRep_Tool

    circles = []
    for e in face.Edges():
        if BRep_Tool.Degenerated_s(e.wrapped) or BRep_Tool.IsClosed_s(e.wrapped, face.wrapped):
            continue
        if e.geomType() != "CIRCLE":
            return None
        circ = e._geomAdaptor().Circle()
        circles.append(
            (
                np.array(circ.Location().Coord()),
                np.array(circ.Axis().Direction().Coord()),
                float(circ.Radius()),
                float(e.Length()),
            )
        )
    if not circles:
        return None
    c0, n0, r0, _ = circles[0]
    for c, n, r, _ in circles[1:]:
        if norm(c - c0) > tol or abs(r - r0) > tol or abs(abs(dot(n, n0)) - 1) > 1e-9:
            return None
    if abs(sum(x[3] for x in circles) - 2 * math.pi * r0) > 1e-6 * r0:
        return None
    return c0, n0, r0
