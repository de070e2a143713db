"""Meshes with known topology for the validators' tests (combinatorial builders)."""

from __future__ import annotations

import numpy as np

TETRA = np.array([(0, 1, 2), (0, 3, 1), (1, 3, 2), (2, 3, 0)])


def torus(n: int = 8, m: int = 6, offset: int = 0) -> np.ndarray:
    """Triangulated n x m grid on a torus (coherently oriented)."""
    tri = []
    for i in range(n):
        for j in range(m):
            a = i * m + j
            b = ((i + 1) % n) * m + j
            c = ((i + 1) % n) * m + (j + 1) % m
            d = i * m + (j + 1) % m
            tri += [(a, b, c), (a, c, d)]
    return np.array(tri) + offset


def torus_points(n: int = 8, m: int = 6, big: float = 2.0, small: float = 0.7) -> np.ndarray:
    u = np.repeat(np.arange(n) * 2 * np.pi / n, m)
    v = np.tile(np.arange(m) * 2 * np.pi / m, n)
    return np.stack(
        [
            (big + small * np.cos(v)) * np.cos(u),
            (big + small * np.cos(v)) * np.sin(u),
            small * np.sin(v),
        ],
        axis=1,
    )


def double_torus() -> np.ndarray:
    """Connected sum of two tori: drop one triangle of each, join the holes by a tube."""
    a = torus()
    b = torus(offset=48)
    ha, hb = a[0], b[0]
    tube = []
    # ha is traversed (x0, x1, x2); hb reversed so that the tube is coherent
    x, y = ha, hb[::-1]
    for k in range(3):
        p, q = x[k], x[(k + 1) % 3]
        r, s = y[k], y[(k + 1) % 3]
        tube += [(q, p, r), (q, r, s)]
    return np.vstack([a[1:], b[1:], np.array(tube)])


def disk(n: int = 6) -> np.ndarray:
    """A fan of n triangles around vertex 0: one boundary loop."""
    return np.array([(0, 1 + i, 1 + (i + 1) % n) for i in range(n)])


def mobius(n: int = 6) -> np.ndarray:
    """A Möbius strip of 2n triangles."""
    top, bot = list(range(n)), list(range(n, 2 * n))
    tri = []
    for i in range(n):
        a, b = top[i], top[(i + 1) % n]
        c, d = bot[i], bot[(i + 1) % n]
        if i == n - 1:
            b, d = d, b
        tri += [(a, b, c), (b, d, c)]
    return np.array(tri)


def icosphere() -> tuple[np.ndarray, np.ndarray]:
    """The icosahedron (points, triangles)."""
    t = (1 + 5**0.5) / 2
    p = np.array(
        [
            [-1, t, 0],
            [1, t, 0],
            [-1, -t, 0],
            [1, -t, 0],
            [0, -1, t],
            [0, 1, t],
            [0, -1, -t],
            [0, 1, -t],
            [t, 0, -1],
            [t, 0, 1],
            [-t, 0, -1],
            [-t, 0, 1],
        ],
        float,
    )
    f = np.array(
        [
            [0, 11, 5],
            [0, 5, 1],
            [0, 1, 7],
            [0, 7, 10],
            [0, 10, 11],
            [1, 5, 9],
            [5, 11, 4],
            [11, 10, 2],
            [10, 7, 6],
            [7, 1, 8],
            [3, 9, 4],
            [3, 4, 2],
            [3, 2, 6],
            [3, 6, 8],
            [3, 8, 9],
            [4, 9, 5],
            [2, 4, 11],
            [6, 2, 10],
            [8, 6, 7],
            [9, 8, 1],
        ]
    )
    return p, f
