"""LocalizedRNG (Algorithm 2): hand-made answers and the O(n^3) definition."""

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from sr33 import DEFAULT, InputError, k_neighbourhoods, localized_rng
from sr33.samplers import cube_lattice, grid_lattice
from tests.helpers import grid_edges
from tests.naive import naive_localized_rng, naive_neighbourhoods
from tests.strategies import clouds


def as_set(edges):
    return {tuple(map(int, e)) for e in edges}


@pytest.mark.parametrize("k", [4, 8, 15, 24])
def test_planar_square_lattice_rng_is_grid(k):
    pts = grid_lattice(5, 5)
    assert as_set(localized_rng(pts, k).edges) == grid_edges(5, 5)


def test_regular_tetrahedron_rng_is_complete():
    tet = np.array([[1, 1, 1], [1, -1, -1], [-1, 1, -1], [-1, -1, 1]], float)
    assert as_set(localized_rng(tet, 3).edges) == {(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)}


def test_cube_lattice_rng_is_lattice_edges():
    pts = cube_lattice(3)
    e = localized_rng(pts, 12).edges
    length = np.linalg.norm(pts[e[:, 0]] - pts[e[:, 1]], axis=1)
    # exactly the unit lattice edges on the surface: 12 cube edges * 3 + 6 faces * 2 * 3 * 2
    assert np.allclose(length, 1.0)
    assert e.shape[0] == 12 * 3 + 6 * 12


def test_neighbourhood_includes_all_ties_with_kth():
    pts = grid_lattice(5, 5)
    nb = k_neighbourhoods(pts, 4)
    centre = 12
    members = set(nb.of(centre).tolist())
    assert nb.of(centre)[0] == centre
    assert members == {12, 7, 11, 13, 17}
    # k = 5: the 4 diagonal neighbours tie with the 5th, so all 4 join
    assert len(nb.of(centre)) == 5
    nb5 = k_neighbourhoods(pts, 5)
    assert set(nb5.of(centre).tolist()) == {12, 7, 11, 13, 17, 6, 8, 16, 18}


@given(clouds(), st.data())
def test_neighbourhoods_match_definition(pts, data):
    n = pts.shape[0]
    k = data.draw(st.integers(3, n - 1))
    nb = k_neighbourhoods(pts, k)
    ref = naive_neighbourhoods(pts, k, DEFAULT.rtol)
    for u in range(n):
        assert set(nb.of(u).tolist()) == ref[u]


@given(clouds())
def test_rng_with_k_n_minus_1_is_global_rng(pts):
    n = pts.shape[0]
    got = as_set(localized_rng(pts, n - 1).edges)
    assert got == naive_localized_rng(pts, n - 1, DEFAULT.rtol)


@given(clouds(min_n=8), st.data())
def test_localized_rng_matches_definition(pts, data):
    k = data.draw(st.integers(3, pts.shape[0] - 1))
    assert as_set(localized_rng(pts, k).edges) == naive_localized_rng(pts, k, DEFAULT.rtol)


def test_rng_rejects_duplicates_with_count():
    pts = np.vstack([grid_lattice(3, 3), [[0.0, 0.0, 0.0]]])
    with pytest.raises(InputError, match=r"contain 1 exact duplicate points"):
        localized_rng(pts, 4)
