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
inside the ring; a cluster reaching two faces' samples sits across an edge,
and the cones handle it).  The face's samples and its clusters are mapped
to the face's best-fit plane (the chart).  The patch is made when:

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
from .mesh import delaunay_triangles, edge_keys


@dataclass(frozen=True)
class Patch:
    """A face re-triangulated with the stray samples it rings round.

    Attributes
    ----------
    face : int
        The face's index.
    interior : (s,) int64
        The strays inside it, ascending.
    triangles : (L - 2 + 2s, 3) int64
        Its triangles, oriented alike (counter-clockwise in the chart); the
        caller orients them with the face.
    """

    face: int
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
    # every side of the polygon is an edge of exactly one kept triangle
    m = L + s
    tk = np.concatenate([simp[:, [0, 1]], simp[:, [1, 2]], simp[:, [2, 0]]])
    keys, counts = np.unique(edge_keys(tk.min(axis=1), tk.max(axis=1), m), return_counts=True)
    sides = np.arange(L)
    side_keys = edge_keys(np.minimum(sides, (sides + 1) % L), np.maximum(sides, (sides + 1) % L), m)
    pos = np.searchsorted(keys, side_keys)
    pos = np.minimum(pos, keys.shape[0] - 1)
    if not (np.array_equal(keys[pos], side_keys) and np.all(counts[pos] == 1)):
        return None
    return np.concatenate([cyc, ins])[simp]  # counter-clockwise in the chart


def stray_patches(
    points,
    faces: CycleSet,
    edges,
    *,
    skip_faces=(),
    min_interior: int = 1,
) -> dict[int, Patch]:
    """The faces to re-triangulate with the stray clusters inside them.

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
        Fewest strays a face must ring round to be patched (a face round
        one stray is left to :func:`sr33.cones.ring_centres`).

    Returns
    -------
    dict of int to Patch
        Face index -> its patch, for the faces whose conditions (module
        docstring) hold.
    """
    pts = np.asarray(points, dtype=np.float64)
    n = pts.shape[0]
    if len(faces) == 0:
        return {}
    used = np.zeros(n, dtype=bool)
    used[faces.vertices] = True
    clusters, reach = stray_clusters(n, used, edges)
    if not clusters:
        return {}
    skip = set(int(f) for f in skip_faces)
    # faces through every sample: (sample, face) rows sorted by sample
    owner = np.repeat(np.arange(len(faces)), faces.lengths)
    order = np.lexsort((owner, faces.vertices))
    fv, fo = faces.vertices[order], owner[order]
    starts = np.searchsorted(fv, np.arange(n + 1))
    hosts: dict[int, list[int]] = {}
    for ci, r in enumerate(reach):
        if r.shape[0] == 0:
            continue
        common = None
        for v in r.tolist():
            here = set(fo[starts[v] : starts[v + 1]].tolist())
            common = here if common is None else common & here
            if not common:
                break
        for f in sorted(common or ()):
            if f not in skip:
                hosts.setdefault(f, []).append(ci)
    pairs, _ = cycle_edges(faces.offsets, faces.vertices)
    face_keys = edge_keys(pairs.min(axis=1), pairs.max(axis=1), n)
    chords: list[np.ndarray] = []
    taken: set[int] = set()
    out: dict[int, Patch] = {}
    for f in sorted(hosts):
        cis = [ci for ci in hosts[f] if ci not in taken]
        if not cis:
            continue
        ins = np.sort(np.concatenate([clusters[ci] for ci in cis]))
        if ins.shape[0] < min_interior:
            continue
        cyc = faces.cycle(f)
        tri = chart_patch(pts, cyc, ins)
        if tri is None:
            continue
        # chords between two cycle samples must not be another face's edge
        on = np.isin(tri, cyc)
        tk = np.concatenate([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]])
        chord = np.concatenate([on[:, [0, 1]], on[:, [1, 2]], on[:, [2, 0]]]).all(axis=1)
        ck = edge_keys(tk[chord].min(axis=1), tk[chord].max(axis=1), n)
        mine = edge_keys(np.minimum(cyc, np.roll(cyc, -1)), np.maximum(cyc, np.roll(cyc, -1)), n)
        if np.isin(np.setdiff1d(ck, mine), np.concatenate([face_keys, *chords])).any():
            continue
        chords.append(np.setdiff1d(ck, mine))
        taken.update(cis)
        out[f] = Patch(face=int(f), interior=ins, triangles=tri)
    return out
