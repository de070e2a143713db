"""One Condition III verdict across the project (issue 23 item 5): where a
truth is known, the inspector's panel and ``sr33 validate --points --truth``
report the geodesic verdict of ``sr33 conditions``; without one they say
that theirs is approximate."""

import json

import numpy as np
import pytest

pytest.importorskip("cadquery")
pytest.importorskip("potpourri3d")
pytest.importorskip("pyvista")

from sr33 import reconstruct  # noqa: E402
from sr33.cli import main  # noqa: E402
from sr33.gui import Inspector, pyvista  # noqa: E402
from sr33.io import read_mesh, read_points, write_mesh  # noqa: E402
from sr33.validators.conditions import sample_conditions  # noqa: E402


@pytest.fixture(scope="module")
def box_hole_rows(tmp_path_factory):
    """A library box with a hole sampled by plain scan rows (no repair):
    where straight rows meet the circular hole Condition III-ii fails at
    some samples, not all."""
    d = tmp_path_factory.mktemp("verdict")
    pts, truth, mesh = d / "p.ply", d / "t.ply", d / "m.ply"
    argv = ["sample", "box_hole", "--no-repair", "--points", "600", "-q"]
    assert main(argv + ["-o", str(pts), "--truth", str(truth)]) == 0
    p = read_points(pts)
    write_mesh(mesh, *_mesh(p))
    return pts, truth, mesh


def _mesh(p):
    r = reconstruct(p, 33)
    return r.vertices, r.triangles


def test_inspector_and_validate_report_the_verdict_of_conditions(box_hole_rows, tmp_path, capsys):
    pts, truth, mesh = box_hole_rows
    assert main(["conditions", str(pts), "--truth", str(truth), "-q"]) == 1  # FAIL
    table = capsys.readouterr().out
    assert "III-ii shorter edges < sqrt(3)/2 longest  FAIL" in table
    p = read_points(pts)
    tv, tf = read_mesh(truth)
    report = sample_conditions(p, tv, tf)
    bad = report.violations()
    assert 0 < bad.shape[0] < p.shape[0]

    out = tmp_path / "v.json"
    main(
        ["validate", str(mesh), "--points", str(pts), "--truth", str(truth), "-q"]
        + ["--json", str(out)]
    )
    line = [
        r for r in capsys.readouterr().out.splitlines() if r.startswith("points' Condition III")
    ]
    assert len(line) == 1 and line[0].split(None, 3)[3] == (
        f"FAIL: {bad.shape[0]} samples violate, worst III-ii ratio "
        f"{report.max_ratio:.4f}, max degree {report.max_degree} (geodesic)"
    )
    doc = json.loads(out.read_text())["condition_iii"]
    assert doc["method"] == "geodesic" and doc["passed"] is False
    assert doc["violating_samples"] == bad.shape[0]

    pv = pyvista(off_screen=True)
    ins = Inspector(pv.Plotter(off_screen=True), p, k=33, truth=(tv, tf), widgets=False)
    assert np.array_equal(ins.conditions, bad)  # the cyan samples are the geodesic ones
    panel = ins.plotter.actors["panel"].GetText(2)
    assert f"condition III violations {bad.shape[0]} (geodesic)" in panel


def test_without_a_truth_the_verdict_says_it_is_approximate(box_hole_rows, capsys):
    pts, _, mesh = box_hole_rows
    main(["validate", str(mesh), "--points", str(pts), "-q"])
    line = [
        r for r in capsys.readouterr().out.splitlines() if r.startswith("points' Condition III")
    ]
    assert len(line) == 1 and line[0].endswith("(approximate (no truth))")
    pv = pyvista(off_screen=True)
    ins = Inspector(pv.Plotter(off_screen=True), read_points(pts), k=33, widgets=False)
    assert "(approximate (no truth))" in ins.plotter.actors["panel"].GetText(2)
