"""The Curvature lab panel: an estimator's principal directions as crosses, its field, its error
against the exact parametric surface (resolution, noise and jitter sliders) or the estimators'
disagreement on a loaded mesh."""

from __future__ import annotations

from typing import Any

import numpy as np
import polyscope as ps

from meshlap_core.options import (
    CURVATURE_ESTIMATOR_LABELS,
    CURVATURE_ESTIMATORS,
    LAB_SHOWS,
    LAB_SOURCES,
    PRINCIPAL_FIELDS,
)
from meshlap_core.surfaces import SURFACES

from ..isolines import draw_isolines
from ..scene import COLORBAR_AT, picked_vertex
from ..state.curvature_lab import (
    MAX_JITTER,
    MAX_NOISE,
    MAX_RES,
    CurvatureLabState,
    LabResult,
    cross_field,
)
from .base import Host, Panel

LAB = "curvature lab"
"""The lab's surface mesh (the parametric surface's, or a copy of the loaded mesh)."""
K1_COLOR = (0.85, 0.15, 0.1)
K2_COLOR = (0.1, 0.3, 0.85)
EXACT_COLOR = (0.1, 0.1, 0.1)


class CurvatureLabPanel(Panel):
    """Source (surface / mesh), estimator, quantity, what is coloured, crosses; on a surface
    its resolution, noise and jitter."""

    title = "Curvature lab"
    shows_mesh = False  # its own copy: a parametric surface or the loaded mesh
    framed = (LAB,)

    def __init__(self, name: str, state: CurvatureLabState) -> None:
        super().__init__(name, state)
        self.state: CurvatureLabState = state

    def on_new_mesh(self, host: Host) -> None:
        self.watch.forget()

    def show(self, host: Host, active: Panel) -> None:
        if active is self:
            self.sync(host)
        elif ps.has_surface_mesh(LAB):  # hidden, its colour bar would stay on screen
            ps.remove_surface_mesh(LAB)
            self.watch.forget("uploaded")

    def points(self, host: Host, name: str) -> np.ndarray | None:
        r = self.state.result
        return r.V if name == LAB and r is not None else None

    def pick(self, host: Host, hit: Any, active: Panel) -> bool:
        """A click on the lab's mesh picks the vertex whose shape operator is shown."""
        r = self.state.result
        if active is not self or r is None or hit.structure_name != LAB:
            return False
        idx = picked_vertex(hit, r.V, r.F)
        if idx is None:
            return False
        self.state.pick(idx)
        return True

    def sync(self, host: Host) -> None:
        """Compute (a job in the window) when an input changed, upload when a result is new."""
        if host.active() is not self:
            return
        lab, mesh = self.state, host.state.mesh
        wanted = lab.inputs(mesh.version)
        if lab.computed_for != wanted and host.state.jobs.running(self.name) is None:
            self._start(host, wanted)
        r = lab.result
        lines = repr(self.isolines)
        if r is None or not self.watch.changed("uploaded", lab.computed_for, lab.crosses, lines):
            return
        self._upload(host, r)

    def _start(self, host: Host, wanted: tuple[Any, ...]) -> None:
        lab, jobs, mesh = self.state, host.state.jobs, host.state.mesh
        params = lab.params()

        def apply(result: LabResult) -> None:
            lab.adopt(wanted, result)

        def fail(message: str) -> None:
            lab.computed_for = wanted  # not retried until an input changes
            host.state.errors[self.name] = message

        jobs.start(
            self.name,
            f"curvature lab ({lab.estimator}, {lab.show})",
            jobs.offload(lab.compute, params, mesh.V, mesh.F),
            apply,
            fail,
            background=bool(host.background),
        )

    def _upload(self, host: Host, r: LabResult) -> None:
        sm = ps.register_surface_mesh(LAB, r.V, r.F, smooth_shade=True)
        v = np.asarray(r.values, dtype=np.float64)
        top = float(np.percentile(np.abs(v), 98)) if v.size else 1.0
        top = top if top > 0 else 1.0
        signed = bool((v < 0).any())
        sm.add_scalar_quantity(
            r.label,
            v,
            cmap="coolwarm" if signed else "viridis",
            vminmax=(-top, top) if signed else (0.0, top),
            enabled=True,
            onscreen_colorbar_enabled=True,
            onscreen_colorbar_location=COLORBAR_AT,
            **self.isolines.options(self.state.show, v),
        )
        if not self.state.crosses:
            return
        for which, name, color in (
            (1, "k1 direction (max)", K1_COLOR),
            (2, "k2 direction (min)", K2_COLOR),
        ):
            vals, bx, by = cross_field(r.principal, which)
            sm.add_tangent_vector_quantity(
                name, vals, bx, by, n_sym=2, enabled=True, color=color, radius=0.0015
            )
        if r.exact_d1 is not None:
            vals, bx, by = cross_field(
                type(r.principal)(
                    r.principal.k1,
                    r.principal.k2,
                    r.exact_d1,
                    r.exact_d1,
                    r.principal.normal,
                    "exact",
                ),
                1,
            )
            sm.add_tangent_vector_quantity(
                "exact k1 direction", vals, bx, by, n_sym=2, enabled=False, color=EXACT_COLOR
            )

    def draw(self, host: Host) -> None:
        ui = host.ui
        if not ui.header(self.title):
            return
        host.draw_job(self.name)
        lab = self.state
        changed = False
        for what, items, tip in (
            ("source", LAB_SOURCES, "a parametric surface (exact values known) or the loaded mesh"),
            (
                "estimator",
                CURVATURE_ESTIMATORS,
                "; ".join(f"{k}: {v}" for k, v in CURVATURE_ESTIMATOR_LABELS.items()),
            ),
            (
                "quantity",
                PRINCIPAL_FIELDS,
                "k1 >= k2, H = (k1+k2)/2 > 0 on spheres, K = k1 k2, abs_max",
            ),
            (
                "show",
                LAB_SHOWS,
                "the estimate, its error against the exact surface, or the largest "
                "difference between all the estimators",
            ),
        ):
            ch, value = ui.combo(what, getattr(lab, what), items, tip)
            if ch:
                lab.set_choice(what, value)
                changed = True
        ch, lab.crosses = ui.checkbox(
            "crosses",
            lab.crosses,
            "principal directions: red k1 (max), blue k2 (min), length by |k|",
        )
        changed |= ch
        if lab.source == "surface":
            ch, value = ui.combo(
                "lab surface", lab.surface, tuple(SURFACES), "the parametric surface"
            )
            if ch:
                lab.set_choice("surface", value)
                changed = True
            for what, lo, hi, tip in (
                ("resolution", 3, MAX_RES, "cells per direction (the torus: twice around)"),
            ):
                ch, value = ui.slider_int(what, lab.res, lo, hi, tip)
                if ch:
                    lab.set_number("res", value)
                    changed = True
            for what, key, hi, tip in (
                (
                    "noise",
                    "noise",
                    MAX_NOISE,
                    "normal noise, a fraction of the bounding-box diagonal",
                ),
                (
                    "jitter",
                    "jitter",
                    MAX_JITTER,
                    "parameter jitter of interior vertices, a fraction of a cell",
                ),
                ("edge flips", "flips", 1.0, "fraction of the interior edges flipped"),
            ):
                ch, value = ui.slider_float(what, getattr(lab, key), 0.0, hi, "%.4f", tip)
                if ch:
                    lab.set_number(key, value)
                    changed = True
        if changed:
            self.sync(host)
            host.refresh()
        if lab.result is not None:
            ui.text(lab.result.label)
            ui.text(lab.result.summary)
            self._draw_shape_operator(host)
            self._draw_convergence(host, lab.result)
        if draw_isolines(ui, self.isolines, lab.show):  # last: the plots above stay in view
            self.sync(host)

    def _draw_shape_operator(self, host: Host) -> None:
        """The picked vertex's 2×2 tensor with its basis and Euler's κn(θ), exact beside it."""
        ui, lab = host.ui, self.state
        ch, v = ui.input_int(
            "vertex", lab.vertex, "pick a vertex (or click the mesh): its shape operator"
        )
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
    def _draw_convergence(host: Host, r: LabResult) -> None:
        """log10(relative RMS error) against log10(h) for H and K, the order in the legend."""
        rows = [row for row in r.convergence if row["H_rel"] > 0 and row["K_rel"] > 0]
        if len(rows) < 2:
            return
        x = np.log10([row["h"] for row in rows])
        with host.ui.plot("error vs h (log-log)", 150, "log10 h", "log10 rel. error") as shown:
            if shown:
                for q in PRINCIPAL_FIELDS[2:4]:  # H and K
                    order = rows[-1][f"{q}_order"]
                    tag = f"{q}, order {order:.2f}" if order is not None else q
                    host.ui.plot_line(tag, x, np.log10([row[f"{q}_rel"] for row in rows]))


PANEL = CurvatureLabPanel
