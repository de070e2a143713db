"""Parametric CAD shapes with sharp features, and their ground truth.

Fourteen shapes built with CadQuery: the five of the paper (``L_sheet``,
``cone``, ``conebox``, ``cube``, ``cutcube``) and nine more covering through
holes, higher genus, apexes where several sharp edges meet, acute and obtuse
dihedral edges, reflex edges, fillets (smooth-to-sharp transitions) and an
isolated sharp point.  :func:`build` returns a :class:`Shape` record holding

* the CadQuery object (``solid``) and the full parameter set used;
* the topology the surface must have (``expected``), computed from the
  B-rep itself, not typed in: components and boundary loops from the
  face/edge adjacency, the Euler characteristic from the cell structure
  ``V - E + sum over faces of (2 - number of wires)`` (degenerate edges at
  apexes and poles left out, seam edges counted once), orientability from
  the edge orientations, genus from the three;
* a watertight ground-truth triangle mesh (OCC tessellation, coincident
  vertices merged), whose own Euler characteristic is checked against
  ``expected`` when the shape is built;
* the surface area, bounding-box diagonal and a default scan-line spacing.

CadQuery (and OCP) are imported only when a shape is built, so importing
this module needs numpy alone.

Examples
--------
>>> from sr33.samplers.shapes import describe, shape_parameters
>>> shape_parameters("cube")
{'side': 1.0}
>>> describe("cube")
'cube: 8 corners where 3 sharp edges meet, 12 sharp edges of 90 degrees'
"""

from __future__ import annotations

import math
import os
import sys
from collections.abc import Callable
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from sr33.mesh import edge_uses, half_edges, norm, unique_rows

MESH_TOLERANCE = 1.0 / 500.0  # linear deflection of the truth mesh, times the size
MESH_ANGULAR = 0.1  # angular deflection of the truth mesh, radians
MERGE_TOLERANCE = 1e-7  # vertices closer than this (times the size) are merged
TARGET_SAMPLES = 6000  # default spacing h: area / h**2 is about this
SCOOP_CENTRE = 0.6  # cutcube's scoop sphere is centred at SCOOP_CENTRE * side * (1, 1, 1)
NICE_MANTISSAS = (1.0, 1.2, 1.5, 2.0, 2.5, 3.0, 4.0, 5.0, 6.0, 8.0)


class ShapeError(ValueError):
    """Bad shape name or parameters: the message names the parameter, the rule and the value."""


@dataclass(frozen=True)
class Topology:
    """Topological type of a surface.

    Attributes
    ----------
    components : int
        Connected components.
    euler : int
        Euler characteristic.
    genus : int
        Genus (handles) of an orientable surface,
        ``(2 * components - euler - boundary_loops) / 2``; for a non-orientable
        one, the number of cross-caps ``2 * components - euler - boundary_loops``.
    boundary_loops : int
        Closed boundary curves (0 for the boundary of a solid).
    orientable : bool
        Whether the surface is (consistently) orientable.
    """

    components: int
    euler: int
    genus: int
    boundary_loops: int
    orientable: bool


@dataclass(frozen=True, eq=False)
class Shape:
    """A built CAD shape with its expected topology and ground-truth mesh.

    Attributes
    ----------
    name : str
        Shape name: one of :func:`shape_names`, or a CAD model's (:func:`from_cad`).
    solid : cadquery.Solid or cadquery.Shell
        The CadQuery object (a solid, or an open shell for ``L_sheet``).
    params : dict of str to float
        Full parameter set used (defaults filled in).
    expected : Topology
        Topology of the surface, computed from the B-rep.
    truth_vertices : (v, 3) float64 ndarray
        Vertices of the ground-truth mesh (read-only).
    truth_triangles : (t, 3) int64 ndarray
        Triangles of the ground-truth mesh, consistently oriented (outward
        normals for solids); every vertex is used (read-only).
    size : float
        Diagonal of the exact bounding box.
    default_spacing : float
        Scan-line spacing h with ``area / h**2`` about 6,000, rounded to a
        value 1, 1.2, 1.5, 2, 2.5, 3, 4, 5, 6 or 8 times a power of ten.
    area : float
        Surface area of the B-rep.
    """

    name: str
    solid: Any
    params: dict[str, float]
    expected: Topology
    truth_vertices: np.ndarray
    truth_triangles: np.ndarray
    size: float
    default_spacing: float
    area: float

    def __repr__(self) -> str:
        return (
            f"Shape(name={self.name!r}, params={self.params!r}, expected={self.expected!r}, "
            f"truth={self.truth_vertices.shape[0]} vertices/"
            f"{self.truth_triangles.shape[0]} triangles, size={self.size:.6g}, "
            f"area={self.area:.6g}, default_spacing={self.default_spacing:g})"
        )


# ---------------------------------------------------------------------------
# parameter checks


def _fmt(x: float) -> str:
    """Short printed form of a number (``0.5``, ``1``, ``0.385``)."""
    return f"{x:g}"


def _require(ok: bool, message: str) -> None:
    if not ok:
        raise ShapeError(message)


def _positive(p: dict[str, float], *names: str) -> None:
    for n in names:
        _require(p[n] > 0, f"{n} must be positive, got {_fmt(p[n])}")


def _less(p: dict[str, float], name: str, limit: float, what: str) -> None:
    """Require ``p[name] < limit``; ``what`` describes the limit in words."""
    _require(
        p[name] < limit,
        f"{name} must be less than {what} ({_fmt(limit)}), got {_fmt(p[name])}",
    )


def _between(p: dict[str, float], name: str, lo: float, hi: float, unit: str) -> None:
    _require(
        lo <= p[name] <= hi,
        f"{name} must be between {_fmt(lo)} and {_fmt(hi)} {unit}, got {_fmt(p[name])}",
    )


def _smaller_side(p: dict[str, float], a: str, b: str) -> tuple[str, float]:
    """Name and length of the smaller of two box sides (``b`` on ties)."""
    return (a, p[a]) if p[a] < p[b] else (b, p[b])


# ---------------------------------------------------------------------------
# CadQuery helpers (cadquery imported lazily)


def _single_solid(shape):
    """The one solid of a boolean result (cleaned: coplanar faces merged)."""
    import cadquery as cq

    solids = shape.clean().Solids()
    if len(solids) != 1:
        raise ShapeError(f"the parameters give {len(solids)} solids instead of one")
    return cq.Solid(solids[0].wrapped)


def _polygon_face(points):
    import cadquery as cq

    wire = cq.Wire.makePolygon([cq.Vector(*map(float, q)) for q in points], close=True)
    return cq.Face.makeFromWires(wire)


def _chain(edges):
    """Wire of consecutive edges, each joined to the wire built so far.

    ``cadquery.Wire.assembleEdges`` hands OCC the edges all at once, and which
    of two nearly coincident end vertices survives then depends on memory
    addresses: the solid would differ in the last bit from one build to the next.
    """
    import cadquery as cq
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeWire

    builder = BRepBuilderAPI_MakeWire()
    for edge in edges:
        builder.Add(edge.wrapped)
    if not builder.IsDone():
        raise ShapeError(f"the profile edges do not form a wire (OCC error {builder.Error()})")
    return cq.Wire(builder.Wire())


def _prism(polygon_xy, height: float):
    """Right prism over a planar polygon (xy, counter-clockwise), z from -h/2 to h/2."""
    import cadquery as cq

    face = _polygon_face([(x, y, -height / 2) for x, y in polygon_xy])
    return cq.Solid.extrudeLinear(face, cq.Vector(0, 0, height))


def _make_L_sheet(p):
    import cadquery as cq

    w, a, b = p["width"], p["length_a"], p["length_b"]
    t = math.radians(p["angle"])
    d = (b * math.cos(t), 0.0, b * math.sin(t))
    face_a = _polygon_face([(0, 0, 0), (a, 0, 0), (a, w, 0), (0, w, 0)])
    face_b = _polygon_face([(0, 0, 0), (0, w, 0), (d[0], w, d[2]), (d[0], 0, d[2])])
    shell = cq.Shell.makeShell([face_a, face_b])
    if shell.wrapped.ShapeType().name != "TopAbs_SHELL":
        shells = shell.Shells()
        _require(len(shells) == 1, "the two sheets of L_sheet could not be sewn together")
        shell = shells[0]
    return cq.Shell(shell.wrapped)


def _make_cone(p):
    import cadquery as cq

    h = p["height"]
    return cq.Solid.makeCone(p["radius"], 0.0, h, pnt=cq.Vector(0, 0, -h / 2))


def _make_conebox(p):
    import cadquery as cq

    lx, ly, lz = p["length"], p["width"], p["height"]
    box = cq.Solid.makeBox(lx, ly, lz, pnt=cq.Vector(-lx / 2, -ly / 2, -lz / 2))
    cone = cq.Solid.makeCone(p["cone_radius"], 0.0, p["cone_height"], pnt=cq.Vector(0, 0, lz / 2))
    return _single_solid(box.fuse(cone))


def _make_cube(p):
    import cadquery as cq

    s = p["side"]
    return cq.Solid.makeBox(s, s, s, pnt=cq.Vector(-s / 2, -s / 2, -s / 2))


def _make_cutcube(p):
    import cadquery as cq

    s = p["side"]
    cube = cq.Solid.makeBox(s, s, s, pnt=cq.Vector(-s / 2, -s / 2, -s / 2))
    hole = cq.Solid.makeCylinder(
        p["hole_radius"], 2 * s, pnt=cq.Vector(0, -s, 0), dir=cq.Vector(0, 1, 0)
    )
    c = SCOOP_CENTRE * s
    scoop = cq.Solid.makeSphere(p["scoop_radius"], pnt=cq.Vector(c, c, c), angleDegrees1=-90)
    return _single_solid(cube.cut(hole).cut(scoop))


def _make_box_hole(p):
    import cadquery as cq

    lx, ly, lz = p["length"], p["width"], p["height"]
    box = cq.Solid.makeBox(lx, ly, lz, pnt=cq.Vector(-lx / 2, -ly / 2, -lz / 2))
    hole = cq.Solid.makeCylinder(p["hole_radius"], 2 * lz, pnt=cq.Vector(0, 0, -lz))
    return _single_solid(box.cut(hole))


def _make_block_two_holes(p):
    import cadquery as cq

    lx, ly, lz = p["length"], p["width"], p["height"]
    out = cq.Solid.makeBox(lx, ly, lz, pnt=cq.Vector(-lx / 2, -ly / 2, -lz / 2))
    for x in (-lx / 4, lx / 4):
        out = out.cut(cq.Solid.makeCylinder(p["hole_radius"], 2 * lz, pnt=cq.Vector(x, 0, -lz)))
    return _single_solid(out)


def _make_pyramid(p):
    import cadquery as cq

    a, h = p["base"] / 2, p["height"]
    z0 = -h / 2
    base = [(-a, -a, z0), (a, -a, z0), (a, a, z0), (-a, a, z0)]
    apex = (0.0, 0.0, h / 2)
    faces = [_polygon_face(base[::-1])]
    faces += [_polygon_face([base[i], base[(i + 1) % 4], apex]) for i in range(4)]
    solid = cq.Solid.makeSolid(cq.Shell.makeShell(faces))
    return cq.Solid(solid.wrapped)


def _make_wedge(p):
    t = math.radians(p["angle"]) / 2
    r = p["length"]
    x = r * math.cos(t)
    y = r * math.sin(t)
    # apex edge along z through (-x/2, 0); the opposite face at x/2
    return _prism([(-x / 2, 0.0), (x / 2, -y), (x / 2, y)], p["depth"])


def _make_cylinder(p):
    import cadquery as cq

    h = p["height"]
    return cq.Solid.makeCylinder(p["radius"], h, pnt=cq.Vector(0, 0, -h / 2))


def _make_sphere(p):
    import cadquery as cq

    return cq.Solid.makeSphere(p["radius"], angleDegrees1=-90, angleDegrees2=90)


def _make_torus(p):
    import cadquery as cq

    return cq.Solid.makeTorus(p["major_radius"], p["minor_radius"])


def _make_star_prism(p):
    ro, ri = p["outer_radius"], p["inner_radius"]
    pts = []
    for k in range(10):
        r = ro if k % 2 == 0 else ri
        t = math.pi / 2 + k * math.pi / 5
        pts.append((r * math.cos(t), r * math.sin(t)))
    return _prism(pts, p["height"])


def _make_hexagonal_prism(p):
    r = p["radius"]
    pts = [(r * math.cos(k * math.pi / 3), r * math.sin(k * math.pi / 3)) for k in range(6)]
    return _prism(pts, p["height"])


def _make_fillet_box(p):
    import cadquery as cq

    lx, ly, lz = p["length"], p["width"], p["height"]
    box = cq.Solid.makeBox(lx, ly, lz, pnt=cq.Vector(-lx / 2, -ly / 2, -lz / 2))
    # vertical edges and top edges, in a fixed order (CadQuery's selectors return
    # sets, whose order would make the fillet's parametrisation vary run to run)
    edges = [
        e
        for e in box.Edges()
        if e.Center().z > 0.25 * lz or abs(e.startPoint().z - e.endPoint().z) > 0.5 * lz
    ]
    edges.sort(key=lambda e: tuple(round(c, 9) for c in e.Center().toTuple()))
    try:
        solid = box.fillet(p["fillet_radius"], edges)
    except Exception as exc:  # OCC StdFail_NotDone and friends
        raise ShapeError(
            f"fillet_radius {_fmt(p['fillet_radius'])} could not be applied: {exc}"
        ) from exc
    return cq.Solid(solid.wrapped)


def _make_cone_tip(p):
    import cadquery as cq

    r, d = p["radius"], p["apex_height"]
    s = r / d  # sine of the cone's half-angle at the apex
    mid = -math.pi / 4 + math.asin(s) / 2  # halfway from the tangent circle to the pole
    apex = cq.Vector(0.0, 0.0, d)
    tangent = cq.Vector(r * math.sqrt(1.0 - s * s), 0.0, r * s)
    pole = cq.Vector(0.0, 0.0, -r)
    # profile in the xz half-plane x >= 0; edges joined one at a time, see _chain
    profile = _chain(
        [
            cq.Edge.makeLine(apex, tangent),
            cq.Edge.makeThreePointArc(
                tangent, cq.Vector(r * math.cos(mid), 0.0, r * math.sin(mid)), pole
            ),
            cq.Edge.makeLine(pole, apex),
        ]
    )
    return cq.Solid.revolve(profile, [], 360.0, cq.Vector(0, 0, 0), cq.Vector(0, 0, 1))


def _make_square_ring(p):
    import cadquery as cq

    r, a = p["radius"], p["section"]
    outer = cq.Solid.makeCylinder(r + a / 2, a, pnt=cq.Vector(0, 0, -a / 2))
    inner = cq.Solid.makeCylinder(r - a / 2, 2 * a, pnt=cq.Vector(0, 0, -a))
    return _single_solid(outer.cut(inner))


# ---------------------------------------------------------------------------
# validation rules


def _check_L_sheet(p):
    _positive(p, "width", "length_a", "length_b")
    _between(p, "angle", 5, 175, "degrees")


def _check_cone(p):
    _positive(p, "radius", "height")


def _check_conebox(p):
    _positive(p, "length", "width", "height", "cone_radius", "cone_height")
    side, value = _smaller_side(p, "length", "width")
    _less(p, "cone_radius", value / 2, f"half the box {side}")


def _check_cube(p):
    _positive(p, "side")


def _check_cutcube(p):
    _positive(p, "side", "hole_radius", "scoop_radius")
    s = p["side"]
    _less(p, "hole_radius", s / 2, "half the side")
    _require(
        p["scoop_radius"] > 0.2 * s,
        f"scoop_radius must be greater than 0.2 times the side ({_fmt(0.2 * s)}) "
        f"to cut the corner, got {_fmt(p['scoop_radius'])}",
    )
    total = p["scoop_radius"] + p["hole_radius"]
    _require(
        total < 0.8 * s,
        f"scoop_radius + hole_radius must be less than 0.8 times the side ({_fmt(0.8 * s)}) "
        f"to keep the scoop off the hole, got {_fmt(total)}",
    )


def _check_box_hole(p):
    _positive(p, "length", "width", "height", "hole_radius")
    side, value = _smaller_side(p, "length", "width")
    _less(p, "hole_radius", value / 2, f"half the block {side}")


def _check_block_two_holes(p):
    _positive(p, "length", "width", "height", "hole_radius")
    _less(p, "hole_radius", p["width"] / 2, "half the block width")
    _less(p, "hole_radius", p["length"] / 4, "a quarter of the block length")


def _check_pyramid(p):
    _positive(p, "base", "height")


def _check_wedge(p):
    _positive(p, "length", "depth")
    _between(p, "angle", 5, 175, "degrees")


def _check_cylinder(p):
    _positive(p, "radius", "height")


def _check_sphere(p):
    _positive(p, "radius")


def _check_torus(p):
    _positive(p, "major_radius", "minor_radius")
    _less(p, "minor_radius", p["major_radius"], "major_radius")


def _check_star_prism(p):
    _positive(p, "outer_radius", "inner_radius", "height")
    _less(p, "inner_radius", p["outer_radius"], "outer_radius")


def _check_hexagonal_prism(p):
    _positive(p, "radius", "height")


def _check_fillet_box(p):
    _positive(p, "length", "width", "height", "fillet_radius")
    smallest = min(p["length"], p["width"], p["height"])
    _less(p, "fillet_radius", smallest / 2, "half the smallest side")


def _check_cone_tip(p):
    _positive(p, "radius", "apex_height")
    _require(
        p["apex_height"] > 1.1 * p["radius"],
        f"apex_height must be greater than 1.1 times the radius ({_fmt(1.1 * p['radius'])}), "
        f"got {_fmt(p['apex_height'])}",
    )


def _check_square_ring(p):
    _positive(p, "radius", "section")
    _less(p, "section", 2 * p["radius"], "twice the radius")


@dataclass(frozen=True)
class _Spec:
    description: str
    defaults: dict[str, float]
    check: Callable[[dict[str, float]], None]
    make: Callable[[dict[str, float]], Any]


_SPECS: dict[str, _Spec] = {
    "L_sheet": _Spec(
        "open L-shaped sheet: two rectangles (width x length_a, width x length_b) meeting "
        "at a sharp fold of the given angle in degrees; a disk with one boundary loop",
        {"width": 1.0, "length_a": 1.0, "length_b": 1.0, "angle": 90.0},
        _check_L_sheet,
        _make_L_sheet,
    ),
    "cone": _Spec(
        "cone with its base disk: sharp apex and a sharp circular edge "
        "(default proportions of the paper's cone: 72-degree rim, 37-degree apex)",
        {"radius": 0.5, "height": 1.5},
        _check_cone,
        _make_cone,
    ),
    "conebox": _Spec(
        "box with a cone standing on its top face, fused into one solid",
        {"length": 1.0, "width": 1.0, "height": 0.5, "cone_radius": 0.35, "cone_height": 0.6},
        _check_conebox,
        _make_conebox,
    ),
    "cube": _Spec(
        "cube: 8 corners where 3 sharp edges meet, 12 sharp edges of 90 degrees",
        {"side": 1.0},
        _check_cube,
        _make_cube,
    ),
    "cutcube": _Spec(
        "cube [-s/2, s/2]^3 with a cylindrical through-hole along y and a spherical scoop "
        "(centre 0.6 s (1, 1, 1)) cut off the corner (s/2, s/2, s/2); genus 1",
        {"side": 1.0, "hole_radius": 0.2, "scoop_radius": 0.45},
        _check_cutcube,
        _make_cutcube,
    ),
    "box_hole": _Spec(
        "box with one cylindrical through-hole along z; genus 1",
        {"length": 1.0, "width": 1.0, "height": 0.5, "hole_radius": 0.25},
        _check_box_hole,
        _make_box_hole,
    ),
    "block_two_holes": _Spec(
        "block with two cylindrical through-holes along z at x = -length/4 and length/4; genus 2",
        {"length": 2.0, "width": 1.0, "height": 0.5, "hole_radius": 0.25},
        _check_block_two_holes,
        _make_block_two_holes,
    ),
    "pyramid": _Spec(
        "square pyramid: an apex where 4 sharp edges meet",
        {"base": 1.0, "height": 0.5},
        _check_pyramid,
        _make_pyramid,
    ),
    "wedge": _Spec(
        "triangular prism whose apex edge has the given dihedral angle in degrees",
        {"angle": 30.0, "length": 1.0, "depth": 1.0},
        _check_wedge,
        _make_wedge,
    ),
    "cylinder": _Spec(
        "closed cylinder: two sharp circular edges",
        {"radius": 0.5, "height": 1.0},
        _check_cylinder,
        _make_cylinder,
    ),
    "sphere": _Spec(
        "ball: one smooth closed face with two poles, no feature at all (Theorem 2's case)",
        {"radius": 0.5},
        _check_sphere,
        _make_sphere,
    ),
    "torus": _Spec(
        "torus: the tube of the given minor radius round a circle of the major radius; "
        "smooth, genus 1",
        {"major_radius": 0.5, "minor_radius": 0.2},
        _check_torus,
        _make_torus,
    ),
    "star_prism": _Spec(
        "5-pointed star extruded along z: convex and reflex sharp edges",
        {"outer_radius": 0.6, "inner_radius": 0.25, "height": 0.3},
        _check_star_prism,
        _make_star_prism,
    ),
    "hexagonal_prism": _Spec(
        "regular hexagon (corners at the given radius, two on the x axis) extruded "
        "along z: 120-degree side edges, two side faces parallel to the x axis",
        {"radius": 0.5, "height": 0.5},
        _check_hexagonal_prism,
        _make_hexagonal_prism,
    ),
    "fillet_box": _Spec(
        "box with its vertical and top edges filleted: smooth blends ending on sharp bottom "
        "edges (smooth-to-sharp transitions)",
        {"length": 1.0, "width": 0.8, "height": 0.6, "fillet_radius": 0.15},
        _check_fillet_box,
        _make_fillet_box,
    ),
    "cone_tip": _Spec(
        "ball of the given radius with a tangent cone whose apex is apex_height above the "
        "ball's centre, revolved from a profile: an isolated sharp point",
        {"radius": 0.35, "apex_height": 1.0},
        _check_cone_tip,
        _make_cone_tip,
    ),
    "square_ring": _Spec(
        "ring with a square cross-section (side section) around a circle of the given "
        "radius: genus 1, 4 sharp circular edges",
        {"radius": 0.4, "section": 0.2},
        _check_square_ring,
        _make_square_ring,
    ),
}


# ---------------------------------------------------------------------------
# public lookups


def shape_names() -> list[str]:
    """Names of the shapes :func:`build` knows, sorted case-insensitively.

    Returns
    -------
    list of str

    Examples
    --------
    >>> names = shape_names()
    >>> len(names), names[:3]
    (17, ['block_two_holes', 'box_hole', 'cone'])
    """
    return sorted(_SPECS, key=str.lower)


def _spec(name: str) -> _Spec:
    if not isinstance(name, str) or name not in _SPECS:
        raise ShapeError(f"unknown shape {name!r}; known shapes: {', '.join(shape_names())}")
    return _SPECS[name]


def shape_parameters(name: str) -> dict[str, float]:
    """Default parameters of a shape.

    Parameters
    ----------
    name : str
        Shape name.

    Returns
    -------
    dict of str to float
        A fresh copy of the defaults.

    Raises
    ------
    ShapeError
        For an unknown name.

    Examples
    --------
    >>> shape_parameters("wedge")
    {'angle': 30.0, 'length': 1.0, 'depth': 1.0}
    """
    return dict(_spec(name).defaults)


def describe(name: str) -> str:
    """One-line description of a shape.

    Parameters
    ----------
    name : str
        Shape name.

    Returns
    -------
    str

    Raises
    ------
    ShapeError
        For an unknown name.
    """
    return _spec(name).description


PARAM_RANGE = (1e-4, 1e6)  # magnitudes OpenCascade's 1e-7 precision models faithfully


#: every shape also takes these: degrees about the world's x, y and z axes
#: (through the origin), applied in that order after the shape is built;
#: they appear in ``Shape.params`` only when not 0
ROTATIONS = ("rotate_x", "rotate_y", "rotate_z")


def _resolve(name: str, params: dict[str, Any]) -> dict[str, float]:
    spec = _spec(name)
    unknown = sorted(set(params) - set(spec.defaults) - set(ROTATIONS))
    if unknown:
        raise ShapeError(
            f"unknown parameter{'s' if len(unknown) > 1 else ''} "
            f"{', '.join(repr(u) for u in unknown)} for shape {name!r}; "
            f"allowed: {', '.join((*spec.defaults, *ROTATIONS))}"
        )
    out = dict(spec.defaults)
    for key, value in params.items():
        if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
            raise ShapeError(f"{key} must be a number, got {value!r}")
        if not math.isfinite(float(value)):
            raise ShapeError(f"{key} must be finite, got {value!r}")
        if key in ROTATIONS:
            if not -360.0 <= float(value) <= 360.0:
                raise ShapeError(f"{key} must be within [-360, 360] degrees, got {value!r}")
            if value != 0:
                out[key] = float(value)
            continue
        if not (value == 0 or PARAM_RANGE[0] <= abs(float(value)) <= PARAM_RANGE[1]):
            raise ShapeError(
                f"{key} must be 0 or of magnitude {_fmt(PARAM_RANGE[0])} to "
                f"{_fmt(PARAM_RANGE[1])}, got {value!r} (OpenCascade models to an absolute "
                "precision of 1e-7: build at unit scale and scale the samples)"
            )
        out[key] = float(value)
    spec.check(out)
    return out


# ---------------------------------------------------------------------------
# topology of a B-rep


def brep_topology(solid) -> Topology:
    """Topological type of the boundary surface of a CadQuery shape, from its B-rep.

    Parameters
    ----------
    solid : cadquery.Shape
        A solid, shell, face or compound.

    Returns
    -------
    Topology
        Components: faces connected through shared edges.  Boundary loops:
        connected chains of free edges (edges with a single face use; a seam
        edge is used twice by its face).  Euler characteristic:
        ``V - E + sum over faces of (2 - wires)``, which counts each face as
        the planar domain it is once cut along its seams; degenerate edges
        (apexes, poles) are left out.  Orientable: every edge used twice is
        used once in each direction.  Genus from
        ``2 - 2 g = euler + boundary_loops`` per component.

    Raises
    ------
    ShapeError
        When an edge is used by more than two faces (non-manifold model).
    """
    from OCP.BRep import BRep_Tool
    from OCP.TopAbs import TopAbs_EDGE, TopAbs_FACE, TopAbs_FORWARD, TopAbs_VERTEX, TopAbs_WIRE
    from OCP.TopExp import TopExp, TopExp_Explorer
    from OCP.TopoDS import TopoDS
    from OCP.TopTools import TopTools_IndexedMapOfShape

    occ = solid.wrapped
    vmap, emap, fmap = (TopTools_IndexedMapOfShape() for _ in range(3))
    TopExp.MapShapes_s(occ, TopAbs_VERTEX, vmap)
    TopExp.MapShapes_s(occ, TopAbs_EDGE, emap)
    TopExp.MapShapes_s(occ, TopAbs_FACE, fmap)
    n_edges = emap.Extent()
    degenerate = [
        BRep_Tool.Degenerated_s(TopoDS.Edge_s(emap.FindKey(i + 1))) for i in range(n_edges)
    ]

    uses: list[list[tuple[int, bool]]] = [[] for _ in range(n_edges)]  # (face, forward)
    chi_faces = 0
    seen_faces: set[int] = set()
    fexp = TopExp_Explorer(occ, TopAbs_FACE)
    while fexp.More():
        face = fexp.Current()
        fexp.Next()
        fi = fmap.FindIndex(face) - 1
        if fi in seen_faces:
            continue
        seen_faces.add(fi)
        wires = 0
        wexp = TopExp_Explorer(face, TopAbs_WIRE)
        while wexp.More():
            wires += 1
            wexp.Next()
        chi_faces += 2 - wires
        eexp = TopExp_Explorer(face, TopAbs_EDGE)
        while eexp.More():
            edge = eexp.Current()
            eexp.Next()
            ei = emap.FindIndex(edge) - 1
            if not degenerate[ei]:
                uses[ei].append((fi, edge.Orientation() == TopAbs_FORWARD))

    n_faces = fmap.Extent()
    parent = list(range(max(n_faces, vmap.Extent())))

    def find(i: int) -> int:
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    orientable = True
    free: list[int] = []
    for ei, u in enumerate(uses):
        if degenerate[ei]:
            continue
        if len(u) > 2:
            raise ShapeError(f"the model is not a manifold: an edge has {len(u)} face uses")
        if len(u) == 1:
            free.append(ei)
        elif len(u) == 2:
            if u[0][1] == u[1][1]:
                orientable = False
            parent[find(u[0][0])] = find(u[1][0])
    components = len({find(f) for f in range(n_faces)})

    parent = list(range(vmap.Extent()))
    loop_vertices = set()
    for ei in free:
        edge = TopoDS.Edge_s(emap.FindKey(ei + 1))
        a = vmap.FindIndex(TopExp.FirstVertex_s(edge)) - 1
        b = vmap.FindIndex(TopExp.LastVertex_s(edge)) - 1
        parent[find(a)] = find(b)
        loop_vertices.update((a, b))
    boundary_loops = len({find(v) for v in loop_vertices})

    euler = vmap.Extent() - (n_edges - sum(degenerate)) + chi_faces
    twice_genus = 2 * components - euler - boundary_loops
    return Topology(
        components=components,
        euler=euler,
        genus=twice_genus // 2 if orientable else twice_genus,
        boundary_loops=boundary_loops,
        orientable=orientable,
    )


# ---------------------------------------------------------------------------
# ground-truth mesh


def _tessellate(solid, deflection: float, angular: float) -> tuple[np.ndarray, np.ndarray]:
    """Per-face OCC triangulation of a copy of ``solid``, faces' vertices not merged.

    Like ``cadquery.Shape.tessellate`` but with an absolute linear deflection
    (CadQuery asks OCC for a deflection relative to each edge's size) and
    sequential meshing; triangles of reversed faces are flipped so normals
    point out of a solid.
    """
    from OCP.BRep import BRep_Tool
    from OCP.BRepMesh import BRepMesh_IncrementalMesh
    from OCP.TopAbs import TopAbs_FACE, TopAbs_REVERSED
    from OCP.TopExp import TopExp
    from OCP.TopLoc import TopLoc_Location
    from OCP.TopoDS import TopoDS
    from OCP.TopTools import TopTools_IndexedMapOfShape

    occ = solid.copy().wrapped
    BRepMesh_IncrementalMesh(occ, deflection, False, angular, False)
    fmap = TopTools_IndexedMapOfShape()
    TopExp.MapShapes_s(occ, TopAbs_FACE, fmap)
    verts: list[np.ndarray] = []
    tris: list[np.ndarray] = []
    offset = 0
    for i in range(1, fmap.Extent() + 1):
        face = TopoDS.Face_s(fmap.FindKey(i))
        loc = TopLoc_Location()
        poly = BRep_Tool.Triangulation_s(face, loc)
        if poly is None:
            raise ShapeError(f"OCC could not mesh face {i} of {type(solid).__name__}")
        trsf = loc.Transformation()
        nodes = [poly.Node(j).Transformed(trsf) for j in range(1, poly.NbNodes() + 1)]
        verts.append(np.array([(q.X(), q.Y(), q.Z()) for q in nodes], dtype=np.float64))
        tri = np.array(
            [poly.Triangle(j).Get() for j in range(1, poly.NbTriangles() + 1)], dtype=np.int64
        ).reshape(-1, 3)
        if face.Orientation() == TopAbs_REVERSED:
            tri = tri[:, ::-1]
        tris.append(tri - 1 + offset)
        offset += poly.NbNodes()
    return np.concatenate(verts).reshape(-1, 3), np.concatenate(tris).reshape(-1, 3)


def _truth_mesh(solid, size: float) -> tuple[np.ndarray, np.ndarray]:
    """Tessellate ``solid`` and merge the per-face vertex lists into one watertight mesh."""
    from scipy.spatial import cKDTree

    v, t = _tessellate(solid, MESH_TOLERANCE * size, MESH_ANGULAR)

    # merge coincident vertices: union-find over close pairs, representative = smallest index
    pairs = cKDTree(v).query_pairs(MERGE_TOLERANCE * size, output_type="ndarray")
    rep = np.arange(v.shape[0])
    if pairs.shape[0]:
        parent = np.arange(v.shape[0])

        def find(i: int) -> int:
            while parent[i] != i:
                parent[i] = parent[parent[i]]
                i = parent[i]
            return i

        for a, b in pairs[np.lexsort((pairs[:, 1], pairs[:, 0]))]:
            ra, rb = find(int(a)), find(int(b))
            if ra != rb:
                parent[max(ra, rb)] = min(ra, rb)
        rep = np.array([find(i) for i in range(v.shape[0])])
    t = rep[t]
    t = t[(t[:, 0] != t[:, 1]) & (t[:, 1] != t[:, 2]) & (t[:, 2] != t[:, 0])]
    used, inverse = np.unique(t, return_inverse=True)
    return np.ascontiguousarray(v[used]), inverse.reshape(-1, 3).astype(np.int64)


def _mesh_problem(tri: np.ndarray, expected: Topology) -> str | None:
    """Why the truth mesh does not fit ``expected``, or None."""
    directed = half_edges(tri)[0]
    if unique_rows(directed).shape[0] < directed.shape[0]:
        return "an edge is used twice in the same direction"
    _, counts = edge_uses(tri)
    if np.any(counts > 2):
        return f"{int(np.sum(counts > 2))} edges are used by more than two triangles"
    if expected.boundary_loops == 0 and np.any(counts == 1):
        return f"{int(np.sum(counts == 1))} open edges on a closed surface"
    euler = int(np.unique(tri).shape[0] - counts.shape[0] + tri.shape[0])
    if euler != expected.euler:
        return f"Euler characteristic {euler}, expected {expected.euler}"
    return None


def _nice(x: float) -> float:
    """The value m * 10**k (m in NICE_MANTISSAS) nearest to x on a log scale."""
    k = math.floor(math.log10(x))
    best = min(
        (m * 10.0**e for e in (k - 1, k, k + 1) for m in NICE_MANTISSAS),
        key=lambda c: abs(math.log(c / x)),
    )
    return float(f"{best:.12g}")


def _exact_size(solid) -> float:
    from OCP.Bnd import Bnd_Box
    from OCP.BRepBndLib import BRepBndLib

    box = Bnd_Box()
    BRepBndLib.AddOptimal_s(solid.wrapped, box, False, False)
    lo = np.array(box.Get()[:3])
    hi = np.array(box.Get()[3:])
    return float(norm(hi - lo))


# ---------------------------------------------------------------------------
# build


def build(name: str, **params: float) -> Shape:
    """Build a shape with its expected topology and ground-truth mesh.

    Parameters
    ----------
    name : str
        One of :func:`shape_names`.
    **params : float
        Parameters overriding the defaults of :func:`shape_parameters`, and
        ``rotate_x``, ``rotate_y``, ``rotate_z`` (degrees, default 0; see
        :data:`ROTATIONS`): the shape turned against the scan directions.

    Returns
    -------
    Shape

    Raises
    ------
    ShapeError
        For an unknown shape or parameter name, a parameter out of its range
        (the message names the parameter, the rule and the value), or a model
        whose tessellation does not fit its B-rep topology.
    """
    p = _resolve(name, params)
    try:
        solid = _SPECS[name].make({k: v for k, v in p.items() if k not in ROTATIONS})
        for axis, key in zip(((1, 0, 0), (0, 1, 0), (0, 0, 1)), ROTATIONS):
            if key in p:
                solid = solid.rotate((0, 0, 0), axis, p[key])
    except ImportError:
        raise  # CadQuery missing: the caller says which extra to install
    except Exception as exc:  # OCP raises Standard_Failure and its kin
        msg = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
        raise ShapeError(f"CadQuery could not build {name} for {p}: {msg}") from None
    from OCP.BRepCheck import BRepCheck_Analyzer

    if not BRepCheck_Analyzer(solid.wrapped).IsValid():
        raise ShapeError(f"CadQuery built an invalid {name} for {p}")
    return _shape_of(name, solid, p, f"{name} for {p}")


def _shape_of(name: str, solid, params: dict[str, float], what: str) -> Shape:
    """The :class:`Shape` record of a valid solid: its B-rep topology, truth
    mesh, size, area and default spacing."""
    expected = brep_topology(solid)
    size = _exact_size(solid)
    vertices, triangles = _truth_mesh(solid, size)
    problem = _mesh_problem(triangles, expected)
    if problem is not None:
        raise ShapeError(f"the truth mesh of {what} does not fit its B-rep: {problem}")
    vertices.setflags(write=False)
    triangles.setflags(write=False)
    area = float(solid.Area())
    return Shape(
        name=name,
        solid=solid,
        params=params,
        expected=expected,
        truth_vertices=vertices,
        truth_triangles=triangles,
        size=size,
        default_spacing=_nice(math.sqrt(area / TARGET_SAMPLES)),
        area=area,
    )


CAD_FORMATS = (".step", ".stp", ".brep")


@contextmanager
def _silenced():
    """Silence what C++ code prints (OpenCascade's STEP reader reports parse
    errors on stdout itself): file descriptors 1 and 2 go to the null device
    for the block; the caller turns failures into one-line errors."""
    sys.stdout.flush()
    sys.stderr.flush()
    saved = [os.dup(1), os.dup(2)]
    null = os.open(os.devnull, os.O_WRONLY)
    try:
        os.dup2(null, 1)
        os.dup2(null, 2)
        yield
    finally:
        os.dup2(saved[0], 1)
        os.dup2(saved[1], 2)
        for fd in saved + [null]:
            os.close(fd)


def cad_format(path) -> str:
    """The CAD format of a file by its extension (one of :data:`CAD_FORMATS`).

    Raises
    ------
    ShapeError
        For any other extension, naming the ones read.
    """
    ext = Path(path).suffix.lower()
    if ext not in CAD_FORMATS:
        raise ShapeError(
            f"{path}: unsupported CAD format {ext or '(none)'}; use one of {', '.join(CAD_FORMATS)}"
        )
    return ext


def _read_cad(path: Path):
    """The CadQuery shape in a STEP or BREP file."""
    import cadquery as cq

    ext = cad_format(path)
    if not path.is_file():
        raise ShapeError(f"{path}: no such file")
    try:
        with _silenced():
            if ext == ".brep":
                return cq.Shape.importBrep(str(path))
            return cq.importers.importStep(str(path)).val()
    except Exception as exc:  # OCC reader failures: ValueError, Standard_Failure...
        msg = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
        raise ShapeError(f"{path}: unreadable {ext} file ({msg})") from None


def from_cad(source, name: str | None = None) -> Shape:
    """A user's CAD model as a :class:`Shape`: its B-rep topology, ground
    truth mesh and default spacing, as :func:`build` gives for the library.

    Parameters
    ----------
    source : cadquery.Workplane, cadquery.Shape, str or path
        A CadQuery object (a Workplane's first solid is taken) or a STEP
        (``.step``/``.stp``) or BREP (``.brep``) file.
    name : str, optional
        The name the record carries (default: the file's stem, or ``"cad"``).

    Returns
    -------
    Shape
        ``params`` is empty.

    Raises
    ------
    ShapeError
        An unreadable or unsupported file, a model that is not one solid or
        shell, an invalid B-rep, or a tessellation that does not fit it.
    """
    import cadquery as cq

    if isinstance(source, (str, Path)):
        path = Path(source)
        obj = _read_cad(path)
        label = name or path.stem
        what = str(path)
    else:
        obj = source.val() if isinstance(source, cq.Workplane) else source
        label = name or "cad"
        what = f"the {type(obj).__name__}"
    if not isinstance(obj, cq.Shape):
        raise ShapeError(f"{what}: not a CadQuery shape (got {type(obj).__name__})")
    solids, shells = obj.Solids(), obj.Shells()
    if len(solids) == 1:
        solid = cq.Solid(solids[0].wrapped)
    elif not solids and len(shells) == 1:
        solid = cq.Shell(shells[0].wrapped)
    else:
        raise ShapeError(
            f"{what}: holds {len(solids)} solids and {len(shells)} shells; "
            "sampling needs one solid (or one open shell)"
        )
    from OCP.BRepCheck import BRepCheck_Analyzer

    if not BRepCheck_Analyzer(solid.wrapped).IsValid():
        raise ShapeError(f"{what}: the B-rep is invalid (OpenCascade's check fails)")
    return _shape_of(label, _merged(solid), {}, what)


def _merged(solid):
    """The solid with the faces of one surface merged where a boolean left
    them in pieces (OpenCascade's ``ShapeUpgrade_UnifySameDomain``, as
    CadQuery's ``clean``), when the result is valid and as many solids or
    shells; else the solid as it is.

    CadQuery's ``Solid.fuse`` leaves a box fused onto another with its
    coplanar sides split along edges that are no sharp features: each piece
    got a lattice of its own, staggered against its neighbour's across the
    seam (a box 0.4 with a box 0.24 fused on its corner: 13 faces, 9
    merged)."""
    import cadquery as cq
    from OCP.BRepCheck import BRepCheck_Analyzer

    try:
        merged = solid.clean()
    except Exception:  # OpenCascade refuses (Standard_Failure and kin): keep the input
        return solid
    if (
        len(merged.Faces()) >= len(solid.Faces())
        or not BRepCheck_Analyzer(merged.wrapped).IsValid()
    ):
        return solid
    kind = cq.Solid if isinstance(solid, cq.Solid) else cq.Shell
    parts = merged.Solids() if kind is cq.Solid else merged.Shells()
    return kind(parts[0].wrapped) if len(parts) == 1 else solid
