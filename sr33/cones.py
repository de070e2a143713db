"""Cones for stray samples (end of Section 5 of the paper).

Theorem 5 leaves a defect: the output need not use every sample.  The paper
remedies it by attaching stray samples with cones whose triangles keep
interiors disjoint.  Here a stray sample p is inserted where it is nearest:
into a triangle t (t is replaced by the three triangles joining p to t's
edges, a cone) or onto an edge e of two triangles (they are replaced by the
four joining p to their sides: the way back onto a sharp edge that a closed
selection bevelled, whose samples sit above the bevel's chords).  Both are
subdivisions, so the topology of the surface is unchanged; orientation is
inherited.  Options are tried nearest first and the first whose new
triangles have area and cross no triangle near them is taken (if none, the
nearest with area).  Then edge flips round the attached samples
(:func:`flip_sharper`) lower the total absolute curvature (edge length
times the angle between its triangles' normals; after Dyn, Hormann, Kim and
Levin 2001, *Optimizing 3D triangulations using discrete curvature
analysis*), when the new triangles cross no triangle near them: that puts a
bevelled edge's samples back on one sharp edge.  A flip keeps the topology
too.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

from ._kernels import flip_costs
from ._validate import InputError, as_points
from .mesh import (
    closest_points_on_triangles,
    cross,
    crossing_eps,
    dot,
    first_crossing,
    half_edges,
    norm,
    unique_rows,
)


def ring_centres(points, faces) -> dict[int, int]:
    """Stray samples that sit inside a face cycle ringing around them.

    At a cone tip the selected face cycle can be the ring of samples around
    the tip, leaving the tip itself unused; triangulating across the ring and
    then coning the tip over one triangle would fold the other triangles over
    it.  The cone of Section 5 is then the whole ring: this returns, for such
    faces, face index -> the stray sample to fan from.  A stray qualifies
    when, in the frame of the face's best-fit plane, its offset from the
    centroid is less than the face's radius (farthest vertex from the
    centroid) within the plane and less than twice that radius across it;
    each face takes at most one stray, nearest faces first.

    Returns
    -------
    dict of int to int
    """
    pts = np.asarray(points, dtype=np.float64)
    n = pts.shape[0]
    if len(faces) == 0:
        return {}
    strays = np.flatnonzero(~faces.used(n))
    if strays.shape[0] == 0:
        return {}
    lengths = faces.lengths
    owner = np.repeat(np.arange(len(faces)), lengths)
    cen = np.zeros((len(faces), 3))
    np.add.at(cen, owner, pts[faces.vertices])
    cen /= lengths[:, None]
    reach = np.zeros(len(faces))
    np.maximum.at(reach, owner, np.linalg.norm(pts[faces.vertices] - cen[owner], axis=1))
    # best-fit plane normals of the faces a ring can be (length >= 4), one
    # stacked SVD per length (the same LAPACK call per face as one by one)
    normal = np.zeros((len(faces), 3))
    for L in np.unique(lengths[lengths >= 4]).tolist():
        ids = np.flatnonzero(lengths == L)
        q = pts[faces.vertices[faces.offsets[ids][:, None] + np.arange(L)]] - cen[ids][:, None]
        normal[ids] = np.linalg.svd(q, full_matrices=False)[2][:, -1]
    tree = cKDTree(cen)
    out: dict[int, int] = {}
    for p in strays.tolist():
        _, idx = tree.query(pts[p], min(8, len(faces)))
        for fi in np.atleast_1d(idx).tolist():
            if fi in out or lengths[fi] < 4:
                continue
            off = pts[p] - cen[fi]
            across = abs(float(off @ normal[fi]))
            within = float(np.linalg.norm(off - (off @ normal[fi]) * normal[fi]))
            if within < reach[fi] and across < 2 * reach[fi]:
                out[int(fi)] = int(p)
                break
    return out


def attach_cones(
    points, triangles, *, candidates: int = 16, flips: bool = True
) -> tuple[np.ndarray, np.ndarray]:
    """Attach every sample no triangle uses, by a triangle or edge split near it.

    Parameters
    ----------
    points : (n, 3) array_like of float
        The samples.
    triangles : (t, 3) array_like of int
        The triangulated output.
    candidates : int
        How many input triangles (nearest by centroid) are searched per stray
        sample, with the triangles they have been split into since.
    flips : bool
        Follow the cones by :func:`flip_sharper` round the attached samples.

    Returns
    -------
    triangles : (t + 2s, 3) int64
        The triangles with every stray sample coned in.
    strays : (s,) int64
        The samples that were attached, in the order they were processed
        (ascending index).

    Examples
    --------
    >>> import numpy as np
    >>> from sr33 import attach_cones
    >>> p = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0.2, 0.2, 0.01]])
    >>> tri, strays = attach_cones(p, [(0, 1, 2)])
    >>> strays.tolist(), tri.shape
    ([3], (3, 3))
    """
    pts = as_points(points)
    tri = np.asarray(triangles, dtype=np.int64).reshape(-1, 3)
    if tri.shape[0] == 0:
        raise InputError("triangles is empty: there is no surface to attach samples to")
    if tri.min() < 0 or tri.max() >= pts.shape[0]:
        raise InputError("triangles index points out of range")
    used = np.zeros(pts.shape[0], dtype=bool)
    used[tri.ravel()] = True
    strays = np.flatnonzero(~used)
    if strays.shape[0] == 0:
        return tri.copy(), strays
    tris = [tuple(t) for t in tri.tolist()]
    alive = [True] * len(tris)
    origin = list(range(len(tris)))  # every triangle's ancestor in the input
    family: dict[int, set[int]] = {i: {i} for i in range(len(tris))}
    owner: dict[tuple[int, int], int] = {}
    for i, (a, b, c) in enumerate(tris):
        owner[a, b] = owner[b, c] = owner[c, a] = i
    cen0 = pts[tri].mean(axis=1)
    tree = cKDTree(cen0)
    kq = min(candidates, len(tris))
    # every triangle lies in the hull of its corners, which are its input
    # ancestor's corners or samples inserted into it: ``rad[o]`` bounds their
    # distance from ancestor o's centroid, so every triangle an insertion can
    # cross descends from an ancestor within the new triangles' span plus
    # ``rad`` of the stray: the usual ancestors are found in the tree (within
    # span plus ``small``), the few long ones (loop faces) are always tried
    rad = norm(pts[tri] - cen0[:, None]).max(axis=1)
    eps = crossing_eps(pts)
    small = 4.0 * float(np.median(rad))
    long_ones = set(np.flatnonzero(rad > small).tolist())

    def replace(old: list[int], new: list[tuple[int, int, int]], src: list[int]) -> None:
        for i in old:
            alive[i] = False
            family[origin[i]].discard(i)
            a, b, c = tris[i]
            for key in ((a, b), (b, c), (c, a)):
                if owner.get(key) == i:
                    del owner[key]
        for t, o in zip(new, src):
            j = len(tris)
            tris.append(t)
            alive.append(True)
            origin.append(o)
            family[o].add(j)
            owner[t[0], t[1]] = owner[t[1], t[2]] = owner[t[2], t[0]] = j

    for p in strays.tolist():
        _, near = tree.query(pts[p], kq)
        cand = sorted({j for o in np.atleast_1d(near).tolist() for j in family[o]})
        options = _insertions(pts, p, cand, tris, owner)
        flat, reach = _flat_and_reach(pts, p, options)
        solid = [o for o, f in zip(options, flat) if not f] or options
        span = float(reach[~flat].max() if (~flat).any() else reach.max())
        near_all = tree.query_ball_point(pts[p], span + small)
        around = sorted({j for o in list(near_all) + sorted(long_ones) for j in family[o]})
        local = np.array([tris[i] for i in around], dtype=np.int64).reshape(-1, 3)
        pick = None
        for _, old, new in solid:
            keep_i = [k for k, i in enumerate(around) if i not in old]
            patch = np.vstack([np.array(new, dtype=np.int64), local[keep_i]])
            if first_crossing(pts, patch, len(new), eps) is None:
                pick = (old, new)
                break
        if pick is None:  # every insertion crosses something: the nearest one
            pick = solid[0][1:]
        old, new = pick
        o0, o1 = origin[old[0]], origin[old[-1]]
        for o in (o0, o1):
            rad[o] = max(rad[o], float(norm(pts[p] - cen0[o])))
            if rad[o] > small:
                long_ones.add(o)
        replace(old, new, [o0] * 3 if len(old) == 1 else [o0, o0, o1, o1])
    out = np.array([t for t, ok in zip(tris, alive) if ok], dtype=np.int64)
    if flips:
        out = flip_sharper(pts, out, strays)
    return out, strays


def _flat_and_reach(pts, p: int, options) -> tuple[np.ndarray, np.ndarray]:
    """Per insertion option: whether one of its new triangles has
    (numerically) no area (its sample on an edge's line: area below 1e-9
    times the square of the option's longest edge from a first corner), and
    the farthest of its corners from sample ``p``."""
    sizes = np.array([len(o[2]) for o in options], dtype=np.int64)
    t = pts[np.array([tr for o in options for tr in o[2]], dtype=np.int64)]
    starts = np.r_[0, np.cumsum(sizes)[:-1]]
    e1, e2 = t[:, 1] - t[:, 0], t[:, 2] - t[:, 0]
    longest = np.maximum.reduceat(np.maximum(norm(e1), norm(e2)), starts)
    owner = np.repeat(np.arange(sizes.shape[0]), sizes)
    thin = norm(cross(e1, e2)) <= 1e-9 * longest[owner] * longest[owner]
    flat = np.logical_or.reduceat(thin, starts)
    reach = np.maximum.reduceat(norm(t - pts[p]).max(axis=1), starts)
    return flat, reach


def _insertions(pts, p: int, cand: list[int], tris, owner) -> list:
    """Ways to insert sample ``p``, nearest first: (distance, removed, added).

    Splitting a triangle (1 → 3) or an edge of two coherently oriented
    triangles (2 → 4, the way back to a sharp edge a bevel cut off); the
    new triangles keep the orientation of those they replace.  Ties are
    broken by kind (triangles first) and triangle index.
    """
    q = pts[p]
    corners = np.array([tris[i] for i in cand], dtype=np.int64)
    d2, _ = closest_points_on_triangles(np.repeat(q[None], len(cand), axis=0), pts[corners])
    out = []
    pairs = []
    for k, i in enumerate(cand):
        a, b, c = tris[i]
        out.append((float(d2[k]), 0, i, [i], [(a, b, p), (b, c, p), (c, a, p)]))
        for u, v in ((a, b), (b, c), (c, a)):
            j = owner.get((v, u))
            if j is None or j < i and j in cand:
                continue  # a boundary edge, or the pair was seen from j
            w = next(x for x in tris[j] if x != u and x != v)
            third = next(x for x in (a, b, c) if x != u and x != v)
            if w != third:
                pairs.append((u, v, i, j, third, w))
    if pairs:
        uv = np.array([(r[0], r[1]) for r in pairs], dtype=np.int64)
        seg = pts[uv[:, 1]] - pts[uv[:, 0]]
        t = np.clip(dot(q - pts[uv[:, 0]], seg) / np.maximum(dot(seg, seg), 1e-300), 0.0, 1.0)
        off = q - (pts[uv[:, 0]] + t[:, None] * seg)
        dist2 = dot(off, off)
        for (u, v, i, j, third, w), dd in zip(pairs, dist2.tolist()):
            out.append((dd, 1, i, [i, j], [(u, p, third), (p, v, third), (v, p, w), (p, u, w)]))
    out.sort(key=lambda r: (r[0], r[1], r[2]))
    return [(r[0], r[3], r[4]) for r in out]


def flip_sharper(points, triangles, seeds, *, rounds: int = 20) -> np.ndarray:
    """Edge flips that lower the total absolute curvature round ``seeds``.

    The cost of an edge is its length times the angle between the normals of
    its two triangles (the discrete integral of absolute mean curvature);
    minimising it straightens a smooth surface and keeps a sharp edge as one
    line of edges, where a bevel across it, with the edge's samples coned on
    as tents, pays for every tent's folds.  An edge (p, q) of triangles
    (p, q, r) and (q, p, s), with p or q near a seed, is replaced by (r, s)
    when that lowers the cost of the five edges involved by more than 1e-9
    relative, (r, s) is not already an edge, no new angle exceeds 165°, and
    neither new triangle crosses another triangle.  Edges are visited
    in a fixed order, ``rounds`` times at most: deterministic.  Used after
    :func:`attach_cones` (Section 5's cones).

    Parameters
    ----------
    points : (n, 3) float
    triangles : (t, 3) int64
    seeds : (s,) int64
        Samples round which edges may flip (the attached strays).
    rounds : int
        Most passes over the candidate edges.

    Returns
    -------
    (t, 3) int64
        The triangles after the flips (same count, same orientation).
    """
    tri = np.array(triangles, dtype=np.int64).reshape(-1, 3)
    seeds = np.asarray(seeds, dtype=np.int64)
    if tri.shape[0] < 2 or seeds.shape[0] == 0:
        return tri
    pts = np.asarray(points, dtype=np.float64)

    def ring(mask):  # the samples of the triangles with a sample in ``mask``
        out = mask.copy()
        out[tri[np.any(mask[tri], axis=1)].ravel()] = True
        return out

    near = np.zeros(pts.shape[0], dtype=bool)
    near[seeds] = True
    near = ring(ring(near))  # two rings round the seeds
    # the triangles a flip can read: those with a sample next to a near one
    # (a flip joins two neighbours of a near sample, so every neighbour of a
    # near sample stays in this zone; the crossing test reads all triangles)
    zone = ring(near)
    zone_tri = np.flatnonzero(np.any(zone[tri], axis=1))
    owner: dict[tuple[int, int], int] = {}
    for i, (a, b, c) in zip(zone_tri.tolist(), tri[zone_tri].tolist()):
        owner[a, b] = owner[b, c] = owner[c, a] = i
    # only edges of two coherently oriented triangles flip: an overloaded or
    # inconsistently oriented edge (a failed selection) keeps its triangles
    # (every triangle with an edge of the zone is in the zone)
    keys, counts = unique_rows(np.sort(half_edges(tri[zone_tri])[0], axis=1), return_counts=True)
    manifold = {tuple(k) for k in keys[counts == 2].tolist()}
    near[np.unique(keys[counts != 2])] = False
    limit = np.radians(165.0)
    eps = crossing_eps(pts)

    def across(a, b):
        k = owner.get((b, a))
        return None if k is None else tri[k]

    for _ in range(rounds):
        cen = pts[tri].mean(axis=1)
        tree = cKDTree(cen)
        radius = float(norm(pts[tri] - cen[:, None]).max())  # no crossing triangle is missed
        edges = sorted({(min(a, b), max(a, b)) for (a, b) in owner if near[a] or near[b]})
        flipped = 0
        for p, q in edges:
            i, j = owner.get((p, q)), owner.get((q, p))
            if i is None or j is None or i == j or (p, q) not in manifold:
                continue
            r = int(next(v for v in tri[i] if v != p and v != q))
            s_ = int(next(v for v in tri[j] if v != p and v != q))
            if r == s_ or (r, s_) in owner or (s_, r) in owner:
                continue
            outer = [(q, r), (r, p), (p, s_), (s_, q)]
            nb = [across(a, b) for a, b in outer]
            if any(t is None for t in nb):
                continue
            t1, t2 = tri[i], tri[j]
            new1 = np.array([r, p, s_])
            new2 = np.array([s_, q, r])
            before, after, largest = flip_costs(
                pts, t1, t2, np.array([p, q, r, s_], dtype=np.int64), np.array(nb, dtype=np.int64)
            )
            if after >= (1 - 1e-9) * before or largest > limit:
                continue
            new = np.stack([new1, new2])
            mid = pts[new].mean(axis=(0, 1))
            ext = float(norm(pts[new.ravel()] - mid).max())
            local = [k for k in tree.query_ball_point(mid, ext + radius) if k != i and k != j]
            patch = np.vstack([new, tri[local]]) if local else new
            if first_crossing(pts, patch, 2, eps) is not None:
                continue
            for key in ((p, q), (q, r), (r, p), (q, p), (p, s_), (s_, q)):
                owner.pop(key, None)
            tri[i], tri[j] = new1, new2
            owner[r, p] = owner[p, s_] = owner[s_, r] = i
            owner[s_, q] = owner[q, r] = owner[r, s_] = j
            manifold.discard((p, q))
            manifold.add((min(r, s_), max(r, s_)))
            flipped += 1
        if not flipped:
            break
    return tri
