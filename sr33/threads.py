"""The thread pool of the reconstruction: numba's thread count, ordered results.

Work split over threads here is always independent pieces whose results
are put together in their given order (numba kernels compiled ``nogil``,
CP-SAT models solved on one worker each), so the output does not depend
on the number of threads.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Iterator
from typing import TypeVar

T = TypeVar("T")
R = TypeVar("R")


def thread_count() -> int:
    """Threads to use: numba's (``NUMBA_NUM_THREADS``, by default the cores)."""
    import numba

    return max(1, int(numba.get_num_threads()))


def thread_map(fn: Callable[[T], R], items: Iterable[T], *, order=None) -> Iterator[R]:
    """``fn`` over ``items`` on :func:`thread_count` threads, results in the
    order of ``items``.

    Parameters
    ----------
    fn : callable
        Releases the GIL for most of its time to gain anything.
    items : iterable
    order : sequence of int, optional
        The order to start the items in (e.g. the longest first); the
        results still come in the order of ``items``.

    Yields
    ------
    The results, in the order of ``items``.
    """
    items = list(items)
    jobs = min(len(items), thread_count())
    if jobs <= 1:
        yield from (fn(x) for x in items)
        return
    from concurrent.futures import ThreadPoolExecutor

    start = list(range(len(items))) if order is None else list(order)
    with ThreadPoolExecutor(jobs) as pool:
        futures = {i: pool.submit(fn, items[i]) for i in start}
        for i in range(len(items)):
            yield futures[i].result()
