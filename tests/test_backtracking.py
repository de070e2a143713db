"""Backtracking (Algorithm 4): the invariant, the success condition, the budget."""

import numpy as np
import pytest
from hypothesis import given

from sr33 import InputError, backtracking, localized_rng, trivial_isometric_cycles
from sr33.cycles import CycleSet
from sr33.samplers import cube_lattice, grid_lattice
from sr33.validators import edge_uses
from tests.strategies import clouds


def select(points, nb_size, **kw):
    e = localized_rng(points, nb_size).edges
    cyc = trivial_isometric_cycles(e, len(points))
    return e, cyc, backtracking(points, e, cyc, **kw)


def face_edge_uses(faces: CycleSet):
    pairs = []
    for i in range(len(faces)):
        c = faces.cycle(i)
        pairs += [tuple(sorted((int(a), int(b)))) for a, b in zip(c, np.roll(c, -1))]
    uniq, counts = np.unique(np.array(pairs), axis=0, return_counts=True)
    return uniq, counts


def test_cube_lattice_selects_the_54_squares_not_the_corner_hexagons():
    pts = cube_lattice(3)
    _, cyc, sel = select(pts, 12)
    assert len(cyc) == 62
    assert len(sel.faces) == 54
    assert set(sel.faces.lengths.tolist()) == {4}
    assert sel.success
    assert sel.open_edges.shape == (0, 2)
    _, counts = face_edge_uses(sel.faces)
    assert set(counts.tolist()) == {2}


def test_planar_grid_faces_are_unit_squares_with_the_border_open():
    pts = grid_lattice(4, 4)
    _, _, sel = select(pts, 8)
    assert len(sel.faces) == 9
    assert sel.success
    border = {tuple(sorted(e)) for e in sel.open_edges.tolist()}
    on_border = lambda v: pts[v, 0] in (0, 3) or pts[v, 1] in (0, 3)  # noqa: E731
    assert len(border) == 12
    assert all(on_border(a) and on_border(b) for a, b in border)


def test_regular_tetrahedron_is_closed_by_its_four_triangles():
    tet = np.array([[1, 1, 1], [1, -1, -1], [-1, 1, -1], [-1, -1, 1]], float)
    _, _, sel = select(tet, 3)
    assert sorted(sel.faces.as_tuples()) == [(0, 1, 2), (0, 1, 3), (0, 2, 3), (1, 2, 3)]
    assert sel.success


def test_folded_pair_is_never_selected_together():
    # square abcd and triangle abe on the same side of ab: selecting both folds
    pts = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0.5, 0.4, 0.01]], float)
    edges = np.array([[0, 1], [1, 2], [2, 3], [0, 3], [0, 4], [1, 4]])
    cyc = CycleSet(np.array([0, 4, 7]), np.array([0, 1, 2, 3, 0, 1, 4]))
    sel = backtracking(pts, edges, cyc)
    assert sel.selected.sum() == 1


@given(clouds(min_n=6, max_n=20))
def test_invariant_no_edge_used_more_than_twice(pts):
    k = min(len(pts) - 1, 8)
    _, cyc, sel = select(pts, k)
    if len(sel.faces):
        _, counts = face_edge_uses(sel.faces)
        assert counts.max() <= 2
    # success (the paper's condition) implies every used sample's link is a
    # disk and no edge is open unless it lies in one candidate only; stray
    # samples are allowed (the cones attach them)
    if sel.success:
        used = np.unique(sel.faces.vertices)
        assert np.intersect1d(sel.unresolved_samples, used).shape[0] == 0
        cand_edges, cand_counts = face_edge_uses(cyc)
        lone = {tuple(k) for k in cand_edges[cand_counts == 1].tolist()}
        assert all(tuple(e) in lone for e in sel.open_edges.tolist())


def test_budget_exhaustion_is_reported_not_silent():
    pts = cube_lattice(4)
    # exact cube lattice with k large: neighbourhoods reach around edges,
    # so some components are ambiguous; a budget of 1 cannot solve them
    e = localized_rng(pts, 30).edges
    cyc = trivial_isometric_cycles(e, len(pts))
    full = backtracking(pts, e, cyc)
    tiny = backtracking(pts, e, cyc, budget=1, exact_seconds=0)
    if full.components == 0:
        pytest.skip("no ambiguous component on this lattice")
    assert tiny.fallback_components > 0
    assert not tiny.success
    _, counts = face_edge_uses(tiny.faces)
    assert counts.max() <= 2
    # the exact selection takes over where the budget ran out, and closes it
    rescued = backtracking(pts, e, cyc, budget=1)
    assert rescued.fallback_components == tiny.fallback_components
    assert rescued.exact.components > 0 and rescued.exact.improved > 0
    assert rescued.success and rescued.open_edges.shape == (0, 2)


def test_neighbourhood_disk_indicator_on_a_closed_cube():
    pts = cube_lattice(4)
    e, cyc, sel = select(pts, 12, k=12)
    assert sel.success
    assert sel.non_disk_neighbourhoods.shape == (0,)


def test_bad_arguments():
    pts = cube_lattice(2)
    e = localized_rng(pts, 8).edges
    cyc = trivial_isometric_cycles(e, len(pts))
    with pytest.raises(InputError, match="budget must be a positive integer, got 0"):
        backtracking(pts, e, cyc, budget=0)
    for seconds in (-1.0, float("nan"), float("inf"), "5"):
        with pytest.raises(InputError, match="exact_seconds must be a finite number >= 0"):
            backtracking(pts, e, cyc, exact_seconds=seconds)
    bad = CycleSet(np.array([0, 3]), np.array([0, 1, 25]))
    with pytest.raises(InputError, match="cycles use a pair of points that is not an edge"):
        backtracking(pts, e, bad)


def test_edge_uses_counts_like_group_rows():
    tri = np.array([[0, 1, 2], [0, 2, 3], [0, 2, 4]])
    uniq, counts = edge_uses(tri)
    assert dict(zip(map(tuple, uniq.tolist()), counts.tolist()))[(0, 2)] == 3
