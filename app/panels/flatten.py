"""The Flatten panel: a map of the mesh to the plane seen three ways side by side (the
checkerboard through the map on the mesh, the flat layout coloured by its distortion, and a
copy of the mesh coloured the same), flipped triangles in a colour of their own, the
distortion's histograms, one table of every map computed, the clicked face's Jacobian and the
ellipse it maps a circle to. The disk's cut and a clicked seam are drawn on the mesh. State in
:mod:`..state.flatten`."""

from __future__ import annotations

import dataclasses
from collections.abc import Iterator
from typing import Any

import numpy as np
import polyscope as ps

from meshlap_core.options import FLATTEN_METHOD_BOUNDARIES

from .. import scene
from ..host import Host
from ..jobs import in_child
from ..panel_spec import PanelSpec
from ..scene import MESH, front_view, picked_vertex
from ..setting_widgets import setting_widget
from ..state.flatten import (
    DISTORTION_LABELS,
    MAP_NAMES,
    SETTINGS,
    FlattenState,
    MapView,
    Request,
    boundary_for,
    compute,
    face_of,
    place_row,
)
from .base import ExportItem, Panel

CHECKER = "checkerboard"
LAYOUT = "flat layout"
COPY = "distortion on the surface"
CUT = "cut"
OUTER = "outer boundary"
SEAM = "seam vertices"
FLIPPED = "flipped faces"
FLIPPED_LAYOUT = "flipped faces (layout)"
CIRCLE = "circle on the face"
ELLIPSE = "its ellipse in the layout"
STRUCTURES = (LAYOUT, COPY, CUT, OUTER, SEAM, FLIPPED, FLIPPED_LAYOUT, CIRCLE, ELLIPSE)
"""Every structure the panel registers (shown in its view only)."""

FLIP_COLOR = (1.0, 0.0, 0.85)
"""Flipped triangles: magenta, in none of the colour maps nor the checkerboard."""
FLIP_TEXT = (1.0, 0.55, 0.95, 1.0)
"""A map with flipped faces in the panel's text and table (a light magenta: readable on the
highlighted row too)."""
CHECKER_COLORS = ((0.97, 0.97, 0.97), (0.16, 0.40, 0.75))
CUT_COLOR = (1.0, 0.55, 0.0)
OUTER_COLOR = (0.1, 0.75, 0.3)
SEAM_COLOR = (0.9, 0.15, 0.15)
ELLIPSE_COLOR = (0.05, 0.05, 0.05)
CMAPS = {"angle": "viridis", "area": "coolwarm"}
STAGED_ABOVE = 100_000
"""In the window, a newly registered structure of more faces (or corners) than this ends the
frame's uploads: the next one follows at the next frame (polyscope makes a structure's
buffers at its first draw, on the UI thread: at 692k vertices the checkerboard, the layout and
the copy in one frame kept the window still for 12.6 s at load 11; one per frame, 6.5-6.7 s
each at load 9-10, the progress of the others shown between them)."""
LIFT = 2e-3
"""How far (a fraction of the mesh's size) the flipped faces are drawn in front of the faces
they cover, so that they are not hidden by them."""


class FlattenPanel(Panel):
    """Map, boundary, ARAP's run, checker size, distortion shown, seam; the table."""

    framed = (LAYOUT, COPY)
    shortcuts = (
        (
            "mouse",
            "flatten: click a face (on the mesh, the layout or the copy) for its Jacobian and "
            "ellipse; shift-click the mesh adds a seam vertex",
        ),
    )

    def __init__(self, spec: PanelSpec, state: FlattenState) -> None:
        super().__init__(spec, state)
        self.state: FlattenState = state
        self._job: tuple[Any, ...] | None = None  # what the running job computes
        self._layout: np.ndarray | None = None  # the layout's display positions (n',3)
        self._offset = np.zeros(3)  # the copy's offset from the mesh
        self._frame = (np.zeros(3), np.zeros((2, 3)))  # the layout: origin + uv01 @ axes
        self._stages: list[str] = []  # what is still to upload of the map shown
        self._due = False  # the map is brought up to date at the next sync (not before the
        # start options and the window's job settings apply: no map computed for nothing)

    # ------------------------------------------------------------------ the scene
    def animating(self) -> bool:
        """ARAP iterates live: the window keeps its full frame rate."""
        return self._job is not None and self._job[1][0] == "arap"

    def on_new_mesh(self, host: Host) -> None:
        host.state.jobs.cancel(self.name)
        self.state.clear()
        self.watch.forget()
        self._job, self._layout = None, None
        for name in STRUCTURES:
            scene.remove_structure(name)

    def show(self, host: Host, active: Panel) -> None:
        mine = active is self
        for name in STRUCTURES:
            for has, get in (
                (ps.has_surface_mesh, ps.get_surface_mesh),
                (ps.has_curve_network, ps.get_curve_network),
                (ps.has_point_cloud, ps.get_point_cloud),
            ):
                if has(name):
                    get(name).set_enabled(mine)
        if mine:
            self._due = True
            self.push(host, force=True)
        elif self.watch.seen("map") is not None:
            # (polyscope draws an enabled quantity's colour bar even on a hidden structure)
            if ps.has_surface_mesh(MESH):
                ps.get_surface_mesh(MESH).remove_quantity(CHECKER)
            for name in (LAYOUT, COPY):
                if ps.has_surface_mesh(name):
                    ps.get_surface_mesh(name).remove_all_quantities()
            self.watch.forget("map")

    def sync(self, host: Host) -> None:
        if self._job is not None and host.state.jobs.running(self.name) is None:
            self._job = None  # done, failed or cancelled
        if self._due and host.active() is self:
            self._due = False
            self.want(host)
        self.push(host)

    def points(self, host: Host, name: str) -> np.ndarray | None:
        if self.state.shown is None or host.active() is not self:
            return None
        if name == LAYOUT and self._layout is not None:
            return self._layout
        if name == COPY and self.state.copy:
            return host.mesh_points() + self._offset
        return None

    def captions(self, host: Host) -> dict[str, str]:
        view = self.state.shown
        if view is None:
            return {}
        m = view.uvmap
        flips = len(view.flipped)
        out = {
            MESH: f"checkerboard through {MAP_NAMES[m.method]}",
            LAYOUT: f"layout ({m.boundary})" + (f", {flips} flipped" if flips else ""),
        }
        if self.state.copy:
            out[COPY] = f"{self.state.distortion} distortion"
        return out

    def export_items(self, host: Host) -> list[ExportItem]:
        """What the view shows: the mesh (PLY; the checkerboard is its map), the layout as a
        flat mesh (PLY, ``z = 0``), the shown distortion per face (CSV: the layout's colours,
        and the copy's on the surface, which is the mesh's shape) and the map's ``uv`` per
        corner of the disk's faces (CSV)."""
        view = self.state.shown
        if view is None:
            return []
        m, kind = view.uvmap, self.state.distortion
        mesh = host.state.mesh
        stem = f"{mesh.stem}_{m.method}_{m.boundary}"
        flat = np.column_stack([view.uv01, np.zeros(len(view.uv01))])
        return [
            (f"{mesh.stem}.ply", mesh.V, mesh.F, None),
            (f"{stem}_layout.ply", flat, m.disk.F, None),
            (f"{stem}_{kind}_distortion.csv", None, None, view.values[kind]),
        ]

    # ------------------------------------------------------------------ jobs
    def want(self, host: Host, run: bool = False) -> None:
        """Bring what is shown to what the settings ask for: the map from the cache, or as a
        job (``run``: ARAP's next iterations even when it has a map); what is on screen stays
        meanwhile."""
        st, mesh = self.state, host.state.mesh
        if len(mesh.F) == 0:
            return
        disk = st.disk_wanted(mesh.version)
        if st.disk_key != disk:
            host.state.jobs.cancel(self.name)
            st.new_disk(disk)
        key = st.key
        if key in st.maps and not run:
            if st.shown is not st.maps[key]:
                st.shown = st.maps[key]
                st.version += 1
            return
        running = host.state.jobs.running(self.name) is not None
        if running and self._job == (disk, key) and not run:
            return  # under way
        if st.failed == (disk, key) and not run:
            return  # said in red; a change of the settings tries again
        self.start_map(host)

    def start_map(self, host: Host) -> None:
        """The map the settings ask for as a job: in a child process in the window (CHOLMOD's
        factorizations hold the GIL, 6 s measured on the 692k scan from a thread; and a
        thread waits for the GIL while the window draws: LSCM of the 2.6k bumpy sphere took
        1.1 s instead of 0.26 s), else with the disk's flattener reused;
        ARAP's maps shown live as they come (Cancel keeps the last one shown)."""
        st, mesh, jobs = self.state, host.state.mesh, host.state.jobs
        req = st.request(mesh.V, mesh.F, mesh.version)
        key = (req.method, req.boundary)
        disk = req.disk
        if jobs.processes and host.background:
            work = in_child(compute, req)
        else:
            flat, arap, lock = st.flattener, st.arap.get(req.boundary), st.lock
            work = lambda r: compute(req, flat, arap, lock, progress=r)  # noqa: E731

        def apply(result: Any) -> None:
            st.adopt(result, disk)
            self.push(host)

        def fail(message: str) -> None:
            host.state.errors[self.name] = message
            st.failed = (disk, key)

        title = f"flatten: {MAP_NAMES[req.method]} map" + (
            f", {req.iters} iterations" if req.method == "arap" else ""
        )
        self._job = (disk, key)
        jobs.start(
            self.name, title, work, apply, fail, background=host.background,
            preview=apply if req.method == "arap" else None,
        )  # fmt: skip

    def reset_arap(self, host: Host) -> None:
        """Forget ARAP's run on this boundary; it starts again from its start map."""
        st = self.state
        boundary = boundary_for("arap", st.boundary)
        if self.animating():
            host.state.jobs.cancel(self.name)
        st.arap.pop(boundary, None)
        st.maps.pop(("arap", boundary), None)
        st.version += 1
        self.want(host)

    # ------------------------------------------------------------------ picks
    def pick(self, host: Host, hit: Any, active: Panel) -> bool:
        st = self.state
        if active is not self or hit.structure_name not in (MESH, LAYOUT, COPY):
            return False
        mesh = host.state.mesh
        if hit.structure_name == MESH and hit.shift:  # a seam vertex
            v = picked_vertex(hit, host.mesh_points(), mesh.F)
            if v is None or not st.add_seam_vertex(len(mesh.V), v):
                return False
            self.seam_changed(host)
            return True
        view = st.shown
        if view is None:
            return False
        data = hit.structure_data
        kind, index = str(data.get("element_type", "")), int(data.get("index", -1))
        if hit.structure_name == LAYOUT and self._layout is not None:
            P, F = self._layout, view.uvmap.disk.F
        else:
            shift = self._offset if hit.structure_name == COPY else 0.0
            P, F = host.mesh_points() + shift, mesh.F
        if kind != "face" and not 0 <= index < len(P):
            kind = ""  # an edge or corner index: the face nearest the hit
        st.face = face_of(kind, index, np.asarray(hit.position), P, F)
        st.version += 1
        return True

    def seam_changed(self, host: Host) -> None:
        self.state.version += 1
        self.want(host)
        self.push(host)

    # ------------------------------------------------------------------ uploads
    def push(self, host: Host, force: bool = False) -> None:
        """Upload the cut, the seam, the checkerboard, the layout, the copy, the flipped
        faces and the clicked face's ellipse (each when it changed)."""
        if host.active() is not self or not ps.has_surface_mesh(MESH):
            return
        st = self.state
        P = host.mesh_points()
        disk = st.shown.uvmap.disk if st.shown is not None else None
        if self.watch.changed("cut", id(disk), id(P), tuple(st.seam)) or force:
            self._push_cut(host, P)
        view = st.shown
        key = (st.version, id(view), id(P), st.distortion, st.copy, st.checker)
        if self.watch.changed("map", *key) or force:
            self._stages = ["checker", "layout", "copy", "marks"]
        if view is None:
            ps.get_surface_mesh(MESH).remove_quantity(CHECKER)
            for name in (LAYOUT, COPY, FLIPPED, FLIPPED_LAYOUT, CIRCLE, ELLIPSE):
                scene.remove_structure(name)
            self._layout, self._stages = None, []
            return
        stage = {
            "checker": self._push_checker, "layout": self._push_layout,
            "copy": self._push_copy, "marks": self._push_marks,
        }  # fmt: skip
        while self._stages:
            registered = stage[self._stages.pop(0)](host, P, view)
            if registered and host.background:
                break  # one new big structure per frame: its first draw is the frame's

    def _push_checker(self, host: Host, P: np.ndarray, view: MapView) -> bool:
        """The checkerboard through the map on the mesh (a new one: True)."""
        new = self.watch.changed("checker map", id(view.corners))
        ps.get_surface_mesh(MESH).add_parameterization_quantity(
            CHECKER, view.corners, defined_on="corners", coords_type="unit",
            viz_style="checker", checker_size=self.state.checker,
            checker_colors=CHECKER_COLORS, enabled=True,
        )  # fmt: skip
        return new and len(view.corners) > STAGED_ABOVE

    def _push_marks(self, host: Host, P: np.ndarray, view: MapView) -> bool:
        """The flipped faces and the clicked face's ellipse."""
        self._push_flipped(host, P, view)
        self._push_face(host, view)
        return False

    def _push_cut(self, host: Host, P: np.ndarray) -> None:
        """The disk's cut edges and, with holes, its outer loop on the mesh; the clicked seam
        vertices."""
        st = self.state
        for name in (CUT, OUTER, SEAM):
            scene.remove_structure(name)
        disk = st.shown.uvmap.disk if st.shown is not None else None
        if disk is not None and len(disk.cut_edges):
            nodes, edges = np.unique(disk.cut_edges, return_inverse=True)  # its vertices only
            cn = ps.register_curve_network(CUT, P[nodes], edges.reshape(-1, 2), color=CUT_COLOR)
            cn.set_radius(0.003, relative=True)
        if disk is not None and disk.holes:
            loop = disk.source[disk.outer]
            cn = ps.register_curve_network(OUTER, P[loop], "loop", color=OUTER_COLOR)
            cn.set_radius(0.003, relative=True)
        if st.seam:
            pc = ps.register_point_cloud(SEAM, P[np.asarray(st.seam)], color=SEAM_COLOR)
            pc.set_radius(0.008, relative=True)

    def _push_layout(self, host: Host, P: np.ndarray, view: MapView) -> bool:
        """The layout beside the mesh, coloured by the distortion shown, with the colour bar
        (registered anew: True)."""
        st, disk = self.state, view.uvmap.disk
        origin, axes, self._offset = place_row(P, front_view(host.state.mesh.name))
        self._frame = (origin, axes)
        layout = self._layout = origin + view.uv01 @ axes
        new = self.watch.changed("layout faces", id(disk)) or not ps.has_surface_mesh(LAYOUT)
        if new:
            scene.remove_structure(LAYOUT)
            shown = host.active() is self  # (polyscope keeps a removed name's enabled flag)
            ps.register_surface_mesh(LAYOUT, layout, disk.F, edge_width=0.0, enabled=shown)
            host.request_frame()
        else:
            ps.get_surface_mesh(LAYOUT).update_vertex_positions(layout)
        kind = st.distortion
        ps.get_surface_mesh(LAYOUT).add_scalar_quantity(
            DISTORTION_LABELS[kind], view.values[kind], defined_on="faces", cmap=CMAPS[kind],
            vminmax=view.ranges[kind], enabled=True, onscreen_colorbar_enabled=True,
            onscreen_colorbar_location=scene.colorbar_at(0, host.state.ui_scale),
        )  # fmt: skip
        return new and len(disk.F) > STAGED_ABOVE

    def _push_copy(self, host: Host, P: np.ndarray, view: MapView) -> bool:
        """The copy of the mesh right of the layout, in the layout's colours (the layout's
        colour bar reads both: the copy's are those colours as RGB, no second bar; registered
        anew: True)."""
        if not self.state.copy:
            scene.remove_structure(COPY)
            return False
        X = P + self._offset
        new = self.watch.changed("copy", id(P)) or not ps.has_surface_mesh(COPY)
        if new:
            scene.remove_structure(COPY)
            scene.register_surface(COPY, X, host.state.mesh.F, host.active() is self)
            host.request_frame()
        elif self.watch.changed("copy offset", *self._offset.tolist()):
            ps.get_surface_mesh(COPY).update_vertex_positions(X)
        kind = self.state.distortion
        rgb = self.watch.cached("copy colours", (id(view), kind), lambda: _colours(view, kind))
        ps.get_surface_mesh(COPY).add_color_quantity(
            DISTORTION_LABELS[kind].split(" [")[0], rgb, defined_on="faces", enabled=True
        )
        return new and len(host.state.mesh.F) > STAGED_ABOVE

    def _push_flipped(self, host: Host, P: np.ndarray, view: MapView) -> None:
        """The flipped faces in :data:`FLIP_COLOR`, over the mesh and over the layout (each
        face its own three corners, lifted towards the viewer)."""
        for name in (FLIPPED, FLIPPED_LAYOUT):
            scene.remove_structure(name)
        flipped = view.flipped
        if not len(flipped) or self._layout is None:
            return
        size = float(np.linalg.norm(P.max(axis=0) - P.min(axis=0)))
        tris = np.arange(3 * len(flipped)).reshape(-1, 3)
        F = host.state.mesh.F[flipped]
        A = P[F]
        n = np.cross(A[:, 1] - A[:, 0], A[:, 2] - A[:, 0])
        n /= np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-300)
        on_mesh = (A + LIFT * size * n[:, None, :]).reshape(-1, 3)
        toward = np.asarray(front_view(host.state.mesh.name), dtype=np.float64)
        toward /= np.linalg.norm(toward)
        on_layout = self._layout[view.uvmap.disk.F[flipped]].reshape(-1, 3) + LIFT * size * toward
        for name, X in ((FLIPPED, on_mesh), (FLIPPED_LAYOUT, on_layout)):
            sm = ps.register_surface_mesh(name, X, tris, color=FLIP_COLOR, edge_width=0.0)
            sm.set_back_face_policy("identical")

    def _push_face(self, host: Host, view: MapView) -> None:
        """The clicked face's circle on the surface and the ellipse it maps to in the
        layout, each with the face's outline."""
        for name in (CIRCLE, ELLIPSE):
            scene.remove_structure(name)
        found = self.state.ellipse()
        if found is None or self._layout is None:
            return
        e, circle, image = found
        d = host.state.display
        tri_3d = d.points(view.uvmap.disk.V[view.uvmap.disk.F[e.face]])
        ring = np.vstack([d.points(circle), tri_3d])
        origin, axes = self._frame
        tri_uv = view.uv01[view.uvmap.disk.F[e.face]]
        flat = origin + np.vstack([image, tri_uv]) @ axes
        k = len(circle)
        edges = np.array(
            [(i, (i + 1) % k) for i in range(k)] + [(k + i, k + (i + 1) % 3) for i in range(3)]
        )
        for name, X in ((CIRCLE, ring), (ELLIPSE, flat)):
            cn = ps.register_curve_network(name, X, edges, color=ELLIPSE_COLOR)
            cn.set_radius(0.002, relative=True)

    # ------------------------------------------------------------------ sessions, start
    def configure(self, host: Host, values: dict[str, Any]) -> None:
        st = self.state
        for s in self.spec.settings:
            setattr(st, s.key, values[s.key])
        st.seam = list(values["seam"])
        st.version += 1

    def restore(self, host: Host, values: dict[str, Any], active: bool) -> None:
        self.configure(host, values)
        self._due = active

    def start(self, host: Host, options: dict[str, Any], shown: bool, screenshot: bool) -> None:
        """``meshlap view --panel flatten --map M --map-boundary B --checker X --distortion
        D``: the map is computed at the first frame when this is the first view."""
        st = self.state
        for flag, key in (("map", "method"), ("map_boundary", "boundary"), ("checker", "checker"),
                          ("distortion", "distortion")):  # fmt: skip
            if options.get(flag) is not None:
                setattr(st, key, options[flag])
        self._due = shown

    # ------------------------------------------------------------------ widgets
    def draw(self, host: Host) -> None:
        ui = host.ui
        if not ui.header(self.title):
            return
        st = self.state
        host.draw_job(self.name)
        self._draw_disk(host)
        ch, method = setting_widget(ui, SETTINGS["method"], st.method)
        if ch:
            st.set_choice("method", method)
            self.want(host)
        allowed = FLATTEN_METHOD_BOUNDARIES[st.method]
        if len(allowed) > 1:
            b = SETTINGS["boundary"]
            ch, boundary = ui.combo(
                b.label, boundary_for(st.method, st.boundary), allowed, b.tooltip
            )
            if ch:
                st.set_choice("boundary", boundary)
                self.want(host)
        else:
            ui.text(f"boundary: {allowed[0]} (the map's own)")
        if st.method == "arap":
            self._draw_arap(host)
        ch, x = setting_widget(ui, SETTINGS["checker"], st.checker)
        if ch:
            st.set_checker(x)
        ch, kind = setting_widget(ui, SETTINGS["distortion"], st.distortion)
        if ch:
            st.set_choice("distortion", kind)
        ch, st.copy = setting_widget(ui, SETTINGS["copy"], st.copy)
        if ch:
            st.version += 1
            host.request_frame()
        self._draw_map(host)

    def _draw_disk(self, host: Host) -> None:
        """What was cut to make the disk, and the seam's buttons."""
        ui, st = host.ui, self.state
        if st.shown is not None:
            d = st.shown.uvmap.disk
            loops = 1 + len(d.holes)
            opened = "" if d.how == "disk" else f" ({d.how})"
            ui.text(
                f"disk{opened}: {len(d.V)} vertices, {len(d.F)} faces, {loops} boundary "
                + ("loop" if loops == 1 else "loops")
            )
            for line in d.messages:
                ui.text_whole_words(line)
        ui.text(
            f"seam: {len(st.seam)} clicked vertices" if st.seam
            else "seam: none (shift-click the mesh to cut along a path)"
        )  # fmt: skip
        if ui.button("undo seam vertex", "forget the last vertex clicked for the seam"):
            if st.undo_seam():
                self.seam_changed(host)
        ui.same_line()
        if ui.button("clear seam", "forget the seam: the disk is cut automatically"):
            st.seam = []
            self.seam_changed(host)

    def _draw_arap(self, host: Host) -> None:
        """ARAP's iterations: run more, start again, the energy per iteration and the rate."""
        ui, st = host.ui, self.state
        ch, n = setting_widget(ui, SETTINGS["iters"], st.iters)
        if ch:
            st.set_iters(n)
        if ui.button("run ARAP", f"{st.iters} more local/global iterations, shown live"):
            self.want(host, run=True)
        ui.same_line()
        if ui.button("restart ARAP", "forget the iterations: start again from the start map"):
            self.reset_arap(host)
        view = st.shown
        if view is None or view.uvmap.method != "arap":
            return
        energies = np.asarray(view.uvmap.energies)
        live = "live" if self.animating() else "last run"
        ui.text(
            f"iteration {view.uvmap.iterations}: E = {energies[-1]:.6g}; "
            f"{st.live_rate:.1f} iterations/s ({live})"
        )
        with ui.plot("ARAP energy", 120, "iteration", "E", y_log=bool(energies.min() > 0)) as ok:
            if ok:
                ui.plot_line("##E", np.arange(len(energies)), energies)

    def _draw_map(self, host: Host) -> None:
        """The shown map's flips, the clicked face, the table and the histograms."""
        ui, st = host.ui, self.state
        view = st.shown
        if view is None:
            ui.note("computing the map ..." if self._job is not None else "no map yet")
            return
        flips = len(view.flipped)
        if flips:
            ui.colored(f"{flips} flipped faces (magenta)", FLIP_TEXT)
        else:
            ui.text("no face flipped")
        self._draw_face(host, view)
        heads = ("map", "flips", "s", "angle", "max", "area", "max")
        tips = ("the map and its boundary (ARAP: its iterations)",
                "faces whose orientation the map reverses", "the map's own time, seconds",
                "area-weighted mean of sigma1/sigma2 (1: conformal)", "largest sigma1/sigma2",
                "area-weighted mean of |log sigma1 sigma2| (0: areas kept)",
                "largest |log sigma1 sigma2|")  # fmt: skip
        numbers = ("angle_mean", "angle_max", "area_mean", "area_max")
        with ui.table("flatten maps", heads, tips):
            for row in st.rows():
                name = f"{MAP_NAMES[row['method']]}, {row['boundary']}"
                if row["method"] == "arap":
                    name += f", {row['iterations']} it"
                cells = [name, str(row["flipped"]), f"{row['seconds']:.2g}",
                         *(f"{row[k]:.3g}" for k in numbers)]  # fmt: skip
                mine = (row["method"], row["boundary"]) == view.key
                ui.row(cells, FLIP_TEXT if row["flipped"] else None, highlight=mine)
        for kind in ("angle", "area"):
            centers, counts, width = view.histograms[kind]
            label = DISTORTION_LABELS[kind]
            with ui.plot(f"{kind} distortion histogram", 140, label, "faces") as ok:
                if ok:
                    colors = self.watch.cached(
                        f"{kind} bars", (id(view),), lambda c=centers, k=kind: _bars(view, k, c)
                    )
                    ui.plot_bars(f"##{kind} faces", centers, counts, width, colors)

    def _draw_face(self, host: Host, view: MapView) -> None:
        ui, st = host.ui, self.state
        found = st.ellipse()
        if found is None:
            ui.text("click a face (mesh, layout or copy): its Jacobian and ellipse")
            return
        e = found[0]
        J = e.jacobian
        ui.text_whole_words(
            f"face {e.face}: sigma1 = {e.sigma1:.4g}, sigma2 = {e.sigma2:.4g}, "
            f"sigma1/sigma2 = {e.sigma1 / max(e.sigma2, 1e-300):.4g}, "
            f"log sigma1 sigma2 = {np.log(max(e.sigma1 * e.sigma2, 1e-300)):.4g}"
            + (" (flipped)" if e.flipped else "")
        )
        ui.text_whole_words(
            f"J = [[{J[0, 0]:.4g}, {J[0, 1]:.4g}], [{J[1, 0]:.4g}, {J[1, 1]:.4g}]] (face frame "
            "to the layout, area normalized): a circle on the face maps to the black ellipse"
        )
        if ui.button("clear face", "forget the clicked face"):
            st.face = -1
            st.version += 1

    # ------------------------------------------------------------------ meshlap animate
    def frames(self, host: Host, options: dict[str, Any]) -> Iterator[str]:
        """ARAP's iterations 0..``--arap-iters`` from its start map on ``--map-boundary``,
        the checkerboard on the mesh and the layout (coloured by the distortion) beside it."""
        st, mesh = self.state, host.state.mesh
        boundary = boundary_for("arap", options["map_boundary"])
        st.method, st.boundary, st.checker = "arap", boundary, float(options["checker"])
        disk = st.disk_wanted(mesh.version)
        if st.disk_key != disk:
            st.new_disk(disk)
        st.arap.pop(boundary, None)
        st.maps.pop(st.key, None)
        req = Request(mesh.V, mesh.F, disk, "arap", boundary, iters=0)
        flat, arap, view, rate = compute(req, st.flattener, None, st.lock)
        st.adopt((flat, arap, view, rate), disk)
        host.refresh()
        self.push(host, force=True)
        host.frame(scene.COLORBAR_STRIP)
        for it in range(int(options["arap_iters"]) + 1):
            if it:
                st.adopt(compute(dataclasses.replace(req, iters=1), flat, arap, st.lock), disk)
                self.push(host)
            view = st.shown
            assert view is not None
            yield (
                f"ARAP ({boundary} boundary), iteration {it}: E = {arap.energy:.4g}, "
                f"{len(view.flipped)} flipped"
            )


def _bars(view: MapView, kind: str, centers: np.ndarray) -> np.ndarray:
    """Each histogram bar ``(k,4)`` in the colour its value has on the layout."""
    from matplotlib import colormaps

    lo, hi = view.ranges[kind]
    t = np.clip((np.asarray(centers) - lo) / (hi - lo), 0.0, 1.0)
    return colormaps[CMAPS[kind]](t)


def _colours(view: MapView, kind: str) -> np.ndarray:
    """Each face's RGB ``(m,3)`` in the colour its distortion has on the layout (the same
    colour map and range, clipped the same)."""
    return _bars(view, kind, view.values[kind])[:, :3]
