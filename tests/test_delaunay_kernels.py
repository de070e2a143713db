"""The repair's own Delaunay triangulation (sweep hull and Lawson's flips in
numba): Qhull's triangles wherever the Delaunay triangulation is unique, a
valid Delaunay tiling of the hull on lattices (cocircular squares) by its
documented tie rule, the same whatever the points' order, and no answer
rather than a wrong one on degenerate input."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial import ConvexHull, Delaunay

from sr33.samplers._delaunay_kernels import delaunay_triangles
from sr33.samplers._repair_kernels import delaunay_flips, incircle


def _valid(pts, tri, nbr, tol_circle):
    """Every triangle counter-clockwise, every point a corner, the hull tiled
    once (the areas add up to the hull's), the neighbours each other's across
    a shared side, and every inner side locally Delaunay within ``tol_circle``."""
    p = pts[tri]
    area = (p[:, 1, 0] - p[:, 0, 0]) * (p[:, 2, 1] - p[:, 0, 1]) - (p[:, 1, 1] - p[:, 0, 1]) * (
        p[:, 2, 0] - p[:, 0, 0]
    )
    assert (area > 0).all()
    assert np.array_equal(np.unique(tri), np.arange(len(pts)))
    hull = ConvexHull(pts).volume
    assert abs(area.sum() / 2 - hull) <= 1e-9 * hull
    for t in range(len(tri)):
        for k in range(3):
            u = nbr[t, k]
            if u < 0:
                continue
            side = {tri[t, (k + 1) % 3], tri[t, (k + 2) % 3]}
            assert side <= set(tri[u].tolist()) and t in nbr[u]
            far = (set(tri[u].tolist()) - side).pop()
            assert incircle(pts, tri[t, 0], tri[t, 1], tri[t, 2], far) <= tol_circle
    # every hull side once: 2n - h - 2 triangles
    assert len(tri) == 2 * len(pts) - (nbr < 0).sum() - 2


@settings(max_examples=80, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), n=st.integers(3, 400), scale=st.sampled_from([1e-3, 1, 1e3]))
def test_points_in_general_position_get_qhulls_triangles(seed, n, scale):
    rng = np.random.default_rng(seed)
    pts = (rng.random((n, 2)) - 0.3) * scale
    got = delaunay_triangles(pts, 1e-12 * scale**2, 1e-12 * scale**4)
    assert got is not None
    tri, nbr = got
    _valid(pts, tri, nbr, 1e-12 * scale**4)
    want = Delaunay(pts).simplices
    assert {tuple(t) for t in np.sort(tri, 1).tolist()} == {
        tuple(t) for t in np.sort(want, 1).tolist()
    }


@settings(max_examples=60, deadline=None)
@given(
    seed=st.integers(0, 2**32 - 1),
    rows=st.integers(2, 20),
    cols=st.integers(2, 20),
    angle=st.sampled_from([0.0, 0.25, np.pi / 4, 1.0, np.pi / 2]),
    jitter=st.sampled_from([0.0, 1e-13, 1e-3]),
)
def test_lattices_are_tiled_by_the_tie_rule_whatever_the_order(seed, rows, cols, angle, jitter):
    """A repair's samples stand on lattices whose squares are cocircular
    within rounding: either diagonal is Delaunay, and the kernel keeps the
    one its insertion order gives (distance from the seed circle's centre,
    then x, then y), so a shuffled input gives the same triangles."""
    rng = np.random.default_rng(seed)
    h = 0.02
    g = np.stack(np.meshgrid(np.arange(cols), np.arange(rows)), -1).reshape(-1, 2).astype(float)
    c, s = np.cos(angle), np.sin(angle)
    pts = (g @ np.array([[c, s], [-s, c]]) + rng.uniform(-jitter, jitter, g.shape)) * h + 0.7
    tol_area, tol_circle = 1e-9 * h * h, 1e-10 * h**4
    got = delaunay_triangles(pts, tol_area, tol_circle)
    assert got is not None
    tri, nbr = got
    _valid(pts, tri, nbr, tol_circle)
    # the carried triangulation's flips (the repair's next step) find nothing to do
    flipped = delaunay_flips(pts, tri, nbr, tol_area, tol_circle)
    assert flipped is not None and flipped[2] == 0
    perm = rng.permutation(len(pts))
    again = delaunay_triangles(pts[perm], tol_area, tol_circle)
    assert again is not None
    assert {tuple(t) for t in np.sort(tri, 1).tolist()} == {
        tuple(t) for t in np.sort(perm[again[0]], 1).tolist()
    }


@pytest.mark.parametrize(
    "pts",
    [
        np.zeros((2, 2)),  # too few
        np.c_[np.arange(6.0), 2 * np.arange(6.0)],  # collinear
        np.array([[0, 0], [1, 0], [0, 1], [1, 1], [1, 0]], float),  # a duplicate
        np.array([[0, 0], [1, 0], [0, 1], [1, 1], [0.5, 0.5], [0.5, 0.5]], float),
    ],
    ids=["two points", "collinear", "duplicate on the hull", "duplicate inside"],
)
def test_degenerate_input_gets_no_triangles_rather_than_wrong_ones(pts):
    assert delaunay_triangles(pts, 1e-12, 1e-12) is None


def test_a_row_of_collinear_points_on_the_hull_makes_no_flat_triangle():
    """Samples along a straight edge of a face's window lie on the hull in a
    row: Qhull left flat triangles of three of them there (peeled by the
    repair's ``_without_flat_hull``); the sweep sees a hull edge only from
    beyond it by more than ``tol_area``."""
    row = np.c_[np.linspace(0, 1, 11), np.zeros(11)]
    pts = np.vstack([row, row + (0.05, 0.1), [[0.5, 0.3]]])
    tri, nbr = delaunay_triangles(pts, 1e-12, 1e-12)
    _valid(pts, tri, nbr, 1e-12)
