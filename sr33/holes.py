"""Boundary loops of the selection as faces (Section 4, proof of Theorem 4).

Candidate face cycles stop at ``max_cycle_length`` edges, so where the
search could not close the surface with small cycles (real scans with
uneven density, thin parts) the selection keeps holes whose boundary loops
are 9-100 edges long.  The proof of Theorem 4 closes a troubled
neighbourhood with the isometric loop around it as one face; this module
does that for the loops the selection leaves open.

A loop becomes a face only when all of these hold:

* it is a simple cycle of open edges (each sample once): at a sample where
  the boundary passes more than once, a loop arriving along one open edge
  leaves along one that ends another piece of the sample's link (so that
  filling every loop there closes the link);
* it has at most ``max_length`` edges (the minimum-area triangulation is
  O(L³));
* adding it leaves the link of every sample that was a disk a disk;
* it does not close a small piece on its own: its triangulation's area is
  less than the area of the faces it borders (no detached bubble);
* its triangulation is *covered by the samples*: every centroid and edge
  midpoint of its triangles is within ``cover`` times the loop's longest
  edge of some sample.  Under the paper's dense-sampling conditions every
  point of the surface is that close to a sample, so a loop round an empty
  region (the rim of a sheet, a true hole) is a boundary and stays open,
  while the narrow slits and the holes round stray samples that the
  selection leaves are closed;
* its triangles cross no other triangle (checked by the caller after
  triangulation, :func:`sr33.reconstruct.reconstruct`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import sparse
from scipy.sparse import csgraph
from scipy.spatial import cKDTree

from .backtracking import links_are_disks
from .cycles import CycleSet, concat
from .graph import cycle_edges
from .mesh import edge_keys, self_intersections


@dataclass(frozen=True)
class HoleLoops:
    """Result of :func:`hole_loops`.

    Attributes
    ----------
    loops : CycleSet
        The boundary loops that may become faces (canonical cycle form).
    found : int
        Boundary loops of the selection (simple or not).
    """

    loops: CycleSet
    found: int


def _canonical(cyc: list[int]) -> list[int]:
    """Start at the smallest vertex, second vertex smaller than the last."""
    i = cyc.index(min(cyc))
    c = cyc[i:] + cyc[:i]
    if c[1] > c[-1]:
        c = [c[0]] + c[1:][::-1]
    return c


def _corners(faces: CycleSet) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(vertex, prev, next) of every corner of every cycle."""
    pairs, owner = cycle_edges(faces.offsets, faces.vertices)
    prev = np.roll(np.arange(faces.vertices.shape[0]), 1)
    prev[faces.offsets[:-1]] = faces.offsets[1:] - 1
    return faces.vertices, faces.vertices[prev], pairs[:, 1]


def _link_pieces(prev, nxt) -> dict[int, int]:
    """Neighbour -> piece of a sample's link (the smallest neighbour of the
    piece), for corners ``(prev[i], nxt[i])`` at that sample."""
    parent: dict[int, int] = {}

    def find(x: int) -> int:
        while parent.setdefault(x, x) != x:
            x = parent[x]
        return x

    for a, b in zip(prev, nxt):
        ra, rb = find(int(a)), find(int(b))
        if ra != rb:
            parent[max(ra, rb)] = min(ra, rb)
    return {x: find(x) for x in list(parent)}


def face_links(n: int, faces: CycleSet) -> np.ndarray:
    """For every sample, whether the faces' corners at it form a disk."""
    v, p, q = _corners(faces)
    return links_are_disks(n, v, p, q)


def _fan_areas(points, cs: CycleSet) -> np.ndarray:
    """Area of a fan triangulation of every cycle (a cheap size estimate)."""
    pairs, owner = cycle_edges(cs.offsets, cs.vertices)
    first = points[np.repeat(cs.vertices[cs.offsets[:-1]], cs.lengths)]
    fan = 0.5 * np.linalg.norm(
        np.cross(points[pairs[:, 0]] - first, points[pairs[:, 1]] - first), axis=1
    )
    return np.bincount(owner, weights=fan, minlength=len(cs))


def hole_loops(points, faces: CycleSet, *, max_length: int = 66) -> HoleLoops:
    """The open boundary loops of a face selection that may be closed by one face.

    Parameters
    ----------
    points : (n, 3) float64
        The samples.
    faces : CycleSet
        The selected face cycles (:attr:`sr33.FaceSelection.faces`).
    max_length : int
        Longest loop considered.

    Returns
    -------
    HoleLoops
        The loops passing the combinatorial tests of the module docstring
        (simple, short enough, links kept disks, no bubble); coverage and
        crossings are tested on their triangulation by the caller.
    """
    pts = np.asarray(points, dtype=np.float64)
    n = pts.shape[0]
    empty = HoleLoops(CycleSet(np.zeros(1, np.int64), np.empty(0, np.int64)), 0)
    if len(faces) == 0:
        return empty
    pairs, owner = cycle_edges(faces.offsets, faces.vertices)
    keys = edge_keys(pairs[:, 0], pairs[:, 1], n)
    _, inv, cnt = np.unique(keys, return_inverse=True, return_counts=True)
    once = cnt[inv] == 1
    if not once.any():
        return empty
    # the open edges, each with the face that uses it
    hole = np.sort(pairs[once], axis=1)
    hole_owner = owner[once]
    order = np.lexsort((hole[:, 1], hole[:, 0]))
    hole, hole_owner = hole[order], hole_owner[order]
    at: dict[int, list[int]] = {}
    for a, b in hole.tolist():
        at.setdefault(a, []).append(b)
        at.setdefault(b, []).append(a)
    # at every sample, which open neighbour the loop continues to from another
    v_all, p_all, q_all = _corners(faces)
    corner_order = np.argsort(v_all, kind="stable")
    starts = np.searchsorted(v_all[corner_order], np.arange(n + 1))
    partner: dict[tuple[int, int], int] = {}
    for v, nbrs in at.items():
        nbrs = sorted(nbrs)
        if len(nbrs) % 2:
            continue  # an odd boundary vertex (an edge used by three faces near it)
        if len(nbrs) == 2:
            partner[(v, nbrs[0])], partner[(v, nbrs[1])] = nbrs[1], nbrs[0]
            continue
        # pieces of v's link: neighbours joined by corners at v; a loop
        # passing v joins the ends of two different pieces
        ks = corner_order[starts[v] : starts[v + 1]]
        piece = _link_pieces(p_all[ks], q_all[ks])
        free = list(nbrs)
        while free:
            x = free.pop(0)
            other = [y for y in free if piece[y] != piece[x]]
            y = (other or free)[0]
            free.remove(y)
            partner[(v, x)], partner[(v, y)] = y, x
    edge_row = {(a, b): i for i, (a, b) in enumerate(hole.tolist())}
    seen = np.zeros(hole.shape[0], dtype=bool)
    found = 0
    loops: list[list[int]] = []
    loop_owner: list[np.ndarray] = []
    for s in range(hole.shape[0]):
        if seen[s]:
            continue
        a, b = (int(x) for x in hole[s])
        cyc, rows = [a], [s]
        seen[s] = True
        closed = False
        while True:
            cyc.append(b)
            c = partner.get((b, a))
            if c is None:
                break
            r = edge_row[(min(b, c), max(b, c))]
            if r == s:  # back at the start
                closed = cyc.pop() == cyc[0]
                break
            if seen[r]:
                break
            seen[r] = True
            rows.append(r)
            a, b = b, c
        if not closed:
            continue
        found += 1
        if len(cyc) < 3 or len(cyc) > max_length or len(set(cyc)) != len(cyc):
            continue
        loops.append(cyc)
        loop_owner.append(hole_owner[rows])
    if not loops:
        return HoleLoops(empty.loops, found)
    # no bubble: a cap smaller than half of the piece of surface it closes
    face_area = _fan_areas(pts, faces)
    cap_area = _fan_areas(pts, _cycleset(loops))
    _, eid = np.unique(keys, return_inverse=True)
    nf = len(faces)
    g = sparse.csr_matrix(
        (np.ones(owner.shape[0], dtype=np.int8), (owner, eid + nf)),
        shape=(nf + int(eid.max()) + 1,) * 2,
    )
    _, lab = csgraph.connected_components(g, directed=False)
    piece_area = np.bincount(lab[:nf], weights=face_area)
    keep = [i for i in range(len(loops)) if cap_area[i] < 0.5 * piece_area[lab[loop_owner[i][0]]]]
    # links kept disks: drop offending loops until none
    disk_before = face_links(n, faces)
    while keep:
        trial = concat(faces, _cycleset([loops[i] for i in keep]))
        disk_after = face_links(n, trial)
        worse = disk_before & ~disk_after
        drop = [i for i in keep if worse[loops[i]].any()]
        if not drop:
            break
        keep = [i for i in keep if i not in drop]
    return HoleLoops(_cycleset([_canonical(loops[i]) for i in keep]), found)


def _cycleset(cycles: list[list[int]]) -> CycleSet:
    lengths = np.array([len(c) for c in cycles], dtype=np.int64)
    offsets = np.zeros(lengths.shape[0] + 1, dtype=np.int64)
    np.cumsum(lengths, out=offsets[1:])
    verts = np.array([v for c in cycles for v in c], dtype=np.int64)
    return CycleSet(offsets=offsets, vertices=verts)


def uncovered(points, triangles, loop_of_triangle, lengths_scale, *, cover: float = 1.0):
    """Which loop faces have a triangle point farther than ``cover`` x scale from every sample.

    Parameters
    ----------
    points : (n, 3) float64
        The samples.
    triangles : (t, 3) int64
        The triangles of the loop faces.
    loop_of_triangle : (t,) int64
        The loop (0-based among the loops) of every triangle.
    lengths_scale : (l,) float64
        The longest edge of every loop.
    cover : float
        The coverage factor of the module docstring.

    Returns
    -------
    (l,) bool
        True for a loop whose triangulation is not covered.
    """
    pts = np.asarray(points, dtype=np.float64)
    bad = np.zeros(lengths_scale.shape[0], dtype=bool)
    if triangles.shape[0] == 0:
        return bad
    p = pts[triangles]
    test = np.concatenate([p.mean(axis=1), 0.5 * (p + np.roll(p, -1, axis=1)).reshape(-1, 3)])
    who = np.concatenate([loop_of_triangle, np.repeat(loop_of_triangle, 3)])
    d, _ = cKDTree(pts).query(test)
    bad[who[d > cover * lengths_scale[who]]] = True
    return bad


def unpinch(faces: CycleSet, n: int) -> np.ndarray:
    """Faces to remove so that every sample's link is at most one piece.

    At a sample whose faces' corners form several pieces (a pinched vertex:
    two fans touching at a point, or a fan plus a stray face), the faces of
    every piece but the largest (most corners; ties: the piece with the
    smallest neighbour) are returned.  Removing them opens holes that
    :func:`hole_loops` can close again, each with a disk round the sample,
    and leaves their samples to the cones when nothing else uses them.

    Parameters
    ----------
    faces : CycleSet
        The face cycles.
    n : int
        Number of samples.

    Returns
    -------
    (r,) int64
        Sorted indices of the faces to remove.
    """
    if len(faces) == 0:
        return np.empty(0, np.int64)
    v, p, q = _corners(faces)
    owner = np.repeat(np.arange(len(faces)), faces.lengths)
    disk = links_are_disks(n, v, p, q)
    bad = np.flatnonzero(~disk[v])
    if bad.shape[0] == 0:
        return np.empty(0, np.int64)
    order = bad[np.argsort(v[bad], kind="stable")]
    out: set[int] = set()
    splits = np.flatnonzero(np.diff(v[order])) + 1
    for group in np.split(order, splits):
        piece = _link_pieces(p[group], q[group])
        roots = [piece[int(p[k])] for k in group.tolist()]
        count: dict[int, int] = {}
        for r in roots:
            count[r] = count.get(r, 0) + 1
        if len(count) < 2:
            continue  # one piece that is not a path or cycle: left alone
        keep = min(count, key=lambda r: (-count[r], r))
        out |= {int(owner[k]) for k, r in zip(group.tolist(), roots) if r != keep}
    return np.array(sorted(out), dtype=np.int64)


def crossing_faces(
    points, faces: CycleSet, triangles, face_of_triangle, n_faces: int, *, everywhere: bool = True
) -> np.ndarray:
    """Faces among the first ``n_faces`` whose triangles cross each other's.

    The search excludes crossing candidate cycles, but not those that share
    a corner, and those can still cross.  Above all, two faces that alone
    cover a sample and share both its edges are a disk combinatorially, yet
    folded onto each other when they lie on one side of it (a quad run
    across a steep cone rim beside a quad of the cone); such pairs are
    always checked, every other pair of faces only with ``everywhere`` (a
    selection the strict search did not make alone).  Both faces of every
    crossing pair are returned; removing them leaves a hole that
    :func:`hole_loops` closes, and a sample only they covered goes to the
    cones, which insert it back where nothing crosses.

    Parameters
    ----------
    points : (n, 3) float
    faces : CycleSet
        The face cycles (the selection's first, loop faces after them).
    triangles : (t, 3) int64
        Their triangulation.
    face_of_triangle : (t,) int64
        The face of every triangle.
    n_faces : int
        Faces ``0 .. n_faces - 1`` are considered (the selection's; loop
        faces are checked on their own).
    everywhere : bool
        Check every pair of faces, not only the folded pairs.

    Returns
    -------
    (r,) int64
        Sorted indices of the crossing faces.
    """
    tri = np.asarray(triangles, dtype=np.int64)
    fot = np.asarray(face_of_triangle, dtype=np.int64)
    out: set[int] = set()
    if everywhere:
        mine = np.flatnonzero(fot < n_faces)
        if mine.shape[0] >= 2:
            hits = self_intersections(points, tri[mine])
            out |= set(fot[mine[hits.ravel()]].tolist())
    elif len(faces):
        n = np.asarray(points).shape[0]
        v, p, q = _corners(faces)
        owner = np.repeat(np.arange(len(faces)), faces.lengths)
        base = owner < n_faces
        uses = np.bincount(v[base], minlength=n)
        two = np.flatnonzero(base & (uses[v] == 2))
        two = two[np.argsort(v[two], kind="stable")].reshape(-1, 2)
        lo, hi = np.minimum(p[two], q[two]), np.maximum(p[two], q[two])
        same = (lo[:, 0] == lo[:, 1]) & (hi[:, 0] == hi[:, 1])
        for f1, f2 in owner[two[same]].tolist():
            pair = np.flatnonzero((fot == f1) | (fot == f2))
            if self_intersections(points, tri[pair]).shape[0]:
                out |= {f1, f2}
    return np.array(sorted(out), dtype=np.int64)
