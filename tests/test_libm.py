"""sr33.libm: the C library's transcendental functions, whatever numpy's
processor-dependent loops give (on AVX-512 numpy's arctan2 and arccos differ
from them in the last bit), so that a sampling is the same bytes on every
machine."""

import ctypes
import ctypes.util
import math
import os
import subprocess
import sys

import numpy as np
import pytest

from sr33 import libm

C = ctypes.CDLL(ctypes.util.find_library("m") or "libm.so.6")
SIGNATURES = {"atan2": 2, "acos": 1, "atan": 1, "tan": 1, "cbrt": 1}
for _name, _arity in SIGNATURES.items():
    getattr(C, _name).restype = ctypes.c_double
    getattr(C, _name).argtypes = [ctypes.c_double] * _arity

SPECIAL = np.array([0.0, -0.0, 1.0, -1.0, np.inf, -np.inf, np.nan, 1e-300, -1e300, 0.5])


def inputs(seed: int, scale: float) -> np.ndarray:
    rng = np.random.default_rng(seed)
    return np.r_[rng.uniform(-scale, scale, 20000), SPECIAL]


def same_bits(a, b) -> bool:
    return np.asarray(a, dtype=np.float64).tobytes() == np.asarray(b, dtype=np.float64).tobytes()


@pytest.mark.parametrize(
    "ours,theirs,scale",
    [
        (libm.arccos, "acos", 1.0),
        (libm.arctan, "atan", 20.0),
        (libm.tan, "tan", 3.0),
        (libm.cbrt, "cbrt", 50.0),
    ],
)
def test_one_argument_functions_are_the_c_librarys_bit_for_bit(ours, theirs, scale):
    x = inputs(1, scale)
    expected = np.array([getattr(C, theirs)(v) for v in x])
    assert same_bits(ours(x), expected)


def test_arctan2_is_the_c_librarys_bit_for_bit_and_broadcasts():
    y, x = inputs(2, 10.0), inputs(3, 10.0)[::-1].copy()
    expected = np.array([C.atan2(a, b) for a, b in zip(y, x)])
    assert same_bits(libm.arctan2(y, x), expected)
    grid = libm.arctan2(np.ones((2, 1)), np.array([1.0, -1.0, 0.0]))
    assert grid.shape == (2, 3)
    assert same_bits(grid[1], [C.atan2(1.0, 1.0), C.atan2(1.0, -1.0), C.atan2(1.0, 0.0)])
    scalar = libm.arctan2(1.0, 2.0)
    assert isinstance(scalar, np.floating) and scalar == math.atan2(1.0, 2.0)
    assert libm.arccos(np.empty((0, 2))).shape == (0, 2)


def numpy_differs_from_the_c_library() -> bool:
    # (contiguous arrays: numpy's SIMD loops take those only, so that even
    # the layout of the input chose the bits)
    x = np.random.default_rng(0).uniform(-10, 10, 4000)
    y = x[::-1].copy()
    return bool((np.arctan2(x, y) != np.array([C.atan2(a, b) for a, b in zip(x, y)])).any())


SAMPLE = """
import hashlib, sys, ctypes
import numpy as np
from sr33.samplers import shapes
from sr33.samplers.scanline import scan
c = ctypes.CDLL("libm.so.6"); c.atan2.restype = ctypes.c_double
c.atan2.argtypes = [ctypes.c_double, ctypes.c_double]
x = np.random.default_rng(0).uniform(-10, 10, 4000)
y = x[::-1].copy()
plain = not (np.arctan2(x, y) != np.array([c.atan2(a, b) for a, b in zip(x, y)])).any()
s = scan(shapes.build("cone"), target_points=2000)
print(plain, hashlib.sha256(s.points.tobytes()).hexdigest())
"""


@pytest.mark.skipif(
    not numpy_differs_from_the_c_library(),
    reason="numpy's arctan2 is the C library's on this processor: nothing to compare",
)
def test_a_sampling_is_the_same_bytes_with_numpys_avx512_loops_off():
    """numpy told to leave its AVX-512 loops (as on a processor without
    them): the same cone sampling, bit for bit (a cone's rings and repairs
    take their angles by arctan2; before :mod:`sr33.libm` the two differed)."""
    out = {}
    for off in ("", "AVX512_ICL X86_V4"):
        env = {**os.environ, "NPY_DISABLE_CPU_FEATURES": off}
        run = subprocess.run(
            [sys.executable, "-c", SAMPLE], env=env, capture_output=True, text=True, check=True
        )
        out[off] = run.stdout.split()[-2:]
    assert out[""][0] == "False"  # numpy's own loops differ here ...
    assert out["AVX512_ICL X86_V4"][0] == "True"  # ... and are the C library's without AVX-512
    assert out[""][1] == out["AVX512_ICL X86_V4"][1]


#: numpy functions whose loops differ from the C library's on some processors
#: (measured on AVX-512, numpy 2.4: the angles, and exp, log, log10, log1p,
#: expm1, sinh, tanh); sin, cos, sqrt and hypot are the C library's on both
DISPATCHED = (
    "arctan2",
    "arccos",
    "arcsin",
    "arctan",
    "tan",
    "cbrt",
    "exp",
    "expm1",
    "log",
    "log10",
    "log2",
    "log1p",
    "sinh",
    "cosh",
    "tanh",
    "power",
)


def test_no_module_takes_a_processor_dependent_function_from_numpy():
    """Outside numba kernels (which call the C library), the package takes
    these functions from :mod:`sr33.libm`, never from numpy: a sampling
    must be the same bytes on every processor."""
    import re
    from pathlib import Path

    root = Path(__file__).resolve().parents[1]
    pattern = re.compile(r"\bnp\.(" + "|".join(DISPATCHED) + r")\(")
    found = []
    for folder in ("sr33", "samplers", "validators", "gui"):
        for path in sorted((root / folder).rglob("*.py")):
            source = path.read_text()
            # numba kernels: their numpy calls are numba's, the C library's
            if path.name == "libm.py" or "@njit" in source:
                continue
            for k, line in enumerate(source.splitlines(), 1):
                if pattern.search(line):
                    found.append(f"{path.relative_to(root)}:{k}: {line.strip()}")
    assert not found, "\n".join(found)
