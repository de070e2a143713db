"""Does a sampling's Condition III verdict hinge on the last bits? (issue 23)

For every library shape (or ``--only``): the default sampling, and the
samplings at the default spacing h times ``1 + e`` for each ``--eps`` e
(1e-12 and -1e-12 by default: a change no CAD model, scanner or machine
could tell apart from h, of the order of the roundoff another machine's
numpy or qhull may make).  Each is checked by the geodesic check
(``sr33.validators.conditions.sample_conditions``); the report gives the
worst III-ii ratio and the samples at or above 0.85 (the sampler's margin)
per run, and flags a shape whose verdict against the margin differs between
the runs.  A sampler meets "results must not hinge on the last bit of a
float" when no shape is flagged.

Run: ``.venv/bin/python bench/perturbation.py [--only cutcube] [--eps=-1e-9]
[--out out/perturbation.json]`` (``--eps=`` with the sign: argparse reads a
bare negative number as an option).
"""

from __future__ import annotations

import argparse
import hashlib
import json
import time
from pathlib import Path

import numpy as np

from sr33.io import write_text
from sr33.samplers import shapes
from sr33.samplers.scanline import scan
from sr33.validators.conditions import sample_conditions

ROOT = Path(__file__).resolve().parents[1]
MARGIN = 0.85  # issue 23's margin under sqrt(3)/2


def run(s, eps: float) -> dict:
    """One sampling of the library shape ``s`` at its default h times
    ``1 + eps``, checked."""
    t0 = time.perf_counter()
    r = scan(s) if eps == 0.0 else scan(s, spacing=s.default_spacing * (1.0 + eps))
    seconds = time.perf_counter() - t0
    p = np.ascontiguousarray(r.points)
    rep = sample_conditions(p, s.truth_vertices, s.truth_triangles)
    w = np.asarray(rep.worst_ratio)
    return {
        "eps": eps,
        "samples": int(p.shape[0]),
        "sha256": hashlib.sha256(p.tobytes()).hexdigest()[:16],
        "worst": float(np.nanmax(w)),
        "at_margin": int((w >= MARGIN).sum()),
        "seconds": round(seconds, 2),
    }


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--only", action="append", default=[])
    ap.add_argument("--eps", type=float, action="append", default=None)
    ap.add_argument("--out", default=str(ROOT / "out" / "perturbation.json"))
    args = ap.parse_args(argv)
    eps = [0.0] + (args.eps if args.eps else [1e-12, -1e-12])
    report, flagged = {}, []
    for name in args.only or shapes.shape_names():
        s = shapes.build(name)
        runs = [run(s, e) for e in eps]
        report[name] = runs
        verdicts = {r["at_margin"] == 0 for r in runs}
        flag = len(verdicts) > 1
        if flag:
            flagged.append(name)
        cells = "  ".join(f"{r['eps']:+.0e}: {r['worst']:.4f} ({r['at_margin']})" for r in runs)
        print(f"{name:16s} {cells}{'  FLIPS' if flag else ''}", flush=True)
    print(f"{len(flagged)} of {len(report)} shapes flip against the margin: {', '.join(flagged)}")
    write_text(args.out, json.dumps({"eps": eps, "shapes": report, "flips": flagged}, indent=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
