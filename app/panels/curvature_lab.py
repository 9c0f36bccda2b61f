"""The Curvature lab panel: an estimator's principal directions as crosses, its field, its error
against the exact parametric surface (resolution, noise and jitter sliders) or the estimators'
disagreement on a loaded mesh."""

from __future__ import annotations

from typing import Any

import numpy as np
import polyscope as ps

from meshlap_core.options import (
    PRINCIPAL_FIELDS,
)

from .. import scene
from ..host import Host
from ..isolines import draw_isolines
from ..panel_spec import PanelSpec
from ..scene import COLORBAR_AT, picked_vertex, scalar_for_upload
from ..setting_widgets import setting_widget
from ..state.curvature_lab import (
    SETTINGS,
    STUDY_LEVELS,
    CurvatureLabState,
    LabResult,
    grid_line,
)
from ..state.display import Display
from .base import ExportItem, Panel, shown_field

LAB = "curvature lab"
"""The lab's surface mesh (the parametric surface's, or a copy of the loaded mesh)."""
K1_COLOR = (0.05, 0.05, 0.05)  # not in the coolwarm / viridis maps under them
K2_COLOR = (0.0, 0.6, 0.25)
EXACT_COLOR = (0.85, 0.1, 0.85)


class CurvatureLabPanel(Panel):
    """Source (surface / mesh), estimator, quantity, what is coloured, crosses; on a surface
    its resolution, noise and jitter."""

    shows_mesh = False  # its own copy: a parametric surface or the loaded mesh
    framed = (LAB,)

    def __init__(self, spec: PanelSpec, state: CurvatureLabState) -> None:
        super().__init__(spec, state)
        self.state: CurvatureLabState = state
        self._study_for: tuple[Any, ...] | None = None  # the study job's inputs
        self._field: str | None = None  # the scalar quantity on the lab's mesh
        self._faces: np.ndarray | None = None  # the faces registered (the estimate's array)

    def on_new_mesh(self, host: Host) -> None:
        self.watch.forget()

    def export_items(self, host: Host) -> list[ExportItem]:
        """The lab's mesh with its coloured field (PLY, and the field as CSV)."""
        lab, r = self.state, self.state.result
        if r is None:
            return []
        where = f"{lab.surface}_res{lab.res}" if lab.source == "surface" else host.state.mesh.stem
        values = np.asarray(r.values, dtype=np.float64)
        return shown_field(f"{where}_{lab.quantity}_{lab.show}", r.V, r.F, values)

    def capture(self, host: Host) -> dict[str, Any]:
        return {**self.state.settings(), **self.isolines_section()}

    def configure(self, host: Host, values: dict[str, Any]) -> None:
        self.state.configure(values)
        self.configure_isolines(values)

    def show(self, host: Host, active: Panel) -> None:
        if active is self:
            self.sync(host)
        elif ps.has_surface_mesh(LAB):  # hidden, its colour bar would stay on screen
            ps.remove_surface_mesh(LAB)
            self.watch.forget("uploaded", "shape")

    def points(self, host: Host, name: str) -> np.ndarray | None:
        r = self.state.result
        return self._shown(r)[0] if name == LAB and r is not None else None

    def _shown(self, r: LabResult) -> tuple[np.ndarray, float]:
        """The lab mesh's positions as uploaded and the scale applied: centred and scaled by
        a power of two to a diagonal near 1 (:class:`~..state.display.Display`), since
        polyscope stores float32 (a mesh at 1e74 or 1e-55 would upload as inf or 0). Kept
        per result (its ``V``)."""
        cached = getattr(self, "_display_of", None)
        if cached is None or cached[0] is not r.V:
            d = Display()
            d.fit(r.V)
            cached = self._display_of = (r.V, d.points(r.V), d.scale)
        return cached[1], cached[2]

    def pick(self, host: Host, hit: Any, active: Panel) -> bool:
        """A click on the lab's mesh picks the vertex whose shape operator is shown."""
        r = self.state.result
        if active is not self or r is None or hit.structure_name != LAB:
            return False
        idx = picked_vertex(hit, self._shown(r)[0], r.F)
        if idx is None:
            return False
        self.state.pick(idx)
        return True

    def sync(self, host: Host) -> None:
        """Compute (a job in the window) when an input changed, upload when a result is new;
        the convergence study is a second job, started once the error map is applied and
        kept per (surface, estimator, noise, jitter, flips): a resolution move skips it."""
        if host.active() is not self:
            return
        lab, mesh, jobs = self.state, host.state.mesh, host.state.jobs
        wanted = lab.inputs(mesh.version)
        if lab.computed_for != wanted and jobs.running(self.name) is None:
            self._start(host, wanted)
        key = lab.study_key()
        if jobs.running(self.study_owner) is not None and self._study_for != key:
            jobs.cancel(self.study_owner)  # obsolete: the error map gets the cores
        if (
            key is not None
            and key not in lab.studies
            and lab.computed_for == wanted
            and jobs.running(self.name) is None
            and jobs.running(self.study_owner) is None
        ):
            self._start_study(host, key)
        r = lab.result
        lines = repr(self.isolines)
        if r is None:
            return
        # the mesh and its crosses only when the estimate changed; a quantity or show move
        # (the same estimate) re-colours the mesh on screen
        shape = (r.estimate_key or lab.computed_for, lab.crosses)
        if self.watch.changed("shape", shape) or not ps.has_surface_mesh(LAB):
            self.watch.forget("uploaded")
            self._upload_shape(r)
        if self.watch.changed("uploaded", lab.computed_for, lines):
            self._upload_field(r)

    @property
    def study_owner(self) -> str:
        """The convergence study's job owner (one beside the error map's)."""
        return f"{self.name} study"

    def _start(self, host: Host, wanted: tuple[Any, ...]) -> None:
        lab, jobs, mesh = self.state, host.state.jobs, host.state.mesh
        params = lab.params()

        def apply(result: LabResult) -> None:
            lab.adopt(wanted, result)

        def fail(message: str) -> None:
            lab.computed_for = wanted  # not retried until an input changes
            host.state.errors[self.name] = message

        base, estimate = lab.base(), lab.estimate()
        if lab.light():  # a thread (or inline when only the colours change): no child process
            work = lambda reporter: lab.compute(  # noqa: E731
                params, mesh.V, mesh.F, base, reporter, estimate
            )
        else:
            work = jobs.offload(lab.compute, params, mesh.V, mesh.F, base)
        jobs.start(
            self.name,
            f"curvature lab ({lab.estimator}, {lab.show})",
            work,
            apply,
            fail,
            background=bool(host.background) and (estimate is None or lab.show == "disagreement"),
        )

    def _start_study(self, host: Host, key: tuple[Any, ...]) -> None:
        lab, jobs = self.state, host.state.jobs

        def fail(message: str) -> None:
            lab.adopt_study(key, [])  # not retried until an input changes
            host.state.errors[self.name] = f"convergence study: {message}"

        self._study_for = key
        jobs.start(
            self.study_owner,
            f"convergence study ({lab.estimator}, {len(STUDY_LEVELS)} resolutions)",
            jobs.offload(lab.study, lab.params()),
            lambda rows: lab.adopt_study(key, rows),
            fail,
            background=bool(host.background),
        )

    def _upload_shape(self, r: LabResult) -> None:
        """The lab's mesh and its crosses (black k1, green k2; the exact k1 hidden). A new
        estimate on the faces already shown (a noise or estimator move: the lab keeps one
        face array per exact surface and flips) moves the vertices of the registered mesh
        instead of registering it again (0.15 ms against 8 ms at 32k on ``openGL_mock``)."""
        crosses = ("k1 direction (max)", "k2 direction (min)", "exact k1 direction")
        P, scale = self._shown(r)  # (float32-safe positions; the crosses scaled alike)
        if self._faces is r.F and ps.has_surface_mesh(LAB):
            sm = ps.get_surface_mesh(LAB)
            sm.update_vertex_positions(P)
            for name in crosses:
                sm.remove_quantity(name)
        else:
            sm = scene.register_surface(LAB, P, r.F, True)  # (registered when shown)
            self._faces, self._field = r.F, None
        c = r.crosses
        if not self.state.crosses or c is None:
            return
        for name, vals, color, on in zip(
            crosses,
            (c.k1, c.k2, c.exact),
            (K1_COLOR, K2_COLOR, EXACT_COLOR),
            (True, True, False),
            strict=True,
        ):
            if vals is not None:
                sm.add_tangent_vector_quantity(
                    name, vals * scale, c.basis_x, c.basis_y, n_sym=2, vectortype="ambient",
                    enabled=on, color=color, radius=0.0012,
                )  # fmt: skip

    def _upload_field(self, r: LabResult) -> None:
        """The coloured field (the previous one removed: one scalar quantity at a time)."""
        sm = ps.get_surface_mesh(LAB)
        v = np.asarray(r.values, dtype=np.float64)
        top = float(np.percentile(np.abs(v), 98)) if v.size else 1.0
        top = top if top > 0 and np.isfinite(top) else 1.0
        signed = bool((v < 0).any())
        # float32-safe: a range beyond [1e-30, 1e30] (a mesh at 1e-55: curvatures of 1e55)
        # is uploaded scaled by a power of ten that the label names
        values, vr, factor = scalar_for_upload(v, (-top, top) if signed else (0.0, top))
        label = r.label + factor
        if self._field is not None and self._field != label:
            sm.remove_quantity(self._field)
        self._field = label
        sm.add_scalar_quantity(
            label,
            values,
            cmap="coolwarm" if signed else "viridis",
            vminmax=vr,
            enabled=True,
            onscreen_colorbar_enabled=True,
            onscreen_colorbar_location=COLORBAR_AT,
            **self.isolines.options(self.state.show, values),
        )

    def draw(self, host: Host) -> None:
        ui = host.ui
        if not ui.header(self.title):
            return
        host.draw_job(self.name, self.study_owner)  # one row kept for either
        lab = self.state
        changed = False
        for what in ("source", "estimator", "quantity", "show"):
            ch, value = setting_widget(ui, SETTINGS[what], getattr(lab, what))
            if ch:
                lab.set_choice(what, value)
                changed = True
        ch, lab.crosses = setting_widget(ui, SETTINGS["crosses"], lab.crosses)
        changed |= ch
        if lab.source == "surface":
            changed |= self._draw_surface_sliders(host)
        if changed:
            self.sync(host)
            host.refresh()
        if lab.result is not None:
            ui.text(lab.result.label)
            ui.text(lab.result.summary)
            self._draw_shape_operator(host)
            self._draw_convergence(host, lab.convergence())
        if draw_isolines(ui, self.isolines, lab.show):  # last: the plots above stay in view
            self.sync(host)

    def _draw_surface_sliders(self, host: Host) -> bool:
        """The parametric surface, its resolution, noise, jitter and edge flips; True when
        one changed."""
        ui, lab = host.ui, self.state
        changed = False
        ch, value = setting_widget(ui, SETTINGS["surface"], lab.surface)
        if ch:
            lab.set_choice("surface", value)
            changed = True
        for key in ("res", "noise", "jitter", "flips"):
            ch, value = setting_widget(ui, SETTINGS[key], getattr(lab, key))
            if ch:
                lab.set_number(key, value)
                changed = True
            if key == "res":  # what N means: the same mesh as `meshlap surface`'s
                ui.note(grid_line({"surface": lab.surface, "res": lab.res}))
        return changed

    def _draw_shape_operator(self, host: Host) -> None:
        """The picked vertex's 2×2 tensor with its basis and Euler's κn(θ), exact beside it."""
        ui, lab = host.ui, self.state
        ch, v = setting_widget(ui, SETTINGS["vertex"], lab.vertex)
        if ch:
            lab.pick(v)
        so = lab.shape_operator()
        if so is None:
            return
        (a, b), (_, c) = so["S"]
        t1, t2 = so["t1"], so["t2"]
        ui.text(f"S = [[{a:.4g}, {b:.4g}], [{b:.4g}, {c:.4g}]]")
        ui.text(f"k1 = {so['k1']:.4g}, k2 = {so['k2']:.4g}")
        fmt = lambda t: f"({t[0]:.3f}, {t[1]:.3f}, {t[2]:.3f})"  # noqa: E731
        ui.text(f"in the basis t1 = {fmt(t1)}, t2 = {fmt(t2)}")
        with ui.plot("Euler: kn(theta) from d1", 150, "theta (deg)", "kn") as shown:
            if shown:
                ui.plot_line("estimate", so["theta_deg"], so["kn"])
                if so["exact_kn"] is not None:
                    ui.plot_line("exact", so["theta_deg"], so["exact_kn"])

    @staticmethod
    def _draw_convergence(host: Host, convergence: list[dict[str, Any]]) -> None:
        """log10(relative RMS error) against log10(h) for H and K, the order in the legend."""
        rows = [row for row in convergence if row["H_rel"] > 0 and row["K_rel"] > 0]
        if len(rows) < 2:
            return
        x = np.log10([row["h"] for row in rows])
        with host.ui.plot("error vs h (log-log)", 150, "log10 h", "log10 rel. error") as shown:
            if shown:
                for q in PRINCIPAL_FIELDS[2:4]:  # H and K
                    order = rows[-1][f"{q}_order"]
                    tag = f"{q}, order {order:.2f}" if order is not None else q
                    host.ui.plot_line(tag, x, np.log10([row[f"{q}_rel"] for row in rows]))
