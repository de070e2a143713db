"""The repair's numba energy: bit for bit the numpy code it replaced (a
sampling is a local search whose end can turn on a last bit), and its
gradient the energy's derivative."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial import Delaunay

from sr33.samplers._repair_kernels import energy_terms, numpy_sum
from sr33.samplers.repair import GAP, SHORT, TARGET
from tests.naive import naive_repair_energy


def problem(seed, n, ghosts, frames, spacing):
    """A jittered lattice of ``spacing`` (h is 0.1; slivers, near-equilateral and
    wide triangles, short edges) with sliding, anchored, fixed, ghost and
    frame points, and its Delaunay triangles."""
    rng = np.random.default_rng(seed)
    side = int(np.ceil(np.sqrt(n + ghosts + frames)))
    g = np.stack(np.meshgrid(np.arange(side), np.arange(side)), -1).reshape(-1, 2)
    pts = (g[: n + ghosts + frames] + rng.uniform(-0.45, 0.45, (n + ghosts + frames, 2))) * spacing
    of = np.r_[np.arange(n), np.full(ghosts, -1), np.full(frames, -2)]
    pick = rng.permutation(pts.shape[0])  # ghosts and frame points anywhere among them
    pts, of = pts[pick], of[pick]
    move = rng.random(n) < 0.6
    hold = ~move & (rng.random(n) < 0.7)
    anchor = hold & (rng.random(n) < 0.3)
    judged = rng.random(n) < 0.8
    return pts, of, Delaunay(pts).simplices.astype(np.int64), move, hold, anchor, judged


@settings(max_examples=60, deadline=None)
@given(
    seed=st.integers(0, 2**32 - 1),
    n=st.integers(3, 400),
    ghosts=st.integers(0, 20),
    frames=st.integers(0, 20),
    reach=st.sampled_from([0.0, 0.1, 0.4]),
    wide=st.sampled_from([1.0, 1.35]),
    spacing=st.sampled_from([0.05, 0.1]),  # 0.05: most edges short, most gaps too small
)
def test_the_energy_is_the_numpy_energy_bit_for_bit(seed, n, ghosts, frames, reach, wide, spacing):
    pts, of, tri, move, hold, anchor, judged = problem(seed, n, ghosts, frames, spacing)
    h = 0.1
    energy, gp, rho, rows = energy_terms(
        pts, of, tri, move, hold, anchor, judged, reach, h, TARGET, SHORT, GAP[0], GAP[1], wide
    )
    e0, gp0, rho0, tri0 = naive_repair_energy(
        pts, of, tri, move, hold, anchor, judged, reach, h, wide, TARGET, SHORT, GAP
    )
    assert np.array_equal(tri[rows], tri0)
    assert rho.tobytes() == rho0.tobytes()
    assert energy == e0  # the same float, not a close one
    assert gp.tobytes() == gp0.tobytes()


@settings(max_examples=60, deadline=None)
@given(
    values=st.lists(
        st.floats(-1e6, 1e6, allow_nan=False, allow_subnormal=False), min_size=0, max_size=2000
    ),
    columns=st.sampled_from([1, 3]),
)
def test_numpy_sum_is_numpys_own(values, columns):
    a = np.asarray(values, dtype=np.float64)
    a = a[: a.size - a.size % columns].reshape(-1, columns)
    assert numpy_sum(a) == float(a.sum())


def test_the_gradient_is_the_energys_derivative_and_the_radius_term_pulls_inwards():
    rng = np.random.default_rng(5)
    g = np.stack(np.meshgrid(np.arange(6.0), np.arange(5.0)), axis=-1).reshape(-1, 2)
    pts = g + rng.uniform(-0.35, 0.35, g.shape)
    tri = Delaunay(pts).simplices.astype(np.int64)
    n = pts.shape[0]
    yes, no = np.ones(n, dtype=bool), np.zeros(n, dtype=bool)

    def energy(p, wide=1e9, hold=no):
        return energy_terms(
            p, np.arange(n), tri, yes, hold, no, yes, 0.0, 1.0, TARGET, SHORT, *GAP, wide
        )

    # without the radius term (wide 1e9) and the gap term (no sliding
    # samples) the gradient is the exact derivative
    e, grad, rho, rows = energy(pts)
    assert e > 0.0 and (rho > TARGET).any() and rows.size == tri.shape[0]
    eps = 1e-7
    numeric = np.zeros_like(grad)
    for i in range(n):
        for j in range(2):
            up, down = pts.copy(), pts.copy()
            up[i, j] += eps
            down[i, j] -= eps
            numeric[i, j] = (energy(up)[0] - energy(down)[0]) / (2 * eps)
    np.testing.assert_allclose(grad, numeric, atol=1e-5)
    # the gap term: two sliding samples 0.5 h apart (below GAP[0]) pushed
    # apart with twice the term's derivative (its weight in the descent)
    pair = np.array([[0.0, 0.0], [0.5, 0.0], [0.25, 0.6]])
    three = np.ones(3, dtype=bool)
    hold = np.array([True, True, False])
    args = (np.array([[0, 1, 2]]), three, hold, ~three, three, 0.0, 1.0, TARGET, SHORT, *GAP)
    e_hold, g_hold, _, _ = energy_terms(pair, np.arange(3), *args, 1e9)
    e_free, g_free, _, _ = energy_terms(pair, np.arange(3), args[0], three, ~three, *args[3:], 1e9)
    gap = GAP[0] - 0.5
    assert e_hold - e_free == pytest.approx(5.0 * gap**2 / 2.0)
    np.testing.assert_allclose((g_hold - g_free)[:2], [[10.0 * gap, 0.0], [-10.0 * gap, 0.0]])
    # the radius term: a wide triangle's corners are pulled to its centroid
    wide = np.array([[0.0, 0.0], [4.0, 0.0], [2.0, 0.5]])
    e, g, _, _ = energy_terms(wide, np.arange(3), *args[:1], three, ~three, *args[3:], 1.0)
    assert e > 0.0
    assert ((g * (wide - wide.mean(axis=0))).sum(axis=1) > 0).all()  # descent moves inwards


def _canonical_delaunay(pts):
    from sr33.samplers.repair import canonical_triangles

    d = Delaunay(pts)
    tri, nbr = canonical_triangles(pts, d.simplices, d.neighbors)
    return tri, nbr


@settings(max_examples=40, deadline=None)
@given(
    seed=st.integers(0, 2**32 - 1),
    side=st.integers(3, 14),
    move=st.sampled_from([0.01, 0.05, 0.2]),
    share=st.sampled_from([1.0, 0.15]),
)
def test_flips_from_the_last_triangulation_give_qhulls_triangles(seed, side, move, share):
    """Lawson's flips from the triangles of the points' last positions end at
    the Delaunay triangles Qhull gives for the new ones (the same rows, the
    same neighbours, in canonical order), or give up (None): never another
    triangulation."""
    from sr33.samplers._repair_kernels import (
        canonical_order,
        canonical_reorder,
        delaunay_flips,
        delaunay_flips_since,
    )

    rng = np.random.default_rng(seed)
    g = np.stack(np.meshgrid(np.arange(side), np.arange(side)), -1).reshape(-1, 2).astype(float)
    before = g + rng.uniform(-0.3, 0.3, g.shape)
    inner = ((g > 0) & (g < side - 1)).all(axis=1)  # the hull's points stay
    inner &= rng.random(inner.size) < share  # (a share of them moves)
    after = before.copy()
    after[inner] += rng.uniform(-move, move, (int(inner.sum()), 2))
    tri, nbr = _canonical_delaunay(before)
    out = delaunay_flips(after, tri, nbr, 1e-9, 1e-10)
    if move <= 0.05:  # no triangle can turn over: flips always do it
        assert out is not None
    # only the edges with a moved point tested first: the same flips
    since = delaunay_flips_since(after, before, tri, nbr, 1e-9, 1e-10)
    assert (since is None) == (out is None)
    if out is not None:
        assert since[2] == out[2]
        np.testing.assert_array_equal(since[0], out[0])
        np.testing.assert_array_equal(since[1], out[1])
    if out is not None:
        got_t, got_n = canonical_order(out[0], out[1])
        want_t, want_n = _canonical_delaunay(after)
        np.testing.assert_array_equal(got_t, want_t)
        np.testing.assert_array_equal(got_n, want_n)
        # the descent's merge of the rows the flips left with the others sorted
        re_t, re_n = canonical_reorder(out[0], out[1], tri)
        np.testing.assert_array_equal(re_t, want_t)
        np.testing.assert_array_equal(re_n, want_n)
    np.testing.assert_array_equal(tri, _canonical_delaunay(before)[0])  # input left alone


def test_flips_give_up_on_a_turned_over_triangle_and_keep_a_squares_diagonal():
    from sr33.samplers._repair_kernels import delaunay_flips

    square = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    tri, nbr = _canonical_delaunay(square)
    # cocircular: both diagonals are Delaunay, the one there stays (no flip)
    out = delaunay_flips(square + 1e-13, tri, nbr, 1e-9, 1e-10)
    assert out is not None and out[2] == 0
    np.testing.assert_array_equal(out[0], tri)
    # a corner pulled in past the circle: one flip to the other diagonal
    kite = square.copy()
    diagonal = set(tri[0]) & set(tri[1])
    far = ({0, 1, 2, 3} - diagonal).pop()
    kite[far] += 0.2 * (np.array([0.5, 0.5]) - kite[far])
    out = delaunay_flips(kite, tri, nbr, 1e-9, 1e-10)
    assert out is not None and out[2] == 1
    assert set(out[0][0]) & set(out[0][1]) == {0, 1, 2, 3} - diagonal
    # a corner pushed across the diagonal turns a triangle over: no answer
    crossed = square.copy()
    crossed[far] = (
        1.2 * (np.array([0.5, 0.5]) - crossed[far])
        + crossed[far]
        + (np.array([0.5, 0.5]) - crossed[far])
    )
    assert delaunay_flips(crossed, tri, nbr, 1e-9, 1e-10) is None


def test_a_flat_triangle_on_the_hull_is_dropped_and_the_rest_carried():
    """Qhull's ``Qt`` can leave three collinear points on the hull as a
    triangle of no area: it is dropped (its neighbours see the hull there),
    and the rest passes the flips' check, so that it is carried to the next
    step instead of triangulated anew; a flat triangle inside stays."""
    from sr33.samplers._repair_kernels import delaunay_flips
    from sr33.samplers.repair import _without_flat_hull

    pts = np.array([[0.0, 0.0], [1.0, 0.0], [2.0, 0.0], [1.0, 1.0]])
    tri = np.array([[0, 1, 3], [1, 2, 3], [0, 1, 2]])
    # neighbour k is across from corner k
    nbr = np.array([[1, -1, 2], [-1, 0, 2], [1, -1, 0]])
    kept, knbr = _without_flat_hull(pts, tri, nbr, 1e-9)
    np.testing.assert_array_equal(kept, tri[:2])
    np.testing.assert_array_equal(knbr, [[1, -1, -1], [-1, 0, -1]])
    out = delaunay_flips(pts, kept, knbr, 1e-9, 1e-10)
    assert out is not None and out[2] == 0
    with_flat = delaunay_flips(pts, tri, nbr, 1e-9, 1e-10)
    assert with_flat is None  # what made every step call Qhull
    # a flat triangle inside (not on the hull) is not dropped
    inner = np.array([[1, -1, 2], [-1, 0, 2], [1, 5, 0]])
    np.testing.assert_array_equal(_without_flat_hull(pts, tri, inner, 1e-9)[0], tri)


def test_a_developments_apex_has_no_image():
    """A development's apex, at the origin, has no image across the glued
    sides: it would be a second point there, which Qhull drops, and the
    triangulation could then not be carried to the next step (8,300 of
    conebox turned a's Qhull calls)."""
    from sr33.samplers.repair import _Problem

    uv = np.array([[0.0, 0.0], [0.5, 0.01], [0.5 * np.cos(2.99), 0.5 * np.sin(2.99)]])
    prob = _Problem(uv, [False, True, True], [False] * 3, None, None, 1.0, turn=3.0)
    _, of, _ = prob.images(np.arange(3))
    assert sorted(of.tolist()) == [1, 2]


@settings(max_examples=60, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), n=st.integers(0, 60), m=st.integers(1, 8))
def test_the_straight_edges_kernels_are_the_numpy_code_bit_for_bit(seed, n, m):
    """The clamp and the projection of a planar face's straight edges (called
    at every descent step) give the numpy code's bits: a sampling must not
    move when they get faster."""
    from sr33.samplers import _line_kernels as lk
    from tests.naive import naive_line_clamp, naive_line_project

    rng = np.random.default_rng(seed)
    a = rng.uniform(-1, 1, (m, 2))
    d = rng.uniform(-1, 1, (m, 2))
    normals = np.stack([-d[:, 1], d[:, 0]], axis=1) / np.linalg.norm(d, axis=1)[:, None]
    p = rng.uniform(-1.5, 1.5, (n, 2))
    p[: n // 3] = a[rng.integers(0, m, n // 3)] + rng.random((n // 3, 1)) * d[:1]  # on edges
    dd = (d * d).sum(axis=-1)
    got = lk.clamp(p, a, d, dd, normals, 0.04, -0.2)
    assert got.tobytes() == naive_line_clamp(p, a, d, normals, 0.04, -0.2).tobytes()
    lo = rng.uniform(0.0, 0.2, m)
    assert lk.project(p, a, d, dd, lo).tobytes() == naive_line_project(p, a, d, lo).tobytes()
    t = ((p[:, None, :] - a[None]) * d[None]).sum(axis=-1) / dd[None]
    assert lk.along(p, a, d, dd).tobytes() == t.tobytes()


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), n=st.integers(1, 300), m=st.integers(0, 500))
def test_centroids_and_the_rasters_lookup_are_numpys_bit_for_bit(seed, n, m):
    """The repair asks at every step which triangles' centroids lie in the
    face: the kernels give numpy's centroids and the raster's cells exactly
    (points outside the grid, NaN and infinities among them, are outside)."""
    from sr33.samplers._repair_kernels import centroids, grid_lookup

    rng = np.random.default_rng(seed)
    pts = rng.uniform(-3.0, 3.0, (n, 2))
    tri = rng.integers(0, n, (m, 3))
    assert centroids(pts, tri).tobytes() == pts[tri].mean(axis=1).tobytes()
    grid = rng.random((37, 23)) < 0.5
    lo, cell = np.array([-2.0, -2.5]), 0.13
    q = np.vstack([pts, [[np.nan, 0.0], [np.inf, 1.0], [0.0, -np.inf], [1e300, 0.0]]])
    ij = np.floor((q - lo) / cell)
    ok = np.isfinite(ij).all(axis=1) & (ij[:, 0] >= 0) & (ij[:, 0] < 23) & (ij[:, 1] >= 0)
    ok &= ij[:, 1] < 37
    want = np.zeros(len(q), dtype=bool)
    want[ok] = grid[ij[ok, 1].astype(int), ij[ok, 0].astype(int)]
    np.testing.assert_array_equal(grid_lookup(q, lo, cell, grid), want)


@settings(max_examples=60, deadline=None)
@given(
    seed=st.integers(0, 2**32 - 1),
    n=st.integers(0, 60),
    lines=st.integers(0, 4),
    arcs=st.integers(1, 4),
)
def test_the_arcs_kernels_are_the_numpy_code_bit_for_bit(seed, n, lines, arcs):
    """The projection onto a planar face's arcs and straight edges, the
    arcs' clamp and their ghosts (called at every descent step) give the
    numpy code's bits, open and closed arcs, points on them and off."""
    from sr33.samplers import _line_kernels as lk
    from tests.naive import (
        naive_arc_clamp,
        naive_arc_ghosts,
        naive_curves_project,
    )

    rng = np.random.default_rng(seed)
    h = 0.05
    arc = [
        (
            rng.uniform(-0.5, 0.5, 2),
            float(rng.uniform(0.1, 0.6)),
            float(rng.uniform(-np.pi, np.pi)),
            float(rng.uniform(0.3, 2 * np.pi)),
            bool(rng.random() < 0.4),
        )
        for _ in range(arcs)
    ]
    line = [
        ("line", rng.uniform(-1, 1, 2), rng.uniform(-1, 1, 2), float(rng.uniform(0, 0.2)))
        for _ in range(lines)
    ]
    curves = [("arc", *a) for a in arc] + line
    order = rng.permutation(len(curves))
    curves = [curves[k] for k in order]
    p = rng.uniform(-1.2, 1.2, (n, 2))
    # a third of them on an arc (within rounding: the ghosts' test)
    k = rng.integers(0, arcs, n // 3)
    t = rng.uniform(0, 2 * np.pi, n // 3)
    radius = np.array([a[1] for a in arc])
    p[: n // 3] = np.array([a[0] for a in arc])[k] + radius[k, None] * np.stack(
        [np.cos(t), np.sin(t)], 1
    )
    m = len(curves)
    kind = np.array([0 if c[0] == "line" else 1 for c in curves], dtype=np.int64)
    a, d, dd, lo = np.zeros((m, 2)), np.zeros((m, 2)), np.ones(m), np.zeros(m)
    centre, rad, start, span = np.zeros((m, 2)), np.zeros(m), np.zeros(m), np.zeros(m)
    closed = np.zeros(m, dtype=bool)
    for q, c in enumerate(curves):
        if c[0] == "line":
            a[q], d[q], lo[q] = c[1], c[2], c[3]
            dd[q] = (c[2] * c[2]).sum()
        else:
            centre[q], rad[q], start[q], span[q], closed[q] = c[1:]
    margin = 0.3 * h
    got = lk.project_curves(p, kind, a, d, dd, lo, centre, rad, start, span, closed, margin)
    assert got.tobytes() == naive_curves_project(p, curves, margin).tobytes()
    sides = rng.choice([-1.0, 1.0], arcs)
    margins = rng.choice([0.25 * h, 0.5 * h], arcs)
    arrays = [np.array(x) for x in zip(*arc)]
    got = lk.clamp_arcs(p, *arrays, sides, margins)
    assert got.tobytes() == naive_arc_clamp(p, arc, sides, margins).tobytes()
    got = lk.ghosts_arcs(p, arrays[0], arrays[1], sides, h)
    want = naive_arc_ghosts(p, [(c, r) for c, r, *_ in arc], sides, h)
    assert got.shape == want.shape and got.tobytes() == want.tobytes()


def neighbours_of(tri: np.ndarray) -> np.ndarray:
    """The triangle across the edge opposite each corner (-1 on the hull)."""
    where = {}
    for t, (a, b, c) in enumerate(tri.tolist()):
        for k, e in enumerate(((b, c), (c, a), (a, b))):
            where.setdefault(frozenset(e), []).append((t, k))
    nbr = np.full(tri.shape, -1)
    for uses in where.values():
        if len(uses) == 2:
            (t, k), (u, j) = uses
            nbr[t, k], nbr[u, j] = u, t
    return nbr


def test_a_chain_of_flat_hull_triangles_is_peeled_whole():
    """A row of collinear samples on the hull (a local window cut off along
    a lattice's diagonal), triangulated as Qhull's ``Qt`` may: a chain of
    flat triangles, the second on the hull only once the first goes.  All
    of them go, every sample stays a corner, and the triangulation can then
    be carried to the next step by edge flips (on block_two_holes the
    chain's second triangle sent 5,776 of 7,928 steps to Qhull)."""
    from sr33.samplers._repair_kernels import delaunay_flips
    from sr33.samplers.repair import _doubled_areas, _without_flat_hull

    # the row P0..P3 on the line y = x, the face below it
    pts = np.array([[0, 0], [1, 1], [2, 2], [3, 3], [1, 0], [2, 1], [3, 2], [3, 0]], dtype=float)
    real = [[0, 4, 1], [1, 4, 5], [1, 5, 2], [2, 5, 6], [2, 6, 3], [4, 7, 5], [5, 7, 6]]
    chain = [[0, 1, 3], [1, 2, 3]]  # flat: the first has the hull edge P0-P3
    tri = np.array(real + chain)
    tri, nbr = _without_flat_hull(pts, tri, neighbours_of(tri), 1e-9)
    assert sorted(map(tuple, tri.tolist())) == sorted(map(tuple, real))
    assert (np.abs(_doubled_areas(pts, tri)) > 1e-9).all()
    np.testing.assert_array_equal(nbr, neighbours_of(tri))  # renumbered
    assert delaunay_flips(pts, tri, nbr, 1e-9, 1e-10) is not None


def _nearest_by_all(q, c):
    """The nearest point of ``c`` to each of ``q`` as a scan of all finds it
    (the first of equally near ones), and its squared distance."""
    d = ((q[:, None, :] - c[None, :, :]) ** 2).sum(axis=2)
    j = np.argmin(d, axis=1)  # the first of the smallest
    return j, d[np.arange(q.shape[0]), j]


@settings(max_examples=30, deadline=None)
@given(
    seed=st.integers(0, 2**31 - 1),
    n=st.integers(1, 400),
    lattice=st.booleans(),
    far=st.floats(0.0, 50.0),
)
def test_the_rim_buckets_find_the_point_a_scan_of_all_finds(seed, n, lattice, far):
    """``_descent_kernels._nearest`` (the rim clamp's lookup in
    ``chart.Buckets``) returns the index and squared distance a scan of
    every rim point returns, ties to the first: on a wavy rim in order along
    it, on a lattice of rim points (equally near ones, repeated points),
    for queries on the grid, off it by up to ``far`` and not finite."""
    from sr33.samplers._descent_kernels import _nearest
    from sr33.samplers.chart import Buckets

    rng = np.random.default_rng(seed)
    t = np.sort(rng.uniform(0.0, 2 * np.pi, n))
    c = np.stack([np.cos(t), 0.6 * np.sin(t) + 0.1 * np.sin(7 * t)], axis=1)
    if lattice:  # the rim's points on a lattice of 1/8: repeated points
        c = np.round(c * 8.0) / 8.0
    b = Buckets.of(c)
    assert b.start[-1] == n and sorted(b.members.tolist()) == list(range(n))
    lo, hi = c.min(axis=0), c.max(axis=0)
    q = rng.uniform(lo - 0.2 - far, hi + 0.2 + far, (200, 2))
    if lattice:  # on a lattice of 1/16: several rim points equally near
        q[:100] = rng.integers(-20, 20, (100, 2)) / 16.0
    want_j, want_d = _nearest_by_all(q, c)
    got = [_nearest(x, y, c, b.lo, b.cell, b.dims, b.start, b.members) for x, y in q]
    assert [j for j, _ in got] == want_j.tolist()
    assert [d for _, d in got] == want_d.tolist()  # the same floats, bit for bit
    for x, y in ((np.nan, 0.0), (0.0, np.inf)):
        assert _nearest(x, y, c, b.lo, b.cell, b.dims, b.start, b.members)[0] == -1


def _star(points: int, inner: float, turn: float) -> np.ndarray:
    """A star polygon's corners (counter-clockwise): ``points`` tips at
    radius 1, notches at ``inner`` (reflex corners when small), turned."""
    a = turn + np.pi * np.arange(2 * points) / points
    r = np.where(np.arange(2 * points) % 2 == 0, 1.0, inner)
    return np.stack([r * np.cos(a), r * np.sin(a)], axis=1)


def _edge_points(corners: np.ndarray, h: float, rng) -> tuple:
    """The polygon's edges (a, d, dd, unit normals into it) and points on
    them: the corners and jittered points about h apart."""
    a = corners
    d = np.roll(corners, -1, axis=0) - a
    dd = (d * d).sum(axis=1)
    inward = np.stack([-d[:, 1], d[:, 0]], axis=1) / np.sqrt(dd)[:, None]
    on = [a]
    for k in range(a.shape[0]):
        m = max(int(np.sqrt(dd[k]) / h), 1)
        t = (np.arange(1, m) + rng.uniform(-0.3, 0.3, m - 1)) / m
        on.append(a[k] + t[:, None] * d[k])
    return a, d, dd, inward, np.vstack(on)


@settings(max_examples=40, deadline=None)
@given(
    seed=st.integers(0, 2**31 - 1),
    points=st.integers(3, 8),
    inner=st.floats(0.3, 0.9),
    turn=st.floats(0.0, 2 * np.pi),
    h=st.floats(0.04, 0.12),
)
def test_ghosts_beside_a_reflex_corner_keep_to_their_own_edge(seed, points, inner, turn, h):
    """``_line_kernels.ghosts`` with ``OWN_GHOSTS``: the points on a face's
    edges moved h and 2h outwards, less those another edge is nearer to
    (beside a reflex corner the faces across its two edges unfold onto one
    another).  Every ghost kept lies h or 2h from the nearest edge; they
    are the plain ghosts in the same order with some left out, none on a
    convex polygon (where the two agree bit for bit), some on a star whose
    notches are reflex corners."""
    from sr33.samplers._line_kernels import GHOSTS, OWN_GHOSTS, distance, ghosts

    rng = np.random.default_rng(seed)
    convex = inner >= np.cos(np.pi / points)  # the notches' corners are not reflex
    a, d, dd, inward, on = _edge_points(_star(points, inner, turn), h, rng)
    none = np.empty((0, 2))
    m = a.shape[0]
    plain = ghosts(on, a, d, dd, inward, h, none, np.full(m, GHOSTS, dtype=np.int64))
    kept = ghosts(on, a, d, dd, inward, h, none, np.full(m, OWN_GHOSTS, dtype=np.int64))
    nearest = distance(kept, a, d, dd).min(axis=1) / h
    assert np.all(np.isclose(nearest, 1.0, atol=1e-6) | np.isclose(nearest, 2.0, atol=1e-6))
    # a subsequence of the plain ghosts
    j = 0
    for g in kept:
        while j < plain.shape[0] and not np.array_equal(plain[j], g):
            j += 1
        assert j < plain.shape[0]
        j += 1
    if convex:
        assert np.array_equal(kept, plain)
    elif inner < 0.8 * np.cos(np.pi / points):  # clearly reflex: ghosts overlap there
        assert kept.shape[0] < plain.shape[0]
        assert distance(plain, a, d, dd).min(axis=1).min() < 0.99 * h
