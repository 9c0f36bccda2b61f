"""The Surfaces panel: a parametric surface, its exact K, the geometry at a point (u, v) and the
normal section at an angle θ (drawn in 3D; ``meshlap animate --theta`` draws it with
:meth:`SurfacesPanel.push_section` too)."""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

import numpy as np
import polyscope as ps

from meshlap_core.errors import MeshError

from .. import scene
from ..host import Host
from ..isolines import draw_isolines
from ..panel_spec import PanelSpec
from ..record import Recorder, draw_record
from ..scene import (
    COLORBAR_AT,
    NORMAL_SECTION,
    SECTION_DIRECTION,
    SURFACE,
    SURFACE_POINT,
    Z_TO_Y,
    picked_vertex,
)
from ..setting_widgets import setting_widget
from ..state.surfaces import ANIMATION, SETTINGS, TURN_STEP_DEG, SurfaceState, section_arc
from ..text_numbers import sig
from .base import ExportItem, Panel, shown_field

K1_COLOR = (0.85, 0.2, 0.1)
"""The first principal direction's arrow on the surface, and k1's marker in the plot."""
K2_COLOR = (0.1, 0.3, 0.85)
"""The second principal direction's arrow, and k2's marker."""
KN_COLOR = (0.85, 0.85, 0.85, 1.0)
"""Euler's curve k_n(phi) in the plot (light: apart from the markers' colours)."""
SIGNS_COLOR = (1.0, 0.75, 0.2, 1.0)
"""The signs line while do Carmo's sign of II is on (amber: another sign than meshlap's)."""


class SurfacesPanel(Panel):
    """Surface choice, (u, v) sliders, fundamental forms, principal directions, k_n(θ), the
    normal section at θ (slider, *turn*) and its recording."""

    shows_mesh = False  # a parametric surface instead of the mesh
    framed = (SURFACE,)
    view_direction = scene.OBLIQUE_VIEW
    SECTION_COLOR = (0.95, 0.55, 0.05)

    def __init__(self, spec: PanelSpec, state: SurfaceState) -> None:
        super().__init__(spec, state)
        self.state: SurfaceState = state
        self.recorder = Recorder(f"{spec.name}.gif")
        self.field: np.ndarray | None = None  # the colour field uploaded on the surface

    def animating(self) -> bool:
        """The normal section turns: the window keeps its full frame rate."""
        return bool(self.state.turning)

    def show(self, host: Host, active: Panel) -> None:
        if active is self:
            self.push(host)
        elif ps.has_surface_mesh(SURFACE):  # hidden, its K colour bar would stay on screen
            ps.remove_surface_mesh(SURFACE)
            self.watch.forget("surface")  # registered again when the panel comes back
        if ps.has_point_cloud(SURFACE_POINT):
            ps.get_point_cloud(SURFACE_POINT).set_enabled(active is self)
        if ps.has_curve_network(NORMAL_SECTION):
            ps.get_curve_network(NORMAL_SECTION).set_enabled(active is self)

    def points(self, host: Host, name: str) -> np.ndarray | None:
        if name == SURFACE and self.state.mesh is not None:
            return self.state.mesh.V @ Z_TO_Y[:3, :3].T
        return None

    def pick(self, host: Host, hit: Any, active: Panel) -> bool:
        """A click on the surface moves the point there."""
        surf = self.state
        if hit.structure_name != SURFACE or surf.mesh is None:
            return False
        shown = surf.mesh.V @ Z_TO_Y[:3, :3].T  # picked positions are in world space
        idx = picked_vertex(hit, shown, surf.mesh.F)
        if idx is not None and surf.pick_vertex(idx):
            self.push_point(host)
            return True
        return False

    def export_items(self, host: Host) -> list[ExportItem]:
        """The parametric surface's mesh with the field on it (PLY, and the field as CSV)."""
        s = self.state
        if s.mesh is None:
            return []
        return shown_field(f"{s.name}_res{s.res}", s.mesh.V, s.mesh.F, self.field)

    def capture(self, host: Host) -> dict[str, Any]:
        s = self.state
        return {
            "surface": s.name,
            "res": int(s.res),
            "u": s.u,
            "v": s.v,
            "theta": s.section_deg,
            **self.isolines_section(),
            "signs": s.signs,
        }

    def configure(self, host: Host, values: dict[str, Any]) -> None:
        """The isolines and the sign of II; :meth:`restore` meshes the surface and sets the
        point."""
        self.configure_isolines(values)
        self.state.signs = values["signs"]

    def restore(self, host: Host, values: dict[str, Any], active: bool) -> None:
        s = self.state
        if s.set_surface(values["surface"], values["res"]):
            s.set_uv(values["u"], values["v"])
        s.set_section(values["theta"])  # a finite number: checked when the file was read

    def push(self, host: Host) -> None:
        surf = self.state
        if surf.mesh is None:
            surf.set_surface(surf.name)
        sm = surf.mesh
        if sm is None:
            return
        if self.watch.changed("surface", surf.version, repr(self.isolines)):
            s = scene.register_surface(SURFACE, sm.V, sm.F, host.active() is self)
            s.set_transform(Z_TO_Y)
            from meshlap_core.surfaces import surface_curvature_fields as surface_curvature

            cf = surface_curvature(surf.name, sm.uv[:, 0], sm.uv[:, 1])
            K = np.nan_to_num(np.asarray(cf.K, dtype=float))
            self.field = K  # what export writes
            r = float(np.percentile(np.abs(K), 98)) or 1.0
            s.add_scalar_quantity(
                "Gaussian curvature K (exact) [1/length^2]",
                K,
                cmap="coolwarm",
                vminmax=(-r, r),
                enabled=True,
                onscreen_colorbar_enabled=True,
                onscreen_colorbar_location=COLORBAR_AT,
                **self.isolines.options("Gaussian curvature", K),
            )
        self.push_point(host)

    def push_point(self, host: Host) -> None:
        surf = self.state
        if surf.point is None:
            return
        size = float(np.ptp(surf.mesh.V, axis=0).max()) if surf.mesh is not None else 1.0
        base, d1, d2 = surf.direction_vectors(scale=0.15 * size)
        pc = ps.register_point_cloud(SURFACE_POINT, base, radius=0.01)
        pc.set_transform(Z_TO_Y)
        pc.set_color((0.9, 0.1, 0.1))
        pc.add_vector_quantity(
            "k1 direction", d1, vectortype="ambient", enabled=True, color=K1_COLOR
        )
        pc.add_vector_quantity(
            "k2 direction", d2, vectortype="ambient", enabled=True, color=K2_COLOR
        )
        pc.add_vector_quantity(
            "normal",
            0.15 * size * surf.point.n[None, :],
            vectortype="ambient",
            enabled=True,
            color=(0.2, 0.7, 0.2),
        )
        self.push_section(host)

    def push_section(self, host: Host, degrees: float | None = None) -> None:
        """Draw the normal section at θ (``degrees``, else the state's): its unit tangent
        t(θ) as an arrow at the point and its osculating arc of curvature κₙ(θ) (orange).
        The point cloud must be registered (:meth:`push_point`)."""
        surf = self.state
        if degrees is not None:
            surf.set_section(degrees)
        if surf.point is None or not ps.has_point_cloud(SURFACE_POINT):
            return
        size = float(np.ptp(surf.mesh.V, axis=0).max()) if surf.mesh is not None else 1.0
        t, kn = surf.section()
        arc = section_arc(surf.point, t, kn, 0.3 * size)
        edges = np.column_stack([np.arange(len(arc) - 1), np.arange(1, len(arc))])
        cn = ps.register_curve_network(NORMAL_SECTION, arc, edges, radius=0.006)
        cn.set_transform(Z_TO_Y)
        cn.set_color(self.SECTION_COLOR)
        ps.get_point_cloud(SURFACE_POINT).add_vector_quantity(
            SECTION_DIRECTION,
            0.2 * size * t[None, :],
            vectortype="ambient",
            enabled=True,
            color=self.SECTION_COLOR,
        )

    def draw(self, host: Host) -> None:
        ui = host.ui
        if not ui.header(self.title):
            return
        s = self.state
        ch, name = setting_widget(ui, SETTINGS["surface"], s.name)
        if ch and s.set_surface(name):
            self.push(host)
            host.request_frame()
        ch, res = setting_widget(ui, SETTINGS["res"], s.res)
        if ch:
            s.set_resolution(res)
            self.push(host)
        if draw_isolines(ui, self.isolines, "Gaussian curvature"):
            self.push(host)
        ch, signs = setting_widget(ui, SETTINGS["signs"], s.signs)
        if ch:
            s.set_signs(signs)
            self.push_point(host)
        u0, u1, v0, v1 = s.domain
        ch1, u = setting_widget(ui, SETTINGS["u"], s.u, u0, u1)
        ch2, v = setting_widget(ui, SETTINGS["v"], s.v, v0, v1)
        if (ch1 or ch2) and s.set_uv(u, v):
            self.push_point(host)
        if s.error:
            ui.error(s.error)
        p = s.point
        if p is None:
            return
        s1 = max(abs(p.E), abs(p.F), abs(p.G))
        s2 = max(abs(p.e), abs(p.f), abs(p.g))
        sk = max(abs(p.k1), abs(p.k2))
        ui.text(f"I:  E = {sig(p.E, s1)}  F = {sig(p.F, s1)}  G = {sig(p.G, s1)}")
        ui.text(f"II: e = {sig(p.e, s2)}  f = {sig(p.f, s2)}  g = {sig(p.g, s2)}")
        ui.text(f"K = {sig(p.K, sk * sk)}  H = {sig(p.H, sk)}  ({p.classification})")
        ui.text(
            f"k1 = {sig(p.k1, sk)} at parameter angle {np.degrees(p.theta_uv_max):.1f} deg,  "
            f"k2 = {sig(p.k2, sk)} at {np.degrees(p.theta_uv_min):.1f} deg (in the (u, v) plane; "
            "90 deg apart in the tangent plane)"
        )
        if s.signs != SETTINGS["signs"].default:  # said in colour: not meshlap's convention
            ui.colored(s.signs_line(), SIGNS_COLOR)
        else:
            ui.note(s.signs_line())
        self.draw_section(host)
        self.draw_euler_plot(host)
        key = (s.version, s.u, s.v, s.section_deg)
        draw_record(host, self.recorder, key, s.section_caption, ANIMATION.fps["theta"])

    def draw_euler_plot(self, host: Host) -> None:
        """κₙ against φ, the angle in the tangent plane from the first principal direction
        (Euler's curve ``κ₁ cos² φ + κ₂ sin² φ``): k1 at φ = 0, 180, k2 at φ = 90, 270 marked,
        and the section's φ."""
        ui, s = host.ui, self.state
        p = s.point
        if p is None:
            return
        title = "normal curvature k_n(phi)"
        if s.signs != SETTINGS["signs"].default:
            title += f", signs: {s.signs}"  # the curve is the other sign's: said on it
        with ui.plot(
            title,
            200,
            "phi (deg) from the k1 direction",
            "k_n",
        ) as shown:
            if shown:
                # each marker in the colour of its arrow on the surface (ImPlot's own
                # colours gave k1 the blue of the k2 arrow)
                ui.plot_line("k_n", np.degrees(s.phi), s.kn_phi, KN_COLOR)
                ui.plot_vlines(f"k1 = {p.k1:.3g}", np.array([0.0, 180.0, 360.0]), (*K1_COLOR, 1.0))
                ui.plot_vlines(f"k2 = {p.k2:.3g}", np.array([90.0, 270.0]), (*K2_COLOR, 1.0))
                section = (*self.SECTION_COLOR, 1.0)
                ui.plot_vlines("section", np.array([s.section_phi_deg()]), section)

    def draw_section(self, host: Host) -> None:
        """The θ slider (showing κₙ(θ)), *turn* / *pause turn* and this frame's turn step."""
        ui, s = host.ui, self.state
        _, kn = s.section()
        shown = f"%.1f deg: k_n = {kn:.4g}"  # κₙ shown in the slider, φ in the row below
        ch, deg = setting_widget(ui, SETTINGS["theta"], s.section_deg, fmt=shown)
        if ch:
            self.push_section(host, deg)
        ui.same_line()
        if ui.button(
            "pause turn" if s.turning else "turn",
            f"turn the section once around, {TURN_STEP_DEG:g} deg per frame "
            "(while recording: a frame per step, as meshlap animate --theta)",
        ):
            s.toggle_turn()
        elif s.tick_turn():
            self.push_section(host)
        ui.text(
            f"section: theta = {s.section_deg:.1f} deg in (u, v) = phi "
            f"{s.section_phi_deg():.1f} deg from the k1 direction"
        )

    # ------------------------------------------------------------------ meshlap animate
    def frames(self, host: Host, options: dict[str, Any]) -> Iterator[str]:
        """The normal section at (u, v) turning once around from its θ: its tangent t(θ) and
        osculating arc, κₙ(θ), drawn by :meth:`push_section` as in the window."""
        surf = self.state
        if not surf.set_surface(options["surface"]):
            raise MeshError(surf.error, "--surface")
        if options.get("uv") is not None and not surf.set_uv(*options["uv"]):
            raise MeshError(surf.error, "--uv")
        host.refresh()  # registers the surface, K and the point
        host.frame(scene.COLORBAR_STRIP)
        start = surf.section_deg  # 0, or the θ a session saved: one turn from there
        for theta in np.linspace(start, start + 360.0, int(options["frames"]), endpoint=False):
            self.push_section(host, theta)
            yield surf.section_caption()
