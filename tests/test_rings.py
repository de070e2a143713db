"""Ring positions along a meridian (samplers.rings): halvings where the gap is
HALVING_GAP row steps, the steps round them, a torus's symmetry."""

import math

import numpy as np
import pytest

from sr33.samplers.chart import halving_count
from sr33.samplers.rings import HALVING_GAP, HALVING_STEPS, ring_positions


def _torus_meridian(major, minor, count=20001):
    v = np.linspace(0.0, 2 * math.pi, count)
    return minor * v, major + minor * np.cos(v)


def _columns(plan, m):
    """Column counts per ring, walked from the widest ring (RingPlan.walk)."""
    cols = {plan.widest: m}
    for j, prev in plan.walk():
        cols[j] = cols[prev] // 2 if plan.halves[j] else cols[prev]
    return cols


@pytest.mark.parametrize("major, minor, h", [(0.5, 0.2, 0.025), (0.5, 0.3, 0.02), (1.0, 0.2, 0.03)])
def test_a_torus_halves_exactly_at_the_gap_with_its_steps(major, minor, h):
    s, rho = _torus_meridian(major, minor)
    t = s[-1] / round(s[-1] / h)
    m = halving_count(2 * math.pi * (major + minor) / h)
    plan = ring_positions(s, rho, t, m, closed=True)
    assert plan.at[0] == 0.0 and plan.widest == 0 and np.all(np.diff(plan.at) > 0)
    assert plan.halves.sum() >= 2 and plan.halves.sum() % 2 == 0
    cols = _columns(plan, m)
    radius = lambda x: np.interp(x % s[-1], s, rho)  # noqa: E731
    n = plan.at.size
    for j in np.flatnonzero(plan.halves):
        # the gap of the columns it halves is HALVING_GAP row steps there
        before = cols[(j - 1) % n] if plan.at[j] < s[-1] / 2 else cols[(j + 1) % n]
        np.testing.assert_allclose(
            2 * math.pi * radius(plan.at[j]) / before, HALVING_GAP * t, rtol=1e-3
        )
        # a step HALVING_STEPS[0] on the side of the full columns, [1] on the merged side
        wide, narrow = (
            ((j - 1) % n, (j + 1) % n) if plan.at[j] < s[-1] / 2 else ((j + 1) % n, (j - 1) % n)
        )
        for k, f in ((wide, HALVING_STEPS[0]), (narrow, HALVING_STEPS[1])):
            d = abs(plan.at[j] - plan.at[k])
            np.testing.assert_allclose(min(d, s[-1] - d), f * t, rtol=1e-9)
    # every step within 20 % of t; mirror images about the widest ring
    steps = np.diff(np.r_[plan.at, s[-1]])
    assert steps.min() > 0.75 * t and steps.max() < 1.2 * t
    np.testing.assert_allclose(
        np.sort((s[-1] - plan.at[1:]) % s[-1]), np.sort(plan.at[1:]), atol=1e-9 * t
    )
    # the columns of every ring: gaps within 0.62 to 1.61 row steps (rectangles below 0.85)
    for j, c in cols.items():
        g = 2 * math.pi * radius(plan.at[j]) / c
        assert 0.62 * t < g < 1.61 * t


def test_an_open_meridian_keeps_its_pole_rings_one_step_apart():
    r = 0.5
    theta = np.linspace(0.0, math.pi, 20001)
    s, rho = r * theta, r * np.sin(theta)
    rows = round(s[-1] / 0.025)
    t = s[-1] / rows
    m = halving_count(2 * math.pi * r / 0.025)
    plan = ring_positions(s, rho, t, m, keep=(10, 10))
    np.testing.assert_allclose(plan.at[:10], np.arange(1, 11) * t, rtol=1e-12)
    np.testing.assert_allclose(plan.at[-10:], s[-1] - np.arange(10, 0, -1) * t, rtol=1e-12)
    assert not plan.halves[:10].any() and not plan.halves[-10:].any()
    assert plan.halves.sum() == 2  # 128 columns halve once on either side before the rims
    np.testing.assert_allclose(np.interp(plan.at[plan.widest], s, rho), r, rtol=1e-3)
    # too short to design: one step apart, no designed halving
    short = ring_positions(s, rho, s[-1] / 12, m, keep=(6, 6))
    np.testing.assert_allclose(np.diff(short.at), s[-1] / 12, rtol=1e-9)
    assert not short.halves.any()


def test_a_cone_from_its_rim_halves_at_the_gap_and_reports_moved_halvings():
    """A cone's straight meridian from its rim (s = 0) to its apex: the
    halvings stand where the gap is HALVING_GAP row steps; one due within
    two steps of the kept apex rows is moved two steps before them and
    counted, so that a caller can choose the apex rows that move none."""
    slant, radius, t, m = 1.58, 0.5, 0.025, 128
    s, rho = np.array([0.0, slant]), np.array([radius, 0.0])
    t = slant / round(slant / t)
    found = {}
    for keep in range(6, 14):
        plan = ring_positions(s, rho, t, m, keep=(1, keep))
        assert plan.widest == 0  # the ring next to the rim
        np.testing.assert_allclose(plan.at[-keep + 1 :], slant - np.arange(keep - 1, 0, -1) * t)
        cols = m
        for j in np.flatnonzero(plan.halves):
            gap = 2 * math.pi * np.interp(plan.at[j], s, rho) / cols
            if plan.moved == 0:
                np.testing.assert_allclose(gap, HALVING_GAP * t, rtol=1e-9)
            else:
                assert gap >= HALVING_GAP * t * (1 - 1e-9)
            np.testing.assert_allclose(plan.at[j] - plan.at[j - 1], HALVING_STEPS[0] * t)
            cols //= 2
        found[keep] = plan.moved
    assert set(found.values()) == {0, 1}  # both happen over these apex zones


def test_fill_honours_the_step_before_a_halving():
    from sr33.samplers.rings import _fill

    assert _fill(0.9, 1.0, 1.0, 1.0) == []
    np.testing.assert_allclose(_fill(2.1, 1.0, 1.0, 0.8), [1.3])
    np.testing.assert_allclose(_fill(2.0, 1.0, 1.0, 1.0), [1.0])
    np.testing.assert_allclose(_fill(5.0, 1.0, 1.0, 0.8), [1.0, 2.0666666, 3.1333333, 4.2])
