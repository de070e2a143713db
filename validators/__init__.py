"""Judges of any triangle mesh: topology, fidelity and sample conditions.

``validators`` never imports the reconstruction, so it can judge any mesh.
"""

if __name__ != "sr33.validators":  # the folder installs as sr33.validators (pyproject.toml)
    raise ImportError(f"this folder is sr33.validators; import it by that name, not {__name__}")

from .topology import MeshStats, edge_uses, mesh_stats  # noqa: E402

__all__ = ["MeshStats", "edge_uses", "mesh_stats"]
