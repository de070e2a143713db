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

    from .io import read_points, write_mesh, write_text
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
        write_text(args.json, json.dumps(doc, indent=2) + "\n")
    return 0


def _cmd_stats(args) -> int:
    from validators.topology import mesh_stats

    from .io import read_mesh

    v, f = read_mesh(args.mesh)
    if f.shape[0] == 0:
        raise InputError(f"{args.mesh}: has no faces; stats needs a triangle mesh")
    print(_table([("mesh", str(args.mesh))] + _stats_rows(mesh_stats(f, v.shape[0]))))
    return 0


def _parse_params(items: list[str]) -> dict[str, float]:
    params: dict[str, float] = {}
    for item in items:
        key, sep, value = item.partition("=")
        if not sep or not key:
            raise InputError(f"--param must look like key=value, got {item!r}")
        try:
            params[key.strip()] = float(value)
        except ValueError:
            raise InputError(f"--param {key}: value must be a number, got {value!r}") from None
    return params


def _cmd_sample(args) -> int:
    try:
        from samplers import scanline, shapes
    except ImportError as exc:  # pragma: no cover - depends on the install
        raise InputError(f"sampling needs CadQuery: pip install cadquery ({exc})") from None

    if args.list:
        for name in shapes.shape_names():
            defaults = ", ".join(f"{k}={v:g}" for k, v in shapes.shape_parameters(name).items())
            print(f"{name:<16} {shapes.describe(name)}")
            print(f"{'':<16} parameters: {defaults}")
        return 0
    if not args.shape:
        raise InputError("sample needs a SHAPE name (see sr33 sample --list)")
    if not args.output:
        raise InputError("sample needs -o/--output for the points")
    from .io import write_mesh, write_points

    try:
        shape = shapes.build(args.shape, **_parse_params(args.param))
        res = scanline.scan(
            shape,
            args.spacing,
            target_points=args.points,
            ratio=args.ratio,
            jitter=args.jitter,
            dropout=args.dropout,
            seed=args.seed,
        )
    except (shapes.ShapeError, scanline.SamplingError) as exc:
        raise InputError(str(exc)) from None
    write_points(
        args.output,
        res.points,
        {"line": res.line_id, "face": res.face_id, "feature": res.on_feature},
    )
    if args.truth:
        write_mesh(args.truth, shape.truth_vertices, shape.truth_triangles)
    if args.meta:
        from .io import write_text

        write_text(args.meta, json.dumps(res.meta, indent=2, sort_keys=True) + "\n")
    exp = shape.expected
    rows = [
        ("shape", shape.name),
        ("parameters", ", ".join(f"{k}={v:g}" for k, v in shape.params.items())),
        ("spacing h", f"{res.meta['spacing']:.6g}"),
        ("ratio r", f"{res.meta['ratio']:g}"),
        ("points", str(res.points.shape[0])),
        ("feature points", str(int(res.on_feature.sum()))),
        ("scan lines", str(res.meta["lines"])),
        (
            "expected topology",
            f"components {exp.components}, Euler {exp.euler}, genus {exp.genus}, "
            f"boundary loops {exp.boundary_loops}",
        ),
        ("output", str(args.output)),
    ]
    print(_table(rows))
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
    sm = sub.add_parser("sample", help="scan-line samples of a sharp CAD shape")
    sm.add_argument("shape", nargs="?", help="shape name (see --list)")
    sm.add_argument("--list", action="store_true", help="list shapes and their parameters")
    sm.add_argument("--param", action="append", default=[], metavar="KEY=VALUE")
    sm.add_argument("--spacing", type=float, help="scan-line spacing h (default: per shape)")
    sm.add_argument("--points", type=int, help="target number of samples instead of --spacing")
    sm.add_argument("--ratio", type=float, default=1.0, help="spacing along a line / h")
    sm.add_argument("--jitter", type=float, default=0.0, help="Gaussian noise sigma / h")
    sm.add_argument("--dropout", type=float, default=0.0, help="fraction of samples dropped")
    sm.add_argument("--seed", type=int, default=0)
    sm.add_argument("-o", "--output", help="points: .ply .xyz .txt .npy .obj .vtp")
    sm.add_argument("--truth", help="also write the ground-truth mesh here")
    sm.add_argument("--meta", help="also write the metadata as JSON here")
    sm.set_defaults(func=_cmd_sample)
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
