"""TrivialIsometricCycles (Algorithm 3): known answers and brute force."""

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from sr33 import InputError, localized_rng, trivial_isometric_cycles
from sr33.samplers import cube_lattice, grid_lattice
from tests.naive import naive_isometric_cycles
from tests.strategies import clouds


def test_planar_lattice_cycles_are_unit_squares():
    pts = grid_lattice(4, 5)
    e = localized_rng(pts, 8).edges
    cyc = trivial_isometric_cycles(e, len(pts)).as_tuples()
    assert len(cyc) == 3 * 4
    for c in cyc:
        assert len(c) == 4
        q = pts[list(c)]
        # a unit square: 4 unit sides
        assert np.allclose(np.linalg.norm(q - np.roll(q, -1, axis=0), axis=1), 1.0)


def test_tetrahedron_cycles_are_its_four_triangles():
    tet_edges = [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)]
    assert set(trivial_isometric_cycles(tet_edges, 4).as_tuples()) == {
        (0, 1, 2),
        (0, 1, 3),
        (0, 2, 3),
        (1, 2, 3),
    }


def test_cube_lattice_cycles_are_squares_and_corner_hexagons():
    pts = cube_lattice(3)
    e = localized_rng(pts, 12).edges
    cyc = trivial_isometric_cycles(e, len(pts))
    lengths = cyc.lengths
    assert np.bincount(lengths).tolist() == [0, 0, 0, 0, 54, 0, 8]
    # the 6-cycles are the links of the 8 corners: all 6 vertices at distance 1 or sqrt(2)
    corners = pts[((pts == 0) | (pts == 3)).all(axis=1)]
    for i in np.flatnonzero(lengths == 6):
        q = pts[cyc.cycle(i)]
        d = np.linalg.norm(q[:, None, :] - corners[None, :, :], axis=2)
        near = np.argmin(d.max(axis=0))
        assert np.allclose(np.sort(d[:, near]), [1, 1, 1, 2**0.5, 2**0.5, 2**0.5])


def test_cycles_of_the_3_cube_graph_are_faces_and_equators():
    # the 1-skeleton of a cube: 6 square faces and the 4 antipodal hexagons
    # (opposite hexagon vertices are antipodes of the cube, 3 apart both ways)
    v = [(x, y, z) for x in (0, 1) for y in (0, 1) for z in (0, 1)]
    edges = [
        (i, j)
        for i in range(8)
        for j in range(i + 1, 8)
        if sum(a != b for a, b in zip(v[i], v[j])) == 1
    ]
    cyc = trivial_isometric_cycles(edges, 8, max_length=8)
    assert np.bincount(cyc.lengths).tolist() == [0, 0, 0, 0, 6, 0, 4]
    assert set(cyc.as_tuples()) == naive_isometric_cycles(edges, 8, 8)


def test_length_bound_is_respected():
    ring = [(i, (i + 1) % 7) for i in range(7)]
    assert len(trivial_isometric_cycles(ring, 7, max_length=6)) == 0
    assert trivial_isometric_cycles(ring, 7, max_length=7).as_tuples() == [tuple(range(7))]


@given(clouds(min_n=6, max_n=14), st.data())
def test_cycles_match_brute_force(pts, data):
    k = data.draw(st.integers(3, pts.shape[0] - 1))
    e = localized_rng(pts, k).edges
    got = set(trivial_isometric_cycles(e, len(pts), max_length=7).as_tuples())
    assert got == naive_isometric_cycles([tuple(x) for x in e.tolist()], len(pts), 7)


def test_bad_arguments_are_named():
    with pytest.raises(InputError, match=r"max_cycle_length must be at least 3, got 2"):
        trivial_isometric_cycles([(0, 1)], 2, max_length=2)
    with pytest.raises(InputError, match=r"edges index points out of range 0..2"):
        trivial_isometric_cycles([(0, 5)], 3)
    with pytest.raises(InputError, match=r"edges must have shape \(m, 2\), got \(3,\)"):
        trivial_isometric_cycles([0, 1, 2], 3)
