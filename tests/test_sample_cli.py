"""sr33 sample: listing, sampling with truth and metadata, errors."""

import json

import numpy as np
import pytest

pytest.importorskip("cadquery")

from sr33.cli import main  # noqa: E402
from sr33.io import read_mesh, read_points  # noqa: E402
from sr33.validators import mesh_stats  # noqa: E402


def test_list_names_every_shape_with_parameters(capsys):
    assert main(["sample", "--list"]) == 0
    out = capsys.readouterr().out
    for name in ("cube", "cutcube", "L_sheet", "wedge", "square_ring", "block_two_holes"):
        assert name in out
    assert "parameters:" in out


def test_sample_writes_points_truth_and_meta(tmp_path, capsys):
    pts, truth, meta = tmp_path / "p.ply", tmp_path / "t.ply", tmp_path / "m.json"
    code = main(
        [
            "sample",
            "cube",
            "--spacing",
            "0.1",
            "--seed",
            "2",
            "-o",
            str(pts),
            "--truth",
            str(truth),
            "--meta",
            str(meta),
        ]
    )
    assert code == 0
    out = capsys.readouterr().out
    assert "expected topology  components 1, Euler 2, genus 0, boundary loops 0" in out
    p = read_points(pts)
    assert p.shape[0] > 100
    v, f = read_mesh(truth)
    s = mesh_stats(f, v.shape[0])
    assert (s.open_edges, s.overloaded_edges, s.euler) == (0, 0, 2)
    m = json.loads(meta.read_text())
    assert m["spacing"] == pytest.approx(0.1) and m["seed"] == 2 and m["points"] == p.shape[0]
    # same arguments, same file (quiet or not)
    again = tmp_path / "p2.ply"
    argv = ["sample", "cube", "--spacing", "0.1", "--seed", "2", "-o", str(again), "--quiet"]
    assert main(argv) == 0
    assert again.read_bytes() == pts.read_bytes()


def test_sampling_logs_every_step_at_debug_level(caplog):
    """Each step of a sampling logs its time (logger sr33, debug level), in order."""
    import logging
    import re

    from sr33.samplers import shapes
    from sr33.samplers.scanline import scan

    with caplog.at_level(logging.DEBUG, logger="sr33"):
        scan(shapes.build("cube"), 0.1)
        scan(shapes.build("cube"), 0.1, repair=False)
    steps = re.findall(r"sample: ([a-z ]+) took \d+\.\d+ s", caplog.text)
    first = ["feature samples", "scan rows", "gaps filled"]
    repairs = ["pyramids", "filleted boxes", "disks", "planar faces", "cylinders", "cones"]
    repairs += ["bodies of revolution", "partial spheres"]
    assert steps == first + repairs + first


@pytest.mark.parametrize(
    "argv, text",
    [
        (["sample", "cubee", "-o", "x.ply"], "unknown shape 'cubee'"),
        (["sample", "cube", "--param", "size", "-o", "x.ply"], "--param must look like key=value"),
        (["sample", "cube", "--param", "size=abc", "-o", "x.ply"], "value must be a number"),
        (["sample", "cube", "--ratio", "3", "-o", "x.ply"], "ratio must be within"),
        (["sample", "cube"], "sample needs -o/--output"),
    ],
)
def test_sample_errors(argv, text, tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("sr33: error: ") and text in err
    assert len(err.splitlines()) == 1


def test_unknown_parameter_is_named(tmp_path, capsys):
    assert main(["sample", "cube", "--param", "radius=2", "-o", str(tmp_path / "x.ply")]) == 2
    assert "radius" in capsys.readouterr().err


def test_sampled_points_reconstruct_to_the_expected_topology(tmp_path, capsys):
    pts, mesh = tmp_path / "p.npy", tmp_path / "m.ply"
    assert main(["sample", "square_ring", "-o", str(pts)]) == 0
    assert main(["reconstruct", str(pts), "-k", "33", "-o", str(mesh), "-q"]) == 0
    v, f = read_mesh(mesh)
    s = mesh_stats(f, v.shape[0])
    assert (s.open_edges, s.overloaded_edges, s.euler, s.components) == (0, 0, 0, 1)
    assert np.unique(f).shape[0] == read_points(pts).shape[0]


def test_no_repair_keeps_the_plain_scan_rows(tmp_path):
    from sr33.samplers import shapes
    from sr33.samplers.scanline import scan

    out = tmp_path / "p.xyz"
    argv = ["sample", "cylinder", "--spacing", "0.1", "-o", str(out)]
    assert main([*argv, "--no-repair"]) == 0
    plain = scan(shapes.build("cylinder"), 0.1, repair=False)
    np.testing.assert_allclose(read_points(out), plain.points, rtol=0, atol=1e-12)
    assert plain.meta["repairs"] == []
