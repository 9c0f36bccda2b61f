"""The validated mesh and what the validator found: :class:`Mesh`, :class:`MeshReport`, and the
ragged :class:`Polygons` the file parsers produce.

Plain data (numpy only): :mod:`meshlap_core.validate` builds these, :mod:`meshlap_core.topology`
fills the report's topology fields, every other module reads them.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass, field
from typing import Any, NamedTuple

import numpy as np

from .types import FloatArray, IntArray

__all__ = ["Mesh", "MeshReport", "Polygons", "count_phrase"]


def count_phrase(n: int, singular: str, plural: str | None = None) -> str:
    """``"1 face"`` / ``"1,489 faces"``."""
    return f"{n:,} {singular if n == 1 else (plural or singular + 's')}"


class Polygons(NamedTuple):
    """Ragged polygon list in flat form (what the file parsers produce).

    Attributes
    ----------
    indices : (k,) int
        All corner indices (0-based), polygon after polygon.
    sizes : (p,) int
        Number of corners of each polygon (``sizes.sum() == len(indices)``).
    """

    indices: IntArray
    sizes: IntArray


@dataclass(eq=False)
class MeshReport:
    """What :func:`validate_mesh` repaired and found.

    Attributes
    ----------
    repairs : list of str
        One sentence per repair applied, e.g. ``"removed 43 unreferenced vertices"``.
    warnings : list of str
        Problems detected but not repaired (non-manifold, orientation, ...).
    n_input_vertices, n_input_faces : int
        Counts before any repair (faces = polygons as given).
    n_edges : int
        Unique undirected edges of the repaired mesh.
    n_boundary_edges : int
        Edges with exactly one incident face.
    n_nonmanifold_edges : int
        Edges with more than two incident faces.
    n_nonmanifold_vertices : int
        Vertices whose incident faces form more than one edge-connected fan (the libigl
        ``is_vertex_manifold`` definition: vertices on non-manifold edges are counted by
        ``n_nonmanifold_edges``, not here).
    n_inconsistent_edges : int
        Two-face edges that both faces traverse in the same direction.
    consistently_oriented : bool
        ``n_inconsistent_edges == 0``.
    n_components : int
        Connected components of the faces (faces sharing a vertex are connected).
    nonmanifold_edges : (k,2) int
        The non-manifold edges (vertex pairs, ``i < j``).
    nonmanifold_vertices : (k,) int
        The non-manifold vertices.

    Examples
    --------
    A triangle given twice and a vertex no face uses:

    >>> from meshlap_core import validate_mesh
    >>> mesh = validate_mesh([[0, 0, 0], [1, 0, 0], [0, 1, 0], [5, 5, 5]], [[0, 1, 2], [2, 0, 1]])
    >>> for repair in mesh.report.repairs:
    ...     print(repair)
    removed 1 duplicate face (same three vertices as an earlier face, in any order)
    removed 1 unreferenced vertex
    >>> mesh.report.n_input_vertices, mesh.report.n_boundary_edges, mesh.V.shape
    (4, 3, (3, 3))
    """

    repairs: list[str] = field(default_factory=list)
    warnings: list[str] = field(default_factory=list)
    n_input_vertices: int = 0
    n_input_faces: int = 0
    n_edges: int = 0
    n_boundary_edges: int = 0
    n_nonmanifold_edges: int = 0
    n_nonmanifold_vertices: int = 0
    n_inconsistent_edges: int = 0
    consistently_oriented: bool = True
    n_components: int = 0
    nonmanifold_edges: IntArray = field(
        default_factory=lambda: np.zeros((0, 2), dtype=np.int64), repr=False
    )
    nonmanifold_vertices: IntArray = field(
        default_factory=lambda: np.zeros(0, dtype=np.int64), repr=False
    )

    @property
    def is_manifold(self) -> bool:
        """No non-manifold edge and no non-manifold vertex."""
        return self.n_nonmanifold_edges == 0 and self.n_nonmanifold_vertices == 0

    @property
    def is_closed(self) -> bool:
        """No boundary edge."""
        return self.n_boundary_edges == 0

    def to_dict(self) -> dict[str, Any]:
        """Plain-Python summary (for ``--json`` output); the index arrays are left out."""
        return {
            "repairs": list(self.repairs),
            "warnings": list(self.warnings),
            "n_input_vertices": self.n_input_vertices,
            "n_input_faces": self.n_input_faces,
            "n_edges": self.n_edges,
            "n_boundary_edges": self.n_boundary_edges,
            "n_nonmanifold_edges": self.n_nonmanifold_edges,
            "n_nonmanifold_vertices": self.n_nonmanifold_vertices,
            "n_inconsistent_edges": self.n_inconsistent_edges,
            "consistently_oriented": self.consistently_oriented,
            "n_components": self.n_components,
            "is_manifold": self.is_manifold,
            "is_closed": self.is_closed,
        }


@dataclass(eq=False)
class Mesh:
    """A validated triangle mesh.

    Attributes
    ----------
    V : (n,3) float64
    F : (m,3) int64
        0-based, every index in ``[0, n)``, no degenerate or duplicate face after repair.
    source : str or None
        The file (or label) the mesh came from; used in error messages.
    report : MeshReport
    vertex_map : (n,) int64
        ``vertex_map[i]`` is the index in the input (0-based order of the file's vertices;
        for STL the index of the first triangle corner welded into vertex ``i``).
    face_map : (m,) int64
        ``face_map[f]`` is the index of the input face (polygon) that triangle ``f`` comes from.
    edge_table : EdgeTable or None
        The :class:`~meshlap_core.topology.EdgeTable` of ``F`` the validator built (one sort
        of the half-edges, with the vertex components), shared by the callers that need edges
        (``meshlap info``, the boundary of a smoother) instead of rebuilt; ``None`` when the
        mesh was made by hand. Do not modify ``F`` in place while it is set.

    Examples
    --------
    >>> from meshlap_core import Mesh, icosphere, validate_mesh
    >>> mesh = validate_mesh(*icosphere(1))
    >>> isinstance(mesh, Mesh), mesh.V.shape, mesh.F.shape, mesh.F.dtype
    (True, (42, 3), (80, 3), dtype('int64'))
    >>> mesh.vertex_map[:3].tolist(), mesh.report.repairs  # nothing to repair
    ([0, 1, 2], [])
    """

    V: FloatArray
    F: IntArray
    source: str | None
    report: MeshReport
    vertex_map: IntArray = field(repr=False, default_factory=lambda: np.zeros(0, np.int64))
    face_map: IntArray = field(repr=False, default_factory=lambda: np.zeros(0, np.int64))
    edge_table: Any = field(repr=False, default=None)  # topology.EdgeTable (no import cycle)

    @property
    def n_vertices(self) -> int:
        """Number of vertices ``n``."""
        return int(self.V.shape[0])

    @property
    def n_faces(self) -> int:
        """Number of triangles ``m``."""
        return int(self.F.shape[0])

    def __iter__(self) -> Iterator[np.ndarray]:  # allows ``V, F = load_mesh(path)``
        yield self.V
        yield self.F
