"""The ``>>>`` examples of every module of the installed namespace run and pass.

pytest's ``--doctest-modules`` imports a file by its folder's name
(``validators/topology.py`` as ``validators.topology``), which is not how
the folders install; here each module is imported by its installed name.
"""

from __future__ import annotations

import doctest
import importlib
import pkgutil

import pytest

PACKAGES = ("sr33", "sr33.validators", "sr33.samplers", "sr33.gui")


def _module_names() -> list[str]:
    out = []
    for name in PACKAGES:
        pkg = importlib.import_module(name)
        out.append(name)
        for info in pkgutil.iter_modules(pkg.__path__, prefix=f"{name}."):
            if info.name not in PACKAGES:
                out.append(info.name)
    return sorted(out)


MODULES = _module_names()


def test_the_walk_finds_every_package_and_module():
    some = {"sr33.rng", "sr33.validators.topology", "sr33.samplers.repair", "sr33.gui.inspector"}
    assert some <= set(MODULES)
    assert not any(name.split(".")[0] != "sr33" for name in MODULES)


@pytest.mark.parametrize("name", MODULES)
def test_examples_in_docstrings_pass(name):
    module = importlib.import_module(name)
    finder = doctest.DocTestFinder(exclude_empty=True)
    runner = doctest.DocTestRunner(optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE)
    out: list[str] = []
    for test in finder.find(module, name):
        runner.run(test, out=out.append)
    result = runner.summarize(verbose=False)
    assert result.failed == 0, "".join(out)
