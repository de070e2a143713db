"""Counting examples per property, for the `make fuzz` report."""

from collections import Counter

EXAMPLES: Counter = Counter()


def count(prop: str) -> None:
    """Record that one generated example of ``prop`` ran."""
    EXAMPLES[prop] += 1
