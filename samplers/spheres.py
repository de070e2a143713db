"""Partial spheres with sharp rims, repaired on their stereographic map.

A partial sphere (cutcube's scoop) keeps its scan rows: sections by the
family's planes, their columns at multiples of one angle that doubles where
a row's gaps would fall below 0.75 h (:func:`sr33.samplers.scanline._sphere_row`).
Where the columns halve, and where the rows end on the sphere's sharp rims
at arbitrary places, Delaunay triangles break Condition III-ii.
:func:`repair_sphere_faces` maps each such face onto the plane by the
stereographic projection from the point opposite the face's centre.  The
map is conformal, so a triangle's ratio of Condition III-ii is kept up to
the change of scale across it (at most 10% over the whole face when the
face lies within 37° of its centre), and it maps circles to circles: the
rims stay circular arcs, along which :func:`sr33.samplers.layers.arc_clamp` keeps
the free samples on the face.  There the face is repaired like a planar
one (:func:`sr33.samplers.repair.repair`): the rims' samples fixed, every other
sample of the face free.  The map's triangles are not quite the sphere's
(the scale changes across them, and where four samples are nearly
cocircular either diagonal is Delaunay): the answer is judged again on
the sphere itself (:func:`sphere_worst`), and repaired from shaken starts
where that verdict is not clear of the margin.

CadQuery and OCP are imported when the functions run.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.spatial import ConvexHull, QhullError

from sr33 import libm
from sr33.mesh import dot, flipped_triangles, near_cocircular, norm

from .chart import Arc, Raster, arc_clamp, arc_sides, segment_distance, unfold_across_arc
from .faces import (
    Stereographic,
    basis_surface,
    boundary_segments,
    face_mesh,
    goes_round,
    rims_sampled,
)
from .layers import POLE_GOOD, RASTER, unstuck
from .repair import repair, shake
from .samples import Samples

FRAME_REACH = 2.5  # the neighbours' samples this near a rim (times h) frame the repair
MAP_GOOD = POLE_GOOD  # a repair ending at or above this on the map is tried again
FACING = 0.2  # the face lies where the direction from the centre has cos > this with the pole
#: a repaired face whose triangles on the sphere itself (:func:`sphere_worst`)
#: reach this is repaired again from seeded shaken starts ...
SPHERE_GOOD = 0.84
SPHERE_TRIES = 4  # ... at most this many, the lowest worst on the sphere kept
SPHERE_SHAKE = 0.05  # ... the free samples moved up to this (times h) times the try's number
SPHERE_SEED = 77  # ... by the seeded stream (SPHERE_SEED, try)
COCIRCULAR = 0.02  # a quad's facing angles summing to pi within this (rad): both diagonals judged


def _circle(a: np.ndarray, b: np.ndarray, c: np.ndarray) -> tuple[np.ndarray, float] | None:
    """Centre and radius of the circle through three 2-D points (None when
    they are collinear)."""
    d = 2.0 * (a[0] * (b[1] - c[1]) + b[0] * (c[1] - a[1]) + c[0] * (a[1] - b[1]))
    scale = max(np.ptp(np.stack([a, b, c]), axis=0).max(), 1e-300)
    if abs(d) < 1e-9 * scale**2:
        return None
    sa, sb, sc = dot(a, a), dot(b, b), dot(c, c)
    ux = (sa * (b[1] - c[1]) + sb * (c[1] - a[1]) + sc * (a[1] - b[1])) / d
    uy = (sa * (c[0] - b[0]) + sb * (a[0] - c[0]) + sc * (b[0] - a[0])) / d
    centre = np.array([ux, uy])
    return centre, float(norm(a - centre))


def _rim_arcs(face, to2d) -> list[Arc] | None:
    """The face's rims as arcs of the map (None when one is not a circle
    there: a rim through the projection's point, or an edge that is no
    circle)."""
    out = []
    for e in face.Edges():
        if e.geomType() != "CIRCLE":
            return None
        if e.IsClosed():
            pts = to2d(np.array([e.positionAt(x).toTuple() for x in (0.0, 1 / 3, 2 / 3)]))
            fit = _circle(*pts)
            if fit is None:
                return None
            out.append(Arc(fit[0], fit[1], 0.0, 2 * math.pi, True, False))
            continue
        s, m, f = to2d(np.array([e.positionAt(x).toTuple() for x in (0.0, 0.5, 1.0)]))
        fit = _circle(s, m, f)
        if fit is None:
            return None
        out.append(Arc.through(*fit, s, m, f))
    return out


def _rim_frame(face, arcs, sides, to2d: Stereographic, s: Samples, own, h: float):
    """The samples of the faces across the rims, within ``FRAME_REACH`` h of
    a rim, unfolded into the map: each at its distance from the rim (times
    the map's scale there), straight out from its nearest rim point.  Their
    triangles with the face's samples cross the sharp rim; judged with the
    face's own (``judge_frame``), they keep the samples on either side from
    crowding the rim together (cutcube: a triangle of 0.59 h, 0.69 h and
    0.77 h across the scoop's rim, ratio 0.89)."""
    x = s.points[np.flatnonzero(~own & ~s.on_feature)]
    out = [np.empty((0, 2))]
    for e, a, side in zip(face.Edges(), arcs, sides):
        circ = e._geomAdaptor().Circle()
        circle = (
            np.array(circ.Location().Coord()),
            np.array(circ.Axis().Direction().Coord()),
            float(circ.Radius()),
        )
        out.append(
            unfold_across_arc(
                x,
                circle,
                a,
                side,
                to2d,
                FRAME_REACH * h,
                scale=lambda yy: 1.0 + (yy**2).sum(axis=1) / (2.0 * to2d.radius) ** 2,
            )
        )
    return np.vstack(out)


def face_pole(face) -> tuple[np.ndarray, float, np.ndarray] | None:
    """A sphere face's centre, radius and the unit direction from the
    centre to the face's own centre (its mass centre), or None where the
    two coincide (a whole ball)."""
    sph = basis_surface(face).Sphere()
    centre = np.array(sph.Location().Coord())
    radius = float(sph.Radius())
    pole = np.array(face.Center().toTuple()) - centre
    if norm(pole) < 1e-9 * radius:
        return None
    return centre, radius, pole / norm(pole)


def repair_sphere_faces(occ, s: Samples, h: float, size: float) -> list[dict]:
    """Repair every partial sphere whose rims are all sampled (sharp edges).

    Parameters
    ----------
    occ : cadquery.Shape
        The shape sampled.
    s : Samples
        Its samples, edited in place: the face's samples off its rims are
        replaced by the repair's.
    h : float
        The sample spacing.
    size : float
        The shape's bounding-box diagonal (tolerances).

    Returns
    -------
    list of dict
        One report per repaired face (kind ``"sphere"``: samples, added,
        removed, bad, worst).

    Notes
    -----
    A face whose rims are not all sharp (fillet_box's corners, blending
    smoothly into cylinders) is left here: repaired this way amid the scan
    rows, the seams' samples fixed and the fillets' as the frame,
    fillet_box went from 2.1% to 0.4% of its samples violating III-ii (the
    rest across the seams); laid out with the rest of its box, whose
    lattices meet the seams square, it is repaired by
    :func:`sr33.samplers.fillets.lattice_filleted_box`.  So is a face reaching
    more than about 78° (``FACING``) from its centre, where the map would
    stretch too much.
    """
    reports = []
    feature = s.points[s.on_feature]
    for fi, face in enumerate(occ.Faces()):
        if face.geomType() != "SPHERE" or goes_round(face):
            continue
        if not rims_sampled(face, feature, h):
            continue
        rep = repair_sphere_face(fi, face, s, h, size)
        if rep is not None:
            reports.append(rep)
    return reports


def repair_sphere_face(fi: int, face, s: Samples, h: float, size: float, fixed=None) -> dict | None:
    """Repair one partial sphere on its stereographic map (see
    :func:`repair_sphere_faces`): the samples of ``fixed`` (default: the
    feature samples) stay, the face's other samples are free, the
    neighbours' samples near its rims are the judged frame; a repair ending
    at or above ``MAP_GOOD`` on the map runs again with wider cells, then
    with its corners split where few triangles are bad, and the lowest
    worst ratio is kept.  Returns the
    face's report, or None where the face is not repaired (it wraps more
    than about 78° from its centre, a rim is no circle on the map, or no
    sample is free)."""
    tol = 1e-7 * size
    fixed = s.on_feature if fixed is None else np.asarray(fixed, dtype=bool)
    got = face_pole(face)
    if got is None:
        return None
    centre, radius, pole = got
    verts, _ = face_mesh(face, h / 20, 0.3)
    reach = dot(verts - centre, pole)
    if reach.min() <= FACING * radius:
        return None  # the face wraps too far round for one map
    to2d = Stereographic(centre, radius, pole)
    arcs = _rim_arcs(face, to2d)
    if arcs is None:
        return None
    q = s.points - centre
    dist = np.linalg.norm(q, axis=1)
    cand = np.flatnonzero((np.abs(dist - radius) < tol) & (dot(q, pole) > FACING * radius))
    uv = to2d(s.points[cand])
    seg = boundary_segments(face, to2d, h / 20)
    raster = Raster(seg, h / RASTER)
    mine = raster(uv) | (segment_distance(uv, seg, h / 100) < 0.1 * h)
    idx, uv = cand[mine], uv[mine]
    order = np.lexsort((np.round(uv[:, 1] / h, 6), np.round(uv[:, 0] / h, 6)))
    idx, uv = idx[order], uv[order]
    free = ~fixed[idx]
    if not free.any():
        return None
    sides = arc_sides(arcs, raster, h)
    own = np.zeros(s.points.shape[0], dtype=bool)
    own[idx] = True
    frame = _rim_frame(face, arcs, sides, to2d, s, own, h)
    args = dict(inside=raster, clamp=arc_clamp(arcs, sides, h), frame=frame, judge_frame=True)
    # the map's ratios are the sphere's up to the scale's change across a
    # triangle: ending near 0.85 on the map is not enough (cutcube's scoop,
    # turned: 0.849 on the map, 0.858 geodesically)
    r = unstuck(uv, free, h, repair(uv, free, h, **args), MAP_GOOD, **args)
    # judged on the sphere itself: the map's Delaunay triangles are not the
    # sphere's where four samples are nearly cocircular, and the scale
    # changes across a triangle (cutcube turned b: 0.825 on the map, 0.851
    # geodesically, 2 to 3 h inside the rims)
    xyz = to2d.inverse(r.uv)
    worst = sphere_worst(xyz, centre, radius, h)
    for k in range(1, SPHERE_TRIES + 1):
        if worst < SPHERE_GOOD:
            break
        start = uv.copy()
        shake(start, free, (SPHERE_SEED, k), SPHERE_SHAKE * k * h, args["clamp"])
        again = unstuck(start, free, h, repair(start, free, h, **args), MAP_GOOD, **args)
        again_xyz = to2d.inverse(again.uv)
        w = sphere_worst(again_xyz, centre, radius, h)
        if (w, again.worst) < (worst, r.worst):
            r, xyz, worst = again, again_xyz, w
    return s.put(idx, r, xyz, fi, "sphere")


def sphere_worst(points: np.ndarray, centre: np.ndarray, radius: float, h: float) -> float:
    """The worst Condition III-ii ratio (Section 3: the middle over the
    longest side) of the Delaunay triangles of ``points`` on the sphere of
    ``centre`` and ``radius`` itself: the facets of their convex hull (the
    spherical Delaunay triangulation of points on one sphere), their sides
    measured along great circles; facets with a chord of 2.5 h or more span
    the part of the sphere that is not the face's (its opening) and are
    left out.  Where two facets make a quad whose corners are cocircular
    within ``COCIRCULAR`` (the angles facing their shared side sum to π
    within it) either diagonal is Delaunay, and a check on another
    triangulation of the sphere (the geodesic one on the truth mesh) may
    take the other: both are judged (cutcube turned b: a quad within
    0.004 rad, 0.830 by the hull's diagonal, 0.851 by the other, which the
    geodesic check took).  0 when there are fewer than four points or they
    are flat."""
    p = np.asarray(points, dtype=np.float64)
    if p.shape[0] < 4:
        return 0.0
    try:
        hull = ConvexHull(p)
    except QhullError:
        return 0.0
    tri = hull.simplices
    chord = norm(p[tri] - p[np.roll(tri, 1, axis=1)])
    kept = chord.max(axis=1) < 2.5 * h
    if not kept.any():
        return 0.0
    # the quads of two kept facets cocircular within COCIRCULAR, with their other diagonal
    flipped = flipped_triangles(near_cocircular(p, tri[kept], COCIRCULAR))
    chords = [chord[kept], norm(p[flipped] - p[np.roll(flipped, 1, axis=1)])]
    half = np.minimum(np.concatenate(chords) / (2.0 * radius), 1.0)  # sine of half the arc
    arc = 2.0 * radius * libm.arctan2(half, np.sqrt(1.0 - half * half))
    side = np.sort(arc, axis=1)
    return float((side[:, 1] / side[:, 2]).max())
