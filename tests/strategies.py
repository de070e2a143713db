"""Hypothesis strategies: small clouds, lattice clouds with exact ties, rotations."""

from __future__ import annotations

import numpy as np
from hypothesis import strategies as st


@st.composite
def random_clouds(draw, min_n: int = 5, max_n: int = 18) -> np.ndarray:
    """Distinct points in general position (floats in a unit box)."""
    n = draw(st.integers(min_n, max_n))
    seed = draw(st.integers(0, 2**32 - 1))
    pts = np.random.default_rng(seed).random((n, 3))
    return pts


@st.composite
def lattice_clouds(draw, min_n: int = 5, max_n: int = 18) -> np.ndarray:
    """Distinct integer lattice points in a small box: many exactly tied distances."""
    n = draw(st.integers(min_n, max_n))
    seed = draw(st.integers(0, 2**32 - 1))
    rng = np.random.default_rng(seed)
    side = draw(st.integers(2, 4))
    grid = np.stack(np.meshgrid(*[np.arange(side + 1)] * 3, indexing="ij"), -1).reshape(-1, 3)
    flat = draw(st.booleans())
    if flat:
        grid = grid[grid[:, 2] == 0]
    n = min(n, grid.shape[0])
    idx = rng.choice(grid.shape[0], size=n, replace=False)
    pts = grid[idx].astype(float)
    # avoid all-collinear sets
    centred = pts - pts.mean(axis=0)
    s = np.linalg.svd(centred, compute_uv=False)
    if s[1] <= 1e-9 * s[0]:
        pts = np.vstack([pts, [[0.5, 0.25, 0.0]]])
    return pts


@st.composite
def clouds(draw, min_n: int = 5, max_n: int = 18) -> np.ndarray:
    """Either kind."""
    return draw(st.one_of(random_clouds(min_n, max_n), lattice_clouds(min_n, max_n)))


def rotation(angle_seed: int) -> np.ndarray:
    """A proper rotation matrix from a seed (arbitrary axis and angle)."""
    rng = np.random.default_rng(angle_seed)
    q = rng.normal(size=4)
    q /= np.linalg.norm(q)
    w, x, y, z = q
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )
