"""Every library shape, default parameters and spacing: the sampler's promises."""

import numpy as np
import pytest

pytest.importorskip("cadquery")

from scipy.spatial import cKDTree  # noqa: E402

from sr33.samplers import shapes  # noqa: E402
from sr33.samplers.scanline import scan  # noqa: E402
from sr33.validators import mesh_stats  # noqa: E402
from sr33.validators.fidelity import surface_points  # noqa: E402

NAMES = shapes.shape_names()
# default samplings quick enough for `make test`; the others run in `make check`
QUICK = {"cube", "L_sheet", "pyramid", "square_ring", "box_hole", "cylinder", "fillet_box", "torus"}


def by_speed(names):
    """``names`` as parameters, those not in QUICK marked slow; each in the
    xdist group of its shape, so that ``--dist loadgroup`` (``make check``)
    samples a shape once, on one worker, and spreads the shapes."""
    return [
        pytest.param(
            n, marks=[pytest.mark.xdist_group(n)] + ([] if n in QUICK else [pytest.mark.slow])
        )
        for n in names
    ]


class _Samplings(dict):
    """A shape's default sampling, made when a test first asks for it."""

    def __missing__(self, name):
        s = shapes.build(name)
        self[name] = (s, scan(s))
        return self[name]


@pytest.fixture(scope="module")
def sampled():
    return _Samplings()


@pytest.fixture(scope="module")
def tall_pyramid():
    """A pyramid of height 0.8 on its unit base (lateral cells of ratio
    sin(beta) = 0.88 as one lattice): it keeps the scan rows and their
    repair, the path of any face with edges slanted to its rows."""
    s = shapes.build("pyramid", height=0.8)
    return s, scan(s)


@pytest.fixture(scope="module")
def checked(sampled):
    """The geodesic sample-condition check of a shape's default samples, run once."""
    pytest.importorskip("potpourri3d")
    from sr33.validators.conditions import sample_conditions

    done = {}

    def check(name):
        if name not in done:
            s, r = sampled[name]
            done[name] = sample_conditions(r.points, s.truth_vertices, s.truth_triangles)
        return done[name]

    return check


def cad_distance(solid, points):
    import cadquery as cq
    from OCP.BRepExtrema import BRepExtrema_DistShapeShape

    faces = cq.Compound.makeCompound(solid.Faces())
    return np.array(
        [
            BRepExtrema_DistShapeShape(cq.Vertex.makeVertex(*p).wrapped, faces.wrapped).Value()
            for p in points
        ]
    )


@pytest.mark.parametrize("name", by_speed(NAMES))
def test_default_sampling_meets_the_sampler_contract(sampled, name):
    s, r = sampled[name]
    p, h = r.points, r.meta["spacing"]
    assert 2000 <= p.shape[0] <= 20000
    # truth: watertight (or the sheet's one boundary loop), expected Euler characteristic
    t = mesh_stats(s.truth_triangles, s.truth_vertices.shape[0])
    assert t.overloaded_edges == 0
    assert t.euler == s.expected.euler
    assert t.boundary_loops == s.expected.boundary_loops
    # every sample on the CAD surface (a deterministic subset, exact OCC distance)
    pick = p[np.linspace(0, p.shape[0] - 1, 60).astype(int)]
    assert cad_distance(s.solid, pick).max() < 1e-6 * s.size
    # coverage: every point of the truth surface within 1.5 h of a sample
    dense = surface_points(s.truth_vertices, s.truth_triangles, 20000, seed=2)
    assert cKDTree(p).query(dense)[0].max() <= 1.5 * h
    # no two samples closer than h / 4
    d, _ = cKDTree(p).query(p, 2)
    assert d[:, 1].min() >= 0.25 * h


@pytest.mark.parametrize("name", by_speed(["cube", "cone_tip", "L_sheet", "pyramid"]))
def test_same_arguments_identical_arrays(sampled, name):
    s, r = sampled[name]
    again = scan(shapes.build(name))
    assert np.array_equal(r.points, again.points)
    assert np.array_equal(r.face_id, again.face_id)


# the default samplings whose reconstruction is quick enough for `make test`
QUICK_RECONSTRUCTION = QUICK - {"pyramid"}


#: why the wedge's default sampling may reconstruct with holes: its 30-degree
#: edge breaks Condition II-i at any density (validators.conditions.
#: neighbourhood_reach: N(u; k) reaches 3.76 R_u along the surface, 247 of
#: 4,749 samples), so the guarantee does not cover it; the exact selection
#: there ends at its budget (CP-SAT FEASIBLE, 1.25 deterministic s) on stop
#: 62's sampling and on stop 63's, and whether its answer closes depends on
#: the layout along the edge (one of stop 63's: 211 open edges there; the
#: landed one is homeomorphic, 1.06 h off the truth)
_WEDGE_II_I = (
    "the 30-degree wedge breaks Condition II-i (its samples' neighbourhoods reach "
    "across the thin end); the exact selection ends at its budget there"
)


@pytest.mark.parametrize(
    "name",
    [
        pytest.param(
            n,
            marks=[pytest.mark.xdist_group(n)]
            + ([] if n in QUICK_RECONSTRUCTION else [pytest.mark.slow])
            + ([pytest.mark.xfail(strict=False, reason=_WEDGE_II_I)] if n == "wedge" else []),
        )
        for n in NAMES
    ],
)
def test_every_library_shape_reconstructs_homeomorphic(sampled, name):
    """Every library shape's default sampling (they all meet Condition III),
    reconstructed with k = 33: homeomorphic to the truth, no crossing
    triangles, every sample a vertex, Hausdorff distance at most h (issue
    21: pyramid, star_prism and wedge, whose acute edges the RNG cuts across,
    once came out with 139-560 open edges)."""
    from sr33 import reconstruct
    from tests.helpers import check_homeomorphism

    s, r = sampled[name]
    rec = reconstruct(r.points, 33)
    check_homeomorphism(s, r.points, r.meta["spacing"], rec)


@pytest.mark.parametrize("name", by_speed(["L_sheet", "cone", "conebox", "cube", "cutcube"]))
def test_paper_like_shapes_reconstruct_with_their_topology(sampled, name):
    """The paper's five shapes, sampled by default and reconstructed with
    k = 33: no open or overloaded edge beyond the sheet's own boundary, the
    expected Euler characteristic (a cone whose rim slid with its disk's
    repair once came out with 207 open edges)."""
    from sr33 import reconstruct

    s, r = sampled[name]
    rec = reconstruct(r.points, 33)
    st = mesh_stats(rec.triangles, rec.vertices.shape[0])
    assert st.overloaded_edges == 0
    assert st.boundary_loops == s.expected.boundary_loops
    assert st.euler == s.expected.euler
    assert st.components == s.expected.components


@pytest.mark.slow
def test_cone_rim_stays_evenly_spaced(sampled):
    """Only rims of full cylinders slide in the disk's repair: the cone's rings
    start from its rim, so the rim keeps its equal steps."""
    s, r = sampled["cone"]
    p = r.points
    z0 = p[:, 2].min()
    rad = np.linalg.norm(p[:, :2], axis=1)
    on = np.isclose(p[:, 2], z0) & np.isclose(rad, rad[np.isclose(p[:, 2], z0)].max())
    ang = np.sort(np.arctan2(p[on, 1], p[on, 0]))
    gap = np.diff(np.r_[ang, ang[0] + 2 * np.pi])
    assert on.sum() >= 3
    np.testing.assert_allclose(gap, 2 * np.pi / on.sum(), rtol=1e-9)


def _side_edge_positions(face, p, on_feature, h):
    """A prism side's horizontal edges (slanted to every axis): the arc
    lengths, from the top edge's start, of the samples on each (corners
    excluded), the edges' length and direction, and the start."""
    edges = [e for e in face.Edges() if abs(e.tangentAt(0.5).z) < 1e-9]
    top = max(edges, key=lambda e: e.Center().z)
    a = np.array(top.startPoint().toTuple())
    u = np.array(top.endPoint().toTuple()) - a
    length = np.linalg.norm(u)
    u /= length
    if np.abs(u[:2]).min() < 1e-9:
        return None  # along an axis: the end's rows cross it, nothing slides
    out = []
    for e in sorted(edges, key=lambda e: -e.Center().z):
        z = e.Center().z
        t = (p - a) @ u
        foot = a + t[:, None] * u
        foot[:, 2] = z
        on = on_feature & (np.linalg.norm(p - foot, axis=1) < 1e-9)
        out.append(np.sort(t[on & (t > 1e-9) & (t < length - 1e-9)]))
    return out, length, u, a


@pytest.mark.slow
@pytest.mark.parametrize("name, count", [("star_prism", 10), ("wedge", 2)])
def test_sides_columns_follow_their_ends_slid_edge_samples(sampled, name, count):
    """A star prism's and a wedge's sides run along no axis: their rows take
    the samples of their horizontal edges as columns.  Those edges are
    slanted to the ends' rows, and the ends' layer repair slides their
    samples (the wedge's 30° corner had an isosceles triangle there, ratio
    1.0, and a ladder of equal rungs in its narrow strip): the sides'
    columns follow, so every row sample of a side lies at the arc length of
    one of its edge samples, the top edge's equal the bottom's (the two ends
    get one answer), and the gaps, from the corners too, stay between 0.6 h
    and 1.6 h (the repair's soft bounds are 0.75 h and 1.35 h; the star's
    crossings were 1.35 h apart; 0.81 h to 1.46 h measured), where a side's
    cells keep their ratio below √3/2.  The samples moved off the
    crossings' lattice.  A side whose layer along its top or bottom edge
    staggers with the end's slid samples is repaired there afterwards
    (``repair_planar_faces(squares=True)``; the wedge's third side on the
    edge-flip path): its samples within ``LAYER`` h of those edges may
    leave their columns, the report of that repair ends below √3/2, and
    every sample farther in still lies on a column."""
    from sr33.samplers.layers import LAYER

    s, r = sampled[name]
    p, h = r.points, r.meta["spacing"]
    relaid = {x["face"]: x for x in r.meta["repairs"] if x["kind"] == "plane"}
    sides = moved = 0
    for fi, face in enumerate(s.solid.Faces()):
        n = np.array(face.normalAt().toTuple())
        if abs(n[2]) > 1e-9:
            continue  # the two ends
        got = _side_edge_positions(face, p, r.on_feature, h)
        if got is None:
            continue
        (top, bottom), length, u, a = got
        sides += 1
        np.testing.assert_allclose(top, bottom, atol=1e-9 * length)
        gaps = np.diff(np.r_[0.0, top, length])
        assert gaps.min() > 0.6 * h and gaps.max() < 1.6 * h
        moved += int(np.ptp(np.diff(top)) > 1e-6 * h)
        q = p[(r.face_id == fi) & (r.line_id >= 0)]
        if fi in relaid:
            assert relaid[fi]["worst"] < np.sqrt(3) / 2
            z = [e.Center().z for e in face.Edges() if abs(e.tangentAt(0.5).z) < 1e-9]
            q = q[np.abs(q[:, 2, None] - np.array(z)[None]).min(axis=1) > LAYER * h]
        t = (q - a) @ u
        t = t[(t > 1e-9) & (t < length - 1e-9)]
        assert t.size > 50
        assert np.abs(t[:, None] - top[None]).min(axis=1).max() < 1e-9 * length
    assert sides == count
    assert moved == count


def lateral_edge_samples(solid, r):
    """Per edge of ``solid`` along no horizontal direction (a pyramid's
    lateral edges; the base's run along the rows or across them): the edge,
    the arc length along it of every sample, the feature samples strictly
    between its ends, and its length."""
    p = r.points
    for e in solid.Edges():
        a = np.array(e.startPoint().toTuple())
        u = np.array(e.endPoint().toTuple()) - a
        length = np.linalg.norm(u)
        u /= length
        if abs(u[2]) < 1e-9:
            continue
        t = (p - a) @ u
        on = r.on_feature & (np.linalg.norm(p - a - t[:, None] * u, axis=1) < 1e-9)
        yield e, t, on & (t > 1e-9) & (t < length - 1e-9), length


@pytest.mark.slow
def test_slanted_edges_hold_the_ends_of_their_faces_lattice_lines(tall_pyramid):
    """A tall pyramid's lateral edges run slanted to the rows of both faces they
    bound: they are sampled where one face's lattice lines (its rows, or the
    columns along them) cross them, at most 1.45 h apart, so that those
    lines end on edge samples (before the layer repair, which slides them);
    an end gap wider than 1.5 h is split."""
    s = tall_pyramid[0]
    r = scan(s, repair=False)
    p, h = r.points, r.meta["spacing"]
    dirs = np.asarray(r.meta["directions"])
    faces = s.solid.Faces()
    lattice = {}
    for fi, face in enumerate(faces):
        n = np.array(face.normalAt().toTuple())
        d = dirs[r.meta["face_directions"][fi]]
        rows = np.cross(n, d)
        rows /= np.linalg.norm(rows)
        # the face's samples well inside it keep the lattice untouched
        mine = p[(r.face_id == fi) & ~r.on_feature]
        inner = mine[cKDTree(p[r.on_feature]).query(mine)[0] > 4 * h]
        lines = []
        for normal in (d, rows):
            c = inner @ normal
            step = np.min(np.diff(np.unique(np.round(c, 9))))
            lines.append((normal, c[0], step))
        lattice[fi] = lines
    slanted = 0
    for e, t, on, length in lateral_edge_samples(s.solid, r):
        slanted += 1
        q = np.sort(t[on])
        gaps = np.diff(q[1:-1])
        np.testing.assert_allclose(gaps, gaps[0], rtol=1e-9)
        assert h <= gaps[0] <= 1.45 * h
        assert q[0] >= 0.75 * h and length - q[-1] >= 0.75 * h
        adjacent = [fi for fi, f in enumerate(faces) if any(e.isSame(x) for x in f.Edges())]
        middle = p[on][np.argsort(t[on])][1:-1]  # the end samples may be splits
        ends = [
            np.allclose(((middle @ nrm - c0) / step + 0.5) % 1.0, 0.5, atol=1e-6)
            for fi in adjacent
            for nrm, c0, step in lattice[fi]
        ]
        assert any(ends)
    assert slanted == 4


@pytest.mark.slow
def test_edges_slanted_to_both_faces_rows_slide_along_them(tall_pyramid):
    """The layer repair slides the samples of an edge slanted to both its
    faces' rows (a tall pyramid's lateral edges) and judges the triangles across
    it: they move along the edge, off the crossings' lattice, and keep
    between h / 2 and 2 h from each other and from the corners (the
    repair's soft bounds are 0.75 h and 1.35 h; 0.57 h to 1.55 h measured
    here, 1.74 h on another machine: a gap of 2 h still leaves every point
    of the edge within h of a sample)."""
    s, r = tall_pyramid
    h = r.meta["spacing"]
    assert not [x for x in r.meta["repairs"] if x["kind"] == "pyramid lattice"]
    lateral = 0
    for _, t, on, length in lateral_edge_samples(s.solid, r):
        lateral += 1
        q = np.sort(t[on])
        assert q.size > 0.5 * length / h
        gaps = np.diff(np.r_[0.0, q, length])
        # soft bounds (a penalty, not a constraint): 1.74 h was seen on another machine
        assert gaps.min() > 0.5 * h and gaps.max() < 2.0 * h
        # off the crossings' lattice: they moved
        assert (np.abs(np.diff(q, 2)) > 1e-6 * h).any()
    assert lateral == 4


def test_partial_sphere_rows_share_their_columns(sampled):
    """fillet_box's corners are sphere octants; on its plain scan rows (its
    default sampling lays them out otherwise, see tests/test_fillets.py)
    the samples inside each row sit at multiples of one angle about the
    scan direction through the centre, the finest row's angle dividing
    every other (rows sampled from their own starts staggered: 21 bad
    triangles per corner)."""
    s = sampled["fillet_box"][0]
    r = scan(s, repair=False)
    p = r.points
    dirs = np.asarray(r.meta["directions"])
    spheres = 0
    for fi, face in enumerate(s.solid.Faces()):
        if face.geomType() != "SPHERE":
            continue
        spheres += 1
        centre = np.array(face._geomAdaptor().Sphere().Location().Coord())
        d = dirs[r.meta["face_directions"][fi]]
        e1 = np.cross(d, np.eye(3)[int(np.argmin(np.abs(d)))])
        e1 /= np.linalg.norm(e1)
        e2 = np.cross(d, e1)
        angles, steps = [], []
        for line in np.unique(r.line_id[(r.face_id == fi) & (r.line_id >= 0)]):
            q = p[(r.line_id == line) & (r.face_id == fi)] - centre
            th = np.sort(np.arctan2(q @ e2, q @ e1))[1:-1]  # the row's ends lie on the boundary
            if th.size >= 2:
                angles.append(th)
                steps.append(np.diff(th).min())
        assert len(angles) >= 3
        unit = min(steps)
        for th in angles:
            k = th / unit
            np.testing.assert_allclose(k, np.round(k), atol=1e-6)
    assert spheres == 4


@pytest.mark.slow
def test_repaired_boundary_layer_cuts_condition_iii_violations(sampled):
    """Condition III by the validators' geodesic check (DT_M on the refined truth):
    the rows meeting the hole's rims break III-ii for over 1% of the samples;
    after the repair of the boundary layer for none (worst ratio 0.832),
    and III-i (degree <= 33) holds everywhere."""
    pytest.importorskip("potpourri3d")
    from sr33.validators.conditions import sample_conditions

    s, r = sampled["box_hole"]
    plain = scan(s, repair=False)

    def share(points):
        rep = sample_conditions(points, s.truth_vertices, s.truth_triangles)
        assert rep.max_degree <= 33
        return np.count_nonzero(~(rep.worst_ratio < np.sqrt(3) / 2)) / points.shape[0]

    before, after = share(plain.points), share(r.points)
    assert before > 0.01
    assert after == 0


def test_repairs_are_reported_and_congruent_ends_agree(sampled):
    s, r = sampled["box_hole"]
    planes = [x for x in r.meta["repairs"] if x["kind"] == "plane"]
    # the top and bottom faces are congruent: one repair serves both
    assert len(planes) == 2
    assert {**planes[0], "face": 0} == {**planes[1], "face": 0}
    # the hole's wall is the lattice its two (identical) rims span
    wall = [x for x in r.meta["repairs"] if x["kind"] == "cylinder lattice"]
    assert len(wall) == 1 and wall[0]["rows"] == round(s.params["height"] / r.meta["spacing"]) - 1
    p = r.points

    def rim(z):
        on = np.isclose(p[:, 2], z) & np.isclose(np.linalg.norm(p[:, :2], axis=1), 0.25)
        q = p[on, :2]
        return q[np.lexsort(q.T[::-1])]

    np.testing.assert_allclose(rim(0.25), rim(-0.25), atol=1e-12)


@pytest.mark.slow
def test_a_holes_rims_agree_when_its_ends_are_unlike(sampled):
    """cutcube's hole (along y) ends on two faces that differ (one has the
    scoop's arc too), so their repairs slid the rims apart and the wall kept
    its scan rows: 80 DT_M triangles across the rims broke III-ii.  The
    second rim now takes the first one's angles and stays, and the wall is
    the lattice both rims span."""
    s, r = sampled["cutcube"]
    wall = [x for x in r.meta["repairs"] if x["kind"] == "cylinder lattice"]
    assert len(wall) == 1 and wall[0]["rows"] == round(s.params["side"] / r.meta["spacing"]) - 1
    p = r.points
    radius, half = s.params["hole_radius"], s.params["side"] / 2

    def rim(y):
        on = np.isclose(p[:, 1], y) & np.isclose(np.hypot(p[:, 0], p[:, 2]), radius)
        return np.sort(np.arctan2(p[on, 2], p[on, 0]))

    assert rim(half).size == wall[0]["columns"]
    np.testing.assert_allclose(rim(half), rim(-half), atol=1e-12)


@pytest.mark.slow
def test_revolved_body_is_laid_out_in_rings():
    """cone_tip (a cone and a ball meeting smoothly): one ring per meridian step,
    the columns of a ring a subset of the widest ring's, on the surface;
    except round the ball's pole and the cone's apex, whose rings are
    repaired (below)."""
    import math

    s = shapes.build("cone_tip")
    r = scan(s)
    (rep,) = [x for x in r.meta["repairs"] if x["kind"] == "revolved rings"]
    reach = rep["pole_reach"]  # the rows round each pole (layers.POLE_REACHES)
    off = np.hypot(r.points[:, 0], r.points[:, 1]) > 1e-9
    assert int(off.sum()) == rep["samples"]
    far = np.ones(len(r.points), dtype=bool)
    for end in (np.argmin, np.argmax):  # the ball's pole and the cone's apex
        pole = r.points[~off][end(r.points[~off, 2])]
        near = np.linalg.norm(r.points - pole, axis=1) <= (reach - 0.5) * r.meta["spacing"]
        assert (off & near).sum() > 30
        far &= ~near
    off &= far
    z = np.round(r.points[off, 2], 9)
    assert np.unique(z).size == rep["rows"] - 2 * (reach - 1)
    ang = np.arctan2(r.points[off, 1], r.points[off, 0]) % (2 * math.pi)
    step = 2 * math.pi / rep["columns"]
    k = ang / step - ang[0] / step
    assert np.abs(k - np.round(k)).max() < 1e-6  # every column is one of the widest ring's
    # the widest ring halves down to the poles: 3, 4 or 5 times a power of two columns
    # (the ring next to the apex is a designed fan, next to the pole a repaired ring)
    c = rep["columns"]
    while c % 2 == 0 and c > 5:
        c //= 2
    assert c in (3, 4, 5)
    from sr33.validators.fidelity import distance_to_surface

    d = distance_to_surface(r.points, s.truth_vertices, s.truth_triangles)
    assert d.max() < 2e-3 * r.meta["spacing"] * 50  # on the surface, up to the truth's sagitta


@pytest.mark.parametrize("radius, chained", [(0.28, 0.33), (0.45, 0.5), (0.4, 0.5)])
def test_ring_plan_gives_a_disks_rim_the_count_of_its_chain(radius, chained):
    """A disk chained to a wider circle (a chamfered cylinder's top, r - c,
    to its wall, r) takes that circle's count on its rim; inside, its rings
    halve as their own gaps ask, one base count throughout."""
    from sr33.samplers.chart import halving_count
    from sr33.samplers.disks import ring_plan

    h = 0.025
    count = halving_count(2 * np.pi * chained / h)
    t, rings = ring_plan((radius,), h, count=count)
    own_t, own = ring_plan((radius,), h)
    assert t == own_t and len(rings) == len(own)
    r = np.array([x for x, _ in rings])
    c = np.array([n for _, n in rings])
    assert c[0] == count
    assert np.all((c[:-2] == c[1:-1]) | (c[:-2] == 2 * c[1:-1]))
    assert 3 <= c[-1] <= 5 and all(n % c[-1] == 0 for n in c)
    gaps = 2 * np.pi * r[1:-1] / c[1:-1]
    assert gaps.min() >= 0.75 * t - 1e-12 and gaps.max() < 1.5 * t


@pytest.mark.parametrize("gap", [0.75, 0.7, 0.8])
@pytest.mark.parametrize(
    "radii, h", [((0.5,), 0.025), ((0.5,), 0.03), ((0.5, 0.3), 0.02), ((0.35, 0.05), 0.02)]
)
def test_ring_plan_halves_its_columns_towards_the_centre(radii, h, gap):
    from sr33.samplers.disks import ring_plan

    t, rings = ring_plan(radii, h, gap)
    r = np.array([x for x, _ in rings])
    c = np.array([n for _, n in rings])
    np.testing.assert_allclose(-np.diff(r), t)
    assert abs(r[0] - radii[0]) < 1e-12
    assert abs(r[-1] - (radii[1] if len(radii) > 1 else t)) < 1e-9
    # one base count, halving ring by ring (a ring's columns are every other of the next one out)
    base = c[-1]
    assert all(n % base == 0 and (n // base) & (n // base - 1) == 0 for n in c)
    inner = slice(None) if len(radii) > 1 else slice(None, -1)  # not the ring round a centre
    d = c[inner]
    assert np.all((d[:-1] == d[1:]) | (d[:-1] == 2 * d[1:]))
    gaps = 2 * np.pi * r / c
    assert gaps[inner].min() >= gap * t - 1e-12
    assert gaps[inner].max() < 2 * gap * t  # a ring halves before its gap doubles it
    if len(radii) == 1:
        assert 3 <= base <= 5  # round a disk's centre: a chord longer than the sides


def test_a_disk_layout_tries_other_ring_plans_until_one_meets_the_margin(monkeypatch):
    """The repair behind a ring layout is a local search whose end depends on
    where the rings halve: ``_layout`` tries the ring plans of ``HALVE_GAPS``
    and then those with ``RINGS_ADDED`` in turn, each distinct plan once, keeps
    the first below ``LAYOUT_GOOD`` and otherwise the lowest (the first of
    equal ones)."""
    from sr33.samplers import disks

    radii = (10.0,)
    order = [(e, g) for e in disks.RINGS_ADDED for g in disks.HALVE_GAPS]

    def plan(e, g):
        t, rings = disks.ring_plan(radii, 1.0, g, e)
        return round(t, 12), tuple(c for _, c in rings)

    distinct = [k for i, k in enumerate(order) if plan(*k) not in {plan(*x) for x in order[:i]}]
    assert len(distinct) > len(disks.RINGS_ADDED)  # the gaps do change the plan

    def fake(worst_of):
        seen = []

        def layout_with(radii, h, gap, extra=0, count=None):
            seen.append((extra, gap))
            w = worst_of(len(seen) - 1)
            return disks._Layout(
                np.zeros((1, 2)), np.zeros(1, bool), np.zeros(1, int), 0, w, w, gap, extra
            )

        monkeypatch.setattr(disks, "_layout_with", layout_with)
        return seen

    # the third plan is the first good one: it is kept and the search stops
    seen = fake(lambda i: [0.90, 0.95, 0.83][i] if i < 3 else 0.5)
    lay = disks._layout(radii, 1.0)
    assert seen == distinct[:3] and (lay.extra, lay.gap, lay.worst) == (*distinct[2], 0.83)
    # none good: every distinct plan tried, the lowest kept (the first of equal ones)
    seen = fake(lambda i: 0.86 if i in (1, 3) else 0.9)
    lay = disks._layout(radii, 1.0)
    assert seen == distinct and (lay.extra, lay.gap, lay.worst) == (*distinct[1], 0.86)
    # the first plan good: nothing else is tried
    seen = fake(lambda i: 0.8)
    assert disks._layout(radii, 1.0).gap == disks.HALVE_GAP and seen == [(0, disks.HALVE_GAP)]


def test_a_disk_layout_settles_its_near_cocircular_cells(monkeypatch):
    """A repaired ring layout whose Delaunay triangles meet the margin can
    keep a cell nearly on one circle whose other diagonal breaks it (a disk
    of radius 9.55 h: 0.807 one way, 0.91 the other); the settle moves a
    corner by a few hundredths of t, rims fixed, until both diagonals meet
    it, and the first ring plan is kept.  Judged on every radius of a few
    whose raw layout has such a cell (which do hangs on the repair's path:
    8.12 h had one until the repair's triangles were mended by flips), at
    least one of them."""
    from scipy.spatial import Delaunay, cKDTree

    from sr33.mesh import flipped_ratios
    from sr33.samplers import disks

    judged = 0
    for radius in (6.96, 9.55, 9.92):
        radii = (radius,)
        lay = disks._layout(radii, 1.0)
        with monkeypatch.context() as m:
            m.setattr(disks, "SETTLE_ROUNDS", 0)
            raw = disks._layout_with(radii, 1.0, lay.gap, lay.extra)
        if not raw.either >= disks.LAYOUT_GOOD > raw.worst:
            continue  # no cell the settle is for
        judged += 1
        assert (lay.gap, lay.extra) == (disks.HALVE_GAPS[0], 0) and lay.settled >= 1
        assert lay.either < disks.LAYOUT_GOOD and lay.worst < disks.LAYOUT_GOOD
        # judged afresh: both diagonals of every near-cocircular cell below the margin
        tri = Delaunay(lay.uv).simplices
        assert flipped_ratios(lay.uv, tri, disks.COCIRCULAR).max() < disks.LAYOUT_GOOD
        # the same samples, a few moved a little, the rims not at all
        t, _ = disks.ring_plan(radii, 1.0, lay.gap, lay.extra)
        assert lay.uv.shape == raw.uv.shape and np.array_equal(lay.rim, raw.rim)
        moved = np.linalg.norm(lay.uv - raw.uv, axis=1)
        assert 1 <= np.count_nonzero(moved) <= lay.settled and not moved[lay.rim].any()
        assert moved.max() <= max(disks.SETTLE_STEPS) * t + 1e-12
        assert cKDTree(lay.uv).query(lay.uv, 2)[0][:, 1].min() >= disks.SETTLE_CLOSEST * t - 1e-12
    assert judged >= 1


@pytest.mark.slow
def test_disk_layouts_meet_condition_iii_at_every_radius():
    """Every disk from 4 h to 34 h in radius (not only the library's): its
    rings' Delaunay triangles stay below 0.85 (HALVE_GAP alone left 6 of 30
    radii between 0.887 and 0.978; 4.5 h needed a ring more), and so do
    their near-cocircular cells with the other diagonal (without the settle,
    7.09 h, 19.45 h and 20.48 h kept 0.842 or more at every ring plan)."""
    from scipy.spatial import Delaunay

    from sr33.mesh import flipped_ratios, triangle_ratios
    from sr33.samplers.disks import COCIRCULAR, _layout

    for radius in [4.5, *np.round(np.arange(4.0, 34.0, 2.06), 3)]:
        lay = _layout((float(radius),), 1.0)
        tri = Delaunay(lay.uv).simplices
        ratio = triangle_ratios(lay.uv, tri)
        assert ratio.max() < 0.85, (radius, ratio.max())
        assert ratio.max() == pytest.approx(lay.worst) and lay.either >= lay.worst
        # near-cocircular cells with their other diagonal too (settled)
        flipped = flipped_ratios(lay.uv, tri, COCIRCULAR)
        assert np.r_[flipped, 0.0].max() < 0.85, (radius, flipped.max())


@pytest.mark.parametrize("name", by_speed(["cone", "cylinder", "square_ring"]))
def test_round_faces_are_rings_without_bad_triangles(sampled, name):
    """Disks and annuli are laid out in rings: in the plane, every Delaunay
    triangle of the face meets Condition III-ii (a plane's DT_M is its
    Delaunay triangulation), and a cylinder's two rims carry the same angles."""
    from scipy.spatial import Delaunay

    s, r = sampled[name]
    rings = [x for x in r.meta["repairs"] if x["kind"] in ("disk rings", "annulus rings")]
    assert len(rings) == {"cone": 1, "cylinder": 2, "square_ring": 2}[name]
    p = r.points
    for z in np.unique(np.round(p[r.on_feature, 2], 9)):
        flat = np.isclose(p[:, 2], z)
        if flat.sum() < 100:
            continue  # the apex
        uv = p[flat, :2]
        tri = Delaunay(uv).simplices
        rad = np.linalg.norm(uv[tri].mean(axis=1), axis=1)
        inner = np.linalg.norm(uv, axis=1).min()
        tri = tri[rad > inner]  # not across an annulus' hole
        side = np.sort(np.linalg.norm(uv[tri] - uv[np.roll(tri, 1, axis=1)], axis=2), axis=1)
        assert (side[:, 1] / side[:, 2]).max() < np.sqrt(3) / 2
    if name == "cylinder":
        from sr33.samplers.disks import ring_plan

        walls = [x for x in r.meta["repairs"] if x["kind"] == "cylinder lattice"]
        rim_count = ring_plan((s.params["radius"],), r.meta["spacing"])[1][0][1]
        assert len(walls) == 1 and walls[0]["columns"] == rim_count
        half = s.params["height"] / 2
        rims = []
        for z in (-half, half):
            q = p[r.on_feature & np.isclose(p[:, 2], z)]
            rims.append(np.sort(np.arctan2(q[:, 1], q[:, 0])))
        assert rims[0].size == rim_count
        np.testing.assert_allclose(rims[0], rims[1], atol=1e-12)


@pytest.mark.parametrize(
    "name",
    by_speed(["cube", "L_sheet", "torus"])
    + [
        pytest.param(n, marks=pytest.mark.slow)
        for n in NAMES
        if n not in ("cube", "L_sheet", "torus")
    ],
)
def test_shapes_meet_condition_iii(checked, name):
    """No sample of any library shape's default sampling breaks Condition
    III by the geodesic check, with issue 23's margin: every sample in a
    DT_M triangle (none left out, as a cone's apex was when its cell's
    corners fell between the truth's vertices) and every ratio at or below
    0.85 (the condition wants below √3/2 ≈ 0.866; the margin keeps the
    verdict from flipping between machines).  Worst ratios measured in stop
    34 (cylinder and fillet_box in 35): cube, L_sheet: plain lattices
    (0.707); box_hole and cylinder: boundary layers and walls (0.832,
    0.820); square_ring: annuli in rings,
    walls as the lattice of their rims (0.805); pyramid: one lattice, the
    ties across its lateral edges decided (0.830; 0.866 with the ties left,
    2.09% violating with the scan rows at height 0.8); cone: a designed fan
    of two spokes round the apex, rings halving by design (0.832; 0.859
    halving by their gaps); sphere and torus: rings halving where their gap
    is 0.707 row steps (0.836, 0.830; 0.864 and the torus's scan rows
    1.000 before); block_two_holes: its one near tie decided by the angle
    test (0.829); cone_tip: an uneven fan of three spokes round its apex,
    its ball's rings halving by design (0.845; 0.862 where they halved
    wherever the gap fell below 0.8 row steps); conebox: its cone's rings
    halving by design, its top's boundary layer retried wider from a chart
    ratio of 0.85 (0.843; 0.853 retried only from √3/2, 0.865 before the
    cone's design); wedge: its ends' edge samples slide and its sides'
    columns follow (0.825; 1.20% violating with them fixed); star_prism:
    the same, and the angle its caps' repair left at a reflex corner split
    by a sample on its bisector (0.829; 2.93% violating with its edge
    samples fixed); cutcube: its scoop's rows h apart along the sphere and
    the scoop repaired on its stereographic map, framed by the cube's faces
    across its rims (0.846; 0.60% violating with the scan rows);
    fillet_box: its pieces' lattices continued across the seams, its
    corner octants in latitude rows repaired on their map (0.830; 2.22%
    violating with the scan rows)."""
    rep = checked(name)
    assert rep.max_degree <= 33
    assert np.isfinite(rep.worst_ratio).all()
    assert rep.worst_ratio.max() <= 0.85


@pytest.fixture(scope="module")
def cutcube_6000():
    """The geodesic Condition III report of cutcube sampled at 6,000
    samples (its default spacing gives 7,523)."""
    pytest.importorskip("potpourri3d")
    from sr33.validators.conditions import sample_conditions

    s = shapes.build("cutcube")
    r = scan(s, target_points=6000)
    return sample_conditions(r.points, s.truth_vertices, s.truth_triangles)


@pytest.mark.slow
@pytest.mark.xdist_group("cutcube")
def test_cutcube_at_6000_samples_keeps_condition_iii(cutcube_6000):
    """A library shape sampled at a density other than its default keeps
    Condition III-ii.  Stop 68: cutcube at 6,000 had 71 samples at up to
    0.9925 along the square edges of the three cube faces the scoop cuts,
    whose lattices stagger against the edges' samples there; a face with
    an arc had its square edges left out of the repair (stop 69: 0.8565,
    none breaking III-ii)."""
    rep = cutcube_6000
    assert rep.max_degree <= 33
    assert rep.worst_ratio.max() < np.sqrt(3) / 2


@pytest.mark.slow
@pytest.mark.xdist_group("cutcube")
@pytest.mark.xfail(
    strict=True,
    reason="stop 69: cutcube at 6,000 samples keeps III-ii but not the margin: 0.8565 at "
    "six samples on the face y = 0.5, 2 to 3 h from the scoop's arc (the chart's "
    "triangles against the geodesic check's); issue 23 asks the margin of the defaults only",
)
def test_regression_cutcube_at_6000_samples_meets_condition_iii(cutcube_6000):
    """... and with the margin of 0.85, as a user choosing ``target_points``
    expects (the general sampler's promise); cutcube at 6,000 does not."""
    rep = cutcube_6000
    assert rep.worst_ratio.max() <= 0.85


@pytest.mark.slow
@pytest.mark.parametrize(
    "name",
    [pytest.param(n, marks=pytest.mark.xdist_group(n)) for n in ("hexagonal_prism", "fillet_box")],
)
def test_a_spacing_changed_in_its_last_bits_keeps_the_margin(name):
    """The verdict must not hinge on the last bits (issue 23's margin, the
    brief's determinism): the spacing times 1 +- 1e-12, far below anything
    a model, a scanner or another machine could tell from h, still samples
    with every ratio at or below 0.85.  Measured in stop 43
    (``bench/perturbation.py``): these two moved by up to 0.011 (0.820 ->
    0.822 and 0.831; fillet_box 0.830 -> 0.830 and 0.832); cutcube (0.846
    -> 0.866 and 0.961), conebox (0.843 -> 0.853 and 0.855), star_prism
    (0.829 -> 0.882 and 0.880) and wedge (0.825 -> 0.882 and 0.829) do not
    keep it yet (block_two_holes 0.829 -> 0.848 both ways, cone 0.832 ->
    0.845 one way): the repair's local search ends elsewhere once qhull
    splits a lattice's exact ties differently (docs/sampler.md, stop 43)."""
    from sr33.validators.conditions import sample_conditions

    s = shapes.build(name)
    for eps in (1e-12, -1e-12):
        r = scan(s, spacing=s.default_spacing * (1.0 + eps))
        rep = sample_conditions(r.points, s.truth_vertices, s.truth_triangles)
        assert np.isfinite(rep.worst_ratio).all()
        assert rep.worst_ratio.max() <= 0.85, (eps, float(rep.worst_ratio.max()))


@pytest.mark.slow
def test_rings_round_a_pole_and_an_apex_are_repaired(sampled, checked):
    """The rings round the cone tip's ball's pole halve like a disk's, and
    where they halved 54 intrinsic Delaunay triangles broke Condition III-ii
    (2.32% of the samples); repaired on the pole's azimuthal map, none is
    left.  Round the cone's apex (a 126° development, where no evenly spaced
    fan qualifies) the rings ended in 3 equal spokes (0.60% of the samples
    broke III-ii there); now the ring round the apex is an uneven fan of 3
    spokes and the rings outside it are repaired on the glued development:
    no sample within POLE_REACH steps of either end breaks the condition
    (nor any other: see test_shapes_meet_condition_iii)."""
    import math

    s, r = sampled["cone_tip"]
    reps = {x["kind"]: x for x in r.meta["repairs"] if x["kind"] in ("pole", "apex")}
    (rings,) = [x for x in r.meta["repairs"] if x["kind"] == "revolved rings"]
    assert set(reps) == {"pole", "apex"}
    assert reps["pole"]["added"] + reps["pole"]["removed"] > 0
    assert reps["apex"]["margin_bad"] == 0 and reps["apex"]["margin_worst"] < 0.85
    # and by the cone's own Delaunay triangles round the apex (stop 51): 0.8265
    assert 0.8 < reps["apex"]["apex_worst"] < 0.835
    h = r.meta["spacing"]
    on_axis = np.hypot(r.points[:, 0], r.points[:, 1]) < 1e-9
    apex = r.points[on_axis][np.argmax(r.points[on_axis, 2])]
    # the fan: the apex's three nearest samples, two at one distance and one nearer
    d = np.linalg.norm(r.points - apex, axis=1)
    spokes = np.sort(d[~on_axis])[:3]
    np.testing.assert_allclose(spokes[0] / spokes[2], 0.76, atol=1e-9)
    np.testing.assert_allclose(spokes[1], spokes[2], rtol=1e-9)
    assert 0.9 * h < spokes[2] < 1.1 * h
    rep = checked("cone_tip")
    bad = ~(rep.worst_ratio < np.sqrt(3) / 2)
    for end in (np.argmin, np.argmax):
        pole = r.points[on_axis][end(r.points[on_axis, 2])]
        near = np.linalg.norm(r.points - pole, axis=1) < (rings["pole_reach"] + 2) * h
        # (the ball's last designed halving stands two steps outside its pole's rim:
        # 139 samples within reach, where rings halving anywhere left 150-odd)
        assert near.sum() > 100 and not bad[near].any()
    assert math.isfinite(rep.worst_ratio[on_axis].max())  # apex and pole in triangles
    # the ball's pole was chosen judged with its rings POLE_ZONE steps past
    # the repaired ones (stop 52), by the figure the geodesic check reads there
    from sr33.samplers.layers import POLE_ZONE, ZONE_GOOD

    assert rings["pole_zone_worst"] < ZONE_GOOD
    ball = r.points[on_axis][np.argmin(r.points[on_axis, 2])]
    zone = np.linalg.norm(r.points - ball, axis=1) < (rings["pole_reach"] + POLE_ZONE - 1) * h
    assert abs(rep.worst_ratio[zone].max() - rings["pole_zone_worst"]) < 0.005


@pytest.mark.parametrize("name", by_speed(["torus", "sphere", "cone_tip", "cone"]))
def test_bodies_of_revolution_meet_condition_iii_with_a_margin(sampled, checked, name):
    """Rings of a body of revolution, and of a cone from its rim, halve
    where their gap is ``HALVING_GAP`` row steps, with the steps of
    ``HALVING_STEPS`` round them (samplers.rings): the geodesic check's
    worst ratio stays at 0.85 or below (issue 23's margin), where halving
    wherever the gap fell below 0.8 row steps (0.75 h on a cone) gave the
    ball 0.864 (352 samples above 0.85), cone_tip 0.862, the cone 0.859 (209
    samples) and the torus's scan rows 1.000 (3,221 samples breaking III-ii)."""
    s, r = sampled[name]
    rep = checked(name)
    assert rep.max_degree <= 33
    assert np.nanmax(rep.worst_ratio) <= 0.85
    assert np.isfinite(rep.worst_ratio).all()  # every sample in a DT_M triangle
    kind = "cone rings" if name == "cone" else "revolved rings"
    assert len([x for x in r.meta["repairs"] if x["kind"] == kind]) == 1


@pytest.mark.parametrize("name", by_speed(["cylinder", "square_ring", "cone_tip", "torus"]))
def test_ring_laid_shapes_reconstruct_with_their_topology(sampled, name):
    from sr33 import reconstruct

    s, r = sampled[name]
    rec = reconstruct(r.points, 33)
    st = mesh_stats(rec.triangles, rec.vertices.shape[0])
    assert (st.open_edges, st.overloaded_edges) == (0, 0)
    assert (st.euler, st.components) == (s.expected.euler, s.expected.components)


@pytest.mark.slow
def test_slanted_edge_layers_are_edited(sampled):
    """The wedge's two triangular ends meet their sides along edges slanted
    15 degrees to the rows, whose samples slide: the two ends get one
    answer (reported for each; one end has a gap-filling sample more),
    with removals and insertions (at most 160 a face), and no triangle is
    left at or above √3/2 (86 were above the repair's margin, relaxing the
    layer alone with the edge samples fixed).  A side may be repaired along
    its edges too (its layer staggering with an end's slid samples): its
    report is no end's and its repair moves samples only."""
    from sr33.samplers.layers import FOLLOW_EDITS

    s, r = sampled["wedge"]
    ends = {i for i, f in enumerate(s.solid.Faces()) if len(f.Edges()) == 3}  # the triangles
    assert len(ends) == 2
    reps = [x for x in r.meta["repairs"] if x["kind"] == "plane"]
    planes = [x for x in reps if x["face"] in ends]
    assert len(planes) == 2
    sides = [x for x in reps if x not in planes]
    assert all(x["added"] == x["removed"] == 0 and x["worst"] < 0.85 for x in sides)
    # one answer: the same samples after it (one end had a gap-filling sample more)
    kept = [(x["samples"] - x["removed"], x["added"], x["bad"], x["worst"]) for x in planes]
    assert kept[0] == kept[1]
    assert all(0 < x["added"] + x["removed"] <= FOLLOW_EDITS for x in planes)
    assert max(x["worst"] for x in planes) < np.sqrt(3) / 2


@pytest.mark.slow
def test_edges_whose_samples_are_far_apart_stay():
    """A 90° wedge's ends cross its sides' edges 1.43 h apart, beyond the
    1.35 h the repair keeps between sliding samples: sliding, most gaps were
    squeezed to that and the excess left in a few gaps of 2 h, whose
    columns broke III-ii all along the sides (7.9% of the samples).  Those
    edges stay: their samples keep the crossings' lattice, and no sample
    breaks Condition III."""
    pytest.importorskip("potpourri3d")
    from sr33.validators.conditions import sample_conditions

    s = shapes.build("wedge", angle=90.0)
    r = scan(s)
    p, h = r.points, r.meta["spacing"]
    checked_sides = 0
    for face in s.solid.Faces():
        n = np.array(face.normalAt().toTuple())
        if abs(n[2]) > 1e-9:
            continue
        got = _side_edge_positions(face, p, r.on_feature, h)
        if got is None:
            continue
        (top, bottom), _, _, _ = got
        checked_sides += 1
        np.testing.assert_allclose(np.diff(top), 1.43 * h, rtol=0.01)
        np.testing.assert_allclose(top, bottom, atol=1e-9)
    assert checked_sides == 2
    rep = sample_conditions(p, s.truth_vertices, s.truth_triangles)
    assert np.all(rep.worst_ratio < np.sqrt(3) / 2)


def test_apex_fans_meet_condition_iii_with_their_spokes_delaunay():
    """A designed fan round a cone's apex: its triangles' ratios below
    FAN_RATIO and every spoke a Delaunay edge with margin; 3 or 4 spokes
    where they can be had; in the band round 120° where no evenly spaced
    fan qualifies (3 equal spokes 40° apart make ratio-1 triangles), 3
    spokes unevenly spaced, their ends no nearer than FAN_CHORD; none below
    83° nor at 115° and 116°."""
    import math

    from sr33.samplers.layers import FAN_ANGLES, FAN_CHORD, FAN_RATIO, _apex_fan, _fan_figures

    uneven = []
    for degrees in range(60, 361, 5):
        theta = math.radians(degrees)
        fan = _apex_fan(theta)
        if fan is None:
            assert degrees < 83 or 115 <= degrees <= 116
            continue
        gaps = theta * np.diff(np.r_[fan.at, 1.0])
        ratio, angles, chord = _fan_figures(fan.radii[None], gaps[None])
        assert ratio[0] < FAN_RATIO and angles[0] < FAN_ANGLES
        assert fan.radii[0] == 1.0 and fan.radii.min() >= 0.4
        if degrees >= 150:
            assert fan.radii.size >= 3  # an apex of degree 2 only where nothing else works
        if np.ptp(gaps) > 1e-9:
            uneven.append(degrees)
            assert fan.radii.size == 3 and chord[0] >= FAN_CHORD
    assert uneven == [120, 125, 130, 135, 140]
    fan = _apex_fan(math.radians(113.84))
    np.testing.assert_allclose(fan.radii, [1.0, 0.66])
    np.testing.assert_allclose(fan.at, [0.0, 0.5])
    assert _apex_fan(math.radians(181.39)).radii.size == 4
    # cone_tip's development: two long spokes 82 degrees apart, a short one between
    fan = _apex_fan(math.radians(126.0))
    np.testing.assert_allclose(fan.radii, [1.0, 1.0, 0.76])
    np.testing.assert_allclose(fan.at * 126.0, [0.0, 82.0, 104.0])


def _fan_figures_by_numpy(radii, phi):
    """The figures of fans as numpy expressions over all of them (the form
    the kernels of ``samplers._fan_kernels`` replaced)."""
    from sr33 import libm

    a, b = radii, np.roll(radii, -1, axis=1)
    c = np.sqrt(a * a + b * b - 2 * a * b * np.cos(phi))
    side = np.sort(np.stack([a, b, c], axis=2), axis=2)
    ratio = (side[..., 1] / side[..., 2]).max(axis=1)
    at_next = libm.arccos(np.clip((b * b + c * c - a * a) / (2 * b * c), -1, 1))
    at_this = libm.arccos(np.clip((a * a + c * c - b * b) / (2 * a * c), -1, 1))
    opposite = at_next + np.roll(at_this, 1, axis=1)
    return ratio, np.degrees(opposite.max(axis=1)), c.min(axis=1)


@pytest.mark.parametrize("spokes", [2, 3, 4, 5])
def test_fan_kernels_give_the_numpy_figures_bit_for_bit(spokes):
    """The fan search's kernels (``_fan_figures`` and the uneven search's
    rows) give the very bits of the numpy form, on random fans and on the
    uneven search's grid: the fan chosen cannot depend on which form ran."""
    import math

    from sr33.samplers._fan_kernels import uneven_figures
    from sr33.samplers.layers import _fan_figures

    rng = np.random.default_rng(spokes)
    radii = np.c_[np.ones(4000), rng.uniform(0.4, 1.0, (4000, spokes - 1))]
    phi = rng.uniform(0.1, 2 * math.pi / spokes, (4000, spokes))
    for got, want in zip(_fan_figures(radii, phi), _fan_figures_by_numpy(radii, phi)):
        assert np.array_equal(got, want)
    theta = 0.6 + spokes * 0.25  # developments of 49 to 109 degrees
    for got, want in zip(
        _fan_figures(radii, theta / spokes), _fan_figures_by_numpy(radii, theta / spokes)
    ):
        assert np.array_equal(got, want)
    g1, g2 = (x.ravel() for x in np.meshgrid(np.linspace(0.1, 0.5, 7), np.linspace(0.1, 0.4, 5)))
    r2, r3 = (x.ravel() for x in np.meshgrid(np.linspace(0.4, 1, 9), np.linspace(0.4, 1, 8)))
    rows = uneven_figures(g1, g2, theta, r2, r3)
    phi = np.stack([g1, g2, theta - g1 - g2], axis=1).repeat(r2.size, axis=0)
    radii = np.tile(np.stack([np.ones(r2.size), r2, r3], axis=1), (g1.size, 1))
    ratio, angles, chord = _fan_figures_by_numpy(radii, phi)
    assert np.array_equal(rows[:, 0], ratio) and np.array_equal(rows[:, 2], chord)
    assert np.array_equal(np.degrees(rows[:, 1]), angles)


@pytest.mark.slow
def test_partial_spheres_with_sharp_rims_are_repaired(sampled):
    """cutcube's scoop (three sharp circular rims) is repaired on its
    stereographic map and left with no triangle above the repair's margin;
    fillet_box's corners blend into its fillets (no sampled rim): they are
    laid out with the box (tests/test_fillets.py), not by this repair."""
    _, r = sampled["cutcube"]
    spheres = [x for x in r.meta["repairs"] if x["kind"] == "sphere"]
    assert len(spheres) == 1
    assert spheres[0]["worst"] < np.sqrt(3) / 2
    assert spheres[0]["added"] + spheres[0]["removed"] > 0
    _, r = sampled["fillet_box"]
    assert not [x for x in r.meta["repairs"] if x["kind"] == "sphere"]


@pytest.mark.parametrize(
    "name, turn",
    [
        pytest.param("torus", (37.0, -112.0, 71.0)),
        pytest.param("sphere", (-111.0, 48.0, 152.0), marks=pytest.mark.slow),
        pytest.param("cone_tip", (-111.0, 48.0, 152.0), marks=pytest.mark.slow),
    ],
)
def test_a_turned_body_of_revolution_gets_the_upright_answer(sampled, checked, name, turn):
    """The rings follow the body's own axis, not the scan directions, and the
    poles' repairs run in units of the row step, so the last bits of the
    step (a turned model's meridian measures its length a bit apart) do not
    decide their path: turned, the torus, the ball and the cone tip get the
    upright sampling's count, every sample on the surface, and its worst
    ratio, at 0.85 or below (the turned ball's poles once ended at 0.975
    where the upright's ended at 0.836)."""
    pytest.importorskip("potpourri3d")
    from sr33.validators.conditions import sample_conditions
    from sr33.validators.fidelity import distance_to_surface

    _, upright = sampled[name]
    s = shapes.build(name, rotate_x=turn[0], rotate_y=turn[1], rotate_z=turn[2])
    r = scan(s)
    assert r.points.shape == upright.points.shape
    d = distance_to_surface(r.points, s.truth_vertices, s.truth_triangles)
    assert d.max() < 0.05 * r.meta["spacing"]  # up to the truth's sagitta
    rep = sample_conditions(r.points, s.truth_vertices, s.truth_triangles)
    assert rep.max_degree <= 33 and np.nanmax(rep.worst_ratio) <= 0.85
    # the same layout, judged on the turned truth's own tessellation (0.841
    # for the ball at its turn, 0.836 upright; 0.975 before)
    np.testing.assert_allclose(
        np.nanmax(rep.worst_ratio), np.nanmax(checked(name).worst_ratio), atol=0.01
    )


# numpy's default_rng(1).uniform(-180, 180, 3): the turn at which the cone's
# disk and cutcube's hole broke (kept to the last digit: the defects were
# the last bits)
TURN = (4.255784892092407, 162.16693067733672, -128.10253942093186)


def _turned(name: str, turn):
    s = shapes.build(name, rotate_x=turn[0], rotate_y=turn[1], rotate_z=turn[2])
    return s, scan(s)


def _reports(r, kind: str) -> list[dict]:
    return [x for x in r.meta["repairs"] if x["kind"] == kind]


def test_a_turned_disk_gets_the_upright_rings(sampled):
    """A disk's rings are laid and repaired in units of h from its radius
    rounded there, so a model turned off the axes (whose radii differ in
    their last bits) gets the upright's layout exactly: the turned cone's
    disk once ended its repair at 0.872 with 1291 samples where the
    upright's ended at 0.82 with 1306."""
    _, upright = sampled["cone"]
    _, r = _turned("cone", TURN)
    disks = _reports(r, "disk rings")
    assert len(disks) == 1 and disks[0]["worst"] < 0.85
    assert disks == _reports(upright, "disk rings")


@pytest.mark.slow
@pytest.mark.parametrize("name", ["cone", "cutcube"])
def test_turned_rims_disks_and_scoops_meet_condition_iii(sampled, name):
    """Turned by (4.3, 162.2, -128.1) degrees: the cone's disk keeps the
    upright's rings (0.872 before), and cutcube's hole keeps its lattice:
    a face repaired a second time takes the rim laid in the first round,
    and a rim sample a repair added counts as the rim's (the two rims of
    the hole once parted, the wall kept its scan rows: 0.998), its scoop
    repaired again from 0.835 on its map (0.849 there was 0.858 on the
    sphere).  The cone read 0.9155 by the check, 2 t from its apex, on a
    triangle that is not Delaunay on the cone (two samples inside its
    circumcircle on the development): the check had counted the bumps its
    inserted samples raise on the truth's chords as curvature, and kept
    the labels' diagonal (stop 61; 0.8455 now)."""
    pytest.importorskip("potpourri3d")
    from sr33.validators.conditions import sample_conditions

    s, r = _turned(name, TURN)
    rep = sample_conditions(r.points, s.truth_vertices, s.truth_triangles)
    assert rep.max_degree <= 33 and np.nanmax(rep.worst_ratio) <= 0.85
    if name == "cutcube":
        _, upright = sampled[name]
        assert _reports(r, "cylinder lattice") == _reports(upright, "cylinder lattice")


@pytest.mark.slow
def test_a_turned_conebox_meets_condition_iii_round_its_apex():
    """The conebox turned by the library's first test turn: its cone's
    development (181°) once had images of one side 2.8° inside the other
    (the repair mended triangles of 0.9 along the cut: 45 s), and round the
    apex the planar picture hid an intrinsic triangle that the geodesic
    check read 0.911, then 0.979 on a sliver 3.4° from Delaunay; the apex's
    intrinsic Delaunay triangles now pick the rings' end limits."""
    pytest.importorskip("potpourri3d")
    from sr33.validators.conditions import sample_conditions

    s, r = _turned("conebox", (37.0, -61.0, 118.0))
    rep = sample_conditions(r.points, s.truth_vertices, s.truth_triangles)
    assert rep.max_degree <= 33 and np.nanmax(rep.worst_ratio) <= 0.85
    cone = [x for x in r.meta["repairs"] if x["kind"] == "cone rings"]
    assert len(cone) == 1 and cone[0]["judged"] < 0.85


def _reconstructs_as_one_closed_sphere(points):
    """The reconstruction (k = 33) is one closed genus-0 surface through every sample."""
    from sr33.reconstruct import reconstruct

    rec = reconstruct(points, 33)
    st = mesh_stats(rec.triangles, rec.vertices.shape[0])
    assert (st.components, st.euler, st.open_edges, st.overloaded_edges) == (1, 2, 0, 0)
    assert rec.vertices.shape[0] == points.shape[0]


@pytest.mark.slow
def test_a_cone_with_ten_apex_rows_reconstructs_as_one_closed_surface(monkeypatch):
    """The default cone laid with 10 rows (not 12) repaired round its apex
    meets Condition III (worst ratio 0.845, degree 8) and must reconstruct
    as its B-rep does: one closed genus-0 surface.  It came out as three
    closed components (Euler characteristic 6): components decided on their
    own capped the cone ring by ring, and the exact selection's answer
    (bubble-free) lost to the capped one, whose extra spheres raise the
    Euler characteristic.  Now a detached piece sends the cycles round it to
    the fallback, and a bubbled selection loses to any valid answer."""
    pytest.importorskip("potpourri3d")
    from sr33.samplers import layers
    from sr33.validators.conditions import sample_conditions

    monkeypatch.setattr(layers, "APEX_REACH", 10)
    s = shapes.build("cone")
    r = scan(s)
    rep = sample_conditions(r.points, s.truth_vertices, s.truth_triangles)
    assert rep.max_degree <= 33 and np.nanmax(rep.worst_ratio) <= 0.85  # conforming
    _reconstructs_as_one_closed_sphere(r.points)


@pytest.mark.slow
def test_a_cones_apex_rows_end_their_columns_within_the_taper_limits():
    """A cone of radius 0.37 by height 0.8 (not the library's proportions):
    the rows near its apex, ending columns up to a merged gap of 1.65 t,
    made two whole rings of tapering cells at 0.863 by the geodesic check
    (42 samples) while the development's repair reported 0.846.  Judged on
    the whole development, that layout fails ``APEX_GOOD`` and the second
    pair of ``APEX_END_LIMITS`` is taken: conforming, and it reconstructs as
    its B-rep does."""
    pytest.importorskip("potpourri3d")
    from sr33.samplers import layers
    from sr33.validators.conditions import sample_conditions

    s = shapes.build("cone", radius=0.37, height=0.8)
    r = scan(s)
    (cone,) = [x for x in r.meta["repairs"] if x["kind"] == "cone rings"]
    assert tuple(cone["end_limits"]) == layers.APEX_END_LIMITS[1]
    assert cone["judged"] < layers.APEX_GOOD
    rep = sample_conditions(r.points, s.truth_vertices, s.truth_triangles)
    assert rep.max_degree <= 33 and np.nanmax(rep.worst_ratio) < 0.85
    _reconstructs_as_one_closed_sphere(r.points)


@pytest.mark.slow
def test_a_lofted_frustum_samples_as_the_made_one():
    """A frustum lofted between two circles has a conical face whose surface
    is a trimmed one: the cone layout asked it for ``Cone()`` and the
    sampling died with an AttributeError.  The analytic surface under any
    trimming (:func:`sr33.samplers.faces.basis_surface`) now serves: the
    lofted frustum is sampled exactly as the one made as a cone."""
    import cadquery as cq
    from scipy.spatial import cKDTree

    lofted = cq.Workplane("XY").circle(0.3).workplane(offset=0.4).circle(0.12).loft()
    made = cq.Workplane("XY").add(cq.Solid.makeCone(0.3, 0.12, 0.4))
    a = scan(shapes.from_cad(lofted), target_points=1500)
    b = scan(shapes.from_cad(made), target_points=1500)
    assert "cone rings" in {x["kind"] for x in a.meta["repairs"]}
    assert a.points.shape == b.points.shape
    assert cKDTree(b.points).query(a.points)[0].max() < 1e-9


def test_a_frustums_samples_stay_on_its_surface():
    """A frustum's cone does not reach its apex: the cone layout
    (:func:`sr33.samplers.layers.lattice_cone_faces`) laid its rings on to
    the apex, past the small rim and off the solid (51 samples up to 7 h
    above the top of this frustum, 3 h across).  Its rings now stop short of
    the small rim and the band between is repaired on the development with
    the rim's samples fixed: every sample lies on the surface, within the
    truth tessellation's own chordal error, and the cone is laid in rings."""
    import cadquery as cq

    from sr33.validators.fidelity import distance_to_surface

    s = shapes.from_cad(cq.Solid.makeCone(0.2, 0.04, 0.4, pnt=cq.Vector(0, 0, -0.2)))
    r = scan(s, target_points=3000)
    h = r.meta["spacing"]
    assert distance_to_surface(r.points, s.truth_vertices, s.truth_triangles).max() < 0.05 * h
    top = r.points[:, 2].max()
    assert top == pytest.approx(0.2, abs=1e-9)
    assert [x["kind"] for x in r.meta["repairs"]].count("cone rings") == 1


def test_a_cone_cut_in_two_by_a_boolean_keeps_each_faces_rings_on_it():
    """A ball fused round a cone's middle leaves two faces of one cone, the
    band between them cut away.  The cone layout took every sample on the
    cone's surface for the face's own and laid the tip's rings from the
    base's rim (the farthest from the apex) up through the ball: 636 of
    3,666 samples up to 4 h off the solid, and the geodesic check could not
    place them.  Each face now takes only the samples within its own extent
    along the axis: every sample lies on the surface."""
    import cadquery as cq

    from sr33.validators.fidelity import distance_to_surface

    cone = cq.Solid.makeCone(0.5, 0.0, 1.0, pnt=cq.Vector(0, 0, -0.5))
    ball = cq.Solid.makeSphere(0.35, angleDegrees1=-90, angleDegrees2=90)
    s = shapes.from_cad(cone.fuse(ball).clean(), name="cone through a ball")
    assert sorted(f.geomType() for f in s.solid.Faces()) == ["CONE", "CONE", "PLANE", "SPHERE"]
    r = scan(s, target_points=1500, quiet=True)
    h = r.meta["spacing"]
    assert distance_to_surface(r.points, s.truth_vertices, s.truth_triangles).max() < 0.05 * h
    # the cone's radius is 0.25 - z / 2: the ball (radius 0.35) bulges out of
    # it between z = -0.141 and 0.341, where no sample of the cone may lie
    p = r.points
    on_cone = np.abs(np.hypot(p[:, 0], p[:, 1]) - (0.25 - p[:, 2] / 2)) < 1e-9
    assert not (on_cone & (p[:, 2] > -0.14) & (p[:, 2] < 0.34)).any()
    assert "cone rings" in {x["kind"] for x in r.meta["repairs"]}


def _fused(a, b, name: str):
    """The one solid of CadQuery solids ``a`` and ``b`` fused, as a shape
    (``from_cad`` merges the coplanar faces the fuse leaves in pieces)."""
    return shapes.from_cad(a.fuse(b), name=name)


def _geodesic_ratios(s, target_points: int):
    """``s`` scanned at ``target_points``, and each sample's worst III-ii
    ratio by the geodesic check (skipped without potpourri3d)."""
    pytest.importorskip("potpourri3d")
    from sr33.validators.conditions import sample_conditions

    r = scan(s, target_points=target_points, quiet=True)
    return r, sample_conditions(r.points, s.truth_vertices, s.truth_triangles).worst_ratio


def _pencil():
    """A cylinder (radius 0.3, height 0.6) under a cone 0.5 high: the
    cylinder's top rim is the cone's, its bottom rim the base disk's.
    Returns the shape and its wall's face index."""
    import cadquery as cq

    cyl = cq.Solid.makeCylinder(0.3, 0.6)
    cone = cq.Solid.makeCone(0.3, 0.0, 0.5, pnt=cq.Vector(0, 0, 0.6))
    s = _fused(cyl, cone, "pencil")
    (wall,) = [f for f, x in enumerate(s.solid.Faces()) if x.geomType() == "CYLINDER"]
    return s, wall


def test_a_cylinders_rim_on_a_cone_takes_its_other_rims_angles():
    """A cylinder whose rims differ (the base's repair slid its rim; here
    turned half a step) is laid out when the other rim's face is laid
    after it (a cone): that rim takes the base rim's angles and the wall is
    the lattice both span.  Before, the wall kept its scan rows and 58 of
    a 3,000-sample pencil's wall samples broke III-ii."""
    from sr33.samplers.layers import lattice_cylinder_faces
    from sr33.samplers.samples import Samples

    s, wall = _pencil()
    r = scan(s, target_points=1500, repair=False, quiet=True)
    h = r.meta["spacing"]
    p = r.points.copy()
    radial = np.hypot(p[:, 0], p[:, 1])
    base = np.isclose(p[:, 2], 0.0, atol=1e-9) & np.isclose(radial, 0.3, atol=1e-9)
    turn = np.pi / base.sum()  # half a step
    c, sn = np.cos(turn), np.sin(turn)
    p[base, :2] = p[base, :2] @ np.array([[c, sn], [-sn, c]])
    bag = Samples(p, r.line_id, r.face_id, r.on_feature)
    base_before = np.sort(np.arctan2(p[base, 1], p[base, 0]))
    size = float(np.linalg.norm(np.ptp(s.truth_vertices, axis=0)))
    reports = lattice_cylinder_faces(s.solid, bag, h, size)
    assert [x["face"] for x in reports] == [wall] and reports[0]["kind"] == "cylinder lattice"
    q = bag.points
    on = np.isclose(np.hypot(q[:, 0], q[:, 1]), 0.3, atol=1e-9)

    def angles(z):
        at = on & np.isclose(q[:, 2], z, atol=1e-9)
        return np.sort(np.arctan2(q[at, 1], q[at, 0]))

    np.testing.assert_allclose(angles(0.0), base_before, atol=1e-12)  # the base's rim stays
    np.testing.assert_allclose(angles(0.6), base_before, atol=1e-12)  # the cone's takes it
    rows = np.unique(np.round(q[on & (q[:, 2] > 1e-6) & (q[:, 2] < 0.6 - 1e-6), 2], 9))
    assert rows.size == reports[0]["rows"] == round(0.6 / h) - 1
    for z in rows:
        np.testing.assert_allclose(angles(z), base_before, atol=1e-12)
    # the cone's rim samples stay on the cone's edge, as feature samples
    top = on & np.isclose(q[:, 2], 0.6, atol=1e-9)
    assert bag.on_feature[top].all() and (bag.line_id[top] == -1).all()


@pytest.mark.slow
def test_a_pencils_wall_meets_condition_iii():
    """The pencil sampled whole: no wall sample breaks III-ii by the geodesic
    check (its worst was 1.0 with the wall's scan rows)."""
    s, wall = _pencil()
    r, worst = _geodesic_ratios(s, 1500)
    assert float(worst[r.face_id == wall].max()) < np.sqrt(3) / 2


def _chamfered_cylinder(both: bool = False):
    """A cylinder of radius 0.33 and height 0.5 whose top edge (or both
    edges) is chamfered by 0.05: a cone band about 0.07 wide, narrower than
    a row at 1,500 samples (h about 0.04)."""
    import cadquery as cq

    w = cq.Workplane().circle(0.33).extrude(0.5)
    solid = (w.edges() if both else w.faces(">Z").edges()).chamfer(0.05).val()
    return shapes.from_cad(solid, name="chamfered cylinder")


def test_a_chamfers_cone_band_chains_its_disk_to_the_wall():
    """Both disks of a cylinder chamfered on top qualify for rings: the
    base through the wall and the chamfer's cone band on to the top disk
    (before, only the top disk did, and the base's repair slid its rim to a
    count of its own).  Both take the count of the widest circle chained to
    them, the wall's; a cone band whose circles are far apart in radius
    (a frustum from 0.5 to 0.2) chains nothing."""
    import cadquery as cq

    from sr33.samplers.adjacency import EdgeFaces
    from sr33.samplers.disks import round_faces
    from sr33.samplers.faces import linked_across, linked_radius

    s = _chamfered_cylinder()
    adj = EdgeFaces(s.solid)
    found = round_faces(adj, 1e-9)
    assert [rf.index for rf in found] == [
        f for f, x in enumerate(s.solid.Faces()) if x.geomType() == "PLANE"
    ]
    assert sorted(round(rf.radii[0], 9) for rf in found) == [0.28, 0.33]
    for rf in found:
        assert linked_radius(adj, rf.index, rf.edges[0]) == pytest.approx(0.33, abs=1e-12)
    frustum = shapes.from_cad(cq.Solid.makeCone(0.5, 0.2, 0.3), name="frustum")
    adj = EdgeFaces(frustum.solid)
    for rf in round_faces(adj, 1e-9):
        assert linked_across(adj, rf.index, rf.edges[0]) is None
        assert linked_radius(adj, rf.index, rf.edges[0]) == pytest.approx(rf.radii[0])


@pytest.mark.parametrize("both", [False, True], ids=["top", "both ends"])
def test_a_chamfered_cylinders_circles_carry_one_set_of_columns(both):
    """Every circle of a chamfered cylinder (the disks' rims, the wall's
    rims and rows, the cone bands') carries the same angles, as many as
    the wall's circle asks (``halving_count(2 pi r / h)``): the chamfer's
    band, narrower than a row, is a strip of rectangles.  Before, its
    inner circle had the top disk's own count and its outer one the
    count the base's repair left, and 38 of 1,455 samples broke III-ii
    (0.999)."""
    from sr33.samplers.chart import halving_count

    s = _chamfered_cylinder(both)
    r = scan(s, target_points=1500, quiet=True)
    h = r.meta["spacing"]
    p = r.points
    radial = np.hypot(p[:, 0], p[:, 1])
    ang = np.arctan2(p[:, 1], p[:, 0]) % (2 * np.pi)
    wall = np.isclose(radial, 0.33, atol=1e-9) & (p[:, 2] > 0.05 - 1e-9 if both else True)
    wall &= p[:, 2] < 0.45 + 1e-9
    columns = np.sort(ang[wall & np.isclose(p[:, 2], 0.45, atol=1e-9)])
    assert columns.size == halving_count(2 * np.pi * 0.33 / h)
    circles = [(0.5, 0.28)] + ([(0.0, 0.28), (0.05, 0.33)] if both else [(0.0, 0.33)])
    for z, rad in circles:
        at = np.isclose(p[:, 2], z, atol=1e-9) & np.isclose(radial, rad, atol=1e-9)
        assert r.on_feature[at].all()
        np.testing.assert_allclose(np.sort(ang[at]), columns, atol=1e-9)
    rows = np.unique(np.round(p[wall, 2], 9))
    assert rows.size >= 3
    for z in rows:
        at = wall & np.isclose(p[:, 2], z, atol=1e-9)
        np.testing.assert_allclose(np.sort(ang[at]), columns, atol=1e-9)


@pytest.mark.slow
@pytest.mark.parametrize("both", [False, True], ids=["top", "both ends"])
def test_a_chamfered_cylinder_meets_condition_iii_with_the_margin(both):
    """A chamfered cylinder sampled whole meets III-ii by the geodesic check
    with the margin of the library's defaults (chamfered on top: 0.999
    before; on both ends it conformed before too, 0.822, its rims' counts
    happening to agree)."""
    _, worst = _geodesic_ratios(_chamfered_cylinder(both), 1500)
    assert float(np.nanmax(worst)) < 0.85


def _domed_cylinder():
    """A cylinder (radius 0.3, height 0.4) under a spherical cap of radius
    0.5 (its rim the cylinder's top rim)."""
    import cadquery as cq

    cyl = cq.Solid.makeCylinder(0.3, 0.4)
    sphere = cq.Solid.makeSphere(0.5, pnt=cq.Vector(0, 0, 0.0))
    cap = sphere.intersect(cq.Solid.makeCylinder(0.3, 1.0, pnt=cq.Vector(0, 0, 0.4)))
    return _fused(cyl, cap, "dome")


def test_a_disk_qualifies_when_its_walls_far_rim_is_laid_from_the_rim():
    """A base disk under a cylinder is laid in rings when the face across
    the wall's other rim is laid out from the rim it is given (a cone, a
    spherical cap); under a wall whose other rim is on a planar face that
    is not round (a post through a plate), it is left to the planar
    repair."""
    import cadquery as cq

    from sr33.samplers.adjacency import EdgeFaces
    from sr33.samplers.disks import round_faces

    def planes(s):
        return [f for f, x in enumerate(s.solid.Faces()) if x.geomType() == "PLANE"]

    for s in (_pencil()[0], _domed_cylinder(), _chamfered_cylinder()):
        assert [rf.index for rf in round_faces(EdgeFaces(s.solid), 1e-9)] == planes(s)
    post = cq.Solid.makeCylinder(0.2, 0.6, pnt=cq.Vector(0, 0, -0.3))
    plate = cq.Solid.makeBox(1.0, 1.0, 0.1, pnt=cq.Vector(-0.5, -0.5, 0.3))
    s = _fused(post, plate, "post")
    assert round_faces(EdgeFaces(s.solid), 1e-9) == []


@pytest.mark.slow
def test_a_domed_cylinder_meets_condition_iii_with_the_margin():
    """A cylinder under a spherical cap, sampled whole: its base in rings,
    its wall a lattice, its cap in rings from the rim (0.999 before, 138
    samples at or above 0.85 on the wall and the cap)."""
    _, worst = _geodesic_ratios(_domed_cylinder(), 3000)
    assert float(np.nanmax(worst)) < 0.85


def _scattered_on_a_development(theta: float, seed: int):
    """Samples about a cone's apex, no two nearer than 0.6 t (t = 1), as
    (slant distance, angle about the axis) for a development of ``theta``."""
    rng = np.random.default_rng(seed)
    pts = []
    while len(pts) < 90:
        r, psi = rng.uniform(0.3, 9.5), rng.uniform(0, theta)
        xy = r * np.array([np.cos(psi * 2 * np.pi / theta), np.sin(psi * 2 * np.pi / theta)])
        if all(np.hypot(*(xy - q)) > 0.6 for _, _, q in pts):
            pts.append((r, psi, xy))
    return np.array([p[0] for p in pts]), np.array([p[1] for p in pts])


def test_the_apex_judge_is_the_planes_delaunay_on_a_flat_development():
    # sin(a) = 1: the development is the plane round the apex, its intrinsic
    # Delaunay triangles the plane's
    from scipy.spatial import Delaunay

    from sr33.mesh import triangle_ratios
    from sr33.samplers.layers import APEX_JUDGED_FROM, _apex_worst

    rho, psi = _scattered_on_a_development(2 * np.pi, 5)
    got = _apex_worst(rho, psi, np.empty(0), 20.0, 1.0, 1.0)
    r = np.r_[0.0, rho]
    xy = np.stack([r * np.cos(np.r_[0.0, psi]), r * np.sin(np.r_[0.0, psi])], 1)
    tri = Delaunay(xy).simplices
    tri = tri[r[tri].mean(axis=1) < APEX_JUDGED_FROM]
    assert got == pytest.approx(triangle_ratios(xy, tri).max(), abs=1e-12)


@pytest.mark.parametrize("degrees", [113.8, 181.39356918867102, 300.0])
def test_the_apex_triangulation_is_the_cones_intrinsic_delaunay(degrees):
    # every edge inside the triangulation round the apex is Delaunay by the
    # lengths on the cone (its two opposite angles sum to pi at most: Lawson's
    # certificate), the triangles tile the zone once (their angles round each
    # inner sample sum to 2 pi, round the apex to the development's angle),
    # and the opened-out picture the flips start from was not (flips made)
    import math

    from sr33.samplers.layers import _apex_triangulation

    theta = math.radians(degrees)
    sin_a = degrees / 360.0
    rho, psi = _scattered_on_a_development(theta, 7)
    r, tris, lengths, flips = _apex_triangulation(rho, psi / sin_a, np.empty(0), 20.0, sin_a, 1.0)
    assert flips > 0

    def angle(a, b, c):  # facing c
        return math.acos(max(-1.0, min(1.0, (a * a + b * b - c * c) / (2 * a * b))))

    # per edge (by its length and two samples: the edges either side of a
    # narrow cone's apex between the same two samples differ in length) the
    # angles facing it; per sample the angles round it
    facing: dict = {}
    round_vertex = np.zeros(r.size)
    for x, ls in zip(tris.tolist(), lengths.tolist()):
        for q in range(3):
            c, a_, b_ = ls[q], ls[(q + 1) % 3], ls[(q + 2) % 3]  # side q faces corner q + 2
            key = (*sorted((x[q], x[(q + 1) % 3])), round(c, 9))
            facing.setdefault(key, []).append(angle(a_, b_, c))
        for q in range(3):  # the angle at corner q, between sides q and q - 1
            round_vertex[x[q]] += angle(ls[q], ls[(q + 2) % 3], ls[(q + 1) % 3])
    inner = [v for v in facing.values() if len(v) == 2]
    assert len(inner) > 100 and all(len(v) <= 2 for v in facing.values())
    assert max(sum(v) for v in inner) <= math.pi + 1e-9
    assert round_vertex[0] == pytest.approx(theta, abs=1e-9)
    boundary = {i for e, v in facing.items() if len(v) == 1 for i in e[:2]}
    interior = [i for i in range(1, r.size) if i not in boundary]
    assert len(interior) > 30
    np.testing.assert_allclose(round_vertex[interior], 2 * math.pi, atol=1e-9)


def test_a_spheres_zone_is_judged_by_its_intrinsic_delaunay_triangles():
    """:func:`sr33.samplers.layers._sphere_zone_worst` (the pole's rings
    judged): on a sphere the intrinsic Delaunay triangles of samples are the
    faces of their convex hull; the zone's figure is the worst ratio over
    those faces without a corner on the zone's rim, exactly."""
    import cadquery as cq
    from scipy.spatial import ConvexHull, Delaunay

    from sr33.mesh import triangle_ratios
    from sr33.samplers.layers import _sphere_zone_worst

    radius = 2.0
    face = cq.Workplane().sphere(radius).faces().val()
    rng = np.random.default_rng(7)
    pole = np.array([0.0, 0.0, -radius])
    # a cap of 35° round the pole: the pole and points at random
    theta = np.arccos(1 - rng.random(300) * (1 - np.cos(np.radians(35))))
    phi = rng.random(300) * 2 * np.pi
    cap = radius * np.stack(
        [np.sin(theta) * np.cos(phi), np.sin(theta) * np.sin(phi), -np.cos(theta)], 1
    )
    pts = np.vstack([pole, cap])
    hull = ConvexHull(pts)
    # the faces towards the outside (the base's are the cap's rim joined)
    outward = hull.equations[:, :3] @ np.array([0.0, 0.0, -1.0]) > 0.0
    faces = hull.simplices[outward & (hull.equations[:, 3] < -0.5 * radius)]
    # the zone's rim: the cap's points on the hull of their map
    theta_all = np.r_[0.0, theta]
    x = pts / radius
    xy = np.stack([x[:, 0], x[:, 1]], 1) / (1.0 - x[:, 2])[:, None]
    rim = np.zeros(pts.shape[0], dtype=bool)
    rim[np.unique(Delaunay(xy).convex_hull)] = True
    faces = faces[~rim[faces].any(axis=1)]
    assert faces.shape[0] > 300 and theta_all[rim].min() > np.radians(20)
    expected = triangle_ratios(pts, faces).max()
    assert _sphere_zone_worst(pts, face, pole) == pytest.approx(expected, abs=1e-12)


@pytest.mark.slow
@pytest.mark.xfail(
    strict=True,
    reason="stop 63, the repair on its own Delaunay kernel: no reach of the blunt cone "
    "tip's apex meets ZONE_GOOD (reach 9: repair 0.8423, zone 0.8475; 10, 8, 11, 12, 13, "
    "7, 14 worse), and the check reads 0.8501 (below sqrt(3)/2, above the 0.85 margin); "
    "through Qhull it passed",
)
def test_a_blunt_cone_tips_rings_past_its_apex_repair_are_judged():
    """A cone tip off the library's defaults (ball 0.4, apex 0.6 above its
    centre: a 240° development): its apex's repair with a reach of 8 ended
    at 0.83, and nothing judged the rings just past it, where 59 samples
    9-10 t from the apex broke the 0.85 margin (0.876).  The revolved
    body's choice of reach now judges the cone's rings POLE_ZONE steps past
    the repaired ones by their intrinsic Delaunay triangles (stop 52), by
    the figure the geodesic check reads there: at the samples whose
    triangles lie within the judged rings (those up to POLE_ZONE - 1 past
    the reach; distances along the surface, the cone's slant from its apex
    and the ball's arc from its pole: a chord is shorter, and the next
    ring's samples, 14.83 h by chord and 15 h by arc, read 0.836 from
    triangles beyond the zone)."""
    from sr33.samplers.layers import POLE_ZONE, ZONE_GOOD
    from sr33.validators.conditions import sample_conditions

    s = shapes.build("cone_tip", radius=0.4, apex_height=0.6)
    r = scan(s)
    (rings,) = [x for x in r.meta["repairs"] if x["kind"] == "revolved rings"]
    assert rings["pole_zone_worst"] < ZONE_GOOD
    rep = sample_conditions(r.points, s.truth_vertices, s.truth_triangles)
    assert rep.worst_ratio.max() < 0.85
    h = r.meta["spacing"]
    # the figure is the worse of the two ends' (the apex's and the ball's pole's)
    reach = (rings["pole_reach"] + POLE_ZONE - 1.5) * h
    slant = np.linalg.norm(r.points - np.array([0.0, 0.0, 0.6]), axis=1)
    arc = 0.4 * np.arccos(np.clip(-r.points[:, 2] / np.linalg.norm(r.points, axis=1), -1, 1))
    zone = (slant < reach) | (arc < reach)
    assert abs(rep.worst_ratio[zone].max() - rings["pole_zone_worst"]) < 0.005


@pytest.mark.slow
def test_a_faces_repair_report_does_not_hide_a_broken_face():
    """A cutcube whose scoop (0.35) nearly meets its hole (0.3): the corner
    splits of its scooped sides (``repair.split_corners``) tried a repair
    that removed every free sample, judged it on no triangle (worst 0) and
    kept it, so the faces were reported clean while 40 of their samples
    each broke Condition III-ii at 1.0.  A trial is now judged where it
    removed free samples too: no planar face whose samples break III-ii
    (0.9 or more by the geodesic check) is reported within the margin."""
    from sr33.validators.conditions import sample_conditions

    s = shapes.build("cutcube", hole_radius=0.3, scoop_radius=0.35)
    r = scan(s)
    rep = sample_conditions(r.points, s.truth_vertices, s.truth_triangles)
    planes = [x for x in r.meta["repairs"] if x["kind"] == "plane"]
    assert planes
    for x in planes:
        on = r.face_id == x["face"]
        if rep.worst_ratio[on].max() >= 0.9:
            assert x["worst"] >= 0.85 and x["bad"] > 0, x


def _notched_cylinder():
    """The stop 54 survey's model (a boolean seam): a cylinder (radius 0.2,
    height 0.59) with a ball (radius 0.31) cut from its top off the axis,
    turned.  The cut leaves a cylinder notched along a B-spline (the curve
    where they meet) and the ball's dish with that rim and a seam: no
    layout takes either."""
    import cadquery as cq

    from tests.strategies import moved

    r, h = 0.20000000000000004, 0.5890878945563615
    solid = cq.Solid.makeCylinder(r, h, pnt=cq.Vector(0, 0, -h / 2))
    ball = (
        cq.Solid.makeSphere(0.5158543122119371, angleDegrees1=-90, angleDegrees2=90)
        .scale(0.6)
        .translate(cq.Vector(0.02165115904743084, 0.01822301996327047, 0.29454394727818073))
    )
    solid = cq.Solid(solid.cut(ball).Solids()[0].wrapped)
    solid = moved(
        solid,
        [139.94100729204922, 4.89441967723362e-229, 136.97646435628957],
        [2.629793343154865, 1.7612338076495861, 4.725057160444777],
    )
    return shapes.from_cad(solid, name="notched cylinder")


@pytest.mark.slow  # 27-31 s: make check (the suite's 10 minutes)
def test_a_cylinder_notched_by_a_ball_is_repaired_in_its_charts():
    """Faces no layout takes are repaired in charts of their own, whatever
    their rims (:mod:`sr33.samplers.outlines`): the ball's dish on its
    stereographic map, the notched cylinder unrolled.  Left to the scan
    rows, 290 of the cylinder's samples and 351 of the dish's broke
    Condition III-ii (3,007 samples, worst 1.0); now none does, with the
    margin.  (Stops 56 and 57 read 0.884 here, on three samples at the
    bottom rim: the check's labels had taken both diagonals of a near tie,
    three overlapping triangles; mended in the check, the sampling is
    0.842.)"""
    from sr33.validators.fidelity import distance_to_surface

    s = _notched_cylinder()
    kinds = sorted(f.geomType() for f in s.solid.Faces())
    assert kinds == ["CYLINDER", "PLANE", "SPHERE"]
    r, ratio = _geodesic_ratios(s, 1500)
    h = r.meta["spacing"]
    done = {x["kind"] for x in r.meta["repairs"]}
    assert {"sphere chart", "cylinder chart"} <= done
    assert distance_to_surface(r.points, s.truth_vertices, s.truth_triangles).max() < 0.05 * h
    assert np.nanmax(ratio) < 0.85


@pytest.mark.slow  # 27-31 s: make check (the suite's 10 minutes)
def test_a_whole_wall_between_two_rims_that_disagree_is_repaired_in_its_chart():
    """A cylinder countersunk and drilled through: its top and bottom are
    annuli laid in rings (inner rims 0.25 and 0.125), whose outer rims,
    the wall's two rims, get different angles; the wall cannot be the
    lattice both span, and no layout took it.  It kept its scan rows (358
    of 4,734 samples broke Condition III-ii, worst 1.0) because the charts
    took only cylinders that do not go round between whole circles; a whole
    band no layout took is repaired in its chart like the others.  The
    whole model conforms at 1,800, 2,500 and 3,000 samples (stop 60); at
    2,000 the countersink's frustum leaves 0.856 at its small rim (below)."""
    import cadquery as cq

    body = cq.Workplane("XY").circle(0.5).extrude(0.4)
    solid = body.faces(">Z").workplane().cskHole(0.25, 0.5, 82).val()
    s = shapes.from_cad(solid, name="countersunk cylinder")
    wall = [
        i
        for i, f in enumerate(s.solid.Faces())
        if f.geomType() == "CYLINDER" and abs(f.Area() - 2 * np.pi * 0.5 * 0.4) < 1e-6
    ]
    assert len(wall) == 1
    r, ratio = _geodesic_ratios(s, 2000)
    kinds = {(x.get("face"), x["kind"]) for x in r.meta["repairs"]}
    assert (wall[0], "cylinder chart") in kinds
    assert (wall[0], "cylinder lattice") not in kinds
    assert np.nanmax(ratio[r.face_id == wall[0]]) < 0.85


@pytest.mark.slow
def test_regression_a_countersunk_cylinder_at_2000_samples_conforms():
    import cadquery as cq

    body = cq.Workplane("XY").circle(0.5).extrude(0.4)
    solid = body.faces(">Z").workplane().cskHole(0.25, 0.5, 82).val()
    s = shapes.from_cad(solid, name="countersunk cylinder")
    assert np.nanmax(_geodesic_ratios(s, 2000)[1]) < 0.85


@pytest.mark.slow  # 27-31 s: make check (the suite's 10 minutes)
def test_a_frustums_rings_take_the_phase_of_its_small_rim():
    """A cone frustum (0.5 -> 0.25, 0.5 high) drilled through (0.1): its
    small rim is the top annulus's, laid in rings round the hole with 62
    samples; the frustum's rings, halving by their gaps from the large rim,
    reached it with 124 columns of another phase, and the development's
    repair against the fixed rim was stuck: 110 samples at or above 0.85,
    worst 0.964 (91 s).  The rings near the small rim take its phase
    (:func:`sr33.samplers.layers._phased`), and the rings' judge ends at
    the small rim."""
    import cadquery as cq

    from sr33.samplers.layers import _phased

    rim = np.array([0.3, 1.9, 4.0])
    got = _phased(np.linspace(0.0, 6.0, 12), rim)  # 12 = 3 x 4: each rim gap split in 4
    np.testing.assert_allclose(got[::4], rim)
    np.testing.assert_allclose(got[1:4], 0.3 + 1.6 * np.array([0.25, 0.5, 0.75]))
    odd = np.linspace(0.0, 6.0, 9)  # 9 = 3 x 3: not a power of two, left as it is
    assert _phased(odd, rim) is odd

    solid = cq.Solid.makeCone(0.5, 0.25, 0.5).cut(cq.Solid.makeCylinder(0.1, 0.5))
    s = shapes.from_cad(solid, name="drilled frustum")
    cone = [i for i, f in enumerate(s.solid.Faces()) if f.geomType() == "CONE"]
    assert len(cone) == 1
    r, ratio = _geodesic_ratios(s, None)
    rings = [x for x in r.meta["repairs"] if x["kind"] == "cone rings"]
    assert [x["face"] for x in rings] == cone
    assert abs(r.meta["spacing"] - 0.02) < 1e-12  # the spacing the rings were stuck at
    assert np.nanmax(ratio) < 0.85
    # the rings' own judge agrees with the check on the cone (it judged the
    # apex's fan across the hole: 1.0 on every drilled frustum)
    on_cone = r.face_id == cone[0]
    assert abs(rings[0]["judged"] - np.nanmax(ratio[on_cone])) < 0.01


def test_an_unrolled_cylinder_is_an_isometry_and_its_raster_wraps():
    """:class:`sr33.samplers.outlines.Unrolled` maps a cylinder onto the
    plane keeping lengths along it (arc length round, height along), and
    back; :class:`sr33.samplers.outlines.TriangleRaster` with its period
    takes a triangle across the cut whole, at both ends."""
    from sr33.samplers.chart import TriangleRaster
    from sr33.samplers.outlines import Unrolled

    o = np.array([0.3, -0.2, 1.0])
    ez = np.array([0.0, 0.6, 0.8])
    ex = np.array([1.0, 0.0, 0.0])
    ey = np.cross(ez, ex)
    chart = Unrolled(o, ex, ey, ez, 0.5, cut=1.0)
    ang = np.array([1.2, 2.0, 4.5, 7.0])
    z = np.array([0.1, -0.3, 0.25, 0.0])
    p = o + z[:, None] * ez + 0.5 * (np.cos(ang)[:, None] * ex + np.sin(ang)[:, None] * ey)
    c = chart(p)
    np.testing.assert_allclose(c[:, 0], 0.5 * ((ang - 1.0) % (2 * np.pi)))
    np.testing.assert_allclose(c[:, 1], z, atol=1e-15)
    np.testing.assert_allclose(chart.inverse(c), p, atol=1e-12)
    # a triangle across the cut: corners near both ends of [0, period)
    period = chart.period
    tri = np.array([[[period - 0.05, 0.0], [0.05, 0.0], [0.0, 0.1]]])
    inside = TriangleRaster(tri, 0.005, period)
    got = inside(np.array([[period - 0.01, 0.02], [0.01, 0.02], [0.5, 0.02], [0.0, 0.2]]))
    assert got.tolist() == [True, True, False, False]


@pytest.mark.slow
def test_a_ball_with_a_bite_is_laid_as_the_whole_ball():
    """A ball with a smaller ball cut from its top (the stop 55 survey's
    model): the ball's face reaches past one map (past 78° from its centre)
    and no layout took it; its scan rows had 1,756 of 3,176 samples at or
    above √3/2.  It is laid as a whole ball is, in rings about the axis
    through the bite, and the rim's boundary layer repaired on the map
    centred in the bite: 3 samples at or above 0.85, worst 0.862."""
    import cadquery as cq

    from sr33.validators.fidelity import distance_to_surface
    from tests.strategies import moved

    ball = cq.Solid.makeSphere(0.3807513439005975, angleDegrees1=-90, angleDegrees2=90)
    bite = (
        cq.Solid.makeSphere(0.446749370158812, angleDegrees1=-90, angleDegrees2=90)
        .scale(0.6)
        .translate(cq.Vector(0.1462172159743036, -0.09372402989079898, 0.3807513439005975))
    )
    solid = moved(
        cq.Solid(ball.cut(bite).Solids()[0].wrapped),
        [157.48521938130256, 1.7091564551760873e-248, 143.24454205139358],
        [-1.1833165727307643e-199, 3.9282921547396903, 1.4376531849088767],
    )
    s = shapes.from_cad(solid, name="bitten ball")
    r, ratio = _geodesic_ratios(s, 3000)
    h = r.meta["spacing"]
    assert "sphere chart" in {x["kind"] for x in r.meta["repairs"]}
    assert distance_to_surface(r.points, s.truth_vertices, s.truth_triangles).max() < 0.05 * h
    assert (ratio >= 0.85).sum() <= 10


@pytest.mark.slow
def test_a_bitten_balls_pole_at_the_maps_centre_of_projection_is_left_out_of_the_repair():
    """A ball with a box cut from its bottom: the face's centre is the ball's
    top pole, where the bite's map projects from (it maps to no point).  The
    ball's rings keep a sample there; taken into the rims' repair, its NaN
    chart position made the repair's k-d tree fail ("data must be finite",
    the stop 55 survey's crash).  It stays out of the repair, which runs."""
    import cadquery as cq

    ball = cq.Solid.makeSphere(0.4, angleDegrees1=-90, angleDegrees2=90)
    box = cq.Solid.makeBox(0.5, 0.5, 0.3, pnt=cq.Vector(-0.25, -0.25, -0.55))
    s = shapes.from_cad(cq.Solid(ball.cut(box).Solids()[0].wrapped), name="bitten ball")
    r = scan(s, target_points=1500, quiet=True)
    assert np.isfinite(r.points).all()
    assert "sphere chart" in {x["kind"] for x in r.meta["repairs"]}
    top = np.array([0.0, 0.0, 0.4])
    assert np.linalg.norm(r.points - top, axis=1).min() < 1e-9  # the pole's sample stays


def _drilled_ball(radius=0.5, hole=0.15):
    """A ball drilled through its centre (a bead), turned off the axes."""
    import cadquery as cq

    from tests.strategies import moved

    ball = cq.Solid.makeSphere(radius, angleDegrees1=-90, angleDegrees2=90)
    drill = cq.Solid.makeCylinder(hole, 4 * radius, pnt=cq.Vector(0, 0, -2 * radius))
    solid = cq.Solid(ball.cut(drill).Solids()[0].wrapped)
    return moved(solid, [23.0, -41.0, 12.0], [0.1, 0.2, 0.3])


def test_a_balls_rims_group_into_bites_where_they_meet():
    """A drilled ball's two rims are two bites on opposite sides (each its
    own map); a ball bitten by a box has one bite of several arcs, however
    many edges it has (stop 65)."""
    import cadquery as cq

    from sr33.samplers.outlines import _bites, rim_edges, rim_lines

    solid = _drilled_ball()
    (face,) = [f for f in solid.Faces() if f.geomType() == "SPHERE"]
    centre = np.array(face.Center().toTuple())  # the ball's centre: the face is symmetric
    rims = rim_edges(face)
    got = _bites(rim_lines(rims, 0.02), centre, 1e-6)
    assert [m for m, _ in got] == [[0], [1]]
    assert np.dot(got[0][1], got[1][1]) == pytest.approx(-1.0, abs=1e-6)
    ball = cq.Solid.makeSphere(0.5, angleDegrees1=-90, angleDegrees2=90)
    box = cq.Solid.makeBox(0.4, 0.5, 0.4, pnt=cq.Vector(-0.1, -0.2, 0.3))
    (face,) = [
        f for f in cq.Solid(ball.cut(box).Solids()[0].wrapped).Faces() if f.geomType() == "SPHERE"
    ]
    rims = rim_edges(face)
    assert len(rims) >= 3
    got = _bites(rim_lines(rims, 0.02), np.zeros(3), 1e-6)
    assert [m for m, _ in got] == [list(range(len(rims)))]
    assert got[0][1][2] > 0.9  # towards the top, where the box bit


@pytest.mark.slow
def test_a_ball_drilled_through_is_laid_whole_and_repaired_at_both_bites():
    """A ball drilled through (a bead): its face's centre is the ball's, no
    map was made for it, and its scan rows had 1,324 of 1,978 samples at or
    above √3/2 (3,000 samples).  Laid as the whole ball, in rings about the
    axis through the widest bite, with each rim's boundary layer repaired on
    the map centred in its own bite: at 1,500 samples, worst 0.849 by the
    geodesic check."""
    from sr33.mesh import SQRT3_2
    from sr33.validators.fidelity import distance_to_surface

    s = shapes.from_cad(_drilled_ball(), name="drilled ball")
    r, ratio = _geodesic_ratios(s, 1500)
    h = r.meta["spacing"]
    assert [x["kind"] for x in r.meta["repairs"]].count("sphere chart") == 2
    assert distance_to_surface(r.points, s.truth_vertices, s.truth_triangles).max() < 0.05 * h
    assert (ratio >= SQRT3_2).sum() <= 5


@pytest.mark.slow
def test_a_ball_cut_by_a_box_and_drilled_keeps_its_holes_rims():
    """The stop 61 survey's boolean-seam model: a ball cut by a box at its
    top and drilled through.  Two bites, on opposite sides: its face was
    left to the scan rows (at 1,500 samples, 688 of 1,008 samples at or
    above √3/2), and the box's floor slid its samples off its arcs round
    the hole (8 of 10 on one at 3,000), as if the hole's wall were laid out
    from its rims (only a whole band is), leaving the wall's chart 20 bad
    samples.  Now 42 samples (sphere 23, floor 19), the wall none."""
    import cadquery as cq

    from sr33.mesh import SQRT3_2
    from tests.strategies import moved

    ball = cq.Solid.makeSphere(0.4936126522668401, angleDegrees1=-90, angleDegrees2=90)
    a, b, c = 0.5, 1.0281381925722326, 0.5239809558804812
    box = (
        cq.Solid.makeBox(a, b, c, pnt=cq.Vector(-a / 2, -b / 2, -c / 2))
        .scale(0.6)
        .translate(cq.Vector(0.07820248268342328, 0.03838980531444497, 0.4936126522668401))
    )
    solid = cq.Solid(ball.cut(box).Solids()[0].wrapped)
    bb = solid.BoundingBox()
    lo = np.array([bb.xmin, bb.ymin, bb.zmin])
    ext = np.array([bb.xlen, bb.ylen, bb.zlen])
    drill = cq.Solid.makeCylinder(
        0.14808379568005203,
        3 * ext[2] + 1,
        pnt=cq.Vector(*(lo + ext / 2 - [0, 0, 1.5 * ext[2] + 0.5])),
    )
    solid = moved(
        cq.Solid(solid.cut(drill).Solids()[0].wrapped),
        [5.0, 0.02, -147.91908833320824],
        [-1.4428277091095816, -4.3824822718598295e-95, -3.8689670623029793],
    )
    s = shapes.from_cad(solid, name="ball cut and drilled")
    r, ratio = _geodesic_ratios(s, 1500)
    kinds = [f.geomType() for f in solid.Faces()]
    bad = ratio >= SQRT3_2
    wall = np.isin(r.face_id, [k for k, x in enumerate(kinds) if x == "CYLINDER"])
    ball_ = np.isin(r.face_id, [k for k, x in enumerate(kinds) if x == "SPHERE"])
    assert [x["kind"] for x in r.meta["repairs"]].count("sphere chart") == 2
    assert (bad & wall).sum() <= 3
    assert (bad & ball_).sum() <= 60
    assert bad.sum() <= 100


def test_the_apex_judge_can_measure_a_triangle_by_the_geodesic_distances_of_its_corners():
    """Round the apex of a narrow cone (the library cone, 0.5 by 1.5: its
    development 114°) an edge of the intrinsic Delaunay triangulation may
    run the longer way round the apex.  The geodesic check measures the
    distance between the corners, the shorter way: the judge can too (the
    cone turned b had a triangle of 0.82 by its edges and 0.870 by the
    check, and its rings were kept with it)."""
    import math

    from sr33.samplers.layers import _apex_triangulation, _apex_worst

    sin_a = 0.5 / math.hypot(0.5, 1.5)
    rho = np.array([0.65, 0.984, 1.529, 1.635, 1.675, 1.849, 2.716, 2.757, 2.793])
    ang = np.array([4.1233, 0.9817, 3.9979, 2.4401, 1.1378, 5.9875, 1.3161, 5.4769, 4.0329])
    r, tris, lengths, _ = _apex_triangulation(rho, ang, np.empty(0), 62.0, sin_a, 1.0)
    theta = 2 * math.pi * sin_a
    psi = np.r_[0.0, ang * sin_a] % theta

    def apart(i, j):
        d = abs(psi[i] - psi[j]) % theta
        d = min(d, theta - d)
        return math.sqrt(r[i] ** 2 + r[j] ** 2 - 2 * r[i] * r[j] * math.cos(d))

    by_corners = max(
        sorted(apart(x[q], x[(q + 1) % 3]) for q in range(3))[1]
        / max(apart(x[q], x[(q + 1) % 3]) for q in range(3))
        for x in tris.tolist()
    )
    edges = np.sort(lengths, axis=1)
    assert (edges[:, 1] / edges[:, 2]).max() < 0.85  # the edges' own lengths miss it
    got = _apex_worst(rho, ang, np.empty(0), 62.0, sin_a, 1.0, corners=True)
    assert got == pytest.approx(by_corners)
    assert by_corners > 0.865
    # by their edges, as before (the judge takes both, lattice_cone_faces)
    assert _apex_worst(rho, ang, np.empty(0), 62.0, sin_a, 1.0) < 0.85


def _chamfered_tube(hole: float = 0.12, chamfer: float = 0.035):
    """A cylinder of radius 0.4 and height 0.6 with a hole of radius
    ``hole`` through it, both top edges chamfered by ``chamfer``: the
    hole's chamfer is a cone band whose circles differ by more than
    ``LINK_RATIO`` in radius (0.12 against 0.155) but lie about 1.4 h apart
    at 3,000 samples."""
    import cadquery as cq

    w = cq.Workplane().circle(0.4).circle(hole).extrude(0.6)
    solid = w.faces(">Z").edges().chamfer(chamfer).val()
    return shapes.from_cad(solid, name="chamfered tube")


def test_a_narrow_band_links_its_circles_whatever_their_ratio():
    """A hole's chamfer, its circles 0.8 of each other in radius or less,
    links them only given h and narrower than ``LINK_WIDTH`` h; the tube's
    two annuli then take one count per chain (inner, and outer a power of
    two times it), where each took counts from its own radii."""
    from sr33.samplers.adjacency import EdgeFaces
    from sr33.samplers.disks import _annulus_counts, round_faces
    from sr33.samplers.faces import LINK_RATIO, LINK_WIDTH, linked_across, linked_radii

    s = _chamfered_tube()
    adj = EdgeFaces(s.solid)
    found = round_faces(adj, 1e-9)
    assert sorted(round(r, 9) for rf in found for r in rf.radii) == [0.12, 0.155, 0.365, 0.4]
    h = 0.03
    for rf in found:
        inner = rf.edges[-1]
        assert min(linked_radii(adj, rf.index, inner, h)) == pytest.approx(0.12, abs=1e-12)
        assert max(linked_radii(adj, rf.index, inner, h)) == pytest.approx(0.155, abs=1e-12)
    top = max(found, key=lambda rf: rf.radii[-1])  # the top annulus, its inner rim the chamfer's
    assert 0.12 / 0.155 < LINK_RATIO
    width = 0.035 * np.sqrt(2)  # the chamfer band's width on the cone
    assert linked_across(adj, top.index, top.edges[-1]) is None
    assert linked_across(adj, top.index, top.edges[-1], h) is not None
    assert linked_across(adj, top.index, top.edges[-1], 0.99 * width / LINK_WIDTH) is None
    counts = {_annulus_counts(adj, rf, h, 1e-9) for rf in found}
    assert len(counts) == 1
    ((inner, outer),) = counts
    assert inner == round(2 * np.pi * 0.155 / h)
    assert outer % inner == 0 and (outer // inner) & (outer // inner - 1) == 0


def test_a_chamfered_tubes_circles_carry_one_set_of_columns_per_chain():
    """Every circle of a chamfered tube's outer chain (the base's rim, the
    wall's rows, both circles of its chamfer, the top's rim) carries the
    same angles, and so does every circle of its hole's; before, the top
    annulus took its counts from its own radii, and the chamfers' bands
    were strips of needle triangles (a survey's model: 209 samples at or
    above sqrt(3)/2)."""
    s = _chamfered_tube()
    r = scan(s, target_points=3000, quiet=True)
    p = r.points
    radial = np.hypot(p[:, 0], p[:, 1])
    ang = np.arctan2(p[:, 1], p[:, 0]) % (2 * np.pi)
    for circles in (
        [(0.0, 0.4), (0.565, 0.4), (0.6, 0.365)],
        [(0.0, 0.12), (0.565, 0.12), (0.6, 0.155)],
    ):
        got = []
        for z, rad in circles:
            at = np.isclose(p[:, 2], z, atol=1e-9) & np.isclose(radial, rad, atol=1e-9)
            assert r.on_feature[at].all() and at.sum() >= 3
            got.append(np.sort(ang[at]))
        for a in got[1:]:
            np.testing.assert_allclose(a, got[0], atol=1e-9)
        wall = np.isclose(radial, circles[0][1], atol=1e-9)
        wall &= (p[:, 2] > 1e-9) & (p[:, 2] < 0.565 - 1e-9)
        for z in np.unique(np.round(p[wall, 2], 9)):
            at = wall & np.isclose(p[:, 2], z, atol=1e-9)
            np.testing.assert_allclose(np.sort(ang[at]), got[0], atol=1e-9)


@pytest.mark.slow
def test_a_chamfered_tube_meets_condition_iii():
    """The chamfered tube sampled whole meets III-ii by the geodesic check."""
    _, worst = _geodesic_ratios(_chamfered_tube(), 3000)
    assert float(np.nanmax(worst)) < np.sqrt(3) / 2


def _notched_cone():
    """A cone (base radius 0.5, height 1) with a box cut from its side at
    mid-height: its face goes round, its base rim is a whole circle, and
    the notch's rims (two hyperbolas, three arcs) are no circles about it."""
    import cadquery as cq

    cone = cq.Solid.makeCone(0.5, 0.0, 1.0)
    tool = cq.Solid.makeBox(0.3, 0.3, 0.3, pnt=cq.Vector(0.15, -0.15, 0.2))
    return shapes.from_cad(cq.Solid(cone.cut(tool).Solids()[0].wrapped), name="notched cone")


def test_a_cones_development_is_an_isometry_with_its_cut_across():
    """The development of a cone (:class:`sr33.samplers.outlines.Developed`)
    keeps lengths (points on one generator and on one circle), inverts
    exactly, takes the face's triangles across the cut on both of its
    sides, and carries points near the cut across it by the sector."""
    from sr33.samplers.outlines import Developed, _cone, _face_triangles

    s = _notched_cone()
    face = next(f for f in s.solid.Faces() if f.geomType() == "CONE")
    apex, axis, ex, ey, sin_a = _cone(face)
    cos_a = np.sqrt(1 - sin_a**2)
    rng = np.random.default_rng(5)
    rho, th = rng.uniform(0.05, 1.0, 200), rng.uniform(0, 2 * np.pi, 200)
    across = np.cos(th)[:, None] * ex + np.sin(th)[:, None] * ey
    p = apex + rho[:, None] * (cos_a * axis + sin_a * across)
    for cut in (0.0, 2.5):
        chart = Developed(apex, axis, ex, ey, sin_a, cut)
        c = chart(p)
        np.testing.assert_allclose(np.hypot(c[:, 0], c[:, 1]), rho, atol=1e-12)
        np.testing.assert_allclose(chart.inverse(c), p, atol=1e-12)
        phi = np.arctan2(c[:, 1], c[:, 0]) % (2 * np.pi)
        assert phi.max() < chart.sector + 1e-12
        # along a circle: the chart's arc is the circle's (an isometry)
        q, r = (
            apex + 0.5 * (cos_a * axis + sin_a * (np.cos(a) * ex + np.sin(a) * ey))
            for a in (cut + 1.0, cut + 1.01)
        )
        arc = 0.5 * sin_a * 0.01
        assert np.linalg.norm(chart(q[None]) - chart(r[None])) == pytest.approx(arc, rel=1e-4)
        tri = chart.triangles(_face_triangles(face, 0.002))
        turned = np.arctan2(tri[..., 1], tri[..., 0])
        assert (turned < -1e-9).any() and (turned % (2 * np.pi) > chart.sector + 1e-9).any()
        near = c[chart.from_cut(c) < 0.05]
        up, down = chart.images(near, 0.05)
        assert up.shape[0] + down.shape[0] == near.shape[0] > 0
        for img, turn in ((up, chart.sector), (down, -chart.sector)):
            rot = np.array([[np.cos(turn), -np.sin(turn)], [np.sin(turn), np.cos(turn)]])
            got = {tuple(np.round(x, 9)) for x in img}
            assert got <= {tuple(np.round(rot @ x, 9)) for x in near}


def test_a_notched_cone_is_laid_in_its_rings_and_repaired_at_its_notch():
    """A cone notched by a box is laid as its whole cone's rings, kept
    inside its face, and repaired round its notch in its development: its
    apex stays a sample, every sample lies on the model, and the samples
    breaking III-ii by the geodesic check are a few (8 of 959 at 1,500
    samples; on its scan rows before, more than half of them)."""
    from sr33.validators.fidelity import distance_to_surface

    s = _notched_cone()
    r, worst = _geodesic_ratios(s, 1500)
    h = r.meta["spacing"]
    assert any(x["kind"] == "notched cone rings" for x in r.meta["repairs"])
    assert np.linalg.norm(r.points - [0.0, 0.0, 1.0], axis=1).min() < 1e-9
    d = distance_to_surface(r.points, s.truth_vertices, s.truth_triangles)
    assert d.max() < 0.05 * h
    cone = [f for f, x in enumerate(s.solid.Faces()) if x.geomType() == "CONE"]
    on = np.isin(r.face_id, cone)
    bad = on & ~(worst < np.sqrt(3) / 2)
    assert bad.sum() <= 0.03 * on.sum()
