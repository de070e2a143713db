"""Sample sets with known surfaces, for tests, benchmarks and the demo.

- :mod:`samplers.shapes`: parametric sharp-featured CadQuery shapes with
  their expected topology and a ground-truth mesh (needs CadQuery);
- :mod:`samplers.scanline`: laser-scanner-like samples of those shapes
  (Condition III, Figure 1 of the paper);
- :mod:`samplers.lattice`: exact square lattices of simple surfaces with
  plain numpy, for unit tests.

CadQuery is imported only when a shape is built or sampled.
"""

from .lattice import cube_lattice, grid_lattice

__all__ = ["cube_lattice", "grid_lattice"]
