"""Numba kernels of the reconstruction: arrays and scalars in, arrays out.

Every kernel here only computes; validation, contiguity and tie rules live in
the public function that calls it.  Each kernel has a slow reference in
``tests/naive.py`` and a property test comparing the two.  No ``fastmath``:
distance comparisons must be exact IEEE arithmetic so that ties are decided
by the documented tolerance and nothing else.
"""

from __future__ import annotations

import numpy as np

from .jit import njit


@njit(cache=True)
def _sqdist(p, a, b):
    dx = p[a, 0] - p[b, 0]
    dy = p[a, 1] - p[b, 1]
    dz = p[a, 2] - p[b, 2]
    return dx * dx + dy * dy + dz * dz


@njit(cache=True, nogil=True)
def local_rng_pairs(points, nb_indptr, nb_indices, shrink2, u_start, u_stop):
    """Union over all neighbourhoods of the neighbourhood's RNG edges.

    ``nb_indices[nb_indptr[u]:nb_indptr[u+1]]`` is N(u;k) including ``u``.
    A pair (a, b) of a neighbourhood is an edge unless some c of the same
    neighbourhood lies strictly inside the lune:
    ``max(|ac|², |bc|²) < shrink2 · |ab|²`` with ``shrink2 = (1 - rtol)²``.
    Only neighbourhoods ``u_start <= u < u_stop`` are processed (the caller
    chunks the work to drive a progress bar).  Returns an (m, 2) int64 array
    of pairs (a < b), possibly repeated.
    """
    cap = 1024
    out = np.empty((cap, 2), dtype=np.int64)
    m = 0
    for u in range(u_start, u_stop):
        lo = nb_indptr[u]
        hi = nb_indptr[u + 1]
        s = hi - lo
        ids = nb_indices[lo:hi]
        d2 = np.empty((s, s), dtype=np.float64)
        for i in range(s):
            d2[i, i] = 0.0
            for j in range(i + 1, s):
                v = _sqdist(points, ids[i], ids[j])
                d2[i, j] = v
                d2[j, i] = v
        for i in range(s):
            for j in range(i + 1, s):
                lim = shrink2 * d2[i, j]
                blocked = False
                for c in range(s):
                    if c == i or c == j:
                        continue
                    if d2[i, c] < lim and d2[j, c] < lim:
                        blocked = True
                        break
                if not blocked:
                    if m == cap:
                        cap *= 2
                        tmp = np.empty((cap, 2), dtype=np.int64)
                        tmp[:m] = out[:m]
                        out = tmp
                    a = ids[i]
                    b = ids[j]
                    if a < b:
                        out[m, 0] = a
                        out[m, 1] = b
                    else:
                        out[m, 0] = b
                        out[m, 1] = a
                    m += 1
    return out[:m]


@njit(cache=True)
def _bfs_bounded(indptr, indices, src, depth, dist, queue):
    """Breadth-first distances from ``src`` up to ``depth`` hops.

    ``dist`` must be all -1 on entry; the visited vertices are left in
    ``queue[:count]`` so the caller can reset them.  Returns ``count``.
    """
    dist[src] = 0
    queue[0] = src
    head = 0
    tail = 1
    while head < tail:
        x = queue[head]
        head += 1
        dx = dist[x]
        if dx == depth:
            continue
        for e in range(indptr[x], indptr[x + 1]):
            y = indices[e]
            if dist[y] < 0:
                dist[y] = dx + 1
                queue[tail] = y
                tail += 1
    return tail


@njit(cache=True)
def _is_isometric(indptr, indices, cyc, L, dist, queue):
    half = L // 2
    for i in range(L):
        cnt = _bfs_bounded(indptr, indices, cyc[i], half, dist, queue)
        ok = True
        for j in range(L):
            dj = j - i
            if dj < 0:
                dj = -dj
            want = min(dj, L - dj)
            if dist[cyc[j]] != want:
                ok = False
                break
        for q in range(cnt):
            dist[queue[q]] = -1
        if not ok:
            return False
    return True


@njit(cache=True, nogil=True)
def isometric_cycles(indptr, indices, max_len, s_start, s_stop):
    """All isometric cycles of length 3..max_len of an undirected graph.

    The graph is CSR with sorted, symmetric adjacency.  A cycle is reported
    once, starting at its smallest vertex and oriented so that its second
    vertex is smaller than its last.  The search from start ``s`` follows the
    characterisation of an isometric cycle seen from one of its vertices: the
    hop distance from ``s`` rises by one per step, may stay level once (odd
    length), then falls by one per step back to ``s``; every candidate is
    then checked pairwise.  Only starts ``s_start <= s < s_stop`` are
    searched (the caller splits the work over threads; the pieces, put
    together in order, are the whole list).  Returns ``(offsets, vertices)``.
    """
    n = indptr.shape[0] - 1
    half = max_len // 2
    dist0 = -np.ones(n, dtype=np.int64)
    dist = -np.ones(n, dtype=np.int64)
    queue = np.empty(n, dtype=np.int64)
    path = np.empty(max_len + 1, dtype=np.int64)
    it = np.empty(max_len + 1, dtype=np.int64)
    onpath = np.zeros(n, dtype=np.bool_)
    cap_c = 1024
    cap_v = 4096
    offs = np.empty(cap_c + 1, dtype=np.int64)
    verts = np.empty(cap_v, dtype=np.int64)
    offs[0] = 0
    nc = 0
    for s in range(s_start, s_stop):
        cnt0 = _bfs_bounded(indptr, indices, s, half, dist0, queue)
        # copy visited set because queue is reused by the isometry check
        visited = queue[:cnt0].copy()
        path[0] = s
        onpath[s] = True
        depth = 0  # index of last vertex on path
        it[0] = indptr[s]
        # phase flags recomputed from the distance profile
        while depth >= 0:
            x = path[depth]
            if it[depth] >= indptr[x + 1]:
                if depth > 0:
                    onpath[x] = False
                depth -= 1
                continue
            y = indices[it[depth]]
            it[depth] += 1
            if y < s:
                continue
            L_now = depth + 1  # vertices on path
            if y == s:
                # closing edge: need at least 3 vertices and last vertex at distance 1
                if L_now >= 3 and dist0[x] == 1 and path[1] < x:
                    L = L_now
                    if _is_isometric(indptr, indices, path, L, dist, queue):
                        if nc == cap_c:
                            cap_c *= 2
                            tmp = np.empty(cap_c + 1, dtype=np.int64)
                            tmp[: nc + 1] = offs[: nc + 1]
                            offs = tmp
                        if offs[nc] + L > cap_v:
                            cap_v = max(cap_v * 2, offs[nc] + L)
                            tmpv = np.empty(cap_v, dtype=np.int64)
                            tmpv[: offs[nc]] = verts[: offs[nc]]
                            verts = tmpv
                        for q in range(L):
                            verts[offs[nc] + q] = path[q]
                        offs[nc + 1] = offs[nc] + L
                        nc += 1
                continue
            if onpath[y] or L_now >= max_len:
                continue
            dy = dist0[y]
            if dy < 0:
                continue
            dx = dist0[x]
            # admissible distance profiles: rise by 1 while no fall happened,
            # one level step at the top, then fall by 1.
            rising = True
            level_used = False
            for q in range(1, depth + 1):
                if dist0[path[q]] < dist0[path[q - 1]]:
                    rising = False
                elif dist0[path[q]] == dist0[path[q - 1]]:
                    level_used = True
                    rising = False
            if dy == dx + 1:
                if not rising:
                    continue
            elif dy == dx:
                if not rising or level_used or depth == 0:
                    continue
            elif dy == dx - 1:
                if depth == 0:
                    continue
            else:
                continue
            # remaining length must allow to come back: need dy more steps
            if L_now + dy > max_len:
                continue
            depth += 1
            path[depth] = y
            onpath[y] = True
            it[depth] = indptr[y]
        onpath[s] = False
        for q in range(cnt0):
            dist0[visited[q]] = -1
    return offs[: nc + 1].copy(), verts[: offs[nc]].copy()


@njit(cache=True)
def _find(parent, a):
    while parent[a] != a:
        parent[a] = parent[parent[a]]
        a = parent[a]
    return a


@njit(cache=True)
def neighbourhood_disks(
    nb_indptr, nb_indices, cyc_offsets, cyc_vertices, cyc_edges, vc_indptr, vc_indices, n_edges
):
    """Euler characteristic and component count of the faces inside each N(u; k).

    The faces inside N(u; k) are the cycles all of whose vertices belong to
    it (the combinatorial stand-in for Conv(N(u; k)) ∩ P'); components are
    counted through shared vertices.  Returns
    ``(chi, comps, nfaces)``, each (n,) int64; a disk has ``chi == 1`` and
    ``comps == 1``.
    """
    n = nb_indptr.shape[0] - 1
    nc = cyc_offsets.shape[0] - 1
    member = np.zeros(n, dtype=np.bool_)
    vseen = np.zeros(n, dtype=np.bool_)
    eowner = -np.ones(n_edges, dtype=np.int64)
    vowner = -np.ones(n, dtype=np.int64)
    cmark = np.zeros(nc, dtype=np.bool_)
    parent = np.arange(nc)
    chi = np.zeros(n, dtype=np.int64)
    comps = np.zeros(n, dtype=np.int64)
    nfaces = np.zeros(n, dtype=np.int64)
    inside = np.empty(nc, dtype=np.int64)
    for u in range(n):
        lo = nb_indptr[u]
        hi = nb_indptr[u + 1]
        for q in range(lo, hi):
            member[nb_indices[q]] = True
        ni = 0
        for q in range(lo, hi):
            v = nb_indices[q]
            for t in range(vc_indptr[v], vc_indptr[v + 1]):
                c = vc_indices[t]
                if cmark[c]:
                    continue
                cmark[c] = True
                ok = True
                for z in range(cyc_offsets[c], cyc_offsets[c + 1]):
                    if not member[cyc_vertices[z]]:
                        ok = False
                        break
                if ok:
                    inside[ni] = c
                    ni += 1
        # reset marks of all touched cycles
        for q in range(lo, hi):
            v = nb_indices[q]
            for t in range(vc_indptr[v], vc_indptr[v + 1]):
                cmark[vc_indices[t]] = False
        nv = 0
        ne = 0
        for i in range(ni):
            c = inside[i]
            parent[c] = c
        ncomp = ni
        for i in range(ni):
            c = inside[i]
            for z in range(cyc_offsets[c], cyc_offsets[c + 1]):
                v = cyc_vertices[z]
                if not vseen[v]:
                    vseen[v] = True
                    vowner[v] = c
                    nv += 1
                else:
                    ra = _find(parent, vowner[v])
                    rb = _find(parent, c)
                    if ra != rb:
                        parent[ra] = rb
                        ncomp -= 1
                e = cyc_edges[z]
                if eowner[e] < 0:
                    eowner[e] = c
                    ne += 1
        for i in range(ni):
            c = inside[i]
            for z in range(cyc_offsets[c], cyc_offsets[c + 1]):
                vseen[cyc_vertices[z]] = False
                eowner[cyc_edges[z]] = -1
        for q in range(lo, hi):
            member[nb_indices[q]] = False
        chi[u] = nv - ne + ni
        comps[u] = ncomp
        nfaces[u] = ni
    return chi, comps, nfaces


@njit(cache=True)
def _corner_cross(p, a, b, c):
    """(b - a) x (c - a), as a tuple."""
    ux = p[b, 0] - p[a, 0]
    uy = p[b, 1] - p[a, 1]
    uz = p[b, 2] - p[a, 2]
    vx = p[c, 0] - p[a, 0]
    vy = p[c, 1] - p[a, 1]
    vz = p[c, 2] - p[a, 2]
    return uy * vz - uz * vy, uz * vx - ux * vz, ux * vy - uy * vx


@njit(cache=True)
def _tri_area(p, a, b, c):
    cx, cy, cz = _corner_cross(p, a, b, c)
    return 0.5 * np.sqrt(cx * cx + cy * cy + cz * cz)


@njit(cache=True)
def _cmp_tol(x, y, rtol):
    if abs(x - y) <= rtol * max(abs(x), abs(y)):
        return 0
    return -1 if x < y else 1


@njit(cache=True)
def min_area_splits(p, allowed, rtol):
    """Dynamic programme of the minimum-area triangulation of a polygon.

    ``p`` (L, 3) are the polygon's corners in order, ``allowed[i, j]``
    whether the chord i-j may be used (sides always may).  Splits are
    compared by total area, ties (relative ``rtol``) by total chord length,
    then the earlier split wins.  Returns ``(split, feasible)``:
    ``split[i, j]`` is the apex m of the triangle on chord (i, j), -1 where
    no triangulation of that sub-polygon exists.
    """
    L = p.shape[0]
    inf = np.inf
    cost = np.zeros((L, L))
    tie = np.zeros((L, L))
    split = -np.ones((L, L), dtype=np.int64)
    for span in range(2, L):
        for i in range(0, L - span):
            j = i + span
            if not allowed[i, j] and not (i == 0 and j == L - 1):
                cost[i, j] = inf
                continue
            best_c = inf
            best_t = inf
            for m in range(i + 1, j):
                if cost[i, m] == inf or cost[m, j] == inf:
                    continue
                c = cost[i, m] + cost[m, j] + _tri_area(p, i, m, j)
                diag = tie[i, m] + tie[m, j]
                if m - i > 1:
                    diag += np.sqrt(_sqdist(p, i, m))
                if j - m > 1:
                    diag += np.sqrt(_sqdist(p, m, j))
                cmp = _cmp_tol(c, best_c, rtol) if best_c < inf else -1
                if cmp == 0:
                    cmp = _cmp_tol(diag, best_t, rtol)
                if cmp < 0:
                    best_c = c
                    best_t = diag
                    cost[i, j] = c
                    tie[i, j] = diag
                    split[i, j] = m
            if best_c == inf:
                cost[i, j] = inf
    return split, cost[0, L - 1] < inf


@njit(cache=True)
def _unit_normal(p, a, b, c, out):
    out[0], out[1], out[2] = _corner_cross(p, a, b, c)
    length = np.sqrt(out[0] * out[0] + out[1] * out[1] + out[2] * out[2])
    if length > 0:
        out[0] /= length
        out[1] /= length
        out[2] /= length
    return length > 0


@njit(cache=True)
def _turn(p, t1, t2, n1, n2):
    """Angle between the normals of triangles t1 and t2 (pi if one is flat)."""
    if not _unit_normal(p, t1[0], t1[1], t1[2], n1) or not _unit_normal(p, t2[0], t2[1], t2[2], n2):
        return np.pi
    d = n1[0] * n2[0] + n1[1] * n2[1] + n1[2] * n2[2]
    return np.arccos(min(1.0, max(-1.0, d)))


@njit(cache=True)
def flip_costs(p, t1, t2, quad, across):
    """Curvature cost of an edge flip's five edges, before and after.

    ``quad`` = (p, q, r, s): triangles ``t1`` = (p, q, r) and ``t2`` =
    (q, p, s) (up to rotation) share the edge (p, q), which the flip
    replaces by (r, s) with triangles (r, p, s) and (s, q, r); ``across``
    (4, 3) are the triangles on the other sides of (q, r), (r, p), (p, s),
    (s, q).  An edge costs its length times the angle between its
    triangles' normals.  Returns ``(before, after, largest angle after)``.
    """
    n1 = np.empty(3)
    n2 = np.empty(3)
    a, b, r, s = quad[0], quad[1], quad[2], quad[3]
    outer = np.array([[b, r], [r, a], [a, s], [s, b]])
    new1 = np.array([r, a, s])
    new2 = np.array([s, b, r])
    before = np.sqrt(_sqdist(p, a, b)) * _turn(p, t1, t2, n1, n2)
    tt = _turn(p, new1, new2, n1, n2)
    after = np.sqrt(_sqdist(p, r, s)) * tt
    largest = tt
    for k in range(4):
        length = np.sqrt(_sqdist(p, outer[k, 0], outer[k, 1]))
        before += length * _turn(p, t1 if k < 2 else t2, across[k], n1, n2)
        tt = _turn(p, new2 if k == 0 or k == 3 else new1, across[k], n1, n2)
        largest = max(largest, tt)
        after += length * tt
    return before, after, largest
