"""validators.intersections: crossing, touching, folded and clean meshes."""

import os

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from sr33 import reconstruct
from sr33.mesh import crossing_eps, first_crossing
from sr33.samplers import cube_lattice
from sr33.validators.intersections import self_intersections
from tests.meshes import icosphere
from tests.naive import naive_self_intersections

DEEP = os.environ.get("HYPOTHESIS_PROFILE") == "deep"


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


@st.composite
def triangle_soups(draw):
    """Triangles on a few lattice points (coplanar sets, shared edges and
    vertices, folds are common), some points jittered off the lattice."""
    n = draw(st.integers(4, 12))
    v = np.array(draw(st.lists(st.tuples(*[st.integers(-2, 2)] * 3), min_size=n, max_size=n)))
    v = v.astype(float)
    if draw(st.booleans()):
        seed = draw(st.integers(0, 2**16))
        v += np.random.default_rng(seed).normal(0, 0.3, v.shape) * (np.arange(n) % 2)[:, None]
    tris = draw(
        st.lists(
            st.lists(st.integers(0, n - 1), min_size=3, max_size=3, unique=True),
            min_size=2,
            max_size=14,
        )
    )
    return v, np.array(tris, dtype=np.int64)


@settings(max_examples=300 if DEEP else 60, deadline=None)
@given(soup=triangle_soups(), new=st.integers(1, 4))
def test_the_kernel_finds_the_pairs_numpy_finds(soup, new):
    """self_intersections (numba kernel, k-d tree candidates) against the
    vectorized numpy reference over every pair; first_crossing against the
    first reference pair that involves one of the first ``new`` rows."""
    v, t = soup
    want = naive_self_intersections(v, t)
    assert self_intersections(v, t).tolist() == want.tolist()
    firsts = [tuple(r) for r in want.tolist() if r[0] < new]
    assert first_crossing(v, t, new, crossing_eps(v)) == (firsts[0] if firsts else None)


@st.composite
def boxes(draw):
    """Boxes round lattice centres: equal, nested, touching (closed boxes
    share a face), zero-size, and a few far larger than the rest."""
    n = draw(st.integers(2, 60))
    seed = draw(st.integers(0, 2**16))
    rng = np.random.default_rng(seed)
    c = rng.integers(-4, 5, (n, 3)).astype(float) * draw(st.sampled_from([1.0, 1e-9, 1e9]))
    scale = np.abs(c).max() or 1.0
    r = rng.integers(0, 3, (n, 3)) * 0.5 * scale / 4
    big = rng.random(n) < draw(st.sampled_from([0.0, 0.05, 0.3]))
    r[big] *= 40
    return c - r, c + r


@settings(max_examples=300 if DEEP else 60, deadline=None)
@given(b=boxes())
def test_box_pairs_are_every_overlapping_pair(b):
    from sr33._intersect import box_pairs

    lo, hi = b
    i, j = np.triu_indices(lo.shape[0], 1)
    ok = np.all((lo[i] <= hi[j]) & (lo[j] <= hi[i]), axis=1)
    assert box_pairs(lo, hi).tolist() == np.stack([i[ok], j[ok]], 1).tolist()
