"""The One-ring panel: a clicked vertex, its neighbours numbered in order, H and K there."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
import polyscope as ps

from meshlap_core.errors import MeshError

from ..camera import project_to_screen
from ..scene import RING_CENTER, RING_CURVE, RING_POINTS

if TYPE_CHECKING:
    from ..viewer import Viewer


class OneRingPanel:
    """Vertex field, clockwise toggle, the ring drawn as numbered points and arrows."""

    def __init__(self) -> None:
        self.labels: list[tuple[tuple[float, float], str]] = []  # the one-ring numbers drawn

    def on_new_mesh(self, viewer: Viewer) -> None:
        self.labels = []

    def show(self, viewer: Viewer, panel: str) -> None:
        if ps.has_curve_network(RING_CURVE):
            ps.get_curve_network(RING_CURVE).set_enabled(panel == "onering")
        for name in (RING_POINTS, RING_CENTER):
            if ps.has_point_cloud(name):
                ps.get_point_cloud(name).set_enabled(panel == "onering")

    def points(self, viewer: Viewer, name: str) -> np.ndarray | None:
        return None

    def select(self, viewer: Viewer, i: int) -> bool:
        """Select vertex ``i`` and draw its ordered one-ring."""
        if not viewer.ring.select(viewer.mesh, viewer.curv, i):
            return False
        self.push(viewer)
        viewer.reframe = True  # the camera turns to the new one-ring (else a speck on the mesh)
        return True

    def push(self, viewer: Viewer) -> None:
        r = viewer.ring
        if r.valence == 0:
            return
        d = viewer.display
        center, ring = d.points(viewer.mesh.V[[r.vertex]]), d.points(r.polyline)
        # sizes follow the ring's own edge length, so any mesh and zoom level looks the same
        scale = 0.08 * float(np.linalg.norm(ring - center, axis=1).mean())
        cn = ps.register_curve_network(RING_CURVE, ring, r.edges, radius=0.5 * scale)
        cn.set_radius(0.5 * scale, relative=False)
        cn.set_color((0.1, 0.1, 0.1))
        pc = ps.register_point_cloud(RING_POINTS, ring, radius=1.5 * scale)
        pc.set_radius(1.5 * scale, relative=False)
        pc.add_scalar_quantity("order", r.order_t, cmap="viridis", enabled=True, vminmax=(0, 1))
        pc.add_vector_quantity(
            "direction",
            0.85 * d.vectors(r.arrows),
            vectortype="ambient",
            enabled=True,
            color=(0.9, 0.5, 0.0),
        )
        c = ps.register_point_cloud(RING_CENTER, center, radius=2.0 * scale)
        c.set_radius(2.0 * scale, relative=False)
        c.set_color((1.0, 0.1, 0.1))
        viewer.show_panel()

    def focus(self, viewer: Viewer) -> None:
        """Point the camera at the selected vertex, along its normal, framing the one-ring."""
        r = viewer.ring
        if r.valence == 0:
            return
        center = viewer.display.points(viewer.mesh.V[[r.vertex]])[0]
        ring = viewer.display.points(r.polyline)
        size = float(np.linalg.norm(ring - center, axis=1).max()) or 1.0
        normal = r.normal if np.linalg.norm(r.normal) > 0 else np.array([0.0, 0.0, 1.0])
        # tilt a little towards the up axis inside the tangent plane: looking straight along
        # the up axis (a flat mesh seen from above) is a degenerate camera frame
        tilt = np.array([0.0, 1.0, 0.0]) - normal[1] * normal
        if np.linalg.norm(tilt) < 1e-6:
            tilt = np.array([1.0, 0.0, 0.0]) - normal[0] * normal
        tilt /= np.linalg.norm(tilt)
        ps.look_at(center + size * (7.0 * normal + 2.0 * tilt), center)

    def ring_labels(self, viewer: Viewer) -> list[tuple[tuple[float, float], str]]:
        """Screen positions and texts of the order numbers ("0", "1", ...) of the one-ring."""
        r = viewer.ring
        if r.valence == 0:
            return []
        params = ps.get_view_camera_parameters()
        w, h = ps.get_window_size()
        xy, front = project_to_screen(
            viewer.display.points(r.polyline),
            params.get_view_mat(),
            params.get_fov_vertical_deg(),
            w,
            h,
        )
        return [
            ((float(x) + 12, float(y) - 22), str(k))
            for k, ((x, y), f) in enumerate(zip(xy, front, strict=True))
            if f
        ]

    def draw_labels(self, viewer: Viewer) -> None:
        """Write the order numbers next to the neighbours (over the 3D view)."""
        self.labels = self.ring_labels(viewer)
        for pos, text in self.labels:
            viewer.ui.overlay_text(pos, text)

    def draw(self, viewer: Viewer) -> None:
        ui = viewer.ui
        if not ui.header("One-ring"):
            return
        ui.text("click a vertex of the mesh")
        n = len(viewer.mesh.V)
        r = viewer.ring
        ch, v = ui.input_int(
            "vertex", max(r.vertex, 0), f"vertex index, 0 to {n - 1}; Enter or -/+ selects it"
        )
        if ch:
            if not 0 <= v < n:
                raise MeshError(f"{v} is out of range (the mesh has {n} vertices)", "vertex")
            self.select(viewer, v)
        ch, _ = ui.checkbox(
            "clockwise (reverse)", r.reverse, "list the neighbours clockwise instead"
        )
        if ch:
            r.toggle_reverse(viewer.mesh, viewer.curv)
            self.push(viewer)
        if r.vertex < 0:
            return
        kind = "boundary vertex (open fan)" if r.boundary else "interior vertex (closed cycle)"
        ui.text(f"vertex {r.vertex}: {kind}, valence {r.valence}")
        ui.text(f"H (cotan) = {r.H + 0.0:.5g}   K (angle deficit) = {r.K + 0.0:.5g}")
        if not r.ordered:
            ui.error("not a disk: neighbours listed by index, not in order")
        ui.text("order: " + " -> ".join(str(j) for j in r.neighbors[:40]))
