"""Stray samples inserted into the face they lie over (end of Section 5).

Theorem 5 leaves stray samples, and the paper attaches them with cones.  A
cone over one triangle is right for a sample near the surface, but not for
a whole cluster of strays standing far off a face: the apex of a slender
cone (a 28 degree tip) whose inner rings the Euclidean RNG leaves without
face cycles, above the ring of samples that the selection closes with one
face, or leaves open.  Coned into that face's flat triangles they make
tents far from the surface (or the ring stays open, its cap uncovered).
Here such a face is re-triangulated *with* the strays it rings round, so
that the surface passes through every one of them and the face's interior
becomes the patch of surface the strays sample.

A cluster of strays is a connected component of the RNG restricted to the
samples no face uses.  It belongs to a face when every sample the cluster's
RNG edges reach outside it lies on that face's cycle (the cluster sits
inside the ring), or to the faces whose samples it reaches all of, when
those faces make one polygon with every sample on its boundary and the
boundary holds every sample the cluster reaches (the ring closed by several
faces).  A cluster reaching samples of faces round an edge sits across the
edge, and the cones handle it.  The host's boundary and its clusters are
mapped to the boundary's best-fit plane (the chart).  The patch is made when:

* the cycle maps to a simple polygon and every stray maps strictly inside
  it (at least 1e-6 of the polygon's size from its sides): the patch is a
  graph over the chart, so its triangles do not cross one another;
* the Delaunay triangulation of the mapped samples keeps every side of the
  polygon as an edge, and the triangles inside the polygon are exactly
  ``L - 2 + 2 s`` (``s`` strays): a disk bounded by the cycle;
* no chord of the patch between two samples of the cycle is an edge of
  another face (it would be used three times).

The caller checks that the patch crosses no other triangle
(:func:`sr33.reconstruct.reconstruct`).  The Delaunay triangulation is
:func:`sr33.mesh.delaunay_triangles` of the mapped samples in a fixed order
(the cycle's, then the strays ascending): ties among cocircular mapped
samples (a cone's rings map to concentric circles, their cells to isosceles
trapezoids) are split by that order, not by the coordinates' last bits.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import sparse
from scipy.sparse import csgraph
from scipy.spatial import QhullError

from .cycles import CycleSet
from .graph import cycle_edges
from .mesh import delaunay_triangles, edge_keys, half_edges, unique_edges


@dataclass(frozen=True)
class Patch:
    """A face re-triangulated with the stray samples it rings round.

    Attributes
    ----------
    interior : (s,) int64
        The strays inside it, ascending.
    triangles : (L - 2 + 2s, 3) int64
        Its triangles, oriented alike (counter-clockwise in the chart); the
        caller orients them with the face.  For a patch over several faces
        (boundary of length L) the first face carries them, and the others
        have none (and no interior).
    """

    interior: np.ndarray
    triangles: np.ndarray


def stray_clusters(n: int, used: np.ndarray, edges: np.ndarray) -> tuple[list[np.ndarray], list]:
    """The clusters of stray samples and the used samples each one reaches.

    Parameters
    ----------
    n : int
        Number of samples.
    used : (n,) bool
        Whether some face uses the sample.
    edges : (m, 2) int64
        The localized RNG.

    Returns
    -------
    clusters : list of (s,) int64
        Connected components of the RNG restricted to the unused samples,
        each ascending, ordered by their smallest sample.
    reach : list of (r,) int64
        For every cluster, the used samples its RNG edges reach, ascending.
    """
    e = np.asarray(edges, dtype=np.int64).reshape(-1, 2)
    strays = np.flatnonzero(~used)
    if strays.shape[0] == 0:
        return [], []
    both = ~used[e[:, 0]] & ~used[e[:, 1]]
    g = sparse.csr_matrix(
        (np.ones(int(both.sum()), np.int8), (e[both, 0], e[both, 1])), shape=(n, n)
    )
    _, lab = csgraph.connected_components(g, directed=False)
    one = ~used[e[:, 0]] ^ ~used[e[:, 1]]
    stray_end = np.where(used[e[one, 0]], e[one, 1], e[one, 0])
    used_end = np.where(used[e[one, 0]], e[one, 0], e[one, 1])
    labels, first = np.unique(lab[strays], return_index=True)
    clusters, reach = [], []
    for lb in labels[np.argsort(strays[first], kind="stable")].tolist():
        clusters.append(strays[lab[strays] == lb])
        reach.append(np.unique(used_end[lab[stray_end] == lb]))
    return clusters, reach


def _segments_cross(p, q) -> bool:
    """Whether two sides of the closed polygon ``p`` (k, 2) that share no
    corner cross (``q`` is ``p`` rolled by one)."""
    k = p.shape[0]
    d = q - p
    for i in range(k):
        j = np.arange(i + 2, k - (i == 0))
        if j.shape[0] == 0:
            continue
        a, b = p[i], d[i]
        c, e = p[j], d[j]
        den = b[0] * e[:, 1] - b[1] * e[:, 0]
        ca = c - a
        with np.errstate(divide="ignore", invalid="ignore"):
            s = (ca[:, 0] * e[:, 1] - ca[:, 1] * e[:, 0]) / den
            t = (ca[:, 0] * b[1] - ca[:, 1] * b[0]) / den
        if np.any((den != 0) & (s >= 0) & (s <= 1) & (t >= 0) & (t <= 1)):
            return True
    return False


def _inside(poly, x, margin: float) -> np.ndarray:
    """Which points ``x`` lie inside the simple polygon ``poly`` (winding
    number) and farther than ``margin`` from all of its sides."""
    a = poly
    b = np.roll(poly, -1, axis=0)
    d = b - a
    rel = x[:, None, :] - a[None]
    t = np.clip((rel * d).sum(-1) / np.maximum((d * d).sum(-1), 1e-300), 0.0, 1.0)
    off = rel - t[..., None] * d
    far = np.sqrt((off * off).sum(-1)).min(axis=1) > margin
    side = d[None, :, 0] * rel[..., 1] - d[None, :, 1] * rel[..., 0]
    up = (a[None, :, 1] <= x[:, None, 1]) & (b[None, :, 1] > x[:, None, 1]) & (side > 0)
    down = (a[None, :, 1] > x[:, None, 1]) & (b[None, :, 1] <= x[:, None, 1]) & (side < 0)
    winding = up.sum(axis=1) - down.sum(axis=1)
    return far & (winding != 0)


def chart_patch(points, cycle, interior) -> np.ndarray | None:
    """The triangulation of a cycle with samples inside it, in its chart.

    Parameters
    ----------
    points : (n, 3) float64
        The samples.
    cycle : (L,) int64
        The face's cycle.
    interior : (s,) int64
        The samples inside it.

    Returns
    -------
    (L - 2 + 2s, 3) int64 or None
        The triangles, counter-clockwise in the chart, or None when one of
        the module's conditions on the chart fails.
    """
    cyc = np.asarray(cycle, dtype=np.int64)
    ins = np.asarray(interior, dtype=np.int64)
    L, s = cyc.shape[0], ins.shape[0]
    ring = points[cyc]
    centre = ring.mean(axis=0)
    basis = np.linalg.svd(ring - centre, full_matrices=False)[2]
    poly = (ring - centre) @ basis[:2].T
    size = float(np.ptp(poly, axis=0).max())
    nxt = np.roll(poly, -1, axis=0)
    area2 = float(np.sum(poly[:, 0] * nxt[:, 1] - nxt[:, 0] * poly[:, 1]))
    if size <= 0 or abs(area2) <= 1e-9 * size * size:
        return None
    if _segments_cross(poly, nxt):
        return None
    flat = (points[ins] - centre) @ basis[:2].T
    if not _inside(poly, flat, 1e-6 * size).all():
        return None
    allp = np.vstack([poly, flat])
    side = float(np.mean(np.linalg.norm(nxt - poly, axis=1)))
    try:
        simp = delaunay_triangles(allp, side)
    except QhullError:
        return None
    cen = allp[simp].mean(axis=1)
    simp = simp[_inside(poly, cen, 0.0)]
    if simp.shape[0] != L - 2 + 2 * s:
        return None
    # the kept triangles' boundary is exactly the polygon's sides
    keys, counts = unique_edges(half_edges(simp)[0], return_counts=True)
    sides = np.arange(L)
    if not np.array_equal(keys[counts == 1], unique_edges(np.c_[sides, (sides + 1) % L])):
        return None
    return np.concatenate([cyc, ins])[simp]  # counter-clockwise in the chart


def _boundary_cycle(faces: CycleSet, ids: list[int]) -> np.ndarray | None:
    """The boundary of the faces ``ids`` as one simple cycle, when their
    union is a polygon bounded by it with no sample inside (every sample of
    the faces on the boundary, every boundary sample on two boundary edges,
    one loop); None otherwise."""
    sub = faces.subset(np.asarray(ids, dtype=np.int64))
    pairs, _ = cycle_edges(sub.offsets, sub.vertices)
    und = np.sort(pairs, axis=1)
    keys, counts = np.unique(und, axis=0, return_counts=True)
    if counts.max() > 2:
        return None
    rim = keys[counts == 1]
    verts = np.unique(sub.vertices)
    if (
        rim.shape[0] < 3
        or np.unique(rim).shape[0] != rim.shape[0]
        or verts.shape[0] != rim.shape[0]
    ):
        return None
    nbr: dict[int, list[int]] = {}
    for a, b in rim.tolist():
        nbr.setdefault(a, []).append(b)
        nbr.setdefault(b, []).append(a)
    if any(len(v) != 2 for v in nbr.values()):
        return None
    start = int(rim.min())
    cyc, prev, cur = [start], -1, start
    while True:
        a, b = nbr[cur]
        nxt = b if a == prev else a
        if nxt == start:
            break
        cyc.append(nxt)
        prev, cur = cur, nxt
    if len(cyc) != rim.shape[0]:
        return None  # several loops: not a disk
    return np.array(cyc, dtype=np.int64)


def stray_patches(
    points,
    faces: CycleSet,
    edges,
    *,
    skip_faces=(),
    min_interior: int = 1,
) -> dict[int, Patch]:
    """The faces to re-triangulate with the stray clusters over them.

    A cluster's host is a face whose cycle holds every sample the cluster
    reaches (the strays stand inside one ring), else the faces whose samples
    the cluster reaches all of, when they make one polygon whose boundary
    holds them all (a ring closed by several faces: a quad, a triangle and
    a hexagon across a cone's ring, the strays above).  The host's boundary
    is triangulated with the strays (:func:`chart_patch`).

    Parameters
    ----------
    points : (n, 3) float64
        The samples.
    faces : CycleSet
        The face cycles.
    edges : (m, 2) int64
        The localized RNG (Algorithm 2).
    skip_faces : iterable of int
        Faces not to patch (whose patch crossed another triangle).
    min_interior : int
        Fewest strays a host must have to be patched (a face round one
        stray is left to :func:`sr33.cones.ring_centres`).

    Returns
    -------
    dict of int to Patch
        Face index -> its patch.  A patch over several faces is given to
        the first of them with an edge on the boundary; the others map to a
        patch with no triangles (they are replaced by the first's).
    """
    pts = np.asarray(points, dtype=np.float64)
    n = pts.shape[0]
    if len(faces) == 0:
        return {}
    clusters, reach = stray_clusters(n, faces.used(n), edges)
    if not clusters:
        return {}
    skip = set(int(f) for f in skip_faces)
    # faces through every sample: (sample, face) rows sorted by sample
    owner = np.repeat(np.arange(len(faces)), faces.lengths)
    order = np.lexsort((owner, faces.vertices))
    fv, fo = faces.vertices[order], owner[order]
    starts = np.searchsorted(fv, np.arange(n + 1))
    pairs, pair_owner = cycle_edges(faces.offsets, faces.vertices)
    face_keys = edge_keys(pairs[:, 0], pairs[:, 1], n)
    # host (the faces a patch replaces) -> its clusters
    hosts: dict[tuple[int, ...], list[int]] = {}
    for ci, r in enumerate(reach):
        if r.shape[0] == 0:
            continue  # a cluster reaching no used sample: the cones place it
        rl = r.tolist()
        common = None
        for v in rl:
            here = set(fo[starts[v] : starts[v + 1]].tolist())
            common = here if common is None else common & here
            if not common:
                break
        single = [(f,) for f in sorted(common or ()) if f not in skip]
        if single:
            for key in single:
                hosts.setdefault(key, []).append(ci)
            continue
        # faces with every sample among those the cluster reaches
        near = sorted(
            set(fo[np.concatenate([np.arange(starts[v], starts[v + 1]) for v in rl])].tolist())
        )
        inside_r = [f for f in near if np.isin(faces.cycle(f), r).all()]
        if len(inside_r) >= 2 and not skip.intersection(inside_r):
            hosts.setdefault(tuple(inside_r), []).append(ci)
    chords: list[np.ndarray] = []
    taken: set[int] = set()
    replaced: set[int] = set()
    out: dict[int, Patch] = {}
    for host in sorted(hosts, key=lambda k: (min(hosts[k]), k)):
        if replaced.intersection(host):
            continue
        cis = [ci for ci in hosts[host] if ci not in taken]
        if not cis:
            continue
        ins = np.sort(np.concatenate([clusters[ci] for ci in cis]))
        if ins.shape[0] < min_interior:
            continue
        cyc = faces.cycle(host[0]) if len(host) == 1 else _boundary_cycle(faces, list(host))
        if (
            cyc is None
            or not np.isin(np.unique(np.concatenate([reach[ci] for ci in cis])), cyc).all()
        ):
            continue
        tri = chart_patch(pts, cyc, ins)
        if tri is None:
            continue
        # chords between two boundary samples must not be an edge of a face
        # outside the host (it would be used three times), nor another patch's
        on = np.isin(tri, cyc)
        tk = np.concatenate([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]])
        chord = np.concatenate([on[:, [0, 1]], on[:, [1, 2]], on[:, [2, 0]]]).all(axis=1)
        mine = edge_keys(cyc, np.roll(cyc, -1), n)
        ck = np.setdiff1d(edge_keys(tk[chord, 0], tk[chord, 1], n), mine)
        outside = face_keys[~np.isin(pair_owner, host)]
        if np.isin(ck, np.concatenate([outside, *chords])).any():
            continue
        chords.append(ck)
        taken.update(cis)
        replaced.update(host)
        # the patch goes to the first face with an edge on the boundary (its
        # orientation orients the patch); the others give up their triangles
        first = next(
            f
            for f in host
            if np.isin(edge_keys(faces.cycle(f), np.roll(faces.cycle(f), -1), n), mine).any()
        )
        for f in host:
            out[f] = Patch(
                interior=ins if f == first else np.empty(0, np.int64),
                triangles=tri if f == first else np.empty((0, 3), np.int64),
            )
    return out
