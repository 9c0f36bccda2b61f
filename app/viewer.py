"""The polyscope layer: registers structures, reads widgets, pushes arrays. No mathematics here.

``run`` opens a window (or, with ``screenshot``, renders one frame with the EGL backend and
exits). Paths are resolved before ``polyscope.init()``, which may change the working directory.

Every panel is a method ``panel_<name>`` of :class:`Viewer` that reads its widgets, calls the
state object's methods and, only when something changed, pushes arrays to polyscope (position
updates where the connectivity is unchanged, never re-registration per frame).
"""

from __future__ import annotations

import os
import sys
from pathlib import Path
from typing import Any

import numpy as np
import polyscope as ps
import polyscope.imgui as psim

from meshlap_core.errors import MeshError
from meshlap_core.io import atomic_write, save_mesh, save_scalars
from meshlap_core.options import AREA_KINDS as AREAS
from meshlap_core.options import BOUNDARY_RULES

from . import smoothing_panel, spectral_panel
from .camera import project_to_screen
from .state import (
    FIELD_LABELS,
    CurvatureState,
    MeshState,
    OneRingState,
    list_meshes,
)
from .surface_state import SurfaceState

MESH = "mesh"
MESH_B = "mesh (second estimator)"
RING_CURVE = "one-ring order"
RING_POINTS = "one-ring neighbours"
RING_CENTER = "selected vertex"
SURFACE = "surface"
SURFACE_POINT = "surface point"

PANELS = ("curvature", "onering", "spectral", "smoothing", "surfaces")

RED = (1.0, 0.35, 0.35, 1.0)


NO_DISPLAY = (
    "no display could be opened for the viewer window; render headless with "
    "`meshlap view MESH --screenshot out.png`"
)


def _init(backend: str) -> None:
    if (
        backend == "auto"
        and sys.platform.startswith("linux")
        and not (os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"))
    ):
        # say so before polyscope tries: a failed init leaves a noisy atexit hook behind
        raise MeshError(NO_DISPLAY, "view")
    if backend in ("openGL3_egl", "openGL_mock"):
        ps.set_allow_headless_backends(True)
    try:
        ps.init(backend)
    except RuntimeError as exc:
        if backend == "auto":
            raise MeshError(NO_DISPLAY, "view") from exc
        raise MeshError(f"polyscope could not start its {backend} backend: {exc}", "view") from exc
    if backend in ("openGL3_egl", "openGL_mock"):
        # headless: render every requested frame (the default mode skips frames to hold 60 fps,
        # so scripted frame_tick loops would silently skip the callback)
        ps.set_max_fps(-1)
        ps.set_frame_tick_limit_fps_mode("ignore_limits")
    ps.set_program_name("meshlap")
    ps.set_up_dir("y_up")  # scans and the course meshes are y-up (polyscope's default)
    ps.set_front_dir("neg_z_front")
    ps.set_ground_plane_mode("shadow_only")
    ps.set_open_imgui_window_for_user_callback(True)


# parametric surfaces are written z-up; the viewer is y-up: display them rotated (x, y, z) ->
# (x, z, -y) with a polyscope transform, so the data (and the numbers in the panel) are unchanged
Z_TO_Y = np.array([[1.0, 0, 0, 0], [0, 0, 1, 0], [0, -1, 0, 0], [0, 0, 0, 1]])


def side_offset(V: np.ndarray) -> np.ndarray:
    """Offset of a copy shown beside a mesh: to its right as seen from the default camera."""
    return np.array([-1.15 * float(np.ptp(V[:, 0])) - 1e-9, 0.0, 0.0])


def remove_structure(name: str) -> None:
    """Remove a registered structure of any of the kinds the viewer uses (no-op if absent)."""
    for has, remove in (
        (ps.has_surface_mesh, ps.remove_surface_mesh),
        (ps.has_curve_network, ps.remove_curve_network),
        (ps.has_point_cloud, ps.remove_point_cloud),
    ):
        if has(name):
            remove(name)


def _combo(label: str, current: str, items: tuple[str, ...] | list[str]) -> tuple[bool, str]:
    changed, idx = psim.Combo(label, list(items).index(current), list(items))
    return changed, items[idx]


class Viewer:
    """All panels; holds one state object per panel and the names of what is registered."""

    def __init__(
        self,
        mesh: MeshState,
        curv: CurvatureState | None = None,
        panel: str = "curvature",
    ) -> None:
        self.mesh = mesh
        self.curv = curv or CurvatureState()
        self.ring = OneRingState()
        self.surf = SurfaceState()
        # the spectral and smoothing panels live in their own modules; they get the same hooks
        self.extra: dict[str, Any] = {
            "spectral": spectral_panel.Panel(),
            "smoothing": smoothing_panel.Panel(),
        }
        self.panel = panel
        self.path_text = ""
        self.side_by_side = False
        self.second_field = "uniform"
        self.shown_field = ""
        self._mesh_version = -1
        self._surface_version = -1
        self.status = ""
        self.labels: list[tuple[tuple[float, float], str]] = []  # the one-ring numbers drawn

    # ------------------------------------------------------------------ registration
    def sync_mesh(self) -> None:
        """Register the mesh when it changed (a new file), then the visible panel."""
        if self._mesh_version != self.mesh.version:
            self._mesh_version = self.mesh.version
            for name in (MESH, MESH_B, RING_CURVE, RING_POINTS, RING_CENTER):
                remove_structure(name)
            ps.register_surface_mesh(MESH, self.mesh.V, self.mesh.F, smooth_shade=True)
            self.ring = OneRingState(reverse=self.ring.reverse)
            self.shown_field = ""
            for hook in self.extra.values():
                hook.on_new_mesh(self)
        self.push_curvature()
        self.show_panel()

    def push_curvature(self, force: bool = False) -> None:
        """Add the selected curvature field(s) as colour maps (only when they changed)."""
        changed = self.curv.update(self.mesh) or force
        key = (self.curv.field_name, self.curv.percentile, self.side_by_side, self.second_field)
        if not changed and key == self.shown_field:
            return
        self.shown_field = key
        sm = ps.get_surface_mesh(MESH)
        self._add_field(sm, self.curv.field_name, enabled=True)
        if self.side_by_side:
            shift = side_offset(self.mesh.V)
            if not ps.has_surface_mesh(MESH_B):
                ps.register_surface_mesh(
                    MESH_B, self.mesh.V + shift, self.mesh.F, smooth_shade=True
                )
            self._add_field(ps.get_surface_mesh(MESH_B), self.second_field, enabled=True)
        elif ps.has_surface_mesh(MESH_B):
            ps.remove_surface_mesh(MESH_B)

    def _add_field(self, sm: Any, name: str, enabled: bool) -> None:
        label, signed = FIELD_LABELS[name]
        lo, hi = self.curv.color_range(name)
        sm.add_scalar_quantity(
            label,
            self.curv.fields[name],
            defined_on="vertices",
            cmap="coolwarm" if signed else "viridis",
            vminmax=(lo, hi),
            enabled=enabled,
        )

    def show_panel(self) -> None:
        """Show the structures of the current panel and hide the others."""
        on_mesh = self.panel in ("curvature", "onering", "spectral", "smoothing")
        if ps.has_surface_mesh(MESH):
            ps.get_surface_mesh(MESH).set_enabled(on_mesh)
        if ps.has_surface_mesh(MESH_B):
            ps.get_surface_mesh(MESH_B).set_enabled(self.panel == "curvature")
        for name in (RING_CURVE,):
            if ps.has_curve_network(name):
                ps.get_curve_network(name).set_enabled(self.panel == "onering")
        for name in (RING_POINTS, RING_CENTER):
            if ps.has_point_cloud(name):
                ps.get_point_cloud(name).set_enabled(self.panel == "onering")
        if self.panel == "surfaces":
            self.push_surface()
        for name in (SURFACE,):
            if ps.has_surface_mesh(name):
                ps.get_surface_mesh(name).set_enabled(self.panel == "surfaces")
        if ps.has_point_cloud(SURFACE_POINT):
            ps.get_point_cloud(SURFACE_POINT).set_enabled(self.panel == "surfaces")
        for hook in self.extra.values():
            hook.show(self, self.panel)

    # ------------------------------------------------------------------ one-ring
    def select_vertex(self, i: int) -> bool:
        """Select vertex ``i`` and draw its ordered one-ring."""
        if not self.ring.select(self.mesh, self.curv, i):
            return False
        self.push_ring()
        return True

    def push_ring(self) -> None:
        r = self.ring
        if r.valence == 0:
            return
        # sizes follow the ring's own edge length, so any mesh and zoom level looks the same
        scale = 0.08 * float(np.linalg.norm(r.polyline - self.mesh.V[r.vertex], axis=1).mean())
        cn = ps.register_curve_network(RING_CURVE, r.polyline, r.edges, radius=0.5 * scale)
        cn.set_radius(0.5 * scale, relative=False)
        cn.set_color((0.1, 0.1, 0.1))
        pc = ps.register_point_cloud(RING_POINTS, r.polyline, radius=1.5 * scale)
        pc.set_radius(1.5 * scale, relative=False)
        pc.add_scalar_quantity("order", r.order_t, cmap="viridis", enabled=True, vminmax=(0, 1))
        pc.add_vector_quantity(
            "direction", 0.85 * r.arrows, vectortype="ambient", enabled=True, color=(0.9, 0.5, 0.0)
        )
        c = ps.register_point_cloud(RING_CENTER, self.mesh.V[[r.vertex]], radius=2.0 * scale)
        c.set_radius(2.0 * scale, relative=False)
        c.set_color((1.0, 0.1, 0.1))
        self.show_panel()

    def focus_ring(self) -> None:
        """Point the camera at the selected vertex, along its normal, framing the one-ring."""
        r = self.ring
        if r.valence == 0:
            return
        center = self.mesh.V[r.vertex]
        size = float(np.linalg.norm(r.polyline - center, axis=1).max()) or 1.0
        normal = r.normal if np.linalg.norm(r.normal) > 0 else np.array([0.0, 0.0, 1.0])
        # tilt a little towards the up axis inside the tangent plane: looking straight along
        # the up axis (a flat mesh seen from above) is a degenerate camera frame
        tilt = np.array([0.0, 1.0, 0.0]) - normal[1] * normal
        if np.linalg.norm(tilt) < 1e-6:
            tilt = np.array([1.0, 0.0, 0.0]) - normal[0] * normal
        tilt /= np.linalg.norm(tilt)
        ps.look_at(center + size * (7.0 * normal + 2.0 * tilt), center)

    def ring_labels(self) -> list[tuple[tuple[float, float], str]]:
        """Screen positions and texts of the order numbers ("0", "1", ...) of the one-ring."""
        if self.ring.valence == 0:
            return []
        params = ps.get_view_camera_parameters()
        w, h = ps.get_window_size()
        xy, front = project_to_screen(
            self.ring.polyline, params.get_view_mat(), params.get_fov_vertical_deg(), w, h
        )
        return [
            ((float(x) + 12, float(y) - 22), str(k))
            for k, ((x, y), f) in enumerate(zip(xy, front, strict=True))
            if f
        ]

    # ------------------------------------------------------------------ surfaces
    def push_surface(self) -> None:
        if self.surf.mesh is None:
            self.surf.set_surface(self.surf.name)
        sm = self.surf.mesh
        if sm is None:
            return
        if self._surface_version != self.surf.version:
            self._surface_version = self.surf.version
            s = ps.register_surface_mesh(SURFACE, sm.V, sm.F, smooth_shade=True)
            s.set_transform(Z_TO_Y)
            from meshlap_core.surfaces import curvature_fields as surface_curvature

            cf = surface_curvature(self.surf.name, sm.uv[:, 0], sm.uv[:, 1])
            K = np.nan_to_num(np.asarray(cf.K, dtype=float))
            r = float(np.percentile(np.abs(K), 98)) or 1.0
            s.add_scalar_quantity(
                "Gaussian curvature K (exact)", K, cmap="coolwarm", vminmax=(-r, r), enabled=True
            )
        self.push_surface_point()

    def push_surface_point(self) -> None:
        if self.surf.point is None:
            return
        size = float(np.ptp(self.surf.mesh.V, axis=0).max()) if self.surf.mesh is not None else 1.0
        base, d1, d2 = self.surf.direction_vectors(scale=0.15 * size)
        pc = ps.register_point_cloud(SURFACE_POINT, base, radius=0.01)
        pc.set_transform(Z_TO_Y)
        pc.set_color((0.9, 0.1, 0.1))
        pc.add_vector_quantity(
            "k1 direction", d1, vectortype="ambient", enabled=True, color=(0.85, 0.2, 0.1)
        )
        pc.add_vector_quantity(
            "k2 direction", d2, vectortype="ambient", enabled=True, color=(0.1, 0.3, 0.85)
        )
        pc.add_vector_quantity(
            "normal",
            0.15 * size * self.surf.point.n[None, :],
            vectortype="ambient",
            enabled=True,
            color=(0.2, 0.7, 0.2),
        )

    # ------------------------------------------------------------------ picking
    def handle_click(self) -> None:
        io = psim.GetIO()
        if io.WantCaptureMouse or not psim.IsMouseClicked(0):
            return
        self.pick_at(io.MousePos)

    def pick_at(self, screen_xy: tuple[float, float]) -> bool:
        """Pick at window coordinates; a vertex of the mesh selects its one-ring (or a point
        on the parametric surface). Uses the structure's own element index."""
        res = ps.pick(screen_coords=screen_xy)
        if not res.is_hit:
            return False
        data = res.structure_data
        if res.structure_name == MESH and self.panel in ("onering", "curvature"):
            idx = self._vertex_of(data, res.position, self.mesh.V, self.mesh.F)
            if idx is not None:
                self.panel = "onering"
                return self.select_vertex(idx)
        if res.structure_name == SURFACE and self.surf.mesh is not None:
            shown = self.surf.mesh.V @ Z_TO_Y[:3, :3].T  # picked positions are in world space
            idx = self._vertex_of(data, res.position, shown, self.surf.mesh.F)
            if idx is not None and self.surf.pick_vertex(idx):
                self.push_surface_point()
                return True
        return False

    @staticmethod
    def _vertex_of(data: dict, position: Any, V: np.ndarray, F: np.ndarray) -> int | None:
        kind = data.get("element_type")
        if kind == "vertex":
            return int(data["index"])
        if kind == "face":  # nearest corner of the clicked face
            f = F[int(data["index"])]
            return int(f[np.argmin(np.linalg.norm(V[f] - np.asarray(position), axis=1))])
        return None

    # ------------------------------------------------------------------ panels
    def callback(self) -> None:
        """The per-frame user callback: draw the panels, react to changes only."""
        psim.PushItemWidth(200)
        self.panel_mesh()
        changed, idx = psim.Combo("view", PANELS.index(self.panel), list(PANELS))
        if changed:
            self.panel = PANELS[idx]
            self.show_panel()
        getattr(self, f"panel_{self.panel}")()
        self.panel_export()
        psim.PopItemWidth()
        self.handle_click()
        if self.panel == "onering":
            self.labels = self.ring_labels()
            dl = psim.GetForegroundDrawList()
            col = psim.GetColorU32((0.05, 0.05, 0.05, 1.0))
            for pos, text in self.labels:
                dl.AddText(pos, col, text)

    def panel_mesh(self) -> None:
        if not psim.CollapsingHeader("Mesh", psim.ImGuiTreeNodeFlags_DefaultOpen):
            return
        info = self.mesh.info
        psim.TextUnformatted(
            f"{self.mesh.name}: {info.get('n_vertices', 0)} vertices, "
            f"{info.get('n_faces', 0)} faces, chi = {info.get('euler_characteristic')}, "
            f"genus = {info.get('genus')}"
        )
        psim.TextUnformatted(
            f"boundary loops {info.get('n_boundary_loops')}, components "
            f"{info.get('n_components')}, manifold {'yes' if info.get('manifold') else 'no'}"
        )
        for r in info.get("repairs", []):
            psim.TextUnformatted(f"repaired: {r}")
        _, self.path_text = psim.InputText("path", self.path_text)
        psim.SameLine()
        if psim.Button("Open") and self.path_text:
            self.open(Path(self.path_text).expanduser())
        choices = list_meshes()
        if choices and psim.BeginCombo("bundled / shared", "choose a mesh"):
            for label, path in choices:
                if psim.Selectable(label)[0]:
                    self.open(path)
            psim.EndCombo()
        if self.mesh.error:
            psim.TextColored(RED, self.mesh.error)

    def open(self, path: Path | None) -> bool:
        if self.mesh.load(path):
            self.sync_mesh()
            ps.reset_camera_to_home_view()
            return True
        return False

    def panel_curvature(self) -> None:
        if not psim.CollapsingHeader("Curvature", psim.ImGuiTreeNodeFlags_DefaultOpen):
            return
        c = self.curv
        names = tuple(FIELD_LABELS)
        ch1, c.field_name = _combo("field", c.field_name, names)
        ch2, c.area = _combo("area", c.area, AREAS)
        ch3, c.boundary = _combo("boundary rule", c.boundary, BOUNDARY_RULES)
        ch4, c.percentile = psim.SliderFloat("clip %", c.percentile, 0.0, 20.0, "%.1f")
        ch5, self.side_by_side = psim.Checkbox("side by side", self.side_by_side)
        ch6 = False
        if self.side_by_side:
            ch6, self.second_field = _combo("second field", self.second_field, names)
        if ch1 or ch2 or ch3 or ch4 or ch5 or ch6:
            self.push_curvature(force=ch2 or ch3)
            self.show_panel()
        if c.field_name not in c.fields:
            return
        st = c.summary()
        lo, hi = st["range"]
        psim.TextUnformatted(
            f"min {st['min']:.4g}  max {st['max']:.4g}  colour range [{lo:.4g}, {hi:.4g}]"
        )
        psim.TextUnformatted(FIELD_LABELS[c.field_name][0])
        ip = self._implot()
        if ip.BeginPlot("histogram (clipped to the colour range)", (-1, 160)):
            ip.PlotBars("vertices", st["centers"], st["counts"], st["width"])
            ip.EndPlot()

    @staticmethod
    def _implot() -> Any:
        import polyscope.implot as psimplot

        return psimplot

    def panel_onering(self) -> None:
        if not psim.CollapsingHeader("One-ring", psim.ImGuiTreeNodeFlags_DefaultOpen):
            return
        psim.TextUnformatted("click a vertex of the mesh")
        n = len(self.mesh.V)
        ch, v = psim.InputInt("vertex", max(self.ring.vertex, 0))
        if ch and 0 <= v < n:
            self.select_vertex(v)
        ch, _ = psim.Checkbox("clockwise (reverse)", self.ring.reverse)
        if ch:
            self.ring.toggle_reverse(self.mesh, self.curv)
            self.push_ring()
        r = self.ring
        if r.vertex < 0:
            return
        kind = "boundary vertex (open fan)" if r.boundary else "interior vertex (closed cycle)"
        psim.TextUnformatted(f"vertex {r.vertex}: {kind}, valence {r.valence}")
        psim.TextUnformatted(f"H (cotan) = {r.H + 0.0:.5g}   K (angle deficit) = {r.K + 0.0:.5g}")
        if not r.ordered:
            psim.TextColored(RED, "not a disk: neighbours listed by index, not in order")
        psim.TextUnformatted("order: " + " -> ".join(str(j) for j in r.neighbors[:40]))

    def panel_spectral(self) -> None:
        self.extra["spectral"].draw(self)

    def panel_smoothing(self) -> None:
        self.extra["smoothing"].draw(self)

    def panel_surfaces(self) -> None:
        if not psim.CollapsingHeader("Surfaces", psim.ImGuiTreeNodeFlags_DefaultOpen):
            return
        s = self.surf
        ch, name = _combo("surface", s.name, s.names)
        if ch and s.set_surface(name):
            self.push_surface()
            ps.reset_camera_to_home_view()
        u0, u1, v0, v1 = s.domain
        ch1, u = psim.SliderFloat("u", s.u, u0, u1)
        ch2, v = psim.SliderFloat("v", s.v, v0, v1)
        if (ch1 or ch2) and s.set_uv(u, v):
            self.push_surface_point()
        if s.error:
            psim.TextColored(RED, s.error)
        p = s.point
        if p is None:
            return
        psim.TextUnformatted(f"I:  E = {p.E:.4g}  F = {p.F:.4g}  G = {p.G:.4g}")
        psim.TextUnformatted(f"II: e = {p.e:.4g}  f = {p.f:.4g}  g = {p.g:.4g}")
        psim.TextUnformatted(f"K = {p.K:.4g}  H = {p.H:.4g}  ({p.classification})")
        psim.TextUnformatted(
            f"k1 = {p.k1:.4g} at {np.degrees(p.theta_max):.1f} deg,  "
            f"k2 = {p.k2:.4g} at {np.degrees(p.theta_min):.1f} deg"
        )
        psim.TextUnformatted("signs: e = p_uu . n with n = p_u x p_v (do Carmo)")
        ip = self._implot()
        if ip.BeginPlot("normal curvature k_n(theta)", (-1, 180)):
            ip.PlotLine("k_n", s.theta, s.kn)
            ip.PlotInfLines("theta max/min", np.array([p.theta_max, p.theta_min]))
            ip.EndPlot()

    def panel_export(self) -> None:
        if not psim.CollapsingHeader("Export"):
            return
        if psim.Button("screenshot"):
            ps.screenshot()
        psim.SameLine()
        if psim.Button("export mesh + field"):
            self.status = self.export(Path.cwd())
        if self.status:
            psim.TextUnformatted(self.status)

    def export(self, folder: Path) -> str:
        """Write the current mesh (PLY with the shown field) and the field (CSV) into folder."""
        stem = Path(self.mesh.name).stem or "mesh"
        field = self.curv.fields.get(self.curv.field_name)
        try:
            save_mesh(
                folder / f"{stem}_{self.curv.field_name}.ply",
                self.mesh.V,
                self.mesh.F,
                scalars=field,
            )
            if field is not None:
                save_scalars(folder / f"{stem}_{self.curv.field_name}.csv", field)
        except (MeshError, OSError) as exc:
            return f"export failed: {exc}"
        return f"wrote {stem}_{self.curv.field_name}.ply/.csv in {folder}"


def run(
    path: str | Path | None = None,
    screenshot: str | Path | None = None,
    field: str = "cotan",
    panel: str = "curvature",
    vertex: int | None = None,
    k: int | None = None,
    backend: str | None = None,
) -> int:
    """Open the viewer on ``path`` (the bundled default mesh when ``None``).

    With ``screenshot`` a single frame is rendered headless (EGL) into that PNG and the
    function returns.
    """
    path = Path(path).resolve() if path is not None else None
    shot = Path(screenshot).resolve() if screenshot is not None else None
    if shot is not None and not shot.parent.is_dir():
        raise MeshError(f"output directory {shot.parent} does not exist", shot)
    if field not in FIELD_LABELS:
        raise MeshError(
            f"unknown field {field!r}; choose one of {', '.join(FIELD_LABELS)}", "--field"
        )
    if panel not in PANELS:
        raise MeshError(f"unknown panel {panel!r}; choose one of {', '.join(PANELS)}", "--panel")
    mesh = MeshState()
    if not mesh.load(path):
        raise MeshError(mesh.error)
    if vertex is not None and not 0 <= vertex < len(mesh.V):
        raise MeshError(
            f"vertex {vertex} is out of range (the mesh has {len(mesh.V)} vertices)", "--vertex"
        )
    _init(backend or ("openGL3_egl" if shot else "auto"))
    viewer = Viewer(mesh, CurvatureState(field_name=field), panel=panel)
    viewer.sync_mesh()
    if shot is not None:
        ps.set_window_size(1600, 900)
        ps.set_build_default_gui_panels(False)  # the screenshot shows our panel only
    if panel == "onering":
        viewer.select_vertex(vertex if vertex is not None else 0)
    if k is not None:
        viewer.extra["spectral"].prepare_screenshot(viewer, k)
    if panel == "smoothing":
        viewer.extra["smoothing"].prepare_screenshot(viewer)
    ps.set_user_callback(viewer.callback)
    if shot is not None:
        if panel == "onering":
            viewer.focus_ring()
        else:
            frame_scene_left(viewer)
        ps.frame_tick()
        ps.frame_tick()  # ImPlot fits its axes on the second frame
        buf = ps.screenshot_to_buffer(transparent_bg=False, include_UI=True)
        _write_png(shot, buf)
        ps.clear_user_callback()
        ps.remove_all_structures()
        return 0
    ps.show()
    return 0


def frame_scene_left(viewer: Viewer, fraction: float = 0.6) -> None:
    """Look at every enabled structure from the front so the scene fills the left
    ``fraction`` of the window (the panel sits on the right in screenshots)."""
    pts = []
    for name in (MESH, MESH_B, SURFACE, "reconstruction", "smoothed", "smoothing input"):
        if ps.has_surface_mesh(name) and ps.get_surface_mesh(name).is_enabled():
            pts.append(_structure_points(viewer, name))
    if not pts:
        ps.reset_camera_to_home_view()
        return
    P = np.vstack(pts)
    lo, hi = P.min(axis=0), P.max(axis=0)
    c = 0.5 * (lo + hi)
    w, h = ps.get_window_size()
    fov = np.radians(ps.get_view_camera_parameters().get_fov_vertical_deg())
    tan_v = np.tan(fov / 2.0)
    tan_h = tan_v * w / h
    # y is up and the camera looks along +z from the front (scans face -z): seen from there,
    # screen-right is -x, so aiming at c - shift puts the scene centre left of the window centre
    depth = hi[2] - lo[2]
    d = max((hi[0] - lo[0]) / (2 * fraction * tan_h), (hi[1] - lo[1]) / (2 * 0.85 * tan_v))
    d += 0.5 * depth
    shift = (0.5 - 0.5 * fraction) * 2 * d * tan_h
    eye = np.array([c[0] - shift, c[1] + 0.15 * (hi[1] - lo[1]), lo[2] - d])
    ps.look_at(eye, np.array([c[0] - shift, c[1], c[2]]))


def _structure_points(viewer: Viewer, name: str) -> np.ndarray:
    if name == MESH:
        return viewer.mesh.V
    if name == MESH_B:
        return viewer.mesh.V + side_offset(viewer.mesh.V)
    if name == SURFACE and viewer.surf.mesh is not None:
        return viewer.surf.mesh.V @ Z_TO_Y[:3, :3].T
    for hook in viewer.extra.values():
        pts = hook.points(viewer, name) if hasattr(hook, "points") else None
        if pts is not None:
            return pts
    return viewer.mesh.V


def _write_png(path: Path, rgba: np.ndarray) -> None:
    """Write an RGBA buffer as PNG atomically (matplotlib's encoder, no extra dependency)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.image as mpimg

    with atomic_write(path, mode="wb") as fh:
        mpimg.imsave(fh, rgba, format="png")
