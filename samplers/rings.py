"""Where the rings of a body of revolution stand along its meridian, and
where their columns halve.

A body of revolution is laid out in rings (parallels, one row each) whose
columns continue from ring to ring (:func:`sr33.samplers.layers.lattice_revolved_body`,
:func:`sr33.samplers.layers.lattice_cone_faces`): the cells are rectangles,
gap by row step, whose Delaunay triangles meet Condition III-ii while the
gap stays within 0.62 to 1.61 row steps.  As the rings shrink towards the
axis, every other column ends.  With a gap x (in row steps) where a ring
halves, the rectangles before it have the ratio ``1 / sqrt(1 + x^2)`` and
the merged ones after it ``2x / sqrt(4x^2 + 1)``: they balance at x = 0.707
(both 0.816), where the triangle joining a dropped column to the two kept
ones has ``sqrt(x^2 + t1^2) / 2x``, 0.76 with a step t1 = 0.8 across the
halving.  Rings one row step apart hit that gap only by chance (on a ball
of radius 20 h a ring's radius changes by up to 7 % a step), so
:func:`ring_positions` puts the halving ring exactly where the gap reaches
it, with the steps ``HALVING_STEPS`` round it, and evens the rest of the
way out over the steps between halvings (measured: docs/sampler.md).

Plain numpy; the meridian is given as arc lengths and radii.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

#: a ring's columns halve where their gap is this many row steps
HALVING_GAP = 0.707
#: the steps before and after a halving ring, times the row step: the
#: shorter step across the halving brings its triangle from 0.87 to 0.76
HALVING_STEPS = (0.8, 1.0)


@dataclass(frozen=True)
class RingPlan:
    """Rings along a meridian (:func:`ring_positions`).

    Attributes
    ----------
    at : (n,) float64
        Arc length of every ring from the meridian's start, increasing (on a
        closed meridian, from the widest ring, in ``[0, length)``).
    halves : (n,) bool
        The ring keeps every other column of its neighbour nearer the widest
        ring (the first of equal ones, round a closed meridian).
    widest : int
        Index of the widest ring, where the columns start.
    meet : int
        On a closed meridian, the narrowest ring, where the columns from
        either side of the widest meet (-1 on an open one).
    moved : int
        Halvings due within two steps of a kept end's first ring, put two
        steps before it (at a gap wider than the design's).
    origin : float
        Arc length of the meridian where ``at`` starts (a closed meridian's
        widest point; 0 on an open one).
    """

    at: np.ndarray
    halves: np.ndarray
    widest: int
    meet: int = -1
    moved: int = 0
    origin: float = 0.0

    def walk(self) -> list[tuple[int, int]]:
        """(ring, the ring it takes its columns from), from the widest ring
        each way: to the ends of an open meridian, to the narrowest ring
        (``meet``) round a closed one, which both ways reach (the second
        way's columns stand there)."""
        n = self.at.size
        out = []
        for step in (-1, 1):
            j = self.widest + step
            while (0 <= j < n) if self.meet < 0 else (j - step) % n != self.meet:
                out.append((j % n, (j - step) % n))
                j += step
        return out


def _crossing(s: np.ndarray, rho: np.ndarray, a: float, b: float, level: float) -> float | None:
    """The first arc length from ``a`` towards ``b`` where the radius falls
    to ``level`` (linear between the meridian's points), or None."""
    lo, hi = min(a, b), max(a, b)
    inner = (s > lo) & (s < hi)
    ss = np.r_[a, s[inner][:: 1 if b > a else -1], b]
    rr = np.interp(ss, s, rho)
    below = np.flatnonzero(rr <= level)
    if below.size == 0:
        return None
    k = int(below[0])
    if k == 0:
        return float(a)
    f = (rr[k - 1] - level) / (rr[k - 1] - rr[k])
    return float(ss[k - 1] + f * (ss[k] - ss[k - 1]))


def _fill(length: float, t: float, first: float, last: float) -> list[float]:
    """Distances of the rings strictly between two rings ``length`` apart:
    a step ``first`` after the first and ``last`` before the second, the
    rest of the way in equal steps as near ``t`` as a whole number of them
    gets.  Two steps in all honour the one that differs from ``t`` (the
    step before a halving first), one step nothing."""
    n = max(1, round(length / t))
    if n == 1:
        return []
    if n == 2:
        if last != t:
            return [length - last]
        return [first] if first != t else [length / 2]
    mid = (length - first - last) / (n - 2)
    return [first] + [first + mid * k for k in range(1, n - 2)] + [length - last]


#: a halving moved for a sharp circle keeps its gap within this (times the
#: row step): the merged rectangles after it and the triangle of a dropped
#: column then stay below 0.85 (``2x / sqrt(4x^2 + 1)`` at 0.78 is 0.843,
#: ``sqrt(x^2 + 0.8^2) / 2x`` at 0.62 is 0.82)
CORNER_GAPS = (0.62, 0.78)


def _by_corner(s, rho, x: float, sign: float, step: float, columns: int, gap: float, fixed):
    """Where a halving due at ``x`` stands when a sharp circle (arc lengths
    ``fixed``) lies within a step of it: the circle must carry a ring, and
    one a fraction of a step off the halving would make a short row.  The
    halving itself stands on the circle, or a step before it (the circle
    the ring after the halving), or the step before a halving
    (``HALVING_STEPS``) before it (the circle the ring before): of those
    whose gap stays within ``CORNER_GAPS``, the one nearest the design's.
    Else ``x`` (the ring nearest the circle then moves onto it)."""
    near = [f for f in fixed if abs(f - x) <= step]
    if not near:
        return x
    f = min(near, key=lambda q: abs(q - x))
    best, off = x, math.inf
    for c in (f, f - sign * HALVING_STEPS[1] * step, f + sign * HALVING_STEPS[0] * step):
        g = 2 * math.pi * float(np.interp(c, s, rho)) / columns / step
        if CORNER_GAPS[0] <= g <= CORNER_GAPS[1] and abs(g - gap) < off:
            best, off = c, abs(g - gap)
    return best


def _side(
    s, rho, start: float, stop: float, step: float, columns: int, gap: float, rim: bool, fixed=()
):
    """Rings from the one at ``start`` (the widest, excluded) to the one at
    ``stop`` (included), halving where the gap reaches ``gap`` row steps:
    {position: halves}, and how many halvings were moved.  Halvings stand
    two steps apart at least; one due within two steps of ``stop`` comes
    two steps before it (moved) where ``stop`` is a pole's ``rim`` (whose
    rings inside are repaired, not the rim), and is left out otherwise (the
    narrowest ring of a torus, where the gap then stays just under ``gap``).
    A halving due within a step of a sharp circle (arc lengths ``fixed``)
    moves so that a ring of its design stands on the circle
    (:func:`_by_corner`)."""
    sign = 1.0 if stop >= start else -1.0
    anchors = [start]
    m = columns
    moved = 0
    while m >= 6:
        x = _crossing(s, rho, anchors[-1], stop, gap * step * m / (2 * math.pi))
        if x is not None:
            x = _by_corner(s, rho, x, sign, step, m, gap, fixed)
        if x is not None and rim and abs(stop - x) < 2 * step:
            x = stop - sign * 2 * step
            moved += 1
        # a halving ring has a row step on either side before the next anchor
        if x is None or abs(stop - x) < 2 * step - 1e-9 * step or abs(x - anchors[-1]) < 2 * step:
            break
        anchors.append(x)
        m //= 2
    anchors.append(stop)
    before, after = (f * step for f in HALVING_STEPS)
    out: dict[float, bool] = {}
    for k, (a, b) in enumerate(zip(anchors[:-1], anchors[1:])):
        first = after if k > 0 else step  # after a halving
        last = before if k < len(anchors) - 2 else step  # before one
        for d in _fill(abs(b - a), step, first, last):
            out[a + sign * d] = False
        out[b] = 0 < k + 1 < len(anchors) - 1
    return out, moved


def ring_positions(
    s: np.ndarray,
    rho: np.ndarray,
    step: float,
    columns: int,
    *,
    closed: bool = False,
    keep: tuple[int, int] = (0, 0),
    gap: float = HALVING_GAP,
    fixed=(),
) -> RingPlan:
    """Rings along a meridian, halving their columns where the gap is ``gap`` row steps.

    Parameters
    ----------
    s, rho : (p,) float64
        The meridian: arc lengths (increasing from 0 to its length) and the
        distance from the axis at each.  A closed meridian (a torus's
        circle) repeats its first point last, ``s[-1]`` being its length.
    step : float
        Row step t; an open meridian's length is a whole number of them.
    columns : int
        Columns on the widest ring (a count that halves, see
        :func:`sr33.samplers.chart.halving_count`).
    closed : bool
        The meridian is a closed curve off the axis (no poles).
    keep : (int, int)
        On an open meridian, rings kept one ``step`` apart at either end
        (round a pole, where the columns end by their own rule and are
        repaired); the rings between are designed.
    gap : float
        Gap (times ``step``) at which a ring's columns halve.
    fixed : sequence of float
        On an open meridian, arc lengths of sharp circles: a halving due
        within a step of one moves so that a ring of its design stands on
        it (a turned part's, :mod:`sr33.samplers.meridians`).

    Returns
    -------
    RingPlan
        An open meridian's rings run from ``step`` after its start to
        ``step`` before its end (the poles are not rings); with fewer than
        two rows between the kept ones, all rings are one ``step`` apart and
        none halves by design.
    """
    s = np.asarray(s, dtype=np.float64)
    rho = np.asarray(rho, dtype=np.float64)
    length = float(s[-1])
    if closed:
        # unrolled so that the widest point is at 0, one turn either way
        w = float(s[int(np.argmax(rho[:-1]))])  # the widest point
        ss = np.r_[s[:-1] - w - length, s[:-1] - w, s[:-1] - w + length]
        rr = np.r_[rho[:-1], rho[:-1], rho[:-1]]
        order = np.argsort(ss, kind="stable")
        ss, rr = ss[order], rr[order]
        half = (ss >= 0.0) & (ss <= length)
        narrow = float(ss[half][int(np.argmin(rr[half]))])
        at = {0.0: False}
        at.update(_side(ss, rr, 0.0, narrow, step, columns, gap, False)[0])
        back = _side(ss, rr, 0.0, narrow - length, step, columns, gap, False)[0]
        for p, halves in back.items():
            if p - (narrow - length) > 1e-9 * step:  # the narrowest ring once
                at[p + length] = halves
        pos = np.array(sorted(at))
        meet = int(np.argmin(np.abs(pos - narrow)))
        return RingPlan(pos, np.array([at[p] for p in sorted(at)]), 0, meet, origin=w)
    rows = round(length / step)
    uniform = np.arange(1, rows) * step
    lo, hi = keep[0] - 1, rows - 1 - keep[1]  # the designed rings' first and last index
    if hi - lo < 2 or lo < 0:
        return RingPlan(
            uniform, np.zeros(uniform.size, bool), int(np.argmax(np.interp(uniform, s, rho)))
        )
    wi = lo + int(np.argmax(np.interp(uniform[lo : hi + 1], s, rho)))
    w = float(uniform[wi])
    at = {w: False}
    moved = 0
    for stop in (float(uniform[lo]), float(uniform[hi])):
        side, k = _side(s, rho, w, stop, step, columns, gap, True, fixed)
        at.update(side)
        moved += k
    mid = sorted(at)
    pos = np.r_[uniform[:lo], mid, uniform[hi + 1 :]]
    halves = np.r_[np.zeros(lo, bool), [at[p] for p in mid], np.zeros(uniform.size - hi - 1, bool)]
    return RingPlan(pos, halves.astype(bool), lo + mid.index(w), -1, moved)
