"""Algorithm 1 of the paper: the whole reconstruction, step by step.

``reconstruct`` validates and de-duplicates the samples, puts them in a
canonical (lexicographic) order so that no decision depends on input order,
runs LocalizedRNG → TrivialIsometricCycles → Backtracking → Triangulate →
cones for stray samples, and maps the result back to the input's vertices.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy import sparse
from scipy.sparse import csgraph
from scipy.spatial import cKDTree

from ._validate import InputError, as_points, check_k, check_max_cycle_length, check_not_degenerate
from .backtracking import backtracking
from .cones import attach_cones, ring_centres
from .cycles import CycleSet, concat, trivial_isometric_cycles
from .graph import cycle_edges
from .holes import HoleLoops, crossing_faces, face_links, hole_loops, uncovered, unpinch
from .jit import compile_notice
from .mesh import edge_keys, self_intersections
from .patches import stray_clusters, stray_patches
from .progress import Steps, log, notice
from .rng import localized_rng
from .selection import ExactReport
from .selfcheck import check_faces_and_triangles, strict_default
from .tolerance import DEFAULT, Tolerance
from .triangulate import triangulate


@dataclass(frozen=True)
class Reconstruction:
    """The result of :func:`reconstruct`; all indices refer to ``vertices``.

    Attributes
    ----------
    vertices : (v, 3) float64
        The distinct input samples, in order of first occurrence in the input.
    triangles : (t, 3) int64
        The output surface, consistently oriented where orientable.
    input_to_vertex : (n,) int64
        For every input point, its row in ``vertices`` (duplicates share one).
    duplicates_merged : int
        Number of input points that were exact duplicates of an earlier one.
    rng_edges : (m, 2) int64
        The localized RNG (Algorithm 2), rows ``(a, b)`` with ``a < b``, sorted.
    candidate_cycles : int
        Number of small isometric cycles found (Algorithm 3).
    face_cycles : CycleSet
        The selected 2-basis (Algorithm 4) before triangulation.
    success : bool
        Whether the backtracking met the paper's success condition (no edge
        used more than twice, every used sample's link a disk, open edges
        only on true boundaries; stray samples are attached by the cones)
        and the output is orientable.
    orientable : bool
        Whether the face cycles could be oriented coherently (a closed
        non-orientable output cannot be embedded, so it is a failure).
    open_edges : (p, 2) int64
        Edges of the face cycles used once (the boundary, or failures).
    unresolved_samples : (q,) int64
        Samples whose face-cycle link is not a disk or that no face cycle used.
    non_disk_neighbourhoods : (r,) int64
        Samples whose neighbourhood's faces do not form a disk (see
        :class:`sr33.FaceSelection`; an indicator).
    coned_samples : (s,) int64
        Samples attached at the end (Section 5): by cones, as the centre of
        a ring face's fan, or inside the face they lie over
        (:mod:`sr33.patches`).
    fallback_components : int
        Ambiguous components where the strict search failed; the greedy
        fallback and then the exact selection (:mod:`sr33.selection`)
        decided them.
    hole_faces : int
        Boundary loops of the selection closed by one face each
        (:mod:`sr33.holes`); they are the last cycles of ``face_cycles``.
    exact : ExactReport
        What the exact selection did where the strict search failed:
        components solved, answers taken (strictly better than the greedy
        one), answers proven optimal (the rest are the best found within
        the budget), lazy cuts.
    timings : dict[str, float]
        Seconds per step.
    k : int
        The neighbourhood size used.
    """

    vertices: np.ndarray
    triangles: np.ndarray
    input_to_vertex: np.ndarray
    duplicates_merged: int
    rng_edges: np.ndarray
    candidate_cycles: int
    face_cycles: CycleSet
    success: bool
    orientable: bool
    open_edges: np.ndarray
    unresolved_samples: np.ndarray
    non_disk_neighbourhoods: np.ndarray
    coned_samples: np.ndarray
    fallback_components: int
    hole_faces: int = 0
    exact: ExactReport = field(default_factory=ExactReport)
    timings: dict[str, float] = field(default_factory=dict)
    k: int = 33

    def __repr__(self) -> str:
        # figures, not arrays: a repr of a 1M-point result must fit a line
        return (
            f"Reconstruction(vertices={self.vertices.shape[0]}, "
            f"triangles={self.triangles.shape[0]}, k={self.k}, success={self.success}, "
            f"orientable={self.orientable}, open_edges={len(self.open_edges)}, "
            f"unresolved_samples={len(self.unresolved_samples)}, "
            f"coned_samples={len(self.coned_samples)}, "
            f"duplicates_merged={self.duplicates_merged}, "
            f"fallback_components={self.fallback_components})"
        )

    def to_pyvista(self):
        """The surface as a ``pyvista.PolyData`` (needs the ``vtk`` extra).

        For trimesh: ``trimesh.Trimesh(rec.vertices, rec.triangles,
        process=False)`` (``process=False`` keeps the vertex order, so
        ``input_to_vertex`` stays valid); for Open3D:
        ``o3d.geometry.TriangleMesh(o3d.utility.Vector3dVector(rec.vertices),
        o3d.utility.Vector3iVector(rec.triangles))``.
        """
        try:
            import pyvista as pv
        except ImportError:
            raise ImportError(
                "Reconstruction.to_pyvista needs PyVista: pip install 'sr33[vtk]'"
            ) from None
        tri = self.triangles.astype(np.int64)
        faces = np.hstack([np.full((tri.shape[0], 1), 3, dtype=np.int64), tri]).ravel()
        return pv.PolyData(self.vertices.copy(), faces)

    def to_meshio(self):
        """The surface as a ``meshio.Mesh`` (one ``triangle`` cell block)."""
        import meshio

        return meshio.Mesh(self.vertices.copy(), [("triangle", self.triangles.copy())])


def normalized(points: np.ndarray) -> np.ndarray:
    """The samples moved and scaled into the frame every step works in.

    Translated by the bounding box's centre rounded to a multiple of the
    power of two ``2^(e+1)`` above its extent (0 for samples round the origin,
    which stay bit for bit as given), then scaled by ``2^-e`` (exact: only
    the exponent changes, so neither 1e300 nor 1e-300 overflows or
    underflows a squared distance).  A georeferenced scan at an offset
    that is a multiple of that power of two (5e5, 4.1e6, 250 for a model a
    metre across) gives the working coordinates of the same points
    re-centred, bit for bit (a difference of nearby doubles is exact), and
    so the same result; any other offset differs by rounding only.
    """
    half = float((0.5 * points.max(axis=0) - 0.5 * points.min(axis=0)).max())
    e = int(np.frexp(half)[1]) if half > 0 else 0
    centre = 0.5 * points.max(axis=0) + 0.5 * points.min(axis=0)
    # exponent arithmetic only: 2^(e+1) itself overflows for an extent of 1e308
    with np.errstate(over="ignore"):
        shift = np.ldexp(np.round(np.ldexp(centre, -(e + 1))), e + 1)
        work = np.ldexp(points - np.where(np.isfinite(shift), shift, 0.0), -e)
    if not np.isfinite(work).all():
        raise InputError(
            "points span more than the float64 range allows (an extent near 1.8e308); "
            "scale them down first"
        )
    return work


def _canonical_order(work: np.ndarray) -> np.ndarray:
    """The order of the (normalized) samples: lexicographic by coordinates
    quantized to 1e-9 of the bounding-box diagonal (exact order breaks the
    remaining ties).

    Exact lexicographic order is permutation invariant but not translation
    invariant: adding 1 to coordinates that differ by less than an ulp makes
    them equal and reorders the points.  Quantized keys are the same after a
    translation or scaling (up to values within rounding of a bucket edge).
    """
    lo = work.min(axis=0)
    size = float(np.linalg.norm(work.max(axis=0) - lo)) or 1.0
    q = np.round((work - lo) / (size * 1e-9)).astype(np.int64)
    return np.lexsort((work[:, 2], work[:, 1], work[:, 0], q[:, 2], q[:, 1], q[:, 0]))


@dataclass(frozen=True)
class _Figures:
    """What the success condition reads off a set of face cycles."""

    open_edges: np.ndarray  # (p, 2) edges used by one face, a < b, sorted
    overloaded: int  # edges used by three or more faces
    disk: np.ndarray  # (n,) bool, the sample's link is a disk
    used: np.ndarray  # (n,) bool, some face uses the sample

    @property
    def defects(self) -> int:
        """Open edges plus used samples whose link is not a disk."""
        return self.open_edges.shape[0] + int((self.used & ~self.disk).sum())


def _figures(faces: CycleSet, n: int) -> _Figures:
    used = faces.used(n)
    if len(faces) == 0:
        return _Figures(np.empty((0, 2), np.int64), 0, np.zeros(n, dtype=bool), used)
    pairs, _ = cycle_edges(faces.offsets, faces.vertices)
    keys, cnt = np.unique(edge_keys(pairs[:, 0], pairs[:, 1], n), return_counts=True)
    once = keys[cnt == 1]
    open_edges = np.stack([once // n, once % n], axis=1).astype(np.int64)
    return _Figures(open_edges, int((cnt > 2).sum()), face_links(n, faces), used)


def _optional_crossings(pts, tri: np.ndarray, optional: np.ndarray) -> np.ndarray:
    """Crossing pairs of triangles with at least one ``optional`` triangle
    (of a loop face or a ring-centre fan), as rows of triangle indices.

    Only triangles that can reach an optional one are tested: two triangles
    whose boxes overlap have centroids within the sum of their radii (the
    farthest corner from the centroid), so the candidates are found with a
    k-d tree round the optional triangles' centroids.
    """
    opt = np.flatnonzero(optional)
    if opt.shape[0] == 0:
        return np.empty((0, 2), dtype=np.int64)
    corners = pts[tri]
    cen = corners.mean(axis=1)
    rad = np.linalg.norm(corners - cen[:, None], axis=2).max(axis=1)
    near = cKDTree(cen).query_ball_point(cen[opt], rad[opt] + rad.max())
    sub = np.unique(np.concatenate([np.asarray(h, dtype=np.int64) for h in near] + [opt]))
    mine = optional[sub]
    hits = self_intersections(pts, tri[sub], keep=lambda a, b: mine[a] | mine[b])
    return sub[hits]


def _triangulate_with_loops(
    pts, base: CycleSet, holes: HoleLoops | None, tolerance: Tolerance, edges: np.ndarray
):
    """Triangulate the selection plus the boundary loops that stay valid.

    Faces ringing round clusters of stray samples are triangulated with them
    (:mod:`sr33.patches`); a patch that crosses another triangle is undone
    first.  A loop face is dropped when its triangles are not covered by the
    samples or cross another triangle (:mod:`sr33.holes`); then a ring-centre
    fan that crosses another triangle (a bevelled acute edge's sample under a
    quad) gives its sample back to the cones, which insert it where nothing
    crosses.  Returns the faces, their triangulation, the centres and
    patches used and the number of loop faces kept, and the *flaps*: faces
    of ``base`` that a dropped loop face crossed and that have two or more
    samples on that loop (a face folded over the hole).
    """
    nb = len(base)
    flaps: set[int] = set()
    loops = holes.loops if holes is not None else None
    active = list(range(len(loops))) if loops is not None else []
    no_centre: set[tuple[str, int]] = set()
    no_patch: set[tuple[str, int]] = set()
    rounds = 0
    while True:
        faces = concat(base, loops.subset(np.array(active, dtype=np.int64))) if active else base
        key = [("f", i) for i in range(nb)] + [("l", i) for i in active]
        skip = {f for f in range(len(faces)) if key[f] in no_patch}
        patches = stray_patches(pts, faces, edges, skip_faces=skip, min_interior=2)
        placed = {int(v) for p in patches.values() for v in p.interior.tolist()}
        centres = {
            f: c
            for f, c in ring_centres(pts, faces).items()
            if key[f] not in no_centre and f not in patches and c not in placed
        }
        tr = triangulate(
            pts,
            faces,
            rtol=tolerance.rtol,
            centres=centres,
            patches={f: p.triangles for f, p in patches.items()},
        )
        fot = tr.face_of_triangle
        optional = (fot >= nb) | np.isin(fot, list(centres)) | np.isin(fot, list(patches))
        hits = _optional_crossings(pts, tr.triangles, optional)
        crossing = set(fot[hits.ravel()].tolist())
        if crossing & set(patches):
            log.debug("stray patches: %d crossing, undone", len(crossing & set(patches)))
            no_patch |= {key[f] for f in crossing & set(patches)}
            continue
        drop = {f for f in crossing if f >= nb}
        for a, b in fot[hits].tolist():
            for lf, bf in ((a, b), (b, a)):
                if lf >= nb > bf:
                    ring = set(faces.cycle(lf).tolist())
                    if len(ring & set(faces.cycle(bf).tolist())) >= 2:
                        flaps.add(bf)
        if active:
            is_loop = fot >= nb
            sub = faces.subset(np.arange(nb, len(faces)))
            pairs, _ = cycle_edges(sub.offsets, sub.vertices)
            el = np.linalg.norm(pts[pairs[:, 0]] - pts[pairs[:, 1]], axis=1)
            scale = np.maximum.reduceat(el, sub.offsets[:-1])
            bad = uncovered(pts, tr.triangles[is_loop], fot[is_loop] - nb, scale)
            drop |= {nb + int(i) for i in np.flatnonzero(bad)}
        if drop:
            log.debug(
                "hole loops: %d of %d dropped (%d crossing)",
                len(drop),
                len(active),
                len({f for f in crossing if f >= nb}),
            )
            active = [a for j, a in enumerate(active) if nb + j not in drop]
            continue
        bad_centres = crossing & set(centres)
        rounds += 1
        if not bad_centres or rounds > 3:
            break
        no_centre |= {key[f] for f in bad_centres}
    return faces, tr, centres, patches, len(active), flaps


def _piece_of_face(faces: CycleSet, n: int) -> np.ndarray:
    """For every face cycle, its connected piece of the surface (labels 0..)."""
    pairs, owner = cycle_edges(faces.offsets, faces.vertices)
    g = sparse.csr_matrix((np.ones(pairs.shape[0], np.int8), (pairs[:, 0], pairs[:, 1])), (n, n))
    _, lab = csgraph.connected_components(g, directed=False)
    first = lab[faces.vertices[faces.offsets[:-1]]]
    return np.unique(first, return_inverse=True)[1].reshape(-1)


def _without_small_open_pieces(
    faces: CycleSet, n: int, edges: np.ndarray, share: float = 0.05
) -> CycleSet:
    """The faces without the small open pieces of the surface.

    A piece other than the largest, with open edges and fewer than
    ``share`` of the faces, whose boundary an RNG edge joins to another
    piece (directly or through a cluster of strays), is a bit the selection
    cut off (a cone's tip closed
    apart from the ring round it, both left open): its samples are better
    placed as strays (:mod:`sr33.patches`, the cones) into the hole it
    leaves.  A closed piece (a second body), an open piece whose boundary no
    RNG edge joins to another piece (a separate sheet) and the largest piece
    (a sheet with a true boundary) stay.
    """
    if len(faces) == 0:
        return faces
    lab = _piece_of_face(faces, n)
    size = np.bincount(lab)
    if size.shape[0] < 2:
        return faces
    pairs, owner = cycle_edges(faces.offsets, faces.vertices)
    keys = edge_keys(pairs[:, 0], pairs[:, 1], n)
    _, inv, cnt = np.unique(keys, return_inverse=True, return_counts=True)
    # the piece of every sample, and of every sample on an open edge (-1 elsewhere)
    piece = np.full(n, -1, dtype=np.int64)
    piece[faces.vertices] = np.repeat(lab, faces.lengths)
    rim_piece = np.full(n, -1, dtype=np.int64)
    once = cnt[inv] == 1
    rim_piece[pairs[once].ravel()] = np.repeat(lab[owner[once]], 2)
    e = np.asarray(edges, dtype=np.int64).reshape(-1, 2)
    facing = np.zeros(size.shape[0], dtype=bool)
    for u, v in ((e[:, 0], e[:, 1]), (e[:, 1], e[:, 0])):
        r, p = rim_piece[u], piece[v]
        facing[r[(r >= 0) & (p >= 0) & (r != p)]] = True
    # ... or through a cluster of strays reaching both
    for reach in stray_clusters(n, piece >= 0, e)[1]:
        rims = np.unique(rim_piece[reach])
        if np.unique(piece[reach]).shape[0] > 1:
            facing[rims[rims >= 0]] = True
    largest = int(np.argmax(size))
    small = facing & (size < share * len(faces))
    small[largest] = False
    if not small.any():
        return faces
    log.debug("hole loops: %d small open pieces taken apart", int(small.sum()))
    return faces.subset(~small[lab])


def _close_holes(
    pts,
    base: CycleSet,
    max_hole_length: int,
    tolerance: Tolerance,
    edges: np.ndarray,
    grow: int = 6,
    everywhere: bool = True,
):
    """The selection with its boundary loops closed (:mod:`sr33.holes`).

    Where a loop face crossed faces folded over its hole (flaps), where
    a sample's faces form several pieces (:func:`sr33.holes.unpinch`), or
    where two faces of the selection cross (:func:`sr33.holes.crossing_faces`),
    those faces are removed and the larger hole's loop is tried instead, up to
    ``grow`` times; pieces of the surface that removing flaps detaches are removed
    too (their samples go to the cones), and so are small open pieces from
    the start (:func:`_without_small_open_pieces`); the round with the fewest open
    edges plus pinched samples plus crossing faces (then the first) is kept.
    Returns the faces, their triangulation, the centres, the patches
    (:mod:`sr33.patches`), the number of loop faces and the faces' figures.
    """
    best, best_score = None, 0
    cur = _without_small_open_pieces(base, pts.shape[0], edges) if max_hole_length else base
    pieces = int(_piece_of_face(cur, pts.shape[0]).max()) + 1 if len(cur) else 0
    for _ in range(grow + 1):
        holes = hole_loops(pts, cur, max_length=max_hole_length) if max_hole_length else None
        faces, tr, centres, patches, n_loops, flaps = _triangulate_with_loops(
            pts, cur, holes, tolerance, edges
        )
        figs = _figures(faces, pts.shape[0])
        folds = crossing_faces(
            pts, faces, tr.triangles, tr.face_of_triangle, len(cur), everywhere=everywhere
        )
        score = figs.defects + folds.shape[0]
        if best is None or score < best_score:
            best, best_score = (faces, tr, centres, patches, n_loops, figs), score
        # the loops' base faces come first in ``faces``: unpinch on the base
        flaps |= set(unpinch(cur, pts.shape[0]).tolist())
        flaps |= set(folds.tolist())
        if not flaps or not max_hole_length:
            break
        log.debug("hole loops: %d flaps and pinching faces removed", len(flaps))
        keep = np.ones(len(cur), dtype=bool)
        keep[sorted(flaps)] = False
        cur = cur.subset(keep)
        # pieces the flaps held on are detached bits: their samples go to the cones
        if len(cur):
            lab = _piece_of_face(cur, pts.shape[0])
            size = np.bincount(lab)
            extra = size.shape[0] - pieces
            if extra > 0:
                small = np.lexsort((np.arange(size.shape[0]), size))[:extra]
                cur = cur.subset(~np.isin(lab, small))
    return best


def _compiling(quiet: bool):
    def notify():
        notice("compiling the numba kernels (once per install, about 13 s)", quiet)

    return notify


@dataclass(frozen=True)
class _Run:
    """What the steps of one run computed, in the canonical order of the
    distinct samples (see :func:`_pipeline`)."""

    pts: np.ndarray  # the working (normalized) coordinates
    uniq: np.ndarray  # the distinct samples as given
    first: np.ndarray  # each one's first input row
    inverse: np.ndarray  # each input row's distinct sample
    duplicates: int
    k: int
    rng: object  # LocalizedRNG
    cycles: CycleSet
    selection: object  # FaceSelection
    faces: CycleSet  # the selection's faces, loop faces after them
    triangulation: object  # Triangulation of ``faces``
    centres: dict
    patches: dict  # face -> Patch (sr33.patches)
    loops: int
    figures: _Figures
    triangles: np.ndarray  # after the cones
    coned: np.ndarray


def _pipeline(
    raw,
    k,
    run,
    timings,
    check,
    tolerance,
    max_cycle_length,
    max_hole_length,
    budget,
    exact_seconds,
    quiet,
) -> _Run:
    """Algorithm 1 on validated points, step by step (see :func:`reconstruct`)."""
    with run.step("prepare", timings):
        uniq, first, inverse = np.unique(raw, axis=0, return_index=True, return_inverse=True)
        inverse = inverse.reshape(-1)
        work = normalized(uniq)
        order = _canonical_order(work)
        uniq, work, first = uniq[order], work[order], first[order]
        back = np.empty_like(order)
        back[order] = np.arange(order.shape[0])
        inverse = back[inverse]
        check_not_degenerate(work)
        k = check_k(k, uniq.shape[0])
        dup = raw.shape[0] - uniq.shape[0]
        if dup:
            log.info("merged %d exact duplicate points", dup)
    # every step works in the normalized frame (see normalized), in canonical
    # order (see _canonical_order); the output keeps the input's coordinates
    pts = work
    with run.step("localized_rng", timings):
        rng = localized_rng(pts, k, tolerance=tolerance, quiet=quiet)
    with run.step("isometric_cycles", timings):
        cycles = trivial_isometric_cycles(rng.edges, pts.shape[0], max_length=max_cycle_length)
    with run.step("backtracking", timings):
        sel = backtracking(
            pts,
            rng.edges,
            cycles,
            tolerance=tolerance,
            k=k,
            neighbourhoods=rng.neighbourhoods,
            budget=budget,
            exact_seconds=exact_seconds,
            quiet=quiet,
        )
    with run.step("triangulate", timings):
        # a selection the strict search made alone is checked for folds only
        faces, tr, centres, patches, n_loops, figs = _close_holes(
            pts,
            sel.faces,
            max_hole_length,
            tolerance,
            rng.edges,
            everywhere=sel.fallback_components > 0,
        )
        tri = tr.triangles
        if patches:
            carriers = [p for p in patches.values() if p.triangles.shape[0]]
            log.debug(
                "stray patches: %d over %d faces, %d strays placed",
                len(carriers),
                len(patches),
                sum(p.interior.shape[0] for p in carriers),
            )
    if check:
        with run.step("self_checks", timings):
            counts = {f: p.triangles.shape[0] for f, p in patches.items()}
            check_faces_and_triangles(faces, tri, tr.face_of_triangle, centres, counts)
    with run.step("cones", timings):
        if tri.shape[0]:
            tri, coned = attach_cones(pts, tri)
        else:
            coned = np.empty(0, dtype=np.int64)
    return _Run(
        pts, uniq, first, inverse, dup, k, rng, cycles, sel, faces, tr, centres, patches,
        n_loops, figs, tri, coned,
    )  # fmt: skip


def reconstruct(
    points,
    k: int = 33,
    *,
    max_cycle_length: int = 8,
    budget: int = 20000,
    exact_seconds: float = 5.0,
    max_hole_length: int = 66,
    tolerance: Tolerance = DEFAULT,
    quiet: bool = True,
    strict: bool | None = None,
) -> Reconstruction:
    """Reconstruct a surface with sharp features from point samples (Algorithm 1).

    Parameters
    ----------
    points : (n, 3) array_like of float
        The samples; exact duplicates are merged (``duplicates_merged``).
    k : int
        Neighbourhood size, ``3 <= k <`` number of distinct points.  The
        paper uses 33 on its sharp-feature sets.
    max_cycle_length : int
        Longest candidate face cycle (Algorithm 3, see :mod:`sr33.cycles`).
    budget : int
        Search assignments per ambiguous component (see :mod:`sr33.backtracking`).
    exact_seconds : float
        Budget of the exact selection per region the search failed on (see
        :mod:`sr33.selection`); 0 keeps the greedy fallback's answer.
    max_hole_length : int
        Longest boundary loop of the selection that may be closed by one
        face (:mod:`sr33.holes`); 0 closes none.
    tolerance : Tolerance
        Tie and fold tolerances (:mod:`sr33.tolerance`).
    quiet : bool
        Hide progress bars.
    strict : bool, optional
        Run the expensive self-checks of :mod:`sr33.selfcheck` (edge use at
        most two, one triangle fewer than sides per face, Euler
        characteristic kept by the triangulation).  Defaults to the
        ``SR33_STRICT`` environment variable (the test suite sets it).

    Returns
    -------
    Reconstruction

    Examples
    --------
    >>> import numpy as np
    >>> from sr33 import reconstruct
    >>> octahedron = np.array([[1, 0, 0], [-1, 0, 0], [0, 1, 0],
    ...                        [0, -1, 0], [0, 0, 1], [0, 0, -1]], float)
    >>> r = reconstruct(octahedron, k=4)
    >>> r.triangles.shape, r.success
    ((8, 3), True)
    """
    raw = as_points(points)
    max_cycle_length = check_max_cycle_length(max_cycle_length)
    timings: dict[str, float] = {}
    check = strict_default() if strict is None else strict
    names = ["prepare", "localized_rng", "isometric_cycles", "backtracking", "triangulate"]
    names += ["self_checks"] * check + ["cones"]
    with Steps(names, quiet) as run, compile_notice(_compiling(quiet)):
        r = _pipeline(
            raw,
            k,
            run,
            timings,
            check,
            tolerance,
            max_cycle_length,
            max_hole_length,
            budget,
            exact_seconds,
            quiet,
        )
    return _result(r, timings)


def _result(r: _Run, timings: dict[str, float]) -> Reconstruction:
    """The :class:`Reconstruction` of a run: labels back in the input's order,
    the success condition read off the final faces."""
    pts, sel, figs, tr = r.pts, r.selection, r.figures, r.triangulation
    # canonical -> output labels (order of first occurrence in the input)
    out_order = np.argsort(r.first, kind="stable")
    relabel = np.empty_like(out_order)
    relabel[out_order] = np.arange(out_order.shape[0])
    rng_edges = np.sort(relabel[r.rng.edges], axis=1)
    rng_edges = rng_edges[np.lexsort((rng_edges[:, 1], rng_edges[:, 0]))]
    # the success condition and its figures on the final faces (loops included)
    still_open, disk = figs.open_edges, figs.disk
    was_open = edge_keys(sel.open_edges[:, 0], sel.open_edges[:, 1], pts.shape[0])
    now_open = edge_keys(still_open[:, 0], still_open[:, 1], pts.shape[0])
    bad_open = was_open[~sel.true_boundary]
    success = bool(
        len(r.faces) > 0
        and figs.overloaded == 0
        and not np.any(figs.used & ~disk)
        and not np.isin(now_open, bad_open).any()
    )
    open_edges = np.sort(relabel[still_open], axis=1) if still_open.size else still_open
    attached = [r.coned, list(r.centres.values())] + [p.interior for p in r.patches.values()]
    faces = CycleSet(offsets=r.faces.offsets, vertices=relabel[r.faces.vertices])
    return Reconstruction(
        vertices=r.uniq[out_order],
        triangles=relabel[r.triangles],
        input_to_vertex=relabel[r.inverse],
        duplicates_merged=int(r.duplicates),
        rng_edges=rng_edges,
        candidate_cycles=len(r.cycles),
        face_cycles=faces,
        success=bool(success and tr.orientable),
        orientable=bool(tr.orientable),
        open_edges=open_edges,
        unresolved_samples=np.sort(relabel[np.flatnonzero(~disk)]),
        non_disk_neighbourhoods=np.sort(relabel[sel.non_disk_neighbourhoods]),
        coned_samples=np.sort(relabel[np.concatenate(attached).astype(np.int64)]),
        fallback_components=sel.fallback_components,
        hole_faces=r.loops,
        exact=sel.exact,
        timings=timings,
        k=r.k,
    )
