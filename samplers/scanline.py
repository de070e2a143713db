"""Scan-line sampling of CAD shapes (the laser-scanner picture of Figure 1).

A laser line scanner sweeps a family of parallel planes across the object
and records points along each section curve.  :func:`scan` does the same on
a CadQuery shape:

* every CAD face is assigned the plane family (sweep direction) that cuts it
  most transversally — the direction d minimising the area-weighted mean of
  ``|n · d|`` over the face — so that no face is missed or hit at a grazing
  angle (the top of a box swept along z would be);
* planes of a family sit at ``t0 + j h_d`` along d, with t0 the shape's
  bounding-box minimum and h_d the spacing nearest to h that divides the
  shape's extent along d, so neighbouring faces of one family share their
  scan lines and faces bounded by the extreme planes start and end their
  lattice on that boundary;
* along each section curve the samples are spaced by arc length, about
  ``r · h`` apart with both ends on the face boundary (``L / round(L / rh)``),
  giving a near-rectangular ``h × r·h`` lattice: the triangles of its
  Delaunay triangulation have legs h and r·h, which meets Condition III-ii
  when ``1/√3 < r < √3``;
* corners (B-rep vertices) and sharp or boundary edges (dihedral angle above
  ``sharp_degrees``) are sampled explicitly, about h apart, so the features
  the reconstruction must keep are in the sample;
* scan-line samples within 3h/4 of a sampled corner or edge are dropped
  (line ends lie on an already sampled edge and would form slivers with its
  samples, as would lines meeting an edge at a grazing angle);
* samples closer than ``min(1, r) · h / 2`` to an earlier one are dropped
  (corners first, then edges, then scan lines), so no two samples are
  closer than a quarter of the spacing;
* where the rows leave a gap (planes grazing a face: the poles of a sphere),
  extra samples are projected onto the surface until every point of it is
  within h of a sample (their ``line_id`` is -2);
* a right square pyramid no taller than about 0.55 of its base is laid
  out as one lattice, its lateral rows on the base's columns and its
  lateral edges the cells' diagonals (:mod:`sr33.samplers.pyramids`); a box
  with filleted vertical and top edges as lattices continued across the
  fillets' seams, its corner octants in latitude rows repaired on their
  stereographic map (:mod:`sr33.samplers.fillets`);
* planar disks and annuli whose rims bound cones or cylinders are laid
  out in rings about their centre, halving their columns inwards
  (:mod:`sr33.samplers.disks`);
* where rows meet a circular sharp edge (a hole, the cut of a scoop) the
  boundary layer of each other planar face is repaired until its
  Delaunay triangles meet Condition III-ii (:mod:`sr33.samplers.layers`,
  :mod:`sr33.samplers.repair`; a face left with a few triangles at or above
  √3/2 is repaired once more from that answer); full cylinders are then
  laid out as the lattice their two rims span, and cones with a sampled
  rim in rings that keep the rim's columns and end crowded ones towards
  the apex; a partial sphere whose rims are all sharp (cutcube's scoop)
  takes rows h apart along its meridians and is repaired on its
  stereographic map (:mod:`sr33.samplers.spheres`) (``repair=False`` keeps the
  plain scan rows);
* optional Gaussian jitter (σ·h) and dropout, both seeded.

A model turned off the world axes is scanned in its own frame (the
directions of its faces, :mod:`sr33.samplers.frame`) and the samples are
turned back, so that a part's sampling does not depend on how it was placed.

Every sample before jitter lies on the CAD surface (points are evaluated on
the exact B-rep curves).  The same arguments give identical arrays.
CadQuery is imported only when this module's functions run.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from scipy.spatial import cKDTree

from sr33 import libm
from sr33.mesh import dot, norm, surface_points
from sr33.progress import bar, log, timed

from .adjacency import EdgeFaces
from .bands import developable_bands
from .faces import (
    FEATURE_CLEARANCE,
    NARROW_BAND,
    STRIP_WIDTH,
    axis_index,
    basis_surface,
    exact_bounds,
    face_mesh,
    goes_round,
    nearest_face,
    perpendicular,
    rims_sampled,
    row_cosine,
    row_direction,
    steps,
    thin,
    width_across,
)
from .frame import in_frame, model_frame

AXES = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))
EDGE_STEP = 1.0  # spacing of corner/edge samples, times h
#: the scan-line samples of two faces that meet where the surface folds back
#: sharper than ``FOLDED`` degrees (an acute edge, a narrow slot) are thinned
#: only this near each other (times h; any others at half a spacing): there
#: they are near in space and far on the surface
ACROSS = 0.3
FOLDED = 60.0
CLOSEST = 0.25  # no two samples nearer than this, times h (the sampler's contract)
FILL_RADIUS = 1.0  # gaps wider than this (times h) get extra samples
#: a strip narrower than this (times its leading edge's step) is sampled
#: half a step on from its leading edge: aligned, its cells were right
#: triangles of ratio step / sqrt(step^2 + width^2), above 0.85 below 0.62
STRIP_STAGGER = 0.65
SLANT_STEP = 1.45  # slanted edges are sampled where rows cross them this close (times h)
LEAST_SPAN = 0.75  # straight edges across a face's rows closer than this (times h) anchor no step
RATIO_RANGE = (0.6, 1.7)  # inside (1/sqrt(3), sqrt(3)) = (0.577, 1.732) with margin


class SamplingError(ValueError):
    """Bad sampling arguments: the message names the argument and the rule."""


@dataclass(frozen=True)
class ScanSamples:
    """Samples of a shape by :func:`scan`.

    Attributes
    ----------
    points : (n, 3) float64
        The samples.
    line_id : (n,) int64
        Scan line of each sample; -1 for samples placed on corners and sharp
        or boundary edges, -2 for samples filling a gap between rows.
    face_id : (n,) int64
        Index (in ``shape.Faces()`` order) of the CAD face the sample lies on;
        for corner and edge samples, the first adjacent face.
    on_feature : (n,) bool
        True for corner and sharp-edge samples.
    meta : dict
        spacing h, ratio r, directions, the frame scanned in (rows: its
        axes in world coordinates), seed, jitter, dropout, shape name,
        parameters and expected topology (when known), counts.
    """

    points: np.ndarray
    line_id: np.ndarray
    face_id: np.ndarray
    on_feature: np.ndarray
    meta: dict[str, Any] = field(default_factory=dict)


def _occ(shape):
    """The CadQuery shape inside a :class:`sr33.samplers.shapes.Shape` or the object itself."""
    # a samplers Shape record carries the CAD object in .solid (CadQuery's own
    # shapes have a .solid() method, hence the check on .expected)
    solid = shape.solid if hasattr(shape, "expected") else shape
    if type(solid).__name__ == "Workplane":
        solid = solid.val()
    if not hasattr(solid, "Faces"):
        raise SamplingError(
            f"shape must be a samplers Shape or a CadQuery shape, got {type(shape).__name__}"
        )
    return solid


def _shape_meta(shape, occ) -> dict[str, Any]:
    """What a sampling's meta says of its shape: name, parameters, expected topology."""
    expected = getattr(shape, "expected", None)
    return {
        "shape": getattr(shape, "name", type(occ).__name__),
        "params": dict(getattr(shape, "params", {}) or {}),
        "expected": None if expected is None else vars(expected).copy(),
    }


def _check_args(spacing, target_points, ratio, jitter, dropout, seed, directions):
    if spacing is not None and target_points is not None:
        raise SamplingError("give either spacing or target_points, not both")
    if spacing is not None and not (isinstance(spacing, (int, float)) and math.isfinite(spacing)):
        raise SamplingError(f"spacing must be a finite number, got {spacing!r}")
    if spacing is not None and spacing <= 0:
        raise SamplingError(f"spacing must be positive, got {spacing}")
    if target_points is not None and (
        not isinstance(target_points, (int, np.integer)) or target_points < 10
    ):
        raise SamplingError(f"target_points must be an integer >= 10, got {target_points!r}")
    lo, hi = RATIO_RANGE
    if not (isinstance(ratio, (int, float)) and lo <= ratio <= hi):
        raise SamplingError(
            f"ratio must be within [{lo}, {hi}] (Condition III-ii needs 1/sqrt(3) < r < sqrt(3)),"
            f" got {ratio!r}"
        )
    if not (isinstance(jitter, (int, float)) and math.isfinite(jitter) and jitter >= 0):
        raise SamplingError(f"jitter must be a finite number >= 0, got {jitter!r}")
    if not (isinstance(dropout, (int, float)) and 0 <= dropout < 1):
        raise SamplingError(f"dropout must be within [0, 1), got {dropout!r}")
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0:
        raise SamplingError(f"seed must be an integer >= 0, got {seed!r}")
    dirs = np.asarray(AXES if directions is None else directions, dtype=float)
    if dirs.ndim != 2 or dirs.shape[1] != 3 or dirs.shape[0] < 1:
        raise SamplingError(f"directions must have shape (d, 3), got {dirs.shape}")
    norms = np.linalg.norm(dirs, axis=1)
    if not np.all(np.isfinite(norms)) or np.any(norms == 0):
        raise SamplingError("directions must be finite, non-zero vectors")
    return dirs / norms[:, None]


def _box_corners(lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """The 8 corners of the box ``[lo, hi]`` (x slowest, z fastest)."""
    return np.array(
        [[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])]
    )


def _faces_of(reports: list[dict]) -> set[int]:
    """The faces the layouts' and repairs' ``reports`` name (``faces`` or ``face``)."""
    took = [f for x in reports for f in x.get("faces", [x.get("face")])]
    return {int(f) for f in took if f is not None}


def _distinct(points: np.ndarray, on_feature: np.ndarray, radius: float) -> np.ndarray:
    """Indices (sorted) of the samples kept when no two may be closer than
    ``radius`` (the sampler's contract: h/4): :func:`~.faces.thin` over the
    samples that have such a neighbour, edge and corner samples first, each
    group in index order.  Layouts that lay a sample where another already
    stands (a seam or rim laid by both its faces) would otherwise leave
    duplicates: a generated cone fused with a box came out with two samples
    0 apart."""
    close = np.unique(cKDTree(points).query_pairs(radius, output_type="ndarray"))
    if close.size == 0:
        return np.arange(points.shape[0])
    close = close[np.argsort(~on_feature[close], kind="stable")]
    gone = np.zeros(points.shape[0], dtype=bool)
    gone[close] = True
    gone[close[thin(points[close], radius)]] = False
    return np.flatnonzero(~gone)


def _dividing_step(extent: float, h: float) -> float:
    """The spacing nearest ``h`` that divides ``extent`` into whole steps."""
    return extent / steps(extent, h) if extent > 0 else h


def _parallel_edge_offsets(face, d: np.ndarray, tol: float) -> list[float]:
    """Offsets along ``d`` of a planar face's straight edges that lie in a
    plane normal to ``d`` (edges parallel to the face's rows)."""
    if face.geomType() != "PLANE":
        return []
    out = []
    for e in face.Edges():
        if e.geomType() != "LINE":
            continue
        a = np.array(e.startPoint().toTuple())
        b = np.array(e.endPoint().toTuple())
        t = b - a
        if norm(t) > tol and abs(float(dot(t, d))) <= 1e-9 * norm(t):
            out.append(float(dot(a, d)))
    return out


def _on_lattice(offsets: np.ndarray, t0: float, hf: float) -> bool:
    """Whether every offset lies on a plane ``t0 + j hf`` (to 1e-6 of a step)."""
    q = (offsets - t0) / hf
    return bool(np.all(np.abs(q - np.round(q)) <= 1e-6))


def _anchored(off: np.ndarray, t0: float, hf: float, h: float, tol: float):
    """A lattice of planes (first, spacing) holding every offset in ``off``
    (sorted): the default ``(t0, hf)`` when it does; else anchored on the
    least offset, its spacing the one nearest ``h`` dividing their span (the
    default spacing when they coincide within ``tol`` or lie within
    ``LEAST_SPAN`` h: a chamfer's setback of 0.6 h made a cap's rows and
    its edges' samples 0.6 h apart); None when no such lattice holds them
    all."""
    if off.size == 0 or _on_lattice(off, t0, hf):
        return t0, hf
    span = float(off[-1] - off[0])
    if span <= max(tol, LEAST_SPAN * h):
        # edges within a sliver's width (a chamfer's setback) divide no
        # span into steps near h: anchored on the first, default spacing
        return float(off[0]), hf
    hs = _dividing_step(span, h)
    return (float(off[0]), hs) if _on_lattice(off, float(off[0]), hs) else None


def _aligned_planes(faces, fam, dirs, corner, h: float, tol: float):
    """First plane and spacing of every face's scan planes, and of every
    family's shared lattice (direction index -> (t0, hf)).

    A family (the faces cut by one direction ``d``) shares one lattice of
    planes ``t0 + j hf``, so that rows go on across the edges between its
    faces.  By default the spacing divides the shape's extent along ``d``
    (the last plane meets the far side as the first meets the near side).
    A straight edge parallel to the rows (in a plane normal to ``d``) must
    lie on a plane too: there the face's rows run along the sampled edge,
    and a plane falling just inside it is dropped (``FEATURE_CLEARANCE``),
    leaving a gap of almost two steps (a hexagonal prism's side faces: the
    rows 1.73 h from the vertical edges, rectangles of ratio 0.862).  Such
    edges' offsets then anchor the lattice: ``t0`` at the least, ``hf``
    dividing the span of them all when their gaps are whole multiples of
    it (to 1e-6 of a step), else each face with such edges takes its own
    lattice, anchored on its least and dividing its own span
    (:func:`_anchored`; edges at one offset keep the default spacing).  A
    family whose edges already lie on the default lattice (boxes, models
    measured in round numbers) keeps it unchanged.  A family whose faces
    have no such edges (a cylinder standing on a box) is anchored on the
    other faces' straight edges across ``d`` the same way, so that the rows
    along ``d`` elsewhere (sampled on this lattice) meet those edges'
    samples (the box's sides, 0.3 h off its vertical edges' samples before).
    """
    family: dict[int, tuple[float, float]] = {}
    own: dict[int, tuple[float, float]] = {}  # faces on a lattice of their own
    offsets = [_parallel_edge_offsets(f, dirs[fam[i]], tol) for i, f in enumerate(faces)]
    for k in sorted(set(fam)):
        proj = dot(corner, dirs[k])
        t0 = float(proj.min())
        hf = _dividing_step(float(proj.max()) - t0, h)
        mine = [i for i in range(len(faces)) if fam[i] == k]
        own_edges = sorted(o for i in mine for o in offsets[i])
        if not own_edges:  # the other faces' edges across d (a post on a box)
            own_edges = sorted({o for f in faces for o in _parallel_edge_offsets(f, dirs[k], tol)})
        shared = _anchored(np.array(own_edges), t0, hf, h, tol)
        family[k] = shared or (t0, hf)
        if shared is not None:
            continue
        # no lattice holds every such edge of the family: each face with
        # such edges off the default lattice takes its own
        for i in mine:
            off = np.array(sorted(offsets[i]))
            if off.size and not _on_lattice(off, t0, hf):
                own[i] = _anchored(off, t0, hf, h, tol) or (
                    float(off[0]),
                    _dividing_step(float(off[-1] - off[0]), h),
                )
    return [own.get(i, family[fam[i]]) for i in range(len(faces))], family


def _anchor_axes(faces, dirs, family, anchor, axis_steps, ratio: float, h: float, tol: float):
    """Anchor the lattice along each coordinate axis that no family of scan
    planes sets, in place: on the straight edges across that axis, as a
    family's planes are (:func:`_anchored`).

    A row along an axis is sampled on that axis's lattice, by default the
    bounding box's (its extent over a whole number of steps).  A box under
    a dome has its top edges inside the box, off that lattice, and the
    rows of its sides then end 0.3 h from the top edges' samples, staggered
    against its vertical edges' (a box of 0.6 under a dome rising to 0.9:
    0.941 there by the geodesic check).  Straight edges across the axis
    anchor the lattice instead, when one lattice holds them all; when they
    lie on the default lattice already (boxes, models measured in round
    numbers) nothing changes.
    """
    set_by_family = {a for k in family if (a := axis_index(dirs[k])) is not None and dirs[k][a] > 0}
    for a in range(3):
        if a in set_by_family:
            continue
        offsets = {o for f in faces for o in _parallel_edge_offsets(f, np.eye(3)[a], tol)}
        if not offsets:
            continue
        got = _anchored(np.array(sorted(offsets)), float(anchor[a]), axis_steps[a] / ratio, h, tol)
        if got is not None:
            anchor[a], axis_steps[a] = got[0], ratio * got[1]


def _face_columns(face, anchor, axis_steps, ratio: float, h: float, tol: float):
    """A planar face's own lattice along each coordinate axis (anchor,
    steps), for the samples of its rows along that axis: anchored on its
    straight edges across the axis (:func:`_anchored`) where they do not lie
    on the shape's lattice (``anchor``, ``axis_steps``), which any other
    face keeps.

    An edge along a face's rows is divided into equal steps from end to
    end.  The rows' samples stood on the shape's lattice, so a face shorter
    than the shape along its rows (a box's side under a chamfered top edge:
    0.388 of 0.4) ended its rows staggered against its edges' samples, a
    little more at each step (ratios 0.87 to 1.0 up the side's vertical
    edges); its own lattice divides the span of its edges across the axis
    as those edges' equal steps do."""
    if face.geomType() != "PLANE":
        return anchor, axis_steps
    own_anchor, own_steps = anchor.copy(), axis_steps.copy()
    for k in range(3):
        off = np.array(sorted(_parallel_edge_offsets(face, np.eye(3)[k], tol)))
        hf = float(axis_steps[k]) / ratio
        if off.size == 0 or _on_lattice(off, float(anchor[k]), hf):
            continue
        t0, hk = _anchored(off, float(anchor[k]), hf, h, tol) or (
            float(off[0]),
            _dividing_step(float(off[-1] - off[0]), h),
        )
        own_anchor[k], own_steps[k] = t0, ratio * hk
    return own_anchor, own_steps


def _strip_rows(ef: EdgeFaces, dirs: np.ndarray, fam: list[int], h: float, tol: float):
    """Scan directions with a narrow planar strip's rows along its edges.

    A planar face between two parallel straight edges, its corners all
    within ``NARROW_BAND`` h of each one's line but not within
    ``STRIP_WIDTH`` h (a strip, whose rows would all fall within the
    clearance of its edges), holds at most two rows between its edges.  The
    planes of its family cut it across them when its edges run along no
    scan direction and across none: a chamfer along a prism's slanted edge
    (a prism over 4 corners chamfered 0.042 at 3,000 samples, 1.76 h wide)
    kept 4 samples of its rows inside it, and the repair left 41 of its
    triangles at or above the margin (worst 0.991).  Such a face is
    scanned by planes normal to ``n x u`` (``n`` its normal, ``u`` the
    longer edge's direction; its largest component made positive, the first
    on a tie), its rows parallels of its edges (:func:`_strip_planes` sets
    their spacing).  A strip whose edges run along or across its family's
    direction keeps it (a chamfer on an axis-aligned box: its rows across
    it put one sample on each of the edges' columns).

    A face's straight edges longer than ``tol`` (:meth:`EdgeFaces.straight`)
    are tried longest first (the first in the shape's edge order on a tie).
    Returns the directions (``dirs`` with new ones appended, one shared by
    strips parallel to each other), each face's direction index, and per
    strip its two edges (face index -> (longer, other), edge indices).
    """
    out, fam = [np.asarray(d, dtype=float) for d in dirs], list(fam)
    strips = {}
    lines, by_face = ef.straight(tol)
    for fi, face in enumerate(ef.faces):
        if face.geomType() != "PLANE":
            continue
        mine = sorted(by_face.get(fi, ()), key=lambda ei: (-lines[ei][2], ei))
        pick = None
        for i, e1 in enumerate(mine):
            width = width_across(face, *lines[e1][:2])
            if not STRIP_WIDTH * h <= width < NARROW_BAND * h or lines[e1][2] < 2.0 * width:
                continue
            for e2 in mine[i + 1 :]:
                gap = _parallel_gap(lines, e1, e2)
                if gap is not None and abs(gap - width) <= 1e-6 * width:
                    pick = (e1, e2)
                    break
            if pick is not None:
                break
        if pick is None:
            continue
        u = lines[pick[0]][1]
        along = abs(float(dot(out[fam[fi]], u)))
        if along <= 1e-9 or along >= 1.0 - 1e-9:
            continue  # rows along the strip's edges, or across them
        d = np.cross(np.array(face.normalAt().toTuple()), u)
        d /= norm(d)
        k = int(np.argmax(np.abs(d) - 1e-12 * np.arange(3)))
        d = d if d[k] > 0 else -d
        same = [j for j, e in enumerate(out) if float(dot(e, d)) >= 1.0 - 1e-12]
        if same:
            fam[fi] = same[0]
        else:
            fam[fi] = len(out)
            out.append(d)
        strips[fi] = pick
    return np.array(out), fam, strips


def _parallel_gap(lines, e1: int, e2: int) -> float | None:
    """How far apart the lines of two straight edges run (``lines`` from
    :meth:`EdgeFaces.straight`); None where they are not parallel."""
    a1, u1, _ = lines[e1]
    a2, u2, _ = lines[e2]
    if abs(abs(float(dot(u1, u2))) - 1.0) > 1e-9:
        return None
    return float(norm((a2 - a1) - dot(a2 - a1, u1) * u1))


def _strip_planes(
    strips, ef: EdgeFaces, planes: list, h: float, tol: float
) -> dict[int, tuple[float, float]]:
    """The first plane and spacing of each narrow strip's rows
    (:func:`_strip_rows`): anchored on its two edges, the width divided into
    ``R`` steps near the step of its edges' samples (``R`` at least 1).

    The edges' samples take the lattice of the rows of the faces across
    them (:func:`_row_crossings`; the other edge follows across the strip,
    :func:`_side_followers`), and the strip's rows take their columns: a
    rectangle of the step along by ``width / R`` across, whose ratio is
    lowest when its sides are nearest.  A cap's rows crossing a 45 degree
    edge 1.4 h apart made the middle row of a strip 1.6 h wide cells of
    1.4 by 0.8 (ratio 0.87); without it they are 1.4 by 1.6 (0.75).  The
    step along is that of the first of the two edges (the longer first)
    whose faces across hold rows crossing it, else the longer's equal
    steps.  ``tol``: the straight edges' length bound, as for the strips."""
    out = {}
    lines = ef.straight(tol)[0]
    for fi, (e1, e2) in sorted(strips.items()):
        d = planes[fi][0]
        along = None
        for ei in (e1, e2):
            adjacent = [j for j in ef.faces_of[ei] if j != fi]
            a, u, _ = lines[ei]
            cross = _row_crossings(
                a, u, ef.edges[ei].Length(), adjacent, ef.faces, planes, EDGE_STEP * h
            )
            if cross is not None:
                along = cross[1]
                break
        if along is None:
            length = ef.edges[e1].Length()  # the edge's own length, as its equal steps take it
            along = length / steps(length, EDGE_STEP * h)
        off = sorted(float(dot(lines[ei][0], d)) for ei in (e1, e2))
        width = off[1] - off[0]
        out[fi] = (off[0], width / steps(width, along))
    return out


def _face_family(face, dirs: np.ndarray, tol: float) -> int:
    """The direction that cuts the face most transversally (area-weighted |n·d|)."""
    p, t = face_mesh(face, tol, 0.3)
    if not t.shape[0]:
        return 0
    cr = np.cross(p[t[:, 1]] - p[t[:, 0]], p[t[:, 2]] - p[t[:, 0]])
    area = np.linalg.norm(cr, axis=1)
    keep = area > 0
    if not keep.any():
        return 0
    n = cr[keep] / area[keep][:, None]
    score = (np.abs(dot(n[:, None, :], dirs[None, :, :])) * area[keep][:, None]).sum(axis=0)
    score /= area[keep].sum()
    best = float(score.min())
    return int(np.flatnonzero(score <= best + 1e-9)[0])


def _edges_of(shape) -> list:
    import cadquery as cq
    from OCP.TopAbs import TopAbs_EDGE
    from OCP.TopExp import TopExp_Explorer

    out = []
    ex = TopExp_Explorer(shape, TopAbs_EDGE)
    while ex.More():
        out.append(cq.Edge(ex.Current()))
        ex.Next()
    return out


def _section(face, origin, normal) -> list:
    """Edges of the intersection of a face with a plane.

    The section is non-destructive: by default OCC's Boolean operations may
    raise the tolerances of their arguments' edges and vertices in place,
    and a later section of the same face (in this scan or another scan of
    the same solid) then differs in its last bits.
    """
    from OCP.BRepAlgoAPI import BRepAlgoAPI_Section
    from OCP.gp import gp_Dir, gp_Pln, gp_Pnt

    sec = BRepAlgoAPI_Section(face.wrapped, gp_Pln(gp_Pnt(*origin), gp_Dir(*normal)), False)
    sec.SetNonDestructive(True)
    sec.Approximation(True)
    sec.Build()
    if not sec.IsDone():
        return []
    return [e for e in _edges_of(sec.Shape()) if e.Length() > 0]


def _chains(edges, tol: float) -> list[tuple[list[tuple[Any, bool]], bool]]:
    """Chain edges end to end: lists of (edge, reversed) and whether closed."""
    remaining = list(edges)
    ends = {
        id(e): (np.array(e.startPoint().toTuple()), np.array(e.endPoint().toTuple())) for e in edges
    }
    chains = []
    while remaining:
        e0 = remaining.pop(0)
        chain = [(e0, False)]
        head, tail = ends[id(e0)]
        grown = True
        while grown:
            grown = False
            for i, e in enumerate(remaining):
                s, t = ends[id(e)]
                if norm(s - tail) <= tol:
                    chain.append((e, False))
                    tail = t
                elif norm(t - tail) <= tol:
                    chain.append((e, True))
                    tail = s
                elif norm(t - head) <= tol:
                    chain.insert(0, (e, False))
                    head = s
                elif norm(s - head) <= tol:
                    chain.insert(0, (e, True))
                    head = t
                else:
                    continue
                remaining.pop(i)
                grown = True
                break
        closed = bool(norm(head - tail) <= tol)
        chains.append((chain, closed))
    return chains


def _even_ends(s: np.ndarray, length: float, clear: float) -> np.ndarray:
    """Lattice positions on a segment ``[0, length]`` whose ends are sampled
    corners or edges: positions nearer than ``clear`` to an end are dropped
    (:func:`_drop_near_features` would drop them) and an end gap wider than
    ``2 clear`` gets a position in its middle.  A lattice anchored elsewhere
    leaves any gap up to ``clear`` plus its spacing at an end; the right
    triangle it makes with the end's samples breaks Condition III-ii once
    its legs differ by half (a star prism's first column 1.8 h from its
    reflex edge: ratio 0.875)."""
    s = s[(s >= clear) & (s <= length - clear)]
    if s.size == 0:
        return s
    extra = []
    if s[0] > 2 * clear:
        extra.append(s[0] / 2)
    if length - s[-1] > 2 * clear:
        extra.append((length + s[-1]) / 2)
    return np.sort(np.concatenate([s, extra]))


def _sample_chain(
    chain,
    closed: bool,
    step: float,
    anchor: np.ndarray,
    axis_steps=None,
    edge_lattices=(),
    ratio: float = 1.0,
    sphere=None,
    clear: float = 0.0,
    cross=None,
) -> np.ndarray:
    """Samples along a chain of edges, about ``step`` apart.

    A straight segment is sampled where its coordinate along its own
    direction, measured from ``anchor`` (the shape's bounding-box minimum),
    is a multiple of ``step`` (plus both ends): parallel scan lines
    of a planar face then share one lattice, the rectangular lattice of
    Figure 1, instead of staggered rows.  A segment along no coordinate
    axis but parallel to one of its face's sampled straight edges
    (``edge_lattices``, from :func:`_feature_samples`: start, direction,
    step and whether it holds another face's row crossings) takes the
    lattice of the first such edge that holds crossings, else of the
    nearest (anchored at its start, ``ratio`` times its step), so that the
    row next to the edge does not stagger against the edge's samples (a
    star prism's sides, a wedge's slanted faces), and the face's rows
    share one lattice where two edges hold two (the interior, which no
    repair moves, keeps its columns; the other edge's layer is repaired);
    its gaps at the row's ends are evened (:func:`_even_ends`, with
    ``clear``).  Any other segment along no axis takes its face's lattice
    across its rows where the face has one (``cross``, from
    :func:`_cross_lattice`).  An open section of a partial sphere (``sphere``, from
    :func:`_sphere_frame`) is sampled by :func:`_sphere_row`.  Any other
    chain is sampled at equal arc-length steps from its start (for a closed
    section of a surface of revolution: from the seam, so rows line up too).
    """
    if len(chain) == 1 and not closed and chain[0][0].geomType() == "LINE":
        e = chain[0][0]
        a = np.array(e.startPoint().toTuple())
        b = np.array(e.endPoint().toTuple())
        length = float(norm(b - a))
        u = (b - a) / length
        aligned = True
        if axis_steps is not None:
            # a row along a coordinate axis steps like the planes across that
            # axis (the extent over a whole number of steps), so that its
            # samples meet the corner and edge samples of the faces it crosses
            k = axis_index(u)
            if k is not None:
                step = float(axis_steps[k])
            else:
                par = [
                    (ea, es, held)
                    for ea, eu, es, held in edge_lattices
                    if abs(abs(dot(eu, u)) - 1.0) < 1e-9
                ]
                if par:
                    held = [i for i, x in enumerate(par) if x[2]]
                    if held:
                        pick = held[0]
                    else:
                        mid = (a + b) / 2
                        off = [norm((mid - ea) - (dot(mid - ea, u)) * u) for ea, _, _ in par]
                        pick = int(np.argmin(off))
                    anchor, es, _ = par[pick]
                    step = ratio * es
                    aligned = False
                elif cross is not None:
                    rows, t0, step = cross
                    anchor = t0 * rows
        c0 = float(dot(a - anchor, u))
        first = math.ceil(c0 / step - 1e-9)
        last = math.floor((c0 + length) / step + 1e-9)
        s = np.arange(first, last + 1) * step - c0
        s = s[(s > 1e-9 * length) & (s < length * (1 - 1e-9))]
        if not aligned and clear > 0:
            s = _even_ends(s, length, clear)
        s = np.concatenate([[0.0], s, [length]])
        return a + s[:, None] * u
    if sphere is not None and not closed:
        return _sphere_row(chain, step, sphere)
    lengths = np.array([e.Length() for e, _ in chain])
    total = float(lengths.sum())
    m = steps(total, step)
    if closed and m < 3:
        m = 3
    count = m if closed else m + 1
    s = np.arange(count) * (total / m)
    starts = np.concatenate([[0.0], np.cumsum(lengths)[:-1]])
    return np.array([_chain_point(chain, lengths, starts, si) for si in s]).reshape(-1, 3)


def _chain_point(chain, lengths: np.ndarray, starts: np.ndarray, s: float) -> np.ndarray:
    """The point at arc length ``s`` along a chain of (edge, reversed) whose
    edges have these lengths and start at these arc lengths."""
    j = int(np.searchsorted(starts, s, side="right") - 1)
    j = min(max(j, 0), len(chain) - 1)
    e, rev = chain[j]
    frac = min(max((s - starts[j]) / lengths[j], 0.0), 1.0)
    if rev:
        frac = 1.0 - frac
    return np.array(e.positionAt(frac, mode="length").toTuple())


def _sphere_frame(face, d: np.ndarray):
    """(centre, radius, e1, e2, d) of a sphere face that does not go all the
    way round, with e1, e2 completing the scan direction ``d`` to a frame;
    None for any other face."""
    if face.geomType() != "SPHERE" or goes_round(face):
        return None
    sph = basis_surface(face).Sphere()
    centre = np.array(sph.Location().Coord())
    e1 = perpendicular(d)
    return centre, float(sph.Radius()), e1, np.cross(d, e1), d


def _sphere_row(chain, step: float, sphere) -> np.ndarray:
    """Samples of an open section of a partial sphere: its ends, and the
    points between them at multiples of one angle about the scan direction
    through the sphere's centre.

    The angle is ``step / R`` times the power of two that keeps the row's
    gaps in [0.75, 1.5) ``step`` (R: the sphere's radius), so the rows of the
    face share their columns, every other one ending where a row's gaps
    would fall below 0.75 ``step``, instead of staggering (rows sampled from
    their own starts made near-equilateral triangles all over fillet_box's
    corners and cutcube's scoop).
    """
    centre, radius, e1, e2, d = sphere
    (first, rev0), (last, rev1) = chain[0], chain[-1]
    ends = [
        np.array((first.endPoint() if rev0 else first.startPoint()).toTuple()),
        np.array((last.startPoint() if rev1 else last.endPoint()).toTuple()),
    ]
    lengths = np.array([e.Length() for e, _ in chain])
    starts = np.concatenate([[0.0], np.cumsum(lengths)[:-1]])
    mid = _chain_point(chain, lengths, starts, float(lengths.sum()) / 2)
    cc = centre + float(dot(ends[0] - centre, d)) * d
    r = float(norm(ends[0] - cc))
    if r < 1e-12:
        return np.array(ends)

    def angle(p):
        q = p - cc
        return math.atan2(float(dot(q, e2)), float(dot(q, e1)))

    a0, am, a1 = angle(ends[0]), angle(mid), angle(ends[1])
    span = (a1 - a0) % (2 * math.pi)
    sign = 1.0 if (am - a0) % (2 * math.pi) <= span else -1.0
    if sign < 0:
        span = 2 * math.pi - span
    dt = step / radius
    while r * dt < 0.75 * step:
        dt *= 2
    lo, hi = (a0, a0 + span) if sign > 0 else (a0 - span, a0)
    k = np.arange(math.ceil(lo / dt + 1e-9), math.floor(hi / dt - 1e-9) + 1)
    th = k * dt if sign > 0 else (k * dt)[::-1]
    inner = cc + r * (np.cos(th)[:, None] * e1 + np.sin(th)[:, None] * e2)
    return np.vstack([ends[0][None], inner, ends[1][None]])


def _plane_offsets(lo: float, hi: float, t0: float, hf: float, sphere=None) -> np.ndarray:
    """Offsets along the family's direction of the planes whose sections are
    a face's rows, the face spanning ``[lo, hi]`` along it: the family's
    planes ``t0 + j hf``, or for a partial sphere with sharp rims
    (``sphere``, from :func:`_sphere_frame`) the planes ``hf`` apart along
    its meridians, from the pole on the side of ``-d``.  Planes ``hf`` apart
    graze the sphere near a pole: their rows there are farther apart on it,
    and where the columns halve such rows made near-equilateral triangles
    (cutcube's scoop: 13 at a ratio of 0.99 to 1.0).  A sphere blending
    into its neighbours (fillet_box's corners) keeps the family's planes,
    whose rows go on across the seams (with meridian rows 3.8% of its
    samples violated III-ii instead of 2.1%)."""
    if sphere is None:
        j0 = math.ceil((lo - t0) / hf - 1e-9)
        j1 = math.floor((hi - t0) / hf + 1e-9)
        return t0 + np.arange(j0, j1 + 1) * hf
    centre, radius, _, _, d = sphere
    c = float(dot(centre, d))
    psi = libm.arccos(np.clip((c - np.array([lo, hi])) / radius, -1.0, 1.0))  # grows with t
    step = hf / radius
    k = np.arange(math.ceil(psi[0] / step - 1e-9), math.floor(psi[1] / step + 1e-9) + 1)
    return c - radius * np.cos(k * step)


def _drop_near_features(points, on_line, feature_curve, radius):
    """Drop scan-line samples lying within ``radius`` of a sampled corner or edge.

    ``feature_curve`` is a dense polyline (h/8 apart) of the sampled edges.

    A scan line ends on its face's boundary; where that boundary is a sharp
    edge it is already sampled along its length, and a line sample close to
    it (its end, or a point of a line meeting the edge at a grazing angle)
    would make a sliver triangle, breaking Condition III-ii, and would sit
    closer to the other face's samples than the edge samples are to each
    other.
    """
    keep = np.ones(points.shape[0], dtype=bool)
    if feature_curve.shape[0] == 0 or not on_line.any():
        return keep
    d, _ = cKDTree(feature_curve).query(points[on_line])
    keep[np.flatnonzero(on_line)[d < radius]] = False
    return keep


def _cross_lattice(face, d, hf: float, ratio: float, anchor, tol: float):
    """The lattice ``(rows, t0, step)`` (the rows' direction, the first
    column's offset along it, the columns' spacing) along a planar face's
    rows when they run along no coordinate axis, anchored on its straight
    edges across them (perpendicular to the rows, in the face): None where
    there are none, where the default lattice (from the projection of
    ``anchor``, ``ratio`` times ``hf``) holds them already, or where no
    lattice holds them all (:func:`_anchored`).

    A row ending on such an edge was sampled from the shape's anchor, so
    its last sample fell anywhere up to a step from the edge, and the one
    within ``FEATURE_CLEARANCE`` h of it was dropped: a box's top edge
    chamfered at 45° (a face whose rows run down its slope) kept a band of
    rectangles 1.72 h across by 1 h along both of its long edges, ratio
    0.864, and 271 of 5,966 samples broke III-ii by the geodesic check.
    Anchored there, the rows divide the span between the edges into whole
    steps, as :func:`_face_columns` does for rows along an axis."""
    rows = row_direction(face, d)
    if rows is None or axis_index(rows) is not None:
        return None
    off = _parallel_edge_offsets(face, rows, tol)  # the edges normal to the rows
    if not off:
        return None
    step = ratio * hf
    default = float(dot(anchor, rows))
    got = _anchored(np.array(sorted(off)), default, step, step, tol)
    if got is None or got == (default, step):
        return None
    return rows, *got


def _columns(face, d, hf, ratio, anchor, axis_steps, cross=None):
    """The planes through a planar face's columns, as :func:`_sample_chain`
    places samples along its rows (normal, offset, spacing); None for a
    curved face or one with a straight edge parallel to its rows (those
    rows take that edge's samples as columns).  ``cross`` is the face's
    lattice along rows that run along no axis (:func:`_cross_lattice`)."""
    rows = row_direction(face, d)
    if rows is None:
        return None
    for e in face.Edges():
        if e.geomType() == "LINE":
            t = np.array(e.endPoint().toTuple()) - np.array(e.startPoint().toTuple())
            if abs(abs(float(dot(t, rows))) - norm(t)) <= 1e-9 * norm(t):
                return None
    k = axis_index(rows)
    if k is not None:
        axis = np.zeros(3)
        axis[k] = 1.0
        return axis, float(anchor[k]), float(axis_steps[k])
    if cross is not None:
        return cross
    return rows, float(dot(anchor, rows)), ratio * hf


def _plane_crossings(a, u, length: float, normal, offset: float, gap: float) -> np.ndarray:
    """Arc lengths (sorted) where the planes ``offset + j gap`` along
    ``normal`` cross the segment from ``a`` along ``u`` (not parallel to
    them), its ends included when a plane passes through them."""
    un = float(dot(u, normal))
    ends = sorted((float(dot(a, normal)), float(dot(a + length * u, normal))))
    j = np.arange(
        math.ceil((ends[0] - offset) / gap - 1e-9),
        math.floor((ends[1] - offset) / gap + 1e-9) + 1,
    )
    return np.sort((offset + j * gap - float(dot(a, normal))) / un)


def _row_crossings(a, u, length, adjacent, faces, planes, step):
    """Where the lattice lines of an adjacent planar face (``adjacent``:
    indices into ``faces``) cross a straight edge slanted to that face's
    rows, if they cross it at most ``SLANT_STEP`` steps apart (the densest
    crossing wins, the first face and rows before columns on ties).

    The lattice lines are the face's scan planes (normal, offset, spacing)
    and, where known, the planes through its columns (the sample positions
    along the rows).  Sampled at their crossings, the edge holds the ends of
    that face's rows or columns, which then end on edge samples instead of
    staggering against equal arc-length ones.  Returns the arc lengths of
    the samples (the crossings with the ends evened by :func:`_even_ends`:
    the corners are sampled), their spacing and the arc length of one
    crossing (the lattice's anchor), or None.
    """
    if planes is None:
        return None
    best = None
    for fi in adjacent:
        f = faces[fi]
        if f.geomType() != "PLANE":
            continue
        d, t0, hf, columns = planes[fi]
        along = row_cosine(f, d, u)
        if along is None or along < 1e-6 or along > 1 - 1e-6:
            continue  # rows parallel or perpendicular to the edge: equal steps fit
        for normal, offset, gap in [(d, t0, hf)] + ([columns] if columns else []):
            un = float(dot(u, normal))
            if abs(un) < 1e-9:
                continue
            spacing = gap / abs(un)
            if spacing > SLANT_STEP * step or (best is not None and spacing >= best[0] - 1e-12):
                continue
            lattice = _plane_crossings(a, u, length, normal, offset, gap)
            if lattice.size:
                best = (spacing, _even_ends(lattice, length, FEATURE_CLEARANCE * step), lattice[0])
    if best is None or best[1].size == 0:
        return None
    return best[1], best[0], best[2]


def _polygonal(face) -> bool:
    """Whether a face is planar and bounded by straight edges only."""
    return face.geomType() == "PLANE" and all(e.geomType() == "LINE" for e in face.Edges())


def _square_crossings(a, u, length, adjacent, faces, polygonal, planes, axes, step):
    """Where the lattice of an adjacent planar face (``adjacent``: indices
    into ``faces``; ``polygonal``: per face, :func:`_polygonal`) meets a
    straight edge along or across its rows: its scan
    planes for an edge across them, the shape's lattice along the edge's
    coordinate axis (``axes``: anchor and steps, as the rows along that axis
    are sampled) for an edge along them.  None where the edge's equal steps
    are those positions already, or no such face exists.

    An edge square to the rows was divided into equal steps from end to
    end, and a face shorter than the shape (a box's side under a chamfered
    top edge: 0.388 of 0.4; the sides of a box fused on another) ended its
    rows staggered against those steps, a little more at each step (ratios
    0.87 to 1.0 along the edge).  Returns the arc lengths of the samples,
    with the ends evened by :func:`_even_ends` (the corners are sampled),
    their spacing and the arc length of one crossing, as
    :func:`_row_crossings` does."""
    if planes is None or axes is None:
        return None
    if not all(polygonal[fi] for fi in adjacent):
        return None  # a face with an arc: its repair slides the arc's samples, not these
    k = axis_index(u)
    for fi in adjacent:
        f = faces[fi]
        if f.geomType() != "PLANE":
            continue
        anchor, axis_steps = axes[fi]
        d, t0, hf, _ = planes[fi]
        along = row_cosine(f, d, u)
        if along is None:
            continue
        if along < 1e-9:  # the edge across the rows: the face's scan planes
            normal, offset, gap = d, t0, hf
        elif along > 1 - 1e-9 and k is not None:  # along them: the axis lattice
            normal, offset, gap = np.eye(3)[k], float(anchor[k]), float(axis_steps[k])
        else:
            continue
        un = float(dot(u, normal))
        lattice = _plane_crossings(a, u, length, normal, offset, gap)
        inner = lattice[(lattice > 1e-9 * length) & (lattice < length * (1 - 1e-9))]
        m = steps(length, step)
        even = np.arange(1, m) * (length / m)
        if inner.size == even.size and np.allclose(inner, even, rtol=0, atol=1e-9 * length):
            return None  # the equal steps are the lattice's crossings
        kept = _even_ends(lattice, length, FEATURE_CLEARANCE * step)
        if kept.size == 0:
            return None
        return kept, gap / abs(un), float(lattice[0])
    return None


def _feature_samples(
    occ,
    step: float,
    sharp_degrees: float,
    tol: float,
    planes=None,
    axes=None,
    banded=frozenset(),
    ef: EdgeFaces | None = None,
):
    """Samples on B-rep vertices and on sharp or boundary edges.

    Returns the samples, their faces, a dense polyline of the sampled edges,
    and per face the lattice of each of its sampled straight edges (start,
    unit direction, step, whether it holds an adjacent face's row
    crossings): a straight edge of length L is divided into
    ``round(L / step)`` equal steps from its start, unless it follows
    another across a narrow strip (:func:`_strip_followers`), or ``planes``
    (per face, its scan planes' normal, offset, spacing and columns) show
    it slanted to an adjacent planar face's rows (:func:`_row_crossings`),
    or, between polygonal faces, along or across them off their lattice
    (:func:`_square_crossings`, with ``axes``: per face, the anchor and
    steps of its rows along each axis, :func:`_face_columns`).  An edge
    between a face of a chain of developable faces (``banded``,
    :mod:`sr33.samplers.bands`) and another takes the other's lattice.  Samples are
    listed edge by edge in the shape's edge order, whatever order the edges
    were sampled in.
    """
    ef = EdgeFaces(occ) if ef is None else ef
    faces = ef.faces
    pts: list[np.ndarray] = []
    fid: list[int] = []
    vertex_pts = [np.array(v.toTuple()) for v in occ.Vertices()]
    cos_lim = math.cos(math.radians(sharp_degrees))
    per_edge: dict[int, tuple[list[np.ndarray], int]] = {}  # edge -> its samples, face
    dense: list[tuple[float, float, float]] = [tuple(p) for p in vertex_pts]
    lattices: dict[int, list[tuple[np.ndarray, np.ndarray, float, bool]]] = {}
    follows = _strip_followers(ef, STRIP_WIDTH * step, tol, banded)
    if planes is not None:
        follows.update(_side_followers(ef, planes, step, tol, banded, follows))
    polygonal = [_polygonal(f) for f in faces]

    # an edge following another across a strip is sampled after it
    def depth(ei: int) -> int:  # how many leads stand before it (chains of followers)
        n = 0
        while ei in follows:
            ei, n = follows[ei], n + 1
        return n

    order = [i for i in range(len(ef.edges)) if i not in follows]
    order += sorted(follows, key=lambda ei: (depth(ei), ei))
    for ei in order:
        edge, fids, uses = ef.edges[ei], ef.faces_of[ei], ef.uses[ei]
        length = edge.Length()
        if length <= tol:
            continue
        uniq = [faces[k] for k in fids]
        first = fids[0] if fids else -1
        if len(uniq) == 2:
            if ef.bend(ei) > cos_lim:
                continue  # smooth edge (fillet tangency) or seam: sampled by scan lines
        elif len(uniq) != 1 or uses != 1:
            continue  # a seam edge (one face on both sides): sampled by scan lines
        m = steps(length, step)
        cross = None
        if edge.geomType() == "LINE":
            a = np.array(edge.startPoint().toTuple())
            u = (np.array(edge.endPoint().toTuple()) - a) / length
            if ei in follows and follows[ei] in per_edge:
                lead = ef.edges[follows[ei]]
                samples, lead_face = per_edge[follows[ei]]
                samples = _with_corners(lead, samples, [a, a + length * u], step)
                per_edge[follows[ei]] = (samples, lead_face)
                cross = _across_strip(a, u, length, lead, samples, step)
            # an edge of a chain of developable faces takes the lattice of the
            # face across it: the chain's layout joins whatever its loops hold
            lattice_of = [k for k in fids if k not in banded] if len(fids) == 2 else fids
            polys = polygonal
            if len(lattice_of) < len(fids):
                polys = [p or k in lattice_of for k, p in enumerate(polygonal)]
            if cross is None:
                cross = _row_crossings(a, u, length, lattice_of, faces, planes, step)
            held = cross is not None
            if cross is None:
                cross = _square_crossings(
                    a, u, length, lattice_of, faces, polys, planes, axes, step
                )
            lattice = (
                (a, u, length / m, held) if cross is None else (a + cross[2] * u, u, cross[1], held)
            )
            for k in fids:
                lattices.setdefault(k, []).append(lattice)
        if cross is not None:
            mine = [a + sj * u for sj in cross[0]]
        else:
            mine = [np.array(edge.positionAt(j / m, mode="length").toTuple()) for j in range(1, m)]
        per_edge[ei] = (mine, first)
    for p in vertex_pts:
        pts.append(p)
        fid.append(nearest_face(p, faces))
    for ei in sorted(per_edge):  # the samples and the dense polyline in the edges' order
        mine, first = per_edge[ei]
        pts += mine
        fid += [first] * len(mine)
        edge = ef.edges[ei]
        md = max(2, int(math.ceil(8 * edge.Length() / step)))
        dense += [edge.positionAt(j / md, mode="length").toTuple() for j in range(md + 1)]
    return pts, fid, np.array(dense, dtype=np.float64).reshape(-1, 3), lattices


def _strip_followers(ef: EdgeFaces, width: float, tol: float, banded=()) -> dict[int, int]:
    """Straight edges that follow another across a narrow planar strip
    (edge index -> the edge it follows).

    A planar face whose corners all lie within ``width`` (two clearances:
    no scan row fits inside) of the line of one of its straight edges is a
    strip, a chamfer's across a box's edge.  Its two long edges were
    sampled each on its own lattice (the side's rows, the top's columns),
    half a step apart somewhere along it (ratio 1.0).  The shorter of two
    parallel straight edges of a strip follows the longer (the first on a
    tie), unless that one follows another strip itself.  A strip in a chain
    of developable faces (``banded``: a chamfer round a filleted profile)
    has no followers: the chain's layout joins its two edges' samples
    whatever they are (:mod:`sr33.samplers.bands`), and each edge keeps the
    lattice of the face across it (a chamfer on both ends of a filleted box
    had each end's edge follow its chamfer's other edge, half a step off
    the end's columns: 171 samples of each end at ratio 1.0)."""
    out: dict[int, int] = {}
    lines, by_face = ef.straight(tol)
    for k, mine in sorted(by_face.items()):
        face = ef.faces[k]
        if face.geomType() != "PLANE" or len(mine) < 2 or k in banded:
            continue
        for i, e1 in enumerate(mine):
            a1, u1, l1 = lines[e1]
            if width_across(face, a1, u1) >= width:
                continue
            for e2 in mine[i + 1 :]:
                l2 = lines[e2][2]
                gap = _parallel_gap(lines, e1, e2)
                if gap is None or gap <= tol:
                    continue
                lead, follow = (e1, e2) if l1 >= l2 - tol else (e2, e1)
                if lead not in out and follow not in out:
                    out[follow] = lead
    return out


def _side_followers(
    ef: EdgeFaces, planes, step: float, tol: float, banded=(), taken: dict | None = None
) -> dict[int, int]:
    """Straight edges that follow another across a planar face whose rows
    run along both (edge index -> the edge it follows): where of two
    parallel edges along a face's rows one holds the crossings of its
    other face's slanted rows (:func:`_row_crossings`: a chamfer's against
    a prism's side) and the other holds nothing but its equal steps, the
    other takes the first's samples across the face (as across a strip,
    :func:`_across_strip`).  The face's rows take their columns from the
    nearer of the two edges (:func:`_sample_chain`); on two lattices (a
    prism over a 4-corner polygon chamfered 0.042 at 3,000 samples: 1.03 h
    steps along the chamfer, 0.99 h along the base) its columns broke off
    in the middle row, 20 samples there at 0.87-0.89.

    An edge that follows holds its lead's lattice, so it may lead in turn
    (a chain): a chamfer scanned along its edges (:func:`_strip_rows`)
    has its edge on the side follow its edge on the cap, whose rows cross
    it, and the side's base follows that (of two edges that both hold a
    lattice, one by following and one by crossings, the first leads: the
    cap across the base then meets samples off its rows' ends, which its
    boundary layer's repair takes, rather than the side's columns breaking
    off in its middle).  Of two edges of such a strip
    (narrower than ``NARROW_BAND`` steps) that hold nothing, the shorter
    follows the longer (the first on a tie).  The faces are visited in
    order until no edge is added; an edge follows one edge at most, and
    never one that follows it; narrow faces are visited first, so that a
    strip's edges join across it.  Edges in ``taken`` (following, or
    followed, across a strip) and faces in ``banded`` are left alone."""
    out: dict[int, int] = {}
    busy = set(taken or {}) | set((taken or {}).values())
    lines, by_face = ef.straight(tol)
    held: dict[tuple[int, int], bool] = {}
    leads: set[int] = set()

    def holds(ei: int, k: int) -> bool:
        if (ei, k) not in held:
            other = [f for f in ef.faces_of[ei] if f != k]
            held[ei, k] = _row_crossings(*lines[ei], other, ef.faces, planes, step) is not None
        return held[ei, k] or ei in out

    def leads_to(lead: int, follow: int) -> bool:  # does ``lead`` follow ``follow``, at any remove?
        while lead in out:
            lead = out[lead]
            if lead == follow:
                return True
        return False

    def narrow(k: int) -> bool:
        face = ef.faces[k]
        return any(width_across(face, *lines[ei][:2]) < NARROW_BAND * step for ei in by_face[k])

    # the strips first (their two edges join across them), then the rest
    order = sorted(by_face, key=lambda k: (not narrow(k), k))
    added = True
    while added:
        added = False
        for k in order:
            face, mine = ef.faces[k], by_face[k]
            if face.geomType() != "PLANE" or k in banded:
                continue
            rows = row_direction(face, planes[k][0])
            if rows is None:
                continue
            along = [ei for ei in mine if abs(abs(float(dot(lines[ei][1], rows))) - 1.0) <= 1e-9]
            for i, e1 in enumerate(along):
                for e2 in along[i + 1 :]:
                    f1, f2 = holds(e1, k), holds(e2, k)
                    if f1 != f2:
                        lead, follow = (e1, e2) if f1 else (e2, e1)
                    elif f1 and (e1 in out) != (e2 in out):
                        lead, follow = (e1, e2) if e1 in out else (e2, e1)
                    elif f1 or width_across(face, *lines[e1][:2]) >= NARROW_BAND * step:
                        continue
                    else:  # a narrow strip's two free edges: the longer leads
                        lead, follow = (e1, e2) if lines[e1][2] >= lines[e2][2] - tol else (e2, e1)
                    if {lead, follow} & busy or follow in out or leads_to(lead, follow):
                        continue
                    if follow in leads:
                        continue  # it leads already: it keeps its own lattice
                    out[follow] = lead
                    leads.add(lead)
                    added = True
    return out


def _with_corners(lead, samples: list, corners: list, step: float) -> list:
    """A strip's leading edge's samples with its other edge's corners
    standing across it (:func:`_strip_followers`): each corner's foot
    inside the edge (at least half a step from its ends) becomes a sample,
    and the samples within ``FEATURE_CLEARANCE`` steps of it go.  A
    chamfer's strip ends on a slanted mitre: with the side's lattice on
    the leading edge, the strip's last cell had sides 1.02, 1.01 and 1.16
    (ratio 0.88) and the next 1.01, 1.38, 1.40 (0.98)."""
    a = np.array(lead.startPoint().toTuple())
    b = np.array(lead.endPoint().toTuple())
    length = float(norm(b - a))
    u = (b - a) / length
    at = np.array([float(dot(p - a, u)) for p in samples]).reshape(-1)
    for c in corners:
        t = float(dot(c - a, u))
        if not 0.5 * step <= t <= length - 0.5 * step:
            continue
        clear = FEATURE_CLEARANCE * step
        t = min(max(t, clear), length - clear)
        at = np.sort(np.r_[at[np.abs(at - t) >= clear], t])
    return [a + t * u for t in at]


def _across_strip(a, u, length: float, lead, lead_samples, step: float):
    """A strip's edge sampled where its leading edge's samples (and ends)
    stand across it (:func:`_strip_followers`, :func:`_side_followers`):
    the arc lengths of their feet on the edge, the ends evened
    (:func:`_even_ends`), their spacing and the arc length of one sample's
    foot (the lattice's anchor for rows along the edge); None where none
    falls on it."""
    ends = [np.array(lead.startPoint().toTuple()), np.array(lead.endPoint().toTuple())]
    at = np.array([float(dot(p - a, u)) for p in ends + list(lead_samples)])
    at = np.sort(at)
    if at.size < 2:
        return None
    lu = (ends[1] - ends[0]) / norm(ends[1] - ends[0])
    width = float(norm((a - ends[0]) - dot(a - ends[0], lu) * lu))
    if width < STRIP_STAGGER * float(np.median(np.diff(at))):
        at = (at[1:] + at[:-1]) / 2  # half a step on: isosceles cells across the strip
    kept = _even_ends(at, length, FEATURE_CLEARANCE * step)
    if kept.size == 0:
        return None
    # the lattice's anchor: a leading sample's foot (the first foot is the
    # leading edge's end, off the lattice by whatever its first step was)
    return kept, float(np.median(np.diff(at))), float(at[1] if at.size > 2 else at[0])


def _fill_gaps(occ, faces, points: np.ndarray, h: float, size: float) -> np.ndarray:
    """Samples added where the scan lines leave a gap wider than the spacing.

    Scan planes meet a face at a grazing angle where its normal turns towards
    the sweep direction (the poles of a sphere, a cone tip's neighbourhood),
    and the rows there are far apart.  Dense points of a fine tessellation
    farther than ``FILL_RADIUS · h`` from every sample are filled greedily,
    farthest first, each projected exactly onto the CAD surface, until every
    dense point is within that radius.
    """
    import cadquery as cq
    from OCP.BRepExtrema import BRepExtrema_DistShapeShape

    tv, tt = face_mesh(occ, size / 500.0, 0.1)
    if not tt.shape[0]:
        return np.empty((0, 3))
    dense = surface_points(tv, tt, 20000, seed=0)
    dist, _ = cKDTree(points).query(dense)
    radius = FILL_RADIUS * h
    if dist.max() <= radius:
        return np.empty((0, 3))
    compound = cq.Compound.makeCompound(faces)
    dtree = cKDTree(dense)
    added: list[np.ndarray] = []
    for _ in range(dense.shape[0]):
        i = int(np.argmax(dist))
        if dist[i] <= radius:
            break
        ext = BRepExtrema_DistShapeShape(cq.Vertex.makeVertex(*dense[i]).wrapped, compound.wrapped)
        q = ext.PointOnShape2(1)
        p = np.array([q.X(), q.Y(), q.Z()])
        added.append(p)
        near = dtree.query_ball_point(p, dist[i] + radius)
        if near:
            idx = np.array(near)
            dist[idx] = np.minimum(dist[idx], np.linalg.norm(dense[idx] - p, axis=1))
        dist[i] = 0.0
    return np.array(added).reshape(-1, 3)


def scan(
    shape,
    spacing: float | None = None,
    *,
    target_points: int | None = None,
    ratio: float = 1.0,
    directions=None,
    jitter: float = 0.0,
    dropout: float = 0.0,
    seed: int = 0,
    sharp_degrees: float = 20.0,
    repair: bool = True,
    quiet: bool = True,
) -> ScanSamples:
    """Sample a CAD shape along scan lines (Condition III, Figure 1 of the paper).

    Parameters
    ----------
    shape : samplers.shapes.Shape or CadQuery shape
        What to sample.
    spacing : float, optional
        Scan-line spacing h.  Defaults to ``shape.default_spacing`` when the
        shape has one, else to the h giving about 6,000 samples.
    target_points : int, optional
        Instead of ``spacing``: choose h so that about this many samples result.
    ratio : float
        Sample spacing along a line, as a multiple r of h (0.6 to 1.7).
    directions : (d, 3) array_like, optional
        Candidate sweep directions.  By default the x, y and z axes of the
        model's frame (:func:`sr33.samplers.frame.model_frame`): the world's
        for a model built upright, the model's own for one turned off them,
        which is scanned in that frame and turned back (``meta["frame"]``).
    jitter : float
        Standard deviation of isotropic Gaussian noise, as a multiple of h.
    dropout : float
        Fraction of samples removed at random (0 to <1).
    seed : int
        Seed of jitter and dropout.
    sharp_degrees : float
        Edges whose faces' normals differ by more than this are sampled
        explicitly (as are boundary edges and corners).
    repair : bool
        Lay disks out in rings and repair the boundary layers where rows
        meet circular edges (:mod:`sr33.samplers.disks`, :mod:`sr33.samplers.layers`),
        so that Condition III-ii holds there too.
    quiet : bool
        No progress bar (one step per face's scan rows, then one per repair
        stage; shown only when stderr is a terminal).  Every step's time is
        logged at debug level (logger ``sr33``) either way.

    Returns
    -------
    ScanSamples
    """
    occ = _occ(shape)
    dirs = _check_args(spacing, target_points, ratio, jitter, dropout, seed, directions)
    faces = occ.Faces()
    if not faces:
        raise SamplingError("shape has no faces to sample")
    area = float(sum(f.Area() for f in faces))
    if spacing is not None:
        h = float(spacing)
    elif target_points is not None:
        h = math.sqrt(area / (ratio * target_points))
    else:
        h = float(getattr(shape, "default_spacing", 0.0) or math.sqrt(area / (ratio * 6000)))
    frame = model_frame(occ) if directions is None else None
    if frame is not None and not frame.world:
        # a model off the world axes is scanned in its own frame and turned back
        with timed("sample: turned into the model's frame"):
            local = in_frame(occ, frame.axes)
        res = scan(
            local,
            h,
            ratio=ratio,
            directions=AXES,
            jitter=jitter,
            dropout=dropout,
            seed=seed,
            sharp_degrees=sharp_degrees,
            repair=repair,
            quiet=quiet,
        )
        meta = dict(
            res.meta,
            **_shape_meta(shape, occ),
            frame=frame.axes.tolist(),
            # the axes (and any strip's own direction), turned into the world
            directions=(np.asarray(res.meta["directions"]) @ frame.axes).tolist(),
        )
        return ScanSamples(
            points=res.points @ frame.axes,
            line_id=res.line_id,
            face_id=res.face_id,
            on_feature=res.on_feature,
            meta=meta,
        )
    with bar(len(faces) + 2 + (11 if repair else 0), "sample", quiet, unit="step") as pbar:
        lo, hi = exact_bounds(occ)
        size = float(norm(hi - lo))
        if area / (h * h * ratio) > 2_000_000:
            raise SamplingError(
                f"spacing {h:g} would give about {area / (h * h * ratio):.0f} samples; "
                "the limit is 2,000,000"
            )
        tol = 1e-7 * size
        fam = [_face_family(f, dirs, size / 200) for f in faces]
        edge_faces = EdgeFaces(occ)
        dirs, fam, strips = _strip_rows(edge_faces, dirs, fam, h, tol)
        corner = _box_corners(lo, hi)

        # rows along a coordinate axis: r times that axis's plane spacing
        axis_steps = ratio * np.array([_dividing_step(float(e), h) for e in hi - lo])
        planes = []  # per face: its family's direction, first plane, spacing, columns
        aligned, family = _aligned_planes(faces, fam, dirs, corner, h, tol)
        # a row along a coordinate axis is sampled where the planes across
        # that axis cut it (ratio times their spacing, from their first), so
        # that its samples meet the rows of the faces those planes cut
        # (a direction along a negative axis keeps the box's corner and step)
        anchor = lo.copy()
        for k, (t0, hf) in family.items():
            a = axis_index(dirs[k])
            if a is not None and dirs[k][a] > 0:
                anchor[a] = t0
                axis_steps[a] = ratio * hf
        _anchor_axes(faces, dirs, family, anchor, axis_steps, ratio, h, tol)
        columns = [_face_columns(f, anchor, axis_steps, ratio, h, tol) for f in faces]
        crosses = []
        for fi, face in enumerate(faces):
            d = dirs[fam[fi]]
            t0, hf = aligned[fi]
            crosses.append(_cross_lattice(face, d, hf, ratio, columns[fi][0], tol))
            planes.append((d, t0, hf, _columns(face, d, hf, ratio, *columns[fi], crosses[fi])))
        for fi, (t0, hf) in _strip_planes(strips, edge_faces, planes, h, tol).items():
            d = planes[fi][0]
            crosses[fi] = _cross_lattice(faces[fi], d, hf, ratio, columns[fi][0], tol)
            planes[fi] = (d, t0, hf, _columns(faces[fi], d, hf, ratio, *columns[fi], crosses[fi]))
        with timed("sample: feature samples"):
            chains = developable_bands(occ, size, sharp_degrees)
            pts, fids, feature_curve, lattices = _feature_samples(
                occ,
                EDGE_STEP * h,
                sharp_degrees,
                tol,
                planes,
                columns,
                {f for band in chains for f in band.faces},
                edge_faces,
            )
        pbar.update(1)
        n_feature = len(pts)
        feature_pts = np.array(pts, dtype=np.float64).reshape(-1, 3)
        line_ids = [-1] * n_feature
        line = 0
        t_rows = time.perf_counter()
        for fi, face in enumerate(faces):
            pbar.update(1)
            d, t0, hf, _ = planes[fi]
            sphere = _sphere_frame(face, d)
            proj = dot(_box_corners(*exact_bounds(face)), d)
            rimmed = sphere is not None and rims_sampled(face, feature_pts, h)
            for t in _plane_offsets(proj.min(), proj.max(), t0, hf, sphere if rimmed else None):
                origin = d * t
                edges = _section(face, tuple(origin), tuple(d))
                for chain, closed in _chains(edges, max(tol, 1e-9)):
                    p = _sample_chain(
                        chain,
                        closed,
                        ratio * hf,
                        *columns[fi],
                        lattices.get(fi, ()),
                        ratio,
                        sphere,
                        FEATURE_CLEARANCE * h,
                        crosses[fi],
                    )
                    pts.extend(p)
                    fids.extend([fi] * len(p))
                    line_ids.extend([line] * len(p))
                    line += 1
        log.debug("sample: scan rows took %.4f s", time.perf_counter() - t_rows)
        allp = np.array(pts, dtype=np.float64).reshape(-1, 3)
        on_line = np.arange(allp.shape[0]) >= n_feature
        alive = np.flatnonzero(
            _drop_near_features(allp, on_line, feature_curve, FEATURE_CLEARANCE * h)
        )
        own = np.where(on_line, np.array(fids, dtype=np.int64), -1)
        radius = 0.5 * min(1.0, ratio) * h
        folded = edge_faces.folded(FOLDED)
        keep = alive[thin(allp[alive], radius, own[alive], min(ACROSS * h, radius), folded)]
        points = allp[keep]
        line_id = np.array(line_ids, dtype=np.int64)[keep]
        face_id = np.array(fids, dtype=np.int64)[keep]
        on_feature = keep < n_feature
        with timed("sample: gaps filled"):
            fill = _fill_gaps(occ, faces, points, h, size)
        pbar.update(1)
        if fill.shape[0]:
            points = np.vstack([points, fill])
            line_id = np.r_[line_id, np.full(fill.shape[0], -2, dtype=np.int64)]
            face_id = np.r_[face_id, [nearest_face(q, faces) for q in fill]].astype(np.int64)
            on_feature = np.r_[on_feature, np.zeros(fill.shape[0], dtype=bool)]
        reports: list[dict] = []
        scan_rows_only: list[dict] | None = None
        if repair:
            from .bands import lattice_developable_bands
            from .disks import lattice_disk_faces
            from .fillets import lattice_filleted_box
            from .layers import (
                Samples,
                lattice_cone_faces,
                lattice_cylinder_faces,
                lattice_revolved_body,
                lattice_sphere_caps,
                repair_planar_faces,
            )
            from .outlines import repair_curved_faces
            from .pyramids import lattice_pyramid
            from .spheres import repair_sphere_faces

            bag = Samples(points, line_id, face_id, on_feature)
            with timed("sample: turned parts"):
                # a turned part with a smooth circle (a fillet's, a dome's) is
                # laid whole in rings along its meridian; nothing else is left
                reports += lattice_revolved_body(occ, bag, h, size, turned=True)
            if reports:
                pbar.update(11)  # the steps skipped
                handled = _faces_of(reports)
            else:
                laid: set[int] = set()  # faces laid out whole: no boundary-layer repair
                for step, layout in (
                    ("pyramids", lattice_pyramid),
                    ("filleted boxes", lattice_filleted_box),
                    ("disks", lattice_disk_faces),
                    ("spherical caps", lattice_sphere_caps),
                ):
                    with timed(f"sample: {step}"):
                        more, done = layout(occ, bag, h, size)
                    reports += more
                    laid |= done
                    pbar.update(1)
                with timed("sample: developable bands"):
                    more, banded = lattice_developable_bands(
                        occ, bag, h, size, skip=laid, sharp_degrees=sharp_degrees, bands=chains
                    )
                reports += more
                laid |= banded
                pbar.update(1)
                with timed("sample: planar faces"):
                    reports += repair_planar_faces(
                        occ, bag, h, size, row_dirs=[dirs[f] for f in fam], skip=laid, unfold=banded
                    )
                with timed("sample: planar faces along square edges"):
                    # then the faces bounded by edges along or across their rows
                    # only, where their lattices stagger against an edge's samples
                    reports += repair_planar_faces(
                        occ,
                        bag,
                        h,
                        size,
                        row_dirs=[dirs[f] for f in fam],
                        skip=laid,
                        squares=True,
                        unfold=banded,
                    )
                pbar.update(1)
                for step, lay in (
                    ("cylinders", lattice_cylinder_faces),
                    ("cones", lattice_cone_faces),
                    ("bodies of revolution", lattice_revolved_body),
                    ("partial spheres", repair_sphere_faces),
                ):
                    with timed(f"sample: {step}"):
                        reports += lay(occ, bag, h, size)
                    pbar.update(1)
                with timed("sample: curved faces in their charts"):
                    # what no layout took: rims of any curve, seams (a boolean's pieces)
                    handled = laid | _faces_of(reports)
                    reports += repair_curved_faces(occ, bag, h, size, skip=handled)
                pbar.update(1)
                handled = laid | _faces_of(reports)
            # curved faces no layout nor repair took keep their scan rows,
            # which do not aim at Condition III (a torus cut by a boolean)
            scan_rows_only = [
                {"face": fi, "kind": f.geomType().lower()}
                for fi, f in enumerate(faces)
                if f.geomType() != "PLANE" and fi not in handled
            ]
            for left in scan_rows_only:
                log.warning(
                    "sample: face %d (%s) keeps its scan rows: no layout or chart takes it, "
                    "so its samples may break Condition III",
                    left["face"],
                    left["kind"],
                )
            points, line_id, face_id, on_feature = (
                bag.points,
                bag.line_id,
                bag.face_id,
                bag.on_feature,
            )
        keep = _distinct(points, on_feature, CLOSEST * h)
        if keep.shape[0] < points.shape[0]:
            log.debug(
                "sample: %d samples closer than h/4 to another dropped",
                points.shape[0] - keep.shape[0],
            )
            points, line_id, face_id, on_feature = (
                a[keep] for a in (points, line_id, face_id, on_feature)
            )
        rng = np.random.default_rng(seed)
        if jitter > 0:
            points = points + rng.normal(size=points.shape) * (jitter * h)
        if dropout > 0:
            mask = rng.random(points.shape[0]) >= dropout
            points, line_id, face_id, on_feature = (
                a[mask] for a in (points, line_id, face_id, on_feature)
            )
        meta = {
            **_shape_meta(shape, occ),
            "spacing": h,
            "ratio": float(ratio),
            "directions": dirs.tolist(),
            "frame": np.eye(3).tolist(),
            "face_directions": [int(f) for f in fam],
            "jitter": float(jitter),
            "dropout": float(dropout),
            "seed": int(seed),
            "sharp_degrees": float(sharp_degrees),
            "points": int(points.shape[0]),
            "repairs": reports,
            "scan_rows_only": scan_rows_only,
            "feature_points": int(on_feature.sum()),
            "lines": int(line),
            "area": area,
            "size": size,
        }
        return ScanSamples(
            points=points, line_id=line_id, face_id=face_id, on_feature=on_feature, meta=meta
        )
