"""The Check panel: a student's exercises file checked on the mesh on screen.

The file is run (in a separate process, as a background job with progress and Cancel) by
:func:`meshlap_core.exercises.check.check_on_mesh`; the panel shows the verdict with its
diagnosis, the difference map student − reference on the mesh with its colour bar, and at a
clicked vertex the student's row beside the reference's, term by term.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import polyscope as ps

from meshlap_core.errors import MeshError

from ..host import Host
from ..isolines import draw_isolines
from ..scene import MESH, colorbar_at, picked_vertex, scalar_for_upload
from ..setting_widgets import setting_widget
from ..state.check import SETTINGS, CheckState, difference_title
from ..ui import RED
from .base import ExportItem, Panel, shown_field


def difference_colours(d: np.ndarray, signed: bool) -> tuple[str, tuple[float, float]]:
    """The colour map and range of a difference map ``d (n,)``: coolwarm on ``[−r, r]`` when
    signed, viridis on ``[0, r]`` for a magnitude, ``r = max |d|`` (1 when zero); the
    panel's map and the notebook picture (:func:`meshlap_app.screenshots.difference_png`)."""
    r = float(np.abs(d).max()) if d.size else 0.0
    r = r if r > 0 else 1.0
    return ("coolwarm", (-r, r)) if signed else ("viridis", (0.0, r))


class CheckPanel(Panel):
    """Student file, task, *check*; verdict; difference map; the clicked vertex's rows."""

    state: CheckState
    _map = ""  # the title of the difference map uploaded on the mesh ("": none)

    def on_new_mesh(self, host: Host) -> None:
        self.watch.forget()
        self.state.vertex = -1

    def show(self, host: Host, active: Panel) -> None:
        if not ps.has_surface_mesh(MESH):
            return
        if active is self:
            self.sync(host)
        elif self.watch.seen("map") is not None:
            # the map's colour bar would stay on screen over another view
            self._remove_map()

    def sync(self, host: Host) -> None:
        """Upload the difference map (this view active, a check made on this mesh)."""
        st, mesh = self.state, host.state.mesh
        if host.active() is not self or not ps.has_surface_mesh(MESH):
            return
        if not st.current(mesh.version) or st.check.difference is None:
            if self.watch.seen("map") is not None:
                self._remove_map()
            return
        lines = repr(self.isolines)
        if not self.watch.changed("map", mesh.version, id(st.check), host.state.ui_scale, lines):
            return
        d = np.asarray(st.check.difference, dtype=np.float64)
        cmap, (lo, hi) = difference_colours(d, st.check.signed)
        values, (lo, hi), factor = scalar_for_upload(d, (lo, hi))
        title = difference_title(st.task, st.check.signed)
        sm = ps.get_surface_mesh(MESH)
        if self._map and self._map != title + factor:
            sm.remove_quantity(self._map)
        self._map = title + factor
        sm.add_scalar_quantity(
            self._map,
            values,
            defined_on="vertices",
            cmap=cmap,
            vminmax=(lo, hi),
            enabled=True,
            onscreen_colorbar_enabled=True,
            onscreen_colorbar_location=colorbar_at(0, host.state.ui_scale),
            **self.isolines.options("difference", values),
        )

    def export_items(self, host: Host) -> list[ExportItem]:
        """The mesh with the difference map student − reference on it (PLY, and the map as
        CSV), once a check of this mesh shows one; before, the plain mesh (the default)."""
        st, mesh = self.state, host.state.mesh
        if st.check is None or st.check.difference is None or not st.current(mesh.version):
            return []
        d = np.asarray(st.check.difference, dtype=np.float64)
        return shown_field(f"{mesh.stem}_{st.task}_student-reference", mesh.V, mesh.F, d)

    def _remove_map(self) -> None:
        """Take the difference map (and its colour bar) off the mesh."""
        if self._map and ps.has_surface_mesh(MESH):
            ps.get_surface_mesh(MESH).remove_quantity(self._map)
        self._map = ""
        self.watch.forget("map")

    def capture(self, host: Host) -> dict[str, Any]:
        st = self.state
        return {
            "file": st.file,
            "task": st.task,
            "vertex": int(st.vertex),
            "checked": st.current(host.state.mesh.version),
            **self.isolines_section(),
        }

    def configure(self, host: Host, values: dict[str, Any]) -> None:
        self.state.file = values["file"]
        self.state.set_task(values["task"])
        self.configure_isolines(values)

    def restore(self, host: Host, values: dict[str, Any], active: bool) -> None:
        """The clicked vertex, and the check run again when one was shown (a job in the
        window); a student file missing here is said in red, the session still opens."""
        self.configure(host, values)
        self.state.vertex = values["vertex"]
        if not values["checked"]:
            return
        try:
            self.start_check(host)
        except MeshError as exc:
            host.state.errors[self.name] = str(exc)

    def pick(self, host: Host, hit: Any, active: Panel) -> bool:
        """A click on the mesh in this view selects the vertex whose rows are shown."""
        if active is not self or hit.structure_name != MESH:
            return False
        idx = picked_vertex(hit, host.mesh_points(), host.state.mesh.F)
        if idx is None:
            return False
        self.state.select(idx, len(host.state.mesh.V))
        return True

    def start_check(self, host: Host) -> None:
        """Check the typed file's task on the mesh: a job in the window, right away outside.

        Raises
        ------
        MeshError
            No file typed, or it does not exist (the last check stays).
        """
        st, mesh = self.state, host.state.mesh
        path = st.student_path(host.state.folder)
        key = (mesh.version, str(path), st.task)

        def apply(check: Any) -> None:
            if host.state.mesh.version == key[0]:
                st.adopt(check, key)
                host.state.errors.pop(self.name, None)

        def fail(message: str) -> None:
            host.state.errors[self.name] = message

        V, F, task = mesh.V, mesh.F, st.task

        def work(reporter: Any) -> Any:  # a thread, not jobs.offload: the check spawns its own
            return st.compute(path, task, V, F, progress=reporter)  # process (no daemon child)

        jobs = host.state.jobs
        jobs.start(self.name, f"check {task}", work, apply, fail, background=host.background)

    def draw(self, host: Host) -> None:
        ui, st = host.ui, self.state
        if not ui.header(self.title):
            return
        _, st.file = setting_widget(ui, SETTINGS["file"], st.file)
        changed, task = setting_widget(ui, SETTINGS["task"], st.task)
        if changed:
            st.set_task(task)
        running = host.draw_job(self.name, reserve=False)  # in the button's place
        check = SETTINGS["checked"]  # the button: a check shown is what a session keeps
        if not running and ui.button(check.label, check.tooltip):
            self.start_check(host)
        for k, line in enumerate(st.verdict()):
            passed = st.check is not None and st.check.result.passed
            (ui.text if k == 0 and passed else ui.error if k == 0 else ui.note)(line.strip())
        if st.check is not None and not st.current(host.state.mesh.version):
            ui.note("(checked on another mesh: check again)")
        if st.check is not None and st.current(host.state.mesh.version):
            self._draw_rows(host)
            if st.check.difference is not None and draw_isolines(ui, self.isolines, "difference"):
                self.sync(host)

    def _draw_rows(self, host: Host) -> None:
        ui, st = host.ui, self.state
        changed, vertex = setting_widget(ui, SETTINGS["vertex"], st.vertex)
        if changed:
            st.select(vertex, len(host.state.mesh.V))
        rows = st.rows()
        if not rows:
            ui.note("click a vertex: your row beside the reference's")
            return
        with ui.table("check rows", ("term", "student", "reference")) as shown:
            if shown:
                for term, mine, ref in rows:
                    ui.row((term, mine, ref), RED if mine != ref else None)
