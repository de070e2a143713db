"""Counting examples per property, for the `make fuzz` report."""

from collections import Counter

EXAMPLES: Counter = Counter()
REJECTED: Counter = Counter()  # generated inputs rejected, by reason


def count(prop: str) -> None:
    """Record that one generated example of ``prop`` ran."""
    EXAMPLES[prop] += 1


def reject(reason: str) -> None:
    """Record that a generated input was rejected (``assume``) and why."""
    REJECTED[reason] += 1
