"""The viewer's loop: opens polyscope, owns the state objects and the panels, runs the frame.

``run`` opens a window (or, with ``screenshot``, renders one frame with the EGL backend and
exits). Paths are resolved before ``polyscope.init()``, which may change the working directory.

Each panel (``app/panels/``) reads its widgets, calls its state object's methods and, only when
something changed, pushes arrays to polyscope (position updates where the connectivity is
unchanged, never re-registration per frame). Structure names, offsets and framing live in
:mod:`.scene`.
"""

from __future__ import annotations

import os
import sys
import traceback
from pathlib import Path
from typing import Any

import numpy as np
import polyscope as ps
import polyscope.imgui as psim

from meshlap_core.errors import MeshError

from . import scene
from .panels.curvature import CurvaturePanel
from .panels.export import ExportPanel
from .panels.mesh import MeshPanel
from .panels.onering import OneRingPanel
from .panels.smoothing import SmoothingPanel
from .panels.spectral import SpectralPanel
from .panels.surfaces import SurfacesPanel
from .scene import MESH, SURFACE, Z_TO_Y
from .state.curvature import CurvatureState
from .state.mesh import MeshState
from .state.names import FIELD_LABELS, PANELS
from .state.onering import OneRingState
from .state.surface import SurfaceState
from .ui import UI

NO_DISPLAY = (
    "no display could be opened for the viewer window; render headless with "
    "`meshlap view MESH --screenshot out.png`"
)

FRAMED = (
    scene.MESH,
    scene.MESH_B,
    scene.SURFACE,
    scene.RECON,
    scene.SMOOTHED,
    scene.SMOOTH_INPUT,
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


class Viewer:
    """The state objects (one per concern) and the panels that show them."""

    def __init__(
        self,
        mesh: MeshState,
        curv: CurvatureState | None = None,
        panel: str = "curvature",
        ui: UI | None = None,
        export_dir: Path | None = None,
    ) -> None:
        self.ui = ui or UI()
        self.errors: dict[str, str] = {}  # section -> the message shown in red there
        self._logged: set[tuple[str, str]] = set()
        self.mesh = mesh
        self.curv = curv or CurvatureState()
        self.ring = OneRingState()
        self.surf = SurfaceState()
        self.panels: dict[str, Any] = {
            "mesh": MeshPanel(),
            "curvature": CurvaturePanel(),
            "onering": OneRingPanel(),
            "spectral": SpectralPanel(),
            "smoothing": SmoothingPanel(),
            "surfaces": SurfacesPanel(),
            "export": ExportPanel(export_dir),
        }
        self.panel = panel
        self._mesh_version = -1

    # ------------------------------------------------------------------ registration
    def sync_mesh(self) -> None:
        """Register the mesh when it changed (a new file), then the visible panel."""
        if self._mesh_version != self.mesh.version:
            self._mesh_version = self.mesh.version
            for name in (
                MESH,
                scene.MESH_B,
                scene.RING_CURVE,
                scene.RING_POINTS,
                scene.RING_CENTER,
            ):
                scene.remove_structure(name)
            ps.register_surface_mesh(MESH, self.mesh.V, self.mesh.F, smooth_shade=True)
            self.ring = OneRingState(reverse=self.ring.reverse)
            for p in self.panels.values():
                p.on_new_mesh(self)
        self.push_curvature()
        self.show_panel()

    def push_curvature(self, force: bool = False) -> None:
        """Add the selected curvature field(s) as colour maps (only when they changed)."""
        self.panels["curvature"].push(self, force)

    def show_panel(self) -> None:
        """Show the structures of the current panel and hide the others."""
        on_mesh = self.panel in ("curvature", "onering", "spectral", "smoothing")
        if ps.has_surface_mesh(MESH):
            ps.get_surface_mesh(MESH).set_enabled(on_mesh)
        for name in ("curvature", "onering", "surfaces", "spectral", "smoothing"):
            self.panels[name].show(self, self.panel)

    # ------------------------------------------------------------------ one-ring
    def select_vertex(self, i: int) -> bool:
        """Select vertex ``i`` and draw its ordered one-ring."""
        return self.panels["onering"].select(self, i)

    def focus_ring(self) -> None:
        """Point the camera at the selected vertex, along its normal, framing the one-ring."""
        self.panels["onering"].focus(self)

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
                self.panels["surfaces"].push_point(self)
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

    # ------------------------------------------------------------------ the frame
    def callback(self) -> None:
        """The per-frame user callback: draw the panels, react to changes only.

        Every section runs guarded (:meth:`draw_guarded`): no exception of a widget handler
        leaves this function, so none ends the session.
        """
        ui = self.ui
        ui.push_width(200)
        try:
            self.draw_guarded("mesh", self.panels["mesh"].draw)
            self.draw_guarded("view", self.draw_view_combo)
            self.draw_guarded(self.panel, self.panels[self.panel].draw)
            self.draw_guarded("export", self.panels["export"].draw)
        finally:
            ui.pop_width()
        self.draw_guarded("picking", lambda viewer: viewer.handle_click())
        if self.panel == "onering":
            self.draw_guarded("labels", self.panels["onering"].draw_labels)

    def draw_view_combo(self, viewer: Viewer) -> None:
        changed, panel = self.ui.combo(
            "view", self.panel, PANELS, "which panel: curvature, one-ring, spectral, ..."
        )
        if changed:
            self.set_panel(panel)

    def set_panel(self, panel: str) -> None:
        """Switch to ``panel`` and show its structures."""
        if panel not in PANELS:
            raise MeshError(f"unknown panel {panel!r}; choose one of {', '.join(PANELS)}", "view")
        self.panel = panel
        self.show_panel()

    def draw_guarded(self, section: str, draw: Any) -> None:
        """Run ``draw(self)``; an exception is shown in red in that section, never raised.

        A ``MeshError``/``ValueError`` (bad widget input) shows its message and the state keeps
        its last good values (the state objects validate before they change). Anything else is
        an internal error: shown with a "details" line and logged once on stderr (with the
        traceback when ``MESHLAP_DEBUG=1``). The message stays until a widget of the section
        changes something without an error.
        """
        ui = self.ui
        outer = (ui.section, ui.changed)  # a screenshot re-runs the callback from inside one
        ui.begin_section(section)
        try:
            draw(self)
        except ValueError as exc:  # MeshError is a ValueError: bad input, said in its message
            self.errors[section] = str(exc)
        except Exception as exc:  # a bug or an API change: keep the session, say what failed
            self.errors[section] = self._internal_error(section, exc)
        else:
            if ui.changed:
                self.errors.pop(section, None)
        message = self.errors.get(section)
        if message:
            ui.error(message)
        ui.section, ui.changed = outer[0], outer[1] or ui.changed

    def _internal_error(self, section: str, exc: Exception) -> str:
        tb = traceback.extract_tb(exc.__traceback__)
        where = f" at {Path(tb[-1].filename).name}:{tb[-1].lineno}" if tb else ""
        text = f"internal error: {type(exc).__name__}: {exc}"
        key = (section, f"{type(exc).__name__}{where}")
        if key not in self._logged:
            self._logged.add(key)
            print(f"meshlap: {section} panel: {text}{where}", file=sys.stderr)
            if os.environ.get("MESHLAP_DEBUG") == "1":
                traceback.print_exception(exc, file=sys.stderr)
        return (
            f"{text}\ndetails: {type(exc).__name__}{where}; the last good state is kept "
            "(MESHLAP_DEBUG=1 prints the traceback)"
        )

    def open(self, path: Path | None) -> bool:
        """Load ``path``; on failure the error is shown in the Mesh panel, the mesh stays."""
        if self.mesh.load(path):
            if path is not None:
                self.panels["mesh"].remember(Path(path))
            self.sync_mesh()
            ps.reset_camera_to_home_view()
            return True
        return False

    def export(self, folder: Path) -> str:
        """Write the current mesh (PLY with the shown field) and the field (CSV) into folder."""
        return self.panels["export"].export(self, folder)

    def structure_points(self, name: str) -> np.ndarray | None:
        """World positions of a structure some panel registered (for camera framing)."""
        for p in self.panels.values():
            P = p.points(self, name)
            if P is not None:
                return P
        return None

    def frame(self, fraction: float = 0.6) -> None:
        """Frame the enabled structures in the left ``fraction`` of the window."""
        scene.frame_scene_left(FRAMED, self.structure_points, fraction)


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
    cwd = Path.cwd()  # before polyscope.init(), which may change it: the export folder
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
    viewer = Viewer(mesh, CurvatureState(field_name=field), panel=panel, export_dir=cwd)
    viewer.sync_mesh()
    if shot is not None:
        ps.set_window_size(1600, 900)
        ps.set_build_default_gui_panels(False)  # the screenshot shows our panel only
    if panel == "onering":
        viewer.select_vertex(vertex if vertex is not None else 0)
    if k is not None:
        viewer.panels["spectral"].prepare_screenshot(viewer, k)
    if panel == "smoothing":
        viewer.panels["smoothing"].prepare_screenshot(viewer)
    ps.set_user_callback(viewer.callback)
    if shot is not None:
        if panel == "onering":
            viewer.focus_ring()
        else:
            viewer.frame()
        ps.frame_tick()
        ps.frame_tick()  # ImPlot fits its axes on the second frame
        scene.save_screenshot(shot)
        ps.clear_user_callback()
        ps.remove_all_structures()
        return 0
    ps.show()
    return 0
