"""The Spectral panel: eigenmodes and the k-reconstruction beside the mesh (state in
:mod:`..state.spectral`), its play / record, and ``meshlap animate --panel spectral``."""

from __future__ import annotations

import sys
from collections.abc import Iterator
from typing import Any

import numpy as np
import polyscope as ps

from meshlap_core.errors import MeshError
from meshlap_core.options import titled

from .. import scene
from ..host import Host
from ..isolines import draw_isolines
from ..panel_spec import PanelSpec
from ..record import Recorder, draw_record
from ..scene import COLORBAR_AT, MESH, RECON, front_view, side_offset
from ..setting_widgets import setting_widget
from ..state.spectral import ANIMATION, PLAY_KINDS, SCREENSHOT_K, SETTINGS, SpectralState
from .base import ExportItem, Panel, shown_field

ERROR_NAME = titled("reconstruction error |x - x_k|", "length")  # per vertex, on the copy
EIGEN = titled("eigenfunction u_i, M-orthonormal", "1/length")  # on the mesh


class SpectralPanel(Panel):
    """Eigenmode browser and k slider; the reconstruction sits beside the original."""

    framed = (RECON,)
    keys = ("right", "left")
    shortcuts = (("right / left", "spectral: k + 1 / k - 1"),)

    def __init__(self, spec: PanelSpec, state: SpectralState) -> None:
        super().__init__(spec, state)
        self.state: SpectralState = state
        self.recorder = Recorder(f"{spec.name}.gif")

    def animating(self) -> bool:
        """The k sweep or the modes play: the window keeps its full frame rate."""
        return bool(self.state.playing)

    def busy(self) -> str:
        return "the eigenbasis is still being computed" if self.state.busy else ""

    def compute(self, host: Host) -> None:
        """Start the eigenbasis job (in the window; right away otherwise)."""
        mesh = host.state.mesh
        self.state.start(
            mesh.V, mesh.F, background=host.background, jobs=host.state.jobs, owner=self.name
        )

    def on_new_mesh(self, host: Host) -> None:
        self.state.clear()
        self.watch.forget()
        scene.remove_structure(RECON)

    def show(self, host: Host, active: Panel) -> None:
        if ps.has_surface_mesh(RECON):
            ps.get_surface_mesh(RECON).set_enabled(active is self)
            if active is not self:  # a hidden copy's error colour bar would stay on screen
                ps.get_surface_mesh(RECON).remove_quantity(ERROR_NAME)
                self.watch.forget("k")
        if active is self and self.state.basis is not None:
            self.push_mode(host, force=True)
            self.push_k(host, force=True)
        elif self.watch.seen("mode") is not None and ps.has_surface_mesh(MESH):
            # the eigenfunction's colour bar stays on screen while the mesh is hidden
            ps.get_surface_mesh(MESH).remove_quantity(EIGEN)
            self.watch.forget("mode")

    def sync(self, host: Host) -> None:
        """Adopt a basis the worker finished, once this view is shown."""
        if host.active() is self:
            self.adopt(host)

    def _offset(self, host: Host) -> np.ndarray:
        """Where the reconstruction sits beside the mesh: computed from all vertices once per
        mesh and display fit (not on every k move)."""
        d, mesh = host.state.display, host.state.mesh
        key = (id(mesh), mesh.version, d.scale, *d.centre.tolist())
        front = front_view(mesh.name)
        return self.watch.cached("offset", key, lambda: side_offset(host.mesh_points(), front))

    def push_mode(self, host: Host, force: bool = False) -> None:
        st = self.state
        if st.basis is None:
            return
        lines = self.isolines.of("eigenfunction")
        key = (st.mode, id(st.basis), lines.on, lines.count)
        if not self.watch.changed("mode", *key) and not force:
            return
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
            **self.isolines.options("eigenfunction", f),
        )

    def push_k(self, host: Host, force: bool = False) -> None:
        st = self.state
        if st.basis is None:
            return
        lines = self.isolines.of("error")
        if not self.watch.changed("k", st.k, id(st.basis), lines.on, lines.count) and not force:
            return
        X = host.state.display.points(st.reconstruction) + self._offset(host)
        if not ps.has_surface_mesh(RECON):
            # shown or not as told (polyscope would restore the flag of a removed copy)
            scene.register_surface(RECON, X, host.state.mesh.F, host.active() is self)
            host.request_frame()  # a new copy beside the mesh
        else:
            ps.get_surface_mesh(RECON).update_vertex_positions(X)
        hi = float(st.errors.max[st.k]) or 1.0  # precomputed for every k
        ps.get_surface_mesh(RECON).add_scalar_quantity(
            ERROR_NAME,
            st.vertex_error,
            cmap="reds",
            vminmax=(0.0, hi),
            enabled=True,
            onscreen_colorbar_enabled=host.active() is self,  # below the eigenfunction's
            onscreen_colorbar_location=scene.colorbar_at(1, host.state.ui_scale),
            **self.isolines.options("error", st.vertex_error),
        )

    def points(self, host: Host, name: str) -> np.ndarray | None:
        """Display positions of a structure this panel registered (for camera framing): the
        reconstruction is framed as the mesh it approximates, shifted beside it, so the camera
        holds still while k changes (x_1 is a single point: framing it would cut the later
        copies off)."""
        if name == RECON and self.state.basis is not None:
            return host.mesh_points() + self._offset(host)
        return None

    def captions(self, host: Host) -> dict[str, str]:
        st = self.state
        if st.basis is None:
            return {}
        return {MESH: f"eigenfunction u_{st.mode}", RECON: f"k = {st.k} of {st.basis.k_max} modes"}

    def export_items(self, host: Host) -> list[ExportItem]:
        """The mesh with the shown eigenfunction, and the k-reconstruction beside it with its
        per-vertex error (each PLY with its field, and the field as CSV)."""
        st, mesh = self.state, host.state.mesh
        if st.basis is None:
            return []
        f, _ = st.eigenfunction()
        return [
            *shown_field(f"{mesh.stem}_mode{st.mode}", mesh.V, mesh.F, f),
            *shown_field(f"{mesh.stem}_k{st.k}", st.reconstruction, mesh.F, st.vertex_error),
        ]

    def on_key(self, host: Host, key: str) -> bool:
        st = self.state
        if key not in ("right", "left") or st.basis is None:
            return False
        st.set_k(st.k + (1 if key == "right" else -1))
        self.push_k(host)
        return True

    # ------------------------------------------------------------------ sessions, start
    def capture(self, host: Host) -> dict[str, Any]:
        st = self.state
        computed = st.basis is not None
        return {
            "computed": computed,
            "k_request": int(st.basis.k_max if computed else st.k_request),
            "k": int(st.k),
            "mode": int(st.mode),
            "play": st.play_what,
            **self.isolines_section(),
        }

    def configure(self, host: Host, values: dict[str, Any]) -> None:
        st = self.state
        st.k_request = min(values["k_request"], max(len(host.state.mesh.V), 2))
        st.k, st.mode = values["k"], values["mode"]
        st.set_play_what(values["play"])
        self.configure_isolines(values)

    def restore(self, host: Host, values: dict[str, Any], active: bool) -> None:
        """The basis (from the cache when it was computed before), mode and k."""
        self.configure(host, values)  # the new mesh cleared them
        if not values["computed"]:
            return
        st = self.state
        st.start(host.state.mesh.V, host.state.mesh.F, background=False)  # cache=True by default
        if st.basis is None:
            return  # the error is shown in the Spectral panel
        st.set_mode(values["mode"])
        st.set_k(values["k"])
        self.push_mode(host, force=True)
        self.push_k(host, force=True)

    def start(self, host: Host, options: dict[str, Any], shown: bool, screenshot: bool) -> None:
        k = options.get("k")
        if k is None and shown and screenshot:
            k = SCREENSHOT_K  # a spectral screenshot shows a reconstruction, not an empty panel
        if k is not None:
            self.prepare_screenshot(host, k)

    def adopt(self, host: Host) -> None:
        """Show a basis that just finished."""
        if self.state.poll():
            self.push_mode(host, force=True)
            self.push_k(host, force=True)

    def prepare_screenshot(self, host: Host, k: int) -> None:
        """Compute synchronously (headless render) and show the reconstruction from k modes."""
        st = self.state
        st.k_request = max(k, 10)
        st.k = k
        st.start(host.state.mesh.V, host.state.mesh.F, background=False)
        if st.error:
            return
        self.push_mode(host, force=True)
        self.push_k(host, force=True)
        host.refresh()

    # ------------------------------------------------------------------ widgets
    def draw(self, host: Host) -> None:
        ui = host.ui
        if not ui.header(self.title):
            return
        st = self.state
        self.adopt(host)
        n = len(host.state.mesh.V)
        ch, k_request = setting_widget(ui, SETTINGS["k_request"], st.k_request, 2, max(n, 2))
        if ch:
            st.set_k_request(k_request, n)
        computed = SETTINGS["computed"]  # the button that computes the basis
        # the job's row takes the button's place (the same height: nothing below moves)
        if not host.draw_job(self.name, reserve=False) and ui.button(
            computed.label, computed.tooltip
        ):
            self.compute(host)
        if st.error:
            ui.error(st.error)
        if st.basis is None:
            if not st.busy:
                ui.text("-C u = lambda M u (cotangent stiffness, Voronoi mass)")
            return
        ui.text(st.message)
        if st.tick():  # what plays advances before the sliders, so they show this frame's k
            self.push_k(host)  # (or mode), as the captions drawn after the panels do
            self.push_mode(host)
        ch, mode = setting_widget(ui, SETTINGS["mode"], st.mode, 0, st.basis.k_max - 1)
        if ch:
            st.set_mode(mode)
            self.push_mode(host)
        if draw_isolines(ui, self.isolines, "eigenfunction", suffix=" (mode)"):
            self.push_mode(host)
        _, lam = st.eigenfunction()
        ui.text(f"lambda_{st.mode} = {lam:.6g}  (frequency of -Laplacian, >= 0)")
        ch, k = setting_widget(ui, SETTINGS["k"], st.k, 1, st.basis.k_max)
        if ch:
            st.set_k(k)
            self.push_k(host)
        if draw_isolines(ui, self.isolines, "error", suffix=" (error)"):
            self.push_k(host)
        e = st.errors
        ui.text(
            f"k = {st.k}: mean error {e.mean[st.k]:.4g}, max {e.max[st.k]:.4g} "
            f"({100 * e.relative_mean[st.k]:.3g}% of the diagonal)"
        )
        with ui.plot("mean error vs k (log scale)", 170, "k", "mean |x - x_k|", y_log=True) as ok:
            if ok:
                ui.plot_line("mean |x - x_k|", e.k[1:], e.mean[1:])
                ui.plot_vlines("current k", np.array([float(st.k)]))
        self.draw_play(host)
        draw_record(host, self.recorder, (st.k, st.mode), self._record_caption, self._record_fps)

    def draw_play(self, host: Host) -> None:
        """What plays (the k sweep or the eigenmodes), play / pause, and this frame's step."""
        ui, st = host.ui, self.state
        ch, what = setting_widget(ui, SETTINGS["play"], st.play_what)
        if ch:
            st.set_play_what(what)
        ui.same_line()
        if ui.button(
            "pause" if st.playing else "play",
            "play the k sweep or the eigenmodes from the first (or go on after a pause); "
            "while recording, each k or mode shown adds a frame",
            width_of=("play", "pause"),
        ):
            if st.toggle_play():
                self.recorder.restart()  # the file starts with the first k (or mode) played
            self.push_k(host)  # the first k (or mode) of a play shows for a frame of its own
            self.push_mode(host)

    def _record_kind(self) -> str:
        """What changed since the last recorded frame: ``k`` or ``modes`` (the play choice for
        the first frame)."""
        last = self.recorder.last
        if last is None:
            return "k" if self.state.play_what == PLAY_KINDS[0] else "modes"
        return "k" if last[0] != self.state.k else "modes"

    def _record_fps(self) -> float:
        return ANIMATION.fps[self._record_kind()]

    def _record_caption(self) -> str:
        st = self.state
        return st.k_caption() if self._record_kind() == "k" else st.mode_caption()

    # ------------------------------------------------------------------ meshlap animate
    def _basis(self, host: Host, k: int) -> SpectralState:
        """Compute (or read from the cache) ``k`` eigenpairs synchronously."""
        st = self.state
        if st.basis is not None and not st.error and st.basis.k_max >= k:
            return st  # restored from a session: its basis has enough modes
        st.k_request = k
        sys.stderr.write(f"meshlap: animate: {k} eigenpairs (from the cache after the first run)\n")
        st.start(host.state.mesh.V, host.state.mesh.F, background=False)
        if st.error or st.basis is None:
            raise MeshError(st.error or "the eigenbasis could not be computed", self.name)
        return st

    def frames(self, host: Host, options: dict[str, Any]) -> Iterator[str]:
        """The k sweep (``options["k"] = (A, B)``: the reconstruction from the first k modes
        beside the mesh, coloured by the error |x - x_k| on one scale for the sweep) or the
        eigenmodes (``options["modes"]``: u_A..u_B as colour maps on the mesh)."""
        if options.get("modes") is not None:
            yield from self._mode_frames(host, options["modes"])
        else:
            yield from self._k_frames(host, options["k"])

    def _k_frames(self, host: Host, k_range: tuple[int, int]) -> Iterator[str]:
        a, b = k_range
        host.refresh()  # before the basis exists: no eigenfunction on the mesh
        ps.get_surface_mesh(MESH).remove_all_quantities()  # the original plain beside x_k
        st = self._basis(host, max(b, 2))
        st.set_k(a)
        self.push_k(host, force=True)
        host.frame(scene.COLORBAR_STRIP)
        e = st.errors
        # one colour range for the whole sweep (the largest error of any of its k), so the
        # colours of two frames compare
        hi = float(max(e.max[k] for k in range(a, b + 1))) or 1.0
        for k in range(a, b + 1):
            st.set_k(k)
            self.push_k(host)
            ps.get_surface_mesh(RECON).add_scalar_quantity(
                ERROR_NAME,
                st.vertex_error,
                cmap="reds",
                vminmax=(0.0, hi),
                enabled=True,
                onscreen_colorbar_enabled=True,
                onscreen_colorbar_location=COLORBAR_AT,
            )
            yield st.k_caption()  # shared with the viewer's recording

    def _mode_frames(self, host: Host, mode_range: tuple[int, int]) -> Iterator[str]:
        a, b = mode_range
        host.refresh()
        st = self._basis(host, max(b + 1, 2))
        scene.remove_structure(RECON)
        host.frame(scene.COLORBAR_STRIP)
        for m in range(a, b + 1):
            st.set_mode(m)
            self.push_mode(host, force=True)
            yield st.mode_caption()  # shared with the viewer's recording
