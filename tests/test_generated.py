"""The guarantee as a property over generated CAD models (issue 24 item 2).

Stated as the paper states it: a model drawn by :func:`tests.strategies.cad_models`
is sampled by the general sampler; the sample conditions are measured by the
validators (Condition III-i and III-ii on the truth, geodesically, and II-i:
no sample of N(u; 33) on another part of the surface, the other sheet of a
wedge sharper than about 44°; II-iv is reported "not computed" above genus 0
and not asserted); a sampling that
does not conform is not a counterexample (counted with its reason, not
asserted); one that conforms must reconstruct homeomorphic to the truth, use
every sample, have pairwise disjoint triangle interiors and a Hausdorff
distance of at most h (:func:`tests.helpers.check_homeomorphism`).

The ci profile draws one model per feature class (with ``make test``); the
deep profile (``make fuzz``) draws ``GENERATED_PER_CLASS`` per class.  The
report lists per class the models drawn, conforming and homeomorphic.
"""

from __future__ import annotations

import os

import numpy as np
import pytest
from hypothesis import HealthCheck, Phase, given, settings
from hypothesis import strategies as st

pytest.importorskip("cadquery")

from sr33.reconstruct import reconstruct  # noqa: E402
from sr33.samplers.scanline import scan  # noqa: E402
from sr33.validators.conditions import REACH, sample_conditions  # noqa: E402
from tests import fuzzstats  # noqa: E402
from tests.helpers import check_homeomorphism  # noqa: E402
from tests.strategies import FEATURE_CLASSES, cad_models, moved  # noqa: E402

DEEP = os.environ.get("HYPOTHESIS_PROFILE") == "deep"
#: a survey (``make fuzz FUZZ_SURVEY=1``): no shrinking, and a failing model (or
#: one the geodesic check cannot judge) is counted and listed with its recipe
#: instead of ending its class's run, so
#: that the report gives every class's shares (shrinking one failure took
#: 744 s of stop 43's 30-minute survey)
SURVEY = os.environ.get("FUZZ_SURVEY") == "1"
GENERATED_PER_CLASS = int(os.environ.get("GENERATED_PER_CLASS", "125"))
#: samples per generated model: small enough for the ci profile (a model's
#: sampling, check and reconstruction take 10-30 s)
TARGET_POINTS = 3000


def conformance(
    shape,
    points: np.ndarray,
    face_id: np.ndarray | None = None,
    spacing: float | None = None,
    *,
    ii_i: bool = True,
) -> str | None:
    """Why ``points`` do not meet the sample conditions on ``shape``'s truth
    (None when they do): Condition III-i (DT_M degree at most 33) and III-ii
    (every DT_M triangle's ratio below √3/2), measured geodesically, then
    II-i (no sample of N(u; 33) on another part of the surface:
    :func:`sr33.validators.conditions.neighbourhood_reach`; not with
    ``ii_i=False``); a
    sample in no DT_M triangle (the check cannot judge it) is not conforming,
    nor are samples closer than h/4 (``spacing``; the sampler's contract,
    which the deep profile found broken: two samples 0 apart on a cone
    fused with a box, which the geodesic check cannot place).
    With the samples' B-rep faces (``face_id``), the reason names the kinds
    of face the offending samples lie on (what the sampler must mend)."""
    if spacing is not None:
        from scipy.spatial import cKDTree

        closest = float(cKDTree(points).query(points, 2)[0][:, 1].min())
        if closest < 0.25 * spacing:
            # the sampler's own contract (closest pair at least h/4): a duplicate
            # or near-duplicate sample is the sampler's defect, and the geodesic
            # check cannot place two samples on one truth vertex
            return f"samples closer than h/4 ({closest / spacing:.3g} h: the sampler)"
    rep = sample_conditions(points, shape.truth_vertices, shape.truth_triangles)
    bad = np.isnan(rep.worst_ratio)
    if bad.any():
        why = "III-ii not measurable (a sample in no DT_M triangle)"
    elif int(rep.degree.max()) > 33:
        why, bad = "III-i (degree above 33)", rep.degree > 33
    elif float(rep.worst_ratio.max()) >= rep.ratio_limit:
        why, bad = "III-ii (a DT_M triangle at or above √3/2)", rep.worst_ratio >= rep.ratio_limit
    elif ii_i and rep.ii_i_violations().size:
        why, bad = "II-i (N(u;k) takes samples from another part of the surface)", rep.reach > REACH
    else:
        return None
    if face_id is not None:
        faces = shape.solid.Faces()
        kinds = [faces[int(f)].geomType().lower() for f in face_id[bad] if f >= 0]
        counts = {k: kinds.count(k) for k in sorted(set(kinds))}
        why += " on " + ", ".join(f"{k} ({n} samples)" for k, n in counts.items()) if kinds else ""
    if why.startswith("II-i"):
        wedge = sharpest_wedge(shape.truth_vertices, shape.truth_triangles)
        if wedge < II_I_WEDGE:
            # the model's, not the sampler's: no density meets II-i along it
            why += f"; a {wedge:.1f}° wedge (II-i fails at any density below {II_I_WEDGE:.1f}°)"
    return why


#: a wedge sharper than this (degrees) breaks Condition II-i along its edge
#: at any density (:func:`sr33.validators.conditions.neighbourhood_reach`:
#: 2 arccot REACH)
II_I_WEDGE = float(np.degrees(2 * np.arctan(1 / REACH)))


def sharpest_wedge(vertices, triangles) -> float:
    """The sharpest wedge of a truth mesh, in degrees: 180 less the largest
    angle between the normals of two triangles sharing an edge (a convex
    edge's inside angle, a reflex edge's opening; 180 where none turns)."""
    from sr33.validators.fidelity import dihedral_pairs

    _, _, _, cos = dihedral_pairs(
        np.asarray(vertices, dtype=np.float64), np.asarray(triangles, dtype=np.int64)
    )
    if cos.size == 0:
        return 180.0
    return float(180.0 - np.degrees(np.arccos(np.clip(cos.min(), -1.0, 1.0))))


def guarantee(model, points: np.ndarray, spacing: float, rec) -> None:
    """The property's conclusion on a conforming sampling (raises AssertionError)."""
    check_homeomorphism(model.shape, points, spacing, rec)


@pytest.mark.parametrize("feature", FEATURE_CLASSES)
@settings(
    max_examples=GENERATED_PER_CLASS if DEEP else 1,
    deadline=None,
    derandomize=not DEEP,
    suppress_health_check=list(HealthCheck),
    phases=[p for p in Phase if p is not Phase.shrink] if SURVEY else list(Phase),
)
@given(data=st.data())
def test_conforming_samplings_of_generated_models_reconstruct_homeomorphic(feature, data):
    """Theorems 3-5 over generated models of each feature class."""
    model = data.draw(cad_models(feature), label="model")
    fuzzstats.count(f"generated model ({feature})")
    r = scan(model.shape, target_points=TARGET_POINTS)
    try:
        why = conformance(model.shape, r.points, r.face_id, r.meta["spacing"])
    except ValueError as err:  # the geodesic check could not judge the samples
        if not SURVEY:
            raise
        fuzzstats.reject(f"generated model ({feature}) CHECK FAILED: {model.recipe}: {err}")
        return
    if why is not None and r.meta["scan_rows_only"]:
        # the sampler's gap: curved faces no layout or chart takes
        kinds = sorted({x["kind"] for x in r.meta["scan_rows_only"]})
        why += f"; left on scan rows: {', '.join(kinds)}"
    if why is not None:
        # not the theorem's input: counted with its reason, not a counterexample
        # a survey names the model too, so that a class's failing kinds can be rebuilt
        case = f": {model.recipe}" if SURVEY else ""
        fuzzstats.reject(f"generated model ({feature}) not conforming: {why}{case}")
        if SURVEY and why.startswith("II-i"):
            # beyond the guarantee (a thin wedge): how the reconstruction fares there
            try:
                guarantee(model, r.points, r.meta["spacing"], reconstruct(r.points, 33))
            except AssertionError as err:
                fuzzstats.reject(
                    f"beyond II-i, not homeomorphic ({feature}): {model.recipe}: {err}"
                )
            else:
                fuzzstats.count(f"beyond II-i, homeomorphic ({feature})")
        return
    fuzzstats.count(f"conforming ({feature})")
    rec = reconstruct(r.points, 33)
    try:
        guarantee(model, r.points, r.meta["spacing"], rec)
    except AssertionError as err:
        if not SURVEY:
            raise
        fuzzstats.reject(f"generated model ({feature}) FAILED: {model.recipe}: {err}")
        return
    fuzzstats.count(f"homeomorphic ({feature})")


def _prism_mesh(corners: np.ndarray, height: float):
    """A closed triangle mesh of a prism over a convex polygon (outward
    orientation): its sides and two fanned ends."""
    m = corners.shape[0]
    v = np.vstack([np.c_[corners, np.zeros(m)], np.c_[corners, np.full(m, height)]])
    tri = []
    for i in range(m):
        j = (i + 1) % m
        tri += [(i, j, m + j), (i, m + j, m + i)]
    tri += [(0, k + 1, k) for k in range(1, m - 1)]
    tri += [(m, m + k, m + k + 1) for k in range(1, m - 1)]
    return v, np.array(tri, dtype=np.int64)


@pytest.mark.parametrize("angle", [20.0, 30.0, 60.0, 90.0])
def test_the_sharpest_wedge_of_a_prism(angle):
    """:func:`sharpest_wedge` reads a prism's sharpest edge off its mesh:
    over a triangle with a corner of ``angle`` degrees (and 60 or more at
    its others), that angle; a survey's II-i reason names a wedge sharper
    than :data:`II_I_WEDGE` (36.9°)."""
    a = np.radians(angle)
    # an isosceles triangle: apex angle a, base angles (180 - a) / 2
    corners = np.array([[0.0, 0.0], [1.0, -np.tan(a / 2)], [1.0, np.tan(a / 2)]])
    v, t = _prism_mesh(corners, 0.5)
    want = min(angle, (180.0 - angle) / 2, 90.0)
    assert abs(sharpest_wedge(v, t) - want) < 1e-9
    assert 36.8 < II_I_WEDGE < 36.9


def test_the_generated_property_fails_on_a_broken_reconstruction():
    """The property's conclusion rejects a reconstruction with one face
    removed, two faces crossing, or one sample left out (issue 24)."""
    import cadquery as cq

    from sr33.reconstruct import Reconstruction
    from sr33.samplers import shapes

    class Model:  # what the property reads of a drawn model
        shape = shapes.from_cad(cq.Workplane().box(1.0, 0.8, 0.6).val())

    r = scan(Model.shape, target_points=1500)
    assert conformance(Model.shape, r.points) is None
    h = r.meta["spacing"]
    rec = reconstruct(r.points, 33)
    guarantee(Model, r.points, h, rec)  # the intact one holds

    def broken(**change):
        return Reconstruction(**{**rec.__dict__, **change})

    # one face removed: a hole
    with pytest.raises(AssertionError, match="boundary loops"):
        guarantee(Model, r.points, h, broken(triangles=rec.triangles[1:]))
    # two faces crossing: a vertex pushed through the box (same combinatorics)
    v = rec.vertices.copy()
    i = int(np.argmax(v[:, 2]))
    v[i, 2] -= 0.9
    with pytest.raises(AssertionError, match="crossing triangle pairs"):
        guarantee(Model, r.points, h, broken(vertices=v))
    # one sample left out: an edge collapsed onto a neighbour (topology kept)
    t = rec.triangles
    a, b = int(t[0, 0]), int(t[0, 1])
    keep = ~((t == a).any(axis=1) & (t == b).any(axis=1))
    collapsed = np.where(t[keep] == a, b, t[keep])
    with pytest.raises(AssertionError, match="samples used"):
        guarantee(Model, r.points, h, broken(triangles=collapsed))


def test_a_sampling_with_a_duplicate_sample_does_not_conform():
    """The deep profile drew a model whose sampling held two samples 0 apart
    (the sampler's defect): not conforming, with the reason, instead of the
    geodesic check's error ending the property."""
    import cadquery as cq

    from sr33.samplers import shapes

    shape = shapes.from_cad(cq.Workplane().box(1.0, 0.8, 0.6).val())
    r = scan(shape, target_points=1500)
    h = r.meta["spacing"]
    assert conformance(shape, r.points, r.face_id, h) is None
    twice = np.vstack([r.points, r.points[:1]])
    assert conformance(shape, twice, None, h) == "samples closer than h/4 (0 h: the sampler)"


# Conforming counterexamples, kept as named regressions.  Stop 43's survey
# (4 models a class): a slender cone (radius 0.276, height 1.1, a 28 degree
# apex) turned off the axes, sampled conforming at 3,000 samples.  The
# Euclidean RNG gives its apex's inner rings no face cycles: 20 samples
# within 5.8 h of the apex are strays.  Coned, they left the 10-sample ring
# round them open (Euler 1, 10 open edges), or, placed 3 lower, closed it
# with a triangle 1.11 h off the surface.  Fixed by re-triangulating the
# ring's face with the strays inside it (sr33.patches).  Stop 44's sixteen
# turned slender cones found a third: the ring closed by four faces (two
# triangles, a quad, a hexagon), 25 strays over them coned 1.08 h off;
# fixed by patching the polygon the four faces make.  And a fourth (a 36
# degree apex): the tip's 11 samples closed as a piece of their own, open,
# apart from the body's open ring round it (two components, 7 open edges);
# fixed by taking such small open pieces apart into strays before the holes
# are closed (reconstruct._without_small_open_pieces); in a fifth (27
# degrees) the tip piece is one triangle, joined to the body only through a
# stray sample.
SLENDER_CONES = {
    "open ring": (
        0.27645672755289213,
        (95.5739218753705, 168.78236605633742, 0.0),
        (2.363048867193828, -4.898524836782179, 4.9375),
    ),
    "hausdorff": (
        0.27645672755289213,
        (95.5739218753705, 168.78236605633742, 0.0),
        (2.363048867193828, -4.898524836782179, 1.9375),
    ),
    "ring of four faces": (
        0.2730126281194281,
        (113.97319186934095, 174.1384714488618, 122.95166801573255),
        (-1.0837516691997386, -3.127474302799019, -1.540393344282669),
    ),
    "tip cut off": (
        0.36031787820624095,
        (122.99164308058629, 141.67744947986418, 34.49092662362434),
        (3.023641611345301, -3.086760739427997, -4.184473826364873),
    ),
    "tip cut off, held by a stray": (
        0.26666401317911376,
        (86.3431062322095, 26.340222556475727, 125.71674209047684),
        (-2.08021384012149, 3.7113914979358906, -2.2462562305192293),
    ),
}


def _turned_cone(radius, height, angles, move):
    """The cone of :func:`tests.strategies.cad_models` ("cone r R top 0 h H;
    turned [a, b, c] moved [x, y, z]"), rebuilt from its recipe."""
    import cadquery as cq

    from sr33.samplers import shapes

    solid = cq.Solid.makeCone(radius, 0.0, height, pnt=cq.Vector(0, 0, -height / 2))
    return shapes.from_cad(moved(solid, angles, move), name="generated")


#: Stop 50's survey (4 models a class): a cone with a through hole along its
#: axis (the apex cut away, a conical tube), turned, sampled conforming at
#: 3,000 samples; the reconstruction is 1.29 h and 1.28 h from the truth
#: (the property wants at most h).  The samplings are byte-identical on
#: dee25de and on this stop's tip: not caused by the sampler's change, not
#: traced.  (radius, height, hole radius, turn, move)
CONES_WITH_A_HOLE = {
    "acute edge": (
        0.29121510631491776,
        0.8707602007376759,
        0.08736453189447532,
        (0.68, -42.973274959768816, 85.54299674347124),
        (1.3024913190992784, 1.401298464324817e-45, 4.52041367194856),
    ),
    "cone apex": (
        0.4604403357408449,
        0.99999,
        0.13813210072225346,
        (87.13609382567472, -147.3190335878659, 8.2016820334888e-241),
        (0.008502335913301629, 1.6214784215778213, -4.720172138279821),
    ),
}


# Stop 50's survey: two cones with a hole through the apex sampled
# conforming to Condition III reconstructed 1.28-1.29 h off the truth.  The
# hole's rim is a wedge of 18.5° (24.7°) between the cone and the hole's
# wall; below it the reconstruction joins the two sheets, 2.7 h apart.  The
# paper does not promise that sampling anything: Condition II-i (M_u ≅ D)
# fails there, N(u; 33) taking samples of the other sheet
# (:func:`sr33.validators.conditions.neighbourhood_reach`), at any density.
def _cone_with_a_hole(case):
    """The strategy's cone with a through hole (recipe "cone r R top 0 h H;
    hole r ..."), rebuilt, and its scan (memoised: two tests read it)."""
    if case not in _CONES_SCANNED:
        import cadquery as cq

        from sr33.samplers import shapes

        radius, height, hole, angles, move = CONES_WITH_A_HOLE[case]
        solid = cq.Solid.makeCone(radius, 0.0, height, pnt=cq.Vector(0, 0, -height / 2))
        # the strategy's hole: a cylinder through the bounding box's centre, along z
        bb = solid.BoundingBox()
        lo = np.array([bb.xmin, bb.ymin, bb.zmin])
        ext = np.array([bb.xmax, bb.ymax, bb.zmax]) - lo
        tool = cq.Solid.makeCylinder(
            hole, 3 * ext[2] + 1, pnt=cq.Vector(*(lo + ext / 2 - [0, 0, 1.5 * ext[2] + 0.5]))
        )
        solid = cq.Solid(solid.cut(tool).Solids()[0].wrapped)
        shape = shapes.from_cad(moved(solid, angles, move), name="generated")
        _CONES_SCANNED[case] = (shape, scan(shape, target_points=TARGET_POINTS))
    return _CONES_SCANNED[case]


_CONES_SCANNED: dict = {}


@pytest.mark.slow
@pytest.mark.parametrize("case", list(CONES_WITH_A_HOLE))
def test_a_cone_with_a_hole_through_its_apex_breaks_condition_ii_i_under_its_rim(case):
    from scipy.spatial.transform import Rotation

    radius, height, hole, angles, move = CONES_WITH_A_HOLE[case]
    shape, r = _cone_with_a_hole(case)
    h = r.meta["spacing"]
    rep = sample_conditions(r.points, shape.truth_vertices, shape.truth_triangles)
    assert rep.max_degree <= 33 and rep.max_ratio < rep.ratio_limit  # Condition III holds
    bad = rep.ii_i_violations()
    assert bad.size > 100, bad.size
    # back in the cone's own frame (moved: turned about x, y, z, then moved)
    q = Rotation.from_euler("xyz", angles, degrees=True).inv().apply(r.points - np.asarray(move))
    rim = height / 2 - hole * height / radius  # where the hole's wall meets the cone
    off_rim = np.hypot(np.hypot(q[:, 0], q[:, 1]) - hole, q[:, 2] - rim) / h
    # all in a band under the thin rim: none at it, none at the base's wide rim
    assert 1.5 < off_rim[bad].min() and off_rim[bad].max() < 12.0, (
        off_rim[bad].min(),
        off_rim[bad].max(),
    )
    assert conformance(shape, r.points, r.face_id, h).startswith("II-i")


@pytest.mark.slow
@pytest.mark.xfail(
    strict=True,
    raises=AssertionError,
    reason="issue 24, stop 50's survey; beyond the guarantee (stop 51): the sampling "
    "breaks Condition II-i under the hole's thin rim, where the reconstruction joins "
    "the cone to the hole's wall, 1.28-1.29 h off the truth",
)
@pytest.mark.parametrize("case", list(CONES_WITH_A_HOLE))
def test_regression_a_cone_with_a_hole_through_its_apex_reconstructs_within_h(case):
    shape, r = _cone_with_a_hole(case)
    why = conformance(shape, r.points, r.face_id, r.meta["spacing"], ii_i=False)
    if why is not None:  # Condition III fails now: say so (not the xfail's error)
        pytest.fail(f"the regression's sampling does not meet Condition III any more: {why}")
    check_homeomorphism(shape, r.points, r.meta["spacing"], reconstruct(r.points, 33))


@pytest.mark.parametrize("case", list(SLENDER_CONES))
def test_regression_a_slender_cone_turned_off_the_axes_closes_round_its_apex(case):
    radius, angles, move = SLENDER_CONES[case]
    shape = _turned_cone(radius, 1.1, angles, move)
    r = scan(shape, target_points=TARGET_POINTS)
    why = conformance(shape, r.points, r.face_id, r.meta["spacing"])
    if why is not None:  # not the counterexample any more: say so
        pytest.fail(f"the regression's sampling does not conform any more: {why}")
    check_homeomorphism(shape, r.points, r.meta["spacing"], reconstruct(r.points, 33))


@pytest.mark.slow
def test_regression_a_star_prism_s_caps_meet_condition_iii_at_their_reflex_corners():
    """Seed 70's survey (stop 70): a star prism over 12 corners (tips at
    0.633, notches at 0.415 of that, 0.365 high), turned 17° about z.  Its
    caps' repair had the ghosts of one side beyond the reflex corner of the
    next (the faces across a reflex corner's two edges unfold onto one
    another), which hid 7 triangles of each cap up to 0.975 from it (judged
    0.830): 40 samples broke III-ii.  The repair now checks each face's own
    triangles after it and repairs again, with the ghosts of each edge kept
    where it is the nearest.  (Its 35.8° tips break II-i at any density:
    the sampling is beyond the guarantee there, by Condition II-i only.)"""
    import cadquery as cq

    from sr33.samplers import shapes

    a = np.pi * np.arange(12) / 6
    r = np.where(np.arange(12) % 2 == 0, 0.633307925673659, 0.26249774248149127)
    corners = [(float(x), float(y)) for x, y in zip(r * np.cos(a), r * np.sin(a))]
    height = 0.3646623097494604
    solid = cq.Workplane().polyline(corners).close().extrude(height).val()
    solid = moved(solid.translate(cq.Vector(0, 0, -height / 2)), (0, 0, 17.0), (0, 1.52, -1.39))
    shape = shapes.from_cad(solid, name="generated")
    s = scan(shape, target_points=TARGET_POINTS)
    rep = sample_conditions(s.points, shape.truth_vertices, shape.truth_triangles)
    worst = float(rep.worst_ratio.max())
    assert worst < rep.ratio_limit - 0.01, worst
    assert conformance(shape, s.points, s.face_id, s.meta["spacing"], ii_i=False) is None
