"""Broken mesh and point files (issue 22, items 4 and 5): truncated PLY,
byte-order marks, non-finite vertices and bad face indices give one line
naming the file and the problem, exit 2, in every subcommand that reads a
mesh."""

import subprocess
import sys
import textwrap

import numpy as np
import pytest

from sr33.cli import main
from sr33.io import ReadError, read_mesh, write_mesh
from sr33.mesh import as_mesh, self_intersections, surface_points

TETRA = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], float)
FACES = np.array([[0, 2, 1], [0, 1, 3], [1, 2, 3], [2, 0, 3]])


def error_line(argv, capsys) -> tuple[int, str]:
    code = main(argv)
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1, err  # one line, no traceback
    return code, err[0]


def ascii_ply(path, vertices, faces=None, declared_vertices=None, declared_faces=None):
    nv = len(vertices) if declared_vertices is None else declared_vertices
    head = f"ply\nformat ascii 1.0\nelement vertex {nv}\n"
    head += "property float x\nproperty float y\nproperty float z\n"
    if faces is not None:
        nf = len(faces) if declared_faces is None else declared_faces
        head += f"element face {nf}\nproperty list uchar int vertex_indices\n"
    body = "".join(f"{float(x)!r} {float(y)!r} {float(z)!r}\n" for x, y, z in vertices)
    if faces is not None:
        body += "".join("3 " + " ".join(str(int(i)) for i in f) + "\n" for f in faces)
    path.write_text(head + "end_header\n" + body)
    return path


# --- item 4: truncated files, byte-order marks ------------------------------


def test_an_ascii_ply_with_fewer_vertices_than_its_header_is_refused(tmp_path, capsys):
    # a header saying 2000 vertices with 1000 present once read as 1000 points
    pts = np.random.default_rng(0).random((1000, 3))
    p = ascii_ply(tmp_path / "short.ply", pts, declared_vertices=2000)
    code, msg = error_line(["stats", str(p)], capsys)
    assert code == 2
    assert msg == (
        f"sr33: error: {p}: truncated PLY: its header declares 2000 vertex elements, "
        "the file holds 1000 data lines"
    )


def test_a_binary_ply_cut_at_a_face_record_boundary_is_refused(tmp_path, capsys):
    # cut after 250 of 500 whole face records: meshio once returned 250 faces
    v = np.random.default_rng(1).random((2000, 3))
    t = np.random.default_rng(2).integers(0, 2000, (500, 3))
    p = write_mesh(tmp_path / "m.ply", v, t)
    data = p.read_bytes()
    body = data.index(b"end_header\n") + len(b"end_header\n")
    p.write_bytes(data[: body + 2000 * 24 + 13 * 250])
    code, msg = error_line(["validate", str(p)], capsys)
    assert code == 2
    assert msg == (
        f"sr33: error: {p}: truncated or inconsistent PLY: its header declares 500 face "
        "elements, 250 were read"
    )


@pytest.mark.parametrize("cut", [0, 5, 24 * 999 + 7])
def test_a_binary_ply_cut_inside_its_vertices_is_refused(tmp_path, cut):
    v = np.random.default_rng(3).random((1000, 3))
    p = write_mesh(tmp_path / "m.ply", v, np.array([[0, 1, 2]]))
    data = p.read_bytes()
    body = data.index(b"end_header\n") + len(b"end_header\n")
    p.write_bytes(data[: body + cut])
    with pytest.raises(ReadError, match=r"truncated PLY: its header declares 1000 vertex and 1 "):
        read_mesh(p)


def test_a_header_promising_a_trillion_vertices_is_refused_before_reading(tmp_path):
    # a 1 kB file must not make the reader allocate terabytes
    p = tmp_path / "huge.ply"
    head = (
        "ply\nformat binary_little_endian 1.0\nelement vertex 1000000000000\n"
        "property double x\nproperty double y\nproperty double z\nend_header\n"
    )
    p.write_bytes(head.encode() + bytes(1000))
    with pytest.raises(ReadError, match=r"needs at least 24000000000000 bytes of data, the file"):
        read_mesh(p)


def test_a_ply_without_end_header_is_refused(tmp_path):
    p = tmp_path / "h.ply"
    p.write_bytes(b"ply\nformat ascii 1.0\nelement vertex 3\n")
    with pytest.raises(ReadError, match="PLY header has no end_header line"):
        read_mesh(p)


@pytest.mark.parametrize("ext", [".obj", ".xyz"])
def test_a_byte_order_mark_does_not_drop_the_first_vertex(tmp_path, ext):
    # an OBJ starting with a UTF-8 BOM once lost its first vertex
    lines = [("v " if ext == ".obj" else "") + " ".join(map(repr, p)) for p in TETRA.tolist()]
    if ext == ".obj":
        lines += ["f " + " ".join(str(i + 1) for i in f) for f in FACES]
    p = tmp_path / f"bom{ext}"
    p.write_text("\n".join(lines) + "\n", encoding="utf-8-sig")
    assert p.read_bytes()[:3] == b"\xef\xbb\xbf"
    v, f = read_mesh(p)
    assert np.array_equal(v, TETRA)
    assert f.tolist() == (FACES.tolist() if ext == ".obj" else [])


# --- item 5: non-finite vertices and bad indices -----------------------------

BROKEN = {
    "inf": (
        lambda v, t: (np.where(np.arange(12).reshape(4, 3) == 7, np.inf, v), t),
        "1 of 4 vertices have non-finite (NaN or inf) coordinates, "
        "first vertex 2 = [0.0, inf, 0.0]",
    ),
    "nan": (
        lambda v, t: (np.where(np.arange(12).reshape(4, 3) == 3, np.nan, v), t),
        "1 of 4 vertices have non-finite (NaN or inf) coordinates, "
        "first vertex 1 = [nan, 0.0, 0.0]",
    ),
    "minus_one": (
        lambda v, t: (v, np.where(np.arange(12).reshape(4, 3) == 5, -1, t)),
        "triangle 1 uses vertex -1, out of range 0..3",
    ),
    "out_of_range": (
        lambda v, t: (v, np.where(np.arange(12).reshape(4, 3) == 9, 7, t)),
        "triangle 3 uses vertex 7, out of range 0..3",
    ),
}


def broken_ply(tmp_path, kind):
    v, t = BROKEN[kind][0](TETRA, FACES)
    return ascii_ply(tmp_path / f"{kind}.ply", v.tolist(), t)


@pytest.mark.parametrize("kind", list(BROKEN))
@pytest.mark.parametrize("command", ["validate", "stats", "conditions", "view", "truth"])
def test_every_mesh_input_refuses_non_finite_vertices_and_bad_indices(
    tmp_path, capsys, kind, command
):
    # validate on an inf vertex once segfaulted; on a NaN vertex said "valid";
    # -1 or out-of-range indices gave tracebacks; conditions on an inf truth hung
    bad = broken_ply(tmp_path, kind)
    good = write_mesh(tmp_path / "good.ply", TETRA, FACES)
    argv = {
        "validate": ["validate", str(bad)],
        "stats": ["stats", str(bad)],
        "conditions": ["conditions", str(good), "--truth", str(bad), "-q"],
        "view": ["view", str(bad), "--screenshot", str(tmp_path / "x.png")],
        "truth": ["validate", str(good), "--truth", str(bad)],
    }[command]
    code, msg = error_line(argv, capsys)
    assert code == 2
    assert msg == f"sr33: error: {bad}: {BROKEN[kind][1]}"
    assert not (tmp_path / "x.png").exists()


@pytest.mark.parametrize("kind", list(BROKEN))
def test_mesh_functions_refuse_what_the_files_refuse(kind):
    v, t = BROKEN[kind][0](TETRA, FACES)
    with pytest.raises(ValueError, match=r"^mesh: " + BROKEN[kind][1][:20].replace("(", r"\(")):
        as_mesh(v, t)
    with pytest.raises(ValueError, match="^mesh: "):
        self_intersections(v, t)
    with pytest.raises(ValueError, match="^mesh: "):
        surface_points(v, t, 10)


def test_the_validators_refuse_a_non_finite_truth_at_once():
    pytest.importorskip("potpourri3d")
    from sr33.validators.conditions import sample_conditions
    from sr33.validators.fidelity import hausdorff

    v = TETRA.copy()
    v[3, 2] = np.inf
    with pytest.raises(ValueError, match=r"^truth: 1 of 4 vertices have non-finite"):
        sample_conditions(TETRA * 0.5, v, FACES)
    with pytest.raises(ValueError, match=r"^mesh: 1 of 4 vertices have non-finite"):
        hausdorff(TETRA, FACES, v, FACES)


# --- item 7: a full disk ------------------------------------------------------


@pytest.mark.skipif(sys.platform == "win32", reason="needs RLIMIT_FSIZE")
def test_a_full_disk_is_a_write_error_in_every_format_and_leaves_nothing(tmp_path):
    # writing .vtp on a full disk once crashed the process (VTK's file writer,
    # SIGSEGV) and left its temporary file; a file-size limit fails writes
    # the way a full disk does (EFBIG instead of ENOSPC)
    pytest.importorskip("pyvista")
    code = textwrap.dedent(
        f"""
        import resource, signal
        import numpy as np
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
        resource.setrlimit(resource.RLIMIT_FSIZE, (4096, 4096))
        from sr33.io import WriteError, write_mesh, write_points
        rng = np.random.default_rng(0)
        v, t = rng.random((5000, 3)), rng.integers(0, 5000, (9000, 3))
        jobs = [(write_mesh, e, (v, t)) for e in ("vtp", "ply", "obj", "stl", "off")]
        jobs += [(write_points, e, (v,)) for e in ("vtp", "ply", "xyz", "npy", "obj")]
        for fn, ext, args in jobs:
            try:
                fn({str(tmp_path)!r} + "/out." + ext, *args)
                print(ext, "written")
            except WriteError as exc:
                print(ext, "cannot write" in str(exc))
        """
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr[-2000:]
    assert [line.split()[1] for line in out.stdout.splitlines()] == ["True"] * 10, out.stdout
    assert list(tmp_path.iterdir()) == []
