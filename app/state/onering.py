"""The clicked vertex and its ordered one-ring, ready to draw (``OneRingState``)."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from meshlap_core.types import FloatArray, IntArray

from .curvature import CurvatureState
from .mesh import MeshState


@dataclass
class OneRingState:
    """The clicked vertex and its ordered neighbourhood, ready to draw.

    ``select(mesh, curv, i)`` fills ``neighbors`` (ordered, counter-clockwise unless
    ``reverse``), ``boundary``, ``valence``, the vertex's ``H`` and ``K``, and the geometry of the
    drawing: ``polyline`` (neighbour positions in order, closed for interior vertices),
    ``edges`` (consecutive pairs), ``arrows`` (direction of travel at each neighbour) and
    ``order_t`` (position in the order, 0..1, for the colour map).
    """

    vertex: int = -1
    reverse: bool = False
    neighbors: list[int] = field(default_factory=list)
    boundary: bool = False
    ordered: bool = True
    H: float = float("nan")
    K: float = float("nan")
    normal: FloatArray = field(default_factory=lambda: np.zeros(3))
    _ring_key: int = -1
    _ring: Any = None
    _normals: Any = None
    polyline: FloatArray = field(default_factory=lambda: np.zeros((0, 3)))
    edges: IntArray = field(default_factory=lambda: np.zeros((0, 2), dtype=np.int64))
    arrows: FloatArray = field(default_factory=lambda: np.zeros((0, 3)))
    order_t: FloatArray = field(default_factory=lambda: np.zeros(0))

    @property
    def valence(self) -> int:
        return len(self.neighbors)

    def select(self, mesh: MeshState, curv: CurvatureState, vertex: int) -> bool:
        """Select ``vertex``; returns False (and keeps the old selection) when out of range."""
        if not 0 <= vertex < len(mesh.V):
            return False
        from meshlap_core.topology import one_ring  # local: keeps app.state import light

        if self._ring_key != mesh.version:
            from meshlap_core.curvature import vertex_normals

            self._ring = one_ring(mesh.F, len(mesh.V))
            self._normals = vertex_normals(mesh.V, mesh.F)
            self._ring_key = mesh.version
        self.normal = self._normals[vertex]
        ring = self._ring.reversed() if self.reverse else self._ring
        nb = ring[vertex]
        self.vertex = int(vertex)
        self.neighbors = [int(j) for j in nb]
        self.boundary = bool(ring.boundary[vertex])
        self.ordered = bool(ring.regular[vertex])
        curv.update(mesh)
        self.H = float(curv.fields["cotan"][vertex])
        self.K = float(curv.fields["gaussian"][vertex])
        k = len(nb)
        self.polyline = mesh.V[nb]
        closed = not self.boundary and k > 2
        nxt = np.arange(1, k + 1) % k if closed else np.minimum(np.arange(1, k + 1), k - 1)
        self.edges = np.stack([np.arange(k), nxt], axis=1)[: k if closed else max(k - 1, 0)]
        step = self.polyline[nxt] - self.polyline
        if not closed:
            step[-1] = 0.0  # an open fan ends at its last neighbour
        self.arrows = step
        self.order_t = np.linspace(0.0, 1.0, k) if k > 1 else np.zeros(k)
        return True

    def toggle_reverse(self, mesh: MeshState, curv: CurvatureState) -> None:
        self.reverse = not self.reverse
        if self.vertex >= 0:
            self.select(mesh, curv, self.vertex)
