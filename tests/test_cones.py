"""Cones for stray samples (end of Section 5)."""

import numpy as np
import pytest

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
