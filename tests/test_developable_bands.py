"""Chains of developable faces laid out as one lattice (samplers.bands).

A prism's walls round filleted vertical edges and the chamfer round its
top form strips whose development is flat; the STEP part of
``tests/test_sample_cli.py`` (holes, fillets, a chamfer) had every sample
of its chamfer's cones and 6 of each fillet breaking Condition III-ii
(0.99) before they were laid out together."""

import math

import numpy as np
import pytest
from scipy.spatial import cKDTree

cq = pytest.importorskip("cadquery")

from sr33.samplers import shapes  # noqa: E402
from sr33.samplers.bands import Window, developable_bands  # noqa: E402
from sr33.samplers.faces import steps  # noqa: E402
from sr33.samplers.scanline import scan  # noqa: E402

from .test_sample_cli import _part  # noqa: E402


def _size(solid):
    bb = solid.BoundingBox()
    return math.sqrt(bb.xlen**2 + bb.ylen**2 + bb.zlen**2)


def _bands(solid):
    return developable_bands(solid, _size(solid))


def test_a_filleted_and_chamfered_prism_has_its_walls_and_its_chamfer_as_chains():
    solid = _part().val()
    bands = _bands(solid)
    kinds = [[st.kind for st in b.strips] for b in bands]
    assert kinds == [["PLANE", "CYLINDER"] * 4, ["PLANE", "CONE"] * 4]
    assert all(b.closed for b in bands)
    faces = solid.Faces()
    walls, chamfer = bands
    # the walls run from the bottom (z -0.15) to the chamfer (0.11), the
    # chamfer's cones from the walls' top to the top face (0.15)
    for st in walls.strips:
        assert st.a0[2] == pytest.approx(-0.15) and st.b0[2] == pytest.approx(0.11)
    for st in chamfer.strips:
        assert st.a0[2] == pytest.approx(0.11) and st.b0[2] == pytest.approx(0.15)
    # the loops' faces across: the bottom, the chamfer; the walls, the top
    top = [i for i, f in enumerate(faces) if f.geomType() == "PLANE" and f.Center().z > 0.149]
    bottom = [i for i, f in enumerate(faces) if f.geomType() == "PLANE" and f.Center().z < -0.149]
    assert walls.across == {"a": set(bottom), "b": set(chamfer.faces)}
    assert chamfer.across == {"a": set(walls.faces), "b": set(top)}


def test_one_filleted_edge_makes_an_open_chain_and_sharp_prisms_none():
    one = cq.Workplane("XY").box(1, 0.8, 0.5).edges("|Z and >X and >Y").fillet(0.15).val()
    (band,) = _bands(one)
    assert not band.closed
    assert [st.kind for st in band.strips] == ["PLANE", "CYLINDER", "PLANE"]
    # its ends are the sharp vertical edges of its two walls
    for p, q in band.ends:
        assert abs(p[2] - q[2]) == pytest.approx(0.5)
    for name in ("cube", "hexagonal_prism", "cylinder", "cone", "fillet_box", "cutcube"):
        assert _bands(shapes.build(name).solid) == [], name


def test_a_strips_development_is_an_isometry_joined_at_its_rulings():
    solid = _part().val()
    rng = np.random.default_rng(5)
    for band in _bands(solid):
        for k, st in enumerate(band.strips):
            # points on the face, back and forth through the development
            sig = rng.random(50)
            for t in (0.0, 0.3, 1.0):
                p = st.at(sig, t)
                assert np.abs(st.lift(st.local(p)) - p).max() < 1e-12
            # lengths along a row and along a ruling are kept
            dense = np.linspace(0, 1, 2001)
            row = st.at(dense, 0.5)
            flat = st.local(row)
            arc3 = np.linalg.norm(np.diff(row, axis=0), axis=1).sum()
            arc2 = np.linalg.norm(np.diff(flat, axis=0), axis=1).sum()
            assert arc2 == pytest.approx(arc3, rel=1e-6)  # chords: 3e-8 short
            ruling = st.local(np.vstack([st.a0, st.b0]))
            assert np.linalg.norm(ruling[1] - ruling[0]) == pytest.approx(
                np.linalg.norm(st.b0 - st.a0), rel=1e-12
            )
            # the window's neighbours meet this strip on the rulings they share
            win = Window(band, k)
            nxt = band.strips[(k + 1) % len(band.strips)]
            j = [w[0] for w in win.parts].index(nxt)
            shared = nxt.at(np.zeros(1), 0.4)  # on the ruling the two share
            here = win.develop(win.own, shared)
            there = win.develop(j, shared)
            assert np.abs(here - there).max() < 1e-12


def test_the_walls_of_a_filleted_prism_are_a_lattice_of_rows_and_columns():
    from sr33.samplers.bands import lattice_developable_bands
    from sr33.samplers.samples import Samples

    part = shapes.from_cad(_part())
    r = scan(part, target_points=2500, repair=False)
    h = r.meta["spacing"]
    bag = Samples(r.points, r.line_id, r.face_id, r.on_feature)
    reports, laid = lattice_developable_bands(part.solid, bag, h, part.size, mend=False)
    walls, chamfer = (x["faces"] for x in reports)
    assert laid == set(walls) | set(chamfer)
    on = np.isin(bag.face_id, walls) & ~bag.on_feature
    z = bag.points[on, 2]
    rows = steps(0.26, h)
    levels = -0.15 + 0.26 * np.arange(1, rows) / rows
    # every wall sample stands on one of the rows, and each row goes round
    # with the bottom edge's columns, joined straight up to the top edge's
    assert np.abs(z[:, None] - levels[None]).min(axis=1).max() < 1e-9

    def loop_at(height):
        ring = bag.points[bag.on_feature & (np.abs(bag.points[:, 2] - height) < 1e-9)]
        # the outer loop: 0.1 from the rectangle its fillets round (not the holes' rims)
        dx = np.maximum(np.abs(ring[:, 0]) - 0.4, 0)
        dy = np.maximum(np.abs(ring[:, 1]) - 0.25, 0)
        return ring[np.abs(np.hypot(dx, dy) - 0.1) < 1e-9, :2]

    loop, top = loop_at(-0.15), loop_at(0.11)

    def gaps(ring):
        # the gaps round the loop, in order of the angle about the centre
        # (the walls' loop is star-shaped about it)
        order = np.argsort(np.arctan2(ring[:, 1], ring[:, 0]))
        q = ring[order]
        return np.linalg.norm(np.roll(q, -1, axis=0) - q, axis=1)

    lo = min(gaps(loop).min(), gaps(top).min())
    hi = max(gaps(loop).max(), gaps(top).max())
    for lv in levels:
        row = bag.points[on][np.abs(z - lv) < 1e-9, :2]
        # on the walls (0.1 from the rectangle the fillets round) ...
        dx = np.maximum(np.abs(row[:, 0]) - 0.4, 0)
        dy = np.maximum(np.abs(row[:, 1]) - 0.25, 0)
        assert np.abs(np.hypot(dx, dy) - 0.1).max() < 1e-9
        # ... with as many columns as the loops, about as far apart
        assert min(loop.shape[0], top.shape[0]) <= row.shape[0] <= max(loop.shape[0], top.shape[0])
        g = gaps(row)
        assert lo - 1e-9 <= g.min() and g.max() <= 1.05 * hi
    n_rows = sum((np.abs(z - lv) < 1e-9).sum() for lv in levels)
    assert n_rows == on.sum()
    # the chamfer's cones got rows too
    assert np.isin(bag.face_id, chamfer).sum() > 0


@pytest.mark.slow
def test_the_step_part_meets_condition_three_with_a_margin(tmp_path):
    """Issue 23's STEP line: ``sr33 sample part.step`` at its defaults
    meets the sampler's contract by the geodesic check (0.9928, 87 samples
    violating III-ii, before the chains were laid out)."""
    import json

    from sr33.cli import main
    from sr33.io import read_points
    from sr33.mesh import surface_points
    from sr33.validators.conditions import sample_conditions

    step = tmp_path / "part.step"
    cq.exporters.export(_part(), str(step))
    pts, truth, meta = tmp_path / "p.ply", tmp_path / "t.ply", tmp_path / "m.json"
    argv = ["sample", str(step), "-q", "-o", str(pts), "--truth", str(truth), "--meta", str(meta)]
    assert main(argv) == 0
    part = shapes.from_cad(step)
    p = read_points(pts)
    h = json.loads(meta.read_text())["spacing"]
    rep = sample_conditions(p, part.truth_vertices, part.truth_triangles)
    assert np.nanmax(rep.worst_ratio) <= 0.85
    assert rep.degree.max() <= 33
    dense = surface_points(part.truth_vertices, part.truth_triangles, 20000, seed=2)
    assert cKDTree(p).query(dense)[0].max() <= 1.5 * h
    assert cKDTree(p).query(p, 2)[0][:, 1].min() >= 0.25 * h
