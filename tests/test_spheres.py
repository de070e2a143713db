"""samplers.spheres and the meridian rows of a partial sphere."""

import math

import numpy as np
import pytest

from sr33.samplers.faces import Stereographic
from sr33.samplers.scanline import _plane_offsets
from sr33.samplers.spheres import _circle


def _sphere_points(n, centre, radius, pole, reach, seed=0):
    """``n`` points of the sphere within ``reach`` radians of ``pole``."""
    rng = np.random.default_rng(seed)
    v = rng.normal(size=(4 * n, 3))
    v /= np.linalg.norm(v, axis=1)[:, None]
    v = v[v @ pole > math.cos(reach)][:n]
    return centre + radius * v


def test_stereographic_map_inverts_and_keeps_ratios():
    """The map and its inverse undo each other; it is isometric at the pole
    (a point at angle θ maps to 2 R tan(θ / 2)); and a small triangle's
    ratio of Condition III-ii (second-longest over longest edge) is kept to
    within a few parts in a thousand (the map is conformal)."""
    centre, radius = np.array([0.6, 0.6, 0.6]), 0.45
    pole = -np.ones(3) / math.sqrt(3)
    m = Stereographic(centre, radius, pole)
    p = _sphere_points(200, centre, radius, pole, math.radians(40))
    q = m(p)
    np.testing.assert_allclose(m.inverse(q), p, atol=1e-12)
    theta = np.arccos(np.clip((p - centre) @ pole / radius, -1, 1))
    np.testing.assert_allclose(
        np.linalg.norm(q, axis=1), 2 * radius * np.tan(theta / 2), rtol=1e-9, atol=1e-12
    )
    # a right triangle of legs 0.03 and 0.025 on the sphere, 30° from the pole
    a = centre + radius * np.array([math.sin(0.5), 0.0, math.cos(0.5)])
    frame = Stereographic(centre, radius, np.array([0.0, 0.0, 1.0]))
    t1 = np.array([math.cos(0.5), 0.0, -math.sin(0.5)])
    t2 = np.array([0.0, 1.0, 0.0])

    def on_sphere(x):
        return centre + radius * (x - centre) / np.linalg.norm(x - centre)

    tri = np.array([a, on_sphere(a + 0.03 * t1), on_sphere(a + 0.025 * t2)])

    def ratio(t):
        e = np.sort(np.linalg.norm(t - np.roll(t, 1, axis=0), axis=1))
        return e[1] / e[2]

    assert abs(ratio(frame(tri)) - ratio(tri)) < 3e-3


def test_circles_through_three_points():
    c, r = _circle(np.array([1.0, 0.0]), np.array([0.0, 1.0]), np.array([-1.0, 0.0]))
    np.testing.assert_allclose(c, [0.0, 0.0], atol=1e-12)
    assert r == pytest.approx(1.0)
    assert _circle(np.zeros(2), np.ones(2), 2 * np.ones(2)) is None


def test_meridian_rows_of_a_partial_sphere_are_h_apart_along_it():
    """A partial sphere with sharp rims takes rows whose planes are ``hf``
    apart along its meridians from the pole on the side of -d, not along
    d: the arc length between consecutive rows is hf everywhere, where the
    family's planes are hf apart along d only (farther apart on the sphere
    near a pole)."""
    radius, hf = 0.45, 0.0305
    d = np.array([0.0, 0.0, 1.0])
    centre = np.array([0.6, 0.6, 0.6])
    sphere = (centre, radius, np.array([1.0, 0.0, 0.0]), np.array([0.0, 1.0, 0.0]), d)
    lo, hi = 0.15, 0.5  # cutcube's scoop spans these heights
    t = _plane_offsets(lo, hi, 0.0, hf, sphere)
    assert t.min() >= lo - 1e-12 and t.max() <= hi + 1e-12
    psi = np.arccos((centre[2] - t) / radius)
    np.testing.assert_allclose(np.diff(psi) * radius, hf, rtol=1e-9)
    np.testing.assert_allclose(psi / (hf / radius), np.round(psi / (hf / radius)), atol=1e-9)
    flat = _plane_offsets(lo, hi, 0.0, hf, None)
    np.testing.assert_allclose(np.diff(flat), hf)
    psi_flat = np.arccos(np.clip((centre[2] - flat) / radius, -1, 1))
    assert (np.diff(psi_flat) * radius).max() > 1.5 * hf  # the family's planes graze the pole


def _great_circle_ratio(p: np.ndarray, tri, radius: float) -> float:
    """Condition III-ii's ratio of the triangle ``tri`` of points on a
    sphere of ``radius`` about the origin, its sides along great circles."""
    a, b, c = (p[i] for i in tri)
    chords = np.array([np.linalg.norm(a - b), np.linalg.norm(b - c), np.linalg.norm(c - a)])
    side = np.sort(2 * radius * np.arcsin(chords / (2 * radius)))
    return side[1] / side[2]


def test_sphere_worst_judges_both_diagonals_of_a_cocircular_quad():
    """Four samples on one circle of the sphere: either diagonal is
    Delaunay, and a check on another triangulation of the sphere may take
    either, so ``sphere_worst`` judges the worse; pulled off the circle,
    only the Delaunay diagonal's triangles count.  The far point (the
    antipode) makes the hull solid; its facets' chords are over 2.5 h."""
    from sr33.samplers.spheres import sphere_worst

    radius, h, rho = 20.0, 1.0, 1.2
    z0 = math.sqrt(radius**2 - rho**2)
    ang = np.radians([0.0, 90.0, 140.0, 250.0])
    quad = np.c_[rho * np.cos(ang), rho * np.sin(ang), np.full(4, z0)]
    far = [0.0, 0.0, -radius]
    pts = np.vstack([quad, far])
    by_02 = max(_great_circle_ratio(pts, t, radius) for t in ((0, 1, 2), (0, 2, 3)))
    by_13 = max(_great_circle_ratio(pts, t, radius) for t in ((1, 2, 3), (1, 3, 0)))
    assert abs(by_02 - by_13) > 0.03  # the two diagonals judge differently
    got = sphere_worst(pts, np.zeros(3), radius, h)
    assert got == pytest.approx(max(by_02, by_13), abs=1e-12)
    # corner 0 pulled towards the circle's centre (along the sphere): inside
    # the circle through 1, 2, 3, so the diagonal 0-2 is Delaunay and the
    # other is no triangle of the sphere
    d = np.array([rho * 0.6, 0.0, 0.0])
    p0 = d + np.array([0.0, 0.0, math.sqrt(radius**2 - d @ d)])
    pulled = np.vstack([p0, quad[1:], far])
    want = max(_great_circle_ratio(pulled, t, radius) for t in ((0, 1, 2), (0, 2, 3)))
    other = max(_great_circle_ratio(pulled, t, radius) for t in ((1, 2, 3), (1, 3, 0)))
    assert abs(want - other) > 0.03
    assert sphere_worst(pulled, np.zeros(3), radius, h) == pytest.approx(want, abs=1e-12)
    # fewer than four points, or all on one circle (flat): nothing to judge
    assert sphere_worst(quad[:3], np.zeros(3), radius, h) == 0.0
    assert sphere_worst(quad, np.zeros(3), radius, h) == 0.0
