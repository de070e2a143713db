"""The library's default samplings under floating-point environments that
differ in the last bits, and their acceptance figures.

A sampling (and everything after it) must not hinge on the last bit of a
float: machines differ in their BLAS kernels (FMA or not, SIMD width) and
in numpy's SIMD paths for transcendental functions.  Every library shape's
default sampling is made in a fresh process under each environment:

* ``default``: this machine as it is;
* ``blas-sse3``: ``OPENBLAS_CORETYPE=Prescott`` (OpenBLAS's SSE3 kernels, no
  FMA, another summation order) and one BLAS thread;
* ``other-libm``: numpy's and Python's sine, cosine, arc functions,
  exponentials and logarithms answer one unit in the last place off for
  about half of all inputs (chosen by a hash of the input's bits), as
  another libm would (the angles of :mod:`sr33.libm`, numba loops calling
  the C library, are not perturbed);
* ``no-avx512``: numpy told to leave its AVX-512 loops
  (``NPY_DISABLE_CPU_FEATURES``, numpy 2.4's names), as on a processor
  without them: its arctan2 and arccos then give the C library's bits,
  which differ from its AVX-512 ones in the last place for some inputs
  (before :mod:`sr33.libm`, a cone's sampling differed between the two).

For each distinct sampling (by the md5 of its points' bytes) the
acceptance figures are measured: sample count, Condition III by the
geodesic check (worst ratio, samples in a violating triangle, largest
degree), coverage and closest pair in h, and the reconstruction's open and
overloaded edges and Euler characteristic against the B-rep's topology.
Exit status 0 when every sampling conforms (III-ii, coverage, spacing) and
the verdicts (conforms, topology as expected) agree across environments.

Run: ``.venv/bin/python bench/fp_environments.py [--only NAME ...] [--out out/fp.json]``
"""

from __future__ import annotations

import argparse
import hashlib
import json
import os
import subprocess
import sys
import tempfile
from concurrent.futures import ProcessPoolExecutor, ThreadPoolExecutor
from pathlib import Path

ENVIRONMENTS = {
    "default": {},
    "blas-sse3": {"OPENBLAS_CORETYPE": "Prescott", "OPENBLAS_NUM_THREADS": "1"},
    "other-libm": {"SR33_BENCH_PERTURB_LIBM": "1"},
    "no-avx512": {"NPY_DISABLE_CPU_FEATURES": "AVX512_ICL X86_V4"},
}

# the child: optionally perturb the transcendental functions, sample, save
CHILD = r"""
import math, os, sys, time
import numpy as np
import cadquery  # noqa: F401  (everything imported before the functions are replaced)
from sr33.samplers import shapes
from sr33.samplers.scanline import scan

if os.environ.get("SR33_BENCH_PERTURB_LIBM"):
    def _flip(x, y):
        y = np.asarray(y, dtype=np.float64)
        x = np.broadcast_to(np.asarray(x, dtype=np.float64), y.shape).reshape(-1).copy()
        odd = ((x.view(np.uint64) * np.uint64(0x9E3779B97F4A7C15)) >> np.uint64(63)).astype(bool)
        flat = y.reshape(-1)
        return np.where(odd & np.isfinite(flat), np.nextafter(flat, np.inf), flat).reshape(y.shape)

    def _wrap_np(f):
        def g(x, *args, **kw):
            y = f(x, *args, **kw)
            if kw.get("out") is not None or np.asarray(y).dtype != np.float64:
                return y
            out = _flip(x, y)
            return out if np.ndim(y) else out[()]
        return g

    def _wrap_math(f):
        def g(x, *args):
            y = f(x, *args)
            return float(_flip(np.float64(x), np.float64(y))[()])
        return g

    for name in ("sin", "cos", "tan", "arcsin", "arccos", "arctan", "arctan2", "exp",
                 "log", "log2", "log10", "hypot"):
        setattr(np, name, _wrap_np(getattr(np, name)))
    for name in ("sin", "cos", "tan", "asin", "acos", "atan", "atan2", "exp", "log", "hypot"):
        setattr(math, name, _wrap_math(getattr(math, name)))

name, out = sys.argv[1], sys.argv[2]
t = time.perf_counter()
r = scan(shapes.build(name))
np.save(out, np.ascontiguousarray(r.points))
print(f"{time.perf_counter() - t:.2f}")
"""


def sample(name: str, env: dict[str, str], folder: Path) -> tuple[str, float, Path]:
    """One default sampling in a fresh process: (md5, seconds, file)."""
    out = folder / f"{name}-{hashlib.md5(json.dumps(env).encode()).hexdigest()[:6]}.npy"
    full = {**os.environ, **env}
    res = subprocess.run(
        [sys.executable, "-c", CHILD, name, str(out)],
        env=full,
        capture_output=True,
        text=True,
        check=True,
    )
    import numpy as np

    md5 = hashlib.md5(np.load(out).tobytes()).hexdigest()[:10]
    return md5, float(res.stdout.strip().splitlines()[-1]), out


def figures(name: str, path: Path) -> dict:
    """The acceptance figures of one sampling."""
    import numpy as np
    from scipy.spatial import cKDTree

    from sr33 import reconstruct
    from sr33.mesh import SQRT3_2, surface_points
    from sr33.samplers import shapes
    from sr33.validators import mesh_stats
    from sr33.validators.conditions import sample_conditions

    p = np.load(path)
    s = shapes.build(name)
    h = s.default_spacing
    d, _ = cKDTree(p).query(p, 2)
    dense = surface_points(s.truth_vertices, s.truth_triangles, 50000, seed=1)
    cond = sample_conditions(p, s.truth_vertices, s.truth_triangles)
    rec = reconstruct(p, 33)
    st = mesh_stats(rec.triangles, rec.vertices.shape[0])
    e = s.expected
    violating = int(np.count_nonzero(~(cond.worst_ratio < SQRT3_2)))
    cover = float(cKDTree(p).query(dense)[0].max())
    closest = float(d[:, 1].min())
    return {
        "points": int(p.shape[0]),
        "iii_worst": round(float(cond.max_ratio), 3),
        "iii_violating": violating,
        "max_degree": int(cond.max_degree),
        "coverage_h": round(cover / h, 2),
        "closest_h": round(closest / h, 2),
        "open": int(st.open_edges),
        "overloaded": int(st.overloaded_edges),
        "euler": int(st.euler),
        "conforms": bool(violating == 0 and cover <= 1.5 * h and closest >= 0.25 * h),
        "topology_ok": bool(
            st.overloaded_edges == 0
            and st.euler == e.euler
            and st.boundary_loops == e.boundary_loops
            and st.components == e.components
        ),
    }


def main(argv=None) -> int:
    from sr33.io import write_text
    from sr33.samplers import shapes

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--only", action="append", default=[])
    ap.add_argument("--env", action="append", default=[], choices=sorted(ENVIRONMENTS))
    ap.add_argument("--out", default="out/fp_environments.json")
    ap.add_argument("--jobs", type=int, default=2, help="samplings run at once (default 2)")
    args = ap.parse_args(argv)
    names = args.only or shapes.shape_names()
    envs = args.env or list(ENVIRONMENTS)
    rows: dict[str, dict] = {}
    same_figures = True
    same_verdicts = True
    all_conform = True
    with tempfile.TemporaryDirectory() as tmp:
        with ThreadPoolExecutor(max(1, args.jobs)) as pool:
            futures = {
                (n, e): pool.submit(sample, n, ENVIRONMENTS[e], Path(tmp))
                for n in names
                for e in envs
            }
            samplings = {key: f.result() for key, f in futures.items()}
        todo = {}
        for name in names:
            for md5, _, path in (samplings[name, e] for e in envs):
                todo.setdefault((name, md5), path)
        with ProcessPoolExecutor(max(1, args.jobs)) as pool:
            jobs = {key: pool.submit(figures, key[0], path) for key, path in todo.items()}
            measured = {key: f.result() for key, f in jobs.items()}
        for name in names:
            runs = {e: samplings[name, e] for e in envs}
            row = {
                env: {"md5": md5, "sample_s": round(t, 2), **measured[name, md5]}
                for env, (md5, t, _) in runs.items()
            }
            rows[name] = row
            distinct = {
                json.dumps(
                    {k: v for k, v in r.items() if k not in ("md5", "sample_s")}, sort_keys=True
                )
                for r in row.values()
            }
            same_figures &= len(distinct) == 1
            same_verdicts &= len({(r["conforms"], r["topology_ok"]) for r in row.values()}) == 1
            all_conform &= all(r["conforms"] for r in row.values())
            for env, r in row.items():
                print(
                    f"{name:<16}{env:<12}{r['md5']:>12}{r['points']:>7}"
                    f"  III {r['iii_worst']:.3f} viol {r['iii_violating']:<4}"
                    f" deg {r['max_degree']:<3}"
                    f" cover {r['coverage_h']:.2f} close {r['closest_h']:.2f}"
                    f" | open {r['open']:<4} over {r['overloaded']} chi {r['euler']:<4}"
                    f" {'ok' if r['topology_ok'] else 'NO'}"
                    f"  {'conforms' if r['conforms'] else 'FAILS'}  {r['sample_s']:6.1f} s",
                    flush=True,
                )
    print(
        "\nevery sampling conforms (III-ii geodesic, coverage <= 1.5 h, closest >= h/4):",
        "yes" if all_conform else "NO",
    )
    print(
        "verdicts (conforms, topology) identical across environments:",
        "yes" if same_verdicts else "NO",
    )
    print("figures identical across environments:", "yes" if same_figures else "no")
    out = Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    write_text(out, json.dumps(rows, indent=2, sort_keys=True) + "\n")
    return 0 if all_conform and same_verdicts else 1


if __name__ == "__main__":
    sys.exit(main())
