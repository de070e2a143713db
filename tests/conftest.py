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
    from tests.fuzzstats import TOTAL_EXAMPLES as EXAMPLES

    tr = terminalreporter
    tr.write_line("")
    tr.write_line(f"{'property':<72}{'examples':>9}{'failed':>8}{'seconds':>9}")
    total = 0
    for name, (failed, secs) in _REPORT.items():
        base = name.split("[")[0].replace("test_", "", 1)
        key = name.split("[")[1].rstrip("]") if "[" in name else ""
        ex = EXAMPLES.get(f"generated model ({key})") if "generated" in base else None
        ex = (
            ex
            or EXAMPLES.get(name.replace("test_", "", 1))
            or EXAMPLES.get(
                f"homeomorphism[{key}]"
                if "homeomorphism" in base or "sharp" in base
                else {
                    "theorem_1_2_rng_equals_urquhart_on_smooth_patches": "theorem_1_2",
                    "invariance_under_permutation_motion_and_scaling": "invariance",
                    "robustness_result_or_documented_error": "robustness",
                    "validator_soundness_planted_defects": "validator_soundness",
                }.get(base, base),
                0,
            )
        )
        tr.write_line(f"{name:<72}{ex:>9}{'yes' if failed else '-':>8}{secs:>9.1f}")
        total += ex
    tr.write_line(f"{'all properties':<72}{total:>9}")
    _generated_report(tr)


def _generated_report(tr) -> None:
    """Per feature class of the generated models: drawn, conforming (share),
    homeomorphic (share of the conforming), failed, seconds, and of the
    samplings that break only Condition II-i (a survey reconstructs them too)
    how many came out homeomorphic; then why the others did not conform
    (issue 24's report)."""
    from tests.fuzzstats import TOTAL_EXAMPLES as EXAMPLES
    from tests.fuzzstats import TOTAL_REJECTED as REJECTED

    tag = "generated model ("
    classes = [k[len(tag) : -1] for k in EXAMPLES if k.startswith(tag)]
    if not classes:
        return
    tr.write_line("")
    head = f"{'feature class':<18}{'drawn':>7}{'conforming':>12}{'homeomorphic':>14}"
    tr.write_line(head + f"{'failed':>8}{'seconds':>9}{'beyond II-i':>13}")
    for c in classes:
        drawn = EXAMPLES[f"generated model ({c})"]
        conf = EXAMPLES[f"conforming ({c})"]
        homeo = EXAMPLES[f"homeomorphic ({c})"]
        rows = [v for k, v in _REPORT.items() if "generated" in k and k.endswith(f"[{c}]")]
        failed = sum(r[0] for r in rows)
        secs = sum(r[1] for r in rows)
        share = f"{conf} ({100 * conf / drawn:.0f}%)" if drawn else "0"
        ok = f"{homeo} ({100 * homeo / conf:.0f}%)" if conf else "-"
        # a survey lists failures and checks that could not judge, not raises
        crashed = any(k.startswith(f"{tag}{c}) CHECK FAILED") for k in REJECTED)
        flag = "yes" if failed or homeo < conf or crashed else "-"
        # III-conforming samplings breaking only II-i (survey): homeomorphic / tried
        good = EXAMPLES[f"beyond II-i, homeomorphic ({c})"]
        tried = good + sum(
            n for k, n in REJECTED.items() if k.startswith(f"beyond II-i, not homeomorphic ({c})")
        )
        beyond = f"{good}/{tried}" if tried else "-"
        tr.write_line(f"{c:<18}{drawn:>7}{share:>12}{ok:>14}{flag:>8}{secs:>9.1f}{beyond:>13}")
    for reason, n in sorted(REJECTED.items()):
        if reason.startswith((tag, "beyond II-i")):
            tr.write_line(f"  {n:>5}  {reason}")
