"""Planar faces shorter than the model, edges square to the rows, booleans'
coplanar pieces and chamfers' narrow strips (issue 23 item 2; stop 50)."""

import numpy as np
import pytest

pytest.importorskip("cadquery")

from sr33.samplers import shapes  # noqa: E402
from sr33.samplers.scanline import scan  # noqa: E402


def _box(a=0.4, b=0.4, c=0.4):
    import cadquery as cq

    return cq.Solid.makeBox(a, b, c, pnt=cq.Vector(-a / 2, -b / 2, -c / 2))


def _chamfered_box(chamfer: float):
    """A box 0.4 on a side with its four top edges chamfered."""
    import cadquery as cq

    return shapes.from_cad(cq.Workplane().add(_box()).edges(">Z").chamfer(chamfer).val())


def _corner_union():
    """A box 0.4 with a box 0.24 fused on its top corner by ``Solid.fuse``
    (which leaves the coplanar sides in pieces)."""
    import cadquery as cq

    small = _box(0.24, 0.24, 0.24).translate(cq.Vector(-0.08, -0.08, 0.2))
    return _box().fuse(small)


def _worst(s, target_points: int) -> float:
    pytest.importorskip("potpourri3d")
    from sr33.validators.conditions import sample_conditions

    r = scan(s, target_points=target_points, quiet=True)
    return float(
        np.nanmax(sample_conditions(r.points, s.truth_vertices, s.truth_triangles).worst_ratio)
    )


def test_a_boolean_leaves_no_coplanar_pieces():
    """``from_cad`` merges the faces a fuse left in pieces on one plane
    (13 faces -> 9); no two faces across an edge are then coplanar, and the
    topology is the solid's."""
    from sr33.samplers.adjacency import EdgeFaces

    solid = _corner_union()
    assert len(solid.Faces()) == 13
    s = shapes.from_cad(solid)
    faces = s.solid.Faces()
    assert len(faces) == 9
    assert s.expected.euler == 2
    ef = EdgeFaces(s.solid)
    for fids in ef.faces_of:
        if len(fids) == 2 and all(faces[k].geomType() == "PLANE" for k in fids):
            n = [np.array(faces[k].normalAt().toTuple()) for k in fids]
            assert abs(float(n[0] @ n[1])) < 1 - 1e-9


def test_a_faces_rows_end_on_its_edges_samples():
    """A box's side under a chamfered top is 0.388 high of the box's 0.4:
    its rows run up it on a lattice of its own, dividing its span as its
    vertical edges' equal steps do, so every sample of a row stands at the
    height of a sample of its edges (before: the box's lattice, 1.023 h
    against the edges' 0.992 h, staggered up to half a step)."""
    s = _chamfered_box(0.012)
    r = scan(s, target_points=3000, repair=False, quiet=True)
    h = r.meta["spacing"]
    side = [
        f
        for f, x in enumerate(s.solid.Faces())
        if x.geomType() == "PLANE" and abs(x.normalAt().toTuple()[0] + 1) < 1e-9
    ][0]
    on_side = np.abs(r.points[:, 0] + 0.2) < 1e-9
    edge = on_side & r.on_feature & (np.abs(np.abs(r.points[:, 1]) - 0.2) < 1e-9)
    rows = on_side & ~r.on_feature & (r.face_id == side)
    assert edge.sum() >= 40 and rows.sum() >= 300
    heights = np.unique(np.round(r.points[edge, 2] / h, 6))
    gap = np.abs(r.points[rows, 2][:, None] / h - heights[None]).min(axis=1)
    assert gap.max() < 1e-6


@pytest.mark.parametrize("chamfer", [0.006, 0.015])
def test_a_chamfers_strip_carries_one_lattice_across(chamfer):
    """A chamfer's strip narrower than two clearances holds no row: its
    shorter edge takes the longer one's samples across it, half a step on
    where the strip is narrower than STRIP_STAGGER steps (0.006: 0.34 h
    wide), and the box meets Condition III-ii with the margin (before:
    0.994 and 0.96, the strip's two edges sampled on two lattices)."""
    from sr33.samplers.scanline import STRIP_STAGGER

    s = _chamfered_box(chamfer)
    r = scan(s, target_points=3000, repair=False, quiet=True)
    h = r.meta["spacing"]
    p = r.points[r.on_feature]
    # the strip along y = -0.2: its long edge at z = 0.2 - c, its short at y = -0.2 + c
    lead = np.sort(
        p[(np.abs(p[:, 1] + 0.2) < 1e-9) & (np.abs(p[:, 2] - (0.2 - chamfer)) < 1e-9), 0]
    )
    short = p[(np.abs(p[:, 1] + 0.2 - chamfer) < 1e-9) & (np.abs(p[:, 2] - 0.2) < 1e-9), 0]
    inner = np.sort(short)[1:-1]  # the strip's corners aside
    width = chamfer * np.sqrt(2.0)
    across = (lead[1:] + lead[:-1]) / 2 if width < STRIP_STAGGER * h else lead
    assert inner.size >= 15
    assert np.abs(inner[:, None] - across[None]).min(axis=1).max() < 1e-9
    assert _worst(s, 3000) < 0.85


@pytest.fixture(scope="module")
def wide_chamfer():
    """A box 1 x 0.8 x 0.5 chamfered 0.12 on its top edges (7.4 h wide at
    6,000 samples), sampled and measured once: the worst III-ii ratio by
    the geodesic check."""
    import cadquery as cq

    b = cq.Workplane().box(1.0, 0.8, 0.5)
    return _worst(shapes.from_cad(b.edges(">Z").chamfer(0.12).val()), 6000)


def test_a_wide_chamfer_meets_condition_iii(wide_chamfer):
    """The chamfers' rows run down their slopes, along no axis: their
    columns are anchored on the long edges (``_cross_lattice``), and the
    long edges, square to the rows, are repaired with the mitre edges in
    the first pass where the rows' ends stagger against the neighbours'
    samples on them (the top's own lattice against the sides').  Before:
    1.0 with 271 samples at or above 0.85, then 68 with the anchoring
    alone."""
    assert wide_chamfer < np.sqrt(3) / 2


@pytest.mark.xfail(
    strict=True,
    reason="stop 64: 0.8504 (3 samples): the triangle at the corner where two chamfers "
    "meet the sides, its sides 1.0 h along the side's edge and 1.23 h along the mitre "
    "in an angle of 54.7 degrees; the mitre's first sample wants 1.4 h",
)
def test_a_wide_chamfer_meets_condition_iii_with_the_margin(wide_chamfer):
    assert wide_chamfer < 0.85


@pytest.mark.slow
def test_a_narrow_chamfer_round_a_polygon_prism_breaks_iii_only_at_its_corners():
    """A prism over a hexagon of uneven sides, its top edges chamfered
    0.0267 (a strip about 1 h wide at 3,000 samples, slanted to the rows):
    the strip's edges carry one set of samples across it, and the cap's
    repair keeps them.  They slid before: 111 samples broke III-ii (0.980),
    62 of them 3.5 to 9.2 h from any corner of the model.  What is left
    (6 samples, 0.918) is where the mitres meet, within 0.8 h of a corner."""
    import cadquery as cq

    from sr33.validators.conditions import sample_conditions

    ring = [(0.661, 0.215), (0.217, 0.660), (-0.503, 0.479), (-0.679, 0.149), (-0.348, -0.602)]
    ring.append((0.266, -0.642))
    prism = cq.Workplane().polyline(ring).close().extrude(0.51).translate((0, 0, -0.255))
    s = shapes.from_cad(prism.edges(">Z").chamfer(0.0267).val())
    r = scan(s, target_points=3000, quiet=True)
    w = sample_conditions(r.points, s.truth_vertices, s.truth_triangles).worst_ratio
    assert not np.isnan(w).any()
    bad = r.points[w >= np.sqrt(3) / 2]
    corners = np.array([v.toTuple() for v in s.solid.Vertices()])
    far = np.linalg.norm(bad[:, None] - corners[None], axis=2).min(axis=1) / r.meta["spacing"]
    assert far.size == 0 or far.max() < 2.0


def test_a_chamfer_two_h_wide_slanted_to_the_rows_is_scanned_along_its_edges():
    """A prism over a quadrilateral whose sides run along no axis, its top
    edges chamfered 0.042: strips 1.6 h wide at 2,500 samples, wider than
    two clearances (a row fits between their edges) and slanted to every
    scan direction.  Cut across by their family's planes, they kept a few
    samples inside, their two edges on two lattices, and 31 samples broke
    III-ii (0.996; 88 at 3,000 samples).  Each strip is now scanned along
    its edges (``_strip_rows``): its direction lies in its plane square to
    its edges, its two edges carry one set of columns (the longer follows
    the cap's edge, ``_side_followers``), its rows are spaced by the width
    over the whole number of steps nearest its columns' step
    (``_strip_planes``: here one, the cap's rows crossing its edge 1.2 to
    1.4 h apart), and what breaks III-ii is where the mitres meet the
    sides, within 3 h of a corner (13 samples, 0.98, the farthest 2.3 h
    off; before: 14 on the top cap far from any)."""
    import cadquery as cq

    from sr33.samplers.adjacency import EdgeFaces
    from sr33.samplers.faces import steps
    from sr33.samplers.scanline import _strip_rows
    from sr33.validators.conditions import sample_conditions

    ring = [(0.569, -0.288), (-0.02, 0.6375), (-0.638, 0.0), (0.0036, -0.638)]
    prism = cq.Workplane().polyline(ring).close().extrude(0.568).translate((0, 0, -0.284))
    s = shapes.from_cad(prism.edges(">Z").chamfer(0.042).val())
    r = scan(s, target_points=2500, quiet=True)
    h = r.meta["spacing"]
    faces = s.solid.Faces()
    dirs = np.asarray(r.meta["directions"])
    width = 0.042 * np.sqrt(2.0)
    strips = 0
    for fi, f in enumerate(faces):
        n = np.array(f.normalAt().toTuple())
        if abs(n[2]) < 1e-6 or abs(abs(n[2]) - 1.0) < 1e-6:
            continue  # a side or a cap
        strips += 1
        d = dirs[r.meta["face_directions"][fi]]
        e1, e2 = sorted(f.Edges(), key=lambda e: -e.Length())[:2]
        a1, a2 = (np.array(e.startPoint().toTuple()) for e in (e1, e2))
        u = np.array(e1.endPoint().toTuple()) - a1
        u /= np.linalg.norm(u)
        assert abs(d @ u) < 1e-9 and abs(d @ n) < 1e-9
        assert np.abs(d).max() < 1.0 - 1e-9  # along no axis
        # the two edges' samples stand across each other, their ends aside
        on = []
        for a, e in ((a1, e1), (a2, e2)):
            q = r.points - a
            t = q @ u
            off = np.linalg.norm(q - t[:, None] * u, axis=1)
            ends = sorted((np.array(p.toTuple()) - a1) @ u for p in (e.startPoint(), e.endPoint()))
            t = (r.points - a1) @ u  # along the longer edge, from its start
            on.append(np.sort(t[(off < 1e-9) & (t > ends[0] - 1e-9) & (t < ends[1] + 1e-9)]))
        lead, other = on
        inner = other[(other > other[0] + 1.5 * h) & (other < other[-1] - 1.5 * h)]
        assert inner.size >= 10
        assert np.abs(inner[:, None] - lead[None]).min(axis=1).max() < 1e-6 * h
        step = float(np.median(np.diff(inner)))
        assert 0.9 * h < step < 1.45 * h
        # its rows: the width over the steps nearest the columns' step
        rows = steps(width, step)
        q = r.points[(r.face_id == fi) & ~r.on_feature] - a1
        off = np.linalg.norm(q - (q @ u)[:, None] * u, axis=1)
        on_row = np.abs(off / (width / rows) - np.round(off / (width / rows))) < 1e-6
        assert rows == 1 and q.shape[0] <= 8 or on_row.mean() >= 0.6
    assert strips == 4
    # a strip wider than three spacings, or narrower than two clearances, keeps its family
    ef = EdgeFaces(s.solid)
    for h_try in (width / 3.2, width / 1.3):
        same, fam, held = _strip_rows(ef, np.eye(3), [0] * len(faces), h_try, 1e-9)
        assert same.shape == (3, 3) and fam == [0] * len(faces) and not held
    w = sample_conditions(r.points, s.truth_vertices, s.truth_triangles).worst_ratio
    bad = r.points[w >= np.sqrt(3) / 2]
    corners = np.array([v.toTuple() for v in s.solid.Vertices()])
    far = np.linalg.norm(bad[:, None] - corners[None], axis=2).min(axis=1) / h
    assert bad.shape[0] <= 20 and (far.size == 0 or far.max() < 3.0)


def test_a_box_fused_on_a_corner_meets_condition_iii_with_the_margin():
    """A box 0.4 with a box 0.24 fused on its top corner (the survey's
    boolean seam class, axis-aligned): 237 samples at or above 0.85 before
    (0.9994), the shorter faces' rows staggered against their edges."""
    assert _worst(shapes.from_cad(_corner_union()), 3000) < 0.85


@pytest.mark.slow
def test_a_box_notched_by_a_cut_meets_condition_iii_with_the_margin():
    """A box 0.5 x 0.4 x 0.3 with a pocket cut from its top and one side
    (1.0 before, 244 samples at or above 0.85): the pocket's walls have
    lattices of their own, the edges between them and the L-shaped faces
    take the lattice crossings, and a face whose lattice still staggers
    against an edge's samples is repaired along it."""
    import cadquery as cq

    pocket = _box(0.2, 0.3, 0.25).translate(cq.Vector(-0.1, 0.05, 0.15))
    s = shapes.from_cad(_box(0.5, 0.4, 0.3).cut(pocket))
    assert _worst(s, 3000) < 0.85
