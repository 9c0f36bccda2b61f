"""The One-ring panel: a clicked vertex, its neighbours numbered in order, H and K there, and
the vertex inspector (every term of the discrete operators at that vertex, listed and drawn)."""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from typing import Any

import numpy as np
import polyscope as ps

from meshlap_core.errors import MeshError
from meshlap_core.inspector import FaceTerm, NeighbourTerm, VertexInspection, format_inspection
from meshlap_core.options import AREA_KINDS, BOUNDARY_RULES, titled

from .. import scene
from ..camera import project_to_screen
from ..host import Host
from ..panel_spec import PanelSpec
from ..scene import MESH, RING_CENTER, RING_CURVE, RING_POINTS, picked_vertex, scene_fraction
from ..setting_widgets import setting_widget
from ..state.onering import (
    SETTINGS,
    HoverThrottle,
    OneRingState,
    angle_arcs,
    area_cell,
    arrow_scales,
    weight_segments,
)
from ..text_numbers import sig
from .base import Panel

NEGATIVE_RGBA = (*scene.NEGATIVE_COLOR, 1.0)

# glyphs the viewer's font lacks, written out (the CLI prints the originals)
ASCII_MATH = str.maketrans(
    {
        "Δ": "L",
        "Σ": "sum ",
        "θ": "theta",
        "π": "pi",
        "κ": "k",
        "₁": "1",
        "₂": "2",
        "√": "sqrt",
        "−": "-",
        "—": "-",
        "·": "*",
        "²": "^2",
    }
)

AREA_HELP = (
    "A_i: barycentric = sum of A_f/3; mixed Voronoi (Meyer et al. 2003) = circumcentre cell, "
    "A_f/2 when the face is obtuse at i, A_f/4 when obtuse elsewhere. Also the curvature fields'."
)
BOUNDARY_HELP = (
    "angle deficit at a boundary vertex: pi - sum(theta) ('pi'), 2 pi - sum(theta) ('2pi'), "
    "or K = 0 ('zero'). Also the curvature fields'."
)


class OneRingPanel(Panel):
    """Vertex field, clockwise toggle, the ring drawn as numbered points and arrows, and the
    inspector: its tables in the panel and its drawings in 3D (ring edges coloured by ``w_ij``,
    corner-angle arcs, the area cell, ``n`` and ``Δx`` at the vertex).

    Parameters
    ----------
    name : str
        Its registry name.
    state : OneRingState
        Its slice of the app state (the selection).
    clock : callable
        Seconds (monotonic) for the hover throttle; a test passes a fake clock.
    """

    shows_curvature = True  # the mesh keeps the curvature field and its colour bar

    def __init__(
        self, spec: PanelSpec, state: OneRingState, clock: Callable[[], float] = time.monotonic
    ) -> None:
        super().__init__(spec, state)
        self.state: OneRingState = state
        self.labels: list[tuple[tuple[float, float], str]] = []  # the one-ring numbers drawn
        self.clock = clock
        self.throttle = HoverThrottle()
        self.hovered = ""  # the text shown at the cursor ("" over nothing)
        self.hovered_vertex = -1  # the mesh vertex under the cursor (its table row is lit)
        self.picks = 0  # hover picks done (the throttle keeps this low)
        self.registered = False  # the inspector's structures are in the scene
        self.arrow_text = ""

    def on_new_mesh(self, host: Host) -> None:
        self.state.clear()
        for name in (RING_CURVE, RING_POINTS, RING_CENTER):
            scene.remove_structure(name)
        self.labels = []
        self.hovered = ""
        self.throttle = HoverThrottle(self.throttle.interval)
        self.remove_inspector()

    def show(self, host: Host, active: Panel) -> None:
        mine = active is self
        if ps.has_curve_network(RING_CURVE):
            ps.get_curve_network(RING_CURVE).set_enabled(mine)
        for name in (RING_POINTS, RING_CENTER):
            if ps.has_point_cloud(name):
                ps.get_point_cloud(name).set_enabled(mine)
        if not mine:
            self.remove_inspector()  # registered again when the panel comes back
        elif not self.registered and self.state.inspection is not None:
            self.push_inspector(host)

    def remove_inspector(self) -> None:
        """Remove the inspector's structures from the scene."""
        for name in scene.INSPECTOR:
            scene.remove_structure(name)
        self.registered = False

    def select(self, host: Host, i: int) -> bool:
        """Select vertex ``i`` and draw its ordered one-ring."""
        if not self.state.select(host.state.mesh, host.state.curv, i):
            return False
        self.push(host)
        host.request_frame()  # the camera turns to the new one-ring (else a speck on the mesh)
        return True

    def pick(self, host: Host, hit: Any, active: Panel) -> bool:
        """A click on the mesh (in this view, or in one that hands its clicks through)
        selects the vertex and shows this view."""
        if hit.structure_name != MESH or not (active is self or active.pick_through):
            return False
        idx = picked_vertex(hit, host.mesh_points(), host.state.mesh.F)
        if idx is None:
            return False
        host.state.panel = self.name
        return self.select(host, idx)

    def capture(self, host: Host) -> dict[str, Any]:
        return {"vertex": int(self.state.vertex), "reverse": bool(self.state.reverse)}

    def configure(self, host: Host, values: dict[str, Any]) -> None:
        self.state.reverse = values["reverse"]

    def restore(self, host: Host, values: dict[str, Any], active: bool) -> None:
        self.state.reverse = values["reverse"]
        if values["vertex"] >= 0:
            self.select(host, values["vertex"])

    def start(self, host: Host, options: dict[str, Any], shown: bool, screenshot: bool) -> None:
        if shown:
            vertex = options.get("vertex")
            self.select(host, vertex if vertex is not None else 0)

    def push(self, host: Host) -> None:
        r = self.state
        if r.valence == 0:
            return
        d = host.state.display
        center, ring = d.points(host.state.mesh.V[[r.vertex]]), d.points(r.polyline)
        # sizes follow the ring's own edge length, so any mesh and zoom level looks the same
        scale = 0.08 * float(np.linalg.norm(ring - center, axis=1).mean())
        cn = ps.register_curve_network(RING_CURVE, ring, r.edges, radius=0.5 * scale)
        cn.set_radius(0.5 * scale, relative=False)
        cn.set_color((0.1, 0.1, 0.1))
        pc = ps.register_point_cloud(RING_POINTS, ring, radius=1.5 * scale)
        pc.set_radius(1.5 * scale, relative=False)
        # the order as RGB colours (viridis, first to last): their legend is the numbers the
        # overlay draws on the neighbours, not a third colour bar over the ring
        from matplotlib import colormaps

        order_rgb = colormaps["viridis"](np.clip(np.asarray(r.order_t, dtype=float), 0, 1))[:, :3]
        pc.add_color_quantity("order (numbered)", order_rgb, enabled=True)
        pc.add_vector_quantity(
            "direction",
            0.85 * d.vectors(r.arrows),
            vectortype="ambient",
            enabled=True,
            color=(0.9, 0.5, 0.0),
        )
        c = ps.register_point_cloud(RING_CENTER, center, radius=2.0 * scale)
        c.set_radius(2.0 * scale, relative=False)
        c.set_color((1.0, 0.1, 0.1))
        self.push_inspector(host)
        host.refresh()

    def push_inspector(self, host: Host) -> None:
        """Register the inspector's drawings for the selected vertex (on a selection change)."""
        ins = self.state.inspection
        self.remove_inspector()
        if ins is None or not ins.neighbors:
            return
        d, V, F = host.state.display, host.state.mesh.V, host.state.mesh.F
        lengths = np.array([t.edge_length for t in ins.neighbors])
        mean = float(lengths.mean())
        r = 0.08 * mean * d.scale  # display radius unit, as the ring's
        self._push_weights(host, ins, r)
        lift = 0.02 * mean * ins.normal  # just above the surface (no z-fighting)
        nodes, edges, theta = angle_arcs(ins, V, F, 0.4 * float(lengths.min()))
        if len(edges):
            arcs = ps.register_curve_network(scene.INSPECT_ARCS, d.points(nodes + lift), edges)
            arcs.set_radius(0.18 * r, relative=False)
            obtuse = (theta > np.pi / 2)[:, None]
            rgb = np.where(obtuse, np.array([[0.9, 0.1, 0.1]]), np.array([scene.ARC_COLOR]))
            arcs.add_color_quantity("corner angle (red: obtuse)", rgb, "edges", enabled=True)
        nodes, tris, outline = area_cell(ins, V, F)
        lifted = nodes + lift
        cell = ps.register_surface_mesh(scene.INSPECT_CELL, d.points(lifted), tris)
        cell.set_color(scene.CELL_COLOR)
        cell.set_transparency(0.6)
        cn = ps.register_curve_network(scene.INSPECT_CELL_EDGE, d.points(lifted), outline)
        cn.set_radius(0.15 * r, relative=False)
        cn.set_color((0.1, 0.5, 0.1))
        self._push_arrows(host, ins, 1.5 * mean, r)
        self.registered = True

    def _push_weights(self, host: Host, ins: VertexInspection, r: float) -> None:
        """The ring edges ``i–j`` coloured by ``w_ij`` (coolwarm, symmetric around 0), the
        negative ones drawn over in their own colour."""
        d = host.state.display
        nodes, edges, w = weight_segments(ins, host.state.mesh.V)
        m = float(np.abs(w).max()) or 1.0
        cn = ps.register_curve_network(scene.INSPECT_WEIGHTS, d.points(nodes), edges)
        cn.set_radius(0.35 * r, relative=False)
        cn.add_scalar_quantity(
            titled("cotangent weight w_ij", "dimensionless"),
            w,
            defined_on="edges",
            cmap="coolwarm",
            vminmax=(-m, m),
            enabled=True,
            onscreen_colorbar_enabled=True,
            # below the mesh field's colour bar, spaced for the UI scale (no overlap at 1.5)
            onscreen_colorbar_location=scene.colorbar_at(1, host.state.ui_scale),
        )
        neg = w < 0
        if neg.any():
            nc = ps.register_curve_network(scene.INSPECT_NEGATIVE, d.points(nodes), edges[neg])
            nc.set_radius(0.45 * r, relative=False)
            nc.set_color(scene.NEGATIVE_COLOR)

    def _push_arrows(self, host: Host, ins: VertexInspection, length: float, r: float) -> None:
        """``n`` (``length`` long, world units) and ``Δ_cotan x`` (scaled to ``0.7 length``, so
        both show when they are parallel, as ``Δx = −2Hn`` makes them) as arrows at ``x_i``."""
        d = host.state.display
        s_n, _ = arrow_scales(ins, length)
        _, s_lap = arrow_scales(ins, 0.7 * length)
        pc = ps.register_point_cloud(scene.INSPECT_ARROWS, d.points(ins.position[None, :]))
        pc.set_radius(0.01 * r, relative=False)
        for name, vec, color, width in (
            ("n (angle-weighted normal)", s_n * ins.normal, scene.NORMAL_COLOR, 0.25),
            ("Lx (cotan Laplacian)", s_lap * ins.laplacian_cotan, scene.LAPLACIAN_COLOR, 0.4),
        ):
            pc.add_vector_quantity(
                name,
                d.vectors(vec[None, :]),
                vectortype="ambient",
                enabled=True,
                color=color,
                radius=width * r / max(ps.get_length_scale(), 1e-30),  # polyscope: relative
            )
        self.arrow_text = (
            f"arrows at i: black n, {length:.3g} long; teal Lx, drawn x {s_lap:.3g} "
            f"(|Lx| = {float(np.linalg.norm(ins.laplacian_cotan)):.4g}; world units)"
        )

    def focus(self, host: Host) -> bool:
        """Point the camera at the selected vertex, along its normal, framing the one-ring
        (nothing selected: the host frames the mesh)."""
        r = self.state
        if r.valence == 0:
            return False
        center = host.state.display.points(host.state.mesh.V[[r.vertex]])[0]
        ring = host.state.display.points(r.polyline)
        size = float(np.linalg.norm(ring - center, axis=1).max()) or 1.0
        normal = r.normal if np.linalg.norm(r.normal) > 0 else np.array([0.0, 0.0, 1.0])
        # tilt a little towards the up axis inside the tangent plane: looking straight along
        # the up axis (a flat mesh seen from above) is a degenerate camera frame
        tilt = np.array([0.0, 1.0, 0.0]) - normal[1] * normal
        if np.linalg.norm(tilt) < 1e-6:
            tilt = np.array([1.0, 0.0, 0.0]) - normal[0] * normal
        tilt /= np.linalg.norm(tilt)
        # obliquely (about 40° off the normal), so the arrows n and Δx at the vertex show
        back = 2.4 * normal + 2.0 * tilt
        if np.linalg.norm(np.cross([0.0, 1.0, 0.0], back)) < 1e-6 * np.linalg.norm(back):
            scene.look_at(center + size * back, center)  # frame_points needs a non-vertical view
            return True
        w, h = ps.get_window_size()
        ui_scale = host.state.ui_scale
        pane = ps.get_right_gui_pane_width() * ui_scale  # at most half the window
        fraction = max(scene_fraction(w, ui_scale), 0.95 * (1.0 - pane / max(w, 1)))
        left = min(scene.COLORBAR_PX * ui_scale / max(w, 1), 0.5 * fraction)  # the bars' strip
        right = np.cross([0.0, 1.0, 0.0], back)
        right /= np.linalg.norm(right)
        fov = np.radians(ps.get_view_camera_parameters().get_fov_vertical_deg())
        tan_v = float(np.tan(fov / 2.0))
        tan_h = tan_v * w / max(h, 1)
        # far enough that the ring (with a margin for its labels and arrows) fits between the
        # colour bars and meshlap's panel, and in the height
        free = max(fraction - left, 0.1)
        d = max(float(np.linalg.norm(back)), 1.4 / (tan_h * free), 1.4 / tan_v) * size
        # shift the target so the vertex lands in the middle of that free strip
        ndc = left + fraction - 1.0
        target = center - ndc * d * tan_h * right
        scene.look_at(target + d * back / np.linalg.norm(back), target)
        return True

    def ring_labels(self, host: Host) -> list[tuple[tuple[float, float], str]]:
        """Screen positions and texts of the order numbers ("0", "1", ...) of the one-ring."""
        r = self.state
        if r.valence == 0:
            return []
        params = ps.get_view_camera_parameters()
        w, h = ps.get_window_size()
        xy, front = project_to_screen(
            host.state.display.points(r.polyline),
            params.get_view_mat(),
            params.get_fov_vertical_deg(),
            w,
            h,
        )
        return [
            ((float(x) + 12, float(y) - 22), str(k))
            for k, ((x, y), f) in enumerate(zip(xy, front, strict=True))
            if f
        ]

    def overlay(self, host: Host) -> None:
        """Write the order numbers next to the neighbours (over the 3D view), and the hovered
        vertex's index and field value at the cursor."""
        self.labels = self.ring_labels(host)
        for pos, text in self.labels:
            host.ui.overlay_text(pos, text)
        self.draw_hover(host)

    def draw_hover(self, host: Host) -> None:
        """Pick under the cursor once it rests ``throttle.interval`` seconds at a new position
        (a moving cursor and an idle frame do no picking); show the answer at the cursor, and
        light the vertex's row in the inspector's tables while it shows."""
        pos = host.ui.hover()
        if pos is None:
            self.hovered, self.hovered_vertex = "", -1
            return
        if self.throttle.due(self.clock(), pos):
            self.picks += 1
            self.hovered = self.hover_text(host, pos)
        if self.hovered and self.throttle.current(pos):  # nothing stale while moving
            host.ui.overlay_text((pos[0] + 16, pos[1] + 12), self.hovered)
        else:
            self.hovered_vertex = -1  # a table row is lit only while its label shows

    def hover_text(self, host: Host, pos: tuple[float, float]) -> str:
        """``"vertex i: <field> = value"`` for the mesh vertex under ``pos``; over a neighbour's
        sphere, that neighbour's number, vertex and cotangent weight ``w_ij``; else ``""``."""
        self.hovered_vertex = -1
        res = ps.pick(screen_coords=pos)
        if res.is_hit and res.structure_name == RING_POINTS:
            return self.neighbour_text(int(res.local_index))
        if not res.is_hit or res.structure_name != MESH:
            return ""
        idx = picked_vertex(res, host.mesh_points(), host.state.mesh.F)
        if idx is None:
            return ""
        self.hovered_vertex = int(idx)
        curv = host.state.curv
        values = curv.fields.get(curv.field_name)
        if values is None:
            return f"vertex {idx}"
        return f"vertex {idx}: {curv.field_name} = {float(values[idx]):.4g}"

    def neighbour_text(self, i: int) -> str:
        """``"neighbour 2 = vertex 17: w_ij = 0.53"`` for the ``i``-th sphere of the ring (its
        table row is lit), ``""`` for an index outside the ring."""
        r = self.state
        if not 0 <= i < len(r.neighbors):
            return ""
        j = r.neighbors[i]
        self.hovered_vertex = j
        ins = r.inspection
        terms = [t for t in (ins.neighbors if ins is not None else []) if t.index == j]
        weight = f": w_ij = {terms[0].weight_cotan:.4g}" if terms else ""
        return f"neighbour {i} = vertex {j}{weight}"

    def draw(self, host: Host) -> None:
        ui = host.ui
        if not ui.header(self.title):
            return
        ui.text("click a vertex of the mesh")
        n = len(host.state.mesh.V)
        r = self.state
        ch, v = setting_widget(ui, SETTINGS["vertex"], max(r.vertex, 0), 0, n - 1)
        if ch:
            if not 0 <= v < n:
                raise MeshError(f"{v} is out of range (the mesh has {n} vertices)", "vertex")
            self.select(host, v)
        ch, _ = setting_widget(ui, SETTINGS["reverse"], r.reverse)
        if ch:
            r.toggle_reverse(host.state.mesh, host.state.curv)
            self.push(host)
        c = host.state.curv
        ch1, area = ui.combo("area kind", c.area, AREA_KINDS, AREA_HELP)
        ch2, rule = ui.combo("boundary rule", c.boundary, BOUNDARY_RULES, BOUNDARY_HELP)
        if ch1 or ch2:
            r.set_rules(host.state.mesh, c, area, rule)  # the mesh's colours follow (sync)
            self.push(host)
        if r.vertex < 0:
            return
        kind = "boundary vertex (open fan)" if r.boundary else "interior vertex (closed cycle)"
        ui.text(f"vertex {r.vertex}: {kind}, valence {r.valence}")
        ui.text(f"H (cotan) = {r.H + 0.0:.5g}   K (angle deficit) = {r.K + 0.0:.5g}")
        self.draw_shape_operator(host)
        if not r.ordered:
            ui.error("not a disk: neighbours listed by index, not in order")
        ui.text("order: " + " -> ".join(str(j) for j in r.neighbors[:40]))
        if r.inspection is None:
            if r.inspection_error:
                ui.error(r.inspection_error)
            return
        self.draw_inspection(host, r.inspection)

    def draw_shape_operator(self, host: Host) -> None:
        """The shape operator row: the Curvature view's estimator's 2×2 tensor at the vertex
        with its tangent basis (a patch around the vertex, or the whole mesh's estimate)."""
        ui, c, mesh = host.ui, host.state.curv, host.state.mesh
        so = self.watch.cached(
            "shape operator",
            (mesh.version, self.state.vertex, c.principal_inputs(mesh), c.principal_current(mesh)),
            lambda: c.shape_operator(mesh, self.state.vertex),
        )
        if so is None:  # the jet: its radius needs the whole mesh (a job)
            c.want_principal(mesh, host.state.jobs, bool(host.background))
            ui.note(f"shape operator ({c.estimator}): computed for the whole mesh ...")
            return
        (a, b), (_, d) = so["S"]
        fmt = lambda t: f"({t[0]:.3f}, {t[1]:.3f}, {t[2]:.3f})"  # noqa: E731
        ui.text(
            f"shape operator ({so['estimator']}): S = [[{a:.4g}, {b:.4g}], [{b:.4g}, {d:.4g}]]"
            f"  (k1 = {so['k1']:.4g}, k2 = {so['k2']:.4g})"
        )
        ui.note(f"in the tangent basis t1 = {fmt(so['t1'])}, t2 = {fmt(so['t2'])}")

    def draw_inspection(self, host: Host, ins: VertexInspection) -> None:
        """The inspector's tables and formulas, and the legend of its 3D drawings."""
        ui = host.ui
        if not ins.manifold:
            ui.error(f"non-manifold vertex: {len(ins.fans)} fans (faces of each, ring per fan)")
            for k, fan in enumerate(ins.fans):
                ui.text(f"  fan {k}: faces {', '.join(str(f) for f in fan)}")
        self.draw_legend(host, ins)
        if ui.header("weights per neighbour (ring order)"):
            self.draw_neighbours(host, ins)
        if ui.header("incident faces", default_open=False):
            self.draw_faces(host, ins)
        if ui.header("the vertex: formulas with numbers"):
            lines = format_inspection(ins).splitlines()
            start = next(k for k, line in enumerate(lines) if line.startswith("A_i"))
            for line in lines[start:]:
                ui.text(line.translate(ASCII_MATH))

    def draw_legend(self, host: Host, ins: VertexInspection) -> None:
        ui = host.ui
        w = np.array([t.weight_cotan for t in ins.neighbors])
        m = float(np.abs(w).max()) if len(w) else 0.0
        ui.note(
            f"edges i-j: w_ij on blue-white-red over [-{m:.3g}, {m:.3g}] (colour bar); "
            f"arcs: corner angles at i (red: obtuse); green: {ins.area_kind} area cell "
            f"A_i = {ins.area:.4g}"
        )
        if (w < 0).any():
            ui.colored(f"magenta edges: negative w_ij ({int((w < 0).sum())})", NEGATIVE_RGBA)
        if self.arrow_text:
            ui.note(self.arrow_text)

    def draw_neighbours(self, host: Host, ins: VertexInspection) -> None:
        """Two tables in ring order: the weights (negative rows in magenta), then each
        neighbour's contribution ``w_ij (x_j − x_i)`` and their sum ``A_i Δx``; the row of the
        neighbour under the cursor in 3D is lit."""
        ui = host.ui
        rows = self.state.rows()
        scale = max((abs(t.weight_cotan) for t in rows), default=0.0)
        with ui.table("weights", NEIGHBOUR_HEADERS, NEIGHBOUR_TIPS):
            for t in rows:
                ui.row(
                    neighbour_cells(t, scale),
                    NEGATIVE_RGBA if t.negative else None,
                    t.index == self.hovered_vertex,
                )
        total = np.sum([t.contribution for t in rows], axis=0) if rows else np.zeros(3)
        size = max((float(np.abs(t.contribution).max()) for t in rows), default=0.0)
        ui.note("each neighbour's term w_ij (x_j - x_i); their sum is A_i Lx:")
        with ui.table("contributions", CONTRIBUTION_HEADERS, CONTRIBUTION_TIPS):
            for t in rows:
                ui.row(
                    [str(t.index), *(sig(float(c), size) for c in t.contribution)],
                    NEGATIVE_RGBA if t.negative else None,
                    t.index == self.hovered_vertex,
                )
            ui.row(["sum", *(sig(float(c), size) for c in total)])

    def draw_faces(self, host: Host, ins: VertexInspection) -> None:
        """The incident faces in ring order: corner angle, area, obtuse, both area shares."""
        ui = host.ui
        with ui.table("faces", FACE_HEADERS, FACE_TIPS):
            for f in ins.faces:
                ui.row(face_cells(f))


NEIGHBOUR_HEADERS = ("j", "|x_j - x_i|", "alpha", "beta", "w_ij", "1/|N|")
NEIGHBOUR_TIPS = (
    "the neighbour's vertex index, in ring order (the numbers in 3D count along it)",
    "edge length",
    "alpha_ij: the angle opposite edge ij in the first face holding it",
    "beta_ij: the angle opposite edge ij in the second face ('-': a boundary edge)",
    "cotangent weight w_ij = 1/2 (cot alpha + cot beta); negative (magenta) when the "
    "opposite angles are obtuse",
    "uniform weight 1/|N(i)|",
)
CONTRIBUTION_HEADERS = ("j", "x", "y", "z")
CONTRIBUTION_TIPS = (
    "the neighbour's vertex index, in ring order; 'sum': the sum of the terms, A_i Lx (the "
    "Lx formula below divides it by A_i)",
    "w_ij (x_j - x_i), x component",
    "w_ij (x_j - x_i), y component",
    "w_ij (x_j - x_i), z component",
)
FACE_HEADERS = ("face", "theta_f", "area", "obtuse", "A_f/3", "Voronoi", "rule")
FACE_TIPS = (
    "face index, in ring order",
    "the corner angle of the face at i",
    "the face's area A_f",
    "does the face have an angle above 90°? ('at i': at this vertex)",
    "the face's share of the barycentric area A_i",
    "the face's share of the mixed Voronoi area A_i (Meyer et al. 2003)",
    "the Voronoi rule: cot = 1/8 sum l^2 cot (acute face), A/2 (obtuse at i), A/4 (obtuse "
    "elsewhere)",
)


def neighbour_cells(t: NeighbourTerm, scale: float) -> list[str]:
    """The weights table's cells of the neighbour ``t`` (``scale``: the largest ``|w|`` of the
    ring, below which round-off shows as ``0``)."""
    beta = "-" if t.beta is None else f"{math.degrees(t.beta):.2f}°"
    return [
        str(t.index),
        f"{t.edge_length:.4g}",
        f"{math.degrees(t.alpha):.2f}°",
        beta,
        sig(t.weight_cotan, scale),
        f"{t.weight_uniform:.4g}",
    ]


def face_cells(f: FaceTerm) -> list[str]:
    """The faces table's cells of the face ``f``."""
    obtuse = "at i" if f.obtuse_at_vertex else ("yes" if f.obtuse else "no")
    rule = "A/2" if f.obtuse_at_vertex else ("A/4" if f.obtuse else "cot")
    return [
        str(f.face),
        f"{math.degrees(f.angle):.2f}°",
        f"{f.area:.4g}",
        obtuse,
        f"{f.share_barycentric:.4g}",
        f"{f.share_voronoi:.4g}",
        rule,
    ]
