"""The Deform panel: click vertices to make handles (geodesic discs), hold a region, drag a
handle with polyscope's transformation gizmo (translate and rotate) or with the mouse in the
screen plane, and watch Laplacian coordinates, k-harmonic displacement and ARAP follow, two
methods side by side with one colour map. State in :mod:`..state.deform`.

The handle set's precomputation (discs, fixed region, each method's factorization) is a job
(progress and Cancel; the last deformation stays on screen); each move is then one
back-substitution, or ARAP iterations running frame after frame until they converge. On a mesh
above :data:`~..state.deform.INLINE_SOLVE_MAX` vertices each solve is a job too.
"""

from __future__ import annotations

import math
import time
from collections.abc import Iterator
from typing import Any

import numpy as np
import polyscope as ps

from .. import scene
from ..deformer_process import build_remote
from ..handle_mouse import HandleMouse
from ..host import Host
from ..ipc import NoChildProcess
from ..panel_spec import PanelSpec
from ..rigid_drag import (
    Gizmo,
    display_frame,
    gizmo_of,
    move_of_gizmo,
    view_axis,
)
from ..scene import front_view, side_offset
from ..setting_widgets import setting_widget
from ..state.deform import ARAP_TOLERANCE, INLINE_SOLVE_MAX, QUANTITY, SETTINGS, DeformState
from ..state.handle_sets import build_set
from ..state.moves import diagonal, move_matrix, move_of
from ..text_numbers import plural
from .base import ExportItem, Panel

DEFORMED = "deformed"
COMPARED = "deformed (second method)"
HANDLES = "deform handles"
HELD = "deform fixed region"
GIZMO = "deform gizmo"
HANDLE_COLOR = (0.9, 0.15, 0.1)
ACTIVE_COLOR = (1.0, 0.75, 0.0)
HELD_COLOR = (0.25, 0.3, 0.8)
DEFORMED_COLOR = (0.82, 0.78, 0.7)
SLOW_FIELD_EVERY = 0.5
"""Seconds between two rotation-error maps while the shape moves (each costs an SVD per
vertex); the map of the shape at rest is always computed."""


class DeformPanel(HandleMouse, Panel):
    """Handles, fixed region, moves; the methods side by side with their numbers."""

    shows_mesh = False  # the deformed copy replaces it
    framed = (DEFORMED, COMPARED)
    keys = ("z", "y", "r")
    shortcuts = (
        (
            "mouse",
            "deform: click a vertex for a handle, shift-click adds one, ctrl-click holds a "
            "disc; drag a handle (or its gizmo) to move it",
        ),
        ("Z / Y", "deform: undo / redo a handle move"),
        ("R", "deform: every handle back at rest"),
    )

    copies = (DEFORMED, COMPARED)
    dots = (HANDLES, HELD)

    def __init__(self, spec: PanelSpec, state: DeformState) -> None:
        super().__init__(spec, state)
        self.state: DeformState = state
        self._building: Any = None  # the setup key of the build job under way
        self._press: tuple[int, frozenset[str], tuple[float, float]] | None = None
        self._drag: dict[str, Any] | None = None  # a handle dragged in the screen plane
        self.gizmo = Gizmo(GIZMO)  # at the active handle: (index, its move) as its key
        self._gesture = False  # a gizmo gesture under way (one undo step)
        self._kept_fields: Any = None  # (what, when, values) of the last colour map

    # ------------------------------------------------------------------ the scene
    def animating(self) -> bool:
        """ARAP iterating, a drag, or solves to show: the window keeps its full rate."""
        return bool(self.state.due()) or self._drag is not None

    def on_new_mesh(self, host: Host) -> None:
        host.state.jobs.cancel(self.name)
        self.state.clear()
        self.watch.forget()
        self._building, self._press, self._drag = None, None, None
        self._end_drag()
        for name in (DEFORMED, COMPARED, HANDLES, HELD):
            scene.remove_structure(name)
        self.gizmo.remove()

    def show(self, host: Host, active: Panel) -> None:
        mine = active is self
        for name in (DEFORMED, COMPARED):
            if ps.has_surface_mesh(name):
                ps.get_surface_mesh(name).set_enabled(mine)
        for name in (HANDLES, HELD):
            if ps.has_point_cloud(name):
                ps.get_point_cloud(name).set_enabled(mine)
        if not mine:
            self.gizmo.remove()
            self._end_drag()
            # (polyscope draws an enabled quantity's colour bar even on a hidden structure:
            # the displacement's bar stayed over the next view)
            for name in (DEFORMED, COMPARED):
                if ps.has_surface_mesh(name):
                    ps.get_surface_mesh(name).remove_all_quantities()
            return
        self.push(host, force=True)

    def _mesh_ok(self, host: Host) -> bool:
        mesh = host.state.mesh
        return len(mesh.V) > 0 and len(mesh.F) > 0

    # ------------------------------------------------------------------ builds and solves
    def sync(self, host: Host) -> None:
        """Every frame, the view active: build the handle set when it changed (a job), solve
        the moves, upload what changed."""
        if host.active() is not self or not self._mesh_ok(host):
            return
        st, mesh = self.state, host.state.mesh
        if st.handles and not st.ready(mesh.version):
            self.build(host)
        elif not st.handles and st.built is not None:
            st.drop()
        if st.built is not None and st.ready(mesh.version):
            self.solve(host)
        self.push(host)

    def build(self, host: Host) -> None:
        """Build the handle set the settings describe, as a job (the deformation on screen
        stays until it is done); not restarted while the same build runs."""
        st, mesh, jobs = self.state, host.state.mesh, host.state.jobs
        key = st.setup_key(mesh.version)
        if self._building == key:
            return  # under way, or it failed (said in red) or was cancelled: not again
        V, F, graph = mesh.V, mesh.F, st.graph_for(mesh.version)
        self._building = key
        st.error = ""

        def apply(built: Any) -> None:  # (the camera stays: the user just clicked there)
            st.adopt(built)
            self.push(host, force=True)

        def fail(message: str) -> None:
            st.error = message

        n = len(st.methods)
        jobs.start(
            self.name,
            f"deformation set-up ({plural(len(st.handles), 'handle')}, {plural(n, 'method')})",
            self._builder(host, V, F, key, graph),
            apply,
            fail,
            background=host.background,
        )

    def _builder(self, host: Host, V: Any, F: Any, key: Any, graph: Any) -> Any:
        """The build job's work: above :data:`INLINE_SOLVE_MAX` vertices in the window, in a
        child process that keeps the deformers (CHOLMOD holds the GIL: a thread would freeze
        the window); else in the job's thread."""

        def here(reporter: Any) -> Any:
            return build_set(V, F, key, graph, reporter, reporter.cancel)

        if not (host.background and host.state.jobs.processes and len(V) > INLINE_SOLVE_MAX):
            return here

        def there(reporter: Any) -> Any:
            try:
                return build_remote(V, F, key, reporter)
            except NoChildProcess:
                return here(reporter)

        return there

    def solve(self, host: Host) -> None:
        """Bring each shown method up to the moves: here on a small mesh (one
        back-substitution, or this frame's ARAP iterations), else as a job (one at a time; the
        next follows the moves of its time)."""
        st, jobs = self.state, host.state.jobs
        due = st.due()
        if not due:
            return
        if len(host.state.mesh.V) <= INLINE_SOLVE_MAX or not host.background:
            for m in due:
                st.solve(m)
            return
        if jobs.running(self.name) is not None:
            return
        m = due[0]
        b = st.built
        assert b is not None
        d, targets, moved, colour = b.deformers[m], st.targets(m), st.moved, st.colour
        iters = st.iterations_for(m)
        if iters == 0:
            st.solve(m)  # (nothing to compute: marked converged)
            return

        def apply(result: Any) -> None:
            if st.built is b:
                st.adopt_solve(m, moved, *result)

        jobs.start(
            self.name,
            f"{m}: solving the move",
            lambda reporter: st.solve_work(d, targets, iters, ARAP_TOLERANCE, colour),
            apply,
            lambda message: setattr(st, "error", message),
            replace=False,
            background=True,
        )

    # ------------------------------------------------------------------ uploads
    def _offset(self, host: Host) -> np.ndarray:
        mesh = host.state.mesh
        return self.watch.cached(
            "offset",
            (mesh.version, host.state.display.scale),
            lambda: side_offset(host.mesh_points(), front_view(mesh.name)),
        )

    def _positions(self, host: Host, method: str) -> np.ndarray:
        """Display positions of ``method``'s copy (the rest pose before any build)."""
        st = self.state
        shown = st.shown.get(method)
        P = host.mesh_points() if shown is None else host.state.display.points(shown.positions)
        if len(st.methods) > 1 and method == st.methods[1]:
            P = P + self._offset(host)
        return P

    def push(self, host: Host, force: bool = False) -> None:
        """Upload the deformed copies, their colour map and the handle / fixed points."""
        if host.active() is not self or not self._mesh_ok(host):
            return
        st, mesh = self.state, host.state.mesh
        key = (st.version, st.colour, st.methods, mesh.version, st.active)
        if not self.watch.changed("pushed", *key) and not force:
            return
        names = dict(zip(st.methods, (DEFORMED, COMPARED), strict=False))
        if len(st.methods) < 2:
            scene.remove_structure(COMPARED)
        fields = self._fields(st, names)
        # one range for both copies, never below a thousandth of the diagonal (or of a unit
        # rotation error): the rest pose is one colour, not round-off stretched over the map
        floor = 1e-3 * (diagonal(mesh.V) if st.colour == "displacement" else 1.0)
        top = max([float(np.max(f)) for f in fields.values() if f is not None and len(f)] + [floor])
        for m, name in names.items():
            P = self._positions(host, m)
            if ps.has_surface_mesh(name) and ps.get_surface_mesh(name).n_vertices() == len(P):
                sm = ps.get_surface_mesh(name)
                sm.update_vertex_positions(P)
            else:
                scene.remove_structure(name)
                sm = scene.register_surface(name, P, mesh.F, host.active() is self)
                sm.set_color(DEFORMED_COLOR)
                host.request_frame()
            f = fields[m]
            if f is None:
                sm.remove_all_quantities()
            else:
                sm.add_scalar_quantity(
                    QUANTITY[st.colour],
                    np.nan_to_num(f),
                    cmap="viridis" if st.colour == "displacement" else "reds",
                    vminmax=(0.0, top),
                    enabled=True,
                    onscreen_colorbar_enabled=name == DEFORMED,
                    onscreen_colorbar_location=scene.COLORBAR_AT,
                )
        self._push_points(host)

    def _fields(self, st: DeformState, names: dict[str, str]) -> dict[str, Any]:
        """The colour map's values per copy. The rotation error (an SVD per vertex: 0.1-0.3 s
        at 43k vertices) is refreshed at most every :data:`SLOW_FIELD_EVERY` seconds while a
        drag or ARAP's iterations go on, and once they stop."""
        now = time.perf_counter()
        slow = st.colour == "rotation error" and self.animating()
        kept = self._kept_fields
        if slow and kept is not None and kept[0] == (st.colour, tuple(names)):
            if now - kept[1] < SLOW_FIELD_EVERY:
                return kept[2]
        fields = {m: st.field(m) for m in names}
        self._kept_fields = ((st.colour, tuple(names)), now, fields)
        return fields

    def _push_points(self, host: Host) -> None:
        st = self.state
        b = st.built
        if b is None or not len(b.regions.vertices):
            for name in (HANDLES, HELD):
                scene.remove_structure(name)
            return
        P = self._positions(host, st.methods[0])
        # registered (and coloured) once per handle set and active handle; later pushes only
        # move the points (a disc on a big scan holds thousands)
        fresh = self.watch.changed("points", id(b), st.active, len(st.methods))
        for name, rows, rgb, size in ((HANDLES, b.regions.vertices, HANDLE_COLOR, 0.004),
                                      (HELD, b.fixed, HELD_COLOR, 0.0024)):  # fmt: skip
            if not len(rows):
                scene.remove_structure(name)
            elif fresh or not ps.has_point_cloud(name):
                ps.register_point_cloud(name, P[rows], color=rgb).set_radius(size, relative=True)
            else:
                ps.get_point_cloud(name).update_point_positions(P[rows])
        if fresh:
            active = np.zeros(len(b.regions.vertices), dtype=bool)
            if 0 <= st.active < len(st.handles) and st.handles[st.active] in b.regions.seeds:
                active[
                    b.regions.region == np.searchsorted(b.regions.seeds, st.handles[st.active])
                ] = True
            colours = np.where(active[:, None], ACTIVE_COLOR, HANDLE_COLOR)
            ps.get_point_cloud(HANDLES).add_color_quantity("handle", colours, enabled=True)

    def points(self, host: Host, name: str) -> np.ndarray | None:
        st = self.state
        if name == DEFORMED:
            return self._positions(host, st.methods[0])
        if name == COMPARED and len(st.methods) > 1:
            return self._positions(host, st.methods[1])
        return None

    def captions(self, host: Host) -> dict[str, str]:
        st = self.state
        if len(st.methods) < 2:
            return {}
        return {DEFORMED: st.methods[0], COMPARED: st.methods[1]}

    def export_items(self, host: Host) -> list[ExportItem]:
        """Each deformed copy (PLY) with the colour map's values."""
        st, stem = self.state, host.state.mesh.stem
        return [
            (f"{stem}_deform_{m}.ply", np.array(s.positions), host.state.mesh.F, st.field(m))
            for m, s in st.shown.items()
        ]

    # ------------------------------------------------------------------ the gizmo
    def _centroid(self, index: int) -> np.ndarray | None:
        """The rest centroid (mesh coordinates) of handle ``index``'s disc."""
        b, st = self.state.built, self.state
        if b is None or not 0 <= index < len(st.handles):
            return None
        hits = np.flatnonzero(b.regions.seeds == st.handles[index])
        if not len(hits):
            return None
        V = next(iter(b.deformers.values())).V
        return V[b.regions.vertices[b.regions.region == hits[0]]].mean(axis=0)

    def sync_gizmo(self, host: Host, held: bool) -> None:
        """Read the gizmo (a drag of it moves the active handle: one undo step per gesture)
        and put it where the active handle's move says (after undo, a drag, the turn)."""
        st, g, i = self.state, self.gizmo, self.state.active
        c = self._centroid(i)
        if c is None:
            g.remove()
            return
        T = g.moved() if g.key is not None and g.key[0] == i else None
        if T is not None and (rigid := move_of_gizmo(host.state.display, c, T)) is not None:
            if not self._gesture:
                st.checkpoint()
                self._gesture = True
            st.set_move(i, move_of(*rigid))
            g.key = (i, st.moves[i])
        if not held:
            self._gesture = False
        if g.key != (i, st.moves[i]):
            g.place(gizmo_of(host.state.display, c, *move_matrix(st.moves[i])), (i, st.moves[i]))

    # ------------------------------------------------------------------ keys
    def on_key(self, host: Host, key: str) -> bool:
        st = self.state
        if key == "z":
            st.undo()
        elif key == "y":
            st.redo()
        elif key == "r":
            st.reset_moves()
        else:
            return False
        return True

    # ------------------------------------------------------------------ sessions, start
    def configure(self, host: Host, values: dict[str, Any]) -> None:
        super().configure(host, values)
        self._building = None
        st = self.state
        st.active = len(st.handles) - 1
        st.undo_stack, st.redo_stack = [], []
        st.drop()
        st.moved += 1

    def restore(self, host: Host, values: dict[str, Any], active: bool) -> None:
        self.configure(host, values)
        if active and st_has(self.state):
            self.build(host)

    def start(self, host: Host, options: dict[str, Any], shown: bool, screenshot: bool) -> None:
        """``--deform-method``, ``--deform-compare``, ``--handle-radius``; shown first with
        ``--vertex``: that vertex is the handle. A headless picture with no handle: the top
        vertex lifted and turned (ARAP iterated to convergence)."""
        st = self.state
        for key, dest in (("method", "deform_method"), ("compare", "deform_compare")):
            if options.get(dest) is not None:
                setattr(st, key, options[dest])
        if options.get("handle_radius") is not None:
            st.radius = float(options["handle_radius"])
        if not shown:
            return
        mesh = host.state.mesh
        if options.get("vertex") is not None:
            st.select(len(mesh.V), int(options["vertex"]))
        elif screenshot and not st.handles:
            st.select(len(mesh.V), top_vertex(host))
            st.set_move(0, demo_move(host))
        if screenshot and st.handles:
            self.settle(host)

    def settle(self, host: Host, most: int = 2000) -> None:
        """Build and solve right here until nothing is due (a headless picture, a test)."""
        self.build(host)
        for _ in range(most):
            if not self.state.due():
                break
            self.solve(host)
        self.push(host, force=True)
        host.refresh()

    # ------------------------------------------------------------------ widgets
    def draw(self, host: Host) -> None:
        ui = host.ui
        if not ui.header(self.title):
            return
        st = self.state
        host.draw_job(self.name)
        held = self.handle_mouse(host)
        self.sync_gizmo(host, held)
        for key in ("method", "compare"):
            ch, value = setting_widget(ui, SETTINGS[key], getattr(st, key))
            if ch:
                setattr(st, key, SETTINGS[key].checked(value, SETTINGS[key].label))
        ch, r = setting_widget(ui, SETTINGS["radius"], st.radius)
        if ch:
            st.radius = SETTINGS["radius"].checked(SETTINGS["radius"].clamp(r), "handle radius %")
        ch, region = setting_widget(ui, SETTINGS["fixed_region"], st.fixed_region)
        if ch:
            st.fixed_region = SETTINGS["fixed_region"].checked(region, "fixed region")
        if st.fixed_region == "farthest":
            ch, share = setting_widget(ui, SETTINGS["fixed_fraction"], st.fixed_fraction)
            if ch:
                s = SETTINGS["fixed_fraction"]
                st.fixed_fraction = s.checked(min(max(share, 0.01), s.hi), s.label)
        elif st.fixed_region == "clicked" and not st.fixed:
            ui.note("ctrl-click a vertex to hold a disc around it")
        if "arap" in st.methods:
            self.draw_arap_settings(host)
        ch, colour = setting_widget(ui, SETTINGS["colour"], st.colour)
        if ch:
            st.colour = SETTINGS["colour"].checked(colour, "colour")
            if getattr(st.built, "remote", False):  # the child computes the map with a solve
                st.solved = {m: -1 for m in st.solved}
        self.draw_handles(host)
        if st.error:
            ui.error(st.error)
        mesh = host.state.mesh
        idle = host.state.jobs.running(self.name) is None
        if st.handles and idle and not st.ready(mesh.version) and not st.error:
            ui.note("set-up cancelled: change a setting (or click a handle) to build again")
        self.draw_numbers(host)

    def draw_arap_settings(self, host: Host) -> None:
        ui, st = host.ui, self.state
        ch, energy = setting_widget(ui, SETTINGS["arap_energy"], st.arap_energy)
        if ch:
            st.arap_energy = SETTINGS["arap_energy"].checked(energy, "ARAP energy")
        ch, per = setting_widget(ui, SETTINGS["arap_per_frame"], st.arap_per_frame)
        if ch:
            st.arap_per_frame = SETTINGS["arap_per_frame"].clamp(per)
        ch, most = setting_widget(ui, SETTINGS["arap_max"], st.arap_max)
        if ch:
            s = SETTINGS["arap_max"]
            st.arap_max = s.checked(most, s.label)
            st.converged = {m: False for m in st.converged}

    def draw_handles(self, host: Host) -> None:
        """The seeds, the active handle's turn, undo / redo / reset / clear."""
        ui, st = host.ui, self.state
        if not st.handles:
            ui.note("click a vertex to make it a handle (shift-click: one more)")
        else:
            held = (
                f"; fixed: {', '.join(map(str, st.fixed))}" if st.fixed_region == "clicked" else ""
            )
            ui.text(f"handles at {', '.join(map(str, st.handles))}{held}")
        i = st.active
        if 0 <= i < len(st.handles):
            deg = st.moves[i]["rotate"][3]
            ch, turn = ui.slider_float(
                "turn (deg)",
                deg,
                -180.0,
                180.0,
                "%.0f",
                "turn the active handle (yellow) about the view axis through its centroid; the "
                "gizmo turns about any axis",
            )
            if ch:
                self.turn(host, i, turn)
        if ui.button("undo", "the last handle move taken back (Z)", ("redo",)):
            st.undo()
        ui.same_line()
        if ui.button("redo", "the move undo took back (Y)"):
            st.redo()
        ui.same_line()
        if ui.button("reset", "every handle back at rest (R)"):
            st.reset_moves()
        ui.same_line()
        if ui.button("clear handles", "no handle, no clicked fixed disc"):
            st.clear_handles()
            self.gizmo.remove()

    def turn(self, host: Host, index: int, degrees: float) -> None:
        """Turn handle ``index`` about the camera's view axis by ``degrees`` (its move kept)."""
        st = self.state
        if not math.isfinite(degrees):
            st.error = "turn: not a number"
            return
        degrees = min(max(float(degrees), -180.0), 180.0)
        Rd, _, _ = display_frame(host.state.display)
        axis = Rd.T @ view_axis()
        m = st.moves[index]
        st.checkpoint()
        st.set_move(index, {"rotate": [*map(float, axis), degrees], "move": list(m["move"])})
        st.error = ""

    def draw_numbers(self, host: Host) -> None:
        """Per method: the energy it minimizes and its value, the system, the timings; ARAP's
        energy against the iterations."""
        ui, st = host.ui, self.state
        if st.built is None:
            return
        figs = [st.figures(m) for m in st.methods if m in st.built.deformers]
        if not figs:
            return
        rate = st.update_rate()
        if rate:
            ui.text(f"{rate:.1f} updates/s shown")
        for f in figs:
            ui.text(f"{f['method']} minimizes {f['minimizes']}")
        headers = ["", *(f["method"] for f in figs)]
        tips = ["", *(f["energy_name"] for f in figs)]
        rows = [
            ("energy", [f"{f['energy']:.4g}" for f in figs]),
            ("unknowns", [f"{f['n_unknowns']:,}" for f in figs]),
            ("nonzeros", [f"{f['nnz']:,}" for f in figs]),
            ("factorize s", [f"{f['factor_seconds']:.3f}" for f in figs]),
            ("set-up s", [f"{f['setup_seconds']:.3f}" for f in figs]),
            ("update ms", [f"{1e3 * f['solve_seconds']:.1f}" for f in figs]),
            ("handle error", [f"{f['handle_error']:.2g}" for f in figs]),
        ]
        with ui.table("deform numbers", headers, tips):
            for name, cells in rows:
                ui.row([name, *cells])
        if st.colour == "rotation error":
            worst = []
            for f in figs:
                e = st.field(f["method"])
                worst.append(f"{f['method']} {float(np.max(e)) if e is not None else 0.0:.3g}")
            ui.text("largest rotation error: " + ", ".join(worst))
        for f in figs:
            if "energies" not in f:
                continue
            state = "iterating"
            if st.converged.get("arap"):
                capped = f["iteration"] >= st.arap_max
                state = f"stopped at the cap of {st.arap_max}" if capped else "converged"
            ui.text(f"ARAP: iteration {f['iteration']} since the last move ({state})")
            E = np.asarray(f["energies"], dtype=float)
            if len(E):
                with ui.plot("ARAP energy", 150, "iteration", "energy", y_log=True) as ok:
                    if ok:
                        ui.plot_line("E(x, R)", np.arange(1, len(E) + 1), np.maximum(E, 1e-300))

    # ------------------------------------------------------------------ meshlap animate
    def frames(self, host: Host, options: dict[str, Any]) -> Iterator[str]:
        """A drag: each frame moves the handle(s) a step of the way (ARAP iterating
        ``--arap-per-frame`` times per frame), the deformation following."""
        st, mesh = self.state, host.state.mesh
        st.method = options["deform_method"]
        st.compare = "none"
        st.radius = float(options["handle_radius"])
        st.arap_per_frame = int(options["arap_per_frame"])
        if options.get("drag_session") and st.handles:
            finals = [dict(m) for m in st.moves]
        else:
            v = int(options["drag_vertex"])
            st.handles, st.moves = [], []
            st.select(len(mesh.V), v if v >= 0 else top_vertex(host))
            diag = diagonal(mesh.V)
            move = [diag * float(x) for x in options["drag_move"]]
            finals = [{"rotate": list(map(float, options["drag_rotate"])), "move": move}]
        st.moves = [dict(m) for m in finals]  # framed on the last frame's shape
        st.moved += 1
        self.settle(host)
        host.frame(scene.COLORBAR_STRIP)
        for i in range(len(finals)):
            st.set_move(i, {"rotate": [0.0, 0.0, 1.0, 0.0], "move": [0.0, 0.0, 0.0]})
        if "arap" in st.built.deformers if st.built is not None else False:
            st.built.deformers["arap"].reset()  # the drag starts from the rest pose
        count = int(options["drag_frames"])
        for k in range(count):
            t = k / (count - 1)
            for i, m in enumerate(finals):
                _, move = move_matrix(m)
                ax, ay, az, deg = m["rotate"]
                st.set_move(i, {"rotate": [ax, ay, az, deg * t], "move": list(t * move)})
            for _ in range(st.arap_per_frame if st.method == "arap" else 1):
                for method in st.due():
                    st.solve(method)
            self.push(host, force=True)
            f = st.figures(st.method)
            it = f"   iteration {f['iteration']}" if "iteration" in f else ""
            yield f"{st.method}: step {k + 1}/{count} of the drag{it}   energy {f['energy']:.3g}"


def st_has(st: DeformState) -> bool:
    """A restored state holds handles (its set is built when its view is shown)."""
    return bool(st.handles)


def top_vertex(host: Host) -> int:
    """The vertex highest on screen (display y): a handle that lifts the shape visibly."""
    P = host.mesh_points()
    return int(np.argmax(P[:, 1])) if len(P) else 0


def demo_move(host: Host) -> dict[str, Any]:
    """A move that shows the methods apart: up on screen by a sixth of the diagonal and a
    40° turn about the screen's depth axis (mesh coordinates)."""
    R = np.asarray(host.state.display.rotation, dtype=float)
    up, depth = R.T @ [0.0, 1.0, 0.0], R.T @ [0.0, 0.0, 1.0]
    lift = up * diagonal(host.state.mesh.V) / 6.0
    return {"rotate": [*map(float, depth), 40.0], "move": [*map(float, lift)]}
