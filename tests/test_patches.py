"""Stray samples inserted into the face they lie over (sr33.patches, issue 21 item 4)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from sr33.cycles import CycleSet
from sr33.patches import chart_patch, stray_clusters, stray_patches
from sr33.triangulate import triangulate
from sr33.validators.intersections import self_intersections


def cone_tip(columns: int, rings: int, half_angle: float, tilt: float, twist: float = 0.3):
    """A cone's tip sampled in rings: ring 0 (``2 * columns`` samples) is the
    face's cycle, rings 1.. (``columns`` each, twisted) and the apex are the
    strays; the axis is tilted by ``tilt`` radians off the ring's normal."""
    pts = []
    slope = np.tan(half_angle)
    for r in range(rings + 1):
        m = 2 * columns if r == 0 else columns
        height = float(r)
        radius = slope * (rings + 1 - height)
        ang = 2 * np.pi * np.arange(m) / m + twist * r
        pts.append(np.stack([radius * np.cos(ang), radius * np.sin(ang), np.full(m, height)], 1))
    pts.append(np.array([[0.0, 0.0, rings + 1.0]]))
    p = np.vstack(pts)
    c, s = np.cos(tilt), np.sin(tilt)
    turn = np.array([[1, 0, 0], [0, c, -s], [0, s, c]])
    return p @ turn.T


def boundary_edges(tri: np.ndarray) -> set[tuple[int, int]]:
    e = np.sort(np.concatenate([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]]), axis=1)
    keys, counts = np.unique(e, axis=0, return_counts=True)
    assert counts.max() <= 2, "an edge used by three triangles"
    return {tuple(k) for k in keys[counts == 1].tolist()}


@settings(max_examples=40, deadline=None)
@given(
    columns=st.integers(3, 8),
    rings=st.integers(1, 5),
    half_angle=st.floats(0.15, 1.2),
    tilt=st.floats(0.0, 0.6),
    twist=st.floats(0.0, 0.6),
)
def test_a_cone_tip_over_its_ring_is_a_disk_through_every_stray(
    columns, rings, half_angle, tilt, twist
):
    p = cone_tip(columns, rings, half_angle, tilt, twist)
    L = 2 * columns
    cyc = np.arange(L)
    ins = np.arange(L, p.shape[0])
    tri = chart_patch(p, cyc, ins)
    assert tri is not None
    # a disk: L - 2 + 2s triangles, bounded by exactly the cycle, through every sample
    assert tri.shape == (L - 2 + 2 * ins.shape[0], 3)
    ring = {(min(a, b), max(a, b)) for a, b in zip(cyc, np.roll(cyc, -1))}
    assert boundary_edges(tri) == ring
    assert set(np.unique(tri).tolist()) == set(range(p.shape[0]))
    # oriented alike: every inner edge is crossed both ways
    half = np.concatenate([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]])
    assert np.unique(half, axis=0).shape[0] == half.shape[0]
    # a graph over the chart: pairwise disjoint interiors
    assert self_intersections(p, tri).shape[0] == 0


def test_a_stray_outside_the_ring_or_a_ring_folded_in_the_chart_gives_no_patch():
    p = cone_tip(4, 2, 0.5, 0.0)
    cyc, ins = np.arange(8), np.arange(8, p.shape[0])
    assert chart_patch(p, cyc, ins) is not None
    out = p.copy()
    out[-1, :2] = [5.0, 0.0]  # the apex moved beyond the ring in the chart
    assert chart_patch(out, cyc, ins) is None
    # the cycle's order crossing itself (a bow tie in the chart)
    bow = np.array([0, 1, 2, 3, 5, 4, 6, 7])
    assert chart_patch(p, bow, ins) is None


def test_clusters_are_the_rng_components_of_the_strays_with_what_they_reach():
    used = np.array([1, 1, 1, 1, 0, 0, 0, 1, 0], dtype=bool)
    edges = np.array([[0, 4], [4, 5], [1, 5], [6, 7], [2, 3], [6, 8]])
    clusters, reach = stray_clusters(9, used, edges)
    assert [c.tolist() for c in clusters] == [[4, 5], [6, 8]]
    assert [r.tolist() for r in reach] == [[0, 1], [7]]


def _tip_faces(p, columns):
    """The tip's ring face plus a band of quads below it, all as cycles."""
    L = 2 * columns
    cycles = [list(range(L))]
    below = p[:L] * np.array([1.2, 1.2, 1.0]) - np.array([0, 0, 1.0])
    pts = np.vstack([p, below])
    base = p.shape[0]
    for i in range(L):
        j = (i + 1) % L
        cycles.append([i, j, base + j, base + i])
    lengths = [len(c) for c in cycles]
    offsets = np.r_[0, np.cumsum(lengths)].astype(np.int64)
    return pts, CycleSet(offsets, np.array([v for c in cycles for v in c], dtype=np.int64))


def test_the_ring_face_takes_the_cluster_that_reaches_only_its_samples():
    p = cone_tip(4, 3, 0.35, 0.2)
    pts, faces = _tip_faces(p, 4)
    L = 8
    ins = np.arange(L, p.shape[0])
    # the RNG: the strays in a chain, the lowest ring reaching the ring face
    chain = np.stack([ins[:-1], ins[1:]], 1)
    reach = np.array([[L + i, 2 * i] for i in range(4)])
    got = stray_patches(pts, faces, np.vstack([chain, reach]), min_interior=2)
    assert list(got) == [0]
    assert got[0].interior.tolist() == ins.tolist()
    # a cluster reaching a sample off the ring face (the band's lower row) is not placed
    off = np.vstack([chain, reach, [[ins[0], p.shape[0]]]])
    assert stray_patches(pts, faces, off, min_interior=2) == {}
    # fewer strays than min_interior: left to the ring centres
    one = np.array([[L, 0]])
    assert stray_patches(pts, faces, one, min_interior=2) == {}


def test_triangulate_orients_a_patch_with_its_face_and_keeps_the_euler_characteristic():
    p = cone_tip(4, 3, 0.35, 0.2)
    pts, faces = _tip_faces(p, 4)
    ins = np.arange(8, p.shape[0])
    chain = np.stack([ins[:-1], ins[1:]], 1)
    reach = np.array([[8 + i, 2 * i] for i in range(4)])
    got = stray_patches(pts, faces, np.vstack([chain, reach]), min_interior=2)
    tr = triangulate(pts, faces, patches={0: got[0].triangles[:, ::-1]})
    tri = tr.triangles
    # one orientation: no directed edge twice
    half = np.concatenate([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]])
    assert np.unique(half, axis=0).shape[0] == half.shape[0]
    used = np.unique(tri)
    e = np.unique(np.sort(half, axis=1), axis=0)
    # an open band capped by the patch: a disk
    assert used.shape[0] - e.shape[0] + tri.shape[0] == 1
    assert np.bincount(tr.face_of_triangle)[0] == 8 - 2 + 2 * ins.shape[0]


def test_triangulate_refuses_a_patch_for_a_face_out_of_range():
    p = cone_tip(3, 1, 0.4, 0.0)
    faces = CycleSet(np.array([0, 6]), np.arange(6))
    with pytest.raises(Exception, match="patches names face 3"):
        triangulate(p, faces, patches={3: np.array([[0, 1, 2]])})


def test_a_ring_that_is_not_convex_in_its_chart_keeps_only_the_triangles_inside_it():
    # a ten-pointed star (radii 1 and 0.8) round three samples raised off its plane:
    # the Delaunay triangles in its notches lie outside the ring and are not the patch's
    ang = np.pi * np.arange(10) / 5
    rad = np.where(np.arange(10) % 2, 0.8, 1.0)
    ring = np.stack([rad * np.cos(ang), rad * np.sin(ang), np.zeros(10)], 1)
    inner = np.array([[0.2, 0.1, 0.3], [-0.25, 0.05, 0.35], [0.0, -0.3, 0.25]])
    p = np.vstack([ring, inner])
    tri = chart_patch(p, np.arange(10), np.arange(10, 13))
    assert tri is not None
    assert tri.shape == (10 - 2 + 2 * 3, 3)
    assert boundary_edges(tri) == {(min(i, (i + 1) % 10), max(i, (i + 1) % 10)) for i in range(10)}


def test_a_ring_closed_by_several_faces_is_patched_as_their_polygon():
    # the tip's ring of 8 closed by two faces (split by the chord 0-4) and a
    # band below it; the strays reach every sample of the ring
    p = cone_tip(4, 3, 0.35, 0.2)
    pts, band = _tip_faces(p, 4)
    cycles = [[0, 1, 2, 3, 4], [0, 4, 5, 6, 7]] + [band.cycle(i).tolist() for i in range(1, 9)]
    offsets = np.r_[0, np.cumsum([len(c) for c in cycles])].astype(np.int64)
    faces = CycleSet(offsets, np.array([v for c in cycles for v in c], dtype=np.int64))
    ins = np.arange(8, p.shape[0])
    chain = np.stack([ins[:-1], ins[1:]], 1)
    reach = np.array([[8 + i % 4, i] for i in range(8)])
    got = stray_patches(pts, faces, np.vstack([chain, reach]), min_interior=2)
    assert sorted(got) == [0, 1]
    carrier = [f for f in got if got[f].triangles.shape[0]]
    assert len(carrier) == 1 and got[carrier[0]].interior.tolist() == ins.tolist()
    patch = got[carrier[0]].triangles
    assert patch.shape == (8 - 2 + 2 * ins.shape[0], 3)
    assert boundary_edges(patch) == {(min(i, (i + 1) % 8), max(i, (i + 1) % 8)) for i in range(8)}
    tr = triangulate(pts, faces, patches={f: q.triangles for f, q in got.items()})
    tri = tr.triangles
    half = np.concatenate([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]])
    assert np.unique(half, axis=0).shape[0] == half.shape[0]  # one orientation
    e = np.unique(np.sort(half, axis=1), axis=0)
    assert np.unique(tri).shape[0] - e.shape[0] + tri.shape[0] == 1  # a disk
    # a cluster that also reaches a sample of the band below is not placed
    off = np.vstack([chain, reach, [[ins[0], p.shape[0]]]])
    assert stray_patches(pts, faces, off, min_interior=2) == {}
    # nor when a face of the polygon is skipped (its patch crossed something)
    assert (
        stray_patches(pts, faces, np.vstack([chain, reach]), skip_faces=[1], min_interior=2) == {}
    )
