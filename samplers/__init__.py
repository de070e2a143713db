"""Sample sets with known surfaces, for tests, benchmarks and the demo.

- :mod:`sr33.samplers.shapes`: parametric sharp-featured CadQuery shapes with
  their expected topology and a ground-truth mesh (needs CadQuery);
- :mod:`sr33.samplers.scanline`: laser-scanner-like samples of those shapes
  (Condition III, Figure 1 of the paper);
- :mod:`sr33.samplers.lattice`: exact square lattices of simple surfaces with
  plain numpy, for unit tests.

CadQuery is imported only when a shape is built or sampled.
"""

if __name__ != "sr33.samplers":  # the folder installs as sr33.samplers (pyproject.toml)
    raise ImportError(f"this folder is sr33.samplers; import it by that name, not {__name__}")

from .lattice import cube_lattice, grid_lattice  # noqa: E402

__all__ = ["cube_lattice", "grid_lattice"]
