"""numba, as every kernel module of sr33 uses it: cached where it can be,
announced when it compiles.

The low layer (``sr33._intersect``), the reconstruction's kernels
(``sr33._kernels``) and the sampler's (``sr33.samplers._repair_kernels``) all
compile through :func:`njit` here, so that one fallback (no cache folder)
covers them all, and one notice the reconstruction's.
"""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager

from numba import njit as _njit

#: modules whose kernels :func:`compile_notice` announces
KERNEL_MODULES = ("sr33._kernels", "sr33._intersect")


def njit(*args, **kwargs):
    """``numba.njit`` with ``cache=True`` where numba can cache: when neither
    the package folder nor a user cache folder (``$NUMBA_CACHE_DIR``,
    ``~/.cache``) is writable, numba refuses ``cache=True`` at import; the
    kernels then compile once per process instead."""

    def wrap(fn):
        try:
            d = _njit(**kwargs)(fn)
        except RuntimeError:  # "cannot cache function ...: no locator available"
            kwargs.pop("cache", None)
            d = _njit(**kwargs)(fn)
        return d

    return wrap(args[0]) if args and callable(args[0]) else wrap


@contextmanager
def compile_notice(notify) -> Iterator[None]:
    """Within the block, call ``notify()`` once when numba starts compiling a
    kernel of sr33 (a first run, or a cache that does not fit this machine:
    about 13 s for all of them); loading a cached kernel is silent."""
    from numba.core import event

    told = []

    class _Listener(event.Listener):
        def on_start(self, ev):
            d = ev.data.get("dispatcher") if ev.data else None
            fn = getattr(d, "py_func", None)
            if not told and getattr(fn, "__module__", None) in KERNEL_MODULES:
                told.append(True)
                notify()

        def on_end(self, ev):
            pass

    with event.install_listener("numba:compile", _Listener()):
        yield
