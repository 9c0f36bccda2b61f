"""Animations for slides: ``meshlap animate`` renders a panel's animation headless (EGL).

Frames come from the viewer's own scene code: a :class:`~.viewer.Viewer` (a host of the
panels) is built on the mesh, and the animated panel's ``frames`` sets up each frame exactly
as the window shows it; polyscope renders each frame (``screenshot_to_buffer`` with its
on-screen colour bar) and :mod:`meshlap_core.io.animation` burns the caption in and writes the GIF
or MP4 atomically.

Which panels can be animated, their options and frame rates are declared by each panel's spec
(its ``animation``, :class:`~.state.animation.Animation`, and its settings' flags); this module
never names a panel.

With a saved session (``meshlap animate --session``) the viewer is first restored from it
(:func:`.session.apply`: mesh, settings, cached basis, camera) and the frames start from that
viewer: the session's camera is kept (``Viewer.keep_camera``) and each frame is cropped to the
part of the saved window left of meshlap's panel (:func:`session_window`).
"""

from __future__ import annotations

import copy
import dataclasses
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import polyscope as ps

from meshlap_core.errors import MeshError
from meshlap_core.io.animation import (
    FrameWriter,
    burn_caption,
    check_animation_output,
    frame_progress,
)
from meshlap_core.options import check_choice
from meshlap_core.progress import Progress

from . import scene
from .panel_spec import PanelSpec
from .registry import REGISTRY, animated
from .state.animation import Animation
from .state.app import AppState
from .state.camera import MAX_WINDOW, window_size
from .state.mesh import MeshState
from .state.session import check_session_mesh

if TYPE_CHECKING:
    from .viewer import Viewer


@dataclass
class AnimationSpec:
    """What ``meshlap animate`` renders (validated by :func:`check_spec` before any rendering).

    ``options`` are the animated panel's own (its settings' flags and its animation's options,
    by dest: defaults filled and checked); ``size`` is ``(width, height)`` pixels.
    """

    panel: str
    out: Path
    mesh: Path | None = None
    options: dict[str, Any] = field(default_factory=dict)
    fps: float | None = None
    size: tuple[int, int] = (960, 540)
    shadow: bool = False
    session: Any = None  # a meshlap_app.state.session.Session to restore first
    session_file: Path | None = None  # its file (named in errors; never overwritten)

    @property
    def panel_spec(self) -> PanelSpec:
        """The animated panel's spec."""
        return animated()[self.panel]

    @property
    def animation(self) -> Animation:
        """The animated panel's animation (:func:`.registry.animated` lists only panels that
        have one)."""
        return self.panel_spec.animation_declared()

    @property
    def what(self) -> str:
        """What is animated (the panel's kind: ``smoothing``, ``k``, ``modes``, ``theta``...)."""
        return self.animation.kind(self.options)

    @property
    def keeps_camera(self) -> bool:
        """The frames keep the session's camera (no re-framing): the session has one and the
        animated panel is the session's (another panel's camera framed other structures)."""
        s = self.session
        return s is not None and s.camera is not None and s.panel == self.panel


def check_spec(spec: AnimationSpec, mesh: MeshState | None) -> None:
    """Every check that does not need a renderer (the CLI calls it before starting EGL).

    Raises
    ------
    MeshError
        An inconsistent or out-of-range option, naming it.
    """
    check_choice(spec.panel, tuple(animated()), "panel", "--panel")
    w, h = spec.size
    if not (64 <= w <= 4096 and 64 <= h <= 4096):
        raise MeshError(f"each side must be 64 to 4096 pixels, got {w}x{h}", "--size")
    if mesh is not None and spec.session is not None:  # the file first, as `view --session`
        check_session_mesh(spec.session, mesh, spec.session_file or "--session")
    spec.panel_spec.check_options(spec.options)
    if mesh is not None:
        spec.animation.check_mesh(spec.options, mesh)
    if spec.session is not None:
        window = session_window(spec.session, spec.size, spec.session_file or "--session")
        if window is not None and window[0][0] > MAX_WINDOW:
            raise MeshError(f"too wide for this session's view, got {w}x{h}", "--size")
    inputs = [spec.mesh, spec.session_file]
    if spec.session is not None:
        inputs.append(spec.session.mesh)
    check_animation_output(spec.out, [p for p in inputs if p is not None])


def load_mesh_state(spec: AnimationSpec) -> MeshState:
    """Load the mesh of ``spec`` (the bundled default when ``None``) or raise its error."""
    mesh = MeshState()
    if not mesh.load(spec.mesh):
        raise MeshError(mesh.error)
    return mesh


def render(spec: AnimationSpec, mesh: MeshState, progress: bool = True) -> Path:
    """Render the animation of ``spec`` headless (EGL) into ``spec.out``; returns the path.

    The viewer is built on ``mesh`` without a user callback (no meshlap panel in the frames)
    and polyscope's own panels off: the frames show the 3D view and the colour bar only.
    """
    from .viewer import Viewer, init_polyscope

    anim = spec.animation
    writer = FrameWriter(spec.out, spec.fps or anim.fps[spec.what], [spec.mesh or ""])
    init_polyscope("openGL3_egl")
    ps.set_build_default_gui_panels(False)
    ps.set_window_size(*spec.size)
    if not spec.shadow:  # the ground shadow is a second render pass: about 40 % of a frame
        ps.set_ground_plane_mode("none")
    viewer = Viewer(AppState(mesh=mesh, panel=spec.panel))
    viewer.sync_mesh()
    keep = restore_session(viewer, spec, mesh) if spec.session is not None else None
    frames = viewer.panels[spec.panel].frames(viewer, spec.options)
    bar = frame_progress(anim.frame_count(spec.options)) if progress else None
    colorbar = anim.colorbar  # polyscope draws its colour bar with imgui
    try:
        write_frames(frames, writer, colorbar, bar, keep)
        return writer.close()
    except BaseException:
        writer.abort()
        raise
    finally:
        ps.remove_all_structures()


def write_frames(
    frames: Iterator[str],
    writer: FrameWriter,
    colorbar: bool,
    bar: Progress | None,
    keep: int | None = None,
) -> None:
    """Render each frame the generator sets up and hand it to the writer.

    The caption and the GIF quantization run in a worker thread while the main thread computes
    the next frame (a smoothing step, a reconstruction: numpy/scipy release the GIL), one frame
    in flight, so the order is kept. ``keep``: only the left ``keep`` window pixels of each
    frame are kept (a session's view, :func:`session_window`).
    """
    from concurrent.futures import Future, ThreadPoolExecutor

    def add(buf: np.ndarray, caption: str) -> None:
        writer.add(burn_caption(buf, caption))

    pending: Future[None] | None = None
    with ThreadPoolExecutor(max_workers=1) as pool:
        for i, caption in enumerate(frames):
            buf = ps.screenshot_to_buffer(transparent_bg=False, include_UI=colorbar)
            if keep is not None:
                buf = buf[:, : keep * buf.shape[1] // max(ps.get_window_size()[0], 1)]
            if pending is not None:
                pending.result()  # re-raises a failure of the previous frame
            pending = pool.submit(add, buf, caption)
            if bar is not None:
                bar.update(i + 1)
        if pending is not None:
            pending.result()
    if bar is not None:
        bar.close()


# ---------------------------------------------------------------- a saved session's view
def _saved_window(session: Any, source: Any) -> tuple[int, int] | None:
    """The window size stored with the session's camera (``None`` without a camera).

    The camera was checked when the session was read (:func:`.state.camera.check_camera`,
    the same check as ``meshlap view --session``); an animation needs the size too.

    Raises
    ------
    MeshError
        A camera whose ``windowWidth`` / ``windowHeight`` are missing or out of range
        (:data:`.state.camera.MIN_WINDOW` to :data:`~.state.camera.MAX_WINDOW`).
    """
    if session.camera is None:
        return None
    return window_size(session.camera, source)


def panel_strip(width: int, ui_scale: float) -> int:
    """Pixels on the right of a window ``width`` wide that meshlap's panel covered at
    ``ui_scale`` (the rule of the viewer's framing and of the record button's crop,
    :func:`.scene.scene_width`)."""
    return width - scene.scene_width(width, ui_scale)


def session_window(
    session: Any, size: tuple[int, int] | None = None, source: Any = "--session"
) -> tuple[tuple[int, int], int] | None:
    """The window to render and the width kept on its left so that the frames show what the
    session's window showed left of meshlap's panel (``None``: the session has no camera).

    The saved window ``W_s x H_s`` showed the view left of a strip ``P`` (:func:`panel_strip`).
    For an output ``size = (W, H)`` (default ``(W_s - P, H_s)``) the window is
    ``(W + P·H/H_s) x H`` and its left ``W`` pixels are kept: polyscope's field of view is
    vertical, so the vertical extent is the saved one at any size, and the kept part is centred
    where the saved view was (an aspect change widens or narrows it symmetrically). The default
    size gives the saved window and exactly its part left of the panel.
    """
    saved = _saved_window(session, source)
    if saved is None:
        return None
    w_s, h_s = saved
    strip = panel_strip(w_s, session.ui_scale)
    if size is None:
        return (w_s, h_s), w_s - strip
    w, h = size
    return (w + round(strip * h / h_s), h), w


def session_size(session: Any, source: Any = "--session") -> tuple[int, int] | None:
    """The default frame size of a session's animation: its window's part left of the panel
    (``None``: the session has no camera)."""
    window = session_window(session, None, source)
    return None if window is None else (window[1], window[0][1])


def restore_session(viewer: Viewer, spec: AnimationSpec, mesh: MeshState) -> int | None:
    """Apply ``spec.session`` to ``viewer`` (:func:`.session.apply` with the window size of
    :func:`session_window`) and return the width of each frame to keep (``None``: all).

    The session's camera is kept (no re-framing) when the animated panel is the session's; on
    another panel (its camera framed other structures) or without a camera, the window is
    ``spec.size`` and the panel frames the view as without a session. What the frames do not
    show is not restored: each panel's ``frames`` starts its own animation from the settings
    (the smoothing runs from iteration 0, the last frame is the saved iteration) and only the
    animated panel's section of the session is restored in full (an eigenbasis is read only
    when it is the one shown).
    """
    from .session import apply

    session = spec.session
    source = spec.session_file or "--session"
    window = session_window(session, spec.size, source)  # None: no camera
    keep_camera = spec.keeps_camera
    settings = copy.deepcopy(session.settings)
    for p in REGISTRY:  # the frames start their own run: no computation nobody will see
        if p.name not in settings:
            continue
        if p.name == spec.panel:
            settings[p.name].update(spec.animation.session_overrides)
        else:
            settings[p.name].update(p.settings.quiet())
    session = dataclasses.replace(session, settings=settings)
    if session.camera is not None:
        camera = dict(session.camera)
        size = window[0] if keep_camera and window is not None else spec.size
        camera["windowWidth"], camera["windowHeight"] = int(size[0]), int(size[1])
        session = dataclasses.replace(session, camera=camera)
    apply(viewer, session, source, resize=True, mesh=mesh)
    viewer.keep_camera = keep_camera
    if not keep_camera:
        ps.set_window_size(*spec.size)
        viewer.set_panel(spec.panel)
        return None
    return window[1] if window is not None else None
