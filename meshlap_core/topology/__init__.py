"""Combinatorial structure of a triangle mesh: the edge table, boundary, components, χ, genus,
manifoldness and orientation, one-rings.

Everything here depends on the faces only (and the vertex count ``n``, so unreferenced
vertices are counted as isolated components, never silently dropped). Every edge question is
answered by one :class:`EdgeTable` (:mod:`.edges`), built once by one sort of the half-edges;
:mod:`.surface` derives the invariants and the validator's report from it, :mod:`.rings` the
ordered one-rings.
"""

from .edges import (
    EdgeTable,
    boundary_edges,
    boundary_loops,
    boundary_vertex_mask,
    edge_face_counts,
    edge_table,
    edges,
    sort_with_order,
)
from .rings import OneRing, one_ring
from .surface import (
    connected_components,
    euler_characteristic,
    genus,
    surface_summary,
    topology_report,
    topology_report_with_table,
)

__all__ = [
    "EdgeTable",
    "OneRing",
    "boundary_edges",
    "boundary_loops",
    "boundary_vertex_mask",
    "connected_components",
    "edge_face_counts",
    "edge_table",
    "edges",
    "euler_characteristic",
    "genus",
    "one_ring",
    "sort_with_order",
    "surface_summary",
    "topology_report",
    "topology_report_with_table",
]
