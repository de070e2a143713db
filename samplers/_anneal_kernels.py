"""numba kernel: a seeded annealing of the few samples round an acute corner.

The repair (:mod:`sr33.samplers.repair`) is a descent with edits; round a
planar face's corner below 60° it ends in a basin it cannot leave (a
wedge's 30° corner: 0.883 from 28 of 40 shaken starts, below 0.85 from
2).  There the two edges' samples must stagger near the corner, then stand
side by side, then let a sample in on the bisector, and a descent on a
smooth energy does not reorder them.  :func:`anneal_corner` searches
instead: one sample at a time moves by a seeded normal step (a free sample
within its sector, an edge's sample along its edge), the Delaunay
triangles of the region are made anew (:func:`delaunay_triangles`), and the
move is kept by Metropolis' rule on the region's score (its worst ratio
first).  The random numbers are the kernel's own (SplitMix64, Box-Muller),
so that a seed gives the same moves with any numpy or numba.
"""

from __future__ import annotations

import math

import numpy as np

from sr33.jit import njit

from ._delaunay_kernels import delaunay_triangles, orient

FREE, ON_EDGE, FIXED = 0, 1, 2  # the kinds of a region's samples


@njit(cache=True)
def _next(state):
    """SplitMix64: the next state and a uniform number in [0, 1)."""
    state = (state + np.uint64(0x9E3779B97F4A7C15)) & np.uint64(0xFFFFFFFFFFFFFFFF)
    z = state
    z = ((z ^ (z >> np.uint64(30))) * np.uint64(0xBF58476D1CE4E5B9)) & np.uint64(0xFFFFFFFFFFFFFFFF)
    z = ((z ^ (z >> np.uint64(27))) * np.uint64(0x94D049BB133111EB)) & np.uint64(0xFFFFFFFFFFFFFFFF)
    z = z ^ (z >> np.uint64(31))
    return state, float(z >> np.uint64(11)) * (1.0 / 9007199254740992.0)


@njit(cache=True)
def _normal(state):
    """A standard normal number (Box-Muller) and the next state."""
    state, u = _next(state)
    state, v = _next(state)
    return state, math.sqrt(-2.0 * math.log(1.0 - u)) * math.cos(2.0 * math.pi * v)


@njit(cache=True)
def _in_sector(dirs, x, y, clear):
    """Whether ``(x, y)`` lies in one of the sectors between consecutive rays
    ``dirs`` (counter-clockwise, each less than 180° wide) at least ``clear``
    inside both of its rays; the sector's index, or -1."""
    for s in range(dirs.shape[0] - 1):
        if (
            dirs[s, 0] * y - dirs[s, 1] * x > clear
            and x * dirs[s + 1, 1] - y * dirs[s + 1, 0] > clear
        ):
            return s
    return -1


@njit(cache=True)
def corner_score(pts, ray, dirs, judged, h, gap_lo, gap_hi, short, wide):
    """The score of a corner's region ``pts`` ((m, 2), the corner at the
    origin): the worst ratio of its Delaunay triangles whose centroid lies
    within ``judged`` of the corner and in one of the sectors between its
    rays ``dirs`` ((k, 2) unit, counter-clockwise, consecutive ones less
    than 180° apart: a planar face's two edges at its corner), plus 0.2
    per unit of ratio above 0.8 summed; and apart the penalties: 2 per h
    of an edge below ``short`` h, 1 per h of circumradius above ``wide``
    h, 10 per h of a gap between neighbours on one ray outside
    ``[gap_lo, gap_hi]`` h (``ray``: the ray a sample lies on, -2 for the
    corner, on all, -1 for none).  Both infinite where the points cannot
    be triangulated."""
    got = delaunay_triangles(pts, 1e-9 * h * h, 1e-10 * h**4)
    if got is None:
        return np.inf, np.inf
    tri, _ = got
    worst = 0.0
    over = 0.0
    pen = 0.0
    for t in range(tri.shape[0]):
        a, b, c = tri[t, 0], tri[t, 1], tri[t, 2]
        cx = (pts[a, 0] + pts[b, 0] + pts[c, 0]) / 3.0
        cy = (pts[a, 1] + pts[b, 1] + pts[c, 1]) / 3.0
        if cx * cx + cy * cy > judged * judged or _in_sector(dirs, cx, cy, 0.0) < 0:
            continue
        la = math.hypot(pts[b, 0] - pts[c, 0], pts[b, 1] - pts[c, 1])
        lb = math.hypot(pts[c, 0] - pts[a, 0], pts[c, 1] - pts[a, 1])
        lc = math.hypot(pts[a, 0] - pts[b, 0], pts[a, 1] - pts[b, 1])
        hi = max(la, lb, lc)
        lo = min(la, lb, lc)
        rho = (la + lb + lc - hi - lo) / hi
        worst = max(worst, rho)
        over += max(0.0, rho - 0.8)
        for ln in (la, lb, lc):
            pen += 2.0 * max(0.0, short - ln / h)
        area2 = abs(orient(pts, a, b, c))
        if area2 > 0.0:
            pen += max(0.0, la * lb * lc / (2.0 * area2) / h - wide)
        else:
            pen += 1e6
    # the gaps between neighbours along each ray
    m = pts.shape[0]
    for e in range(dirs.shape[0]):
        cnt = 0
        for i in range(m):
            if ray[i] == e or ray[i] == -2:
                cnt += 1
        ts = np.empty(cnt)
        k = 0
        for i in range(m):
            if ray[i] == e or ray[i] == -2:
                ts[k] = pts[i, 0] * dirs[e, 0] + pts[i, 1] * dirs[e, 1]
                k += 1
        ts.sort()
        for k in range(cnt - 1):
            g = (ts[k + 1] - ts[k]) / h
            pen += 10.0 * (max(0.0, gap_lo - g) + max(0.0, g - gap_hi))
    return worst + 0.2 * over, pen


@njit(cache=True)
def anneal_corner(
    pts,
    kind,
    ray,
    dirs,
    reach,
    judged,
    clear,
    h,
    gap_lo,
    gap_hi,
    short,
    wide,
    seed,
    moves,
    sigma,
    t0,
):
    """One seeded annealing of a corner's region (:func:`corner_score`; the
    corner at the origin).

    ``kind`` says which samples move: ``FREE`` ones within their sector
    (the one they start in), at least ``clear`` h inside both its rays and
    within ``reach`` of the corner, ``ON_EDGE`` ones along their ray
    within ``reach``, keeping their order on it; ``FIXED`` ones stay.  A
    move that brings a sample nearer than ``short`` h to another is
    refused.  ``moves`` steps, each of one sample (drawn uniformly) by a
    normal step of ``sigma`` h, accepted by Metropolis' rule at a
    temperature falling geometrically from ``t0`` to ``t0 / 1000``, on the
    ratio's part of the score; a move that makes the penalties' part exceed
    the start's is refused (the annealing trades no spacing for a ratio).
    Returns the best points met and their ratio score."""
    m = pts.shape[0]
    p = pts.copy()
    movable = np.flatnonzero(kind != FIXED)
    score, cap = corner_score(p, ray, dirs, judged, h, gap_lo, gap_hi, short, wide)
    if movable.size == 0:
        return p, score
    cap += 1e-9
    sector = np.full(m, -1, dtype=np.int64)
    for i in range(m):
        if kind[i] == FREE:
            sector[i] = _in_sector(dirs, p[i, 0], p[i, 1], 0.0)
    state = np.uint64(seed) * np.uint64(0x2545F4914F6CDD1D) + np.uint64(1)
    best = p.copy()
    best_score = score
    temp = t0
    cool = math.exp(math.log(1e-3) / moves)
    for _ in range(moves):
        temp *= cool
        state, u = _next(state)
        i = movable[min(int(u * movable.size), movable.size - 1)]
        ox, oy = p[i, 0], p[i, 1]
        if kind[i] == ON_EDGE:
            e = ray[i]
            ux, uy = dirs[e, 0], dirs[e, 1]
            t = ox * ux + oy * uy
            state, z = _normal(state)
            nt = t + sigma * h * z
            if nt > reach or nt <= 0.0:
                continue
            # keep the order along the ray: no neighbour passed
            passed = False
            for j in range(m):
                if j != i and (ray[j] == e or ray[j] == -2):
                    tj = p[j, 0] * ux + p[j, 1] * uy
                    if (tj - t) * (tj - nt) < 0.0:
                        passed = True
                        break
            if passed:
                continue
            nx = nt * ux
            ny = nt * uy
        else:
            state, zx = _normal(state)
            state, zy = _normal(state)
            nx = ox + sigma * h * zx
            ny = oy + sigma * h * zy
            if nx * nx + ny * ny > reach * reach:
                continue
            s = sector[i]
            if s < 0:
                continue
            if dirs[s, 0] * ny - dirs[s, 1] * nx < clear * h:
                continue
            if nx * dirs[s + 1, 1] - ny * dirs[s + 1, 0] < clear * h:
                continue
        near = False
        for j in range(m):
            if j != i and (p[j, 0] - nx) ** 2 + (p[j, 1] - ny) ** 2 < (short * h) ** 2:
                near = True
                break
        if near:
            continue
        p[i, 0], p[i, 1] = nx, ny
        s2, pen = corner_score(p, ray, dirs, judged, h, gap_lo, gap_hi, short, wide)
        state, u = _next(state)
        if pen <= cap and (s2 < score or u < math.exp(-(s2 - score) / temp)):
            score = s2
            if score < best_score:
                best_score = score
                best[:, :] = p
        else:
            p[i, 0], p[i, 1] = ox, oy
    return best, best_score
