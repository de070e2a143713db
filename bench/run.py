"""Benchmark of the reconstruction (``make bench``).

For every paper set (``<data>/paper/large/*.obj``) and every real mesh
(``<data>/meshes/*.obj``, vertices as samples) this runs
``sr33.reconstruct(points, k)`` once untimed (numba loads its cached
kernels), then ``--repeats`` times, and reports the median seconds of every
step and of the whole call.  The floor is the median time of what any
k-neighbourhood method must do at least: building scipy's cKDTree on the
same points and querying k + 1 neighbours of each.  The ratio total / floor
is the figure of merit; targets on the 2-core machine: cube (6144 points,
k = 33) under 1 s, ratio at most 50 everywhere.

With the optional extra ``compare`` installed (open3d, cgal), the same
points are also given to Open3D's ball pivoting and screened Poisson and to
CGAL's advancing front, in the same process, and their time and topology
(validators.mesh_stats) are printed next to ours.  A competitor that is
missing or fails is reported in one line and the benchmark goes on.

Results are printed as tables and written as JSON (atomically) to ``--out``.
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np
from scipy.spatial import cKDTree

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from sr33 import reconstruct  # noqa: E402
from sr33.io import read_points, write_text  # noqa: E402
from validators import mesh_stats  # noqa: E402

STEPS = ("localized_rng", "isometric_cycles", "backtracking", "triangulate", "cones")


def median_time(fn: Callable[[], object], repeats: int) -> tuple[float, object]:
    """Median wall time of ``repeats`` calls and the last result."""
    times = []
    out = None
    for _ in range(repeats):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times), out


def knn_floor(points: np.ndarray, k: int) -> float:
    t0 = time.perf_counter()
    cKDTree(points).query(points, k + 1)
    return time.perf_counter() - t0


def bench_sr33(points: np.ndarray, k: int, repeats: int) -> dict:
    reconstruct(points, k, quiet=True)  # warm-up: numba cache load
    runs = []
    totals = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        r = reconstruct(points, k, quiet=True)
        totals.append(time.perf_counter() - t0)
        runs.append(r.timings)
    floor = statistics.median(knn_floor(points, k) for _ in range(max(repeats, 5)))
    steps = {s: statistics.median(t.get(s, 0.0) for t in runs) for s in STEPS}
    total = statistics.median(totals)
    s = mesh_stats(r.triangles, r.vertices.shape[0])
    return {
        "points": int(points.shape[0]),
        "k": k,
        "seconds": steps,
        "total": total,
        "floor": floor,
        "ratio": total / floor if floor > 0 else float("inf"),
        "success": bool(r.success),
        "stats": s.as_dict(),
    }


def _open3d_mesh_stats(mesh, n_points: int, points: np.ndarray | None):
    tri = np.asarray(mesh.triangles, dtype=np.int64)
    verts = np.asarray(mesh.vertices)
    if points is not None and verts.shape[0] == points.shape[0]:
        return mesh_stats(tri, n_points).as_dict()
    return mesh_stats(tri, verts.shape[0]).as_dict()


def bench_open3d(points: np.ndarray, repeats: int) -> list[dict]:
    import open3d as o3d

    out = []
    pcd = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(points))
    spacing = float(np.median(cKDTree(points).query(points, 2)[0][:, 1]))

    def prepare():
        p = o3d.geometry.PointCloud(pcd)
        p.estimate_normals(o3d.geometry.KDTreeSearchParamKNN(30))
        p.orient_normals_consistent_tangent_plane(30)
        return p

    def bpa():
        p = prepare()
        radii = o3d.utility.DoubleVector([1.0 * spacing, 1.5 * spacing, 2.0 * spacing])
        return o3d.geometry.TriangleMesh.create_from_point_cloud_ball_pivoting(p, radii)

    def poisson():
        p = prepare()
        mesh, _ = o3d.geometry.TriangleMesh.create_from_point_cloud_poisson(p, depth=8)
        return mesh

    for name, fn in (("open3d ball pivoting", bpa), ("open3d poisson (depth 8)", poisson)):
        try:
            t, mesh = median_time(fn, repeats)
            stats = _open3d_mesh_stats(mesh, points.shape[0], points if "pivot" in name else None)
            out.append({"method": name, "seconds": t, "stats": stats})
        except Exception as exc:  # a competitor failing must not stop the benchmark
            out.append({"method": name, "error": f"{type(exc).__name__}: {exc}"})
    return out


def bench_cgal(points: np.ndarray, repeats: int) -> list[dict]:
    from CGAL.CGAL_Advancing_front_surface_reconstruction import (
        advancing_front_surface_reconstruction,
    )
    from CGAL.CGAL_Kernel import Point_3
    from CGAL.CGAL_Point_set_3 import Point_set_3
    from CGAL.CGAL_Polyhedron_3 import Polyhedron_3

    def run():
        ps = Point_set_3()
        for p in points:
            ps.insert(Point_3(float(p[0]), float(p[1]), float(p[2])))
        poly = Polyhedron_3()
        advancing_front_surface_reconstruction(ps, poly)
        return poly

    try:
        t, poly = median_time(run, repeats)
        index = {}
        for i, p in enumerate(points):
            index[(float(p[0]), float(p[1]), float(p[2]))] = i
        tris = []
        for f in poly.facets():
            h = f.halfedge()
            ids = []
            for _ in range(3):
                q = h.vertex().point()
                ids.append(index[(q.x(), q.y(), q.z())])
                h = h.next()
            tris.append(ids)
        stats = mesh_stats(np.array(tris, dtype=np.int64), points.shape[0]).as_dict()
        return [{"method": "cgal advancing front", "seconds": t, "stats": stats}]
    except Exception as exc:
        return [{"method": "cgal advancing front", "error": f"{type(exc).__name__}: {exc}"}]


def competitors(points: np.ndarray, repeats: int) -> list[dict]:
    out: list[dict] = []
    for label, fn in (("open3d", bench_open3d), ("CGAL", bench_cgal)):
        try:
            out += fn(points, repeats)
        except ImportError:
            out.append({"method": label, "error": "not installed (pip install '.[compare]')"})
    return out


def print_tables(results: dict) -> None:
    head = (
        f"{'set':<12}{'points':>7}{'k':>4}{'rng':>8}{'cycles':>8}{'backtr':>8}{'triang':>8}"
        f"{'cones':>7}{'total':>8}{'floor ms':>9}{'ratio':>7}{'open':>6}{'over':>6}{'euler':>7}"
        f"{'comp':>6}  success"
    )
    print(head)
    print("-" * len(head))
    for name, r in results.items():
        s, st = r["seconds"], r["stats"]
        print(
            f"{name:<12}{r['points']:>7}{r['k']:>4}"
            + "".join(f"{s[x]:>8.3f}" for x in STEPS[:4])
            + f"{s['cones']:>7.3f}{r['total']:>8.3f}{1000 * r['floor']:>9.1f}{r['ratio']:>7.1f}"
            f"{st['open_edges']:>6}{st['overloaded_edges']:>6}{st['euler']:>7}{st['components']:>6}"
            f"  {r['success']}"
        )
    rows = [(name, c) for name, r in results.items() for c in r.get("compare", [])]
    if not rows:
        return
    print()
    head = (
        f"{'set':<12}{'method':<28}{'seconds':>9}{'used':>7}{'faces':>7}{'open':>6}"
        f"{'over':>6}{'euler':>7}{'comp':>6}"
    )
    print(head)
    print("-" * len(head))
    for name, r in results.items():
        st = r["stats"]
        print(
            f"{name:<12}{'sr33 (this)':<28}{r['total']:>9.3f}{st['used_vertices']:>7}"
            f"{st['faces']:>7}{st['open_edges']:>6}{st['overloaded_edges']:>6}{st['euler']:>7}"
            f"{st['components']:>6}"
        )
        for c in r.get("compare", []):
            if "error" in c:
                print(f"{name:<12}{c['method']:<28}  {c['error']}")
                continue
            st = c["stats"]
            print(
                f"{name:<12}{c['method']:<28}{c['seconds']:>9.3f}{st['used_vertices']:>7}"
                f"{st['faces']:>7}{st['open_edges']:>6}{st['overloaded_edges']:>6}"
                f"{st['euler']:>7}{st['components']:>6}"
            )


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--data", default=str(ROOT.parent / "shared" / "datasets"))
    ap.add_argument("--out", default=str(ROOT / "out" / "bench.json"))
    ap.add_argument("--k", type=int, default=33)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--only", action="append", default=[], help="set name (file stem)")
    g = ap.add_mutually_exclusive_group()
    g.add_argument("--compare", dest="compare", action="store_true", default=None)
    g.add_argument("--no-compare", dest="compare", action="store_false")
    args = ap.parse_args(argv)
    data = Path(args.data)
    files = sorted((data / "paper" / "large").glob("*.obj")) + sorted(
        (data / "meshes").glob("*.obj")
    )
    if args.only:
        files = [f for f in files if f.stem in args.only]
    if not files:
        print(f"bench: no data sets found under {data}", file=sys.stderr)
        return 2
    results: dict[str, dict] = {}
    for f in files:
        pts = read_points(f)
        results[f.stem] = bench_sr33(pts, args.k, args.repeats)
        if args.compare is not False:
            comp = competitors(pts, args.repeats)
            if args.compare or any("error" not in c for c in comp):
                results[f.stem]["compare"] = comp
    print_tables(results)
    out = Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    write_text(out, json.dumps(results, indent=2, sort_keys=True) + "\n")
    print(f"\nwritten {out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
