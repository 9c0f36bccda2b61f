"""A notebook's pictures drawn by the viewer (the ``meshlap.pictures`` entry point that
:mod:`meshlap_core.pictures` reads; the core never imports the viewer).

:func:`render_frames` takes the plain scene :func:`meshlap_core.pictures.scene.build_scene`
made (arrays, numbers and strings only: no pickled objects of the core) and returns one RGBA
image per camera turn. The scene is set up by the viewer's own code: a
:class:`~meshlap_app.viewer.Viewer` (a host of the panels, as ``meshlap animate`` builds one)
on the mesh, started on the scene's view with its options (``--panel onering --vertex I``
draws the one-ring and the vertex inspector, framed as the window's *F* key frames them), the
display transform of the window (centre, scale, up axis), its colour maps, its on-screen
colour bars (:func:`~meshlap_app.scene.colorbar_at`), its isolines
(:class:`~meshlap_app.state.isolines.Isolines`), the curvature lab's crosses (black k1, green
k2, :func:`~meshlap_app.state.curvature_lab.crosses_of`) and a second field beside the mesh at
:func:`~meshlap_app.scene.side_offset` (the Curvature view's side-by-side mode).

The drawing runs in one child process kept for the session (:class:`PictureProcess`, through
:class:`meshlap_app.ipc.Child`): polyscope and EGL start once (about 2 s), each later picture
costs its render only, and EGL failing to start (which can abort its process) never takes a
notebook's kernel down: the caller draws with matplotlib and says why.
"""

from __future__ import annotations

import contextlib
import functools
import math
import tempfile
from pathlib import Path
from typing import Any

import numpy as np

from meshlap_core.errors import MeshError

from . import ipc
from .screenshots import captured_output, in_folder

PICTURE_TIMEOUT = 120.0
"""Seconds a picture may take, the start of polyscope and EGL in a new process included."""

SECOND = "mesh (second field)"
"""The structure of the second pane of a side-by-side picture."""

STARTED = "meshlap: picture process started"
"""What the picture process prints once polyscope's EGL backend has started."""


class PictureProcess:
    """The child process that draws pictures: started on the first picture, kept for the
    next ones, started again after it died. Once EGL failed to start in it, every later
    picture fails at once with the same reason (no second wait of seconds for the same
    failure)."""

    def __init__(self) -> None:
        self.child: ipc.Child | None = None
        self.folder = tempfile.TemporaryDirectory(prefix="meshlap-pictures-")
        self.failed = ""

    def render(self, scene: dict[str, Any]) -> list[np.ndarray]:
        """The RGBA frames of ``scene`` (see :func:`render_frames`).

        Raises
        ------
        RuntimeError
            EGL could not render (why, with polyscope's last message line when it printed
            one), or the scene failed to draw.
        """
        if self.failed:
            raise RuntimeError(self.failed)
        try:
            if self.child is None or not self.child.alive:
                self.child = ipc.Child(_serve, self.folder.name, duplex=True, name="picture")
            self.child.send(("render", ipc.pack(scene)))
            return self.child.receive(timeout=PICTURE_TIMEOUT)[1]
        except KeyboardInterrupt:  # a notebook's interrupt: its answer would come next time
            self.end()
            raise
        except ipc.NoChildProcess as exc:
            self.failed = f"no process could start for the picture: {exc}"
            raise RuntimeError(self.failed) from exc
        except MeshError as exc:
            lines = self._log()
            started = STARTED in lines
            said = [x for x in lines if x != STARTED and not x.startswith("[polyscope] EGL:")]
            why = f"{exc} ({said[-1]})" if said else str(exc)
            self.end()  # it died, hangs or failed: the next picture starts a new one
            if not started:  # EGL did not start: it will not start next time either
                self.failed = f"polyscope's EGL backend did not render: {why}"
                raise RuntimeError(self.failed) from exc
            raise RuntimeError(f"the viewer could not draw the picture: {why}") from exc

    def _log(self) -> list[str]:
        """The picture process's output lines (polyscope's messages), stripped."""
        log = Path(self.folder.name) / "output.log"
        text = log.read_text(errors="replace") if log.is_file() else ""
        return [x.strip() for x in text.splitlines() if x.strip()]

    def end(self) -> None:
        """End the child (the next picture starts a new one)."""
        if self.child is not None:
            self.child.end(("bye",), grace=2.0)
            self.child = None


@functools.cache
def picture_process() -> PictureProcess:
    """The one picture process of this Python process (made on first use)."""
    return PictureProcess()


def render_frames(scene: dict[str, Any]) -> list[np.ndarray]:
    """The ``meshlap.pictures`` entry point: ``scene`` drawn by the viewer on polyscope's
    EGL backend in the picture process, one ``(h, w, 4) uint8`` RGBA image per entry of
    ``scene["turns"]``.

    Parameters
    ----------
    scene : dict
        Plain data (:func:`meshlap_core.pictures.scene.build_scene`): ``panes`` (one or two
        dicts with ``V (n,3)``, ``F (m,3)``, ``field (n,)`` or ``None``, ``label``, ``cmap``,
        ``range``, ``isolines``, ``edges``, ``title`` and optionally ``arrows (n,3)`` or
        ``crosses`` (``normal``, ``d1``, ``d2`` ``(n,3)``, ``k1``, ``k2`` ``(n,)``)),
        ``name`` (the mesh's file name: its up axis and front view as in the window), ``up``,
        ``panel`` and ``options`` (the viewer's view and start options, as ``meshlap view
        --panel P --vertex I``), ``camera`` (towards the eye, or ``None``), ``turns``
        (degrees about the up axis), ``size`` (width, height).

    Raises
    ------
    RuntimeError
        EGL could not render (the caller falls back to matplotlib and says why).
    """
    return picture_process().render(scene)


# ---------------------------------------------------------------------- the child process
def _serve(conn: Any, folder: str) -> None:
    """The picture process: polyscope started once on EGL, then one scene per message until
    ``("bye",)`` or the parent's end. polyscope's messages go to ``folder/output.log``."""
    import signal

    signal.signal(signal.SIGINT, signal.SIG_IGN)  # a notebook's interrupt is the parent's
    work = Path(folder)
    with in_folder(work), captured_output(work / "output.log"):
        import polyscope as ps

        from .viewer import init_polyscope

        init_polyscope("openGL3_egl")
        ps.set_build_default_gui_panels(False)
        ps.set_ground_plane_mode("none")
        print(STARTED, flush=True)
        while True:
            try:
                message = conn.recv()
            except (EOFError, OSError):
                break
            if message[0] != "render":
                break
            try:
                frames = draw(ipc.unpack(message[1]))
            except Exception as exc:  # said to the parent; the process serves on
                print(f"meshlap: draw: {ipc.error_message(exc)}", flush=True)
                conn.send(("error", ipc.error_message(exc)))
            else:
                conn.send(("frames", ipc.pack(frames)))
        with contextlib.suppress(Exception):
            ps.shutdown()


def draw(scene: dict[str, Any]) -> list[np.ndarray]:
    """Set ``scene`` up with the viewer's code (:func:`set_up`) and render one frame per
    turn; the scene is removed afterwards (polyscope already started, on any backend)."""
    import polyscope as ps

    try:
        viewer, points = set_up(scene)
        frames = []
        for turn in scene["turns"]:
            _frame(scene, viewer, points, float(turn))
            frames.append(ps.screenshot_to_buffer(transparent_bg=False, include_UI=True))
        return frames
    finally:
        ps.clear_user_callback()
        ps.set_open_imgui_window_for_user_callback(True)  # the viewer's setting
        ps.remove_all_structures()


def set_up(scene: dict[str, Any]) -> tuple[Any, list[np.ndarray]]:
    """Register ``scene`` in polyscope: a viewer on the first pane's mesh (:func:`_viewer`),
    the panes' fields, colour bars, isolines, arrows and crosses, the second pane beside the
    first, the one-ring's numbers as the overlay. Returns the viewer and each pane's display
    positions ``(n,3)`` (what the camera frames)."""
    import polyscope as ps

    from . import scene as sc

    ps.remove_all_structures()
    ps.clear_user_callback()
    ps.set_window_size(*scene["size"])
    ps.set_right_gui_pane_width(1)  # no meshlap panel: the framing uses the whole width
    ps.set_open_imgui_window_for_user_callback(False)  # the overlay's text only
    viewer = _viewer(scene)
    panes = scene["panes"]
    display = viewer.state.display
    main = ps.get_surface_mesh(sc.MESH)
    main.remove_all_quantities()  # the scene's field, not the view's default one
    points = [viewer.mesh_points()]
    meshes = [main]
    if len(panes) > 1:
        second = panes[1]
        P = display.points(second["V"])
        P = P + sc.side_offset(np.vstack([points[0], P]), _toward_eye(scene, viewer))
        meshes.append(ps.register_surface_mesh(SECOND, P, second["F"], smooth_shade=True))
        points.append(P)
    w = scene["size"][0]
    for slot, (pane, sm) in enumerate(zip(panes, meshes, strict=True)):
        # the second pane's colour bar on the right, beside its mesh
        at = sc.colorbar_at(0) if slot == 0 else (w - _bar_width(pane) + 15.0, 15.0)
        _paint(sm, pane, at, display)
    ps.set_user_callback(_overlay_of(viewer))
    return viewer, points


def _viewer(scene: dict[str, Any]) -> Any:
    """A viewer on the first pane's mesh, started on the scene's view and options as
    ``meshlap view --panel P [--vertex I] --screenshot`` starts it."""
    from .state.app import AppState
    from .state.mesh import MeshState
    from .viewer import Viewer

    pane = scene["panes"][0]
    mesh = MeshState(V=pane["V"], F=pane["F"], name=scene["name"], version=1)
    state = AppState(mesh=mesh)
    state.panel = state.check_panel(scene.get("panel") or state.panel, "panel")
    state.up_given[scene["name"]] = scene["up"]
    viewer = Viewer(state)
    viewer.sync_mesh()
    options = dict(scene.get("options") or {})
    for name, p in viewer.panels.items():
        p.start(viewer, options, name == state.panel, True)
    return viewer


def _paint(sm: Any, pane: dict[str, Any], at: tuple[float, float], display: Any) -> None:
    """The pane's field (its colour bar at window pixel ``at``, its isolines), arrows and
    crosses on ``sm``, as the window's views upload them."""
    from .scene import scalar_for_upload
    from .state.isolines import Isolines

    field = pane.get("field")
    if field is not None:
        label = pane["label"]
        values, vminmax, factor = scalar_for_upload(field, tuple(pane["range"]))
        isolines = Isolines()
        if pane.get("isolines"):
            isolines.of(label, on=True).set_count(pane["isolines"])
        sm.add_scalar_quantity(
            label + factor,
            values,
            defined_on="vertices",
            cmap=pane["cmap"],
            vminmax=vminmax,
            enabled=True,
            onscreen_colorbar_enabled=True,
            onscreen_colorbar_location=at,
            **isolines.options(label, values),
        )
    # polyscope keeps a structure's options by its name: set them for every picture
    sm.set_edge_width(1.0 if pane.get("edges") else 0.0)
    sm.set_edge_color((0.15, 0.15, 0.15))
    arrows = pane.get("arrows")
    if arrows is not None:
        from .state.curvature_lab import cross_length

        # the longest arrow 5 crosses long (two mean edges), the others in proportion
        top = float(np.linalg.norm(arrows, axis=1).max()) or 1.0
        scale = 5.0 * cross_length(pane["V"], pane["F"]) / top
        sm.add_vector_quantity(
            "vectors",
            display.vectors(scale * arrows),
            defined_on="vertices",
            vectortype="ambient",
            enabled=True,
            color=(0.1, 0.1, 0.1),
        )
    crosses = pane.get("crosses")
    if crosses is not None:
        _crosses(sm, pane, crosses, display)


def _crosses(sm: Any, pane: dict[str, Any], c: dict[str, Any], display: Any) -> None:
    """The principal directions as the curvature lab draws them: black k1, green k2 crosses,
    arms by ``|k|``, a cross no longer than 0.4 of the mean edge."""
    from types import SimpleNamespace

    from .panels.curvature_lab import K1_COLOR, K2_COLOR
    from .state.curvature_lab import cross_length, crosses_of

    p = SimpleNamespace(**c)
    x = crosses_of(p, length=cross_length(pane["V"], pane["F"]))
    bx, by = display.vectors(x.basis_x), display.vectors(x.basis_y)
    for name, vals, color in (
        ("k1 direction (max)", x.k1, K1_COLOR),
        ("k2 direction (min)", x.k2, K2_COLOR),
    ):
        sm.add_tangent_vector_quantity(
            name, vals, bx, by, n_sym=2, vectortype="ambient", enabled=True, color=color,
            radius=0.0012,
        )  # fmt: skip


def _bar_width(pane: dict[str, Any]) -> float:
    """Pixels a colour bar takes at UI scale 1: its box, or its label when longer (about
    7.5 pixels a character in polyscope's font)."""
    from .scene import COLORBAR_PX

    return max(COLORBAR_PX, 7.5 * len(pane.get("label") or "") + 25.0)


def _toward_eye(scene: dict[str, Any], viewer: Any) -> tuple[float, float, float]:
    cam = scene.get("camera")
    return tuple(cam) if cam is not None else viewer.view_direction()


def _frame(scene: dict[str, Any], viewer: Any, points: list[np.ndarray], turn: float) -> None:
    """The camera: the one-ring's framing when the view focuses on one (a vertex given and
    no camera), else every pane from the scene's direction turned by ``turn`` degrees about
    the up axis, clear of the colour bars on the left. A turntable frames the bounding
    sphere (the same distance at every turn)."""
    import polyscope as ps

    from . import scene as sc

    if scene.get("camera") is None and turn == 0 and len(scene["turns"]) == 1:
        if viewer.active().focus(viewer):
            return
    eye = np.asarray(_toward_eye(scene, viewer), dtype=np.float64)
    a = math.radians(turn)
    c, s = math.cos(a), math.sin(a)
    eye = np.array([c * eye[0] + s * eye[2], eye[1], -s * eye[0] + c * eye[2]])
    P = np.vstack(points)
    if len(scene["turns"]) > 1:
        centre = 0.5 * (P.min(axis=0) + P.max(axis=0))
        r = float(np.linalg.norm(P - centre, axis=1).max())
        P = centre + r * np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)])
    w = max(ps.get_window_size()[0], 1)
    panes = scene["panes"]
    left = min(sc.COLORBAR_PX / w, 0.3) if panes[0].get("field") is not None else 0.02
    right = 0.02
    if len(panes) > 1 and panes[1].get("field") is not None:
        right = min(_bar_width(panes[1]) / w, 0.3)
    sc.frame_points(P, tuple(eye), fraction=1.0 - right, left=left)


def _overlay_of(viewer: Any) -> Any:
    """A user callback drawing only the active view's text over the 3D view (the one-ring's
    order numbers), not meshlap's panel."""

    import polyscope as ps

    def overlay() -> None:
        viewer.ui.overlay_right = float(ps.get_window_size()[0])  # no panel on the right
        viewer.draw_guarded("labels", viewer.active().overlay)

    return overlay
