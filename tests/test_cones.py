"""Cones for stray samples (end of Section 5)."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from sr33 import InputError, attach_cones
from sr33.validators import mesh_stats

TETRA = np.array([[0, 1, 2], [0, 3, 1], [1, 3, 2], [2, 3, 0]])
TETRA_PTS = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], float)


def test_stray_sample_is_coned_over_its_nearest_triangle_keeping_topology():
    pts = np.vstack([TETRA_PTS, [[0.3, 0.3, 0.38]], [[0.05, 0.02, -0.01]]])
    tri, strays = attach_cones(pts, TETRA)
    assert strays.tolist() == [4, 5]
    s = mesh_stats(tri, len(pts))
    assert s.used_vertices == 6
    assert (s.open_edges, s.overloaded_edges, s.euler, s.components) == (0, 0, 2, 1)
    assert tri.shape[0] == 4 + 2 * 2
    # sample 4 lies over the slanted face (1, 3, 2): that face is the one replaced
    assert (1, 3, 2) not in {tuple(t) for t in tri.tolist()}
    # orientation inherited: still each directed edge once
    d = np.concatenate([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]])
    assert np.unique(d, axis=0).shape[0] == d.shape[0]


def test_no_strays_returns_a_copy():
    tri, strays = attach_cones(TETRA_PTS, TETRA)
    assert strays.size == 0
    assert np.array_equal(tri, TETRA)


def test_empty_surface_is_an_error():
    with pytest.raises(InputError, match="triangles is empty"):
        attach_cones(TETRA_PTS, np.empty((0, 3), int))


def _bevelled_roof(angle_deg, n=12, rows=4):
    """Two planar faces meeting at a sharp edge of ``angle_deg`` (dihedral),
    rows h apart on each face, the edge's own samples left stray and the two
    first rows joined across the edge by chords: the bevel a closed selection
    makes at an acute edge (issue 21)."""
    a = np.radians(angle_deg) / 2
    faces = {"A": np.array([0, np.sin(a), np.cos(a)]), "B": np.array([0, -np.sin(a), np.cos(a)])}
    idx, pts = {}, []
    for side, d in faces.items():
        for j in range(1, rows + 1):
            for i in range(n):
                idx[side, i, j] = len(pts)
                pts.append(np.array([i + 0.5 * (j % 2), 0, 0]) + j * d)
    ridge = []
    for i in range(n):
        ridge.append(len(pts))
        pts.append(np.array([i + 0.5, 0, 0]))
    tri = []
    for side in "AB":
        for j in range(1, rows):
            for i in range(n - 1):
                a_, b_ = idx[side, i, j], idx[side, i + 1, j]
                c_, d_ = idx[side, i, j + 1], idx[side, i + 1, j + 1]
                tri += [(a_, b_, d_), (a_, d_, c_)] if side == "A" else [(a_, d_, b_), (a_, c_, d_)]
    for i in range(n - 1):
        a_, b_ = idx["A", i, 1], idx["A", i + 1, 1]
        c_, d_ = idx["B", i, 1], idx["B", i + 1, 1]
        tri += [(a_, d_, b_), (a_, c_, d_)]
    return np.array(pts), np.array(tri), ridge


@pytest.mark.parametrize("angle", [20.0, 40.0, 60.0, 90.0])
def test_cones_on_a_bevel_are_flipped_back_to_the_sharp_edge(angle):
    """The stray samples of a bevelled sharp edge, inserted where no new
    triangle crosses another (an edge split or a cone) and flipped for the
    least total absolute curvature, lie on one line of edges again, with no
    two triangles crossing, before the flips and after."""
    from sr33.mesh import half_edges, self_intersections, unique_edges

    pts, tri, ridge = _bevelled_roof(angle)
    tents, _ = attach_cones(pts, tri, flips=False)
    out, strays = attach_cones(pts, tri)
    assert sorted(strays.tolist()) == ridge
    assert self_intersections(pts, tents).shape[0] == 0
    assert self_intersections(pts, out).shape[0] == 0
    edges = {tuple(e) for e in unique_edges(half_edges(out)[0]).tolist()}
    assert all((a, b) in edges for a, b in zip(ridge[:-1], ridge[1:]))
    assert out.shape[0] == tents.shape[0]


@settings(max_examples=60, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), flat=st.booleans())
def test_flip_cost_kernel_matches_its_definition(seed, flat):
    """The numba cost of an edge flip equals the curvature from its
    definition (tests/naive.py), degenerate (zero-area) triangles included."""
    from sr33._kernels import flip_costs
    from tests.naive import naive_flip_costs

    rng = np.random.default_rng(seed)
    pts = rng.normal(size=(8, 3))
    if flat:  # a zero-area triangle across one outer edge
        pts[7] = 0.5 * (pts[1] + pts[3])
    quad = np.array([0, 1, 2, 3])
    across = np.array([[2, 1, 4], [0, 2, 5], [3, 0, 6], [1, 3, 7]])
    t1, t2 = np.array([0, 1, 2]), np.array([1, 0, 3])
    got = flip_costs(pts, t1, t2, quad, across)
    want = naive_flip_costs(pts, quad, across)
    assert np.allclose(got, want, rtol=1e-12, atol=1e-12)


def test_an_insertion_never_crosses_a_long_triangle_whose_centroid_is_far():
    """A sliver reaching from far away to just beside a stray sample crosses
    the cone over the triangle under the sample, not a cone one cell over:
    the crossing check must see the sliver although it is not among the
    triangles nearest the sample (a crossing cheburashka once got)."""
    from sr33.validators.intersections import self_intersections

    xs, ys = np.meshgrid(np.arange(31.0), np.arange(3.0), indexing="ij")
    grid = np.stack([xs.ravel(), ys.ravel(), np.zeros(xs.size)], axis=1)
    idx = np.arange(xs.size).reshape(xs.shape)
    tri = []
    for i in range(30):
        for j in range(2):
            a, b, c, d = idx[i, j], idx[i + 1, j], idx[i + 1, j + 1], idx[i, j + 1]
            tri += [(a, b, d), (b, c, d)]
    m = grid.shape[0]
    sliver = np.array([[1.3, 0.45, 0.05], [40.0, 0.40, 0.05], [40.0, 0.50, 0.05]])
    stray = np.array([[1.5, 0.45, 0.1]])
    pts = np.vstack([grid, sliver, stray])
    tri.append((m, m + 1, m + 2))
    out, strays = attach_cones(pts, tri, flips=False)
    assert strays.tolist() == [m + 3]
    assert (out == m + 3).any()
    assert self_intersections(pts, out).shape[0] == 0
