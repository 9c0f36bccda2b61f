"""The Smoothing panel: a smoother stepped live beside its input (state in
:mod:`..state.smoothing`), its play / record, and ``meshlap animate --panel smoothing``."""

from __future__ import annotations

import threading
import time
from collections.abc import Iterator
from dataclasses import dataclass
from typing import Any

import numpy as np
import polyscope as ps

from meshlap_core.errors import MeshError

from .. import scene, smoother_process
from ..host import Host
from ..jobs import Reporter
from ..panel_spec import PanelSpec
from ..record import Recorder, draw_record
from ..scene import (
    INPUT_COLOR,
    LARGE_MESH_FACES,
    SMOOTH_INPUT,
    SMOOTHED,
    SMOOTHED_COLOR,
    front_view,
    side_offset,
)
from ..setting_widgets import setting_widget
from ..state.smoothing import (
    ANIMATION,
    SETTINGS,
    SmoothingState,
    caption,
    encode_lam_steps,
    replay_steps,
)
from ..text_numbers import plural
from ..ui import UI
from .base import ExportItem, Panel


class SmoothingPanel(Panel):
    """Method, Laplacian, λ, noise; step / play / pause / reset; live figures; g(μ)."""

    shows_mesh = False  # the input and the smoothed copy replace it
    framed = (SMOOTHED, SMOOTH_INPUT)
    keys = ("space", "right", "left", "r")
    shortcuts = (
        ("space", "smoothing: play / pause"),
        ("right", "smoothing: one step"),
        ("left", "smoothing: one step back (the last steps are kept: all on a small mesh)"),
        ("R", "smoothing: back to the input"),
    )

    def __init__(self, spec: PanelSpec, state: SmoothingState) -> None:
        super().__init__(spec, state)
        self.state: SmoothingState = state
        self.recorder = Recorder(f"{spec.name}.gif")
        self._shown_at: float | None = None  # when push last uploaded new steps
        self._ready: Shown | None = None  # display arrays a build job prepared off the UI thread
        self._input_due = False  # the input copy is registered at the next frame (not this one)
        self._pending_input: np.ndarray | None = None  # its display positions meanwhile

    def animating(self) -> bool:
        """A smoothing run plays: the window keeps its full frame rate."""
        return bool(self.state.playing)

    def on_new_mesh(self, host: Host) -> None:
        self.state.drop()  # a stepper in a child process: the process ends
        for name in (SMOOTHED, SMOOTH_INPUT):
            scene.remove_structure(name)
        self.watch.forget()
        self._ready, self._pending_input, self._input_due = None, None, False

    def show(self, host: Host, active: Panel) -> None:
        if active is self and self.state.smoother is None and not self.building(host):
            self.start_build(host, raise_errors=False)  # a job in the window: usable meanwhile
        for name in (SMOOTHED, SMOOTH_INPUT):
            if ps.has_surface_mesh(name):
                ps.get_surface_mesh(name).set_enabled(active is self)
        self._show_input()

    def rebuild(self, host: Host) -> None:
        if self.state.rebuild(host.state.mesh.V, host.state.mesh.F):
            self.push(host, force=True)

    def building(self, host: Host) -> bool:
        """A stepper is being built (a job of this panel runs)."""
        return host.state.jobs.running(self.name) is not None

    def start_build(self, host: Host, raise_errors: bool = True, **changes: Any) -> None:
        """Build a stepper with the options changed by ``changes`` as a job (in the window:
        noise, operators, factorization, stable lambda off the UI thread; the stepper on
        screen keeps going meanwhile) and show it when it is done. A bad option changes
        nothing: said in red (raised right away for a bad seed; a failed build too when
        ``raise_errors`` and the build runs inline)."""
        st = self.state
        options = st.plan(**changes)
        V, F = host.state.mesh.V, host.state.mesh.F

        view = view_of(host)

        def apply(result: tuple[Any, Shown]) -> None:
            smoother, self._ready = result
            st.adopt_built(options, smoother)
            if not host.background:  # (the window: the panel's draw this frame registers it,
                self.push(host, force=True)  # the input copy at the next one)

        def fail(message: str) -> None:
            if raise_errors and not host.background:
                raise MeshError(message)
            st.error, st.playing = message, False

        jobs = host.state.jobs
        if jobs.processes and host.background:
            # the window: the stepper lives in a child process (CHOLMOD holds the GIL while
            # it factorizes, which froze the window for seconds from a thread)
            def work(reporter: Any) -> Any:
                smoother = smoother_process.build(V, F, options, reporter, st.build)
                return smoother, prepare_shown(smoother, view)  # off the UI thread
        else:

            def work(reporter: Any) -> Any:
                smoother = st.build(V, F, options, reporter)
                return smoother, prepare_shown(smoother, view)

        jobs.start(
            self.name,
            f"building the {options[0]} {options[1]} smoother",
            work,
            apply,
            fail,
            background=host.background,
        )

    def _shift_key(self, host: Host) -> tuple[Any, ...]:
        d = host.state.display
        return (self.state.version, d.scale, *d.centre.tolist(), *view_of(host)[3])

    def _shift(self, host: Host) -> np.ndarray:
        st, d = self.state, host.state.display
        front = front_view(host.state.mesh.name)
        make = lambda: side_offset(d.points(st.V_start), front)  # noqa: E731
        return self.watch.cached("shift", self._shift_key(host), make)

    def push(self, host: Host, force: bool = False) -> None:
        """Upload the current positions (position update; re-register only on a rebuild).

        In the window a new stepper's two copies are registered on two frames, the smoothed
        copy first and the input (and the camera framing both) on the next: polyscope's
        registration and first draw of a 1.4M-face copy make the longest frames; two in one
        frame froze the window twice as long. (Framing on a third frame of its own cost one
        more full redraw of both copies, 1.9–2.4 s at load 5.)"""
        st = self.state
        if st.smoother is None:
            return
        d = host.state.display
        if self.watch.changed("registered", st.version, id(st.smoother)):
            self._register(host)
            self.watch.changed("iteration", st.smoother.iteration)
            if not self._input_due:
                host.request_frame()  # a new copy: frame it
            return
        if self._input_due:
            self._register_input(host)
            host.request_frame()  # the two new copies (redrawn once, framed)
            return
        if self.watch.changed("iteration", st.smoother.iteration) or force:
            mesh = ps.get_surface_mesh(SMOOTHED)
            self._shown_at = time.perf_counter()
            if st.playing:
                st.meter.shown(self._shown_at)
            made = getattr(st.smoother, "display", None)
            ready = made(self.view_key(host)) if made is not None else None
            if ready is not None:  # the child made them in the window's coordinates
                upload_positions(mesh, *ready)
                return
            P = d.points(st.V) + self._shift(host)
            N = getattr(st.smoother, "normals", None)
            if N is None:
                mesh.update_vertex_positions(P)
            else:  # the child computed the normals: two buffers, no geometry re-derived here
                upload_positions(mesh, P, N @ d.rotation.T.astype(np.float32))

    def view_key(self, host: Host) -> tuple[float, ...]:
        """The smoothed copy's display transform, flattened for the child process
        (:func:`meshlap_app.smoother_process.display_arrays`): centre, scale, rotation, shift."""
        d = host.state.display
        R = np.asarray(d.rotation, dtype=float).ravel()
        shift = self._shift(host)
        return (*d.centre.tolist(), float(d.scale), *R.tolist(), *np.asarray(shift).tolist())

    def _shown(self, host: Host) -> Shown:
        """The display arrays of the stepper at its adoption: those its build job prepared
        (off the UI thread) when made for this stepper and display, else made here."""
        st = self.state
        ready, self._ready = self._ready, None
        if ready is None or ready.smoother is not st.smoother or ready.view != view_of(host):
            ready = prepare_shown(st.smoother, view_of(host))
        return ready

    def _register(self, host: Host) -> None:
        """Show a new stepper: the input (with its noise) stays put, the smoothed copy moves
        beside it. The two structures of the previous stepper of this mesh (same faces) get
        new positions instead of being registered again (0.5–1 s each at 692k vertices);
        new ones are registered from display arrays made off the UI thread
        (:func:`prepare_shown`), the input one frame later in the window."""
        st = self.state
        assert st.smoother is not None
        shown = self._shown(host)
        self.watch.cached("shift", self._shift_key(host), lambda: shown.shift)
        self.watch.cached("input box", (st.version,), lambda: shown.box_in)
        self._input_due = False
        if all(
            ps.has_surface_mesh(name)
            and ps.get_surface_mesh(name).n_vertices() == len(shown.P)
            and ps.get_surface_mesh(name).n_faces() == len(st.F)
            for name in (SMOOTH_INPUT, SMOOTHED)
        ):
            for name, points, normals in (
                (SMOOTH_INPUT, shown.P_in, shown.N_in),
                (SMOOTHED, shown.P, shown.N),
            ):
                mesh = ps.get_surface_mesh(name)
                if normals is None:
                    mesh.update_vertex_positions(points)
                else:
                    upload_positions(mesh, points, normals)
            return
        for name in (SMOOTH_INPUT, SMOOTHED):
            scene.remove_structure(name)  # (another mesh's copies, if any)
        sm = scene.register_surface(SMOOTHED, shown.P, st.F, host.active() is self)
        sm.set_color(SMOOTHED_COLOR)  # (its normals are derived at its first draw: a
        # buffer that polyscope has not filled yet refuses data)
        self._pending_input = shown.P_in
        if host.background:
            self._input_due = True  # the next frame: one registration per frame
        else:
            self._register_input(host)

    def _register_input(self, host: Host) -> None:
        """Register the input copy (the second of a new stepper's two copies)."""
        self._input_due = False
        P_in, self._pending_input = self._pending_input, None
        if P_in is None or self.state.smoother is None:
            return
        shown = ps.get_surface_mesh(SMOOTHED).is_enabled() and not self._hidden_input()
        inp = scene.register_surface(SMOOTH_INPUT, P_in, self.state.F, shown)
        inp.set_color(INPUT_COLOR)

    def _hidden_input(self) -> bool:
        """The input copy is hidden while *play* runs on a big mesh: the renderer then draws
        one copy instead of two (with software OpenGL, each frame is about halved)."""
        st = self.state
        return st.playing and len(st.F) > LARGE_MESH_FACES

    def _show_input(self) -> None:
        """Hide the input copy while *play* runs on a big mesh, show it on pause."""
        if not ps.has_surface_mesh(SMOOTH_INPUT) or not ps.has_surface_mesh(SMOOTHED):
            return
        want = ps.get_surface_mesh(SMOOTHED).is_enabled() and not self._hidden_input()
        mesh = ps.get_surface_mesh(SMOOTH_INPUT)
        if mesh.is_enabled() != want:
            mesh.set_enabled(want)

    def points(self, host: Host, name: str) -> np.ndarray | None:
        """Display positions of a structure this panel registered, for camera framing: the
        eight corners of its bounding box (framing reads only the box; made from the
        positions' box in mesh coordinates, as the display's rotation permutes axes)."""
        st = self.state
        if st.smoother is None or name not in (SMOOTHED, SMOOTH_INPUT):
            return None
        d = host.state.display
        if name == SMOOTH_INPUT:
            lo, hi = self.watch.cached("input box", (st.version,), lambda: model_box(st.V_start))
            return corners(d.points(np.array([lo, hi])))
        box = getattr(st.smoother, "box", None)
        lo, hi = box if box is not None else model_box(st.V)
        return corners(d.points(np.array([lo, hi]))) + self._shift(host)

    def captions(self, host: Host) -> dict[str, str]:
        sm = self.state
        if sm.smoother is None:
            return {}
        noisy = f"noisy alpha = {sm.noise_alpha:g}" if sm.noise_alpha else "no noise"
        out = {
            SMOOTH_INPUT: f"input, {noisy}",
            SMOOTHED: f"{sm.method}, lambda = {sm.lam:g}, {plural(sm.smoother.iteration, 'step')}",
        }
        if self._hidden_input():
            del out[SMOOTH_INPUT]  # hidden while play runs
        return out

    def export_items(self, host: Host) -> list[ExportItem]:
        """The smoothed mesh as it is now and the (noisy) input beside it (PLY)."""
        st = self.state
        if st.smoother is None:
            return []
        stem = host.state.mesh.stem
        name = f"{stem}_{st.method}_{st.laplacian}_it{st.smoother.iteration}.ply"
        return [(name, np.array(st.V), st.F, None), (f"{stem}_input.ply", st.V_start, st.F, None)]

    def on_key(self, host: Host, key: str) -> bool:
        st = self.state
        if key == "space":
            st.toggle_play()
        elif key == "right":
            st.advance()
        elif key == "left":
            st.step_back()
        elif key == "r":
            st.reset()
            self.push(host, force=True)
        else:
            return False
        return True

    # ------------------------------------------------------------------ sessions, start
    def capture(self, host: Host) -> dict[str, Any]:
        sm = self.state
        return {
            "method": sm.method,
            "laplacian": sm.laplacian,
            "lam": float(sm.lam),
            "noise_alpha": float(sm.noise_alpha),
            "seed": int(sm.seed),
            "iterations": int(sm.smoother.iteration) if sm.smoother is not None else 0,
            "lam_steps": (
                encode_lam_steps(sm.lam_steps, sm.lam) if sm.smoother is not None else None
            ),
        }

    def configure(self, host: Host, values: dict[str, Any]) -> None:
        st = self.state
        st.method, st.laplacian = values["method"], values["laplacian"]
        st.lam, st.noise_alpha, st.seed = values["lam"], values["noise_alpha"], values["seed"]
        st.drop()

    def restore(self, host: Host, values: dict[str, Any], active: bool) -> None:
        """When the run had steps (or this view is shown), rebuild and replay them, each run of
        steps with the λ it used (``lam_steps``), then set the saved ``lam``."""
        self.configure(host, values)
        if not (active or values["iterations"]):
            return
        st = self.state
        runs = replay_steps(values)
        st.lam = runs[0][0] if runs else values["lam"]  # the stepper is built with the first λ
        if not st.rebuild(host.state.mesh.V, host.state.mesh.F, self._builder(host)):
            st.lam = values["lam"]  # (set_lam would clear the error the panel shows)
            return
        for lam, steps in runs:
            st.set_lam(lam)
            if not st.run(steps):
                break  # a diverging run stops where it stopped when it was saved
        st.set_lam(values["lam"])
        self.push(host, force=True)

    def _builder(self, host: Host) -> Any:
        """How a session's replay builds its stepper: in the window, in a child process as
        the panel's own builds (the factor lives there; *play* goes on from it), each run of
        steps one request; elsewhere (``meshlap animate``, tests: offline) in this process."""
        st = self.state
        if not (host.background and host.state.jobs.processes):
            return None

        def build(V: Any, F: Any, options: Any) -> Any:
            return smoother_process.build(V, F, options, Reporter(threading.Event()), st.build)

        return build

    def start(self, host: Host, options: dict[str, Any], shown: bool, screenshot: bool) -> None:
        if shown:
            self.prepare_screenshot(host)

    def prepare_screenshot(self, host: Host, iterations: int = 10) -> None:
        """Add a little noise, smooth a few steps and show the result (headless render)."""
        st = self.state
        st.noise_alpha = 0.004
        self.rebuild(host)
        for _ in range(iterations):
            st.step()
        self.push(host, force=True)
        host.refresh()

    # ------------------------------------------------------------------ widgets
    def draw(self, host: Host) -> None:
        ui = host.ui
        if not ui.header(self.title):
            return
        st = self.state
        host.draw_job(self.name)  # a stepper being built: progress and Cancel
        ch, method = setting_widget(ui, SETTINGS["method"], st.method)
        if ch:
            self.start_build(host, method=method)
        ch, lap = setting_widget(ui, SETTINGS["laplacian"], st.laplacian)
        if ch:
            self.start_build(host, laplacian=lap)
        ch, lam = setting_widget(ui, SETTINGS["lam"], st.lam)
        if ch:
            st.set_lam(lam)
        ch, alpha = setting_widget(ui, SETTINGS["noise_alpha"], st.noise_alpha)
        if ch:
            self.start_build(host, noise_alpha=alpha)
        ch, seed = setting_widget(ui, SETTINGS["seed"], st.seed)
        if ch:
            self.start_build(host, seed=seed)
        kept, oldest = st.kept_steps()
        if ui.button(
            "back",
            f"one step back (left arrow): the positions of the last {kept} steps are kept"
            + (f", back to iteration {oldest}" if oldest > 1 else ""),
        ):
            st.step_back()
        ui.same_line()
        step = SETTINGS["iterations"]  # a step: one more iteration of the run
        if ui.button(step.label, step.tooltip):
            st.advance()
        ui.same_line()
        if ui.button(
            "pause" if st.playing else "play",
            "step every frame (space); beyond the stable lambda, play stops at the first step "
            "that grows",
            width_of=("play", "pause"),  # the same width: reset keeps its place
        ):
            st.toggle_play()
        ui.same_line()
        if ui.button("reset", "back to the (noisy) input, iteration 0"):
            st.reset()
            self.push(host, force=True)
        if self._shown_at is not None:  # the frame that showed new steps has been drawn
            st.show_s, self._shown_at = time.perf_counter() - self._shown_at, None
        if st.asynchronous:
            st.view = self.view_key(host)  # asked for with the steps: the child transforms
        st.poll()  # a step a child process finished (never waits)
        if st.playing:
            st.play_step()
        self._show_input()
        self.push(host)
        if st.error:
            ui.error(st.error)
        self.draw_rates(ui)
        self.draw_figures(ui)
        it = st.smoother.iteration if st.smoother is not None else None
        fps = ANIMATION.fps[ANIMATION.kind({})]
        draw_record(host, self.recorder, (st.version, it), lambda: caption(st), fps)

    def draw_rates(self, ui: UI) -> None:
        """While *play* runs (and after it, the last run's): the steps computed per second and
        the frames that showed a step per second, counted apart (the stepper runs ahead of the
        window on a big mesh); on a big mesh, that the input copy is hidden meanwhile."""
        st = self.state
        if st.meter.started is None:
            return
        now = time.perf_counter()
        if not st.playing:
            st.meter.stop(now)
        steps, frames = st.meter.rates(now)
        what = "playing" if st.playing else "last play"
        ui.text(f"{what}: {steps:.2f} steps/s computed, {frames:.2f} frames/s showing a step")
        if self._hidden_input():
            ui.text("the input copy is hidden while playing (one copy to draw); pause shows it")

    def draw_figures(self, ui: UI) -> None:
        """Iteration, RMSE, volume change, the stable limit and the amplification plot."""
        st = self.state
        fig = st.figures()
        if not fig:
            return
        vol = fig["volume_change_pct"]
        ui.text(
            f"iteration {fig['iteration']}   RMSE vs original "
            f"{fig['rmse']:.4g}   volume change "
            + (f"{vol:+.3f}%" if vol is not None else f"undefined ({fig['volume_note']})")
        )
        limit = fig["stable_limit"]
        ui.text(
            "largest stable explicit lambda: "
            + ("unconditionally stable" if limit is None else f"{limit:.4g}")
        )
        if fig["warning"]:
            ui.error(fig["warning"])
        if fig.get("solver"):
            ui.text(f"solver: {fig['solver']}")
        mu, g = st.amplification()
        with ui.plot(
            "amplification g(mu) per step", 170, "mu (eigenvalue of L)", "g(mu)", fit_y=False
        ) as shown:
            if shown:
                lo = min(-1.2, float(np.min(g)) - 0.1)
                hi = max(1.2, float(np.max(g)) + 0.1)
                ui.plot_y_limits(lo, hi)
                ui.plot_line("g", mu, g)
                ui.plot_hlines("|g| = 1", np.array([-1.0, 1.0]))

    # ------------------------------------------------------------------ meshlap animate
    def frames(self, host: Host, options: dict[str, Any]) -> Iterator[str]:
        """Iterations 0..iters of the stepper (input beside the smoothed copy).

        A stepper already built with the same options (a restored session) is reset to
        iteration 0 and kept (same noise: same seed); otherwise it is rebuilt with
        ``options``. Step ``i`` uses the ``i``-th λ of ``options["lam_steps"]`` (a session whose
        λ changed mid-run: the last frame is the saved view), then ``options["lam"]``.
        """
        st = self.state
        wanted = (
            options["method"],
            options["laplacian"],
            options["lam"],
            options["noise"],
            options["seed"],
        )
        if (
            st.smoother is not None
            and (
                st.method,
                st.laplacian,
                st.lam,
                st.noise_alpha,
                st.seed,
            )
            == wanted
        ):
            st.reset()
        else:
            st.method, st.laplacian, st.lam, st.noise_alpha, st.seed = wanted
            if not st.rebuild(host.state.mesh.V, host.state.mesh.F):
                raise MeshError(st.error)
        self.push(host, force=True)
        host.refresh()
        host.frame(0.0)  # no colour map: no colour bar
        steps = options.get("lam_steps")
        schedule = [float(lam) for lam, n in steps or [] for _ in range(int(n))]
        iters = int(options["iters"])
        for it in range(iters + 1):
            if it > 0:
                lam = schedule[it - 1] if it <= len(schedule) else options["lam"]
                if lam != st.lam:
                    st.set_lam(lam)
                if not st.step():
                    raise MeshError(st.error or "the smoothing stopped", "--lam")
            self.push(host)
            yield caption(st, iters)


def upload_positions(mesh: Any, P: np.ndarray, N: np.ndarray) -> None:
    """New vertex positions ``P (n,3)`` with their smooth-shading normals ``N (n,3)``
    (:func:`meshlap_app.smoother_process.vertex_normals`, polyscope's own formula) written
    into the mesh's two vertex buffers: ``update_vertex_positions`` would re-derive face
    normals, areas and vertex normals on the UI thread (0.2–0.6 s at 692k vertices)."""
    normals = mesh.get_buffer("vertexNormals")
    if not normals.has_data():  # not drawn yet: polyscope fills it at the first draw
        mesh.update_vertex_positions(P)
        return
    single = np.asarray(P).dtype == np.float32  # (polyscope keeps float32: no conversion)
    mesh.get_buffer("vertexPositions").update_data(P if single else np.asarray(P, np.float64))
    normals.update_data(np.asarray(N, dtype=np.float32))
    ps.request_redraw()


@dataclass
class Shown:
    """What a new stepper's two copies show, in display coordinates: made by
    :func:`prepare_shown` in the build job's thread (numpy releases the GIL), so the frame that
    registers them does no per-vertex arithmetic."""

    smoother: Any
    view: tuple[Any, ...]  # :func:`view_of` when made
    P_in: np.ndarray  # (n,3) the input (noisy) copy
    P: np.ndarray  # (n,3) the smoothed copy, shifted beside it
    N: np.ndarray | None  # (n,3) float32 its normals (display frame), when the stepper has them
    N_in: np.ndarray | None  # the input's (the same at iteration 0)
    shift: np.ndarray  # (3,) the smoothed copy's offset
    box_in: np.ndarray  # (2,3) the input's box in mesh coordinates


def view_of(host: Host) -> tuple[Any, ...]:
    """The display transform and the mesh's front view (what the copies' positions depend on):
    ``(centre, scale, rotation, front)`` as tuples (compared, hashed)."""
    d = host.state.display
    rot = tuple(map(tuple, np.asarray(d.rotation, dtype=float).tolist()))
    return (tuple(d.centre.tolist()), float(d.scale), rot, front_view(host.state.mesh.name))


def prepare_shown(smoother: Any, view: tuple[Any, ...]) -> Shown:
    """The display arrays of ``smoother``'s two copies for ``view`` (:func:`view_of`); any
    thread (no polyscope call)."""
    centre, scale, rot, front = view
    c, R = np.asarray(centre), np.asarray(rot)
    V0 = np.asarray(smoother.V0, dtype=np.float64)
    P_in = ((V0 - c) * scale) @ R.T
    shift = side_offset(P_in, front)
    if smoother.iteration == 0:
        P = P_in + shift
    else:
        P = ((np.asarray(smoother.V, dtype=np.float64) - c) * scale) @ R.T + shift
    N = getattr(smoother, "normals", None)
    N = None if N is None else N @ R.T.astype(np.float32)
    N_in = N if smoother.iteration == 0 else None
    return Shown(smoother, view, P_in, P, N, N_in, shift, model_box(V0))


def model_box(V: np.ndarray) -> np.ndarray:
    """``[min, max]`` ``(2,3)`` of the positions ``V (n,3)`` (zeros when empty)."""
    V = np.asarray(V, dtype=np.float64)
    return np.array([V.min(axis=0), V.max(axis=0)]) if len(V) else np.zeros((2, 3))


def corners(box: np.ndarray) -> np.ndarray:
    """The eight corners ``(8,3)`` of the box spanned by the two points ``box (2,3)``."""
    lo, hi = np.minimum(box[0], box[1]), np.maximum(box[0], box[1])
    return np.array(
        [[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])]
    )
