"""The Smoothing panel: a smoother stepped live beside its input (state in
:mod:`..state.smoothing`)."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
import polyscope as ps
import polyscope.imgui as psim
import polyscope.implot as psimplot

from meshlap_core.options import LAPLACIAN_KINDS as LAPLACIANS

from ..scene import INPUT_COLOR, MESH, RED, SMOOTH_INPUT, SMOOTHED, SMOOTHED_COLOR, side_offset
from ..state.smoothing import METHODS, SmoothingState

if TYPE_CHECKING:
    from ..viewer import Viewer


class SmoothingPanel:
    """Method, Laplacian, λ, noise; step / play / pause / reset; live figures; g(μ)."""

    def __init__(self) -> None:
        self.state = SmoothingState()
        self._registered = -1
        self._shown_iteration = -1
        self._shift = np.zeros(3)

    def on_new_mesh(self, viewer: Viewer) -> None:
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
        self._shift = side_offset(st.V_start)
        if self._registered != st.version:
            # the input (with its noise) stays put; the smoothed copy moves beside it
            inp = ps.register_surface_mesh(SMOOTH_INPUT, st.V_start, st.F, smooth_shade=True)
            inp.set_color(INPUT_COLOR)
            sm = ps.register_surface_mesh(SMOOTHED, st.V + self._shift, st.F, smooth_shade=True)
            sm.set_color(SMOOTHED_COLOR)
            self._registered = st.version
        elif force or st.smoother.iteration != self._shown_iteration:
            ps.get_surface_mesh(SMOOTHED).update_vertex_positions(st.V + self._shift)
        self._shown_iteration = st.smoother.iteration

    def points(self, viewer: Viewer, name: str) -> np.ndarray | None:
        """World positions of a structure this panel registered (for camera framing)."""
        if self.state.smoother is None:
            return None
        if name == SMOOTHED:
            return self.state.V + self._shift
        return self.state.V_start if name == SMOOTH_INPUT else None

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
        if not psim.CollapsingHeader("Smoothing", psim.ImGuiTreeNodeFlags_DefaultOpen):
            return
        st = self.state
        c1, idx = psim.Combo("method", METHODS.index(st.method), list(METHODS))
        c2, jdx = psim.Combo("Laplacian", LAPLACIANS.index(st.laplacian), list(LAPLACIANS))
        c3, lam = psim.InputFloat("lambda", st.lam, 0.0, 0.0, "%.4g")
        c4, alpha = psim.SliderFloat("noise alpha", st.noise_alpha, 0.0, 0.05, "%.4f")
        c5, seed = psim.InputInt("noise seed", st.seed)
        if c1 or c2 or c3 or c4 or c5:
            st.method, st.laplacian = METHODS[idx], LAPLACIANS[jdx]
            st.lam, st.noise_alpha, st.seed = float(lam), float(alpha), max(int(seed), 0)
            self.rebuild(viewer)
        if psim.Button("step"):
            st.step()
        psim.SameLine()
        if psim.Button("pause" if st.playing else "play"):
            st.playing = not st.playing
        psim.SameLine()
        if psim.Button("reset"):
            st.reset()
            self.push(force=True)
        if st.playing:
            st.step()
        self.push()
        if st.error:
            psim.TextColored(RED, st.error)
        fig = st.figures()
        if not fig:
            return
        vol = fig["volume_change_pct"]
        psim.TextUnformatted(
            f"iteration {fig['iteration']}   RMSE vs original "
            f"{fig['rmse']:.4g}   volume change "
            + (f"{vol:+.3f}%" if vol is not None else f"undefined ({fig['volume_note']})")
        )
        limit = fig["stable_limit"]
        psim.TextUnformatted(
            "largest stable explicit lambda: "
            + ("unconditionally stable" if limit is None else f"{limit:.4g}")
        )
        if fig["warning"]:
            psim.TextColored(RED, fig["warning"])
        mu, g = st.amplification()
        if psimplot.BeginPlot("amplification g(mu) per step", (-1, 170)):
            lo = min(-1.2, float(np.min(g)) - 0.1)
            hi = max(1.2, float(np.max(g)) + 0.1)
            psimplot.SetupAxisLimits(psimplot.ImAxis_Y1, lo, hi, psimplot.ImPlotCond_Always)
            psimplot.PlotLine(
                "g", np.asarray(mu, dtype=np.float64), np.asarray(g, dtype=np.float64)
            )
            psimplot.PlotInfLines(
                "|g| = 1", np.array([-1.0, 1.0]), psimplot.ImPlotInfLinesFlags_Horizontal
            )
            psimplot.EndPlot()
