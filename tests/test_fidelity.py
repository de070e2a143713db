"""validators.fidelity: exact distances, Hausdorff of displaced copies, sharp edges."""

import numpy as np
import pytest

pv = pytest.importorskip("pyvista")

from sr33.validators.fidelity import feature_distance, hausdorff, sharp_edges  # noqa: E402


@pytest.fixture(scope="module")
def sphere():
    s = pv.Sphere(radius=1.0, theta_resolution=60, phi_resolution=60).triangulate()
    return np.asarray(s.points, dtype=float), np.asarray(s.faces).reshape(-1, 4)[:, 1:]


def test_mesh_against_itself_is_zero(sphere):
    v, f = sphere
    r = hausdorff(v, f, v, f, samples=2000)
    assert r.hausdorff < 1e-12 and r.mean < 1e-12


@pytest.mark.parametrize("d", [0.01, 0.05, 0.2])
def test_copy_displaced_along_normals(sphere, d):
    v, f = sphere
    n = v / np.linalg.norm(v, axis=1)[:, None]
    r = hausdorff(v + d * n, f, v, f, spacing=0.1, samples=2000)
    assert r.hausdorff == pytest.approx(d, rel=0.05)
    assert r.hausdorff_h == pytest.approx(d / 0.1, rel=0.05)


def test_sharp_edges_of_a_cube_and_feature_distance():
    cube = pv.Cube().triangulate()
    v = np.asarray(cube.points, dtype=float)
    f = np.asarray(cube.faces).reshape(-1, 4)[:, 1:]
    # the cube's 12 edges (diagonals of its faces are flat, so not sharp)
    assert sharp_edges(v, f).shape == (12, 2)
    assert feature_distance(v, f, v, f).max() < 1e-12
    shifted = feature_distance(v * 1.1, f, v, f)
    assert shifted.min() > 0
