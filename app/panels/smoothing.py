"""The Smoothing panel: a smoother stepped live beside its input (state in
:mod:`..state.smoothing`)."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
import polyscope as ps

from meshlap_core.options import LAPLACIAN_KINDS as LAPLACIANS

from ..animate import smoothing_caption
from ..record import Recorder, draw_record
from ..scene import (
    INPUT_COLOR,
    MESH,
    SMOOTH_INPUT,
    SMOOTHED,
    SMOOTHED_COLOR,
    Display,
    side_offset,
)
from ..state.smoothing import METHODS, SmoothingState

if TYPE_CHECKING:
    from ..ui import UI
    from ..viewer import Viewer


class SmoothingPanel:
    """Method, Laplacian, λ, noise; step / play / pause / reset; live figures; g(μ)."""

    def __init__(self) -> None:
        self.state = SmoothingState()
        self._registered = -1
        self._shown_iteration = -1
        self._shift = np.zeros(3)
        self.new_copy = False
        self.display = Display()  # the viewer's, set in on_new_mesh
        self.recorder = Recorder("smoothing.gif")

    def on_new_mesh(self, viewer: Viewer) -> None:
        self.display = viewer.display
        self.state.smoother = None
        self.state.playing = False
        for name in (SMOOTHED, SMOOTH_INPUT):
            if ps.has_surface_mesh(name):
                ps.remove_surface_mesh(name)
        self._registered = -1

    def show(self, viewer: Viewer, panel: str) -> None:
        if panel == "smoothing" and self.state.smoother is None:
            self.rebuild(viewer)
        for name in (SMOOTHED, SMOOTH_INPUT):
            if ps.has_surface_mesh(name):
                ps.get_surface_mesh(name).set_enabled(panel == "smoothing")
        if ps.has_surface_mesh(MESH) and panel == "smoothing":
            ps.get_surface_mesh(MESH).set_enabled(False)

    def rebuild(self, viewer: Viewer) -> None:
        if self.state.rebuild(viewer.mesh.V, viewer.mesh.F):
            self.push(force=True)

    def push(self, force: bool = False) -> None:
        """Upload the current positions (position update; re-register only on a rebuild)."""
        st = self.state
        if st.smoother is None:
            return
        d = self.display
        if self._registered != st.version:
            start = d.points(st.V_start)
            self._shift = side_offset(start)
            # the input (with its noise) stays put; the smoothed copy moves beside it
            inp = ps.register_surface_mesh(SMOOTH_INPUT, start, st.F, smooth_shade=True)
            inp.set_color(INPUT_COLOR)
            sm = ps.register_surface_mesh(
                SMOOTHED, d.points(st.V) + self._shift, st.F, smooth_shade=True
            )
            sm.set_color(SMOOTHED_COLOR)
            self._registered = st.version
            self.new_copy = True  # the viewer re-frames
        elif force or st.smoother.iteration != self._shown_iteration:
            ps.get_surface_mesh(SMOOTHED).update_vertex_positions(d.points(st.V) + self._shift)
        self._shown_iteration = st.smoother.iteration

    def points(self, viewer: Viewer, name: str) -> np.ndarray | None:
        """Display positions of a structure this panel registered (for camera framing)."""
        if self.state.smoother is None:
            return None
        if name == SMOOTHED:
            return self.display.points(self.state.V) + self._shift
        return self.display.points(self.state.V_start) if name == SMOOTH_INPUT else None

    def prepare_screenshot(self, viewer: Viewer, iterations: int = 10) -> None:
        """Add a little noise, smooth a few steps and show the result (headless render)."""
        st = self.state
        st.noise_alpha = 0.004
        self.rebuild(viewer)
        for _ in range(iterations):
            st.step()
        self.push(force=True)
        viewer.show_panel()

    def draw(self, viewer: Viewer) -> None:
        ui = viewer.ui
        if not ui.header("Smoothing"):
            return
        st = self.state
        V, F = viewer.mesh.V, viewer.mesh.F
        ch, method = ui.combo(
            "method",
            st.method,
            METHODS,
            "explicit: x <- x + lam L x;  implicit: (I - lam L) x' = x (backward Euler);  "
            "taubin: lam step, then a negative nu step (no shrinkage)",
        )
        if ch:
            st.configure(V, F, method=method)
            self.push(force=True)
        ch, lap = ui.combo(
            "Laplacian",
            st.laplacian,
            LAPLACIANS,
            "uniform: L = D^-1 A - I (lam dimensionless);  cotan: L = M^-1 C (lam in length^2)",
        )
        if ch:
            st.configure(V, F, laplacian=lap)
            self.push(force=True)
        ch, lam = ui.input_float(
            "lambda",
            st.lam,
            "%.4g",
            "step size lam > 0; type a number and press Enter (keeps the current mesh)",
        )
        if ch:
            st.set_lam(lam)
        ch, alpha = ui.slider_float(
            "noise alpha",
            st.noise_alpha,
            0.0,
            0.05,
            "%.4f",
            "Gaussian noise along the normals, sigma = alpha x mean edge length "
            "(rebuilds the input)",
        )
        if ch:
            st.configure(V, F, noise_alpha=alpha)
            self.push(force=True)
        ch, seed = ui.input_int("noise seed", st.seed, "seed of the noise (an integer >= 0)")
        if ch:
            st.configure(V, F, seed=seed)
            self.push(force=True)
        if ui.button("step", "one iteration"):
            st.step()
        ui.same_line()
        if ui.button("pause" if st.playing else "play", "step every frame (space)"):
            st.playing = not st.playing
        ui.same_line()
        if ui.button("reset", "back to the (noisy) input, iteration 0"):
            st.reset()
            self.push(force=True)
        if st.playing:
            st.step()
        self.push()
        if self.new_copy:
            viewer.reframe, self.new_copy = True, False
        if st.error:
            ui.error(st.error)
        self.draw_figures(ui)
        it = st.smoother.iteration if st.smoother is not None else None
        draw_record(viewer, self.recorder, (st.version, it), lambda: smoothing_caption(st))

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
