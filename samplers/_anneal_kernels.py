"""numba kernel: a seeded annealing of the few samples round an acute corner.

The repair (:mod:`sr33.samplers.repair`) is a descent with edits; round a
planar face's corner below 60° it ends in a basin it cannot leave (a
wedge's 30° corner: 0.883 from 40 shaken starts of 41, one below 0.85).
There the two edges' samples must stagger near the corner, then stand
side by side, then let a sample in on the bisector, and a descent on a
smooth energy does not reorder them.  :func:`anneal_corner` searches
instead: one sample at a time moves by a seeded normal step (a free sample
in the corner's sector, an edge's sample along its edge), the Delaunay
triangles of the region are made anew (:func:`delaunay_triangles`), and the
move is kept by Metropolis' rule on the region's score (its worst ratio
first).  The random numbers are the kernel's own (SplitMix64, Box-Muller),
so that a seed gives the same moves with any numpy or numba.
"""

from __future__ import annotations

import math

import numpy as np

from sr33.jit import njit

from ._delaunay_kernels import delaunay_triangles

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
def corner_score(pts, edge, apex, dirs, normals, judged, h, gap_lo, gap_hi, short, wide):
    """The score of a corner's region ``pts`` ((m, 2)): the worst ratio of
    its Delaunay triangles whose centroid lies in the corner's sector (on
    the inner side of both ``normals`` (2, 2) from ``apex``; ``dirs`` (2, 2)
    the unit directions of its edges from the apex) within
    ``judged`` of the apex plus 0.2 per unit of ratio above 0.8 summed,
    and apart the penalties: 2 per h of an edge below ``short`` h, 1 per h
    of circumradius above ``wide`` h, 10 per h of a gap between neighbours
    on one edge (``edge``: 0 or 1 for the samples on the corner's two
    edges, the apex on both, -1 elsewhere) outside ``[gap_lo, gap_hi]`` h.
    Both infinite where the points cannot be triangulated."""
    got = delaunay_triangles(pts, 1e-9 * h * h, 1e-10 * h**4)
    if got is None:
        return np.inf, np.inf
    tri, _ = got
    worst = 0.0
    over = 0.0
    pen = 0.0
    for t in range(tri.shape[0]):
        a, b, c = tri[t, 0], tri[t, 1], tri[t, 2]
        cx = (pts[a, 0] + pts[b, 0] + pts[c, 0]) / 3.0 - apex[0]
        cy = (pts[a, 1] + pts[b, 1] + pts[c, 1]) / 3.0 - apex[1]
        if cx * cx + cy * cy > judged * judged:
            continue
        if cx * normals[0, 0] + cy * normals[0, 1] <= 0.0:
            continue
        if cx * normals[1, 0] + cy * normals[1, 1] <= 0.0:
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
        area2 = abs(
            (pts[b, 0] - pts[a, 0]) * (pts[c, 1] - pts[a, 1])
            - (pts[b, 1] - pts[a, 1]) * (pts[c, 0] - pts[a, 0])
        )
        if area2 > 0.0:
            pen += max(0.0, la * lb * lc / (2.0 * area2) / h - wide)
        else:
            pen += 1e6
    # the gaps between neighbours along each edge
    m = pts.shape[0]
    for e in range(2):
        ux = dirs[e, 0]
        uy = dirs[e, 1]
        cnt = 0
        for i in range(m):
            if edge[i] == e or edge[i] == 2:
                cnt += 1
        ts = np.empty(cnt)
        k = 0
        for i in range(m):
            if edge[i] == e or edge[i] == 2:
                ts[k] = (pts[i, 0] - apex[0]) * ux + (pts[i, 1] - apex[1]) * uy
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
    edge,
    apex,
    dirs,
    normals,
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
    """One seeded annealing of a corner's region (:func:`corner_score`).

    ``kind`` says which samples move: ``FREE`` ones anywhere in the sector
    at least ``clear`` h inside both edges and within ``reach`` of the
    apex, ``ON_EDGE`` ones along their edge (``edge`` 0 or 1) within
    ``reach``, keeping their order on it; ``FIXED`` ones stay.  A move
    that brings a sample nearer than ``short`` h to another is refused.
    ``moves`` steps, each of one sample (drawn uniformly) by a normal step
    of ``sigma`` h, accepted by Metropolis' rule at a temperature falling
    geometrically from ``t0`` to ``t0 / 1000``, on the ratio's part of the
    score; a move that makes the penalties' part exceed the start's is
    refused (the annealing trades no spacing for a ratio).  Returns the best
    points met and their ratio score."""
    m = pts.shape[0]
    p = pts.copy()
    movable = np.flatnonzero(kind != FIXED)
    score, cap = corner_score(p, edge, apex, dirs, normals, judged, h, gap_lo, gap_hi, short, wide)
    if movable.size == 0:
        return p, score
    cap += 1e-9
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
            e = edge[i]
            ux, uy = dirs[e, 0], dirs[e, 1]
            t = (ox - apex[0]) * ux + (oy - apex[1]) * uy
            state, z = _normal(state)
            nt = t + sigma * h * z
            if nt > reach or nt <= 0.0:
                continue
            # keep the order along the edge: no neighbour passed
            passed = False
            for j in range(m):
                if j != i and (edge[j] == e or edge[j] == 2):
                    tj = (p[j, 0] - apex[0]) * ux + (p[j, 1] - apex[1]) * uy
                    if (tj - t) * (tj - nt) < 0.0:
                        passed = True
                        break
            if passed:
                continue
            nx = apex[0] + nt * ux
            ny = apex[1] + nt * uy
        else:
            state, zx = _normal(state)
            state, zy = _normal(state)
            nx = ox + sigma * h * zx
            ny = oy + sigma * h * zy
            dx, dy = nx - apex[0], ny - apex[1]
            if dx * dx + dy * dy > reach * reach:
                continue
            if dx * normals[0, 0] + dy * normals[0, 1] < clear * h:
                continue
            if dx * normals[1, 0] + dy * normals[1, 1] < clear * h:
                continue
        near = False
        for j in range(m):
            if j != i and (p[j, 0] - nx) ** 2 + (p[j, 1] - ny) ** 2 < (short * h) ** 2:
                near = True
                break
        if near:
            continue
        p[i, 0], p[i, 1] = nx, ny
        s2, pen = corner_score(p, edge, apex, dirs, normals, judged, h, gap_lo, gap_hi, short, wide)
        state, u = _next(state)
        if pen <= cap and (s2 < score or u < math.exp(-(s2 - score) / temp)):
            score = s2
            if score < best_score:
                best_score = score
                best[:, :] = p
        else:
            p[i, 0], p[i, 1] = ox, oy
    return best, best_score
