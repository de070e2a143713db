"""Exact selection of face cycles where the backtracking search fails (Section 4).

Algorithm 4 asks for a maximal set of face cycles in which every edge is
used at most twice and every sample's neighbourhood is a disk.  The
propagation search of :mod:`sr33.backtracking` decides almost every
component at once; where it proves a component infeasible or runs out of
budget (acute sharp edges, where the Euclidean RNG loses within-face edges
and the strict rules leave no closed choice), this module solves the same
selection exactly, as a constraint program (OR-Tools CP-SAT, one worker,
fixed seed, a deterministic-time budget: the same model always gives the
same answer).

The model, over the cycles of one *region* (the failed components and the
cycles fixed next to them), with the rest of the selection held fixed:

* ``x_c`` — cycle ``c`` is a face;
* every edge is used ``2 y_e + o_e`` times (``o_e`` = open); the first
  round allows no open edge at all (a closed surface, Section 4's aim), the
  second allows open edges and minimises them;
* folding or crossing cycles are never both faces (the conflicts of
  :mod:`sr33.backtracking`);
* a sample is *stray* when no face uses it: the paper's success condition
  allows that and attaches it later with cones (end of Section 5);
* the link of every sample is one cycle or one path (the vertex form of
  "Conv(N(u; k)) ∩ P' is a disk"): a circuit constraint per sample, added
  lazily at the samples where a solution was pinched;
* no detached closed bubble: every face reaches a face outside the region
  through faces.  First by lazy cuts only (a connectivity cut per bubble
  found: a face of it needs a neighbouring face outside it); where those
  rounds keep finding new bubbles until the budget ends, the closed model
  is solved again with rooted connectivity by levels up front (slower per
  model, but it settles).  Where the component touches no outside face,
  its largest piece is kept;
* where the closed model is proven infeasible with the selection round
  the component held fixed, the cycles sharing a sample with the model
  are freed and it is solved again (up to ``rings`` times): on input that
  does not conform, a face decided on its own (no candidate competes for
  its edges) can be what makes closing impossible.  Still infeasible, the
  component is repaired round each cluster of its defects (open or
  overloaded edges, pinched samples of the selection given), a window at
  a time: the window's closed models, else its open model.  Out of time
  instead, the open model of the whole component (and the windows of at
  most half of it).

Components are solved side by side first (one thread each, up to numba's
thread count): their models read disjoint parts of the selection, CP-SAT
releases the GIL while it solves, and every model runs on one worker, so
the answers do not depend on the number of threads.  They are then taken
in component order; an answer whose model read a cycle an earlier answer
changed (a grown model reaching another component) or that crosses an
earlier answer is solved again next to it.

The objective is lexicographic: open edges (the open model only), then
stray samples, then the total area of the faces (``Incidence.cycle_cost``:
each cycle's fan area in units of a sixteenth of the median cycle's).  Of
the closed selections with the same coverage, the least area is the one
that follows the surface: at an acute sharp edge, where the Euclidean RNG
joins samples across the edge at every scan height, a stack of such
"plates" closes the surface too, but folded like an accordion about a
sample spacing deep; a smaller-faces-first tie-break chose the plates
(they are triangles).  The Euler characteristic is not in the objective
(it rewards detached bubbles, which the lazy cuts then chase round by
round): an answer is taken only when it is valid (edge use at most two,
links disks) and strictly better than the selection it replaces (the
closed model: no open edge, then the region's Euler characteristic,
highest first, then stray samples, then area; the open model: open edges
and strays, then area), so the result is never worse than the greedy
fallback and never buys coverage with a handle.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import sparse
from scipy.sparse import csgraph

from .graph import link_is_disk
from .progress import log
from .threads import thread_map

#: CP-SAT deterministic time per second of ``seconds``: on the models first
#: measured one deterministic unit took about four seconds of one core, on
#: cheburashka's (stop 45) two to three, so ``seconds`` is at most about
#: wall-clock seconds (the limit itself is machine-independent)
_DET_PER_SECOND = 0.25

#: CP-SAT's parameters: one worker, a fixed seed, no randomisation (the same
#: model always gives the same answer); the search starts from the
#: objective's lower bound (the area tie-break is what takes the time: on
#: cheburashka's models this proves the optimum about 2x sooner than the
#: default; the LP with every constraint linearised and core-based
#: optimisation did so 2.4x sooner there but took 2.3x longer on
#: star_prism's, whose lazy rounds re-solve the model many times; stop 46)
_PARAMETERS = {
    "num_workers": 1,
    "random_seed": 0,
    "randomize_search": False,
    "use_objective_lb_search": True,
}


@dataclass(frozen=True)
class ExactReport:
    """What :func:`exact_selection` did.

    Attributes
    ----------
    components : int
        Region components solved (connected through shared samples).
    improved : int
        Components whose answer replaced the selection given.
    proven : int
        Components whose answer is proven optimal for the model.
    cuts : int
        Lazy constraints added (vertex links and bubbles).
    grown : int
        Components closed only once the faces round them were freed (their
        closed model was infeasible with those faces held fixed).
    """

    components: int = 0
    improved: int = 0
    proven: int = 0
    cuts: int = 0
    grown: int = 0

    def as_tuple(self) -> tuple[int, int, int, int, int]:
        """(components, improved, proven, cuts, grown)."""
        return (self.components, self.improved, self.proven, self.cuts, self.grown)


@dataclass
class _Tables:
    """Incidence of the cycles, edges and corners (all cycles, not one region)."""

    cycle_edges: list  # per cycle: its edge ids
    cycle_vertices: list  # per cycle: its vertices
    edge_cycles: sparse.csr_matrix  # edge -> cycles
    vertex_corners: sparse.csr_matrix  # vertex -> corner index + 1
    corner_owner: np.ndarray
    corner_prev: np.ndarray
    corner_next: np.ndarray
    edges: np.ndarray  # (m, 2) the edges (a < b), by id
    edge_keys: np.ndarray  # a * n + b of every edge, ascending
    edge_order: np.ndarray  # edge ids in that order
    n_points: int
    cost: np.ndarray  # per cycle: its quantized area, the objective's last term

    def edge_id(self, a: int, b: int) -> int:
        """The id of the edge (a, b) (it must be an edge)."""
        key = min(a, b) * self.n_points + max(a, b)
        return int(self.edge_order[np.searchsorted(self.edge_keys, key)])

    def cycles_at_edge(self, e: int) -> np.ndarray:
        ec = self.edge_cycles
        return ec.indices[ec.indptr[e] : ec.indptr[e + 1]]

    def corners_at(self, v: int) -> np.ndarray:
        vc = self.vertex_corners
        return vc.data[vc.indptr[v] : vc.indptr[v + 1]] - 1


@dataclass(frozen=True)
class Incidence:
    """The candidate cycles as :func:`exact_selection` reads them.

    Attributes
    ----------
    cycle_edge_ids, cycle_vertices : list of (L,) int64 arrays
        Every candidate cycle's edge ids and vertices.
    corner_owner, corner_vertex, corner_prev, corner_next : (s,) int64
        Every corner (cycle, vertex, previous and next vertex on the cycle).
    edges : (m, 2) int64
        The graph's edges (sorted rows), indexed by the edge ids.
    n_points : int
        Number of samples.
    cycle_cost : (c,) int64
        Every cycle's area, quantized (the objective's last term).
    """

    cycle_edge_ids: list
    cycle_vertices: list
    corner_owner: np.ndarray
    corner_vertex: np.ndarray
    corner_prev: np.ndarray
    corner_next: np.ndarray
    edges: np.ndarray
    n_points: int
    cycle_cost: np.ndarray


def _tables(inc: Incidence) -> _Tables:
    ids = inc.cycle_edge_ids
    owner = np.repeat(np.arange(len(ids)), [len(c) for c in ids])
    flat = np.concatenate(ids) if len(ids) else np.empty(0, np.int64)
    edges = np.asarray(inc.edges, dtype=np.int64).reshape(-1, 2)
    ec = sparse.csr_matrix(
        (np.ones(flat.shape[0], dtype=np.int8), (flat, owner)), shape=(edges.shape[0], len(ids))
    )
    ec.sort_indices()
    s = inc.corner_vertex.shape[0]
    vc = sparse.csr_matrix(
        (np.arange(1, s + 1), (inc.corner_vertex, np.arange(s))), shape=(inc.n_points, s)
    )
    vc.sort_indices()
    keys = edges[:, 0] * inc.n_points + edges[:, 1]
    order = np.argsort(keys, kind="stable")
    return _Tables(
        list(ids),
        list(inc.cycle_vertices),
        ec,
        vc,
        inc.corner_owner,
        inc.corner_prev,
        inc.corner_next,
        edges,
        keys[order],
        order,
        inc.n_points,
        np.asarray(inc.cycle_cost, dtype=np.int64),
    )


@dataclass(frozen=True)
class _Score:
    over: int
    open: int
    open_lone: int
    minus_chi: int
    strays: int
    area: int

    def better_than(self, old: _Score, closed: bool) -> bool:
        """The order answers are taken in (closed: Euler characteristic
        first, which the model itself does not weigh; open: the model's)."""
        if self.over:
            return False
        if old.over or (closed and old.open):
            return True
        if closed:
            return (self.minus_chi, self.strays, self.area) < (
                old.minus_chi,
                old.strays,
                old.area,
            )
        key = (self.open + self.strays, self.open_lone, self.area)
        return key < (old.open + old.strays, old.open_lone, old.area)


def _uses(tab: _Tables, state: np.ndarray, edges_) -> dict[int, int]:
    """How many selected cycles use each of ``edges_``."""
    return {e: int(sum(1 for c in tab.cycles_at_edge(e) if state[c] == 1)) for e in edges_}


def _score(tab: _Tables, state: np.ndarray, cycles, edges_, verts, lone) -> _Score:
    """(overloaded, open, open true-boundary edges, -Euler characteristic,
    strays, quantized area) of ``state`` over a region: the model's
    objective, lexicographic."""
    use = _uses(tab, state, edges_)
    over = sum(1 for u in use.values() if u > 2)
    open_ = sum(1 for e, u in use.items() if u == 1 and e not in lone)
    open_lone = sum(1 for e, u in use.items() if u == 1 and e in lone)
    used_e = sum(1 for u in use.values() if u > 0)
    cov = 0
    for v in verts:
        if any(state[tab.corner_owner[k]] == 1 for k in tab.corners_at(v)):
            cov += 1
    faces = sum(1 for c in cycles if state[c] == 1)
    chi = cov - used_e + faces
    area = sum(int(tab.cost[c]) for c in cycles if state[c] == 1)
    return _Score(over, open_, open_lone, -chi, len(verts) - cov, area)


def _link_ok(tab: _Tables, state: np.ndarray, v: int) -> bool:
    """Whether the selected corners at ``v`` form one path or one cycle (or none)."""
    pairs = [
        (int(tab.corner_prev[k]), int(tab.corner_next[k]))
        for k in tab.corners_at(v)
        if state[tab.corner_owner[k]] == 1
    ]
    return not pairs or link_is_disk(pairs)


def _bubbles(tab: _Tables, state: np.ndarray, cycles, outside_faces: bool) -> list[list[int]]:
    """Connected sets of selected region cycles that touch no selected cycle outside.

    When nothing outside the region is selected, the largest set (then the
    one with the smallest cycle index) is kept and the others are bubbles.
    """
    region = [c for c in cycles if state[c] == 1]
    if not region:
        return []
    index = {c: i for i, c in enumerate(region)}
    rows, cols = [], []
    anchored = np.zeros(len(region), dtype=bool)
    for c in region:
        for e in tab.cycle_edges[c]:
            for d in tab.cycles_at_edge(int(e)):
                d = int(d)
                if d == c or state[d] != 1:
                    continue
                if d in index:
                    rows.append(index[c])
                    cols.append(index[d])
                else:
                    anchored[index[c]] = True
    g = sparse.csr_matrix(
        (np.ones(len(rows), dtype=np.int8), (rows, cols)), shape=(len(region), len(region))
    )
    ncomp, labels = csgraph.connected_components(g, directed=False)
    groups = [[region[i] for i in np.flatnonzero(labels == j)] for j in range(ncomp)]
    if outside_faces:
        return [grp for j, grp in enumerate(groups) if not anchored[labels == j].any()]
    keep = max(range(ncomp), key=lambda j: (len(groups[j]), -min(groups[j])))
    return [grp for j, grp in enumerate(groups) if j != keep]


def _touches_outside(tab: _Tables, state: np.ndarray, cycles) -> bool:
    """Whether a selected cycle outside ``cycles`` shares an edge with one of them."""
    inside = set(cycles)
    return any(
        int(d) not in inside and state[d] == 1
        for c in cycles
        for e in tab.cycle_edges[c]
        for d in tab.cycles_at_edge(int(e))
    )


def _connect(m, tab, state, cycles, cyc_set, x) -> None:
    """Every face of the region reaches a face outside it through faces.

    Rooted connectivity by levels: a face next to a fixed face outside may
    take level 0; any other face needs a neighbouring face (sharing an edge)
    of a lower level.  This forbids detached bubbles up front.
    """
    depth = len(cycles)
    level = {c: m.NewIntVar(0, depth, f"l{c}") for c in cycles}
    for c in cycles:
        anchored = False
        preds = []
        for e in tab.cycle_edges[c]:
            for d in tab.cycles_at_edge(int(e)):
                d = int(d)
                if d == c:
                    continue
                if d not in cyc_set:
                    anchored = anchored or state[d] == 1
                    continue
                preds.append(d)
        if anchored:
            continue
        lits = []
        for d in sorted(set(preds)):
            a = m.NewBoolVar("")
            m.AddImplication(a, x[d])
            m.Add(level[d] < level[c]).OnlyEnforceIf(a)
            lits.append(a)
        m.AddBoolOr(lits + [x[c].Not()])


def _solve_component(
    tab, state, cycles, conflicts, lone, seconds, max_rounds, links, allow_open, outside, levels
):
    """One CP-SAT model over ``cycles``, lazy rounds until valid.

    ``links`` are the samples whose link circuit is added up front; it is
    extended with the samples cut lazily.  ``outside``: a selected cycle
    outside ``cycles`` shares an edge with them (:func:`_touches_outside`,
    the same for every model of one component: only its cycles change).
    ``levels``: forbid detached bubbles up front (:func:`_connect`) instead
    of by lazy cuts only.
    Returns (new state or None, proven -- optimal, or with None infeasible --,
    cuts).
    """
    from ortools.sat.python import cp_model

    cyc_set = set(cycles)
    edges_, verts = _extent(tab, cycles)
    m = cp_model.CpModel()
    x = {c: m.NewBoolVar(f"x{c}") for c in cycles}
    hint = {c: int(state[c] == 1) for c in cycles}
    for c, val in hint.items():
        m.AddHint(x[c], val)
    y, o = {}, {}
    for e in edges_:
        at = [int(c) for c in tab.cycles_at_edge(e)]
        fixed = sum(1 for c in at if c not in cyc_set and state[c] == 1)
        terms = [x[c] for c in at if c in cyc_set]
        y[e] = m.NewBoolVar(f"y{e}")
        if allow_open:
            o[e] = m.NewBoolVar(f"o{e}")
            m.Add(sum(terms) + fixed == 2 * y[e] + o[e])
        else:
            m.Add(sum(terms) + fixed == 2 * y[e])
    for c in cycles:
        for d in conflicts.get(c, ()):
            if d in cyc_set and d > c:
                m.AddBoolOr([x[c].Not(), x[d].Not()])
            elif d not in cyc_set and state[d] == 1:
                m.Add(x[c] == 0)
    # two faces with the same corner (prev, v, next) fold onto each other at v
    # (v would have degree two): at most one of them
    for v in verts:
        groups: dict[tuple[int, int], list[int]] = {}
        for k in tab.corners_at(v):
            a, b = int(tab.corner_prev[k]), int(tab.corner_next[k])
            groups.setdefault((min(a, b), max(a, b)), []).append(int(tab.corner_owner[k]))
        for owners in groups.values():
            if len(owners) < 2:
                continue
            mine = [x[c] for c in owners if c in cyc_set]
            if any(c not in cyc_set and state[c] == 1 for c in owners):
                for lit in mine:
                    m.Add(lit == 0)
            elif len(mine) > 1:
                m.AddAtMostOne(mine)
    cov = {}
    for v in verts:
        ks = tab.corners_at(v)
        owners = sorted({int(tab.corner_owner[k]) for k in ks})
        if any(c not in cyc_set and state[c] == 1 for c in owners):
            cov[v] = 1
            continue
        cv = m.NewBoolVar(f"v{v}")
        mine = [x[c] for c in owners if c in cyc_set]
        for lit in mine:
            m.AddImplication(lit, cv)
        m.AddBoolOr(mine + [cv.Not()])
        cov[v] = cv
    # objective, lexicographic by weights.  Closed model: strays, then
    # area.  Open model (no closed answer):
    # open edges and strays together (a hole and a lost sample weigh the
    # same; removing faces to avoid an open edge loses their samples), then
    # open true-boundary edges, then area.
    ne = len(edges_)
    cost = {c: int(tab.cost[c]) for c in cycles}
    strays = [1 - cov[v] if isinstance(cov[v], int) else cov[v].Not() for v in verts]
    area = sum(cost[c] * x[c] for c in cycles)
    w_stray = 1 + sum(cost.values())
    if allow_open:
        open_bad = [o[e] for e in edges_ if e in o and e not in lone]
        open_lone = [o[e] for e in edges_ if e in o and e in lone]
        w_main = w_stray * (ne + 1)
        obj = w_main * (sum(open_bad) + sum(strays)) + w_stray * sum(open_lone) + area
    else:
        obj = w_stray * sum(strays) + area
    m.Minimize(obj)

    def add_link(v: int) -> None:
        links.add(v)
        ks = tab.corners_at(v)
        node: dict[int, int] = {}
        for k in ks:
            for w in (int(tab.corner_prev[k]), int(tab.corner_next[k])):
                node.setdefault(w, len(node))
        arcs = []
        for k in ks:
            c = int(tab.corner_owner[k])
            p, q = node[int(tab.corner_prev[k])], node[int(tab.corner_next[k])]
            if c in cyc_set:
                a, b = m.NewBoolVar(""), m.NewBoolVar("")
                m.Add(a + b == x[c])
            elif state[c] == 1:
                a, b = m.NewBoolVar(""), m.NewBoolVar("")
                m.Add(a + b == 1)
            else:
                continue
            arcs += [(p, q, a), (q, p, b)]
        dummy = len(node)
        any_open = []
        for w, i in node.items():
            e = tab.edge_id(v, w)
            if e in y:
                used_lit = y[e]
                if e in o:
                    u = m.NewBoolVar("")
                    m.AddBoolOr([y[e], o[e], u.Not()])
                    m.AddImplication(y[e], u)
                    m.AddImplication(o[e], u)
                    used_lit = u
                arcs.append((i, i, used_lit.Not()))
                if e in o:
                    d1, d2 = m.NewBoolVar(""), m.NewBoolVar("")
                    m.Add(d1 + d2 == o[e])
                    arcs += [(dummy, i, d1), (i, dummy, d2)]
                    any_open.append(o[e])
            else:
                at = [int(c) for c in tab.cycles_at_edge(e)]
                fixed = sum(1 for c in at if state[c] == 1)
                if fixed == 0:
                    arcs.append((i, i, m.NewConstant(1)))
                elif fixed == 1:
                    d1, d2 = m.NewBoolVar(""), m.NewBoolVar("")
                    m.Add(d1 + d2 == 1)
                    arcs += [(dummy, i, d1), (i, dummy, d2)]
                    any_open.append(m.NewConstant(1))
        skip = m.NewBoolVar("")
        for lit in any_open:
            m.AddImplication(lit, skip.Not())
        arcs.append((dummy, dummy, skip))
        m.AddCircuit(arcs)

    for v in sorted(links & set(verts)):
        add_link(v)
    # a component next to faces outside it must reach them; one that touches
    # none (a separate object) keeps its largest piece.  Up front by levels,
    # or by the lazy cuts below only
    if outside and levels:
        _connect(m, tab, state, cycles, cyc_set, x)
    elif not outside and not allow_open:
        m.Add(sum(x.values()) >= 1)  # closing a lone component by deleting it
    solver = cp_model.CpSolver()
    for key, value in _PARAMETERS.items():
        setattr(solver.parameters, key, value)
    budget = seconds * _DET_PER_SECOND
    cuts = 0
    best = None
    proven = False
    for _ in range(max_rounds):
        if budget <= 0:
            break
        solver.parameters.max_deterministic_time = budget
        status = solver.Solve(m)
        budget -= solver.deterministic_time
        if status not in (cp_model.OPTIMAL, cp_model.FEASIBLE):
            # INFEASIBLE: proven that no selection meets the model (the lazy
            # cuts only ever add constraints)
            proven = status == cp_model.INFEASIBLE
            break
        trial = state.copy()
        for c in cycles:
            trial[c] = int(solver.Value(x[c]))
        bad = [v for v in verts if v not in links and not _link_ok(tab, trial, v)]
        bubbles = _bubbles(tab, trial, cycles, outside)
        for v in bad:
            add_link(v)
        for grp in bubbles:
            # connectivity cut: a face of the bubble needs a face next to it
            # outside the bubble (every path to the rest leaves through one)
            inside = set(grp)
            ring = sorted(
                {
                    int(d)
                    for c in grp
                    for e in tab.cycle_edges[c]
                    for d in tab.cycles_at_edge(int(e))
                    if int(d) in cyc_set and int(d) not in inside
                }
            )
            for c in grp:
                m.AddBoolOr([x[d] for d in ring] + [x[c].Not()])
        cuts += len(bad) + len(bubbles)
        log.debug(
            "exact selection: %d cycles, open %s, levels %s, status %s, objective %d, "
            "%d pinched samples, %d bubbles, %.2f deterministic s",
            len(cycles),
            allow_open,
            levels,
            solver.StatusName(status),
            solver.ObjectiveValue(),
            len(bad),
            len(bubbles),
            solver.deterministic_time,
        )
        if not bad and not bubbles:
            best = trial
            proven = status == cp_model.OPTIMAL
            break
        # keep the solution as a hint for the next round
        m.ClearHints()
        for c in cycles:
            m.AddHint(x[c], int(trial[c]))
    return best, proven, cuts


def _extent(tab: _Tables, cycles) -> tuple[list[int], list[int]]:
    """The edges and the samples of ``cycles``, sorted."""
    edges_ = sorted({int(e) for c in cycles for e in tab.cycle_edges[c]})
    verts = sorted({int(v) for c in cycles for v in tab.cycle_vertices[c]})
    return edges_, verts


def _ring(tab: _Tables, cycles) -> list[int]:
    """``cycles`` and every cycle with a sample of theirs, sorted."""
    out = set(cycles)
    for v in {int(v) for c in cycles for v in tab.cycle_vertices[c]}:
        out.update(int(c) for c in tab.corner_owner[tab.corners_at(v)])
    return sorted(out)


def _closed(tab, state, cycles, conflicts, lone, seconds, max_rounds, links):
    """The closed models of ``cycles``: lazy bubble cuts, then (next to faces
    outside, where those rounds run out of time) levels.

    Leaves ``state`` as it is (components are solved side by side).
    Returns (an answer was found, proven -- optimal, or without an answer
    infeasible --, cuts, the answer is better than the selection in
    ``state`` and to be taken, the answer or None).
    """
    outside = _touches_outside(tab, state, cycles)
    cuts = 0
    best, prov = None, False
    # lazy bubble cuts first (fast: most models are proven optimal in a few
    # rounds); where the rounds keep finding new bubbles until the budget
    # ends, the model is solved again with the bubbles forbidden up front by
    # levels (slow, but it settles; levels bind only next to faces outside)
    for levels in (False, True) if outside else (False,):
        best, prov, cut = _solve_component(
            tab, state, cycles, conflicts, lone, seconds, max_rounds, links, False, outside, levels
        )
        cuts += cut
        if best is not None or prov:
            break
    if best is None:
        return False, prov, cuts, False, None
    return True, prov, cuts, _improves(tab, state, best, cycles, lone, outside, True), best


def _improves(tab, state, answer, cycles, lone, outside: bool, closed: bool) -> bool:
    """Whether ``answer`` is to replace ``state`` over ``cycles`` (the order
    of :meth:`_Score.better_than`).  A selection given with a detached
    bubble is beaten by any valid answer (they have none): its extra
    spheres raise the Euler characteristic the comparison would otherwise
    prefer."""
    if _bubbles(tab, state, cycles, outside):
        return True
    edges_, verts = _extent(tab, cycles)
    before = _score(tab, state, cycles, edges_, verts, lone)
    return _score(tab, answer, cycles, edges_, verts, lone).better_than(before, closed)


def _crosses(conflicts, state: np.ndarray, answer: np.ndarray, cycles) -> bool:
    """Whether a face of ``answer`` among ``cycles`` conflicts with (crosses or
    folds onto) a face selected in ``state`` outside them."""
    inside = set(cycles)
    return any(
        answer[c] == 1 and d not in inside and state[d] == 1
        for c in cycles
        for d in conflicts.get(c, ())
    )


def _settle(tab, state, comp, conflicts, lone, seconds, max_rounds, links, rings):
    """The closed models of a component, grown while proven infeasible.

    Where the closed model is proven infeasible with the selection round
    the component held fixed, the cycles sharing a sample with the model
    are freed and it is solved again, up to ``rings`` times: on input that
    does not conform a face decided on its own (no candidate competes for
    its edges) can be what makes closing impossible.  Leaves ``state`` as
    it is.  Returns :func:`_closed`'s five figures (cuts summed over the
    models), the cycles of the last model, and how many rings it has.
    """
    cuts = 0
    cur = comp
    for ring in range(rings + 1):
        found, prov, cut, took, best = _closed(
            tab, state, cur, conflicts, lone, seconds, max_rounds, links
        )
        cuts += cut
        if found or not prov or ring == rings:
            # an answer, or out of time (a larger model would only take longer)
            break
        grow = _ring(tab, cur)
        if len(grow) == len(cur):
            break  # nothing round it to free
        cur = grow
    return found, prov, cuts, took, best, cur, ring


def _open_model(tab, state, cycles, conflicts, lone, seconds, max_rounds, links):
    """The open model of ``cycles``; its answer is taken into ``state`` when
    it is better (open edges and strays, then area).  Returns (taken,
    proven, cuts)."""
    outside = _touches_outside(tab, state, cycles)
    best, prov, cuts = _solve_component(
        tab, state, cycles, conflicts, lone, seconds, max_rounds, links, True, outside, False
    )
    if best is None or not _improves(tab, state, best, cycles, lone, outside, False):
        return False, prov, cuts
    state[cycles] = best[cycles]
    return True, prov, cuts


def _defect_windows(tab, state, comp, lone) -> list[list[int]]:
    """The cycles of ``comp`` round each cluster of its defects in ``state``.

    Defects are the samples of an edge used once (but not one lying in a
    single candidate) or more than twice, and samples whose link is not a
    disk; samples sharing a cycle of ``comp`` are one cluster.  A window is
    the cluster's cycles and every cycle of ``comp`` sharing a sample with
    them.  Clusters come in the order of their smallest sample.
    """
    inside = set(comp)
    edges_, verts = _extent(tab, comp)
    bad = set()
    for e, use in _uses(tab, state, edges_).items():
        if (use == 1 and e not in lone) or use > 2:
            bad.update(int(v) for v in tab.edges[e])
    bad.update(v for v in verts if not _link_ok(tab, state, v))
    if not bad:
        return []
    bad_sorted = sorted(bad)
    rows, cols, seed = [], [], []
    for v in bad_sorted:
        mine = [int(tab.corner_owner[k]) for k in tab.corners_at(v)]
        seed.append(sorted(c for c in mine if c in inside))
    by_cycle: dict[int, int] = {}
    for i, cs in enumerate(seed):
        for c in cs:
            j = by_cycle.setdefault(c, i)
            rows.append(i)
            cols.append(j)
    g = sparse.csr_matrix(
        (np.ones(len(rows), dtype=np.int8), (rows, cols)), shape=(len(bad_sorted),) * 2
    )
    _, labels = csgraph.connected_components(g, directed=False)
    _, first = np.unique(labels, return_index=True)  # each cluster's smallest sample
    windows = []
    for j in np.argsort(first, kind="stable").tolist():
        core = sorted({c for i in np.flatnonzero(labels == j) for c in seed[i]})
        if core:
            windows.append([c for c in _ring(tab, core) if c in inside])
    return windows


def exact_selection(
    incidence: Incidence,
    state: np.ndarray,
    region: np.ndarray,
    conflicts: dict[int, list[int]],
    *,
    seconds: float = 5.0,
    max_rounds: int = 40,
    rings: int = 2,
) -> ExactReport:
    """Select the faces of ``region`` exactly; updates ``state`` in place.

    Parameters
    ----------
    incidence : Incidence
        The candidate cycles, their edges and corners.
    state : (c,) int64
        1 for a selected cycle, 0 otherwise; cycles of ``region`` are
        re-decided, the others are held fixed.
    region : (r,) int64
        The cycles to decide (failed components and the fixed cycles next
        to them).
    conflicts : dict
        Cycle -> cycles it may not be selected with (folds and crossings).
    seconds : float
        Budget per model of a component (CP-SAT deterministic time, shared
        by its lazy rounds): the closed model, then, where it gives no
        answer in time, the closed model with levels (next to outside
        faces), then the open model where no closed answer came.
    max_rounds : int
        Lazy rounds per component.
    rings : int
        Where the closed model is proven infeasible with the selection
        round the component held fixed, the cycles sharing a sample with
        the model are freed and it is solved again, up to ``rings`` times
        (before the open model).

    Returns
    -------
    ExactReport
    """
    tab = _tables(incidence)
    n_points = incidence.n_points
    region = np.unique(np.asarray(region, dtype=np.int64))
    if region.shape[0] == 0:
        return ExactReport()
    n_at_edge = np.diff(tab.edge_cycles.indptr)
    lone = set(np.flatnonzero(n_at_edge == 1).tolist())
    # components of the region through shared samples
    owner = np.repeat(np.arange(region.shape[0]), [len(tab.cycle_vertices[c]) for c in region])
    verts = np.concatenate([tab.cycle_vertices[c] for c in region])
    g = sparse.csr_matrix(
        (np.ones(owner.shape[0], dtype=np.int8), (owner, verts + region.shape[0])),
        shape=(region.shape[0] + n_points,) * 2,
    )
    _, labels = csgraph.connected_components(g, directed=False)
    lab = labels[: region.shape[0]]
    comps = [region[lab == j].tolist() for j in np.unique(lab)]
    improved = proven = cuts = grown = 0

    def settle(comp, links):
        return _settle(tab, state, comp, conflicts, lone, seconds, max_rounds, links, rings)

    # every component's closed models first, side by side: a model reads
    # the selection only on the cycles sharing a sample with it (and, for
    # crossings, the faces it may not cross), which differ between
    # components unless a grown model reaches another one (checked below).
    # CP-SAT releases the GIL while it solves and each model is solved
    # alone on one worker, so the answers do not depend on the thread count
    given = state.copy()
    links_of = [set() for _ in comps]  # lazily (all up front: 2x slower, no better)
    # the largest components first (the last to finish bounds the time)
    order = sorted(range(len(comps)), key=lambda i: (-len(comps[i]), i))
    firsts = list(
        thread_map(lambda i: settle(comps[i], links_of[i]), range(len(comps)), order=order)
    )
    # then in order: the answers taken, the open models where no closed
    # answer came
    for comp, links, first in zip(comps, links_of, firsts):
        found, prov, cut, took, best, cur, ring = first
        cuts += cut
        read = _ring(tab, cur)
        if np.any(state[read] != given[read]) or (took and _crosses(conflicts, state, best, cur)):
            # an earlier answer changed what this model read, or this answer
            # crosses an earlier one (it was solved next to the selection
            # given): solved again next to them
            log.debug("exact selection: a component solved again after an earlier answer")
            found, prov, cut, took, best, cur, ring = settle(comp, links)
            cuts += cut
        if found:
            if took:
                state[cur] = best[cur]
                improved += 1
                proven += int(prov)
                grown += int(ring > 0)
            continue
        # no closed answer for the whole, proven: it is repaired round each of its
        # defects (open or overloaded edges, pinched samples of the
        # selection in ``state``), a window at a time: the closed models
        # (grown while infeasible), else the open model of the window.  A
        # component too large for one model (a sparse scan: thousands of
        # cycles, out of time) closes where it can and opens least elsewhere
        taken = []
        windows = _defect_windows(tab, state, comp, lone)
        if not prov:
            # out of time rather than infeasible: a window of more than half
            # the component would run out of time too (wedge: one window of
            # 878 of 947 cycles); with none smaller, the open model of the
            # whole, as before
            windows = [w for w in windows if 2 * len(w) <= len(comp)] or [comp]
        for win in windows:
            if len(win) < len(comp):  # the component's own closed models ran
                found, prov, cut, took, best, cur, ring = settle(win, links)
                cuts += cut
                if found:
                    if took:
                        state[cur] = best[cur]
                        taken.append(prov)
                        grown += int(ring > 0)
                    continue
            took, prov, cut = _open_model(
                tab, state, win, conflicts, lone, seconds, max_rounds, links
            )
            cuts += cut
            if took:
                taken.append(prov)
        improved += int(bool(taken))
        proven += int(bool(taken) and all(taken))
    return ExactReport(len(comps), improved, proven, cuts, grown)
