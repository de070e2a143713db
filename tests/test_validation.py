"""Bad input to the library: one clear error naming the problem."""

import numpy as np
import pytest

from sr33 import InputError, reconstruct
from sr33.samplers import cube_lattice


def test_nan_is_named_with_its_row():
    pts = cube_lattice(2)
    pts[5, 1] = np.nan
    with pytest.raises(
        InputError,
        match=r"^points: 1 of 26 points have non-finite \(NaN or inf\) coordinates, "
        r"first point 5 = \[",
    ):
        reconstruct(pts, 8)


def test_inf_is_named():
    pts = cube_lattice(2)
    pts[0, 0] = np.inf
    with pytest.raises(InputError, match="1 of 26 points have non-finite"):
        reconstruct(pts, 8)


def test_too_few_points():
    with pytest.raises(InputError, match="points must hold at least 4 points, got 3"):
        reconstruct(np.eye(3), 3)


def test_wrong_shape():
    with pytest.raises(InputError, match=r"points must have shape \(n, 3\), got \(10, 2\)"):
        reconstruct(np.zeros((10, 2)), 3)


def test_not_numeric():
    with pytest.raises(InputError, match="points must be numeric"):
        reconstruct([["a", "b", "c"]] * 5, 3)


def test_collinear_points():
    pts = np.stack([np.arange(10.0), 2 * np.arange(10.0), np.zeros(10)], 1)
    with pytest.raises(InputError, match="points are degenerate: all 10 points lie on one line"):
        reconstruct(pts, 4)


def test_all_equal_points_are_duplicates_then_too_few():
    with pytest.raises(InputError, match="at least 4 points|degenerate"):
        reconstruct(np.ones((10, 3)), 3)


@pytest.mark.parametrize(
    "k, msg",
    [
        (2, "k must be at least 3, got 2"),
        (26, "k must be less than the number of distinct points \\(26\\), got 26"),
        (3.5, "k must be an integer, got float 3.5"),
    ],
)
def test_k_out_of_range(k, msg):
    with pytest.raises(InputError, match=msg):
        reconstruct(cube_lattice(2), k)


def test_duplicates_are_merged_reported_and_mapped_back():
    pts = cube_lattice(2)
    dup = np.vstack([pts, pts[[3, 3, 7]]])
    r = reconstruct(dup, 8)
    assert r.duplicates_merged == 3
    assert r.vertices.shape == pts.shape
    assert r.input_to_vertex[26] == r.input_to_vertex[3] == r.input_to_vertex[27]
    assert r.input_to_vertex[28] == r.input_to_vertex[7]
    np.testing.assert_array_equal(r.vertices[r.input_to_vertex], dup)


def test_input_array_is_not_modified():
    pts = cube_lattice(2)[::-1].copy()
    before = pts.copy()
    reconstruct(pts, 8)
    np.testing.assert_array_equal(pts, before)


def test_errors_are_value_errors():
    assert issubclass(InputError, ValueError)
