"""Render time of the inspector for a ~100k-triangle reconstruction, all layers on.

Samples the cube shape with about 50,000 points, reconstructs it (k = 33),
opens the inspector off-screen with every layer visible and reports the
median time of a full render to an image (``--repeats``).
Run: ``.venv/bin/python bench/gui_bench.py``.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

from sr33.gui import pyvista  # noqa: E402

pv = pyvista(off_screen=True)

from sr33 import reconstruct  # noqa: E402
from sr33.gui import LAYERS, Inspector  # noqa: E402
from sr33.samplers import shapes  # noqa: E402
from sr33.samplers.scanline import scan  # noqa: E402


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--points", type=int, default=50000)
    ap.add_argument("--repeats", type=int, default=3)
    args = ap.parse_args(argv)
    s = shapes.build("cube")
    pts = scan(s, target_points=args.points).points
    t0 = time.perf_counter()
    rec = reconstruct(pts, 33)
    t_rec = time.perf_counter() - t0
    p = pv.Plotter(off_screen=True, window_size=(1200, 900))
    t0 = time.perf_counter()
    ins = Inspector(p, pts, k=33, reconstruction=rec, truth=(s.truth_vertices, s.truth_triangles))
    t_build = time.perf_counter() - t0
    for name in LAYERS:
        ins.set_layer(name, True)
    t0 = time.perf_counter()
    p.screenshot(return_img=True)  # the window is created and drawn here
    t_first = time.perf_counter() - t0
    times = []
    for _ in range(args.repeats):
        p.camera.azimuth += 15  # a new view: a full render, not a cached frame
        t0 = time.perf_counter()
        p.render()
        p.screenshot(return_img=True)
        times.append(time.perf_counter() - t0)
    print(
        f"{pts.shape[0]} samples, {rec.triangles.shape[0]} triangles (reconstruction {t_rec:.2f} s)"
    )
    print(f"inspector set-up (layers, defects, condition check): {t_build:.2f} s")
    print(f"first render with all layers on: {t_first:.3f} s")
    print(f"render of a new view, all layers on: median {statistics.median(times):.3f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
