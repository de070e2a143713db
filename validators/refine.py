"""Ground-truth meshes fine enough to measure geodesics between samples.

The sample conditions (Section 3 of the paper) are stated with geodesic
distances on the surface.  :mod:`sr33.validators.conditions` measures them on a
ground-truth triangle mesh, whose resolution bounds the accuracy of the
answer; CAD tessellations are coarse on flat faces (a cube's has 8
vertices) and the samples are not among their vertices.  Two steps fix
both:

* :func:`refine_to_edge_length` splits every edge longer than a bound, by
  conforming longest-edge bisection (Rivara): a triangle with any edge to
  split also splits its longest edge, so angles stay bounded away from 0 and
  no T-junction is made;
* :func:`insert_points` makes every sample a vertex of the mesh: the nearest
  vertex is moved onto it when the sample is that close, the nearest edge is
  split at it when the sample lies on that edge (samples on sharp edges),
  the triangle is split in three otherwise.

Both keep the orientation of every triangle and the topology of the mesh.
"""

from __future__ import annotations

import numpy as np

from sr33.mesh import closest_points_on_triangles, edge_incidence, half_edges

SNAP = 1e-3  # barycentric weight below which a sample counts as on an edge / at a vertex


def _edges_of(tri: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Undirected edges and, per triangle, the id of local edge j = (t[j], t[j+1])."""
    inc = edge_incidence(*half_edges(tri))
    return inc.edges, inc.edge_of.reshape(-1, 3)


def _too_fine(max_edge: float, max_triangles: int) -> str:
    return (
        f"refining the truth mesh to edges of {max_edge:.3g} needs more than "
        f"{max_triangles} triangles; give a coarser resolution"
    )


def refine_to_edge_length(
    vertices, triangles, max_edge: float, *, local=None, max_triangles: int = 12_000_000
):
    """Split triangles until no edge is longer than ``max_edge``.

    Parameters
    ----------
    vertices : (v, 3) array_like of float
    triangles : (t, 3) array_like of int
    max_edge : float
        Longest edge allowed in the result.
    local : callable, optional
        ``local(midpoints) -> (m,) lengths``: a shorter limit where it is
        below ``max_edge``, read at each edge's midpoint (finer round crowded
        samples, :func:`sr33.validators.conditions.sample_conditions`); its
        attribute ``floor``, when it has one, is a lower bound of its values
        (edges no longer than it are not asked about).
    max_triangles : int
        Refuse (``ValueError``) when the result would exceed this many triangles.

    Returns
    -------
    vertices : (v', 3) float64 ndarray
        The input vertices first, then edge midpoints.
    triangles : (t', 3) int64 ndarray
        Same orientation as the input triangles they subdivide.

    Examples
    --------
    >>> v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], float)
    >>> rv, rt = refine_to_edge_length(v, [[0, 1, 2]], 0.3)
    >>> bool(np.linalg.norm(rv[rt] - np.roll(rv[rt], 1, axis=1), axis=2).max() <= 0.3)
    True
    >>> round(float(np.linalg.norm(np.cross(rv[rt[:, 1]] - rv[rt[:, 0]],
    ...     rv[rt[:, 2]] - rv[rt[:, 0]]), axis=1).sum() / 2), 12)
    0.5
    """
    v = np.asarray(vertices, dtype=np.float64).copy()
    t = np.asarray(triangles, dtype=np.int64).copy()
    if not (np.isfinite(max_edge) and max_edge > 0):
        raise ValueError(f"max_edge must be a positive finite number, got {max_edge!r}")
    # no triangle with edges at most max_edge is larger than the equilateral
    # one, so the mesh's area bounds the result's count from below: a
    # resolution out of reach is refused before any splitting (refining a
    # unit square towards 3e-6 to the budget took 24 s)
    area = 0.5 * np.linalg.norm(np.cross(v[t[:, 1]] - v[t[:, 0]], v[t[:, 2]] - v[t[:, 0]]), axis=1)
    if float(area.sum()) / (np.sqrt(3.0) / 4.0 * max_edge**2) > max_triangles:
        raise ValueError(_too_fine(max_edge, max_triangles))
    while True:
        edges, tedge = _edges_of(t)
        length = np.linalg.norm(v[edges[:, 0]] - v[edges[:, 1]], axis=1)
        split = length > max_edge
        if local is not None:
            # only edges longer than the shortest local limit can be split
            maybe = np.flatnonzero(~split & (length > getattr(local, "floor", 0.0)))
            if maybe.size:
                mid = 0.5 * (v[edges[maybe, 0]] + v[edges[maybe, 1]])
                split[maybe] = length[maybe] > local(mid)
        if not split.any():
            return v, t
        # a triangle splitting any edge splits its longest one too (Rivara), so
        # bisection always runs from the midpoint of the longest edge
        tlen = length[tedge]
        longest = np.argmax(tlen, axis=1)
        rows = np.arange(t.shape[0])
        while True:
            need = split[tedge].any(axis=1) & ~split[tedge[rows, longest]]
            if not need.any():
                break
            split[tedge[need, longest[need]]] = True
        if t.shape[0] + 3 * int(split.sum()) > max_triangles:
            raise ValueError(_too_fine(max_edge, max_triangles))
        mid = np.full(edges.shape[0], -1, dtype=np.int64)
        mid[split] = v.shape[0] + np.arange(int(split.sum()))
        v = np.vstack([v, 0.5 * (v[edges[split, 0]] + v[edges[split, 1]])])
        # rotate each triangle so that local edge 0 is its longest
        r = (np.arange(3)[None, :] + longest[:, None]) % 3
        tr = np.take_along_axis(t, r, axis=1)
        m = mid[np.take_along_axis(tedge, r, axis=1)]
        a, b, c = tr[:, 0], tr[:, 1], tr[:, 2]
        m0, m1, m2 = m[:, 0], m[:, 1], m[:, 2]
        out = [tr[m0 < 0]]
        s = m0 >= 0
        # bisect the longest edge: (a, m0, c) and (m0, b, c), each split again
        # at its own marked edge (m2 on c-a, m1 on b-c)
        left = s & (m2 < 0)
        out.append(np.stack([a[left], m0[left], c[left]], 1))
        left = s & (m2 >= 0)
        out.append(np.stack([a[left], m0[left], m2[left]], 1))
        out.append(np.stack([m0[left], c[left], m2[left]], 1))
        right = s & (m1 < 0)
        out.append(np.stack([m0[right], b[right], c[right]], 1))
        right = s & (m1 >= 0)
        out.append(np.stack([m0[right], b[right], m1[right]], 1))
        out.append(np.stack([m0[right], m1[right], c[right]], 1))
        t = np.concatenate(out)


#: a point in a triangle lies within this share of its longest edge of its
#: centroid (the farthest corner is 2/3 of its median away, and a median is
#: at most the longest edge)
CENTROID_REACH = 2.0 / 3.0


def _longest_edge(v: np.ndarray, t: np.ndarray) -> float:
    if t.shape[0] == 0:
        return 0.0
    p = v[t]
    return float(np.sqrt(((p - p[:, [1, 2, 0]]) ** 2).sum(axis=2)).max())


def _nearest_triangles(p, v, t, inc, kk: int):
    """Per point, the nearest of the triangles round its ``kk`` nearest
    vertices (``inc``: vertex-triangle incidence): triangle, barycentric
    coordinates, distance."""
    from scipy.spatial import cKDTree

    kk = min(kk, v.shape[0])
    _, near = cKDTree(v).query(p, kk)
    near = near.reshape(p.shape[0], kk)
    # candidate triangles: those around the kk nearest vertices (padded with -1)
    deg = np.diff(inc.indptr)
    width = int(deg[near].sum(axis=1).max())
    cand = np.full((p.shape[0], width), -1, dtype=np.int64)
    col = np.zeros(p.shape[0], dtype=np.int64)
    for j in range(kk):
        vj = near[:, j]
        for s_ in range(int(deg[vj].max())):
            has = deg[vj] > s_
            cand[has, col[has]] = inc.indices[inc.indptr[vj[has]] + s_]
            col[has] += 1
    rows = np.repeat(np.arange(p.shape[0]), width)
    flat = cand.ravel()
    ok = flat >= 0
    d, bary = closest_points_on_triangles(p[rows[ok]], v[t[flat[ok]]])
    dist = np.full(flat.size, np.inf)
    dist[ok] = d
    full_bary = np.zeros((flat.size, 3))
    full_bary[ok] = bary
    pick = np.argmin(dist.reshape(p.shape[0], width), axis=1)
    at = np.arange(p.shape[0]) * width + pick
    return flat[at], full_bary[at], dist[at]


def insert_points(vertices, triangles, points, *, candidates: int = 4):
    """Make every point a vertex of the mesh (snap, edge split or face split).

    Parameters
    ----------
    vertices : (v, 3) array_like of float
    triangles : (t, 3) array_like of int
        A mesh whose triangles are smaller than the spacing of ``points`` (no
        two points in one triangle; see :func:`refine_to_edge_length`).
    points : (n, 3) array_like of float
        Points on or very near the mesh.
    candidates : int
        Nearest mesh vertices whose triangles are searched for each point.

    Returns
    -------
    vertices : (v', 3) float64 ndarray
    triangles : (t', 3) int64 ndarray
    index : (n,) int64 ndarray
        The vertex that is each point; ``vertices[index]`` equals ``points``.

    Raises
    ------
    ValueError
        When two points fall on the same vertex (near-duplicate points, or
        the mesh is too coarse); the message names them and their distance.

    Examples
    --------
    >>> v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], float)
    >>> nv, nt, idx = insert_points(v, [[0, 1, 2]], [[0.2, 0.2, 0.0], [0.5, 0.0, 0.0]])
    >>> idx.tolist(), nt.shape[0]
    ([3, 4], 4)
    """
    from scipy import sparse
    from scipy.spatial import cKDTree

    v = np.asarray(vertices, dtype=np.float64).copy()
    t = np.asarray(triangles, dtype=np.int64).copy()
    pts = np.asarray(points, dtype=np.float64)
    n = pts.shape[0]
    # rounding, in the search's reach below
    slack = 1e-6 * float(np.ptp(v, axis=0).max()) if v.size else 0.0
    index = np.full(n, -1, dtype=np.int64)
    pending = np.arange(n)
    while pending.size:
        nv = v.shape[0]
        inc = sparse.csr_matrix(
            (np.ones(t.size), (t.ravel(), np.repeat(np.arange(t.shape[0]), 3))), (nv, t.shape[0])
        )
        best_tri, best_bary, best_d = _nearest_triangles(pts[pending], v, t, inc, candidates)
        # the triangles round a few nearest vertices can miss the point's
        # own (a ball's dish meeting a cylinder's wall at a sharp rim: the 4
        # nearest vertices were the wall's, and a dish sample split a wall
        # triangle, folding the mesh into a cone point that geodesics bent
        # round, 1.93 h between samples 0.78 h apart).  A point over a
        # triangle lies within 2/3 of its longest edge of its centroid (in
        # its plane), and within the pick's distance off it: every triangle
        # that near is searched too
        centroid = v[t].mean(axis=1)
        near = cKDTree(centroid).query_ball_point(
            pts[pending], CENTROID_REACH * _longest_edge(v, t) + best_d + slack
        )
        count = np.array([len(x) for x in near], dtype=np.int64)
        if count.sum():
            which = np.repeat(np.arange(pending.size), count)
            tri = np.concatenate([np.asarray(x, dtype=np.int64) for x in near if x])
            d, bary = closest_points_on_triangles(pts[pending][which], v[t[tri]])
            # per point, the nearest (the first of equals, in the tree's order)
            order = np.lexsort((np.arange(d.size), d, which))
            first = order[np.r_[True, which[order][1:] != which[order][:-1]]]
            rows = which[first]
            better = d[first] < best_d[rows]
            rows, first = rows[better], first[better]
            best_tri[rows], best_bary[rows], best_d[rows] = tri[first], bary[first], d[first]
        edges, tedge = _edges_of(t)
        touched = np.zeros(t.shape[0], dtype=bool)  # split this round (replaced below)
        new_tris: list[list[int]] = []
        deferred = []
        # edge -> its (up to two) triangles
        owner = np.full((edges.shape[0], 2), -1, dtype=np.int64)
        flat = tedge.ravel()
        order = np.argsort(flat, kind="stable")
        first = np.ones(order.size, dtype=bool)
        first[1:] = flat[order][1:] != flat[order][:-1]
        owner[flat[order][first], 0] = order[first] // 3
        owner[flat[order][~first], 1] = order[~first] // 3
        snapped = set(index[index >= 0].tolist())
        added: list[np.ndarray] = []
        for row, i in enumerate(pending):
            ti, w = int(best_tri[row]), best_bary[row]
            corner = int(np.argmax(w))
            if w[corner] > 1 - SNAP:
                vid = int(t[ti, corner])
                if vid in snapped:
                    j = int(np.flatnonzero(index == vid)[0])
                    gap = float(np.linalg.norm(pts[i] - pts[j]))
                    raise ValueError(
                        f"samples {min(i, j)} and {max(i, j)} fall on one vertex of the truth "
                        f"mesh ({gap:.3g} apart): near-duplicate samples, or a truth mesh too "
                        "coarse for them"
                    )
                snapped.add(vid)
                v[vid] = pts[i]
                index[i] = vid
                continue
            low = int(np.argmin(w))
            on_edge = w[low] < SNAP
            # the triangles to split: the two beside the edge the sample is on
            # (local edge (low + 1) % 3 is the one opposite corner ``low``), or its own
            e = int(tedge[ti, (low + 1) % 3]) if on_edge else -1
            tris = owner[e][owner[e] >= 0] if on_edge else np.array([ti])
            if touched[tris].any():
                deferred.append(i)
                continue
            new_id = nv + len(added)
            added.append(pts[i])
            index[i] = new_id
            touched[tris] = True
            if not on_edge:
                a, b, c = t[ti]
                new_tris += [[a, b, new_id], [b, c, new_id], [c, a, new_id]]
                continue
            ends = set(edges[e].tolist())
            for tj in tris:
                tri = t[tj]
                rot = next(r for r in range(3) if {int(tri[r]), int(tri[(r + 1) % 3])} == ends)
                a, b, c = np.roll(tri, -rot)
                new_tris += [[a, new_id, c], [new_id, b, c]]
        if added:
            v = np.vstack([v, np.array(added)])
        if new_tris:
            t = np.vstack([t[~touched], np.array(new_tris, dtype=np.int64).reshape(-1, 3)])
        if len(deferred) == pending.size:
            raise ValueError("could not insert the samples into the truth mesh")
        pending = np.array(deferred, dtype=np.int64)
    return v, t, index
