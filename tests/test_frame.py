"""A model turned off the world axes is scanned in its own frame (issue 23 item 6)."""

import numpy as np
import pytest

pytest.importorskip("cadquery")

from scipy.spatial import cKDTree  # noqa: E402

from sr33.samplers import shapes  # noqa: E402
from sr33.samplers.frame import in_frame, model_frame  # noqa: E402
from sr33.samplers.scanline import scan  # noqa: E402

TURNS = {"a": (37.0, -61.0, 118.0), "b": (-150.0, 22.5, 73.0)}


def _turned(name: str, turn: str, **params):
    rx, ry, rz = TURNS[turn]
    return shapes.build(name, rotate_x=rx, rotate_y=ry, rotate_z=rz, **params)


def _rotation(rx: float, ry: float, rz: float) -> np.ndarray:
    """The matrix of turning about x, then y, then z (degrees)."""

    def about(axis, deg):  # Rodrigues: right-handed, as OpenCascade turns
        k = np.eye(3)[axis]
        c, s = np.cos(np.radians(deg)), np.sin(np.radians(deg))
        cross = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
        return c * np.eye(3) + s * cross + (1 - c) * np.outer(k, k)

    return about(2, rz) @ about(1, ry) @ about(0, rx)


def test_every_library_shape_built_upright_keeps_the_world_axes():
    """The frame keeps the scanner's axes unless the model's own line up a
    quarter of the area more: every library shape is built upright (its
    default sampling is the one its tests measure); turned, none keeps them
    but the ball, which has no direction to take."""
    for name in shapes.shape_names():
        upright = shapes.build(name)
        f = model_frame(upright.solid)
        assert f.world, name
        np.testing.assert_array_equal(f.axes, np.eye(3))
        turned = model_frame(_turned(name, "a").solid)
        if f.aligned == 0.0:
            # a ball: no planar or axial face gives a direction, so every turn
            # keeps the world's axes (its rings follow its own axis anyway)
            assert name == "sphere" and turned.world and turned.aligned == 0.0
            continue
        assert not turned.world and turned.world_aligned == 0.0, name
        assert turned.aligned >= f.world_aligned - 1e-9, name


def test_the_frame_turns_with_the_model():
    """The frame's axes are the model's directions: a box turned by R has
    the frame of the upright box turned by R (rows F R^T), whatever the
    turn, so two turns of one model are scanned in one local position."""
    import cadquery as cq

    box = cq.Workplane().box(2.0, 1.0, 0.5).val()
    frames = []
    for rx, ry, rz in TURNS.values():
        r = _rotation(rx, ry, rz)
        solid = box.rotate((0, 0, 0), (1, 0, 0), rx)
        solid = solid.rotate((0, 0, 0), (0, 1, 0), ry).rotate((0, 0, 0), (0, 0, 1), rz)
        f = model_frame(solid)
        assert not f.world and abs(f.aligned - 1.0) < 1e-12
        np.testing.assert_allclose(f.axes @ f.axes.T, np.eye(3), atol=1e-12)
        assert np.linalg.det(f.axes) == pytest.approx(1.0, abs=1e-12)
        frames.append(f.axes @ r)  # the frame in the upright box's coordinates
    np.testing.assert_allclose(frames[0], frames[1], atol=1e-9)
    # z is the heaviest direction (the 2 x 1 faces' normal), x the next
    np.testing.assert_allclose(np.abs(frames[0]), np.eye(3)[[0, 1, 2]], atol=1e-9)


def test_a_turned_cube_samples_as_the_upright_one():
    """A cube turned off the axes: before, 4 % of its samples broke
    Condition III-ii (worst 0.97, 337 s of repair); in its frame it is the
    upright cube's lattice turned (same count, every sample within 1e-9 h
    of a turned upright sample), worst ratio 0.707 by the geodesic check."""
    pytest.importorskip("potpourri3d")
    from sr33.validators.conditions import sample_conditions

    upright = scan(shapes.build("cube"))
    s = _turned("cube", "a")
    r = scan(s)
    h = r.meta["spacing"]
    frame = np.asarray(r.meta["frame"])
    assert not np.allclose(frame, np.eye(3))
    # the samples in frame coordinates are the upright cube's, up to the
    # cube's symmetry (its frame may be a turn of the world's by quarter turns)
    local = r.points @ frame.T
    assert local.shape == upright.points.shape
    perm = np.abs(frame @ _rotation(*TURNS["a"])).round().astype(int)
    back = (local - local.mean(axis=0)) @ (frame @ _rotation(*TURNS["a"]))
    gap, _ = cKDTree(upright.points - upright.points.mean(axis=0)).query(back)
    assert perm.sum() == 3 and gap.max() < 1e-9 * h
    rep = sample_conditions(r.points, s.truth_vertices, s.truth_triangles)
    assert np.nanmax(rep.worst_ratio) < 0.71 and rep.max_degree <= 33


@pytest.mark.parametrize("name", ["wedge", "cylinder", "block_two_holes"])
def test_two_turns_of_a_model_give_one_scan(name):
    """The scan rows do not depend on how the model was placed: wedge
    (slanted faces, an acute edge), cylinder (one direction: its x is the
    seam's side) and block_two_holes (its 0.5 high sides take 12.5 steps of
    0.04: a half-way count the turn's rounding decided, 12 or 13, before
    ``samplers.faces.steps``) under two turns give the same samples in their
    frame, within 1e-9 h, on the same faces.  (The boundary-layer repair that
    follows is a local search: a turn's rounding, 1e-16, moves wedge's
    repaired samples by up to 0.3 h.)"""
    a, b = (scan(_turned(name, t), repair=False) for t in TURNS)
    h = a.meta["spacing"]
    la = a.points @ np.asarray(a.meta["frame"]).T
    lb = b.points @ np.asarray(b.meta["frame"]).T
    assert la.shape == lb.shape
    gap, idx = cKDTree(la).query(lb)
    assert gap.max() < 1e-9 * h
    np.testing.assert_array_equal(a.face_id[idx], b.face_id)
    np.testing.assert_array_equal(a.on_feature[idx], b.on_feature)


def test_in_frame_keeps_the_faces_in_order():
    """face_id of a turned scan names the model's own faces: each sample
    lies on the face it names (in the model's position)."""
    s = _turned("box_hole", "b")
    local = in_frame(s.solid, model_frame(s.solid).axes)
    assert [round(f.Area(), 9) for f in local.Faces()] == [
        round(f.Area(), 9) for f in s.solid.Faces()
    ]
    r = scan(s, repair=False)
    from sr33.samplers.faces import nearest_face

    faces = s.solid.Faces()
    picks = np.linspace(0, r.points.shape[0] - 1, 40).astype(int)
    for i in picks:
        if not r.on_feature[i]:
            assert nearest_face(r.points[i], faces) == r.face_id[i]


def test_rotation_parameters():
    """Every shape takes rotate_x/y/z in degrees; they are recorded only
    when not 0, and bad values are named."""
    assert "rotate_x" not in shapes.build("cube").params
    s = shapes.build("cube", rotate_z=45.0)
    assert s.params == {"side": 1.0, "rotate_z": 45.0}
    lo, hi = s.truth_vertices.min(axis=0), s.truth_vertices.max(axis=0)
    np.testing.assert_allclose(hi - lo, [np.sqrt(2), np.sqrt(2), 1.0], atol=1e-6)
    with pytest.raises(shapes.ShapeError, match=r"rotate_x must be within \[-360, 360\]"):
        shapes.build("cube", rotate_x=400)
    with pytest.raises(shapes.ShapeError, match="allowed: side, rotate_x, rotate_y, rotate_z"):
        shapes.build("cube", turn=3)


def test_a_turned_model_in_its_upright_frame_scans_as_the_upright_one():
    """block_two_holes turned off the axes is scanned in exactly its upright
    position (its frame's z along its holes' axes, x along its length): the
    scan rows are the upright shape's, turned, within 1e-9 h."""
    upright = shapes.build("block_two_holes")
    turned = _turned("block_two_holes", "a")
    a = scan(upright, repair=False)
    b = scan(turned, repair=False)
    back = b.points @ np.asarray(b.meta["frame"]).T
    assert back.shape == a.points.shape
    gap, _ = cKDTree(a.points).query(back)
    assert gap.max() < 1e-9 * a.meta["spacing"]


def test_congruent_faces_are_told_equal_whatever_their_last_bits():
    """repair_planar_faces gives congruent faces (a prism's two ends) one
    answer; their layouts are compared on a grid of 1e-6 h, so that a turned
    model's ends, 1e-14 h apart, are still equal (rounded to 1e-12 absolute,
    a thousand coordinates 4e-16 apart straddle a rounding boundary about
    one time in three), and -0.0 is 0.0."""
    from sr33.samplers.layers import _congruence

    h = 0.04
    rng = np.random.default_rng(0)
    uv = rng.random((500, 2)) * 2.0
    noisy = uv + rng.normal(size=uv.shape) * 1e-14 * h
    assert _congruence(uv, h) == _congruence(noisy, h)
    assert _congruence(np.array([0.0, -0.0]), h) == _congruence(np.array([0.0, 0.0]), h)
    moved = uv.copy()
    moved[7] += 1e-3 * h
    assert _congruence(uv, h) != _congruence(moved, h)
    assert _congruence(0.25, h) == _congruence(0.25 + 1e-16, h)


@pytest.mark.slow
@pytest.mark.xfail(
    strict=True,
    reason=(
        "issue 23: the boundary-layer repair's answer hangs on the last bit of its "
        "input (lattice samples at exactly 3 h of a movable one, Qhull's diagonal in "
        "co-circular cells), and a turn's rounding re-rolls it (stop 38's note)"
    ),
)
def test_a_turned_model_samples_as_the_upright_one_after_repair():
    """The named regression for turned models: block_two_holes' scan rows under
    turn a are the upright ones in its frame (test above), and so should be its
    repaired sampling -- same count, every sample within 1e-9 h of an upright
    one.  Today 1,348 of 4,684 differ (the hole walls and the faces round
    them) and the worst III-ii ratio is 0.984 against the upright's 0.829."""
    upright = scan(shapes.build("block_two_holes"))
    r = scan(_turned("block_two_holes", "a"))
    h = r.meta["spacing"]
    local = r.points @ np.asarray(r.meta["frame"]).T
    assert np.allclose(np.asarray(upright.meta["frame"]), np.eye(3))
    assert local.shape == upright.points.shape
    gap, _ = cKDTree(upright.points).query(local)
    assert gap.max() < 1e-9 * h


def test_mirror_planes_are_the_models_own_and_turn_with_it():
    """A box has its three mid-planes, a regular hexagonal prism its seven
    (six through its axis, one across), a five-pointed star prism six; a
    turned model's mirrors are the upright's turned; a model whose vertices
    no mirror permutes (a box with one side edge cut off and a blind hole
    off its middle) has none."""
    import cadquery as cq

    from sr33.samplers.symmetry import mirror_normals

    box = cq.Workplane().box(2.0, 1.0, 0.5).val()
    rows = sorted(tuple(r) for r in np.abs(mirror_normals(box)).round(12))
    assert rows == [(0.0, 0.0, 1.0), (0.0, 1.0, 0.0), (1.0, 0.0, 0.0)]
    assert mirror_normals(shapes.build("hexagonal_prism").solid).shape == (7, 3)
    upright = mirror_normals(shapes.build("star_prism").solid)
    assert upright.shape == (6, 3)
    turned = mirror_normals(_turned("star_prism", "b").solid)
    back = turned @ _rotation(*TURNS["b"])  # into the upright's coordinates
    cos = np.abs(back @ upright.T)
    assert np.allclose(np.sort(cos.max(axis=1)), 1.0, atol=1e-9)
    lopsided = (
        cq.Workplane()
        .box(1.0, 0.8, 0.6)
        .faces(">Z")
        .workplane()
        .center(0.2, 0.1)
        .hole(0.2, depth=0.3)
        .edges("|Z and >X and >Y")
        .chamfer(0.1)
        .val()
    )
    assert mirror_normals(lopsided).shape == (0, 3)


@pytest.mark.parametrize("name", ["hexagonal_prism", "star_prism", "pyramid"])
def test_a_turned_symmetric_model_is_scanned_in_a_frame_its_symmetry_maps_upright(name):
    """A regular prism or a pyramid turned off the axes takes the frame that
    keeps its mirrors (a hexagon's vertex direction along x, a star's point
    along y, a pyramid's base edges along x and y), not one lined up with a
    side: its scan rows, in that frame, are the upright shape's within 1e-9 h
    (before: a hexagon turned 30 degrees, worst ratio 0.867; a star turned
    20 degrees, 0.999).  The star's frame is the upright's turned by three
    fifths of a turn, where a row's end at one point's tip, on the cap whose
    edges now come in another order, leaves out one gap sample of 4,969."""
    upright = scan(shapes.build(name), repair=False)
    h = upright.meta["spacing"]
    missing = 1 if name == "star_prism" else 0
    for turn in TURNS:
        r = scan(_turned(name, turn), repair=False)
        back = r.points @ np.asarray(r.meta["frame"]).T
        gap, _ = cKDTree(upright.points).query(back)
        assert gap.max() < 1e-9 * h, (name, turn, gap.max() / h)
        gap, _ = cKDTree(back).query(upright.points)
        assert (gap > 1e-9 * h).sum() == missing, (name, turn)
