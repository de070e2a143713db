"""Honest reports, guards and odd environments (issue 22, items 8-10):
what a command says matches what it measured, parameters that would hang
or silently mislead are refused, a missing optional package names its
extra, an unwritable numba cache does not stop the import."""

import subprocess
import sys
import textwrap

import numpy as np
import pytest

from sr33 import Reconstruction, Tolerance, reconstruct
from sr33.cli import main
from sr33.io import write_mesh, write_points
from sr33.samplers import cube_lattice

TETRA = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], float)
FACES = np.array([[0, 2, 1], [0, 1, 3], [1, 2, 3], [2, 0, 3]])


def one_error(argv, capsys) -> tuple[int, str]:
    code = main(argv)
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "Traceback" not in err[0], err
    return code, err[0]


def run_python(code: str, *args: str) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-c", textwrap.dedent(code), *args],
        capture_output=True,
        text=True,
        timeout=300,
    )


# --- item 8: honest reports -------------------------------------------------


@pytest.fixture(scope="module")
def plane():
    pv = pytest.importorskip("pyvista")
    g = pv.Plane(i_size=1, j_size=1, i_resolution=100, j_resolution=100).triangulate()
    return np.asarray(g.points, float), np.asarray(g.faces).reshape(-1, 4)[:, 1:]


def square_lattice(z=0.0, shift=0.0):
    xs = np.arange(-0.45, 0.451, 0.1)
    p = np.stack(np.meshgrid(xs, xs, [z]), -1).reshape(-1, 3)
    p[:, :2] += np.random.default_rng(0).normal(0, 0.002, (len(p), 2))
    p[:, 0] += shift
    return p


def spacing(p):
    from scipy.spatial import cKDTree

    return float(np.median(cKDTree(p).query(p, 2)[0][:, 1]))


def test_view_of_a_mesh_file_reports_its_own_defects_not_a_success(tmp_path):
    # `sr33 view mesh.ply` once said "success condition met" for a mesh with
    # 136 open edges, and showed a k that was never used
    pytest.importorskip("pyvista")
    from sr33.gui import Inspector, mesh_as_reconstruction, pyvista

    pv = pyvista(off_screen=True)
    pts = cube_lattice(5)
    closed = reconstruct(pts, 12)
    torn = mesh_as_reconstruction(closed.vertices, closed.triangles[7:])
    whole = mesh_as_reconstruction(closed.vertices, closed.triangles)
    assert whole.success and not torn.success
    assert torn.k == 0 and len(torn.open_edges) > 0
    ins = Inspector(pv.Plotter(off_screen=True), pts, k=12, reconstruction=torn, widgets=False)
    panel = ins.plotter.actors["panel"].GetText(2)
    assert "mesh as read (no k used)" in panel
    assert "every sample a vertex: NO" in panel
    assert "success condition met" not in panel and "k = 12" not in panel
    assert ins.state.figures["open_edges"] == len(torn.open_edges)


def test_conditions_says_the_samples_are_off_the_truth_in_another_frame(plane, tmp_path, capsys):
    # points and truth in different frames once gave "the truth mesh is too coarse"
    write_points(tmp_path / "p.xyz", square_lattice(z=3.0))
    write_mesh(tmp_path / "t.ply", *plane)
    code, msg = one_error(
        ["conditions", str(tmp_path / "p.xyz"), "--truth", str(tmp_path / "t.ply"), "-q"], capsys
    )
    assert code == 2
    h = spacing(square_lattice())
    assert msg.startswith(
        f"sr33: error: the samples are off the truth by {3 / h:.3g} h (median; max {3 / h:.3g} h"
    )
    assert msg.endswith("are points and truth in the same frame and units?")


def test_conditions_fails_samples_a_third_of_h_off_the_truth(plane, tmp_path, capsys):
    # once silent: every condition "pass" on samples 1/3 h above the truth
    h = spacing(square_lattice())
    write_points(tmp_path / "p.xyz", square_lattice(z=h / 3))
    write_mesh(tmp_path / "t.ply", *plane)
    argv = ["conditions", str(tmp_path / "p.xyz"), "--truth", str(tmp_path / "t.ply"), "-q"]
    assert main(argv) == 1
    row = [r for r in capsys.readouterr().out.splitlines() if r.startswith("samples on the truth")]
    assert len(row) == 1 and row[0].split()[7:10] == ["FAIL", "0.333", "h"], row


def test_conditions_on_three_points_does_not_fail_on_nan():
    # III-ii once read "FAIL nan" for 3 points (no smooth DT_M edge: epsilon NaN)
    pytest.importorskip("potpourri3d")
    from sr33.validators.conditions import sample_conditions

    rep = sample_conditions(TETRA[:3] * 0.9 + 0.03, TETRA, FACES)
    rows = {r[0][:6]: r for r in rep.table()}
    assert np.isnan(rep.epsilon)
    assert rows["III-ii"][1] == "pass" and 0.7 < float(rows["III-ii"][2]) < 0.8
    assert all(r[1] != "FAIL" for r in rows.values())


# --- item 9: guards and budgets ---------------------------------------------


def test_k_beyond_the_neighbourhood_budget_is_refused_at_once(capsys, tmp_path):
    # k = 1999 on 2000 points once ran for more than 600 s without a word
    p = np.random.default_rng(0).normal(size=(2000, 3))
    write_points(tmp_path / "p.xyz", p)
    argv = ["reconstruct", str(tmp_path / "p.xyz"), "-k", "1999", "-o", str(tmp_path / "o.ply")]
    code, msg = one_error(argv, capsys)
    assert code == 2
    assert msg.startswith("sr33: error: k must be at most 256, got 1999: the localized RNG")
    assert not (tmp_path / "o.ply").exists()


@pytest.mark.parametrize(
    "kwargs, message",
    [
        ({"rtol": 0.5}, r"Tolerance.rtol must be within \[0, 0.001\], got 0.5"),
        ({"rtol": -1.0}, r"Tolerance.rtol must be >= 0, got -1.0"),
        ({"rtol": float("nan")}, r"Tolerance.rtol must be >= 0, got nan"),
        ({"fold_degrees": 90.0}, r"Tolerance.fold_degrees must be within \[0, 90\), got 90.0"),
    ],
)
def test_tolerances_that_hang_or_empty_the_result_are_refused(kwargs, message):
    # rtol = 0.5 once hung; rtol = -1 silently gave an empty mesh
    with pytest.raises(ValueError, match=message):
        Tolerance(**kwargs)


def test_complex_points_are_refused_not_truncated():
    pts = cube_lattice(3).astype(complex)
    pts[0, 0] += 1j
    with pytest.raises(ValueError, match="points must be real numbers, got a complex array"):
        reconstruct(pts, 8)


def test_a_run_has_one_bar_over_its_steps_and_every_step_is_timed(monkeypatch):
    import sr33.progress as progress

    seen = []
    real = progress.Steps.step

    def spy(self, name, timings=None):
        seen.append(name)
        return real(self, name, timings)

    monkeypatch.setattr(progress.Steps, "step", spy)
    rec = reconstruct(cube_lattice(4), 12, strict=False)
    assert (
        seen
        == list(rec.timings)
        == [
            "prepare",
            "localized_rng",
            "isometric_cycles",
            "backtracking",
            "triangulate",
            "cones",
        ]
    )


def test_a_kernel_compiled_in_this_run_is_announced_once():
    # the first run's numba compilation (about 13 s) says so, once; without
    # a usable cache every process compiles, so every process says so
    out = run_python(
        """
        import logging, sys
        logging.basicConfig(level=logging.INFO, stream=sys.stdout, format="%(message)s")
        import numba.core.caching as caching
        caching.CacheImpl._locator_classes = []  # nothing cached: everything compiles
        import numpy as np
        from sr33 import reconstruct
        octahedron = np.array([[1, 0, 0], [-1, 0, 0], [0, 1, 0],
                               [0, -1, 0], [0, 0, 1], [0, 0, -1]], float)
        for _ in range(2):
            reconstruct(octahedron, 4, quiet=False)
        """
    )
    assert out.returncode == 0, out.stderr
    said = [line for line in out.stdout.splitlines() if "compiling" in line]
    assert said == ["compiling the numba kernels (once per install, about 13 s)"]


def test_a_cached_or_compiled_kernel_is_not_announced_again():
    from sr33 import jit

    reconstruct(cube_lattice(3), 8)  # compiled or loaded now
    told = []
    with jit.compile_notice(lambda: told.append(1)):
        reconstruct(cube_lattice(3), 8)
    assert told == []


# --- item 10: missing optional packages, odd environments --------------------


@pytest.mark.parametrize(
    "missing, argv, extra",
    [
        ("cadquery", ["sample", "cube", "-o", "{d}/s.ply", "-q"], "cad"),
        ("pyvista", ["view", "{d}/m.ply", "--screenshot", "{d}/x.png"], "vtk"),
        ("pyvista", ["conditions", "{d}/m.ply", "--truth", "{d}/m.ply", "-q"], "vtk"),
        ("potpourri3d", ["conditions", "{d}/m.ply", "--truth", "{d}/m.ply", "-q"], "validate"),
    ],
)
def test_a_missing_optional_package_names_its_extra(tmp_path, missing, argv, extra):
    write_mesh(tmp_path / "m.ply", TETRA, FACES)
    out = run_python(
        f"""
        import sys
        sys.modules[{missing!r}] = None  # import fails as if not installed
        from sr33.cli import main
        sys.exit(main(sys.argv[1:]))
        """,
        *[a.format(d=tmp_path) for a in argv],
    )
    assert out.returncode == 2, out.stderr
    lines = out.stderr.strip().splitlines()
    assert len(lines) == 1, out.stderr
    assert lines[0].startswith(f"sr33: error: {argv[0]} needs ")
    assert lines[0].endswith(f"({missing} is not installed): pip install 'sr33[{extra}]'")


@pytest.mark.parametrize(
    "argv, message",
    [
        (["sample", "cube", "-o", "{d}/s.ply", "--seed", "-1"], "seed must be an integer >= 0"),
        (
            ["sample", "cube", "-o", "{d}/s.ply", "--param", "side=1e300"],
            "side must be 0 or of magnitude 0.0001 to 1e+06, got 1e+300",
        ),
        (
            ["view", "{d}/m.ply", "--show", "foo", "--screenshot", "{d}/x.png"],
            "--show/--hide: layer must be one of samples",
        ),
    ],
)
def test_odd_arguments_are_input_errors_not_internal_ones(tmp_path, capsys, argv, message):
    # each once ended in a traceback (exit 3 after issue 22's exit codes)
    if argv[0] == "sample":
        pytest.importorskip("cadquery")
    else:
        pytest.importorskip("pyvista")
    write_mesh(tmp_path / "m.ply", TETRA, FACES)
    code, msg = one_error([a.format(d=tmp_path) for a in argv], capsys)
    assert code == 2
    assert msg.startswith(f"sr33: error: {message}")
    assert not any(tmp_path.glob("s.ply")) and not any(tmp_path.glob("x.png"))


def test_the_kernels_import_and_run_where_numba_cannot_cache():
    # numba refuses cache=True at import when neither the package folder nor
    # $HOME is writable (once an exception at import); sr33 then compiles per
    # process instead
    out = run_python(
        """
        import numba.core.caching as caching
        caching.CacheImpl._locator_classes = []  # no writable cache location anywhere
        import numpy as np
        from sr33 import reconstruct
        octahedron = np.array([[1, 0, 0], [-1, 0, 0], [0, 1, 0],
                               [0, -1, 0], [0, 0, 1], [0, 0, -1]], float)
        r = reconstruct(octahedron, 4)
        print(r.triangles.shape[0], r.success)
        """
    )
    assert out.returncode == 0, out.stderr
    assert out.stdout.split() == ["8", "True"]


# --- the user-facing extras: repr and conversions ----------------------------


def test_repr_states_figures_not_arrays_and_conversions_keep_the_mesh():
    rec = reconstruct(cube_lattice(5), 12)
    text = repr(rec)
    assert text == (
        f"Reconstruction(vertices={rec.vertices.shape[0]}, triangles={rec.triangles.shape[0]}, "
        "k=12, success=True, orientable=True, open_edges=0, unresolved_samples=0, "
        "coned_samples=0, duplicates_merged=0, fallback_components=0)"
    )
    assert isinstance(rec, Reconstruction)
    m = rec.to_meshio()
    assert np.array_equal(m.points, rec.vertices)
    assert np.array_equal(m.cells_dict["triangle"], rec.triangles)
    pytest.importorskip("pyvista")
    pd = rec.to_pyvista()
    assert np.array_equal(np.asarray(pd.points), rec.vertices)
    assert np.array_equal(np.asarray(pd.faces).reshape(-1, 4)[:, 1:], rec.triangles)


def test_an_extent_near_the_float64_limit_is_reconstructed_not_nan():
    # found by the fuzz target: a sphere at 1e300 with one outlier near
    # 1.7e308 once made the working frame's shift 2^1025 = inf and the
    # degeneracy check's SVD fail on NaN
    p = np.random.default_rng(0).normal(size=(21, 3))
    p = p / np.linalg.norm(p, axis=1)[:, None] * 1e300
    p[3] = [-4.4e307, -1.2e308, 1.7e308]
    r = reconstruct(p, 3)
    assert np.array_equal(r.vertices[r.input_to_vertex], p)
    assert r.triangles.shape[0] > 0 and np.isfinite(r.vertices).all()
