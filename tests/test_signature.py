"""validators.signature: meshes with known answers, planted defects."""

import numpy as np

from sr33.validators.signature import homeomorphic, signature
from tests.meshes import TETRA, disk, double_torus, icosphere, mobius, torus


def keys(s):
    return [(c.orientable, c.euler, c.boundary_loops, c.genus) for c in s.components]


def test_tetrahedron_and_icosphere_are_spheres():
    assert keys(signature(TETRA)) == [(True, 2, 0, 0)]
    p, f = icosphere()
    s = signature(f, points=p)
    assert keys(s) == [(True, 2, 0, 0)] and s.manifold and s.incoherent_edges == 0
    assert homeomorphic(TETRA, f)


def test_torus_and_double_torus():
    assert keys(signature(torus())) == [(True, 0, 0, 1)]
    s = signature(double_torus())
    assert keys(s) == [(True, -2, 0, 2)]
    assert s.manifold
    v = homeomorphic(torus(), double_torus())
    assert not v
    assert v.reasons == ("Euler characteristic: mesh 0, truth -2",)


def test_disk_has_one_boundary_loop():
    assert keys(signature(disk())) == [(True, 1, 1, 0)]


def test_mobius_strip_is_non_orientable():
    s = signature(mobius())
    assert keys(s) == [(False, 0, 1, 1)]
    v = homeomorphic(mobius(), np.vstack([disk(), disk()[:0]]))
    assert "orientability: mesh component is non-orientable, truth's is orientable" in v.reasons


def test_two_spheres_are_two_components():
    s = signature(np.vstack([TETRA, TETRA + 4]))
    assert keys(s) == [(True, 2, 0, 0), (True, 2, 0, 0)]
    assert homeomorphic(TETRA, np.vstack([TETRA, TETRA + 4])).reasons == (
        "components: mesh has 1, truth has 2",
    )


def test_bow_tie_pinch_is_one_non_manifold_vertex():
    s = signature([(0, 1, 2), (0, 3, 4)])
    assert s.non_manifold_vertices.tolist() == [0]
    assert not s.manifold
    assert (
        "mesh has 1 non-manifold vertices" in homeomorphic([(0, 1, 2), (0, 3, 4)], disk()).reasons
    )


def test_duplicated_face_is_flagged():
    s = signature(np.vstack([TETRA, TETRA[:1]]))
    assert s.duplicate_faces == 1
    assert s.overloaded_edges == 3
    assert not s.manifold


def test_flipped_face_is_still_orientable_but_incoherent():
    flipped = TETRA.copy()
    flipped[0] = flipped[0][::-1]
    s = signature(flipped)
    assert s.orientable
    assert s.incoherent_edges == 3
    assert homeomorphic(flipped, TETRA)


def test_removed_face_opens_a_hole():
    v = homeomorphic(TETRA[1:], TETRA)
    assert v.reasons == ("Euler characteristic: mesh 1, truth 2", "boundary loops: mesh 1, truth 0")


def test_degenerate_face_with_points():
    p, f = icosphere()
    p2 = np.vstack([p, p[0]])
    s = signature(np.vstack([f, [[0, 1, 1]]]), points=p2)
    assert s.degenerate_faces == 1


def test_unused_points_counted():
    assert signature(TETRA, n_points=10).unused_points == 6


def test_shared_meshes_are_spheres():
    from sr33.io import read_mesh
    from tests.helpers import MESHES, need

    for name in ("spot", "cheburashka"):
        v, f = read_mesh(need(MESHES / f"{name}.obj"))
        s = signature(f, v.shape[0], points=v)
        assert [(c.orientable, c.euler, c.boundary_loops, c.genus) for c in s.components] == [
            (True, 2, 0, 0)
        ]
        assert s.manifold and s.unused_points == 0
