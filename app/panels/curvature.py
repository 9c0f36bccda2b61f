"""The Curvature panel: a curvature field as a colour map, optionally a second one beside it."""

from __future__ import annotations

from typing import Any

import numpy as np
import polyscope as ps

from meshlap_core.options import CURVATURE_FIELD_LABELS, curvature_field_title

from .. import scene
from ..host import Host
from ..isolines import draw_isolines
from ..scene import MESH, MESH_B, colorbar_at, front_view, scalar_for_upload, side_offset
from ..setting_widgets import setting_widget
from ..state.curvature import PRINCIPAL_JOB, SETTINGS
from .base import ExportItem, Panel, shown_field


class CurvaturePanel(Panel):
    """Field, area, boundary rule, clip percentage, side-by-side second estimator, histogram.

    Its state is the :class:`~meshlap_app.state.app.AppState`'s curvature fields (the One-ring
    view and the export read them too); this panel shows them on the mesh whenever the active
    view ``shows_curvature``.
    """

    shows_curvature = True
    pick_through = True  # a click on the mesh selects a vertex (the one-ring view takes it)
    framed = (MESH_B,)
    _fields_job: tuple[tuple[Any, ...], Any] | None = None  # (inputs, job) of the last fields job

    def on_new_mesh(self, host: Host) -> None:
        self.watch.forget()
        if ps.has_surface_mesh(MESH_B):  # the side-by-side copy of the previous mesh
            ps.remove_surface_mesh(MESH_B)

    def show(self, host: Host, active: Panel) -> None:
        self.sync(host)
        if ps.has_surface_mesh(MESH_B):
            ps.get_surface_mesh(MESH_B).set_enabled(active is self)

    def points(self, host: Host, name: str) -> np.ndarray | None:
        if name == MESH_B:
            shown = host.mesh_points()
            return shown + side_offset(shown, front_view(host.state.mesh.name))
        return None

    def captions(self, host: Host) -> dict[str, str]:
        c = host.state.curv
        if not c.side_by_side:
            return {}
        return {
            MESH: CURVATURE_FIELD_LABELS[c.field_name][0],
            MESH_B: CURVATURE_FIELD_LABELS[c.second_field][0],
        }

    def export_items(self, host: Host) -> list[ExportItem]:
        """The mesh with its field, and side by side the copy with the second field."""
        c, mesh = host.state.curv, host.state.mesh
        c.update(mesh)
        items = shown_field(f"{mesh.stem}_{c.field_name}", mesh.V, mesh.F, c.values(c.field_name))
        if c.side_by_side and c.second_field != c.field_name:
            second = c.values(c.second_field)
            items += shown_field(f"{mesh.stem}_{c.second_field}", mesh.V, mesh.F, second)
        return items

    def capture(self, host: Host) -> dict[str, Any]:
        c = host.state.curv
        return {
            "field": c.field_name,
            "area": c.area,
            "boundary": c.boundary,
            "clip": float(c.percentile),
            "side_by_side": bool(c.side_by_side),
            "second_field": c.second_field,
            "estimator": c.estimator,
            **self.isolines_section(),
        }

    def configure(self, host: Host, values: dict[str, Any]) -> None:
        c = host.state.curv
        c.field_name, c.area, c.boundary = values["field"], values["area"], values["boundary"]
        c.set_percentile(values["clip"])
        c.side_by_side, c.second_field = values["side_by_side"], values["second_field"]
        c.set_estimator(values["estimator"])
        self.configure_isolines(values)

    def start(self, host: Host, options: dict[str, Any], shown: bool, screenshot: bool) -> None:
        if options.get("field") is not None:
            host.state.curv.field_name = options["field"]

    def sync(self, host: Host) -> None:
        """Upload the selected curvature field(s) as colour maps when the mesh, the fields'
        options or the display options changed (the field's colour bar is on while the active
        view ``shows_curvature``)."""
        curv, mesh = host.state.curv, host.state.mesh
        colorbar = host.active().shows_curvature
        if not ps.has_surface_mesh(MESH):
            return
        if not self.fields_ready(host):
            return  # a job computes them: the map on screen stays until they arrive
        if curv.estimator != "cotan":  # k1, k2 stay cotan's until the estimator's arrive
            curv.want_principal(mesh, host.state.jobs, bool(host.background))
        key = (
            mesh.version,
            curv.area,
            curv.boundary,
            curv.field_name,
            curv.percentile,
            curv.side_by_side,
            curv.second_field,
            colorbar,
            host.active() is self,  # the copy (and its colour bar) only in this view
            host.state.ui_scale,
            repr(self.isolines),
            curv.estimator,
            curv.principal_inputs(mesh) if curv.principal_current(mesh) else None,
        )
        if not self.watch.changed("uploaded", *key):
            return
        # shown only with its colour bar: a view that does not show the curvature (the
        # spectral view before its eigenbasis) sees the plain mesh, not colours with no legend
        self._add_field(host, ps.get_surface_mesh(MESH), curv.field_name, colorbar)
        if curv.side_by_side:
            if not ps.has_surface_mesh(MESH_B):
                V = host.mesh_points()
                X = V + side_offset(V, front_view(mesh.name))
                scene.register_surface(MESH_B, X, mesh.F, host.active() is self)
            # its own labelled colour bar, below the first one
            mine = host.active() is self  # polyscope draws a hidden copy's bar too
            self._add_field(host, ps.get_surface_mesh(MESH_B), curv.second_field, mine, 1)
        elif ps.has_surface_mesh(MESH_B):
            ps.remove_surface_mesh(MESH_B)

    def fields_ready(self, host: Host) -> bool:
        """Bring the curvature fields up to date: right here for a new mesh or outside the
        window; as a job (progress and Cancel in this panel) when only the area or the
        boundary rule changed in the window. False while that job runs. Cancel goes back to
        the area and rule of the fields on screen."""
        curv, mesh = host.state.curv, host.state.mesh
        if curv.current(mesh):
            return True
        same_mesh = bool(curv.fields) and curv.computed_for()[0] == mesh.version
        if not (host.background and same_mesh):
            curv.update(mesh)
            return True
        jobs, wanted = host.state.jobs, (mesh.version, curv.area, curv.boundary)
        job = self._fields_job
        if job is not None and job[0] == wanted:
            if job[1].status == "running":
                return False
            if job[1].status == "cancelled":  # the user's Cancel: back to what is shown
                curv.area, curv.boundary = curv.computed_for()[1:]
                self._fields_job = None
                return True
        V, F, area, boundary = mesh.V, mesh.F, curv.area, curv.boundary

        def apply(fields: dict[str, np.ndarray]) -> None:
            if (mesh.version, curv.area, curv.boundary) == wanted:
                curv.adopt(mesh, fields)

        started = jobs.start(
            self.name,
            f"curvature fields ({area} areas, boundary {boundary})",
            jobs.offload(curv.compute, V, F, area, boundary),
            apply,
        )
        self._fields_job = (wanted, started)
        return False

    def _add_field(
        self, host: Host, sm: Any, name: str, colorbar: bool = False, slot: int = 0
    ) -> None:
        """Upload the field ``name`` on ``sm``: enabled with its colour bar (at ``slot``,
        :func:`.scene.colorbar_at`) when ``colorbar``, else uploaded but hidden."""
        curv = host.state.curv
        signed = CURVATURE_FIELD_LABELS[name][1]
        label = curvature_field_title(name, curv.estimator)  # what it is and its unit
        values, (lo, hi), factor = scalar_for_upload(curv.values(name), curv.color_range(name))
        sm.add_scalar_quantity(
            label + factor,
            values,
            defined_on="vertices",
            cmap="coolwarm" if signed else "viridis",
            vminmax=(lo, hi),
            enabled=colorbar,
            onscreen_colorbar_enabled=colorbar,
            onscreen_colorbar_location=colorbar_at(slot, host.state.ui_scale),
            **self.isolines.options(name, values),
        )

    def draw(self, host: Host) -> None:
        ui = host.ui
        if not ui.header(self.title):
            return
        # new area or boundary rule: the fields' progress, Cancel; the estimator's run (k1,
        # k2 and directions): one row kept for either
        host.draw_job(self.name, PRINCIPAL_JOB)
        c = host.state.curv
        ch1, c.field_name = setting_widget(ui, SETTINGS["field"], c.field_name)
        ch7, estimator = setting_widget(ui, SETTINGS["estimator"], c.estimator)
        if ch7:
            c.set_estimator(estimator)
        if c.principal_error:
            ui.error(f"{c.estimator}: {c.principal_error}")
        ch2, c.area = setting_widget(ui, SETTINGS["area"], c.area)
        ch3, c.boundary = setting_widget(ui, SETTINGS["boundary"], c.boundary)
        ch4, pct = setting_widget(ui, SETTINGS["clip"], c.percentile)
        if ch4:
            c.set_percentile(pct)
        ch5, c.side_by_side = setting_widget(ui, SETTINGS["side_by_side"], c.side_by_side)
        if c.side_by_side:
            _, c.second_field = setting_widget(ui, SETTINGS["second_field"], c.second_field)
        ch6 = draw_isolines(ui, self.isolines, c.field_name)
        if ch1 or ch2 or ch3 or ch4 or ch5 or ch6 or ch7:
            self.sync(host)
            host.refresh()
        if ch5:
            host.request_frame()
        if c.field_name not in c.fields:
            return
        loading = host.loading()
        if loading is not None and loading[1] is not None:  # another mesh's preview shown
            ui.note(f"statistics and histogram once {loading[0]} has loaded")
            return
        st = c.summary()
        lo, hi = st["range"]
        ui.text(f"min {st['min']:.4g}  max {st['max']:.4g}  colour range [{lo:.4g}, {hi:.4g}]")
        with ui.plot(  # the field's name is the x axis's label (and the colour bar's title)
            "histogram (clipped to the colour range)",
            130,
            curvature_field_title(c.field_name, c.estimator),
            "vertices",
        ) as shown:
            if shown:
                signed = CURVATURE_FIELD_LABELS[c.field_name][1]
                colors = self.watch.cached(  # a colour map lookup: once per histogram
                    "bar colours",
                    (id(st), lo, hi, signed),
                    lambda: _bar_colors(st["centers"], lo, hi, signed),
                )
                # one series, named by the y axis: no legend (it went above the plot, over
                # every corner's bars, and took the plot's height)
                ui.plot_bars("##vertices", st["centers"], st["counts"], st["width"], colors)


def _bar_colors(centers: np.ndarray, lo: float, hi: float, signed: bool) -> np.ndarray:
    """Each histogram bar ``(k,4)`` in the colour the mesh shows for its value (the same map,
    coolwarm or viridis, and the same range ``[lo, hi]``)."""
    from matplotlib import colormaps

    c = np.asarray(centers, dtype=np.float64)
    t = (c - lo) / (hi - lo) if hi > lo else np.full(len(c), 0.5)
    return colormaps["coolwarm" if signed else "viridis"](np.clip(t, 0.0, 1.0))
