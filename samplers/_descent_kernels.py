"""numba kernel of the repair's descent on a face bounded by straight edges
(:func:`sr33.samplers.repair._steps`): the steps of one descent in one loop.

A descent step on a few hundred samples is a dozen small kernels and twice
as many numpy calls; in Python the calls cost several times the arithmetic
(a hexagonal prism's caps: 0.27 ms a step, 0.05 ms of it in kernels).
Where every callback of a repair problem is one of the straight-edge forms
of :mod:`sr33.samplers.chart` (:class:`~sr33.samplers.chart.LineProjection`,
:class:`~sr33.samplers.chart.LineClamp`,
:class:`~sr33.samplers.chart.LineGhosts`, an inside test by
:class:`~sr33.samplers.chart.Raster`), :func:`descend_lines` runs the steps
here, calling the same kernels on the same arrays in the same order as the
Python loop: bit for bit its samples.  It hands back to Python when a step
needs Qhull (the points changed or an edge flip cannot mend the last
triangulation), which triangulates anew and goes on.
"""

from __future__ import annotations

import numpy as np

from sr33.jit import njit

from ._line_kernels import clamp, ghosts, project
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

FINISHED, QHULL, OUT_OF_STEPS = 0, 1, 2  # why :func:`descend_lines` returned
GHOST, FRAME = -1, -2  # the sample id of a ghost point and of a judged frame point


@njit(cache=True)
def _extended(uv, idx, slide, ghost_lines, ghost_h, corners, has_ghosts, frame, frame_id, h):
    """The samples ``idx``, the ghosts of their sliding ones and the frame's
    points within 3 h of their bounding box, with the id of each
    (``repair._Problem.extended`` without a development's images)."""
    n = idx.size
    if has_ghosts:
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
        ga, gd, gdd, gin = ghost_lines
        g = ghosts(on, ga, gd, gdd, gin, ghost_h, corners)
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
def descend_lines(
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
    clamps,
    clamp_start,
    clamp_margins,
    ghost_lines,
    ghost_h,
    corners,
    has_ghosts,
    frame,
    frame_id,
    raster,
    raster_cell,
):
    """Up to ``steps`` steps of the repair's descent (``repair._steps``), in
    place on ``uv``, for a face bounded by straight edges.

    ``params`` = (h, reach, target, short, gap_lo, gap_hi, wide, stop
    ratio, step length, keep move, keep area, keep circle), as the repair
    computes them; ``last`` = (ids, points, triangles, neighbours) of the
    last triangulation (empty ids: none); ``projection`` = (a, d, dd, lo)
    of :class:`~sr33.samplers.chart.LineProjection`; ``clamps`` = (a, d,
    dd, normals) of every :class:`~sr33.samplers.chart.LineClamp` stacked,
    the k-th's rows from ``clamp_start[k]``, its (least, beyond) in
    ``clamp_margins[k]``; the ghosts' (a, d, dd, inward), h and corners;
    ``raster`` = (lo, grid) with its cell.

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
    pa, pd, pdd, plo = projection
    ca, cd, cdd, cn = clamps
    lo, grid = raster
    n = uv.shape[0]
    move = free | slide
    hold = slide | anchor
    changed = False
    done = 0
    while done < steps:
        pts, of = _extended(
            uv, idx, slide, ghost_lines, ghost_h, corners, has_ghosts, frame, frame_id, h
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
        if slid.any():
            _scatter(uv, slid, project(_gather(uv, slid), pa, pd, pdd, plo))
        shifted = moved & free
        if clamp_start.size > 1 and shifted.any():
            q = _gather(uv, shifted)
            for k in range(clamp_start.size - 1):
                s, e = clamp_start[k], clamp_start[k + 1]
                q = clamp(
                    q,
                    ca[s:e].copy(),
                    cd[s:e].copy(),
                    cdd[s:e].copy(),
                    cn[s:e].copy(),
                    clamp_margins[k, 0],
                    clamp_margins[k, 1],
                )
            _scatter(uv, shifted, q)
        done += 1
    return OUT_OF_STEPS, done, best, since, last_pts, last_tri, last_nbr, changed
