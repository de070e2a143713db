"""sr33.mesh: the shared primitives against slow, obviously correct references."""

from __future__ import annotations

import itertools

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays
from scipy.spatial import Delaunay, QhullError

from sr33.mesh import (
    delaunay_triangles,
    dot,
    edge_incidence,
    edge_uses,
    half_edges,
    norm,
    orientation_double_cover,
    triangle_ratios,
    unique_edges,
    unique_rows,
)

triangles = st.lists(
    st.lists(st.integers(0, 7), min_size=3, max_size=3, unique=True), min_size=1, max_size=12
)


@given(
    arrays(np.int64, st.tuples(st.integers(0, 30), st.integers(1, 4)), elements=st.integers(0, 9))
)
def test_unique_rows_is_numpys_unique(a):
    got, counts = unique_rows(a, return_counts=True)
    want, wcounts = np.unique(a, axis=0, return_counts=True)
    assert np.array_equal(got, want.reshape(-1, a.shape[1]))
    assert np.array_equal(counts, wcounts)


def test_unique_rows_refuses_other_than_two_dimensions():
    with pytest.raises(ValueError, match=r"rows must be a 2-D array, got shape \(3,\)"):
        unique_rows([1, 2, 3])


@given(triangles)
def test_edge_incidence_matches_counting_by_hand(tris):
    t = np.array(tris)
    uses: dict[tuple[int, int], list[tuple[int, bool]]] = {}
    for f, (a, b, c) in enumerate(tris):
        for p, q in ((a, b), (b, c), (c, a)):
            uses.setdefault((min(p, q), max(p, q)), []).append((f, p < q))
    inc = edge_incidence(*half_edges(t))
    assert [tuple(e) for e in inc.edges.tolist()] == sorted(uses)
    assert inc.counts.tolist() == [len(uses[k]) for k in sorted(uses)]
    e, c = edge_uses(t)
    assert np.array_equal(e, inc.edges) and np.array_equal(c, inc.counts)
    # every half-edge points at its own edge
    pairs, owner = half_edges(t)
    assert np.array_equal(np.sort(pairs, axis=1), inc.edges[inc.edge_of])
    assert np.array_equal(owner, inc.face)
    # the manifold pairs: exactly the edges of two uses, coherent when opposite
    edge, fa, fb, coherent = inc.manifold_pairs()
    want = {k: v for k, v in uses.items() if len(v) == 2}
    got = {tuple(inc.edges[i]): (a, b, ok) for i, a, b, ok in zip(edge, fa, fb, coherent)}
    assert set(got) == set(want)
    for k, (a, b, ok) in got.items():
        (f0, d0), (f1, d1) = want[k]
        assert {a, b} == {f0, f1} and ok == (d0 != d1)
    # shared(): k - 1 consecutive pairs per edge of k uses
    assert inc.shared()[0].size == sum(len(v) - 1 for v in uses.values())


def test_orientation_double_cover_tells_a_moebius_strip_from_an_annulus():
    # a strip of 4 triangles closed with a twist: its last link crosses
    fa, fb = [0, 1, 2, 3], [1, 2, 3, 0]
    twisted = orientation_double_cover(4, fa, fb, [True, True, True, False])
    assert twisted[0] == twisted[4]  # a face and its flip in one component: non-orientable
    plain = orientation_double_cover(4, fa, fb, [True, True, True, True])
    assert plain[0] != plain[4]


@given(arrays(np.float64, (5, 3), elements=st.floats(-10, 10)))
def test_dot_and_norm_are_the_plain_sums_of_products(a):
    b = a[::-1]
    want = np.array([sum(x * y for x, y in zip(r, s)) for r, s in zip(a, b)])
    assert np.array_equal(dot(a, b), want)  # left to right, each product rounded: no FMA
    np.testing.assert_allclose(norm(a), np.sqrt((a * a).sum(axis=1)), rtol=1e-15)


def test_triangle_ratios_of_known_triangles():
    p = np.array([[0, 0], [1, 0], [0, 1], [0.5, np.sqrt(3) / 2], [2, 0], [0, 1.0]])
    r = triangle_ratios(p, [(0, 1, 2), (0, 1, 3), (0, 4, 5)])
    np.testing.assert_allclose(r, [1 / np.sqrt(2), 1.0, 2 / np.sqrt(5)])
    assert r[0] < np.sqrt(3) / 2 < r[1]


def test_flipped_ratios_judge_a_near_cocircular_cell_with_its_other_diagonal():
    from scipy.spatial import Delaunay

    from sr33.mesh import flipped_ratios

    # four corners near one circle (one of them 0.5 % outside it)
    t = np.deg2rad([0.0, 100.0, 180.0, 250.0])
    p = np.c_[np.cos(t), np.sin(t)] * np.array([1.0, 1.0, 1.0, 1.005])[:, None]
    tri = Delaunay(p).simplices
    shared = np.intersect1d(tri[0], tri[1])
    other = np.setdiff1d(np.arange(4), shared)
    # the other diagonal's two triangles, by brute force
    want = triangle_ratios(p, [(shared[0], *other), (shared[1], *other)])
    np.testing.assert_allclose(np.sort(flipped_ratios(p, tri, 0.05)), np.sort(want))
    assert np.abs(np.sort(want) - np.sort(triangle_ratios(p, tri))).max() > 0.1  # it matters
    assert flipped_ratios(p, tri, 1e-6).size == 0  # beyond the slack: not near cocircular
    # a square lattice: every cell is cocircular, the flip is the mirror image
    g = np.stack(np.meshgrid(np.arange(4.0), np.arange(4.0)), -1).reshape(-1, 2)
    flipped = flipped_ratios(g, Delaunay(g).simplices, 1e-9)
    assert flipped.size == 2 * 9  # nine cells, each with its other diagonal
    np.testing.assert_allclose(flipped, 1 / np.sqrt(2))


def test_near_cocircular_names_each_cell_by_its_diagonal_and_opposite_corners():
    from scipy.spatial import Delaunay

    from sr33.mesh import near_cocircular

    # a 3 x 2 grid of unit squares beside a far point: the two squares are
    # cocircular cells, the triangles to the far point are not
    g = np.array([[0, 0], [1, 0], [2, 0], [0, 1], [1, 1], [2, 1], [1, 5.0]])
    tri = Delaunay(g).simplices
    cells = near_cocircular(g, tri, 1e-9)
    assert cells.shape == (2, 4)
    for a, b, c, d in cells.tolist():
        assert a < b
        # a b is a square's diagonal, c and d its other corners
        assert {a, b, c, d} in ({0, 1, 3, 4}, {1, 2, 4, 5})
        assert np.isclose(np.linalg.norm(g[a] - g[b]), np.sqrt(2))
        assert np.isclose(np.linalg.norm(g[c] - g[d]), np.sqrt(2))
        # both triangles are among the triangulation's
        have = {frozenset(t) for t in tri.tolist()}
        assert {frozenset((a, b, c)), frozenset((a, b, d))} <= have
    # their shared corner raised by 0.02: both cells about 0.04 rad off one
    # circle, near within a slack of 0.05, not within 0.01
    g2 = g.copy()
    g2[4] = [1.0, 1.02]
    tri2 = Delaunay(g2).simplices
    assert len(near_cocircular(g2, tri2, 0.05)) == 2
    assert len(near_cocircular(g2, tri2, 0.01)) == 0


@given(arrays(np.float64, (4, 3), elements=st.floats(-3, 3)))
def test_closest_point_beats_a_dense_sampling_of_the_triangle(q):
    from sr33.mesh import closest_points_on_triangles

    p, tri = q[0], q[1:]
    if np.linalg.norm(np.cross(tri[1] - tri[0], tri[2] - tri[0])) < 1e-3:
        return  # (nearly) degenerate: nothing to compare with
    d2, w = closest_points_on_triangles(p[None], tri[None])
    assert np.all(w >= -1e-9) and abs(w.sum() - 1) < 1e-9
    np.testing.assert_allclose(((w @ tri - p) ** 2).sum(), d2[0], rtol=1e-9, atol=1e-12)
    s = np.linspace(0, 1, 41)
    grid = np.array([(a, b) for a, b in itertools.product(s, s) if a + b <= 1])
    pts = tri[0] + grid[:, :1] * (tri[1] - tri[0]) + grid[:, 1:] * (tri[2] - tri[0])
    assert d2[0] <= ((pts - p) ** 2).sum(axis=1).min() + 1e-12


def test_unique_edges_sorts_each_pair():
    assert unique_edges([[3, 1], [1, 3], [0, 2]]).tolist() == [[0, 2], [1, 3]]


# --- delaunay_triangles: ties broken by the indices, not the last bits --------


def _lattices():
    """A rectangular lattice (rows 0.8 apart) and rings of a disk (isosceles
    trapezoids between them): every cell's corners on one circle."""
    x, y = np.meshgrid(np.arange(12.0), 0.8 * np.arange(9.0))
    rect = np.column_stack([x.ravel(), y.ravel()])
    ang = 2 * np.pi * np.arange(24) / 24
    rings = np.vstack([np.column_stack([r * np.cos(ang), r * np.sin(ang)]) for r in (1, 2, 3)])
    return [rect, np.vstack([rings, [[0.0, 0.0]]])]


@pytest.mark.parametrize("which", [0, 1], ids=["rectangles", "rings"])
@given(
    factor=st.floats(-1e-11, 1e-11),
    shift=st.floats(-1e3, 1e3),
    seed=st.integers(0, 2**16),
)
def test_delaunay_triangles_split_ties_the_same_under_rounding_changes(which, factor, shift, seed):
    p = _lattices()[which]
    want = delaunay_triangles(p, 1.0)
    noise = np.random.default_rng(seed).uniform(-1e-13, 1e-13, p.shape) * max(1.0, abs(shift))
    moved = (p * (1.0 + factor) + shift + noise) - shift
    assert np.array_equal(delaunay_triangles(moved, 1.0), want)


@given(seed=st.integers(0, 2**16), n=st.integers(3, 200))
def test_delaunay_triangles_are_scipys_on_points_in_general_position(seed, n):
    p = np.random.default_rng(seed).random((n, 2)) * 10.0
    try:
        theirs = Delaunay(p).simplices
    except QhullError:
        return
    mine = delaunay_triangles(p)
    assert {tuple(sorted(t)) for t in theirs.tolist()} == {tuple(sorted(t)) for t in mine.tolist()}


@pytest.mark.parametrize("which", [0, 1], ids=["rectangles", "rings"])
def test_delaunay_triangles_are_delaunay_ccw_and_canonical_on_ties(which):
    p = _lattices()[which]
    tri = delaunay_triangles(p, 1.0)
    a, b, c = p[tri[:, 0]], p[tri[:, 1]], p[tri[:, 2]]
    turn = (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0])
    assert (turn > 0).all()
    assert (tri[:, 0] < tri[:, 1:].min(axis=1)).all()
    assert np.array_equal(tri, tri[np.lexsort((tri[:, 2], tri[:, 1], tri[:, 0]))])
    # a triangulation of the hull: Euler's count, and every triangle's circle empty
    assert tri.shape[0] == Delaunay(p).simplices.shape[0]
    d = a - c
    e = b - c
    den = 2 * (d[:, 0] * e[:, 1] - d[:, 1] * e[:, 0])
    ux = (e[:, 1] * (d * d).sum(1) - d[:, 1] * (e * e).sum(1)) / den
    uy = (d[:, 0] * (e * e).sum(1) - e[:, 0] * (d * d).sum(1)) / den
    centre = c + np.column_stack([ux, uy])
    r2 = ux * ux + uy * uy
    dist2 = ((p[None] - centre[:, None]) ** 2).sum(-1)
    assert (dist2 >= r2[:, None] - 1e-9).all()


def test_edge_incidence_orders_sides_as_a_stable_sort_of_their_keys():
    """The linear-time grouping (sr33._edges) gives what a stable argsort of
    the keys min * n + max gives: the edges, their uses in order, each
    side's edge; repeated sides and loops (a == b) included."""
    from sr33.mesh import edge_incidence

    rng = np.random.default_rng(7)
    for trial in range(100):
        n = int(rng.integers(1, 40))
        p = rng.integers(0, n, (int(rng.integers(0, 200)), 2))
        inc = edge_incidence(p, np.arange(p.shape[0]), n)
        key = p.min(axis=1) * n + p.max(axis=1)
        order = np.argsort(key, kind="stable")
        uniq, first, counts = np.unique(key[order], return_index=True, return_counts=True)
        assert np.array_equal(inc.order, order), trial
        assert np.array_equal(inc.start, first) and np.array_equal(inc.counts, counts)
        assert np.array_equal(inc.edges, np.stack([uniq // n, uniq % n], axis=1).reshape(-1, 2))
        assert np.array_equal(key, uniq[inc.edge_of])
    import pytest

    with pytest.raises(ValueError, match=r"vertex indices must lie in \[0, 3\)"):
        edge_incidence([[0, 3]], [0], 3)
