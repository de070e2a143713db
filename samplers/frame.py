"""The frame a model is scanned in: its own axes when it lies off the world's.

:func:`sr33.samplers.scanline.scan` sweeps planes perpendicular to three
axes, and its layouts (rows dividing the bounding box's extents, the
lattices continued across faces) assume a model whose faces line up with
them, as a part on a scanner's table does.  A model built or exported off
those axes (a STEP part in its assembly's position, a library shape under
``rotate_x/y/z``) would be cut at arbitrary angles: a unit cube turned off
the axes came out with 4 % of its samples breaking Condition III-ii (worst
ratio 0.97, in 337 s) where the upright cube has none (0.707, 0.5 s).

:func:`model_frame` reads the model's directions from its B-rep (the
normals of planar faces and the axes of cylinders, cones, tori and surfaces
of revolution or extrusion, weighted by the faces' areas), groups parallel
ones, finds its mirror planes (:func:`sr33.samplers.symmetry.mirror_normals`),
and builds a frame from them:

* its z axis is the heaviest direction (ties: all heaviest are tried), its
  x axis a direction perpendicular to z, or a mirror's normal perpendicular
  to z, or that normal turned a quarter about z, and each of these turned
  half about z; of these frames the one that keeps the most mirrors (maps
  the model's mirrors onto its own axes, or swaps two axes: a hexagonal
  prism's vertex direction, a star's axis, not a frame lined up with one
  of their sides), then lines up the most area with z, x and z × x, then
  the most length of straight edges (a pyramid's base edges, not its
  diagonals), then the one the model is longest along x (as a part lies
  on a table), then reaches farther along +y and then +x from its centre
  of mass (a star's point up, as it is drawn), then the first in face
  order; for a model with no direction perpendicular to z (a cylinder, a
  cone) x is the x axis of z's first surface; z points along the axis of
  its first axial face (a cylinder's, a cone's: as the model was built),
  else away from its largest planar face (the one the model would rest
  on), so the frame turns with the model (rotating a B-rep keeps its
  faces' order, orientation and parametrisation), and a symmetric model
  turned any way is scanned in its upright frame or one its symmetry maps
  there (a turned hexagonal or star prism: the upright's scan rows);
* the world axes are kept unless the model's frame lines up at least
  ``SWITCH`` (a quarter) of the surface area more than they do.  Every
  library shape built upright keeps them (the largest gain among the 14 is
  wedge's 16 %, from its slanted face; star_prism's is 6 %); a model turned
  off the axes lines up nothing with them, and a model without a planar or
  axial face (a sphere, a B-spline body) has no frame of its own.

The frame's choice depends on areas, lengths and directions only (no float's
last bit decides between frames: directions within ``TOL`` are one, and the
candidates' areas and lengths, as shares of the model's area and size, are
equal within ``_WEIGHT_TIE``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from sr33.mesh import dot, norm

from .faces import exact_bounds
from .symmetry import mirror_normals, respected

TOL = 1e-7  # directions whose cross product is shorter than this are parallel
SWITCH = 0.25  # share of the area the model's frame must line up beyond the world's
_WEIGHT_TIE = 1e-9  # weights (or shares) closer than this, relatively, are equal

WORLD = np.eye(3)


@dataclass(frozen=True)
class Frame:
    """The frame chosen for a scan (:func:`model_frame`).

    Attributes
    ----------
    axes : (3, 3) float64
        Rows: the frame's x, y and z axes in world coordinates (a rotation:
        orthonormal, determinant +1).  A point ``p`` of the model has frame
        coordinates ``axes @ p``.
    aligned : float
        Share of the surface area whose direction lies along one of
        ``axes`` (its planar faces' normals, its axial faces' axes).
    world_aligned : float
        The same share for the world axes.
    """

    axes: np.ndarray
    aligned: float
    world_aligned: float

    @property
    def world(self) -> bool:
        """Whether the world axes are kept (``axes`` is the identity)."""
        return bool(np.array_equal(self.axes, WORLD))


def surface_directions(solid) -> tuple[np.ndarray, np.ndarray]:
    """The directions of a B-rep's faces, with their areas.

    Planar faces give their normal, cylinders, cones, tori and surfaces of
    revolution their axis, surfaces of extrusion their direction; spheres
    and free-form (B-spline, Bézier, offset) faces give none.

    Parameters
    ----------
    solid : cadquery.Shape

    Returns
    -------
    directions : (m, 3) float64
        Unit vectors, in face order (a planar face's outward normal).
    areas : (m,) float64
    references : (m, 3) float64
        Each surface's own x direction (the first axis of its local
        coordinate system, perpendicular to the direction): it turns with
        the model and decides a frame's x where the model has one direction.
    planar : (m,) bool
        Which faces are planar.
    """
    from OCP.BRepAdaptor import BRepAdaptor_Surface
    from OCP.GeomAbs import (
        GeomAbs_Cone,
        GeomAbs_Cylinder,
        GeomAbs_Plane,
        GeomAbs_SurfaceOfExtrusion,
        GeomAbs_SurfaceOfRevolution,
        GeomAbs_Torus,
    )

    dirs, areas, refs, planar = [], [], [], []
    for face in solid.Faces():
        s = BRepAdaptor_Surface(face.wrapped)
        kind = s.GetType()
        if kind == GeomAbs_Plane:
            ax3 = s.Plane().Position()
        elif kind == GeomAbs_Cylinder:
            ax3 = s.Cylinder().Position()
        elif kind == GeomAbs_Cone:
            ax3 = s.Cone().Position()
        elif kind == GeomAbs_Torus:
            ax3 = s.Torus().Position()
        elif kind in (GeomAbs_SurfaceOfRevolution, GeomAbs_SurfaceOfExtrusion):
            d = (
                s.AxeOfRevolution().Direction()
                if kind == GeomAbs_SurfaceOfRevolution
                else s.Direction()
            )
            dirs.append((d.X(), d.Y(), d.Z()))
            areas.append(float(face.Area()))
            refs.append(np.full(3, np.nan))  # no frame of its own
            planar.append(False)
            continue
        else:
            continue
        d, x = ax3.Direction(), ax3.XDirection()
        if kind == GeomAbs_Plane:  # the outward normal: the face's orientation counts
            dirs.append(face.normalAt().toTuple())
        else:
            dirs.append((d.X(), d.Y(), d.Z()))
        refs.append((x.X(), x.Y(), x.Z()))
        areas.append(float(face.Area()))
        planar.append(kind == GeomAbs_Plane)
    return (
        np.array(dirs, dtype=np.float64).reshape(-1, 3),
        np.array(areas, dtype=np.float64),
        np.array(refs, dtype=np.float64).reshape(-1, 3),
        np.array(planar, dtype=bool),
    )


def line_directions(solid) -> tuple[np.ndarray, np.ndarray]:
    """The unit directions and lengths of a B-rep's straight edges.

    Parameters
    ----------
    solid : cadquery.Shape

    Returns
    -------
    directions : (m, 3) float64
    lengths : (m,) float64
    """
    dirs, lengths = [], []
    for e in solid.Edges():
        if e.geomType() != "LINE":
            continue
        d = np.subtract(e.endPoint().toTuple(), e.startPoint().toTuple())
        length = float(norm(d))
        if length > 0:
            dirs.append(d / length)
            lengths.append(length)
    return np.array(dirs, dtype=np.float64).reshape(-1, 3), np.array(lengths, dtype=np.float64)


def _parallel(a: np.ndarray, b: np.ndarray) -> bool:
    return float(norm(np.cross(a, b))) < TOL


def _groups(dirs, areas, refs, planar) -> list[tuple]:
    """Parallel directions as one, with their total area and reference x.

    A group points along its first axial face's axis (block_two_holes' holes
    point up as built), else away from its largest planar face (the face
    the model would rest on: a filleted box's bottom, not its smaller top;
    ties: the first in face order)."""
    out: list[list] = []
    for d, w, r, flat in zip(dirs, areas, refs, planar):
        for g in out:
            if _parallel(g[0], d):
                g[1] += float(w)
                if np.isnan(g[2]).any():
                    g[2] = r
                break
        else:
            g = [d, float(w), r, None, 0.0, None]
            out.append(g)
        if flat and w > g[4] * (1 + _WEIGHT_TIE):
            g[3], g[4] = -d, float(w)
        if not flat and g[5] is None:
            g[5] = d
    return [(g[5] if g[5] is not None else g[3], g[1], g[2]) for g in out]


def _aligned(axes: np.ndarray, groups) -> float:
    return sum(w for d, w, _ in groups if any(_parallel(a, d) for a in axes))


def _frames(groups, mirrors: np.ndarray):
    """Candidate frames (rows x, y, z): z a heaviest direction, x a
    direction perpendicular to it, or a mirror's normal perpendicular to it
    or that normal turned a quarter about z; for a model with no direction
    perpendicular to z, the x of z's first surface (a cylinder's seam
    side), else the world axis least along z, made perpendicular."""
    top = max(w for _, w, _ in groups)
    for z, w, ref in groups:
        if w < top * (1 - _WEIGHT_TIE):
            continue
        z = z / norm(z)
        across = [d for d, _, _ in groups if abs(float(dot(d, z))) < TOL]
        flat = [m for m in mirrors if abs(float(dot(m, z))) < TOL]
        across += flat + [np.cross(z, m) for m in flat]
        if not across and not np.isnan(ref).any() and abs(float(dot(ref, z))) < 1 - TOL:
            across = [ref]
        if not across:
            e = WORLD[int(np.argmin(np.abs(z)))]
            across = [e]
        for x in across:
            x = x - float(dot(x, z)) * z
            x = x / norm(x)
            yield np.array([x, np.cross(z, x), z])


def _before(a: tuple, b: tuple) -> bool:
    """Whether the key ``a`` ranks before ``b``: compared term by term, the
    larger first; its terms are counts and shares of the model's area or
    size, and shares within ``_WEIGHT_TIE`` are equal, so that no last bit
    decides."""
    for p, q in zip(a, b):
        if abs(p - q) > _WEIGHT_TIE:
            return p > q
    return False


def model_frame(solid) -> Frame:
    """The frame to scan a model in (module docstring).

    Parameters
    ----------
    solid : cadquery.Shape

    Returns
    -------
    Frame

    Examples
    --------
    >>> import cadquery as cq
    >>> box = cq.Workplane().box(2, 1, 0.5).val()
    >>> model_frame(box).world
    True
    >>> turned = box.rotate((0, 0, 0), (1, 1, 0), 30)
    >>> f = model_frame(turned)
    >>> f.world, round(f.aligned, 6), round(f.world_aligned, 6)
    (False, 1.0, 0.0)
    """
    dirs, areas, refs, planar = surface_directions(solid)
    total = float(sum(f.Area() for f in solid.Faces()))
    if areas.shape[0] == 0 or total <= 0:
        return Frame(WORLD.copy(), 0.0, 0.0)
    groups = _groups(dirs, areas, refs, planar)
    world = _aligned(WORLD, groups)
    mirrors = mirror_normals(solid)
    line_dirs, line_len = line_directions(solid)
    centre = np.asarray(solid.Center().toTuple(), dtype=np.float64)
    size = float(norm(np.subtract(*exact_bounds(solid)[::-1])))
    best, best_key = None, None
    for axes in _frames(groups, mirrors):
        lo, hi = exact_bounds(in_frame(solid, axes))
        c = axes @ centre
        # more mirrors kept; more area lined up; more length of straight
        # edges lined up; the longest along x: the same for the frame turned
        # half about z (x and y reversed, its bounds the mirror of these)
        along = np.abs(line_dirs @ axes.T).max(axis=1) >= 1.0 - TOL
        head = (
            respected(axes, mirrors),
            _aligned(axes, groups) / total,
            float(line_len[along].sum()) / size,
            float(hi[0] - lo[0]) / size,
        )
        # then the model reaching farther along +y, then +x, from its centre
        # of mass (which of the two half turns); then the first
        reach = ((hi - c) - (c - lo))[:2] / size
        for sign in (1.0, -1.0):
            key = (*head, float(sign * reach[1]), float(sign * reach[0]))
            if best_key is None or _before(key, best_key):
                best, best_key = axes * np.array([[sign], [sign], [1.0]]), key
    share = best_key[1] if best_key is not None else 0.0
    if best is None or share < (world + SWITCH * total) / total:
        return Frame(WORLD.copy(), world / total, world / total)
    return Frame(best, share, world / total)


def in_frame(solid, axes: np.ndarray):
    """The model in frame coordinates: every point ``p`` goes to ``axes @ p``.

    Parameters
    ----------
    solid : cadquery.Shape
    axes : (3, 3) array_like
        A rotation (rows: the frame's axes in world coordinates).

    Returns
    -------
    cadquery.Shape
        A transformed copy (faces in the same order).
    """
    import cadquery as cq
    from OCP.BRepBuilderAPI import BRepBuilderAPI_Transform
    from OCP.gp import gp_Trsf

    r = np.asarray(axes, dtype=np.float64)
    trsf = gp_Trsf()
    trsf.SetValues(*r[0], 0.0, *r[1], 0.0, *r[2], 0.0)
    return cq.Shape.cast(BRepBuilderAPI_Transform(solid.wrapped, trsf, True).Shape())


__all__ = [
    "Frame",
    "SWITCH",
    "TOL",
    "in_frame",
    "line_directions",
    "model_frame",
    "surface_directions",
]
