"""The viewer: a host for the registered panels (:mod:`.registry`) on polyscope's frame loop.

``run`` opens a window (or, with ``screenshot``, renders one frame with the EGL backend and
exits). Paths are resolved before ``polyscope.init()``, which may change the working directory.
polyscope's own settings files are off: the window's layout lives in meshlap's config folder
(:mod:`.config`), and nothing is written in the current directory.

The :class:`Viewer` owns the one :class:`~.state.app.AppState`, the UI adapter and the main
mesh structure; everything else belongs to a panel. Each frame it draws the sections and the
active view, lets every panel bring its uploads up to date (``sync``: cheap when nothing
changed), hands clicks and keys to the panels, and frames the scene when asked. It implements
:class:`~.host.Host`, the narrow interface panels are given; it never names a panel.
"""

from __future__ import annotations

import os
import sys
import traceback
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import polyscope as ps

from meshlap_core.errors import MeshError
from meshlap_core.options import UP_AXES, check_choice

from . import job_rows, opening, scene, window
from .frame_wait import FrameWait
from .jobs import prefer_gil_free_solvers, warm_up
from .pacing import Pacer
from .panels.base import Panel, Pick
from .registry import REGISTRY, VIEW_KEYS, VIEWS
from .scene import MESH
from .state.app import AppState
from .state.preview import MeshPreview
from .state.watch import Watch
from .ui import UI

NO_DISPLAY = (
    "no display could be opened for the viewer window; render headless with "
    "`meshlap view MESH --screenshot out.png`"
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
    # no ./imgui.ini, no ./.polyscope.ini: nothing is read or written in the current directory
    # (the window keeps its layout in meshlap's config folder, see run and meshlap_app.config)
    ps.set_use_prefs_file(False)
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


def make_panels(state: AppState) -> dict[str, Panel]:
    """One instance of every registered panel (its spec's class), given its slice of ``state``."""
    return {s.name: s.panel_class()(s, state.slices.get(s.name)) for s in REGISTRY}


class Viewer:
    """The host of the panels: state, UI adapter, the main mesh, framing and captions.

    Parameters
    ----------
    state : AppState
        The mesh (loaded), settings and every panel's state slice.
    ui : UI, optional
        The imgui adapter (a test passes a scripted one).
    """

    def __init__(self, state: AppState, ui: UI | None = None) -> None:
        self.state = state
        self.ui = ui or UI()
        self.ui.scale = state.ui_scale
        self.panels = make_panels(state)
        self.background = False  # long operations run as jobs (the window; False: inline)
        self.pace = False  # the window sleeps between frames (Pacer); tests tick freely
        self.wait = FrameWait(state.jobs)  # the pause: ended by input and by jobs' news
        self.pacer = Pacer(sleep=self.wait)
        self._activity: tuple[Any, ...] = ()
        self.reframe = True  # frame the visible structures at the end of the next frame
        self.whole = False  # R: the next framing shows the whole subject (no view's focus)
        self.wrap_default = self.ui.wrap_width  # fit_panel narrows it with the pane
        self.keep_camera = False  # an animation of a saved view: never re-frame
        self.window_size: tuple[int, int] = (0, 0)
        self.watch = Watch()
        self._logged: set[tuple[str, str]] = set()
        self._caption_boxes: dict[str, tuple[np.ndarray, np.ndarray]] = {}
        self.preview: MeshPreview | None = None  # a mesh being opened, shown as parsed
        self.opening = ""  # the name of the file a job of the Mesh section opens
        self.preview_fit: tuple[Any, ...] = ()  # the display fit its points were made with
        self.no_shadow = False  # the ground's shadow is off for a big mesh (scene.shadow_for)
        self.picturing = False  # picture() is rendering the view: the callback draws its overlays

    # ------------------------------------------------------------------ Host
    def active(self) -> Panel:
        return self.panels[self.state.panel]

    def request_frame(self) -> None:
        self.reframe = True

    def set_ui_scale(self, scale: float) -> None:
        """UI scale in [0.5, 3] for the state, polyscope and the adapter (``MeshError`` for a
        non-finite value; nothing changes)."""
        value = self.state.set_ui_scale(scale)
        ps.set_ui_scale(value)
        self.ui.scale = value
        self.fit_panel()
        self.reframe = True

    def fit_panel(self) -> None:
        """Keep meshlap's panel within half the window: polyscope draws it
        ``right_gui_pane_width × UI scale`` pixels wide, so at a large scale on a small window
        the pane gets narrower (its text wraps) instead of covering the scene."""
        w = max(int(ps.get_window_size()[0]), 1)
        scale = max(self.state.ui_scale, 1e-3)
        width = min(scene.PANE_WIDTH, int(0.5 * w / scale))
        if width != ps.get_right_gui_pane_width():
            ps.set_right_gui_pane_width(max(width, 1))
        # text wraps inside the pane (the default 430 of 500 pixels; in a narrower pane, at
        # its right edge)
        self.ui.wrap_width = float(min(self.wrap_default, width - 20))

    def mesh_points(self) -> np.ndarray:
        d, mesh = self.state.display, self.state.mesh
        key = (mesh.version, id(mesh.V), d.scale, *d.centre.tolist())
        return self.watch.cached("mesh points", key, lambda: d.points(mesh.V))

    @property
    def sections(self) -> list[Panel]:
        """The panels drawn on every frame (not views)."""
        return [self.panels[e.name] for e in REGISTRY if not e.view]

    # ------------------------------------------------------------------ registration
    def sync_mesh(self) -> None:
        """Register the mesh when it changed (a new file), bring every panel up to date and
        show the active view."""
        mesh = self.state.mesh
        if self.watch.changed("mesh", mesh.version, id(mesh)):
            for view in VIEWS:  # a refused value of the last mesh's context
                self.forget_errors(view)
            self.state.display.fit(mesh.V, self.state.up_for(mesh.name))
            self.no_shadow = scene.shadow_for(len(mesh.F), self.no_shadow)
            if not opening.keep_preview(self, mesh):
                scene.remove_structure(MESH)
                ps.register_surface_mesh(MESH, self.mesh_points(), mesh.F, smooth_shade=True)
            window.set_title(window.window_title(mesh.name, True))  # the window's, if any
            for p in self.panels.values():
                p.on_new_mesh(self)
        for p in self.panels.values():
            p.sync(self)
        self.refresh()

    def show_preview(self, preview: MeshPreview) -> None:
        """Show a mesh being opened as parsed (:func:`.opening.show_preview`)."""
        opening.show_preview(self, preview)

    def restore_mesh(self) -> None:
        """Show the current mesh again after a preview (:func:`.opening.restore_mesh`)."""
        opening.restore_mesh(self)

    def forget_errors(self, section: str) -> None:
        """Drop the refused-value errors of ``section`` (its context changed)."""
        self.state.errors.pop(section, None)
        self.ui.clear_field_errors(section)

    def refresh(self) -> None:
        """Show the structures of the active view and hide the others."""
        active = self.active()
        if ps.has_surface_mesh(MESH):
            ps.get_surface_mesh(MESH).set_enabled(active.shows_mesh)
        for p in self.panels.values():
            p.show(self, active)

    def set_panel(self, name: str) -> None:
        """Switch to the view ``name``, show its structures and frame them (the errors of the
        view left behind go: they belonged to that context)."""
        name = self.state.check_panel(name)
        if name != self.state.panel:
            self.forget_errors(self.state.panel)
        self.state.panel = name
        self.refresh()
        self.reframe = True

    # ------------------------------------------------------------------ input
    def handle_click(self) -> None:
        if self.preview is not None:  # the picture is not the mesh the panels know
            return
        click = self.ui.scene_click()
        if click is not None:
            self.pick_at(*click)

    def pick_at(
        self, screen_xy: tuple[float, float], modifiers: frozenset[str] = frozenset()
    ) -> bool:
        """Pick at window coordinates (``modifiers``: the keys held, see :class:`Pick`); the
        active view first, then the others, may use it."""
        res = ps.pick(screen_coords=screen_xy)
        if not res.is_hit:
            return False
        hit = Pick.of(res, modifiers)
        active = self.active()
        others = [p for p in self.panels.values() if p is not active]
        return any(p.pick(self, hit, active) for p in (active, *others))

    def handle_keys(self) -> None:
        """The shortcuts: a number selects a view; other keys go to the active view, then to
        the sections, then to the host's own (F frames, R re-frames)."""
        ui = self.ui
        for key, name in zip(VIEW_KEYS, VIEWS, strict=False):
            if ui.key(key):
                self.pacer.touch()
                self.set_panel(name)
        panels = [self.active(), *self.sections]
        keys = dict.fromkeys([*(k for p in self.panels.values() for k in p.keys), "f", "r"])
        for key in keys:
            pressed = ui.key(key)
            if pressed:
                self.pacer.touch()  # a key: full rate (the idle rate would lag the answer)
            if pressed and not any(p.on_key(self, key) for p in panels):
                if key in ("f", "r"):  # nobody used it: F frames, R resets to the whole subject
                    self.reframe = True
                    self.whole = key == "r"

    def files_dropped(self, paths: list[str]) -> None:
        """polyscope's drag-and-drop callback: open the first file dropped on the window (a
        ``.json`` file is loaded as a saved session).

        Runs outside the imgui frame, so it draws nothing: a failure is kept for the Mesh
        section (``mesh.error``, or ``errors["mesh"]`` for an internal error), never raised.
        """
        if not paths:
            return
        section = REGISTRY[0].name  # the first section: the mesh's
        try:
            if Path(paths[0]).suffix.lower() == ".json":  # a saved session
                from .session import load

                load(self, paths[0])
                self.state.errors.pop(section, None)
            else:
                self.open(Path(paths[0]))
        except MeshError as exc:  # a refused session: said in the Mesh section, nothing changes
            self.state.errors[section] = str(exc)
        except Exception as exc:  # a callback from C++ must not raise
            self.state.errors[section] = self._internal_error(section, exc)

    # ------------------------------------------------------------------ the frame
    def callback(self) -> None:
        """The per-frame user callback: draw the sections and the active view, let each panel
        sync, react to clicks and keys, frame and caption.

        Every step runs guarded (:meth:`draw_guarded`): no exception of a widget handler
        leaves this function, so none ends the session.
        """
        if self.picturing:  # picture() renders the view: what lies over it, no panel, no input
            self.draw_overlays()
            return
        ui = self.ui
        jobs = self.state.jobs
        if self.pace:
            # idle is idle, play is not; input pending is answered in this frame
            self.pacer.wait(jobs.busy, self.active().animating(), self.input_pending())
        self.draw_guarded("jobs", lambda host: host.poll_jobs())
        # the keys before the panels draw: the frame that reads a key draws its answer
        self.draw_guarded("keys", lambda host: host.handle_keys())
        ui.push_width(200)
        try:
            viewed = False
            for e in REGISTRY:
                if not e.view:
                    self.draw_guarded(e.name, self.panels[e.name].draw)
                elif not viewed:  # where the views start: the combo, then the active one
                    viewed = True
                    self.draw_guarded("view", lambda host: host.draw_view_combo())
                    self.draw_guarded(self.state.panel, self.active().draw)
            # last: a job row that comes and goes here moves no widget
            self.draw_guarded("jobs", lambda host: host.draw_other_jobs())
        finally:
            ui.pop_width()
        for name, p in self.panels.items():
            self.draw_guarded(name, p.sync, show=False)
        self.draw_guarded("picking", lambda host: host.handle_click())
        self.draw_guarded("labels", lambda host: host.limit_overlays())
        self.draw_guarded("labels", self.active().overlay)
        self.draw_guarded("layout", lambda host: host.layout())
        self.draw_guarded("pacing", lambda host: host.note_activity())

    # ------------------------------------------------------------------ jobs, pacing
    def input_pending(self) -> bool:
        """This frame starts with input to answer (the mouse moved or a button, the wheel, a
        modifier or an active widget changed since the last frame ended, or a key is down):
        the pacer does not pause before answering it."""
        return self.ui.activity() != self._activity or self.ui.keys_down()

    def poll_jobs(self) -> None:
        """Apply what the finished jobs computed (here, on the UI thread)."""
        if self.state.jobs.poll():
            self.pacer.touch()  # a result to show: full rate for a moment
        if self.preview is not None and self.state.jobs.running(REGISTRY[0].name) is None:
            self.restore_mesh()  # its job failed or was cancelled: the mesh comes back

    def note_activity(self) -> None:
        """Input this frame (the UI's activity changed, or polyscope was asked to redraw: the
        camera moved, a structure changed) keeps the window at full rate."""
        now = self.ui.activity()
        if now != self._activity or ps.get_redraw_requested():
            self.pacer.touch()
        self._activity = now

    def loading(self) -> tuple[str, MeshPreview | None] | None:
        """The file being opened and its preview once parsed (see :class:`.host.Host`)."""
        if not self.opening or self.state.jobs.running(REGISTRY[0].name) is None:
            return None
        return self.opening, self.preview

    def draw_job(self, *owners: str, reserve: bool = True) -> bool:
        """The row of ``owners``' running job, kept when none runs (:mod:`.job_rows`)."""
        return job_rows.draw_job(self.ui, self.state.jobs, owners, reserve)

    def draw_other_jobs(self) -> None:
        """A row for each job whose panel is not on screen, at the panel's end."""
        shown = {self.state.panel, *(e.name for e in REGISTRY if not e.view)}
        job_rows.draw_others(self.ui, self.state.jobs, shown)

    def layout(self) -> None:
        """Re-frame after a change of what is shown or of the window size; draw captions."""
        size = tuple(ps.get_window_size())
        if self.reframe or size != self.window_size:
            if size != self.window_size:
                self.fit_panel()
            self.window_size = size
            # nothing shown yet (a view's structures still being computed): frame them when
            # they appear (before, polyscope's home view put the camera inside the lab's torus)
            self.reframe = not self.frame(whole=self.whole)
            if not self.reframe:
                self.whole = False
        self.draw_captions()

    def limit_overlays(self) -> None:
        """Text over the 3D view (hover labels, ring labels, captions) ends left of meshlap's
        panel: the narrower of its scene width and the panel's real left edge."""
        w, _ = ps.get_window_size()
        pane = ps.get_right_gui_pane_width() * self.state.ui_scale
        self.ui.overlay_right = float(min(scene.scene_width(w, self.state.ui_scale), w - pane))

    def keep_view(self) -> None:
        """Keep the camera as it is now: no pending re-frame, the window size taken as seen."""
        self.reframe = False
        self.window_size = tuple(ps.get_window_size())

    def flush_frame(self) -> None:
        """Frame now if a re-frame was requested (before a recorded picture)."""
        if self.reframe:
            self.reframe = False
            self.frame()

    def picture(self) -> np.ndarray:
        """The 3D view as it is on screen: what the window shows left of meshlap's panel
        (:func:`.scene.crop_to_scene`), with its colour bars, captions and labels, at the
        window's height; ``(h, w, 3) uint8`` RGB. The *screenshot* button and the recorder's
        frames.

        polyscope draws its colour bars with imgui, so the picture is rendered with its UI
        (``screenshot_to_buffer(include_UI=True)``: a fresh imgui frame in which this
        viewer's callback draws only what lies over the view, :meth:`draw_overlays`, and
        polyscope opens no window for it). polyscope refuses that inside ``ps.show()``; the
        window runs its own frame loop instead (:func:`run_frames`).
        """
        self.flush_frame()
        self.picturing = True
        ps.set_open_imgui_window_for_user_callback(False)
        try:
            buf = ps.screenshot_to_buffer(transparent_bg=False, include_UI=True)
        finally:
            ps.set_open_imgui_window_for_user_callback(True)
            self.picturing = False
        if buf.size == 0:  # polyscope said why (a frame it could not render)
            raise MeshError("the renderer returned no picture", "screenshot")
        crop = scene.crop_to_scene(buf, ps.get_window_size()[0], self.state.ui_scale)
        return np.ascontiguousarray(crop[..., :3])

    def draw_overlays(self) -> None:
        """What lies over the 3D view: the active view's labels (no hover: a picture has no
        pointer) and the captions under the structures."""
        hover, self.ui.pointer = self.ui.pointer, False
        try:
            self.draw_guarded("labels", lambda host: host.limit_overlays())
            self.draw_guarded("labels", self.active().overlay)
            self.draw_guarded("layout", lambda host: host.draw_captions())
        finally:
            self.ui.pointer = hover

    def draw_view_combo(self) -> None:
        changed, panel = self.ui.combo(
            "view", self.state.panel, VIEWS, "which panel: curvature, one-ring, spectral, ..."
        )
        if changed:
            self.set_panel(panel)

    def draw_guarded(self, section: str, draw: Callable[[Any], None], show: bool = True) -> None:
        """Run ``draw(self)``; an exception is shown in red in that section, never raised.

        A ``MeshError``/``ValueError`` (bad widget input) shows its message and the state keeps
        its last good values (the state objects validate before they change). Anything else is
        an internal error: shown with a "details" line and logged once on stderr (with the
        traceback when ``MESHLAP_DEBUG=1``). The message stays until a widget of the section
        changes something without an error. ``show=False``: the message is only kept (drawn
        with the section's widgets).
        """
        ui, errors = self.ui, self.state.errors
        outer = (ui.section, ui.changed)  # a screenshot re-runs the callback from inside one
        ui.begin_section(section)
        try:
            draw(self)
        except ValueError as exc:  # MeshError is a ValueError: bad input, said in its message
            errors[section] = ui.field_failed(str(exc))  # under its field, if one was typed
        except Exception as exc:  # a bug or an API change: keep the session, say what failed
            errors[section] = self._internal_error(section, exc)
        else:
            if ui.changed:
                errors.pop(section, None)
                ui.clear_field_errors(section)
        message = errors.get(section)
        if message and show and not ui.field_error_shown():
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
        """Load ``path``; on failure the error is shown in the Mesh section, the mesh stays.

        In the window (:attr:`background`) the file is read, validated and its curvature
        fields computed as one job of the Mesh section, a preview shown as soon as it is
        parsed (:mod:`.opening`; True: started); otherwise right here (True: loaded).
        """
        return opening.open_mesh(self, path)

    # ------------------------------------------------------------------ framing, captions
    def framed_names(self) -> tuple[str, ...]:
        """The surface meshes framing fits in view: the mesh and every panel's copies."""
        return (MESH, *(n for p in self.panels.values() for n in p.framed))

    def structure_points(self, name: str) -> np.ndarray | None:
        """Display positions of a structure the host or a panel registered (for framing)."""
        if name == MESH:
            return self.mesh_points()
        for p in self.panels.values():
            P = p.points(self, name)
            if P is not None:
                return P
        return None

    def structure_box(self, name: str) -> np.ndarray | None:
        """The corners ``(2,3)`` (min, max) of a structure's display positions, ``(0,3)``
        when it has none, ``None`` when unknown: all that framing and captions read (the
        main mesh's is kept while its points are: two passes over millions of points less at
        each re-frame)."""
        if name == MESH:
            d, mesh = self.state.display, self.state.mesh
            key = (mesh.version, id(mesh.V), d.scale, *d.centre.tolist(), d.up)  # as the points'
            return self.watch.cached("mesh box", key, lambda: scene.box_of(self.mesh_points()))
        P = self.structure_points(name)
        return None if P is None else scene.box_of(P)

    def view_direction(self) -> tuple[float, float, float]:
        """Where the camera looks from: the active view's own direction, else the mesh's
        front (:data:`.scene.FRONT_VIEWS`)."""
        own = getattr(self.active(), "view_direction", None)
        return own or scene.FRONT_VIEWS.get(self.state.mesh.name, scene.DEFAULT_VIEW)

    def frame(self, strip: float | None = None, whole: bool = False) -> bool:
        """Frame what the active view shows in the part of the window left of meshlap's panel
        (a view may frame its own way: the one-ring its selected vertex; ``whole``: not that
        way, the whole subject, as R does). ``strip``: an animation frame (no panel), keeping
        that left fraction of the width clear for the colour bar; nothing happens when the
        animation keeps a saved camera. False when the view shows nothing yet (its structures
        come from a job): the camera is not moved."""
        if strip is not None:
            if not self.keep_camera:
                scene.frame_scene_left(
                    self.framed_names(), self.structure_box, 0.95, self.view_direction(), strip
                )
            return True
        if not whole and self.active().focus(self):
            return True
        w, _ = ps.get_window_size()
        pane = ps.get_right_gui_pane_width() * self.state.ui_scale  # at most half (fit_panel)
        fraction = max(scene.scene_fraction(w, self.state.ui_scale), 0.95 * (1 - pane / w))
        left = scene.COLORBAR_PX * self.state.ui_scale / max(w, 1)  # clear of the colour bar
        names = self.framed_names()
        framed = scene.frame_scene_left(
            names, self.structure_box, fraction, self.view_direction(), left
        )
        self._caption_boxes = {}
        for name in names:
            if ps.has_surface_mesh(name) and ps.get_surface_mesh(name).is_enabled():
                box = self.structure_box(name)
                if box is not None and len(box):
                    self._caption_boxes[name] = (box[0], box[1])
        return framed

    def captions(self) -> dict[str, str]:
        """Caption of each structure the active view shows side by side."""
        return self.active().captions(self)

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


def check_options(options: dict[str, Any], state: AppState) -> None:
    """Each panel's ``meshlap view`` options, checked before any window opens
    (:meth:`.panel_spec.PanelSpec.check_view`: parsed in place, then against the mesh)."""
    for spec in REGISTRY:
        spec.check_view(options, state)


def run(
    path: str | Path | None = None,
    screenshot: str | Path | None = None,
    panel: str | None = None,
    backend: str | None = None,
    ui_scale: float | None = None,
    session: str | Path | None = None,
    up: str | None = None,
    **options: Any,
) -> int:
    """Open the viewer on ``path`` (the bundled default mesh when ``None``).

    With ``screenshot`` a single frame is rendered headless (EGL) into that PNG and the
    function returns. With ``session`` (a saved session file) its mesh, settings, up axis and
    camera replace ``path``, ``panel``, ``up`` and ``options``; ``up``: the mesh's axis shown
    up (:func:`.state.display.up_rotation`; ``None``: the mesh's rule); a ``ui_scale`` given
    wins over the session's (the room's projector, not the saved view; ``None``: the
    session's, else 1). ``options`` are the panels' start options (``field``, ``vertex``,
    ``k``: ``None`` when not given), each checked by its panel's state module first.
    """
    from .state.session import check_session_mesh, read_session

    saved = read_session(session) if session is not None else None  # refused before a window
    if saved is not None:
        path, panel = saved.mesh, saved.panel
    cwd = Path.cwd()  # before polyscope.init(), which may change it: the export folder
    path = Path(path).resolve() if path is not None else None
    shot = Path(screenshot).absolute() if screenshot is not None else None  # (a link: replaced)
    if shot is not None and not shot.parent.is_dir():
        raise MeshError(f"output directory {shot.parent} does not exist", shot)
    if shot is None:  # the fork server of the window's jobs starts while the window opens
        warm_up()
    state = AppState(folder=cwd)
    state.panel = state.check_panel(panel or VIEWS[0], "--panel")
    later = path if opening.opens_later(path, shot, saved, options) else None
    if not opening.load_now(state, None if later is not None else path):
        raise MeshError(state.mesh.error)
    if saved is not None:
        check_session_mesh(saved, state.mesh, session)
    check_options(options, state)
    if ui_scale is not None and not 0.5 <= ui_scale <= 3.0:  # also refuses NaN
        raise MeshError(f"must be between 0.5 and 3, got {ui_scale}", "--ui-scale")
    title = later.name if later is not None else state.mesh.name
    if up is not None:
        state.up_given[title] = check_choice(up, UP_AXES, "up axis", "--up")
    # the title polyscope gives the window when it creates it: the mesh's name only when
    # it can follow the meshes opened later (window.title_follows), else the product's
    ps.set_program_name(window.window_title(title, window.can_follow()))
    init_polyscope(backend or ("openGL3_egl" if shot else "auto"))
    if shot is None:
        window.place_window(tuple(ps.get_window_size()))  # inside the screen, centred
    viewer = Viewer(state)
    ps.set_build_default_gui_panels(False)  # polyscope's own panels: a toggle in Help
    if ui_scale is not None and ui_scale != 1.0:
        viewer.set_ui_scale(ui_scale)
    viewer.sync_mesh()
    if shot is not None:
        ps.set_window_size(1600, 900)
    if saved is not None:
        from .session import apply

        apply(viewer, saved, session, mesh=state.mesh)
        if ui_scale is not None:  # typed with --session: wins over the saved scale
            viewer.set_ui_scale(ui_scale)
    else:
        for name, p in viewer.panels.items():
            p.start(viewer, options, name == state.panel, shot is not None)
    ps.set_user_callback(viewer.callback)
    ps.set_files_dropped_callback(viewer.files_dropped)
    if shot is None:  # the window: long operations as jobs, paced frames (idle is idle)
        viewer.background = viewer.pace = True
        state.jobs.processes = True  # load and fields in child processes: no shared GIL
        prefer_gil_free_solvers()  # an eigenbasis job in a thread must not hold the GIL
        ps.set_max_fps(-1)  # polyscope's limit spins a core; the Pacer sleeps instead
        viewer.wait.listen(viewer.pacer)  # ... in GLFW's wait for events: input ends it
        if later is not None:
            viewer.open(later)
    if shot is not None:
        if saved is None:  # a session brings its own camera
            viewer.frame()
        ps.frame_tick()
        ps.frame_tick()  # ImPlot fits its axes on the second frame
        scene.save_screenshot(shot)
        ps.clear_user_callback()
        ps.remove_all_structures()
        return 0
    show_window(viewer)
    return 0


def show_window(viewer: Viewer) -> None:
    """Run the interactive window with the UI layout of meshlap's config folder
    (:mod:`.config`): read before the first frame, written when the window closes."""
    from . import config

    saved = config.read_layout()
    if saved:
        viewer.ui.load_layout(saved)
    run_frames()
    config.write_layout(viewer.ui.layout())


def run_frames() -> None:
    """The window's frame loop, until the window is closed: ``ps.frame_tick`` rather than
    ``ps.show()``, inside which polyscope refuses a picture with its UI (the colour bars of
    :meth:`Viewer.picture`: "Screenshot with includeUI=true is not supported within show()").
    Each tick is one frame of the same loop ``show()`` runs (input, the user callback, the
    drawing); the pacing sleeps in the callback (:class:`.pacing.Pacer`)."""
    while not ps.window_requests_close():
        ps.frame_tick()
