"""The paper's guarantees as properties that hypothesis attacks (Theorems 1-5).

Each test is named after the guarantee it checks.  The ``ci`` profile runs a
few examples per property inside ``make test``; ``make fuzz`` runs the
``deep`` profile and prints, per property, the examples run, failures and
seconds.

Two homeomorphism properties cover the library shapes.  With drawn
parameters, shapes are sampled from the plain scan rows (``repair=False``):
the boundary-layer repair costs seconds per shape, which hypothesis would
pay on every example.  Plain rows across an edge sharper than 60 degrees
break Condition III (the geodesic check found none of a dozen such draws
conforming), so shapes with such edges are not drawn there; instead every
shape's repaired default sampling, which meets Condition III by the
geodesic check (``tests/test_sampling_shapes.py``), is reconstructed under
drawn rigid motions, scalings and point orders.  Until the sampler is fast
and general (issue 23) the drawn-parameter property cannot measure
conformance per example (issue 24).
"""

import os

import numpy as np
import pytest
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

pytest.importorskip("cadquery")

from sr33 import InputError, Reconstruction, localized_rng, reconstruct  # noqa: E402
from sr33.samplers import cube_lattice, shapes  # noqa: E402
from sr33.samplers.scanline import scan  # noqa: E402
from sr33.validators import mesh_stats  # noqa: E402
from sr33.validators.intersections import self_intersections  # noqa: E402
from sr33.validators.signature import homeomorphic, signature  # noqa: E402
from tests.fuzzstats import count  # noqa: E402
from tests.helpers import check_homeomorphism, triangle_set  # noqa: E402
from tests.strategies import (  # noqa: E402
    arbitrary_points,
    rigid_motions,
    scan_settings,
    shape_params,
)

DEEP = os.environ.get("HYPOTHESIS_PROFILE") == "deep"
PER_SHAPE = 36 if DEEP else 2  # 14 shapes x 36 = 504 examples in the deep profile
HEAVY = settings(max_examples=PER_SHAPE, deadline=None, suppress_health_check=list(HealthCheck))


def sample_shape(name, params, cfg):
    try:
        s = shapes.build(name, **params)
    except shapes.ShapeError:
        assume(False)
    r = scan(
        s,
        s.default_spacing / cfg["density"],
        ratio=cfg["ratio"],
        seed=cfg["seed"],
        repair=False,
    )
    return s, r


def _acute(shape, below_degrees: float = 60.0) -> bool:
    """Whether the shape's truth has an edge whose interior dihedral angle is
    below ``below_degrees`` (where plain scan rows break Condition III-ii:
    the Euclidean RNG cuts across such edges, issue 21)."""
    from sr33.validators.fidelity import dihedral_pairs

    _, _, _, cos = dihedral_pairs(shape.truth_vertices, shape.truth_triangles)
    return bool(cos.size) and float(cos.min()) < np.cos(np.radians(180.0 - below_degrees))


def _homeomorphism_case(name, data):
    params = data.draw(shape_params(name), label="params")
    cfg = data.draw(scan_settings(), label="scan")
    s, r = sample_shape(name, params, cfg)
    # plain scan rows across an acute edge break Condition III (the geodesic
    # check finds 0 of 12 such draws conforming): not the theorem's input
    assume(not _acute(s))
    rec = reconstruct(r.points, 33)
    count(f"homeomorphism[{name}]")
    check_homeomorphism(s, r.points, r.meta["spacing"], rec)


# Failures this property found and that were fixed at the root (crossing
# face cycles are now excluded by the backtracking), kept as regressions:
# cone_tip got a zero-area triangle (apex_height 1.0625) and crossing
# triangles near its tip (ratio 1.125); conebox crossing triangles at its
# apex (ratio 0.875).


# shapes whose edges are all 60 degrees or wider: their plain scan rows are
# drawn; the others (acute edges) are tested on their conforming default
# samplings below
PLAIN_ROWS = [n for n in shapes.shape_names() if not _acute(shapes.build(n))]


@pytest.mark.parametrize("name", PLAIN_ROWS)
@HEAVY
@given(data=st.data())
def test_homeomorphism_of_conforming_samples(name, data):
    """Theorems 3-5 on the library shapes, their parameters drawn, sampled by
    plain scan rows."""
    _homeomorphism_case(name, data)


#: why the wedge's default sampling can fail the rigid-motion property
_WEDGE_TURNED = (
    "stop 57, make check: the default wedge's sampling of stop 56 (the repair's flip path), "
    "turned, reconstructs 1.04-1.2 h off the truth near an acute corner (a triangle across "
    "the 30-degree edge's thin end, 3 h thick there); upright 0.87 h; 9acc45c's sampling "
    "passed (test_regression_the_default_wedge_turned_reconstructs_within_h)"
)
#: the turn drawn by the ci profile that found it (to 8 decimals; orthonormalised)
_WEDGE_TURN = np.array(
    [
        [-0.85361172, -0.43041808, 0.2934064],
        [-0.31431799, 0.87475609, 0.3687899],
        [-0.41539287, 0.22258047, -0.88199019],
    ]
)

# the repaired default samplings (Condition III by the geodesic check in
# tests/test_sampling_shapes.py), made once per session
_DEFAULT_SAMPLINGS: dict = {}
# reconstructions quick enough for `make test`; the others run in `make check`
_QUICK_MOTION = {"cube", "L_sheet", "cylinder"}


def _default_sampling(name):
    if name not in _DEFAULT_SAMPLINGS:
        s = shapes.build(name)
        _DEFAULT_SAMPLINGS[name] = (s, scan(s))
    return _DEFAULT_SAMPLINGS[name]


@pytest.mark.parametrize(
    "name",
    [
        pytest.param(
            n,
            marks=([] if n in _QUICK_MOTION else [pytest.mark.slow])
            + ([pytest.mark.xfail(strict=False, reason=_WEDGE_TURNED)] if n == "wedge" else []),
        )
        for n in shapes.shape_names()
    ],
)
@settings(
    max_examples=1 if not DEEP else 12, deadline=None, suppress_health_check=list(HealthCheck)
)
@given(motion=rigid_motions(), perm_seed=st.integers(0, 2**31))
def test_homeomorphism_of_default_samplings_under_rigid_motions(name, motion, perm_seed):
    """Every library shape's conforming default sampling, moved, scaled and
    shuffled: homeomorphic, crossing-free, every sample a vertex, Hausdorff
    at most h (acute edges included: pyramid, star_prism, wedge)."""
    s, r = _default_sampling(name)
    rot, t, scale = motion
    perm = np.random.default_rng(perm_seed).permutation(r.points.shape[0])
    moved = (r.points[perm] @ rot.T) * scale + t
    rec = reconstruct(moved, 33)
    count(f"rigid motion[{name}]")
    back = ((rec.vertices - t) / scale) @ rot  # into the shape's frame
    check_homeomorphism(
        s, r.points, r.meta["spacing"], Reconstruction(**{**rec.__dict__, "vertices": back})
    )


#: not strict: on the same sampling's bytes and the same pinned packages it
#: failed in stop 65's ``make check`` and passes on stop 66's machine (an AMD
#: EPYC), so that the outcome hangs on the machine (the selection's path at
#: the wedge's thin end), which is the defect this marks
_WEDGE_MACHINE = _WEDGE_TURNED + "; its outcome differs between machines (stops 65 and 66)"


@pytest.mark.slow
@pytest.mark.xfail(strict=False, reason=_WEDGE_MACHINE)
def test_regression_the_default_wedge_turned_reconstructs_within_h():
    """The rigid-motion property's example: the default wedge sampling (its
    samples shuffled, seed 0), turned by ``_WEDGE_TURN``, reconstructs
    homeomorphic, within h of the truth."""
    u, _, vt = np.linalg.svd(_WEDGE_TURN)
    rot = u @ vt
    s, r = _default_sampling("wedge")
    perm = np.random.default_rng(0).permutation(r.points.shape[0])
    rec = reconstruct(r.points[perm] @ rot.T, 33)
    check_homeomorphism(
        s,
        r.points,
        r.meta["spacing"],
        Reconstruction(**{**rec.__dict__, "vertices": rec.vertices @ rot}),
    )


@pytest.mark.parametrize(
    "name, params, ratio",
    [
        ("cone_tip", {"radius": 0.35, "apex_height": 1.0625}, 1.0),
        ("cone_tip", {}, 1.125),
        ("conebox", {}, 0.875),
    ],
)
def test_regression_crossing_faces_at_cone_tips(name, params, ratio):
    s = shapes.build(name, **params)
    r = scan(s, ratio=ratio, repair=False)
    check_homeomorphism(s, r.points, r.meta["spacing"], reconstruct(r.points, 33))


def test_the_homeomorphism_property_can_fail():
    s = shapes.build("cube")
    r = scan(s, repair=False)
    rec = reconstruct(r.points, 33)
    check_homeomorphism(s, r.points, r.meta["spacing"], rec)
    broken = Reconstruction(**{**rec.__dict__, "triangles": rec.triangles[1:]})
    with pytest.raises(AssertionError, match="boundary loops: mesh 1, truth 0"):
        check_homeomorphism(s, r.points, r.meta["spacing"], broken)


@pytest.fixture(scope="module")
def flat_truth():
    pv = pytest.importorskip("pyvista")
    g = pv.Plane(center=(4, 4, 0), i_size=10, j_size=10, i_resolution=150, j_resolution=150)
    g = g.triangulate()
    return np.asarray(g.points, float), np.asarray(g.faces).reshape(-1, 4)[:, 1:]


@settings(
    max_examples=20 if not DEEP else 500,
    deadline=None,
    suppress_health_check=[HealthCheck.function_scoped_fixture],
)
@given(
    perturb=st.floats(0.0, 0.08),
    seed=st.integers(0, 2**31),
    motion=rigid_motions(),
)
def test_theorem_1_2_rng_equals_urquhart_on_smooth_patches(flat_truth, perturb, seed, motion):
    # a flat, slightly perturbed square lattice: the validators' P_UG (the
    # intrinsic Urquhart graph, Theorem 1) must equal the localized RNG
    # (Theorem 2), and both the grid; the RNG is also checked after a rigid
    # motion and scaling
    from sr33.validators.conditions import sample_conditions
    from tests.helpers import grid_edges

    count("theorem_1_2")
    n = 9
    xs = np.arange(n, dtype=float)
    p = np.stack(np.meshgrid(xs, xs, [0.0], indexing="ij"), -1).reshape(-1, 3)
    p[:, :2] += np.random.default_rng(seed).uniform(-perturb, perturb, (p.shape[0], 2))
    ug = {tuple(x) for x in sample_conditions(p, *flat_truth).urquhart_edges.tolist()}
    rng = {tuple(x) for x in localized_rng(p, 8).edges.tolist()}
    assert rng == ug == grid_edges(n, n)
    rot, t, scale = motion
    moved = {tuple(x) for x in localized_rng((p @ rot.T) * scale + t, 8).edges.tolist()}
    assert moved == rng


INVARIANT_SHAPES = ["cube", "cylinder", "square_ring", "cutcube"]


@settings(
    max_examples=3 if not DEEP else 500, deadline=None, suppress_health_check=list(HealthCheck)
)
@given(
    name=st.sampled_from(INVARIANT_SHAPES),
    cfg=scan_settings(),
    motion=rigid_motions(),
    perm_seed=st.integers(0, 2**31),
)
def test_invariance_under_permutation_motion_and_scaling(name, cfg, motion, perm_seed):
    count("invariance")
    s = shapes.build(name)
    pts = scan(s, s.default_spacing / cfg["density"], ratio=cfg["ratio"], repair=False).points
    a = reconstruct(pts, 33)
    perm = np.random.default_rng(perm_seed).permutation(pts.shape[0])
    b = reconstruct(pts[perm], 33)
    assert triangle_set(b.triangles, perm) == triangle_set(a.triangles)
    rot, t, scale = motion
    c = reconstruct(pts * scale + t, 33)
    assert triangle_set(c.triangles) == triangle_set(a.triangles)
    d = reconstruct(pts @ rot.T + t, 33)
    fig = mesh_stats(a.triangles, pts.shape[0]).as_dict()
    assert mesh_stats(d.triangles, pts.shape[0]).as_dict() == fig
    assert np.array_equal(reconstruct(pts, 33).triangles, a.triangles)


ROBUSTNESS_BUDGET = 120.0  # seconds per input: a run longer than this is a hang


@settings(max_examples=40 if not DEEP else 500, deadline=None)
@given(points=arbitrary_points(), k=st.integers(1, 40))
def test_robustness_result_or_documented_error(points, k):
    """Any cloud ends within the budget in a one-line InputError or in a
    result whose figures the validators confirm: every input point a vertex,
    bit for bit; the reported open edges the mesh's own; success only for a
    mesh with no overloaded edge and no non-manifold vertex."""
    import time

    count("robustness")
    t0 = time.perf_counter()
    try:
        r = reconstruct(points, k, budget=2000, exact_seconds=1.0)
    except InputError as exc:
        assert "\n" not in str(exc) and str(exc)
        return
    finally:
        assert time.perf_counter() - t0 < ROBUSTNESS_BUDGET
    assert np.array_equal(r.vertices[r.input_to_vertex], points)
    assert r.vertices.shape[0] == np.unique(points, axis=0).shape[0]
    if r.triangles.size == 0:
        assert not r.success
        return
    st_ = mesh_stats(r.triangles, r.vertices.shape[0])
    assert st_.used_vertices == r.vertices.shape[0]  # the cones attach every sample
    assert triangle_set(_open(r.triangles)) == triangle_set(r.open_edges)
    if r.success:
        sig = signature(r.triangles, r.vertices.shape[0])
        assert st_.overloaded_edges == 0 and sig.non_manifold_vertices.size == 0


def _open(triangles) -> np.ndarray:
    """Edges of the mesh in one triangle (sorted pairs)."""
    from sr33.mesh import edge_uses

    edges, counts = edge_uses(triangles)
    return edges[counts == 1]


@pytest.fixture(scope="module")
def clean_mesh():
    pts = cube_lattice(5)
    r = reconstruct(pts, 12)
    return r.vertices, r.triangles


@settings(
    max_examples=40 if not DEEP else 500,
    deadline=None,
    suppress_health_check=[HealthCheck.function_scoped_fixture],
)
@given(
    kind=st.sampled_from(["remove", "duplicate", "pinch", "flip", "cross"]),
    pick=st.integers(0, 10**6),
)
def test_validator_soundness_planted_defects(clean_mesh, kind, pick):
    count("validator_soundness")
    v, t = clean_mesh
    i = pick % t.shape[0]
    truth = signature(t, v.shape[0])
    if kind == "remove":
        bad = np.delete(t, i, axis=0)
        verdict = homeomorphic(bad, truth)
        assert "boundary loops: mesh 1, truth 0" in verdict.reasons
    elif kind == "duplicate":
        bad = np.vstack([t, t[i]])
        assert signature(bad).duplicate_faces == 1
        assert not homeomorphic(bad, truth)
    elif kind == "pinch":
        # glue a vertex onto the one farthest from it: two fans meet at one vertex
        a = int(t[i, 0])
        b = int(np.argmax(np.linalg.norm(v - v[a], axis=1)))
        bad = np.where(t == b, a, t)
        s = signature(bad, v.shape[0])
        assert a in s.non_manifold_vertices.tolist()
        assert not homeomorphic(bad, truth)
    elif kind == "flip":
        bad = t.copy()
        bad[i] = bad[i][::-1]
        s = signature(bad)
        assert s.incoherent_edges == 3 and s.orientable
        assert homeomorphic(bad, truth)  # the rule: a flipped face is still orientable
    else:
        c = v[t[i]].mean(axis=0)
        n = np.cross(v[t[i, 1]] - v[t[i, 0]], v[t[i, 2]] - v[t[i, 0]])
        n /= np.linalg.norm(n)
        spike = np.array([c - 0.3 * n, c + 0.3 * n, c + 0.3 * n + 0.2 * (v[t[i, 0]] - c)])
        vv = np.vstack([v, spike])
        m = v.shape[0]
        bad = np.vstack([t, [m, m + 1, m + 2]])
        pairs = self_intersections(vv, bad)
        assert any(i in p for p in pairs.tolist())


def test_regression_translation_keeps_the_canonical_order():
    # found by the deep profile: on the cylinder, translating by (1, 0, 0)
    # merged x coordinates closer than an ulp and reordered the samples
    s = shapes.build("cylinder")
    pts = scan(s, repair=False).points
    a = reconstruct(pts, 33)
    c = reconstruct(pts + np.array([1.0, 0.0, 0.0]), 33)
    assert triangle_set(c.triangles) == triangle_set(a.triangles)


# Minimal failing cases the deep profile found, fixed at the root and kept
# as regressions: crossing triangles near holes and at cone tips, a
# non-manifold cone at a flatter apex, a zero-area triangle at the cone tip,
# a hole in the conebox junction (fixed by the paper's success condition and
# the exact selection, issue 21).
DEEP_PROFILE_FAILURES = [
    (
        "block_two_holes",
        {"length": 1.90625, "width": 1.0, "height": 0.501953125, "hole_radius": 0.25},
        0.921875,
        0.8515625,
    ),
    (
        "box_hole",
        {"length": 0.65625, "width": 0.65625, "height": 0.328125, "hole_radius": 0.1640625},
        0.875,
        0.875,
    ),
    ("cone", {"radius": 0.5, "height": 1.3125}, 1.0, 0.8515625),
    ("cone_tip", {"radius": 0.35, "apex_height": 1.0}, 1.125, 1.0),
    (
        "conebox",
        {"length": 1.0, "width": 1.0, "height": 0.5625, "cone_radius": 0.39375, "cone_height": 0.6},
        1.125,
        0.8671875,
    ),
]


def test_regression_two_faces_folded_at_one_corner_of_a_steep_cone_rim():
    # the cone's rim (dihedral about 72 degrees): two quads, one of them
    # across the rim, share both edges at a rim sample (its link is two arcs
    # between the same two samples) and cross; they are removed, the quad
    # hole they leave is closed and the sample coned back onto the rim
    # (sr33.holes.crossing_faces)
    s = shapes.build("cone", radius=0.5, height=1.5)
    r = scan(s, s.default_spacing, ratio=0.8515625, repair=False)
    rec = reconstruct(r.points, 33)
    check_homeomorphism(s, r.points, r.meta["spacing"], rec)
    assert rec.coned_samples.shape[0] >= 1 and rec.hole_faces >= 1


@pytest.mark.parametrize("name, params, density, ratio", DEEP_PROFILE_FAILURES)
def test_regression_failures_found_by_the_deep_profile(name, params, density, ratio):
    s = shapes.build(name, **params)
    r = scan(s, s.default_spacing / density, ratio=ratio, repair=False)
    check_homeomorphism(s, r.points, r.meta["spacing"], reconstruct(r.points, 33))
