"""The import contract (``tests/import_contract.py``) holds, and catches breaches."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from tests.import_contract import ROOT, layer_of, violations


def test_the_namespace_keeps_its_contract():
    assert violations() == []


def test_layers_are_read_off_module_names():
    assert layer_of("sr33.mesh") == "base"
    assert layer_of("sr33.backtracking") == "reconstruction"
    assert layer_of("sr33.validators.signature") == "validators"
    assert layer_of("sr33.samplers.repair") == "samplers"
    assert layer_of("sr33.gui.inspector") == "gui"
    assert layer_of("sr33.cli") == "top"


def _tree(tmp_path: Path, files: dict[str, str]) -> Path:
    for folder in ("sr33", "validators", "samplers", "gui"):
        (tmp_path / folder).mkdir()
        (tmp_path / folder / "__init__.py").write_text("")
    for name, text in files.items():
        (tmp_path / name).write_text(text)
    return tmp_path


@pytest.mark.parametrize(
    "files, expected",
    [
        (  # the reconstruction imports a validator (module level or lazily)
            {
                "sr33/rng.py": "def f():\n    from sr33.validators.topology import mesh_stats\n",
                "validators/topology.py": "mesh_stats = 1\n",
            },
            "sr33/rng.py:2: sr33.rng (reconstruction) imports "
            "sr33.validators.topology (validators)",
        ),
        (  # a validator imports the reconstruction through a relative import
            {
                "validators/signature.py": "from .. import backtracking\n",
                "sr33/backtracking.py": "",
            },
            "validators/signature.py:1: sr33.validators.signature (validators) imports "
            "sr33.backtracking (reconstruction)",
        ),
        (  # a sampler takes a constant from the validators
            {
                "samplers/repair.py": "from sr33.validators.conditions import SQRT3_2\n",
                "validators/conditions.py": "SQRT3_2 = 0.8\n",
            },
            "samplers/repair.py:1: sr33.samplers.repair (samplers) imports "
            "sr33.validators.conditions (validators)",
        ),
        (  # a private name of a sibling module
            {
                "samplers/disks.py": "from .layers import _goes_round\n",
                "samplers/layers.py": "def _goes_round(): pass\n",
            },
            "samplers/disks.py:1: sr33.samplers.disks imports the private name _goes_round "
            "from sr33.samplers.layers",
        ),
        (  # a private module of another package
            {"sr33/cli.py": "from sr33.gui._pv import pyvista\n", "gui/_pv.py": "pyvista = 1\n"},
            "sr33/cli.py:1: sr33.cli imports the private module sr33.gui._pv",
        ),
        (  # two modules importing each other, one of them lazily
            {
                "samplers/scanline.py": "def f():\n    from .layers import g\n",
                "samplers/layers.py": "from .scanline import f\n",
            },
            "import cycle: sr33.samplers.layers <-> sr33.samplers.scanline",
        ),
    ],
)
def test_each_kind_of_breach_is_reported(tmp_path, files, expected):
    assert expected in violations(_tree(tmp_path, files))


def test_allowed_imports_are_not_reported(tmp_path):
    """A package's own private kernel module, the low layer from every
    layer, the validators and the reconstruction from the gui."""
    root = _tree(
        tmp_path,
        {
            "sr33/mesh.py": "import numpy as np\n",
            "sr33/_kernels.py": "",
            "sr33/rng.py": "from . import _kernels\nfrom ._kernels import k\nfrom .mesh import a\n",
            "validators/topology.py": "from sr33.mesh import np\n",
            "samplers/scanline.py": "def f():\n    from sr33 import mesh\n",
            "gui/inspector.py": "from sr33.rng import np\nfrom sr33.validators import topology\n",
        },
    )
    assert violations(root) == []


def test_a_forbidden_import_added_to_the_real_tree_fails_the_contract(tmp_path):
    """The check run on a copy of the source with one bad import added."""
    import shutil

    for folder in ("sr33", "validators", "samplers", "gui"):
        skip = shutil.ignore_patterns("__pycache__")
        shutil.copytree(ROOT / folder, tmp_path / folder, ignore=skip)
    target = tmp_path / "sr33" / "triangulate.py"
    target.write_text(target.read_text() + "\nfrom sr33.validators.signature import signature\n")
    found = violations(tmp_path)
    assert len(found) == 1, found
    assert "sr33.triangulate (reconstruction) imports sr33.validators.signature" in found[0]


def test_the_folders_import_only_by_their_installed_names():
    code = (
        "import sr33.validators, sr33.samplers, sr33.gui\n"
        "try:\n    import validators\nexcept ImportError as e:\n    print('refused:', e)\n"
        "else:\n    print('imported', validators.__file__)\n"
    )
    for cwd in (ROOT, ROOT / "tests"):
        out = subprocess.run(
            [sys.executable, "-c", code], cwd=cwd, capture_output=True, text=True, check=True
        ).stdout
        assert out.startswith("refused:") or ("imported" in out and str(ROOT) not in out), out
