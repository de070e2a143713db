"""Report on the shape library and the scan-line sampler (issue: samplers).

For every library shape at its default parameters and default spacing h:
truth-mesh checks (watertight/manifold, Euler characteristic against the
B-rep's), distance of the samples to the CAD surface (OCC's exact
BRepExtrema distance, as a multiple of the shape's size), coverage (largest
distance from the truth surface to the nearest sample, in h), the closest
pair (in h), nearest-neighbour spacing, Condition III by the validators'
geodesic check (``sr33.validators.conditions.sample_conditions``: DT_M on the
refined truth with the samples inserted; worst ratio, share of samples in a
violating triangle, largest degree), seconds to build, to sample (median of
``--repeat`` runs, 3 by default) at the default spacing and at ``--large``
samples (20,000 by default), and to run the geodesic check (median of the
same runs): issue 23's speed figures (6,000 samples in 5 s, 20,000 in 15 s,
the check in 30 s); and the reconstruction's open/overloaded edges and Euler
characteristic next to the expected ones.

Run: ``.venv/bin/python bench/samplers_report.py [--out out/samplers.json]``.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np
from scipy.spatial import cKDTree

ROOT = Path(__file__).resolve().parents[1]

from sr33 import reconstruct  # noqa: E402
from sr33.io import write_text  # noqa: E402
from sr33.samplers import shapes  # noqa: E402
from sr33.samplers.scanline import scan  # noqa: E402
from sr33.validators import mesh_stats  # noqa: E402
from sr33.validators.conditions import sample_conditions  # noqa: E402
from sr33.validators.fidelity import surface_points  # noqa: E402


def surface_distance(solid, points: np.ndarray) -> np.ndarray:
    """Exact distance of each point to the CAD shape's surface (OCC)."""
    import cadquery as cq
    from OCP.BRepExtrema import BRepExtrema_DistShapeShape

    faces = cq.Compound.makeCompound(solid.Faces())
    out = np.empty(points.shape[0])
    for i, p in enumerate(points):
        d = BRepExtrema_DistShapeShape(cq.Vertex.makeVertex(*p).wrapped, faces.wrapped)
        out[i] = d.Value()
    return out


def timed_runs(repeat: int, fn, *args, **kwargs):
    """``fn(*args, **kwargs)`` run ``repeat`` times: (median seconds, every
    run's seconds, the last result; NaN, [], None for no run)."""
    runs, out = [], None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn(*args, **kwargs)
        runs.append(time.perf_counter() - t0)
    return (float(np.median(runs)) if runs else float("nan")), runs, out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default=str(ROOT / "out" / "samplers.json"))
    ap.add_argument("--only", action="append", default=[])
    ap.add_argument(
        "--surface-checks",
        type=int,
        default=1000,
        help="samples per shape checked against the CAD surface (0 = all)",
    )
    ap.add_argument("--repeat", type=int, default=3, help="timed runs per figure (median)")
    ap.add_argument(
        "--large", type=int, default=20000, help="samples of the second sampling (0: none)"
    )
    args = ap.parse_args(argv)
    repeat = max(1, args.repeat)
    names = [n for n in shapes.shape_names() if not args.only or n in args.only]
    rows = {}
    head = (
        f"{'shape':<16}{'points':>7}{'h':>7}{'nn min/med/max (h)':>20}{'close':>7}"
        f"{'cover':>7}{'on CAD':>9}{'III':>7}{'viol':>6}{'deg':>5}{'build':>7}{'scan':>7}"
        f"{'large':>7}{'check':>7}"
        f" | {'expect':>10} | {'open':>5}{'over':>5}{'euler':>6}  ok"
    )
    print(head)
    print("-" * len(head))
    for name in names:
        t0 = time.perf_counter()
        s = shapes.build(name)
        tb = time.perf_counter() - t0
        ts, times, r = timed_runs(repeat, scan, s)
        tl, large_times, big = timed_runs(
            repeat if args.large else 0, scan, s, target_points=args.large
        )
        p, h = r.points, r.meta["spacing"]
        d, _ = cKDTree(p).query(p, 2)
        nn = d[:, 1] / h
        truth = mesh_stats(s.truth_triangles, s.truth_vertices.shape[0])
        dense = surface_points(s.truth_vertices, s.truth_triangles, 50000, seed=1)
        cover = float(cKDTree(p).query(dense)[0].max() / h)
        pick = (
            p
            if args.surface_checks == 0
            else p[
                np.random.default_rng(0).choice(
                    len(p), min(len(p), args.surface_checks), replace=False
                )
            ]
        )
        on = float(surface_distance(s.solid, pick).max() / s.size)
        tc, check_times, cond = timed_runs(
            repeat, sample_conditions, p, s.truth_vertices, s.truth_triangles
        )
        violating = int(np.count_nonzero(~(cond.worst_ratio < np.sqrt(3) / 2)))
        rec = reconstruct(p, 33)
        st = mesh_stats(rec.triangles, rec.vertices.shape[0])
        e = s.expected
        rows[name] = {
            "points": int(len(p)),
            "spacing": h,
            "nn_min": float(nn.min()),
            "nn_median": float(np.median(nn)),
            "nn_max": float(nn.max()),
            "coverage_h": cover,
            "surface_distance_over_size": on,
            "condition_iii_worst_ratio": cond.max_ratio,
            "condition_iii_violating_samples": violating,
            "max_degree": cond.max_degree,
            "conditions_s": tc,
            "conditions_runs_s": check_times,
            "sample_runs_s": times,
            "large_points": int(big.points.shape[0]) if big is not None else 0,
            "large_sample_s": tl,
            "large_sample_runs_s": large_times,
            "repairs": r.meta.get("repairs", []),
            "build_s": tb,
            "sample_s": ts,
            "truth": truth.as_dict(),
            "expected": vars(e),
            "reconstruction": st.as_dict(),
            "success": bool(rec.success),
        }
        match = (
            st.open_edges == 2 * 0 + (0 if e.boundary_loops == 0 else st.open_edges)
            and st.overloaded_edges == 0
            and st.euler == e.euler
            and st.boundary_loops == e.boundary_loops
            and st.components == e.components
        )
        print(
            f"{name:<16}{len(p):>7}{h:>7.3f}{nn.min():>8.2f}/{np.median(nn):.2f}/{nn.max():.2f}"
            f"{nn.min():>7.2f}{cover:>7.2f}{on:>9.1e}{cond.max_ratio:>7.3f}"
            f"{100 * violating / len(p):>5.1f}%{cond.max_degree:>5}"
            f"{tb:>7.2f}{ts:>7.2f}{tl:>7.2f}{tc:>7.2f} | χ{e.euler:>3} b{e.boundary_loops}"
            f" g{e.genus} |"
            f" {st.open_edges:>5}{st.overloaded_edges:>5}{st.euler:>6}  {'yes' if match else 'NO'}"
        )
        rows[name]["topology_matches"] = bool(match)
    out = Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    write_text(out, json.dumps(rows, indent=2, sort_keys=True) + "\n")
    print(f"\nwritten {out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
