"""The clicked vertex and its ordered one-ring, ready to draw (``OneRingState``), and the
vertex inspector's geometry: the ring edges with their weights, the corner-angle arcs, the
vertex's area cell and the arrows (pure numpy, tested headless)."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from meshlap_core.errors import MeshError
from meshlap_core.inspector import VertexInspection, inspect_vertex
from meshlap_core.options import AREA_KINDS, BOUNDARY_RULES, check_choice
from meshlap_core.types import FloatArray, IntArray

from ..panel_spec import PanelSpec
from .curvature import CurvatureState
from .mesh import MeshState
from .settings import MAX_INT, Flag, Integer, Settings, Toggle

# fmt: off
SETTINGS = Settings(
    Integer("vertex", -1, lo=-1, hi=MAX_INT - 1, label="vertex",
            tooltip="vertex index; Enter or -/+ selects it",
            view=Flag("--vertex", "the vertex selected first (one of the mesh)")),
    Toggle("reverse", False, label="clockwise (reverse)",
           tooltip="list the neighbours clockwise instead"),
)
# fmt: on
"""The One-ring panel's settings: the selected vertex (-1: none; the mesh bounds it,
:func:`check_mesh`) and the order."""


def check_start(options: dict[str, Any], state: Any) -> None:
    """``meshlap view --vertex``: a vertex of the mesh.

    Raises
    ------
    MeshError
        Out of range, naming the mesh's vertex count.
    """
    vertex = options.get("vertex")
    if vertex is not None and not 0 <= vertex < len(state.mesh.V):
        raise MeshError(
            f"vertex {vertex} is out of range (the mesh has {len(state.mesh.V)} vertices)",
            "--vertex",
        )


def check_mesh(values: dict[str, Any], mesh: MeshState, source: Any) -> None:
    """A saved one-ring vertex the session's mesh has (``-1``: none selected).

    Raises
    ------
    MeshError
        ``onering.vertex`` beyond the mesh's vertices.
    """
    vertex = values["vertex"]
    if vertex >= len(mesh.V):
        raise MeshError(
            f'"onering.vertex" {vertex} is out of range (the mesh has {len(mesh.V)} vertices)',
            source,
        )


@dataclass
class OneRingState:
    """The clicked vertex and its ordered neighbourhood, ready to draw.

    ``select(mesh, curv, i)`` fills ``neighbors`` (ordered, counter-clockwise unless
    ``reverse``), ``boundary``, ``valence``, the vertex's ``H`` and ``K``, and the geometry of the
    drawing: ``polyline`` (neighbour positions in order, closed for interior vertices),
    ``edges`` (consecutive pairs), ``arrows`` (direction of travel at each neighbour) and
    ``order_t`` (position in the order, 0..1, for the colour map). ``inspection`` is
    :func:`meshlap_core.inspector.inspect_vertex` at the vertex for the curvature state's area
    kind and boundary rule (``None`` for a vertex in no face, with ``inspection_error``).
    """

    vertex: int = SETTINGS.default("vertex")
    reverse: bool = SETTINGS.default("reverse")
    neighbors: list[int] = field(default_factory=list)
    boundary: bool = False
    ordered: bool = True
    H: float = float("nan")
    K: float = float("nan")
    normal: FloatArray = field(default_factory=lambda: np.zeros(3))
    polyline: FloatArray = field(default_factory=lambda: np.zeros((0, 3)))
    edges: IntArray = field(default_factory=lambda: np.zeros((0, 2), dtype=np.int64))
    arrows: FloatArray = field(default_factory=lambda: np.zeros((0, 3)))
    order_t: FloatArray = field(default_factory=lambda: np.zeros(0))
    inspection: VertexInspection | None = None
    inspection_error: str = ""

    @property
    def valence(self) -> int:
        return len(self.neighbors)

    def clear(self) -> None:
        """Forget the selection and the ring of the previous mesh (the order stays)."""
        reverse = self.reverse
        self.__init__()  # type: ignore[misc]  # the dataclass defaults, in place
        self.reverse = reverse

    def select(self, mesh: MeshState, curv: CurvatureState, vertex: int) -> bool:
        """Select ``vertex``; returns False (and keeps the old selection) when out of range."""
        if not 0 <= vertex < len(mesh.V):
            return False
        from meshlap_core.curvature import vertex_normals  # local: keeps app.state import light
        from meshlap_core.topology import one_ring

        # the ring and normal of one vertex need only its own faces: the same fans, order and
        # angle-weighted normal as the whole mesh's, in O(m) instead of minutes at 2.77M vertices
        F = mesh.F[np.flatnonzero((mesh.F == vertex).any(axis=1))]
        ring = one_ring(F, len(mesh.V))
        self.normal = vertex_normals(mesh.V, F)[vertex]
        ring = ring.reversed() if self.reverse else ring
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
        if not closed and k:
            step[-1] = 0.0  # an open fan ends at its last neighbour
        self.arrows = step
        self.order_t = np.linspace(0.0, 1.0, k) if k > 1 else np.zeros(k)
        self._inspect(mesh, curv)
        return True

    def _inspect(self, mesh: MeshState, curv: CurvatureState) -> None:
        try:
            self.inspection = inspect_vertex(mesh.V, mesh.F, self.vertex, curv.area, curv.boundary)
            self.inspection_error = ""
        except MeshError as exc:  # a vertex in no face: the ring panel still shows it
            self.inspection, self.inspection_error = None, str(exc)

    def set_rules(self, mesh: MeshState, curv: CurvatureState, area: str, boundary: str) -> None:
        """Inspect with the area kind ``area`` and the boundary rule ``boundary`` (shared with
        the curvature fields, so the colour map and the inspection agree).

        Raises
        ------
        MeshError
            For an unknown area kind or boundary rule (nothing changes).
        """
        check_choice(area, AREA_KINDS, "area")
        check_choice(boundary, BOUNDARY_RULES, "boundary rule")
        curv.area, curv.boundary = area, boundary
        if self.vertex >= 0:
            self.select(mesh, curv, self.vertex)

    def rows(self) -> list[Any]:
        """The inspection's neighbour terms in the order the panel lists the ring (clockwise
        when ``reverse``)."""
        if self.inspection is None:
            return []
        terms = list(self.inspection.neighbors)
        return terms[::-1] if self.reverse else terms

    def toggle_reverse(self, mesh: MeshState, curv: CurvatureState) -> None:
        self.reverse = not self.reverse
        if self.vertex >= 0:
            self.select(mesh, curv, self.vertex)


# ---------------------------------------------------------------- the inspector's geometry
def _corners(F: IntArray, i: int, faces: list[int]) -> IntArray:
    """Rows ``(i, a, b)`` of the faces ``faces`` around ``i``, keeping their orientation."""
    tri = F[np.asarray(faces, dtype=np.int64)].reshape(-1, 3)
    shift = np.argmax(tri == i, axis=1)
    idx = (shift[:, None] + np.arange(3)[None, :]) % 3
    return np.take_along_axis(tri, idx, axis=1)


def weight_segments(
    ins: VertexInspection, V: FloatArray
) -> tuple[FloatArray, IntArray, FloatArray]:
    """The ring edges ``i–j`` with their cotangent weights.

    Returns
    -------
    nodes : (k+1,3) float
        ``x_i`` then the neighbours in ring order.
    edges : (k,2) int
        ``(0, 1 + m)`` for the ``m``-th neighbour.
    weights : (k,) float
        ``w_ij`` of each edge.
    """
    j = np.array([t.index for t in ins.neighbors], dtype=np.int64)
    nodes = np.vstack([V[ins.vertex][None, :], V[j]])
    edges = np.stack([np.zeros(len(j), dtype=np.int64), 1 + np.arange(len(j))], axis=1)
    return nodes, edges, np.array([t.weight_cotan for t in ins.neighbors])


def angle_arcs(
    ins: VertexInspection, V: FloatArray, F: IntArray, radius: float, steps: int = 12
) -> tuple[FloatArray, IntArray, FloatArray]:
    """Arcs of radius ``radius`` around ``x_i`` spanning each corner angle ``θ_f`` at ``i``, in
    the plane of its face.

    Returns
    -------
    nodes : (f·(steps+1),3) float
    edges : (f·steps,2) int
    angle : (f·steps,) float
        The corner angle (radians) each arc segment belongs to (for colouring).
    """
    tri = _corners(F, ins.vertex, [f.face for f in ins.faces])
    x = V[ins.vertex]
    t = np.linspace(0.0, 1.0, steps + 1)
    nodes, edges, angle = [], [], []
    for k, (_, a, b) in enumerate(tri):
        u, w = V[a] - x, V[b] - x
        u = u / (np.linalg.norm(u) or 1.0)
        w = w / (np.linalg.norm(w) or 1.0)
        theta = ins.faces[k].angle
        s = np.sin(theta)
        if s < 1e-12:  # a degenerate corner: a straight segment
            arc = (1 - t)[:, None] * u + t[:, None] * w
        else:  # slerp from u to w
            arc = (np.sin((1 - t) * theta)[:, None] * u + np.sin(t * theta)[:, None] * w) / s
        base = k * (steps + 1)
        nodes.append(x + radius * arc)
        edges.append(np.stack([base + np.arange(steps), base + 1 + np.arange(steps)], axis=1))
        angle.append(np.full(steps, theta))
    if not nodes:
        return np.zeros((0, 3)), np.zeros((0, 2), dtype=np.int64), np.zeros(0)
    return np.vstack(nodes), np.vstack(edges), np.concatenate(angle)


def _circumcentre(p: FloatArray, q: FloatArray, r: FloatArray) -> FloatArray:
    a, b = q - p, r - p
    axb = np.cross(a, b)
    d = 2.0 * float(axb @ axb)
    if d <= 0:
        return (p + q + r) / 3.0
    return p + (np.cross(axb, a) * float(b @ b) + np.cross(b, axb) * float(a @ a)) / d


def cell_path(p: FloatArray, q: FloatArray, r: FloatArray, kind: str) -> FloatArray:
    """The boundary of vertex ``p``'s area cell inside the triangle ``(p, q, r)``: points from
    the midpoint of ``pq`` to the midpoint of ``pr`` (Meyer et al. 2003 for ``"voronoi"``).

    Barycentric: through the centroid (a third of the face). Mixed Voronoi: through the
    circumcentre on a non-obtuse face; through the midpoint of ``qr`` when the face is obtuse at
    ``p`` (half the face); straight across when it is obtuse elsewhere (a quarter).
    """
    m_q, m_r = 0.5 * (p + q), 0.5 * (p + r)
    if kind == "barycentric":
        return np.array([m_q, (p + q + r) / 3.0, m_r])
    e_pq, e_pr, e_qr = q - p, r - p, r - q
    obtuse_p = float(e_pq @ e_pr) < 0
    obtuse_other = float(-e_pq @ e_qr) < 0 or float(e_pr @ e_qr) < 0
    if obtuse_p:
        return np.array([m_q, 0.5 * (q + r), m_r])
    if obtuse_other:
        return np.array([m_q, m_r])
    return np.array([m_q, _circumcentre(p, q, r), m_r])


def area_cell(
    ins: VertexInspection, V: FloatArray, F: IntArray
) -> tuple[FloatArray, IntArray, IntArray]:
    """The vertex's area cell (``ins.area_kind``) as a fan of triangles around ``x_i``, and its
    outline; the fan's area is ``A_i`` (the inspection's area).

    Returns
    -------
    nodes : (p,3) float
        ``x_i`` first, then each face's cell path (:func:`cell_path`).
    triangles : (t,3) int
        The fan ``(0, s, s+1)`` along every path.
    outline : (e,2) int
        The path segments, plus ``x_i``–midpoint on boundary edges (one face).
    """
    x = V[ins.vertex]
    tri = _corners(F, ins.vertex, [f.face for f in ins.faces])
    nodes, triangles, outline = [x[None, :]], [], []
    count = 1
    half_edges: dict[int, list[int]] = {}  # neighbour -> node indices of the midpoints on it
    for _, a, b in tri:
        path = cell_path(x, V[a], V[b], ins.area_kind)
        idx = count + np.arange(len(path))
        nodes.append(path)
        triangles += [(0, int(s), int(s) + 1) for s in idx[:-1]]
        outline += [(int(s), int(s) + 1) for s in idx[:-1]]
        half_edges.setdefault(int(a), []).append(int(idx[0]))
        half_edges.setdefault(int(b), []).append(int(idx[-1]))
        count += len(path)
    outline += [(0, ids[0]) for ids in half_edges.values() if len(ids) == 1]
    return (
        np.vstack(nodes),
        np.array(triangles, dtype=np.int64).reshape(-1, 3),
        np.array(outline, dtype=np.int64).reshape(-1, 2),
    )


def fan_area(nodes: FloatArray, triangles: IntArray) -> float:
    """Total area of the triangles ``(t,3)`` over ``nodes (p,3)``."""
    P = nodes[triangles]
    return float(0.5 * np.linalg.norm(np.cross(P[:, 1] - P[:, 0], P[:, 2] - P[:, 0]), axis=1).sum())


def arrow_scales(ins: VertexInspection, length: float) -> tuple[float, float]:
    """Factors that draw ``n`` and ``Δ_cotan x`` as arrows of length ``length`` (world units):
    ``(length, length / |Δx|)``; the second is ``0`` when ``|Δx| · length < 1e-9`` (a flat
    vertex: its round-off is not drawn as a full-length arrow)."""
    lap = float(np.linalg.norm(ins.laplacian_cotan))
    return float(length), (float(length) / lap if lap * length >= 1e-9 else 0.0)


@dataclass
class HoverThrottle:
    """Decides when hovering picks the scene: once the cursor has rested ``interval`` seconds
    at a position it has not picked at yet. So picks are at least ``interval`` apart, a moving
    cursor does no picking (one pick renders a pick buffer: 0.12 s on a software-rendered EGL
    context), and neither does an idle frame."""

    interval: float = 0.1
    last_pos: tuple[float, float] | None = None  # where the last pick was
    rest_pos: tuple[float, float] | None = None  # where the cursor is resting
    rest_since: float = float("-inf")

    def due(self, now: float, pos: tuple[float, float]) -> bool:
        """Whether to pick at ``pos`` at time ``now`` (seconds); records the pick when it is."""
        if pos != self.rest_pos:
            self.rest_pos, self.rest_since = pos, now
        if pos == self.last_pos or now - self.rest_since < self.interval:
            return False
        self.last_pos = pos
        return True

    def current(self, pos: tuple[float, float]) -> bool:
        """Whether the last pick was made at ``pos`` (its answer describes the cursor)."""
        return pos == self.last_pos


SPEC = PanelSpec(
    name="onering",
    title="One-ring",
    summary="a clicked vertex, its neighbours numbered in order, H and K there, and the "
    "vertex inspector (every term of the operators at that vertex)",
    panel="OneRingPanel",
    state=OneRingState,
    settings=SETTINGS,
    check_mesh=check_mesh,
    check_start=check_start,
    unsaved={
        "area kind": "the Curvature section's area (declared there): one value for both views",
        "boundary rule": "the Curvature section's boundary rule (declared there)",
    },
)
"""The One-ring panel."""
