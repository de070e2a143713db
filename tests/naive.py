"""Slow, obviously correct references for the kernels (straight from the definitions)."""

from __future__ import annotations

import itertools

import numpy as np
from scipy.sparse import csgraph, csr_matrix


def naive_neighbourhoods(points: np.ndarray, k: int, rtol: float) -> list[set[int]]:
    """N(u; k): u, its k nearest, and every sample tied with the k-th (Section 1.2)."""
    n = points.shape[0]
    out = []
    for u in range(n):
        d = np.sqrt(((points - points[u]) ** 2).sum(axis=1))
        others = np.sort(np.delete(d, u))
        dk = others[k - 1]
        out.append({u} | {v for v in range(n) if v != u and d[v] <= dk * (1 + rtol)})
    return out


def naive_rng_of(points: np.ndarray, members, rtol: float) -> set[tuple[int, int]]:
    """RNG of a set of samples: ab is an edge iff no c lies strictly in the open lune."""
    members = sorted(members)
    edges = set()
    for a, b in itertools.combinations(members, 2):
        dab = np.linalg.norm(points[a] - points[b])
        blocked = False
        for c in members:
            if c in (a, b):
                continue
            dac = np.linalg.norm(points[a] - points[c])
            dbc = np.linalg.norm(points[b] - points[c])
            if max(dac, dbc) < (1 - rtol) * dab:
                blocked = True
                break
        if not blocked:
            edges.add((a, b))
    return edges


def naive_localized_rng(points: np.ndarray, k: int, rtol: float) -> set[tuple[int, int]]:
    """Algorithm 2 literally: the union of the RNGs of all N(u; k)."""
    out: set[tuple[int, int]] = set()
    for nb in naive_neighbourhoods(points, k, rtol):
        out |= naive_rng_of(points, nb, rtol)
    return out


def naive_isometric_cycles(edges, n: int, max_len: int) -> set[tuple[int, ...]]:
    """Every simple cycle up to max_len whose cycle distances equal graph distances."""
    adj: dict[int, set[int]] = {v: set() for v in range(n)}
    for a, b in edges:
        adj[a].add(b)
        adj[b].add(a)
    rows = [a for a, b in edges] + [b for a, b in edges]
    cols = [b for a, b in edges] + [a for a, b in edges]
    g = csr_matrix((np.ones(len(rows)), (rows, cols)), shape=(n, n))
    dist = csgraph.shortest_path(g, unweighted=True, directed=False)
    found: set[tuple[int, ...]] = set()

    def extend(path):
        if len(path) > max_len:
            return
        last = path[-1]
        for y in adj[last]:
            if y == path[0] and len(path) >= 3:
                cyc = tuple(path)
                if cyc[1] < cyc[-1]:
                    found.add(cyc)
            elif y > path[0] and y not in path:
                extend(path + [y])

    for s in range(n):
        extend([s])
    iso = set()
    for cyc in found:
        L = len(cyc)
        ok = all(
            dist[cyc[i], cyc[j]] == min(abs(i - j), L - abs(i - j))
            for i in range(L)
            for j in range(i + 1, L)
        )
        if ok:
            iso.add(cyc)
    return iso


def naive_min_area_triangulation(points: np.ndarray, allowed: np.ndarray):
    """Smallest total area over every triangulation of the polygon ``points``
    (corners in order) whose chords are all ``allowed``; None if there is
    none.  Enumerates the triangulations (Catalan many): small polygons only."""

    def area(a, b, c):
        return 0.5 * np.linalg.norm(np.cross(points[b] - points[a], points[c] - points[a]))

    def best(i, j):
        if j - i < 2:
            return 0.0
        out = None
        for m in range(i + 1, j):
            if not all(y - x == 1 or allowed[x, y] for x, y in ((i, m), (m, j))):
                continue
            left, right = best(i, m), best(m, j)
            if left is None or right is None:
                continue
            total = left + right + area(i, m, j)
            out = total if out is None else min(out, total)
        return out

    return best(0, len(points) - 1)


def naive_flip_costs(points: np.ndarray, quad, across):
    """Curvature cost (length times normal angle) of the five edges of the
    flip of (p, q) to (r, s), before and after, and the largest new angle,
    from the definition (reference of ``sr33._kernels.flip_costs``)."""
    p, q, r, s = quad

    def turn(t1, t2):
        n1 = np.cross(points[t1[1]] - points[t1[0]], points[t1[2]] - points[t1[0]])
        n2 = np.cross(points[t2[1]] - points[t2[0]], points[t2[2]] - points[t2[0]])
        if not np.linalg.norm(n1) or not np.linalg.norm(n2):
            return np.pi
        c = n1 @ n2 / np.linalg.norm(n1) / np.linalg.norm(n2)
        return float(np.arccos(np.clip(c, -1, 1)))

    def length(a, b):
        return float(np.linalg.norm(points[a] - points[b]))

    t1, t2, new1, new2 = (p, q, r), (q, p, s), (r, p, s), (s, q, r)
    outer = [(q, r), (r, p), (p, s), (s, q)]
    before = length(p, q) * turn(t1, t2)
    turns = [turn(new1, new2)]
    after = length(r, s) * turns[0]
    for k, (a, b) in enumerate(outer):
        before += length(a, b) * turn(t1 if k < 2 else t2, across[k])
        turns.append(turn(new2 if k in (0, 3) else new1, across[k]))
        after += length(a, b) * turns[-1]
    return before, after, max(turns)
