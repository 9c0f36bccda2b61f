"""The Spectral panel: eigenmodes and the k-reconstruction beside the mesh (state in
:mod:`..state.spectral`)."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
import polyscope as ps

from ..record import Recorder, draw_record
from ..scene import COLORBAR_AT, EIGEN, MESH, RECON, side_offset
from ..state.spectral import PLAY_KINDS, SpectralState

if TYPE_CHECKING:
    from ..viewer import Viewer


class SpectralPanel:
    """Eigenmode browser and k slider; the reconstruction sits beside the original."""

    def __init__(self) -> None:
        self.state = SpectralState()
        self._shown_k = -1
        self._shown_mode = -1
        self.recorder = Recorder("spectral.gif")
        self._offset_key: tuple[object, ...] = ()
        self._offset_value = np.zeros(3)

    def on_new_mesh(self, viewer: Viewer) -> None:
        self.state.clear()
        self._shown_k = self._shown_mode = -1
        self._offset_key = ()
        if ps.has_surface_mesh(RECON):
            ps.remove_surface_mesh(RECON)

    def show(self, viewer: Viewer, panel: str) -> None:
        if ps.has_surface_mesh(RECON):
            ps.get_surface_mesh(RECON).set_enabled(panel == "spectral")
        if panel == "spectral" and self.state.basis is not None:
            self.push_mode(viewer, force=True)
        elif self._shown_mode >= 0 and ps.has_surface_mesh(MESH):
            # the eigenfunction's colour bar stays on screen while the mesh is hidden
            ps.get_surface_mesh(MESH).remove_quantity(EIGEN)
            self._shown_mode = -1

    def _offset(self, viewer: Viewer) -> np.ndarray:
        """Where the reconstruction sits beside the mesh: computed from all vertices once per
        mesh and display fit (not on every k move)."""
        d = viewer.display
        key = (id(viewer.mesh), viewer.mesh.version, d.scale, *d.centre.tolist())
        if key != self._offset_key:
            self._offset_value = side_offset(d.points(viewer.mesh.V))
            self._offset_key = key
        return self._offset_value

    def push_mode(self, viewer: Viewer, force: bool = False) -> None:
        st = self.state
        if st.basis is None or (st.mode == self._shown_mode and not force):
            return
        self._shown_mode = st.mode
        f, _ = st.eigenfunction()
        r = float(np.abs(f).max()) or 1.0
        ps.get_surface_mesh(MESH).add_scalar_quantity(
            EIGEN,
            f,
            cmap="coolwarm",
            vminmax=(-r, r),
            enabled=True,
            onscreen_colorbar_enabled=True,
            onscreen_colorbar_location=COLORBAR_AT,
        )

    def push_k(self, viewer: Viewer, force: bool = False) -> None:
        st = self.state
        if st.basis is None or (st.k == self._shown_k and not force):
            return
        self._shown_k = st.k
        X = viewer.display.points(st.reconstruction) + self._offset(viewer)
        if not ps.has_surface_mesh(RECON):
            ps.register_surface_mesh(RECON, X, viewer.mesh.F, smooth_shade=True)
            viewer.reframe = True  # a new copy beside the mesh
        else:
            ps.get_surface_mesh(RECON).update_vertex_positions(X)
        hi = float(st.errors.max[st.k]) or 1.0  # precomputed for every k
        ps.get_surface_mesh(RECON).add_scalar_quantity(
            "error |x - x_k|", st.vertex_error, cmap="reds", vminmax=(0.0, hi), enabled=True
        )

    def points(self, viewer: Viewer, name: str) -> np.ndarray | None:
        """Display positions of a structure this panel registered (for camera framing): the
        reconstruction is framed as the mesh it approximates, shifted beside it, so the camera
        holds still while k changes (x_1 is a single point: framing it would cut the later
        copies off)."""
        if name == RECON and self.state.basis is not None:
            return viewer.display.points(viewer.mesh.V) + self._offset(viewer)
        return None

    def adopt(self, viewer: Viewer) -> None:
        """Show a basis that just finished."""
        if self.state.poll():
            self.push_mode(viewer, force=True)
            self.push_k(viewer, force=True)

    def prepare_screenshot(self, viewer: Viewer, k: int) -> None:
        """Compute synchronously (headless render) and show the reconstruction from k modes."""
        st = self.state
        st.k_request = max(k, 10)
        st.k = k
        st.start(viewer.mesh.V, viewer.mesh.F, background=False)
        if st.error:
            return
        self.push_mode(viewer, force=True)
        self.push_k(viewer, force=True)
        viewer.show_panel()

    def draw(self, viewer: Viewer) -> None:
        ui = viewer.ui
        if not ui.header("Spectral"):
            return
        st = self.state
        self.adopt(viewer)
        n = len(viewer.mesh.V)
        ch, k_request = ui.input_int(
            "modes to compute",
            st.k_request,
            f"number of eigenpairs of -C u = lambda M u to compute (2 to {n}); Enter applies",
        )
        if ch:
            st.set_k_request(k_request, n)
        if st.busy:
            ui.progress(st.progress, st.message or "working")
        elif ui.button("compute eigenbasis", "solve for the modes in the background"):
            st.start(viewer.mesh.V, viewer.mesh.F)
        if st.error:
            ui.error(st.error)
        if st.basis is None:
            if not st.busy:
                ui.text("-C u = lambda M u (cotangent stiffness, Voronoi mass)")
            return
        ui.text(st.message)
        ch, mode = ui.slider_int(
            "eigenmode i",
            st.mode,
            0,
            st.basis.k_max - 1,
            "eigenfunction u_i shown as a colour map (i = 0 is constant)",
        )
        if ch:
            st.set_mode(mode)
            self.push_mode(viewer)
        _, lam = st.eigenfunction()
        ui.text(f"lambda_{st.mode} = {lam:.6g}  (frequency of -Laplacian, >= 0)")
        ch, k = ui.slider_int(
            "k (reconstruct)",
            st.k,
            1,
            st.basis.k_max,
            "x_k = sum_{i<k} u_i (u_i^T M x): the shape from its first k modes",
        )
        if ch:
            st.set_k(k)
            self.push_k(viewer)
        e = st.errors
        ui.text(
            f"k = {st.k}: mean error {e.mean[st.k]:.4g}, max {e.max[st.k]:.4g} "
            f"({100 * e.relative_mean[st.k]:.3g}% of the diagonal)"
        )
        with ui.plot("mean error vs k (log scale)", 170, "k", "mean |x - x_k|", y_log=True) as ok:
            if ok:
                ui.plot_line("mean |x - x_k|", e.k[1:], e.mean[1:])
                ui.plot_vlines("current k", np.array([float(st.k)]))
        self.draw_play(viewer)
        draw_record(viewer, self.recorder, (st.k, st.mode), self._record_caption, self._record_kind)

    def draw_play(self, viewer: Viewer) -> None:
        """What plays (the k sweep or the eigenmodes), play / pause, and this frame's step."""
        ui, st = viewer.ui, self.state
        ch, what = ui.combo(
            "play what",
            st.play_what,
            PLAY_KINDS,
            "k sweep: k = 1, 2, ... one per frame (as meshlap animate --k); modes: the "
            "eigenmodes 1, 2, ... at 1.5 per second (as --modes); playing stops at the end",
        )
        if ch:
            st.set_play_what(what)
        ui.same_line()
        if ui.button(
            "pause" if st.playing else "play",
            "play the k sweep or the eigenmodes from the first (or go on after a pause); "
            "while recording, each k or mode shown adds a frame",
        ):
            if st.toggle_play():
                self.recorder.restart()  # the file starts with the first k (or mode) played
        elif not st.tick():  # the first k (or mode) of a play shows for a frame of its own
            return
        self.push_k(viewer)
        self.push_mode(viewer)

    def _record_kind(self) -> str:
        """What changed since the last recorded frame: ``k`` or ``modes`` (the play choice for
        the first frame)."""
        last = self.recorder.last
        if last is None:
            return "k" if self.state.play_what == "k sweep" else "modes"
        return "k" if last[0] != self.state.k else "modes"

    def _record_caption(self) -> str:
        st = self.state
        return st.k_caption() if self._record_kind() == "k" else st.mode_caption()
