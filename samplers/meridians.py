"""A turned part's meridian: its faces' profiles chained end to end, the
sharp circles on it, and rings moved onto those circles.

A body of revolution whose faces are planes across its axis (disks and
annuli), cylinders, cones, spheres and tori about one axis, each going all
the way round, is one curve turned about the axis: its meridian, from the
axis back to the axis (a ball, a filleted cylinder) or closed (a torus, a
drilled and filleted cylinder).  :func:`sr33.samplers.layers.lattice_revolved_body`
lays such a body in rings along the meridian; the rings' cells are the
same on either side of a sharp circle (the meridian is a geodesic of the
surface and its arc length the distance across the edge), but the edge
itself must carry a ring, so that the samples follow the surface's crease
(:func:`snapped`).

Plain numpy; the faces' profiles are read with OCP when the functions run.
"""

from __future__ import annotations

import numpy as np

from sr33.mesh import dot, norm

#: a ring moved onto a sharp circle drags the rings this many steps either
#: side along, less and less (a step then changes by at most an eighth of
#: the row step where the ring moved half a step)
SNAP_REACH = 4


def plane_meridian(face, o: np.ndarray, axis: np.ndarray, tol: float, count: int = 2000):
    """The meridian of a plane face across the axis (a disk or an annulus
    round it): parameters (its radii), axial and radial coordinates from
    its inner circle (or the axis) to its outer one; None when the face is
    not one (its normal off the axis, an edge that is not a whole circle
    about the axis, more than two circles)."""
    from OCP.BRep import BRep_Tool

    normal = np.array(face.normalAt().toTuple())
    if abs(abs(dot(normal, axis)) - 1.0) > 1e-9:
        return None
    radii, heights = [], []
    for e in face.Edges():
        if BRep_Tool.Degenerated_s(e.wrapped):
            continue
        if e.geomType() != "CIRCLE" or not e.IsClosed():
            return None
        c = np.array(e.Center().toTuple()) - o
        z = float(dot(c, axis))
        if norm(c - z * axis) > tol:
            return None
        radii.append(float(e.radius()))
        heights.append(z)
    if not radii or len(radii) > 2 or max(heights) - min(heights) > tol:
        return None
    inner = min(radii) if len(radii) == 2 else 0.0
    v = np.linspace(inner, max(radii), count)
    return v, np.full(count, heights[0]), v.copy()


def chained(parts: list, tol: float):
    """The faces' profiles ``(face, v, axial, radial)`` in order along the
    meridian, each turned to run on from the one before, and whether the
    meridian closes; None when they do not make one curve.  An open meridian
    starts on the axis at its lowest end (along the axis), a closed one at
    the end of the profile with the lowest point (the first of equal ones)."""
    if not parts:
        return None

    def ends(q):
        return np.array([q[2][0], q[3][0]]), np.array([q[2][-1], q[3][-1]])

    def flip(q):
        return (q[0], q[1][::-1], q[2][::-1], q[3][::-1])

    on_axis = [
        (float(e[0]), k, side)
        for k, q in enumerate(parts)
        for side, e in enumerate(ends(q))
        if e[1] <= tol
    ]
    if on_axis:
        if len(on_axis) != 2:
            return None
        _, k, side = min(on_axis)
        first = parts[k] if side == 0 else flip(parts[k])
    else:
        k = min(range(len(parts)), key=lambda i: (float(parts[i][2].min()), i))
        first = parts[k]
    order, left = [first], [q for i, q in enumerate(parts) if i != k]
    while left:
        tail = ends(order[-1])[1]
        hits = [
            (i, side)
            for i, q in enumerate(left)
            for side, e in enumerate(ends(q))
            if norm(e - tail) <= tol
        ]
        if len(hits) != 1:
            return None
        i, side = hits[0]
        order.append(left[i] if side == 0 else flip(left[i]))
        del left[i]
    start, stop = ends(order[0])[0], ends(order[-1])[1]
    closed = bool(norm(start - stop) <= tol) and not on_axis
    if not closed and not (start[1] <= tol and stop[1] <= tol):
        return None
    return order, closed


def snapped(
    at: np.ndarray, sharp: list[float], frozen: np.ndarray
) -> tuple[np.ndarray, list[int]] | None:
    """Ring positions ``at`` (arc lengths along a meridian from the axis to
    the axis, increasing) with a ring on every sharp circle (arc lengths
    ``sharp``): the nearest ring moves onto it and the ``SNAP_REACH`` rings
    either side follow it less and less (between two moved rings nearer
    than twice that, the moves blend linearly).  Rings ``frozen`` (a
    pole's, whose repair wants them one step apart) stay.  Returns the
    positions and the rings on the sharp circles, or None when a sharp
    circle's nearest ring is frozen or nearest to another one too."""
    n = at.size
    knots: dict[int, float] = {}
    for f in sharp:
        d = f - at
        j = int(np.argmin(np.abs(d)))
        if frozen[j] or j in knots:
            return None
        knots[j] = float(d[j])
    fixed = dict(knots)
    for j in np.flatnonzero(frozen):
        fixed[int(j)] = 0.0
    ext = [(-SNAP_REACH - 1, 0.0)] + sorted(fixed.items()) + [(n + SNAP_REACH, 0.0)]
    move = np.zeros(n)
    for (j0, d0), (j1, d1) in zip(ext[:-1], ext[1:]):
        for j in range(max(j0 + 1, 0), min(j1, n)):
            if j1 - j0 <= 2 * SNAP_REACH:
                x = d0 + (d1 - d0) * (j - j0) / (j1 - j0)
            else:
                x = d0 * max(0.0, 1 - (j - j0) / SNAP_REACH)
                x += d1 * max(0.0, 1 - (j1 - j) / SNAP_REACH)
            move[j] = x
    for j, d in fixed.items():
        move[j] = d
    out = at + move
    if (np.diff(out) <= 0).any():
        return None
    return out, sorted(knots)
