"""Chains of developable faces joined along smooth rulings, laid out as one lattice.

A prism's walls with filleted vertical edges (planes and quarter cylinders),
the chamfer round such a prism's top (slanted planes and partial cones), a
box's walls round one filleted edge: faces that are planes, cylinders or
cones and meet their neighbours along a smooth straight edge (a ruling of
both surfaces) form a strip whose development is flat.  The scan rows cut
each such face on its own, the fillets' sections match nothing across the
smooth edges, and the repair of each face alone did not reach Condition
III-ii: the STEP part of ``tests/test_sample_cli.py`` (fillets of 0.1, a
chamfer of 0.04, h = 0.02) had 6 to 11 samples of each fillet and every
sample of each partial cone at ratios 0.97 to 0.99.

Here each chain is laid out as one lattice on its development.  Every face
of a chain is a quadrilateral of the strip: two rulings (the smooth edges
to its neighbours, or a sharp straight edge at an open chain's end) and two
runs of sharp edges, one on each of the strip's two boundaries (the loops
``A`` and ``B``), whose samples the scan already placed
(:func:`sr33.samplers.scanline._feature_samples`) and which stay.  A point
of the face is ``(1 - t) A(s) + t B(s)``, where ``A(s)`` and ``B(s)`` are
the ends of the ruling at the fraction ``s`` of the face's turn (a
cylinder or a cone) or of its runs' lengths (a plane): a ruling of the
surface, so the point lies on it.  The rulings must be of one length to
``RULING_SPREAD``, so that the rows ``t = j / R`` (``R`` the whole number
of steps of about h along a ruling, :func:`sr33.samplers.faces.steps`)
are parallels of the boundaries on the development, evenly spaced.  Row
``j`` of a face has ``round((1 - t) n_A + t n_B)`` steps where its runs
have ``n_A`` and ``n_B`` (their samples' gaps), at the fractions
interpolated between the runs' own (the quantiles of their samples'
fractions): where the two runs have the same count, the columns join
their samples pairwise, so a plane strip and a cylinder keep the columns
of their boundary samples (rectangles on the development) and a cone's
rows shed their extra steps evenly from its wide run to its narrow one.
Each row puts one sample on every smooth ruling it crosses; an open
chain's end edges are sharp and sampled already, so their samples must
stand on the rows (else the chain is left to the scan rows).

The lattice is then judged by Condition III-ii (Section 3 of the paper:
every intrinsic Delaunay triangle's second-longest edge below √3/2 of its
longest) strip by strip, on the development of the strip and its two
neighbours (:class:`Window`; the development is an isometry, so its
Delaunay triangles are the intrinsic ones), and repaired there where a
triangle reaches the repair's margin (:func:`repair_band`,
:func:`sr33.samplers.repair.repair`); the loop whose faces across are
still to be laid out or repaired slides along its runs.  The planar faces
of a chain are then left out of the planar faces' boundary-layer repair
(:func:`sr33.samplers.layers.repair_planar_faces`), and a planar face
across a chain's arc judges the chain's samples near it.

CadQuery and OCP are imported when the functions run.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass, field

import numpy as np
from scipy.spatial import Delaunay, QhullError, cKDTree

from sr33 import libm
from sr33.mesh import dot, norm, triangle_ratios

from .adjacency import EdgeFaces
from .faces import basis_surface, perpendicular, revolution_axis, steps
from .repair import BAD, MOVABLE, repair
from .samples import Samples

#: a chain's rulings (the strip's width across) may differ by this share of
#: their median and still be laid out in rows of one spacing
RULING_SPREAD = 0.02
#: an open chain's end edge's samples stand on the rows to this (times h)
ON_ROW = 1e-3
KINDS = ("PLANE", "CYLINDER", "CONE")
#: a window's samples this near (times h) its outer rulings stay in its repair
OUTER_KEEP = 2.0
#: a repaired sample keeps this far (times h) from the chain's loops
LOOP_CLEAR = 0.25


@dataclass
class Strip:
    """One face of a chain, as a quadrilateral of its development.

    ``a0``, ``a1`` are the ends of its run on loop A (``a0`` on the
    incoming ruling), ``b0``, ``b1`` those on loop B.  A cylinder or cone
    also carries its axis (``o``, ``ez``, with ``ex``, ``ey`` across it),
    the angle ``theta0`` of its incoming ruling and the signed turn
    ``delta`` to its outgoing one, and each run's height along the axis and
    radius (``run_a``, ``run_b``).
    """

    face: int
    kind: str
    a0: np.ndarray
    a1: np.ndarray
    b0: np.ndarray
    b1: np.ndarray
    o: np.ndarray = field(default_factory=lambda: np.zeros(3))
    ez: np.ndarray = field(default_factory=lambda: np.zeros(3))
    ex: np.ndarray = field(default_factory=lambda: np.zeros(3))
    ey: np.ndarray = field(default_factory=lambda: np.zeros(3))
    theta0: float = 0.0
    delta: float = 0.0
    run_a: tuple[float, float] = (0.0, 0.0)
    run_b: tuple[float, float] = (0.0, 0.0)
    apex: np.ndarray = field(default_factory=lambda: np.zeros(3))
    edges_a: list = field(default_factory=list)
    edges_b: list = field(default_factory=list)

    def turn(self, pts: np.ndarray) -> np.ndarray:
        """The angle (radians, >= 0 towards the outgoing ruling) about the
        axis from the incoming ruling to each of ``pts``; a point just
        before the incoming ruling has a small negative turn."""
        q = pts - self.o
        th = libm.arctan2(dot(q, self.ey), dot(q, self.ex))
        a = (th - self.theta0) * math.copysign(1.0, self.delta) % (2 * math.pi)
        return np.where(a > 0.5 * (abs(self.delta) + 2 * math.pi), a - 2 * math.pi, a)

    @functools.cached_property
    def far_ruling(self) -> np.ndarray:
        """The developed ends ``a1``, ``b1`` of the outgoing ruling (the
        repair's clamps and inside tests ask at every step)."""
        return self.local(np.vstack([self.a1, self.b1]))

    @functools.cached_property
    def cone(self) -> tuple[float, float, float]:
        """A cone's (slant distance of ``a0``, sin of its half angle, side of
        the apex along the ruling: +1 beyond ``b0``, -1 behind ``a0``)."""
        rho = float(norm(self.a0 - self.apex))
        side = 1.0 if float(dot(self.apex - self.a0, self.b0 - self.a0)) > 0 else -1.0
        return rho, self.run_a[1] / rho, side

    def local(self, pts: np.ndarray) -> np.ndarray:
        """The strip's development: points of the face (``(k, 3)``) to the
        plane, isometrically, ``a0`` at the origin, ``b0`` on the +y axis
        and the strip towards +x."""
        e1 = (self.b0 - self.a0) / norm(self.b0 - self.a0)
        if self.kind == "PLANE":
            w = self.a1 - self.a0
            e2 = w - dot(w, e1) * e1
            e2 = e2 / norm(e2)
            q = pts - self.a0
            return np.stack([dot(q, e2), dot(q, e1)], axis=1)
        if self.kind == "CYLINDER":
            return np.stack([self.run_a[1] * self.turn(pts), dot(pts - self.a0, e1)], axis=1)
        rho0, sin_a, side = self.cone
        rho = np.linalg.norm(pts - self.apex, axis=1)
        phi = self.turn(pts) * sin_a
        return np.stack([rho * np.sin(phi), side * (rho0 - rho * np.cos(phi))], axis=1)

    def lift(self, xy: np.ndarray) -> np.ndarray:
        """The inverse of :meth:`local`: developed points back onto the surface."""
        e1 = (self.b0 - self.a0) / norm(self.b0 - self.a0)
        if self.kind == "PLANE":
            w = self.a1 - self.a0
            e2 = w - dot(w, e1) * e1
            e2 = e2 / norm(e2)
            return self.a0 + xy[:, :1] * e2 + xy[:, 1:] * e1
        if self.kind == "CYLINDER":
            th = self.theta0 + math.copysign(1.0, self.delta) * xy[:, 0] / self.run_a[1]
            base = self.run_points(np.zeros(1), "a")[0]
            z0 = float(dot(base - self.o, self.ez))
            ring = self.o + z0 * self.ez
            r = self.run_a[1]
            p = ring + r * (np.cos(th)[:, None] * self.ex + np.sin(th)[:, None] * self.ey)
            return p + xy[:, 1:] * e1
        rho0, sin_a, side = self.cone
        v = np.stack([xy[:, 0], rho0 - side * xy[:, 1]], axis=1)  # (rho sin phi, rho cos phi)
        rho = np.linalg.norm(v, axis=1)
        phi = libm.arctan2(v[:, 0], v[:, 1])
        th = self.theta0 + math.copysign(1.0, self.delta) * phi / sin_a
        axial, radius = self.run_a
        on_a = (
            self.o
            + axial * self.ez
            + radius * (np.cos(th)[:, None] * self.ex + np.sin(th)[:, None] * self.ey)
        )
        d = on_a - self.apex
        return self.apex + rho[:, None] * d / np.linalg.norm(d, axis=1)[:, None]

    def onto_run(self, xy: np.ndarray, side: str) -> tuple[np.ndarray, np.ndarray]:
        """Developed points (own frame) projected onto run ``side`` within
        its ends: (the points, their distances)."""
        if self.kind == "CONE":
            rho0, sin_a, side_ = self.cone
            rho = rho0 if side == "a" else float(norm(self.b0 - self.apex))
            v = np.stack([xy[:, 0], rho0 - side_ * xy[:, 1]], axis=1)
            phi = np.clip(libm.arctan2(v[:, 0], v[:, 1]), 0.0, abs(self.delta) * sin_a)
            q = np.stack([rho * np.sin(phi), side_ * (rho0 - rho * np.cos(phi))], axis=1)
        else:
            p0, p1 = self.local(
                np.vstack([self.a0, self.a1] if side == "a" else [self.b0, self.b1])
            )
            d = p1 - p0
            t = np.clip(((xy - p0) @ d) / float(d @ d), 0.0, 1.0)
            q = p0 + t[:, None] * d
        return q, np.linalg.norm(xy - q, axis=1)

    def clamp_across(self, xy: np.ndarray, margin: float) -> np.ndarray:
        """Developed points (own frame) moved across the strip to at least
        ``margin`` from both runs (the strip at least twice as wide)."""
        out = xy.copy()
        if self.kind == "CONE":
            rho0, _, side = self.cone
            rho_b = float(norm(self.b0 - self.apex))
            v = np.stack([xy[:, 0], rho0 - side * xy[:, 1]], axis=1)
            rho = np.linalg.norm(v, axis=1)
            lo, hi = min(rho0, rho_b) + margin, max(rho0, rho_b) - margin
            k = np.clip(rho, lo, hi) / np.maximum(rho, 1e-300)
            v = v * k[:, None]
            return np.stack([v[:, 0], (rho0 - v[:, 1]) * side], axis=1)
        a1, b1 = self.far_ruling
        top = np.array([0.0, float(norm(self.b0 - self.a0))])
        for p, q, sign in ((np.zeros(2), a1, 1.0), (top, b1, -1.0)):
            d = (q - p) / norm(q - p)
            nrm = np.array([-d[1], d[0]])  # left of p -> q
            dist = sign * ((out - p) @ nrm)
            short = np.maximum(0.0, margin - dist)
            out = out + sign * short[:, None] * nrm
        return out

    def contains(self, xy: np.ndarray, pad: float, eps: float) -> np.ndarray:
        """Whether developed points (in the strip's own :meth:`local` frame)
        lie in the strip, between its runs (to ``eps``) and between its
        rulings grown by ``pad``."""
        x, y = xy[:, 0], xy[:, 1]
        if self.kind == "CONE":
            rho0, sin_a, side = self.cone
            rho_b = float(norm(self.b0 - self.apex))
            vx, vy = x, rho0 - side * y
            rho = np.hypot(vx, vy)
            phi = libm.arctan2(vx, vy)
            lo, hi = min(rho0, rho_b) - eps, max(rho0, rho_b) + eps
            span = abs(self.delta) * sin_a
            return (rho >= lo) & (rho <= hi) & (phi * rho >= -pad) & ((phi - span) * rho <= pad)
        a1, b1 = self.far_ruling
        w = float(norm(self.b0 - self.a0))

        def left(p, q):  # signed distance of the points left of the line p -> q
            d = (q - p) / norm(q - p)
            return d[0] * (y - p[1]) - d[1] * (x - p[0])

        origin, top = np.zeros(2), np.array([0.0, w])
        return (
            (left(origin, a1) >= -eps)
            & (left(top, b1) <= eps)
            & (x >= -pad)
            & (left(a1, b1) >= -pad)
        )

    def run_points(self, sigma: np.ndarray, side: str) -> np.ndarray:
        """The points of run ``side`` ("a" or "b") at the fractions ``sigma``."""
        sigma = np.asarray(sigma, dtype=np.float64)
        if self.kind == "PLANE":
            p0, p1 = (self.a0, self.a1) if side == "a" else (self.b0, self.b1)
            return p0 + sigma[:, None] * (p1 - p0)
        axial, radius = self.run_a if side == "a" else self.run_b
        th = self.theta0 + sigma * self.delta
        return (
            self.o
            + axial * self.ez
            + radius * (np.cos(th)[:, None] * self.ex + np.sin(th)[:, None] * self.ey)
        )

    def at(self, sigma: np.ndarray, t: float) -> np.ndarray:
        """The points ``(1 - t) A(sigma) + t B(sigma)``: on the rulings at ``sigma``."""
        return (1.0 - t) * self.run_points(sigma, "a") + t * self.run_points(sigma, "b")

    def on_run(self, pts: np.ndarray, side: str, tol: float) -> tuple[np.ndarray, np.ndarray]:
        """Which of ``pts`` lie on run ``side`` ("a" or "b") within ``tol``
        (its ends included), and every point's fraction along it."""
        p0, p1 = (self.a0, self.a1) if side == "a" else (self.b0, self.b1)
        if self.kind == "PLANE":
            u = p1 - p0
            length = float(norm(u))
            sig = dot(pts - p0, u) / (length * length)
            near = np.linalg.norm(pts - p0 - sig[:, None] * u, axis=1) < tol
            span = length
        else:
            axial, radius = self.run_a if side == "a" else self.run_b
            q = pts - self.o
            z = dot(q, self.ez)
            r = np.linalg.norm(q - z[:, None] * self.ez, axis=1)
            sig = self.turn(pts) / abs(self.delta)
            near = (np.abs(z - axial) < tol) & (np.abs(r - radius) < tol)
            span = abs(self.delta) * radius
        edge = tol / max(span, tol)
        return near & (sig > -edge) & (sig < 1.0 + edge), sig

    def fractions(self, pts: np.ndarray, side: str, tol: float) -> np.ndarray:
        """The fractions along run ``side`` of those of ``pts`` on it
        (within ``tol``), its ends 0 and 1 included once each, ascending."""
        on, sig = self.on_run(pts, side, tol)
        p0, p1 = (self.a0, self.a1) if side == "a" else (self.b0, self.b1)
        edge = tol / max(float(norm(p1 - p0)), tol)
        keep = on & (sig > edge) & (sig < 1.0 - edge)
        return np.r_[0.0, np.sort(sig[keep]), 1.0]

    def ruling_lengths(self) -> np.ndarray:
        """The lengths of the rulings at fractions 0, 1/2 and 1."""
        sig = np.array([0.0, 0.5, 1.0])
        return np.linalg.norm(self.run_points(sig, "b") - self.run_points(sig, "a"), axis=1)


@dataclass
class Band:
    """A chain of strips (:class:`Strip`), in order along the strip.

    ``closed``: the chain goes round (its last face's outgoing ruling is the
    first one's incoming one); else ``ends`` are its two sharp end edges'
    (start, end) points, each a ruling of an end face.
    """

    strips: list[Strip]
    closed: bool
    ends: list[tuple[np.ndarray, np.ndarray]]
    across: dict[str, set[int]] = field(default_factory=dict)
    width: float = 0.0  # the median length of its rulings

    @property
    def faces(self) -> list[int]:
        return [s.face for s in self.strips]


def _pt(v) -> np.ndarray:
    return np.array(v.toTuple(), dtype=np.float64)


def _ends(edge) -> tuple[np.ndarray, np.ndarray]:
    return _pt(edge.startPoint()), _pt(edge.endPoint())


def _smooth_links(ef: EdgeFaces, cos_lim: float) -> dict[int, tuple[int, int]]:
    """Edge index -> the two faces it joins, for every straight edge between
    two distinct planes, cylinders or cones whose normals agree across it
    (within the scan's sharp angle: the scan samples no such edge)."""
    links = {}
    for ei, edge in enumerate(ef.edges):
        fids = ef.faces_of[ei]
        if len(fids) != 2 or ef.uses[ei] != 2 or edge.geomType() != "LINE":
            continue
        f1, f2 = (ef.faces[k] for k in fids)
        if f1.geomType() not in KINDS or f2.geomType() not in KINDS:
            continue
        mid = edge.positionAt(0.5, mode="length")
        n1 = np.array(f1.normalAt(mid).toTuple())
        n2 = np.array(f2.normalAt(mid).toTuple())
        if float(dot(n1, n2)) > cos_lim:
            links[ei] = (fids[0], fids[1])
    return links


def _path(edges: list, start: np.ndarray, tol: float):
    """Walk ``edges`` (a face's boundary edges off its rulings) from the
    point ``start``, edge to edge by shared end points: (the edges walked,
    the point reached), or None when no edge starts there."""
    walked, here, left = [], start, list(edges)
    while True:
        hit = None
        for k, e in enumerate(left):
            p, q = _ends(e)
            if norm(p - here) < tol or norm(q - here) < tol:
                hit = k, (q if norm(p - here) < tol else p)
                break
        if hit is None:
            return (walked, here) if walked else None
        walked.append(left.pop(hit[0]))
        here = hit[1]


def _strip(face, fi: int, rin, rout, a0: np.ndarray, tol: float):
    """The :class:`Strip` of face ``fi`` between its incoming ruling ``rin``
    (whose end on loop A is ``a0``) and its outgoing one ``rout``, or None
    when the face is not such a quadrilateral."""
    if len(face.Wires()) != 1:
        return None
    p, q = _ends(rin)
    b0 = q if norm(p - a0) < tol else p
    rest = [e for e in face.Edges() if not e.isSame(rin) and not e.isSame(rout)]
    ra = _path(rest, a0, tol)
    rb = _path(rest, b0, tol)
    if ra is None or rb is None or len(ra[0]) + len(rb[0]) != len(rest):
        return None
    (edges_a, a1), (edges_b, b1) = ra, rb
    c, d = _ends(rout)
    if not (
        (norm(a1 - c) < tol and norm(b1 - d) < tol) or (norm(a1 - d) < tol and norm(b1 - c) < tol)
    ):
        return None
    kind = face.geomType()
    if kind == "PLANE":
        for run, p0, p1 in ((edges_a, a0, a1), (edges_b, b0, b1)):
            u = p1 - p0
            if norm(u) < tol:
                return None
            for e in run:
                if e.geomType() != "LINE":
                    return None
                for x in _ends(e):
                    w = x - p0
                    if norm(w - dot(w, u) / dot(u, u) * u) > tol:
                        return None
        return Strip(fi, kind, a0, a1, b0, b1, edges_a=edges_a, edges_b=edges_b)
    o, ez = revolution_axis(face)
    ex = perpendicular(ez)
    ey = np.cross(ez, ex)

    def polar(x):
        w = x - o
        z = float(dot(w, ez))
        return z, float(norm(w - z * ez)), math.atan2(float(dot(w, ey)), float(dot(w, ex)))

    runs = []
    for run, p0 in ((edges_a, a0), (edges_b, b0)):
        z0, r0, _ = polar(p0)
        if r0 < tol:
            return None  # a run through the apex
        for e in run:
            if e.geomType() != "CIRCLE":
                return None
            for x in (*_ends(e), _pt(e.positionAt(0.5, mode="length"))):
                z, r, _ = polar(x)
                if abs(z - z0) > tol or abs(r - r0) > tol:
                    return None
        runs.append((z0, r0))
    theta0 = polar(a0)[2]
    if abs(math.remainder(polar(b0)[2] - theta0, 2 * math.pi)) > 1e-9:
        return None  # not a ruling
    turn = (polar(a1)[2] - theta0) % (2 * math.pi)
    mid = (polar(_pt(edges_a[0].positionAt(0.5, mode="length")))[2] - theta0) % (2 * math.pi)
    delta = turn if mid < turn else turn - 2 * math.pi
    if abs(delta) < 1e-9:
        return None
    apex = np.zeros(3)
    if kind == "CONE":
        apex = np.array(basis_surface(face).Cone().Apex().Coord())
    return Strip(
        fi,
        kind,
        a0,
        a1,
        b0,
        b1,
        o,
        ez,
        ex,
        ey,
        theta0,
        delta,
        runs[0],
        runs[1],
        apex,
        edges_a,
        edges_b,
    )


def _opposite(face, link):
    """The edge of a four-sided ``face`` sharing no end point with ``link``."""
    edges = face.Edges()
    if len(edges) != 4:
        return None
    p, q = _ends(link)
    tol = 1e-7 * max(1.0, float(norm(p - q)))
    out = []
    for e in edges:
        if e.isSame(link):
            continue
        c, d = _ends(e)
        if min(norm(c - p), norm(c - q), norm(d - p), norm(d - q)) > tol:
            out.append(e)
    return out[0] if len(out) == 1 and out[0].geomType() == "LINE" else None


def developable_bands(occ, size: float, sharp_degrees: float = 20.0) -> list[Band]:
    """The chains of developable faces of ``occ`` (see the module's text).

    Each chain is a path or a cycle of planes, cylinders and cones linked
    by smooth straight edges, every face a quadrilateral of the strip
    (:func:`_strip`), its rulings of one length (``RULING_SPREAD``).  A
    chain is walked from its lowest face index (a path from its end of
    lower index), loop A on its first ruling's start point.
    """
    tol = 1e-7 * size
    ef = EdgeFaces(occ)
    links = _smooth_links(ef, math.cos(math.radians(sharp_degrees)))
    by_face: dict[int, list[int]] = {}
    for ei, (f1, f2) in links.items():
        by_face.setdefault(f1, []).append(ei)
        by_face.setdefault(f2, []).append(ei)
    seen: set[int] = set()
    bands = []
    for start in sorted(by_face):
        if start in seen:
            continue
        # the component of linked faces
        comp, todo = {start}, [start]
        while todo:
            f = todo.pop()
            for ei in by_face[f]:
                for g in links[ei]:
                    if g not in comp:
                        comp.add(g)
                        todo.append(g)
        seen |= comp
        if any(len(by_face[f]) > 2 for f in comp):
            continue
        ones = sorted(f for f in comp if len(by_face[f]) == 1)
        closed = not ones
        if not closed and len(ones) != 2:
            continue
        first = min(comp) if closed else ones[0]
        band = _walk(ef, links, by_face, first, closed, tol)
        if band is None:
            continue
        widths = np.concatenate([s.ruling_lengths() for s in band.strips])
        mid = float(np.median(widths))
        if mid < tol or float(np.abs(widths - mid).max()) > RULING_SPREAD * mid:
            continue
        band.width = mid
        for side in ("a", "b"):
            band.across[side] = {
                ef.other(e, st.face)
                for st in band.strips
                for e in (st.edges_a if side == "a" else st.edges_b)
            }
        bands.append(band)
    return bands


def _walk(ef: EdgeFaces, links, by_face, first: int, closed: bool, tol: float) -> Band | None:
    """The chain from face ``first`` (a closed one's lowest face, through its
    link of higher index; an open one's end face, from its sharp end edge),
    face after face across the links, loop A from the first ruling's start
    point; None where a face is no quadrilateral of the strip or the walk
    does not close (a Moebius band) or comes back early."""
    faces = ef.faces
    if closed:
        rin = ef.edges[min(by_face[first])]
    else:
        rin = _opposite(faces[first], ef.edges[by_face[first][0]])
        if rin is None:
            return None
    ends = [] if closed else [_ends(rin)]
    a0 = _ends(rin)[0]
    first_in = rin
    strips, f, used = [], first, set()
    while True:
        outs = [ei for ei in by_face[f] if not ef.edges[ei].isSame(rin)]
        if len(outs) == 1:
            rout = ef.edges[outs[0]]
            nxt = [g for g in links[outs[0]] if g != f][0]
        elif not outs and not closed:
            rout = _opposite(faces[f], rin)
            nxt = None
            if rout is None:
                return None
        else:
            return None
        s = _strip(faces[f], f, rin, rout, a0, tol)
        if s is None:
            return None
        strips.append(s)
        used.add(f)
        if nxt is None:
            ends.append(_ends(rout))
            break
        if closed and rout.isSame(first_in):
            if norm(s.a1 - strips[0].a0) < tol:
                break
            return None  # a Moebius band's loops are one
        if nxt in used:
            return None
        rin, a0, f = rout, s.a1, nxt
    return Band(strips, closed, ends)


def _lay(band: Band, s: Samples, t: np.ndarray, line: int, tol: float) -> dict:
    """Replace the samples off the features on ``band``'s faces by its
    lattice: rows ``t``, each face's row ``round((1 - t) n_A + t n_B)``
    steps at fractions interpolated between its loops' own."""
    feat = s.points[s.on_feature]
    new, fids, lines = [], [], []
    for k, st in enumerate(band.strips):
        sa = st.fractions(feat, "a", tol)
        sb = st.fractions(feat, "b", tol)
        na, nb = sa.size - 1, sb.size - 1
        for j, tj in enumerate(t):
            n = max(1, round((1.0 - tj) * na + tj * nb))
            u = np.arange(n + 1) / n
            sig = (1.0 - tj) * np.interp(u, np.linspace(0, 1, na + 1), sa) + tj * np.interp(
                u, np.linspace(0, 1, nb + 1), sb
            )
            # the incoming ruling's sample is this face's, the outgoing one the next's;
            # an open chain's end edges keep their own samples
            lo = 1 if (k == 0 and not band.closed) else 0
            sig = sig[lo:n]
            new.append(st.at(sig, float(tj)))
            fids.append(np.full(sig.size, st.face))
            lines.append(np.full(sig.size, line + j))
    mine = np.isin(s.face_id, band.faces) & ~s.on_feature
    pts = np.vstack(new) if new else np.empty((0, 3))
    s.replace(
        np.flatnonzero(mine),
        pts,
        np.concatenate(lines) if lines else np.empty(0, np.int64),
        np.concatenate(fids) if fids else np.empty(0, np.int64),
        np.zeros(pts.shape[0], dtype=bool),
    )
    return {"samples": int(pts.shape[0]), "replaced": int(mine.sum())}


def lattice_developable_bands(
    occ,
    s: Samples,
    h: float,
    size: float,
    skip=(),
    mend: bool = True,
    sharp_degrees: float = 20.0,
    bands: list[Band] | None = None,
) -> tuple[list[dict], set[int]]:
    """Lay every chain of developable faces out as one lattice (the
    module's text), then repair it (:func:`repair_band`, unless not
    ``mend``); returns a report per chain and the faces laid out.  Edges
    whose faces' normals differ by less than ``sharp_degrees`` link faces
    (the scan's own rule for the edges it does not sample); ``bands``, the
    chains :func:`developable_bands` found already (the scan finds them
    before its feature samples), saves finding them again.

    The samples off the features on the chain's faces are replaced; the
    samples on its two loops (and an open chain's end edges) stay, except
    that a loop whose faces across are still to be laid out or repaired
    slides in the repair.
    """
    tol = 1e-7 * size
    line = int(s.line_id.max()) + 1 if s.line_id.size else 0
    reports, laid = [], set()
    if bands is None:
        bands = developable_bands(occ, size, sharp_degrees)
    for band in bands:
        if set(band.faces) & set(skip):
            continue  # a face laid out already
        rows = steps(band.width, h)
        t = np.arange(1, rows) / rows
        if not band.closed and not _ends_on_rows(band, s.points[s.on_feature], t, h, tol):
            continue
        laid |= set(band.faces)
        done = set(skip) | laid
        slide = [side for side in ("a", "b") if not band.across[side] & done]
        figures = _lay(band, s, t, line, tol)
        if mend:
            figures.update(repair_band(band, s, h, tol, slide))
        line += max(0, rows - 1)
        reports.append(
            {
                **figures,
                "face": band.faces[0],
                "faces": band.faces,
                "kind": "developable band",
                "closed": band.closed,
                "rows": int(max(0, rows - 1)),
            }
        )
    return reports, laid


def _ends_on_rows(band: Band, feat: np.ndarray, t: np.ndarray, h: float, tol: float) -> bool:
    """Whether each end edge of an open chain has one sample on each row
    (to ``ON_ROW`` h) and none between."""
    for (p, q), st in zip(band.ends, (band.strips[0], band.strips[-1])):
        # orient the edge from loop A to loop B
        a = st.a0 if st is band.strips[0] else st.a1
        if norm(q - a) < norm(p - a):
            p, q = q, p
        u = q - p
        length = float(norm(u))
        w = feat - p
        sig = dot(w, u) / (length * length)
        off = np.linalg.norm(w - sig[:, None] * u, axis=1)
        inner = (off < tol) & (sig > tol / length) & (sig < 1 - tol / length)
        at = np.sort(sig[inner])
        if at.size != t.size or (at.size and np.abs(at - t).max() * length > ON_ROW * h):
            return False
    return True


def _rigid(p: np.ndarray, u: np.ndarray):
    """The rotation taking +y to the unit vector ``u`` and the translation
    ``p``: (2 x 2 matrix, offset) of ``x -> R x + p``."""
    return np.array([[u[1], u[0]], [-u[0], u[1]]]), p


class Window:
    """A few consecutive strips of a chain developed into one plane frame:
    strip ``k``'s own (:meth:`Strip.local`), its neighbours turned and moved
    so that the rulings they share coincide.  ``parts`` are (strip, R, p)
    with frame = R local + p."""

    def __init__(self, band: Band, k: int):
        n = len(band.strips)
        st = band.strips[k]
        self.parts = [(st, np.eye(2), np.zeros(2))]
        self.own = 0  # strip k's place in parts
        self.outer = []  # the window's outer rulings' ends, in the frame
        nxt = (k + 1) % n if band.closed else k + 1
        prv = (k - 1) % n if band.closed else k - 1
        a1, b1 = st.far_ruling
        if nxt < n and nxt != k:
            s2 = band.strips[nxt]
            r, p = _rigid(a1, (b1 - a1) / norm(b1 - a1))
            self.parts.append((s2, r, p))
            e = s2.local(np.vstack([s2.a1, s2.b1]))
            self.outer.append(e @ r.T + p)
        else:
            self.outer.append(np.vstack([a1, b1]))
        if prv >= 0 and prv != k and prv != nxt:
            s0 = band.strips[prv]
            pa, pb = s0.local(np.vstack([s0.a1, s0.b1]))
            r0, _ = _rigid(np.zeros(2), (pb - pa) / norm(pb - pa))
            r = r0.T  # takes the ruling's direction to +y
            p = -(r @ pa)
            self.parts.insert(0, (s0, r, p))
            self.own = 1
            e = s0.local(np.vstack([s0.a0, s0.b0]))
            self.outer.append(e @ r.T + p)
        else:
            self.outer.append(np.array([[0.0, 0.0], [0.0, float(norm(st.b0 - st.a0))]]))

    def develop(self, j: int, pts: np.ndarray) -> np.ndarray:
        st, r, p = self.parts[j]
        return st.local(pts) @ r.T + p

    def _locals(self, xy: np.ndarray):
        for st, r, p in self.parts:
            yield st, (xy - p) @ r

    def inside(self, xy: np.ndarray, eps: float = 1e-9) -> np.ndarray:
        """Whether frame points lie in the window's strips."""
        out = np.zeros(xy.shape[0], dtype=bool)
        for st, loc in self._locals(xy):
            out |= st.contains(loc, 0.0, eps)
        return out

    def lift(self, xy: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Frame points back onto the surface: (3-D points, faces), each by
        the first strip whose rulings it lies between (else by the strip
        whose incoming ruling is nearest)."""
        pts = np.zeros((xy.shape[0], 3))
        face = np.full(xy.shape[0], -1)
        far = np.inf
        for st, loc in self._locals(xy):
            inn = st.contains(loc, 0.0, far) & (face < 0)
            pts[inn] = st.lift(loc[inn])
            face[inn] = st.face
        miss = np.flatnonzero(face < 0)
        if miss.size:
            best = np.full(miss.size, np.inf)
            for st, loc in self._locals(xy[miss]):
                d = np.abs(loc[:, 0])
                take = d < best
                pts[miss[take]] = st.lift(loc[take])
                face[miss[take]] = st.face
                best[take] = d[take]
        return pts, face

    def onto_loop(self, xy: np.ndarray, side: str) -> np.ndarray:
        """Frame points projected onto the window's loop ``side`` (the
        nearest of its strips' runs)."""
        out = xy.copy()
        best = np.full(xy.shape[0], np.inf)
        for st, r, p in self.parts:
            q, d = st.onto_run((xy - p) @ r, side)
            take = d < best
            out[take] = q[take] @ r.T + p
            best[take] = d[take]
        return out

    def onto_loops(self, xy: np.ndarray, sides=("a", "b")) -> np.ndarray:
        """Frame points projected onto the nearest of the loops ``sides``."""
        if len(sides) == 1:
            return self.onto_loop(xy, sides[0])
        qa, qb = self.onto_loop(xy, "a"), self.onto_loop(xy, "b")
        da = np.linalg.norm(xy - qa, axis=1)
        db = np.linalg.norm(xy - qb, axis=1)
        return np.where((da <= db)[:, None], qa, qb)

    def clamp(self, xy: np.ndarray, margin: float) -> np.ndarray:
        """Frame points moved off the window's loops to at least ``margin``
        (each in the strip whose rulings it lies between)."""
        out = xy.copy()
        done = np.zeros(xy.shape[0], dtype=bool)
        for st, r, p in self.parts:
            loc = (xy - p) @ r
            inn = st.contains(loc, 0.0, np.inf) & ~done
            if inn.any():
                out[inn] = st.clamp_across(loc[inn], margin) @ r.T + p
                done |= inn
        return out


def _segment_distance(xy: np.ndarray, seg: np.ndarray) -> np.ndarray:
    p, q = seg
    d = q - p
    t = np.clip(((xy - p) @ d) / float(d @ d), 0.0, 1.0)
    return np.linalg.norm(xy - (p + t[:, None] * d), axis=1)


def repair_band(band: Band, s: Samples, h: float, tol: float, slide_sides=()) -> dict:
    """Repair a laid-out chain where its cells break Condition III-ii, strip
    by strip on the development of the strip and its neighbours
    (:class:`Window`): the samples within ``MOVABLE`` h of a triangle of the
    strip at or above ``BAD`` may move (:func:`sr33.samplers.repair.repair`),
    unless within ``OUTER_KEEP`` h of the window's outer rulings; the
    samples of a loop in ``slide_sides`` ("a", "b": a loop whose faces
    across are still to be laid out or repaired) slide along it, its
    corners stay; the other loop's samples stay.  Returns the chain's
    repair figures."""
    worst, bad, windows = 0.0, 0, 0
    for k in range(len(band.strips)):
        win = Window(band, k)
        feat = np.flatnonzero(s.on_feature)
        fp = s.points[feat]
        idx, xy, slid, ends = [], [], [], []
        seen = np.zeros(s.points.shape[0], dtype=bool)
        for j, (st, _, _) in enumerate(win.parts):
            mine = np.flatnonzero((s.face_id == st.face) & ~s.on_feature)
            on = np.zeros(feat.size, dtype=bool)
            sl = np.zeros(feat.size, dtype=bool)
            for side in ("a", "b"):
                run, _ = st.on_run(fp, side, tol)
                on |= run
                if side in slide_sides:
                    sl |= run
            corner = np.zeros(feat.size, dtype=bool)
            for c in (st.a0, st.a1, st.b0, st.b1):
                corner |= np.linalg.norm(fp - c, axis=1) < tol
            for ra, rb in ((st.a0, st.b0), (st.a1, st.b1)):  # an open chain's sharp end edges
                on |= _segment_distance(fp, np.vstack([ra, rb])) < tol
            take = np.r_[mine, feat[on]]
            fresh = ~seen[take]
            seen[take] = True
            idx.append(take[fresh])
            xy.append(win.develop(j, s.points[take[fresh]]))
            slid.append(np.r_[np.zeros(mine.size, bool), (sl & ~corner)[on]][fresh])
            ends.append(np.r_[np.zeros(mine.size, bool), corner[on]][fresh])
        idx = np.concatenate(idx)
        if idx.size < 4:
            continue
        xy = np.vstack(xy)
        slid = np.concatenate(slid)
        ends = np.concatenate(ends)
        movable_src = ~s.on_feature[idx]
        try:
            tri = Delaunay(xy).simplices
        except QhullError:
            continue  # the window's samples are degenerate (on one line): nothing to judge
        cen = xy[tri].mean(axis=1)
        own = win.parts[win.own][0].contains(cen, 0.0, 1e-9) & win.inside(cen)
        broken = cen[own & (triangle_ratios(xy, tri) >= BAD)]
        if not broken.shape[0]:
            continue
        near = cKDTree(broken).query(xy)[0] <= MOVABLE * h
        far = np.min([_segment_distance(xy, seg) for seg in win.outer], axis=0) >= OUTER_KEEP * h
        free = movable_src & near & far
        slide = slid & near & far
        if not (free | slide).any():
            continue
        windows += 1
        sides = tuple(slide_sides)
        out = repair(
            xy,
            free,
            h,
            slide=slide,
            project=functools.partial(win.onto_loops, sides=sides),
            anchors=ends | (slid & ~slide),
            inside=win.inside,
            clamp=functools.partial(win.clamp, margin=LOOP_CLEAR * h),
            retry_bad=1,
        )
        bad += int(out.bad)
        worst = max(worst, float(out.worst))
        kept = out.origin >= 0
        o = np.maximum(out.origin, 0)
        src = idx[o]
        touched = movable_src | slide
        mine = ~kept | touched[o]
        moved = ~kept | free[o] | slide[o]
        pts3 = s.points[src].copy()
        fid = s.face_id[src].copy()
        if moved.any():
            lp, lf = win.lift(out.uv[moved])
            pts3[moved] = lp
            fid[moved] = np.where(s.on_feature[src[moved]] & kept[moved], fid[moved], lf)
        lid = np.where(kept, s.line_id[src], -3)
        feature = kept & s.on_feature[src]
        s.replace(idx[touched], pts3[mine], lid[mine], fid[mine], feature[mine])
    return {"windows": windows, "bad": bad, "worst": worst}
