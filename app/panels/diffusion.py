"""The Diffusion panel: heat from clicked vertices two ways (backward Euler and the
eigen-expansion, their difference on one colour range, the truncation bound), geodesic distance
by the heat method with isolines (the exact distance on demand, as a job), spectral filters over
the computed eigenvalues, and the heat kernel signature. State in :mod:`..state.diffusion`."""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

import numpy as np
import polyscope as ps

from meshlap_core.diffusion import HeatGeodesic, exact_distance, mean_edge_length
from meshlap_core.options import SMOOTHING_METHODS

from .. import scene
from ..host import Host
from ..isolines import draw_isolines
from ..panel_spec import PanelSpec
from ..scene import MESH, front_view, picked_vertex, side_offset
from ..setting_widgets import setting_widget
from ..state.diffusion import (
    CURVE_POINTS,
    DEFAULT_KNOTS,
    DISTANCE_ERROR_TITLE,
    DISTANCE_TITLE,
    HEAT_FIELDS,
    HEAT_TITLES,
    HKS_DISTANCE_TITLE,
    HKS_TITLE,
    ISO_FIELDS,
    SETTINGS,
    DiffusionState,
    find_basis,
    symmetric_range,
)
from ..state.isolines import DEFAULT_COUNT
from .base import ExportItem, Panel, shown_field

SOURCES = "heat sources"
FILTERED = "filtered"
HEAT_COPIES = ("heat (second way)", "heat (third field)")
"""The two heat fields not on the mesh, on copies beside it (same colour range)."""
INLINE_DISTANCE_MAX = 100_000
"""Up to this many vertices a new source's distance is solved on the UI thread (about 40 ms
at 43k once factorized); above, as a job."""
FACTORING = "heat method: factorizing"
SOLVING = "heat method: distance"
"""The titles of the distance's two jobs (a click during the first waits for it)."""
NEEDS_BASIS = "needs an eigenbasis: compute one in the Spectral view first"
ISOLINES_ON = ("distance", "hks")
"""Fields whose isolines start shown (heat is ~0 over most of the mesh: its level 0 would
blacken it)."""


class DiffusionPanel(Panel):
    """Heat, distance, filters and HKS from clicked vertices."""

    framed = (FILTERED, *HEAT_COPIES)
    shortcuts = (
        (
            "mouse",
            "diffusion: click a vertex for the heat / distance source; shift-click adds one",
        ),
    )

    def __init__(self, spec: PanelSpec, state: DiffusionState) -> None:
        super().__init__(spec, state)
        self.state: DiffusionState = state
        self._factoring: Any = None  # the geodesic key of the last factorization started
        self._title = ""  # the title of the field uploaded on the mesh ("": none)

    # ------------------------------------------------------------------ the scene
    def animating(self) -> bool:
        """T plays up its log scale: the window keeps its full frame rate."""
        return bool(self.state.playing)

    def on_new_mesh(self, host: Host) -> None:
        host.state.jobs.cancel(self.name)
        self.state.clear()
        self.watch.forget()
        for name in (SOURCES, FILTERED, *HEAT_COPIES):
            scene.remove_structure(name)

    def show(self, host: Host, active: Panel) -> None:
        mine = active is self
        for name in (SOURCES, FILTERED, *HEAT_COPIES):
            if ps.has_point_cloud(name):
                ps.get_point_cloud(name).set_enabled(mine)
            if ps.has_surface_mesh(name):
                ps.get_surface_mesh(name).set_enabled(mine)
        if mine:
            # the window factorizes before the first click (a headless render or animation
            # computes what it shows right away instead)
            ready = self.state.geodesic_ready(host.state.mesh.version)
            if host.background and self.state.show == "distance" and not ready:
                self.precompute(host)
            self.push(host, force=True)
        elif self.watch.seen("field") is not None and ps.has_surface_mesh(MESH):
            self._remove_field(ps.get_surface_mesh(MESH))
            self.watch.forget("field")

    def sync(self, host: Host) -> None:
        """The heat kernel signature of the eigenbasis there is now: a basis that arrives
        after the view was set (a session's, read from the cache; one computed in the
        Spectral view) gives it its field and its t (the filter's is made when drawn)."""
        st = self.state
        if host.active() is not self or st.show != "hks":
            return
        basis = self._basis(host)
        if basis is not None and (st._hks is None or st._hks[0] is not basis):
            st.compute_hks(basis)
            self.push(host)

    def pick(self, host: Host, hit: Any, active: Panel) -> bool:
        if active is not self or hit.structure_name != MESH:
            return False
        idx = picked_vertex(hit, host.mesh_points(), host.state.mesh.F)
        if idx is None:
            return False
        return self.select(host, idx, add="shift" in getattr(hit, "modifiers", ()))

    def select(self, host: Host, vertex: int, add: bool = False) -> bool:
        """Make ``vertex`` the source (``add``: one more, a shift-click) and recompute what is
        shown."""
        if not self.state.select(len(host.state.mesh.V), vertex, add):
            return False
        self.recompute(host)
        return True

    def _basis(self, host: Host) -> Any:
        slices = [p.state for p in host.panels.values() if p is not self]
        return find_basis(slices, host.state.mesh.V)

    def _h(self, host: Host) -> float:
        mesh = host.state.mesh
        return self.watch.cached(
            "h", (id(mesh), mesh.version), lambda: mean_edge_length(mesh.V, mesh.F)
        )

    def recompute(self, host: Host) -> None:
        """Compute the field of the current view (a precomputation runs as a job)."""
        st = self.state
        basis = self._basis(host)
        if st.show == "heat":
            self.start_heat(host, basis)
        elif st.show == "distance":
            self.distance(host)
        elif basis is not None and st.show == "filter":
            st.compute_filter(basis)
        elif basis is not None and st.show == "hks":
            st.compute_hks(basis)
        self.push(host)

    def start_heat(self, host: Host, basis: Any) -> None:
        """The heat fields as a job (a new t refactorizes ``M + τK``: about a second at 43k
        vertices); what is shown stays until they arrive."""
        st, mesh = self.state, host.state.mesh
        if not st.sources:
            return
        V, F, h = mesh.V, mesh.F, self._h(host)

        def apply(result: Any) -> None:
            st.adopt_heat(result)
            self.push(host)

        host.state.jobs.start(
            self.name, "heat", lambda reporter: st.heat_work(V, F, h, basis), apply,
            self._failed(host), background=host.background,
        )  # fmt: skip

    def distance(self, host: Host) -> None:
        """The heat method's distance from the sources: its factorizations first (a job, once
        per mesh, ``m`` and boundary rule), then per click only back-substitutions (inline up
        to :data:`INLINE_DISTANCE_MAX` vertices, else a job: 0.3–0.6 s at 692k)."""
        st, mesh = self.state, host.state.mesh
        if not st.geodesic_ready(mesh.version):
            self.precompute(host)
            return
        if not st.sources:
            return
        if len(mesh.V) <= INLINE_DISTANCE_MAX:
            st.compute_distance()
            return
        solver, sources = st._geodesic, list(st.sources)

        def apply(d: np.ndarray) -> None:
            st.adopt_distance(d)
            self.push(host)

        host.state.jobs.start(
            self.name, SOLVING, lambda reporter: solver.distance(sources), apply,
            self._failed(host), background=host.background,
        )  # fmt: skip

    def precompute(self, host: Host) -> None:
        """The heat method's factorizations as a job (about a second at 43k vertices, 10–30 s
        at 692k), started as soon as the distance view shows a mesh, so the first click only
        back-substitutes; clicks meanwhile wait for it (it is not restarted), and it answers
        the sources of its end."""
        st, mesh, jobs = self.state, host.state.mesh, host.state.jobs
        if len(mesh.V) == 0 or len(mesh.F) == 0:
            return
        key = st.geodesic_key(mesh.version)
        job = jobs.running(self.name)
        if job is not None and job.title == FACTORING and self._factoring == key:
            return  # under way: it answers the sources when done
        V, F, m, rule = mesh.V, mesh.F, st.m, st.boundary

        def apply(solver: HeatGeodesic) -> None:
            st.adopt_geodesic(solver, key)
            if st.show == "distance" and st.sources:
                self.recompute(host)

        self._factoring = key
        jobs.start(
            self.name, FACTORING, lambda reporter: HeatGeodesic(V, F, m=m, boundary=rule),
            apply, self._failed(host), background=host.background,
        )  # fmt: skip

    def start_exact(self, host: Host) -> None:
        """The exact polyhedral distance as a cancellable job (a child process when the
        window allows: libigl holds the GIL for the whole propagation)."""
        st, mesh, jobs = self.state, host.state.mesh, host.state.jobs
        if not st.sources:
            return
        work = jobs.offload(exact_distance, mesh.V, mesh.F, np.asarray(st.sources))

        def apply(d: np.ndarray) -> None:
            st.adopt_exact(d)
            self.push(host)

        jobs.start(
            self.name, "exact geodesic distance", work, apply, self._failed(host),
            background=host.background,
        )  # fmt: skip

    def _failed(self, host: Host) -> Any:
        def fail(message: str) -> None:
            host.state.errors[self.name] = message

        return fail

    def _field(self) -> tuple[np.ndarray | None, tuple[float, float] | None, str, str]:
        """The field on the mesh, its colour range (``None``: its own), colour map and
        title (what it is and its unit: the colour bar's)."""
        st = self.state
        if st.show == "heat":
            f, vr = st.heat_shown()
            shown = st.heat_field if st.heat_field in st.heat else "euler"
            return f, vr, "coolwarm", HEAT_TITLES[shown]
        if st.show == "distance":
            if st.exact_error is not None and st.heat_field == "difference":
                return st.exact_error, None, "reds", DISTANCE_ERROR_TITLE
            return st.distance, None, "viridis", DISTANCE_TITLE
        if st.show == "hks":
            if st.hks_dist is not None:
                return st.hks_dist, None, "viridis", HKS_DISTANCE_TITLE
            return st.hks, None, "viridis", HKS_TITLE
        return None, None, "viridis", ""

    def iso_field(self) -> str | None:
        """The isoline settings' name of the field on the mesh (``None``: no field)."""
        st = self.state
        if st.show == "filter":
            return None
        error = st.heat_field == "difference" and st.show in ("heat", "distance")
        return f"{st.show} error" if error else st.show

    def push(self, host: Host, force: bool = False) -> None:
        """Upload the shown field (with isolines), the sources and the filtered copy."""
        if host.active() is not self or not ps.has_surface_mesh(MESH):
            return
        st, name = self.state, self.iso_field()
        lines = self.isolines.of(name, name in ISOLINES_ON) if name else None
        key = (st.version, st.show, st.heat_field, lines and (lines.on, lines.count))
        if not self.watch.changed("field", *key) and not force:
            return
        f, vr, cmap, title = self._field()
        sm = ps.get_surface_mesh(MESH)
        if f is None or len(f) != len(host.state.mesh.V):
            self._remove_field(sm)
        else:
            if vr is None:
                fin = f[np.isfinite(f)]
                vr = (float(fin.min()), float(fin.max())) if fin.size else (0.0, 1.0)
            # unreachable vertices (another component) and undefined errors take the top
            # colour: polyscope refuses non-finite values
            shown = np.where(np.isfinite(f), f, vr[1])
            self._show_field(sm, shown, vr, cmap, title, str(name), name in ISOLINES_ON)
        self._push_sources(host)
        self._push_filtered(host)
        self._push_heat_copies(host)

    def _push_sources(self, host: Host) -> None:
        if not self.state.sources:
            scene.remove_structure(SOURCES)
            return
        P = host.mesh_points()[np.asarray(self.state.sources)]
        pc = ps.register_point_cloud(SOURCES, P, color=scene.RED[:3])
        pc.set_radius(0.01, relative=True)

    def _push_filtered(self, host: Host) -> None:
        st = self.state
        if st.show != "filter" or st.filtered is None:
            scene.remove_structure(FILTERED)
            return
        mesh = host.state.mesh
        X = host.state.display.points(st.filtered) + self._offset(host)
        if ps.has_surface_mesh(FILTERED):
            ps.get_surface_mesh(FILTERED).update_vertex_positions(X)
        else:
            scene.register_surface(FILTERED, X, mesh.F, host.active() is self)
            host.request_frame()

    def _offset(self, host: Host, slot: int = 1) -> np.ndarray:
        mesh = host.state.mesh
        return slot * side_offset(host.mesh_points(), front_view(mesh.name))

    def _copy_fields(self) -> list[str]:
        """The heat fields shown on the copies (the two not on the mesh), when all three
        exist."""
        st = self.state
        if st.show != "heat" or len(st.heat) < 3:
            return []
        return [f for f in HEAT_FIELDS if f != st.heat_field]

    def _push_heat_copies(self, host: Host) -> None:
        fields = self._copy_fields()
        if not fields:
            for name in HEAT_COPIES:
                scene.remove_structure(name)
            return
        _, vr = self.state.heat_shown()
        F = host.state.mesh.F
        for slot, (name, which) in enumerate(zip(HEAT_COPIES, fields, strict=True), start=1):
            X = host.mesh_points() + self._offset(host, slot)
            if ps.has_surface_mesh(name):
                ps.get_surface_mesh(name).update_vertex_positions(X)
            else:
                scene.register_surface(name, X, F, host.active() is self)
                host.request_frame()
            iso = "heat error" if which == "difference" else "heat"
            values, vrs, factor = scene.scalar_for_upload(self.state.heat[which], vr)
            ps.get_surface_mesh(name).add_scalar_quantity(
                HEAT_TITLES[which] + factor, values, cmap="coolwarm", vminmax=vrs, enabled=True,
                **self.isolines.options(iso, values, iso in ISOLINES_ON),
            )  # fmt: skip

    def _remove_field(self, sm: Any) -> None:
        """Take the field (and its colour bar) off the mesh ``sm``."""
        if self._title:
            sm.remove_quantity(self._title)
        self._title = ""

    def _show_field(self, sm: Any, f: Any, vr: Any, cmap: str, title: str, *iso: Any) -> None:
        """``f`` float32-safe (:func:`.scene.scalar_for_upload`) under ``title`` (what it is
        and its unit, the colour bar's: one field on the mesh at a time); ``iso``: name,
        on[, span]."""
        values, vr, factor = scene.scalar_for_upload(f, vr)
        if self._title != title + factor:
            self._remove_field(sm)
        self._title = title + factor
        sm.add_scalar_quantity(
            self._title, values, cmap=cmap, vminmax=vr, enabled=True,
            onscreen_colorbar_enabled=True, onscreen_colorbar_location=scene.COLORBAR_AT,
            **self.isolines.options(iso[0], np.array(vr) if iso[2:] else values, iso[1]),
        )  # fmt: skip

    def points(self, host: Host, name: str) -> np.ndarray | None:
        if name == FILTERED and self.state.filtered is not None:
            return host.mesh_points() + self._offset(host)
        if name in HEAT_COPIES and self._copy_fields():
            return host.mesh_points() + self._offset(host, 1 + HEAT_COPIES.index(name))
        return None

    def captions(self, host: Host) -> dict[str, str]:
        st = self.state
        if st.show == "filter" and st.filtered is not None:
            return {FILTERED: f"{st.filter} filter"}
        fields = self._copy_fields()
        if fields:
            words = {"euler": "backward Euler", "difference": "spectral - Euler"}
            words[HEAT_FIELDS[1]] = f"eigen-expansion, k = {st.k_used}"
            out = {MESH: words[st.heat_field]}
            out.update({n: words[f] for n, f in zip(HEAT_COPIES, fields, strict=True)})
            return out
        return {}

    def export_items(self, host: Host) -> list[ExportItem]:
        """The mesh with the field on it, the heat copies with theirs, the filtered copy
        (each PLY with its field, the field as CSV)."""
        st, mesh = self.state, host.state.mesh
        f, _, _, _ = self._field()
        stem = mesh.stem
        items: list[ExportItem] = []
        if f is not None and len(f) == len(mesh.V):
            name = f"{stem}_{self.iso_field()}".replace(" ", "_")
            items += shown_field(name, mesh.V, mesh.F, f)
        else:
            items.append((f"{stem}.ply", mesh.V, mesh.F, None))
        for which in self._copy_fields():
            items += shown_field(f"{stem}_heat_{which}", mesh.V, mesh.F, st.heat[which])
        if st.filtered is not None and st.show == "filter":
            items.append((f"{stem}_filtered_{st.filter}.ply", st.filtered, mesh.F, None))
        return items

    # ------------------------------------------------------------------ sessions
    def capture(self, host: Host) -> dict[str, Any]:
        st = self.state
        return {
            "show": st.show,
            "sources": [int(v) for v in st.sources],
            "log_t": float(st.log_t),
            "steps": int(st.steps),
            "heat_field": st.heat_field,
            "m": float(st.m),
            "boundary": st.boundary,
            "isolines": bool(self.isolines.of("distance", True).on),
            "isoline_count": int(self.isolines.of("distance", True).count),
            "isoline_fields": self._iso_changed(),
            "filter": st.filter,
            "keep": int(st.keep),
            "gain": float(st.gain),
            "hks_scale": int(st.hks_scale),
            "iters": int(st.iters),
            "residual": bool(st.residual),
            "curve": [float(y) for _, y in st.knots],
        }

    def _iso_changed(self) -> dict[str, dict[str, Any]]:
        """The isoline settings of :data:`ISO_FIELDS` that differ from a new field's."""
        out = {}
        for name in ISO_FIELDS:
            s = self.isolines.fields.get(name)
            if s is not None and (s.on != (name in ISOLINES_ON) or s.count != DEFAULT_COUNT):
                out[name] = {"on": bool(s.on), "count": int(s.count)}
        return out

    def configure(self, host: Host, values: dict[str, Any]) -> None:
        st = self.state
        lines = self.isolines.of("distance", True)  # the session keeps the distance's
        for key, value in values.items():
            if key == "isolines":
                lines.on = bool(value)
            elif key == "isoline_count":
                lines.set_count(value)
            elif key == "isoline_fields":
                for name in ISO_FIELDS:  # a field not saved is at its defaults
                    field = self.isolines.of(name, name in ISOLINES_ON)
                    saved = value.get(name, {"on": name in ISOLINES_ON, "count": DEFAULT_COUNT})
                    field.on = bool(saved["on"])
                    field.set_count(saved["count"])
            elif key == "curve":  # the drawn gains at the fixed control points
                st.knots = [(x, float(y)) for (x, _), y in zip(DEFAULT_KNOTS, value, strict=True)]
            elif key != "sources":
                setattr(st, key, value)
        st.filtered = None  # computed again for these settings when shown

    def restore(self, host: Host, values: dict[str, Any], active: bool) -> None:
        self.configure(host, values)
        self.state.sources = list(values["sources"])
        if self.state.sources and active:
            self.recompute(host)

    def start(self, host: Host, options: dict[str, Any], shown: bool, screenshot: bool) -> None:
        """``meshlap view --panel diffusion --vertex I``: that vertex is the source."""
        vertex = options.get("vertex")
        if shown and vertex is not None:
            self.select(host, int(vertex))

    # ------------------------------------------------------------------ widgets
    def draw(self, host: Host) -> None:
        ui = host.ui
        if not ui.header(self.title):
            return
        st = self.state
        host.draw_job(self.name)
        ch, show = setting_widget(ui, SETTINGS["show"], st.show)
        if ch:
            st.set_choice("show", show)
            st.playing = False  # t plays in the heat view only
            self.recompute(host)
        if ui.button("clear sources", "forget the clicked vertices"):
            st.sources = []
            st.version += 1
            self.push(host)
        ui.text(
            f"sources: {', '.join(map(str, st.sources)) or 'click a vertex'}"
            + (" (shift-click adds one)" if st.sources else "")
        )
        basis = self._basis(host)
        {"heat": self._draw_heat, "distance": self._draw_distance}.get(
            st.show, self._draw_spectral
        )(host, basis)
        name = self.iso_field()
        if name is not None and draw_isolines(ui, self.isolines, name, name in ISOLINES_ON):
            self.push(host)

    def _draw_heat(self, host: Host, basis: Any) -> None:
        ui, st = host.ui, self.state
        h = self._h(host)
        ch, x = setting_widget(ui, SETTINGS["log_t"], st.log_t)
        if ch:
            st.set_log_t(x)
            self.recompute(host)
        if ui.button(
            "pause t" if st.playing else "play t",
            "sweep t up its log scale, one step each time the last heat field has arrived",
        ):
            st.toggle_play()
        # a step once the last field is shown: each t refactorizes M + tau K (a job)
        if st.playing and host.state.jobs.running(self.name) is None and st.play_step():
            self.recompute(host)
        ch, steps = setting_widget(ui, SETTINGS["steps"], st.steps)
        if ch:
            st.steps = SETTINGS["steps"].clamp(steps)
            self.recompute(host)
        ch, which = setting_widget(ui, SETTINGS["heat_field"], st.heat_field)
        if ch:
            st.set_choice("heat_field", which)
            self.push(host)
        ui.text(f"t = {st.t(h):.4g}")
        if basis is None:
            ui.note(f"spectral heat {NEEDS_BASIS}")
        elif st.k_used:
            ui.text(
                f"k = {st.k_used}: omitted modes damped by <= exp(-lambda_k t) = {st.bound:.3g}"
            )
            if "difference" in st.heat:
                _, hi_ = symmetric_range(st.heat["difference"])
                ui.text(f"max |spectral - euler| = {hi_:.3g}")

    def _draw_distance(self, host: Host, basis: Any) -> None:
        ui, st = host.ui, self.state
        ch, m = setting_widget(ui, SETTINGS["m"], st.m)
        if ch:
            st.set_m(m)
            self.recompute(host)
        ch, rule = setting_widget(ui, SETTINGS["boundary"], st.boundary)
        if ch:
            st.set_choice("boundary", rule)
            self.recompute(host)
        if ui.button("exact distance", "igl.exact_geodesic (MMP) as a job; error map after"):
            self.start_exact(host)
        if st.exact_stats:
            ui.text(
                f"heat vs exact: max {100 * st.exact_stats['max']:.3g}%, "
                f"mean {100 * st.exact_stats['mean']:.3g}% relative error"
            )
            ch, err = ui.checkbox(
                "show error map", st.heat_field == "difference", "|d - d_exact| / d_exact"
            )
            if ch:
                st.heat_field = "difference" if err else "euler"
                self.push(host)

    def _draw_spectral(self, host: Host, basis: Any) -> None:
        ui, st = host.ui, self.state
        if basis is None:
            ui.note(f"{st.show} {NEEDS_BASIS}")
            return
        if st.show == "hks":
            ch, s = setting_widget(ui, SETTINGS["hks_scale"], st.hks_scale)
            if ch:
                st.hks_scale = SETTINGS["hks_scale"].clamp(s)
                self.recompute(host)
            ui.text(f"t = {st.hks_time():.4g}; with a source: signature distance from it")
            return
        self._draw_filter(host, basis)

    def _draw_filter(self, host: Host, basis: Any) -> None:
        ui, st = host.ui, self.state
        ch, kind = setting_widget(ui, SETTINGS["filter"], st.filter)
        if ch:
            st.set_choice("filter", kind)
        ch, keep = setting_widget(ui, SETTINGS["keep"], min(st.keep, basis.k_max), 0, basis.k_max)
        if ch:
            st.keep = int(min(max(keep, 0), basis.k_max))
            st.band = (1, max(st.keep, 2))
        ch, gain = setting_widget(ui, SETTINGS["gain"], st.gain)
        if ch:
            st.gain = SETTINGS["gain"].checked(gain, "band gain")
        ch, iters = setting_widget(ui, SETTINGS["iters"], st.iters)
        if ch:
            st.iters = SETTINGS["iters"].clamp(iters)
        ch, res = setting_widget(ui, SETTINGS["residual"], st.residual)
        if ch:
            st.residual = res
        if st.filtered is None or ui.changed:
            st.measured = None  # for another filter
            st.compute_filter(basis)
            self.push(host)
        if st.filter in SMOOTHING_METHODS and ui.button(
            "measure by smoothing",
            "run the smoother on the mesh and project on the modes: the measured gain per mode "
            "(equal to the formula for these frozen-operator methods)",
        ):
            self.start_measure(host, basis)
        if st.measured is not None and st.gains is not None:
            ok = np.isfinite(st.measured)
            gap = float(np.abs(st.measured[ok] - st.gains[ok]).max()) if ok.any() else 0.0
            ui.text(f"measured vs formula: max |difference| = {gap:.2g}")
        if st.gains is not None:
            with ui.plot("transfer function h(lambda)", 150, "lambda", "h") as ok:
                if ok:
                    ui.plot_line("h(lambda)", basis.eigenvalues, st.gains)
                    if st.measured is not None:
                        ui.plot_line("measured", basis.eigenvalues, st.measured)
                    if st.filter == "drawn":
                        self._drag_curve(host, basis)
        if st.filter == "drawn":
            ui.text("drag the points up or down: U h(Lambda) U^T M X follows")

    def _drag_curve(self, host: Host, basis: Any) -> None:
        """The drawn curve's control points, each dragged in the plot; the filtered copy
        follows every move (the projection is kept: one product per drag)."""
        ui, st = host.ui, self.state
        P = st.curve_points(basis)
        ui.plot_line("drawn curve", P[:, 0], P[:, 1])
        for i, (x, y) in enumerate(P):
            moved, _, ny = ui.plot_drag_point(
                CURVE_POINTS[i], i, x, y,
                f"drag up or down: the gain h at lambda = {x:.3g} (linear between the points)",
            )  # fmt: skip
            if moved:
                st.move_knot(i, ny)
                st.compute_filter(basis)
                self.push(host)

    def start_measure(self, host: Host, basis: Any) -> None:
        """Run the smoother and project (a job: the implicit one factorizes)."""
        st = self.state

        def apply(g: np.ndarray) -> None:
            st.measured = g

        host.state.jobs.start(
            self.name, f"{st.filter} smoother, projected", lambda reporter: st.measure(basis),
            apply, self._failed(host), background=host.background,
        )  # fmt: skip

    # ------------------------------------------------------------------ meshlap animate
    def frames(self, host: Host, options: dict[str, Any]) -> Iterator[str]:
        """Heat from ``--heat-vertex`` (default: the vertex facing the camera) by backward
        Euler, t swept on a log scale; each frame coloured from 0 to its own maximum (the
        caption gives it: the peak falls as the heat spreads)."""
        st, mesh = self.state, host.state.mesh
        st.show, st.heat_field = "heat", "euler"
        source = int(options["heat_vertex"])
        if source < 0:
            P = mesh.V - mesh.V.mean(axis=0)
            source = int(np.argmax(P @ np.asarray(front_view(mesh.name))))
        st.select(len(mesh.V), source)
        host.refresh()
        host.frame(scene.COLORBAR_STRIP)
        a, b = options["heat_t"]
        h = self._h(host)
        for x in np.linspace(a, b, int(options["heat_frames"])):
            st.log_t = float(x)
            st.compute_heat(mesh.V, mesh.F, h, None)
            f = st.heat["euler"]
            top = float(f.max()) or 1.0
            self._show_field(
                ps.get_surface_mesh(MESH), f, (0.0, top), "viridis", HEAT_TITLES["euler"],
                "distance", 1, 1,
            )  # fmt: skip
            self._push_sources(host)
            yield f"heat from vertex {source}: t = {st.t(h):.3g} = 10^{x:.2f} h^2, peak {top:.3g}"
