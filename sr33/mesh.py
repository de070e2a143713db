"""Mesh primitives shared by every layer of sr33: the one implementation of each.

The reconstruction, the validators, the samplers and the inspector all count
edges, link faces across shared edges, orient them, test triangles for
intersection, find closest points and measure the Condition III-ii ratio;
they do it here.  Plain numpy and scipy; arrays in, arrays out (points
``(n, 3)`` or ``(n, 2)`` float64, indices int64).

* :func:`unique_rows`, :func:`edge_keys`, :func:`unique_edges`: grouping by
  one int64 key per row (a 1-D sort instead of a lexicographic one).
* :func:`half_edges`, :func:`edge_incidence`, :class:`EdgeIncidence`,
  :func:`edge_uses`: every face's directed edges grouped by undirected edge
  (use counts, the faces two uses link, whether they agree in direction).
* :func:`orientation_double_cover`: orientability and coherent orientation.
* :func:`self_intersections`: pairs of triangles whose interiors meet.
* :func:`closest_points_on_triangles`: Ericson's region test, vectorized.
* :func:`triangle_ratios` and ``SQRT3_2``: Condition III-ii of the paper.
* :func:`dot`, :func:`norm`: products whose bits do not depend on the machine.
* :func:`surface_points`: area-uniform points on a triangle mesh.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import sparse
from scipy.sparse import csgraph
from scipy.spatial import ConvexHull, QhullError

from sr33 import libm

from . import _edges, _intersect

SQRT3_2 = float(np.sqrt(3.0) / 2.0)  # Condition III-ii: shorter edges below this times the longest


def dot(a, b) -> np.ndarray:
    """Dot products along the last axis, the same bits on every machine.

    ``a @ b`` and ``np.linalg.norm(v)`` call BLAS, whose kernels (chosen by
    the CPU: FMA or not, SIMD width) sum in different orders, so their last
    bits differ between machines; an iterative layout or a tie amplifies
    that into a different result.  Here every product is rounded on its own
    and summed by numpy's own reduction, whose order is fixed by the array's
    length, not by the CPU (no BLAS).

    Examples
    --------
    >>> float(dot([1.0, 2.0, 3.0], [4.0, 5.0, 6.0]))
    32.0
    >>> dot([[1.0, 0.0], [0.0, 2.0]], [3.0, 4.0]).tolist()
    [3.0, 8.0]
    """
    return (np.asarray(a, dtype=np.float64) * np.asarray(b, dtype=np.float64)).sum(axis=-1)


def norm(v) -> np.ndarray:
    """Euclidean length along the last axis, by :func:`dot` (no BLAS)."""
    return np.sqrt(dot(v, v))


def cross(a, b) -> np.ndarray:
    """Cross products of 3-vectors along the last axis (``np.cross`` without
    its axis handling, which dominates on small arrays; the same bits)."""
    a = np.asarray(a, dtype=np.float64)
    b = np.asarray(b, dtype=np.float64)
    ax, ay, az = a[..., 0], a[..., 1], a[..., 2]
    bx, by, bz = b[..., 0], b[..., 1], b[..., 2]
    return np.stack([ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx], axis=-1)


def edge_keys(a, b, n: int) -> np.ndarray:
    """Order-free int64 key ``min * n + max`` of the undirected edges (a, b)."""
    a, b = np.asarray(a, dtype=np.int64), np.asarray(b, dtype=np.int64)
    return np.minimum(a, b) * int(n) + np.maximum(a, b)


def unique_rows(a, return_counts: bool = False):
    """``np.unique(a, axis=0)`` for rows of non-negative ints (same rows, same order).

    One int64 key per row makes it a 1-D sort; rows too wide for one key fall
    back to numpy's lexicographic sort.

    Examples
    --------
    >>> unique_rows([[2, 1], [0, 3], [2, 1]], return_counts=True)
    (array([[0, 3],
           [2, 1]]), array([1, 2]))
    """
    a = np.asarray(a, dtype=np.int64)
    if a.ndim != 2:
        raise ValueError(f"rows must be a 2-D array, got shape {a.shape}")
    base = int(a.max()) + 1 if a.size else 1
    if a.shape[1] == 0 or float(base) ** a.shape[1] >= 2.0**62:
        return np.unique(a, axis=0, return_counts=return_counts)
    key = np.zeros(a.shape[0], dtype=np.int64)
    for col in range(a.shape[1]):
        key = key * base + a[:, col]
    _, first, counts = np.unique(key, return_index=True, return_counts=True)
    return (a[first], counts) if return_counts else a[first]


def unique_edges(pairs, return_counts: bool = False):
    """Distinct undirected edges (sorted rows, sorted order) of vertex pairs."""
    p = np.asarray(pairs, dtype=np.int64).reshape(-1, 2)
    return unique_rows(np.sort(p, axis=1), return_counts=return_counts)


def half_edges(triangles) -> tuple[np.ndarray, np.ndarray]:
    """The directed edges of triangles and the triangle of each.

    Row ``3 f + j`` is the edge ``(t[f, j], t[f, (j + 1) % 3])``, so that
    ``values.reshape(-1, 3)`` gives per-triangle answers in local edge order.
    """
    t = as_triangles(triangles)
    pairs = np.stack([t.ravel(), np.roll(t, -1, axis=1).ravel()], axis=1)
    return pairs, np.repeat(np.arange(t.shape[0], dtype=np.int64), 3)


@dataclass(frozen=True)
class EdgeIncidence:
    """Directed edges of faces grouped by their undirected edge.

    Attributes
    ----------
    edges : (e, 2) int64
        The distinct undirected edges, sorted rows in sorted order.
    counts : (e,) int64
        How many directed edges (face sides) use each.
    edge_of : (h,) int64
        The edge (row of ``edges``) of every directed edge.
    face : (h,) int64
        The face of every directed edge.
    forward : (h,) bool
        Whether a directed edge runs from the smaller vertex to the larger.
    order : (h,) int64
        The directed edges sorted by edge (stable): the uses of edge i are
        ``order[start[i]:start[i] + counts[i]]``.
    start : (e,) int64
        Where each edge's uses begin in ``order``.
    """

    edges: np.ndarray
    counts: np.ndarray
    edge_of: np.ndarray
    face: np.ndarray
    forward: np.ndarray
    order: np.ndarray
    start: np.ndarray

    def shared(self, uses: int | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Consecutive uses of every edge used more than once: (edge, first
        use, second use), an edge of k uses giving k - 1 pairs; with ``uses``,
        only edges of exactly that many uses."""
        used = np.repeat(self.counts, self.counts)[:-1] if self.order.size else self.counts[:0]
        same = np.flatnonzero(self.edge_of[self.order[1:]] == self.edge_of[self.order[:-1]])
        if uses is not None:
            same = same[used[same] == uses]
        a, b = self.order[same], self.order[same + 1]
        return self.edge_of[a], a, b

    def manifold_pairs(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Edges used exactly twice: (edge, face a, face b, coherent), where
        coherent means the two faces traverse the edge in opposite directions."""
        e, a, b = self.shared(uses=2)
        return e, self.face[a], self.face[b], self.forward[a] != self.forward[b]


def edge_incidence(pairs, face, n: int | None = None) -> EdgeIncidence:
    """Group directed edges (``pairs[i]`` a side of face ``face[i]``) by edge.

    Parameters
    ----------
    pairs : (h, 2) array_like of int
        Directed edges.
    face : (h,) array_like of int
        The face each belongs to.
    n : int, optional
        Number of vertices (defaults to the largest index + 1).

    Returns
    -------
    EdgeIncidence

    Examples
    --------
    >>> inc = edge_incidence(*half_edges([(0, 1, 2), (0, 2, 3)]))
    >>> inc.edges.tolist(), inc.counts.tolist()
    ([[0, 1], [0, 2], [0, 3], [1, 2], [2, 3]], [1, 2, 1, 1, 1])
    >>> [x.tolist() for x in inc.manifold_pairs()]
    [[1], [0], [1], [True]]
    """
    p = np.asarray(pairs, dtype=np.int64).reshape(-1, 2)
    f = np.asarray(face, dtype=np.int64)
    n = int(p.max()) + 1 if n is None and p.size else int(n or 0)
    n = max(n, 1)
    lo = np.minimum(p[:, 0], p[:, 1])
    hi = np.maximum(p[:, 0], p[:, 1])
    if p.size and (lo.min() < 0 or hi.max() >= n):
        raise ValueError(f"edge_incidence: vertex indices must lie in [0, {n})")
    # the stable order of the keys min * n + max, in linear time
    order, edge_of, start = _edges.group_sides(lo, hi, n)
    return EdgeIncidence(
        edges=np.stack([lo[order[start]], hi[order[start]]], axis=1).reshape(-1, 2),
        counts=np.diff(np.r_[start, p.shape[0]]).astype(np.int64),
        edge_of=edge_of,
        face=f,
        forward=p[:, 0] < p[:, 1],
        order=order,
        start=start.astype(np.int64),
    )


def as_triangles(triangles) -> np.ndarray:
    """Triangles as a ``(t, 3)`` int64 array (an empty input gives ``(0, 3)``)."""
    tri = np.asarray(triangles)
    if tri.size == 0:
        return np.empty((0, 3), dtype=np.int64)
    if tri.ndim != 2 or tri.shape[1] != 3:
        raise ValueError(f"triangles must have shape (t, 3), got {tri.shape}")
    if not np.issubdtype(tri.dtype, np.integer):
        raise ValueError(f"triangles must be integer indices, got dtype {tri.dtype}")
    if tri.min() < 0:
        raise ValueError("triangles contain negative vertex indices")
    return tri.astype(np.int64)


def as_coordinates(values, name: str = "points", item: str = "point") -> np.ndarray:
    """``values`` as a float64 ``(n, 3)`` array of finite coordinates, or one
    :class:`ValueError` naming ``name``, the rule and the first offender
    (the one check of coordinates: points, vertices, truths).

    Examples
    --------
    >>> as_coordinates([[0, 0], [1, 2]], "p")
    Traceback (most recent call last):
    ...
    ValueError: p must have shape (n, 3), got (2, 2)
    """
    try:
        v = np.asarray(values, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{name} must be numeric, could not convert: {exc}") from None
    if v.ndim != 2 or v.shape[1] != 3:
        raise ValueError(f"{name} must have shape (n, 3), got {v.shape}")
    bad = ~np.isfinite(v).all(axis=1)
    if bad.any():
        first = int(np.flatnonzero(bad)[0])
        plural = {"vertex": "vertices"}.get(item, item + "s")
        raise ValueError(
            f"{name}: {int(bad.sum())} of {v.shape[0]} {plural} have non-finite (NaN or inf) "
            f"coordinates, first {item} {first} = {v[first].tolist()}"
        )
    return v


def as_mesh(
    vertices, triangles, name: str = "mesh", item: str = "vertex"
) -> tuple[np.ndarray, np.ndarray]:
    """A mesh's ``(vertices, triangles)`` checked: float64 ``(n, 3)`` finite
    vertices and int64 ``(t, 3)`` indices within ``0..n-1``.

    Every mesh given to sr33 (a file read, a validator's argument) passes
    here, so that a NaN or inf vertex or an index out of range is one
    :class:`ValueError` naming the first offender, never a crash further on.

    Examples
    --------
    >>> as_mesh([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 3]])
    Traceback (most recent call last):
    ...
    ValueError: mesh: triangle 0 uses vertex 3, out of range 0..2
    """
    v = as_coordinates(vertices, name, item)
    tri = np.asarray(triangles)
    if tri.size and not np.issubdtype(tri.dtype, np.integer):
        raise ValueError(f"{name}: triangles must be integer indices, got dtype {tri.dtype}")
    if tri.size == 0:
        tri = np.empty((0, 3), dtype=np.int64)
    elif tri.ndim != 2 or tri.shape[1] != 3:
        raise ValueError(f"{name}: triangles must have shape (t, 3), got {tri.shape}")
    tri = tri.astype(np.int64)
    out = (tri < 0) | (tri >= v.shape[0])
    if out.any():
        row = int(np.flatnonzero(out.any(axis=1))[0])
        idx = int(tri[row][out[row]][0])
        raise ValueError(
            f"{name}: triangle {row} uses vertex {idx}, out of range 0..{v.shape[0] - 1}"
        )
    return np.ascontiguousarray(v), np.ascontiguousarray(tri)


def edge_uses(triangles) -> tuple[np.ndarray, np.ndarray]:
    """Distinct undirected edges of triangles (sorted rows) and how many triangles use each.

    Examples
    --------
    >>> e, c = edge_uses([(0, 1, 2), (0, 2, 3)])
    >>> e[c == 2].tolist()
    [[0, 2]]
    """
    tri = as_triangles(triangles)
    if tri.shape[0] == 0:
        return np.empty((0, 2), dtype=np.int64), np.empty(0, dtype=np.int64)
    return unique_edges(half_edges(tri)[0], return_counts=True)


def orientation_double_cover(n: int, fa, fb, coherent) -> np.ndarray:
    """Component labels of the orientation double cover of ``n`` faces.

    Face f has nodes f ("as stored") and f + n ("flipped").  Faces ``fa[i]``
    and ``fb[i]`` share a manifold edge; when they traverse it coherently the
    cover joins (fa, fb) and (fa + n, fb + n), otherwise (fa, fb + n) and
    (fa + n, fb).  A face is on a non-orientable component exactly when its
    two nodes share a label; on an orientable one, faces whose "as stored"
    node shares the label of a reference face's need no flip relative to it.

    Examples
    --------
    >>> lab = orientation_double_cover(2, [0], [1], [False])
    >>> bool(lab[0] == lab[1 + 2])  # face 1 must flip to agree with face 0
    True
    """
    fa, fb = np.asarray(fa, dtype=np.int64), np.asarray(fb, dtype=np.int64)
    coherent = np.asarray(coherent, dtype=bool)
    rows = np.concatenate([fa, fa + n])
    cols = np.concatenate([np.where(coherent, fb, fb + n), np.where(coherent, fb + n, fb)])
    dc = sparse.csr_matrix(
        (np.ones(rows.shape[0], dtype=np.int8), (rows, cols)), shape=(2 * n, 2 * n)
    )
    _, labels = csgraph.connected_components(dc, directed=False)
    return labels


def triangle_ratios(points, triangles) -> np.ndarray:
    """Per triangle, its second-longest edge over its longest.

    Condition III-ii of the paper asks every intrinsic Delaunay triangle for
    a ratio below ``SQRT3_2`` (both shorter edges below √3/2 of the
    longest); a square lattice's right isosceles triangles have 1/√2.
    Works on 2-D and 3-D points.

    Examples
    --------
    >>> round(float(triangle_ratios([[0, 0], [1, 0], [0, 1]], [(0, 1, 2)])[0]), 4)
    0.7071
    """
    p = np.asarray(points, dtype=np.float64)[as_triangles(triangles)]
    length = np.sort(np.sqrt(((p - p[:, [1, 2, 0]]) ** 2).sum(axis=2)), axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        return length[:, 1] / length[:, 2]


#: ties of :func:`delaunay_triangles` within this power distance (times the
#: squared scale) are broken by the points' indices
TIE_SLACK = 1e-6


def _index_weights(n: int) -> np.ndarray:
    """n numbers in [0, 1) that no linear relation among indices makes equal
    (splitmix64 of the index): the tie-breaking weights of
    :func:`delaunay_triangles`.  A linear rule (frac(i phi)) would not do: a
    row-major lattice cell's corners i, i + m + 1 and i + 1, i + m have
    equal sums."""
    z = np.arange(n, dtype=np.uint64) + np.uint64(0x9E3779B97F4A7C15)
    z = (z ^ (z >> np.uint64(30))) * np.uint64(0xBF58476D1CE4E5B9)
    z = (z ^ (z >> np.uint64(27))) * np.uint64(0x94D049BB133111EB)
    z = z ^ (z >> np.uint64(31))
    return (z >> np.uint64(11)).astype(np.float64) / 2.0**53


def delaunay_triangles(points, scale: float | None = None, *, slack: float = TIE_SLACK):
    """Delaunay triangles of 2-D points, ties broken by a fixed rule.

    A lattice's cells (rectangles; isosceles trapezoids between rings) have
    their four corners on one circle, so either diagonal is Delaunay, and
    which one qhull takes depends on the last bits of the coordinates (a
    spacing changed by 1e-12 changes most of them).  Here the points are
    lifted to the paraboloid ``|p - c|^2 / scale^2`` plus ``slack`` times a
    weight fixed by each point's index (:func:`_index_weights`) and the
    lower convex hull is taken: the regular triangulation for those
    weights.  It is Delaunay wherever the empty-circle test decides by more
    than ``slack`` (a power distance, in units of ``scale^2``); at a tie or
    a near tie the diagonal is the one whose corners weigh less, the same
    for any coordinates within rounding of the same points.

    Parameters
    ----------
    points : (n, 2) array_like of float
        The points (at least 3, not all on one line).
    scale : float, optional
        Their spacing; by default the side of a square cell per point over
        their bounding box.
    slack : float
        The tie band, in units of ``scale^2``.  The rounding of the lifted
        coordinates, about ``(R / scale)^2`` times 1e-16 for points spread
        over R, must stay well below it (R up to 1e4 scale by default).

    Returns
    -------
    (t, 3) int64
        Counter-clockwise triangles, each starting at its smallest index,
        rows sorted: one canonical array for one point set.  Raises
        ``scipy.spatial.QhullError`` on degenerate input, as
        ``scipy.spatial.Delaunay`` does.

    Examples
    --------
    >>> square = [[0, 0], [1, 0], [1, 1], [0, 1]]
    >>> delaunay_triangles(square).tolist() == delaunay_triangles(
    ...     np.array(square) * (1 + 1e-12)).tolist()
    True
    """
    p = np.asarray(points, dtype=np.float64).reshape(-1, 2)
    if scale is None:
        ext = np.ptp(p, axis=0) if p.shape[0] else np.ones(2)
        scale = float(np.sqrt(ext[0] * ext[1] / max(p.shape[0], 1))) or float(ext.max()) or 1.0
    q = (p - p.mean(axis=0)) / scale
    lifted = np.column_stack([q, (q * q).sum(axis=1) + slack * _index_weights(q.shape[0])])
    if q.shape[0] == 3:  # too few for a hull in 3-D: one triangle, or a line
        tri = np.arange(3, dtype=np.int64)[None]
        e1, e2 = q[1] - q[0], q[2] - q[0]
        if abs(e1[0] * e2[1] - e1[1] * e2[0]) <= 1e-12 * float((q * q).sum()):
            raise QhullError("the three points are on one line")
    else:
        hull = ConvexHull(lifted)
        # the lower hull; a facet within 1e-9 of vertical is a sliver of
        # points (nearly) on one line of the 2-D hull's boundary: not a triangle
        tri = hull.simplices[hull.equations[:, 2] < -1e-9].astype(np.int64)
    a, b, c = q[tri[:, 0]], q[tri[:, 1]], q[tri[:, 2]]
    turn = (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0])
    tri = np.where((turn < 0)[:, None], tri[:, [0, 2, 1]], tri)
    first = np.argmin(tri, axis=1)
    tri = np.take_along_axis(tri, (first[:, None] + np.arange(3)) % 3, axis=1)
    return tri[np.lexsort((tri[:, 2], tri[:, 1], tri[:, 0]))]


def near_cocircular(points, triangles, slack: float) -> np.ndarray:
    """The cells of two triangles whose four corners are nearly on one circle.

    Where two triangles ``(a, b, c)`` and ``(b, a, d)`` share an edge and
    their angles at ``c`` and ``d`` sum to more than ``pi - slack``, the four
    corners are within ``slack`` of one circle: the Delaunay triangulation
    could as well take the diagonal ``c d``, and which one a triangulation
    (or a geodesic check on a tessellated truth) takes depends on tiny
    differences.  Works on 2-D points (a planar chart).

    Returns
    -------
    (m, 4) int64
        Every such cell's ``a, b, c, d`` (``a < b``), in the order of its
        shared edge ``(a, b)``.

    Examples
    --------
    >>> near_cocircular([[0, 0], [1, 0], [1, 1], [0, 1]], [(0, 1, 2), (0, 2, 3)], 0.01)
    array([[0, 2, 1, 3]])
    """
    p = np.asarray(points, dtype=np.float64)
    t = as_triangles(triangles)
    none = np.empty((0, 4), dtype=np.int64)
    if t.shape[0] < 2:
        return none
    # every triangle's three edges (ends sorted), with the corner opposite each
    ends = np.stack([t[:, [1, 2]], t[:, [2, 0]], t[:, [0, 1]]], axis=1).reshape(-1, 2)
    opposite = t.reshape(-1)
    key = np.sort(ends, axis=1)
    order = np.lexsort((key[:, 1], key[:, 0]))
    k = key[order]
    pair = np.flatnonzero((k[1:] == k[:-1]).all(axis=1))
    if pair.size == 0:
        return none
    i, j = order[pair], order[pair + 1]
    a, b = key[i, 0], key[i, 1]
    c, d = opposite[i], opposite[j]

    def angle(at, u, v):
        x, y = p[u] - p[at], p[v] - p[at]
        cos = (x * y).sum(axis=1) / np.maximum(norm(x) * norm(y), 1e-300)
        return libm.arccos(np.clip(cos, -1.0, 1.0))

    near = angle(c, a, b) + angle(d, a, b) > np.pi - slack
    return np.stack([a, b, c, d], axis=1)[near].astype(np.int64)


def flipped_ratios(points, triangles, slack: float) -> np.ndarray:
    """Ratios (:func:`triangle_ratios`) of the triangles a near-cocircular
    cell (:func:`near_cocircular`) would have with its other diagonal.

    Condition III-ii is met with a margin only if both diagonals of such a
    cell meet it.  Returns the ratios of the triangles ``(a, c, d)`` and
    ``(b, d, c)`` of every such cell, the first triangles of all cells first
    (empty when there is none).

    Examples
    --------
    A unit square's two triangulations are mirror images:

    >>> np.round(flipped_ratios([[0, 0], [1, 0], [1, 1], [0, 1]], [(0, 1, 2), (0, 2, 3)], 0.01), 4)
    array([0.7071, 0.7071])
    """
    cells = near_cocircular(points, triangles, slack)
    if cells.shape[0] == 0:
        return np.empty(0)
    return triangle_ratios(np.asarray(points, dtype=np.float64), flipped_triangles(cells))


def flipped_triangles(cells) -> np.ndarray:
    """The triangles ``(a, c, d)`` and ``(b, d, c)`` of cells ``a, b, c, d``
    (:func:`near_cocircular`) with their other diagonal, the first
    triangles of all cells first: (2 m, 3).

    Examples
    --------
    >>> flipped_triangles([[0, 2, 1, 3]])
    array([[0, 1, 3],
           [2, 3, 1]])
    """
    cells = np.asarray(cells, dtype=np.int64).reshape(-1, 4)
    return np.concatenate([cells[:, [0, 2, 3]], cells[:, [1, 3, 2]]])


def closest_points_on_triangles(p, corners) -> tuple[np.ndarray, np.ndarray]:
    """Squared distance from each point to its triangle and the closest point's
    barycentric weights (Ericson, *Real-Time Collision Detection* 5.1.5).

    Parameters
    ----------
    p : (m, 3) array_like of float
    corners : (m, 3, 3) array_like of float
        Row i: the corners of the triangle point i is measured against.

    Returns
    -------
    distance2 : (m,) float64
    weights : (m, 3) float64
        Weights of the corners (a degenerate triangle's closest point is
        taken at its centroid where the regions cannot decide).

    Examples
    --------
    >>> d2, w = closest_points_on_triangles([[0.2, 0.2, 1.0]], [[[0, 0, 0], [1, 0, 0], [0, 1, 0]]])
    >>> float(d2[0]), w.round(2).tolist()
    (1.0, [[0.6, 0.2, 0.2]])
    """
    p = np.asarray(p, dtype=np.float64).reshape(-1, 3)
    tri_pts = np.asarray(corners, dtype=np.float64).reshape(-1, 3, 3)
    a, b, c = tri_pts[:, 0], tri_pts[:, 1], tri_pts[:, 2]

    def dot(x, y):
        return np.einsum("ij,ij->i", x, y)

    ab, ac, ap = b - a, c - a, p - a
    d1, d2 = dot(ab, ap), dot(ac, ap)
    bp = p - b
    d3, d4 = dot(ab, bp), dot(ac, bp)
    cp = p - c
    d5, d6 = dot(ab, cp), dot(ac, cp)
    va = d3 * d6 - d5 * d4
    vb = d5 * d2 - d1 * d6
    vc = d1 * d4 - d3 * d2
    with np.errstate(divide="ignore", invalid="ignore"):
        w = np.stack([va, vb, vc], axis=1) / (va + vb + vc)[:, None]
        t_ab = d1 / (d1 - d3)
        t_ac = d2 / (d2 - d6)
        t_bc = (d4 - d3) / ((d4 - d3) + (d5 - d6))
    zero = np.zeros(p.shape[0])
    regions = [  # later regions win: edges over the face, corners over edges
        ((vc <= 0) & (d1 >= 0) & (d3 <= 0), np.stack([1 - t_ab, t_ab, zero], 1)),
        ((vb <= 0) & (d2 >= 0) & (d6 <= 0), np.stack([1 - t_ac, zero, t_ac], 1)),
        ((va <= 0) & (d4 - d3 >= 0) & (d5 - d6 >= 0), np.stack([zero, 1 - t_bc, t_bc], 1)),
        ((d1 <= 0) & (d2 <= 0), np.eye(3)[[0]]),
        ((d3 >= 0) & (d4 <= d3), np.eye(3)[[1]]),
        ((d6 >= 0) & (d5 <= d6), np.eye(3)[[2]]),
    ]
    for sel, value in regions:
        w = np.where(sel[:, None], value, w)
    w = np.nan_to_num(w, nan=1.0 / 3.0)
    q = np.einsum("ij,ijk->ik", w, tri_pts)
    return ((p - q) ** 2).sum(axis=1), w


def surface_points(vertices, triangles, count: int, seed: int = 0) -> np.ndarray:
    """The vertices triangles use plus ``count`` area-uniform random surface points (seeded)."""
    v, t = as_mesh(vertices, triangles)
    if t.shape[0] == 0:
        raise ValueError("mesh: surface points need at least one triangle")
    p = v[t]
    area = 0.5 * np.linalg.norm(np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), axis=1)
    rng = np.random.default_rng(seed)
    pick = rng.choice(t.shape[0], size=count, p=area / area.sum())
    r1, r2 = rng.random(count), rng.random(count)
    s = np.sqrt(r1)
    w = np.stack([1 - s, s * (1 - r2), s * r2], axis=1)
    inner = np.einsum("ij,ijk->ik", w, p[pick])
    return np.vstack([v[np.unique(t)], inner])


# --- triangle intersection -------------------------------------------------


def _candidate_pairs(lo: np.ndarray, hi: np.ndarray, keep=None) -> np.ndarray:
    """Pairs (i, j), i < j, of overlapping boxes, sorted, filtered by ``keep``
    (:func:`sr33._intersect.box_pairs`: a grid whose memory follows the
    number of boxes, not their extent)."""
    pairs = _intersect.box_pairs(np.ascontiguousarray(lo), np.ascontiguousarray(hi))
    if keep is not None and pairs.shape[0]:
        pairs = pairs[np.asarray(keep(pairs[:, 0], pairs[:, 1]), dtype=bool)]
    return pairs


def self_intersections(vertices, triangles, keep=None) -> np.ndarray:
    """Pairs (i, j), i < j, of triangles whose interiors intersect.

    The paper requires the triangles of the output to have pairwise disjoint
    interiors (Section 4, Triangulate).  Candidate pairs have overlapping
    boxes (a hashed grid); each is decided by exact segment–triangle tests
    (Möller–Trumbore; both are numba kernels, :mod:`sr33._intersect`): two
    non-coplanar triangles intersect exactly when an edge of one crosses
    the other.  Pairs sharing an edge are
    adjacent, not intersecting, unless they fold onto each other (coplanar
    and on the same side); pairs sharing one vertex intersect when an edge
    not at that vertex crosses the other.

    Parameters
    ----------
    vertices : (n, 3) array_like of float
    triangles : (t, 3) array_like of int
    keep : callable, optional
        ``keep(i, j) -> bool array`` filters the candidate pairs before the
        exact tests (callers that only care about some pairs).

    Returns
    -------
    (p, 2) int64, sorted rows.

    Examples
    --------
    >>> v = np.array([[0, 0, 0], [2, 0, 0], [0, 2, 0],
    ...               [0.5, 0.5, -1], [0.5, 0.5, 1], [3, 3, 0]], float)
    >>> self_intersections(v, [(0, 1, 2), (3, 4, 5)]).tolist()
    [[0, 1]]
    """
    v, t = as_mesh(vertices, np.asarray(triangles).reshape(-1, 3))
    if t.shape[0] < 2:
        return np.empty((0, 2), dtype=np.int64)
    p = v[t]
    lo, hi = p.min(axis=1), p.max(axis=1)
    pairs = _candidate_pairs(lo, hi, keep)
    if pairs.shape[0] == 0:
        return np.empty((0, 2), dtype=np.int64)
    # candidate rows are sorted and unique (i < j): so are the hits
    return pairs[_intersect.pairs_meet(v, t, pairs, crossing_eps(v))]


def crossing_eps(vertices: np.ndarray) -> float:
    """The determinant below which :func:`self_intersections` treats a segment
    as parallel to a triangle: ``1e-14`` times the squared largest coordinate
    magnitude of ``vertices`` (1 when all are 0)."""
    scale = float(np.abs(vertices).max()) if vertices.size else 0.0
    scale = scale or 1.0
    return 1e-14 * scale * scale


def first_crossing(vertices: np.ndarray, patch: np.ndarray, new: int, eps: float):
    """The first pair ``(i, j)``, ``i < j``, ``i < new``, of rows of ``patch``
    whose interiors meet (the predicate of :func:`self_intersections`), or
    ``None``: a few new triangles (the first ``new`` rows) against each other
    and the triangles round them, without the set-up of a whole-mesh search.

    ``vertices`` must be float64 ``(n, 3)`` and ``patch`` int64 ``(t, 3)``
    within range (they are not checked: this is the inner loop of the cones,
    the flips and the hole closing); ``eps`` from :func:`crossing_eps` of the
    whole vertex array.

    Examples
    --------
    >>> v = np.array([[0, 0, 0], [2, 0, 0], [0, 2, 0],
    ...               [0.5, 0.5, -1], [0.5, 0.5, 1], [3, 3, 0]], float)
    >>> first_crossing(v, np.array([(3, 4, 5), (0, 1, 2)]), 1, crossing_eps(v))
    (0, 1)
    """
    i, j = _intersect.first_crossing(vertices, patch, new, eps)
    return None if i < 0 else (int(i), int(j))
