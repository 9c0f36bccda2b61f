"""Animations for slides: ``meshlap animate`` (headless, EGL) and the viewer's *record* button.

Frames come from the viewer's own scene code: a :class:`~.viewer.Viewer` is built on the mesh
and its panels register and update the structures exactly as in the window (``push``,
``push_k``, ``push_mode``, the Surfaces panel's ``push``); the camera is framed with
:func:`.scene.frame_scene_left`; polyscope renders each frame (``screenshot_to_buffer`` with its
on-screen colour bar) and :mod:`meshlap_core.frames` burns the caption in and writes the GIF or
MP4 atomically.

Kinds: ``smoothing`` (one frame per iteration, 0 to ``iters``), ``spectral`` with ``k`` (the
reconstruction from the first k modes, k = A..B) or ``modes`` (the eigenmodes A..B one by one),
``surfaces`` with ``theta`` (the normal section at (u, v) turning through 360°, κₙ(θ)).

With a saved session (``meshlap animate --session``) the viewer is first restored from it
(:func:`.session.apply`: mesh, settings, replayed smoothing, cached basis, camera) and the
frame generators start from that viewer: the session's camera is kept (:func:`frame_view` does
nothing for it) and each frame is cropped to the part of the saved window left of meshlap's
panel (:func:`session_window`).
"""

from __future__ import annotations

import copy
import dataclasses
import sys
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import polyscope as ps

from meshlap_core.errors import MeshError
from meshlap_core.frames import FrameWriter, burn_caption, check_animation_output, frame_progress
from meshlap_core.frames import parse_range as parse_range
from meshlap_core.progress import Progress

from . import scene
from .scene import COLORBAR_AT, MESH, RECON
from .state.mesh import MeshState

if TYPE_CHECKING:
    from .viewer import Viewer

KINDS = ("smoothing", "spectral", "surfaces")
NORMAL_SECTION = "normal section"
SECTION_DIRECTION = "normal section direction"
RECORD_HEADER = "record (GIF / MP4)"
DEFAULT_FPS = {"smoothing": 10.0, "k": 15.0, "modes": 1.5, "theta": 15.0}


@dataclass
class AnimationSpec:
    """What ``meshlap animate`` renders (validated by :func:`check_spec` before any rendering).

    ``k`` / ``modes`` are inclusive ranges ``(A, B)``; ``size`` is ``(width, height)`` pixels.
    """

    panel: str
    out: Path
    mesh: Path | None = None
    method: str = "implicit"
    laplacian: str = "uniform"
    lam: float = 1.0
    iters: int = 30
    noise: float = 0.0
    seed: int = 0
    k: tuple[int, int] | None = None
    modes: tuple[int, int] | None = None
    theta: bool = False
    surface: str = "saddle"
    uv: tuple[float, float] | None = None
    frames: int = 72
    fps: float | None = None
    size: tuple[int, int] = (960, 540)
    shadow: bool = False
    lam_steps: list[list[Any]] | None = None  # a session's [[λ, steps], ...]; then ``lam``
    session: Any = None  # a meshlap_app.state.session.Session to restore first
    session_file: Path | None = None  # its file (named in errors; never overwritten)

    @property
    def what(self) -> str:
        """``smoothing``, ``k``, ``modes`` or ``theta``."""
        if self.panel == "spectral":
            return "modes" if self.modes is not None else "k"
        return "theta" if self.panel == "surfaces" else "smoothing"

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
    if spec.panel not in KINDS:
        raise MeshError(
            f"unknown panel {spec.panel!r}; choose one of {', '.join(KINDS)}", "--panel"
        )
    w, h = spec.size
    if not (64 <= w <= 4096 and 64 <= h <= 4096):
        raise MeshError(f"each side must be 64 to 4096 pixels, got {w}x{h}", "--size")
    if spec.panel == "spectral" and (spec.k is None) == (spec.modes is None):
        raise MeshError("give exactly one of --k A:B (reconstruction) or --modes A:B", "--panel")
    if spec.panel == "surfaces" and not spec.theta:
        raise MeshError("the surfaces animation is the normal section: add --theta", "--panel")
    if spec.panel == "surfaces":
        from meshlap_core import surfaces

        if spec.surface not in surfaces.SURFACES:
            names = ", ".join(surfaces.SURFACES)
            raise MeshError(f"unknown surface {spec.surface!r}; choose one of {names}", "--surface")
    if spec.panel == "surfaces" and not 2 <= spec.frames <= 2000:
        raise MeshError(f"must be 2 to 2000, got {spec.frames}", "--frames")
    if mesh is not None and spec.panel == "spectral":
        n = len(mesh.V)
        if spec.k is not None and spec.k[1] > n:
            raise MeshError(f"must end at {n} or less (the mesh has {n} vertices)", "--k")
        if spec.modes is not None and spec.modes[1] > n - 1:
            raise MeshError(f"must end at {n - 1} or less (the mesh has {n} vertices)", "--modes")
    if spec.session is not None:
        window = session_window(spec.session, spec.size, spec.session_file or "--session")
        if window is not None and window[0][0] > 8192:
            raise MeshError(f"too wide for this session's view, got {w}x{h}", "--size")
    if mesh is not None and spec.session is not None:
        from .state.session import check_vertex

        check_vertex(spec.session, len(mesh.V), spec.session_file or "--session")
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
    from .state.curvature import CurvatureState
    from .viewer import Viewer, init_polyscope

    writer = FrameWriter(spec.out, spec.fps or DEFAULT_FPS[spec.what], [spec.mesh or ""])
    init_polyscope("openGL3_egl")
    ps.set_build_default_gui_panels(False)
    ps.set_window_size(*spec.size)
    if not spec.shadow:  # the ground shadow is a second render pass: about 40 % of a frame
        ps.set_ground_plane_mode("none")
    colorbar = spec.what != "smoothing"  # polyscope draws its colour bar with imgui
    viewer = Viewer(mesh, CurvatureState(), panel=spec.panel)
    viewer.sync_mesh()
    keep = restore_session(viewer, spec, mesh) if spec.session is not None else None
    scenes = {"smoothing": smoothing_frames, "k": k_frames, "modes": mode_frames}
    frames = scenes.get(spec.what, theta_frames)(viewer, spec)
    bar = frame_progress(frame_count(spec)) if progress else None
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


def frame_count(spec: AnimationSpec) -> int:
    """How many frames ``spec`` renders."""
    if spec.what == "smoothing":
        return spec.iters + 1
    if spec.what in ("k", "modes"):
        a, b = spec.k if spec.what == "k" else spec.modes  # type: ignore[misc]
        return b - a + 1
    return spec.frames


# ---------------------------------------------------------------- a saved session's view
def _saved_window(session: Any, source: Any) -> tuple[int, int] | None:
    """The window size stored with the session's camera (``None`` without a camera).

    Raises
    ------
    MeshError
        A camera whose ``windowWidth`` / ``windowHeight`` are missing or not 64 to 8192.
    """
    if session.camera is None:
        return None
    size = []
    for key in ("windowWidth", "windowHeight"):
        x = session.camera.get(key)
        if not isinstance(x, int) or isinstance(x, bool) or not 64 <= x <= 8192:
            raise MeshError(f'"camera.{key}" must be an integer 64 to 8192, got {x!r}', source)
        size.append(x)
    return size[0], size[1]


def panel_strip(width: int, ui_scale: float) -> int:
    """Pixels on the right of a window ``width`` wide that meshlap's panel covered at
    ``ui_scale`` (the rule of the viewer's framing and of the record button's crop: at most
    70 % of the window; what is kept has an even width)."""
    keep = int(width * scene.scene_fraction(width, ui_scale, cap=1.0))
    return width - max(keep // 2 * 2, 2)


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
    ``spec.size`` and the frame generators frame the view as without a session. What the
    frames do not show is not restored: the smoothing is not replayed to the saved iteration
    (the frames run it from iteration 0: the last frame is the saved iteration) and the
    eigenbasis is read only for the spectral panel.
    """
    from .session import apply

    session = spec.session
    source = spec.session_file or "--session"
    window = session_window(session, spec.size, source)  # None: no camera
    keep_camera = spec.keeps_camera
    settings = copy.deepcopy(session.settings)
    settings["smoothing"]["iterations"] = 0  # the frames run the smoothing from iteration 0
    if spec.panel != "spectral":
        settings["spectral"]["computed"] = False  # no eigenbasis needed in the frames
    session = dataclasses.replace(session, settings=settings)
    if session.camera is not None:
        camera = dict(session.camera)
        size = window[0] if keep_camera and window is not None else spec.size
        camera["windowWidth"], camera["windowHeight"] = int(size[0]), int(size[1])
        session = dataclasses.replace(session, camera=camera)
    apply(viewer, session, source, resize=True, mesh=mesh)
    if not keep_camera:
        ps.set_window_size(*spec.size)
        viewer.set_panel(spec.panel)
        return None
    return window[1] if window is not None else None


COLORBAR_STRIP = 0.17
"""Left fraction of a frame kept clear for polyscope's colour bar (top-left, ``COLORBAR_AT``)."""


def frame_view(viewer: Viewer, spec: AnimationSpec, strip: float = COLORBAR_STRIP) -> None:
    """Frame the current panel's structures in the window right of a ``strip`` (fraction of
    the width) kept for the colour bar (:func:`.scene.frame_scene_left`); a session's camera
    is kept (``spec.keeps_camera``: nothing happens)."""
    if spec.keeps_camera:
        return
    view = scene.OBLIQUE_VIEW if viewer.panel == "surfaces" else viewer_view(viewer)
    scene.frame_scene_left(viewer_framed(), viewer.structure_points, 0.95, view, max(strip, 0.0))


def viewer_view(viewer: Viewer) -> tuple[float, float, float]:
    return scene.FRONT_VIEWS.get(viewer.mesh.name, scene.DEFAULT_VIEW)


def viewer_framed() -> tuple[str, ...]:
    from .viewer import FRAMED

    return FRAMED


def smoothing_frames(viewer: Viewer, spec: AnimationSpec) -> Iterator[str]:
    """Iterations 0..iters of the Smoothing panel's stepper (input beside the smoothed copy).

    A stepper already built with the same options (a restored session) is reset to iteration
    0 and kept (same noise: same seed); otherwise it is rebuilt with the options of ``spec``.
    Step ``i`` uses the ``i``-th λ of ``spec.lam_steps`` (a session whose λ changed mid-run:
    the last frame is the saved view), then ``spec.lam``.
    """
    panel = viewer.panels["smoothing"]
    st = panel.state
    options = (spec.method, spec.laplacian, spec.lam, spec.noise, spec.seed)
    current = (st.method, st.laplacian, st.lam, st.noise_alpha, st.seed)
    if st.smoother is not None and current == options:
        st.reset()
    else:
        st.method, st.laplacian, st.lam, st.noise_alpha, st.seed = options
        if not st.rebuild(viewer.mesh.V, viewer.mesh.F):
            raise MeshError(st.error)
    panel.push(force=True)
    viewer.show_panel()
    frame_view(viewer, spec, strip=0.0)  # no colour map: no colour bar
    schedule = [float(lam) for lam, n in spec.lam_steps or [] for _ in range(int(n))]
    for it in range(spec.iters + 1):
        if it > 0:
            lam = schedule[it - 1] if it <= len(schedule) else spec.lam
            if lam != st.lam:
                st.set_lam(lam)
            if not st.step():
                raise MeshError(st.error or "the smoothing stopped", "--lam")
        panel.push()
        yield smoothing_caption(st, spec.iters)


def smoothing_caption(st: Any, iters: int | None = None) -> str:
    """``implicit (uniform L), λ = 1   iteration 3/30   RMSE 0.0012`` for a smoothing state
    (read from the stepper's history: never the lazy stability estimate, an eigensolve)."""
    s = st.smoother
    last = s.history[-1] if s is not None and s.history else {}
    rmse = last.get("rmse")
    it = s.iteration if s is not None else 0
    of = f"/{iters}" if iters is not None else ""
    noise = f", noise α = {st.noise_alpha:g}" if st.noise_alpha else ""
    return f"{st.method} ({st.laplacian} L), λ = {st.lam:g}{noise}   iteration {it}{of}" + (
        f"   RMSE {rmse:.4g}" if rmse is not None else ""
    )


def _basis(viewer: Viewer, k: int) -> Any:
    """Compute (or read from the cache) ``k`` eigenpairs synchronously."""
    st = viewer.panels["spectral"].state
    if st.basis is not None and not st.error and st.basis.k_max >= k:
        return st  # restored from a session: its basis has enough modes
    st.k_request = k
    sys.stderr.write(f"meshlap: animate: {k} eigenpairs (from the cache after the first run)\n")
    st.start(viewer.mesh.V, viewer.mesh.F, background=False)
    if st.error or st.basis is None:
        raise MeshError(st.error or "the eigenbasis could not be computed", "spectral")
    return st


def k_frames(viewer: Viewer, spec: AnimationSpec) -> Iterator[str]:
    """The reconstruction from the first k modes beside the mesh, k = A..B, coloured by the
    error |x - x_k| on each k's own scale (the colour bar; the numbers are in the caption)."""
    a, b = spec.k  # type: ignore[misc]
    viewer.show_panel()  # before the basis exists: no eigenfunction on the mesh
    ps.get_surface_mesh(MESH).remove_all_quantities()  # the original plain beside x_k
    panel = viewer.panels["spectral"]
    st = _basis(viewer, max(b, 2))
    st.set_k(a)
    panel.push_k(viewer, force=True)
    frame_view(viewer, spec)
    e = st.errors
    for k in range(a, b + 1):
        st.set_k(k)
        panel.push_k(viewer)
        ps.get_surface_mesh(RECON).add_scalar_quantity(
            "error |x - x_k|",
            st.vertex_error,
            cmap="reds",
            vminmax=(0.0, float(e.max[k]) or 1.0),  # as the viewer: this k's largest error
            enabled=True,
            onscreen_colorbar_enabled=True,
            onscreen_colorbar_location=COLORBAR_AT,
        )
        yield st.k_caption()  # shared with the viewer's recording


def mode_frames(viewer: Viewer, spec: AnimationSpec) -> Iterator[str]:
    """The eigenfunctions u_A..u_B as colour maps on the mesh, one per frame."""
    a, b = spec.modes  # type: ignore[misc]
    viewer.show_panel()
    panel = viewer.panels["spectral"]
    st = _basis(viewer, max(b + 1, 2))
    scene.remove_structure(RECON)
    frame_view(viewer, spec)
    for m in range(a, b + 1):
        st.set_mode(m)
        panel.push_mode(viewer, force=True)
        yield st.mode_caption()  # shared with the viewer's recording


def theta_frames(viewer: Viewer, spec: AnimationSpec) -> Iterator[str]:
    """The normal section at (u, v) turning: its tangent t(θ) and osculating arc, κₙ(θ), drawn
    by the Surfaces panel's :meth:`~.panels.surfaces.SurfacesPanel.push_section` as in the
    window."""
    surf = viewer.surf
    if not surf.set_surface(spec.surface):
        raise MeshError(surf.error, "--surface")
    if spec.uv is not None and not surf.set_uv(*spec.uv):
        raise MeshError(surf.error, "--uv")
    viewer.show_panel()  # the Surfaces panel registers the surface, K and the point
    frame_view(viewer, spec)
    panel = viewer.panels["surfaces"]
    start = surf.section_deg  # 0, or the θ a session saved: one turn from there
    for theta in np.linspace(start, start + 360.0, spec.frames, endpoint=False):
        panel.push_section(viewer, theta)
        yield surf.section_caption()
