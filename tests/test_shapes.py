"""CAD shape library: expected topology, watertight truth meshes, parameter errors, determinism."""

import re
import subprocess
import sys

import numpy as np
import pytest

cq = pytest.importorskip("cadquery")

from sr33.samplers.shapes import (  # noqa: E402
    Shape,
    ShapeError,
    Topology,
    brep_topology,
    build,
    describe,
    shape_names,
    shape_parameters,
)
from sr33.validators import mesh_stats  # noqa: E402

NAMES = shape_names()

# what the surfaces must be: (components, euler, genus, boundary_loops, orientable)
TRUTH = {
    "L_sheet": (1, 1, 0, 1, True),
    "block_two_holes": (1, -2, 2, 0, True),
    "box_hole": (1, 0, 1, 0, True),
    "cone": (1, 2, 0, 0, True),
    "cone_tip": (1, 2, 0, 0, True),
    "conebox": (1, 2, 0, 0, True),
    "cube": (1, 2, 0, 0, True),
    "cutcube": (1, 0, 1, 0, True),
    "cylinder": (1, 2, 0, 0, True),
    "fillet_box": (1, 2, 0, 0, True),
    "hexagonal_prism": (1, 2, 0, 0, True),
    "pyramid": (1, 2, 0, 0, True),
    "sphere": (1, 2, 0, 0, True),
    "square_ring": (1, 0, 1, 0, True),
    "star_prism": (1, 2, 0, 0, True),
    "torus": (1, 0, 1, 0, True),
    "wedge": (1, 2, 0, 0, True),
}


@pytest.fixture(scope="module")
def built() -> dict[str, Shape]:
    return {name: build(name) for name in NAMES}


def _edge_uses(tri: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    e = np.concatenate([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]])
    return np.unique(np.sort(e, axis=1), axis=0, return_counts=True)


def test_the_library_shapes_are_known():
    assert sorted(NAMES) == sorted(TRUTH)
    assert NAMES == sorted(NAMES, key=str.lower)


@pytest.mark.parametrize("name", NAMES)
def test_expected_topology_is_what_the_surface_must_be(built, name):
    assert built[name].expected == Topology(*TRUTH[name])


@pytest.mark.parametrize("name", NAMES)
def test_truth_mesh_is_watertight_and_manifold(built, name):
    s = built[name]
    tri = s.truth_triangles
    edges, counts = _edge_uses(tri)
    assert counts.max() == 2
    if s.expected.boundary_loops == 0:
        assert np.all(counts == 2)
    else:
        assert np.any(counts == 1)
    stats = mesh_stats(tri, n_points=s.truth_vertices.shape[0])
    assert stats.used_vertices == stats.points  # no unused vertices
    assert stats.overloaded_edges == 0
    assert stats.boundary_loops == s.expected.boundary_loops
    assert stats.components == s.expected.components
    # consistently oriented: each directed edge at most once
    d = np.concatenate([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]])
    assert np.unique(d, axis=0).shape[0] == d.shape[0]
    # no degenerate triangles
    assert np.all((tri[:, 0] != tri[:, 1]) & (tri[:, 1] != tri[:, 2]) & (tri[:, 2] != tri[:, 0]))


@pytest.mark.parametrize("name", NAMES)
def test_truth_mesh_euler_matches_expected(built, name):
    s = built[name]
    edges, _ = _edge_uses(s.truth_triangles)
    v = np.unique(s.truth_triangles).shape[0]
    assert v - edges.shape[0] + s.truth_triangles.shape[0] == s.expected.euler
    assert mesh_stats(s.truth_triangles).euler == s.expected.euler


@pytest.mark.parametrize("name", NAMES)
def test_truth_mesh_matches_the_brep(built, name):
    s = built[name]
    v, t = s.truth_vertices, s.truth_triangles
    a, b, c = v[t[:, 0]], v[t[:, 1]], v[t[:, 2]]
    area = 0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1).sum()
    assert area == pytest.approx(s.area, rel=2e-3)
    if s.expected.boundary_loops == 0:  # outward normals: signed volume is the solid's
        volume = np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6
        assert volume == pytest.approx(s.solid.Volume(), rel=3e-3)
    lo, hi = v.min(axis=0), v.max(axis=0)
    assert np.linalg.norm(hi - lo) <= s.size * (1 + 1e-9)
    assert np.linalg.norm(hi - lo) > 0.95 * s.size


@pytest.mark.parametrize("name", NAMES)
def test_record_fields(built, name):
    s = built[name]
    assert s.name == name
    assert s.params == shape_parameters(name)
    assert all(isinstance(x, float) for x in s.params.values())
    assert s.truth_vertices.dtype == np.float64 and s.truth_vertices.shape[1] == 3
    assert s.truth_triangles.dtype == np.int64 and s.truth_triangles.shape[1] == 3
    assert not s.truth_vertices.flags.writeable and not s.truth_triangles.flags.writeable
    assert 0.5 < s.size < 3.0
    assert s.area == pytest.approx(s.solid.Area())
    assert 3000 < s.area / s.default_spacing**2 < 12000
    mantissa = s.default_spacing / 10 ** np.floor(np.log10(s.default_spacing))
    assert round(mantissa, 9) in (1, 1.2, 1.5, 2, 2.5, 3, 4, 5, 6, 8)
    kind = cq.Shell if name == "L_sheet" else cq.Solid
    assert isinstance(s.solid, kind)
    assert describe(name) and "\n" not in describe(name)
    assert name in repr(s)


@pytest.mark.parametrize("name", NAMES)
def test_builds_are_deterministic(built, name):
    again = build(name)
    assert np.array_equal(again.truth_vertices, built[name].truth_vertices)
    assert np.array_equal(again.truth_triangles, built[name].truth_triangles)
    assert again.expected == built[name].expected


@pytest.mark.parametrize(
    "name, params, euler",
    [
        ("L_sheet", {"angle": 45.0, "width": 0.5}, 1),
        ("wedge", {"angle": 150}, 2),
        ("cutcube", {"side": 2.0, "hole_radius": 0.3, "scoop_radius": 0.8}, 0),
        ("block_two_holes", {"length": 3, "hole_radius": 0.4}, -2),
        ("fillet_box", {"fillet_radius": 0.29}, 2),
        ("cone_tip", {"apex_height": 0.4}, 2),
    ],
)
def test_other_parameters(name, params, euler):
    s = build(name, **params)
    assert s.expected.euler == euler
    assert mesh_stats(s.truth_triangles).euler == euler
    assert s.params == {**shape_parameters(name), **{k: float(v) for k, v in params.items()}}


def test_brep_topology_sees_inconsistent_orientation():
    from OCP.BRep import BRep_Builder
    from OCP.TopoDS import TopoDS_Shell

    faces = build("L_sheet").solid.Faces()
    shell = TopoDS_Shell()
    builder = BRep_Builder()
    builder.MakeShell(shell)
    builder.Add(shell, faces[0].wrapped)
    builder.Add(shell, faces[1].wrapped.Reversed())
    topo = brep_topology(cq.Shell(shell))
    assert not topo.orientable
    assert (topo.components, topo.euler, topo.boundary_loops) == (1, 1, 1)


BAD = [
    (
        "box_hole",
        {"hole_radius": 0.7},
        "hole_radius must be less than half the block width (0.5), got 0.7",
    ),
    (
        "box_hole",
        {"length": 0.4},
        "hole_radius must be less than half the block length (0.2), got 0.25",
    ),
    (
        "block_two_holes",
        {"hole_radius": 0.5},
        "hole_radius must be less than half the block width (0.5), got 0.5",
    ),
    (
        "block_two_holes",
        {"length": 0.8},
        "hole_radius must be less than a quarter of the block length (0.2), got 0.25",
    ),
    ("cube", {"side": -1}, "side must be positive, got -1"),
    ("cube", {"side": 0}, "side must be positive, got 0"),
    ("cone", {"height": -0.5}, "height must be positive, got -0.5"),
    ("wedge", {"angle": 180}, "angle must be between 5 and 175 degrees, got 180"),
    ("wedge", {"angle": 4.5}, "angle must be between 5 and 175 degrees, got 4.5"),
    ("L_sheet", {"angle": 0}, "angle must be between 5 and 175 degrees, got 0"),
    (
        "star_prism",
        {"inner_radius": 0.7},
        "inner_radius must be less than outer_radius (0.6), got 0.7",
    ),
    (
        "fillet_box",
        {"fillet_radius": 0.3},
        "fillet_radius must be less than half the smallest side (0.3), got 0.3",
    ),
    (
        "conebox",
        {"cone_radius": 0.5},
        "cone_radius must be less than half the box width (0.5), got 0.5",
    ),
    ("cutcube", {"hole_radius": 0.5}, "hole_radius must be less than half the side (0.5), got 0.5"),
    (
        "cutcube",
        {"scoop_radius": 0.1},
        "scoop_radius must be greater than 0.2 times the side (0.2) to cut the corner, got 0.1",
    ),
    (
        "cutcube",
        {"scoop_radius": 0.7},
        "scoop_radius + hole_radius must be less than 0.8 times the side (0.8) "
        "to keep the scoop off the hole, got 0.9",
    ),
    (
        "cone_tip",
        {"apex_height": 0.3},
        "apex_height must be greater than 1.1 times the radius (0.385), got 0.3",
    ),
    ("square_ring", {"section": 0.8}, "section must be less than twice the radius (0.8), got 0.8"),
    (
        "cube",
        {"sidee": 1},
        "unknown parameter 'sidee' for shape 'cube'; allowed: side, rotate_x, rotate_y, rotate_z",
    ),
    (
        "cylinder",
        {"r": 1, "h": 2},
        "unknown parameters 'h', 'r' for shape 'cylinder'; allowed: radius, height, "
        "rotate_x, rotate_y, rotate_z",
    ),
    ("cube", {"side": "1"}, "side must be a number, got '1'"),
    ("cube", {"side": True}, "side must be a number, got True"),
    ("cube", {"side": float("nan")}, "side must be finite, got nan"),
]


@pytest.mark.parametrize("name, params, message", BAD)
def test_bad_parameters_raise_shape_error(name, params, message):
    with pytest.raises(ShapeError, match=f"^{re.escape(message)}$"):
        build(name, **params)


def test_unknown_shape_names_the_known_ones():
    message = f"unknown shape 'cubee'; known shapes: {', '.join(NAMES)}"
    assert message.startswith(
        "unknown shape 'cubee'; known shapes: block_two_holes, box_hole, cone"
    )
    for call in (build, shape_parameters, describe):
        with pytest.raises(ShapeError, match=f"^{re.escape(message)}$"):
            call("cubee")
    assert issubclass(ShapeError, ValueError)


def test_shape_parameters_are_fresh_copies():
    p = shape_parameters("cube")
    assert p == {"side": 1.0}
    p["side"] = 2.0
    assert shape_parameters("cube") == {"side": 1.0}


def test_numpy_numbers_are_accepted():
    s = build("cube", side=np.float32(2.0))
    assert s.params == {"side": 2.0}
    assert s.area == pytest.approx(24.0)


def test_import_does_not_need_cadquery():
    code = (
        "import sys, sr33.samplers.shapes as m; m.shape_names(); m.shape_parameters('cube'); "
        "assert 'cadquery' not in sys.modules and 'OCP' not in sys.modules"
    )
    subprocess.run([sys.executable, "-c", code], check=True)
