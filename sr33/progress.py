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
    disable = quiet or not sys.stderr.isatty()
    return tqdm(total=total, desc=desc, disable=disable, leave=False, unit=unit)


def chunks(n: int, parts: int = 50) -> Iterator[tuple[int, int]]:
    """Split ``range(n)`` into at most ``parts`` contiguous (start, stop) pieces."""
    step = max(1, -(-n // parts))
    for lo in range(0, n, step):
        yield lo, min(n, lo + step)


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
