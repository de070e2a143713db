"""The command line: summary table, error lines, exit codes, atomic output."""

import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from sr33.cli import main
from sr33.io import read_mesh, write_mesh
from sr33.samplers import cube_lattice
from tests.helpers import PAPER_SMALL, need


@pytest.fixture
def cube_xyz(tmp_path):
    p = tmp_path / "cube.xyz"
    np.savetxt(p, cube_lattice(4))
    return p


def run(argv, capsys):
    code = main(argv)
    out, err = capsys.readouterr()
    return code, out, err


def test_reconstruct_prints_the_summary_and_writes_the_mesh(cube_xyz, tmp_path, capsys):
    out_path = tmp_path / "cube.ply"
    code, out, err = run(
        ["reconstruct", str(cube_xyz), "-k", "12", "-o", str(out_path), "-q"], capsys
    )
    assert code == 0, err
    rows = dict(
        line.split(None, 1) if False else (line[:26].strip(), line[26:].strip())
        for line in out.splitlines()
    )
    assert rows["points"] == "98"
    assert rows["used vertices"] == "98"
    assert rows["open edges"] == "0"
    assert rows["overloaded edges"] == "0"
    assert rows["Euler characteristic"] == "2"
    assert rows["components"] == "1"
    assert rows["boundary loops"] == "0"
    assert rows["success condition"] == "met"
    for step in ("localized_rng", "isometric_cycles", "backtracking", "triangulate", "cones"):
        assert f"seconds {step}" in rows
    v, f = read_mesh(out_path)
    assert v.shape == (98, 3) and f.shape == (192, 3)
    assert err == ""


def test_stats_prints_the_same_figures(cube_xyz, tmp_path, capsys):
    out_path = tmp_path / "cube.obj"
    assert main(["reconstruct", str(cube_xyz), "-k", "12", "-o", str(out_path), "-q"]) == 0
    capsys.readouterr()
    code, out, _ = run(["stats", str(out_path)], capsys)
    assert code == 0
    assert "Euler characteristic  2" in out
    assert "edges                 288" in out


@pytest.mark.parametrize("fmt", [".ply", ".obj", ".off", ".stl", ".vtp"])
def test_every_output_format_round_trips(fmt, cube_xyz, tmp_path, capsys):
    out_path = tmp_path / f"cube{fmt}"
    assert main(["reconstruct", str(cube_xyz), "-k", "12", "-o", str(out_path), "-q"]) == 0
    v, f = read_mesh(out_path)
    assert f.shape[0] == 192
    # STL stores triangle soup: vertices are repeated per triangle
    if fmt != ".stl":
        assert v.shape[0] == 98


@pytest.mark.parametrize("fmt", [".ply", ".obj", ".off", ".vtp", ".npy", ".txt"])
def test_every_input_format_is_read(fmt, tmp_path, capsys):
    pts = cube_lattice(3)
    src = tmp_path / f"in{fmt}"
    if fmt == ".npy":
        np.save(src, pts)
    elif fmt == ".txt":
        np.savetxt(src, pts, delimiter=",")
    else:
        write_mesh(src, pts, np.array([[0, 1, 2]]))
    code, out, err = run(
        ["reconstruct", str(src), "-k", "12", "-o", str(tmp_path / "o.ply"), "-q"], capsys
    )
    assert code == 0, err
    assert "points                    56" in out


def test_two_runs_give_byte_identical_files(cube_xyz, tmp_path):
    for fmt in (".ply", ".obj", ".off", ".stl", ".vtp"):
        a, b = tmp_path / f"a{fmt}", tmp_path / f"b{fmt}"
        assert main(["reconstruct", str(cube_xyz), "-k", "12", "-o", str(a), "-q"]) == 0
        assert main(["reconstruct", str(cube_xyz), "-k", "12", "-o", str(b), "-q"]) == 0
        assert a.read_bytes() == b.read_bytes()


def error_of(argv, capsys):
    code, out, err = run(argv, capsys)
    assert code == 2
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert "Traceback" not in err
    return lines[0]


def test_missing_file(tmp_path, capsys):
    msg = error_of(
        ["reconstruct", str(tmp_path / "nope.xyz"), "-o", str(tmp_path / "o.ply")], capsys
    )
    assert msg == f"sr33: error: {tmp_path / 'nope.xyz'}: no such file"


def test_empty_file(tmp_path, capsys):
    p = tmp_path / "empty.ply"
    p.write_bytes(b"")
    msg = error_of(["reconstruct", str(p), "-o", str(tmp_path / "o.ply")], capsys)
    assert msg.endswith("empty.ply: file is empty")


def test_truncated_ply(tmp_path, capsys):
    p = tmp_path / "t.ply"
    write_mesh(p, cube_lattice(3), np.array([[0, 1, 2]]))
    data = p.read_bytes()
    p.write_bytes(data[: len(data) // 2])
    msg = error_of(["reconstruct", str(p), "-o", str(tmp_path / "o.ply")], capsys)
    assert msg == (
        f"sr33: error: {p}: truncated PLY: its header declares 56 vertex and 1 face "
        "elements, which needs at least 1345 bytes of data, the file holds 580"
    )


def test_garbage_text(tmp_path, capsys):
    p = tmp_path / "g.xyz"
    p.write_text("1 2 3\n4 five 6\n")
    msg = error_of(["reconstruct", str(p), "-o", str(tmp_path / "o.ply")], capsys)
    assert msg.endswith("g.xyz: line 2: coordinates are not numbers")


def test_binary_junk_as_text(tmp_path, capsys):
    p = tmp_path / "b.xyz"
    p.write_bytes(bytes(range(256)) * 4)
    msg = error_of(["reconstruct", str(p), "-o", str(tmp_path / "o.ply")], capsys)
    assert "b.xyz: not a text .xyz file" in msg


def test_unsupported_extension(tmp_path, capsys):
    p = tmp_path / "x.las"
    p.write_text("1 2 3")
    msg = error_of(["reconstruct", str(p), "-o", str(tmp_path / "o.ply")], capsys)
    assert "unsupported format .las" in msg


def test_nan_in_file(tmp_path, capsys):
    p = tmp_path / "n.xyz"
    pts = cube_lattice(2)
    pts[2, 2] = np.nan
    np.savetxt(p, pts)
    msg = error_of(["reconstruct", str(p), "-k", "8", "-o", str(tmp_path / "o.ply")], capsys)
    assert msg == (
        f"sr33: error: {p}: 1 of 26 points have non-finite (NaN or inf) coordinates, "
        "first point 2 = [0.0, 0.0, nan]"
    )


def test_too_few_points_file(tmp_path, capsys):
    p = tmp_path / "few.xyz"
    np.savetxt(p, np.eye(3))
    msg = error_of(["reconstruct", str(p), "-o", str(tmp_path / "o.ply")], capsys)
    assert msg == "sr33: error: points must hold at least 4 points, got 3"


def test_k_too_large(cube_xyz, tmp_path, capsys):
    msg = error_of(
        ["reconstruct", str(cube_xyz), "-k", "500", "-o", str(tmp_path / "o.ply")], capsys
    )
    assert msg == "sr33: error: k must be less than the number of distinct points (98), got 500"


def test_output_directory_missing(cube_xyz, tmp_path, capsys):
    out = tmp_path / "nodir" / "o.ply"
    msg = error_of(["reconstruct", str(cube_xyz), "-k", "12", "-o", str(out)], capsys)
    assert msg == f"sr33: error: {out}: directory {out.parent} does not exist"


def test_output_not_writable_leaves_nothing(cube_xyz, capsys):
    out = Path("/proc/sr33-cannot-write.ply")
    msg = error_of(["reconstruct", str(cube_xyz), "-k", "12", "-o", str(out)], capsys)
    assert msg.startswith(f"sr33: error: {out}: cannot write")
    assert not out.exists()


def test_output_is_replaced_atomically(cube_xyz, tmp_path):
    out = tmp_path / "o.ply"
    out.write_bytes(b"old")
    assert main(["reconstruct", str(cube_xyz), "-k", "12", "-o", str(out), "-q"]) == 0
    assert out.read_bytes().startswith(b"ply")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["cube.xyz", "o.ply"]


def test_unsupported_output_format(cube_xyz, tmp_path, capsys):
    msg = error_of(
        ["reconstruct", str(cube_xyz), "-k", "12", "-o", str(tmp_path / "o.xyz")], capsys
    )
    assert "unsupported output format .xyz" in msg


def test_stats_needs_faces(tmp_path, capsys):
    p = tmp_path / "pts.xyz"
    np.savetxt(p, cube_lattice(2))
    msg = error_of(["stats", str(p)], capsys)
    assert msg.endswith("pts.xyz: has no faces; stats needs a triangle mesh")


def test_console_script_runs_on_a_paper_set(tmp_path):
    src = need(PAPER_SMALL / "cube.obj")
    out = tmp_path / "c.ply"
    res = subprocess.run(
        [
            sys.executable,
            "-m",
            "sr33.cli",
            "reconstruct",
            str(src),
            "-k",
            "16",
            "-o",
            str(out),
            "-q",
        ],
        capture_output=True,
        text=True,
        check=False,
    )
    assert res.returncode == 0, res.stderr
    assert "overloaded edges          0" in res.stdout
    assert out.exists()


def test_validate_exit_codes(cube_xyz, tmp_path, capsys):
    good = tmp_path / "good.ply"
    assert main(["reconstruct", str(cube_xyz), "-k", "12", "-o", str(good), "-q"]) == 0
    capsys.readouterr()
    code, out, _ = run(["validate", str(good), "--points", str(cube_xyz)], capsys)
    assert code == 0
    assert "self-intersecting pairs    0" in out
    assert "input points not vertices  0" in out
    # drop one face: no longer homeomorphic to the full cube
    v, f = read_mesh(good)
    holed = tmp_path / "holed.ply"
    write_mesh(holed, v, f[1:])
    code, out, _ = run(["validate", str(holed), "--truth", str(good)], capsys)
    assert code == 1
    assert "Euler characteristic: mesh 1, truth 2" in out
    assert "boundary loops: mesh 1, truth 0" in out


def test_validate_bad_input(tmp_path, capsys):
    msg = error_of(["validate", str(tmp_path / "none.ply")], capsys)
    assert msg.endswith("none.ply: no such file")


# --- exit codes, early output checks, signals (issue 22) ----------------------


@pytest.fixture
def crossing_planes_xyz(tmp_path):
    """Two planes crossing along a line: no surface, the success condition fails."""
    g = np.linspace(-1, 1, 9)
    a = [(x, y, 0.0) for x in g for y in g]
    b = [(x, 0.0, z) for x in g for z in g if z != 0]
    p = tmp_path / "cross.xyz"
    np.savetxt(p, np.array(a + b))
    return p


def test_reconstruct_exits_1_when_the_success_condition_fails(
    crossing_planes_xyz, tmp_path, capsys
):
    out = tmp_path / "cross.ply"
    code, text, _ = run(
        ["reconstruct", str(crossing_planes_xyz), "-k", "12", "-o", str(out), "-q"], capsys
    )
    assert code == 1
    assert re.search(r"^success condition +NOT met$", text, re.M)
    # what the search could not decide, and what the exact selection made of it
    assert re.search(r"^strict search failed +1 component$", text, re.M)
    assert re.search(r"^exact selection +0 of 1 improved, 0 proven optimal$", text, re.M)
    assert out.exists()  # the result is still written


def test_outputs_are_checked_before_the_work(cube_xyz, tmp_path, capsys, monkeypatch):
    import importlib

    def boom(*a, **k):
        raise AssertionError("the reconstruction ran before the outputs were checked")

    monkeypatch.setattr(importlib.import_module("sr33.reconstruct"), "reconstruct", boom)
    good = str(tmp_path / "ok.ply")
    cases = [
        (["-o", str(tmp_path / "out.xyz2")], "unsupported output format .xyz2"),
        (["-o", good, "--json", str(tmp_path / "no" / "s.json")], "does not exist"),
        (["-o", good, "--save", str(tmp_path / "s.txt")], "unsupported reconstruction format"),
        (["-o", str(cube_xyz)], "unsupported output format .xyz"),
    ]
    for extra, text in cases:
        msg = error_of(["reconstruct", str(cube_xyz), "-q"] + extra, capsys)
        assert text in msg, msg
    from sr33.io import write_points

    ply = tmp_path / "points.ply"
    write_points(ply, cube_lattice(4))
    before = ply.read_bytes()
    msg = error_of(["reconstruct", str(ply), "-o", str(ply), "-q"], capsys)
    assert "is also the input" in msg
    assert ply.read_bytes() == before  # the input is never overwritten
    assert not (tmp_path / "ok.ply").exists()


def test_sample_refuses_the_same_path_for_points_and_truth(tmp_path, capsys):
    pytest.importorskip("cadquery")
    x = str(tmp_path / "x.ply")
    msg = error_of(["sample", "cube", "-o", x, "--truth", x, "-q"], capsys)
    assert "is also the point file" in msg
    assert not Path(x).exists()


def test_internal_errors_exit_3_with_one_line(cube_xyz, tmp_path, capsys, monkeypatch):
    import importlib

    def broken(*a, **k):
        raise RuntimeError("kernel exploded")

    monkeypatch.setattr(importlib.import_module("sr33.reconstruct"), "reconstruct", broken)
    argv = ["reconstruct", str(cube_xyz), "-o", str(tmp_path / "o.ply"), "-q"]
    code, _, err = run(argv, capsys)
    assert code == 3
    assert err.strip().splitlines() == [
        "sr33: internal error: RuntimeError: kernel exploded (run with -v for the traceback)"
    ]
    code, _, err = run(argv + ["-v"], capsys)  # -v after the subcommand
    assert code == 3 and "Traceback (most recent call last)" in err


def test_version_and_defaults_in_help(capsys):
    from sr33 import __version__

    with pytest.raises(SystemExit) as exc:
        main(["--version"])
    assert exc.value.code == 0 and capsys.readouterr().out.strip() == f"sr33 {__version__}"
    with pytest.raises(SystemExit):
        main(["reconstruct", "--help"])
    out = capsys.readouterr().out
    assert "(default: 33)" in out and "(default: 20000)" in out
    with pytest.raises(SystemExit):
        main(["--help"])
    assert "2  bad input or output" in capsys.readouterr().out


def test_a_closed_pipe_is_not_an_error(cube_xyz, tmp_path, capsys, monkeypatch):
    mesh = tmp_path / "c.ply"
    assert main(["reconstruct", str(cube_xyz), "-k", "12", "-o", str(mesh), "-q"]) == 0
    capsys.readouterr()

    class ClosedPipe:
        def write(self, s):
            return len(s)

        def flush(self):
            raise BrokenPipeError(32, "Broken pipe")

        def fileno(self):
            return os.open(os.devnull, os.O_WRONLY)

    monkeypatch.setattr(sys, "stdout", ClosedPipe())
    assert main(["stats", str(mesh)]) == 0
    assert "Traceback" not in capsys.readouterr().err


def test_sigterm_during_a_write_leaves_no_temporary_file(cube_xyz, tmp_path):
    import signal
    import time

    out = tmp_path / "out" / "mesh.obj"
    out.parent.mkdir()
    code = f"""
import time, numpy as np, sys
real = np.savetxt
def slow(*a, **k):
    real(*a, **k)
    time.sleep(60)
np.savetxt = slow
from sr33.cli import main
sys.exit(main(["reconstruct", {str(cube_xyz)!r}, "-k", "12", "-o", {str(out)!r}, "-q"]))
"""
    proc = subprocess.Popen([sys.executable, "-c", code], stderr=subprocess.PIPE, text=True)
    deadline = time.time() + 120
    while time.time() < deadline and not list(out.parent.iterdir()):
        time.sleep(0.1)
    assert list(out.parent.iterdir()), "the write never started"
    proc.send_signal(signal.SIGTERM)
    assert proc.wait(timeout=60) == 128 + signal.SIGTERM
    assert list(out.parent.iterdir()) == []
