"""Reading samples and meshes, writing meshes atomically.

Point lists: ``.xyz``/``.txt`` (whitespace or comma separated, first three
columns), ``.npy`` ((n, 3) array), ``.obj`` (``v`` lines; faces ignored).
Meshes: ``.ply`` and ``.stl`` through meshio (PLY element counts checked
against the header), ``.obj`` and ``.off`` by own readers, ``.vtp``
through PyVista (optional extra ``vtk``); as inputs their vertices are the
samples.  Every failure becomes :class:`ReadError` / :class:`WriteError`
with the path and the reason; outputs go to a temporary file in the target
directory that is renamed into place, so a failed write leaves nothing.
"""

from __future__ import annotations

import io
import os
import tempfile
import warnings
from collections.abc import Iterator
from contextlib import contextmanager, redirect_stderr, redirect_stdout
from pathlib import Path

import numpy as np

from ._validate import InputError
from .mesh import as_mesh

POINT_LISTS = (".xyz", ".txt", ".npy")
MESH_FORMATS = (".ply", ".obj", ".off", ".stl", ".vtp")


class ReadError(InputError):
    """An input file could not be read."""


class WriteError(InputError):
    """An output file could not be written."""


def _read_obj(path: Path) -> tuple[np.ndarray, np.ndarray]:
    verts: list[list[float]] = []
    faces: list[list[int]] = []
    # utf-8-sig: a byte-order mark (Windows editors write one) is not part
    # of the first line
    with open(path, encoding="utf-8-sig", errors="strict") as fh:
        for lineno, line in enumerate(fh, 1):
            parts = line.split()
            if not parts:
                continue
            if parts[0] == "v":
                if len(parts) < 4:
                    raise ReadError(f"{path}: line {lineno}: vertex needs 3 coordinates")
                try:
                    verts.append([float(parts[1]), float(parts[2]), float(parts[3])])
                except ValueError:
                    raise ReadError(f"{path}: line {lineno}: bad vertex coordinates") from None
            elif parts[0] == "f" and len(parts) >= 4:
                try:
                    idx = [int(p.split("/")[0]) for p in parts[1:]]
                except ValueError:
                    raise ReadError(f"{path}: line {lineno}: bad face indices") from None
                idx = [i - 1 if i > 0 else len(verts) + i for i in idx]
                for j in range(1, len(idx) - 1):
                    faces.append([idx[0], idx[j], idx[j + 1]])
    v = np.array(verts, dtype=np.float64).reshape(-1, 3)
    f = np.array(faces, dtype=np.int64).reshape(-1, 3)
    if f.size and (f.min() < 0 or f.max() >= v.shape[0]):
        raise ReadError(f"{path}: face indices out of range")
    return v, f


def _read_off(path: Path) -> tuple[np.ndarray, np.ndarray]:
    """OFF (optionally ``COFF``/``NOFF``...: extra per-vertex values ignored):
    the counts line is checked against the vertex and face lines present."""
    with open(path, encoding="utf-8-sig", errors="strict") as fh:
        lines = [(i, ln.split("#", 1)[0].split()) for i, ln in enumerate(fh, 1)]
    lines = [(i, parts) for i, parts in lines if parts]
    if not lines or not lines[0][1][0].endswith("OFF"):
        raise ReadError(f"{path}: not an OFF file (the first line must be OFF)")
    head = lines[0][1][1:]
    rest = lines[1:]
    if not head:
        if not rest:
            raise ReadError(f"{path}: OFF file has no counts line")
        head, rest = rest[0][1], rest[1:]
    try:
        nv, nf = int(head[0]), int(head[1])
    except (ValueError, IndexError):
        raise ReadError(f"{path}: OFF counts line must hold the vertex and face counts") from None
    if nv < 0 or nf < 0:
        raise ReadError(f"{path}: OFF counts must not be negative, got {nv} {nf}")
    if len(rest) < nv + nf:
        raise ReadError(
            f"{path}: truncated OFF: it declares {nv} vertices and {nf} faces, "
            f"the file holds {len(rest)} data lines"
        )
    verts = np.empty((nv, 3), dtype=np.float64)
    for row, (lineno, parts) in enumerate(rest[:nv]):
        try:
            verts[row] = [float(x) for x in parts[:3]]
        except ValueError:
            raise ReadError(f"{path}: line {lineno}: bad vertex coordinates") from None
    faces: list[list[int]] = []
    for lineno, parts in rest[nv : nv + nf]:
        try:
            m = int(parts[0])
            idx = [int(x) for x in parts[1 : 1 + m]]
        except ValueError:
            raise ReadError(f"{path}: line {lineno}: bad face indices") from None
        if m < 3 or len(idx) != m:
            raise ReadError(f"{path}: line {lineno}: a face needs at least 3 vertex indices")
        faces.extend([idx[0], idx[j], idx[j + 1]] for j in range(1, m - 1))
    return verts, np.array(faces, dtype=np.int64).reshape(-1, 3)


def _read_text_points(path: Path) -> np.ndarray:
    rows = []
    with open(path, encoding="utf-8-sig") as fh:
        for lineno, line in enumerate(fh, 1):
            s = line.strip()
            if not s or s.startswith("#"):
                continue
            parts = s.replace(",", " ").split()
            if len(parts) < 3:
                raise ReadError(f"{path}: line {lineno}: expected 3 coordinates, got {len(parts)}")
            try:
                rows.append([float(parts[0]), float(parts[1]), float(parts[2])])
            except ValueError:
                raise ReadError(f"{path}: line {lineno}: coordinates are not numbers") from None
    return np.array(rows, dtype=np.float64).reshape(-1, 3)


def read_mesh(path) -> tuple[np.ndarray, np.ndarray]:
    """Read ``(vertices, triangles)`` from a mesh or point file.

    Point lists give an empty (0, 3) triangle array.  Polygons are fanned
    into triangles.
    """
    p = Path(path)
    ext = p.suffix.lower()
    if ext not in POINT_LISTS + MESH_FORMATS:
        raise ReadError(
            f"{p}: unsupported format {ext or '(none)'}; "
            f"use one of {', '.join(POINT_LISTS + MESH_FORMATS)}"
        )
    if not p.exists():
        raise ReadError(f"{p}: no such file")
    if p.is_dir():
        raise ReadError(f"{p}: is a directory")
    if p.stat().st_size == 0:
        raise ReadError(f"{p}: file is empty")
    empty_tri = np.empty((0, 3), dtype=np.int64)
    try:
        if ext == ".obj":
            v, f = _read_obj(p)
        elif ext == ".off":
            v, f = _read_off(p)
        elif ext in (".xyz", ".txt"):
            v, f = _read_text_points(p), empty_tri
        elif ext == ".npy":
            arr = np.load(p, allow_pickle=False)
            if arr.ndim != 2 or arr.shape[1] != 3:
                raise ReadError(f"{p}: array must have shape (n, 3), got {arr.shape}")
            v, f = arr.astype(np.float64), empty_tri
        elif ext == ".vtp":
            v, f = _read_vtp(p)
        else:
            import meshio

            declared = _ply_counts(p) if ext == ".ply" else None
            with (
                warnings.catch_warnings(),
                redirect_stdout(io.StringIO()),
                redirect_stderr(io.StringIO()),
            ):
                # meshio's STL reader overflows a uint32 size check (harmless)
                warnings.simplefilter("ignore", RuntimeWarning)
                try:
                    m = meshio.read(p, file_format=ext[1:])
                except SystemExit:  # some meshio readers exit on a bad file
                    raise ReadError(f"{p}: not a valid {ext} file") from None
            v = np.asarray(m.points, dtype=np.float64)
            if v.ndim != 2 or v.shape[1] < 3:
                raise ReadError(f"{p}: vertices must be 3D")
            v = v[:, :3]
            tris = [np.asarray(c.data) for c in m.cells if c.type == "triangle"]
            for c in m.cells:
                if c.type in ("quad", "polygon") or c.type.startswith("polygon"):
                    d = np.asarray(c.data)
                    for j in range(1, d.shape[1] - 1):
                        tris.append(d[:, [0, j, j + 1]])
            f = np.concatenate(tris).astype(np.int64) if tris else empty_tri
            if declared is not None:
                polygons = sum(len(c.data) for c in m.cells if c.type not in ("vertex", "line"))
                _check_counts(p, declared, v.shape[0], polygons)
    except InputError:
        raise
    except UnicodeDecodeError:
        raise ReadError(f"{p}: not a text {ext} file (could not decode)") from None
    except Exception as exc:  # meshio/VTK raise many types; report them plainly
        msg = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
        raise ReadError(f"{p}: unreadable or truncated {ext} file ({msg})") from None
    if v.shape[0] == 0:
        raise ReadError(f"{p}: contains no points")
    try:
        return as_mesh(v, f, name=str(p), item="point" if ext in POINT_LISTS else "vertex")
    except ValueError as exc:
        raise ReadError(str(exc)) from None


_PLY_SIZES = {
    **dict.fromkeys(("char", "int8", "uchar", "uint8"), 1),
    **dict.fromkeys(("short", "int16", "ushort", "uint16"), 2),
    **dict.fromkeys(("int", "int32", "uint", "uint32", "float", "float32"), 4),
    **dict.fromkeys(("double", "float64", "int64", "uint64"), 8),
}


def _ply_counts(p: Path) -> dict[str, int]:
    """The element counts a PLY header declares, checked against the file's
    size before anything is read (a header that promises 10^12 vertices in a
    1 kB file is truncated, not a reason to allocate terabytes)."""
    with open(p, "rb") as fh:
        head = fh.read(1 << 16)
    if not head.startswith(b"ply"):
        raise ReadError(f"{p}: not a PLY file (it does not start with 'ply')")
    end = head.find(b"end_header")
    if end < 0:
        raise ReadError(f"{p}: PLY header has no end_header line (truncated or not PLY)")
    body = head.find(b"\n", end)
    body = len(head) if body < 0 else body + 1
    counts: dict[str, int] = {}
    min_bytes: dict[str, int] = {}
    fmt = ""
    current = None
    for line in head[:end].decode("ascii", errors="replace").splitlines():
        parts = line.split()
        if len(parts) >= 2 and parts[0] == "format":
            fmt = parts[1]
        elif len(parts) == 3 and parts[0] == "element":
            try:
                counts[parts[1]] = int(parts[2])
            except ValueError:
                raise ReadError(f"{p}: PLY element {parts[1]} has count {parts[2]!r}") from None
            if counts[parts[1]] < 0:
                raise ReadError(f"{p}: PLY element {parts[1]} has a negative count")
            current = parts[1]
            min_bytes[current] = 0
        elif current is not None and len(parts) >= 3 and parts[0] == "property":
            # a list needs at least its count; a scalar exactly its size
            size = _PLY_SIZES.get(parts[2] if parts[1] == "list" else parts[1], 1)
            min_bytes[current] += size
    size = p.stat().st_size - body
    if fmt.startswith("binary"):
        need = sum(counts[e] * min_bytes[e] for e in counts)
        if size < need:
            raise ReadError(
                f"{p}: truncated PLY: its header declares {_declared(counts)}, "
                f"which needs at least {need} bytes of data, the file holds {size}"
            )
    else:
        with open(p, "rb") as fh:
            fh.seek(body)
            lines = sum(chunk.count(b"\n") for chunk in iter(lambda: fh.read(1 << 20), b""))
        # the last line may lack its newline
        if lines + 1 < sum(counts.values()):
            raise ReadError(
                f"{p}: truncated PLY: its header declares {_declared(counts)}, "
                f"the file holds {lines} data lines"
            )
    return counts


def _declared(counts: dict[str, int]) -> str:
    return " and ".join(f"{n} {e}" for e, n in counts.items()) + " elements"


def _check_counts(p: Path, declared: dict[str, int], vertices: int, faces: int) -> None:
    """Raise unless the vertices and faces read are the header's counts."""
    for what, got in (("vertex", vertices), ("face", faces)):
        want = declared.get(what, 0)
        if got != want:
            raise ReadError(
                f"{p}: truncated or inconsistent PLY: its header declares {want} "
                f"{what} elements, {got} were read"
            )


def read_points(path) -> np.ndarray:
    """Read the samples of a point or mesh file as an (n, 3) float64 array."""
    return read_mesh(path)[0]


def _read_vtp(p: Path):
    try:
        import pyvista as pv
    except ImportError:
        raise ReadError(f"{p}: reading .vtp needs PyVista: pip install 'sr33[vtk]'") from None
    mesh = pv.read(p)
    v = np.asarray(mesh.points, dtype=np.float64)
    f = np.empty((0, 3), dtype=np.int64)
    if mesh.n_cells:
        tri = mesh.triangulate()
        faces = np.asarray(tri.faces).reshape(-1, 4)
        f = faces[:, 1:].astype(np.int64)
    return v, f


POINT_FORMATS = (".ply", ".xyz", ".txt", ".npy", ".obj", ".vtp")
TEXT_FORMATS = (".json", ".txt")


def check_output(path, formats: tuple[str, ...], what: str) -> Path:
    """Raise :class:`WriteError` unless ``path`` can be written as one of
    ``formats`` (extension, existing writable directory, not a directory).

    Called before any long computation, so that a bad output path fails in
    a second, not after the work (and by :func:`atomic_output` itself).
    """
    p = Path(path)
    ext = p.suffix.lower()
    if ext not in formats:
        raise WriteError(
            f"{p}: unsupported {what} format {ext or '(none)'}; use one of {', '.join(formats)}"
        )
    parent = p.parent if str(p.parent) else Path(".")
    if not parent.is_dir():
        raise WriteError(f"{p}: directory {parent} does not exist")
    if p.is_dir():
        raise WriteError(f"{p}: is a directory")
    if not os.access(parent, os.W_OK | os.X_OK):
        raise WriteError(f"{p}: directory {parent} is not writable")
    return p


@contextmanager
def atomic_output(path, formats: tuple[str, ...], what: str) -> Iterator[tuple[str, str]]:
    """Yield ``(temporary path, extension)`` in the target's directory; on
    success rename it over ``path``, on any failure (or a signal turned into
    ``SystemExit`` by the command line) remove it."""
    p = check_output(path, formats, what)
    ext = p.suffix.lower()
    parent = p.parent if str(p.parent) else Path(".")
    try:
        fd, tmp = tempfile.mkstemp(prefix=f".{p.stem}.", suffix=ext, dir=parent)
    except OSError as exc:
        raise WriteError(f"{p}: cannot write ({exc.strerror})") from None
    os.close(fd)
    umask = os.umask(0)
    os.umask(umask)
    os.chmod(tmp, 0o666 & ~umask)
    try:
        yield tmp, ext
        os.replace(tmp, p)
    except WriteError:
        _unlink(tmp)
        raise
    except OSError as exc:
        _unlink(tmp)
        raise WriteError(f"{p}: cannot write ({exc.strerror or exc})") from None
    except BaseException:
        _unlink(tmp)
        raise


def _pyvista(p):
    try:
        import pyvista as pv
    except ImportError:
        raise WriteError(f"{p}: writing .vtp needs PyVista: pip install 'sr33[vtk]'") from None
    return pv


def write_mesh(path, vertices: np.ndarray, triangles: np.ndarray) -> Path:
    """Write a triangle mesh atomically (temporary file, then rename).

    The format follows the extension: ``.ply``, ``.obj``, ``.off``, ``.stl``
    or ``.vtp``.  Same arrays give byte-identical files.
    """
    v = np.ascontiguousarray(vertices, dtype=np.float64)
    t = np.ascontiguousarray(triangles, dtype=np.int64)
    with atomic_output(path, MESH_FORMATS, "output") as (tmp, ext):
        if ext == ".vtp":
            faces = np.hstack([np.full((t.shape[0], 1), 3, dtype=np.int64), t]).ravel()
            _write_vtp(tmp, _pyvista(path).PolyData(v, faces))
        elif ext == ".obj":
            with open(tmp, "w", encoding="ascii") as fh:
                fh.write("# written by sr33\n")
                np.savetxt(fh, v, fmt="v %.17g %.17g %.17g")
                np.savetxt(fh, t + 1, fmt="f %d %d %d")
        elif ext == ".ply":
            _write_ply(tmp, v, t)
        elif ext == ".off":
            with open(tmp, "w", encoding="ascii") as fh:
                fh.write(f"OFF\n{v.shape[0]} {t.shape[0]} 0\n")
                np.savetxt(fh, v, fmt="%.17g %.17g %.17g")
                np.savetxt(fh, t, fmt="3 %d %d %d")
        else:
            import meshio

            meshio.write_points_cells(tmp, v, [("triangle", t.astype(np.int32))], file_format="stl")
    return Path(path)


def write_points(path, points: np.ndarray, fields: dict[str, np.ndarray] | None = None) -> Path:
    """Write a point list atomically: ``.ply``, ``.xyz``, ``.txt``, ``.npy``, ``.obj``, ``.vtp``.

    ``fields`` (integer arrays, one value per point, e.g. scan-line ids) are
    stored as extra vertex properties in PLY and VTP and ignored elsewhere.
    """
    v = np.ascontiguousarray(points, dtype=np.float64)
    fields = {k: np.asarray(a, dtype=np.int32) for k, a in (fields or {}).items()}
    with atomic_output(path, POINT_FORMATS, "point") as (tmp, ext):
        if ext == ".ply":
            _write_ply(tmp, v, None, fields)
        elif ext in (".xyz", ".txt"):
            np.savetxt(tmp, v, fmt="%.17g %.17g %.17g")
        elif ext == ".npy":
            with open(tmp, "wb") as fh:
                np.save(fh, v)
        elif ext == ".obj":
            with open(tmp, "w", encoding="ascii") as fh:
                fh.write("# written by sr33\n")
                np.savetxt(fh, v, fmt="v %.17g %.17g %.17g")
        else:
            cloud = _pyvista(path).PolyData(v)
            for k, a in fields.items():
                cloud.point_data[k] = a
            _write_vtp(tmp, cloud)
    return Path(path)


def _write_vtp(tmp: str, poly) -> None:
    """VTK XML PolyData (binary, base64), serialised by VTK in memory and
    written by Python: VTK's own file writer crashes the process (SIGSEGV)
    when the disk fills up, where Python raises ``OSError``."""
    from vtkmodules.vtkIOXML import vtkXMLPolyDataWriter

    w = vtkXMLPolyDataWriter()
    w.SetInputData(poly)
    w.SetDataModeToBinary()
    w.WriteToOutputStringOn()
    if not w.Write():
        raise WriteError(f"{tmp}: VTK could not serialise the mesh")
    with open(tmp, "w", encoding="ascii") as fh:
        fh.write(w.GetOutputString())


def write_text(path, text: str) -> Path:
    """Write a JSON or text file atomically."""
    with atomic_output(path, TEXT_FORMATS, "text") as (tmp, _):
        with open(tmp, "w", encoding="utf-8") as fh:
            fh.write(text)
    return Path(path)


def _write_ply(path: str, v: np.ndarray, t: np.ndarray | None, fields=None) -> None:
    """Binary little-endian PLY, no timestamp (meshio's writer adds one)."""
    fields = fields or {}
    header = "ply\nformat binary_little_endian 1.0\ncomment written by sr33\n"
    header += f"element vertex {v.shape[0]}\n"
    header += "property double x\nproperty double y\nproperty double z\n"
    header += "".join(f"property int {k}\n" for k in fields)
    if t is not None:
        header += f"element face {t.shape[0]}\nproperty list uchar int vertex_indices\n"
    header += "end_header\n"
    vdt = [("xyz", "<f8", (3,))] + [(k, "<i4") for k in fields]
    verts = np.empty(v.shape[0], dtype=vdt)
    verts["xyz"] = v
    for k, a in fields.items():
        verts[k] = a
    with open(path, "wb") as fh:
        fh.write(header.encode("ascii"))
        fh.write(verts.tobytes())
        if t is not None:
            faces = np.empty(t.shape[0], dtype=[("n", "u1"), ("idx", "<i4", (3,))])
            faces["n"] = 3
            faces["idx"] = t
            fh.write(faces.tobytes())


def _unlink(path: str) -> None:
    try:
        os.unlink(path)
    except OSError:
        pass


def save_reconstruction(path, rec) -> Path:
    """Write a :class:`sr33.Reconstruction` to one ``.npz`` file, atomically.

    Everything round-trips: vertices, triangles, the RNG edges, the face
    cycles, the status arrays, the timings and k (see
    :func:`load_reconstruction`).
    """
    arrays = {
        "vertices": rec.vertices,
        "triangles": rec.triangles,
        "input_to_vertex": rec.input_to_vertex,
        "rng_edges": rec.rng_edges,
        "face_offsets": rec.face_cycles.offsets,
        "face_vertices": rec.face_cycles.vertices,
        "open_edges": np.asarray(rec.open_edges, dtype=np.int64).reshape(-1, 2),
        "unresolved_samples": rec.unresolved_samples,
        "non_disk_neighbourhoods": rec.non_disk_neighbourhoods,
        "coned_samples": rec.coned_samples,
        "scalars": np.array(
            [
                rec.duplicates_merged,
                rec.candidate_cycles,
                int(rec.success),
                int(rec.orientable),
                rec.fallback_components,
                rec.k,
                rec.hole_faces,
                *rec.exact.as_tuple(),
            ],
            dtype=np.int64,
        ),
        "timing_names": np.array(list(rec.timings), dtype=str),
        "timing_values": np.array(list(rec.timings.values()), dtype=np.float64),
    }
    with atomic_output(path, (".npz",), "reconstruction") as (tmp, _):
        with open(tmp, "wb") as fh:
            np.savez(fh, sr33_reconstruction=np.array(1), **arrays)
    return Path(path)


def load_reconstruction(path):
    """Read a reconstruction written by :func:`save_reconstruction`."""
    from .cycles import CycleSet
    from .reconstruct import Reconstruction
    from .selection import ExactReport

    p = Path(path)
    if not p.exists():
        raise ReadError(f"{p}: no such file")
    try:
        with np.load(p, allow_pickle=False) as z:
            if "sr33_reconstruction" not in z:
                raise ReadError(f"{p}: not an sr33 reconstruction (.npz without its marker)")
            s = z["scalars"]
            return Reconstruction(
                vertices=z["vertices"],
                triangles=z["triangles"],
                input_to_vertex=z["input_to_vertex"],
                duplicates_merged=int(s[0]),
                rng_edges=z["rng_edges"],
                candidate_cycles=int(s[1]),
                face_cycles=CycleSet(z["face_offsets"], z["face_vertices"]),
                success=bool(s[2]),
                orientable=bool(s[3]),
                open_edges=z["open_edges"],
                unresolved_samples=z["unresolved_samples"],
                non_disk_neighbourhoods=z["non_disk_neighbourhoods"],
                coned_samples=z["coned_samples"],
                fallback_components=int(s[4]),
                # files of earlier versions end after k
                hole_faces=int(s[6]) if s.shape[0] > 6 else 0,
                # files of earlier versions have 4 exact-selection figures, or none
                exact=ExactReport(*(int(x) for x in s[7:12])),
                timings=dict(zip(z["timing_names"].tolist(), z["timing_values"].tolist())),
                k=int(s[5]),
            )
    except InputError:
        raise
    except Exception as exc:
        raise ReadError(f"{p}: unreadable reconstruction ({type(exc).__name__}: {exc})") from None
