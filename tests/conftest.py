"""Hypothesis profiles: ``ci`` (default, few derandomized examples) and ``deep``."""

import os

import pytest

# every reconstruction in the suite runs the expensive self-checks
os.environ["SR33_STRICT"] = "1"

from hypothesis import HealthCheck, settings

settings.register_profile(
    "ci",
    max_examples=40,
    deadline=None,
    derandomize=True,
    suppress_health_check=[HealthCheck.too_slow],
)
settings.register_profile("deep", max_examples=1000, deadline=None)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "ci"))


# --- `make fuzz` report: property, examples run, failures, seconds ------------
_REPORT: dict[str, list[float]] = {}


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_makereport(item, call):
    """Hand the examples a test counted to its report (``tests.fuzzstats``),
    so that they reach the report from pytest-xdist's workers too."""
    outcome = yield
    if call.when == "call":
        from tests import fuzzstats

        outcome.get_result().user_properties.append((fuzzstats.KEY, fuzzstats.taken()))


def pytest_runtest_logreport(report):
    if report.when == "call":
        from tests import fuzzstats

        fuzzstats.merge(report.user_properties)
    if report.when != "call" or not any(
        f in report.nodeid for f in ("test_properties.py", "test_fuzz.py", "test_generated.py")
    ):
        return
    name = report.nodeid.split("::", 1)[1]
    row = _REPORT.setdefault(name, [0, 0.0])
    row[0] += 0 if report.outcome == "passed" else 1
    row[1] += report.duration


def pytest_terminal_summary(terminalreporter):
    if not os.environ.get("FUZZ_REPORT") or not _REPORT:
        return
    from tests import fuzzstats

    tr = terminalreporter
    for line in fuzzstats.report_lines(_REPORT, fuzzstats.TOTAL_EXAMPLES, fuzzstats.TOTAL_REJECTED):
        tr.write_line(line)
    saved = os.environ.get("FUZZ_REPORT_JSON")
    if saved:
        fuzzstats.save(saved, _REPORT)
        tr.write_line(f"report saved to {saved} (merge runs: make fuzz-merge FUZZ_REPORTS=...)")
