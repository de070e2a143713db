"""Fuzz targets (issue 22): the file readers over arbitrary and mutated
bytes, and ``reconstruct`` over point arrays with outliers, duplicates,
offsets and magnitudes.

Every input ends in a result that keeps the documented invariants or in the
documented error (:class:`sr33.io.ReadError` / :class:`sr33.InputError`),
never another exception, a crash or a hang past the example's deadline.
The ``ci`` profile runs a few hundred inputs in ``make test``;
``make fuzz`` (``HYPOTHESIS_PROFILE=deep``) runs over 10,000.
"""

import os
from datetime import timedelta

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from sr33 import InputError, reconstruct
from sr33.io import ReadError, read_mesh, write_mesh, write_points
from sr33.samplers import cube_lattice
from sr33.validators import mesh_stats
from tests.fuzzstats import count

DEEP = os.environ.get("HYPOTHESIS_PROFILE") == "deep"
READER_EXAMPLES = 3000 if DEEP else 60  # per format: 5 formats -> 15,000 inputs deep
POINT_EXAMPLES = 400 if DEEP else 15
FORMATS = (".ply", ".obj", ".off", ".stl", ".xyz")
READ_BUDGET = timedelta(seconds=5)  # a reader that takes longer on < 4 kB hangs
RECONSTRUCT_BUDGET = timedelta(seconds=60)


@pytest.fixture(scope="module")
def seeds(tmp_path_factory):
    """One small valid file per format (the seeds the mutations start from)."""
    d = tmp_path_factory.mktemp("fuzz")
    v = cube_lattice(2).astype(float)
    from scipy.spatial import ConvexHull

    t = ConvexHull(v).simplices
    out = {}
    for ext in FORMATS:
        p = d / f"seed{ext}"
        if ext == ".xyz":
            write_points(p, v)
        else:
            write_mesh(p, v, t)
        out[ext] = p.read_bytes()
    if ".ply" in out:  # an ASCII PLY seed too: the binary one exercises only one reader path
        head = f"ply\nformat ascii 1.0\nelement vertex {len(v)}\nproperty double x\n"
        head += "property double y\nproperty double z\n"
        head += f"element face {len(t)}\nproperty list uchar int vertex_indices\nend_header\n"
        body = "".join(f"{a!r} {b!r} {c!r}\n" for a, b, c in v.tolist())
        body += "".join(f"3 {a} {b} {c}\n" for a, b, c in t.tolist())
        out[".ply-ascii"] = (head + body).encode()
    return d, out


@st.composite
def mutated(draw, seed: bytes) -> bytes:
    """A valid file with a few byte-level edits: truncation, overwrite,
    insertion, deletion, a duplicated chunk, a header number changed."""
    data = bytearray(seed)
    for _ in range(draw(st.integers(1, 4))):
        op = draw(st.sampled_from(["cut", "set", "insert", "delete", "repeat", "number"]))
        at = draw(st.integers(0, max(0, len(data) - 1)))
        if op == "cut":
            del data[at:]
        elif op == "set" and data:
            data[at] = draw(st.integers(0, 255))
        elif op == "insert":
            data[at:at] = draw(st.binary(min_size=1, max_size=8))
        elif op == "delete":
            del data[at : at + draw(st.integers(1, 16))]
        elif op == "repeat":
            data[at:at] = data[at : at + draw(st.integers(1, 64))]
        elif op == "number":
            num = draw(st.sampled_from(["0", "-1", "1e12", "4294967295", "nan", "inf", "-0"]))
            data[at:at] = num.encode()
        if not data:
            break
    return bytes(data)


def check_read(path):
    """read_mesh's contract: a valid mesh or a ReadError, nothing else."""
    try:
        v, f = read_mesh(path)
    except ReadError as exc:
        assert str(exc).startswith(str(path)), exc
        assert "\n" not in str(exc)
        return
    assert v.dtype == np.float64 and v.ndim == 2 and v.shape[1] == 3 and v.shape[0] > 0
    assert np.isfinite(v).all()
    assert f.dtype == np.int64 and f.ndim == 2 and f.shape[1] == 3
    assert f.size == 0 or (f.min() >= 0 and f.max() < v.shape[0])


@pytest.mark.parametrize("fmt", FORMATS + (".ply-ascii",))
@settings(
    max_examples=READER_EXAMPLES,
    deadline=READ_BUDGET,
    suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow],
)
@given(data=st.data())
def test_fuzz_readers(seeds, fmt, data):
    d, seed_bytes = seeds
    ext = fmt.split("-")[0]
    raw = data.draw(
        st.one_of(mutated(seed_bytes[fmt]), st.binary(max_size=512)),
        label="file bytes",
    )
    count(f"fuzz_readers[{fmt}]")
    p = d / f"input{ext}"
    p.write_bytes(raw)
    check_read(p)


@st.composite
def messy_points(draw) -> np.ndarray:
    """A scan-like cloud with what real input carries: outliers far away,
    exact duplicates, a large offset, an extreme magnitude."""
    seed = draw(st.integers(0, 2**31))
    rng = np.random.default_rng(seed)
    n = draw(st.integers(20, 120))
    p = rng.normal(size=(n, 3))
    p /= np.linalg.norm(p, axis=1)[:, None]  # a sphere: something to reconstruct
    if draw(st.booleans()):
        far = draw(st.sampled_from([10.0, 1e4, 1e8]))
        m = draw(st.integers(1, 3))
        p = np.vstack([p, rng.normal(size=(m, 3)) * far])
    if draw(st.booleans()):
        p = np.vstack([p, p[rng.integers(0, len(p), draw(st.integers(1, 10)))]])
    scale = 10.0 ** draw(st.sampled_from([0, -300, -150, -9, 9, 150, 300]))
    with np.errstate(over="ignore", invalid="ignore"):  # inf is input too: refused
        p = p * scale
        if draw(st.booleans()):
            offset = draw(st.sampled_from([[5e5, 4.1e6, 250.0], [1e7, -3e7, 0.0]]))
            p = p + np.array(offset) * scale
    return p[rng.permutation(len(p))]


@settings(
    max_examples=POINT_EXAMPLES,
    deadline=RECONSTRUCT_BUDGET,
    suppress_health_check=[HealthCheck.too_slow],
)
@given(points=messy_points(), k=st.sampled_from([3, 8, 12, 33]))
def test_fuzz_reconstruct(points, k):
    count("fuzz_reconstruct")
    try:
        r = reconstruct(points, k, budget=2000, exact_seconds=1.0)
    except InputError as exc:
        assert "\n" not in str(exc)
        return
    uniq = np.unique(points, axis=0)
    assert r.vertices.shape == uniq.shape
    assert np.array_equal(r.vertices[r.input_to_vertex], points)  # every sample kept, exactly
    t = r.triangles
    assert t.size == 0 or (t.min() >= 0 and t.max() < r.vertices.shape[0])
    if r.success:  # the success condition: no edge in more than two triangles
        assert mesh_stats(t, r.vertices.shape[0]).overloaded_edges == 0
