"""A planar (or developed) face's domain in 2-D: inside tests, its circular
arcs, clamps that keep samples on the face, distances to its boundary.

These are the pieces the layouts and repairs of a face work with in its
own coordinates (:mod:`sr33.samplers.layers`, :mod:`sr33.samplers.disks`,
:mod:`sr33.samplers.spheres`); plain numpy.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

from sr33 import libm
from sr33.mesh import dot

from . import _line_kernels as line_kernels
from ._repair_kernels import grid_lookup

ARC_MARGIN = 0.5  # free samples keep this far (times h) from a cylinder's rim (else h / 4)


class Raster:
    """Inside test of a 2-D domain given by its boundary segments (even-odd rule)."""

    def __init__(self, segments: np.ndarray, cell: float):
        lo = segments.reshape(-1, 2).min(axis=0) - 2 * cell
        hi = segments.reshape(-1, 2).max(axis=0) + 2 * cell
        self.lo, self.cell = lo, cell
        nx, ny = (np.ceil((hi - lo) / cell).astype(int) + 1).tolist()
        ys = lo[1] + (np.arange(ny) + 0.5) * cell
        xs = lo[0] + (np.arange(nx) + 0.5) * cell
        a, b = segments[:, 0], segments[:, 1]
        y0, y1 = a[:, 1], b[:, 1]
        grid = np.zeros((ny, nx), dtype=bool)
        for j, y in enumerate(ys):
            cross = (y0 <= y) != (y1 <= y)
            if not cross.any():
                continue
            t = (y - y0[cross]) / (y1[cross] - y0[cross])
            x = np.sort(a[cross, 0] + t * (b[cross, 0] - a[cross, 0]))
            count = np.searchsorted(x, xs)
            grid[j] = count % 2 == 1
        self.grid = grid

    def __call__(self, pts: np.ndarray) -> np.ndarray:
        return grid_lookup(as_points(pts), self.lo, float(self.cell), self.grid)


def as_points(p) -> np.ndarray:
    """``p`` as a C-contiguous (n, 2) float64 array (the kernels' input)."""
    return np.ascontiguousarray(np.asarray(p, dtype=np.float64).reshape(-1, 2))


# The repair's callbacks on a face bounded by straight edges, as data: the
# repair runs its descent in one numba loop when every callback of a
# problem is one of these (:func:`sr33.samplers.repair._steps`), else it
# calls them step by step.  Edges are given as in
# :mod:`sr33.samplers._line_kernels`: start ``a`` (m, 2), direction ``d``
# (m, 2), squared length ``dd`` (m,).


@dataclass(frozen=True, eq=False)
class LineProjection:
    """Each point moved to the nearest point of its nearest edge, its
    parameter kept within ``[lo, 1 - lo]`` of that edge (``lo`` (m,))."""

    a: np.ndarray
    d: np.ndarray
    dd: np.ndarray
    lo: np.ndarray

    def __call__(self, p: np.ndarray) -> np.ndarray:
        return line_kernels.project(as_points(p), self.a, self.d, self.dd, self.lo)


@dataclass(frozen=True, eq=False)
class LineClamp:
    """Points moved ``least`` inside every edge they are less than that
    inside and less than ``-beyond`` outside of, edge after edge
    (``normals`` (m, 2) unit, into the face)."""

    a: np.ndarray
    d: np.ndarray
    dd: np.ndarray
    normals: np.ndarray
    least: float
    beyond: float

    def __call__(self, p: np.ndarray) -> np.ndarray:
        return line_kernels.clamp(
            as_points(p), self.a, self.d, self.dd, self.normals, self.least, self.beyond
        )


@dataclass(frozen=True, eq=False)
class LineGhosts:
    """The neighbouring faces unfolded across straight edges: ``corners``,
    then the points on each edge moved ``h`` and ``2 h`` outwards
    (``inward`` (m, 2) unit normals into the face).  ``own`` (m,) tells
    what each edge gives (:data:`sr33.samplers._line_kernels.GHOSTS`, or
    ``OWN_GHOSTS``: only those no other edge is nearer to, or
    ``NO_GHOSTS``: another edge of the face, there for that test; None:
    ``GHOSTS`` for all)."""

    a: np.ndarray
    d: np.ndarray
    dd: np.ndarray
    inward: np.ndarray
    h: float
    corners: np.ndarray
    own: np.ndarray | None = None

    def ghosting(self) -> np.ndarray:
        """(m,) int64: what each edge gives (see ``own``)."""
        if self.own is None:
            return np.full(self.a.shape[0], line_kernels.GHOSTS, dtype=np.int64)
        return np.asarray(self.own, dtype=np.int64)

    def __call__(self, p: np.ndarray) -> np.ndarray:
        return line_kernels.ghosts(
            as_points(p),
            self.a,
            self.d,
            self.dd,
            self.inward,
            self.h,
            self.corners,
            self.ghosting(),
        )


@dataclass(frozen=True, eq=False)
class Chain:
    """The composition of callables, in order (clamps one after another)."""

    parts: tuple

    def __call__(self, p: np.ndarray) -> np.ndarray:
        for f in self.parts:
            p = f(p)
        return p


@dataclass(frozen=True)
class Arc:
    centre: np.ndarray  # 2-D
    radius: float
    start: float  # the arc runs from angle start to start + span (0, 2 pi when closed)
    span: float
    closed: bool
    slides: bool  # its samples slide along it (it bounds a full cylinder)
    wall: int = -1  # the index of that full cylinder's face, else -1

    @classmethod
    def through(cls, centre, radius: float, s, m, f, slides: bool = False, wall: int = -1):
        """The open arc of that circle from ``s`` through ``m`` to ``f`` (2-D points)."""
        a0, am, a1 = (math.atan2(*(np.asarray(q) - centre)[::-1]) for q in (s, m, f))
        span = (a1 - a0) % (2 * math.pi)
        if (am - a0) % (2 * math.pi) > span:  # the arc runs the other way round
            a0, span = a1, 2 * math.pi - span
        return cls(centre, radius, a0, span, False, slides, wall)

    def distance(self, p: np.ndarray) -> np.ndarray:
        return np.abs(np.linalg.norm(p - self.centre, axis=1) - self.radius)


def unfold_across_arc(x, circle, arc: Arc, side: float, to2d, reach: float, scale=None, clear=None):
    """Points of the face across a circular sharp edge unfolded into a
    face's chart: each at its distance from the edge's circle, straight out
    from its foot on the circle (exact across a straight edge, first order
    across an arc).  ``circle`` is the edge's (centre, unit normal, radius)
    in 3-D, ``arc`` its image in the chart and ``side`` +1 where the face
    lies inside it (:func:`arc_sides`); only points within ``reach`` of the
    circle whose feet fall on the arc are kept, and farther than ``clear``
    when given (the edge's own samples are no frame).  ``scale`` maps the
    feet's chart points to the chart's scale there (a sphere's
    stereographic map), else 1."""
    cc, nn, rr = circle
    w = x - cc
    w -= np.outer(dot(w, nn), nn)
    length = np.linalg.norm(w, axis=1)
    ok = length > 1e-12 * rr
    y = cc + rr * w[ok] / length[ok, None]  # the nearest point of the circle
    d = np.linalg.norm(x[ok] - y, axis=1)
    near = d < reach if clear is None else (d < reach) & (d > clear)
    if not near.any():
        return np.empty((0, 2))
    yy, d = to2d(y[near]), d[near]
    ang = (libm.arctan2(*(yy - arc.centre).T[::-1]) - arc.start) % (2 * math.pi)
    on_arc = arc.closed | (ang <= arc.span)
    yy, d = yy[on_arc], d[on_arc]
    out_dir = side * (yy - arc.centre)
    out_dir /= np.linalg.norm(out_dir, axis=1)[:, None]
    if scale is not None:
        d = d * scale(yy)
    return yy + d[:, None] * out_dir


def arc_sides(arcs: list[Arc], raster: Raster, h: float) -> list[float]:
    """Per arc, +1 when the face lies inside its circle, -1 when outside."""
    sides = []
    for a in arcs:
        mid = a.start + a.span / 2
        probe = a.centre + (a.radius - 0.5 * h) * np.array([[math.cos(mid), math.sin(mid)]])
        sides.append(1.0 if raster(probe)[0] else -1.0)
    return sides


def arc_clamp(arcs: list[Arc], sides: list[float], h: float) -> ArcClamp:
    """Keep free samples on the face side of every arc, at least ``ARC_MARGIN`` h
    from a full cylinder's rim (nearer, a sample makes a Delaunay triangle with
    the wall's first row across the rim, which the repair does not judge) and
    h / 4 from other arcs."""
    return ArcClamp(
        *_arc_arrays(arcs),
        np.array(sides, dtype=np.float64).reshape(-1),
        np.array([(ARC_MARGIN if a.slides else 0.25) * h for a in arcs], dtype=np.float64),
    )


def _arc_arrays(arcs: list[Arc]):
    """(centres, radii, starts, spans, closed) of ``arcs`` as arrays."""
    return (
        np.array([a.centre for a in arcs], dtype=np.float64).reshape(-1, 2),
        np.array([a.radius for a in arcs], dtype=np.float64).reshape(-1),
        np.array([a.start for a in arcs], dtype=np.float64).reshape(-1),
        np.array([a.span for a in arcs], dtype=np.float64).reshape(-1),
        np.array([a.closed for a in arcs], dtype=np.bool_).reshape(-1),
    )


@dataclass(frozen=True, eq=False)
class ArcClamp:
    """Points moved onto the face's side of every arc (``side`` +1 where the
    face lies inside its circle), ``margin`` (per arc) from it where they
    fall within its span and are nearer, arc after arc."""

    centre: np.ndarray
    radius: np.ndarray
    start: np.ndarray
    span: np.ndarray
    closed: np.ndarray
    side: np.ndarray
    margin: np.ndarray

    def __call__(self, p: np.ndarray) -> np.ndarray:
        return line_kernels.clamp_arcs(
            as_points(p),
            self.centre,
            self.radius,
            self.start,
            self.span,
            self.closed,
            self.side,
            self.margin,
        )


@dataclass(frozen=True, eq=False)
class ArcGhosts:
    """The faces across arcs unfolded: the points on an arc moved ``h``
    and ``2 h`` across it, straight out from its centre (``side`` +1 where
    the face lies inside its circle)."""

    centre: np.ndarray
    radius: np.ndarray
    side: np.ndarray
    h: float

    @classmethod
    def of(cls, arcs: list[Arc], sides: list[float], h: float) -> ArcGhosts:
        centre, radius, _, _, _ = _arc_arrays(arcs)
        return cls(centre, radius, np.array(sides, dtype=np.float64).reshape(-1), float(h))

    def __call__(self, p: np.ndarray) -> np.ndarray:
        return line_kernels.ghosts_arcs(as_points(p), self.centre, self.radius, self.side, self.h)


@dataclass(frozen=True, eq=False)
class CurveProjection:
    """Each point moved to the nearest point of its nearest curve, arcs and
    straight edges in one table (``kind`` 0 a straight edge: ``a``, ``d``,
    ``dd``, its parameter kept within ``[lo, 1 - lo]``; 1 an arc: its
    ``centre``, ``radius``, ``start``, ``span``, ``closed``, kept ``margin``
    from an open arc's ends); the first of equally near curves."""

    kind: np.ndarray
    a: np.ndarray
    d: np.ndarray
    dd: np.ndarray
    lo: np.ndarray
    centre: np.ndarray
    radius: np.ndarray
    start: np.ndarray
    span: np.ndarray
    closed: np.ndarray
    margin: float

    @classmethod
    def of_lines(cls, lines: LineProjection) -> CurveProjection:
        """The straight edges of a :class:`LineProjection` as a table."""
        m = lines.a.shape[0]
        zeros = np.zeros(m)
        return cls(
            np.zeros(m, dtype=np.int64),
            lines.a,
            lines.d,
            lines.dd,
            lines.lo,
            np.zeros((m, 2)),
            zeros,
            zeros,
            zeros,
            np.zeros(m, dtype=np.bool_),
            0.0,
        )

    @classmethod
    def of_curves(cls, curves: list, lines, margin: float) -> CurveProjection:
        """``curves`` in order, each an :class:`Arc` or a straight edge
        (``lines``, in the order the straight ones come, as (a, d, dd, lo))."""
        m = len(curves)
        kind = np.array([0 if not isinstance(c, Arc) else 1 for c in curves], dtype=np.int64)
        a, d, dd, lo = np.zeros((m, 2)), np.zeros((m, 2)), np.ones(m), np.zeros(m)
        straight = np.flatnonzero(kind == 0)
        a[straight], d[straight], dd[straight], lo[straight] = lines
        centre, radius, start, span, closed = (
            np.zeros((m, 2)),
            np.zeros(m),
            np.zeros(m),
            np.zeros(m),
            np.zeros(m, dtype=np.bool_),
        )
        round_ = np.flatnonzero(kind == 1)
        arrays = _arc_arrays([curves[k] for k in round_])
        centre[round_], radius[round_], start[round_], span[round_], closed[round_] = arrays
        return cls(kind, a, d, dd, lo, centre, radius, start, span, closed, float(margin))

    def __call__(self, p: np.ndarray) -> np.ndarray:
        return line_kernels.project_curves(
            as_points(p),
            self.kind,
            self.a,
            self.d,
            self.dd,
            self.lo,
            self.centre,
            self.radius,
            self.start,
            self.span,
            self.closed,
            self.margin,
        )


@dataclass(frozen=True, eq=False)
class Joined:
    """The points of several ghost callables, one after another."""

    parts: tuple

    def __call__(self, p: np.ndarray) -> np.ndarray:
        return np.vstack([f(p) for f in self.parts])


def radial_clamp(lo: float, hi: float) -> RadialClamp:
    """Keep points at a distance from the origin within [lo, hi] (the origin stays)."""
    return RadialClamp(float(lo), float(hi))


@dataclass(frozen=True, eq=False)
class RadialClamp:
    """Points moved to a distance from the origin within [lo, hi] (the origin stays)."""

    lo: float
    hi: float

    def __call__(self, p: np.ndarray) -> np.ndarray:
        return line_kernels.clamp_radial(as_points(p), self.lo, self.hi)


@dataclass(frozen=True, eq=False)
class Sector:
    """Inside test of an annular sector about the origin: farther than
    ``inner`` and nearer than ``outer``, at an angle in [0, ``theta``) unless
    ``full`` (a disk or an annulus; a cone's development)."""

    outer: float
    inner: float
    theta: float
    full: bool

    def __call__(self, c: np.ndarray) -> np.ndarray:
        return line_kernels.inside_sector(
            as_points(c), float(self.outer), float(self.inner), float(self.theta), bool(self.full)
        )


def segment_distance(p: np.ndarray, seg: np.ndarray, step: float) -> np.ndarray:
    """Distance from each point to the segments, within ``step`` (a resampling that fine)."""
    a, b = seg[:, 0], seg[:, 1]
    length = np.linalg.norm(b - a, axis=1)
    counts = np.maximum(1, np.ceil(length / step).astype(np.int64))
    which = np.repeat(np.arange(seg.shape[0]), counts + 1)
    frac = (np.arange(which.size) - np.repeat(np.cumsum(counts + 1) - counts - 1, counts + 1)) / (
        np.repeat(counts, counts + 1)
    )
    dense = a[which] + frac[:, None] * (b - a)[which]
    d, _ = cKDTree(dense).query(p)
    return d


def halving_count(x: float) -> int:
    """The count of the form c 2^k (c = 3, 4 or 5) nearest ``x`` by ratio (the
    smaller on ties).

    A ring of equal gaps ends every other column (:func:`_end_columns`), so
    that a widest ring of such a count halves exactly, ring after ring; the
    ring round a pole then halves once more if it has over 5 columns, so
    that the pole's triangles have a chord longer than their sides (6 or
    more columns make them near equilateral, breaking Condition III-ii).
    Counts of this form lie at most a third apart, so the widest ring's
    gaps stay within 15% of h.  Measured on cone_tip: 3.3% of the samples
    violating with ``round(2 pi r / h)`` columns, 2.3% with this count.
    """
    best = 3
    for c in (3, 4, 5):
        n = c
        while n < 2 * max(x, 3.0):
            if abs(math.log(n / max(x, 1e-12))) < abs(math.log(best / max(x, 1e-12))) - 1e-12:
                best = n
            n *= 2
    return best


def _segment_gap(c: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Distance from each point ``c`` to the segment from ``a`` to ``b`` (row by row)."""
    ab = b - a
    t = np.clip(((c - a) * ab).sum(axis=1) / np.maximum((ab * ab).sum(axis=1), 1e-300), 0.0, 1.0)
    return np.linalg.norm(c - a - t[:, None] * ab, axis=1)


class TriangleRaster:
    """Inside test of a domain given as triangles (``(t, 3, 2)``): the
    cells of side ``cell`` whose centres lie in a triangle.  With
    ``period``, the domain repeats along the first axis: a triangle across
    ``[0, period)``'s ends is taken whole, and points are looked up modulo
    the period.  With ``beyond``, every point not within that distance of
    the origin is inside too (a map filled in only near its centre).  With
    ``grow``, a cell whose centre lies within that distance of a triangle
    is inside too: a fan of slivers (a cone's tessellation round its apex,
    thinner than a cell) leaves no holes.  The repair's descent kernel
    looks it up as it does (``_descent_kernels._inside``, kind 0)."""

    def __init__(
        self,
        tri: np.ndarray,
        cell: float,
        period: float | None = None,
        beyond: float = math.inf,
        grow: float = 0.0,
    ):
        self.beyond = float(beyond)
        tri = np.asarray(tri, dtype=np.float64)
        if period is not None:
            x = tri[..., 0]
            # a triangle across the cut has corners near both ends: lift the low ones
            across = (x.max(axis=1) - x.min(axis=1)) > 0.5 * period
            x[across] = np.where(x[across] < 0.5 * period, x[across] + period, x[across])
            tri = np.concatenate([tri, tri - [period, 0.0]])
        lo = tri.reshape(-1, 2).min(axis=0) - 2 * cell
        hi = tri.reshape(-1, 2).max(axis=0) + 2 * cell
        if period is not None:
            lo[0], hi[0] = 0.0, period
        self.lo, self.cell, self.period = lo, cell, period
        nx, ny = (np.ceil((hi - lo) / cell).astype(int) + 1).tolist()
        self.grid = np.zeros((ny, nx), dtype=bool)
        i0 = np.ceil((tri.min(axis=1) - grow - lo) / cell - 0.5).astype(np.int64)
        i1 = np.floor((tri.max(axis=1) + grow - lo) / cell - 0.5).astype(np.int64)
        i0 = np.maximum(i0, 0)
        i1 = np.minimum(i1, [nx - 1, ny - 1])
        span = np.maximum(i1 - i0 + 1, 0)
        counts = span[:, 0] * span[:, 1]
        k = np.repeat(np.arange(tri.shape[0]), counts)
        local = np.arange(k.size) - np.repeat(np.cumsum(counts) - counts, counts)
        ix = i0[k, 0] + local % np.maximum(span[k, 0], 1)
        iy = i0[k, 1] + local // np.maximum(span[k, 0], 1)
        c = lo + (np.stack([ix, iy], axis=1) + 0.5) * cell
        a, b, d = tri[k, 0], tri[k, 1], tri[k, 2]
        den = (b[:, 0] - a[:, 0]) * (d[:, 1] - a[:, 1]) - (d[:, 0] - a[:, 0]) * (b[:, 1] - a[:, 1])
        ok = np.abs(den) > 0
        den = np.where(ok, den, 1.0)
        w1 = (
            (c[:, 0] - a[:, 0]) * (d[:, 1] - a[:, 1]) - (d[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1])
        ) / den
        w2 = (
            (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (c[:, 0] - a[:, 0]) * (b[:, 1] - a[:, 1])
        ) / den
        eps = 1e-9
        ok &= (w1 >= -eps) & (w2 >= -eps) & (w1 + w2 <= 1 + eps)
        if grow > 0:
            for p, q in ((a, b), (b, d), (d, a)):
                ok |= _segment_gap(c, p, q) <= grow
        self.grid[iy[ok], ix[ok]] = True

    def __call__(self, pts: np.ndarray) -> np.ndarray:
        pts = given = as_points(pts)
        if self.period is not None:
            pts = np.ascontiguousarray(np.stack([pts[:, 0] % self.period, pts[:, 1]], axis=1))
        out = grid_lookup(pts, self.lo, float(self.cell), self.grid)
        if self.beyond < math.inf:  # (NaN, a map's centre of projection, too)
            out |= ~(np.linalg.norm(given, axis=1) <= self.beyond)
        return out


@dataclass(frozen=True)
class Buckets:
    """Points bucketed on a uniform grid, for the repair's descent kernel,
    which cannot call a k-d tree (``_descent_kernels._nearest``): the grid's
    corner ``lo``, its ``cell``, its ``dims`` (columns, rows), and per cell
    (column-major, ``i * rows + j``) its points' indices ascending,
    ``members[start[k]:start[k + 1]]``."""

    lo: np.ndarray
    cell: float
    dims: np.ndarray
    start: np.ndarray
    members: np.ndarray

    #: a cell is this many times the median gap between consecutive points
    #: (a rim's points are in order along it) ...
    CELL_GAPS = 10.0
    #: ... grown where the grid would have more than this many cells per point
    MAX_CELLS_PER_POINT = 16.0

    def table(self) -> tuple:
        """``(lo, cell, dims, start, members)``, as the kernel takes them."""
        return (self.lo, self.cell, self.dims, self.start, self.members)

    @classmethod
    def of(cls, points: np.ndarray) -> Buckets:
        p = np.asarray(points, dtype=np.float64).reshape(-1, 2)
        lo, hi = (p.min(axis=0), p.max(axis=0)) if p.shape[0] else (np.zeros(2), np.zeros(2))
        gaps = np.linalg.norm(np.diff(p, axis=0), axis=1)
        gaps = gaps[gaps > 0]
        cell = cls.CELL_GAPS * float(np.median(gaps)) if gaps.size else float((hi - lo).max())
        if not (cell > 0.0 and math.isfinite(cell)):
            cell = 1.0
        dims = np.floor((hi - lo) / cell).astype(np.int64) + 1
        most = cls.MAX_CELLS_PER_POINT * max(1, p.shape[0])
        if float(dims[0]) * float(dims[1]) > most:
            cell *= math.sqrt(float(dims[0]) * float(dims[1]) / most)
            dims = np.floor((hi - lo) / cell).astype(np.int64) + 1
        ij = np.minimum(np.floor((p - lo) / cell).astype(np.int64), dims - 1)
        key = ij[:, 0] * dims[1] + ij[:, 1]
        members = np.argsort(key, kind="stable").astype(np.int64)
        start = np.searchsorted(key[members], np.arange(int(dims[0] * dims[1]) + 1)).astype(
            np.int64
        )
        return cls(lo.astype(np.float64), float(cell), dims.astype(np.int64), start, members)


class RimClamp:
    """A chart's clamp (:meth:`sr33.samplers.outlines.Rims.clamp`): rim
    points ``c`` (in a k-d ``tree``) with the directions ``inward`` into
    the face and the chart's ``scale`` there; a free sample nearer its
    nearest rim point than ``margin`` times the chart's scale there, or
    outside the face (``inside``), goes to that rim point's inward normal
    at that distance.  ``gap`` per rim point, ``c`` and ``inward`` are what
    the repair's descent kernel clamps by
    (``_descent_kernels._rim_clamped``), finding the nearest rim point in
    ``buckets`` (:class:`Buckets`)."""

    def __init__(self, c, inward, scale, tree: cKDTree, inside, margin: float):
        self.c, self.inward, self.tree, self.inside = c, inward, tree, inside
        self.gap = margin * scale
        self.buckets = Buckets.of(c)

    def __call__(self, p: np.ndarray) -> np.ndarray:
        d, j = self.tree.query(p)
        gap = self.gap[j]
        bad = (d < gap) | ~self.inside(p)
        if not bad.any():
            return p
        out = p.copy()
        out[bad] = self.c[j[bad]] + gap[bad, None] * self.inward[j[bad]]
        return out
