"""Transcendental functions that give the same bits on every x86-64 machine.

numpy picks its elementwise loops by the processor it runs on: on a
processor with AVX-512 its ``arctan2``, ``arccos``, ``arctan``, ``tan`` and
``cbrt`` run SIMD code whose results differ from the C library's in the
last bit for some inputs (measured on an AVX-512 machine, numpy 2.4:
``arctan2`` on 7.7 % of random inputs, ``arccos`` on 9.5 %, ``cbrt`` on
56 %), while on a processor without it they are the C library's.  A
sampling is a local search whose end can turn on a last bit, and the
project promises the same bytes on every machine: the samplers, the
validators and the reconstruction take these functions from here, numba
loops calling the C library (``sin``, ``cos``, ``sqrt`` and ``hypot`` are
the C library's in numpy on both, and stay numpy's).

Every function takes arrays (or scalars) that broadcast, as numpy's do, and
returns float64 arrays (a numpy float for scalars).
"""

from __future__ import annotations

import numpy as np

from sr33.jit import njit

#: the one-argument functions, by their code in :func:`_unary`
ACOS, ATAN, TAN, CBRT = 0, 1, 2, 3


@njit(cache=True)
def _unary(op, x):
    out = np.empty(x.size)
    for i in range(x.size):
        if op == ACOS:
            out[i] = np.arccos(x[i])
        elif op == ATAN:
            out[i] = np.arctan(x[i])
        elif op == TAN:
            out[i] = np.tan(x[i])
        else:
            out[i] = np.cbrt(x[i])
    return out


@njit(cache=True)
def _atan2(y, x):
    out = np.empty(y.size)
    for i in range(y.size):
        out[i] = np.arctan2(y[i], x[i])
    return out


def _flat(*args):
    arrays = np.broadcast_arrays(*(np.asarray(a, dtype=np.float64) for a in args))
    shape = arrays[0].shape
    return shape, [np.ascontiguousarray(a).ravel() for a in arrays]


def arctan2(y, x) -> np.ndarray:
    """``np.arctan2(y, x)`` as the C library computes it (see the module)."""
    shape, (yy, xx) = _flat(y, x)
    return _atan2(yy, xx).reshape(shape)[()]


def arccos(x) -> np.ndarray:
    """``np.arccos(x)`` as the C library computes it (see the module)."""
    shape, (xx,) = _flat(x)
    return _unary(ACOS, xx).reshape(shape)[()]


def arctan(x) -> np.ndarray:
    """``np.arctan(x)`` as the C library computes it (see the module)."""
    shape, (xx,) = _flat(x)
    return _unary(ATAN, xx).reshape(shape)[()]


def tan(x) -> np.ndarray:
    """``np.tan(x)`` as the C library computes it (see the module)."""
    shape, (xx,) = _flat(x)
    return _unary(TAN, xx).reshape(shape)[()]


def cbrt(x) -> np.ndarray:
    """``np.cbrt(x)`` as the C library computes it (see the module)."""
    shape, (xx,) = _flat(x)
    return _unary(CBRT, xx).reshape(shape)[()]
