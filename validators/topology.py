"""Topological figures of a triangle mesh, the one implementation of them.

Edges are counted by :func:`sr33.mesh.edge_uses` (the one edge count of
the project); components and boundary loops come from
``scipy.sparse.csgraph.connected_components``.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np
from scipy import sparse
from scipy.sparse import csgraph

from sr33.mesh import as_triangles, edge_uses

__all__ = ["MeshStats", "edge_uses", "mesh_stats"]


@dataclass(frozen=True)
class MeshStats:
    """Table-2 style figures of a triangle mesh.

    Attributes
    ----------
    points : int
        Number of vertices in the vertex table (samples).
    used_vertices : int
        Vertices that some triangle uses.
    faces : int
        Triangles.
    edges : int
        Distinct undirected edges of the triangles.
    open_edges : int
        Edges used by exactly one triangle.
    overloaded_edges : int
        Edges used by three or more triangles.
    euler : int
        Euler characteristic ``used_vertices - edges + faces``.
    components : int
        Connected components of the triangles (through shared vertices).
    boundary_loops : int
        Connected components of the open edges.
    """

    points: int
    used_vertices: int
    faces: int
    edges: int
    open_edges: int
    overloaded_edges: int
    euler: int
    components: int
    boundary_loops: int

    def as_dict(self) -> dict[str, int]:
        """The figures as a plain dict (for JSON and tables)."""
        return asdict(self)


def _count_components(edges: np.ndarray, nodes: np.ndarray, n: int) -> int:
    if nodes.shape[0] == 0:
        return 0
    g = sparse.csr_matrix(
        (np.ones(edges.shape[0], dtype=np.int8), (edges[:, 0], edges[:, 1])), shape=(n, n)
    )
    _, labels = csgraph.connected_components(g, directed=False)
    return int(np.unique(labels[nodes]).shape[0])


def mesh_stats(triangles, n_points: int | None = None) -> MeshStats:
    """Figures of a triangle mesh: edges, open/overloaded edges, Euler, components.

    Parameters
    ----------
    triangles : (t, 3) array_like of int
        Vertex indices.
    n_points : int, optional
        Size of the vertex table; defaults to ``max index + 1``.

    Returns
    -------
    MeshStats

    Examples
    --------
    >>> from sr33.validators import mesh_stats
    >>> tetra = [(0, 1, 2), (0, 3, 1), (1, 3, 2), (2, 3, 0)]
    >>> s = mesh_stats(tetra)
    >>> (s.edges, s.open_edges, s.euler, s.components)
    (6, 0, 2, 1)
    """
    tri = as_triangles(triangles)
    n = int(tri.max()) + 1 if tri.shape[0] else 0
    if n_points is not None:
        if n_points < n:
            raise ValueError(f"n_points ({n_points}) is smaller than the largest index + 1 ({n})")
        n = int(n_points)
    edges, counts = edge_uses(tri)
    used = np.unique(tri)
    open_e = edges[counts == 1]
    return MeshStats(
        points=n,
        used_vertices=int(used.shape[0]),
        faces=int(tri.shape[0]),
        edges=int(edges.shape[0]),
        open_edges=int(open_e.shape[0]),
        overloaded_edges=int((counts > 2).sum()),
        euler=int(used.shape[0] - edges.shape[0] + tri.shape[0]),
        components=_count_components(edges, used, n),
        boundary_loops=_count_components(open_e, np.unique(open_e), n),
    )
