"""Counting examples per property, for the `make fuzz` report.

The counters of a test are handed to its report as it ends
(:func:`taken`, from ``conftest.pytest_runtest_makereport``) and summed
where the reports arrive (:func:`merge`, in ``pytest_runtest_logreport``):
in the one process of a plain run, and in the controller of a run spread
over workers (``make fuzz FUZZ_JOBS=2``, pytest-xdist), whose workers'
counters would otherwise never reach the report.

A run's report can be saved (``make fuzz FUZZ_OUT=run.json``: :func:`save`)
and the saved reports of several runs (other seeds, other sessions)
printed as one (``make fuzz-merge FUZZ_REPORTS="a.json b.json"``:
``python -m tests.fuzzstats a.json b.json``), so that a deep run too long
for one sitting is made in parts.
"""

import json
import sys
from collections import Counter

EXAMPLES: Counter = Counter()
REJECTED: Counter = Counter()  # generated inputs rejected, by reason
#: the counters of the tests whose reports arrived (what the report prints)
TOTAL_EXAMPLES: Counter = Counter()
TOTAL_REJECTED: Counter = Counter()
#: the key of the counters in a report's ``user_properties``
KEY = "fuzzstats"


def count(prop: str) -> None:
    """Record that one generated example of ``prop`` ran."""
    EXAMPLES[prop] += 1


def reject(reason: str) -> None:
    """Record that a generated input was rejected (``assume``) and why."""
    REJECTED[reason] += 1


def taken() -> tuple[dict, dict]:
    """The counters since the last call (examples, rejections), cleared."""
    out = (dict(EXAMPLES), dict(REJECTED))
    EXAMPLES.clear()
    REJECTED.clear()
    return out


def merge(user_properties) -> None:
    """Add the counters a report carries (:func:`taken`) to the totals."""
    for key, value in user_properties:
        if key == KEY:
            examples, rejected = value
            TOTAL_EXAMPLES.update(examples)
            TOTAL_REJECTED.update(rejected)


#: the properties whose examples the report counts under another name
_ALIASES = {
    "theorem_1_2_rng_equals_urquhart_on_smooth_patches": "theorem_1_2",
    "invariance_under_permutation_motion_and_scaling": "invariance",
    "robustness_result_or_documented_error": "robustness",
    "validator_soundness_planted_defects": "validator_soundness",
}


def report_lines(report: dict, examples: Counter, rejected: Counter) -> list[str]:
    """The `make fuzz` report: per property test (``report``: name ->
    [failed, seconds]) its examples and whether it failed; then per feature
    class of the generated models drawn, conforming (share), homeomorphic
    (share of the conforming), failed, seconds, and of the samplings that
    break only Condition II-i (a survey reconstructs them too) how many
    came out homeomorphic; then why the others did not conform (issue 24's
    report)."""
    out = ["", f"{'property':<72}{'examples':>9}{'failed':>8}{'seconds':>9}"]
    total = 0
    for name, (failed, secs) in report.items():
        base = name.split("[")[0].replace("test_", "", 1)
        key = name.split("[")[1].rstrip("]") if "[" in name else ""
        ex = examples.get(f"generated model ({key})") if "generated" in base else None
        ex = (
            ex
            or examples.get(name.replace("test_", "", 1))
            or examples.get(
                f"homeomorphism[{key}]"
                if "homeomorphism" in base or "sharp" in base
                else _ALIASES.get(base, base),
                0,
            )
        )
        out.append(f"{name:<72}{ex:>9}{'yes' if failed else '-':>8}{secs:>9.1f}")
        total += ex
    out.append(f"{'all properties':<72}{total:>9}")
    tag = "generated model ("
    classes = [k[len(tag) : -1] for k in examples if k.startswith(tag)]
    if not classes:
        return out
    out.append("")
    head = f"{'feature class':<18}{'drawn':>7}{'conforming':>12}{'homeomorphic':>14}"
    out.append(head + f"{'failed':>8}{'seconds':>9}{'beyond II-i':>13}")
    for c in classes:
        drawn = examples[f"generated model ({c})"]
        conf = examples[f"conforming ({c})"]
        homeo = examples[f"homeomorphic ({c})"]
        rows = [v for k, v in report.items() if "generated" in k and k.endswith(f"[{c}]")]
        failed = sum(r[0] for r in rows)
        secs = sum(r[1] for r in rows)
        share = f"{conf} ({100 * conf / drawn:.0f}%)" if drawn else "0"
        ok = f"{homeo} ({100 * homeo / conf:.0f}%)" if conf else "-"
        # a survey lists failures and checks that could not judge, not raises
        crashed = any(k.startswith(f"{tag}{c}) CHECK FAILED") for k in rejected)
        flag = "yes" if failed or homeo < conf or crashed else "-"
        # III-conforming samplings breaking only II-i (survey): homeomorphic / tried
        good = examples[f"beyond II-i, homeomorphic ({c})"]
        tried = good + sum(
            n for k, n in rejected.items() if k.startswith(f"beyond II-i, not homeomorphic ({c})")
        )
        beyond = f"{good}/{tried}" if tried else "-"
        out.append(f"{c:<18}{drawn:>7}{share:>12}{ok:>14}{flag:>8}{secs:>9.1f}{beyond:>13}")
    for reason, n in sorted(rejected.items()):
        if reason.startswith((tag, "beyond II-i")):
            out.append(f"  {n:>5}  {reason}")
    return out


def save(path: str, report: dict) -> None:
    """Write the run's report (``report`` and the totals) to ``path`` as
    JSON, atomically (:func:`sr33.io.write_text`)."""
    from sr33.io import write_text

    text = json.dumps(
        {"report": report, "examples": TOTAL_EXAMPLES, "rejected": TOTAL_REJECTED}, indent=1
    )
    write_text(path, text + "\n")


def merged(paths: list[str]) -> tuple[dict, Counter, Counter]:
    """The reports saved in ``paths`` (:func:`save`) summed: per property
    test its failures and seconds, the examples and the rejections."""
    report: dict[str, list] = {}
    examples, rejected = Counter(), Counter()
    for path in paths:
        try:
            with open(path) as f:
                saved = json.load(f)
            runs, ex, rej = saved["report"], saved["examples"], saved["rejected"]
        except (OSError, ValueError, KeyError, TypeError) as exc:
            raise SystemExit(f"{path}: not a saved fuzz report ({exc})") from None
        for name, (failed, secs) in runs.items():
            row = report.setdefault(name, [0, 0.0])
            row[0] += failed
            row[1] += secs
        examples.update(ex)
        rejected.update(rej)
    return report, examples, rejected


if __name__ == "__main__":
    if len(sys.argv) < 2:
        raise SystemExit("usage: python -m tests.fuzzstats REPORT.json [REPORT.json ...]")
    print("\n".join(report_lines(*merged(sys.argv[1:]))))
