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
import time
import traceback
from pathlib import Path
from typing import Any

import numpy as np
import polyscope as ps

from meshlap_core.errors import MeshError

from . import scene
from .panels.curvature import CurvaturePanel
from .panels.export import ExportPanel
from .panels.help import HelpPanel
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
from .state.spectral import SCREENSHOT_K
from .state.surface import SurfaceState
from .ui import UI

NO_DISPLAY = (
    "no display could be opened for the viewer window; render headless with "
    "`meshlap view MESH --screenshot out.png`"
)

PANEL_PX = scene.PANEL_PX

BUSY_FRAME_S = 0.35
"""While the eigen worker runs, each frame waits this long (about 5 frames/s): the render loop
then leaves the cores to the solver, so the basis takes about as long as ``meshlap spectral``."""

FRAMED = (
    scene.MESH,
    scene.MESH_B,
    scene.SURFACE,
    scene.RECON,
    scene.SMOOTHED,
    scene.SMOOTH_INPUT,
)


def init_polyscope(backend: str) -> None:
    """Start polyscope on ``backend`` ("auto", "openGL3_egl", "openGL_mock") with meshlap's scene
    options; a missing display or a failed backend is a ``MeshError`` (one line, exit 2)."""
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
        self.display = scene.Display()  # world -> display coordinates (float32-safe uploads)
        self.busy_frame_s = BUSY_FRAME_S
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
            "help": HelpPanel(),
        }
        self.panel = panel
        self._mesh_version = -1
        self.reframe = True  # frame the visible structures at the end of the next frame
        self._window_size: tuple[int, int] = (0, 0)
        self._caption_boxes: dict[str, tuple[np.ndarray, np.ndarray]] = {}

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
            self.display.fit(self.mesh.V)
            shown = self.display.points(self.mesh.V)
            ps.register_surface_mesh(MESH, shown, self.mesh.F, smooth_shade=True)
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
        xy = self.ui.scene_click()
        if xy is not None:
            self.pick_at(xy)

    def handle_keys(self) -> None:
        """The shortcuts (listed in the Help panel)."""
        ui = self.ui
        for i, name in enumerate(PANELS):
            if ui.key(str(i + 1)):
                self.set_panel(name)
        smoothing, spectral = self.panels["smoothing"], self.panels["spectral"]
        if ui.key("space") and self.panel == "smoothing":
            smoothing.state.playing = not smoothing.state.playing
        for key, dk in (("right", 1), ("left", -1)):
            if not ui.key(key):
                continue
            if self.panel == "smoothing" and dk > 0:
                smoothing.state.step()
            elif self.panel == "spectral" and spectral.state.basis is not None:
                spectral.state.set_k(spectral.state.k + dk)
                spectral.push_k(self)
        if ui.key("f"):
            self.reframe = True
        if ui.key("h"):
            self.panels["help"].toggle()
        if ui.key("r"):
            if self.panel == "smoothing":
                smoothing.state.reset()
                smoothing.push(force=True)
            else:
                self.reframe = True

    def files_dropped(self, paths: list[str]) -> None:
        """polyscope's drag-and-drop callback: open the first file dropped on the window (a
        ``.json`` file is loaded as a saved session).

        Runs outside the imgui frame, so it draws nothing: a failure is kept for the Mesh panel
        (``mesh.error``, or ``errors["mesh"]`` for an internal error) and never raised.
        """
        if not paths:
            return
        try:
            if Path(paths[0]).suffix.lower() == ".json":  # a saved session
                from .session import load

                load(self, paths[0])
                self.errors.pop("mesh", None)
            else:
                self.open(Path(paths[0]))
        except MeshError as exc:  # a refused session: said in the Mesh panel, nothing changes
            self.errors["mesh"] = str(exc)
        except Exception as exc:  # a callback from C++ must not raise
            self.errors["mesh"] = self._internal_error("mesh", exc)

    def pick_at(self, screen_xy: tuple[float, float]) -> bool:
        """Pick at window coordinates; a vertex of the mesh selects its one-ring (or a point
        on the parametric surface). Uses the structure's own element index."""
        res = ps.pick(screen_coords=screen_xy)
        if not res.is_hit:
            return False
        data = res.structure_data
        if res.structure_name == MESH and self.panel in ("onering", "curvature"):
            shown = self.display.points(self.mesh.V)  # picked positions are display positions
            idx = self._vertex_of(data, res.position, shown, self.mesh.F)
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
        if self.panels["spectral"].state.busy and self.busy_frame_s > 0:
            time.sleep(self.busy_frame_s)  # releases the GIL too
        ui.push_width(200)
        try:
            self.draw_guarded("mesh", self.panels["mesh"].draw)
            self.draw_guarded("view", self.draw_view_combo)
            self.draw_guarded(self.panel, self.panels[self.panel].draw)
            self.draw_guarded("export", self.panels["export"].draw)
            self.draw_guarded("help", self.panels["help"].draw)
        finally:
            ui.pop_width()
        self.draw_guarded("picking", lambda viewer: viewer.handle_click())
        self.draw_guarded("keys", lambda viewer: viewer.handle_keys())
        if self.panel == "onering":
            self.draw_guarded("labels", self.panels["onering"].draw_labels)
        self.draw_guarded("layout", lambda viewer: viewer.layout())

    def layout(self) -> None:
        """Re-frame after a change of what is shown or of the window size; draw captions."""
        size = tuple(ps.get_window_size())
        if self.reframe or size != self._window_size:
            self._window_size = size
            self.reframe = False
            self.frame()
        self.draw_captions()

    def draw_view_combo(self, viewer: Viewer) -> None:
        changed, panel = self.ui.combo(
            "view", self.panel, PANELS, "which panel: curvature, one-ring, spectral, ..."
        )
        if changed:
            self.set_panel(panel)

    def set_panel(self, panel: str) -> None:
        """Switch to ``panel``, show its structures and frame them."""
        if panel not in PANELS:
            raise MeshError(f"unknown panel {panel!r}; choose one of {', '.join(PANELS)}", "view")
        self.panel = panel
        self.show_panel()
        self.reframe = True

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
            self.reframe = True
            return True
        return False

    def export(self, folder: Path) -> str:
        """Write the current mesh (PLY with the shown field) and the field (CSV) into folder."""
        return self.panels["export"].export(self, folder)

    def structure_points(self, name: str) -> np.ndarray | None:
        """Display positions of a structure some panel registered (for camera framing)."""
        for p in self.panels.values():
            P = p.points(self, name)
            if P is not None:
                return P
        return None

    def frame(self) -> None:
        """Frame what the current panel shows in the part of the window left of meshlap's panel
        (the one-ring: its selected vertex; the surfaces: obliquely from above; a mesh: from its
        front, see ``scene.FRONT_VIEWS``). The same code serves the window and screenshots."""
        if self.panel == "onering" and self.ring.valence:
            self.focus_ring()
            return
        w, _ = ps.get_window_size()
        fraction = scene.scene_fraction(w, self.ui.scale)
        if self.panel == "surfaces":
            view = scene.OBLIQUE_VIEW
        else:
            view = scene.FRONT_VIEWS.get(self.mesh.name, scene.DEFAULT_VIEW)
        left = scene.COLORBAR_PX * self.ui.scale / max(w, 1)  # keep clear of the colour bar
        scene.frame_scene_left(FRAMED, self.structure_points, fraction, view, left)
        self._caption_boxes = {}
        for name in FRAMED:
            if ps.has_surface_mesh(name) and ps.get_surface_mesh(name).is_enabled():
                P = self.structure_points(name)
                if P is not None and len(P):
                    self._caption_boxes[name] = (P.min(axis=0), P.max(axis=0))

    def captions(self) -> dict[str, str]:
        """Caption of each structure shown side by side in the current panel."""
        out: dict[str, str] = {}
        curv = self.panels["curvature"]
        if self.panel == "curvature" and curv.side_by_side:
            out[MESH] = FIELD_LABELS[self.curv.field_name][0]
            out[scene.MESH_B] = FIELD_LABELS[curv.second_field][0]
        spec = self.panels["spectral"].state
        if self.panel == "spectral" and spec.basis is not None:
            out[MESH] = f"eigenfunction u_{spec.mode}"
            out[scene.RECON] = f"k = {spec.k} of {spec.basis.k_max} modes"
        sm = self.panels["smoothing"].state
        if self.panel == "smoothing" and sm.smoother is not None:
            noisy = f"noisy alpha = {sm.noise_alpha:g}" if sm.noise_alpha else "no noise"
            out[scene.SMOOTH_INPUT] = f"input, {noisy}"
            out[scene.SMOOTHED] = f"{sm.method}, lambda = {sm.lam:g}, {sm.smoother.iteration} steps"
        return out

    def draw_captions(self) -> None:
        """Write each caption under its structure (the bottom of its bounding box on screen)."""
        texts = self.captions()
        if not texts:
            return
        from .camera import project_to_screen

        params = ps.get_view_camera_parameters()
        w, h = ps.get_window_size()
        for name, text in texts.items():
            box = self._caption_boxes.get(name)
            if box is None:
                continue
            lo, hi = box
            corners = np.array(
                [[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])]
            )
            xy, front = project_to_screen(
                corners, params.get_view_mat(), params.get_fov_vertical_deg(), w, h
            )
            if not front.all():
                continue
            x = float(xy[:, 0].mean()) - 3.5 * len(text) * self.ui.scale
            y = float(min(xy[:, 1].max() + 8, h - 24))
            self.ui.overlay_text((x, y), text)


def run(
    path: str | Path | None = None,
    screenshot: str | Path | None = None,
    field: str = "cotan",
    panel: str = "curvature",
    vertex: int | None = None,
    k: int | None = None,
    backend: str | None = None,
    ui_scale: float = 1.0,
    session: str | Path | None = None,
) -> int:
    """Open the viewer on ``path`` (the bundled default mesh when ``None``).

    With ``screenshot`` a single frame is rendered headless (EGL) into that PNG and the
    function returns. With ``session`` (a saved session file) its mesh, settings and camera
    replace ``path``, ``field``, ``panel``, ``vertex``, ``k`` and ``ui_scale``.
    """
    from .state.session import check_vertex, read_session

    saved = read_session(session) if session is not None else None  # refused before a window
    if saved is not None:
        path, panel = saved.mesh, saved.panel
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
    if saved is not None:
        check_vertex(saved, len(mesh.V), session)
    if vertex is not None and not 0 <= vertex < len(mesh.V):
        raise MeshError(
            f"vertex {vertex} is out of range (the mesh has {len(mesh.V)} vertices)", "--vertex"
        )
    if not 0.5 <= ui_scale <= 3.0:  # also refuses NaN
        raise MeshError(f"must be between 0.5 and 3, got {ui_scale}", "--ui-scale")
    ps.set_program_name(f"meshlap — {mesh.name}")  # the window title (set before init)
    init_polyscope(backend or ("openGL3_egl" if shot else "auto"))
    viewer = Viewer(mesh, CurvatureState(field_name=field), panel=panel, export_dir=cwd)
    ps.set_build_default_gui_panels(False)  # polyscope's own panels: a toggle in Help
    if ui_scale != 1.0:
        viewer.panels["help"].set_scale(viewer, ui_scale)
    viewer.sync_mesh()
    if shot is not None:
        ps.set_window_size(1600, 900)
    if saved is not None:
        from .session import apply

        apply(viewer, saved, session, mesh=mesh)
    elif panel == "onering":
        viewer.select_vertex(vertex if vertex is not None else 0)
    if saved is None and k is None and shot is not None and panel == "spectral":
        k = SCREENSHOT_K  # a spectral screenshot shows a reconstruction, not an empty panel
    if k is not None:
        viewer.panels["spectral"].prepare_screenshot(viewer, k)
    if saved is None and panel == "smoothing":
        viewer.panels["smoothing"].prepare_screenshot(viewer)
    ps.set_user_callback(viewer.callback)
    ps.set_files_dropped_callback(viewer.files_dropped)
    if shot is not None:
        if saved is None:  # a session brings its own camera
            viewer.frame()
        ps.frame_tick()
        ps.frame_tick()  # ImPlot fits its axes on the second frame
        scene.save_screenshot(shot)
        ps.clear_user_callback()
        ps.remove_all_structures()
        return 0
    ps.show()
    return 0
