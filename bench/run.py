"""Benchmark of the reconstruction (``make bench``).

What is measured
----------------
Data sets: every ``<data>/paper/large/*.obj`` (the paper's sharp-feature sets:
L, cone, conebox, cube, cutcube) and every ``<data>/meshes/*.obj`` (real
models whose vertices are used as the samples: spot, cheburashka; their own
faces are read only to report the ground truth's topology).

For each set, ``sr33.reconstruct(points, k)`` (k = 33 unless ``--k``) is run
once untimed (numba loads or compiles its kernels), then ``--repeats`` times
(default 3).  Reported are the median seconds of every step of
``Reconstruction.timings`` and the median wall time of the whole call
(``time.perf_counter`` around it).  The self-checks of ``sr33.selfcheck``
are switched off (``strict=False``) whatever ``SR33_STRICT`` says, so that
the production path is timed.

The floor is what any k-neighbourhood method has to do at least: the median,
over the same number of repeats, of building ``scipy.spatial.cKDTree`` on
the same points and querying the k + 1 nearest neighbours of every point.
The figure of merit is ratio = median total / median floor.

Targets (2-core reference machine): cube (6144 points, k = 33) under 1 s,
ratio at most 50 on every set.  They are checked and printed, but a missed
target does not change the exit status (only a crash of sr33 does).

Topology of every output comes from ``sr33.validators.mesh_stats``: open edges
(used by one triangle), overloaded edges (by three or more), Euler
characteristic and connected components, next to ``Reconstruction.success``.

Comparison (``--compare``; automatic when the packages are importable,
``--no-compare`` to skip): the same points, in the same process, are given to

- Open3D ball pivoting: normals from the 30 nearest neighbours, oriented with
  ``orient_normals_consistent_tangent_plane(30)`` (or, if one orientation
  takes longer than ``--orient-budget`` seconds, away from the centroid),
  radii 1, 1.5 and 2 times the mean nearest-neighbour distance;
- Open3D screened Poisson, depth 8, on the same oriented normals (its
  vertices are new points of an implicit surface, not the samples);
- CGAL advancing front (``cgal`` bindings, default parameters).

Their seconds (median of the repeats) include what each needs beyond the
points: normal estimation and orientation for Open3D, filling the CGAL point
set for CGAL.  A competitor that is missing or fails is reported in one line
and the benchmark goes on.

Results are printed as fixed-width tables and written as JSON (atomically:
temporary file in the same directory, then ``os.replace``) to ``--out``.
"""

from __future__ import annotations

import argparse
import importlib
import importlib.util
import json
import os
import platform
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable, Sequence
from datetime import datetime, timezone
from pathlib import Path
from typing import Any

import numpy as np
from scipy.spatial import cKDTree

ROOT = Path(__file__).resolve().parents[1]

import sr33  # noqa: E402
from sr33.io import read_mesh, read_points  # noqa: E402
from sr33.validators import mesh_stats  # noqa: E402

# every step reported by Reconstruction.timings, in pipeline order
STEPS = (
    "prepare",
    "localized_rng",
    "isometric_cycles",
    "backtracking",
    "triangulate",
    "cones",
)
# (column title, timings key) of the first table
STEP_COLUMNS = (
    ("rng", "localized_rng"),
    ("cycles", "isometric_cycles"),
    ("backtr", "backtracking"),
    ("triang", "triangulate"),
    ("cones", "cones"),
)
CUBE_TARGET_SECONDS = 1.0
RATIO_TARGET = 50.0
NORMAL_KNN = 30
BPA_RADIUS_FACTORS = (1.0, 1.5, 2.0)
POISSON_DEPTH = 8

Record = dict[str, Any]


def note(message: str) -> None:
    """A one-line note on stderr (progress, a missing or failing competitor)."""
    sys.stdout.flush()
    print(f"bench: {message}", file=sys.stderr, flush=True)


def one_line(exc: BaseException) -> str:
    text = str(exc).strip().splitlines()
    return f"{type(exc).__name__}: {text[0]}" if text else type(exc).__name__


def median(values: Sequence[float]) -> float:
    return float(statistics.median(values))


def find_sets(data: Path, only: Sequence[str]) -> list[tuple[str, str, Path]]:
    """``(name, kind, path)`` of the paper's large sets, then of the meshes."""
    found = [(p.stem, "paper", p) for p in sorted((data / "paper" / "large").glob("*.obj"))]
    found += [(p.stem, "mesh", p) for p in sorted((data / "meshes").glob("*.obj"))]
    if only:
        found = [s for s in found if s[0] in only]
    return found


def stats_dict(triangles: np.ndarray, n_points: int) -> dict[str, int]:
    return mesh_stats(np.asarray(triangles, dtype=np.int64).reshape(-1, 3), n_points).as_dict()


# ----------------------------------------------------------------- sr33 and floor


def knn_floor(points: np.ndarray, k: int, repeats: int) -> list[float]:
    """Seconds of ``repeats`` cKDTree builds + (k + 1)-NN queries, after one warm-up."""
    kk = min(k + 1, points.shape[0])
    cKDTree(points).query(points, kk)
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        cKDTree(points).query(points, kk)
        times.append(time.perf_counter() - t0)
    return times


def bench_sr33(points: np.ndarray, k: int, repeats: int) -> Record:
    """Median step and total seconds of ``repeats`` reconstructions, and their topology."""
    sr33.reconstruct(points, k, quiet=True, strict=False)  # warm-up: numba JIT / cache load
    totals: list[float] = []
    runs: list[dict[str, float]] = []
    results: list[sr33.Reconstruction] = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        r = sr33.reconstruct(points, k, quiet=True, strict=False)
        totals.append(time.perf_counter() - t0)
        runs.append(dict(r.timings))
        results.append(r)
    r = results[-1]
    keys = list(STEPS) + sorted({key for t in runs for key in t} - set(STEPS))
    floor = knn_floor(points, k, repeats)
    total, floor_med = median(totals), median(floor)
    first = results[0]
    return {
        "points": int(points.shape[0]),
        "k": int(r.k),
        "seconds": {key: median([t.get(key, 0.0) for t in runs]) for key in keys},
        "total": total,
        "total_runs": totals,
        "floor": floor_med,
        "floor_runs": floor,
        "ratio": total / floor_med if floor_med > 0 else None,
        "success": bool(r.success),
        "orientable": bool(r.orientable),
        "fallback_components": int(r.fallback_components),
        "unresolved_samples": int(r.unresolved_samples.shape[0]),
        "coned_samples": int(r.coned_samples.shape[0]),
        "duplicates_merged": int(r.duplicates_merged),
        "candidate_cycles": int(r.candidate_cycles),
        "repeats_identical": all(np.array_equal(x.triangles, first.triangles) for x in results[1:]),
        "stats": stats_dict(r.triangles, r.vertices.shape[0]),
    }


# -------------------------------------------------------------------- competitors


def _mean_spacing(points: np.ndarray) -> float:
    return float(cKDTree(points).query(points, 2)[0][:, 1].mean())


def _method_record(
    method: str,
    parts: dict[str, list[float]],
    stats: list[dict[str, int]],
    **extra: Any,
) -> Record:
    per_run = [sum(vals) for vals in zip(*parts.values())]
    return {
        "method": method,
        "seconds": median(per_run),
        "seconds_runs": per_run,
        "parts": {name: median(vals) for name, vals in parts.items()},
        "stats": stats[-1],
        "repeats_identical": all(s == stats[0] for s in stats[1:]),
        **extra,
    }


def bench_open3d(points: np.ndarray, repeats: int, orient_budget: float) -> list[Record]:
    """Open3D ball pivoting and screened Poisson on the same oriented normals."""
    import open3d as o3d

    o3d.utility.set_verbosity_level(o3d.utility.VerbosityLevel.Error)
    n = points.shape[0]
    spacing = _mean_spacing(points)
    radii = [f * spacing for f in BPA_RADIUS_FACTORS]
    base = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(points))
    centroid = points.mean(axis=0)

    # untimed probe (also a warm-up): is the consistent orientation fast enough?
    probe = o3d.geometry.PointCloud(base)
    probe.estimate_normals(o3d.geometry.KDTreeSearchParamKNN(NORMAL_KNN))
    t0 = time.perf_counter()
    probe.orient_normals_consistent_tangent_plane(NORMAL_KNN)
    probe_seconds = time.perf_counter() - t0
    consistent = probe_seconds <= orient_budget
    orientation = (
        f"consistent tangent plane ({NORMAL_KNN})" if consistent else "away from the centroid"
    )
    if not consistent:
        note(f"open3d: orientation took {probe_seconds:.1f} s; orienting away from the centroid")

    def oriented_cloud() -> tuple[Any, float, float]:
        pcd = o3d.geometry.PointCloud(base)
        t0 = time.perf_counter()
        pcd.estimate_normals(o3d.geometry.KDTreeSearchParamKNN(NORMAL_KNN))
        t1 = time.perf_counter()
        if consistent:
            pcd.orient_normals_consistent_tangent_plane(NORMAL_KNN)
        else:
            pcd.orient_normals_towards_camera_location(centroid)
            pcd.normals = o3d.utility.Vector3dVector(-np.asarray(pcd.normals))
        t2 = time.perf_counter()
        return pcd, t1 - t0, t2 - t1

    def ball_pivoting(pcd: Any) -> tuple[np.ndarray, int]:
        mesh = o3d.geometry.TriangleMesh.create_from_point_cloud_ball_pivoting(
            pcd, o3d.utility.DoubleVector(radii)
        )
        return np.asarray(mesh.triangles, dtype=np.int64), len(mesh.vertices)

    def poisson(pcd: Any) -> tuple[np.ndarray, int]:
        mesh, _densities = o3d.geometry.TriangleMesh.create_from_point_cloud_poisson(
            pcd, depth=POISSON_DEPTH
        )
        return np.asarray(mesh.triangles, dtype=np.int64), len(mesh.vertices)

    methods: dict[str, Callable[[Any], tuple[np.ndarray, int]]] = {
        "open3d ball pivoting": ball_pivoting,
        f"open3d poisson d{POISSON_DEPTH}": poisson,
    }
    parts: dict[str, dict[str, list[float]]] = {
        m: {"normals": [], "orient": [], "method": []} for m in methods
    }
    stats: dict[str, list[dict[str, int]]] = {m: [] for m in methods}
    vertices: dict[str, int] = {}
    errors: dict[str, str] = {}
    for _ in range(repeats):
        pcd, t_normals, t_orient = oriented_cloud()
        for name, fn in methods.items():
            if name in errors:
                continue
            try:
                t0 = time.perf_counter()
                tri, nv = fn(pcd)
                t_method = time.perf_counter() - t0
                stats[name].append(stats_dict(tri, nv))
            except Exception as exc:  # a failing competitor must not stop the benchmark
                errors[name] = one_line(exc)
                continue
            parts[name]["normals"].append(t_normals)
            parts[name]["orient"].append(t_orient)
            parts[name]["method"].append(t_method)
            vertices[name] = nv
    out: list[Record] = []
    for name in methods:
        if name in errors:
            out.append({"method": name, "error": errors[name]})
            continue
        extra: dict[str, Any] = {"orientation": orientation, "normal_knn": NORMAL_KNN}
        if name == "open3d ball pivoting":
            extra.update(radii=radii, mean_spacing=spacing)
            if vertices[name] != n:
                extra["note"] = f"output has {vertices[name]} vertices for {n} samples"
        else:
            extra.update(depth=POISSON_DEPTH, own_vertices=vertices[name])
            extra["note"] = "vertices are Poisson's own (an implicit surface), not the samples"
        out.append(_method_record(name, parts[name], stats[name], **extra))
    return out


def bench_cgal(points: np.ndarray, repeats: int, orient_budget: float) -> list[Record]:
    """CGAL advancing front surface reconstruction (default parameters)."""
    from CGAL.CGAL_Advancing_front_surface_reconstruction import (
        advancing_front_surface_reconstruction,
    )
    from CGAL.CGAL_Point_set_3 import Point_set_3

    name = "cgal advancing front"
    n = points.shape[0]
    flat = np.ascontiguousarray(points, dtype=np.float64).ravel().tolist()
    fill: list[float] = []
    run: list[float] = []
    stats: list[dict[str, int]] = []
    try:
        for _ in range(repeats):
            t0 = time.perf_counter()
            ps = Point_set_3()
            ps.insert_range(flat)  # flat x, y, z list, kept in order
            t1 = time.perf_counter()
            if ps.size() != n:
                raise RuntimeError(f"point set holds {ps.size()} points, expected {n}")
            ids: list[int] = []  # the overload with an output list gives sample indices
            advancing_front_surface_reconstruction(ps, ids)
            t2 = time.perf_counter()
            fill.append(t1 - t0)
            run.append(t2 - t1)
            stats.append(stats_dict(np.asarray(ids, dtype=np.int64), n))
    except Exception as exc:  # a failing competitor must not stop the benchmark
        return [{"method": name, "error": one_line(exc)}]
    return [
        _method_record(
            name,
            {"point_set": fill, "method": run},
            stats,
            radius_ratio_bound=5.0,
            beta=0.52,
        )
    ]


Competitor = Callable[[np.ndarray, int, float], list[Record]]
COMPETITORS: tuple[tuple[str, str, str, Competitor], ...] = (
    # (label, import name, pip name, runner)
    ("open3d", "open3d", "open3d", bench_open3d),
    ("CGAL", "CGAL", "cgal", bench_cgal),
)


def available_competitors(requested: bool | None) -> list[tuple[str, Competitor]]:
    """The competitors that import; notes for the missing ones when asked for."""
    if requested is False:
        return []
    out = []
    for label, module, pip_name, fn in COMPETITORS:
        if importlib.util.find_spec(module) is None:
            if requested:
                note(f"{label} not installed (pip install {pip_name}); skipped")
            continue
        try:
            importlib.import_module(module)
        except Exception as exc:  # e.g. open3d without its system library libusb
            note(f"{label} does not import ({one_line(exc)}); skipped")
            continue
        out.append((label, fn))
    return out


# -------------------------------------------------------------------------- output


def _row_stats(st: dict[str, int]) -> str:
    return (
        f"{st['used_vertices']:>7}{st['faces']:>7}{st['open_edges']:>6}"
        f"{st['overloaded_edges']:>6}{st['euler']:>7}{st['components']:>6}"
    )


def print_tables(sets: dict[str, Record]) -> None:
    head = (
        f"{'set':<12}{'points':>7}{'k':>5}"
        + "".join(f"{title:>8}" for title, _ in STEP_COLUMNS)
        + f"{'total':>8}{'floor ms':>9}{'ratio':>7}{'open':>6}{'over':>6}{'euler':>7}"
        f"{'comp':>6}  success"
    )
    print(head)
    print("-" * len(head))
    for name, rec in sets.items():
        if "error" in rec:
            print(f"{name:<12}{rec['points']:>7}{rec['k']:>5}  FAILED: {rec['error']}")
            continue
        sec, st = rec["seconds"], rec["stats"]
        print(
            f"{name:<12}{rec['points']:>7}{rec['k']:>5}"
            + "".join(f"{sec[key]:>8.3f}" for _, key in STEP_COLUMNS)
            + f"{rec['total']:>8.3f}{1000 * rec['floor']:>9.1f}{rec['ratio']:>7.1f}"
            f"{st['open_edges']:>6}{st['overloaded_edges']:>6}{st['euler']:>7}"
            f"{st['components']:>6}  {rec['success']}"
        )
    truths = [(name, rec["ground_truth"]) for name, rec in sets.items() if "ground_truth" in rec]
    if truths:
        print()
        for name, st in truths:
            print(
                f"ground truth {name}: {st['points']} vertices, {st['faces']} faces, "
                f"{st['open_edges']} open, {st['overloaded_edges']} overloaded, "
                f"Euler {st['euler']}, {st['components']} component(s)"
            )
    rows = [name for name, rec in sets.items() if rec.get("compare")]
    if not rows:
        return
    print()
    head = (
        f"{'set':<12}{'method':<26}{'seconds':>9}{'used':>7}{'faces':>7}{'open':>6}"
        f"{'over':>6}{'euler':>7}{'comp':>6}"
    )
    print(head)
    print("-" * len(head))
    for name in rows:
        rec = sets[name]
        if "error" not in rec:
            print(
                f"{name:<12}{'sr33 (k=' + str(rec['k']) + ')':<26}{rec['total']:>9.3f}"
                + _row_stats(rec["stats"])
            )
        for c in rec["compare"]:
            if "error" in c:
                print(f"{name:<12}{c['method']:<26}  failed: {c['error']}")
            else:
                print(f"{name:<12}{c['method']:<26}{c['seconds']:>9.3f}" + _row_stats(c["stats"]))
    if any(c.get("depth") for name in rows for c in sets[name]["compare"]):
        print("(Poisson: 'used' counts its own vertices, not samples.)")


def check_targets(sets: dict[str, Record]) -> Record:
    """The two targets of the module docstring, on the sets that ran."""
    ok = {n: r for n, r in sets.items() if "error" not in r}
    cube = ok.get("cube")
    worst = max(ok, key=lambda n: ok[n]["ratio"], default=None)
    return {
        "cube_seconds": cube["total"] if cube else None,
        "cube_target": CUBE_TARGET_SECONDS,
        "cube_met": (cube["total"] < CUBE_TARGET_SECONDS) if cube else None,
        "ratio_target": RATIO_TARGET,
        "worst_ratio_set": worst,
        "worst_ratio": ok[worst]["ratio"] if worst else None,
        "ratio_met": all(r["ratio"] <= RATIO_TARGET for r in ok.values()) if ok else None,
    }


def print_targets(t: Record) -> None:
    def verdict(flag: bool | None) -> str:
        return "not run" if flag is None else ("met" if flag else "MISSED")

    cube = f"{t['cube_seconds']:.3f} s, " if t["cube_seconds"] is not None else ""
    worst = (
        f"worst {t['worst_ratio']:.1f} ({t['worst_ratio_set']}), " if t["worst_ratio_set"] else ""
    )
    print(
        f"targets: cube < {t['cube_target']:g} s: {cube}{verdict(t['cube_met'])}; "
        f"ratio <= {t['ratio_target']:g}: {worst}{verdict(t['ratio_met'])}"
    )


def _version(module: str) -> str | None:
    try:
        from importlib.metadata import version

        return version(module)
    except Exception:
        return None


def _git_commit() -> str | None:
    try:
        res = subprocess.run(
            ["git", "rev-parse", "HEAD"], cwd=ROOT, capture_output=True, text=True, timeout=10
        )
    except (OSError, subprocess.SubprocessError):
        return None
    if res.returncode != 0:
        return None
    return res.stdout.strip() or None


def environment(args: argparse.Namespace, competitors: list[str]) -> Record:
    return {
        "date": datetime.now(timezone.utc).isoformat(timespec="seconds"),
        "python": platform.python_version(),
        "platform": platform.platform(),
        "cpu_count": os.cpu_count(),
        "git_commit": _git_commit(),
        "versions": {m: _version(m) for m in ("sr33", "numpy", "scipy", "numba", "open3d", "cgal")},
        "k": args.k,
        "repeats": args.repeats,
        "data": str(Path(args.data).resolve()),
        "competitors": competitors,
    }


def write_json_atomic(path: Path, payload: Record) -> None:
    """Write ``payload`` to a temporary file beside ``path``, then ``os.replace`` it."""
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    umask = os.umask(0)
    os.umask(umask)
    try:
        os.chmod(tmp, 0o666 & ~umask)  # mkstemp creates 0600; give the usual mode
        with os.fdopen(fd, "w", encoding="utf-8") as fh:
            json.dump(payload, fh, indent=2)
            fh.write("\n")
            fh.flush()
            os.fsync(fh.fileno())
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


# ---------------------------------------------------------------------------- main


def parse_args(argv: Sequence[str] | None) -> argparse.Namespace:
    ap = argparse.ArgumentParser(
        description="Benchmark sr33.reconstruct: median step times, ratio to the kNN floor."
    )
    ap.add_argument(
        "--data",
        type=Path,
        default=ROOT.parent / "shared" / "datasets",
        help="datasets directory (with paper/large/ and meshes/)",
    )
    ap.add_argument(
        "--out",
        type=Path,
        default=ROOT / "out" / "bench.json",
        help="JSON output file (written atomically)",
    )
    ap.add_argument("--k", type=int, default=33, help="neighbourhood size (default 33)")
    ap.add_argument("--repeats", type=int, default=3, help="timed runs per set (default 3)")
    ap.add_argument(
        "--only",
        action="append",
        default=[],
        metavar="NAME",
        help="run only this set (file stem); repeatable",
    )
    ap.add_argument(
        "--compare",
        action=argparse.BooleanOptionalAction,
        default=None,
        help="run Open3D / CGAL too (default: when importable)",
    )
    ap.add_argument(
        "--orient-budget",
        type=float,
        default=10.0,
        metavar="SECONDS",
        help="longest Open3D consistent normal orientation before falling back "
        "to orientation away from the centroid (default 10)",
    )
    args = ap.parse_args(argv)
    if args.repeats < 1:
        ap.error("--repeats must be at least 1")
    return args


def main(argv: Sequence[str] | None = None) -> int:
    args = parse_args(argv)
    sets_found = find_sets(args.data, args.only)
    if not sets_found:
        what = f" named {', '.join(args.only)}" if args.only else ""
        note(f"no data sets{what} under {args.data}")
        return 2
    if args.only:
        missing = sorted(set(args.only) - {name for name, _, _ in sets_found})
        if missing:
            note(f"no data set named {', '.join(missing)}; skipped")
    competitors = available_competitors(args.compare)
    results: dict[str, Record] = {}
    crashed = False
    for name, kind, path in sets_found:
        points = read_points(path)
        note(f"{name}: {points.shape[0]} points, k = {args.k}")
        try:
            rec = bench_sr33(points, args.k, args.repeats)
        except Exception as exc:  # report and go on with the other sets
            crashed = True
            note(f"{name}: sr33 failed: {one_line(exc)}")
            rec = {"points": int(points.shape[0]), "k": args.k, "error": one_line(exc)}
        rec = {"kind": kind, "file": str(path), **rec}
        if kind == "mesh":
            verts, tri = read_mesh(path)
            rec["ground_truth"] = stats_dict(tri, verts.shape[0])
        if competitors:
            rec["compare"] = []
            for label, fn in competitors:
                try:
                    got = fn(points, args.repeats, args.orient_budget)
                except Exception as exc:  # a failing competitor must not stop the benchmark
                    got = [{"method": label, "error": one_line(exc)}]
                for c in got:
                    if "error" in c:
                        note(f"{name}: {c['method']} failed: {c['error']}")
                rec["compare"] += got
        results[name] = rec
    print_tables(results)
    targets = check_targets(results)
    print()
    print_targets(targets)
    payload = {
        "environment": environment(args, [label for label, _ in competitors]),
        "targets": targets,
        "sets": results,
    }
    write_json_atomic(args.out, payload)
    print(f"written {args.out}")
    return 1 if crashed else 0


if __name__ == "__main__":
    sys.exit(main())
