"""Counting examples per property, for the `make fuzz` report.

The counters of a test are handed to its report as it ends
(:func:`taken`, from ``conftest.pytest_runtest_makereport``) and summed
where the reports arrive (:func:`merge`, in ``pytest_runtest_logreport``):
in the one process of a plain run, and in the controller of a run spread
over workers (``make fuzz FUZZ_JOBS=2``, pytest-xdist), whose workers'
counters would otherwise never reach the report.
"""

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
