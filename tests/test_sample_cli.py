"""sr33 sample: listing, sampling with truth and metadata, errors."""

import json
import re

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
    assert "every shape also takes rotate_x, rotate_y, rotate_z: degrees" in out


def test_sample_a_turned_shape_records_its_frame(tmp_path):
    """--param rotate_z=30: the meta records the parameter and the frame
    the shape was scanned in (its own, turned 30 degrees about z)."""
    meta = tmp_path / "m.json"
    argv = ["sample", "cube", "--param", "rotate_z=30", "--no-repair", "--points", "600"]
    assert main(argv + ["-o", str(tmp_path / "p.npy"), "--meta", str(meta), "-q"]) == 0
    doc = json.loads(meta.read_text())
    assert doc["params"] == {"side": 1.0, "rotate_z": 30.0}
    frame = np.array(doc["frame"])
    c, s = np.cos(np.radians(30)), np.sin(np.radians(30))
    turn = np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])
    # the frame's axes are the turned cube's, up to the cube's quarter turns
    np.testing.assert_allclose(np.abs(frame @ turn).round(9) % 1, 0, atol=1e-9)
    assert not np.allclose(frame, np.eye(3))


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
    repairs = ["turned parts", "pyramids", "filleted boxes", "disks", "spherical caps"]
    repairs += ["developable bands"]
    repairs += ["planar faces"]
    repairs += ["planar faces along square edges", "cylinders", "cones"]
    repairs += ["bodies of revolution", "partial spheres", "curved faces in their charts"]
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


# --- a user's CAD file (issue 23 item 1) -----------------------------------


def _part():
    """A part with two through-holes, filleted vertical edges and a
    chamfered top: genus 2, planar, cylindrical and conical faces."""
    import cadquery as cq

    return (
        cq.Workplane("XY")
        .box(1.0, 0.7, 0.3)
        .edges("|Z")
        .fillet(0.1)
        .faces(">Z")
        .edges()
        .chamfer(0.04)
        .faces(">Z")
        .workplane()
        .pushPoints([(-0.25, 0), (0.25, 0)])
        .hole(0.18)
    )


def test_a_step_file_is_sampled_on_its_surface_and_reconstructs(tmp_path, capsys):
    import cadquery as cq

    from sr33 import reconstruct
    from sr33.validators.fidelity import distance_to_surface
    from sr33.validators.intersections import self_intersections
    from sr33.validators.signature import homeomorphic, signature

    step = tmp_path / "part.step"
    cq.exporters.export(_part(), str(step))
    pts, truth, meta = tmp_path / "p.ply", tmp_path / "t.ply", tmp_path / "m.json"
    argv = ["sample", str(step), "--no-repair", "--points", "2000", "-q"]
    argv += ["-o", str(pts), "--truth", str(truth), "--meta", str(meta)]
    assert main(argv) == 0
    out = capsys.readouterr().out
    assert "expected topology  components 1, Euler -2, genus 2, boundary loops 0" in out
    doc = json.loads(meta.read_text())
    assert doc["shape"] == "part" and doc["params"] == {}
    p = read_points(pts)
    tv, tf = read_mesh(truth)
    # on the CAD surface (the truth is its tessellation, 1/500 of the size)
    assert distance_to_surface(p, tv, tf).max() < 1e-3
    r = reconstruct(p, 33)
    sig = signature(r.triangles, r.vertices.shape[0], points=r.vertices)
    assert homeomorphic(sig, signature(tf, tv.shape[0]))
    assert self_intersections(r.vertices, r.triangles).shape[0] == 0


def test_from_cad_reads_cadquery_objects_and_brep_files(tmp_path):
    import cadquery as cq

    from sr33.samplers import shapes

    direct = shapes.from_cad(_part())
    assert direct.name == "cad" and direct.expected.genus == 2
    brep = tmp_path / "part.brep"
    _part().val().exportBrep(str(brep))
    read = shapes.from_cad(brep)
    assert read.name == "part" and read.expected == direct.expected
    assert read.area == pytest.approx(direct.area, rel=1e-9)
    box = shapes.from_cad(cq.Workplane().box(1, 2, 3), name="brick")
    assert (box.name, box.expected.euler, box.expected.genus) == ("brick", 2, 0)
    assert box.area == pytest.approx(22.0)


@pytest.mark.parametrize(
    "case, message",
    [
        ("missing", "missing.step: no such file"),
        ("garbage", "garbage.step: unreadable .step file"),
        ("two", "two.step: holds 2 solids"),
        ("iges", "part.iges: unsupported CAD format .iges; use one of .step, .stp, .brep"),
        ("param", "--param applies to library shapes, not to the CAD file"),
    ],
)
def test_bad_cad_files_are_one_line_errors(tmp_path, capfd, case, message):
    import cadquery as cq

    argv = ["sample"]
    if case == "missing":
        argv.append(str(tmp_path / "missing.step"))
    elif case == "garbage":
        (tmp_path / "garbage.step").write_text("not a STEP file\n")
        argv.append(str(tmp_path / "garbage.step"))
    elif case == "two":
        two = cq.Workplane().box(1, 1, 1).union(cq.Workplane().box(1, 1, 1).translate((3, 0, 0)))
        cq.exporters.export(two, str(tmp_path / "two.step"))
        argv.append(str(tmp_path / "two.step"))
    elif case == "iges":
        argv.append(str(tmp_path / "part.iges"))
    else:
        cq.exporters.export(_part(), str(tmp_path / "part.step"))
        argv += [str(tmp_path / "part.step"), "--param", "side=2"]
    assert main(argv + ["-o", str(tmp_path / "p.ply")]) == 2
    captured = capfd.readouterr()  # the file descriptors: OpenCascade writes to them
    err = captured.err.strip().splitlines()
    assert len(err) == 1 and message in err[0], err
    assert "StepFile" not in captured.out  # OpenCascade's own report is silenced
    assert not (tmp_path / "p.ply").exists()


def test_a_curved_face_no_layout_takes_is_named(tmp_path, capsys, caplog):
    """A torus cut by a box: its face, trimmed, is a body of revolution no
    more and no chart takes it, so it keeps its scan rows; the sampling
    says so (the meta's ``scan_rows_only``, a warning, the summary's row),
    and a cylinder, its curved face laid out, says none."""
    import cadquery as cq

    torus = cq.Solid.makeTorus(0.5, 0.15)
    cut = torus.cut(cq.Solid.makeBox(1.0, 1.0, 1.0, pnt=cq.Vector(-0.2, -0.5, 0.05)))
    brep = tmp_path / "bitten.brep"
    cq.Solid(cut.Solids()[0].wrapped).exportBrep(str(brep))
    meta = tmp_path / "m.json"
    argv = ["sample", str(brep), "--points", "400", "-o", str(tmp_path / "p.ply")]
    with caplog.at_level("WARNING", logger="sr33"):
        assert main(argv + ["--meta", str(meta), "--quiet"]) == 0
    left = json.loads(meta.read_text())["scan_rows_only"]
    kinds = [f.geomType() for f in cq.Shape.importBrep(str(brep)).Faces()]
    assert left == [{"face": kinds.index("TORUS"), "kind": "torus"}]
    out = capsys.readouterr().out
    assert re.search(r"^scan rows only +face \d+ \(torus\) \(no layout", out, re.M), out
    assert any("keeps its scan rows" in r.getMessage() for r in caplog.records)
    assert main(["sample", "cylinder", "--spacing", "0.15", "-o", str(tmp_path / "c.ply")]) == 0
    assert re.search(r"^scan rows only +none$", capsys.readouterr().out, re.M)
