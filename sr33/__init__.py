"""sr33: reconstruction of surfaces with sharp features from point samples.

The steps of Algorithm 1 of the paper, each usable alone:

- :func:`localized_rng` (Algorithm 2)
- :func:`trivial_isometric_cycles` (Algorithm 3)
- :func:`backtracking` (Algorithm 4)
- :func:`triangulate` (Algorithm 1, line 4)
- :func:`attach_cones` (cones for stray samples, end of Section 5)

and :func:`reconstruct`, which chains them.  The folders beside this one
install as its subpackages: :mod:`sr33.validators` (judges of any mesh),
:mod:`sr33.samplers` (CAD shapes and their samplings) and :mod:`sr33.gui`
(the inspector).
"""

from ._validate import InputError
from .backtracking import FaceSelection, backtracking
from .cones import attach_cones
from .cycles import CycleSet, trivial_isometric_cycles
from .reconstruct import Reconstruction, reconstruct
from .rng import LocalizedRNG, Neighbourhoods, k_neighbourhoods, localized_rng
from .tolerance import DEFAULT, Tolerance
from .triangulate import Triangulation, triangulate

__version__ = "0.1.0"

__all__ = [
    "DEFAULT",
    "CycleSet",
    "FaceSelection",
    "InputError",
    "LocalizedRNG",
    "Neighbourhoods",
    "Reconstruction",
    "Tolerance",
    "Triangulation",
    "attach_cones",
    "backtracking",
    "k_neighbourhoods",
    "localized_rng",
    "reconstruct",
    "trivial_isometric_cycles",
    "triangulate",
]
