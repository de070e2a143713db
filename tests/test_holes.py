"""Boundary loops of the selection closed by one face (sr33.holes, issue 21 item 3)."""

import numpy as np

from sr33 import reconstruct
from sr33.cycles import CycleSet, concat
from sr33.holes import face_links, hole_loops, uncovered, unpinch
from sr33.io import read_points
from sr33.samplers import cube_lattice
from sr33.triangulate import triangulate
from sr33.validators import mesh_stats
from sr33.validators.intersections import self_intersections
from tests.helpers import PAPER_SMALL, need


def _cycles(rows) -> CycleSet:
    lengths = np.array([len(r) for r in rows], dtype=np.int64)
    offsets = np.r_[0, np.cumsum(lengths)].astype(np.int64)
    return CycleSet(offsets, np.array([v for r in rows for v in r], dtype=np.int64))


def _grid(m: int, z=None):
    """An (m+1) x (m+1) planar grid of unit quads (optionally lifted by z(x, y))."""
    ij = np.stack(np.meshgrid(np.arange(m + 1), np.arange(m + 1), indexing="ij"), -1)
    ij = ij.reshape(-1, 2).astype(float)
    h = np.zeros(ij.shape[0]) if z is None else z(ij[:, 0], ij[:, 1])
    pts = np.c_[ij, h]
    idx = np.arange((m + 1) ** 2).reshape(m + 1, m + 1)
    quads = [
        [idx[i, j], idx[i + 1, j], idx[i + 1, j + 1], idx[i, j + 1]]
        for i in range(m)
        for j in range(m)
    ]
    return pts, quads


def _cube_faces():
    pts = cube_lattice(6)
    rec = reconstruct(pts, 12)
    assert rec.success and rec.hole_faces == 0
    return rec.vertices, rec.face_cycles


def test_a_hole_round_a_stray_sample_is_closed_by_its_loop():
    pts, faces = _cube_faces()
    # remove the faces round one sample of a cube face: a hole, the sample stray
    centre = int(np.argmin(np.linalg.norm(pts - [3.0, 3.0, 0.0], axis=1)))
    rows = faces.as_tuples()
    ring = [r for r in rows if centre in r]
    holed = _cycles([r for r in rows if centre not in r])
    hl = hole_loops(pts, holed)
    assert hl.found == 1 and len(hl.loops) == 1
    rim = {v for r in ring for v in r} - {centre}
    assert set(hl.loops.cycle(0).tolist()) == rim
    closed = concat(holed, hl.loops)
    disk = face_links(pts.shape[0], closed)
    assert disk[list(rim)].all() and not disk[centre]
    # triangulated, it is covered by the samples (the stray sits under it)
    tr = triangulate(pts, closed)
    mine = tr.face_of_triangle == len(holed)
    assert not uncovered(pts, tr.triangles[mine], np.zeros(mine.sum(), np.int64), np.ones(1))[0]


def test_the_whole_pipeline_closes_such_a_hole_and_keeps_every_sample():
    # the paper's small cutcube (a solid torus's surface) with k = 4: the
    # selection leaves one hole; its loop face closes it cleanly
    pts = read_points(need(PAPER_SMALL / "cutcube.obj"))
    off = reconstruct(pts, 4, max_hole_length=0)
    assert off.hole_faces == 0 and mesh_stats(off.triangles, pts.shape[0]).open_edges > 0
    rec = reconstruct(pts, 4)
    st = mesh_stats(rec.triangles, rec.vertices.shape[0])
    assert rec.hole_faces >= 1 and rec.success
    assert st.open_edges == 0 and st.overloaded_edges == 0 and st.euler == 0
    assert st.used_vertices == pts.shape[0] and rec.open_edges.shape[0] == 0
    assert self_intersections(rec.vertices, rec.triangles).shape[0] == 0


def test_the_rim_of_a_sheet_is_not_closed_into_a_pillow():
    pts, quads = _grid(5)
    hl = hole_loops(pts, _cycles(quads))
    assert hl.found == 1 and len(hl.loops) == 0  # the cap would double the sheet


def test_the_rim_of_a_tube_is_not_covered_by_its_samples():
    # an open cylinder of 24 x 10 unit-ish quads: its two rims are loops of 24
    # edges over empty discs of radius about 3.8 edges
    m, rows = 24, 10
    ang = 2 * np.pi * np.arange(m) / m
    r = 1.0 / (2 * np.sin(np.pi / m))
    pts = np.array([[r * np.cos(a), r * np.sin(a), z] for z in range(rows + 1) for a in ang])
    quads = [
        [z * m + i, z * m + (i + 1) % m, (z + 1) * m + (i + 1) % m, (z + 1) * m + i]
        for z in range(rows)
        for i in range(m)
    ]
    faces = _cycles(quads)
    hl = hole_loops(pts, faces)
    assert hl.found == 2 and len(hl.loops) == 2  # combinatorially fine
    closed = concat(faces, hl.loops)
    tr = triangulate(pts, closed)
    mine = tr.face_of_triangle >= len(faces)
    bad = uncovered(pts, tr.triangles[mine], tr.face_of_triangle[mine] - len(faces), np.ones(2))
    assert bad.all()
    # and the reconstruction keeps both rims open (48 boundary edges)
    rec = reconstruct(pts + 1e-3 * np.sin(np.arange(pts.size)).reshape(pts.shape), 12)
    assert rec.hole_faces == 0
    assert mesh_stats(rec.triangles, rec.vertices.shape[0]).boundary_loops == 2


def test_a_figure_eight_boundary_splits_into_the_two_loops_that_unpinch_it():
    # two squares of a grid removed that share one corner: the boundary is a
    # figure eight through that corner; each square's loop joins two pieces of
    # the corner's link, so both loops together close it into a disk
    pts, quads = _grid(4)
    idx = np.arange(25).reshape(5, 5)
    gone = [
        [idx[1, 1], idx[2, 1], idx[2, 2], idx[1, 2]],
        [idx[2, 2], idx[3, 2], idx[3, 3], idx[2, 3]],
    ]
    faces = _cycles([q for q in quads if q not in gone])
    hl = hole_loops(pts, faces)
    assert len(hl.loops) == 2
    assert sorted(map(sorted, hl.loops.as_tuples())) == sorted(sorted(g) for g in gone)
    disk = face_links(pts.shape[0], concat(faces, hl.loops))
    assert disk.all()


def test_unpinch_removes_the_smaller_fan_at_a_pinched_sample():
    # a 4 x 4 grid and a 1 x 2 strip standing on its centre sample 12
    pts, quads = _grid(4)
    extra = np.array([[3.0, 2.0, 1.0], [3.0, 2.0, 2.0], [2.0, 2.0, 2.0], [3.0, 2.0, 3.0]])
    pts = np.vstack([pts, extra, [[2.0, 2.0, 3.0]]])
    strip = [[12, 25, 26, 27], [27, 26, 28, 29]]
    faces = _cycles(quads + strip)
    assert not face_links(pts.shape[0], faces)[12]
    gone = unpinch(faces, pts.shape[0])
    assert gone.tolist() == [len(quads)]  # the strip's face at 12, nothing else
    keep = np.ones(len(faces), bool)
    keep[gone] = False
    assert face_links(pts.shape[0], faces.subset(keep))[12]
    # a sample whose link is already a disk is never touched
    assert unpinch(_cycles(quads), pts.shape[0]).shape[0] == 0
