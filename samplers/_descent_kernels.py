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
Python loop: bit for bit its samples.  It hands back to Python when a step
needs Qhull (the points changed or an edge flip cannot mend the last
triangulation), which triangulates anew and goes on.
"""

from __future__ import annotations

import numpy as np

from sr33.jit import njit

from ._line_kernels import clamp, clamp_arcs, ghosts, ghosts_arcs, project_curves
from ._repair_kernels import (
    canonical_order,
    centroids,
    delaunay_flips,
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
            ga, gd, gdd, gin, corners = ghost_lines
            parts.append(ghosts(on, ga, gd, gdd, gin, ghost_h, corners))
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
def _extended(uv, idx, slide, ghost_arcs, ghost_lines, ghost_h, ghost_kinds, frame, frame_id, h):
    """The samples ``idx``, the ghosts of their sliding ones and the frame's
    points within 3 h of their bounding box, with the id of each
    (``repair._Problem.extended`` without a development's images)."""
    n = idx.size
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
    total = n + g.shape[0] + nf
    pts = np.empty((total, 2))
    of = np.empty(total, dtype=np.int64)
    for i in range(n):
        pts[i, 0] = uv[idx[i], 0]
        pts[i, 1] = uv[idx[i], 1]
        of[i] = idx[i]
    row = n
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
    return pts, of


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
def _clamped(q, parts, line_clamps, line_margins, arc_clamps):
    """``q`` through every clamp of ``parts`` in order (rows: kind, first,
    end; kind 0 the straight edges ``line_clamps`` [first, end) with that
    part's (least, beyond) in ``line_margins``, kind 1 the arcs
    ``arc_clamps`` [first, end))."""
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
    raster,
    raster_cell,
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
    straight edges (a, d, dd, inward, corners), h and kinds in order (see
    :func:`_ghost_points`); ``raster`` = (lo, grid) with its cell.

    Returns why it stopped (``FINISHED``: the descent is over; ``QHULL``:
    the next step needs Qhull; ``OUT_OF_STEPS``), the steps made, the
    descent's best energy and steps since, and the last triangulation's
    points, triangles and neighbours with whether they changed.
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
    lo, grid = raster
    n = uv.shape[0]
    move = free | slide
    hold = slide | anchor
    changed = False
    done = 0
    while done < steps:
        pts, of = _extended(
            uv, idx, slide, ghost_arcs, ghost_lines, ghost_h, ghost_kinds, frame, frame_id, h
        )
        if pts.shape[0] < 3:
            return FINISHED, done, best, since, last_pts, last_tri, last_nbr, changed
        if last_of.size == 0 or not same_points(last_of, of, last_pts, pts, keep_move):
            return QHULL, done, best, since, last_pts, last_tri, last_nbr, changed
        flipped = delaunay_flips(pts, last_tri, last_nbr, keep_area, keep_circle)
        if flipped is None:
            return QHULL, done, best, since, last_pts, last_tri, last_nbr, changed
        tri, nbr, flips = flipped
        if flips:
            tri, nbr = canonical_order(tri, nbr)
        last_pts, last_tri, last_nbr, changed = pts, tri, nbr, True
        # the face's triangles: inside it, or on its judged frame
        inside = grid_lookup(centroids(pts, tri), lo, raster_cell, grid)
        count = 0
        for t in range(tri.shape[0]):
            if not inside[t]:
                for j in range(3):
                    if of[tri[t, j]] == FRAME:
                        inside[t] = True
            if inside[t]:
                count += 1
        if count == 0:
            return FINISHED, done, best, since, last_pts, last_tri, last_nbr, changed
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
            return FINISHED, done, best, since, last_pts, last_tri, last_nbr, changed
        if energy < 0.99 * best:
            best, since = energy, 0
        else:
            since += 1
            if since >= 15:
                return FINISHED, done, best, since, last_pts, last_tri, last_nbr, changed
        grad = gathered_gradient(of, gp, n, move)
        moved = descent_step(uv, grad, move, label, regions, step)
        if not moved.any():
            return FINISHED, done, best, since, last_pts, last_tri, last_nbr, changed
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
                _clamped(_gather(uv, shifted), clamp_parts, line_clamps, line_margins, arc_clamps),
            )
        done += 1
    return OUT_OF_STEPS, done, best, since, last_pts, last_tri, last_nbr, changed
