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


def _segments_cross_triangles(p0, p1, a, b, c, eps):
    """Vectorized Möller–Trumbore: does the open segment p0-p1 cross triangle abc?"""
    from sr33.mesh import cross

    d = p1 - p0
    e1, e2 = b - a, c - a
    h = cross(d, e2)
    det = np.einsum("ij,ij->i", e1, h)
    ok = np.abs(det) > eps
    inv = np.where(ok, 1.0 / np.where(ok, det, 1.0), 0.0)
    s = p0 - a
    u = inv * np.einsum("ij,ij->i", s, h)
    q = cross(s, e1)
    v = inv * np.einsum("ij,ij->i", d, q)
    t = inv * np.einsum("ij,ij->i", e2, q)
    tol = 1e-12
    return ok & (u >= -tol) & (v >= -tol) & (u + v <= 1 + tol) & (t > tol) & (t < 1 - tol)


def naive_self_intersections(v: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Every pair of triangles tested with numpy (the kernel's reference):
    box overlap, then an edge of one crossing the other (edges touching the
    other's vertices skipped), then the fold of two triangles on one edge."""
    from sr33.mesh import cross

    if t.shape[0] < 2:
        return np.empty((0, 2), dtype=np.int64)
    p = v[t]
    scale = float(np.abs(v).max()) or 1.0
    eps = 1e-14 * scale * scale
    lo, hi = p.min(axis=1), p.max(axis=1)
    i, j = np.triu_indices(t.shape[0], 1)
    box = np.all((lo[i] <= hi[j]) & (lo[j] <= hi[i]), axis=1)
    i, j = i[box], j[box]
    ti, tj = t[i], t[j]
    shared = (ti[:, :, None] == tj[:, None, :]).sum(axis=(1, 2))
    hit = np.zeros(i.shape[0], dtype=bool)
    for dst, ts, td in ((j, ti, tj), (i, tj, ti)):
        for k in range(3):
            a_idx, b_idx = ts[:, k], ts[:, (k + 1) % 3]
            touches = (a_idx[:, None] == td).any(axis=1) | (b_idx[:, None] == td).any(axis=1)
            sel = np.flatnonzero(~touches)
            if not sel.size:
                continue
            r = _segments_cross_triangles(
                v[a_idx[sel]], v[b_idx[sel]], p[dst[sel], 0], p[dst[sel], 1], p[dst[sel], 2], eps
            )
            hit[sel[r]] = True
    two = np.flatnonzero((shared == 2) & ~hit)
    if two.shape[0]:
        a, b = ti[two], tj[two]
        in_b = (a[:, :, None] == b[:, None, :]).any(axis=2)
        in_a = (b[:, :, None] == a[:, None, :]).any(axis=2)
        oa = a[~in_b]
        ob = b[~in_a]
        common = a[in_b].reshape(-1, 2)
        e0, e1 = v[common[:, 0]], v[common[:, 1]]
        na = cross(e1 - e0, v[oa] - e0)
        nb = cross(e1 - e0, v[ob] - e0)
        la, lb = np.linalg.norm(na, axis=1), np.linalg.norm(nb, axis=1)
        cos = np.einsum("ij,ij->i", na, nb) / np.maximum(la * lb, 1e-300)
        hit[two[cos > 1 - 1e-12]] = True
    return np.stack([i[hit], j[hit]], axis=1).astype(np.int64)


_EDGES = np.array([[0, 1], [1, 2], [2, 0]])


def naive_repair_energy(
    pts, of, tri, move, hold, anchor, judged, reach, h, wide, target, short_, gap
):
    """The boundary repair's energy, gradient, ratios and counted triangles as
    numpy computed them before the numba kernel
    (``sr33.samplers._repair_kernels.energy_terms``; stop 42's
    ``repair._energy``, its per-point sums left to ``np.bincount``)."""
    kind = of[tri]
    real = kind >= 0
    movable = real & move[np.maximum(kind, 0)]
    tri = tri[(kind != -1).all(axis=1) & (real.all(axis=1) | movable.any(axis=1))]
    tri = tri[(judged[np.maximum(of[tri], 0)] & (of[tri] >= 0)).any(axis=1)]
    p = pts[tri]
    vec = p[:, _EDGES[:, 0]] - p[:, _EDGES[:, 1]]
    length = np.linalg.norm(vec, axis=2)
    if reach > 0:
        near = length.max(axis=1) <= reach
        tri, p, vec, length = tri[near], p[near], vec[near], length[near]
    order = np.argsort(length, axis=1, kind="stable")
    rows = np.arange(tri.shape[0])
    i2, i3 = order[:, 1], order[:, 2]
    l2, l3 = length[rows, i2], length[rows, i3]
    rho = l2 / l3
    over = np.maximum(0.0, rho - target)
    energy = float((over**2).sum())
    at, terms = [], []

    def push(edge_col, coef):
        a = tri[rows, _EDGES[edge_col, 0]]
        b = tri[rows, _EDGES[edge_col, 1]]
        unit = vec[rows, edge_col] / length[rows, edge_col][:, None]
        at.extend((a, b))
        terms.extend((coef[:, None] * unit, -coef[:, None] * unit))

    push(i2, 2 * over / l3)
    push(i3, -2 * over * l2 / l3**2)
    short = np.maximum(0.0, short_ * h - length) / h
    energy += float((short**2).sum()) / 2.0
    for col in range(3):
        push(np.full(tri.shape[0], col), -short[:, col] / h)
    ends = of[tri[:, _EDGES]]
    real_ends = ends >= 0
    ids = np.maximum(ends, 0)
    both = (real_ends & hold[ids]).all(axis=2) & ~(real_ends & anchor[ids]).all(axis=2)
    if both.any():
        gap = (
            np.where(
                both,
                np.maximum(0.0, gap[0] * h - length) - np.maximum(0.0, length - gap[1] * h),
                0.0,
            )
            / h
        )
        energy += 5.0 * float((gap**2).sum()) / 2.0
        for col in range(3):
            push(np.full(tri.shape[0], col), -10.0 * gap[:, col] / h)
    cross = vec[:, 0, 0] * (-vec[:, 2, 1]) - vec[:, 0, 1] * (-vec[:, 2, 0])
    area = 0.5 * np.abs(cross)
    radius = np.minimum(length.prod(axis=1) / np.maximum(4.0 * area, 1e-300), 1e6 * h)
    wd = np.maximum(0.0, radius - wide * h) / h
    energy += float((wd**2).sum())
    cen = p.mean(axis=1)
    pull = (
        (2 * wd / h)[:, None, None]
        * (p - cen[:, None, :])
        / np.maximum(radius, 1e-300)[:, None, None]
    )
    at.append(tri.ravel())
    terms.append(pull.reshape(-1, 2))
    index, values = np.concatenate(at), np.concatenate(terms)
    gp = np.stack(
        [np.bincount(index, weights=values[:, j], minlength=pts.shape[0]) for j in range(2)],
        axis=1,
    )
    return energy, gp, rho, tri


def naive_line_clamp(p, a, d, normals, least, beyond):
    """The straight edges' clamp as numpy (the code the kernel replaced)."""
    dd = (d * d).sum(axis=-1)

    def measure(q):
        u = q[:, None, :] - a[None]
        return (u * d[None]).sum(axis=-1) / dd[None], (u * normals[None]).sum(axis=-1)

    out = p.copy()
    t_all, in_all = measure(out)
    for k in range(a.shape[0]):
        t, inward = t_all[:, k], in_all[:, k]
        bad = (t > 0) & (t < 1) & (inward < least) & (inward > beyond)
        if bad.any():
            out[bad] += (least - inward[bad])[:, None] * normals[k]
            t_all[bad], in_all[bad] = measure(out[bad])
    return out


def naive_line_project(p, a, d, lo):
    """Nearest point of the nearest straight edge, as numpy (the code the kernel replaced)."""
    dd = (d * d).sum(axis=-1)
    t = np.clip(((p[:, None, :] - a[None]) * d[None]).sum(axis=-1) / dd[None], 0.0, 1.0)
    q = p[:, None, :] - (a[None] + t[:, :, None] * d[None])
    which = np.argmin(np.sqrt((q * q).sum(axis=-1)), axis=1)
    s = ((p - a[which]) * d[which]).sum(axis=-1) / dd[which]
    s = np.clip(s, lo[which], 1.0 - lo[which])
    return a[which] + s[:, None] * d[which]


def naive_arc_project(p, centre, radius, start, span, closed, margin):
    """Nearest point of one arc, kept ``margin`` from an open arc's ends
    (a point past either end to the nearer end), as numpy (``chart.Arc``'s
    projection, the code the kernel replaced)."""
    from sr33 import libm

    d = p - centre
    ang = libm.arctan2(d[:, 1], d[:, 0])
    if not closed:
        rel = (ang - start) % (2 * np.pi)
        lo, hi = margin / radius, span - margin / radius
        past = rel > span + (2 * np.pi - span) / 2
        rel = np.where(past, lo, np.clip(rel, lo, hi))
        ang = start + rel
    return centre + radius * np.stack([np.cos(ang), np.sin(ang)], axis=1)


def naive_curves_project(p, curves, margin):
    """Nearest point of the nearest curve: ``curves`` are ("line", a, d, lo)
    or ("arc", centre, radius, start, span, closed), as numpy (the first of
    equally near ones)."""
    dist = np.empty((p.shape[0], len(curves)))
    for k, c in enumerate(curves):
        if c[0] == "line":
            _, a, d, _ = c
            t = np.clip(((p - a) * d).sum(axis=1) / (d * d).sum(), 0.0, 1.0)
            q = p - (a + t[:, None] * d)
            dist[:, k] = np.sqrt((q * q).sum(axis=1))
        else:
            dist[:, k] = np.abs(np.linalg.norm(p - c[1], axis=1) - c[2])
    which = np.argmin(dist, axis=1)
    out = p.copy()
    for k, c in enumerate(curves):
        sel = which == k
        if not sel.any():
            continue
        if c[0] == "line":
            _, a, d, lo = c
            t = np.clip(((p[sel] - a) * d).sum(axis=1) / (d * d).sum(), lo, 1.0 - lo)
            out[sel] = a + t[:, None] * d
        else:
            out[sel] = naive_arc_project(p[sel], *c[1:], margin)
    return out


def naive_arc_clamp(p, arcs, sides, margins):
    """Points kept on the face's side of every arc ((centre, radius, start,
    span, closed) each), ``margins`` from it, arc after arc, as numpy (the
    code the kernel replaced)."""
    from sr33 import libm

    out = p.copy()
    for (centre, radius, start, span, closed), side, margin in zip(arcs, sides, margins):
        w = out - centre
        r = np.linalg.norm(w, axis=1)
        ang = (libm.arctan2(w[:, 1], w[:, 0]) - start) % (2 * np.pi)
        within = closed | (ang <= span)
        inward = side * (radius - r)
        bad = within & (inward < margin) & (r > 1e-12)
        if bad.any():
            out[bad] = centre + w[bad] / r[bad, None] * (radius - side * margin)
    return out


def naive_arc_ghosts(p, arcs, sides, h):
    """The points of ``p`` on an arc (within 1e-6 h of the nearest) moved h
    and 2h across it from its centre, arc by arc, as numpy (the code the
    kernel replaced; ``arcs`` are (centre, radius) each)."""
    if not arcs:
        return np.empty((0, 2))
    d = np.stack([np.abs(np.linalg.norm(p - c, axis=1) - r) for c, r in arcs], axis=1)
    on = d.min(axis=1) < 1e-6 * h
    if not on.any():
        return np.empty((0, 2))
    p = p[on]
    which = np.argmin(d[on], axis=1)
    out = []
    for k, (c, r) in enumerate(arcs):
        w = p[which == k] - c
        w /= np.linalg.norm(w, axis=1)[:, None]
        for j in (1.0, 2.0):
            out.append(c + (r + sides[k] * j * h) * w)
    return np.vstack(out)
