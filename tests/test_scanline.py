"""Scan-line sampler: on the surface, lattice spacing, coverage, determinism, errors."""

import functools

import numpy as np
import pytest

cq = pytest.importorskip("cadquery")

from scipy.spatial import cKDTree  # noqa: E402

from sr33.samplers.scanline import SamplingError, scan  # noqa: E402
from sr33.validators.conditions import local_delaunay  # noqa: E402


@pytest.fixture(scope="module")
def box():
    return cq.Workplane().box(1, 1, 1).val()


@pytest.fixture(scope="module")
def cylinder():
    return cq.Workplane().cylinder(1.0, 0.5).val()


def test_box_samples_form_the_square_lattice(box):
    r = scan(box, 0.05)
    p = r.points
    # on the surface: one coordinate is at +-0.5
    assert np.all(np.isclose(np.abs(p), 0.5, atol=1e-12).any(axis=1))
    d, _ = cKDTree(p).query(p, 2)
    assert d[:, 1].min() == pytest.approx(0.05)
    assert d[:, 1].max() == pytest.approx(0.05)
    # 21 x 21 lattice per face, shared edges and corners once: 6*19^2 + 12*19 + 8
    assert p.shape[0] == 6 * 19 * 19 + 12 * 19 + 8
    ld = local_delaunay(p)
    assert ld.max_ratio < np.sqrt(3) / 2
    assert ld.max_degree <= 33


def test_cylinder_samples_lie_on_it_and_cover_it(cylinder):
    h = 0.04
    r = scan(cylinder, h)
    p = r.points
    radial = np.linalg.norm(p[:, :2], axis=1)
    on_side = np.isclose(radial, 0.5, atol=1e-9)
    on_cap = np.isclose(np.abs(p[:, 2]), 0.5, atol=1e-12) & (radial <= 0.5 + 1e-9)
    assert np.all(on_side | on_cap)
    d, _ = cKDTree(p).query(p, 2)
    assert d[:, 1].min() > 0.25 * h
    # coverage: dense points of the true surface are within 1.5 h of a sample
    t = np.linspace(0, 2 * np.pi, 400, endpoint=False)
    zz = np.linspace(-0.5, 0.5, 60)
    side = np.stack(
        [
            0.5 * np.cos(t)[None, :].repeat(60, 0),
            0.5 * np.sin(t)[None, :].repeat(60, 0),
            zz[:, None].repeat(400, 1),
        ],
        -1,
    ).reshape(-1, 3)
    g = np.stack(np.meshgrid(np.linspace(-0.5, 0.5, 80), np.linspace(-0.5, 0.5, 80)), -1).reshape(
        -1, 2
    )
    g = g[np.linalg.norm(g, axis=1) <= 0.5]
    caps = np.vstack([np.c_[g, np.full(len(g), 0.5)], np.c_[g, np.full(len(g), -0.5)]])
    dist, _ = cKDTree(p).query(np.vstack([side, caps]))
    assert dist.max() <= 1.5 * h


def test_features_are_sampled(box):
    r = scan(box, 0.1)
    corners = np.array([[x, y, z] for x in (-0.5, 0.5) for y in (-0.5, 0.5) for z in (-0.5, 0.5)])
    d, _ = cKDTree(r.points).query(corners)
    assert d.max() < 1e-12
    assert r.on_feature.sum() == 8 + 12 * 9
    assert np.all(r.line_id[r.on_feature] == -1)
    assert np.all(r.line_id[~r.on_feature] >= 0)


def test_same_arguments_same_samples(cylinder):
    a = scan(cylinder, 0.05, jitter=0.1, dropout=0.1, seed=3)
    b = scan(cylinder, 0.05, jitter=0.1, dropout=0.1, seed=3)
    c = scan(cylinder, 0.05, jitter=0.1, dropout=0.1, seed=4)
    assert np.array_equal(a.points, b.points)
    assert np.array_equal(a.line_id, b.line_id)
    assert not np.array_equal(a.points, c.points)


def _tolerances(solid) -> list[float]:
    from OCP.BRep import BRep_Tool

    return [BRep_Tool.Tolerance_s(v.wrapped) for v in solid.Vertices()] + [
        BRep_Tool.Tolerance_s(e.wrapped) for e in solid.Edges()
    ]


def _meshed_faces(solid) -> int:
    from OCP.BRep import BRep_Tool
    from OCP.TopLoc import TopLoc_Location

    return sum(
        BRep_Tool.Triangulation_s(f.wrapped, TopLoc_Location()) is not None for f in solid.Faces()
    )


def test_a_solid_scanned_again_gives_the_same_bytes_and_is_left_as_it_was():
    """Scanning must not change the solid: OCC's sections raised the
    tolerances of the face's edges in place (a second scan of this chamfered
    hexagon in the same process moved 49 samples by a last bit) and
    CadQuery's tessellate stored meshes on the faces, reused by later ones."""
    ring = [(0.661, 0.215), (0.217, 0.660), (-0.503, 0.479), (-0.679, 0.149),
            (-0.348, -0.602), (0.266, -0.642)]  # fmt: skip
    prism = cq.Workplane().polyline(ring).close().extrude(0.51).translate((0, 0, -0.255))
    solid = prism.edges(">Z").chamfer(0.06).val()
    before = _tolerances(solid)
    first = scan(solid, target_points=2500, quiet=True, repair=False)
    assert _tolerances(solid) == before
    assert _meshed_faces(solid) == 0
    again = scan(solid, target_points=2500, quiet=True, repair=False)
    fresh = scan(solid.copy(), target_points=2500, quiet=True, repair=False)
    for other in (again, fresh):
        assert first.points.tobytes() == other.points.tobytes()
        assert np.array_equal(first.face_id, other.face_id)


def test_jitter_and_dropout(box):
    clean = scan(box, 0.1)
    noisy = scan(box, 0.1, jitter=0.05, seed=1)
    assert noisy.points.shape == clean.points.shape
    assert 0 < np.abs(noisy.points - clean.points).max() < 0.05
    fewer = scan(box, 0.1, dropout=0.5, seed=1)
    assert 0.4 < fewer.points.shape[0] / clean.points.shape[0] < 0.6


def test_target_points(cylinder):
    r = scan(cylinder, target_points=3000)
    assert 2400 < r.points.shape[0] < 3600


def test_metadata(box):
    r = scan(box, 0.1, ratio=1.2, seed=5)
    m = r.meta
    assert m["spacing"] == pytest.approx(0.1)
    assert m["ratio"] == 1.2 and m["seed"] == 5
    assert m["points"] == r.points.shape[0]
    assert len(m["face_directions"]) == 6


@pytest.mark.parametrize(
    "kwargs, msg",
    [
        ({"spacing": -1.0}, "spacing must be positive, got -1.0"),
        ({"spacing": 0.1, "ratio": 2.0}, r"ratio must be within \[0.6, 1.7\]"),
        ({"spacing": 0.1, "jitter": -0.1}, "jitter must be a finite number >= 0"),
        ({"spacing": 0.1, "dropout": 1.0}, r"dropout must be within \[0, 1\)"),
        ({"spacing": 0.1, "seed": 1.5}, "seed must be an integer"),
        ({"spacing": 0.1, "target_points": 100}, "give either spacing or target_points"),
        ({"spacing": 0.1, "directions": [[0, 0, 0]]}, "directions must be finite, non-zero"),
        ({"spacing": 1e-5}, "the limit is 2,000,000"),
    ],
)
def test_bad_arguments(box, kwargs, msg):
    with pytest.raises(SamplingError, match=msg):
        scan(box, **kwargs)


def test_not_a_shape():
    with pytest.raises(SamplingError, match="shape must be a samplers Shape or a CadQuery shape"):
        scan(np.zeros((3, 3)), 0.1)


def test_even_ends_split_a_wide_end_gap():
    """A lattice anchored off a segment's ends (a star prism's side, its
    columns taken from a slanted edge) drops positions nearer than the
    clearance to an end and splits an end gap wider than twice it: the
    reflex edge's neighbours stood 1.8 h off (ratio 0.875)."""
    from sr33.samplers.scanline import _even_ends

    lattice = np.arange(0.6, 8.0, 1.2)  # 0.6, 1.8, ..., 7.8 on [0, 10]
    out = _even_ends(lattice, 10.0, 0.75)
    np.testing.assert_allclose(out, np.r_[0.9, np.arange(1.8, 7.9, 1.2), 8.9])
    # gaps within twice the clearance stay as they are
    kept = np.arange(1.0, 9.5, 1.0)
    np.testing.assert_allclose(_even_ends(kept, 10.0, 0.75), kept)
    assert _even_ends(np.array([0.2, 9.9]), 10.0, 0.75).size == 0


def _regular_prism(sides: int = 6):
    ring = [(0.5 * np.cos(a), 0.5 * np.sin(a)) for a in np.linspace(0, 2 * np.pi, sides + 1)[:-1]]
    return cq.Workplane().polyline(ring).close().extrude(0.5).translate((0, 0, -0.25)).val()


def test_rows_parallel_to_an_edge_start_on_it():
    # the hexagon's two faces normal to y are cut by planes normal to x, so
    # their vertical edges (x = +-0.25) lie in the rows' planes; the planes
    # dividing the bounding box (x from -0.5) miss them by a quarter step,
    # and the plane just inside each edge was dropped (1.73 h gap)
    from sr33.samplers.scanline import AXES, _aligned_planes, _box_corners, _face_family

    dirs = np.array(AXES)
    solid = _regular_prism(6)
    faces = solid.Faces()
    h = 0.5 / 16.4
    fam = [_face_family(f, dirs, 0.005) for f in faces]
    lo = np.array([-0.5, -np.sqrt(3) / 4, -0.25])
    planes, _ = _aligned_planes(faces, fam, dirs, _box_corners(lo, -lo), h, 1e-7)
    sides = [i for i, f in enumerate(faces) if abs(f.normalAt().y) > 0.999]
    assert len(sides) == 2
    for i in sides:
        assert fam[i] == 0  # planes normal to x
        t0, hf = planes[i]
        q = (np.array([-0.25, 0.25]) - t0) / hf
        np.testing.assert_allclose(q, np.round(q), atol=1e-9)
        assert 0.9 * h < hf < 1.1 * h
    # the default lattice misses those edges: that is what is being mended
    t0, hf = -0.5, 1.0 / round(1.0 / h)
    q = (0.25 - t0) / hf
    assert abs(q - round(q)) > 0.1


def test_rows_down_a_chamfers_slope_divide_it_between_its_long_edges():
    """A 45° chamfer's rows run down its slope, along no axis: their samples
    stand on a lattice anchored on the chamfer's long edges (across the
    rows) that divides the span between them into whole steps
    (:func:`sr33.samplers.scanline._cross_lattice`).  Anchored on the
    bounding box, the last sample before each edge fell within the feature
    clearance and was dropped, leaving rows 1.72 h from both edges
    (rectangles of ratio 0.864; 271 of 5,966 samples broke III-ii)."""
    solid = cq.Workplane().box(1.0, 0.8, 0.5).edges(">Z").chamfer(0.12).val()
    r = scan(solid, target_points=6000, repair=False)
    h = r.meta["spacing"]
    slopes = [f for f in solid.Faces() if 0.5 < abs(f.normalAt().z) < 0.9]
    assert len(slopes) == 4
    for f in slopes:
        n = np.array(f.normalAt().toTuple())
        c = np.array(f.Center().toTuple())
        down = np.cross(n, [0.0, 0.0, 1.0])
        down = np.cross(n, down / np.linalg.norm(down))  # in the face, down its slope
        on = np.abs((r.points - c) @ n) < 1e-9
        levels = np.unique(np.round((r.points[on] - c) @ down / h, 6))
        ends = np.array([(np.array(v.toTuple()) - c) @ down / h for v in f.Vertices()])
        # the long edges' levels are sampled, and the rows' between them
        np.testing.assert_allclose(levels[[0, -1]], [ends.min(), ends.max()], atol=1e-6)
        gaps = np.diff(levels)
        assert gaps.size >= 6
        assert np.all((gaps > 0.9) & (gaps < 1.1)), gaps


def _chamfered_prism(pts, height: float, size: float, turn):
    """A prism over the polygon ``pts``, ``height`` high, its top edges
    chamfered ``size``, turned by ``turn`` (degrees about x, y, z), as the
    generated models' recipes build it."""
    from tests.strategies import moved

    solid = cq.Workplane().polyline(pts).close().extrude(height).val()
    top = solid.BoundingBox().zmax
    edges = [
        e
        for e in solid.Edges()
        if abs(e.Center().z - top) < 1e-6 and abs(e.tangentAt(0.5).z) < 1e-6
    ]
    solid = cq.Solid(solid.chamfer(size, None, edges).Solids()[0].wrapped)
    return moved(solid, turn, [0.0, 0.0, 0.0])


def test_a_prisms_side_takes_one_lattice_between_its_edges():
    """A prism's side runs its rows along its two long edges and takes its
    columns from their samples (:func:`sr33.samplers.scanline._sample_chain`).
    The edge against the chamfer holds the chamfer's row crossings (1.03 h
    apart, 3,000 samples), the base's edge its own equal steps (0.99 h):
    each row took the nearer edge's, and the columns broke off in the
    middle row, where no repair reaches (20 samples at 0.87-0.89 on one
    side).  Now the base's edge follows the chamfer's across the side
    (:func:`sr33.samplers.scanline._side_followers`), and where both edges
    hold crossings every row takes the first's: every row of every side
    stands on one lattice.  The model: the stop 61 survey's prism over 4
    corners, chamfered 0.042, turned upside down."""
    solid = _chamfered_prism(
        [
            (0.5689581110276988, -0.2883166436340236),
            (-0.02003503742544976, 0.6375252280309829),
            (-0.6378399635493184, 7.811286697289372e-17),
            (0.003593601166018955, -0.6378298402640435),
        ],
        0.5681219105962784,
        0.04229502170622691,
        [-6.103515625e-05, 179.99999999999997, 1e-300],
    )
    r = scan(solid, target_points=3000, repair=False)
    h = r.meta["spacing"]
    sides = [
        (k, f) for k, f in enumerate(solid.Faces()) if abs(f.normalAt().z) < 1e-3 and f.Area() > 0.2
    ]
    assert len(sides) == 4
    for k, f in sides:
        n = np.array(f.normalAt().toTuple())
        along = np.cross(n, [0.0, 0.0, 1.0])
        along /= np.linalg.norm(along)
        c = np.array(f.Center().toTuple())
        q = r.points[np.abs((r.points - c) @ n) < 1e-9] - c
        u, z = q @ along, q[:, 2]
        levels, counts = np.unique(np.round(z / h, 2), return_counts=True)
        levels = levels[counts > 5]  # the rows and the long edges (not the short edges' samples)
        assert levels.size >= 12
        # the columns of the row next to one long edge, against every other row's
        cols = [np.sort(u[np.abs(z / h - level) < 0.02])[1:-1] for level in levels]
        for row in cols[2:-1]:
            d = np.abs(row[:, None] - cols[1][None, :]).min(axis=1) / h
            assert np.all(d < 1e-3), (k, np.round(d.max(), 3))


def test_a_chamfers_setback_sets_no_rows_spacing():
    """A chamfer sets its cap's edges back by its size: 0.6 h on the seed
    64 survey's pentagonal prism (chamfer 0.022, 3,000 samples).  Those
    edges lie in planes across the cap's rows, and the lattice anchored on
    them divided the 0.6 h between them into one step: the cap's rows, and
    the samples along its sides' edges (the sides' columns), stood 0.6 h
    apart, and 726 samples broke III-ii.  Edges closer than ``LEAST_SPAN``
    h anchor no step (:func:`sr33.samplers.scanline._anchored`): no face's
    samples stand much closer than h to their nearest neighbour."""
    solid = _chamfered_prism(
        [
            (0.5227438697946817, 0.11198080501979356),
            (0.16520155284738997, 0.5084380995141996),
            (-0.4325032803487288, 0.31423202667517686),
            (-0.34564741962287193, -0.4078341763619749),
            (0.16520155284738985, -0.5084380995141997),
        ],
        0.7362912590080357,
        0.022088737770241073,
        [0.0, -87.96293099179188, 74.73552812761872],
    )
    r = scan(solid, target_points=3000, repair=False)
    h = r.meta["spacing"]
    d = cKDTree(r.points).query(r.points, 2)[0][:, 1] / h
    for k, f in enumerate(solid.Faces()):
        mine = (r.face_id == k) & ~r.on_feature
        if f.Area() > 0.3 and mine.sum() > 50:
            assert np.median(d[mine]) > 0.9, (k, np.median(d[mine]))


@pytest.mark.slow
@pytest.mark.parametrize("sides", [6, 7])
def test_regular_prisms_meet_condition_iii(sides):
    # rows parallel to a side's edges start on them, and rows along an axis
    # are sampled where the planes across it (moved onto those edges) cut
    # them.  Measured 0.827 (6 sides) and 0.828 (7); before: 1.000 on 10.5 %
    # and 2.2 % of the samples
    from sr33.samplers import shapes
    from sr33.validators.conditions import sample_conditions

    s = shapes.from_cad(_regular_prism(sides))
    r = scan(s, target_points=3000)
    rep = sample_conditions(r.points, s.truth_vertices, s.truth_triangles)
    assert not np.isnan(rep.worst_ratio).any()
    assert np.max(rep.worst_ratio) <= 0.85


def test_no_two_samples_closer_than_a_quarter_step():
    # of two close samples an edge sample stays, else the earlier one
    from sr33.samplers.scanline import _distinct

    p = np.array([[0, 0, 0], [0.1, 0, 0], [1, 0, 0], [1, 0, 0], [2, 0, 0], [2.2, 0, 0.0]])
    feature = np.array([False, True, False, False, True, False])
    np.testing.assert_array_equal(_distinct(p, feature, 0.25), [1, 2, 4])
    np.testing.assert_array_equal(_distinct(p[[0, 2, 4]], feature[[0, 2, 4]], 0.25), [0, 1, 2])


@pytest.mark.parametrize("on_top", ["post", "dome", "none"])
def test_a_boxs_side_rows_meet_its_vertical_edges_samples_whatever_stands_on_it(on_top):
    """A cylinder or a dome on a box raises the bounding box, whose lattice
    along the vertical then no longer holds the box's top edges: the rows of
    the box's sides were sampled 0.3 h off the vertical edges' samples
    (0.941 by the geodesic check at the box's top corners).  Anchored on
    the straight edges across the axis, every side sample stands at a
    height of the vertical edges' lattice."""
    import cadquery as cq

    from sr33.samplers import shapes

    solid = cq.Solid.makeBox(1, 1, 0.6, pnt=cq.Vector(-0.5, -0.5, -0.6))
    if on_top == "post":
        solid = solid.fuse(cq.Solid.makeCylinder(0.15, 0.3, pnt=cq.Vector(0.1, 0.05, 0)))
    elif on_top == "dome":
        solid = solid.fuse(cq.Solid.makeSphere(0.25, angleDegrees1=-90, angleDegrees2=90))
    s = scan(shapes.from_cad(solid, name=on_top), target_points=3000, repair=False)
    p = s.points
    corner = np.isclose(np.abs(p[:, 0]), 0.5) & np.isclose(np.abs(p[:, 1]), 0.5)
    edge_z = np.unique(np.round(p[corner, 2], 9))
    assert edge_z[0] == pytest.approx(-0.6) and edge_z[-1] == pytest.approx(0.0)
    m = edge_z.size - 1
    np.testing.assert_allclose(edge_z, -0.6 + 0.6 * np.arange(m + 1) / m, atol=1e-9)
    side = np.isclose(np.abs(p[:, 0]), 0.5) | np.isclose(np.abs(p[:, 1]), 0.5)
    q = (p[side, 2] + 0.6) * m / 0.6
    assert side.sum() > 500
    assert np.abs(q - np.round(q)).max() < 1e-6


def test_thinning_keeps_two_faces_samples_that_stand_near_across_a_fold():
    """Points of two faces that meet along a fold (an acute edge) are
    thinned against each other only within ``across``; any others (one
    face, a shared edge's samples, label -1, faces across a tangent seam)
    within the radius."""
    from sr33.samplers.faces import thin

    pts = np.array([[0.0, 0, 0], [0.43, 0, 0], [0.0, 0.2, 0], [1.0, 0, 0], [1.2, 0, 0]])
    labels = np.array([0, 1, 1, -1, 0])
    folded = {(0, 1), (1, 0)}
    assert thin(pts, 0.5).tolist() == [0, 3]
    # 1 stays (the folded face, 0.43 away), 2 goes (0.2 from 0, within
    # across), 4 goes (0.2 from the edge's sample 3)
    assert thin(pts, 0.5, labels, 0.3, folded).tolist() == [0, 1, 3]
    assert thin(pts, 0.5, labels, 0.3).tolist() == [0, 3]  # no fold: as before


@functools.lru_cache(maxsize=1)
def _acute_prism():
    """A prism over an isosceles triangle of 25° sampled at 3,000, and its
    samples' worst ratios by the geodesic check."""
    from sr33.samplers import shapes
    from sr33.validators.conditions import sample_conditions

    t = np.tan(np.radians(12.5))
    solid = cq.Workplane("XY").polyline([(0, 0), (1.0, -t), (1.0, t)]).close().extrude(0.5).val()
    shape = shapes.from_cad(solid, name="25° prism")
    r = scan(shape, target_points=3000)
    return r, sample_conditions(r.points, shape.truth_vertices, shape.truth_triangles).worst_ratio


def test_the_faces_of_an_acute_edge_keep_their_first_rows():
    """A prism over an isosceles triangle of 25°: the rows of its two
    sides 1 h off the apex edge stand 2 sin(12.5°) h = 0.43 h apart, and
    thinning them at half a spacing left one side's first row 2 h off the
    edge (54 samples breaking Condition III-ii along it, worst 0.896).
    Now both sides keep a row within 1.3 h, and no sample of the edge's
    middle (3 h or more from its ends, where the caps' acute corners are)
    breaks III-ii; nor does any at the ends."""
    pytest.importorskip("potpourri3d")
    from sr33.samplers.scanline import ACROSS

    r, w = _acute_prism()
    h = r.meta["spacing"]
    p = r.points
    off_edge = np.hypot(p[:, 0], p[:, 1])  # the apex edge is the z axis
    # the two sides that meet at the apex edge (the caps lie in z = 0, 0.5)
    sides = [
        f
        for f in np.unique(r.face_id)
        if np.ptp(p[r.face_id == f, 2]) > 0.4 and off_edge[r.face_id == f].min() < 3 * h
    ]
    assert len(sides) == 2
    for f in sides:
        rows = (r.face_id == f) & (r.line_id >= 0)
        assert off_edge[rows].min() < 1.3 * h
    assert cKDTree(p).query(p, 2)[0][:, 1].min() >= ACROSS * h - 1e-12
    middle = (off_edge < 3 * h) & (p[:, 2] > 3 * h) & (p[:, 2] < 0.5 - 3 * h)
    assert middle.sum() > 20 and np.nanmax(w[middle]) < 0.85
    # and at its ends: the sides, repaired after the caps, judge the caps'
    # edge samples there too (0.9943, 8 samples, when their frame held the
    # caps' scan-line samples only; 0.848 through Qhull, 0.8634 through the
    # repair's own Delaunay kernel with its local attempts, stop 63): no
    # sample breaks III-ii there; the margin is the strict xfail below
    assert np.nanmax(w) < np.sqrt(3) / 2


@pytest.mark.xfail(
    strict=True,
    reason="stop 63: at its ends the 25-degree prism's sides are stuck at 0.8634 by the "
    "geodesic check (6 samples, the caps' acute corners and the apex edge's first "
    "samples): below sqrt(3)/2, above the 0.85 margin; 0.848 through Qhull and 0.8394 "
    "without the repair's local attempts, the path decides it",
)
def test_the_faces_of_an_acute_edge_meet_the_margin_at_their_ends():
    """The 25° prism of the test above, at its ends too, below the 0.85 margin."""
    pytest.importorskip("potpourri3d")
    assert np.nanmax(_acute_prism()[1]) < 0.85


def test_a_union_of_boxes_flush_on_one_side_conforms():
    """Two boxes' union, the small one on the big one's top and flush with
    its side (a generated model of the boolean-seam class, seed 61): that
    side is one L-shaped face.  Its frame across the big top's exposed edge
    takes the top's edge samples too; beside the reflex corner the top's
    edge along the small box unfolds onto the side's own edge, and a frame
    that held those samples (0.98 h and 1.95 h up it) made the side's
    repair judge phantom triangles: 0.9427, 4 samples.  They are left out
    (none within 0.5 h of the face's own samples)."""
    pytest.importorskip("potpourri3d")
    from sr33.samplers import shapes
    from sr33.validators.conditions import sample_conditions

    a = 0.4
    big = cq.Solid.makeBox(a, a, a, pnt=cq.Vector(-a / 2, -a / 2, -a / 2))
    small = (
        cq.Solid.makeBox(a, a, a, pnt=cq.Vector(-a / 2, -a / 2, -a / 2))
        .scale(0.6)
        .translate(cq.Vector(-0.08, -0.08, 0.2))
    )
    shape = shapes.from_cad(big.fuse(small), name="boxes flush")
    r = scan(shape, target_points=3000)
    w = sample_conditions(r.points, shape.truth_vertices, shape.truth_triangles).worst_ratio
    assert np.nanmax(w) < 0.845
