"""reconstruct (Algorithm 1): invariance, determinism, small paper sets."""

import os

import numpy as np
import pytest

from sr33 import reconstruct
from sr33.io import read_points
from sr33.samplers import cube_lattice
from sr33.validators import mesh_stats
from tests.helpers import PAPER_SMALL, need, triangle_set
from tests.strategies import rotation


def figures(r):
    return mesh_stats(r.triangles, r.vertices.shape[0]).as_dict()


@pytest.mark.parametrize("name, euler", [("cone", 2), ("conebox", 2), ("cube", 2), ("cutcube", 0)])
def test_small_paper_sets_are_closed_manifolds(name, euler):
    pts = read_points(need(PAPER_SMALL / f"{name}.obj"))
    r = reconstruct(pts, 16)
    s = figures(r)
    assert r.success
    assert (s["open_edges"], s["overloaded_edges"], s["components"]) == (0, 0, 1)
    assert s["euler"] == euler
    assert s["used_vertices"] == len(pts)
    assert s["edges"] == 3 * len(pts) - 3 * euler  # closed triangulation: E = 3V - 3χ


def jittered(pts, scale, seed=0):
    h = np.median(np.linalg.norm(np.diff(pts, axis=0), axis=1))
    return pts + np.random.default_rng(seed).normal(size=pts.shape) * h * scale


@pytest.fixture(params=["lattice", "jittered"])
def cloud(request):
    pts = read_points(need(PAPER_SMALL / "cube.obj"))
    return pts if request.param == "lattice" else jittered(pts, 0.01)


def test_shuffling_gives_the_same_triangles(cloud):
    a = reconstruct(cloud, 16)
    perm = np.random.default_rng(3).permutation(len(cloud))
    b = reconstruct(cloud[perm], 16)
    # vertex i of b is input point perm[i] (no duplicates): relabel to a's labels
    assert triangle_set(b.triangles, perm) == triangle_set(a.triangles)
    edges_a = {tuple(e) for e in a.rng_edges.tolist()}
    edges_b = {tuple(sorted(e)) for e in perm[b.rng_edges].tolist()}
    assert edges_a == edges_b


@pytest.mark.parametrize(
    "factor, shift", [(3.7, (0, 0, 0)), (1e-3, (5, -2, 1)), (250.0, (0.5, 0.5, 0.5))]
)
def test_scaling_and_translation_give_the_same_triangles(cloud, factor, shift):
    a = reconstruct(cloud, 16)
    b = reconstruct(cloud * factor + np.array(shift), 16)
    assert triangle_set(b.triangles) == triangle_set(a.triangles)


@pytest.mark.parametrize("seed", [1, 7, 42])
def test_rotation_keeps_graph_and_topology_on_lattices(seed):
    pts = read_points(need(PAPER_SMALL / "cube.obj"))
    a = reconstruct(pts, 16)
    b = reconstruct(pts @ rotation(seed).T + np.array([0.3, -2.0, 5.0]), 16)
    assert np.array_equal(a.rng_edges, b.rng_edges)
    assert figures(a) == figures(b)


@pytest.mark.parametrize("seed", [1, 7, 42])
def test_rotation_gives_the_same_triangles_without_exact_ties(seed):
    pts = jittered(read_points(need(PAPER_SMALL / "cube.obj")), 0.01)
    a = reconstruct(pts, 16)
    b = reconstruct(pts @ rotation(seed).T + np.array([0.3, -2.0, 5.0]), 16)
    assert triangle_set(a.triangles) == triangle_set(b.triangles)


def test_two_runs_are_identical_arrays():
    pts = cube_lattice(5)
    a, b = reconstruct(pts, 12), reconstruct(pts, 12)
    assert a.triangles.tobytes() == b.triangles.tobytes()
    assert a.vertices.tobytes() == b.vertices.tobytes()


def test_result_passes_through_every_sample_and_reports_steps():
    pts = cube_lattice(4)
    r = reconstruct(pts, 12)
    np.testing.assert_array_equal(r.vertices, pts)  # first-occurrence order
    assert np.unique(r.triangles).shape[0] == len(pts)
    assert set(r.timings) >= {
        "localized_rng",
        "isometric_cycles",
        "backtracking",
        "triangulate",
        "cones",
    }
    assert r.candidate_cycles >= len(r.face_cycles)
    assert r.orientable and r.success


def test_strict_self_check_catches_a_broken_triangulation():
    import pytest as _pytest

    from sr33.cycles import CycleSet
    from sr33.selfcheck import InternalError, check_faces_and_triangles

    faces = CycleSet(np.array([0, 4]), np.array([0, 1, 2, 3]))
    with _pytest.raises(InternalError, match="a face did not become length - 2 triangles"):
        check_faces_and_triangles(faces, np.array([[0, 1, 2]]), np.array([0]))
    two = CycleSet(np.array([0, 3, 6, 9]), np.array([0, 1, 2, 0, 1, 3, 0, 1, 4]))
    with _pytest.raises(InternalError, match="an edge is used 3 times"):
        check_faces_and_triangles(two, np.array([[0, 1, 2], [0, 1, 3], [0, 1, 4]]), np.arange(3))


def test_output_bytes_do_not_depend_on_thread_counts():
    # numba, OpenMP and BLAS thread pools of 1 and 2 threads: the same bytes
    import subprocess
    import sys

    code = (
        "import hashlib, numpy as np\n"
        "from sr33 import reconstruct\n"
        "from sr33.samplers import cube_lattice\n"
        "p = cube_lattice(8) + 0.01 * np.sin(np.arange(3 * 386)).reshape(-1, 3)\n"
        "r = reconstruct(p, 12)\n"
        "print(hashlib.sha256(r.triangles.tobytes()).hexdigest(), r.triangles.shape[0])\n"
    )
    out = []
    for threads in ("1", "2"):
        env = dict(os.environ)
        for pool in ("NUMBA", "OMP", "OPENBLAS", "MKL"):
            env[f"{pool}_NUM_THREADS"] = threads
        res = subprocess.run(
            [sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True
        )
        out.append(res.stdout.split())
    assert out[0] == out[1] and int(out[0][1]) > 0


def test_a_separate_small_open_sheet_stays_apart_from_a_closed_body():
    """A small open piece is taken apart into strays only when the RNG joins
    its boundary to another piece (a tip cut off its cone): a sheet scanned
    apart from a ball keeps its own triangles, none joins it to the ball."""
    i = np.arange(900) + 0.5
    z = 1 - 2 * i / 900
    t = np.pi * (1 + 5**0.5) * i
    ball = np.column_stack([np.sqrt(1 - z * z) * np.cos(t), np.sqrt(1 - z * z) * np.sin(t), z])
    g = 0.12 * np.arange(6)
    sheet = np.column_stack([np.repeat(g, 6), np.tile(g, 6), np.full(36, 4.0)])
    r = reconstruct(np.vstack([ball, sheet]), 20)
    in_sheet = np.isin(r.triangles, np.arange(900, 936))
    assert not (in_sheet.any(axis=1) & ~in_sheet.all(axis=1)).any()  # no triangle joins them
    assert np.unique(r.triangles[in_sheet.all(axis=1)]).shape[0] == 36
    s = mesh_stats(r.triangles[in_sheet.all(axis=1)], r.vertices.shape[0])
    assert s.open_edges == 20  # the sheet's own boundary
