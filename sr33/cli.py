"""Command line: ``sr33 reconstruct`` and ``sr33 stats``, thin over the library."""

from __future__ import annotations

import argparse
import json
import logging
import os
import sys
from pathlib import Path

from ._validate import InputError

EXIT_CODES = """exit codes:
  0  done, and the result passes its check (reconstruct: the success
     condition; validate: a valid mesh, homeomorphic and within h of the
     truth; conditions: every condition met)
  1  done, but the result fails its check (the outputs are still written)
  2  bad input or output (one line on stderr naming the problem)
  3  internal error (one line; the traceback with -v)
  130  interrupted; 143 terminated (no temporary file is left)"""

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
    from sr33.validators.topology import mesh_stats

    from .io import MESH_FORMATS, TEXT_FORMATS, read_points, write_mesh, write_text
    from .reconstruct import reconstruct

    out = Path(args.output)
    _check_outputs(
        [
            (args.output, MESH_FORMATS, "output"),
            (args.json, TEXT_FORMATS, "text"),
            (args.save, (".npz",), "reconstruction"),
        ],
        inputs=[args.input],
    )
    points = read_points(args.input)
    r = reconstruct(
        points,
        args.k,
        max_cycle_length=args.max_cycle_length,
        budget=args.budget,
        exact_seconds=args.exact_seconds,
        quiet=args.quiet,
    )
    write_mesh(out, r.vertices, r.triangles)
    if args.save:
        from .io import save_reconstruction

        save_reconstruction(args.save, r)
    stats = mesh_stats(r.triangles, r.vertices.shape[0])
    rows = [("input", str(args.input)), ("k", str(r.k))]
    rows += [("duplicates merged", str(r.duplicates_merged))] if r.duplicates_merged else []
    rows += _stats_rows(stats)
    rows += [
        ("success condition", "met" if r.success else "NOT met"),
        ("unresolved samples", str(r.unresolved_samples.shape[0])),
        ("coned samples", str(r.coned_samples.shape[0])),
        (
            "strict search failed",
            f"{r.fallback_components} component{'' if r.fallback_components == 1 else 's'}",
        ),
    ]
    if r.exact.components:
        e = r.exact
        rows += [
            (
                "exact selection",
                f"{e.improved} of {e.components} improved, {e.proven} proven optimal"
                + (f", {e.grown} after freeing the faces round them" if e.grown else ""),
            )
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
            "fallback_components": r.fallback_components,
            "exact_selection": dict(
                zip(("components", "improved", "proven", "cuts", "grown"), r.exact.as_tuple())
            ),
            "stats": stats.as_dict(),
            "seconds": r.timings,
        }
        write_text(args.json, json.dumps(doc, indent=2) + "\n")
    if r.triangles.shape[0] == 0:
        print("sr33: the mesh has no faces", file=sys.stderr)
        return 1
    return 0 if r.success else 1


def _check_outputs(outputs, inputs) -> None:
    """Check every output path before the work: writable, a known format,
    none equal to an input or to another output."""
    from .io import check_output

    seen: dict[Path, str] = {Path(p).resolve(): "input" for p in inputs if p}
    for path, formats, what in outputs:
        if not path:
            continue
        check_output(path, formats, what)
        key = Path(path).resolve()
        if key in seen:
            raise InputError(f"{path}: is also the {seen[key]}; give the {what} another path")
        seen[key] = f"{what} file"


def _cmd_stats(args) -> int:
    from sr33.validators.topology import mesh_stats

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
    from sr33.samplers import scanline, shapes  # CadQuery is imported on use

    if args.list:
        for name in shapes.shape_names():
            defaults = ", ".join(f"{k}={v:g}" for k, v in shapes.shape_parameters(name).items())
            print(f"{name:<16} {shapes.describe(name)}")
            print(f"{'':<16} parameters: {defaults}")
        print(
            f"every shape also takes {', '.join(shapes.ROTATIONS)}: degrees about the "
            "x, y and z axes, in that order (default 0)"
        )
        return 0
    if not args.shape:
        raise InputError(
            "sample needs a SHAPE: a library name (see sr33 sample --list) or a STEP/BREP file"
        )
    from_file = bool(Path(args.shape).suffix)
    if from_file:
        try:
            shapes.cad_format(args.shape)
        except shapes.ShapeError as exc:
            raise InputError(f"{exc} (or a library shape name, see sr33 sample --list)") from None
    if from_file and args.param:
        raise InputError(f"--param applies to library shapes, not to the CAD file {args.shape}")
    if not args.output:
        raise InputError("sample needs -o/--output for the points")
    from .io import MESH_FORMATS, POINT_FORMATS, TEXT_FORMATS, write_mesh, write_points

    _check_outputs(
        [
            (args.output, POINT_FORMATS, "point"),
            (args.truth, MESH_FORMATS, "truth mesh"),
            (args.meta, TEXT_FORMATS, "text"),
        ],
        inputs=[args.shape] if from_file else [],
    )

    try:
        if from_file:
            shape = shapes.from_cad(args.shape)
        else:
            shape = shapes.build(args.shape, **_parse_params(args.param))
        res = scanline.scan(
            shape,
            args.spacing,
            target_points=args.points,
            ratio=args.ratio,
            jitter=args.jitter,
            dropout=args.dropout,
            seed=args.seed,
            repair=not args.no_repair,
            quiet=args.quiet,
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
        ("parameters", ", ".join(f"{k}={v:g}" for k, v in shape.params.items()) or "-"),
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
        ("scan rows only", _scan_rows_only(res.meta.get("scan_rows_only"))),
        ("output", str(args.output)),
    ]
    print(_table(rows))
    return 0


def _scan_rows_only(left: list[dict] | None) -> str:
    """The sampling's curved faces that kept their scan rows (a sampling's
    ``meta["scan_rows_only"]``; None: every face, ``--no-repair``)."""
    if left is None:
        return "all (--no-repair)"
    if not left:
        return "none"
    faces = ", ".join(f"face {x['face']} ({x['kind']})" for x in left)
    return f"{faces} (no layout or chart takes them: Condition III not aimed at there)"


def _cmd_validate(args) -> int:
    import numpy as np
    from scipy.spatial import cKDTree

    from sr33.validators.intersections import self_intersections
    from sr33.validators.signature import homeomorphic, signature
    from sr33.validators.topology import mesh_stats

    from .io import read_mesh, read_points

    v, f = read_mesh(args.mesh)
    if f.shape[0] == 0:
        raise InputError(f"{args.mesh}: has no faces; validate needs a triangle mesh")
    sig = signature(f, v.shape[0], points=v)
    stats = mesh_stats(f, v.shape[0])
    crossing = self_intersections(v, f)
    rows = [("mesh", str(args.mesh))] + _stats_rows(stats)
    rows += [
        ("orientable", "yes" if sig.orientable else "NO"),
        ("genus per component", ", ".join(str(c.genus) for c in sig.components)),
        ("non-manifold vertices", str(sig.non_manifold_vertices.shape[0])),
        ("duplicate faces", str(sig.duplicate_faces)),
        ("degenerate faces", str(sig.degenerate_faces)),
        ("self-intersecting pairs", str(crossing.shape[0])),
    ]
    doc: dict = {"mesh": str(args.mesh), "stats": stats.as_dict()}
    if args.points:
        pts = read_points(args.points)
        d, _ = cKDTree(v).query(pts)
        missing = int((d > 1e-9 * max(1.0, float(np.abs(v).max()))).sum())
        rows.append(("input points not vertices", str(missing)))
        doc["points_not_vertices"] = missing
    ok = sig.manifold and sig.orientable and crossing.shape[0] == 0 and stats.overloaded_edges == 0
    ok = ok and not (args.points and missing)
    if args.json:
        from .io import TEXT_FORMATS

        _check_outputs([(args.json, TEXT_FORMATS, "text")], inputs=[args.mesh, args.truth])
    tv, tf = read_mesh(args.truth) if args.truth else (None, None)
    if args.truth:
        from sr33.validators.fidelity import hausdorff

        verdict = homeomorphic(sig, signature(tf, tv.shape[0], points=tv))
        spacing = float(np.median(cKDTree(v).query(v, 2)[0][:, 1]))
        fid = hausdorff(v, f, tv, tf, spacing=spacing, samples=5000)
        rows += [
            ("truth", str(args.truth)),
            ("homeomorphic to truth", "yes" if verdict else "NO"),
        ]
        rows += [("  reason", r) for r in verdict.reasons]
        rows += [
            ("Hausdorff / h", f"{fid.hausdorff_h:.4f}"),
            ("mean distance / h", f"{fid.mean_h:.4f}"),
        ]
        ok = bool(verdict) and crossing.shape[0] == 0 and fid.hausdorff_h <= 1.0
        ok = ok and not (args.points and missing)
        doc["homeomorphic"] = bool(verdict)
        doc["reasons"] = list(verdict.reasons)
        doc["hausdorff_h"] = fid.hausdorff_h
    if args.points:
        # the samples' Condition III: geodesic on the truth when there is one
        # (the verdict of `sr33 conditions`), else approximate; reported, not
        # part of the mesh's check
        from sr33.validators.conditions import condition_iii

        cond = condition_iii(pts, tv, tf, quiet=args.quiet)
        rows.append(("points' Condition III", cond.line()))
        doc["condition_iii"] = {
            "method": cond.method,
            "passed": cond.passed,
            "violating_samples": int(cond.violations.shape[0]),
            "worst_ratio": cond.max_ratio,
            "max_degree": cond.max_degree,
        }
    print(_table(rows))
    doc["ok"] = bool(ok)
    if args.json:
        from .io import write_text

        write_text(args.json, json.dumps(doc, indent=2) + "\n")
    return 0 if ok else 1


def _cmd_conditions(args) -> int:
    from sr33.validators.conditions import sample_conditions

    from .io import read_mesh, read_points

    pts = read_points(args.points)
    tv, tf = read_mesh(args.truth)
    if tf.shape[0] == 0:
        raise InputError(f"{args.truth}: has no faces; the truth must be a triangle mesh")
    try:
        rep = sample_conditions(pts, tv, tf, quiet=args.quiet)
    except ValueError as exc:
        raise InputError(str(exc)) from None
    width = max(len(r[0]) for r in rep.table())
    print(f"{'condition':<{width}}  {'result':<12}  {'measured':<10}  worst samples")
    rows = rep.table()
    for name, res, fig, worst in rows:
        print(f"{name:<{width}}  {res:<12}  {fig:<10}  {worst}")
    return 1 if any(res == "FAIL" for _, res, _, _ in rows) else 0


def _cmd_view(args) -> int:
    from sr33.gui import has_display, mesh_as_reconstruction, pyvista

    from .io import load_reconstruction, read_mesh

    if not args.screenshot and not has_display():
        raise InputError(
            "no display to open a window on; render off-screen with "
            "--screenshot out.png (sr33 view INPUT --screenshot out.png)"
        )
    pv = pyvista(off_screen=bool(args.screenshot))
    from sr33.gui import Inspector

    path = Path(args.input)
    rec = None
    if path.suffix.lower() == ".npz":
        rec = load_reconstruction(path)
        points = rec.vertices
    else:
        v, f = read_mesh(path)
        points = v
        if f.shape[0]:
            from .reconstruct import reconstruct

            rec = reconstruct(v, args.k) if args.reconstruct else mesh_as_reconstruction(v, f)
    truth = read_mesh(args.truth) if args.truth else None
    if truth is not None and truth[1].shape[0] == 0:
        raise InputError(f"{args.truth}: has no faces; the truth must be a triangle mesh")
    shape = (1, 2) if args.side_by_side else (1, 1)
    size = (1600, 800) if args.side_by_side else (1000, 800)
    plotter = pv.Plotter(off_screen=bool(args.screenshot), shape=shape, window_size=size)
    ins = Inspector(
        plotter, points, k=args.k, truth=truth, reconstruction=rec, widgets=not args.screenshot
    )
    try:
        for layer in args.show or []:
            ins.set_layer(layer, True)
        for layer in args.hide or []:
            ins.set_layer(layer, False)
    except ValueError as exc:
        raise InputError(f"--show/--hide: {exc}") from None
    if args.screenshot:
        from .io import atomic_output

        with atomic_output(args.screenshot, (".png",), "screenshot") as (tmp, _):
            ins.screenshot(tmp)
        print(f"screenshot written to {args.screenshot}")
        return 0
    plotter.show(title="sr33 inspector")
    return 0


# optional packages: module -> (extra that installs it, what it is for)
OPTIONAL = {
    "cadquery": ("cad", "CadQuery for the CAD shapes"),
    "OCP": ("cad", "CadQuery's OpenCascade for the CAD shapes"),
    "pyvista": ("vtk", "PyVista for rendering, .vtp files and surface distances"),
    "vtk": ("vtk", "VTK (through PyVista)"),
    "potpourri3d": ("validate", "potpourri3d for geodesics on the truth"),
}


class _DefaultsShown(argparse.ArgumentDefaultsHelpFormatter):
    """Shows real defaults in --help, not ``None`` or ``False`` for unset options."""

    def _get_help_string(self, action):
        if action.default in (None, False, argparse.SUPPRESS) or action.default == []:
            return action.help
        return super()._get_help_string(action)


def build_parser() -> argparse.ArgumentParser:
    from importlib.metadata import version

    common = argparse.ArgumentParser(add_help=False)
    common.add_argument(
        "-v",
        "--verbose",
        action="store_true",
        default=argparse.SUPPRESS,
        help="log step timings (debug) and show tracebacks of internal errors",
    )
    fmt = _DefaultsShown
    p = argparse.ArgumentParser(
        prog="sr33",
        description="Reconstruct surfaces with sharp features from point samples.",
        epilog=EXIT_CODES,
        formatter_class=argparse.RawDescriptionHelpFormatter,
        parents=[common],
    )
    p.add_argument("--version", action="version", version=f"sr33 {version('sr33')}")
    sub = p.add_subparsers(dest="command", required=True)

    def add(name, help_):
        return sub.add_parser(name, help=help_, parents=[common], formatter_class=fmt)

    r = add("reconstruct", "reconstruct a mesh from samples")
    r.add_argument("input", help="samples: .xyz .txt .npy or a mesh .ply .obj .off .stl .vtp")
    r.add_argument("-k", type=int, default=33, help="neighbourhood size")
    r.add_argument("-o", "--output", required=True, help="output mesh .ply .obj .off .stl .vtp")
    r.add_argument("--max-cycle-length", type=int, default=8, help="longest face cycle")
    r.add_argument("--budget", type=int, default=20000, help="search budget per component")
    r.add_argument(
        "--exact-seconds",
        type=float,
        default=5.0,
        help="exact selection budget per model of a failed component (closed, then "
        "with levels or open where needed), in CP-SAT "
        "deterministic time (about seconds of one core; the same on every machine; "
        "0 keeps the greedy answer)",
    )
    r.add_argument("--json", help="also write the summary as JSON here")
    r.add_argument("--save", help="also save the whole reconstruction (.npz) for sr33 view")
    r.add_argument("-q", "--quiet", action="store_true", help="no progress bars")
    r.set_defaults(func=_cmd_reconstruct)
    sm = add("sample", "scan-line samples of a sharp CAD shape")
    sm.add_argument(
        "shape", nargs="?", help="a library shape name (see --list) or a .step/.stp/.brep file"
    )
    sm.add_argument("--list", action="store_true", help="list shapes and their parameters")
    sm.add_argument("--param", action="append", default=[], metavar="KEY=VALUE")
    sm.add_argument("--spacing", type=float, help="scan-line spacing h (default: per shape)")
    sm.add_argument("--points", type=int, help="target number of samples instead of --spacing")
    sm.add_argument("--ratio", type=float, default=1.0, help="spacing along a line / h")
    sm.add_argument("--jitter", type=float, default=0.0, help="Gaussian noise sigma / h")
    sm.add_argument("--dropout", type=float, default=0.0, help="fraction of samples dropped")
    sm.add_argument("--seed", type=int, default=0)
    sm.add_argument(
        "--no-repair",
        action="store_true",
        help="plain scan rows: skip the boundary-layer repair at circular edges (faster)",
    )
    sm.add_argument("-o", "--output", help="points: .ply .xyz .txt .npy .obj .vtp")
    sm.add_argument("--truth", help="also write the ground-truth mesh here")
    sm.add_argument("--meta", help="also write the metadata as JSON here")
    sm.add_argument("-q", "--quiet", action="store_true", help="no progress bar")
    sm.set_defaults(func=_cmd_sample)
    va = add("validate", "topology, defects and fidelity of a mesh")
    va.add_argument("mesh")
    va.add_argument("--truth", help="ground-truth mesh: homeomorphism and Hausdorff distance")
    va.add_argument(
        "--points",
        help="the input samples: are they all vertices, and their Condition III "
        "(geodesic with --truth, else approximate)",
    )
    va.add_argument("--json", help="also write the report as JSON here")
    va.add_argument("-q", "--quiet", action="store_true", help="no progress bar")
    va.set_defaults(func=_cmd_validate)
    co = add("conditions", "measure the paper's sample conditions")
    co.add_argument("points")
    co.add_argument("--truth", required=True, help="ground-truth mesh, much finer than h")
    co.add_argument("-q", "--quiet", action="store_true", help="no progress bar")
    co.set_defaults(func=_cmd_conditions)
    vw = add("view", "inspect a reconstruction (PyVista window or screenshot)")
    vw.add_argument("input", help="points (reconstructed first), a mesh, or a saved .npz")
    vw.add_argument("--truth", help="ground-truth mesh, drawn translucent")
    vw.add_argument("-k", type=int, default=33, help="neighbourhood size")
    vw.add_argument("--screenshot", help="render off-screen to this PNG and exit")
    vw.add_argument("--side-by-side", action="store_true", help="truth in a second view")
    vw.add_argument(
        "--reconstruct",
        action="store_true",
        help="treat a mesh INPUT's vertices as samples and reconstruct them",
    )
    vw.add_argument("--show", action="append", help="turn a layer on (repeatable)")
    vw.add_argument("--hide", action="append", help="turn a layer off (repeatable)")
    vw.set_defaults(func=_cmd_view)
    s = add("stats", "print topology figures of a mesh")
    s.add_argument("mesh")
    s.set_defaults(func=_cmd_stats)
    return p


def _terminated(signum, frame):
    # SIGTERM unwinds like an exception: atomic outputs remove their temp file
    raise SystemExit(128 + signum)


def main(argv: list[str] | None = None) -> int:
    """Run the command line; returns the exit code (see ``EXIT_CODES``)."""
    import signal

    args = build_parser().parse_args(argv)
    verbose = getattr(args, "verbose", False)
    logging.basicConfig(
        level=logging.DEBUG if verbose else logging.WARNING,
        format="%(name)s: %(message)s",
    )
    logging.getLogger("numba").setLevel(logging.WARNING)
    try:
        previous = signal.signal(signal.SIGTERM, _terminated)
    except ValueError:  # not the main thread: leave signals alone
        previous = None
    try:
        code = args.func(args)
        sys.stdout.flush()  # a closed pipe shows here, not at exit
        return code
    except InputError as exc:
        print(f"sr33: error: {exc}", file=sys.stderr)
        return 2
    except ImportError as exc:
        root = (exc.name or "").split(".")[0]
        if root not in OPTIONAL:
            raise
        extra, what = OPTIONAL[root]
        print(
            f"sr33: error: {args.command} needs {what} ({root} is not installed): "
            f"pip install 'sr33[{extra}]'",
            file=sys.stderr,
        )
        return 2
    except KeyboardInterrupt:
        print("sr33: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:  # the reader of stdout went away (| head)
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        return 0
    except Exception as exc:  # noqa: BLE001 - the documented exit code 3
        if verbose:
            import traceback

            traceback.print_exc()
        print(
            f"sr33: internal error: {type(exc).__name__}: {exc} (run with -v for the traceback)",
            file=sys.stderr,
        )
        return 3
    finally:
        if previous is not None:
            signal.signal(signal.SIGTERM, previous)


if __name__ == "__main__":
    sys.exit(main())
