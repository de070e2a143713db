"""The import contract of the ``sr33`` namespace, checked on the source.

The four folders install as one namespace (``pyproject.toml``)::

    sr33/        -> sr33              the reconstruction (and its low layer)
    validators/  -> sr33.validators   judges any mesh
    samplers/    -> sr33.samplers     CAD shapes and their samplings
    gui/         -> sr33.gui          the inspector

Every module belongs to one layer (:func:`layer_of`); ``ALLOWED`` says
which layers a layer may import.  :func:`violations` walks every ``import``
and ``from ... import`` of every module (at module level and inside
functions: a lazy import is still a dependency) and reports

* an import of a layer that ``ALLOWED`` does not list;
* a private name (``_x``) imported from another module, or any name from a
  private module (``_x.py``) of another package;
* an import cycle among the modules (the package hubs ``__init__.py``,
  which re-export their modules, excepted as targets).

Tests and benchmarks are outside the contract.
"""

from __future__ import annotations

import ast
from dataclasses import dataclass
from pathlib import Path

from scipy.sparse import csr_matrix
from scipy.sparse.csgraph import connected_components

ROOT = Path(__file__).resolve().parents[1]
FOLDERS = {
    "sr33": "sr33",
    "validators": "sr33.validators",
    "samplers": "sr33.samplers",
    "gui": "sr33.gui",
}

# the low layer: mesh primitives (and their numba kernels), neighbours with
# their ties, progress bars and step timing
BASE = {
    "sr33.mesh",
    "sr33.neighbours",
    "sr33.progress",
    "sr33._intersect",
    "sr33._edges",
    "sr33.jit",
    "sr33.libm",
}
TOP = {"sr33", "sr33.cli"}  # the hub and the command line see everything

ALLOWED = {
    "base": {"base"},
    "reconstruction": {"base", "reconstruction"},
    "validators": {"base", "validators"},
    "samplers": {"base", "samplers"},
    "gui": {"base", "reconstruction", "validators", "gui"},
    "top": {"base", "reconstruction", "validators", "samplers", "gui", "top"},
}


@dataclass(frozen=True)
class Import:
    """One imported name: ``module`` imports ``name`` (None: the module itself)
    from ``target`` at ``line``."""

    module: str
    target: str
    name: str | None
    line: int


def layer_of(module: str) -> str:
    """The layer of a module of the namespace."""
    if module in BASE:
        return "base"
    if module in TOP:
        return "top"
    for sub in ("validators", "samplers", "gui"):
        if module == f"sr33.{sub}" or module.startswith(f"sr33.{sub}."):
            return sub
    return "reconstruction"


def modules(root: Path = ROOT, folders: dict[str, str] = FOLDERS) -> dict[str, Path]:
    """Every module of the namespace and its file."""
    out = {}
    for folder, package in folders.items():
        for path in sorted((root / folder).rglob("*.py")):
            rel = path.relative_to(root / folder).with_suffix("")
            parts = [] if rel.parts == ("__init__",) else list(rel.parts)
            if parts and parts[-1] == "__init__":
                parts = parts[:-1]
            out[".".join([package, *parts])] = path
    return out


def imports(module: str, path: Path, known: set[str]) -> list[Import]:
    """The imports of one module that name modules of the namespace."""
    package = module if path.name == "__init__.py" else module.rpartition(".")[0]
    out = []
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        if isinstance(node, ast.Import):
            for alias in node.names:
                if alias.name.split(".")[0] == "sr33":
                    out.append(Import(module, alias.name, None, node.lineno))
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")
                base = base[: len(base) - node.level + 1]
                source = ".".join(base + ([node.module] if node.module else []))
            else:
                source = node.module or ""
            if source.split(".")[0] != "sr33":
                continue
            for alias in node.names:
                sub = f"{source}.{alias.name}"
                if sub in known:  # ``from package import module``
                    out.append(Import(module, sub, None, node.lineno))
                else:
                    out.append(Import(module, source, alias.name, node.lineno))
    return out


def _package(module: str, known: dict[str, Path]) -> str:
    """The package a module is in (a package ``__init__`` is in itself)."""
    return module if known[module].name == "__init__.py" else module.rpartition(".")[0]


def violations(root: Path = ROOT, folders: dict[str, str] = FOLDERS) -> list[str]:
    """Every breach of the contract, one line each (empty when it holds)."""
    known = modules(root, folders)
    found = []
    edges = []
    for module, path in known.items():
        for imp in imports(module, path, set(known)):
            where = f"{known[module].relative_to(root)}:{imp.line}"
            if imp.target not in known:
                found.append(f"{where}: {module} imports {imp.target}, which does not exist")
                continue
            a, b = layer_of(module), layer_of(imp.target)
            if b not in ALLOWED[a]:
                found.append(f"{where}: {module} ({a}) imports {imp.target} ({b})")
            leaf = imp.target.rpartition(".")[2]
            own = _package(module, known)
            if (
                leaf.startswith("_")
                and not leaf.startswith("__")
                and (_package(imp.target, known) != own)
            ):
                found.append(f"{where}: {module} imports the private module {imp.target}")
            if imp.name is not None and imp.name.startswith("_") and imp.target != module:
                found.append(
                    f"{where}: {module} imports the private name {imp.name} from {imp.target}"
                )
            if known[imp.target].name != "__init__.py" and imp.target != module:
                edges.append((module, imp.target))
    found = list(dict.fromkeys(found))  # one line per breach, in order
    return found + _cycles(sorted(known), edges)


def _cycles(names: list[str], edges: list[tuple[str, str]]) -> list[str]:
    """One line per strongly connected group of more than one module."""
    if not edges:
        return []
    index = {n: i for i, n in enumerate(names)}
    rows = [index[a] for a, _ in edges]
    cols = [index[b] for _, b in edges]
    g = csr_matrix(([1] * len(rows), (rows, cols)), shape=(len(names), len(names)))
    count, label = connected_components(g, directed=True, connection="strong")
    out = []
    for c in range(count):
        group = [names[i] for i in range(len(names)) if label[i] == c]
        if len(group) > 1:
            out.append("import cycle: " + " <-> ".join(group))
    return out
