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


def test_one_far_outlier_costs_memory_by_the_pairs_not_the_extent():
    """A triangle reaching an outlier at 1e4 or 1e8 (a real scan's stray
    return): the candidate pairs come from a k-d tree, so memory follows the
    number of pairs (a uniform grid over the bounding box asked for 41.8 GiB
    at 1e4 and 19.7 PiB at 1e8); the long triangle's crossings are found."""
    import tracemalloc

    pts = cube_lattice(12)
    rec = reconstruct(pts, 12)
    base = self_intersections(rec.vertices, rec.triangles)
    assert base.shape == (0, 2)
    centre = rec.vertices.mean(axis=0)
    a = int(np.argmin(np.linalg.norm(rec.vertices - centre - [0, 0, 6], axis=1)))  # top
    b = int(np.argmin(np.linalg.norm(rec.vertices - centre + [0, 0, 6], axis=1)))  # bottom
    for far in (1e4, 1e8):
        v = np.vstack([rec.vertices, [[far, centre[1], centre[2] + 0.3]]])
        t = np.vstack([rec.triangles, [[a, b, v.shape[0] - 1]]])  # through the cube
        tracemalloc.start()
        hits = self_intersections(v, t)
        peak = tracemalloc.get_traced_memory()[1]
        tracemalloc.stop()
        assert peak < 200e6
        assert hits.shape[0] > 0 and np.all(hits[:, 1] == t.shape[0] - 1)
