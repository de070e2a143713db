"""Spherical caps laid out in rings from their rim to their pole
(samplers.layers.lattice_sphere_caps)."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from sr33.samplers.chart import halving_count
from sr33.samplers.faces import cap_rim
from sr33.samplers.layers import CAP_GAPS, _Cap, _cap_rings

cq = pytest.importorskip("cadquery")


def _box(top=0.0):
    return cq.Solid.makeBox(1, 1, 0.6, pnt=cq.Vector(-0.5, -0.5, top - 0.6))


def _ball(r, z0=0.0):
    return cq.Solid.makeSphere(r, pnt=cq.Vector(0, 0, z0), angleDegrees1=-90, angleDegrees2=90)


def _sphere_faces(solid):
    return [f for f in solid.Faces() if f.geomType() == "SPHERE"]


@pytest.mark.parametrize(
    "solid, centre, radius",
    [
        (_box().fuse(_ball(0.3)), (0, 0, 0), 0.3),  # a dome: a hemisphere
        (_box().cut(_ball(0.35, -0.15)), (0, 0, 0), math.sqrt(0.35**2 - 0.15**2)),  # a dimple
        (_box().fuse(_ball(0.2, 0.05)), (0, 0, 0), math.sqrt(0.2**2 - 0.05**2)),  # past its equator
        (cq.Solid.makeSphere(0.4, angleDegrees1=0, angleDegrees2=90), (0, 0, 0), 0.4),
    ],
)
def test_a_caps_rim_is_its_one_circle(solid, centre, radius):
    (face,) = _sphere_faces(solid)
    got = cap_rim(face, 1e-9)
    assert got is not None
    c, n, r = got
    np.testing.assert_allclose(c, centre, atol=1e-9)
    assert abs(abs(n[2]) - 1) < 1e-12
    assert r == pytest.approx(radius, abs=1e-9)


def test_faces_that_are_no_cap_have_no_rim():
    """A whole ball (no edge but its seam), cutcube's scoop (three arcs of
    three circles) and a sphere cut by two planes (two circles) are no caps."""
    from sr33.samplers import shapes

    (ball,) = _sphere_faces(_ball(0.3))
    assert cap_rim(ball, 1e-9) is None
    scoop = _sphere_faces(shapes.build("cutcube").solid)
    assert scoop and all(cap_rim(f, 1e-9) is None for f in scoop)
    slab = cq.Solid.makeBox(2, 2, 0.3, pnt=cq.Vector(-1, -1, -0.15))
    (band,) = _sphere_faces(_ball(0.3).intersect(slab).Solids()[0])
    assert cap_rim(band, 1e-9) is None


@settings(max_examples=40, deadline=None)
@given(
    st.floats(6.0, 40.0),  # the sphere's radius (times t)
    st.floats(0.35, 1.0),  # the rim's angle from the pole (times pi / 2)
    st.sampled_from(CAP_GAPS),
    st.integers(2, 12),
)
def test_a_caps_rings_keep_nested_columns_down_to_at_most_five_round_its_pole(
    radius, theta, gap, reach
):
    """Every ring stands nearer the pole than the ring before it and keeps a
    subset of its columns (the rim's, evenly spaced at a count that halves
    cleanly), so that the cells are quadrilaterals with a pentagon where a
    column ends; the ring round the pole keeps at most 5 and at least 3."""
    theta *= math.pi / 2
    rows = max(round(radius * theta), 3)
    if reach > rows - 2:
        reach = rows - 2
    t = radius * theta / rows
    rr = radius * math.sin(theta)
    m = halving_count(2 * math.pi * rr / t)
    mer_s = np.linspace(0.0, rows, 2001)
    cap = _Cap(
        radius / t,
        float(rows),
        2 * math.pi * np.arange(m) / m,
        mer_s,
        np.minimum(radius / t * np.sin(theta - mer_s * t / radius), rr / t),
    )
    sig, ang, row, first = _cap_rings(cap, reach, gap)
    rings = np.unique(row)
    assert rings.tolist() == list(range(rings.size)) and 0 < first <= rings.size
    prev_sigma, prev_ang = cap.slant, cap.rim_ang
    for j in rings:
        a, s_j = ang[row == j], sig[row == j]
        assert np.all(s_j == s_j[0]) and 0 < s_j[0] < prev_sigma
        assert np.all(np.isin(a, prev_ang)) and 3 <= a.size
        prev_sigma, prev_ang = s_j[0], a
    assert prev_ang.size <= 5


def _cap_worst(points, face_id, fi, truth):
    from sr33.validators.conditions import sample_conditions

    rep = sample_conditions(points, *truth)
    return float(np.nanmax(rep.worst_ratio[face_id == fi])), float(np.nanmax(rep.worst_ratio))


def test_a_hemisphere_on_its_disk_samples_conforming():
    """The hemisphere's cap is laid out in rings from the disk's rim (whose
    columns the disk's rings set) to its pole: the whole sampling meets
    Condition III-ii with the margin (0.85) by the geodesic check; scan rows
    with the stereographic repair left 39% of the samples violating."""
    from sr33.samplers import scanline, shapes

    shape = shapes.from_cad(
        cq.Solid.makeSphere(0.3, angleDegrees1=0, angleDegrees2=90), name="hemisphere"
    )
    s = scanline.scan(shape, target_points=2500)
    kinds = {r["kind"] for r in s.meta["repairs"]}
    assert {"disk rings", "cap rings"} <= kinds
    cap_worst, worst = _cap_worst(
        s.points, s.face_id, 0, (shape.truth_vertices, shape.truth_triangles)
    )
    assert worst <= 0.85, worst
    # every sample of the cap on the sphere, its pole a sample
    d = np.linalg.norm(s.points[s.face_id == 0], axis=1)
    np.testing.assert_allclose(d, 0.3, atol=1e-9)
    assert np.linalg.norm(s.points - [0, 0, 0.3], axis=1).min() < 1e-9


@pytest.mark.slow
@pytest.mark.parametrize("op, r, z0", [("fuse", 0.3, 0.0), ("cut", 0.3, 0.0), ("fuse", 0.25, -0.1)])
def test_a_cap_fused_on_or_cut_into_a_box_samples_conforming(op, r, z0):
    """A dome, a dimple and a low dome: the cap's samples meet Condition
    III-ii with the margin by the geodesic check (before the cap layout,
    about 400 of each cap's samples violated it).  The planar face round
    the cap is not asserted: its repair round a circular hole still leaves
    0.87 to 0.94 there (noted on issue 23)."""
    from sr33.samplers import scanline, shapes

    solid = getattr(_box(), op)(_ball(r, z0))
    shape = shapes.from_cad(solid, name="capped")
    fi = next(k for k, f in enumerate(solid.Faces()) if f.geomType() == "SPHERE")
    s = scanline.scan(shape, target_points=6000)
    cap_worst, _ = _cap_worst(
        s.points, s.face_id, fi, (shape.truth_vertices, shape.truth_triangles)
    )
    assert cap_worst <= 0.85, cap_worst
