"""Backtracking (Algorithm 4 of the paper, Section 4): a 2-basis of face cycles.

Algorithm 4 grows a set of face cycles under *the backtracking invariant*
(every edge is used at most twice, a new face shares an edge used once) and
accepts a maximal set when *the success condition* holds: every
Conv(N(u; k)) ∩ P' is a disk.  Tried literally, the search is exponential.
This module searches the same space, made tractable by four observations:

1. **Unambiguous cycles are fixed.**  An edge lying in exactly two small
   isometric cycles is used by both in every closed solution (each edge of a
   closed 2-basis is used exactly twice), and an edge in one cycle only is a
   boundary edge of that cycle (the open L sheet).  A cycle all of whose
   edges are like this, and which folds onto no neighbour, is selected
   outright.  Under the sample conditions this is almost every cycle:
   Theorem 2 (Lemmas 4, 5) makes the localized RNG equal the Urquhart graph
   on smooth parts, whose small isometric cycles are exactly its faces.
2. **The rest splits into independent local problems.**  The remaining
   ("free") cycles contain an edge in three or more cycles, or fold onto a
   neighbour (see :class:`sr33.tolerance.Tolerance`).  A free cycle whose
   surface (its fan from the centroid) crosses another cycle's is never
   selected with it: Triangulate needs disjoint interiors (Section 4), and
   without this test cone tips and non-conforming scans got crossing or
   twisted (non-orientable) patches.  They are grouped into
   components connected through shared edges.  Condition II-iii puts each
   face cycle inside one k-neighbourhood and Theorems 3 and 4 confine the
   ambiguity to neighbourhoods of sharp edges, corners and sharp points, so
   these components are small and solved one by one; a choice in one cannot
   affect the edge counts of another.
3. **Each component is a constraint search with propagation** (DPLL-style
   backtracking): every edge must end with 0 or 2 uses (fixed boundary edges
   keep their single use), a selected cycle excludes every cycle folding onto
   it, and once all cycles at a vertex are decided its link must be one
   cycle or one path (a disk: the vertex form of the success condition) and
   not empty if the vertex had candidates.  Forced moves (an edge used once
   with one candidate left, an edge used twice, an edge unused with a single
   candidate) are propagated before branching.  Branching picks the most
   constrained edge and tries its best-ranked cycle first; ranking is by
   length, then flatness, then the canonical vertex order, so the first
   solution found is the one Algorithm 4 would return with candidates tried
   in that order.
4. **A budget bounds the search.**  Each component gets ``budget``
   assignments.  When the strict search fails or exhausts the budget (acute
   sharp edges, where the RNG cuts across the edge and covering every
   sample is impossible, or input that does not meet the sample
   conditions), the component falls back to a greedy pass that grows the
   surface from its boundary, as Algorithm 4 does, keeping the invariant
   (no edge above two uses, no vertex link that is not a disk; see
   :func:`_front_greedy`), and then to the exact selection of :mod:`sr33.selection`
   over the failed components and the cycles fixed next to them because of
   an edge in no other candidate; it allows stray samples, as the paper's
   success condition does, and its answer replaces the greedy one only
   when strictly better.  The result reports the edges and samples that
   could not be closed.
5. **One surface per connected piece of the samples** (the success
   condition of Section 5).  Components decided on their own can close a
   piece off (a cone's rings capped one by one round its apex: three closed
   spheres where the cone is one); every cycle within two graph edges of a
   detached closed piece of the strict search's decisions
   (:func:`_detaching`) goes to the fallback, whose exact selection forbids
   bubbles, and a selection with a bubble loses to any valid answer.
"""

from __future__ import annotations

import sys
from dataclasses import dataclass, field

import numpy as np
from scipy import sparse
from scipy.sparse import csgraph

from . import _kernels
from ._validate import InputError, as_edges, as_points
from .cycles import CycleSet
from .graph import cycle_edges, link_is_disk, lookup_edges
from .mesh import self_intersections, unique_edges, unique_rows
from .progress import bar, log
from .rng import Neighbourhoods, k_neighbourhoods
from .selection import ExactReport, Incidence, exact_selection
from .tolerance import DEFAULT, Tolerance


@dataclass(frozen=True)
class FaceSelection:
    """Result of :func:`backtracking`.

    Attributes
    ----------
    faces : CycleSet
        The selected face cycles (the 2-basis), in the input cycle order.
    selected : (c,) bool
        Which input cycles were selected.
    success : bool
        True when the paper's success condition held: no edge used more
        than twice, every used sample's link a disk, and open edges only on
        true boundaries (edges lying in one candidate cycle).  Stray samples
        (no face uses them) are allowed; the cones attach them (Section 5).
    open_edges : (p, 2) int64
        Edges of the selection used once (the boundary; empty when closed).
    unresolved_samples : (q,) int64
        Samples whose link is not a disk, or that no selected face uses.
    components : int
        Number of independent ambiguous components searched.
    fallback_components : int
        How many of them the strict search could not solve (they fell back
        to the greedy pass, then to the exact selection).
    assignments : int
        Total search assignments made (a measure of the work done).
    non_disk_neighbourhoods : (r,) int64
        Samples u for which the faces lying wholly inside N(u; k) do not form
        one disk (Euler characteristic 1, connected): the combinatorial form
        of the success condition "Conv(N(u; k)) ∩ P' is a disk".  Only
        computed when ``k`` is given (else empty).  It is an indicator, not
        part of ``success``: a face with vertices outside N(u; k) (a large
        face at a cone tip) leaves a hole in this stand-in that the convex
        hull would cover.
    notes : tuple of str
        Human-readable remarks (overloaded edges, empty input).
    exact : ExactReport
        What the exact selection (:mod:`sr33.selection`) did on the
        components the strict search failed.
    true_boundary : (p,) bool
        For every row of ``open_edges``, whether it lies in one candidate
        cycle only (a true boundary in the success condition).
    """

    faces: CycleSet
    selected: np.ndarray
    success: bool
    open_edges: np.ndarray
    unresolved_samples: np.ndarray
    components: int
    fallback_components: int
    assignments: int
    non_disk_neighbourhoods: np.ndarray = field(default_factory=lambda: np.empty(0, np.int64))
    notes: tuple[str, ...] = field(default=())
    exact: ExactReport = field(default_factory=ExactReport)
    true_boundary: np.ndarray = field(default_factory=lambda: np.empty(0, bool))


def _cycle_geometry(points, cs: CycleSet):
    """Centroid and non-planarity (smallest singular value / perimeter) per cycle."""
    lengths = cs.lengths
    owner = np.repeat(np.arange(len(cs)), lengths)
    p = points[cs.vertices]
    sums = np.zeros((len(cs), 3))
    np.add.at(sums, owner, p)
    cen = sums / lengths[:, None]
    flat = np.zeros(len(cs))
    nxt_pairs, _ = cycle_edges(cs.offsets, cs.vertices)
    seg = np.linalg.norm(points[nxt_pairs[:, 0]] - points[nxt_pairs[:, 1]], axis=1)
    perim = np.zeros(len(cs))
    np.add.at(perim, owner, seg)
    for L in np.unique(lengths):
        if L <= 3:
            continue
        sel = np.flatnonzero(lengths == L)
        idx = cs.offsets[sel][:, None] + np.arange(L)[None, :]
        q = points[cs.vertices[idx]] - cen[sel][:, None, :]
        s = np.linalg.svd(q, compute_uv=False)
        flat[sel] = s[:, -1] / perim[sel]
    return cen, flat


def _cycle_area(points, cs: CycleSet, centroid) -> np.ndarray:
    """Area of every cycle's fan from its centroid (label-free, rotation-free)."""
    pairs, owner = cycle_edges(cs.offsets, cs.vertices)
    c = centroid[owner]
    tri = 0.5 * np.linalg.norm(np.cross(points[pairs[:, 0]] - c, points[pairs[:, 1]] - c), axis=1)
    return np.bincount(owner, weights=tri, minlength=len(cs))


def _rank(cs: CycleSet, area: np.ndarray, flat: np.ndarray, spread: np.ndarray) -> np.ndarray:
    """Rank of every cycle: length, area, flatness, spread, then canonical order.

    Area, flatness and spread (distance of the cycle's centroid from the
    centroid of all samples) are compared after rounding to 1e-6 relative,
    so that rounding noise from a rigid motion does not reorder tied cycles.
    All four keys are invariant under permutation, rigid motion and uniform
    scaling; only cycles tied on all four fall to the canonical
    (lexicographic) order, which is not rotation invariant.
    """
    scale = float(np.median(area)) if area.shape[0] else 1.0
    qa = np.round(area / (scale * 1e-6 if scale > 0 else 1.0))
    qf = np.round(flat * 1e6)
    reach = float(spread.max()) if spread.shape[0] else 1.0
    qs = np.round(spread / (reach * 1e-7 if reach > 0 else 1.0))
    order = np.lexsort((np.arange(len(cs)), qs, qf, qa, cs.lengths))
    rank = np.empty(len(cs), dtype=np.int64)
    rank[order] = np.arange(len(cs))
    return rank


def _fold_pairs(points, edges, inc_edge, inc_cycle, centroid, fold_degrees):
    """Pairs of cycles sharing an edge whose wings are closer than the fold angle."""
    order = np.lexsort((inc_cycle, inc_edge))
    e_sorted = inc_edge[order]
    c_sorted = inc_cycle[order]
    a = points[edges[e_sorted, 0]]
    b = points[edges[e_sorted, 1]]
    d = b - a
    d /= np.linalg.norm(d, axis=1)[:, None]
    w = centroid[c_sorted] - 0.5 * (a + b)
    w -= (w * d).sum(axis=1)[:, None] * d
    norm = np.linalg.norm(w, axis=1)
    w /= np.where(norm > 0, norm, 1.0)[:, None]
    cos_lim = np.cos(np.radians(fold_degrees))
    starts = np.flatnonzero(np.r_[True, e_sorted[1:] != e_sorted[:-1]])
    ends = np.r_[starts[1:], e_sorted.shape[0]]
    size = ends - starts
    # the common case, edges in exactly two cycles, vectorized
    two = starts[size == 2]
    hit = (w[two] * w[two + 1]).sum(axis=1) > cos_lim
    pairs = [np.stack([c_sorted[two[hit]], c_sorted[two[hit] + 1]], axis=1)]
    for g in np.flatnonzero(size >= 3):
        s, t = starts[g], ends[g]
        ww = w[s:t]
        ii, jj = np.nonzero(np.triu((ww @ ww.T) > cos_lim, 1))
        pairs.append(np.stack([c_sorted[s + ii], c_sorted[s + jj]], axis=1))
    out = np.concatenate(pairs).astype(np.int64)
    if not out.shape[0]:
        return np.empty((0, 2), dtype=np.int64)
    return unique_edges(out)


def _crossing_pairs(points, cs: CycleSet, centroid, free) -> np.ndarray:
    """Pairs (free cycle, any cycle near it) whose centroid fans intersect.

    Each cycle is fanned from its centroid; triangle pairs are tested exactly
    (:func:`sr33.mesh.self_intersections`).  Only cycles that are free, or share a
    vertex with a free cycle, take part, so the cost follows the ambiguity.
    """
    idx = np.flatnonzero(free)
    if idx.shape[0] == 0:
        return np.empty((0, 2), dtype=np.int64)
    near = np.zeros(points.shape[0], dtype=bool)
    for i in idx.tolist():
        near[cs.cycle(i)] = True
    lengths = cs.lengths
    owner_all = np.repeat(np.arange(len(cs)), lengths)
    touch = np.zeros(len(cs), dtype=bool)
    touch[np.unique(owner_all[near[cs.vertices]])] = True
    sel = np.flatnonzero(touch)
    n = points.shape[0]
    extra = centroid[sel]
    slot = np.full(len(cs), -1, dtype=np.int64)
    slot[sel] = np.arange(sel.shape[0])
    tris, owner = [], []
    for L in np.unique(lengths[sel]).tolist():
        ids = sel[lengths[sel] == L]
        ring = cs.vertices[cs.offsets[ids][:, None] + np.arange(L)]
        if L == 3:
            tris.append(ring)
            owner.append(ids)
            continue
        centre = np.repeat(n + slot[ids], L)
        tris.append(np.stack([centre, ring.ravel(), np.roll(ring, -1, axis=1).ravel()], axis=1))
        owner.append(np.repeat(ids, L))
    tri = np.concatenate(tris)
    own = np.concatenate(owner)

    def keep(i, j):
        a, b = own[i], own[j]
        return (a != b) & (free[a] | free[b])

    hits = self_intersections(np.vstack([points, extra]), tri, keep=keep)
    if hits.shape[0] == 0:
        return np.empty((0, 2), dtype=np.int64)
    a, b = own[hits[:, 0]], own[hits[:, 1]]
    keep = (a != b) & (free[a] | free[b])
    pairs = np.sort(np.stack([a[keep], b[keep]], axis=1), axis=1)
    return unique_rows(pairs) if pairs.shape[0] else pairs


def links_are_disks(n: int, vertex, prev, nxt) -> np.ndarray:
    """For every vertex, whether its link (corner pairs prev-next) is one path or cycle.

    Vectorized over all vertices: link nodes are (vertex, neighbour) pairs,
    each corner joins two of them; a link is a disk when every node has
    degree <= 2 and the nodes form a single connected component.  Vertices
    with no corner get False.
    """
    vertex = np.asarray(vertex, dtype=np.int64)
    ok = np.zeros(n, dtype=bool)
    if vertex.shape[0] == 0:
        return ok
    a = vertex * n + np.asarray(prev, dtype=np.int64)
    b = vertex * n + np.asarray(nxt, dtype=np.int64)
    keys, inv = np.unique(np.concatenate([a, b]), return_inverse=True)
    m = vertex.shape[0]
    ia, ib = inv[:m], inv[m:]
    deg = np.bincount(inv, minlength=keys.shape[0])
    node_vertex = keys // n
    g = sparse.csr_matrix(
        (np.ones(m, dtype=np.int8), (ia, ib)), shape=(keys.shape[0], keys.shape[0])
    )
    _, labels = csgraph.connected_components(g, directed=False)
    comp_keys = np.unique(node_vertex * keys.shape[0] + labels)
    comps = np.bincount(comp_keys // keys.shape[0], minlength=n)
    bad_deg = np.zeros(n, dtype=bool)
    bad_deg[node_vertex[deg > 2]] = True
    loops = np.zeros(n, dtype=bool)
    loops[vertex[np.asarray(prev) == np.asarray(nxt)]] = True
    has = np.bincount(vertex, minlength=n) > 0
    return has & (comps == 1) & ~bad_deg & ~loops


def _link_is_partial_ok(corners: list[tuple[int, int]]) -> bool:
    """True when corner pairs can still grow into one disk: paths, or one lone cycle."""
    if not corners:
        return True
    deg: dict[int, int] = {}
    for p, q in corners:
        if p == q:
            return False
        deg[p] = deg.get(p, 0) + 1
        deg[q] = deg.get(q, 0) + 1
    if max(deg.values()) > 2:
        return False
    # a closed cycle is only fine if it is everything
    n_edges = len(corners)
    n_nodes = len(deg)
    if n_edges >= n_nodes:  # contains a cycle
        return link_is_disk(corners)
    return True


class _Problem:
    """Shared incidence tables of one backtracking run."""

    def __init__(self, cs: CycleSet, edges: np.ndarray, n: int):
        pairs, owner = cycle_edges(cs.offsets, cs.vertices)
        eid = lookup_edges(edges, pairs, n)
        if np.any(eid < 0):
            raise InputError("cycles use a pair of points that is not an edge of the graph")
        self.cycle_edge_ids = [eid[cs.offsets[i] : cs.offsets[i + 1]] for i in range(len(cs))]
        self.cycle_vertices = [cs.cycle(i) for i in range(len(cs))]
        self.inc_edge = eid
        self.inc_cycle = owner
        m = edges.shape[0]
        ec = sparse.csr_matrix(
            (np.ones(eid.shape[0], dtype=np.int8), (eid, owner)), shape=(m, len(cs))
        )
        ec.sort_indices()
        self.edge_cycles = ec
        self.n_cycles_at_edge = np.diff(ec.indptr)
        # corners: for every cycle and vertex position, (vertex, prev, next)
        verts = cs.vertices
        nxt = np.arange(verts.shape[0]) + 1
        nxt[cs.offsets[1:] - 1] = cs.offsets[:-1]
        prv = np.arange(verts.shape[0]) - 1
        prv[cs.offsets[:-1]] = cs.offsets[1:] - 1
        self.corner_vertex = verts
        self.corner_prev = verts[prv]
        self.corner_next = verts[nxt]
        self.corner_owner = owner
        vc = sparse.csr_matrix(
            (np.arange(1, verts.shape[0] + 1), (verts, owner)), shape=(n, len(cs))
        )
        vc.sort_indices()
        self.vertex_cycles = vc  # data - 1 = corner index

    def cycles_at_edge(self, e: int) -> np.ndarray:
        ec = self.edge_cycles
        return ec.indices[ec.indptr[e] : ec.indptr[e + 1]]

    def corners_at_vertex(self, v: int):
        vc = self.vertex_cycles
        lo, hi = vc.indptr[v], vc.indptr[v + 1]
        return vc.indices[lo:hi], vc.data[lo:hi] - 1


class _Budget(Exception):
    pass


def _solve_component(prob: _Problem, comp, state, rank, conflicts, budget):
    """Strict DPLL search on one component; mutates ``state`` (1/0) on success."""
    comp = sorted(comp, key=lambda c: rank[c])
    comp_set = set(comp)
    edges = sorted({int(e) for c in comp for e in prob.cycle_edge_ids[c]})
    cnt = {}
    rem = {}
    for e in edges:
        cyc = prob.cycles_at_edge(e)
        cnt[e] = int(sum(1 for c in cyc if state[c] == 1))
        rem[e] = int(sum(1 for c in cyc if int(c) in comp_set))
    verts = sorted({int(v) for c in comp for v in prob.cycle_vertices[c]})
    vrem = {}
    for v in verts:
        cyc, _ = prob.corners_at_vertex(v)
        vrem[v] = int(sum(1 for c in cyc if int(c) in comp_set))
    x = {c: -1 for c in comp}
    has_fixed = bool(np.any(state == 1))
    trail: list[int] = []
    counter = [0]

    def vertex_ok(v):
        cyc, corner = prob.corners_at_vertex(v)
        pairs = []
        for c, k in zip(cyc, corner):
            c = int(c)
            on = x[c] == 1 if c in x else state[c] == 1
            if on:
                pairs.append((int(prob.corner_prev[k]), int(prob.corner_next[k])))
        if vrem[v] == 0:
            return link_is_disk(pairs)
        return _link_is_partial_ok(pairs)

    def assign(c, val, queue_e, queue_v):
        counter[0] += 1
        if counter[0] > budget:
            raise _Budget
        x[c] = val
        trail.append(c)
        for e in prob.cycle_edge_ids[c]:
            e = int(e)
            rem[e] -= 1
            if val == 1:
                cnt[e] += 1
            queue_e.append(e)
        for v in prob.cycle_vertices[c]:
            v = int(v)
            vrem[v] -= 1
            queue_v.append(v)

    def unassign_to(mark):
        while len(trail) > mark:
            c = trail.pop()
            val = x[c]
            for e in prob.cycle_edge_ids[c]:
                e = int(e)
                rem[e] += 1
                if val == 1:
                    cnt[e] -= 1
            for v in prob.cycle_vertices[c]:
                vrem[int(v)] += 1
            x[c] = -1

    def propagate(queue_e, queue_v):
        while queue_e or queue_v:
            if queue_e:
                e = queue_e.pop()
                ce, re = cnt[e], rem[e]
                if ce > 2:
                    return False
                if re == 0:
                    if ce == 1 and prob.n_cycles_at_edge[e] > 1:
                        return False
                    continue
                und = [int(c) for c in prob.cycles_at_edge(e) if int(c) in x and x[int(c)] == -1]
                if ce == 2:
                    for c in und:
                        if x[c] == -1:
                            assign(c, 0, queue_e, queue_v)
                elif ce == 1 and re == 1:
                    c = und[0]
                    assign(c, 1, queue_e, queue_v)
                    for d in conflicts.get(c, ()):
                        if d in x:
                            if x[d] == 1:
                                return False
                            if x[d] == -1:
                                assign(d, 0, queue_e, queue_v)
                        elif state[d] == 1:
                            return False
                elif ce == 0 and re == 1:
                    assign(und[0], 0, queue_e, queue_v)
            else:
                v = queue_v.pop()
                if not vertex_ok(v):
                    return False
        return True

    def choose():
        # the best-ranked undecided cycle on an edge that still needs one use,
        # else the best-ranked undecided cycle: decisions follow geometry only
        pick = None
        for c in comp:  # comp is sorted by rank
            if x[c] != -1:
                continue
            if pick is None:
                pick = c
            if any(cnt[int(e)] == 1 for e in prob.cycle_edge_ids[c]):
                return c
        return pick

    def set_and_propagate(c, val):
        qe: list[int] = []
        qv: list[int] = []
        if val == 1:
            for d in conflicts.get(c, ()):
                if d in x:
                    if x[d] == 1:
                        return False
                elif state[d] == 1:
                    return False
        assign(c, val, qe, qv)
        if val == 1:
            for d in conflicts.get(c, ()):
                if d in x and x[d] == -1:
                    assign(d, 0, qe, qv)
        return propagate(qe, qv)

    def _all_attached(chosen):
        # every chosen cycle must reach a fixed face through chosen faces
        reached: set[int] = set()
        for c0 in chosen:
            if c0 in reached:
                continue
            seen = {c0}
            stack = [c0]
            ok = False
            while stack:
                c = stack.pop()
                for e in prob.cycle_edge_ids[c]:
                    for d in prob.cycles_at_edge(int(e)):
                        d = int(d)
                        if d in seen:
                            continue
                        if d in x:
                            if x[d] == 1:
                                seen.add(d)
                                stack.append(d)
                        elif state[d] == 1:
                            ok = True
            if not ok:
                return False
            reached |= seen
        return True

    def search():
        c = choose()
        if c is None:
            return not has_fixed or _all_attached([d for d in comp if x[d] == 1])
        for val in (1, 0):
            mark = len(trail)
            if set_and_propagate(c, val) and search():
                return True
            unassign_to(mark)
        return False

    # initial propagation over everything
    qe = list(edges)
    qv = list(verts)
    ok = propagate(qe, qv) and search()
    if ok:
        for c in comp:
            state[c] = 1 if x[c] == 1 else 0
    return ok, counter[0]


def _addable(prob: _Problem, c: int, state, use, conflicts) -> bool:
    """Whether cycle ``c`` keeps the invariant: no edge above two uses, no
    conflict with a selected cycle, every vertex link still able to become
    a disk."""
    if any(use[int(e)] >= 2 for e in prob.cycle_edge_ids[c]):
        return False
    if any(state[d] == 1 for d in conflicts.get(c, ())):
        return False
    state[c] = 1
    try:
        for v in prob.cycle_vertices[c]:
            cyc, corner = prob.corners_at_vertex(int(v))
            pairs = [
                (int(prob.corner_prev[k]), int(prob.corner_next[k]))
                for d, k in zip(cyc, corner)
                if state[d] == 1
            ]
            if not _link_is_partial_ok(pairs):
                return False
        return True
    finally:
        state[c] = 0


def _front_greedy(prob: _Problem, comp, state, rank, conflicts):
    """Fallback: grow the surface from its boundary, as Algorithm 4 does.

    Algorithm 4 adds a cycle only where it meets the basis along an edge used
    once (its rule ii).  This takes that order greedily: of the cycles that
    touch the current boundary and keep the invariant (:func:`_addable`), the
    one that closes the most boundary edges net of the new ones it opens
    (edges used once minus edges unused), then the best-ranked; when no
    cycle touches the boundary, the best-ranked addable cycle starts a new
    front.  A cycle that breaks the invariant once never becomes addable
    again (edge uses and conflicts only grow; a link that cannot become a
    disk stays so), so each is rejected at most once.  Deterministic: the
    rank is a total order.
    """
    import heapq

    comp = sorted(comp, key=lambda c: rank[c])
    for c in comp:
        state[c] = 0
    use: dict[int, int] = {}
    at_edge: dict[int, list[int]] = {}
    for c in comp:
        for e in prob.cycle_edge_ids[c]:
            e = int(e)
            at_edge.setdefault(e, []).append(c)
            if e not in use:
                use[e] = int(sum(1 for d in prob.cycles_at_edge(e) if state[d] == 1))
    dead: set[int] = set()

    def key(c):
        ones = sum(1 for e in prob.cycle_edge_ids[c] if use[int(e)] == 1)
        zeros = sum(1 for e in prob.cycle_edge_ids[c] if use[int(e)] == 0)
        return ones, (zeros - ones, int(rank[c]))

    heap: list = []
    current: dict[int, tuple] = {}

    def push(c):
        ones, k = key(c)
        current[c] = k
        if ones:
            heapq.heappush(heap, (k, c))

    for c in comp:
        push(c)
    seeds = iter(comp)
    while True:
        pick = None
        while heap:
            k, c = heapq.heappop(heap)
            if state[c] == 1 or c in dead or current.get(c) != k:
                continue  # stale entry
            if _addable(prob, c, state, use, conflicts):
                pick = c
                break
            dead.add(c)
        if pick is None:  # nothing touches the boundary: a new front
            for c in seeds:
                if state[c] != 1 and c not in dead:
                    if _addable(prob, c, state, use, conflicts):
                        pick = c
                        break
                    dead.add(c)
        if pick is None:
            return
        state[pick] = 1
        touched = set()
        for e in prob.cycle_edge_ids[pick]:
            e = int(e)
            use[e] += 1
            touched.update(at_edge[e])
        for d in sorted(touched):
            if state[d] != 1 and d not in dead:
                push(d)


def _edge_linked(prob: _Problem, mask: np.ndarray, n_edges: int) -> np.ndarray:
    """Component labels of the cycles in ``mask`` linked through shared edges
    (indexed by cycle; the graph's other nodes are the edges)."""
    nc = mask.shape[0]
    inc = mask[prob.inc_cycle]
    g = sparse.csr_matrix(
        (np.ones(int(inc.sum()), dtype=np.int8), (prob.inc_cycle[inc], prob.inc_edge[inc] + nc)),
        shape=(nc + n_edges, nc + n_edges),
    )
    return csgraph.connected_components(g, directed=False)[1]


def _detaching(prob: _Problem, state: np.ndarray, edges, n: int, reach: int = 2) -> np.ndarray:
    """The candidate cycles to decide again where the selection has a
    detached piece: a closed piece of the surface (faces linked through
    shared edges, each of its edges used twice) other than the largest (most
    faces, then the lowest cycle) on one connected piece of the graph.
    Every cycle with a sample within ``reach`` graph edges of a detached
    piece's samples is returned (the faces that closed the big piece off
    next to it among them)."""
    sel = state == 1
    if not sel.any():
        return np.empty(0, dtype=np.int64)
    inc = sel[prob.inc_cycle]
    piece = _edge_linked(prob, sel, edges.shape[0])
    gs = sparse.csr_matrix(
        (np.ones(edges.shape[0], dtype=np.int8), (edges[:, 0], edges[:, 1])), shape=(n, n)
    )
    gs = gs + gs.T
    _, part = csgraph.connected_components(gs, directed=False)
    faces = np.flatnonzero(sel)
    of_face = piece[faces]
    size = np.bincount(of_face)
    # every piece's lowest cycle (faces ascend), and the graph piece it lies on
    pieces, at = np.unique(of_face, return_index=True)
    first = faces[at]
    on = part[[int(prob.cycle_vertices[c][0]) for c in first.tolist()]]
    # on each graph piece the largest piece of surface, then the lowest cycle, stays
    order = np.lexsort((first, -size[pieces], on))
    lead = np.r_[True, on[order][1:] != on[order][:-1]]
    keep = pieces[order[lead]]
    # only closed pieces (every edge of theirs used twice) are detached: a
    # piece with a boundary is a part the rest of the selection completes
    use = np.bincount(prob.inc_edge[inc], minlength=edges.shape[0])
    open_piece = np.zeros(size.shape[0], dtype=bool)
    at_open = inc & (use[prob.inc_edge] != 2)
    open_piece[piece[prob.inc_cycle[at_open]]] = True
    lost = faces[~np.isin(of_face, keep) & ~open_piece[of_face]]
    if lost.size == 0:
        return np.empty(0, dtype=np.int64)
    near = np.zeros(n, dtype=bool)
    near[np.concatenate([prob.cycle_vertices[c] for c in lost])] = True
    for _ in range(reach):
        near = near | (gs @ near.astype(np.int64) > 0)
    return np.unique(prob.corner_owner[near[prob.corner_vertex]])


def _region(prob: _Problem, failed: list[int], lone_edge: np.ndarray, n: int) -> np.ndarray:
    """The cycles the exact selection re-decides: the failed components, and the
    cycles fixed next to them (sharing a sample) because one of their edges lies
    in no other candidate (right on a true boundary, wrong on a closed surface)."""
    near = np.zeros(n, dtype=bool)
    for c in failed:
        near[prob.cycle_vertices[c]] = True
    lone_cycle = np.zeros(len(prob.cycle_vertices), dtype=bool)
    lone_cycle[np.unique(prob.inc_cycle[lone_edge[prob.inc_edge]])] = True
    touch = np.zeros(len(prob.cycle_vertices), dtype=bool)
    touch[np.unique(prob.corner_owner[near[prob.corner_vertex]])] = True
    return np.union1d(np.asarray(failed, dtype=np.int64), np.flatnonzero(lone_cycle & touch))


def backtracking(
    points,
    edges,
    cycles: CycleSet,
    *,
    tolerance: Tolerance = DEFAULT,
    k: int | None = None,
    neighbourhoods: Neighbourhoods | None = None,
    budget: int = 20000,
    exact_seconds: float = 5.0,
    quiet: bool = True,
) -> FaceSelection:
    """Backtracking({}, {◇_i}, k): Algorithm 4, a closed manifold set of face cycles.

    See the module docstring for the design and the lemmas each part relies
    on.  Departures from the paper: candidates are decided by constraint
    propagation over independent components rather than one global
    recursion, the vertex link condition stands in for
    "Conv(N(u; k)) ∩ P' is a disk", and a per-component budget bounds the
    search (exhausting it is reported, never silent).

    Parameters
    ----------
    points : (n, 3) array_like of float
        The samples.
    edges : (m, 2) array_like of int
        The localized RNG (sorted rows ``a < b``).
    cycles : CycleSet
        Candidate cycles, normally from :func:`trivial_isometric_cycles`.
    tolerance : Tolerance
        ``fold_degrees`` decides which neighbouring cycles fold onto each other.
    k : int, optional
        Neighbourhood size; when given, the neighbourhood form of the success
        condition is evaluated (``non_disk_neighbourhoods``).
    neighbourhoods : Neighbourhoods, optional
        The N(u; k) already computed for these points with this ``k`` (as in
        :attr:`LocalizedRNG.neighbourhoods`), to avoid recomputing them.
    budget : int
        Maximum assignments of the strict search per component.
    exact_seconds : float
        Budget of the exact selection (:mod:`sr33.selection`) per model of
        a region component where the strict search failed; 0 keeps the
        greedy answer.
    quiet : bool
        Hide the progress bar.

    Returns
    -------
    FaceSelection

    Examples
    --------
    >>> import numpy as np
    >>> from sr33 import backtracking, localized_rng, trivial_isometric_cycles
    >>> tet = np.array([[1, 1, 1], [1, -1, -1], [-1, 1, -1], [-1, -1, 1]], float)
    >>> g = localized_rng(tet, 3).edges
    >>> sel = backtracking(tet, g, trivial_isometric_cycles(g, 4))
    >>> len(sel.faces), sel.success, sel.open_edges.shape
    (4, True, (0, 2))
    """
    pts = as_points(points)
    n = pts.shape[0]
    e = as_edges(edges, n)
    e = unique_edges(e) if e.shape[0] else e
    if not isinstance(budget, (int, np.integer)) or budget < 1:
        raise InputError(f"budget must be a positive integer, got {budget!r}")
    if not isinstance(exact_seconds, (int, float, np.integer, np.floating)) or not (
        0 <= float(exact_seconds) < float("inf")
    ):
        raise InputError(f"exact_seconds must be a finite number >= 0, got {exact_seconds!r}")
    nc = len(cycles)
    if nc == 0:
        return FaceSelection(
            faces=cycles,
            selected=np.zeros(0, bool),
            success=False,
            open_edges=np.empty((0, 2), np.int64),
            unresolved_samples=np.arange(n, dtype=np.int64),
            components=0,
            fallback_components=0,
            assignments=0,
            notes=("no candidate cycles",),
        )
    prob = _Problem(cycles, e, n)
    centroid, flat = _cycle_geometry(pts, cycles)
    spread = np.linalg.norm(centroid - pts.mean(axis=0), axis=1)
    area = _cycle_area(pts, cycles, centroid)
    rank = _rank(cycles, area, flat, spread)
    folds = _fold_pairs(pts, e, prob.inc_edge, prob.inc_cycle, centroid, tolerance.fold_degrees)
    conflicts: dict[int, list[int]] = {}
    for a, b in folds:
        conflicts.setdefault(int(a), []).append(int(b))
        conflicts.setdefault(int(b), []).append(int(a))

    ambiguous_edge = prob.n_cycles_at_edge >= 3
    free = np.zeros(nc, dtype=bool)
    free[np.unique(prob.inc_cycle[ambiguous_edge[prob.inc_edge]])] = True
    if folds.shape[0]:
        free[folds.ravel()] = True
    # free cycles whose surfaces cross each other (or a fixed cycle) are never
    # selected together: Triangulate needs disjoint interiors (Section 4)
    for a, b in _crossing_pairs(pts, cycles, centroid, free).tolist():
        conflicts.setdefault(int(a), []).append(int(b))
        conflicts.setdefault(int(b), []).append(int(a))
    state = np.where(free, -1, 1).astype(np.int64)

    # components of free cycles linked through shared edges
    free_idx = np.flatnonzero(free)
    comps: list[list[int]] = []
    if free_idx.shape[0]:
        lab = _edge_linked(prob, free, e.shape[0])[free_idx]
        order = np.argsort(lab, kind="stable")
        lab_sorted = lab[order]
        splits = np.flatnonzero(np.diff(lab_sorted)) + 1
        comps = [list(map(int, g)) for g in np.split(free_idx[order], splits)]
        comps.sort(key=lambda g: min(rank[c] for c in g))

    old_limit = sys.getrecursionlimit()
    sys.setrecursionlimit(max(old_limit, 20000))
    total = 0
    fallback = 0
    failed: list[int] = []
    try:
        with bar(len(comps), "backtracking", quiet) as pbar:
            for comp in comps:
                snapshot = state.copy()
                try:
                    ok, used = _solve_component(prob, comp, state, rank, conflicts, budget)
                except _Budget:
                    ok, used = False, budget
                total += used
                if not ok:
                    state[:] = snapshot
                    fallback += 1
                    failed.extend(comp)
                    _front_greedy(prob, comp, state, rank, conflicts)
                pbar.update(1)
    finally:
        sys.setrecursionlimit(old_limit)

    # Section 5's success condition, one surface per connected piece of the
    # samples: components decided on their own can close a piece off (a
    # cone's apex capped ring by ring); the cycles round it go to the
    # fallback, whose exact selection forbids detached bubbles (the failed
    # components' greedy answers are left out: it re-decides them anyway)
    failed_idx = np.asarray(failed, dtype=np.int64)
    decided = state.copy()
    decided[failed_idx] = 0
    redo = np.setdiff1d(_detaching(prob, decided, e, n), failed_idx)
    if redo.size:
        log.debug("backtracking: %d cycles round detached pieces decided again", redo.size)
        state[redo] = -1
        failed.extend(redo.tolist())
        _front_greedy(prob, redo.tolist(), state, rank, conflicts)

    exact = ExactReport()
    lone_edge = prob.n_cycles_at_edge == 1
    if failed and exact_seconds > 0:
        region = _region(prob, failed, lone_edge, n)
        # the region's fixed cycles were not free: only their crossings are new
        mask = np.zeros(nc, dtype=bool)
        mask[region] = True
        mask &= ~free
        exact_conflicts = {c: list(d) for c, d in conflicts.items()}
        for a, b in _crossing_pairs(pts, cycles, centroid, mask).tolist():
            if b not in exact_conflicts.get(a, ()):
                exact_conflicts.setdefault(int(a), []).append(int(b))
                exact_conflicts.setdefault(int(b), []).append(int(a))
        incidence = Incidence(
            prob.cycle_edge_ids,
            prob.cycle_vertices,
            prob.corner_owner,
            prob.corner_vertex,
            prob.corner_prev,
            prob.corner_next,
            e,
            n,
            # areas in sixteenths of the median cycle's (integers for CP-SAT)
            np.round(16.0 * area / max(float(np.median(area)), 1e-300)).astype(np.int64),
        )
        exact = exact_selection(
            incidence,
            state,
            region,
            exact_conflicts,
            seconds=exact_seconds,
        )
    selected = state == 1
    faces = cycles.subset(selected)
    # final checks: edge use, links, coverage
    use = np.bincount(prob.inc_edge[selected[prob.inc_cycle]], minlength=e.shape[0])
    open_edges = e[use == 1]
    over = int((use > 2).sum())
    sel_corner = selected[prob.corner_owner]
    disk = links_are_disks(
        n,
        prob.corner_vertex[sel_corner],
        prob.corner_prev[sel_corner],
        prob.corner_next[sel_corner],
    )
    unresolved = np.flatnonzero(~disk)
    unresolved_arr = unresolved.astype(np.int64)
    # the paper's success condition: no overload, every used sample's link a
    # disk, open edges only where an edge lies in one candidate (a true
    # boundary); stray samples are allowed (cones attach them, Section 5)
    used_sample = np.zeros(n, dtype=bool)
    used_sample[prob.corner_vertex[sel_corner]] = True
    success = (
        len(faces) > 0
        and over == 0
        and not np.any(used_sample & ~disk)
        and not np.any((use == 1) & ~lone_edge)
    )
    non_disk = np.empty(0, dtype=np.int64)
    if (k is not None or neighbourhoods is not None) and len(faces):
        nb = neighbourhoods or k_neighbourhoods(pts, k, tolerance=tolerance)
        f_pairs, f_owner = cycle_edges(faces.offsets, faces.vertices)
        f_eid = lookup_edges(e, f_pairs, n)
        vc = sparse.csr_matrix(
            (np.ones(f_owner.shape[0], dtype=np.int8), (faces.vertices, f_owner)),
            shape=(n, len(faces)),
        )
        vc.sort_indices()
        chi, ncomp, _ = _kernels.neighbourhood_disks(
            nb.indptr,
            nb.indices,
            faces.offsets,
            faces.vertices,
            f_eid,
            vc.indptr.astype(np.int64),
            vc.indices.astype(np.int64),
            e.shape[0],
        )
        non_disk = np.flatnonzero((chi != 1) | (ncomp != 1)).astype(np.int64)
    notes = []
    if over:
        notes.append(f"{over} edges used more than twice")
    return FaceSelection(
        faces=faces,
        selected=selected,
        success=bool(success),
        open_edges=open_edges,
        unresolved_samples=unresolved_arr,
        components=len(comps),
        fallback_components=fallback,
        assignments=total,
        non_disk_neighbourhoods=non_disk,
        notes=tuple(notes),
        exact=exact,
        true_boundary=lone_edge[use == 1],
    )
