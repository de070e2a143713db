"""Self-intersections: pairs of triangles whose interiors meet.

The paper requires the triangles of the output to have pairwise disjoint
interiors (Section 4, Triangulate).  The test itself is a mesh primitive
that the reconstruction uses too (:func:`sr33.mesh.self_intersections`);
the validators judge any mesh with it.
"""

from __future__ import annotations

from sr33.mesh import self_intersections

__all__ = ["self_intersections"]
