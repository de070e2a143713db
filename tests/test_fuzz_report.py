"""The `make fuzz` report sums the examples of every process and of every
saved run (issue 24 item 4).

Each test hands the examples it counted (``tests.fuzzstats``) to its report,
and the report sums the reports that arrive: with the tests spread over
pytest-xdist's workers (``make fuzz FUZZ_JOBS=2``) as in one process.  A
run's report saved (``FUZZ_OUT``) is merged with others' (``make
fuzz-merge``).  Run here on a small test file of four feature classes, in a
pytest of its own with the suite's conftest as a plugin.
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]

COUNTING = """
import pytest
from tests import fuzzstats

@pytest.mark.parametrize("feature", ["a", "b", "c", "d"])
def test_generated(feature):
    drawn = {"a": 3, "b": 4, "c": 5, "d": 6}[feature]
    for _ in range(drawn):
        fuzzstats.count(f"generated model ({feature})")
    for _ in range(drawn - 2):
        fuzzstats.count(f"conforming ({feature})")
        fuzzstats.count(f"homeomorphic ({feature})")
    fuzzstats.reject(f"generated model ({feature}) not conforming: III-ii")
    fuzzstats.reject("generated model (shared) not conforming: III-i")
"""


def _run(argv: list[str], **env: str) -> subprocess.CompletedProcess:
    """``python argv`` at the repository's root, the suite importable."""
    full = {**os.environ, "FUZZ_REPORT": "1", "PYTHONPATH": str(ROOT), **env}
    full.pop("HYPOTHESIS_PROFILE", None)
    return subprocess.run(
        [sys.executable, *argv], cwd=ROOT, env=full, capture_output=True, text=True, timeout=300
    )


def _report(tmp_path: Path, *args: str, **env: str) -> tuple[dict, dict]:
    """The feature-class table (class: drawn, conforming, homeomorphic) and
    the reasons' counts of the report of a pytest run over ``COUNTING``."""
    test = tmp_path / "test_generated.py"
    test.write_text(COUNTING)
    pytest_ = ["-m", "pytest", "-q", "-p", "no:cacheprovider", "-p", "tests.conftest"]
    run = _run(pytest_ + list(args) + [str(test)], **env)
    assert run.returncode == 0, run.stdout + run.stderr
    return _tables(run.stdout)


def _tables(out: str) -> tuple[dict, dict]:
    """A report's feature-class table and reasons' counts, read back."""
    rows = {
        m[1]: (int(m[2]), int(m[3]), int(m[4]))
        for m in re.finditer(r"^([abcd]) +(\d+) +(\d+) \(\d+%\) +(\d+) \(", out, re.M)
    }
    reasons = {m[2]: int(m[1]) for m in re.finditer(r"^ +(\d+)  (generated model .*)$", out, re.M)}
    return rows, reasons


@pytest.mark.parametrize("jobs", [[], ["-n", "2", "--dist", "load"]], ids=["one", "two"])
def test_the_fuzz_report_sums_the_examples_of_every_process(tmp_path, jobs):
    rows, reasons = _report(tmp_path, *jobs)
    assert rows == {"a": (3, 1, 1), "b": (4, 2, 2), "c": (5, 3, 3), "d": (6, 4, 4)}
    assert reasons["generated model (shared) not conforming: III-i"] == 4
    assert all(reasons[f"generated model ({c}) not conforming: III-ii"] == 1 for c in "abcd")


def test_saved_reports_of_two_runs_merge_into_one(tmp_path):
    one, two = tmp_path / "one.json", tmp_path / "two.json"
    first = _report(tmp_path, FUZZ_REPORT_JSON=str(one))
    _report(tmp_path, "-n", "2", "--dist", "load", FUZZ_REPORT_JSON=str(two))
    assert _tables(_run(["-m", "tests.fuzzstats", str(one)]).stdout) == first
    rows, reasons = _tables(_run(["-m", "tests.fuzzstats", str(one), str(two)]).stdout)
    assert rows == {"a": (6, 2, 2), "b": (8, 4, 4), "c": (10, 6, 6), "d": (12, 8, 8)}
    assert reasons["generated model (shared) not conforming: III-i"] == 8
    (tmp_path / "bad.json").write_text("{}")
    bad = _run(["-m", "tests.fuzzstats", str(one), str(tmp_path / "bad.json")])
    assert bad.returncode != 0
    assert bad.stderr.strip().endswith("bad.json: not a saved fuzz report ('report')")
