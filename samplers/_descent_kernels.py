"""numba kernel of the repair's descent on a planar face (straight edges, arcs)
(:func:`sr33.samplers.repair._steps`): the steps of one descent in one loop.

A descent step on a few hundred samples is a dozen small kernels and twice
as many numpy calls; in Python the calls cost several times the arithmetic
(a hexagonal prism's caps: 0.27 ms a step, 0.05 ms of it in kernels).
Where every callback of a repair problem is one of the planar forms of
:mod:`sr33.samplers.chart` (the projections onto straight edges and arcs,
their clamps and ghosts, an inside test by
:class:`~sr33.samplers.chart.Raster`), :func:`descend` runs the steps
here, calling the same kernels on the same arrays in the same order as the
Python loop: bit for bit its samples.  It triangulates anew where the
points changed or an edge flip cannot mend the last triangulation, and
hands back to Python only where that needs Qhull.
"""

from __future__ import annotations

import numpy as np

from sr33.jit import njit

from ._delaunay_kernels import checkable, delaunay_triangles
from ._line_kernels import (
    TWO_PI,
    clamp,
    clamp_arcs,
    clamp_radial,
    ghosts,
    ghosts_arcs,
    inside_sector,
    project_curves,
)
from ._repair_kernels import (
    canonical_order,
    canonical_reorder,
    centroids,
    delaunay_flips_since,
    descent_step,
    energy_terms,
    gathered_gradient,
    grid_lookup,
    same_points,
)

FINISHED, QHULL, OUT_OF_STEPS = 0, 1, 2  # why :func:`descend` returned
GHOST, FRAME = -1, -2  # the sample id of a ghost point and of a judged frame point


@njit(cache=True)
def _ghost_points(on, ghost_arcs, ghost_lines, ghost_h, kinds):
    """The ghosts of the sliding samples ``on``: of each of ``kinds`` in
    order (0: across straight edges, :func:`ghosts`; 1: across arcs,
    :func:`ghosts_arcs`)."""
    parts = []
    for kind in kinds:
        if kind == 0:
            ga, gd, gdd, gin, corners, own = ghost_lines
            parts.append(ghosts(on, ga, gd, gdd, gin, ghost_h, corners, own))
        else:
            centre, radius, side = ghost_arcs
            parts.append(ghosts_arcs(on, centre, radius, side, ghost_h))
    total = 0
    for g in parts:
        total += g.shape[0]
    out = np.empty((total, 2))
    row = 0
    for g in parts:
        out[row : row + g.shape[0]] = g
        row += g.shape[0]
    return out


@njit(cache=True)
def _turned(x, y, angle):
    """(x, y) turned about the origin by ``angle`` (``repair.rotate``)."""
    c = np.cos(angle)
    s = np.sin(angle)
    return c * x - s * y, s * x + c * y


@njit(cache=True)
def _images(uv, idx, turn, band, half):
    """The images of the samples ``idx`` across a development's glued
    sides, the sample each is and the angle it is turned by
    (``repair._Problem.images``): those within ``band`` (along their arc)
    and ``half`` (an angle) of the side at 0 turned by ``+turn``, then those
    near the side at ``turn`` by ``-turn``."""
    n = idx.size
    r = np.empty(n)
    a = np.empty(n)
    for i in range(n):
        x, y = uv[idx[i], 0], uv[idx[i], 1]
        r[i] = np.sqrt(x * x + y * y)
        a[i] = np.arctan2(y, x) % TWO_PI
    pos = np.empty((2 * n, 2))
    of = np.empty(2 * n, dtype=np.int64)
    angle = np.empty(2 * n)
    row = 0
    for sign in (1.0, -1.0):
        for i in range(n):
            off = a[i] if sign > 0 else turn - a[i]
            if off * r[i] < band and off < half and r[i] > 0.0:
                pos[row, 0], pos[row, 1] = _turned(uv[idx[i], 0], uv[idx[i], 1], sign * turn)
                of[row] = idx[i]
                angle[row] = sign * turn
                row += 1
    return pos[:row], of[:row], angle[:row]


@njit(cache=True)
def _extended(
    uv, idx, slide, ghost_arcs, ghost_lines, ghost_h, ghost_kinds, frame, frame_id, h, glue
):
    """The samples ``idx``, their images across a development's glued sides
    (``glue`` = (turn, band, half), turn 0: none), the ghosts of their
    sliding ones and the frame's points within 3 h of their bounding box,
    with the id of each and the angle each image is turned by
    (``repair._Problem.extended``)."""
    n = idx.size
    turn, band, half = glue
    if turn != 0.0:
        img, img_of, img_angle = _images(uv, idx, turn, band, half)
    else:
        img, img_of, img_angle = np.empty((0, 2)), np.empty(0, dtype=np.int64), np.empty(0)
    if ghost_kinds.size:
        count = 0
        for i in range(n):
            if slide[idx[i]]:
                count += 1
        on = np.empty((count, 2))
        count = 0
        for i in range(n):
            if slide[idx[i]]:
                on[count, 0] = uv[idx[i], 0]
                on[count, 1] = uv[idx[i], 1]
                count += 1
        g = _ghost_points(on, ghost_arcs, ghost_lines, ghost_h, ghost_kinds)
    else:
        g = np.empty((0, 2))
    kept = np.zeros(frame.shape[0], dtype=np.bool_)
    nf = 0
    if frame.shape[0] > 0 and n > 0:
        lo0, lo1 = uv[idx[0], 0], uv[idx[0], 1]
        hi0, hi1 = lo0, lo1
        for i in range(1, n):
            x, y = uv[idx[i], 0], uv[idx[i], 1]
            lo0, hi0 = min(lo0, x), max(hi0, x)
            lo1, hi1 = min(lo1, y), max(hi1, y)
        lo0, lo1 = lo0 - 3 * h, lo1 - 3 * h
        hi0, hi1 = hi0 + 3 * h, hi1 + 3 * h
        for k in range(frame.shape[0]):
            f0, f1 = frame[k, 0], frame[k, 1]
            if f0 >= lo0 and f1 >= lo1 and f0 <= hi0 and f1 <= hi1:
                kept[k] = True
                nf += 1
    total = n + img.shape[0] + g.shape[0] + nf
    pts = np.empty((total, 2))
    of = np.empty(total, dtype=np.int64)
    turned = np.zeros(total)
    for i in range(n):
        pts[i, 0] = uv[idx[i], 0]
        pts[i, 1] = uv[idx[i], 1]
        of[i] = idx[i]
    row = n
    for i in range(img.shape[0]):
        pts[row, 0] = img[i, 0]
        pts[row, 1] = img[i, 1]
        of[row] = img_of[i]
        turned[row] = img_angle[i]
        row += 1
    for i in range(g.shape[0]):
        pts[row, 0] = g[i, 0]
        pts[row, 1] = g[i, 1]
        of[row] = GHOST
        row += 1
    for k in range(frame.shape[0]):
        if kept[k]:
            pts[row, 0] = frame[k, 0]
            pts[row, 1] = frame[k, 1]
            of[row] = frame_id
            row += 1
    return pts, of, turned


@njit(cache=True)
def _gather(uv, mask):
    out = np.empty((int(mask.sum()), 2))
    row = 0
    for v in range(uv.shape[0]):
        if mask[v]:
            out[row, 0] = uv[v, 0]
            out[row, 1] = uv[v, 1]
            row += 1
    return out


@njit(cache=True)
def _scatter(uv, mask, values):
    row = 0
    for v in range(uv.shape[0]):
        if mask[v]:
            uv[v, 0] = values[row, 0]
            uv[v, 1] = values[row, 1]
            row += 1


@njit(cache=True)
def _inside(c, kind, raster, raster_cell, sector, far):
    """Which points ``c`` are in the face: by its raster (``kind`` 0,
    ``chart.Raster``, or ``chart.TriangleRaster`` with ``far`` = (period,
    beyond): looked up modulo the period along the first axis where it is
    positive, and every point not within ``beyond`` of the origin inside
    too; (0, inf) for a plain raster) or in an annular sector (1: outer,
    inner, theta, full; ``chart.Sector``)."""
    if kind == 0:
        lo, grid = raster
        period, beyond = far
        q = c.copy()
        if period > 0.0:
            for k in range(q.shape[0]):
                q[k, 0] = q[k, 0] % period
        out = grid_lookup(q, lo, raster_cell, grid)
        if beyond < np.inf:
            for k in range(c.shape[0]):
                if not (np.sqrt(c[k, 0] * c[k, 0] + c[k, 1] * c[k, 1]) <= beyond):
                    out[k] = True
        return out
    outer, inner, theta, full = sector
    return inside_sector(c, outer, inner, theta, full)


@njit(cache=True)
def _rim_clamped(q, rim, inside):
    """``q`` kept in the face and off its rims (``chart.RimClamp``):
    ``rim`` = (points, inward normals, gaps, and their ``chart.Buckets``'
    lo, cell, dims, start, members); a point nearer its nearest rim point
    than that point's gap, or outside (``inside``), goes to the nearest rim
    point's inward normal at the gap.  The nearest rim point by all of
    them, the first of equally near ones (:func:`_nearest`)."""
    c, inward, gap, lo, cell, dims, start, members = rim
    out = q.copy()
    for k in range(q.shape[0]):
        j, best = _nearest(q[k, 0], q[k, 1], c, lo, cell, dims, start, members)
        if j < 0:
            continue
        if np.sqrt(best) < gap[j] or not inside[k]:
            out[k, 0] = c[j, 0] + gap[j] * inward[j, 0]
            out[k, 1] = c[j, 1] + gap[j] * inward[j, 1]
    return out


@njit(cache=True)
def _nearest(x, y, c, lo, cell, dims, start, members):
    """The point of ``c`` nearest (x, y) and its squared distance: the one a
    scan of all of them finds (the same squared distances, the first of
    equally near ones; -1 for a point that is not finite), looked up in the
    buckets ``lo, cell, dims, start, members`` (``chart.Buckets``) ring by
    ring of cells round the point's own, until the rings left are all
    farther (by half a cell more, against rounding) than the nearest found."""
    best, j = np.inf, -1
    if not (np.isfinite(x) and np.isfinite(y)) or c.shape[0] == 0:
        return j, best
    nx, ny = dims[0], dims[1]
    # a point off the grid counts from the cell just off it: every cell is
    # then on one side of it, and the rings' bound still holds
    ci = int(min(max(np.floor((x - lo[0]) / cell), -1.0), float(nx)))
    cj = int(min(max(np.floor((y - lo[1]) / cell), -1.0), float(ny)))
    last = max(ci + 1, nx - ci, cj + 1, ny - cj)
    for r in range(last + 1):
        for i in range(max(0, ci - r), min(nx - 1, ci + r) + 1):
            edge = i == ci - r or i == ci + r
            jj = cj - r
            while jj <= cj + r:
                if 0 <= jj < ny:
                    cellid = i * ny + jj
                    for t in range(start[cellid], start[cellid + 1]):
                        m = members[t]
                        dx = x - c[m, 0]
                        dy = y - c[m, 1]
                        d = dx * dx + dy * dy
                        if d < best or (d == best and m < j):
                            best, j = d, m
                jj = jj + 1 if edge else (jj + 2 * r if r > 0 else jj + 1)
        if j >= 0 and r >= 1 and best < ((r - 0.5) * cell) ** 2:
            break
    return j, best


@njit(cache=True)
def _clamped(q, parts, line_clamps, line_margins, arc_clamps, rim, inside_of):
    """``q`` through every clamp of ``parts`` in order (rows: kind, first,
    end; kind 0 the straight edges ``line_clamps`` [first, end) with that
    part's (least, beyond) in ``line_margins``, kind 1 the arcs
    ``arc_clamps`` [first, end), kind 2 a distance from the origin within
    that part's (lo, hi) in ``line_margins``, ``chart.RadialClamp``; kind 3
    the rims ``rim`` of :func:`_rim_clamped`, with ``inside_of`` = (kind,
    raster, cell, sector, far) the face's inside test as :func:`_inside`
    takes it)."""
    ca, cd, cdd, cn = line_clamps
    centre, radius, start, span, closed, side, margin = arc_clamps
    for k in range(parts.shape[0]):
        s, e = parts[k, 1], parts[k, 2]
        if parts[k, 0] == 0:
            q = clamp(
                q,
                ca[s:e].copy(),
                cd[s:e].copy(),
                cdd[s:e].copy(),
                cn[s:e].copy(),
                line_margins[k, 0],
                line_margins[k, 1],
            )
        elif parts[k, 0] == 2:
            q = clamp_radial(q, line_margins[k, 0], line_margins[k, 1])
        elif parts[k, 0] == 3:
            kind, raster, cell, sector, far = inside_of
            q = _rim_clamped(q, rim, _inside(q, kind, raster, cell, sector, far))
        else:
            q = clamp_arcs(
                q,
                centre[s:e].copy(),
                radius[s:e].copy(),
                start[s:e].copy(),
                span[s:e].copy(),
                closed[s:e].copy(),
                side[s:e].copy(),
                margin[s:e].copy(),
            )
    return q


@njit(cache=True)
def descend(
    uv,
    free,
    slide,
    anchor,
    judged,
    idx,
    label,
    regions,
    steps,
    best,
    since,
    params,
    last,
    projection,
    has_projection,
    clamp_parts,
    line_clamps,
    line_margins,
    arc_clamps,
    ghost_arcs,
    ghost_lines,
    ghost_h,
    ghost_kinds,
    frame,
    frame_id,
    inside_kind,
    raster,
    raster_cell,
    sector,
    glue,
    far,
    rim_clamp,
):
    """Up to ``steps`` steps of the repair's descent (``repair._steps``), in
    place on ``uv``, for a planar face bounded by straight edges and arcs.

    ``params`` = (h, reach, target, short, gap_lo, gap_hi, wide, stop
    ratio, step length, keep move, keep area, keep circle), as the repair
    computes them; ``last`` = (ids, points, triangles, neighbours) of the
    last triangulation (empty ids: none); ``projection`` the table of a
    :class:`~sr33.samplers.chart.CurveProjection` (kind, a, d, dd, lo,
    centre, radius, start, span, closed, margin); the clamps as
    :func:`_clamped` takes them; the ghosts' arcs (centre, radius, side),
    straight edges (a, d, dd, inward, corners, own), h and kinds in order (see
    :func:`_ghost_points`); the inside test as :func:`_inside` takes it;
    ``glue`` = (turn, band, half, middle) of a development whose sides are
    glued (turn 0: none; ``repair._Problem.images`` and ``wrap``).  ``far``
    = (period, beyond) of a raster's inside test (see :func:`_inside`);
    ``rim_clamp`` = (points, inward normals, gaps, and their buckets)
    of the rims a chart's clamp keeps free samples off (kind 3 of
    :func:`_clamped`).

    A step whose points are not the last triangulation's (an edit added or
    removed a sample, one moved by more than the keep move) or whose flips
    cannot mend it is triangulated anew here, by the repair's own sweep
    (:func:`sr33.samplers._delaunay_kernels.delaunay_triangles`), as
    ``repair._delaunay`` does; where the sweep gives up, Qhull is Python's.

    Returns why it stopped (``FINISHED``: the descent is over; ``QHULL``:
    the next step needs Qhull; ``OUT_OF_STEPS``), the steps made, the
    descent's best energy and steps since, and the last triangulation's
    ids (none: not to be carried on), points, triangles and neighbours with
    whether they changed.
    """
    (
        h,
        reach,
        target,
        short,
        gap_lo,
        gap_hi,
        wide,
        stop,
        step,
        keep_move,
        keep_area,
        keep_circle,
    ) = params
    last_of, last_pts, last_tri, last_nbr = last
    kind, pa, pd, pdd, plo, centre, radius, start, span, closed, margin = projection
    turn = glue[0]
    n = uv.shape[0]
    move = free | slide
    hold = slide | anchor
    changed = False
    done = 0
    while done < steps:
        pts, of, turned = _extended(
            uv,
            idx,
            slide,
            ghost_arcs,
            ghost_lines,
            ghost_h,
            ghost_kinds,
            frame,
            frame_id,
            h,
            (glue[0], glue[1], glue[2]),
        )
        if pts.shape[0] < 3:
            return FINISHED, done, best, since, last_of, last_pts, last_tri, last_nbr, changed
        anew = last_of.size == 0 or not same_points(last_of, of, last_pts, pts, keep_move)
        tri, nbr = last_tri, last_nbr
        if not anew:
            flipped = delaunay_flips_since(
                pts, last_pts, last_tri, last_nbr, keep_area, keep_circle
            )
            if flipped is None:
                anew = True
            else:
                tri, nbr, flips = flipped
                if flips:
                    tri, nbr = canonical_reorder(tri, nbr, last_tri)
        if anew:  # as repair._delaunay: the sweep, canonical, kept when checkable
            swept = delaunay_triangles(pts, keep_area, keep_circle)
            if swept is None:  # Qhull's
                return QHULL, done, best, since, last_of, last_pts, last_tri, last_nbr, changed
            t0, n0 = swept
            tri, nbr = canonical_order(t0, n0)
            if checkable(pts, tri, keep_area):
                last_of = of
            else:
                last_of = np.empty(0, dtype=np.int64)
        last_pts, last_tri, last_nbr, changed = pts, tri, nbr, True
        # the face's triangles: inside it, or on its judged frame
        inside = _inside(centroids(pts, tri), inside_kind, raster, raster_cell, sector, far)
        count = 0
        for t in range(tri.shape[0]):
            if not inside[t]:
                for j in range(3):
                    if of[tri[t, j]] == FRAME:
                        inside[t] = True
            if inside[t]:
                count += 1
        if count == 0:
            return FINISHED, done, best, since, last_of, last_pts, last_tri, last_nbr, changed
        face = np.empty((count, 3), dtype=np.int64)
        row = 0
        for t in range(tri.shape[0]):
            if inside[t]:
                face[row] = tri[t]
                row += 1
        energy, gp, rho, _ = energy_terms(
            pts, of, face, move, hold, anchor, judged, reach, h, target, short, gap_lo, gap_hi, wide
        )
        if rho.size == 0 or rho.max() < stop:
            return FINISHED, done, best, since, last_of, last_pts, last_tri, last_nbr, changed
        if energy < 0.99 * best:
            best, since = energy, 0
        else:
            since += 1
            if since >= 15:
                return FINISHED, done, best, since, last_of, last_pts, last_tri, last_nbr, changed
        if turn != 0.0:  # an image's gradient, turned back onto its sample
            for k in range(gp.shape[0]):
                gp[k, 0], gp[k, 1] = _turned(gp[k, 0], gp[k, 1], -turned[k])
        grad = gathered_gradient(of, gp, n, move)
        moved = descent_step(uv, grad, move, label, regions, step)
        if not moved.any():
            return FINISHED, done, best, since, last_of, last_pts, last_tri, last_nbr, changed
        slid = moved & slide
        if has_projection and slid.any():
            on = project_curves(
                _gather(uv, slid),
                kind,
                pa,
                pd,
                pdd,
                plo,
                centre,
                radius,
                start,
                span,
                closed,
                margin,
            )
            _scatter(uv, slid, on)
        shifted = moved & free
        if clamp_parts.shape[0] and shifted.any():
            _scatter(
                uv,
                shifted,
                _clamped(
                    _gather(uv, shifted),
                    clamp_parts,
                    line_clamps,
                    line_margins,
                    arc_clamps,
                    rim_clamp,
                    (inside_kind, raster, raster_cell, sector, far),
                ),
            )
        if turn != 0.0:  # back into the sector
            for v in range(n):
                if moved[v]:
                    a = np.arctan2(uv[v, 1], uv[v, 0]) % TWO_PI
                    k = 0.0
                    if a >= turn:
                        k = 1.0 if a >= glue[3] else -1.0
                    uv[v, 0], uv[v, 1] = _turned(uv[v, 0], uv[v, 1], k * turn)
        done += 1
    return OUT_OF_STEPS, done, best, since, last_of, last_pts, last_tri, last_nbr, changed
