"""numba kernel of the repair (:mod:`sr33.samplers.repair`): its energy and
the energy's gradient over the Delaunay triangles of a step.

Bit for bit the numpy code it replaced: the same operations in the same
order, the sums as numpy sums (its pairwise summation, :func:`_pairwise`),
every gradient term added per point in the order ``np.bincount`` added them
(the ratio's terms, then the short edges', the gaps', the radii's).  A
sampling is a local search whose end can turn on a last bit; a faster
energy must not move one.
"""

from __future__ import annotations

import math

import numpy as np

from sr33.jit import njit


@njit(cache=True)
def _block(a, lo, n):
    """``a[lo:lo + n].sum()`` for n <= 128, as numpy: a plain loop below 8,
    else 8 partial sums combined pairwise, then the rest."""
    if n < 8:
        res = 0.0
        for i in range(n):
            res += a[lo + i]
        return res
    r = np.empty(8)
    for j in range(8):
        r[j] = a[lo + j]
    i = 8
    while i < n - (n % 8):
        for j in range(8):
            r[j] += a[lo + i + j]
        i += 8
    res = ((r[0] + r[1]) + (r[2] + r[3])) + ((r[4] + r[5]) + (r[6] + r[7]))
    while i < n:
        res += a[lo + i]
        i += 1
    return res


@njit(cache=True)
def _pairwise(a):
    """``a.sum()`` of a contiguous float64 array as numpy sums it
    (``pairwise_sum`` of its ``loops_utils``): blocks of at most 128 by
    :func:`_block`, longer runs halved at a multiple of 8 and the halves'
    sums added.  The recursion runs on an explicit stack (numba's cache
    does not hold recursive functions)."""
    # tasks: (lo, n) to sum, or n = -1: add the last two sums
    task_lo = np.empty(256, dtype=np.int64)
    task_n = np.empty(256, dtype=np.int64)
    sums = np.empty(128)
    tasks, depth = 1, 0
    task_lo[0], task_n[0] = 0, a.size
    while tasks:
        tasks -= 1
        lo, n = task_lo[tasks], task_n[tasks]
        if n < 0:
            depth -= 1
            sums[depth - 1] = sums[depth - 1] + sums[depth]
        elif n <= 128:
            sums[depth] = _block(a, lo, n)
            depth += 1
        else:
            n2 = n // 2
            n2 -= n2 % 8
            # popped in reverse: the first half, the second, then their sum
            task_lo[tasks], task_n[tasks] = 0, -1
            task_lo[tasks + 1], task_n[tasks + 1] = lo + n2, n - n2
            task_lo[tasks + 2], task_n[tasks + 2] = lo, n2
            tasks += 3
    return sums[0]  # (an empty array is one block of 0, summing to 0.0)


@njit(cache=True)
def numpy_sum(a):
    """``a.sum()`` of a contiguous float64 array, bit for bit as numpy."""
    return _pairwise(a.ravel())


@njit(cache=True)
def _edge_sum(terms, by_row):
    """The sum of per-edge ``terms`` (3, m), edge column by column, or
    triangle by triangle where ``by_row``."""
    return numpy_sum(terms.T.copy() if by_row else terms)


@njit(cache=True)
def _push(gp, tri, rows, vec, length, col, coef, far):
    """The gradient terms of one edge per triangle (``col`` (m,), an edge's
    column: corners ``col`` and ``col + 1``): ``coef`` times its unit vector
    at its first corner, or minus that at its second (``far``).  :func:`_edge`
    makes both passes, all triangles in turn each: the order ``np.bincount``
    saw them in."""
    for k in range(rows.size):
        c = col[k]
        ux = vec[k, c, 0] / length[k, c]
        uy = vec[k, c, 1] / length[k, c]
        v = tri[rows[k], (c + 1) % 3 if far else c]
        f = -coef[k] if far else coef[k]
        gp[v, 0] += f * ux
        gp[v, 1] += f * uy


@njit(cache=True)
def _edge(gp, tri, rows, vec, length, col, coef):
    _push(gp, tri, rows, vec, length, col, coef, False)
    _push(gp, tri, rows, vec, length, col, coef, True)


@njit(cache=True)
def energy_terms(
    pts, of, tri, move, hold, anchor, judged, reach, h, target, short, gap_lo, gap_hi, wide
):
    """The repair's energy over the Delaunay triangles ``tri`` of the
    extended points ``pts`` (each the sample ``of`` says, -1 for a ghost,
    -2 for a judged frame point) and its gradient on those points.

    A triangle counts when it has no ghost, has a ``judged`` sample and
    either only samples or a movable one (``move``); with ``reach`` > 0,
    only when its longest edge is at most ``reach``.  Terms per triangle
    (h the spacing): ``max(0, rho - target)**2`` (rho = second-longest over
    longest edge); ``max(0, short h - l)**2 / h**2 / 2`` per edge (an
    interior edge is seen twice); ``5 g**2 / 2`` per edge between two
    samples sliding or anchored (not both anchored), g the excess outside
    ``[gap_lo h, gap_hi h]`` over h (its gradient weighted 10 g), so that
    the samples of an edge keep the spacing the lattice of the face across
    it starts from; and ``max(0, R - wide h)**2 / h**2`` for the
    circumradius R (capped at 1e6 h: a sliver's would overflow the square),
    whose gradient pulls the corners to the centroid.

    Returns the energy, the gradient on ``pts`` (P, 2), the ratios of the
    triangles that count and their rows in ``tri``.
    """
    npts = pts.shape[0]
    gp = np.zeros((npts, 2))
    # the triangles that count, with their edges (edge j runs from corner j
    # to corner j + 1) and lengths
    m0 = tri.shape[0]
    rows = np.empty(m0, dtype=np.int64)
    vec = np.empty((m0, 3, 2))
    length = np.empty((m0, 3))
    m = 0
    for t in range(m0):
        ghost = False
        real = 0
        movable = False
        seen = False
        for j in range(3):
            s = of[tri[t, j]]
            if s == -1:
                ghost = True
            elif s >= 0:
                real += 1
                movable = movable or move[s]
                seen = seen or judged[s]
        if ghost or not seen or not (real == 3 or movable):
            continue
        longest = 0.0
        for j in range(3):
            a, b = tri[t, j], tri[t, (j + 1) % 3]
            vx = pts[a, 0] - pts[b, 0]
            vy = pts[a, 1] - pts[b, 1]
            vec[m, j, 0] = vx
            vec[m, j, 1] = vy
            length[m, j] = np.sqrt(vx * vx + vy * vy)
            longest = max(longest, length[m, j])
        if reach > 0.0 and not longest <= reach:
            continue
        rows[m] = t
        m += 1
    rows, vec, length = rows[:m], vec[:m], length[:m]
    rho = np.empty(m)
    over = np.empty(m)
    i2 = np.empty(m, dtype=np.int64)
    i3 = np.empty(m, dtype=np.int64)
    for q in range(m):
        # the edges in order of length, ties by column (a stable argsort)
        o0, o1, o2 = 0, 1, 2
        if length[q, o1] < length[q, o0]:
            o0, o1 = o1, o0
        if length[q, o2] < length[q, o1]:
            o1, o2 = o2, o1
            if length[q, o1] < length[q, o0]:
                o0, o1 = o1, o0
        i2[q], i3[q] = o1, o2
        rho[q] = length[q, o1] / length[q, o2]
        over[q] = max(0.0, rho[q] - target)
    energy = numpy_sum(over * over)
    coef = np.empty(m)
    for q in range(m):
        coef[q] = 2 * over[q] / length[q, i3[q]]
    _edge(gp, tri, rows, vec, length, i2, coef)
    for q in range(m):
        l2, l3 = length[q, i2[q]], length[q, i3[q]]
        coef[q] = -2 * over[q] * l2 / (l3 * l3)
    _edge(gp, tri, rows, vec, length, i3, coef)
    # short edges
    # (numpy summed the edges' terms in the order it held their lengths in
    # memory: column by column as its fancy indexing left them, row by row
    # once the reach filter had copied them; hence ``_edge_sum``)
    sh = np.empty((3, m))
    for q in range(m):
        for j in range(3):
            sh[j, q] = max(0.0, short * h - length[q, j]) / h
    energy += _edge_sum(sh * sh, reach > 0.0) / 2.0
    col = np.empty(m, dtype=np.int64)
    for j in range(3):
        col[:] = j
        for q in range(m):
            coef[q] = -sh[j, q] / h
        _edge(gp, tri, rows, vec, length, col, coef)
    # samples sliding along one edge keep their spacing
    gap = np.zeros((3, m))
    both = False
    for q in range(m):
        t = rows[q]
        for j in range(3):
            sa, sb = of[tri[t, j]], of[tri[t, (j + 1) % 3]]
            if sa >= 0 and sb >= 0 and hold[sa] and hold[sb] and not (anchor[sa] and anchor[sb]):
                both = True
                g = max(0.0, gap_lo * h - length[q, j]) - max(0.0, length[q, j] - gap_hi * h)
                gap[j, q] = g / h
    if both:
        energy += 5.0 * _edge_sum(gap * gap, reach > 0.0) / 2.0
        for j in range(3):
            col[:] = j
            for q in range(m):
                coef[q] = -10.0 * gap[j, q] / h
            _edge(gp, tri, rows, vec, length, col, coef)
    # circumradius R = abc / (4 area): a hole in the coverage
    wd = np.empty(m)
    radius = np.empty(m)
    for q in range(m):
        cross = vec[q, 0, 0] * (-vec[q, 2, 1]) - vec[q, 0, 1] * (-vec[q, 2, 0])
        area = 0.5 * abs(cross)
        prod = length[q, 0] * length[q, 1] * length[q, 2]
        radius[q] = min(prod / max(4.0 * area, 1e-300), 1e6 * h)
        wd[q] = max(0.0, radius[q] - wide * h) / h
    energy += numpy_sum(wd * wd)
    for q in range(m):
        t = rows[q]
        a, b, c = tri[t, 0], tri[t, 1], tri[t, 2]
        f = 2 * wd[q] / h
        r = max(radius[q], 1e-300)
        for d in range(2):
            cen = (pts[a, d] + pts[b, d] + pts[c, d]) / 3.0
            gp[a, d] += f * (pts[a, d] - cen) / r
            gp[b, d] += f * (pts[b, d] - cen) / r
            gp[c, d] += f * (pts[c, d] - cen) / r
    return energy, gp, rho, rows


@njit(cache=True)
def delaunay_flips(pts, tri, nbr, tol_area, tol_circle):
    """See :func:`_flips` (every edge checked)."""
    return _flips(pts, tri, nbr, tol_area, tol_circle, np.ones(pts.shape[0], dtype=np.bool_))


@njit(cache=True)
def delaunay_flips_since(pts, before, tri, nbr, tol_area, tol_circle):
    """:func:`delaunay_flips` from ``tri``, the Delaunay triangulation of
    the points at their positions ``before``: an edge none of whose four
    points moved since is still Delaunay (its in-circle value is the one
    its last check passed), so only the others start on the stack, in the
    same order (an edge a flip changes is pushed again by that flip): the
    same flips in the same order, without testing every edge of a large
    face at every descent step."""
    n = pts.shape[0]
    moved = np.zeros(n, dtype=np.bool_)
    for i in range(n):
        moved[i] = pts[i, 0] != before[i, 0] or pts[i, 1] != before[i, 1]
    return _flips(pts, tri, nbr, tol_area, tol_circle, moved)


@njit(cache=True)
def _flips(pts, tri, nbr, tol_area, tol_circle, moved):
    """The Delaunay triangulation of ``pts`` from ``tri``, a triangulation of
    the same points at earlier positions (counter-clockwise triangles, their
    neighbours ``nbr`` opposite each corner, -1 on the hull), by Lawson's
    edge flips; or None where flips cannot make it (the positions must be
    tiled by the triangles as they are: every triangle counter-clockwise
    with twice its area above ``tol_area``, and the hull's edges a convex
    polygon, turning left or straight at every vertex and once round in
    all; the triangles then cover it once, their map having degree one).

    An edge is flipped when its neighbour's far corner lies inside a
    triangle's circumcircle by more than ``tol_circle`` (the in-circle
    determinant), so that cocircular points (a lattice's squares, within
    rounding) keep the diagonal they have.  Returns new arrays (the input
    is left as it is) and the number of flips.  A repair step moves the
    samples by 0.02 h: a few edges flip where a Qhull call would triangulate
    them all anew.
    """
    n = pts.shape[0]
    m = tri.shape[0]
    # every triangle counter-clockwise ...
    for t in range(m):
        a = tri[t, 0]
        b = tri[t, 1]
        c = tri[t, 2]
        ux = pts[b, 0] - pts[a, 0]
        uy = pts[b, 1] - pts[a, 1]
        vx = pts[c, 0] - pts[a, 0]
        vy = pts[c, 1] - pts[a, 1]
        if ux * vy - uy * vx <= tol_area:
            return None
    # ... and the hull's cycle turning left (or straight) at every vertex,
    # once round in all: a convex polygon, which the triangles (all of
    # degree one) then cover once
    after = np.full(n, -1, dtype=np.int64)
    start = -1
    count = 0
    for t in range(m):
        for k in range(3):
            if nbr[t, k] < 0:
                after[tri[t, (k + 1) % 3]] = tri[t, (k + 2) % 3]
                start = tri[t, (k + 1) % 3]
                count += 1
    turning = 0.0
    v = start
    for _ in range(count):
        w = after[v]
        x = after[w]
        if w < 0 or x < 0:
            return None
        ux = pts[w, 0] - pts[v, 0]
        uy = pts[w, 1] - pts[v, 1]
        vx = pts[x, 0] - pts[w, 0]
        vy = pts[x, 1] - pts[w, 1]
        turn = np.arctan2(ux * vy - uy * vx, ux * vx + uy * vy)
        if turn < -1e-10:
            return None
        turning += turn
        v = w
    if v != start or abs(turning - 2.0 * np.pi) > 1e-6:
        return None
    tri = tri.copy()
    nbr = nbr.copy()
    stack_t = np.empty(3 * m + 64, dtype=np.int64)
    stack_k = np.empty(3 * m + 64, dtype=np.int64)
    top = 0
    for t in range(m):
        for k in range(3):
            u = nbr[t, k]
            if u > t:
                j = 0
                while tri[u, j] == tri[t, (k + 1) % 3] or tri[u, j] == tri[t, (k + 2) % 3]:
                    j += 1
                if moved[tri[t, 0]] or moved[tri[t, 1]] or moved[tri[t, 2]] or moved[tri[u, j]]:
                    stack_t[top] = t
                    stack_k[top] = k
                    top += 1
    flips = 0
    while top > 0:
        top -= 1
        t = stack_t[top]
        k = stack_k[top]
        u = nbr[t, k]
        if u < 0:
            continue
        a = tri[t, k]
        b = tri[t, (k + 1) % 3]
        c = tri[t, (k + 2) % 3]
        j = 0
        while tri[u, j] == b or tri[u, j] == c:
            j += 1
        d = tri[u, j]  # u is (d, c, b) counter-clockwise from j
        if incircle(pts, a, b, c, d) <= tol_circle:
            continue
        nt_b = nbr[t, (k + 1) % 3]  # across (c, a)
        nt_c = nbr[t, (k + 2) % 3]  # across (a, b)
        nu_c = nbr[u, (j + 1) % 3]  # across (b, d)
        nu_b = nbr[u, (j + 2) % 3]  # across (d, c)
        # t becomes (a, b, d), u becomes (a, d, c)
        tri[t, 0], tri[t, 1], tri[t, 2] = a, b, d
        nbr[t, 0], nbr[t, 1], nbr[t, 2] = nu_c, u, nt_c
        tri[u, 0], tri[u, 1], tri[u, 2] = a, d, c
        nbr[u, 0], nbr[u, 1], nbr[u, 2] = nu_b, nt_b, t
        for w, old, new in ((nu_c, u, t), (nt_b, t, u)):
            if w >= 0:
                for q in range(3):
                    if nbr[w, q] == old:
                        nbr[w, q] = new
        flips += 1
        if flips > 4 * m or top + 4 > stack_t.size:
            return None
        # the four outer edges may have stopped being Delaunay
        stack_t[top], stack_k[top] = t, 0
        stack_t[top + 1], stack_k[top + 1] = t, 2
        stack_t[top + 2], stack_k[top + 2] = u, 0
        stack_t[top + 3], stack_k[top + 3] = u, 1
        top += 4
    return tri, nbr, flips


@njit(cache=True)
def _in_order(t2, n2, order):
    """The rows of ``t2`` (with their neighbours ``n2``) taken in ``order``,
    the neighbours renumbered to the new rows (-1 stays)."""
    m = t2.shape[0]
    back = np.empty(m, dtype=np.int64)
    for i in range(m):
        back[order[i]] = i
    out_t = np.empty_like(t2)
    out_n = np.empty_like(n2)
    for i in range(m):
        for k in range(3):
            out_t[i, k] = t2[order[i], k]
            w = n2[order[i], k]
            out_n[i, k] = back[w] if w >= 0 else -1
    return out_t, out_n


@njit(cache=True)
def canonical_order(tri, nbr):
    """Counter-clockwise triangles ``tri`` in one order whatever the
    triangulator's: each turned to start at its smallest corner, the rows
    sorted; with their neighbours ``nbr`` (opposite each corner, -1 on the
    hull) turned and renumbered alike.  Returns new arrays."""
    m = tri.shape[0]
    t2 = np.empty_like(tri)
    n2 = np.empty_like(nbr)
    key = np.empty(m, dtype=np.int64)
    big = np.int64(tri.max() + 1) if m else np.int64(1)
    for t in range(m):
        r = 0
        if tri[t, 1] < tri[t, r]:
            r = 1
        if tri[t, 2] < tri[t, r]:
            r = 2
        for k in range(3):
            t2[t, k] = tri[t, (r + k) % 3]
            n2[t, k] = nbr[t, (r + k) % 3]
        key[t] = (t2[t, 0] * big + t2[t, 1]) * big + t2[t, 2]
    order = np.argsort(key)
    return _in_order(t2, n2, order)


@njit(cache=True)
def canonical_reorder(tri, nbr, before):
    """:func:`canonical_order` of ``tri`` (with ``nbr``) made by edge flips
    from ``before``, a triangulation in canonical order with as many rows:
    the rows the flips left as they were are in canonical form and order
    already, so only the others are turned and sorted, and the two runs
    merged (the same arrays as :func:`canonical_order`, whose sort of every
    row's key was a quarter of a descent step on a large face).  Falls back
    to the full sort if the untouched rows are not in order."""
    m = tri.shape[0]
    t2 = np.empty_like(tri)
    n2 = np.empty_like(nbr)
    key = np.empty(m, dtype=np.int64)
    big = np.int64(tri.max() + 1) if m else np.int64(1)
    changed = np.zeros(m, dtype=np.bool_)
    count = 0
    for t in range(m):
        same = tri[t, 0] == before[t, 0] and tri[t, 1] == before[t, 1] and tri[t, 2] == before[t, 2]
        r = 0
        if not same:
            changed[t] = True
            count += 1
            if tri[t, 1] < tri[t, r]:
                r = 1
            if tri[t, 2] < tri[t, r]:
                r = 2
        for k in range(3):
            t2[t, k] = tri[t, (r + k) % 3]
            n2[t, k] = nbr[t, (r + k) % 3]
        key[t] = (t2[t, 0] * big + t2[t, 1]) * big + t2[t, 2]
    moved = np.empty(count, dtype=np.int64)
    kept = np.empty(m - count, dtype=np.int64)
    i = j = 0
    for t in range(m):
        if changed[t]:
            moved[i] = t
            i += 1
        else:
            if j and key[t] <= key[kept[j - 1]]:
                return canonical_order(tri, nbr)
            kept[j] = t
            j += 1
    moved = moved[np.argsort(key[moved])]
    order = np.empty(m, dtype=np.int64)
    i = j = 0
    for o in range(m):
        if j >= kept.size or (i < moved.size and key[moved[i]] < key[kept[j]]):
            order[o] = moved[i]
            i += 1
        else:
            order[o] = kept[j]
            j += 1
    return _in_order(t2, n2, order)


@njit(cache=True)
def incircle(pts, a, b, c, d):
    """Positive when ``d`` lies inside the circle through the counter-clockwise ``a, b, c``."""
    adx = pts[a, 0] - pts[d, 0]
    ady = pts[a, 1] - pts[d, 1]
    bdx = pts[b, 0] - pts[d, 0]
    bdy = pts[b, 1] - pts[d, 1]
    cdx = pts[c, 0] - pts[d, 0]
    cdy = pts[c, 1] - pts[d, 1]
    return (
        (adx * adx + ady * ady) * (bdx * cdy - cdx * bdy)
        - (bdx * bdx + bdy * bdy) * (adx * cdy - cdx * ady)
        + (cdx * cdx + cdy * cdy) * (adx * bdy - bdx * ady)
    )


@njit(cache=True)
def same_points(of_before, of, before, pts, reach):
    """Whether ``pts`` are the points ``before`` moved: the same ids ``of``,
    none farther than ``reach``."""
    if of_before.shape[0] != of.shape[0]:
        return False
    for i in range(of.shape[0]):
        if of_before[i] != of[i]:
            return False
        if abs(before[i, 0] - pts[i, 0]) > reach or abs(before[i, 1] - pts[i, 1]) > reach:
            return False
    return True


@njit(cache=True)
def centroids(pts, tri):
    """(m, 2): the triangles' centroids, ``pts[tri].mean(axis=1)`` bit for bit
    (numpy adds the corners in order, then divides by 3)."""
    m = tri.shape[0]
    out = np.empty((m, 2))
    for t in range(m):
        a = tri[t, 0]
        b = tri[t, 1]
        c = tri[t, 2]
        out[t, 0] = ((pts[a, 0] + pts[b, 0]) + pts[c, 0]) / 3.0
        out[t, 1] = ((pts[a, 1] + pts[b, 1]) + pts[c, 1]) / 3.0
    return out


@njit(cache=True)
def grid_lookup(pts, lo, cell, grid):
    """The cell of ``grid`` (rows along y) each point falls in, as
    :class:`sr33.samplers.chart.Raster` looks it up; False outside."""
    ny, nx = grid.shape
    out = np.zeros(pts.shape[0], dtype=np.bool_)
    for k in range(pts.shape[0]):
        x = (pts[k, 0] - lo[0]) / cell
        y = (pts[k, 1] - lo[1]) / cell
        if not (np.isfinite(x) and np.isfinite(y)):
            continue
        i = np.floor(x)
        j = np.floor(y)
        if i >= 0 and i < nx and j >= 0 and j < ny:
            out[k] = grid[int(j), int(i)]
    return out


@njit(cache=True)
def gathered_gradient(of, gp, n, move):
    """(n, 2): the gradient ``gp`` of the extended points added up per sample
    ``of`` (ghosts and frame points, ``of`` < 0, left out), one after
    another in their order from zero as ``np.bincount`` adds them, and
    zero on the samples that do not ``move``."""
    grad = np.zeros((n, 2))
    for k in range(of.shape[0]):
        v = of[k]
        if v >= 0:
            grad[v, 0] += gp[k, 0]
            grad[v, 1] += gp[k, 1]
    for v in range(n):
        if not move[v]:
            grad[v, 0] = 0.0
            grad[v, 1] = 0.0
    return grad


@njit(cache=True)
def descent_step(uv, grad, movable, label, regions, step):
    """One step of the repair's descent, in place: every ``movable`` sample
    moves against its gradient by ``step`` times its gradient over the
    largest gradient norm of its region (``label``, one of ``regions``),
    so that the largest move per region is ``step``.  Returns which samples
    moved (none where every region's largest norm is zero).  Bit for bit
    the numpy code it replaced: ``np.linalg.norm`` rows, ``np.maximum.at``
    per region from zero, ``uv[move] -= (step / g)[:, None] * grad``."""
    n = uv.shape[0]
    peak = np.zeros(regions)
    for v in range(n):
        x = math.sqrt(grad[v, 0] * grad[v, 0] + grad[v, 1] * grad[v, 1])
        p = peak[label[v]]
        if p == p and (x > p or x != x):
            peak[label[v]] = x
    moved = np.zeros(n, dtype=np.bool_)
    for v in range(n):
        g = peak[label[v]]
        if movable[v] and g > 0.0:
            moved[v] = True
            c = step / g
            uv[v, 0] -= c * grad[v, 0]
            uv[v, 1] -= c * grad[v, 1]
    return moved
