"""Progress bars and step timing shared by all pipeline steps."""

from __future__ import annotations

import logging
import sys
import time
from collections.abc import Iterator
from contextlib import contextmanager

from tqdm.auto import tqdm

log = logging.getLogger("sr33")


def bar(total: int, desc: str, quiet: bool, unit: str = "pt"):
    """A tqdm bar that is silent with ``quiet`` or when stderr is not a TTY."""
    return tqdm(total=total, desc=desc, disable=not shown(quiet), leave=False, unit=unit)


def chunks(n: int, parts: int = 50) -> Iterator[tuple[int, int]]:
    """Split ``range(n)`` into at most ``parts`` contiguous (start, stop) pieces."""
    step = max(1, -(-n // parts))
    for lo in range(0, n, step):
        yield lo, min(n, lo + step)


def shown(quiet: bool) -> bool:
    """Whether bars and notices go to stderr: not ``quiet`` and a terminal."""
    return not quiet and sys.stderr.isatty()


def notice(message: str, quiet: bool) -> None:
    """One line for the person at the terminal (above any bar), and the log."""
    log.info(message)
    if shown(quiet):
        tqdm.write(f"sr33: {message}", file=sys.stderr)


class Steps:
    """One bar over the named steps of a whole run (the long steps add their
    own bars below it); ``step`` also times and logs each step.

    Examples
    --------
    >>> timings = {}
    >>> with Steps(["a", "b"], quiet=True) as run:
    ...     with run.step("a", timings):
    ...         pass
    >>> list(timings)
    ['a']
    """

    def __init__(self, names: list[str], quiet: bool, desc: str = "sr33"):
        self.bar = tqdm(
            total=len(names), desc=desc, disable=not shown(quiet), leave=False, unit="step"
        )

    @contextmanager
    def step(self, name: str, timings: dict[str, float] | None = None):
        self.bar.set_postfix_str(name)
        with timed(name, timings):
            yield
        self.bar.update(1)

    def __enter__(self) -> Steps:
        return self

    def __exit__(self, *exc) -> None:
        self.bar.close()


@contextmanager
def timed(name: str, timings: dict[str, float] | None = None):
    """Time a block, log it at debug level and store it in ``timings``."""
    t0 = time.perf_counter()
    try:
        yield
    finally:
        dt = time.perf_counter() - t0
        log.debug("%s took %.4f s", name, dt)
        if timings is not None:
            timings[name] = timings.get(name, 0.0) + dt
