"""Triangulate: disjoint interiors, forbidden diagonals, coherent orientation."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from sr33 import InputError, backtracking, localized_rng, triangulate, trivial_isometric_cycles
from sr33.cycles import CycleSet
from sr33.samplers import cube_lattice
from sr33.validators import edge_uses


def area(pts, tri):
    p = pts[tri]
    return 0.5 * np.linalg.norm(np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), axis=1).sum()


def test_square_gives_two_triangles_covering_it():
    sq = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], float)
    t = triangulate(sq, CycleSet(np.array([0, 4]), np.array([0, 1, 2, 3]))).triangles
    assert t.shape == (2, 3)
    assert area(sq, t) == pytest.approx(1.0)


def test_convex_pentagon_area_is_preserved():
    ang = np.linspace(0, 2 * np.pi, 6)[:-1]
    pent = np.stack([np.cos(ang), np.sin(ang), np.zeros(5)], 1)
    t = triangulate(pent, CycleSet(np.array([0, 5]), np.arange(5))).triangles
    assert t.shape == (3, 3)
    assert area(pent, t) == pytest.approx(2.5 * np.sin(2 * np.pi / 5))
    # triangles only use the polygon's vertices, no edge used 3 times
    _, counts = edge_uses(t)
    assert counts.max() <= 2


def test_diagonal_that_is_another_faces_edge_is_avoided():
    # quad 0-1-2-3 and a triangle 0-2-4 that already uses the diagonal 0-2
    pts = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [1, -1, 1]], float)
    faces = CycleSet(np.array([0, 4, 7]), np.array([0, 1, 2, 3, 0, 2, 4]))
    t = triangulate(pts, faces)
    quad_tris = t.triangles[t.face_of_triangle == 0]
    _, counts = edge_uses(t.triangles)
    assert counts.max() <= 2
    assert {tuple(sorted(x)) for x in quad_tris.tolist()} == {(0, 1, 3), (1, 2, 3)}


def test_cube_lattice_is_coherently_oriented_outwards():
    pts = cube_lattice(3)
    e = localized_rng(pts, 12).edges
    sel = backtracking(pts, e, trivial_isometric_cycles(e, len(pts)))
    t = triangulate(pts, sel.faces)
    assert t.orientable
    directed = np.concatenate(
        [t.triangles[:, [0, 1]], t.triangles[:, [1, 2]], t.triangles[:, [2, 0]]]
    )
    # each directed edge exactly once: a coherently oriented closed surface
    assert np.unique(directed, axis=0).shape[0] == directed.shape[0]
    p = pts[t.triangles]
    volume = np.einsum("ij,ij->i", p[:, 0], np.cross(p[:, 1], p[:, 2])).sum() / 6
    assert volume == pytest.approx(27.0)


def test_bad_faces_argument():
    pts = cube_lattice(1)
    with pytest.raises(InputError, match="faces must be a CycleSet, got list"):
        triangulate(pts, [[0, 1, 2]])
    with pytest.raises(InputError, match="faces index points out of range"):
        triangulate(pts, CycleSet(np.array([0, 3]), np.array([0, 1, 99])))


@settings(max_examples=60, deadline=None)
@given(
    L=st.integers(4, 8),
    seed=st.integers(0, 2**32 - 1),
    blocked=st.floats(0.0, 0.7),
)
def test_min_area_kernel_matches_every_triangulation_enumerated(L, seed, blocked):
    """The numba dynamic programme finds the smallest area over all
    triangulations whose chords are allowed (brute force, tests/naive.py),
    and says so when there is none."""
    from sr33._kernels import min_area_splits
    from tests.naive import naive_min_area_triangulation

    rng = np.random.default_rng(seed)
    ang = np.sort(rng.uniform(0, 2 * np.pi, L))
    p = np.stack([np.cos(ang), np.sin(ang), rng.normal(0, 0.4, L)], axis=1)
    allowed = rng.random((L, L)) >= blocked
    split, feasible = min_area_splits(p, allowed, 1e-9)
    want = naive_min_area_triangulation(p, allowed)
    assert feasible == (want is not None)
    if want is None:
        return
    tri, stack = [], [(0, L - 1)]
    while stack:
        i, j = stack.pop()
        if j - i >= 2:
            m = int(split[i, j])
            assert (
                m > i and m < j and (m - i == 1 or allowed[i, m]) and (j - m == 1 or allowed[m, j])
            )
            tri.append((i, m, j))
            stack += [(i, m), (m, j)]
    assert len(tri) == L - 2
    assert area(p, np.array(tri)) == pytest.approx(want, rel=1e-6)
