"""A box with its vertical and top edges filleted, laid out as one lattice.

The scan rows of fillet_box ran along one family's planes across its flat
sides, its quarter-cylinder fillets and its corners (sphere octants), and
the corners broke Condition III-ii for 2.2% of the samples, mostly inside
the octants and across their smooth seams.  Each piece of such a box has a
natural lattice that continues across the seams:

* the sides and the vertical fillets form one prism over the bottom's
  rounded rectangle: columns at the bottom edges' samples (``round(L / h)``
  equal steps on every straight edge, ``n = round(pi R / (2 h))`` on every
  quarter circle, as the scan samples those sharp edges), rows
  ``round((z_t - z_b) / h)`` equal steps up to the fillets' axes;
* a top fillet carries the columns of the side below it and n rows round
  its quarter circle; the top is the lattice of the sides' columns;
* a corner octant takes its latitude circles about the vertical through
  its centre, n equal steps from its top (the corner of the top face) to
  its equator (the vertical fillet's top row), so that they meet the two
  top fillets' rows where those end on it and its equator carries the
  vertical fillet's columns; each circle is divided into equal steps of
  about h.  The octant is then repaired on its stereographic map
  (:func:`sr33.samplers.spheres.repair_sphere_face`), its seams' samples fixed
  and the fillets' and the top's samples near them as the judged frame;
* the bottom keeps its scan rows and the boundary-layer repair of planar
  faces (:func:`sr33.samplers.layers.repair_planar_faces`).

Everything but the octants is a lattice of near-squares (ratio below
0.75).  A box filleted otherwise (all edges, or the bottom's too) is left
to the scan rows.  CadQuery is imported when the functions run.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

from .faces import basis_surface, exact_bounds, nearest_face, revolution_axis, steps, thin
from .samples import Samples
from .spheres import repair_sphere_face


@dataclass(frozen=True)
class FilletedBox:
    """An axis-aligned box whose four vertical and four top edges are filleted.

    Attributes
    ----------
    lo, hi : (3,) float64
        The box's corners.
    radius : float
        The fillets' radius.
    """

    lo: np.ndarray
    hi: np.ndarray
    radius: float


def find_filleted_box(occ, tol: float) -> FilletedBox | None:
    """The box with filleted vertical and top edges that ``occ`` is, or None.

    Six planes (four sides, top, bottom), four sphere octants of one radius
    R centred R inside the box's top corners, four vertical quarter
    cylinders on the vertical edges' fillet axes and four horizontal ones
    on the top edges', all within ``tol`` of that geometry.
    """
    faces = occ.Faces()
    kinds = [f.geomType() for f in faces]
    if len(faces) != 18 or sorted(kinds) != sorted(
        ["PLANE"] * 6 + ["CYLINDER"] * 8 + ["SPHERE"] * 4
    ):
        return None
    lo, hi = exact_bounds(occ)
    spheres = [basis_surface(f).Sphere() for f, k in zip(faces, kinds) if k == "SPHERE"]
    r = float(spheres[0].Radius())
    if any(abs(float(sp.Radius()) - r) > tol for sp in spheres):
        return None
    xs, ys, zt = (lo[0] + r, hi[0] - r), (lo[1] + r, hi[1] - r), hi[2] - r
    if min(xs[1] - xs[0], ys[1] - ys[0], zt - lo[2]) <= tol:
        return None
    want = {(x, y) for x in range(2) for y in range(2)}
    got = set()
    for sp in spheres:
        c = np.array(sp.Location().Coord())
        ix = int(np.argmin([abs(c[0] - x) for x in xs]))
        iy = int(np.argmin([abs(c[1] - y) for y in ys]))
        if abs(c[0] - xs[ix]) > tol or abs(c[1] - ys[iy]) > tol or abs(c[2] - zt) > tol:
            return None
        got.add((ix, iy))
    if got != want:
        return None
    axes = {"x": 0, "y": 0, "z": 0}
    for f, k in zip(faces, kinds):
        if k != "CYLINDER":
            continue
        if abs(float(basis_surface(f).Cylinder().Radius()) - r) > tol:
            return None
        o, d = revolution_axis(f)
        a = int(np.argmax(np.abs(d)))
        if abs(abs(d[a]) - 1.0) > 1e-9:
            return None
        name = "xyz"[a]
        if name == "z":
            ok = min(abs(o[0] - x) for x in xs) < tol and min(abs(o[1] - y) for y in ys) < tol
        elif name == "x":
            ok = min(abs(o[1] - y) for y in ys) < tol and abs(o[2] - zt) < tol
        else:
            ok = min(abs(o[0] - x) for x in xs) < tol and abs(o[2] - zt) < tol
        if not ok:
            return None
        axes[name] += 1
    if axes != {"x": 2, "y": 2, "z": 4}:
        return None
    for f, k in zip(faces, kinds):
        if k != "PLANE":
            continue
        n = np.array(f.normalAt().toTuple())
        a = int(np.argmax(np.abs(n)))
        p = np.array(f.Center().toTuple())
        if abs(abs(n[a]) - 1.0) > 1e-9 or min(abs(p[a] - lo[a]), abs(p[a] - hi[a])) > tol:
            return None
    return FilletedBox(lo=lo, hi=hi, radius=r)


def _octant_rows(radius: float, n: int, h: float) -> list[np.ndarray]:
    """Latitude circles of the octant x, y, z >= 0 of a sphere about the
    origin: ``n - 1`` of them, ``pi / (2 n)`` apart from the pole down, each
    from the xz-plane to the yz-plane in equal steps of about h."""
    rows = []
    for k in range(1, n):
        phi = k * math.pi / (2 * n)
        ring = radius * math.sin(phi)
        m = steps(ring * math.pi / 2, h)
        t = np.linspace(0.0, math.pi / 2, m + 1)
        rows.append(
            np.stack(
                [ring * np.cos(t), ring * np.sin(t), np.full(t.size, radius * math.cos(phi))], 1
            )
        )
    return rows


def _pieces(box: FilletedBox, xs, ys, zs, ang, corners) -> list[list[np.ndarray]]:
    """The rows of the sides, the vertical fillets, the top fillets and the
    top (each piece a list of rows, each row an (m, 3) array): the sides'
    and vertical fillets' rows at the heights ``zs``, their columns at
    ``ys`` or ``xs`` and at the angles ``ang``; the top fillets' rows at the
    angles ``ang`` round their axes, their columns ``xs`` or ``ys``."""
    lo, hi, r = box.lo, box.hi, box.radius
    x0, x1, y0, y1 = lo[0] + r, hi[0] - r, lo[1] + r, hi[1] - r
    zt = hi[2] - r

    def rows(outer, inner, x, y, z):
        """Per value u of ``outer``, the row of points (x, y, z)(u, inner)."""
        return [
            np.stack([np.broadcast_to(f(u, inner), inner.shape) for f in (x, y, z)], axis=1)
            for u in outer
        ]

    out = []
    for x in (lo[0], hi[0]):
        out.append(rows(zs, ys, lambda z, c, x=x: x, lambda z, c: c, lambda z, c: z))
    for y in (lo[1], hi[1]):
        out.append(rows(zs, xs, lambda z, c: c, lambda z, c, y=y: y, lambda z, c: z))
    for sx, sy in corners:
        cx, cy, _ = _corner(box, sx, sy)
        out.append(
            rows(
                zs,
                ang,
                lambda z, t, cx=cx, sx=sx: cx + sx * r * np.cos(t),
                lambda z, t, cy=cy, sy=sy: cy + sy * r * np.sin(t),
                lambda z, t: z,
            )
        )
    # the top fillets: along x (round the axes at y0, y1), then along y
    for along, cols, axes in ((0, xs, (y0, y1)), (1, ys, (x0, x1))):
        for sign, axis in zip((-1, 1), axes):

            def across(a, c, axis=axis, sign=sign):
                return axis + sign * r * math.cos(a)

            xy = [lambda a, c: c, across][:: 1 if along == 0 else -1]
            out.append(rows(ang, cols, *xy, lambda a, c: zt + r * math.sin(a)))
    out.append(rows(ys, xs, lambda y, c: c, lambda y, c: y, lambda y, c: hi[2]))
    return out


def lattice_filleted_box(occ, s: Samples, h: float, size: float) -> tuple[list[dict], set[int]]:
    """Lay a box with filleted vertical and top edges out as one lattice
    (see the module's docstring).

    Replaces every sample off the bottom's plane when ``occ`` is such a box
    (:func:`find_filleted_box`); does nothing otherwise.  Each row of a
    piece is a scan line; samples at B-rep vertices are feature samples,
    as in the scan.  Returns one report per octant (its repair) and the
    indices of the faces laid out (all but the bottom).
    """
    tol = 1e-7 * size
    box = find_filleted_box(occ, tol)
    if box is None:
        return [], set()
    faces = occ.Faces()
    lo, hi, r = box.lo, box.hi, box.radius
    x0, x1, y0, y1 = lo[0] + r, hi[0] - r, lo[1] + r, hi[1] - r
    zb, zt = lo[2], hi[2] - r
    n = steps(math.pi * r / 2, h)
    xs = np.linspace(x0, x1, steps(x1 - x0, h) + 1)
    ys = np.linspace(y0, y1, steps(y1 - y0, h) + 1)
    zs = np.linspace(zb, zt, steps(zt - zb, h) + 1)[1:]  # the bottom's row is kept
    ang = np.linspace(0.0, math.pi / 2, n + 1)
    corners = [(sx, sy) for sx in (-1, 1) for sy in (-1, 1)]
    octant = _octant_rows(r, n, h)
    pieces = _pieces(box, xs, ys, zs, ang, corners) + [
        # the corner octants' latitude rows
        [_corner(box, sx, sy) + q * np.array([sx, sy, 1.0]) for q in octant]
        for sx, sy in corners
    ]
    line = int(s.line_id.max()) + 1 if s.line_id.size else 0
    pts, lid, fid = [], [], []
    for rows in pieces:
        middle = rows[len(rows) // 2]
        face = nearest_face(middle[len(middle) // 2], faces)
        for row in rows:
            pts.append(row)
            lid += [line] * row.shape[0]
            fid += [face] * row.shape[0]
            line += 1
    pts3 = np.vstack(pts)
    keep = thin(pts3, tol)  # a seam's samples come once, from the first piece
    pts3, lid, fid = pts3[keep], np.array(lid)[keep], np.array(fid)[keep]
    vertices = np.array([v.toTuple() for v in occ.Vertices()])
    feat = cKDTree(vertices).query(pts3)[0] < tol
    off_bottom = np.flatnonzero(np.abs(s.points[:, 2] - zb) > tol)
    s.replace(off_bottom, pts3, np.where(feat, -1, lid), fid, feat)
    laid = {
        f
        for f in range(len(faces))
        if faces[f].geomType() != "PLANE"
        or abs(np.array(faces[f].Center().toTuple())[2] - zb) > tol
    }
    # the octants repaired on their maps one after another until one is left
    # with no triangle above the repair's margin; that one, or the best
    # (lowest worst ratio, then fewest bad triangles), is mirrored onto the
    # others, whose seams and neighbours are its mirror images
    octants = []
    for fi, face in enumerate(faces):
        if face.geomType() == "SPHERE":
            c = revolution_axis(face)[0]
            sign = np.array([np.sign(c[0] - (x0 + x1) / 2), np.sign(c[1] - (y0 + y1) / 2), 1.0])
            octants.append((fi, face, c, sign))
    tried = []
    for fi, face, c, sign in octants:
        rep = repair_sphere_face(
            fi, face, s, h, size, fixed=s.on_feature | _seams(s.points, c, r, tol)
        )
        if rep is not None:
            tried.append((rep["worst"], rep["bad"], fi, c, sign, rep))
            if rep["bad"] == 0:
                break
    if not tried:
        return [], laid
    _, _, best, cb, sb, rep = min(tried, key=lambda o: o[:3])
    answer = (s.points[_free_octant(s, cb, sb, r, tol)] - cb) * sb  # in the octant's frame
    reports = []
    for fi, _, c, sign in octants:
        if fi != best:
            s.replace(
                _free_octant(s, c, sign, r, tol),
                c + answer * sign,
                np.full(answer.shape[0], -3),
                np.full(answer.shape[0], fi),
                np.zeros(answer.shape[0], dtype=bool),
            )
        reports.append({**rep, "face": fi, "kind": "filleted corner", "from": best})
    return reports, laid


def _corner(box: FilletedBox, sx: float, sy: float) -> np.ndarray:
    """The centre of the corner sphere on the (sx, sy) side (signs of x, y)."""
    lo, hi, r = box.lo, box.hi, box.radius
    return np.array(
        [hi[0] - r if sx > 0 else lo[0] + r, hi[1] - r if sy > 0 else lo[1] + r, hi[2] - r]
    )


def _on_sphere(points: np.ndarray, centre: np.ndarray, radius: float, tol: float) -> np.ndarray:
    return np.abs(np.linalg.norm(points - centre, axis=1) - radius) < tol


def _seams(points: np.ndarray, centre: np.ndarray, radius: float, tol: float) -> np.ndarray:
    """The samples on a corner sphere's seams: on the sphere and on one of
    the three coordinate planes through its centre."""
    on_plane = (np.abs(points - centre) < tol).any(axis=1)
    return _on_sphere(points, centre, radius, tol) & on_plane


def _free_octant(s: Samples, centre: np.ndarray, sign: np.ndarray, radius: float, tol: float):
    """Indices of an octant's samples off its seams and off the features."""
    inside = ((s.points - centre) * sign > tol).all(axis=1)
    return np.flatnonzero(_on_sphere(s.points, centre, radius, tol) & inside & ~s.on_feature)
