"""Command line: ``sr33 reconstruct`` and ``sr33 stats``, thin over the library."""

from __future__ import annotations

import argparse
import json
import logging
import sys
from pathlib import Path

from ._validate import InputError

STEPS = ("localized_rng", "isometric_cycles", "backtracking", "triangulate", "cones")


def _table(rows: list[tuple[str, str]]) -> str:
    width = max(len(k) for k, _ in rows)
    return "\n".join(f"{k:<{width}}  {v}" for k, v in rows)


def _stats_rows(stats) -> list[tuple[str, str]]:
    names = [
        ("points", "points"),
        ("used vertices", "used_vertices"),
        ("faces", "faces"),
        ("edges", "edges"),
        ("open edges", "open_edges"),
        ("overloaded edges", "overloaded_edges"),
        ("Euler characteristic", "euler"),
        ("components", "components"),
        ("boundary loops", "boundary_loops"),
    ]
    return [(label, str(getattr(stats, attr))) for label, attr in names]


def _cmd_reconstruct(args) -> int:
    from validators.topology import mesh_stats

    from .io import read_points, write_mesh
    from .reconstruct import reconstruct

    out = Path(args.output)
    points = read_points(args.input)
    r = reconstruct(
        points,
        args.k,
        max_cycle_length=args.max_cycle_length,
        budget=args.budget,
        quiet=args.quiet,
    )
    write_mesh(out, r.vertices, r.triangles)
    stats = mesh_stats(r.triangles, r.vertices.shape[0])
    rows = [("input", str(args.input)), ("k", str(r.k))]
    rows += [("duplicates merged", str(r.duplicates_merged))] if r.duplicates_merged else []
    rows += _stats_rows(stats)
    rows += [
        ("success condition", "met" if r.success else "NOT met"),
        ("unresolved samples", str(r.unresolved_samples.shape[0])),
        ("coned samples", str(r.coned_samples.shape[0])),
    ]
    rows += [(f"seconds {s}", f"{r.timings.get(s, 0.0):.3f}") for s in STEPS]
    rows += [("seconds total", f"{sum(r.timings.values()):.3f}"), ("output", str(out))]
    print(_table(rows))
    if args.json:
        doc = {
            "input": str(args.input),
            "output": str(out),
            "k": r.k,
            "duplicates_merged": r.duplicates_merged,
            "success": r.success,
            "unresolved_samples": int(r.unresolved_samples.shape[0]),
            "coned_samples": int(r.coned_samples.shape[0]),
            "stats": stats.as_dict(),
            "seconds": r.timings,
        }
        Path(args.json).write_text(json.dumps(doc, indent=2) + "\n")
    return 0


def _cmd_stats(args) -> int:
    from validators.topology import mesh_stats

    from .io import read_mesh

    v, f = read_mesh(args.mesh)
    if f.shape[0] == 0:
        raise InputError(f"{args.mesh}: has no faces; stats needs a triangle mesh")
    print(_table([("mesh", str(args.mesh))] + _stats_rows(mesh_stats(f, v.shape[0]))))
    return 0


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="sr33", description="Reconstruct surfaces with sharp features from point samples."
    )
    p.add_argument("-v", "--verbose", action="store_true", help="log step timings (debug)")
    sub = p.add_subparsers(dest="command", required=True)
    r = sub.add_parser("reconstruct", help="reconstruct a mesh from samples")
    r.add_argument("input", help="samples: .xyz .txt .npy or a mesh .ply .obj .off .stl .vtp")
    r.add_argument("-k", type=int, default=33, help="neighbourhood size (default 33)")
    r.add_argument("-o", "--output", required=True, help="output mesh .ply .obj .off .stl .vtp")
    r.add_argument("--max-cycle-length", type=int, default=8, help="longest face cycle")
    r.add_argument("--budget", type=int, default=20000, help="search budget per component")
    r.add_argument("--json", help="also write the summary as JSON here")
    r.add_argument("-q", "--quiet", action="store_true", help="no progress bars")
    r.set_defaults(func=_cmd_reconstruct)
    s = sub.add_parser("stats", help="print topology figures of a mesh")
    s.add_argument("mesh")
    s.set_defaults(func=_cmd_stats)
    return p


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    logging.basicConfig(
        level=logging.DEBUG if args.verbose else logging.WARNING,
        format="%(name)s: %(message)s",
    )
    logging.getLogger("numba").setLevel(logging.WARNING)
    try:
        return args.func(args)
    except InputError as exc:
        print(f"sr33: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("sr33: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
