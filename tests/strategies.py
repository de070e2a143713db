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


# --- library shapes and scan settings (the paper's guarantees) --------------------


@st.composite
def shape_params(draw, name: str) -> dict[str, float]:
    """Parameters of a library shape: each default perturbed by up to 15%,
    times one overall scale in [0.5, 2]; angles moved by up to 10 degrees."""
    from sr33.samplers import shapes

    scale = draw(st.floats(0.5, 2.0))
    out = {}
    for key, value in shapes.shape_parameters(name).items():
        if key == "angle":
            out[key] = value + draw(st.floats(-10.0, 10.0))
        else:
            out[key] = value * scale * draw(st.floats(0.85, 1.15))
    return out


@st.composite
def scan_settings(draw) -> dict:
    """Sampler settings inside the Condition III bounds."""
    return {
        "density": draw(st.floats(0.8, 1.25)),
        "ratio": draw(st.floats(0.85, 1.2)),
        "seed": draw(st.integers(0, 2**16)),
    }


@st.composite
def rigid_motions(draw) -> tuple[np.ndarray, np.ndarray, float]:
    """(rotation, translation, uniform scale)."""
    r = rotation(draw(st.integers(0, 2**31)))
    t = np.array([draw(st.floats(-10, 10)) for _ in range(3)])
    s = draw(st.sampled_from([1.0, 0.01, 3.5, 100.0]))
    return r, t, s


@st.composite
def arbitrary_points(draw) -> np.ndarray:
    """Robustness inputs: duplicates and near duplicates, collinear, coplanar,
    clustered, huge, tiny, a NaN or an inf mixed in, a sphere (a surface to
    find) among them."""
    kind = draw(
        st.sampled_from(
            [
                "random",
                "duplicates",
                "near duplicates",
                "collinear",
                "coplanar",
                "cluster",
                "huge",
                "tiny",
                "few",
                "sphere",
                "non-finite",
            ]
        )
    )
    seed = draw(st.integers(0, 2**31))
    rng = np.random.default_rng(seed)
    n = draw(st.integers(4, 60))
    p = rng.random((n, 3))
    if kind == "duplicates":
        p = np.vstack([p, p[rng.integers(0, n, n // 2 + 1)]])
    elif kind == "collinear":
        p = np.outer(rng.random(n), rng.random(3))
    elif kind == "coplanar":
        p[:, 2] = 0.0
    elif kind == "cluster":
        p = np.vstack([p * 1e-9, p + 5.0])
    elif kind == "huge":
        p = p * 1e12
    elif kind == "tiny":
        p = p * 1e-12
    elif kind == "few":
        p = p[: draw(st.integers(1, 4))]
    elif kind == "near duplicates":
        p = np.vstack([p, p[: n // 2] + rng.normal(0, 1e-12, (n // 2, 3))])
    elif kind == "sphere":
        p = rng.normal(size=(max(n, 20), 3))
        p /= np.linalg.norm(p, axis=1)[:, None]
        p *= 10.0 ** draw(st.sampled_from([-150, -6, 0, 6, 150]))
    elif kind == "non-finite":
        p[rng.integers(0, n)] = draw(st.sampled_from([np.nan, np.inf, -np.inf]))
    return p
