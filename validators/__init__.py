"""Judges of any triangle mesh: topology, fidelity and sample conditions.

``validators`` never imports the reconstruction, so it can judge any mesh.
"""

from .topology import MeshStats, edge_uses, mesh_stats

__all__ = ["MeshStats", "edge_uses", "mesh_stats"]
