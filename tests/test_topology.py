"""validators.topology: the counting every report uses."""

import numpy as np
import pytest

from sr33.validators import mesh_stats

TETRA = [(0, 1, 2), (0, 3, 1), (1, 3, 2), (2, 3, 0)]


def test_tetrahedron():
    s = mesh_stats(TETRA)
    assert s.as_dict() == {
        "points": 4,
        "used_vertices": 4,
        "faces": 4,
        "edges": 6,
        "open_edges": 0,
        "overloaded_edges": 0,
        "euler": 2,
        "components": 1,
        "boundary_loops": 0,
    }


def test_open_square_has_one_boundary_loop():
    s = mesh_stats([(0, 1, 2), (0, 2, 3)], n_points=6)
    assert (s.points, s.used_vertices, s.edges, s.open_edges, s.euler, s.boundary_loops) == (
        6,
        4,
        5,
        4,
        1,
        1,
    )


def test_two_tetrahedra_are_two_components():
    t = np.array(TETRA)
    s = mesh_stats(np.vstack([t, t + 4]))
    assert (s.components, s.euler) == (2, 4)


def test_overloaded_edge_is_counted():
    s = mesh_stats([(0, 1, 2), (0, 1, 3), (0, 1, 4)])
    assert s.overloaded_edges == 1
    assert s.open_edges == 6


def test_annulus_has_two_boundary_loops():
    # a ring of 4 quads (8 triangles) between an inner and outer square
    inner, outer = [0, 1, 2, 3], [4, 5, 6, 7]
    tri = []
    for i in range(4):
        a, b = inner[i], inner[(i + 1) % 4]
        c, d = outer[(i + 1) % 4], outer[i]
        tri += [(a, b, c), (a, c, d)]
    s = mesh_stats(tri)
    assert (s.euler, s.boundary_loops, s.open_edges) == (0, 2, 8)


def test_bad_input_messages():
    with pytest.raises(ValueError, match=r"triangles must have shape \(t, 3\), got \(2, 2\)"):
        mesh_stats([(0, 1), (1, 2)])
    with pytest.raises(ValueError, match="n_points \\(2\\) is smaller than the largest index"):
        mesh_stats(TETRA, n_points=2)
