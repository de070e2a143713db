"""Real-world input (issue 22): offsets, magnitudes and outliers never break,
hang or silently change the result."""

import subprocess
import sys
import textwrap

import numpy as np
import pytest

from sr33 import reconstruct
from sr33.io import read_points
from sr33.samplers import cube_lattice
from sr33.validators import mesh_stats
from tests.helpers import MESHES, need, triangle_set


def _in_subprocess(code: str, timeout: float = 120.0) -> str:
    """Run ``code`` in a fresh interpreter (a hang fails instead of blocking
    the suite); returns its stdout."""
    out = subprocess.run(
        [sys.executable, "-c", textwrap.dedent(code)],
        capture_output=True,
        text=True,
        timeout=timeout,
        check=True,
    )
    return out.stdout


def test_a_georeferenced_offset_gives_the_triangles_of_the_centred_run():
    # spot translated as a georeferenced scan is: once Euler -1 and
    # non-orientable, exit 0, where the re-centred points gave Euler 2
    p = np.asarray(read_points(need(MESHES / "spot.obj")), float)
    off = np.array([5e5, 4.1e6, 250.0])
    moved = p + off
    a = reconstruct(moved, 33)
    b = reconstruct(moved - off, 33)
    assert mesh_stats(a.triangles, a.vertices.shape[0]).euler == 2
    assert np.array_equal(a.triangles, b.triangles)
    assert np.array_equal(a.vertices, moved)  # the output keeps the input's frame


@pytest.mark.parametrize("shift", [1e7, -3e7])
def test_translation_invariance_to_offsets_of_1e7_times_the_size(shift):
    # points exactly on a grid of the offset's ulp, so the offset is exact:
    # the result must not change at all
    p = cube_lattice(8) / 8.0
    a = reconstruct(p, 33)
    moved = p + np.array([shift, 0.5 * shift, -shift])
    assert np.array_equal(moved - np.array([shift, 0.5 * shift, -shift]), p)
    b = reconstruct(moved, 33)
    assert triangle_set(b.triangles) == triangle_set(a.triangles)


SCALES = (1e300, 1e200, 1e-300, 1e150, 1e-150)


def test_extreme_magnitudes_give_the_unit_result():
    # the cube x 1e300 or x 1e-300 once never finished (squared distances
    # overflowed or underflowed in the localized RNG); spot x 1e+-150 came
    # out with 54 open edges.  A hang fails the subprocess's timeout.
    got = _in_subprocess(
        f"""
        import numpy as np
        from sr33 import reconstruct
        from sr33.samplers import cube_lattice
        p = cube_lattice(6) / 6.0
        a = reconstruct(p, 33).triangles
        for scale in {SCALES!r}:
            b = reconstruct(p * scale, 33).triangles
            print(scale, int(np.array_equal(a, b)), len(b))
        """
    )
    rows = [line.split() for line in got.splitlines()]
    assert [float(r[0]) for r in rows] == list(SCALES)
    for scale, same, count in rows:
        assert same == "1" and int(count) == 2 * (6 * 36 + 2) - 4, scale


def test_spot_at_extreme_magnitudes_stays_closed():
    p = np.asarray(read_points(need(MESHES / "spot.obj")), float)
    ref = reconstruct(p, 33)
    for scale in (1e150, 1e-150):
        rec = reconstruct(p * scale, 33)
        st = mesh_stats(rec.triangles, rec.vertices.shape[0])
        assert st.open_edges == 0 and st.euler == 2
        assert np.array_equal(rec.triangles, ref.triangles)


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc/self/status")
@pytest.mark.parametrize("far", [1e4, 1e8])
def test_one_outlier_keeps_memory_bounded_and_the_cube_closed(far):
    # the cube plus one point at (far, 0, 0) once asked for 41.8 GiB (1e4)
    # and 19.7 PiB (1e8) in the crossing tests' grid
    got = _in_subprocess(
        f"""
        import numpy as np
        from sr33 import reconstruct
        from sr33.samplers import cube_lattice
        from sr33.validators import mesh_stats
        p = np.vstack([cube_lattice(8) / 8.0, [[{far!r}, 0.0, 0.0]]])
        r = reconstruct(p, 33)
        st = mesh_stats(r.triangles, r.vertices.shape[0])
        # this process's own peak: VmHWM belongs to the memory map exec made
        # (ru_maxrss is carried over exec from the forking parent, a pytest
        # worker of gigabytes)
        with open("/proc/self/status") as fh:
            peak = next(int(ln.split()[1]) for ln in fh if ln.startswith("VmHWM:"))  # KiB
        print(peak, st.used_vertices, st.overloaded_edges)
        """
    )
    peak_kib, used, overloaded = (int(x) for x in got.split())
    assert peak_kib < 2 * 1024 * 1024, f"peak {peak_kib / 1024:.0f} MiB"
    assert used == 6 * 64 + 2 + 1 and overloaded == 0
