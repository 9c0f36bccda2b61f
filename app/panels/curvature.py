"""The Curvature panel: a curvature field as a colour map, optionally a second one beside it."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np
import polyscope as ps

from meshlap_core.options import AREA_KINDS as AREAS
from meshlap_core.options import BOUNDARY_RULES

from ..scene import COLORBAR_AT, MESH, MESH_B, scalar_for_upload, side_offset
from ..state.names import FIELD_LABELS

if TYPE_CHECKING:
    from ..viewer import Viewer


FIELD_HELP = (
    "H = |Lx|/2 with the uniform or cotangent Laplacian (signed by the normal); "
    "K = (2 pi - sum of angles) / A_i; k1,2 = H +- sqrt(H^2 - K)"
)


class CurvaturePanel:
    """Field, area, boundary rule, clip percentage, side-by-side second estimator, histogram."""

    def __init__(self) -> None:
        self.side_by_side = False
        self.second_field = "uniform"
        self.shown: Any = ""
        self.colorbar = True  # the main field's colour bar: on in this panel and the one-ring's

    def on_new_mesh(self, viewer: Viewer) -> None:
        self.shown = ""

    def show(self, viewer: Viewer, panel: str) -> None:
        want = panel in ("curvature", "onering")
        if want != self.colorbar and ps.has_surface_mesh(MESH):
            self.colorbar = want
            self.push(viewer, force=True)
        if ps.has_surface_mesh(MESH_B):
            ps.get_surface_mesh(MESH_B).set_enabled(panel == "curvature")

    def points(self, viewer: Viewer, name: str) -> np.ndarray | None:
        shown = viewer.display.points(viewer.mesh.V)
        if name == MESH:
            return shown
        if name == MESH_B:
            return shown + side_offset(shown)
        return None

    def push(self, viewer: Viewer, force: bool = False) -> None:
        """Add the selected curvature field(s) as colour maps (only when they changed)."""
        curv = viewer.curv
        changed = curv.update(viewer.mesh) or force
        key = (curv.field_name, curv.percentile, self.side_by_side, self.second_field)
        if not changed and key == self.shown:
            return
        self.shown = key
        self._add_field(viewer, ps.get_surface_mesh(MESH), curv.field_name, self.colorbar)
        if self.side_by_side:
            if not ps.has_surface_mesh(MESH_B):
                V = viewer.display.points(viewer.mesh.V)
                ps.register_surface_mesh(
                    MESH_B, V + side_offset(V), viewer.mesh.F, smooth_shade=True
                )
            self._add_field(viewer, ps.get_surface_mesh(MESH_B), self.second_field)
        elif ps.has_surface_mesh(MESH_B):
            ps.remove_surface_mesh(MESH_B)

    @staticmethod
    def _add_field(viewer: Viewer, sm: Any, name: str, colorbar: bool = False) -> None:
        label, signed = FIELD_LABELS[name]
        label += " [1/length^2]" if name == "gaussian" else " [1/length]"
        values, (lo, hi), factor = scalar_for_upload(
            viewer.curv.fields[name], viewer.curv.color_range(name)
        )
        sm.add_scalar_quantity(
            label + factor,
            values,
            defined_on="vertices",
            cmap="coolwarm" if signed else "viridis",
            vminmax=(lo, hi),
            enabled=True,
            onscreen_colorbar_enabled=colorbar,
            onscreen_colorbar_location=COLORBAR_AT,
        )

    def draw(self, viewer: Viewer) -> None:
        ui = viewer.ui
        if not ui.header("Curvature"):
            return
        c = viewer.curv
        names = tuple(FIELD_LABELS)
        ch1, c.field_name = ui.combo("field", c.field_name, names, FIELD_HELP)
        ch2, c.area = ui.combo(
            "area", c.area, AREAS, "vertex area A_i: barycentric (1/3 of each face) or Voronoi"
        )
        ch3, c.boundary = ui.combo(
            "boundary rule",
            c.boundary,
            BOUNDARY_RULES,
            "Gaussian curvature at boundary vertices: pi - sum(angles) (geodesic curvature) "
            "or not defined",
        )
        ch4, pct = ui.slider_float(
            "clip %",
            c.percentile,
            0.0,
            20.0,
            "%.1f",
            "colour range clips this percentage of vertices at each end (0 to 49)",
        )
        if ch4:
            c.set_percentile(pct)
        ch5, self.side_by_side = ui.checkbox(
            "side by side", self.side_by_side, "show a second field on a copy beside the mesh"
        )
        ch6 = False
        if self.side_by_side:
            ch6, self.second_field = ui.combo(
                "second field", self.second_field, names, "the field on the copy"
            )
        if ch1 or ch2 or ch3 or ch4 or ch5 or ch6:
            self.push(viewer, force=ch2 or ch3)
            viewer.show_panel()
            viewer.reframe = viewer.reframe or ch5
        if c.field_name not in c.fields:
            return
        st = c.summary()
        lo, hi = st["range"]
        ui.text(f"min {st['min']:.4g}  max {st['max']:.4g}  colour range [{lo:.4g}, {hi:.4g}]")
        ui.text(FIELD_LABELS[c.field_name][0])
        with ui.plot(
            "histogram (clipped to the colour range)",
            160,
            FIELD_LABELS[c.field_name][0],
            "vertices",
        ) as shown:
            if shown:
                ui.plot_bars(
                    "vertices",
                    st["centers"],
                    st["counts"],
                    st["width"],
                    _bar_colors(st["centers"], lo, hi, FIELD_LABELS[c.field_name][1]),
                )


def _bar_colors(centers: np.ndarray, lo: float, hi: float, signed: bool) -> np.ndarray:
    """Each histogram bar ``(k,4)`` in the colour the mesh shows for its value (the same map,
    coolwarm or viridis, and the same range ``[lo, hi]``)."""
    from matplotlib import colormaps

    c = np.asarray(centers, dtype=np.float64)
    t = (c - lo) / (hi - lo) if hi > lo else np.full(len(c), 0.5)
    return colormaps["coolwarm" if signed else "viridis"](np.clip(t, 0.0, 1.0))
