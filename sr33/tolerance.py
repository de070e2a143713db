"""The one documented tolerance object of sr33.

Lattice-sampled surfaces (the paper's data sets, scan lines) put many point
pairs at *exactly* equal distances.  Rounding after a rotation or a scaling
turns such exact ties into near-ties of relative size ~1e-16, so every
distance comparison whose outcome decides the result goes through one
relative tolerance, ``rtol``:

* **Neighbourhood rule.**  N(u; k) is u together with its k nearest other
  samples *and every further sample whose distance to u is within
  ``(1 + rtol)`` times the k-th distance*.  A tie with the k-th neighbour
  therefore never depends on input order.
* **Lune rule.**  c blocks the pair (a, b) only if it lies inside the open
  lune *by more than the tolerance*:
  ``max(|ac|, |bc|) < (1 - rtol) · |ab|``.  A point on (or within rounding of)
  the lune's boundary does not block, matching the paper's open balls.
* **Area/score ties** in the face search and the triangulation are compared
  after rounding to ``rtol`` relative precision; remaining exact ties are
  broken by the canonical (lexicographic) order of the samples, which does
  not depend on input order.

Both rules are invariant under permutation, rigid motion and uniform
scaling up to rounding far below ``rtol``.
"""

from __future__ import annotations

from dataclasses import dataclass

from ._validate import InputError

RTOL_RANGE = (0.0, 1e-3)


@dataclass(frozen=True)
class Tolerance:
    """Tolerances of the reconstruction.

    Attributes
    ----------
    rtol : float
        Relative tolerance under which two distances count as tied.
    fold_degrees : float
        Two face cycles sharing an edge fold onto each other when the angle
        between their wings (the directions from the shared edge towards the
        two cycles' centroids, perpendicular to the edge) is below this;
        such a pair is never selected together.
    """

    rtol: float = 1e-9
    fold_degrees: float = 20.0

    def __post_init__(self):
        lo, hi = RTOL_RANGE
        if isinstance(self.rtol, bool) or not isinstance(self.rtol, (int, float)):
            raise InputError(f"Tolerance.rtol must be a number, got {self.rtol!r}")
        if not self.rtol >= lo:
            raise InputError(f"Tolerance.rtol must be >= 0, got {self.rtol!r}")
        if not self.rtol <= hi:
            raise InputError(
                f"Tolerance.rtol must be within [{lo:g}, {hi:g}], got {self.rtol!r} (a "
                "tolerance that large ties distances that differ, and neighbourhoods grow "
                "without bound)"
            )
        if isinstance(self.fold_degrees, bool) or not isinstance(self.fold_degrees, (int, float)):
            raise InputError(f"Tolerance.fold_degrees must be a number, got {self.fold_degrees!r}")
        if not 0 <= self.fold_degrees < 90:
            raise InputError(
                f"Tolerance.fold_degrees must be within [0, 90), got {self.fold_degrees!r}"
            )


DEFAULT = Tolerance()
