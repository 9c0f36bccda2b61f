"""The One-ring view's widgets: the vertex field, the orientation, and the vertex inspector's
widgets (area kind, boundary rule, hover)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import polyscope as ps
from meshlap_app import scene
from meshlap_app.state.onering import HoverThrottle

from tests.support.widgets import FakeClock, drive


def drive_onering_widgets(viewer):
    viewer.set_panel("onering")
    drive(viewer, "vertex", 7)
    assert (
        viewer.panels["onering"].state.vertex == 7 and viewer.panels["onering"].state.valence >= 5
    )
    before = list(viewer.panels["onering"].state.neighbors)
    for bad in ["", "-1", "nan", "1e309", "abc", str(len(viewer.state.mesh.V)), 10**9]:
        drive(viewer, "vertex", bad)
        assert viewer.panels["onering"].state.vertex == 7  # the selection stays
        assert "vertex" in viewer.state.errors["onering"]
    drive(viewer, "clockwise (reverse)", True)
    assert viewer.panels["onering"].state.neighbors == before[::-1]
    drive(viewer, "clockwise (reverse)", False)
    assert (
        viewer.panels["onering"].state.neighbors == before and "onering" not in viewer.state.errors
    )


def inspector_names() -> set[str]:
    return {
        n
        for n in scene.INSPECTOR
        if ps.has_curve_network(n) or ps.has_point_cloud(n) or ps.has_surface_mesh(n)
    }


def drive_inspector(viewer) -> None:
    """Every inspector widget with good and bad values (also run by the every-widget tour)."""
    viewer.set_panel("onering")
    drive(viewer, "vertex", 7)
    ins = viewer.panels["onering"].state.inspection
    assert ins is not None and ins.vertex == 7
    assert {scene.INSPECT_WEIGHTS, scene.INSPECT_ARCS, scene.INSPECT_CELL} <= inspector_names()
    drive(viewer, "area kind", "voronoi")
    assert (
        viewer.state.curv.area == "voronoi"
        and viewer.panels["onering"].state.inspection.area_kind == "voronoi"
    )
    cell = ps.get_surface_mesh(scene.INSPECT_CELL)
    assert cell.n_faces() >= 2 * len(ins.faces)  # circumcentre paths on the acute sphere
    for bad in ("", "nonsense", "VORONOI"):
        drive(viewer, "area kind", bad)
        assert viewer.state.curv.area == "voronoi" and "area kind" in viewer.state.errors["onering"]
    drive(viewer, "area kind", "barycentric")
    assert (
        viewer.panels["onering"].state.inspection.area_kind == "barycentric"
        and "onering" not in viewer.state.errors
    )
    for rule in ("zero", "2pi", "pi"):
        drive(viewer, "boundary rule", rule)
        assert (
            viewer.state.curv.boundary
            == rule
            == viewer.panels["onering"].state.inspection.boundary_rule
        )
    for bad in ("", "4pi", "-1"):
        drive(viewer, "boundary rule", bad)
        assert (
            viewer.state.curv.boundary == "pi" and "boundary rule" in viewer.state.errors["onering"]
        )
    drive_hover(viewer)


def drive_hover(viewer) -> None:
    panel = viewer.panels["onering"]
    panel.clock, panel.throttle = (clock := FakeClock()), HoverThrottle()
    picks0 = panel.picks
    for _ in range(3):  # over nothing: one pick once the cursor rests, then idle
        drive(viewer, "hover", (5.0, 5.0))
        clock.t += 0.1
    assert panel.picks == picks0 + 1 and panel.hovered == ""
    for x in (6.0, 7.0, 8.0):  # moving: no picking
        drive(viewer, "hover", (x, 5.0))
        clock.t += 0.05
    assert panel.picks == picks0 + 1
    drive(viewer, "hover", (-1e9, 1e9))  # off-screen: no hit, no error
    clock.t += 0.1
    drive(viewer, "hover", (-1e9, 1e9))
    assert panel.picks == picks0 + 2 and panel.hovered == ""
    assert "labels" not in viewer.state.errors


def drive_panel_onering(viewer, tmp_path: Path) -> None:
    drive_onering_widgets(viewer)
    drive_inspector(viewer)


# ------------------------------------------------------------------ shown for the export test
def show_for_export(viewer, tmp_path: Path) -> Any:
    """What the view shows for the export test (``tests/app/test_export_views.py``): its
    fields and copies; a generator yields once per state to export."""
    drive(viewer, "vertex", 5)
