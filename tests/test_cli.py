"""The command line: summary table, error lines, exit codes, atomic output."""

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
    assert "t.ply: unreadable or truncated .ply file" in msg


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
    assert (
        msg
        == "sr33: error: points contain 1 non-finite (NaN or inf) coordinates rows, first at row 2"
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
