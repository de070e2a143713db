"""Sample sets with known surfaces, for tests and benchmarks.

:mod:`samplers.lattice` builds exact square-lattice samples of simple
surfaces with plain numpy (no CAD kernel needed).
"""

from .lattice import cube_lattice, grid_lattice

__all__ = ["cube_lattice", "grid_lattice"]
