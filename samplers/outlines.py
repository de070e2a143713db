"""Curved faces no layout takes, repaired in their own charts, whatever their rims.

The layouts take whole bands of revolution and caps (:mod:`sr33.samplers.layers`,
:mod:`sr33.samplers.disks`), and :func:`sr33.samplers.spheres.repair_sphere_faces`
partial spheres whose rims are circles and that have no seam.  A boolean
leaves faces none of them takes, and their scan rows end on the rims at
arbitrary places: a cylinder notched by a ball cut from its top (its rim
the curve where they meet, a B-spline), and the ball's piece inside it
(that curve, a circle and its seam).  On the stop 54 survey's model of it
(3,007 samples), 290 samples of the cylinder and 351 of the ball's piece
broke Condition III-ii.

Each such face is repaired in a chart of its own (the repair of
:func:`sr33.samplers.repair.repair`, as for the planar faces):

* a cylinder unrolled (:class:`Unrolled`): an isometry, so the chart's
  Delaunay triangles and ratios are the surface's;
* a sphere on its stereographic map from the point opposite the face's
  centre (:class:`sr33.samplers.faces.Stereographic`): conformal, ratios kept
  up to the scale's change across a triangle, as for the partial spheres.

The face's rims (its edges but seams and degenerate ones, whatever curves
they are) are dense points (:class:`Rims`) with the direction into the
face in the chart; the face's domain is its own tessellation filled into a
raster (:class:`TriangleRaster`).  Samples on the rims stay; the others
near them move (all of a sphere's), kept on the face a quarter of h from
the rims; the neighbours' samples across a rim are unfolded into the chart
(each at its distance from its nearest rim point, straight out) and judged
with the face's own.  A cylinder going all the way round is unrolled twice,
cut in two places half a turn apart: the samples near the cut stay in a
pass, with their images across it as the frame, and the second pass
repairs round the first pass's cut.

CadQuery and OCP are imported when the functions run.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy.spatial import cKDTree

from sr33 import libm
from sr33.mesh import dot

from .chart import RimClamp, TriangleRaster
from .faces import (
    RIM_SAMPLED,
    Stereographic,
    basis_surface,
    cone_frame,
    face_mesh,
    goes_round,
    steps,
    whole_band,
)
from .layers import POLE_GOOD, RASTER, STUCK, lattice_revolved_body, lay_cone, unstuck
from .repair import repair
from .samples import Samples
from .spheres import FACING, face_pole

RIM_STEP = 1.0 / 20.0  # rims as points this far apart (times h)
LAYER = 3.0  # a developed face's samples this near a rim (times h) move
CUT_CLEAR = 3.0  # ... unless this near the pass's cut (times h)
IMAGE_REACH = 2.0  # own samples this near the cut (times h) are imaged across it
FRAME_REACH = 2.5  # the neighbours' samples this near a rim (times h) are the frame
CLEAR = 0.25  # free samples keep this far (times h) from the rims
ON_RIM = 0.1  # a feature sample this near a rim's points (times h; they are h / 20 apart) is on it
#: a sphere face is mapped when it lies within 78° of its centre (cos >
#: this, :data:`sr33.samplers.spheres.FACING`): the lattice laid on the map
#: is denser on the sphere by the map's scale, 1.6 there, against the rims'
#: samples h apart (a hemisphere's dish, 90°: 21 samples at or above 0.85
#: where the scan rows had 296, in 70 s of repair)
REACH = FACING
#: the dishes, then the cylinders, repaired this many times over (each
#: round's repairs see the other faces' answers across the rims)
ROUNDS = 2
#: a ball with a bite: its rims lie within this angle of the bite's centre
BITE = math.radians(110.0)
KEEP_OFF = 0.5  # a laid lattice's points this near a rim (times h) are left out


def rim_edges(face) -> list:
    """The face's rims: its edges but its seams and degenerate ones."""
    from OCP.BRep import BRep_Tool

    return [
        e
        for e in face.Edges()
        if not (BRep_Tool.Degenerated_s(e.wrapped) or BRep_Tool.IsClosed_s(e.wrapped, face.wrapped))
    ]


class Unrolled:
    """A cylinder unrolled from the angle ``cut``: a point at angle θ about
    the axis and height z along it maps to ``(R ((θ - cut) mod 2π), z)``,
    an isometry onto ``[0, 2π R)`` by the height (``period`` 2π R)."""

    def __init__(self, o, ex, ey, ez, radius: float, cut: float):
        self.o, self.ex, self.ey, self.ez = o, ex, ey, ez
        self.radius, self.cut = radius, cut
        self.period = 2.0 * math.pi * radius

    def __call__(self, p) -> np.ndarray:
        q = np.asarray(p, dtype=np.float64) - self.o
        ang = (libm.arctan2(dot(q, self.ey), dot(q, self.ex)) - self.cut) % (2.0 * math.pi)
        return np.stack([self.radius * ang, dot(q, self.ez)], axis=1)

    def inverse(self, c: np.ndarray) -> np.ndarray:
        ang = self.cut + c[:, 0] / self.radius
        return (
            self.o
            + c[:, 1:] * self.ez
            + self.radius * (np.cos(ang)[:, None] * self.ex + np.sin(ang)[:, None] * self.ey)
        )

    def scale(self, c: np.ndarray) -> np.ndarray:
        return np.ones(c.shape[0])

    #: a raster cell is inside only where its centre lies in a triangle; the
    #: repair tries shaken starts when stuck
    grow_raster, shaken = False, True

    def triangles(self, tri3: np.ndarray) -> np.ndarray:
        """A face's triangles ``(t, 3, 3)`` in the chart (across the cut as
        :class:`sr33.samplers.chart.TriangleRaster` takes them, by its period)."""
        return self(tri3.reshape(-1, 3)).reshape(-1, 3, 2)

    def images(self, c: np.ndarray, reach: float) -> list[np.ndarray]:
        """The chart points ``c`` within ``reach`` of the cut, carried across it."""
        low, high = c[:, 0] < reach, c[:, 0] > self.period - reach
        return [c[low] + [self.period, 0.0], c[high] - [self.period, 0.0]]

    def from_cut(self, c: np.ndarray) -> np.ndarray:
        """Distance in the chart from each point to the cut."""
        return np.minimum(c[:, 0], self.period - c[:, 0])

    def from_half_turn(self, c: np.ndarray) -> np.ndarray:
        """Distance in the chart from each point to the line half a turn from the cut."""
        return np.abs(c[:, 0] - 0.5 * self.period)


class Developed:
    """A cone developed from the angle ``cut``: a point at angle θ about the
    axis (from ``ex`` towards ``ey``) and slant distance ρ from the apex
    maps to ``ρ (cos φ, sin φ)``, ``φ = sin(a) ((θ - cut) mod 2π)``: an
    isometry onto a sector of angle ``2π sin(a)`` (``sector``) about the
    apex.  The cut's two sides are the sector's two rays; the chart has no
    period (a turn is a rotation by ``sector``, not a translation).  Points
    outside the sector (the images across the cut) are frame points only:
    ``inverse`` takes their angle modulo a full turn, not the sector."""

    period = None
    #: the fan of slivers round the apex is thinner than a raster cell: cells
    #: within half a diagonal of a triangle are inside; a notch's corners stay
    #: stuck whatever the shaken starts (a cone notched by a box: 19 bad
    #: triangles in 80 s of them, 17 kept), so its repair ends at the splits
    grow_raster, shaken = True, False

    def __init__(self, apex, axis, ex, ey, sin_a: float, cut: float):
        self.apex, self.axis, self.ex, self.ey = apex, axis, ex, ey
        self.sin_a, self.cos_a, self.cut = sin_a, math.sqrt(1.0 - sin_a * sin_a), cut
        self.sector = 2.0 * math.pi * sin_a

    def _polar(self, p) -> tuple[np.ndarray, np.ndarray]:
        q = np.asarray(p, dtype=np.float64) - self.apex
        ang = (libm.arctan2(dot(q, self.ey), dot(q, self.ex)) - self.cut) % (2.0 * math.pi)
        return np.linalg.norm(q, axis=1), ang

    def __call__(self, p) -> np.ndarray:
        rho, ang = self._polar(p)
        return _rotated(rho, self.sin_a * ang)

    def inverse(self, c: np.ndarray) -> np.ndarray:
        rho, phi = _polar_of(c)
        ang = self.cut + phi / self.sin_a
        across = np.cos(ang)[:, None] * self.ex + np.sin(ang)[:, None] * self.ey
        return self.apex + rho[:, None] * (self.cos_a * self.axis + self.sin_a * across)

    def scale(self, c: np.ndarray) -> np.ndarray:
        return np.ones(c.shape[0])

    def triangles(self, tri3: np.ndarray) -> np.ndarray:
        """A face's triangles ``(t, 3, 3)`` in the chart; one across the cut
        (corners more than half a turn apart) twice, once lifted past the
        sector's far ray and once below its first."""
        rho, ang = self._polar(tri3.reshape(-1, 3))
        rho, ang = rho.reshape(-1, 3), ang.reshape(-1, 3)
        across = ang.max(axis=1) - ang.min(axis=1) > math.pi
        up = np.where(ang[across] < math.pi, ang[across] + 2.0 * math.pi, ang[across])
        down = np.where(ang[across] >= math.pi, ang[across] - 2.0 * math.pi, ang[across])
        parts = [(rho[~across], ang[~across]), (rho[across], up), (rho[across], down)]
        return np.concatenate(
            [
                _rotated(r.reshape(-1), self.sin_a * a.reshape(-1)).reshape(-1, 3, 2)
                for r, a in parts
            ]
        )

    def images(self, c: np.ndarray, reach: float) -> list[np.ndarray]:
        """The chart points ``c`` within ``reach`` of a side of the cut,
        turned across it (by the sector's angle)."""
        rho, phi = _polar_of(c)
        low = _from_ray(rho, phi) < reach
        high = _from_ray(rho, self.sector - phi) < reach
        return [
            _rotated(rho[low], phi[low] + self.sector),
            _rotated(rho[high], phi[high] - self.sector),
        ]

    def from_cut(self, c: np.ndarray) -> np.ndarray:
        """Distance in the chart from each point to the cut (either ray)."""
        rho, phi = _polar_of(c)
        return np.minimum(_from_ray(rho, phi), _from_ray(rho, self.sector - phi))

    def from_half_turn(self, c: np.ndarray) -> np.ndarray:
        """Distance in the chart from each point to the ray half a turn from the cut."""
        rho, phi = _polar_of(c)
        return _from_ray(rho, np.abs(phi - 0.5 * self.sector))


def _polar_of(c: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The plane's points in polar coordinates (radius, angle in [0, 2π))."""
    return np.hypot(c[:, 0], c[:, 1]), libm.arctan2(c[:, 1], c[:, 0]) % (2.0 * math.pi)


def _rotated(rho: np.ndarray, phi: np.ndarray) -> np.ndarray:
    """Polar coordinates to the plane's."""
    return np.stack([rho * np.cos(phi), rho * np.sin(phi)], axis=1)


def _from_ray(rho: np.ndarray, psi: np.ndarray) -> np.ndarray:
    """Distance from a point at ``rho`` and angle ``psi`` off a ray from the
    origin to that ray (to the origin past a right angle)."""
    return np.where(np.abs(psi) < 0.5 * math.pi, rho * np.abs(np.sin(psi)), rho)


class _Sphere(Stereographic):
    """The stereographic map with its scale (chart length per length); the
    centre of projection maps to no point (NaN or inf), without a warning."""

    period = None
    grow_raster, shaken = False, True

    def __call__(self, p) -> np.ndarray:
        with np.errstate(divide="ignore", invalid="ignore"):
            return super().__call__(p)

    def scale(self, c: np.ndarray) -> np.ndarray:
        return 1.0 + (c**2).sum(axis=1) / (2.0 * self.radius) ** 2

    def triangles(self, tri3: np.ndarray) -> np.ndarray:
        """A face's triangles ``(t, 3, 3)`` on the map."""
        return self(tri3.reshape(-1, 3)).reshape(-1, 3, 2)


def _face_triangles(face, tol: float) -> np.ndarray:
    """The face's own tessellation (tolerance ``tol``) as 3-D triangles ``(t, 3, 3)``."""
    v, t = face_mesh(face, tol, 0.1)
    return v[t]


def rim_lines(edges, h: float) -> list[np.ndarray]:
    """Each edge as points ``RIM_STEP`` h apart along it (in space)."""
    out = []
    for e in edges:
        n = max(2, math.ceil(e.Length() / (RIM_STEP * h))) + 1
        out.append(np.array([v.toTuple() for v in e.positions(np.linspace(0.0, 1.0, n))]))
    return out


class Rims:
    """A face's rims (:func:`rim_edges`), as points along them
    (:func:`rim_lines`): ``p3`` in space, ``c`` in the chart, ``inward``
    the unit direction into the face there (in the chart)."""

    def __init__(self, lines: list[np.ndarray], chart, inside, h: float):
        c, inward = [], []
        period = chart.period
        for q in lines:
            cq_ = chart(q)
            d = np.gradient(cq_, axis=0)
            if period is not None:  # across the cut, the short way
                d[:, 0] -= period * np.round(d[:, 0] / period)
            nrm = np.stack([-d[:, 1], d[:, 0]], axis=1)
            nrm /= np.maximum(np.linalg.norm(nrm, axis=1), 1e-300)[:, None]
            probe = 0.3 * h * chart.scale(cq_)[:, None] * nrm
            plus, minus = inside(cq_ + probe), inside(cq_ - probe)
            # per point where the probes disagree, else the edge's majority
            sign = np.where(plus & ~minus, 1.0, np.where(minus & ~plus, -1.0, 0.0))
            sign[sign == 0] = 1.0 if (sign > 0).sum() >= (sign < 0).sum() else -1.0
            c.append(cq_)
            inward.append(sign[:, None] * nrm)
        self.p3 = np.vstack(lines)
        self.c = np.vstack(c)
        self.inward = np.vstack(inward)
        self.tree3 = cKDTree(self.p3)
        self.tree2 = cKDTree(self.c)
        self.scale = chart.scale(self.c)

    def distance(self, x: np.ndarray) -> np.ndarray:
        """Distance in space from each point to the rims (to ``RIM_STEP`` h)."""
        return self.tree3.query(x)[0]

    def clamp(self, inside, margin: float) -> RimClamp:
        """Keep free samples in the face and ``margin`` (times the chart's
        scale) from the rims (:class:`RimClamp`)."""
        return RimClamp(self.c, self.inward, self.scale, self.tree2, inside, margin)

    def unfold(self, x: np.ndarray, reach: float, clear: float) -> np.ndarray:
        """Points across the rims (in space) unfolded into the chart: each
        at its distance from its nearest rim point, straight out of the
        face; only those within ``reach`` of a rim and farther than ``clear``."""
        if x.shape[0] == 0:
            return np.empty((0, 2))
        d, j = self.tree3.query(x)
        keep = (d < reach) & (d > clear)
        d, j = d[keep], j[keep]
        return self.c[j] - (d * self.scale[j])[:, None] * self.inward[j]


@dataclass
class _View:
    """A face in one chart: its domain there (``inside``), its rims, and
    the spacing its repair aims at there (``step``)."""

    chart: Any
    inside: Callable[[np.ndarray], np.ndarray]
    rims: Rims
    step: float


def _view(chart, tri3: np.ndarray, lines, h: float, inside=None, step=None) -> _View:
    """``chart``'s view of a face: its domain the face's tessellation
    ``tri3`` filled in (unless ``inside`` is given), its rims ``lines``."""
    if inside is None:
        grow = h / RASTER / math.sqrt(2.0) if chart.grow_raster else 0.0
        inside = TriangleRaster(chart.triangles(tri3), h / RASTER, chart.period, grow=grow)
    return _View(chart, inside, Rims(lines, chart, inside, h), h if step is None else step)


def _sphere_chart(face) -> _Sphere:
    """A sphere face's stereographic map from the point opposite its
    centre; where the face's centre is the sphere's (a ball drilled
    through, bitten on opposite sides alike), from the sphere's own pole
    (its surface's axis): such a face reaches round too far for one map
    and is laid as the whole ball (:func:`_bitten_ball`)."""
    got = face_pole(face)
    if got is not None:
        return _Sphere(*got)
    sph = basis_surface(face).Sphere()
    return _Sphere(
        np.array(sph.Location().Coord()),
        float(sph.Radius()),
        np.array(sph.Position().Direction().Coord()),
    )


def _cylinder(face):
    cyl = basis_surface(face).Cylinder()
    pos = cyl.Position()
    return (
        np.array(pos.Location().Coord()),
        np.array(pos.XDirection().Coord()),
        np.array(pos.YDirection().Coord()),
        np.array(pos.Direction().Coord()),
        float(cyl.Radius()),
    )


def _on_surface(face, points: np.ndarray, tol: float) -> np.ndarray:
    """Whether each point lies on the face's sphere, cylinder or cone (to ``tol``)."""
    if face.geomType() == "SPHERE":
        sph = basis_surface(face).Sphere()
        d = np.linalg.norm(points - np.array(sph.Location().Coord()), axis=1)
        return np.abs(d - float(sph.Radius())) < tol
    if face.geomType() == "CONE":
        apex, axis, _, _, sin_a = _cone(face)
        q = points - apex
        along = dot(q, axis)
        radial = np.linalg.norm(q - along[:, None] * axis, axis=1)
        return (np.abs(radial * math.sqrt(1.0 - sin_a * sin_a) - along * sin_a) < tol) & (along > 0)
    o, _, _, ez, radius = _cylinder(face)
    q = points - o
    radial = np.linalg.norm(q - dot(q, ez)[:, None] * ez, axis=1)
    return np.abs(radial - radius) < tol


def _repair_in(fi, face, view: _View, s: Samples, h, tol, movable, good, images):
    """One repair of face ``fi`` in ``view``: ``movable(c, d)`` says which
    of its samples (at ``c`` in the chart, ``d`` from the rims in space)
    may move; ``images`` whether its samples near the chart's cut are
    imaged across it.  Returns the report, or None when nothing moves."""
    chart, inside, rims = view.chart, view.inside, view.rims
    near_rim = rims.distance(s.points) < ON_RIM * h
    on = _on_surface(face, s.points, tol)
    cand = np.flatnonzero(on | (near_rim & s.on_feature))
    c = chart(s.points[cand])
    # a sample at a map's centre of projection (a bitten ball's pole) has no
    # place on it: it is far from the rims, and stays out of the repair
    mine = (inside(c) | (near_rim[cand] & s.on_feature[cand])) & np.isfinite(c).all(axis=1)
    idx, c = cand[mine], c[mine]
    if idx.size == 0:
        return None
    order = np.lexsort((np.round(c[:, 1] / h, 6), np.round(c[:, 0] / h, 6)))
    idx, c = idx[order], c[order]
    fixed = s.on_feature[idx]
    free = ~fixed & movable(c, rims.distance(s.points[idx]))
    if not free.any():
        return None
    own = np.zeros(s.points.shape[0], dtype=bool)
    own[idx] = True
    frame = [rims.unfold(s.points[~own & ~s.on_feature], FRAME_REACH * h, 1e-6 * h)]
    if images:
        frame += chart.images(c, IMAGE_REACH * h)
    args = dict(
        inside=inside,
        clamp=rims.clamp(inside, CLEAR * h),
        frame=np.vstack(frame),
        judge_frame=True,
    )
    step = view.step
    r = unstuck(c, free, step, repair(c, free, step, **args), good, shake=chart.shaken, **args)
    pts3 = chart.inverse(r.uv)
    kept = r.origin >= 0
    stay = kept & ~free[np.maximum(r.origin, 0)]
    pts3[stay] = s.points[idx[r.origin[stay]]]  # the fixed samples exactly where they were
    return s.put(idx, r, pts3, fi, f"{face.geomType().lower()} chart")


def _relay(s: Samples, fi: int, idx, within, p3, keep, rows, rims: np.ndarray, h: float):
    """Lay face ``fi`` out anew: its samples ``idx`` that lie in it
    (``within``), but for those on its rims, give way to the laid points
    ``p3`` that lie in it (``keep``) and ``KEEP_OFF`` h off its rims
    (points ``rims``), each on the line ``rows`` after the last one."""
    keep = keep.copy()
    keep[keep] = cKDTree(rims).query(p3[keep])[0] >= KEEP_OFF * h
    drop = idx[within & _off_rims(s, idx, rims, h)]
    line = int(s.line_id.max()) + 1 if s.line_id.size else 0
    n = int(keep.sum())
    s.replace(drop, p3[keep], line + rows[keep], np.full(n, fi), np.zeros(n, dtype=bool))


def _lay_lattice(fi, face, view: _View, tri3, lines, s: Samples, h: float, tol: float) -> None:
    """Replace the face's samples off its rims by a square lattice of side
    h in the chart (rows along its first axis, one through the origin: its
    Delaunay triangles are right isosceles, ratio 1/√2 on the map), without
    the points nearer than ``KEEP_OFF`` h to a rim.  The chart's scale is
    at least 1 (1 at a stereographic map's centre), so the samples are at
    most h apart on the surface."""
    chart, inside = view.chart, view.inside
    tri = chart(tri3.reshape(-1, 3))
    lo, hi = tri.min(axis=0), tri.max(axis=0)
    rows = np.arange(math.floor(lo[1] / h) - 1, math.ceil(hi[1] / h) + 2)
    cols = np.arange(math.floor(lo[0] / h) - 1, math.ceil(hi[0] / h) + 2)
    jj, ii = np.meshgrid(rows, cols, indexing="ij")
    c = np.stack([ii * h, jj * h], axis=-1).reshape(-1, 2).astype(np.float64)
    on = np.flatnonzero(_on_surface(face, s.points, tol))
    _relay(
        s,
        fi,
        on,
        inside(chart(s.points[on])),
        chart.inverse(c),
        inside(c),
        jj.reshape(-1) - rows[0],
        np.vstack(lines),
        h,
    )


def _cuts(face) -> list[float]:
    """Where a cylinder face is unrolled from: going round, at its seam and
    half a turn on; else in the middle of the missing turn."""
    umin, umax, _, _ = face._uvBounds()
    return [umin, umin + math.pi] if goes_round(face) else [0.5 * (umin + umax) + math.pi]


def _lay_cylinder(fi, face, view: _View, lines, s: Samples, h: float, tol: float) -> None:
    """Replace a cylinder face's samples off its rims by the lattice its
    unrolled chart (``view``, from its first cut) carries: columns at the
    angles of the samples on a whole circle round it (its lowest one, as
    :func:`sr33.samplers.layers.lattice_cylinder_faces` takes a rim's), else
    evenly spaced (about h apart), and rows as far apart as the columns
    from that circle (else from the face's lowest point), so that the cells
    are squares; without the points nearer than ``KEEP_OFF`` h to a rim."""
    o, ex, ey, ez, radius = _cylinder(face)
    umin, umax, vmin, vmax = face._uvBounds()
    round_ = goes_round(face)
    chart = view.chart
    q = s.points - o
    axial = dot(q, ez)
    radial = np.linalg.norm(q - axial[:, None] * ez, axis=1)
    on = (np.abs(radial - radius) < tol) & (axial > vmin - tol) & (axial < vmax + tol)
    angles, z0 = None, vmin
    circles = [
        e
        for e in rim_edges(face)
        if e.geomType() == "CIRCLE"
        and e.IsClosed()
        and abs(abs(dot(np.array(e.normal().toTuple()), ez)) - 1.0) < 1e-9
    ]
    for e in sorted(circles, key=lambda e: float(dot(np.array(e.Center().toTuple()) - o, ez))):
        at = float(dot(np.array(e.Center().toTuple()) - o, ez))
        mine = on & s.on_feature & (np.abs(axial - at) < tol)
        if mine.sum() >= 3:
            angles = np.sort(libm.arctan2(dot(q[mine], ey), dot(q[mine], ex)) % (2 * math.pi))
            z0 = at
            break
    if angles is None:
        if round_:
            n = steps(2 * math.pi * radius, h, 3)
            angles = umin + 2 * math.pi * np.arange(n) / n
        else:
            n = steps(radius * (umax - umin), h, 1)
            angles = umin + (umax - umin) * np.arange(1, n) / n
    gap = radius * (2 * math.pi if round_ else umax - umin) / max(angles.size, 1)
    k = np.arange(math.floor((vmin - z0) / gap), math.ceil((vmax - z0) / gap) + 1)
    z = z0 + k[k != 0] * gap
    z = z[(z > vmin) & (z < vmax)]
    zz, aa = np.repeat(z, angles.size), np.tile(angles, z.size)
    p3 = o + zz[:, None] * ez + radius * (np.cos(aa)[:, None] * ex + np.sin(aa)[:, None] * ey)
    idx = np.flatnonzero(on)
    _relay(
        s,
        fi,
        idx,
        view.inside(chart(s.points[idx])),
        p3,
        view.inside(chart(p3)),
        np.repeat(np.arange(z.size), angles.size),
        np.vstack(lines),
        h,
    )


def _lay_notched_cone(fi, face, view: _View, lines, s: Samples, h: float, tol: float):
    """Replace a notched cone face's samples off its rims by the rings of
    its whole cone (:func:`sr33.samplers.layers.lay_cone`, from its widest
    rim to the apex) that lie in the face (``view``, a development) and
    ``KEEP_OFF`` h off its rims.  Returns the layout's report, or None
    where it lays nothing (its widest rim a smooth edge)."""
    lay = lay_cone(fi, face, s, h, tol, whole=False)
    if lay is None:
        return None
    chart = view.chart
    on = np.flatnonzero(_on_surface(face, s.points, tol))
    rows = np.where(lay.rows >= 0, lay.rows, lay.nrows)
    # the apex, where the face keeps it, stays: the rings round it are laid for it
    apex = np.linalg.norm(s.points[on] - chart.apex, axis=1) < tol
    _relay(
        s,
        fi,
        on,
        view.inside(chart(s.points[on])) & ~apex,
        lay.points,
        view.inside(chart(lay.points)),
        rows,
        np.vstack(lines),
        h,
    )
    return {**lay.report, "kind": "notched cone rings"}


def _off_rims(s: Samples, idx: np.ndarray, rims: np.ndarray, h: float) -> np.ndarray:
    """Which of the samples ``idx`` a laid lattice replaces: those off the
    features, and feature samples off the rims (points ``rims``): a seam's
    end, which the scan samples as a corner (a ball's pole)."""
    far = cKDTree(rims).query(s.points[idx])[0] > ON_RIM * h
    return ~s.on_feature[idx] | far


def _bites(lines: list[np.ndarray], centre: np.ndarray, tol: float):
    """A sphere face's rims (``lines``: each edge as points along it)
    grouped into bites: edges that meet (an end of one within ``tol`` of an
    end of another) are one bite's, whatever curves they are.  Returns, per
    bite, its edges' indices (ascending) and the unit direction from the
    sphere's centre to the bite's centre (the mean of its rim points'
    directions); bites in the order of their first edge."""
    n = len(lines)
    group = list(range(n))

    def root(i: int) -> int:
        while group[i] != i:
            group[i] = group[group[i]]
            i = group[i]
        return i

    ends = np.array([[q[0], q[-1]] for q in lines]).reshape(-1, 3)
    for a, b in cKDTree(ends).query_pairs(tol):
        ra, rb = root(a // 2), root(b // 2)
        if ra != rb:
            group[max(ra, rb)] = min(ra, rb)
    out = []
    for g in sorted({root(i) for i in range(n)}):
        members = [i for i in range(n) if root(i) == g]
        d = np.vstack([lines[i] for i in members]) - centre
        d /= np.linalg.norm(d, axis=1)[:, None]
        mean = d.mean(axis=0)
        out.append((members, mean / max(float(np.linalg.norm(mean)), 1e-300)))
    return out


def _bite_map(centre, radius: float, towards: np.ndarray, tri3, lines, h: float):
    """The stereographic map centred in a bite (``towards``, the direction
    from the sphere's centre to the bite's centre; projected from the point
    opposite) with the face's inside there, filled in as far as 20° past
    the bite's farthest rim point (beyond 10° past it, everything counts
    as the face: the map runs to infinity at its centre of projection).
    None where a rim point lies ``BITE`` or more from the bite's centre."""
    bite = _Sphere(centre, radius, towards)
    rim_pts = np.vstack(lines)
    rim_cos = dot(rim_pts - centre, towards) / radius
    if rim_cos.min() <= math.cos(BITE):
        return None
    far = math.acos(max(-1.0, rim_cos.min()))
    near = (dot(tri3.reshape(-1, 3) - centre, towards).reshape(-1, 3) / radius) > math.cos(
        min(far + math.radians(20.0), math.pi * 0.95)
    )
    beyond = 2.0 * radius * math.tan(min(far + math.radians(10.0), math.pi * 0.9) / 2.0)
    inside = TriangleRaster(
        bite(tri3[near.all(axis=1)].reshape(-1, 3)).reshape(-1, 3, 2), h / RASTER, beyond=beyond
    )
    return bite, inside


def _bitten_ball(fi, face, chart, tri3, lines, s: Samples, h: float, tol: float, size: float):
    """A sphere face too wide for one map (``chart``, centred on the face;
    ``tri3`` its tessellation, ``lines`` its rims): a ball with bites
    taken out (by a box, another ball, a hole through it).  Laid as the
    whole ball is (:func:`sr33.samplers.layers.lattice_revolved_body`, rings
    with halving columns between two poles), keeping the rings' samples on
    the face and h / 2 off its rims; then each bite's boundary layer is
    repaired on the stereographic map centred in that bite (its rims within
    ``BITE`` of its centre, where the map's scale is at most
    1 / cos²(BITE / 2)).  The bites are the rims grouped where they meet
    (:func:`_bites`).  With one bite, the rings' axis runs through the
    face's centre (its far pole in the bite); with more, through the
    widest bite (the one whose rims reach farthest from its centre), and
    the others' repairs see the first ones' answers.  Returns the reports
    (one per bite), or None where the face is not of that kind (a rim
    ``BITE`` or more from its bite's centre)."""
    import cadquery as cq

    centre, radius = chart.centre, chart.radius
    bites = _bites(lines, centre, max(tol, 1e-3 * h))
    if len(bites) == 1:
        bites = [(bites[0][0], -chart.pole)]  # the face's centre opposite: as laid before
    maps = []
    for members, towards in bites:
        got = _bite_map(centre, radius, towards, tri3, [lines[i] for i in members], h)
        if got is None:
            return None  # a rim far from its bite's centre: not one map's
        maps.append((members, got[0], got[1]))

    def nearest(members, towards) -> float:
        # the cosine of the bite's farthest rim point from its centre
        return float(dot(np.vstack([lines[i] for i in members]) - centre, towards).min())

    # (cosines to 1e-6: bites alike, a drilled ball's two rims, go by their order)
    widest = min(range(len(bites)), key=lambda k: (round(nearest(*bites[k]) / radius, 6), k))
    axis = -bites[widest][1]

    def inside_all(p3: np.ndarray) -> np.ndarray:
        ok = np.ones(p3.shape[0], dtype=bool)
        for _, bite, inside in maps:
            ok &= inside(bite(p3))
        return ok

    ball = cq.Solid.makeSphere(
        radius, cq.Vector(*centre), cq.Vector(*axis), angleDegrees1=-90, angleDegrees2=90
    )
    poles = np.array([centre + radius * axis, centre - radius * axis])
    laid = Samples(poles, np.full(2, -1), np.zeros(2, dtype=np.int64), np.ones(2, dtype=bool))
    if not lattice_revolved_body(ball, laid, h, size):
        return None
    on = np.flatnonzero(_on_surface(face, s.points, tol))
    _relay(
        s,
        fi,
        on,
        inside_all(s.points[on]),
        laid.points,
        inside_all(laid.points),
        np.maximum(laid.line_id, 0),
        np.vstack(lines),
        h,
    )
    reports = []
    for members, bite, inside in maps:
        own = [lines[i] for i in members]
        scale = float(np.median(bite.scale(bite(np.vstack(own)))))
        view = _view(bite, tri3, own, h, inside=inside, step=h * scale)
        rep = _repair_in(
            fi, face, view, s, h, tol, functools.partial(_layer, h=h), POLE_GOOD, False
        )
        if rep is not None:
            reports.append(rep)
    return reports


def _layer(c: np.ndarray, d: np.ndarray, *, h: float) -> np.ndarray:
    """The samples within ``LAYER`` h of a rim (``d``) move."""
    return d < LAYER * h


def _cut_pass(c: np.ndarray, d: np.ndarray, *, h: float, chart, passes: int, k: int, only=None):
    """Which samples of a face unrolled or developed in ``chart`` move in
    pass ``k`` of ``passes`` (at ``c`` in the chart, ``d`` from the rims):
    those within ``LAYER`` h of a rim (of the rims in the k-d tree
    ``only``, in space, when given: a notched cone's notch); with two
    passes, not within ``CUT_CLEAR`` h of the pass's cut, and in the second
    only those round the first pass's cut (half a turn on)."""
    layer = _layer(c, d, h=h)
    if only is not None:
        layer &= only.query(chart.inverse(c))[0] < LAYER * h
    if passes == 1:
        return layer
    away = chart.from_cut(c) > CUT_CLEAR * h
    if k == 0:
        return layer & away
    return layer & away & (chart.from_half_turn(c) < (CUT_CLEAR + 1.0) * h)


def _cone(face):
    """A cone face's apex, axis, ``ex``, ``ey`` and the sine of its
    half-angle (:func:`sr33.samplers.faces.cone_frame`)."""
    apex, axis, ex, ey, half = cone_frame(face)
    return apex, axis, ex, ey, math.sin(half)


def _notched_cone(face, rims, lines, tol: float):
    """The rims (edges ``rims``, as points ``lines``) of a cone face that
    goes round, is no whole band and whose widest rim is a whole circle (a
    cone notched by a boolean away from its base): the other rims' points
    (the notch), or None."""
    if whole_band(face) or not goes_round(face):
        return None
    apex, axis, _, _, _ = _cone(face)
    reach = [float(dot(q - apex, axis).max()) for q in lines]
    widest = int(np.argmax(reach))
    edge = rims[widest]
    if edge.geomType() != "CIRCLE" or not edge.IsClosed():
        return None
    rest = [q for i, q in enumerate(lines) if i != widest]
    if not rest or max(float(dot(q - apex, axis).max()) for q in rest) > reach[widest] - tol:
        return None
    return np.vstack(rest)


def repair_curved_faces(occ, s: Samples, h: float, size: float, skip=frozenset()) -> list[dict]:
    """Repair every sphere and cylinder face that no layout took (not in
    ``skip``) and whose rims are all sampled, in its own chart (see the
    module's notes).

    Parameters
    ----------
    occ : cadquery.Shape
        The shape sampled.
    s : Samples
        Its samples, edited in place.
    h : float
        The sample spacing.
    size : float
        The shape's bounding-box diagonal (tolerances).
    skip : set of int
        Faces laid out or repaired already.

    Returns
    -------
    list of dict
        One report per repair (kind ``"sphere chart"`` or ``"cylinder
        chart"``; a cylinder going all the way round has two).

    Notes
    -----
    Condition III-ii of the paper (Section 3) on the faces the layouts
    leave to the scan rows; the spheres first (all their samples move),
    then the cylinders' boundary layers with the spheres' answers across
    their rims.
    """
    tol = 1e-7 * size
    reports: list[dict] = []
    faces = occ.Faces()
    spheres, cylinders, cones = [], [], []
    notches: dict[int, cKDTree] = {}  # a notched cone's notch: its rims' points
    feature = s.points[s.on_feature]
    if feature.shape[0] == 0:
        return reports
    for fi, face in enumerate(faces):
        kind = face.geomType()
        if fi in skip or kind not in ("SPHERE", "CYLINDER", "CONE"):
            continue
        rims = rim_edges(face)
        if not rims:
            continue
        mids = np.array([e.positionAt(0.5).toTuple() for e in rims])
        if cKDTree(feature).query(mids)[0].max() > RIM_SAMPLED * h:
            continue  # a smooth edge: the face blends into its neighbour
        lines = rim_lines(rims, h)
        if kind == "SPHERE":
            spheres.append((fi, face, lines))
        elif kind == "CONE":
            notch = _notched_cone(face, rims, lines, tol)
            if notch is not None:
                cones.append((fi, face, lines))
                notches[fi] = cKDTree(notch)
        else:  # a whole band only where no layout took it (it is in skip otherwise)
            cylinders.append((fi, face, lines))
    views: dict[int, list[_View]] = {}  # per face, its chart (a cylinder's: per cut)
    wide = []
    for fi, face, lines in spheres:
        chart = _sphere_chart(face)
        tri3 = _face_triangles(face, h / 20)
        if dot(tri3.reshape(-1, 3) - chart.centre, chart.pole).min() <= REACH * chart.radius:
            wide.append((fi, face, chart, tri3, lines))  # too far round for one map
            continue
        views[fi] = [_view(chart, tri3, lines, h)]
        _lay_lattice(fi, face, views[fi][0], tri3, lines, s, h, tol)
    for fi, face, lines in cylinders:
        o, ex, ey, ez, radius = _cylinder(face)
        tri3 = _face_triangles(face, h / 20)
        views[fi] = [
            _view(Unrolled(o, ex, ey, ez, radius, cut), tri3, lines, h) for cut in _cuts(face)
        ]
        _lay_cylinder(fi, face, views[fi][0], lines, s, h, tol)
    for fi, face, lines in cones:
        apex, axis, ex, ey, sin_a = _cone(face)
        tri3 = _face_triangles(face, h / 20)
        views[fi] = [
            _view(Developed(apex, axis, ex, ey, sin_a, cut), tri3, lines, h)
            for cut in (0.0, math.pi)
        ]
        rep = _lay_notched_cone(fi, face, views[fi][0], lines, s, h, tol)
        if rep is not None:
            reports.append(rep)
        cylinders.append((fi, face, lines))  # repaired in its two developments as a cylinder
    for fi, face, chart, tri3, lines in wide:
        reports += _bitten_ball(fi, face, chart, tri3, lines, s, h, tol, size) or []
    layer = functools.partial(_layer, h=h)
    for _ in range(ROUNDS):
        for fi, face, _ in spheres:
            if fi in views:
                rep = _repair_in(fi, face, views[fi][0], s, h, tol, layer, POLE_GOOD, False)
                if rep is not None:
                    reports.append(rep)
        for fi, face, _ in cylinders:
            passes = len(views[fi])
            for k, view in enumerate(views[fi]):
                move = functools.partial(
                    _cut_pass, h=h, chart=view.chart, passes=passes, k=k, only=notches.get(fi)
                )
                rep = _repair_in(fi, face, view, s, h, tol, move, STUCK, passes > 1)
                if rep is not None:
                    reports.append(rep)
    return reports
