"""validators.refine: conforming refinement and exact insertion of samples."""

import numpy as np
import pytest

from sr33.validators import mesh_stats
from sr33.validators.refine import insert_points, refine_to_edge_length
from sr33.validators.topology import edge_uses


def octahedron():
    v = np.array([[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]], float)
    f = np.array(
        [[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4], [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]]
    )
    return v, f


def area(v, f):
    return 0.5 * np.linalg.norm(np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]]), axis=1)


def edge_lengths(v, f):
    return np.linalg.norm(v[f] - v[np.roll(f, 1, axis=1)], axis=2)


@pytest.mark.parametrize("bound", [0.9, 0.3, 0.05])
def test_refinement_bounds_edges_and_keeps_surface_and_topology(bound):
    v, f = octahedron()
    rv, rf = refine_to_edge_length(v, f, bound)
    assert edge_lengths(rv, rf).max() <= bound
    assert area(rv, rf).sum() == pytest.approx(area(v, f).sum(), rel=1e-12)
    s = mesh_stats(rf, rv.shape[0])
    assert (s.open_edges, s.overloaded_edges, s.euler, s.components) == (0, 0, 2, 1)
    # orientation kept: every edge used once in each direction
    assert edge_uses(rf)[1].max() == 2
    d = np.concatenate([rf[:, [0, 1]], rf[:, [1, 2]], rf[:, [2, 0]]])
    assert np.unique(d, axis=0).shape[0] == d.shape[0]
    # no sliver: smallest angle bounded (longest-edge bisection)
    a = rv[rf]
    for i in range(3):
        u, w = a[:, (i + 1) % 3] - a[:, i], a[:, (i + 2) % 3] - a[:, i]
        cos = (u * w).sum(1) / np.linalg.norm(u, axis=1) / np.linalg.norm(w, axis=1)
        assert np.degrees(np.arccos(np.clip(cos, -1, 1))).min() > 10


def test_insertion_makes_each_sample_a_vertex():
    v, f = octahedron()
    rv, rf = refine_to_edge_length(v, f, 0.1)
    rng = np.random.default_rng(0)
    x = rng.normal(size=(40, 3))
    x /= np.abs(x).sum(axis=1, keepdims=True)  # on the octahedron (|x|+|y|+|z| = 1)
    on_edge = np.array([[0.31, 0.69, 0.0], [0.0, -0.23, 0.77]])  # on two of its edges
    corner = np.array([[0.0, 0.0, 1.0]])
    pts = np.vstack([x, on_edge, corner])
    nv, nf, idx = insert_points(rv, rf, pts)
    np.testing.assert_array_equal(nv[idx], pts)
    assert np.unique(idx).shape[0] == pts.shape[0]
    assert area(nv, nf).sum() == pytest.approx(area(v, f).sum(), rel=1e-9)
    assert area(nv, nf).min() > 0
    s = mesh_stats(nf, nv.shape[0])
    assert (s.open_edges, s.overloaded_edges, s.euler) == (0, 0, 2)
    # the corner sample is the octahedron's own vertex, the edge samples split edges
    assert idx[-1] == 4
    assert nv.shape[0] == rv.shape[0] + pts.shape[0] - 1


def test_a_sample_splits_its_own_triangle_where_another_faces_vertices_are_nearer():
    """A sample on a coarse face next to a finely meshed one, whose vertices
    are all nearer than the coarse face's corners (a ball's dish meeting a
    cylinder's wall at a sharp rim): it splits the triangle it lies in.
    With only the triangles round its 4 nearest vertices searched, it split
    one of the wall's 0.05 away, folding the mesh into a cone point that
    geodesics bent round (1.93 h between samples 0.78 h apart)."""
    floor = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], float)
    ys, zs = np.linspace(0.4, 0.6, 11), np.linspace(0.0, 0.1, 6)
    wall = np.array([[0.0, y, z] for z in zs for y in ys])
    v = np.vstack([floor, wall])
    f = [[0, 1, 2], [0, 2, 3]]
    for j in range(zs.size - 1):
        for i in range(ys.size - 1):
            a = 4 + j * ys.size + i
            f += [[a, a + 1, a + ys.size + 1], [a, a + ys.size + 1, a + ys.size]]
    sample = np.array([[0.05, 0.5, 0.0]])
    assert np.linalg.norm(v - sample, axis=1).argsort()[:4].min() >= 4  # the wall's nearest
    nv, nf, idx = insert_points(v, np.array(f), sample)
    around = nf[(nf == idx[0]).any(axis=1)]
    assert around.shape[0] == 3
    np.testing.assert_array_equal(nv[around][..., 2], 0.0)  # the floor's own triangle
    assert area(nv, around).sum() == pytest.approx(0.5)


def test_two_samples_on_one_vertex_is_an_error():
    """Near-duplicate samples (a sampler's defect) cannot both become a
    vertex: the error names them and how far apart they are."""
    v, f = octahedron()
    with pytest.raises(
        ValueError, match=r"^samples 0 and 1 fall on one vertex .*\(1.41e-09 apart\)"
    ):
        insert_points(v, f, [[0.0, 0.0, 1.0], [0.0, 1e-9, 1.0 - 1e-9]])


def test_a_local_limit_refines_only_where_it_is_shorter():
    """``local`` (any callable of the edges' midpoints) sets a shorter limit
    where it is below ``max_edge``: finer there, as before elsewhere, still
    one conforming surface of the same area."""
    v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], float)
    rv, rt = refine_to_edge_length(
        v, [[0, 1, 2]], 0.5, local=lambda m: np.where(m[:, 0] < 0.3, 0.1, 0.5)
    )
    a, b = rv[rt], np.roll(rv[rt], 1, axis=1)
    length, mid = np.linalg.norm(a - b, axis=2), 0.5 * (a + b)
    assert length.max() <= 0.5
    assert length[mid[..., 0] < 0.3].max() <= 0.1
    assert length[mid[..., 0] > 0.6].min() > 0.1  # not refined where the limit is 0.5
    plain, _ = refine_to_edge_length(v, [[0, 1, 2]], 0.5)
    assert rv.shape[0] > plain.shape[0]
    s = mesh_stats(rt, rv.shape[0])
    assert (s.overloaded_edges, s.euler, s.components) == (0, 1, 1)  # one disk
    area = np.linalg.norm(
        np.cross(rv[rt[:, 1]] - rv[rt[:, 0]], rv[rt[:, 2]] - rv[rt[:, 0]]), axis=1
    )
    assert area.sum() / 2 == pytest.approx(0.5, abs=1e-12)


@pytest.mark.parametrize("budget", [10_000, 12_000, 60_000])
def test_a_resolution_beyond_the_triangle_budget_is_refused(budget):
    """A unit right triangle (area 1/2) refined to edges of 0.01 needs at
    least 0.5 / (sqrt(3)/4 * 0.01**2) = 11,547 triangles: refused at once
    below that budget, refused during the splitting when the bound is met
    but the result is larger, and refined within a budget it fits."""
    v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], float)
    size = refine_to_edge_length(v, [[0, 1, 2]], 0.01, max_triangles=10**8)[1].shape[0]
    assert 11_547 < size < 60_000
    if budget < size:
        with pytest.raises(ValueError, match=r"edges of 0\.01 needs more than \d+ triangles"):
            refine_to_edge_length(v, [[0, 1, 2]], 0.01, max_triangles=budget)
    else:
        rv, rt = refine_to_edge_length(v, [[0, 1, 2]], 0.01, max_triangles=budget)
        assert rt.shape[0] == size
