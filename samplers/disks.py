"""Planar disks and annuli laid out in rings (Condition III-ii, Section 3).

A scan lattice of straight rows meets a circular rim at arbitrary places;
the cells cut there make near-equilateral Delaunay triangles all round the
rim, and across it where a cylinder or a cone starts from the rim's
samples.  A planar face bounded only by concentric full circles (a disk,
or an annulus) is better laid out in rings about its centre, every ring a
row:

* the rings are ``round(W / h)`` equal radial steps ``t`` apart (W the
  face's radial width), the rims included;
* ring counts are ``c 2^L`` with ``c`` shared by all rings of the face and
  ``L`` the largest level whose gaps are at least ``HALVE_GAP`` t, so that
  towards the centre a ring keeps every other column of the ring outside it
  (angles ``2 pi i / count``, nested) and the cells stay near-rectangles;
* a disk's innermost ring keeps ``c`` (3 to 5) columns about a centre
  sample; the rims are resampled at their ring's angles, so that the
  cylinder or cone across a rim (laid out from the rims afterwards) keeps
  the disk's columns;
* where a ring halves, and round the centre, the triangles come out
  slightly too regular; :func:`sr33.samplers.repair.repair` mends them, the
  rims held fixed.  That repair is a local search whose end depends on
  where it starts: the halving gap is tried at a few values in turn
  (``HALVE_GAPS``), then with one ring more (``RINGS_ADDED``), until the
  repaired layout meets Condition III-ii with a margin (``LAYOUT_GOOD``),
  both diagonals of a cell nearly on one circle judged
  (``COCIRCULAR``); such a cell whose Delaunay diagonal meets the margin
  and whose other one does not is first settled by moving one of its
  corners a little (:func:`_settle_cocircular`).

The angles start from one direction per plane orientation (parallel faces,
such as a cylinder's two caps, get the same angles), so a cylinder's two
rims carry the same columns.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.spatial import Delaunay

from sr33.mesh import dot, flipped_triangles, near_cocircular, norm, triangle_ratios

from .adjacency import EdgeFaces
from .chart import Sector, halving_count, radial_clamp
from .faces import (
    cap_rim,
    goes_round,
    linked_radii,
    linked_radius,
    perpendicular,
    steps,
    whole_band,
)
from .repair import MOVABLE, repair
from .samples import Samples

HALVE_GAP = 0.75  # a ring halves its columns rather than let gaps fall below this (times t)
#: the halving gaps tried in turn (:func:`_layout`) until a repaired layout's
#: worst ratio is below ``LAYOUT_GOOD``; measured on disks of radius 4 h to
#: 34 h (every 1.03 h): 0.75 alone left 6 of 30 at or above 0.85 (0.887 to
#: 0.978: 4.0 h, 5.03 h and 18.4 h to 21.5 h), each of them below 0.84 with
#: 0.72 (18.4 h to 22.5 h) or 0.80 (4.0 h, 5.03 h)
HALVE_GAPS = (HALVE_GAP, 0.72, 0.80, 0.70, 0.78)
#: ... and then again with one ring more (a disk of radius 4.5 h: 0.931 at
#: every gap with 4 rings, 0.827 with 5 rings and the gap 0.80)
RINGS_ADDED = (0, 1)
#: a layout whose worst Delaunay ratio is below this ends the search (the
#: margin the poles' repairs keep too); ratios are compared rounded to 1e-9,
#: so that a last-bit difference cannot decide between two plans
LAYOUT_GOOD = 0.835
#: a cell whose opposite angles sum to within this (radians) of pi is judged
#: with either diagonal (:func:`sr33.mesh.flipped_ratios`): a cone's disk
#: whose Delaunay triangles were all below 0.832 had a cell 0.012 short of
#: cocircular whose other diagonal makes a triangle of 0.988, and the
#: geodesic check, on the tessellated truth, took that one
COCIRCULAR = 0.05
#: a repaired layout whose Delaunay triangles meet ``LAYOUT_GOOD`` but whose
#: near-cocircular cells do not with their other diagonal is settled
#: (:func:`_settle_cocircular`): one corner of such a cell at a time moves
#: by one of these steps (times t) so that the cell is decisively Delaunay
#: the good way round.  Measured on disks of radius 4 h to 34 h (every
#: 1.03 h): without it 7.09 h, 19.45 h, 20.48 h and 21.51 h kept 0.857 to
#: 0.993 after trying every ring plan (21 s to 139 s each); with it all 30
#: are below 0.835, settled by 1 to 3 moves on 11 of them, none trying more
#: than 4 plans (the slowest 46 s)
SETTLE_STEPS = (0.02, 0.04, 0.06, 0.08, 0.1)
SETTLE_ROUNDS = 40  # ... at most this many moves in all
SETTLE_CLOSEST = 0.5  # ... none within this (times t) of another sample


@dataclass(frozen=True)
class RoundFace:
    """A planar face bounded by concentric full circles.

    Attributes
    ----------
    index : int
        The face's index in ``shape.Faces()``.
    centre, normal : (3,) float64
        The circles' centre and the plane's unit normal (its first nonzero
        coordinate positive, the same for parallel faces).
    radii : tuple of float
        Outer radius, then the inner one for an annulus.
    edges : list
        The circle edges, outer first.
    """

    index: int
    centre: np.ndarray
    normal: np.ndarray
    radii: tuple[float, ...]
    edges: list


def _canonical(n: np.ndarray) -> np.ndarray:
    k = int(np.flatnonzero(np.abs(n) > 1e-12)[0])
    return n if n[k] > 0 else -n


def _as_round(fi: int, face, tol: float) -> RoundFace | None:
    if face.geomType() != "PLANE":
        return None
    edges = face.Edges()
    if not 1 <= len(edges) <= 2:
        return None
    if any(e.geomType() != "CIRCLE" or not e.IsClosed() for e in edges):
        return None
    centres = [np.array(e.arcCenter().toTuple()) for e in edges]
    if norm(centres[-1] - centres[0]) > tol:
        return None
    order = sorted(range(len(edges)), key=lambda k: -edges[k].radius())
    radii = tuple(float(edges[k].radius()) for k in order)
    if len(radii) == 2 and radii[0] - radii[1] <= tol:
        return None
    n = _canonical(np.array(face.normalAt().toTuple()))
    return RoundFace(fi, centres[0], n, radii, [edges[k] for k in order])


def round_faces(adjacency: EdgeFaces, tol: float) -> list[RoundFace]:
    """The disks and annuli that can be laid out in rings.

    A planar face bounded by one full circle or two concentric ones
    qualifies when across each circle lies nothing (an open rim), a full
    cone or a spherical cap (their rings start from the rim,
    :func:`sr33.samplers.layers.lattice_sphere_caps`), or a full cylinder whose other rim
    bounds a qualifying face or a face laid out from the rim it is given (a
    whole cone band: a chamfer, a pencil's tip; a spherical cap), so that
    the wall's rims carry the disk's columns
    (:func:`sr33.samplers.layers.lattice_cylinder_faces`).  Before, such a
    base was left to the planar repair, whose rim took a count of its own:
    a domed cylinder broke III-ii at 0.999 (138 of 3,033 samples), 0.827
    now; a chamfered one at 0.93 to 0.999.
    """
    faces = adjacency.faces
    found = {fi: r for fi, f in enumerate(faces) if (r := _as_round(fi, f, tol)) is not None}
    changed = True
    while changed:
        changed = False
        for fi in sorted(found):
            if not all(_rim_ok(fi, e, adjacency, found, tol) for e in found[fi].edges):
                del found[fi]
                changed = True
    return [found[fi] for fi in sorted(found)]


def _rim_ok(fi: int, edge, adjacency: EdgeFaces, found, tol: float) -> bool:
    other = adjacency.other(edge, fi)
    if other < 0:
        return True
    face = adjacency.faces[other]
    if face.geomType() == "CONE":
        return goes_round(face)
    if face.geomType() == "SPHERE":  # a cap: its rings start from the rim
        return cap_rim(face, tol) is not None
    if face.geomType() != "CYLINDER" or not goes_round(face):
        return False
    for e in face.Edges():
        if e.geomType() == "CIRCLE" and not e.isSame(edge):
            k = adjacency.other(e, other)
            if k in found and k != fi:
                return True
            # a cone (a chamfer's band, a pencil's tip) or a cap is laid from
            # the rim it is given
            return k >= 0 and _from_the_rim(adjacency.faces[k], tol)
    return False


def _from_the_rim(face, tol: float) -> bool:
    """Whether ``face``, across a cylinder's rim, is laid out from the
    samples the rim is given: a cone between whole circles (a chamfer's
    band, a pencil's tip: :func:`sr33.samplers.layers.lattice_cone_faces`)
    or a spherical cap (:func:`sr33.samplers.layers.lattice_sphere_caps`)."""
    if face.geomType() == "CONE":
        return whole_band(face)
    return face.geomType() == "SPHERE" and cap_rim(face, tol) is not None


def ring_plan(
    radii: tuple[float, ...],
    h: float,
    gap: float = HALVE_GAP,
    extra: int = 0,
    count: int | tuple[int | None, int | None] | None = None,
) -> tuple[float, list[tuple[float, int]]]:
    """Radial step and (radius, column count) of every ring, the rims included.

    Parameters
    ----------
    radii : tuple of float
        Outer radius, then the inner one for an annulus.
    h : float
        The sample spacing.
    gap : float
        A ring halves its columns rather than let their gaps fall below
        this (times t).
    extra : int
        Rings added to the ``round(W / h)`` steps (a finer radial step).
    count : int or (int or None, int or None), optional
        A disk's rim count, of the form ``c 2^k`` (:func:`halving_count`),
        instead of its own ``halving_count(2 pi r / h)``: the count of a
        chain of rims it shares (:func:`sr33.samplers.faces.linked_radius`).
        An annulus' counts start from its inner rim, ``steps(2 pi r / h)``
        by default; a pair gives its inner rim's count and its outer rim's
        (that count times a power of two), each None for its own: the
        counts of the chains its rims share (a tube chamfered at one end:
        both ends' annuli take one count per chain, so that the chamfers'
        bands have their columns on both circles).

    Returns
    -------
    t : float
        The radial step, ``W / (round(W / h) + extra)``.
    rings : list of (float, int)
        From the outer rim inwards; a disk's innermost ring is at ``t``
        (its centre sample is not listed).  Every count is ``c 2^L`` for
        one ``c``, each at most twice the next one's, except that the
        ring round a disk's centre has ``c`` (3 to 5) columns whatever the
        ring outside it has (halving ring by ring to it, measured on the
        cylinder's caps: 9 triangles the repair could not mend, worst
        ratio 0.90; with the jump, none).

    Examples
    --------
    >>> t, rings = ring_plan((0.5,), 0.025)
    >>> round(t, 6), rings[0][1], rings[-1][1], len(rings)
    (0.025, 128, 4, 20)
    >>> [c for _, c in ring_plan((0.5, 0.3), 0.02)[1]]
    [188, 188, 188, 94, 94, 94, 94, 94, 94, 94, 94]
    """
    outer = radii[0]
    inner = radii[1] if len(radii) > 1 else 0.0
    rows = steps(outer - inner, h) + extra
    t = (outer - inner) / rows
    if inner > 0:
        base_in, outer_count = count if isinstance(count, tuple) else (None, None)
        base = base_in if base_in is not None else steps(2 * math.pi * inner, h, least=3)
        if outer_count is not None:
            top = round(math.log2(outer_count / base))
        else:
            top = max(0, math.floor(math.log2(2 * math.pi * outer / (gap * t * base))))
        nrings = rows + 1
    else:
        n = count if count is not None else halving_count(2 * math.pi * outer / h)
        top = 0
        while n > 5 and n % 2 == 0:
            n //= 2
            top += 1
        base, nrings = n, rows
    rings = []
    level = top
    for j in range(nrings):
        r = outer - j * t
        fit = math.floor(math.log2(2 * math.pi * r / (gap * t * base)))
        level = max(0, min(level, fit)) if j else top
        if j == nrings - 1 and (inner > 0 or j > 0):
            level = 0  # the inner rim, or the ring round a disk's centre
        rings.append((r, base << level))
    return t, rings


def _ring_points(t: float, rings, disk: bool) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """2-D ring samples about the origin: positions, ring index (-1: the
    centre) and whether the ring may move (near a halving or the centre)."""
    uv, ring, near = [], [], []
    halving = [j for j in range(1, len(rings)) if rings[j][1] != rings[j - 1][1]]
    for j, (r, m) in enumerate(rings):
        a = 2 * math.pi * np.arange(m) / m
        uv.append(r * np.stack([np.cos(a), np.sin(a)], axis=1))
        ring.append(np.full(m, j))
        close = any(abs(r - rings[k][0]) <= MOVABLE * t + 1e-12 for k in halving)
        close |= disk and r <= MOVABLE * t + 1e-12
        near.append(np.full(m, close))
    if disk:
        uv.append(np.zeros((1, 2)))
        ring.append(np.array([-1]))
        near.append(np.array([True]))
    return np.vstack(uv), np.concatenate(ring), np.concatenate(near)


@dataclass(frozen=True)
class _Layout:
    """A face's ring samples in 2-D about its centre, after the repair."""

    uv: np.ndarray
    rim: np.ndarray  # on a rim (a feature sample)
    ring: np.ndarray  # ring index (0 the outer rim); -1 the centre or a sample the repair added
    bad: int
    worst: float  # of the face's Delaunay triangles
    either: float  # ... and of near-cocircular cells with their other diagonal
    gap: float  # the halving gap of its rings (HALVE_GAPS)
    extra: int = 0  # rings added to round(W / h) (RINGS_ADDED)
    settled: int = 0  # moves of _settle_cocircular


def _layout(radii: tuple[float, ...], h: float, count: int | None = None) -> _Layout:
    """The repaired ring samples of a face of these radii: the first ring
    plan (``HALVE_GAPS`` in turn, then the same with one ring more; a plan
    equal to one tried before is skipped) whose layout's worst Delaunay
    ratio, near-cocircular cells judged with either diagonal, is below
    ``LAYOUT_GOOD``; else the one with the lowest worst Delaunay ratio (then
    the lowest with either diagonal, then the first).  Where the rings
    halve decides what the repair starts from, and a repair left stuck
    from one plan is mended from another's rings more often than by more
    attempts from the same ones (see ``HALVE_GAPS``)."""
    best = None
    tried = set()
    for extra in RINGS_ADDED:
        for gap in HALVE_GAPS:
            t, rings = ring_plan(radii, h, gap, extra, count)
            plan = (round(t, 12), tuple(c for _, c in rings))
            if plan in tried:
                continue
            tried.add(plan)
            lay = _layout_with(radii, h, gap, extra, count)
            rank = (round(lay.worst, 9), round(lay.either, 9))
            if best is None or rank < best[0]:
                best = (rank, lay)
            if round(lay.either, 9) < LAYOUT_GOOD:
                return lay
    return best[1]


def _layout_with(
    radii: tuple[float, ...], h: float, gap: float, extra: int = 0, count: int | None = None
) -> _Layout:
    """:func:`_layout` for one ring plan (:func:`ring_plan`'s ``gap``,
    ``extra`` and ``count``); ``worst`` is that of the face's whole Delaunay triangulation
    (an annulus' hole left out), ``either`` that with near-cocircular cells
    judged with either diagonal (``COCIRCULAR``)."""
    t, rings = ring_plan(radii, h, gap, extra, count)
    disk = len(radii) == 1
    uv, ring, near = _ring_points(t, rings, disk)
    rim = (ring == 0) | ((ring == len(rings) - 1) & (not disk))
    free = near & ~rim
    lo = radii[1] + 0.25 * t if len(radii) > 1 else 0.0
    clamp = radial_clamp(lo, radii[0] - 0.25 * t)

    inside = Sector(radii[0], radii[1] if len(radii) > 1 else -1.0, 2 * math.pi, True)

    bad = 0
    if free.any():
        out = repair(uv, free, t, inside=inside, clamp=clamp)
        keep = out.origin
        rim = np.where(keep >= 0, rim[np.maximum(keep, 0)], False)
        ring = np.where(keep >= 0, ring[np.maximum(keep, 0)], -1)
        uv, bad = out.uv, int(out.bad)
    worst, either, _, _ = _judged(uv, inside)
    settled = 0
    if round(worst, 9) < LAYOUT_GOOD <= round(either, 9):
        uv, settled = _settle_cocircular(uv, ~rim, inside, clamp, t)
        worst, either, _, _ = _judged(uv, inside)
    return _Layout(uv, rim, ring, bad, worst, either, gap, extra, settled)


def _judged(uv: np.ndarray, inside) -> tuple[float, float, np.ndarray, np.ndarray]:
    """A layout's worst Delaunay ratio (triangles inside the face), the worst
    with near-cocircular cells judged with either diagonal too, those cells
    (``COCIRCULAR``, :func:`sr33.mesh.near_cocircular`) and the worse ratio
    of each cell's two triangles with the other diagonal."""
    tri = Delaunay(uv).simplices
    tri = tri[inside(uv[tri].mean(axis=1))]
    worst = float(np.r_[triangle_ratios(uv, tri), 0.0].max())
    cells = near_cocircular(uv, tri, COCIRCULAR)
    flipped = triangle_ratios(uv, flipped_triangles(cells)).reshape(2, -1).max(axis=0)
    return worst, max(worst, float(np.r_[flipped, 0.0].max())), cells, flipped


def _settle_rank(either: float, flipped: np.ndarray) -> tuple:
    """How :func:`_settle_cocircular` ranks a layout: its cells breaking the
    margin with the other diagonal, then the worst ratio either way (rounded
    to 1e-9, so that no last bit decides)."""
    return int(np.count_nonzero(np.round(flipped, 9) >= LAYOUT_GOOD)), round(either, 9)


def _settle_cocircular(uv: np.ndarray, movable: np.ndarray, inside, clamp, t: float):
    """Make the near-cocircular cells of a repaired layout decisively
    Delaunay the way whose triangles meet ``LAYOUT_GOOD``.

    A cell ``a, b, c, d`` (diagonal ``a b``; :func:`sr33.mesh.near_cocircular`)
    whose triangles with the diagonal ``c d`` break the margin is taken
    (cells in the order of their centres, x then y): each of its movable
    corners is tried at ``SETTLE_STEPS`` t further from the cell's diagonal
    (``c`` and ``d`` away from the midpoint of ``a b``, ``a`` and ``b`` away
    from each other), kept on the face (``inside``, ``clamp``) and
    ``SETTLE_CLOSEST`` t from every other sample; the move with the best
    :func:`_settle_rank` that keeps every Delaunay triangle below
    ``LAYOUT_GOOD`` and improves the rank is made, ties to the first tried.
    A cell no move improves is left.  Returns the samples and the number of
    moves (at most ``SETTLE_ROUNDS``)."""
    uv = uv.copy()
    _, either, cells, flipped = _judged(uv, inside)
    rank = _settle_rank(either, flipped)
    left: set[tuple] = set()
    moves = 0
    while moves < SETTLE_ROUNDS:
        todo = [
            tuple(c)
            for c, r in zip(cells.tolist(), flipped.tolist())
            if round(r, 9) >= LAYOUT_GOOD and tuple(sorted(c)) not in left
        ]
        if not todo:
            break
        centre = [np.round(uv[list(c)].mean(axis=0), 9).tolist() for c in todo]
        a, b, c, d = todo[min(range(len(todo)), key=lambda i: centre[i])]
        mid = 0.5 * (uv[a] + uv[b])
        best = None
        for v, away in ((c, uv[c] - mid), (d, uv[d] - mid), (a, uv[a] - uv[b]), (b, uv[b] - uv[a])):
            if not movable[v]:
                continue
            for step in SETTLE_STEPS:
                at = uv[v] + step * t * away / norm(away)
                if not inside(at[None])[0] or norm(clamp(at[None])[0] - at) > 1e-12 * t:
                    continue
                gap = np.linalg.norm(uv - at, axis=1)
                gap[v] = np.inf
                if gap.min() < SETTLE_CLOSEST * t:
                    continue
                trial = uv.copy()
                trial[v] = at
                got = _judged(trial, inside)
                r = _settle_rank(got[1], got[3])
                if round(got[0], 9) < LAYOUT_GOOD and r < rank and (best is None or r < best[0]):
                    best = (r, trial, got)
        if best is None:
            left.add(tuple(sorted((a, b, c, d))))
            continue
        rank, uv, (_, _, cells, flipped) = best
        moves += 1
    return uv, moves


def _annulus_counts(adjacency: EdgeFaces, rf: RoundFace, h: float, tol: float):
    """An annulus' rim counts from the chains its rims share
    (:func:`sr33.samplers.faces.linked_radii`), for :func:`ring_plan`, in
    units of h: None where neither chain holds circles of two radii (its
    own counts, as every annulus of such chains makes them alike), else
    (inner, outer) such that every annulus on the chains gets the same:

    * an inner chain of two radii: the inner count ``steps(2 pi R / h)`` of
      its widest circle, the outer one that count times the power of two
      whose gaps on the outer chain's widest circle are nearest above
      ``HALVE_GAP`` h (None, its own, where the outer rim is chained to
      nothing);
    * else (an outer chain of two radii): the outer count
      ``halving_count(2 pi R / h)`` of its widest circle, as a disk's, and
      the inner one that count halved while its gaps on the inner rim stay
      below ``HALVE_GAP`` h.

    A cylinder with a hole, both chamfered at the top, whose top annulus
    took its counts from its own radii (r - c and r' + c): 96 and 62
    columns on the two circles of the outer chamfer's band, 24 and 31 on
    the hole's, and 209 samples broke Condition III-ii; with its hole
    chamfered wider than its counts link, the outer band kept 66 and 86
    (153 samples).
    """
    inner = [round(r / h, 9) for r in linked_radii(adjacency, rf.index, rf.edges[-1], h)]
    outer = [round(r / h, 9) for r in linked_radii(adjacency, rf.index, rf.edges[0], h)]
    spread = tol / h
    if max(inner) - min(inner) > spread:
        base = steps(2 * math.pi * max(inner), 1.0, least=3)
        if len(outer) == 1:
            return base, None
        level = max(0, math.floor(math.log2(2 * math.pi * max(outer) / (HALVE_GAP * base))))
        return base, base << level
    if max(outer) - min(outer) <= spread:
        return None
    top = halving_count(2 * math.pi * max(outer))
    base = top
    while base % 2 == 0 and base // 2 >= 3 and 2 * math.pi * inner[0] / base < HALVE_GAP:
        base //= 2
    return base, top


def lattice_disk_faces(occ, s: Samples, h: float, size: float) -> tuple[list[dict], set[int]]:
    """Lay every disk and annulus of :func:`round_faces` out in rings.

    Replaces the face's samples (its rims' included) by the rings of
    :func:`ring_plan`, repaired where a ring halves and round a disk's
    centre.  The layout is made in units of h from the radii rounded on a
    1e-9 h grid (a model turned off the axes, whose radii differ in their
    last bits, gets the upright's layout; the rims are then put back on
    their circles), so faces of equal radii get one layout (a cylinder's two
    caps).  A disk's rim takes the count of the widest circle chained to it
    through cylinders and narrow cone bands
    (:func:`sr33.samplers.faces.linked_radius`): a chamfered cylinder's top
    disk, of radius r - c, carries the wall's count, so that the chamfer's
    band has the same columns on both its circles.  Returns one report per
    face and the indices of the faces laid out.
    """
    tol = 1e-7 * size
    adjacency = EdgeFaces(occ)
    reports: list[dict] = []
    done: set[int] = set()
    cache: dict[tuple, _Layout] = {}
    line = int(s.line_id.max()) + 1 if s.line_id.size else 0
    for rf in round_faces(adjacency, tol):
        # the layout is made in units of h from the radii rounded there, so
        # that its repair does not hinge on the radii's last bits (a cone
        # turned off the axes: its disk's repair took another path and ended
        # at 0.872 where the upright's ended at 0.82); the rims are then put
        # back on their circles
        key = tuple(round(r / h, 9) for r in rf.radii)
        count = None
        if len(key) == 1:
            # a disk's rim takes the count of the widest circle chained to it
            # (a chamfer's cone band and the wall beyond carry its columns on)
            chain = round(linked_radius(adjacency, rf.index, rf.edges[0], h) / h, 9)
            if chain > key[0]:
                count = halving_count(2 * math.pi * chain)
        else:
            count = _annulus_counts(adjacency, rf, h, tol)
        if (key, count) not in cache:
            cache[key, count] = _layout(key, 1.0, count)
        lay = cache[key, count]
        uv, rim, ring = lay.uv * h, lay.rim, lay.ring
        radius = np.where(ring == 0, rf.radii[0], rf.radii[-1])[rim]  # outer rim, inner rim
        uv[rim] *= (radius / np.linalg.norm(uv[rim], axis=1))[:, None]
        ex = perpendicular(rf.normal)
        ey = np.cross(rf.normal, ex)
        q = s.points - rf.centre
        off = dot(q, rf.normal)
        radial = np.linalg.norm(q - off[:, None] * rf.normal, axis=1)
        lo = rf.radii[1] if len(rf.radii) > 1 else 0.0
        mine = (np.abs(off) < tol) & (radial < rf.radii[0] + tol) & (radial > lo - tol)
        idx = np.flatnonzero(mine)
        # a rim sample belongs to its edge's first face, as in the scan
        first = [adjacency.faces_of[adjacency.index(e)][0] for e in rf.edges]
        rim_face = np.where(ring == 0, first[0], first[-1])
        pts3 = rf.centre + uv[:, :1] * ex + uv[:, 1:] * ey
        s.replace(
            idx,
            pts3,
            np.where(rim, -1, np.where(ring >= 0, line + ring, -3)),
            np.where(rim, rim_face, rf.index),
            rim,
        )
        line += int(ring.max()) + 1
        done.add(rf.index)
        reports.append(
            {
                "face": rf.index,
                "kind": "disk rings" if len(rf.radii) == 1 else "annulus rings",
                "rings": int(ring.max()) + 1,
                "samples": int(uv.shape[0]),
                "bad": lay.bad,
                "worst": lay.worst,
                "halving_gap": lay.gap,
                "rings_added": lay.extra,
                "settled": lay.settled,
            }
        )
    return reports, done
