"""Hypothesis strategies: small clouds, lattice clouds with exact ties,
rotations, library shapes' parameters, robustness inputs, generated CAD models."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from hypothesis import assume
from hypothesis import strategies as st

from tests import fuzzstats


@st.composite
def random_clouds(draw, min_n: int = 5, max_n: int = 18) -> np.ndarray:
    """Distinct points in general position (floats in a unit box)."""
    n = draw(st.integers(min_n, max_n))
    seed = draw(st.integers(0, 2**32 - 1))
    pts = np.random.default_rng(seed).random((n, 3))
    return pts


@st.composite
def lattice_clouds(draw, min_n: int = 5, max_n: int = 18) -> np.ndarray:
    """Distinct integer lattice points in a small box: many exactly tied distances."""
    n = draw(st.integers(min_n, max_n))
    seed = draw(st.integers(0, 2**32 - 1))
    rng = np.random.default_rng(seed)
    side = draw(st.integers(2, 4))
    grid = np.stack(np.meshgrid(*[np.arange(side + 1)] * 3, indexing="ij"), -1).reshape(-1, 3)
    flat = draw(st.booleans())
    if flat:
        grid = grid[grid[:, 2] == 0]
    n = min(n, grid.shape[0])
    idx = rng.choice(grid.shape[0], size=n, replace=False)
    pts = grid[idx].astype(float)
    # avoid all-collinear sets
    centred = pts - pts.mean(axis=0)
    s = np.linalg.svd(centred, compute_uv=False)
    if s[1] <= 1e-9 * s[0]:
        pts = np.vstack([pts, [[0.5, 0.25, 0.0]]])
    return pts


@st.composite
def clouds(draw, min_n: int = 5, max_n: int = 18) -> np.ndarray:
    """Either kind."""
    return draw(st.one_of(random_clouds(min_n, max_n), lattice_clouds(min_n, max_n)))


def rotation(angle_seed: int) -> np.ndarray:
    """A proper rotation matrix from a seed (arbitrary axis and angle)."""
    rng = np.random.default_rng(angle_seed)
    q = rng.normal(size=4)
    q /= np.linalg.norm(q)
    w, x, y, z = q
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )


# --- library shapes and scan settings (the paper's guarantees) --------------------


@st.composite
def shape_params(draw, name: str) -> dict[str, float]:
    """Parameters of a library shape: each default perturbed by up to 15%,
    times one overall scale in [0.5, 2]; angles moved by up to 10 degrees."""
    from sr33.samplers import shapes

    scale = draw(st.floats(0.5, 2.0))
    out = {}
    for key, value in shapes.shape_parameters(name).items():
        if key == "angle":
            out[key] = value + draw(st.floats(-10.0, 10.0))
        else:
            out[key] = value * scale * draw(st.floats(0.85, 1.15))
    return out


@st.composite
def scan_settings(draw) -> dict:
    """Sampler settings inside the Condition III bounds."""
    return {
        "density": draw(st.floats(0.8, 1.25)),
        "ratio": draw(st.floats(0.85, 1.2)),
        "seed": draw(st.integers(0, 2**16)),
    }


@st.composite
def rigid_motions(draw) -> tuple[np.ndarray, np.ndarray, float]:
    """(rotation, translation, uniform scale)."""
    r = rotation(draw(st.integers(0, 2**31)))
    t = np.array([draw(st.floats(-10, 10)) for _ in range(3)])
    s = draw(st.sampled_from([1.0, 0.01, 3.5, 100.0]))
    return r, t, s


@st.composite
def arbitrary_points(draw) -> np.ndarray:
    """Robustness inputs: duplicates and near duplicates, collinear, coplanar,
    clustered, huge, tiny, a NaN or an inf mixed in, a sphere (a surface to
    find) among them."""
    kind = draw(
        st.sampled_from(
            [
                "random",
                "duplicates",
                "near duplicates",
                "collinear",
                "coplanar",
                "cluster",
                "huge",
                "tiny",
                "few",
                "sphere",
                "non-finite",
            ]
        )
    )
    seed = draw(st.integers(0, 2**31))
    rng = np.random.default_rng(seed)
    n = draw(st.integers(4, 60))
    p = rng.random((n, 3))
    if kind == "duplicates":
        p = np.vstack([p, p[rng.integers(0, n, n // 2 + 1)]])
    elif kind == "collinear":
        p = np.outer(rng.random(n), rng.random(3))
    elif kind == "coplanar":
        p[:, 2] = 0.0
    elif kind == "cluster":
        p = np.vstack([p * 1e-9, p + 5.0])
    elif kind == "huge":
        p = p * 1e12
    elif kind == "tiny":
        p = p * 1e-12
    elif kind == "few":
        p = p[: draw(st.integers(1, 4))]
    elif kind == "near duplicates":
        p = np.vstack([p, p[: n // 2] + rng.normal(0, 1e-12, (n // 2, 3))])
    elif kind == "sphere":
        p = rng.normal(size=(max(n, 20), 3))
        p /= np.linalg.norm(p, axis=1)[:, None]
        p *= 10.0 ** draw(st.sampled_from([-150, -6, 0, 6, 150]))
    elif kind == "non-finite":
        p[rng.integers(0, n)] = draw(st.sampled_from([np.nan, np.inf, -np.inf]))
    return p


# --- generated CAD models (issue 24 item 1) -----------------------------------------

#: the feature classes a generated model is reported under (``make fuzz``)
FEATURE_CLASSES = (
    "acute edge",
    "cone apex",
    "smooth blend",
    "chamfer",
    "hole",
    "boolean seam",
    "curved face",
    "reflex edge",
)
PRIMITIVES = ("box", "cylinder", "cone", "frustum", "sphere", "torus", "prism", "star prism")


@dataclass(frozen=True)
class CadModel:
    """A generated solid with its library record and what it exercises.

    ``recipe`` says how it was built, every drawn number in full (a
    shrunk failure from the deep profile rebuilds from it: the stop 43
    cone, ``test_generated.test_regression_...``, could not from three
    digits),
    ``shape`` is :func:`sr33.samplers.shapes.from_cad`'s record (B-rep
    topology, truth mesh), ``features`` the classes it has, read from the
    result (the B-rep and its truth mesh), not assumed from the recipe.
    """

    recipe: str
    shape: Any
    features: frozenset


def _polygon(draw, convex: bool) -> list[tuple[float, float]]:
    """A polygon about the origin: convex (points on a circle at jittered
    angles) or star-shaped non-convex (alternating radii)."""
    if convex:
        n = draw(st.integers(3, 8))
        step = 2 * np.pi / n
        angles = [k * step + draw(st.floats(-0.3, 0.3)) * step for k in range(n)]
        r = draw(st.floats(0.4, 0.7))
        return [(r * np.cos(a), r * np.sin(a)) for a in angles]
    n = draw(st.integers(3, 6))
    outer, inner = draw(st.floats(0.5, 0.7)), draw(st.floats(0.3, 0.8))
    pts = []
    for k in range(2 * n):
        a = np.pi * k / n
        r = outer if k % 2 == 0 else outer * inner
        pts.append((r * np.cos(a), r * np.sin(a)))
    return pts


def _primitive(draw, kind: str):
    import cadquery as cq

    size = lambda lo=0.4, hi=1.2: draw(st.floats(lo, hi))  # noqa: E731
    if kind == "box":
        a, b, c = size(), size(), size()
        return cq.Solid.makeBox(
            a, b, c, pnt=cq.Vector(-a / 2, -b / 2, -c / 2)
        ), f"box {a!r} {b!r} {c!r}"
    if kind == "cylinder":
        r, h = size(0.2, 0.6), size()
        return cq.Solid.makeCylinder(r, h, pnt=cq.Vector(0, 0, -h / 2)), f"cylinder r {r!r} h {h!r}"
    if kind in ("cone", "frustum"):
        r, h = size(0.2, 0.6), size()
        top = 0.0 if kind == "cone" else r * draw(st.floats(0.2, 0.8))
        return cq.Solid.makeCone(
            r, top, h, pnt=cq.Vector(0, 0, -h / 2)
        ), f"{kind} r {r!r} top {top!r} h {h!r}"
    if kind == "sphere":
        r = size(0.3, 0.6)
        return cq.Solid.makeSphere(r, angleDegrees1=-90, angleDegrees2=90), f"sphere r {r!r}"
    if kind == "torus":
        big = size(0.35, 0.6)
        small = big * draw(st.floats(0.2, 0.5))
        return cq.Solid.makeTorus(big, small), f"torus {big!r} {small!r}"
    pts = _polygon(draw, convex=kind == "prism")
    h = size(0.2, 0.8)
    solid = cq.Workplane().polyline(pts).close().extrude(h).translate((0, 0, -h / 2)).val()
    corners = [(float(x), float(y)) for x, y in pts]
    return solid, f"{kind} over {len(pts)} corners {corners} h {h!r}"


def _dihedral_features(vertices: np.ndarray, triangles: np.ndarray) -> set[str]:
    """'acute edge' where the truth mesh turns by more than 100 degrees across
    an edge (an interior angle below 80), 'reflex edge' where it turns
    inwards by more than 20 (a concave sharp edge)."""
    from sr33.validators.fidelity import dihedral_pairs

    v = np.asarray(vertices, dtype=np.float64)
    t = np.asarray(triangles, dtype=np.int64)
    edge, fa, fb, cos = dihedral_pairs(v, t)
    out = set()
    if (cos < np.cos(np.radians(100))).any():
        out.add("acute edge")
    # concave: fb's far corner lies outside fa's plane
    n = np.cross(v[t[fa, 1]] - v[t[fa, 0]], v[t[fa, 2]] - v[t[fa, 0]])
    far = t[fb].sum(axis=1) - edge.sum(axis=1)
    outside = (n * (v[far] - v[edge[:, 0]])).sum(axis=1) > 0
    if (outside & (cos < np.cos(np.radians(20)))).any():
        out.add("reflex edge")
    return out


def _cone_apex(solid) -> bool:
    """A conical face ending in a point: its surface's apex is a vertex of the model."""
    from OCP.BRepAdaptor import BRepAdaptor_Surface

    corners = np.array([v.toTuple() for v in solid.Vertices()]).reshape(-1, 3)
    for f in solid.Faces():
        if f.geomType() != "CONE":
            continue
        a = BRepAdaptor_Surface(f.wrapped).Cone().Apex()
        gap = np.linalg.norm(corners - [a.X(), a.Y(), a.Z()], axis=1)
        if gap.size and gap.min() < 1e-7:
            return True
    return False


def _reject(reason: str) -> None:
    fuzzstats.reject(reason)
    assume(False)


#: primitives and operations that give each feature class (the ci profile
#: draws every class through these)
FOR_FEATURE = {
    "acute edge": (("cone", "frustum", "star prism"), ()),
    "cone apex": (("cone",), ()),
    "smooth blend": (("box", "prism", "star prism", "cylinder", "frustum"), ("fillet",)),
    "chamfer": (("box", "prism", "cylinder"), ("chamfer",)),
    "hole": (("box", "prism", "cylinder", "torus"), ("hole",)),
    "boolean seam": (("box", "cylinder", "sphere", "prism"), ("union", "cut")),
    "curved face": (("cylinder", "sphere", "torus", "frustum"), ()),
    "reflex edge": (("star prism",), ()),
}


def moved(solid, angles, move):
    """A generated model's rigid motion (the recipe's "turned [a, b, c] moved
    [x, y, z]"): turned about the x, y and z axes by ``angles`` (degrees) in
    turn, then moved by ``move``."""
    import cadquery as cq

    for axis, a in zip(((1, 0, 0), (0, 1, 0), (0, 0, 1)), angles):
        solid = solid.rotate((0, 0, 0), axis, a)
    return solid.translate(cq.Vector(*move))


@st.composite
def cad_models(draw, feature: str | None = None) -> CadModel:
    """A solid composed from primitives (box, cylinder, cone, frustum,
    sphere, torus, prisms over convex and star-shaped polygons), then up to
    two of: a union with a second primitive, a cut of one, a through hole,
    fillets of the vertical edges (of the top circles where there are none:
    a turned body's rim), chamfers of the top edges (random sizes),
    then a random rigid motion.  Models CadQuery cannot build, that are not
    one valid solid, or whose truth mesh does not fit the B-rep are
    rejected (``assume``), each with its reason counted
    (:data:`fuzzstats.REJECTED`).  ``feature`` draws from the primitives and
    operations that give that class (:data:`FOR_FEATURE`)."""
    import cadquery as cq

    from sr33.samplers import shapes

    kinds, forced = FOR_FEATURE[feature] if feature else (PRIMITIVES, ())
    kind = draw(st.sampled_from(kinds))
    solid, recipe = _primitive(draw, kind)
    steps = [recipe]
    done: set[str] = set()
    ops = draw(
        st.lists(
            st.sampled_from(["union", "cut", "hole", "fillet", "chamfer"]), max_size=2, unique=True
        )
    )
    if forced:
        ops = [draw(st.sampled_from(forced))] + [op for op in ops if op not in forced][:1]
    for op in ops:
        bb = solid.BoundingBox()
        lo, hi = np.array([bb.xmin, bb.ymin, bb.zmin]), np.array([bb.xmax, bb.ymax, bb.zmax])
        ext = hi - lo
        try:
            if op in ("union", "cut"):
                other, what = _primitive(draw, draw(st.sampled_from(["box", "cylinder", "sphere"])))
                # centred on a point of the bounding box's top, so that it overlaps
                at = lo + ext * np.array(
                    [draw(st.floats(0.3, 0.7)), draw(st.floats(0.3, 0.7)), 1.0]
                )
                other = other.scale(0.6).translate(cq.Vector(*at))
                new = solid.fuse(other) if op == "union" else solid.cut(other)
                steps.append(f"{op} {what} x0.6 at {at.tolist()}")
            elif op == "hole":
                r = 0.15 * float(min(ext[0], ext[1]))
                tool = cq.Solid.makeCylinder(
                    r, 3 * ext[2] + 1, pnt=cq.Vector(*(lo + ext / 2 - [0, 0, 1.5 * ext[2] + 0.5]))
                )
                new = solid.cut(tool)
                steps.append(f"hole r {r!r}")
            elif op == "fillet":
                edges = [
                    e
                    for e in solid.Edges()
                    if e.geomType() == "LINE" and abs(e.tangentAt(0.5).z) > 0.999
                ]
                what, scale = "vertical edges", min((e.Length() for e in edges), default=0.0)
                if not edges:  # a turned body (a cylinder, a cone): its top rim, a circle
                    edges = [
                        e
                        for e in solid.Edges()
                        if e.geomType() == "CIRCLE" and abs(e.Center().z - float(hi[2])) < 1e-6
                    ]
                    what, scale = "top circles", float(min(ext))
                if not edges:
                    continue
                r = draw(st.floats(0.05, 0.2)) * scale
                new = solid.fillet(r, edges)
                steps.append(f"fillet {len(edges)} {what} r {r!r}")
            else:
                top = float(hi[2])
                edges = [
                    e
                    for e in solid.Edges()
                    if abs(e.Center().z - top) < 1e-6 and abs(e.tangentAt(0.5).z) < 1e-6
                ]
                if not edges:
                    continue
                d = draw(st.floats(0.03, 0.12)) * float(min(ext))
                new = solid.chamfer(d, None, edges)
                steps.append(f"chamfer {len(edges)} top edges {d!r}")
        except Exception as exc:  # OpenCascade refuses: Standard_Failure and kin
            _reject(f"{op} failed ({type(exc).__name__})")
        if len(new.Solids()) != 1:
            _reject(f"{op} gave {len(new.Solids())} solids")
        solid = cq.Solid(new.Solids()[0].wrapped)
        done.add(op)
    angles = [draw(st.floats(-180, 180)) for _ in range(3)]
    move = [draw(st.floats(-5, 5)) for _ in range(3)]
    solid = moved(solid, angles, move)
    steps.append(f"turned {angles} moved {move}")
    recipe = "; ".join(steps)
    try:
        shape = shapes.from_cad(solid, name="generated")
    except shapes.ShapeError as exc:
        _reject(str(exc).split(":")[-1].strip()[:60])
    features = _dihedral_features(shape.truth_vertices, shape.truth_triangles)
    if _cone_apex(solid):
        features.add("cone apex")
    if "fillet" in done:
        features.add("smooth blend")
    if "chamfer" in done:
        features.add("chamfer")
    if shape.expected.genus > 0:
        features.add("hole")
    if done & {"union", "cut"}:
        features.add("boolean seam")
    if any(f.geomType() != "PLANE" for f in solid.Faces()):
        features.add("curved face")
    return CadModel(recipe, shape, frozenset(features))
