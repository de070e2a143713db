"""Reading samples and meshes, writing meshes atomically.

Point lists: ``.xyz``/``.txt`` (whitespace or comma separated, first three
columns), ``.npy`` ((n, 3) array), ``.obj`` (``v`` lines; faces ignored).
Meshes: ``.ply``, ``.off``, ``.stl``, ``.obj`` through meshio, ``.vtp``
through PyVista (optional extra ``vtk``); as inputs their vertices are the
samples.  Every failure becomes :class:`ReadError` / :class:`WriteError`
with the path and the reason; outputs go to a temporary file in the target
directory that is renamed into place, so a failed write leaves nothing.
"""

from __future__ import annotations

import os
import tempfile
import warnings
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import numpy as np

from ._validate import InputError

POINT_FORMATS = (".xyz", ".txt", ".npy")
MESH_FORMATS = (".ply", ".obj", ".off", ".stl", ".vtp")


class ReadError(InputError):
    """An input file could not be read."""


class WriteError(InputError):
    """An output file could not be written."""


def _read_obj(path: Path) -> tuple[np.ndarray, np.ndarray]:
    verts: list[list[float]] = []
    faces: list[list[int]] = []
    with open(path, encoding="utf-8", errors="strict") as fh:
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


def _read_text_points(path: Path) -> np.ndarray:
    rows = []
    with open(path, encoding="utf-8") as fh:
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
    if ext not in POINT_FORMATS + MESH_FORMATS:
        raise ReadError(
            f"{p}: unsupported format {ext or '(none)'}; "
            f"use one of {', '.join(POINT_FORMATS + MESH_FORMATS)}"
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

            with warnings.catch_warnings():
                # meshio's STL reader overflows a uint32 size check (harmless)
                warnings.simplefilter("ignore", RuntimeWarning)
                m = meshio.read(p)
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
    except InputError:
        raise
    except UnicodeDecodeError:
        raise ReadError(f"{p}: not a text {ext} file (could not decode)") from None
    except Exception as exc:  # meshio/VTK raise many types; report them plainly
        msg = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
        raise ReadError(f"{p}: unreadable or truncated {ext} file ({msg})") from None
    if v.shape[0] == 0:
        raise ReadError(f"{p}: contains no points")
    return v, f


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
            _pyvista(path).PolyData(v, faces).save(tmp, binary=True)
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
            cloud.save(tmp, binary=True)
    return Path(path)


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
                timings=dict(zip(z["timing_names"].tolist(), z["timing_values"].tolist())),
                k=int(s[5]),
            )
    except InputError:
        raise
    except Exception as exc:
        raise ReadError(f"{p}: unreadable reconstruction ({type(exc).__name__}: {exc})") from None
