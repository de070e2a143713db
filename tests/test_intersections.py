"""validators.intersections: crossing, touching, folded and clean meshes."""

import numpy as np

from sr33 import reconstruct
from sr33.samplers import cube_lattice
from sr33.validators.intersections import self_intersections
from tests.meshes import icosphere


def test_two_crossing_triangles_are_one_pair():
    v = np.array([[0, 0, 0], [2, 0, 0], [0, 2, 0], [0.5, 0.5, -1], [0.5, 0.5, 1], [3, 3, 0]], float)
    assert self_intersections(v, [(0, 1, 2), (3, 4, 5)]).tolist() == [[0, 1]]


def test_triangles_sharing_an_edge_or_vertex_do_not_intersect():
    p, f = icosphere()
    assert self_intersections(p, f).shape == (0, 2)


def test_fold_over_a_shared_edge_is_an_intersection():
    v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0.3, 0.6, 0]], float)
    assert self_intersections(v, [(0, 1, 2), (0, 1, 3)]).tolist() == [[0, 1]]


def test_edge_through_a_triangle_sharing_a_vertex():
    v = np.array([[0, 0, 0], [2, 0, 0], [0, 2, 0], [1, 0.2, -1], [0.2, 1, 1]], float)
    # triangle (0, 3, 4) shares vertex 0; its edge 3-4 pierces triangle (0, 1, 2)
    assert self_intersections(v, [(0, 1, 2), (0, 3, 4)]).tolist() == [[0, 1]]


def test_reconstructed_cube_lattice_has_disjoint_interiors():
    pts = cube_lattice(5)
    r = reconstruct(pts, 12)
    assert self_intersections(r.vertices, r.triangles).shape == (0, 2)
